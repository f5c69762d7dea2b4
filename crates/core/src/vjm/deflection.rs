//! Rigid and deflected forward kinematics, deflection (Eq. 2-9) and the linearized
//! Cartesian compliance. Every function here is allocation-free, bounded by the chain length
//! and panic-free.

use nalgebra::{Isometry3, Matrix6, UnitQuaternion, Vector3};

use super::chain::{compose, rotate_axis, turn};
use super::data::check_q;
use super::loads::arm_pass;
use super::model::{Op, Pass};
use super::{Data, Load, Model, Vector6};
use crate::error::{TickError, check_finite, check_output};

/// One pass over the chain at `q` (validated by the caller): the rigid TCP pose, and in
/// `data` the world frames of the springs, which every kernel below reads, and with `JOINTS`
/// the world axes and origins of the joints (before their own motion), which the Jacobian
/// reads ([`fill_jacobian`]; the compliance and [`linear_deflection`] skip them). Compiled
/// for AVX2 too and chosen at run time (with `std`): the VEX encoding's three-operand form
/// drops the register copies of the baseline SSE2 code (UR5 linearized deflection -7 %,
/// KR 300 compliance -3 %; an AVX-512 version measured the same). The springs' loads and turns that follow run in the
/// explicit lanes of [`super::turns`] and [`super::lanes`].
#[cfg_attr(
    feature = "std",
    multiversion::multiversion(targets("x86_64+avx2+fma"))
)]
fn rigid_pass<'m, 'd, 'q, const JOINTS: bool>(
    model: &'m Model,
    data: &'d mut Data,
    q: &'q [f64],
) -> Isometry3<f64> {
    let mut frame = Isometry3::identity();
    for p in model.pass.iter() {
        match p {
            Pass::Joint(k) => {
                let Some(step) = model.tcp_chain.get(*k) else {
                    continue; // unreachable: built together
                };
                let i = step.index;
                frame = compose(&frame, &step.pre, step.pre_shape);
                if JOINTS {
                    let u = rotate_axis(&frame.rotation, step.kind, &step.axis);
                    if let (Some(a), Some(o)) =
                        (data.joint_axes.get_mut(i), data.joint_origins.get_mut(i))
                    {
                        *a = u;
                        *o = frame.translation.vector;
                    }
                }
                let qi = q.get(i).copied().unwrap_or(0.0);
                if step.revolute {
                    let (s, c) = super::trig::sin_cos(qi * 0.5);
                    frame.rotation = turn(&frame.rotation, step.kind, &step.axis, s, c);
                } else {
                    let u = rotate_axis(&frame.rotation, step.kind, &step.axis);
                    frame.translation.vector += u * qi;
                }
            }
            Pass::Spring {
                local,
                shape,
                index,
            } => {
                if let Some(slot) = data.spring_frames.get_mut(*index) {
                    *slot = compose(&frame, local, *shape);
                }
            }
        }
    }
    frame * model.tcp_tail
}

/// The rigid TCP pose alone: the joints with the fixed transforms between them folded at
/// build (springs and masses do not move the rigid chain), one composition per joint.
fn tcp_pass(model: &Model, q: &[f64]) -> Isometry3<f64> {
    let mut frame = Isometry3::identity();
    for step in model.tcp_chain.iter() {
        frame = compose(&frame, &step.pre, step.pre_shape);
        let qi = q.get(step.index).copied().unwrap_or(0.0);
        if step.revolute {
            let (s, c) = super::trig::sin_cos(qi * 0.5);
            frame.rotation = turn(&frame.rotation, step.kind, &step.axis, s, c);
        } else {
            frame.translation.vector += frame.rotation * (step.axis.into_inner() * qi);
        }
    }
    frame * model.tcp_tail
}

/// Rigid TCP pose in the base frame (Eq. 2 with i = 0). `q` \[rad or m\], length
/// [`Model::dof`]. Also stored in `data.tcp`.
pub fn forward(model: &Model, data: &mut Data, q: &[f64]) -> Result<Isometry3<f64>, TickError> {
    check_q(model, data, q)?;
    let tcp = tcp_pass(model, q);
    check_output("tcp translation", tcp.translation.vector.as_slice())?;
    data.tcp = tcp;
    Ok(tcp)
}

