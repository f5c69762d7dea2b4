//! Example 7: a machining job offline. The KR 300 of `robots/kr300` mills the groove, ramp and
//! circular pocket of `data/groove_and_pocket.nc` in aluminium with a 16 mm three-flute end
//! mill (the tool of Hähn and Weigold) at 13,000 rpm and 25 mm/s: the program is driven at
//! its feeds and sampled every 4 ms, the stock is cut along it, the engagement at each sample
//! gives the milling force, the arm's virtual-joint model its deflection, and the loaded pose
//! IK the compensated joints. Prints the force per program line and the predicted path and
//! part errors with and without compensation; writes the compensated program and every
//! sample to `target/machining/`.
//!
//! Run: `cargo run --release --example 07_machining_job`
//! Your program: `cargo run --release --example 07_machining_job -- PROGRAM.nc` (mm, in the
//! workpiece frame: x 5..85 mm, y -15..45 mm, top at z = 0).

use deflect_core::SerialRobot;
use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::io::job_out;
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_core::machining::job::{self, Job, Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::mechanism::PoseIkOptions;
use deflect_core::units::LengthUnit;
use nalgebra::{Isometry3, Vector2, Vector3};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = env!("CARGO_MANIFEST_DIR");
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| format!("{root}/data/groove_and_pocket.nc"));
    let robot = SerialRobot::from_path(
        format!("{root}/robots/kr300/kr300_r2500.urdf"),
        format!("{root}/robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    )?;
    let program = gcode::from_path(
        std::path::Path::new(&path),
        &GcodeOptions {
            start: Vector3::new(0.0, 0.0, 0.02),
            units: LengthUnit::Millimetre,
            ..GcodeOptions::default()
        },
    )?;
    // The workpiece on a table in front of the robot: its origin at (2.45, 0.02, 0.92) m in
    // the base frame, z up, x towards the robot (turned by pi about z); the tool points down.
    let setup = Setup {
        placement: Isometry3::new(
            Vector3::new(2.45, 0.02, 0.92),
            Vector3::new(0.0, 0.0, std::f64::consts::PI),
        ),
        tool_orientation: Setup::tool_down(),
        tool: Tool::new(0.016, 3, 0.0)?,
        coefficients: Coefficients::AL7075_T6_CARBIDE,
        stock: Stock {
            min: Vector2::new(0.005, -0.015),
            max: Vector2::new(0.085, 0.045),
            top: 0.0,
            cell: 5.0e-4,
        },
        path: PathOptions::default(),
        ik: PoseIkOptions::default(),
        hand_spindle: None,
        rapid_skim: job::RAPID_SKIM,
    };
    let job = Job::new(robot.model.clone(), &robot.joint_limits, setup)?;
    // Joints near the first pose (the tool down over the table): they choose the IK branch.
    let seed = [0.0, -0.9, 1.4, 0.0, -0.5, 0.0];
    let started = std::time::Instant::now();
    let report = job::run(&job, &program, &seed)?;
    let wall = started.elapsed().as_secs_f64();
    let last = report.samples.last().map_or(0.0, |s| s.path.time);
    println!(
        "{} samples over {last:.2} s of program in {:.0} ms ({} plunge samples without side force)",
        report.samples.len(),
        wall * 1e3,
        report.plunge_samples
    );
    println!("line  samples  mean |F| [N]  max |F| [N]");
    for l in report.line_forces().iter().filter(|l| l.max > 0.0) {
        println!(
            "{:>4}  {:>7}  {:>12.1}  {:>11.1}",
            l.line,
            l.samples,
            l.mean.norm(),
            l.max
        );
    }
    let mm = |e: job::ErrorStats| format!("max {:.3} mm, RMS {:.3} mm", e.max * 1e3, e.rms * 1e3);
    println!(
        "path error uncompensated:  {}",
        mm(report.path_error(false))
    );
    println!("path error compensated:    {}", mm(report.path_error(true)));
    for (label, part) in [
        ("uncompensated", &report.uncompensated),
        ("compensated", &report.compensated),
    ] {
        let e = report.surface_error(part);
        println!(
            "part floors {label:<13}: {}; walls: {:.0} mm^2 left, {:.0} mm^2 overcut",
            mm(e.floor),
            e.material_left * 1e6,
            e.overcut * 1e6
        );
    }
    let out = std::path::Path::new(root).join("target/machining");
    std::fs::create_dir_all(&out)?;
    job_out::write(
        out.join("compensated.nc"),
        &job_out::compensated_gcode(&report, &program, 1e-6),
    )?;
    job_out::write(
        out.join("samples.csv"),
        &job_out::samples_csv(&report, 0.04),
    )?;
    println!("wrote {}/compensated.nc and samples.csv", out.display());
    Ok(())
}
