//! CSV for a controller that reads a table (or a script of the user's), SI, the model's own
//! frames and joints (no controller convention):
//!
//! - Cartesian: `time_s, line, x_m, y_m, z_m, qw, qx, qy, qz, blend_m` of the kept commanded
//!   TCP poses in the model's base frame, `blend_m` 0 at an exact stop;
//! - axis-specific: `time_s, line, q1, .., qn` (rad, or m for a linear axis) of the
//!   compensated joints at every sample.
//!
//! Lines starting with `#` are comments (the first one names the writer).

use std::fmt::Write as _;
use std::string::String;

use super::{Command, Context};
use crate::io::decimate::Kept;

pub(crate) fn header(out: &mut String, cx: &mut Context<'_>, command: Command) {
    let _ = writeln!(
        out,
        "# compensated by deflect {}: {}",
        env!("CARGO_PKG_VERSION"),
        match command {
            Command::Cartesian => "the commanded TCP, base frame (m, quaternion)",
            Command::Joints => "the compensated joints (rad or m) at every sample",
        }
    );
    match command {
        Command::Cartesian => out.push_str("time_s,line,x_m,y_m,z_m,qw,qx,qy,qz,blend_m\n"),
        Command::Joints => {
            out.push_str("time_s,line");
            for j in 1..=cx.target.model.dof() {
                let _ = write!(out, ",q{j}");
            }
            out.push('\n');
        }
    }
}

pub(crate) fn motion(out: &mut String, cx: &mut Context<'_>, command: Command, k: &Kept) {
    let s = &k.sample;
    let _ = write!(out, "{},{}", s.path.time, s.path.line);
    match command {
        Command::Cartesian => {
            let p = cx.target.placement * super::pose(s);
            let (v, q) = (p.translation.vector, p.rotation.coords);
            let _ = writeln!(
                out,
                ",{},{},{},{},{},{},{},{}",
                v.x,
                v.y,
                v.z,
                q.w,
                q.x,
                q.y,
                q.z,
                cx.blend_of(k)
            );
        }
        Command::Joints => {
            for q in cx.joints(s) {
                let _ = write!(out, ",{q}");
            }
            out.push('\n');
        }
    }
}
