//! `deflect.posture_sweep` and the per-chunk kernel of `deflect.atlas`: the stiffness-optimal
//! rotation about the tool axis (deflect-core's `posture::sweep`), for one task or for a
//! batch of tasks on every core.

use deflect_core::TickError;
use deflect_core::mechanism::PoseIkOptions;
use deflect_core::posture::{
    self, AnglePoint, MAX_ANGLES, MAX_DIRECTIONS, MAX_SEEDS, Measure, PostureOptions, Reach,
};
use deflect_core::vjm::{self, Data, Vector6};
use nalgebra::Vector3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::InputError;
use crate::arrays::{batch_pair, check_count, matrix, try_rows, vector, vector_upto};
use crate::batch::{self, BatchFailure};
use crate::errors::{tick_err, tick_err_at};
use crate::vjm::SerialRobot;

/// Columns of one atlas row before the joints: status code, reachable angles, best angle,
/// best measure, best deflection (6).
const HEAD: usize = 10;
/// Columns after the joints: worst angle, worst measure, compliance (36), seed index, angles
/// beyond the model.
const TAIL: usize = 40;

/// The sweep's settings from the Python arguments.
struct Settings {
    angles: Vec<f64>,
    seeds: Vec<f64>,
    options: PostureOptions,
}

fn settings(
    robot: &SerialRobot,
    angles: Option<&Bound<'_, PyAny>>,
    seeds: Option<&Bound<'_, PyAny>>,
    measure: Option<&Bound<'_, PyAny>>,
    refine: bool,
    min_sigma: f64,
) -> PyResult<Settings> {
    let dof = robot.inner.model.dof();
    let angles = match angles {
        // One degree over the full turn.
        None => (0..360).map(|k| f64::from(k - 180).to_radians()).collect(),
        Some(a) => vector_upto(a, "angles", MAX_ANGLES, "MAX_ANGLES")?,
    };
    if angles.is_empty() || angles.len() > MAX_ANGLES {
        return Err(InputError::new_err(format!(
            "angles: {} angles, expected 1..={MAX_ANGLES}",
            angles.len()
        )));
    }
    let seeds = match seeds {
        None => robot
            .inner
            .joint_limits
            .iter()
            .map(|(lo, hi)| 0.5 * (lo + hi))
            .collect(),
        Some(s) => {
            let a = crate::arrays::float_array(s, "seeds")?;
            if a.ndim() == 1 {
                vector(s, "seeds", dof)?
            } else {
                let m = matrix(s, "seeds", None, Some(dof))?;
                check_count(
                    "seeds",
                    m.as_array().nrows(),
                    "rows",
                    MAX_SEEDS,
                    "MAX_SEEDS",
                )?;
                m.as_array().iter().copied().collect()
            }
        }
    };
    let measure = match measure {
        None => Measure::Norm,
        Some(m) if m.is_instance_of::<pyo3::types::PyString>() => {
            match m.extract::<String>()?.as_str() {
                "norm" => Measure::Norm,
                "max" => Measure::Max,
                other => {
                    return Err(InputError::new_err(format!(
                        "measure = '{other}': expected 'norm', 'max' or directions (k, 3), k <= 3"
                    )));
                }
            }
        }
        Some(m) => {
            let d = matrix(m, "measure", None, Some(3))?;
            let k = d.as_array().nrows();
            check_count("measure", k, "directions", MAX_DIRECTIONS, "MAX_DIRECTIONS")?;
            let dirs: Vec<Vector3<f64>> = d
                .as_array()
                .rows()
                .into_iter()
                .map(|r| Vector3::from_iterator(r.iter().copied()))
                .collect();
            Measure::along(&dirs).ok_or_else(|| {
                InputError::new_err("measure: 1 to 3 finite, non-zero directions (k, 3) expected")
            })?
        }
    };
    let ik = PoseIkOptions {
        min_sigma,
        ..PostureOptions::default().ik
    };
    ik.validate().map_err(crate::errors::build_err)?;
    Ok(Settings {
        angles,
        seeds,
        options: PostureOptions {
            measure,
            ik,
            refine,
        },
    })
}

