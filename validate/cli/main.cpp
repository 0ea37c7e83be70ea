// rdyn command-line interface. Exit status (README, "Exit status"): 0 success; 1 a numerical
// failure (an integrator that cannot go on, an energy balance that does not close, a
// calibration or validation that misses its target); 2 bad input (scene, arguments, table,
// output destination, a mechanism that cannot assemble), with the file, line and field.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>
#include <vector>

#include "engine/full_model.hpp"
#include "models/scene.hpp"
#include "reduced/samples.hpp"
#include "validate/cli/cli_options.hpp"
#include "validate/cli/animate_command.hpp"
#include "validate/cli/commands.hpp"
#include "validate/cli/expand.hpp"
#include "validate/cli/inspect.hpp"
#include "validate/cli/drive_command.hpp"
#include "validate/cli/optimize_command.hpp"
#include "validate/io/output_dir.hpp"
#include "validate/harness/peers.hpp"

namespace {
using namespace rdyn::validate;

constexpr int kExitBadInput = 2;
constexpr int kExitNumerical = 1;

// An empty --load would silently mean "no load named" (every joint torque): refuse it.
CLI::Validator names_a_load() {
  return CLI::Validator(
      [](std::string& v) { return v.empty() ? std::string("an empty name names no load") : std::string(); }, "NAME");
}

void add_simulate_command(CLI::App& app, SimulateArgs& sim) {
  auto* simulate = app.add_subcommand(
      "simulate",
      "Simulate a scene with the full model (Simbody forward dynamics) or the reduced model, and write "
      "DIR/timeseries.csv (t,q,qdot,qddot,energy,work,F_<name>...) and DIR/run.json (settings, cost, "
      "energy-balance residual).");
  simulate->add_option("scene", sim.scene, "Scene name or YAML file")->required();
  simulate->add_option("--model", sim.model, "full (Simbody) or reduced (tables + Eksergian's equation)")
      ->check(CLI::IsMember({"full", "reduced"}));
  // Typed values are kept apart from the defaults: the optional fields are set only when given.
  simulate->add_option_function<double>("--duration", [&sim](const double& v) { sim.duration = v; },
                                        "Simulated time [s] (default: the scene's)");
  simulate->add_option_function<double>("--dt-out", [&sim](const double& v) { sim.dt_out = v; },
                                        "Output interval [s] (default: the scene's)");
  simulate->add_option("--set", sim.sets, "Override a scalar of the scene: key.path=value (repeatable)");
  simulate->add_option("--out", sim.out, "Output folder (written atomically)")->required();
  simulate->add_flag("--force", sim.force, kForceHelpDir);
  auto* full = simulate->add_option_group("full model");
  full->add_option_function<double>("--tolerance", [&sim](const double& v) { sim.tolerance = v; },
                                    "Integrator accuracy (default: the scene's)");
  full->add_option("--integrator", sim.integrator, "rkmerson, rk3 or cpodes")
      ->check(CLI::IsMember({"rkmerson", "rk3", "cpodes"}));
  full->add_option("--constraint-force-route", sim.route,
                   "actuator (pin + prescribed slider, the paper's constraint actuator) or reaction "
                   "(Simbody's joint reaction projected on the direction)")
      ->check(CLI::IsMember({"actuator", "reaction"}));
  auto* red = simulate->add_option_group("reduced model");
  red->add_option("--table", sim.table, "Reduced table from `rdyn extract` (default: extract now)");
  red->add_option("--grid-deg", sim.grid_deg,
                  "Grid step when extracting [deg] (default 10, as the paper, halved down to 0.3125 while the table "
                  "does not resolve the mechanism, then while the run changes more than 5e-4 of a column's peak on "
                  "half the grid; run.json: grid_check)")
      ->each([&sim](const std::string&) { sim.grid_given = true; });
  red->add_option("--method", sim.method, "Extraction method")
      ->check(CLI::IsMember({"kinetostatic", "paper-sweep", "integrated", "direct"}));
  red->add_option("--interp", sim.interpolation,
                  "Interpolation: cubic (periodic spline), akima, linear, or fourier (trigonometric, periodic only)")
      ->check(CLI::IsMember({"cubic", "akima", "linear", "fourier"}));
  red->add_flag("--energy-consistent", sim.energy_consistent, "Use m2 = ½ dm1/dq of the m1 interpolant");
  red->add_option("--reduced-integrator", sim.reduced_integrator, "rk8pd, rkf45, rkck (adaptive) or rk4-fixed")
      ->check(CLI::IsMember({"rk8pd", "rkf45", "rkck", "rk4-fixed"}));
  red->add_option("--reduced-tolerance", sim.reduced_tolerance, "Adaptive integrator tolerance (default 1e-8)");
  red->add_option("--fixed-step", sim.fixed_step, "rk4-fixed step [s] (default 1e-3)");
}

void add_extract_command(CLI::App& app, ExtractArgs& ext) {
  auto* extract = app.add_subcommand(
      "extract",
      "Extract the reduced parameters of a scene from kinetostatic calls of the full model and write a portable "
      "table: q_deg,m1,m2,me1_<f>,me2_<f>,Q_cons,V,Qx_cons_<f>,r_<joint>...,rx_<f>_<joint>...,w_<body>...");
  extract->add_option("scene", ext.scene, "Scene name or YAML file")->required();
  extract->add_option("--grid-deg", ext.grid_deg,
                      "Grid step [deg]; must divide 360 (default 10). Range tables: intervals of at most this "
                      "over a revolute range, 360/step intervals over a prismatic one");
  extract->add_option("--method", ext.method, "kinetostatic, paper-sweep, integrated or direct")
      ->check(CLI::IsMember({"kinetostatic", "paper-sweep", "integrated", "direct"}));
  extract->add_option("--set", ext.sets, "Override a scalar of the scene: key.path=value (repeatable)");
  extract->add_option("--out", ext.out, "Output CSV file")->required();
  extract->add_flag("--force", ext.force, kForceHelpFile);
}

void add_calibrate_command(CLI::App& app, CalibrateArgs& cal) {
  auto* calibrate = app.add_subcommand(
      "calibrate",
      "Find (GSL Brent) the value of a drive load -- a joint torque or force, or a motor's stall torque with its "
      "no-load speed kept (--load), or every joint torque together -- that holds the mean steady rate of the "
      "independent coordinate at F rev/s with the reduced model, confirmed with the full model. With --power-w "
      "the scene's one resistance is set too, so that the steady cycle dissipates P watts on average at F; "
      "without, the resistances stay as given. "
      "Prints JSON on standard output (load, load_kind, load_value, load_unit, drive_torque_Nm for joint torques, "
      "mean_cadence_hz_reduced, mean_cadence_hz_full, mean_power_w, mean_dissipated_power_w, load_searches, "
      "force_name and its peak_force_N, "
      "speed_fluctuation, ...); progress goes to standard error.");
  calibrate->add_option("scene", cal.scene, "Scene name or YAML file")->required();
  add_operating_point_options(*calibrate, cal.cadence_hz, cal.cadence_given, cal.power_w, cal.power_given);
  calibrate->add_option("--load", cal.load,
                        "The joint_torque, point_force or motor to adjust, or joint torques or point forces joined "
                        "by + (default: the scene's validation.calibrate.load, else every joint torque together)")
      ->check(names_a_load());
  calibrate->add_option("--write-scene", cal.write_scene, "Write the calibrated scene (YAML) here");
  calibrate->add_flag("--force", cal.force, kForceHelpFile);
  add_scene_overrides(*calibrate, cal.sets);
  add_reduced_table_options(*calibrate, cal.grid_deg, cal.interpolation);
  // Given: it overrides the scene's validation.calibrate.grid_deg.
  calibrate->get_option("--grid-deg")->each([&cal](const std::string&) { cal.grid_given = true; });
}

void add_validate_command(CLI::App& app, ValidateArgs& val) {
  auto* validate = app.add_subcommand(
      "validate",
      "Validate the reduced model against full forward dynamics: a converged reference, a ladder of full-model "
      "tolerances and of reduced models (grid × interpolation × integrator; fixed steps from the scene's time "
      "scale), errors over the steady cycles (the whole run when it has none), median timings of repeats up to a "
      "minimum wall time, the matched-error speedup, calibration when the scene declares an operating point. Writes "
      "DIR/summary.json (every number and the data of every figure), the CSVs and gnuplot scripts behind every "
      "figure, and DIR/report.html (rendered from summary.json; verdicts first). With --suite, every scene of a "
      "folder and an index with their verdicts (exit status 1 if any fails its thresholds).");
  validate->add_option("scene", val.scene, "Scene name or YAML file");
  validate->add_option("--suite", val.suite, "Folder of scenes to validate (each may declare thresholds)");
  validate->add_option("--out", val.out, "Output folder (written atomically)")->required();
  validate->add_flag("--force", val.force, kForceHelpDir);
  validate->add_option("--set", val.sets, "Override a scalar of the scene(s): key.path=value (repeatable)");
  validate->add_flag("--quick", val.quick, "Short ladders and single repeats (default for --suite)");
  validate->add_flag("--thorough", val.thorough, "Full ladders for --suite too");
  validate->add_option("--peers", val.peers,
                       "Peer engines to run beside the full model: mujoco (MuJoCo's Euler and RK4 at fixed steps from "
                       "the scene's time scale, in summary.json's peers and the accuracy-against-cost figure; needs "
                       "rdyn built with MuJoCo)")
      ->check(CLI::IsMember(kPeers));
}

void add_report_command(CLI::App& app, ReportArgs& rep) {
  auto* report = app.add_subcommand(
      "report",
      "Re-render a validation report from its summary.json alone (e.g. after editing a gnuplot style or moving "
      "the folder): writes DIR/report.html, the figures' data, scripts and SVGs, and a copy of the summary.");
  report->add_option("summary", rep.summary, "summary.json written by `rdyn validate`")->required();
  report->add_option("--out", rep.out, "Output folder (written atomically)")->required();
  report->add_flag("--force", rep.force, kForceHelpDir);
}

void add_sweep_command(CLI::App& app, SweepArgs& sw) {
  auto* sweep = app.add_subcommand(
      "sweep",
      "Population sweep: calibrate the drive load of many cases with the reduced model, in parallel threads. "
      "One CSV row per case: the varied parameters, the calibrated drive load, the peak of the first constraint "
      "force, the speed fluctuation and a peak_COLUMN per --peak. --shard i/N runs the i-th of N contiguous blocks of cases "
      "(Slurm job arrays, GNU parallel), each CSV naming its sweep and cases; `rdyn sweep --merge OUT.csv PART...` "
      "checks the parts are one whole sweep and writes what one process would have.");
  sweep->add_option("scene", sw.inputs, "Scene name or YAML file (with --merge: the part CSVs)")->required();
  auto* vary = sweep->add_option("--vary", sw.vary,
                                 "key=a:b:n: n values of a scene key from a to b (repeatable: all combinations)");
  auto* set = sweep->add_option("--set", sw.sets, "Fixed override key.path=value (repeatable)");
  auto* out = sweep->add_option("--out", sw.out, "Output CSV file (required unless --merge)");
  sweep->add_flag("--force", sw.force, kForceHelpFile);
  auto* shard = sweep->add_option("--shard", sw.shard, "i/N: run the i-th of N blocks of cases (default 0/1)");
  auto* resume = sweep->add_flag("--resume", sw.resume,
                                 "Skip the run when --out already holds this shard complete (a partial or other "
                                 "sweep's file is run again and replaced)");
  // Typed values are kept apart from the defaults, so a typed 0 is refused instead of meaning "default".
  auto* threads = sweep->add_option_function<int>("--threads", [&sw](const int& v) { sw.threads = v; },
                                                  "Worker threads, 1..256 (default: hardware threads)");
  auto* cadence = sweep->add_option_function<double>("--cadence-hz", [&sw](const double& v) { sw.cadence_hz = v; },
                                     "Calibration cadence [Hz] (default: the scene's validation.calibrate)");
  auto* power = sweep->add_option_function<double>(
      "--power-w", [&sw](const double& v) { sw.power_w = v; },
      "Calibration power [W] (default: the scene's validation.calibrate; none: the resistances stay as given)");
  auto* load = sweep->add_option("--load", sw.load, "The drive load to calibrate, as for calibrate --load")
                   ->check(names_a_load());
  auto* grid = sweep->add_option("--grid-deg", sw.grid_deg,
                                 "Reduced table grid [deg] (default: the scene's validation.calibrate.grid_deg, else "
                                 "10, halved per case while it does not resolve the mechanism)")
                   ->each([&sw](const std::string&) { sw.grid_given = true; });
  auto* drive = sweep->add_option_function<double>(
      "--drive-cadence-hz", [&sw](const double& v) { sw.drive_cadence_hz = v; },
      "Drive each case at this constant rate [rev/s] for one revolution (reduced model, as rdyn drive) instead of "
      "calibrating it: the rows give the drive's RMS, peak and mean, the mean and peak power");
  drive->excludes(cadence)->excludes(power)->excludes(load);
  auto* peak = sweep->add_option(
      "--peak", sw.peaks,
      "COLUMN (repeatable): add peak_COLUMN, the largest |value| of that column of the case's reduced run over its "
      "steady cycle (a drive sweep: its revolution): any column of `rdyn simulate --model reduced` but t (q, qdot, "
      "qddot, energy, work, F_<force>, the joint outputs the scene requests: R_<joint>_x, shaking_y, q_<joint>, …; "
      "a drive sweep's: also drive_Nm, drive_W); an unknown or unrequested column is refused, naming the available");
  sweep->add_option("--merge", sw.merge,
                    "OUT.csv: merge the part CSVs given as positional arguments (one sweep, every case once) into "
                    "one file in case order")
      ->excludes(vary)
      ->excludes(set)
      ->excludes(out)
      ->excludes(shard)
      ->excludes(resume)
      ->excludes(threads)
      ->excludes(cadence)
      ->excludes(power)
      ->excludes(load)
      ->excludes(grid)
      ->excludes(drive)
      ->excludes(peak);
}

void add_inspect_command(CLI::App& app, InspectArgs& ins) {
  auto* inspect = app.add_subcommand(
      "inspect",
      "Assemble a scene and print, as JSON on standard output, what a newcomer needs while writing it: every "
      "joint coordinate and body pose at t = 0 (degrees and metres), the degrees of freedom (rank of the "
      "constraint Jacobian), each loop's closure gap, the range of the independent coordinate (full turn or its "
      "dead points, found by continuation) and warnings (also on standard error).");
  inspect->add_option("scene", ins.scene, "Scene name or YAML file")->required();
  inspect->add_option("--set", ins.sets, "Override a scalar of the scene: key.path=value (repeatable)");
  inspect->add_option("--svg", ins.svg,
                      "Also draw the assembled configuration as SVG into FILE: every joint (data-joint, data-x, "
                      "data-y in metres), body (data-body), ground pivot, loop, spring and point force; the range "
                      "and dead points noted");
  inspect->add_flag("--force", ins.force, kForceHelpFile);
}

void add_animate_command(CLI::App& app, AnimateArgs& an) {
  auto* animate = app.add_subcommand(
      "animate",
      "Simulate a scene (every joint's coordinate output) and write DIR/animation.html: one self-contained page "
      "(inline SVG, script and frames; no network) playing the mechanism with play/pause, a time slider, speed, "
      "the independent coordinate's value, arrows for the requested constraint forces and reactions, and traced "
      "points' paths. animation.html#t=T shows the pose at T (clamped to the run).");
  animate->add_option("scene", an.scene, "Scene name or YAML file")->required();
  animate->add_option("--model", an.model, "full (Simbody, default) or reduced (table at 10°, Eksergian's equation)")
      ->check(CLI::IsMember({"full", "reduced"}));
  animate->add_option_function<double>("--duration", [&an](const double& v) { an.duration = v; },
                                       "Time simulated [s] (default: the scene's)");
  animate->add_option_function<double>("--dt-out", [&an](const double& v) { an.dt_out = v; },
                                       "Output interval [s] (default: the scene's); at most 2000 frames are kept");
  animate->add_option("--trace", an.traces,
                      "BODY.POINT whose path is drawn (repeatable; default: the named points where loops close)");
  add_scene_overrides(*animate, an.sets);
  add_output_folder(*animate, an.out, an.force);
}

void add_export_mjcf_command(CLI::App& app, ExportMjcfArgs& mj) {
  auto* export_mjcf = app.add_subcommand(
      "export-mjcf",
      "Write the scene as MJCF (MuJoCo XML): bodies, hinges and slides, loops as connect equalities and gears as "
      "joint equalities, written at the assembled initial configuration; a comment lists the loads MJCF cannot "
      "express (rdyn's MuJoCo runner applies them at every step).");
  export_mjcf->add_option("scene", mj.scene, "Scene name or YAML file")->required();
  export_mjcf->add_option("--out", mj.out, "Output XML file (default: standard output)");
  export_mjcf->add_flag("--force", mj.force, kForceHelpFile);
  export_mjcf->add_option("--set", mj.sets, "Override a scalar of the scene: key.path=value (repeatable)");
  export_mjcf->add_flag("--fold", mj.fold, "Fold geared bodies into their drivers (as the full model does)");
  export_mjcf->add_option("--timestep", mj.timestep_s, "<option timestep> [s] (default 1e-3)");
  export_mjcf->add_option("--integrator", mj.integrator, "<option integrator>: Euler or RK4")
      ->check(CLI::IsMember({"Euler", "RK4"}));
}

void add_optimize_command(CLI::App& app, OptimizeArgs& opz) {
  auto* optimize = app.add_subcommand(
      "optimize",
      "Find the shape of drive loads (truncated Fourier series of a joint angle, the scene's `optimize` block) that "
      "minimises the peak (or p-norm) of a constraint force over the reduced steady cycle, the amplitude calibrated "
      "per shape to hold the mean cadence (with --power-w: the resistance dissipating P at F); NLopt COBYLA; both the "
      "constant strategy and the optimum confirmed with the full model. Writes DIR/summary.json, profile.csv, "
      "report.html.");
  optimize->add_option("scene", opz.scene, "Scene name or YAML file")->required();
  add_operating_point_options(*optimize, opz.cadence_hz, opz.cadence_given, opz.power_w, opz.power_given);
  optimize->add_option("--harmonics", opz.harmonics, "Harmonics H of each shape, 1..12 (default: the scene's, else 3)");
  optimize->add_option("--objective", opz.objective, "peak (default) or pnorm: (mean |F|^p)^(1/p) over the cycle")
      ->check(CLI::IsMember({"peak", "pnorm"}));
  optimize->add_option("--p", opz.p, "Exponent of pnorm, 2..64 (default 8)");
  optimize->add_option("--max-load", opz.max_load,
                       "Bound on |value·τ(θ)| of the scene's design loads [N·m or N] (default: the scene's optimize.max_load, "
                       "else 5× the constant strategy's value; loads added by --add-torque take --add-torque-max)");
  optimize->add_option_function<std::string>(
      "--force-name", [&opz](const std::string& v) { opz.force_name = v, opz.force_name_given = true; },
      "Constraint force to minimise (default: the scene's, else the first)");
  optimize->add_option("--add-torque", opz.add_torques,
                       "Add a profiled torque torque_<JOINT> on a revolute joint as a further design load (signed "
                       "shape; repeatable)");
  optimize->add_option("--add-torque-max", opz.add_torque_max, "Bound on |torque_<JOINT>| [N·m] (default 50)");
  optimize->add_option("--max-evaluations", opz.max_evaluations, "Optimiser evaluations, 1..100000 (default 400)");
  optimize->add_option("--rel-tolerance", opz.rel_tolerance, "Optimiser relative tolerance (default 1e-4)");
  add_reduced_table_options(*optimize, opz.grid_deg, opz.interpolation);
  optimize->get_option("--grid-deg")->each([&opz](const std::string&) { opz.grid_given = true; });
  optimize->add_option("--full-duration", opz.full_duration_s, "Each full-model confirmation run [s], 4..600 (default 20)");
  add_scene_overrides(*optimize, opz.sets);
  add_output_folder(*optimize, opz.out, opz.force);
}

void add_drive_command(CLI::App& app, DriveArgs& drv) {
  auto* drive = app.add_subcommand(
      "drive",
      "Prescribed motion: the independent coordinate follows a constant rate (--cadence-hz) or a profile q(t) "
      "(--profile t,q_deg or t,q_m CSV, natural cubic spline) with every other load of the scene applied, and each "
      "model says what the drive must supply. Writes DIR/timeseries.csv (t,q,qdot,qddot,drive_Nm or drive_N, "
      "drive_W, F_<name>...) and DIR/run.json (drive RMS, peak, mean, mean and peak power, constraint-force peaks).");
  drive->add_option("scene", drv.scene, "Scene name or YAML file")->required();
  // Typed values are kept apart from the defaults: the optional fields are set only when given.
  drive->add_option_function<double>("--cadence-hz", [&drv](const double& v) { drv.cadence_hz = v; },
                                     "Constant rate [rev/s] of a revolute coordinate (sign: direction)");
  drive->add_option("--profile", drv.profile, "CSV of t,q_deg (revolute) or t,q_m (prismatic) to follow");
  drive->add_option("--model", drv.model, "full (Simbody inverse dynamics, default) or reduced")
      ->check(CLI::IsMember({"full", "reduced"}));
  drive->add_option_function<double>("--duration", [&drv](const double& v) { drv.duration = v; },
                                     "Time [s] (default: one revolution, or the profile's span)");
  drive->add_option_function<double>("--dt-out", [&drv](const double& v) { drv.dt_out = v; },
                                     "Output interval [s] (default: the scene's)");
  drive->add_option("--motor", drv.motor,
                    "STALL,NO_LOAD: check that a motor on the independent coordinate with this torque-speed line "
                    "(N*m,rad/s; N,m/s on a slider) covers the drive at every angle; run.json gets motor_check");
  add_reduced_table_options(*drive, drv.grid_deg, drv.interpolation);
  drive->get_option("--grid-deg")->each([&drv](const std::string&) { drv.grid_given = true; });
  add_scene_overrides(*drive, drv.sets);
  add_output_folder(*drive, drv.out, drv.force);
}

void add_expand_command(CLI::App& app, ExpandArgs& exp) {
  auto* expand = app.add_subcommand(
      "expand",
      "Write the scene as rdyn reads it -- generators (bicycle_leg) expanded into bodies and joints, --set "
      "overrides applied, named points as coordinates, every default explicit, angles in radians -- as YAML that "
      "every command loads as the same scene (checked before writing: the text is read back and must give the "
      "same scene). Comments of the original are not kept.");
  expand->add_option("scene", exp.scene, "Scene name or YAML file")->required();
  expand->add_option("--set", exp.sets, "Override a scalar of the scene: key.path=value (repeatable)");
  expand->add_option("--out", exp.out, "Output YAML file (default: standard output)");
  expand->add_flag("--force", exp.force, kForceHelpFile);
}

// The first argument when it is neither an option nor a subcommand ("" otherwise), control
// characters shown as \xNN.
std::vector<const CLI::App*> subcommands(const CLI::App& app) {
  return app.get_subcommands([](const CLI::App*) { return true; });
}

// Text a user typed, shown with its control characters as \xNN (never written to the terminal).
std::string shown_text(const char* text) {
  std::string shown;
  for (const char* c = text; *c; ++c) {
    const auto b = static_cast<unsigned char>(*c);
    if (b < 0x20 || b == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", b);
      shown += hex;
    } else {
      shown += *c;
    }
  }
  return shown;
}

std::string unknown_subcommand(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return "";
  for (const CLI::App* sub : subcommands(app))
    if (sub->check_name(argv[1])) return "";
  return shown_text(argv[1]);
}

std::string subcommand_names(const CLI::App& app) {
  std::string names;
  for (const CLI::App* sub : subcommands(app))
    names += (names.empty() ? "" : ", ") + sub->get_name();
  return names;
}

// Every subcommand's arguments, filled while the command line is parsed.
struct CommandArgs {
  SimulateArgs sim;
  ExtractArgs ext;
  CalibrateArgs cal;
  ValidateArgs val;
  ReportArgs rep;
  SweepArgs sw;
  InspectArgs ins;
  ExportMjcfArgs mj;
  OptimizeArgs opz;
  DriveArgs drv;
  ExpandArgs exp;
  AnimateArgs an;
};

// Runs the one subcommand given; the errors a command reports become the exit status (README,
// "Exit status") with one line on standard error.
int run_command(const CLI::App& app, const CommandArgs& a) {
  try {
    if (app.got_subcommand("simulate")) return run_simulate(a.sim);
    if (app.got_subcommand("extract")) return run_extract(a.ext);
    if (app.got_subcommand("calibrate")) return run_calibrate(a.cal);
    if (app.got_subcommand("validate")) return run_validate(a.val);
    if (app.got_subcommand("sweep")) return run_sweep_command(a.sw);
    if (app.got_subcommand("report")) return run_report(a.rep);
    if (app.got_subcommand("inspect")) return run_inspect(a.ins);
    if (app.got_subcommand("export-mjcf")) return run_export_mjcf(a.mj);
    if (app.got_subcommand("optimize")) return run_optimize(a.opz);
    if (app.got_subcommand("drive")) return run_drive(a.drv);
    if (app.got_subcommand("expand")) return run_expand(a.exp);
    if (app.got_subcommand("animate")) return run_animate(a.an);
  } catch (const rdyn::models::SceneError& e) {
    std::fprintf(stderr, "rdyn: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const rdyn::engine::EngineError& e) {
    std::fprintf(stderr, "rdyn: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const rdyn::reduced::TableError& e) {
    std::fprintf(stderr, "rdyn: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const OutputError& e) {
    std::fprintf(stderr, "rdyn: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const ArgumentError& e) {
    std::fprintf(stderr, "rdyn: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const rdyn::models::NumericalError& e) {
    std::fprintf(stderr, "rdyn: numerical failure: %s\n", e.what());
    return kExitNumerical;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "rdyn: numerical failure: out of memory\n");
    return kExitNumerical;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rdyn: internal error: %s\n", e.what());
    return kExitNumerical;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rdyn — reduced-parameter models of one-degree-of-freedom planar mechanisms, validated against a "
      "full multibody model (Simbody).\n"
      "A SCENE is a shipped scene name (bicycle, bicycle-profile, bicycle-muscle, fourbar, fourbar-rocker, slider-crank, slider-crank-slider, crane-luffing) or a YAML file (see docs/scene-format.md)."};
  app.require_subcommand(1);
  CommandArgs a;
  add_simulate_command(app, a.sim);
  add_extract_command(app, a.ext);
  add_calibrate_command(app, a.cal);
  add_validate_command(app, a.val);
  add_report_command(app, a.rep);
  add_sweep_command(app, a.sw);
  add_inspect_command(app, a.ins);
  add_export_mjcf_command(app, a.mj);
  add_optimize_command(app, a.opz);
  add_drive_command(app, a.drv);
  add_expand_command(app, a.exp);
  add_animate_command(app, a.an);
  require_decimal_numbers(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // CLI11 reports a mistyped subcommand as a missing one: name it instead.
    if (const std::string typed = unknown_subcommand(app, argc, argv); !typed.empty()) {
      std::fprintf(stderr, "rdyn: error: unknown subcommand '%s' (%s); run with --help for more information\n",
                   typed.c_str(), subcommand_names(app).c_str());
      return kExitBadInput;
    }
    // With the prefix every other refusal has (CLI11 printed "--model: bogus not in {…}" bare).
    std::fprintf(stderr, "rdyn: error: %s\nRun with --help for more information.\n", shown_text(e.what()).c_str());
    return kExitBadInput;
  }
  return run_command(app, a);
}
