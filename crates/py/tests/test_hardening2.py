"""Hardening, round two: one regression test per defect of the second adversarial pass.

Batches whose result cannot be allocated raise ``MemoryError`` (numpy's answer to the same
request) instead of aborting the interpreter; they run in a child interpreter with a memory
limit (``test_hardening.isolated``), so that a regression fails its test instead of killing
the session. The atlas tells "out of reach" from "beyond the model's validity"; every budget
is named, once per quantity, in its messages.
"""

import json
import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

import deflect
from conftest import KR300_POSE, KR300_TOML, KR300_URDF, REPO
from test_hardening import isolated, quick

OC = REPO / "data" / "paksoy2025_compliance_oc.csv"
ROBOT = deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp")
MAP = deflect.ComplianceMap.from_csv(OC)
OVERLOAD = [1e12, 0.0, 0.0, 0.0, 0.0, 0.0]


def kr300_task():
    """The TCP position and tool axis of the KR 300 at its test pose."""
    t = ROBOT.forward(KR300_POSE)
    return t[:3, 3], t[:3, 2]


# Batches: the five lines, then the same with sizes past any address space ---------
def test_batches_whose_result_cannot_be_allocated_raise_memory_error():
    setup = f"""
robot = deflect.SerialRobot.from_urdf({str(KR300_URDF)!r}, {str(KR300_TOML)!r}, "tcp")
q0 = np.array({KR300_POSE.tolist()!r})
cmap = deflect.ComplianceMap.from_csv({str(OC)!r})
"""
    calls = [
        "robot.deflection_batch(np.broadcast_to(q0, (10**9, 6)), np.zeros(6))",
        "robot.compliance_batch(np.broadcast_to(q0, (10**9, 6)))",
        "robot.forward_batch(np.broadcast_to(q0, (10**9, 6)))",
        "cmap.displacement_batch(np.broadcast_to([0.2, 0.0], (10**10, 2)), [0.0, -245.0])",
        "cmap.field([0.0, -245.0]).displacement_batch(np.broadcast_to([0.2, 0.0], (10**10, 2)))",
        # 4.8e18 bytes: past any address space (numpy's own limit is 2**63 bytes).
        "robot.deflection_batch(np.broadcast_to(q0, (10**17, 6)), np.zeros(6))",
        # The atlas's rows (59 numbers each).
        "deflect._deflect._atlas_chunk(robot, np.broadcast_to([1.5, 0.0, 0.2], (10**9, 3)), "
        "[0.0, 0.0, -1.0], np.zeros(6))",
    ]
    results = isolated(calls, setup=setup)
    for r in results:
        assert r["exc"] == "MemoryError", r
        assert "cannot allocate" in r["msg"] and "bytes" in r["msg"], r
        assert r["seconds"] < 1.0, r
    assert "48000000000 bytes" in results[0]["msg"]
    # The interpreter is still there: a small batch afterwards works (in the same child).
    after = isolated(calls[:1] + ["robot.deflection_batch(q0[None, :], np.zeros(6)).shape"], setup)
    assert after[1]["exc"] is None and after[1]["finite"], after


def test_broadcast_map_arguments_are_read_block_by_block_with_the_same_numbers():
    # Broadcast and strided arguments take the block path (4,096 rows a block): the same
    # numbers as the contiguous call, and an error names the absolute row.
    rng = np.random.default_rng(3)
    n = 10_000
    p = np.c_[rng.uniform(MAP.x[0], MAP.x[-1], n), rng.uniform(MAP.y[0], MAP.y[-1], n)]
    f = rng.uniform(-245.0, 245.0, (n, 2))
    want = MAP.displacement_batch(p, f)
    strided = np.empty((n, 4))
    strided[:, ::2] = p
    np.testing.assert_array_equal(MAP.displacement_batch(strided[:, ::2], f), want)
    np.testing.assert_array_equal(MAP.displacement_batch(p, np.asfortranarray(f)), want)
    one = MAP.displacement_batch(p[:1], f[:1])
    np.testing.assert_array_equal(MAP.displacement_batch(np.broadcast_to(p[0], (n, 2)), f[0]),
                                  np.broadcast_to(one, (n, 2)))
    field = MAP.field(f[0])
    np.testing.assert_array_equal(field.displacement_batch(strided[:, ::2]),
                                  field.displacement_batch(p))
    bad = strided.copy()
    bad[9000, 0] = np.nan
    with pytest.raises(deflect.InputError, match="row 9000"):
        MAP.displacement_batch(bad[:, ::2], f)
    with pytest.raises(deflect.InputError, match="row 9000"):
        field.displacement_batch(bad[:, ::2])


