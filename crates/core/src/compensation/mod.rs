//! Online force-based compliance compensation (Hähn and Weigold, "Hybrid compliance
//! compensation for path accuracy enhancement in robot machining", Production Engineering
//! (2020), sections 2.2-2.6): every control cycle, the force/torque sensor's
//! reading is cleaned of offsets and tool weight (Eq. 12-18), carried to the TCP (Eq. 19-20),
//! filtered to its quasi-static part (low-pass + moving average), optionally replaced by the
//! offline-estimated force where the two disagree (pilot control, section 2.3), turned into a
//! TCP deflection by the virtual-joint model (Eq. 1-9), and the opposite correction is
//! projected onto the plane normal to the feed (Eq. 10-11), limited in size and rate, and
//! output in Cartesian or axis-specific form (section 2.2).
//!
//! Everything per cycle is `no_std`, allocation-free and panic-free; the paper ran it at a
//! 4 ms cycle (KUKA RSI), and it runs at 2 kHz as well.

pub mod filter;
pub mod pilot;
pub mod projection;
pub mod sensor;

use nalgebra::Vector3;

pub use filter::{LowPass, MovingAverage};
pub use pilot::PilotControl;
pub use projection::project_normal_to_feed;
pub use sensor::SensorCalibration;

use crate::error::{BuildError, TickError, check_finite, param};
use crate::vjm::{self, MAX_DOF, Vector6};

/// Capacity of the moving-average buffer \[samples\]: 64 cycles are 256 ms at the paper's 4 ms
/// cycle and 32 ms at 2 kHz, longer than any window that still reacts to a cutter exit.
pub const MAX_AVERAGE_WINDOW: usize = 64;

/// The paper's control cycle \[s\] (KUKA RSI).
pub const PAPER_CYCLE: f64 = 0.004;

/// In which form the correction leaves the compensator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CorrectionOutput {
    /// Cartesian correction values `[dx, dy, dz, rx, ry, rz]` for the robot controller.
    #[default]
    Cartesian,
    /// Axis-specific values: also `dq` through the actuated-joint Jacobian.
    Joint,
}

/// Settings of the online compensation chain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompensatorConfig {
    /// Cycle time \[s\] (0.004 in the paper, 0.0005 at 2 kHz).
    pub dt: f64,
    /// Sensor offsets, weight, residual polynomial and sensor-to-TCP transform.
    pub calibration: SensorCalibration,
    /// Low-pass cut-off \[Hz\].
    pub lowpass_cutoff_hz: f64,
    /// Moving-average window \[cycles\], 1..=[`MAX_AVERAGE_WINDOW`].
    pub moving_average_window: usize,
    /// Pilot control `(threshold [N], ramp [s])`, or `None` for measured forces only.
    pub pilot: Option<(f64, f64)>,
    /// Project the translational correction onto the plane normal to the feed (Eq. 10-11).
    pub project_on_feed: bool,
    /// Largest translational correction \[m\]; larger ones are scaled down and reported.
    pub max_correction: f64,
    /// Largest change of the translational correction per second \[m/s\]; faster changes are
    /// limited and reported.
    pub max_rate: f64,
    /// Cartesian or axis-specific output.
    pub output: CorrectionOutput,
}

impl CompensatorConfig {
    /// The paper's chain at cycle `dt`: 10 Hz low-pass, 5-cycle moving average, pilot
    /// control 150 N / 80 ms, projection on, 3 mm and 50 mm/s limits, Cartesian output.
    pub fn paper(dt: f64, calibration: SensorCalibration) -> Self {
        Self {
            dt,
            calibration,
            lowpass_cutoff_hz: 10.0,
            moving_average_window: 5,
            pilot: Some((pilot::PAPER_THRESHOLD, pilot::PAPER_RAMP)),
            project_on_feed: true,
            max_correction: 3.0e-3,
            max_rate: 0.05,
            output: CorrectionOutput::Cartesian,
        }
    }
}

/// What one cycle produced.
#[derive(Debug, Clone, Copy, PartialEq)]
#[must_use]
pub struct CycleOutput {
    /// The wrench fed to the model \[N, N m\]: TCP, base frame, filtered (and piloted).
    pub wrench: Vector6,
    /// The wrench before pilot control (filtered measurement) \[N, N m\].
    pub measured_wrench: Vector6,
    /// Model deflection `[dp; dr]` \[m, rad\] under `wrench` (Eq. 9).
    pub deflection: Vector6,
    /// Correction to add to the commanded pose `[dp; dr]` \[m, rad\], base frame, after
    /// projection and limits.
    pub correction: Vector6,
    /// Axis-specific correction \[rad or m\] (zeros unless the output is `Joint`).
    pub dq: [f64; MAX_DOF],
    /// Weight of the estimated force in the blend (0 = measured only).
    pub pilot_weight: f64,
    /// The feed direction was removed (false when standing still or projection is off).
    pub projected: bool,
    /// The size limit acted this cycle.
    pub size_limited: bool,
    /// The rate limit acted this cycle.
    pub rate_limited: bool,
}

/// The online compensation chain of one robot: its kinematic chain and validated settings.
/// Immutable; the filter, pilot and rate-limiter states live in [`Data`].
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    chain: vjm::Model,
    config: CompensatorConfig,
    // Fresh filter and pilot states, validated here; `Data::new` copies them.
    lowpass: LowPass,
    average: MovingAverage<MAX_AVERAGE_WINDOW>,
    pilot: Option<PilotControl>,
}

