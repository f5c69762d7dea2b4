//! 6-D pose inverse kinematics of a serial chain by damped least squares, warm-started from
//! a seed, optionally of the *loaded* chain: the joints at which the TCP, deflected by a
//! wrench through the virtual-joint model (exact, Eq. 2-9 of Hähn and Weigold, or the
//! linearized compliance), lands on the target. The loaded problem is what a deflection
//! correction needs: command those joints and the compliant robot reaches the target.
//!
//! Each iteration evaluates the (loaded) pose and the rigid joint Jacobian `J` in one pass,
//! and steps `dq = J^T (J J^T + lambda^2 I)^-1 e` with the pose error
//! `e = [p_t - p; log(R_t R^T)]`, clipped to `max_step`. The loaded Jacobian differs from the
//! rigid one by the deflection's slope, far below 1 %: the iteration still converges, slightly
//! slower than Newton. Bounded: at most `max_iterations` steps. Allocation-free; the
//! workspace is the chain's [`Data`].

use nalgebra::{Isometry3, Matrix6};

use crate::error::{BuildError, TickError, check_finite, check_output, param};
use crate::vjm::{self, Data, Load, MAX_CORRECTION_ITERATIONS, MAX_DOF, Model, Vector6};

/// Settings of [`pose_ik`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseIkOptions {
    /// Iteration budget, at most [`MAX_CORRECTION_ITERATIONS`].
    pub max_iterations: usize,
    /// Position tolerance \[m\].
    pub position_tolerance: f64,
    /// Orientation tolerance \[rad\].
    pub orientation_tolerance: f64,
    /// Damping `lambda` \[m/rad\]: keeps steps bounded near singularities.
    pub damping: f64,
    /// Largest joint step per iteration (Euclidean norm) \[rad or m\].
    pub max_step: f64,
    /// Singularity threshold on the (estimated) smallest singular value of the 6 x n joint
    /// Jacobian \[m/rad\] (rows mix m and rad; the position rows dominate on a robot arm).
    pub min_sigma: f64,
}

impl Default for PoseIkOptions {
    /// 20 iterations, 1e-8 m and 1e-8 rad, damping 1e-6, steps of at most 0.5 rad,
    /// threshold 1e-3 m/rad.
    fn default() -> Self {
        Self {
            max_iterations: 20,
            position_tolerance: 1.0e-8,
            orientation_tolerance: 1.0e-8,
            damping: 1.0e-6,
            max_step: 0.5,
            min_sigma: 1.0e-3,
        }
    }
}

impl PoseIkOptions {
    /// Checks every setting.
    pub fn validate(&self) -> Result<(), BuildError> {
        if self.max_iterations == 0 || self.max_iterations > MAX_CORRECTION_ITERATIONS {
            return Err(BuildError::InvalidParameter {
                what: "max_iterations",
                value: self.max_iterations as f64,
                expected: "in 1..=MAX_CORRECTION_ITERATIONS (256)",
            });
        }
        param(
            "position_tolerance",
            self.position_tolerance,
            self.position_tolerance > 0.0,
            "> 0 (m)",
        )?;
        param(
            "orientation_tolerance",
            self.orientation_tolerance,
            self.orientation_tolerance > 0.0,
            "> 0 (rad)",
        )?;
        param("damping", self.damping, self.damping >= 0.0, ">= 0")?;
        param("max_step", self.max_step, self.max_step > 0.0, "> 0")?;
        param("min_sigma", self.min_sigma, self.min_sigma >= 0.0, ">= 0")?;
        Ok(())
    }
}

/// Result of [`pose_ik`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[must_use]
pub struct PoseIkSolution {
    /// Joints \[rad or m\]; entries past the dof are zero.
    pub q: [f64; MAX_DOF],
    /// Steps taken.
    pub iterations: usize,
    /// Position error left \[m\].
    pub position_error: f64,
    /// Orientation error left \[rad\].
    pub orientation_error: f64,
    /// Estimated smallest singular value of the joint Jacobian at the solution.
    pub sigma_min: f64,
    /// Deflection `[dp; dr]` of the TCP at `q` under the load (zero for [`Load::Rigid`]).
    pub deflection: Vector6,
}

/// `J J^T` over the first `dof` columns (no transposed copy of the 6 x 8 Jacobian).
#[inline]
fn gram(j: &nalgebra::SMatrix<f64, 6, MAX_DOF>, dof: usize) -> Matrix6<f64> {
    let mut g = Matrix6::zeros();
    for col in j.column_iter().take(dof) {
        // Rank-one update with the column: g += col col^T.
        g.ger(1.0, &col, &col, 1.0);
    }
    g
}

