//! ABB RAPID (RobotWare 6 / 7): one `.mod` module.
//!
//! - `PERS tooldata tool_deflect := [TRUE, [[x, y, z], [q1, q2, q3, q4]], [mass, [0, 0, 0],
//!   [1, 0, 0, 0], 0, 0, 0]]`: the TCP in the flange frame (mm, quaternion w first), the tool
//!   load [`super::ProgramOptions::tool_mass`] at the TCP;
//! - `PERS wobjdata wobj_deflect := [FALSE, TRUE, "", [[x, y, z], [q1..q4]], [[0, 0, 0], [1, 0,
//!   0, 0]]]`: the workpiece frame in the base frame (the user frame);
//! - `PROC main()`: a `MoveAbsJ` to the first sample's joints; then, Cartesian: `MoveL
//!   [[x, y, z], [q1, q2, q3, q4], [cf1, cf4, cf6, cfx], [9E9, ...]], [v_tcp, 500, 5000, 1000],
//!   zone, tool_deflect \WObj:=wobj_deflect;` with the `robtarget` in the work object,
//!   `confdata` of the compensated joints by ABB's definition
//!   ([`crate::controller::abb_confdata`]), `speeddata` of the move's programmed feed (mm/s),
//!   `zonedata` `fine` at an exact stop and `[FALSE, r, r, r, 0.1 r, r, 0.1 r]` of the blending
//!   tolerance `r` (mm, degrees: the pattern of ABB's predefined `z1`) elsewhere;
//!   axis-specific: `MoveAbsJ [[j1..j6], [9E9, ...]]\NoEOffs, ...` (degrees); `WaitTime` for a
//!   dwell; comments (`!`) naming the program lines.

use std::fmt::Write as _;
use std::string::String;

use nalgebra::Isometry3;

use super::{Command, Context, ProgramError, join};
use crate::controller;
use crate::io::decimate::Kept;
use crate::machining::job::JobSample;

/// The external axes RAPID's targets carry: none (9E9).
const NO_EXTERNAL: &str = "[9E9,9E9,9E9,9E9,9E9,9E9]";

/// `[[x, y, z], [q1, q2, q3, q4]]` of a frame (mm, quaternion w-x-y-z).
pub(crate) fn pose(t: &Isometry3<f64>) -> String {
    let p = t.translation.vector * 1e3;
    let q = t.rotation.coords;
    std::format!(
        "[[{:.6},{:.6},{:.6}],[{:.12},{:.12},{:.12},{:.12}]]",
        p.x,
        p.y,
        p.z,
        q.w,
        q.x,
        q.y,
        q.z
    )
}

/// `[[j1, .., j6], [9E9, ..]]` of a sample's compensated joints (degrees, mm for a linear
/// axis).
fn joint_target(cx: &Context<'_>, s: &JobSample) -> String {
    std::format!("[[{}],{NO_EXTERNAL}]", join(&cx.axes(s, true), ",", 9))
}

/// `speeddata` of a speed \[m/s\].
fn speed(v: f64) -> String {
    std::format!("[{:.4},500,5000,1000]", v * 1e3)
}

/// `zonedata` of a blending tolerance \[m\] (0: `fine`).
fn zone(r: f64) -> String {
    if r <= 0.0 {
        return "fine".into();
    }
    let mm = r * 1e3;
    std::format!(
        "[FALSE,{mm:.6},{mm:.6},{mm:.6},{:.6},{mm:.6},{:.6}]",
        0.1 * mm,
        0.1 * mm
    )
}

pub(crate) fn header(
    out: &mut String,
    cx: &mut Context<'_>,
    command: Command,
    first: &JobSample,
) -> Result<(), ProgramError> {
    let c = cx.convention();
    let what = match command {
        Command::Cartesian => {
            "MoveL of the commanded TCP in the work object (mm, quaternion), confdata of the \
             compensated joints"
        }
        Command::Joints => "MoveAbsJ of the compensated joints (degrees)",
    };
    let _ = writeln!(
        out,
        "MODULE {name}\n  ! compensated by deflect {version}: {what}\n\
         \x20 ! the TCP in the flange frame; tool load {mass} kg at the TCP (give your spindle's)\n\
         \x20 PERS tooldata tool_deflect := [TRUE,{tool},[{mass},[0,0,0],[1,0,0,0],0,0,0]];\n\
         \x20 ! the workpiece frame in the base frame\n\
         \x20 PERS wobjdata wobj_deflect := [FALSE,TRUE,\"\",{wobj},[[0,0,0],[1,0,0,0]]];\n\
         \x20 PROC main()\n\
         \x20   ! to the first sample's joints\n\
         \x20   MoveAbsJ {first}\\NoEOffs,v100,fine,tool_deflect\\WObj:=wobj_deflect;",
        name = cx.options.name,
        version = env!("CARGO_PKG_VERSION"),
        mass = cx.options.tool_mass,
        tool = pose(&c.tool),
        wobj = pose(&(c.base.inverse() * cx.target.placement)),
        first = joint_target(cx, first),
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
    if cx.preamble(out, "    ", "!", s, |t| std::format!("WaitTime {t:.4};")) {
        return Ok(());
    }
    let (v, z) = (speed(cx.speed_of(s)), zone(cx.blend_of(k)));
    match command {
        Command::Cartesian => {
            let c = cx.convention();
            let (model, data, q) = cx.arm(s);
            let [cf1, cf4, cf6, cfx] =
                controller::abb_confdata(model, data, q, &c).map_err(|e| Context::at(s, e))?;
            let p = pose(&super::pose(s));
            let target = p.strip_suffix(']').unwrap_or(&p);
            let _ = writeln!(
                out,
                "    MoveL {target},[{cf1},{cf4},{cf6},{cfx}],{NO_EXTERNAL}],{v},{z},tool_deflect\\WObj:=wobj_deflect;"
            );
        }
        Command::Joints => {
            let _ = writeln!(
                out,
                "    MoveAbsJ {}\\NoEOffs,{v},{z},tool_deflect\\WObj:=wobj_deflect;",
                joint_target(cx, s)
            );
        }
    }
    Ok(())
}

pub(crate) fn footer(out: &mut String) {
    out.push_str("  ENDPROC\nENDMODULE\n");
}
