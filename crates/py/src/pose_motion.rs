//! `deflect.plan_pose` and `deflect.PoseTrajectory`: a 6-D rest-to-rest pose motion (a
//! straight TCP line and a jerk-limited turn about one fixed axis, synchronised), planned by
//! deflect-core, evaluated at any time or sampled at a fixed rate.

use std::sync::OnceLock;

use deflect_core::motion::{
    DEFAULT_RATE_HZ, Limits, MAX_SAMPLES, PoseLimits, PoseState, PoseTrajectory as Core,
};
use numpy::ndarray::{Array1, Array2, Array3, Ix1, Ix2, Ix3};
use numpy::{PyArray1, PyArray2, PyArray3, PyUntypedArrayMethods, ToPyArray};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::InputError;
use crate::args;
use crate::arrays::{
    fixed_matrix, float_array, iso_to_py, matrix_to_py, pose_of, put_pose, try_array, try_vec,
    vector_upto,
};
use crate::errors::{build_err, shape_error, tick_err};
use crate::scalars::real;
use nalgebra::Matrix4;

/// Every tick of a pose motion, one row each.
#[derive(Debug, Clone)]
struct PoseSamples {
    t: Array1<f64>,
    pose: Array3<f64>,
    velocity: Array2<f64>,
    acceleration: Array2<f64>,
    angular_velocity: Array2<f64>,
    angular_acceleration: Array2<f64>,
}

impl PoseSamples {
    /// The rows of `states`, in arrays allocated fallibly (`MemoryError`, never an abort).
    fn try_of(states: &[PoseState]) -> PyResult<Self> {
        let n = states.len();
        let what = "the pose samples";
        let mut out = Self {
            t: try_array(Ix1(n), what)?,
            pose: try_array(Ix3(n, 4, 4), what)?,
            velocity: try_array(Ix2(n, 3), what)?,
            acceleration: try_array(Ix2(n, 3), what)?,
            angular_velocity: try_array(Ix2(n, 3), what)?,
            angular_acceleration: try_array(Ix2(n, 3), what)?,
        };
        for (i, s) in states.iter().enumerate() {
            if let Some(t) = out.t.get_mut(i) {
                *t = s.t;
            }
            put_pose(&mut out.pose, i, &s.pose);
            for (arr, v) in [
                (&mut out.velocity, &s.velocity),
                (&mut out.acceleration, &s.acceleration),
                (&mut out.angular_velocity, &s.angular_velocity),
                (&mut out.angular_acceleration, &s.angular_acceleration),
            ] {
                arr.row_mut(i)
                    .iter_mut()
                    .zip(v.iter())
                    .for_each(|(d, x)| *d = *x);
            }
        }
        Ok(out)
    }
}

/// The states of every tick of `traj` at `rate_hz` (at most `MAX_SAMPLES`), in a vector
/// allocated fallibly: `MemoryError` rather than an abort, a tick's error as its exception.
pub(crate) fn pose_ticks(traj: &Core, rate_hz: f64) -> PyResult<Vec<PoseState>> {
    let n = traj.sample_count(rate_hz).map_err(tick_err)?;
    let mut states = try_vec(n, "the pose samples")?;
    for k in 0..n {
        states.push(
            traj.sample(traj.tick_time(rate_hz, k, n))
                .map_err(tick_err)?,
        );
    }
    Ok(states)
}

/// A 6-D rest-to-rest pose motion (from `plan_pose`), base frame, SI units: the TCP moves on
/// the straight line between the two positions and turns about one fixed axis (the geodesic
/// between the orientations) on one jerk-limited profile, so both start and stop together
/// and neither exceeds its limits. `at(t)` evaluates the plan at any time; the arrays (`t`,
/// `pose`, ...) hold its ticks at `rate_hz`, computed on first access (`rate_hz=None`: plan
/// only).
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct PoseTrajectory {
    pub(crate) plan: Core,
    pub(crate) rate_hz: Option<f64>,
    /// `plan_pose`'s arguments, for pickling.
    recipe: PoseRecipe,
    samples: OnceLock<PoseSamples>,
}

/// The arguments of `plan_pose` a pose trajectory was planned from: the 4 x 4 matrices as
/// given (converting them to the planner's quaternions and back would not be exact).
#[derive(Debug, Clone, Copy)]
struct PoseRecipe {
    start: Matrix4<f64>,
    end: Matrix4<f64>,
    linear: [f64; 3],
    angular: [f64; 3],
}

