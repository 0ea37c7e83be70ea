// Fingerprint of the part of a scene that a reduced table depends on, so a table can record
// the scene it came from and a consumer can refuse a table from another scene.
#pragma once

#include <cstdint>
#include <string>

#include "models/scene.hpp"

namespace rdyn::models {

// Canonical, deterministic text of everything extraction reads from the scene: bodies (mass,
// centre of mass, inertia, named points), ground points, joints (type, parent, child, points,
// axis, offset, guess — the guesses pick the assembled branch), loops, gears, the independent
// joint, gravity, the requested constraint forces, the initial q (it anchors the grid and the
// branch), springs (their values enter Q_cons and V), and where each other load acts (torque
// joints and rate gates — the gates decide which switch angles a table carries —, motor joints,
// resistance bodies — they decide the w_<body> columns).
//
// Left out, because no table column depends on them: the values of non-conservative loads
// (torque values, motor stall torque and no-load speed, resistance law and coefficient — the
// reduced model applies them to the table; calibration and sweeps vary them on one table),
// load names, the scene name, description and source file, outputs.bodies, initial q̇, and
// the simulation and validation blocks.
//
// Doubles are printed as C99 hex floats (exact); −0 is written as 0; every string is
// length-prefixed; vectors keep scene order (order is part of the mechanism: it names the
// columns' order), maps are sorted by key.
std::string canonical_scene_text(const Scene& scene);

// Appends v as C99's "%a" prints a double with glibc (0x1.8p+1, 0x0p+0, 0x0.8p-1022 for a
// subnormal, inf, -nan; lowercase, trailing zeros of the fraction dropped): the canonical text's
// numbers, byte for byte what snprintf wrote before (the table headers' recorded hashes stay
// valid), without snprintf's cost.
void append_hex_double(std::string& out, double v);

// 64-bit FNV-1a of canonical_scene_text (offset basis 14695981039346656037, prime
// 1099511628211 — Fowler, Noll, Vo; IETF draft-eastlake-fnv, section 2).
std::uint64_t scene_hash(const Scene& scene);

// 64-bit FNV-1a of any text (the same function scene_hash applies to the canonical text; sweeps
// fingerprint their options with it).
std::uint64_t fnv1a64(const std::string& text);

// The hash as 16 lowercase hexadecimal digits (what a table header records).
std::string scene_hash_hex(std::uint64_t hash);

}  // namespace rdyn::models
