//! A flexible Delta robot (Clavel) in rapier3d-f64.
//!
//! # Topology
//! One reduced-coordinate multibody rooted at the fixed base holds the exact joints:
//! * three arms, each a revolute joint at `R u_i` about the horizontal `v_i = z x u_i`
//!   (deflect-core's [`Delta`] convention: 0 horizontal outwards, positive downwards), with a
//!   drive spring `k` between the arm and its motor (the compliance under test);
//! * the platform, joined to the base by three free translations and no rotation: what the
//!   three parallelograms do kinematically (they keep the platform parallel to the base), so
//!   the parallelograms' second rods need not be simulated.
//!
//! Each forearm is one rigid rod (a free rigid body) held by two impulse ball joints, at the
//! elbow and at the platform joint `P + r u_i`: the loop closures. The rod's spin about its
//! own axis is free and carries no load. Rigidly, the platform centre follows deflect-core's
//! [`Delta`] kinematics; with the drive springs, a static force at the platform moves it by
//! `J K^-1 J^T F` (`K = diag(k)`, `J` the Delta's Jacobian), which a test checks.
//!
//! # Servo
//! Each motor is a rotor of reflected inertia `j_motor` under a discrete PD position loop
//! with velocity and acceleration feed-forward, integrated implicitly with the drive spring
//! (the five-bar scene's servo). Gravity is off: a Delta's static sag is calibrated out; the
//! scene studies the inertial loads of a pick-and-place cycle.

use deflect_core::mechanism::Delta;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::*;
use serde::Serialize;

use crate::SimError;
use crate::rapier_util::{ANG_Y, new_world, pose_na, set_spring};

/// The Delta testbed's physical parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DeltaParams {
    /// Geometry (deflect-core's Delta, pick-and-place size by default).
    #[serde(skip)]
    pub delta: Delta,
    /// Drive stiffness of each arm \[N m/rad\] (gearbox and shaft: the compliance under test).
    pub k_drive: f64,
    /// Mass of each arm with its elbow \[kg\].
    pub arm_mass: f64,
    /// Mass of each forearm rod (the parallelogram pair) \[kg\].
    pub forearm_mass: f64,
    /// Platform mass with the gripper \[kg\].
    pub platform_mass: f64,
    /// Payload mass \[kg\] (on the platform).
    pub payload_mass: f64,
    /// Position-loop bandwidth of every motor \[Hz\].
    pub bandwidth_hz: f64,
    /// Loop stiffness over the drive stiffness.
    pub kp_ratio: f64,
    /// Damping ratio of the position loop.
    pub zeta: f64,
    /// Relative damping of the drive spring.
    pub drive_zeta: f64,
    /// Physics step \[s\].
    pub dt: f64,
}

impl Default for DeltaParams {
    /// The pick-and-place Delta, 2e4 N m/rad drives, 1.2 kg arms, 0.25 kg forearms, 0.4 kg
    /// platform, 1 kg payload, 150 Hz loops, 0.5 ms.
    fn default() -> Self {
        Self {
            delta: Delta::pick_and_place(),
            k_drive: 2.0e4,
            arm_mass: 1.2,
            forearm_mass: 0.25,
            platform_mass: 0.4,
            payload_mass: 1.0,
            bandwidth_hz: 150.0,
            kp_ratio: 50.0,
            zeta: 0.7,
            drive_zeta: 0.3,
            dt: 5.0e-4,
        }
    }
}

/// One servo motor: rotor angle and speed.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Motor {
    angle: f64,
    speed: f64,
}

/// The Delta in its rapier world.
pub struct DeltaSim {
    world: PhysicsWorld,
    params: DeltaParams,
    q_ref: Vector3<f64>,
    arms: [RigidBodyHandle; 3],
    drives: [MultibodyJointHandle; 3],
    platform: RigidBodyHandle,
    motors: [Motor; 3],
    j_motor: f64,
    kp: f64,
    kd: f64,
    c_drive: f64,
    time: f64,
}

impl core::fmt::Debug for DeltaSim {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("DeltaSim")
            .field("params", &self.params)
            .field("time", &self.time)
            .finish_non_exhaustive()
    }
}

fn to_pose(iso: &Isometry3<f64>) -> Pose {
    let t = iso.translation.vector;
    let q = iso.rotation;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

/// Radial unit vector of arm `i`.
fn radial(i: usize) -> Vector3<f64> {
    let phi = 2.0 * core::f64::consts::PI * i as f64 / 3.0;
    Vector3::new(phi.cos(), phi.sin(), 0.0)
}

/// Frame of arm `i` at angle `theta`: at its base joint, x along the arm, y along its axis.
fn arm_frame(delta: &Delta, i: usize, theta: f64) -> Isometry3<f64> {
    let phi = 2.0 * core::f64::consts::PI * i as f64 / 3.0;
    Isometry3::from_parts(
        Translation3::from(radial(i) * delta.base_radius()),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), phi)
            * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), theta),
    )
}

