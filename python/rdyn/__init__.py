"""rdyn from Python: the reduced-parameter model of 1-DOF mechanisms and its full Simbody model.

A thin layer over rdyn's C++ library: the same functions the ``rdyn`` command runs, with the
same names, units (SI, radians) and errors. See docs/python.md.

    import rdyn
    scene = rdyn.load_scene("fourbar", overrides={"gravity.enabled": False})
    run = rdyn.simulate(scene, model="reduced", duration=1.0)
    run["qdot"]            # numpy array, timeseries.csv's column
    run.info               # run.json's content

Errors: ``rdyn.SceneError`` (attributes file, line, field), ``rdyn.NumericalError``,
``rdyn.ArgumentError`` (also a ValueError), ``rdyn.TableError``, ``rdyn.OutputError``; all
derive from ``rdyn.Error``.
"""
import builtins as _builtins
import csv as _csv
import io as _io
import json as _json
import os as _os
from collections.abc import Mapping as _Mapping

# An installed package finds the shipped scenes of its own prefix
# (P/lib/python3/dist-packages/rdyn → P/share/rdyn/scenes) unless RDYN_SCENES_DIR says otherwise.
_installed_scenes = _os.path.normpath(
    _os.path.join(_os.path.dirname(__file__), "..", "..", "..", "..", "share", "rdyn", "scenes"))
if "RDYN_SCENES_DIR" not in _os.environ and _os.path.isdir(_installed_scenes):
    _os.environ["RDYN_SCENES_DIR"] = _installed_scenes

from . import _rdyn
from ._rdyn import (Error, SceneError, NumericalError, ArgumentError, TableError,  # noqa: F401
                    OutputError)

__all__ = ["load_scene", "extract", "load_table", "simulate", "calibrate", "drive", "validate", "sweep",
           "Runtime",
           "Scene", "Table", "Run", "Error", "SceneError", "NumericalError", "ArgumentError",
           "TableError", "OutputError"]


def _real(value, name):
    """A number argument as float (None stays None: not given); True and False are refused
    (float(True) is 1.0: calibrate ran at 1 Hz when given cadence_hz=True)."""
    if value is None:
        return None
    if isinstance(value, bool):
        raise ArgumentError(f"{name}: expected a number (got {value!r})")
    return float(value)


def _override_text(path, value):
    # --set's syntax: PATH=VALUE, VALUE as YAML; Python's booleans are YAML's true/false.
    if isinstance(value, bool):
        value = "true" if value else "false"
    return f"{path}={value}"


class _Columns(_Mapping):
    """A read-only mapping column name → numpy array, in the file's column order."""

    def __init__(self, columns):
        self._columns = dict(columns)

    def __getitem__(self, name):
        return self._columns[name]

    def __iter__(self):
        return iter(self._columns)

    def __len__(self):
        return len(self._columns)

    def to_pandas(self):
        """The columns as a pandas DataFrame (needs pandas)."""
        import pandas
        return pandas.DataFrame(self._columns)


class Scene:
    """A loaded scene (``rdyn.load_scene``); immutable."""

    def __init__(self, name_or_path, sets, scene):
        self.name_or_path = name_or_path
        self.sets = list(sets)  # the overrides as --set texts, for the CLI-backed functions
        self._scene = scene

    @property
    def name(self):
        return self._scene.name

    @property
    def source_file(self):
        return self._scene.source_file

    def to_yaml(self):
        """The scene as rdyn reads it (``rdyn expand``'s YAML)."""
        return _rdyn.scene_to_yaml(self._scene)

    def inspect(self):
        """``rdyn inspect``'s JSON as a dict: assembly, DOF, loop gaps, range (degrees, metres)."""
        return _json.loads(_rdyn.inspect_json(self._scene))

    def __repr__(self):
        return f"rdyn.Scene({self.name!r}, file={self.source_file!r})"


def load_scene(name_or_path, overrides=None):
    """Loads a shipped scene by name or a YAML file; ``overrides`` maps a scene path to a value
    (``rdyn --set PATH=VALUE``). Raises SceneError (file, line, field)."""
    sets = [_override_text(k, v) for k, v in (overrides or {}).items()]
    return Scene(name_or_path, sets, _rdyn.load_scene(str(name_or_path), sets))


def _as_scene(scene, who):
    """A Scene, or a scene name or path (read with load_scene); anything else is a TypeError that
    says what to give (``extract("fourbar")`` raised AttributeError from inside)."""
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, (str, _os.PathLike)):
        return load_scene(scene)
    raise TypeError(f"{who}: scene must be an rdyn.Scene (rdyn.load_scene) or a scene name or path, "
                    f"not {type(scene).__name__}")


