//! Rigid kinematics behind one interface, so that a D'Alembert corrector (desired
//! acceleration -> force -> compliance map -> corrected task point -> IK, section 3.3 of
//! Paksoy et al., `shared/papers/002_cf21300bacbb0f8b.txt`) does not care which robot it
//! drives.
//!
//! [`Mechanism<T, J>`] has the task dimension `T` and the joint dimension `J` as const
//! parameters (stable Rust cannot size an `SVector` from an associated const), so every
//! quantity is a fixed-size `nalgebra` type: task points `SVector<f64, T>`, joints
//! `SVector<f64, J>`, Jacobians `SMatrix<f64, T, J>`. Nothing allocates or panics; errors are
//! a [`MechanismError`].
//!
//! Implementations:
//! * [`ParallelRobot2`]: the paper's 2-DoF planar parallel robot, `Mechanism<2, 2>`,
//!   closed-form IK/FK.
//! * [`SerialArm`]: a [`crate::vjm::Model`] (serial arm with `J` joints), `Mechanism<3, J>`:
//!   the task is the rigid TCP position; IK by bounded damped least squares from a seed.

use core::fmt;

use nalgebra::{ComplexField, Matrix2, Matrix3, RealField, SMatrix, SVector, Vector2, Vector3};

use crate::error::TickError;
use crate::vjm::{self, Data, Model};

/// Why a kinematic call failed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum MechanismError {
    /// An input holds NaN or an infinity.
    NonFinite {
        /// Which input ("x", "q", "seed").
        what: &'static str,
        /// Index of the first non-finite entry.
        index: usize,
    },
    /// The task point cannot be reached at all.
    OutOfWorkspace {
        /// Task x [m].
        x: f64,
        /// Task y [m].
        y: f64,
        /// Largest distance from the base centre that can be reached [m].
        reach: f64,
    },
    /// The point is reachable but at or too near a singularity: the smallest singular value
    /// of the task Jacobian (see [`Mechanism::singularity_distance`]) is below the
    /// mechanism's threshold.
    Singular {
        /// Smallest singular value of the task Jacobian [m/rad].
        distance: f64,
    },
    /// An iterative IK did not reach its tolerance within its iteration budget.
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// Task-space error left [m].
        residual: f64,
    },
    /// A serial model's number of joints differs from the `J` of [`SerialArm<J>`].
    WrongDof {
        /// `J`.
        expected: usize,
        /// [`Model::dof`].
        got: usize,
    },
    /// A geometric or solver parameter is not finite or not > 0.
    InvalidParameter {
        /// Its name.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// An underlying per-tick call failed.
    Tick {
        /// The error of the VJM call.
        error: TickError,
    },
}

impl fmt::Display for MechanismError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite { what, index } => write!(f, "{what}[{index}] is not finite"),
            Self::OutOfWorkspace { x, y, reach } => write!(
                f,
                "point ({x}, {y}) m is out of the workspace (reach {reach} m)"
            ),
            Self::Singular { distance } => write!(
                f,
                "singular pose: smallest singular value of the Jacobian is {distance:e} m/rad"
            ),
            Self::NotConverged {
                iterations,
                residual,
            } => write!(
                f,
                "IK did not converge in {iterations} iterations (residual {residual:e} m)"
            ),
            Self::WrongDof { expected, got } => {
                write!(
                    f,
                    "the model has {got} joints, the mechanism expects {expected}"
                )
            }
            Self::InvalidParameter { what, value } => {
                write!(f, "{what} is {value}; it must be finite and > 0")
            }
            Self::Tick { error } => write!(f, "{error}"),
        }
    }
}

impl core::error::Error for MechanismError {}

impl From<TickError> for MechanismError {
    fn from(error: TickError) -> Self {
        match error {
            TickError::NonFinite { what, index } => Self::NonFinite { what, index },
            TickError::Singular { sigma_min } => Self::Singular {
                distance: sigma_min,
            },
            TickError::NotConverged {
                iterations,
                residual,
            } => Self::NotConverged {
                iterations,
                residual,
            },
            error => Self::Tick { error },
        }
    }
}

