"""The online compensation chain and identification from Python (VJM paper, sec. 2.2-2.6)."""

import math

import numpy as np
import pytest

import deflect
from conftest import KR300_POSE

RNG = np.random.default_rng(6)


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def test_filters_step_response_and_delay():
    lp = deflect.LowPass(10.0, 0.004)
    tau = 1 / (2 * math.pi * 10)
    assert lp.delay_seconds == pytest.approx(tau)
    lp.step(np.zeros(6))
    ys = [lp.step(np.ones(6))[0] for _ in range(10)]
    a = lp.alpha
    np.testing.assert_allclose(ys, [1 - (1 - a) ** n for n in range(1, 11)], rtol=1e-14)
    ma = deflect.MovingAverage(4, 0.004)
    assert ma.delay_samples == 1.5 and ma.delay_seconds == pytest.approx(0.006)
    out = [ma.step(np.full(6, float(k)))[0] for k in range(10)]
    assert out[-1] == pytest.approx(9 - 1.5)
    with pytest.raises(deflect.InputError):
        deflect.MovingAverage(65, 0.004)


def test_pilot_threshold_and_ramp():
    p = deflect.PilotControl(150.0, 0.08, 0.004)
    m = np.array([100.0, 0, 0, 0, 0, 0])
    p.step(m, m + [150.0, 0, 0, 0, 0, 0])
    assert p.weight == 0.0
    for k in range(1, 21):
        p.step(m, m + [150.5, 0, 0, 0, 0, 0])
        assert p.weight == pytest.approx(min(1.0, 0.05 * k))
    assert p.weight == 1.0


def test_projection_matches_numpy():
    r, v = RNG.normal(size=3), RNG.normal(size=3)
    rv, ok = deflect.project_normal_to_feed(r, v)
    vn = v / np.linalg.norm(v)
    assert ok
    np.testing.assert_allclose(rv, r - (r @ vn) * vn, atol=1e-15)
    same, ok = deflect.project_normal_to_feed(r, np.zeros(3))
    assert not ok and np.array_equal(same, r)


def test_sensor_identification_from_three_orientations():
    truth = deflect.SensorCalibration(
        force_offset=[4.0, -3.0, 12.0],
        moment_offset=[0.5, -0.2, 0.1],
        weight=180.0,
        center_of_gravity=[0.005, -0.01, 0.12],
    )
    rots = np.array([np.eye(3), rot_x(math.pi), rot_y(math.pi / 4) @ rot_x(math.pi / 4)])
    readings = np.array([truth.unloaded_reading(r) for r in rots])
    # Independent numpy model of a reading: F = F_SI + R^T (0,0,-G), M = M_SI + r_G x (R^T g).
    g_s = rots[1].T @ np.array([0, 0, -180.0])
    np.testing.assert_allclose(readings[1][:3], [4.0, -3.0, 12.0] + g_s, atol=1e-12)
    np.testing.assert_allclose(readings[1][3:], [0.5, -0.2, 0.1] + np.cross([0.005, -0.01, 0.12], g_s), atol=1e-12)
    cal, info = deflect.identify_sensor(rots, readings)
    assert info["force_rank"] == 4 and info["moment_rank"] == 6
    np.testing.assert_allclose(cal.force_offset, truth.force_offset, atol=1e-10)
    assert cal.weight == pytest.approx(180.0)
    np.testing.assert_allclose(cal.center_of_gravity, truth.center_of_gravity, atol=1e-12)
    with pytest.raises(deflect.InputError, match="not a rotation"):
        deflect.identify_sensor(rots * 2.0, readings)


def test_stiffness_identification_round_trips_table_1(kr300):
    # TCP deflections of the KR 300 from deflect's own linearized model (a round trip of the
    # stiffness file: the independent check is the numpy-lstsq test below).
    n = 30
    Q = KR300_POSE + RNG.uniform(-0.6, 0.6, (n, 6))
    W = np.hstack([RNG.uniform(-750, 750, (n, 3)), RNG.uniform(-50, 50, (n, 3))])
    D = np.array([kr300.compliance(q) @ w for q, w in zip(Q, W)])
    out = deflect.identify_stiffness_from_tcp(kr300, Q, W, D)
    ok = np.array(out["identifiable"])
    assert ok.sum() >= 10 and out["rank"] < len(ok)  # coaxial springs are not separable
    # Table 1 values (N m/rad, robots/kr300) come back for every spring axis these poses and
    # loads identify; each entry below must be identifiable (no check is skipped).
    table = {
        ("link_1", 0): 1.2e7,
        ("link_1", 2): 7.5e6,
        ("link_2", 1): 6.1e6,
        ("link_2", 2): 5.4e6,
        ("link_2#1", 1): 3.8e6,
        ("link_2#1", 2): 1.0e7,
        ("link_3", 2): 4.3e6,
        ("link_3#1", 1): 1.3e7,
        ("link_4", 0): 3.0e6,
    }
    names = kr300.spring_names
    for (name, axis), k in table.items():
        i = [j for j in range(len(ok)) if names[out["spring"][j]] == name and out["axis"][j] == axis]
        assert len(i) == 1
        assert ok[i[0]], (name, axis)
        assert out["stiffness"][i[0]] == pytest.approx(k, rel=1e-6)
    # The wrist-end springs (flange, sensor, spindle, tool) sit on one rigid body: only their
    # sums are observable, so none of them is identifiable alone.
    for j in range(len(ok)):
        if names[out["spring"][j]] in ("ft_sensor", "spindle", "tool"):
            assert not ok[j], names[out["spring"][j]]
    # Unobservable ones are NaN, never silently set.
    assert np.all(np.isnan(out["compliance"][~ok]))


