//! A program as the tool moves it: the moves at their programmed feed, jerk-limited, sampled
//! at the controller rate (the 4 ms RSI cycle of Hähn and Weigold 2020, sec. 2.1, by
//! default; 2 kHz or any rate up to [`MAX_RATE_HZ`]).
//!
//! # What the controller does where the program is silent
//! G-code fixes the geometry and the feed, not the acceleration. deflect plans it as a
//! controller in exact-stop mode with tangent look-ahead does:
//!
//! * consecutive moves form one **run** when they are of the same kind (feed or rapid), at
//!   the same feed, and meet tangentially (the tangents differ by at most
//!   [`PathOptions::corner_angle`]): a linearised arc or a line into a tangent arc is driven
//!   through at the feed;
//! * each run is one time-optimal rest-to-rest jerk-limited profile along its arc length
//!   ([`crate::motion::Profile`], the 7-phase profile of Paksoy, Dede and Kiper 2025, sec. 3.3)
//!   with the run's feed (or [`PathOptions::rapid_speed`]) as speed limit: the tool stops at
//!   corners, feed changes and between rapid and feed moves.
//!
//! The tool therefore stays exactly on the programmed geometry (no corner rounding), which
//! is what a prediction of the programmed part needs; the price is the stop at each corner,
//! and the arm's ringing after it. [`PathOptions::blending`] drives the corners as a
//! controller in blending mode does instead (the program's `G64 P` per move, or one
//! tolerance for all): the next run starts while the last one decelerates, within the
//! tolerance of the corner ([`blend`]). A dwell (`G4`, a drilling cycle's pause) holds the
//! tool at rest for its time between two runs.

use alloc::vec::Vec;

use nalgebra::{ComplexField, Vector3};

use super::{Motion, Program};
use crate::error::{BuildError, param};
use crate::motion::{Limits, PathState, Profile};

mod between;
pub mod blend;
mod plan;

use plan::{Plan, Run};

pub use between::{MAX_ARC_CHORDS, WAYPOINT_TOLERANCE, between};
pub use blend::{Blending, MAX_BLEND_TOLERANCE};

/// Highest sampling rate \[Hz\] (10 kHz; servo loops run at 1-8 kHz).
pub const MAX_RATE_HZ: f64 = 1.0e4;
/// Lowest sampling rate \[Hz\] (1 Hz: slower, a program is two samples and its errors
/// read 0).
pub const MIN_RATE_HZ: f64 = 1.0;
/// Most samples of one program sampled into memory ([`sample`], and the offline pass that
/// keeps every sample, [`super::job::run`]): 1,000,000 (67 min at the 4 ms cycle, 8 min at
/// 2 kHz; the pass keeps about 0.6 KB per sample). Longer programs stream
/// ([`Sampler`], [`super::job::run_streaming`]) up to [`MAX_STREAM_SAMPLES`].
pub const MAX_PATH_SAMPLES: usize = 1_000_000;
/// Moves shorter than this \[m\] carry no motion and are skipped.
pub const MIN_MOVE_LENGTH: f64 = 1.0e-12;

/// How the program is driven and sampled (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathOptions {
    /// Sampling rate \[Hz\], `(0, MAX_RATE_HZ]`.
    pub rate_hz: f64,
    /// Path acceleration limit \[m/s^2\].
    pub acceleration: f64,
    /// Path jerk limit \[m/s^3\].
    pub jerk: f64,
    /// Speed of rapid moves (`G0`) \[m/s\].
    pub rapid_speed: f64,
    /// Largest change of direction \[rad\] driven through without stopping, `[0, pi/2)`.
    pub corner_angle: f64,
    /// How the corners past `corner_angle` are driven: an exact stop (the default) or a
    /// blend ([`blend`]).
    pub blending: Blending,
}

impl Default for PathOptions {
    /// 250 Hz (the 4 ms cycle), 2 m/s^2, 20 m/s^3, rapids at 0.25 m/s, 1 degree, exact stops.
    fn default() -> Self {
        Self {
            rate_hz: 250.0,
            acceleration: 2.0,
            jerk: 20.0,
            rapid_speed: 0.25,
            corner_angle: 1.0_f64.to_radians(),
            blending: Blending::ExactStop,
        }
    }
}

