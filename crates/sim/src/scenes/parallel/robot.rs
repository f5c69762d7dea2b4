//! The paper's 2-DoF planar parallel robot as a rapier3d-f64 multibody with compliant joints.
//!
//! # Topology (our model; the paper does not publish one)
//! Reduced-coordinate multibody rooted at the fixed base, three branches:
//! * arm A: base -> actuated link A1 (revolute z at A0 = (0, +h)) -> distal link A2 (revolute z
//!   at the elbow A, passive);
//! * arm B: the same from B0 = (0, -h);
//! * the moving platform: base -> platform with free x, y translation and three rotations
//!   (z locked). The rotation about z carries a stiff spring `k_orient` (what the
//!   parallelograms do: keep the platform's orientation); the rotations about x and y carry the
//!   out-of-plane bending springs `k_tilt` (pivot at the static-test force point G).
//!
//! The loop is closed by two impulse joints that pin the tips of A2 and B2 in the plane to the
//! platform joints D = G + (0, +h) and E = G + (0, -h) (x, y locked, z and rotations free, so
//! the platform can tilt). Rigidly, C - O = D - A0 = E - B0: the rigid kinematics are exactly
//! [`ParallelRobot2`]'s.
//!
//! # Compliance
//! Each actuated link hangs on its motor through a drive spring `k_a` / `k_b` (gearbox, shaft
//! and coupling) with relative damping `c_drive`. A force at G in the plane gives no moment
//! about the tilt pivot, so the static compliance at the tool point is exactly the linearized
//! `J K^-1 J^T` with `K = diag(k_a, k_b)` and `J` the robot Jacobian ([`linear_compliance`](super::params::linear_compliance)).
//! Inertial forces act at the head's centre of mass, `d` above G (35.9 mm upper, 5.3 mm lower
//! head), and tilt the head: the tool point W, `z_tool` below G, then moves by the tilt too,
//! which a static test at G does not see (the paper's section 5.2).
//!
//! # Servo
//! Each motor is a rotor of reflected inertia `j_motor` under a discrete PD position loop with
//! velocity and acceleration feed-forward, updated at the simulation rate (2 kHz), integrated
//! implicitly together with the drive spring reaction. Its finite gains add a little dynamic
//! compliance (`1/kp`) the static tests (motors locked) do not see.

use deflect_core::mechanism::ParallelRobot2;
use nalgebra::{Vector2, Vector3};
use rapier3d_f64::prelude::*;

use super::params::{
    ACTUATED_LINK_MASS, DT, HALF_WIDTH, INTERMEDIATE_MASS, LINK, PLATFORM_MASS, RobotParams,
    THICK_LINK_MASS, THIN_LINK_MASS,
};
use crate::SimError;
use crate::rapier_util::{
    ANG_X, ANG_Y, ANG_Z, body_point, gravity_z_down, new_world, revolute_z_state, set_spring,
};

/// Mass properties of a set of point masses / rods along a body's local x axis:
/// `(mass, x, own inertia about the body's y and z axes)`.
fn lumped(parts: &[(f64, f64, f64)]) -> MassProperties {
    let m: f64 = parts.iter().map(|p| p.0).sum();
    let cx = parts.iter().map(|p| p.0 * p.1).sum::<f64>() / m;
    let i: f64 = parts
        .iter()
        .map(|p| p.2 + p.0 * (p.1 - cx) * (p.1 - cx))
        .sum();
    MassProperties::new(Vector::new(cx, 0.0, 0.0), m, Vector::new(1e-5, i, i))
}

fn rz(angle: f64) -> Rotation {
    Rotation::from_rotation_z(angle)
}

fn pose(x: f64, y: f64, angle: f64) -> Pose {
    Pose::from_parts(Vector::new(x, y, 0.0), rz(angle))
}

/// One servo motor: rotor angle and speed \[rad, rad/s\] (absolute, like the link angle).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Motor {
    angle: f64,
    speed: f64,
}

/// The robot in its rapier world.
pub struct ParallelSim {
    world: PhysicsWorld,
    params: RobotParams,
    q_ref: Vector2<f64>,
    links: [RigidBodyHandle; 2],
    platform: RigidBodyHandle,
    joints: [MultibodyJointHandle; 2],
    motors: [Motor; 2],
    time: f64,
}

impl core::fmt::Debug for ParallelSim {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ParallelSim")
            .field("params", &self.params)
            .field("q_ref", &self.q_ref)
            .field("time", &self.time)
            .finish_non_exhaustive()
    }
}