def test_online_compensator_from_python(kr300):
    comp = deflect.OnlineCompensator(kr300, dt=0.004, project_on_feed=False, max_rate=1.0)
    assert comp.delay_samples == pytest.approx(1 / (2 * math.pi * 10) / 0.004 + 2.0)
    q = KR300_POSE
    tcp = kr300.forward(q)
    f_base = np.array([-386.1, 386.1, 0.0])
    f_s = tcp[:3, :3].T @ f_base  # sensor frame = TCP frame here
    for _ in range(300):
        out = comp.step(q, np.concatenate([f_s, np.zeros(3)]))
    np.testing.assert_allclose(out["wrench"][:3], f_base, atol=1e-9)
    np.testing.assert_allclose(out["correction"], -kr300.deflection(q, out["wrench"]), atol=1e-15)
    with pytest.raises(deflect.InputError, match="reading"):
        comp.step(q, np.array([np.nan, 0, 0, 0, 0, 0]))
    with pytest.raises(deflect.InputError, match="output"):
        deflect.OnlineCompensator(kr300, output="sideways")


def test_stiffness_identification_from_noisy_data_is_numpys_lstsq(kr300, kr300_ref):
    """The same least-squares problem solved by numpy: the regressor built from the numpy
    chain (Eq. 5-9 linearised: a unit compliance of spring axis u at frame t turns the TCP by
    u (u . (m + r x f)) and moves it by u x r times that), the data that regressor times Table
    1's compliances plus 1 um / 1 urad of noise. deflect's identification and
    ``numpy.linalg.lstsq`` must agree on every identifiable compliance (every least-squares
    solution shares those components), and both land near Table 1."""
    rng = np.random.default_rng(11)
    n = 40
    Q = KR300_POSE + rng.uniform(-0.6, 0.6, (n, 6))
    W = np.hstack([rng.uniform(-750, 750, (n, 3)), rng.uniform(-50, 50, (n, 3))])
    springs = [e for e in kr300_ref.elements if e[0] == "spring"]
    assert len(springs) == len(kr300.spring_names)
    truth = np.concatenate([e[1] for e in springs])
    rows = []
    for q, w in zip(Q, W):
        tcp, frames = kr300_ref._walk(q)
        p = tcp[:3, 3]
        f, m = w[:3], w[3:]
        cols = []
        for e, t in frames:
            if e[0] != "spring":
                continue
            r = p - t[:3, 3]
            for a in range(3):
                u = t[:3, a]
                mu = u @ (m + np.cross(r, f))
                cols.append(np.concatenate([np.cross(u, r) * mu, u * mu]))
        rows.append(np.array(cols).T)
    A = np.vstack(rows)
    # Without noise, Table 1 comes back on every identifiable axis (the regressor is deflect's
    # model); with noise, numpy's least squares.
    exact = deflect.identify_stiffness_from_tcp(kr300, Q, W, (A @ truth).reshape(n, 6))
    D = A @ truth + rng.normal(0.0, 1e-6, A.shape[0])
    c_np = np.linalg.lstsq(A, D, rcond=None)[0]
    out = deflect.identify_stiffness_from_tcp(kr300, Q, W, D.reshape(n, 6))
    ok = np.array(out["identifiable"])
    assert ok.sum() >= 10 and list(ok) == list(exact["identifiable"])
    moved = 0.0
    for j in np.flatnonzero(ok):
        k = 3 * out["spring"][j] + out["axis"][j]
        assert exact["compliance"][j] == pytest.approx(truth[k], rel=1e-8), (j, k)
        assert out["compliance"][j] == pytest.approx(c_np[k], rel=1e-6), (j, k)
        moved = max(moved, abs(out["compliance"][j] / truth[k] - 1))
    # The noise does move the estimates (the comparison above is not of identical data).
    assert moved > 1e-3