# The atlas: out of reach is not beyond the model ------------------------------------------
def test_an_overload_is_beyond_the_model_not_out_of_reach():
    p, z = kr300_task()
    angles = np.radians([-20.0, 0.0, 20.0])
    r = deflect.posture_sweep(ROBOT, p, z, OVERLOAD, angles=angles, seeds=KR300_POSE)
    assert r["reach"] == ["beyond_model"] * 3 and r["status"] == "beyond_model"
    assert r["best"] is None and not r["reachable"].any()
    assert np.isnan(r["measure"]).all() and np.isnan(r["deflection"]).all()
    ok = deflect.posture_sweep(ROBOT, p, z, np.zeros(6), angles=angles, seeds=KR300_POSE)
    assert ok["status"] == "reachable" and ok["reach"] == ["reachable"] * 3
    far = deflect.posture_sweep(ROBOT, [10.0, 0.0, 0.2], z, OVERLOAD, angles=angles,
                                seeds=KR300_POSE)
    assert far["status"] == "out_of_reach"

    a = deflect.atlas(ROBOT, [p, [10.0, 0.0, 0.2]], z, OVERLOAD, angles=angles, seeds=KR300_POSE)
    assert a.status.tolist() == ["beyond_model", "out_of_reach"]
    assert a.beyond_model_angles.tolist() == [3, 0]
    assert not a.reachable.any()
    assert a.summary() == (
        "reachable: 0 of 2; 1 in reach but beyond the model's validity (a spring past "
        "MAX_SPRING_ANGLE), 1 out of reach"
    )
    b = deflect.atlas(ROBOT, [p], z, WRENCH_PAPER, angles=angles, seeds=KR300_POSE)
    assert b.status.tolist() == ["reachable"] and b.summary() == "reachable: 1 of 1"
    # The new fields travel with the result.
    c = pickle.loads(pickle.dumps(a))
    assert c.status.tolist() == a.status.tolist()


WRENCH_PAPER = [-386.1, 386.1, -60.0, 0.0, 0.0, 0.0]


@pytest.mark.parametrize("chunk_size", [0, -1, True, 2.5, "8"])
def test_chunk_size_must_be_a_positive_integer_with_or_without_an_executor(chunk_size):
    p, z = kr300_task()
    with pytest.raises(deflect.InputError, match="chunk_size"):
        deflect.atlas(ROBOT, [p], z, np.zeros(6), angles=[0.0], chunk_size=chunk_size)


def test_complex_atlas_positions_are_refused_not_truncated():
    p, z = kr300_task()
    with pytest.raises(deflect.InputError, match="positions: expected an array of real"):
        deflect.atlas(ROBOT, np.array([p + 0j]), z, np.zeros(6), angles=[0.0])


