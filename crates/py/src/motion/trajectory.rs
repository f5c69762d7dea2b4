//! `deflect.Trajectory` and the planning functions that make one.

use std::sync::OnceLock;

use deflect_core::motion::{DEFAULT_RATE_HZ, Limits, MAX_POINTS, MAX_SAMPLES, SampledTrajectory};
use nalgebra::SVector;
use numpy::ndarray::{Array2, ArrayView2};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods, ToPyArray};
use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::InputError;
use crate::args;
use crate::arrays::{check_count, float_array, matrix, vector, vector_upto};
use crate::errors::{build_err, shape_error, tick_err};
use crate::scalars::real;

use super::plan::{LimitSpec, MAX_DIM, Plan, Samples, limit_spec, plan_dyn};

/// Calls `$f::<N>($($arg),*)` for the run-time dimension `$d` (1..=8); `$else` for any
/// other dimension.
macro_rules! dispatch_dim {
    ($d:expr, $f:ident($($arg:expr),*), $else:expr) => {
        match $d {
            1 => $f::<1>($($arg),*),
            2 => $f::<2>($($arg),*),
            3 => $f::<3>($($arg),*),
            4 => $f::<4>($($arg),*),
            5 => $f::<5>($($arg),*),
            6 => $f::<6>($($arg),*),
            7 => $f::<7>($($arg),*),
            8 => $f::<8>($($arg),*),
            _ => $else,
        }
    };
}

/// A planned or sampled motion in 1..=8 coordinates, SI units.
///
/// From `plan_line`/`plan_polyline`: the plan itself (exact at any `t`, `at(t)`) and, unless
/// planned with `rate_hz=None` (plan only), its ticks at `rate_hz` (`t`, `position`, ...:
/// one row per tick, tick `k` at `k / rate_hz`, the last exactly at the end point; computed
/// on first access). From `Trajectory.from_samples`: the user's samples with their
/// finite-difference derivatives (no plan: `at` and `sampled` are not available).
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct Trajectory {
    plan: Option<Plan>,
    /// What it was made from, for pickling.
    recipe: Recipe,
    dim: usize,
    duration: f64,
    rate_hz: Option<f64>,
    samples: OnceLock<Samples>,
}

/// What a trajectory was made from: pickling remakes it from these, bit for bit.
#[derive(Debug, Clone)]
pub(crate) enum Recipe {
    /// `plan_line` / `plan_polyline`: the points (n, d) and the limits.
    Planned {
        points: Array2<f64>,
        spec: LimitSpec,
    },
    /// `Trajectory.from_samples`: the positions (n, d) and accelerations, if given.
    Sampled {
        position: Array2<f64>,
        acceleration: Option<Array2<f64>>,
    },
}

impl Trajectory {
    pub(super) fn planned(plan: Plan, recipe: Recipe, rate_hz: Option<f64>) -> PyResult<Self> {
        if let Some(r) = rate_hz {
            // Refuse a tick budget overrun now, not on first access.
            plan.sample_count(r).map_err(tick_err)?;
        }
        Ok(Self {
            dim: plan.dim(),
            duration: plan.duration(),
            plan: Some(plan),
            recipe,
            rate_hz,
            samples: OnceLock::new(),
        })
    }

    /// The ticks, sampled on first use (without the GIL).
    pub(crate) fn samples(&self, py: Python<'_>) -> PyResult<&Samples> {
        if let Some(s) = self.samples.get() {
            return Ok(s);
        }
        let (Some(plan), Some(rate)) = (&self.plan, self.rate_hz) else {
            return Err(InputError::new_err(
                "this Trajectory is plan-only (planned with rate_hz=None): evaluate it with \
                 .at(t) or sample it with .sampled(rate_hz)",
            ));
        };
        let s = py.detach(|| plan.sample(rate))?;
        Ok(self.samples.get_or_init(|| s))
    }
}

fn samples_to_dict<'py>(
    py: Python<'py>,
    s: &Samples,
    scalar: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    if scalar {
        d.set_item("t", s.t.first().copied().unwrap_or(f64::NAN))?;
        for (k, a) in [
            ("position", &s.position),
            ("velocity", &s.velocity),
            ("acceleration", &s.acceleration),
            ("jerk", &s.jerk),
        ] {
            d.set_item(k, a.row(0).to_pyarray(py))?;
        }
    } else {
        d.set_item("t", s.t.to_pyarray(py))?;
        for (k, a) in [
            ("position", &s.position),
            ("velocity", &s.velocity),
            ("acceleration", &s.acceleration),
            ("jerk", &s.jerk),
        ] {
            d.set_item(k, a.to_pyarray(py))?;
        }
    }
    Ok(d)
}

