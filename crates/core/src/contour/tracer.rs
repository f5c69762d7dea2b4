//! The contour tracer of the contour-tracking paper (section 3.2, Figures 3-4) in the crate's
//! tick shape: [`Model`] (validated settings and initial stiffness), [`Data`] (the tracer's
//! state, one method per phase) and [`step`].

use nalgebra::{ComplexField, Matrix2, Vector2};

use super::config::{TraceFailure, TracerConfig, TracerState, TracerStats, TracerStep};
use super::geometry::{compliance_of, finite2, rotate};
use crate::error::{BuildError, TickError};

/// The tracer's validated settings and the xy stiffness it starts with. Immutable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Model {
    config: TracerConfig,
    stiffness: Matrix2<f64>,
    compliance: Matrix2<f64>,
}

impl Model {
    /// Validates `config` and the initial xy stiffness `stiffness` \[N/m\] (finite,
    /// non-singular).
    pub fn new(config: TracerConfig, stiffness: &Matrix2<f64>) -> Result<Self, BuildError> {
        config.validate()?;
        let compliance = compliance_of(stiffness).map_err(|e| match e {
            TickError::Singular { what, sigma_min } => BuildError::Singular {
                what,
                measure: sigma_min,
            },
            _ => BuildError::NonFinite {
                what: "stiffness",
                index: stiffness.iter().position(|v| !v.is_finite()).unwrap_or(0),
            },
        })?;
        let mut config = config;
        config.approach_direction = config.approach_direction.normalize();
        Ok(Self {
            config,
            stiffness: *stiffness,
            compliance,
        })
    }

    /// The configuration (approach direction normalized).
    pub fn config(&self) -> &TracerConfig {
        &self.config
    }

    /// The initial xy stiffness \[N/m\].
    pub fn stiffness(&self) -> &Matrix2<f64> {
        &self.stiffness
    }
}

/// Where the tracer last stood in steady contact: the point, the tangent it left along and
/// the force it read there. Recovery (Figure 4) restarts from it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Anchor {
    position: Vector2<f64>,
    tangent: Vector2<f64>,
    force: Vector2<f64>,
}

/// The tracer's state: phase, force bias, current xy stiffness, first contact, anchor and
/// counters. Created in `Init` by [`Data::new`].
#[derive(Debug, Clone, PartialEq)]
pub struct Data {
    stiffness: Matrix2<f64>,
    compliance: Matrix2<f64>,
    state: TracerState,
    bias_sum: Vector2<f64>,
    bias_count: usize,
    bias: Vector2<f64>,
    start: Option<Vector2<f64>>,
    left_start: bool,
    anchor: Anchor,
    // The last commanded position, force and tangent, for Eq. 21 on the next reading.
    prev: Option<(Vector2<f64>, Vector2<f64>, Vector2<f64>)>,
    bisections: usize,
    jam_run: usize,
    loss_run: usize,
    last_tool: Option<Vector2<f64>>,
    stats: TracerStats,
}

impl Data {
    /// A tracer in `Init` with the model's initial stiffness.
    pub fn new(model: &Model) -> Self {
        Self {
            stiffness: model.stiffness,
            compliance: model.compliance,
            state: TracerState::Init,
            bias_sum: Vector2::zeros(),
            bias_count: 0,
            bias: Vector2::zeros(),
            start: None,
            left_start: false,
            anchor: Anchor::default(),
            prev: None,
            bisections: 0,
            jam_run: 0,
            loss_run: 0,
            last_tool: None,
            stats: TracerStats::default(),
        }
    }

    /// Always `true`: any tracer state fits any tracer model (no dimensions differ); present
    /// for the crate's uniform `Data::check`.
    pub fn check(&self, _model: &Model) -> bool {
        true
    }

    /// Updates the xy stiffness `K` \[N/m\] used by Eq. 11 and 21 (the stiffness varies with
    /// the pose). The old one stays on error.
    pub fn set_stiffness(&mut self, stiffness: &Matrix2<f64>) -> Result<(), TickError> {
        self.compliance = compliance_of(stiffness)?;
        self.stiffness = *stiffness;
        Ok(())
    }