/// The rigid bodies of the robot at rest with the tool point at `start`, in insertion order:
/// the base, per arm (A, then B) the actuated and the distal link, then the platform.
struct Bodies {
    base: RigidBodyHandle,
    /// Actuated links A1, B1.
    links: [RigidBodyHandle; 2],
    /// Distal links A2, B2.
    tips: [RigidBodyHandle; 2],
    platform: RigidBodyHandle,
    /// Angles of the distal links \[rad\] (absolute, from +x).
    phis: [f64; 2],
}

impl Bodies {
    fn insert(
        world: &mut PhysicsWorld,
        params: &RobotParams,
        q: &Vector2<f64>,
        start: &Vector2<f64>,
    ) -> Self {
        let l = LINK;
        let base = world.insert_body(RigidBodyBuilder::fixed());
        // Actuated link: rod + intermediate platform at the elbow.
        let rod = |m: f64| m * l * l / 12.0;
        let a1_mass = lumped(&[
            (ACTUATED_LINK_MASS, 0.5 * l, rod(ACTUATED_LINK_MASS)),
            (INTERMEDIATE_MASS, l, 2e-4),
        ]);
        // Distal link: thick link + its parallel thin link, both rods.
        let dm = THICK_LINK_MASS + THIN_LINK_MASS;
        let a2_mass = lumped(&[(dm, 0.5 * l, rod(dm))]);
        let platform_mass = MassProperties::new(
            Vector::new(0.0, 0.0, params.com_height),
            PLATFORM_MASS,
            Vector::new(0.008, 0.008, 0.006),
        );
        let (mut links, mut tips, mut phis) = ([base; 2], [base; 2], [0.0; 2]);
        for (k, (theta, sign)) in [(q.x, 1.0), (q.y, -1.0)].into_iter().enumerate() {
            let (pivot, elbow, phi) = arm_geometry(theta, sign, start);
            links[k] = world.insert_body(
                RigidBodyBuilder::dynamic()
                    .pose(pose(pivot.x, pivot.y, theta))
                    .additional_mass_properties(a1_mass)
                    .can_sleep(false),
            );
            tips[k] = world.insert_body(
                RigidBodyBuilder::dynamic()
                    .pose(pose(elbow.x, elbow.y, phi))
                    .additional_mass_properties(a2_mass)
                    .can_sleep(false),
            );
            phis[k] = phi;
        }
        let platform = world.insert_body(
            RigidBodyBuilder::dynamic()
                .pose(pose(start.x, start.y, 0.0))
                .additional_mass_properties(platform_mass)
                .can_sleep(false),
        );
        Self {
            base,
            links,
            tips,
            platform,
            phis,
        }
    }
}

/// Pivot, elbow and distal-link angle of the arm with actuated angle `theta` on the side
/// `sign` (+1 for A, -1 for B) whose tip meets the platform with the tool point at `start`.
fn arm_geometry(theta: f64, sign: f64, start: &Vector2<f64>) -> (Vector2<f64>, Vector2<f64>, f64) {
    let pivot = Vector2::new(0.0, sign * HALF_WIDTH);
    let elbow = pivot + LINK * Vector2::new(theta.cos(), theta.sin());
    let tip = start + pivot; // D = C + A0, E = C + B0
    (pivot, elbow, (tip.y - elbow.y).atan2(tip.x - elbow.x))
}

/// The robot's joints: the multibody tree (drives at A0 and B0, passive elbows, the platform's
/// free in-plane translation and rotations) and the two loop closures.
struct Joints {
    /// The drive joints at A0 and B0.
    drives: [MultibodyJointHandle; 2],
    /// The platform's joint to the base.
    platform: MultibodyJointHandle,
}

