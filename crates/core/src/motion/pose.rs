//! A 6-D pose motion: the TCP position along a straight line and its orientation turned
//! about one fixed axis (base frame) by a jerk-limited angle, both on one synchronised
//! profile, so the motion is rest-to-rest, time-optimal for its limits and the orientation
//! path is the geodesic between the two orientations.

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use super::{Limits, Profile};
use crate::error::{BuildError, TickError};

/// Limits of a pose motion: `linear` on the TCP's path (\[m/s, m/s^2, m/s^3\]) and `angular`
/// on its rotation angle (\[rad/s, rad/s^2, rad/s^3\]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseLimits {
    /// Translation limits.
    pub linear: Limits,
    /// Rotation limits.
    pub angular: Limits,
}

/// The state of a pose motion at one time, base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseState {
    /// Time since the start \[s\].
    pub t: f64,
    /// TCP pose.
    pub pose: Isometry3<f64>,
    /// TCP velocity \[m/s\].
    pub velocity: Vector3<f64>,
    /// TCP acceleration \[m/s^2\].
    pub acceleration: Vector3<f64>,
    /// Angular velocity \[rad/s\].
    pub angular_velocity: Vector3<f64>,
    /// Angular acceleration \[rad/s^2\].
    pub angular_acceleration: Vector3<f64>,
}

impl PoseState {
    /// At rest at `pose`.
    pub fn at_rest(t: f64, pose: Isometry3<f64>) -> Self {
        Self {
            t,
            pose,
            velocity: Vector3::zeros(),
            acceleration: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
            angular_acceleration: Vector3::zeros(),
        }
    }
}

/// A rest-to-rest pose motion from `start` to `end` (see the module docs). The normalised
/// progress `u(t)` from 0 to 1 follows one time-optimal jerk-limited profile whose limits are
/// the tighter of `linear / L` and `angular / theta` (`L` the distance, `theta` the rotation
/// angle), so neither part exceeds its limits and both start and stop together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseTrajectory {
    start: Isometry3<f64>,
    end: Isometry3<f64>,
    delta: Vector3<f64>,
    axis: Unit<Vector3<f64>>,
    angle: f64,
    profile: Profile,
}

impl PoseTrajectory {
    /// Plans the motion. Limits must be finite and > 0; the poses finite.
    pub fn line(
        start: &Isometry3<f64>,
        end: &Isometry3<f64>,
        limits: &PoseLimits,
    ) -> Result<Self, BuildError> {
        limits.linear.validate()?;
        limits.angular.validate()?;
        for (what, iso) in [("start pose", start), ("end pose", end)] {
            if let Some(index) = iso
                .translation
                .vector
                .iter()
                .chain(iso.rotation.coords.iter())
                .position(|v| !v.is_finite())
            {
                return Err(BuildError::NonFinite { what, index });
            }
        }
        let delta = end.translation.vector - start.translation.vector;
        let length = delta.norm();
        let turn = end.rotation * start.rotation.inverse();
        let (axis, angle) = turn.axis_angle().unwrap_or((Vector3::z_axis(), 0.0));
        // Normalised progress: per-quantity limits divided by the extent they drive.
        let scale = |lin: f64, ang: f64| {
            let a = if length > 0.0 {
                lin / length
            } else {
                f64::INFINITY
            };
            let b = if angle > 0.0 {
                ang / angle
            } else {
                f64::INFINITY
            };
            a.min(b)
        };
        let (l, r) = (&limits.linear, &limits.angular);
        let (v, a, j) = (
            scale(l.v_max, r.v_max),
            scale(l.a_max, r.a_max),
            scale(l.j_max, r.j_max),
        );
        let progress = if v.is_finite() {
            Limits::new(v, a, j)?
        } else {
            // Nothing moves: a zero-duration profile under any limits.
            Limits::new(1.0, 1.0, 1.0)?
        };
        let extent = if v.is_finite() { 1.0 } else { 0.0 };
        Ok(Self {
            start: *start,
            end: *end,
            delta,
            axis,
            angle,
            profile: Profile::new(extent, &progress)?,
        })
    }

    /// Duration \[s\].
    pub fn duration(&self) -> f64 {
        self.profile.duration()
    }
    /// Start pose.
    pub fn start(&self) -> Isometry3<f64> {
        self.start
    }
    /// End pose (reached exactly at [`Self::duration`]).
    pub fn end(&self) -> Isometry3<f64> {
        self.end
    }
    /// The fixed rotation axis (base frame) and the total angle \[rad\] in `[0, pi]`.
    pub fn rotation(&self) -> (Unit<Vector3<f64>>, f64) {
        (self.axis, self.angle)
    }

    /// The exact state at `t` \[s\] (at rest before 0 and from the duration on).
    pub fn sample(&self, t: f64) -> Result<PoseState, TickError> {
        if !t.is_finite() {
            return Err(TickError::NonFinite {
                what: "t",
                index: 0,
            });
        }
        if t >= self.duration() {
            return Ok(PoseState::at_rest(t, self.end));
        }
        if t <= 0.0 {
            return Ok(PoseState::at_rest(t, self.start));
        }
        let u = self.profile.sample(t);
        let w = self.axis.into_inner() * self.angle;
        let rotation =
            UnitQuaternion::from_axis_angle(&self.axis, u.s * self.angle) * self.start.rotation;
        let position = self.start.translation.vector + self.delta * u.s;
        Ok(PoseState {
            t,
            pose: Isometry3::from_parts(Translation3::from(position), rotation),
            velocity: self.delta * u.v,
            acceleration: self.delta * u.a,
            angular_velocity: w * u.v,
            angular_acceleration: w * u.a,
        })
    }

    /// Number of ticks at `rate_hz`, as [`super::Trajectory::tick_count`]: tick `k` at
    /// `k / rate_hz`, the last exactly at the duration; [`TickError::Budget`] past
    /// [`MAX_TICKS`](super::MAX_TICKS).
    pub fn tick_count(&self, rate_hz: f64) -> Result<usize, TickError> {
        super::tick_count(self.duration(), rate_hz)
    }

    /// [`Self::tick_count`] for a call that stores every tick: [`TickError::Budget`] past
    /// [`super::MAX_SAMPLES`] (the one budget such calls report).
    pub fn sample_count(&self, rate_hz: f64) -> Result<usize, TickError> {
        super::sample_count(self.duration(), rate_hz)
    }

    /// Time of tick `k` of `count` at `rate_hz` (the last tick exactly at the duration).
    pub fn tick_time(&self, rate_hz: f64, k: usize, count: usize) -> f64 {
        if k + 1 >= count {
            self.duration()
        } else {
            (k as f64 / rate_hz).min(self.duration())
        }
    }
}
