//! What a fit leaves on the map it made: per node, each line's slope, offset and residuals
//! (Eq. 12-13 of Paksoy, Dede and Kiper, 2025) and the design's conditioning.

use alloc::vec::Vec;

/// Statistics of one line fit `disp_d = slope * F_f + offset` at one node (Eq. 12-13).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "std", derive(serde::Serialize, serde::Deserialize))]
pub struct LineStats {
    /// Fitted slope \[m/N\].
    pub slope: f64,
    /// Fitted offset \[m\].
    pub offset: f64,
    /// Root mean square of the residuals, `sqrt(sum r^2 / k)` over the `k` readings \[m\].
    pub rms: f64,
    /// Coefficient of determination `1 - SS_res / SS_tot` (1 when the displacement does not
    /// vary at all).
    pub r_squared: f64,
}

/// Fit statistics of one node.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "std", derive(serde::Serialize, serde::Deserialize))]
pub struct NodeFit {
    /// Node index along x.
    pub i: usize,
    /// Node index along y.
    pub j: usize,
    /// Node x \[m\] (mean of its readings' x).
    pub x: f64,
    /// Node y \[m\].
    pub y: f64,
    /// Line statistics, index `d * n_force + f`.
    pub lines: Vec<LineStats>,
    /// 2-norm condition number of the design matrix `A = [F_k 1]` (Eq. 12) per force axis;
    /// it depends on the force levels and on the force unit (here N).
    pub condition: Vec<f64>,
    /// Readings per force axis.
    pub samples: Vec<usize>,
}
