//! What an offline pass hands back to the shop (`std`): the compensated program as G-code
//! the user's CAM or controller loads like the original ([`compensated_gcode`]), and every
//! sample as CSV ([`samples_csv`]: programmed and commanded poses, nominal and compensated
//! joints for axis-specific correction, the force, the deflection and the pilot wrench of
//! the annotated program).
//!
//! The compensated G-code is in mm (`G21`), absolute (`G90`), one `G1`/`G0` per kept sample
//! of the commanded tip: samples are dropped while the straight line between the kept ones
//! stays within `tolerance` of every dropped one (the correction varies along a move, so
//! arcs come out as lines). Every block says in a comment which program line it comes from.
//! Only the position is corrected in G-code (a 3-axis program has no orientation); the
//! orientation part of the correction is in the CSV's commanded quaternion and joints. The
//! program's tool changes (`T M6`), spindle directions (`M3`, `M4`, `M5`) and dwells (`G4`)
//! are written where they happen.

use std::fmt::Write as _;
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use crate::contour::shape::distance_to_segment;
use crate::error::LoadError;
use crate::machining::job::Report;
use crate::machining::{Motion, Program};

/// Most samples one dropped run may hold before a block is written anyway (bounds the
/// decimation's time to `O(n x 256)`).
pub const MAX_DROPPED: usize = 256;

/// The compensated program (see the module docs); `tolerance` \[m\] > 0 (1e-6 keeps the
/// compensation to a micrometre). `program` must be the one the report was run on (for the
/// feeds).
pub fn compensated_gcode(report: &Report, program: &Program, tolerance: f64) -> String {
    let tolerance = if tolerance.is_finite() && tolerance > 0.0 {
        tolerance
    } else {
        1.0e-6
    };
    let mut out = String::new();
    let _ = writeln!(
        out,
        "%\n(compensated by deflect {}: the commanded tool tip, workpiece frame, mm)\n\
         G21 G90 G17",
        env!("CARGO_PKG_VERSION")
    );
    let samples = &report.samples;
    let point = |k: usize| samples.get(k).map(|s| s.commanded.translation.vector);
    // Keep the first and last sample, every sample where the move changes, and the samples
    // the tolerance needs.
    let mut keep = Vec::with_capacity(samples.len() / 8 + 2);
    let mut anchor = 0usize;
    keep.push(0usize);
    for k in 1..samples.len() {
        let (Some(a), Some(p)) = (point(anchor), point(k)) else {
            continue;
        };
        let changes = samples.get(k + 1).is_none_or(|n| {
            samples
                .get(k)
                .is_some_and(|s| s.path.move_index != n.path.move_index)
        });
        let within = k - anchor <= MAX_DROPPED
            && (anchor + 1..k)
                .all(|j| point(j).is_some_and(|q| distance_to_segment(&q, &a, &p) <= tolerance));
        if !within {
            keep.push(k - 1);
            anchor = k - 1;
        }
        if changes {
            keep.push(k);
            anchor = k;
        }
    }
    keep.dedup();
    let (mut line, mut feed, mut spindle, mut tool) = (0usize, f64::NAN, f64::NAN, 0u32);
    let mut first = true;
    let mut dwelt = usize::MAX;
    for &k in &keep {
        let Some(s) = samples.get(k) else { continue };
        let p = s.commanded.translation.vector * 1e3;
        let mv = program.moves.get(s.path.move_index);
        if s.path.tool != tool {
            tool = s.path.tool;
            let _ = writeln!(out, "T{tool} M6");
            // M6 stops the spindle: it is started again below.
            spindle = f64::NAN;
        }
        if s.path.spindle != spindle {
            spindle = s.path.spindle;
            let rpm = spindle.abs() * 60.0;
            let _ = match spindle {
                v if v > 0.0 => writeln!(out, "S{rpm:.0} M3"),
                v if v < 0.0 => writeln!(out, "S{rpm:.0} M4"),
                _ => writeln!(out, "M5"),
            };
        }
        if s.path.line != line {
            line = s.path.line;
            let _ = writeln!(out, "(program line {line})");
        }
        if let Some(Motion::Dwell { seconds }) = mv.map(|m| m.motion) {
            if dwelt != s.path.move_index {
                dwelt = s.path.move_index;
                let _ = writeln!(out, "G4 P{seconds:.4}");
            }
            continue;
        }
        let word = if first || !s.path.feed_move {
            "G0"
        } else {
            "G1"
        };
        let _ = write!(out, "{word} X{:.4} Y{:.4} Z{:.4}", p.x, p.y, p.z);
        if word == "G1"
            && let Some(f) = mv.map(|m| m.feed)
            && f != feed
        {
            feed = f;
            let _ = write!(out, " F{:.1}", f * 60e3);
        }
        out.push('\n');
        first = false;
    }
    let _ = writeln!(out, "M5\nM30\n%");
    out
}

/// Every sample as CSV, SI: `time_s, line, x_m, y_m, z_m` (programmed tip, workpiece
/// frame), `cx_m, cy_m, cz_m, cqx, cqy, cqz, cqw` (commanded pose, workpiece frame),
/// `q1_rad..` (rigid joints) and `qc1_rad..` (compensated joints), `fx_n, fy_n, fz_n`
/// (force on the tool, workpiece frame), `dx_m, dy_m, dz_m` (deflection, base frame),
/// `pilot_fx_n .. pilot_mz_nm` (the TCP wrench `lead` \[s\] ahead, base frame: the
/// annotated program's pilot signal), `entry_rad, exit_rad, depth_m` (engagement span).
pub fn samples_csv(report: &Report, lead: f64) -> String {
    let n = report.dof;
    let mut out = String::from("time_s,line,x_m,y_m,z_m,cx_m,cy_m,cz_m,cqx,cqy,cqz,cqw");
    for prefix in ["q", "qc"] {
        for j in 1..=n {
            let _ = write!(out, ",{prefix}{j}_rad");
        }
    }
    out.push_str(",fx_n,fy_n,fz_n,dx_m,dy_m,dz_m");
    out.push_str(",pilot_fx_n,pilot_fy_n,pilot_fz_n,pilot_mx_nm,pilot_my_nm,pilot_mz_nm");
    out.push_str(",entry_rad,exit_rad,depth_m\n");
    let pilot = report.pilot_wrenches(lead);
    for (s, w) in report.samples.iter().zip(&pilot) {
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
        for v in s.q.iter().take(n).chain(s.q_commanded.iter().take(n)) {
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
    out
}

/// Writes `text` to `path`, naming the file in the error.
pub fn write(path: impl AsRef<Path>, text: &str) -> Result<(), LoadError> {
    let path = path.as_ref();
    std::fs::write(path, text).map_err(|e| LoadError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}
