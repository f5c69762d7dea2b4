//! The pass itself: the nominal stage (the stock cut move by move, the engagement and the
//! force at each sample) and the three arms it feeds (the program as sampled, the rigid
//! joints, the compensated joints), each cutting its own stock along chords.

use alloc::vec::Vec;

use nalgebra::{Isometry3, Point3, Translation3, Vector3};

use super::follow::Chord;
use super::{Cutter, Options, Report, Sample, cutter, cutters, find, orientation};
use crate::error::{BuildError, JobError, TickError};
use crate::machining::Program;
use crate::machining::dexel::Dexels;
use crate::machining::job::{Job, NominalSample, Warm, check_seed, rotate};
use crate::machining::kinematics::ToolPose;
use crate::machining::path::{self, PathSample};
use crate::machining::profile::{Band, MAX_BANDS};
use crate::machining::program::slerp;
use crate::machining::spin::{Cursor, SpinSchedule};
use crate::vjm::{self, Data, Load, MAX_DOF, Vector6};

/// Why a sample failed: a tick error at its line, or a job error of its own.
pub(super) enum Fault {
    Tick(TickError),
    Job(JobError),
}

impl From<TickError> for Fault {
    fn from(e: TickError) -> Self {
        Self::Tick(e)
    }
}

/// One predicted arm: its solver, buffers and stock.
pub(super) struct Arm {
    pub(super) warm: Warm,
    pub(super) data: Data,
    pub(super) stock: Dexels,
    pub(super) follow: Chord,
    /// The last sample's predicted tool.
    pub(super) last: Option<ToolPose>,
}

impl Arm {
    pub(super) fn new(job: &Job, seed: &[f64], stock: Dexels) -> Self {
        Self {
            warm: Warm::new(seed),
            data: Data::new(job.model()),
            stock,
            follow: Chord::default(),
            last: None,
        }
    }
}

pub(super) struct Pass<'a> {
    pub(super) job: &'a Job,
    pub(super) program: &'a Program,
    pub(super) options: &'a Options,
    pub(super) cutters: &'a [Cutter],
    pub(super) nominal: Dexels,
    /// The program as sampled (its tool on the program: the nominal part), the uncompensated
    /// and the compensated arm (none for the nominal stage alone, [`nominal_pass`]).
    pub(super) arms: Vec<Arm>,
    /// Where the job's spin schedule stands.
    pub(super) spin: Cursor,
    /// The moves before this index are cut into the nominal stock.
    pub(super) cut_moves: usize,
    pub(super) ray_updates: usize,
    pub(super) rapid_volume: f64,
    pub(super) bands: [Band; MAX_BANDS],
    /// The last sample.
    pub(super) prev: Option<PathSample>,
}

impl<'a> Pass<'a> {
    pub(super) fn new(
        job: &'a Job,
        program: &'a Program,
        options: &'a Options,
        cutters: &'a [Cutter],
        nominal: Dexels,
    ) -> Self {
        Self {
            job,
            program,
            options,
            cutters,
            nominal,
            arms: Vec::new(),
            spin: Cursor::default(),
            cut_moves: 0,
            ray_updates: 0,
            rapid_volume: 0.0,
            bands: [Band::new(0.0, 0.0, 0.0); MAX_BANDS],
            prev: None,
        }
    }

    /// The nominal stage at `s`: the stock cut through the moves before it, the cutter in the
    /// spindle and its feed per tooth, bands, force and wrench (workpiece frame).
    pub(super) fn nominal(
        &mut self,
        s: &PathSample,
    ) -> Result<(Cutter, f64, usize, Vector3<f64>, Vector6), Fault> {
        self.cut_through(s.move_index)?;
        let Some(&c) = find(self.cutters, s.tool) else {
            return Err(Fault::Job(JobError::UnknownTool {
                line: s.line,
                time: s.time,
                tool: s.tool,
            }));
        };
        let (fz, bands, force, wrench) = self.force(s, &c)?;
        Ok((c, fz, bands, force, wrench))
    }

