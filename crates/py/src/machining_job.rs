//! The offline pass over a program (deflect-core's `machining::job`): `MachiningJob` (the arm,
//! the workpiece placement, the tool, the material, the stock and how the program is driven)
//! and `MachiningResult` (every sample as arrays, the three predicted parts, the compensated
//! program). Thin: core runs the pass, with the GIL released.

use deflect_core::machining::cutting::Coefficients;
use deflect_core::machining::cutting::Tool;
use deflect_core::machining::job::{self, Job, Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::machining::spin::{self, LoadPath, SpinSchedule};
use deflect_core::mechanism::PoseIkOptions;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};
use pyo3::prelude::*;

use crate::InputError;
use crate::arrays::{pose, rotation, vector};
use crate::cutter::coefficients;
use crate::errors::{build_err, job_err, load_err};
use crate::job_args::{
    InertiaState, Spin, SpinState, blending, blending_state, inertia_state, of_blending_state,
    of_inertia_state, unit,
};
use crate::machining::GcodeProgram;
use crate::scalars::{count, pair, real};
use crate::tools::{ToolState, ToolTable, from_states, tool_state};
use crate::vjm::SerialRobot;
use deflect_core::io::tool_table::{self, TblOptions};
use deflect_core::machining::tools::ToolTable as CoreTable;
use deflect_core::units::LengthUnit;

/// A robot-machining job without its program: the arm (a `SerialRobot`, its tip the tool
/// tip), the workpiece frame in the robot's base frame (`placement`, 4x4), the TCP
/// orientation in the workpiece frame (`tool_orientation`, 3x3; default the tool pointing
/// down the workpiece z), a flat end mill (`diameter` [m], `flutes`, `helix` [rad]; default
/// the 16 mm three-flute tool of Hähn and Weigold), the material (`coefficients` as in
/// `milling_force`), the stock block (`stock_min`, `stock_max` (x, y) [m], `stock_top` [m],
/// `cell` [m]), and how the program is driven: sampled at `rate_hz` (default 250, the 4 ms
/// cycle), path `acceleration` [m/s^2] and `jerk` [m/s^3], `rapid_speed` [m/s] and the
/// `corner_angle` [rad] driven through without a stop; `blending`: how the other corners are
/// driven, `"stop"` (the default: an exact stop, the tool on the programmed geometry),
/// `"program"` (the program's `G64 P` tolerance per move, `G61` stops) or a tolerance [m]
/// for every corner (0: as fast as the ramps allow). `tools`: a `ToolTable` (or the path of a
/// `.tbl` / `.toml` table, its `.tbl` tools taking `flutes` and `helix`): each move cuts with
/// the tool its program put in the spindle; without one the `diameter` tool serves every `T`.
/// `spindle_rpm`: the speed of a spindle the program never starts (a hand-started spindle),
/// clockwise, wherever the program's spindle is off. `rapid_skim` [m]: how deep a rapid may run
/// into the predicted stock before the run refuses it as a crash (default 1e-4 m; the deepest
/// contact within it is `MachiningResult.rapid_contact`).
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct MachiningJob {
    inner: Job,
    /// The arm, kept for pickling.
    robot: Py<SerialRobot>,
    /// What `spin=` asked for.
    spin: Spin,
}

/// A job as pickled: the robot, the placement (translation, quaternion i j k w), the tool
/// orientation (quaternion), the stock (min x, min y, max x, max y, top, cell), the tool
/// (diameter, flutes, helix), the coefficients, the path options (rate, acceleration, jerk,
/// rapid speed, corner angle, blending as `job_args::blending_state` writes it), the tool table, the hand spindle [rev/s] and the rapid skim
/// [m].
type JobState = (
    Py<SerialRobot>,
    [f64; 3],
    [f64; 4],
    [f64; 4],
    [f64; 6],
    (f64, u32, f64),
    [f64; 6],
    [f64; 6],
    Option<Vec<ToolState>>,
    Option<f64>,
    f64,
    (SpinState, InertiaState),
);

