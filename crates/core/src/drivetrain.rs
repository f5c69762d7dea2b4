//! Drive-train errors of a position-controlled robot and their compensation, after
//! "Shape recovery from robot contour tracking with force feedback", section 2
//! (`shared/papers/000_5ce4550bc71d85da.txt`, Eq. 1-13).
//!
//! The joint encoders sit on the motors, so the link angles differ from the readings by the
//! gear backlash taken up in the direction of the joint torque (Eq. 8) and by the joint
//! compliance `u / K` (Eq. 9). With the gravity torques (Eq. 3-7, accumulated from the tip)
//! and the contact torques `J^T F` of the sensed wrench, the link angles are recovered by
//! Eq. 10:
//!
//! ```text
//! u_i     = g_i(q) + (J^T F)_i                       drive torque [N m or N]
//! theta_i := theta_i - sgn(u_i) theta_b_i - u_i / K_i
//! ```
//!
//! **Sign conventions.** `u` is the torque the drive delivers to hold the arm: the gravity
//! part is the usual gravity vector of the dynamics, `g(q) = dV/dq` with the potential
//! `V = -sum m_k g . p_k` (the paper's Eq. 4-7 with Paul's upward "gravity" `-g`). `F` is the
//! wrench the **tool exerts on the environment** (the contact force of Eq. 11 and 20: it
//! points into the object), `[Fx, Fy, Fz, Mx, My, Mz]` [N, N m] in the base frame, moment
//! about the TCP. That is the negative of the load wrench that [`crate::vjm::deflection`]
//! takes. Under this `u` the joint gives way by `-u / K`, hence Eq. 10.
//!
//! `sgn(0) = 0`: with no torque (or a torque inside [`DriveTrain::torque_deadband`]) no
//! backlash is taken up and none is removed. `theta_b` is the lost motion taken up in the
//! direction of the torque, measured from the encoder's zero for a torque-free joint.
//!
//! Per-call functions take `(&Model, &mut Data, &DriveTrain, inputs)`, allocate nothing,
//! never panic and return a [`TickError`] for wrong-sized or non-finite input.

use core::fmt;

use nalgebra::{Isometry3, Matrix2, Matrix3, Matrix6, SMatrix, SVD, Translation3, UnitQuaternion};
use nalgebra::{Vector3, Vector6};

use crate::error::{TickError, check_finite};
use crate::vjm::{self, Data, Element, MAX_DOF, Model};

/// Most point masses a [`LinkMasses`] table holds: one per link of an 8-axis cell plus its
/// tool, sensor and payload parts.
pub const MAX_MASSES: usize = 16;

/// Default largest `sigma_max / sigma_min` of the square Jacobian in the Cartesian stiffness.
pub const DEFAULT_MAX_CONDITION: f64 = 1.0e6;

/// Standard gravity, pointing down the base z axis [m/s^2].
pub const STANDARD_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// A drive-train description could not be assembled.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum DriveTrainError {
    /// More masses than [`MAX_MASSES`].
    CapacityExceeded {
        /// The capacity.
        capacity: usize,
    },
    /// A mass is negative, NaN or infinite.
    InvalidMass {
        /// Position in the table.
        index: usize,
        /// The value [kg].
        value: f64,
    },
    /// A centre of mass holds NaN or an infinity.
    NonFiniteCom {
        /// Position in the table.
        index: usize,
    },
    /// A mass hangs after a joint the model does not have.
    JointOutOfRange {
        /// Position in the table.
        index: usize,
        /// The joint index given.
        joint: usize,
        /// The model's number of joints.
        dof: usize,
    },
    /// The stiffness or backlash vector does not have one entry per joint.
    WrongLength {
        /// "stiffness" or "backlash".
        what: &'static str,
        /// The model's number of joints.
        expected: usize,
        /// Length given.
        got: usize,
    },
    /// A joint stiffness is not finite and positive.
    NonPositiveStiffness {
        /// The joint.
        joint: usize,
        /// The value [N m/rad or N/m].
        value: f64,
    },
    /// A backlash is negative or not finite.
    InvalidBacklash {
        /// The joint.
        joint: usize,
        /// The value [rad or m].
        value: f64,
    },
    /// The gravity vector, deadband or condition limit is not finite (or not positive where
    /// it must be).
    InvalidParameter {
        /// Which parameter.
        what: &'static str,
    },
}