/// Rigid kinematics of a robot with `J` joints whose task is a point in `T` dimensions.
///
/// A corrector written against `M: Mechanism<T, J>` gets everything it needs: `inverse` to
/// turn the corrected task point into joint commands (seeded with the previous tick's
/// joints), `forward` and `jacobian` to map back, and `singularity_distance` to refuse
/// commands near a singularity.
pub trait Mechanism<const T: usize, const J: usize> {
    /// Joints that put the task point on `x`. Closed-form solvers ignore `seed`; iterative
    /// ones start from it (pass the previous tick's joints).
    fn inverse(
        &self,
        x: &SVector<f64, T>,
        seed: &SVector<f64, J>,
    ) -> Result<SVector<f64, J>, MechanismError>;

    /// Task point of joints `q`.
    fn forward(&self, q: &SVector<f64, J>) -> Result<SVector<f64, T>, MechanismError>;

    /// Task Jacobian `dx/dq` at `q` [m/rad or m/m].
    fn jacobian(&self, q: &SVector<f64, J>) -> Result<SMatrix<f64, T, J>, MechanismError>;

    /// Distance to the nearest singularity: the smallest singular value of [`Self::jacobian`]
    /// at `q` [m/rad] (0 at a singularity; the task speed the worst-placed unit joint speed
    /// still produces).
    fn singularity_distance(&self, q: &SVector<f64, J>) -> Result<f64, MechanismError>;
}

fn check_finite<const D: usize>(
    what: &'static str,
    v: &SVector<f64, D>,
) -> Result<(), MechanismError> {
    match v.iter().position(|c| !c.is_finite()) {
        Some(index) => Err(MechanismError::NonFinite { what, index }),
        None => Ok(()),
    }
}

fn positive(what: &'static str, value: f64) -> Result<f64, MechanismError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(MechanismError::InvalidParameter { what, value })
    }
}

/// Smallest singular value of a 2 x 2 matrix, closed form.
fn sigma_min2(m: &Matrix2<f64>) -> f64 {
    // Eigenvalues of M^T M: (tr +- sqrt(tr^2 - 4 det^2)) / 2.
    let g = m.transpose() * m;
    let tr = g.trace();
    let det = m.determinant();
    let disc = (tr * tr - 4.0 * det * det).max(0.0);
    let lmin = (0.5 * (tr - ComplexField::sqrt(disc))).max(0.0);
    ComplexField::sqrt(lmin)
}

/// Link length of the paper's robot: every arm link is 150 mm (section 4.1) [m].
pub const PAPER_LINK: f64 = 0.150;
/// Distance of the base pivots A0, B0 from the base centre O, and of the platform joints D,
/// E from the tool point C: 90 mm (section 4.1) [m].
pub const PAPER_HALF_WIDTH: f64 = 0.090;
/// Default singularity threshold of [`ParallelRobot2`]: the smallest Jacobian singular value
/// must be at least 20 mm/rad. Over the paper's grid it is at least 72 mm/rad; the
/// threshold cuts off the last ~1.3 mm before full stretch (reach 298.7 mm of 300 mm).
pub const DEFAULT_MIN_SIGMA: f64 = 0.020;

