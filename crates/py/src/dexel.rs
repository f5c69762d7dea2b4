//! The tri-dexel stock from Python (deflect-core's `machining::dexel`): a block cut by a
//! flat, ball or bull-nose tool at any orientation, or by a whole program.

use deflect_core::machining::cutting::Tool;
use deflect_core::machining::dexel::{DexelTool, Dexels as CoreDexels};
use deflect_core::machining::profile::Profile;
use nalgebra::Vector3;
use numpy::ndarray::Array1;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use std::sync::Mutex;

use crate::InputError;
use crate::arrays::{matrix, vector};
use crate::errors::{build_err, tick_err};
use crate::machining::GcodeProgram;

/// A block of stock as three grids of rays (x, y, z), each holding its material's intervals,
/// cut exactly by a tool swept at any orientation. `min`, `max` (3,) [m]: the block;
/// `cell` [m]: the rays' spacing (memory: 24 bytes per ray, 16 per interval; budgets
/// MAX_RAYS = 2^25, MAX_INTERVALS = 2^26).
#[pyclass(module = "deflect")]
#[derive(Debug)]
pub struct Dexels {
    inner: Mutex<CoreDexels>,
}

fn three(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector3<f64>> {
    Ok(Vector3::from_column_slice(&vector(o, what, 3)?))
}

/// The tool's solid: `shape` "flat" | "ball" | "bull-nose" (with `corner_radius`),
/// `diameter` and `length` above the tip [m].
fn tool(
    shape: &str,
    diameter: f64,
    length: f64,
    corner_radius: Option<f64>,
) -> PyResult<DexelTool> {
    let shape = crate::cutter::shape(shape, corner_radius)?;
    let t = Tool::new(diameter, 2, 0.0).map_err(build_err)?;
    let p = Profile::new(&t, shape).map_err(build_err)?;
    DexelTool::new(&p, length).map_err(build_err)
}

#[pymethods]
impl Dexels {
    #[new]
    fn new(min: &Bound<'_, PyAny>, max: &Bound<'_, PyAny>, cell: f64) -> PyResult<Self> {
        let d =
            CoreDexels::block(three(min, "min")?, three(max, "max")?, cell).map_err(build_err)?;
        Ok(Self {
            inner: Mutex::new(d),
        })
    }

    /// Sweeps the tool from `start` to `end` (tips, (3,) [m]) with its axis turning from
    /// `start_axis` to `end_axis` (unit, tip towards spindle): `(rays updated, volume
    /// removed [m^3])`.
    #[pyo3(signature = (shape, diameter, length, start, start_axis, end, end_axis, *, corner_radius=None))]
    #[allow(clippy::too_many_arguments)] // reason: the documented Python arguments
    fn cut(
        &self,
        py: Python<'_>,
        shape: &str,
        diameter: f64,
        length: f64,
        start: &Bound<'_, PyAny>,
        start_axis: &Bound<'_, PyAny>,
        end: &Bound<'_, PyAny>,
        end_axis: &Bound<'_, PyAny>,
        corner_radius: Option<f64>,
    ) -> PyResult<(usize, f64)> {
        let t = tool(shape, diameter, length, corner_radius)?;
        let (a, aa, b, ba) = (
            three(start, "start")?,
            three(start_axis, "start_axis")?,
            three(end, "end")?,
            three(end_axis, "end_axis")?,
        );
        let mut guard = self
            .inner
            .lock()
            .map_err(|_| InputError::new_err("stock poisoned"))?;
        let d: &mut CoreDexels = &mut guard;
        let r = py
            .detach(|| d.cut(&t, &a, &aa, &b, &ba))
            .map_err(tick_err)?;
        Ok((r.rays, r.volume))
    }

    /// Cuts every move of `program` (its tool axes; arcs as chords within an eighth of a
    /// cell): `(rays updated, volume removed [m^3])`.
    #[pyo3(signature = (program, shape, diameter, length, *, corner_radius=None))]
    fn cut_program(
        &self,
        py: Python<'_>,
        program: &GcodeProgram,
        shape: &str,
        diameter: f64,
        length: f64,
        corner_radius: Option<f64>,
    ) -> PyResult<(usize, f64)> {
        let t = tool(shape, diameter, length, corner_radius)?;
        let mut guard = self
            .inner
            .lock()
            .map_err(|_| InputError::new_err("stock poisoned"))?;
        let d: &mut CoreDexels = &mut guard;
        let p = &program.inner;
        let r = py.detach(|| d.cut_program(&t, p)).map_err(tick_err)?;
        Ok((r.rays, r.volume))
    }

    /// Whether each point (n, 3) [m] is material (read from the nearest z-ray).
    fn is_material<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let pts = matrix(points, "points", None, Some(3))?;
        let d = self
            .inner
            .lock()
            .map_err(|_| InputError::new_err("stock poisoned"))?;
        let out: Array1<bool> = pts
            .as_array()
            .rows()
            .into_iter()
            .map(|r| {
                let at = |i: usize| r.get(i).copied().unwrap_or(f64::NAN);
                d.is_material(&Vector3::new(at(0), at(1), at(2)))
            })
            .collect();
        Ok(out.into_pyarray(py))
    }

    /// The material's volume [m^3].
    #[getter]
    fn volume(&self) -> PyResult<f64> {
        let d = self
            .inner
            .lock()
            .map_err(|_| InputError::new_err("stock poisoned"))?;
        Ok(d.volume())
    }

    /// Cells along x, y, z.
    #[getter]
    fn shape(&self) -> PyResult<(usize, usize, usize)> {
        let d = self
            .inner
            .lock()
            .map_err(|_| InputError::new_err("stock poisoned"))?;
        let [a, b, c] = d.shape();
        Ok((a, b, c))
    }
}

/// Adds `Dexels` to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Dexels>()
}
