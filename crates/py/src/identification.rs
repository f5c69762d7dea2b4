//! Identification (VJM paper, section 2.5, Eq. 12-17): `deflect.identify_stiffness_from_tcp`,
//! `identify_stiffness_from_frames`, `identify_sensor`.

use deflect_core::identification::{
    self as ident, FrameMeasurement, MAX_MEASUREMENTS, StiffnessIdentification, TcpMeasurement,
};
use deflect_core::vjm::Vector6;
use nalgebra::{Isometry3, Matrix3, Vector3};
use numpy::ToPyArray;
use numpy::ndarray::{Array1, Array2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::InputError;
use crate::arrays::{array_dyn, check_count, indices, matrix, pose, rotation_of};
use crate::compensation::SensorCalibration;
use crate::errors::{build_err, shape_error};
use crate::vjm::SerialRobot;

fn stiffness_dict<'py>(
    py: Python<'py>,
    id: &StiffnessIdentification,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let spring: Vec<usize> = id.axes.iter().map(|a| a.spring).collect();
    let axis: Vec<usize> = id.axes.iter().map(|a| a.axis).collect();
    let c: Array1<f64> = id
        .axes
        .iter()
        .map(|a| a.compliance.unwrap_or(f64::NAN))
        .collect();
    let k: Array1<f64> = id
        .axes
        .iter()
        .map(|a| a.stiffness().unwrap_or(f64::NAN))
        .collect();
    let se: Array1<f64> = id.axes.iter().map(|a| a.std_error).collect();
    let ok: Vec<bool> = id.axes.iter().map(|a| a.compliance.is_some()).collect();
    d.set_item("spring", spring)?;
    d.set_item("axis", axis)?;
    d.set_item("compliance", c.to_pyarray(py))?;
    d.set_item("stiffness", k.to_pyarray(py))?;
    d.set_item("std_error", se.to_pyarray(py))?;
    d.set_item("identifiable", ok)?;
    d.set_item("rank", id.fit.rank)?;
    d.set_item("residual_rms", id.fit.residual_rms)?;
    Ok(d)
}

/// An (N, cols) array (N fixed by `n` if given), copied in row-major order.
fn rows(a: &Bound<'_, PyAny>, what: &str, cols: usize, n: Option<usize>) -> PyResult<Array2<f64>> {
    let m = matrix(a, what, n, Some(cols))?;
    let v = m.as_array();
    // Before the copy: core refuses the same count after it.
    check_count(
        what,
        v.nrows(),
        "measurements",
        MAX_MEASUREMENTS,
        "MAX_MEASUREMENTS",
    )?;
    Ok(v.as_standard_layout().into_owned())
}

/// The rows of a row-major (N, cols) array as slices.
fn row_slices(a: &Array2<f64>) -> PyResult<core::slice::Chunks<'_, f64>> {
    let cols = a.ncols().max(1);
    a.as_slice()
        .map(|s| s.chunks(cols))
        .ok_or_else(|| InputError::new_err("internal: array not contiguous"))
}

/// 6-vectors from the rows of a row-major (N, 6) array.
fn vectors6(a: &Array2<f64>) -> PyResult<Vec<Vector6>> {
    Ok(row_slices(a)?.map(Vector6::from_column_slice).collect())
}

/// Stiffness identification from TCP deflections: `Q` (N, dof), `W` (N, 6), `D` (N, 6) ->
/// dict of per-axis `spring`, `axis`, `compliance` (NaN if unobservable), `stiffness`,
/// `std_error`, `identifiable`, and `rank`. At most 100000 measurements (`InputError`
/// beyond); memory and time grow linearly with N.
#[pyfunction]
#[pyo3(signature = (robot, Q, W, D, translation_only=false, all_axes=false))]
#[allow(non_snake_case)] // reason: matrix names as in the documented Python signature
fn identify_stiffness_from_tcp<'py>(
    py: Python<'py>,
    robot: &SerialRobot,
    Q: &Bound<'py, PyAny>,
    W: &Bound<'py, PyAny>,
    D: &Bound<'py, PyAny>,
    translation_only: bool,
    all_axes: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let model = &robot.inner.model;
    let q = rows(Q, "Q", model.dof(), None)?;
    let n = q.nrows();
    let (w, d) = (rows(W, "W", 6, Some(n))?, rows(D, "D", 6, Some(n))?);
    let meas: Vec<TcpMeasurement> = row_slices(&q)?
        .zip(vectors6(&w)?)
        .zip(vectors6(&d)?)
        .map(|((q, wrench), deflection)| TcpMeasurement {
            q,
            wrench,
            deflection,
            translation_only,
        })
        .collect();
    let id = py
        .detach(|| ident::identify_from_tcp(model, &meas, all_axes))
        .map_err(build_err)?;
    stiffness_dict(py, &id)
}

