//! Force-feedback contour tracing of an unknown planar object by a position-controlled robot,
//! after "Shape recovery from robot contour tracking with force feedback", section 3
//! (`shared/papers/000_5ce4550bc71d85da.txt`, Eq. 11-24, Figures 3-4).
//!
//! * The contact force model: a robot of xy stiffness `K` demanded to `x_d` but stopped at
//!   `x` pushes with `F = K (x_d - x)` (Eq. 11); a demanded step `D` against an edge at angle
//!   `theta_2` slides the tool by the projection of `D` on the edge (Eq. 16-17) and leaves the
//!   error `e` of Eq. 18-19, `F = K e` (Eq. 20).
//! * The edge direction from the steady-state force (Eq. 21): the tool moved by
//!   `D - K^-1 F` along the edge, so `theta_2 = atan2(D_y - [K^-1 F]_y, D_x - [K^-1 F]_x)`.
//! * [`ContourTracer`]: the algorithm of Figures 3-4 as a state machine that consumes one
//!   steady-state force reading per step and returns the next position command.
//!
//! Forces here are the force the **tool exerts on the object** (it points into the object),
//! in the xy plane of the base frame [N]; positions [m], angles [rad]. Everything is
//! allocation-free and panic-free; bad input is a [`ContourError`], a failed trace a
//! [`TracerState::Failed`] status.

use core::fmt;

use nalgebra::{ComplexField, Matrix2, RealField, Vector2};

/// A contour computation refused its input.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum ContourError {
    /// An input holds NaN or an infinity.
    NonFinite {
        /// Which input.
        what: &'static str,
    },
    /// The stiffness matrix is singular (Eq. 21 needs `K^-1`): `det / (|K|_F^2 / 2)` is
    /// below [`MIN_RECIPROCAL_CONDITION`].
    SingularStiffness {
        /// The determinant.
        det: f64,
    },
    /// The tool did not move along the edge (`|D - K^-1 F|` is zero within rounding): the
    /// step pushed straight into the edge and Eq. 21 has no direction.
    NoEdgeMotion,
    /// A configuration value is out of range.
    InvalidConfig {
        /// Which value.
        what: &'static str,
    },
}

impl fmt::Display for ContourError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite { what } => write!(f, "{what} is not finite"),
            Self::SingularStiffness { det } => {
                write!(f, "the xy stiffness matrix is singular (det {det:e})")
            }
            Self::NoEdgeMotion => write!(
                f,
                "the tool did not move along the edge: no edge direction (Eq. 21)"
            ),
            Self::InvalidConfig { what } => write!(f, "tracer configuration: {what} is invalid"),
        }
    }
}

impl core::error::Error for ContourError {}

/// Smallest accepted `det(K) / (|K|_F^2 / 2)` (about `2 lambda_min / lambda_max` for a
/// symmetric K) before `K` counts as singular.
pub const MIN_RECIPROCAL_CONDITION: f64 = 1.0e-10;

fn finite2(what: &'static str, v: &Vector2<f64>) -> Result<(), ContourError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ContourError::NonFinite { what })
    }
}

/// `K^-1`, or an error if `K` is not finite or singular.
pub fn compliance_of(k: &Matrix2<f64>) -> Result<Matrix2<f64>, ContourError> {
    if !k.iter().all(|x| x.is_finite()) {
        return Err(ContourError::NonFinite { what: "stiffness" });
    }
    let det = k.determinant();
    let scale = 0.5 * k.norm_squared();
    if !(scale > 0.0 && ComplexField::abs(det) >= MIN_RECIPROCAL_CONDITION * scale) {
        return Err(ContourError::SingularStiffness { det });
    }
    k.try_inverse()
        .ok_or(ContourError::SingularStiffness { det })
}

/// Eq. 11: the force `K (x_d - x)` [N] of a robot demanded to `demanded` but stopped at
/// `actual` [m].
pub fn contact_force(
    k: &Matrix2<f64>,
    demanded: &Vector2<f64>,
    actual: &Vector2<f64>,
) -> Vector2<f64> {
    k * (demanded - actual)
}

