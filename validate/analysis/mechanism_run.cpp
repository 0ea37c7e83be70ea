#include "validate/analysis/mechanism_run.hpp"

#include <algorithm>
#include <stdexcept>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"
#include "reduced/extract.hpp"
#include "reduced/joint_outputs.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "validate/analysis/build_reduced.hpp"

namespace rdyn::validate {

models::Scene with_every_joint_output(const models::Scene& scene) {
  models::Scene s = scene;
  s.outputs.joints.clear();
  for (const auto& j : s.joints) s.outputs.joints.push_back(j.name);
  return s;
}

models::TimeSeries simulate_every_joint(const models::Scene& scene, const std::string& model, double duration_s,
                                        double output_interval_s) {
  const models::Scene s = with_every_joint_output(scene);
  if (model == "full") {
    engine::FullModel fm(s);
    engine::ForwardOptions opt;
    opt.duration_s = duration_s, opt.output_interval_s = output_interval_s, opt.tolerance = s.simulation.tolerance;
    return engine::simulate_full(fm, opt);
  }
  if (model != "reduced") throw std::invalid_argument("simulate_every_joint: model is full or reduced");
  // The reduced model gives every joint's coordinate from its table (p_<j> + k_j q); reactions
  // need one constraint line per component (reduced/joint_outputs.hpp).
  const models::Scene rs = reduced::with_reaction_requests(s);
  auto e = extract_from_full(rs, 10.0, reduced::parse_method("kinetostatic"));
  const auto rm = reduced::make_reduced_model(e.samples, rs, reduced::parse_interpolation("fourier"), false);
  reduced::ReducedOptions opt;
  opt.duration_s = duration_s, opt.output_interval_s = output_interval_s;
  auto ts = reduced::simulate_reduced(rm, s.initial.q, s.initial.qdot, opt);
  reduced::check_energy_balance(ts, 0.01, "rk8pd at tolerance 1e-8");
  reduced::add_joint_outputs(s, rm, ts);
  return ts;
}

std::vector<double> joint_coordinates(const models::Scene& scene, const models::TimeSeries& ts, size_t row) {
  std::vector<double> q;
  for (const auto& j : scene.joints) {
    const auto it = std::find(ts.column_names.begin(), ts.column_names.end(), "q_" + j.name);
    if (it == ts.column_names.end()) throw std::invalid_argument("the run has no column q_" + j.name);
    const auto& col = ts.columns[static_cast<size_t>(it - ts.column_names.begin())];
    if (row >= col.size()) throw std::invalid_argument("joint_coordinates: no such row");
    q.push_back(col[row]);
  }
  return q;
}

}  // namespace rdyn::validate