    /// Cuts arm `k`'s stock through the points where the program bends between the last
    /// sample and `s` ([`path::between`]: corners and arcs between two samples), each moved
    /// by the arm's offset from the program (tip and axis), interpolated along the path.
    pub(super) fn cut_between(
        &mut self,
        k: usize,
        s: &PathSample,
        pose: &ToolPose,
        c: &Cutter,
    ) -> Result<(), TickError> {
        let (Some(p0), Some(arm)) = (self.prev, self.arms.get_mut(k)) else {
            return Ok(());
        };
        let Some(t0) = arm.last else {
            return Ok(());
        };
        // In a corner blend the tool leaves the program's corners: its chord is the path.
        if p0.blend || s.blend {
            return Ok(());
        }
        let (off0, off1) = (t0.tip - p0.position, pose.tip - s.position);
        let (tilt0, tilt1) = (t0.axis - p0.axis, pose.axis - s.axis);
        let program = self.program;
        let mut failed = None;
        path::between(
            program,
            (p0.move_index, p0.fraction),
            (s.move_index, s.fraction),
            |w, m, share| {
                let Some(mv) = program.moves.get(m) else {
                    return;
                };
                let axis = if (w - mv.end).norm() <= 1e-12 {
                    mv.end_axis
                } else {
                    slerp(&p0.axis, &s.axis, share)
                };
                let axis = (axis + tilt0 + (tilt1 - tilt0) * share).normalize();
                let at = ToolPose {
                    tip: w + off0 + (off1 - off0) * share,
                    axis,
                };
                if failed.is_none()
                    && let Err(e) = arm.follow.to(&mut arm.stock, &c.model.solid, s.tool, &at)
                {
                    failed = Some(e);
                }
            },
        );
        failed.map_or(Ok(()), Err)
    }

    /// Cuts the nominal stock through the moves before `index`.
    pub(super) fn cut_through(&mut self, index: usize) -> Result<(), TickError> {
        while self.cut_moves < index {
            let Some(m) = self.program.moves.get(self.cut_moves) else {
                break;
            };
            self.cut_moves += 1;
            let Some(c) = find(self.cutters, m.tool) else {
                continue;
            };
            let before = self.nominal.volume();
            let r = self.nominal.cut_move(&c.model.solid, m)?;
            self.ray_updates += r.rays;
            if m.motion == crate::machining::Motion::Rapid {
                self.rapid_volume += before - self.nominal.volume();
            }
        }
        Ok(())
    }

    pub(super) fn finish(&mut self) -> Result<(), TickError> {
        self.cut_through(self.program.moves.len())?;
        for arm in &mut self.arms {
            arm.follow.flush(&mut arm.stock)?;
        }
        Ok(())
    }

    /// The force of the nominal tool at `s`: feed per tooth, bands, force and wrench about
    /// the tip (workpiece frame).
    pub(super) fn force(
        &mut self,
        s: &PathSample,
        c: &Cutter,
    ) -> Result<(f64, usize, Vector3<f64>, Vector6), Fault> {
        let none = (0.0, 0, Vector3::zeros(), Vector6::zeros());
        if !s.feed_move || s.speed <= 0.0 {
            return Ok(none);
        }
        let Some(frame) = cutter::frame(&s.axis, &s.direction) else {
            return Ok(none);
        };
        let n = self.nominal.engagement(
            &c.model.solid,
            &s.position,
            &frame,
            self.options.slices,
            self.options.angles,
            &mut self.bands,
        )?;
        if n == 0 {
            return Ok(none);
        }
        let err = |e: JobError| Err(Fault::Job(e));
        if !c.known {
            return err(JobError::UnknownTool {
                line: s.line,
                time: s.time,
                tool: s.tool,
            });
        }
        let spindle = match (s.spindle, self.job.setup().hand_spindle) {
            (0.0, Some(hand)) => hand,
            (v, _) => v,
        };
        if spindle == 0.0 {
            return err(JobError::SpindleOff {
                line: s.line,
                time: s.time,
            });
        }
        if spindle < 0.0 {
            return Err(Fault::Tick(TickError::InvalidArgument {
                what: "spindle direction (M4: the five-axis pass cuts with a clockwise spindle)",
                value: spindle,
            }));
        }
        let fz = s.speed / (spindle * f64::from(c.model.tool.flutes));
        let bands = self.bands.get(..n).unwrap_or(&[]);
        let (f, w) = cutter::edge_wrench(
            &self.job.setup().coefficients,
            &c.model,
            &frame,
            bands,
            &s.axis,
            &s.direction,
            fz,
        )?;
        Ok((fz, n, f, w))
    }