/// Stiffness identification from frame pairs (section 2.5): `Q` (N, dof), `W` (N, 6),
/// `springs` (N,) virtual-joint indices, `rotations` (N, 3) [rad] in the spring frames.
#[pyfunction]
#[pyo3(signature = (robot, Q, W, springs, rotations, all_axes=false))]
#[allow(non_snake_case)] // reason: matrix names as in the documented Python signature
fn identify_stiffness_from_frames<'py>(
    py: Python<'py>,
    robot: &SerialRobot,
    Q: &Bound<'py, PyAny>,
    W: &Bound<'py, PyAny>,
    springs: &Bound<'py, PyAny>,
    rotations: &Bound<'py, PyAny>,
    all_axes: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let model = &robot.inner.model;
    let q = rows(Q, "Q", model.dof(), None)?;
    let n = q.nrows();
    let (w, r) = (
        rows(W, "W", 6, Some(n))?,
        rows(rotations, "rotations", 3, Some(n))?,
    );
    let springs = indices(
        springs,
        "springs",
        deflect_core::vjm::MAX_SPRINGS,
        "MAX_SPRINGS",
    )?;
    if springs.len() != n {
        return Err(shape_error("springs", &format!("({n},)"), &[springs.len()]));
    }
    let meas: Vec<FrameMeasurement> = row_slices(&q)?
        .zip(vectors6(&w)?)
        .zip(springs)
        .zip(row_slices(&r)?)
        .map(|(((q, wrench), spring), rot)| FrameMeasurement {
            q,
            wrench,
            spring,
            rotation: Vector3::from_column_slice(rot),
        })
        .collect();
    let id = py
        .detach(|| ident::identify_from_frames(model, &meas, all_axes))
        .map_err(build_err)?;
    stiffness_dict(py, &id)
}

/// Sensor offsets, weight, centre of gravity (Eq. 12-15) and optionally the residual
/// polynomial (Eq. 16-17) from unloaded `readings` (N, 6) at sensor `rotations` (N, 3, 3).
/// Returns `(SensorCalibration, info dict)`.
#[pyfunction]
#[pyo3(signature = (rotations, readings, fit_polynomial=false, sensor_to_tcp=None))]
fn identify_sensor<'py>(
    py: Python<'py>,
    rotations: &Bound<'py, PyAny>,
    readings: &Bound<'py, PyAny>,
    fit_polynomial: bool,
    sensor_to_tcp: Option<&Bound<'py, PyAny>>,
) -> PyResult<(SensorCalibration, Bound<'py, PyDict>)> {
    let r = array_dyn(rotations, "rotations")?;
    let r = r.as_array();
    let n = match r.shape() {
        &[n, 3, 3] => n,
        s => return Err(shape_error("rotations", "(N, 3, 3)", s)),
    };
    check_count(
        "rotations",
        n,
        "measurements",
        MAX_MEASUREMENTS,
        "MAX_MEASUREMENTS",
    )?;
    let w = rows(readings, "readings", 6, Some(n))?;
    let mut quats = Vec::with_capacity(n);
    for (i, m) in r.outer_iter().enumerate() {
        let what = format!("rotations[{i}]");
        let m = m
            .into_dimensionality::<numpy::ndarray::Ix2>()
            .map_err(|e| InputError::new_err(format!("{what}: {e}")))?;
        let mut m3 = Matrix3::zeros();
        for ((a, b), x) in m.indexed_iter() {
            if !x.is_finite() {
                return Err(InputError::new_err(format!(
                    "{what}[{a}, {b}] is not finite"
                )));
            }
            if let Some(dst) = m3.get_mut((a, b)) {
                *dst = *x;
            }
        }
        quats.push(rotation_of(&m3, &what)?);
    }
    let ws = vectors6(&w)?;
    let s2t = match sensor_to_tcp {
        Some(a) => pose(a, "sensor_to_tcp")?,
        None => Isometry3::identity(),
    };
    let id = ident::identify_sensor(&quats, &ws, fit_polynomial, s2t).map_err(build_err)?;
    let d = PyDict::new(py);
    d.set_item("force_rank", id.force_rank)?;
    d.set_item("moment_rank", id.moment_rank)?;
    d.set_item("force_rms", id.force_rms)?;
    d.set_item("moment_rms", id.moment_rms)?;
    d.set_item("polynomial_rms", id.polynomial_rms)?;
    Ok((
        SensorCalibration {
            inner: id.calibration,
        },
        d,
    ))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(identify_stiffness_from_tcp, m)?)?;
    m.add_function(wrap_pyfunction!(identify_stiffness_from_frames, m)?)?;
    m.add_function(wrap_pyfunction!(identify_sensor, m)?)?;
    Ok(())
}