impl fmt::Display for DriveTrainError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::CapacityExceeded { capacity } => {
                write!(
                    f,
                    "too many point masses: the table holds at most {capacity}"
                )
            }
            Self::InvalidMass { index, value } => {
                write!(f, "mass #{index} is {value} kg; it must be finite and >= 0")
            }
            Self::NonFiniteCom { index } => write!(f, "mass #{index}: centre of mass not finite"),
            Self::JointOutOfRange { index, joint, dof } => write!(
                f,
                "mass #{index} hangs after joint {joint}, but the model has {dof} joints"
            ),
            Self::WrongLength {
                what,
                expected,
                got,
            } => write!(
                f,
                "{what}: expected {expected} entries (one per joint), got {got}"
            ),
            Self::NonPositiveStiffness { joint, value } => write!(
                f,
                "joint {joint}: stiffness {value} must be finite and > 0 (N m/rad)"
            ),
            Self::InvalidBacklash { joint, value } => write!(
                f,
                "joint {joint}: backlash {value} must be finite and >= 0 (rad)"
            ),
            Self::InvalidParameter { what } => write!(f, "{what} is not valid"),
        }
    }
}

impl core::error::Error for DriveTrainError {}

/// One point mass of a link: `mass` [kg] at `com` [m], expressed in the frame right after
/// the motion of actuated joint `after_joint` (the URDF frame of that joint's child link).
/// It loads that joint and every joint before it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointMass {
    /// Index (in `q` order) of the last actuated joint before the mass.
    pub after_joint: usize,
    /// Mass [kg].
    pub mass: f64,
    /// Centre of mass [m] in the frame after `after_joint`'s motion.
    pub com: Vector3<f64>,
}

/// A fixed-capacity table of link masses ([`MAX_MASSES`] entries), built without a heap.
/// Masses before the first actuated joint load no joint and need no entry.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinkMasses {
    masses: heapless::Vec<PointMass, MAX_MASSES>,
}

impl LinkMasses {
    /// An empty table (a massless arm).
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `mass` [kg] at `com` [m] in the frame after joint `after_joint`.
    pub fn push(
        &mut self,
        after_joint: usize,
        mass: f64,
        com: Vector3<f64>,
    ) -> Result<(), DriveTrainError> {
        let index = self.masses.len();
        if !(mass.is_finite() && mass >= 0.0) {
            return Err(DriveTrainError::InvalidMass { index, value: mass });
        }
        if !com.iter().all(|v| v.is_finite()) {
            return Err(DriveTrainError::NonFiniteCom { index });
        }
        self.masses
            .push(PointMass {
                after_joint,
                mass,
                com,
            })
            .map_err(|_| DriveTrainError::CapacityExceeded {
                capacity: MAX_MASSES,
            })
    }

    /// Builder form of [`LinkMasses::push`].
    pub fn with(
        mut self,
        after_joint: usize,
        mass: f64,
        com: Vector3<f64>,
    ) -> Result<Self, DriveTrainError> {
        self.push(after_joint, mass, com)?;
        Ok(self)
    }

    /// The masses, in insertion order.
    pub fn as_slice(&self) -> &[PointMass] {
        &self.masses
    }

    /// Total mass [kg].
    pub fn total(&self) -> f64 {
        self.masses.iter().map(|m| m.mass).sum()
    }
}

/// Per-joint drive-train parameters of a model: stiffness `K_i` [N m/rad, N/m for a
/// prismatic joint], backlash `theta_b_i` [rad or m], link masses and gravity.
#[derive(Debug, Clone, PartialEq)]
pub struct DriveTrain {
    dof: usize,
    stiffness: [f64; MAX_DOF],
    backlash: [f64; MAX_DOF],
    masses: LinkMasses,
    gravity: Vector3<f64>,
    torque_deadband: f64,
    max_condition: f64,
}

fn copy_checked(
    what: &'static str,
    src: &[f64],
    dof: usize,
    ok: impl Fn(f64) -> bool,
    err: impl Fn(usize, f64) -> DriveTrainError,
) -> Result<[f64; MAX_DOF], DriveTrainError> {
    if src.len() != dof {
        return Err(DriveTrainError::WrongLength {
            what,
            expected: dof,
            got: src.len(),
        });
    }
    let mut out = [0.0; MAX_DOF];
    for (i, (d, &s)) in out.iter_mut().zip(src.iter()).enumerate() {
        if !ok(s) {
            return Err(err(i, s));
        }
        *d = s;
    }
    Ok(out)
}

