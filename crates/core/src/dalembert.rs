//! D'Alembert trajectory correction after Paksoy et al. (`shared/papers/002_cf21300bacbb0f8b.txt`,
//! sections 2-3.3, Fig. 2): the planned acceleration `a` of the end effector gives the
//! D'Alembert force `F_D = -m* a` (Eq. 5), a compliance model predicts the displacement that
//! force causes at the planned position (Eq. 9-14), the commanded point is the desired point
//! minus that displacement, and inverse kinematics turns it into joint commands, every servo
//! tick (2 kHz in the paper).
//!
//! Beyond the paper, the command can be iterated to a fixed point `c = x_d - d(c, F_D)`: the
//! compliance model is then evaluated where the robot is actually sent, not where the path
//! is. With `iterations = 0` the corrector is exactly the paper's one-shot update.
//!
//! The corrector is generic over the robot ([`Mechanism`]) and over the compliance model
//! ([`DisplacementModel`]): the paper's compliance map for the 2-DoF parallel robot, or the
//! virtual-joint model of a serial arm ([`VjmDisplacement`]), where the D'Alembert force acts
//! at the TCP. The paper's paths are pure translations, so D'Alembert moments (Euler's part of
//! Eq. 3) are zero there; a serial-arm caller that plans rotations adds them through
//! [`VjmDisplacement::moment`].
//!
//! Every per-tick function allocates nothing, runs in bounded time (at most
//! `1 + iterations` model evaluations and one IK) and never panics.

use core::fmt;

use nalgebra::{SVector, Vector2, Vector3};

use crate::compliance_map::{ComplianceMapView, QueryError, QueryStatus};
use crate::mechanism::{Mechanism, MechanismError};
use crate::motion::{MotionError, Trajectory};
use crate::vjm::{self, Data, Model, Vector6};

/// Why a corrector tick failed. `Copy`, never a panic: the caller decides (hold the last
/// command, stop the motion, ...).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum CorrectorError {
    /// A position or acceleration input holds NaN or an infinity.
    NonFinite {
        /// "position" or "acceleration".
        what: &'static str,
        /// Index of the first non-finite entry.
        index: usize,
    },
    /// The compliance map refused the query (e.g. out of its grid with policy `Error`).
    Map(QueryError),
    /// The compliance map does not have the corrector's force/displacement dimension.
    MapDimension {
        /// Dimension the corrector needs.
        expected: usize,
        /// Force axes of the map.
        n_force: usize,
        /// Displacement axes of the map.
        n_displacement: usize,
    },
    /// The virtual-joint model refused its input.
    Vjm(crate::TickError),
    /// The mechanism could not reach the commanded point (out of workspace, singular, ...).
    Mechanism(MechanismError),
    /// The motion could not be sampled.
    Motion(MotionError),
    /// The mass parameter is not finite and non-negative.
    InvalidMass {
        /// The value [kg].
        mass: f64,
    },
}

impl fmt::Display for CorrectorError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite { what, index } => write!(f, "{what}[{index}] is not finite"),
            Self::Map(e) => write!(f, "compliance map: {e}"),
            Self::MapDimension {
                expected,
                n_force,
                n_displacement,
            } => write!(
                f,
                "compliance map has {n_force} force and {n_displacement} displacement axes; the corrector needs {expected} and {expected}"
            ),
            Self::Vjm(e) => write!(f, "virtual-joint model: {e}"),
            Self::Mechanism(e) => write!(f, "mechanism: {e}"),
            Self::Motion(e) => write!(f, "motion: {e}"),
            Self::InvalidMass { mass } => {
                write!(f, "mass parameter {mass} kg must be finite and >= 0")
            }
        }
    }
}

impl core::error::Error for CorrectorError {}

impl From<MechanismError> for CorrectorError {
    fn from(e: MechanismError) -> Self {
        Self::Mechanism(e)
    }
}
impl From<QueryError> for CorrectorError {
    fn from(e: QueryError) -> Self {
        Self::Map(e)
    }
}
impl From<MotionError> for CorrectorError {
    fn from(e: MotionError) -> Self {
        Self::Motion(e)
    }
}

/// How the compliance model answered: inside its validity range or not.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ModelStatus {
    /// Inside the map's grid (or a model without bounds).
    #[default]
    Inside,
    /// The map clamped the position to its boundary (policy `Clamp`).
    Clamped,
    /// The map extrapolated beyond its boundary (policy `Extrapolate`).
    Extrapolated,
}

impl ModelStatus {
    fn worst(self, other: Self) -> Self {
        match (self, other) {
            (Self::Inside, o) => o,
            (s, Self::Inside) => s,
            (Self::Extrapolated, _) | (_, Self::Extrapolated) => Self::Extrapolated,
            _ => Self::Clamped,
        }
    }
}

