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
    with pytest.raises(deflect.InputError, match=r"1 <= d <= 8"):
        deflect.plan_polyline(np.zeros((3, 9)), 1.0, 1.0, 1.0)
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


# --- N-D planning, plan-only trajectories, user samples, pose motions -------------------------

RNG = np.random.default_rng(13)


def ruckig_duration(start, end, v, a, j, phase=False):
    """Duration of ruckig's time-optimal rest-to-rest motion (an independent planner)."""
    from ruckig import InputParameter, Result, Ruckig, Synchronization, Trajectory

    n = len(start)
    inp = InputParameter(n)
    inp.current_position, inp.target_position = list(start), list(end)
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = list(v), list(a), list(j)
    if phase:
        inp.synchronization = Synchronization.Phase
    tr = Trajectory(n)
    assert Ruckig(n).calculate(inp, tr) == Result.Working
    return tr.duration


def test_one_dimensional_durations_equal_ruckigs():
    for _ in range(200):
        length = 10 ** RNG.uniform(-4, 0.5)
        v, a, j = 10 ** RNG.uniform(-1, 0.5), 10 ** RNG.uniform(0, 2), 10 ** RNG.uniform(1, 4)
        ours = deflect.plan_line([0.0], [length], v, a, j, rate_hz=None).duration
        assert ours == pytest.approx(ruckig_duration([0.0], [length], [v], [a], [j]), rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("d", range(1, 9))
def test_path_limits_in_any_dimension_plan_the_path_length(d):
    start, end = RNG.uniform(-1, 1, d), RNG.uniform(-1, 1, d)
    tr = deflect.plan_line(start, end, 0.8, 6.0, 90.0, rate_hz=500.0)
    length = np.linalg.norm(end - start)
    one = deflect.plan_line([0.0], [length], 0.8, 6.0, 90.0, rate_hz=None)
    assert tr.duration == pytest.approx(one.duration, rel=1e-14)
    assert tr.dim == d and tr.position.shape == (len(tr), d)
    np.testing.assert_array_equal(tr.position[-1], end)
    assert np.linalg.norm(tr.velocity, axis=1).max() <= 0.8 * (1 + 1e-12)
    # The line stays straight: every sample on start + s (end - start).
    s = (tr.position - start) @ (end - start) / length**2
    np.testing.assert_allclose(tr.position, start + np.outer(s, end - start), atol=1e-14)


def test_joint_space_limits_per_axis_against_ruckig():
    # Six joints; axis 1 binds speed, acceleration and jerk at once (limits proportional),
    # so the synchronised straight line is as fast as ruckig's time-synchronised motion.
    start = np.array([0.0, -1.2, 1.0, 0.3, -0.5, 0.1])
    end = np.array([0.4, 0.8, 0.2, 0.1, 0.5, -0.2])
    v = np.array([2.0, 1.0, 2.0, 3.0, 3.0, 3.0])
    a, j = 8.0 * v, 80.0 * v
    tr = deflect.plan_line(start, end, v, a, j, rate_hz=2000.0)
    assert tr.duration == pytest.approx(ruckig_duration(start, end, v, a, j), rel=1e-9)
    for arr, lim in ((tr.velocity, v), (tr.acceleration, a), (tr.jerk, j)):
        assert (np.abs(arr) <= lim * (1 + 1e-9)).all()
    assert np.abs(tr.velocity[:, 1]).max() == pytest.approx(v[1], rel=1e-9)
    # In general (different axes binding different limits) a straight line in joint space
    # cannot be faster than ruckig's free per-axis profiles, and every limit holds.
    for _ in range(50):
        s, e = RNG.uniform(-1, 1, 6), RNG.uniform(-1, 1, 6)
        v, a, j = RNG.uniform(0.5, 3, 6), RNG.uniform(2, 20, 6), RNG.uniform(20, 400, 6)
        tr = deflect.plan_line(s, e, v, a, j, rate_hz=1000.0)
        assert tr.duration >= ruckig_duration(s, e, v, a, j) * (1 - 1e-9)
        for arr, lim in ((tr.velocity, v), (tr.acceleration, a), (tr.jerk, j)):
            assert (np.abs(arr) <= lim * (1 + 1e-9)).all()


def test_scalar_limits_broadcast_with_per_axis_ones():
    a = deflect.plan_line([0, 0], [0.3, 0.1], [1.0, 0.5], 10.0, 200.0, rate_hz=None)
    b = deflect.plan_line([0, 0], [0.3, 0.1], [1.0, 0.5], [10.0, 10.0], [200.0, 200.0], rate_hz=None)
    assert a.duration == b.duration
    with pytest.raises(deflect.InputError, match=r"v_max: expected shape \(2,\)"):
        deflect.plan_line([0, 0], [0.3, 0.1], [1.0, 0.5, 1.0], 10.0, 200.0)
    with pytest.raises(deflect.InputError, match="v_max"):
        deflect.plan_line([0, 0], [0.3, 0.1], [1.0, -0.5], 10.0, 200.0)


def test_plan_only_is_exact_at_any_time_and_samples_on_demand():
    tr = deflect.plan_line([0.1, 0.2, 0.3, 0.4], [0.5, -0.2, 0.0, 0.9], 0.5, 4.0, 60.0, rate_hz=None)
    assert tr.rate_hz is None and tr.is_planned
    with pytest.raises(deflect.InputError, match="plan-only"):
        tr.position
    with pytest.raises(deflect.InputError, match="plan-only"):
        len(tr)
    sampled = tr.sampled(1000.0)
    ts = sampled.t
    at = tr.at(ts)
    for k in ("position", "velocity", "acceleration", "jerk"):
        np.testing.assert_array_equal(at[k], getattr(sampled, k))
    one = tr.at(0.25)
    assert one["position"].shape == (4,) and one["t"] == 0.25
    np.testing.assert_array_equal(one["position"], at["position"][250])
    # Before the start and after the end: at rest.
    np.testing.assert_array_equal(tr.at(-1.0)["position"], [0.1, 0.2, 0.3, 0.4])
    np.testing.assert_array_equal(tr.at(1e9)["velocity"], np.zeros(4))
    with pytest.raises(deflect.InputError, match="t"):
        tr.at(float("nan"))
    with pytest.raises(deflect.InputError, match=r"t: expected shape a number or \(m,\)"):
        tr.at(np.zeros((2, 2)))


def test_polyline_with_per_segment_limits():
    pts = np.array([[0.0, 0.0, 0.0], [0.2, 0.0, 0.0], [0.2, 0.1, 0.0]])
    tr = deflect.plan_polyline(pts, segment_limits=[[1.0, 10.0, 500.0], [0.2, 2.0, 50.0]], rate_hz=None)
    first = deflect.plan_line(pts[0], pts[1], 1.0, 10.0, 500.0, rate_hz=None).duration
    second = deflect.plan_line(pts[1], pts[2], 0.2, 2.0, 50.0, rate_hz=None).duration
    assert tr.duration == pytest.approx(first + second, rel=1e-14)
    assert np.linalg.norm(tr.at(first + 0.5 * second)["velocity"]) <= 0.2 * (1 + 1e-12)
    with pytest.raises(deflect.InputError, match=r"segment_limits: expected shape \(2, 3\)"):
        deflect.plan_polyline(pts, segment_limits=[[1.0, 10.0, 500.0]])
    with pytest.raises(deflect.InputError, match="segment_limits row 1"):
        deflect.plan_polyline(pts, segment_limits=[[1.0, 10.0, 500.0], [0.2, 0.0, 50.0]])
    with pytest.raises(deflect.InputError, match="not both"):
        deflect.plan_polyline(pts, 1.0, 10.0, 500.0, segment_limits=[[1.0, 10.0, 500.0]] * 2)
    with pytest.raises(deflect.InputError, match="needs limits"):
        deflect.plan_polyline(pts)


def test_trajectory_from_samples_uses_the_stated_differences():
    rate = 100.0
    t = np.arange(50) / rate
    p = np.column_stack([3.0 * t**2 - t, 0.5 * t**2])
    tr = deflect.Trajectory.from_samples(p, rate)
    assert not tr.is_planned and tr.rate_hz == rate and len(tr) == 50 and tr.dim == 2
    # Second-order stencils are exact for quadratics, inside and at the ends.
    np.testing.assert_allclose(tr.acceleration, np.tile([6.0, 1.0], (50, 1)), atol=1e-8)
    np.testing.assert_allclose(tr.velocity, np.column_stack([6 * t - 1, t]), atol=1e-10)
    np.testing.assert_allclose(tr.t, t, atol=1e-15)
    # Given accelerations are used as they are.
    acc = RNG.normal(size=(50, 2))
    np.testing.assert_array_equal(deflect.Trajectory.from_samples(p, rate, acc).acceleration, acc)
    # A 1-D array is one coordinate.
    assert deflect.Trajectory.from_samples(t, rate).position.shape == (50, 1)
    with pytest.raises(deflect.InputError, match="from samples"):
        tr.at(0.1)
    with pytest.raises(deflect.InputError, match="needed 4|4"):
        deflect.Trajectory.from_samples(p[:3], rate)
    with pytest.raises(deflect.InputError, match=r"position\[4, 1\]|position"):
        bad = p.copy()
        bad[4, 1] = np.nan
        deflect.Trajectory.from_samples(bad, rate)
    with pytest.raises(deflect.InputError, match=r"acceleration: expected shape \(N, 2\)"):
        deflect.Trajectory.from_samples(p, rate, acc[:, :1])
    with pytest.raises(deflect.InputError, match="rate_hz"):
        deflect.Trajectory.from_samples(p, 0.0)


def rotation_vector(r):
    angle = np.arccos(np.clip((np.trace(r) - 1) / 2, -1, 1))
    if angle < 1e-12:
        return np.zeros(3)
    return angle / (2 * np.sin(angle)) * np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])


