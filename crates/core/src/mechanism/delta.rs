//! The 3-DoF Delta robot of Clavel (1988): three actuated arms turning in vertical planes 120
//! degrees apart, each carrying a parallelogram forearm to a platform that keeps its
//! orientation. Closed-form IK, FK (intersection of three spheres) and Jacobian, so that the
//! D'Alembert corrector of Paksoy, Dede and Kiper (2025, section 3.3: desired acceleration ->
//! force -> compliance map -> corrected point -> IK) drives it as it drives their five-bar,
//! with a 3-D compliance map.
//!
//! # Geometry and frame
//! Base frame: origin at the centre of the base joint circle, z up, the platform below
//! (z < 0). Arm `i` (i = 0, 1, 2) lies in the vertical plane at azimuth `phi_i = 2 pi i / 3`
//! from +x, with radial unit vector `u_i = (cos phi_i, sin phi_i, 0)`. Its actuated joint sits
//! at `R u_i` (`base_radius`), its axis horizontal, normal to the plane; the arm of length
//! `L` (`arm`) ends at the elbow `E_i = (R + L cos theta_i) u_i - L sin theta_i z`: `theta_i`
//! is 0 with the arm horizontal and pointing outwards, positive downwards. The forearm
//! (the parallelogram's long side, `l` = `forearm`) joins the elbow to the platform joint
//! `P + r u_i` (`platform_radius`), so the constraint of arm `i` is
//! `|P + r u_i - E_i| = l`: a sphere of radius `l` about `E_i - r u_i` for the platform
//! centre `P` (the task point).
//!
//! # Kinematics
//! IK per arm, in its plane (local `a = P.u_i + r - R`, lateral `b = P.v_i`,
//! `v_i = z x u_i`): `-2 a L cos theta + 2 z L sin theta = l^2 - a^2 - b^2 - z^2 - L^2`, i.e.
//! `A cos theta + B sin theta = K`, `theta = atan2(B, A) -/+ acos(K / hypot(A, B))`; the root
//! with the elbow outwards (larger `R + L cos theta`) is taken, the working mode of Delta
//! robots. `|K| > hypot(A, B)` is out of reach ([`TickError::OutOfWorkspace`]).
//! FK: the three spheres intersect in two points mirrored in the plane of their centres; the
//! lower one (platform below the elbows) is taken.
//! Jacobian from the constraints `f_i = |s_i|^2 - l^2 = 0`, `s_i = P + r u_i - E_i`:
//! `S dP = D dq` with rows `s_i^T` and `D = diag(s_i . dE_i/dtheta_i)`, so `J = S^-1 D`.
//! `det S = 0` is the parallel (FK) singularity, `D_ii = 0` the serial (IK) one; poses whose
//! Jacobian's smallest singular value is below `min_sigma` are [`TickError::Singular`].

// Without std, f64's transcendental functions come from nalgebra's real-number trait.
#[cfg(not(feature = "std"))]
use nalgebra::ComplexField;
use nalgebra::{Matrix3, RealField, Vector3};

use super::{Mechanism, check_finite, positive};
use crate::error::{BuildError, TickError};

/// Default singularity threshold of [`Delta`]: 10 mm/rad, as for a Delta of a few hundred
/// millimetres (the paper's five-bar uses 20 mm/rad).
pub const DELTA_MIN_SIGMA: f64 = 0.010;

/// Shortest length of a [`Delta`] \[m\] (a micrometre: below it a length is a units mistake,
/// and 5e-324 m would square to 0).
pub const DELTA_MIN_LENGTH: f64 = 1.0e-6;
/// Longest length of a [`Delta`] \[m\].
pub const DELTA_MAX_LENGTH: f64 = 100.0;

/// A Delta robot's dimensions (see the module docs) and singularity threshold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Delta {
    base_radius: f64,
    platform_radius: f64,
    arm: f64,
    forearm: f64,
    min_sigma: f64,
}

/// `(cos phi_i, sin phi_i)` of the three arms.
fn azimuths() -> [(f64, f64); 3] {
    let c = -0.5;
    let s = 0.75f64.sqrt();
    [(1.0, 0.0), (c, s), (c, -s)]
}

