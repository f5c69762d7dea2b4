//! Online compensation chain (VJM paper, sections 2.2-2.6) and identification (section 2.5,
//! Eq. 12-17): `deflect.SensorCalibration`, `LowPass`, `MovingAverage`, `PilotControl`,
//! `project_normal_to_feed`, `OnlineCompensator`, `identify_stiffness_from_tcp`,
//! `identify_stiffness_from_frames`, `identify_sensor`.

use deflect_core::compensation::sensor::POLY_TERMS;
use deflect_core::compensation::{
    CompensatorConfig, CorrectionOutput, LowPass as CoreLowPass, MAX_AVERAGE_WINDOW,
    MovingAverage as CoreMovingAverage, OnlineCompensator as CoreCompensator,
    PilotControl as CorePilot, SensorCalibration as CoreCalibration,
    project_normal_to_feed as core_project,
};
use deflect_core::identification::{
    self as ident, FrameMeasurement, StiffnessIdentification, TcpMeasurement,
};
use deflect_core::vjm::{Model, Vector6};
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use numpy::ndarray::{Array1, Array2, ArrayView2};
use numpy::{AllowTypeChange, PyArray1, PyArrayLikeDyn, ToPyArray};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::InputError;
use crate::convert::{Arr1, Arr2, finite_vec, iso_to_py, tick_err};
use crate::vjm::SerialRobot;

fn v3(a: &Arr1<'_>, what: &str) -> PyResult<Vector3<f64>> {
    Ok(Vector3::from_column_slice(&finite_vec(a, what, 3)?))
}

fn v6(a: &Arr1<'_>, what: &str) -> PyResult<Vector6> {
    Ok(Vector6::from_column_slice(&finite_vec(a, what, 6)?))
}

fn mat3(m: ArrayView2<'_, f64>, what: &str) -> PyResult<Matrix3<f64>> {
    if m.shape() != [3, 3] || m.iter().any(|x| !x.is_finite()) {
        return Err(InputError::new_err(format!(
            "{what}: expected a finite (3, 3) rotation matrix, got shape {:?}",
            m.shape()
        )));
    }
    Ok(Matrix3::from_fn(|i, j| m[(i, j)]))
}

fn rotation(m: ArrayView2<'_, f64>, what: &str) -> PyResult<UnitQuaternion<f64>> {
    let r = mat3(m, what)?;
    if (r.transpose() * r - Matrix3::identity()).norm() > 1e-6 {
        return Err(InputError::new_err(format!(
            "{what}: not a rotation matrix"
        )));
    }
    Ok(UnitQuaternion::from_rotation_matrix(
        &Rotation3::from_matrix_unchecked(r),
    ))
}

fn pose(m: ArrayView2<'_, f64>, what: &str) -> PyResult<Isometry3<f64>> {
    if m.shape() != [4, 4] {
        return Err(InputError::new_err(format!(
            "{what}: expected shape (4, 4), got {:?}",
            m.shape()
        )));
    }
    let r = rotation(m.slice(numpy::ndarray::s![0..3, 0..3]), what)?;
    let t = Translation3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
    if !t.vector.iter().all(|x| x.is_finite()) {
        return Err(InputError::new_err(format!("{what}: not finite")));
    }
    Ok(Isometry3::from_parts(t, r))
}

fn out6<'py>(py: Python<'py>, v: &Vector6) -> Bound<'py, PyArray1<f64>> {
    v.as_slice().to_pyarray(py)
}

/// Force/torque sensor calibration (Eq. 12-20): offsets [N, N m] and weight [N] in the
/// sensor frame, centre of gravity [m], residual polynomial (6, 15) and the TCP pose in the
/// sensor frame (4, 4).
#[pyclass(module = "deflect", frozen)]
#[derive(Debug, Clone)]
pub struct SensorCalibration {
    pub(crate) inner: CoreCalibration,
}

