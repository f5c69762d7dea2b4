"""deflect.ComplianceMap against scipy/numpy references (Paksoy et al. 2025, Eq. 9-14)."""

import csv
import json
import pathlib

import numpy as np
import pytest
from scipy.interpolate import RegularGridInterpolator

import deflect

ROOT = pathlib.Path(__file__).resolve().parents[3]
OC = ROOT / "data" / "paksoy2025_compliance_oc.csv"
NC = ROOT / "data" / "paksoy2025_compliance_nc.csv"


def table(path):
    """Grid axes [m] and coefficient arrays (nx, ny, 2 disp, 2 force) in SI, read with csv."""
    rows = list(csv.DictReader(open(path)))
    xs = sorted({float(r["x_mm"]) for r in rows})
    ys = sorted({float(r["y_mm"]) for r in rows})
    slopes = np.zeros((len(xs), len(ys), 2, 2))
    offsets = np.zeros_like(slopes)
    for r in rows:
        i, j = xs.index(float(r["x_mm"])), ys.index(float(r["y_mm"]))
        c = {k: float(r[k]) for k in "mnopsuvw"}
        slopes[i, j] = [[c["m"], c["o"]], [c["s"], c["v"]]]
        offsets[i, j] = [[c["n"], c["p"]], [c["u"], c["w"]]]
    return np.array(xs) * 1e-3, np.array(ys) * 1e-3, slopes * 1e-3, offsets * 1e-3


def scipy_displacement(path, P, F):
    """Reference: interpolate the slope and offset fields with RegularGridInterpolator."""
    x, y, s, o = table(path)
    rgi_s = RegularGridInterpolator((x, y), s.reshape(len(x), len(y), 4), method="linear")
    rgi_o = RegularGridInterpolator((x, y), o.reshape(len(x), len(y), 4), method="linear")
    S = rgi_s(P).reshape(-1, 2, 2)
    O = rgi_o(P).reshape(-1, 2, 2)
    return np.einsum("ndf,nf->nd", S, F) + O.sum(axis=2)


@pytest.fixture(scope="module")
def oc():
    return deflect.ComplianceMap.from_csv(OC)


def random_queries(n, seed=0):
    rng = np.random.default_rng(seed)
    P = np.column_stack([rng.uniform(0.172132, 0.272132, n), rng.uniform(-0.075, 0.075, n)])
    F = rng.uniform(-250.0, 250.0, (n, 2))
    return P, F


@pytest.mark.parametrize("path", [OC, NC])
def test_bilinear_matches_scipy(path):
    m = deflect.ComplianceMap.from_csv(path, force_unit="N", length_unit="mm")
    P, F = random_queries(2000, seed=1)
    got = m.displacement_batch(P, F)
    want = scipy_displacement(path, P, F)
    assert got.shape == (2000, 2)
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-16)
    assert np.abs(got).max() > 1e-5  # tens of micrometres: a real comparison


def test_units_are_explicit():
    n = deflect.ComplianceMap.from_csv(OC, force_unit="N")
    kgf = deflect.ComplianceMap.from_csv(OC, force_unit="kgf")
    np.testing.assert_allclose(kgf.slopes * 9.80665, n.slopes, rtol=1e-14)
    np.testing.assert_allclose(kgf.offsets, n.offsets, rtol=0)
    assert n.slopes[0, 0, 0, 0] == pytest.approx(1.344e-6, rel=1e-12)
    assert n.x[0] == pytest.approx(0.172132)


def test_batch_equals_single(oc):
    P, F = random_queries(50, seed=2)
    for interpolation in ["bilinear", "bicubic"]:
        batch = oc.displacement_batch(P, F, interpolation=interpolation)
        single = np.array([oc.displacement(p, f, interpolation=interpolation) for p, f in zip(P, F)])
        np.testing.assert_array_equal(batch, single)
    # A third position column is ignored.
    P3 = np.column_stack([P, np.full(len(P), 0.7)])
    np.testing.assert_array_equal(oc.displacement_batch(P3, F), oc.displacement_batch(P, F))


def test_bicubic_differs_but_agrees_at_nodes(oc):
    x, y = oc.x, oc.y
    f = np.array([120.0, -60.0])
    for xi in x:
        for yj in y:
            p = np.array([xi, yj])
            np.testing.assert_allclose(
                oc.displacement(p, f, interpolation="bicubic"), oc.displacement(p, f), rtol=1e-12
            )
    p = np.array([0.19, -0.06])
    assert np.abs(oc.displacement(p, f, interpolation="bicubic") - oc.displacement(p, f)).max() > 1e-9


