"""Model classes pickle and deep-copy: the copy computes bit for bit what the original does, and
a tampered state is refused by the core's validation, not turned into a different model."""

import copy
import pickle

import numpy as np
import pytest

import deflect
from conftest import KR300_TOML, KR300_URDF, REPO, ur5_urdf

Q = np.array([0.3, -0.8, 1.2, 0.5, 0.9, -0.4])
W = np.array([-386.1, 386.1, -60.0, 12.0, -7.0, 3.0])


@pytest.fixture(scope="module")
def robots():
    return [
        deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp"),
        deflect.SerialRobot.from_urdf(ur5_urdf(), REPO / "robots/ur5/ur5_stiffness.toml", "tool0"),
    ]


@pytest.mark.parametrize("clone", [lambda r: pickle.loads(pickle.dumps(r)), copy.deepcopy])
def test_serial_robot_round_trips_exactly(robots, clone):
    for robot in robots:
        other = clone(robot)
        assert other is not robot
        for name in ["dof", "joint_names", "joint_limits", "spring_names", "base_link", "tip_link"]:
            assert getattr(other, name) == getattr(robot, name), name
        np.testing.assert_array_equal(other.forward(Q), robot.forward(Q))
        np.testing.assert_array_equal(other.deflection(Q, W), robot.deflection(Q, W))
        np.testing.assert_array_equal(other.compliance(Q), robot.compliance(Q))
        np.testing.assert_array_equal(other.equilibrium(Q, W), robot.equilibrium(Q, W))


def test_a_tampered_robot_state_is_refused(robots):
    rebuild, (state,) = robots[0].__reduce__()
    version, elements, *rest = state
    kind, values = next(e for e in elements if e[0] == "revolute")
    bad = [(kind, [0.0, 0.0, 2.0]) if e[0] == "revolute" else e for e in elements]
    with pytest.raises(deflect.InputError, match="joint axis"):
        rebuild((version, bad, *rest))
    negative = [("spring", [-1e-6] + v[1:]) if k == "spring" else (k, v) for k, v in elements]
    with pytest.raises(deflect.InputError, match="stiffness"):
        rebuild((version, negative, *rest))
    with pytest.raises(deflect.InputError, match="version"):
        rebuild((99, elements, *rest))
    with pytest.raises(deflect.InputError, match="joint names"):
        rebuild((version, elements, rest[0][:-1], *rest[1:]))


def test_compliance_map_round_trips_with_its_options():
    cmap = deflect.ComplianceMap.from_csv(REPO / "data/paksoy2025_compliance_oc.csv")
    cubic = cmap.with_options(interpolation="cubic", out_of_grid="extrapolate")
    for m in [cmap, cubic]:
        for other in [pickle.loads(pickle.dumps(m)), copy.deepcopy(m)]:
            assert other.to_json() == m.to_json()
            for p in ([0.2, 0.02], [0.25, -0.06]):
                np.testing.assert_array_equal(
                    other.displacement(p, [0.0, -245.0]), m.displacement(p, [0.0, -245.0])
                )
    far = [0.5, 0.3]
    np.testing.assert_array_equal(
        pickle.loads(pickle.dumps(cubic)).displacement(far, [10.0, 0.0]),
        cubic.displacement(far, [10.0, 0.0]),
    )


def test_parallel_robot_round_trips():
    robot = deflect.ParallelRobot2(link=0.16, half_width=0.085, min_sigma=0.01)
    for other in [pickle.loads(pickle.dumps(robot)), copy.deepcopy(robot)]:
        q = other.ik([0.2, 0.03])
        np.testing.assert_array_equal(q, robot.ik([0.2, 0.03]))
        np.testing.assert_array_equal(other.jacobian(q), robot.jacobian(q))


def test_from_json_takes_the_text_or_a_path(tmp_path):
    cmap = deflect.ComplianceMap.from_csv(REPO / "data/paksoy2025_compliance_oc.csv")
    path = tmp_path / "map.json"
    cmap.save_json(path)
    for source in [cmap.to_json(), "  \n" + cmap.to_json(), path, str(path)]:
        assert deflect.ComplianceMap.from_json(source).to_json() == cmap.to_json()
    with pytest.raises(deflect.LoadError, match="nonexistent"):
        deflect.ComplianceMap.from_json(tmp_path / "nonexistent.json")
    with pytest.raises(deflect.InputError, match="source"):
        deflect.ComplianceMap.from_json(42)


CLONES = [lambda o: pickle.loads(pickle.dumps(o)), copy.deepcopy]