/// A rotation taking x onto the unit vector `d`.
fn x_onto(d: &Vector3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::rotation_between(&Vector3::x(), d).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), core::f64::consts::PI)
    })
}

/// Locked axes of the arms' revolute joints (free: rotation about y).
const REVOLUTE_Y: JointAxesMask = JointAxesMask::LIN_X
    .union(JointAxesMask::LIN_Y)
    .union(JointAxesMask::LIN_Z)
    .union(JointAxesMask::ANG_X)
    .union(JointAxesMask::ANG_Z);

/// Sets the generalized damping of the arms' joints to `c` \[N m s/rad\] (the link's part of
/// the drive damping `c (w_link - w_motor)`: implicit in rapier, so any value is stable).
fn set_arm_damping(world: &mut PhysicsWorld, arms: &[RigidBodyHandle; 3], c: f64) {
    let Some(root) = arms.first() else { return };
    let Some(link) = world.multibody_joints.rigid_body_link(*root).copied() else {
        return;
    };
    let Some(mb) = world.multibody_joints.get_multibody_mut(link.multibody) else {
        return;
    };
    let mut offsets = Vec::new();
    let mut n = 0;
    for l in mb.links() {
        offsets.push((l.rigid_body_handle(), n, l.joint().ndofs()));
        n += l.joint().ndofs();
    }
    let damping = mb.damping_mut();
    for (body, start, ndofs) in offsets {
        if arms.contains(&body)
            && ndofs == 1
            && let Some(d) = damping.get_mut(start)
        {
            *d = c;
        }
    }
}

/// Inserts the three arms, each on its drive joint at its angle `q` \[rad\]; their bodies,
/// drive joints and elbows \[m\].
fn insert_arms(
    world: &mut PhysicsWorld,
    params: &DeltaParams,
    base: RigidBodyHandle,
    q: &Vector3<f64>,
) -> Result<ArmBodies, SimError> {
    let delta = params.delta;
    let l_arm = delta.arm();
    let arm_props = MassProperties::new(
        Vector::new(0.6 * l_arm, 0.0, 0.0),
        params.arm_mass,
        Vector::new(
            1e-3,
            params.arm_mass * l_arm * l_arm / 12.0,
            params.arm_mass * l_arm * l_arm / 12.0,
        ),
    );
    let mut arms = [base; 3];
    let mut drives = Vec::with_capacity(3);
    let mut elbows = [Vector3::zeros(); 3];
    for (i, theta) in q.iter().enumerate() {
        let frame = arm_frame(&delta, i, *theta);
        let arm = world.insert_body(
            RigidBodyBuilder::dynamic()
                .pose(to_pose(&frame))
                .additional_mass_properties(arm_props)
                .can_sleep(false),
        );
        let joint = GenericJointBuilder::new(REVOLUTE_Y)
            .local_frame1(to_pose(&frame))
            .local_frame2(Pose::IDENTITY)
            .contacts_enabled(false)
            .build();
        drives.push(
            world
                .insert_multibody_joint(base, arm, joint)
                .ok_or_else(|| SimError::new("Delta arm joint rejected"))?,
        );
        if let (Some(a), Some(e)) = (arms.get_mut(i), elbows.get_mut(i)) {
            *a = arm;
            *e = (frame * nalgebra::Point3::new(l_arm, 0.0, 0.0)).coords;
        }
    }
    Ok((arms, drives, elbows))
}

/// Inserts the platform (with the payload) at `start` \[m\], free to translate only.
fn insert_platform(
    world: &mut PhysicsWorld,
    params: &DeltaParams,
    base: RigidBodyHandle,
    start: &Vector3<f64>,
) -> Result<RigidBodyHandle, SimError> {
    let platform_mass = params.platform_mass + params.payload_mass;
    let platform = world.insert_body(
        RigidBodyBuilder::dynamic()
            .pose(to_pose(&Isometry3::translation(start.x, start.y, start.z)))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                platform_mass,
                Vector::new(2e-3, 2e-3, 3e-3),
            ))
            .can_sleep(false),
    );
    let slide = GenericJointBuilder::new(JointAxesMask::ANG_AXES)
        .local_frame1(to_pose(&Isometry3::translation(start.x, start.y, start.z)))
        .local_frame2(Pose::IDENTITY)
        .contacts_enabled(false)
        .build();
    world
        .insert_multibody_joint(base, platform, slide)
        .ok_or_else(|| SimError::new("Delta platform joint rejected"))?;
    Ok(platform)
}

