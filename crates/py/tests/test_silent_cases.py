"""Issue 28's silent cases: inputs that came back non-finite or nonsensical without a word.
Each now raises a typed error naming what was wrong; each test here fails on the old
behaviour (noted per test)."""

import numpy as np
import pytest

import deflect
from conftest import KR300_POSE, REPO, ur5_urdf

UR5_TOML = REPO / "robots/ur5/ur5_stiffness.toml"
Q0 = np.array([0.3, -1.2, 1.5, -1.9, -1.57, 0.4])


@pytest.fixture(scope="module")
def ur5():
    return deflect.SerialRobot.from_urdf(ur5_urdf(), UR5_TOML, "tool0")


# Before: jerk [inf, inf, 0, -inf, -inf], duration inf, accelerations inf.
@pytest.mark.parametrize(
    "position, rate, match",
    [
        (np.array([0.0, 1e300, -1e300, 1e300, 0.0]), 1000.0, "finite differences overflow"),
        (np.linspace(0.0, 1.0, 6), 5e-324, "rate_hz"),
        (np.linspace(0.0, 1.0, 6), 1e300, "finite differences overflow"),
        (np.linspace(0.0, 1.0, 10), 3e-308, "duration of the samples overflows"),
    ],
)
def test_sampled_trajectories_refuse_overflowing_differences(position, rate, match):
    with pytest.raises(deflect.InputError, match=match):
        deflect.Trajectory.from_samples(position, rate)
    # Still fine at a sane rate and scale.
    tr = deflect.Trajectory.from_samples(np.linspace(0.0, 1.0, 6) ** 2, 10.0)
    assert np.isfinite(tr.jerk).all()


# Before: a NaN rotation.
def test_commanded_pose_refuses_a_rotation_past_pi_and_non_finite_input():
    with pytest.raises(deflect.InputError, match="at most pi"):
        deflect.commanded_pose(np.eye(4), np.full(6, 1e300))
    with pytest.raises(deflect.InputError, match="deflection"):
        deflect.commanded_pose(np.eye(4), [0.0, 0.0, np.nan, 0.0, 0.0, 0.0])
    pose = deflect.commanded_pose(np.eye(4), [1e-3, 0.0, 0.0, 0.0, 0.0, 1e-3])
    assert np.isfinite(pose).all() and pose[0, 3] == -1e-3


# Before: a sub-normal rate planned one tick; limits of 1e-300 planned 3e299 s.
def test_planner_refuses_sub_normal_rates_and_endless_motions(ur5):
    with pytest.raises(deflect.InputError, match="rate_hz"):
        deflect.plan_line([0.0], [0.1], 1.0, 10.0, 100.0, rate_hz=5e-324)
    start = ur5.forward(Q0)
    end = start.copy()
    end[0, 3] += 0.1
    with pytest.raises(deflect.InputError, match="MAX_DURATION"):
        deflect.plan_pose(start, end, (1e-300, 1e-300, 1e-300), (1.0, 10.0, 100.0), rate_hz=None)
    with pytest.raises(deflect.InputError, match="MAX_DURATION"):
        deflect.plan_line([0.0], [0.1], 1e-300, 10.0, 100.0, rate_hz=None)
    # 0.1 m at 1 mm/s is 100 s: planned.
    assert deflect.plan_line([0.0], [0.1], 1e-3, 10.0, 100.0, rate_hz=None).duration == pytest.approx(
        100.0, rel=1e-3
    )


# Before: the imaginary part was dropped with a ComplexWarning.
def test_atlas_refuses_complex_positions(ur5):
    p = np.array([[0.4, 0.1, 0.4]], dtype=complex)
    with pytest.raises(deflect.InputError, match="positions.*complex"):
        deflect.atlas(ur5, p, [0.0, 0.0, -1.0], np.zeros(6))


# Before: t=nan was accepted; diag(1, 1, 5) (no rigid body's inertia) too.
def test_serial_corrector_refuses_nan_time_and_impossible_inertia(ur5):
    c = deflect.SerialDalembertCorrector(ur5, 2.0, seed=Q0)
    pose = ur5.forward(Q0)
    with pytest.raises(deflect.InputError, match="t"):
        c.step(pose, t=float("nan"))
    c.step(pose, t=0.25)
    with pytest.raises(deflect.InputError, match="triangle|sum of the other two"):
        deflect.SerialDalembertCorrector(ur5, 2.0, inertia=np.diag([1.0, 1.0, 5.0]), seed=Q0)
    deflect.SerialDalembertCorrector(ur5, 2.0, inertia=np.diag([1.0, 1.0, 2.0]), seed=Q0)


