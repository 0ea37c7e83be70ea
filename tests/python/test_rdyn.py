"""The Python module against the CLI on the same scenes (the same C++ code path, so the values
agree bit for bit where both write them at full precision), and its errors with their fields."""
import json
import os
import threading
import time

import numpy as np
import pytest

import rdyn
from conftest import read_csv, read_json


def test_simulate_reduced_matches_cli(rdyn_cli, tmp_path):
    scene = rdyn.load_scene("fourbar")
    run = rdyn.simulate(scene, model="reduced", duration=1.0)
    rdyn_cli("simulate", "fourbar", "--model", "reduced", "--duration", "1", "--out", str(tmp_path / "cli"))
    cli = read_csv(tmp_path / "cli" / "timeseries.csv")
    assert list(run.keys()) == list(cli.keys())
    assert len(run["qdot"]) == len(cli["qdot"]) > 10
    # The CSV holds %.17g: the round trip is exact, so the same code path agrees bit for bit.
    np.testing.assert_allclose(run["qdot"], cli["qdot"], rtol=0, atol=1e-12)
    assert np.array_equal(run["q"], np.array(cli["q"]))
    info = read_json(tmp_path / "cli" / "run.json")
    for key in ("scene", "model", "duration_s", "kinetostatic_calls", "steps_taken", "energy_balance_residual_J"):
        assert run.info[key] == info[key], key


def test_simulate_full_matches_cli(rdyn_cli, tmp_path):
    scene = rdyn.load_scene("fourbar", overrides={"gravity.enabled": False})
    run = rdyn.simulate(scene, model="full", duration=0.2)
    rdyn_cli("simulate", "fourbar", "--set", "gravity.enabled=false", "--model", "full", "--duration", "0.2",
             "--out", str(tmp_path / "cli"))
    cli = read_csv(tmp_path / "cli" / "timeseries.csv")
    assert np.array_equal(run["qdot"], np.array(cli["qdot"]))
    assert run.info["steps_taken"] == read_json(tmp_path / "cli" / "run.json")["steps_taken"]


