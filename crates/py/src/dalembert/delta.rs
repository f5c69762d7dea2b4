//! `deflect.DeltaCorrector`: the paper's D'Alembert corrector (Paksoy, Dede and Kiper 2025,
//! Fig. 2) on a Delta robot, driven by a 3-D task-space compliance map (`GridMap`).

use std::sync::{Mutex, MutexGuard, PoisonError};

use deflect_core::compliance_map::GridMap as CoreGrid;
use deflect_core::dalembert::parallel::{self, Tick};
use deflect_core::mechanism::Delta as CoreDelta;
use nalgebra::Vector3;
use numpy::ToPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::args;
use crate::arrays::vector;
use crate::errors::{build_err, tick_err};
use crate::grid_map::GridMap;
use crate::mechanism::Delta;

type Model = parallel::Model<CoreDelta, CoreGrid>;
type Data = parallel::Data<(), (), 3>;

fn vec3(a: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector3<f64>> {
    Ok(Vector3::from_column_slice(&vector(a, what, 3)?))
}

/// D'Alembert correction of a Delta robot from a 3-D compliance map over (x, y, z): per tick
/// `F_D = -mass * a` (Eq. 5), the platform's displacement under it from the map (Eq. 9-14 in
/// 3-D; the map's interpolation and out-of-grid policy apply), command = desired -
/// displacement (iterated `iterations` times to a fixed point if > 0), closed-form IK.
/// `grid_map`: 3 axes, 3 force and 3 displacement axes. SI units.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct DeltaCorrector {
    model: Model,
    data: Mutex<Data>,
    config: Py<pyo3::types::PyTuple>,
}

impl DeltaCorrector {
    fn data(&self) -> MutexGuard<'_, Data> {
        // A poisoned lock only means another call failed mid-tick; the data stays valid.
        self.data.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

#[pymethods]
impl DeltaCorrector {
    #[new]
    #[pyo3(signature = (grid_map, delta, mass, iterations=0, tolerance=0.0))]
    fn new(
        grid_map: &Bound<'_, GridMap>,
        delta: &Bound<'_, Delta>,
        #[pyo3(from_py_with = args::real::mass)] mass: f64,
        #[pyo3(from_py_with = args::count::iterations)] iterations: usize,
        #[pyo3(from_py_with = args::real::tolerance)] tolerance: f64,
    ) -> PyResult<Self> {
        let model = Model::new(delta.get().inner, grid_map.get().inner.clone(), mass)
            .and_then(|m| m.with_fixed_point(iterations, tolerance))
            .map_err(build_err)?;
        let data = Mutex::new(Data::new(&model));
        let config = (grid_map, delta, mass, iterations, tolerance)
            .into_pyobject(grid_map.py())?
            .unbind();
        Ok(Self {
            model,
            data,
            config,
        })
    }

    /// Pickling and `copy.deepcopy`: the constructor's arguments; a copy starts from its
    /// first tick.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (
        Bound<'py, pyo3::types::PyType>,
        Bound<'py, pyo3::types::PyTuple>,
    ) {
        (slf.get_type(), slf.get().config.bind(slf.py()).clone())
    }

    /// Mass parameter m* [kg].
    #[getter]
    fn mass(&self) -> f64 {
        self.model.mass()
    }

    /// One tick: platform `position` (3,) [m], planned `acceleration` (3,) [m/s^2] -> dict
    /// with `commanded` (3,) [m], `joints` (3,) [rad], `force` (3,) [N], `displacement` (3,)
    /// [m], `iterations`, `model_status`.
    fn step<'py>(
        &self,
        py: Python<'py>,
        position: &Bound<'py, PyAny>,
        acceleration: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let x = vec3(position, "position")?;
        let a = vec3(acceleration, "acceleration")?;
        let t: Tick<3, 3> =
            parallel::step(&self.model, &mut self.data(), &x, &a).map_err(tick_err)?;
        let d = PyDict::new(py);
        d.set_item("commanded", t.commanded.as_slice().to_pyarray(py))?;
        d.set_item("joints", t.joints.as_slice().to_pyarray(py))?;
        d.set_item("force", t.load.as_slice().to_pyarray(py))?;
        d.set_item("displacement", t.displacement.as_slice().to_pyarray(py))?;
        d.set_item("iterations", t.iterations)?;
        d.set_item("model_status", t.diagnostics.placement.name())?;
        Ok(d)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<DeltaCorrector>()
}
