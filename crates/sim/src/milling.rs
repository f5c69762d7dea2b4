//! Milling scenario for the online force-based compensation of Hähn & Weigold (sections 2.2-2.6
//! and 3, `shared/papers/001_bf9bba303970c33c.txt`) on a 4-axis spatial flexible arm in rapier.
//!
//! The arm: a yaw joint (z) at the base and three pitch joints (y: shoulder, elbow, wrist),
//! each a reduced-coordinate multibody revolute joint with a drive spring whose rest angle is
//! the motor angle (rapier's implicit joint springs), and structural damping. Its virtual-joint
//! model ([`vjm_model`]) has one spring about each joint axis, so rapier's static compliance
//! is the VJM one. Gravity is off in rapier (the arm's own sag is treated as calibrated out);
//! the tool weight only enters the simulated force/torque sensor at the flange.
//!
//! The scenario: a straight groove along +x at constant feed with the tool pointing down; a
//! process force that steps up at cutter entry and down at exit acts at the TCP; the sensor
//! reads it with an internal offset, the tool's weight and seeded Gaussian noise. Three runs:
//! uncompensated, Cartesian compensation ([`OnlineCompensator`], measured forces only), and
//! compensation with pilot control (an offline force estimate leading the real force). The
//! correction is applied every control cycle through the arm's inverse kinematics; the robot
//! answers a correction after a transport delay and a first-order servo lag. Before the runs
//! the stiffnesses are identified from frame-pair rotations and TCP deflections under static
//! loads in rapier, and the sensor from unloaded readings at several orientations; the
//! compensator uses the identified values.

use deflect_core::compensation::{CompensatorConfig, OnlineCompensator, SensorCalibration};
use deflect_core::identification::{
    FrameMeasurement, StiffnessIdentification, TcpMeasurement, identify_from_frames,
    identify_from_tcp, identify_sensor,
};
use deflect_core::vjm::{self, Data, Model, ModelBuilder, Vector6};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::*;
use serde::Serialize;

use crate::SimError;
use crate::robot::DT;

/// Number of joints of the arm.
pub const JOINTS: usize = 4;

/// The arm: geometry, masses, stiffnesses and damping.
#[derive(Debug, Clone, Serialize)]
pub struct ArmParams {
    /// Shoulder height above the base [m].
    pub shoulder_height: f64,
    /// Upper arm (shoulder to elbow) [m].
    pub upper_arm: f64,
    /// Forearm (elbow to wrist) [m].
    pub forearm: f64,
    /// Wrist joint to the flange (sensor) [m].
    pub wrist_to_flange: f64,
    /// Flange (sensor) to the tool point [m].
    pub tool_length: f64,
    /// Masses of turret, upper arm, forearm, wrist + spindle [kg].
    pub masses: [f64; JOINTS],
    /// Joint stiffnesses (drive springs) [N m/rad].
    pub stiffness: [f64; JOINTS],
    /// Joint damping [N m s/rad].
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

    /// Joint angles that put the tool point at `p` [m] with the tool pointing down (the last
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

/// The arm's virtual-joint model with joint stiffnesses `k` [N m/rad]: one spring about each
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

fn to_na(v: Vector) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

fn rot_na(q: Rotation) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q.w, q.x, q.y, q.z))
}

