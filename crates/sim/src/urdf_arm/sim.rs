//! The arm of an [`ArmSpec`] in rapier3d-f64: a reduced-coordinate multibody, one rigid body
//! per actuated joint and per virtual joint, with servo motors outside rapier.
//!
//! * **Virtual joints** are multibody joints with rapier's implicit joint springs, rest angle
//!   zero: one free rotation when one stiffness is finite, all three when two or three are
//!   (rapier's multibody joints take 0, 1 or 3 free rotations; a rigid axis among three gets a
//!   spring [`STIFF_RATIO`] times the joint's stiffest), and stiffness-proportional structural
//!   damping `beta k`. For small angles the three rotations are the virtual joint's `M / k`,
//!   so the arm's static compliance is deflect-core's `J K^-1 J^T` (a test checks it to 1 %).
//! * **Actuated joints** are revolute or prismatic multibody joints (exact coordinate). The link
//!   hangs on its motor through a drive spring of stiffness [`ServoParams::drive_ratio`] times
//!   the arm's stiffest virtual joint (gearbox and shaft, nearly rigid: the compliance under
//!   test is the virtual joints'), with relative damping. Each motor is a rotor of reflected
//!   inertia under a discrete PD position loop with velocity and acceleration feed-forward at
//!   the simulation rate, integrated implicitly with the drive spring's reaction: the five-bar
//!   scene's servo ([`crate::scenes::parallel::robot`]). Its gains come from a bandwidth and a loop stiffness
//!   [`ServoParams::kp_ratio`] times the stiffest virtual joint. A prismatic joint's motor and
//!   drive take the same constants read per metre (loop and drive stiffness in N/m, reflected
//!   mass in kg: a screw of 1 m/rad), so its loop has the same bandwidth.
//! * The URDF links' mass properties sit on the body after the link's last spring (the
//!   proximal part of a link split by an in-link spring is lumped distally); bodies that carry
//!   no link get a small mass ([`ServoParams::filler_mass`], at most 3 % of the links' total
//!   so that a hobby arm of a few hundred grams is not made heavier than its model). A
//!   payload adds to the last body.
//!   Gravity is off: a robot's static sag under its own weight is calibrated out in practice,
//!   and the scenarios study inertial and process loads.

use deflect_core::dalembert::serial::Payload;
use deflect_core::vjm::Vector6;
use nalgebra::{Isometry3, Point3, Vector3};
use rapier3d_f64::prelude::*;

use super::build::{Chain, ChainParams, build_chain};
use super::spec::{ArmSpec, Piece, RIGID};
use crate::SimError;
use crate::rapier_util::{ANG_X, LIN_X, pose_na, set_spring};

/// A rigid axis among a virtual joint's three free rotations gets this many times the joint's
/// stiffest finite stiffness.
pub const STIFF_RATIO: f64 = 1.0e3;

/// Servo and structure settings of the testbed arm.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ServoParams {
    /// Position-loop bandwidth of every motor \[Hz\].
    pub bandwidth_hz: f64,
    /// Damping ratio of the position loop.
    pub zeta: f64,
    /// Loop stiffness `kp` over the arm's stiffest virtual joint: the motor's reflected
    /// inertia is `kp / (2 pi bandwidth)^2`.
    pub kp_ratio: f64,
    /// Drive-spring stiffness over the arm's stiffest virtual joint.
    pub drive_ratio: f64,
    /// Damping ratio of the drive spring (relative motor-link damping, against the motor's
    /// reflected inertia).
    pub drive_zeta: f64,
    /// Stiffness-proportional damping of the virtual joints, `c = beta k` \[s\].
    pub beta: f64,
    /// Mass of a body that carries no URDF link \[kg\] (inertia of a 5 cm sphere), at most
    /// 3 % of the links' total mass.
    pub filler_mass: f64,
    /// Time step \[s\].
    pub dt: f64,
    /// rapier substeps per time step (its `num_solver_iterations`): each one integrates
    /// `dt / substeps` and rebuilds the multibody mass matrix, most of a step's cost.
    pub substeps: usize,
}

