//! The scenario's pose motions, sampled at the servo rate: a straight line with a turn about
//! the vertical (deflect-core's `PoseTrajectory`) and a horizontal circle whose orientation
//! turns about the vertical in proportion to the arc (a jerk-limited profile along the arc,
//! deflect-core's `Profile`), both rest to rest, with velocity, acceleration, angular
//! velocity and angular acceleration per tick.

use deflect_core::motion::{Limits, PoseLimits, PoseState, PoseTrajectory, Profile};
use deflect_core::units::STANDARD_GRAVITY;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::Serialize;

use crate::SimError;

/// Which path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum PathKind {
    /// A straight line with a turn about the vertical.
    Line,
    /// A horizontal circle with a turn about the vertical.
    Circle,
}

impl PathKind {
    /// "line" / "circle".
    pub fn label(self) -> &'static str {
        match self {
            Self::Line => "line",
            Self::Circle => "circle",
        }
    }
}

/// Size and pace of the motions.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MotionParams {
    /// Peak acceleration \[g\] (translation; the circle's tangential and centripetal parts each
    /// stay below it).
    pub g: f64,
    /// Length scale \[m\]: the line moves `(0.3, 0.2, -0.1) * scale`, the circle's radius is
    /// `0.15 * scale`.
    pub scale: f64,
    /// Time to ramp the acceleration up (jerk-limited) \[s\].
    pub ramp: f64,
    /// Turn about the vertical over the whole motion \[rad\].
    pub turn: f64,
    /// Largest speed \[m/s\].
    pub v_max: f64,
}

impl MotionParams {
    /// The acceleration \[m/s^2\].
    pub fn accel(&self) -> f64 {
        self.g * STANDARD_GRAVITY
    }
}

/// Every tick of a line from `start` (see [`MotionParams`]) at `rate_hz`.
pub fn line(
    start: &Isometry3<f64>,
    p: &MotionParams,
    rate_hz: f64,
) -> Result<Vec<PoseState>, SimError> {
    let a = p.accel();
    let end = Isometry3::from_parts(
        Translation3::from(start.translation.vector + Vector3::new(0.3, 0.2, -0.1) * p.scale),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), p.turn) * start.rotation,
    );
    let limits = PoseLimits {
        linear: Limits::new(p.v_max, a, a / p.ramp)?,
        // The turn keeps pace with the translation: its limits are never the tighter ones
        // by much (about one radian per metre).
        angular: Limits::new(p.v_max / p.scale, a / p.scale, a / (p.ramp * p.scale))?,
    };
    let traj = PoseTrajectory::line(start, &end, &limits)?;
    let n = traj.sample_count(rate_hz)?;
    (0..n)
        .map(|k| {
            traj.sample(traj.tick_time(rate_hz, k, n))
                .map_err(SimError::from)
        })
        .collect()
}

/// The circle's centre and radius for a start pose: the start lies on the circle, the
/// centre `radius` towards the base axis (horizontally).
pub fn circle_geometry(start: &Isometry3<f64>, p: &MotionParams) -> (Vector3<f64>, f64) {
    let r = 0.15 * p.scale;
    let s = start.translation.vector;
    let out = Vector3::new(s.x, s.y, 0.0);
    let dir = if out.norm() > 1e-9 {
        out.normalize()
    } else {
        Vector3::x()
    };
    (s - dir * r, r)
}

/// Every tick of a full horizontal circle through `start` at `rate_hz` (see the module docs):
/// the speed is limited so that the centripetal acceleration stays within the peak.
pub fn circle(
    start: &Isometry3<f64>,
    p: &MotionParams,
    rate_hz: f64,
) -> Result<Vec<PoseState>, SimError> {
    let a = p.accel();
    let (c, r) = circle_geometry(start, p);
    let length = 2.0 * core::f64::consts::PI * r;
    let v = p.v_max.min((0.8 * a * r).sqrt());
    let profile = Profile::new(length, &Limits::new(v, 0.8 * a, 0.8 * a / p.ramp)?)?;
    let phi0 = {
        let d = start.translation.vector - c;
        d.y.atan2(d.x)
    };
    let z = start.translation.vector.z;
    let k_turn = p.turn / length;
    let duration = profile.duration();
    let n = (duration * rate_hz - 1e-9).ceil().max(0.0) as usize + 1;
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let t = if k + 1 == n {
            duration
        } else {
            k as f64 / rate_hz
        };
        let st = profile.sample(t);
        let phi = phi0 + st.s / r;
        let (sn, cs) = phi.sin_cos();
        let radial = Vector3::new(cs, sn, 0.0);
        let tangent = Vector3::new(-sn, cs, 0.0);
        let position = Vector3::new(c.x + r * cs, c.y + r * sn, z);
        let angle = k_turn * st.s;
        out.push(PoseState {
            t,
            pose: Isometry3::from_parts(
                Translation3::from(position),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle) * start.rotation,
            ),
            velocity: tangent * st.v,
            acceleration: tangent * st.a - radial * (st.v * st.v / r),
            angular_velocity: Vector3::z() * (k_turn * st.v),
            angular_acceleration: Vector3::z() * (k_turn * st.a),
        });
    }
    Ok(out)
}

/// Distance \[m\] of `p` from the planned path of `kind` (the line segment, or the circle).
pub fn path_distance(
    kind: PathKind,
    start: &Isometry3<f64>,
    params: &MotionParams,
    p: &Vector3<f64>,
) -> f64 {
    match kind {
        PathKind::Line => {
            let a = start.translation.vector;
            let d = Vector3::new(0.3, 0.2, -0.1) * params.scale;
            let s = ((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
            (p - (a + d * s)).norm()
        }
        PathKind::Circle => {
            let (c, r) = circle_geometry(start, params);
            let d = p - c;
            let radial = (d.x * d.x + d.y * d.y).sqrt() - r;
            (radial * radial + d.z * d.z).sqrt()
        }
    }
}
