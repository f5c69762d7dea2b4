//! `contour` scenario: force-feedback contour tracing of unknown planar objects and shape
//! recovery with drive-train compensation, after "Shape recovery from robot contour tracking
//! with force feedback" (`shared/papers/000_5ce4550bc71d85da.txt`, sections 2-3, Figures 6-8).
//!
//! * The arm: a planar 2R arm in the horizontal plane (joint axes vertical, so gravity loads
//!   no joint), two links as rapier3d-f64 multibody bodies on revolute-z joints. Each joint is
//!   driven by an ideal position servo (the motor angle follows the command on a cosine ramp)
//!   through a drive train that rapier's joint springs cannot express: a spring with a dead
//!   zone of `+-backlash` (total play `2 backlash`) plus a relative viscous damper, computed
//!   per physics step and applied as a torque pair on the link and its parent.
//!   `tau = K dz(q_motor - q_link) + c (w_motor - w_link)`.
//! * Contact: a penalty force computed from the tool point's penetration into the objects
//!   (spring `k_contact`, damper `c_contact` on the inward velocity, never pulling), no
//!   friction; only the tool point touches (the links pass above the objects).
//! * The force sensor at the tool: the mean contact force over the last `average` seconds of
//!   each settle, plus a constant bias and seeded Gaussian noise on every physics-step sample.
//! * [`deflect_core::contour::ContourTracer`] consumes one settled reading per step; its
//!   command goes through the closed-form IK to the motors. On each contact sample the motor
//!   readings are recorded; the shape is recovered raw (FK of the motor readings) and
//!   compensated (Eq. 10, [`deflect_core::drivetrain::correct_joints`] with the arm's
//!   stiffness, backlash and masses and the sensed force).

use deflect_core::contour::{
    ContourTracer, TraceDirection, TracerConfig, TracerState, TracerStats, shape,
};
use deflect_core::drivetrain::{DriveTrain, LinkMasses, cartesian_stiffness_xy, correct_joints};
use deflect_core::vjm::Data;
use deflect_core::{Model, ModelBuilder};
use nalgebra::{Isometry3, Matrix2, Vector2, Vector3, Vector6};
use rapier3d_f64::prelude::*;
use serde::Serialize;

use crate::SimError;
use crate::serial::insert_planar_chain;

fn err<E: core::fmt::Display>(e: E) -> SimError {
    SimError::new(format!("contour: {e}"))
}

/// Physics time step of the contour scene [s].
pub const DT: f64 = 0.5e-3;

/// The planar 2R arm with compliant, backlashed joints.
#[derive(Debug, Clone, Serialize)]
pub struct ArmParams {
    /// Link lengths [m] (shoulder-elbow, elbow-tool point).
    pub lengths: [f64; 2],
    /// Link masses [kg] (uniform rods).
    pub masses: [f64; 2],
    /// Tool and sensor mass at the tool point [kg].
    pub tool_mass: f64,
    /// Drive-train stiffness `K_i` [N m/rad].
    pub stiffness: [f64; 2],
    /// Backlash `theta_b_i` [rad]: the link moves freely within `+-theta_b` of the motor.
    pub backlash: [f64; 2],
    /// Relative motor-link damping [N m s/rad].
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
    /// Tool point of link angles `q` (relative, q2 from link 1) [m].
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

    /// Closed-form IK, elbow angle in [0, pi] (clamped at the workspace boundary).
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

    /// The drive train for Eq. 10: stiffness, backlash, the link and tool masses (their
    /// gravity torques vanish for vertical joint axes, but they are part of the model), a
    /// 0.02 N m deadband on the backlash sign against sensor noise.
    pub fn drive_train(&self, model: &Model) -> Result<DriveTrain, SimError> {
        let [l1, l2] = self.lengths;
        let masses = LinkMasses::new()
            .with(0, self.masses[0], Vector3::new(0.5 * l1, 0.0, 0.0))
            .and_then(|m| m.with(1, self.masses[1], Vector3::new(0.5 * l2, 0.0, 0.0)))
            .and_then(|m| m.with(1, self.tool_mass, Vector3::new(l2, 0.0, 0.0)))
            .map_err(err)?;
        DriveTrain::new(model, &self.stiffness, &self.backlash)
            .and_then(|d| d.with_masses(masses))
            .and_then(|d| d.with_torque_deadband(0.02))
            .map_err(err)
    }
}

/// An unknown rigid object in the plane.
#[derive(Debug, Clone, Serialize)]
pub enum Outline {
    /// A disk: centre [m], radius [m].
    Circle {
        /// Centre [m].
        center: [f64; 2],
        /// Radius [m].
        radius: f64,
    },
    /// A closed polygon (convex or not), counter-clockwise vertices [m].
    Polygon {
        /// Vertices [m].
        vertices: Vec<[f64; 2]>,
    },
}

