//! Compliance maps over grids of 1 to 4 dimensions: the least-squares-per-node map of Paksoy,
//! Dede and Kiper (2025, Eq. 9-13) over any coordinates a robot's compliance varies with: task
//! space `(x, y, z)` of a spatial robot (a Delta), or joint angles of a serial arm (its `q2`,
//! `q3`), where the paper's map is 2-D over the planar `(x, y)` of its five-bar.
//!
//! Between nodes the node displacements are blended by the tensor product of the 1-D stencils
//! of the 2-D map ([`super::Interpolation::Bilinear`]: multilinear over the `2^N` corners of the cell,
//! Eq. 14 generalised; [`super::Interpolation::Bicubic`]: C1 cubic Hermite over up to `4^N` nodes),
//! with the same out-of-grid policies. Layout: node `(i_0, ..., i_{N-1})` is
//! `sum_k i_k * stride_k` with the last axis fastest (the 2-D map's `i * ny + j`), and its
//! coefficient `(d, f)` at `node * n_displacement * n_force + d * n_force + f`.
//!
//! The 2-D [`super::ComplianceMap`] keeps its own specialised kernels (its batch lookup is not
//! slowed by the generality here); [`GridMap::from_map`] turns one into a 2-D `GridMap`.
//! Queries allocate nothing and never panic.

use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use super::fit::{FitOptions, cluster, fit_lines, grouped_order};
use super::grid::{Axis, Stencil, check_axis};
use super::view::check_counts;
use super::{ComplianceMap, MAX_AXES, MAX_MEASUREMENTS, QueryOptions};
use crate::error::{BuildError, Placement, TickError};

/// Most grid dimensions of a [`GridMap`].
pub const MAX_GRID_DIMS: usize = 4;

/// Most nodes of a [`GridMap`]: 2^20 (a 32^4 grid), 8 MiB of coefficients per force and
/// displacement axis pair; a typed [`BuildError::Budget`] past it.
pub const MAX_GRID_NODES: usize = 1 << 20;

/// How axes are named in errors (the names a user gives are `String`s).
const AXIS: [&str; MAX_GRID_DIMS] = ["axis 0", "axis 1", "axis 2", "axis 3"];

/// A compliance map over a 1-4 dimensional rectilinear grid (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct GridMap {
    axes: Vec<Vec<f64>>,
    inv_steps: [f64; MAX_GRID_DIMS],
    strides: [usize; MAX_GRID_DIMS],
    names: Vec<String>,
    n_force: usize,
    n_displacement: usize,
    slopes: Vec<f64>,
    offsets: Vec<f64>,
    options: QueryOptions,
}

impl GridMap {
    /// A map over `axes` (1..=[`MAX_GRID_DIMS`] axes of at least 2 finite, strictly
    /// increasing nodes each; at most [`MAX_GRID_NODES`] nodes in all) named `names` (one
    /// distinct, non-empty name per axis: `"x"`, `"q2"`, ...), with `n_force` force and
    /// `n_displacement` displacement axes (1..=6 each) and the slopes and offsets in the
    /// layout of the module docs. Default options: multilinear, errors outside the grid.
    pub fn new(
        axes: Vec<Vec<f64>>,
        names: Vec<String>,
        n_force: usize,
        n_displacement: usize,
        slopes: Vec<f64>,
        offsets: Vec<f64>,
    ) -> Result<Self, BuildError> {
        check_counts(n_force, n_displacement)?;
        let dims = axes.len();
        if dims == 0 || dims > MAX_GRID_DIMS {
            return Err(BuildError::InvalidParameter {
                what: "grid dimensions",
                value: dims as f64,
                expected: "1 to 4 axes",
            });
        }
        if names.len() != dims {
            return Err(BuildError::WrongLength {
                what: "grid axis names",
                expected: dims,
                got: names.len(),
            });
        }
        for (index, n) in names.iter().enumerate() {
            let repeated = names.iter().take(index).any(|m| m == n);
            if n.is_empty() || repeated {
                return Err(BuildError::InvalidEntry {
                    what: "grid axis names",
                    index,
                    value: index as f64,
                    expected: "a non-empty name, distinct from the other axes'",
                });
            }
        }
        let mut inv_steps = [0.0; MAX_GRID_DIMS];
        let mut nodes = 1usize;
        for ((axis, nodes_k), inv) in AXIS.iter().zip(&axes).zip(inv_steps.iter_mut()) {
            *inv = check_axis(axis, nodes_k)?;
            nodes = nodes.saturating_mul(nodes_k.len());
        }
        if nodes > MAX_GRID_NODES {
            return Err(BuildError::Budget {
                what: "grid nodes",
                budget: "MAX_GRID_NODES",
                limit: MAX_GRID_NODES,
                requested: nodes,
            });
        }
        let mut strides = [0usize; MAX_GRID_DIMS];
        let mut stride = 1usize;
        for k in (0..dims).rev() {
            if let Some(s) = strides.get_mut(k) {
                *s = stride;
            }
            stride = stride.saturating_mul(axes.get(k).map_or(1, Vec::len));
        }
        let coefficients = nodes * n_force * n_displacement;
        for (what, v) in [("slopes", &slopes), ("offsets", &offsets)] {
            if v.len() != coefficients {
                return Err(BuildError::WrongLength {
                    what,
                    expected: coefficients,
                    got: v.len(),
                });
            }
            if let Some(index) = v.iter().position(|x| !x.is_finite()) {
                return Err(BuildError::NonFinite { what, index });
            }
        }
        Ok(Self {
            axes,
            inv_steps,
            strides,
            names,
            n_force,
            n_displacement,
            slopes,
            offsets,
            options: QueryOptions::default(),
        })
    }

