//! Static equilibrium beyond the paper's model (`alloc`). Hähn and Weigold, "Hybrid compliance
//! compensation for path accuracy enhancement in robot machining" (2020), section 2.1, Eq. 5-7, takes every spring's
//! moment in the *undeformed* pose and sets the angles to `M / k`. In equilibrium the load
//! acts on the *deflected* chain: the TCP and the downstream spring frames have moved and
//! turned. Here each virtual joint is a conservative spring, energy `1/2 sum k theta^2` in its
//! z-y'-x'' angles (Eq. 3-4), and the angles solve the principle of virtual work
//!
//! ```text
//! K theta = E(theta)^T M_s(theta),   M_s(theta) = R_s(theta)^T (M + (p_tcp(theta) - o_s(theta)) x F)
//! ```
//!
//! with `R_s`, `o_s` the spring's frame in the deflected chain (before its own rotation),
//! `E(theta)` the map from angle rates to angular velocity (`E(0) = I`), and the TCP wrench
//! fixed in the base frame (force at the deflected TCP, moment about it). Newton's method on
//! the spring angles (Jacobian by central differences, bounded iterations) from the paper's
//! solution. At `theta -> 0` both models agree; they differ at second order in the load, by
//! roughly the deflection times its own angular size (lever-arm change and spring-axis
//! turn): 0.1-1 % of the deflection for millimetre deflections of a metre-size arm, more for
//! soft or long arms. Use it to check when the paper's model is accurate enough, or for large
//! deflections; the per-tick correctors use the paper's model.

use alloc::vec;
use alloc::vec::Vec;

use nalgebra::{DMatrix, DVector, Isometry3, Translation3, UnitQuaternion, Vector3};

use super::data::check_q;
use super::model::Op;
use super::{Data, MAX_SPRING_ANGLE, Model, Vector6};
use crate::error::{TickError, check_finite, check_output};

/// Settings of [`equilibrium`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumOptions {
    /// Most Newton iterations (1..=64).
    pub max_iterations: usize,
    /// Largest change of any spring angle at which the iteration stops \[rad\].
    pub tolerance: f64,
}

impl Default for EquilibriumOptions {
    /// 20 iterations, 1e-12 rad (1e-12 m of TCP motion per metre of arm).
    fn default() -> Self {
        Self {
            max_iterations: 20,
            tolerance: 1e-12,
        }
    }
}

/// Result of [`equilibrium`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[must_use]
pub struct Equilibrium {
    /// TCP deflection `[dp; dr]` \[m, rad\] in equilibrium, the layout of
    /// [`super::deflection`].
    pub deflection: Vector6,
    /// Newton iterations done.
    pub iterations: usize,
    /// Largest residual `|theta - C (.) M(theta)|` left \[rad\].
    pub residual: f64,
}

fn euler(a: &Vector3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_euler_angles(a.x, a.y, a.z)
}

/// The deflected chain at spring angles `theta` (3 per spring): each spring's world frame
/// (before its own rotation) and the deflected TCP.
fn deflected_frames(
    model: &Model,
    q: &[f64],
    theta: &[Vector3<f64>],
    frames: &mut [Isometry3<f64>],
) -> Isometry3<f64> {
    let mut t = Isometry3::identity();
    for op in model.ops.iter() {
        match op {
            Op::Fixed(f) => t *= f,
            Op::Joint {
                pre,
                axis,
                revolute,
                index,
            } => {
                t *= pre;
                let qi = q.get(*index).copied().unwrap_or(0.0);
                if *revolute {
                    t.rotation *= super::trig::axis_angle(axis, qi);
                } else {
                    t.translation.vector += t.rotation * (axis.into_inner() * qi);
                }
            }
            Op::Spring { offset, index, .. } => {
                let o = offset.unwrap_or_else(Isometry3::identity);
                let s = t * o;
                if let Some(slot) = frames.get_mut(*index) {
                    *slot = s;
                }
                let a = theta.get(*index).copied().unwrap_or_else(Vector3::zeros);
                t = s * Isometry3::from_parts(Translation3::identity(), euler(&a)) * o.inverse();
            }
            Op::Mass { .. } => {}
        }
    }
    t
}

