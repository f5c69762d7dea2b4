//! Lines and polylines in N-D built from 1-D profiles, sampled at any time or tick by tick.

use nalgebra::{ComplexField, SVector};

use super::{
    Limits, MAX_POINTS, MAX_SEGMENTS, MIN_SEGMENT_LENGTH, PathState, PreparedLimits, Profile,
};
use crate::error::{BuildError, TickError};

/// The state of an N-D trajectory at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State<const N: usize> {
    /// Time since the start \[s\].
    pub t: f64,
    /// Index of the segment being travelled (the last one once the motion is over).
    pub segment: usize,
    /// Path length from the start of the whole polyline, speed, acceleration and jerk along
    /// the current segment.
    pub path: PathState,
    /// Position \[m\].
    pub position: SVector<f64, N>,
    /// Velocity \[m/s\].
    pub velocity: SVector<f64, N>,
    /// Acceleration \[m/s^2\]: what the D'Alembert force `-m a` needs.
    pub acceleration: SVector<f64, N>,
    /// Jerk \[m/s^3\].
    pub jerk: SVector<f64, N>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Segment<const N: usize> {
    start: SVector<f64, N>,
    direction: SVector<f64, N>,
    profile: Profile,
    limits: Limits,
    /// Start time \[s\] and path length before the segment \[m\].
    t0: f64,
    s0: f64,
}

/// Per-axis limits of a joint-space (or any N-D) motion: speed, acceleration and jerk of each
/// coordinate \[unit/s, unit/s^2, unit/s^3\]. A straight segment then runs at the largest
/// path speed, acceleration and jerk at which no coordinate exceeds its own limit (all
/// coordinates on one synchronised profile, the path stays straight).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisLimits<const N: usize> {
    /// Largest speed of each coordinate.
    pub v_max: SVector<f64, N>,
    /// Largest acceleration of each coordinate.
    pub a_max: SVector<f64, N>,
    /// Largest jerk of each coordinate.
    pub j_max: SVector<f64, N>,
}

impl<const N: usize> AxisLimits<N> {
    /// The path limits along the unit `direction`: `min_i v_i / |d_i|` and so on.
    fn along(&self, direction: &SVector<f64, N>) -> Result<Limits, BuildError> {
        let mut out = [f64::INFINITY; 3];
        let names = ["v_max", "a_max", "j_max"];
        for ((slot, what), lim) in
            out.iter_mut()
                .zip(names)
                .zip([&self.v_max, &self.a_max, &self.j_max])
        {
            for (i, (&l, &d)) in lim.iter().zip(direction.iter()).enumerate() {
                if !(l.is_normal() && l > 0.0) {
                    return Err(BuildError::InvalidEntry {
                        what,
                        index: i,
                        value: l,
                        expected: "finite and > 0 (not sub-normal)",
                    });
                }
                if d != 0.0 {
                    *slot = slot.min(l / d.abs());
                }
            }
        }
        let [v, a, j] = out;
        Limits::new(v, a, j)
    }
}

/// A rest-to-rest jerk-limited motion along a line or polyline in N-D (1..=8 coordinates:
/// Cartesian points or joint vectors), stopping at every corner. Plan it once, sample it at
/// any time (nothing is stored per tick).
///
/// ```
/// use deflect_core::motion::{Limits, Trajectory};
/// use nalgebra::Vector2;
/// let lim = Limits::new(1.0, 10.0, 1000.0)?;
/// let traj = Trajectory::line(Vector2::new(0.0, 0.0), Vector2::new(0.1, 0.0), &lim)?;
/// let end = traj.sample(traj.duration())?;
/// assert_eq!(end.position, Vector2::new(0.1, 0.0));
/// let ticks = traj.ticks(2000.0)?.count();
/// assert_eq!(ticks, 1 + (traj.duration() * 2000.0).ceil() as usize);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory<const N: usize> {
    segments: heapless::Vec<Segment<N>, MAX_SEGMENTS>,
    start: SVector<f64, N>,
    end: SVector<f64, N>,
    limits: Limits,
    duration: f64,
    path_length: f64,
}

