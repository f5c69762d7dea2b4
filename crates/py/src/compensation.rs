//! Online compensation chain (VJM paper, sections 2.2-2.6): `deflect.SensorCalibration`,
//! `LowPass`, `MovingAverage`, `PilotControl`, `project_normal_to_feed`, `OnlineCompensator`.

use deflect_core::compensation::sensor::POLY_TERMS;
use deflect_core::compensation::{
    self, CompensatorConfig, CorrectionOutput, LowPass as CoreLowPass, MAX_AVERAGE_WINDOW,
    MovingAverage as CoreMovingAverage, PilotControl as CorePilot,
    SensorCalibration as CoreCalibration, project_normal_to_feed as core_project,
};
use deflect_core::vjm::Vector6;
use nalgebra::Vector3;
use numpy::ndarray::Array2;
use numpy::{PyArray1, ToPyArray};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::InputError;
use crate::args;
use crate::arrays::{iso_to_py, matrix, pose, rotation, vector};
use crate::errors::{build_err, tick_err};
use crate::vjm::SerialRobot;

pub(crate) fn v3(a: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector3<f64>> {
    Ok(Vector3::from_column_slice(&vector(a, what, 3)?))
}

pub(crate) fn v6(a: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector6> {
    Ok(Vector6::from_column_slice(&vector(a, what, 6)?))
}

pub(crate) fn out6<'py>(py: Python<'py>, v: &Vector6) -> Bound<'py, PyArray1<f64>> {
    v.as_slice().to_pyarray(py)
}

/// Force/torque sensor calibration (Eq. 12-20): offsets [N, N m] and weight [N] in the
/// sensor frame, centre of gravity [m], residual polynomial (6, 15) and the TCP pose in the
/// sensor frame (4, 4), a rigid transform. Validated as the C API does: finite values,
/// weight >= 0, a proper rotation (`InputError` otherwise).
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
        force_offset: Option<&Bound<'_, PyAny>>,
        moment_offset: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = args::real::weight)] weight: f64,
        center_of_gravity: Option<&Bound<'_, PyAny>>,
        residual: Option<&Bound<'_, PyAny>>,
        sensor_to_tcp: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let mut c = CoreCalibration::default();
        if let Some(a) = force_offset {
            c.force_offset = v3(a, "force_offset")?;
        }
        if let Some(a) = moment_offset {
            c.moment_offset = v3(a, "moment_offset")?;
        }
        c.weight = weight;
        if let Some(a) = center_of_gravity {
            c.center_of_gravity = v3(a, "center_of_gravity")?;
        }
        if let Some(a) = residual {
            let r = matrix(a, "residual", Some(6), Some(POLY_TERMS))?;
            let r = r.as_array();
            for (row, src) in c.residual.iter_mut().zip(r.rows()) {
                for (v, x) in row.iter_mut().zip(src.iter()) {
                    *v = *x;
                }
            }
        }
        if let Some(a) = sensor_to_tcp {
            c.sensor_to_tcp = pose(a, "sensor_to_tcp")?;
        }
        c.validate().map_err(build_err)?;
        Ok(Self { inner: c })
    }

    /// Pickling and `copy.deepcopy`: every number of the calibration (the TCP pose as
    /// translation and unit quaternion), an exact round trip validated again on the way back.
    #[allow(clippy::type_complexity)] // reason: the pickle protocol's (callable, args) pair
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (crate::pickle::CalibrationState,))> {
        let rebuild = slf.get_type().getattr("_from_state")?;
        Ok((
            rebuild,
            (crate::pickle::calibration_state(&slf.get().inner),),
        ))
    }

    /// The calibration of a pickled state (see `__reduce__`).
    #[staticmethod]
    fn _from_state(state: crate::pickle::CalibrationState) -> PyResult<Self> {
        Ok(Self {
            inner: crate::pickle::calibration_of(state)?,
        })
    }

    /// Internal force offset `F_SI` (3,) [N], sensor frame (Eq. 12).
    #[getter]
    fn force_offset<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.force_offset.as_slice().to_pyarray(py)
    }
    /// Internal moment offset `M_SI` (3,) [N m], sensor frame (Eq. 12).
    #[getter]
    fn moment_offset<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.moment_offset.as_slice().to_pyarray(py)
    }
    /// Weight of everything beyond the sensor `G` [N] (gravity along -z of the base).
    #[getter]
    fn weight(&self) -> f64 {
        self.inner.weight
    }
    /// Centre of gravity `r_G` (3,) [m], sensor frame (Eq. 13).
    #[getter]
    fn center_of_gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.center_of_gravity.as_slice().to_pyarray(py)
    }
    /// Residual-offset polynomial coefficients (6, 15), one row per wrench component (Eq. 17).
    #[getter]
    fn residual<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        let flat: Vec<f64> = self.inner.residual.iter().flatten().copied().collect();
        Array2::from_shape_vec((6, POLY_TERMS), flat)
            .unwrap_or_else(|_| Array2::zeros((6, POLY_TERMS)))
            .to_pyarray(py)
    }
    /// Pose of the TCP in the sensor frame `^S T_TCP`, (4, 4).
    #[getter]
    fn sensor_to_tcp<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        iso_to_py(py, &self.inner.sensor_to_tcp)
    }

    /// What the unloaded sensor reads at orientation `rotation` (3, 3) (base from sensor).
    fn unloaded_reading<'py>(
        &self,
        py: Python<'py>,
        rotation: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let r = self::rotation(rotation, "rotation")?;
        Ok(out6(py, &self.inner.unloaded_reading(&r)))
    }

    /// Eq. 18: external wrench on the sensor (sensor frame) from a raw reading.
    fn compensate<'py>(
        &self,
        py: Python<'py>,
        reading: &Bound<'py, PyAny>,
        rotation: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let r = self::rotation(rotation, "rotation")?;
        Ok(out6(
            py,
            &self.inner.compensate(&v6(reading, "reading")?, &r),
        ))
    }

    /// Eq. 19-20: a sensor-frame wrench as the wrench about the TCP in the TCP frame.
    fn to_tcp_frame<'py>(
        &self,
        py: Python<'py>,
        wrench: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(out6(py, &self.inner.to_tcp_frame(&v6(wrench, "wrench")?)))
    }

    /// Raw reading -> compensated TCP wrench in the base frame, given the TCP pose (4, 4).
    fn tcp_wrench_base<'py>(
        &self,
        py: Python<'py>,
        reading: &Bound<'py, PyAny>,
        tcp: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = pose(tcp, "tcp")?;
        Ok(out6(
            py,
            &self.inner.tcp_wrench_base(&v6(reading, "reading")?, &t),
        ))
    }
}

