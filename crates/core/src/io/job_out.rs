//! What an offline pass hands back to the shop (`std`): the compensated program as G-code
//! the user's CAM or controller loads like the original ([`compensated_gcode`], or
//! [`GcodeWriter`] as the samples stream), and every sample as CSV ([`samples_csv`],
//! [`CsvWriter`]: programmed and commanded poses, nominal and compensated joints for
//! axis-specific correction, the force, the deflection and the pilot wrench of the annotated
//! program). The writers hold a bounded window of samples (at most [`MAX_DROPPED`] + 2, and
//! the pilot lead's), whatever the program's length.
//!
//! The compensated G-code is in mm (`G21`), absolute (`G90`), one `G1`/`G0` per kept sample
//! of the commanded tip: samples are dropped while the straight line between the kept ones
//! stays within `tolerance` of every dropped one (the correction varies along a move, so
//! arcs come out as lines). Every block says in a comment which program line it comes from.
//! Only the position is corrected in G-code (a 3-axis program has no orientation); the
//! orientation part of the correction is in the CSV's commanded quaternion and joints. The
//! program's tool changes (`T M6`), spindle directions (`M3`, `M4`, `M5`) and dwells (`G4`)
//! are written where they happen.

use std::collections::VecDeque;
use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use crate::error::LoadError;
use crate::geometry::distance_to_segment;
use crate::machining::job::{JobSample, Report};
use crate::machining::{Motion, Program};

pub use super::decimate::MAX_DROPPED;
use super::decimate::{Decimator, Kept};

/// Writes `text` to `out` once it holds 64 KiB (the writers' buffer), and clears it.
fn spill<W: Write>(out: &mut W, text: &mut String) -> std::io::Result<()> {
    if text.len() > 1 << 16 {
        out.write_all(text.as_bytes())?;
        text.clear();
    }
    Ok(())
}

/// The compensated program (see the module docs); `tolerance` \[m\] > 0 (1e-6 keeps the
/// compensation to a micrometre). `program` must be the one the report was run on (for the
/// feeds).
pub fn compensated_gcode(report: &Report, program: &Program, tolerance: f64) -> String {
    let mut w = GcodeWriter::new(Vec::new(), program, tolerance);
    // Writing to a Vec cannot fail.
    let _ = w.push(&report.samples);
    let bytes = w.finish().unwrap_or_default();
    String::from_utf8(bytes).unwrap_or_default()
}

/// The compensated program written as the samples come ([`compensated_gcode`] in pieces):
/// [`Self::push`] each chunk in time order, then [`Self::finish`].
#[derive(Debug)]
pub struct GcodeWriter<'p, W: Write> {
    out: W,
    program: &'p Program,
    tolerance: f64,
    decimator: Decimator,
    started: bool,
    state: BlockState,
    text: String,
}

/// What the blocks written so far have set.
#[derive(Debug, Clone, Copy)]
struct BlockState {
    line: usize,
    feed: f64,
    spindle: f64,
    tool: u32,
    first: bool,
    dwelt: usize,
}

impl<'p, W: Write> GcodeWriter<'p, W> {
    /// A writer of the program run as `program` (for its feeds and dwells), to `out`, the
    /// path decimated to `tolerance` \[m\] (not finite or <= 0: 1e-6).
    pub fn new(out: W, program: &'p Program, tolerance: f64) -> Self {
        Self {
            out,
            program,
            tolerance: if tolerance.is_finite() && tolerance > 0.0 {
                tolerance
            } else {
                1.0e-6
            },
            decimator: Decimator::default(),
            started: false,
            state: BlockState {
                line: 0,
                feed: f64::NAN,
                spindle: f64::NAN,
                tool: 0,
                first: true,
                dwelt: usize::MAX,
            },
            text: String::new(),
        }
    }

