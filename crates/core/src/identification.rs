//! Identification from measurements (std, least squares with faer):
//!
//! - virtual-joint compliances `1/k` from loaded/unloaded measurements (VJM paper, section
//!   2.5): either the rotation of the frames on either side of a virtual joint (the paper's
//!   measurement cubes, [`identify_from_frames`]) or the TCP deflection of the whole robot
//!   ([`identify_from_tcp`]); per-parameter standard errors, the rank, and parameters the
//!   data cannot see flagged rather than set;
//! - the force/torque sensor's internal offsets, the end effector's weight and centre of
//!   gravity (Eq. 12-15, by least squares over any three or more orientations) and the
//!   residual-offset polynomial in the orientation quaternion (Eq. 16-17).

// reason: offline (std) code; every index below is bounded by construction (rows of a
// fixed width built here, solution vectors of a known length).
#![allow(clippy::indexing_slicing)]

use std::vec;
use std::vec::Vec;

use faer::Mat;
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use crate::compensation::SensorCalibration;
use crate::compensation::sensor::{POLY_TERMS, orientation_quaternion, poly_terms};
use crate::error::{BuildError, TickError};
use crate::vjm::{Data, Element, Model, Vector6, forward};

/// Singular values below `RANK_TOLERANCE * sigma_max` count as zero.
pub const RANK_TOLERANCE: f64 = 1.0e-9;
/// A parameter whose squared weight in the null space exceeds this is unobservable.
const NULL_WEIGHT: f64 = 1.0e-6;

/// A linear least-squares solution with its statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct LeastSquares {
    /// Minimum-norm solution (unobservable directions set to zero).
    pub x: Vec<f64>,
    /// Standard error of each parameter from the residual variance (NaN without redundancy).
    pub std_error: Vec<f64>,
    /// Whether each parameter is determined by the data.
    pub identifiable: Vec<bool>,
    /// Numerical rank of the design matrix.
    pub rank: usize,
    /// Singular values, largest first.
    pub singular_values: Vec<f64>,
    /// Root mean square of the residuals.
    pub residual_rms: f64,
}

/// Most measurements one identification accepts (the one measurements budget of deflect,
/// [`crate::compliance_map::MAX_MEASUREMENTS`]: 100 000; a calibration campaign has tens to
/// thousands, the VJM paper's had a few dozen). Past it the call refuses with
/// [`BuildError::Budget`] before any work, which bounds its time (about 10 us per TCP
/// measurement); memory does not grow with the count at all ([`LeastSquaresAccumulator`]).
pub use crate::compliance_map::MAX_MEASUREMENTS;

/// Rows folded into the accumulated factor at a time.
const BLOCK: usize = 256;

/// Linear least squares `A x = b` accumulated row by row in O(n^2) memory, whatever the number
/// of rows: the rows are buffered `BLOCK` at a time and folded into the triangular factor of a
/// Householder QR of the augmented matrix `[A | b]` (faer). [`Self::finish`] then solves with
/// an SVD of the n x n factor, which has the singular values of `A` itself (the normal
/// equations would square the condition number; this does not).
#[derive(Debug, Clone)]
pub struct LeastSquaresAccumulator {
    n: usize,
    // (n + 1) x (n + 1) upper triangular factor of [A | b] so far.
    r: Mat<f64>,
    // Buffered rows, each n + 1 values (the row and its b).
    pending: Vec<f64>,
    rows: usize,
}

impl LeastSquaresAccumulator {
    /// An empty problem with `n` unknowns.
    pub fn new(n: usize) -> Self {
        Self {
            n,
            r: Mat::zeros(n + 1, n + 1),
            pending: Vec::with_capacity(BLOCK * (n + 1)),
            rows: 0,
        }
    }

    /// Rows pushed so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Adds the equation `row . x = b` (`row` of `n` entries, all finite).
    pub fn push(&mut self, row: &[f64], b: f64) -> Result<(), BuildError> {
        if row.len() != self.n {
            return Err(BuildError::WrongLength {
                what: "least-squares row",
                expected: self.n,
                got: row.len(),
            });
        }
        if let Some(index) = row.iter().chain([&b]).position(|v| !v.is_finite()) {
            return Err(BuildError::NonFinite {
                what: "least-squares row (then b)",
                index,
            });
        }
        self.pending.extend_from_slice(row);
        self.pending.push(b);
        self.rows += 1;
        if self.pending.len() >= BLOCK * (self.n + 1) {
            self.fold();
        }
        Ok(())
    }

