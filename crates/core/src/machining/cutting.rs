//! The mechanistic (linear edge-force) model of end milling: the force on the tool from its
//! engagement, feed per tooth and the material's cutting and edge coefficients.
//!
//! Per cutting edge in contact at the immersion angle `phi` (measured clockwise from the
//! tool frame's +y axis, the tool turning clockwise seen from the spindle, feed along +x),
//! with axial depth `a` and chip thickness `h = c sin(phi)` (`c` the feed per tooth):
//!
//! ```text
//! F_t = K_tc a h + K_te a,   F_r = K_rc a h + K_re a,   F_a = K_ac a h + K_ae a
//! F_x = -F_t cos(phi) - F_r sin(phi),   F_y = F_t sin(phi) - F_r cos(phi),   F_z = F_a
//! ```
//!
//! summed over the `N` edges (pitch `2 pi / N`) that lie inside `[entry, exit]`, and with a
//! helix over axial discs, each lagging by `2 tan(beta) z / D`. Averaged over a revolution
//! the sum has a closed form ([`average`]): it is what the robot's structure feels at spindle
//! speeds far above its first eigenfrequency, the "roughly estimated cutting forces" of the
//! hybrid compensation (Hähn and Weigold 2020, sec. 2.4). Source of the model: Altintas,
//! "Manufacturing Automation", 2nd ed. (Cambridge, 2012), ch. 2 (mechanics of milling).
//!
//! Frames: the tool frame has x along the feed, z along the tool axis from the tip towards
//! the spindle, y = z x x; the forces are those the workpiece exerts on the tool \[N\].
//! [`tool_frame`] turns them into the base frame. Allocation-free.

use nalgebra::{ComplexField, Matrix3, Rotation3, Vector3};

use crate::error::{BuildError, TickError};

/// Most flutes of a tool.
pub const MAX_FLUTES: u32 = 16;
/// Most axial discs one evaluation sums (a helix resolved to 1/256 of the depth).
pub const MAX_DISCS: usize = 256;
/// Largest helix angle \[rad\] (60 degrees; end mills have 0-50).
pub const MAX_HELIX: f64 = core::f64::consts::FRAC_PI_3;
/// Most edge-force evaluations one batch of instantaneous forces may ask for (angles x discs
/// x flutes): 2^26, about 2 s at the 35 million per second of one core; past it
/// [`check_force_evaluations`] refuses the batch instead of running for minutes.
pub const MAX_FORCE_EVALUATIONS: usize = 1 << 26;

/// [`TickError::Budget`] when `angles` instantaneous forces of `discs` discs with `tool`
/// would take more than [`MAX_FORCE_EVALUATIONS`] edge evaluations.
pub fn check_force_evaluations(angles: usize, discs: usize, tool: &Tool) -> Result<(), TickError> {
    let n = angles
        .saturating_mul(discs)
        .saturating_mul(tool.flutes.max(1) as usize);
    if n > MAX_FORCE_EVALUATIONS {
        return Err(TickError::Budget {
            what: "edge-force evaluations (angles x discs x flutes; 35 M/s on one core)",
            budget: "MAX_FORCE_EVALUATIONS",
            limit: MAX_FORCE_EVALUATIONS as f64,
            requested: n as f64,
        });
    }
    Ok(())
}

/// Smallest tool diameter \[m\] (10 um; micro end mills start at about 50 um).
pub const MIN_TOOL_DIAMETER: f64 = 1.0e-5;
/// Largest cutting coefficient `k_*c` \[N/m^2\]: 1e11 (100,000 N/mm^2; hardened steels are
/// a few thousand): past it a set is in the wrong unit.
pub const MAX_CUTTING_COEFFICIENT: f64 = 1.0e11;
/// Largest edge coefficient `k_*e` \[N/m\]: 1e7 (10,000 N/mm).
pub const MAX_EDGE_COEFFICIENT: f64 = 1.0e7;

/// Cutting (`k_*c`, \[N/m^2\]) and edge (`k_*e`, \[N/m\]) coefficients of a material with a
/// tool, tangential, radial and axial.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// Tangential cutting coefficient \[N/m^2\].
    pub k_tc: f64,
    /// Radial cutting coefficient \[N/m^2\].
    pub k_rc: f64,
    /// Axial cutting coefficient \[N/m^2\].
    pub k_ac: f64,
    /// Tangential edge coefficient \[N/m\].
    pub k_te: f64,
    /// Radial edge coefficient \[N/m\].
    pub k_re: f64,
    /// Axial edge coefficient \[N/m\].
    pub k_ae: f64,
}

