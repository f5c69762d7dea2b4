//! The files of `deflect-sim job`, written as the samples stream out of the pass (on a
//! writer thread, a chunk at a time): the samples as `job_samples.npz` (every sample, one
//! array per quantity) and as `job.mcap` (Foxglove's plots of force, deflection and path
//! error against time, at `--log-rate`), the compensated program, the CSV on request, and
//! the figures per operation for the summary.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use deflect_core::io::job_out::{CsvWriter, GcodeWriter};
use deflect_core::io::robot_program::{Command, Language, ProgramOptions, RobotProgram, Target};
use deflect_core::machining::Program;
use deflect_core::machining::job::JobSample;
use deflect_sim::SimError;
use deflect_sim::mcap_log::{self, Kind, McapLog, RunInfo};
use deflect_sim::npz_stream::{Dtype, NpzStream};
use nalgebra::UnitQuaternion;

/// What one operation of the program did (a CAM toolpath: see `Program::operations`).
#[derive(Debug, Clone, Default)]
pub struct OperationFigures {
    /// Its name (the CAM's comment, or `T<n>`).
    pub name: String,
    /// Its first program line.
    pub line: usize,
    /// The tool of its first sample.
    pub tool: u32,
    /// Samples, and the time of the first and last \[s\].
    pub samples: usize,
    pub start: f64,
    pub end: f64,
    /// Largest and summed force magnitude \[N\].
    pub max_force: f64,
    pub sum_force: f64,
    /// Largest distance of each prediction from the program over the feed moves \[m\].
    pub error_uncompensated: f64,
    pub error_compensated: f64,
    /// Feed samples whose compensated prediction is past the tolerance.
    pub deviating: usize,
}

/// The arrays of the archive, by name (see the README's table).
struct Arrays {
    time: usize,
    line: usize,
    tool: usize,
    feed_move: usize,
    position: usize,
    commanded: usize,
    commanded_rotation: usize,
    actual_uncompensated: usize,
    actual_compensated: usize,
    force: usize,
    force_uncompensated: usize,
    force_compensated: usize,
    wrench: usize,
    deflection: usize,
    q: usize,
    q_commanded: usize,
    feed_per_tooth: usize,
    speed: usize,
    engagement: usize,
    coupling_residual: usize,
}

/// The MCAP channels.
struct Channels {
    force: [u16; 3],
    error: [u16; 2],
    deflection: u16,
    engagement: u16,
}

/// Everything being written.
pub struct JobFiles<'p> {
    program: &'p Program,
    dof: usize,
    to_base: UnitQuaternion<f64>,
    npz: NpzStream,
    arrays: Arrays,
    mcap: McapLog,
    channels: Channels,
    log_every: usize,
    count: usize,
    gcode: GcodeWriter<'p, BufWriter<File>>,
    csv: Option<CsvWriter<BufWriter<File>>>,
    /// The robot programs of `--robot-program` (the Cartesian command, then the joints).
    robot_programs: Vec<(String, RobotProgram<'p, BufWriter<File>>)>,
    operations: Vec<OperationFigures>,
    tolerance: f64,
    paths: Vec<PathBuf>,
}

impl std::fmt::Debug for JobFiles<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JobFiles")
            .field("count", &self.count)
            .finish_non_exhaustive()
    }
}

/// Where and how the files are written.
#[derive(Debug, Clone)]
pub struct FileOptions {
    /// The output folder.
    pub out: PathBuf,
    /// Largest distance of the compensated G-code from the commanded path \[m\].
    pub tolerance: f64,
    /// Whether to write `job_samples.csv`, and the pilot lead of its wrench column \[s\].
    pub csv: Option<f64>,
    /// MCAP messages per second of program (0: every sample).
    pub log_rate: f64,
    /// The sampling rate \[Hz\].
    pub rate_hz: f64,
    /// The arm's name (for the MCAP's metadata) and its joints.
    pub robot: String,
    pub dof: usize,
    /// The workpiece's orientation in the base frame (the MCAP's forces are in the base frame).
    pub to_base: UnitQuaternion<f64>,
    /// The robot program's language (`--robot-program`), written for both commands.
    pub robot_program: Option<Language>,
}