/// First-order low-pass on wrenches (6,), cut-off [Hz], sample time [s].
#[pyclass(module = "deflect")]
#[derive(Debug, Clone)]
pub struct LowPass {
    inner: CoreLowPass,
}

#[pymethods]
impl LowPass {
    /// Refused: a `LowPass` carries its filter state from tick to tick, which a copy in another
    /// process could not continue; send its arguments and build one there. `copy.deepcopy`
    /// copies the state exactly, within this process.
    fn __reduce__(&self) -> PyResult<()> {
        Err(crate::pickle::per_tick_state("LowPass", "its filter state"))
    }
    /// An exact copy, state included.
    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }
    /// An exact copy, state included.
    fn __copy__(&self) -> Self {
        self.clone()
    }
    #[new]
    fn new(
        #[pyo3(from_py_with = args::real::cutoff_hz)] cutoff_hz: f64,
        #[pyo3(from_py_with = args::real::dt)] dt: f64,
    ) -> PyResult<Self> {
        CoreLowPass::new(cutoff_hz, dt)
            .map(|inner| Self { inner })
            .map_err(build_err)
    }
    /// Filters one wrench sample `x` (6,) [N, N m]; returns the filtered wrench (6,).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(out6(py, &self.inner.step(&v6(x, "x")?)))
    }
    /// Smoothing factor of the first-order filter, `dt / (dt + 1 / (2 pi f_c))`.
    #[getter]
    fn alpha(&self) -> f64 {
        self.inner.alpha()
    }
    /// Phase delay at low frequency [samples].
    #[getter]
    fn delay_samples(&self) -> f64 {
        self.inner.delay_samples()
    }
    /// Phase delay at low frequency [s].
    #[getter]
    fn delay_seconds(&self) -> f64 {
        self.inner.delay_seconds()
    }
    /// Forgets the filter state: the next sample starts it afresh.
    fn reset(&mut self) {
        self.inner.reset()
    }
}

