//! Force pilot control (VJM paper, section 2.3): forces estimated offline along the program
//! are trusted over the measured ones when the two differ by more than a threshold (paper:
//! 150 N): the signal then blends linearly to the estimate within a ramp time (paper: 80 ms),
//! and back to the measurement once they agree again. This removes the 100-150 ms reaction
//! time of the filtered measurement at cutter entry and exit.

use crate::error::{BuildError, param};
use crate::vjm::Vector6;

/// The paper's switching threshold \[N\].
pub const PAPER_THRESHOLD: f64 = 150.0;
/// The paper's blending time \[s\].
pub const PAPER_RAMP: f64 = 0.080;

/// Pilot-control state: the weight `w` of the estimate in `(1 - w) measured + w estimated`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PilotControl {
    threshold: f64,
    ramp: f64,
    dt: f64,
    weight: f64,
}

impl PilotControl {
    /// Switch when `|F_measured - F_estimated| > threshold` \[N\] (force part of the wrench),
    /// blend over `ramp` \[s\] at cycle time `dt` \[s\]. `ramp = 0` switches in one cycle.
    /// Threshold >= 0, ramp >= 0 and dt > 0, all finite.
    pub fn new(threshold: f64, ramp: f64, dt: f64) -> Result<Self, BuildError> {
        param("pilot threshold", threshold, threshold >= 0.0, ">= 0 (N)")?;
        param("pilot ramp", ramp, ramp >= 0.0, ">= 0 (s)")?;
        param("dt", dt, dt > 0.0, "> 0 (s)")?;
        Ok(Self {
            threshold,
            ramp,
            dt,
            weight: 0.0,
        })
    }

    /// The paper's 150 N / 80 ms at cycle time `dt` \[s\].
    pub fn paper(dt: f64) -> Result<Self, BuildError> {
        Self::new(PAPER_THRESHOLD, PAPER_RAMP, dt)
    }

    /// Current weight of the estimate, 0 (measured) .. 1 (estimated).
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// Threshold \[N\].
    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    /// Ramp time \[s\].
    pub fn ramp(&self) -> f64 {
        self.ramp
    }

    /// One cycle: blends `measured` and `estimated` wrenches \[N, N m\] and returns the blend.
    /// The weight moves by `dt / ramp` per cycle towards 1 while the forces differ by more than
    /// the threshold, towards 0 otherwise.
    pub fn step(&mut self, measured: &Vector6, estimated: &Vector6) -> Vector6 {
        let diff = (measured.fixed_rows::<3>(0) - estimated.fixed_rows::<3>(0)).norm();
        let target = if diff > self.threshold { 1.0 } else { 0.0 };
        let rate = if self.ramp > 0.0 {
            self.dt / self.ramp
        } else {
            1.0
        };
        self.weight = if target > self.weight {
            (self.weight + rate).min(1.0)
        } else {
            (self.weight - rate).max(0.0)
        };
        measured * (1.0 - self.weight) + estimated * self.weight
    }

    /// Back to trusting the measurement.
    pub fn reset(&mut self) {
        self.weight = 0.0;
    }
}