def synthetic_tests(m, sigma=0.0, seed=0):
    """Static tests from a map: 49.05 k N, k = 1..5, along x then y at every node."""
    rng = np.random.default_rng(seed)
    s, o = m.slopes, m.offsets
    pos, axis, force, disp = [], [], [], []
    for i, xi in enumerate(m.x):
        for j, yj in enumerate(m.y):
            for f in range(2):
                for k in range(1, 6):
                    F = 49.05 * k
                    pos.append([xi, yj])
                    axis.append(f)
                    force.append(F)
                    disp.append(s[i, j, :, f] * F + o[i, j, :, f] + sigma * rng.standard_normal(2))
    return np.array(pos), np.array(axis), np.array(force), np.array(disp)


def test_fit_matches_numpy_lstsq(oc):
    pos, axis, force, disp = synthetic_tests(oc, sigma=3e-6, seed=4)
    fitted = deflect.ComplianceMap.fit(pos, axis, force, disp)
    res = fitted.residuals
    assert len(res) == 15
    for node in res:
        sel_node = np.all(np.isclose(pos, [node["x"], node["y"]], atol=1e-9), axis=1)
        for f in range(2):
            sel = sel_node & (axis == f)
            A = np.column_stack([force[sel], np.ones(sel.sum())])  # Eq. 12
            Q, ss, rank, sv = np.linalg.lstsq(A, disp[sel], rcond=None)  # Eq. 13
            np.testing.assert_allclose(node["slope"][:, f], Q[0], rtol=1e-9)
            np.testing.assert_allclose(node["offset"][:, f], Q[1], rtol=1e-9, atol=1e-15)
            rms = np.sqrt(((disp[sel] - A @ Q) ** 2).mean(axis=0))
            np.testing.assert_allclose(node["rms"][:, f], rms, rtol=1e-9)
            assert node["condition"][f] == pytest.approx(sv[0] / sv[1], rel=1e-9)
            assert node["samples"][f] == 5
            r2 = 1 - ((disp[sel] - A @ Q) ** 2).sum(0) / ((disp[sel] - disp[sel].mean(0)) ** 2).sum(0)
            np.testing.assert_allclose(node["r_squared"][:, f], r2, rtol=1e-9)
    # And the fitted map's coefficients are those lines.
    i, j = 1, 2
    node = res[i * 5 + j]
    np.testing.assert_allclose(fitted.slopes[i, j], node["slope"], rtol=0)


def test_fit_two_point_form(oc):
    pos, axis, force, disp = synthetic_tests(oc)
    # Displacements of P_l (0 mm) and P_u (100 mm above) with a tilt, such that the point
    # 2.5 mm below P_l moves by `disp`: lower = d - e*t, upper = lower - L*t  (t = tilt).
    L, e = 0.1, 0.0025
    tilt = np.random.default_rng(5).uniform(-1e-4, 1e-4, disp.shape)
    lower = disp - e * tilt
    upper = lower - L * tilt
    fitted = deflect.ComplianceMap.fit(pos, axis, force, upper=upper, lower=lower, spacing=L, extension=e)
    np.testing.assert_allclose(fitted.slopes, oc.slopes, rtol=1e-7, atol=1e-15)


def test_fit_csv_and_json_round_trip(tmp_path, oc):
    pos, axis, force, disp = synthetic_tests(oc, sigma=1e-6, seed=6)
    path = tmp_path / "static.csv"
    with open(path, "w") as fh:
        fh.write("x,y,force_axis,force,dx,dy\n")
        for p, a, f, d in zip(pos, axis, force, disp):
            vals = [float(p[0]) * 1e3, float(p[1]) * 1e3, float(f) / 9.80665, float(d[0]) * 1e3, float(d[1]) * 1e3]
            fh.write("{!r},{!r},{},{!r},{!r},{!r}\n".format(vals[0], vals[1], "xy"[a], *vals[2:]))
    from_csv = deflect.ComplianceMap.fit_csv(path, force_unit="kgf", length_unit="mm")
    from_arrays = deflect.ComplianceMap.fit(pos, axis, force, disp)
    np.testing.assert_allclose(from_csv.slopes, from_arrays.slopes, rtol=1e-9)
    text = from_csv.to_json()
    doc = json.loads(text)
    assert doc["format_version"] == 1 and doc["units"]["position"] == "m"
    back = deflect.ComplianceMap.from_json(text)
    np.testing.assert_array_equal(back.slopes, from_csv.slopes)
    np.testing.assert_array_equal(back.offsets, from_csv.offsets)
    assert back.residuals[3]["rms"].tolist() == from_csv.residuals[3]["rms"].tolist()


