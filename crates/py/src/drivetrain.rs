//! Drive-train errors and force-feedback contour tracing (contour-tracking paper, Eq. 3-24):
//! `deflect.DriveTrain`, `deflect.ContourTracer`, `edge_direction`, `edge_contact_force`.

use deflect_core::contour::{self, TraceDirection, TracerConfig, TracerStep};
use deflect_core::drivetrain::{self as dt, LinkMasses};
use deflect_core::io;
use deflect_core::units::GRAVITY_Z_DOWN;
use deflect_core::vjm::MAX_DOF;
use nalgebra::{Matrix2, Vector2, Vector3, Vector6};
use numpy::{PyArray1, PyArray2, ToPyArray};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::InputError;
use crate::args;
use crate::arrays::{fixed_matrix, iso_to_py, matrix_to_py, vector, vector_upto};
use crate::errors::{build_err, load_err, tick_err};
use crate::scalars::{count, real};
use crate::vjm::SerialRobot;

fn v2(a: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector2<f64>> {
    Ok(Vector2::from_column_slice(&vector(a, what, 2)?))
}

fn m2(a: &Bound<'_, PyAny>, what: &str) -> PyResult<Matrix2<f64>> {
    fixed_matrix::<2, 2>(a, what)
}

fn square<'py, const R: usize, const C: usize>(
    py: Python<'py>,
    m: &nalgebra::SMatrix<f64, R, C>,
) -> Bound<'py, PyArray2<f64>> {
    matrix_to_py(py, m)
}

/// A point mass `(after_joint, mass_kg, com_xyz)` as the Python signature gives it.
type MassEntry = (usize, f64, [f64; 3]);

/// Point masses `[(after_joint, mass_kg, com_xyz), ...]` read item by item so that every
/// refusal names its entry.
fn masses_arg(o: &Bound<'_, PyAny>) -> PyResult<Option<Vec<MassEntry>>> {
    if o.is_none() {
        return Ok(None);
    }
    let items = o.try_iter().map_err(|_| {
        InputError::new_err("masses: expected a list of (after_joint, mass_kg, com_xyz) tuples")
    })?;
    let mut out = Vec::new();
    for (i, item) in items.enumerate() {
        let item = item?;
        let what = format!("masses[{i}]");
        let fields = item
            .try_iter()
            .and_then(|it| it.collect::<PyResult<Vec<_>>>());
        match fields.as_deref() {
            Ok([j, m, c]) => {
                let com = vector(c, &format!("{what}[2] (com_xyz)"), 3)?;
                let mut xyz = [0.0; 3];
                xyz.iter_mut().zip(&com).for_each(|(d, s)| *d = *s);
                out.push((
                    count(j, &format!("{what}[0] (after_joint)"))?,
                    real(m, &format!("{what}[1] (mass_kg)"))?,
                    xyz,
                ));
            }
            _ => {
                return Err(InputError::new_err(format!(
                    "{what}: expected a tuple (after_joint, mass_kg, com_xyz)"
                )));
            }
        }
    }
    Ok(Some(out))
}

/// Drive-train errors of a serial robot (contour-tracking paper, Eq. 3-13): joint stiffness
/// and backlash, link masses, gravity. Wrenches are the wrench the tool exerts on the
/// environment `[Fx, Fy, Fz, Mx, My, Mz]` [N, N m], base frame (the negative of the load
/// wrench `SerialRobot.deflection` takes); torques are the drive torques.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct DriveTrain {
    /// The drive train; it owns its kinematic chain.
    inner: dt::Model,
    /// The robot it was built on, kept for pickling (its chain is `inner`'s).
    robot: Py<SerialRobot>,
}

impl DriveTrain {
    /// A workspace for one call.
    fn data(&self) -> dt::Data {
        dt::Data::new(&self.inner)
    }
    fn q(&self, q: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        vector(q, "q", self.inner.dof())
    }
    fn wrench(w: &Bound<'_, PyAny>) -> PyResult<Vector6<f64>> {
        Ok(Vector6::from_column_slice(&vector(w, "wrench", 6)?))
    }
    fn out<'py>(&self, py: Python<'py>, v: &[f64]) -> Bound<'py, PyArray1<f64>> {
        v.get(..self.inner.dof()).unwrap_or(&[]).to_pyarray(py)
    }
}

