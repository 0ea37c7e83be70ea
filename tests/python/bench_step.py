"""The Python control-loop step against the C++ step on the reduced bicycle (a measurement for
docs/performance.md, not a test): per-step cost of n steps at 1 kHz from C++ (one call), from
Python through Runtime.step, and through the raw binding, best of 5.

    PYTHONPATH=build/python /usr/bin/python3 tests/python/bench_step.py
"""
import time

import rdyn

scene = rdyn.load_scene("bicycle")
table = rdyn.extract(scene, grid_deg=10)
n = 20000


def fresh():
    return rdyn.Runtime(table, scene)


def py_loop(rt, step):
    t0 = time.perf_counter()
    for _ in range(n):
        step(1e-3, 69.7)
    return (time.perf_counter() - t0) / n


cpp = min(fresh()._rt.time_cpp_steps(1e-3, n, 69.7) for _ in range(5))
wrapped = min(py_loop(rt, rt.step) for rt in (fresh() for _ in range(5)))
raw = min(py_loop(rt, rt.step_raw) for rt in (fresh() for _ in range(5)))
print(f"C++ step {cpp * 1e6:.3f} µs; Python Runtime.step {wrapped * 1e6:.3f} µs "
      f"(overhead {(wrapped - cpp) * 1e6:.3f} µs); raw binding {raw * 1e6:.3f} µs (overhead {(raw - cpp) * 1e6:.3f} µs)")
