//! Canned cycles (`G73`, `G74`, `G81`-`G89`) expanded into the moves LinuxCNC makes (its
//! `interp_cycles.cc`): the rise to R when the tool starts below it, the clear height (`G99`:
//! R; `G98`: the series' initial level, not below R), `L` repeats with `G91` increments, the
//! modal R, depth, P, Q and I/J/K, the pecks of `G73`/`G83` (retract 0.254 mm = 0.010 in), in
//! any plane (the drilling axis is the plane's normal). Arithmetic is in the program's unit,
//! as LinuxCNC's, so the number of pecks is the same.

use std::string::String;

use nalgebra::Vector3;

use super::fault::{Fault, fault};
use super::interp::{FeedMode, Machine};
use super::words::{Words, g_name};
use crate::machining::{Motion, Plane};

/// The peck retract of `G73` and the approach gap of `G83` \[m\] (0.010 in = 0.254 mm).
pub const PECK_CLEARANCE: f64 = 0.254e-3;

/// What a cycle's body does.
struct Geometry {
    /// Plane axes: the two positioning axes and the drilling axis (indices 0 x, 1 y, 2 z).
    axes: (usize, usize, usize),
    /// R, bottom and clear heights along the drilling axis, program units.
    r: f64,
    bottom: f64,
    clear: f64,
}

impl Machine {
    /// A point at plane coordinates (`a`, `b`) and height `c`, all in program units.
    fn cycle_point(&self, g: &Geometry, a: f64, b: f64, c: f64) -> Vector3<f64> {
        let mut p = Vector3::zeros();
        let (ia, ib, ic) = g.axes;
        for (k, v) in [(ia, a), (ib, b), (ic, c)] {
            if let Some(x) = p.get_mut(k) {
                *x = v * self.units;
            }
        }
        p
    }

    fn rapid_to(
        &mut self,
        g: &Geometry,
        a: f64,
        b: f64,
        c: f64,
        column: usize,
    ) -> Result<(), Fault> {
        let p = self.cycle_point(g, a, b, c);
        self.emit(Motion::Rapid, p, 0.0, column)
    }

    fn feed_to(
        &mut self,
        g: &Geometry,
        a: f64,
        b: f64,
        c: f64,
        w: &Words,
        column: usize,
    ) -> Result<(), Fault> {
        let p = self.cycle_point(g, a, b, c);
        self.straight(Motion::Linear, p, w, column)
    }

    /// A canned cycle block (see the module docs).
    pub(super) fn cycle(&mut self, w: &mut Words, code: u16, column: usize) -> Result<(), Fault> {
        let name = g_name(code);
        if self.feed_mode == FeedMode::InverseTime {
            return fault(
                column,
                std::format!("{name}: no inverse time feed (G93) with a canned cycle"),
            );
        }
        let same = self.motion == Some(code);
        let repeats = repeats(w, &name)?;
        let (axes, depth_letter) = match self.plane {
            Plane::Xy => ((0, 1, 2), b'z'),
            Plane::Zx => ((2, 0, 1), b'y'),
            Plane::Yz => ((1, 2, 0), b'x'),
        };
        let axis_name = char::from(depth_letter.to_ascii_uppercase());
        let (r_word, depth_word) = self.cycle_levels(w, depth_letter, same, &name, column)?;
        let (ia, ib, ic) = axes;
        let here = |m: &Self, k: usize| m.pos.get(k).copied().unwrap_or(0.0) / m.units;
        let initial = match self.cycle.initial {
            Some(v) => v,
            None => {
                let v = self.pos.get(ic).copied().unwrap_or(0.0);
                self.cycle.initial = Some(v);
                v
            }
        };
        let mut old_c = initial / self.units;
        let mut holes = self.holes(w, axes, &name, column)?;
        let (r, bottom) = if self.absolute {
            (r_word, depth_word)
        } else {
            (r_word + old_c, r_word + old_c + depth_word)
        };
        if r < bottom {
            return fault(
                w.column(b'r'),
                std::format!(
                    "{name}: R at or above the depth {axis_name} (R {r}, {axis_name} {bottom})"
                ),
            );
        }
        let mut g = Geometry {
            axes,
            r,
            bottom,
            clear: r,
        };
        if old_c < r {
            self.rapid_to(&g, here(self, ia), here(self, ib), r, column)?;
            old_c = r;
        }
        g.clear = if self.retract_old_z { old_c } else { r };
        let body = self.cycle_words(w, code, same, &name, column)?;
        for rep in 0..repeats {
            let (a, b) = holes
                .next()
                .map_err(|e| (column, std::format!("{name}: {e}")))?;
            self.approach(&g, a, b, rep == 0, column)?;
            self.cycle_body(&g, &body, a, b, w, code, column)?;
        }
        self.cycle.r = Some(r_word);
        self.cycle.depth = Some(depth_word);
        Ok(())
    }