#[pymethods]
impl DriveTrain {
    /// `stiffness` K_i [N m/rad] and `backlash` theta_b_i [rad] per joint of `robot`;
    /// `masses` a list of `(after_joint, mass_kg, com_xyz)` with the CoM in the frame after
    /// that joint; `gravity` [m/s^2] in the base frame, default standard gravity down the
    /// base z axis, (0, 0, -9.80665).
    #[new]
    #[pyo3(signature = (robot, stiffness, backlash=None, masses=None, gravity=None,
                        torque_deadband=0.0, max_condition=dt::DEFAULT_MAX_CONDITION),
           text_signature = "(robot, stiffness, backlash=None, masses=None, gravity=None, \
                             torque_deadband=0.0, max_condition=1000000.0)")]
    #[allow(clippy::too_many_arguments)] // reason: keyword arguments of the Python signature
    fn new(
        robot: &Bound<'_, SerialRobot>,
        stiffness: &Bound<'_, PyAny>,
        backlash: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = masses_arg)] masses: Option<Vec<MassEntry>>,
        #[pyo3(from_py_with = args::opt_triple::gravity)] gravity: Option<[f64; 3]>,
        #[pyo3(from_py_with = args::real::torque_deadband)] torque_deadband: f64,
        #[pyo3(from_py_with = args::real::max_condition)] max_condition: f64,
    ) -> PyResult<Self> {
        // Values are validated by deflect-core's builders.
        let (handle, robot) = (robot.clone().unbind(), robot.get());
        let k = vector_upto(stiffness, "stiffness", MAX_DOF, "MAX_DOF")?;
        let b = match backlash {
            Some(b) => vector_upto(b, "backlash", MAX_DOF, "MAX_DOF")?,
            None => vec![0.0; robot.inner.model.dof()],
        };
        let mut table = LinkMasses::new();
        for (j, m, c) in masses.unwrap_or_default() {
            table.push(j, m, Vector3::from(c)).map_err(build_err)?;
        }
        let inner = dt::Model::new(robot.inner.model.clone(), &k, &b)
            .and_then(|d| d.with_masses(table))
            .and_then(|d| d.with_gravity(Vector3::from(gravity.unwrap_or(GRAVITY_Z_DOWN))))
            .and_then(|d| d.with_torque_deadband(torque_deadband))
            .and_then(|d| d.with_max_condition(max_condition))
            .map_err(build_err)?;
        Ok(Self {
            inner,
            robot: handle,
        })
    }

    /// Pickling and `copy.deepcopy`: the constructor arguments (robot, stiffness, backlash,
    /// masses, gravity, torque deadband, condition limit) as plain values, an exact round
    /// trip validated again on the way back.
    #[allow(clippy::type_complexity)] // reason: the pickle protocol's (callable, args) pair
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(
        Bound<'py, pyo3::types::PyType>,
        (
            Py<SerialRobot>,
            Vec<f64>,
            Vec<f64>,
            Vec<(usize, f64, [f64; 3])>,
            [f64; 3],
            f64,
            f64,
        ),
    )> {
        let me = slf.get();
        let m = &me.inner;
        Ok((
            slf.get_type(),
            (
                me.robot.clone_ref(slf.py()),
                me.stiffness(),
                me.backlash(),
                me.masses(),
                me.gravity(),
                m.torque_deadband(),
                m.max_condition(),
            ),
        ))
    }

    /// Stiffness and backlash from the `[[joint]]` entries of a TOML file (the robot's
    /// stiffness file or a sibling), masses from the URDF `<inertial>` elements.
    #[staticmethod]
    fn from_urdf(
        robot: &Bound<'_, SerialRobot>,
        urdf_path: std::path::PathBuf,
        drive_path: std::path::PathBuf,
    ) -> PyResult<Self> {
        let inner =
            io::drive::from_path(&robot.get().inner, urdf_path, drive_path).map_err(load_err)?;
        Ok(Self {
            inner,
            robot: robot.clone().unbind(),
        })
    }

    /// Same as `from_urdf`, from the files' texts.
    #[staticmethod]
    fn from_strings(
        robot: &Bound<'_, SerialRobot>,
        urdf: &str,
        drive_toml: &str,
    ) -> PyResult<Self> {
        let inner = io::drive::from_str(&robot.get().inner, urdf, drive_toml).map_err(load_err)?;
        Ok(Self {
            inner,
            robot: robot.clone().unbind(),
        })
    }

    /// Joint stiffnesses [N m/rad].
    #[getter]
    fn stiffness(&self) -> Vec<f64> {
        self.inner.stiffness().to_vec()
    }
    /// Joint backlashes [rad].
    #[getter]
    fn backlash(&self) -> Vec<f64> {
        self.inner.backlash().to_vec()
    }
    /// Point masses `(after_joint, mass, com)`.
    #[getter]
    fn masses(&self) -> Vec<(usize, f64, [f64; 3])> {
        self.inner
            .masses()
            .as_slice()
            .iter()
            .map(|m| (m.after_joint, m.mass, [m.com.x, m.com.y, m.com.z]))
            .collect()
    }
    /// Gravity acceleration [m/s^2], base frame.
    #[getter]
    fn gravity(&self) -> [f64; 3] {
        let g = self.inner.gravity();
        [g.x, g.y, g.z]
    }

    /// Drive torques holding the arm against gravity, (dof,) (Eq. 3-7).
    fn gravity_torques<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.q(q)?;
        let t = dt::gravity_torques(&self.inner, &mut self.data(), &q).map_err(tick_err)?;
        Ok(self.out(py, &t))
    }

    /// Contact torques `J^T F`, (dof,).
    fn contact_torques<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.q(q)?;
        let w = Self::wrench(wrench)?;
        let t = dt::contact_torques(&self.inner, &mut self.data(), &q, &w).map_err(tick_err)?;
        Ok(self.out(py, &t))
    }

    /// Total drive torques `u = g(q) + J^T F`, (dof,) (Eq. 8).
    fn joint_torques<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.q(q)?;
        let w = Self::wrench(wrench)?;
        let c = dt::step(&self.inner, &mut self.data(), &q, &w).map_err(tick_err)?;
        Ok(self.out(py, &c.torque))
    }

    /// Eq. 10: link angles from the motor readings `q` and the contact wrench,
    /// `q - sgn(u) backlash - u / stiffness`, (dof,).
    fn correct_joints<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.q(q)?;
        let w = Self::wrench(wrench)?;
        let c = dt::step(&self.inner, &mut self.data(), &q, &w).map_err(tick_err)?;
        Ok(self.out(py, &c.q))
    }

    /// TCP pose (4, 4) at the corrected joints: the compensated shape-recovery point.
    fn compensated_forward<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let q = self.q(q)?;
        let w = Self::wrench(wrench)?;
        let t = dt::compensated_forward(&self.inner, &mut self.data(), &q, &w).map_err(tick_err)?;
        Ok(iso_to_py(py, &t))
    }

    /// Cartesian stiffness `J^-T K_theta J^-1` (Eq. 12-13): (6, 6) for a 6-joint robot,
    /// `[dp; dr] -> [F; M]`; `planar="xy"` gives the (2, 2) xy stiffness of a 2-joint arm,
    /// `planar="xyrz"` the (3, 3) `[x, y, rz]` one of a 3-joint arm. Raises `SingularError`
    /// near singular poses.
    #[pyo3(signature = (q, planar=None))]
    fn cartesian_stiffness<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        planar: Option<&str>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let q = self.q(q)?;
        let (m, data) = (&self.inner, &mut self.data());
        Ok(match planar {
            None => square(py, &dt::cartesian_stiffness(m, data, &q).map_err(tick_err)?),
            Some("xy") => square(
                py,
                &dt::cartesian_stiffness_xy(m, data, &q).map_err(tick_err)?,
            ),
            Some("xyrz") => square(
                py,
                &dt::cartesian_stiffness_planar(m, data, &q).map_err(tick_err)?,
            ),
            Some(other) => {
                return Err(InputError::new_err(format!(
                    "planar: expected None, 'xy' or 'xyrz', got {other:?}"
                )));
            }
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "DriveTrain(dof={}, masses={}, total_mass={} kg)",
            self.inner.dof(),
            self.inner.masses().as_slice().len(),
            self.inner.masses().total()
        )
    }
}

