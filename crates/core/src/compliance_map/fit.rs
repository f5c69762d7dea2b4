//! Fitting a [`ComplianceMap`] from static tests (Eq. 10-13), with per-node statistics, and
//! the paper's two-point input form (displacements of P_u and P_l extrapolated along the
//! tool axis).

use alloc::vec;
use alloc::vec::Vec;

use super::fit_stats::{LineStats, NodeFit};
use super::view::check_counts;
use super::{ComplianceMap, MAX_AXES, MAX_MEASUREMENTS, sqrt};
use crate::error::BuildError;

/// Column names used in errors for the displacement entries of a [`Measurement`].
pub(crate) const DISPLACEMENT_COLUMNS: [&str; MAX_AXES] = ["d0", "d1", "d2", "d3", "d4", "d5"];

/// One static-test reading: at node position `(x, y)` \[m\] a force `force` \[N\] (or moment
/// \[N m\]) is applied along force axis `force_axis` only, and the displacement of the working
/// point is measured (`displacement[..n_displacement]`, \[m\] or \[rad\]; later entries unused).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// Node x \[m\].
    pub x: f64,
    /// Node y \[m\].
    pub y: f64,
    /// Loaded force axis, `0..n_force`.
    pub force_axis: usize,
    /// Force level \[N\] (moment \[N m\]).
    pub force: f64,
    /// Measured displacement \[m\] / \[rad\]; the first `n_displacement` entries are used.
    pub displacement: [f64; MAX_AXES],
}

impl Measurement {
    /// A reading with the displacement copied from `displacement` (at most [`MAX_AXES`]
    /// entries are kept; missing ones are 0).
    pub fn new(x: f64, y: f64, force_axis: usize, force: f64, displacement: &[f64]) -> Self {
        let mut d = [0.0; MAX_AXES];
        d.iter_mut().zip(displacement).for_each(|(a, b)| *a = *b);
        Self {
            x,
            y,
            force_axis,
            force,
            displacement: d,
        }
    }

    /// A reading in the paper's two-point form: displacements of the upper point `upper`
    /// (P_u) and lower point `lower` (P_l) of the end effector, extrapolated to the working
    /// point with [`two_point_displacement`].
    #[allow(clippy::too_many_arguments)] // reason: one reading's fields, in table order
    pub fn from_two_point(
        x: f64,
        y: f64,
        force_axis: usize,
        force: f64,
        upper: &[f64],
        lower: &[f64],
        spacing: f64,
        extension: f64,
    ) -> Result<Self, BuildError> {
        let n = upper.len().min(lower.len()).min(MAX_AXES);
        let mut d = [0.0; MAX_AXES];
        two_point_displacement(
            upper.get(..n).unwrap_or(&[]),
            lower.get(..n).unwrap_or(&[]),
            spacing,
            extension,
            d.get_mut(..n).unwrap_or(&mut []),
        )?;
        Ok(Self {
            x,
            y,
            force_axis,
            force,
            displacement: d,
        })
    }
}

/// Displacement of the working point W from those of two points on the tool axis (the
/// paper's static tests measure P_u and P_l on the end effector and extrapolate 2.5 mm below
/// its bottom, Appendix A and section 4.2.1).
///
/// With the end effector rigid and its rotation small, the displacement of a point on the
/// line P_u P_l is affine in its position along the line, so
///
/// ```text
/// delta_W = delta_l + (e / L) * (delta_l - delta_u)
/// ```
///
/// where `L = |P_u P_l| > 0` is the spacing of the two points \[m\] and `e` the signed distance
/// from P_l to W along the axis pointing from P_u to P_l \[m\] (`e > 0` beyond P_l, the paper's
/// `e = 2.5 mm`; `e = 0` gives P_l, `e = -L` gives P_u). `(delta_l - delta_u) / L` is the
/// small tilt of the tool axis \[rad\] for the transverse components. Component-wise on equal
/// length slices; `out` gets `min(len)` entries.
pub fn two_point_displacement(
    upper: &[f64],
    lower: &[f64],
    spacing: f64,
    extension: f64,
    out: &mut [f64],
) -> Result<(), BuildError> {
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(BuildError::BadTwoPoint { spacing });
    }
    let k = extension / spacing;
    for ((o, u), l) in out.iter_mut().zip(upper).zip(lower) {
        *o = l + k * (l - u);
    }
    Ok(())
}

