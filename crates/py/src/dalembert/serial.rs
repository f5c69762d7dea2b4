//! `deflect.SerialDalembertCorrector`: the 6-D D'Alembert corrector of deflect-core for any
//! serial arm loaded from URDF and a stiffness file.

use std::sync::{Mutex, MutexGuard, PoisonError};

use deflect_core::dalembert::serial::{self, Payload};
use deflect_core::mechanism::pose_ik::{PoseIkOptions, Task, largest_task};
use deflect_core::motion::PoseState;
use deflect_core::vjm::Deflection;
use deflect_core::vjm::Vector6;
use nalgebra::{Matrix3, Vector3};
use numpy::ndarray::{Array2, Ix1, Ix2, Ix3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyUntypedArrayMethods, ToPyArray};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::InputError;
use crate::args;
use crate::arrays::{
    fixed_matrix, float_array, iso_to_py, matrix, put_pose, try_array, try_copy, vector, vector6,
};
use crate::errors::{build_err, tick_err, tick_err_at};
use crate::pose_motion::{PoseTrajectory, pose_ticks};
use crate::vjm::SerialRobot;

/// The Python name of a deflection model.
fn model_name(d: Deflection) -> &'static str {
    match d {
        Deflection::Exact => "exact",
        Deflection::Linearized => "linearized",
    }
}

/// A payload of `mass` \[kg\], centre of mass `com` (3,) \[m\] (default the TCP) and inertia
/// about it (3, 3) \[kg m^2\] (default zero), TCP frame; checked by the core where it is used.
pub(crate) fn payload(
    mass: f64,
    com: Option<&Bound<'_, PyAny>>,
    inertia: Option<&Bound<'_, PyAny>>,
) -> PyResult<Payload> {
    Ok(Payload {
        mass,
        com: vec3(com, "com")?,
        inertia: match inertia {
            None => Matrix3::zeros(),
            Some(i) => fixed_matrix::<3, 3>(i, "inertia")?,
        },
    })
}

fn vec3(o: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Vector3<f64>> {
    match o {
        None => Ok(Vector3::zeros()),
        Some(o) => Ok(Vector3::from_column_slice(&vector(o, what, 3)?)),
    }
}

/// The D'Alembert corrector for a serial arm (any `SerialRobot` with at least 6 joints), in
/// 6-D: per tick, the inertial wrench of the payload and tool (`F = -m a_c`,
/// `M = r x F - (I alpha + omega x I omega)`, Paksoy, Dede and Kiper 2025, Eq. 3-5, with the
/// moment part) plus an optional process wrench goes through the virtual-joint deflection
/// (`model="exact"`: Hähn and Weigold 2020, Eq. 2-9; `"linearized"`: `C(q) w`), and a
/// damped-least-squares pose IK of the loaded arm, warm-started from the last ticks, gives
/// the joints at which the deflected TCP lands on the desired pose. For the paper's
/// five-bar and a compliance map, use `DalembertCorrector`.
///
/// `mass` [kg], `com` (3,) [m] and `inertia` (3, 3) [kg m^2] about the centre of mass, both
/// in the TCP frame (default: a point mass at the TCP); `joint_limits` (dof, 2) [rad or m]
/// (default: the robot's URDF limits; a command outside them is an `InputError`);
/// `max_iterations` (1..=256), `position_tolerance` [m] and `orientation_tolerance` [rad]
/// of the IK (`ConvergenceError` when missed); `seed` (dof,): the joints the motion starts
/// from (default zeros; the first tick solves from there). `link_inertia=True` also
/// cancels the links' own inertial loads (`-m a_c`, `-(I alpha + omega x I omega)` of every
/// URDF `<inertial>`, from the joint rates of the motion; default off, as in the paper);
/// `gravity` (3,) [m/s^2], base frame (default zero): the weights then load the springs too,
/// so the command also cancels the static sag. `task`: what the corrector makes the loaded
/// TCP reach: `"pose"` (6 or more joints), `"position_and_axis"` (the spin about the TCP's z
/// free), `"position_and_spin"` (a SCARA), `"position"`, or `"auto"` (default: with a `seed`,
/// the largest of these the arm controls there, non-singular; without, the pose with 6 or
/// more joints, position and axis with 5, position with 3 or 4); the rotation left about the
/// free axes is reported per tick (`free_rotation` [rad]).
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct SerialDalembertCorrector {
    model: serial::Model,
    /// The tick state (the last joints, the next IK seed), locked per call.
    data: Mutex<serial::Data>,
    joint_names: Vec<String>,
    /// The constructor's arguments, as validated, for pickling.
    config: Py<pyo3::types::PyTuple>,
}

impl SerialDalembertCorrector {
    fn data(&self) -> MutexGuard<'_, serial::Data> {
        // A poisoned lock only means another call failed mid-tick; the data stays valid.
        self.data.lock().unwrap_or_else(PoisonError::into_inner)
    }
    fn dof(&self) -> usize {
        self.model.chain().dof()
    }
}