/// The contour tracer of Figures 3-4: feed it the held position command and the raw sensed
/// force (xy, the force the tool exerts on the object, bias included) once the robot is at
/// rest; it returns the next command and its state name.
#[pyclass(module = "deflect")]
#[derive(Debug, Clone)]
pub struct ContourTracer {
    model: contour::Model,
    data: contour::Data,
    last: Option<TracerStep>,
}

#[pymethods]
impl ContourTracer {
    /// Refused: a `ContourTracer` carries its tracing state (contact, bias, path so far) from tick to tick, which a copy in another
    /// process could not continue; send its arguments and build one there. `copy.deepcopy`
    /// copies the state exactly, within this process.
    fn __reduce__(&self) -> PyResult<()> {
        Err(crate::pickle::per_tick_state(
            "ContourTracer",
            "its tracing state (contact, bias, path so far)",
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
    /// `stiffness` the (2, 2) xy stiffness [N/m]; `step` Delta r [m]; force window
    /// `contact_force < |F| < jam_force` [N]. Other settings as `TracerConfig` in Rust.
    #[new]
    #[pyo3(signature = (stiffness, step, contact_force, jam_force, *, target_force=None,
                        approach_direction=(1.0, 0.0), approach_step=None, bias_samples=10,
                        stop_radius=None, clockwise=false, max_turn=std::f64::consts::FRAC_PI_4,
                        min_motion_fraction=0.25, jam_margin=0.8, min_step_fraction=0.1,
                        max_bisections=6, max_jam_steps=10,
                        max_approach_steps=10_000, max_steps=100_000),
           text_signature = "(stiffness, step, contact_force, jam_force, *, target_force=None, \
                             approach_direction=(1.0, 0.0), approach_step=None, bias_samples=10, \
                             stop_radius=None, clockwise=False, max_turn=0.7853981633974483, \
                             min_motion_fraction=0.25, jam_margin=0.8, min_step_fraction=0.1, \
                             max_bisections=6, max_jam_steps=10, max_approach_steps=10000, \
                             max_steps=100000)")]
    #[allow(clippy::too_many_arguments)] // reason: keyword arguments of the Python signature
    fn new(
        stiffness: &Bound<'_, PyAny>,
        #[pyo3(from_py_with = args::real::step)] step: f64,
        #[pyo3(from_py_with = args::real::contact_force)] contact_force: f64,
        #[pyo3(from_py_with = args::real::jam_force)] jam_force: f64,
        #[pyo3(from_py_with = args::opt_real::target_force)] target_force: Option<f64>,
        #[pyo3(from_py_with = args::pair::approach_direction)] approach_direction: (f64, f64),
        #[pyo3(from_py_with = args::opt_real::approach_step)] approach_step: Option<f64>,
        #[pyo3(from_py_with = args::count::bias_samples)] bias_samples: usize,
        #[pyo3(from_py_with = args::opt_real::stop_radius)] stop_radius: Option<f64>,
        clockwise: bool,
        #[pyo3(from_py_with = args::real::max_turn)] max_turn: f64,
        #[pyo3(from_py_with = args::real::min_motion_fraction)] min_motion_fraction: f64,
        #[pyo3(from_py_with = args::real::jam_margin)] jam_margin: f64,
        #[pyo3(from_py_with = args::real::min_step_fraction)] min_step_fraction: f64,
        #[pyo3(from_py_with = args::count::max_bisections)] max_bisections: usize,
        #[pyo3(from_py_with = args::count::max_jam_steps)] max_jam_steps: usize,
        #[pyo3(from_py_with = args::count::max_approach_steps)] max_approach_steps: usize,
        #[pyo3(from_py_with = args::count::max_steps)] max_steps: usize,
    ) -> PyResult<Self> {
        let k = m2(stiffness, "stiffness")?;
        let mut cfg = TracerConfig::new(step, contact_force, jam_force);
        if let Some(t) = target_force {
            cfg.target_force = t;
        }
        cfg.approach_direction = Vector2::new(approach_direction.0, approach_direction.1);
        if let Some(a) = approach_step {
            cfg.approach_step = a;
        }
        cfg.bias_samples = bias_samples;
        if let Some(r) = stop_radius {
            cfg.stop_radius = r;
        }
        cfg.direction = if clockwise {
            TraceDirection::Clockwise
        } else {
            TraceDirection::CounterClockwise
        };
        cfg.max_turn = max_turn;
        cfg.min_motion_fraction = min_motion_fraction;
        cfg.jam_margin = jam_margin;
        cfg.min_step_fraction = min_step_fraction;
        cfg.max_bisections = max_bisections;
        cfg.max_jam_steps = max_jam_steps;
        cfg.max_approach_steps = max_approach_steps;
        cfg.max_steps = max_steps;
        let model = contour::Model::new(cfg, &k).map_err(build_err)?;
        let data = contour::Data::new(&model);
        Ok(Self {
            model,
            data,
            last: None,
        })
    }

