//! One row of cells of a sweep (see the parent module): which of its cells a straight move
//! can reach, each stretch handed to the [`Pass`] (searched cell by cell) or lowered to the
//! move's floor. Column indices are cells along x; heights and lengths in metres.

use nalgebra::{ComplexField, Vector3};

use super::cutter::{Cutter, Removal};
use super::pass::Pass;

/// A sweep's rows: the pass, and what maps an x \[m\] to a column of the grid's window
/// `[i0, i1)`.
pub(super) struct Rows<'a> {
    pass: &'a Pass<'a>,
    /// Cell edge \[m\] and its inverse.
    cell: f64,
    inv_cell: f64,
    /// The x of the grid's lower corner \[m\].
    ox: f64,
    /// The columns the move can reach.
    i0: usize,
    i1: usize,
    /// The move's horizontal step \[m\] and its slope `by / bx` (0 for `bx = 0`).
    bx: f64,
    by: f64,
    slope: f64,
}

impl<'a> Rows<'a> {
    /// The rows of `pass` over the columns `[i0, i1)` of a grid of cells `cell` \[m\] whose
    /// lower corner lies at x = `ox` \[m\].
    pub(super) fn new(pass: &'a Pass<'a>, cell: f64, ox: f64, i0: usize, i1: usize) -> Self {
        // Per row a few column look-ups: a product, not a division (the row's set-up is a
        // third of a small step's sweep).
        let inv_cell = 1.0 / cell;
        // The crescent's half-plane ahead of `from`: x > from.x - (y - from.y) by / bx.
        let (from, to) = (pass.from, pass.to);
        let (bx, by) = (to.x - from.x, to.y - from.y);
        let slope = if bx != 0.0 { by / bx } else { 0.0 };
        Self {
            pass,
            cell,
            inv_cell,
            ox,
            i0,
            i1,
            bx,
            by,
            slope,
        }
    }

    /// The centre column of x \[m\] rounded up.
    #[inline]
    fn above(&self, x: f64) -> f64 {
        -floor_of(-((x - self.ox) * self.inv_cell - 0.5))
    }

    /// The centre column of x \[m\] rounded down.
    #[inline]
    fn below(&self, x: f64) -> f64 {
        floor_of((x - self.ox) * self.inv_cell - 0.5)
    }

    /// A column clamped into the window.
    #[inline]
    fn clamp(&self, k: f64) -> usize {
        k.clamp(self.i0 as f64, self.i1 as f64) as usize
    }

    /// The pass over the columns `[a, b)` of `row` (its centres at y = `cy` \[m\]).
    #[inline]
    fn search(&self, row: &mut [f64], a: usize, b: usize, cy: f64, removal: &mut Removal) {
        self.pass.row(row, a, b, cy, self.ox, self.cell, removal);
    }

    /// Every column of the window: a long move.
    #[inline]
    pub(super) fn whole(&self, row: &mut [f64], cy: f64, removal: &mut Removal) {
        self.search(row, self.i0, self.i1, cy, removal);
    }

