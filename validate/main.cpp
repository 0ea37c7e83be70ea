// rdyn command-line interface. Exit status: 0 success, 2 bad input (scene, arguments,
// output folder, a mechanism that cannot assemble), 1 an internal failure.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"
#include "models/scene_yaml.hpp"
#include "validate/output_dir.hpp"
#include "validate/timeseries_csv.hpp"

namespace {

using namespace rdyn;

constexpr int kExitBadInput = 2;

struct SimulateArgs {
  std::string scene;
  std::string model = "full";
  double duration = NAN;
  double dt_out = NAN;
  double tolerance = NAN;
  std::string integrator = "rkmerson";
  std::string route = "actuator";
  std::vector<std::string> sets;
  std::string out;
};

models::Scene load(const std::string& scene, const std::vector<std::string>& sets) {
  std::vector<models::Override> overrides;
  for (const auto& s : sets) overrides.push_back(models::parse_override(s));
  return models::load_scene(scene, overrides);
}

int run_simulate(const SimulateArgs& a) {
  models::Scene scene = load(a.scene, a.sets);
  engine::ForwardOptions opt;
  opt.duration_s = std::isnan(a.duration) ? scene.simulation.duration_s : a.duration;
  opt.output_interval_s = std::isnan(a.dt_out) ? scene.simulation.output_interval_s : a.dt_out;
  opt.tolerance = std::isnan(a.tolerance) ? scene.simulation.tolerance : a.tolerance;
  opt.integrator = a.integrator;
  if (!(opt.duration_s > 0) || !(opt.output_interval_s > 0) || !(opt.tolerance > 0 && opt.tolerance < 1))
    throw models::SceneError(a.scene, 0, "--duration/--dt-out/--tolerance", "must be positive (tolerance < 1)");
  validate::OutputDir out(a.out);  // fails early on an unwritable folder

  engine::FullModelOptions mo;
  mo.route = a.route == "reaction" ? engine::ConstraintForceRoute::Reaction : engine::ConstraintForceRoute::Actuator;
  engine::FullModel model(scene, mo);
  const engine::TimeSeries ts = engine::simulate_full(model, opt);
  validate::write_timeseries_csv(out.file("timeseries.csv"), ts);

  const auto eb = validate::energy_balance(ts);
  nlohmann::json run = {
      {"scene", scene.name},
      {"scene_file", scene.source_file},
      {"model", a.model},
      {"duration_s", opt.duration_s},
      {"output_interval_s", opt.output_interval_s},
      {"tolerance", opt.tolerance},
      {"integrator", opt.integrator},
      {"constraint_force_route", a.route},
      {"simbody_bodies", model.num_simbody_bodies()},
      {"steps_taken", ts.stats.steps_taken},
      {"steps_attempted", ts.stats.steps_attempted},
      {"smallest_step_s", ts.stats.smallest_step_s},
      {"max_loop_gap_m", ts.stats.max_constraint_error},
      {"wall_time_s", ts.stats.wall_time_s},
      {"wall_time_per_simulated_s", ts.stats.wall_time_s / opt.duration_s},
      {"energy_balance_residual_J", eb.max_residual_J},
      {"energy_scale_J", eb.energy_scale_J},
  };
  {
    std::ofstream f(out.file("run.json"));
    f << run.dump(2) << "\n";
    if (!f) throw validate::OutputError(a.out + ": cannot write run.json");
  }
  out.commit();
  std::fprintf(stderr, "%s\n",
               fmt::format("rdyn: {} ({} model) {:.3g} s simulated in {:.3g} s wall, {} steps; energy balance "
                           "residual {:.3g} J of {:.3g} J; wrote {}/timeseries.csv",
                           scene.name, a.model, opt.duration_s, ts.stats.wall_time_s, ts.stats.steps_taken,
                           eb.max_residual_J, eb.energy_scale_J, a.out)
                   .c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rdyn — reduced-parameter models of one-degree-of-freedom planar mechanisms, validated against a "
      "full multibody model (Simbody).\n"
      "A SCENE is a shipped scene name (bicycle, fourbar, slider-crank) or a YAML file (see models/README.md)."};
  app.require_subcommand(1);

  SimulateArgs sim;
  auto* simulate = app.add_subcommand(
      "simulate", "Simulate a scene and write DIR/timeseries.csv (t,q,qdot,qddot,energy,work,F_<name>...) "
                  "and DIR/run.json (settings, cost, energy-balance residual).");
  simulate->add_option("scene", sim.scene, "Scene name or YAML file")->required();
  simulate->add_option("--model", sim.model, "Model to simulate: full (Simbody forward dynamics)")
      ->check(CLI::IsMember({"full"}));
  simulate->add_option("--duration", sim.duration, "Simulated time [s] (default: the scene's)");
  simulate->add_option("--dt-out", sim.dt_out, "Output interval [s] (default: the scene's)");
  simulate->add_option("--tolerance", sim.tolerance, "Full-model integrator accuracy (default: the scene's)");
  simulate->add_option("--integrator", sim.integrator, "Full-model integrator")
      ->check(CLI::IsMember({"rkmerson", "rk3", "cpodes"}));
  simulate->add_option("--constraint-force-route", sim.route,
                       "actuator (pin + prescribed slider, the paper's constraint actuator) or reaction "
                       "(Simbody's joint reaction projected on the direction)")
      ->check(CLI::IsMember({"actuator", "reaction"}));
  simulate->add_option("--set", sim.sets, "Override a scalar of the scene: key.path=value (repeatable)");
  simulate->add_option("--out", sim.out, "Output folder (written atomically)")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  }

  try {
    if (*simulate) return run_simulate(sim);
  } catch (const models::SceneError& e) {
    std::fprintf(stderr, "rdyn: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const engine::EngineError& e) {
    std::fprintf(stderr, "rdyn: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const validate::OutputError& e) {
    std::fprintf(stderr, "rdyn: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rdyn: internal error: %s\n", e.what());
    return 1;
  }
  return 0;
}