fn pose_na(p: &Pose) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::from(to_na(p.translation)), rot_na(p.rotation))
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
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::ZERO;
        world.integration_parameters.dt = dt;
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
            if let Some((mb, id)) = world.multibody_joints.get_mut(h) {
                if let Some(link) = mb.link_mut(id) {
                    link.joint.set_spring(spring_axis(i), p.stiffness[i], 0.0);
                }
                if let Some(d) = mb.damping_mut().iter_mut().last() {
                    *d = p.damping[i] * damping_scale;
                }
            }
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
            .and_then(|h| self.world.bodies.get(*h))
            .map(|rb| pose_na(rb.position()))
            .unwrap_or_else(Isometry3::identity)
    }

    /// Pose of the sensor (flange) frame, base frame.
    pub fn sensor_pose(&self) -> Isometry3<f64> {
        self.body_pose(JOINTS - 1) * Isometry3::translation(self.params.wrist_to_flange, 0.0, 0.0)
    }

    /// The tool point [m], base frame.
    pub fn tcp(&self) -> Vector3<f64> {
        (self.sensor_pose() * Isometry3::translation(self.params.tool_length, 0.0, 0.0))
            .translation
            .vector
    }

    /// Rotation across each drive spring (link minus motor side) as a rotation vector in the
    /// spring frame (the joint's child frame) [rad], for motor angles `q_motor`.
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
    /// `force` [N] at the tool point (base frame).
    pub fn step(&mut self, q_motor: &[f64; JOINTS], force: &Vector3<f64>) {
        for (i, h) in self.joints.iter().enumerate() {
            let rest = q_motor[i] - self.q_ref[i];
            if let Some((mb, id)) = self.world.multibody_joints.get_mut(*h) {
                if let Some(link) = mb.link_mut(id) {
                    link.joint
                        .set_spring(spring_axis(i), self.params.stiffness[i], rest);
                }
            }
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

fn spring_axis(i: usize) -> usize {
    if i == 0 { 5 } else { 4 }
}

/// Seeded Gaussian noise (SplitMix64 and Box-Muller): deterministic, no dependency.
#[derive(Debug, Clone)]
pub struct Noise(u64);

impl Noise {
    /// A generator with `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    /// A standard normal sample.
    pub fn gauss(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * core::f64::consts::PI * u2).cos()
    }
}

/// The simulated flange force/torque sensor.
#[derive(Debug, Clone, Serialize)]
pub struct SensorParams {
    /// Internal force offset [N], sensor frame.
    pub force_offset: [f64; 3],
    /// Internal moment offset [N m], sensor frame.
    pub moment_offset: [f64; 3],
    /// Weight of tool and spindle beyond the sensor [N].
    pub weight: f64,
    /// Their centre of gravity [m], sensor frame.
    pub center_of_gravity: [f64; 3],
    /// Noise standard deviation of the forces [N] and moments [N m].
    pub noise: [f64; 2],
}

impl Default for SensorParams {
    fn default() -> Self {
        Self {
            force_offset: [14.0, -9.0, 22.0],
            moment_offset: [0.8, -0.5, 0.3],
            weight: 180.0,
            center_of_gravity: [0.09, 0.004, -0.006],
            noise: [4.0, 0.3],
        }
    }
}

impl SensorParams {
    /// The true calibration (what identification should find).
    pub fn calibration(&self, sensor_to_tcp: Isometry3<f64>) -> SensorCalibration {
        SensorCalibration {
            force_offset: Vector3::from(self.force_offset),
            moment_offset: Vector3::from(self.moment_offset),
            weight: self.weight,
            center_of_gravity: Vector3::from(self.center_of_gravity),
            sensor_to_tcp,
            ..SensorCalibration::default()
        }
    }

    /// A reading (sensor frame) with the sensor at `sensor` (base frame) under the external
    /// force `force` [N] at `tcp` [m] (base frame), with noise from `noise` scaled by `scale`.
    pub fn reading(
        &self,
        cal: &SensorCalibration,
        sensor: &Isometry3<f64>,
        tcp: &Vector3<f64>,
        force: &Vector3<f64>,
        noise: &mut Noise,
        scale: f64,
    ) -> Vector6 {
        let r_inv = sensor.rotation.inverse();
        let f = r_inv * force;
        let m = r_inv * (tcp - sensor.translation.vector).cross(force);
        let mut w =
            Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z) + cal.unloaded_reading(&sensor.rotation);
        for (k, v) in w.iter_mut().enumerate() {
            *v += scale * self.noise[usize::from(k >= 3)] * noise.gauss();
        }
        w
    }
}