def test_extract_table_and_round_trip(rdyn_cli, tmp_path):
    scene = rdyn.load_scene("fourbar")
    table = rdyn.extract(scene, grid_deg=10)
    rdyn_cli("extract", "fourbar", "--grid-deg", "10", "--out", str(tmp_path / "cli.csv"))
    cli = read_csv(tmp_path / "cli.csv")
    assert list(table.keys()) == list(cli.keys())
    assert len(table["m1"]) == len(cli["m1"]) == 36
    for name in cli:
        assert np.array_equal(table[name], np.array(cli[name])), name
    # Saved from Python: the same bytes as the CLI's file; read back: the same columns.
    table.save(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    back = rdyn.load_table(tmp_path / "cli.csv", scene)
    assert np.array_equal(back["m2"], table["m2"])
    # Another scene's table is refused when loaded, not at its first use.
    with pytest.raises(rdyn.TableError, match="different scene"):
        rdyn.load_table(tmp_path / "cli.csv", rdyn.load_scene("slider-crank"))
    # A table given to simulate: the same run as extracting there.
    a = rdyn.simulate(scene, model="reduced", duration=0.5, table=back)
    b = rdyn.simulate(scene, model="reduced", duration=0.5)
    assert np.array_equal(a["q"], b["q"])
    assert a.info["table"] == str(tmp_path / "cli.csv")


def test_save_refuses_a_foreign_file(tmp_path):
    table = rdyn.extract(rdyn.load_scene("fourbar"), grid_deg=30)
    (tmp_path / "mine.csv").write_text("not rdyn's\n")
    with pytest.raises(rdyn.OutputError):
        table.save(tmp_path / "mine.csv")
    assert (tmp_path / "mine.csv").read_text() == "not rdyn's\n"
    table.save(tmp_path / "mine.csv", force=True)
    assert (tmp_path / "mine.csv").read_text().startswith("# rdyn-table")


def test_calibrate_matches_cli(rdyn_cli):
    r = rdyn.calibrate(rdyn.load_scene("bicycle"), cadence_hz=1, power_w=125)
    cli = json.loads(rdyn_cli("calibrate", "bicycle", "--cadence-hz", "1", "--power-w", "125").stdout)
    assert abs(r["drive_torque_Nm"] - cli["drive_torque_Nm"]) <= 1e-9
    assert set(r) == set(cli)
    assert abs(r["mean_power_w"] - 125) < 0.01 * 125  # and it does what it says


def test_scene_yaml_and_inspect_match_cli(rdyn_cli):
    scene = rdyn.load_scene("fourbar")
    assert scene.to_yaml() == rdyn_cli("expand", "fourbar").stdout
    assert scene.inspect() == json.loads(rdyn_cli("inspect", "fourbar").stdout)


def test_scene_error_fields(tmp_path):
    bad = tmp_path / "bad.yaml"
    text = open(os.path.join(os.environ["RDYN_SCENES_SRC"], "fourbar.yaml")).read()
    bad.write_text(text.replace("initial: {q_deg: 30,", "initial: {bogus_field: 3, q_deg: 30,", 1))
    with pytest.raises(rdyn.SceneError) as e:
        rdyn.load_scene(bad)
    assert e.value.file == str(bad)
    assert e.value.line > 0
    assert "bogus_field" in e.value.field or "bogus_field" in str(e.value)
    with pytest.raises(rdyn.SceneError) as e:
        rdyn.load_scene("no-such-scene")
    assert e.value.line == 0
    with pytest.raises(rdyn.SceneError) as e:
        rdyn.load_scene("fourbar", overrides={"gravity.enabled": "maybe"})
    assert "gravity.enabled" in e.value.field


def test_argument_errors_name_the_option():
    scene = rdyn.load_scene("fourbar")
    with pytest.raises(rdyn.ArgumentError, match="--grid-deg"):
        rdyn.extract(scene, grid_deg=7)
    with pytest.raises(rdyn.ArgumentError, match="--duration"):
        rdyn.simulate(scene, duration=-1)
    with pytest.raises(ValueError):  # ArgumentError is a ValueError
        rdyn.calibrate(scene, cadence_hz=-1)
    with pytest.raises(TypeError):
        rdyn.simulate(scene, duration=1, no_such_option=3)
    # A bool is not a number here (float(True) is 1: calibrate ran at 1 Hz for cadence_hz=True).
    with pytest.raises(rdyn.ArgumentError, match="cadence_hz"):
        rdyn.calibrate(rdyn.load_scene("bicycle"), cadence_hz=True)
    with pytest.raises(rdyn.ArgumentError, match="duration"):
        rdyn.simulate(scene, duration=False)
    with pytest.raises(rdyn.ArgumentError, match="grid_deg"):  # it ran on a 1° grid
        rdyn.simulate(scene, duration=1, grid_deg=True)


def test_table_error():
    with pytest.raises(rdyn.TableError):
        rdyn.load_table(os.path.join(os.environ["RDYN_SCENES_SRC"], "fourbar.yaml"), rdyn.load_scene("fourbar"))


def runtime_for(scene_name, grid_deg=10):
    scene = rdyn.load_scene(scene_name)
    return rdyn.Runtime(rdyn.extract(scene, grid_deg=grid_deg), scene)


def test_runtime_matches_fixed_step_simulate():
    # The runtime's step is simulate's rk4-fixed: the same states at the output times.
    scene = rdyn.load_scene("fourbar")
    table = rdyn.extract(scene, grid_deg=10)
    run = rdyn.simulate(scene, model="reduced", duration=0.1, table=table, reduced_integrator="rk4-fixed",
                        fixed_step=1e-3, dt_out=0.01, interpolation="fourier")
    rt = rdyn.Runtime(table, scene)
    qs = []
    for i in range(100):
        rt.step(1e-3)
        if (i + 1) % 10 == 0:
            qs.append(rt.q)
    np.testing.assert_allclose(qs, run["q"][1:], rtol=0, atol=1e-12)


def test_runtime_joint_outputs_are_the_reduced_runs_rows():
    # A scene that asks for reactions and the shaking load: the runtime takes the table extract
    # gives it, and reset to a row's state gives that row's joint outputs (runtime_test.cpp
    # checks them against closed forms).
    scene = rdyn.load_scene("slider-crank", {"outputs.reactions": "all", "outputs.shaking": "true"})
    table = rdyn.extract(scene, grid_deg=10)
    run = rdyn.simulate(scene, model="reduced", duration=0.05, table=table, interpolation="fourier")
    rt = rdyn.Runtime(table, scene)
    assert rt.force_names == ["rod_axial"]
    assert rt.joint_output_names[:2] == ["R_crank_x", "R_crank_y"] and rt.joint_output_names[-1] == "shaking_M"
    for i in (0, len(run["t"]) // 2, len(run["t"]) - 1):
        rt.reset(run["q"][i], run["qdot"][i])
        values = rt.joint_output_dict()
        assert list(values) == rt.joint_output_names
        for name, v in values.items():
            assert v == pytest.approx(run[name][i], rel=1e-9, abs=1e-9 * np.max(np.abs(run[name]))), name
    assert runtime_for("fourbar", 30).joint_output_names == []


def test_runtime_errors_leave_the_state():
    rt = runtime_for("fourbar", 30)
    q0, qdot0 = rt.q, rt.qdot
    with pytest.raises(rdyn.ArgumentError):
        rt.step(10.0)  # dt beyond 1 s
    with pytest.raises(rdyn.ArgumentError, match="not finite"):  # its own cause, not the others'
        rt.step(1e-3, drive=float("nan"))
    assert (rt.q, rt.qdot) == (q0, qdot0)


def test_runtime_refuses_a_drive_it_cannot_apply_and_wrong_types(tmp_path):
    # fourbar has no joint torque: a commanded drive was ignored in silence (the controller ran
    # open loop); the scene's own drive (none given) still steps.
    rt = runtime_for("fourbar", 30)
    with pytest.raises(rdyn.ArgumentError, match="no joint torque"):
        rt.step(1e-3, drive=5.0)
    with pytest.raises(rdyn.ArgumentError, match="no joint torque"):
        rt.step(1e-3, scale=2.0)
    q0 = rt.q
    rt.step(1e-3)
    assert rt.q != q0
    # A path is read for its scene; a path without one, or another type, is a TypeError.
    scene = rdyn.load_scene("fourbar")
    rdyn.extract(scene, grid_deg=30).save(tmp_path / "t.csv")
    assert rdyn.Runtime(str(tmp_path / "t.csv"), scene).q == pytest.approx(rdyn.Runtime(tmp_path / "t.csv", scene).q)
    with pytest.raises(TypeError, match="needs the scene"):
        rdyn.Runtime(str(tmp_path / "t.csv"))
    with pytest.raises(TypeError, match="must be an rdyn.Table"):
        rdyn.Runtime(42, scene)
    # A scene name stands for its scene everywhere (extract("fourbar") raised AttributeError).
    assert rdyn.Runtime(tmp_path / "t.csv", "fourbar").q == pytest.approx(rdyn.Runtime(tmp_path / "t.csv", scene).q)
    assert rdyn.extract("fourbar", grid_deg=30)["m1"].size == rdyn.extract(scene, grid_deg=30)["m1"].size
    with pytest.raises(TypeError, match="must be an rdyn.Scene"):
        rdyn.Runtime(tmp_path / "t.csv", 42)
    with pytest.raises(TypeError, match="extract: scene must be an rdyn.Scene"):
        rdyn.extract(None)
    # The same for simulate and drive; one peak column by name is one column.
    with pytest.raises(TypeError, match="simulate: table must be an rdyn.Table"):
        rdyn.simulate(scene, table=5)
    assert rdyn.simulate(scene, table=tmp_path / "t.csv", duration=0.1)["q"].size > 0
    # A table without its checksum is compared with a fresh extraction when loaded (as the CLI
    # does): an edited value is refused, by load_table and so by Runtime(path).
    text = (tmp_path / "t.csv").read_text()
    first, rest = text.split("\n", 1)
    unchecked = first.split(" content=")[0] + "\n" + rest
    (tmp_path / "u.csv").write_text(unchecked)
    assert rdyn.Runtime(tmp_path / "u.csv", scene).q == pytest.approx(rdyn.Runtime(tmp_path / "t.csv", scene).q)
    header_end = unchecked.index("q_deg,")
    row = unchecked.index("\n", header_end) + 1
    cells = unchecked[row:unchecked.index("\n", row)].split(",")
    cells[1] = repr(float(cells[1]) * 1.01)
    edited = unchecked[:row] + ",".join(cells) + unchecked[unchecked.index("\n", row):]
    (tmp_path / "e.csv").write_text(edited)
    with pytest.raises(rdyn.TableError, match="the scene gives"):
        rdyn.Runtime(tmp_path / "e.csv", scene)


def test_control_loop_1khz_bicycle():
    # A PD controller holds the reduced bicycle at 1 Hz, 1 kHz from Python (docs/embedding.md).
    rt = runtime_for("bicycle")
    target = 2 * np.pi
    for _ in range(20000):
        hip = 69.7 + 400 * (target - rt.qdot) - 20 * rt.qddot
        rt.step(1e-3, drive=min(max(hip, 0.0), 500.0))
    qdots = []
    for _ in range(5000):
        hip = 69.7 + 400 * (target - rt.qdot) - 20 * rt.qddot
        rt.step(1e-3, drive=min(max(hip, 0.0), 500.0))
        qdots.append(rt.qdot)
    assert abs(np.mean(qdots) - target) < 0.01 * target
    assert len(rt.forces) == len(rt.force_names)


def test_step_releases_the_gil():
    # Another Python thread makes progress while one thread steps: with the GIL held through
    # the C++ call it could only run between steps. Counted, not timed.
    rt = runtime_for("fourbar", 30)
    counter = {"n": 0, "stop": False}

    def count():
        while not counter["stop"]:
            counter["n"] += 1
    th = threading.Thread(target=count)
    th.start()
    rt._rt.time_cpp_steps(1e-4, 200000, 0.0)  # one long C++ call without the GIL
    counter["stop"] = True
    th.join()
    assert counter["n"] > 0


def test_run_to_pandas():
    pandas = pytest.importorskip("pandas")
    run = rdyn.simulate(rdyn.load_scene("fourbar"), duration=0.2)
    df = run.to_pandas()
    assert isinstance(df, pandas.DataFrame) and list(df.columns) == list(run.keys())


def read_sweep_csv(path):
    """`rdyn sweep`'s CSV as the module returns it: one dict per row, after the metadata line."""
    import csv
    with open(path, newline="") as f:
        rows = list(csv.reader(f))[1:]
    header = rows[0]
    out = []
    for r in rows[1:]:
        d = {}
        for name, value in zip(header, r):
            if name == "case":
                d[name] = int(value)
            elif name in ("status", "error"):
                d[name] = value
            else:
                d[name] = float(value) if value != "" else None
        out.append(d)
    return out


@pytest.mark.parametrize("model", ["reduced", "full"])
def test_drive_matches_cli(rdyn_cli, tmp_path, model):
    scene = rdyn.load_scene("fourbar")
    run = rdyn.drive(scene, cadence_hz=2, model=model)
    rdyn_cli("drive", "fourbar", "--cadence-hz", "2", "--model", model, "--out", str(tmp_path / "cli"))
    cli = read_csv(tmp_path / "cli" / "timeseries.csv")
    assert list(run.keys()) == list(cli.keys()) == ["t", "q", "qdot", "qddot", "drive_Nm", "drive_W",
                                                    "F_rocker_axial"]
    np.testing.assert_allclose(run["t"], cli["t"], rtol=1e-9, atol=0)  # the CSV's t has 10 digits
    for name in list(cli)[1:]:  # 17 digits: the same code path agrees bit for bit
        assert np.array_equal(run[name], np.array(cli[name])), name
    info = read_json(tmp_path / "cli" / "run.json")
    assert set(run.info) == set(info)
    for key in set(info) - {"wall_s", "extraction_ms"}:
        assert run.info[key] == info[key], key
    assert run.info["drive_peak"] > 0.1


def test_drive_profile_table_and_motor(tmp_path):
    # A profile through a table from extract, and the motor check: the same numbers as extracting there.
    scene = rdyn.load_scene("fourbar")
    profile = tmp_path / "p.csv"
    profile.write_text("t,q_deg\n" + "".join(f"{0.05 * i!r},{30 + 200 * np.sin(np.pi * 0.05 * i)!r}\n"
                                             for i in range(21)))
    table = rdyn.extract(scene, grid_deg=10)
    a = rdyn.drive(scene, profile=profile, table=table, motor=(5, 20))
    b = rdyn.drive(scene, profile=profile)
    assert np.array_equal(a["drive_Nm"], b["drive_Nm"])
    assert a.info["table"] == "(in memory)"
    assert a.info["motor_check"]["stall"] == 5.0 and "covers" in a.info["motor_check"]
    assert a["qdot"].min() < 0 < a["qdot"].max() and a["qddot"].min() < 0  # there and back


def test_drive_errors_have_their_fields(tmp_path):
    scene = rdyn.load_scene("fourbar")
    with pytest.raises(rdyn.SceneError) as e:
        rdyn.drive(scene)  # neither a rate nor a profile
    assert e.value.field == "--cadence-hz" and e.value.file == scene.source_file and e.value.line == 0
    with pytest.raises(rdyn.SceneError) as e:
        rdyn.drive(scene, cadence_hz=1, motor=(5, -20))
    assert e.value.field == "--motor"
    bad = tmp_path / "bad.csv"
    bad.write_text("t,q_deg\n0,0\n1,10\n0.5,20\n2,30\n")
    with pytest.raises(rdyn.SceneError) as e:
        rdyn.drive(scene, profile=bad)
    assert (e.value.file, e.value.line, e.value.field) == (str(bad), 4, "t")
    with pytest.raises(rdyn.ArgumentError):
        rdyn.drive(scene, cadence_hz=1, model="neither")


def test_runtime_drive_torque_is_the_drive_commands_rows(tmp_path):
    # Runtime.drive_torque(q, qdot, qddot) at rdyn drive's rows (a profile: q̈ ≠ 0, both signs
    # of q̇) gives its drive_Nm: the C API's and the CLI's one Eksergian inverse.
    scene = rdyn.load_scene("fourbar")
    table = rdyn.extract(scene, grid_deg=10)
    profile = tmp_path / "p.csv"
    profile.write_text("t,q_deg\n" + "".join(f"{0.05 * i!r},{30 + 300 * np.sin(np.pi * 0.05 * i)!r}\n"
                                             for i in range(41)))
    run = rdyn.drive(scene, profile=profile, table=table)
    rt = rdyn.Runtime(table, scene)
    got = np.array([rt.drive_torque(q, qd, qdd) for q, qd, qdd in zip(run["q"], run["qdot"], run["qddot"])])
    np.testing.assert_allclose(got, run["drive_Nm"], rtol=1e-9, atol=1e-12)
    assert rt.t == 0.0  # the state is not changed
    with pytest.raises(rdyn.ArgumentError):
        rt.drive_torque(float("nan"), 1.0, 0.0)


def test_validate_matches_cli(rdyn_cli, tmp_path):
    scene = rdyn.load_scene("fourbar")
    summary = rdyn.validate(scene, out=tmp_path / "py", quick=True)
    assert summary == read_json(tmp_path / "py" / "summary.json")
    assert (tmp_path / "py" / "report.html").exists()
    rdyn_cli("validate", "fourbar", "--quick", "--out", str(tmp_path / "cli"))
    cli = read_json(tmp_path / "cli" / "summary.json")
    assert summary["status"] == cli["status"] == "pass"
    assert summary["quantities"] == cli["quantities"]
    # The same runs with the same errors (deterministic); their wall times are measured.
    assert [r["label"] for r in summary["runs"]] == [r["label"] for r in cli["runs"]]
    for a, b in zip(summary["runs"], cli["runs"]):
        assert a["errors"] == b["errors"], a["label"]
    with pytest.raises(rdyn.OutputError):  # a folder holding files rdyn did not write
        (tmp_path / "foreign").mkdir()
        (tmp_path / "foreign" / "mine.txt").write_text("x")
        rdyn.validate(scene, out=tmp_path / "foreign", quick=True)


def test_sweep_on_any_pool_is_the_cli_sweep(rdyn_cli, tmp_path):
    from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
    scene = rdyn.load_scene("bicycle")
    vary = {"bicycle_leg.crank_length_m": (0.16, 0.18, 3)}
    rdyn_cli("sweep", "bicycle", "--vary", "bicycle_leg.crank_length_m=0.16:0.18:3", "--drive-cadence-hz", "1",
             "--out", str(tmp_path / "cli.csv"))
    cli = read_sweep_csv(tmp_path / "cli.csv")
    in_process = rdyn.sweep(scene, vary, drive_cadence_hz=1)
    with ThreadPoolExecutor(2) as pool:
        threaded = rdyn.sweep(scene, vary, drive_cadence_hz=1, map=pool.map)
    with ProcessPoolExecutor(2) as pool:
        processes = rdyn.sweep(scene, vary, drive_cadence_hz=1, map=pool.map)
    assert in_process == threaded == processes == cli
    assert [r["status"] for r in cli] == ["ok"] * 3
    assert list(cli[0]) == ["case", "bicycle_leg.crank_length_m", "status", "drive_rms_Nm", "drive_peak_Nm",
                            "drive_mean_Nm", "mean_power_w", "peak_power_w", "peak_knee_force_N", "error"]
    # Each case is `rdyn drive --model reduced` of that scene over one revolution on 1° rows, on the
    # sweep's grid (10° here: a sweep refines by the table alone, drive also by the drive on half the grid).
    rdyn_cli("drive", "bicycle", "--set", "bicycle_leg.crank_length_m=0.17", "--cadence-hz", "1", "--model",
             "reduced", "--dt-out", repr(1 / 360), "--grid-deg", "10", "--out", str(tmp_path / "drive"))
    one = read_json(tmp_path / "drive" / "run.json")
    for key, col in (("drive_rms", "drive_rms_Nm"), ("drive_peak", "drive_peak_Nm"), ("mean_power_W", "mean_power_w")):
        assert abs(cli[1][col] - one[key]) <= 1e-9 * abs(one[key]), key


def test_calibrating_sweep_on_a_thread_pool_is_the_cli_sweep(rdyn_cli, tmp_path):
    from concurrent.futures import ThreadPoolExecutor
    scene = rdyn.load_scene("bicycle")
    rdyn_cli("sweep", "bicycle", "--vary", "bicycle_leg.crank_length_m=0.16:0.18:2", "--out", str(tmp_path / "c.csv"))
    with ThreadPoolExecutor(2) as pool:
        rows = rdyn.sweep(scene, {"bicycle_leg.crank_length_m": "0.16:0.18:2"}, map=pool.map)
    assert rows == read_sweep_csv(tmp_path / "c.csv")
    assert rows[0]["drive_torque_Nm"] > rows[1]["drive_torque_Nm"] > 0  # a longer crank needs less torque


def test_sweep_peaks_on_a_thread_pool_are_the_cli_sweep(rdyn_cli, tmp_path):
    from concurrent.futures import ThreadPoolExecutor
    scene = rdyn.load_scene("bicycle")
    rdyn_cli("sweep", "bicycle", "--vary", "bicycle_leg.crank_length_m=0.16:0.18:2", "--peak", "F_knee",
             "--out", str(tmp_path / "p.csv"))
    with ThreadPoolExecutor(2) as pool:
        rows = rdyn.sweep(scene, {"bicycle_leg.crank_length_m": "0.16:0.18:2"}, map=pool.map, peaks=["F_knee"])
    assert rows == read_sweep_csv(tmp_path / "p.csv")
    for r in rows:  # the sampled cycle's peak against the refined one (sweep_peaks_test.cpp)
        assert r["peak_F_knee"] == pytest.approx(r["peak_knee_force_N"], rel=1e-4)
    with pytest.raises(rdyn.SceneError) as e:
        rdyn.sweep(scene, {"bicycle_leg.crank_length_m": (0.16, 0.18, 2)}, peaks=["R_knee_x"])
    assert e.value.field == "--peak"


def test_sweep_errors_have_their_fields():
    scene = rdyn.load_scene("bicycle")
    with pytest.raises(rdyn.SceneError) as e:
        rdyn.sweep(scene, {"no.such.key": (1, 2, 2)}, drive_cadence_hz=1)
    assert "no.such.key" in str(e.value)
    with pytest.raises(rdyn.ArgumentError, match="--drive-cadence-hz"):
        rdyn.sweep(scene, {"bicycle_leg.crank_length_m": (0.16, 0.18, 2)}, drive_cadence_hz=0)
    with pytest.raises(rdyn.SceneError) as e:
        rdyn.sweep(scene, {"bicycle_leg.crank_length_m": (0.16, 0.18, 2)}, drive_cadence_hz=1, cadence_hz=1)
    assert e.value.field == "--drive-cadence-hz"


def test_two_threads_first_calls_do_not_hang(tmp_path):
    """Two threads whose first rdyn calls run at once, in a fresh interpreter: the first array
    pybind11 made initialised numpy's C API in a static while an import let the other thread take
    the GIL and wait for that static: both hung forever (a hostile pass, issue #23)."""
    import subprocess
    import sys
    script = (
        "import threading, rdyn\n"
        "out = []\n"
        "def work(): out.append(rdyn.simulate(rdyn.load_scene('fourbar'), model='reduced', duration=0.05)['qdot'][-1])\n"
        "ts = [threading.Thread(target=work) for _ in range(4)]\n"
        "[t.start() for t in ts]; [t.join() for t in ts]\n"
        "assert len(out) == 4 and len(set(out)) == 1, out\n"
        "print('ok')\n")
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                       env=dict(os.environ))
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == "ok"