impl PoseTrajectory {
    fn new(plan: Core, recipe: PoseRecipe, rate_hz: Option<f64>) -> PyResult<Self> {
        if let Some(r) = rate_hz {
            plan.sample_count(r).map_err(tick_err)?;
        }
        Ok(Self {
            plan,
            rate_hz,
            recipe,
            samples: OnceLock::new(),
        })
    }

    fn samples(&self, py: Python<'_>) -> PyResult<&PoseSamples> {
        if let Some(s) = self.samples.get() {
            return Ok(s);
        }
        let Some(rate) = self.rate_hz else {
            return Err(InputError::new_err(
                "this PoseTrajectory is plan-only (planned with rate_hz=None): evaluate it with \
                 .at(t) or sample it with .sampled(rate_hz)",
            ));
        };
        let s = py.detach(|| {
            let states = pose_ticks(&self.plan, rate)?;
            PoseSamples::try_of(&states)
        })?;
        Ok(self.samples.get_or_init(|| s))
    }
}

#[pymethods]
impl PoseTrajectory {
    /// The exact state at time `t` [s] (a number, or an array of m times): a dict with `t`,
    /// `pose` (4, 4), `velocity` (3,) [m/s], `acceleration` (3,) [m/s^2],
    /// `angular_velocity` (3,) [rad/s] and `angular_acceleration` (3,) [rad/s^2], base
    /// frame; with a leading axis of m for an array (at most `MAX_SAMPLES` times). Before 0
    /// the start pose at rest, from `duration` on the end pose at rest (held, not an error).
    fn at<'py>(&self, py: Python<'py>, t: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
        let a = float_array(t, "t")?;
        let (times, scalar) = match a.ndim() {
            0 => (vec![real(t, "t")?], true),
            1 => (vector_upto(t, "t", MAX_SAMPLES, "MAX_SAMPLES")?, false),
            _ => return Err(shape_error("t", "a number or (m,)", a.shape())),
        };
        let mut states = try_vec(times.len(), "the states")?;
        for &t in &times {
            states.push(self.plan.sample(t).map_err(tick_err)?);
        }
        let d = PyDict::new(py);
        match (scalar, states.first()) {
            (true, Some(s)) => {
                d.set_item("t", s.t)?;
                d.set_item("pose", iso_to_py(py, &s.pose))?;
                d.set_item("velocity", s.velocity.as_slice().to_pyarray(py))?;
                d.set_item("acceleration", s.acceleration.as_slice().to_pyarray(py))?;
                d.set_item(
                    "angular_velocity",
                    s.angular_velocity.as_slice().to_pyarray(py),
                )?;
                d.set_item(
                    "angular_acceleration",
                    s.angular_acceleration.as_slice().to_pyarray(py),
                )?;
            }
            _ => {
                let s = PoseSamples::try_of(&states)?;
                d.set_item("t", s.t.to_pyarray(py))?;
                d.set_item("pose", s.pose.to_pyarray(py))?;
                d.set_item("velocity", s.velocity.to_pyarray(py))?;
                d.set_item("acceleration", s.acceleration.to_pyarray(py))?;
                d.set_item("angular_velocity", s.angular_velocity.to_pyarray(py))?;
                d.set_item(
                    "angular_acceleration",
                    s.angular_acceleration.to_pyarray(py),
                )?;
            }
        }
        Ok(d)
    }

    /// The same plan with its ticks at `rate_hz` [Hz] (at most 2^22 ticks).
    fn sampled(&self, #[pyo3(from_py_with = args::real::rate_hz)] rate_hz: f64) -> PyResult<Self> {
        Self::new(self.plan, self.recipe, Some(rate_hz))
    }

    /// Pickling and `copy.deepcopy`: `plan_pose` with the same arguments, planned again bit
    /// for bit.
    #[allow(clippy::type_complexity)] // reason: the pickle protocol's (callable, args) pair
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (
            Bound<'py, PyArray2<f64>>,
            Bound<'py, PyArray2<f64>>,
            [f64; 3],
            [f64; 3],
            Option<f64>,
        ),
    )> {
        let (py, me) = (slf.py(), slf.get());
        let r = &me.recipe;
        let f = py.import("deflect._deflect")?.getattr("plan_pose")?;
        Ok((
            f,
            (
                matrix_to_py(py, &r.start),
                matrix_to_py(py, &r.end),
                r.linear,
                r.angular,
                me.rate_hz,
            ),
        ))
    }

    /// Tick times [s], (n,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(self.samples(py)?.t.to_pyarray(py))
    }
    /// TCP poses, (n, 4, 4).
    #[getter]
    fn pose<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        Ok(self.samples(py)?.pose.to_pyarray(py))
    }
    /// TCP velocities [m/s], (n, 3).
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(self.samples(py)?.velocity.to_pyarray(py))
    }
    /// TCP accelerations [m/s^2], (n, 3).
    #[getter]
    fn acceleration<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(self.samples(py)?.acceleration.to_pyarray(py))
    }
    /// Angular velocities [rad/s], (n, 3).
    #[getter]
    fn angular_velocity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(self.samples(py)?.angular_velocity.to_pyarray(py))
    }
    /// Angular accelerations [rad/s^2], (n, 3).
    #[getter]
    fn angular_acceleration<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(self.samples(py)?.angular_acceleration.to_pyarray(py))
    }
    /// Start pose, (4, 4).
    #[getter]
    fn start<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        iso_to_py(py, &self.plan.start())
    }
    /// End pose, (4, 4).
    #[getter]
    fn end<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        iso_to_py(py, &self.plan.end())
    }
    /// Unit axis of the turn (base frame), (3,).
    #[getter]
    fn axis<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.plan.rotation().0.as_slice().to_pyarray(py)
    }
    /// Angle of the turn [rad], in [0, pi].
    #[getter]
    fn angle(&self) -> f64 {
        self.plan.rotation().1
    }
    /// Duration [s].
    #[getter]
    fn duration(&self) -> f64 {
        self.plan.duration()
    }
    /// Sampling rate [Hz]; None for a plan-only trajectory.
    #[getter]
    fn rate_hz(&self) -> Option<f64> {
        self.rate_hz
    }
    /// Number of ticks; `InputError` for a plan-only trajectory.
    fn __len__(&self) -> PyResult<usize> {
        match self.rate_hz {
            Some(r) => self.plan.sample_count(r).map_err(tick_err),
            None => Err(InputError::new_err(
                "a plan-only PoseTrajectory (rate_hz=None) has no ticks: use .sampled(rate_hz)",
            )),
        }
    }
    fn __repr__(&self) -> String {
        let (_, angle) = self.plan.rotation();
        let distance =
            (self.plan.end().translation.vector - self.plan.start().translation.vector).norm();
        let ticks = match self.rate_hz {
            Some(r) => format!(
                "ticks={}, rate_hz={r}",
                self.plan.sample_count(r).unwrap_or_default()
            ),
            None => "plan only".to_string(),
        };
        format!(
            "PoseTrajectory(duration={:.6} s, distance={distance:.6} m, angle={angle:.6} rad, \
             {ticks})",
            self.plan.duration()
        )
    }
}

