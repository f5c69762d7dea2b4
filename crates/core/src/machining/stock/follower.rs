//! A tool followed sample by sample over one z-map ([`Follower`]): the cells each step newly
//! reaches, and straight runs of samples held back and cut as one move.

use nalgebra::Vector3;

use super::{Cutter, Removal, ZMap};
use crate::error::{TickError, check_finite};
use crate::geometry::distance_to_segment;

/// How far a [`Follower`] may leave cells above the exact sweep \[m\]: 1e-8 m, the pose
/// IK's position tolerance.
pub const FOLLOW_TOLERANCE: f64 = 1.0e-8;

/// Most tips a [`Follower`] holds back ([`Follower::hold_to`]) before it cuts them as one
/// straight move.
pub const MAX_HELD: usize = 16;

/// How far behind the tip, in cells, a held move may reach sideways or ahead of it and still
/// leave every cell the engagement reads untouched ([`Follower::settle`]): the probes lie
/// `R + 2` cells from the tip ([`crate::machining::engagement`]) and read centres within `sqrt(2)`
/// cells of themselves; a cut changes centres within `R + 1/2` cell of the move. With both
/// ends of the move within `h` of the ray behind the tip, its points lie `R + 2 - sqrt(2) h`
/// cells from every probe or more, which clears `R + 1/2 + sqrt(2)` for `h < 0.06`.
const HELD_CLEARANCE: f64 = 0.05;

/// A tool followed sample by sample over one z-map: each [`Self::cut_to`] cuts from where
/// the last one ended. A flat end mill stepping less than a cell visits only the cells its
/// disc newly reaches (every cell within its radius of the last tip is at or below the last
/// tip's height), a few per row instead of its whole footprint, as long as the highest tip
/// since the last full sweep lies at most [`FOLLOW_TOLERANCE`] above the move: the cells are
/// then within that tolerance of [`ZMap::cut`]'s, and a deflected tool's nanometre wobble
/// does not lower its whole footprint every sample.
///
/// [`Self::hold_to`] goes further for a tool moving along a line: it holds up to
/// [`MAX_HELD`] tips back, while they stay within [`FOLLOW_TOLERANCE`] of the straight move
/// from the last tip cut to the newest, shorter than a cell, and cuts that move once (a 10 mm
/// ball stepping 40 um footprints 300 cells once per dozen samples instead of every sample).
/// A tool `FOLLOW_TOLERANCE` off its move cuts cells within that distance times their slope
/// of the exact ones (the surface of a ball, the rim's band), the same as the tip's own
/// tolerance does. [`Self::settle`] cuts the held move before a read that could see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Follower {
    last: Option<(Cutter, Vector3<f64>)>,
    /// The highest a cell under the cutter's disc at the last tip may be \[m\].
    high: f64,
    held: [Vector3<f64>; MAX_HELD],
    count: usize,
}

impl Default for Follower {
    fn default() -> Self {
        Self {
            last: None,
            high: 0.0,
            held: [Vector3::zeros(); MAX_HELD],
            count: 0,
        }
    }
}

impl Follower {
    /// A tool not yet on the stock.
    pub fn new() -> Self {
        Self::default()
    }

    /// The last tip cut to or held \[m\].
    pub fn tip(&self) -> Option<Vector3<f64>> {
        match self.count {
            0 => self.last.map(|(_, p)| p),
            n => self.held.get(n - 1).copied(),
        }
    }

    /// Cuts `stock` with `cutter` from the last tip (or at `to` the first time, or after a
    /// tool change) to `to` \[m\], after the tips held back; the errors of [`ZMap::cut`].
    pub fn cut_to(
        &mut self,
        stock: &mut ZMap,
        cutter: &Cutter,
        to: &Vector3<f64>,
    ) -> Result<Removal, TickError> {
        let held = self.flush(stock)?;
        Ok(held.and(self.cut_now(stock, cutter, to)?))
    }

    /// [`Self::cut_to`], or holds `to` back while the tips since the last cut lie on a line
    /// (see the type's docs). What was cut now (nothing when held) and what was done, for
    /// [`Self::step_to`] to repeat on another stock.
    pub fn hold_to(
        &mut self,
        stock: &mut ZMap,
        cutter: &Cutter,
        to: &Vector3<f64>,
    ) -> Result<(Removal, Step), TickError> {
        check_finite("cut end", to.as_slice())?;
        let Some((c, a)) = self.last else {
            return Ok((self.cut_now(stock, cutter, to)?, Step::Cut));
        };
        if c != *cutter {
            return Ok((self.cut_to(stock, cutter, to)?, Step::Cut));
        }
        let held = self.held.get(..self.count).unwrap_or(&[]);
        if self.count < MAX_HELD
            && (to.xy() - a.xy()).norm() < stock.cell
            && held
                .iter()
                .all(|p| distance_to_segment(p, &a, to) <= FOLLOW_TOLERANCE)
        {
            return Ok((self.step_to(stock, cutter, to, Step::Hold)?, Step::Hold));
        }
        Ok((
            self.step_to(stock, cutter, to, Step::Restart)?,
            Step::Restart,
        ))
    }