/// Options of [`fit()`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// Number of force axes (1..=6).
    pub n_force: usize,
    /// Number of displacement axes (1..=6).
    pub n_displacement: usize,
    /// Coordinates closer than this are the same grid line \[m\]. Default 1e-6 m.
    pub position_tolerance: f64,
}

impl Default for FitOptions {
    /// The paper's case: 2 forces, 2 displacements, 1 um position tolerance.
    fn default() -> Self {
        Self {
            n_force: 2,
            n_displacement: 2,
            position_tolerance: 1e-6,
        }
    }
}

/// Groups coordinates into grid lines: returns the line centres (means, computed relative to
/// the lowest value so that equal coordinates give exactly that value) and each value's line.
pub(crate) fn cluster(
    values: &[f64],
    axis: &'static str,
    tolerance: f64,
) -> Result<(Vec<f64>, Vec<usize>), BuildError> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    let val = |k: usize| values.get(k).copied().unwrap_or(0.0);
    order.sort_by(|a, b| val(*a).total_cmp(&val(*b)));
    let mut centres = Vec::new();
    let mut line_of = vec![0usize; values.len()];
    let (mut start, mut prev, mut sum, mut count) = (f64::NAN, f64::NAN, 0.0, 0usize);
    for &k in &order {
        let v = val(k);
        if count > 0 && v - prev > tolerance {
            centres.push(start + sum / count as f64);
            (sum, count) = (0.0, 0);
        }
        if count == 0 {
            start = v;
        } else if v - start > tolerance {
            return Err(BuildError::AmbiguousCoordinate {
                axis,
                low: start,
                high: v,
                tolerance,
            });
        }
        if let Some(slot) = line_of.get_mut(k) {
            *slot = centres.len();
        }
        sum += v - start;
        count += 1;
        prev = v;
    }
    if count > 0 {
        centres.push(start + sum / count as f64);
    }
    Ok((centres, line_of))
}

/// Grid lines along x and y \[m\] and each reading's node index.
pub(crate) type Grid = (Vec<f64>, Vec<f64>, Vec<usize>);

/// Grid lines of the readings' positions and each reading's node `i * ny + j`; checks that
/// the nodes form a full rectilinear grid of at least 2 x 2.
pub(crate) fn grid_of(measurements: &[Measurement], tol: f64) -> Result<Grid, BuildError> {
    let xs: Vec<f64> = measurements.iter().map(|m| m.x).collect();
    let ys: Vec<f64> = measurements.iter().map(|m| m.y).collect();
    let (cx, line_x) = cluster(&xs, "x", tol)?;
    let (cy, line_y) = cluster(&ys, "y", tol)?;
    let (nx, ny) = (cx.len(), cy.len());
    if nx < 2 {
        return Err(BuildError::TooFew {
            what: "x nodes",
            needed: 2,
            got: nx,
        });
    }
    if ny < 2 {
        return Err(BuildError::TooFew {
            what: "y nodes",
            needed: 2,
            got: ny,
        });
    }
    let nodes: Vec<usize> = line_x
        .iter()
        .zip(&line_y)
        .map(|(i, j)| i * ny + j)
        .collect();
    let mut present = vec![false; nx * ny];
    for n in &nodes {
        if let Some(p) = present.get_mut(*n) {
            *p = true;
        }
    }
    let measured = present.iter().filter(|p| **p).count();
    if 2 * measured < nx * ny {
        return Err(BuildError::NotRectilinear {
            nodes: measured,
            distinct_x: nx,
            distinct_y: ny,
        });
    }
    if let Some(k) = present.iter().position(|p| !*p) {
        return Err(BuildError::MissingNode {
            x: cx.get(k / ny).copied().unwrap_or(f64::NAN),
            y: cy.get(k % ny).copied().unwrap_or(f64::NAN),
        });
    }
    Ok((cx, cy, nodes))
}