/// `C (.) E(theta)^T M_s(theta)` for every spring, flattened (see the module docs).
fn spring_response(
    model: &Model,
    q: &[f64],
    theta: &[Vector3<f64>],
    frames: &mut [Isometry3<f64>],
    wrench: &Vector6,
) -> Vec<f64> {
    let tcp = deflected_frames(model, q, theta, frames);
    let force = Vector3::new(wrench[0], wrench[1], wrench[2]);
    let moment = Vector3::new(wrench[3], wrench[4], wrench[5]);
    let mut out = vec![0.0; 3 * model.springs];
    for op in model.ops.iter() {
        let Op::Spring {
            compliance, index, ..
        } = op
        else {
            continue;
        };
        let (Some(f), Some(a)) = (frames.get(*index), theta.get(*index)) else {
            continue;
        };
        let m = f.rotation.inverse_transform_vector(
            &(moment + (tcp.translation.vector - f.translation.vector).cross(&force)),
        );
        // Angular velocity of R = Rz(gamma) Ry(beta) Rx(alpha) in the spring frame:
        // gamma' z + beta' Rz y + alpha' Rz Ry x; the generalized forces are its columns
        // dotted with the moment.
        let rz = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a.z);
        let rzy = rz * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), a.y);
        let generalized = Vector3::new(
            (rzy * Vector3::x()).dot(&m),
            (rz * Vector3::y()).dot(&m),
            m.z,
        );
        let angles = compliance.component_mul(&generalized);
        for (k, v) in angles.iter().enumerate() {
            if let Some(slot) = out.get_mut(3 * index + k) {
                *slot = *v;
            }
        }
    }
    out
}

fn as_angles(x: &[f64]) -> Vec<Vector3<f64>> {
    x.chunks_exact(3).map(Vector3::from_column_slice).collect()
}

/// The deflection in static equilibrium (see the module docs) at joints `q` under the TCP
/// wrench `wrench` \[N, N m\] (base frame, moment about the TCP). Fills `data.tcp`,
/// `data.tcp_deflected` and `data.spring_angles` with the equilibrium's values.
/// [`TickError::NotConverged`] when Newton's method does not settle within the budget,
/// [`TickError::InvalidArgument`] for a load past [`MAX_SPRING_ANGLE`]. Allocates (a few
/// vectors and a matrix of `3 * springs` squared): not a per-tick function.
pub fn equilibrium(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    wrench: &Vector6,
    options: &EquilibriumOptions,
) -> Result<Equilibrium, TickError> {
    check_q(model, data, q)?;
    check_finite("wrench", wrench.as_slice())?;
    check_options(options)?;
    // The paper's solution is the start (and fills data.tcp with the rigid pose).
    super::deflection(model, data, q, wrench, super::Load::Exact)?;
    let rigid = data.tcp;
    let mut x: Vec<f64> = data
        .spring_angles
        .iter()
        .take(model.springs)
        .flat_map(|a| a.iter().copied())
        .collect();
    let mut frames = vec![Isometry3::identity(); model.springs];
    let problem = Problem { model, q, wrench };
    let mut iterations = 0;
    let mut g = problem.residual(&x, &mut frames);
    loop {
        let step_norm = problem.newton_step(&mut x, &g, &mut frames)?;
        iterations += 1;
        g = problem.residual(&x, &mut frames);
        if step_norm <= options.tolerance {
            break;
        }
        if iterations >= options.max_iterations {
            return Err(TickError::NotConverged {
                iterations,
                residual: g.iter().fold(0.0f64, |a, v| a.max(v.abs())),
            });
        }
    }
    let d = write_back(model, data, q, &x, &rigid, &mut frames)?;
    Ok(Equilibrium {
        deflection: d,
        iterations,
        residual: g.iter().fold(0.0f64, |a, v| a.max(v.abs())),
    })
}