/// Result of `SerialDalembertCorrector.correct`: one row per tick, base frame.
#[pyclass(module = "deflect", frozen, get_all)]
#[derive(Debug)]
pub struct CorrectedPoses {
    /// Tick times [s], (N,).
    t: Py<PyArray1<f64>>,
    /// Desired TCP poses, (N, 4, 4).
    desired: Py<PyArray3<f64>>,
    /// Commanded (rigid) TCP poses, (N, 4, 4): where the joints put the unloaded TCP.
    commanded: Py<PyArray3<f64>>,
    /// Joint commands [rad or m], (N, dof).
    joints: Py<PyArray2<f64>>,
    /// Wrench cancelled (D'Alembert plus process) [N, N m], (N, 6).
    wrench: Py<PyArray2<f64>>,
    /// Predicted TCP deflection at the command [m, rad], (N, 6).
    deflection: Py<PyArray2<f64>>,
    /// IK iterations per tick, (N,).
    iterations: Py<PyArray1<u32>>,
    /// Position error left per tick [m], (N,).
    position_error: Py<PyArray1<f64>>,
    /// Orientation error left per tick in the controlled rotations [rad], (N,).
    orientation_error: Py<PyArray1<f64>>,
    /// Rotation left about the axes the task leaves free [rad], (N,) (0 for the pose).
    free_rotation: Py<PyArray1<f64>>,
}

fn tick_dict<'py>(py: Python<'py>, t: &serial::Tick, dof: usize) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("desired", iso_to_py(py, &t.desired))?;
    d.set_item("commanded", iso_to_py(py, &t.commanded))?;
    d.set_item("joints", t.joints.get(..dof).unwrap_or(&[]).to_pyarray(py))?;
    d.set_item("wrench", t.load.as_slice().to_pyarray(py))?;
    d.set_item("deflection", t.displacement.as_slice().to_pyarray(py))?;
    d.set_item("iterations", t.iterations)?;
    d.set_item("position_error", t.diagnostics.position_error)?;
    d.set_item("orientation_error", t.diagnostics.orientation_error)?;
    d.set_item("sigma_min", t.diagnostics.sigma_min)?;
    d.set_item("free_rotation", t.diagnostics.free_rotation)?;
    Ok(d)
}

/// The deflection model named `model` (`'exact'` or `'linearized'`).
fn deflection_model(model: &str) -> PyResult<Deflection> {
    match model {
        "exact" => Ok(Deflection::Exact),
        "linearized" => Ok(Deflection::Linearized),
        other => Err(InputError::new_err(format!(
            "model = '{other}': expected 'exact' or 'linearized'"
        ))),
    }
}

