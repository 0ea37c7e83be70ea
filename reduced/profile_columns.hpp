// A new shape for profiled drive loads on the same table. A joint torque's profile enters the
// reduced model only through its column tau_<load> = τ(θ_of(q)) per unit amplitude (the
// kinematic columns do not depend on loads), so a search over shapes recomputes that column
// from the profile joint's angle at the grid points and refits it, never re-extracting
// (extraction costs ~15 ms and a full model; a refit of one column ~0.1 ms).
#pragma once

#include <string>
#include <vector>

#include "models/scene.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/samples.hpp"
#include "reduced/table.hpp"

namespace rdyn::reduced {

// The angle θ [rad] of revolute joint `of` at the grid points s.q: q itself when `of` is the
// independent coordinate, else p_<of> + k_<of>·q from the joint-position columns
// (reduced/joint_outputs.hpp). Throws TableError when the table has neither.
std::vector<double> calc_profile_angles(const Samples& s, const models::Scene& scene, const std::string& of);

// The samples with the tau_<load> column of every profiled joint torque of `scene` recomputed
// from its profile (models::calc_profile at calc_profile_angles), and the scene hash of
// `scene`. `scene` must differ from the extracted one in profile shapes and load values only
// (that is what the hash then certifies). Throws TableError when a tau column is missing.
Samples with_profile_columns(Samples s, const models::Scene& scene);

// Refits the tau columns of `s` (from with_profile_columns) into m's table with the
// interpolation m was built with; every other column is left as it is, and the packed column
// blocks (rhs_block, record_block) are rebuilt from the new table. Throws TableError when the
// grids differ.
void refit_profile_columns(ReducedModel& m, const Samples& s, Interpolation interp);

}  // namespace rdyn::reduced
