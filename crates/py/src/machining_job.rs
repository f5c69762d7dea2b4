//! The offline pass over a program (deflect-core's `machining::job`): `MachiningJob` (the arm,
//! the workpiece placement, the tool, the material, the stock and how the program is driven)
//! and `MachiningResult` (every sample as arrays, the three predicted parts, the compensated
//! program). Thin: core runs the pass, with the GIL released.

use deflect_core::io::{job_out, robot_program};
use deflect_core::machining::Program;
use deflect_core::machining::cutting::Coefficients;
use deflect_core::machining::cutting::Tool;
use deflect_core::machining::job::{self, Job, Report, Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::machining::stock::ZMap;
use deflect_core::mechanism::PoseIkOptions;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector2, Vector3};
use numpy::ndarray::{Array1, Array2, Ix3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;

use crate::InputError;
use crate::arrays::{pose, put_pose, rotation, try_array, try_rows, vector};
use crate::errors::{build_err, job_err, load_err};
use crate::machining::{GcodeProgram, coefficients};
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
/// `corner_angle` [rad] driven through without a stop. `tools`: a `ToolTable` (or the path of a
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
}

/// A job as pickled: the robot, the placement (translation, quaternion i j k w), the tool
/// orientation (quaternion), the stock (min x, min y, max x, max y, top, cell), the tool
/// (diameter, flutes, helix), the coefficients, the path options (rate, acceleration, jerk,
/// rapid speed, corner angle), the tool table, the hand spindle [rev/s] and the rapid skim
/// [m].
type JobState = (
    Py<SerialRobot>,
    [f64; 3],
    [f64; 4],
    [f64; 4],
    [f64; 6],
    (f64, u32, f64),
    [f64; 6],
    [f64; 5],
    Option<Vec<ToolState>>,
    Option<f64>,
    f64,
);

/// A unit quaternion from pickled coordinates, bit for bit (norm checked to 1e-12).
fn unit(q: [f64; 4], what: &str) -> PyResult<UnitQuaternion<f64>> {
    let q = Quaternion::new(q[3], q[0], q[1], q[2]);
    let n = q.norm();
    if (n - 1.0).abs() <= 1e-12 {
        Ok(UnitQuaternion::new_unchecked(q))
    } else {
        Err(InputError::new_err(format!(
            "pickled {what}: a unit quaternion expected, norm {n}"
        )))
    }
}

impl MachiningJob {
    fn build(robot: Py<SerialRobot>, setup: Setup, tools: Option<CoreTable>) -> PyResult<Self> {
        let mut inner = {
            let r = &robot.get().inner;
            Job::new(r.model.clone(), &r.joint_limits, setup).map_err(build_err)?
        };
        if let Some(t) = tools {
            inner = inner.with_tools(t);
        }
        Ok(Self { inner, robot })
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
    #[pyo3(signature = (robot, placement, *, stock_min, stock_max, stock_top=None, cell=None, tool_orientation=None, diameter=None, flutes=None, helix=None, coefficients=None, rate_hz=None, acceleration=None, jerk=None, rapid_speed=None, corner_angle=None, tools=None, spindle_rpm=None, rapid_skim=None),
           text_signature = "(robot, placement, *, stock_min, stock_max, stock_top=0.0, cell=0.0005, tool_orientation=None, diameter=0.016, flutes=3, helix=0.0, coefficients=None, rate_hz=250.0, acceleration=2.0, jerk=20.0, rapid_speed=0.25, corner_angle=0.017453292519943295, tools=None, spindle_rpm=None, rapid_skim=0.0001)")]
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
        tools: Option<&Bound<'_, PyAny>>,
        spindle_rpm: Option<&Bound<'_, PyAny>>,
        rapid_skim: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
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
        Self::build(robot.unbind(), setup, tools)
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
            ],
            me.inner
                .tools()
                .map(|t| t.tools().iter().map(tool_state).collect()),
            s.hand_spindle,
            s.rapid_skim,
        );
        Ok((rebuild, (state,)))
    }

    /// The job of a pickled state (see `__reduce__`).
    #[staticmethod]
    fn _from_state(state: JobState) -> PyResult<Self> {
        let (robot, t, pq, tq, st, (d, flutes, helix), k, p, tools, hand, skim) = state;
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
            },
            ik: PoseIkOptions::default(),
            hand_spindle: hand,
            rapid_skim: skim,
        };
        Self::build(robot, setup, tools.map(from_states).transpose()?)
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.inner.setup() == other.inner.setup()
            && self.inner.model() == other.inner.model()
            && self.inner.tools() == other.inner.tools()
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
        let report = py
            .detach(|| job::run(&self.inner, &program, &seed))
            .map_err(job_err)?;
        let placement = self.inner.setup().placement;
        Ok(MachiningResult {
            report,
            program,
            placement,
        })
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