/// Eq. 16-17: the steady-state tool motion when the demanded step `step` slides the tool
/// along a rigid straight edge at angle `edge_angle` [rad]: `r cos(theta_2 - theta_1)` along
/// the edge.
pub fn edge_motion(step: &Vector2<f64>, edge_angle: f64) -> Vector2<f64> {
    let (s, c) = (ComplexField::sin(edge_angle), ComplexField::cos(edge_angle));
    let along = step.x * c + step.y * s; // r cos(theta_2 - theta_1)
    Vector2::new(along * c, along * s)
}

/// Eq. 18-20: the contact force `K e` [N] after the demanded step `step` [m] against an edge
/// at `edge_angle`, starting from zero force: `e = D - (motion along the edge)`.
pub fn edge_contact_force(k: &Matrix2<f64>, step: &Vector2<f64>, edge_angle: f64) -> Vector2<f64> {
    k * (step - edge_motion(step, edge_angle))
}

/// The tool motion `D - K^-1 F` [m] behind Eq. 21, from the demanded step `step` [m] and the
/// steady-state force (change) `force` [N].
pub fn edge_displacement(
    k: &Matrix2<f64>,
    step: &Vector2<f64>,
    force: &Vector2<f64>,
) -> Result<Vector2<f64>, ContourError> {
    finite2("step", step)?;
    finite2("force", force)?;
    let c = compliance_of(k)?;
    Ok(step - c * force)
}

/// Eq. 21: the direction `theta_2` [rad] of the edge, pointing the way the tool moved,
/// from the demanded step `step` [m] and the steady-state contact force `force` [N] it built
/// up (the change of force if the tool was already pressing before the step). Valid while
/// `K` is non-singular and the force stays in the linear range.
pub fn edge_direction(
    k: &Matrix2<f64>,
    step: &Vector2<f64>,
    force: &Vector2<f64>,
) -> Result<f64, ContourError> {
    let a = edge_displacement(k, step, force)?;
    let scale = step.norm().max(f64::MIN_POSITIVE);
    if a.norm() <= 1.0e-12 * scale {
        return Err(ContourError::NoEdgeMotion);
    }
    Ok(RealField::atan2(a.y, a.x))
}

fn rotate(v: &Vector2<f64>, angle: f64) -> Vector2<f64> {
    let (s, c) = (ComplexField::sin(angle), ComplexField::cos(angle));
    Vector2::new(c * v.x - s * v.y, s * v.x + c * v.y)
}

/// Which way the tracer goes around the object, seen from +z.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TraceDirection {
    /// Counter-clockwise around the object.
    CounterClockwise,
    /// Clockwise around the object.
    Clockwise,
}

impl TraceDirection {
    /// +1 counter-clockwise, -1 clockwise: the turn from the tangent to the force direction.
    fn side(self) -> f64 {
        match self {
            Self::CounterClockwise => 1.0,
            Self::Clockwise => -1.0,
        }
    }
}

/// Settings of a [`ContourTracer`]. Forces [N], lengths [m], angles [rad].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TracerConfig {
    /// `Delta r` of Eq. 24: the commanded step along the edge.
    pub step: f64,
    /// Step of the approach phase.
    pub approach_step: f64,
    /// Direction of the approach (any non-zero length; normalized).
    pub approach_direction: Vector2<f64>,
    /// `F_contact_min` of Eq. 22-23: above it (bias removed) the tool is in contact. Set it
    /// above the sensor noise.
    pub contact_force: f64,
    /// `F_jam_min` of Eq. 23: at or above it the tracer backs off.
    pub jam_force: f64,
    /// Force the tracer steers to inside the window (default: the window's middle).
    pub target_force: f64,
    /// Readings averaged for the bias at initialization (at least 1), robot at rest and
    /// out of contact.
    pub bias_samples: usize,
    /// Radius of the stopping circle around the first contact point (section 3.2e). The
    /// tool must first get farther than twice this radius from it.
    pub stop_radius: f64,
    /// Way around the object.
    pub direction: TraceDirection,
    /// Largest angle between the Eq. 21 edge and the tangent normal to the force for Eq. 21
    /// to be used; beyond it (corners, noise) the tracer moves normal to the force.
    pub max_turn: f64,
    /// Shortest tool motion, as a fraction of `step`, for Eq. 21 to be used.
    pub min_motion_fraction: f64,
    /// Position-discretization guard (section 3.2c): every move is shortened so that, were
    /// it blocked outright, the force would stay below `jam_margin * jam_force`
    /// (`|F + K d| <= |F| + |K d|`). In (0, 1].
    pub jam_margin: f64,
    /// Shortest move along the edge, as a fraction of `step`, that the guard may leave.
    pub min_step_fraction: f64,
    /// Bisections (Figure 4) tried after contact is lost before giving up.
    pub max_bisections: usize,
    /// Consecutive readings at or above the jam force before giving up.
    pub max_jam_steps: usize,
    /// Approach steps before giving up.
    pub max_approach_steps: usize,
    /// Steps after the first contact before giving up.
    pub max_steps: usize,
}

