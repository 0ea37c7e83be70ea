// Geared bodies folded into their drivers (docs/theory.md §7): a body on a ground joint that
// turns about its own centre of mass at a fixed ratio r to another ground joint, touched by
// nothing else, is not built as a body. Its coordinate follows the driver, q_driven =
// r·q_driver + c, and its kinetic energy ½ I (r u)² = ½ (r² I) u² moves onto the driver's
// body. One rule for the full model (engine/full_model.cpp), the MJCF export and the MuJoCo
// peer, so that every engine simulates the same bodies.
#pragma once

#include <string>
#include <vector>

#include "models/scene.hpp"

namespace rdyn::models {

struct GearFold {
  int gear = -1;          // scene gear index
  int body = -1;          // the folded (driven) body, scene body index
  int driven_joint = -1;  // scene joint index of the folded body's joint
  int driver_joint = -1;
  int driver_body = -1;   // the driver joint's child, which carries the folded inertia
  double ratio = 1.0;     // r: q̇_driven = r·q̇_driver
  double q_offset = 0.0;  // c: q_driven = r·q_driver + c (calc_gear_offset)
  double moved_inertia_kgm2 = 0.0;  // r²·I of the folded body, added to the driver body's Izz
};

// Whether gear `g` can be folded into its driver: the driven body is a leaf turning about its
// centre of mass on a ground joint, the driver's joint is on ground too, the driven joint is not
// the independent coordinate, and no loop, spring, point force, joint torque or its gate, motor,
// constraint-force request, other gear or outputs.bodies entry touches them. (A driver folded
// itself is refused as well; the "other gear" condition already excludes it.)
std::vector<bool> calc_foldable_gears(const Scene& scene);

// The folds of every foldable gear, in gear order.
std::vector<GearFold> calc_gear_folds(const Scene& scene);

// c of gear `gear` in q_driven = r·q_driver + c: fixed by the joints' guesses (the assembly's
// starting point), as for an unfolded gear's constraint. Both joints must exist.
double calc_gear_offset(const Scene& scene, const Gear& gear);

// How many turns of the independent coordinate bring every revolute joint geared to it (through
// chains of gears, either way round) back to its angle mod 2π: the smallest k ≤ kMaxTurnsToRepeat
// with k·ρ_j whole for every joint's rate ratio ρ_j (1 without gears; 0 when no such k exists).
// `why` names the gear and ratio that needs the most turns. Geometry alone is not consulted: a
// driven disc turning about its own centre repeats each turn whatever its ratio, so this says
// what the gears allow, and a sweep that does not close one turn uses it for its message.
inline constexpr int kMaxTurnsToRepeat = 1000;
int calc_turns_to_repeat(const Scene& scene, std::string& why);

}  // namespace rdyn::models
