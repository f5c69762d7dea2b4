//! `serial`: the serial testbed of [`deflect_sim::scenes::serial`] on the built-in KR 300 or
//! on the user's URDF and stiffness file. [`load`] reads and checks everything before any
//! work (files, chain, start pose, motion reach); [`Cmd::run`] runs, prints the table and
//! writes the files.

use std::path::Path;

use deflect_core::dalembert::serial::Payload;
use deflect_core::mechanism::{Task, largest_task};
use deflect_core::vjm::Deflection;
use deflect_core::vjm::{self, Data};
use deflect_sim::SimError;
use deflect_sim::scenes::serial::{self, MotionParams, SerialOptions, output};
use deflect_sim::urdf_arm::{ArmSpec, KR300_Q0, ServoParams};
use nalgebra::{Matrix3, Vector3};

use super::Cmd;
use super::inputs::{ArmFiles, load_arm};
use crate::cli::{CliError, ModelArg, SerialArgs, TaskArg};

/// Density of the payload cube \[kg/m^3\] (aluminium).
const PAYLOAD_DENSITY: f64 = 2700.0;

/// Everything `serial` needs, checked.
#[derive(Debug)]
pub struct SerialInput {
    /// The arm.
    pub spec: ArmSpec,
    /// The scenario's settings.
    pub options: SerialOptions,
}

/// Margin of a default start joint from its limits \[rad or m\]: 5 % of the range, at most
/// 0.1 (a motion from a pose on a limit leaves the range at once when it moves that joint
/// outwards: the Unitree Z1's elbow, range [0, 2.967], at 0).
fn margin((lo, hi): (f64, f64)) -> f64 {
    let range = hi - lo;
    if range.is_finite() {
        (0.05 * range).min(0.1)
    } else {
        0.1
    }
}

/// The most dexterous pose of the grid {-1, -0.5, 0, 0.5, 1}^n inside the limits less a
/// [`margin`]: the largest smallest singular value of the position-scaled Jacobian. At most 6
/// joints are searched (5^6 poses); further joints sit in the middle of their limits (or the
/// margin inside a one-sided range, or 0 in an unbounded one).
fn dexterous_pose(spec: &ArmSpec, reach: f64) -> Option<Vec<f64>> {
    let robot = &spec.robot;
    let n = robot.model.dof();
    let mut data = Data::new(&robot.model);
    let grid = [-1.0, -0.5, 0.0, 0.5, 1.0];
    let searched = n.min(6);
    let mid = |(lo, hi): (f64, f64)| match (lo.is_finite(), hi.is_finite()) {
        (true, true) => 0.5 * (lo + hi),
        (true, false) => (lo + margin((lo, hi))).max(0.0),
        (false, true) => (hi - margin((lo, hi))).min(0.0),
        (false, false) => 0.0,
    };
    let mut q: Vec<f64> = robot.joint_limits.iter().map(|&l| mid(l)).collect();
    // Per searched joint: the grid's values inside its range less the margin, or five evenly
    // spaced over that interior when fewer fit (a quill's 0.15 m stroke, a narrow wrist).
    let candidates: Vec<Vec<f64>> = (0..searched)
        .map(|k| {
            let (lo, hi) = robot.joint_limits.get(k).copied().unwrap_or((-1e9, 1e9));
            let m = margin((lo, hi));
            let (a, b) = (lo + m, hi - m);
            let inside: Vec<f64> = grid
                .iter()
                .copied()
                .filter(|v| *v >= a && *v <= b)
                .collect();
            if inside.len() >= 2 || !(a.is_finite() && b.is_finite()) || a > b {
                inside
            } else {
                (0..5).map(|i| a + (b - a) * f64::from(i) / 4.0).collect()
            }
        })
        .collect();
    let mut best: Option<(f64, Vec<f64>)> = None;
    let combos: usize = candidates.iter().map(Vec::len).product();
    for code in 0..combos {
        let mut c = code;
        for (qk, cands) in q.iter_mut().zip(&candidates) {
            let len = cands.len().max(1);
            *qk = cands.get(c % len).copied().unwrap_or(0.0);
            c /= len;
        }
        let inside = true;
        if !inside || vjm::joint_jacobian(&robot.model, &mut data, &q).is_err() {
            continue;
        }
        let mut j = data.jacobian.columns(0, n).into_owned();
        for r in 3..6 {
            j.row_mut(r).scale_mut(reach);
        }
        let s = j.svd(false, false).singular_values.min();
        if best.as_ref().is_none_or(|(b, _)| s > *b) {
            best = Some((s, q.clone()));
        }
    }
    best.filter(|(s, _)| *s > 1e-6).map(|(_, q)| q)
}

