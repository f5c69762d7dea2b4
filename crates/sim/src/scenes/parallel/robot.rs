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
//! `J K^-1 J^T` with `K = diag(k_a, k_b)` and `J` the robot Jacobian ([`linear_compliance`]).
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
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use rapier3d_f64::prelude::*;

use crate::SimError;
use crate::rapier_util::{
    ANG_X, ANG_Y, ANG_Z, body_point, gravity_z_down, new_world, revolute_z_state, set_spring,
};

/// Simulation step \[s\]: the paper's 2 kHz servo rate.
pub const DT: f64 = 1.0 / 2000.0;
/// Link length \[m\] (section 4.1).
pub const LINK: f64 = 0.150;
/// Half width |A0O| = |BC| \[m\].
pub const HALF_WIDTH: f64 = 0.090;
/// Moving platform with end effector \[kg\].
pub const PLATFORM_MASS: f64 = 3.6;
/// Thick distal link \[kg\].
pub const THICK_LINK_MASS: f64 = 0.2194;
/// Thin link \[kg\].
pub const THIN_LINK_MASS: f64 = 0.1236;
/// Intermediate platform \[kg\].
pub const INTERMEDIATE_MASS: f64 = 0.2512;
/// Actuated link: not reported by the paper ("assumed rigid"); our value \[kg\].
pub const ACTUATED_LINK_MASS: f64 = 0.30;
/// CoM height above G, upper head \[m\].
pub const D_UPPER: f64 = 0.0359;
/// CoM height above G, lower head \[m\].
pub const D_LOWER: f64 = 0.0053;
/// Tool point W (laser working point) below G \[m\]: our choice.
pub const Z_TOOL: f64 = 0.030;

/// Over- or normal-constrained mechanism.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum Constraint {
    /// Over-constrained (stiffer, symmetric).
    Oc,
    /// Normal-constrained (softer, arm B softer than arm A).
    Nc,
}

/// Head (laser) position: centre of mass high or low above G.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum Head {
    /// G_U: CoM 35.9 mm above G.
    Upper,
    /// G_L: CoM 5.3 mm above G.
    Lower,
}

impl Constraint {
    /// "OC" / "NC".
    pub fn label(self) -> &'static str {
        match self {
            Self::Oc => "OC",
            Self::Nc => "NC",
        }
    }
}

impl Head {
    /// "GU" / "GL".
    pub fn label(self) -> &'static str {
        match self {
            Self::Upper => "GU",
            Self::Lower => "GL",
        }
    }
    /// CoM height above G \[m\].
    pub fn com_height(self) -> f64 {
        match self {
            Self::Upper => D_UPPER,
            Self::Lower => D_LOWER,
        }
    }
}

/// Every physical parameter of one robot configuration (SI).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RobotParams {
    /// Mechanism variant.
    pub constraint: Constraint,
    /// Head position.
    pub head: Head,
    /// Drive stiffness of arm A \[N m/rad\].
    pub k_a: f64,
    /// Drive stiffness of arm B \[N m/rad\].
    pub k_b: f64,
    /// Relative damping of each drive spring \[N m s/rad\].
    pub c_drive: f64,
    /// Out-of-plane bending (tilt) stiffness of the head about G \[N m/rad\].
    pub k_tilt: f64,
    /// Tilt damping \[N m s/rad\].
    pub c_tilt: f64,
    /// Orientation stiffness of the parallelograms \[N m/rad\].
    pub k_orient: f64,
    /// Orientation damping \[N m s/rad\].
    pub c_orient: f64,
    /// Reflected motor inertia \[kg m^2\].
    pub j_motor: f64,
    /// Servo position gain \[N m/rad\].
    pub kp: f64,
    /// Servo velocity gain \[N m s/rad\].
    pub kd: f64,
    /// Head CoM height above G \[m\].
    pub com_height: f64,
    /// Tool point below G \[m\].
    pub z_tool: f64,
    /// rapier solver iterations (substeps).
    pub solver_iterations: usize,
    /// rapier internal PGS iterations per substep.
    pub pgs_iterations: usize,
}

