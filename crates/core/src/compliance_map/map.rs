//! The owning compliance map (`alloc`): grid, coefficients, default options and fit
//! statistics, with the queries of its [`ComplianceMapView`].

use alloc::vec::Vec;

use super::fit_stats::NodeFit;
use super::view::ComplianceMapView;
use super::{BatchError, BatchSummary, Interpolation, QueryOptions, grid};
use crate::error::{BuildError, Placement, TickError};

/// Owning compliance map (`alloc`): grid, per-node line coefficients, default query options
/// and, when fitted, the per-node fit statistics. See the module documentation for units and
/// [`ComplianceMapView`] for the coefficient layout.
#[derive(Debug, Clone, PartialEq)]
pub struct ComplianceMap {
    x: Vec<f64>,
    y: Vec<f64>,
    x_inv_step: f64,
    y_inv_step: f64,
    n_force: usize,
    n_disp: usize,
    slopes: Vec<f64>,
    offsets: Vec<f64>,
    /// Slopes and offset sums node by node, the layout the query kernels read (derived
    /// from `slopes` and `offsets` at build).
    packed: Vec<f64>,
    /// The two axes' first nodes and steps when both are evenly spaced (derived at build), for
    /// the single query's path without a view.
    even: Option<[grid::EvenStart; 2]>,
    options: QueryOptions,
    fit: Option<Vec<NodeFit>>,
}

impl ComplianceMap {
    /// Builds a map from node coordinates `x` (nx), `y` (ny) \[m\] and `slopes`, `offsets`
    /// (`nx * ny * n_displacement * n_force`, SI) in the layout of [`ComplianceMapView`].
    pub fn new(
        x: Vec<f64>,
        y: Vec<f64>,
        n_force: usize,
        n_displacement: usize,
        slopes: Vec<f64>,
        offsets: Vec<f64>,
    ) -> Result<Self, BuildError> {
        let v = ComplianceMapView::new(&x, &y, n_force, n_displacement, &slopes, &offsets)?;
        let (x_inv_step, y_inv_step) = (v.x.inv_step, v.y.inv_step);
        let even =
            v.x.even()
                .zip(v.y.even())
                .map(|(a, b)| [a.start(), b.start()]);
        let packed = super::kernel::pack(n_displacement, n_force, &slopes, &offsets);
        Ok(Self {
            x,
            y,
            x_inv_step,
            y_inv_step,
            n_force,
            n_disp: n_displacement,
            slopes,
            offsets,
            packed,
            even,
            options: QueryOptions::default(),
            fit: None,
        })
    }

