//! Errors in three tiers, and the one placement status every query reports.
//!
//! 1. [`BuildError`]: a model, a configuration or a fit could not be assembled from the values
//!    given (no heap, `Copy`, fields name what, where, the value and what was expected).
//!    [`LoadError`] (`std`) is its file-level sibling: it names the file element at fault and
//!    wraps a [`BuildError`] where the values themselves were wrong.
//! 2. [`TickError`]: a per-tick call refused its input or could not finish. Flat and `Copy`,
//!    one variant per C status code of the C API, never a panic.
//! 3. Numerical failure inside a solver is a value (`Option`), as nalgebra's
//!    `Cholesky::new`: the caller turns it into one of the above where it has the context.
//!
//! [`Placement`] says where a query fell relative to a model's validity range (a compliance
//! map's grid): inside, clamped to it or extrapolated beyond it.

mod build;
mod job;
#[cfg(feature = "std")]
mod load;
mod tick;

pub use build::BuildError;
pub use job::JobError;
#[cfg(feature = "std")]
pub use load::LoadError;
pub use tick::TickError;
pub(crate) use tick::{check_finite, check_output};

/// Where a successful query fell relative to a model's validity range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Placement {
    /// Inside (boundary included), or a model without bounds.
    #[default]
    Inside,
    /// Outside along at least one axis and moved to the boundary.
    Clamped,
    /// Outside along at least one axis and extrapolated.
    Extrapolated,
}

impl Placement {
    /// The worse of two placements (extrapolated > clamped > inside): the status of a tick
    /// that made several queries.
    #[inline]
    #[must_use]
    pub fn worst(self, other: Self) -> Self {
        match (self, other) {
            (Self::Inside, o) => o,
            (s, Self::Inside) => s,
            (Self::Extrapolated, _) | (_, Self::Extrapolated) => Self::Extrapolated,
            _ => Self::Clamped,
        }
    }

    /// A short lowercase name ("inside", "clamped", "extrapolated").
    pub fn name(self) -> &'static str {
        match self {
            Self::Inside => "inside",
            Self::Clamped => "clamped",
            Self::Extrapolated => "extrapolated",
        }
    }
}

pub(crate) use build::{check_frame, param};