impl RobotParams {
    /// The documented defaults of one configuration.
    ///
    /// Stiffnesses were chosen so that the static compliance over the paper's grid is of the
    /// order of its tables: OC about 0.2-0.5 mm, NC about 0.4-1.1 mm of displacement at
    /// 245 N. Damping ratios are a few percent; the servo loop has about 250 Hz bandwidth.
    pub fn new(constraint: Constraint, head: Head) -> Self {
        let (k_a, k_b, k_tilt) = match constraint {
            Constraint::Oc => (16_000.0, 16_000.0, 2_500.0),
            Constraint::Nc => (9_000.0, 7_000.0, 1_500.0),
        };
        let j_motor = 0.05;
        let w = 2.0 * core::f64::consts::PI * 250.0;
        Self {
            constraint,
            head,
            k_a,
            k_b,
            c_drive: 3.0,
            k_tilt,
            c_tilt: 0.5,
            k_orient: 40_000.0,
            c_orient: 2.0,
            j_motor,
            kp: j_motor * w * w,
            kd: 2.0 * 0.7 * w * j_motor,
            com_height: head.com_height(),
            z_tool: Z_TOOL,
            solver_iterations: 1,
            pgs_iterations: 4,
        }
    }

    /// "OC GU" etc.
    pub fn label(&self) -> String {
        format!("{} {}", self.constraint.label(), self.head.label())
    }
}

/// The linearized static compliance of the model at the tool point for an in-plane force at
/// G: `J K^-1 J^T` \[m/N\] over the three elastic coordinates of the closed chain,
/// `K = diag(k_a, k_b, k_orient)` (the two drive springs and the parallelograms' orientation
/// spring) and `J = d(x, y, psi)/d(theta_a, theta_b, psi)` at the tool point `p` \[m\] (x, y
/// block returned). Without the orientation spring (`k_orient -> inf`) this is the robot's
/// 2 x 2 `J K^-1 J^T` with [`ParallelRobot2::jacobian_at`].
///
/// `J^-1` is built by central differences of the arms' closed-form IK: with the platform
/// rotated by `psi`, arm A reaches `D - A0 = p + R(psi) (0, h) - (0, h)` and arm B
/// `E - B0 = p + R(psi) (0, -h) - (0, -h)`.
pub fn linear_compliance(params: &RobotParams, p: &Vector2<f64>) -> Result<Matrix2<f64>, SimError> {
    let mech = ParallelRobot2::paper();
    let h = HALF_WIDTH;
    let joints = |x: f64, y: f64, psi: f64| -> Result<Vector3<f64>, SimError> {
        let (s, c) = psi.sin_cos();
        let ta = Vector2::new(x - h * s, y + h * c - h);
        let tb = Vector2::new(x + h * s, y - h * c + h);
        Ok(Vector3::new(mech.ik(&ta)?.x, mech.ik(&tb)?.y, psi))
    };
    let e = 1e-7;
    let mut jinv = Matrix3::zeros();
    for k in 0..3 {
        let mut dp = Vector3::zeros();
        dp[k] = e;
        let plus = joints(p.x + dp.x, p.y + dp.y, dp.z)?;
        let minus = joints(p.x - dp.x, p.y - dp.y, -dp.z)?;
        jinv.set_column(k, &((plus - minus) / (2.0 * e)));
    }
    let j = jinv
        .try_inverse()
        .ok_or_else(|| SimError::new("singular pose in linear_compliance"))?;
    let kinv = Matrix3::from_diagonal(&Vector3::new(
        1.0 / params.k_a,
        1.0 / params.k_b,
        1.0 / params.k_orient,
    ));
    let c = j * kinv * j.transpose();
    Ok(Matrix2::new(c[(0, 0)], c[(0, 1)], c[(1, 0)], c[(1, 1)]))
}

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