# Budgets: one per quantity, named --------------------------------------------------------
def test_a_call_that_stores_every_tick_names_one_budget_however_far_past_it():
    start, end = np.eye(4), np.eye(4)
    # 9e5 m at 1 m/s: 9e5 s, within MAX_DURATION; at 2 MHz 1.8e12 ticks, past MAX_TICKS too.
    end[0, 3] = 9e5
    lim = (1.0, 10.0, 100.0)
    end1 = np.eye(4)
    end1[0, 3] = 1.0
    cases = [
        lambda: deflect.plan_pose(start, end, lim, lim, rate_hz=2e6),  # far past both budgets
        lambda: deflect.plan_pose(start, end1, lim, lim, rate_hz=1e12),  # past the samples only
        lambda: deflect.plan_line([0.0], [9e5], 1.0, 10.0, 100.0, rate_hz=2e6),
        lambda: deflect.plan_line([0.0], [1.0], 1.0, 10.0, 100.0, rate_hz=1e12),
    ]
    for f in cases:
        with pytest.raises(deflect.InputError) as e:
            quick(f)
        msg = str(e.value)
        assert f"the limit is MAX_SAMPLES = {deflect.MAX_SAMPLES} samples" in msg, msg
        assert ".0 samples" not in msg, msg
    assert deflect.MAX_SAMPLES == 2**22 and deflect.MAX_TICKS == 2**40


def test_at_with_more_times_than_the_sample_budget_is_refused_before_copying():
    tr = deflect.plan_line([0.0], [1.0], 1.0, 10.0, 100.0, rate_hz=None)
    with pytest.raises(deflect.InputError, match=r"t: 1000000000000 entries; the limit is "
                                                 r"MAX_SAMPLES = 4194304 entries"):
        quick(tr.at, np.broadcast_to(0.5, (10**12,)))


def test_budgets_on_copied_arguments_are_named_before_any_copy():
    p, z = kr300_task()
    huge = 10**12
    cases = [
        (lambda: deflect.posture_sweep(ROBOT, p, z, np.zeros(6),
                                       angles=np.broadcast_to(0.0, (huge,))),
         f"angles: {huge} entries; the limit is MAX_ANGLES = {deflect.MAX_ANGLES}"),
        (lambda: deflect.posture_sweep(ROBOT, p, z, np.zeros(6),
                                       seeds=np.broadcast_to(KR300_POSE, (huge, 6))),
         f"seeds: {huge} rows; the limit is MAX_SEEDS = {deflect.MAX_SEEDS}"),
        (lambda: deflect.posture_sweep(ROBOT, p, z, np.zeros(6),
                                       measure=np.broadcast_to([1.0, 0, 0], (huge, 3))),
         f"measure: {huge} directions; the limit is MAX_DIRECTIONS = {deflect.MAX_DIRECTIONS}"),
        (lambda: deflect.plan_polyline(np.broadcast_to([0.0, 0.0], (huge, 2)), 1.0, 1.0, 1.0),
         f"points: {huge} rows; the limit is MAX_POINTS = {deflect.MAX_POINTS}"),
        (lambda: deflect.Trajectory.from_samples(np.broadcast_to([0.0], (huge, 1)), 2000.0),
         f"position: {huge} samples; the limit is MAX_SAMPLES = {deflect.MAX_SAMPLES}"),
        (lambda: deflect.ComplianceMap.fit(
            np.broadcast_to([0.2, 0.0], (huge, 2)), [0], [1.0], displacement=np.zeros((1, 2))),
         f"positions: {huge} measurements; the limit is MAX_MEASUREMENTS = "
         f"{deflect.MAX_MEASUREMENTS}"),
        (lambda: MAP.cross_validate(np.broadcast_to([0.0, -245.0], (huge, 2))),
         f"forces: {huge} rows; the limit is MAX_MEASUREMENTS"),
    ]
    for f, match in cases:
        with pytest.raises(deflect.InputError) as e:
            quick(f)
        assert match in str(e.value), (match, str(e.value))