impl MachiningJob {
    /// The core job.
    pub(crate) fn job(&self) -> &Job {
        &self.inner
    }

    /// What `spin=` asked for.
    pub(crate) fn spin(&self) -> Spin {
        self.spin
    }

    fn build(
        robot: Py<SerialRobot>,
        setup: Setup,
        tools: Option<CoreTable>,
        spin: Spin,
        inertia: Option<job::Inertia>,
    ) -> PyResult<Self> {
        let mut inner = {
            let r = &robot.get().inner;
            Job::new(r.model.clone(), &r.joint_limits, setup).map_err(build_err)?
        };
        if let Some(t) = tools {
            inner = inner.with_tools(t);
        }
        if let Some(c) = robot.get().inner.controller {
            inner = inner.with_controller(c);
        }
        if let Spin::Constant(a) = spin {
            inner = inner.with_spin(SpinSchedule::constant(a).map_err(build_err)?);
        }
        if let Some(i) = inertia {
            inner = inner.with_inertia(i).map_err(build_err)?;
        }
        Ok(Self { inner, robot, spin })
    }
}

/// `tools=`: a `ToolTable`, or the path of a table file.
fn tool_table(t: &Bound<'_, PyAny>, flutes: u32, helix: f64) -> PyResult<CoreTable> {
    if let Ok(table) = t.cast::<ToolTable>() {
        return Ok(table.get().inner.clone());
    }
    let path: std::path::PathBuf = t.extract().map_err(|_| {
        InputError::new_err(format!(
            "tools must be a ToolTable or the path of a .tbl / .toml table, got {}",
            t.get_type()
                .name()
                .map_or_else(|_| "?".to_string(), |n| n.to_string())
        ))
    })?;
    let o = TblOptions {
        units: LengthUnit::Millimetre,
        flutes,
        helix,
    };
    tool_table::from_path(&path, &o).map_err(load_err)
}