def test_out_of_grid_policies(oc):
    f = np.array([100.0, 50.0])
    outside = np.array([0.30, 0.0])
    with pytest.raises(deflect.InputError, match="outside the grid"):
        oc.displacement(outside, f)
    clamped = oc.displacement(outside, f, out_of_grid="clamp")
    np.testing.assert_array_equal(clamped, oc.displacement(np.array([oc.x[-1], 0.0]), f))
    a = oc.displacement(np.array([oc.x[1], 0.0]), f)
    b = oc.displacement(np.array([oc.x[2], 0.0]), f)
    ext = oc.displacement(outside, f, out_of_grid="extrapolate")
    np.testing.assert_allclose(ext, b + (0.30 - oc.x[2]) / (oc.x[2] - oc.x[1]) * (b - a), rtol=1e-9)
    m2 = oc.with_options(out_of_grid="clamp", interpolation="bicubic")
    assert (m2.out_of_grid, m2.interpolation) == ("clamp", "bicubic")
    with pytest.raises(deflect.InputError, match="row 1"):
        oc.displacement_batch(np.array([[0.2, 0.0], [0.5, 0.0]]), np.zeros((2, 2)))


def test_bad_input_raises_value_error_subclasses(oc, tmp_path):
    with pytest.raises(deflect.InputError):
        oc.displacement(np.array([np.nan, 0.0]), np.array([1.0, 1.0]))
    with pytest.raises(deflect.InputError):
        oc.displacement(np.array([0.2, 0.0]), np.array([1.0, 1.0, 1.0]))
    with pytest.raises(deflect.InputError):
        oc.displacement_batch(np.zeros((3, 2)), np.zeros((2, 2)))
    with pytest.raises(deflect.InputError):
        oc.displacement(np.array([0.2, 0.0]), np.array([1.0, 1.0]), interpolation="spline")
    with pytest.raises(deflect.InputError):
        deflect.ComplianceMap.from_csv(OC, force_unit="lbf")
    with pytest.raises(deflect.LoadError, match="missing column"):
        bad = tmp_path / "bad.csv"
        bad.write_text("i,j,x_mm,y_mm,m\n1,1,0,0,1\n")
        deflect.ComplianceMap.from_csv(bad)
    with pytest.raises(deflect.LoadError, match="cannot read"):
        deflect.ComplianceMap.from_csv(tmp_path / "absent.csv")
    with pytest.raises(deflect.LoadError, match="format_version 3"):
        deflect.ComplianceMap.from_json(oc.to_json().replace('"format_version": 1', '"format_version": 3'))
    pos, axis, force, disp = synthetic_tests(oc)
    keep = ~((axis == 1) & (force > 50) & (pos[:, 0] == pos[0, 0]) & (pos[:, 1] == pos[0, 1]))
    with pytest.raises(deflect.InputError, match="1 distinct force level"):
        deflect.ComplianceMap.fit(pos[keep], axis[keep], force[keep], disp[keep])
    drop = ~((pos[:, 0] == pos[0, 0]) & (pos[:, 1] == pos[0, 1]))
    with pytest.raises(deflect.InputError, match="has no data"):
        deflect.ComplianceMap.fit(pos[drop], axis[drop], force[drop], disp[drop])
    with pytest.raises(deflect.InputError, match="repeats"):
        deflect.ComplianceMap.fit(
            np.vstack([pos, pos[:1]]), np.append(axis, axis[0]), np.append(force, force[0]), np.vstack([disp, disp[:1]])
        )
    d2 = disp.copy()
    d2[4, 1] = np.inf
    with pytest.raises(deflect.InputError, match="row 4, column d1"):
        deflect.ComplianceMap.fit(pos, axis, force, d2)
    for exc in (deflect.InputError, deflect.LoadError):
        assert issubclass(exc, ValueError)


def test_cross_validation_numbers():
    forces = np.zeros((10, 2))
    forces[:5, 0] = 49.05 * np.arange(1, 6)
    forces[5:, 1] = 49.05 * np.arange(1, 6)
    for path in (OC, NC):
        cv = deflect.ComplianceMap.from_csv(path).cross_validate(forces, axis="y")
        print(path.name, cv["rms_bilinear"], cv["rms_bicubic"], cv["better"])
        assert len(cv["nodes"]) == 9
        assert 1e-6 < cv["rms_bicubic"] < cv["rms_bilinear"] < 1e-3