/// The rotation about the tool axis that deflects least: for the TCP `position` (3,) [m]
/// and `tool_axis` (3,) (the TCP z axis, base frame) under the TCP `wrench` (6,) [N, N m],
/// solves the pose IK at every angle of `angles` [rad] (default: -180..179 degrees in 1
/// degree steps), warm-started along the sweep from each of `seeds` ((dof,) or (k, dof), k <=
/// 8, one per IK branch; default the middle of the joint limits), within the joint limits
/// and `min_sigma` [m/rad] from a singularity, and evaluates the exact deflection. `measure`:
/// 'norm' (|dp|), 'max' (max |dp_i|) or directions (k, 3), k <= 3 (max |u_k . dp|).
/// `refine`: a golden-section search between the best angle's neighbours.
///
/// Returns a dict: `angle` (n,), `reach` (n strings: 'reachable', 'out_of_reach',
/// 'singular', 'joint_limit', or 'beyond_model': a posture exists but the wrench turns a
/// spring past `MAX_SPRING_ANGLE`, outside the small-deflection model), `status` (the
/// point's: 'reachable' if an angle is, else the most telling of the others,
/// 'beyond_model' first), `reachable` (n,) bool, `measure` (n,) [m], `deflection` (n, 6)
/// [m, rad], `q` (n, dof) (NaN where not reachable), `best` (a dict with `angle`, `measure`,
/// `deflection`, `q`, or None if nothing is reachable), `best_index`, `worst_index`.
#[pyfunction]
#[pyo3(signature = (robot, position, tool_axis, wrench, *, angles=None, seeds=None, measure=None, refine=true, min_sigma=1e-3),
       text_signature = "(robot, position, tool_axis, wrench, *, angles=None, seeds=None, measure=None, refine=True, min_sigma=0.001)")]
#[allow(clippy::too_many_arguments)] // reason: the documented Python keyword arguments
fn posture_sweep<'py>(
    py: Python<'py>,
    robot: &SerialRobot,
    position: &Bound<'py, PyAny>,
    tool_axis: &Bound<'py, PyAny>,
    wrench: &Bound<'py, PyAny>,
    angles: Option<&Bound<'py, PyAny>>,
    seeds: Option<&Bound<'py, PyAny>>,
    measure: Option<&Bound<'py, PyAny>>,
    refine: bool,
    #[pyo3(from_py_with = crate::args::real::min_sigma)] min_sigma: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let s = settings(robot, angles, seeds, measure, refine, min_sigma)?;
    let p = Vector3::from_column_slice(&vector(position, "position", 3)?);
    let a = Vector3::from_column_slice(&vector(tool_axis, "tool_axis", 3)?);
    let w = Vector6::from_column_slice(&vector(wrench, "wrench", 6)?);
    let model = &robot.inner.model;
    let dof = model.dof();
    let mut out = vec![AnglePoint::default(); s.angles.len()];
    let summary = py
        .detach(|| {
            posture::sweep(
                model,
                &mut Data::new(model),
                &robot.inner.joint_limits,
                &p,
                &a,
                &w,
                &s.angles,
                &s.seeds,
                &s.options,
                &mut out,
            )
        })
        .map_err(tick_err)?;
    let n = out.len();
    let d = PyDict::new(py);
    d.set_item(
        "angle",
        Array1::from_iter(out.iter().map(|o| o.angle)).into_pyarray(py),
    )?;
    let reach: Vec<&str> = out.iter().map(|o| o.reach.name()).collect();
    d.set_item("reach", reach)?;
    d.set_item("status", summary.status.name())?;
    let reachable: Vec<bool> = out.iter().map(|o| o.reach == Reach::Reachable).collect();
    d.set_item("reachable", numpy::PyArray1::from_vec(py, reachable))?;
    d.set_item(
        "measure",
        Array1::from_iter(out.iter().map(|o| o.measure)).into_pyarray(py),
    )?;
    let rows = |k: usize, f: &dyn Fn(&AnglePoint) -> Vec<f64>| {
        Array2::from_shape_vec((n, k), out.iter().flat_map(f).collect())
            .map_err(|e| InputError::new_err(format!("internal: {e}")))
    };
    d.set_item(
        "deflection",
        rows(6, &|o| o.deflection.iter().copied().collect())?.into_pyarray(py),
    )?;
    d.set_item(
        "q",
        rows(dof, &|o| o.q.iter().take(dof).copied().collect())?.into_pyarray(py),
    )?;
    match summary.best {
        Some(b) => {
            let best = PyDict::new(py);
            best.set_item("angle", b.angle)?;
            best.set_item("measure", b.measure)?;
            best.set_item("deflection", b.deflection.as_slice().to_vec())?;
            best.set_item("q", b.q.get(..dof).unwrap_or(&[]).to_vec())?;
            d.set_item("best", best)?;
        }
        None => d.set_item("best", py.None())?,
    }
    d.set_item("best_index", summary.best_index)?;
    d.set_item("worst_index", summary.worst_index)?;
    Ok(d)
}

/// One chunk of `deflect.atlas` (see there): positions (N, 3), tool axes (N, 3) or (3,),
/// wrenches (N, 6) or (6,) -> (N, 10 + dof + 39) rows, on every core without the GIL.
/// Row layout: the point's status (`posture::Reach::code`: 0 reachable, 1 out of reach, 2
/// singular, 3 joint limit, 4 beyond the model), reachable angles, best angle, best measure, best deflection
/// (6), best joints (dof), worst angle, worst measure, compliance at the best posture (36,
/// row-major), best seed, angles beyond the model; NaN where nothing is reachable.
#[pyfunction]
#[pyo3(signature = (robot, positions, tool_axes, wrenches, angles=None, seeds=None, measure=None, refine=true, min_sigma=1e-3),
       text_signature = "(robot, positions, tool_axes, wrenches, angles=None, seeds=None, measure=None, refine=True, min_sigma=0.001)")]
