"""Drive-train errors and contour tracing from Python (contour-tracking paper, Eq. 3-24)."""

import math

import numpy as np
import pytest

import deflect
from conftest import KR300_POSE, KR300_TOML, KR300_URDF

RNG = np.random.default_rng(7)

URDF = """<robot name="two_link">
  <link name="base"><inertial><origin xyz="0 0 0.1"/><mass value="50"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="upper"><inertial><origin xyz="0.4 0 0"/><mass value="12"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="fore"><inertial><origin xyz="0.3 0 0.01"/><mass value="6"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="tool"/>
  <joint name="a1" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="a2" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.8 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="fore"/><child link="tool"/><origin xyz="0.6 0 0"/></joint>
</robot>"""

STIFFNESS = """
[[virtual_joint]]
link = "upper"
k = [inf, 2.0e5, inf]

[[joint]]
name = "a1"
stiffness = 1.0e5   # N m/rad
backlash = 1.0e-4   # rad

[[joint]]
name = "a2"
stiffness = 8.0e4
backlash = 2.0e-4
"""

PLANAR = """<robot name="planar">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="tip"/>
  <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="t" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="0.4 0 0"/></joint>
</robot>"""

PLANAR_K = """
[[virtual_joint]]
link = "l1"
k = [inf, inf, 2000.0]
[[virtual_joint]]
link = "l2"
k = [inf, inf, 1000.0]
[[joint]]
name = "j1"
stiffness = 2000.0
[[joint]]
name = "j2"
stiffness = 1000.0
"""


@pytest.fixture
def two_link():
    robot = deflect.SerialRobot.from_strings(URDF, STIFFNESS, "tool")
    return robot, deflect.DriveTrain.from_strings(robot, URDF, STIFFNESS)


def test_gravity_and_eq10_by_hand(two_link):
    robot, drive = two_link
    assert drive.stiffness == [1.0e5, 8.0e4]
    assert drive.backlash == [1.0e-4, 2.0e-4]
    assert [(j, m) for j, m, _ in drive.masses] == [(0, 12.0), (1, 6.0)]
    # At q = 0 the CoMs sit 0.4 m (12 kg) and 0.8 + 0.3 m (6 kg) from a1 along x; about +y
    # gravity turns them down, so the drives hold u = -(sum x m) g.
    g = drive.gravity_torques(np.zeros(2))
    assert g == pytest.approx([-(0.4 * 12 + 1.1 * 6) * 9.80665, -(0.3 * 6) * 9.80665])
    # Eq. 10 with a contact force of 100 N along +z at the TCP (x = 1.4 m from a1, 0.6 m from
    # a2): J^T F about +y is -x F_z.
    w = np.array([0.0, 0.0, 100.0, 0.0, 0.0, 0.0])
    c = drive.contact_torques(np.zeros(2), w)
    assert c == pytest.approx([-140.0, -60.0])
    u = drive.joint_torques(np.zeros(2), w)
    assert u == pytest.approx(g + c)
    q = drive.correct_joints(np.zeros(2), w)
    expect = -np.sign(u) * np.array([1.0e-4, 2.0e-4]) - u / np.array([1.0e5, 8.0e4])
    assert q == pytest.approx(expect, rel=1e-12)
    t = drive.compensated_forward(np.zeros(2), w)
    assert t == pytest.approx(robot.forward(q))


def test_programmatic_masses_match_the_urdf(two_link):
    robot, drive = two_link
    by_hand = deflect.DriveTrain(
        robot,
        [1.0e5, 8.0e4],
        [1.0e-4, 2.0e-4],
        masses=[(0, 12.0, (0.4, 0.0, 0.0)), (1, 6.0, (0.3, 0.0, 0.01))],
    )
    for _ in range(5):
        q = RNG.uniform(-1, 1, 2)
        assert by_hand.gravity_torques(q) == pytest.approx(drive.gravity_torques(q))
    # Sideways gravity: joints about y feel only the x and z components.
    side = deflect.DriveTrain(robot, [1.0, 1.0], gravity=(0.0, 9.81, 0.0), masses=by_hand.masses)
    assert side.gravity_torques(np.array([0.3, -0.2])) == pytest.approx([0.0, 0.0], abs=1e-12)


def test_planar_stiffness_inverts_the_compliance():
    robot = deflect.SerialRobot.from_strings(PLANAR, PLANAR_K, "tip")
    drive = deflect.DriveTrain.from_strings(robot, PLANAR, PLANAR_K)
    q = np.array([0.4, 1.3])
    k = drive.cartesian_stiffness(q, planar="xy")
    c = robot.compliance(q)[:2, :2]
    assert k @ c == pytest.approx(np.eye(2), abs=1e-10)
    with pytest.raises(deflect.SingularError):
        drive.cartesian_stiffness(np.array([0.4, 0.0]), planar="xy")
    with pytest.raises(deflect.InputError):
        drive.cartesian_stiffness(q)  # 6x6 needs 6 joints
    with pytest.raises(deflect.InputError):
        drive.cartesian_stiffness(q, planar="yz")