impl Model {
    /// Validates `config` (cycle time, filter, pilot, limits, calibration) for `chain`.
    pub fn new(chain: vjm::Model, config: CompensatorConfig) -> Result<Self, BuildError> {
        let c = &config;
        param("dt", c.dt, c.dt > 0.0, "> 0 (s)")?;
        param(
            "max_correction",
            c.max_correction,
            c.max_correction >= 0.0,
            ">= 0 (m)",
        )?;
        param("max_rate", c.max_rate, c.max_rate >= 0.0, ">= 0 (m/s)")?;
        c.calibration.validate()?;
        let lowpass = LowPass::new(c.lowpass_cutoff_hz, c.dt)?;
        let average = MovingAverage::new(c.moving_average_window, c.dt)?;
        let pilot = match c.pilot {
            Some((threshold, ramp)) => Some(PilotControl::new(threshold, ramp, c.dt)?),
            None => None,
        };
        Ok(Self {
            chain,
            config,
            lowpass,
            average,
            pilot,
        })
    }

    /// The kinematic chain.
    pub fn chain(&self) -> &vjm::Model {
        &self.chain
    }

    /// The settings.
    pub fn config(&self) -> &CompensatorConfig {
        &self.config
    }

    /// Delay of the filter chain at low frequencies \[cycles\]: low-pass plus moving average.
    pub fn delay_samples(&self) -> f64 {
        self.lowpass.delay_samples() + self.average.delay_samples()
    }

    /// Delay of the filter chain \[s\].
    pub fn delay_seconds(&self) -> f64 {
        self.delay_samples() * self.config.dt
    }
}

/// The compensation chain's state and workspace: filters, pilot control, rate limiter and the
/// chain's [`vjm::Data`]. One per robot; created without allocation.
#[derive(Debug, Clone)]
pub struct Data {
    /// Workspace of the chain.
    pub vjm: vjm::Data,
    lowpass: LowPass,
    average: MovingAverage<MAX_AVERAGE_WINDOW>,
    pilot: Option<PilotControl>,
    last: Vector3<f64>,
}

impl Data {
    /// Fresh states for `model` (filters empty, pilot off, no previous correction).
    pub fn new(model: &Model) -> Self {
        Self {
            vjm: vjm::Data::new(&model.chain),
            lowpass: model.lowpass,
            average: model.average,
            pilot: model.pilot,
            last: Vector3::zeros(),
        }
    }

    /// Whether this state was made for a model of `model`'s dimensions and settings.
    pub fn check(&self, model: &Model) -> bool {
        self.vjm.check(&model.chain)
            && self.average.window() == model.config.moving_average_window
            && self.pilot.is_some() == model.config.pilot.is_some()
    }

    /// Clears filter, pilot and rate-limiter states.
    pub fn reset(&mut self) {
        self.lowpass.reset();
        self.average.reset();
        if let Some(p) = self.pilot.as_mut() {
            p.reset();
        }
        self.last = Vector3::zeros();
    }
}

/// One control cycle: joints `q` \[rad or m\], raw sensor `reading` \[N, N m\] (sensor frame),
/// the offline estimate of the TCP wrench (base frame) if the program provides one, and the
/// feed velocity \[m/s\] (base frame). Allocation-free, never panics.
pub fn step(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    reading: &Vector6,
    estimated: Option<&Vector6>,
    feed_velocity: &Vector3<f64>,
) -> Result<CycleOutput, TickError> {
    data.vjm.check_model(&model.chain)?;
    if !data.check(model) {
        return Err(TickError::ModelMismatch {
            what: "moving-average window",
            expected: model.config.moving_average_window,
            got: data.average.window(),
        });
    }
    check_finite("reading", reading.as_slice())?;
    check_finite("feed_velocity", feed_velocity.as_slice())?;
    if let Some(e) = estimated {
        check_finite("estimated", e.as_slice())?;
    }
    let config = &model.config;
    let tcp = vjm::forward(&model.chain, &mut data.vjm, q)?;
    let raw = config.calibration.tcp_wrench_base(reading, &tcp);
    crate::error::check_output("TCP wrench from the reading", raw.as_slice())?;
    let measured = data.average.step(&data.lowpass.step(&raw));
    let (wrench, pilot_weight) = match (data.pilot.as_mut(), estimated) {
        (Some(p), Some(e)) => {
            let w = p.step(&measured, e);
            (w, p.weight())
        }
        _ => (measured, 0.0),
    };
    let deflection = vjm::deflection(&model.chain, &mut data.vjm, q, &wrench, vjm::Load::Exact)?;
    let mut c: Vector3<f64> = -deflection.fixed_rows::<3>(0).into_owned();
    let dr: Vector3<f64> = -deflection.fixed_rows::<3>(3).into_owned();
    let mut projected = false;
    if config.project_on_feed {
        (c, projected) = project_normal_to_feed(&c, feed_velocity);
    }
    let mut size_limited = false;
    let norm = c.norm();
    if norm > config.max_correction {
        c *= config.max_correction / norm;
        size_limited = true;
    }
    let mut rate_limited = false;
    let step = c - data.last;
    let max_step = config.max_rate * config.dt;
    if step.norm() > max_step {
        c = data.last + step * (max_step / step.norm());
        rate_limited = true;
    }
    data.last = c;
    let correction = Vector6::new(c.x, c.y, c.z, dr.x, dr.y, dr.z);
    let dq = match config.output {
        CorrectionOutput::Cartesian => [0.0; MAX_DOF],
        CorrectionOutput::Joint => vjm::joint_delta(&model.chain, &mut data.vjm, q, &correction)?,
    };
    Ok(CycleOutput {
        wrench,
        measured_wrench: measured,
        deflection,
        correction,
        dq,
        pilot_weight,
        projected,
        size_limited,
        rate_limited,
    })
}