    /// The block's R and depth words (the drilling axis' letter `depth_letter`), program
    /// units: its own, or in a series of the same cycle (`same`) the remembered ones.
    fn cycle_levels(
        &self,
        w: &mut Words,
        depth_letter: u8,
        same: bool,
        name: &str,
        column: usize,
    ) -> Result<(f64, f64), Fault> {
        let axis_name = char::from(depth_letter.to_ascii_uppercase());
        let Some(r_word) = w.take(b'r').or(if same { self.cycle.r } else { None }) else {
            return fault(
                column,
                std::format!("{name}: R, the retract plane (needed on a cycle's first block)"),
            );
        };
        let Some(depth_word) = w
            .take(depth_letter)
            .or(if same { self.cycle.depth } else { None })
        else {
            return fault(
                column,
                std::format!(
                    "{name}: {axis_name}, the hole's depth (needed on a cycle's first block)"
                ),
            );
        };
        Ok((r_word, depth_word))
    }

    /// The rapid moves to R over the hole at (`a`, `b`): for the block's `first` hole when
    /// the tool is above R, straight across at its height and down, else by way of the clear
    /// height. Program units.
    fn approach(
        &mut self,
        g: &Geometry,
        a: f64,
        b: f64,
        first: bool,
        column: usize,
    ) -> Result<(), Fault> {
        let r = g.r;
        let c = self.pos.get(g.axes.2).copied().unwrap_or(0.0) / self.units;
        if first && c > r {
            let p = self.cycle_point(g, a, b, c);
            self.emit(Motion::Rapid, p, 0.0, column)?;
            self.rapid_to(g, a, b, r, column)?;
        } else {
            self.rapid_to(g, a, b, g.clear, column)?;
            if g.clear > r {
                self.rapid_to(g, a, b, r, column)?;
            }
        }
        Ok(())
    }

    /// Where the block's holes are, in the plane's axes (program units): its words, or polar
    /// `@ ^` (G17); in `G91`, steps from the current point per repeat.
    fn holes(
        &self,
        w: &mut Words,
        (ia, ib, _): (usize, usize, usize),
        name: &str,
        column: usize,
    ) -> Result<Holes, Fault> {
        let letter = |k: usize| [b'x', b'y', b'z'].get(k).copied().unwrap_or(b'x');
        let (aw, bw) = (w.take(letter(ia)), w.take(letter(ib)));
        let (radius, theta) = (w.take(b'@'), w.take(b'^').map(f64::to_radians));
        let polar = radius.is_some() || theta.is_some();
        if polar && (self.plane != Plane::Xy || aw.is_some() || bw.is_some()) {
            return fault(
                w.first_of(b"@^").unwrap_or(column),
                std::format!("{name}: polar coordinates (@, ^) in G17 only, without X and Y"),
            );
        }
        let here = |k: usize| self.pos.get(k).copied().unwrap_or(0.0) / self.units;
        let (mut a, mut b) = (here(ia), here(ib));
        if !self.absolute {
            return Ok(Holes {
                a,
                b,
                step: (aw.unwrap_or(0.0), bw.unwrap_or(0.0)),
                polar: (radius.unwrap_or(0.0), theta.unwrap_or(0.0)),
            });
        }
        if polar {
            let rad = radius.unwrap_or(a.hypot(b));
            let th = theta.unwrap_or(b.atan2(a));
            (a, b) = (rad * th.cos(), rad * th.sin());
        } else {
            (a, b) = (aw.unwrap_or(a), bw.unwrap_or(b));
        }
        Ok(Holes {
            a,
            b,
            step: (0.0, 0.0),
            polar: (0.0, 0.0),
        })
    }

