//! The flexible 4-axis arm of the milling scenario: its geometry ([`ArmParams`]), its
//! virtual-joint model ([`vjm_model`]) and the arm in rapier ([`FlexArm`]).
//!
//! A yaw joint (z) at the base and three pitch joints (y: shoulder, elbow, wrist), each a
//! reduced-coordinate multibody revolute joint with a drive spring whose rest angle is the
//! motor angle (rapier's implicit joint springs), and structural damping. The virtual-joint
//! model has one spring about each joint axis, so rapier's static compliance is the VJM one.
//! Gravity is off in rapier (the arm's own sag is treated as calibrated out); the tool weight
//! only enters the simulated force/torque sensor at the flange ([`super::sensor`]).

use deflect_core::vjm::{Model, ModelBuilder};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::*;
use serde::Serialize;

use crate::SimError;
use crate::rapier_util::{ANG_Y, ANG_Z, body_pose, new_world, set_last_dof_damping, set_spring};

/// Number of joints of the arm.
pub const JOINTS: usize = 4;

/// The arm: geometry, masses, stiffnesses and damping.
#[derive(Debug, Clone, Serialize)]
pub struct ArmParams {
    /// Shoulder height above the base \[m\].
    pub shoulder_height: f64,
    /// Upper arm (shoulder to elbow) \[m\].
    pub upper_arm: f64,
    /// Forearm (elbow to wrist) \[m\].
    pub forearm: f64,
    /// Wrist joint to the flange (sensor) \[m\].
    pub wrist_to_flange: f64,
    /// Flange (sensor) to the tool point \[m\].
    pub tool_length: f64,
    /// Masses of turret, upper arm, forearm, wrist + spindle \[kg\].
    pub masses: [f64; JOINTS],
    /// Joint stiffnesses (drive springs) \[N m/rad\].
    pub stiffness: [f64; JOINTS],
    /// Joint damping \[N m s/rad\].
    pub damping: [f64; JOINTS],
}

impl Default for ArmParams {
    fn default() -> Self {
        Self {
            shoulder_height: 0.6,
            upper_arm: 0.9,
            forearm: 0.8,
            wrist_to_flange: 0.15,
            tool_length: 0.2,
            masses: [40.0, 25.0, 15.0, 20.0],
            stiffness: [1.1e6, 7.2e5, 4.5e5, 2.2e5],
            damping: [3500.0, 3000.0, 1300.0, 250.0],
        }
    }
}

impl ArmParams {
    fn wrist_to_tcp(&self) -> f64 {
        self.wrist_to_flange + self.tool_length
    }

    /// Pose of the TCP in the sensor (flange) frame: a translation along the last link.
    pub fn sensor_to_tcp(&self) -> Isometry3<f64> {
        Isometry3::translation(self.tool_length, 0.0, 0.0)
    }

    /// Joint angles that put the tool point at `p` \[m\] with the tool pointing down (the last
    /// link along -z), elbow up. Outside the workspace the elbow is stretched.
    pub fn ik(&self, p: &Vector3<f64>) -> [f64; JOINTS] {
        let q1 = p.y.atan2(p.x);
        let r = (p.x * p.x + p.y * p.y).sqrt();
        let s = self.shoulder_height - (p.z + self.wrist_to_tcp());
        let (l2, l3) = (self.upper_arm, self.forearm);
        let d = ((r * r + s * s - l2 * l2 - l3 * l3) / (2.0 * l2 * l3)).clamp(-1.0, 1.0);
        let q3 = d.acos();
        let q2 = s.atan2(r) - (l3 * q3.sin()).atan2(l2 + l3 * q3.cos());
        let q4 = core::f64::consts::FRAC_PI_2 - q2 - q3;
        [q1, q2, q3, q4]
    }
}

