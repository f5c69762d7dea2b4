//! The 2-DoF planar parallel robot of Paksoy, Dede and Kiper (2025), section 4.1: closed-form
//! IK, FK and Jacobian.

use nalgebra::{ComplexField, Matrix2, RealField, Vector2};

use super::{Mechanism, check_finite, positive};
use crate::error::{BuildError, TickError};

/// Link length of the paper's robot: every arm link is 150 mm (section 4.1) \[m\].
pub const PAPER_LINK: f64 = 0.150;
/// Distance of the base pivots A0, B0 from the base centre O, and of the platform joints D,
/// E from the tool point C: 90 mm (section 4.1) \[m\].
pub const PAPER_HALF_WIDTH: f64 = 0.090;
/// Default singularity threshold of [`ParallelRobot2`]: the smallest Jacobian singular value
/// must be at least 20 mm/rad. Over the paper's grid it is at least 72 mm/rad; the
/// threshold cuts off the last ~1.3 mm before full stretch (reach 298.7 mm of 300 mm).
pub const DEFAULT_MIN_SIGMA: f64 = 0.020;

/// The paper's 2-DoF planar parallel robot (over- or normal-constrained, the same rigid
/// kinematics: section 4.1), with the dimensions of section 4.1.
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
/// [`TickError::OutOfWorkspace`]; points whose Jacobian's smallest singular value is
/// below `min_sigma` (near full stretch, `r -> 2L`, or near the base centre, `r -> 0`) are
/// [`TickError::Singular`]. FK and Jacobian accept any finite joints.
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

    /// A robot of link length `link` \[m\], pivots `half_width` \[m\] from O, singularity
    /// threshold `min_sigma` \[m/rad\]; each must be finite and > 0.
    pub fn new(link: f64, half_width: f64, min_sigma: f64) -> Result<Self, BuildError> {
        Ok(Self {
            link: positive("link", link)?,
            half_width: positive("half_width", half_width)?,
            min_sigma: positive("min_sigma", min_sigma)?,
        })
    }

    /// Link length L \[m\].
    pub fn link(&self) -> f64 {
        self.link
    }
    /// Distance of A0, B0 from O \[m\].
    pub fn half_width(&self) -> f64 {
        self.half_width
    }
    /// Singularity threshold \[m/rad\].
    pub fn min_sigma(&self) -> f64 {
        self.min_sigma
    }
    /// Largest reach `2 L` from O \[m\] (singular there).
    pub fn reach(&self) -> f64 {
        2.0 * self.link
    }

    /// The joint points at `q`, base frame \[m\]:
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
    pub fn ik(&self, p: &Vector2<f64>) -> Result<Vector2<f64>, TickError> {
        check_finite("x", p)?;
        let r = p.norm();
        let reach = self.reach();
        if r > reach {
            return Err(TickError::OutOfWorkspace { distance: r, reach });
        }
        // cos(Delta/2) = r / 2L, sin(Delta/2) = sqrt(1 - (r/2L)^2).
        let c = r / reach;
        let s = ComplexField::sqrt((1.0 - c * c).max(0.0));
        let distance = core::f64::consts::SQRT_2 * self.link * c.min(s);
        if distance < self.min_sigma {
            return Err(TickError::Singular {
                what: "task Jacobian",
                sigma_min: distance,
            });
        }
        let sigma = RealField::atan2(p.y, p.x);
        let beta = RealField::atan2(s, c);
        Ok(Vector2::new(sigma + beta, sigma - beta))
    }

    /// Closed-form FK `p = L (u(theta_A) + u(theta_B))`.
    pub fn fk(&self, q: &Vector2<f64>) -> Result<Vector2<f64>, TickError> {
        check_finite("q", q)?;
        let l = self.link;
        Ok(Vector2::new(
            l * (ComplexField::cos(q.x) + ComplexField::cos(q.y)),
            l * (ComplexField::sin(q.x) + ComplexField::sin(q.y)),
        ))
    }

    /// Jacobian `dp/dq = L [u'(theta_A), u'(theta_B)]` \[m/rad\].
    pub fn jacobian_at(&self, q: &Vector2<f64>) -> Result<Matrix2<f64>, TickError> {
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
    type Data = ();
    fn new_data(&self) {}
    fn inverse(
        &self,
        _data: &mut (),
        x: &Vector2<f64>,
        _seed: &Vector2<f64>,
    ) -> Result<Vector2<f64>, TickError> {
        self.ik(x)
    }
    fn forward(&self, _data: &mut (), q: &Vector2<f64>) -> Result<Vector2<f64>, TickError> {
        self.fk(q)
    }
    fn jacobian(&self, _data: &mut (), q: &Vector2<f64>) -> Result<Matrix2<f64>, TickError> {
        self.jacobian_at(q)
    }
    fn singularity_distance(&self, _data: &mut (), q: &Vector2<f64>) -> Result<f64, TickError> {
        Ok(sigma_min2(&self.jacobian_at(q)?))
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