/// The milling scenario's settings.
#[derive(Debug, Clone, Serialize)]
pub struct MillingOptions {
    /// The arm.
    pub arm: ArmParams,
    /// The sensor.
    pub sensor: SensorParams,
    /// Start of the groove (tool point) [m]; the groove runs along +x.
    pub start: [f64; 3],
    /// Feed speed [m/s] (paper: 25 mm/s).
    pub feed: f64,
    /// Process force while cutting [N], base frame (paper: 546 N in the xy plane).
    pub force: [f64; 3],
    /// Standstill before the motion [s].
    pub settle: f64,
    /// Acceleration ramp to the feed speed [s].
    pub ramp: f64,
    /// Travel from reaching the feed to cutter entry [s].
    pub approach: f64,
    /// Cutting time [s].
    pub cut: f64,
    /// Travel after cutter exit [s].
    pub runout: f64,
    /// Rise (and fall) time of the force at entry and exit [s]: the cutter's engagement, 0.1 s
    /// = 2.5 mm of travel at 25 mm/s.
    pub force_rise: f64,
    /// Control cycle [s] (paper: 4 ms, KUKA RSI).
    pub cycle: f64,
    /// Transport delay of a correction into the servos [cycles].
    pub delay_cycles: usize,
    /// Servo lag time constant for corrections [s].
    pub servo_tau: f64,
    /// Lead of the offline force estimate over the real force [s] (paper Fig. 3: ~40 ms).
    pub estimate_lead: f64,
    /// Relative error of the offline estimate (0.1 = 10 % too large).
    pub estimate_error: f64,
    /// Pilot control `(threshold [N], ramp [s])` (paper: 150 N, 80 ms).
    pub pilot: (f64, f64),
    /// Physics step [s] (0.5 ms; tests use 2 ms).
    pub dt: f64,
    /// Static test loads for the stiffness identification [N].
    pub id_load: f64,
    /// Number of poses for the stiffness identification (1..=3).
    pub id_poses: usize,
    /// Hold time of each static load before reading [s].
    pub id_hold: f64,
    /// Noise of the frame-pair rotation measurements [rad] and TCP deflections [m].
    pub id_noise: [f64; 2],
    /// Seed of all noise.
    pub seed: u64,
}

impl Default for MillingOptions {
    fn default() -> Self {
        Self {
            arm: ArmParams::default(),
            sensor: SensorParams::default(),
            start: [1.05, -0.15, 0.1],
            feed: 0.025,
            force: [-386.1, 386.1, -60.0],
            settle: 0.1,
            ramp: 0.2,
            approach: 0.3,
            cut: 1.2,
            runout: 0.4,
            force_rise: 0.1,
            cycle: 0.004,
            delay_cycles: 2,
            servo_tau: 0.012,
            estimate_lead: 0.04,
            estimate_error: 0.1,
            pilot: (150.0, 0.08),
            dt: DT,
            id_load: 800.0,
            id_poses: 3,
            id_hold: 0.2,
            id_noise: [2.0e-6, 2.0e-6],
            seed: 6,
        }
    }
}

impl MillingOptions {
    /// A short scenario for tests (seconds in a debug build): 2 ms physics step, shorter
    /// approach, cut and run-out, one identification pose with shorter holds, noise-free
    /// identification.
    pub fn short() -> Self {
        Self {
            settle: 0.02,
            ramp: 0.05,
            approach: 0.1,
            cut: 0.35,
            runout: 0.2,
            dt: 0.002,
            id_poses: 1,
            id_hold: 0.12,
            id_noise: [0.0, 0.0],
            ..Self::default()
        }
    }

    /// Cutter entry time [s].
    pub fn t_entry(&self) -> f64 {
        self.settle + self.ramp + self.approach
    }

    /// Cutter exit time [s].
    pub fn t_exit(&self) -> f64 {
        self.t_entry() + self.cut
    }

    /// End of the run [s].
    pub fn t_end(&self) -> f64 {
        self.t_exit() + self.runout
    }