    /// Cuts or holds `to` as `step` says (a step [`Self::hold_to`] took on another stock,
    /// so both stocks are cut along moves that end at the same samples), whatever the tips
    /// since the last cut look like; a hold past [`MAX_HELD`] tips, or with another cutter,
    /// cuts first. What was cut now.
    pub fn step_to(
        &mut self,
        stock: &mut ZMap,
        cutter: &Cutter,
        to: &Vector3<f64>,
        step: Step,
    ) -> Result<Removal, TickError> {
        check_finite("cut end", to.as_slice())?;
        let same = matches!(self.last, Some((c, _)) if c == *cutter);
        let removal = match step {
            Step::Cut => return self.cut_to(stock, cutter, to),
            Step::Hold if same && self.count < MAX_HELD => Removal::default(),
            Step::Hold | Step::Restart if same => self.flush(stock)?,
            Step::Hold | Step::Restart => return self.cut_to(stock, cutter, to),
        };
        if let Some(slot) = self.held.get_mut(self.count) {
            *slot = *to;
            self.count += 1;
        }
        Ok(removal)
    }

    /// The tips held back.
    pub fn held(&self) -> usize {
        self.count
    }

    /// Cuts the held move if a read of the stock around `tip` \[m\] moving along `feed`
    /// (the engagement's probes, [`crate::machining::engagement::read`]) could see a cell it changes:
    /// unless both its ends lie within 0.05 cell of the ray behind the tip
    /// (and always for a plunge, read under the tip). What was cut.
    pub fn settle(
        &mut self,
        stock: &mut ZMap,
        tip: &Vector3<f64>,
        feed: &Vector3<f64>,
    ) -> Result<Removal, TickError> {
        let (Some((_, a)), Some(b)) = (self.last, self.count.checked_sub(1)) else {
            return Ok(Removal::default());
        };
        let b = self.held.get(b).copied().unwrap_or(a);
        let horizontal = feed.xy();
        let n = horizontal.norm();
        let h = HELD_CLEARANCE * stock.cell;
        let behind = |p: &Vector3<f64>| {
            let d = p.xy() - tip.xy();
            let x = horizontal / n;
            d.dot(&x) <= h && (d.x * x.y - d.y * x.x).abs() <= h
        };
        if n > 1.0e-9 * feed.norm() && behind(&a) && behind(&b) {
            return Ok(Removal::default());
        }
        self.flush(stock)
    }

    /// Cuts the held tips (as one move to the newest); what was cut.
    pub fn flush(&mut self, stock: &mut ZMap) -> Result<Removal, TickError> {
        let (Some((cutter, _)), Some(b)) = (self.last, self.count.checked_sub(1)) else {
            return Ok(Removal::default());
        };
        let to = self.held.get(b).copied().unwrap_or_default();
        self.count = 0;
        self.cut_now(stock, &cutter, &to)
    }

    fn cut_now(
        &mut self,
        stock: &mut ZMap,
        cutter: &Cutter,
        to: &Vector3<f64>,
    ) -> Result<Removal, TickError> {
        let (from, same) = match self.last {
            Some((c, p)) => (p, c == *cutter),
            None => (*to, false),
        };
        // Every cell under the disc at `from` is at or below `high`; the crescent leaves
        // them there, at most `high` minus the move's lowest tip above the exact sweep.
        let crescent = same && self.high - from.z.min(to.z) <= FOLLOW_TOLERANCE;
        let removal = stock.sweep(cutter, &from, to, crescent)?;
        // `sweep` visits the whole footprint unless the step allows the crescent: then the
        // cells it newly reaches are at or below the higher end of the move, the others
        // where they were; after a whole footprint, every cell under the disc at `to` is at
        // or below `to`.
        self.high = if crescent && stock.crescent(cutter, &from, to) {
            self.high.max(from.z).max(to.z)
        } else {
            to.z
        };
        self.last = Some((*cutter, *to));
        Ok(removal)
    }
}

impl Removal {
    /// Both removals together.
    pub fn and(self, other: Self) -> Self {
        Self {
            cells: self.cells + other.cells,
            volume: self.volume + other.volume,
            deepest: self.deepest.max(other.deepest),
        }
    }
}

/// What [`Follower::hold_to`] did with a tip.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// Held back, on the line of the tips before it.
    Hold,
    /// The tips before it cut; it starts a new line.
    Restart,
    /// Cut at once (the first tip, another cutter).
    Cut,
}