    /// Updates the xy stiffness (2, 2) [N/m] for the current pose.
    fn set_stiffness(&mut self, stiffness: &Bound<'_, PyAny>) -> PyResult<()> {
        let k = m2(stiffness, "stiffness")?;
        self.data.set_stiffness(&k).map_err(tick_err)
    }

    /// One steady-state reading -> `(next_command (2,), state_name)`. State names: "init",
    /// "approach", "trace", "recover", "retreat", "done", "failed_no_contact",
    /// "failed_contact_lost", "failed_jammed", "failed_step_limit".
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        position: &Bound<'py, PyAny>,
        force: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, &'static str)> {
        let p = v2(position, "position")?;
        let f = v2(force, "force")?;
        let out = contour::step(&self.model, &mut self.data, &p, &f).map_err(tick_err)?;
        self.last = Some(out);
        Ok((out.command.as_slice().to_pyarray(py), out.state.name()))
    }

    /// Current state name.
    #[getter]
    fn state(&self) -> &'static str {
        self.data.state().name()
    }
    /// `True` once done or failed.
    #[getter]
    fn finished(&self) -> bool {
        self.data.state().is_finished()
    }
    /// Whether the last reading was a steady contact inside the force window (record the
    /// joints now).
    #[getter]
    fn contact(&self) -> bool {
        self.last.is_some_and(|s| s.contact)
    }
    /// Estimated tool position of the last reading, `position - K^-1 F` [m], or None.
    #[getter]
    fn tool(&self) -> Option<(f64, f64)> {
        self.last.map(|s| (s.tool.x, s.tool.y))
    }
    /// Bias-removed force of the last reading [N], or None.
    #[getter]
    fn force(&self) -> Option<(f64, f64)> {
        self.last.map(|s| (s.force.x, s.force.y))
    }
    /// Force bias found at initialization [N].
    #[getter]
    fn bias(&self) -> (f64, f64) {
        let b = self.data.bias();
        (b.x, b.y)
    }
    /// Estimated first contact point [m], or None.
    #[getter]
    fn start(&self) -> Option<(f64, f64)> {
        self.data.start().map(|s| (s.x, s.y))
    }
    /// Counters: steps, contacts, eq21_steps, normal_steps, bisections, shortened, jams,
    /// longest_loss, max_force, path_length.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.data.stats();
        let d = PyDict::new(py);
        d.set_item("steps", s.steps)?;
        d.set_item("contacts", s.contacts)?;
        d.set_item("eq21_steps", s.eq21_steps)?;
        d.set_item("normal_steps", s.normal_steps)?;
        d.set_item("bisections", s.bisections)?;
        d.set_item("shortened", s.shortened)?;
        d.set_item("jams", s.jams)?;
        d.set_item("longest_loss", s.longest_loss)?;
        d.set_item("max_force", s.max_force)?;
        d.set_item("path_length", s.path_length)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!("ContourTracer(state='{}')", self.data.state().name())
    }
}