# Before: finite, meaningless results.
@pytest.mark.parametrize(
    "call",
    [
        lambda r, q: r.equilibrium(q, np.ones(6)),
        lambda r, q: r.linear_deflection(q, np.ones(6)),
        lambda r, q: r.forward_batch(q[None]),
        lambda r, q: r.compliance_batch(q[None]),
        lambda r, q: r.deflection(q, np.ones(6)),
        lambda r, q: r.forward(q),
    ],
)
def test_joint_positions_past_the_documented_range_are_refused(ur5, call):
    q = Q0.copy()
    q[2] = 1e300
    with pytest.raises(deflect.InputError, match="MAX_JOINT_POSITION"):
        call(ur5, q)
    q[2] = 1e5  # 16,000 turns: still accepted
    assert np.isfinite(call(ur5, q)).all()


# Before: the NaN in the ignored z column went unnoticed.
def test_a_nan_in_the_ignored_z_column_is_refused():
    m = deflect.ComplianceMap.from_csv(REPO / "data/paksoy2025_compliance_oc.csv")
    field = m.field([100.0, -50.0])
    for call in [
        lambda: field.displacement_batch([[0.2, 0.0, np.nan]]),
        lambda: field.displacement([0.2, 0.0, np.nan]),
        lambda: m.displacement_batch([[0.2, 0.0, 0.0], [0.2, 0.0, np.inf]], [100.0, 0.0]),
        lambda: m.displacement([0.2, 0.0, np.nan], [100.0, 0.0]),
    ]:
        with pytest.raises(deflect.InputError, match="position"):
            call()
    np.testing.assert_array_equal(
        field.displacement_batch([[0.2, 0.0, 7.0]]), field.displacement_batch([[0.2, 0.0]])
    )


URDF = """<robot name="r">
  <link name="base"/><link name="l1"/><link name="tip"/>{extra}
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.3"/><axis xyz="{axis}"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="fixed"><parent link="l1"/><child link="tip"/><origin xyz="0.5 0 0"/></joint>
</robot>"""
STIFF = '[[virtual_joint]]\njoint = "j1"\nk = [1e4, 1e5, 1e5]\n'


# Before: both loaded without a word (the second root ignored; the axis silently scaled).
def test_urdf_with_two_roots_is_refused_and_a_long_axis_is_normalised():
    with pytest.raises(deflect.LoadError, match="root links.*'base', 'stray'"):
        deflect.SerialRobot.from_strings(URDF.format(extra='<link name="stray"/>', axis="0 0 1"), STIFF, "tip")
    unit = deflect.SerialRobot.from_strings(URDF.format(extra="", axis="0 0 1"), STIFF, "tip")
    long = deflect.SerialRobot.from_strings(URDF.format(extra="", axis="0 0 2"), STIFF, "tip")
    np.testing.assert_allclose(long.forward([0.7]), unit.forward([0.7]), atol=1e-15)
    np.testing.assert_allclose(long.forward([0.7])[:2, 3], [0.5 * np.cos(0.7), 0.5 * np.sin(0.7)])


# Before: 1e7-1e8 times aborted the interpreter on allocation (the fast path copied them all
# before the count was checked). Proven in a child whose address space leaves 40 MB: the
# old copy of 80 MB could not be made and aborted the child.
_AT_CHILD = r"""
import json, os, resource
import numpy as np
import deflect
tr = deflect.plan_line([0.0], [0.1], 1.0, 10.0, 100.0, rate_hz=None)
times = np.zeros(10_000_000)
tr.at(np.zeros(10))
size = os.sysconf("SC_PAGE_SIZE") * int(open("/proc/self/statm").read().split()[0])
resource.setrlimit(resource.RLIMIT_AS, (size + (40 << 20), resource.RLIM_INFINITY))
out = {}
for name, arg in [("array", times), ("list", [0.0] * 3_000_000)]:
    try:
        tr.at(arg)
        out[name] = "ok"
    except deflect.InputError as e:
        out[name] = str(e)
    except MemoryError:
        out[name] = "MemoryError"
print(json.dumps(out))
"""


def test_trajectory_at_refuses_more_times_than_the_budget_before_copying():
    import json
    import os
    import subprocess
    import sys

    env = dict(os.environ, MALLOC_MMAP_THRESHOLD_="131072", MALLOC_ARENA_MAX="1", OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, "-c", _AT_CHILD], capture_output=True, text=True, timeout=120, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert "MAX_SAMPLES" in out["array"], out
    # A list of 3e6 is within the budget: evaluated, or refused as memory, never an abort.
    assert out["list"] in ("ok", "MemoryError"), out
    tr = deflect.plan_line([0.0], [0.1], 1.0, 10.0, 100.0, rate_hz=None)
    assert tr.at(np.linspace(0.0, 1.0, 1000))["position"].shape == (1000, 1)