/// A compliance model the corrector can query: the static displacement [m] of the task point
/// at `position` [m] (robot at joints `q`) under the force `force` [N] acting there.
pub trait DisplacementModel<const T: usize, const J: usize> {
    /// The displacement and whether the model was inside its range.
    fn displacement(
        &self,
        position: &SVector<f64, T>,
        q: &SVector<f64, J>,
        force: &SVector<f64, T>,
    ) -> Result<(SVector<f64, T>, ModelStatus), CorrectorError>;

    /// Whether [`Self::displacement`] reads `q` (then the corrector solves IK before each
    /// evaluation; a compliance map depends on the position only).
    fn needs_joints(&self) -> bool {
        false
    }
}

/// The paper's compliance map (2 force axes, 2 displacement axes over the (x, y) grid) with
/// the query options stored in the view.
impl<const J: usize> DisplacementModel<2, J> for ComplianceMapView<'_> {
    fn displacement(
        &self,
        position: &Vector2<f64>,
        _q: &SVector<f64, J>,
        force: &Vector2<f64>,
    ) -> Result<(Vector2<f64>, ModelStatus), CorrectorError> {
        if self.n_force() != 2 || self.n_displacement() != 2 {
            return Err(CorrectorError::MapDimension {
                expected: 2,
                n_force: self.n_force(),
                n_displacement: self.n_displacement(),
            });
        }
        let mut out = [0.0; 2];
        let status = self.displacement_with(
            [position.x, position.y],
            force.as_slice(),
            &mut out,
            self.options(),
        )?;
        let status = match status {
            QueryStatus::Inside => ModelStatus::Inside,
            QueryStatus::Clamped => ModelStatus::Clamped,
            QueryStatus::Extrapolated => ModelStatus::Extrapolated,
        };
        Ok((Vector2::new(out[0], out[1]), status))
    }
}

/// The virtual-joint model of a serial arm as a compliance model: the D'Alembert force acts at
/// the TCP (plus an optional constant D'Alembert moment), and the displacement is the TCP
/// translation of [`vjm::deflection`] at the joints `q`.
#[derive(Debug, Clone, Copy)]
pub struct VjmDisplacement<'m> {
    /// The arm.
    pub model: &'m Model,
    /// D'Alembert moment `-(I alpha + omega x I omega)` (Eq. 3) [N m], base frame; zero for
    /// pure translations.
    pub moment: Vector3<f64>,
}

impl<'m> VjmDisplacement<'m> {
    /// Forces only (translational paths).
    pub fn new(model: &'m Model) -> Self {
        Self {
            model,
            moment: Vector3::zeros(),
        }
    }
}

impl<const J: usize> DisplacementModel<3, J> for VjmDisplacement<'_> {
    fn displacement(
        &self,
        _position: &Vector3<f64>,
        q: &SVector<f64, J>,
        force: &Vector3<f64>,
    ) -> Result<(Vector3<f64>, ModelStatus), CorrectorError> {
        let w = Vector6::new(
            force.x,
            force.y,
            force.z,
            self.moment.x,
            self.moment.y,
            self.moment.z,
        );
        let mut data = Data::new(self.model);
        let d = vjm::deflection(self.model, &mut data, q.as_slice(), &w)
            .map_err(CorrectorError::Vjm)?;
        Ok((Vector3::new(d.x, d.y, d.z), ModelStatus::Inside))
    }

    fn needs_joints(&self) -> bool {
        true
    }
}

/// One corrected tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorrectedTick<const T: usize, const J: usize> {
    /// Desired (planned) task point [m].
    pub desired: SVector<f64, T>,
    /// Commanded task point [m]: desired minus the predicted displacement.
    pub commanded: SVector<f64, T>,
    /// Joint command: IK of `commanded` [rad or m].
    pub joints: SVector<f64, J>,
    /// D'Alembert force `-m* a` [N] (Eq. 5).
    pub force: SVector<f64, T>,
    /// Predicted displacement at the commanded point [m].
    pub displacement: SVector<f64, T>,
    /// Fixed-point iterations done (0 = the paper's one-shot update).
    pub iterations: usize,
    /// `|c_k - c_(k-1)|` of the last iteration [m] (0 without iterations).
    pub fixed_point_residual: f64,
    /// Worst compliance-model status met during the tick.
    pub model_status: ModelStatus,
}

/// The D'Alembert corrector's settings. Immutable; one per robot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DalembertCorrector {
    mass: f64,
    iterations: usize,
    tolerance: f64,
}

impl DalembertCorrector {
    /// The paper's tuned mass parameter m* [kg] for its 3.6 kg platform (section 5.1).
    pub const PAPER_MASS: f64 = 5.0;

    /// A corrector with mass parameter `mass` [kg] (m* of the paper), one-shot update.
    pub fn new(mass: f64) -> Result<Self, CorrectorError> {
        if !(mass.is_finite() && mass >= 0.0) {
            return Err(CorrectorError::InvalidMass { mass });
        }
        Ok(Self {
            mass,
            iterations: 0,
            tolerance: 0.0,
        })
    }