/// The angles (Eq. 7) of every spring from `data.spring_moments` (the arm's own loads with
/// the TCP wrench), into `data.spring_angles`; [`super::turns`] checks them.
fn angles_from_moments(model: &Model, data: &mut Data) {
    for op in model.ops.iter() {
        let Op::Spring {
            compliance, index, ..
        } = op
        else {
            continue;
        };
        let (Some(f), Some(m)) = (
            data.spring_frames.get(*index),
            data.spring_moments.get(*index),
        ) else {
            continue;
        };
        let angles = compliance.component_mul(&f.rotation.inverse_transform_vector(m));
        if let Some(slot) = data.spring_angles.get_mut(*index) {
            *slot = angles;
        }
    }
}

/// `t` moved by the small pose change `d = [dp; dr]` (translation, then the rotation vector
/// applied in the base frame): the loaded pose of the linearized model. The rotation is
/// nalgebra's `from_scaled_axis` with the inline sine and cosine of
/// [`super::trig`] (the library's `sincos` was 5 % of the UR5's linearized deflection).
fn displaced(t: &Isometry3<f64>, d: &Vector6) -> Isometry3<f64> {
    let dp = Vector3::new(d[0], d[1], d[2]);
    let dr = Vector3::new(d[3], d[4], d[5]);
    let angle = dr.norm();
    let turn = if angle > 0.0 {
        let (s, c) = super::trig::sin_cos(angle * 0.5);
        UnitQuaternion::new_unchecked(nalgebra::Quaternion::from_parts(c, dr * (s / angle)))
    } else {
        UnitQuaternion::identity()
    };
    Isometry3::from_parts((t.translation.vector + dp).into(), turn * t.rotation)
}

/// TCP deflection `[dx, dy, dz, rx, ry, rz]` \[m, rad\] in the base frame at joints `q`
/// \[rad or m\] under the TCP wrench `[Fx, Fy, Fz, Mx, My, Mz]` \[N, N m\] (base frame, moment
/// about the TCP) and, with an arm motion in `load`, the link masses' own loads: one pass
/// over the chain for every [`Load`].
///
/// The paper's exact model ([`Load::Exact`]): torques on each spring are taken in the
/// undeformed pose (Eq. 5-6, plus the applied moment), turned into angles `M / k` (Eq. 7) and
/// inserted as z-y'-x'' rotations (Eq. 3-4); the result is the deflected FK (Eq. 8) minus the
/// rigid one (Eq. 9): the translation, then the rotation vector of `R_deflected * R_rigid^T`.
/// [`Load::Linearized`] takes each spring's turn to first order (`C(q) w`, the same as
/// [`compliance`] times the wrench to rounding); [`Load::Rigid`] deflects nothing.
///
/// After the pass `data` holds, as pinocchio's `computeJointJacobians` leaves them: the rigid
/// TCP `data.tcp`, the loaded TCP `data.tcp_deflected` (for the linearized model, the rigid
/// pose moved by the returned deflection), the actuated-joint Jacobian of the rigid TCP
/// `data.jacobian`, and per spring `data.spring_moments` and `data.spring_angles` (zero for
/// [`Load::Rigid`]).
///
/// [`TickError::InvalidArgument`] when a load turns a spring past [`MAX_SPRING_ANGLE`](super::MAX_SPRING_ANGLE)
/// (outside the small-deflection model), [`TickError::NonFiniteOutput`] when loads far
/// outside the physical range overflow.
pub fn deflection(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    wrench: &Vector6,
    load: Load<'_>,
) -> Result<Vector6, TickError> {
    check_q(model, data, q)?;
    check_finite("wrench", wrench.as_slice())?;
    // The rigid TCP, and the TCP wrench whose loads the springs' pass computes (with an arm
    // motion, the moments of every load are in `data` already).
    let (tcp, tcp_wrench) = match load.arm() {
        Some(motion) => {
            let tcp = arm_pass(model, data, q, wrench, motion)?;
            angles_from_moments(model, data);
            (tcp, None)
        }
        None => (rigid_pass::<true>(model, data, q), Some(wrench)),
    };
    fill_jacobian(model, data, &tcp);
    let (d, deflected) = match load {
        Load::Rigid => {
            let n = model.springs;
            for slot in data.spring_angles.iter_mut().take(n) {
                *slot = Vector3::zeros();
            }
            for slot in data.spring_moments.iter_mut().take(n) {
                *slot = Vector3::zeros();
            }
            (Vector6::zeros(), None)
        }
        Load::Exact | Load::ExactWithArm(_) => {
            let (d, deflected) = super::turns::exact(model, data, &tcp, tcp_wrench)?;
            (d, Some(deflected))
        }
        Load::Linearized | Load::LinearizedWithArm(_) => {
            (super::turns::linear(model, data, &tcp, tcp_wrench)?, None)
        }
    };
    // A wrench of 1e308 N overflows the spring moments: refuse rather than return NaN.
    check_output("deflection", d.as_slice())?;
    data.tcp = tcp;
    data.tcp_deflected = deflected.unwrap_or_else(|| displaced(&tcp, &d));
    Ok(d)
}