impl Default for ServoParams {
    /// 150 Hz, 0.7; loop 50x and drive 100x the stiffest virtual joint; drive 0.7 damped;
    /// beta 1 ms (2-4 % of critical on the arms' first modes); 0.5 kg fillers; 0.5 ms in
    /// rapier's default 4 substeps.
    fn default() -> Self {
        Self {
            bandwidth_hz: 150.0,
            zeta: 0.7,
            kp_ratio: 50.0,
            drive_ratio: 100.0,
            drive_zeta: 0.7,
            beta: 1.0e-3,
            filler_mass: 0.5,
            dt: 1.0 / 2000.0,
            substeps: 4,
        }
    }
}

/// One servo motor: rotor angle and speed \[rad, rad/s\], absolute like the joint angle.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Motor {
    angle: f64,
    speed: f64,
}

/// The arm in rapier (see the module docs).
pub struct FlexSerialArm {
    world: PhysicsWorld,
    bodies: Vec<RigidBodyHandle>,
    joints: Vec<MultibodyJointHandle>,
    /// Body index of each actuated joint, in `q` order.
    actuated: Vec<usize>,
    /// Joint axis of each actuated joint in its body frame.
    axes: Vec<Vector3<f64>>,
    /// Whether each actuated joint is prismatic (its coordinate a length).
    prismatic: Vec<bool>,
    /// Body index and attachment (in the previous body) of each virtual joint, chain order.
    springs: Vec<(usize, Isometry3<f64>)>,
    q0: Vec<f64>,
    motors: Vec<Motor>,
    tcp: Isometry3<f64>,
    k_drive: f64,
    j_motor: f64,
    kp: f64,
    kd: f64,
    c_drive: f64,
    dt: f64,
    time: f64,
}

impl core::fmt::Debug for FlexSerialArm {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("FlexSerialArm")
            .field("bodies", &self.bodies.len())
            .field("q0", &self.q0)
            .field("k_drive", &self.k_drive)
            .field("kp", &self.kp)
            .finish_non_exhaustive()
    }
}

impl FlexSerialArm {
    /// The arm of `spec` at rest at joints `q0` \[rad\], carrying `payload` (TCP frame), with
    /// `servo` settings. `damping_scale` multiplies every damping (> 1 to settle static tests
    /// quickly).
    pub fn new(
        spec: &ArmSpec,
        q0: &[f64],
        payload: Option<&Payload>,
        servo: &ServoParams,
        damping_scale: f64,
    ) -> Result<Self, SimError> {
        let dof = spec.robot.model.dof();
        if q0.len() != dof {
            return Err(SimError::new(format!(
                "start joints: {} values for a {dof}-joint arm",
                q0.len()
            )));
        }
        let k_max = spec
            .bodies
            .iter()
            .filter_map(|b| match &b.piece {
                Piece::Spring { k, .. } => {
                    k.iter().copied().filter(|v| *v < RIGID).reduce(f64::max)
                }
                Piece::Revolute { .. } | Piece::Prismatic { .. } => None,
            })
            .fold(0.0f64, f64::max);
        if k_max <= 0.0 || k_max.is_nan() {
            return Err(SimError::new(
                "the stiffness file gives the arm no finite stiffness: nothing to simulate",
            ));
        }
        let w = 2.0 * core::f64::consts::PI * servo.bandwidth_hz;
        let kp = servo.kp_ratio * k_max;
        let j_motor = kp / (w * w);
        let kd = 2.0 * servo.zeta * w * j_motor;
        let k_drive = servo.drive_ratio * k_max;
        let c_drive = 2.0 * servo.drive_zeta * (k_drive * j_motor).sqrt();

        let links: f64 = spec.bodies.iter().map(|b| b.inertia.mass).sum();
        let filler = if links > 0.0 {
            servo.filler_mass.min(0.03 * links)
        } else {
            servo.filler_mass
        };
        if servo.substeps == 0 {
            return Err(SimError::new(
                "servo settings: substeps must be at least 1, got 0",
            ));
        }
        let params = ChainParams {
            k_drive,
            c_drive,
            beta: servo.beta,
            damping_scale,
            filler,
            stiff_ratio: STIFF_RATIO,
            dt: servo.dt,
            substeps: servo.substeps,
        };
        let Chain {
            world,
            bodies,
            joints,
            actuated,
            axes,
            springs: spring_bodies,
        } = build_chain(spec, q0, payload, &params)?;
        let motors = q0
            .iter()
            .map(|&angle| Motor { angle, speed: 0.0 })
            .collect();
        let prismatic = actuated
            .iter()
            .map(|&b| {
                matches!(
                    spec.bodies.get(b).map(|x| &x.piece),
                    Some(Piece::Prismatic { .. })
                )
            })
            .collect();
        Ok(Self {
            world,
            bodies,
            joints,
            actuated,
            axes,
            prismatic,
            springs: spring_bodies,
            q0: q0.to_vec(),
            motors,
            tcp: spec.tcp,
            k_drive,
            j_motor,
            kp,
            kd,
            c_drive,
            dt: servo.dt,
            time: 0.0,
        })
    }