impl<const N: usize> Trajectory<N> {
    /// A straight rest-to-rest move from `start` to `end` (equal points give a zero-duration
    /// trajectory).
    pub fn line(
        start: SVector<f64, N>,
        end: SVector<f64, N>,
        limits: &Limits,
    ) -> Result<Self, BuildError> {
        Self::polyline(&[start, end], limits)
    }

    /// Re-plans this trajectory as [`Self::line`]`(start, end, limits)` in place, bit for bit
    /// the same result: ruckig's habit (`calculate(input, &mut trajectory)`), for a caller
    /// that plans move after move into one trajectory it owns. A trajectory keeps room for
    /// [`MAX_SEGMENTS`] segments inline (4.5-8 KB), and moving that out of [`Self::line`] is
    /// most of its time; here nothing moves and the limits are validated once. On error
    /// `self` is unchanged.
    ///
    /// ```
    /// use deflect_core::motion::{Limits, Trajectory};
    /// use nalgebra::Vector1;
    /// let lim = Limits::new(1.2, 25.0, 600.0)?;
    /// let mut traj = Trajectory::line(Vector1::new(0.0), Vector1::new(0.0), &lim)?;
    /// traj.replan_line(Vector1::new(0.05), Vector1::new(0.35), &lim)?;
    /// assert_eq!(traj, Trajectory::line(Vector1::new(0.05), Vector1::new(0.35), &lim)?);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn replan_line(
        &mut self,
        start: SVector<f64, N>,
        end: SVector<f64, N>,
        limits: &Limits,
    ) -> Result<(), BuildError> {
        self.replan_line_with(start, end, &PreparedLimits::new(limits)?)
    }

    /// [`Self::replan_line`] under limits validated and prepared once ([`PreparedLimits`]):
    /// per move only the length's part of the profile is solved. Bit for bit the same
    /// trajectory; on error `self` is unchanged.
    pub fn replan_line_with(
        &mut self,
        start: SVector<f64, N>,
        end: SVector<f64, N>,
        limits: &PreparedLimits,
    ) -> Result<(), BuildError> {
        for (index, p) in [&start, &end].into_iter().enumerate() {
            if let Some(axis) = p.iter().position(|c| !c.is_finite()) {
                return Err(BuildError::NonFinite {
                    what: "points (flattened, N per point)",
                    index: index * N + axis,
                });
            }
        }
        let d = end - start;
        let length = d.norm();
        let segment = if length <= MIN_SEGMENT_LENGTH {
            None
        } else {
            Some(Segment {
                start,
                direction: d / length,
                profile: limits.profile(length)?,
                limits: *limits.limits(),
                t0: 0.0,
                s0: 0.0,
            })
        };
        self.segments.clear();
        let (duration, path_length) = match segment {
            Some(seg) => {
                let duration = seg.profile.duration();
                // Cannot fail after `clear` (capacity MAX_SEGMENTS >= 1).
                self.segments.push(seg).map_err(|_| BuildError::Capacity {
                    what: "points",
                    capacity: MAX_POINTS,
                    got: 2,
                })?;
                (duration, length)
            }
            None => (0.0, 0.0),
        };
        self.start = start;
        self.end = end;
        self.limits = *limits.limits();
        self.duration = duration;
        self.path_length = path_length;
        Ok(())
    }

    /// Rest-to-rest moves through `points` (2..=[`MAX_POINTS`]), stopping at each one;
    /// segments of length <= [`MIN_SEGMENT_LENGTH`] are skipped. `limits` bound the path
    /// speed, acceleration and jerk (the Euclidean norm of the vector quantities).
    pub fn polyline(points: &[SVector<f64, N>], limits: &Limits) -> Result<Self, BuildError> {
        limits.validate()?;
        Self::plan(points, |_, _| Ok(*limits))
    }

    /// [`Self::polyline`] with limits per segment: `limits[i]` for the move from `points[i]`
    /// to `points[i + 1]` (`points.len() - 1` entries).
    pub fn polyline_with_limits(
        points: &[SVector<f64, N>],
        limits: &[Limits],
    ) -> Result<Self, BuildError> {
        if limits.len() + 1 != points.len() {
            return Err(BuildError::WrongLength {
                what: "limits (one per segment)",
                expected: points.len().saturating_sub(1),
                got: limits.len(),
            });
        }
        for l in limits {
            l.validate()?;
        }
        Self::plan(points, |i, _| {
            limits.get(i).copied().ok_or(BuildError::WrongLength {
                what: "limits (one per segment)",
                expected: points.len().saturating_sub(1),
                got: limits.len(),
            })
        })
    }

    /// Straight moves through `points` under per-coordinate limits (joint space): see
    /// [`AxisLimits`]. The duration of each segment is that of the time-optimal
    /// rest-to-rest profile under the tightest coordinate.
    pub fn polyline_axis_limits(
        points: &[SVector<f64, N>],
        limits: &AxisLimits<N>,
    ) -> Result<Self, BuildError> {
        // Validate every entry once, whatever the directions.
        limits.along(&SVector::from_element(1.0))?;
        Self::plan(points, |_, d| limits.along(d))
    }

    fn plan(
        points: &[SVector<f64, N>],
        limits_of: impl Fn(usize, &SVector<f64, N>) -> Result<Limits, BuildError>,
    ) -> Result<Self, BuildError> {
        let too_few = BuildError::TooFew {
            what: "points",
            needed: 2,
            got: points.len(),
        };
        if points.len() < 2 {
            return Err(too_few);
        }
        let capacity = BuildError::Capacity {
            what: "points",
            capacity: MAX_POINTS,
            got: points.len(),
        };
        if points.len() > MAX_POINTS {
            return Err(capacity);
        }
        for (index, p) in points.iter().enumerate() {
            if let Some(axis) = p.iter().position(|c| !c.is_finite()) {
                return Err(BuildError::NonFinite {
                    what: "points (flattened, N per point)",
                    index: index * N + axis,
                });
            }
        }
        let (Some(&start), Some(&end)) = (points.first(), points.last()) else {
            return Err(too_few);
        };
        let first = limits_of(0, &SVector::from_element(1.0))?;
        let mut segments = heapless::Vec::new();
        let (mut prev, mut t0, mut s0) = (start, 0.0, 0.0);
        for (i, &p) in points.iter().skip(1).enumerate() {
            let d = p - prev;
            let length = d.norm();
            if length <= MIN_SEGMENT_LENGTH {
                continue;
            }
            let direction = d / length;
            let limits = limits_of(i, &direction)?;
            let profile = Profile::new(length, &limits)?;
            let seg = Segment {
                start: prev,
                direction,
                profile,
                limits,
                t0,
                s0,
            };
            segments.push(seg).map_err(|_| capacity)?;
            t0 += profile.duration();
            s0 += length;
            prev = p;
        }
        let limits = segments.first().map_or(first, |s: &Segment<N>| s.limits);
        Ok(Self {
            segments,
            start,
            end,
            limits,
            duration: t0,
            path_length: s0,
        })
    }

    /// Total duration \[s\].
    pub fn duration(&self) -> f64 {
        self.duration
    }
    /// Total path length \[m\].
    pub fn path_length(&self) -> f64 {
        self.path_length
    }
    /// First point.
    pub fn start(&self) -> SVector<f64, N> {
        self.start
    }
    /// Last point (reached exactly at [`Self::duration`]).
    pub fn end(&self) -> SVector<f64, N> {
        self.end
    }
    /// The path limits of the first segment (all segments with [`Self::polyline`]).
    pub fn limits(&self) -> Limits {
        self.limits
    }
    /// The path limits of segment `i`.
    pub fn segment_limits(&self, i: usize) -> Option<Limits> {
        self.segments.get(i).map(|s| s.limits)
    }
    /// Number of (non-skipped) segments.
    pub fn segment_count(&self) -> usize {
        self.segments.len()
    }
    /// The 1-D profile of segment `i`, and its start time \[s\].
    pub fn segment_profile(&self, i: usize) -> Option<(&Profile, f64)> {
        self.segments.get(i).map(|s| (&s.profile, s.t0))
    }

    /// The exact state at `t` \[s\]; before 0 it is the start at rest, from [`Self::duration`]
    /// on the end at rest (exactly the last point).
    pub fn sample(&self, t: f64) -> Result<State<N>, TickError> {
        if !t.is_finite() {
            return Err(TickError::NonFinite {
                what: "t",
                index: 0,
            });
        }
        Ok(self.sample_from(t, 0).0)
    }

    /// Samples at `t` searching segments from `hint` on; returns the segment found.
    fn sample_from(&self, t: f64, hint: usize) -> (State<N>, usize) {
        let rest = |position, segment, s| State {
            t,
            segment,
            path: PathState {
                s,
                ..PathState::default()
            },
            position,
            velocity: SVector::zeros(),
            acceleration: SVector::zeros(),
            jerk: SVector::zeros(),
        };
        let last = self.segments.len().saturating_sub(1);
        if t >= self.duration {
            return (rest(self.end, last, self.path_length), last);
        }
        if t <= 0.0 {
            return (rest(self.start, 0, 0.0), 0);
        }
        // Cursors move forward, so start at the hint and fall back to a full scan.
        let start = if self.segments.get(hint).is_some_and(|s| s.t0 <= t) {
            hint
        } else {
            0
        };
        let mut index = start;
        for (i, seg) in self.segments.iter().enumerate().skip(start) {
            if seg.t0 <= t {
                index = i;
            } else {
                break;
            }
        }
        let Some(seg) = self.segments.get(index) else {
            return (rest(self.end, last, self.path_length), last);
        };
        let p = seg.profile.sample(t - seg.t0);
        let state = State {
            t,
            segment: index,
            path: PathState {
                s: seg.s0 + p.s,
                ..p
            },
            position: seg.start + seg.direction * p.s,
            velocity: seg.direction * p.v,
            acceleration: seg.direction * p.a,
            jerk: seg.direction * p.j,
        };
        (state, index)
    }

    /// A cursor over ticks at `rate_hz` ([`super::DEFAULT_RATE_HZ`] in the paper): tick `k` is at
    /// `t = k / rate_hz`, computed from `k` (no drift), and a last tick lands exactly on
    /// [`Self::duration`] (the end point), so there are `ceil(duration * rate) + 1` ticks.
    /// [`TickError::InvalidArgument`] for a rate that is not finite and > 0,
    /// [`TickError::Budget`] past [`MAX_TICKS`](super::MAX_TICKS).
    pub fn ticks(&self, rate_hz: f64) -> Result<Cursor<'_, N>, TickError> {
        Ok(Cursor {
            trajectory: self,
            data: Data::new(self, rate_hz)?,
        })
    }

    /// Number of ticks at `rate_hz` (see [`Self::ticks`]), at most [`MAX_TICKS`](super::MAX_TICKS).
    pub fn tick_count(&self, rate_hz: f64) -> Result<usize, TickError> {
        super::tick_count(self.duration, rate_hz)
    }

    /// [`Self::tick_count`] for a call that stores every tick: [`TickError::Budget`] past
    /// [`MAX_SAMPLES`](super::MAX_SAMPLES), so that nothing allocates more than that documents (the one budget
    /// such calls report, however far past it the request is).
    pub fn sample_count(&self, rate_hz: f64) -> Result<usize, TickError> {
        super::sample_count(self.duration, rate_hz)
    }
}