/// Inserts the forearms: rods from the `arms`' `elbows` to the platform joints, ball-jointed
/// at both ends.
fn insert_forearms(
    world: &mut PhysicsWorld,
    params: &DeltaParams,
    start: &Vector3<f64>,
    (arms, elbows): (&[RigidBodyHandle; 3], [Vector3<f64>; 3]),
    platform: RigidBodyHandle,
) {
    let delta = params.delta;
    let l_arm = delta.arm();
    let l = delta.forearm();
    let m_f = params.forearm_mass;
    let rod = MassProperties::new(
        Vector::new(0.5 * l, 0.0, 0.0),
        m_f,
        Vector::new(1e-4, m_f * l * l / 12.0, m_f * l * l / 12.0),
    );
    for (i, (arm, elbow)) in arms.iter().zip(elbows).enumerate() {
        let joint_at = start + radial(i) * delta.platform_radius();
        let d = (joint_at - elbow) / l;
        let frame = Isometry3::from_parts(Translation3::from(elbow), x_onto(&d));
        let body = world.insert_body(
            RigidBodyBuilder::dynamic()
                .pose(to_pose(&frame))
                .additional_mass_properties(rod)
                .angular_damping(0.5)
                .can_sleep(false),
        );
        // Elbow: the arm's (L, 0, 0) to the rod's origin.
        let at_elbow = GenericJointBuilder::new(JointAxesMask::LIN_AXES)
            .local_frame1(to_pose(&Isometry3::translation(l_arm, 0.0, 0.0)))
            .local_frame2(Pose::IDENTITY)
            .contacts_enabled(false)
            .build();
        world.insert_impulse_joint(*arm, body, at_elbow);
        // Platform joint: the rod's (l, 0, 0) to r u_i on the platform.
        let local = radial(i) * delta.platform_radius();
        let at_platform = GenericJointBuilder::new(JointAxesMask::LIN_AXES)
            .local_frame1(to_pose(&Isometry3::translation(l, 0.0, 0.0)))
            .local_frame2(to_pose(&Isometry3::translation(local.x, local.y, local.z)))
            .contacts_enabled(false)
            .build();
        world.insert_impulse_joint(body, platform, at_platform);
    }
}

/// The arms' bodies, their drive joints and their elbows \[m\].
type ArmBodies = (
    [RigidBodyHandle; 3],
    Vec<MultibodyJointHandle>,
    [Vector3<f64>; 3],
);

impl DeltaSim {
    /// The Delta at rest with its platform centre at `start` \[m\].
    pub fn new(params: DeltaParams, start: &Vector3<f64>) -> Result<Self, SimError> {
        let delta = params.delta;
        let q = delta.ik(start)?;
        let mut world = new_world(Vector::ZERO, params.dt);
        world.integration_parameters.num_solver_iterations = 4;
        world.integration_parameters.num_internal_pgs_iterations = 4;
        let base = world.insert_body(RigidBodyBuilder::fixed());
        let (arms, drives, elbows) = insert_arms(&mut world, &params, base, &q)?;
        let platform = insert_platform(&mut world, &params, base, start)?;
        insert_forearms(&mut world, &params, start, (&arms, elbows), platform);
        let w = 2.0 * core::f64::consts::PI * params.bandwidth_hz;
        let kp = params.kp_ratio * params.k_drive;
        let j_motor = kp / (w * w);
        let kd = 2.0 * params.zeta * w * j_motor;
        let c_drive = 2.0 * params.drive_zeta * (params.k_drive * j_motor).sqrt();
        for h in &drives {
            set_spring(&mut world, *h, ANG_Y, params.k_drive, 0.0);
        }
        set_arm_damping(&mut world, &arms, c_drive);
        let drives: [MultibodyJointHandle; 3] = drives
            .try_into()
            .map_err(|_| SimError::new("three Delta drives expected"))?;
        let motors = [0, 1, 2].map(|i| Motor {
            angle: q.get(i).copied().unwrap_or(0.0),
            speed: 0.0,
        });
        Ok(Self {
            world,
            params,
            q_ref: q,
            arms,
            drives,
            platform,
            motors,
            j_motor,
            kp,
            kd,
            c_drive,
            time: 0.0,
        })
    }