#[pymethods]
impl MachiningJob {
    #[new]
    #[pyo3(signature = (robot, placement, *, stock_min, stock_max, stock_top=None, cell=None, tool_orientation=None, diameter=None, flutes=None, helix=None, coefficients=None, rate_hz=None, acceleration=None, jerk=None, rapid_speed=None, corner_angle=None, blending=None, tools=None, spindle_rpm=None, rapid_skim=None, spin=None, spin_step=5.0, spin_rate=(1.0, 30.0), spin_measure="normal"),
           text_signature = "(robot, placement, *, stock_min, stock_max, stock_top=0.0, cell=0.0005, tool_orientation=None, diameter=0.016, flutes=3, helix=0.0, coefficients=None, rate_hz=250.0, acceleration=2.0, jerk=20.0, rapid_speed=0.25, corner_angle=0.017453292519943295, blending='stop', tools=None, spindle_rpm=None, rapid_skim=0.0001, spin='keep', spin_step=5.0, spin_rate=(1.0, 30.0), spin_measure='normal')")]
    #[allow(clippy::too_many_arguments)] // reason: the documented Python keyword arguments
    fn new(
        robot: Bound<'_, SerialRobot>,
        placement: &Bound<'_, PyAny>,
        stock_min: &Bound<'_, PyAny>,
        stock_max: &Bound<'_, PyAny>,
        stock_top: Option<&Bound<'_, PyAny>>,
        cell: Option<&Bound<'_, PyAny>>,
        tool_orientation: Option<&Bound<'_, PyAny>>,
        diameter: Option<&Bound<'_, PyAny>>,
        flutes: Option<&Bound<'_, PyAny>>,
        helix: Option<&Bound<'_, PyAny>>,
        coefficients: Option<&Bound<'_, PyAny>>,
        rate_hz: Option<&Bound<'_, PyAny>>,
        acceleration: Option<&Bound<'_, PyAny>>,
        jerk: Option<&Bound<'_, PyAny>>,
        rapid_speed: Option<&Bound<'_, PyAny>>,
        corner_angle: Option<&Bound<'_, PyAny>>,
        blending: Option<&Bound<'_, PyAny>>,
        tools: Option<&Bound<'_, PyAny>>,
        spindle_rpm: Option<&Bound<'_, PyAny>>,
        rapid_skim: Option<&Bound<'_, PyAny>>,
        spin: Option<&Bound<'_, PyAny>>,
        spin_step: f64,
        spin_rate: (f64, f64),
        spin_measure: &str,
    ) -> PyResult<Self> {
        let spin = Spin::from_args(spin, spin_step, spin_rate, spin_measure)?;
        // The documented defaults (shown in the text signature).
        let or = |o: Option<&Bound<'_, PyAny>>, what: &str, default: f64| {
            o.map_or(Ok(default), |o| real(o, what))
        };
        let flutes = match flutes {
            Some(f) => u32::try_from(count(f, "flutes")?).unwrap_or(u32::MAX),
            None => 3,
        };
        let (x0, y0) = pair(stock_min, "stock_min")?;
        let (x1, y1) = pair(stock_max, "stock_max")?;
        let d = PathOptions::default();
        let setup = Setup {
            placement: pose(placement, "placement")?,
            tool_orientation: match tool_orientation {
                Some(r) => rotation(r, "tool_orientation")?,
                None => Setup::tool_down(),
            },
            tool: Tool::new(
                or(diameter, "diameter", 0.016)?,
                flutes,
                or(helix, "helix", 0.0)?,
            )
            .map_err(build_err)?,
            coefficients: self::coefficients(coefficients)?,
            stock: Stock {
                min: Vector2::new(x0, y0),
                max: Vector2::new(x1, y1),
                top: or(stock_top, "stock_top", 0.0)?,
                cell: or(cell, "cell", 5e-4)?,
            },
            path: PathOptions {
                rate_hz: or(rate_hz, "rate_hz", d.rate_hz)?,
                acceleration: or(acceleration, "acceleration", d.acceleration)?,
                jerk: or(jerk, "jerk", d.jerk)?,
                rapid_speed: or(rapid_speed, "rapid_speed", d.rapid_speed)?,
                corner_angle: or(corner_angle, "corner_angle", d.corner_angle)?,
                blending: self::blending(blending)?,
            },
            ik: PoseIkOptions::default(),
            hand_spindle: spindle_rpm
                .map(|r| real(r, "spindle_rpm"))
                .transpose()?
                .map(|rpm| rpm / 60.0),
            rapid_skim: or(rapid_skim, "rapid_skim", job::RAPID_SKIM)?,
        };
        let tools = tools
            .map(|t| tool_table(t, setup.tool.flutes, setup.tool.helix))
            .transpose()?;
        Self::build(robot.unbind(), setup, tools, spin, None)
    }

    /// The job with inertial loads: the tool and spindle beyond the TCP (`mass` [kg], `com`
    /// (3,) [m] and `inertia` (3, 3) about it [kg m^2], TCP frame) in the path's planned
    /// motion and, with `links`, the arm's link masses (the URDF's `<inertial>`) join the
    /// process wrench of every sample before the deflection. `MachiningResult`'s
    /// `deflection_inertial` is the inertial part. A negative or non-finite mass, an
    /// asymmetric or indefinite inertia or one no rigid body has (a principal moment above
    /// the sum of the other two) raises an `InputError`.
    #[pyo3(signature = (mass, com=None, inertia=None, links=false))]
    fn with_inertia(
        &self,
        py: Python<'_>,
        mass: f64,
        com: Option<&Bound<'_, PyAny>>,
        inertia: Option<&Bound<'_, PyAny>>,
        links: bool,
    ) -> PyResult<Self> {
        let payload = crate::dalembert::serial::payload(mass, com, inertia)?;
        let inner = self
            .inner
            .clone()
            .with_inertia(job::Inertia { payload, links })
            .map_err(build_err)?;
        Ok(Self {
            inner,
            robot: self.robot.clone_ref(py),
            spin: self.spin,
        })
    }

    /// Pickling and copy.deepcopy: the robot and the setup as plain values, rebuilt bit for
    /// bit and validated again.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (JobState,))> {
        let py = slf.py();
        let rebuild = slf.get_type().getattr("_from_state")?;
        let me = slf.get();
        let s = me.inner.setup();
        let c = &s.coefficients;
        let q = |r: &UnitQuaternion<f64>| [r.i, r.j, r.k, r.w];
        let state = (
            me.robot.clone_ref(py),
            s.placement.translation.vector.into(),
            q(&s.placement.rotation),
            q(&s.tool_orientation),
            [
                s.stock.min.x,
                s.stock.min.y,
                s.stock.max.x,
                s.stock.max.y,
                s.stock.top,
                s.stock.cell,
            ],
            (s.tool.diameter, s.tool.flutes, s.tool.helix),
            [c.k_tc, c.k_rc, c.k_ac, c.k_te, c.k_re, c.k_ae],
            [
                s.path.rate_hz,
                s.path.acceleration,
                s.path.jerk,
                s.path.rapid_speed,
                s.path.corner_angle,
                blending_state(&s.path.blending),
            ],
            me.inner
                .tools()
                .map(|t| t.tools().iter().map(tool_state).collect()),
            s.hand_spindle,
            s.rapid_skim,
            (me.spin.state(), inertia_state(me.inner.inertia())),
        );
        Ok((rebuild, (state,)))
    }

    /// The job of a pickled state (see `__reduce__`).
    #[staticmethod]
    fn _from_state(state: JobState) -> PyResult<Self> {
        let (robot, t, pq, tq, st, (d, flutes, helix), k, p, tools, hand, skim, (spin, inertia)) =
            state;
        let setup = Setup {
            placement: Isometry3::from_parts(
                Translation3::from(Vector3::from(t)),
                unit(pq, "placement")?,
            ),
            tool_orientation: unit(tq, "tool orientation")?,
            tool: Tool::new(d, flutes, helix).map_err(build_err)?,
            coefficients: Coefficients::new(k[0], k[1], k[2], k[3], k[4], k[5])
                .map_err(build_err)?,
            stock: Stock {
                min: Vector2::new(st[0], st[1]),
                max: Vector2::new(st[2], st[3]),
                top: st[4],
                cell: st[5],
            },
            path: PathOptions {
                rate_hz: p[0],
                acceleration: p[1],
                jerk: p[2],
                rapid_speed: p[3],
                corner_angle: p[4],
                blending: of_blending_state(p[5]),
            },
            ik: PoseIkOptions::default(),
            hand_spindle: hand,
            rapid_skim: skim,
        };
        Self::build(
            robot,
            setup,
            tools.map(from_states).transpose()?,
            Spin::of_state(spin)?,
            of_inertia_state(inertia),
        )
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.inner.setup() == other.inner.setup()
            && self.inner.model() == other.inner.model()
            && self.inner.tools() == other.inner.tools()
            && self.spin == other.spin
            && self.inner.inertia() == other.inner.inertia()
    }

    /// Runs the offline pass over `program` (a `GcodeProgram`) from the joints `seed` (dof,)
    /// near its first pose (they pick the IK branch). Raises a `DeflectError` naming the
    /// program line where a pose is out of reach (`ConvergenceError`), singular
    /// (`SingularError`) or off the joint limits, the spindle is off in a cut or a rapid
    /// runs into the stock (`InputError`).
    fn run(
        &self,
        py: Python<'_>,
        program: &GcodeProgram,
        seed: &Bound<'_, PyAny>,
    ) -> PyResult<MachiningResult> {
        let seed = vector(seed, "seed", self.inner.model().dof())?;
        let program = program.inner.clone();
        let spin = self.spin;
        let (report, job, plan) = py
            .detach(|| -> Result<_, deflect_core::JobError> {
                let Spin::Optimize(o) = spin else {
                    return Ok((
                        job::run(&self.inner, &program, &seed)?,
                        self.inner.clone(),
                        None,
                    ));
                };
                let loads =
                    LoadPath::new(&self.inner, &program, o.step, o.per_metre, o.per_second)?;
                let plan = spin::plan(&self.inner, &loads, &seed, &o)?;
                let job = self.inner.clone().with_spin(plan.schedule.clone());
                Ok((job::run(&job, &program, &seed)?, job, Some(plan)))
            })
            .map_err(job_err)?;
        let r = &self.robot.get().inner;
        Ok(MachiningResult {
            report,
            program,
            job,
            robot_name: format!("the robot {} -> {}", r.base_link, r.tip_link),
            spin_plan: plan,
        })
    }

    /// Runs the five-axis pass over `program` (a `GcodeProgram` whose tool axis may leave the
    /// workpiece z: APT with tool vectors, G-code with A/B/C under a `kinematics`, points with
    /// `i, j, k`) from the joints `seed` (dof,): the target pose follows the program's tool
    /// axis, the force is the cutter's along its edge on the engagement read from a tri-dexel
    /// stock (the job's stock in x and y, `depth` [m] below its top), and the compensated
    /// joints hold the tip and the axis under it. `shape` ("flat", "ball", "bull-nose" with
    /// `corner_radius` [m]) is the job's tool's end when the job has no tool table; `length`
    /// [m] the length of every tool that removes material; the engagement is read in `slices`
    /// along the edge of `angles` each. The job's `spin` turns the tool about the program's
    /// axis (`"optimize"`: the search over the five-axis pass's loads). The spindle must turn
    /// clockwise. Raises as `run` does.
    #[pyo3(signature = (program, seed, depth=0.05, shape="flat", corner_radius=None, length=0.03, slices=32, angles=180))]
    #[allow(clippy::too_many_arguments)] // reason: the pass's options as keywords
    fn run_five_axis(
        &self,
        py: Python<'_>,
        program: &GcodeProgram,
        seed: &Bound<'_, PyAny>,
        depth: f64,
        shape: &str,
        corner_radius: Option<f64>,
        length: f64,
        slices: usize,
        angles: usize,
    ) -> PyResult<crate::five_axis::FiveAxisResult> {
        let seed = vector(seed, "seed", self.inner.model().dof())?;
        let options = deflect_core::machining::five_axis::Options {
            depth,
            shape: crate::cutter::shape(shape, corner_radius)?,
            length,
            slices,
            angles,
        };
        let program = &program.inner;
        let job = match self.spin {
            Spin::Optimize(o) => {
                let plan = py
                    .detach(|| -> Result<_, deflect_core::JobError> {
                        let loads = LoadPath::new_five_axis(
                            &self.inner,
                            program,
                            &options,
                            o.step,
                            o.per_metre,
                            o.per_second,
                        )?;
                        spin::plan(&self.inner, &loads, &seed, &o)
                    })
                    .map_err(job_err)?;
                std::borrow::Cow::Owned(self.inner.clone().with_spin(plan.schedule))
            }
            // A constant spin is in the job already.
            _ => std::borrow::Cow::Borrowed(&self.inner),
        };
        crate::five_axis::run(py, &job, program, &seed, &options)
    }

    fn __repr__(&self) -> String {
        let s = self.inner.setup();
        format!(
            "MachiningJob(dof={}, tool={} mm x {} flutes, cell={} mm, rate_hz={})",
            self.inner.model().dof(),
            s.tool.diameter * 1e3,
            s.tool.flutes,
            s.stock.cell * 1e3,
            s.path.rate_hz
        )
    }
}

pub use crate::machining_result::MachiningResult;

/// Adds the classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<MachiningJob>()?;
    m.add_class::<MachiningResult>()?;
    Ok(())
}
