//! Rigid and deflected forward kinematics, deflection (Eq. 2-9) and the linearized
//! Cartesian compliance. Every function here is allocation-free, bounded by the chain length
//! and panic-free.

use nalgebra::{Isometry3, Matrix6, Translation3, UnitQuaternion, Vector3};

use super::{Data, Element, MAX_DOF, Model, Vector6};
use crate::error::{TickError, check_finite};

/// Validates a joint vector against the model.
pub(crate) fn check_q(model: &Model, q: &[f64]) -> Result<(), TickError> {
    if q.len() != model.dof {
        return Err(TickError::WrongLength {
            what: "q",
            expected: model.dof,
            got: q.len(),
        });
    }
    check_finite("q", q)
}

/// `(sin x, cos x)`. Elastic angles are tiny (1e-6..1e-3 rad): below 0.01 rad the Taylor
/// series to x^9 / x^10 is exact to rounding (the next terms are below 1e-22 relative) and
/// several times cheaper than the library call.
#[inline]
fn sin_cos_small(x: f64) -> (f64, f64) {
    if x.abs() < 1.0e-2 {
        let x2 = x * x;
        let s = x * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0))));
        let c = 1.0
            - x2 / 2.0
                * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0 * (1.0 - x2 / 90.0))));
        (s, c)
    } else {
        (
            nalgebra::ComplexField::sin(x),
            nalgebra::ComplexField::cos(x),
        )
    }
}

/// `Rz(gamma) Ry(beta) Rx(alpha)` as a unit quaternion (the same as nalgebra's
/// `from_euler_angles(alpha, beta, gamma)`), from half-angle sines and cosines.
#[inline]
fn euler_zyx(alpha: f64, beta: f64, gamma: f64) -> UnitQuaternion<f64> {
    let (sr, cr) = sin_cos_small(alpha * 0.5);
    let (sp, cp) = sin_cos_small(beta * 0.5);
    let (sy, cy) = sin_cos_small(gamma * 0.5);
    UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ))
}

/// The motions of the actuated joints at `q`, computed once per call (each costs a sin/cos).
fn joint_motions(model: &Model, q: &[f64]) -> [Isometry3<f64>; MAX_DOF] {
    let mut out = [Isometry3::identity(); MAX_DOF];
    for e in model.elements.iter() {
        let (m, index) = match *e {
            Element::Revolute { axis, index } => (
                Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_axis_angle(&axis, q.get(index).copied().unwrap_or(0.0)),
                ),
                index,
            ),
            Element::Prismatic { axis, index } => (
                Isometry3::from_parts(
                    Translation3::from(axis.into_inner() * q.get(index).copied().unwrap_or(0.0)),
                    UnitQuaternion::identity(),
                ),
                index,
            ),
            _ => continue,
        };
        if let Some(slot) = out.get_mut(index) {
            *slot = m;
        }
    }
    out
}

/// The transform an element applies (`None` for a spring), given the joint motions.
#[inline]
fn motion(e: &Element, motions: &[Isometry3<f64>; MAX_DOF]) -> Option<Isometry3<f64>> {
    match *e {
        Element::Fixed(t) => Some(t),
        Element::Revolute { index, .. } | Element::Prismatic { index, .. } => Some(
            motions
                .get(index)
                .copied()
                .unwrap_or_else(Isometry3::identity),
        ),
        Element::Spring { .. } => None,
    }
}

/// Rigid forward kinematics without checks (callers have validated `q`).
fn rigid_tcp(model: &Model, motions: &[Isometry3<f64>; MAX_DOF]) -> Isometry3<f64> {
    model
        .elements
        .iter()
        .filter_map(|e| motion(e, motions))
        .fold(Isometry3::identity(), |t, m| t * m)
}

/// Rigid TCP pose in the base frame (Eq. 2 with i = 0). `q` [rad or m], length
/// [`Model::dof`]. Also stored in `data.tcp`.
pub fn forward(model: &Model, data: &mut Data, q: &[f64]) -> Result<Isometry3<f64>, TickError> {
    check_q(model, q)?;
    data.tcp = rigid_tcp(model, &joint_motions(model, q));
    Ok(data.tcp)
}

