//! The engagement of a tool in the stock, read from the dexels: per axial slice of the
//! cutter's edge, the immersion angles where the edge meets material as it advances (the
//! surface point a cell ahead along the feed is material, read along the grid direction
//! nearest the surface's normal), as the bands the force model
//! along the edge takes ([`crate::machining::profile::Band`]). Ahead rather than outside the
//! surface: a wall the tool's flank runs along is not engaged (a point outside the flank lies
//! in it; the same point ahead lies in the slot the tool has cut), so the arc's ends are read
//! to a few degrees where the chip is thinnest.

use nalgebra::{ComplexField, Rotation3, Vector3};

use super::{DexelTool, Dexels};
use crate::error::TickError;
use crate::machining::profile::{Band, MAX_BANDS};

/// Most surface samples one engagement reads (slices x angles): 2^20.
pub const MAX_ENGAGEMENT_SAMPLES: usize = 1 << 20;

/// Most angles per slice (a sample every 0.1 degree).
const MAX_ANGLES: usize = 3600;

impl Dexels {
    /// The engagement of `tool` with its tip at `tip` in the tool frame `frame` (its z the tool
    /// axis, x the feed's part across it: [`crate::machining::cutting::tool_frame`]), workpiece
    /// frame: the edge cut into `slices` axial slices of equal height up to the tool's
    /// length, each read at `angles` immersion angles (clockwise from the frame's +y, the
    /// sample at the middle of each of `angles` equal steps) at its middle height, a sample
    /// engaged when its point of the cutter's surface moved a cell along the frame's x is
    /// material (read along the grid direction nearest the surface's normal there). Each
    /// run of engaged angles of a slice becomes a band (a run through angle 0 wraps: its
    /// entry in `[pi, 2 pi)`, its exit past `2 pi`); slices with the same runs merge. Writes
    /// the bands into `out` and returns how many.
    ///
    /// [`TickError::InvalidArgument`] for zero slices or angles, more than 3600 angles, or
    /// `out` too short for the bands found; [`TickError::Budget`] past
    /// [`MAX_ENGAGEMENT_SAMPLES`]; [`TickError::NonFinite`] for a non-finite tip.
    pub fn engagement(
        &self,
        tool: &DexelTool,
        tip: &Vector3<f64>,
        frame: &Rotation3<f64>,
        slices: usize,
        angles: usize,
        out: &mut [Band],
    ) -> Result<usize, TickError> {
        crate::error::check_finite("engagement tip", tip.as_slice())?;
        if slices == 0 || !(1..=MAX_ANGLES).contains(&angles) {
            return Err(TickError::InvalidArgument {
                what: "engagement slices (>= 1) and angles (1..=3600)",
                value: slices.min(angles) as f64,
            });
        }
        let samples = slices.saturating_mul(angles);
        if samples > MAX_ENGAGEMENT_SAMPLES {
            return Err(TickError::Budget {
                what: "engagement surface samples (slices x angles)",
                budget: "MAX_ENGAGEMENT_SAMPLES",
                limit: MAX_ENGAGEMENT_SAMPLES as f64,
                requested: samples as f64,
            });
        }
        let tau = core::f64::consts::TAU;
        let step = tau / angles as f64;
        let dz = tool.length / slices as f64;
        let ahead = frame * Vector3::x() * self.cell;
        let mut n = 0usize;
        for k in 0..slices {
            let z = (k as f64 + 0.5) * dz;
            let engaged = |j: usize| {
                let phi = (j as f64 + 0.5) * step;
                self.engaged_at(tool, tip, frame, &ahead, z, phi)
            };
            // Runs of engaged samples; a run through the last sample continues at sample 0.
            let start = (0..angles).find(|&j| !engaged(j));
            let Some(start) = start else {
                n = push_band(out, n, k, dz, (0.0, tau))?;
                continue;
            };
            let mut j = start + 1;
            while j <= start + angles {
                if engaged(j % angles) {
                    let first = j;
                    while j < start + angles && engaged(j % angles) {
                        j += 1;
                    }
                    let (a, b) = (first as f64 * step, j as f64 * step);
                    // Entries in [0, 2 pi).
                    let (a, b) = if a >= tau { (a - tau, b - tau) } else { (a, b) };
                    n = push_band(out, n, k, dz, (a, b))?;
                }
                j += 1;
            }
        }
        self.refine(
            tool,
            tip,
            frame,
            &ahead,
            dz,
            out.get_mut(..n).unwrap_or(&mut []),
        );
        Ok(n)
    }