#[pymethods]
impl SensorCalibration {
    #[new]
    #[pyo3(signature = (force_offset=None, moment_offset=None, weight=0.0, center_of_gravity=None, residual=None, sensor_to_tcp=None))]
    fn new(
        force_offset: Option<Arr1<'_>>,
        moment_offset: Option<Arr1<'_>>,
        weight: f64,
        center_of_gravity: Option<Arr1<'_>>,
        residual: Option<Arr2<'_>>,
        sensor_to_tcp: Option<Arr2<'_>>,
    ) -> PyResult<Self> {
        let mut c = CoreCalibration::default();
        if let Some(a) = force_offset {
            c.force_offset = v3(&a, "force_offset")?;
        }
        if let Some(a) = moment_offset {
            c.moment_offset = v3(&a, "moment_offset")?;
        }
        if !weight.is_finite() {
            return Err(InputError::new_err("weight: not finite"));
        }
        c.weight = weight;
        if let Some(a) = center_of_gravity {
            c.center_of_gravity = v3(&a, "center_of_gravity")?;
        }
        if let Some(a) = residual {
            let r = a.as_array();
            if r.shape() != [6, POLY_TERMS] || r.iter().any(|x| !x.is_finite()) {
                return Err(InputError::new_err(format!(
                    "residual: expected finite shape (6, {POLY_TERMS}), got {:?}",
                    r.shape()
                )));
            }
            for (i, row) in c.residual.iter_mut().enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    *v = r[(i, j)];
                }
            }
        }
        if let Some(a) = sensor_to_tcp {
            c.sensor_to_tcp = pose(a.as_array(), "sensor_to_tcp")?;
        }
        Ok(Self { inner: c })
    }

    #[getter]
    fn force_offset<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.force_offset.as_slice().to_pyarray(py)
    }
    #[getter]
    fn moment_offset<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.moment_offset.as_slice().to_pyarray(py)
    }
    #[getter]
    fn weight(&self) -> f64 {
        self.inner.weight
    }
    #[getter]
    fn center_of_gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.center_of_gravity.as_slice().to_pyarray(py)
    }
    #[getter]
    fn residual<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        Array2::from_shape_fn((6, POLY_TERMS), |(i, j)| self.inner.residual[i][j]).to_pyarray(py)
    }
    #[getter]
    fn sensor_to_tcp<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        iso_to_py(py, &self.inner.sensor_to_tcp)
    }

    /// What the unloaded sensor reads at orientation `rotation` (3, 3) (base from sensor).
    fn unloaded_reading<'py>(
        &self,
        py: Python<'py>,
        rotation: Arr2<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let r = self::rotation(rotation.as_array(), "rotation")?;
        Ok(out6(py, &self.inner.unloaded_reading(&r)))
    }

    /// Eq. 18: external wrench on the sensor (sensor frame) from a raw reading.
    fn compensate<'py>(
        &self,
        py: Python<'py>,
        reading: Arr1<'py>,
        rotation: Arr2<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let r = self::rotation(rotation.as_array(), "rotation")?;
        Ok(out6(
            py,
            &self.inner.compensate(&v6(&reading, "reading")?, &r),
        ))
    }

    /// Eq. 19-20: a sensor-frame wrench as the wrench about the TCP in the TCP frame.
    fn to_tcp_frame<'py>(
        &self,
        py: Python<'py>,
        wrench: Arr1<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(out6(py, &self.inner.to_tcp_frame(&v6(&wrench, "wrench")?)))
    }

    /// Raw reading -> compensated TCP wrench in the base frame, given the TCP pose (4, 4).
    fn tcp_wrench_base<'py>(
        &self,
        py: Python<'py>,
        reading: Arr1<'py>,
        tcp: Arr2<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = pose(tcp.as_array(), "tcp")?;
        Ok(out6(
            py,
            &self.inner.tcp_wrench_base(&v6(&reading, "reading")?, &t),
        ))
    }
}

/// First-order low-pass on wrenches (6,), cut-off [Hz], sample time [s].
#[pyclass(module = "deflect")]
#[derive(Debug)]
pub struct LowPass {
    inner: CoreLowPass,
}

#[pymethods]
impl LowPass {
    #[new]
    fn new(cutoff_hz: f64, dt: f64) -> PyResult<Self> {
        CoreLowPass::new(cutoff_hz, dt)
            .map(|inner| Self { inner })
            .ok_or_else(|| InputError::new_err("LowPass: cutoff_hz and dt must be finite and > 0"))
    }
    fn step<'py>(&mut self, py: Python<'py>, x: Arr1<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(out6(py, &self.inner.step(&v6(&x, "x")?)))
    }
    #[getter]
    fn alpha(&self) -> f64 {
        self.inner.alpha()
    }
    #[getter]
    fn delay_samples(&self) -> f64 {
        self.inner.delay_samples()
    }
    #[getter]
    fn delay_seconds(&self) -> f64 {
        self.inner.delay_seconds()
    }
    fn reset(&mut self) {
        self.inner.reset()
    }
}