impl TracerConfig {
    /// Defaults for a step of `step` [m] and a force window `contact_force < |F| <
    /// jam_force` [N]: approach along +x with the same step, target force in the window's
    /// middle, 10 bias samples, stop radius 1.5 steps, counter-clockwise, Eq. 21 trusted
    /// within 45 degrees and above 25 % of the commanded move, moves shortened to keep a
    /// blocked move below 80 % of the jam force (down to 10 % of the step), 6 bisections,
    /// 10 jammed readings, 10 000 approach steps, 100 000 steps.
    pub fn new(step: f64, contact_force: f64, jam_force: f64) -> Self {
        Self {
            step,
            approach_step: step,
            approach_direction: Vector2::new(1.0, 0.0),
            contact_force,
            jam_force,
            target_force: 0.5 * (contact_force + jam_force),
            bias_samples: 10,
            stop_radius: 1.5 * step,
            direction: TraceDirection::CounterClockwise,
            max_turn: core::f64::consts::FRAC_PI_4,
            min_motion_fraction: 0.25,
            jam_margin: 0.8,
            min_step_fraction: 0.1,
            max_bisections: 6,
            max_jam_steps: 10,
            max_approach_steps: 10_000,
            max_steps: 100_000,
        }
    }

    fn validate(&self) -> Result<(), ContourError> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        let fraction = |v: f64| v.is_finite() && v > 0.0 && v <= 1.0;
        let checks: [(bool, &'static str); 10] = [
            (pos(self.step), "step"),
            (pos(self.approach_step), "approach_step"),
            (
                self.approach_direction.iter().all(|v| v.is_finite())
                    && self.approach_direction.norm() > 0.0,
                "approach_direction",
            ),
            (pos(self.contact_force), "contact_force"),
            (
                pos(self.jam_force) && self.jam_force > self.contact_force,
                "jam_force (must exceed contact_force)",
            ),
            (
                self.target_force > self.contact_force && self.target_force < self.jam_force,
                "target_force (must lie inside the window)",
            ),
            (self.bias_samples >= 1, "bias_samples"),
            (pos(self.stop_radius), "stop_radius"),
            (
                pos(self.max_turn) && pos(self.min_motion_fraction),
                "max_turn / min_motion_fraction",
            ),
            (
                fraction(self.jam_margin) && fraction(self.min_step_fraction),
                "jam_margin / min_step_fraction (must lie in (0, 1])",
            ),
        ];
        match checks.iter().find(|(ok, _)| !ok) {
            Some((_, what)) => Err(ContourError::InvalidConfig { what }),
            None => Ok(()),
        }
    }
}

/// Why a trace stopped without closing the contour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TraceFailure {
    /// The approach found no contact within its step budget.
    NoContact,
    /// Contact was lost and every bisected direction (Figure 4) failed to regain it.
    ContactLost,
    /// The force stayed at or above the jam force.
    Jammed,
    /// The step budget ran out before the tool re-entered the stopping circle.
    StepLimit,
}

/// Phase of a [`ContourTracer`] (Figure 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TracerState {
    /// Averaging the force bias (section 3.2a).
    Init,
    /// Moving towards the object until the contact threshold (Eq. 22).
    Approach,
    /// In contact, moving along the estimated edge (Eq. 23-24).
    Trace,
    /// Contact lost: bisecting the step direction towards the object (Figure 4).
    Recover,
    /// Force at or above the jam force: backing off.
    Retreat,
    /// The tool re-entered the circle around the first contact: contour closed.
    Done,
    /// Stopped without closing the contour.
    Failed(TraceFailure),
}