    /// Nominal tool point and velocity at time `t`: standstill, a (1 - cos) ramp to the feed,
    /// then constant feed along +x.
    pub fn nominal(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let start = Vector3::from(self.start);
        let tm = t - self.settle;
        let (s, v) = if tm <= 0.0 {
            (0.0, 0.0)
        } else if tm < self.ramp {
            let w = core::f64::consts::PI / self.ramp;
            (
                0.5 * self.feed * (tm - (w * tm).sin() / w),
                0.5 * self.feed * (1.0 - (w * tm).cos()),
            )
        } else {
            (
                0.5 * self.feed * self.ramp + self.feed * (tm - self.ramp),
                self.feed,
            )
        };
        (start + Vector3::x() * s, Vector3::x() * v)
    }

    /// The real process force at time `t` [N]: smooth steps at entry and exit.
    pub fn process_force(&self, t: f64) -> Vector3<f64> {
        let smooth = |x: f64| {
            let x = (x / self.force_rise.max(1e-9)).clamp(0.0, 1.0);
            x * x * (3.0 - 2.0 * x)
        };
        let level = smooth(t - self.t_entry()) - smooth(t - self.t_exit());
        Vector3::from(self.force) * level
    }

    /// The offline estimate: the real force `estimate_lead` earlier and `estimate_error` off.
    pub fn estimated_force(&self, t: f64) -> Vector3<f64> {
        self.process_force(t + self.estimate_lead) * (1.0 + self.estimate_error)
    }
}

/// Which compensation a run uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Mode {
    /// No compensation.
    Uncompensated,
    /// Online compensation with measured forces (pilot off).
    Cartesian,
    /// Online compensation with pilot control from the offline estimate.
    Pilot,
    /// As `Cartesian`, but with an empty sensor calibration (offsets and tool weight not
    /// removed): shows why the sensor identification matters.
    Uncalibrated,
}

impl Mode {
    /// Short name for topics and files.
    pub fn label(self) -> &'static str {
        match self {
            Self::Uncompensated => "uncompensated",
            Self::Cartesian => "cartesian",
            Self::Pilot => "pilot",
            Self::Uncalibrated => "uncalibrated",
        }
    }
}

/// One control cycle of a run.
#[derive(Debug, Clone, Serialize)]
pub struct Sample {
    /// Time [s].
    pub t: f64,
    /// Nominal tool point [m].
    pub nominal: [f64; 3],
    /// Simulated tool point [m].
    pub actual: [f64; 3],
    /// Commanded tool point (nominal + correction) [m].
    pub commanded: [f64; 3],
    /// Motor angles [rad].
    pub q_motor: [f64; JOINTS],
    /// True process force [N].
    pub force_true: [f64; 3],
    /// Raw sensor reading (sensor frame) [N, N m].
    pub force_measured: [f64; 6],
    /// Filtered, compensated TCP wrench (base frame) [N, N m].
    pub force_filtered: [f64; 6],
    /// Wrench fed to the model (after pilot control) [N, N m].
    pub force_used: [f64; 6],
    /// Correction `[dp; dr]` [m, rad].
    pub correction: [f64; 6],
    /// Pilot weight of the estimate.
    pub pilot_weight: f64,
    /// Distance of the tool point from the nominal line (across the feed) [mm].
    pub error_mm: f64,
}

/// Path-error metrics of a run [mm].
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Metrics {
    /// Max deviation from cutter entry (start of the force rise) to 0.1 s after the force
    /// has fallen at exit.
    pub max_mm: f64,
    /// RMS deviation over the same window.
    pub rms_mm: f64,
    /// Max deviation from 0.1 s after the force has risen to exit (steady cutting).
    pub steady_max_mm: f64,
    /// Max deviation around entry (from 0.1 s before to 0.1 s after the force has risen).
    pub entry_max_mm: f64,
    /// Max deviation around exit (from 0.1 s before to 0.1 s after the force has fallen).
    pub exit_max_mm: f64,
}