/// `Trajectory.at` and `LinePlanner.at`: the states of `plan` at `t` (a number or (m,)).
pub(super) fn plan_at<'py>(
    py: Python<'py>,
    plan: &Plan,
    t: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let a = float_array(t, "t")?;
    let (times, scalar) = match a.ndim() {
        0 => (vec![real(t, "t")?], true),
        1 => (vector_upto(t, "t", MAX_SAMPLES, "MAX_SAMPLES")?, false),
        _ => {
            return Err(shape_error("t", "a number or (m,)", a.shape()));
        }
    };
    let s = py.detach(|| plan.eval(&times))?;
    samples_to_dict(py, &s, scalar)
}

fn from_samples_n<const N: usize>(
    rate_hz: f64,
    position: &ArrayView2<'_, f64>,
    acceleration: Option<&ArrayView2<'_, f64>>,
) -> PyResult<Samples> {
    let rows = |m: &ArrayView2<'_, f64>| -> Vec<SVector<f64, N>> {
        m.rows()
            .into_iter()
            .map(|r| SVector::<f64, N>::from_iterator(r.iter().copied()))
            .collect()
    };
    let traj = match acceleration {
        None => SampledTrajectory::from_positions(rate_hz, rows(position)),
        Some(a) => {
            SampledTrajectory::from_positions_and_accelerations(rate_hz, rows(position), rows(a))
        }
    }
    .map_err(build_err)?;
    let mut out = Samples::try_zeros(traj.len(), N)?;
    for i in 0..traj.len() {
        out.set(i, &traj.state(i).map_err(tick_err)?);
    }
    Ok(out)
}

