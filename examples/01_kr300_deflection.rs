//! Example 1: deflection of the KR 300 R2500 milling robot of the VJM paper under the paper's
//! validation loads (750 N along base x, y, -z) and a 546 N milling load.
//!
//! Run: `cargo run --release --example 01_kr300_deflection [-- URDF TOML TIP q1..q6]`
//! (built-in defaults: the shipped KR 300 model in a milling pose).

use deflect_core::SerialRobot;
use deflect_core::vjm::{self, Data, Vector6};

/// A milling pose [rad]: flange pointing down, TCP 1.80 m in front of A1 and 0.48 m above the
/// base, tool axis horizontal.
const MILLING_POSE: [f64; 6] = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];
/// A 546 N milling force (the paper's largest) in the horizontal plane, base frame [N, N m].
const MILLING_WRENCH: [f64; 6] = [-386.1, 386.1, 0.0, 0.0, 0.0, 0.0];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = env!("CARGO_MANIFEST_DIR");
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (urdf, toml, tip) = match args.as_slice() {
        [u, t, tip, ..] => (u.clone(), t.clone(), tip.clone()),
        _ => (
            format!("{root}/robots/kr300/kr300_r2500.urdf"),
            format!("{root}/robots/kr300/kr300_r2500_stiffness.toml"),
            "tcp".to_string(),
        ),
    };
    let robot = SerialRobot::from_path(&urdf, &toml, &tip)?;
    let q: Vec<f64> = if args.len() > 3 {
        args[3..]
            .iter()
            .map(|s| s.parse())
            .collect::<Result<_, _>>()?
    } else {
        MILLING_POSE.to_vec()
    };
    let model = &robot.model;
    let mut data = Data::new(model);
    let tcp = vjm::forward(model, &mut data, &q)?;
    println!(
        "{} joints, {} virtual joints; q = {:?} rad",
        model.dof(),
        model.spring_count(),
        q
    );
    let p = tcp.translation.vector * 1e3;
    println!("rigid TCP [mm]: x {:.1}  y {:.1}  z {:.1}", p.x, p.y, p.z);
    println!();
    println!("load                  |  dx [mm]  dy [mm]  dz [mm] | |dp| [mm] | |dr| [mrad]");
    let loads: [(&str, [f64; 6]); 4] = [
        ("750 N along +x", [750.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        ("750 N along +y", [0.0, 750.0, 0.0, 0.0, 0.0, 0.0]),
        ("750 N along -z", [0.0, 0.0, -750.0, 0.0, 0.0, 0.0]),
        ("546 N milling (xy)", MILLING_WRENCH),
    ];
    for (name, w) in loads {
        let d = vjm::deflection(
            model,
            &mut data,
            &q,
            &Vector6::from_row_slice(&w),
            vjm::Load::Exact,
        )?;
        let dp = d.fixed_rows::<3>(0) * 1e3;
        let dr = d.fixed_rows::<3>(3) * 1e3;
        println!(
            "{name:<21} | {:8.3} {:8.3} {:8.3} | {:9.3} | {:10.3}",
            dp.x,
            dp.y,
            dp.z,
            dp.norm(),
            dr.norm()
        );
    }
    println!();
    println!("Paper (Haehn & Weigold): up to 1.4 mm at 546 N while milling; its validation");
    println!("loads of 750 N were matched to 6 % on average (0.11 mm), at most 0.44 mm off.");
    Ok(())
}
