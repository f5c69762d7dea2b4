//! Fitting an N-D [`GridMap`] from static tests: the 2-D fit of Paksoy, Dede and Kiper (2025,
//! Eq. 10-13) over grids of 1 to 4 dimensions. Readings are grouped by node and force axis,
//! and each group's least-squares line per displacement axis gives the node's slope and
//! offset.

use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use super::MAX_AXES;
use super::fit::{FitOptions, check_budget, check_load, cluster, fit_lines, grouped_order};
use super::grid::AxisId;
use super::nd::{GridMap, MAX_GRID_DIMS, check_node_budget};
use super::view::check_counts;
use crate::error::BuildError;

/// One static-test reading on an N-D grid: at node `point` (its first `dims` entries) a force
/// `force` \[N\] (moment \[N m\]) along force axis `force_axis` only, and the measured
/// `displacement` (first `n_displacement` entries \[m | rad\]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridMeasurement {
    /// Node coordinates; entries past the grid's dimensions are ignored.
    pub point: [f64; MAX_GRID_DIMS],
    /// Loaded force axis, `0..n_force`.
    pub force_axis: usize,
    /// Force level \[N\] (moment \[N m\]).
    pub force: f64,
    /// Measured displacement; the first `n_displacement` entries are used.
    pub displacement: [f64; MAX_AXES],
}

impl GridMeasurement {
    /// A reading at `point` (at most 4 coordinates; missing ones 0) with the displacement
    /// copied from `displacement` (at most 6 entries).
    pub fn new(point: &[f64], force_axis: usize, force: f64, displacement: &[f64]) -> Self {
        let mut p = [0.0; MAX_GRID_DIMS];
        p.iter_mut().zip(point).for_each(|(a, b)| *a = *b);
        let mut d = [0.0; MAX_AXES];
        d.iter_mut().zip(displacement).for_each(|(a, b)| *a = *b);
        Self {
            point: p,
            force_axis,
            force,
            displacement: d,
        }
    }
}

/// Fits a grid map over `names.len()` axes (1..=4) from static tests, as [`super::fit()`]
/// does in 2-D (Eq. 10-13): readings grouped by node (coordinates within
/// `options.position_tolerance` share a grid line, every node of the grid of distinct
/// coordinates needs readings) and by force axis; per node, force axis and displacement axis
/// the least-squares line, each force axis keeping its intercept as its offset.
///
/// Errors name the reading (row and column) or the node: non-finite values, a force axis
/// `>= n_force`, ambiguous coordinates, a missing node ([`BuildError::MissingGridNode`]), a
/// repeated (node, axis, force), fewer than 2 force levels, past [`super::MAX_MEASUREMENTS`] or
/// [`super::MAX_GRID_NODES`].
pub fn fit_grid(
    names: Vec<String>,
    measurements: &[GridMeasurement],
    options: &FitOptions,
) -> Result<GridMap, BuildError> {
    let (nf, nd) = (options.n_force, options.n_displacement);
    check_counts(nf, nd)?;
    let dims = names.len();
    check_readings(dims, measurements, nf, nd)?;
    let grid = Lines::cluster(dims, measurements, options.position_tolerance)?;
    let key = |r: usize| {
        let m = measurements.get(r);
        (
            grid.node_of.get(r).copied().unwrap_or(0),
            m.map_or(0, |m| m.force_axis),
            m.map_or(0.0, |m| m.force),
        )
    };
    let order = grouped_order(measurements.len(), key)?;
    grid.check_every_node_read()?;
    let block = nd * nf;
    let mut slopes = vec![0.0; grid.nodes * block];
    let mut offsets = vec![0.0; grid.nodes * block];
    let mut pos = 0usize;
    for node in 0..grid.nodes {
        for f in 0..nf {
            let begin = pos;
            while order
                .get(pos)
                .is_some_and(|r| key(*r).0 == node && key(*r).1 == f)
            {
                pos += 1;
            }
            let rows = order.get(begin..pos).unwrap_or(&[]);
            if rows.len() < 2 {
                return Err(BuildError::TooFewGridForceLevels {
                    node: grid.coordinates(node),
                    dims,
                    force_axis: f,
                    levels: rows.len(),
                });
            }
            let group: Vec<(f64, [f64; MAX_AXES])> = rows
                .iter()
                .filter_map(|r| measurements.get(*r))
                .map(|m| (m.force, m.displacement))
                .collect();
            let (_, lines) = fit_lines(&group, nd);
            for (d, line) in lines.iter().enumerate().take(nd) {
                let idx = node * block + d * nf + f;
                if let (Some(s), Some(o)) = (slopes.get_mut(idx), offsets.get_mut(idx)) {
                    *s = line.slope;
                    *o = line.offset;
                }
            }
        }
    }
    if let Some(index) = slopes.iter().chain(&offsets).position(|v| !v.is_finite()) {
        return Err(BuildError::NonFinite {
            what: "fitted slopes then offsets: forces or displacements too large",
            index,
        });
    }
    GridMap::new(grid.axes, names, nf, nd, slopes, offsets)
}