/// TCP deflection `[dx, dy, dz, rx, ry, rz]` [m, rad] in the base frame under the TCP wrench
/// `[Fx, Fy, Fz, Mx, My, Mz]` [N, N m] (base frame, moment about the TCP): the paper's exact
/// model. Torques on each spring are taken in the undeformed pose (Eq. 5-6, plus the applied
/// moment), turned into angles `M / k` (Eq. 7) and inserted as z-y'-x'' rotations (Eq. 3-4);
/// the result is the deflected FK (Eq. 8) minus the rigid one (Eq. 9): the translation, then
/// the rotation vector of `R_deflected * R_rigid^T`.
///
/// Fills `data.tcp`, `data.tcp_deflected` and `data.spring_angles`.
pub fn deflection(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    wrench: &Vector6,
) -> Result<Vector6, TickError> {
    check_q(model, q)?;
    check_finite("wrench", wrench.as_slice())?;
    let motions = joint_motions(model, q);
    let tcp = rigid_tcp(model, &motions);
    let force = Vector3::new(wrench[0], wrench[1], wrench[2]);
    let moment = Vector3::new(wrench[3], wrench[4], wrench[5]);

    let mut rigid = Isometry3::identity();
    let mut deflected = Isometry3::identity();
    for e in model.elements.iter() {
        match (motion(e, &motions), e) {
            (Some(m), _) => {
                rigid *= m;
                deflected *= m;
            }
            (None, Element::Spring { compliance, index }) => {
                // Eq. 5-6: load moved to the spring origin, expressed in the spring frame.
                let r = tcp.translation.vector - rigid.translation.vector;
                let m_local = rigid.rotation.inverse() * (moment + r.cross(&force));
                // Eq. 7: alpha = M_C / k_C, beta = M_B / k_B, gamma = M_A / k_A.
                let angles = compliance.component_mul(&m_local);
                if let Some(slot) = data.spring_angles.get_mut(*index) {
                    *slot = angles;
                }
                // Eq. 4: R* = Rz(gamma) Ry(beta) Rx(alpha), nalgebra's roll-pitch-yaw.
                let r_star = euler_zyx(angles.x, angles.y, angles.z);
                deflected *= r_star;
            }
            (None, _) => {}
        }
    }
    data.tcp = tcp;
    data.tcp_deflected = deflected;
    let dp = deflected.translation.vector - tcp.translation.vector;
    let dr = (deflected.rotation * tcp.rotation.inverse()).scaled_axis();
    Ok(Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z))
}

/// The 6x6 Cartesian compliance of the linearized model, `C = sum_s J_s K_s^-1 J_s^T`
/// [m/N, m/(N m), rad/N, rad/(N m)] in the base frame, ordered as the wrench
/// `[F; M]` and the deflection `[dp; dr]`: `deflection(q, w) = C w + O(|w|^2)`.
/// `J_s` maps the three spring angles to the TCP's translation and rotation.
/// Also stored in `data.compliance`.
pub fn compliance(model: &Model, data: &mut Data, q: &[f64]) -> Result<Matrix6<f64>, TickError> {
    check_q(model, q)?;
    let motions = joint_motions(model, q);
    let tcp = rigid_tcp(model, &motions);
    let mut c = Matrix6::zeros();
    let mut frame = Isometry3::identity();
    for e in model.elements.iter() {
        match (motion(e, &motions), e) {
            (Some(m), _) => frame *= m,
            (None, Element::Spring { compliance, .. }) => {
                let r = tcp.translation.vector - frame.translation.vector;
                let rot = frame.rotation.to_rotation_matrix();
                for (a, &ca) in compliance.iter().enumerate() {
                    if ca == 0.0 {
                        continue;
                    }
                    let u: Vector3<f64> = rot.matrix().column(a).into_owned();
                    let lin = u.cross(&r);
                    let col = Vector6::new(lin.x, lin.y, lin.z, u.x, u.y, u.z);
                    c += (col * col.transpose()) * ca;
                }
            }
            (None, _) => {}
        }
    }
    data.tcp = tcp;
    data.compliance = c;
    Ok(c)
}

/// Fills `data.jacobian` with the actuated-joint Jacobian of the rigid TCP, rows
/// `[v; w]` in the base frame, and `data.tcp` with the rigid pose. Columns past the model's
/// dof are zero.
pub fn joint_jacobian(model: &Model, data: &mut Data, q: &[f64]) -> Result<(), TickError> {
    check_q(model, q)?;
    let motions = joint_motions(model, q);
    let tcp = rigid_tcp(model, &motions);
    data.jacobian.fill(0.0);
    let mut frame = Isometry3::identity();
    for e in model.elements.iter() {
        // The joint's axis is expressed in the frame *before* its own motion (the same axis
        // after it, since a joint moves along/about its own axis).
        let column = match *e {
            Element::Revolute { axis, index } => {
                let u = frame.rotation * axis.into_inner();
                let lin = u.cross(&(tcp.translation.vector - frame.translation.vector));
                Some((index, Vector6::new(lin.x, lin.y, lin.z, u.x, u.y, u.z)))
            }
            Element::Prismatic { axis, index } => {
                let u = frame.rotation * axis.into_inner();
                Some((index, Vector6::new(u.x, u.y, u.z, 0.0, 0.0, 0.0)))
            }
            _ => None,
        };
        if let Some((index, col)) = column {
            if index < data.jacobian.ncols() {
                data.jacobian.set_column(index, &col);
            }
        }
        if let Some(m) = motion(e, &motions) {
            frame *= m;
        }
    }
    data.tcp = tcp;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_zyx_equals_nalgebra_small_and_large() {
        for &(a, b, g) in &[
            (1e-4, -2e-5, 3e-4),
            (0.009, -0.0099, 0.005),
            (0.3, -1.2, 2.5),
            (0.0, 0.0, 0.0),
            (0.02, 0.019, -0.021),
        ] {
            let ours = euler_zyx(a, b, g);
            let theirs = UnitQuaternion::from_euler_angles(a, b, g);
            assert!(ours.angle_to(&theirs) < 1e-15, "{a} {b} {g}");
            assert!((ours.quaternion().norm() - 1.0).abs() < 1e-15);
        }
        for i in -100..=100 {
            let x = i as f64 * 1.0e-4; // up to 0.01
            let (s, c) = sin_cos_small(x);
            assert!(
                (s - x.sin()).abs() <= 1e-18 + 2.0 * f64::EPSILON * x.abs(),
                "{x}"
            );
            assert!((c - x.cos()).abs() <= 2.0 * f64::EPSILON, "{x}");
        }
    }
}