/// The per-tick state of sampling a [`Trajectory`] at a fixed rate: the tick counter and the
/// segment the last tick fell in (the next search starts there). `Copy`, no borrow of the
/// trajectory, so a controller (or the C API) keeps it beside the trajectory; [`step`]
/// advances it, [`Cursor`] wraps both as an iterator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Data {
    rate_hz: f64,
    /// Duration of the trajectory it was made for \[s\] ([`Self::check`]).
    duration: f64,
    next: usize,
    last: usize,
    hint: usize,
    done: bool,
}

impl Data {
    /// The state before the first tick of `model` sampled at `rate_hz`: tick `k` is at
    /// `t = k / rate_hz`, computed from `k` (no drift), and a last tick lands exactly on
    /// [`Trajectory::duration`] (the end point), so there are `ceil(duration * rate) + 1`
    /// ticks. [`TickError::InvalidArgument`] for a rate that is not finite and > 0,
    /// [`TickError::Budget`] past [`MAX_TICKS`](super::MAX_TICKS).
    pub fn new<const N: usize>(model: &Trajectory<N>, rate_hz: f64) -> Result<Self, TickError> {
        let count = model.tick_count(rate_hz)?;
        Ok(Self {
            rate_hz,
            duration: model.duration,
            next: 0,
            last: count.saturating_sub(1),
            hint: 0,
            done: false,
        })
    }

