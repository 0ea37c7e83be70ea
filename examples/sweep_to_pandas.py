"""A sweep in Python: the four-bar's peak rocker force against its initial speed, each case
a reduced run, the cases mapped over a process pool, the results in a pandas DataFrame (when
pandas is installed; a printed table otherwise).

    PYTHONPATH=P/lib/python3/dist-packages python3 examples/sweep_to_pandas.py
"""
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import rdyn


def case(qdot0):
    scene = rdyn.load_scene("fourbar", overrides={"initial.qdot": qdot0})
    run = rdyn.simulate(scene, model="reduced", duration=1.0, grid_deg=10)
    return {"qdot0": qdot0, "peak_F_rocker_axial_N": float(np.max(np.abs(run["F_rocker_axial"]))),
            "mean_qdot": float(np.mean(run["qdot"]))}


if __name__ == "__main__":
    speeds = [4.0, 8.0, 12.0, 16.0]
    with ProcessPoolExecutor(max_workers=2) as pool:
        rows = list(pool.map(case, speeds))
    try:
        import pandas
        print(pandas.DataFrame(rows).to_string(index=False))
    except ImportError:
        for r in rows:
            print(r)
    peaks = [r["peak_F_rocker_axial_N"] for r in rows]
    assert all(b > a for a, b in zip(peaks, peaks[1:])), "a faster crank pulls harder on the rocker"
