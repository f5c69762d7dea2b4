"""Regression tests of the adversarial pass over the Python API: one test per defect found.

Every call here must raise or return finite values, within a second. Calls that once killed
the interpreter (an abort on a 33 GB allocation) or hung it (an unbounded iteration) run in a
child interpreter with a memory limit, so that a regression fails its test instead of taking
the whole session down.
"""

import json
import math
import os
import subprocess
import sys
import time
import tomllib

import numpy as np
import pytest

import deflect
from conftest import KR300_POSE, KR300_TOML, KR300_URDF, REPO

OC = REPO / "data" / "paksoy2025_compliance_oc.csv"
LIMIT_S = 1.0
WRENCH = np.array([-386.1, 386.1, -200.0, 0.0, 0.0, 0.0])

# The child: runs each call in order, reporting its start and then its outcome as JSON lines.
CHILD = r"""
import json, math, resource, sys, time
import numpy as np
# A regression that allocates without bound fails inside this limit instead of swapping.
cap = 6 << 30
resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
import deflect

def finite(v):
    if isinstance(v, np.ndarray):
        return bool(np.all(np.isfinite(v))) if v.dtype.kind in "fc" else True
    if isinstance(v, float):
        return math.isfinite(v)
    if isinstance(v, (list, tuple)):
        return all(finite(x) for x in v)
    if isinstance(v, dict):
        return all(finite(x) for x in v.values())
    if isinstance(v, (int, str, bool, type(None))):
        return True
    return all(finite(getattr(v, a)) for a in dir(v)
               if not a.startswith("_") and isinstance(getattr(v, a), (np.ndarray, float)))

setup, calls = json.loads(sys.argv[1])
exec(setup)
for call in calls:
    print(json.dumps({"start": call}), flush=True)
    t0 = time.perf_counter()
    try:
        value = eval(call)
        out = {"exc": None, "finite": finite(value)}
    except Exception as e:
        out = {"exc": type(e).__name__, "msg": str(e),
               "deflect_error": isinstance(e, deflect.DeflectError)}
    out["seconds"] = time.perf_counter() - t0
    out["call"] = call
    print(json.dumps(out), flush=True)
"""

SETUP = f"""
robot = deflect.SerialRobot.from_urdf({str(KR300_URDF)!r}, {str(KR300_TOML)!r}, "tcp")
q = np.array({KR300_POSE.tolist()!r})
w = np.array({WRENCH.tolist()!r})
"""


