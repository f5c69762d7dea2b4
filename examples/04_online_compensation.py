"""Example 4 (Python twin of 04_online_compensation.rs): online force-based compensation on the
KR 300 at 4 ms with a cutter exit, with and without pilot control (150 N / 80 ms); the force
estimate leads by 40 ms and the robot applies corrections 3 cycles late."""

import collections
import math
import pathlib

import numpy as np

import deflect

ROOT = pathlib.Path(__file__).resolve().parents[1]
robot = deflect.SerialRobot.from_urdf(
    ROOT / "robots/kr300/kr300_r2500.urdf", ROOT / "robots/kr300/kr300_r2500_stiffness.toml", "tcp"
)
q = np.array([0.0, -0.9, 1.4, 0.0, 1.0708, 0.0])
tcp = robot.forward(q)


def transform(rot, xyz):
    t = np.eye(4)
    t[:3, :3] = rot
    t[:3, 3] = xyz
    return t


c, s = math.cos(math.pi / 2), math.sin(math.pi / 2)
ry = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
s2t = transform(np.eye(3), [0, 0, 0.31]) @ transform(ry, [0, 0, 0]) @ transform(np.eye(3), [0, 0, 0.12])
cal = deflect.SensorCalibration(sensor_to_tcp=s2t)
cutting = np.array([-386.1, 386.1, 0.0, 0.0, 0.0, 0.0])
r_bs = tcp[:3, :3] @ s2t[:3, :3].T


def sensor_reading(w):
    f_s = r_bs.T @ w[:3]
    return np.concatenate([f_s, np.cross(s2t[:3, 3], f_s)])


for pilot in (None, (150.0, 0.08)):
    comp = deflect.OnlineCompensator(robot, dt=0.004, calibration=cal, pilot=pilot, project_on_feed=False, max_rate=1.0)
    sent = collections.deque([np.zeros(6)] * 3)
    worst = 0.0
    for k in range(200):
        true_w = cutting if k < 100 else np.zeros(6)
        estimate = cutting if k < 90 else np.zeros(6)
        out = comp.step(q, sensor_reading(true_w), estimate)
        sent.append(out["correction"])
        applied = sent.popleft()
        err = np.linalg.norm(robot.deflection(q, true_w)[:3] + applied[:3])
        if k >= 20:
            worst = max(worst, err)
    print(f"pilot control {pilot}: filter delay {comp.delay_seconds * 1e3:.1f} ms, worst path error {worst * 1e3:.3f} mm")