impl PathOptions {
    /// Checks every option ([`BuildError::InvalidParameter`] naming it).
    pub fn validate(&self) -> Result<(), BuildError> {
        param(
            "rate_hz",
            self.rate_hz,
            (MIN_RATE_HZ..=MAX_RATE_HZ).contains(&self.rate_hz),
            "in [MIN_RATE_HZ, MAX_RATE_HZ] = [1, 10000] Hz",
        )?;
        Limits::new(self.rapid_speed, self.acceleration, self.jerk)?;
        param(
            "corner_angle",
            self.corner_angle,
            (0.0..core::f64::consts::FRAC_PI_2).contains(&self.corner_angle),
            "in [0, pi/2) rad",
        )?;
        self.blending.validate()
    }
}

/// The tool at one sample, workpiece frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathSample {
    /// Time since the program start \[s\].
    pub time: f64,
    /// Index of the move in [`Program::moves`].
    pub move_index: usize,
    /// The move's program line (1-based).
    pub line: usize,
    /// Tool tip \[m\].
    pub position: Vector3<f64>,
    /// Unit feed direction (the move's tangent).
    pub direction: Vector3<f64>,
    /// Unit tool axis, from the tip towards the spindle (the move's
    /// [`super::Move::axis`]: `+z` in a 2.5-D program).
    pub axis: Vector3<f64>,
    /// Path speed \[m/s\].
    pub speed: f64,
    /// Path acceleration \[m/s^2\]: along [`Self::direction`].
    pub acceleration: f64,
    /// The tool's acceleration \[m/s^2\], workpiece frame: along the path and towards its
    /// centre of curvature (`T a + k v^2`, [`super::Move::curvature`]); in a blend the sum
    /// of both runs'.
    pub acceleration_vector: Vector3<f64>,
    /// Whether the sample lies in a corner blend (two runs moving at once): the tool is off
    /// the programmed path there, within the blending tolerance of the corner, and the move,
    /// line and fraction are those of the faster run.
    pub blend: bool,
    /// Whether the move is a feed move (`G1`-`G3`), not a rapid.
    pub feed_move: bool,
    /// Spindle speed \[rev/s\] (< 0 counter-clockwise, `M4`).
    pub spindle: f64,
    /// The tool in the spindle (the move's [`super::Move::tool`]).
    pub tool: u32,
    /// Where on its move the sample lies: the fraction of [`super::Move::point`], in
    /// \[0, 1\].
    pub fraction: f64,
    /// The rest-to-rest run holding the sample (0, 1, ...): the path stops where the run
    /// changes (a corner past [`PathOptions::corner_angle`], a feed change, a rapid, a dwell):
    /// an exact stop, what a robot program writes as one.
    pub run: usize,
}

fn plan(program: &Program, options: &PathOptions) -> Result<Plan, BuildError> {
    options.validate()?;
    program.validate()?;
    let cos_corner = ComplexField::cos(options.corner_angle);
    let mut p = Plan {
        segs: Vec::new(),
        s0: Vec::new(),
        runs: Vec::new(),
    };
    let (mut t0, mut s) = (0.0, 0.0);
    let mut close = |p: &mut Plan, first: usize, length: f64| -> Result<(), BuildError> {
        let last = p.segs.len().saturating_sub(1);
        let Some(m) = p.segs.get(first).and_then(|&i| program.moves.get(i)) else {
            return Ok(());
        };
        let (speed, hold) = match m.motion {
            Motion::Rapid => (options.rapid_speed, 0.0),
            Motion::Dwell { seconds } => (options.rapid_speed, seconds),
            _ => (m.feed, 0.0),
        };
        let profile = Profile::new(
            length,
            &Limits::new(speed, options.acceleration, options.jerk)?,
        )?;
        let run = Run {
            first,
            last,
            t0,
            profile,
            hold,
            blend_in: 0.0,
        };
        p.runs.push(run);
        t0 += run.duration();
        Ok(())
    };
    let mut first = 0usize;
    for (i, m) in program.moves.iter().enumerate() {
        let length = m.length();
        if let Motion::Dwell { .. } = m.motion {
            // A dwell is a run of its own: what runs before it stops there.
            if !p.segs.is_empty() && first < p.segs.len() {
                close(&mut p, first, s)?;
            }
            first = p.segs.len();
            p.segs.push(i);
            p.s0.push(0.0);
            close(&mut p, first, 0.0)?;
            first = p.segs.len();
            s = 0.0;
            continue;
        }
        if length.is_nan() || length <= MIN_MOVE_LENGTH {
            continue;
        }
        if m.motion != Motion::Rapid && (m.feed.is_nan() || m.feed <= 0.0) {
            return Err(BuildError::InvalidEntry {
                what: "feed move without a feed (index: its program line)",
                index: m.line,
                value: m.feed,
                expected: "an F word before the first G1/G2/G3",
            });
        }
        if let Some(prev) = p
            .segs
            .get(first..)
            .and_then(<[usize]>::last)
            .and_then(|&j| program.moves.get(j))
        {
            let joins = (prev.motion == Motion::Rapid) == (m.motion == Motion::Rapid)
                && prev.feed == m.feed
                && prev.tangent(1.0).dot(&m.tangent(0.0)) >= cos_corner;
            if !joins {
                close(&mut p, first, s)?;
                first = p.segs.len();
                s = 0.0;
            }
        }
        p.segs.push(i);
        p.s0.push(s);
        s += length;
    }
    if p.segs.is_empty() {
        return Err(BuildError::TooFew {
            what: "moves with motion (longer than 1e-12 m) or dwells",
            needed: 1,
            got: 0,
        });
    }
    if first < p.segs.len() {
        close(&mut p, first, s)?;
    }
    blend::overlap(program, &options.blending, &mut p)?;
    Ok(p)
}

