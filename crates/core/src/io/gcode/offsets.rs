//! Work and axis offsets as LinuxCNC keeps them: coordinate systems `G54`-`G59.3` (their
//! offsets and XY rotation in the parameters, mm and degrees), `G10 L2`/`L20`, `G92`,
//! `G92.1`-`G92.3`, `G52`, and the stored points of `G28.1`/`G30.1`. The tool stays where it
//! is when an offset changes: its program coordinates change.

use nalgebra::{Vector2, Vector3};

use super::fault::{Fault, fault};
use super::interp::{Machine, rotate};
use super::params::Params;
use super::words::{Words, g_name};

impl Machine {
    /// Switches to coordinate system `n` (1..=9), loading its offsets from the parameters
    /// (stored in mm) and keeping the machine position.
    pub(super) fn select_system(&mut self, n: usize, params: &Params) {
        let m = self.to_machine(&self.pos);
        let base = 5200 + 20 * n;
        self.system = n;
        self.g5x = Vector3::new(
            params.get(base + 1) * 1e-3,
            params.get(base + 2) * 1e-3,
            params.get(base + 3) * 1e-3,
        );
        self.rotation = params.get(base + 10);
        self.pos = self.to_program(&m);
    }

    /// Group 0 and 16: G10, G28/G30 (and .1), G52, G92 (and .1-.3). Returns whether the
    /// axis words were used here (they then move nothing else).
    pub(super) fn non_modal(&mut self, w: &mut Words, params: &mut Params) -> Result<bool, Fault> {
        let axis_users = [100, 280, 300, 520, 920];
        let user = axis_users.iter().find_map(|&g| w.g(g).map(|c| (g, c)));
        if let Some((g, column)) = user
            && let Some(&(m, _)) =
                w.g.iter()
                    .find(|x| super::words_group(x.0) == Some(1) && x.0 != 800)
        {
            return fault(
                column,
                std::format!(
                    "{} and {}: two codes that both use the axis words",
                    g_name(g),
                    g_name(m)
                ),
            );
        }
        if w.g(281).is_some() || w.g(301).is_some() {
            let base = if w.g(281).is_some() { 5161 } else { 5181 };
            let m = self.to_machine(&self.pos);
            for (k, v) in m.iter().enumerate() {
                params.set(base + k, v * 1e3);
            }
        }
        match user {
            Some((100, column)) => self.g10(w, params, column).map(|()| true),
            Some((280 | 300, column)) => {
                let base = if w.g(280).is_some() { 5161 } else { 5181 };
                self.home(w, params, base, column).map(|()| true)
            }
            Some((520 | 920, column)) => self.g92(w, params, column).map(|()| true),
            _ => {
                for (g, keep_params) in [(921, false), (922, true)] {
                    if w.g(g).is_some() {
                        self.pos += self.g92;
                        self.g92 = Vector3::zeros();
                        params.set(5210, 0.0);
                        if !keep_params {
                            for k in 5211..=5219 {
                                params.set(k, 0.0);
                            }
                        }
                    }
                }
                if w.g(923).is_some() {
                    let stored =
                        Vector3::new(params.get(5211), params.get(5212), params.get(5213)) * 1e-3;
                    self.pos += self.g92 - stored;
                    self.g92 = stored;
                    params.set(5210, 1.0);
                }
                Ok(false)
            }
        }
    }

    /// G92 (set the axis offset so the current point has the given coordinates) and G52 (set
    /// the axis offset itself).
    fn g92(&mut self, w: &mut Words, params: &mut Params, column: usize) -> Result<(), Fault> {
        let local = w.g(520).is_some();
        if w.first_of(b"xyz").is_none() {
            return fault(column, "G92/G52 need at least one axis word (X, Y, Z)");
        }
        for (k, l) in [b'x', b'y', b'z'].into_iter().enumerate() {
            if let Some(v) = w.take(l) {
                let v = v * self.units;
                let (Some(p), Some(o)) = (self.pos.get_mut(k), self.g92.get_mut(k)) else {
                    continue;
                };
                if local {
                    *p += *o - v;
                    *o = v;
                } else {
                    *o += *p - v;
                    *p = v;
                }
            }
        }
        params.set(5210, 1.0);
        for k in 0..3 {
            params.set(5211 + k, self.g92.get(k).copied().unwrap_or(0.0) * 1e3);
        }
        Ok(())
    }