impl Joints {
    fn insert(
        world: &mut PhysicsWorld,
        bodies: &Bodies,
        q: &Vector2<f64>,
        start: &Vector2<f64>,
    ) -> Result<Self, SimError> {
        let mut drives = Vec::new();
        for (k, (theta, sign)) in [(q.x, 1.0), (q.y, -1.0)].into_iter().enumerate() {
            let (pivot, _, phi) = arm_geometry(theta, sign, start);
            let j1 = GenericJointBuilder::new(REVOLUTE_Z)
                .local_frame1(pose(pivot.x, pivot.y, theta))
                .local_frame2(Pose::IDENTITY)
                .contacts_enabled(false)
                .build();
            let j2 = GenericJointBuilder::new(REVOLUTE_Z)
                .local_frame1(pose(LINK, 0.0, phi - theta))
                .local_frame2(Pose::IDENTITY)
                .contacts_enabled(false)
                .build();
            let (b1, b2) = (bodies.links[k], bodies.tips[k]);
            drives.push(
                world
                    .insert_multibody_joint(bodies.base, b1, j1)
                    .ok_or_else(|| SimError::new("multibody joint A0/B0 rejected"))?,
            );
            world
                .insert_multibody_joint(b1, b2, j2)
                .ok_or_else(|| SimError::new("multibody elbow joint rejected"))?;
        }
        let pj = GenericJointBuilder::new(JointAxesMask::LIN_Z)
            .local_frame1(pose(start.x, start.y, 0.0))
            .local_frame2(Pose::IDENTITY)
            .contacts_enabled(false)
            .build();
        let platform = world
            .insert_multibody_joint(bodies.base, bodies.platform, pj)
            .ok_or_else(|| SimError::new("platform joint rejected"))?;
        // Loop closures: the distal tips pinned in the plane to D and E on the platform.
        for (k, sign) in [(0usize, 1.0), (1, -1.0)] {
            let closure = GenericJointBuilder::new(JointAxesMask::LIN_X | JointAxesMask::LIN_Y)
                .local_frame1(pose(LINK, 0.0, 0.0))
                .local_frame2(pose(0.0, sign * HALF_WIDTH, bodies.phis[k]))
                .contacts_enabled(false)
                .build();
            world.insert_impulse_joint(bodies.tips[k], bodies.platform, closure);
        }
        match drives.as_slice() {
            &[a, b] => Ok(Self {
                drives: [a, b],
                platform,
            }),
            _ => Err(SimError::new("two drive joints expected")),
        }
    }

    /// The joints' compliance: the drive springs `k_a`, `k_b`, the platform's tilt and
    /// orientation springs, and the generalized damping of every degree of freedom (drive
    /// damping acts relative to the motor and is applied per step by the servo instead).
    fn set_compliance(&self, world: &mut PhysicsWorld, params: &RobotParams, bodies: &Bodies) {
        for (hd, k) in [(self.drives[0], params.k_a), (self.drives[1], params.k_b)] {
            set_spring(world, hd, ANG_Z, k, 0.0);
        }
        let ph = self.platform;
        set_spring(world, ph, ANG_X, params.k_tilt, 0.0);
        set_spring(world, ph, ANG_Y, params.k_tilt, 0.0);
        set_spring(world, ph, ANG_Z, params.k_orient, 0.0);
        let Some((mb, _)) = world.multibody_joints.get_mut(ph) else {
            return;
        };
        // Generalized damping, in link order (assembly ids are the running DoF count).
        let mut offsets = Vec::new();
        let mut n = 0;
        for link in mb.links() {
            offsets.push((link.rigid_body_handle(), n, link.joint().ndofs()));
            n += link.joint().ndofs();
        }
        let damping = mb.damping_mut();
        for (body, start_dof, ndofs) in offsets {
            for i in 0..ndofs {
                let value = if body == bodies.platform {
                    // LinX, LinY, AngX, AngY, AngZ
                    [0.0, 0.0, params.c_tilt, params.c_tilt, params.c_orient]
                        .get(i)
                        .copied()
                        .unwrap_or(0.0)
                } else if bodies.links.contains(&body) {
                    0.0 // drive damping is applied relative to the motor, explicitly
                } else {
                    0.002 // passive elbows
                };
                if let Some(slot) = damping.get_mut(start_dof + i) {
                    *slot = value;
                }
            }
        }
    }
}

