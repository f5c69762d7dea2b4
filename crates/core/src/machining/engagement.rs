//! Where a flat end mill meets the stock: the material in front of the cutter at up to
//! [`ANGLES`] immersion angles (the [`Chip`]), read from the z-map ([`super::stock::ZMap`]) at
//! the tool's position, so the force model ([`super::chip`]) never asks the user for an
//! engagement.
//!
//! The front half of the cutter (`phi` in `[0, pi]`, clockwise from the tool frame's +y, feed
//! along +x; the conventions of [`super::cutting`]) is probed at [`probe_count`] angles, at
//! most half a cell apart along the rim and at most 1 degree apart: the interpolated
//! stock has its kinks a cell apart, so finer probes only repeat its lines. The probe of
//! angle `phi` lies at the rim's lateral offset `R cos(phi)` and ahead of the tool on the
//! circle of radius `R + PROBE_CLEARANCE cell` around the tip: what the edge at `phi` meets as
//! the tool advances, read where the tool has not cut yet. The clearance of 2 cells keeps the
//! four cell centres the probe interpolates outside the cutter's swept path and its rim's band
//! of half a cell ([`super::stock`]) for any feed direction (they lie within `sqrt(2)` cells
//! of the probe), so the engagement never reads the material the tool itself has just removed; a wall parallel to the feed (the previous pass
//! of a side cut) is read at its exact lateral offset, so the radial width of cut is not
//! biased by the clearance.
//!
//! The depth at a probe is the stock's clipped depth above the tip, interpolated between cell
//! centres ([`super::stock::ZMap::depth_at`]): no threshold switches a probe on, and a change
//! `d` of the tool's position changes every probe's depth by at most `|d_z| + sqrt(2) D / cell
//! |d_xy|` (`D` the largest depth read), which [`super::chip`] turns into the bound on the
//! force. Resolution: a wall met head-on (an entry into the stock) is felt up to
//! `PROBE_CLEARANCE` cells early at the front (`phi = pi / 2`) and up to
//! `sqrt(2 R PROBE_CLEARANCE cell)` early at the sides, where the chip is thinnest.
//!
//! [`Contact`] summarises a chip for reports: the arcs where the depth exceeds [`MIN_DEPTH`].

use nalgebra::{ComplexField, Vector2, Vector3};

use super::stock::ZMap;

/// Most angles probed over the front half of the cutter (1 degree apart).
pub const ANGLES: usize = 181;
/// Fewest angles probed (10 degrees apart).
pub const MIN_ANGLES: usize = 19;
/// How far outside the cutter the probes lie, in cells of the z-map (see the module docs).
pub const PROBE_CLEARANCE: f64 = 2.0;
/// Least depth \[m\] a report counts as an engaged arc (1 um); the force has no threshold.
pub const MIN_DEPTH: f64 = 1.0e-6;
/// Most separate engaged arcs one contact keeps; further arcs are merged into the last.
pub const MAX_ARCS: usize = 8;

/// The probe angle `phi_k = k pi / (count - 1)` of `count` probes \[rad\].
#[inline]
pub fn angle(k: usize, count: usize) -> f64 {
    k as f64 * (core::f64::consts::PI / (count.max(2) - 1) as f64)
}

/// How many angles a cutter of `radius` \[m\] on cells of `cell` \[m\] is probed at: the
/// fewest that put them at most half a cell apart along the rim, within [`MIN_ANGLES`] and
/// [`ANGLES`] (a 16 mm end mill on 0.5 mm cells: 102; a 2 mm one on 0.17 mm cells: 39).
pub fn probe_count(radius: f64, cell: f64) -> usize {
    let gaps = core::f64::consts::PI * radius / (0.5 * cell);
    if gaps.is_finite() && gaps > 0.0 {
        (ComplexField::ceil(gaps.min(ANGLES as f64)) as usize + 1).clamp(MIN_ANGLES, ANGLES)
    } else {
        ANGLES
    }
}

