//! The mechanistic force of a cutter of any profile: flat, ball and bull-nose end mills, the
//! edge discretised along the profile, each element with its own angle `kappa` between the tool
//! axis and the surface normal, the tool tilted to the feed.
//!
//! Lee and Altintas, "Prediction of ball-end milling forces from orthogonal cutting data",
//! Int. J. Mach. Tools Manufact. 36(9), 1996, sec. 2 (Eqs. 1-8), generalised to any profile
//! as in Altintas, "Manufacturing Automation", 2nd ed. (Cambridge, 2012), sec. 2.7: an element
//! of the edge at height `z` (from the tip along the axis) and immersion `phi` (clockwise
//! from +y, as in [`super::cutting`]) with a feed per tooth `f` (a vector in the tool frame:
//! its part along the axis is the tilt's) cuts a chip
//!
//! ```text
//! h = f . n,   n = sin(kappa) (sin phi, cos phi, 0) - cos(kappa) z      (the outward normal)
//! ```
//!
//! (`h = f_x sin(phi) sin(kappa)` for a tool not tilted to the feed), of width `db` (the
//! element's length along the profile), and feels
//!
//! ```text
//! dF_t = (K_tc h + K_te) db,   dF_r = (K_rc h + K_re) db,   dF_a = (K_ac h + K_ae) db
//! dF = -dF_t t - dF_r n + dF_a a,   t = (cos phi, -sin phi, 0),
//!                                     a = cos(kappa) (sin phi, cos phi, 0) + sin(kappa) z
//! ```
//!
//! where `h >= 0` (where `h < 0` the edge moves away from the material: no chip, no force).
//! At `kappa = 90 degrees` (the cylinder) this is [`super::cutting`]'s flat end mill exactly;
//! the axial force keeps that module's sign (along `+z` on the cylinder; Altintas' book counts
//! it the other way). Two choices of this model, stated where they matter: the edge force acts
//! on the element's profile length `db` (Lee and Altintas take the helical edge length `dS`;
//! the flat model takes the depth, and so does this one on the cylinder), and the helix is a
//! constant lead: an element at height `z` lags `z tan(helix) / R` behind the tip (the flat
//! model's lag, and Lee and Altintas' ball-end lag with `i0` the helix).
//!
//! The profile (`R` the tool radius, `r` the corner radius: 0 flat, `R` ball, in between
//! bull-nose), by arc length `s` from the tip: the corner's quarter circle `kappa = s / r`,
//! radius `R - r + r sin(kappa)`, height `r (1 - cos(kappa))`, then the cylinder. A flat end
//! mill's bottom face is not part of it (it lies at `z = 0` and cuts only when plunging).
//!
//! Engagement is given as [`Band`]s: an axial range of the edge and the immersion angles it
//! cuts over (what a stock model reads along the cutter's edge). [`average`] integrates over
//! a revolution: in the immersion in closed form, along the profile by 8-point Gauss-Legendre
//! on pieces split wherever the integrand is not smooth (band ends, the corner's end, where the
//! chip's zero crosses an entry or exit angle, and, with a square-root substitution, where the
//! chip's zeros meet). [`force`] sums the edges at one spindle angle the same way along the
//! profile, split where an edge enters or leaves its band. Both return the wrench about the
//! tool tip in the tool frame. Allocation-free.

mod average;
mod instant;

pub use average::average;
pub use instant::force;

use nalgebra::{ComplexField, Vector3};

use super::cutting::{Coefficients, Tool};
use crate::error::{BuildError, TickError};

/// Most bands one cut may list.
pub const MAX_BANDS: usize = 64;

/// Most helix turns one band of [`force`] may span (`(top - bottom) tan(helix) / R / 2 pi`):
/// each turn is one more piece per flute; past it [`force`] refuses with [`TickError::Budget`].
pub const MAX_LAG_TURNS: f64 = 64.0;

