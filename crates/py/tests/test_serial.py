"""Any serial arm: the UR5 of example-robot-data with springs placed at its joints, static
equilibrium against an independent virtual-work solve, and the 6-D D'Alembert corrector."""

import math

import numpy as np
import pytest

import deflect
from conftest import REPO, NumpyChain, axis_angle, homogeneous, ur5_urdf

UR5_TOML = REPO / "robots" / "ur5" / "ur5_stiffness.toml"
Q0 = np.array([0.3, -1.2, 1.5, -1.9, -1.57, 0.4])


@pytest.fixture(scope="module")
def ur5():
    return deflect.SerialRobot.from_urdf(ur5_urdf(), UR5_TOML, "tool0")


@pytest.fixture(scope="module")
def ur5_ref():
    return NumpyChain(ur5_urdf(), UR5_TOML, "tool0")


def test_joint_placed_springs_match_the_independent_chain(ur5, ur5_ref):
    assert ur5.spring_names == [
        "shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
        "wrist_1_joint", "wrist_2_joint", "wrist_3_joint",
    ]
    rng = np.random.default_rng(5)
    for _ in range(20):
        q = rng.uniform(-math.pi, math.pi, 6)
        w = rng.uniform(-100, 100, 6)
        np.testing.assert_allclose(ur5.deflection(q, w), ur5_ref.deflection(q, w), rtol=1e-9, atol=1e-15)
    # A torque about a joint axis turns only that joint's drive spring: k[0] is along the axis.
    t = ur5.forward(Q0)
    angles = ur5.spring_angles(Q0, np.r_[0, 0, 0, 30.0 * np.array([0, 0, 1.0])])
    assert angles[0, 0] == pytest.approx(30.0 / 3.0e4, rel=1e-12)  # shoulder pan is about z
    assert t.shape == (4, 4)


def test_equilibrium_agrees_with_an_independent_solve_far_better_than_the_paper(ur5, ur5_ref):
    for w in ([0, 0, -100.0, 0, 0, 0], [60.0, -40.0, -80.0, 3.0, -2.0, 1.0]):
        w = np.array(w)
        paper = ur5.deflection(Q0, w)
        eq = ur5.equilibrium(Q0, w)
        ref = ur5_ref.equilibrium(Q0, w)
        assert np.linalg.norm(paper[:3]) > 2e-3  # millimetres: the regime of the comparison
        err_eq, err_paper = np.abs(eq - ref).max(), np.abs(paper - ref).max()
        assert err_eq < 1e-11, err_eq
        assert err_paper > 1e-6  # the paper's first-order model is off by micrometres here
        assert err_eq < 1e-4 * err_paper
        # Second order in the load: 0.1-0.4 % of the deflection at 2-3 mm.
        rel = np.linalg.norm(eq[:3] - paper[:3]) / np.linalg.norm(paper[:3])
        assert 5e-4 < rel < 5e-3, rel
    # Typed errors.
    with pytest.raises(deflect.InputError, match="max_iterations"):
        ur5.equilibrium(Q0, w, max_iterations=0)
    with pytest.raises(deflect.InputError, match="wrench"):
        ur5.equilibrium(Q0, [0, 0, np.nan, 0, 0, 0])
    with pytest.raises(deflect.ConvergenceError):
        ur5.equilibrium(Q0, w * 50, max_iterations=1, tolerance=1e-15)
    with pytest.raises(deflect.InputError, match="MAX_SPRING_ANGLE"):
        ur5.equilibrium(Q0, w * 1e6)


def motion(ur5, rate_hz=2000.0):
    start = ur5.forward(Q0)
    end = start.copy()
    end[:3, 3] += [0.15, -0.1, 0.05]
    end[:3, :3] = axis_angle([0.3, 1.0, 0.2], 0.4) @ start[:3, :3]
    return deflect.plan_pose(start, end, (1.0, 30.0, 600.0), (2.0, 40.0, 800.0), rate_hz=rate_hz)


def inertial_wrench(state, mass, com, inertia):
    """F = -m a_c, M = r x F - (I alpha + omega x I omega), written out with numpy."""
    r_mat = state["pose"][:3, :3]
    r = r_mat @ com
    w, al = state["angular_velocity"], state["angular_acceleration"]
    a_c = state["acceleration"] + np.cross(al, r) + np.cross(w, np.cross(w, r))
    f = -mass * a_c
    i_w = r_mat @ inertia @ r_mat.T
    m = np.cross(r, f) - (i_w @ al + np.cross(w, i_w @ w))
    return np.concatenate([f, m])