fn v2(p: &[f64; 2]) -> Vector2<f64> {
    Vector2::new(p[0], p[1])
}

impl Outline {
    fn verts(vertices: &[[f64; 2]]) -> Vec<Vector2<f64>> {
        vertices.iter().map(v2).collect()
    }

    /// Distance of `p` to the outline [m].
    pub fn distance(&self, p: &Vector2<f64>) -> f64 {
        match self {
            Self::Circle { center, radius } => shape::distance_to_circle(p, &v2(center), *radius),
            Self::Polygon { vertices } => shape::distance_to_polygon(p, &Self::verts(vertices)),
        }
    }

    /// Signed distance [m]: positive outside, negative inside.
    pub fn signed_distance(&self, p: &Vector2<f64>) -> f64 {
        match self {
            Self::Circle { center, radius } => (p - v2(center)).norm() - radius,
            Self::Polygon { vertices } => {
                let v = Self::verts(vertices);
                let d = shape::distance_to_polygon(p, &v);
                if shape::inside_polygon(p, &v) { -d } else { d }
            }
        }
    }

    /// For a point inside: penetration depth [m] and the unit direction into the object (the
    /// direction of the force the tool exerts on it).
    pub fn penetration(&self, p: &Vector2<f64>) -> Option<(f64, Vector2<f64>)> {
        match self {
            Self::Circle { center, radius } => {
                let d = p - v2(center);
                let n = d.norm();
                (n < *radius && n > 0.0).then(|| (radius - n, -d / n))
            }
            Self::Polygon { vertices } => {
                let v = Self::verts(vertices);
                if !shape::inside_polygon(p, &v) {
                    return None;
                }
                let mut best = (f64::INFINITY, Vector2::zeros());
                for i in 0..v.len() {
                    let (a, b) = (v[i], v[(i + 1) % v.len()]);
                    let ab = b - a;
                    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                    let q = a + ab * t;
                    let d = (p - q).norm();
                    if d < best.0 {
                        best = (d, q);
                    }
                }
                let (d, q) = best;
                (d > 0.0).then(|| (d, (p - q) / d))
            }
        }
    }

    /// Points along the outline for plots [m] (closed: the first point repeats).
    pub fn polyline(&self) -> Vec<Vector2<f64>> {
        match self {
            Self::Circle { center, radius } => (0..=180)
                .map(|k| {
                    let a = k as f64 * core::f64::consts::TAU / 180.0;
                    v2(center) + Vector2::new(a.cos(), a.sin()) * *radius
                })
                .collect(),
            Self::Polygon { vertices } => {
                let mut v = Self::verts(vertices);
                if let Some(f) = v.first().copied() {
                    v.push(f);
                }
                v
            }
        }
    }

    /// Perimeter [m].
    pub fn perimeter(&self) -> f64 {
        match self {
            Self::Circle { radius, .. } => core::f64::consts::TAU * radius,
            Self::Polygon { .. } => self
                .polyline()
                .windows(2)
                .map(|w| (w[1] - w[0]).norm())
                .sum(),
        }
    }
}

/// One object to trace: its outline and where the tracer starts (out of contact), approaching
/// along +x.
#[derive(Debug, Clone, Serialize)]
pub struct ObjectSpec {
    /// Short name ("circle", "rectangle", "l_shape").
    pub name: String,
    /// The true outline.
    pub outline: Outline,
    /// Start point of the tool [m].
    pub start: [f64; 2],
}

/// The default objects: a disk of 60 mm radius, a 160 x 110 mm rectangle with sharp corners
/// and a non-convex L (150 x 150 mm, arms 70 mm wide), spread over the arm's workspace.
pub fn default_objects() -> Vec<ObjectSpec> {
    vec![
        ObjectSpec {
            name: "circle".into(),
            outline: Outline::Circle {
                center: [0.60, 0.30],
                radius: 0.06,
            },
            start: [0.50, 0.30],
        },
        ObjectSpec {
            name: "rectangle".into(),
            outline: Outline::Polygon {
                vertices: vec![[0.50, -0.06], [0.66, -0.06], [0.66, 0.05], [0.50, 0.05]],
            },
            start: [0.46, 0.0],
        },
        ObjectSpec {
            name: "l_shape".into(),
            outline: Outline::Polygon {
                vertices: vec![
                    [0.45, -0.42],
                    [0.60, -0.42],
                    [0.60, -0.35],
                    [0.52, -0.35],
                    [0.52, -0.27],
                    [0.45, -0.27],
                ],
            },
            start: [0.41, -0.38],
        },
    ]
}