/// A finished run.
#[derive(Debug, Clone, Serialize)]
pub struct Run {
    /// The compensation used.
    pub mode: Mode,
    /// Errors.
    pub metrics: Metrics,
    /// Per-cycle log.
    pub samples: Vec<Sample>,
}

/// Identification of one joint's stiffness.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct JointEstimate {
    /// Joint index (0 = yaw).
    pub joint: usize,
    /// True stiffness [N m/rad].
    pub k_true: f64,
    /// From frame-pair rotations [N m/rad].
    pub k_frames: f64,
    /// Its standard error [N m/rad].
    pub se_frames: f64,
    /// From TCP deflections (translation only) [N m/rad].
    pub k_tcp: f64,
    /// Its standard error [N m/rad].
    pub se_tcp: f64,
}

/// Result of the sensor identification.
#[derive(Debug, Clone, Serialize)]
pub struct SensorEstimate {
    /// Orientations used.
    pub orientations: usize,
    /// True and identified force offset [N].
    pub force_offset: ([f64; 3], [f64; 3]),
    /// True and identified moment offset [N m].
    pub moment_offset: ([f64; 3], [f64; 3]),
    /// True and identified weight [N].
    pub weight: (f64, f64),
    /// True and identified centre of gravity [m].
    pub center_of_gravity: ([f64; 3], [f64; 3]),
    /// RMS force residual [N].
    pub force_rms: f64,
}

/// Everything the scenario produced.
#[derive(Debug, Clone, Serialize)]
pub struct MillingResult {
    /// Settings.
    pub options: MillingOptions,
    /// Stiffness identification per joint.
    pub stiffness: Vec<JointEstimate>,
    /// Sensor identification.
    pub sensor: SensorEstimate,
    /// The runs: uncompensated, Cartesian, pilot, uncalibrated.
    pub runs: Vec<Run>,
    /// Simulated time of the runs and the static tests [s].
    pub sim_seconds: f64,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
}

fn stiffness_of(id: &StiffnessIdentification, joint: usize) -> (f64, f64) {
    id.axes
        .iter()
        .find(|a| a.spring == joint)
        .map(|a| match a.compliance {
            Some(c) if c > 0.0 => (1.0 / c, a.std_error / (c * c)),
            _ => (f64::NAN, f64::NAN),
        })
        .unwrap_or((f64::NAN, f64::NAN))
}

