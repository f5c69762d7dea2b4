"""deflect.GridMap: compliance maps over 1-4 dimensional grids.

Multilinear interpolation equals scipy's RegularGridInterpolator (method="linear") in 1-4 D
to 1e-15 of the values' scale; a fitted 3-D map reproduces its nodes; the 2-D case equals the
2-D ComplianceMap; JSON version 2 round-trips bit for bit and version 1 is read; pickling and
bad input.
"""

import pickle

import numpy as np
import pytest
from scipy.interpolate import RegularGridInterpolator

import deflect


def grid(dims, seed):
    rng = np.random.default_rng(seed)
    axes = [np.cumsum(rng.uniform(0.02, 0.08, size=4 + (k % 2))) + 0.1 * k for k in range(dims)]
    shape = tuple(len(a) for a in axes)
    slopes = rng.normal(size=shape + (3, 2)) * 1e-6
    offsets = rng.normal(size=shape + (3, 2)) * 1e-5
    return axes, slopes, offsets


@pytest.mark.parametrize("dims", [1, 2, 3, 4])
def test_multilinear_is_scipys_regular_grid_interpolator(dims):
    axes, slopes, offsets = grid(dims, dims)
    m = deflect.GridMap(axes, 2, 3, slopes, offsets)
    assert m.dims == dims and m.names == ["x", "y", "z", "w"][:dims]
    rng = np.random.default_rng(10 + dims)
    force = np.array([150.0, -60.0])
    # Node displacements under this force, interpolated by scipy.
    node_values = (slopes * force).sum(-1) + offsets.sum(-1)
    ref = RegularGridInterpolator(tuple(axes), node_values, method="linear")
    P = np.column_stack([rng.uniform(a[0], a[-1], 300) for a in axes])
    got = m.displacement_batch(P, force)
    want = ref(P)
    scale = np.abs(node_values).max()
    assert np.abs(got - want).max() <= 1e-15 * scale, np.abs(got - want).max() / scale
    # A strided (Fortran-order) batch is copied, and answers the same.
    np.testing.assert_array_equal(m.displacement_batch(np.asfortranarray(P), force), got)
    # Single queries are the batch's rows.
    for k in range(5):
        np.testing.assert_array_equal(m.displacement(P[k], force), got[k])


def test_a_fitted_3d_map_reproduces_its_nodes_and_the_2d_case_is_the_compliance_map():
    axes, slopes, offsets = grid(3, 7)
    truth = deflect.GridMap(axes, 2, 3, slopes, offsets, names=["x", "y", "z"])
    pts, fa, fv, disp = [], [], [], []
    for idx in np.ndindex(*[len(a) for a in axes]):
        p = np.array([a[i] for a, i in zip(axes, idx)])
        for f in range(2):
            for level in (-200.0, 50.0, 300.0):
                force = np.zeros(2)
                force[f] = level
                # Each force axis keeps its own intercept (Eq. 10): the other's offset out.
                d = slopes[idx][:, f] * level + offsets[idx][:, f]
                pts.append(p)
                fa.append(f)
                fv.append(level)
                disp.append(d)
    fitted = deflect.GridMap.fit(np.array(pts), fa, fv, np.array(disp), names=["x", "y", "z"])
    np.testing.assert_allclose(fitted.slopes, slopes, rtol=1e-10)
    np.testing.assert_allclose(fitted.offsets, offsets, rtol=1e-8, atol=1e-17)
    for idx in [(0, 0, 0), (2, 3, 1), (3, 4, 3)]:
        p = [a[i] for a, i in zip(axes, idx)]
        np.testing.assert_allclose(
            fitted.displacement(p, [100.0, 20.0]), truth.displacement(p, [100.0, 20.0]), rtol=1e-9
        )
    # The 2-D map as a grid map: the same numbers (to rounding of the summation order).
    a2, s2, o2 = grid(2, 3)
    s2, o2 = s2[:, :, :2, :], o2[:, :, :2, :]
    cm = deflect.ComplianceMap.fit(
        np.array([[x, y] for x in a2[0] for y in a2[1] for _ in range(4)]),
        [f for _ in range(len(a2[0]) * len(a2[1])) for f in (0, 0, 1, 1)],
        [v for _ in range(len(a2[0]) * len(a2[1])) for v in (-100.0, 100.0, -100.0, 100.0)],
        np.array(
            [
                s2[i, j][:, f] * v + o2[i, j][:, f]
                for i in range(len(a2[0]))
                for j in range(len(a2[1]))
                for f, v in ((0, -100.0), (0, 100.0), (1, -100.0), (1, 100.0))
            ]
        ),
    )
    g = deflect.GridMap.from_map(cm)
    P = np.column_stack([np.linspace(a2[0][0], a2[0][-1], 50), np.linspace(a2[1][-1], a2[1][0], 50)])
    for method in ("bilinear", "bicubic"):
        a = cm.displacement_batch(P, [80.0, -30.0], interpolation=method)
        b = g.displacement_batch(P, [80.0, -30.0], interpolation=method)
        assert np.abs(a - b).max() <= 1e-14 * np.abs(a).max()


def test_json_version_2_pickle_and_version_1():
    axes, slopes, offsets = grid(3, 11)
    m = deflect.GridMap(axes, 2, 3, slopes, offsets, names=["x", "y", "q3"], interpolation="cubic")
    text = m.to_json()
    assert '"format_version": 2' in text
    back = deflect.GridMap.from_json(text)
    assert back == m and back.interpolation == "cubic" and back.names == ["x", "y", "q3"]
    assert pickle.loads(pickle.dumps(m)) == m
    np.testing.assert_array_equal(back.slopes, slopes)
    # A 2-D map's version-1 JSON reads as a grid map over x, y.
    a2, s2, o2 = grid(2, 5)
    v1 = deflect.GridMap(a2, 2, 3, s2, o2)
    cm = deflect.ComplianceMap.from_json(v1.to_json())
    assert '"format_version": 1' in cm.to_json()
    assert deflect.GridMap.from_json(cm.to_json()) == v1