impl TracerState {
    /// A short lowercase name ("init", "approach", "trace", "recover", "retreat", "done",
    /// "failed_no_contact", "failed_contact_lost", "failed_jammed", "failed_step_limit").
    pub fn name(&self) -> &'static str {
        match self {
            Self::Init => "init",
            Self::Approach => "approach",
            Self::Trace => "trace",
            Self::Recover => "recover",
            Self::Retreat => "retreat",
            Self::Done => "done",
            Self::Failed(TraceFailure::NoContact) => "failed_no_contact",
            Self::Failed(TraceFailure::ContactLost) => "failed_contact_lost",
            Self::Failed(TraceFailure::Jammed) => "failed_jammed",
            Self::Failed(TraceFailure::StepLimit) => "failed_step_limit",
        }
    }

    /// `Done` or `Failed`: further steps hold the position.
    pub fn is_finished(&self) -> bool {
        matches!(self, Self::Done | Self::Failed(_))
    }
}

/// What one [`ContourTracer::step`] returns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TracerStep {
    /// Next position command [m].
    pub command: Vector2<f64>,
    /// Phase after this step.
    pub state: TracerState,
    /// The reading just consumed was a steady contact inside the force window (Eq. 23):
    /// record the robot's joints and the force now for shape recovery.
    pub contact: bool,
    /// Estimated tool position of that reading, `position - K^-1 F` [m] (Eq. 11), or the
    /// position out of contact.
    pub tool: Vector2<f64>,
    /// Bias-removed force of that reading [N].
    pub force: Vector2<f64>,
}

/// Counters of a trace, for supervision and tests.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TracerStats {
    /// Readings consumed since the first contact.
    pub steps: usize,
    /// Contact samples (readings inside the window).
    pub contacts: usize,
    /// Edge directions taken from Eq. 21.
    pub eq21_steps: usize,
    /// Edge directions taken normal to the force (corners, first contact, after recovery).
    pub normal_steps: usize,
    /// Bisected moves (Figure 4).
    pub bisections: usize,
    /// Moves shortened by the jam guard ([`TracerConfig::jam_margin`]).
    pub shortened: usize,
    /// Readings at or above the jam force.
    pub jams: usize,
    /// Longest run of consecutive readings out of contact after the first contact.
    pub longest_loss: usize,
    /// Largest bias-removed force seen [N].
    pub max_force: f64,
    /// Path length of the estimated tool positions of the contact samples [m].
    pub path_length: f64,
}

/// The contour-tracing algorithm of Figures 3-4 as a state machine, one steady-state reading
/// per step:
///
/// 1. `Init`: the robot holds still out of contact; `bias_samples` readings give the bias.
/// 2. `Approach`: step along `approach_direction` until `|F| > contact_force` (Eq. 22).
/// 3. `Trace`: with the force in the window (Eq. 23) move `step` along the edge (Eq. 24), its
///    direction from Eq. 21 on the last step (or normal to the force at corners and right
///    after contact), plus a move along the force that steers `|F|` to `target_force`; the
///    move along the edge is shortened when, blocked outright, it would push the force past
///    `jam_margin * jam_force` (a corner ahead in a stiff direction).
/// 4. `Recover`: out of contact, retry from the last contact point with the direction turned
///    towards the object by 45, 90, 135, 157.5, ... degrees (Figure 4).
/// 5. `Retreat`: at or above the jam force, back off along the force.
/// 6. `Done` once the estimated tool position, having left it, re-enters the circle of
///    `stop_radius` around the first contact point.
///
/// `position` is the command the robot holds (the previous output, at rest), `force` the raw
/// sensor force the tool exerts on the object (bias included), both xy in the base frame.
/// The xy stiffness `K` of Eq. 21 comes from [`ContourTracer::set_stiffness`] (update it as
/// the pose changes, e.g. from [`crate::drivetrain::cartesian_stiffness_xy`]).
#[derive(Debug, Clone)]
pub struct ContourTracer {
    config: TracerConfig,
    stiffness: Matrix2<f64>,
    compliance: Matrix2<f64>,
    state: TracerState,
    bias_sum: Vector2<f64>,
    bias_count: usize,
    bias: Vector2<f64>,
    start: Option<Vector2<f64>>,
    left_start: bool,
    anchor: Vector2<f64>,
    anchor_tangent: Vector2<f64>,
    anchor_force: Vector2<f64>,
    prev: Option<(Vector2<f64>, Vector2<f64>, Vector2<f64>)>,
    bisections: usize,
    jam_run: usize,
    loss_run: usize,
    last_tool: Option<Vector2<f64>>,
    stats: TracerStats,
}

