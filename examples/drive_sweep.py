"""The motor a stationary bicycle needs, across riders: a drive sweep over the subject's height
at 1 rev/s (each case is `rdyn drive --model reduced` over one revolution: the drive's RMS and
peak, the mean and peak power), its cases mapped over a thread pool; then the nominal rider's
drive from both models, the full one by Simbody inverse dynamics.

    PYTHONPATH=P/lib/python3/dist-packages python3 examples/drive_sweep.py
"""
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import rdyn

if __name__ == "__main__":
    scene = rdyn.load_scene("bicycle")
    with ThreadPoolExecutor(max_workers=2) as pool:  # any executor's map: processes, a dask client …
        rows = rdyn.sweep(scene, {"bicycle_leg.subject.height_m": (1.6, 1.9, 4)}, drive_cadence_hz=1,
                          map=pool.map)
    print("height_m  drive_rms_Nm  drive_peak_Nm  mean_power_W  peak_power_W")
    for r in rows:
        assert r["status"] == "ok", r["error"]
        print(f"{r['bicycle_leg.subject.height_m']:8.3f}  {r['drive_rms_Nm']:12.2f}  {r['drive_peak_Nm']:13.2f}  "
              f"{r['mean_power_w']:12.1f}  {r['peak_power_w']:12.1f}")
    full = rdyn.drive(scene, cadence_hz=1, model="full")
    reduced = rdyn.drive(scene, cadence_hz=1, model="reduced", grid_deg=5)
    print(f"nominal rider at 1 rev/s: peak drive {full.info['drive_peak']:.2f} N·m (full), "
          f"{reduced.info['drive_peak']:.2f} N·m (reduced, 5° table); peak power {full.info['peak_power_W']:.1f} W")
    # The two models agree along the whole revolution (docs/theory.md §11: 2.5e-6 of the peak).
    worst = np.max(np.abs(full["drive_Nm"] - reduced["drive_Nm"]))
    assert worst < 1e-4 * full.info["drive_peak"], worst