/// Settings of a trace.
#[derive(Debug, Clone, Serialize)]
pub struct TraceOptions {
    /// The arm.
    pub arm: ArmParams,
    /// Tracer step along the edge `Delta r` [m].
    pub step: f64,
    /// Approach step [m].
    pub approach_step: f64,
    /// Contact threshold `F_contact_min` [N].
    pub contact_force: f64,
    /// Jam force `F_jam_min` [N].
    pub jam_force: f64,
    /// Target force [N].
    pub target_force: f64,
    /// Motor ramp time per tracer step [s].
    pub ramp: f64,
    /// Settling time after the ramp [s].
    pub settle: f64,
    /// Sensor averaging window at the end of the settle [s].
    pub average: f64,
    /// Sensor noise, standard deviation per sample and axis [N].
    pub noise: f64,
    /// Sensor bias [N].
    pub bias: [f64; 2],
    /// Seed of the sensor noise.
    pub seed: u64,
    /// Contact penalty stiffness [N/m].
    pub k_contact: f64,
    /// Contact penalty damping [N s/m].
    pub c_contact: f64,
    /// Tracer steps after which a trace is stopped.
    pub max_steps: usize,
    /// Readings averaged for the sensor bias before the approach.
    pub bias_samples: usize,
}

impl Default for TraceOptions {
    fn default() -> Self {
        Self {
            arm: ArmParams::default(),
            step: 1.5e-3,
            approach_step: 1.0e-3,
            contact_force: 1.5,
            jam_force: 30.0,
            target_force: 6.0,
            ramp: 0.020,
            settle: 0.060,
            average: 0.010,
            noise: 0.3,
            bias: [0.7, -0.4],
            seed: 7,
            k_contact: 5.0e5,
            c_contact: 150.0,
            max_steps: 4000,
            bias_samples: 10,
        }
    }
}

/// Seeded Gaussian noise (SplitMix64 + Box-Muller).
#[derive(Debug, Clone)]
struct Noise(u64);