impl ContourTracer {
    /// A tracer in `Init` with the xy stiffness `stiffness` [N/m].
    pub fn new(config: TracerConfig, stiffness: &Matrix2<f64>) -> Result<Self, ContourError> {
        config.validate()?;
        let compliance = compliance_of(stiffness)?;
        let mut config = config;
        config.approach_direction = config.approach_direction.normalize();
        Ok(Self {
            config,
            stiffness: *stiffness,
            compliance,
            state: TracerState::Init,
            bias_sum: Vector2::zeros(),
            bias_count: 0,
            bias: Vector2::zeros(),
            start: None,
            left_start: false,
            anchor: Vector2::zeros(),
            anchor_tangent: Vector2::zeros(),
            anchor_force: Vector2::zeros(),
            prev: None,
            bisections: 0,
            jam_run: 0,
            loss_run: 0,
            last_tool: None,
            stats: TracerStats::default(),
        })
    }

    /// Updates the xy stiffness `K` [N/m] used by Eq. 11 and 21 (the stiffness varies with
    /// the pose). The old one stays on error.
    pub fn set_stiffness(&mut self, stiffness: &Matrix2<f64>) -> Result<(), ContourError> {
        self.compliance = compliance_of(stiffness)?;
        self.stiffness = *stiffness;
        Ok(())
    }

    /// The configuration.
    pub fn config(&self) -> &TracerConfig {
        &self.config
    }
    /// Current phase.
    pub fn state(&self) -> TracerState {
        self.state
    }
    /// Force bias removed from every reading [N] (zero until `Init` ends).
    pub fn bias(&self) -> Vector2<f64> {
        self.bias
    }
    /// Estimated tool position at the first contact [m].
    pub fn start(&self) -> Option<Vector2<f64>> {
        self.start
    }
    /// Counters.
    pub fn stats(&self) -> &TracerStats {
        &self.stats
    }

    /// Normal stiffness `n^T K n` along the unit `n`, floored to stay positive.
    fn normal_stiffness(&self, n: &Vector2<f64>) -> f64 {
        (n.dot(&(self.stiffness * n))).max(f64::MIN_POSITIVE)
    }

    /// Scale in `[min_step_fraction, 1]` for the move `d` from a reading with force `f`:
    /// a blocked move must stay below the jam guard.
    fn guard(&mut self, f: &Vector2<f64>, d: &Vector2<f64>) -> f64 {
        let cfg = &self.config;
        let worst = (self.stiffness * d).norm();
        let room = cfg.jam_margin * cfg.jam_force - f.norm();
        if worst <= room {
            return 1.0;
        }
        self.stats.shortened += 1;
        let s = room / worst;
        if s.is_finite() {
            s.clamp(cfg.min_step_fraction, 1.0)
        } else {
            cfg.min_step_fraction
        }
    }