impl Coefficients {
    /// Aluminium Al7075-T6 with a cemented-carbide end mill, dry: K_tc 767.01 N/mm^2,
    /// K_rc 168.8 N/mm^2, K_ac 222 N/mm^2, K_te 27.7 N/mm, K_re 26.6 N/mm, K_ae 0.7 N/mm, as
    /// compiled in Table 5 of Zhang et al., "Milling Force Model for Aviation Aluminum Alloy:
    /// Academic Insight and Perspective Analysis", Chinese Journal of Mechanical Engineering
    /// 34:107 (2021), doi 10.1186/s10033-021-00536-9. A stand-in for the AW2017 of Hähn and
    /// Weigold, for which no published set was found: pass your own identified set.
    pub const AL7075_T6_CARBIDE: Self = Self {
        k_tc: 767.01e6,
        k_rc: 168.8e6,
        k_ac: 222.0e6,
        k_te: 27.7e3,
        k_re: 26.6e3,
        k_ae: 0.7e3,
    };

    /// Checked coefficients: every one finite and >= 0 (a negative coefficient has no
    /// physical reading in this model), cutting ones at most [`MAX_CUTTING_COEFFICIENT`],
    /// edge ones at most [`MAX_EDGE_COEFFICIENT`]; [`BuildError::InvalidParameter`] naming it
    /// otherwise.
    pub fn new(
        k_tc: f64,
        k_rc: f64,
        k_ac: f64,
        k_te: f64,
        k_re: f64,
        k_ae: f64,
    ) -> Result<Self, BuildError> {
        let c = Self {
            k_tc,
            k_rc,
            k_ac,
            k_te,
            k_re,
            k_ae,
        };
        c.validate()?;
        Ok(c)
    }

    /// Checks a set built field by field (as [`Self::new`]).
    pub fn validate(&self) -> Result<(), BuildError> {
        let (cut, edge) = (
            "within 0..=MAX_CUTTING_COEFFICIENT (1e11 N/m^2)",
            "within 0..=MAX_EDGE_COEFFICIENT (1e7 N/m)",
        );
        for (what, v, max, expected) in [
            ("k_tc", self.k_tc, MAX_CUTTING_COEFFICIENT, cut),
            ("k_rc", self.k_rc, MAX_CUTTING_COEFFICIENT, cut),
            ("k_ac", self.k_ac, MAX_CUTTING_COEFFICIENT, cut),
            ("k_te", self.k_te, MAX_EDGE_COEFFICIENT, edge),
            ("k_re", self.k_re, MAX_EDGE_COEFFICIENT, edge),
            ("k_ae", self.k_ae, MAX_EDGE_COEFFICIENT, edge),
        ] {
            if !(v.is_finite() && (0.0..=max).contains(&v)) {
                return Err(BuildError::InvalidParameter {
                    what,
                    value: v,
                    expected,
                });
            }
        }
        Ok(())
    }
}

/// A flat end mill.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tool {
    /// Diameter \[m\].
    pub diameter: f64,
    /// Number of flutes (cutting edges), 1..=[`MAX_FLUTES`].
    pub flutes: u32,
    /// Helix angle \[rad\], 0..[`MAX_HELIX`].
    pub helix: f64,
}

impl Tool {
    /// A checked tool: diameter in [[`MIN_TOOL_DIAMETER`], 1 m], flutes in
    /// 1..=[`MAX_FLUTES`], helix in \[0, [`MAX_HELIX`]).
    pub fn new(diameter: f64, flutes: u32, helix: f64) -> Result<Self, BuildError> {
        let t = Self {
            diameter,
            flutes,
            helix,
        };
        t.validate()?;
        Ok(t)
    }

    /// Checks a tool built field by field (as [`Self::new`]).
    pub fn validate(&self) -> Result<(), BuildError> {
        if !(self.diameter.is_finite() && (MIN_TOOL_DIAMETER..=1.0).contains(&self.diameter)) {
            return Err(BuildError::InvalidParameter {
                what: "tool diameter",
                value: self.diameter,
                expected: "finite, in [1e-5, 1] m (MIN_TOOL_DIAMETER)",
            });
        }
        if !(1..=MAX_FLUTES).contains(&self.flutes) {
            return Err(BuildError::InvalidParameter {
                what: "flutes",
                value: f64::from(self.flutes),
                expected: "1..=16",
            });
        }
        if !(self.helix.is_finite() && (0.0..MAX_HELIX).contains(&self.helix)) {
            return Err(BuildError::InvalidParameter {
                what: "helix angle",
                value: self.helix,
                expected: "finite, in [0, 60 deg) (rad)",
            });
        }
        Ok(())
    }
}