class Table(_Columns):
    """A reduced table (``rdyn extract``): mapping column → numpy array, q_deg (or q_m) first."""

    def __init__(self, samples, scene, calls=None, extraction_ms=None):
        super().__init__(_rdyn.table_columns(samples))
        self._samples = samples
        self.scene = scene
        self.kinetostatic_calls = calls
        self.extraction_ms = extraction_ms

    def save(self, path, force=False):
        """Writes the table as ``rdyn extract --out`` does (atomically; replacing a file rdyn did
        not write needs force=True)."""
        _rdyn.save_table(self._samples, _os.fspath(path), force)


def extract(scene, grid_deg=10, method="kinetostatic"):
    """``rdyn extract``: the reduced table of a scene on a grid of ``grid_deg`` degrees."""
    scene = _as_scene(scene, "extract")
    samples, calls, ms = _rdyn.extract(scene._scene, _real(grid_deg, "grid_deg"), method)
    return Table(samples, scene, calls, ms)


def load_table(path, scene):
    """Reads a table written by ``rdyn extract`` (or Table.save) for ``scene``. Raises
    TableError (file, line and field in the message), also when the table was extracted from
    another scene (or for other outputs); a table without a content checksum (written before rdyn
    recorded one, or edited) is compared here with a fresh extraction of ``scene``."""
    scene = _as_scene(scene, "load_table")
    samples = _rdyn.read_table(_os.fspath(path))
    _rdyn.check_table(samples, scene._scene)
    return Table(samples, scene)


def _as_table(table, scene, who):
    """A Table, a path read for ``scene`` (load_table), or None; a TypeError naming ``who``."""
    if table is None or isinstance(table, Table):
        return table
    if isinstance(table, (str, bytes, _os.PathLike)):
        return load_table(table, scene)
    raise TypeError(f"{who}: table must be an rdyn.Table (rdyn.extract, rdyn.load_table) or a path, "
                    f"not {type(table).__name__}")


class Run(_Columns):
    """A simulated motion: mapping column → numpy array (timeseries.csv's columns);
    ``info`` is run.json's content."""

    def __init__(self, columns, info):
        super().__init__(columns)
        self.info = info


def simulate(scene, model="reduced", duration=None, table=None, **options):
    """``rdyn simulate``: ``model`` "reduced" or "full"; ``duration`` [s] (None: the scene's);
    ``table`` a Table (None: extract now); options as the CLI's long options with
    underscores: dt_out, tolerance, integrator, route, grid_deg, method, interpolation,
    energy_consistent, reduced_integrator, reduced_tolerance, fixed_step."""
    scene = _as_scene(scene, "simulate")
    if model not in ("reduced", "full"):
        raise ArgumentError(f"model: must be reduced or full (got {model!r})")
    args = _rdyn.SimulateArgs()
    args.model = model
    if duration is not None:
        args.duration = _real(duration, "duration")
    if options.get("grid_deg", 0) is None:  # None: the default grid, refined as in drive()
        del options["grid_deg"]
    for key, value in options.items():
        if key in ("model", "duration", "table") or not hasattr(args, key):
            raise TypeError(f"simulate() got an unknown option {key!r}")
        if key in ("dt_out", "tolerance", "grid_deg", "reduced_tolerance", "fixed_step"):
            value = _real(value, key)  # a bool is no number (grid_deg=True ran on a 1° grid)
        setattr(args, key, value)
    args.grid_given = "grid_deg" in options  # else refined where 10° does not resolve the mechanism
    table = _as_table(table, scene, "simulate")
    columns, info = _rdyn.simulate(scene._scene, args, None if table is None else table._samples)
    return Run(columns, _json.loads(info))


def calibrate(scene, cadence_hz=None, power_w=None, load=None, grid_deg=None, interpolation="fourier"):
    """``rdyn calibrate``: the drive (or ``load``) for a mean cadence [Hz] and, optionally, a
    mean power [W]; returns the CLI's JSON as a dict (e.g. "drive_torque_Nm"). ``grid_deg``
    None: the scene's validation.calibrate.grid_deg, else 10° halved while it does not resolve
    the mechanism (the JSON's "grid_deg" is the grid used)."""
    scene = _as_scene(scene, "calibrate")
    return _json.loads(_rdyn.calibrate(scene._scene, _real(cadence_hz, "cadence_hz"), _real(power_w, "power_w"),
                                       load or "", _real(grid_deg, "grid_deg"), interpolation))


