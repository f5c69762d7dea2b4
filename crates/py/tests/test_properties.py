"""Property tests (hypothesis) of the Python API: finite in-range inputs give finite outputs,
non-finite or out-of-range inputs give `deflect.InputError`, and the batch calls agree with
their loops. Each test is sized to run in a few seconds."""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import deflect
from conftest import KR300_POSE, KR300_TOML, KR300_URDF, REPO

OC = REPO / "data" / "paksoy2025_compliance_oc.csv"
ROBOT = deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp")
MAP = deflect.ComplianceMap.from_csv(OC)
# No example database: nothing is written into the checkout.
FAST = settings(max_examples=150, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])

NON_FINITE = st.sampled_from([math.nan, math.inf, -math.inf])


def floats(lo, hi):
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


# Joints anywhere within the KR 300's limits; wrenches up to 3 kN and 300 N m.
joints = st.tuples(*[floats(lo, hi) for lo, hi in ROBOT.joint_limits]).map(np.array)
wrenches = st.tuples(*([floats(-3000.0, 3000.0)] * 3 + [floats(-300.0, 300.0)] * 3)).map(np.array)
# Positions inside the map's grid, forces up to 500 N.
grid_points = st.tuples(floats(MAP.x[0], MAP.x[-1]), floats(MAP.y[0], MAP.y[-1])).map(np.array)
map_forces = st.tuples(floats(-500.0, 500.0), floats(-500.0, 500.0)).map(np.array)
interpolations = st.sampled_from(["bilinear", "bicubic"])


def assert_input_error(f, *args, **kwargs):
    with pytest.raises(deflect.InputError) as info:
        f(*args, **kwargs)
    assert isinstance(info.value, deflect.DeflectError)


def close(a, b, rtol=1e-12):
    """Equal to `rtol` relative to the larger magnitude of the two arrays."""
    scale = max(np.abs(a).max(), np.abs(b).max(), 1e-300)
    np.testing.assert_allclose(a, b, rtol=0, atol=rtol * scale)


def test_input_error_is_a_deflect_error():
    assert issubclass(deflect.InputError, deflect.DeflectError)
    assert issubclass(deflect.DeflectError, ValueError)


@FAST
@given(q=joints, w=wrenches)
def test_deflection_and_compliance_are_finite_in_range(q, w):
    d = ROBOT.deflection(q, w)
    c = ROBOT.compliance(q)
    assert d.shape == (6,) and np.all(np.isfinite(d))
    assert c.shape == (6, 6) and np.all(np.isfinite(c))
    # Millimetres under kilonewtons, not metres.
    assert np.abs(d[:3]).max() < 0.05


@FAST
@given(p=grid_points, f=map_forces, interpolation=interpolations)
def test_map_displacement_is_finite_inside_the_grid(p, f, interpolation):
    d = MAP.displacement(p, f, interpolation=interpolation)
    assert d.shape == (2,) and np.all(np.isfinite(d))


@settings(max_examples=80, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    dim=st.sampled_from([2, 3]),
    start=st.lists(floats(-0.5, 0.5), min_size=3, max_size=3),
    end=st.lists(floats(-0.5, 0.5), min_size=3, max_size=3),
    v_max=floats(0.05, 2.0),
    a_max=floats(0.5, 50.0),
    j_max=floats(10.0, 5000.0),
    rate_hz=floats(250.0, 4000.0),
)
def test_plan_line_is_finite_for_realistic_limits(dim, start, end, v_max, a_max, j_max, rate_hz):
    start, end = np.array(start[:dim]), np.array(end[:dim])
    assume(np.linalg.norm(end - start) > 1e-6)
    tr = deflect.plan_line(start, end, v_max, a_max, j_max, rate_hz=rate_hz)
    n = len(tr)
    assert n >= 2 and math.isfinite(tr.duration)
    for a in (tr.position, tr.velocity, tr.acceleration, tr.jerk):
        assert a.shape == (n, dim) and np.all(np.isfinite(a))
    np.testing.assert_array_equal(tr.position[-1], end)
    speed = np.linalg.norm(tr.velocity, axis=1)
    assert speed.max() <= v_max * (1 + 1e-9)