    pub(super) fn advance(&mut self, s: &PathSample) -> Result<Sample, Fault> {
        let (c, fz, bands, force, wrench) = self.nominal(s)?;
        let setup = self.job.setup();
        let to_base = setup.placement;
        let to_work = to_base.inverse();
        let step = self
            .prev
            .map_or(Vector3::zeros(), |p| s.position - p.position);
        let spin = match self.job.spin() {
            Some(schedule) => self.spin.advance(schedule, &step, s.time),
            None => 0.0,
        };
        let tilted = orientation(&setup.tool_orientation, &s.axis)?;
        let rotation = if spin == 0.0 {
            tilted
        } else {
            SpinSchedule::turn(&tilted, spin)
        };
        let target = to_base * Isometry3::from_parts(Translation3::from(s.position), rotation);
        let wrench_base = rotate(&to_base, &wrench);
        let model = self.job.model();
        let dof = model.dof();
        let back = setup.tool_orientation.inverse();
        let mut poses = [ToolPose {
            tip: s.position,
            axis: s.axis,
        }; 3];
        for (k, pose) in poses.iter_mut().enumerate() {
            let (w, load) = if k == 1 {
                (Vector6::zeros(), Load::Rigid)
            } else {
                (wrench_base, Load::Exact)
            };
            let Some(arm) = self.arms.get_mut(k) else {
                continue;
            };
            if k == 0 {
                self.cut_between(k, s, pose, &c)?;
                if let Some(arm) = self.arms.get_mut(k) {
                    arm.follow
                        .to(&mut arm.stock, &c.model.solid, s.tool, pose)?;
                    arm.last = Some(*pose);
                }
                continue;
            }
            arm.warm.solve(self.job, &mut arm.data, &target, &w, load)?;
            let q = arm.warm.q;
            let qs = q.get(..dof).unwrap_or(&[]);
            vjm::deflection(model, &mut arm.data, qs, &wrench_base, Load::Exact)?;
            let at = to_work * arm.data.tcp_deflected;
            *pose = ToolPose {
                tip: (at * Point3::origin()).coords,
                axis: (at.rotation * back) * Vector3::z(),
            };
            crate::error::check_output("predicted tool", pose.tip.as_slice())?;
            self.cut_between(k, s, pose, &c)?;
            if let Some(arm) = self.arms.get_mut(k) {
                arm.follow
                    .to(&mut arm.stock, &c.model.solid, s.tool, pose)?;
                arm.last = Some(*pose);
            }
        }
        self.prev = Some(*s);
        let q = |k: usize| self.arms.get(k).map_or([0.0; MAX_DOF], |a| a.warm.q);
        Ok(Sample {
            path: *s,
            feed_per_tooth: fz,
            bands,
            force,
            wrench,
            q: q(1),
            q_commanded: q(2),
            uncompensated: poses[1],
            compensated: poses[2],
            spin,
        })
    }
}

