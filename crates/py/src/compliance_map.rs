//! `deflect.ComplianceMap`: the static-test compliance map of deflect-core (Paksoy et al.
//! 2025, Eq. 9-14). SI units in and out: positions m, forces N, displacements m.

use deflect_core::TickError;
use deflect_core::compliance_map::{
    self as cm, ComplianceMap as CoreMap, FitOptions, HoldOutAxis, Measurement, QueryOptions,
};
use deflect_core::io::{map_csv, map_json};
use deflect_core::units::{ForceUnit, LengthUnit};
use numpy::ndarray::{Array1, Array2, Array4};
use numpy::{IntoPyArray, PyArray1, PyArray4, PyReadonlyArray2, ToPyArray};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::InputError;
use crate::args;
use crate::arrays::{batch_pair, check_count, indices, matrix, vector_upto};
use crate::batch;
use crate::errors::{build_err, load_err, shape_error, tick_err};
use crate::field::DisplacementField;
use crate::map_common::{self, interpolation_name, out_of_grid_name, query_options};
use crate::out::fill_into;

pub(crate) fn units(force_unit: &str, length_unit: &str) -> PyResult<(ForceUnit, LengthUnit)> {
    let f = ForceUnit::parse(force_unit).ok_or_else(|| {
        InputError::new_err(format!(
            "force_unit must be \"N\" or \"kgf\", got {force_unit:?}"
        ))
    })?;
    let l = LengthUnit::parse(length_unit).ok_or_else(|| {
        InputError::new_err(format!(
            "length_unit must be \"m\", \"mm\" or \"in\", got {length_unit:?}"
        ))
    })?;
    Ok((f, l))
}

/// A compliance map from static tests (Paksoy et al. 2025, Eq. 9-14): at each node of a
/// rectilinear grid of positions, `disp_d = sum_f (slope[d, f] * F_f + offset[d, f])`; bilinear
/// (Eq. 14) or C1 cubic Hermite interpolation between nodes. SI: positions m, forces N,
/// displacements m.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct ComplianceMap {
    pub(crate) inner: CoreMap,
}

impl ComplianceMap {
    fn wrap(mut inner: CoreMap, interpolation: &str, out_of_grid: &str) -> PyResult<Self> {
        inner.set_options(query_options(interpolation, out_of_grid)?);
        Ok(Self { inner })
    }

    fn options(
        &self,
        interpolation: Option<&str>,
        out_of_grid: Option<&str>,
    ) -> PyResult<QueryOptions> {
        map_common::options_over(self.inner.options(), interpolation, out_of_grid)
    }
}