/// Checks the settings: 1..=64 iterations, a finite positive tolerance.
fn check_options(options: &EquilibriumOptions) -> Result<(), TickError> {
    if options.max_iterations == 0 || options.max_iterations > 64 {
        return Err(TickError::InvalidArgument {
            what: "max_iterations (1..=64)",
            value: options.max_iterations as f64,
        });
    }
    if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
        return Err(TickError::InvalidArgument {
            what: "tolerance",
            value: options.tolerance,
        });
    }
    Ok(())
}

/// The equations Newton's method solves: the chain at joints `q` under `wrench`.
struct Problem<'a> {
    model: &'a Model,
    q: &'a [f64],
    wrench: &'a Vector6,
}

impl Problem<'_> {
    /// The residual `theta - C (.) E^T M_s(theta)` \[rad\] at the flattened spring angles `x`
    /// (`frames` is the workspace of [`deflected_frames`]).
    fn residual(&self, x: &[f64], frames: &mut [Isometry3<f64>]) -> Vec<f64> {
        let r = spring_response(self.model, self.q, &as_angles(x), frames, self.wrench);
        x.iter().zip(&r).map(|(a, b)| a - b).collect::<Vec<f64>>()
    }

    /// One Newton step on `x` from its residual `g` (Jacobian by central differences):
    /// `x -= J^-1 g`; returns the step's largest entry \[rad\].
    fn newton_step(
        &self,
        x: &mut [f64],
        g: &[f64],
        frames: &mut [Isometry3<f64>],
    ) -> Result<f64, TickError> {
        let n = 3 * self.model.springs;
        // Jacobian of g by central differences.
        let mut jac = DMatrix::<f64>::zeros(n, n);
        for j in 0..n {
            // Angles are below 0.5 rad: a fixed step keeps the truncation error
            // (h^2 times the third derivative) and the rounding error (eps / h) both
            // near 1e-12 of the response.
            let h = 1e-6;
            let mut xp = x.to_vec();
            let mut xm = x.to_vec();
            if let (Some(p), Some(m)) = (xp.get_mut(j), xm.get_mut(j)) {
                *p += h;
                *m -= h;
            }
            let (gp, gm) = (self.residual(&xp, frames), self.residual(&xm, frames));
            for (i, (a, b)) in gp.iter().zip(&gm).enumerate() {
                if let Some(slot) = jac.get_mut((i, j)) {
                    *slot = (a - b) / (2.0 * h);
                }
            }
        }
        let Some(dx) = jac.lu().solve(&DVector::from_column_slice(g)) else {
            return Err(TickError::Singular {
                what: "equilibrium Jacobian",
                sigma_min: 0.0,
            });
        };
        let step_norm = dx.amax();
        for (xi, d) in x.iter_mut().zip(dx.iter()) {
            *xi -= d;
        }
        Ok(step_norm)
    }
}

/// The equilibrium's spring angles `x` (flattened, \[rad\]) into `data` (the angles and the
/// deflected TCP), checked against [`MAX_SPRING_ANGLE`]; returns the deflection `[dp; dr]`
/// \[m, rad\] from the rigid TCP `rigid`.
fn write_back(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    x: &[f64],
    rigid: &Isometry3<f64>,
    frames: &mut [Isometry3<f64>],
) -> Result<Vector6, TickError> {
    let angles = as_angles(x);
    let largest = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if largest > MAX_SPRING_ANGLE {
        return Err(TickError::InvalidArgument {
            what: "wrench (an equilibrium elastic angle exceeds MAX_SPRING_ANGLE)",
            value: largest,
        });
    }
    let tcp = deflected_frames(model, q, &angles, frames);
    for (slot, a) in data.spring_angles.iter_mut().zip(&angles) {
        *slot = *a;
    }
    let dp = tcp.translation.vector - rigid.translation.vector;
    let dr = super::rotation_vector(&(tcp.rotation * rigid.rotation.inverse()));
    let d = Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z);
    check_output("deflection", d.as_slice())?;
    data.tcp_deflected = tcp;
    Ok(d)
}
