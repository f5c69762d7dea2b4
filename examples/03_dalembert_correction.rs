//! Example 3: the paper's 2 kHz D'Alembert trajectory correction of the 2-DoF parallel robot:
//! the 150 mm y-line at 1..5 g, planned jerk-limited, F_D = -m* a with m* = 5 kg, the OC
//! compliance map, closed-form IK. Prints the largest correction per acceleration level.
//!
//! Run: `cargo run --release --example 03_dalembert_correction`

use deflect_core::Placement;
use deflect_core::compliance_map::{OutOfGrid, QueryOptions};
use deflect_core::dalembert::parallel::{self, Data, Model};
use deflect_core::io::map_csv;
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::motion::{Trajectory, paper_limits};
use deflect_core::units::{ForceUnit, LengthUnit};
use nalgebra::Vector2;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/paksoy2025_compliance_oc.csv"
    );
    let map = map_csv::from_path(path, ForceUnit::Newton, LengthUnit::Millimetre)?.with_options(
        QueryOptions {
            out_of_grid: OutOfGrid::Clamp,
            ..QueryOptions::default()
        },
    );
    let corrector = Model::new(ParallelRobot2::paper(), map, parallel::PAPER_MASS)?
        .with_fixed_point(3, 1e-12)?;
    let mut data = Data::new(&corrector);
    println!("g   duration [ms]  ticks  max |correction| [mm]  max |F_D| [N]  clamped ticks");
    for g in 1..=5u8 {
        let traj = Trajectory::line(
            Vector2::new(0.222132, -0.075),
            Vector2::new(0.222132, 0.075),
            &paper_limits(g)?,
        )?;
        let (mut max_c, mut max_f, mut clamped) = (0.0f64, 0.0f64, 0);
        let ticks = parallel::correct_each(&corrector, &mut data, &traj, 2000.0, |_, t| {
            max_c = max_c.max((t.commanded - t.desired).norm());
            max_f = max_f.max(t.load.norm());
            if t.diagnostics.placement != Placement::Inside {
                clamped += 1;
            }
        })?;
        println!(
            "{g}   {:>13.1}  {ticks:>5}  {:>21.4}  {max_f:>13.1}  {clamped:>13}",
            traj.duration() * 1e3,
            max_c * 1e3
        );
    }
    Ok(())
}
