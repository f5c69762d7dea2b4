//! The contour scene's arm: a planar 2R arm with compliant, backlashed joints — its
//! kinematics and deflect-core models ([`ArmParams`]) and the arm in rapier ([`ArmSim`]), whose
//! drive trains (spring with a dead zone plus a relative damper) and penalty contact are
//! applied as explicit torques and forces every physics step.

use deflect_core::drivetrain::{self, LinkMasses};
use deflect_core::{Model, ModelBuilder};
use nalgebra::{Isometry3, Matrix2, Vector2, Vector3};
use rapier3d_f64::prelude::*;
use serde::Serialize;

use super::objects::Outline;
use super::{DT, err};
use crate::SimError;
use crate::rapier_util::{gravity_z_down, insert_planar_chain, new_world, revolute_z_state};

/// The planar 2R arm with compliant, backlashed joints.
#[derive(Debug, Clone, Serialize)]
pub struct ArmParams {
    /// Link lengths \[m\] (shoulder-elbow, elbow-tool point).
    pub lengths: [f64; 2],
    /// Link masses \[kg\] (uniform rods).
    pub masses: [f64; 2],
    /// Tool and sensor mass at the tool point \[kg\].
    pub tool_mass: f64,
    /// Drive-train stiffness `K_i` \[N m/rad\].
    pub stiffness: [f64; 2],
    /// Backlash `theta_b_i` \[rad\]: the link moves freely within `+-theta_b` of the motor.
    pub backlash: [f64; 2],
    /// Relative motor-link damping \[N m s/rad\].
    pub damping: [f64; 2],
}

impl Default for ArmParams {
    fn default() -> Self {
        Self {
            lengths: [0.5, 0.4],
            masses: [2.0, 1.2],
            tool_mass: 0.3,
            stiffness: [2000.0, 1000.0],
            backlash: [2.0e-4, 3.0e-4],
            damping: [80.0, 20.0],
        }
    }
}

impl ArmParams {
    /// Tool point of link angles `q` (relative, q2 from link 1) \[m\].
    pub fn fk(&self, q: &[f64; 2]) -> Vector2<f64> {
        let (a, b) = (q[0], q[0] + q[1]);
        let [l1, l2] = self.lengths;
        Vector2::new(l1 * a.cos() + l2 * b.cos(), l1 * a.sin() + l2 * b.sin())
    }

    /// Tool-point Jacobian.
    pub fn jacobian(&self, q: &[f64; 2]) -> Matrix2<f64> {
        let (a, b) = (q[0], q[0] + q[1]);
        let [l1, l2] = self.lengths;
        Matrix2::new(
            -l1 * a.sin() - l2 * b.sin(),
            -l2 * b.sin(),
            l1 * a.cos() + l2 * b.cos(),
            l2 * b.cos(),
        )
    }

    /// Closed-form IK, elbow angle in \[0, pi\] (clamped at the workspace boundary).
    pub fn ik(&self, p: &Vector2<f64>) -> [f64; 2] {
        let [l1, l2] = self.lengths;
        let c2 = ((p.norm_squared() - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)).clamp(-1.0, 1.0);
        let q2 = c2.acos();
        let q1 = p.y.atan2(p.x) - (l2 * q2.sin()).atan2(l1 + l2 * q2.cos());
        [q1, q2]
    }

    /// The rigid model for deflect-core (two revolute-z joints).
    pub fn model(&self) -> Result<Model, SimError> {
        ModelBuilder::new()
            .revolute(Vector3::z())
            .and_then(|b| b.fixed(Isometry3::translation(self.lengths[0], 0.0, 0.0)))
            .and_then(|b| b.revolute(Vector3::z()))
            .and_then(|b| b.fixed(Isometry3::translation(self.lengths[1], 0.0, 0.0)))
            .and_then(|b| b.build())
            .map_err(err)
    }

    /// The drive train for Eq. 10: the rigid chain of [`Self::model`], stiffness, backlash, the
    /// link and tool masses under standard gravity down z (their gravity torques vanish for
    /// vertical joint axes, but they are part of the model), a 0.02 N m deadband on the
    /// backlash sign against sensor noise.
    pub fn drive_train(&self) -> Result<drivetrain::Model, SimError> {
        let [l1, l2] = self.lengths;
        let masses = LinkMasses::new()
            .with(0, self.masses[0], Vector3::new(0.5 * l1, 0.0, 0.0))
            .and_then(|m| m.with(1, self.masses[1], Vector3::new(0.5 * l2, 0.0, 0.0)))
            .and_then(|m| m.with(1, self.tool_mass, Vector3::new(l2, 0.0, 0.0)))
            .map_err(err)?;
        drivetrain::Model::new(self.model()?, &self.stiffness, &self.backlash)
            .and_then(|d| d.with_masses(masses))
            .and_then(|d| d.with_torque_deadband(0.02))
            .map_err(err)
    }
}