/// What `MachiningJob.run` predicts: every sample (arrays, SI, workpiece frame unless said),
/// the part three ways, and the compensated program.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct MachiningResult {
    report: Report,
    program: Program,
    /// The job's workpiece frame in the base frame (robot programs are in the base frame).
    placement: nalgebra::Isometry3<f64>,
}

impl MachiningResult {
    fn column<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&job::JobSample) -> f64,
    ) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.report.samples.iter().map(f)).into_pyarray(py)
    }

    fn rows<'py>(
        &self,
        py: Python<'py>,
        width: usize,
        fill: impl Fn(&job::JobSample, &mut [f64]),
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.report.samples.len();
        let mut out = try_rows(n, width, "the samples")?;
        for (s, o) in self.report.samples.iter().zip(out.chunks_mut(width)) {
            fill(s, o);
        }
        let a = Array2::from_shape_vec((n, width), out)
            .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
        Ok(a.into_pyarray(py))
    }

    fn surface<'py>(&self, py: Python<'py>, z: &ZMap) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (nx, ny) = z.shape();
        let a = Array2::from_shape_vec((ny, nx), z.heights().to_vec())
            .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
        Ok(a.into_pyarray(py))
    }

    fn which(&self, part: &str) -> PyResult<&ZMap> {
        match part {
            "uncompensated" => Ok(&self.report.uncompensated),
            "compensated" => Ok(&self.report.compensated),
            other => Err(InputError::new_err(format!(
                "part must be \"uncompensated\" or \"compensated\", got {other:?}"
            ))),
        }
    }
}

#[pymethods]
impl MachiningResult {
    fn __len__(&self) -> usize {
        self.report.samples.len()
    }