    /// Whether this state was made for a trajectory of `model`'s duration.
    pub fn check<const N: usize>(&self, model: &Trajectory<N>) -> bool {
        self.duration.to_bits() == model.duration.to_bits()
    }

    /// The sampling rate \[Hz\].
    pub fn rate_hz(&self) -> f64 {
        self.rate_hz
    }
    /// Ticks already returned.
    pub fn ticks_done(&self) -> usize {
        self.next
    }
    /// `true` once the final tick has been returned.
    pub fn is_finished(&self) -> bool {
        self.done
    }
    /// Ticks left, including the final one.
    pub fn remaining(&self) -> usize {
        if self.done {
            0
        } else {
            self.last.saturating_sub(self.next).saturating_add(1)
        }
    }

    /// The next tick of `model` (made for it: the caller checked), or `None` after the last.
    fn advance<const N: usize>(&mut self, model: &Trajectory<N>) -> Option<State<N>> {
        if self.done {
            return None;
        }
        let k = self.next;
        let t = if k >= self.last {
            self.done = true;
            model.duration
        } else {
            (k as f64 / self.rate_hz).min(model.duration)
        };
        self.next = k.saturating_add(1);
        let (state, seg) = model.sample_from(t, self.hint);
        self.hint = seg;
        Some(state)
    }
}