/// The arm in rapier: two links on revolute-z multibody joints, the drive trains as explicit
/// torques, the penalty contact as an explicit force at the tool point.
pub struct ArmSim {
    world: PhysicsWorld,
    params: ArmParams,
    q_ref: [f64; 2],
    joints: [MultibodyJointHandle; 2],
    bodies: [RigidBodyHandle; 2],
    k_contact: f64,
    c_contact: f64,
    /// Largest contact force of any physics step \[N\].
    pub peak_force: f64,
    /// Physics steps taken.
    pub physics_steps: usize,
}

impl core::fmt::Debug for ArmSim {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ArmSim")
            .field("params", &self.params)
            .field("q_ref", &self.q_ref)
            .finish_non_exhaustive()
    }
}

impl ArmSim {
    /// The arm at rest at link angles `q`, with a penalty contact of stiffness `k_contact`
    /// \[N/m\] and damping `c_contact` \[N s/m\].
    pub fn new(
        params: &ArmParams,
        q: &[f64; 2],
        k_contact: f64,
        c_contact: f64,
    ) -> Result<Self, SimError> {
        // Standard gravity down z, as in the drive-train model: the arm moves in the
        // horizontal plane, so gravity loads no joint (only the locked axes carry it).
        let mut world = new_world(gravity_z_down(), DT);
        let links = [0, 1].map(|i| {
            let (l, m) = (params.lengths[i], params.masses[i]);
            // Rod plus (on the last link) the tool mass at the tip.
            let (mt, com, i_zz) = if i == 1 {
                let mt = m + params.tool_mass;
                let com = (m * 0.5 * l + params.tool_mass * l) / mt;
                let i_zz = m * l * l / 12.0
                    + m * (0.5 * l - com).powi(2)
                    + params.tool_mass * (l - com).powi(2);
                (mt, com, i_zz)
            } else {
                (m, 0.5 * l, m * l * l / 12.0)
            };
            let props = MassProperties::new(
                Vector::new(com, 0.0, 0.0),
                mt,
                Vector::new(1e-4 * mt, i_zz, i_zz),
            );
            (l, props)
        });
        let (joints, bodies) = insert_planar_chain(
            &mut world,
            &links,
            q,
            "contour arm joint rejected",
            |_, _, _| {},
        )?;
        let (Ok(joints), Ok(bodies)) = (joints.try_into(), bodies.try_into()) else {
            return Err(SimError::new("contour arm: two joints expected"));
        };
        Ok(Self {
            world,
            params: params.clone(),
            q_ref: *q,
            joints,
            bodies,
            k_contact,
            c_contact,
            peak_force: 0.0,
            physics_steps: 0,
        })
    }

    /// Link-side joint angles and rates \[rad, rad/s\].
    pub fn link_state(&self) -> ([f64; 2], [f64; 2]) {
        let mut q = self.q_ref;
        let mut w = [0.0; 2];
        for k in 0..2 {
            if let Some((dq, rate)) = revolute_z_state(&self.world, self.joints[k]) {
                q[k] += dq;
                w[k] = rate;
            }
        }
        (q, w)
    }

    /// The tool point \[m\].
    pub fn tool(&self) -> Vector2<f64> {
        self.params.fk(&self.link_state().0)
    }

    /// One physics step with motor angles and rates; returns the contact force the tool exerts
    /// on the objects \[N\] (computed at the start of the step and applied during it).
    pub fn step(
        &mut self,
        q_motor: &[f64; 2],
        w_motor: &[f64; 2],
        objects: &[&Outline],
    ) -> Vector2<f64> {
        let (ql, wl) = self.link_state();
        let p = &self.params;
        let mut tau = [0.0; 2];
        for i in 0..2 {
            let e = q_motor[i] - ql[i];
            let b = p.backlash[i];
            let dz = if e > b {
                e - b
            } else if e < -b {
                e + b
            } else {
                0.0
            };
            tau[i] = p.stiffness[i] * dz + p.damping[i] * (w_motor[i] - wl[i]);
        }
        let tool = p.fk(&ql);
        let v = p.jacobian(&ql) * Vector2::new(wl[0], wl[1]);
        let mut f_obj = Vector2::zeros();
        for o in objects {
            if let Some((d, u)) = o.penetration(&tool) {
                let fnormal = (self.k_contact * d + self.c_contact * v.dot(&u)).max(0.0);
                f_obj += u * fnormal;
            }
        }
        self.peak_force = self.peak_force.max(f_obj.norm());
        let torques = [tau[0] - tau[1], tau[1]];
        for (k, h) in self.bodies.iter().enumerate() {
            if let Some(rb) = self.world.bodies.get_mut(*h) {
                rb.reset_forces(false);
                rb.reset_torques(false);
                rb.add_torque(Vector::new(0.0, 0.0, torques[k]), false);
                if k == 1 {
                    rb.add_force_at_point(
                        Vector::new(-f_obj.x, -f_obj.y, 0.0),
                        Vector::new(tool.x, tool.y, 0.0),
                        false,
                    );
                }
            }
        }
        self.world.step();
        self.physics_steps += 1;
        f_obj
    }
}