    /// Consumes one steady-state reading and returns the next command (see the type docs).
    pub fn step(
        &mut self,
        position: &Vector2<f64>,
        force: &Vector2<f64>,
    ) -> Result<TracerStep, ContourError> {
        finite2("position", position)?;
        finite2("force", force)?;
        let cfg = self.config;
        let hold = |state, tool| TracerStep {
            command: *position,
            state,
            contact: false,
            tool,
            force: Vector2::zeros(),
        };
        match self.state {
            TracerState::Done | TracerState::Failed(_) => {
                return Ok(hold(self.state, *position));
            }
            TracerState::Init => {
                self.bias_sum += force;
                self.bias_count += 1;
                if self.bias_count >= cfg.bias_samples {
                    self.bias = self.bias_sum / self.bias_count as f64;
                    self.state = TracerState::Approach;
                }
                return Ok(hold(self.state, *position));
            }
            _ => {}
        }
        let f = force - self.bias;
        let magnitude = f.norm();
        if self.state == TracerState::Approach {
            if magnitude <= cfg.contact_force {
                self.stats.steps += 1;
                if self.stats.steps > cfg.max_approach_steps {
                    self.state = TracerState::Failed(TraceFailure::NoContact);
                    return Ok(hold(self.state, *position));
                }
                let mut out = hold(self.state, *position);
                out.command = position + cfg.approach_direction * cfg.approach_step;
                out.force = f;
                return Ok(out);
            }
            // Contact (Eq. 22): from here on, count tracing steps.
            self.stats.steps = 0;
        }
        self.stats.steps += 1;
        self.stats.max_force = self.stats.max_force.max(magnitude);
        let side = cfg.direction.side();
        let tool = position - self.compliance * f;
        let mut out = TracerStep {
            command: *position,
            state: self.state,
            contact: false,
            tool,
            force: f,
        };
        if self.stats.steps > cfg.max_steps {
            self.state = TracerState::Failed(TraceFailure::StepLimit);
            out.state = self.state;
            return Ok(out);
        }

        if magnitude >= cfg.jam_force {
            // Too much force: back off along the force (Eq. 23, upper bound).
            self.stats.jams += 1;
            self.jam_run += 1;
            self.loss_run = 0;
            self.prev = None;
            let n = f / magnitude;
            if self.jam_run > cfg.max_jam_steps {
                self.state = TracerState::Failed(TraceFailure::Jammed);
                out.command = position - n * cfg.step;
            } else {
                self.state = TracerState::Retreat;
                let back = (magnitude - cfg.target_force) / self.normal_stiffness(&n);
                out.command = position - n * back.min(cfg.step);
            }
            out.state = self.state;
            return Ok(out);
        }
        self.jam_run = 0;

        if magnitude <= cfg.contact_force {
            // Contact lost (Figure 4): bisect from the last contact towards the object.
            self.prev = None;
            self.loss_run += 1;
            self.stats.longest_loss = self.stats.longest_loss.max(self.loss_run);
            if self.start.is_none() {
                // Lost before the first steady contact: resume the approach.
                self.state = TracerState::Approach;
                out.command = position + cfg.approach_direction * cfg.approach_step;
                out.state = self.state;
                return Ok(out);
            }
            self.bisections += 1;
            self.stats.bisections += 1;
            if self.bisections > cfg.max_bisections {
                self.state = TracerState::Failed(TraceFailure::ContactLost);
                out.command = self.anchor;
                out.state = self.state;
                return Ok(out);
            }
            let k = self.bisections;
            let turn = if k == 1 {
                core::f64::consts::FRAC_PI_4
            } else {
                // 90, 135, 157.5, ... degrees: halving towards the reversed tangent.
                let halvings = i32::try_from(k - 1).unwrap_or(i32::MAX);
                core::f64::consts::PI * (1.0 - ComplexField::powi(0.5f64, halvings))
            };
            let dir = rotate(&self.anchor_tangent, side * turn) * cfg.step;
            let anchor_force = self.anchor_force;
            let scale = self.guard(&anchor_force, &dir);
            self.state = TracerState::Recover;
            out.command = self.anchor + dir * scale;
            out.state = self.state;
            return Ok(out);
        }

        // In the window (Eq. 23): a contact sample.
        out.contact = true;
        self.stats.contacts += 1;
        self.loss_run = 0;
        self.bisections = 0;
        if let Some(last) = self.last_tool {
            self.stats.path_length += (tool - last).norm();
        }
        self.last_tool = Some(tool);
        let n = f / magnitude;
        // Tangent normal to the force, on the chosen side (force = object side).
        let t_normal = rotate(&n, -side * core::f64::consts::FRAC_PI_2);
        let mut tangent = t_normal;
        let mut from_eq21 = false;
        if let (TracerState::Trace, Some((p_prev, f_prev, _))) = (self.state, self.prev) {
            // Eq. 21 on the last commanded step and the change of the steady force.
            let commanded = position - p_prev;
            let a = commanded - self.compliance * (f - f_prev);
            let len = a.norm();
            if len >= cfg.min_motion_fraction * commanded.norm() && len > 0.0 {
                let cand = a / len;
                let cos = cand.dot(&t_normal).clamp(-1.0, 1.0);
                if ComplexField::acos(cos) <= cfg.max_turn {
                    tangent = cand;
                    from_eq21 = true;
                }
            }
        }
        if from_eq21 {
            self.stats.eq21_steps += 1;
        } else {
            self.stats.normal_steps += 1;
        }
        match self.start {
            None => self.start = Some(tool),
            Some(s) => {
                let d = (tool - s).norm();
                if !self.left_start && d > 2.0 * cfg.stop_radius {
                    self.left_start = true;
                }
                if self.left_start && d < cfg.stop_radius {
                    self.state = TracerState::Done;
                    out.state = self.state;
                    return Ok(out);
                }
            }
        }
        // Eq. 24 plus a move along the force that steers |F| to the target.
        let correction =
            ((cfg.target_force - magnitude) / self.normal_stiffness(&n)).clamp(-cfg.step, cfg.step);
        let push = n * correction;
        let along = tangent * cfg.step;
        let scale = self.guard(&(f + self.stiffness * push), &along);
        out.command = position + along * scale + push;
        self.anchor = *position;
        self.anchor_tangent = tangent;
        self.anchor_force = f;
        self.prev = Some((*position, f, tangent));
        self.state = TracerState::Trace;
        out.state = self.state;
        Ok(out)
    }
}