/// One tick of sampling: the state of the next tick of `model`, or `None` after the final
/// tick (at the end point). [`TickError::ModelMismatch`] when `data` was made for another
/// trajectory. Closed form, allocation-free, bounded by the segment count.
pub fn step<const N: usize>(
    model: &Trajectory<N>,
    data: &mut Data,
) -> Result<Option<State<N>>, TickError> {
    if !data.check(model) {
        return Err(TickError::ModelMismatch {
            what: "ticks (the data was made for a trajectory of another duration)",
            expected: model.tick_count(data.rate_hz).unwrap_or(0),
            got: data.last.saturating_add(1),
        });
    }
    Ok(data.advance(model))
}

/// Steps through a [`Trajectory`] tick by tick ([`Trajectory::ticks`]): the trajectory and its
/// [`Data`] as an [`Iterator`] of [`State`]s that a 2 kHz loop can also drive one
/// [`Cursor::step`] at a time.
#[derive(Debug, Clone)]
pub struct Cursor<'a, const N: usize> {
    trajectory: &'a Trajectory<N>,
    data: Data,
}

impl<const N: usize> Cursor<'_, N> {
    /// The next tick's state, or `None` after the final tick (at the end point).
    pub fn step(&mut self) -> Option<State<N>> {
        self.data.advance(self.trajectory)
    }
    /// Ticks already returned.
    pub fn ticks_done(&self) -> usize {
        self.data.ticks_done()
    }
    /// `true` once the final tick has been returned.
    pub fn is_finished(&self) -> bool {
        self.data.is_finished()
    }
    /// Ticks left, including the final one.
    pub fn remaining(&self) -> usize {
        self.data.remaining()
    }
}

impl<const N: usize> Iterator for Cursor<'_, N> {
    type Item = State<N>;
    fn next(&mut self) -> Option<State<N>> {
        self.step()
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.remaining();
        (n, Some(n))
    }
}

impl<const N: usize> ExactSizeIterator for Cursor<'_, N> {}
