//! `deflect.GridMap`: deflect-core's compliance map over a 1-4 dimensional grid (Paksoy et al.
//! 2025, Eq. 9-14, over task-space or joint coordinates). SI units in and out.

use deflect_core::TickError;
use deflect_core::compliance_map::{
    self as cm, FitOptions, GridMap as CoreGrid, GridMeasurement, MAX_AXES, MAX_GRID_DIMS,
    QueryOptions,
};
use deflect_core::io::{grid_csv, map_json};
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArray1, PyArrayDyn, PyUntypedArrayMethods, ToPyArray};
use pyo3::prelude::*;

use crate::InputError;
use crate::args;
use crate::arrays::{array_dyn, check_count, indices, matrix, try_copy, vector_upto};
use crate::compliance_map::{ComplianceMap, units};
use crate::errors::{build_err, load_err, shape_error, tick_err, tick_err_at};
use crate::map_common::{self, interpolation_name, out_of_grid_name, query_options};
use crate::out::fill_into;

/// A compliance map over a grid of 1 to 4 dimensions: `axes` a list of 1-4 increasing node
/// coordinate arrays (task space x, y, z [m], or joint angles [rad]), named by `names`
/// (default "x", "y", "z", "w"); `slopes` and `offsets` of shape
/// (n_0, ..., n_{N-1}, n_displacement, n_force) [m/N, m]. `interpolation`: "multilinear" (the
/// paper's Eq. 14 in N-D; "bilinear" is accepted) or "cubic" (C1 cubic Hermite);
/// `out_of_grid`: "error", "clamp" or "extrapolate". Build one from static tests with
/// `GridMap.fit`, from a 2-D `ComplianceMap` with `GridMap.from_map`, or from its JSON
/// (`format_version` 2; version 1, a 2-D map, is read too).
#[pyclass(module = "deflect", frozen, eq)]
#[derive(Debug, Clone, PartialEq)]
pub struct GridMap {
    pub(crate) inner: CoreGrid,
}

/// The default axis names.
const NAMES: [&str; MAX_GRID_DIMS] = ["x", "y", "z", "w"];

fn names_or_default(names: Option<Vec<String>>, dims: usize) -> Vec<String> {
    names.unwrap_or_else(|| NAMES.iter().take(dims).map(|s| s.to_string()).collect())
}

impl GridMap {
    fn options(
        &self,
        interpolation: Option<&str>,
        out_of_grid: Option<&str>,
    ) -> PyResult<QueryOptions> {
        map_common::options_over(self.inner.options(), interpolation, out_of_grid)
    }

    /// A tick error, an out-of-grid one naming the map's axis (the core's message knows axes
    /// by index only).
    fn query_err(&self, context: Option<usize>, e: TickError) -> PyErr {
        let at = context.map_or(String::new(), |r| format!("row {r}: "));
        match e {
            TickError::OutOfGrid {
                axis,
                value,
                min,
                max,
            } => InputError::new_err(format!(
                "{at}point {} = {value:?} (axis {axis}) is outside the grid [{min:?}, {max:?}]",
                self.inner.names().get(axis).map_or("?", String::as_str)
            )),
            e => match context {
                Some(r) => tick_err_at(format_args!("row {r}"), e),
                None => tick_err(e),
            },
        }
    }

    fn coefficients<'py>(
        &self,
        py: Python<'py>,
        v: &[f64],
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let mut shape: Vec<usize> = self.inner.axes().iter().map(Vec::len).collect();
        shape.extend([self.inner.n_displacement(), self.inner.n_force()]);
        let a = ArrayD::from_shape_vec(IxDyn(&shape), v.to_vec())
            .map_err(|e| InputError::new_err(e.to_string()))?;
        Ok(a.into_pyarray(py))
    }
}