/// The paper's 2-DoF planar parallel robot (over- or normal-constrained, the same rigid
/// kinematics: section 4.1), as read in `shared/data/README.md`.
///
/// # Geometry and frame
/// Base centre O at the origin; base pivots A0 = (0, +h) and B0 = (0, -h) with
/// h = [`PAPER_HALF_WIDTH`]; x along the robot's symmetry axis, away from the base, y
/// lateral. The parallelograms keep the platform's orientation, so
/// `C - O = D - A0 = E - B0 = p`: each arm is a 2R chain of two links of length
/// L = [`PAPER_LINK`] reaching the same relative point `p`.
///
/// **Task coordinates are `p = (x, y)` = C - O**, the frame of the paper's static-test grid
/// (x = 0.122132 + 0.05 i, y = -0.1125 + 0.0375 j, i = 1..3, j = 1..5), whose nodes lie at
/// 183..282 mm from O.
///
/// # Kinematics
/// Joints `q = (theta_A, theta_B)`: the angles of the actuated links A0A and B0B from +x.
/// FK: `p = L (u(theta_A) + u(theta_B))` with `u(a) = (cos a, sin a)`, i.e.
/// `p = 2 L cos(Delta/2) (cos sigma, sin sigma)`, `sigma = (theta_A + theta_B)/2`,
/// `Delta = theta_A - theta_B` (the distal link of arm A is parallel to the actuated link of
/// arm B and vice versa). Jacobian: columns `L u'(theta_A)`, `L u'(theta_B)`, with singular
/// values `sqrt(2) L cos(Delta/2)` and `sqrt(2) L sin(Delta/2)`, `|det| = L^2 |sin Delta|`.
///
/// IK, working mode "elbows out": `r = |p|`, `sigma = atan2(y, x)`,
/// `beta = acos(r / 2L)`, `theta_A = sigma + beta` (elbow A on the +y side, A0's side),
/// `theta_B = sigma - beta`, so `Delta = 2 beta` is in (0, pi). Points with `r > 2L` are
/// [`MechanismError::OutOfWorkspace`]; points whose Jacobian's smallest singular value is
/// below `min_sigma` (near full stretch, `r -> 2L`, or near the base centre, `r -> 0`) are
/// [`MechanismError::Singular`]. FK and Jacobian accept any finite joints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParallelRobot2 {
    link: f64,
    half_width: f64,
    min_sigma: f64,
}

impl Default for ParallelRobot2 {
    fn default() -> Self {
        Self::paper()
    }
}

impl ParallelRobot2 {
    /// The paper's robot: L = 150 mm, pivots 90 mm from O, threshold [`DEFAULT_MIN_SIGMA`].
    pub fn paper() -> Self {
        Self {
            link: PAPER_LINK,
            half_width: PAPER_HALF_WIDTH,
            min_sigma: DEFAULT_MIN_SIGMA,
        }
    }

    /// A robot of link length `link` [m], pivots `half_width` [m] from O, singularity
    /// threshold `min_sigma` [m/rad]; each must be finite and > 0.
    pub fn new(link: f64, half_width: f64, min_sigma: f64) -> Result<Self, MechanismError> {
        Ok(Self {
            link: positive("link", link)?,
            half_width: positive("half_width", half_width)?,
            min_sigma: positive("min_sigma", min_sigma)?,
        })
    }

    /// Link length L [m].
    pub fn link(&self) -> f64 {
        self.link
    }
    /// Distance of A0, B0 from O [m].
    pub fn half_width(&self) -> f64 {
        self.half_width
    }
    /// Singularity threshold [m/rad].
    pub fn min_sigma(&self) -> f64 {
        self.min_sigma
    }
    /// Largest reach `2 L` from O [m] (singular there).
    pub fn reach(&self) -> f64 {
        2.0 * self.link
    }

    /// The joint points at `q`, base frame [m]:
    /// `[A0, A (elbow), D, B0, B (elbow), E, C]`.
    pub fn points(&self, q: &Vector2<f64>) -> [Vector2<f64>; 7] {
        let l = self.link;
        let ua = Vector2::new(ComplexField::cos(q.x), ComplexField::sin(q.x));
        let ub = Vector2::new(ComplexField::cos(q.y), ComplexField::sin(q.y));
        let p = (ua + ub) * l;
        let a0 = Vector2::new(0.0, self.half_width);
        let b0 = Vector2::new(0.0, -self.half_width);
        [a0, a0 + ua * l, a0 + p, b0, b0 + ub * l, b0 + p, p]
    }