#[pymethods]
impl Trajectory {
    /// A trajectory from the user's own positions `position` (n, d) [m or rad], 1 <= d <= 8
    /// (a 1-D array is one coordinate), sampled at `rate_hz` [Hz], sample `k` at
    /// `k / rate_hz`. Velocities by central differences (second-order one-sided at the
    /// ends), accelerations by `(p[k+1] - 2 p[k] + p[k-1]) / h^2` (second-order one-sided
    /// at the ends, at least 4 samples), jerks by central differences of the accelerations,
    /// unless `acceleration` (n, d) is given (then at least 3 samples). Differences amplify
    /// noise by `1 / h^2`: filter measured paths first, or give the accelerations. At most
    /// 2^22 samples.
    #[staticmethod]
    #[pyo3(signature = (position, rate_hz, acceleration=None))]
    fn from_samples(
        py: Python<'_>,
        position: &Bound<'_, PyAny>,
        #[pyo3(from_py_with = args::real::rate_hz)] rate_hz: f64,
        acceleration: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let as_2d = |o: &Bound<'_, PyAny>, what: &str, cols: Option<usize>| {
            let a = float_array(o, what)?;
            let a = if a.ndim() == 1 {
                let n = a.len();
                a.reshape(vec![n, 1])?
            } else {
                a
            };
            let m = matrix(a.as_any(), what, None, cols)?;
            let v = m.as_array();
            // Before the copy: core refuses the same counts after it.
            check_count(what, v.nrows(), "samples", MAX_SAMPLES, "MAX_SAMPLES")?;
            if v.ncols() == 0 || v.ncols() > MAX_DIM {
                return Err(shape_error(
                    what,
                    &format!("(n, d) with 1 <= d <= {MAX_DIM}"),
                    v.shape(),
                ));
            }
            Ok::<_, PyErr>(v.to_owned())
        };
        let p = as_2d(position, "position", None)?;
        let d = p.ncols();
        let a = acceleration
            .map(|a| as_2d(a, "acceleration", Some(d)))
            .transpose()?;
        let (pv, av) = (p.view(), a.as_ref().map(|a| a.view()));
        let samples = py.detach(|| {
            dispatch_dim!(
                d,
                from_samples_n(rate_hz, &pv, av.as_ref()),
                Err(shape_error(
                    "position",
                    &format!("(n, d) with 1 <= d <= {MAX_DIM}"),
                    &[pv.nrows(), d]
                ))
            )
        })?;
        let duration = samples.t.last().copied().unwrap_or(0.0);
        Ok(Self {
            plan: None,
            recipe: Recipe::Sampled {
                position: p.clone(),
                acceleration: a.clone(),
            },
            dim: d,
            duration,
            rate_hz: Some(rate_hz),
            samples: OnceLock::from(samples),
        })
    }

    /// The exact state at time `t` [s] (a number, or an array of times): a dict with `t`,
    /// `position`, `velocity`, `acceleration`, `jerk`, each (d,) for a number and (m, d) for
    /// m times (at most `MAX_SAMPLES`). Before 0 the start at rest, from `duration` on the
    /// end at rest (held, as a controller holds the end states; not an error). Planned
    /// trajectories only.
    fn at<'py>(&self, py: Python<'py>, t: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
        let Some(plan) = &self.plan else {
            return Err(InputError::new_err(
                "this Trajectory was built from samples and has no plan to evaluate between \
                 them: index its arrays instead",
            ));
        };
        plan_at(py, plan, t)
    }

    /// The same plan with its ticks at `rate_hz` [Hz] (at most 2^22 ticks).
    fn sampled(&self, #[pyo3(from_py_with = args::real::rate_hz)] rate_hz: f64) -> PyResult<Self> {
        let Some(plan) = &self.plan else {
            return Err(InputError::new_err(
                "this Trajectory was built from samples: it has no plan to sample again",
            ));
        };
        Self::planned(plan.clone(), self.recipe.clone(), Some(rate_hz))
    }

    /// Pickling and `copy.deepcopy`: planned trajectories are planned again from their
    /// points and limits, sampled ones rebuilt from their samples; both bit for bit.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, pyo3::types::PyTuple>)> {
        let me = slf.get();
        trajectory_reduce(slf.py(), &me.recipe, me.rate_hz)
    }

    /// Tick times [s], shape (n,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(self.samples(py)?.t.to_pyarray(py))
    }
    /// Positions [m or rad], shape (n, d).
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(self.samples(py)?.position.to_pyarray(py))
    }
    /// Velocities [m/s or rad/s], shape (n, d).
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(self.samples(py)?.velocity.to_pyarray(py))
    }
    /// Accelerations [m/s^2 or rad/s^2], shape (n, d).
    #[getter]
    fn acceleration<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(self.samples(py)?.acceleration.to_pyarray(py))
    }
    /// Jerks [m/s^3 or rad/s^3], shape (n, d).
    #[getter]
    fn jerk<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(self.samples(py)?.jerk.to_pyarray(py))
    }
    /// Total duration [s].
    #[getter]
    fn duration(&self) -> f64 {
        self.duration
    }
    /// Number of coordinates d.
    #[getter]
    fn dim(&self) -> usize {
        self.dim
    }
    /// Sampling rate [Hz]; None for a plan-only trajectory.
    #[getter]
    fn rate_hz(&self) -> Option<f64> {
        self.rate_hz
    }
    /// Whether this trajectory comes from the planner (`at` and `sampled` work).
    #[getter]
    fn is_planned(&self) -> bool {
        self.plan.is_some()
    }
    /// Number of ticks; `InputError` for a plan-only trajectory.
    fn __len__(&self) -> PyResult<usize> {
        if let Some(s) = self.samples.get() {
            return Ok(s.t.len());
        }
        match (&self.plan, self.rate_hz) {
            (Some(p), Some(r)) => p.sample_count(r).map_err(tick_err),
            _ => Err(InputError::new_err(
                "a plan-only Trajectory (rate_hz=None) has no ticks: use .sampled(rate_hz)",
            )),
        }
    }
    fn __repr__(&self) -> String {
        let ticks = match (&self.plan, self.rate_hz) {
            (_, None) => "plan only".to_string(),
            (Some(p), Some(r)) => format!(
                "ticks={}, rate_hz={r}",
                p.sample_count(r).unwrap_or_default()
            ),
            (None, Some(r)) => format!(
                "samples={}, rate_hz={r}",
                self.samples.get().map_or(0, |s| s.t.len())
            ),
        };
        format!(
            "Trajectory(duration={:.6} s, dim={}, {ticks})",
            self.duration, self.dim
        )
    }
}

