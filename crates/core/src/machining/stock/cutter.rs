//! The z-map's cutter and what one cut removes: the pieces the stock's passes and its
//! follower share.

/// A vertical cutter, its tip on the tool path (the tool axis along +z of the workpiece).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cutter {
    /// Flat end mill of radius \[m\].
    Flat {
        /// Radius \[m\].
        radius: f64,
    },
    /// Ball end mill of radius \[m\] (the tip is the lowest point of the ball).
    Ball {
        /// Radius \[m\].
        radius: f64,
    },
}

impl Cutter {
    /// The radius \[m\].
    pub fn radius(&self) -> f64 {
        match *self {
            Self::Flat { radius } | Self::Ball { radius } => radius,
        }
    }
}

/// What one cut removed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[must_use]
pub struct Removal {
    /// Cells whose height went down.
    pub cells: usize,
    /// Volume removed \[m^3\] (height drops times the cell area).
    pub volume: f64,
    /// The largest height drop of a cell \[m\].
    pub deepest: f64,
}