    /// Closed-form IK (see the type docs); same as [`Mechanism::inverse`] without a seed.
    pub fn ik(&self, p: &Vector2<f64>) -> Result<Vector2<f64>, MechanismError> {
        check_finite("x", p)?;
        let r = p.norm();
        let reach = self.reach();
        if r > reach {
            return Err(MechanismError::OutOfWorkspace {
                x: p.x,
                y: p.y,
                reach,
            });
        }
        // cos(Delta/2) = r / 2L, sin(Delta/2) = sqrt(1 - (r/2L)^2).
        let c = r / reach;
        let s = ComplexField::sqrt((1.0 - c * c).max(0.0));
        let distance = core::f64::consts::SQRT_2 * self.link * c.min(s);
        if distance < self.min_sigma {
            return Err(MechanismError::Singular { distance });
        }
        let sigma = RealField::atan2(p.y, p.x);
        let beta = RealField::atan2(s, c);
        Ok(Vector2::new(sigma + beta, sigma - beta))
    }

    /// Closed-form FK `p = L (u(theta_A) + u(theta_B))`.
    pub fn fk(&self, q: &Vector2<f64>) -> Result<Vector2<f64>, MechanismError> {
        check_finite("q", q)?;
        let l = self.link;
        Ok(Vector2::new(
            l * (ComplexField::cos(q.x) + ComplexField::cos(q.y)),
            l * (ComplexField::sin(q.x) + ComplexField::sin(q.y)),
        ))
    }

    /// Jacobian `dp/dq = L [u'(theta_A), u'(theta_B)]` [m/rad].
    pub fn jacobian_at(&self, q: &Vector2<f64>) -> Result<Matrix2<f64>, MechanismError> {
        check_finite("q", q)?;
        let l = self.link;
        Ok(Matrix2::new(
            -l * ComplexField::sin(q.x),
            -l * ComplexField::sin(q.y),
            l * ComplexField::cos(q.x),
            l * ComplexField::cos(q.y),
        ))
    }
}

impl Mechanism<2, 2> for ParallelRobot2 {
    fn inverse(
        &self,
        x: &Vector2<f64>,
        _seed: &Vector2<f64>,
    ) -> Result<Vector2<f64>, MechanismError> {
        self.ik(x)
    }
    fn forward(&self, q: &Vector2<f64>) -> Result<Vector2<f64>, MechanismError> {
        self.fk(q)
    }
    fn jacobian(&self, q: &Vector2<f64>) -> Result<Matrix2<f64>, MechanismError> {
        self.jacobian_at(q)
    }
    fn singularity_distance(&self, q: &Vector2<f64>) -> Result<f64, MechanismError> {
        Ok(sigma_min2(&self.jacobian_at(q)?))
    }
}

/// Settings of [`SerialArm`]'s damped-least-squares IK.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkOptions {
    /// Iteration budget (bounds the time of a call).
    pub max_iterations: usize,
    /// Position tolerance [m].
    pub tolerance: f64,
    /// Damping `lambda` of `dq = J^T (J J^T + lambda^2 I)^-1 e` [m/rad].
    pub damping: f64,
    /// Largest joint step per iteration (Euclidean norm) [rad].
    pub max_step: f64,
    /// Singularity threshold on the smallest singular value of the 3 x J position Jacobian
    /// [m/rad].
    pub min_sigma: f64,
}

impl Default for IkOptions {
    /// 50 iterations, 1e-9 m, damping 1e-3 m/rad, steps of at most 0.5 rad, threshold
    /// 1e-4 m/rad.
    fn default() -> Self {
        Self {
            max_iterations: 50,
            tolerance: 1.0e-9,
            damping: 1.0e-3,
            max_step: 0.5,
            min_sigma: 1.0e-4,
        }
    }
}

/// A serial arm ([`crate::vjm::Model`] with exactly `J` joints) as a `Mechanism<3, J>`: the
/// task is the rigid TCP position in the base frame (orientation is left free, so a 6R arm
/// is redundant here and the IK keeps it close to the seed).
///
/// Each call works in a [`Data`] on the stack (no heap; about 2 kB).
#[derive(Debug, Clone, Copy)]
pub struct SerialArm<'m, const J: usize> {
    model: &'m Model,
    options: IkOptions,
}

impl<'m, const J: usize> SerialArm<'m, J> {
    /// Wraps `model`; its [`Model::dof`] must be `J`.
    pub fn new(model: &'m Model, options: IkOptions) -> Result<Self, MechanismError> {
        if model.dof() != J {
            return Err(MechanismError::WrongDof {
                expected: J,
                got: model.dof(),
            });
        }
        positive("tolerance", options.tolerance)?;
        positive("damping", options.damping)?;
        positive("max_step", options.max_step)?;
        positive("min_sigma", options.min_sigma)?;
        Ok(Self { model, options })
    }

