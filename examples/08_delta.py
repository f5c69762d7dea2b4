"""Example 8 (Python twin of 08_delta.rs): the D'Alembert correction on a Delta robot with a
3-D compliance map fitted from static tests on a 3 x 3 x 3 grid (read off a model whose drives
give the platform J K^-1 J^T; on a real robot, measured), applied to every 2 kHz tick of a
0.3 m move at 8 g."""

import itertools

import numpy as np

import deflect

delta = deflect.Delta.pick_and_place()
k = 2.0e4  # drive stiffness [N m/rad]
points, axes, forces, disps = [], [], [], []
for x, y, z in itertools.product([-0.2, 0.0, 0.2], [-0.1, 0.0, 0.1], [-0.85, -0.775, -0.7]):
    j = delta.jacobian(delta.ik([x, y, z]))
    c = j @ j.T / k
    for axis in range(3):
        for f in (-50.0, 50.0):
            force = np.zeros(3)
            force[axis] = f
            points.append([x, y, z])
            axes.append(axis)
            forces.append(f)
            disps.append(c @ force)
m = deflect.GridMap.fit(np.array(points), axes, forces, np.array(disps), names=["x", "y", "z"],
                        position_tolerance=1e-9)
print(f"map: {m.slopes.shape[0] * m.slopes.shape[1] * m.slopes.shape[2]} nodes over x, y, z from {len(points)} static tests")
corrector = deflect.DeltaCorrector(m, delta, 1.775)
g = 8.0 * 9.81
motion = deflect.plan_pose(
    np.block([[np.eye(3), np.array([[-0.15], [-0.05], [-0.8]])], [np.zeros((1, 3)), np.ones((1, 1))]]),
    np.block([[np.eye(3), np.array([[0.15], [0.05], [-0.75]])], [np.zeros((1, 3)), np.ones((1, 1))]]),
    linear=(4.0, g, g / 0.02),
    angular=(1.0, 1.0, 10.0),
    rate_hz=2000.0,
)
worst = force = 0.0
for pose, a in zip(motion.pose, motion.acceleration):
    p = pose[:3, 3]
    t = corrector.step(p, a)
    worst = max(worst, np.linalg.norm(t["displacement"]))
    force = max(force, np.linalg.norm(t["force"]))
print(
    f"0.3 m move at 8 g: {len(motion.pose)} ticks of 0.5 ms, D'Alembert force up to "
    f"{force:.0f} N, predicted displacement up to {worst * 1e3:.3f} mm, pre-compensated every tick"
)
