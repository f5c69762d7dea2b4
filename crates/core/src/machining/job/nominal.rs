//! Stage 1 of the pass: the nominal tool on the nominal stock, sample by sample (each cut
//! depends on the last): its chip, force and wrench, and the checks of the cut (a tool the
//! job lacks, a rapid into the stock, a cut with the spindle off).

use nalgebra::{Isometry3, Vector3};

use super::{Job, ToolModels, check_cell, chip_wrench, engagement, rotate, tooth_feed};
use crate::error::{JobError, TickError};
use crate::machining::Program;
use crate::machining::engagement::{Chip, Contact};
use crate::machining::path;
use crate::machining::path::PathSample;
use crate::machining::report::RapidContact;
use crate::machining::stock::{Follower, Step, ZMap};
use crate::vjm::Vector6;

/// What the nominal stage hands on for one sample.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sample {
    pub path: PathSample,
    /// Index of the tool in [`ToolModels`].
    pub tool: usize,
    pub counter_clockwise: bool,
    /// Feed per tooth \[m\].
    pub fz: f64,
    pub contact: Contact,
    /// Force on the tool \[N\], workpiece frame.
    pub force: Vector3<f64>,
    /// The wrench about the tip \[N, N m\], base frame.
    pub wrench: Vector6,
    /// The same wrench in the workpiece frame (what does not depend on the placement).
    pub wrench_work: Vector6,
    /// The programmed step since the last sample \[m\].
    pub step: Vector3<f64>,
    /// The nominal stock's held move was cut before this sample's chip was read.
    pub settled: bool,
    /// What the nominal cut did with this sample's tip: the arms cut their stocks along
    /// moves that end at the same samples (see [`Follower::step_to`]).
    pub cut: Step,
    /// The programmed path bends between the last sample and this one
    /// ([`path::between`]): the stocks were cut through its points, not along the chord.
    pub via: bool,
}

pub(super) struct Stage<'a> {
    job: &'a Job,
    program: &'a Program,
    /// The last sample's move and fraction on it.
    prev_at: Option<(usize, f64, bool)>,
    tools: &'a ToolModels,
    to_base: Isometry3<f64>,
    pub stock: ZMap,
    chip: Chip,
    prev: Option<Vector3<f64>>,
    last_tool: Option<(u32, usize)>,
    follower: Follower,
    pub rapid_contact: Option<RapidContact>,
    pub plunge_samples: usize,
    pub cell_updates: usize,
}

impl<'a> Stage<'a> {
    pub fn new(job: &'a Job, program: &'a Program, tools: &'a ToolModels, stock: ZMap) -> Self {
        Self {
            job,
            program,
            prev_at: None,
            tools,
            to_base: job.setup.placement,
            stock,
            chip: Chip::default(),
            prev: None,
            last_tool: None,
            follower: Follower::new(),
            rapid_contact: None,
            plunge_samples: 0,
            cell_updates: 0,
        }
    }

    /// Cuts what the follower holds back (before the stock is handed on).
    pub fn flush(&mut self) -> Result<(), TickError> {
        self.cell_updates += self.follower.flush(&mut self.stock)?.cells;
        Ok(())
    }

    fn tool_index(&mut self, number: u32) -> usize {
        match self.last_tool {
            Some((n, i)) if n == number => i,
            _ => {
                let i = self.tools.find(number);
                self.last_tool = Some((number, i));
                i
            }
        }
    }

    /// The nominal tool at sample `s`: its chip on the stock before the cut, the cut, the
    /// checks, the force.
    pub fn advance(&mut self, s: &PathSample) -> Result<Sample, JobError> {
        let at = |error: TickError| JobError::AtLine {
            line: s.line,
            time: s.time,
            error,
        };
        let setup = &self.job.setup;
        let p = s.position;
        let from = self.prev.unwrap_or(p);
        let index = self.tool_index(s.tool);
        let tools = self.tools;
        let Some(tm) = tools.get(index) else {
            return Err(JobError::UnknownTool {
                line: s.line,
                time: s.time,
                tool: s.tool,
            });
        };
        let spindle = match (s.spindle, setup.hand_spindle) {
            (0.0, Some(hand)) => hand,
            (v, _) => v,
        };
        let ccw = spindle < 0.0;
        let held = self.follower.held();
        let settled = self
            .follower
            .settle(&mut self.stock, &p, &s.direction)
            .map_err(at)?;
        self.cell_updates += settled.cells;
        let settled = held > 0 && self.follower.held() == 0;
        engagement::read(
            &self.stock,
            &tm.probes,
            &p,
            &s.direction,
            ccw,
            &mut self.chip,
        );
        let contact = self.chip.contact();
        // A rapid's removal is checked at once, and a tool the job lacks must cut nothing:
        // those are cut now, moves along a line held back (see `Follower::hold_to`).
        // Where the path bends between the samples (a corner, an arc at a low rate), the
        // stock is cut through its points: a chord would cut material the program never
        // enters (a rapid's corner into a feed move).
        let (via, via_rapid) = self.cut_between(s).map_err(at)?;
        let (removed, cut) = if s.feed_move && tm.known && !via {
            self.follower.hold_to(&mut self.stock, &tm.cutter, &p)
        } else {
            self.flush().map_err(at)?;
            (self.follower.cut_to(&mut self.stock, &tm.cutter, &p)).map(|r| (r, Step::Cut))
        }
        .map_err(at)?;
        let rapid_depth = if s.feed_move {
            via_rapid
        } else {
            via_rapid.max(removed.deepest)
        };
        self.check(s, &contact, removed.cells, rapid_depth, tm.known, spindle)?;
        if matches!(contact, Contact::Plunge { .. }) {
            self.plunge_samples += 1;
        }
        let fz = tooth_feed(&tm.tool, s, spindle);
        let (force, wrench_w) =
            chip_wrench(&tm.chip, &self.chip, &s.direction, fz, ccw).map_err(at)?;
        self.cell_updates += removed.cells;
        self.prev = Some(p);
        Ok(Sample {
            path: *s,
            tool: index,
            counter_clockwise: ccw,
            fz,
            contact,
            force,
            wrench: rotate(&self.to_base, &wrench_w),
            wrench_work: wrench_w,
            step: p - from,
            settled,
            cut,
            via,
        })
    }