/// The 8-point Gauss-Legendre rule on `[-1, 1]`: nodes and weights.
const GAUSS: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_27),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_361_96),
    (0.183_434_642_495_649_8, 0.362_683_783_378_361_96),
    (0.525_532_409_916_329, 0.313_706_645_877_887_27),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];

/// The `(node, weight)` pairs of the 8-point rule on `[a, b]`; with `graded` the nodes crowd
/// towards `a` by `s = a + (b - a) u^2` (the weight carries `2 u`), which turns a
/// square-root endpoint behaviour at `a` into a smooth integrand.
fn nodes(a: f64, b: f64, graded: bool) -> impl Iterator<Item = (f64, f64)> {
    let w = b - a;
    GAUSS.iter().map(move |&(x, g)| {
        let u = 0.5 * (x + 1.0);
        if graded {
            (a + w * u * u, g * w * u)
        } else {
            (a + w * u, 0.5 * g * w)
        }
    })
}

/// The end of a cutter.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ToolShape {
    /// Flat end mill.
    #[default]
    Flat,
    /// Ball end mill (end radius = half the diameter).
    Ball,
    /// Bull-nose (torus) end mill with `corner_radius` \[m\], in `(0, diameter / 2)`.
    BullNose {
        /// Corner radius \[m\].
        corner_radius: f64,
    },
}

impl ToolShape {
    /// "flat", "ball" or "bull-nose".
    pub fn name(&self) -> &'static str {
        match self {
            Self::Flat => "flat",
            Self::Ball => "ball",
            Self::BullNose { .. } => "bull-nose",
        }
    }
}

/// A cutter's profile and flutes, from a tool and its end shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    radius: f64,
    corner: f64,
    lead: f64,
    flutes: u32,
}

/// One element of the edge: its distance from the axis `radius` \[m\], height `z` above the
/// tip \[m\] and the angle `kappa` \[rad\] between the axis and the surface normal, with
/// `sin` and `cos` of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Element {
    /// Distance from the axis \[m\].
    pub radius: f64,
    /// Height above the tip along the axis \[m\].
    pub z: f64,
    /// `sin(kappa)`.
    pub sin: f64,
    /// `cos(kappa)`.
    pub cos: f64,
}

impl Profile {
    /// The profile of `tool` (diameter, flutes, helix) with end `shape`: a corner radius of 0
    /// (flat), the tool's radius (ball) or the bull-nose's (in `(0, D / 2)`).
    /// [`BuildError::InvalidParameter`] for a tool or corner out of range.
    pub fn new(tool: &Tool, shape: ToolShape) -> Result<Self, BuildError> {
        tool.validate()?;
        let radius = 0.5 * tool.diameter;
        let corner = match shape {
            ToolShape::Flat => 0.0,
            ToolShape::Ball => radius,
            ToolShape::BullNose { corner_radius } => crate::error::param(
                "bull-nose corner radius",
                corner_radius,
                corner_radius > 0.0 && corner_radius < radius,
                "in (0, diameter / 2) m",
            )?,
        };
        Ok(Self {
            radius,
            corner,
            lead: ComplexField::tan(tool.helix) / radius,
            flutes: tool.flutes,
        })
    }

    /// The tool's radius \[m\].
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The corner radius \[m\] (0 flat, the radius for a ball).
    pub fn corner(&self) -> f64 {
        self.corner
    }

    /// The number of flutes.
    pub fn flutes(&self) -> u32 {
        self.flutes
    }

    /// The helix lag per metre of height \[rad/m\]: `tan(helix) / R`.
    pub fn lead(&self) -> f64 {
        self.lead
    }

    /// The arc length of the corner's quarter circle \[m\].
    fn round(&self) -> f64 {
        self.corner * core::f64::consts::FRAC_PI_2
    }

