//! `atlas`: the workspace compliance atlas of [`deflect_sim::scenes::serial::atlas`] on the built-in KR 300
//! or on the user's URDF and stiffness file. [`load`] reads and checks everything before any
//! work; [`Cmd::run`] runs, prints the summary and writes `atlas.npz` and `atlas.png`.

use std::path::Path;
use std::time::Instant;

use deflect_core::posture::Reach;
use deflect_sim::SimError;
use deflect_sim::scenes::serial::atlas::{self, AtlasTask};
use deflect_sim::urdf_arm::KR300_Q0;
use deflect_sim::workers::progress;
use nalgebra::Vector3;

use super::Cmd;
use super::inputs::load_robot;
use super::stdout;
use crate::cli::{AtlasArgs, CliError};

/// Reads the robot, checks the seed, builds the task.
pub fn load(a: &AtlasArgs) -> Result<AtlasTask, CliError> {
    let loaded = load_robot(
        a.urdf.as_deref(),
        a.stiffness.as_deref(),
        a.base.as_deref(),
        a.tip.as_deref(),
    )?;
    let (robot, builtin) = (loaded.robot, loaded.builtin);
    let name = a
        .urdf
        .as_ref()
        .map_or("the built-in KR 300 URDF".to_string(), |p| {
            format!("--urdf {}", p.display())
        });
    let tip = robot.tip_link.clone();
    let dof = robot.model.dof();
    if dof < 6 {
        return Err(CliError::Usage(format!(
            "{name}, tip {tip}: {dof} joints; the atlas needs at least 6 (a TCP position and \
             tool axis leave one rotation free only on a 6-axis arm)"
        )));
    }
    let seed = match (&a.seed, builtin) {
        (Some(q), _) => q.clone(),
        (None, true) => KR300_Q0.to_vec(),
        (None, false) => robot
            .joint_limits
            .iter()
            .map(|(l, h)| 0.5 * (l + h))
            .collect(),
    };
    if seed.len() != dof {
        return Err(CliError::Usage(format!(
            "--seed: {} values; expected {dof}, one per joint of {name}",
            seed.len()
        )));
    }
    let (xa, ya, z) = a.region()?;
    let n = (360.0 / a.angle_step).round().max(1.0) as usize;
    let angles = (0..n)
        .map(|k| (-180.0 + a.angle_step * k as f64).to_radians())
        .filter(|t| *t < std::f64::consts::PI)
        .collect();
    Ok(AtlasTask {
        robot,
        name: loaded.name,
        xs: xa.points(),
        ys: ya.points(),
        z,
        tool_axis: Vector3::from_column_slice(&a.tool_axis),
        wrench: deflect_core::vjm::Vector6::from_column_slice(&a.wrench),
        angles,
        seed,
    })
}

/// Runs the atlas and writes its files.
fn run(a: &AtlasArgs, task: &AtlasTask, out: &Path) -> Result<(), SimError> {
    let t0 = Instant::now();
    let bar = progress(task.xs.len(), "atlas rows");
    let points = atlas::compute(task, a.jobs, &bar)?;
    bar.finish_and_clear();
    let wall = t0.elapsed().as_secs_f64();
    let evaluations = points.len() * task.angles.len();
    let reachable = points.iter().filter(|p| p.reachable_angles > 0).count();
    let why = unreachable_summary(&points);
    let npz = out.join("atlas.npz");
    atlas::write_npz(&npz, task, &points)?;
    let png = out.join("atlas.png");
    atlas::plot_heat_map(&png, task, &points)?;
    stdout(format_args!(
        "atlas: {}, {} points x {} angles on {} thread(s) in {wall:.2} s ({:.0} pose \
         evaluations/s)\n{}\nreachable points: {reachable} of {}{why}\n",
        task.name,
        points.len(),
        task.angles.len(),
        a.jobs,
        evaluations as f64 / wall.max(1e-9),
        atlas::title(task),
        points.len()
    ))?;
    let ny = task.ys.len().max(1);
    let best = points
        .iter()
        .enumerate()
        .filter(|(_, p)| p.best_measure.is_finite())
        .min_by(|x, y| x.1.best_measure.total_cmp(&y.1.best_measure));
    match best {
        Some((k, p)) => stdout(format_args!(
            "best placement: x = {:.3} m, y = {:.3} m: |dp| = {:.3} mm at {:.2} deg about the \
             tool axis (worst angle there: {:.3} mm)\n",
            task.xs.get(k / ny).copied().unwrap_or(f64::NAN),
            task.ys.get(k % ny).copied().unwrap_or(f64::NAN),
            p.best_measure * 1e3,
            p.best_angle.to_degrees(),
            p.worst_measure * 1e3
        ))?,
        None if points.iter().any(|p| p.status == Reach::BeyondModel) => stdout(format_args!(
            "no point has a valid posture: the postures exist, but the wrench turns a spring \
             past MAX_SPRING_ANGLE = {} rad (beyond the small-deflection model)\n",
            deflect_core::vjm::MAX_SPRING_ANGLE
        ))?,
        None => stdout(format_args!("no point of the region is reachable\n"))?,
    }
    stdout(format_args!(
        "outputs: {}, {}\n",
        npz.display(),
        png.display()
    ))
}

/// Why the points without a posture have none, as "; 3 out of reach, 2 beyond the model's
/// validity ..." (empty when every point is reachable).
fn unreachable_summary(points: &[atlas::AtlasPoint]) -> String {
    let mut text = String::new();
    for status in Reach::ALL {
        let n = points.iter().filter(|p| p.status == status).count();
        let what = match status {
            Reach::Reachable => continue,
            Reach::OutOfReach => "out of reach",
            Reach::Singular => "only singular postures",
            Reach::JointLimit => "only postures past a joint limit",
            Reach::BeyondModel => {
                "in reach but beyond the model's validity (the wrench turns a spring past \
                 MAX_SPRING_ANGLE)"
            }
        };
        if n > 0 {
            text.push_str(&format!("; {n} {what}"));
        }
    }
    text
}

impl Cmd for AtlasArgs {
    type Input = AtlasTask;

    fn load(&self) -> Result<AtlasTask, CliError> {
        load(self)
    }

    fn run(&self, input: AtlasTask, out: &Path) -> Result<(), SimError> {
        run(self, &input, out)
    }
}