    /// Simulated time \[s\].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Number of rigid bodies of the arm (the fixed base excluded).
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// The motor's reflected inertia \[kg m^2\], loop stiffness \[N m/rad\] and drive stiffness
    /// \[N m/rad\] (the same for every joint).
    pub fn servo_constants(&self) -> (f64, f64, f64) {
        (self.j_motor, self.kp, self.k_drive)
    }

    fn pose_of(&self, body: RigidBodyHandle) -> Isometry3<f64> {
        self.world
            .bodies
            .get(body)
            .map(|rb| pose_na(rb.position()))
            .unwrap_or_else(Isometry3::identity)
    }

    /// The TCP pose, base frame.
    pub fn tcp_pose(&self) -> Isometry3<f64> {
        match self.bodies.last() {
            Some(b) => self.pose_of(*b) * self.tcp,
            None => self.tcp,
        }
    }

    /// The rotation across each virtual joint of the simulated arm (the bodies built for
    /// springs with a finite stiffness, chain order) as a rotation vector in the spring frame
    /// \[rad\]: what a frame-pair measurement on either side of it reads (Hähn and Weigold,
    /// sec. 2.5).
    pub fn spring_rotations(&self) -> Vec<Vector3<f64>> {
        self.springs
            .iter()
            .map(|&(b, attach)| {
                let parent = match b.checked_sub(1).and_then(|p| self.bodies.get(p)) {
                    Some(h) => self.pose_of(*h),
                    None => Isometry3::identity(),
                };
                let body = self
                    .bodies
                    .get(b)
                    .map_or_else(Isometry3::identity, |h| self.pose_of(*h));
                ((parent * attach).rotation.inverse() * body.rotation).scaled_axis()
            })
            .collect()
    }

    /// Joint angles and rates of the link side \[rad, rad/s\].
    pub fn joint_state(&self) -> (Vec<f64>, Vec<f64>) {
        let mut q = self.q0.clone();
        let mut w = vec![0.0; self.q0.len()];
        for (k, &b) in self.actuated.iter().enumerate() {
            let Some(h) = self.joints.get(b) else {
                continue;
            };
            let Some((mb, id)) = self.world.multibody_joints.get(*h) else {
                continue;
            };
            let Some(link) = mb.link(id) else { continue };
            let coord = if self.prismatic.get(k).copied().unwrap_or(false) {
                LIN_X
            } else {
                ANG_X
            };
            if let (Some(qk), Some(wk)) = (q.get_mut(k), w.get_mut(k)) {
                *qk += link.joint().coords()[coord];
                *wk = mb.joint_velocity(link).get(0).copied().unwrap_or(0.0);
            }
        }
        (q, w)
    }

    /// Motor angles \[rad\].
    pub fn motor_angles(&self) -> Vec<f64> {
        self.motors.iter().map(|m| m.angle).collect()
    }

