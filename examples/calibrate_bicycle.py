"""The hip torque (and brake resistance) that pedal the stationary bicycle at 1 Hz and 125 W:
rdyn calibrate from Python.

    PYTHONPATH=P/lib/python3/dist-packages python3 examples/calibrate_bicycle.py
"""
import rdyn

scene = rdyn.load_scene("bicycle")
cal = rdyn.calibrate(scene, cadence_hz=1.0, power_w=125.0)
print(f"hip torque {cal['drive_torque_Nm']:.4f} N·m, resistance coefficient {cal['resistance_coefficient']:.6g}")
print(f"mean cadence {cal['mean_cadence_hz_reduced']:.4f} Hz (reduced), {cal['mean_cadence_hz_full']} Hz (full)")
print(f"mean power {cal['mean_power_w']:.2f} W, peak {cal['force_name']} {cal['peak_force_N']:.1f} N")
assert abs(cal["mean_cadence_hz_reduced"] - 1.0) < 0.01 and abs(cal["mean_power_w"] - 125.0) < 1.25
