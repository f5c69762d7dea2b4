//! 1e4 consecutive 2 kHz ticks of planner + compliance map + corrector + IK allocate nothing:
//! a counting global allocator watches them. One test function only.

use deflect_core::compliance_map::{OutOfGrid, QueryOptions};
use deflect_core::dalembert::parallel::{self, Data, Model};
use deflect_core::io::map_csv;
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::motion::{Trajectory, paper_limits};
use deflect_core::units::{ForceUnit, LengthUnit};
use nalgebra::Vector2;

mod common;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

#[test]
fn corrector_ticks_do_not_allocate() {
    common::watch_this_thread();
    common::assert_counter_works();
    let text = std::fs::read_to_string(format!(
        "{}/../../data/paksoy2025_compliance_oc.csv",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let map = map_csv::from_str(&text, ForceUnit::Newton, LengthUnit::Millimetre)
        .unwrap()
        .with_options(QueryOptions {
            out_of_grid: OutOfGrid::Clamp,
            ..QueryOptions::default()
        });
    let robot = ParallelRobot2::paper();
    // y line of the paper, 150 mm at 5 g, back and forth until 1e4 ticks have run.
    let up = Trajectory::line(
        Vector2::new(0.222132, -0.075),
        Vector2::new(0.222132, 0.075),
        &paper_limits(5).unwrap(),
    )
    .unwrap();
    let view = map.view();
    let corr = Model::new(robot, view, 5.0)
        .unwrap()
        .with_fixed_point(3, 1e-12)
        .unwrap();
    let mut data = Data::new(&corr);
    let mut q = Vector2::zeros();
    let mut ticks = 0usize;
    let mut sink = 0.0;

    let before = common::allocations();
    while ticks < 10_000 {
        let mut cursor = up.ticks(2000.0).unwrap();
        while let Some(s) = cursor.step() {
            data.set_seed(q);
            let t = parallel::step(&corr, &mut data, &s.position, &s.acceleration).unwrap();
            q = t.joints;
            sink += t.commanded.x;
            ticks += 1;
        }
    }
    let after = common::allocations();
    assert!(sink.is_finite());
    assert_eq!(after - before, 0, "allocations in {ticks} corrector ticks");
}
