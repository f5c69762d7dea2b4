//! Tier 2: a per-tick call refused its input or could not finish.

use core::fmt;

/// Why a per-tick call refused its input or could not finish. `Copy`, never a panic; each
/// variant has one C status code (`DEFLECT_ERR_*` of the C API).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum TickError {
    /// An input slice has the wrong length.
    WrongLength {
        /// Which input ("q", "wrench", ...).
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Length received.
        got: usize,
    },
    /// An input holds NaN or an infinity.
    NonFinite {
        /// Which input.
        what: &'static str,
        /// Index of the first non-finite entry.
        index: usize,
    },
    /// The result overflowed to NaN or an infinity although every input was finite (inputs
    /// far outside the model's physical range).
    NonFiniteOutput {
        /// Which output.
        what: &'static str,
        /// Index of the first non-finite entry.
        index: usize,
    },
    /// An input value is outside the range the call accepts.
    InvalidArgument {
        /// Which input.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// The position is outside a compliance map's grid and the policy is to refuse.
    OutOfGrid {
        /// 0 for x, 1 for y.
        axis: usize,
        /// The coordinate \[m\].
        value: f64,
        /// Lowest node coordinate \[m\].
        min: f64,
        /// Highest node coordinate \[m\].
        max: f64,
    },
    /// The task point cannot be reached at all.
    OutOfWorkspace {
        /// Distance of the point from the mechanism's base centre \[m\].
        distance: f64,
        /// Largest distance that can be reached \[m\].
        reach: f64,
    },
    /// The pose is singular (or too near it): the smallest singular value of the relevant
    /// Jacobian or stiffness is below the threshold. No unique answer exists.
    Singular {
        /// Which matrix ("joint Jacobian", "task Jacobian", "xy stiffness", ...).
        what: &'static str,
        /// Its smallest singular value (or a measure of it), in the matrix's units.
        sigma_min: f64,
    },
    /// An iterative solve did not reach its tolerance within its iteration budget.
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// Residual norm left.
        residual: f64,
    },
    /// The contour tracer's tool did not move along the edge: the step pushed straight into
    /// it, and Eq. 21 of the contour-tracking paper has no direction.
    NoEdgeMotion,
    /// A joint command falls outside its limits.
    JointLimit {
        /// Joint index in `q` order.
        joint: usize,
        /// The command \[rad or m\].
        value: f64,
        /// Lower limit.
        lower: f64,
        /// Upper limit.
        upper: f64,
    },
    /// A call would need more memory or time than its documented budget.
    Budget {
        /// What grows ("samples", "iterations", ...).
        what: &'static str,
        /// The name of the documented limit (`"MAX_SAMPLES"`): one budget per quantity,
        /// named in every message that refuses it.
        budget: &'static str,
        /// The documented limit.
        limit: f64,
        /// What the arguments ask for.
        requested: f64,
    },
    /// The `Data` was built for a model of other dimensions (`Data::check` failed).
    ModelMismatch {
        /// Which dimension differs ("dof", "springs", ...).
        what: &'static str,
        /// The model's value.
        expected: usize,
        /// The data's value.
        got: usize,
    },
}

impl fmt::Display for TickError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::WrongLength {
                what,
                expected,
                got,
            } => write!(f, "{what}: expected length {expected}, got {got}"),
            Self::NonFinite { what, index } => write!(f, "{what}[{index}] is not finite"),
            Self::NonFiniteOutput { what, index } => write!(
                f,
                "output {what}[{index}] overflowed to a non-finite value: the inputs are far \
                 outside the model's range"
            ),
            Self::InvalidArgument { what, value } => {
                write!(f, "{what} = {value:?} is outside its valid range")
            }
            Self::OutOfGrid {
                axis,
                value,
                min,
                max,
            } => write!(
                f,
                "position {} = {value:?} m is outside the grid [{min:?}, {max:?}] m",
                if *axis == 0 { "x" } else { "y" }
            ),
            Self::OutOfWorkspace { distance, reach } => write!(
                f,
                "point {distance} m from the base centre is out of the workspace (reach {reach} m)"
            ),
            Self::Singular { what, sigma_min } => write!(
                f,
                "singular {what}: its smallest singular value {sigma_min:e} is below the \
                 threshold (no unique answer at this pose)"
            ),
            Self::NotConverged {
                iterations,
                residual,
            } => write!(
                f,
                "did not converge in {iterations} iterations (residual {residual:e})"
            ),
            Self::NoEdgeMotion => write!(
                f,
                "the tool did not move along the edge: no edge direction (Eq. 21)"
            ),
            Self::JointLimit {
                joint,
                value,
                lower,
                upper,
            } => write!(
                f,
                "joint {joint}: command {value:?} is outside its limits [{lower:?}, {upper:?}]"
            ),
            Self::Budget {
                what,
                budget,
                limit,
                requested,
            } => write!(
                f,
                "{} {what} requested; the limit is {budget} = {} {what}",
                Count(*requested),
                Count(*limit)
            ),
            Self::ModelMismatch {
                what,
                expected,
                got,
            } => write!(
                f,
                "the data was built for another model: {what} is {got}, the model has {expected}"
            ),
        }
    }
}

impl core::error::Error for TickError {}

/// A count held as `f64` (it may be past `u64`), shown as a whole number when it is one
/// below 2^53, as `{:?}` otherwise.
struct Count(f64);

impl fmt::Display for Count {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        // Whole and below 2^53 in size: exact as an integer (no `fract` without std).
        if -9.0e15 < x && x < 9.0e15 && (x as i64) as f64 == x {
            write!(f, "{}", x as i64)
        } else {
            write!(f, "{x:?}")
        }
    }
}

/// Checks that every entry of `values` is finite; names the first one that is not.
#[inline]
pub(crate) fn check_finite(what: &'static str, values: &[f64]) -> Result<(), TickError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(TickError::NonFinite { what, index }),
        None => Ok(()),
    }
}

/// Checks that every entry of an output is finite (inputs far out of range overflow).
#[inline]
pub(crate) fn check_output(what: &'static str, values: &[f64]) -> Result<(), TickError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(TickError::NonFiniteOutput { what, index }),
        None => Ok(()),
    }
}