#[allow(clippy::too_many_arguments)] // reason: the documented Python keyword arguments
fn _atlas_chunk<'py>(
    py: Python<'py>,
    robot: &SerialRobot,
    positions: &Bound<'py, PyAny>,
    tool_axes: &Bound<'py, PyAny>,
    wrenches: &Bound<'py, PyAny>,
    angles: Option<&Bound<'py, PyAny>>,
    seeds: Option<&Bound<'py, PyAny>>,
    measure: Option<&Bound<'py, PyAny>>,
    refine: bool,
    #[pyo3(from_py_with = crate::args::real::min_sigma)] min_sigma: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let s = settings(robot, angles, seeds, measure, refine, min_sigma)?;
    let (n1, pm, am) = batch_pair(
        (positions, "positions", &[3]),
        (tool_axes, "tool_axes", &[3]),
    )?;
    let (n, _, wm) = batch_pair((positions, "positions", &[3]), (wrenches, "wrenches", &[6]))?;
    if n1 != n {
        return Err(InputError::new_err(format!(
            "tool_axes and wrenches: {n1} and {n} rows do not broadcast together"
        )));
    }
    let (p, a, w) = (pm.as_array(), am.as_array(), wm.as_array());
    let (Some(p), Some(a), Some(w)) = (
        p.broadcast((n, 3)),
        a.broadcast((n, 3)),
        w.broadcast((n, 6)),
    ) else {
        return Err(InputError::new_err(
            "positions, tool_axes, wrenches: rows do not broadcast",
        ));
    };
    let model = &robot.inner.model;
    let dof = model.dof();
    let width = HEAD + dof + TAIL;
    let mut out = try_rows(n, width, "the atlas's result")?;
    out.fill(f64::NAN);
    let limits = &robot.inner.joint_limits;
    py.detach(|| {
        batch::rows(
            &mut out,
            width,
            batch::row_cost::POSTURE_SWEEP,
            || {
                (
                    Data::new(model),
                    vec![AnglePoint::default(); s.angles.len()],
                )
            },
            |i, (data, sweep_out), row| {
                let v3 = |m: &numpy::ndarray::ArrayView2<'_, f64>| {
                    Vector3::from_iterator(m.row(i).iter().copied())
                };
                let wrench = Vector6::from_iterator(w.row(i).iter().copied());
                let summary = posture::sweep(
                    model,
                    data,
                    limits,
                    &v3(&p),
                    &v3(&a),
                    &wrench,
                    &s.angles,
                    &s.seeds,
                    &s.options,
                    sweep_out,
                )?;
                fill_row(model, data, &summary, sweep_out, dof, row)
            },
        )
    })
    .map_err(|e| match e {
        BatchFailure::Row(i, e) => tick_err_at(format_args!("point {i}"), e),
        BatchFailure::Panicked => InputError::new_err("internal: an atlas worker thread panicked"),
    })?;
    let arr = Array2::from_shape_vec((n, width), out)
        .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
    Ok(arr.into_pyarray(py))
}

/// One atlas row (layout in `_atlas_chunk`) from a sweep's result.
fn fill_row(
    model: &vjm::Model,
    data: &mut Data,
    summary: &posture::SweepSummary,
    sweep: &[AnglePoint],
    dof: usize,
    row: &mut [f64],
) -> Result<(), TickError> {
    let mut put = |k: usize, v: f64| {
        if let Some(x) = row.get_mut(k) {
            *x = v;
        }
    };
    put(0, f64::from(summary.status.code()));
    put(1, summary.reachable as f64);
    put(HEAD + dof + TAIL - 1, summary.beyond_model as f64);
    let Some(best) = summary.best else {
        return Ok(());
    };
    put(2, best.angle);
    put(3, best.measure);
    for (k, v) in best.deflection.iter().enumerate() {
        put(4 + k, *v);
    }
    let q = best.q.get(..dof).unwrap_or(&[]);
    for (k, v) in q.iter().enumerate() {
        put(HEAD + k, *v);
    }
    if let Some(worst) = summary.worst_index.and_then(|i| sweep.get(i)) {
        put(HEAD + dof, worst.angle);
        put(HEAD + dof + 1, worst.measure);
    }
    let c = vjm::compliance(model, data, q)?;
    for r in 0..6 {
        for col in 0..6 {
            put(
                HEAD + dof + 2 + 6 * r + col,
                c.get((r, col)).copied().unwrap_or(f64::NAN),
            );
        }
    }
    put(HEAD + dof + TAIL - 2, best.seed as f64);
    Ok(())
}

/// Adds the posture functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(posture_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(_atlas_chunk, m)?)?;
    Ok(())
}