@pytest.mark.parametrize("clone", CLONES)
def test_drive_train_round_trips_with_its_robot(robots, clone):
    kr300 = robots[0]
    drive = deflect.DriveTrain(
        kr300,
        [1.0e7, 6.0e6, 4.0e6, 1.0e6, 8.0e5, 5.0e5],
        [1e-4, 2e-4, 0.0, 0.0, 1e-4, 0.0],
        masses=[(1, 120.0, (0.3, 0.0, 0.1)), (2, 60.0, (0.5, 0.02, 0.0))],
        gravity=(0.0, 0.5, -9.8),
        torque_deadband=2.0,
        max_condition=1e5,
    )
    other = clone(drive)
    for name in ["stiffness", "backlash", "masses", "gravity"]:
        assert getattr(other, name) == getattr(drive, name), name
    np.testing.assert_array_equal(other.gravity_torques(Q), drive.gravity_torques(Q))
    np.testing.assert_array_equal(other.correct_joints(Q, W), drive.correct_joints(Q, W))
    np.testing.assert_array_equal(other.cartesian_stiffness(Q), drive.cartesian_stiffness(Q))


@pytest.mark.parametrize("clone", CLONES)
def test_trajectories_round_trip_planned_or_sampled(clone):
    pts = [[0.0, 0.0, 0.0], [0.1, 0.2, 0.0], [0.3, 0.0, 0.05]]
    made = [
        deflect.plan_line([0.0, 0.1], [0.2, -0.05], 1.0, 20.0, 400.0),
        deflect.plan_line([0.0, 0.1], [0.2, -0.05], 1.0, 20.0, 400.0, rate_hz=None),
        deflect.plan_polyline(pts, [1.0, 0.5, 0.2], 20.0, 400.0, rate_hz=1000.0),
        deflect.plan_polyline(pts, segment_limits=[[1.0, 10.0, 100.0], [0.5, 20.0, 300.0]]),
        deflect.plan_line([0.0, 0.1], [0.2, -0.05], 1.0, 20.0, 400.0).sampled(500.0),
        deflect.Trajectory.from_samples(np.linspace(0.0, 1.0, 40) ** 3, 250.0),
        deflect.Trajectory.from_samples(
            np.c_[np.linspace(0, 1, 30), np.zeros(30)], 100.0, acceleration=np.ones((30, 2))
        ),
    ]
    times = np.linspace(-0.1, 2.0, 17)
    for traj in made:
        other = clone(traj)
        assert repr(other) == repr(traj)
        assert (other.duration, other.dim, other.rate_hz) == (traj.duration, traj.dim, traj.rate_hz)
        if traj.rate_hz is not None:
            for name in ["t", "position", "velocity", "acceleration", "jerk"]:
                np.testing.assert_array_equal(getattr(other, name), getattr(traj, name), name)
        if traj.is_planned:
            for k, v in traj.at(times).items():
                np.testing.assert_array_equal(other.at(times)[k], v, k)


@pytest.mark.parametrize("clone", CLONES)
def test_line_planner_round_trips_with_its_current_plan(clone):
    planner = deflect.LinePlanner(3, 1.0, 20.0, 400.0)
    planner.plan([0.0, 0.1, 0.2], [0.2, -0.05, 0.3])
    planner.end = [0.4, 0.0, 0.0]  # an input not planned yet travels too
    other = clone(planner)
    assert repr(other) == repr(planner)
    assert (other.limits, other.start, other.end) == (planner.limits, planner.start, planner.end)
    assert other.end == [0.4, 0.0, 0.0] and other.duration == planner.duration
    times = np.linspace(-0.1, 1.0, 13)
    for k, v in planner.at(times).items():
        np.testing.assert_array_equal(other.at(times)[k], v, k)
    # The copy re-plans on its own.
    other.plan([0.0, 0.0, 0.0], [0.1, 0.0, 0.0])
    assert planner.end == [0.4, 0.0, 0.0] and planner.start == [0.0, 0.1, 0.2]


@pytest.mark.parametrize("clone", CLONES)
def test_pose_trajectory_round_trips(robots, clone):
    ur5 = robots[1]
    q0 = np.array([0.3, -1.2, 1.5, -1.9, -1.57, 0.4])
    start = ur5.forward(q0)
    end = ur5.forward(q0 + 0.2)
    for rate in [2000.0, None]:
        traj = deflect.plan_pose(start, end, (1.0, 30.0, 600.0), (2.0, 40.0, 800.0), rate_hz=rate)
        other = clone(traj)
        assert repr(other) == repr(traj)
        np.testing.assert_array_equal(other.at(0.137)["pose"], traj.at(0.137)["pose"])
        if rate is not None:
            np.testing.assert_array_equal(other.pose, traj.pose)


