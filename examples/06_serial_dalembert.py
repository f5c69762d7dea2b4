"""Example 6 (Python twin of 06_serial_dalembert.rs): D'Alembert correction of a serial arm in
6-D. The KR 300 carries a 150 kg spindle through a 0.33 m / 0.3 rad pose motion at 0.5, 1 and
2 g; each 2 kHz tick's joints put the loaded arm on the desired pose.

Your own arm: python examples/06_serial_dalembert.py URDF STIFFNESS TIP Q0 (Q0 comma-separated),
e.g. the UR5 of example-robot-data with robots/ur5/ur5_stiffness.toml, tip tool0,
Q0 = 0.3,-1.2,1.5,-1.9,-1.57,0.4."""

import pathlib
import sys

import numpy as np

import deflect

ROOT = pathlib.Path(__file__).resolve().parents[1]
if len(sys.argv) == 5:
    robot = deflect.SerialRobot.from_urdf(sys.argv[1], sys.argv[2], sys.argv[3])
    q0 = np.array([float(v) for v in sys.argv[4].split(",")])
elif len(sys.argv) == 1:
    robot = deflect.SerialRobot.from_urdf(
        ROOT / "robots/kr300/kr300_r2500.urdf", ROOT / "robots/kr300/kr300_r2500_stiffness.toml", "tcp"
    )
    q0 = np.array([0.0, -0.9, 1.4, 0.0, 1.0708, 0.0])
else:
    sys.exit("usage: 06_serial_dalembert.py [URDF STIFFNESS TIP Q0]")

corrector = deflect.SerialDalembertCorrector(
    robot, 150.0, com=[0.0, 0.0, 0.25], inertia=np.diag([4.0, 4.0, 2.5])
)
start = robot.forward(q0)
end = start.copy()
end[:3, 3] += [0.1, 0.3, -0.1]
c, s = np.cos(0.3), np.sin(0.3)
end[:3, :3] = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ start[:3, :3]

print("g    duration [ms]  ticks  max |dp| [mm]  max |dr| [mrad]  max |F| [N]  IK iterations (max)")
for g in (0.5, 1.0, 2.0):
    a = g * 9.80665
    motion = deflect.plan_pose(start, end, linear=(2.0, a, 20 * a), angular=(1.5, 0.8 * a, 10 * a))
    corrector.reset(q0)
    out = corrector.correct(motion)  # GIL released, one row per 2 kHz tick
    dp = np.linalg.norm(out.commanded[:, :3, 3] - out.desired[:, :3, 3], axis=1).max()
    rel = np.einsum("nij,nkj->nik", out.commanded[:, :3, :3], out.desired[:, :3, :3])
    dr = np.arccos(np.clip((np.trace(rel, axis1=1, axis2=2) - 1) / 2, -1, 1)).max()
    f = np.linalg.norm(out.wrench[:, :3], axis=1).max()
    print(
        f"{g:<4} {motion.duration * 1e3:13.1f}  {len(motion):5d}  {dp * 1e3:13.3f}  {dr * 1e3:15.3f}"
        f"  {f:11.0f}  {out.iterations.max():19d}"
    )
