"""The four-bar's crank speed from both models on one plot (needs matplotlib), written to
fourbar_qdot.png or to the path given.

    PYTHONPATH=P/lib/python3/dist-packages python3 examples/plot_fourbar.py [out.png]
"""
import sys

import rdyn

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed (apt-get install python3-matplotlib); nothing plotted")
    sys.exit(0)

scene = rdyn.load_scene("fourbar")
full = rdyn.simulate(scene, model="full", duration=1.0)
reduced = rdyn.simulate(scene, model="reduced", duration=1.0)
fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(full["t"], full["qdot"], label="full (Simbody)")
ax.plot(reduced["t"], reduced["qdot"], "--", label="reduced (10° table)")
ax.set_xlabel("t [s]")
ax.set_ylabel("crank speed [rad/s]")
ax.legend()
out = sys.argv[1] if len(sys.argv) > 1 else "fourbar_qdot.png"
fig.savefig(out, dpi=100)
print("wrote", out)