/// The program's duration \[s\] when driven as the module docs say.
pub fn duration(program: &Program, options: &PathOptions) -> Result<f64, BuildError> {
    Ok(plan(program, options)?.duration())
}

/// The program driven as the module docs say, sampled every `1 / rate_hz` from 0 to the end
/// (the last sample exactly at the end). [`BuildError::Budget`] past
/// [`MAX_PATH_SAMPLES`], [`BuildError::TooFew`] for a program without motion,
/// [`BuildError::InvalidEntry`] for a feed move before any `F`.
pub fn sample(program: &Program, options: &PathOptions) -> Result<Vec<PathSample>, BuildError> {
    let sampler = Sampler::new(program, options)?;
    let count = sampler.len();
    if count > MAX_PATH_SAMPLES {
        return Err(BuildError::Budget {
            what: "path samples (duration x rate + 1)",
            budget: "MAX_PATH_SAMPLES",
            limit: MAX_PATH_SAMPLES,
            requested: count,
        });
    }
    let mut out = Vec::new();
    out.try_reserve_exact(count)
        .map_err(|_| BuildError::Budget {
            what: "path samples (the allocation was refused)",
            budget: "MAX_PATH_SAMPLES",
            limit: MAX_PATH_SAMPLES,
            requested: count,
        })?;
    out.extend(sampler);
    Ok(out)
}

/// Most samples a streamed program may have ([`Sampler`]): 2^30 (1193 hours at the 4 ms
/// cycle, 149 hours at 2 kHz). The samples are made one at a time; only the plan (a few
/// words per move) is held.
pub const MAX_STREAM_SAMPLES: usize = 1 << 30;

/// The samples of [`sample`] one at a time, in bounded memory: the program is planned once
/// (memory grows with its moves, not its duration) and each sample is made when asked for.
#[derive(Debug, Clone)]
pub struct Sampler<'a> {
    program: &'a Program,
    plan: Plan,
    rate_hz: f64,
    total: f64,
    count: usize,
    tick: usize,
    run: usize,
    seg: usize,
}

impl<'a> Sampler<'a> {
    /// Plans `program`. [`BuildError::Budget`] past [`MAX_STREAM_SAMPLES`], the errors of
    /// [`sample`] otherwise.
    pub fn new(program: &'a Program, options: &PathOptions) -> Result<Self, BuildError> {
        let plan = plan(program, options)?;
        let total = plan.duration();
        let ticks = ComplexField::ceil(total * options.rate_hz - 1.0e-9).max(0.0);
        if ticks.is_nan() || ticks >= MAX_STREAM_SAMPLES as f64 {
            return Err(BuildError::Budget {
                what: "path samples (duration x rate + 1)",
                budget: "MAX_STREAM_SAMPLES",
                limit: MAX_STREAM_SAMPLES,
                requested: (ticks + 1.0).min(usize::MAX as f64) as usize,
            });
        }
        Ok(Self {
            program,
            plan,
            rate_hz: options.rate_hz,
            total,
            count: ticks as usize + 1,
            tick: 0,
            run: 0,
            seg: 0,
        })
    }