    /// The allocation-free view used for queries (O(1), nothing checked again).
    #[inline]
    pub fn view(&self) -> ComplianceMapView<'_> {
        ComplianceMapView {
            x: grid::Axis {
                nodes: &self.x,
                inv_step: self.x_inv_step,
            },
            y: grid::Axis {
                nodes: &self.y,
                inv_step: self.y_inv_step,
            },
            n_force: self.n_force,
            n_disp: self.n_disp,
            slopes: &self.slopes,
            offsets: &self.offsets,
            packed: &self.packed,
            options: self.options,
        }
    }

    /// Displacement \[m | rad\] at `position` `[x, y]` \[m\] under `force` \[N | N m\] into `out`,
    /// with the map's default options (Eq. 9-10 at nodes, Eq. 14 or cubic between them).
    /// Allocation-free, never panics. See [`ComplianceMapView::displacement_with`].
    #[inline]
    pub fn displacement(
        &self,
        position: [f64; 2],
        force: &[f64],
        out: &mut [f64],
    ) -> Result<Placement, TickError> {
        self.displacement_with(position, force, out, self.options)
    }

    /// [`Self::displacement`] with explicit options for this query.
    #[inline]
    pub fn displacement_with(
        &self,
        position: [f64; 2],
        force: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<Placement, TickError> {
        if let Some(placed) = self.even_bilinear(position, force, out, options) {
            return placed;
        }
        self.displacement_by_view(position, force, out, options)
    }

    /// Every query [`Self::even_bilinear`] leaves, through the view; not inlined, so that a
    /// caller's loop around the even-grid path keeps its registers.
    #[inline(never)]
    fn displacement_by_view(
        &self,
        position: [f64; 2],
        force: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<Placement, TickError> {
        self.view().displacement_with(position, force, out, options)
    }

    /// The bilinear query inside an evenly spaced grid at the kernels' fixed sizes (the
    /// paper's 2 x 2, 3-D, 6-D, and a field's one load), without building a view
    /// ([`super::kernel::even_bilinear`]: the same bits as the view's path); `None` for any
    /// other query, which the view's path answers.
    #[inline(always)]
    fn even_bilinear(
        &self,
        position: [f64; 2],
        force: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Option<Result<Placement, TickError>> {
        let even = self.even?;
        if options.interpolation != Interpolation::Bilinear {
            return None;
        }
        macro_rules! fixed {
            ($nd:literal, $nf:literal) => {{
                let f = <&[f64; $nf]>::try_from(force).ok()?;
                let o = <&mut [f64; $nd]>::try_from(out).ok()?;
                *o = super::kernel::even_bilinear::<$nd, $nf>(
                    &self.packed,
                    [&self.x, &self.y],
                    even,
                    position,
                    f,
                )?;
                Some(crate::error::check_output("displacement", o).map(|()| Placement::Inside))
            }};
        }
        super::kernel::fixed_shapes!((self.n_disp, self.n_force), fixed, None)
    }

    /// Many queries at once; see [`ComplianceMapView::displacement_batch`].
    pub fn displacement_batch(
        &self,
        positions: &[f64],
        stride: usize,
        forces: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<BatchSummary, BatchError> {
        self.view()
            .displacement_batch(positions, stride, forces, out, options)
    }

    /// Displacement at node `(i, j)` from its own lines (Eq. 9-10), no interpolation.
    pub fn node_displacement(
        &self,
        i: usize,
        j: usize,
        force: &[f64],
        out: &mut [f64],
    ) -> Result<(), BuildError> {
        let (nf, nd) = (self.n_force, self.n_disp);
        if force.len() != nf || out.len() != nd {
            return Err(BuildError::WrongLength {
                what: if force.len() != nf { "force" } else { "out" },
                expected: if force.len() != nf { nf } else { nd },
                got: if force.len() != nf {
                    force.len()
                } else {
                    out.len()
                },
            });
        }
        if i >= self.x.len() || j >= self.y.len() {
            return Err(BuildError::NodeOutOfRange { i, j });
        }
        let start = (i * self.y.len() + j) * nd * nf;
        let range = start..start + nd * nf;
        let (Some(s), Some(o)) = (self.slopes.get(range.clone()), self.offsets.get(range)) else {
            return Err(BuildError::NodeOutOfRange { i, j });
        };
        for ((out_d, s_row), o_row) in out
            .iter_mut()
            .zip(s.chunks_exact(nf))
            .zip(o.chunks_exact(nf))
        {
            *out_d = s_row
                .iter()
                .zip(o_row)
                .zip(force)
                .map(|((s, o), f)| s * f + o)
                .sum();
        }
        Ok(())
    }

    /// Slope of displacement axis `d` w.r.t. force axis `f` at node `(i, j)` \[m/N\].
    pub fn slope(&self, i: usize, j: usize, d: usize, f: usize) -> Option<f64> {
        self.coefficient(&self.slopes, i, j, d, f)
    }
    /// Offset of displacement axis `d` in the line of force axis `f` at node `(i, j)` \[m\].
    pub fn offset(&self, i: usize, j: usize, d: usize, f: usize) -> Option<f64> {
        self.coefficient(&self.offsets, i, j, d, f)
    }
    fn coefficient(&self, v: &[f64], i: usize, j: usize, d: usize, f: usize) -> Option<f64> {
        if i >= self.x.len() || j >= self.y.len() || d >= self.n_disp || f >= self.n_force {
            return None;
        }
        v.get(((i * self.y.len() + j) * self.n_disp + d) * self.n_force + f)
            .copied()
    }

    /// All slopes in the layout of [`ComplianceMapView`] \[m/N\].
    pub fn slopes(&self) -> &[f64] {
        &self.slopes
    }
    /// All offsets in the layout of [`ComplianceMapView`] \[m\].
    pub fn offsets(&self) -> &[f64] {
        &self.offsets
    }
    /// Node x coordinates \[m\].
    pub fn x(&self) -> &[f64] {
        &self.x
    }
    /// Node y coordinates \[m\].
    pub fn y(&self) -> &[f64] {
        &self.y
    }
    /// Number of force axes.
    pub fn n_force(&self) -> usize {
        self.n_force
    }
    /// Number of displacement axes.
    pub fn n_displacement(&self) -> usize {
        self.n_disp
    }
    /// Default query options.
    pub fn options(&self) -> QueryOptions {
        self.options
    }
    /// Sets the default query options.
    pub fn set_options(&mut self, options: QueryOptions) {
        self.options = options;
    }
    /// The same map with other default query options.
    #[must_use]
    pub fn with_options(mut self, options: QueryOptions) -> Self {
        self.options = options;
        self
    }
    /// Per-node fit statistics (node order `i * ny + j`), when the map was fitted.
    pub fn fit_stats(&self) -> Option<&[NodeFit]> {
        self.fit.as_deref()
    }
    pub(crate) fn set_fit_stats(&mut self, fit: Option<Vec<NodeFit>>) {
        self.fit = fit;
    }

    /// The map without the grid line `x = x_k` (`along_x`) or `y = y_k`.
    pub(crate) fn without_line(&self, along_x: bool, k: usize) -> Result<Self, BuildError> {
        let (nx, ny) = (self.x.len(), self.y.len());
        let block = self.n_force * self.n_disp;
        let keep = |i: usize, j: usize| if along_x { i != k } else { j != k };
        let mut slopes = Vec::with_capacity(self.slopes.len());
        let mut offsets = Vec::with_capacity(self.offsets.len());
        for i in 0..nx {
            for j in 0..ny {
                if keep(i, j) {
                    let r = (i * ny + j) * block..(i * ny + j + 1) * block;
                    slopes.extend_from_slice(self.slopes.get(r.clone()).unwrap_or(&[]));
                    offsets.extend_from_slice(self.offsets.get(r).unwrap_or(&[]));
                }
            }
        }
        let drop = |v: &[f64], skip: bool| -> Vec<f64> {
            v.iter()
                .enumerate()
                .filter(|(i, _)| !skip || *i != k)
                .map(|(_, c)| *c)
                .collect()
        };
        let m = Self::new(
            drop(&self.x, along_x),
            drop(&self.y, !along_x),
            self.n_force,
            self.n_disp,
            slopes,
            offsets,
        )?;
        Ok(m.with_options(self.options))
    }
}
