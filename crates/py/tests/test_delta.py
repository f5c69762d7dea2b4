"""deflect.Delta and deflect.DeltaCorrector: the Delta robot's kinematics against an
independent numpy reading of its geometry, and the D'Alembert corrector with a 3-D map."""

import math
import pickle

import numpy as np
import pytest
import deflect

R, r, L, l = 0.2, 0.045, 0.35, 0.8


def elbows(q):
    out = []
    for i, t in enumerate(q):
        phi = 2 * math.pi * i / 3
        u = np.array([math.cos(phi), math.sin(phi), 0.0])
        out.append((u * (R + L * math.cos(t)) - np.array([0, 0, L * math.sin(t)]), u))
    return out


def fk_numpy(q, guess=(0.0, 0.0, -0.8)):
    """The platform centre by Newton's method on the three forearm constraints
    |p + r u_i - e_i| = l (quadratic convergence to rounding)."""
    p = np.array(guess, float)
    for _ in range(30):
        rows = [(p + u * r - e) for e, u in elbows(q)]
        f = np.array([np.linalg.norm(s) - l for s in rows])
        jac = np.array([s / np.linalg.norm(s) for s in rows])
        p = p - np.linalg.solve(jac, f)
    return p


def test_fk_and_ik_agree_with_the_geometry_solved_numerically():
    d = deflect.Delta(R, r, L, l)
    assert d == deflect.Delta.pick_and_place()
    rng = np.random.default_rng(3)
    for _ in range(50):
        p = np.array([rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), rng.uniform(-0.95, -0.6)])
        q = d.ik(p)
        # Each forearm closes at the IK's joints.
        for e, u in elbows(q):
            assert np.linalg.norm(p + u * r - e) == pytest.approx(l, abs=1e-12)
        np.testing.assert_allclose(d.fk(q), p, atol=1e-12)
        np.testing.assert_allclose(fk_numpy(q, p + 0.01), p, atol=1e-10)
        # The Jacobian is the derivative of FK (central differences of the numeric FK).
        h = 1e-6
        fd = np.column_stack(
            [(fk_numpy(q + h * e, p) - fk_numpy(q - h * e, p)) / (2 * h) for e in np.eye(3)]
        )
        np.testing.assert_allclose(d.jacobian(q), fd, atol=1e-7)
    assert pickle.loads(pickle.dumps(d)) == d
    with pytest.raises(deflect.InputError, match="out of the workspace"):
        d.ik([0.0, 0.0, -1.5])
    with pytest.raises(deflect.InputError, match="forearm"):
        deflect.Delta(0.2, 0.045, 0.35, 0.1)


def test_the_corrector_pre_compensates_a_3d_map_displacement():
    axes = [[-0.4, 0.4], [-0.4, 0.4], [-1.0, -0.5]]
    block = np.diag([1e-6, 1e-6, 2e-6])
    slopes = np.broadcast_to(block, (2, 2, 2, 3, 3)).copy()
    m = deflect.GridMap(axes, 3, 3, slopes, np.zeros_like(slopes), names=["x", "y", "z"])
    c = deflect.DeltaCorrector(m, deflect.Delta.pick_and_place(), 1.5)
    t = c.step([0.1, -0.05, -0.8], [0.0, 0.0, -8 * 9.81])
    np.testing.assert_allclose(t["force"], [0, 0, 1.5 * 8 * 9.81])
    np.testing.assert_allclose(t["commanded"], [0.1, -0.05, -0.8 - 2e-6 * 1.5 * 8 * 9.81], atol=1e-15)
    assert t["model_status"] == "inside"
    c2 = pickle.loads(pickle.dumps(c))
    np.testing.assert_allclose(c2.step([0.1, -0.05, -0.8], [0.0, 0.0, -8 * 9.81])["joints"], t["joints"])
    flat = deflect.GridMap([[0, 1], [0, 1]], 3, 3, np.zeros((2, 2, 3, 3)), np.zeros((2, 2, 3, 3)))
    with pytest.raises(deflect.InputError, match="grid dimensions"):
        deflect.DeltaCorrector(flat, deflect.Delta.pick_and_place(), 1.5)
