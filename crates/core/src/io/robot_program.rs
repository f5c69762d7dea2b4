//! Robot programs out (`std`): the compensated job in a robot controller's own language, for
//! controllers without a CNC kernel. Universal Robots URScript so far (KUKA KRL and ABB RAPID
//! follow):
//!
//! - [`urscript_movel`]: the Cartesian command, `movel(p[x, y, z, rx, ry, rz], a, v, r)` per kept
//!   sample of the commanded TCP in the robot's base frame (m; `rx, ry, rz` the rotation
//!   vector, UR's pose convention), `v` the path speed there (m/s), `r` a blend radius of the
//!   decimation tolerance except at a move's end (`r=0`: the program's exact stop). Samples
//!   are dropped while every dropped one lies within `tolerance` of the straight move between
//!   the kept ones and its orientation within `tolerance / 0.1 m` rad of their
//!   interpolation (a point 0.1 m off the flange moves by the tolerance).
//! - [`urscript_servoj`]: the axis-specific command, `servoj(q, 0, 0, t, 0.1, 300)` of the
//!   compensated joints at every sample (`t` the sample period), as the joints of the robot's
//!   URDF: a UR's URDF joints are its controller's.
//!
//! Every motion is preceded by a comment naming the program line and the sample's time when
//! the line changes (`# line 12, t = 3.456 s`), so a user finds the CAM block of each motion.

use std::fmt::Write as _;
use std::string::String;

use nalgebra::{Isometry3, UnitQuaternion};

use crate::contour::shape::distance_to_segment;
use crate::machining::job::{JobSample, Report};

/// Longest run of dropped samples between two `movel`s (bounds the decimation's time).
pub const MAX_DROPPED: usize = super::job_out::MAX_DROPPED;

/// The lever \[m\] that turns the position tolerance into the orientation one.
const ORIENTATION_LEVER: f64 = 0.1;

/// The Cartesian URScript of a run (see the module docs): `placement` the workpiece frame in
/// the base frame (the job's), `tolerance` \[m\] > 0 (not finite or <= 0: 1e-6),
/// `acceleration` \[m/s^2\] the `a` of every `movel` (not finite or <= 0: 1.2, UR's default).
pub fn urscript_movel(
    report: &Report,
    placement: &Isometry3<f64>,
    tolerance: f64,
    acceleration: f64,
) -> String {
    let tol = if tolerance.is_finite() && tolerance > 0.0 {
        tolerance
    } else {
        1.0e-6
    };
    let a = if acceleration.is_finite() && acceleration > 0.0 {
        acceleration
    } else {
        1.2
    };
    let samples = &report.samples;
    let pose = |s: &JobSample| placement * s.commanded;
    let mut text = String::new();
    let _ = writeln!(
        text,
        "def deflect_job():\n  # compensated by deflect {}: the commanded TCP, base frame (m, rotation vector)",
        env!("CARGO_PKG_VERSION")
    );
    let mut line = usize::MAX;
    let mut emit = |text: &mut String, s: &JobSample, end_of_move: bool| {
        if s.path.line != line {
            line = s.path.line;
            let _ = writeln!(text, "  # line {}, t = {:.3} s", line, s.path.time);
        }
        let p = pose(s);
        let v = p.translation.vector;
        let r = p.rotation.scaled_axis();
        let blend = if end_of_move { 0.0 } else { tol };
        let _ = writeln!(
            text,
            "  movel(p[{}, {}, {}, {}, {}, {}], a={a}, v={}, r={blend})",
            v.x,
            v.y,
            v.z,
            r.x,
            r.y,
            r.z,
            s.path.speed.max(1.0e-6)
        );
    };
    let mut anchor = 0usize;
    if let Some(first) = samples.first() {
        emit(&mut text, first, true);
    }
    let holds = |from: usize, to: usize| -> bool {
        let (Some(a), Some(b)) = (samples.get(from), samples.get(to)) else {
            return false;
        };
        let (pa, pb) = (pose(a), pose(b));
        let (ta, tb) = (pa.translation.vector, pb.translation.vector);
        let length = (tb - ta).norm();
        samples.get(from + 1..to).unwrap_or(&[]).iter().all(|s| {
            let p = pose(s);
            let x = p.translation.vector;
            if distance_to_segment(&x, &ta, &tb) > tol {
                return false;
            }
            let t = if length > 0.0 {
                ((x - ta).dot(&(tb - ta)) / (length * length)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let between: UnitQuaternion<f64> = pa.rotation.slerp(&pb.rotation, t);
            between.angle_to(&p.rotation) <= tol / ORIENTATION_LEVER
        })
    };
    for i in 1..samples.len() {
        let (Some(s), next) = (samples.get(i), samples.get(i + 1)) else {
            continue;
        };
        let end_of_move = next.is_none_or(|n| n.path.move_index != s.path.move_index);
        if end_of_move {
            if i - anchor > 1
                && !holds(anchor, i)
                && let Some(prev) = samples.get(i - 1)
            {
                emit(&mut text, prev, false);
            }
            emit(&mut text, s, true);
            anchor = i;
            continue;
        }
        if i - anchor > MAX_DROPPED || !holds(anchor, i) {
            // The sample before `i` is the last the line from the anchor held.
            let keep = (i - 1).max(anchor + 1);
            if let Some(k) = samples.get(keep) {
                emit(&mut text, k, false);
            }
            anchor = keep;
        }
    }
    text.push_str("end\ndeflect_job()\n");
    text
}

/// The axis-specific URScript of a run (see the module docs): `servoj` of the compensated
/// joints of every sample, its first `dof` joints \[rad\].
pub fn urscript_servoj(report: &Report) -> String {
    let mut text = String::new();
    let _ = writeln!(
        text,
        "def deflect_job_joints():\n  # compensated by deflect {}: the compensated joints (rad) at every sample",
        env!("CARGO_PKG_VERSION")
    );
    let t = if report.rate_hz > 0.0 {
        1.0 / report.rate_hz
    } else {
        0.004
    };
    let dof = report.dof;
    let mut line = usize::MAX;
    for s in &report.samples {
        if s.path.line != line {
            line = s.path.line;
            let _ = writeln!(text, "  # line {}, t = {:.3} s", line, s.path.time);
        }
        let _ = write!(text, "  servoj([");
        for (k, q) in s.q_commanded.iter().take(dof).enumerate() {
            let _ = write!(text, "{}{q}", if k > 0 { ", " } else { "" });
        }
        let _ = writeln!(text, "], 0, 0, {t}, 0.1, 300)");
    }
    text.push_str("end\ndeflect_job_joints()\n");
    text
}
