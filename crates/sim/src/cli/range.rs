//! The documented range of every numeric flag ([`Range`], shown in its `--help` and checked
//! before any work) and the ranges themselves.

use std::fmt;

use super::CliError;

/// The documented range of a numeric flag: `[min, max]` (`(min, max)` if `open`), with its
/// unit. Shown in the flag's `--help` ([`Range::help`]) and checked before any work
/// ([`Range::check`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// The flag, `--cut`.
    pub flag: &'static str,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Both ends excluded.
    pub open: bool,
    /// Unit ("" if none).
    pub unit: &'static str,
}

impl Range {
    /// `[min, max]` in `unit`.
    const fn closed(flag: &'static str, min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            flag,
            min,
            max,
            open: false,
            unit,
        }
    }

    /// The range as written in help and errors: "[0.01, 5] s", "(1.5, 30) N", "[1, 64]".
    pub fn text(&self) -> String {
        let (l, r) = if self.open { ('(', ')') } else { ('[', ']') };
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!("{l}{}, {}{r}{unit}", self.min, self.max)
    }

    /// The help of the flag: "`what`. Range: <text>. `more`."
    pub fn help(&self, what: &str, more: &str) -> String {
        let more = if more.is_empty() {
            String::new()
        } else {
            format!(" {more}.")
        };
        format!("{what}. Range: {}.{more}", self.text())
    }

    /// Whether `v` is in the range (NaN is not).
    pub fn contains(&self, v: f64) -> bool {
        if self.open {
            v > self.min && v < self.max
        } else {
            v >= self.min && v <= self.max
        }
    }

    /// `v` in the range, or the usage error "--flag v is out of range: allowed <text>".
    pub fn check(&self, v: f64) -> Result<(), CliError> {
        self.check_shown(v, &shown(v))
    }

    /// [`Range::check`] of an integer flag (shown as given; u64 -> f64 rounds only above
    /// 2^53, far outside every integer range here).
    pub fn check_int(&self, v: impl Into<u64> + Copy + fmt::Display) -> Result<(), CliError> {
        self.check_shown(v.into() as f64, &v.to_string())
    }

    fn check_shown(&self, v: f64, shown: &str) -> Result<(), CliError> {
        if self.contains(v) {
            Ok(())
        } else {
            Err(CliError::Usage(format!(
                "{} {shown} is out of range: allowed {}",
                self.flag,
                self.text()
            )))
        }
    }
}