/// Rows of a (N, k) float array as a contiguous row-major Vec.
fn rows_of(a: &PyReadonlyArray2<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

#[pymethods]
impl ComplianceMap {
    /// Loads a coefficient table in the layout of the paper's Tables II/III: columns
    /// `x_mm, y_mm` (or `x_m, y_m`, or `x, y` in `length_unit`) and `m, n, o, p, s, u, v, w`
    /// with `dx = (m Fx + n) + (o Fy + p)`, `dy = (s Fx + u) + (v Fy + w)`.
    /// `length_unit` ("mm" | "m") is the displacement unit, `force_unit` ("N" | "kgf") the
    /// force unit the lines were fitted in.
    #[staticmethod]
    #[pyo3(signature = (path, force_unit="N", length_unit="mm", interpolation="bilinear", out_of_grid="error"))]
    fn from_csv(
        path: std::path::PathBuf,
        force_unit: &str,
        length_unit: &str,
        interpolation: &str,
        out_of_grid: &str,
    ) -> PyResult<Self> {
        let (f, l) = units(force_unit, length_unit)?;
        let inner = map_csv::from_path(&path, f, l).map_err(load_err)?;
        Self::wrap(inner, interpolation, out_of_grid)
    }

    /// Same as `from_csv`, from the CSV text.
    #[staticmethod]
    #[pyo3(signature = (text, force_unit="N", length_unit="mm", interpolation="bilinear", out_of_grid="error"))]
    fn from_csv_text(
        #[pyo3(from_py_with = crate::args::text::text)] text: String,
        force_unit: &str,
        length_unit: &str,
        interpolation: &str,
        out_of_grid: &str,
    ) -> PyResult<Self> {
        let (f, l) = units(force_unit, length_unit)?;
        let inner = map_csv::from_str(&text, f, l).map_err(load_err)?;
        Self::wrap(inner, interpolation, out_of_grid)
    }

    /// Fits a map from static tests (Eq. 10-13), SI arrays, one reading per row:
    /// `positions` (N, 2) [m] node x, y; `force_axis` (N,) int, the loaded axis
    /// (0..n_force); `force` (N,) [N]; `displacement` (N, n_displacement) [m] measured at
    /// the working point. Alternatively pass `upper` and `lower` (N, n_displacement), the
    /// displacements of P_u and P_l, with `spacing` = |P_u P_l| [m] and `extension` [m] (the
    /// working point's distance beyond P_l along the tool axis):
    /// `d = lower + extension / spacing * (lower - upper)`.
    #[staticmethod]
    #[pyo3(signature = (positions, force_axis, force, displacement=None, *, upper=None, lower=None,
        spacing=None, extension=0.0, n_force=None, position_tolerance=1e-6,
        interpolation="bilinear", out_of_grid="error"))]
    #[allow(clippy::too_many_arguments)] // reason: mirrors the documented Python signature
    fn fit(
        positions: &Bound<'_, PyAny>,
        force_axis: &Bound<'_, PyAny>,
        force: &Bound<'_, PyAny>,
        displacement: Option<&Bound<'_, PyAny>>,
        upper: Option<&Bound<'_, PyAny>>,
        lower: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = args::opt_real::spacing)] spacing: Option<f64>,
        #[pyo3(from_py_with = args::real::extension)] extension: f64,
        #[pyo3(from_py_with = args::opt_count::n_force)] n_force: Option<usize>,
        #[pyo3(from_py_with = args::real::position_tolerance)] position_tolerance: f64,
        interpolation: &str,
        out_of_grid: &str,
    ) -> PyResult<Self> {
        let positions = matrix(positions, "positions", None, None)?;
        let p = positions.as_array();
        let n = p.nrows();
        if p.ncols() != 2 && p.ncols() != 3 {
            return Err(shape_error("positions", "(N, 2) or (N, 3)", p.shape()));
        }
        // Before any copy: core's fit refuses the same count, after the copies.
        check_count(
            "positions",
            n,
            "measurements",
            cm::MAX_MEASUREMENTS,
            "MAX_MEASUREMENTS",
        )?;
        let axes = indices(
            force_axis,
            "force_axis",
            cm::MAX_MEASUREMENTS,
            "MAX_MEASUREMENTS",
        )?;
        if axes.len() != n {
            return Err(shape_error("force_axis", &format!("({n},)"), &[axes.len()]));
        }
        let forces = vector_upto(force, "force", cm::MAX_MEASUREMENTS, "MAX_MEASUREMENTS")?;
        if forces.len() != n {
            return Err(shape_error("force", &format!("({n},)"), &[forces.len()]));
        }
        let check_disp = |a: &Bound<'_, PyAny>, what: &str| -> PyResult<(usize, Vec<f64>)> {
            let m = matrix(a, what, Some(n), None)?;
            let c = m.as_array().ncols();
            if !(1..=cm::MAX_AXES).contains(&c) {
                return Err(shape_error(
                    what,
                    &format!("({n}, 1..{})", cm::MAX_AXES),
                    m.as_array().shape(),
                ));
            }
            Ok((c, rows_of(&m)))
        };
        let (nd, disp): (usize, Vec<f64>) = match (displacement, upper, lower) {
            (Some(d), None, None) => check_disp(d, "displacement")?,
            (None, Some(u), Some(l)) => {
                let (nd, u) = check_disp(u, "upper")?;
                let (nl, l) = check_disp(l, "lower")?;
                if nl != nd {
                    return Err(InputError::new_err("upper and lower: shapes differ"));
                }
                let spacing = spacing.ok_or_else(|| {
                    InputError::new_err("spacing (|P_u P_l| [m]) is required with upper/lower")
                })?;
                let mut d = vec![0.0; n * nd];
                for ((o, uu), ll) in d.chunks_mut(nd).zip(u.chunks(nd)).zip(l.chunks(nd)) {
                    cm::two_point_displacement(uu, ll, spacing, extension, o).map_err(build_err)?;
                }
                (nd, d)
            }
            _ => {
                return Err(InputError::new_err(
                    "give either displacement or both upper and lower",
                ));
            }
        };
        let mut ms = Vec::with_capacity(n);
        for (r, ((prow, a), f)) in p
            .rows()
            .into_iter()
            .zip(axes.iter())
            .zip(forces.iter())
            .enumerate()
        {
            let d = disp.get(r * nd..(r + 1) * nd).unwrap_or(&[]);
            let xy = |k: usize| prow.get(k).copied().unwrap_or(f64::NAN);
            ms.push(Measurement::new(xy(0), xy(1), *a, *f, d));
        }
        let n_force =
            n_force.unwrap_or_else(|| ms.iter().map(|m| m.force_axis + 1).max().unwrap_or(1));
        let options = FitOptions {
            n_force,
            n_displacement: nd,
            position_tolerance,
        };
        let inner = cm::fit(&ms, &options).map_err(build_err)?;
        Self::wrap(inner, interpolation, out_of_grid)
    }

    /// Fits a map from a CSV of static tests, one reading a row, columns:
    /// `x, y` [length_unit] node position; `force_axis` (0.. or x, y, z, mx, my, mz);
    /// `force` [force_unit; moments force_unit * length_unit]; displacement columns, those
    /// present in the order `dx, dy, dz` [length_unit], `rx, ry, rz` [rad].
    /// `position_tolerance` [m] groups coordinates into grid lines.
    #[staticmethod]
    #[pyo3(signature = (path, force_unit="N", length_unit="mm", n_force=None, position_tolerance=1e-6,
        interpolation="bilinear", out_of_grid="error"))]
    fn fit_csv(
        path: std::path::PathBuf,
        force_unit: &str,
        length_unit: &str,
        #[pyo3(from_py_with = args::opt_count::n_force)] n_force: Option<usize>,
        #[pyo3(from_py_with = args::real::position_tolerance)] position_tolerance: f64,
        interpolation: &str,
        out_of_grid: &str,
    ) -> PyResult<Self> {
        let (f, l) = units(force_unit, length_unit)?;
        let inner =
            map_csv::fit_static_path(&path, f, l, n_force, position_tolerance).map_err(load_err)?;
        Self::wrap(inner, interpolation, out_of_grid)
    }

    /// The map as versioned JSON (`"format_version": 1`, SI units recorded); exact round trip.
    fn to_json(&self) -> PyResult<String> {
        map_json::to_string(&self.inner).map_err(load_err)
    }

    /// Writes the map's JSON (see `to_json`) to the file `path`.
    fn save_json(&self, path: std::path::PathBuf) -> PyResult<()> {
        map_json::to_path(&self.inner, &path).map_err(load_err)
    }

    /// Loads a map saved by `to_json` / `save_json`: `source` is the JSON text (a `str`
    /// whose first non-blank character is `{`) or a path (`str` or `os.PathLike`) to the file.
    #[staticmethod]
    fn from_json(source: &Bound<'_, PyAny>) -> PyResult<Self> {
        let inner =
            map_common::json_source(source, map_json::from_str, |p| map_json::from_path(p))?;
        Ok(Self { inner })
    }

    /// Pickling (and `copy.deepcopy`): the map's JSON (coefficients, grid and default query
    /// options), an exact round trip.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let rebuild = slf.get_type().getattr("from_json")?;
        Ok((rebuild, (slf.get().to_json()?,)))
    }

    /// The displacement field under the fixed `force` (n_force,) [N]: every node's
    /// displacement computed once, for position-only queries (`DisplacementField`).
    /// `InputError` for a wrong length or a non-finite force.
    fn field(slf: &Bound<'_, Self>, force: &Bound<'_, PyAny>) -> PyResult<DisplacementField> {
        let f = vector_upto(force, "force", cm::MAX_AXES, "MAX_AXES")?;
        let inner = slf.get().inner.field(&f).map_err(build_err)?;
        Ok(DisplacementField::new(slf.as_any(), inner))
    }

    /// The same map with other default options.
    #[pyo3(signature = (interpolation=None, out_of_grid=None))]
    fn with_options(
        &self,
        interpolation: Option<&str>,
        out_of_grid: Option<&str>,
    ) -> PyResult<Self> {
        let o = self.options(interpolation, out_of_grid)?;
        Ok(Self {
            inner: self.inner.clone().with_options(o),
        })
    }

    /// Displacement (n_displacement,) [m] at `position` (x, y) [m] (a 3rd entry, z, is
    /// ignored: the map is planar) under `force` (n_force,) [N]. Keywords override the map's
    /// default `interpolation` ("bilinear" | "bicubic") and `out_of_grid` ("error" | "clamp"
    /// | "extrapolate") for this call. Into `out` (n_displacement,) if given.
    #[pyo3(signature = (position, force, *, interpolation=None, out_of_grid=None, out=None))]
    fn displacement<'py>(
        &self,
        py: Python<'py>,
        position: &Bound<'py, PyAny>,
        force: &Bound<'py, PyAny>,
        interpolation: Option<&str>,
        out_of_grid: Option<&str>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let o = self.options(interpolation, out_of_grid)?;
        let p = cm::planar_position(&vector_upto(position, "position", 3, "3 coordinates")?)
            .map_err(tick_err)?;
        let f = vector_upto(force, "force", cm::MAX_AXES, "MAX_AXES")?;
        map_common::one_query(py, self.inner.n_displacement(), out, |d| {
            self.inner.displacement_with(p, &f, d, o).map_err(tick_err)
        })
    }

    /// Displacements (N, n_displacement) [m] for positions `P` (N, 2) or (N, 3) [m] (z
    /// ignored) and forces `F` (N, n_force) [N]; either may be a single row ((2,), (n_force,)
    /// or one-row 2-D) that broadcasts over the other's rows, as in numpy (a displacement
    /// field under one load, or one point under many loads). float64 C-contiguous arrays are
    /// read in place. Runs without the GIL, on every core for large batches. With
    /// `out_of_grid="error"` the first row outside the grid raises `InputError`. Into `out`
    /// (N, n_displacement) if given.
    #[allow(non_snake_case)] // reason: matrix names as in the documented Python signature
    #[pyo3(signature = (P, F, *, interpolation=None, out_of_grid=None, out=None))]
    fn displacement_batch<'py>(
        &self,
        py: Python<'py>,
        P: &Bound<'py, PyAny>,
        F: &Bound<'py, PyAny>,
        interpolation: Option<&str>,
        out_of_grid: Option<&str>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let opts = self.options(interpolation, out_of_grid)?;
        let (nf, nd) = (self.inner.n_force(), self.inner.n_displacement());
        let (n, pm, fm) = batch_pair((P, "P", &[2, 3]), (F, "F", &[nf]))?;
        let (p, f) = (pm.as_array(), fm.as_array());
        let pc = p.ncols();
        let (Some(p), Some(f)) = (p.broadcast((n, pc)), f.broadcast((n, nf))) else {
            return Err(InputError::new_err("P and F: rows do not broadcast"));
        };
        let view = self.inner.view();
        fill_into(py, &[n, nd], out, |buf| {
            py.detach(|| {
                batch::chunks(
                    buf,
                    nd,
                    batch::row_cost::MAP_QUERY,
                    || (Vec::new(), Vec::new()),
                    |rows, (pb, fb), o| {
                        // Block by block: a C-contiguous argument is read in place, a broadcast
                        // or strided one copied a block at a time.
                        let first = rows.start;
                        for b in batch::blocks(rows) {
                            let (pr, fr) = (
                                batch::block(&p, b.clone(), pb),
                                batch::block(&f, b.clone(), fb),
                            );
                            let ob = o
                                .get_mut((b.start - first) * nd..(b.end - first) * nd)
                                .unwrap_or_default();
                            view.displacement_batch(pr, pc.max(1), fr, ob, opts)
                                .map_err(|e| (b.start + e.row, e.error))?;
                        }
                        Ok(())
                    },
                )
            })
            .map_err(PyErr::from)
        })
    }

    /// Leave-one-node-out cross-validation of bilinear vs bicubic: `forces` (K, n_force) [N];
    /// `axis` "y" (remove the grid line y = y_j, predict along columns) or "x". Returns a dict
    /// with `rms_bilinear`, `rms_bicubic` [m] and per-node errors.
    #[pyo3(signature = (forces, axis="y"))]
    fn cross_validate<'py>(
        &self,
        py: Python<'py>,
        forces: &Bound<'py, PyAny>,
        axis: &str,
    ) -> PyResult<Bound<'py, PyDict>> {
        let a = match axis {
            "x" => HoldOutAxis::X,
            "y" => HoldOutAxis::Y,
            _ => {
                return Err(InputError::new_err(format!(
                    "axis must be \"x\" or \"y\", got {axis:?}"
                )));
            }
        };
        let forces = matrix(forces, "forces", None, Some(self.inner.n_force()))?;
        let rows = forces.as_array().nrows();
        check_count(
            "forces",
            rows,
            "rows",
            cm::MAX_MEASUREMENTS,
            "MAX_MEASUREMENTS",
        )?;
        let cv = cm::leave_one_node_out(&self.inner, &rows_of(&forces), a).map_err(build_err)?;
        // deflect-core does not check these outputs: forces near f64::MAX overflow the RMS.
        let rms = [cv.rms_bilinear, cv.rms_bicubic].into_iter().chain(
            cv.nodes
                .iter()
                .flat_map(|n| [n.rms_bilinear, n.rms_bicubic]),
        );
        if let Some(index) = rms.into_iter().position(|x| !x.is_finite()) {
            return Err(tick_err(TickError::NonFiniteOutput {
                what: "cross-validation RMS",
                index,
            }));
        }
        let d = PyDict::new(py);
        d.set_item("axis", axis)?;
        d.set_item("rms_bilinear", cv.rms_bilinear)?;
        d.set_item("rms_bicubic", cv.rms_bicubic)?;
        d.set_item("better", interpolation_name(cv.better()))?;
        let nodes: Vec<(usize, usize, f64, f64)> = cv
            .nodes
            .iter()
            .map(|n| (n.i, n.j, n.rms_bilinear, n.rms_bicubic))
            .collect();
        d.set_item("nodes", nodes)?;
        Ok(d)
    }

    /// Per-node fit statistics (a list in node order `i * ny + j` of dicts with `i, j, x, y`,
    /// `slope, offset, rms, r_squared` arrays (n_displacement, n_force), `condition` and
    /// `samples` (n_force,)), or None for a map not fitted here.
    #[getter]
    fn residuals<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyList>>> {
        let Some(stats) = self.inner.fit_stats() else {
            return Ok(None);
        };
        let (nf, nd) = (self.inner.n_force(), self.inner.n_displacement());
        let list = PyList::empty(py);
        for s in stats {
            let d = PyDict::new(py);
            d.set_item("i", s.i)?;
            d.set_item("j", s.j)?;
            d.set_item("x", s.x)?;
            d.set_item("y", s.y)?;
            let field = |g: fn(&cm::LineStats) -> f64| {
                Array2::from_shape_fn((nd, nf), |(a, b)| {
                    s.lines.get(a * nf + b).map_or(f64::NAN, g)
                })
            };
            d.set_item("slope", field(|l| l.slope).to_pyarray(py))?;
            d.set_item("offset", field(|l| l.offset).to_pyarray(py))?;
            d.set_item("rms", field(|l| l.rms).to_pyarray(py))?;
            d.set_item("r_squared", field(|l| l.r_squared).to_pyarray(py))?;
            d.set_item(
                "condition",
                Array1::from(s.condition.clone()).to_pyarray(py),
            )?;
            d.set_item("samples", s.samples.clone())?;
            list.append(d)?;
        }
        Ok(Some(list))
    }

    /// Node x coordinates (nx,) [m].
    #[getter]
    fn x<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.x().to_pyarray(py)
    }
    /// Node y coordinates (ny,) [m].
    #[getter]
    fn y<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.y().to_pyarray(py)
    }
    /// Number of force axes.
    #[getter]
    fn n_force(&self) -> usize {
        self.inner.n_force()
    }
    /// Number of displacement axes.
    #[getter]
    fn n_displacement(&self) -> usize {
        self.inner.n_displacement()
    }
    /// Default interpolation ("bilinear" | "bicubic").
    #[getter]
    fn interpolation(&self) -> &'static str {
        interpolation_name(self.inner.options().interpolation)
    }
    /// Default out-of-grid policy ("error" | "clamp" | "extrapolate").
    #[getter]
    fn out_of_grid(&self) -> &'static str {
        out_of_grid_name(self.inner.options().out_of_grid)
    }
    /// Slopes (nx, ny, n_displacement, n_force) [m/N].
    #[getter]
    fn slopes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray4<f64>>> {
        self.coefficients(py, self.inner.slopes())
    }
    /// Offsets (nx, ny, n_displacement, n_force) [m]; at zero force `disp_d = sum_f offset`.
    #[getter]
    fn offsets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray4<f64>>> {
        self.coefficients(py, self.inner.offsets())
    }

    fn __repr__(&self) -> String {
        format!(
            "ComplianceMap(grid={}x{}, n_force={}, n_displacement={}, interpolation='{}', out_of_grid='{}')",
            self.inner.x().len(),
            self.inner.y().len(),
            self.inner.n_force(),
            self.inner.n_displacement(),
            self.interpolation(),
            self.out_of_grid()
        )
    }
}

impl ComplianceMap {
    fn coefficients<'py>(&self, py: Python<'py>, v: &[f64]) -> PyResult<Bound<'py, PyArray4<f64>>> {
        let shape = (
            self.inner.x().len(),
            self.inner.y().len(),
            self.inner.n_displacement(),
            self.inner.n_force(),
        );
        let a = Array4::from_shape_vec(shape, v.to_vec())
            .map_err(|e| InputError::new_err(e.to_string()))?;
        Ok(a.into_pyarray(py))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ComplianceMap>()?;
    Ok(())
}
