//! The offline pass itself: the program sampled, each sample through the nominal stage and
//! both arms' predictions in chunks, handed to a sink or kept.

use alloc::vec::Vec;

use super::streaming::{RunError, RunOptions, Sink};
use super::{
    Job, JobSample, MAX_CHUNK, Report, Setup, Summary, ToolModels, check_cell, check_flat,
    check_seed, nominal, predict,
};
use crate::error::{BuildError, JobError};
use crate::machining::Program;
use crate::machining::path;
use crate::machining::stock::ZMap;

/// Runs the offline pass (see the module docs) from the joints `seed` near the first pose
/// (they choose the IK branch), keeping every sample in [`Report::samples`]: at most
/// [`path::MAX_PATH_SAMPLES`] ([`BuildError::Budget`] past it; [`run_streaming`] takes
/// longer programs). Errors name the program line.
pub fn run(job: &Job, program: &Program, seed: &[f64]) -> Result<Report, JobError> {
    check_flat(program)?;
    let count = path::Sampler::new(program, &job.setup.path)?.len();
    if count > path::MAX_PATH_SAMPLES {
        return Err(BuildError::Budget {
            what: "job samples (duration x rate + 1)",
            budget: "MAX_PATH_SAMPLES",
            limit: path::MAX_PATH_SAMPLES,
            requested: count,
        }
        .into());
    }
    let mut samples = Vec::new();
    samples
        .try_reserve_exact(count)
        .map_err(|_| BuildError::Budget {
            what: "job samples (the allocation was refused)",
            budget: "MAX_PATH_SAMPLES",
            limit: path::MAX_PATH_SAMPLES,
            requested: count,
        })?;
    let mut keep = |chunk: &[JobSample]| -> Result<(), core::convert::Infallible> {
        samples.extend_from_slice(chunk);
        Ok(())
    };
    let mut report = match run_streaming(job, program, seed, &RunOptions::default(), &mut keep) {
        Ok(r) => r,
        Err(RunError::Job(e)) => return Err(e),
        Err(RunError::Sink(never)) => match never {},
    };
    report.samples = samples;
    Ok(report)
}

/// Runs the offline pass as [`run`] does, handing the samples to `sink` chunk by chunk
/// instead of keeping them: memory bounded by the z-maps, the program's plan and per-line
/// figures and one chunk, whatever the duration (up to [`path::MAX_STREAM_SAMPLES`]). The
/// returned report's `samples` is empty; its [`Report::summary`] holds the figures.
pub fn run_streaming<S: Sink + ?Sized>(
    job: &Job,
    program: &Program,
    seed: &[f64],
    options: &RunOptions,
    sink: &mut S,
) -> Result<Report, RunError<S::Error>> {
    options.validate()?;
    check_seed(job, seed)?;
    check_flat(program)?;
    let job = &*job.at_seed(seed)?;
    let setup = &job.setup;
    let dof = job.model.dof();
    let mut sampler = path::Sampler::new(program, &setup.path)?;
    let tools = ToolModels::new(job, program);
    check_cell(&setup.stock, &tools)?;
    let mut stages = Stages::new(job, program, &tools, seed)?;
    let chunk = options.chunk.min(sampler.len().max(1));
    let mut buf = Buffers::reserve(chunk)?;
    let mut summary = Summary::default();
    let mut next_failed = fill(&mut stages.nominal, &mut sampler, chunk, &mut buf.next);
    // The program line and time of the last sample (for an error after the last chunk).
    let mut last_at = (0, 0.0);
    loop {
        if buf.next.is_empty() && next_failed.is_none() {
            break;
        }
        core::mem::swap(&mut buf.noms, &mut buf.next);
        buf.next.clear();
        if let Some(n) = buf.noms.last() {
            last_at = (n.path.line, n.path.time);
        }
        let mut failed = next_failed.take();
        buf.out_u.clear();
        buf.out_c.clear();
        // The arms on this chunk; beside them the nominal cut of the next (unless this one
        // failed: the job ends with it).
        let more = failed.is_none();
        let (ru, rc, nf) = predict::both(
            &mut stages.unc,
            &mut stages.comp,
            &buf.noms,
            (&mut buf.out_u, &mut buf.out_c),
            options,
            || {
                if more {
                    fill(&mut stages.nominal, &mut sampler, chunk, &mut buf.next)
                } else {
                    None
                }
            },
        );
        next_failed = nf;
        earliest(&mut failed, [ru, rc]);
        buf.join(&mut summary);
        if !buf.done.is_empty() {
            sink.samples(&buf.done).map_err(RunError::Sink)?;
        }
        if let Some((_, e)) = failed {
            return Err(RunError::Job(e));
        }
    }
    stages
        .finish(last_at, summary, setup, dof)
        .map_err(RunError::Job)
}

/// The pass's three stages, each cutting its own z-map of the job's stock: the nominal cut
/// and the uncompensated and compensated arms' predictions.
struct Stages<'a> {
    nominal: nominal::Stage<'a>,
    unc: predict::Arm<'a>,
    comp: predict::Arm<'a>,
}

