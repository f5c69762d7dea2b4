//! The D'Alembert trajectory corrector (Paksoy et al., sec. 3.3, Eq. 5, 9-14).

use approx::assert_relative_eq;
use deflect_core::compliance_map::{ComplianceMap, OutOfGrid, QueryOptions};
use deflect_core::dalembert::parallel::{self, Data, Model};
use deflect_core::io::map_csv;
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::motion::{Trajectory, paper_limits};
use deflect_core::units::{ForceUnit, LengthUnit};
use deflect_core::{Placement, TickError};
use nalgebra::Vector2;

/// The paper's 3 x 5 grid [m] with the same slopes at every node.
fn constant_map(c: [[f64; 2]; 2], offsets: [f64; 2]) -> ComplianceMap {
    let x: Vec<f64> = (1..=3).map(|i| 0.122132 + 0.05 * i as f64).collect();
    let y: Vec<f64> = (1..=5).map(|j| -0.1125 + 0.0375 * j as f64).collect();
    let mut slopes = Vec::new();
    let mut offs = Vec::new();
    for _ in 0..15 {
        for (row, off) in c.iter().zip(offsets) {
            for &cdf in row {
                slopes.push(cdf);
                // Split the offset between the two force axes, as the paper does.
                offs.push(off / 2.0);
            }
        }
    }
    ComplianceMap::new(x, y, 2, 2, slopes, offs).unwrap()
}

fn paper_map(file: &str) -> ComplianceMap {
    let text = std::fs::read_to_string(format!("{}/../../data/{file}", env!("CARGO_MANIFEST_DIR")))
        .unwrap();
    map_csv::from_str(&text, ForceUnit::Newton, LengthUnit::Millimetre).unwrap()
}

fn x_line(g: u8) -> Trajectory<2> {
    Trajectory::line(
        Vector2::new(0.172132, 0.0),
        Vector2::new(0.272132, 0.0),
        &paper_limits(g).unwrap(),
    )
    .unwrap()
}

#[test]
fn zero_map_leaves_the_path_unchanged() {
    let map = constant_map([[0.0; 2]; 2], [0.0; 2]);
    let robot = ParallelRobot2::paper();
    let corr = Model::new(robot, map.view(), 5.0)
        .unwrap()
        .with_fixed_point(3, 0.0)
        .unwrap();
    let mut data = Data::new(&corr);
    data.set_seed(Vector2::zeros());
    let traj = x_line(5);
    let mut n = 0;
    parallel::correct_each(&corr, &mut data, &traj, 2000.0, |_, t| {
        assert_eq!(t.commanded, t.desired);
        assert_eq!(t.joints, robot.ik(&t.desired).unwrap());
        n += 1;
    })
    .unwrap();
    assert_eq!(n, (traj.duration() * 2000.0).ceil() as usize + 1);
}

#[test]
fn constant_map_gives_exactly_c_m_a() {
    let c = [[2.0e-6, -0.5e-6], [0.3e-6, 4.0e-6]]; // m/N
    let map = constant_map(c, [0.0; 2]);
    let robot = ParallelRobot2::paper();
    let corr = Model::new(robot, map.view(), 5.0).unwrap();
    let mut data = Data::new(&corr);
    let a = Vector2::new(3.0 * 9.81, -2.0 * 9.81);
    let x = Vector2::new(0.2, 0.01);
    data.set_seed(Vector2::zeros());
    let t = parallel::step(&corr, &mut data, &x, &a).unwrap();
    // F_D = -m* a; displacement C F_D; command x - C F_D = x + C m* a.
    assert_eq!(t.load, Vector2::new(-5.0 * 3.0 * 9.81, 5.0 * 2.0 * 9.81));
    let cma = Vector2::new(
        c[0][0] * 5.0 * a.x + c[0][1] * 5.0 * a.y,
        c[1][0] * 5.0 * a.x + c[1][1] * 5.0 * a.y,
    );
    assert_relative_eq!(t.commanded, x + cma, epsilon = 1e-17);
    assert_eq!(t.iterations, 0);
    // A constant map has a constant displacement: one fixed-point iteration changes nothing.
    let corr2 = Model::new(robot, map.view(), 5.0)
        .unwrap()
        .with_fixed_point(5, 1e-15)
        .unwrap();
    let mut data2 = Data::new(&corr2);
    data2.set_seed(Vector2::zeros());
    let t2 = parallel::step(&corr2, &mut data2, &x, &a).unwrap();
    assert_eq!(t2.iterations, 1);
    assert_relative_eq!(t2.commanded, t.commanded, epsilon = 1e-18);
}