    /// The 2-D `map` as a grid map over axes `x`, `y`, with its coefficients and options.
    pub fn from_map(map: &ComplianceMap) -> Self {
        let (x, y) = (map.x().to_vec(), map.y().to_vec());
        let mut inv_steps = [0.0; MAX_GRID_DIMS];
        for (inv, nodes) in inv_steps.iter_mut().zip([&x, &y]) {
            // The map's axes were checked when it was built.
            *inv = check_axis("x", nodes).unwrap_or(0.0);
        }
        Self {
            strides: [y.len(), 1, 0, 0],
            axes: vec![x, y],
            inv_steps,
            names: vec!["x".to_string(), "y".to_string()],
            n_force: map.n_force(),
            n_displacement: map.n_displacement(),
            slopes: map.slopes().to_vec(),
            offsets: map.offsets().to_vec(),
            options: map.options(),
        }
    }

    /// Number of grid dimensions.
    pub fn dims(&self) -> usize {
        self.axes.len()
    }
    /// The grid axes' node coordinates.
    pub fn axes(&self) -> &[Vec<f64>] {
        &self.axes
    }
    /// The grid axes' names.
    pub fn names(&self) -> &[String] {
        &self.names
    }
    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.axes.iter().map(Vec::len).product()
    }
    /// Force axes.
    pub fn n_force(&self) -> usize {
        self.n_force
    }
    /// Displacement axes.
    pub fn n_displacement(&self) -> usize {
        self.n_displacement
    }
    /// Slopes in the layout of the module docs \[m/N, ...\].
    pub fn slopes(&self) -> &[f64] {
        &self.slopes
    }
    /// Offsets in the layout of the module docs \[m, ...\].
    pub fn offsets(&self) -> &[f64] {
        &self.offsets
    }
    /// Default query options.
    pub fn options(&self) -> QueryOptions {
        self.options
    }
    /// Sets the default query options.
    #[must_use]
    pub fn with_options(mut self, options: QueryOptions) -> Self {
        self.options = options;
        self
    }

    /// The displacement at `point` (one coordinate per grid axis) under `force` (`n_force`
    /// entries \[N | N m\]) into `out` (`n_displacement` entries \[m | rad\]), with the
    /// default options.
    pub fn displacement(
        &self,
        point: &[f64],
        force: &[f64],
        out: &mut [f64],
    ) -> Result<Placement, TickError> {
        self.displacement_with(point, force, out, self.options)
    }

    /// [`Self::displacement`] with explicit `options`. Allocation-free, never panics;
    /// [`TickError::WrongLength`] for a point, force or output of the wrong length,
    /// [`TickError::NonFinite`] for non-finite input, [`TickError::OutOfGrid`] naming the
    /// axis (0-based) outside the grid under [`super::OutOfGrid::Error`].
    pub fn displacement_with(
        &self,
        point: &[f64],
        force: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<Placement, TickError> {
        let dims = self.dims();
        for (what, got, expected) in [
            ("point", point.len(), dims),
            ("force", force.len(), self.n_force),
            ("displacement", out.len(), self.n_displacement),
        ] {
            if got != expected {
                return Err(TickError::WrongLength {
                    what,
                    expected,
                    got,
                });
            }
        }
        crate::error::check_finite("point", point)?;
        crate::error::check_finite("force", force)?;
        let mut stencils = [Stencil {
            base: 0,
            len: 1,
            w: [1.0, 0.0, 0.0, 0.0],
        }; MAX_GRID_DIMS];
        let mut placement = Placement::Inside;
        for (k, ((nodes, inv), s)) in self
            .axes
            .iter()
            .zip(&self.inv_steps)
            .zip(stencils.iter_mut())
            .enumerate()
        {
            let axis = Axis {
                nodes,
                inv_step: *inv,
            };
            let v = point.get(k).copied().unwrap_or(0.0);
            let (st, place) = axis.stencil(k, v, options.interpolation, options.out_of_grid)?;
            *s = st;
            placement = worse(placement, place);
        }
        out.iter_mut().for_each(|o| *o = 0.0);
        let (nf, nd) = (self.n_force, self.n_displacement);
        // Odometer over the stencils' nodes, the last axis fastest.
        let mut idx = [0usize; MAX_GRID_DIMS];
        loop {
            let mut weight = 1.0;
            let mut node = 0usize;
            for ((s, i), stride) in stencils.iter().zip(&idx).zip(&self.strides).take(dims) {
                weight *= s.w.get(*i).copied().unwrap_or(0.0);
                node += (s.base + i) * stride;
            }
            if weight != 0.0 {
                let base = node * nd * nf;
                for (d, o) in out.iter_mut().enumerate() {
                    let mut v = 0.0;
                    for (f, force_f) in force.iter().enumerate() {
                        let c = base + d * nf + f;
                        let slope = self.slopes.get(c).copied().unwrap_or(0.0);
                        let offset = self.offsets.get(c).copied().unwrap_or(0.0);
                        v += slope * force_f + offset;
                    }
                    *o += weight * v;
                }
            }
            // Next index: carry from the last axis.
            let mut k = dims;
            loop {
                if k == 0 {
                    crate::error::check_output("displacement", out)?;
                    return Ok(placement);
                }
                k -= 1;
                let (Some(i), Some(s)) = (idx.get_mut(k), stencils.get(k)) else {
                    return Ok(placement);
                };
                *i += 1;
                if *i < s.len {
                    break;
                }
                *i = 0;
            }
        }
    }

    /// Displacements of `n` points: `points` row-major `(n, dims)`, `forces` either one row of
    /// `n_force` for every point or `(n, n_force)`, into `out` `(n, n_displacement)`. The
    /// first row refused and why on failure.
    pub fn displacement_batch(
        &self,
        points: &[f64],
        forces: &[f64],
        out: &mut [f64],
    ) -> Result<super::BatchSummary, super::BatchError> {
        self.displacement_batch_with(points, forces, out, self.options)
    }

    /// [`Self::displacement_batch`] with explicit `options`.
    pub fn displacement_batch_with(
        &self,
        points: &[f64],
        forces: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<super::BatchSummary, super::BatchError> {
        let (dims, nf, nd) = (self.dims(), self.n_force, self.n_displacement);
        let shape = |what, expected, got| super::BatchError {
            row: 0,
            error: TickError::WrongLength {
                what,
                expected,
                got,
            },
        };
        if !points.len().is_multiple_of(dims) {
            return Err(shape("points (rows of dims)", dims, points.len() % dims));
        }
        let n = points.len() / dims;
        if forces.len() != nf && forces.len() != n * nf {
            return Err(shape("forces", n * nf, forces.len()));
        }
        if out.len() != n * nd {
            return Err(shape("displacements", n * nd, out.len()));
        }
        let mut summary = super::BatchSummary::default();
        let broadcast = forces.len() == nf && n != 1;
        for (row, (p, o)) in points
            .chunks_exact(dims)
            .zip(out.chunks_exact_mut(nd))
            .enumerate()
        {
            let f = if broadcast {
                forces
            } else {
                forces.get(row * nf..(row + 1) * nf).unwrap_or(&[])
            };
            let place = self
                .displacement_with(p, f, o, options)
                .map_err(|error| super::BatchError { row, error })?;
            summary.count(place);
        }
        Ok(summary)
    }
}

/// The farther from inside of two placements.
fn worse(a: Placement, b: Placement) -> Placement {
    let rank = |p: Placement| match p {
        Placement::Inside => 0,
        Placement::Clamped => 1,
        Placement::Extrapolated => 2,
    };
    if rank(b) > rank(a) { b } else { a }
}

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
/// repeated (node, axis, force), fewer than 2 force levels, past [`MAX_MEASUREMENTS`] or
/// [`MAX_GRID_NODES`].
pub fn fit_grid(
    names: Vec<String>,
    measurements: &[GridMeasurement],
    options: &FitOptions,
) -> Result<GridMap, BuildError> {
    let (nf, nd) = (options.n_force, options.n_displacement);
    check_counts(nf, nd)?;
    let dims = names.len();
    if dims == 0 || dims > MAX_GRID_DIMS {
        return Err(BuildError::InvalidParameter {
            what: "grid dimensions",
            value: dims as f64,
            expected: "1 to 4 axes",
        });
    }
    if measurements.len() > MAX_MEASUREMENTS {
        return Err(BuildError::Budget {
            what: "measurements",
            budget: "MAX_MEASUREMENTS",
            limit: MAX_MEASUREMENTS,
            requested: measurements.len(),
        });
    }
    for (row, m) in measurements.iter().enumerate() {
        for (column, v) in AXIS.iter().zip(&m.point).take(dims) {
            if !v.is_finite() {
                return Err(BuildError::NonFiniteMeasurement { row, column });
            }
        }
        if !m.force.is_finite() {
            return Err(BuildError::NonFiniteMeasurement {
                row,
                column: "force",
            });
        }
        for (column, v) in super::fit::DISPLACEMENT_COLUMNS
            .iter()
            .zip(&m.displacement)
            .take(nd)
        {
            if !v.is_finite() {
                return Err(BuildError::NonFiniteMeasurement { row, column });
            }
        }
        if m.force_axis >= nf {
            return Err(BuildError::ForceAxisOutOfRange {
                row,
                force_axis: m.force_axis,
                n_force: nf,
            });
        }
    }
    // Grid lines per axis and each reading's node.
    let mut axes = Vec::with_capacity(dims);
    let mut node_of = vec![0usize; measurements.len()];
    for (k, axis) in AXIS.iter().enumerate().take(dims) {
        let values: Vec<f64> = measurements
            .iter()
            .map(|m| m.point.get(k).copied().unwrap_or(0.0))
            .collect();
        let (centres, line_of) = cluster(&values, axis, options.position_tolerance)?;
        for (n, l) in node_of.iter_mut().zip(&line_of) {
            *n = n.saturating_mul(centres.len()).saturating_add(*l);
        }
        axes.push(centres);
    }
    let nodes: usize = axes.iter().map(Vec::len).product();
    for (axis, a) in AXIS.iter().zip(&axes) {
        if a.len() < 2 {
            return Err(BuildError::TooFew {
                what: axis,
                needed: 2,
                got: a.len(),
            });
        }
    }
    if nodes > MAX_GRID_NODES {
        return Err(BuildError::Budget {
            what: "grid nodes",
            budget: "MAX_GRID_NODES",
            limit: MAX_GRID_NODES,
            requested: nodes,
        });
    }
    let coordinates = |node: usize| {
        let mut out = [0.0; MAX_GRID_DIMS];
        let mut rest = node;
        for k in (0..dims).rev() {
            let len = axes.get(k).map_or(1, Vec::len).max(1);
            if let Some(o) = out.get_mut(k) {
                *o = axes
                    .get(k)
                    .and_then(|a| a.get(rest % len))
                    .copied()
                    .unwrap_or(0.0);
            }
            rest /= len;
        }
        out
    };
    let key = |r: usize| {
        let m = measurements.get(r);
        (
            node_of.get(r).copied().unwrap_or(0),
            m.map_or(0, |m| m.force_axis),
            m.map_or(0.0, |m| m.force),
        )
    };
    let order = grouped_order(measurements.len(), key)?;
    let mut measured = vec![false; nodes];
    for n in &node_of {
        if let Some(m) = measured.get_mut(*n) {
            *m = true;
        }
    }
    if let Some(node) = measured.iter().position(|m| !*m) {
        return Err(BuildError::MissingGridNode {
            node: coordinates(node),
            dims,
        });
    }
    let block = nd * nf;
    let mut slopes = vec![0.0; nodes * block];
    let mut offsets = vec![0.0; nodes * block];
    let mut pos = 0usize;
    for node in 0..nodes {
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
                    node: coordinates(node),
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
    GridMap::new(axes, names, nf, nd, slopes, offsets)
}