    /// The element at arc length `s` \[m\] from the tip.
    pub fn element(&self, s: f64) -> Element {
        let round = self.round();
        if s < round && self.corner > 0.0 {
            let (sin, cos) = ComplexField::sin_cos(s / self.corner);
            Element {
                radius: self.radius - self.corner + self.corner * sin,
                z: self.corner * (1.0 - cos),
                sin,
                cos,
            }
        } else {
            Element {
                radius: self.radius,
                z: self.corner + (s - round),
                sin: 1.0,
                cos: 0.0,
            }
        }
    }

    /// The arc length \[m\] at height `z` \[m\] above the tip (`z >= 0`).
    pub fn arc_length(&self, z: f64) -> f64 {
        if z < self.corner {
            self.corner * ComplexField::acos((1.0 - z / self.corner).clamp(-1.0, 1.0))
        } else {
            self.round() + (z - self.corner)
        }
    }

    /// The arc length \[m\] where the corner's `kappa` is `kappa` (in `[0, pi / 2]`), `None`
    /// on a flat end mill or outside.
    fn arc_at(&self, kappa: f64) -> Option<f64> {
        (self.corner > 0.0 && (0.0..=core::f64::consts::FRAC_PI_2).contains(&kappa))
            .then_some(self.corner * kappa)
    }
}

/// An axial range of the edge and the immersion it cuts over: heights `bottom..top` \[m\]
/// above the tip along the axis, angles `entry..exit` \[rad\] clockwise from +y (`0 <= entry
/// < 2 pi`, `entry < exit <= entry + 2 pi`: the back of the tool too, where a tilted or
/// plunging tool cuts).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Band {
    /// Lowest height \[m\].
    pub bottom: f64,
    /// Highest height \[m\].
    pub top: f64,
    /// Entry angle \[rad\].
    pub entry: f64,
    /// Exit angle \[rad\].
    pub exit: f64,
}

impl Band {
    /// The band of a 2.5-D cut: depth `depth` from the tip, immersion `entry..exit`.
    pub fn new(depth: f64, entry: f64, exit: f64) -> Self {
        Self {
            bottom: 0.0,
            top: depth,
            entry,
            exit,
        }
    }
}

/// What one cut engages: the bands and the feed per tooth as a vector in the tool frame
/// \[m\] (x along the feed's part across the axis, z along the axis: a tool tilted to the
/// feed moves along it too; see [`tool_feed`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cut<'a> {
    /// The engaged bands, at most [`MAX_BANDS`].
    pub bands: &'a [Band],
    /// Feed per tooth \[m\], tool frame, length at most 0.01 m.
    pub feed: Vector3<f64>,
}

impl Cut<'_> {
    /// Checks the bands (heights finite, `0 <= bottom < top <= 1 m`; angles as [`Band`]
    /// says) and the feed (finite, at most 0.01 m long): [`TickError::NonFinite`],
    /// [`TickError::InvalidArgument`] naming the first out of range, [`TickError::Budget`]
    /// past [`MAX_BANDS`].
    pub fn validate(&self) -> Result<(), TickError> {
        if self.bands.len() > MAX_BANDS {
            return Err(TickError::Budget {
                what: "engaged bands of one cut",
                budget: "MAX_BANDS",
                limit: MAX_BANDS as f64,
                requested: self.bands.len() as f64,
            });
        }
        crate::error::check_finite("feed per tooth", self.feed.as_slice())?;
        if self.feed.norm() > 0.01 {
            return Err(TickError::InvalidArgument {
                what: "feed per tooth (length 0..=0.01 m)",
                value: self.feed.norm(),
            });
        }
        let tau = core::f64::consts::TAU;
        for b in self.bands {
            crate::error::check_finite("band", &[b.bottom, b.top, b.entry, b.exit])?;
            let checks = [
                ("band bottom (0 <= bottom < top)", b.bottom, b.bottom >= 0.0),
                (
                    "band top (bottom < top <= 1 m)",
                    b.top,
                    b.top > b.bottom && b.top <= 1.0,
                ),
                (
                    "band entry (0 <= entry < 2 pi)",
                    b.entry,
                    (0.0..tau).contains(&b.entry),
                ),
                (
                    "band exit (entry < exit <= entry + 2 pi)",
                    b.exit,
                    b.exit > b.entry && b.exit <= b.entry + tau,
                ),
            ];
            for (what, value, ok) in checks {
                if !ok {
                    return Err(TickError::InvalidArgument { what, value });
                }
            }
        }
        Ok(())
    }
}