def drive(scene, cadence_hz=None, profile=None, model="reduced", duration=None, table=None, dt_out=None,
          grid_deg=None, interpolation="fourier", motor=None):
    """``rdyn drive``: the independent coordinate follows a constant rate ``cadence_hz`` [rev/s]
    or a ``profile`` (a CSV t,q_deg or t,q_m), every other load of the scene applied; returns a
    Run whose columns are timeseries.csv's (t, q, qdot, qddot, drive_Nm or drive_N, drive_W,
    F_<force>…) and whose ``info`` is run.json (drive_rms, drive_peak, mean_power_W, …).
    ``model`` "reduced" or "full"; ``table`` a Table for the reduced model (None: extract at
    ``grid_deg``, None: 10°, halved while it does not resolve the mechanism); ``motor`` (stall, no_load_speed)
    checks a torque–speed line (info["motor_check"])."""
    scene = _as_scene(scene, "drive")
    if model not in ("reduced", "full"):
        raise ArgumentError(f"model: must be reduced or full (got {model!r})")
    args = _rdyn.DriveArgs()
    args.model = model
    if cadence_hz is not None:
        args.cadence_hz = _real(cadence_hz, "cadence_hz")
    if profile is not None:
        args.profile = _os.fspath(profile)
    if duration is not None:
        args.duration = _real(duration, "duration")
    if dt_out is not None:
        args.dt_out = _real(dt_out, "dt_out")
    if grid_deg is not None:  # None: 10°, refined where it does not resolve the mechanism (as the CLI)
        args.grid_deg = _real(grid_deg, "grid_deg")
        args.grid_given = True
    args.interpolation = interpolation
    if motor is not None:
        args.motor = motor if isinstance(motor, str) else ",".join(repr(float(v)) for v in motor)
    table = _as_table(table, scene, "drive")
    columns, info = _rdyn.drive(scene._scene, args, None if table is None else table._samples)
    return Run(columns, _json.loads(info))


def validate(scene, out, quick=False, force=False, peers=()):
    """``rdyn validate SCENE --out DIR``: runs the validation, writes the report into ``out``
    (atomically; a folder holding files rdyn did not write needs force=True) and returns
    summary.json's content as a dict. ``summary["status"]`` is "pass" or "fail" (the CLI's exit
    0 or 1; the report is written either way)."""
    scene = _as_scene(scene, "validate")
    return _json.loads(_rdyn.validate(scene._scene, _os.fspath(out), bool(quick), bool(force), list(peers)))


def _axis_text(key, spec):
    # --vary's syntax: key=a:b:n; a (a, b, n) tuple is written with repr's round-trip digits.
    if isinstance(spec, str):
        return f"{key}={spec}"
    a, b, n = spec
    return f"{key}={float(a)!r}:{float(b)!r}:{int(n)}"


def _sweep_values(header, values):
    # One CSV row of `rdyn sweep` as a dict: case an int, status and error strings, every other
    # field a float (None where the CSV leaves it empty).
    out = {}
    for name, value in zip(header, values):
        if name == "case":
            out[name] = int(value)
        elif name in ("status", "error"):
            out[name] = value
        else:
            out[name] = float(value) if value != "" else None
    return out


def _csv_rows(text):
    # RFC 4180 rows (an error message may hold commas, quotes or line breaks).
    return list(_csv.reader(_io.StringIO(text)))


_plans = {}  # a worker's plans by their definition: a process pool's worker plans each sweep once


def _plan(spec):
    if spec not in _plans:
        scene, sets, vary, cadence_hz, power_w, load, grid_deg, drive_cadence_hz, peaks = spec
        _plans[spec] = _rdyn.plan_sweep(scene, list(sets), list(vary), cadence_hz, power_w, load, grid_deg,
                                        drive_cadence_hz, list(peaks), None)
    return _plans[spec]


def sweep_case(case):
    """One case of a sweep, ``case`` = (spec, index) as ``sweep`` hands it to ``map``: the row
    (a CSV line of ``rdyn sweep``) of that case. A module-level function of small, picklable
    arguments, so any executor's map (threads, processes, a dask client) can run it."""
    spec, index = case
    return _rdyn.sweep_case(_plan(spec), int(index))