impl DriveTrain {
    /// Joint stiffnesses `K_i` (finite, > 0) and backlashes `theta_b_i` (finite, >= 0), one
    /// per actuated joint of `model`, in `q` order. No masses, gravity (0, 0, -9.81) m/s^2,
    /// no torque deadband, [`DEFAULT_MAX_CONDITION`].
    pub fn new(
        model: &Model,
        stiffness: &[f64],
        backlash: &[f64],
    ) -> Result<Self, DriveTrainError> {
        let dof = model.dof();
        let stiffness = copy_checked(
            "stiffness",
            stiffness,
            dof,
            |k| k.is_finite() && k > 0.0,
            |joint, value| DriveTrainError::NonPositiveStiffness { joint, value },
        )?;
        let backlash = copy_checked(
            "backlash",
            backlash,
            dof,
            |b| b.is_finite() && b >= 0.0,
            |joint, value| DriveTrainError::InvalidBacklash { joint, value },
        )?;
        Ok(Self {
            dof,
            stiffness,
            backlash,
            masses: LinkMasses::new(),
            gravity: Vector3::from(STANDARD_GRAVITY),
            torque_deadband: 0.0,
            max_condition: DEFAULT_MAX_CONDITION,
        })
    }

    /// Sets the link masses; every `after_joint` must be a joint of the model.
    pub fn with_masses(mut self, masses: LinkMasses) -> Result<Self, DriveTrainError> {
        for (index, m) in masses.as_slice().iter().enumerate() {
            if m.after_joint >= self.dof {
                return Err(DriveTrainError::JointOutOfRange {
                    index,
                    joint: m.after_joint,
                    dof: self.dof,
                });
            }
        }
        self.masses = masses;
        Ok(self)
    }

    /// Sets the gravity acceleration [m/s^2] in the base frame (default (0, 0, -9.81)).
    pub fn with_gravity(mut self, gravity: Vector3<f64>) -> Result<Self, DriveTrainError> {
        if !gravity.iter().all(|v| v.is_finite()) {
            return Err(DriveTrainError::InvalidParameter { what: "gravity" });
        }
        self.gravity = gravity;
        Ok(self)
    }

    /// Torques with `|u| <= deadband` [N m] count as zero for the backlash sign (sensor noise
    /// must not flip a backlash back and forth). Default 0: only an exact zero.
    pub fn with_torque_deadband(mut self, deadband: f64) -> Result<Self, DriveTrainError> {
        if !(deadband.is_finite() && deadband >= 0.0) {
            return Err(DriveTrainError::InvalidParameter {
                what: "torque deadband",
            });
        }
        self.torque_deadband = deadband;
        Ok(self)
    }

    /// Largest `sigma_max / sigma_min` of the square Jacobian accepted by the Cartesian
    /// stiffness functions (default [`DEFAULT_MAX_CONDITION`]).
    pub fn with_max_condition(mut self, max_condition: f64) -> Result<Self, DriveTrainError> {
        if !(max_condition.is_finite() && max_condition > 1.0) {
            return Err(DriveTrainError::InvalidParameter {
                what: "max condition",
            });
        }
        self.max_condition = max_condition;
        Ok(self)
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.dof
    }
    /// Joint stiffnesses `K_i` in `q` order.
    pub fn stiffness(&self) -> &[f64] {
        self.stiffness.get(..self.dof).unwrap_or(&[])
    }
    /// Joint backlashes `theta_b_i` in `q` order.
    pub fn backlash(&self) -> &[f64] {
        self.backlash.get(..self.dof).unwrap_or(&[])
    }
    /// The link masses.
    pub fn masses(&self) -> &LinkMasses {
        &self.masses
    }
    /// Gravity acceleration in the base frame [m/s^2].
    pub fn gravity(&self) -> Vector3<f64> {
        self.gravity
    }
    /// Backlash-sign deadband [N m].
    pub fn torque_deadband(&self) -> f64 {
        self.torque_deadband
    }

