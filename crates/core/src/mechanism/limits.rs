//! Joint limits: one check, one tolerance, for every place a joint command is compared with
//! its range (the serial D'Alembert corrector, the machining job, the posture sweep).
//!
//! An iterative IK converges to a tolerance, not to the exact value: a motion that starts on a
//! limit (a range `[0, x]` with the joint at 0, as the Unitree Z1's elbow) lands a few 1e-9 rad
//! past it by rounding alone. A command within [`JOINT_LIMIT_TOLERANCE`] of its range counts
//! as inside and is passed on as computed (not clamped: the controller sees what the model
//! asked for).

use crate::error::TickError;

/// Slack on joint limits \[rad or m\]: 1e-6, below any joint encoder's resolution (a 20-bit
/// absolute encoder resolves 6e-6 rad) and far above the pose IK's rounding (its 1e-8 m
/// tolerance over a lever of 0.1 m or more is at most 1e-7 rad).
pub const JOINT_LIMIT_TOLERANCE: f64 = 1.0e-6;

/// `Ok` when every `q[i]` lies in `limits[i]` widened by `tolerance` \[rad or m\] (extra
/// entries of either are ignored); else [`TickError::JointLimit`] naming the first joint past
/// its range. A NaN joint is outside.
pub fn check_limits(q: &[f64], limits: &[(f64, f64)], tolerance: f64) -> Result<(), TickError> {
    for (joint, (&value, &(lower, upper))) in q.iter().zip(limits).enumerate() {
        let inside = value >= lower - tolerance && value <= upper + tolerance;
        if !inside {
            return Err(TickError::JointLimit {
                joint,
                value,
                lower,
                upper,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_starting_at_zero_takes_rounding_below_it_and_nothing_more() {
        let limits = [(0.0, 2.967)];
        // The Z1's first tick: 1.59e-9 rad below a range [0, 2.967].
        assert!(check_limits(&[-1.59e-9], &limits, JOINT_LIMIT_TOLERANCE).is_ok());
        assert!(check_limits(&[2.967 + 0.9e-6], &limits, JOINT_LIMIT_TOLERANCE).is_ok());
        for bad in [-1.1e-6, 2.967 + 1.1e-6, f64::NAN] {
            let e = check_limits(&[bad], &limits, JOINT_LIMIT_TOLERANCE).unwrap_err();
            assert!(
                matches!(e, TickError::JointLimit { joint: 0, lower, upper, .. }
                if lower == 0.0 && upper == 2.967)
            );
        }
        // Exact comparison when asked.
        assert!(check_limits(&[-1e-12], &limits, 0.0).is_err());
        // The first joint past its range is named.
        let e = check_limits(&[0.1, 5.0, 9.0], &[(0.0, 1.0), (0.0, 1.0), (0.0, 1.0)], 0.0);
        assert!(matches!(e, Err(TickError::JointLimit { joint: 1, .. })));
    }
}