def test_pose_motion_is_synchronised_and_its_rates_are_derivatives():
    from conftest import axis_angle, homogeneous

    start = homogeneous(axis_angle([0, 0, 1], 0.3), [0.4, 0.1, 0.5])
    end = homogeneous(axis_angle([1, 1, 0], 0.8) @ start[:3, :3], [0.6, -0.1, 0.4])
    linear, angular = (0.5, 5.0, 100.0), (1.0, 8.0, 200.0)
    tr = deflect.plan_pose(start, end, linear, angular, rate_hz=2000.0)
    assert tr.angle == pytest.approx(0.8, abs=1e-12)
    np.testing.assert_allclose(tr.axis, np.array([1, 1, 0]) / np.sqrt(2), atol=1e-12)
    np.testing.assert_allclose(tr.pose[0], start, atol=1e-15)
    np.testing.assert_allclose(tr.pose[-1], end, atol=1e-15)
    assert tr.pose.shape == (len(tr), 4, 4)
    # Limits hold on both parts, and one of them is reached (time-optimal).
    v, w = np.linalg.norm(tr.velocity, axis=1), np.linalg.norm(tr.angular_velocity, axis=1)
    assert v.max() <= linear[0] * (1 + 1e-9) and w.max() <= angular[0] * (1 + 1e-9)
    assert np.linalg.norm(tr.acceleration, axis=1).max() <= linear[1] * (1 + 1e-9)
    assert np.linalg.norm(tr.angular_acceleration, axis=1).max() <= angular[1] * (1 + 1e-9)
    assert max(v.max() / linear[0], w.max() / angular[0]) == pytest.approx(1.0, rel=1e-9) or max(
        np.linalg.norm(tr.acceleration, axis=1).max() / linear[1],
        np.linalg.norm(tr.angular_acceleration, axis=1).max() / angular[1],
    ) == pytest.approx(1.0, rel=1e-6)
    # Angular velocity is the derivative of the orientation, velocity that of the position.
    h = 1e-6
    for t in np.linspace(0.01, tr.duration - 0.01, 9):
        a, b, c = tr.at(t - h), tr.at(t), tr.at(t + h)
        w_fd = rotation_vector(c["pose"][:3, :3] @ a["pose"][:3, :3].T) / (2 * h)
        np.testing.assert_allclose(b["angular_velocity"], w_fd, atol=1e-7)
        np.testing.assert_allclose(b["velocity"], (c["pose"][:3, 3] - a["pose"][:3, 3]) / (2 * h), atol=1e-7)
        np.testing.assert_allclose(b["angular_acceleration"], (c["angular_velocity"] - a["angular_velocity"]) / (2 * h), atol=1e-4)
    with pytest.raises(deflect.InputError, match="linear"):
        deflect.plan_pose(start, end, (0.5, 0.0, 100.0), angular)
    with pytest.raises(deflect.InputError, match="end"):
        bad = end.copy()
        bad[0, 0] = 2.0
        deflect.plan_pose(start, bad, linear, angular)
    with pytest.raises(deflect.InputError, match="plan-only"):
        deflect.plan_pose(start, end, linear, angular, rate_hz=None).pose


