//! What `deflect.DalembertCorrector` (the paper's five-bar with a 2-D map) and
//! `deflect.DeltaCorrector` (a Delta with a 3-D map) share, one code path for both: the
//! core's model built from the constructor's arguments, its tick state behind a lock, the
//! inputs of a tick and the tick as a dict. Generic over the task dimension `N`.

use std::sync::{Mutex, MutexGuard, PoisonError};

use deflect_core::dalembert::parallel::{self, DisplacementModel, Tick};
use deflect_core::mechanism::Mechanism;
use nalgebra::SVector;
use numpy::ToPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::vector;
use crate::errors::build_err;

/// A parallel corrector: its validated model and its tick state (the last joints, the next
/// IK seed), locked per call so that the class stays frozen and a whole path can be
/// corrected without the GIL.
#[derive(Debug)]
pub(crate) struct Corrector<M, D, const N: usize> {
    pub model: parallel::Model<M, D>,
    data: Mutex<parallel::Data<(), (), N>>,
}

impl<M, D, const N: usize> Corrector<M, D, N>
where
    M: Mechanism<N, N, Data = ()>,
    D: DisplacementModel<N, N, Data = ()>,
{
    /// The corrector of `mechanism` with `map` (copied in), mass parameter `mass` m* \[kg\]
    /// and the fixed-point settings (`iterations` 0 is the paper's one-shot update).
    pub fn new(
        mechanism: M,
        map: D,
        mass: f64,
        iterations: usize,
        tolerance: f64,
    ) -> PyResult<Self> {
        let model = parallel::Model::new(mechanism, map, mass)
            .and_then(|m| m.with_fixed_point(iterations, tolerance))
            .map_err(build_err)?;
        let data = Mutex::new(parallel::Data::new(&model));
        Ok(Self { model, data })
    }
}

impl<M, D, const N: usize> Corrector<M, D, N> {
    /// The tick state. A poisoned lock only means another call failed mid-tick; the state
    /// stays valid.
    pub fn data(&self) -> MutexGuard<'_, parallel::Data<(), (), N>> {
        self.data.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// A tick input of `N` entries (`what` names it in errors).
pub(crate) fn input<const N: usize>(a: &Bound<'_, PyAny>, what: &str) -> PyResult<SVector<f64, N>> {
    Ok(SVector::from_column_slice(&vector(a, what, N)?))
}

/// One tick as the `step` methods return it: `commanded`, `joints`, `force`, `displacement`
/// (arrays of `N`), `iterations` and `model_status` (the worst map placement's name).
pub(crate) fn tick_dict<'py, const N: usize>(
    py: Python<'py>,
    t: &Tick<N, N>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("commanded", t.commanded.as_slice().to_pyarray(py))?;
    d.set_item("joints", t.joints.as_slice().to_pyarray(py))?;
    d.set_item("force", t.load.as_slice().to_pyarray(py))?;
    d.set_item("displacement", t.displacement.as_slice().to_pyarray(py))?;
    d.set_item("iterations", t.iterations)?;
    d.set_item("model_status", t.diagnostics.placement.name())?;
    Ok(d)
}
