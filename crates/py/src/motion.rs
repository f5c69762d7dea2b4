//! `deflect.plan_line`, `deflect.plan_polyline` (jerk-limited rest-to-rest motions sampled
//! at a fixed rate) and `deflect.ParallelRobot2` (the paper's 2-DoF parallel robot).

use deflect_core::mechanism::{Mechanism, MechanismError, ParallelRobot2 as CoreRobot2};
use deflect_core::motion::{DEFAULT_RATE_HZ, Limits, MotionError, Trajectory as CoreTraj};
use nalgebra::{SVector, Vector2};
use numpy::ndarray::{Array1, Array2};
use numpy::{AllowTypeChange, PyArray1, PyArray2, PyArrayLike1, PyArrayLike2, ToPyArray};
use pyo3::prelude::*;

use crate::{ConvergenceError, InputError, SingularError};

fn motion_err(e: MotionError) -> PyErr {
    InputError::new_err(e.to_string())
}

pub(crate) fn mech_err(e: MechanismError) -> PyErr {
    match e {
        MechanismError::Singular { .. } => SingularError::new_err(e.to_string()),
        MechanismError::NotConverged { .. } => ConvergenceError::new_err(e.to_string()),
        _ => InputError::new_err(e.to_string()),
    }
}

/// A planned motion sampled at a fixed rate: one row per tick, the last tick exactly at the
/// end point. SI units.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct Trajectory {
    pub(crate) t: Array1<f64>,
    pub(crate) position: Array2<f64>,
    velocity: Array2<f64>,
    pub(crate) acceleration: Array2<f64>,
    jerk: Array2<f64>,
    duration: f64,
    rate_hz: f64,
}

#[pymethods]
impl Trajectory {
    /// Tick times [s], shape (n,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.t.to_pyarray(py)
    }
    /// Positions [m], shape (n, d).
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.position.to_pyarray(py)
    }
    /// Velocities [m/s], shape (n, d).
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.velocity.to_pyarray(py)
    }
    /// Accelerations [m/s^2], shape (n, d).
    #[getter]
    fn acceleration<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.acceleration.to_pyarray(py)
    }
    /// Jerks [m/s^3], shape (n, d).
    #[getter]
    fn jerk<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.jerk.to_pyarray(py)
    }
    /// Total duration [s].
    #[getter]
    fn duration(&self) -> f64 {
        self.duration
    }
    /// Sampling rate [Hz].
    #[getter]
    fn rate_hz(&self) -> f64 {
        self.rate_hz
    }
    fn __len__(&self) -> usize {
        self.t.len()
    }
    fn __repr__(&self) -> String {
        format!(
            "Trajectory(duration={:.6} s, ticks={}, dim={}, rate_hz={})",
            self.duration,
            self.t.len(),
            self.position.ncols(),
            self.rate_hz
        )
    }
}

fn sample_all<const N: usize>(traj: &CoreTraj<N>, rate_hz: f64) -> PyResult<Trajectory> {
    let states: Vec<_> = traj.ticks(rate_hz).map_err(motion_err)?.collect();
    let n = states.len();
    let rows = |f: &dyn Fn(usize) -> SVector<f64, N>| {
        Array2::from_shape_fn((n, N), |(i, j)| f(i).get(j).copied().unwrap_or(f64::NAN))
    };
    let at = |i: usize| states.get(i);
    Ok(Trajectory {
        t: states.iter().map(|s| s.t).collect(),
        position: rows(&|i| at(i).map_or(SVector::zeros(), |s| s.position)),
        velocity: rows(&|i| at(i).map_or(SVector::zeros(), |s| s.velocity)),
        acceleration: rows(&|i| at(i).map_or(SVector::zeros(), |s| s.acceleration)),
        jerk: rows(&|i| at(i).map_or(SVector::zeros(), |s| s.jerk)),
        duration: traj.duration(),
        rate_hz,
    })
}

fn points_of<const N: usize>(rows: &numpy::ndarray::ArrayView2<'_, f64>) -> Vec<SVector<f64, N>> {
    rows.rows()
        .into_iter()
        .map(|r| SVector::<f64, N>::from_iterator(r.iter().copied()))
        .collect()
}

fn plan(
    points: numpy::ndarray::ArrayView2<'_, f64>,
    limits: &Limits,
    rate_hz: f64,
) -> PyResult<Trajectory> {
    match points.ncols() {
        2 => sample_all(
            &CoreTraj::polyline(&points_of::<2>(&points), limits).map_err(motion_err)?,
            rate_hz,
        ),
        3 => sample_all(
            &CoreTraj::polyline(&points_of::<3>(&points), limits).map_err(motion_err)?,
            rate_hz,
        ),
        d => Err(InputError::new_err(format!(
            "points must be 2-D or 3-D, got dimension {d}"
        ))),
    }
}

