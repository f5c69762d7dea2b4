//! Example 6: D'Alembert correction of a serial arm in 6-D. The KR 300 of `robots/kr300`
//! carries a 150 kg spindle (centre of mass 0.25 m down the tool axis) through a pose motion of
//! 0.33 m and 0.3 rad at 0.5, 1 and 2 g; every 2 kHz tick the payload's inertial wrench goes
//! through the arm's virtual-joint stiffness to the joints at which the loaded arm reaches the
//! desired pose. Prints the largest correction per acceleration level.
//!
//! Run: `cargo run --release --example 06_serial_dalembert`
//! Your own arm: `cargo run --release --example 06_serial_dalembert -- URDF STIFFNESS TIP Q0`
//! with `Q0` the start joints, comma-separated (e.g. the UR5 of example-robot-data with
//! `robots/ur5/ur5_stiffness.toml`, tip `tool0`, `Q0 = 0.3,-1.2,1.5,-1.9,-1.57,0.4`).

use deflect_core::SerialRobot;
use deflect_core::dalembert::serial::{self, Payload};
use deflect_core::motion::{Limits, PoseLimits, PoseTrajectory};
use deflect_core::vjm::{self, Data};
use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let root = env!("CARGO_MANIFEST_DIR");
    let (robot, q0) = match args.as_slice() {
        [] => (
            SerialRobot::from_path(
                format!("{root}/robots/kr300/kr300_r2500.urdf"),
                format!("{root}/robots/kr300/kr300_r2500_stiffness.toml"),
                "tcp",
            )?,
            vec![0.0, -0.9, 1.4, 0.0, 1.0708, 0.0],
        ),
        [urdf, stiffness, tip, q0] => (
            SerialRobot::from_path(urdf, stiffness, tip)?,
            q0.split(',')
                .map(|v| v.trim().parse::<f64>())
                .collect::<Result<Vec<_>, _>>()?,
        ),
        _ => return Err("usage: 06_serial_dalembert [URDF STIFFNESS TIP Q0]".into()),
    };
    let payload = Payload {
        mass: 150.0,
        com: Vector3::new(0.0, 0.0, 0.25),
        inertia: Matrix3::from_diagonal(&Vector3::new(4.0, 4.0, 2.5)),
    };
    let model =
        serial::Model::new(robot.model.clone(), payload)?.with_joint_limits(&robot.joint_limits)?;
    let mut data = serial::Data::new(&model);

    // The motion: from the start pose, 0.1, 0.3, -0.1 m and 0.3 rad about the base z axis.
    let start = vjm::forward(&robot.model, &mut Data::new(&robot.model), &q0)?;
    let end = Isometry3::from_parts(
        Translation3::from(start.translation.vector + Vector3::new(0.1, 0.3, -0.1)),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.0, 0.3)) * start.rotation,
    );
    println!(
        "g    duration [ms]  ticks  max |dp| [mm]  max |dr| [mrad]  max |F| [N]  IK iterations (max)"
    );
    for g in [0.5, 1.0, 2.0] {
        let a = g * deflect_core::units::STANDARD_GRAVITY;
        let limits = PoseLimits {
            linear: Limits::new(2.0, a, 20.0 * a)?,
            angular: Limits::new(1.5, 0.8 * a, 10.0 * a)?,
        };
        let motion = PoseTrajectory::line(&start, &end, &limits)?;
        data.set_seed(&q0);
        let n = motion.tick_count(2000.0)?;
        let (mut dp, mut dr, mut f, mut iters) = (0.0f64, 0.0f64, 0.0f64, 0usize);
        for k in 0..n {
            let state = motion.sample(motion.tick_time(2000.0, k, n))?;
            let tick = serial::step(&model, &mut data, &state, None)?;
            let off = tick.commanded.translation.vector - tick.desired.translation.vector;
            dp = dp.max(off.norm());
            dr = dr.max(tick.commanded.rotation.angle_to(&tick.desired.rotation));
            f = f.max(tick.load.fixed_rows::<3>(0).norm());
            iters = iters.max(tick.iterations);
        }
        println!(
            "{g:<4} {:>13.1}  {n:>5}  {:>13.3}  {:>15.3}  {f:>11.0}  {iters:>19}",
            motion.duration() * 1e3,
            dp * 1e3,
            dr * 1e3,
        );
    }
    Ok(())
}