    /// Sample times (n,) [s].
    #[getter]
    fn time<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(py, |s| s.path.time)
    }

    /// Program line of each sample (n,).
    #[getter]
    fn line<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        Array1::from_iter(self.report.samples.iter().map(|s| s.path.line as u64)).into_pyarray(py)
    }

    /// The tool in the spindle at each sample (n,) (its program's T; 0 for none).
    #[getter]
    fn tool<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        Array1::from_iter(self.report.samples.iter().map(|s| s.path.tool)).into_pyarray(py)
    }

    /// The program's spindle speed at each sample (n,) [rev/s]: > 0 clockwise (M3), < 0
    /// counter-clockwise (M4), 0 off (a hand-started spindle's speed is not in it).
    #[getter]
    fn spindle<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(py, |s| s.path.spindle)
    }

    /// The deepest a rapid move ran into the predicted stock (within the job's
    /// `rapid_skim`): `(line, time [s], depth [m])`, or None.
    #[getter]
    fn rapid_contact(&self) -> Option<(usize, f64, f64)> {
        self.report.rapid_contact.map(|c| (c.line, c.time, c.depth))
    }

    /// Programmed tool tip (n, 3) [m].
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| o.copy_from_slice(s.path.position.as_slice()))
    }

    /// Engagement (n, 3): first entry, last exit [rad] and mean depth [m]; NaN where the
    /// tool is not side milling (air, plunge).
    #[getter]
    fn engagement<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| match s.contact.span() {
            Some(a) => o.copy_from_slice(&[a.entry, a.exit, a.depth]),
            None => o.fill(f64::NAN),
        })
    }

    /// Feed per tooth (n,) [m].
    #[getter]
    fn feed_per_tooth<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(py, |s| s.feed_per_tooth)
    }

    /// Per-revolution force on the tool from the nominal cut (n, 3) [N].
    #[getter]
    fn force<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| o.copy_from_slice(s.force.as_slice()))
    }

    /// Force the uncompensated tool feels where it is (n, 3) [N].
    #[getter]
    fn force_uncompensated<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| {
            o.copy_from_slice(s.force_uncompensated.as_slice())
        })
    }

    /// Force the compensated tool feels where it is (n, 3) [N].
    #[getter]
    fn force_compensated<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| {
            o.copy_from_slice(s.force_compensated.as_slice())
        })
    }

    /// The last step of each prediction's force-deflection coupling (n, 2) [m]
    /// (uncompensated, compensated): at most 1e-8 m where the fixed point converged.
    #[getter]
    fn coupling_residual<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 2, |s, o| o.copy_from_slice(&s.coupling_residual))
    }

    /// Program lines where the compensated prediction leaves the program by more than 1 um:
    /// `(line, largest distance [m], reason)`, reason "coupling" (the force-deflection
    /// coupling did not converge) or "stock" (the compensated tool meets a stock an earlier
    /// deviation left). Empty where the compensation holds.
    #[getter]
    fn deviations(&self) -> Vec<(usize, f64, &'static str)> {
        self.report
            .line_forces()
            .iter()
            .filter_map(|l| l.deviation.map(|d| (l.line, l.error_compensated, d.name())))
            .collect()
    }

    /// The program's operations with their figures: per operation `(name, first_line,
    /// samples, max_force [N], path_error_uncompensated [m], path_error_compensated [m])`.
    #[getter]
    fn operations(&self) -> Vec<(String, usize, usize, f64, f64, f64)> {
        let n = self.program.operations.len().max(1);
        let mut out: Vec<(String, usize, usize, f64, f64, f64)> = (0..n)
            .map(|k| {
                let name = self
                    .program
                    .operations
                    .get(k)
                    .map_or_else(|| "program".to_string(), |o| o.name.clone());
                (name, 0, 0, 0.0, 0.0, 0.0)
            })
            .collect();
        for s in &self.report.samples {
            let k = self.program.operation_of(s.path.move_index);
            if let Some(o) = out.get_mut(k) {
                if o.2 == 0 {
                    o.1 = s.path.line;
                }
                o.2 += 1;
                o.3 = o.3.max(s.force.norm());
                if s.path.feed_move {
                    let p = s.path.position;
                    o.4 = o.4.max((s.actual_uncompensated - p).norm());
                    o.5 = o.5.max((s.actual_compensated - p).norm());
                }
            }
        }
        out.retain(|o| o.2 > 0);
        out
    }

    /// TCP wrench (n, 6) [N, N m], base frame, about the tool tip.
    #[getter]
    fn wrench<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 6, |s, o| o.copy_from_slice(s.wrench.as_slice()))
    }

    /// Deflection [dp; dr] of the tip (n, 6) [m, rad], base frame.
    #[getter]
    fn deflection<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 6, |s, o| o.copy_from_slice(s.deflection.as_slice()))
    }

    /// Rigid pose-IK joints of the programmed path (n, dof).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.report.dof;
        self.rows(py, n, |s, o| o.copy_from_slice(s.q.get(..n).unwrap_or(&[])))
    }

    /// Compensated joints (n, dof): the axis-specific command.
    #[getter]
    fn q_commanded<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.report.dof;
        self.rows(py, n, |s, o| {
            o.copy_from_slice(s.q_commanded.get(..n).unwrap_or(&[]))
        })
    }

    /// Commanded poses (n, 4, 4), workpiece frame: the Cartesian command.
    #[getter]
    fn commanded<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let n = self.report.samples.len();
        let mut a = try_array(Ix3(n, 4, 4), "the samples")?;
        for (i, s) in self.report.samples.iter().enumerate() {
            put_pose(&mut a, i, &s.commanded);
        }
        Ok(a.into_pyarray(py))
    }

    /// Predicted tool tip without compensation (n, 3) [m].
    #[getter]
    fn actual_uncompensated<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| {
            o.copy_from_slice(s.actual_uncompensated.as_slice())
        })
    }

    /// Predicted tool tip with compensation (n, 3) [m].
    #[getter]
    fn actual_compensated<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| {
            o.copy_from_slice(s.actual_compensated.as_slice())
        })
    }

    /// The part as programmed: heights (ny, nx) [m], row j at y = origin_y + (j + 0.5) cell.
    #[getter]
    fn nominal_surface<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.surface(py, &self.report.nominal)
    }

    /// The part the uncompensated arm cuts, (ny, nx) [m].
    #[getter]
    fn uncompensated_surface<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.surface(py, &self.report.uncompensated)
    }

    /// The part the compensated arm cuts, (ny, nx) [m].
    #[getter]
    fn compensated_surface<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.surface(py, &self.report.compensated)
    }

    /// Lower corner (x, y) of the surfaces' cell (0, 0) [m] and the cell edge [m].
    #[getter]
    fn surface_grid(&self) -> ((f64, f64), f64) {
        let z = &self.report.nominal;
        ((z.origin().x, z.origin().y), z.cell())
    }

    /// Samples plunging into material (no side-milling force modelled there).
    #[getter]
    fn plunge_samples(&self) -> usize {
        self.report.plunge_samples
    }

    /// (max, rms) [m] of the predicted tip's distance from the program over the feed moves.
    #[pyo3(signature = (part="uncompensated"))]
    fn path_error(&self, part: &str) -> PyResult<(f64, f64)> {
        self.which(part)?;
        let e = self.report.path_error(part == "compensated");
        Ok((e.max, e.rms))
    }

    /// The predicted part against the nominal one: `floor_max`, `floor_rms` [m] over the
    /// cells both cut (height above nominal, > 0: material left) and the walls' shift as
    /// `material_left` and `overcut` [m^2] (areas cut by one part and not the other).
    #[pyo3(signature = (part="uncompensated"))]
    fn surface_error(&self, part: &str) -> PyResult<std::collections::HashMap<&'static str, f64>> {
        let e = self.report.surface_error(self.which(part)?);
        Ok([
            ("floor_max", e.floor.max),
            ("floor_rms", e.floor.rms),
            ("material_left", e.material_left),
            ("overcut", e.overcut),
        ]
        .into_iter()
        .collect())
    }

    /// The pilot-control signal (n, 6) [N, N m], base frame: each sample's TCP wrench `lead`
    /// [s] ahead (the annotated program of Hähn and Weigold, sec. 2.3; they used 40 ms).
    #[pyo3(signature = (lead=0.04))]
    fn pilot_wrenches<'py>(
        &self,
        py: Python<'py>,
        lead: f64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let w = self.report.pilot_wrenches(checked_lead(lead)?);
        let mut out = try_rows(w.len(), 6, "the pilot wrenches")?;
        for (o, v) in out.chunks_mut(6).zip(&w) {
            o.copy_from_slice(v.as_slice());
        }
        let a = Array2::from_shape_vec((w.len(), 6), out)
            .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
        Ok(a.into_pyarray(py))
    }

    /// The compensated program as G-code text (mm), blocks kept within `tolerance` [m] of the
    /// commanded path.
    #[pyo3(signature = (tolerance=1e-6))]
    fn compensated_gcode(&self, tolerance: f64) -> PyResult<String> {
        let t = tolerance;
        if !(t.is_finite() && t > 0.0) {
            return Err(InputError::new_err(format!(
                "tolerance: expected > 0 m, got {t}"
            )));
        }
        Ok(job_out::compensated_gcode(&self.report, &self.program, t))
    }

    /// The compensated job as a robot controller's program text. `kind`: "urscript" (Universal
    /// Robots: `movel` of the commanded TCP in the base frame, m and rotation vector, kept
    /// within `tolerance` [m] of the commanded path and `tolerance / 0.1 m` rad of its
    /// orientation, `acceleration` [m/s^2] the `a` of every move; with `joints=True`, `servoj`
    /// of the compensated joints at every sample). The program's lines are comments.
    #[pyo3(signature = (kind, *, tolerance=1e-6, acceleration=1.2, joints=false))]
    fn robot_program(
        &self,
        kind: &str,
        tolerance: f64,
        acceleration: f64,
        joints: bool,
    ) -> PyResult<String> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(InputError::new_err(format!(
                "tolerance: expected > 0 m, got {tolerance}"
            )));
        }
        if !(acceleration.is_finite() && acceleration > 0.0) {
            return Err(InputError::new_err(format!(
                "acceleration: expected > 0 m/s^2, got {acceleration}"
            )));
        }
        match kind {
            "urscript" if joints => Ok(robot_program::urscript_servoj(&self.report)),
            "urscript" => Ok(robot_program::urscript_movel(
                &self.report,
                &self.placement,
                tolerance,
                acceleration,
            )),
            other => Err(InputError::new_err(format!(
                "kind: {other:?}; expected \"urscript\""
            ))),
        }
    }

    /// Every sample as CSV text (columns in deflect-core's `io::job_out::samples_csv`), the
    /// pilot wrench `lead` [s] ahead.
    #[pyo3(signature = (lead=0.04))]
    fn samples_csv(&self, lead: f64) -> PyResult<String> {
        Ok(job_out::samples_csv(&self.report, checked_lead(lead)?))
    }

    fn __repr__(&self) -> String {
        let (u, c) = (self.report.path_error(false), self.report.path_error(true));
        format!(
            "MachiningResult({} samples, path error max {:.3} mm uncompensated, {:.3} mm compensated)",
            self.report.samples.len(),
            u.max * 1e3,
            c.max * 1e3
        )
    }
}

/// A pilot lead \[s\]: finite and >= 0, else `InputError` naming it.
fn checked_lead(lead: f64) -> PyResult<f64> {
    if lead.is_finite() && lead >= 0.0 {
        Ok(lead)
    } else {
        Err(InputError::new_err(format!(
            "lead: expected >= 0 s, got {lead}"
        )))
    }
}

/// Adds the classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<MachiningJob>()?;
    m.add_class::<MachiningResult>()?;
    Ok(())
}