    /// The P, Q and I/J/K a cycle needs, checked and remembered.
    fn cycle_words(
        &mut self,
        w: &mut Words,
        code: u16,
        same: bool,
        name: &str,
        column: usize,
    ) -> Result<Body, Fault> {
        let mut body = Body::default();
        if matches!(code, 740 | 820 | 840 | 860 | 880 | 890) {
            let p = w.take(b'p').filter(|p| *p != -1.0);
            if let Some(p) = p {
                self.cycle.p = Some(p);
            } else if !matches!(code, 740 | 840) && !same {
                return fault(
                    column,
                    std::format!("{name}: P, the dwell time (needed on its first block)"),
                );
            }
            body.dwell = self.cycle.p.unwrap_or(0.0);
        }
        if matches!(code, 730 | 830) {
            let q = w.take(b'q').filter(|q| *q != -1.0);
            if let Some(q) = q {
                self.cycle.q = Some(q);
            } else if !same {
                return fault(
                    column,
                    std::format!("{name}: Q, the peck depth (needed on its first block)"),
                );
            }
            let q = self.cycle.q.unwrap_or(0.0);
            if q <= 0.0 {
                return fault(
                    w.column(b'q'),
                    std::format!("{name}: a peck depth Q > 0, got Q{q}"),
                );
            }
            body.q = q;
        }
        if code == 870 {
            for (letter, slot) in [(b'i', 0), (b'j', 1), (b'k', 2)] {
                let v = w.take(letter);
                let stored = match slot {
                    0 => &mut self.cycle.i,
                    1 => &mut self.cycle.j,
                    _ => &mut self.cycle.k,
                };
                if v.is_some() {
                    *stored = v;
                } else if !same {
                    return fault(
                        column,
                        std::format!(
                            "G87: {} (needed on its first block)",
                            char::from(letter.to_ascii_uppercase())
                        ),
                    );
                }
            }
        }
        self.check_cycle_spindle(code, name, column)?;
        Ok(body)
    }

    /// The spindle a cycle needs turning: `G74` counter-clockwise, `G84` clockwise, `G86`,
    /// `G87` and `G88` either way.
    fn check_cycle_spindle(&self, code: u16, name: &str, column: usize) -> Result<(), Fault> {
        if matches!(code, 740 | 840 | 860 | 870 | 880) {
            let want = if code == 740 { -1 } else { 1 };
            if self.spindle_dir == 0 || (matches!(code, 740 | 840) && self.spindle_dir != want) {
                return fault(
                    column,
                    std::format!(
                        "{name}: the spindle turning {} before the cycle",
                        if code == 740 {
                            "counter-clockwise (M4)"
                        } else if code == 840 {
                            "clockwise (M3)"
                        } else {
                            "(M3 or M4)"
                        }
                    ),
                );
            }
        }
        Ok(())
    }

    /// The moves of one hole at (`a`, `b`) from R: the cycle's body down to the bottom and
    /// out to the clear height. Program units.
    #[allow(clippy::too_many_arguments)] // reason: the cycle's geometry, its words and where it runs
    fn cycle_body(
        &mut self,
        g: &Geometry,
        body: &Body,
        a: f64,
        b: f64,
        w: &Words,
        code: u16,
        column: usize,
    ) -> Result<(), Fault> {
        let (r, bottom, clear) = (g.r, g.bottom, g.clear);
        let dwell = |m: &mut Self| m.dwell(body.dwell, column);
        match code {
            810 => {
                self.feed_to(g, a, b, bottom, w, column)?;
                self.rapid_to(g, a, b, clear, column)?;
            }
            820 => {
                self.feed_to(g, a, b, bottom, w, column)?;
                dwell(self)?;
                self.rapid_to(g, a, b, clear, column)?;
            }
            730 | 830 => self.peck_drill(g, body, a, b, w, code, column)?,
            740 | 840 => {
                // Tapping: feed in, reverse, dwell, feed out, restore.
                self.feed_to(g, a, b, bottom, w, column)?;
                self.spindle_dir = -self.spindle_dir;
                dwell(self)?;
                self.feed_to(g, a, b, clear, w, column)?;
                self.spindle_dir = -self.spindle_dir;
            }
            850 => {
                self.feed_to(g, a, b, bottom, w, column)?;
                self.feed_to(g, a, b, r, w, column)?;
                self.rapid_to(g, a, b, clear, column)?;
            }
            860 | 880 => {
                // Feed, dwell, spindle stop, out at rapid, spindle on again. G88 stops for
                // LinuxCNC's operator to retract by hand, its interpreter taking the tool to be
                // at the clear height: a robot has no operator's hand, so its retract is this
                // rapid (the one move LinuxCNC does not make).
                let dir = self.spindle_dir;
                self.feed_to(g, a, b, bottom, w, column)?;
                dwell(self)?;
                self.spindle_dir = 0;
                self.rapid_to(g, a, b, clear, column)?;
                self.spindle_dir = dir;
            }
            870 => self.back_bore(g, a, b, w, column)?,
            890 => {
                self.feed_to(g, a, b, bottom, w, column)?;
                dwell(self)?;
                self.feed_to(g, a, b, clear, w, column)?;
            }
            _ => return fault(column, std::format!("{}: not a canned cycle", g_name(code))),
        }
        Ok(())
    }