def isolated(calls, setup=SETUP):
    """Outcome of each call expression, evaluated in order in one child interpreter. Fails
    the test, naming the call, if the child dies or hangs."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    timeout = 20.0 + 2.0 * len(calls)
    cmd = [sys.executable, "-c", CHILD, json.dumps([setup, calls])]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env, cwd=REPO)
        stdout, code, err = proc.stdout, proc.returncode, proc.stderr
    except subprocess.TimeoutExpired as e:
        out = e.stdout.decode() if isinstance(e.stdout, bytes) else (e.stdout or "")
        stdout, code, err = out, "timeout", ""
    lines = [json.loads(s) for s in stdout.splitlines() if s.startswith("{")]
    results = [x for x in lines if "start" not in x]
    if len(results) != len(calls):
        started = [x["start"] for x in lines if "start" in x]
        last = started[-1] if started else "(before the first call)"
        pytest.fail(f"child ended ({code}) during {last!r}: {err[-2000:]}")
    return results


def assert_refused(results, exc="InputError", match=None):
    for r in results:
        assert r["exc"] == exc, r
        assert r["deflect_error"], r
        assert r["seconds"] < LIMIT_S, r
        if match is not None:
            assert match in r["msg"], r


def quick(f, *args, **kwargs):
    """Calls f, failing if it takes a second or more; returns its value."""
    t0 = time.perf_counter()
    try:
        return f(*args, **kwargs)
    finally:
        assert time.perf_counter() - t0 < LIMIT_S, f"{f.__name__} took too long"


def refused(exc, f, *args, match=None, **kwargs):
    """Asserts that f(*args, **kwargs) raises `exc` (a DeflectError) within a second."""
    t0 = time.perf_counter()
    with pytest.raises(exc, match=match) as info:
        f(*args, **kwargs)
    assert time.perf_counter() - t0 < LIMIT_S
    assert isinstance(info.value, deflect.DeflectError)
    return str(info.value)


# 1 ---------------------------------------------------------------------------------------------
def test_sampling_budget_refuses_huge_trajectories_before_allocating():
    results = isolated(
        [
            "deflect.plan_line([0.2, -0.075], [0.2, 0.075], 1e-6, 49.05, 5207.0)",
            "deflect.plan_line([0.0, 0.0], [2e5, 0.0], 1.0, 10.0, 100.0)",
            "deflect.plan_line([0.0, 0.0], [0.1, 0.0], 1.0, 10.0, 100.0, rate_hz=1e9)",
            "deflect.plan_polyline([[0.0, 0.0], [0.1, 0.0], [0.1, 0.1]], 1e-6, 10.0, 100.0)",
            "deflect.plan_line([0.0, 0.0], [0.1, 0.0], 2e-7, 10.0, 100.0)",
            "deflect.plan_line([0.0, 0.0], [0.1, 0.0], 1.0, 10.0, 100.0, rate_hz=1e300)",
            "deflect.plan_line([0.0, 0.0, 0.0], [0.1, 0.0, 0.0], 1.0, 10.0, 100.0, rate_hz=float('nan'))",
            "deflect.plan_line([0.0, 0.0], [0.1, 0.0], 1.0, 10.0, 100.0, rate_hz=0.0)",
            "deflect.plan_line([0.0, 0.0], [0.1, 0.0], 1.0, 10.0, 100.0, rate_hz=-2000.0)",
        ]
    )
    assert_refused(results)
    assert all("requested; the limit is" in r["msg"] for r in results[:6]), results
    # Within the budget the arrays are filled to the last tick, which lands on the end point.
    tr = quick(deflect.plan_line, [0.0, 0.0], [0.1, 0.05], 0.5, 20.0, 2000.0, rate_hz=4000.0)
    n = len(tr)
    assert n == math.ceil(tr.duration * 4000.0 - 1e-9) + 1
    for a in (tr.position, tr.velocity, tr.acceleration, tr.jerk):
        assert a.shape == (n, 2) and np.all(np.isfinite(a))
    np.testing.assert_array_equal(tr.position[-1], [0.1, 0.05])
    assert tr.t[-1] == tr.duration


# 2 ---------------------------------------------------------------------------------------------
def test_pose_and_rotation_arguments_are_checked_not_projected():
    bottom = np.eye(4)
    bottom[3, 0] = 0.5
    nan_bottom = np.eye(4)
    nan_bottom[3, 2] = np.nan
    results = isolated(
        [
            "deflect.commanded_pose(np.diag([1e200, 1.0, 1.0, 1.0]), np.zeros(6))",
            "deflect.commanded_pose(np.zeros((4, 4)), np.zeros(6))",
            f"deflect.commanded_pose(np.array({bottom.tolist()}), np.zeros(6))",
            "deflect.commanded_pose(np.diag([1.0, 1.0, -1.0, 1.0]), np.zeros(6))",
            "deflect.commanded_pose(np.diag([1.0 + 1e-6, 1.0, 1.0, 1.0]), np.zeros(6))",
            "deflect.SensorCalibration(sensor_to_tcp=np.diag([-1.0, 1.0, 1.0, 1.0]))",
            "deflect.SensorCalibration(sensor_to_tcp=np.diag([1e200, 1.0, 1.0, 1.0]))",
            "deflect.SensorCalibration().tcp_wrench_base(np.zeros(6), np.diag([1.0, -1.0, 1.0, 1.0]))",
            "deflect.SensorCalibration().compensate(np.zeros(6), np.diag([1.0, 1.0, -1.0]))",
            "deflect.SensorCalibration().unloaded_reading(np.diag([1e200, 1.0, 1.0]))",
            "deflect.SensorCalibration().unloaded_reading(np.zeros((3, 3)))",
            "deflect.identify_sensor(np.array([np.eye(3), np.eye(3), -np.eye(3)]), np.zeros((3, 6)))",
            "deflect.identify_sensor(np.array([np.eye(3)] * 3), np.zeros((3, 6)),"
            " sensor_to_tcp=np.diag([1.0, 1.0, 1.0, 2.0]))",
        ]
    )
    assert_refused(results)
    # A proper rigid transform passes unchanged.
    target = deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp").forward(KR300_POSE)
    np.testing.assert_allclose(quick(deflect.commanded_pose, target, np.zeros(6)), target, atol=1e-15)
    # Nothing in the bindings projects a matrix onto a rotation any more.
    for src in (REPO / "crates" / "py" / "src").glob("*.rs"):
        text = src.read_text()
        assert "Rotation3::from_matrix(" not in text, src
        assert "from_matrix_unchecked" not in text, src


# 3 ---------------------------------------------------------------------------------------------
def test_identification_streams_and_refuses_beyond_measurement_budget(kr300):
    n = 200_000
    results = isolated(
        [
            f"deflect.identify_stiffness_from_tcp(robot, np.tile(q, ({n}, 1)), np.tile(w, ({n}, 1)),"
            f" np.zeros(({n}, 6)))",
            f"deflect.identify_stiffness_from_frames(robot, np.tile(q, ({n}, 1)), np.tile(w, ({n}, 1)),"
            f" np.zeros({n}, dtype=int), np.zeros(({n}, 3)))",
        ]
    )
    assert_refused(results, match="measurements")
    # A few thousand measurements still identify the Table 1 stiffnesses.
    rng = np.random.default_rng(3)
    m = 3000
    Q = KR300_POSE + rng.uniform(-0.6, 0.6, (m, 6))
    W = np.hstack([rng.uniform(-750, 750, (m, 3)), rng.uniform(-50, 50, (m, 3))])
    D = np.array([kr300.compliance(qi) @ wi for qi, wi in zip(Q, W)])
    out = quick(deflect.identify_stiffness_from_tcp, kr300, Q, W, D)
    ok = np.array(out["identifiable"])
    assert ok.sum() >= 10
    # Every identifiable axis comes back as the stiffness file has it.
    table = [s["k"] for s in tomllib.loads(KR300_TOML.read_text())["virtual_joint"]]
    truth = np.array([table[s][a] for s, a in zip(out["spring"], out["axis"])])
    np.testing.assert_allclose(out["stiffness"][ok], truth[ok], rtol=1e-6)
    assert np.all(np.isnan(out["compliance"][~ok]))


# 4 ---------------------------------------------------------------------------------------------
def test_python_refuses_what_the_c_api_refuses(kr300):
    cmap = deflect.ComplianceMap.from_csv(OC, out_of_grid="clamp")
    robot2 = deflect.ParallelRobot2()
    for tol in (math.nan, math.inf, -1.0):
        refused(deflect.InputError, deflect.DalembertCorrector, cmap, robot2, iterations=3, tolerance=tol, match="tolerance")
        refused(deflect.InputError, kr300.joint_correction, KR300_POSE, WRENCH, 10, tol, match="tolerance")
    for weight in (-50.0, math.nan, math.inf):
        refused(deflect.InputError, deflect.SensorCalibration, weight=weight, match="weight")
    refused(deflect.InputError, deflect.SensorCalibration, force_offset=[0.0, math.inf, 0.0], match="force_offset")
    reflection = np.diag([1.0, 1.0, -1.0])
    refused(deflect.InputError, deflect.SensorCalibration().compensate, np.zeros(6), reflection, match="rotation")
    nan_bottom = np.eye(4)
    nan_bottom[3, 1] = math.nan
    refused(deflect.InputError, deflect.SensorCalibration, sensor_to_tcp=nan_bottom, match="sensor_to_tcp")
    refused(deflect.InputError, deflect.SensorCalibration().tcp_wrench_base, np.zeros(6), nan_bottom, match="tcp")
    refused(deflect.InputError, deflect.commanded_pose, nan_bottom, np.zeros(6), match="target")
    # What C accepts, Python accepts.
    cal = quick(deflect.SensorCalibration, weight=50.0, sensor_to_tcp=np.eye(4))
    assert cal.weight == 50.0
    assert quick(kr300.joint_correction, KR300_POSE, WRENCH, 10, 1e-9).shape == (6,)


# 5 ---------------------------------------------------------------------------------------------
def test_joint_correction_iteration_budget():
    results = isolated(
        [
            "robot.joint_correction(q, w, 10**6, 0.0)",
            "robot.joint_correction(q, w, 257, 1e-9)",
            "robot.joint_correction(q, w, max_iterations=10**6, tolerance=1e-9)",
        ]
    )
    assert_refused(results, match="iterations")
    kr300 = deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp")
    # The largest budget is accepted; the correction converges in a few steps anyway.
    dq = quick(kr300.joint_correction, KR300_POSE, WRENCH, 256, 1e-9)
    assert np.all(np.isfinite(dq))
    # Tolerance 0 cannot be met: the iteration stops at its fixed point and says so.
    msg = refused(deflect.ConvergenceError, kr300.joint_correction, KR300_POSE, WRENCH, 256, 0.0)
    assert "stalled" in msg


# 6 ---------------------------------------------------------------------------------------------
def test_edge_direction_and_tracer_refuse_degenerate_inputs():
    k = np.eye(2) * 1e4
    refused(deflect.InputError, deflect.edge_direction, k, [1e-3, 0.0], [0.0, 0.0], match="force")
    refused(deflect.InputError, deflect.edge_direction, k, [0.0, 0.0], [1.0, 0.0], match="step")
    refused(deflect.SingularError, deflect.edge_direction, -k, [1e-3, 0.0], [1.0, 0.0])
    refused(deflect.SingularError, deflect.edge_direction, np.diag([1e4, -1e4]), [1e-3, 0.0], [1.0, 0.0])
    # A step straight into the edge: the tool did not move along it (Eq. 21 has no direction).
    refused(deflect.SingularError, deflect.edge_direction, k, [1e-3, 0.0], [10.0, 0.0])
    refused(deflect.SingularError, deflect.ContourTracer, -k, 1e-3, 2.0, 20.0)
    refused(deflect.SingularError, deflect.ContourTracer, np.diag([1e4, -1.0]), 1e-3, 2.0, 20.0)
    tracer = deflect.ContourTracer(k, 1e-3, 2.0, 20.0)
    refused(deflect.SingularError, tracer.set_stiffness, -k)
    refused(deflect.InputError, tracer.set_stiffness, np.array([[1e4, np.nan], [0.0, 1e4]]))
    # The well-posed case still gives the edge angle.
    f = deflect.edge_contact_force(k, [1e-3, 1e-3], 0.0)
    assert quick(deflect.edge_direction, k, [1e-3, 1e-3], f) == pytest.approx(0.0, abs=1e-12)


# 7 ---------------------------------------------------------------------------------------------
def test_overflowing_inputs_raise_instead_of_nan(kr300):
    for w in ([1e308, -1e308, 1e308, 0, 0, 0], [0, 0, 0, 1e308, 1e308, -1e308], [1e12, 0, 0, 0, 0, 0]):
        w = np.array(w, dtype=float)
        refused(deflect.InputError, kr300.deflection, KR300_POSE, w, match="elastic angle")
        refused(deflect.InputError, kr300.spring_angles, KR300_POSE, w, match="elastic angle")
        refused(deflect.InputError, kr300.deflection_batch, np.array([KR300_POSE]), np.array([w]), match="row 0")
        refused(deflect.InputError, kr300.joint_correction, KR300_POSE, w)
    ext = deflect.ComplianceMap.from_csv(OC, out_of_grid="extrapolate")
    for p, f in (([1e300, 1e300], [1e10, 1e10]), ([1e308, 0.0], [1e308, 0.0])):
        refused(deflect.InputError, ext.displacement, p, f, match="overflowed")
        refused(deflect.InputError, ext.displacement_batch, np.array([p]), np.array([f]), match="row 0")
    refused(deflect.InputError, deflect.edge_contact_force, np.eye(2) * 1e308, [1e10, 0.0], 1.0)
    refused(deflect.InputError, ext.cross_validate, np.array([[1e308, 0.0], [0.0, 1e308]]), match="RMS")
    # Results that are returned are finite.
    assert np.all(np.isfinite(quick(ext.displacement, [1e300, 0.0], [1.0, 1.0])))


# 8 ---------------------------------------------------------------------------------------------
def test_bad_argument_types_raise_input_error_naming_the_argument(kr300):
    q, w = KR300_POSE, WRENCH
    cmap = deflect.ComplianceMap.from_csv(OC)
    robot2 = deflect.ParallelRobot2()
    # Counts: negative, huge, fractional or non-numeric integers name the argument.
    for bad in (-1, 10**30, -(10**30), 2.5, 10.0, "3", 1j, None):
        refused(deflect.InputError, kr300.joint_correction, q, w, max_iterations=bad, match="max_iterations")
        refused(deflect.InputError, deflect.MovingAverage, bad, 0.004, match="window")
        refused(deflect.InputError, deflect.DalembertCorrector, cmap, robot2, iterations=bad, match="iterations")
        refused(deflect.InputError, deflect.OnlineCompensator, kr300, moving_average_window=bad, match="moving_average_window")
        refused(deflect.InputError, deflect.ContourTracer, np.eye(2), 1e-3, 2.0, 20.0, bias_samples=bad, match="bias_samples")
        refused(deflect.InputError, deflect.ContourTracer, np.eye(2), 1e-3, 2.0, 20.0, max_steps=bad, match="max_steps")
        refused(deflect.InputError, deflect.paper_limits, bad, match="g_level")
    refused(deflect.InputError, deflect.paper_limits, 300, match="g_level")
    refused(deflect.InputError, deflect.ComplianceMap.fit_csv, OC, n_force=-1, match="n_force")
    refused(deflect.InputError, deflect.DriveTrain, kr300, [1e6] * 6, masses=[(-1, 1.0, (0, 0, 0))], match="after_joint")
    # Real scalars: complex, strings and integers beyond a float name the argument.
    for bad in (1j, "1.0", 10**400, [1.0, 2.0]):
        refused(deflect.InputError, kr300.joint_correction, q, w, 10, bad, match="tolerance")
        # A list of 2 is a valid per-coordinate v_max for a 2-D line; one of 3 is not.
        v_bad = [1.0, 2.0, 3.0] if isinstance(bad, list) else bad
        refused(deflect.InputError, deflect.plan_line, [0, 0], [0.1, 0], v_bad, 10.0, 100.0, match="v_max")
        refused(deflect.InputError, deflect.plan_line, [0, 0], [0.1, 0], 1.0, 10.0, 100.0, rate_hz=bad, match="rate_hz")
        refused(deflect.InputError, deflect.LowPass, bad, 0.004, match="cutoff_hz")
        refused(deflect.InputError, deflect.SensorCalibration, weight=bad, match="weight")
        refused(deflect.InputError, deflect.ParallelRobot2, link=bad, match="link")
        refused(deflect.InputError, deflect.edge_contact_force, np.eye(2), [1e-3, 0], bad, match="edge_angle")
    # Arrays of complex, object or string dtype: named, with the dtype and shape received.
    arrays = {
        "complex128": q.astype(complex),
        "object": np.array([0.0, None, 0, 0, 0, 0], dtype=object),
        "<U3": np.array(["0.0"] * 6),
    }
    for dtype, a in arrays.items():
        for name, call in (
            ("q", lambda a: kr300.deflection(a, w)),
            ("wrench", lambda a: kr300.deflection(q, a[:6])),
            ("Q", lambda a: kr300.deflection_batch(a[None, :], np.zeros((1, 6)))),
            ("W", lambda a: kr300.deflection_batch(q[None, :], a[None, :])),
            ("target", lambda a: deflect.commanded_pose(np.resize(a, (4, 4)), np.zeros(6))),
            ("rotation", lambda a: deflect.SensorCalibration().compensate(np.zeros(6), np.resize(a, (3, 3)))),
            ("position", lambda a: cmap.displacement(a[:2], [0.0, 0.0])),
            ("F", lambda a: cmap.displacement_batch(np.array([[0.2, 0.0]]), a[None, :2])),
            ("start", lambda a: deflect.plan_line(a[:2], [0.1, 0.0], 1.0, 10.0, 100.0)),
            ("points", lambda a: deflect.plan_polyline(np.resize(a, (3, 2)), 1.0, 10.0, 100.0)),
            ("stiffness", lambda a: deflect.DriveTrain(kr300, a)),
            ("Q", lambda a: deflect.identify_stiffness_from_tcp(kr300, a[None, :], np.zeros((1, 6)), np.zeros((1, 6)))),
            ("force_axis", lambda a: deflect.ComplianceMap.fit(np.zeros((1, 2)), a[:1], [1.0], np.zeros((1, 2)))),
        ):
            msg = refused(deflect.InputError, call, a)
            assert msg.startswith(name), (name, msg)
            assert dtype in msg and "shape" in msg, (name, msg)
    # Wrong shapes: the expected and the received shape.
    msg = refused(deflect.InputError, kr300.deflection, np.zeros((2, 3)), w)
    assert "expected shape (6,)" in msg and "got (2, 3)" in msg
    msg = refused(deflect.InputError, kr300.deflection_batch, np.zeros((3, 6)), np.zeros(5))
    assert "W: expected shape (N, 6) or (6,)" in msg and "got (5,)" in msg
    msg = refused(deflect.InputError, deflect.commanded_pose, np.eye(3), np.zeros(6))
    assert "target: expected shape (4, 4)" in msg and "got (3, 3)" in msg
    msg = refused(deflect.InputError, deflect.identify_sensor, np.zeros((2, 3)), np.zeros((2, 6)))
    assert "rotations: expected shape (N, 3, 3)" in msg
    msg = refused(deflect.InputError, cmap.displacement, [[0.2, 0.0]], [0.0, 0.0])
    assert "position" in msg and "(1, 2)" in msg
    refused(deflect.InputError, kr300.deflection, [[1.0, 2.0], [3.0]], w, match="q")  # ragged
    # Lists, tuples, integer arrays and float32 convert as before.
    np.testing.assert_array_equal(kr300.deflection(list(q), tuple(w)), kr300.deflection(q, w))
    q32 = q.astype(np.float32)
    np.testing.assert_array_equal(kr300.deflection(q32, w), kr300.deflection(q32.astype(float), w))
    assert np.all(np.isfinite(kr300.deflection(np.zeros(6, dtype=int), w)))
    assert kr300.joint_correction(q, w, np.int64(10), np.float32(1e-6)).shape == (6,)


# 9 ---------------------------------------------------------------------------------------------
def test_bindings_deny_clippy_indexing_slicing():
    lib = (REPO / "crates" / "py" / "src" / "lib.rs").read_text()
    start = lib.index("#![deny(")
    deny = lib[start : lib.index(")]", start)]
    for lint in ("clippy::indexing_slicing", "clippy::unwrap_used", "clippy::expect_used", "clippy::panic"):
        assert lint in deny, lint