@pytest.mark.parametrize("clone", CLONES)
def test_correctors_pickle_their_configuration_and_start_afresh(robots, clone):
    cmap = deflect.ComplianceMap.from_csv(REPO / "data/paksoy2025_compliance_oc.csv")
    five_bar = deflect.DalembertCorrector(cmap, deflect.ParallelRobot2(), 4.5, 3, 1e-9)
    traj = deflect.plan_line([0.19, 0.0], [0.25, 0.0], *deflect.paper_limits(5))
    a = five_bar.correct(traj)
    other = clone(five_bar)
    assert other.mass == five_bar.mass
    np.testing.assert_array_equal(other.correct(traj).commanded, a.commanded)

    ur5 = robots[1]
    q0 = np.array([0.3, -1.2, 1.5, -1.9, -1.57, 0.4])
    start = ur5.forward(q0)
    end = start.copy()
    end[:3, 3] += [0.1, -0.05, 0.02]
    pose_traj = deflect.plan_pose(start, end, (1.0, 30.0, 600.0), (2.0, 40.0, 800.0))
    serial = deflect.SerialDalembertCorrector(
        ur5, 3.0, com=[0.0, 0.0, 0.05], inertia=np.diag([0.01, 0.02, 0.03]), seed=q0,
        gravity=[0.0, 0.0, -9.80665], max_iterations=30,
    )
    fresh = clone(serial)
    first = serial.correct(pose_traj)
    # The copy made before any tick and the one made after both start from `seed`.
    later = clone(serial)
    for c in [fresh, later]:
        assert (c.mass, c.model, c.dof, c.joint_names) == (
            serial.mass, serial.model, serial.dof, serial.joint_names)
        np.testing.assert_array_equal(c.gravity, serial.gravity)
        np.testing.assert_array_equal(c.correct(pose_traj).joints, first.joints)


@pytest.mark.parametrize("clone", CLONES)
def test_sensor_calibration_round_trips(clone):
    rng = np.random.default_rng(3)
    tcp = np.eye(4)
    tcp[:3, :3] = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    tcp[:3, 3] = [0.01, 0.0, 0.2]
    cal = deflect.SensorCalibration(
        force_offset=[1.0, -2.0, 3.0], moment_offset=[0.1, 0.2, -0.3], weight=45.0,
        center_of_gravity=[0.0, 0.01, 0.08], residual=rng.normal(size=(6, 15)) * 1e-3,
        sensor_to_tcp=tcp,
    )
    other = clone(cal)
    for name in ["force_offset", "moment_offset", "center_of_gravity", "residual", "sensor_to_tcp"]:
        np.testing.assert_array_equal(getattr(other, name), getattr(cal, name), name)
    assert other.weight == cal.weight


def test_a_tampered_calibration_state_is_refused():
    rebuild, (state,) = deflect.SensorCalibration(weight=10.0).__reduce__()
    f, m, w, cog, residual, p, q = state
    with pytest.raises(deflect.InputError, match="quaternion"):
        rebuild((f, m, w, cog, residual, p, (0.0, 0.0, 0.0, 2.0)))
    with pytest.raises(deflect.InputError, match="weight"):
        rebuild((f, m, -1.0, cog, residual, p, q))


def test_per_tick_state_is_deep_copied_but_not_pickled(robots):
    x = np.array([1.0, 2.0, 3.0, 0.1, 0.2, 0.3])
    made = [
        (deflect.LowPass(10.0, 0.004), lambda o: o.step(x)),
        (deflect.MovingAverage(4, 0.004), lambda o: o.step(x)),
        (deflect.PilotControl(), lambda o: o.step(x * 100, x)),
        (
            deflect.OnlineCompensator(robots[0], project_on_feed=False, max_rate=1.0),
            lambda o: o.step(Q, x * 100)["correction"],
        ),
    ]
    for obj, tick in made:
        tick(obj)
        twin = copy.deepcopy(obj)
        for _ in range(3):
            np.testing.assert_array_equal(tick(twin), tick(obj))
        name = type(obj).__name__
        with pytest.raises(TypeError, match=f"cannot pickle a {name}: it carries"):
            pickle.dumps(obj)
    tracer = deflect.ContourTracer(4e4 * np.eye(2), 1.5e-3, 1.5, 30.0, bias_samples=3)
    with pytest.raises(TypeError, match="cannot pickle a ContourTracer"):
        pickle.dumps(tracer)
    assert copy.deepcopy(tracer).state == tracer.state