impl Noise {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn gauss(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (core::f64::consts::TAU * u2).cos()
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
    /// Largest contact force of any physics step [N].
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
    /// [N/m] and damping `c_contact` [N s/m].
    pub fn new(
        params: &ArmParams,
        q: &[f64; 2],
        k_contact: f64,
        c_contact: f64,
    ) -> Result<Self, SimError> {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::ZERO; // horizontal plane: gravity loads no joint
        world.integration_parameters.dt = DT;
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

    /// Link-side joint angles and rates [rad, rad/s].
    pub fn link_state(&self) -> ([f64; 2], [f64; 2]) {
        let mut q = self.q_ref;
        let mut w = [0.0; 2];
        for k in 0..2 {
            if let Some((mb, id)) = self.world.multibody_joints.get(self.joints[k]) {
                if let Some(link) = mb.link(id) {
                    q[k] += link.joint().coords()[5];
                    w[k] = mb.joint_velocity(link).get(0).copied().unwrap_or(0.0);
                }
            }
        }
        (q, w)
    }

    /// The tool point [m].
    pub fn tool(&self) -> Vector2<f64> {
        self.params.fk(&self.link_state().0)
    }

    /// One physics step with motor angles and rates; returns the contact force the tool exerts
    /// on the objects [N] (computed at the start of the step and applied during it).
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

/// One tracer step: the settled reading and what the tracer made of it.
#[derive(Debug, Clone, Serialize)]
pub struct Sample {
    /// Simulated time at the reading [s].
    pub t: f64,
    /// Tracer phase after the reading.
    pub state: &'static str,
    /// Position command the arm held for the reading [m].
    pub command: [f64; 2],
    /// True tool point at the reading [m].
    pub tool_actual: [f64; 2],
    /// Sensed force, raw (bias and noise included) [N].
    pub force_sensed: [f64; 2],
    /// Bias-removed sensed force the tracer used [N].
    pub force: [f64; 2],
    /// True mean contact force over the averaging window [N].
    pub force_true: [f64; 2],
    /// Motor-side joint readings [rad].
    pub q_motor: [f64; 2],
    /// Link-side joint angles (simulation truth) [rad].
    pub q_link: [f64; 2],
    /// A contact sample: the shape points below are recorded.
    pub contact: bool,
    /// FK of the motor readings [m] (contact samples).
    pub raw: Option<[f64; 2]>,
    /// FK of the Eq. 10 corrected joints [m] (contact samples).
    pub compensated: Option<[f64; 2]>,
}

/// RMS and max distance to the true outline [mm].
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ShapeErr {
    /// RMS [mm].
    pub rms_mm: f64,
    /// Max [mm].
    pub max_mm: f64,
    /// Points.
    pub count: usize,
}

/// Result of tracing one object.
#[derive(Debug, Clone, Serialize)]
pub struct ContourRun {
    /// Object name.
    pub name: String,
    /// The object.
    pub outline: Outline,
    /// Final tracer state ("done" on success).
    pub state: &'static str,
    /// Tracer steps (readings), including init and approach.
    pub tracer_steps: usize,
    /// Contact samples recorded.
    pub contacts: usize,
    /// Edge directions from Eq. 21 / normal to the force.
    pub eq21_steps: usize,
    /// Edge directions normal to the force.
    pub normal_steps: usize,
    /// Readings out of contact after the first contact (each one a bisected recovery move).
    pub contact_losses: usize,
    /// Longest run of consecutive readings out of contact.
    pub longest_loss: usize,
    /// Readings at or above the jam force.
    pub jams: usize,
    /// Moves shortened by the jam guard.
    pub shortened: usize,
    /// Largest settled true contact force [N].
    pub max_force: f64,
    /// Largest contact force of any physics step (transients included) [N].
    pub peak_force: f64,
    /// Path length of the tracer's tool estimates [m] and the true perimeter [m].
    pub path_length: f64,
    /// True perimeter [m].
    pub perimeter: f64,
    /// Shape error of the raw recovered contour.
    pub raw: ShapeErr,
    /// Shape error of the compensated (Eq. 10) contour.
    pub compensated: ShapeErr,
    /// Distance of the true tool points (contact samples) to the outline: the floor set by
    /// the penalty contact's penetration.
    pub actual: ShapeErr,
    /// Simulated time [s].
    pub sim_time: f64,
    /// Physics steps.
    pub physics_steps: usize,
    /// Wall time [s].
    pub wall: f64,
    /// Every tracer step.
    pub samples: Vec<Sample>,
}

fn shape_err<'a>(outline: &Outline, pts: impl IntoIterator<Item = &'a Vector2<f64>>) -> ShapeErr {
    let e = shape::shape_error(pts, |p| outline.distance(p));
    ShapeErr {
        rms_mm: e.rms * 1e3,
        max_mm: e.max * 1e3,
        count: e.count,
    }
}

fn arr(v: &Vector2<f64>) -> [f64; 2] {
    [v.x, v.y]
}

/// Traces `object` counter-clockwise with the [`ContourTracer`] and recovers its shape.
pub fn trace(object: &ObjectSpec, opts: &TraceOptions) -> Result<ContourRun, SimError> {
    let wall = std::time::Instant::now();
    let arm = &opts.arm;
    let model = arm.model()?;
    let drive = arm.drive_train(&model)?;
    let mut data = Data::new(&model);
    let mut cfg = TracerConfig::new(opts.step, opts.contact_force, opts.jam_force);
    cfg.target_force = opts.target_force;
    cfg.approach_step = opts.approach_step;
    cfg.direction = TraceDirection::CounterClockwise;
    cfg.max_steps = opts.max_steps;
    cfg.bias_samples = opts.bias_samples.max(1);
    let start = v2(&object.start);
    let mut q_cmd = arm.ik(&start);
    let k0 = cartesian_stiffness_xy(&model, &mut data, &drive, &q_cmd).map_err(err)?;
    let mut tracer = ContourTracer::new(cfg, &k0).map_err(err)?;
    let mut sim = ArmSim::new(arm, &q_cmd, opts.k_contact, opts.c_contact)?;
    let mut noise = Noise(opts.seed ^ 0x5EED_C0DE);
    let bias = v2(&opts.bias);
    let objects = [&object.outline];
    let n_ramp = ((opts.ramp / DT).round() as usize).max(1);
    let n_settle = (opts.settle / DT).round() as usize;
    let n_avg = ((opts.average / DT).round() as usize).clamp(1, n_ramp + n_settle);
    let mut cmd = start;
    let mut q_prev = q_cmd;
    let mut samples = Vec::new();
    let (mut raw, mut comp, mut actual) = (Vec::new(), Vec::new(), Vec::new());
    let mut max_force = 0.0f64;
    let mut t = 0.0;
    let mut steps = 0;
    let state = loop {
        steps += 1;
        // Move the motors to the command on a cosine ramp, then hold and settle.
        let total = n_ramp + n_settle;
        let (mut f_true, mut f_sensed) = (Vector2::zeros(), Vector2::zeros());
        for k in 0..total {
            let (q, w) = if k < n_ramp {
                let s = (k + 1) as f64 / n_ramp as f64;
                let blend = 0.5 * (1.0 - (core::f64::consts::PI * s).cos());
                let rate = 0.5 * core::f64::consts::PI * (core::f64::consts::PI * s).sin()
                    / (n_ramp as f64 * DT);
                (
                    [
                        q_prev[0] + (q_cmd[0] - q_prev[0]) * blend,
                        q_prev[1] + (q_cmd[1] - q_prev[1]) * blend,
                    ],
                    [(q_cmd[0] - q_prev[0]) * rate, (q_cmd[1] - q_prev[1]) * rate],
                )
            } else {
                (q_cmd, [0.0; 2])
            };
            let f = sim.step(&q, &w, &objects);
            t += DT;
            if k + n_avg >= total {
                f_true += f;
                f_sensed += f + bias + Vector2::new(noise.gauss(), noise.gauss()) * opts.noise;
            }
        }
        f_true /= n_avg as f64;
        f_sensed /= n_avg as f64;
        max_force = max_force.max(f_true.norm());
        let (q_link, _) = sim.link_state();
        let tool_actual = arm.fk(&q_link);
        // The motor readings are exact (the servo holds the command at rest).
        let q_motor = q_cmd;
        let k = cartesian_stiffness_xy(&model, &mut data, &drive, &q_motor)
            .map_err(|e| err(format!("{e} at t {t} q {q_motor:?} cmd {cmd:?}")))?;
        tracer.set_stiffness(&k).map_err(err)?;
        let out = tracer.step(&cmd, &f_sensed).map_err(err)?;
        let mut sample = Sample {
            t,
            state: out.state.name(),
            command: arr(&cmd),
            tool_actual: arr(&tool_actual),
            force_sensed: arr(&f_sensed),
            force: arr(&out.force),
            force_true: arr(&f_true),
            q_motor,
            q_link,
            contact: out.contact,
            raw: None,
            compensated: None,
        };
        if out.contact {
            let p_raw = arm.fk(&q_motor);
            let w = Vector6::new(out.force.x, out.force.y, 0.0, 0.0, 0.0, 0.0);
            let c = correct_joints(&model, &mut data, &drive, &q_motor, &w).map_err(err)?;
            let p_comp = arm.fk(&[c.q[0], c.q[1]]);
            sample.raw = Some(arr(&p_raw));
            sample.compensated = Some(arr(&p_comp));
            raw.push(p_raw);
            comp.push(p_comp);
            actual.push(tool_actual);
        }
        samples.push(sample);
        if out.state.is_finished() {
            break out.state;
        }
        if steps >= opts.max_steps + 200 {
            break TracerState::Failed(deflect_core::contour::TraceFailure::StepLimit);
        }
        cmd = out.command;
        q_prev = q_cmd;
        q_cmd = arm.ik(&cmd);
    };
    let stats: TracerStats = *tracer.stats();
    Ok(ContourRun {
        name: object.name.clone(),
        outline: object.outline.clone(),
        state: state.name(),
        tracer_steps: steps,
        contacts: stats.contacts,
        eq21_steps: stats.eq21_steps,
        normal_steps: stats.normal_steps,
        contact_losses: stats.bisections,
        longest_loss: stats.longest_loss,
        jams: stats.jams,
        shortened: stats.shortened,
        max_force,
        peak_force: sim.peak_force,
        path_length: stats.path_length,
        perimeter: object.outline.perimeter(),
        raw: shape_err(&object.outline, &raw),
        compensated: shape_err(&object.outline, &comp),
        actual: shape_err(&object.outline, &actual),
        sim_time: t,
        physics_steps: sim.physics_steps,
        wall: wall.elapsed().as_secs_f64(),
        samples,
    })
}

/// Traces every object, one thread per object up to `jobs` at a time; results in the order
/// of `objects` whatever `jobs` is.
pub fn trace_all(
    objects: &[ObjectSpec],
    opts: &TraceOptions,
    jobs: usize,
) -> Result<Vec<ContourRun>, SimError> {
    let mut out = Vec::with_capacity(objects.len());
    for chunk in objects.chunks(jobs.max(1)) {
        let results: Vec<Result<ContourRun, SimError>> = std::thread::scope(|s| {
            let handles: Vec<_> = chunk
                .iter()
                .map(|o| s.spawn(move || trace(o, opts)))
                .collect();
            handles
                .into_iter()
                .map(|h| {
                    h.join()
                        .unwrap_or_else(|_| Err(SimError::new("contour thread panicked")))
                })
                .collect()
        });
        for r in results {
            out.push(r?);
        }
    }
    Ok(out)
}