def sweep(scene, vary, map=None, cadence_hz=None, power_w=None, load=None, grid_deg=None, drive_cadence_hz=None,
          threads=None, peaks=()):
    """``rdyn sweep``: every combination of the ``vary`` axes ({scene key: (a, b, n)} or
    {key: "a:b:n"}), each case calibrated on the reduced model (or, with ``drive_cadence_hz``,
    driven at that constant rate for one revolution). Returns one dict per case in case order
    with the CLI CSV's columns (case, the varied keys, status, …, error); ``peaks``: output
    columns whose peak over the case's steady cycle (revolution) each row adds as
    ``peak_<column>`` (``rdyn sweep --peak``).

    ``map``: any executor's map (``ThreadPoolExecutor().map``, ``ProcessPoolExecutor().map``,
    a dask client's map followed by gather, …) over the cases; the work item is a small tuple
    and the worker ``rdyn.sweep_case``. None: the C++ sweep in ``threads`` threads (None: the
    hardware's), reusing a thread's table between cases as the CLI does."""
    scene = _as_scene(scene, "sweep")
    if isinstance(peaks, str):  # one column name, not its characters
        peaks = (peaks,)
    spec = (scene.name_or_path if isinstance(scene.name_or_path, str) else _os.fspath(scene.name_or_path),
            tuple(scene.sets), tuple(_axis_text(k, v) for k, v in vary.items()),
            _real(cadence_hz, "cadence_hz"),
            _real(power_w, "power_w"),
            load or "", _real(grid_deg, "grid_deg"),
            _real(drive_cadence_hz, "drive_cadence_hz"),
            tuple(peaks))
    plan = _plan(spec)  # checked here, before any case runs: bad input raises at once
    header = _csv_rows(plan.header)[0]
    if map is None:
        if threads is not None:
            plan = _rdyn.plan_sweep(*spec, int(threads))
        text = _rdyn.run_sweep(plan)
        rows = _csv_rows(text[text.index("\n") + 1:])[1:]  # after the metadata line and the header
    else:
        rows = [_csv_rows(row)[0] for row in map(sweep_case, [(spec, i) for i in range(plan.cases)])]
    return [_sweep_values(header, r) for r in rows]


class Runtime:
    """The embedding runtime (docs/embedding.md): a fixed-step RK4 reduced model, allocation-free
    and releasing the GIL while it steps.

        rt = rdyn.Runtime(table, scene)
        rt.step(1e-3, drive=69.7)     # hip torque magnitude [N·m] (scene signs); None: scene's
        rt.q, rt.qdot, rt.forces
    """

    def __init__(self, table, scene=None, interpolation=None, energy_consistent=False):
        # A path is read for its scene (load_table); anything else but a Table is a TypeError
        # that says what to give, not an AttributeError from inside.
        if scene is not None:
            scene = _as_scene(scene, "Runtime")
        if isinstance(table, (str, bytes, _os.PathLike)) and scene is None:
            raise TypeError("Runtime(path, scene): a table file needs the scene it was extracted from")
        if table is None:
            raise TypeError("Runtime: table must be an rdyn.Table (rdyn.extract, rdyn.load_table) or a path, not None")
        table = _as_table(table, scene, "Runtime")
        scene = table.scene if scene is None else scene
        self._rt = _rdyn.Runtime(table._samples, scene._scene, interpolation, energy_consistent)
        self.step_raw = self._rt.step  # (dt, torque=None, scale=None): the call without this wrapper

    def step(self, dt, drive=None, scale=None):
        """One step of ``dt`` [s]; ``drive`` sets every scene joint torque to that magnitude
        (scene signs), ``scale`` scales them; neither: the scene's torques. Raises
        ArgumentError (bad dt or drive) or NumericalError; the state is then unchanged."""
        self._rt.step(dt, drive, scale)

    def reset(self, q, qdot, drive=None, scale=None):
        """Sets t = 0 and the state (q [rad or m], qdot)."""
        self._rt.reset(q, qdot, drive, scale)

    t = property(lambda self: self._rt.t, doc="time since the last reset [s]")
    q = property(lambda self: self._rt.q, doc="independent coordinate [rad or m]")
    qdot = property(lambda self: self._rt.qdot, doc="its rate [rad/s or m/s]")
    qddot = property(lambda self: self._rt.qddot, doc="its acceleration [rad/s² or m/s²]")

    def drive_torque(self, q, qdot, qddot):
        """The inverse of step: the generalized force [N·m or N] a drive on q must add for the
        reduced model to move with (q, qdot, qddot) — m1 q̈ + m2 q̇² − F*, every scene load in F*
        with the joint torques as last commanded — as ``rdyn drive --model reduced`` gives per
        row. Raises ArgumentError for a state out of range; the state is not changed."""
        return self._rt.drive_torque(q, qdot, qddot)
    energy = property(lambda self: self._rt.energy, doc="kinetic + potential energy [J]")
    work = property(lambda self: self._rt.work, doc="work of the non-conservative loads [J]")
    forces = property(lambda self: self._rt.forces, doc="constraint forces [N] (force_names order)")
    force_names = property(lambda self: self._rt.force_names)
    joint_outputs = property(lambda self: self._rt.joint_outputs,
                             doc="the scene's joint outputs at the current state: reactions [N], shaking "
                                 "load, joint motion (joint_output_names order; empty when it asks for none)")
    joint_output_names = property(lambda self: self._rt.joint_output_names,
                                  doc="their names, as rdyn simulate --model reduced names its columns")

    def joint_output_dict(self):
        """The joint outputs at the current state as {name: value}."""
        return dict(zip(self._rt.joint_output_names, self._rt.joint_outputs.tolist()))
    drive_names = property(lambda self: self._rt.drive_names)
    drive_torques = property(lambda self: self._rt.drive_torques)