/// Moving average of the last `window` wrenches (window <= 64).
#[pyclass(module = "deflect")]
#[derive(Debug)]
pub struct MovingAverage {
    inner: CoreMovingAverage<MAX_AVERAGE_WINDOW>,
}

#[pymethods]
impl MovingAverage {
    #[new]
    fn new(window: usize, dt: f64) -> PyResult<Self> {
        CoreMovingAverage::new(window, dt)
            .map(|inner| Self { inner })
            .ok_or_else(|| {
                InputError::new_err(format!(
                    "MovingAverage: window must be 1..={MAX_AVERAGE_WINDOW} and dt finite > 0"
                ))
            })
    }
    fn step<'py>(&mut self, py: Python<'py>, x: Arr1<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(out6(py, &self.inner.step(&v6(&x, "x")?)))
    }
    #[getter]
    fn delay_samples(&self) -> f64 {
        self.inner.delay_samples()
    }
    #[getter]
    fn delay_seconds(&self) -> f64 {
        self.inner.delay_seconds()
    }
    fn reset(&mut self) {
        self.inner.reset()
    }
}

/// Force pilot control (section 2.3): threshold [N], ramp [s], cycle time [s].
#[pyclass(module = "deflect")]
#[derive(Debug)]
pub struct PilotControl {
    inner: CorePilot,
}

#[pymethods]
impl PilotControl {
    #[new]
    #[pyo3(signature = (threshold=150.0, ramp=0.08, dt=0.004))]
    fn new(threshold: f64, ramp: f64, dt: f64) -> PyResult<Self> {
        CorePilot::new(threshold, ramp, dt)
            .map(|inner| Self { inner })
            .ok_or_else(|| InputError::new_err("PilotControl: threshold, ramp >= 0 and dt > 0"))
    }
    /// Blend of `measured` and `estimated` wrenches (6,) for this cycle.
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        measured: Arr1<'py>,
        estimated: Arr1<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (m, e) = (v6(&measured, "measured")?, v6(&estimated, "estimated")?);
        Ok(out6(py, &self.inner.step(&m, &e)))
    }
    #[getter]
    fn weight(&self) -> f64 {
        self.inner.weight()
    }
    fn reset(&mut self) {
        self.inner.reset()
    }
}

/// Eq. 10-11: `(r_v, projected)`; `r` returned unchanged with `False` at zero feed.
#[pyfunction]
fn project_normal_to_feed<'py>(
    py: Python<'py>,
    r: Arr1<'py>,
    v: Arr1<'py>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, bool)> {
    let (rv, ok) = core_project(&v3(&r, "r")?, &v3(&v, "v")?);
    Ok((rv.as_slice().to_pyarray(py), ok))
}

/// The online compensation chain for a `SerialRobot`.
#[pyclass(module = "deflect")]
#[derive(Debug)]
pub struct OnlineCompensator {
    model: Model,
    inner: CoreCompensator,
}

#[pymethods]
impl OnlineCompensator {
    #[new]
    #[pyo3(signature = (robot, dt=0.004, calibration=None, lowpass_cutoff_hz=10.0, moving_average_window=5, pilot=Some((150.0, 0.08)), project_on_feed=true, max_correction=3.0e-3, max_rate=0.05, output="cartesian"))]
    #[allow(clippy::too_many_arguments)] // reason: mirrors the Python keyword arguments
    fn new(
        robot: &SerialRobot,
        dt: f64,
        calibration: Option<&SensorCalibration>,
        lowpass_cutoff_hz: f64,
        moving_average_window: usize,
        pilot: Option<(f64, f64)>,
        project_on_feed: bool,
        max_correction: f64,
        max_rate: f64,
        output: &str,
    ) -> PyResult<Self> {
        let output = match output {
            "cartesian" => CorrectionOutput::Cartesian,
            "joint" => CorrectionOutput::Joint,
            other => {
                return Err(InputError::new_err(format!(
                    "output: expected 'cartesian' or 'joint', got '{other}'"
                )));
            }
        };
        let config = CompensatorConfig {
            dt,
            calibration: calibration.map(|c| c.inner).unwrap_or_default(),
            lowpass_cutoff_hz,
            moving_average_window,
            pilot,
            project_on_feed,
            max_correction,
            max_rate,
            output,
        };
        let model = robot.inner.model.clone();
        let inner =
            CoreCompensator::new(&model, config).map_err(|e| InputError::new_err(e.to_string()))?;
        Ok(Self { model, inner })
    }