/// Distances to simple shapes, for judging recovered contours.
pub mod shape {
    use nalgebra::Vector2;

    /// Distance [m] from `p` to the segment `a`-`b`.
    pub fn distance_to_segment(p: &Vector2<f64>, a: &Vector2<f64>, b: &Vector2<f64>) -> f64 {
        let ab = b - a;
        let l2 = ab.norm_squared();
        let t = if l2 > 0.0 {
            ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p - (a + ab * t)).norm()
    }

    /// Distance [m] from `p` to the boundary of the closed polygon `vertices` (any order,
    /// convex or not); infinity for no vertices.
    pub fn distance_to_polygon(p: &Vector2<f64>, vertices: &[Vector2<f64>]) -> f64 {
        let n = vertices.len();
        (0..n)
            .filter_map(|i| {
                let a = vertices.get(i)?;
                let b = vertices.get((i + 1) % n)?;
                Some(distance_to_segment(p, a, b))
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Distance [m] from `p` to the circle of `radius` around `center`.
    pub fn distance_to_circle(p: &Vector2<f64>, center: &Vector2<f64>, radius: f64) -> f64 {
        nalgebra::ComplexField::abs((p - center).norm() - radius)
    }

    /// `true` if `p` lies inside the closed polygon `vertices` (even-odd rule).
    pub fn inside_polygon(p: &Vector2<f64>, vertices: &[Vector2<f64>]) -> bool {
        let n = vertices.len();
        let mut inside = false;
        for i in 0..n {
            let (Some(a), Some(b)) = (vertices.get(i), vertices.get((i + 1) % n)) else {
                continue;
            };
            if (a.y > p.y) != (b.y > p.y) {
                let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if p.x < x {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// RMS and largest of the distances of `points` to a shape.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct ShapeError {
        /// Root mean square distance [m].
        pub rms: f64,
        /// Largest distance [m].
        pub max: f64,
        /// Number of points.
        pub count: usize,
    }

    /// RMS and max of `distance(p)` over `points` (zeros for no points).
    pub fn shape_error<'a>(
        points: impl IntoIterator<Item = &'a Vector2<f64>>,
        distance: impl Fn(&Vector2<f64>) -> f64,
    ) -> ShapeError {
        let (mut sum, mut max, mut count) = (0.0, 0.0f64, 0usize);
        for p in points {
            let d = distance(p);
            sum += d * d;
            max = max.max(d);
            count += 1;
        }
        let rms = if count > 0 {
            nalgebra::ComplexField::sqrt(sum / count as f64)
        } else {
            0.0
        };
        ShapeError { rms, max, count }
    }
}