/// Eq. 21: edge direction [rad] from the demanded step (2,) [m] and the steady-state force
/// (change) (2,) [N] under the xy stiffness (2, 2).
#[pyfunction]
fn edge_direction(
    stiffness: &Bound<'_, PyAny>,
    step: &Bound<'_, PyAny>,
    force: &Bound<'_, PyAny>,
) -> PyResult<f64> {
    contour::edge_direction(
        &m2(stiffness, "stiffness")?,
        &v2(step, "step")?,
        &v2(force, "force")?,
    )
    .map_err(tick_err)
}

/// Eq. 16-20: the force (2,) [N] after the demanded step (2,) [m] against a rigid edge at
/// `edge_angle` [rad], starting from zero force.
#[pyfunction]
fn edge_contact_force<'py>(
    py: Python<'py>,
    stiffness: &Bound<'py, PyAny>,
    step: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::real::edge_angle)] edge_angle: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let f =
        contour::edge_contact_force(&m2(stiffness, "stiffness")?, &v2(step, "step")?, edge_angle)
            .map_err(tick_err)?;
    Ok(f.as_slice().to_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<DriveTrain>()?;
    m.add_class::<ContourTracer>()?;
    m.add_function(wrap_pyfunction!(edge_direction, m)?)?;
    m.add_function(wrap_pyfunction!(edge_contact_force, m)?)?;
    Ok(())
}