#[test]
fn fixed_point_reproduces_the_desired_path() {
    // With the map's own prediction applied at the command, command + d(command) = desired.
    let map = paper_map("paksoy2025_compliance_oc.csv");
    let view = map.view();
    let robot = ParallelRobot2::paper();
    let corr = Model::new(robot, view, parallel::PAPER_MASS)
        .unwrap()
        .with_fixed_point(20, 1e-13)
        .unwrap();
    let mut data = Data::new(&corr);
    data.set_seed(Vector2::zeros());
    let traj = Trajectory::polyline(
        &[
            Vector2::new(0.19, -0.05),
            Vector2::new(0.25, 0.0),
            Vector2::new(0.19, 0.05),
            Vector2::new(0.19, -0.05),
        ],
        &paper_limits(5).unwrap(),
    )
    .unwrap();
    let mut worst: f64 = 0.0;
    let mut largest_correction: f64 = 0.0;
    parallel::correct_each(&corr, &mut data, &traj, 2000.0, |_, t| {
        let mut d = [0.0; 2];
        view.displacement_with(
            [t.commanded.x, t.commanded.y],
            t.load.as_slice(),
            &mut d,
            QueryOptions::default(),
        )
        .unwrap();
        let reached = t.commanded + Vector2::new(d[0], d[1]);
        worst = worst.max((reached - t.desired).norm());
        largest_correction = largest_correction.max((t.commanded - t.desired).norm());
        assert_eq!(t.diagnostics.placement, Placement::Inside);
        assert_relative_eq!(robot.fk(&t.joints).unwrap(), t.commanded, epsilon = 1e-14);
    })
    .unwrap();
    assert!(worst < 1e-12, "fixed-point error {worst}");
    // The paper's loads at 5 g give sub-millimetre corrections on the OC robot.
    assert!(
        largest_correction > 1e-5 && largest_correction < 2e-3,
        "{largest_correction}"
    );
}

#[test]
fn streaming_and_offline_agree_exactly() {
    let map = paper_map("paksoy2025_compliance_nc.csv");
    let robot = ParallelRobot2::paper();
    let traj = x_line(3);
    // The paper's x line spans the grid edge to edge: the corrected command leaves it by a
    // few micrometres at the ends, so clamp there (and see it flagged).
    let view = map.view().with_options(QueryOptions {
        out_of_grid: OutOfGrid::Clamp,
        ..QueryOptions::default()
    });
    let corr = Model::new(robot, view, 5.0)
        .unwrap()
        .with_fixed_point(2, 0.0)
        .unwrap();
    let mut data = Data::new(&corr);
    data.set_seed(Vector2::zeros());
    let offline = parallel::correct(&corr, &mut data, &traj, 2000.0).unwrap();
    assert!(
        offline
            .iter()
            .any(|t| t.diagnostics.placement == Placement::Clamped)
    );
    let mut q = Vector2::zeros();
    let mut cursor = traj.ticks(2000.0).unwrap();
    let mut i = 0;
    while let Some(s) = cursor.step() {
        data.set_seed(q);
        let t = parallel::step(&corr, &mut data, &s.position, &s.acceleration).unwrap();
        assert_eq!(t, offline[i]);
        q = t.joints;
        i += 1;
    }
    assert_eq!(i, offline.len());
}

#[test]
fn out_of_map_points_are_statuses_not_panics() {
    let map = paper_map("paksoy2025_compliance_oc.csv");
    let robot = ParallelRobot2::paper();
    let corr = Model::new(robot, map.view(), 5.0).unwrap();
    let mut data = Data::new(&corr);
    let outside = Vector2::new(0.15, 0.0); // x below the grid's 0.172 m
    let a = Vector2::new(9.81, 0.0);
    data.set_seed(Vector2::zeros());
    let e = parallel::step(&corr, &mut data, &outside, &a).unwrap_err();
    // The map refuses the point (its default is to refuse out-of-grid queries).
    assert!(matches!(e, TickError::OutOfGrid { .. }), "{e:?}");
    let clamp = map.view().with_options(QueryOptions {
        out_of_grid: OutOfGrid::Clamp,
        ..QueryOptions::default()
    });
    let corr_clamp = Model::new(robot, clamp, 5.0).unwrap();
    let mut data = Data::new(&corr_clamp);
    data.set_seed(Vector2::zeros());
    let t = parallel::step(&corr_clamp, &mut data, &outside, &a).unwrap();
    assert_eq!(t.diagnostics.placement, Placement::Clamped);
    // Out of the robot's reach (2 L = 0.3 m): a mechanism error.
    let far = Model::new(robot, clamp, 5.0).unwrap();
    let mut data = Data::new(&far);
    data.set_seed(Vector2::zeros());
    let e = parallel::step(&far, &mut data, &Vector2::new(0.35, 0.0), &a).unwrap_err();
    assert!(matches!(e, TickError::OutOfWorkspace { .. }), "{e:?}");
    let mut data = Data::new(&corr_clamp);
    data.set_seed(Vector2::zeros());
    let e = parallel::step(&corr_clamp, &mut data, &Vector2::new(f64::NAN, 0.0), &a).unwrap_err();
    assert_eq!(
        e,
        TickError::NonFinite {
            what: "position",
            index: 0
        }
    );
    assert!(Model::new(robot, map.view(), -1.0).is_err());
    assert!(Model::new(robot, map.view(), f64::NAN).is_err());
}