/// Reading indices `0..n` sorted by `key(row)` = (node, force axis, force), then row, so that
/// each (node, force axis) group is contiguous; a repeated key is
/// [`BuildError::DuplicateMeasurement`] naming both rows.
pub(crate) fn grouped_order(
    n: usize,
    key: impl Fn(usize) -> (usize, usize, f64),
) -> Result<Vec<usize>, BuildError> {
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|a, b| {
        let (ka, kb) = (key(*a), key(*b));
        ka.0.cmp(&kb.0)
            .then(ka.1.cmp(&kb.1))
            .then(ka.2.total_cmp(&kb.2))
            .then(a.cmp(b))
    });
    for w in order.windows(2) {
        if let [a, b] = w
            && key(*a) == key(*b)
        {
            return Err(BuildError::DuplicateMeasurement {
                row: *b,
                previous_row: *a,
            });
        }
    }
    Ok(order)
}

/// The least-squares lines `disp_d = slope F + offset` (Eq. 13, `A = [F_k 1]`, centred form)
/// of one node and force axis over its readings `(F_k, displacement_k)`, for the first `nd`
/// displacement axes, and the 2-norm condition number of `A` (at least 2 readings of
/// distinct forces: the caller checks).
pub(crate) fn fit_lines(
    group: &[(f64, [f64; MAX_AXES])],
    nd: usize,
) -> (f64, [LineStats; MAX_AXES]) {
    let k = group.len() as f64;
    let f_mean = group.iter().map(|m| m.0).sum::<f64>() / k;
    let sxx: f64 = group.iter().map(|m| (m.0 - f_mean) * (m.0 - f_mean)).sum();
    // Condition number of A = [F 1]: eigenvalues of A^T A = [[sum F^2, sum F], [sum F, k]].
    let (a, b, c) = (
        group.iter().map(|m| m.0 * m.0).sum::<f64>(),
        group.iter().map(|m| m.0).sum::<f64>(),
        k,
    );
    // hypot, not sqrt of the squares: (a - c)^2 overflows for forces above ~1e77 N.
    let lmax = 0.5 * (a + c + nalgebra::ComplexField::hypot(a - c, 2.0 * b));
    // det(A^T A) = k * sum (F - mean)^2, computed without cancellation.
    let lmin = k * sxx / lmax;
    let mut lines = [LineStats {
        slope: 0.0,
        offset: 0.0,
        rms: 0.0,
        r_squared: 1.0,
    }; MAX_AXES];
    for (d, line) in lines.iter_mut().enumerate().take(nd) {
        let disp = |m: &(f64, [f64; MAX_AXES])| m.1.get(d).copied().unwrap_or(0.0);
        let d_mean = group.iter().map(disp).sum::<f64>() / k;
        let sxy: f64 = group
            .iter()
            .map(|m| (m.0 - f_mean) * (disp(m) - d_mean))
            .sum();
        let slope = sxy / sxx;
        let offset = d_mean - slope * f_mean;
        let ss_res: f64 = group
            .iter()
            .map(|m| {
                let r = disp(m) - (slope * m.0 + offset);
                r * r
            })
            .sum();
        let ss_tot: f64 = group
            .iter()
            .map(|m| (disp(m) - d_mean) * (disp(m) - d_mean))
            .sum();
        *line = LineStats {
            slope,
            offset,
            rms: sqrt(ss_res / k),
            r_squared: if ss_tot > 0.0 {
                1.0 - ss_res / ss_tot
            } else {
                1.0
            },
        };
    }
    (sqrt(lmax / lmin), lines)
}

