//! Deflection under the arm's own inertia: the D'Alembert wrench of every link mass
//! ([`super::Element::Mass`]) under joint motion, plus a TCP wrench, through the virtual joints.
//!
//! The paper's deflection (Hähn and Weigold 2020, Eq. 5-7) loads every spring with the one
//! TCP wrench. A moving arm also loads each spring with the inertial wrenches of the links
//! beyond it (Paksoy, Dede and Kiper 2025, Eq. 3-5, applied link by link): for a link of mass
//! `m`, centre of mass `c`, inertia `I` (world axes), with the frame's angular velocity `w`,
//! angular acceleration `alpha` and the centre's acceleration `a_c`,
//!
//! ```text
//! F = -m (a_c - g),   M_c = -(I alpha + w x I w),
//! ```
//!
//! (`g` the gravity vector if the weights are wanted, else 0), and spring `s` at `o_s` carries
//! `M_s = sum over loads beyond s of (M + (p - o_s) x F)`, the TCP wrench included. The link
//! velocities and accelerations come from one forward pass over the rigid chain given the
//! joint rates and accelerations (the springs' own motion is second order and left out, as
//! the paper leaves out the deflected pose); one backward pass accumulates the moments. The
//! angles `C M_s` then go through the paper's exact deflected chain (Eq. 3-4, 8-9) or its
//! linearization ([`super::deflection`] with [`Load::ExactWithArm`] or
//! [`Load::LinearizedWithArm`]). Allocation-free, bounded by the chain length.

use nalgebra::{Isometry3, Vector3};

use super::data::check_q;
use super::model::Op;
use super::{Data, Model, Vector6};
use crate::error::{TickError, check_finite, check_output};

/// The deflection model of a loaded chain: what a corrector or a solver is configured with
/// once; [`Load::new`] pairs it with the tick's arm motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Deflection {
    /// The paper's exact virtual-joint model (Hähn and Weigold, Eq. 2-9).
    #[default]
    Exact,
    /// The linearized model `C(q) w` (each spring's turn to first order).
    Linearized,
}

/// What one pass of [`super::deflection`] evaluates: the springs' response (none, exact or
/// linearized) and whether the link masses' inertial (and weight) loads of an arm motion join
/// the TCP wrench.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Load<'a> {
    /// The rigid chain: no deflection (the pass still leaves the rigid pose and the Jacobian).
    Rigid,
    /// The exact model (Eq. 2-9) under the TCP wrench.
    Exact,
    /// The linearized model under the TCP wrench: `C(q) w`.
    Linearized,
    /// The exact model under the TCP wrench and the link masses' loads of this joint motion.
    ExactWithArm(ArmMotion<'a>),
    /// The linearized model under the same loads: `sum_s J_s C_s R_s^T M_s`.
    LinearizedWithArm(ArmMotion<'a>),
}

impl<'a> Load<'a> {
    /// The load of `deflection`, with the link masses' loads of `arm` when given.
    pub fn new(deflection: Deflection, arm: Option<ArmMotion<'a>>) -> Self {
        match (deflection, arm) {
            (Deflection::Exact, None) => Self::Exact,
            (Deflection::Linearized, None) => Self::Linearized,
            (Deflection::Exact, Some(m)) => Self::ExactWithArm(m),
            (Deflection::Linearized, Some(m)) => Self::LinearizedWithArm(m),
        }
    }

    /// The arm motion whose link loads join the TCP wrench, if any.
    pub fn arm(&self) -> Option<&ArmMotion<'a>> {
        match self {
            Self::ExactWithArm(m) | Self::LinearizedWithArm(m) => Some(m),
            Self::Rigid | Self::Exact | Self::Linearized => None,
        }
    }
}

/// The joint motion that loads the arm with its own inertia: rates `qd` \[rad/s or m/s\] and
/// accelerations `qdd` \[rad/s^2 or m/s^2\] (one per joint), and the gravity vector `gravity`
/// \[m/s^2\] (base frame; zero to leave the weights out, as for a robot calibrated with its
/// sag).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmMotion<'a> {
    /// Joint rates.
    pub qd: &'a [f64],
    /// Joint accelerations.
    pub qdd: &'a [f64],
    /// Gravity \[m/s^2\], base frame.
    pub gravity: Vector3<f64>,
}

fn check_motion(model: &Model, motion: &ArmMotion<'_>) -> Result<(), TickError> {
    for (what, v) in [("qd", motion.qd), ("qdd", motion.qdd)] {
        if v.len() != model.dof {
            return Err(TickError::WrongLength {
                what,
                expected: model.dof,
                got: v.len(),
            });
        }
        check_finite(what, v)?;
    }
    check_finite("gravity", motion.gravity.as_slice())
}

