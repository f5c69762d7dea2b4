"""Example 11 (Python twin of 11_five_axis.rs): a five-axis program in: ball-end finishing
across a tilted plane and a swarf cut along a leaning wall (data/five_axis_finish.apt), read
with its tool axes and cutters; the ball end's cutting wrench with the tool leaning 10 degrees
to the feed; the program cut into a tri-dexel block (2 mm rays), each operation with its own cutter.

Run: python examples/11_five_axis.py
"""

import math
from pathlib import Path

import numpy as np

import deflect

ROOT = Path(__file__).resolve().parent.parent
program = deflect.GcodeProgram.from_apt_file(ROOT / "data/five_axis_finish.apt")
tilt = np.degrees(np.arccos(np.clip(program.end_axis[:, 2], -1.0, 1.0)))
firsts = [first for _, first, _ in program.operations] + [len(program)]
ops = [(name, first, end) for (name, first, _), end in zip(program.operations, firsts[1:])]
print(f"{len(program)} moves, {len(ops)} operations")
for name, first, end in ops:
    print(f"  {name:<28} moves {first:>3}..{end:<3} tool axis "
          f"{tilt[first:end].min():.1f}..{tilt[first:end].max():.1f} deg from +z")
for tool, diameter, shape, corner, line in program.cutters:
    print(f"  cutter of T{tool}: {diameter * 1e3:g} mm {shape}")

# The first finishing line: the feed per tooth as a vector in the tool frame (x along the
# feed's part across the axis, z along the axis).
kinds = program.kind
def across(k):
    d = program.end[k] - program.start[k]
    n = np.linalg.norm(d)
    return n > 0 and abs(d.dot(program.end_axis[k])) < 0.5 * n


i = next(k for k in range(len(program)) if kinds[k] == "linear" and across(k)
         and np.all(program.start_axis[k] == program.end_axis[k]))
axis = program.end_axis[i]
direction = program.end[i] - program.start[i]
direction /= np.linalg.norm(direction)
x = direction - axis * direction.dot(axis)
feed = 0.1e-3 * np.array([direction.dot(x / np.linalg.norm(x)), 0.0, direction.dot(axis)])
_, diameter, shape, _, _ = program.cutters[0]
force, moment = deflect.cutter_force(
    diameter, 2, [[0.0, 0.3e-3, 0.0, math.pi]], feed, shape=shape, helix=math.radians(30)
)
print(f"ball end, lead {math.degrees(math.atan2(feed[2], feed[0])):.1f} deg: force "
      f"({force[0]:.1f}, {force[1]:.1f}, {force[2]:.1f}) N, torque {moment[2]:.3f} N m")

stock = deflect.Dexels((-6e-3, -16e-3, -12e-3), (56e-3, 26e-3, 10e-3), 2e-3)
before = stock.volume
for (name, first, end), (_, diameter, shape, _, _) in zip(ops, program.cutters):
    removed = 0.0
    for k in range(first, end):
        if kinds[k] == "rapid":
            continue
        removed += stock.cut(shape, diameter, 15e-3, program.start[k], program.start_axis[k],
                             program.end[k], program.end_axis[k])[1]
    print(f"  {name:<28} removed {removed * 1e9:.0f} mm^3")
print(f"stock {before * 1e9:.0f} -> {stock.volume * 1e9:.0f} mm^3")
