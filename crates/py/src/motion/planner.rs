//! `deflect.LinePlanner`: one line plan re-planned in place move after move (ruckig's
//! `Ruckig.calculate(input, trajectory)` habit), for callers that plan many moves: no
//! trajectory object per move, the limits validated once, the points read without numpy.
//! The planner holds its input points as ruckig's `InputParameter` does: set them (or pass
//! them to `plan`), and `plan()` plans from them.

use deflect_core::motion::{Limits, PreparedLimits, Trajectory as CoreTraj};
use nalgebra::SVector;
use numpy::ndarray::Array2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::plan::{LimitSpec, MAX_DIM, Plan, with_plan};
use super::trajectory::{Recipe, Trajectory, plan_at};
use crate::InputError;
use crate::args;
use crate::arrays::{fill_fast, vector};
use crate::errors::build_err;

/// A jerk-limited straight-line planner in `dim` coordinates (1 to 8) under path limits
/// `v_max` [m/s], `a_max` [m/s^2], `j_max` [m/s^3] (Euclidean norms; finite and > 0),
/// validated once here. `plan(start, end)` re-plans the planner's one trajectory in place,
/// bit for bit `plan_line(start, end, v_max, a_max, j_max, rate_hz=None)`, and returns the
/// duration [s]; or set `start` / `end` (ruckig's `InputParameter`) and call `plan()`.
/// `at(t)` evaluates the plan and `trajectory()` copies it out as a `Trajectory`. Until the
/// first `plan` it rests at the origin. Per-coordinate limits: `plan_line`.
///
/// A planner is mutable state, as a numpy `Generator` is: give each thread its own (or hold
/// a lock around each call); a call while another thread's call on the same planner runs
/// raises `RuntimeError("Already borrowed")` and leaves the plan as the other call leaves it.
#[pyclass(module = "deflect")]
#[derive(Debug)]
pub struct LinePlanner {
    plan: Plan,
    /// The limits validated once, with the length-independent part of the profile solved.
    limits: PreparedLimits,
    /// The points `plan()` plans from (the first `dim` entries): ruckig's `InputParameter`.
    /// Set by the `start` / `end` setters and by every `plan(start, end)`.
    input: [[f64; MAX_DIM]; 2],
}

/// The first `N` entries of an input point.
fn input_point<const N: usize>(p: &[f64; MAX_DIM]) -> SVector<f64, N> {
    SVector::from_fn(|i, _| p.get(i).copied().unwrap_or(0.0))
}