    /// Sets the drive springs' rest angles to the motors, the relative drive damping torques,
    /// and an optional TCP wrench `[F; M]` (base frame, moment about the TCP).
    fn apply(&mut self, wrench: Option<&Vector6>) {
        for b in &self.bodies {
            if let Some(rb) = self.world.bodies.get_mut(*b) {
                rb.reset_forces(false);
                rb.reset_torques(false);
            }
        }
        for (k, &b) in self.actuated.iter().enumerate() {
            let (Some(m), Some(h)) = (self.motors.get(k), self.joints.get(b)) else {
                continue;
            };
            let rest = m.angle - self.q0.get(k).copied().unwrap_or(0.0);
            let prismatic = self.prismatic.get(k).copied().unwrap_or(false);
            set_spring(
                &mut self.world,
                *h,
                if prismatic { LIN_X } else { ANG_X },
                self.k_drive,
                rest,
            );
            // The motor's part of the relative drive damping, `+c v_motor` along or about the
            // joint axis (world frame), reacted by the body before (the link's part,
            // `-c v_link`, is rapier's implicit joint damping); a force pair acts at the
            // joint's origin, so it carries no moment.
            let body = self.bodies.get(b).copied();
            let frame = body
                .map(|h| self.pose_of(h))
                .unwrap_or_else(Isometry3::identity);
            let axis_w = frame.rotation * self.axes.get(k).copied().unwrap_or_default();
            let t = axis_w * (self.c_drive * m.speed);
            let v = Vector::new(t.x, t.y, t.z);
            let at = frame.translation.vector;
            let at = Vector::new(at.x, at.y, at.z);
            let mut push = |h: Option<RigidBodyHandle>, sign: f64| {
                if let Some(rb) = h.and_then(|h| self.world.bodies.get_mut(h)) {
                    if prismatic {
                        rb.add_force_at_point(v * sign, at, false);
                    } else {
                        rb.add_torque(v * sign, false);
                    }
                }
            };
            push(body, 1.0);
            if b > 0 {
                push(self.bodies.get(b - 1).copied(), -1.0);
            }
        }
        if let (Some(w), Some(last)) = (wrench, self.bodies.last().copied()) {
            let p = self.tcp_pose().translation.vector;
            if let Some(rb) = self.world.bodies.get_mut(last) {
                rb.add_force_at_point(
                    Vector::new(w[0], w[1], w[2]),
                    Vector::new(p.x, p.y, p.z),
                    false,
                );
                rb.add_torque(Vector::new(w[3], w[4], w[5]), false);
            }
        }
    }

    /// One servo tick: joint command `q` \[rad\] with its rate and acceleration (feed-forward)
    /// and an optional process wrench at the TCP, then one physics step.
    pub fn step_servo(&mut self, q: &[f64], qd: &[f64], qdd: &[f64], wrench: Option<&Vector6>) {
        let (ql, wl) = self.joint_state();
        let dt = self.dt;
        for (k, m) in self.motors.iter_mut().enumerate() {
            let at = |v: &[f64]| v.get(k).copied().unwrap_or(0.0);
            let (qc, wc, ac) = (at(q), at(qd), at(qdd));
            // Implicit Euler of J w' = kp (qc - qm) + kd (wc - w) + J ac - k (qm - ql) - c (w - wl).
            let a = self.j_motor / dt + self.kd + self.c_drive + dt * (self.kp + self.k_drive);
            let b = self.j_motor / dt * m.speed
                + self.kp * (qc - m.angle)
                + self.kd * wc
                + self.j_motor * ac
                - self.k_drive * (m.angle - at(&ql))
                + self.c_drive * at(&wl);
            let speed = b / a;
            *m = Motor {
                angle: m.angle + dt * speed,
                speed,
            };
        }
        self.apply(wrench);
        self.world.step();
        self.time += dt;
    }

    /// One physics step with the motors locked at their angles and a TCP wrench.
    pub fn step_locked(&mut self, wrench: &Vector6) {
        for m in &mut self.motors {
            m.speed = 0.0;
        }
        self.apply(Some(wrench));
        self.world.step();
        self.time += self.dt;
    }

    /// The TCP's displacement `[dp; dr]` \[m, rad\] under a static TCP `wrench`, motors locked:
    /// steps until the TCP moves less than 1e-12 m (and rad) per step, at most `max_steps`.
    /// Build the arm with a large damping scale for quick settling.
    pub fn static_deflection(&mut self, wrench: &Vector6, max_steps: usize) -> Vector6 {
        let start = self.tcp_pose();
        let mut last = start;
        for _ in 0..max_steps {
            self.step_locked(wrench);
            let now = self.tcp_pose();
            let dp = (now.translation.vector - last.translation.vector).norm();
            let dr = now.rotation.angle_to(&last.rotation);
            last = now;
            if dp < 1e-12 && dr < 1e-12 {
                break;
            }
        }
        let dp = last.translation.vector - start.translation.vector;
        let dr = (last.rotation * start.rotation.inverse()).scaled_axis();
        Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z)
    }

    /// World position of the TCP-frame point `p` \[m\].
    pub fn tcp_point(&self, p: &Vector3<f64>) -> Vector3<f64> {
        (self.tcp_pose() * Point3::from(*p)).coords
    }
}