/// `joint_limits=`: a (dof, 2) array of (lower, upper) \[rad or m\], else the robot's.
fn joint_limits_arg(
    joint_limits: Option<&Bound<'_, PyAny>>,
    robot_limits: &[(f64, f64)],
    dof: usize,
) -> PyResult<Vec<(f64, f64)>> {
    Ok(match joint_limits {
        None => robot_limits.to_vec(),
        Some(l) => {
            let m = matrix(l, "joint_limits", Some(dof), Some(2))?;
            m.as_array()
                .rows()
                .into_iter()
                .map(|r| {
                    let at = |k: usize| r.get(k).copied().unwrap_or(f64::NAN);
                    (at(0), at(1))
                })
                .collect()
        }
    })
}

/// `seed=`: the IK's start joints \[rad or m\], `dof` finite values, if given.
fn seed_arg(seed: Option<&Bound<'_, PyAny>>, dof: usize) -> PyResult<Option<Vec<f64>>> {
    Ok(match seed {
        Some(s) => {
            let q = vector(s, "seed", dof)?;
            if let Some(i) = q.iter().position(|v| !v.is_finite()) {
                return Err(InputError::new_err(format!("seed[{i}] is not finite")));
            }
            Some(q)
        }
        None => None,
    })
}

/// `task=`: the IK's task by name; `'auto'` the largest the arm has at the seed (else by
/// its joint count).
fn task_arg(task: &str, seed: Option<&[f64]>, chain: &deflect_core::vjm::Model) -> PyResult<Task> {
    let dof = chain.dof();
    Ok(match (task, seed) {
        ("auto", Some(q)) => largest_task(chain, &mut deflect_core::vjm::Data::new(chain), q)
            .map_err(|e| tick_err_at(format_args!("task='auto' at the seed"), e))?,
        ("auto", None) => Task::for_dof(dof),
        (task, _) => match task {
            "pose" => Task::POSE,
            "position_and_axis" => Task::POSITION_AND_AXIS,
            "position_and_spin" => Task::POSITION_AND_SPIN,
            "position" => Task::POSITION,
            other => {
                return Err(InputError::new_err(format!(
                    "task = '{other}': expected 'auto', 'pose', 'position_and_axis', \
                     'position_and_spin' or 'position'"
                )));
            }
        },
    })
}