@FAST
@given(
    q=joints,
    w=wrenches,
    which=st.sampled_from(["q", "wrench"]),
    index=st.integers(0, 5),
    bad=NON_FINITE,
)
def test_non_finite_robot_inputs_raise_input_error(q, w, which, index, bad):
    (q if which == "q" else w)[index] = bad
    assert_input_error(ROBOT.deflection, q, w)
    assert_input_error(ROBOT.spring_angles, q, w)
    assert_input_error(ROBOT.joint_correction, q, w)
    assert_input_error(ROBOT.deflection_batch, q[None, :], w[None, :])
    if which == "q":
        assert_input_error(ROBOT.compliance, q)
        assert_input_error(ROBOT.forward, q)


@FAST
@given(
    q=joints,
    w=wrenches,
    tolerance=st.one_of(NON_FINITE, floats(-1e300, -1e-300)),
    iterations=st.integers(257, 10**40),
)
def test_out_of_range_correction_arguments_raise_input_error(q, w, tolerance, iterations):
    assert_input_error(ROBOT.joint_correction, q, w, 10, tolerance)
    assert_input_error(ROBOT.joint_correction, q, w, iterations, 1e-9)
    assert_input_error(ROBOT.joint_correction, q, w, -iterations, 1e-9)


@FAST
@given(
    p=grid_points,
    f=map_forces,
    which=st.sampled_from(["position", "force"]),
    index=st.integers(0, 1),
    bad=NON_FINITE,
)
def test_non_finite_map_inputs_raise_input_error(p, f, which, index, bad):
    (p if which == "position" else f)[index] = bad
    for policy in ("error", "clamp", "extrapolate"):
        assert_input_error(MAP.displacement, p, f, out_of_grid=policy)
        assert_input_error(MAP.displacement_batch, p[None, :], f[None, :], out_of_grid=policy)


@FAST
@given(
    x=st.one_of(floats(-10.0, MAP.x[0] - 1e-6), floats(MAP.x[-1] + 1e-6, 10.0)),
    y=floats(-10.0, 10.0),
    f=map_forces,
)
def test_positions_outside_the_grid_raise_input_error(x, y, f):
    p = np.array([x, y])
    assert_input_error(MAP.displacement, p, f)
    assert_input_error(MAP.displacement_batch, p[None, :], f[None, :])
    # With the clamp policy the same query is answered, finitely.
    assert np.all(np.isfinite(MAP.displacement(p, f, out_of_grid="clamp")))


@FAST
@given(
    limits=st.tuples(floats(0.05, 2.0), floats(0.5, 50.0), floats(10.0, 5000.0)).map(list),
    index=st.integers(0, 3),
    bad=st.one_of(NON_FINITE, floats(-1e300, 0.0)),
)
def test_bad_plan_limits_raise_input_error(limits, index, bad):
    args = limits + [2000.0]
    args[index] = bad
    assert_input_error(deflect.plan_line, [0.2, -0.05], [0.25, 0.05], *args[:3], rate_hz=args[3])
    assert_input_error(deflect.plan_polyline, [[0.2, -0.05], [0.25, 0.05], [0.2, 0.05]], *args[:3], rate_hz=args[3])


@FAST
@given(
    Q=st.lists(joints, min_size=1, max_size=12).map(np.array),
    seed=st.integers(0, 2**32 - 1),
)
def test_deflection_batch_equals_loop(Q, seed):
    W = np.random.default_rng(seed).uniform(-3000.0, 3000.0, (len(Q), 6))
    W[:, 3:] *= 0.1
    batch = ROBOT.deflection_batch(Q, W)
    loop = np.array([ROBOT.deflection(q, w) for q, w in zip(Q, W)])
    assert batch.shape == (len(Q), 6)
    close(batch, loop)


@FAST
@given(
    P=st.lists(grid_points, min_size=1, max_size=40).map(np.array),
    seed=st.integers(0, 2**32 - 1),
    interpolation=interpolations,
)
def test_displacement_batch_equals_loop(P, seed, interpolation):
    F = np.random.default_rng(seed).uniform(-500.0, 500.0, (len(P), 2))
    batch = MAP.displacement_batch(P, F, interpolation=interpolation)
    loop = np.array([MAP.displacement(p, f, interpolation=interpolation) for p, f in zip(P, F)])
    assert batch.shape == (len(P), 2)
    close(batch, loop)