/// The rigid chain at `q` with the velocities and accelerations of `motion`: fills the spring
/// frames, joint axes and origins, and each mass's inertial force and moment about the world
/// origin; returns the rigid TCP pose, its angular acceleration and the acceleration of its
/// origin (both without gravity: the Jacobian's bias `Jd qd` when `qdd = 0`).
fn motion_pass(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    motion: &ArmMotion<'_>,
) -> (Isometry3<f64>, Vector3<f64>, Vector3<f64>) {
    let mut frame = Isometry3::identity();
    // World angular velocity and acceleration of the current frame, acceleration of its
    // origin (gravity as an upward acceleration of the base, so that -m a includes m g).
    let (mut w, mut al) = (Vector3::zeros(), Vector3::zeros());
    let mut acc = -motion.gravity;
    let step = |frame: &mut Isometry3<f64>,
                w: &Vector3<f64>,
                al: &Vector3<f64>,
                acc: &mut Vector3<f64>,
                t: &Isometry3<f64>| {
        let r = frame.rotation * t.translation.vector;
        *acc += al.cross(&r) + w.cross(&w.cross(&r));
        *frame *= t;
    };
    for op in model.ops.iter() {
        match op {
            Op::Fixed(t) => step(&mut frame, &w, &al, &mut acc, t),
            Op::Joint {
                pre,
                axis,
                revolute,
                index,
            } => {
                step(&mut frame, &w, &al, &mut acc, pre);
                let i = *index;
                let u = frame.rotation * axis.into_inner();
                if let (Some(a), Some(o)) =
                    (data.joint_axes.get_mut(i), data.joint_origins.get_mut(i))
                {
                    *a = u;
                    *o = frame.translation.vector;
                }
                let at = |v: &[f64]| v.get(i).copied().unwrap_or(0.0);
                let (qi, qd, qdd) = (at(q), at(motion.qd), at(motion.qdd));
                if *revolute {
                    al += u * qdd + w.cross(&(u * qd));
                    w += u * qd;
                    frame.rotation *= super::trig::axis_angle(axis, qi);
                } else {
                    acc += u * qdd + w.cross(&(u * qd)) * 2.0;
                    frame.translation.vector += u * qi;
                }
            }
            Op::Spring { offset, index, .. } => {
                if let Some(slot) = data.spring_frames.get_mut(*index) {
                    *slot = match offset {
                        Some(o) => frame * o,
                        None => frame,
                    };
                }
            }
            Op::Mass {
                mass,
                com,
                inertia,
                index,
            } => {
                let r = frame.rotation * com;
                let c = frame.translation.vector + r;
                let a_c = acc + al.cross(&r) + w.cross(&w.cross(&r));
                let rot = frame.rotation.to_rotation_matrix();
                let i_w = rot.matrix() * inertia * rot.matrix().transpose();
                let f = -a_c * *mass;
                let m_c = -(i_w * al + w.cross(&(i_w * w)));
                if let Some(slot) = data.mass_loads.get_mut(*index) {
                    *slot = (f, c.cross(&f) + m_c);
                }
            }
        }
    }
    // The TCP's acceleration without the gravity offset.
    (frame, al, acc + motion.gravity)
}

/// The moment on every spring (world axes, about its origin) from the masses' loads of the
/// last pass and the TCP `wrench` at `tcp` (backward pass: forces and moments about the world
/// origin accumulated from the tip), into `data.spring_moments`.
fn accumulate_moments(model: &Model, data: &mut Data, tcp: &Isometry3<f64>, wrench: &Vector6) {
    let mut force = Vector3::new(wrench[0], wrench[1], wrench[2]);
    let mut moment =
        Vector3::new(wrench[3], wrench[4], wrench[5]) + tcp.translation.vector.cross(&force);
    for op in model.ops.iter().rev() {
        match op {
            Op::Mass { index, .. } => {
                if let Some((f, m)) = data.mass_loads.get(*index) {
                    force += f;
                    moment += m;
                }
            }
            Op::Spring { index, .. } => {
                let o = data
                    .spring_frames
                    .get(*index)
                    .map_or_else(Vector3::zeros, |f| f.translation.vector);
                if let Some(slot) = data.spring_moments.get_mut(*index) {
                    *slot = moment - o.cross(&force);
                }
            }
            Op::Fixed(_) | Op::Joint { .. } => {}
        }
    }
}

/// The loaded pass of an arm motion: the rigid chain at `q` with the motion's velocities and
/// accelerations, then every spring's moment from the link loads and the TCP `wrench` into
/// `data.spring_moments`. Returns the rigid TCP pose.
pub(super) fn arm_pass(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    wrench: &Vector6,
    motion: &ArmMotion<'_>,
) -> Result<Isometry3<f64>, TickError> {
    check_motion(model, motion)?;
    let (tcp, _, _) = motion_pass(model, data, q, motion);
    accumulate_moments(model, data, &tcp, wrench);
    // Huge rates or masses overflow the moments: a status, not NaN angles.
    for m in data.spring_moments.get(..model.springs).unwrap_or(&[]) {
        check_output("spring moments", m.as_slice())?;
    }
    Ok(tcp)
}

/// The TCP's acceleration `[a; alpha]` \[m/s^2, rad/s^2\] (base frame) at joints `q` with
/// rates `qd` and zero joint accelerations: the bias `Jd qd` of `[a; alpha] = J qdd + Jd qd`,
/// from one forward pass. What turns a desired TCP acceleration into joint accelerations.
pub fn tcp_acceleration_bias(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
) -> Result<Vector6, TickError> {
    check_q(model, data, q)?;
    let zeros = [0.0; super::MAX_DOF];
    let motion = ArmMotion {
        qd,
        qdd: zeros.get(..model.dof).unwrap_or(&[]),
        gravity: Vector3::zeros(),
    };
    check_motion(model, &motion)?;
    let (tcp, al, acc) = motion_pass(model, data, q, &motion);
    data.tcp = tcp;
    let out = Vector6::new(acc.x, acc.y, acc.z, al.x, al.y, al.z);
    check_output("TCP acceleration", out.as_slice())?;
    Ok(out)
}