    /// G10 L2 / L20 (work offsets); L1, L10, L11 (tool table entries) and L0 (reload) are
    /// read and recorded: deflect takes the tools from its own table.
    fn g10(&mut self, w: &mut Words, params: &mut Params, column: usize) -> Result<(), Fault> {
        let l = w.take(b'l').map(|l| l.round() as i64);
        let p = w.take(b'p');
        match l {
            Some(2 | 20) => {}
            Some(0 | 1 | 10 | 11) => {
                for letter in *b"xyzrijq" {
                    w.take(letter);
                }
                return Ok(());
            }
            _ => {
                return fault(
                    column,
                    "G10 needs L2 or L20 (work offsets), or L0, L1, L10, L11",
                );
            }
        }
        let Some(p) = p else {
            return fault(
                column,
                "G10 L2/L20 needs P, the coordinate system (0: the active one, 1-9)",
            );
        };
        if p + 0.0001 - p.round() > 0.0002 || !(-0.0001..9.0001).contains(&p) {
            return fault(
                w.column(b'p'),
                std::format!("a coordinate system P in 0..=9 with G10, got P{p}"),
            );
        }
        let n = match (p + 0.0001) as usize {
            0 => self.system,
            n => n,
        };
        let l20 = l == Some(20);
        if w.has(b'i') || w.has(b'j') {
            return fault(
                w.first_of(b"ij").unwrap_or(column),
                "no I or J with G10 L2/L20",
            );
        }
        let base = 5200 + 20 * n;
        let r = match w.take(b'r') {
            Some(_) if l20 => return fault(w.column(b'r'), "no R with G10 L20"),
            Some(r) => {
                params.set(base + 10, r);
                r
            }
            None => params.get(base + 10),
        };
        let old = Vector3::new(
            params.get(base + 1),
            params.get(base + 2),
            params.get(base + 3),
        ) * 1e-3;
        let mut new = old;
        let (x, y, z) = (w.take(b'x'), w.take(b'y'), w.take(b'z'));
        if l20 {
            let m = self.to_machine(&self.pos);
            // The current point in system n, then the offset that gives it the words.
            let cur = rotate(m.xy() - old.xy(), -r) - self.g92.xy();
            let want = Vector2::new(
                x.map_or(cur.x, |v| v * self.units),
                y.map_or(cur.y, |v| v * self.units),
            );
            if x.is_some() || y.is_some() {
                let o = m.xy() - rotate(want + self.g92.xy(), r);
                new.x = o.x;
                new.y = o.y;
            }
            if let Some(z) = z {
                new.z = m.z - self.g92.z - z * self.units;
            }
        } else {
            for (k, v) in [x, y, z].into_iter().enumerate() {
                if let (Some(v), Some(o)) = (v, new.get_mut(k)) {
                    *o = v * self.units;
                }
            }
        }
        for k in 0..3 {
            params.set(base + 1 + k, new.get(k).copied().unwrap_or(0.0) * 1e3);
        }
        if n == self.system {
            // The tool stays where it is: its program coordinates change. (LinuxCNC leaves G92
            // out of this, so with G92 set and a new rotation its tool would jump without a
            // move; a robot's path is continuous, so the machine position is kept.)
            let m = self.to_machine(&self.pos);
            self.g5x = new;
            self.rotation = r;
            self.pos = self.to_program(&m);
        }
        Ok(())
    }
}