# Leading dimensions whose result cannot exist: from 2**44 rows (at 16 bytes a row, past the
# 128 TiB address space of x86-64, so no allocator says yes whatever the overcommit policy)
# to 2**57 (numpy's own limit for a (N, 6) float64 view).
huge_rows = st.integers(2**44, 2**57)


@settings(max_examples=40, deadline=None, database=None)
@given(rows=huge_rows, q=joints, w=wrenches, p=grid_points, f=map_forces,
       kind=st.sampled_from(["deflection", "compliance", "forward", "map", "field"]),
       broadcast_second=st.booleans())
def test_batches_of_huge_broadcast_inputs_raise_memory_error_and_the_process_survives(
    rows, q, w, p, f, kind, broadcast_second
):
    Q = np.broadcast_to(q, (rows, 6))
    P = np.broadcast_to(p, (rows, 2))
    calls = {
        "deflection": lambda: ROBOT.deflection_batch(Q, np.broadcast_to(w, (rows, 6))
                                                     if broadcast_second else w),
        "compliance": lambda: ROBOT.compliance_batch(Q),
        "forward": lambda: ROBOT.forward_batch(Q),
        "map": lambda: MAP.displacement_batch(P, np.broadcast_to(f, (rows, 2))
                                              if broadcast_second else f),
        "field": lambda: MAP.field(f).displacement_batch(P),
    }
    with pytest.raises(MemoryError, match="cannot allocate"):
        calls[kind]()
    # Still alive and still right: the same call on one row.
    assert np.all(np.isfinite(ROBOT.deflection_batch(q[None, :], w)))


# Tool tables: any set of valid tools written as LinuxCNC .tbl or TOML reads back with its
# numbers, diameters (to the printed digits) and shapes; any text is a table or a LoadError.
tool_specs = st.lists(
    st.tuples(
        st.integers(1, 99999),
        floats(0.01, 1000.0),  # diameter [mm]
        st.integers(1, 16),
        st.sampled_from(["flat", "ball", "bull-nose"]),
    ),
    min_size=1,
    max_size=12,
    unique_by=lambda t: t[0],
)


@FAST
@given(tool_specs)
def test_tool_tables_read_back_what_was_written(specs):
    tbl = "".join(f"T{n} P{n} D{d:.9g} Z+0 ;tool {n}\n" for n, d, _, _ in specs)
    toml = 'units = "mm"\n' + "".join(
        f"[[tool]]\nnumber = {n}\ndiameter = {d:.17g}\nflutes = {f}\nshape = \"{s}\"\n"
        + (f"corner_radius = {d / 4:.17g}\n" if s == "bull-nose" else "")
        for n, d, f, s in specs
    )
    want = sorted(specs)
    from_tbl = deflect.ToolTable.from_text(tbl)
    assert from_tbl.numbers == [n for n, _, _, _ in want]
    for (n, d, _, _), got in zip(want, from_tbl.tools):
        assert got[0] == n and got[4] == "flat"
        assert got[1] == pytest.approx(float(f"{d:.9g}") * 1e-3, rel=1e-12)
    from_toml = deflect.ToolTable.from_text(toml, format="toml")
    for (n, d, f, s), got in zip(want, from_toml.tools):
        assert (got[0], got[2], got[4]) == (n, f, s)
        assert got[1] == pytest.approx(d * 1e-3, rel=1e-15)


TOKENS = "T P D Z ; 0 1 2 . - + e \n [[tool]] number diameter = \" units mm flat ball".split(" ") + [" "]


@FAST
@given(st.lists(st.sampled_from(TOKENS), max_size=60).map("".join))
def test_any_tool_table_text_reads_or_raises_load_error(text):
    for fmt in ("tbl", "toml"):
        try:
            t = deflect.ToolTable.from_text(text, format=fmt)
        except deflect.LoadError:
            continue
        assert all(0 < tool[1] <= 1.0 and math.isfinite(tool[1]) for tool in t.tools)
        assert t.numbers == sorted(set(t.numbers))