/// Moving average of the last `window` wrenches (window <= 64).
#[pyclass(module = "deflect")]
#[derive(Debug, Clone)]
pub struct MovingAverage {
    inner: CoreMovingAverage<MAX_AVERAGE_WINDOW>,
}

#[pymethods]
impl MovingAverage {
    /// Refused: a `MovingAverage` carries its window of samples from tick to tick, which a copy in another
    /// process could not continue; send its arguments and build one there. `copy.deepcopy`
    /// copies the state exactly, within this process.
    fn __reduce__(&self) -> PyResult<()> {
        Err(crate::pickle::per_tick_state(
            "MovingAverage",
            "its window of samples",
        ))
    }
    /// An exact copy, state included.
    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }
    /// An exact copy, state included.
    fn __copy__(&self) -> Self {
        self.clone()
    }
    #[new]
    fn new(
        #[pyo3(from_py_with = args::count::window)] window: usize,
        #[pyo3(from_py_with = args::real::dt)] dt: f64,
    ) -> PyResult<Self> {
        CoreMovingAverage::new(window, dt)
            .map(|inner| Self { inner })
            .map_err(build_err)
    }
    /// Averages one wrench sample `x` (6,) [N, N m] over the window; returns (6,).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(out6(py, &self.inner.step(&v6(x, "x")?)))
    }
    /// Delay of the window, `(window - 1) / 2` [samples].
    #[getter]
    fn delay_samples(&self) -> f64 {
        self.inner.delay_samples()
    }
    /// Delay of the window [s].
    #[getter]
    fn delay_seconds(&self) -> f64 {
        self.inner.delay_seconds()
    }
    /// Empties the window.
    fn reset(&mut self) {
        self.inner.reset()
    }
}

/// Force pilot control (section 2.3): threshold [N], ramp [s], cycle time [s].
#[pyclass(module = "deflect")]
#[derive(Debug, Clone)]
pub struct PilotControl {
    inner: CorePilot,
}

#[pymethods]
impl PilotControl {
    /// Refused: a `PilotControl` carries its blend state from tick to tick, which a copy in another
    /// process could not continue; send its arguments and build one there. `copy.deepcopy`
    /// copies the state exactly, within this process.
    fn __reduce__(&self) -> PyResult<()> {
        Err(crate::pickle::per_tick_state(
            "PilotControl",
            "its blend state",
        ))
    }
    /// An exact copy, state included.
    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }
    /// An exact copy, state included.
    fn __copy__(&self) -> Self {
        self.clone()
    }
    #[new]
    #[pyo3(signature = (threshold=150.0, ramp=0.08, dt=0.004))]
    fn new(
        #[pyo3(from_py_with = args::real::threshold)] threshold: f64,
        #[pyo3(from_py_with = args::real::ramp)] ramp: f64,
        #[pyo3(from_py_with = args::real::dt)] dt: f64,
    ) -> PyResult<Self> {
        CorePilot::new(threshold, ramp, dt)
            .map(|inner| Self { inner })
            .map_err(build_err)
    }
    /// Blend of `measured` and `estimated` wrenches (6,) for this cycle.
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        measured: &Bound<'py, PyAny>,
        estimated: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (m, e) = (v6(measured, "measured")?, v6(estimated, "estimated")?);
        Ok(out6(py, &self.inner.step(&m, &e)))
    }
    /// Current weight of the measured wrench in the blend, 0..1.
    #[getter]
    fn weight(&self) -> f64 {
        self.inner.weight()
    }
    /// Back to the start: the estimate alone, weight 0.
    fn reset(&mut self) {
        self.inner.reset()
    }
}

/// Eq. 10-11: `(r_v, projected)`; `r` returned unchanged with `False` at zero feed.
#[pyfunction]
fn project_normal_to_feed<'py>(
    py: Python<'py>,
    r: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, bool)> {
    let (rv, ok) = core_project(&v3(r, "r")?, &v3(v, "v")?);
    Ok((rv.as_slice().to_pyarray(py), ok))
}

/// The online compensation chain for a `SerialRobot`.
#[pyclass(module = "deflect")]
#[derive(Debug, Clone)]
pub struct OnlineCompensator {
    /// The chain (the robot's, copied in) and the validated settings.
    model: compensation::Model,
    /// Filter, pilot and rate-limiter states.
    data: compensation::Data,
}