    /// Delay of the filter chain [cycles].
    #[getter]
    fn delay_samples(&self) -> f64 {
        self.inner.delay_samples()
    }
    /// Delay of the filter chain [s].
    #[getter]
    fn delay_seconds(&self) -> f64 {
        self.inner.delay_seconds()
    }

    /// One control cycle -> dict with `wrench`, `measured_wrench`, `deflection`,
    /// `correction`, `dq`, `pilot_weight`, `projected`, `size_limited`, `rate_limited`.
    #[pyo3(signature = (q, reading, estimated=None, feed_velocity=None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        q: Arr1<'py>,
        reading: Arr1<'py>,
        estimated: Option<Arr1<'py>>,
        feed_velocity: Option<Arr1<'py>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let q = finite_vec(&q, "q", self.model.dof())?;
        let reading = v6(&reading, "reading")?;
        let est = estimated.map(|e| v6(&e, "estimated")).transpose()?;
        let feed = feed_velocity
            .map(|v| v3(&v, "feed_velocity"))
            .transpose()?
            .unwrap_or_else(Vector3::zeros);
        let o = self
            .inner
            .step(&self.model, &q, &reading, est.as_ref(), &feed)
            .map_err(tick_err)?;
        let d = PyDict::new(py);
        d.set_item("wrench", out6(py, &o.wrench))?;
        d.set_item("measured_wrench", out6(py, &o.measured_wrench))?;
        d.set_item("deflection", out6(py, &o.deflection))?;
        d.set_item("correction", out6(py, &o.correction))?;
        d.set_item(
            "dq",
            o.dq.get(..self.model.dof()).unwrap_or(&[]).to_pyarray(py),
        )?;
        d.set_item("pilot_weight", o.pilot_weight)?;
        d.set_item("projected", o.projected)?;
        d.set_item("size_limited", o.size_limited)?;
        d.set_item("rate_limited", o.rate_limited)?;
        Ok(d)
    }

    fn reset(&mut self) {
        self.inner.reset()
    }
}

fn id_err(e: ident::IdentificationError) -> PyErr {
    InputError::new_err(e.to_string())
}

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

fn rows(a: &Arr2<'_>, what: &str, cols: usize, n: Option<usize>) -> PyResult<Array2<f64>> {
    let v = a.as_array();
    if v.ncols() != cols || n.is_some_and(|n| v.nrows() != n) {
        return Err(InputError::new_err(format!(
            "{what}: expected shape ({}, {cols}), got {:?}",
            n.map_or("N".to_string(), |n| n.to_string()),
            v.shape()
        )));
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(InputError::new_err(format!(
            "{what}: row {} is not finite",
            i / cols
        )));
    }
    Ok(v.to_owned())
}