/// Where and how deep the tool cuts: immersion from `entry` to `exit` \[rad\] (clockwise
/// from +y, `0 <= entry < exit <= pi`), axial depth \[m\] and feed per tooth \[m\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Engagement {
    /// Entry angle \[rad\].
    pub entry: f64,
    /// Exit angle \[rad\].
    pub exit: f64,
    /// Axial depth of cut \[m\].
    pub depth: f64,
    /// Feed per tooth \[m\] (0: the edges rub, edge forces only).
    pub feed_per_tooth: f64,
}

impl Engagement {
    /// A full slot (`0..pi`).
    pub fn slot(depth: f64, feed_per_tooth: f64) -> Self {
        Self {
            entry: 0.0,
            exit: core::f64::consts::PI,
            depth,
            feed_per_tooth,
        }
    }

    /// Up milling (conventional) with radial width `width` of a tool of `diameter` \[m\]:
    /// `0 .. acos(1 - 2 width / D)`.
    pub fn up_milling(width: f64, diameter: f64, depth: f64, feed_per_tooth: f64) -> Self {
        Self {
            entry: 0.0,
            exit: ComplexField::acos((1.0 - 2.0 * width / diameter).clamp(-1.0, 1.0)),
            depth,
            feed_per_tooth,
        }
    }

    /// Down milling (climb) with radial width `width`: `acos(2 width / D - 1) .. pi`.
    pub fn down_milling(width: f64, diameter: f64, depth: f64, feed_per_tooth: f64) -> Self {
        Self {
            entry: ComplexField::acos((2.0 * width / diameter - 1.0).clamp(-1.0, 1.0)),
            exit: core::f64::consts::PI,
            depth,
            feed_per_tooth,
        }
    }

    /// Checks the angles, depth and feed: [`TickError::InvalidArgument`] naming the first
    /// out of range, [`TickError::NonFinite`] for NaN or infinities.
    pub fn validate(&self) -> Result<(), TickError> {
        crate::error::check_finite(
            "engagement",
            &[self.entry, self.exit, self.depth, self.feed_per_tooth],
        )?;
        let pi = core::f64::consts::PI;
        let checks = [
            (
                "entry angle (0 <= entry < exit <= pi)",
                self.entry,
                self.entry >= 0.0,
            ),
            (
                "exit angle (0 <= entry < exit <= pi)",
                self.exit,
                self.exit > self.entry && self.exit <= pi,
            ),
            (
                "axial depth (0..=1 m)",
                self.depth,
                (0.0..=1.0).contains(&self.depth),
            ),
            (
                "feed per tooth (0..=0.01 m)",
                self.feed_per_tooth,
                (0.0..=0.01).contains(&self.feed_per_tooth),
            ),
        ];
        for (what, value, ok) in checks {
            if !ok {
                return Err(TickError::InvalidArgument { what, value });
            }
        }
        Ok(())
    }
}

/// Force of one edge at immersion `phi` on a disc of height `dz` (zero outside the
/// engagement), tool frame \[N\].
#[inline]
fn edge(c: &Coefficients, e: &Engagement, phi: f64, dz: f64) -> Vector3<f64> {
    let tau = core::f64::consts::TAU;
    // `rem_euclid` without std.
    let phi = phi % tau;
    let phi = if phi < 0.0 { phi + tau } else { phi };
    if phi < e.entry || phi > e.exit {
        return Vector3::zeros();
    }
    let (sin, cos) = phi.sin_cos();
    let h = e.feed_per_tooth * sin;
    let ft = (c.k_tc * h + c.k_te) * dz;
    let fr = (c.k_rc * h + c.k_re) * dz;
    let fa = (c.k_ac * h + c.k_ae) * dz;
    Vector3::new(-ft * cos - fr * sin, ft * sin - fr * cos, fa)
}