/// Fits a compliance map from static tests (Eq. 10-13).
///
/// Readings are grouped by node (coordinates within `position_tolerance` share a grid line)
/// and by loaded force axis `f`. For each node, `f` and displacement axis `d`, the line
/// `disp_d = slope[d][f] * F + offset[d][f]` is the least-squares solution
/// `Q = (A^T A)^-1 A^T B` of Eq. 13 with `A = [F_k 1]`, computed in centred form. As in the
/// paper (Eq. 10), each force axis keeps its own intercept as its offset, so the model's
/// zero-force displacement is the sum of the offsets over the force axes.
///
/// Errors: non-finite values ([`BuildError::NonFinite`] with row and column `x`, `y`,
/// `force` or `d<k>`), a force axis `>= n_force`, ambiguous or non-rectilinear positions, a
/// missing node, a repeated (node, axis, force), fewer than 2 force levels for a line;
/// [`BuildError::Budget`] past [`MAX_MEASUREMENTS`].
pub fn fit(
    measurements: &[Measurement],
    options: &FitOptions,
) -> Result<ComplianceMap, BuildError> {
    let (nf, nd) = (options.n_force, options.n_displacement);
    check_counts(nf, nd)?;
    check_measurements(measurements, nf, nd)?;
    let tol = options.position_tolerance;
    let (cx, cy, nodes) = grid_of(measurements, tol)?;
    let (nx, ny) = (cx.len(), cy.len());
    let readings = Readings {
        measurements,
        nodes: &nodes,
    };
    let order = grouped_order(measurements.len(), |r| readings.key(r))?;
    let block = nd * nf;
    let mut fitter = Fitter {
        readings,
        order: &order,
        cx: &cx,
        cy: &cy,
        nf,
        nd,
        slopes: vec![0.0; nx * ny * block],
        offsets: vec![0.0; nx * ny * block],
        pos: 0,
    };
    let mut stats = Vec::with_capacity(nx * ny);
    for node in 0..nx * ny {
        let nfit = fitter.node(node)?;
        check_node_stats(&nfit)?;
        stats.push(nfit);
    }
    let Fitter {
        slopes, offsets, ..
    } = fitter;
    let mut map = ComplianceMap::new(cx, cy, nf, nd, slopes, offsets)?;
    map.set_fit_stats(Some(stats));
    Ok(map)
}

/// Checks the readings before any grouping: at most [`MAX_MEASUREMENTS`], finite positions,
/// forces and first `nd` displacements, force axes below `nf`.
fn check_measurements(
    measurements: &[Measurement],
    nf: usize,
    nd: usize,
) -> Result<(), BuildError> {
    check_budget(measurements.len())?;
    for (row, m) in measurements.iter().enumerate() {
        for (column, v) in [("x", m.x), ("y", m.y), ("force", m.force)] {
            if !v.is_finite() {
                return Err(BuildError::NonFiniteMeasurement { row, column });
            }
        }
        check_load(row, &m.displacement, m.force_axis, nf, nd)?;
    }
    Ok(())
}

/// At most [`MAX_MEASUREMENTS`] readings, for the 2-D and the N-D fit.
pub(super) fn check_budget(readings: usize) -> Result<(), BuildError> {
    if readings > MAX_MEASUREMENTS {
        return Err(BuildError::Budget {
            what: "measurements",
            budget: "MAX_MEASUREMENTS",
            limit: MAX_MEASUREMENTS,
            requested: readings,
        });
    }
    Ok(())
}

/// The part of a reading's check the 2-D and N-D fits share: its first `nd` displacements
/// finite and its force axis below `nf`, errors naming row `row`.
pub(super) fn check_load(
    row: usize,
    displacement: &[f64; MAX_AXES],
    force_axis: usize,
    nf: usize,
    nd: usize,
) -> Result<(), BuildError> {
    for (column, v) in DISPLACEMENT_COLUMNS.iter().zip(displacement).take(nd) {
        if !v.is_finite() {
            return Err(BuildError::NonFiniteMeasurement { row, column });
        }
    }
    if force_axis >= nf {
        return Err(BuildError::ForceAxisOutOfRange {
            row,
            force_axis,
            n_force: nf,
        });
    }
    Ok(())
}

/// The readings with each one's node `i * ny + j` (from [`grid_of`]).
#[derive(Clone, Copy)]
struct Readings<'a> {
    measurements: &'a [Measurement],
    nodes: &'a [usize],
}

impl Readings<'_> {
    /// Reading `r`'s grouping key: (node, force axis, force \[N\]).
    fn key(&self, r: usize) -> (usize, usize, f64) {
        let m = self.measurements.get(r);
        (
            self.nodes.get(r).copied().unwrap_or(0),
            m.map_or(0, |m| m.force_axis),
            m.map_or(0.0, |m| m.force),
        )
    }
}