fn create(path: &Path) -> Result<BufWriter<File>, SimError> {
    File::create(path)
        .map(|f| BufWriter::with_capacity(1 << 20, f))
        .map_err(|e| SimError::file(path, "create", e))
}

impl Arrays {
    /// Declares the archive's arrays in `npz` (`dof` joints wide for `q`).
    fn declare(npz: &mut NpzStream, dof: usize) -> Result<Self, SimError> {
        let mut a = |name: &str, dtype: Dtype, width: usize| npz.array(name, dtype, width);
        Ok(Self {
            time: a("time", Dtype::F64, 0)?,
            line: a("line", Dtype::I64, 0)?,
            tool: a("tool", Dtype::I64, 0)?,
            feed_move: a("feed_move", Dtype::Bool, 0)?,
            position: a("position", Dtype::F64, 3)?,
            commanded: a("commanded", Dtype::F64, 3)?,
            commanded_rotation: a("commanded_quaternion", Dtype::F64, 4)?,
            actual_uncompensated: a("actual_uncompensated", Dtype::F64, 3)?,
            actual_compensated: a("actual_compensated", Dtype::F64, 3)?,
            force: a("force", Dtype::F64, 3)?,
            force_uncompensated: a("force_uncompensated", Dtype::F64, 3)?,
            force_compensated: a("force_compensated", Dtype::F64, 3)?,
            wrench: a("wrench", Dtype::F64, 6)?,
            deflection: a("deflection", Dtype::F64, 6)?,
            q: a("q", Dtype::F64, dof)?,
            q_commanded: a("q_commanded", Dtype::F64, dof)?,
            feed_per_tooth: a("feed_per_tooth", Dtype::F64, 0)?,
            speed: a("speed", Dtype::F64, 0)?,
            engagement: a("engagement", Dtype::F64, 3)?,
            coupling_residual: a("coupling_residual", Dtype::F64, 2)?,
        })
    }
}

/// Opens the MCAP log at `path`: every run's metadata, then the channels.
fn open_mcap(path: &Path, o: &FileOptions) -> Result<(McapLog, Channels), SimError> {
    let mut mcap = McapLog::create(path)?;
    let channel = |run: &str, quantity: &str, kind: Kind, log: &mut McapLog| {
        log.channel(&format!("/job/{run}/"), quantity, kind)
    };
    for (run, what) in [
        ("nominal", "the tool on the program, on the nominal stock"),
        ("uncompensated", "the arm at the program's rigid joints"),
        ("compensated", "the arm at the compensated joints"),
    ] {
        mcap.run_metadata(&RunInfo {
            scenario: "job".into(),
            run: run.into(),
            robot: o.robot.clone(),
            motion: "the program, sampled at the controller rate".into(),
            acceleration: "the path's jerk-limited profile".into(),
            correction: what.into(),
            options: serde_json::json!({"rate_hz": o.rate_hz, "log_rate_hz": o.log_rate}),
        })?;
    }
    let channels = Channels {
        force: [
            channel("nominal", "force", Kind::Force, &mut mcap)?,
            channel("uncompensated", "force", Kind::Force, &mut mcap)?,
            channel("compensated", "force", Kind::Force, &mut mcap)?,
        ],
        error: [
            channel("uncompensated", "path_error", Kind::PathError, &mut mcap)?,
            channel("compensated", "path_error", Kind::PathError, &mut mcap)?,
        ],
        deflection: channel("nominal", "deflection", Kind::Displacement, &mut mcap)?,
        engagement: channel("nominal", "engagement", Kind::Engagement, &mut mcap)?,
    };
    Ok((mcap, channels))
}

/// The robot programs being written, each with its path.
type RobotPrograms<'p> = Vec<(String, RobotProgram<'p, BufWriter<File>>)>;