/// Whether the smallest singular value of `J` is at least `min_sigma`, decided exactly from the
/// Gram matrix `J J^T`: `J J^T - min_sigma^2 I` has a Cholesky factor iff every eigenvalue of
/// `J J^T` is above `min_sigma^2`. Returns `Ok(estimate)` or `Err(estimate)`, the estimate of
/// the smallest singular value being an upper bound from three inverse iterations on that
/// shifted matrix with a Rayleigh quotient (exact to a few percent; the decision does not
/// depend on it). Cheap enough per tick: one or two 6 x 6 factorisations and three solves.
fn singularity(jj: &Matrix6<f64>, min_sigma: f64) -> Result<f64, f64> {
    let shift = min_sigma * min_sigma;
    let estimate = |chol: &nalgebra::Cholesky<f64, nalgebra::U6>, shift: f64| {
        let mut v = Vector6::repeat(1.0 / nalgebra::ComplexField::sqrt(6.0f64));
        let mut rayleigh = 0.0;
        for _ in 0..3 {
            let w = chol.solve(&v);
            // v^T B^-1 v for the unit v: at most 1 / lambda_min(B), converging as the
            // square of the eigenvalue ratio.
            rayleigh = v.dot(&w);
            let n = w.norm();
            if !(n.is_finite() && n > 0.0 && rayleigh > 0.0) {
                return 0.0;
            }
            v = w / n;
        }
        nalgebra::ComplexField::sqrt(1.0 / rayleigh + shift)
    };
    match (jj - Matrix6::identity() * shift).cholesky() {
        Some(chol) => Ok(estimate(&chol, shift)),
        None => Err(jj.cholesky().map_or(0.0, |c| estimate(&c, 0.0))),
    }
}

/// Joints at which the TCP, loaded by `wrench` \[N, N m\] (base frame, moment about the TCP)
/// as `load` says ([`vjm::deflection`]; `wrench` is unused for [`Load::Rigid`]), reaches
/// `target`, from `seed` (see the module docs).
/// [`TickError::NotConverged`] when the budget ends first (e.g. an unreachable target),
/// [`TickError::Singular`] at a singular pose, [`TickError::WrongLength`] /
/// [`TickError::NonFinite`] for bad inputs. On success `data.tcp` is the rigid pose of the
/// solution (the pose to command).
pub fn pose_ik(
    model: &Model,
    data: &mut Data,
    target: &Isometry3<f64>,
    seed: &[f64],
    wrench: &Vector6,
    load: Load<'_>,
    options: &PoseIkOptions,
) -> Result<PoseIkSolution, TickError> {
    let dof = model.dof();
    if seed.len() != dof {
        return Err(TickError::WrongLength {
            what: "seed",
            expected: dof,
            got: seed.len(),
        });
    }
    check_finite("seed", seed)?;
    check_finite("target translation", target.translation.vector.as_slice())?;
    check_finite("target rotation", target.rotation.coords.as_slice())?;
    let mut q = [0.0; MAX_DOF];
    for (dst, &s) in q.iter_mut().zip(seed) {
        *dst = s;
    }
    let lambda2 = options.damping * options.damping;
    let mut iterations = 0;
    loop {
        let qs = q.get(..dof).unwrap_or(&[]);
        // One pass: the loaded pose, the deflection and the rigid Jacobian at `qs`.
        let deflection = vjm::deflection(model, data, qs, wrench, load)?;
        let pose = data.tcp_deflected;
        let jj = gram(&data.jacobian, dof);
        let ep = target.translation.vector - pose.translation.vector;
        let er = vjm::rotation_vector(&(target.rotation * pose.rotation.inverse()));
        let (pe, oe) = (ep.norm(), er.norm());
        if pe <= options.position_tolerance && oe <= options.orientation_tolerance {
            let s = singularity(&jj, options.min_sigma).map_err(|s| TickError::Singular {
                what: "joint Jacobian (pose IK)",
                sigma_min: s,
            })?;
            check_output("joints", &q)?;
            return Ok(PoseIkSolution {
                q,
                iterations,
                position_error: pe,
                orientation_error: oe,
                sigma_min: s,
                deflection,
            });
        }
        if iterations >= options.max_iterations {
            return Err(TickError::NotConverged {
                iterations,
                residual: pe + oe,
            });
        }
        let e = Vector6::new(ep.x, ep.y, ep.z, er.x, er.y, er.z);
        let g = jj + Matrix6::identity() * lambda2;
        let Some(chol) = g.cholesky() else {
            return Err(TickError::Singular {
                what: "joint Jacobian (pose IK)",
                sigma_min: 0.0,
            });
        };
        let y = chol.solve(&e);
        let mut dq = data.jacobian.tr_mul(&y);
        let n = dq.norm();
        if !n.is_finite() {
            return Err(TickError::NonFiniteOutput {
                what: "pose IK step",
                index: 0,
            });
        }
        if n > options.max_step {
            dq *= options.max_step / n;
        }
        for (qi, d) in q.iter_mut().zip(dq.iter()).take(dof) {
            *qi += d;
        }
        iterations += 1;
    }
}