/// Runs the five-axis pass (see the module docs) from the joints `seed` near the first pose,
/// keeping every sample (at most [`path::MAX_PATH_SAMPLES`]). Errors name the program line.
pub fn run(
    job: &Job,
    program: &Program,
    seed: &[f64],
    options: &Options,
) -> Result<Report, JobError> {
    options.validate()?;
    check_seed(job, seed)?;
    let job = &*job.at_seed(seed)?;
    let setup = job.setup();
    let sampler = path::Sampler::new(program, &setup.path)?;
    let count = sampler.len();
    if count > path::MAX_PATH_SAMPLES {
        return Err(BuildError::Budget {
            what: "five-axis samples (duration x rate + 1)",
            budget: "MAX_PATH_SAMPLES",
            limit: path::MAX_PATH_SAMPLES,
            requested: count,
        }
        .into());
    }
    let cutters = cutters(job, program, options)?;
    let block = || stock_block(job, options);
    let mut pass = Pass::new(job, program, options, &cutters, block()?);
    for _ in 0..3 {
        pass.arms.push(Arm::new(job, seed, block()?));
    }
    let mut samples = Vec::new();
    samples
        .try_reserve_exact(count)
        .map_err(|_| BuildError::Budget {
            what: "five-axis samples (the allocation was refused)",
            budget: "MAX_PATH_SAMPLES",
            limit: path::MAX_PATH_SAMPLES,
            requested: count,
        })?;
    let mut last = (0, 0.0);
    for s in sampler {
        last = (s.line, s.time);
        let sample = pass.advance(&s).map_err(|error| match error {
            Fault::Tick(error) => JobError::AtLine {
                line: s.line,
                time: s.time,
                error,
            },
            Fault::Job(e) => e,
        })?;
        samples.push(sample);
    }
    pass.finish().map_err(|error| JobError::AtLine {
        line: last.0,
        time: last.1,
        error,
    })?;
    let mut arms = core::mem::take(&mut pass.arms).into_iter();
    let (Some(part), Some(unc), Some(comp)) = (arms.next(), arms.next(), arms.next()) else {
        return Err(BuildError::InvalidParameter {
            what: "five-axis pass arms (three)",
            value: 0.0,
            expected: "three",
        }
        .into());
    };
    Ok(Report {
        samples,
        nominal: part.stock,
        uncompensated: unc.stock,
        compensated: comp.stock,
        rate_hz: setup.path.rate_hz,
        dof: job.model().dof(),
        ray_updates: pass.ray_updates + part.follow.rays + unc.follow.rays + comp.follow.rays,
        rapid_volume: pass.rapid_volume,
    })
}

/// The stock block of the pass: the job's stock in x and y, `options.depth` below its top.
fn stock_block(job: &Job, options: &Options) -> Result<Dexels, BuildError> {
    let st = &job.setup().stock;
    Dexels::block(
        Vector3::new(st.min.x, st.min.y, st.top - options.depth),
        Vector3::new(st.max.x, st.max.y, st.top),
        st.cell,
    )
}

/// The nominal stage of the five-axis pass alone (the nominal tool on the nominal stock:
/// the force at every sample, the checks of the cut), handing each sample to `f`: what the
/// placement and the spin about the tool axis do not change, for a search over them
/// ([`crate::machining::spin::LoadPath::new_five_axis`]). Errors as [`run`]'s nominal ones,
/// or `f`'s.
pub fn nominal_pass(
    job: &Job,
    program: &Program,
    options: &Options,
    f: &mut dyn FnMut(&NominalSample) -> Result<(), JobError>,
) -> Result<(), JobError> {
    options.validate()?;
    let sampler = path::Sampler::new(program, &job.setup().path)?;
    let cutters = cutters(job, program, options)?;
    let mut pass = Pass::new(job, program, options, &cutters, stock_block(job, options)?);
    let mut prev: Option<Vector3<f64>> = None;
    for s in sampler {
        let (_, _, _, _, wrench) = pass.nominal(&s).map_err(|error| match error {
            Fault::Tick(error) => JobError::AtLine {
                line: s.line,
                time: s.time,
                error,
            },
            Fault::Job(e) => e,
        })?;
        let step = prev.map_or(Vector3::zeros(), |p| s.position - p);
        prev = Some(s.position);
        f(&NominalSample {
            path: s,
            step,
            wrench,
        })?;
    }
    Ok(())
}
