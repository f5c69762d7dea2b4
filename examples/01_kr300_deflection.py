"""Example 1 (Python twin of 01_kr300_deflection.rs): deflection of the KR 300 milling robot
of the VJM paper under its validation loads and a 546 N milling load, and the correction.

Run: python examples/01_kr300_deflection.py   (after `pip install ./crates/py`)
"""

import pathlib

import numpy as np

import deflect

ROOT = pathlib.Path(__file__).resolve().parents[1]
robot = deflect.SerialRobot.from_urdf(
    ROOT / "robots/kr300/kr300_r2500.urdf", ROOT / "robots/kr300/kr300_r2500_stiffness.toml", "tcp"
)
q = np.array([0.0, -0.9, 1.4, 0.0, 1.0708, 0.0])  # rad: flange down, TCP 1.8 m out
print(robot, "\nrigid TCP [mm]:", np.round(robot.forward(q)[:3, 3] * 1e3, 1))
loads = {
    "750 N along +x": [750, 0, 0, 0, 0, 0],
    "750 N along +y": [0, 750, 0, 0, 0, 0],
    "750 N along -z": [0, 0, -750, 0, 0, 0],
    "546 N milling (xy)": [-386.1, 386.1, 0, 0, 0, 0],
}
for name, w in loads.items():
    d = robot.deflection(q, np.array(w, float))
    print(f"{name:<20} dp = {np.round(d[:3] * 1e3, 3)} mm  |dp| = {np.linalg.norm(d[:3]) * 1e3:.3f} mm")

w = np.array(loads["546 N milling (xy)"], float)
dq = robot.joint_correction(q, w)  # axis-specific correction [rad]
print("joint correction [mrad]:", np.round(dq * 1e3, 4))
