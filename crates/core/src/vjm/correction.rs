//! Compensation: the pose or the joint values to command so that the deflected TCP lands on
//! the target (section 2.2 of the VJM paper: Cartesian correction values sent to the robot
//! controller, or axis-specific ones through an inverse kinematics).

use nalgebra::{Isometry3, SVD, SVector, Translation3, UnitQuaternion, Vector3};

use super::deflection::{check_q, deflection, joint_jacobian};
use super::{Data, MAX_DOF, Model, Vector6};
use crate::error::{TickError, check_finite};

/// Largest ratio `sigma_max / sigma_min` of the joint Jacobian at which a joint correction
/// is still computed; beyond it the pose counts as singular.
const MAX_CONDITION: f64 = 1.0e8;
/// Sweeps allowed to nalgebra's SVD: bounds the time of a call. A 6 x 8 matrix converges in
/// well under 20 in practice.
const SVD_MAX_ITERATIONS: usize = 100;

/// The pose to command so that a TCP that deflects by `deflection` (from
/// [`crate::vjm::deflection`] at the target) lands on `target`: translation minus `dp`,
/// rotation turned back by `dr`. First order in the pose dependence of the deflection, exact
/// for the given deflection.
pub fn commanded_pose(target: &Isometry3<f64>, deflection: &Vector6) -> Isometry3<f64> {
    let dp = Vector3::new(deflection[0], deflection[1], deflection[2]);
    let dr = Vector3::new(deflection[3], deflection[4], deflection[5]);
    Isometry3::from_parts(
        Translation3::from(target.translation.vector - dp),
        UnitQuaternion::from_scaled_axis(-dr) * target.rotation,
    )
}

/// Result of [`joint_correction`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointCorrection {
    /// Axis-specific correction `dq` [rad or m] to add to the nominal joints; entries past
    /// [`Model::dof`] are zero.
    pub dq: [f64; MAX_DOF],
    /// Gauss-Newton steps taken.
    pub iterations: usize,
    /// Remaining pose error `|[dp; dr]|` [m, rad] of the deflected TCP at `q + dq`.
    pub residual: f64,
    /// Smallest singular value of the actuated-joint Jacobian at the last step (NaN if no
    /// step was needed).
    pub sigma_min: f64,
    /// `residual <= tolerance`. An under-actuated robot (fewer than 6 joints) generally
    /// cannot cancel the whole pose error: it gets the least-squares fixed point instead.
    pub converged: bool,
}

/// Least-squares, minimum-norm `dq` with `J dq = delta` for the Jacobian in `data`
/// (filled by [`joint_jacobian`]); also returns the smallest relevant singular value.
fn solve_jacobian(
    data: &Data,
    dof: usize,
    delta: &Vector6,
) -> Result<(SVector<f64, MAX_DOF>, f64), TickError> {
    let svd = SVD::try_new(data.jacobian, true, true, f64::EPSILON, SVD_MAX_ITERATIONS).ok_or(
        TickError::NotConverged {
            iterations: SVD_MAX_ITERATIONS,
            residual: f64::NAN,
        },
    )?;
    // The `min(dof, 6)` largest singular values span the reachable directions.
    let mut sv = [0.0f64; 6];
    for (dst, &s) in sv.iter_mut().zip(svd.singular_values.iter()) {
        *dst = s;
    }
    sv.sort_unstable_by(|a, b| b.total_cmp(a));
    let rank = dof.min(6);
    let sigma_max = sv.first().copied().unwrap_or(0.0);
    let sigma_min = sv.get(rank.saturating_sub(1)).copied().unwrap_or(0.0);
    if !(sigma_min > 0.0 && sigma_max / sigma_min < MAX_CONDITION) {
        return Err(TickError::Singular { sigma_min });
    }
    let step = svd
        .solve(delta, sigma_max / MAX_CONDITION)
        .map_err(|_| TickError::Singular { sigma_min })?;
    Ok((step, sigma_min))
}

/// Axis-specific values for a Cartesian correction: the least-squares, minimum-norm `dq`
/// [rad or m] with `J(q) dq = delta`, `delta = [dp; dr]` [m, rad] in the base frame (the
/// paper's conversion of Cartesian correction values into axis values, section 2.2).
/// Entries past [`Model::dof`] are zero. [`TickError::Singular`] near singular poses.
pub fn joint_delta(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    delta: &Vector6,
) -> Result<[f64; MAX_DOF], TickError> {
    check_finite("delta", delta.as_slice())?;
    joint_jacobian(model, data, q)?;
    let (step, _) = solve_jacobian(data, model.dof, delta)?;
    let mut out = [0.0; MAX_DOF];
    for (dst, &v) in out.iter_mut().zip(step.iter()).take(model.dof) {
        *dst = v;
    }
    Ok(out)
}

/// Axis-specific correction: the `dq` such that the robot commanded to `q + dq` and loaded by
/// `wrench` puts its deflected TCP on the rigid TCP of `q`.
///
/// Each step solves `J dq = -e` in the least-squares, minimum-norm sense through an SVD of
/// the actuated-joint Jacobian (robots with fewer or more than 6 axes work too); with
/// `max_iterations = 1` this is the paper's first-order `dq = -J^+ Delta`. The wrench is held
/// constant in the base frame while the pose changes. Steps stop once the residual is at most
/// `tolerance` or after `max_iterations`; [`JointCorrection::converged`] says which. Returns
/// [`TickError::Singular`] near a singular pose.
pub fn joint_correction(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    wrench: &Vector6,
    max_iterations: usize,
    tolerance: f64,
) -> Result<JointCorrection, TickError> {
    check_q(model, q)?;
    check_finite("wrench", wrench.as_slice())?;
    let dof = model.dof;
    let mut qk = [0.0; MAX_DOF];
    for (dst, &src) in qk.iter_mut().zip(q) {
        *dst = src;
    }
    // The target is the rigid TCP at the nominal joints.
    super::forward(model, data, q)?;
    let target = data.tcp;
    let mut out = JointCorrection {
        dq: [0.0; MAX_DOF],
        iterations: 0,
        residual: f64::INFINITY,
        sigma_min: f64::NAN,
        converged: false,
    };
    for it in 0..=max_iterations {
        let qcur = qk;
        let qs = qcur.get(..dof).unwrap_or(&[]);
        deflection(model, data, qs, wrench)?;
        let d = data.tcp_deflected;
        let ep = d.translation.vector - target.translation.vector;
        let er = (d.rotation * target.rotation.inverse()).scaled_axis();
        let e = Vector6::new(ep.x, ep.y, ep.z, er.x, er.y, er.z);
        out.residual = e.norm();
        out.iterations = it;
        if out.residual <= tolerance || it == max_iterations {
            break;
        }
        joint_jacobian(model, data, qs)?;
        let (step, sigma_min) = solve_jacobian(data, dof, &(-e))?;
        out.sigma_min = sigma_min;
        for (qi, si) in qk.iter_mut().zip(step.iter()).take(dof) {
            *qi += si;
        }
    }
    for ((dst, &qi), &q0) in out.dq.iter_mut().zip(qk.iter()).zip(q) {
        *dst = qi - q0;
    }
    out.converged = out.residual <= tolerance;
    Ok(out)
}