def test_line_planner_replans_in_place_bit_for_bit():
    planner = deflect.LinePlanner(2, 1.2, 25.0, 600.0)
    assert planner.duration == 0.0 and planner.start == planner.end == [0.0, 0.0]
    rng = np.random.default_rng(7)
    for _ in range(50):
        s, e = rng.uniform(-0.5, 0.5, 2), rng.uniform(-0.5, 0.5, 2)
        for start, end in [(s, e), (list(s), tuple(e)), (s.astype(np.float32), e)]:
            ref = deflect.plan_line(start, end, 1.2, 25.0, 600.0, rate_hz=None)
            assert planner.plan(start, end) == ref.duration
            assert planner.duration == ref.duration
            t = np.linspace(-0.01, ref.duration + 0.01, 17)
            got, want = planner.at(t), ref.at(t)
            for k in ("t", "position", "velocity", "acceleration", "jerk"):
                np.testing.assert_array_equal(got[k], want[k])
    copy = planner.trajectory(rate_hz=1000.0)
    assert copy.duration == planner.duration and copy.rate_hz == 1000.0
    np.testing.assert_array_equal(copy.position[-1], planner.end)
    # The path limits are ruckig's in 1-D: the same durations.
    one = deflect.LinePlanner(1, 1.2, 25.0, 600.0)
    assert one.plan([0.05], [0.35]) == pytest.approx(
        deflect.plan_line([0.05], [0.35], 1.2, 25.0, 600.0).duration, rel=0, abs=0
    )


