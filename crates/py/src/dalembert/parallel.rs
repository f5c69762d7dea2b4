//! `deflect.DalembertCorrector`: the 2 kHz D'Alembert trajectory corrector of the paper's
//! parallel robot driven by a compliance map.

use deflect_core::compliance_map::ComplianceMap as CoreMap;
use deflect_core::dalembert::parallel::{self, Tick};
use deflect_core::mechanism::ParallelRobot2 as CoreRobot2;
use deflect_core::{Placement, TickError};
use nalgebra::Vector2;
use numpy::ndarray::{Array1, Array2, Ix2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::corrector::{self, Corrector};
use crate::InputError;
use crate::args;
use crate::arrays::{try_array, try_copy};
use crate::compliance_map::ComplianceMap;
use crate::errors::{tick_err, tick_err_at};
use crate::mechanism::ParallelRobot2;
use crate::motion::Trajectory;

/// D'Alembert trajectory correction of the paper's five-bar (Paksoy et al., Fig. 2) from a
/// compliance map: per tick `F_D = -mass * a` (Eq. 5), displacement from the compliance map
/// (Eq. 9-14), command = desired - displacement (iterated `iterations` times to a fixed point
/// if > 0), closed-form IK. SI units. For a serial arm, use `SerialDalembertCorrector`.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct DalembertCorrector {
    /// The corrector of the paper's robot driven by a compliance map (copied in at
    /// construction), with its tick state.
    corrector: Corrector<CoreRobot2, CoreMap, 2>,
    /// The constructor's arguments, for pickling.
    config: Py<pyo3::types::PyTuple>,
}

/// Result of `DalembertCorrector.correct`: one row per tick.
#[pyclass(module = "deflect", frozen, get_all)]
#[derive(Debug)]
pub struct CorrectedPath {
    /// Tick times [s], (N,).
    t: Py<PyArray1<f64>>,
    /// Desired (planned) points [m], (N, 2).
    desired: Py<PyArray2<f64>>,
    /// Commanded points [m], (N, 2) (`step()['commanded']` per tick).
    commanded: Py<PyArray2<f64>>,
    /// Joint commands [rad], (N, 2).
    joints: Py<PyArray2<f64>>,
    /// D'Alembert forces [N], (N, 2).
    force: Py<PyArray2<f64>>,
    /// Predicted displacements [m], (N, 2).
    displacement: Py<PyArray2<f64>>,
    /// Ticks at which the map clamped or extrapolated.
    flagged_ticks: Vec<usize>,
}

#[pymethods]
impl CorrectedPath {
    /// The old name of `commanded` (kept so that existing code runs; `commanded` is the name
    /// `step()` and `SerialDalembertCorrector` use).
    #[getter]
    fn position(&self, py: Python<'_>) -> Py<PyArray2<f64>> {
        self.commanded.clone_ref(py)
    }
}