/// Reads and checks the arm, the start pose and the settings before any work.
pub fn load(a: &SerialArgs) -> Result<SerialInput, CliError> {
    let ArmFiles {
        spec,
        tip,
        urdf_name,
        builtin,
        ..
    } = load_arm(
        a.urdf.as_deref(),
        a.stiffness.as_deref(),
        a.base.as_deref(),
        a.tip.as_deref(),
    )?;
    let model = &spec.robot.model;
    let dof = model.dof();
    if dof < 3 {
        return Err(CliError::Failure(format!(
            "{urdf_name}, tip {tip}: the chain has {dof} actuated joints; the correction needs \
             at least 3 (the TCP position)"
        )));
    }
    // Summed link lengths: the motion's size and the dexterity's length scale.
    let mut data = Data::new(model);
    let reach = {
        let zeros = vec![0.0; dof];
        vjm::forward(model, &mut data, &zeros)
            .map(|p| p.translation.vector.norm())
            .unwrap_or(1.0)
            .max(0.1)
    };
    let scale = match (a.scale, builtin) {
        (Some(s), _) => s,
        (None, true) => 1.0,
        (None, false) => (reach / 3.0).clamp(0.05, 3.0),
    };
    let q0 = start_joints(a, &spec, builtin, reach, &urdf_name)?;
    let task = match a.task {
        TaskArg::Pose => Task::POSE,
        TaskArg::PositionAndAxis => Task::POSITION_AND_AXIS,
        TaskArg::PositionAndSpin => Task::POSITION_AND_SPIN,
        TaskArg::Position => Task::POSITION,
        TaskArg::Auto => largest_task(model, &mut data, &q0).map_err(|e| {
            CliError::Usage(format!(
                "--q0: the start joints are singular for {urdf_name} ({e}); give others"
            ))
        })?,
    };
    if task.rank() > dof {
        return Err(CliError::Usage(format!(
            "--task {}: {} rows for a {dof}-joint arm; choose one with at most {dof}",
            task.name().replace('_', "-"),
            task.rank()
        )));
    }
    let payload = payload(a, &spec, builtin, &urdf_name)?;
    let options = SerialOptions {
        robot: if builtin {
            "KR 300 R2500".to_string()
        } else {
            a.urdf
                .as_ref()
                .and_then(|p| p.file_stem())
                .map_or("robot".into(), |s| s.to_string_lossy().into_owned())
        },
        q0,
        payload,
        motion: MotionParams {
            g: a.g,
            scale,
            ramp: a.ramp,
            turn: a.turn,
            v_max: a.v_max.unwrap_or(2.0 * scale),
        },
        servo: ServoParams::default(),
        tail: 0.3,
        model: match a.model {
            ModelArg::Exact => Deflection::Exact,
            ModelArg::Linearized => Deflection::Linearized,
        },
        link_inertia: !a.payload_only && spec.robot.model.mass_count() > 0,
        task,
    };
    // The motions must be plannable and reachable (rigid IK along them) before the runs.
    serial::check_motions(&spec, &options).map_err(|e| {
        CliError::Usage(format!(
            "the motions from the start pose do not fit {urdf_name} (change --q0, --scale or \
             --turn): {}",
            e.0
        ))
    })?;
    Ok(SerialInput { spec, options })
}

/// The start joints \[rad or m\]: `--q0`, the KR 300's, or the grid's most dexterous pose;
/// checked against the arm's joints and limits.
fn start_joints(
    a: &SerialArgs,
    spec: &ArmSpec,
    builtin: bool,
    reach: f64,
    urdf_name: &str,
) -> Result<Vec<f64>, CliError> {
    let dof = spec.robot.model.dof();
    let q0 = match (&a.q0, builtin) {
        (Some(q), _) => q.clone(),
        (None, true) => KR300_Q0.to_vec(),
        (None, false) => dexterous_pose(spec, reach).ok_or_else(|| {
            CliError::Usage(format!(
                "--q0: no non-singular start pose found on the grid for {urdf_name}; give one"
            ))
        })?,
    };
    if q0.len() != dof {
        return Err(CliError::Usage(format!(
            "--q0: {} values given; expected {dof} (one per actuated joint of {})",
            q0.len(),
            spec.robot.joint_names.join(", ")
        )));
    }
    for (k, (&q, &(lo, hi))) in q0.iter().zip(&spec.robot.joint_limits).enumerate() {
        if q < lo || q > hi {
            return Err(CliError::Usage(format!(
                "--q0: joint {k} ({}) is {q} rad: outside its limits [{lo}, {hi}] rad",
                spec.robot.joint_names.get(k).map_or("?", String::as_str)
            )));
        }
    }
    Ok(q0)
}

/// The payload: `--payload-mass` \[kg\] (the KR 300's 150 kg, else 10 % of the links) as a
/// cube of aluminium on the tool axis.
fn payload(
    a: &SerialArgs,
    spec: &ArmSpec,
    builtin: bool,
    urdf_name: &str,
) -> Result<Payload, CliError> {
    let links_mass: f64 = spec.bodies.iter().map(|b| b.inertia.mass).sum();
    let mass = match (a.payload_mass, builtin) {
        (Some(m), _) => m,
        (None, true) => 150.0,
        // 10 % of the links, to two significant digits (0.03 kg on a hobby arm).
        (None, false) if links_mass > 0.0 => {
            let m = 0.1 * links_mass;
            let unit = 10f64.powf(m.log10().floor() - 1.0);
            (m / unit).round() * unit
        }
        (None, false) => {
            return Err(CliError::Usage(format!(
                "--payload-mass: {urdf_name} has no link masses to take 10 % of; give the \
                 payload mass [kg]"
            )));
        }
    };
    // A cube of aluminium centred on the tool axis, half a side beyond the flange.
    let side = (mass / PAYLOAD_DENSITY).cbrt();
    Ok(Payload {
        mass,
        com: Vector3::new(0.0, 0.0, 0.5 * side),
        inertia: Matrix3::from_diagonal_element(mass * side * side / 6.0),
    })
}

/// The `serial` command (arguments checked by [`SerialArgs::check`], inputs by [`load`]).
fn run(a: &SerialArgs, input: SerialInput, out: &Path) -> Result<(), SimError> {
    let r = serial::serial(&input.spec, &input.options, a.jobs)?;
    put!("{}", output::table(&r));
    let n = output::write_all(out, &r)?;
    say!(
        "wrote {}/serial_summary.{{txt,csv,json}}, serial.mcap ({n} messages), serial.png",
        out.display()
    );
    Ok(())
}

impl Cmd for SerialArgs {
    type Input = SerialInput;

    fn load(&self) -> Result<SerialInput, CliError> {
        load(self)
    }

    fn run(&self, input: SerialInput, out: &Path) -> Result<(), SimError> {
        run(self, input, out)
    }
}
