//! Universal Robots URScript (CB3, e-Series): one `.script` defining and calling
//! `deflect_job()` (the program's name).
//!
//! - `set_tcp(p[x, y, z, rx, ry, rz])`: the TCP in the flange frame (m, rotation vector);
//! - Cartesian: a `movej` to the first sample's joints, then `movel(p[x, y, z, rx, ry, rz],
//!   a=.., v=.., r=..)` of the commanded TCP in the controller's base frame, `v` the move's
//!   programmed speed (m/s), `r` the blending radius (m, 0 at an exact stop), `a`
//!   [`super::ProgramOptions::acceleration`];
//! - axis-specific: `movej` to the first sample's joints, then `servoj(q, 0, 0, t, 0.1, 300)`
//!   of the compensated joints at every sample (`t` the sample period: UR's servo interface
//!   at the job's rate);
//! - `sleep(t)` for a dwell; comments (`#`) naming the program lines.

use std::fmt::Write as _;
use std::string::String;

use nalgebra::Isometry3;

use super::{Command, Context, ProgramError, join};
use crate::io::decimate::Kept;
use crate::machining::job::JobSample;

/// `p[x, y, z, rx, ry, rz]` of a frame (m, rotation vector).
pub(crate) fn pose(t: &Isometry3<f64>) -> String {
    let v = t.translation.vector;
    let r = t.rotation.scaled_axis();
    std::format!(
        "p[{:.9}, {:.9}, {:.9}, {:.12}, {:.12}, {:.12}]",
        v.x,
        v.y,
        v.z,
        r.x,
        r.y,
        r.z
    )
}

/// `[q1, .., qn]` of a sample's compensated joints as the controller reads them (rad).
fn joints(cx: &Context<'_>, s: &JobSample) -> String {
    std::format!("[{}]", join(&cx.axes(s, false), ", ", 12))
}

pub(crate) fn header(
    out: &mut String,
    cx: &mut Context<'_>,
    command: Command,
    first: &JobSample,
) -> Result<(), ProgramError> {
    let c = cx.convention();
    let what = match command {
        Command::Cartesian => "movel of the commanded TCP, base frame (m, rotation vector)",
        Command::Joints => "servoj of the compensated joints (rad) at every sample",
    };
    let _ = writeln!(
        out,
        "def {name}():\n  # compensated by deflect {version}: {what}\n\
         \x20 # the TCP in the flange frame\n\
         \x20 set_tcp({tcp})\n\
         \x20 # to the first sample's joints\n\
         \x20 movej({q}, a=1.4, v=1.05)",
        name = cx.options.name,
        version = env!("CARGO_PKG_VERSION"),
        tcp = pose(&c.tool),
        q = joints(cx, first),
    );
    Ok(())
}

pub(crate) fn motion(
    out: &mut String,
    cx: &mut Context<'_>,
    command: Command,
    k: &Kept,
) -> Result<(), ProgramError> {
    let s = &k.sample;
    match command {
        Command::Cartesian => {
            if cx.preamble(out, "  ", "#", s, |t| std::format!("sleep({t:.4})")) {
                return Ok(());
            }
            let c = cx.convention();
            let p = c.in_controller_base(&(cx.target.placement * super::pose(s)));
            let _ = writeln!(
                out,
                "  movel({}, a={}, v={:.6}, r={:.9})",
                pose(&p),
                cx.options.acceleration,
                cx.speed_of(s),
                cx.blend_of(k)
            );
        }
        Command::Joints => {
            // A dwell is held by its samples: servoj keeps the joints for their periods.
            cx.line_comment(out, "  ", "#", s);
            let period = 1.0 / cx.target.rate_hz;
            let _ = writeln!(out, "  servoj({}, 0, 0, {period}, 0.1, 300)", joints(cx, s));
        }
    }
    Ok(())
}

pub(crate) fn footer(out: &mut String, cx: &Context<'_>) {
    let _ = writeln!(out, "end\n{}()", cx.options.name);
}
