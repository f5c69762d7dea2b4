//! The free spin about the tool axis, chosen along the whole program for the least predicted
//! deflection.
//!
//! A 3-axis program fixes five of the tool's six pose coordinates; the spin `theta` about its
//! axis is free, and the arm's compliance, so its deflection under the process force, changes
//! with it (the posture lever of [`crate::posture`], per point; here along a program). The
//! offline-programming suites turn this spin to avoid joint limits and singularities; this
//! chooses it for stiffness, within the joint limits, a singularity margin and a bound on how
//! fast it may turn (per metre of path and per second: [`schedule`]).
//!
//! The search ([`plan`]) is a shortest path (dynamic programming) over stations x candidate
//! spins ([`loads`]): candidates `theta_j = j step` within `+-range` of the setup's
//! orientation (`theta = 0`, the seed's spin). At every station each candidate's joints come
//! from the rigid pose IK, warm-started from the same candidate at the station before (a
//! continuous IK branch per candidate; at the first station from the seed and then candidate
//! by candidate outwards), kept if they are within the joint limits less
//! [`SpinOptions::limit_margin`], at least [`SpinOptions::min_sigma`] from a singularity and
//! within [`SpinOptions::max_joint_step`] of where they came from. A node's cost is the sum
//! over the cutting samples around its station of their hat weight times the squared
//! [`SpinMeasure`] of the deflection `C(q) w` (the linearised virtual-joint compliance of
//! Hähn and Weigold 2020, Eq. 9, at the node's joints, under each sample's nominal wrench).
//! A step from one station to the next may change the spin by as many candidate steps as the
//! spin budget between them allows, where the joints of both nodes lie within
//! `max_joint_step` of each other. Ties go to the smaller change of spin.
//!
//! The seed's constant spin and every other constant spin are paths of the same graph: the
//! optimised schedule's cost is at most theirs ([`SpinPlan`] reports all three).

pub mod loads;
mod plan;
pub mod schedule;

pub use loads::{LoadPath, MAX_LOADED_SAMPLES, MAX_STATIONS, MIN_STATION_PATH, Station};
pub use plan::{plan, plan_at};
pub(crate) use schedule::Cursor;
pub use schedule::{MAX_SPIN_RATE, SpinSchedule, budget_step};

use alloc::vec::Vec;

use nalgebra::Vector3;

use crate::error::BuildError;

/// Most candidate spins: 721 (a quarter-degree over a full turn each way).
pub const MAX_CANDIDATES: usize = 721;

/// What "deflects least" means for a cut: a measure of the tip's deflection `dp` (workpiece
/// frame) at a sample with feed direction `d` and tool axis `z`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[non_exhaustive]
pub enum SpinMeasure {
    /// `|dp - (dp . d) d|`: normal to the cut (what shows on walls and floors; the
    /// deflection along the feed only shifts the tool along its path).
    #[default]
    Normal,
    /// `|dp|`.
    Position,
    /// `|dp . z|`: along the tool axis (the floor).
    Axial,
    /// `|dp . n|`, `n` the horizontal normal of the feed (`z x d`, unit): the walls.
    Lateral,
}

impl SpinMeasure {
    /// Every measure.
    pub const ALL: [Self; 4] = [Self::Normal, Self::Position, Self::Axial, Self::Lateral];

    /// `"normal"`, `"position"`, `"axial"`, `"lateral"`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Normal => "normal",
            Self::Position => "position",
            Self::Axial => "axial",
            Self::Lateral => "lateral",
        }
    }

    /// The measure of a name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The measure of `dp` \[m\] at feed direction `d` (unit), workpiece frame.
    pub fn of(self, dp: &Vector3<f64>, d: &Vector3<f64>) -> f64 {
        match self {
            Self::Normal => (dp - d * dp.dot(d)).norm(),
            Self::Position => dp.norm(),
            Self::Axial => dp.z.abs(),
            Self::Lateral => {
                let n = Vector3::new(-d.y, d.x, 0.0);
                let len = n.norm();
                if len > 1e-12 {
                    (n.dot(dp) / len).abs()
                } else {
                    0.0
                }
            }
        }
    }
}

