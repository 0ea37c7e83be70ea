#include "validate/harness/peers.hpp"

#include <fmt/format.h>

#include <cmath>

#include "engine/full_model.hpp"
#include "engine/kinetostatic.hpp"
#include "engine/mujoco_peer.hpp"
#include "validate/io/argument_error.hpp"
#include "validate/harness/pareto.hpp"
#include "validate/harness/timing.hpp"

namespace rdyn::validate {

JointState calc_initial_joint_state(const models::Scene& scene) {
  engine::FullModel full(scene);
  engine::FullWorkspace ws(full);
  const auto k = engine::calc_kinetostatic(full, ws, scene.initial.q, scene.initial.qdot, 0.0, engine::Loads::Off);
  return {k.joint_q, k.joint_u};
}

void check_peers(const std::vector<std::string>& peers) {
  for (size_t i = 0; i < peers.size(); ++i)
    for (size_t k = 0; k < i; ++k)
      if (peers[i] == peers[k]) throw ArgumentError("--peers: '" + peers[i] + "' given twice");
  for (const auto& p : peers) {
    if (p != "mujoco") throw ArgumentError("--peers: unknown peer '" + p + "' (mujoco)");
    if (!engine::mujoco_available())
      throw ArgumentError(
          "--peers mujoco: MuJoCo was not found when rdyn was built (install libmujoco-dev and reconfigure with "
          "CMake)");
  }
}

namespace {

// One MuJoCo ladder: the model is compiled once per step (not timed, like the full model's
// construction); each run is timed by repeats from the same initial state.
PeerLadder run_mujoco_ladder(const models::Scene& scene, const JointState& start, const std::string& integrator,
                             const LadderPlan& plan, ValidationResult& v, Progress& progress, long& done, long total) {
  PeerLadder ladder;
  ladder.engine = "mujoco";
  ladder.version = engine::mujoco_version();
  ladder.integrator = integrator;
  engine::MujocoSettings settings;
  settings.integrator = integrator;
  ladder.how = fmt::format(
      "MuJoCo {} ({} integrator) at fixed steps, each shortened to fill the {:g} s output interval with whole steps; "
      "the scene exported as MJCF (rdyn export-mjcf --fold), loops as connect equalities with solref = [2·step, 1], "
      "solimp = [{:g}, {:g}, 0.001]; loads applied at every evaluation; started from the full model's assembled state; "
      "{}",
      ladder.version, integrator == "rk4" ? "RK4" : "semi-implicit Euler", v.output_interval_s, settings.impedance,
      settings.impedance,
      plan.time_peers_without_outputs
          ? "timed with one output at the end like the full and reduced models (its fixed step is the same), errors "
            "from the same settings on the output grid."
          : "timed with its outputs (its fixed step is not capped by them).");
  for (double h0 : plan.peer_steps_s) {
    progress.count(scene.name + ": MuJoCo ladders", done++, total);
    RunRecord r;
    r.model = "mujoco";
    r.integrator = integrator;
    settings.timestep_s = engine::calc_peer_step(h0, v.output_interval_s);
    r.fixed_step_s = settings.timestep_s;
    engine::MujocoRunOptions ro;
    ro.duration_s = v.duration_s;
    ro.output_interval_s = v.output_interval_s;
    ro.initial_u = start.u;
    try {
      const engine::MujocoModel model(scene, start.q, settings);
      models::TimeSeries ts, timed;
      auto ro_timed = ro;
      // One output at the end when the run is a whole number of steps (else the grid's rows).
      const double per_run = v.duration_s / settings.timestep_s;
      const bool one_output =
          plan.time_peers_without_outputs && std::abs(per_run - std::round(per_run)) <= 1e-9 * per_run;
      if (one_output) ro_timed.output_interval_s = v.duration_s;
      const auto walls = time_repeats([&] { timed = engine::simulate_mujoco(model, ro_timed); }, plan.peer_repeats);
      r.timed_steps = timed.stats.steps_taken;
      r.timed_output_interval_s = ro_timed.output_interval_s;
      ts = one_output ? engine::simulate_mujoco(model, ro) : timed;
      finish_run(r, walls, ts, v);
    } catch (const models::NumericalError& e) {
      mark_stopped(r, e.what(), v.quantities);
    }
    ladder.runs.push_back(r);
  }
  return ladder;
}

}  // namespace

void run_peer_ladders(const models::Scene& scene, const std::vector<std::string>& peers, const LadderPlan& plan,
                      ValidationResult& v, Progress& progress) {
  check_peers(peers);
  if (peers.empty()) return;
  const JointState start = calc_initial_joint_state(scene);
  long done = 0;
  const long total = static_cast<long>(2 * plan.peer_steps_s.size());
  for (const char* integrator : {"euler", "rk4"})
    v.peers.push_back(run_mujoco_ladder(scene, start, integrator, plan, v, progress, done, total));
  progress.count(scene.name + ": MuJoCo ladders", total, total);
}

void analyse_peers(ValidationResult& v) {
  for (auto& p : v.peers) {
    mark_pareto(p.runs, v.headline_quantity);
    // The peer's runs beside the reduced ones, so one rule picks both sides of the ratio.
    std::vector<RunRecord> both = p.runs;
    both.insert(both.end(), v.runs.begin(), v.runs.end());
    const auto m = calc_matched_speedup(both, v.headline_quantity, v.matched_target, p.engine);
    p.matched_peer = m.full;
    p.matched_reduced = m.reduced >= 0 ? m.reduced - static_cast<int>(p.runs.size()) : -1;
    p.speedup_at_matched_error.reset();
    // No claim from a validation that already failed (as the full model's speedup).
    if (v.failures.empty() && v.reference_change.samples >= kMinComparedSamples) p.speedup_at_matched_error = m.speedup;
  }
}

}  // namespace rdyn::validate
