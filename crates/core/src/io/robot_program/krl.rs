//! KUKA KRL (KUKA System Software 8): a `.src` of the motions and a `.dat` of the frames.
//!
//! - `.dat`: `DECL FRAME DEFLECT_BASE` (the workpiece frame in `$ROBROOT`: the controller's
//!   base frame, `$WORLD` for a robot at the world's origin) and `DECL FRAME DEFLECT_TOOL`
//!   (the TCP in the flange frame), each `{X, Y, Z [mm], A, B, C [deg]}` with
//!   `R = Rz(A) Ry(B) Rx(C)` (about Z, Y', X'').
//! - `.src`: `$BASE`, `$TOOL` from those, `$ADVANCE = 3`, a `PTP` of `E6AXIS` to the first
//!   sample's joints; then, Cartesian: `LIN {E6POS: X, Y, Z, A, B, C, S, T}` in `BASE` with
//!   `C_DIS` where the motion blends (`$APO.CDIS` the blending tolerance, mm) and none at an
//!   exact stop, `$VEL.CP` (m/s) where the programmed speed changes; axis-specific: `PTP
//!   {E6AXIS: A1..A6}` (degrees, or mm for a linear axis) with `C_PTP` (at the controller's
//!   PTP speed: the joints' timing is the servo interface's, RSI); `WAIT SEC` for a dwell;
//!   comments (`;`) naming the program lines.
//!
//! Status `S` and turn `T` come from the compensated joints by KUKA's definition
//! ([`crate::controller::kuka_status_turn`]); a `LIN` ignores them, a `PTP` reads them.

use std::fmt::Write as _;
use std::string::String;

use nalgebra::Isometry3;

use super::{Command, Context, ProgramError};
use crate::controller;
use crate::io::decimate::Kept;
use crate::machining::job::JobSample;

/// `X .., Y .., Z .., A .., B .., C ..` of a frame (mm, degrees).
pub(crate) fn frame(t: &Isometry3<f64>) -> String {
    let p = t.translation.vector * 1e3;
    let (roll, pitch, yaw) = t.rotation.euler_angles();
    std::format!(
        "X {:.6},Y {:.6},Z {:.6},A {:.9},B {:.9},C {:.9}",
        p.x,
        p.y,
        p.z,
        yaw.to_degrees(),
        pitch.to_degrees(),
        roll.to_degrees()
    )
}

/// The `.dat` file of the frames.
pub(crate) fn dat(cx: &Context<'_>) -> String {
    let c = cx.convention();
    let base = c.base.inverse() * cx.target.placement;
    std::format!(
        "&ACCESS RVP\n&REL 1\nDEFDAT {name} PUBLIC\n\
         ; written by deflect {version}: the frames of {name}.src\n\
         ; the workpiece frame in $ROBROOT (mm, degrees about Z, Y', X'')\n\
         DECL FRAME DEFLECT_BASE={{{base}}}\n\
         ; the TCP in the flange frame\n\
         DECL FRAME DEFLECT_TOOL={{{tool}}}\n\
         ENDDAT\n",
        name = cx.options.name,
        version = env!("CARGO_PKG_VERSION"),
        base = frame(&base),
        tool = frame(&c.tool),
    )
}

/// `A1 .., A2 .., ..` of the controller's axes of a sample's compensated joints (degrees, mm).
fn axes(cx: &Context<'_>, s: &JobSample) -> String {
    let mut out = String::new();
    for (i, v) in cx.axes(s, true).iter().enumerate() {
        let _ = write!(out, "{}A{} {v:.9}", if i > 0 { "," } else { "" }, i + 1);
    }
    out
}

pub(crate) fn header(
    out: &mut String,
    cx: &mut Context<'_>,
    command: Command,
    first: &JobSample,
) -> Result<(), ProgramError> {
    let what = match command {
        Command::Cartesian => {
            "LIN of the commanded TCP in BASE (mm, degrees), S and T of the compensated joints"
        }
        Command::Joints => "PTP of the compensated joints (degrees)",
    };
    let _ = writeln!(
        out,
        "&ACCESS RVP\n&REL 1\nDEF {name}( )\n\
         ; compensated by deflect {version}: {what}\n\
         $BASE = DEFLECT_BASE\n$TOOL = DEFLECT_TOOL\n$ADVANCE = 3\n\
         ; to the first sample's joints\n\
         PTP {{E6AXIS: {axes}}}",
        name = cx.options.name,
        version = env!("CARGO_PKG_VERSION"),
        axes = axes(cx, first),
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
    if cx.preamble(out, "", ";", s, |t| std::format!("WAIT SEC {t:.4}")) {
        return Ok(());
    }
    let blend = cx.blend_of(k);
    match command {
        Command::Cartesian => {
            let speed = cx.speed_of(s);
            if speed != cx.speed {
                cx.speed = speed;
                let _ = writeln!(out, "$VEL.CP = {speed:.6}");
            }
            if blend > 0.0 && blend != cx.blend {
                cx.blend = blend;
                let _ = writeln!(out, "$APO.CDIS = {:.6}", blend * 1e3);
            }
            let c = cx.convention();
            let (model, data, q) = cx.arm(s);
            let (st, turn) =
                controller::kuka_status_turn(model, data, q, &c).map_err(|e| Context::at(s, e))?;
            let _ = writeln!(
                out,
                "LIN {{E6POS: {},S {st},T {turn}}}{}",
                frame(&super::pose(s)),
                if blend > 0.0 { " C_DIS" } else { "" }
            );
        }
        Command::Joints => {
            let _ = writeln!(
                out,
                "PTP {{E6AXIS: {}}}{}",
                axes(cx, s),
                if blend > 0.0 { " C_PTP" } else { "" }
            );
        }
    }
    Ok(())
}

pub(crate) fn footer(out: &mut String) {
    out.push_str("END\n");
}