/// The feed per tooth `feed_per_tooth` \[m\] along the base-frame direction `direction` as a
/// vector in the tool frame of [`super::cutting::tool_frame`]`(axis, direction)`: `c (cos t,
/// 0, sin t)` with `t` the angle of the direction above the plane across the axis (a tool
/// tilted to the feed by a lead angle moves along its axis too). `None` when the direction
/// is zero or along the axis (a plunge: every element's chip is `-c cos(kappa)`, given as
/// `(0, 0, -c)` by the caller).
pub fn tool_feed(
    axis: &Vector3<f64>,
    direction: &Vector3<f64>,
    feed_per_tooth: f64,
) -> Option<Vector3<f64>> {
    let frame = super::cutting::tool_frame(axis, direction)?;
    let d = direction.try_normalize(1.0e-300)?;
    Some(frame.inverse() * d * feed_per_tooth)
}

/// The wrench of a cut on the tool: force \[N\] and moment about the tool tip \[N m\], tool
/// frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EdgeWrench {
    /// Force \[N\].
    pub force: Vector3<f64>,
    /// Moment about the tip \[N m\] (its z part is the cutting torque about the axis).
    pub moment: Vector3<f64>,
}

impl EdgeWrench {
    fn check(self, what: &'static str) -> Result<Self, TickError> {
        crate::error::check_output(what, self.force.as_slice())?;
        crate::error::check_output(what, self.moment.as_slice())?;
        Ok(self)
    }
}

/// The element's chip `h = f . n` at immersion `phi` \[m\].
#[inline]
fn chip(feed: &Vector3<f64>, e: &Element, phi: f64) -> f64 {
    let (s, c) = ComplexField::sin_cos(phi);
    e.sin * (feed.x * s + feed.y * c) - e.cos * feed.z
}

/// The force per metre of profile on an element at `phi` with chip `h` \[N/m\], tool frame.
#[inline]
fn element_force(k: &Coefficients, e: &Element, phi: f64, h: f64) -> Vector3<f64> {
    let (s, c) = ComplexField::sin_cos(phi);
    let ft = k.k_tc * h + k.k_te;
    let fr = k.k_rc * h + k.k_re;
    let fa = k.k_ac * h + k.k_ae;
    // Along (sin, cos, 0): -F_r sin(kappa) + F_a cos(kappa); along z: F_r cos + F_a sin.
    let ar = -fr * e.sin + fa * e.cos;
    Vector3::new(-ft * c + ar * s, ft * s + ar * c, fr * e.cos + fa * e.sin)
}

/// The element's position in the tool frame at `phi` \[m\].
#[inline]
fn position(e: &Element, phi: f64) -> Vector3<f64> {
    let (s, c) = ComplexField::sin_cos(phi);
    Vector3::new(e.radius * s, e.radius * c, e.z)
}

/// Appends `x` to `points[..*n]` when it lies strictly inside `(a, b)` and room is left.
fn push(points: &mut [f64], n: &mut usize, x: f64, a: f64, b: f64) {
    if x > a
        && x < b
        && let Some(slot) = points.get_mut(*n)
    {
        *slot = x;
        *n += 1;
    }
}

/// Sorts `points[..n]` ascending (insertion sort: a handful of breakpoints, no allocation).
fn sort(points: &mut [f64], n: usize) {
    let Some(p) = points.get_mut(..n) else {
        return;
    };
    for i in 1..p.len() {
        let mut j = i;
        while j > 0 && p.get(j - 1) > p.get(j) {
            p.swap(j - 1, j);
            j -= 1;
        }
    }
}
