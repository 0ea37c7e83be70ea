#!/usr/bin/env python3
"""Writes chain-N.yaml: N equal-link parallelogram loops (the published four-bar chain benchmark's
geometry: 1 m / 1 kg uniform rods, ground pivots 1 m apart, gravity, cranks vertical at 1 rad/s).
Run from this folder: python3 generate.py 1 3 10 40. Chains of 1 and 3 loops are also written to
../hard/ with a validation block (the hard suite: `rdyn validate --suite models/scenes/hard`); 10
and 40 loops take 8 s and 2 min per full-model run, too long for a validation ladder."""
import sys


VALIDATION = """validation:
  note: parallelogram chain through its flat configurations (twice a turn every loop's Jacobian
    loses rank and the antiparallelogram branch crosses). The full model crosses them in the
    partitioned formulation (docs/theory.md, "Singular passages"); its default run stays within
    ~3e-7 rad of the exact motion over 10 s, the reduced tables take limits at the singular samples.
"""


def chain(n, validation=False):
    lines = [f"""# A chain of {n} equal-link parallelogram loop{'s' if n > 1 else ''} (a published multibody benchmark's
# geometry): {n + 1} cranks of 1 m / 1 kg (uniform rods, inertia m L²/12 about the centre) on ground
# pivots 1 m apart, joined at their tips by {n} coupler{'s' if n > 1 else ''} of 1 m / 1 kg; gravity; the cranks start
# vertical at 1 rad/s. Twice a turn the chain lies flat (cranks along the ground line), where
# every loop's Jacobian loses rank and the antiparallelogram branch crosses. On the
# parallelogram branch all cranks turn alike and the couplers translate: the exact motion is
# the pendulum m1 θ̈ = −g [(N+1)/2 + N] cos θ with constant m1 = (N+1)/3 + N kg·m²
# (tests/engine/test_scenes.hpp integrates it).
# Generated (N = {n}) by generate.py beside this file.
name: chain-{n}
ground_points: {{{', '.join(f'P{i}: [{i}, 0]' for i in range(n + 1))}}}
bodies:"""]
    for i in range(n + 1):
        lines.append(f"  - {{name: crank{i}, mass_kg: 1, com_m: [0.5, 0], inertia_kgm2: 0.08333333333333333, "
                     f"points: {{T: [1, 0]}}}}")
    for i in range(n):
        lines.append(f"  - {{name: coupler{i}, mass_kg: 1, com_m: [0.5, 0], inertia_kgm2: 0.08333333333333333, "
                     f"points: {{E: [1, 0]}}}}")
    lines.append("joints:")
    for i in range(n + 1):
        lines.append(f"  - {{name: crank{i}, type: revolute, parent: ground, parent_point: P{i}, child: crank{i}, "
                     f"guess_deg: 90}}")
    for i in range(n):
        lines.append(f"  - {{name: coupler{i}, type: revolute, parent: crank{i}, parent_point: T, "
                     f"child: coupler{i}, guess_deg: -90}}")
    lines.append("loops:")
    for i in range(n):
        lines.append(f"  - {{name: L{i}, body_a: coupler{i}, point_a: E, body_b: crank{i + 1}, point_b: T}}")
    lines.append("""independent: crank0
gravity: {enabled: true, g_m_s2: [0, -9.81]}
initial: {q_deg: 90, qdot: 1.0}
simulation: {duration_s: 10, output_interval_s: 0.01}
""" + (VALIDATION if validation else ""))
    return "\n".join(lines)


for arg in sys.argv[1:]:
    with open(f"chain-{int(arg)}.yaml", "w") as f:
        f.write(chain(int(arg)))
    if int(arg) in (1, 3):
        with open(f"../hard/chain-{int(arg)}.yaml", "w") as f:
            f.write(chain(int(arg), validation=True))
