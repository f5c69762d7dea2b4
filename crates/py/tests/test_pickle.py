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
