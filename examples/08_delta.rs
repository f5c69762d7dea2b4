//! Example 8: the D'Alembert correction on a Delta robot with a 3-D compliance map. The map is
//! fitted from static tests on a 3 x 3 x 3 grid over the workspace (here read off a model
//! whose drives give the platform J K^-1 J^T; on a real robot, measured), then each 2 kHz
//! tick of a 0.3 m move at 8 g gets the commanded platform point and joints.
//!
//! Run: `cargo run --release --example 08_delta` (Python twin: `examples/08_delta.py`).

use deflect_core::compliance_map::{FitOptions, GridMeasurement, fit_grid};
use deflect_core::dalembert::parallel::{self, Data, Model};
use deflect_core::mechanism::{Delta, Mechanism};
use deflect_core::motion::{Limits, PoseLimits, PoseTrajectory};
use nalgebra::{Isometry3, Matrix3, Vector3};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let delta = Delta::pick_and_place();
    let k = 2.0e4; // drive stiffness [N m/rad]
    // Static tests: +-50 N along x, y, z at every node; the platform's displacement.
    let mut readings = Vec::new();
    for x in [-0.2, 0.0, 0.2] {
        for y in [-0.1, 0.0, 0.1] {
            for z in [-0.85, -0.775, -0.7] {
                let p = Vector3::new(x, y, z);
                let j = delta.jacobian(&mut (), &delta.ik(&p)?)?;
                let c = j * Matrix3::identity() / k * j.transpose();
                for axis in 0..3 {
                    for f in [-50.0, 50.0] {
                        let mut force = Vector3::zeros();
                        force[axis] = f;
                        let d = c * force;
                        readings.push(GridMeasurement::new(&[x, y, z], axis, f, d.as_slice()));
                    }
                }
            }
        }
    }
    let names = ["x", "y", "z"].map(String::from).to_vec();
    let options = FitOptions {
        n_force: 3,
        n_displacement: 3,
        position_tolerance: 1e-9,
    };
    let map = fit_grid(names, &readings, &options)?;
    println!(
        "map: {} nodes over x, y, z from {} static tests",
        map.node_count(),
        readings.len()
    );
    // The corrector: m* = platform, payload and the forearms' share [kg].
    let model = Model::new(delta, map, 1.775)?;
    let mut data = Data::new(&model);
    let g = 8.0 * 9.81;
    let limits = PoseLimits {
        linear: Limits::new(4.0, g, g / 0.02)?,
        angular: Limits::new(1.0, 1.0, 10.0)?,
    };
    let (a, b) = (
        Isometry3::translation(-0.15, -0.05, -0.8),
        Isometry3::translation(0.15, 0.05, -0.75),
    );
    let motion = PoseTrajectory::line(&a, &b, &limits)?;
    let n = motion.tick_count(2000.0)?;
    let (mut worst, mut force) = (0.0f64, 0.0f64);
    for i in 0..n {
        let s = motion.sample(motion.tick_time(2000.0, i, n))?;
        let tick = parallel::step(
            &model,
            &mut data,
            &s.pose.translation.vector,
            &s.acceleration,
        )?;
        worst = worst.max(tick.displacement.norm());
        force = force.max(tick.load.norm());
    }
    println!(
        "0.3 m move at 8 g: {n} ticks of 0.5 ms, D'Alembert force up to {force:.0} N, \
         predicted displacement up to {:.3} mm, pre-compensated every tick",
        worst * 1e3
    );
    Ok(())
}
