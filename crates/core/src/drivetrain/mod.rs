//! Drive-train errors of a position-controlled robot and their compensation, after
//! "Shape recovery from robot contour tracking with force feedback", section 2
//! (Eq. 1-13).
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
//! points into the object), `[Fx, Fy, Fz, Mx, My, Mz]` \[N, N m\] in the base frame, moment
//! about the TCP. That is the negative of the load wrench that [`crate::vjm::deflection`]
//! takes. Under this `u` the joint gives way by `-u / K`, hence Eq. 10.
//!
//! `sgn(0) = 0`: with no torque (or a torque inside [`Model::torque_deadband`]) no
//! backlash is taken up and none is removed. `theta_b` is the lost motion taken up in the
//! direction of the torque, measured from the encoder's zero for a torque-free joint.
//!
//! The [`Model`] holds the chain with its joint stiffnesses, backlashes, link masses and
//! gravity, validated once; [`Data`] owns every buffer (the chain's [`vjm::Data`] included);
//! the tick [`step`] (Eq. 10) and the quantities it is built from take `(&Model, &mut Data,
//! inputs)`, allocate nothing, never panic and return a [`TickError`] for wrong-sized or
//! non-finite input.

mod stiffness;
mod torques;

pub use stiffness::{
    cartesian_stiffness, cartesian_stiffness_planar, cartesian_stiffness_xy, free_moment_xy,
};
pub use torques::{JointErrors, compensated_forward, contact_torques, gravity_torques, step};

use nalgebra::Vector3;

use crate::error::{BuildError, TickError, param};
use crate::units::GRAVITY_Z_DOWN;
use crate::vjm::{self, MAX_DOF, MAX_MASSES};

/// Default largest `sigma_max / sigma_min` of the square Jacobian in the Cartesian stiffness.
pub const DEFAULT_MAX_CONDITION: f64 = 1.0e6;

/// One point mass of a link: `mass` \[kg\] at `com` \[m\], expressed in the frame right after
/// the motion of actuated joint `after_joint` (the URDF frame of that joint's child link).
/// It loads that joint and every joint before it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointMass {
    /// Index (in `q` order) of the last actuated joint before the mass.
    pub after_joint: usize,
    /// Mass \[kg\].
    pub mass: f64,
    /// Centre of mass \[m\] in the frame after `after_joint`'s motion.
    pub com: Vector3<f64>,
}

/// A fixed-capacity table of link masses ([`vjm::MAX_MASSES`] entries, the same bound as the
/// chain's own masses), built without a heap.
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

    /// Adds `mass` \[kg\] at `com` \[m\] in the frame after joint `after_joint`.
    pub fn push(
        &mut self,
        after_joint: usize,
        mass: f64,
        com: Vector3<f64>,
    ) -> Result<(), BuildError> {
        let index = self.masses.len();
        if !(mass.is_finite() && mass >= 0.0) {
            return Err(BuildError::InvalidEntry {
                what: "masses",
                index,
                value: mass,
                expected: "finite and >= 0 (kg)",
            });
        }
        if let Some(k) = com.iter().position(|v| !v.is_finite()) {
            return Err(BuildError::NonFinite {
                what: "centre of mass",
                index: 3 * index + k,
            });
        }
        self.masses
            .push(PointMass {
                after_joint,
                mass,
                com,
            })
            .map_err(|_| BuildError::Capacity {
                what: "masses",
                capacity: MAX_MASSES,
                got: MAX_MASSES + 1,
            })
    }

    /// Builder form of [`LinkMasses::push`].
    pub fn with(
        mut self,
        after_joint: usize,
        mass: f64,
        com: Vector3<f64>,
    ) -> Result<Self, BuildError> {
        self.push(after_joint, mass, com)?;
        Ok(self)
    }

    /// The masses, in insertion order.
    pub fn as_slice(&self) -> &[PointMass] {
        &self.masses
    }

    /// Total mass \[kg\].
    pub fn total(&self) -> f64 {
        self.masses.iter().map(|m| m.mass).sum()
    }
}

/// The drive-train model of a serial chain: the chain itself, per-joint stiffness `K_i`
/// \[N m/rad, N/m for a prismatic joint\] and backlash `theta_b_i` \[rad or m\], link masses and
/// gravity. Immutable once built; every setter validates and returns a new model.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    chain: vjm::Model,
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
    expected: &'static str,
) -> Result<[f64; MAX_DOF], BuildError> {
    if src.len() != dof {
        return Err(BuildError::WrongLength {
            what,
            expected: dof,
            got: src.len(),
        });
    }
    let mut out = [0.0; MAX_DOF];
    for (index, (d, &s)) in out.iter_mut().zip(src.iter()).enumerate() {
        if !ok(s) {
            return Err(BuildError::InvalidEntry {
                what,
                index,
                value: s,
                expected,
            });
        }
        *d = s;
    }
    Ok(out)
}