    /// The next samples, in time order.
    pub fn push(&mut self, chunk: &[JobSample]) -> std::io::Result<()> {
        if !self.started {
            self.started = true;
            let _ = writeln!(
                self.text,
                "%\n(compensated by deflect {}: the commanded tool tip, workpiece frame, mm)\n\
                 G21 G90 G17",
                env!("CARGO_PKG_VERSION")
            );
        }
        let tolerance = self.tolerance;
        let holds = |a: &JobSample, b: &JobSample, x: &JobSample| {
            let p = |s: &JobSample| s.commanded.translation.vector;
            distance_to_segment(&p(x), &p(a), &p(b)) <= tolerance
        };
        for s in chunk {
            let (decimator, state, text) = (&mut self.decimator, &mut self.state, &mut self.text);
            decimator.push(s, &holds, &mut |k: &Kept| {
                block(state, text, self.program, &k.sample);
            });
            spill(&mut self.out, &mut self.text)?;
        }
        Ok(())
    }

    /// Writes the last sample and the program's end; hands back the output.
    pub fn finish(mut self) -> std::io::Result<W> {
        if !self.started {
            self.push(&[])?;
        }
        let tolerance = self.tolerance;
        let holds = |a: &JobSample, b: &JobSample, x: &JobSample| {
            let p = |s: &JobSample| s.commanded.translation.vector;
            distance_to_segment(&p(x), &p(a), &p(b)) <= tolerance
        };
        let (state, text) = (&mut self.state, &mut self.text);
        self.decimator.finish(&holds, &mut |k: &Kept| {
            block(state, text, self.program, &k.sample);
        });
        let _ = writeln!(self.text, "M5\nM30\n%");
        self.out.write_all(self.text.as_bytes())?;
        self.out.flush()?;
        Ok(self.out)
    }
}

/// Writes the block of a kept sample.
fn block(st: &mut BlockState, out: &mut String, program: &Program, s: &JobSample) {
    let p = s.commanded.translation.vector * 1e3;
    let mv = program.moves.get(s.path.move_index);
    if s.path.tool != st.tool {
        st.tool = s.path.tool;
        let _ = writeln!(out, "T{} M6", st.tool);
        // M6 stops the spindle: it is started again below.
        st.spindle = f64::NAN;
    }
    if s.path.spindle != st.spindle {
        st.spindle = s.path.spindle;
        let rpm = st.spindle.abs() * 60.0;
        let _ = match st.spindle {
            v if v > 0.0 => writeln!(out, "S{rpm:.0} M3"),
            v if v < 0.0 => writeln!(out, "S{rpm:.0} M4"),
            _ => writeln!(out, "M5"),
        };
    }
    if s.path.line != st.line {
        st.line = s.path.line;
        let _ = writeln!(out, "(program line {})", st.line);
    }
    if let Some(Motion::Dwell { seconds }) = mv.map(|m| m.motion) {
        if st.dwelt != s.path.move_index {
            st.dwelt = s.path.move_index;
            let _ = writeln!(out, "G4 P{seconds:.4}");
        }
        return;
    }
    let word = if st.first || !s.path.feed_move {
        "G0"
    } else {
        "G1"
    };
    let _ = write!(out, "{word} X{:.4} Y{:.4} Z{:.4}", p.x, p.y, p.z);
    if word == "G1"
        && let Some(f) = mv.map(|m| m.feed)
        && f != st.feed
    {
        st.feed = f;
        let _ = write!(out, " F{:.1}", f * 60e3);
    }
    out.push('\n');
    st.first = false;
}

/// The CSV's header for an arm of `dof` joints (see [`samples_csv`]).
fn csv_header(dof: usize) -> String {
    let mut out = String::from("time_s,line,x_m,y_m,z_m,cx_m,cy_m,cz_m,cqx,cqy,cqz,cqw");
    for prefix in ["q", "qc"] {
        for j in 1..=dof {
            let _ = write!(out, ",{prefix}{j}_rad");
        }
    }
    out.push_str(",fx_n,fy_n,fz_n,dx_m,dy_m,dz_m");
    out.push_str(",pilot_fx_n,pilot_fy_n,pilot_fz_n,pilot_mx_nm,pilot_my_nm,pilot_mz_nm");
    out.push_str(",entry_rad,exit_rad,depth_m\n");
    out
}