/// Static tests in rapier: at several poses, loads of `id_load` along ±x, ±y, ±z at the tool
/// point with the motors locked; frame-pair rotations across each spring and the TCP
/// translation (loaded minus unloaded), with measurement noise; least squares for each.
pub fn identify_stiffness(opts: &MillingOptions) -> Result<Vec<JointEstimate>, SimError> {
    let arm = &opts.arm;
    // The structure of the model matters, not its values.
    let guess = vjm_model(arm, &[1.0e5; JOINTS])?;
    let poses = [
        Vector3::new(1.1, -0.2, 0.1),
        Vector3::new(1.3, 0.25, 0.3),
        Vector3::new(0.9, 0.1, -0.05),
    ];
    let loads = [
        Vector3::x(),
        -Vector3::x(),
        Vector3::y(),
        -Vector3::y(),
        Vector3::z(),
        -Vector3::z(),
    ];
    let mut noise = Noise::new(opts.seed ^ 0x1D);
    let mut qs = Vec::new();
    let mut frame_data = Vec::new(); // (pose, wrench, spring, rotation)
    let mut tcp_data = Vec::new(); // (pose, wrench, deflection)
    let hold = (opts.id_hold / opts.dt).round().max(1.0) as usize;
    let ramp = (0.03 / opts.dt).round().max(1.0) as usize;
    for (pi, p) in poses.iter().take(opts.id_poses.clamp(1, 3)).enumerate() {
        let q = arm.ik(p);
        qs.push(q);
        // Critically damped (about) so that each load settles quickly.
        let mut sim = FlexArm::new(arm, &q, 4.0, opts.dt)?;
        sim.step(&q, &Vector3::zeros());
        let rot0 = sim.spring_rotations(&q);
        let tcp0 = sim.tcp();
        let mut prev = Vector3::zeros();
        for dir in &loads {
            let target = dir * opts.id_load;
            for k in 0..ramp {
                let s = (k + 1) as f64 / ramp as f64;
                sim.step(&q, &(prev + (target - prev) * s));
            }
            for _ in 0..hold {
                sim.step(&q, &target);
            }
            prev = target;
            let rot = sim.spring_rotations(&q);
            let w = Vector6::new(target.x, target.y, target.z, 0.0, 0.0, 0.0);
            for (j, (r1, r0)) in rot.iter().zip(&rot0).enumerate() {
                let mut r = r1 - r0;
                for v in r.iter_mut() {
                    *v += opts.id_noise[0] * noise.gauss();
                }
                frame_data.push((pi, w, j, r));
            }
            let mut d = sim.tcp() - tcp0;
            for v in d.iter_mut() {
                *v += opts.id_noise[1] * noise.gauss();
            }
            tcp_data.push((pi, w, Vector6::new(d.x, d.y, d.z, 0.0, 0.0, 0.0)));
        }
    }
    let frames: Vec<FrameMeasurement<'_>> = frame_data
        .iter()
        .map(|(pi, w, j, r)| FrameMeasurement {
            q: &qs[*pi],
            wrench: *w,
            spring: *j,
            rotation: *r,
        })
        .collect();
    let tcps: Vec<TcpMeasurement<'_>> = tcp_data
        .iter()
        .map(|(pi, w, d)| TcpMeasurement {
            q: &qs[*pi],
            wrench: *w,
            deflection: *d,
            translation_only: true,
        })
        .collect();
    let e = |e: deflect_core::identification::IdentificationError| {
        SimError::new(format!("identification: {e}"))
    };
    let by_frames = identify_from_frames(&guess, &frames, false).map_err(e)?;
    let by_tcp = identify_from_tcp(&guess, &tcps, false).map_err(e)?;
    Ok((0..JOINTS)
        .map(|j| {
            let (k_frames, se_frames) = stiffness_of(&by_frames, j);
            let (k_tcp, se_tcp) = stiffness_of(&by_tcp, j);
            JointEstimate {
                joint: j,
                k_true: arm.stiffness[j],
                k_frames,
                se_frames,
                k_tcp,
                se_tcp,
            }
        })
        .collect())
}

/// Sensor identification from unloaded readings (each the mean of 50 noisy samples) at
/// orientations reached by the arm's yaw and wrist joints.
pub fn identify_sensor_calibration(
    opts: &MillingOptions,
) -> Result<(SensorCalibration, SensorEstimate), SimError> {
    let arm = &opts.arm;
    let model = vjm_model(arm, &arm.stiffness)?;
    let mut data = Data::new(&model);
    let s2t = arm.sensor_to_tcp();
    let truth = opts.sensor.calibration(s2t);
    let mut noise = Noise::new(opts.seed ^ 0x5E);
    let base = arm.ik(&Vector3::new(1.1, 0.0, 0.2));
    let mut orientations = Vec::new();
    let mut readings = Vec::new();
    for yaw in [-0.7, 0.0, 0.7] {
        for wrist in [-1.2, -0.4, 0.4, 1.2] {
            let q = [yaw, base[1], base[2], base[3] + wrist];
            let tcp = vjm::forward(&model, &mut data, &q)
                .map_err(|e| SimError::new(format!("sensor poses: {e}")))?;
            let sensor = tcp * s2t.inverse();
            let n = 50;
            let mut mean = Vector6::zeros();
            for _ in 0..n {
                mean += opts.sensor.reading(
                    &truth,
                    &sensor,
                    &tcp.translation.vector,
                    &Vector3::zeros(),
                    &mut noise,
                    1.0,
                );
            }
            orientations.push(sensor.rotation);
            readings.push(mean / n as f64);
        }
    }
    let id = identify_sensor(&orientations, &readings, false, s2t)
        .map_err(|e| SimError::new(format!("sensor identification: {e}")))?;
    let c = &id.calibration;
    let arr = |v: &Vector3<f64>| [v.x, v.y, v.z];
    let est = SensorEstimate {
        orientations: orientations.len(),
        force_offset: (opts.sensor.force_offset, arr(&c.force_offset)),
        moment_offset: (opts.sensor.moment_offset, arr(&c.moment_offset)),
        weight: (opts.sensor.weight, c.weight),
        center_of_gravity: (opts.sensor.center_of_gravity, arr(&c.center_of_gravity)),
        force_rms: id.force_rms,
    };
    Ok((id.calibration, est))
}