    /// `G73` (chip break: back up [`PECK_CLEARANCE`]) and `G83` (out to R and back to
    /// [`PECK_CLEARANCE`] above the last depth): feed down `Q` at a time to the bottom, then
    /// out at rapid. Heights in program units.
    #[allow(clippy::too_many_arguments)] // reason: the cycle's geometry, its words and where it runs
    fn peck_drill(
        &mut self,
        g: &Geometry,
        body: &Body,
        a: f64,
        b: f64,
        w: &Words,
        code: u16,
        column: usize,
    ) -> Result<(), Fault> {
        let (r, bottom, clear) = (g.r, g.bottom, g.clear);
        let delta = PECK_CLEARANCE / self.units;
        let mut d = r - body.q;
        let mut pecks = 0u32;
        while d > bottom {
            pecks += 1;
            if pecks > 100_000 {
                return fault(column, "at most 100000 pecks in one hole");
            }
            self.feed_to(g, a, b, d, w, column)?;
            if code == 830 {
                self.rapid_to(g, a, b, r, column)?;
            }
            self.rapid_to(g, a, b, d + delta, column)?;
            d -= body.q;
        }
        self.feed_to(g, a, b, bottom, w, column)?;
        self.rapid_to(g, a, b, clear, column)?;
        Ok(())
    }

    /// `G87`, the back bore: down to the bottom at rapid, offset by the plane's centre words
    /// with the spindle stopped, then on the hole's axis feed to the middle height (the normal's
    /// word: absolute, or from the bottom in `G91`) and back, and out at rapid offset again.
    /// Heights in program units.
    fn back_bore(
        &mut self,
        g: &Geometry,
        a: f64,
        b: f64,
        w: &Words,
        column: usize,
    ) -> Result<(), Fault> {
        let (r, bottom, clear) = (g.r, g.bottom, g.clear);
        let dir = self.spindle_dir;
        let (i, j, k) = (
            self.cycle.i.unwrap_or(0.0),
            self.cycle.j.unwrap_or(0.0),
            self.cycle.k.unwrap_or(0.0),
        );
        // The offset words of the plane's axes and the middle (counterbore top).
        let (oa, ob, mid) = match self.plane {
            Plane::Xy => (i, j, k),
            Plane::Zx => (k, i, j),
            Plane::Yz => (j, k, i),
        };
        let mid = if self.absolute { mid } else { bottom + mid };
        self.rapid_to(g, a + oa, b + ob, r, column)?;
        self.spindle_dir = 0;
        self.rapid_to(g, a + oa, b + ob, bottom, column)?;
        self.rapid_to(g, a, b, bottom, column)?;
        self.spindle_dir = dir;
        self.feed_to(g, a, b, mid, w, column)?;
        self.feed_to(g, a, b, bottom, w, column)?;
        self.spindle_dir = 0;
        self.rapid_to(g, a + oa, b + ob, bottom, column)?;
        self.rapid_to(g, a + oa, b + ob, clear, column)?;
        self.rapid_to(g, a, b, clear, column)?;
        self.spindle_dir = dir;
        Ok(())
    }
}

/// The holes of a block: the first at (`a`, `b`) plus one `step` (`G91`), each next one a step
/// further, the polar steps (radius, angle in radians) turning it about the origin after.
struct Holes {
    a: f64,
    b: f64,
    step: (f64, f64),
    polar: (f64, f64),
}

impl Holes {
    fn next(&mut self) -> Result<(f64, f64), String> {
        self.a += self.step.0;
        self.b += self.step.1;
        for (k, inc) in [self.polar.0, self.polar.1].into_iter().enumerate() {
            if inc == 0.0 {
                continue;
            }
            if self.a == 0.0 && self.b == 0.0 {
                return Err(
                    "incremental polar coordinates away from the origin (the angle is undefined \
                     there)"
                        .into(),
                );
            }
            let (mut rad, mut th) = (self.a.hypot(self.b), self.b.atan2(self.a));
            if k == 0 {
                rad += inc;
            } else {
                th += inc;
            }
            (self.a, self.b) = (rad * th.cos(), rad * th.sin());
        }
        Ok((self.a, self.b))
    }
}

/// `L`, the repeats of a cycle block: an integer in 1..=100,000, 1 without it (not modal).
fn repeats(w: &mut Words, name: &str) -> Result<u32, Fault> {
    let Some(l) = w.take(b'l') else {
        return Ok(1);
    };
    match super::expr::integer(l) {
        Some(l) if (1..=100_000).contains(&l) => Ok(l as u32),
        _ => fault(
            w.column(b'l'),
            std::format!("{name}: repeats L in 1..=100000, got L{l}"),
        ),
    }
}

/// A cycle's dwell \[s\] and peck \[program units\].
#[derive(Debug, Clone, Copy, Default)]
struct Body {
    dwell: f64,
    q: f64,
}