    /// `sgn(u)` of Eq. 8 and 10 with the deadband: -1, 0 or 1.
    pub fn backlash_sign(&self, u: f64) -> f64 {
        if u > self.torque_deadband {
            1.0
        } else if u < -self.torque_deadband {
            -1.0
        } else {
            0.0
        }
    }
}

fn check_model(model: &Model, drive: &DriveTrain) -> Result<(), TickError> {
    if drive.dof != model.dof() {
        return Err(TickError::WrongLength {
            what: "drive train joints",
            expected: model.dof(),
            got: drive.dof,
        });
    }
    Ok(())
}

fn check_q(model: &Model, q: &[f64]) -> Result<(), TickError> {
    if q.len() != model.dof() {
        return Err(TickError::WrongLength {
            what: "q",
            expected: model.dof(),
            got: q.len(),
        });
    }
    check_finite("q", q)
}

/// Gravity torques `g(q)` [N m, N for prismatic joints] the drives deliver to hold the arm
/// still (Eq. 3-7): for each joint the mass `M_j` and first moment `S_j = sum m_k p_k`
/// beyond it are accumulated from the tip (Eq. 7), then `g_j = -z_j . ((S_j - M_j o_j) x g)`
/// for a revolute joint at `o_j` about `z_j` and `g_j = -M_j z_j . g` for a prismatic one.
/// Entries past [`Model::dof`] are zero.
pub fn gravity_torques(
    model: &Model,
    drive: &DriveTrain,
    q: &[f64],
) -> Result<[f64; MAX_DOF], TickError> {
    check_model(model, drive)?;
    check_q(model, q)?;
    // Forward pass: joint axes and origins, and the frame after each joint's motion.
    let mut axis = [Vector3::zeros(); MAX_DOF];
    let mut origin = [Vector3::zeros(); MAX_DOF];
    let mut revolute = [true; MAX_DOF];
    let mut after = [Isometry3::identity(); MAX_DOF];
    let mut frame = Isometry3::<f64>::identity();
    for e in model.elements() {
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
            Element::Spring { .. } => {}
        }
    }
    // Mass and first moment attached right after each joint.
    let mut m_at = [0.0; MAX_DOF];
    let mut s_at = [Vector3::zeros(); MAX_DOF];
    for pm in drive.masses.as_slice() {
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
    let g = drive.gravity;
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
    Ok(out)
}

/// Contact torques `J^T F` [N m or N] of the wrench `F` the tool exerts on the environment
/// (base frame, moment about the TCP). Fills `data.jacobian` and `data.tcp`.
pub fn contact_torques(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    wrench: &Vector6<f64>,
) -> Result<[f64; MAX_DOF], TickError> {
    check_finite("wrench", wrench.as_slice())?;
    vjm::joint_jacobian(model, data, q)?;
    let mut out = [0.0; MAX_DOF];
    for (j, o) in out.iter_mut().enumerate().take(model.dof()) {
        *o = data.jacobian.column(j).dot(wrench);
    }
    Ok(out)
}

/// Result of [`correct_joints`].
#[derive(Debug, Clone, Copy, PartialEq)]
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
/// evaluated at the readings. Fills `data.jacobian` and `data.tcp`.
pub fn correct_joints(
    model: &Model,
    data: &mut Data,
    drive: &DriveTrain,
    q: &[f64],
    wrench: &Vector6<f64>,
) -> Result<JointErrors, TickError> {
    let gravity = gravity_torques(model, drive, q)?;
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
        .zip(drive.stiffness.iter().zip(drive.backlash.iter()));
    for ((((qc, u), s), (&theta, (&ug, &uc))), (&k, &b)) in rows {
        *u = ug + uc;
        *s = drive.backlash_sign(*u);
        *qc = theta - *s * b - *u / k;
    }
    Ok(out)
}

/// The compensated TCP pose: rigid forward kinematics at the corrected joints of
/// [`correct_joints`] (the paper's shape recovery with Eq. 10). Fills `data.tcp` with it.
pub fn compensated_forward(
    model: &Model,
    data: &mut Data,
    drive: &DriveTrain,
    q: &[f64],
    wrench: &Vector6<f64>,
) -> Result<Isometry3<f64>, TickError> {
    let c = correct_joints(model, data, drive, q, wrench)?;
    vjm::forward(model, data, c.q.get(..model.dof()).unwrap_or(&[]))
}

