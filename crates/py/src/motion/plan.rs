//! The plans behind `deflect.Trajectory`: deflect-core's jerk-limited trajectories in 1..=8
//! coordinates behind one run-time dimension, their limits as the Python arguments give them,
//! and their ticks as numpy-ready rows.

use deflect_core::TickError;
use deflect_core::motion::{AxisLimits, Limits, State, Trajectory as CoreTraj};
use nalgebra::SVector;
use numpy::PyUntypedArrayMethods;
use numpy::ndarray::{Array1, Array2, ArrayView2};
use pyo3::prelude::*;

use crate::InputError;
use crate::arrays::{float_array, try_rows, try_zeros, vector};
use crate::errors::{build_err, shape_error, tick_err};
use crate::scalars::real;

/// Most coordinates of a planned or sampled motion (joint vectors of up to 8 joints).
pub const MAX_DIM: usize = 8;

/// A plan in `N` coordinates, `N` known at run time. Boxed: a trajectory holds room for its
/// 31 segments inline (up to 8 KB), and moving that through the binding's layers cost more
/// than the plan itself (perf: 47 % of `plan_line` in memmove/memset before).
#[derive(Debug, Clone)]
pub(crate) enum Plan {
    D1(Box<CoreTraj<1>>),
    D2(Box<CoreTraj<2>>),
    D3(Box<CoreTraj<3>>),
    D4(Box<CoreTraj<4>>),
    D5(Box<CoreTraj<5>>),
    D6(Box<CoreTraj<6>>),
    D7(Box<CoreTraj<7>>),
    D8(Box<CoreTraj<8>>),
}

/// Runs `$body` with `$t` bound to the plan of whatever dimension `$plan` holds (`&Plan`
/// or `&mut Plan`).
macro_rules! with_plan {
    ($plan:expr, $t:ident => $body:expr) => {
        match $plan {
            $crate::motion::plan::Plan::D1($t) => $body,
            $crate::motion::plan::Plan::D2($t) => $body,
            $crate::motion::plan::Plan::D3($t) => $body,
            $crate::motion::plan::Plan::D4($t) => $body,
            $crate::motion::plan::Plan::D5($t) => $body,
            $crate::motion::plan::Plan::D6($t) => $body,
            $crate::motion::plan::Plan::D7($t) => $body,
            $crate::motion::plan::Plan::D8($t) => $body,
        }
    };
}
pub(super) use with_plan;

/// Every tick of a trajectory, one row each.
#[derive(Debug, Clone)]
pub(crate) struct Samples {
    pub(crate) t: Array1<f64>,
    pub(crate) position: Array2<f64>,
    pub(crate) velocity: Array2<f64>,
    pub(crate) acceleration: Array2<f64>,
    pub(crate) jerk: Array2<f64>,
}

impl Samples {
    /// `n` rows of `d` zeros, allocated fallibly: `MemoryError` naming the request when the
    /// system refuses it (up to `MAX_SAMPLES` rows of 8 coordinates is 1.1 GB), never an
    /// abort of the interpreter.
    pub(super) fn try_zeros(n: usize, d: usize) -> PyResult<Self> {
        let what = "the trajectory's samples";
        let rows = || -> PyResult<Array2<f64>> {
            let v = try_rows(n, d, what)?;
            Array2::from_shape_vec((n, d), v).map_err(|e| InputError::new_err(e.to_string()))
        };
        Ok(Self {
            t: Array1::from_vec(try_zeros(n, what)?),
            position: rows()?,
            velocity: rows()?,
            acceleration: rows()?,
            jerk: rows()?,
        })
    }

    pub(super) fn set<const N: usize>(&mut self, i: usize, s: &State<N>) {
        if let Some(t) = self.t.get_mut(i) {
            *t = s.t;
        }
        for (arr, v) in [
            (&mut self.position, &s.position),
            (&mut self.velocity, &s.velocity),
            (&mut self.acceleration, &s.acceleration),
            (&mut self.jerk, &s.jerk),
        ] {
            arr.row_mut(i)
                .iter_mut()
                .zip(v.iter())
                .for_each(|(d, x)| *d = *x);
        }
    }
}

/// Every tick of `traj` at `rate_hz`. The count comes first from deflect-core's
/// [`CoreTraj::sample_count`], which refuses more than `deflect_core::motion::MAX_SAMPLES`
/// ticks before anything is allocated.
fn sample_plan<const N: usize>(traj: &CoreTraj<N>, rate_hz: f64) -> PyResult<Samples> {
    let n = traj.sample_count(rate_hz).map_err(tick_err)?;
    let mut out = Samples::try_zeros(n, N)?;
    for (i, s) in traj.ticks(rate_hz).map_err(tick_err)?.enumerate().take(n) {
        out.set(i, &s);
    }
    Ok(out)
}

/// The states of `traj` at `times`.
fn eval_plan<const N: usize>(traj: &CoreTraj<N>, times: &[f64]) -> PyResult<Samples> {
    let mut out = Samples::try_zeros(times.len(), N)?;
    for (i, &t) in times.iter().enumerate() {
        out.set(i, &traj.sample(t).map_err(tick_err)?);
    }
    Ok(out)
}