/// Time-optimal jerk-limited rest-to-rest straight move from `start` to `end` (1 to 8
/// coordinates: a point [m] or a joint vector [rad]). `v_max`, `a_max`, `j_max` are either
/// numbers, limiting the path's speed, acceleration and jerk (Euclidean norms), or arrays of
/// one limit per coordinate (numbers broadcast), for joint space: each coordinate stays
/// within its own limits and all arrive together. Sampled at `rate_hz` [Hz] on first access
/// of the arrays (at most 2^22 ticks, `InputError` beyond); `rate_hz=None` plans only (see
/// `Trajectory.at`).
#[pyfunction]
#[pyo3(signature = (start, end, v_max, a_max, j_max, rate_hz=Some(DEFAULT_RATE_HZ)),
       text_signature = "(start, end, v_max, a_max, j_max, rate_hz=2000.0)")]
pub(super) fn plan_line(
    start: &Bound<'_, PyAny>,
    end: &Bound<'_, PyAny>,
    v_max: &Bound<'_, PyAny>,
    a_max: &Bound<'_, PyAny>,
    j_max: &Bound<'_, PyAny>,
    #[pyo3(from_py_with = args::opt_real::rate_hz)] rate_hz: Option<f64>,
) -> PyResult<Trajectory> {
    // A list, tuple or float64 vector of 1..=8 numbers is read directly (numpy's asarray
    // would cost more than the plan); anything else goes through numpy, the dimension
    // checked before anything is copied.
    let s = match crate::arrays::fast_vector(start) {
        Some(v) if (1..=MAX_DIM).contains(&v.len()) => v,
        _ => {
            let sa = float_array(start, "start")?;
            let d = sa.len();
            if sa.ndim() != 1 || !(1..=MAX_DIM).contains(&d) {
                return Err(shape_error(
                    "start",
                    &format!("(d,) with 1 <= d <= {MAX_DIM}"),
                    sa.shape(),
                ));
            }
            vector(start, "start", d)?
        }
    };
    let d = s.len();
    let e = vector(end, "end", d)?;
    let pts = Array2::from_shape_vec((2, d), [s, e].concat())
        .map_err(|e| InputError::new_err(e.to_string()))?;
    let spec = limit_spec(v_max, a_max, j_max, d)?;
    let plan = plan_dyn(pts.view(), &spec)?;
    Trajectory::planned(plan, Recipe::Planned { points: pts, spec }, rate_hz)
}

/// Rest-to-rest moves through `points` (n, d), 2 <= n <= 32, 1 <= d <= 8, stopping at every
/// point; repeated points are skipped. Limits as `plan_line` (`v_max`, `a_max`, `j_max`:
/// numbers for the path, arrays per coordinate), or per segment: `segment_limits` (n - 1, 3),
/// row `i` the `(v_max, a_max, j_max)` of the move from `points[i]` to `points[i + 1]` (then
/// leave `v_max`, `a_max`, `j_max` out). Ticks and `rate_hz` as `plan_line`.
#[pyfunction]
#[pyo3(signature = (points, v_max=None, a_max=None, j_max=None, rate_hz=Some(DEFAULT_RATE_HZ), segment_limits=None),
       text_signature = "(points, v_max=None, a_max=None, j_max=None, rate_hz=2000.0, segment_limits=None)")]
