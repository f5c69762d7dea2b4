//! The time-optimal jerk-limited rest-to-rest 1-D profile (closed form in the module docs).

use nalgebra::ComplexField;

use super::Limits;
use crate::error::{BuildError, param};

/// Position, velocity, acceleration and jerk along a path (scalars) \[m, m/s, m/s^2, m/s^3\].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PathState {
    /// Path length covered \[m\].
    pub s: f64,
    /// Path speed \[m/s\].
    pub v: f64,
    /// Path acceleration \[m/s^2\].
    pub a: f64,
    /// Path jerk \[m/s^3\].
    pub j: f64,
}

/// A time-optimal jerk-limited rest-to-rest 1-D profile from 0 to `length` (see the module
/// docs for the closed form).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    length: f64,
    jerk: f64,
    t_v: f64,
    // t_j, t_a and the state at the end of phases 1, 2, 3 (end of the acceleration half).
    phases: Phases,
}

/// Path limits validated once, with the part of the profile that does not depend on the
/// length solved once: the acceleration half that reaches `v_max` (cases 1 and 2 of the
/// closed form). A planner that plans move after move under the same limits (Python's
/// `LinePlanner`, [`super::Trajectory::replan_line_with`]) builds this once and solves only
/// the length's part per move. [`Self::profile`] is bit for bit [`Profile::new`]: both are
/// the same arithmetic on the same numbers, only kept from the first call.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreparedLimits {
    limits: Limits,
    // The acceleration half that reaches v_max: its jerk and acceleration phase durations
    // (t_a as solved, before clamping at 0), and the distance of both halves.
    t_j: f64,
    t_a: f64,
    d_v: f64,
    // Its phase-end states, from t_a clamped at 0: what every move of length >= d_v uses.
    cruise: Phases,
}

/// `t_j`, `t_a` (clamped at 0) and the states at the end of phases 1, 2, 3.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Phases {
    t_j: f64,
    t_a: f64,
    s1: f64,
    v1: f64,
    s2: f64,
    v2: f64,
    s3: f64,
    v3: f64,
}

impl Phases {
    fn new(j: f64, t_j: f64, t_a: f64) -> Self {
        let t_a = t_a.max(0.0);
        let ap = j * t_j;
        let s1 = j * t_j * t_j * t_j / 6.0;
        let v1 = 0.5 * j * t_j * t_j;
        let s2 = s1 + v1 * t_a + 0.5 * ap * t_a * t_a;
        let v2 = v1 + ap * t_a;
        let s3 = s2 + v2 * t_j + 0.5 * ap * t_j * t_j - j * t_j * t_j * t_j / 6.0;
        let v3 = v2 + ap * t_j - 0.5 * j * t_j * t_j;
        Self {
            t_j,
            t_a,
            s1,
            v1,
            s2,
            v2,
            s3,
            v3,
        }
    }
}

impl PreparedLimits {
    /// `limits` validated ([`Limits::validate`]) and the length-independent part solved.
    pub fn new(limits: &Limits) -> Result<Self, BuildError> {
        limits.validate()?;
        let (v, a, j) = (limits.v_max, limits.a_max, limits.j_max);
        // Acceleration half that reaches v_max (cases 1 and 2).
        let (t_j, t_a) = if a * a / j <= v {
            (a / j, v / a - a / j)
        } else {
            (ComplexField::sqrt(v / j), 0.0)
        };
        let a_peak = j * t_j;
        // Distance of the acceleration and deceleration halves together.
        let d_v = a_peak * (t_j + t_a) * (2.0 * t_j + t_a);
        Ok(Self {
            limits: *limits,
            t_j,
            t_a,
            d_v,
            cruise: Phases::new(j, t_j, t_a),
        })
    }

    /// The validated limits.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The profile over `length` \[m\] (finite, >= 0; 0 gives a zero-duration profile).
    pub fn profile(&self, length: f64) -> Result<Profile, BuildError> {
        param(
            "profile length",
            length,
            length >= 0.0,
            "finite and >= 0 (m)",
        )?;
        let (a, j) = (self.limits.a_max, self.limits.j_max);
        let p = if length < self.d_v {
            let (t_j, t_a) = if length >= 2.0 * a * a * a / (j * j) {
                // Case 3.
                let t_j = a / j;
                (
                    t_j,
                    0.5 * (ComplexField::sqrt(t_j * t_j + 4.0 * length / a) - 3.0 * t_j),
                )
            } else {
                // Case 4.
                (ComplexField::cbrt(length / (2.0 * j)), 0.0)
            };
            Phases::new(j, t_j, t_a)
        } else {
            self.cruise
        };
        let t_v = if p.v3 > 0.0 {
            ((length - 2.0 * p.s3) / p.v3).max(0.0)
        } else {
            0.0
        };
        // Limits far outside any machine (a sub-normal v_max, a jerk of 1e-300) overflow the
        // closed form; refuse them rather than plan a motion of infinite duration.
        let duration = 2.0 * (2.0 * p.t_j + p.t_a) + t_v;
        let reached = 2.0 * p.s3 + p.v3 * t_v;
        if !(duration.is_finite()
            && p.s3.is_finite()
            && p.v3.is_finite()
            && (reached - length).abs() <= 1.0e-9 * length.max(f64::MIN_POSITIVE))
        {
            return Err(BuildError::InvalidParameter {
                what: "limits (the motion's duration overflows)",
                value: duration,
                expected: "limits that give a finite duration",
            });
        }
        if duration > super::MAX_DURATION {
            return Err(BuildError::InvalidParameter {
                what: "limits (the motion lasts longer than MAX_DURATION)",
                value: duration,
                expected: "limits that move the length within MAX_DURATION = 1e6 s",
            });
        }
        Ok(Profile {
            length,
            jerk: j,
            t_v,
            phases: p,
        })
    }
}