/// The arm's virtual-joint model with joint stiffnesses `k` \[N m/rad\]: one spring about each
/// joint axis right after the joint (the other two axes rigid); TCP = tool point with the
/// orientation of the last link (x along the link).
pub fn vjm_model(p: &ArmParams, k: &[f64; JOINTS]) -> Result<Model, SimError> {
    let inf = f64::INFINITY;
    let e = |e: deflect_core::BuildError| SimError::new(format!("arm model: {e}"));
    ModelBuilder::new()
        .fixed(Isometry3::translation(0.0, 0.0, p.shoulder_height))
        .and_then(|b| b.revolute(Vector3::z()))
        .and_then(|b| b.spring([inf, inf, k[0]]))
        .and_then(|b| b.revolute(Vector3::y()))
        .and_then(|b| b.spring([inf, k[1], inf]))
        .and_then(|b| b.fixed(Isometry3::translation(p.upper_arm, 0.0, 0.0)))
        .and_then(|b| b.revolute(Vector3::y()))
        .and_then(|b| b.spring([inf, k[2], inf]))
        .and_then(|b| b.fixed(Isometry3::translation(p.forearm, 0.0, 0.0)))
        .and_then(|b| b.revolute(Vector3::y()))
        .and_then(|b| b.spring([inf, k[3], inf]))
        .and_then(|b| b.fixed(Isometry3::translation(p.wrist_to_tcp(), 0.0, 0.0)))
        .and_then(|b| b.build())
        .map_err(e)
}

/// Joint axis of joint `i` in its own frame.
fn axis(i: usize) -> Vector3<f64> {
    if i == 0 { Vector3::z() } else { Vector3::y() }
}

/// The arm in rapier: four bodies on revolute multibody joints with drive springs.
pub struct FlexArm {
    world: PhysicsWorld,
    params: ArmParams,
    q_ref: [f64; JOINTS],
    joints: Vec<MultibodyJointHandle>,
    bodies: Vec<RigidBodyHandle>,
}

impl core::fmt::Debug for FlexArm {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("FlexArm")
            .field("params", &self.params)
            .field("q_ref", &self.q_ref)
            .finish_non_exhaustive()
    }
}

impl FlexArm {
    /// The arm at rest at joint angles `q`, with the damping scaled by `damping_scale` (> 1 to
    /// settle static tests quickly).
    pub fn new(
        params: &ArmParams,
        q: &[f64; JOINTS],
        damping_scale: f64,
        dt: f64,
    ) -> Result<Self, SimError> {
        let mut world = new_world(Vector::ZERO, dt);
        let ground = world.insert_body(RigidBodyBuilder::fixed());
        let p = params;
        let lengths = [0.0, p.upper_arm, p.forearm, p.wrist_to_tcp()];
        let offsets = [
            Vector::new(0.0, 0.0, p.shoulder_height),
            Vector::ZERO,
            Vector::new(p.upper_arm, 0.0, 0.0),
            Vector::new(p.forearm, 0.0, 0.0),
        ];
        let mut parent = ground;
        let mut pose = Pose::IDENTITY;
        let (mut joints, mut bodies) = (Vec::new(), Vec::new());
        for (i, &qi) in q.iter().enumerate() {
            let rot = if i == 0 {
                Rotation::from_rotation_z(qi)
            } else {
                Rotation::from_rotation_y(qi)
            };
            let frame1 = Pose::from_parts(offsets[i], rot);
            pose *= frame1;
            let (l, m) = (lengths[i], p.masses[i]);
            let (com, inertia) = if i == 0 {
                (
                    Vector::ZERO,
                    Vector::new(0.5 * m * 0.04, 0.5 * m * 0.04, 0.5 * m * 0.04),
                )
            } else if i == 3 {
                // wrist and spindle: centre of mass 0.2 m along the link
                (
                    Vector::new(0.2, 0.0, 0.0),
                    Vector::new(0.05 * m, 0.02 * m, 0.02 * m),
                )
            } else {
                let i_t = m * l * l / 12.0;
                (
                    Vector::new(0.5 * l, 0.0, 0.0),
                    Vector::new(0.01 * m, i_t, i_t),
                )
            };
            let body = world.insert_body(
                RigidBodyBuilder::dynamic()
                    .pose(pose)
                    .additional_mass_properties(MassProperties::new(com, m, inertia))
                    .can_sleep(false),
            );
            let free_axis = if i == 0 {
                JointAxesMask::ANG_X | JointAxesMask::ANG_Y
            } else {
                JointAxesMask::ANG_X | JointAxesMask::ANG_Z
            };
            let joint = GenericJointBuilder::new(JointAxesMask::LIN_AXES | free_axis)
                .local_frame1(frame1)
                .contacts_enabled(false)
                .build();
            let h = world
                .insert_multibody_joint(parent, body, joint)
                .ok_or_else(|| SimError::new("arm joint rejected"))?;
            set_spring(&mut world, h, spring_axis(i), p.stiffness[i], 0.0);
            set_last_dof_damping(&mut world, h, p.damping[i] * damping_scale);
            joints.push(h);
            bodies.push(body);
            parent = body;
        }
        Ok(Self {
            world,
            params: params.clone(),
            q_ref: *q,
            joints,
            bodies,
        })
    }

