"""Example 11 (Python twin of 11_five_axis.rs): a five-axis program in: ball-end finishing
across a tilted plane and a swarf cut along a leaning wall (data/five_axis_finish.apt), read
with its tool axes and cutters; the ball end's cutting wrench with the tool leaning 10 degrees
to the feed; the program cut into a tri-dexel block (2 mm rays), each operation with its own cutter;
then the five-axis job on the KR 300: the tool axis in every pose, the force along each cutter's
edge, the tip and the tilt compensated, the parts predicted along the surface's normal.

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

robot = deflect.SerialRobot.from_urdf(
    ROOT / "robots/kr300/kr300_r2500.urdf", ROOT / "robots/kr300/kr300_r2500_stiffness.toml", "tcp"
)
# Each operation's cutter from its CUTTER statement, as a tool table (TOML form, mm).
toml = 'units = "mm"\n' + "".join(
    f'[[tool]]\nnumber = {tool}\ndiameter = {diameter * 1e3}\nflutes = 2\nshape = "{shape}"\n'
    + (f"corner_radius = {corner * 1e3}\n" if shape == "bull-nose" else "")
    for tool, diameter, shape, corner, _ in program.cutters
)
tools = deflect.ToolTable.from_text(toml, format="toml")
placement = np.eye(4)
placement[:3, :3] = np.diag([-1.0, -1.0, 1.0])  # pi about z
placement[:3, 3] = [2.0, 0.0, 0.4]
job = deflect.MachiningJob(robot, placement, stock_min=(-0.006, -0.016), stock_max=(0.056, 0.026),
                           diameter=0.01, flutes=2, cell=5e-4, tools=tools)
result = job.run_five_axis(program, [0.0, -0.9, 1.4, 0.0, -0.5, 0.0], depth=0.02)
for part in ("uncompensated", "compensated"):
    e = result.errors(part)
    dev = result.surface(part, reach=3e-3)["deviation"]
    print(f"{part:<13} tool: tip max {e['max_position'] * 1e3:.4f} mm, axis max "
          f"{e['max_axis'] * 1e3:.4f} mrad; part: {max(dev.max(), 0) * 1e3:+.4f} / "
          f"{min(dev.min(), 0) * 1e3:+.4f} mm, RMS {np.sqrt(np.mean(dev ** 2)) * 1e3:.4f} mm")