/// The instantaneous force on the tool \[N\], tool frame, with edge 0 at `angle` \[rad\]
/// (clockwise from +y, at the tip) and the depth cut into `discs` axial discs (1 for a
/// straight-fluted tool; the lag of disc `k` at height `z_k` is `2 tan(helix) z_k / D`).
///
/// [`TickError::InvalidArgument`] for an engagement out of range or `discs` outside
/// 1..=[`MAX_DISCS`], [`TickError::NonFinite`] for a non-finite angle.
pub fn force(
    coefficients: &Coefficients,
    tool: &Tool,
    engagement: &Engagement,
    angle: f64,
    discs: usize,
) -> Result<Vector3<f64>, TickError> {
    engagement.validate()?;
    crate::error::check_finite("angle", &[angle])?;
    if !(1..=MAX_DISCS).contains(&discs) {
        return Err(TickError::InvalidArgument {
            what: "discs (1..=256)",
            value: discs as f64,
        });
    }
    let n = tool.flutes.max(1);
    let pitch = core::f64::consts::TAU / f64::from(n);
    let dz = engagement.depth / discs as f64;
    let lag_per_m = 2.0 * tool.helix.tan() / tool.diameter;
    let mut total = Vector3::zeros();
    for k in 0..discs {
        let z = (k as f64 + 0.5) * dz;
        let lag = lag_per_m * z;
        for j in 0..n {
            total += edge(
                coefficients,
                engagement,
                angle + f64::from(j) * pitch - lag,
                dz,
            );
        }
    }
    crate::error::check_output("cutting force", total.as_slice())?;
    Ok(total)
}

/// The force averaged over one revolution \[N\], tool frame: the closed form of the integral
/// of the edge forces from entry to exit (independent of the helix when the engagement is
/// the same along the depth), times `N / (2 pi)`.
pub fn average(
    coefficients: &Coefficients,
    tool: &Tool,
    engagement: &Engagement,
) -> Result<Vector3<f64>, TickError> {
    engagement.validate()?;
    let c = coefficients;
    let (a, f) = (engagement.depth, engagement.feed_per_tooth);
    // The antiderivatives of F_x, F_y, F_z in phi.
    let primitive = |phi: f64| {
        let (s, co) = phi.sin_cos();
        let (s2, c2) = (2.0 * phi).sin_cos();
        Vector3::new(
            a * f / 4.0 * (c.k_tc * c2 - c.k_rc * (2.0 * phi - s2))
                + a * (-c.k_te * s + c.k_re * co),
            a * f / 4.0 * (c.k_tc * (2.0 * phi - s2) + c.k_rc * c2)
                - a * (c.k_te * co + c.k_re * s),
            -c.k_ac * a * f * co + c.k_ae * a * phi,
        )
    };
    let n = f64::from(tool.flutes.max(1));
    let mean =
        (primitive(engagement.exit) - primitive(engagement.entry)) * (n / core::f64::consts::TAU);
    crate::error::check_output("average cutting force", mean.as_slice())?;
    Ok(mean)
}

/// The cutting torque about the tool axis averaged over one revolution \[N m\], on the tool,
/// positive about +z of the tool frame: every edge's tangential force acts at the radius
/// (`(p x F)_z = R F_t`; the radial and axial forces have no moment about the axis), so
/// `M = R a N / (2 pi) (K_tc c (cos(entry) - cos(exit)) + K_te (exit - entry))`. The spindle
/// housing passes it to the flange: part of the wrench the arm bends under.
pub fn average_torque(
    coefficients: &Coefficients,
    tool: &Tool,
    engagement: &Engagement,
) -> Result<f64, TickError> {
    engagement.validate()?;
    let c = coefficients;
    let e = engagement;
    let n = f64::from(tool.flutes.max(1));
    let integral =
        c.k_tc * e.feed_per_tooth * (e.entry.cos() - e.exit.cos()) + c.k_te * (e.exit - e.entry);
    let m = 0.5 * tool.diameter * e.depth * n / core::f64::consts::TAU * integral;
    crate::error::check_output("average cutting torque", &[m])?;
    Ok(m)
}

/// The rotation from the tool frame to the base frame for a tool axis `axis` (from the tip
/// towards the spindle) and a feed direction `feed` (any length; its part along the axis is
/// dropped), base frame. `None` when either is zero or they are parallel.
pub fn tool_frame(axis: &Vector3<f64>, feed: &Vector3<f64>) -> Option<Rotation3<f64>> {
    let z = axis.try_normalize(1.0e-12)?;
    let x = (feed - z * z.dot(feed)).try_normalize(1.0e-9 * feed.norm().max(1e-300))?;
    let y = z.cross(&x);
    Some(Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
        x, y, z,
    ])))
}