    fn body_pose(&self, i: usize) -> Isometry3<f64> {
        self.bodies
            .get(i)
            .and_then(|h| body_pose(&self.world, *h))
            .unwrap_or_else(Isometry3::identity)
    }

    /// Pose of the sensor (flange) frame, base frame.
    pub fn sensor_pose(&self) -> Isometry3<f64> {
        self.body_pose(JOINTS - 1) * Isometry3::translation(self.params.wrist_to_flange, 0.0, 0.0)
    }

    /// The tool point \[m\], base frame.
    pub fn tcp(&self) -> Vector3<f64> {
        (self.sensor_pose() * Isometry3::translation(self.params.tool_length, 0.0, 0.0))
            .translation
            .vector
    }

    /// Rotation across each drive spring (link minus motor side) as a rotation vector in the
    /// spring frame (the joint's child frame) \[rad\], for motor angles `q_motor`.
    pub fn spring_rotations(&self, q_motor: &[f64; JOINTS]) -> [Vector3<f64>; JOINTS] {
        let mut out = [Vector3::zeros(); JOINTS];
        for (i, o) in out.iter_mut().enumerate() {
            let parent = if i == 0 {
                Isometry3::identity()
            } else {
                self.body_pose(i - 1)
            };
            let rel = parent.rotation.inverse() * self.body_pose(i).rotation;
            let rigid = UnitQuaternion::from_axis_angle(
                &nalgebra::Unit::new_normalize(axis(i)),
                q_motor[i],
            );
            *o = (rigid.inverse() * rel).scaled_axis();
        }
        out
    }

    /// One physics step with motor angles `q_motor` (spring rest angles) and an external force
    /// `force` \[N\] at the tool point (base frame).
    pub fn step(&mut self, q_motor: &[f64; JOINTS], force: &Vector3<f64>) {
        for (i, h) in self.joints.iter().enumerate() {
            let rest = q_motor[i] - self.q_ref[i];
            set_spring(
                &mut self.world,
                *h,
                spring_axis(i),
                self.params.stiffness[i],
                rest,
            );
        }
        let tcp = self.tcp();
        if let Some(rb) = self
            .bodies
            .last()
            .and_then(|h| self.world.bodies.get_mut(*h))
        {
            rb.reset_forces(false);
            rb.reset_torques(false);
            rb.add_force_at_point(
                Vector::new(force.x, force.y, force.z),
                Vector::new(tcp.x, tcp.y, tcp.z),
                false,
            );
        }
        self.world.step();
    }
}

/// The spring coordinate of joint `i`: the rotation about z (yaw) or y (pitch joints).
fn spring_axis(i: usize) -> usize {
    if i == 0 { ANG_Z } else { ANG_Y }
}