impl Delta {
    /// A Delta of base joint circle radius `base_radius`, platform joint circle radius
    /// `platform_radius`, arm length `arm` and forearm length `forearm` \[m\], each within
    /// [`DELTA_MIN_LENGTH`]..=[`DELTA_MAX_LENGTH`], with [`DELTA_MIN_SIGMA`]. The forearm must be longer than the arm is offset,
    /// `|base_radius - platform_radius|`, else no pose closes.
    pub fn new(
        base_radius: f64,
        platform_radius: f64,
        arm: f64,
        forearm: f64,
    ) -> Result<Self, BuildError> {
        let length = |what: &'static str, v: f64| {
            crate::error::param(
                what,
                v,
                (DELTA_MIN_LENGTH..=DELTA_MAX_LENGTH).contains(&v),
                "within DELTA_MIN_LENGTH..=DELTA_MAX_LENGTH (1e-6..=100 m)",
            )
        };
        let d = Self {
            base_radius: length("base_radius", base_radius)?,
            platform_radius: length("platform_radius", platform_radius)?,
            arm: length("arm", arm)?,
            forearm: length("forearm", forearm)?,
            min_sigma: DELTA_MIN_SIGMA,
        };
        if forearm <= (base_radius - platform_radius).abs() {
            return Err(BuildError::InvalidParameter {
                what: "forearm",
                value: forearm,
                expected: "longer than |base_radius - platform_radius| (m)",
            });
        }
        Ok(d)
    }

    /// The same robot with singularity threshold `min_sigma` \[m/rad\], finite and > 0.
    pub fn with_min_sigma(mut self, min_sigma: f64) -> Result<Self, BuildError> {
        self.min_sigma = positive("min_sigma", min_sigma)?;
        Ok(self)
    }

    /// A pick-and-place Delta of the size of the ABB FlexPicker IRB 360-1/800 class: base
    /// radius 0.2 m, platform 0.045 m, arm 0.35 m, forearm 0.8 m (deflect's choice, no
    /// manufacturer data).
    pub fn pick_and_place() -> Self {
        Self {
            base_radius: 0.2,
            platform_radius: 0.045,
            arm: 0.35,
            forearm: 0.8,
            min_sigma: DELTA_MIN_SIGMA,
        }
    }

    /// Base joint circle radius R \[m\].
    pub fn base_radius(&self) -> f64 {
        self.base_radius
    }
    /// Platform joint circle radius r \[m\].
    pub fn platform_radius(&self) -> f64 {
        self.platform_radius
    }
    /// Arm length L \[m\].
    pub fn arm(&self) -> f64 {
        self.arm
    }
    /// Forearm length l \[m\].
    pub fn forearm(&self) -> f64 {
        self.forearm
    }
    /// Singularity threshold \[m/rad\].
    pub fn min_sigma(&self) -> f64 {
        self.min_sigma
    }

    /// Elbow of arm `(c, s)` at angle `theta`, and its derivative in `theta`.
    fn elbow(&self, (c, s): (f64, f64), theta: f64) -> (Vector3<f64>, Vector3<f64>) {
        let (st, ct) = theta.sin_cos();
        let radial = self.base_radius + self.arm * ct;
        (
            Vector3::new(radial * c, radial * s, -self.arm * st),
            Vector3::new(-self.arm * st * c, -self.arm * st * s, -self.arm * ct),
        )
    }

    /// Joints `(theta_0, theta_1, theta_2)` \[rad\] putting the platform centre on `p` \[m\]
    /// (elbows out). [`TickError::OutOfWorkspace`] when an arm cannot reach (the distance
    /// reported is the platform joint's from the arm's actuated joint, the reach `L + l`).
    pub fn ik(&self, p: &Vector3<f64>) -> Result<Vector3<f64>, TickError> {
        check_finite("position", p)?;
        let (big_r, r, l_arm, l) = (
            self.base_radius,
            self.platform_radius,
            self.arm,
            self.forearm,
        );
        let mut q = Vector3::zeros();
        for (k, (c, s)) in azimuths().into_iter().enumerate() {
            let a = p.x * c + p.y * s + r - big_r;
            let b = -p.x * s + p.y * c;
            let z = p.z;
            let (ca, cb) = (-2.0 * a * l_arm, 2.0 * z * l_arm);
            let kk = l * l - a * a - b * b - z * z - l_arm * l_arm;
            let rho = ca.hypot(cb);
            if rho.is_nan() || rho == 0.0 || kk.abs() > rho {
                return Err(TickError::OutOfWorkspace {
                    distance: (a * a + b * b + z * z).sqrt(),
                    reach: l_arm + l,
                });
            }
            let alpha = cb.atan2(ca);
            let beta = (kk / rho).acos();
            // Elbow out: the root with the larger radial reach R + L cos(theta).
            let (t1, t2) = (alpha - beta, alpha + beta);
            let theta = if t1.cos() >= t2.cos() { t1 } else { t2 };
            if let Some(slot) = q.get_mut(k) {
                *slot = wrap(theta);
            }
        }
        // Each arm reaches `p`, but the three spheres also meet at `p`'s mirror image in the
        // plane of their centres: the working mode (and `fk`) has the platform below that
        // plane; a point above it is the other assembly, refused rather than returned as
        // joints whose platform sits elsewhere.
        let mut centres = [Vector3::zeros(); 3];
        for ((centre, az), theta) in centres.iter_mut().zip(azimuths()).zip(q.iter()) {
            let (e, _) = self.elbow(az, *theta);
            *centre = e - Vector3::new(az.0, az.1, 0.0) * r;
        }
        let [c0, c1, c2] = centres;
        let mut normal = (c1 - c0).cross(&(c2 - c0));
        if normal.z > 0.0 {
            normal = -normal;
        }
        let below = (p - c0).dot(&normal);
        if below.is_nan() || below < -1e-12 * normal.norm() * (l_arm + l) {
            return Err(TickError::InvalidArgument {
                what: "position (above the plane of the elbows: the Delta's working mode has \
                       the platform below its elbows)",
                value: p.z,
            });
        }
        Ok(q)
    }

    /// Platform centre \[m\] at joints `q` \[rad\]: the lower intersection of the three
    /// spheres. [`TickError::OutOfWorkspace`] when the spheres do not meet (the joints cannot
    /// be assembled), [`TickError::Singular`] when their centres are collinear.
    pub fn fk(&self, q: &Vector3<f64>) -> Result<Vector3<f64>, TickError> {
        check_finite("joints", q)?;
        crate::vjm::check_joint_range(q.as_slice())?;
        let r = self.platform_radius;
        let mut centres = [Vector3::zeros(); 3];
        for ((centre, az), theta) in centres.iter_mut().zip(azimuths()).zip(q.iter()) {
            let (e, _) = self.elbow(az, *theta);
            *centre = e - Vector3::new(az.0, az.1, 0.0) * r;
        }
        let [c0, c1, c2] = centres;
        // Trilateration in the frame of the centres: ex along c0 -> c1, ey in their plane.
        let d01 = c1 - c0;
        let d = d01.norm();
        let singular = TickError::Singular {
            what: "Delta forward kinematics (sphere centres collinear)",
            sigma_min: 0.0,
        };
        if d == 0.0 || d.is_nan() {
            return Err(singular);
        }
        let ex = d01 / d;
        let d02 = c2 - c0;
        let i = ex.dot(&d02);
        let ey_raw = d02 - ex * i;
        let j = ey_raw.norm();
        if j <= 1e-12 * d {
            return Err(singular);
        }
        let ey = ey_raw / j;
        let ez = ex.cross(&ey);
        let l2 = self.forearm * self.forearm;
        let x = d / 2.0;
        let y = (i * i + j * j - 2.0 * i * x) / (2.0 * j);
        let z2 = l2 - x * x - y * y;
        if z2.is_nan() || z2 < 0.0 {
            return Err(TickError::OutOfWorkspace {
                distance: (x * x + y * y).sqrt(),
                reach: self.forearm,
            });
        }
        let z = z2.sqrt();
        let base = c0 + ex * x + ey * y;
        // The lower of the two mirrored solutions.
        let (a, b) = (base + ez * z, base - ez * z);
        Ok(if a.z <= b.z { a } else { b })
    }

    /// The Jacobian `dP/dq` \[m/rad\] at joints `q` and the platform centre `p` there, with
    /// the singularity checks of the module docs.
    pub fn jacobian_at(
        &self,
        q: &Vector3<f64>,
        p: &Vector3<f64>,
    ) -> Result<Matrix3<f64>, TickError> {
        check_finite("joints", q)?;
        crate::vjm::check_joint_range(q.as_slice())?;
        check_finite("position", p)?;
        let r = self.platform_radius;
        let mut s = Matrix3::zeros();
        let mut d = Matrix3::zeros();
        for (k, (az, theta)) in azimuths().into_iter().zip(q.iter()).enumerate() {
            let (e, de) = self.elbow(az, *theta);
            let si = p + Vector3::new(az.0, az.1, 0.0) * r - e;
            s.set_row(k, &si.transpose());
            if let Some(x) = d.get_mut((k, k)) {
                *x = si.dot(&de);
            }
        }
        let singular = |sigma_min| TickError::Singular {
            what: "Delta Jacobian",
            sigma_min,
        };
        let s_inv = s.try_inverse().ok_or(singular(0.0))?;
        let j = s_inv * d;
        let sigma = j.singular_values().min();
        if sigma.is_nan() || sigma < self.min_sigma {
            return Err(singular(sigma));
        }
        Ok(j)
    }
}