/// Stiffness identification from TCP deflections: `Q` (N, dof), `W` (N, 6), `D` (N, 6) ->
/// dict of per-axis `spring`, `axis`, `compliance` (NaN if unobservable), `stiffness`,
/// `std_error`, `identifiable`, and `rank`.
#[pyfunction]
#[pyo3(signature = (robot, Q, W, D, translation_only=false, all_axes=false))]
#[allow(non_snake_case)] // reason: matrix names as in the documented Python signature
fn identify_stiffness_from_tcp<'py>(
    py: Python<'py>,
    robot: &SerialRobot,
    Q: Arr2<'py>,
    W: Arr2<'py>,
    D: Arr2<'py>,
    translation_only: bool,
    all_axes: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let model = &robot.inner.model;
    let q = rows(&Q, "Q", model.dof(), None)?;
    let n = q.nrows();
    let (w, d) = (rows(&W, "W", 6, Some(n))?, rows(&D, "D", 6, Some(n))?);
    let qs: Vec<Vec<f64>> = q.rows().into_iter().map(|r| r.to_vec()).collect();
    let meas: Vec<TcpMeasurement> = (0..n)
        .map(|i| TcpMeasurement {
            q: &qs[i],
            wrench: Vector6::from_iterator(w.row(i).iter().copied()),
            deflection: Vector6::from_iterator(d.row(i).iter().copied()),
            translation_only,
        })
        .collect();
    let id = py
        .detach(|| ident::identify_from_tcp(model, &meas, all_axes))
        .map_err(id_err)?;
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
    Q: Arr2<'py>,
    W: Arr2<'py>,
    springs: Vec<usize>,
    rotations: Arr2<'py>,
    all_axes: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let model = &robot.inner.model;
    let q = rows(&Q, "Q", model.dof(), None)?;
    let n = q.nrows();
    let (w, r) = (
        rows(&W, "W", 6, Some(n))?,
        rows(&rotations, "rotations", 3, Some(n))?,
    );
    if springs.len() != n {
        return Err(InputError::new_err(format!(
            "springs: expected {n} entries, got {}",
            springs.len()
        )));
    }
    let qs: Vec<Vec<f64>> = q.rows().into_iter().map(|r| r.to_vec()).collect();
    let meas: Vec<FrameMeasurement> = (0..n)
        .map(|i| FrameMeasurement {
            q: &qs[i],
            wrench: Vector6::from_iterator(w.row(i).iter().copied()),
            spring: springs[i],
            rotation: Vector3::from_iterator(r.row(i).iter().copied()),
        })
        .collect();
    let id = py
        .detach(|| ident::identify_from_frames(model, &meas, all_axes))
        .map_err(id_err)?;
    stiffness_dict(py, &id)
}

/// Sensor offsets, weight, centre of gravity (Eq. 12-15) and optionally the residual
/// polynomial (Eq. 16-17) from unloaded `readings` (N, 6) at sensor `rotations` (N, 3, 3).
/// Returns `(SensorCalibration, info dict)`.
#[pyfunction]
#[pyo3(signature = (rotations, readings, fit_polynomial=false, sensor_to_tcp=None))]
fn identify_sensor<'py>(
    py: Python<'py>,
    rotations: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
    readings: Arr2<'py>,
    fit_polynomial: bool,
    sensor_to_tcp: Option<Arr2<'py>>,
) -> PyResult<(SensorCalibration, Bound<'py, PyDict>)> {
    let r = rotations.as_array();
    if r.ndim() != 3 || r.shape()[1..] != [3, 3] {
        return Err(InputError::new_err(format!(
            "rotations: expected shape (N, 3, 3), got {:?}",
            r.shape()
        )));
    }
    let n = r.shape()[0];
    let w = rows(&readings, "readings", 6, Some(n))?;
    let mut quats = Vec::with_capacity(n);
    for i in 0..n {
        let m = r.index_axis(numpy::ndarray::Axis(0), i);
        let m2 = m
            .into_dimensionality::<numpy::ndarray::Ix2>()
            .map_err(|e| InputError::new_err(e.to_string()))?;
        quats.push(rotation(m2, &format!("rotations[{i}]"))?);
    }
    let ws: Vec<Vector6> = (0..n)
        .map(|i| Vector6::from_iterator(w.row(i).iter().copied()))
        .collect();
    let s2t = match sensor_to_tcp {
        Some(a) => pose(a.as_array(), "sensor_to_tcp")?,
        None => Isometry3::identity(),
    };
    let id = ident::identify_sensor(&quats, &ws, fit_polynomial, s2t).map_err(id_err)?;
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
    m.add_class::<SensorCalibration>()?;
    m.add_class::<LowPass>()?;
    m.add_class::<MovingAverage>()?;
    m.add_class::<PilotControl>()?;
    m.add_class::<OnlineCompensator>()?;
    m.add_function(wrap_pyfunction!(project_normal_to_feed, m)?)?;
    m.add_function(wrap_pyfunction!(identify_stiffness_from_tcp, m)?)?;
    m.add_function(wrap_pyfunction!(identify_stiffness_from_frames, m)?)?;
    m.add_function(wrap_pyfunction!(identify_sensor, m)?)?;
    Ok(())
}