def loaded_pose(ref, q, wrench):
    """The TCP of the arm commanded to q and deflected by the wrench (NumpyChain)."""
    t = ref.forward(q)
    d = ref.deflection(q, wrench)
    out = t.copy()
    out[:3, 3] += d[:3]
    angle = np.linalg.norm(d[3:])
    if angle > 0:
        out[:3, :3] = axis_angle(d[3:], angle) @ t[:3, :3]
    return out


def test_corrected_commands_land_the_loaded_arm_on_the_desired_pose(ur5, ur5_ref):
    mass, com = 8.0, np.array([0.0, 0.02, 0.12])
    inertia = np.diag([0.05, 0.06, 0.03])
    c = deflect.SerialDalembertCorrector(ur5, mass, com=com, inertia=inertia, seed=Q0)
    traj = motion(ur5)
    out = c.correct(traj)
    n = len(traj)
    assert out.joints.shape == (n, 6) and out.commanded.shape == (n, 4, 4)
    assert out.iterations.max() <= 3 and np.median(out.iterations) <= 1
    correction = np.linalg.norm(out.commanded[:, :3, 3] - out.desired[:, :3, 3], axis=1)
    assert correction.max() > 1e-4  # a real correction, tenths of a millimetre
    for k in range(0, n, 7):
        state = traj.at(traj.t[k])
        w = inertial_wrench(state, mass, com, inertia)
        np.testing.assert_allclose(out.wrench[k], w, rtol=1e-9, atol=1e-9)
        landed = loaded_pose(ur5_ref, out.joints[k], out.wrench[k])
        np.testing.assert_allclose(landed[:3, 3], state["pose"][:3, 3], atol=2e-8)
        err = np.linalg.norm(axis_angle_log(landed[:3, :3] @ state["pose"][:3, :3].T))
        assert err < 2e-8, (k, err)
    # At rest at the ends: no inertial load, so the command is the rigid pose.
    np.testing.assert_allclose(out.wrench[-1], 0.0, atol=1e-12)
    # step(**at(t)) gives the same tick as the batch (from the same warm-start history).
    c.reset(Q0)
    first = c.step(**traj.at(0.0))
    np.testing.assert_allclose(first["joints"], out.joints[0], atol=1e-12)


def axis_angle_log(r):
    angle = np.arccos(np.clip((np.trace(r) - 1) / 2, -1, 1))
    if angle < 1e-15:
        return np.zeros(3)
    return angle / (2 * np.sin(angle)) * np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])


def test_linearized_model_and_process_wrench(ur5):
    traj = motion(ur5, rate_hz=500.0)
    process = np.array([0.0, 0.0, -80.0, 0.0, 0.0, 0.0])
    exact = deflect.SerialDalembertCorrector(ur5, 5.0, seed=Q0).correct(traj, process_wrench=process)
    lin = deflect.SerialDalembertCorrector(ur5, 5.0, model="linearized", seed=Q0).correct(traj, process)
    np.testing.assert_allclose(exact.wrench[0], process, atol=1e-12)
    # Both cancel millimetres; they differ at second order (micrometres).
    gap = np.abs(exact.commanded[:, :3, 3] - lin.commanded[:, :3, 3]).max()
    corr = np.abs(exact.commanded[:, :3, 3] - exact.desired[:, :3, 3]).max()
    assert corr > 1e-3 and gap < 0.02 * corr
    per_tick = np.tile(process, (len(traj), 1))
    again = deflect.SerialDalembertCorrector(ur5, 5.0, seed=Q0).correct(traj, per_tick)
    np.testing.assert_array_equal(again.joints, exact.joints)


