"""Jerk-limited motions and the paper's 2-DoF parallel robot through the Python bindings."""

import numpy as np
import pytest

import deflect

G = 9.81
GRID = np.array(
    [[0.122132 + 0.05 * i, -0.1125 + 0.0375 * j] for i in range(1, 4) for j in range(1, 6)]
)


def test_line_hand_case():
    # L = 1 m, v = 1, a = 10, j = 1000: t_j = 10 ms, t_a = 90 ms, T = L/v + 110 ms.
    tr = deflect.plan_line([0.0, 0.0, 0.0], [0.6, 0.8, 0.0], 1.0, 10.0, 1000.0, rate_hz=1000.0)
    assert tr.duration == pytest.approx(1.11, abs=1e-12)
    assert len(tr) == tr.t.shape[0] == 1110 + 1
    assert tr.position.shape == tr.velocity.shape == tr.acceleration.shape == (1111, 3)
    np.testing.assert_array_equal(tr.position[0], [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(tr.position[-1], [0.6, 0.8, 0.0])
    assert tr.t[-1] == tr.duration
    speed = np.linalg.norm(tr.velocity, axis=1)
    assert speed.max() == pytest.approx(1.0, rel=1e-12)
    assert np.linalg.norm(tr.acceleration, axis=1).max() <= 10.0 * (1 + 1e-12)
    assert np.linalg.norm(tr.jerk, axis=1).max() <= 1000.0 * (1 + 1e-12)


@pytest.mark.parametrize(
    "g, tx, ty, tacc",
    [(1, 288, 408, 56), (2, 272, 391, 37), (3, 262, 382, 26), (4, 255, 377, 21), (5, 253, 375, 18)],
)
def test_paper_motions(g, tx, ty, tacc):
    v, a, j = deflect.paper_limits(g)
    assert a == pytest.approx(g * G)
    x = deflect.plan_line([0.172132, 0.0], [0.272132, 0.0], v, a, j)
    y = deflect.plan_line([0.222132, -0.075], [0.222132, 0.075], v, a, j)
    assert abs(x.duration * 1e3 - tx) < 2.5
    assert abs(y.duration * 1e3 - ty) < 2.5
    # Acceleration time: until the speed first reaches v_max.
    speed = np.abs(x.velocity[:, 0])
    t_reach = x.t[np.argmax(speed >= v * (1 - 1e-9))]
    assert t_reach == pytest.approx(tacc * 1e-3, abs=1e-3)
    assert np.abs(x.acceleration).max() <= a * (1 + 1e-12)
    assert np.diff(x.t)[:-1] == pytest.approx(5e-4)


def test_polyline_and_errors():
    pts = np.array([[0.172132, -0.075], [0.272132, 0.0], [0.172132, 0.075], [0.172132, -0.075]])
    tr = deflect.plan_polyline(pts, *deflect.paper_limits(3))
    np.testing.assert_array_equal(tr.position[-1], pts[-1])
    assert tr.position.shape[1] == 2
    with pytest.raises(deflect.InputError):
        deflect.plan_line([0.0, 0.0], [0.1, 0.0], 0.0, 1.0, 1.0)
    with pytest.raises(deflect.InputError):
        deflect.plan_line([0.0, np.nan], [0.1, 0.0], 1.0, 1.0, 1.0)
    with pytest.raises(deflect.InputError):
        deflect.plan_polyline(np.zeros((1, 2)), 1.0, 1.0, 1.0)
    with pytest.raises(deflect.InputError):
        deflect.plan_polyline(np.arange(66.0).reshape(33, 2), 1.0, 1.0, 1.0)
    with pytest.raises(deflect.InputError):
        deflect.plan_polyline(np.zeros((3, 4)), 1.0, 1.0, 1.0)
    with pytest.raises(ValueError):
        deflect.paper_limits(6)


def test_parallel_robot_round_trip_and_jacobian():
    r = deflect.ParallelRobot2()
    assert r.reach == pytest.approx(0.3)
    h = 1e-6
    for p in GRID:
        q = r.ik(p)
        np.testing.assert_allclose(r.fk(q), p, atol=1e-15)
        jfd = np.column_stack(
            [(r.fk(q + h * e) - r.fk(q - h * e)) / (2 * h) for e in np.eye(2)]
        )
        np.testing.assert_allclose(r.jacobian(q), jfd, atol=1e-9)
        assert r.singularity_distance(q) > 0.07


def test_parallel_robot_errors():
    r = deflect.ParallelRobot2()
    with pytest.raises(deflect.InputError):
        r.ik([0.31, 0.0])
    with pytest.raises(deflect.SingularError):
        r.ik([0.0, 0.0])
    with pytest.raises(deflect.SingularError):
        r.ik([0.2999, 0.0])
    with pytest.raises(deflect.InputError):
        r.ik([0.2, 0.0, 0.0])
    with pytest.raises(deflect.InputError):
        deflect.ParallelRobot2(link=-1.0)