    /// The current xy stiffness \[N/m\].
    pub fn stiffness(&self) -> &Matrix2<f64> {
        &self.stiffness
    }
    /// Current phase.
    pub fn state(&self) -> TracerState {
        self.state
    }
    /// Force bias removed from every reading \[N\] (zero until `Init` ends).
    pub fn bias(&self) -> Vector2<f64> {
        self.bias
    }
    /// Estimated tool position at the first contact \[m\].
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
    fn guard(&mut self, cfg: &TracerConfig, f: &Vector2<f64>, d: &Vector2<f64>) -> f64 {
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

    /// `Init`: one more reading towards the bias.
    fn init(&mut self, cfg: &TracerConfig, force: &Vector2<f64>) {
        self.bias_sum += force;
        self.bias_count += 1;
        if self.bias_count >= cfg.bias_samples {
            self.bias = self.bias_sum / self.bias_count as f64;
            self.state = TracerState::Approach;
        }
    }

    /// `Approach` without contact yet: the next approach step, or a failure once the budget
    /// is spent. `None` once the force crosses the contact threshold (Eq. 22).
    fn approach(&mut self, cfg: &TracerConfig, out: &mut TracerStep, magnitude: f64) -> bool {
        if magnitude > cfg.contact_force {
            // Contact (Eq. 22): from here on, count tracing steps.
            self.stats.steps = 0;
            return false;
        }
        self.stats.steps += 1;
        if self.stats.steps > cfg.max_approach_steps {
            self.state = TracerState::Failed(TraceFailure::NoContact);
            out.force = Vector2::zeros();
        } else {
            out.command += cfg.approach_direction * cfg.approach_step;
        }
        out.state = self.state;
        true
    }

    /// `Retreat`: the force is at or above the jam force; back off along it (Eq. 23, upper
    /// bound).
    fn retreat(
        &mut self,
        cfg: &TracerConfig,
        position: &Vector2<f64>,
        out: &mut TracerStep,
        f: &Vector2<f64>,
        magnitude: f64,
    ) {
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
    }

    /// `Recover`: contact lost (Figure 4); bisect from the last contact towards the object.
    fn recover(&mut self, cfg: &TracerConfig, position: &Vector2<f64>, out: &mut TracerStep) {
        self.prev = None;
        self.loss_run += 1;
        self.stats.longest_loss = self.stats.longest_loss.max(self.loss_run);
        if self.start.is_none() {
            // Lost before the first steady contact: resume the approach.
            self.state = TracerState::Approach;
            out.command = position + cfg.approach_direction * cfg.approach_step;
            out.state = self.state;
            return;
        }
        self.bisections += 1;
        self.stats.bisections += 1;
        if self.bisections > cfg.max_bisections {
            self.state = TracerState::Failed(TraceFailure::ContactLost);
            out.command = self.anchor.position;
            out.state = self.state;
            return;
        }
        let k = self.bisections;
        let turn = if k == 1 {
            core::f64::consts::FRAC_PI_4
        } else {
            // 90, 135, 157.5, ... degrees: halving towards the reversed tangent.
            let halvings = i32::try_from(k - 1).unwrap_or(i32::MAX);
            core::f64::consts::PI * (1.0 - ComplexField::powi(0.5f64, halvings))
        };
        let dir = rotate(&self.anchor.tangent, cfg.direction.side() * turn) * cfg.step;
        let anchor_force = self.anchor.force;
        let scale = self.guard(cfg, &anchor_force, &dir);
        self.state = TracerState::Recover;
        out.command = self.anchor.position + dir * scale;
        out.state = self.state;
    }

    /// `Trace`: a steady contact inside the window (Eq. 23); the next move along the edge
    /// (Eq. 21 and 24), or `Done` back at the start.
    fn trace(
        &mut self,
        cfg: &TracerConfig,
        position: &Vector2<f64>,
        out: &mut TracerStep,
        f: &Vector2<f64>,
        magnitude: f64,
    ) {
        let side = cfg.direction.side();
        let tool = out.tool;
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
                    return;
                }
            }
        }
        // Eq. 24 plus a move along the force that steers |F| to the target.
        let correction =
            ((cfg.target_force - magnitude) / self.normal_stiffness(&n)).clamp(-cfg.step, cfg.step);
        let push = n * correction;
        let along = tangent * cfg.step;
        let scale = self.guard(cfg, &(f + self.stiffness * push), &along);
        out.command = position + along * scale + push;
        self.anchor = Anchor {
            position: *position,
            tangent,
            force: *f,
        };
        self.prev = Some((*position, *f, tangent));
        self.state = TracerState::Trace;
        out.state = self.state;
    }
}

/// One step of the contour-tracing algorithm of Figures 3-4, a state machine fed one
/// steady-state reading per step:
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
/// The xy stiffness `K` of Eq. 21 starts as the model's and is updated with
/// [`Data::set_stiffness`] as the pose changes (e.g. from
/// [`crate::drivetrain::cartesian_stiffness_xy`]).
/// Consumes one steady-state reading and returns the next command (see above): `position`
/// \[m\] the command the robot holds, `force` \[N\] the raw sensor force, xy in the base frame.
/// Allocation-free, never panics.
pub fn step(
    model: &Model,
    data: &mut Data,
    position: &Vector2<f64>,
    force: &Vector2<f64>,
) -> Result<TracerStep, TickError> {
    finite2("position", position)?;
    finite2("force", force)?;
    let cfg = &model.config;
    let mut out = TracerStep {
        command: *position,
        state: data.state,
        contact: false,
        tool: *position,
        force: Vector2::zeros(),
    };
    match data.state {
        TracerState::Done | TracerState::Failed(_) => return Ok(out),
        TracerState::Init => {
            data.init(cfg, force);
            out.state = data.state;
            return Ok(out);
        }
        _ => {}
    }
    let f = force - data.bias;
    let magnitude = f.norm();
    out.force = f;
    if data.state == TracerState::Approach && data.approach(cfg, &mut out, magnitude) {
        return Ok(out);
    }
    data.stats.steps += 1;
    data.stats.max_force = data.stats.max_force.max(magnitude);
    out.tool = position - data.compliance * f;
    if data.stats.steps > cfg.max_steps {
        data.state = TracerState::Failed(TraceFailure::StepLimit);
        out.state = data.state;
        return Ok(out);
    }
    if magnitude >= cfg.jam_force {
        data.retreat(cfg, position, &mut out, &f, magnitude);
        return Ok(out);
    }
    data.jam_run = 0;
    if magnitude <= cfg.contact_force {
        data.recover(cfg, position, &mut out);
    } else {
        data.trace(cfg, position, &mut out, &f, magnitude);
    }
    Ok(out)
}