def test_line_planner_plans_from_its_input_points():
    # ruckig's habit: the input points are set (or kept), `plan()` plans from them.
    planner = deflect.LinePlanner(2, 1.2, 25.0, 600.0)
    planner.start, planner.end = [0.1, -0.2], np.array([0.3, 0.25])
    assert (planner.start, planner.end) == ([0.1, -0.2], [0.3, 0.25])
    assert planner.duration == 0.0  # setting points plans nothing
    ref = deflect.plan_line([0.1, -0.2], [0.3, 0.25], 1.2, 25.0, 600.0, rate_hz=None)
    assert planner.plan() == ref.duration
    # Planned again from the same input: the same plan, computed again.
    assert planner.plan() == ref.duration
    np.testing.assert_array_equal(planner.at(0.1)["position"], ref.at(0.1)["position"])
    # One point given: the other is the input's.
    other = deflect.plan_line([0.1, -0.2], [0.0, 0.0], 1.2, 25.0, 600.0, rate_hz=None)
    assert planner.plan(end=(0.0, 0.0)) == other.duration
    assert planner.end == [0.0, 0.0]
    back = deflect.plan_line([0.3, 0.3], [0.0, 0.0], 1.2, 25.0, 600.0, rate_hz=None)
    assert planner.plan(start=[0.3, 0.3]) == back.duration
    # plan(start, end) makes its points the input.
    planner.plan([0.0, 0.0], [0.2, 0.1])
    assert (planner.start, planner.end) == ([0.0, 0.0], [0.2, 0.1])
    assert planner.plan() == planner.duration
    # A bad point set is refused by the setter (shape) or by the next plan (value); on a
    # refused plan the previous plan and input stay.
    with pytest.raises(deflect.InputError, match="start"):
        planner.start = [0.0, 0.0, 0.0]
    planner.end = [np.nan, 0.0]
    d = planner.duration
    with pytest.raises(deflect.InputError, match="points"):
        planner.plan()
    assert planner.duration == d
    with pytest.raises(deflect.InputError, match="points"):
        planner.plan(start=[np.inf, 0.0], end=[0.0, 0.0])
    assert planner.start == [0.0, 0.0]
    with pytest.raises(deflect.InputError, match="points"):
        planner.plan(start=[1.0, 0.0])
    assert planner.start == [0.0, 0.0]


def test_line_planner_refuses_and_keeps_its_plan():
    planner = deflect.LinePlanner(1, 1.2, 25.0, 600.0)
    d = planner.plan([0.0], [0.3])
    for start, end, what in [
        ([np.nan], [0.3], "points"),
        ([0.0], [0.1, 0.2], "end"),
        ([0.0], ["x"], "end"),
        ([0.0 + 1j], [0.3], "start"),
    ]:
        with pytest.raises(deflect.InputError, match=what):
            planner.plan(start, end)
        assert planner.duration == d and planner.end == [0.3]
    for args, what in [
        ((0, 1.0, 1.0, 1.0), "dim"),
        ((9, 1.0, 1.0, 1.0), "dim"),
        ((2, 0.0, 1.0, 1.0), "v_max"),
        ((2, 1.0, np.inf, 1.0), "a_max"),
        ((2, 1.0, 1.0, 5e-324), "j_max"),
    ]:
        with pytest.raises(deflect.InputError, match=what):
            deflect.LinePlanner(*args)