    /// Samples in all (made or not).
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether the program has no samples (never: a planned program has at least one).
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The program's duration \[s\].
    pub fn duration(&self) -> f64 {
        self.total
    }
}

/// One run's part of a sample: the move holding its arc length and the (unclamped)
/// fraction on it, the run's path state, and the tool's place, tangent and acceleration.
struct Part<'p> {
    index: usize,
    mv: &'p super::Move,
    fraction: f64,
    state: PathState,
    position: Vector3<f64>,
    direction: Vector3<f64>,
    acceleration: Vector3<f64>,
}

impl<'p> Part<'p> {
    fn new(program: &'p Program, plan: &Plan, seg: usize, state: PathState) -> Option<Self> {
        let (&index, &s) = (plan.segs.get(seg)?, plan.s0.get(seg)?);
        let mv = program.moves.get(index)?;
        let length = mv.length();
        let fraction = if length > 0.0 {
            (state.s - s) / length
        } else {
            0.0
        };
        let f = fraction.clamp(0.0, 1.0);
        let direction = mv.tangent(f);
        Some(Self {
            index,
            mv,
            fraction,
            state,
            position: mv.point(fraction),
            direction,
            acceleration: direction * state.a + mv.curvature(f) * (state.v * state.v),
        })
    }
}

impl Iterator for Sampler<'_> {
    type Item = PathSample;

    fn next(&mut self) -> Option<PathSample> {
        if self.tick >= self.count {
            return None;
        }
        let plan = &self.plan;
        let t = (self.tick as f64 / self.rate_hz).min(self.total);
        self.tick += 1;
        // The latest run started: a blended run from its start, one after a stop once the
        // run before has ended.
        while let (Some(run), Some(next)) = (plan.runs.get(self.run), plan.runs.get(self.run + 1)) {
            let started = if next.blend_in > 0.0 {
                t >= next.t0
            } else {
                t > run.t0 + run.duration()
            };
            if !started {
                break;
            }
            self.run += 1;
        }
        let run = plan.runs.get(self.run)?;
        let state = run.profile.sample(t - run.t0);
        self.seg = plan.locate(run, state.s, self.seg);
        let head = Part::new(self.program, plan, self.seg, state)?;
        // The run before, while it still decelerates into the blend.
        let tail = (run.blend_in > 0.0 && t < run.t0 + run.blend_in)
            .then(|| self.run.checked_sub(1).and_then(|k| plan.runs.get(k)))
            .flatten()
            .and_then(|before| {
                let state = before.profile.sample(t - before.t0);
                let seg = plan.locate_back(before, state.s);
                Part::new(self.program, plan, seg, state)
            });
        let Some(tail) = tail else {
            return Some(make(
                t,
                self.run,
                &head,
                head.position,
                head.direction,
                false,
            ));
        };
        // Both runs' displacements from the corner (the tail's end, the head's start).
        let corner = plan
            .segs
            .get(run.first)
            .and_then(|&m| self.program.moves.get(m))
            .map_or(head.position, |m| m.point(0.0));
        let position = tail.position + head.position - corner;
        let velocity = tail.direction * tail.state.v + head.direction * head.state.v;
        let speed = velocity.norm();
        let direction = if speed > 0.0 {
            velocity / speed
        } else {
            head.direction
        };
        let acceleration = tail.acceleration + head.acceleration;
        let (owner, index) = if head.state.v >= tail.state.v {
            (&head, self.run)
        } else {
            (&tail, self.run - 1)
        };
        let mut s = make(t, index, owner, position, direction, true);
        s.speed = speed;
        s.acceleration = acceleration.dot(&direction);
        s.acceleration_vector = acceleration;
        Some(s)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.count - self.tick;
        (left, Some(left))
    }
}

/// The sample at `t` of `part` on run `run`, the tool at `position` moving along
/// `direction`.
fn make(
    t: f64,
    run: usize,
    part: &Part<'_>,
    position: Vector3<f64>,
    direction: Vector3<f64>,
    blend: bool,
) -> PathSample {
    let (mv, f) = (part.mv, part.fraction.clamp(0.0, 1.0));
    PathSample {
        time: t,
        move_index: part.index,
        line: mv.line,
        position,
        direction,
        axis: mv.axis(f),
        speed: part.state.v,
        acceleration: part.state.a,
        acceleration_vector: part.acceleration,
        blend,
        feed_move: mv.is_feed(),
        spindle: mv.spindle,
        tool: mv.tool,
        fraction: f,
        run,
    }
}
