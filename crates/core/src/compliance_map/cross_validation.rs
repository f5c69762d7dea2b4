//! Leave-one-node-out cross-validation of the bilinear (Eq. 14) and cubic Hermite
//! interpolations of a fitted map (`alloc`).

use alloc::vec::Vec;

use super::{
    ComplianceMap, Interpolation, MAX_AXES, MAX_MEASUREMENTS, OutOfGrid, QueryOptions, sqrt,
};
use crate::error::BuildError;

/// Which grid line is removed to hold a node out (see [`leave_one_node_out`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HoldOutAxis {
    /// Remove the line `x = x_i` through the node; the node is predicted along its row.
    X,
    /// Remove the line `y = y_j` through the node; the node is predicted along its column.
    Y,
}

/// Prediction errors at one held-out node.
#[derive(Debug, Clone, PartialEq)]
pub struct HeldOutNode {
    /// Node index along x.
    pub i: usize,
    /// Node index along y.
    pub j: usize,
    /// RMS over the test forces of the Euclidean displacement error \[m\], bilinear.
    pub rms_bilinear: f64,
    /// Same for the cubic Hermite interpolation \[m\].
    pub rms_bicubic: f64,
}

/// Result of [`leave_one_node_out`].
#[derive(Debug, Clone, PartialEq)]
pub struct CrossValidation {
    /// The axis along which nodes were held out.
    pub axis: HoldOutAxis,
    /// Per held-out node errors.
    pub nodes: Vec<HeldOutNode>,
    /// RMS over all held-out nodes and test forces of `|predicted - node model|` \[m\].
    pub rms_bilinear: f64,
    /// Same for the cubic Hermite interpolation \[m\].
    pub rms_bicubic: f64,
}

impl CrossValidation {
    /// The interpolation with the smaller RMS error (bilinear on a tie).
    pub fn better(&self) -> Interpolation {
        if self.rms_bicubic < self.rms_bilinear {
            Interpolation::Bicubic
        } else {
            Interpolation::Bilinear
        }
    }
}

/// Leave-one-node-out cross-validation of bilinear vs cubic Hermite interpolation.
///
/// A rectilinear grid with one node removed is no longer rectilinear, so node `(i, j)` is
/// held out by removing its whole grid line along `axis` (for `HoldOutAxis::Y` the line
/// `y = y_j`, leaving an unevenly spaced grid) and predicting the node from the rest.
/// Because the node still lies on the grid line `x = x_i`, whose 1-D weight is 1, the
/// prediction uses column `i` only: it is exactly the leave-one-node-out prediction
/// along that column. Nodes held out are those interior along `axis`
/// (`0 < j < ny - 1` for `Y`), all indices across it; the axis must keep >= 2 nodes.
///
/// `forces` holds the test forces back to back, `n_force` entries each \[N\], at most
/// [`MAX_MEASUREMENTS`] rows ([`BuildError::Budget`] past it). The error at a
/// node for one force is the Euclidean norm of predicted minus the node's own lines
/// (Eq. 10) \[m\]; reported as RMS per node and over everything.
pub fn leave_one_node_out(
    map: &ComplianceMap,
    forces: &[f64],
    axis: HoldOutAxis,
) -> Result<CrossValidation, BuildError> {
    let (nx, ny) = (map.x().len(), map.y().len());
    let (nf, nd) = (map.n_force(), map.n_displacement());
    if forces.len() / nf.max(1) > MAX_MEASUREMENTS {
        return Err(BuildError::Budget {
            what: "force rows",
            budget: "MAX_MEASUREMENTS",
            limit: MAX_MEASUREMENTS,
            requested: forces.len() / nf.max(1),
        });
    }
    if forces.is_empty() || !forces.len().is_multiple_of(nf) {
        return Err(BuildError::WrongLength {
            what: "forces",
            expected: nf,
            got: forces.len(),
        });
    }
    let along = if axis == HoldOutAxis::X { nx } else { ny };
    if along < 3 {
        return Err(BuildError::TooFew {
            what: if axis == HoldOutAxis::X {
                "x nodes"
            } else {
                "y nodes"
            },
            needed: 3,
            got: along,
        });
    }
    let mut nodes = Vec::new();
    let (mut sum_lin, mut sum_cub, mut count) = (0.0, 0.0, 0usize);
    let mut truth = [0.0; MAX_AXES];
    let mut pred = [0.0; MAX_AXES];
    for k in 1..along - 1 {
        let reduced = map.without_line(axis == HoldOutAxis::X, k)?;
        let across = if axis == HoldOutAxis::X { ny } else { nx };
        for l in 0..across {
            let (i, j) = if axis == HoldOutAxis::X {
                (k, l)
            } else {
                (l, k)
            };
            let pos = [
                map.x().get(i).copied().unwrap_or(f64::NAN),
                map.y().get(j).copied().unwrap_or(f64::NAN),
            ];
            let (mut s_lin, mut s_cub) = (0.0, 0.0);
            for f in forces.chunks_exact(nf) {
                let t = truth.get_mut(..nd).unwrap_or(&mut []);
                map.node_displacement(i, j, f, t)?;
                for (method, acc) in [
                    (Interpolation::Bilinear, &mut s_lin),
                    (Interpolation::Bicubic, &mut s_cub),
                ] {
                    let p = pred.get_mut(..nd).unwrap_or(&mut []);
                    let opts = QueryOptions {
                        interpolation: method,
                        out_of_grid: OutOfGrid::Error,
                    };
                    reduced
                        .displacement_with(pos, f, p, opts)
                        .map_err(BuildError::Query)?;
                    *acc += p
                        .iter()
                        .zip(truth.iter())
                        .map(|(a, b)| (a - b) * (a - b))
                        .sum::<f64>();
                }
            }
            let nforce = (forces.len() / nf) as f64;
            sum_lin += s_lin;
            sum_cub += s_cub;
            count += forces.len() / nf;
            nodes.push(HeldOutNode {
                i,
                j,
                rms_bilinear: sqrt(s_lin / nforce),
                rms_bicubic: sqrt(s_cub / nforce),
            });
        }
    }
    let c = count.max(1) as f64;
    let (rms_bilinear, rms_bicubic) = (sqrt(sum_lin / c), sqrt(sum_cub / c));
    // Test forces near f64::MAX overflow the squared errors: a status, not inf.
    crate::error::check_output("cross-validation RMS", &[rms_bilinear, rms_bicubic])
        .map_err(BuildError::Query)?;
    Ok(CrossValidation {
        axis,
        nodes,
        rms_bilinear,
        rms_bicubic,
    })
}
