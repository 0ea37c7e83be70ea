#include "reduced/profile_columns.hpp"

#include <fmt/format.h>

#include "models/scene_hash.hpp"

namespace rdyn::reduced {

std::vector<double> calc_profile_angles(const Samples& s, const models::Scene& scene, const std::string& of) {
  if (of == scene.independent) return s.q;
  const int p = s.column("p_" + of), k = s.column("k_" + of);
  if (p < 0 || k < 0)
    throw TableError(fmt::format("the table has no position column p_{} for the profile of joint '{}': extract it "
                                 "with outputs.joints listing '{}'",
                                 of, of, of));
  // p_<j> holds the joint angle minus its whole turns per turn of q (joint_outputs.cpp).
  std::vector<double> theta(s.q.size());
  for (size_t i = 0; i < s.q.size(); ++i) theta[i] = s.columns[p][i] + s.columns[k][i] * s.q[i];
  return theta;
}

Samples with_profile_columns(Samples s, const models::Scene& scene) {
  for (const auto& t : scene.joint_torques) {
    if (!t.profile) continue;
    const int c = s.column("tau_" + t.name);
    if (c < 0) throw TableError("the table has no column tau_" + t.name + ": extract it from the profiled scene");
    const auto theta = calc_profile_angles(s, scene, t.profile->of);
    for (size_t i = 0; i < theta.size(); ++i) s.columns[c][i] = models::calc_profile(*t.profile, theta[i]);
  }
  s.scene_hash = models::scene_hash(scene);
  return s;
}

void refit_profile_columns(ReducedModel& m, const Samples& s, Interpolation interp) {
  // The tau columns alone, on the same grid: every interpolant fits each column by itself.
  Samples one;
  one.periodic = s.periodic;
  one.revolute = s.revolute;
  one.q0 = s.q0;
  one.step = s.step;
  one.q = s.q;
  std::vector<int> dest;
  for (size_t c = 0; c < s.names.size(); ++c)
    if (s.names[c].rfind("tau_", 0) == 0) {
      one.add(s.names[c], s.columns[c]);
      dest.push_back(m.table.column(s.names[c]));
      if (dest.back() < 0) throw TableError("the reduced model has no column " + s.names[c]);
    }
  if (dest.empty()) return;
  const Table t = build_table(one, interp);
  if (t.intervals != m.table.intervals || t.step != m.table.step || t.q0 != m.table.q0)
    throw TableError("refit_profile_columns: the samples' grid is not the model's");
  for (int iv = 0; iv < t.intervals; ++iv)
    for (size_t c = 0; c < dest.size(); ++c)
      for (int k = 0; k < 4; ++k)
        m.table.coef[(static_cast<size_t>(iv) * m.table.cols + dest[c]) * 4 + k] =
            t.coef[(static_cast<size_t>(iv) * t.cols + c) * 4 + k];
  // The fused evaluations read packed copies of the columns: repack them from the new table.
  m.rhs_block = make_column_block(m.table, m.rhs_cols);
  m.record_block = make_column_block(m.table, m.record_cols);
}

}  // namespace rdyn::reduced