    /// QR of the factor stacked over the buffered rows; keeps the new factor.
    fn fold(&mut self) {
        let w = self.n + 1;
        let k = self.pending.len() / w;
        if k == 0 {
            return;
        }
        let stacked = Mat::<f64>::from_fn(w + k, w, |i, j| {
            if i < w {
                self.r[(i, j)]
            } else {
                self.pending.get((i - w) * w + j).copied().unwrap_or(0.0)
            }
        });
        let qr = stacked.qr();
        let r = qr.thin_R();
        self.r = Mat::from_fn(w, w, |i, j| if j >= i { r[(i, j)] } else { 0.0 });
        self.pending.clear();
    }

    /// The minimum-norm solution with rank, standard errors and identifiability.
    pub fn finish(mut self) -> Result<LeastSquares, BuildError> {
        self.fold();
        let (m, n) = (self.rows, self.n);
        if m == 0 || n == 0 {
            return Err(BuildError::TooFew {
                what: "measurements",
                needed: 1,
                got: m,
            });
        }
        let r = Mat::<f64>::from_fn(n, n, |i, j| self.r[(i, j)]);
        let qtb: Vec<f64> = (0..n).map(|i| self.r[(i, n)]).collect();
        let rho = self.r[(n, n)];
        let svd = r.svd().map_err(|_| BuildError::Numerical {
            what: "least-squares SVD",
        })?;
        let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
        let k = m.min(n);
        let sigma: Vec<f64> = (0..k).map(|i| s[i]).collect();
        let sigma_max = sigma.iter().copied().fold(0.0, f64::max);
        let tol = sigma_max * RANK_TOLERANCE;
        let rank = sigma.iter().filter(|&&x| x > tol).count();
        let mut x = vec![0.0; n];
        for (i, &si) in sigma.iter().enumerate() {
            if si <= tol {
                continue;
            }
            let ub: f64 = (0..n).map(|r| u[(r, i)] * qtb[r]).sum();
            for (j, xj) in x.iter_mut().enumerate() {
                *xj += v[(j, i)] * ub / si;
            }
        }
        // |b - A x|^2 = |Q^T b - R x|^2 over the first n rows plus what lies outside A's
        // range (rho^2).
        let rss: f64 = (0..n)
            .map(|i| {
                let e = qtb[i] - (0..n).map(|j| r[(i, j)] * x[j]).sum::<f64>();
                e * e
            })
            .sum::<f64>()
            + rho * rho;
        let dof = m.saturating_sub(rank);
        let s2 = if dof > 0 { rss / dof as f64 } else { f64::NAN };
        let mut std_error = vec![0.0; n];
        let mut identifiable = vec![true; n];
        for j in 0..n {
            let mut var = 0.0;
            let mut null = 0.0;
            for i in 0..n {
                let vji = v[(j, i)];
                match sigma.get(i) {
                    Some(&si) if si > tol => var += vji * vji / (si * si),
                    _ => null += vji * vji,
                }
            }
            std_error[j] = (s2 * var).sqrt();
            identifiable[j] = null < NULL_WEIGHT;
        }
        Ok(LeastSquares {
            x,
            std_error,
            identifiable,
            rank,
            singular_values: sigma,
            residual_rms: (rss / m as f64).sqrt(),
        })
    }
}

/// Solves `A x = b` (rows of `a`, each of `n` entries) in the least-squares sense with rank,
/// standard errors and identifiability ([`LeastSquaresAccumulator`] over the rows).
pub fn least_squares(rows: &[Vec<f64>], b: &[f64], n: usize) -> Result<LeastSquares, BuildError> {
    let mut acc = LeastSquaresAccumulator::new(n);
    for (row, &bi) in rows.iter().zip(b) {
        acc.push(row, bi)?;
    }
    acc.finish()
}

/// Refuses more than [`MAX_MEASUREMENTS`].
fn check_count(count: usize) -> Result<(), BuildError> {
    if count > MAX_MEASUREMENTS {
        return Err(BuildError::Budget {
            what: "measurements",
            budget: "MAX_MEASUREMENTS",
            limit: MAX_MEASUREMENTS,
            requested: count,
        });
    }
    Ok(())
}

/// Identified stiffness of one virtual-joint axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisEstimate {
    /// Virtual joint index (chain order).
    pub spring: usize,
    /// 0, 1, 2 for the spring frame's x, y, z (k_C, k_B, k_A).
    pub axis: usize,
    /// Compliance `1/k` \[rad / (N m)\], or `None` when the data cannot see this axis.
    pub compliance: Option<f64>,
    /// Standard error of the compliance \[rad / (N m)\].
    pub std_error: f64,
}