    /// Whether the cutter's surface point at height `z` and immersion `phi` (tool frame
    /// `frame`, tip `tip`), moved by `ahead`, is material: read along the grid direction
    /// closest to the surface's normal there (the material's boundary near the tool runs
    /// along the tool).
    fn engaged_at(
        &self,
        tool: &DexelTool,
        tip: &Vector3<f64>,
        frame: &Rotation3<f64>,
        ahead: &Vector3<f64>,
        z: f64,
        phi: f64,
    ) -> bool {
        let r = tool.radius_at(z);
        // The outward normal's parts at this height: across (sin kappa) and down (cos).
        let slope = {
            let h = 1e-6 * tool.length;
            let (lo, hi) = ((z - h).max(0.0), (z + h).min(tool.length));
            (tool.radius_at(hi) - tool.radius_at(lo)) / (hi - lo)
        };
        let m = ComplexField::sqrt(1.0 + slope * slope);
        let (sk, ck) = (1.0 / m, slope / m);
        let (s, c) = ComplexField::sin_cos(phi);
        let local = Vector3::new(r * s, r * c, z);
        let normal = frame * Vector3::new(sk * s, sk * c, -ck);
        self.is_material_along(&(tip + frame * local + ahead), normal.iamax())
    }

    /// The bands' axial ends found between the slices' middles: where the engagement at a
    /// band's middle angle changes, by bisection to a millionth of a slice (a band's end at
    /// a slice boundary would be off by up to half a slice: the depth of cut, and the force
    /// with it). An end another band continues from stays where it is.
    fn refine(
        &self,
        tool: &DexelTool,
        tip: &Vector3<f64>,
        frame: &Rotation3<f64>,
        ahead: &Vector3<f64>,
        dz: f64,
        bands: &mut [Band],
    ) {
        let joined = |b: &Band, z: f64| (b.bottom - z).abs() <= 1e-12 || (b.top - z).abs() <= 1e-12;
        for k in 0..bands.len() {
            let Some(&b) = bands.get(k) else { continue };
            let phi = 0.5 * (b.entry + b.exit);
            let at = |z: f64| self.engaged_at(tool, tip, frame, ahead, z, phi);
            let mut ends = [b.bottom, b.top];
            for (e, lower) in ends.iter_mut().zip([true, false]) {
                let z = *e;
                let inner = if lower { z + 0.5 * dz } else { z - 0.5 * dz };
                let outer = if lower { z - 0.5 * dz } else { z + 0.5 * dz };
                let shared = bands
                    .iter()
                    .enumerate()
                    .any(|(i, o)| i != k && joined(o, z));
                if shared || outer < 0.0 || outer > tool.length || !at(inner) || at(outer) {
                    continue;
                }
                let (mut yes, mut no) = (inner, outer);
                while (yes - no).abs() > 1e-6 * dz {
                    let mid = 0.5 * (yes + no);
                    if at(mid) {
                        yes = mid;
                    } else {
                        no = mid;
                    }
                }
                *e = 0.5 * (yes + no);
            }
            let [lo, hi] = ends;
            if let Some(slot) = bands.get_mut(k) {
                slot.bottom = lo.min(hi);
                slot.top = hi.max(lo);
            }
        }
    }
}

/// Appends the band of slice `k` over `angles`, merging it into a band of the slice below
/// with the same angles.
fn push_band(
    out: &mut [Band],
    n: usize,
    k: usize,
    dz: f64,
    angles: (f64, f64),
) -> Result<usize, TickError> {
    {
        let (bottom, top) = (k as f64 * dz, (k + 1) as f64 * dz);
        if let Some(last) = out.get_mut(..n).and_then(|o| {
            o.iter_mut().rev().find(|b| {
                (b.top - bottom).abs() <= 1e-12 * top.max(1e-300)
                    && b.entry == angles.0
                    && b.exit == angles.1
            })
        }) {
            last.top = top;
            return Ok(n);
        }
        let Some(slot) = out.get_mut(n).filter(|_| n < MAX_BANDS) else {
            return Err(TickError::InvalidArgument {
                what: "engagement bands (more than the output holds, or MAX_BANDS)",
                value: (n + 1) as f64,
            });
        };
        *slot = Band {
            bottom,
            top,
            entry: angles.0,
            exit: angles.1,
        };
        Ok(n + 1)
    }
}