/// An angle in (-pi, pi].
fn wrap(a: f64) -> f64 {
    let two_pi = f64::two_pi();
    let w = a - two_pi * ((a + f64::pi()) / two_pi).floor();
    if w <= -f64::pi() { w + two_pi } else { w }
}

impl Mechanism<3, 3> for Delta {
    type Data = ();

    fn new_data(&self) {}

    fn inverse(
        &self,
        _data: &mut (),
        x: &Vector3<f64>,
        _seed: &Vector3<f64>,
    ) -> Result<Vector3<f64>, TickError> {
        let q = self.ik(x)?;
        // Refuse commands at (or too near) a singularity, as the five-bar does.
        self.jacobian_at(&q, x)?;
        Ok(q)
    }

    fn forward(&self, _data: &mut (), q: &Vector3<f64>) -> Result<Vector3<f64>, TickError> {
        self.fk(q)
    }

    fn jacobian(&self, _data: &mut (), q: &Vector3<f64>) -> Result<Matrix3<f64>, TickError> {
        let p = self.fk(q)?;
        self.jacobian_at(q, &p)
    }

    fn singularity_distance(&self, _data: &mut (), q: &Vector3<f64>) -> Result<f64, TickError> {
        let p = self.fk(q)?;
        match self.jacobian_at(q, &p) {
            Ok(j) => Ok(j.singular_values().min()),
            Err(TickError::Singular { sigma_min, .. }) => Ok(sigma_min),
            Err(e) => Err(e),
        }
    }
}
