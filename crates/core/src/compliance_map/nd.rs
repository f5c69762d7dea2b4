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
//! One concept, two kernels: the 2-D [`super::ComplianceMap`] is the fast path. A `GridMap`
//! of two axes holds one and answers its queries with the 2-D map's specialised kernels (the
//! same bits as the 2-D map, at its speed); grids of 1, 3 or 4 axes take the general
//! tensor-product path here. [`GridMap::from_map`] turns a 2-D map into a 2-D `GridMap`.
//! Queries allocate nothing and never panic.

use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use super::grid::{Axis, AxisId, Stencil, check_axis};
use super::view::check_counts;
use super::{ComplianceMap, QueryOptions};
use crate::error::{BuildError, Placement, TickError};

/// Most grid dimensions of a [`GridMap`].
pub const MAX_GRID_DIMS: usize = 4;

/// Most nodes of a [`GridMap`]: 2^20 (a 32^4 grid), 8 MiB of coefficients per force and
/// displacement axis pair; a typed [`BuildError::Budget`] past it.
pub const MAX_GRID_NODES: usize = 1 << 20;

/// At most [`MAX_GRID_NODES`] nodes, for a grid built or fitted.
pub(super) fn check_node_budget(nodes: usize) -> Result<(), BuildError> {
    if nodes > MAX_GRID_NODES {
        return Err(BuildError::Budget {
            what: "grid nodes",
            budget: "MAX_GRID_NODES",
            limit: MAX_GRID_NODES,
            requested: nodes,
        });
    }
    Ok(())
}

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
    /// The same map as a 2-D [`ComplianceMap`] when it has two axes (derived at build): its
    /// queries take the 2-D map's kernels, so a 2-D grid map answers what the 2-D map
    /// answers, bit for bit, at its speed. Twice the coefficients' memory for 2-D maps.
    planar: Option<ComplianceMap>,
}

/// The 2-D map of a grid map with two axes, or `None` for another dimension count (the axes
/// and coefficients are already checked, so building it cannot fail on them).
fn planar_of(
    axes: &[Vec<f64>],
    n_force: usize,
    n_displacement: usize,
    slopes: &[f64],
    offsets: &[f64],
) -> Option<ComplianceMap> {
    let [x, y] = axes else { return None };
    ComplianceMap::new(
        x.clone(),
        y.clone(),
        n_force,
        n_displacement,
        slopes.to_vec(),
        offsets.to_vec(),
    )
    .ok()
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
        for (k, (nodes_k, inv)) in axes.iter().zip(inv_steps.iter_mut()).enumerate() {
            *inv = check_axis(AxisId::Grid(k), nodes_k)?;
            nodes = nodes.saturating_mul(nodes_k.len());
        }
        check_node_budget(nodes)?;
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
        let planar = planar_of(&axes, n_force, n_displacement, &slopes, &offsets);
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
            planar,
        })
    }

    /// The 2-D `map` as a grid map over axes `x`, `y`, with its coefficients and options.
    pub fn from_map(map: &ComplianceMap) -> Self {
        let (x, y) = (map.x().to_vec(), map.y().to_vec());
        let mut inv_steps = [0.0; MAX_GRID_DIMS];
        for ((inv, nodes), id) in inv_steps
            .iter_mut()
            .zip([&x, &y])
            .zip([AxisId::X, AxisId::Y])
        {
            // The map's axes were checked when it was built.
            *inv = check_axis(id, nodes).unwrap_or(0.0);
        }
        let (n_force, n_displacement) = (map.n_force(), map.n_displacement());
        let (slopes, offsets) = (map.slopes().to_vec(), map.offsets().to_vec());
        let axes = vec![x, y];
        let planar = planar_of(&axes, n_force, n_displacement, &slopes, &offsets);
        Self {
            strides: [axes.get(1).map_or(1, Vec::len), 1, 0, 0],
            axes,
            inv_steps,
            names: vec!["x".to_string(), "y".to_string()],
            n_force,
            n_displacement,
            slopes,
            offsets,
            options: map.options(),
            planar,
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
        if let (Some(planar), &[x, y]) = (&self.planar, point) {
            return planar.displacement_with([x, y], force, out, options);
        }
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