def test_bad_inputs_are_typed_errors(ur5):
    traj = motion(ur5, rate_hz=500.0)
    make = deflect.SerialDalembertCorrector
    with pytest.raises(deflect.InputError, match="payload mass"):
        make(ur5, -1.0)
    with pytest.raises(deflect.InputError, match="asymmetry"):
        make(ur5, 1.0, inertia=[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]])
    with pytest.raises(deflect.SingularError, match="positive semi-definite"):
        make(ur5, 1.0, inertia=np.diag([1.0, -1.0, 1.0]))
    with pytest.raises(deflect.InputError, match="model = 'rigid'"):
        make(ur5, 1.0, model="rigid")
    with pytest.raises(deflect.InputError, match=r"joint_limits: expected shape \(6, 2\)"):
        make(ur5, 1.0, joint_limits=np.zeros((5, 2)))
    with pytest.raises(deflect.InputError, match="lower < upper"):
        make(ur5, 1.0, joint_limits=[[1.0, -1.0]] * 6)
    with pytest.raises(deflect.InputError, match="max_iterations"):
        make(ur5, 1.0, max_iterations=0)
    with pytest.raises(deflect.InputError, match=r"seed\[1\]"):
        make(ur5, 1.0, seed=[0, np.nan, 0, 0, 0, 0])
    c = make(ur5, 5.0, seed=Q0)
    with pytest.raises(deflect.InputError, match="pose"):
        c.step(np.eye(4) * 2)
    with pytest.raises(deflect.InputError, match="acceleration"):
        c.step(ur5.forward(Q0), acceleration=[0, np.inf, 0])
    with pytest.raises(deflect.InputError, match="process_wrench"):
        c.correct(traj, process_wrench=np.zeros((3, 6)))
    with pytest.raises(deflect.InputError, match="plan-only"):
        c.correct(motion(ur5, rate_hz=None))
    # Joint limits: a motion that needs a joint outside them names the joint.
    tight = np.array([[q - 0.01, q + 0.01] for q in Q0])
    c = make(ur5, 5.0, joint_limits=tight, seed=Q0)
    with pytest.raises(deflect.InputError, match="tick .*joint"):
        c.correct(traj)
    # Out of reach: the pose IK cannot converge.
    far = ur5.forward(Q0)
    far[:3, 3] = [3.0, 0.0, 0.0]
    c = make(ur5, 5.0, seed=Q0)
    with pytest.raises((deflect.ConvergenceError, deflect.SingularError)):
        c.step(far)
    # The five-bar corrector points a serial arm to this class.
    cmap = deflect.ComplianceMap.from_csv(REPO / "data" / "paksoy2025_compliance_oc.csv")
    with pytest.raises(deflect.InputError, match="SerialDalembertCorrector"):
        deflect.DalembertCorrector(cmap, ur5)


def so101_urdf():
    """The SO-101 URDF of example-robot-data (a test dependency)."""
    return ur5_urdf().parents[2] / "so_arm_description" / "urdf" / "so101.urdf"


def test_arms_with_fewer_than_six_joints_correct_what_they_control(tmp_path):
    # The KR 300 cut at link_3: three joints, the TCP position only.
    urdf = REPO / "robots" / "kr300" / "kr300_r2500.urdf"
    toml = tmp_path / "s.toml"
    toml.write_text('[[virtual_joint]]\njoint = "a1"\nk = [1e6, 1e6, 1e6]\n')
    robot = deflect.SerialRobot.from_urdf(urdf, toml, "link_3")
    assert robot.dof == 3
    assert deflect.SerialDalembertCorrector(robot, 1.0).task == "position"
    # Six rows on three joints, or an unknown task, are refused naming them.
    with pytest.raises(deflect.InputError, match="6"):
        deflect.SerialDalembertCorrector(robot, 1.0, task="pose")
    with pytest.raises(deflect.InputError, match="task = 'wrist'"):
        deflect.SerialDalembertCorrector(robot, 1.0, task="wrist")
    two = deflect.SerialRobot.from_urdf(urdf, toml, "link_2")
    with pytest.raises(deflect.InputError, match="at least 3"):
        deflect.SerialDalembertCorrector(two, 1.0)


def test_the_so101_lands_its_loaded_gripper_on_the_position_and_reports_the_rest():
    toml = REPO / "robots" / "so101" / "so101_stiffness.toml"
    robot = deflect.SerialRobot.from_urdf(so101_urdf(), toml, tip_link="gripper_frame_link")
    ref = NumpyChain(so101_urdf(), toml, "gripper_frame_link")
    q0 = np.array([-1.0, 0.5, 0.5, -1.0, 0.0])
    # At this pose the five joints control the position and the spin about the gripper axis,
    # not its tilt out of the arm's plane.
    corr = deflect.SerialDalembertCorrector(robot, 0.05, com=[0, 0, 0.02], seed=q0)
    assert corr.task == "position_and_spin"
    import pickle

    assert pickle.loads(pickle.dumps(corr)).task == "position_and_spin"
    assert deflect.SerialDalembertCorrector(robot, 0.05, seed=q0, task="position").task == "position"
    start = robot.forward(q0)
    pose = start.copy()
    # A desired turn of 0.2 rad about the base's vertical: part of it is spin (controlled), the
    # rest tilt (left, reported).
    turn = axis_angle([0.0, 0.0, 1.0], 0.2)
    pose[:3, :3] = turn @ start[:3, :3]
    pose[:3, 3] += [0.01, -0.01, 0.005]
    tick = corr.step(pose, acceleration=[8.0, -5.0, 3.0])
    q = tick["joints"]
    rigid, d = ref.forward(q), ref.deflection(q, tick["wrench"])
    angle = np.linalg.norm(d[3:])
    turn_d = axis_angle(d[3:] if angle > 0 else [0, 0, 1], angle)
    loaded = homogeneous(turn_d @ rigid[:3, :3], rigid[:3, 3] + d[:3])
    # The independent chain puts the loaded gripper on the desired position, its spin about
    # the gripper axis on the desired one; what is left is the tilt, as reported.
    assert np.linalg.norm(loaded[:3, 3] - pose[:3, 3]) < 1e-7
    rel = loaded[:3, :3].T @ pose[:3, :3]
    # Its rotation vector (log map), in the loaded gripper's frame.
    angle = math.acos(min(1.0, (np.trace(rel) - 1) / 2))
    skew = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]])
    rv = angle / (2 * math.sin(angle)) * skew
    assert abs(rv[2]) < 1e-6
    assert tick["free_rotation"] == pytest.approx(np.linalg.norm(rv[:2]), rel=1e-9)
    assert tick["free_rotation"] > 0.01
    # 50 g at a few m/s^2 on 30-60 N m/rad servos: tenths of a millimetre, all corrected.
    assert np.linalg.norm(tick["deflection"][:3]) > 1e-5