# Trajectory.at outside [0, duration]: documented, and as documented -----------------------
def test_at_outside_the_motion_holds_the_end_states_as_documented():
    tr = deflect.plan_line([0.0, 0.0], [0.1, 0.05], 0.5, 20.0, 2000.0, rate_hz=None)
    assert "before 0" in deflect.Trajectory.at.__doc__.lower()
    before, after = tr.at(-1.0), tr.at(1e9)
    np.testing.assert_array_equal(before["position"], [0.0, 0.0])
    np.testing.assert_array_equal(after["position"], [0.1, 0.05])
    for s in (before, after):
        for k in ("velocity", "acceleration", "jerk"):
            np.testing.assert_array_equal(s[k], [0.0, 0.0])
    pose_end = np.eye(4)
    pose_end[0, 3] = 0.1
    pt = deflect.plan_pose(np.eye(4), pose_end, (0.5, 20.0, 2000.0), (1.0, 10.0, 100.0),
                           rate_hz=None)
    assert "before 0" in deflect.PoseTrajectory.at.__doc__.lower()
    np.testing.assert_array_equal(pt.at(-1.0)["pose"], np.eye(4))
    np.testing.assert_array_equal(pt.at(1e9)["pose"], pose_end)
    np.testing.assert_array_equal(pt.at(1e9)["velocity"], np.zeros(3))


# Results that grow with a trajectory's ticks are allocated fallibly ----------------------
_TICKS_CHILD = r"""
import json, os, resource, sys
import numpy as np
import deflect
urdf, toml, q0 = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
start, end = np.eye(4), np.eye(4)
end[0, 3] = 1.0
lim = (1.0, 10.0, 100.0)
d = deflect.plan_pose(start, end, lim, lim, rate_hz=None).duration
rate = 4.0e6 / d  # about 4e6 ticks, inside MAX_SAMPLES: 0.64 GB of states, 1 GB of arrays
times = np.linspace(0.0, d, 4_000_000)
robot = deflect.SerialRobot.from_urdf(urdf, toml, "tcp")
corrector = deflect.SerialDalembertCorrector(robot, 5.0, seed=np.array(q0))
small = deflect.plan_pose(start, end, lim, lim, rate_hz=100.0)
small.pose, small.at(times[:10])  # every code path once, before the cap
plan = deflect.plan_pose(start, end, lim, lim, rate_hz=rate)
size = os.sysconf("SC_PAGE_SIZE") * int(open("/proc/self/statm").read().split()[0])
resource.setrlimit(resource.RLIMIT_AS, (size + (256 << 20), resource.RLIM_INFINITY))
res = {}
for name, call in [
    ("samples", lambda: plan.pose),
    ("at", lambda: plan.at(times)),
    ("correct", lambda: corrector.correct(plan)),
    ("small_after", lambda: small.at(times[:10])["pose"].shape),
]:
    try:
        out = call()
        res[name] = "ok" if name != "small_after" else list(out)
    except MemoryError as e:
        res[name] = "MemoryError: " + str(e)
print(json.dumps(res))
"""


def test_results_as_long_as_a_trajectory_raise_memory_error_not_abort():
    """A pose trajectory's samples, `at` over many times and the serial D'Alembert
    correction of every tick allocate their results fallibly: with the address space capped
    256 MB above the process's size, each raises MemoryError naming what it could not
    allocate (an infallible allocation would abort the child), and the interpreter goes on."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               MALLOC_MMAP_THRESHOLD_="131072", MALLOC_ARENA_MAX="1")
    proc = subprocess.run(
        [sys.executable, "-c", _TICKS_CHILD, str(KR300_URDF), str(KR300_TOML),
         json.dumps(KR300_POSE.tolist())],
        capture_output=True, text=True, timeout=120, env=env,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    res = json.loads(proc.stdout.strip().splitlines()[-1])
    assert res["samples"].startswith("MemoryError: the pose samples: cannot allocate"), res
    assert res["at"].startswith("MemoryError: the states: cannot allocate"), res
    assert res["correct"].startswith("MemoryError: the corrected trajectory: cannot allocate"), res
    assert res["small_after"] == [10, 4, 4], res
