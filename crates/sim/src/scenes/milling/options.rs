//! The milling scenario's settings ([`MillingOptions`]): the robot's start, the sensor, the
//! groove and its timing, the controller, the identification and the seed.

use nalgebra::Vector3;
use serde::Serialize;

use super::sensor::SensorParams;
use crate::rapier_util::SERVO_DT as DT;
use crate::urdf_arm::KR300_Q0;

/// Largest physics step of the program runs \[s\]: 1 ms, twice the groove scenario's; the step
/// is shortened to divide the control cycle. See [`PROGRAM_SUBSTEPS`] for what it changes.
pub const PROGRAM_DT: f64 = 1.0e-3;

/// rapier substeps per physics step of the program scenarios (identification and runs): 2, half
/// rapier's default 4. rapier rebuilds the multibody mass matrix of the KR 300 (36 degrees of
/// freedom) in every substep, and that is most of a run's time. On the test workpiece (maximum
/// path deviation, uncompensated / offline / Cartesian / hybrid, mm): 1 ms in 2 substeps 1.939 /
/// 0.400 / 0.987 / 0.732; 1 ms in 4 1.952 / 0.415 / 0.998 / 0.741; 0.5 ms in 4 1.971 / 0.430 /
/// 0.983 / 0.743. Halving the substeps moves the figures by less than halving the step does (at
/// most 1.5 % against 2 %), and the scenario takes 36 s instead of 78 s on 2 cores.
pub const PROGRAM_SUBSTEPS: usize = 2;

/// The milling scenario's settings.
#[derive(Debug, Clone, Serialize)]
pub struct MillingOptions {
    /// Start joints of the KR 300 \[rad\]: the groove starts at the TCP there and runs along
    /// +x of the base with the tool's orientation held.
    pub q0: Vec<f64>,
    /// The sensor.
    pub sensor: SensorParams,
    /// Feed speed \[m/s\] (paper: 25 mm/s).
    pub feed: f64,
    /// Process force while cutting \[N\], base frame (paper: 546 N in the xy plane).
    pub force: [f64; 3],
    /// Standstill before the motion \[s\].
    pub settle: f64,
    /// Acceleration ramp to the feed speed \[s\].
    pub ramp: f64,
    /// Travel from reaching the feed to cutter entry \[s\].
    pub approach: f64,
    /// Cutting time \[s\].
    pub cut: f64,
    /// Travel after cutter exit \[s\].
    pub runout: f64,
    /// Rise (and fall) time of the force at entry and exit \[s\]: the cutter's engagement, 0.1 s
    /// = 2.5 mm of travel at 25 mm/s.
    pub force_rise: f64,
    /// Control cycle \[s\] (paper: 4 ms, KUKA RSI).
    pub cycle: f64,
    /// Transport delay of a correction into the servos \[cycles\].
    pub delay_cycles: usize,
    /// Servo lag time constant for corrections \[s\].
    pub servo_tau: f64,
    /// Lead of the offline force estimate over the real force \[s\] (paper Fig. 3: ~40 ms).
    pub estimate_lead: f64,
    /// Relative error of the offline estimate (0.1 = 10 % too large).
    pub estimate_error: f64,
    /// Pilot control `(threshold [N], ramp [s])` (paper: 150 N, 80 ms).
    pub pilot: (f64, f64),
    /// Physics step \[s\] (0.5 ms; tests use 2 ms).
    pub dt: f64,
    /// rapier substeps per physics step (4, rapier's default).
    pub substeps: usize,
    /// Largest physics step of the program runs \[s\] ([`PROGRAM_DT`]).
    pub program_dt: f64,
    /// rapier substeps per physics step of the program scenarios, identification and runs
    /// ([`PROGRAM_SUBSTEPS`]).
    pub program_substeps: usize,
    /// Static test loads for the stiffness identification: forces \[N\] along +-x, +-y, +-z
    /// and moments of a quarter of it \[N m\] about them.
    pub id_load: f64,
    /// Number of poses for the stiffness identification (1..=3).
    pub id_poses: usize,
    /// Hold time of each static load before reading \[s\].
    pub id_hold: f64,
    /// Noise of the frame-pair rotation measurements \[rad\] and TCP deflections \[m\].
    pub id_noise: [f64; 2],
    /// Mass of the spindle and tool beyond the TCP \[kg\] in the program scenarios: the
    /// simulated arm carries it (a point mass halfway between the TCP and the sensor) and the
    /// combined run's inertial feed-forward counts it. 0: the built-in KR 300's massless
    /// spindle.
    pub spindle_mass: f64,
    /// Whether the combined run's inertial feed-forward counts the link masses' loads.
    pub link_inertia: bool,
    /// Seed of all noise.
    pub seed: u64,
    /// Worker threads (identification poses, runs); results do not depend on it.
    pub jobs: usize,
}

impl Default for MillingOptions {
    fn default() -> Self {
        Self {
            q0: KR300_Q0.to_vec(),
            sensor: SensorParams::default(),
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
            substeps: 4,
            program_dt: PROGRAM_DT,
            program_substeps: PROGRAM_SUBSTEPS,
            id_load: 800.0,
            id_poses: 3,
            id_hold: 0.25,
            id_noise: [2.0e-6, 2.0e-6],
            spindle_mass: 0.0,
            link_inertia: true,
            seed: 6,
            jobs: 2,
        }
    }
}

impl MillingOptions {
    /// A short scenario for tests: shorter approach, cut and run-out, one identification
    /// pose with shorter holds, noise-free identification.
    pub fn short() -> Self {
        Self {
            settle: 0.02,
            ramp: 0.05,
            approach: 0.1,
            cut: 0.35,
            runout: 0.2,
            id_poses: 1,
            id_noise: [0.0, 0.0],
            ..Self::default()
        }
    }

    /// Cutter entry time \[s\].
    pub fn t_entry(&self) -> f64 {
        self.settle + self.ramp + self.approach
    }

    /// Cutter exit time \[s\].
    pub fn t_exit(&self) -> f64 {
        self.t_entry() + self.cut
    }

    /// End of the run \[s\].
    pub fn t_end(&self) -> f64 {
        self.t_exit() + self.runout
    }

    /// Nominal tool point and velocity at time `t` from `start`: standstill, a (1 - cos) ramp
    /// to the feed, then constant feed along +x.
    pub fn nominal(&self, start: &Vector3<f64>, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let start = *start;
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

    /// The real process force at time `t` \[N\]: smooth steps at entry and exit.
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