impl AxisEstimate {
    /// Stiffness `k = 1/c` \[N m / rad\] (`inf` for a zero compliance), `None` if unobservable
    /// or the estimate is not positive.
    pub fn stiffness(&self) -> Option<f64> {
        match self.compliance {
            Some(c) if c > 0.0 => Some(1.0 / c),
            Some(0.0) => Some(f64::INFINITY),
            _ => None,
        }
    }
}

/// Result of a stiffness identification.
#[derive(Debug, Clone, PartialEq)]
pub struct StiffnessIdentification {
    /// One entry per identified axis.
    pub axes: Vec<AxisEstimate>,
    /// The least-squares details (parameters in the order of `axes`).
    pub fit: LeastSquares,
}

/// A spring frame's rigid pose (base frame) and its compliances.
type SpringFrame = (Isometry3<f64>, Vector3<f64>);

/// Poses of every spring frame and of the TCP at `q` (rigid).
fn spring_frames(
    model: &Model,
    q: &[f64],
) -> Result<(Vec<SpringFrame>, Isometry3<f64>), TickError> {
    let mut data = Data::new(model);
    let tcp = forward(model, &mut data, q)?;
    let mut frames = Vec::new();
    let mut t = Isometry3::identity();
    let mut qi = q.iter();
    for e in model.elements() {
        match *e {
            Element::Fixed(m) => t *= m,
            Element::Revolute { axis, .. } => {
                let a = qi.next().copied().unwrap_or(0.0);
                t *= UnitQuaternion::from_axis_angle(&axis, a);
            }
            Element::Prismatic { axis, .. } => {
                let a = qi.next().copied().unwrap_or(0.0);
                t *= nalgebra::Translation3::from(axis.into_inner() * a);
            }
            Element::Spring {
                compliance, offset, ..
            } => frames.push((t * offset, compliance)),
            Element::Mass { .. } => {}
        }
    }
    Ok((frames, tcp))
}

/// The moment on each spring in its own frame under `wrench` (Eq. 5-6, undeformed pose).
fn spring_moments(
    frames: &[SpringFrame],
    tcp: &Isometry3<f64>,
    wrench: &Vector6,
) -> Vec<Vector3<f64>> {
    let f: Vector3<f64> = wrench.fixed_rows::<3>(0).into_owned();
    let m: Vector3<f64> = wrench.fixed_rows::<3>(3).into_owned();
    frames
        .iter()
        .map(|(t, _)| {
            let r = tcp.translation.vector - t.translation.vector;
            t.rotation.inverse() * (m + r.cross(&f))
        })
        .collect()
}

/// Which axes to identify: the compliant axes of the model (`all_axes = false`; rigid axes stay
/// rigid), or every axis of every spring.
fn parameter_axes(model: &Model, all_axes: bool) -> Vec<(usize, usize)> {
    model
        .elements()
        .iter()
        .filter_map(|e| match e {
            Element::Spring {
                compliance, index, ..
            } => Some((*index, *compliance)),
            _ => None,
        })
        .flat_map(|(s, c)| {
            (0..3)
                .filter(move |&a| all_axes || c.get(a).copied().unwrap_or(0.0) != 0.0)
                .map(move |a| (s, a))
        })
        .collect()
}

fn finish(params: Vec<(usize, usize)>, fit: LeastSquares) -> StiffnessIdentification {
    let axes = params
        .iter()
        .enumerate()
        .map(|(j, &(spring, axis))| AxisEstimate {
            spring,
            axis,
            compliance: fit
                .identifiable
                .get(j)
                .copied()
                .unwrap_or(false)
                .then(|| fit.x.get(j).copied().unwrap_or(f64::NAN)),
            std_error: fit.std_error.get(j).copied().unwrap_or(f64::NAN),
        })
        .collect();
    StiffnessIdentification { axes, fit }
}

/// A frame-pair measurement (section 2.5): the robot at `q` under the TCP `wrench` (base
/// frame, moment about the TCP); the frames on either side of virtual joint `spring` turned
/// against each other by `rotation` \[rad\] (rotation vector in the spring frame, loaded minus
/// unloaded; to first order the Eq. 7 angles `[alpha, beta, gamma]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameMeasurement<'q> {
    /// Joint values.
    pub q: &'q [f64],
    /// Known load.
    pub wrench: Vector6,
    /// Virtual joint index (chain order).
    pub spring: usize,
    /// Measured relative rotation.
    pub rotation: Vector3<f64>,
}

