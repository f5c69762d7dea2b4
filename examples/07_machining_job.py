"""Example 7 (Python twin of 07_machining_job.rs): a machining job offline. The KR 300 mills
data/groove_and_pocket.nc in aluminium with a 16 mm three-flute end mill at 13,000 rpm and
25 mm/s; prints the force per program line and the predicted path and part errors with and
without compensation; writes the compensated program and every sample to target/machining/.

Your program: python examples/07_machining_job.py PROGRAM.nc (mm, workpiece frame: x 5..85 mm,
y -15..45 mm, top at z = 0)."""

import math
import pathlib
import sys
import time

import numpy as np

import deflect

ROOT = pathlib.Path(__file__).resolve().parents[1]
path = sys.argv[1] if len(sys.argv) > 1 else ROOT / "data" / "groove_and_pocket.nc"
robot = deflect.SerialRobot.from_urdf(
    ROOT / "robots/kr300/kr300_r2500.urdf", ROOT / "robots/kr300/kr300_r2500_stiffness.toml", "tcp"
)
program = deflect.GcodeProgram.from_file(path, start=[0.0, 0.0, 0.02])
# The workpiece on a table in front of the robot: origin at (2.45, 0.02, 0.92) m, z up, x
# towards the robot (pi about z); the tool points down (the default tool_orientation).
placement = np.eye(4)
placement[:3, :3] = [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]
placement[:3, 3] = [2.45, 0.02, 0.92]
job = deflect.MachiningJob(
    robot,
    placement,
    stock_min=(0.005, -0.015),
    stock_max=(0.085, 0.045),
    cell=5e-4,
    diameter=0.016,
    flutes=3,
)
started = time.perf_counter()
result = job.run(program, [0.0, -0.9, 1.4, 0.0, -0.5, 0.0])
wall = time.perf_counter() - started
print(
    f"{len(result)} samples over {result.time[-1]:.2f} s of program in {wall * 1e3:.0f} ms "
    f"({result.plunge_samples} plunge samples without side force)"
)
print("line  samples  mean |F| [N]  max |F| [N]")
lines = result.line
magnitude = np.linalg.norm(result.force, axis=1)
for line in dict.fromkeys(lines.tolist()):
    on = lines == line
    if magnitude[on].max() > 0:
        mean = np.linalg.norm(result.force[on].mean(axis=0))
        print(f"{line:>4}  {on.sum():>7}  {mean:>12.1f}  {magnitude[on].max():>11.1f}")
for part in ("uncompensated", "compensated"):
    mx, rms = result.path_error(part)
    print(f"path error {part + ':':<15} max {mx * 1e3:.3f} mm, RMS {rms * 1e3:.3f} mm")
for part in ("uncompensated", "compensated"):
    e = result.surface_error(part)
    print(
        f"part floors {part:<13}: max {e['floor_max'] * 1e3:.3f} mm, RMS {e['floor_rms'] * 1e3:.3f} mm; "
        f"walls: {e['material_left'] * 1e6:.0f} mm^2 left, {e['overcut'] * 1e6:.0f} mm^2 overcut"
    )
out = ROOT / "target" / "machining"
out.mkdir(parents=True, exist_ok=True)
(out / "compensated_py.nc").write_text(result.compensated_gcode(1e-6))
(out / "samples_py.csv").write_text(result.samples_csv(0.04))
assert math.isfinite(result.path_error()[0])
print(f"wrote {out}/compensated_py.nc and samples_py.csv")