/// The grid's dimension count (1 to 4), the measurement budget, and every reading's used
/// entries finite with its force axis below `nf`: errors name the reading's row and column.
fn check_readings(
    dims: usize,
    measurements: &[GridMeasurement],
    nf: usize,
    nd: usize,
) -> Result<(), BuildError> {
    if dims == 0 || dims > MAX_GRID_DIMS {
        return Err(BuildError::InvalidParameter {
            what: "grid dimensions",
            value: dims as f64,
            expected: "1 to 4 axes",
        });
    }
    check_budget(measurements.len())?;
    for (row, m) in measurements.iter().enumerate() {
        for (k, v) in m.point.iter().enumerate().take(dims) {
            if !v.is_finite() {
                let column = AxisId::Grid(k).name();
                return Err(BuildError::NonFiniteMeasurement { row, column });
            }
        }
        if !m.force.is_finite() {
            return Err(BuildError::NonFiniteMeasurement {
                row,
                column: "force",
            });
        }
        check_load(row, &m.displacement, m.force_axis, nf, nd)?;
    }
    Ok(())
}

/// The grid the readings lie on: each axis's lines (the clustered coordinates) and each
/// reading's node (last axis fastest, the map's layout).
struct Lines {
    dims: usize,
    axes: Vec<Vec<f64>>,
    node_of: Vec<usize>,
    nodes: usize,
}

impl Lines {
    /// Clusters each axis's coordinates within `tolerance` into grid lines; at least 2 per
    /// axis and at most [`super::MAX_GRID_NODES`] nodes.
    fn cluster(
        dims: usize,
        measurements: &[GridMeasurement],
        tolerance: f64,
    ) -> Result<Self, BuildError> {
        let mut axes = Vec::with_capacity(dims);
        let mut node_of = vec![0usize; measurements.len()];
        for k in 0..dims {
            let values: Vec<f64> = measurements
                .iter()
                .map(|m| m.point.get(k).copied().unwrap_or(0.0))
                .collect();
            let (centres, line_of) = cluster(&values, AxisId::Grid(k).name(), tolerance)?;
            for (n, l) in node_of.iter_mut().zip(&line_of) {
                *n = n.saturating_mul(centres.len()).saturating_add(*l);
            }
            axes.push(centres);
        }
        let nodes: usize = axes.iter().map(Vec::len).product();
        for (k, a) in axes.iter().enumerate() {
            if a.len() < 2 {
                return Err(BuildError::TooFew {
                    what: AxisId::Grid(k).name(),
                    needed: 2,
                    got: a.len(),
                });
            }
        }
        check_node_budget(nodes)?;
        Ok(Self {
            dims,
            axes,
            node_of,
            nodes,
        })
    }

    /// The coordinates of `node` (entries past the grid's dimensions 0), for errors.
    fn coordinates(&self, node: usize) -> [f64; MAX_GRID_DIMS] {
        let mut out = [0.0; MAX_GRID_DIMS];
        let mut rest = node;
        for k in (0..self.dims).rev() {
            let len = self.axes.get(k).map_or(1, Vec::len).max(1);
            if let Some(o) = out.get_mut(k) {
                *o = self
                    .axes
                    .get(k)
                    .and_then(|a| a.get(rest % len))
                    .copied()
                    .unwrap_or(0.0);
            }
            rest /= len;
        }
        out
    }

    /// [`BuildError::MissingGridNode`] at the first node of the grid no reading lies on.
    fn check_every_node_read(&self) -> Result<(), BuildError> {
        let mut read = vec![false; self.nodes];
        for n in &self.node_of {
            if let Some(m) = read.get_mut(*n) {
                *m = true;
            }
        }
        match read.iter().position(|m| !*m) {
            Some(node) => Err(BuildError::MissingGridNode {
                node: self.coordinates(node),
                dims: self.dims,
            }),
            None => Ok(()),
        }
    }
}