/// Compliances from frame-pair measurements: `rotation_a = c_a M_a` per axis, the moment
/// `M` from the known load in the undeformed pose (Eq. 5-6), least squares over all
/// measurements. With `all_axes` the model's rigid axes are identified too.
pub fn identify_from_frames(
    model: &Model,
    measurements: &[FrameMeasurement<'_>],
    all_axes: bool,
) -> Result<StiffnessIdentification, BuildError> {
    check_count(measurements.len())?;
    let params = parameter_axes(model, all_axes);
    let mut acc = LeastSquaresAccumulator::new(params.len());
    let mut row = vec![0.0; params.len()];
    for (i, meas) in measurements.iter().enumerate() {
        let bad = |error| BuildError::BadMeasurement {
            measurement: i,
            error,
        };
        if meas.spring >= model.spring_count() {
            return Err(BuildError::UnknownSpring {
                measurement: i,
                spring: meas.spring,
                springs: model.spring_count(),
            });
        }
        crate::error::check_finite("wrench", meas.wrench.as_slice()).map_err(bad)?;
        crate::error::check_finite("rotation", meas.rotation.as_slice()).map_err(bad)?;
        let (frames, tcp) = spring_frames(model, meas.q).map_err(bad)?;
        let moments = spring_moments(&frames, &tcp, &meas.wrench);
        let m = moments
            .get(meas.spring)
            .copied()
            .unwrap_or_else(Vector3::zeros);
        for a in 0..3 {
            for (r, &(s, pa)) in row.iter_mut().zip(&params) {
                *r = if s == meas.spring && pa == a {
                    m[a]
                } else {
                    0.0
                };
            }
            acc.push(&row, meas.rotation[a])?;
        }
    }
    Ok(finish(params, acc.finish()?))
}

/// A TCP measurement: the robot at `q` under `wrench` deflects by `deflection`
/// `[dp; dr]` \[m, rad\] (base frame). With `translation_only` only `dp` was measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TcpMeasurement<'q> {
    /// Joint values.
    pub q: &'q [f64],
    /// Known load.
    pub wrench: Vector6,
    /// Measured deflection.
    pub deflection: Vector6,
    /// Only the translation was measured (e.g. a laser tracker without orientation).
    pub translation_only: bool,
}

/// Compliances from TCP deflections: the linearized model `delta = sum_s,a c_sa j_sa (j_sa .
/// w)` (`j_sa` the TCP twist of a unit turn of spring s about axis a) is linear in the
/// compliances; least squares over all measurements.
pub fn identify_from_tcp(
    model: &Model,
    measurements: &[TcpMeasurement<'_>],
    all_axes: bool,
) -> Result<StiffnessIdentification, BuildError> {
    check_count(measurements.len())?;
    let params = parameter_axes(model, all_axes);
    let mut acc = LeastSquaresAccumulator::new(params.len());
    let mut row = vec![0.0; params.len()];
    for (i, meas) in measurements.iter().enumerate() {
        let bad = |error| BuildError::BadMeasurement {
            measurement: i,
            error,
        };
        crate::error::check_finite("wrench", meas.wrench.as_slice()).map_err(bad)?;
        crate::error::check_finite("deflection", meas.deflection.as_slice()).map_err(bad)?;
        let (frames, tcp) = spring_frames(model, meas.q).map_err(bad)?;
        // Unit-turn twists of every parameter.
        let cols: Vec<Vector6> = params
            .iter()
            .map(|&(s, a)| {
                let (t, _) = frames
                    .get(s)
                    .copied()
                    .unwrap_or((Isometry3::identity(), Vector3::zeros()));
                let u = t.rotation * Vector3::ith(a, 1.0);
                let lin = u.cross(&(tcp.translation.vector - t.translation.vector));
                Vector6::new(lin.x, lin.y, lin.z, u.x, u.y, u.z)
            })
            .collect();
        let n_rows = if meas.translation_only { 3 } else { 6 };
        for r in 0..n_rows {
            for (x, c) in row.iter_mut().zip(&cols) {
                *x = c[r] * c.dot(&meas.wrench);
            }
            acc.push(&row, meas.deflection[r]).map_err(|_| {
                bad(TickError::NonFiniteOutput {
                    what: "design row",
                    index: r,
                })
            })?;
        }
    }
    Ok(finish(params, acc.finish()?))
}

/// Result of the sensor identification.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorIdentification {
    /// Offsets, weight, centre of gravity and (if fitted) the residual polynomial; the
    /// `sensor_to_tcp` transform is copied from the input.
    pub calibration: SensorCalibration,
    /// Rank of the force fit (4 = offsets and weight determined).
    pub force_rank: usize,
    /// Rank of the moment fit (6 = offsets and centre of gravity determined).
    pub moment_rank: usize,
    /// RMS of the force residuals after the physical model \[N\].
    pub force_rms: f64,
    /// RMS of the moment residuals after the physical model \[N m\].
    pub moment_rms: f64,
    /// RMS left after the residual polynomial \[N or N m\], if fitted.
    pub polynomial_rms: Option<f64>,
}