pub(super) fn plan_polyline(
    points: &Bound<'_, PyAny>,
    v_max: Option<&Bound<'_, PyAny>>,
    a_max: Option<&Bound<'_, PyAny>>,
    j_max: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = args::opt_real::rate_hz)] rate_hz: Option<f64>,
    segment_limits: Option<&Bound<'_, PyAny>>,
) -> PyResult<Trajectory> {
    let points = matrix(points, "points", None, None)?;
    let points = points.as_array();
    // Before anything is copied (segment limits, the plan's points): core refuses the same.
    check_count("points", points.nrows(), "rows", MAX_POINTS, "MAX_POINTS")?;
    if points.ncols() == 0 || points.ncols() > MAX_DIM {
        return Err(shape_error(
            "points",
            &format!("(n, d) with 1 <= d <= {MAX_DIM}"),
            &[points.nrows(), points.ncols()],
        ));
    }
    let spec = match (v_max, a_max, j_max, segment_limits) {
        (Some(v), Some(a), Some(j), None) => limit_spec(v, a, j, points.ncols())?,
        (None, None, None, Some(s)) => {
            let rows = points.nrows().saturating_sub(1);
            let m = matrix(s, "segment_limits", Some(rows), Some(3))?;
            let limits = m
                .as_array()
                .rows()
                .into_iter()
                .enumerate()
                .map(|(i, r)| {
                    let at = |k: usize| r.get(k).copied().unwrap_or(f64::NAN);
                    Limits::new(at(0), at(1), at(2))
                        .map_err(|e| InputError::new_err(format!("segment_limits row {i}: {e}")))
                })
                .collect::<PyResult<Vec<_>>>()?;
            LimitSpec::Segments(limits)
        }
        (None, None, None, None) => {
            return Err(InputError::new_err(
                "plan_polyline needs limits: v_max, a_max and j_max, or segment_limits",
            ));
        }
        (_, _, _, Some(_)) => {
            return Err(InputError::new_err(
                "plan_polyline: give either v_max, a_max and j_max or segment_limits, not both",
            ));
        }
        _ => {
            return Err(InputError::new_err(
                "plan_polyline: v_max, a_max and j_max go together (all three)",
            ));
        }
    };
    let plan = plan_dyn(points, &spec)?;
    let recipe = Recipe::Planned {
        points: points.to_owned(),
        spec,
    };
    Trajectory::planned(plan, recipe, rate_hz)
}

/// Limits `(v_max, a_max, j_max)` that reproduce the paper's motions at `g_level` g (1..5).
#[pyfunction]
pub(super) fn paper_limits(
    #[pyo3(from_py_with = args::count::g_level)] g_level: usize,
) -> PyResult<(f64, f64, f64)> {
    let g = u8::try_from(g_level).map_err(|_| {
        InputError::new_err(format!(
            "g_level = {g_level}: the paper's motions exist for 1..=5 g"
        ))
    })?;
    let l = deflect_core::motion::paper_limits(g).map_err(build_err)?;
    Ok((l.v_max, l.a_max, l.j_max))
}

/// Adds the motion planner to the module.
/// `(callable, args)` that remakes a trajectory of `recipe` sampled at `rate_hz`: the public
/// `plan_polyline` (which is what `plan_line` plans with) or `Trajectory.from_samples`, so
/// that the state is validated again on the way back.
fn trajectory_reduce<'py>(
    py: Python<'py>,
    recipe: &Recipe,
    rate_hz: Option<f64>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
    let module = py.import("deflect._deflect")?;
    let none = || py.None().into_bound(py);
    match recipe {
        Recipe::Planned { points, spec } => {
            let (v, a, j, segments) = match spec {
                LimitSpec::Path(l) => (
                    l.v_max.into_bound_py_any(py)?,
                    l.a_max.into_bound_py_any(py)?,
                    l.j_max.into_bound_py_any(py)?,
                    none(),
                ),
                LimitSpec::Axis([v, a, j]) => (
                    v.clone().into_bound_py_any(py)?,
                    a.clone().into_bound_py_any(py)?,
                    j.clone().into_bound_py_any(py)?,
                    none(),
                ),
                LimitSpec::Segments(ls) => {
                    let rows: Vec<[f64; 3]> =
                        ls.iter().map(|l| [l.v_max, l.a_max, l.j_max]).collect();
                    (none(), none(), none(), rows.into_bound_py_any(py)?)
                }
            };
            let args = [
                points.to_pyarray(py).into_any(),
                v,
                a,
                j,
                rate_hz.into_bound_py_any(py)?,
                segments,
            ];
            Ok((module.getattr("plan_polyline")?, PyTuple::new(py, args)?))
        }
        Recipe::Sampled {
            position,
            acceleration,
        } => {
            let args = [
                position.to_pyarray(py).into_any(),
                rate_hz.unwrap_or(f64::NAN).into_bound_py_any(py)?,
                match acceleration {
                    Some(a) => a.to_pyarray(py).into_any(),
                    None => none(),
                },
            ];
            let ctor = module.getattr("Trajectory")?.getattr("from_samples")?;
            Ok((ctor, PyTuple::new(py, args)?))
        }
    }
}