/// Where the probes lie around a cutter of one radius on a z-map of one cell: per angle, the
/// offset ahead of the tip along the feed and to its side (+y of the tool frame) \[m\].
/// Computed once per tool; reading a chip then costs no trigonometry.
#[derive(Debug, Clone, PartialEq)]
pub struct Probes {
    radius: f64,
    count: usize,
    /// The probes' largest distance from the tip \[m\].
    reach: f64,
    ahead: [f64; ANGLES],
    side: [f64; ANGLES],
}

impl Probes {
    /// The probes of a cutter of `radius` \[m\] on a z-map of cells of `cell` \[m\] (both
    /// finite and > 0, as a validated job's are; other values give probes that read no
    /// material).
    pub fn new(radius: f64, cell: f64) -> Self {
        let rho = radius + PROBE_CLEARANCE * cell;
        let count = probe_count(radius, cell);
        let mut ahead = [0.0; ANGLES];
        let mut side = [0.0; ANGLES];
        for (k, (a, s)) in ahead
            .iter_mut()
            .zip(side.iter_mut())
            .enumerate()
            .take(count)
        {
            let lateral = radius * ComplexField::cos(angle(k, count));
            *s = lateral;
            *a = ComplexField::sqrt((rho * rho - lateral * lateral).max(0.0));
        }
        Self {
            radius,
            count,
            reach: rho.abs(),
            ahead,
            side,
        }
    }

    /// The cutter radius \[m\].
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The angles probed ([`probe_count`]).
    pub fn count(&self) -> usize {
        self.count
    }
}

/// What the cutter meets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ChipKind {
    /// Side or slot milling (or air: every depth 0).
    #[default]
    Side,
    /// The tool moves along its axis (or too steeply to have a feed direction): a plunge,
    /// which the side-milling model does not cover; the depths are 0.
    Plunge,
}

/// The material in front of the cutter: its depth above the tip at each probe angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chip {
    /// Depth of stock above the tip at `phi_k` ([`angle`]) \[m\], `>= 0`; entries from
    /// `count` on are unused.
    pub depth: [f64; ANGLES],
    /// The angles probed, [`MIN_ANGLES`]..=[`ANGLES`] (`phi_k = k pi / (count - 1)`).
    pub count: usize,
    /// Side milling or a plunge.
    pub kind: ChipKind,
    /// For a plunge: the stock above the tip at the tool's axis \[m\].
    pub plunge_depth: f64,
}

impl Default for Chip {
    fn default() -> Self {
        Self {
            depth: [0.0; ANGLES],
            count: ANGLES,
            kind: ChipKind::Side,
            plunge_depth: 0.0,
        }
    }
}

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

/// A chip summarised for reports: the arcs deeper than [`MIN_DEPTH`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact {
    /// No probe deeper than [`MIN_DEPTH`].
    Air,
    /// A plunge with material under the tip \[m\] ([`ChipKind::Plunge`]).
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

impl Chip {
    /// The chip summarised: arcs of consecutive probes deeper than [`MIN_DEPTH`] (a single
    /// probe spans one probe step), each with its probes' mean depth.
    pub fn contact(&self) -> Contact {
        if self.kind == ChipKind::Plunge {
            return if self.plunge_depth > MIN_DEPTH {
                Contact::Plunge {
                    depth: self.plunge_depth,
                }
            } else {
                Contact::Air
            };
        }
        let n = self.count.clamp(2, ANGLES);
        let step = angle(1, n);
        let mut arcs = [Arc::default(); MAX_ARCS];
        let (mut count, mut open, mut probes) = (0usize, false, 0usize);
        for (k, &depth) in self.depth.iter().enumerate().take(n) {
            if depth <= MIN_DEPTH {
                open = false;
                continue;
            }
            let phi = angle(k, n);
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
                probes += 1;
                a.depth += (depth - a.depth) / probes as f64;
                a.exit = phi;
            }
        }
        if count == 0 {
            return Contact::Air;
        }
        for a in arcs.iter_mut().take(count) {
            if a.exit <= a.entry {
                a.exit = (a.entry + step).min(core::f64::consts::PI);
                a.entry = a.exit - step;
            }
        }
        Contact::Cutting { arcs, count }
    }

    /// The largest depth over the probes \[m\].
    pub fn deepest(&self) -> f64 {
        self.depth
            .iter()
            .take(self.count)
            .fold(0.0, |m, &d| m.max(d))
    }
}