/// Identifies the sensor's internal offsets `F_SI, M_SI`, the end effector's weight `G` and
/// centre of gravity `r_G` (the quantities of Eq. 12-15) from unloaded readings at known
/// sensor orientations `r_bs` (base from sensor), by least squares: forces
/// `F = F_SI + R^T (0, 0, -G)`, then moments `M = M_SI + r_G x (R^T g)`. Needs at least
/// three orientations with different gravity directions. With `fit_polynomial` the
/// residuals are then fitted by the quadratic quaternion polynomial of Eq. 16-17, one per
/// wrench component (at least 15 orientations; the paper used 27).
pub fn identify_sensor(
    orientations: &[UnitQuaternion<f64>],
    readings: &[Vector6],
    fit_polynomial: bool,
    sensor_to_tcp: Isometry3<f64>,
) -> Result<SensorIdentification, BuildError> {
    check_count(orientations.len().max(readings.len()))?;
    let n = orientations.len().min(readings.len());
    let needed = if fit_polynomial { POLY_TERMS } else { 3 };
    if n < needed || orientations.len() != readings.len() {
        return Err(BuildError::TooFew {
            what: "measurements",
            needed,
            got: n,
        });
    }
    for (i, r) in readings.iter().enumerate() {
        crate::error::check_finite("reading", r.as_slice()).map_err(|error| {
            BuildError::BadMeasurement {
                measurement: i,
                error,
            }
        })?;
    }
    // Forces: unknowns [F_SI (3), G].
    let mut rows = Vec::new();
    let mut b = Vec::new();
    for (r, w) in orientations.iter().zip(readings) {
        let down = r.inverse() * Vector3::new(0.0, 0.0, -1.0);
        for k in 0..3 {
            let mut row = vec![0.0; 4];
            row[k] = 1.0;
            row[3] = down[k];
            rows.push(row);
            b.push(w[k]);
        }
    }
    let ff = least_squares(&rows, &b, 4)?;
    let f_si = Vector3::new(ff.x[0], ff.x[1], ff.x[2]);
    let weight = ff.x[3];
    // Moments: M = M_SI - (R^T g) x r_G = M_SI - skew(g_s) r_G; unknowns [M_SI (3), r_G (3)].
    let mut rows = Vec::new();
    let mut b = Vec::new();
    for (r, w) in orientations.iter().zip(readings) {
        let g = r.inverse() * Vector3::new(0.0, 0.0, -weight);
        // -skew(g) = [[0, g.z, -g.y], [-g.z, 0, g.x], [g.y, -g.x, 0]]
        let ms = [[0.0, g.z, -g.y], [-g.z, 0.0, g.x], [g.y, -g.x, 0.0]];
        for (k, mk) in ms.iter().enumerate() {
            let mut row = vec![0.0; 6];
            row[k] = 1.0;
            row[3..].copy_from_slice(mk);
            rows.push(row);
            b.push(w[3 + k]);
        }
    }
    let mf = least_squares(&rows, &b, 6)?;
    let mut calibration = SensorCalibration {
        force_offset: f_si,
        moment_offset: Vector3::new(mf.x[0], mf.x[1], mf.x[2]),
        weight,
        center_of_gravity: Vector3::new(mf.x[3], mf.x[4], mf.x[5]),
        sensor_to_tcp,
        ..SensorCalibration::default()
    };
    let mut polynomial_rms = None;
    if fit_polynomial {
        let terms: Vec<Vec<f64>> = orientations
            .iter()
            .map(|r| poly_terms(&orientation_quaternion(r)).to_vec())
            .collect();
        let mut sq = 0.0;
        for c in 0..6 {
            let resid: Vec<f64> = orientations
                .iter()
                .zip(readings)
                .map(|(r, w)| w[c] - calibration.unloaded_reading(r)[c])
                .collect();
            let fit = least_squares(&terms, &resid, POLY_TERMS)?;
            for (dst, &v) in calibration.residual[c].iter_mut().zip(&fit.x) {
                *dst = v;
            }
            sq += fit.residual_rms * fit.residual_rms;
        }
        polynomial_rms = Some((sq / 6.0).sqrt());
    }
    Ok(SensorIdentification {
        calibration,
        force_rank: ff.rank,
        moment_rank: mf.rank,
        force_rms: ff.residual_rms,
        moment_rms: mf.residual_rms,
        polynomial_rms,
    })
}