#[pymethods]
impl OnlineCompensator {
    /// Refused: a `OnlineCompensator` carries its filter, pilot and rate-limiter states from tick to tick, which a copy in another
    /// process could not continue; send its arguments and build one there. `copy.deepcopy`
    /// copies the state exactly, within this process.
    fn __reduce__(&self) -> PyResult<()> {
        Err(crate::pickle::per_tick_state(
            "OnlineCompensator",
            "its filter, pilot and rate-limiter states",
        ))
    }
    /// An exact copy, state included.
    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }
    /// An exact copy, state included.
    fn __copy__(&self) -> Self {
        self.clone()
    }
    #[new]
    #[pyo3(signature = (robot, dt=0.004, calibration=None, lowpass_cutoff_hz=10.0, moving_average_window=5, pilot=Some((150.0, 0.08)), project_on_feed=true, max_correction=3.0e-3, max_rate=0.05, output="cartesian"),
           text_signature = "(robot, dt=0.004, calibration=None, lowpass_cutoff_hz=10.0, moving_average_window=5, pilot=(150.0, 0.08), project_on_feed=True, max_correction=0.003, max_rate=0.05, output='cartesian')")]
    #[allow(clippy::too_many_arguments)] // reason: mirrors the Python keyword arguments
    fn new(
        robot: &SerialRobot,
        #[pyo3(from_py_with = args::real::dt)] dt: f64,
        calibration: Option<&SensorCalibration>,
        #[pyo3(from_py_with = args::real::lowpass_cutoff_hz)] lowpass_cutoff_hz: f64,
        #[pyo3(from_py_with = args::count::moving_average_window)] moving_average_window: usize,
        #[pyo3(from_py_with = args::opt_pair::pilot)] pilot: Option<(f64, f64)>,
        project_on_feed: bool,
        #[pyo3(from_py_with = args::real::max_correction)] max_correction: f64,
        #[pyo3(from_py_with = args::real::max_rate)] max_rate: f64,
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
        let model =
            compensation::Model::new(robot.inner.model.clone(), config).map_err(build_err)?;
        let data = compensation::Data::new(&model);
        Ok(Self { model, data })
    }

    /// Delay of the filter chain [cycles].
    #[getter]
    fn delay_samples(&self) -> f64 {
        self.model.delay_samples()
    }
    /// Delay of the filter chain [s].
    #[getter]
    fn delay_seconds(&self) -> f64 {
        self.model.delay_seconds()
    }

    /// One control cycle -> dict with `wrench`, `measured_wrench`, `deflection`,
    /// `correction`, `dq`, `pilot_weight`, `projected`, `size_limited`, `rate_limited`.
    #[pyo3(signature = (q, reading, estimated=None, feed_velocity=None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        reading: &Bound<'py, PyAny>,
        estimated: Option<&Bound<'py, PyAny>>,
        feed_velocity: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let dof = self.model.chain().dof();
        let q = vector(q, "q", dof)?;
        let reading = v6(reading, "reading")?;
        let est = estimated.map(|e| v6(e, "estimated")).transpose()?;
        let feed = feed_velocity
            .map(|v| v3(v, "feed_velocity"))
            .transpose()?
            .unwrap_or_else(Vector3::zeros);
        let o = compensation::step(
            &self.model,
            &mut self.data,
            &q,
            &reading,
            est.as_ref(),
            &feed,
        )
        .map_err(tick_err)?;
        let d = PyDict::new(py);
        d.set_item("wrench", out6(py, &o.wrench))?;
        d.set_item("measured_wrench", out6(py, &o.measured_wrench))?;
        d.set_item("deflection", out6(py, &o.deflection))?;
        d.set_item("correction", out6(py, &o.correction))?;
        d.set_item("dq", o.dq.get(..dof).unwrap_or(&[]).to_pyarray(py))?;
        d.set_item("pilot_weight", o.pilot_weight)?;
        d.set_item("projected", o.projected)?;
        d.set_item("size_limited", o.size_limited)?;
        d.set_item("rate_limited", o.rate_limited)?;
        Ok(d)
    }

    /// Forgets the filter, pilot and rate-limiter states (a new process step).
    fn reset(&mut self) {
        self.data.reset()
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<SensorCalibration>()?;
    m.add_class::<LowPass>()?;
    m.add_class::<MovingAverage>()?;
    m.add_class::<PilotControl>()?;
    m.add_class::<OnlineCompensator>()?;
    m.add_function(wrap_pyfunction!(project_normal_to_feed, m)?)?;
    Ok(())
}