/// Reads the chip of a vertical cutter with its tip at `tip` \[m\], moving along `feed` (any
/// length; only its horizontal part counts), workpiece frame, into `chip`: allocation-free.
/// `counter_clockwise` (`M4`, a left-hand cutter) mirrors the angles about the feed
/// direction (`phi` clockwise from the tool frame's -y), so [`super::cutting`]'s model of a
/// clockwise cutter applies to the mirror image. A feed whose horizontal part is below 1e-9 of
/// its length is a plunge.
pub fn read(
    stock: &ZMap,
    probes: &Probes,
    tip: &Vector3<f64>,
    feed: &Vector3<f64>,
    counter_clockwise: bool,
    chip: &mut Chip,
) {
    let horizontal = feed.xy();
    let n = horizontal.norm();
    if n.is_nan() || n <= 1.0e-9 * feed.norm() {
        chip.kind = ChipKind::Plunge;
        chip.count = probes.count;
        chip.depth = [0.0; ANGLES];
        chip.plunge_depth = stock.depth_at(&tip.xy(), tip.z);
        return;
    }
    chip.kind = ChipKind::Side;
    chip.plunge_depth = 0.0;
    chip.count = probes.count;
    let x = horizontal / n;
    let left = Vector2::new(-x.y, x.x);
    let y = if counter_clockwise { -left } else { left };
    // Fractional cell coordinates: the tip's, and per metre along x and y.
    let cell = stock.cell();
    let base = (tip.xy() - stock.origin()) / cell - Vector2::repeat(0.5);
    let (xs, ys) = (x / cell, y / cell);
    // A probe whose four cells lie inside the grid is read without the edge cases of
    // `depth_at_index` (the common case, and the hot loop of the pass).
    let (nx, ny) = stock.shape();
    let (umax, vmax) = (nx as f64 - 1.0, ny as f64 - 1.0);
    let z = tip.z;
    let heights = stock.heights();
    for ((d, &a), &s) in chip
        .depth
        .iter_mut()
        .zip(probes.ahead.iter())
        .zip(probes.side.iter())
        .take(probes.count)
    {
        let u = base + xs * a + ys * s;
        *d = if u.x >= 0.0 && u.y >= 0.0 && u.x < umax && u.y < vmax {
            // u, v >= 0: the casts are the floors.
            let (iu, iv) = (u.x as usize, u.y as usize);
            let (fa, fb) = (u.x - iu as f64, u.y - iv as f64);
            let k = iv * nx + iu;
            match (heights.get(k..k + 2), heights.get(k + nx..k + nx + 2)) {
                (Some(&[h00, h10]), Some(&[h01, h11])) => {
                    let (d00, d10) = ((h00 - z).max(0.0), (h10 - z).max(0.0));
                    let (d01, d11) = ((h01 - z).max(0.0), (h11 - z).max(0.0));
                    let low = d00 + (d10 - d00) * fa;
                    let high = d01 + (d11 - d01) * fa;
                    low + (high - low) * fb
                }
                _ => 0.0,
            }
        } else {
            stock.depth_at_index(u.x, u.y, z)
        };
    }
}

/// The contact of a vertical flat end mill of `radius` \[m\] with its tip at `tip` \[m\],
/// moving along `feed`, its spindle turning clockwise seen from above (`M3`): [`read`] with
/// probes built for this call, summarised.
pub fn contact(stock: &ZMap, radius: f64, tip: &Vector3<f64>, feed: &Vector3<f64>) -> Contact {
    contact_turning(stock, radius, tip, feed, false)
}

/// [`contact`] for either spindle direction (see [`read`]).
pub fn contact_turning(
    stock: &ZMap,
    radius: f64,
    tip: &Vector3<f64>,
    feed: &Vector3<f64>,
    counter_clockwise: bool,
) -> Contact {
    let probes = Probes::new(radius, stock.cell());
    let mut chip = Chip::default();
    read(stock, &probes, tip, feed, counter_clockwise, &mut chip);
    chip.contact()
}