impl Plan {
    pub(super) fn dim(&self) -> usize {
        with_plan!(self, p => p.start().len())
    }
    pub(super) fn duration(&self) -> f64 {
        with_plan!(self, p => p.duration())
    }
    pub(super) fn sample_count(&self, rate_hz: f64) -> Result<usize, TickError> {
        with_plan!(self, p => p.sample_count(rate_hz))
    }
    pub(super) fn sample(&self, rate_hz: f64) -> PyResult<Samples> {
        with_plan!(self, p => sample_plan(p, rate_hz))
    }
    pub(super) fn eval(&self, times: &[f64]) -> PyResult<Samples> {
        with_plan!(self, p => eval_plan(p, times))
    }
}

/// How a plan is limited: on the path (Euclidean norms), per coordinate, or per segment.
#[derive(Debug, Clone)]
pub(crate) enum LimitSpec {
    Path(Limits),
    Axis([Vec<f64>; 3]),
    Segments(Vec<Limits>),
}

fn plan_points<const N: usize>(
    points: &ArrayView2<'_, f64>,
    spec: &LimitSpec,
) -> PyResult<Box<CoreTraj<N>>> {
    let pts: Vec<SVector<f64, N>> = points
        .rows()
        .into_iter()
        .map(|r| SVector::<f64, N>::from_iterator(r.iter().copied()))
        .collect();
    match spec {
        LimitSpec::Path(l) => CoreTraj::polyline(&pts, l),
        LimitSpec::Segments(l) => CoreTraj::polyline_with_limits(&pts, l),
        LimitSpec::Axis([v, a, j]) => CoreTraj::polyline_axis_limits(
            &pts,
            &AxisLimits {
                v_max: SVector::from_column_slice(v),
                a_max: SVector::from_column_slice(a),
                j_max: SVector::from_column_slice(j),
            },
        ),
    }
    .map(Box::new)
    .map_err(build_err)
}

pub(super) fn plan_dyn(points: ArrayView2<'_, f64>, spec: &LimitSpec) -> PyResult<Plan> {
    let p = &points;
    Ok(match points.ncols() {
        1 => Plan::D1(plan_points::<1>(p, spec)?),
        2 => Plan::D2(plan_points::<2>(p, spec)?),
        3 => Plan::D3(plan_points::<3>(p, spec)?),
        4 => Plan::D4(plan_points::<4>(p, spec)?),
        5 => Plan::D5(plan_points::<5>(p, spec)?),
        6 => Plan::D6(plan_points::<6>(p, spec)?),
        7 => Plan::D7(plan_points::<7>(p, spec)?),
        8 => Plan::D8(plan_points::<8>(p, spec)?),
        _ => {
            return Err(shape_error(
                "points",
                &format!("(n, d) with 1 <= d <= {MAX_DIM}"),
                points.shape(),
            ));
        }
    })
}

/// One of `v_max`, `a_max`, `j_max`: a real number, or one per coordinate (`d` of them).
enum LimitArg {
    Scalar(f64),
    Axis(Vec<f64>),
}

fn limit_arg(o: &Bound<'_, PyAny>, what: &str, d: usize) -> PyResult<LimitArg> {
    if o.is_exact_instance_of::<pyo3::types::PyFloat>()
        || o.is_exact_instance_of::<pyo3::types::PyInt>()
    {
        return Ok(LimitArg::Scalar(real(o, what)?));
    }
    let a = float_array(o, what)?;
    match a.ndim() {
        0 => Ok(LimitArg::Scalar(real(o, what)?)),
        1 => Ok(LimitArg::Axis(vector(o, what, d)?)),
        _ => Err(shape_error(
            what,
            &format!("a real number or ({d},)"),
            a.shape(),
        )),
    }
}

/// The limits from the `v_max`, `a_max`, `j_max` arguments: path limits if all three are
/// numbers, per-coordinate limits (numbers broadcast) if any is an array.
pub(super) fn limit_spec(
    v_max: &Bound<'_, PyAny>,
    a_max: &Bound<'_, PyAny>,
    j_max: &Bound<'_, PyAny>,
    d: usize,
) -> PyResult<LimitSpec> {
    let args = [
        limit_arg(v_max, "v_max", d)?,
        limit_arg(a_max, "a_max", d)?,
        limit_arg(j_max, "j_max", d)?,
    ];
    if let [
        LimitArg::Scalar(v),
        LimitArg::Scalar(a),
        LimitArg::Scalar(j),
    ] = args
    {
        return Ok(LimitSpec::Path(Limits::new(v, a, j).map_err(build_err)?));
    }
    let [v, a, j] = args.map(|x| match x {
        LimitArg::Scalar(s) => vec![s; d],
        LimitArg::Axis(v) => v,
    });
    Ok(LimitSpec::Axis([v, a, j]))
}
