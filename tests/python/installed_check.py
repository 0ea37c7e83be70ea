"""Run by ctest (python.installed) with PYTHONPATH=<prefix>/lib/python3/dist-packages only:
`import rdyn` loads the installed package, which finds the scenes of its own prefix."""
import os
import sys

import rdyn

prefix = os.path.realpath(sys.argv[1])
assert os.path.realpath(rdyn.__file__).startswith(prefix + os.sep), rdyn.__file__
scene = rdyn.load_scene("fourbar")
assert os.path.realpath(scene.source_file).startswith(os.path.join(prefix, "share", "rdyn", "scenes")), scene.source_file
run = rdyn.simulate(scene, model="reduced", duration=0.2)
assert len(run["qdot"]) > 10 and rdyn.extract(scene, grid_deg=30)["m1"].shape == (12,)
print("installed rdyn at", os.path.dirname(rdyn.__file__))