/// How the spin is searched.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpinOptions {
    /// Candidate spacing \[rad\], in [0.25, 90] degrees.
    pub step: f64,
    /// Candidates within `+-range` of the setup's orientation \[rad\], in [0, 2 pi].
    pub range: f64,
    /// Largest spin rate along the path \[rad/m\].
    pub per_metre: f64,
    /// Largest spin rate in time \[rad/s\].
    pub per_second: f64,
    /// What is minimised.
    pub measure: SpinMeasure,
    /// Distance kept from every joint limit \[rad or m\], >= 0.
    pub limit_margin: f64,
    /// Singularity margin: least smallest singular value of the joint Jacobian \[m/rad\].
    pub min_sigma: f64,
    /// Largest change of any joint between neighbouring stations on one IK branch \[rad or
    /// m\], > 0: a larger one is a jump to another branch.
    pub max_joint_step: f64,
}

impl Default for SpinOptions {
    /// 5 degree candidates within +-180 degrees of the setup's spin, 1 degree per mm
    /// and 30 degrees per second, the deflection normal to the cut, 1 degree from the limits,
    /// sigma >= 0.05 m/rad (the KR 300 converges slowly in its IK below it, between
    /// stations), joint steps of at most 20 degrees between stations.
    fn default() -> Self {
        Self {
            step: 5f64.to_radians(),
            range: core::f64::consts::PI,
            per_metre: 1f64.to_radians() * 1e3,
            per_second: 30f64.to_radians(),
            measure: SpinMeasure::Normal,
            limit_margin: 1f64.to_radians(),
            min_sigma: 5.0e-2,
            max_joint_step: 20f64.to_radians(),
        }
    }
}

/// The candidate step: in [0.25, 90] degrees.
pub(crate) fn check_step(step: f64) -> Result<(), BuildError> {
    crate::error::param(
        "spin candidate step (rad)",
        step,
        (0.25f64.to_radians()..=core::f64::consts::FRAC_PI_2).contains(&step),
        "in [0.25, 90] degrees",
    )?;
    Ok(())
}

impl SpinOptions {
    /// Checks every option ([`BuildError::InvalidParameter`] naming it).
    pub fn validate(&self) -> Result<(), BuildError> {
        check_step(self.step)?;
        crate::error::param(
            "spin range (rad)",
            self.range,
            (0.0..=core::f64::consts::TAU).contains(&self.range),
            "in [0, 2 pi] rad",
        )?;
        schedule::check_rates(self.per_metre, self.per_second)?;
        crate::error::param(
            "spin joint-limit margin (rad or m)",
            self.limit_margin,
            (0.0..=1.0).contains(&self.limit_margin),
            "in [0, 1]",
        )?;
        crate::error::param(
            "spin singularity margin (m/rad)",
            self.min_sigma,
            (0.0..=1.0).contains(&self.min_sigma),
            "in [0, 1] m/rad",
        )?;
        crate::error::param(
            "spin largest joint step (rad or m)",
            self.max_joint_step,
            self.max_joint_step > 0.0 && self.max_joint_step <= core::f64::consts::PI,
            "in (0, pi]",
        )?;
        Ok(())
    }

    /// The candidate spins \[rad\], ascending (0 among them: the setup's orientation).
    pub fn candidates(&self) -> Vec<f64> {
        let n = nalgebra::ComplexField::floor(self.range / self.step + 1e-9) as i64;
        let n = n.min(((MAX_CANDIDATES - 1) / 2) as i64);
        (-n..=n).map(|j| j as f64 * self.step).collect()
    }
}

/// The predicted deflection of a schedule, over the cutting samples: root mean square and
/// largest of the measure \[m\] (the largest: of the nodes' largest on their samples).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SpinCost {
    /// Root mean square \[m\].
    pub rms: f64,
    /// Largest \[m\].
    pub max: f64,
}

/// What [`plan`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct SpinPlan {
    /// The optimised spin along the program.
    pub schedule: SpinSchedule,
    /// Its predicted deflection.
    pub optimised: SpinCost,
    /// The seed's constant spin (0) and its deflection, `None` where it leaves the limits,
    /// the singularity margin or its branch somewhere.
    pub seed: Option<SpinCost>,
    /// The best constant spin \[rad\] and its deflection (`None` if none holds all along).
    pub best_constant: Option<(f64, SpinCost)>,
    /// The candidate spins \[rad\].
    pub candidates: Vec<f64>,
    /// Stations, and the nodes (station x candidate) refused (IK, limits, singularity,
    /// branch).
    pub stations: usize,
    /// Nodes refused.
    pub refused: usize,
    /// What was minimised.
    pub measure: SpinMeasure,
}