impl ParallelSim {
    /// Builds the robot at rest with its tool point at `start` = (x, y) \[m\] (task frame C - O),
    /// under standard gravity down z ([`deflect_core::units::GRAVITY_Z_DOWN`]), normal to the
    /// plane of motion.
    pub fn new(params: RobotParams, start: &Vector2<f64>) -> Result<Self, SimError> {
        let mech = ParallelRobot2::paper();
        let q = mech.ik(start)?;
        let (l, h) = (LINK, HALF_WIDTH);
        let mut world = new_world(gravity_z_down(), DT);
        world.integration_parameters.num_solver_iterations = params.solver_iterations;
        world.integration_parameters.num_internal_pgs_iterations = params.pgs_iterations;

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
        let d = params.com_height;
        let platform_mass = MassProperties::new(
            Vector::new(0.0, 0.0, d),
            PLATFORM_MASS,
            Vector::new(0.008, 0.008, 0.006),
        );

        let mut links = [base; 2];
        let mut joints = Vec::new();
        let mut tips = [base; 2];
        for (k, (theta, sign)) in [(q.x, 1.0), (q.y, -1.0)].into_iter().enumerate() {
            let pivot = Vector2::new(0.0, sign * h);
            let elbow = pivot + l * Vector2::new(theta.cos(), theta.sin());
            let tip = start + pivot; // D = C + A0, E = C + B0
            let phi = (tip.y - elbow.y).atan2(tip.x - elbow.x);
            let b1 = world.insert_body(
                RigidBodyBuilder::dynamic()
                    .pose(pose(pivot.x, pivot.y, theta))
                    .additional_mass_properties(a1_mass)
                    .can_sleep(false),
            );
            let b2 = world.insert_body(
                RigidBodyBuilder::dynamic()
                    .pose(pose(elbow.x, elbow.y, phi))
                    .additional_mass_properties(a2_mass)
                    .can_sleep(false),
            );
            let j1 = GenericJointBuilder::new(REVOLUTE_Z)
                .local_frame1(pose(pivot.x, pivot.y, theta))
                .local_frame2(Pose::IDENTITY)
                .contacts_enabled(false)
                .build();
            let j2 = GenericJointBuilder::new(REVOLUTE_Z)
                .local_frame1(pose(l, 0.0, phi - theta))
                .local_frame2(Pose::IDENTITY)
                .contacts_enabled(false)
                .build();
            let h1 = world
                .insert_multibody_joint(base, b1, j1)
                .ok_or_else(|| SimError::new("multibody joint A0/B0 rejected"))?;
            world
                .insert_multibody_joint(b1, b2, j2)
                .ok_or_else(|| SimError::new("multibody elbow joint rejected"))?;
            links[k] = b1;
            tips[k] = b2;
            joints.push((h1, phi));
        }
        let platform = world.insert_body(
            RigidBodyBuilder::dynamic()
                .pose(pose(start.x, start.y, 0.0))
                .additional_mass_properties(platform_mass)
                .can_sleep(false),
        );
        let pj = GenericJointBuilder::new(JointAxesMask::LIN_Z)
            .local_frame1(pose(start.x, start.y, 0.0))
            .local_frame2(Pose::IDENTITY)
            .contacts_enabled(false)
            .build();
        let ph = world
            .insert_multibody_joint(base, platform, pj)
            .ok_or_else(|| SimError::new("platform joint rejected"))?;
        // Loop closures: the distal tips pinned in the plane to D and E on the platform.
        for (k, sign) in [(0usize, 1.0), (1, -1.0)] {
            let phi = joints[k].1;
            let closure = GenericJointBuilder::new(JointAxesMask::LIN_X | JointAxesMask::LIN_Y)
                .local_frame1(pose(l, 0.0, 0.0))
                .local_frame2(pose(0.0, sign * h, phi))
                .contacts_enabled(false)
                .build();
            world.insert_impulse_joint(tips[k], platform, closure);
        }
        // Springs and damping.
        let drive = [joints[0].0, joints[1].0];
        let (ka, kb) = (params.k_a, params.k_b);
        for (hd, k) in [(drive[0], ka), (drive[1], kb)] {
            set_spring(&mut world, hd, ANG_Z, k, 0.0);
        }
        set_spring(&mut world, ph, ANG_X, params.k_tilt, 0.0);
        set_spring(&mut world, ph, ANG_Y, params.k_tilt, 0.0);
        set_spring(&mut world, ph, ANG_Z, params.k_orient, 0.0);
        if let Some((mb, _)) = world.multibody_joints.get_mut(ph) {
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
                    let value = if body == platform {
                        // LinX, LinY, AngX, AngY, AngZ
                        [0.0, 0.0, params.c_tilt, params.c_tilt, params.c_orient]
                            .get(i)
                            .copied()
                            .unwrap_or(0.0)
                    } else if links.contains(&body) {
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
        Ok(Self {
            world,
            params,
            q_ref: q,
            links,
            platform,
            joints: drive,
            motors: [
                Motor {
                    angle: q.x,
                    speed: 0.0,
                },
                Motor {
                    angle: q.y,
                    speed: 0.0,
                },
            ],
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
