//! Example 5: where on the table, and in which posture, is the KR 300 stiff enough to mill? A
//! workspace atlas under the milling load of the VJM paper (the Python twin,
//! `05_workspace_atlas.py`, runs the same atlas on every core or on a Dask/Ray cluster).
//!
//! For a grid of workpiece placements on a table 0.2 m above the robot base (x 1.4..2.2 m,
//! y -0.6..0.6 m), the tool pointing down, the rotation about the tool axis is swept in 5
//! degree steps and refined (`deflect_core::posture::sweep`), and the posture that deflects
//! least under the 546 N milling force (Hähn and Weigold, sec. 3) is kept.
//!
//! Run: `cargo run --release --example 05_workspace_atlas`

use deflect_core::SerialRobot;
use deflect_core::posture::{self, AnglePoint, PostureOptions};
use deflect_core::vjm::{Data, Vector6};
use nalgebra::Vector3;

/// The milling posture of example 1 [rad]: the sweeps start from it.
const SEED: [f64; 6] = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];
/// The 546 N milling force in the horizontal plane, base frame [N, N m].
const MILLING: [f64; 6] = [-386.1, 386.1, 0.0, 0.0, 0.0, 0.0];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = env!("CARGO_MANIFEST_DIR");
    let robot = SerialRobot::from_path(
        format!("{root}/robots/kr300/kr300_r2500.urdf"),
        format!("{root}/robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    )?;
    let xs: Vec<f64> = (0..9).map(|i| 1.4 + 0.1 * f64::from(i)).collect();
    let ys: Vec<f64> = (0..7).map(|j| -0.6 + 0.2 * f64::from(j)).collect();
    let angles: Vec<f64> = (0..72)
        .map(|k| (-180.0 + 5.0 * f64::from(k)).to_radians())
        .collect();
    let wrench = Vector6::from_column_slice(&MILLING);
    let down = Vector3::new(0.0, 0.0, -1.0);
    let mut data = Data::new(&robot.model);
    let mut sweep = vec![AnglePoint::default(); angles.len()];
    let options = PostureOptions::default();
    // (best |dp| [m], its angle [rad], worst |dp| [m]) per placement, NaN if unreachable.
    let mut best = vec![vec![(f64::NAN, f64::NAN, f64::NAN); ys.len()]; xs.len()];
    for (row, &x) in best.iter_mut().zip(&xs) {
        for (cell, &y) in row.iter_mut().zip(&ys) {
            let s = posture::sweep(
                &robot.model,
                &mut data,
                &robot.joint_limits,
                &Vector3::new(x, y, 0.2),
                &down,
                &wrench,
                &angles,
                &SEED,
                &options,
                &mut sweep,
            )?;
            if let (Some(b), Some(w)) = (s.best, s.worst_index) {
                *cell = (b.measure, b.angle, sweep[w].measure);
            }
        }
    }
    println!("best |dp| [mm] under 546 N, rows x [m], columns y [m]:");
    let header: Vec<String> = ys.iter().map(|y| format!("{y:6.2}")).collect();
    println!("  x \\ y {}", header.join(" "));
    for (x, row) in xs.iter().zip(&best) {
        let cells: Vec<String> = row
            .iter()
            .map(|c| {
                if c.0.is_nan() {
                    "   ---".to_string()
                } else {
                    format!("{:6.3}", c.0 * 1e3)
                }
            })
            .collect();
        println!("  {x:5.2} {}", cells.join(" "));
    }
    let (i, j) = best
        .iter()
        .enumerate()
        .flat_map(|(i, r)| r.iter().enumerate().map(move |(j, c)| (c.0, (i, j))))
        .filter(|(m, _)| !m.is_nan())
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, ij)| ij)
        .ok_or("no placement is reachable")?;
    let (m, angle, worst) = best[i][j];
    println!(
        "best placement: x = {:.2} m, y = {:.2} m: |dp| = {:.3} mm at {:.2} deg about the tool \
         axis (worst angle there: {:.3} mm)",
        xs[i],
        ys[j],
        m * 1e3,
        angle.to_degrees(),
        worst * 1e3
    );
    Ok(())
}