    /// A step shorter than a cell: the columns within r + cell of either end (the hull of
    /// the two discs' chords), a flat end's cells inside its rim's band at both ends lowered
    /// to the floor without the search.
    #[inline]
    pub(super) fn short(&self, row: &mut [f64], cy: f64, removal: &mut Removal) {
        let (cell, r) = (self.cell, self.pass.r);
        let (from, to) = (self.pass.from, self.pass.to);
        // Within r + cell of either end: the hull of the two discs' chords.
        let reach = r + cell;
        let core = (r - 0.5 * cell).max(0.0);
        let core_chord = |p: &Vector3<f64>| {
            let dy = cy - p.y;
            let inner = core * core - dy * dy;
            // 1e-9 m inside, as the crescent's exclusion: rounding stays out.
            (inner > 0.0).then(|| {
                let w = ComplexField::sqrt(inner) - 1.0e-9;
                (p.x - w, p.x + w)
            })
        };
        let chord = |p: &Vector3<f64>| {
            let dy = cy - p.y;
            (dy.abs() <= reach).then(|| {
                let w = ComplexField::sqrt(reach * reach - dy * dy);
                (p.x - w, p.x + w)
            })
        };
        let (a, b) = match (chord(from), chord(to)) {
            (Some(f), Some(t)) => (f.0.min(t.0), f.1.max(t.1)),
            (Some(c), None) | (None, Some(c)) => c,
            (None, None) => return,
        };
        let (a, b) = (self.clamp(self.above(a)), self.clamp(self.below(b) + 1.0));
        // A flat end's cells within `R - cell / 2` of both ends (inside its rim's band all
        // along the move) go to the lower end: one comparison each instead of the cell's
        // search.
        let (ca, cb) = match (self.pass.cutter, core_chord(from), core_chord(to)) {
            (Cutter::Flat { .. }, Some(f), Some(t)) => (
                self.clamp(self.above(f.0.max(t.0))).max(a).min(b),
                self.clamp(self.below(f.1.min(t.1)) + 1.0).max(a).min(b),
            ),
            _ => (b, b),
        };
        if ca >= cb {
            self.search(row, a, b, cy, removal);
        } else {
            self.search(row, a, ca, cy, removal);
            self.pass.floor(row, ca, cb, removal);
            self.search(row, cb, b, cy, removal);
        }
    }

    /// A followed flat end's step shorter than a cell, the crescent only: the disc at `to`
    /// grown by a cell (so the sliver of the capsule between the discs is inside), ahead of
    /// `from`, minus the cells strictly inside the disc at `from`.
    #[inline]
    pub(super) fn crescent(&self, row: &mut [f64], cy: f64, removal: &mut Removal) {
        let (cell, r) = (self.cell, self.pass.r);
        let (from, to) = (self.pass.from, self.pass.to);
        let (bx, by, slope) = (self.bx, self.by, self.slope);
        let reach = r + cell;
        let dy = cy - to.y;
        if dy.abs() > reach {
            return;
        }
        let w = ComplexField::sqrt(reach * reach - dy * dy);
        let (a, b) = (
            self.clamp(self.above(to.x - w)),
            self.clamp(self.below(to.x + w) + 1.0),
        );
        let df = cy - from.y;
        // Only cells ahead of `from` along the move: one behind it has `from` for its
        // closest point, as it had at the end of the last move, and keeps its height to
        // the descent the follower allows.
        let (ha, hb) = if bx > 0.0 {
            (self.clamp(self.above(from.x - df * slope)), self.i1)
        } else if bx < 0.0 {
            (self.i0, self.clamp(self.below(from.x - df * slope) + 1.0))
        } else if df * by > 0.0 {
            (self.i0, self.i1)
        } else {
            return;
        };
        let (a, b) = (a.max(ha), b.min(hb));
        if a >= b {
            return;
        }
        // Cells fully under the disc at `from` (inside its rim's band) are at or below it.
        let core = (r - 0.5 * cell).max(0.0);
        let inner = core * core - df * df;
        if inner <= 0.0 {
            self.search(row, a, b, cy, removal);
            return;
        }
        let wf = ComplexField::sqrt(inner) - 1.0e-9;
        let (ea, eb) = (
            self.clamp(self.above(from.x - wf)),
            self.clamp(self.below(from.x + wf) + 1.0),
        );
        if ea >= eb {
            self.search(row, a, b, cy, removal);
        } else {
            self.search(row, a, ea.max(a).min(b), cy, removal);
            self.search(row, eb.max(a).min(b), b, cy, removal);
        }
    }
}

/// The floor of `x` without a libm call (`x` within +-2^52; else `x`).
#[inline]
fn floor_of(x: f64) -> f64 {
    if x.is_nan() || x.abs() >= 4.0e15 {
        return x;
    }
    let t = x as i64 as f64;
    if t > x { t - 1.0 } else { t }
}
