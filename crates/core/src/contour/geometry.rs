//! The contact geometry of the contour-tracking paper (Eq. 11-21): contact force of a
//! compliant position-controlled robot, sliding along a rigid edge, and the edge direction
//! recovered from the steady-state force.

use nalgebra::{ComplexField, Matrix2, RealField, Vector2};

use crate::error::{TickError, check_finite, check_output};

/// Smallest accepted `det(K) / (|K|_F^2 / 2)` (about `2 lambda_min / lambda_max` for a
/// symmetric K) before `K` counts as singular.
pub const MIN_RECIPROCAL_CONDITION: f64 = 1.0e-10;

pub(super) fn finite2(what: &'static str, v: &Vector2<f64>) -> Result<(), TickError> {
    check_finite(what, v.as_slice())
}

/// `K^-1`, or an error if `K` is not finite ([`TickError::NonFinite`]), not positive
/// definite (the stiffness of a robot pushes back along every direction: its symmetric
/// part's smallest eigenvalue must be > 0) or singular ([`TickError::Singular`] carries
/// that eigenvalue, or `det(K) / (|K|_F^2 / 2)` when `K` is ill-conditioned).
pub fn compliance_of(k: &Matrix2<f64>) -> Result<Matrix2<f64>, TickError> {
    check_finite("stiffness", k.as_slice())?;
    let (a, b, d) = (k[(0, 0)], 0.5 * (k[(0, 1)] + k[(1, 0)]), k[(1, 1)]);
    let lambda_min = 0.5 * (a + d) - ComplexField::sqrt(0.25 * (a - d) * (a - d) + b * b);
    if lambda_min.is_nan() || lambda_min <= 0.0 {
        return Err(TickError::Singular {
            what: "xy stiffness (not positive definite)",
            sigma_min: lambda_min,
        });
    }
    let det = k.determinant();
    let scale = 0.5 * k.norm_squared();
    let singular = TickError::Singular {
        what: "xy stiffness",
        sigma_min: if scale > 0.0 { det / scale } else { 0.0 },
    };
    if !(scale > 0.0 && ComplexField::abs(det) >= MIN_RECIPROCAL_CONDITION * scale) {
        return Err(singular);
    }
    k.try_inverse().ok_or(singular)
}

/// Eq. 11: the force `K (x_d - x)` \[N\] of a robot demanded to `demanded` but stopped at
/// `actual` \[m\].
pub fn contact_force(
    k: &Matrix2<f64>,
    demanded: &Vector2<f64>,
    actual: &Vector2<f64>,
) -> Vector2<f64> {
    k * (demanded - actual)
}

/// Eq. 16-17: the steady-state tool motion when the demanded step `step` slides the tool
/// along a rigid straight edge at angle `edge_angle` \[rad\]: `r cos(theta_2 - theta_1)` along
/// the edge.
pub fn edge_motion(step: &Vector2<f64>, edge_angle: f64) -> Vector2<f64> {
    let (s, c) = (ComplexField::sin(edge_angle), ComplexField::cos(edge_angle));
    let along = step.x * c + step.y * s; // r cos(theta_2 - theta_1)
    Vector2::new(along * c, along * s)
}

/// Eq. 18-20: the contact force `K e` \[N\] after the demanded step `step` \[m\] against an edge
/// at `edge_angle` \[rad\], starting from zero force: `e = D - (motion along the edge)`.
/// Inputs must be finite; a result that overflows is [`TickError::NonFiniteOutput`].
pub fn edge_contact_force(
    k: &Matrix2<f64>,
    step: &Vector2<f64>,
    edge_angle: f64,
) -> Result<Vector2<f64>, TickError> {
    check_finite("stiffness", k.as_slice())?;
    finite2("step", step)?;
    check_finite("edge_angle", &[edge_angle])?;
    let f = k * (step - edge_motion(step, edge_angle));
    check_output("force", f.as_slice())?;
    Ok(f)
}

/// The tool motion `D - K^-1 F` \[m\] behind Eq. 21, from the demanded step `step` \[m\] and the
/// steady-state force (change) `force` \[N\].
pub fn edge_displacement(
    k: &Matrix2<f64>,
    step: &Vector2<f64>,
    force: &Vector2<f64>,
) -> Result<Vector2<f64>, TickError> {
    finite2("step", step)?;
    finite2("force", force)?;
    let c = compliance_of(k)?;
    Ok(step - c * force)
}

/// Eq. 21: the direction `theta_2` \[rad\] of the edge, pointing the way the tool moved,
/// from the demanded step `step` \[m\] and the steady-state contact force `force` \[N\] it built
/// up (the change of force if the tool was already pressing before the step). Valid while
/// `K` is positive definite and the force stays in the linear range. A zero step or a zero
/// force ([`TickError::InvalidArgument`]) carries no edge information; a tool that did not
/// move along the edge gives [`TickError::NoEdgeMotion`].
pub fn edge_direction(
    k: &Matrix2<f64>,
    step: &Vector2<f64>,
    force: &Vector2<f64>,
) -> Result<f64, TickError> {
    let a = edge_displacement(k, step, force)?;
    let step_norm = step.norm();
    if step_norm == 0.0 {
        return Err(TickError::InvalidArgument {
            what: "step (zero length: no motion to read an edge from)",
            value: step_norm,
        });
    }
    let force_norm = force.norm();
    if force_norm == 0.0 {
        return Err(TickError::InvalidArgument {
            what: "force (zero: no contact, Eq. 21 needs a steady contact force)",
            value: force_norm,
        });
    }
    if a.norm() <= 1.0e-12 * step_norm {
        return Err(TickError::NoEdgeMotion);
    }
    Ok(RealField::atan2(a.y, a.x))
}

/// `v` turned by `angle` \[rad\] counter-clockwise.
pub(super) fn rotate(v: &Vector2<f64>, angle: f64) -> Vector2<f64> {
    let (s, c) = (ComplexField::sin(angle), ComplexField::cos(angle));
    Vector2::new(c * v.x - s * v.y, s * v.x + c * v.y)
}
