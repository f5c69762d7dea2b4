//! Drive-train errors and force-feedback contour tracing (contour-tracking paper, Eq. 3-24):
//! `deflect.DriveTrain`, `deflect.ContourTracer`, `edge_direction`, `edge_contact_force`.

use deflect_core::contour::{
    self, ContourError, ContourTracer as CoreTracer, TraceDirection, TracerConfig, TracerStep,
};
use deflect_core::drivetrain::{self as dt, DriveTrain as CoreDrive, DriveTrainError, LinkMasses};
use deflect_core::drivetrain_io;
use deflect_core::vjm::{Data, Model};
use nalgebra::{Matrix2, Vector2, Vector3, Vector6};
use numpy::ndarray::Array2;
use numpy::{PyArray1, PyArray2, ToPyArray};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{Arr1, Arr2, finite_vec, iso_to_py, tick_err};
use crate::vjm::SerialRobot;
use crate::{InputError, LoadError, SingularError};

fn v2(a: &Arr1<'_>, what: &str) -> PyResult<Vector2<f64>> {
    Ok(Vector2::from_column_slice(&finite_vec(a, what, 2)?))
}

fn m2(a: &Arr2<'_>, what: &str) -> PyResult<Matrix2<f64>> {
    let m = a.as_array();
    if m.shape() != [2, 2] || m.iter().any(|x| !x.is_finite()) {
        return Err(InputError::new_err(format!(
            "{what}: expected a finite (2, 2) matrix, got shape {:?}",
            m.shape()
        )));
    }
    Ok(Matrix2::from_fn(|i, j| m[(i, j)]))
}

fn drive_err(e: DriveTrainError) -> PyErr {
    InputError::new_err(e.to_string())
}

fn contour_err(e: ContourError) -> PyErr {
    match e {
        ContourError::SingularStiffness { .. } | ContourError::NoEdgeMotion => {
            SingularError::new_err(e.to_string())
        }
        _ => InputError::new_err(e.to_string()),
    }
}

fn square<'py, const R: usize, const C: usize>(
    py: Python<'py>,
    m: &nalgebra::SMatrix<f64, R, C>,
) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((R, C), |(i, j)| m[(i, j)]).to_pyarray(py)
}

/// Drive-train errors of a serial robot (contour-tracking paper, Eq. 3-13): joint stiffness
/// and backlash, link masses, gravity. Wrenches are the wrench the tool exerts on the
/// environment `[Fx, Fy, Fz, Mx, My, Mz]` [N, N m], base frame (the negative of the load
/// wrench `SerialRobot.deflection` takes); torques are the drive torques.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct DriveTrain {
    model: Model,
    inner: CoreDrive,
}

impl DriveTrain {
    fn q(&self, q: &Arr1<'_>) -> PyResult<Vec<f64>> {
        finite_vec(q, "q", self.model.dof())
    }
    fn wrench(w: &Arr1<'_>) -> PyResult<Vector6<f64>> {
        Ok(Vector6::from_column_slice(&finite_vec(w, "wrench", 6)?))
    }
    fn out<'py>(&self, py: Python<'py>, v: &[f64]) -> Bound<'py, PyArray1<f64>> {
        v.get(..self.model.dof()).unwrap_or(&[]).to_pyarray(py)
    }
}

