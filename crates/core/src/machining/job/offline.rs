//! The offline pass itself: the program sampled, each sample through the nominal stage and
//! both arms' predictions in chunks, handed to a sink or kept.

use alloc::vec::Vec;

use super::streaming::{RunError, RunOptions, Sink};
use super::{
    Job, JobSample, MAX_CHUNK, Report, Summary, ToolModels, check_cell, check_flat, check_seed,
    nominal, predict,
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
    let st = &setup.stock;
    check_cell(st, &tools)?;
    let zmap = || ZMap::new(st.min, st.max, st.top, st.cell);
    let mut nominal = nominal::Stage::new(job, program, &tools, zmap()?);
    let mut unc = predict::Arm::new(job, program, &tools, zmap()?, seed, false);
    let mut comp = predict::Arm::new(job, program, &tools, zmap()?, seed, true);
    let chunk = options.chunk.min(sampler.len().max(1));
    let reserve = |what: &'static str| -> Result<(), BuildError> {
        Err(BuildError::Budget {
            what,
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
        reserve("job chunk (the allocation was refused)")?;
    }
    let mut summary = Summary::default();
    let mut next = Vec::new();
    if next.try_reserve_exact(chunk).is_err() {
        reserve("job chunk (the allocation was refused)")?;
    }
    let mut next_failed = fill(&mut nominal, &mut sampler, chunk, &mut next);
    // The program line and time of the last sample (for an error after the last chunk).
    let mut last_at = (0, 0.0);
    loop {
        if next.is_empty() && next_failed.is_none() {
            break;
        }
        core::mem::swap(&mut noms, &mut next);
        next.clear();
        if let Some(n) = noms.last() {
            last_at = (n.path.line, n.path.time);
        }
        let mut failed = next_failed.take();
        out_u.clear();
        out_c.clear();
        // The arms on this chunk; beside them the nominal cut of the next (unless this one
        // failed: the job ends with it).
        let more = failed.is_none();
        let (ru, rc, nf) = predict::both(
            &mut unc,
            &mut comp,
            &noms,
            (&mut out_u, &mut out_c),
            options,
            || {
                if more {
                    fill(&mut nominal, &mut sampler, chunk, &mut next)
                } else {
                    None
                }
            },
        );
        next_failed = nf;
        // The earliest failure wins (a nominal failure comes after every sample before it).
        for r in [ru, rc] {
            if let Err((k, e)) = r
                && failed.as_ref().is_none_or(|(f, _)| k < *f)
            {
                failed = Some((k, e));
            }
        }
        done.clear();
        for ((n, u), c) in noms.iter().zip(&out_u).zip(&out_c) {
            let s = JobSample {
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
            };
            summary.add(&s);
            done.push(s);
        }
        if !done.is_empty() {
            sink.samples(&done).map_err(RunError::Sink)?;
        }
        if let Some((_, e)) = failed {
            return Err(RunError::Job(e));
        }
    }
    // The moves the followers still hold back, cut before the stocks are handed on.
    let flushed = nominal
        .flush()
        .and_then(|()| unc.flush())
        .and_then(|()| comp.flush());
    if let Err(error) = flushed {
        return Err(RunError::Job(JobError::AtLine {
            line: last_at.0,
            time: last_at.1,
            error,
        }));
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
        top: st.top,
    })
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
