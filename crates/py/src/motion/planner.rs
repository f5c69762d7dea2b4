//! `deflect.LinePlanner`: one line plan re-planned in place move after move (ruckig's
//! `Ruckig.calculate(input, trajectory)` habit), for callers that plan many moves: no
//! trajectory object per move, the limits validated once, the points read without numpy.

use deflect_core::motion::{Limits, Trajectory as CoreTraj};
use nalgebra::SVector;
use numpy::ndarray::Array2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::plan::{LimitSpec, Plan, with_plan};
use super::{MAX_DIM, Recipe, Trajectory, plan_at};
use crate::InputError;
use crate::args;
use crate::arrays::{fill_fast, vector};
use crate::errors::build_err;

/// A jerk-limited straight-line planner in `dim` coordinates (1 to 8) under path limits
/// `v_max` [m/s], `a_max` [m/s^2], `j_max` [m/s^3] (Euclidean norms; finite and > 0),
/// validated once here. `plan(start, end)` re-plans the planner's one trajectory in place,
/// bit for bit `plan_line(start, end, v_max, a_max, j_max, rate_hz=None)`, and returns the
/// duration [s]; `at(t)` evaluates it and `trajectory()` copies it out as a `Trajectory`.
/// Until the first `plan` it rests at the origin. Per-coordinate limits: `plan_line`.
#[pyclass(module = "deflect")]
#[derive(Debug)]
pub struct LinePlanner {
    plan: Plan,
    limits: Limits,
}

/// `o` as a point of `N` coordinates: lists, tuples and float64 vectors read directly, the
/// rest through numpy's conversion and its checks.
fn point<const N: usize>(o: &Bound<'_, PyAny>, what: &str) -> PyResult<SVector<f64, N>> {
    let mut p = SVector::<f64, N>::zeros();
    if !fill_fast(o, p.as_mut_slice()) {
        p.copy_from_slice(&vector(o, what, N)?);
    }
    Ok(p)
}

fn replan<const N: usize>(
    traj: &mut CoreTraj<N>,
    start: &Bound<'_, PyAny>,
    end: &Bound<'_, PyAny>,
    limits: &Limits,
) -> PyResult<f64> {
    let (s, e) = (point::<N>(start, "start")?, point::<N>(end, "end")?);
    traj.replan_line(s, e, limits).map_err(build_err)?;
    Ok(traj.duration())
}

fn at_rest<const N: usize>(limits: &Limits) -> PyResult<Box<CoreTraj<N>>> {
    let o = SVector::<f64, N>::zeros();
    CoreTraj::line(o, o, limits)
        .map(Box::new)
        .map_err(build_err)
}

impl LinePlanner {
    /// Start and end points of the current plan.
    fn points(&self) -> (Vec<f64>, Vec<f64>) {
        with_plan!(&self.plan, t => (t.start().as_slice().to_vec(), t.end().as_slice().to_vec()))
    }
}

#[pymethods]
impl LinePlanner {
    #[new]
    #[pyo3(signature = (dim, v_max, a_max, j_max))]
    fn new(
        #[pyo3(from_py_with = args::count::dim)] dim: usize,
        #[pyo3(from_py_with = args::real::v_max)] v_max: f64,
        #[pyo3(from_py_with = args::real::a_max)] a_max: f64,
        #[pyo3(from_py_with = args::real::j_max)] j_max: f64,
    ) -> PyResult<Self> {
        let limits = Limits::new(v_max, a_max, j_max).map_err(build_err)?;
        let plan = match dim {
            1 => Plan::D1(at_rest(&limits)?),
            2 => Plan::D2(at_rest(&limits)?),
            3 => Plan::D3(at_rest(&limits)?),
            4 => Plan::D4(at_rest(&limits)?),
            5 => Plan::D5(at_rest(&limits)?),
            6 => Plan::D6(at_rest(&limits)?),
            7 => Plan::D7(at_rest(&limits)?),
            8 => Plan::D8(at_rest(&limits)?),
            _ => {
                return Err(InputError::new_err(format!(
                    "dim = {dim}: expected 1 <= dim <= {MAX_DIM}"
                )));
            }
        };
        Ok(Self { plan, limits })
    }

    /// Re-plans the time-optimal rest-to-rest line from `start` to `end` (`dim` numbers
    /// each) in place and returns its duration [s]. On error the previous plan is kept.
    fn plan(&mut self, start: &Bound<'_, PyAny>, end: &Bound<'_, PyAny>) -> PyResult<f64> {
        let l = self.limits;
        with_plan!(&mut self.plan, t => replan(t, start, end, &l))
    }

    /// The exact state of the current plan at `t` [s], as `Trajectory.at`.
    fn at<'py>(&self, py: Python<'py>, t: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
        plan_at(py, &self.plan, t)
    }

    /// A copy of the current plan as a `Trajectory`, its ticks at `rate_hz` [Hz]
    /// (`None`: plan only), as `plan_line` returns it.
    #[pyo3(signature = (rate_hz=Some(deflect_core::motion::DEFAULT_RATE_HZ)),
           text_signature = "($self, rate_hz=2000.0)")]
    fn trajectory(
        &self,
        #[pyo3(from_py_with = args::opt_real::rate_hz)] rate_hz: Option<f64>,
    ) -> PyResult<Trajectory> {
        let (s, e) = self.points();
        let d = s.len();
        let points = Array2::from_shape_vec((2, d), [s, e].concat())
            .map_err(|e| InputError::new_err(e.to_string()))?;
        let recipe = Recipe::Planned {
            points,
            spec: LimitSpec::Path(self.limits),
        };
        Trajectory::planned(self.plan.clone(), recipe, rate_hz)
    }

    /// Duration of the current plan [s].
    #[getter]
    fn duration(&self) -> f64 {
        self.plan.duration()
    }
    /// Number of coordinates.
    #[getter]
    fn dim(&self) -> usize {
        self.plan.dim()
    }
    /// Path limits `(v_max, a_max, j_max)`.
    #[getter]
    fn limits(&self) -> (f64, f64, f64) {
        (self.limits.v_max, self.limits.a_max, self.limits.j_max)
    }
    /// Start point of the current plan.
    #[getter]
    fn start(&self) -> Vec<f64> {
        self.points().0
    }
    /// End point of the current plan.
    #[getter]
    fn end(&self) -> Vec<f64> {
        self.points().1
    }

    /// Pickling: the limits, then the current line planned again (bit for bit).
    fn __getnewargs__(&self) -> (usize, f64, f64, f64) {
        let l = self.limits;
        (self.plan.dim(), l.v_max, l.a_max, l.j_max)
    }
    fn __getstate__(&self) -> (Vec<f64>, Vec<f64>) {
        self.points()
    }
    fn __setstate__(&mut self, py: Python<'_>, state: (Vec<f64>, Vec<f64>)) -> PyResult<()> {
        let (s, e) = (
            state.0.into_pyobject(py)?.into_any(),
            state.1.into_pyobject(py)?.into_any(),
        );
        self.plan(&s, &e).map(|_| ())
    }
    fn __repr__(&self) -> String {
        let l = self.limits;
        format!(
            "LinePlanner(dim={}, v_max={}, a_max={}, j_max={}, duration={:.6} s)",
            self.plan.dim(),
            l.v_max,
            l.a_max,
            l.j_max,
            self.plan.duration()
        )
    }
}