def test_bad_input_is_named():
    axes, slopes, offsets = grid(2, 1)
    with pytest.raises(deflect.InputError, match="slopes"):
        deflect.GridMap(axes, 2, 3, slopes[:-1], offsets)
    with pytest.raises(deflect.InputError, match="1 to 4"):
        deflect.GridMap([], 2, 3, slopes, offsets)
    with pytest.raises(deflect.InputError, match="names"):
        deflect.GridMap(axes, 2, 3, slopes, offsets, names=["x", "x"])
    m = deflect.GridMap(axes, 2, 3, slopes, offsets)
    with pytest.raises(deflect.InputError, match=r"point y = 99.0 \(axis 1\)"):
        m.displacement([axes[0][1], 99.0], [1.0, 0.0])
    with pytest.raises(deflect.InputError, match="row 2"):
        m.displacement_batch([[axes[0][1], axes[1][1]]] * 2 + [[np.nan, 0.0]], [1.0, 0.0])
    with pytest.raises(deflect.InputError, match=r"\(N, 2\)"):
        m.displacement_batch(np.zeros((3, 3)), [1.0, 0.0])
    with pytest.raises(deflect.InputError, match="interpolation"):
        m.displacement([axes[0][1], axes[1][1]], [1.0, 0.0], interpolation="spline")
    assert m.displacement([axes[0][1], 99.0], [1.0, 0.0], out_of_grid="clamp").shape == (3,)


def test_a_csv_names_the_axes(tmp_path):
    # A Delta's workspace in mm, displacements in mm: dz = 2e-3 mm/N (1 + z/0.1 m) F.
    rows = ["x_mm,y_mm,z_mm,force_axis,force,dx,dy,dz"]
    for x in (-50, 0, 50):
        for y in (-50, 50):
            for z in (-400, -300):
                for axis in ("x", "y", "z"):
                    for f in (-10.0, 10.0):
                        dz = 2e-3 * (1 + z / 1000 / 0.1) * f if axis == "z" else 0.0
                        rows.append(f"{x},{y},{z},{axis},{f},0,0,{dz}")
    path = tmp_path / "delta.csv"
    path.write_text("\n".join(rows) + "\n")
    m = deflect.GridMap.fit_csv(path)
    assert m.names == ["x", "y", "z"] and m.n_force == 3 and m.n_displacement == 3
    np.testing.assert_allclose(m.axes[2], [-0.4, -0.3])
    got = m.displacement([0.01, 0.0, -0.35], [0, 0, 5.0])
    assert got[2] == pytest.approx(2e-6 * (1 - 3.5) * 5.0, rel=1e-12)
    (tmp_path / "bad.csv").write_text("x_mm,yy,force_axis,force,dx\n")
    with pytest.raises(deflect.LoadError, match="yy"):
        deflect.GridMap.fit_csv(tmp_path / "bad.csv")
    # Force axis x never loaded at one node: named, not "no data".
    (tmp_path / "gap.csv").write_text("\n".join(r for r in rows if not r.startswith("-50,-50,-400,x")) + "\n")
    with pytest.raises(deflect.LoadError, match=r"\(-0.05, -0.05, -0.4\), force axis 0"):
        deflect.GridMap.fit_csv(tmp_path / "gap.csv")


@pytest.mark.parametrize("dims", [3, 4])
def test_out_of_grid_in_3d_and_4d_by_value(dims):
    """A map whose node values are a linear function of the coordinates (so multilinear
    interpolation and extrapolation are exact): outside the grid, "extrapolate" gives the
    linear function there, "clamp" its value at the nearest grid point, "error" refuses
    naming the axis. Values by hand from the function, not from the map."""
    axes = [np.linspace(0.1 * k, 0.1 * k + 0.3, 4 + (k % 2)) for k in range(dims)]
    grad = np.array([2e-6, -1e-6, 3e-6, 5e-7][:dims])  # m/N per m of each coordinate, row 0

    def slope(p):
        base = 1e-6 + grad @ p
        return np.array([[base, 0.5 * base], [0.0, base], [2 * base, 0.0]])  # (3, 2)

    shape = tuple(len(a) for a in axes)
    slopes = np.empty(shape + (3, 2))
    for idx in np.ndindex(*shape):
        slopes[idx] = slope(np.array([a[i] for a, i in zip(axes, idx)]))
    offsets = np.zeros(shape + (3, 2))
    m = deflect.GridMap(axes, 2, 3, slopes, offsets)
    force = np.array([100.0, -40.0])
    outside = np.array([a[-1] + 0.05 * (k + 1) for k, a in enumerate(axes)])
    outside[0] = axes[0][0] - 0.07  # below on the first axis, above on the others
    np.testing.assert_allclose(
        m.displacement(outside, force, out_of_grid="extrapolate"), slope(outside) @ force, rtol=1e-12
    )
    clamped = np.array([np.clip(v, a[0], a[-1]) for v, a in zip(outside, axes)])
    np.testing.assert_allclose(
        m.displacement(outside, force, out_of_grid="clamp"), slope(clamped) @ force, rtol=1e-12
    )
    with pytest.raises(deflect.InputError, match=r"axis 0"):
        m.displacement(outside, force)
    # Batches answer as single queries, out of the grid too.
    P = np.array([outside, clamped, (outside + clamped) / 2])
    np.testing.assert_allclose(
        m.displacement_batch(P, force, out_of_grid="extrapolate"),
        np.array([slope(p) @ force for p in P]),
        rtol=1e-12,
    )