/// Time-optimal jerk-limited rest-to-rest straight move from `start` to `end` (2 or 3
/// coordinates [m]) under `v_max` [m/s], `a_max` [m/s^2], `j_max` [m/s^3], sampled at
/// `rate_hz`.
#[pyfunction]
#[pyo3(signature = (start, end, v_max, a_max, j_max, rate_hz=DEFAULT_RATE_HZ))]
fn plan_line(
    start: PyArrayLike1<'_, f64, AllowTypeChange>,
    end: PyArrayLike1<'_, f64, AllowTypeChange>,
    v_max: f64,
    a_max: f64,
    j_max: f64,
    rate_hz: f64,
) -> PyResult<Trajectory> {
    let (s, e) = (start.as_array(), end.as_array());
    if s.len() != e.len() {
        return Err(InputError::new_err(format!(
            "start has {} coordinates, end {}",
            s.len(),
            e.len()
        )));
    }
    let d = s.len();
    let pts = Array2::from_shape_fn((2, d), |(i, j)| {
        let row = if i == 0 { &s } else { &e };
        row.get(j).copied().unwrap_or(f64::NAN)
    });
    let limits = Limits::new(v_max, a_max, j_max).map_err(motion_err)?;
    plan(pts.view(), &limits, rate_hz)
}

/// Rest-to-rest moves through `points` (shape (n, 2) or (n, 3), 2 <= n <= 32 [m]), stopping
/// at every point; repeated points are skipped.
#[pyfunction]
#[pyo3(signature = (points, v_max, a_max, j_max, rate_hz=DEFAULT_RATE_HZ))]
fn plan_polyline(
    points: PyArrayLike2<'_, f64, AllowTypeChange>,
    v_max: f64,
    a_max: f64,
    j_max: f64,
    rate_hz: f64,
) -> PyResult<Trajectory> {
    let limits = Limits::new(v_max, a_max, j_max).map_err(motion_err)?;
    plan(points.as_array(), &limits, rate_hz)
}

/// Limits `(v_max, a_max, j_max)` that reproduce the paper's motions at `g_level` g (1..5).
#[pyfunction]
fn paper_limits(g_level: u8) -> PyResult<(f64, f64, f64)> {
    let l = deflect_core::motion::paper_limits(g_level).map_err(motion_err)?;
    Ok((l.v_max, l.a_max, l.j_max))
}

fn vec2(a: &PyArrayLike1<'_, f64, AllowTypeChange>, what: &str) -> PyResult<Vector2<f64>> {
    let v = a.as_array();
    match (v.len(), v.get(0), v.get(1)) {
        (2, Some(&x), Some(&y)) => Ok(Vector2::new(x, y)),
        _ => Err(InputError::new_err(format!(
            "{what}: expected shape (2,), got ({},)",
            v.len()
        ))),
    }
}

/// The paper's 2-DoF planar parallel robot (links 150 mm, pivots 90 mm from O). Task point
/// `p = (x, y)` = C - O [m] in the static-test grid's frame; joints `q = (theta_A, theta_B)`
/// [rad], the actuated links' angles from +x; working mode "elbows out".
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct ParallelRobot2 {
    pub(crate) inner: CoreRobot2,
}

#[pymethods]
impl ParallelRobot2 {
    /// Paper geometry by default; `min_sigma` [m/rad] is the singularity threshold.
    #[new]
    #[pyo3(signature = (link=0.150, half_width=0.090, min_sigma=deflect_core::mechanism::DEFAULT_MIN_SIGMA))]
    fn new(link: f64, half_width: f64, min_sigma: f64) -> PyResult<Self> {
        Ok(Self {
            inner: CoreRobot2::new(link, half_width, min_sigma).map_err(mech_err)?,
        })
    }
    /// Joints `q` [rad] that put C on `p` [m]; InputError out of reach, SingularError near a
    /// singularity.
    fn ik<'py>(
        &self,
        py: Python<'py>,
        p: PyArrayLike1<'py, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.inner.ik(&vec2(&p, "p")?).map_err(mech_err)?;
        Ok(q.as_slice().to_pyarray(py))
    }
    /// Task point `p` [m] of joints `q` [rad].
    fn fk<'py>(
        &self,
        py: Python<'py>,
        q: PyArrayLike1<'py, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let p = self.inner.fk(&vec2(&q, "q")?).map_err(mech_err)?;
        Ok(p.as_slice().to_pyarray(py))
    }
    /// Jacobian `dp/dq` [m/rad], shape (2, 2).
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: PyArrayLike1<'py, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let j = self.inner.jacobian_at(&vec2(&q, "q")?).map_err(mech_err)?;
        Ok(
            Array2::from_shape_fn((2, 2), |(r, c)| j.get((r, c)).copied().unwrap_or(f64::NAN))
                .to_pyarray(py),
        )
    }
    /// Smallest singular value of the Jacobian at `q` [m/rad].
    fn singularity_distance(&self, q: PyArrayLike1<'_, f64, AllowTypeChange>) -> PyResult<f64> {
        self.inner
            .singularity_distance(&vec2(&q, "q")?)
            .map_err(mech_err)
    }
    /// Largest reach 2 L [m].
    #[getter]
    fn reach(&self) -> f64 {
        self.inner.reach()
    }
    fn __repr__(&self) -> String {
        format!(
            "ParallelRobot2(link={}, half_width={}, min_sigma={})",
            self.inner.link(),
            self.inner.half_width(),
            self.inner.min_sigma()
        )
    }
}

/// Adds the motion planner and the parallel robot to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Trajectory>()?;
    m.add_class::<ParallelRobot2>()?;
    m.add_function(wrap_pyfunction!(plan_line, m)?)?;
    m.add_function(wrap_pyfunction!(plan_polyline, m)?)?;
    m.add_function(wrap_pyfunction!(paper_limits, m)?)?;
    Ok(())
}