impl Profile {
    /// The profile over `length` \[m\] (finite, >= 0; 0 gives a zero-duration profile).
    /// Planning many lengths under the same limits: [`PreparedLimits`].
    pub fn new(length: f64, limits: &Limits) -> Result<Self, BuildError> {
        PreparedLimits::new(limits)?.profile(length)
    }

    /// Path length \[m\].
    pub fn length(&self) -> f64 {
        self.length
    }
    /// Duration of each of the four constant-jerk phases \[s\].
    pub fn t_j(&self) -> f64 {
        self.phases.t_j
    }
    /// Duration of each of the two constant-acceleration phases \[s\].
    pub fn t_a(&self) -> f64 {
        self.phases.t_a
    }
    /// Duration of the constant-velocity phase \[s\].
    pub fn t_v(&self) -> f64 {
        self.t_v
    }
    /// Acceleration (= deceleration) time `2 t_j + t_a` \[s\].
    pub fn accel_time(&self) -> f64 {
        2.0 * self.phases.t_j + self.phases.t_a
    }
    /// Total duration `2 (2 t_j + t_a) + t_v` \[s\].
    pub fn duration(&self) -> f64 {
        2.0 * self.accel_time() + self.t_v
    }
    /// Peak speed \[m/s\] (`v_max` unless the path is too short).
    pub fn v_peak(&self) -> f64 {
        self.phases.v3
    }
    /// Peak acceleration \[m/s^2\] (`a_max` unless the path or `v_max` is too small).
    pub fn a_peak(&self) -> f64 {
        self.jerk * self.phases.t_j
    }
    /// Phase durations `[t_j, t_a, t_j, t_v, t_j, t_a, t_j]` \[s\].
    pub fn phase_durations(&self) -> [f64; 7] {
        let (tj, ta) = (self.phases.t_j, self.phases.t_a);
        [tj, ta, tj, self.t_v, tj, ta, tj]
    }

    /// The state at `t` \[s\], clamped to rest at 0 before the start and at `length` after the
    /// end (NaN counts as before the start; [`super::Trajectory::sample`] rejects it).
    pub fn sample(&self, t: f64) -> PathState {
        let total = self.duration();
        // `!(t > 0)` also catches NaN.
        if t.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return PathState::default();
        }
        if t >= total {
            return PathState {
                s: self.length,
                ..PathState::default()
            };
        }
        if t <= 0.5 * total {
            self.first_half(t)
        } else {
            let m = self.first_half(total - t);
            PathState {
                s: self.length - m.s,
                v: m.v,
                a: -m.a,
                j: m.j,
            }
        }
    }

    /// Acceleration half and cruise, integrated forward from rest.
    fn first_half(&self, t: f64) -> PathState {
        let (j, tj, ta) = (self.jerk, self.phases.t_j, self.phases.t_a);
        let ap = j * tj;
        if t < tj {
            PathState {
                s: j * t * t * t / 6.0,
                v: 0.5 * j * t * t,
                a: j * t,
                j,
            }
        } else if t < tj + ta {
            let d = t - tj;
            PathState {
                s: self.phases.s1 + self.phases.v1 * d + 0.5 * ap * d * d,
                v: self.phases.v1 + ap * d,
                a: ap,
                j: 0.0,
            }
        } else if t < 2.0 * tj + ta {
            let d = t - tj - ta;
            PathState {
                s: self.phases.s2 + self.phases.v2 * d + 0.5 * ap * d * d - j * d * d * d / 6.0,
                v: self.phases.v2 + ap * d - 0.5 * j * d * d,
                a: ap - j * d,
                j: -j,
            }
        } else {
            let d = t - (2.0 * tj + ta);
            PathState {
                s: self.phases.s3 + self.phases.v3 * d,
                v: self.phases.v3,
                a: 0.0,
                j: 0.0,
            }
        }
    }
}
