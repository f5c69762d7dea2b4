//! Where a flat end mill meets the stock: the immersion (entry and exit angles) and the axial
//! depth read from the z-map ([`super::stock::ZMap`]) at the tool's position, so the force
//! model ([`super::cutting`]) never asks the user for them.
//!
//! The front half of the cutter circle (`phi` in `[0, pi]`, clockwise from the tool frame's
//! +y, feed along +x; the conventions of [`super::cutting`]) is probed at [`ANGLES`] angles on
//! a circle of radius `R + 0.75 cell`: three quarters of a cell outside the cutter, so a cell
//! the tool has just cut (its centre within `R` of the path) is never read as material, and a
//! cell it is about to cut is. An angle is engaged where the stock stands more than
//! [`MIN_DEPTH`] above the tip; the entry and exit are the first and last engaged angles and
//! the depth is the mean height above the tip over the engaged angles (the depth that gives
//! the per-revolution force of a varying depth when the force is linear in it). Resolution:
//! one cell at the cutter's rim, i.e. about `sqrt(2 cell / R)` rad at the ends of a slot,
//! where the chip is thin and the force small.

use nalgebra::{ComplexField, Vector2, Vector3};

use super::stock::ZMap;

/// Angles probed over the front half of the cutter (1 degree apart).
pub const ANGLES: usize = 181;
/// Least height of stock above the tip \[m\] that counts as material (1 um).
pub const MIN_DEPTH: f64 = 1.0e-6;
/// Most separate engaged arcs one contact keeps; further arcs are merged into the last.
pub const MAX_ARCS: usize = 8;

/// One contiguous engaged arc of the cutter.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Arc {
    /// Entry angle \[rad\].
    pub entry: f64,
    /// Exit angle \[rad\].
    pub exit: f64,
    /// Mean axial depth over the arc's probes \[m\].
    pub depth: f64,
}

/// Where the cutter meets the stock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact {
    /// No material in front of the cutter.
    Air,
    /// The tool moves along its axis (or too steeply to have a feed direction) with
    /// material under it \[m\]: a plunge, which the side-milling model does not cover.
    Plunge {
        /// Stock above the tip at the tool's axis \[m\].
        depth: f64,
    },
    /// Side and slot milling: the engaged arcs, in increasing angle (`arcs[..count]`).
    Cutting {
        /// The arcs; entries past `count` are zero.
        arcs: [Arc; MAX_ARCS],
        /// Arcs in use, 1..=[`MAX_ARCS`].
        count: usize,
    },
}

impl Contact {
    /// The engaged arcs (empty in air and for plunges).
    pub fn arcs(&self) -> &[Arc] {
        match self {
            Self::Cutting { arcs, count } => arcs.get(..*count).unwrap_or(&[]),
            _ => &[],
        }
    }

    /// The first entry, the last exit \[rad\] and the mean depth over the engaged probes
    /// \[m\]; `None` when not side milling.
    pub fn span(&self) -> Option<Arc> {
        let arcs = self.arcs();
        let (first, last) = (arcs.first()?, arcs.last()?);
        let (mut sum, mut width) = (0.0, 0.0);
        for a in arcs {
            let w = (a.exit - a.entry).max(0.0);
            sum += a.depth * w;
            width += w;
        }
        Some(Arc {
            entry: first.entry,
            exit: last.exit,
            depth: if width > 0.0 {
                sum / width
            } else {
                first.depth
            },
        })
    }
}

/// The contact of a vertical flat end mill of `radius` \[m\] with its tip at `tip` \[m\],
/// moving along `feed` (any length; only its horizontal part counts), workpiece frame, its
/// spindle turning clockwise seen from above (`M3`). A feed whose horizontal part is below
/// 1e-9 of its length is a plunge (or air).
pub fn contact(stock: &ZMap, radius: f64, tip: &Vector3<f64>, feed: &Vector3<f64>) -> Contact {
    contact_turning(stock, radius, tip, feed, false)
}

/// [`contact`] for either spindle direction: `counter_clockwise` (`M4`, a left-hand cutter)
/// mirrors the cutter's angles about the feed direction (`phi` clockwise from the tool frame's
/// -y), so [`super::cutting`]'s model of a clockwise cutter applies to the mirror image.
pub fn contact_turning(
    stock: &ZMap,
    radius: f64,
    tip: &Vector3<f64>,
    feed: &Vector3<f64>,
    counter_clockwise: bool,
) -> Contact {
    let horizontal = feed.xy();
    let n = horizontal.norm();
    if n.is_nan() || n <= 1.0e-9 * feed.norm() {
        return match stock.height_at(&tip.xy()) {
            Some(h) if h - tip.z > MIN_DEPTH => Contact::Plunge { depth: h - tip.z },
            _ => Contact::Air,
        };
    }
    let x = horizontal / n;
    let left = Vector2::new(-x.y, x.x);
    let y = if counter_clockwise { -left } else { left };
    let rho = radius + 0.75 * stock.cell();
    let step = core::f64::consts::PI / (ANGLES - 1) as f64;
    let mut arcs = [Arc::default(); MAX_ARCS];
    let (mut count, mut open, mut probes) = (0usize, false, 0usize);
    for k in 0..ANGLES {
        let phi = k as f64 * step;
        let (sin, cos) = ComplexField::sin_cos(phi);
        let p = tip.xy() + (x * sin + y * cos) * rho;
        let depth = stock.height_at(&p).map_or(0.0, |h| h - tip.z);
        if depth > MIN_DEPTH {
            if !open {
                if count < MAX_ARCS {
                    count += 1;
                    probes = 0;
                    if let Some(a) = arcs.get_mut(count - 1) {
                        *a = Arc {
                            entry: phi,
                            exit: phi,
                            depth: 0.0,
                        };
                    }
                }
                open = true;
            }
            if let Some(a) = arcs.get_mut(count.saturating_sub(1)) {
                // Running mean over the arc's probes.
                probes += 1;
                a.depth += (depth - a.depth) / probes as f64;
                a.exit = phi;
            }
        } else {
            open = false;
        }
    }
    if count == 0 {
        return Contact::Air;
    }
    for a in arcs.iter_mut().take(count) {
        // A single engaged probe still spans one probe step.
        if a.exit <= a.entry {
            a.exit = (a.entry + step).min(core::f64::consts::PI);
            a.entry = a.exit - step;
        }
    }
    Contact::Cutting { arcs, count }
}
