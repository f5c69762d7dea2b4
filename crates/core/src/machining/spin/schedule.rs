//! The spin of the tool about its own axis along a program: piecewise linear in the *spin
//! budget* `G`, the angle the rate bounds allow the spin to have turned since the start.
//!
//! Between two samples the path advances by the chord `ds` (the programmed step) in `dt`;
//! the spin may turn by at most `dG = min(per_metre ds, per_second dt)`, and `G` is the sum of
//! those steps. A schedule holds stations `(G_i, theta_i)` with `|theta_i - theta_(i-1)| <=
//! G_i - G_(i-1)` and interpolates linearly in `G` between them, so between any two samples
//! the spin turns by at most `dG`: both bounds hold sample by sample, whatever the speed does
//! between the stations. A dwell (`ds` = 0) holds the spin.

use alloc::vec::Vec;

use nalgebra::{UnitQuaternion, Vector3};

use crate::error::BuildError;

/// Largest spin rate a bound takes: 1e6 rad/m or rad/s.
pub const MAX_SPIN_RATE: f64 = 1.0e6;

/// A spin along the program (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SpinSchedule {
    /// The spin budget at each station \[rad\], increasing.
    budget: Vec<f64>,
    /// The spin at each station \[rad\] about the tool axis, from the setup's orientation.
    spin: Vec<f64>,
    /// Largest spin rate along the path \[rad/m\].
    per_metre: f64,
    /// Largest spin rate in time \[rad/s\].
    per_second: f64,
}

impl SpinSchedule {
    /// The spin `angle` \[rad\] everywhere (finite, at most two turns).
    pub fn constant(angle: f64) -> Result<Self, BuildError> {
        crate::error::param(
            "spin (rad)",
            angle,
            angle.is_finite() && angle.abs() <= 4.0 * core::f64::consts::PI,
            "finite, within two turns",
        )?;
        Ok(Self {
            budget: alloc::vec![0.0],
            spin: alloc::vec![angle],
            per_metre: 1.0,
            per_second: 1.0,
        })
    }

    /// A schedule of stations: `budget` increasing, `spin` one per station, each step of the
    /// spin within the budget's step; the rate bounds finite and > 0 (at most
    /// [`MAX_SPIN_RATE`]).
    pub fn new(
        budget: Vec<f64>,
        spin: Vec<f64>,
        per_metre: f64,
        per_second: f64,
    ) -> Result<Self, BuildError> {
        check_rates(per_metre, per_second)?;
        if budget.len() != spin.len() {
            return Err(BuildError::WrongLength {
                what: "spin stations (one spin per budget)",
                expected: budget.len(),
                got: spin.len(),
            });
        }
        if budget.is_empty() {
            return Err(BuildError::TooFew {
                what: "spin stations",
                needed: 1,
                got: 0,
            });
        }
        if let Some(index) = spin.iter().chain(&budget).position(|v| !v.is_finite()) {
            return Err(BuildError::NonFinite {
                what: "spin stations",
                index,
            });
        }
        for index in 1..budget.len() {
            let (Some(b0), Some(b1), Some(s0), Some(s1)) = (
                budget.get(index - 1),
                budget.get(index),
                spin.get(index - 1),
                spin.get(index),
            ) else {
                continue;
            };
            // Rounding of the interpolation aside: 1e-12 of the step.
            if b1 < b0 || (s1 - s0).abs() > (b1 - b0) * (1.0 + 1e-12) + 1e-15 {
                return Err(BuildError::InvalidEntry {
                    what: "spin station (budget increasing, each spin step within it)",
                    index,
                    value: s1 - s0,
                    expected: "|spin step| <= budget step",
                });
            }
        }
        Ok(Self {
            budget,
            spin,
            per_metre,
            per_second,
        })
    }

    /// The stations' budgets \[rad\].
    pub fn budgets(&self) -> &[f64] {
        &self.budget
    }

    /// The stations' spins \[rad\].
    pub fn spins(&self) -> &[f64] {
        &self.spin
    }

    /// The rate bounds: (per metre of path \[rad/m\], per second \[rad/s\]).
    pub fn rates(&self) -> (f64, f64) {
        (self.per_metre, self.per_second)
    }

    /// The budget step of a sample: the programmed `step` \[m\] taken in `dt` \[s\].
    pub fn budget_step(&self, step: &Vector3<f64>, dt: f64) -> f64 {
        budget_step(self.per_metre, self.per_second, step, dt)
    }

    /// The spin \[rad\] at budget `g` (the ends held beyond the first and last station).
    pub fn at(&self, g: f64) -> f64 {
        let i = self.budget.partition_point(|b| *b <= g);
        let before = i.checked_sub(1);
        let at = |k: Option<usize>, v: &[f64]| k.and_then(|k| v.get(k)).copied();
        match (
            at(before, &self.budget),
            self.budget.get(i).copied(),
            at(before, &self.spin),
            self.spin.get(i).copied(),
        ) {
            (Some(b0), Some(b1), Some(s0), Some(s1)) if b1 > b0 => {
                s0 + (s1 - s0) * ((g - b0) / (b1 - b0))
            }
            (_, _, Some(s0), _) => s0,
            _ => self.spin.first().copied().unwrap_or(0.0),
        }
    }

    /// The tool orientation with spin `theta` about its own axis: `orientation * Rz(theta)`.
    pub fn turn(orientation: &UnitQuaternion<f64>, theta: f64) -> UnitQuaternion<f64> {
        orientation * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), theta)
    }
}

/// `min(per_metre |step|, per_second dt)` (see the module docs).
pub fn budget_step(per_metre: f64, per_second: f64, step: &Vector3<f64>, dt: f64) -> f64 {
    (per_metre * step.norm()).min(per_second * dt.max(0.0))
}

/// Both bounds finite, > 0 and at most [`MAX_SPIN_RATE`].
pub(crate) fn check_rates(per_metre: f64, per_second: f64) -> Result<(), BuildError> {
    crate::error::param(
        "spin rate per metre of path (rad/m)",
        per_metre,
        per_metre > 0.0 && per_metre <= MAX_SPIN_RATE,
        "in (0, MAX_SPIN_RATE = 1e6] rad/m",
    )?;
    crate::error::param(
        "spin rate per second (rad/s)",
        per_second,
        per_second > 0.0 && per_second <= MAX_SPIN_RATE,
        "in (0, MAX_SPIN_RATE = 1e6] rad/s",
    )?;
    Ok(())
}

/// Follows a schedule sample by sample (the budget so far and the last sample's time).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Cursor {
    budget: f64,
    time: Option<f64>,
}

impl Cursor {
    /// The spin at the next sample (`step` since the last one, at `time`).
    pub fn advance(&mut self, schedule: &SpinSchedule, step: &Vector3<f64>, time: f64) -> f64 {
        if let Some(t0) = self.time.replace(time) {
            self.budget += schedule.budget_step(step, time - t0);
        }
        schedule.at(self.budget)
    }
}
