//! The paper's validation on a program: a short groove cut by the flexible KR 300 six ways;
//! with nothing for the inertial feed-forward to count (a massless spindle, the link loads
//! off) the combined run is the hybrid one bit for bit.

use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_core::machining::job::{Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::mechanism::PoseIkOptions;
use deflect_core::units::LengthUnit;
use deflect_sim::scenes::milling::MillingArm;
use deflect_sim::scenes::milling::options::MillingOptions;
use deflect_sim::scenes::milling::program::{self, ProgramMode};
use nalgebra::{Vector2, Vector3};

#[test]
fn a_short_groove_six_ways() {
    let text = "G0 X-12 Y20 Z5\nS13000 M3\nG1 Z-6 F1500\nX40\nG0 Z5\n";
    let p = gcode::from_str(
        text,
        &GcodeOptions {
            start: Vector3::new(-12.0e-3, 20.0e-3, 5.0e-3),
            units: LengthUnit::Millimetre,
            ..GcodeOptions::default()
        },
    )
    .unwrap();
    let setup = Setup {
        placement: program::kr300_placement(),
        tool_orientation: Setup::tool_down(),
        tool: Tool::new(0.016, 3, 0.0).unwrap(),
        coefficients: Coefficients::AL7075_T6_CARBIDE,
        stock: Stock {
            min: Vector2::new(0.0, 0.0),
            max: Vector2::new(0.03, 0.04),
            top: 0.0,
            cell: 5e-4,
        },
        path: PathOptions::default(),
        ik: PoseIkOptions::default(),
        hand_spindle: None,
        rapid_skim: deflect_core::machining::job::RAPID_SKIM,
    };
    let opts = MillingOptions {
        spindle_mass: 0.0,
        link_inertia: false,
        ..MillingOptions::short()
    };
    // On a thread with a 16 MB stack: in a debug build the scenario's frames hold the 70 KB
    // arm and 35 KB models several times over, past a test thread's 2 MB (release frames are
    // a fraction of it; the command line's main thread has 8 MB).
    let r = std::thread::Builder::new()
        .stack_size(16 << 20)
        .spawn(move || {
            let arm = MillingArm::kr300()?;
            program::milling_program(&opts, &arm, &p, &setup, &program::PROGRAM_SEED)
        })
        .unwrap()
        .join()
        .unwrap()
        .unwrap();
    for run in &r.runs {
        println!(
            "{:<14} max {:.3} rms {:.3} entry {:.3} exit {:.3} mm; floors max {:.3} mm, walls left {:.1} mm2 over {:.1} mm2",
            run.mode.label(),
            run.metrics.max_mm,
            run.metrics.rms_mm,
            run.metrics.entry_max_mm,
            run.metrics.exit_max_mm,
            run.part_error.floor.max * 1e3,
            run.part_error.material_left * 1e6,
            run.part_error.overcut * 1e6
        );
    }
    println!("wall {:.1} s", r.wall_seconds);
    let by = |m: ProgramMode| r.runs.iter().find(|x| x.mode == m).unwrap();
    let (un, off, cart, hyb, axis) = (
        by(ProgramMode::Uncompensated),
        by(ProgramMode::Offline),
        by(ProgramMode::Cartesian),
        by(ProgramMode::Hybrid),
        by(ProgramMode::AxisSpecific),
    );
    // The paper's ordering (Fig. 10-12): uncompensated about a millimetre off at this cut's
    // 6 mm depth, Cartesian compensation about half of it at the cutter entry, pilot control
    // from the offline forces less again; every compensation keeps the walls within a few
    // cells and leaves less floor error.
    assert!(un.metrics.max_mm > 0.8, "{:?}", un.metrics);
    assert!(
        cart.metrics.max_mm < 0.7 * un.metrics.max_mm,
        "{:?}",
        cart.metrics
    );
    assert!(
        hyb.metrics.entry_max_mm < cart.metrics.entry_max_mm,
        "{:?}",
        hyb.metrics
    );
    // At the exit (the stock ends at x = 30 mm, the groove at 40 mm) the force falls away:
    // the Cartesian loop, lagging, keeps part of its correction; pilot control lets it go
    // with the offline force.
    assert_eq!(r.cuts.len(), 1, "{:?}", r.cuts);
    assert!(
        hyb.metrics.exit_max_mm < cart.metrics.exit_max_mm
            && cart.metrics.exit_max_mm < un.metrics.exit_max_mm,
        "{:?} {:?} {:?}",
        un.metrics,
        cart.metrics,
        hyb.metrics
    );
    assert!(hyb.metrics.rms_mm < cart.metrics.rms_mm);
    assert!(axis.metrics.max_mm < cart.metrics.max_mm);
    assert!(
        off.metrics.max_mm < hyb.metrics.max_mm && off.metrics.rms_mm < 0.1 * un.metrics.rms_mm
    );
    let combined = by(ProgramMode::Combined);
    assert_eq!(combined.samples.len(), hyb.samples.len());
    for (c, h) in combined.samples.iter().zip(&hyb.samples) {
        assert_eq!(c.actual, h.actual, "t = {}", c.t);
        assert_eq!(c.force, h.force, "t = {}", c.t);
    }
    assert_eq!(combined.part_error.floor.max, hyb.part_error.floor.max);
    assert!(
        r.lines.is_empty(),
        "no inertial pass when it counts nothing"
    );
    for run in [off, cart, hyb, axis] {
        assert!(run.part_error.floor.max < un.part_error.floor.max);
        assert!(
            run.part_error.material_left + run.part_error.overcut
                < 0.25 * (un.part_error.material_left + un.part_error.overcut)
        );
    }
}
