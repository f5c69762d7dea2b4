//! `deflect.DeltaCorrector`: the paper's D'Alembert corrector (Paksoy, Dede and Kiper 2025,
//! Fig. 2) on a Delta robot, driven by a 3-D task-space compliance map (`GridMap`).

use deflect_core::compliance_map::GridMap as CoreGrid;
use deflect_core::dalembert::parallel::{self, Tick};
use deflect_core::mechanism::Delta as CoreDelta;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::corrector::{self, Corrector};
use crate::args;
use crate::errors::tick_err;
use crate::grid_map::GridMap;
use crate::mechanism::Delta;

/// D'Alembert correction of a Delta robot from a 3-D compliance map over (x, y, z): per tick
/// `F_D = -mass * a` (Eq. 5), the platform's displacement under it from the map (Eq. 9-14 in
/// 3-D; the map's interpolation and out-of-grid policy apply), command = desired -
/// displacement (iterated `iterations` times to a fixed point if > 0), closed-form IK.
/// `grid_map`: 3 axes, 3 force and 3 displacement axes. SI units.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct DeltaCorrector {
    corrector: Corrector<CoreDelta, CoreGrid, 3>,
    /// The constructor's arguments, for pickling.
    config: Py<pyo3::types::PyTuple>,
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
        let corrector = Corrector::new(
            delta.get().inner,
            grid_map.get().inner.clone(),
            mass,
            iterations,
            tolerance,
        )?;
        let config = (grid_map, delta, mass, iterations, tolerance)
            .into_pyobject(grid_map.py())?
            .unbind();
        Ok(Self { corrector, config })
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
        self.corrector.model.mass()
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
        let x = corrector::input::<3>(position, "position")?;
        let a = corrector::input::<3>(acceleration, "acceleration")?;
        let c = &self.corrector;
        let t: Tick<3, 3> = parallel::step(&c.model, &mut c.data(), &x, &a).map_err(tick_err)?;
        corrector::tick_dict(py, &t)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<DeltaCorrector>()
}