def test_kr300_cartesian_stiffness_against_numpy():
    robot = deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp")
    k_theta = np.array([1.0e7, 6.0e6, 4.0e6, 1.0e6, 8.0e5, 5.0e5])
    drive = deflect.DriveTrain(robot, k_theta)
    k = drive.cartesian_stiffness(KR300_POSE)
    j = robot.joint_jacobian(KR300_POSE)
    ref = np.linalg.inv(j @ np.diag(1.0 / k_theta) @ j.T)
    assert k == pytest.approx(ref, rel=1e-7, abs=1e-6 * np.abs(ref).max())


def test_loader_and_input_errors(two_link):
    robot, drive = two_link
    with pytest.raises(deflect.LoadError, match="a2"):
        deflect.DriveTrain.from_strings(robot, URDF, '[[joint]]\nname = "a1"\nstiffness = 1.0\n')
    with pytest.raises(deflect.LoadError):
        deflect.DriveTrain.from_urdf(robot, "/nonexistent.urdf", "/nonexistent.toml")
    with pytest.raises(deflect.InputError):
        deflect.DriveTrain(robot, [1.0, -1.0])
    with pytest.raises(deflect.InputError):
        deflect.DriveTrain(robot, [1.0, 1.0], masses=[(5, 1.0, (0.0, 0.0, 0.0))])
    with pytest.raises(deflect.InputError):
        drive.correct_joints(np.zeros(3), np.zeros(6))
    with pytest.raises(deflect.InputError):
        drive.correct_joints(np.zeros(2), np.array([np.nan, 0, 0, 0, 0, 0]))
    assert issubclass(deflect.InputError, ValueError)


def test_edge_direction_eq21():
    for _ in range(200):
        a = RNG.uniform(-1, 1, (2, 2)) * 100.0
        k = a @ a.T + np.eye(2) * 1e3
        edge = RNG.uniform(-math.pi, math.pi)
        t1 = edge + RNG.uniform(-1.2, 1.2)  # within 70 degrees of the edge
        step = 1e-3 * np.array([math.cos(t1), math.sin(t1)])
        f = deflect.edge_contact_force(k, step, edge)
        # Independent Eq. 18-20.
        r = np.linalg.norm(step)
        e = step - r * math.cos(edge - t1) * np.array([math.cos(edge), math.sin(edge)])
        assert f == pytest.approx(k @ e, rel=1e-12, abs=1e-12)
        got = deflect.edge_direction(k, step, f)
        assert math.remainder(got - edge, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(deflect.SingularError):
        deflect.edge_direction(np.ones((2, 2)), [1e-3, 0.0], [1.0, 0.0])


def circle_world(k, center, radius, command):
    """A point tool of constant isotropic stiffness k against a rigid disc: the tool stops on
    the circle, the force is k (command - tool)."""
    d = command - center
    n = np.linalg.norm(d)
    if n >= radius:
        return command, np.zeros(2)
    tool = center + d / n * radius
    return tool, k * (command - tool)


def test_tracer_closes_a_circle_from_python():
    k = 5000.0
    center, radius = np.array([0.6, 0.05]), 0.08
    tracer = deflect.ContourTracer(k * np.eye(2), 1.5e-3, 1.5, 30.0, target_force=6.0, bias_samples=3)
    assert tracer.state == "init"
    bias = np.array([0.3, -0.2])
    cmd = np.array([0.45, 0.05])
    tools, states = [], set()
    for _ in range(2000):
        tool, f = circle_world(k, center, radius, cmd)
        cmd, state = tracer.step(cmd, f + bias)
        states.add(state)
        if tracer.contact:
            tools.append(tracer.tool)
        if tracer.finished:
            break
    assert state == "done", state
    assert {"init", "approach", "trace", "done"} <= states
    assert tracer.bias == pytest.approx(tuple(bias))
    tools = np.array(tools)
    # The estimated tool positions (command - K^-1 F) lie on the circle.
    assert np.abs(np.linalg.norm(tools - center, axis=1) - radius).max() < 1e-9
    stats = tracer.stats()
    assert stats["path_length"] == pytest.approx(2 * math.pi * radius, rel=0.05)
    assert stats["longest_loss"] == 0
    assert stats["max_force"] < 30.0
    # Finished tracers hold their position.
    again, state = tracer.step(cmd, np.zeros(2))
    assert state == "done" and again == pytest.approx(cmd)


def test_tracer_errors():
    with pytest.raises(deflect.InputError):
        deflect.ContourTracer(np.eye(2), 1e-3, 5.0, 2.0)  # jam below contact
    with pytest.raises(deflect.SingularError):
        deflect.ContourTracer(np.ones((2, 2)), 1e-3, 2.0, 20.0)
    t = deflect.ContourTracer(np.eye(2) * 1e4, 1e-3, 2.0, 20.0)
    with pytest.raises(deflect.InputError):
        t.step([0.0, 0.0, 0.0], [0.0, 0.0])
    with pytest.raises(deflect.InputError):
        t.step([0.0, np.inf], [0.0, 0.0])
    with pytest.raises(deflect.InputError):
        t.set_stiffness(np.eye(3))
    assert t.state == "init" and t.tool is None and not t.contact