    /// Iterate `c = x_d - d(c, F)` at most `iterations` times, stopping once successive
    /// commands differ by at most `tolerance` [m]. Bounded: each iteration costs one model
    /// evaluation (plus one IK for models that read the joints).
    pub fn with_fixed_point(mut self, iterations: usize, tolerance: f64) -> Self {
        self.iterations = iterations;
        self.tolerance = if tolerance.is_finite() && tolerance >= 0.0 {
            tolerance
        } else {
            0.0
        };
        self
    }

    /// Mass parameter m* [kg].
    pub fn mass(&self) -> f64 {
        self.mass
    }
    /// Most fixed-point iterations.
    pub fn iterations(&self) -> usize {
        self.iterations
    }
    /// Fixed-point tolerance [m].
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// One tick: desired point `desired` [m] with planned acceleration `acceleration` [m/s^2];
    /// `seed` are the previous tick's joints (ignored by closed-form IK).
    pub fn step<const T: usize, const J: usize, M, D>(
        &self,
        mechanism: &M,
        model: &D,
        desired: &SVector<f64, T>,
        acceleration: &SVector<f64, T>,
        seed: &SVector<f64, J>,
    ) -> Result<CorrectedTick<T, J>, CorrectorError>
    where
        M: Mechanism<T, J>,
        D: DisplacementModel<T, J>,
    {
        if let Some(index) = desired.iter().position(|v| !v.is_finite()) {
            return Err(CorrectorError::NonFinite {
                what: "position",
                index,
            });
        }
        if let Some(index) = acceleration.iter().position(|v| !v.is_finite()) {
            return Err(CorrectorError::NonFinite {
                what: "acceleration",
                index,
            });
        }
        // Eq. 5: the D'Alembert force of the tuned mass.
        let force = acceleration * (-self.mass);
        let needs_q = model.needs_joints();
        // The paper's update: the model evaluated at the desired point.
        let mut q = if needs_q {
            mechanism.inverse(desired, seed)?
        } else {
            *seed
        };
        let (mut disp, mut status) = model.displacement(desired, &q, &force)?;
        let mut commanded = desired - disp;
        let mut residual = 0.0;
        let mut iterations = 0;
        while iterations < self.iterations {
            if needs_q {
                q = mechanism.inverse(&commanded, &q)?;
            }
            let (d, s) = model.displacement(&commanded, &q, &force)?;
            status = status.worst(s);
            let next = desired - d;
            residual = (next - commanded).norm();
            commanded = next;
            disp = d;
            iterations += 1;
            if residual <= self.tolerance {
                break;
            }
        }
        let joints = mechanism.inverse(&commanded, if needs_q { &q } else { seed })?;
        Ok(CorrectedTick {
            desired: *desired,
            commanded,
            joints,
            force,
            displacement: disp,
            iterations,
            fixed_point_residual: residual,
            model_status: status,
        })
    }

    /// Corrects a whole planned trajectory sampled at `rate_hz`, handing every tick to `sink`
    /// in order. Uses [`Self::step`] tick by tick with the previous joints as seed, so it
    /// agrees exactly with a streaming loop. `seed` seeds the first tick. Allocation-free.
    pub fn correct_each<const T: usize, const J: usize, M, D>(
        &self,
        mechanism: &M,
        model: &D,
        trajectory: &Trajectory<T>,
        rate_hz: f64,
        seed: &SVector<f64, J>,
        mut sink: impl FnMut(usize, &CorrectedTick<T, J>),
    ) -> Result<usize, CorrectorError>
    where
        M: Mechanism<T, J>,
        D: DisplacementModel<T, J>,
    {
        let mut q = *seed;
        let mut n = 0;
        for state in trajectory.ticks(rate_hz)? {
            let tick = self.step(mechanism, model, &state.position, &state.acceleration, &q)?;
            q = tick.joints;
            sink(n, &tick);
            n += 1;
        }
        Ok(n)
    }

    /// [`Self::correct_each`] collected into a vector (needs `alloc`).
    #[cfg(feature = "alloc")]
    pub fn correct<const T: usize, const J: usize, M, D>(
        &self,
        mechanism: &M,
        model: &D,
        trajectory: &Trajectory<T>,
        rate_hz: f64,
        seed: &SVector<f64, J>,
    ) -> Result<alloc::vec::Vec<CorrectedTick<T, J>>, CorrectorError>
    where
        M: Mechanism<T, J>,
        D: DisplacementModel<T, J>,
    {
        let mut out = alloc::vec::Vec::new();
        self.correct_each(mechanism, model, trajectory, rate_hz, seed, |_, t| {
            out.push(*t)
        })?;
        Ok(out)
    }
}