    /// Simulated time \[s\].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The platform centre \[m\].
    pub fn platform_position(&self) -> Vector3<f64> {
        self.world
            .bodies
            .get(self.platform)
            .map(|rb| pose_na(rb.position()).translation.vector)
            .unwrap_or_else(Vector3::zeros)
    }

    /// Arm angles and rates of the link side \[rad, rad/s\].
    pub fn arm_state(&self) -> (Vector3<f64>, Vector3<f64>) {
        let (mut q, mut w) = (self.q_ref, Vector3::zeros());
        for (k, h) in self.drives.iter().enumerate() {
            let Some((mb, id)) = self.world.multibody_joints.get(*h) else {
                continue;
            };
            let Some(link) = mb.link(id) else { continue };
            if let (Some(qk), Some(wk)) = (q.get_mut(k), w.get_mut(k)) {
                *qk += link.joint().coords()[ANG_Y];
                *wk = mb.joint_velocity(link).get(0).copied().unwrap_or(0.0);
            }
        }
        (q, w)
    }

    /// Sets the drive springs' rest angles to the motors, applies the motors' part of the
    /// relative drive damping and an optional force at the platform centre.
    fn apply(&mut self, force: Option<&Vector3<f64>>, damping_scale: f64) {
        for b in self.arms.iter().chain([&self.platform]) {
            if let Some(rb) = self.world.bodies.get_mut(*b) {
                rb.reset_forces(false);
                rb.reset_torques(false);
            }
        }
        for k in 0..3 {
            let (Some(m), Some(h), Some(arm)) =
                (self.motors.get(k), self.drives.get(k), self.arms.get(k))
            else {
                continue;
            };
            let rest = m.angle - self.q_ref.get(k).copied().unwrap_or(0.0);
            set_spring(&mut self.world, *h, ANG_Y, self.params.k_drive, rest);
            // The motor's part of the drive damping, `+c w_motor` about the arm's axis (world
            // frame); the link's part is the joint's implicit damping.
            let axis = Vector3::z().cross(&radial(k));
            let t = axis * (self.c_drive * damping_scale * m.speed);
            if let Some(rb) = self.world.bodies.get_mut(*arm) {
                rb.add_torque(Vector::new(t.x, t.y, t.z), false);
            }
        }
        if let (Some(f), Some(rb)) = (force, self.world.bodies.get_mut(self.platform)) {
            rb.add_force(Vector::new(f.x, f.y, f.z), false);
        }
    }

    /// One servo tick: joint command `q` with rate and acceleration (feed-forward), then one
    /// physics step.
    pub fn step_servo(&mut self, q: &Vector3<f64>, qd: &Vector3<f64>, qdd: &Vector3<f64>) {
        let (ql, wl) = self.arm_state();
        let dt = self.params.dt;
        let k = self.params.k_drive;
        for (i, m) in self.motors.iter_mut().enumerate() {
            let at = |v: &Vector3<f64>| v.get(i).copied().unwrap_or(0.0);
            // Implicit Euler of J w' = kp (qc - qm) + kd (wc - w) + J ac - k (qm - ql) - c (w - wl).
            let a = self.j_motor / dt + self.kd + self.c_drive + dt * (self.kp + k);
            let b = self.j_motor / dt * m.speed
                + self.kp * (at(q) - m.angle)
                + self.kd * at(qd)
                + self.j_motor * at(qdd)
                - k * (m.angle - at(&ql))
                + self.c_drive * at(&wl);
            let speed = b / a;
            *m = Motor {
                angle: m.angle + dt * speed,
                speed,
            };
        }
        self.apply(None, 1.0);
        self.world.step();
        self.time += dt;
    }

    /// The platform's displacement \[m\] under a static `force` \[N\] at its centre, motors
    /// locked, damped `damping_scale` times to settle: steps until it moves less than 1e-12 m
    /// per step, at most `max_steps`.
    pub fn static_deflection(
        &mut self,
        force: &Vector3<f64>,
        damping_scale: f64,
        max_steps: usize,
    ) -> Vector3<f64> {
        let start = self.platform_position();
        let mut last = start;
        for m in &mut self.motors {
            m.speed = 0.0;
        }
        set_arm_damping(&mut self.world, &self.arms, self.c_drive * damping_scale);
        for _ in 0..max_steps {
            self.apply(Some(force), damping_scale);
            self.world.step();
            self.time += self.params.dt;
            let now = self.platform_position();
            let moved = (now - last).norm();
            last = now;
            if moved < 1e-12 {
                break;
            }
        }
        set_arm_damping(&mut self.world, &self.arms, self.c_drive);
        last - start
    }
}