/// The linearized TCP deflection `C(q) w` \[m, rad\] at joints `q` \[rad or m\] under the TCP
/// wrench `[Fx, Fy, Fz, Mx, My, Mz]` \[N, N m\] (base frame, moment about the TCP): the value
/// of [`deflection`] with [`Load::Linearized`], bit for bit, and its errors, for callers that
/// want that number alone (the Python `linear_deflection`). It leaves in `data` the rigid TCP
/// `data.tcp` and skips the by-products nobody asked for: `data.jacobian`,
/// `data.tcp_deflected` and the springs' moments and angles keep the values of the last call
/// that filled them (their assembly was a fifth of the UR5's linearized [`deflection`],
/// `cargo bench --bench vjm`).
pub fn linear_deflection(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    wrench: &Vector6,
) -> Result<Vector6, TickError> {
    check_q(model, data, q)?;
    check_finite("wrench", wrench.as_slice())?;
    let tcp = rigid_pass::<false>(model, data, q);
    let d = super::turns::linear_alone(model, data, &tcp, wrench)?;
    check_output("deflection", d.as_slice())?;
    data.tcp = tcp;
    Ok(d)
}

/// Fills `data.jacobian` from the joint axes and origins of the last pass: one column per
/// joint (the columns past the model's dof stay zero from [`Data::new`]).
pub(super) fn fill_jacobian(model: &Model, data: &mut Data, tcp: &Isometry3<f64>) {
    let p = tcp.translation.vector;
    for step in model.tcp_chain.iter() {
        let i = step.index;
        let (Some(u), Some(o)) = (data.joint_axes.get(i), data.joint_origins.get(i)) else {
            continue;
        };
        let col = if step.revolute {
            let lin = u.cross(&(p - o));
            Vector6::new(lin.x, lin.y, lin.z, u.x, u.y, u.z)
        } else {
            Vector6::new(u.x, u.y, u.z, 0.0, 0.0, 0.0)
        };
        if i < data.jacobian.ncols() {
            data.jacobian.set_column(i, &col);
        }
    }
}

/// The 6x6 Cartesian compliance of the linearized model, `C = sum_s J_s K_s^-1 J_s^T`
/// \[m/N, m/(N m), rad/N, rad/(N m)\] in the base frame, ordered as the wrench
/// `[F; M]` and the deflection `[dp; dr]`: `deflection(q, w) = C w + O(|w|^2)`.
/// `J_s` maps the three spring angles to the TCP's translation and rotation.
/// Also stored in `data.compliance`.
pub fn compliance(model: &Model, data: &mut Data, q: &[f64]) -> Result<Matrix6<f64>, TickError> {
    check_q(model, data, q)?;
    let tcp = rigid_pass::<false>(model, data, q);
    // Per spring with world axes R and compliances c, lever r from its origin to the TCP and
    // S = [r]x: the columns [u_a x r; u_a] of J_s give the blocks A = R diag(c) R^T
    // (rotation), -S A (translation-rotation) and S A S^T (translation), summed over springs
    // four at a time (`lanes`). A and S A S^T are symmetric: their six distinct entries are
    // computed once each, and S is applied as cross products.
    super::lanes::compliance_sums(model, data, &tcp.translation.vector);
    data.tcp = tcp;
    check_output("compliance", data.compliance.as_slice())?;
    Ok(data.compliance)
}

/// The actuated-joint Jacobian of the rigid TCP, rows `[v; w]` in the base frame, into
/// `data.jacobian` (columns past the model's dof are zero), and the rigid pose into
/// `data.tcp`. Every [`deflection`] pass leaves the same Jacobian in `data`.
pub fn joint_jacobian(model: &Model, data: &mut Data, q: &[f64]) -> Result<(), TickError> {
    check_q(model, data, q)?;
    let tcp = rigid_pass::<true>(model, data, q);
    fill_jacobian(model, data, &tcp);
    data.tcp = tcp;
    Ok(())
}