impl ParallelSim {
    /// Builds the robot at rest with its tool point at `start` = (x, y) \[m\] (task frame C - O),
    /// under standard gravity down z ([`deflect_core::units::GRAVITY_Z_DOWN`]), normal to the
    /// plane of motion: its bodies, their joints and the loop closures, the joints'
    /// springs and damping, and the servos at rest.
    pub fn new(params: RobotParams, start: &Vector2<f64>) -> Result<Self, SimError> {
        let q = ParallelRobot2::paper().ik(start)?;
        let mut world = new_world(gravity_z_down(), DT);
        world.integration_parameters.num_solver_iterations = params.solver_iterations;
        world.integration_parameters.num_internal_pgs_iterations = params.pgs_iterations;
        let bodies = Bodies::insert(&mut world, &params, &q, start);
        let joints = Joints::insert(&mut world, &bodies, &q, start)?;
        joints.set_compliance(&mut world, &params, &bodies);
        Ok(Self {
            world,
            params,
            q_ref: q,
            links: bodies.links,
            platform: bodies.platform,
            joints: joints.drives,
            motors: [q.x, q.y].map(|angle| Motor { angle, speed: 0.0 }),
            time: 0.0,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &RobotParams {
        &self.params
    }

    /// Simulated time \[s\].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Joints at construction (IK of the start point) \[rad\].
    pub fn q_ref(&self) -> Vector2<f64> {
        self.q_ref
    }

    /// Angle and rate of the actuated links (absolute, from +x) \[rad, rad/s\].
    pub fn link_state(&self) -> (Vector2<f64>, Vector2<f64>) {
        let mut q = self.q_ref;
        let mut w = Vector2::zeros();
        for k in 0..2 {
            if let Some((dq, rate)) = revolute_z_state(&self.world, self.joints[k]) {
                q[k] += dq;
                w[k] = rate;
            }
        }
        (q, w)
    }

    /// Motor angles \[rad\].
    pub fn motor_angles(&self) -> Vector2<f64> {
        Vector2::new(self.motors[0].angle, self.motors[1].angle)
    }

    /// World position of a platform-local point \[m\].
    fn platform_point(&self, local: Vector) -> Vector3<f64> {
        body_point(&self.world, self.platform, local)
    }

    /// The tool point W (x, y, z) \[m\]; (x, y) is in the task frame.
    pub fn tool_point(&self) -> Vector3<f64> {
        self.platform_point(Vector::new(0.0, 0.0, -self.params.z_tool))
    }

    /// The static-test force point G \[m\].
    pub fn force_point(&self) -> Vector3<f64> {
        self.platform_point(Vector::ZERO)
    }

    /// The head's centre of mass \[m\].
    pub fn com(&self) -> Vector3<f64> {
        self.platform_point(Vector::new(0.0, 0.0, self.params.com_height))
    }

    /// One servo tick: joint command `q` \[rad\] with its rate and acceleration (feed-forward),
    /// then one physics step of [`DT`].
    pub fn step_servo(&mut self, q: &Vector2<f64>, qd: &Vector2<f64>, qdd: &Vector2<f64>) {
        let (ql, wl) = self.link_state();
        let p = self.params;
        let k = [p.k_a, p.k_b];
        for i in 0..2 {
            let m = self.motors[i];
            let (qc, wc, ac) = (q[i], qd[i], qdd[i]);
            // Implicit Euler of J w' = kp (qc - qm) + kd (wc - w) + J ac - k (qm - ql) - c (w - wl).
            let a = p.j_motor / DT + p.kd + p.c_drive + DT * (p.kp + k[i]);
            let b = p.j_motor / DT * m.speed + p.kp * (qc - m.angle) + p.kd * wc + p.j_motor * ac
                - k[i] * (m.angle - ql[i])
                + p.c_drive * wl[i];
            let speed = b / a;
            self.motors[i] = Motor {
                angle: m.angle + DT * speed,
                speed,
            };
        }
        self.apply_drive(&wl, None);
        self.world.step();
        self.time += DT;
    }

    /// One physics step with the motors locked at their current angles and an in-plane force
    /// `force` \[N\] at G (the static test). `damping_scale` multiplies the drive damping (to
    /// settle faster).
    pub fn step_locked(&mut self, force: &Vector2<f64>, damping_scale: f64) {
        let (_, wl) = self.link_state();
        for m in &mut self.motors {
            m.speed = 0.0;
        }
        let g = self.force_point();
        self.apply_drive(&wl, Some((force, damping_scale, g)));
        self.world.step();
        self.time += DT;
    }

    /// Sets the drive springs' rest angles to the motors and applies the relative damping
    /// torques (and an optional static force at G).
    fn apply_drive(
        &mut self,
        wl: &Vector2<f64>,
        force: Option<(&Vector2<f64>, f64, Vector3<f64>)>,
    ) {
        let scale = force.map_or(1.0, |f| f.1);
        let k = [self.params.k_a, self.params.k_b];
        for i in 0..2 {
            let rest = self.motors[i].angle - self.q_ref[i];
            set_spring(&mut self.world, self.joints[i], ANG_Z, k[i], rest);
            let torque = -self.params.c_drive * scale * (wl[i] - self.motors[i].speed);
            if let Some(rb) = self.world.bodies.get_mut(self.links[i]) {
                rb.reset_forces(false);
                rb.reset_torques(false);
                rb.add_torque(Vector::new(0.0, 0.0, torque), false);
            }
        }
        if let Some(rb) = self.world.bodies.get_mut(self.platform) {
            rb.reset_forces(false);
            rb.reset_torques(false);
            if let Some((f, _, g)) = force {
                rb.add_force_at_point(
                    Vector::new(f.x, f.y, 0.0),
                    Vector::new(g.x, g.y, g.z),
                    false,
                );
            }
        }
    }
}

/// Locked axes of a revolute joint about z.
const REVOLUTE_Z: JointAxesMask = JointAxesMask::LIN_X
    .union(JointAxesMask::LIN_Y)
    .union(JointAxesMask::LIN_Z)
    .union(JointAxesMask::ANG_X)
    .union(JointAxesMask::ANG_Y);