/// A float as the errors show it: plain, or in exponent form when very large or small.
pub fn shown(v: f64) -> String {
    let a = v.abs();
    if v.is_finite() && a != 0.0 && !(1e-4..1e6).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// `reproduce --mass`, `run --mass` \[kg\].
pub const MASS: Range = Range::closed("--mass", 0.0, 50.0, "kg");
/// `reproduce --g` (each level), `run --g`.
pub const G_LEVEL: Range = Range::closed("--g", 1.0, 5.0, "g");
/// `reproduce --fixed-point`.
pub const FIXED_POINT: Range = Range::closed("--fixed-point", 0.0, 50.0, "");
/// `reproduce --jobs`, `contour --jobs`: 0 is refused (it used to mean 1).
pub const JOBS: Range = Range::closed("--jobs", 1.0, 64.0, "");
/// `milling --feed` \[mm/s\]: with the longest cut the groove stays within 300 mm, well inside
/// the arm's reach.
pub const FEED: Range = Range::closed("--feed", 0.1, 50.0, "mm/s");
/// `milling --force` \[N\].
pub const FORCE: Range = Range::closed("--force", 0.0, 2000.0, "N");
/// `milling --cut` \[s\]: at most 4 x 6.2 s simulated at 0.5 ms plus the identification's
/// 10 s, about 1.5 min on 2 cores.
pub const CUT: Range = Range::closed("--cut", 0.01, 5.0, "s");
/// `milling --rise-ms` \[ms\]: within the 0.4 s run-out.
pub const RISE_MS: Range = Range::closed("--rise-ms", 0.1, 300.0, "ms");
/// `milling --cycle-ms` \[ms\], also a multiple of the 0.5 ms physics step.
pub const CYCLE_MS: Range = Range::closed("--cycle-ms", 0.5, 20.0, "ms");
/// `milling --lead-ms` \[ms\].
pub const LEAD_MS: Range = Range::closed("--lead-ms", 0.0, 500.0, "ms");
/// `milling --estimate-error`.
pub const ESTIMATE_ERROR: Range = Range::closed("--estimate-error", -1.0, 1.0, "");
/// `milling --id-poses`: poses of the stiffness identification.
pub const ID_POSES: Range = Range::closed("--id-poses", 1.0, 3.0, "");
/// `milling --step-ms` \[ms\]: the program runs' largest physics step.
pub const PHYSICS_STEP_MS: Range = Range::closed("--step-ms", 0.1, 2.0, "ms");
/// `milling --spindle-mass` \[kg\]: the KR 300's spindles weigh tens of kg.
pub const SPINDLE_MASS: Range = Range::closed("--spindle-mass", 0.0, 500.0, "kg");
/// `milling --substeps`: rapier substeps per physics step of the program scenarios.
pub const SUBSTEPS: Range = Range::closed("--substeps", 1.0, 8.0, "");
/// `contour --step-mm` \[mm\].
pub const STEP_MM: Range = Range::closed("--step-mm", 0.2, 20.0, "mm");
/// `contour --target-force` \[N\]: strictly between the tracer's contact and jam forces.
pub const TARGET_FORCE: Range = Range {
    flag: "--target-force",
    min: 1.5,
    max: 30.0,
    open: true,
    unit: "N",
};
/// `contour --noise` \[N\].
pub const NOISE: Range = Range::closed("--noise", 0.0, 5.0, "N");
/// `serial --g`: peak acceleration of the motions.
pub const SERIAL_G: Range = Range::closed("--g", 0.05, 5.0, "g");
/// `serial --payload-mass` \[kg\].
pub const PAYLOAD_MASS: Range = Range::closed("--payload-mass", 0.0, 2000.0, "kg");
/// `serial --scale` \[m\]: the line is `(0.3, 0.2, -0.1) scale`, the circle's radius `0.15 scale`.
pub const SCALE: Range = Range::closed("--scale", 0.01, 3.0, "m");
/// `serial --v-max` \[m/s\].
pub const V_MAX: Range = Range::closed("--v-max", 0.01, 10.0, "m/s");
/// `serial --ramp` \[s\]: time to ramp the acceleration up (sets the jerk).
pub const RAMP: Range = Range::closed("--ramp", 0.005, 1.0, "s");
/// `serial --turn` \[rad\]: turn about the vertical over a motion.
pub const TURN: Range = Range::closed("--turn", 0.0, 3.0, "rad");
/// `atlas --region`: grid points per axis (at most 100 x 100 points x 3600 angles, about a
/// minute on 2 cores).
pub const ATLAS_POINTS: Range = Range::closed("--region", 1.0, 100.0, "points per axis");
/// `atlas --angle-step` \[deg\].
pub const ANGLE_STEP: Range = Range::closed("--angle-step", 0.1, 90.0, "deg");
/// `job --cell`: z-map resolution.
pub const CELL_MM: Range = Range::closed("--cell", 0.01, 10.0, "mm");
/// `job --log-rate`.
pub const LOG_RATE_HZ: Range = Range::closed("--log-rate", 0.0, 10000.0, "Hz");
/// `job --diameter`: end mill diameter.
pub const DIAMETER_MM: Range = Range::closed("--diameter", 0.1, 200.0, "mm");
/// `job --flutes`.
pub const FLUTES: Range = Range::closed("--flutes", 1.0, 16.0, "");
/// How deep a rapid may run into the stock.
pub const RAPID_SKIM_MM: Range = Range::closed("--rapid-skim", 0.0, 100.0, "mm");
/// A hand-started spindle's speed.
pub const SPINDLE_RPM: Range = Range::closed("--spindle-rpm", 1.0, 1.0e6, "rpm");
/// `job --helix`.
pub const HELIX_DEG: Range = Range::closed("--helix", 0.0, 60.0, "deg");
/// `job --rate`: sampling rate of the program.
pub const RATE_HZ: Range = Range::closed("--rate", 1.0, 10000.0, "Hz");
/// `job --acceleration`: path acceleration limit.
pub const PATH_ACCELERATION: Range = Range::closed("--acceleration", 0.01, 100.0, "m/s^2");
/// `job --jerk`: path jerk limit.
pub const PATH_JERK: Range = Range::closed("--jerk", 0.1, 10000.0, "m/s^3");
/// `job --rapid-speed`.
pub const RAPID_SPEED: Range = Range::closed("--rapid-speed", 0.001, 10.0, "m/s");
/// `job --tolerance`: decimation of the compensated program.
pub const TOLERANCE_MM: Range = Range::closed("--tolerance", 1e-5, 1.0, "mm");
/// `job --spin DEG`: a constant spin about the tool axis.
pub const SPIN_DEG: Range = Range::closed("--spin", -720.0, 720.0, "degrees");
/// `job --spin-step`: the spin search's candidate spacing.
pub const SPIN_STEP_DEG: Range = Range::closed("--spin-step", 0.25, 90.0, "degrees");
/// `job --spin-rate`: the spin's rate bounds, per mm of path and per second.
pub const SPIN_RATE_PER_MM: Range =
    Range::closed("--spin-rate (per mm)", 1e-6, 1000.0, "degrees/mm");
/// See [`SPIN_RATE_PER_MM`].
pub const SPIN_RATE_PER_S: Range =
    Range::closed("--spin-rate (per second)", 1e-6, 1.0e5, "degrees/s");
/// `job --top`: stock top.
pub const TOP_MM: Range = Range::closed("--top", -1000.0, 1000.0, "mm");
/// `job --stock-depth`: the five-axis stock's depth below its top.
pub const STOCK_DEPTH_MM: Range = Range::closed("--stock-depth", 0.1, 1000.0, "mm");
/// `job --flute-length`: the length of the tool that removes material (five-axis).
pub const FLUTE_LENGTH_MM: Range = Range::closed("--flute-length", 0.1, 1000.0, "mm");
/// Peak acceleration of the Delta's move.
pub const DELTA_G: Range = Range::closed("--g", 1.0, 15.0, "g");
/// The Delta's payload.
pub const DELTA_PAYLOAD: Range = Range::closed("--payload-mass", 0.0, 10.0, "kg");
/// Static-test grid nodes per axis.
pub const DELTA_NODES: Range = Range::closed("--nodes", 2.0, 6.0, "");
/// Static-test force.
pub const DELTA_TEST_FORCE: Range = Range::closed("--test-force", 1.0, 500.0, "N");