@pytest.mark.parametrize(
    "entry, match",
    [
        ('joint = "nope"\nk = [1e4, 1e5, 1e5]', "unknown joint 'nope'"),
        ('joint = "elbow_joint"\nlink = "forearm_link"\nk = [1e4, 1e5, 1e5]', "exactly one of `link` and `joint`"),
        ("k = [1e4, 1e5, 1e5]", "exactly one of `link` and `joint`"),
        ('joint = "elbow_joint"\nk = [1e4, 0.0, 1e5]', "virtual_joint #0"),
        ('joint = "elbow_joint"\nk = [1e4, -1e5, 1e5]', "virtual_joint #0"),
        ('joint = "elbow_joint"\nk = [1e4, 1e-310, 1e5]', "virtual_joint #0"),
        ('joint = "elbow_joint"\nk = [1e4, 1e5]', "3"),
        ('joint = "elbow_joint"\nxyz = [0.0, 0.0, 0.1]\nk = [1e4, 1e5, 1e5]', "xyz"),
    ],
)
def test_stiffness_file_errors_name_the_entry(tmp_path, entry, match):
    toml = tmp_path / "bad.toml"
    toml.write_text("[[virtual_joint]]\n" + entry + "\n")
    with pytest.raises(deflect.LoadError, match=match):
        deflect.SerialRobot.from_urdf(ur5_urdf(), toml, "tool0")


def test_link_inertia_and_gravity_are_opt_in(ur5):
    traj = motion(ur5, rate_hz=500.0)
    plain = deflect.SerialDalembertCorrector(ur5, 3.0, seed=Q0)
    assert plain.link_inertia is False
    np.testing.assert_array_equal(plain.gravity, [0.0, 0.0, 0.0])
    links = deflect.SerialDalembertCorrector(ur5, 3.0, seed=Q0, link_inertia=True)
    assert links.link_inertia is True
    a, b = plain.correct(traj), links.correct(traj)
    # The UR5's links (18 kg) outweigh a 3 kg payload: their inertia adds a correction of the
    # same order, and the payload's wrench itself is unchanged.
    np.testing.assert_allclose(a.wrench, b.wrench, atol=1e-9)
    extra = np.linalg.norm(b.commanded[:, :3, 3] - a.commanded[:, :3, 3], axis=1).max()
    own = np.linalg.norm(a.commanded[:, :3, 3] - a.desired[:, :3, 3], axis=1).max()
    assert extra > 0.3 * own > 0, (extra, own)
    # At rest under gravity: the payload's weight (F = m g, M = r x F) is cancelled.
    g = np.array([0.0, 0.0, -9.81])
    sag = deflect.SerialDalembertCorrector(ur5, 3.0, com=[0.0, 0.0, 0.1], seed=Q0, gravity=g)
    rest = ur5.forward(Q0)
    tick = sag.step(rest)
    r = rest[:3, :3] @ np.array([0.0, 0.0, 0.1])
    np.testing.assert_allclose(tick["wrench"][:3], 3.0 * g, rtol=1e-12)
    np.testing.assert_allclose(tick["wrench"][3:], np.cross(r, 3.0 * g), rtol=1e-9, atol=1e-12)
    assert np.linalg.norm(tick["commanded"][:3, 3] - rest[:3, 3]) > 1e-5
    with pytest.raises(deflect.InputError, match="gravity"):
        deflect.SerialDalembertCorrector(ur5, 3.0, gravity=[0.0, np.nan, 0.0])
