"""Example 10 (Python twin of 10_robot_program.rs): the built-in job on the KR 300, from the
program to the robot's own program: the spin about the tool axis chosen along the program for
the least deflection, the KRL of both commands, and the placement of the workpiece searched in
a box around the job's own.

Run: python examples/10_robot_program.py
"""

import math
from pathlib import Path

import numpy as np

import deflect

ROOT = Path(__file__).resolve().parent.parent
robot = deflect.SerialRobot.from_urdf(
    ROOT / "robots/kr300/kr300_r2500.urdf", ROOT / "robots/kr300/kr300_r2500_stiffness.toml", "tcp"
)
program = deflect.GcodeProgram.from_file(ROOT / "data/groove_and_pocket.nc", start=[0, 0, 0.02])
placement = np.eye(4)
placement[:3, :3] = np.diag([-1.0, -1.0, 1.0])
placement[:3, 3] = [2.45, 0.02, 0.92]
seed = [0.0, -0.9, 1.4, 0.0, -0.5, 0.0]
stock = dict(stock_min=(0.005, -0.015), stock_max=(0.085, 0.045))

job = deflect.MachiningJob(robot, placement, spin="optimize", **stock)
result = job.run(program, seed)
plan = result.spin_plan
mm = lambda c: f"RMS {c[0] * 1e3:.4f} mm, max {c[1] * 1e3:.4f} mm"
print(f"spin over {plan['stations']} stations x {plan['candidates']} candidates:")
print(f"  the seed's constant spin  {mm(plan['seed'])}")
print(f"  the best constant spin    {mm(plan['best_constant'])} ({math.degrees(plan['best_constant_spin']):.0f} degrees)")
print(f"  optimised along the path  {mm(plan['optimised'])}")
print(
    f"path error max, uncompensated {result.path_error('uncompensated')[0] * 1e3:.3f} mm, "
    f"compensated {result.path_error('compensated')[0]:.1e} m"
)
for command in ("cartesian", "joints"):
    files = result.robot_program("krl", command=command)
    name, src = next(iter(files.items()))
    motions = [l for l in src.splitlines() if l.startswith(("LIN ", "PTP "))]
    print(f"{name} ({len(motions)} motions), {command}:")
    for line in motions[:2]:
        print(f"  {line}")

problem = deflect.PlacementProblem(deflect.MachiningJob(robot, placement, **stock), program, seed)
found = deflect.place(
    problem, (2.30, -0.13, 0.87, math.radians(-30)), (2.60, 0.17, 0.97, math.radians(30)), (4, 4, 3, 3), refine=3
)
x, y, z, yaw = found.best
print(
    f"best placement (the seed's spin, {found.evaluations} placements): x {x:.3f} m, y {y:.3f} m, "
    f"z {z:.3f} m, yaw {math.degrees(yaw):.1f} degrees: RMS {found.best_rms * 1e3:.4f} mm"
)