#[pymethods]
impl SerialDalembertCorrector {
    #[new]
    #[pyo3(signature = (robot, mass, com=None, inertia=None, model="exact", joint_limits=None, max_iterations=20, position_tolerance=1e-8, orientation_tolerance=1e-8, seed=None, link_inertia=false, gravity=None, task="auto"))]
    #[allow(clippy::too_many_arguments)] // reason: the documented Python keyword arguments
    fn new(
        robot: &Bound<'_, SerialRobot>,
        #[pyo3(from_py_with = args::real::mass)] mass: f64,
        com: Option<&Bound<'_, PyAny>>,
        inertia: Option<&Bound<'_, PyAny>>,
        model: &str,
        joint_limits: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = args::count::max_iterations)] max_iterations: usize,
        #[pyo3(from_py_with = args::real::position_tolerance)] position_tolerance: f64,
        #[pyo3(from_py_with = args::real::orientation_tolerance)] orientation_tolerance: f64,
        seed: Option<&Bound<'_, PyAny>>,
        link_inertia: bool,
        gravity: Option<&Bound<'_, PyAny>>,
        task: &str,
    ) -> PyResult<Self> {
        let handle = robot;
        let robot = robot.get();
        let chain = robot.inner.model.clone();
        let dof = chain.dof();
        let payload = payload(mass, com, inertia)?;
        let deflection = deflection_model(model)?;
        let limits = joint_limits_arg(joint_limits, &robot.inner.joint_limits, dof)?;
        let seed = seed_arg(seed, dof)?;
        let task = task_arg(task, seed.as_deref(), &chain)?;
        let ik = PoseIkOptions {
            max_iterations,
            position_tolerance,
            orientation_tolerance,
            task,
            ..PoseIkOptions::default()
        };
        let g = vec3(gravity, "gravity")?;
        let model = serial::Model::new(chain, payload)
            .and_then(|m| m.with_joint_limits(&limits))
            .and_then(|m| m.with_ik_options(ik))
            .map(|m| {
                m.with_deflection(deflection)
                    .with_link_inertia(link_inertia)
            })
            .and_then(|m| m.with_gravity(g))
            .map_err(build_err)?;
        let mut data = serial::Data::new(&model);
        if let Some(q) = &seed {
            data.set_seed(q);
        }
        let p = &model.payload();
        let inertia: [[f64; 3]; 3] = core::array::from_fn(|r| {
            core::array::from_fn(|c| p.inertia.get((r, c)).copied().unwrap_or(f64::NAN))
        });
        // The constructor's positional arguments (more than pyo3's tuples of 12 convert).
        let py = handle.py();
        let args: Vec<Bound<'_, PyAny>> = vec![
            handle.clone().into_any(),
            mass.into_pyobject(py)?.into_any(),
            [p.com.x, p.com.y, p.com.z].into_pyobject(py)?.into_any(),
            inertia.into_pyobject(py)?.into_any(),
            model_name(model.deflection()).into_pyobject(py)?.into_any(),
            limits.into_pyobject(py)?.into_any(),
            max_iterations.into_pyobject(py)?.into_any(),
            position_tolerance.into_pyobject(py)?.into_any(),
            orientation_tolerance.into_pyobject(py)?.into_any(),
            seed.into_pyobject(py)?.into_any(),
            pyo3::types::PyBool::new(py, link_inertia)
                .to_owned()
                .into_any(),
            [g.x, g.y, g.z].into_pyobject(py)?.into_any(),
            model.ik_options().task.name().into_pyobject(py)?.into_any(),
        ];
        let config = pyo3::types::PyTuple::new(py, args)?.unbind();
        Ok(Self {
            model,
            data: Mutex::new(data),
            joint_names: robot.inner.joint_names.clone(),
            config,
        })
    }

    /// Pickling and `copy.deepcopy`: the configuration (the constructor's arguments as
    /// validated, the robot pickled with it). The tick state (the last ticks' joints, the
    /// IK's warm start) is not pickled: a copy starts from `seed`, as a new corrector would.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (
        Bound<'py, pyo3::types::PyType>,
        Bound<'py, pyo3::types::PyTuple>,
    ) {
        (slf.get_type(), slf.get().config.bind(slf.py()).clone())
    }

    /// Number of joints.
    #[getter(dof)]
    fn dof_py(&self) -> usize {
        self.dof()
    }
    /// Joint names in `joints` order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.joint_names.clone()
    }
    /// Whether the links' own inertial loads (from the URDF's inertials) are corrected too.
    #[getter]
    fn link_inertia(&self) -> bool {
        self.model.link_inertia()
    }
    /// Gravity [m/s^2], base frame, (3,): zero unless given.
    #[getter]
    fn gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.model.gravity().as_slice().to_pyarray(py)
    }
    /// What the corrector controls: 'pose', 'position_and_axis', 'position_and_spin' or
    /// 'position' (the resolved task when constructed with 'auto').
    #[getter]
    fn task(&self) -> &'static str {
        self.model.ik_options().task.name()
    }
    /// Payload mass [kg].
    #[getter]
    fn mass(&self) -> f64 {
        self.model.payload().mass
    }
    /// Deflection model inverted: 'exact' or 'linearized'.
    #[getter]
    fn model(&self) -> &'static str {
        model_name(self.model.deflection())
    }
    /// The last tick's joints (the next tick's warm start), (dof,).
    #[getter]
    fn joints<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let q = self.data().joints();
        q.get(..self.dof()).unwrap_or(&[]).to_pyarray(py)
    }

    /// Restarts the warm start from joints `q` (dof,) [rad or m]: call it before a motion
    /// that does not continue the last one.
    fn reset(&self, q: &Bound<'_, PyAny>) -> PyResult<()> {
        let q = vector(q, "q", self.dof())?;
        if let Some(i) = q.iter().position(|v| !v.is_finite()) {
            return Err(InputError::new_err(format!("q[{i}] is not finite")));
        }
        self.data().set_seed(&q);
        Ok(())
    }

    /// One tick: the desired TCP `pose` (4, 4) and its `velocity`, `acceleration` (3,)
    /// [m/s, m/s^2], `angular_velocity`, `angular_acceleration` (3,) [rad/s, rad/s^2] (zeros
    /// if left out), all base frame, and an optional `process_wrench` (6,) [N, N m] at the TCP.
    /// `t` [s] is not used (it may be given, finite, so that `step(**trajectory.at(t))` works). Returns a dict: `desired`,
    /// `commanded` (4, 4), `joints` (dof,), `wrench` (6,), `deflection` (6,), `iterations`,
    /// `position_error`, `orientation_error`, `sigma_min`.
    #[pyo3(signature = (pose, velocity=None, acceleration=None, angular_velocity=None, angular_acceleration=None, process_wrench=None, t=None))]
    #[allow(clippy::too_many_arguments)] // reason: the documented Python keyword arguments
    fn step<'py>(
        &self,
        py: Python<'py>,
        pose: &Bound<'py, PyAny>,
        velocity: Option<&Bound<'py, PyAny>>,
        acceleration: Option<&Bound<'py, PyAny>>,
        angular_velocity: Option<&Bound<'py, PyAny>>,
        angular_acceleration: Option<&Bound<'py, PyAny>>,
        process_wrench: Option<&Bound<'py, PyAny>>,
        #[pyo3(from_py_with = args::opt_real::t)] t: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let state = PoseState {
            // Not used by the tick; core refuses a non-finite one all the same.
            t: t.unwrap_or(0.0),
            pose: crate::arrays::pose(pose, "pose")?,
            velocity: vec3(velocity, "velocity")?,
            acceleration: vec3(acceleration, "acceleration")?,
            angular_velocity: vec3(angular_velocity, "angular_velocity")?,
            angular_acceleration: vec3(angular_acceleration, "angular_acceleration")?,
        };
        let process = process_wrench
            .map(|w| vector6(w, "process_wrench"))
            .transpose()?;
        let tick = serial::step(&self.model, &mut self.data(), &state, process.as_ref())
            .map_err(tick_err)?;
        tick_dict(py, &tick, self.dof())
    }

    /// Corrects every tick of a `PoseTrajectory` (from `plan_pose`, with a `rate_hz`),
    /// without the GIL, continuing from the corrector's last joints (call `reset` first for
    /// a new motion). `process_wrench`: none, one (6,) for every tick, or (N, 6) per tick
    /// [N, N m]. A tick that fails raises with its index.
    #[pyo3(signature = (trajectory, process_wrench=None))]
    fn correct(
        &self,
        py: Python<'_>,
        trajectory: &PoseTrajectory,
        process_wrench: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<CorrectedPoses> {
        let Some(rate) = trajectory.rate_hz else {
            return Err(InputError::new_err(
                "trajectory is plan-only (rate_hz=None): correct trajectory.sampled(rate_hz)",
            ));
        };
        let n = trajectory.plan.sample_count(rate).map_err(tick_err)?;
        // Every result (and the broadcast process wrench) grows with the trajectory's ticks
        // (at most MAX_SAMPLES): allocated fallibly, a MemoryError rather than an abort.
        let what = "the corrected trajectory";
        let process: Option<Array2<f64>> = match process_wrench {
            None => None,
            Some(w) => {
                let a = float_array(w, "process_wrench")?;
                match a.ndim() {
                    1 => {
                        let v = vector6(w, "process_wrench")?;
                        let mut all = try_array::<f64, _>(Ix2(n, 6), "process_wrench")?;
                        for mut row in all.rows_mut() {
                            row.iter_mut().zip(v.iter()).for_each(|(d, x)| *d = *x);
                        }
                        Some(all)
                    }
                    _ => {
                        let m = matrix(w, "process_wrench", Some(n), Some(6))?;
                        let copy = try_copy(&m.as_array(), "process_wrench")?;
                        Some(
                            Array2::from_shape_vec((n, 6), copy)
                                .map_err(|e| InputError::new_err(format!("internal: {e}")))?,
                        )
                    }
                }
            }
        };
        let dof = self.dof();
        let mut t = try_array::<f64, _>(Ix1(n), what)?;
        let mut desired = try_array::<f64, _>(Ix3(n, 4, 4), what)?;
        let mut commanded = try_array::<f64, _>(Ix3(n, 4, 4), what)?;
        let mut joints = try_array::<f64, _>(Ix2(n, dof), what)?;
        let mut wrench = try_array::<f64, _>(Ix2(n, 6), what)?;
        let mut deflection = try_array::<f64, _>(Ix2(n, 6), what)?;
        let mut iterations = try_array::<u32, _>(Ix1(n), what)?;
        let mut pos_err = try_array::<f64, _>(Ix1(n), what)?;
        let mut ori_err = try_array::<f64, _>(Ix1(n), what)?;
        let mut free = try_array::<f64, _>(Ix1(n), what)?;
        let states = py.detach(|| pose_ticks(&trajectory.plan, rate))?;
        py.detach(|| -> Result<(), (usize, deflect_core::TickError)> {
            let mut data = self.data();
            for (i, s) in states.iter().enumerate() {
                let p = process
                    .as_ref()
                    .map(|w| Vector6::from_iterator(w.row(i).iter().copied()));
                let tick =
                    serial::step(&self.model, &mut data, s, p.as_ref()).map_err(|e| (i, e))?;
                if let Some(x) = t.get_mut(i) {
                    *x = s.t;
                }
                put_pose(&mut desired, i, &tick.desired);
                put_pose(&mut commanded, i, &tick.commanded);
                for (arr, v) in [
                    (&mut joints, tick.joints.get(..dof).unwrap_or(&[])),
                    (&mut wrench, tick.load.as_slice()),
                    (&mut deflection, tick.displacement.as_slice()),
                ] {
                    arr.row_mut(i).iter_mut().zip(v).for_each(|(d, x)| *d = *x);
                }
                if let Some(x) = iterations.get_mut(i) {
                    *x = u32::try_from(tick.iterations).unwrap_or(u32::MAX);
                }
                if let Some(x) = pos_err.get_mut(i) {
                    *x = tick.diagnostics.position_error;
                }
                if let Some(x) = ori_err.get_mut(i) {
                    *x = tick.diagnostics.orientation_error;
                }
                if let Some(x) = free.get_mut(i) {
                    *x = tick.diagnostics.free_rotation;
                }
            }
            Ok(())
        })
        .map_err(|(i, e)| tick_err_at(format_args!("tick {i}"), e))?;
        Ok(CorrectedPoses {
            t: t.into_pyarray(py).unbind(),
            desired: desired.into_pyarray(py).unbind(),
            commanded: commanded.into_pyarray(py).unbind(),
            joints: joints.into_pyarray(py).unbind(),
            wrench: wrench.into_pyarray(py).unbind(),
            deflection: deflection.into_pyarray(py).unbind(),
            iterations: iterations.into_pyarray(py).unbind(),
            position_error: pos_err.into_pyarray(py).unbind(),
            orientation_error: ori_err.into_pyarray(py).unbind(),
            free_rotation: free.into_pyarray(py).unbind(),
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "SerialDalembertCorrector(dof={}, mass={}, model='{}')",
            self.dof(),
            self.model.payload().mass,
            self.model()
        )
    }
}

/// Adds the serial-arm corrector to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<SerialDalembertCorrector>()?;
    m.add_class::<CorrectedPoses>()?;
    Ok(())
}
