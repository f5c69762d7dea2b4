//! The codes of a block before its motion, steps 2-23 of LinuxCNC's order: feed mode, F, S,
//! T, the M codes by group (I/O, tool change, spindle and modal state, coolant, overrides),
//! dwell, plane, units, tool length offsets (recorded), coordinate system, path control,
//! distance and retract modes, each checked as LinuxCNC checks it.

use nalgebra::Vector3;

use super::{FeedMode, INCH, Machine};
use crate::io::gcode::fault::{Fault, fault};
use crate::io::gcode::params::Params;
use crate::io::gcode::words::Words;
use crate::machining::{MAX_SPINDLE_RPM, MAX_TOOL_NUMBER, PathControl, Plane};

impl Machine {
    /// Steps 2-23 of LinuxCNC's order: modes, F, S, T, M codes, dwell, plane, units,
    /// compensation, coordinate system, path control, distance and retract modes.
    pub(super) fn modes_before_motion(
        &mut self,
        w: &mut Words,
        params: &mut Params,
    ) -> Result<(), Fault> {
        self.feed_speed_tool(w)?;
        if w.g(1030).is_some() || w.g(1870).is_some() {
            // Haas's look-ahead and smoothness settings (fanuc dialect): recorded.
            w.take(b'p');
            w.take(b'e');
        }
        self.m_codes(w, params)?;
        if let Some(column) = w.g(40) {
            if w.g(20).is_some() || w.g(30).is_some() {
                return fault(column, "G4 alone: G2/G3 on its line use P too");
            }
            let Some(p) = w.take(b'p').filter(|p| *p != -1.0) else {
                return fault(column, "G4 needs P, the dwell time in seconds");
            };
            self.dwell(p, w.column(b'p'))?;
        }
        self.modes(w, params)
    }

    /// Feed mode (`G93`-`G95`: per minute and per revolution reset F), `F`, `S`, `T`.
    fn feed_speed_tool(&mut self, w: &mut Words) -> Result<(), Fault> {
        if w.g(930).is_some() {
            self.feed_mode = FeedMode::InverseTime;
        } else if w.g(940).is_some() {
            self.feed_mode = FeedMode::PerMinute;
            self.feed = 0.0;
        } else if w.g(950).is_some() {
            self.feed_mode = FeedMode::PerRevolution;
            self.feed = 0.0;
        }
        if let Some(f) = w.peek(b'f') {
            if f < 0.0 {
                return fault(w.column(b'f'), std::format!("a feed F >= 0, got F{f}"));
            }
            w.take(b'f');
            if self.feed_mode != FeedMode::InverseTime {
                self.feed = f;
            }
        }
        if let Some(s) = w.take(b's') {
            if !(0.0..=MAX_SPINDLE_RPM).contains(&s) {
                return fault(
                    w.column(b's'),
                    std::format!("a spindle speed S in [0, {MAX_SPINDLE_RPM}] rpm, got S{s}"),
                );
            }
            self.spindle_rpm = s;
        }
        if let Some(t) = w.take(b't') {
            self.selected = tool_number(t, w.column(b't'), "T")?;
        }
        Ok(())
    }

    /// The M codes before the motion, in LinuxCNC's order: I/O, tool change, spindle and
    /// modal state, coolant, overrides.
    fn m_codes(&mut self, w: &mut Words, params: &Params) -> Result<(), Fault> {
        self.io_codes(w)?;
        if w.m(6).is_some() {
            self.tool = self.selected;
            self.spindle_dir = 0;
            self.operation_next = true;
        } else if let Some(column) = w.m(61) {
            let Some(q) = w.take(b'q').filter(|q| *q >= 0.0) else {
                return fault(column, "M61 needs Q, the tool number (>= 0)");
            };
            self.tool = tool_number(q, w.column(b'q'), "M61 Q")?;
        }
        self.spindle_codes(w, params)?;
        if w.m(7).is_some() {
            self.mist = true;
        } else if w.m(8).is_some() {
            self.flood = true;
        } else if w.m(9).is_some() {
            self.mist = false;
            self.flood = false;
        }
        for (m, feed, speed) in [(48, true, true), (49, false, false)] {
            if w.m(m).is_some() {
                self.feed_override = feed;
                self.speed_override = speed;
            }
        }
        for m in 50..=53 {
            if w.m(m).is_some() {
                let on = w.take(b'p') != Some(0.0);
                match m {
                    50 => self.feed_override = on,
                    51 => self.speed_override = on,
                    _ => {}
                }
            }
        }
        Ok(())
    }