    /// Cuts the stock through the points where the path bends since the last sample
    /// ([`path::between`]), each stretch with the tool of its move. Whether there were any,
    /// and the deepest cut of a stretch on a rapid move \[m\].
    fn cut_between(&mut self, s: &PathSample) -> Result<(bool, f64), TickError> {
        let here = (s.move_index, s.fraction);
        let Some((m0, f0, blend)) = self.prev_at.replace((here.0, here.1, s.blend)) else {
            return Ok((false, 0.0));
        };
        // In a corner blend the tool leaves the program's corners: its chord is the path.
        if blend || s.blend {
            return Ok((false, 0.0));
        }
        let from = (m0, f0);
        let program = self.program;
        let tools = self.tools;
        let (mut rapid, mut failed, mut cells) = (0.0f64, None, 0usize);
        let (stock, follower) = (&mut self.stock, &mut self.follower);
        // The held feed move is cut before the first point (and not counted as a rapid's).
        let mut first = true;
        let points = path::between(program, from, here, |w, m, _| {
            if failed.is_some() {
                return;
            }
            if core::mem::take(&mut first) {
                match follower.flush(stock) {
                    Ok(r) => cells += r.cells,
                    Err(e) => {
                        failed = Some(e);
                        return;
                    }
                }
            }
            let Some(mv) = program.moves.get(m) else {
                return;
            };
            let Some(tm) = tools.get(tools.find(mv.tool)) else {
                return;
            };
            match follower.cut_to(stock, &tm.cutter, &w) {
                Ok(r) => {
                    cells += r.cells;
                    if !mv.is_feed() {
                        rapid = rapid.max(r.deepest);
                    }
                }
                Err(e) => failed = Some(e),
            }
        });
        if points == 0 {
            return Ok((false, 0.0));
        }
        self.cell_updates += cells;
        match failed {
            Some(e) => Err(e),
            None => Ok((true, rapid)),
        }
    }

    /// A tool the job lacks must not cut (`cells` the cells this sample lowered), a rapid
    /// may skim the stock by `rapid_skim` (`depth` the deepest cut on a rapid move since the
    /// last sample; the deepest skim kept), the spindle must turn in a cut.
    fn check(
        &mut self,
        s: &PathSample,
        contact: &Contact,
        cells: usize,
        depth: f64,
        known: bool,
        spindle: f64,
    ) -> Result<(), JobError> {
        let (line, time) = (s.line, s.time);
        let cuts = *contact != Contact::Air;
        if !known && (cuts || cells > 0) {
            return Err(JobError::UnknownTool {
                line,
                time,
                tool: s.tool,
            });
        }
        if depth > engagement::MIN_DEPTH {
            if self.rapid_contact.is_none_or(|c| depth > c.depth) {
                self.rapid_contact = Some(RapidContact { line, time, depth });
            }
            if depth > self.job.setup.rapid_skim {
                return Err(JobError::RapidInStock { line, time, depth });
            }
        }
        if cuts && spindle == 0.0 {
            return Err(JobError::SpindleOff { line, time });
        }
        Ok(())
    }
}

/// One sample of the nominal pass alone ([`nominal_pass`]): what the program asks of the arm,
/// whatever the arm and its placement.
#[derive(Debug, Clone, Copy)]
pub struct NominalSample {
    /// The programmed tool.
    pub path: PathSample,
    /// The programmed step since the last sample \[m\] (0 at the first).
    pub step: Vector3<f64>,
    /// The wrench on the tool about its tip from the nominal cut \[N, N m\], workpiece frame.
    pub wrench: Vector6,
}

/// The nominal stage of the pass alone (the nominal tool on the nominal stock: the chip and
/// its force at every sample, the job's checks of the cut), handing each sample to `f`:
/// what the placement and the spin about the tool axis do not change, computed once for a
/// search over them ([`crate::machining::spin`], [`crate::machining::placement`]). Errors as [`super::run`]'s nominal
/// ones, or `f`'s.
pub fn nominal_pass(
    job: &Job,
    program: &Program,
    mut f: impl FnMut(&NominalSample) -> Result<(), JobError>,
) -> Result<(), JobError> {
    let setup = &job.setup;
    super::check_flat(program)?;
    let sampler = path::Sampler::new(program, &setup.path)?;
    let tools = ToolModels::new(job, program);
    let st = &setup.stock;
    check_cell(st, &tools)?;
    let mut nominal = Stage::new(
        job,
        program,
        &tools,
        ZMap::new(st.min, st.max, st.top, st.cell)?,
    );
    for s in sampler {
        let n = nominal.advance(&s)?;
        f(&NominalSample {
            path: n.path,
            step: n.step,
            wrench: n.wrench_work,
        })?;
    }
    Ok(())
}
