// rdyn._rdyn: the pybind11 layer under the `rdyn` Python package (python/rdyn/__init__.py).
// A thin adapter: every computation is the C++ library's (the same functions the CLI calls),
// every error is translated to the Python exception of the same name with the same fields.
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "engine/full_model.hpp"
#include "engine/inspect.hpp"
#include "models/scene_write.hpp"
#include "models/scene_yaml.hpp"
#include "reduced/runtime.hpp"
#include "reduced/samples.hpp"
#include "reduced/samples_fit.hpp"
#include "reduced/joint_outputs.hpp"
#include "validate/analysis/sweep.hpp"
#include "validate/analysis/table_check.hpp"
#include "validate/cli/commands.hpp"
#include "validate/cli/drive_command.hpp"
#include "validate/cli/inspect.hpp"
#include "validate/io/output_dir.hpp"
#include "validate/io/progress.hpp"

namespace py = pybind11;
namespace rm = rdyn::models;
namespace rr = rdyn::reduced;
namespace rv = rdyn::validate;

namespace {

constexpr double kPi = 3.14159265358979323846;  // as reduced/samples.cpp writes q_deg

py::array_t<double> to_array(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

// timeseries.csv's columns, in its order, refusing a non-finite value as the CSV writer does
// (validate/report/timeseries_csv.cpp): no NaN leaves rdyn.
py::list timeseries_columns(const rm::TimeSeries& ts) {
  py::list out;
  auto add = [&](const std::string& name, const std::vector<double>& v) {
    for (size_t i = 0; i < v.size(); ++i)
      if (!std::isfinite(v[i]))
        throw rm::NumericalError(fmt::format("the time series has a non-finite {} at t = {:.6g} s", name, ts.t[i]));
    out.append(py::make_tuple(name, to_array(v)));
  };
  add("t", ts.t);
  add("q", ts.q);
  add("qdot", ts.qdot);
  add("qddot", ts.qddot);
  add("energy", ts.energy);
  add("work", ts.work);
  for (size_t c = 0; c < ts.forces.size(); ++c) add("F_" + ts.force_names[c], ts.forces[c]);
  for (size_t c = 0; c < ts.columns.size(); ++c) add(ts.column_names[c], ts.columns[c]);
  return out;
}

// `rdyn drive`'s timeseries.csv columns, in its order (validate/cli/drive_command.hpp); every
// value was checked finite by the drive itself.
py::list drive_columns(const rv::DriveRun& d) {
  const auto& r = d.rows;
  std::vector<const std::vector<double>*> cols{&r.t, &r.q, &r.qdot, &r.qddot, &r.drive, &r.power};
  for (const auto& c : r.forces) cols.push_back(&c);
  for (const auto& c : r.columns) cols.push_back(&c);
  const auto names = rv::drive_column_names(r, d.revolute);
  py::list out;
  for (size_t c = 0; c < names.size(); ++c) {
    for (double v : *cols[c])
      if (!std::isfinite(v)) throw rm::NumericalError("the drive has a non-finite " + names[c]);
    out.append(py::make_tuple(names[c], to_array(*cols[c])));
  }
  return out;
}

// The table's columns as the CSV names them: q_deg (or q_m) first, then the named columns.
py::list table_columns(const rr::Samples& s) {
  py::list out;
  std::vector<double> q(s.q.size());
  for (size_t i = 0; i < q.size(); ++i) q[i] = s.revolute ? s.q[i] * 180.0 / kPi : s.q[i];
  out.append(py::make_tuple(s.revolute ? "q_deg" : "q_m", to_array(q)));
  for (size_t c = 0; c < s.names.size(); ++c) out.append(py::make_tuple(s.names[c], to_array(s.columns[c])));
  return out;
}

// The Python exception classes, created in PYBIND11_MODULE and kept for the module's life.
PyObject* g_rdyn_error = nullptr;
PyObject* g_scene_error = nullptr;
PyObject* g_numerical_error = nullptr;
PyObject* g_argument_error = nullptr;
PyObject* g_table_error = nullptr;
PyObject* g_output_error = nullptr;

void raise(PyObject* cls, const char* message) { PyErr_SetString(cls, message); }

// Runtime statuses: argument faults (1–4) are ArgumentError, the others NumericalError.
void raise_status(rr::Status s, const rr::RuntimeWorkspace& ws) {
  if (s == rr::Status::Ok) return;
  const int code = static_cast<int>(s);
  if (code <= 4) throw rv::ArgumentError(ws.describe(s));
  throw rm::NumericalError(ws.describe(s));
}

struct Runtime {
  rr::RuntimeModel model;
  rr::RuntimeWorkspace ws;
  Runtime(const rr::Samples& samples, const rm::Scene& scene, const rr::RuntimeOptions& opt)
      : model(rr::make_runtime_model(samples, scene, opt)), ws(model) {}
};

rr::Drive drive_of(const std::optional<double>& torque, const std::optional<double>& scale) {
  if (torque && scale) throw rv::ArgumentError("drive: give a torque or a scale, not both");
  if (torque) return rr::Drive::torque(*torque);
  if (scale) return rr::Drive::scaled(*scale);
  return rr::Drive::scaled(1.0);  // the scene's joint torques
}

}  // namespace

PYBIND11_MODULE(_rdyn, m) {
  m.doc() = "rdyn's C++ library (the rdyn package wraps it; use `import rdyn`).";
  // pybind11 finds numpy's C API in a function-local static on the first array made, importing
  // numpy there; an import lets other threads take the GIL, and a second thread that then made an
  // array waited for that static while holding the GIL the first one needed to finish it: two
  // threads' first calls hung forever. Made here, at import, while one thread runs.
  (void)py::array_t<double>(1);

  // Exceptions: rdyn.Error is the base; SceneError carries file, line and field.
  g_rdyn_error = PyErr_NewException("rdyn.Error", PyExc_RuntimeError, nullptr);
  g_scene_error = PyErr_NewException("rdyn.SceneError", g_rdyn_error, nullptr);
  g_numerical_error = PyErr_NewException("rdyn.NumericalError", g_rdyn_error, nullptr);
  {
    py::tuple bases = py::make_tuple(py::handle(g_rdyn_error), py::handle(PyExc_ValueError));
    g_argument_error = PyErr_NewExceptionWithDoc("rdyn.ArgumentError", "A bad argument (as the CLI's exit 2).",
                                                 bases.ptr(), nullptr);
  }
  g_table_error = PyErr_NewException("rdyn.TableError", g_rdyn_error, nullptr);
  g_output_error = PyErr_NewException("rdyn.OutputError", g_rdyn_error, nullptr);
  m.add_object("Error", py::handle(g_rdyn_error));
  m.add_object("SceneError", py::handle(g_scene_error));
  m.add_object("NumericalError", py::handle(g_numerical_error));
  m.add_object("ArgumentError", py::handle(g_argument_error));
  m.add_object("TableError", py::handle(g_table_error));
  m.add_object("OutputError", py::handle(g_output_error));
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const rm::SceneError& e) {
      py::object err = py::reinterpret_borrow<py::object>(g_scene_error)(e.what());
      err.attr("file") = e.file();
      err.attr("line") = e.line();
      err.attr("field") = e.field();
      PyErr_SetObject(g_scene_error, err.ptr());
    } catch (const rm::NumericalError& e) {
      raise(g_numerical_error, e.what());
    } catch (const rv::ArgumentError& e) {
      raise(g_argument_error, e.what());
    } catch (const rr::TableError& e) {
      raise(g_table_error, e.what());
    } catch (const rv::OutputError& e) {
      raise(g_output_error, e.what());
    } catch (const rdyn::engine::EngineError& e) {
      raise(g_rdyn_error, e.what());  // the CLI's exit 2 for a scene the engine cannot build
    }
  });

  py::class_<rm::Scene>(m, "Scene", "A scene as rdyn reads it (immutable).")
      .def_property_readonly("name", [](const rm::Scene& s) { return s.name; })
      .def_property_readonly("source_file", [](const rm::Scene& s) { return s.source_file; });
  m.def("load_scene", [](const std::string& name, const std::vector<std::string>& sets) {
    std::vector<rm::Override> ov;
    for (const auto& s : sets) ov.push_back(rm::parse_override(s));
    return rm::load_scene(name, ov);
  });
  m.def("scene_to_yaml", &rm::scene_to_yaml);
  m.def("inspect_json", [](const rm::Scene& scene) {
    const rdyn::engine::FullModel model(scene);
    return rv::inspection_json(scene, rdyn::engine::calc_inspection(model)).dump();
  });

  py::class_<rv::SimulateArgs>(m, "SimulateArgs", "rdyn simulate's options (docs/cli.md)")
      .def(py::init<>())
      .def_readwrite("model", &rv::SimulateArgs::model)
      .def_readwrite("duration", &rv::SimulateArgs::duration)
      .def_readwrite("dt_out", &rv::SimulateArgs::dt_out)
      .def_readwrite("tolerance", &rv::SimulateArgs::tolerance)
      .def_readwrite("integrator", &rv::SimulateArgs::integrator)
      .def_readwrite("route", &rv::SimulateArgs::route)
      .def_readwrite("table", &rv::SimulateArgs::table)
      .def_readwrite("grid_deg", &rv::SimulateArgs::grid_deg)
      .def_readwrite("grid_given", &rv::SimulateArgs::grid_given)
      .def_readwrite("method", &rv::SimulateArgs::method)
      .def_readwrite("interpolation", &rv::SimulateArgs::interpolation)
      .def_readwrite("energy_consistent", &rv::SimulateArgs::energy_consistent)
      .def_readwrite("reduced_integrator", &rv::SimulateArgs::reduced_integrator)
      .def_readwrite("reduced_tolerance", &rv::SimulateArgs::reduced_tolerance)
      .def_readwrite("fixed_step", &rv::SimulateArgs::fixed_step);
  m.def("simulate", [](const rm::Scene& scene, const rv::SimulateArgs& a, const rr::Samples* table) {
    rv::SimulateRun r;
    {
      py::gil_scoped_release free;  // a long run: other Python threads go on
      r = rv::simulate_scene(scene, a, table);
    }
    return py::make_tuple(timeseries_columns(r.ts), r.run.dump());
  }, py::arg("scene"), py::arg("args"), py::arg("table").none(true));

  py::class_<rr::Samples>(m, "Samples", "A reduced table (rdyn extract's CSV)")
      .def_property_readonly("scene", [](const rr::Samples& s) { return s.scene; })
      .def_property_readonly("method", [](const rr::Samples& s) { return s.method; })
      .def_property_readonly("periodic", [](const rr::Samples& s) { return s.periodic; })
      .def_property_readonly("file", [](const rr::Samples& s) { return s.file; });
  m.def("table_columns", &table_columns);
  m.def("extract", [](const rm::Scene& scene, double grid_deg, const std::string& method) {
    rv::Extraction e;
    {
      py::gil_scoped_release free;
      e = rv::extract_scene(scene, grid_deg, method);
    }
    return py::make_tuple(std::move(e.samples), e.calls, e.extraction_ms);
  });
  m.def("save_table", [](const rr::Samples& s, const std::string& path, bool force) {
    rv::OutputFile out(path, force, rv::is_rdyn_table_file);  // atomic, as rdyn extract --out
    out.write(rr::format_samples_csv(s));
    out.commit();
  });
  m.def("read_table", &rr::read_samples_csv);
  // A table file without a content checksum against a fresh extraction of its scene, as the CLI
  // checks it (validate/analysis/table_check.hpp): load_table runs it, so Runtime(path) does too.
  m.def("check_table", [](const rr::Samples& s, const rm::Scene& scene) {
    // The scene the table must come from, as simulate and the runtime build it (`reactions: all`
    // those the reduced model can give, their reaction lines): a table of another scene is refused
    // here, when it is loaded, not at its first use.
    const rm::Scene oscene = scene.outputs.reactions_all ? rr::split_reduced_reactions(scene).scene : scene;
    const rm::Scene rscene = rr::wants_joint_outputs(oscene) ? rr::with_reaction_requests(oscene) : oscene;
    rr::check_samples_fit(s, rscene);
    if (s.content_checked || s.file.empty()) return;
    py::gil_scoped_release free;
    rv::check_table_against_scene(s, rscene);
  });

  m.def("calibrate", [](const rm::Scene& scene, std::optional<double> cadence_hz, std::optional<double> power_w,
                        const std::string& load, std::optional<double> grid_deg, const std::string& interpolation) {
    rv::CalibrateArgs a;
    if (cadence_hz) a.cadence_hz = *cadence_hz, a.cadence_given = true;
    if (power_w) a.power_w = *power_w, a.power_given = true;
    a.load = load;
    if (grid_deg) a.grid_deg = *grid_deg, a.grid_given = true;  // else as the CLI without --grid-deg
    a.interpolation = interpolation;
    const rv::CalibrationOptions opt = rv::check_calibrate_args(scene, a);
    py::gil_scoped_release free;
    rdyn::validate::Progress quiet(false);
    const auto r = rv::calibrate(scene, opt, quiet);
    if (!r.unconfirmed.empty()) throw rm::NumericalError(r.unconfirmed);
    return rv::calibration_json(scene, opt, r).dump();
  });

  py::class_<rv::DriveArgs>(m, "DriveArgs", "rdyn drive's options (docs/cli.md)")
      .def(py::init<>())
      .def_readwrite("cadence_hz", &rv::DriveArgs::cadence_hz)
      .def_readwrite("profile", &rv::DriveArgs::profile)
      .def_readwrite("model", &rv::DriveArgs::model)
      .def_readwrite("duration", &rv::DriveArgs::duration)
      .def_readwrite("dt_out", &rv::DriveArgs::dt_out)
      .def_readwrite("grid_deg", &rv::DriveArgs::grid_deg)
      .def_readwrite("grid_given", &rv::DriveArgs::grid_given)
      .def_readwrite("interpolation", &rv::DriveArgs::interpolation)
      .def_readwrite("motor", &rv::DriveArgs::motor);
  m.def("drive", [](const rm::Scene& scene, const rv::DriveArgs& a, const rr::Samples* table) {
    rv::DriveRun r;
    {
      py::gil_scoped_release free;
      r = rv::drive_scene(scene, a, table);
    }
    return py::make_tuple(drive_columns(r), r.run.dump());
  }, py::arg("scene"), py::arg("args"), py::arg("table").none(true));

  m.def("validate", [](const rm::Scene& scene, const std::string& out, bool quick, bool force,
                       const std::vector<std::string>& peers) {
    rv::ValidateArgs a;
    a.out = out, a.quick = quick, a.force = force, a.peers = peers;
    py::gil_scoped_release free;
    rdyn::validate::Progress quiet(false);
    return rv::validate_scene(scene, a, quiet).dump();
  });

  // Sweeps: a plan (checked, as `rdyn sweep` checks it), then cases by index, each alone — so a
  // Python pool can map over the indices — or all in C++ threads (run_sweep, as the CLI).
  py::class_<rv::SweepPlan>(m, "SweepPlan", "A checked sweep (rdyn sweep)")
      .def_property_readonly("header", [](const rv::SweepPlan& p) { return p.header; })
      .def_property_readonly("cases", [](const rv::SweepPlan& p) { return p.id.total; });
  m.def("plan_sweep", [](const std::string& scene, const std::vector<std::string>& sets,
                         const std::vector<std::string>& vary, std::optional<double> cadence_hz,
                         std::optional<double> power_w, const std::string& load, std::optional<double> grid_deg,
                         std::optional<double> drive_cadence_hz, const std::vector<std::string>& peaks,
                         std::optional<int> threads) {
    rv::SweepArgs a;  // checked as `rdyn sweep` checks its options (ArgumentError names them)
    a.inputs = {scene}, a.sets = sets, a.vary = vary, a.cadence_hz = cadence_hz, a.power_w = power_w;
    a.load = load, a.drive_cadence_hz = drive_cadence_hz, a.threads = threads;
    if (grid_deg) a.grid_deg = *grid_deg, a.grid_given = true;
    a.peaks = peaks;
    return rv::plan_sweep(rv::check_sweep_args(a));
  });
  m.def("sweep_case", [](const rv::SweepPlan& plan, long index) {
    py::gil_scoped_release free;
    return rv::run_sweep_case(plan, index);
  });
  m.def("run_sweep", [](const rv::SweepPlan& plan) {
    py::gil_scoped_release free;
    return rv::run_sweep(plan, nullptr).csv;
  });

  py::class_<Runtime>(m, "Runtime")
      .def(py::init([](const rr::Samples& s, const rm::Scene& scene, std::optional<std::string> interpolation,
                       bool energy_consistent) {
             rr::RuntimeOptions opt;
             if (interpolation) opt.interpolation = rr::parse_interpolation(*interpolation);
             opt.energy_consistent_m2 = energy_consistent;
             return new Runtime(s, scene, opt);
           }),
           py::arg("samples"), py::arg("scene"), py::arg("interpolation").none(true), py::arg("energy_consistent"))
      .def("step",
           [](Runtime& r, double dt, std::optional<double> torque, std::optional<double> scale) {
             const rr::Drive d = drive_of(torque, scale);
             rr::Status s;
             {
               py::gil_scoped_release free;  // step is noexcept and allocation-free
               s = rr::step(r.model, r.ws, dt, d);
             }
             raise_status(s, r.ws);
           },
           py::arg("dt"), py::arg("torque").none(true) = py::none(), py::arg("scale").none(true) = py::none())
      .def("reset",
           [](Runtime& r, double q, double qdot, std::optional<double> torque, std::optional<double> scale) {
             raise_status(rr::reset(r.model, r.ws, q, qdot, drive_of(torque, scale)), r.ws);
           },
           py::arg("q"), py::arg("qdot"), py::arg("torque").none(true) = py::none(), py::arg("scale").none(true) = py::none())
      .def("drive_torque",
           [](Runtime& r, double q, double qdot, double qddot) {
             double d = 0.0;
             raise_status(rr::calc_drive_torque(r.model, r.ws, q, qdot, qddot, d), r.ws);
             return d;
           },
           py::arg("q"), py::arg("qdot"), py::arg("qddot"))
      .def_property_readonly("t", [](const Runtime& r) { return r.ws.get_t(); })
      .def_property_readonly("q", [](const Runtime& r) { return r.ws.get_q(); })
      .def_property_readonly("qdot", [](const Runtime& r) { return r.ws.get_qdot(); })
      .def_property_readonly("qddot", [](const Runtime& r) { return r.ws.get_qddot(); })
      .def_property_readonly("energy", [](const Runtime& r) { return r.ws.get_energy(); })
      .def_property_readonly("work", [](const Runtime& r) { return r.ws.get_work(); })
      .def_property_readonly("steps", [](const Runtime& r) { return r.ws.get_steps(); })
      .def_property_readonly("forces", [](const Runtime& r) { return to_array(r.ws.get_forces()); })
      .def_property_readonly("drive_torques", [](const Runtime& r) { return to_array(r.ws.get_drive_torques()); })
      .def_property_readonly("force_names", [](const Runtime& r) { return r.model.force_names; })
      // The scene's joint outputs at the current state (reactions, shaking, joint motion), named
      // as `rdyn simulate --model reduced` names its columns; empty when the scene asks for none.
      .def_property_readonly("joint_outputs", [](const Runtime& r) { return to_array(r.ws.get_joint_outputs()); })
      .def_property_readonly("joint_output_names",
                             [](const Runtime& r) {
                               return r.model.joint_outputs ? r.model.joint_outputs->names
                                                            : std::vector<std::string>();
                             })
      .def_property_readonly("drive_names", [](const Runtime& r) { return r.model.drive_names; })
      // The C++ cost of n steps at dt, timed inside C++ (no Python between steps) [s per step]:
      // the baseline a Python control loop's overhead is measured against.
      .def("time_cpp_steps", [](Runtime& r, double dt, long n, double torque) {
        py::gil_scoped_release free;
        const rr::Drive d = rr::Drive::torque(torque);
        const auto t0 = std::chrono::steady_clock::now();
        for (long i = 0; i < n; ++i)
          if (rr::step(r.model, r.ws, dt, d) != rr::Status::Ok) break;
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / static_cast<double>(n);
      });
}