#[pymethods]
impl DalembertCorrector {
    /// `compliance_map` (2 forces x 2 displacements, its out-of-grid policy applies),
    /// `mechanism` (a `ParallelRobot2`), `mass` m* [kg] (the paper tuned 5 kg); fixed-point
    /// `iterations` (a count) and `tolerance` [m] (finite, >= 0).
    #[new]
    #[pyo3(signature = (compliance_map, mechanism, mass=parallel::PAPER_MASS, iterations=0, tolerance=0.0),
           text_signature = "(compliance_map, mechanism, mass=5.0, iterations=0, tolerance=0.0)")]
    fn new(
        compliance_map: &Bound<'_, ComplianceMap>,
        mechanism: &Bound<'_, PyAny>,
        #[pyo3(from_py_with = args::real::mass)] mass: f64,
        #[pyo3(from_py_with = args::count::iterations)] iterations: usize,
        #[pyo3(from_py_with = args::real::tolerance)] tolerance: f64,
    ) -> PyResult<Self> {
        let Ok(mechanism) = mechanism.cast::<ParallelRobot2>() else {
            let hint = if mechanism.is_instance_of::<crate::vjm::SerialRobot>() {
                "; for a serial arm use SerialDalembertCorrector(robot, mass, ...), which \
                 corrects in 6-D through the robot's own stiffness model"
            } else {
                ""
            };
            return Err(InputError::new_err(format!(
                "mechanism: expected a ParallelRobot2 (the paper's five-bar, driven by a \
                 compliance map), got {}{hint}",
                mechanism.get_type().name()?
            )));
        };
        let corrector = Corrector::new(
            mechanism.get().inner,
            compliance_map.get().inner.clone(),
            mass,
            iterations,
            tolerance,
        )?;
        let config = (compliance_map, mechanism, mass, iterations, tolerance)
            .into_pyobject(compliance_map.py())?
            .unbind();
        Ok(Self { corrector, config })
    }

    /// Pickling and `copy.deepcopy`: the configuration (the constructor's arguments, the map
    /// and mechanism pickled with it). The tick state (the last joints) is not pickled: a
    /// copy starts from its first tick, as a new corrector would.
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

    /// One tick: `position` (2,) [m], planned `acceleration` (2,) [m/s^2] -> dict with
    /// `commanded`, `joints`, `force`, `displacement`, `iterations`, `model_status`. The IK
    /// starts from the last tick's joints, or from `seed` (2,) [rad] if given (the paper's
    /// closed-form IK ignores the seed).
    #[pyo3(signature = (position, acceleration, seed=None))]
    fn step<'py>(
        &self,
        py: Python<'py>,
        position: &Bound<'py, PyAny>,
        acceleration: &Bound<'py, PyAny>,
        seed: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let x = corrector::input::<2>(position, "position")?;
        let a = corrector::input::<2>(acceleration, "acceleration")?;
        let seed = seed.map(|s| corrector::input::<2>(s, "seed")).transpose()?;
        let c = &self.corrector;
        let t: Tick<2, 2> = {
            let mut data = c.data();
            if let Some(q) = seed {
                data.set_seed(q);
            }
            parallel::step(&c.model, &mut data, &x, &a).map_err(tick_err)?
        };
        corrector::tick_dict(py, &t)
    }

    /// Corrects every tick of a planned 2-D `trajectory` (from `plan_line`/`plan_polyline`),
    /// without the GIL. The same arithmetic as `step`, tick by tick, each IK seeded by the
    /// previous tick (the first by the corrector's last joints).
    fn correct(&self, py: Python<'_>, trajectory: &Trajectory) -> PyResult<CorrectedPath> {
        let samples = trajectory.samples(py)?;
        let (pos, acc) = (&samples.position, &samples.acceleration);
        if pos.ncols() != 2 {
            return Err(InputError::new_err(format!(
                "trajectory: the corrector needs a 2-D trajectory, got {} columns",
                pos.ncols()
            )));
        }
        let n = pos.nrows();
        // Five results of the trajectory's length: allocated fallibly (MemoryError, never an
        // abort), before the GIL is released.
        let what = "the corrected path";
        let mut out: [Array2<f64>; 5] = [
            try_array(Ix2(n, 2), what)?,
            try_array(Ix2(n, 2), what)?,
            try_array(Ix2(n, 2), what)?,
            try_array(Ix2(n, 2), what)?,
            try_array(Ix2(n, 2), what)?,
        ];
        let t = Array1::from_vec(try_copy(&samples.t.view(), what)?);
        let result = py.detach(|| -> Result<_, (usize, TickError)> {
            let c = &self.corrector;
            let mut data = c.data();
            let mut flagged = Vec::new();
            let inputs = pos.rows().into_iter().zip(acc.rows());
            for (i, (prow, arow)) in inputs.enumerate() {
                let x = Vector2::from_iterator(prow.iter().copied());
                let a = Vector2::from_iterator(arow.iter().copied());
                let t = parallel::step(&c.model, &mut data, &x, &a).map_err(|e| (i, e))?;
                for (arr, v) in
                    out.iter_mut()
                        .zip([t.desired, t.commanded, t.joints, t.load, t.displacement])
                {
                    arr.row_mut(i)
                        .iter_mut()
                        .zip(v.iter())
                        .for_each(|(d, s)| *d = *s);
                }
                if t.diagnostics.placement != Placement::Inside {
                    flagged.push(i);
                }
            }
            Ok(flagged)
        });
        let flagged = result.map_err(|(i, e)| tick_err_at(format_args!("tick {i}"), e))?;
        let [desired, position, joints, force, displacement] = out;
        Ok(CorrectedPath {
            t: t.into_pyarray(py).unbind(),
            desired: desired.into_pyarray(py).unbind(),
            commanded: position.into_pyarray(py).unbind(),
            joints: joints.into_pyarray(py).unbind(),
            force: force.into_pyarray(py).unbind(),
            displacement: displacement.into_pyarray(py).unbind(),
            flagged_ticks: flagged,
        })
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<DalembertCorrector>()?;
    m.add_class::<CorrectedPath>()?;
    Ok(())
}