/// `o` (`dim` numbers) into an input point: the checks of `plan`'s points (the values
/// themselves are validated by the plan).
fn read_input(
    o: &Bound<'_, PyAny>,
    what: &str,
    dim: usize,
    into: &mut [f64; MAX_DIM],
) -> PyResult<()> {
    let mut p = [0.0; MAX_DIM];
    let slot = p.get_mut(..dim).unwrap_or_default();
    if !fill_fast(o, slot) {
        slot.copy_from_slice(&vector(o, what, dim)?);
    }
    *into = p;
    Ok(())
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

/// Plans from `start` to `end` and, once planned, makes them the input.
fn replan<const N: usize>(
    traj: &mut CoreTraj<N>,
    start: &Bound<'_, PyAny>,
    end: &Bound<'_, PyAny>,
    limits: &PreparedLimits,
    input: &mut [[f64; MAX_DIM]; 2],
) -> PyResult<f64> {
    let (s, e) = (point::<N>(start, "start")?, point::<N>(end, "end")?);
    traj.replan_line_with(s, e, limits).map_err(build_err)?;
    for (slot, p) in input.iter_mut().zip([s, e]) {
        for (x, v) in slot.iter_mut().zip(p.iter()) {
            *x = *v;
        }
    }
    Ok(traj.duration())
}

fn replan_input<const N: usize>(
    traj: &mut CoreTraj<N>,
    input: &[[f64; MAX_DIM]; 2],
    limits: &PreparedLimits,
) -> PyResult<f64> {
    let [s, e] = input;
    traj.replan_line_with(input_point::<N>(s), input_point::<N>(e), limits)
        .map_err(build_err)?;
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

    /// An input point as a list of `dim` numbers.
    fn input_list(&self, which: usize) -> Vec<f64> {
        let dim = self.plan.dim();
        self.input
            .get(which)
            .map(|p| p.iter().take(dim).copied().collect())
            .unwrap_or_default()
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
        let limits = Limits::new(v_max, a_max, j_max)
            .and_then(|l| PreparedLimits::new(&l))
            .map_err(build_err)?;
        let plan = match dim {
            1 => Plan::D1(at_rest(limits.limits())?),
            2 => Plan::D2(at_rest(limits.limits())?),
            3 => Plan::D3(at_rest(limits.limits())?),
            4 => Plan::D4(at_rest(limits.limits())?),
            5 => Plan::D5(at_rest(limits.limits())?),
            6 => Plan::D6(at_rest(limits.limits())?),
            7 => Plan::D7(at_rest(limits.limits())?),
            8 => Plan::D8(at_rest(limits.limits())?),
            _ => {
                return Err(InputError::new_err(format!(
                    "dim = {dim}: expected 1 <= dim <= {MAX_DIM}"
                )));
            }
        };
        Ok(Self {
            plan,
            limits,
            input: [[0.0; MAX_DIM]; 2],
        })
    }

    /// Re-plans the time-optimal rest-to-rest line from `start` to `end` (`dim` numbers
    /// each) in place and returns its duration [s]. A point not given is the planner's input
    /// (`start` / `end`, ruckig's `InputParameter`): `plan()` plans from the points set
    /// before. Given points become the input once the plan succeeds; on error the previous
    /// plan and input are kept.
    #[pyo3(signature = (start=None, end=None))]
    fn plan(
        &mut self,
        start: Option<&Bound<'_, PyAny>>,
        end: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<f64> {
        let l = self.limits;
        match (start, end) {
            (None, None) => with_plan!(&mut self.plan, t => replan_input(t, &self.input, &l)),
            (Some(s), Some(e)) => {
                let input = &mut self.input;
                with_plan!(&mut self.plan, t => replan(t, s, e, &l, input))
            }
            (s, e) => {
                let dim = self.plan.dim();
                let mut input = self.input;
                let [si, ei] = &mut input;
                if let Some(s) = s {
                    read_input(s, "start", dim, si)?;
                }
                if let Some(e) = e {
                    read_input(e, "end", dim, ei)?;
                }
                let d = with_plan!(&mut self.plan, t => replan_input(t, &input, &l))?;
                self.input = input;
                Ok(d)
            }
        }
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
            spec: LimitSpec::Path(*self.limits.limits()),
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
        let l = self.limits.limits();
        (l.v_max, l.a_max, l.j_max)
    }
    /// Start point of the input: what `plan()` plans from (after a plan, the plan's start).
    #[getter]
    fn start(&self) -> Vec<f64> {
        self.input_list(0)
    }
    /// Sets the start point of the next `plan()` (`dim` numbers; their values are checked
    /// when planning).
    #[setter]
    fn set_start(&mut self, start: &Bound<'_, PyAny>) -> PyResult<()> {
        let dim = self.plan.dim();
        let [s, _] = &mut self.input;
        read_input(start, "start", dim, s)
    }
    /// End point of the input: what `plan()` plans to (after a plan, the plan's end).
    #[getter]
    fn end(&self) -> Vec<f64> {
        self.input_list(1)
    }
    /// Sets the end point of the next `plan()`.
    #[setter]
    fn set_end(&mut self, end: &Bound<'_, PyAny>) -> PyResult<()> {
        let dim = self.plan.dim();
        let [_, e] = &mut self.input;
        read_input(end, "end", dim, e)
    }

    /// Pickling: the limits, then the current line planned again (bit for bit) and the
    /// input restored.
    fn __getnewargs__(&self) -> (usize, f64, f64, f64) {
        let l = self.limits.limits();
        (self.plan.dim(), l.v_max, l.a_max, l.j_max)
    }
    #[allow(clippy::type_complexity)] // reason: the pickled tuple, spelled out for pyo3
    fn __getstate__(&self) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let (s, e) = self.points();
        (s, e, self.input_list(0), self.input_list(1))
    }
    fn __setstate__(
        &mut self,
        py: Python<'_>,
        state: (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>),
    ) -> PyResult<()> {
        let (s, e) = (
            state.0.into_pyobject(py)?.into_any(),
            state.1.into_pyobject(py)?.into_any(),
        );
        self.plan(Some(&s), Some(&e))?;
        let (si, ei) = (
            state.2.into_pyobject(py)?.into_any(),
            state.3.into_pyobject(py)?.into_any(),
        );
        self.set_start(&si)?;
        self.set_end(&ei)
    }
    fn __repr__(&self) -> String {
        let l = self.limits.limits();
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