/// The fit node by node: the readings in [`grouped_order`], the grid lines \[m\], and the
/// slopes and offsets filled at `node * nd * nf + d * nf + f`.
struct Fitter<'a> {
    readings: Readings<'a>,
    order: &'a [usize],
    cx: &'a [f64],
    cy: &'a [f64],
    nf: usize,
    nd: usize,
    slopes: Vec<f64>,
    offsets: Vec<f64>,
    /// The first entry of `order` not yet fitted.
    pos: usize,
}

impl Fitter<'_> {
    /// Fits the lines of node `node` (`i * ny + j`) for every force axis, its readings being
    /// the next in `order`; returns its statistics.
    fn node(&mut self, node: usize) -> Result<NodeFit, BuildError> {
        let (nf, ny, block) = (self.nf, self.cy.len(), self.nd * self.nf);
        let (node_x, node_y) = (
            self.cx.get(node / ny).copied().unwrap_or(f64::NAN),
            self.cy.get(node % ny).copied().unwrap_or(f64::NAN),
        );
        let mut nfit = NodeFit {
            i: node / ny,
            j: node % ny,
            x: node_x,
            y: node_y,
            lines: vec![
                LineStats {
                    slope: 0.0,
                    offset: 0.0,
                    rms: 0.0,
                    r_squared: 1.0
                };
                block
            ],
            condition: vec![0.0; nf],
            samples: vec![0; nf],
        };
        for f in 0..nf {
            self.axis(node, f, &mut nfit)?;
        }
        Ok(nfit)
    }

    /// Fits the lines of node `node` under force axis `f` into the tables and `nfit`: at
    /// least two force levels, the next readings in `order`.
    fn axis(&mut self, node: usize, f: usize, nfit: &mut NodeFit) -> Result<(), BuildError> {
        let (nf, nd, block) = (self.nf, self.nd, self.nd * self.nf);
        let (order, readings) = (self.order, self.readings);
        let begin = self.pos;
        while order
            .get(self.pos)
            .is_some_and(|r| readings.key(*r).0 == node && readings.key(*r).1 == f)
        {
            self.pos += 1;
        }
        let rows = order.get(begin..self.pos).unwrap_or(&[]);
        if rows.len() < 2 {
            return Err(BuildError::TooFewForceLevels {
                node_x: nfit.x,
                node_y: nfit.y,
                force_axis: f,
                levels: rows.len(),
            });
        }
        let group: Vec<(f64, [f64; MAX_AXES])> = rows
            .iter()
            .filter_map(|r| readings.measurements.get(*r))
            .map(|m| (m.force, m.displacement))
            .collect();
        let (condition, lines) = fit_lines(&group, nd);
        if let Some(slot) = nfit.condition.get_mut(f) {
            *slot = condition;
        }
        if let Some(slot) = nfit.samples.get_mut(f) {
            *slot = group.len();
        }
        for (d, line) in lines.iter().enumerate().take(nd) {
            let idx = node * block + d * nf + f;
            if let Some(s) = self.slopes.get_mut(idx) {
                *s = line.slope;
            }
            if let Some(o) = self.offsets.get_mut(idx) {
                *o = line.offset;
            }
            if let Some(l) = nfit.lines.get_mut(d * nf + f) {
                *l = *line;
            }
        }
        Ok(())
    }
}

/// Refuses a node whose statistics are not finite: sums of squares of huge (finite) forces or
/// displacements overflow, and JSON cannot hold NaN or inf.
fn check_node_stats(nfit: &NodeFit) -> Result<(), BuildError> {
    let mut values = nfit.condition.iter().copied().chain(
        nfit.lines
            .iter()
            .flat_map(|l| [l.slope, l.offset, l.rms, l.r_squared]),
    );
    if let Some(index) = values.position(|v| !v.is_finite()) {
        return Err(BuildError::NonFinite {
            what: "fit statistics (condition, then slope, offset, rms, r_squared per \
                   line) of a node: forces or displacements too large",
            index,
        });
    }
    Ok(())
}