/// Opens the robot programs of `--robot-program` (the Cartesian command, then the joints),
/// each path (and its companion file's) added to `paths`.
fn open_robot_programs<'p>(
    target: Target<'p>,
    o: &FileOptions,
    paths: &mut Vec<PathBuf>,
) -> Result<RobotPrograms<'p>, SimError> {
    let mut robot_programs = Vec::new();
    if let Some(language) = o.robot_program {
        for (command, name) in [
            (Command::Cartesian, "job_program"),
            (Command::Joints, "job_program_joints"),
        ] {
            let options = ProgramOptions {
                name: name.to_string(),
                tolerance: o.tolerance,
                ..ProgramOptions::new(language, command)
            };
            let path = o.out.join(format!("{name}.{}", language.extension()));
            let w = RobotProgram::new(create(&path)?, target, &options)
                .map_err(|e| SimError::new(format!("--robot-program {}: {e}", language.name())))?;
            if let Some(f) = w.companion() {
                let p = o.out.join(&f.name);
                std::fs::write(&p, &f.text).map_err(|e| SimError::file(&p, "write", e))?;
                paths.push(p);
            }
            paths.push(path.clone());
            robot_programs.push((path.display().to_string(), w));
        }
    }
    Ok(robot_programs)
}

impl<'p> JobFiles<'p> {
    /// Opens every file (the archive's parts, the MCAP log, the G-code, the CSV if asked).
    pub fn create(
        program: &'p Program,
        target: Target<'p>,
        o: &FileOptions,
    ) -> Result<Self, SimError> {
        let mut npz = NpzStream::create(&o.out.join("job_samples.npz"))?;
        let dof = o.dof;
        let arrays = Arrays::declare(&mut npz, dof)?;
        let mcap_path = o.out.join("job.mcap");
        let (mcap, channels) = open_mcap(&mcap_path, o)?;
        let log_every = if o.log_rate > 0.0 {
            (o.rate_hz / o.log_rate).round().max(1.0) as usize
        } else {
            1
        };
        let gcode_path = o.out.join("job_compensated.nc");
        let gcode = GcodeWriter::new(create(&gcode_path)?, program, o.tolerance);
        let mut paths = vec![o.out.join("job_samples.npz"), mcap_path, gcode_path];
        let csv = match o.csv {
            Some(lead) => {
                let p = o.out.join("job_samples.csv");
                let w = CsvWriter::new(create(&p)?, dof, o.rate_hz, lead);
                paths.push(p);
                Some(w)
            }
            None => None,
        };
        let robot_programs = open_robot_programs(target, o, &mut paths)?;
        Ok(Self {
            program,
            dof,
            to_base: o.to_base,
            npz,
            arrays,
            mcap,
            channels,
            log_every,
            count: 0,
            gcode,
            csv,
            robot_programs,
            operations: Vec::new(),
            tolerance: deflect_core::machining::job::PREDICTION_TOLERANCE,
            paths,
        })
    }

    /// The next chunk of samples, in time order.
    pub fn write(&mut self, chunk: &[JobSample]) -> Result<(), SimError> {
        let io = |what: &str, e: std::io::Error| SimError::new(format!("writing {what}: {e}"));
        self.gcode
            .push(chunk)
            .map_err(|e| io("job_compensated.nc", e))?;
        if let Some(csv) = &mut self.csv {
            csv.push(chunk).map_err(|e| io("job_samples.csv", e))?;
        }
        for (name, w) in &mut self.robot_programs {
            w.push(chunk)
                .map_err(|e| SimError::new(format!("writing {name}: {e}")))?;
        }
        for s in chunk {
            self.arrays(s)?;
            if self.count.is_multiple_of(self.log_every) {
                self.log(s)?;
            }
            self.operation(s);
            self.count += 1;
        }
        Ok(())
    }

    fn arrays(&mut self, s: &JobSample) -> Result<(), SimError> {
        let (a, z) = (&self.arrays, &mut self.npz);
        let dof = self.dof;
        z.f64s(a.time, &[s.path.time])?;
        z.i64(a.line, s.path.line as i64)?;
        z.i64(a.tool, i64::from(s.path.tool))?;
        z.bool(a.feed_move, s.path.feed_move)?;
        z.f64s(a.position, s.path.position.as_slice())?;
        z.f64s(a.commanded, s.commanded.translation.vector.as_slice())?;
        z.f64s(a.commanded_rotation, s.commanded.rotation.coords.as_slice())?;
        z.f64s(a.actual_uncompensated, s.actual_uncompensated.as_slice())?;
        z.f64s(a.actual_compensated, s.actual_compensated.as_slice())?;
        z.f64s(a.force, s.force.as_slice())?;
        z.f64s(a.force_uncompensated, s.force_uncompensated.as_slice())?;
        z.f64s(a.force_compensated, s.force_compensated.as_slice())?;
        z.f64s(a.wrench, s.wrench.as_slice())?;
        z.f64s(a.deflection, s.deflection.as_slice())?;
        z.f64s(a.q, s.q.get(..dof).unwrap_or(&[]))?;
        z.f64s(a.q_commanded, s.q_commanded.get(..dof).unwrap_or(&[]))?;
        z.f64s(a.feed_per_tooth, &[s.feed_per_tooth])?;
        z.f64s(a.speed, &[s.path.speed])?;
        let span = s.contact.span();
        z.f64s(
            a.engagement,
            &[
                span.map_or(0.0, |x| x.entry),
                span.map_or(0.0, |x| x.exit),
                span.map_or(0.0, |x| x.depth),
            ],
        )?;
        z.f64s(a.coupling_residual, &s.coupling_residual)?;
        z.row_done();
        Ok(())
    }