fn metrics(opts: &MillingOptions, samples: &[Sample]) -> Metrics {
    let (te, tx) = (opts.t_entry(), opts.t_exit());
    let max_in = |a: f64, b: f64| {
        samples
            .iter()
            .filter(|s| s.t >= a && s.t <= b)
            .map(|s| s.error_mm)
            .fold(0.0, f64::max)
    };
    let win: Vec<f64> = samples
        .iter()
        .filter(|s| s.t >= te && s.t <= tx + opts.force_rise + 0.1)
        .map(|s| s.error_mm)
        .collect();
    let rms = (win.iter().map(|e| e * e).sum::<f64>() / win.len().max(1) as f64).sqrt();
    Metrics {
        max_mm: max_in(te, tx + opts.force_rise + 0.1),
        rms_mm: rms,
        steady_max_mm: max_in(te + opts.force_rise + 0.1, tx),
        entry_max_mm: max_in(te - 0.1, te + opts.force_rise + 0.1),
        exit_max_mm: max_in(tx - 0.1, tx + opts.force_rise + 0.1),
    }
}

/// One run of the groove with `mode`, the compensator using `model` (identified stiffnesses)
/// and `calibration` (identified sensor).
pub fn run(
    opts: &MillingOptions,
    mode: Mode,
    model: &Model,
    calibration: &SensorCalibration,
) -> Result<Run, SimError> {
    let arm = &opts.arm;
    let truth = opts.sensor.calibration(arm.sensor_to_tcp());
    let (p0, _) = opts.nominal(0.0);
    let q0 = arm.ik(&p0);
    let mut sim = FlexArm::new(arm, &q0, 1.0, opts.dt)?;
    let mut comp = match mode {
        Mode::Uncompensated => None,
        Mode::Cartesian | Mode::Pilot | Mode::Uncalibrated => {
            let cal = if mode == Mode::Uncalibrated {
                SensorCalibration {
                    sensor_to_tcp: calibration.sensor_to_tcp,
                    ..SensorCalibration::default()
                }
            } else {
                *calibration
            };
            let mut cfg = CompensatorConfig::paper(opts.cycle, cal);
            cfg.pilot = (mode == Mode::Pilot).then_some(opts.pilot);
            Some(
                OnlineCompensator::new(model, cfg)
                    .map_err(|e| SimError::new(format!("compensator: {e}")))?,
            )
        }
    };
    let mut noise = Noise::new(opts.seed);
    let dt = opts.dt;
    let sub = ((opts.cycle / dt).round() as usize).max(1);
    let cycles = (opts.t_end() / (sub as f64 * dt)).ceil() as usize;
    // Corrections (joint offsets) in flight to the servos, and the servo's lagged offset.
    let mut queue: std::collections::VecDeque<[f64; JOINTS]> =
        std::iter::repeat_n([0.0; JOINTS], opts.delay_cycles).collect();
    let mut lagged = [0.0; JOINTS];
    let alpha = dt / (opts.servo_tau + dt);
    let mut dq_target = [0.0; JOINTS];
    let mut samples = Vec::with_capacity(cycles);
    let mut q_motor = q0;
    let mut step_index = 0usize;
    for c in 0..cycles {
        let t = c as f64 * sub as f64 * dt;
        let (p_nom, v_nom) = opts.nominal(t);
        let q_nom = arm.ik(&p_nom);
        // The sensor is read at the start of the cycle.
        let f_true = opts.process_force(t);
        let sensor = sim.sensor_pose();
        let tcp = sim.tcp();
        let reading = opts
            .sensor
            .reading(&truth, &sensor, &tcp, &f_true, &mut noise, 1.0);
        let mut sample = Sample {
            t,
            nominal: p_nom.into(),
            actual: tcp.into(),
            commanded: p_nom.into(),
            q_motor,
            force_true: f_true.into(),
            force_measured: reading.into(),
            force_filtered: [0.0; 6],
            force_used: [0.0; 6],
            correction: [0.0; 6],
            pilot_weight: 0.0,
            error_mm: ((tcp.y - p_nom.y).powi(2) + (tcp.z - p_nom.z).powi(2)).sqrt() * 1e3,
        };
        if let Some(comp) = comp.as_mut() {
            let f_est = opts.estimated_force(t);
            let est = Vector6::new(f_est.x, f_est.y, f_est.z, 0.0, 0.0, 0.0);
            let out = comp
                .step(model, &q_motor, &reading, Some(&est), &v_nom)
                .map_err(|e| SimError::new(format!("compensator step: {e}")))?;
            let target = p_nom + out.correction.fixed_rows::<3>(0).into_owned();
            let q_cmd = arm.ik(&target);
            dq_target = core::array::from_fn(|j| q_cmd[j] - q_nom[j]);
            sample.commanded = target.into();
            sample.force_filtered = out.measured_wrench.into();
            sample.force_used = out.wrench.into();
            sample.correction = out.correction.into();
            sample.pilot_weight = out.pilot_weight;
        }
        samples.push(sample);
        queue.push_back(dq_target);
        let dq_servo = queue.pop_front().unwrap_or([0.0; JOINTS]);
        for _ in 0..sub {
            let ts = step_index as f64 * dt;
            let (p, _) = opts.nominal(ts);
            let qn = arm.ik(&p);
            for (((l, m), d), n) in lagged.iter_mut().zip(&mut q_motor).zip(&dq_servo).zip(&qn) {
                *l += alpha * (d - *l);
                *m = n + *l;
            }
            sim.step(&q_motor, &opts.process_force(ts));
            step_index += 1;
        }
    }
    Ok(Run {
        mode,
        metrics: metrics(opts, &samples),
        samples,
    })
}

/// The whole scenario: identification of stiffnesses and sensor, then the three runs with the
/// identified values (and a fourth, Cartesian compensation without sensor calibration).
pub fn milling(opts: &MillingOptions) -> Result<MillingResult, SimError> {
    let start = std::time::Instant::now();
    let stiffness = identify_stiffness(opts)?;
    let mut k = [0.0; JOINTS];
    for (dst, e) in k.iter_mut().zip(&stiffness) {
        *dst = if e.k_frames.is_finite() && e.k_frames > 0.0 {
            e.k_frames
        } else {
            e.k_true
        };
    }
    let model = vjm_model(&opts.arm, &k)?;
    let (calibration, sensor) = identify_sensor_calibration(opts)?;
    let mut runs = Vec::new();
    for mode in [
        Mode::Uncompensated,
        Mode::Cartesian,
        Mode::Pilot,
        Mode::Uncalibrated,
    ] {
        runs.push(run(opts, mode, &model, &calibration)?);
    }
    Ok(MillingResult {
        options: opts.clone(),
        stiffness,
        sensor,
        runs,
        sim_seconds: opts.t_end() * 4.0
            + opts.id_poses.clamp(1, 3) as f64 * 6.0 * (opts.id_hold + 0.03),
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}