#[pymethods]
impl GridMap {
    #[new]
    #[pyo3(signature = (axes, n_force, n_displacement, slopes, offsets, *, names=None,
        interpolation="multilinear", out_of_grid="error"))]
    #[allow(clippy::too_many_arguments)] // reason: mirrors the documented Python signature
    fn new(
        axes: Vec<Bound<'_, PyAny>>,
        #[pyo3(from_py_with = args::count::n_force)] n_force: usize,
        #[pyo3(from_py_with = args::count::n_displacement)] n_displacement: usize,
        slopes: &Bound<'_, PyAny>,
        offsets: &Bound<'_, PyAny>,
        names: Option<Vec<String>>,
        interpolation: &str,
        out_of_grid: &str,
    ) -> PyResult<Self> {
        if axes.is_empty() || axes.len() > MAX_GRID_DIMS {
            return Err(InputError::new_err(format!(
                "axes: {} given; expected 1 to {MAX_GRID_DIMS}",
                axes.len()
            )));
        }
        let mut nodes = Vec::with_capacity(axes.len());
        for (k, a) in axes.iter().enumerate() {
            nodes.push(vector_upto(
                a,
                &format!("axes[{k}]"),
                cm::MAX_GRID_NODES,
                "MAX_GRID_NODES",
            )?);
        }
        let flat = |o: &Bound<'_, PyAny>, what: &str| -> PyResult<Vec<f64>> {
            let a = array_dyn(o, what)?;
            let n: usize = nodes.iter().map(Vec::len).product();
            check_count(
                what,
                a.len(),
                "entries",
                cm::MAX_GRID_NODES * 36,
                "MAX_GRID_NODES x 36",
            )?;
            // The exact shape, not only the count: a transposed array has the same count
            // and would be read in the wrong order.
            let mut want: Vec<usize> = nodes.iter().map(Vec::len).collect();
            want.extend([n_displacement, n_force]);
            if a.len() != n * n_force * n_displacement || a.shape() != want.as_slice() {
                let want: Vec<String> = want.iter().map(usize::to_string).collect();
                return Err(shape_error(
                    what,
                    &format!("({})", want.join(", ")),
                    a.shape(),
                ));
            }
            Ok(a.as_array().iter().copied().collect())
        };
        let (s, o) = (flat(slopes, "slopes")?, flat(offsets, "offsets")?);
        let dims = nodes.len();
        let inner = CoreGrid::new(
            nodes,
            names_or_default(names, dims),
            n_force,
            n_displacement,
            s,
            o,
        )
        .map_err(build_err)?;
        Ok(Self {
            inner: inner.with_options(query_options(interpolation, out_of_grid)?),
        })
    }

    /// Fits a map from static tests (Eq. 10-13 at every node of an N-D grid): `points`
    /// (M, dims) node coordinates, `force_axis` (M,) the loaded force axis, `force` (M,) its
    /// level [N], `displacement` (M, n_displacement) [m]. Coordinates within
    /// `position_tolerance` share a grid line; every node of the grid of distinct coordinates
    /// needs at least 2 force levels per force axis. Errors name the reading or the node.
    #[staticmethod]
    #[pyo3(signature = (points, force_axis, force, displacement, *, names=None, n_force=None,
        position_tolerance=1e-6, interpolation="multilinear", out_of_grid="error"))]
    #[allow(clippy::too_many_arguments)] // reason: mirrors the documented Python signature
    fn fit(
        points: &Bound<'_, PyAny>,
        force_axis: &Bound<'_, PyAny>,
        force: &Bound<'_, PyAny>,
        displacement: &Bound<'_, PyAny>,
        names: Option<Vec<String>>,
        #[pyo3(from_py_with = args::opt_count::n_force)] n_force: Option<usize>,
        #[pyo3(from_py_with = args::real::position_tolerance)] position_tolerance: f64,
        interpolation: &str,
        out_of_grid: &str,
    ) -> PyResult<Self> {
        let p = matrix(points, "points", None, None)?;
        let p = p.as_array();
        let (m, dims) = (p.nrows(), p.ncols());
        if dims == 0 || dims > MAX_GRID_DIMS {
            return Err(shape_error("points", "(M, 1) to (M, 4)", p.shape()));
        }
        check_count(
            "points",
            m,
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
        let forces = vector_upto(force, "force", cm::MAX_MEASUREMENTS, "MAX_MEASUREMENTS")?;
        let d = matrix(displacement, "displacement", Some(m), None)?;
        let d = d.as_array();
        let nd = d.ncols();
        if nd == 0 || nd > MAX_AXES {
            return Err(shape_error("displacement", "(M, 1) to (M, 6)", d.shape()));
        }
        for (what, len) in [("force_axis", axes.len()), ("force", forces.len())] {
            if len != m {
                return Err(shape_error(what, &format!("({m},)"), &[len]));
            }
        }
        let nf = n_force.unwrap_or_else(|| axes.iter().max().map_or(1, |a| a + 1));
        let readings: Vec<GridMeasurement> = (0..m)
            .map(|r| {
                let point: Vec<f64> = p.row(r).iter().copied().collect();
                let disp: Vec<f64> = d.row(r).iter().copied().collect();
                GridMeasurement::new(
                    &point,
                    axes.get(r).copied().unwrap_or(0),
                    forces.get(r).copied().unwrap_or(f64::NAN),
                    &disp,
                )
            })
            .collect();
        let options = FitOptions {
            n_force: nf,
            n_displacement: nd,
            position_tolerance,
        };
        let inner =
            cm::fit_grid(names_or_default(names, dims), &readings, &options).map_err(build_err)?;
        Ok(Self {
            inner: inner.with_options(query_options(interpolation, out_of_grid)?),
        })
    }

    /// Fits a map from a CSV of static tests on a grid whose axes the columns name: one to four
    /// `<name>_<unit>` columns (unit `m`, `mm`, `rad` or `deg`: `x_mm, y_mm, z_mm` for a
    /// Delta, `q2_deg, q3_deg` for an arm's elbow), `force_axis` (0.. or x, y, z, mx, my, mz),
    /// `force` [force_unit], displacement columns `dx, dy, dz` [length_unit], `rx, ry, rz`
    /// [rad]. Any other column is refused by name.
    #[staticmethod]
    #[pyo3(signature = (path, force_unit="N", length_unit="mm", n_force=None, position_tolerance=1e-6,
        interpolation="multilinear", out_of_grid="error"))]
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
        let inner = grid_csv::fit_static_path(&path, f, l, n_force, position_tolerance)
            .map_err(load_err)?;
        Ok(Self {
            inner: inner.with_options(query_options(interpolation, out_of_grid)?),
        })
    }

    /// The 2-D `ComplianceMap` as a grid map over axes "x", "y" (same coefficients, same
    /// default options).
    #[staticmethod]
    fn from_map(map: &ComplianceMap) -> Self {
        Self {
            inner: CoreGrid::from_map(&map.inner),
        }
    }

    /// The map as versioned JSON (`"format_version": 2`, named axes, SI units); exact round
    /// trip.
    fn to_json(&self) -> PyResult<String> {
        map_json::grid_to_string(&self.inner).map_err(load_err)
    }

    /// Writes the map's JSON (see `to_json`) to the file `path`.
    fn save_json(&self, path: std::path::PathBuf) -> PyResult<()> {
        map_json::grid_to_path(&self.inner, &path).map_err(load_err)
    }

    /// Loads a map from JSON text (a `str` starting with `{`) or a path: version 2, or a 2-D
    /// map of version 1.
    #[staticmethod]
    fn from_json(source: &Bound<'_, PyAny>) -> PyResult<Self> {
        let inner = map_common::json_source(source, map_json::grid_from_str, |p| {
            map_json::grid_from_path(p)
        })?;
        Ok(Self { inner })
    }

    /// Pickling and `copy.deepcopy`: the map's JSON, an exact round trip.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let rebuild = slf.get_type().getattr("from_json")?;
        Ok((rebuild, (slf.get().to_json()?,)))
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

    /// Displacement (n_displacement,) [m] at `point` (dims,) under `force` (n_force,) [N];
    /// keywords override the default options for this call. Into `out` (n_displacement,) if
    /// given.
    #[pyo3(signature = (point, force, *, interpolation=None, out_of_grid=None, out=None))]
    fn displacement<'py>(
        &self,
        py: Python<'py>,
        point: &Bound<'py, PyAny>,
        force: &Bound<'py, PyAny>,
        interpolation: Option<&str>,
        out_of_grid: Option<&str>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let o = self.options(interpolation, out_of_grid)?;
        let p = vector_upto(point, "point", MAX_GRID_DIMS, "MAX_GRID_DIMS")?;
        let f = vector_upto(force, "force", MAX_AXES, "MAX_AXES")?;
        map_common::one_query(py, self.inner.n_displacement(), out, |d| {
            self.inner
                .displacement_with(&p, &f, d, o)
                .map_err(|e| self.query_err(None, e))
        })
    }

    /// Displacements (N, n_displacement) [m] at points `P` (N, dims) under forces `F`
    /// (N, n_force), or one force row (n_force,) for every point [N]. Runs without the GIL;
    /// the first refused row raises naming it. Into `out` (N, n_displacement) if given.
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
        let o = self.options(interpolation, out_of_grid)?;
        let (dims, nf, nd) = (
            self.inner.dims(),
            self.inner.n_force(),
            self.inner.n_displacement(),
        );
        let p = matrix(P, "P", None, Some(dims))?;
        let p = p.as_array();
        let n = p.nrows();
        let f = array_dyn(F, "F")?;
        let fshape = f.shape().to_vec();
        let single = fshape == [nf] || fshape == [1, nf];
        if !single && fshape != [n, nf] {
            return Err(shape_error(
                "F",
                &format!("({n}, {nf}) or ({nf},)"),
                &fshape,
            ));
        }
        // float64 C-contiguous arguments are read in place, others copied fallibly. A single
        // force row (n_force entries) broadcasts over the points in the core.
        let (fa, pa) = (f.as_array(), p.view());
        let (f_copy, p_copy);
        let forces = match fa.as_slice() {
            Some(v) => v,
            None => {
                f_copy = try_copy(&fa, "F")?;
                &f_copy[..]
            }
        };
        let points = match pa.as_slice() {
            Some(v) => v,
            None => {
                p_copy = try_copy(&pa, "P")?;
                &p_copy[..]
            }
        };
        fill_into(py, &[n, nd], out, |buf| {
            py.detach(|| self.inner.displacement_batch_with(points, forces, buf, o))
                .map(|_| ())
                .map_err(|e| self.query_err(Some(e.row), e.error))
        })
    }

    /// Grid dimensions.
    #[getter]
    fn dims(&self) -> usize {
        self.inner.dims()
    }
    /// Axis names.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.inner.names().to_vec()
    }
    /// Node coordinates per axis.
    #[getter]
    fn axes<'py>(&self, py: Python<'py>) -> Vec<Bound<'py, PyArray1<f64>>> {
        self.inner.axes().iter().map(|a| a.to_pyarray(py)).collect()
    }
    /// Force axes.
    #[getter]
    fn n_force(&self) -> usize {
        self.inner.n_force()
    }
    /// Displacement axes.
    #[getter]
    fn n_displacement(&self) -> usize {
        self.inner.n_displacement()
    }
    /// Default interpolation: "multilinear" or "cubic".
    #[getter]
    fn interpolation(&self) -> &'static str {
        match interpolation_name(self.inner.options().interpolation) {
            "bicubic" => "cubic",
            _ => "multilinear",
        }
    }
    /// Default out-of-grid policy.
    #[getter]
    fn out_of_grid(&self) -> &'static str {
        out_of_grid_name(self.inner.options().out_of_grid)
    }
    /// Slopes (n_0, ..., n_{N-1}, n_displacement, n_force) [m/N].
    #[getter]
    fn slopes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        self.coefficients(py, self.inner.slopes())
    }
    /// Offsets (n_0, ..., n_{N-1}, n_displacement, n_force) [m].
    #[getter]
    fn offsets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        self.coefficients(py, self.inner.offsets())
    }

    fn __repr__(&self) -> String {
        let shape: Vec<String> = self
            .inner
            .axes()
            .iter()
            .map(|a| a.len().to_string())
            .collect();
        format!(
            "GridMap(names={:?}, nodes={}, n_force={}, n_displacement={}, interpolation='{}')",
            self.inner.names(),
            shape.join("x"),
            self.inner.n_force(),
            self.inner.n_displacement(),
            self.interpolation()
        )
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<GridMap>()?;
    m.add("MAX_GRID_DIMS", MAX_GRID_DIMS)?;
    m.add("MAX_GRID_NODES", cm::MAX_GRID_NODES)?;
    Ok(())
}