    /// The wrapped model.
    pub fn model(&self) -> &'m Model {
        self.model
    }
    /// The IK settings.
    pub fn options(&self) -> IkOptions {
        self.options
    }

    fn fk_jac(
        &self,
        data: &mut Data,
        q: &SVector<f64, J>,
    ) -> Result<(Vector3<f64>, SMatrix<f64, 3, J>), MechanismError> {
        vjm::joint_jacobian(self.model, data, q.as_slice())?;
        let x = data.tcp.translation.vector;
        let jac =
            SMatrix::<f64, 3, J>::from_fn(|r, c| data.jacobian.get((r, c)).copied().unwrap_or(0.0));
        Ok((x, jac))
    }
}

/// Smallest singular value of a 3 x J matrix via the eigenvalues of `J J^T` (0 if J < 3 or
/// the eigen-solver does not converge).
fn sigma_min3<const J: usize>(jac: &SMatrix<f64, 3, J>) -> f64 {
    let g: Matrix3<f64> = jac * jac.transpose();
    match nalgebra::SymmetricEigen::try_new(g, 1.0e-15, 100) {
        Some(e) => ComplexField::sqrt(e.eigenvalues.min().max(0.0)),
        None => 0.0,
    }
}

impl<const J: usize> Mechanism<3, J> for SerialArm<'_, J> {
    /// Damped least squares from `seed`: `dq = J^T (J J^T + lambda^2 I)^-1 (x - FK(q))`, the
    /// step clipped to `max_step`, at most `max_iterations` steps. Fails with
    /// [`MechanismError::Singular`] if the final pose's smallest singular value is below
    /// `min_sigma`, else [`MechanismError::NotConverged`] if the residual is above
    /// `tolerance` (e.g. a target out of reach).
    fn inverse(
        &self,
        x: &Vector3<f64>,
        seed: &SVector<f64, J>,
    ) -> Result<SVector<f64, J>, MechanismError> {
        check_finite("x", x)?;
        check_finite("seed", seed)?;
        let o = self.options;
        let mut data = Data::new(self.model);
        let mut q = *seed;
        let lambda2 = o.damping * o.damping;
        let mut iterations = 0;
        loop {
            let (fx, jac) = self.fk_jac(&mut data, &q)?;
            let e = x - fx;
            let residual = e.norm();
            if residual <= o.tolerance || iterations >= o.max_iterations {
                let distance = sigma_min3(&jac);
                if distance < o.min_sigma {
                    return Err(MechanismError::Singular { distance });
                }
                if residual <= o.tolerance {
                    return Ok(q);
                }
                return Err(MechanismError::NotConverged {
                    iterations,
                    residual,
                });
            }
            let g = jac * jac.transpose() + Matrix3::identity() * lambda2;
            let Some(w) = g.cholesky().map(|c| c.solve(&e)) else {
                let distance = sigma_min3(&jac);
                return Err(MechanismError::Singular { distance });
            };
            let mut dq = jac.transpose() * w;
            let n = dq.norm();
            if n > o.max_step {
                dq *= o.max_step / n;
            }
            q += dq;
            iterations += 1;
        }
    }

    fn forward(&self, q: &SVector<f64, J>) -> Result<Vector3<f64>, MechanismError> {
        let mut data = Data::new(self.model);
        Ok(vjm::forward(self.model, &mut data, q.as_slice())?
            .translation
            .vector)
    }

    fn jacobian(&self, q: &SVector<f64, J>) -> Result<SMatrix<f64, 3, J>, MechanismError> {
        let mut data = Data::new(self.model);
        Ok(self.fk_jac(&mut data, q)?.1)
    }

    fn singularity_distance(&self, q: &SVector<f64, J>) -> Result<f64, MechanismError> {
        Ok(sigma_min3(&self.jacobian(q)?))
    }
}