fn limits(what: &str, [v, a, j]: [f64; 3]) -> PyResult<Limits> {
    Limits::new(v, a, j).map_err(|e| InputError::new_err(format!("{what}: {e}")))
}

/// Time-optimal jerk-limited rest-to-rest pose motion from `start` to `end` (4 x 4 rigid
/// transforms, base frame): the TCP on the straight line between the positions under
/// `linear = (v_max [m/s], a_max [m/s^2], j_max [m/s^3])`, the orientation turned about one
/// fixed axis by the angle between them under `angular = (w_max [rad/s], alpha_max
/// [rad/s^2], jerk_max [rad/s^3])`, on one profile (the tighter part sets the pace). Ticks at
/// `rate_hz` [Hz] (at most 2^22); `rate_hz=None` plans only.
#[pyfunction]
#[pyo3(signature = (start, end, linear, angular, rate_hz=Some(DEFAULT_RATE_HZ)),
       text_signature = "(start, end, linear, angular, rate_hz=2000.0)")]
fn plan_pose(
    start: &Bound<'_, PyAny>,
    end: &Bound<'_, PyAny>,
    #[pyo3(from_py_with = args::triple::linear)] linear: [f64; 3],
    #[pyo3(from_py_with = args::triple::angular)] angular: [f64; 3],
    #[pyo3(from_py_with = args::opt_real::rate_hz)] rate_hz: Option<f64>,
) -> PyResult<PoseTrajectory> {
    let (sm, em) = (
        fixed_matrix::<4, 4>(start, "start")?,
        fixed_matrix::<4, 4>(end, "end")?,
    );
    let (s, e) = (pose_of(&sm, "start")?, pose_of(&em, "end")?);
    let limits = PoseLimits {
        linear: limits("linear", linear)?,
        angular: limits("angular", angular)?,
    };
    let recipe = PoseRecipe {
        start: sm,
        end: em,
        linear,
        angular,
    };
    PoseTrajectory::new(
        Core::line(&s, &e, &limits).map_err(build_err)?,
        recipe,
        rate_hz,
    )
}

/// Adds the pose planner to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PoseTrajectory>()?;
    m.add_function(wrap_pyfunction!(plan_pose, m)?)?;
    Ok(())
}