impl Model {
    /// The drive train of `chain`: joint stiffnesses `K_i` (finite, > 0) and backlashes
    /// `theta_b_i` (finite, >= 0), one per actuated joint, in `q` order. No masses, standard
    /// gravity down the base z axis ([`crate::units::GRAVITY_Z_DOWN`]), no torque deadband,
    /// [`DEFAULT_MAX_CONDITION`].
    pub fn new(chain: vjm::Model, stiffness: &[f64], backlash: &[f64]) -> Result<Self, BuildError> {
        let dof = chain.dof();
        let stiffness = copy_checked(
            "stiffness",
            stiffness,
            dof,
            |k| k.is_normal() && k > 0.0,
            "a normal number > 0 (N m/rad)",
        )?;
        let backlash = copy_checked(
            "backlash",
            backlash,
            dof,
            |b| b.is_finite() && b >= 0.0,
            "finite and >= 0 (rad)",
        )?;
        Ok(Self {
            chain,
            stiffness,
            backlash,
            masses: LinkMasses::new(),
            gravity: Vector3::from(GRAVITY_Z_DOWN),
            torque_deadband: 0.0,
            max_condition: DEFAULT_MAX_CONDITION,
        })
    }

    /// Sets the link masses; every `after_joint` must be a joint of the chain.
    pub fn with_masses(mut self, masses: LinkMasses) -> Result<Self, BuildError> {
        for (index, m) in masses.as_slice().iter().enumerate() {
            if m.after_joint >= self.chain.dof() {
                return Err(BuildError::InvalidEntry {
                    what: "masses (after_joint)",
                    index,
                    value: m.after_joint as f64,
                    expected: "a joint index of the chain",
                });
            }
        }
        self.masses = masses;
        Ok(self)
    }

    /// Sets the gravity acceleration \[m/s^2\] in the base frame (default
    /// [`crate::units::GRAVITY_Z_DOWN`]).
    pub fn with_gravity(mut self, gravity: Vector3<f64>) -> Result<Self, BuildError> {
        if let Some(index) = gravity.iter().position(|v| !v.is_finite()) {
            return Err(BuildError::NonFinite {
                what: "gravity",
                index,
            });
        }
        self.gravity = gravity;
        Ok(self)
    }

    /// Torques with `|u| <= deadband` \[N m\] count as zero for the backlash sign (sensor noise
    /// must not flip a backlash back and forth). Default 0: only an exact zero.
    pub fn with_torque_deadband(mut self, deadband: f64) -> Result<Self, BuildError> {
        self.torque_deadband = param("torque deadband", deadband, deadband >= 0.0, ">= 0 (N m)")?;
        Ok(self)
    }

    /// Largest `sigma_max / sigma_min` of the square Jacobian accepted by the Cartesian
    /// stiffness functions (default [`DEFAULT_MAX_CONDITION`]).
    pub fn with_max_condition(mut self, max_condition: f64) -> Result<Self, BuildError> {
        self.max_condition = param("max condition", max_condition, max_condition > 1.0, "> 1")?;
        Ok(self)
    }

    /// The kinematic chain.
    pub fn chain(&self) -> &vjm::Model {
        &self.chain
    }
    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.chain.dof()
    }
    /// Joint stiffnesses `K_i` in `q` order.
    pub fn stiffness(&self) -> &[f64] {
        self.stiffness.get(..self.dof()).unwrap_or(&[])
    }
    /// Joint backlashes `theta_b_i` in `q` order.
    pub fn backlash(&self) -> &[f64] {
        self.backlash.get(..self.dof()).unwrap_or(&[])
    }
    /// The link masses.
    pub fn masses(&self) -> &LinkMasses {
        &self.masses
    }
    /// Gravity acceleration in the base frame \[m/s^2\].
    pub fn gravity(&self) -> Vector3<f64> {
        self.gravity
    }
    /// Backlash-sign deadband \[N m\].
    pub fn torque_deadband(&self) -> f64 {
        self.torque_deadband
    }
    /// Largest accepted condition number of the square Jacobian.
    pub fn max_condition(&self) -> f64 {
        self.max_condition
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

/// Workspace and by-products of the drive-train functions: the chain's [`vjm::Data`] and the
/// last torques. Allocation-free to create.
#[derive(Debug, Clone)]
pub struct Data {
    /// Workspace of the chain (its Jacobian and TCP after the last call).
    pub vjm: vjm::Data,
    /// Gravity torques `g(q)` of the last call \[N m or N\]; entries past the dof are zero.
    pub gravity: [f64; MAX_DOF],
    /// Contact torques `J^T F` of the last call \[N m or N\].
    pub contact: [f64; MAX_DOF],
}

impl Data {
    /// A workspace for `model`.
    pub fn new(model: &Model) -> Self {
        Self {
            vjm: vjm::Data::new(&model.chain),
            gravity: [0.0; MAX_DOF],
            contact: [0.0; MAX_DOF],
        }
    }

    /// Whether this workspace was made for a model of `model`'s dimensions.
    pub fn check(&self, model: &Model) -> bool {
        self.vjm.check(&model.chain)
    }
}

/// Validates the workspace and the joint vector.
fn check_q(model: &Model, data: &Data, q: &[f64]) -> Result<(), TickError> {
    data.vjm.check_model(&model.chain)?;
    if q.len() != model.dof() {
        return Err(TickError::WrongLength {
            what: "q",
            expected: model.dof(),
            got: q.len(),
        });
    }
    crate::vjm::check_joint_range(q)
}