    /// Plane, units, tool length offsets (recorded), coordinate system, path control,
    /// distance modes, retract mode.
    fn modes(&mut self, w: &mut Words, params: &Params) -> Result<(), Fault> {
        for (code, plane) in [(170, Plane::Xy), (180, Plane::Zx), (190, Plane::Yz)] {
            if w.g(code).is_some() {
                self.plane = plane;
            }
        }
        if w.g(200).is_some() {
            self.units = INCH;
        } else if w.g(210).is_some() {
            self.units = 1.0e-3;
        }
        self.tool_length(w)?;
        let systems = [540, 550, 560, 570, 580, 590, 591, 592, 593];
        if let Some(n) = systems.iter().position(|&g| w.g(g).is_some())
            && n + 1 != self.system
        {
            self.select_system(n + 1, params);
        }
        if w.g(610).is_some() {
            self.path_control = PathControl::ExactPath;
        } else if w.g(611).is_some() {
            self.path_control = PathControl::ExactStop;
        } else if w.g(640).is_some() {
            let p = w.take(b'p').filter(|p| *p > 0.0).unwrap_or(0.0) * self.units;
            let q = w.take(b'q').map_or(p, |q| q.max(0.0) * self.units);
            self.path_control = PathControl::Blend {
                tolerance: p,
                naive_tolerance: q,
            };
        }
        for (on, off, flag) in [
            (900, 910, &mut self.absolute),
            (901, 911, &mut self.ijk_absolute),
            (980, 990, &mut self.retract_old_z),
        ] {
            if w.g(on).is_some() {
                *flag = true;
            } else if w.g(off).is_some() {
                *flag = false;
            }
        }
        Ok(())
    }

    /// `G43 H`, `G43.1`, `G43.2`, `G49`: recorded (the TCP carries the tool length); their
    /// words are read and checked.
    fn tool_length(&mut self, w: &mut Words) -> Result<(), Fault> {
        if w.g(430).is_some() || w.g(432).is_some() {
            // H names the tool (0: the one in the spindle).
            if let Some(h) = w.take(b'h') {
                tool_number(h, w.column(b'h'), "H")?;
            }
            if let Some(column) = w.g(432)
                && w.peek(b'h').is_none()
                && w.first_of(b"xyz").is_none()
            {
                return fault(column, "G43.2 needs H or axis words");
            }
        } else if w.g(431).is_some() {
            // G43.1 reads every axis word as an offset; they move the tool only with a motion
            // code on the same line (LinuxCNC).
            let motion_here =
                w.g.iter()
                    .any(|g| crate::io::gcode::words_group(g.0) == Some(1) && g.0 != 800);
            for (k, l) in [b'x', b'y', b'z'].into_iter().enumerate() {
                let v = if motion_here { w.peek(l) } else { w.take(l) };
                if let (Some(v), Some(o)) = (v, self.tool_offset.get_mut(k)) {
                    *o = v * self.units;
                }
            }
        } else if w.g(490).is_some() {
            self.tool_offset = Vector3::zeros();
        }
        Ok(())
    }

    /// M62-M68 (outputs and inputs, recorded) and M19 (spindle orientation, recorded): their
    /// words are read and checked, nothing moves.
    fn io_codes(&mut self, w: &mut Words) -> Result<(), Fault> {
        for m in 62..=65 {
            if let Some(column) = w.m(m)
                && w.take(b'p').is_none()
            {
                return fault(column, std::format!("M{m} needs P, the output number"));
            }
        }
        if let Some(column) = w.m(66) {
            let (p, e) = (w.take(b'p'), w.take(b'e'));
            w.take(b'l');
            w.take(b'q');
            if p.is_some() == e.is_some() {
                return fault(
                    column,
                    "M66 needs either P (digital input) or E (analog input)",
                );
            }
        }
        for m in [67, 68] {
            if let Some(column) = w.m(m) {
                if w.take(b'e').is_none() {
                    return fault(
                        column,
                        std::format!("M{m} needs E, the analog output number"),
                    );
                }
                w.take(b'q');
            }
        }
        if w.m(19).is_some() {
            w.take(b'r');
            w.take(b'p');
            w.take(b'q');
        }
        Ok(())
    }

    /// Spindle direction (`M3`-`M5`) and the modal state saved, dropped and restored
    /// (`M70`-`M73`).
    fn spindle_codes(&mut self, w: &mut Words, params: &Params) -> Result<(), Fault> {
        if w.m(3).is_some() {
            self.spindle_dir = 1;
        } else if w.m(4).is_some() {
            self.spindle_dir = -1;
        } else if w.m(5).is_some() {
            self.spindle_dir = 0;
        } else if w.m(70).is_some() || w.m(73).is_some() {
            self.saved = Some(self.modal());
        } else if w.m(71).is_some() {
            self.saved = None;
        } else if let Some(column) = w.m(72) {
            let Some(m) = self.saved else {
                return fault(column, "M72 restores the state M70 saved: no M70 before it");
            };
            self.restore(&m, params);
        }
        Ok(())
    }
}

/// A tool number: an integer within 0.0001, 0..=MAX_TOOL_NUMBER.
fn tool_number(v: f64, column: usize, what: &str) -> Result<u32, Fault> {
    match crate::io::gcode::expr::integer(v) {
        Some(t) if (0..=i64::from(MAX_TOOL_NUMBER)).contains(&t) => Ok(t as u32),
        _ => fault(
            column,
            std::format!("a tool number {what} in 0..={MAX_TOOL_NUMBER} (an integer), got {v}"),
        ),
    }
}