# The property deferred twice: for any valid model a pickled copy computes what the original
# does, bit for bit, on any input in its domain.
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

PROPERTY = settings(max_examples=40, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])
_finite = st.floats(-1e3, 1e3, allow_nan=False)


@st.composite
def grid_maps(draw):
    dims = draw(st.integers(1, 3))
    nf, nd = draw(st.integers(1, 3)), draw(st.integers(1, 3))
    axes = []
    for _ in range(dims):
        n = draw(st.integers(2, 4))
        steps = draw(st.lists(st.floats(0.01, 1.0), min_size=n - 1, max_size=n - 1))
        start = draw(st.floats(-1.0, 1.0))
        axes.append(start + np.concatenate([[0.0], np.cumsum(steps)]))
    shape = tuple(len(a) for a in axes) + (nd, nf)
    coeff = st.lists(_finite, min_size=int(np.prod(shape)), max_size=int(np.prod(shape)))
    slopes = np.array(draw(coeff)).reshape(shape) * 1e-6
    offsets = np.array(draw(coeff)).reshape(shape) * 1e-6
    interp = draw(st.sampled_from(["multilinear", "cubic"]))
    m = deflect.GridMap(axes, nf, nd, slopes, offsets, interpolation=interp, out_of_grid="clamp")
    u = np.array(draw(st.lists(st.floats(-0.2, 1.2), min_size=5 * dims, max_size=5 * dims))).reshape(5, dims)
    lo, hi = np.array([a[0] for a in axes]), np.array([a[-1] for a in axes])
    points = lo + u * (hi - lo)
    forces = np.array(draw(st.lists(_finite, min_size=5 * nf, max_size=5 * nf))).reshape(5, nf)
    return m, points, forces


@PROPERTY
@given(grid_maps(), st.sampled_from([pickle.dumps, copy.deepcopy]))
def test_pickled_maps_compute_what_the_original_does(case, how):
    m, points, forces = case
    other = pickle.loads(how(m)) if how is pickle.dumps else how(m)
    np.testing.assert_array_equal(other.displacement_batch(points, forces), m.displacement_batch(points, forces))
    np.testing.assert_array_equal(other.slopes, m.slopes)
    assert other.to_json() == m.to_json()


@PROPERTY
@given(
    st.lists(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3), min_size=2, max_size=6),
    st.floats(0.05, 2.0),
    st.floats(1.0, 50.0),
    st.floats(10.0, 1e4),
    st.lists(st.floats(-0.5, 5.0), min_size=7, max_size=7),
)
def test_pickled_trajectories_and_planners_compute_what_the_original_does(pts, v, a, j, times):
    pts = np.array(pts)
    traj = deflect.plan_polyline(pts, v, a, j, rate_hz=None)
    other = pickle.loads(pickle.dumps(traj))
    for k, val in traj.at(np.array(times)).items():
        np.testing.assert_array_equal(other.at(np.array(times))[k], val, k)
    planner = deflect.LinePlanner(3, v, a, j)
    planner.plan(pts[0], pts[-1])
    copy_ = pickle.loads(pickle.dumps(planner))
    assert copy_.duration == planner.duration
    for k, val in planner.at(np.array(times)).items():
        np.testing.assert_array_equal(copy_.at(np.array(times))[k], val, k)


@PROPERTY
@given(st.lists(st.lists(st.floats(-0.4, 0.4), min_size=6, max_size=6), min_size=1, max_size=4),
       st.lists(st.lists(_finite, min_size=6, max_size=6), min_size=1, max_size=4))
def test_pickled_robots_compute_what_the_original_does(dq, wrench):
    robot = _KR300
    other = pickle.loads(pickle.dumps(robot))
    q = np.array([0.0, -0.9, 1.4, 0.0, 1.0708, 0.0]) + np.array(dq)
    w = np.array(wrench)[: len(q)]
    q = q[: len(w)]
    np.testing.assert_array_equal(other.deflection_batch(q, w), robot.deflection_batch(q, w))
    np.testing.assert_array_equal(other.compliance_batch(q), robot.compliance_batch(q))
    np.testing.assert_array_equal(other.forward_batch(q), robot.forward_batch(q))


_KR300 = deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp")