/// One CSV row: sample `s` with the pilot wrench `w`.
fn csv_row(out: &mut String, s: &JobSample, w: &crate::vjm::Vector6, dof: usize) {
    let c = &s.commanded;
    let q = c.rotation.coords;
    let _ = write!(
        out,
        "{},{},{},{},{},{},{},{},{},{},{},{}",
        s.path.time,
        s.path.line,
        s.path.position.x,
        s.path.position.y,
        s.path.position.z,
        c.translation.x,
        c.translation.y,
        c.translation.z,
        q.x,
        q.y,
        q.z,
        q.w
    );
    for v in s.q.iter().take(dof).chain(s.q_commanded.iter().take(dof)) {
        let _ = write!(out, ",{v}");
    }
    for v in s
        .force
        .iter()
        .chain(s.deflection.fixed_rows::<3>(0).iter())
        .chain(w.iter())
    {
        let _ = write!(out, ",{v}");
    }
    let span = s.contact.span();
    let _ = writeln!(
        out,
        ",{},{},{}",
        span.map_or(0.0, |a| a.entry),
        span.map_or(0.0, |a| a.exit),
        span.map_or(0.0, |a| a.depth)
    );
}

/// Every sample as CSV, SI: `time_s, line, x_m, y_m, z_m` (programmed tip, workpiece
/// frame), `cx_m, cy_m, cz_m, cqx, cqy, cqz, cqw` (commanded pose, workpiece frame),
/// `q1_rad..` (rigid joints) and `qc1_rad..` (compensated joints), `fx_n, fy_n, fz_n`
/// (force on the tool, workpiece frame), `dx_m, dy_m, dz_m` (deflection, base frame),
/// `pilot_fx_n .. pilot_mz_nm` (the TCP wrench `lead` \[s\] ahead, base frame: the
/// annotated program's pilot signal), `entry_rad, exit_rad, depth_m` (engagement span).
pub fn samples_csv(report: &Report, lead: f64) -> String {
    let mut w = CsvWriter::new(Vec::new(), report.dof, report.rate_hz, lead);
    let _ = w.push(&report.samples);
    String::from_utf8(w.finish().unwrap_or_default()).unwrap_or_default()
}

/// [`samples_csv`] written as the samples come: each row waits for the sample `lead` ahead
/// (its pilot wrench); the last rows take the last wrench.
#[derive(Debug)]
pub struct CsvWriter<W: Write> {
    out: W,
    dof: usize,
    shift: usize,
    held: VecDeque<JobSample>,
    started: bool,
    text: String,
}

impl<W: Write> CsvWriter<W> {
    /// A writer to `out` for an arm of `dof` joints sampled at `rate_hz`, the pilot wrench
    /// `lead` \[s\] ahead (rounded to samples; negative or non-finite: 0).
    pub fn new(out: W, dof: usize, rate_hz: f64, lead: f64) -> Self {
        let shift = if lead.is_finite() && lead > 0.0 && rate_hz.is_finite() {
            (lead * rate_hz).round().min(1.0e6) as usize
        } else {
            0
        };
        Self {
            out,
            dof,
            shift,
            held: VecDeque::new(),
            started: false,
            text: String::new(),
        }
    }

    /// The next samples, in time order.
    pub fn push(&mut self, chunk: &[JobSample]) -> std::io::Result<()> {
        if !self.started {
            self.started = true;
            self.text.push_str(&csv_header(self.dof));
        }
        for s in chunk {
            self.held.push_back(*s);
            if self.held.len() > self.shift
                && let Some(first) = self.held.pop_front()
            {
                let w = self.held.back().map_or(first.wrench, |b| b.wrench);
                csv_row(&mut self.text, &first, &w, self.dof);
            }
            spill(&mut self.out, &mut self.text)?;
        }
        Ok(())
    }

    /// Writes the rows held for their lead (with the last wrench); hands back the output.
    pub fn finish(mut self) -> std::io::Result<W> {
        if !self.started {
            self.push(&[])?;
        }
        let last = self.held.back().map(|s| s.wrench);
        while let Some(s) = self.held.pop_front() {
            csv_row(&mut self.text, &s, &last.unwrap_or(s.wrench), self.dof);
        }
        self.out.write_all(self.text.as_bytes())?;
        self.out.flush()?;
        Ok(self.out)
    }
}

/// Writes `text` to `path`, naming the file in the error.
pub fn write(path: impl AsRef<Path>, text: &str) -> Result<(), LoadError> {
    let path = path.as_ref();
    std::fs::write(path, text).map_err(|e| LoadError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}