    fn log(&mut self, s: &JobSample) -> Result<(), SimError> {
        let t = s.path.time;
        let c = &self.channels;
        let base = |f: &nalgebra::Vector3<f64>| -> [f64; 3] { (self.to_base * f).into() };
        let forces = [s.force, s.force_uncompensated, s.force_compensated];
        for (ch, run, f) in [
            (c.force[0], "nominal", &forces[0]),
            (c.force[1], "uncompensated", &forces[1]),
            (c.force[2], "compensated", &forces[2]),
        ] {
            self.mcap.write(ch, t, &mcap_log::force(run, t, base(f)))?;
        }
        let p = s.path.position;
        for (ch, run, tip) in [
            (c.error[0], "uncompensated", s.actual_uncompensated),
            (c.error[1], "compensated", s.actual_compensated),
        ] {
            self.mcap
                .write(ch, t, &mcap_log::path_error(run, t, (tip - p).norm()))?;
        }
        let d: [f64; 6] = s.deflection.into();
        self.mcap
            .write(c.deflection, t, &mcap_log::displacement("nominal", t, &d))?;
        let span = s.contact.span();
        self.mcap.write(
            c.engagement,
            t,
            &mcap_log::engagement(
                "nominal",
                t,
                span.map_or(0.0, |a| a.depth),
                span.map_or([0.0; 2], |a| [a.entry, a.exit]),
                s.contact.arcs().len(),
            ),
        )
    }

    fn operation(&mut self, s: &JobSample) {
        let k = self.program.operation_of(s.path.move_index);
        if self.operations.len() <= k {
            self.operations
                .resize_with(k + 1, OperationFigures::default);
        }
        let Some(o) = self.operations.get_mut(k) else {
            return;
        };
        if o.samples == 0 {
            o.name = self
                .program
                .operations
                .get(k)
                .map_or_else(|| "program".to_string(), |op| op.name.clone());
            o.line = s.path.line;
            o.tool = s.path.tool;
            o.start = s.path.time;
        }
        o.samples += 1;
        o.end = s.path.time;
        let f = s.force.norm();
        o.max_force = o.max_force.max(f);
        o.sum_force += f;
        if s.path.feed_move {
            let p = s.path.position;
            let eu = (s.actual_uncompensated - p).norm();
            let ec = (s.actual_compensated - p).norm();
            o.error_uncompensated = o.error_uncompensated.max(eu);
            o.error_compensated = o.error_compensated.max(ec);
            if ec > self.tolerance {
                o.deviating += 1;
            }
        }
    }

    /// Closes every file; the operations' figures (those with samples, in program order)
    /// and the files written.
    pub fn finish(self) -> Result<(Vec<OperationFigures>, Vec<PathBuf>), SimError> {
        let io = |what: &str, e: std::io::Error| SimError::new(format!("writing {what}: {e}"));
        self.gcode
            .finish()
            .map_err(|e| io("job_compensated.nc", e))?;
        if let Some(csv) = self.csv {
            csv.finish().map_err(|e| io("job_samples.csv", e))?;
        }
        for (name, w) in self.robot_programs {
            w.finish()
                .map_err(|e| SimError::new(format!("writing {name}: {e}")))?;
        }
        self.npz.finish()?;
        self.mcap.finish()?;
        let ops = self
            .operations
            .into_iter()
            .filter(|o| o.samples > 0)
            .collect();
        Ok((ops, self.paths))
    }
}
