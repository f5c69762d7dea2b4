//! Joint torques of the drive train (Eq. 3-8 of the contour-tracking paper) and the link
//! angles they recover (Eq. 10).

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3, Vector6};

use super::{Data, Model, check_q};
use crate::error::{TickError, check_finite, check_output};
use crate::vjm::{self, Element, MAX_DOF};

/// Gravity torques `g(q)` \[N m, N for prismatic joints\] the drives deliver to hold the arm
/// still (Eq. 3-7): for each joint the mass `M_j` and first moment `S_j = sum m_k p_k`
/// beyond it are accumulated from the tip (Eq. 7), then `g_j = -z_j . ((S_j - M_j o_j) x g)`
/// for a revolute joint at `o_j` about `z_j` and `g_j = -M_j z_j . g` for a prismatic one.
/// Entries past [`Model::dof`] are zero.
pub fn gravity_torques(
    model: &Model,
    data: &mut Data,
    q: &[f64],
) -> Result<[f64; MAX_DOF], TickError> {
    check_q(model, data, q)?;
    // Forward pass: joint axes and origins, and the frame after each joint's motion.
    let mut axis = [Vector3::zeros(); MAX_DOF];
    let mut origin = [Vector3::zeros(); MAX_DOF];
    let mut revolute = [true; MAX_DOF];
    let mut after = [Isometry3::identity(); MAX_DOF];
    let mut frame = Isometry3::<f64>::identity();
    for e in model.chain().elements() {
        match *e {
            Element::Fixed(t) => frame *= t,
            Element::Revolute { axis: a, index } | Element::Prismatic { axis: a, index } => {
                let is_rev = matches!(e, Element::Revolute { .. });
                let qi = q.get(index).copied().unwrap_or(0.0);
                if let Some(s) = axis.get_mut(index) {
                    *s = frame.rotation * a.into_inner();
                }
                if let Some(s) = origin.get_mut(index) {
                    *s = frame.translation.vector;
                }
                if let Some(s) = revolute.get_mut(index) {
                    *s = is_rev;
                }
                frame *= if is_rev {
                    Isometry3::from_parts(
                        Translation3::identity(),
                        UnitQuaternion::from_axis_angle(&a, qi),
                    )
                } else {
                    Isometry3::from_parts(
                        Translation3::from(a.into_inner() * qi),
                        UnitQuaternion::identity(),
                    )
                };
                if let Some(s) = after.get_mut(index) {
                    *s = frame;
                }
            }
            Element::Spring { .. } | Element::Mass { .. } => {}
        }
    }
    // Mass and first moment attached right after each joint.
    let mut m_at = [0.0; MAX_DOF];
    let mut s_at = [Vector3::zeros(); MAX_DOF];
    for pm in model.masses.as_slice() {
        let p = after
            .get(pm.after_joint)
            .map(|t| t.transform_point(&pm.com.into()).coords)
            .unwrap_or_else(Vector3::zeros);
        if let (Some(m), Some(s)) = (m_at.get_mut(pm.after_joint), s_at.get_mut(pm.after_joint)) {
            *m += pm.mass;
            *s += p * pm.mass;
        }
    }
    // Backward pass from the tip (Eq. 7): accumulate, then project on each axis.
    let g = model.gravity;
    let mut out = [0.0; MAX_DOF];
    let mut mass = 0.0;
    let mut moment = Vector3::zeros();
    for j in (0..model.dof().min(MAX_DOF)).rev() {
        mass += m_at.get(j).copied().unwrap_or(0.0);
        moment += s_at.get(j).copied().unwrap_or_else(Vector3::zeros);
        let z = axis.get(j).copied().unwrap_or_else(Vector3::zeros);
        let o = origin.get(j).copied().unwrap_or_else(Vector3::zeros);
        let u = if revolute.get(j).copied().unwrap_or(true) {
            -z.dot(&(moment - o * mass).cross(&g))
        } else {
            -mass * z.dot(&g)
        };
        if let Some(s) = out.get_mut(j) {
            *s = u;
        }
    }
    check_output("gravity torques", &out)?;
    data.gravity = out;
    Ok(out)
}

/// Contact torques `J^T F` \[N m or N\] of the wrench `F` the tool exerts on the environment
/// (base frame, moment about the TCP). Fills `data.contact`, `data.vjm.jacobian` and
/// `data.vjm.tcp`.
pub fn contact_torques(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    wrench: &Vector6<f64>,
) -> Result<[f64; MAX_DOF], TickError> {
    check_finite("wrench", wrench.as_slice())?;
    vjm::joint_jacobian(model.chain(), &mut data.vjm, q)?;
    let mut out = [0.0; MAX_DOF];
    for (j, o) in out.iter_mut().enumerate().take(model.dof()) {
        *o = data.vjm.jacobian.column(j).dot(wrench);
    }
    check_output("contact torques", &out)?;
    data.contact = out;
    Ok(out)
}

/// Result of [`step`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[must_use]
pub struct JointErrors {
    /// Corrected joint values `theta - sgn(u) theta_b - u / K` (Eq. 10); entries past the
    /// model's dof are zero.
    pub q: [f64; MAX_DOF],
    /// Total drive torque `u = g(q) + J^T F` (Eq. 8 and 10).
    pub torque: [f64; MAX_DOF],
    /// Gravity part `g(q)`.
    pub gravity: [f64; MAX_DOF],
    /// Backlash sign `sgn(u)` of each joint: -1, 0 or 1.
    pub backlash_sign: [f64; MAX_DOF],
}

/// Eq. 10: the link angles from the motor-side readings `q` and the wrench the tool exerts
/// on the environment (see the module docs for the signs). Gravity and contact torques are
/// evaluated at the readings. Fills `data`.
pub fn step(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    wrench: &Vector6<f64>,
) -> Result<JointErrors, TickError> {
    let gravity = gravity_torques(model, data, q)?;
    let contact = contact_torques(model, data, q, wrench)?;
    let mut out = JointErrors {
        q: [0.0; MAX_DOF],
        torque: [0.0; MAX_DOF],
        gravity,
        backlash_sign: [0.0; MAX_DOF],
    };
    let rows = out
        .q
        .iter_mut()
        .zip(out.torque.iter_mut())
        .zip(out.backlash_sign.iter_mut())
        .zip(q.iter().zip(gravity.iter().zip(contact.iter())))
        .zip(model.stiffness.iter().zip(model.backlash.iter()));
    for ((((qc, u), s), (&theta, (&ug, &uc))), (&k, &b)) in rows {
        *u = ug + uc;
        *s = model.backlash_sign(*u);
        *qc = theta - *s * b - *u / k;
    }
    check_output("corrected joints", &out.q)?;
    Ok(out)
}

/// The compensated TCP pose: rigid forward kinematics at the corrected joints of
/// [`step`] (the paper's shape recovery with Eq. 10). Fills `data.vjm.tcp` with it.
pub fn compensated_forward(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    wrench: &Vector6<f64>,
) -> Result<Isometry3<f64>, TickError> {
    let c = step(model, data, q, wrench)?;
    vjm::forward(
        model.chain(),
        &mut data.vjm,
        c.q.get(..model.dof()).unwrap_or(&[]),
    )
}
