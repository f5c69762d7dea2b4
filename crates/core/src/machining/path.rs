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
//! is what a prediction of the machined part needs; the price is the stop at each corner,
//! which a real controller's blending would shorten (the program's `G64` tolerance is
//! recorded per move, [`super::PathControl`], not yet used here). A dwell (`G4`, a drilling
//! cycle's pause) holds the tool at rest for its time between two runs.

use alloc::vec::Vec;

use nalgebra::{ComplexField, Vector3};

use super::{Motion, Program};
use crate::error::{BuildError, param};
use crate::motion::{Limits, Profile};

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
}

impl Default for PathOptions {
    /// 250 Hz (the 4 ms cycle), 2 m/s^2, 20 m/s^3, rapids at 0.25 m/s, 1 degree.
    fn default() -> Self {
        Self {
            rate_hz: 250.0,
            acceleration: 2.0,
            jerk: 20.0,
            rapid_speed: 0.25,
            corner_angle: 1.0_f64.to_radians(),
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
        Ok(())
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
    /// Path acceleration \[m/s^2\].
    pub acceleration: f64,
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

/// One rest-to-rest profile over the moves `segs[first..=last]`, or a dwell of `hold`
/// seconds at the one move `segs[first]` (then `profile` is the zero-length profile).
#[derive(Debug, Clone, Copy)]
struct Run {
    first: usize,
    last: usize,
    t0: f64,
    profile: Profile,
    hold: f64,
}

impl Run {
    fn duration(&self) -> f64 {
        self.profile.duration() + self.hold
    }
}

/// The program planned: the moves with motion (`segs`, indices into the program), the arc
/// length at which each starts within its run (`s0`, parallel to `segs`), and the runs.
#[derive(Debug, Clone)]
struct Plan {
    segs: Vec<usize>,
    s0: Vec<f64>,
    runs: Vec<Run>,
}

impl Plan {
    fn duration(&self) -> f64 {
        self.runs.last().map_or(0.0, |r| r.t0 + r.duration())
    }
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

impl Iterator for Sampler<'_> {
    type Item = PathSample;

    fn next(&mut self) -> Option<PathSample> {
        if self.tick >= self.count {
            return None;
        }
        let plan = &self.plan;
        let t = (self.tick as f64 / self.rate_hz).min(self.total);
        self.tick += 1;
        while self.run + 1 < plan.runs.len()
            && plan
                .runs
                .get(self.run)
                .is_some_and(|run| t > run.t0 + run.duration())
        {
            self.run += 1;
        }
        let run = plan.runs.get(self.run)?;
        let state = run.profile.sample(t - run.t0);
        // The move holding arc length `s`: the last one of the run starting at or before it.
        self.seg = self.seg.max(run.first);
        while self.seg < run.last && plan.s0.get(self.seg + 1).is_some_and(|&s| state.s >= s) {
            self.seg += 1;
        }
        let (&m, &s) = (plan.segs.get(self.seg)?, plan.s0.get(self.seg)?);
        let mv = self.program.moves.get(m)?;
        let length = mv.length();
        let fraction = if length > 0.0 {
            (state.s - s) / length
        } else {
            0.0
        };
        Some(PathSample {
            time: t,
            move_index: m,
            line: mv.line,
            position: mv.point(fraction),
            direction: mv.tangent(fraction.clamp(0.0, 1.0)),
            axis: mv.axis(fraction.clamp(0.0, 1.0)),
            speed: state.v,
            acceleration: state.a,
            feed_move: mv.is_feed(),
            spindle: mv.spindle,
            tool: mv.tool,
            fraction: fraction.clamp(0.0, 1.0),
            run: self.run,
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.count - self.tick;
        (left, Some(left))
    }
}

/// How far the stock's cut may leave the programmed path between two samples \[m\]: 1 um. An
/// arc is cut along chords whose sagitta stays below it (at the 4 ms cycle a sample's chord
/// on a 10 mm arc at 25 mm/s has 0.13 um, so none is added there).
pub const WAYPOINT_TOLERANCE: f64 = 1.0e-6;

/// Most chords one arc is cut into between two samples: past it (a kilometre arc at one
/// sample per second) its chords' sagitta exceeds [`WAYPOINT_TOLERANCE`].
pub const MAX_ARC_CHORDS: usize = 4096;

/// The points where the programmed path bends strictly between two samples at `from` and
/// `to` (each `(move index, fraction)` of [`PathSample`], `from` not after `to`): every
/// move's end between them and the points that cut each arc into chords within
/// [`WAYPOINT_TOLERANCE`]. Calls `visit(point, move index, share)` in path order, `share` the
/// part of the path's length from `from` to the point (0..1), the move index that of the
/// move the segment *ending* at the point lies on; returns how many points it visited. None
/// for two samples on one straight move. Allocation-free.
pub fn between(
    program: &Program,
    from: (usize, f64),
    to: (usize, f64),
    mut visit: impl FnMut(Vector3<f64>, usize, f64),
) -> usize {
    let (m0, f0) = from;
    let (m1, f1) = to;
    if m1 < m0 || (m1 == m0 && f1 <= f0) {
        return 0;
    }
    // The stretches of moves between the samples: (move, fraction from, fraction to).
    let stretch = |m: usize| -> (f64, f64) {
        let a = if m == m0 { f0 } else { 0.0 };
        let b = if m == m1 { f1 } else { 1.0 };
        (a, b)
    };
    // Chords per stretch of an arc, so that each one's sagitta is within the tolerance.
    let chords = |mv: &super::Move, a: f64, b: f64| -> usize {
        match mv.motion {
            super::Motion::Arc { sweep, .. } => {
                let r = mv.radius().max(mv.end_radius());
                if r.is_nan() || r <= WAYPOINT_TOLERANCE {
                    return 1;
                }
                let step = 2.0 * ComplexField::acos(1.0 - WAYPOINT_TOLERANCE / r);
                let angle = ComplexField::abs(sweep) * (b - a);
                let n = ComplexField::ceil(angle / step);
                if n.is_finite() && n >= 1.0 {
                    (n as usize).min(MAX_ARC_CHORDS)
                } else {
                    1
                }
            }
            _ => 1,
        }
    };
    let moves = program.moves.get(m0..=m1).unwrap_or(&[]);
    let total: f64 = moves
        .iter()
        .zip(m0..)
        .map(|(mv, m)| {
            let (a, b) = stretch(m);
            mv.length() * (b - a)
        })
        .sum();
    let mut done = 0.0;
    let mut count = 0;
    for (mv, m) in moves.iter().zip(m0..) {
        let (a, b) = stretch(m);
        let n = chords(mv, a, b);
        let length = mv.length() * (b - a);
        for k in 1..=n {
            // The stretch's inner chord ends, and its end unless it is the sample itself.
            if k == n && m == m1 {
                break;
            }
            let f = a + (b - a) * k as f64 / n as f64;
            let share = if total > 0.0 {
                (done + length * k as f64 / n as f64) / total
            } else {
                0.0
            };
            visit(mv.point(f), m, share.clamp(0.0, 1.0));
            count += 1;
        }
        done += length;
    }
    count
}
