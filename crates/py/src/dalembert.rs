//! `deflect.DalembertCorrector`: the 2 kHz D'Alembert trajectory corrector of the paper's
//! parallel robot driven by a compliance map.

use deflect_core::compliance_map::{ComplianceMap as CoreMap, QueryError};
use deflect_core::dalembert::{
    CorrectedTick, CorrectorError, DalembertCorrector as CoreCorrector, ModelStatus,
};
use deflect_core::mechanism::ParallelRobot2 as CoreRobot2;
use nalgebra::Vector2;
use numpy::ndarray::{Array1, Array2};
use numpy::{PyArray1, PyArray2, ToPyArray};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::InputError;
use crate::compliance_map::ComplianceMap;
use crate::convert::{Arr1, finite_vec};
use crate::motion::{ParallelRobot2, Trajectory, mech_err};

fn corr_err(e: CorrectorError) -> PyErr {
    match e {
        CorrectorError::Mechanism(m) => mech_err(m),
        CorrectorError::Map(QueryError::OutOfGrid { .. }) => InputError::new_err(e.to_string()),
        _ => InputError::new_err(e.to_string()),
    }
}

fn status_name(s: ModelStatus) -> &'static str {
    match s {
        ModelStatus::Inside => "inside",
        ModelStatus::Clamped => "clamped",
        ModelStatus::Extrapolated => "extrapolated",
    }
}

fn vec2(a: &Arr1<'_>, what: &str) -> PyResult<Vector2<f64>> {
    Ok(Vector2::from_column_slice(&finite_vec(a, what, 2)?))
}

/// D'Alembert trajectory correction (Paksoy et al., Fig. 2): per tick `F_D = -mass * a`
/// (Eq. 5), displacement from the compliance map (Eq. 9-14), command = desired - displacement
/// (iterated `iterations` times to a fixed point if > 0), closed-form IK. SI units.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct DalembertCorrector {
    map: CoreMap,
    robot: CoreRobot2,
    corrector: CoreCorrector,
}

/// Result of `DalembertCorrector.correct`: one row per tick.
#[pyclass(module = "deflect", frozen, get_all)]
#[derive(Debug)]
pub struct CorrectedPath {
    /// Tick times [s], (N,).
    t: Py<PyArray1<f64>>,
    /// Desired (planned) points [m], (N, 2).
    desired: Py<PyArray2<f64>>,
    /// Commanded points [m], (N, 2).
    position: Py<PyArray2<f64>>,
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
impl DalembertCorrector {
    /// `compliance_map` (2 forces x 2 displacements, its out-of-grid policy applies),
    /// `mechanism` (a `ParallelRobot2`), `mass` m* [kg] (the paper tuned 5 kg).
    #[new]
    #[pyo3(signature = (compliance_map, mechanism, mass=CoreCorrector::PAPER_MASS, iterations=0, tolerance=0.0))]
    fn new(
        compliance_map: &ComplianceMap,
        mechanism: &ParallelRobot2,
        mass: f64,
        iterations: usize,
        tolerance: f64,
    ) -> PyResult<Self> {
        let map = compliance_map.inner.clone();
        if map.n_force() != 2 || map.n_displacement() != 2 {
            return Err(InputError::new_err(format!(
                "compliance_map: needs 2 force and 2 displacement axes, has {} and {}",
                map.n_force(),
                map.n_displacement()
            )));
        }
        let corrector = CoreCorrector::new(mass)
            .map_err(corr_err)?
            .with_fixed_point(iterations, tolerance);
        Ok(Self {
            map,
            robot: mechanism.inner,
            corrector,
        })
    }

    /// Mass parameter m* [kg].
    #[getter]
    fn mass(&self) -> f64 {
        self.corrector.mass()
    }

    /// One tick: `position` (2,) [m], planned `acceleration` (2,) [m/s^2] -> dict with
    /// `commanded`, `joints`, `force`, `displacement`, `iterations`, `model_status`.
    fn step<'py>(
        &self,
        py: Python<'py>,
        position: Arr1<'py>,
        acceleration: Arr1<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let x = vec2(&position, "position")?;
        let a = vec2(&acceleration, "acceleration")?;
        let t: CorrectedTick<2, 2> = self
            .corrector
            .step(&self.robot, &self.map.view(), &x, &a, &Vector2::zeros())
            .map_err(corr_err)?;
        let d = PyDict::new(py);
        d.set_item("commanded", t.commanded.as_slice().to_pyarray(py))?;
        d.set_item("joints", t.joints.as_slice().to_pyarray(py))?;
        d.set_item("force", t.force.as_slice().to_pyarray(py))?;
        d.set_item("displacement", t.displacement.as_slice().to_pyarray(py))?;
        d.set_item("iterations", t.iterations)?;
        d.set_item("model_status", status_name(t.model_status))?;
        Ok(d)
    }

    /// Corrects every tick of a planned 2-D `trajectory` (from `plan_line`/`plan_polyline`),
    /// without the GIL. The same arithmetic as `step`, tick by tick.
    fn correct(&self, py: Python<'_>, trajectory: &Trajectory) -> PyResult<CorrectedPath> {
        let (pos, acc) = (&trajectory.position, &trajectory.acceleration);
        if pos.ncols() != 2 {
            return Err(InputError::new_err(format!(
                "trajectory: the corrector needs a 2-D trajectory, got {} columns",
                pos.ncols()
            )));
        }
        let n = pos.nrows();
        let view = self.map.view();
        let result = py.detach(|| -> Result<_, String> {
            let mut out: [Array2<f64>; 5] = core::array::from_fn(|_| Array2::zeros((n, 2)));
            let mut flagged = Vec::new();
            let mut q = Vector2::zeros();
            for i in 0..n {
                let x = Vector2::new(pos[(i, 0)], pos[(i, 1)]);
                let a = Vector2::new(acc[(i, 0)], acc[(i, 1)]);
                let t = self
                    .corrector
                    .step(&self.robot, &view, &x, &a, &q)
                    .map_err(|e| format!("tick {i}: {e}"))?;
                q = t.joints;
                for (arr, v) in
                    out.iter_mut()
                        .zip([t.desired, t.commanded, t.joints, t.force, t.displacement])
                {
                    arr[(i, 0)] = v.x;
                    arr[(i, 1)] = v.y;
                }
                if t.model_status != ModelStatus::Inside {
                    flagged.push(i);
                }
            }
            Ok((out, flagged))
        });
        let (out, flagged) = result.map_err(InputError::new_err)?;
        let [desired, position, joints, force, displacement] = out;
        let t: Array1<f64> = trajectory.t.clone();
        Ok(CorrectedPath {
            t: t.to_pyarray(py).unbind(),
            desired: desired.to_pyarray(py).unbind(),
            position: position.to_pyarray(py).unbind(),
            joints: joints.to_pyarray(py).unbind(),
            force: force.to_pyarray(py).unbind(),
            displacement: displacement.to_pyarray(py).unbind(),
            flagged_ticks: flagged,
        })
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<DalembertCorrector>()?;
    m.add_class::<CorrectedPath>()?;
    Ok(())
}
