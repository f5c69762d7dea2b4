//! Settings, phases and outputs of the contour tracer (section 3.2 of the contour-tracking
//! paper, Figures 3-4).

use nalgebra::Vector2;

use crate::error::{BuildError, param};

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
    pub(super) fn side(self) -> f64 {
        match self {
            Self::CounterClockwise => 1.0,
            Self::Clockwise => -1.0,
        }
    }
}

/// Settings of a tracer ([`super::step`]). Forces \[N\], lengths \[m\], angles \[rad\].
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
    /// (`|F + K d| <= |F| + |K d|`). In (0, 1\].
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
    /// Defaults for a step of `step` \[m\] and a force window
    /// `contact_force < |F| < jam_force` \[N\]: approach along +x with the same step, target force in the window's
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

    pub(super) fn validate(&self) -> Result<(), BuildError> {
        let fraction = "in (0, 1]";
        param("step", self.step, self.step > 0.0, "> 0 (m)")?;
        param(
            "approach_step",
            self.approach_step,
            self.approach_step > 0.0,
            "> 0 (m)",
        )?;
        let n = self.approach_direction.norm();
        param("approach_direction (norm)", n, n > 0.0, "finite and > 0")?;
        param(
            "contact_force",
            self.contact_force,
            self.contact_force > 0.0,
            "> 0 (N)",
        )?;
        param(
            "jam_force",
            self.jam_force,
            self.jam_force > self.contact_force,
            "above contact_force (N)",
        )?;
        param(
            "target_force",
            self.target_force,
            self.target_force > self.contact_force && self.target_force < self.jam_force,
            "inside (contact_force, jam_force)",
        )?;
        if self.bias_samples == 0 {
            return Err(BuildError::InvalidParameter {
                what: "bias_samples",
                value: 0.0,
                expected: ">= 1",
            });
        }
        param(
            "stop_radius",
            self.stop_radius,
            self.stop_radius > 0.0,
            "> 0 (m)",
        )?;
        param("max_turn", self.max_turn, self.max_turn > 0.0, "> 0 (rad)")?;
        param(
            "min_motion_fraction",
            self.min_motion_fraction,
            self.min_motion_fraction > 0.0,
            "> 0",
        )?;
        for (what, v) in [
            ("jam_margin", self.jam_margin),
            ("min_step_fraction", self.min_step_fraction),
        ] {
            param(what, v, v > 0.0 && v <= 1.0, fraction)?;
        }
        Ok(())
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

/// Phase of a tracer ([`super::step`]) (Figure 3).
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

/// What one [`super::step`] returns.
#[derive(Debug, Clone, Copy, PartialEq)]
#[must_use]
pub struct TracerStep {
    /// Next position command \[m\].
    pub command: Vector2<f64>,
    /// Phase after this step.
    pub state: TracerState,
    /// The reading just consumed was a steady contact inside the force window (Eq. 23):
    /// record the robot's joints and the force now for shape recovery.
    pub contact: bool,
    /// Estimated tool position of that reading, `position - K^-1 F` \[m\] (Eq. 11), or the
    /// position out of contact.
    pub tool: Vector2<f64>,
    /// Bias-removed force of that reading \[N\].
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
    /// Largest bias-removed force seen \[N\].
    pub max_force: f64,
    /// Path length of the estimated tool positions of the contact samples \[m\].
    pub path_length: f64,
}