#[pymethods]
impl DriveTrain {
    /// `stiffness` K_i [N m/rad] and `backlash` theta_b_i [rad] per joint of `robot`;
    /// `masses` a list of `(after_joint, mass_kg, com_xyz)` with the CoM in the frame after
    /// that joint; gravity [m/s^2] in the base frame.
    #[new]
    #[pyo3(signature = (robot, stiffness, backlash=None, masses=None, gravity=None,
                        torque_deadband=0.0, max_condition=dt::DEFAULT_MAX_CONDITION))]
    #[allow(clippy::too_many_arguments)] // reason: keyword arguments of the Python signature
    fn new(
        robot: &SerialRobot,
        stiffness: Arr1<'_>,
        backlash: Option<Arr1<'_>>,
        masses: Option<Vec<(usize, f64, [f64; 3])>>,
        gravity: Option<[f64; 3]>,
        torque_deadband: f64,
        max_condition: f64,
    ) -> PyResult<Self> {
        let model = robot.inner.model.clone();
        let n = model.dof();
        let k = finite_vec(&stiffness, "stiffness", n)?;
        let b = match backlash {
            Some(b) => finite_vec(&b, "backlash", n)?,
            None => vec![0.0; n],
        };
        let mut table = LinkMasses::new();
        for (j, m, c) in masses.unwrap_or_default() {
            table.push(j, m, Vector3::from(c)).map_err(drive_err)?;
        }
        let inner = CoreDrive::new(&model, &k, &b)
            .and_then(|d| d.with_masses(table))
            .and_then(|d| d.with_gravity(Vector3::from(gravity.unwrap_or(dt::STANDARD_GRAVITY))))
            .and_then(|d| d.with_torque_deadband(torque_deadband))
            .and_then(|d| d.with_max_condition(max_condition))
            .map_err(drive_err)?;
        Ok(Self { model, inner })
    }

    /// Stiffness and backlash from the `[[joint]]` entries of a TOML file (the robot's
    /// stiffness file or a sibling), masses from the URDF `<inertial>` elements.
    #[staticmethod]
    fn from_urdf(
        robot: &SerialRobot,
        urdf_path: std::path::PathBuf,
        drive_path: std::path::PathBuf,
    ) -> PyResult<Self> {
        let inner = drivetrain_io::drive_train_from_files(&robot.inner, urdf_path, drive_path)
            .map_err(|e| LoadError::new_err(e.to_string()))?;
        Ok(Self {
            model: robot.inner.model.clone(),
            inner,
        })
    }

    /// Same as `from_urdf`, from the files' texts.
    #[staticmethod]
    fn from_strings(robot: &SerialRobot, urdf: &str, drive_toml: &str) -> PyResult<Self> {
        let inner = drivetrain_io::drive_train_from_strs(&robot.inner, urdf, drive_toml)
            .map_err(|e| LoadError::new_err(e.to_string()))?;
        Ok(Self {
            model: robot.inner.model.clone(),
            inner,
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
        q: Arr1<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.q(&q)?;
        let t = dt::gravity_torques(&self.model, &self.inner, &q).map_err(tick_err)?;
        Ok(self.out(py, &t))
    }

    /// Contact torques `J^T F`, (dof,).
    fn contact_torques<'py>(
        &self,
        py: Python<'py>,
        q: Arr1<'py>,
        wrench: Arr1<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.q(&q)?;
        let w = Self::wrench(&wrench)?;
        let t = dt::contact_torques(&self.model, &mut Data::new(&self.model), &q, &w)
            .map_err(tick_err)?;
        Ok(self.out(py, &t))
    }

    /// Total drive torques `u = g(q) + J^T F`, (dof,) (Eq. 8).
    fn joint_torques<'py>(
        &self,
        py: Python<'py>,
        q: Arr1<'py>,
        wrench: Arr1<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.q(&q)?;
        let w = Self::wrench(&wrench)?;
        let c = dt::correct_joints(
            &self.model,
            &mut Data::new(&self.model),
            &self.inner,
            &q,
            &w,
        )
        .map_err(tick_err)?;
        Ok(self.out(py, &c.torque))
    }

    /// Eq. 10: link angles from the motor readings `q` and the contact wrench,
    /// `q - sgn(u) backlash - u / stiffness`, (dof,).
    fn correct_joints<'py>(
        &self,
        py: Python<'py>,
        q: Arr1<'py>,
        wrench: Arr1<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.q(&q)?;
        let w = Self::wrench(&wrench)?;
        let c = dt::correct_joints(
            &self.model,
            &mut Data::new(&self.model),
            &self.inner,
            &q,
            &w,
        )
        .map_err(tick_err)?;
        Ok(self.out(py, &c.q))
    }

    /// TCP pose (4, 4) at the corrected joints: the compensated shape-recovery point.
    fn compensated_forward<'py>(
        &self,
        py: Python<'py>,
        q: Arr1<'py>,
        wrench: Arr1<'py>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let q = self.q(&q)?;
        let w = Self::wrench(&wrench)?;
        let t = dt::compensated_forward(
            &self.model,
            &mut Data::new(&self.model),
            &self.inner,
            &q,
            &w,
        )
        .map_err(tick_err)?;
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
        q: Arr1<'py>,
        planar: Option<&str>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let q = self.q(&q)?;
        let mut data = Data::new(&self.model);
        let (m, d) = (&self.model, &self.inner);
        Ok(match planar {
            None => square(
                py,
                &dt::cartesian_stiffness(m, &mut data, d, &q).map_err(tick_err)?,
            ),
            Some("xy") => square(
                py,
                &dt::cartesian_stiffness_xy(m, &mut data, d, &q).map_err(tick_err)?,
            ),
            Some("xyrz") => square(
                py,
                &dt::cartesian_stiffness_planar(m, &mut data, d, &q).map_err(tick_err)?,
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
#[derive(Debug)]
pub struct ContourTracer {
    inner: CoreTracer,
    last: Option<TracerStep>,
}

#[pymethods]
impl ContourTracer {
    /// `stiffness` the (2, 2) xy stiffness [N/m]; `step` Delta r [m]; force window
    /// `contact_force < |F| < jam_force` [N]. Other settings as `TracerConfig` in Rust.
    #[new]
    #[pyo3(signature = (stiffness, step, contact_force, jam_force, *, target_force=None,
                        approach_direction=(1.0, 0.0), approach_step=None, bias_samples=10,
                        stop_radius=None, clockwise=false, max_turn=std::f64::consts::FRAC_PI_4,
                        min_motion_fraction=0.25, jam_margin=0.8, min_step_fraction=0.1,
                        max_bisections=6, max_jam_steps=10,
                        max_approach_steps=10_000, max_steps=100_000))]
    #[allow(clippy::too_many_arguments)] // reason: keyword arguments of the Python signature
    fn new(
        stiffness: Arr2<'_>,
        step: f64,
        contact_force: f64,
        jam_force: f64,
        target_force: Option<f64>,
        approach_direction: (f64, f64),
        approach_step: Option<f64>,
        bias_samples: usize,
        stop_radius: Option<f64>,
        clockwise: bool,
        max_turn: f64,
        min_motion_fraction: f64,
        jam_margin: f64,
        min_step_fraction: f64,
        max_bisections: usize,
        max_jam_steps: usize,
        max_approach_steps: usize,
        max_steps: usize,
    ) -> PyResult<Self> {
        let k = m2(&stiffness, "stiffness")?;
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
        let inner = CoreTracer::new(cfg, &k).map_err(contour_err)?;
        Ok(Self { inner, last: None })
    }

    /// Updates the xy stiffness (2, 2) [N/m] for the current pose.
    fn set_stiffness(&mut self, stiffness: Arr2<'_>) -> PyResult<()> {
        let k = m2(&stiffness, "stiffness")?;
        self.inner.set_stiffness(&k).map_err(contour_err)
    }

    /// One steady-state reading -> `(next_command (2,), state_name)`. State names: "init",
    /// "approach", "trace", "recover", "retreat", "done", "failed_no_contact",
    /// "failed_contact_lost", "failed_jammed", "failed_step_limit".
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        position: Arr1<'py>,
        force: Arr1<'py>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, &'static str)> {
        let p = v2(&position, "position")?;
        let f = v2(&force, "force")?;
        let out = self.inner.step(&p, &f).map_err(contour_err)?;
        self.last = Some(out);
        Ok((out.command.as_slice().to_pyarray(py), out.state.name()))
    }

    /// Current state name.
    #[getter]
    fn state(&self) -> &'static str {
        self.inner.state().name()
    }
    /// `True` once done or failed.
    #[getter]
    fn finished(&self) -> bool {
        self.inner.state().is_finished()
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
        let b = self.inner.bias();
        (b.x, b.y)
    }
    /// Estimated first contact point [m], or None.
    #[getter]
    fn start(&self) -> Option<(f64, f64)> {
        self.inner.start().map(|s| (s.x, s.y))
    }
    /// Counters: steps, contacts, eq21_steps, normal_steps, bisections, shortened, jams,
    /// longest_loss, max_force, path_length.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.inner.stats();
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
        format!("ContourTracer(state='{}')", self.inner.state().name())
    }
}