impl<'a> Stages<'a> {
    /// The stages of `job` on `program`, both arms from the joints `seed`.
    fn new(
        job: &'a Job,
        program: &'a Program,
        tools: &'a ToolModels,
        seed: &[f64],
    ) -> Result<Self, BuildError> {
        let st = &job.setup.stock;
        let zmap = || ZMap::new(st.min, st.max, st.top, st.cell);
        let nominal = nominal::Stage::new(job, program, tools, zmap()?);
        let unc = predict::Arm::new(job, program, tools, zmap()?, seed, false);
        let comp = predict::Arm::new(job, program, tools, zmap()?, seed, true);
        Ok(Self { nominal, unc, comp })
    }

    /// The report with `summary` once the moves the followers still hold back are cut (an
    /// error names `last_at`, the last sample's line and time \[s\]), the stocks handed on.
    fn finish(
        self,
        last_at: (usize, f64),
        summary: Summary,
        setup: &Setup,
        dof: usize,
    ) -> Result<Report, JobError> {
        let Self {
            mut nominal,
            mut unc,
            mut comp,
        } = self;
        let flushed = nominal
            .flush()
            .and_then(|()| unc.flush())
            .and_then(|()| comp.flush());
        if let Err(error) = flushed {
            return Err(JobError::AtLine {
                line: last_at.0,
                time: last_at.1,
                error,
            });
        }
        let cell_updates = nominal.cell_updates + unc.cell_updates + comp.cell_updates;
        Ok(Report {
            samples: Vec::new(),
            summary,
            rapid_contact: nominal.rapid_contact,
            plunge_samples: nominal.plunge_samples,
            nominal: nominal.stock,
            uncompensated: unc.stock,
            compensated: comp.stock,
            cell_updates,
            rate_hz: setup.path.rate_hz,
            dof,
            top: setup.stock.top,
        })
    }
}

/// The per-chunk buffers of [`run_streaming`], each reserved once for a whole chunk: the
/// nominal samples being predicted and the next chunk's, both arms' outputs, and the joined
/// samples handed to the sink.
struct Buffers {
    noms: Vec<nominal::Sample>,
    out_u: Vec<predict::Out>,
    out_c: Vec<predict::Out>,
    done: Vec<JobSample>,
    next: Vec<nominal::Sample>,
}

impl Buffers {
    /// The buffers, each with room for `chunk` samples ([`BuildError::Budget`] when an
    /// allocation is refused).
    fn reserve(chunk: usize) -> Result<Self, BuildError> {
        let refused = || -> Result<(), BuildError> {
            Err(BuildError::Budget {
                what: "job chunk (the allocation was refused)",
                budget: "MAX_CHUNK",
                limit: MAX_CHUNK,
                requested: chunk,
            })
        };
        let mut noms = Vec::new();
        let mut out_u = Vec::new();
        let mut out_c = Vec::new();
        let mut done: Vec<JobSample> = Vec::new();
        if noms.try_reserve_exact(chunk).is_err()
            || out_u.try_reserve_exact(chunk).is_err()
            || out_c.try_reserve_exact(chunk).is_err()
            || done.try_reserve_exact(chunk).is_err()
        {
            refused()?;
        }
        let mut next = Vec::new();
        if next.try_reserve_exact(chunk).is_err() {
            refused()?;
        }
        Ok(Self {
            noms,
            out_u,
            out_c,
            done,
            next,
        })
    }

    /// The chunk's nominal samples joined with both arms' outputs into `done` (cleared
    /// first), each added to `summary`.
    fn join(&mut self, summary: &mut Summary) {
        self.done.clear();
        for ((n, u), c) in self.noms.iter().zip(&self.out_u).zip(&self.out_c) {
            let s = sample(n, u, c);
            summary.add(&s);
            self.done.push(s);
        }
    }
}

/// Keeps in `failed` the earliest of it and the arms' failures (by index in the chunk; a
/// nominal failure comes after every sample before it).
fn earliest(failed: &mut Option<(usize, JobError)>, arms: [predict::Outcome; 2]) {
    for r in arms {
        if let Err((k, e)) = r
            && failed.as_ref().is_none_or(|(f, _)| k < *f)
        {
            *failed = Some((k, e));
        }
    }
}

/// One job sample: the nominal stage's figures with the uncompensated arm's `u` and the
/// compensated arm's `c` at it.
#[inline]
fn sample(n: &nominal::Sample, u: &predict::Out, c: &predict::Out) -> JobSample {
    JobSample {
        path: n.path,
        contact: n.contact,
        feed_per_tooth: n.fz,
        force: n.force,
        wrench: n.wrench,
        q: u.q,
        deflection: u.deflection,
        inertial_wrench: u.inertial_wrench,
        deflection_inertial: u.deflection_inertial,
        tool_acceleration: n.path.acceleration_vector,
        q_commanded: c.q,
        commanded: c.commanded,
        actual_uncompensated: u.tip,
        force_uncompensated: u.force,
        actual_compensated: c.tip,
        force_compensated: c.force,
        coupling_residual: [u.residual, c.residual],
        spin: c.spin,
    }
}

/// The nominal stage over the next `chunk` samples into `noms`; the index in it and the error
/// of a sample that failed (the chunk ends there).
fn fill(
    nominal: &mut nominal::Stage<'_>,
    sampler: &mut path::Sampler<'_>,
    chunk: usize,
    noms: &mut Vec<nominal::Sample>,
) -> Option<(usize, JobError)> {
    for s in sampler.by_ref().take(chunk) {
        match nominal.advance(&s) {
            Ok(n) => noms.push(n),
            Err(e) => return Some((noms.len(), e)),
        }
    }
    None
}