macro_rules! square_stiffness {
    ($n:literal, $mat:ty, $rows:expr, $model:expr, $data:expr, $drive:expr, $q:expr) => {{
        check_model($model, $drive)?;
        if $model.dof() != $n {
            return Err(TickError::WrongLength {
                what: "joints (square Jacobian)",
                expected: $n,
                got: $model.dof(),
            });
        }
        vjm::joint_jacobian($model, $data, $q)?;
        let rows: [usize; $n] = $rows;
        let j = <$mat>::from_fn(|r, c| {
            rows.get(r)
                .and_then(|&src| $data.jacobian.get((src, c)))
                .copied()
                .unwrap_or(0.0)
        });
        let svd =
            SVD::try_new(j, true, true, f64::EPSILON, 100).ok_or(TickError::NotConverged {
                iterations: 100,
                residual: f64::NAN,
            })?;
        let s = &svd.singular_values;
        let (smin, smax) = s
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
        if !(smin > 0.0 && smax / smin <= $drive.max_condition) {
            return Err(TickError::Singular { sigma_min: smin });
        }
        let j_inv = svd
            .pseudo_inverse(0.0)
            .map_err(|_| TickError::Singular { sigma_min: smin })?;
        let k_theta = <$mat>::from_fn(|r, c| {
            if r == c {
                $drive.stiffness.get(r).copied().unwrap_or(0.0)
            } else {
                0.0
            }
        });
        let k = j_inv.transpose() * k_theta * j_inv;
        // Symmetrize away the rounding.
        Ok((k + k.transpose()) * 0.5)
    }};
}

/// Cartesian stiffness `K = J^-T K_theta J^-1` (Eq. 12-13) of a 6-joint arm, 6x6, ordered
/// `[dp; dr] -> [F; M]` like the Jacobian rows `[v; w]` (base frame). Joint compliance only:
/// the links are rigid. [`TickError::Singular`] when the Jacobian's condition number exceeds
/// the drive train's limit; [`TickError::WrongLength`] unless the model has 6 joints.
pub fn cartesian_stiffness(
    model: &Model,
    data: &mut Data,
    drive: &DriveTrain,
    q: &[f64],
) -> Result<Matrix6<f64>, TickError> {
    square_stiffness!(6, Matrix6<f64>, [0, 1, 2, 3, 4, 5], model, data, drive, q)
}

/// Planar xy stiffness of a 2-joint arm moving in the xy plane (Eq. 11-13 for the contour
/// case): the x and y rows of the Jacobian, 2x2 [N/m]. Errors as [`cartesian_stiffness`].
pub fn cartesian_stiffness_xy(
    model: &Model,
    data: &mut Data,
    drive: &DriveTrain,
    q: &[f64],
) -> Result<Matrix2<f64>, TickError> {
    square_stiffness!(2, Matrix2<f64>, [0, 1], model, data, drive, q)
}

/// Planar stiffness of a 3-joint arm moving in the xy plane: rows x, y and the rotation
/// about z, 3x3, `[dx, dy, rz] -> [Fx, Fy, Mz]`. Errors as [`cartesian_stiffness`].
pub fn cartesian_stiffness_planar(
    model: &Model,
    data: &mut Data,
    drive: &DriveTrain,
    q: &[f64],
) -> Result<Matrix3<f64>, TickError> {
    square_stiffness!(3, Matrix3<f64>, [0, 1, 5], model, data, drive, q)
}

/// The xy block of a planar 3x3 stiffness with the moment about z left free (`Mz = 0`): the
/// Schur complement `K_xx - K_xr K_rr^-1 K_rx`, for a probe that transmits no moment.
/// `None` if `K_rr` is not positive.
pub fn free_moment_xy(k: &Matrix3<f64>) -> Option<Matrix2<f64>> {
    let at = |r: usize, c: usize| k.get((r, c)).copied().unwrap_or(f64::NAN);
    let krr = at(2, 2);
    if !(krr > 0.0 && krr.is_finite()) {
        return None;
    }
    let kxr = SMatrix::<f64, 2, 1>::new(at(0, 2), at(1, 2));
    let kxx = Matrix2::new(at(0, 0), at(0, 1), at(1, 0), at(1, 1));
    Some(kxx - kxr * kxr.transpose() / krr)
}
