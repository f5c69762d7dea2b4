//! Errors in three tiers: [`BuildError`] when a model is assembled (no heap, names by
//! element index), [`TickError`] on the real-time path (`Copy`, never a panic), and, with the
//! `urdf` feature, [`crate::robot::LoadError`] naming URDF and TOML elements.

use core::fmt;

/// A model could not be assembled by [`crate::ModelBuilder`].
///
/// `element` counts builder calls from 0, so the caller can tell which call was wrong.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum BuildError {
    /// A fixed capacity of the real-time model was exceeded.
    CapacityExceeded {
        /// Which capacity ("elements", "joints", "springs").
        what: &'static str,
        /// Its size.
        capacity: usize,
    },
    /// A transform holds NaN or an infinity.
    NonFiniteTransform {
        /// Builder call index.
        element: usize,
    },
    /// A joint axis is zero or not finite.
    ZeroAxis {
        /// Builder call index.
        element: usize,
    },
    /// A stiffness is zero, negative or NaN (`+inf` means rigid and is allowed).
    NonPositiveStiffness {
        /// Builder call index.
        element: usize,
        /// 0, 1, 2 for the spring frame's x, y, z axis.
        axis: usize,
        /// The offending value [N m / rad].
        value: f64,
    },
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::CapacityExceeded { what, capacity } => {
                write!(
                    f,
                    "too many {what}: the real-time model holds at most {capacity}"
                )
            }
            Self::NonFiniteTransform { element } => {
                write!(f, "element {element}: transform is not finite")
            }
            Self::ZeroAxis { element } => {
                write!(f, "element {element}: joint axis is zero or not finite")
            }
            Self::NonPositiveStiffness {
                element,
                axis,
                value,
            } => write!(
                f,
                "element {element}: stiffness about axis {} is {value}; it must be > 0 (inf = rigid)",
                ["x", "y", "z"].get(*axis).copied().unwrap_or("?")
            ),
        }
    }
}

impl core::error::Error for BuildError {}

/// Why a per-tick call refused its input or could not finish. Cheap to return, never panics.
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
    /// The Jacobian is singular (smallest singular value below the tolerance): no unique
    /// joint correction exists at this pose.
    Singular {
        /// Smallest singular value of the actuated-joint Jacobian.
        sigma_min: f64,
    },
    /// An iterative solve did not reach its tolerance within its iteration budget.
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// Residual norm left.
        residual: f64,
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
            Self::NonFinite { what, index } => {
                write!(f, "{what}[{index}] is not finite")
            }
            Self::Singular { sigma_min } => write!(
                f,
                "singular pose: smallest singular value of the joint Jacobian is {sigma_min:e}"
            ),
            Self::NotConverged {
                iterations,
                residual,
            } => write!(
                f,
                "did not converge in {iterations} iterations (residual {residual:e})"
            ),
        }
    }
}

impl core::error::Error for TickError {}

/// Checks that every entry of `values` is finite; names the first one that is not.
pub(crate) fn check_finite(what: &'static str, values: &[f64]) -> Result<(), TickError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(TickError::NonFinite { what, index }),
        None => Ok(()),
    }
}