/// Eq. 21: edge direction [rad] from the demanded step (2,) [m] and the steady-state force
/// (change) (2,) [N] under the xy stiffness (2, 2).
#[pyfunction]
fn edge_direction(stiffness: Arr2<'_>, step: Arr1<'_>, force: Arr1<'_>) -> PyResult<f64> {
    contour::edge_direction(
        &m2(&stiffness, "stiffness")?,
        &v2(&step, "step")?,
        &v2(&force, "force")?,
    )
    .map_err(contour_err)
}

/// Eq. 16-20: the force (2,) [N] after the demanded step (2,) [m] against a rigid edge at
/// `edge_angle` [rad], starting from zero force.
#[pyfunction]
fn edge_contact_force<'py>(
    py: Python<'py>,
    stiffness: Arr2<'py>,
    step: Arr1<'py>,
    edge_angle: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    if !edge_angle.is_finite() {
        return Err(InputError::new_err("edge_angle is not finite"));
    }
    let f = contour::edge_contact_force(
        &m2(&stiffness, "stiffness")?,
        &v2(&step, "step")?,
        edge_angle,
    );
    Ok(f.as_slice().to_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<DriveTrain>()?;
    m.add_class::<ContourTracer>()?;
    m.add_function(wrap_pyfunction!(edge_direction, m)?)?;
    m.add_function(wrap_pyfunction!(edge_contact_force, m)?)?;
    Ok(())
}
