//! Regression tests of the adversarial pass (issue "no input may kill, hang or silently
//! corrupt a process"): each test is named for the defect it guards and replays its
//! reproducer through deflect-core, the depth at which it is fixed.

use deflect_core::compliance_map::{ComplianceMap, OutOfGrid, QueryOptions};
use deflect_core::contour::{self, TracerConfig};
use deflect_core::dalembert::parallel::{self, PAPER_MASS};
use deflect_core::identification::{
    self, LeastSquaresAccumulator, MAX_MEASUREMENTS, TcpMeasurement,
};
use deflect_core::io::{drive, map_csv, stiffness, urdf};
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::motion::{Limits, MAX_SAMPLES, Trajectory};
use deflect_core::units::{ForceUnit, LengthUnit};
use deflect_core::vjm::{self, Data, ModelBuilder, Vector6};
use deflect_core::{BuildError, LoadError, SerialRobot, TickError};
use nalgebra::{Isometry3, Matrix2, Matrix3, Matrix4, Vector2, Vector3};

const ARM_URDF: &str = r#"<robot name="arm">
  <link name="base"/><link name="l1"/><link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="100" velocity="1"/></joint>
  <joint name="j2" type="fixed"><parent link="l1"/><child link="tip"/>
    <origin xyz="0.8 0 0"/></joint>
</robot>"#;
const ARM_TOML: &str = "[[virtual_joint]]\nlink = \"l1\"\nk = [1e6, 1e6, 2e5]\n";

fn y_line(v_max: f64) -> Trajectory<2> {
    let lim = Limits::new(v_max, 49.05, 5207.0).unwrap();
    Trajectory::line(Vector2::new(0.2, -0.075), Vector2::new(0.2, 0.075), &lim).unwrap()
}

#[test]
fn sampling_has_a_budget_instead_of_an_abort() {
    // Reproducer 1 and 5: tiny v_max, huge rates. A cursor is free, storing every tick is not.
    let slow = y_line(1e-6);
    assert!(slow.ticks(2000.0).is_ok());
    assert!(matches!(
        slow.sample_count(2000.0),
        Err(TickError::Budget { what: "samples", limit, .. }) if limit == MAX_SAMPLES as f64
    ));
    let normal = y_line(0.42);
    assert!(matches!(
        normal.sample_count(1e9),
        Err(TickError::Budget {
            what: "samples",
            ..
        })
    ));
    assert!(matches!(
        normal.ticks(1e300),
        Err(TickError::Budget { what: "ticks", .. })
    ));
    // 0.15 m at 1 um/s: 1.5e5 s, within MAX_DURATION; at 100 MHz past MAX_TICKS.
    assert!(matches!(
        y_line(1e-6).ticks(1e8),
        Err(TickError::Budget { what: "ticks", .. })
    ));
    // A call that stores every tick names one budget however far past it the request is
    // (not MAX_TICKS for the farthest), with whole numbers.
    let far = y_line(1e-6).sample_count(1e8).unwrap_err();
    assert!(matches!(
        far,
        TickError::Budget {
            what: "samples",
            budget: "MAX_SAMPLES",
            ..
        }
    ));
    assert!(
        far.to_string()
            .ends_with("samples requested; the limit is MAX_SAMPLES = 4194304 samples"),
        "{far}"
    );
    let ticks = (normal.duration() * 1e9 - 1e-9).ceil() as u64 + 1;
    assert_eq!(
        normal.sample_count(1e9).unwrap_err().to_string(),
        format!("{ticks} samples requested; the limit is MAX_SAMPLES = 4194304 samples")
    );
    // A sub-normal limit would give an infinite (or wrongly zero) duration: refused.
    assert!(matches!(
        Limits::new(5e-324, 49.05, 5207.0),
        Err(BuildError::InvalidParameter { what: "v_max", .. })
    ));
    let raw = Limits {
        v_max: 0.4,
        a_max: 5e-324,
        j_max: 5207.0,
    };
    assert!(Trajectory::line(Vector2::new(0.0, 0.0), Vector2::new(0.1, 0.0), &raw).is_err());
    // Whole-trajectory correction stores every tick: same budget.
    let map = ComplianceMap::new(
        vec![0.1, 0.3],
        vec![-0.1, 0.1],
        2,
        2,
        vec![1e-6; 16],
        vec![0.0; 16],
    )
    .unwrap();
    let model = parallel::Model::new(ParallelRobot2::paper(), map, PAPER_MASS).unwrap();
    let mut data = parallel::Data::new(&model);
    assert!(matches!(
        parallel::correct(&model, &mut data, &slow, 2000.0),
        Err(TickError::Budget { .. })
    ));
    assert_eq!(
        normal.sample_count(2000.0).unwrap(),
        normal.ticks(2000.0).unwrap().count()
    );
}

#[test]
fn deeply_nested_urdf_is_refused_before_the_recursive_parser() {
    // Reproducer 2: 15 000 nested elements overflowed urdf-rs's stack (SIGSEGV).
    let deep = format!(
        "<robot name=\"r\">{}{}</robot>",
        "<a>".repeat(15_000),
        "</a>".repeat(15_000)
    );
    assert!(matches!(
        urdf::from_str(&deep, ARM_TOML, None, "tip"),
        Err(LoadError::TooLarge {
            limit: urdf::MAX_XML_DEPTH,
            ..
        })
    ));
    // Item 9: a root that is not <robot>, or two roots.
    let not_robot =
        ARM_URDF
            .replacen("<robot", "<machine", 1)
            .replacen("</robot>", "</machine>", 1);
    let err = urdf::from_str(&not_robot, ARM_TOML, None, "tip").unwrap_err();
    assert!(err.to_string().contains("expected <robot>"), "{err}");
    let two = format!("{ARM_URDF}\n<robot name=\"b\"/>");
    let err = urdf::from_str(&two, ARM_TOML, None, "tip").unwrap_err();
    assert!(err.to_string().contains("more than one root"), "{err}");
    // Comments, declarations and '>' inside attribute values are not elements.
    let decorated = format!(
        "<?xml version=\"1.0\"?>\n<!-- a <comment> -->\n{}",
        ARM_URDF.replacen("name=\"arm\"", "name=\"a>b\"", 1)
    );
    assert!(urdf::from_str(&decorated, ARM_TOML, None, "tip").is_ok());
}

#[test]
fn pose_from_matrix_checks_instead_of_projecting() {
    // Reproducer 3: diag(1e200, 1, 1, 1) hung nalgebra's iterative projection; an all-zero
    // matrix became the identity; a reflection passed as a rotation.
    let mut huge = Matrix4::identity();
    huge[(0, 0)] = 1e200;
    assert!(matches!(
        vjm::pose_from_matrix(&huge),
        Err(TickError::InvalidArgument { .. })
    ));
    assert!(matches!(
        vjm::pose_from_matrix(&Matrix4::zeros()),
        Err(TickError::InvalidArgument { .. })
    ));
    let mut reflection = Matrix4::identity();
    reflection[(2, 2)] = -1.0;
    assert!(matches!(
        vjm::pose_from_matrix(&reflection),
        Err(TickError::InvalidArgument { value, .. }) if value < 0.0
    ));
    let mut nan_bottom = Matrix4::identity();
    nan_bottom[(3, 1)] = f64::NAN;
    assert_eq!(
        vjm::pose_from_matrix(&nan_bottom),
        Err(TickError::NonFinite {
            what: "pose",
            index: 7
        })
    );
    let mut bottom = Matrix4::identity();
    bottom[(3, 0)] = 0.5;
    assert!(vjm::pose_from_matrix(&bottom).is_err());
    // A proper transform round-trips exactly enough.
    let t = Isometry3::new(Vector3::new(0.1, -0.2, 0.3), Vector3::new(0.3, -1.2, 2.0));
    let back = vjm::pose_from_matrix(&t.to_homogeneous()).unwrap();
    assert!((back.translation.vector - t.translation.vector).norm() < 1e-15);
    assert!(back.rotation.angle_to(&t.rotation) < 1e-14);
    assert!(vjm::rotation_from_matrix(&Matrix3::from_diagonal_element(2.0)).is_err());
}

#[test]
fn overflowing_outputs_are_a_status_not_nan() {
    // Reproducer 7: a wrench of +-1e308 returned OK and NaN (or, on a short arm, finite
    // garbage from elastic angles of 1e302 rad). Loads that turn a spring past
    // MAX_SPRING_ANGLE are outside the small-deflection model and refused.
    let robot = SerialRobot::from_str(ARM_URDF, ARM_TOML, None, "tip").unwrap();
    let mut data = Data::new(&robot.model);
    for w in [
        Vector6::new(1e308, -1e308, 1e308, 0.0, 0.0, 0.0),
        Vector6::new(0.0, 0.0, 0.0, 1e308, -1e308, 1e308),
        Vector6::new(0.0, 2e5, 0.0, 0.0, 0.0, 0.0),
    ] {
        assert!(matches!(
            vjm::deflection(&robot.model, &mut data, &[0.3], &w, vjm::Load::Exact),
            Err(TickError::InvalidArgument { value, .. }) if value > vjm::MAX_SPRING_ANGLE
        ));
        assert!(vjm::joint_correction(&robot.model, &mut data, &[0.3], &w, 3, 1e-9).is_err());
    }
    // A realistic load is fine.
    let ok = Vector6::new(0.0, 500.0, 0.0, 0.0, 0.0, 0.0);
    assert!(vjm::deflection(&robot.model, &mut data, &[0.3], &ok, vjm::Load::Exact).is_ok());
    // An extrapolating map queried at 1e300 m returned [nan, nan].
    let map = ComplianceMap::new(
        vec![0.0, 0.1],
        vec![0.0, 0.1],
        2,
        2,
        vec![1e-6; 16],
        vec![1e-4; 16],
    )
    .unwrap()
    .with_options(QueryOptions {
        out_of_grid: OutOfGrid::Extrapolate,
        ..QueryOptions::default()
    });
    let mut out = [0.0; 2];
    let far = map.displacement([1e300, -1e300], &[1e300, 1e300], &mut out);
    assert!(
        matches!(far, Err(TickError::NonFiniteOutput { .. })),
        "{far:?}"
    );
    // The batch kernel checks too (slopes of 10 m/N times 1e308 N overflow).
    let steep = ComplianceMap::new(
        vec![0.0, 0.1],
        vec![0.0, 0.1],
        2,
        2,
        vec![10.0; 16],
        vec![0.0; 16],
    )
    .unwrap();
    let mut batch = [0.0; 4];
    let r = steep.displacement_batch(
        &[0.05, 0.05, 0.05, 0.05],
        2,
        &[1.0, 1.0, 1e308, 1e308],
        &mut batch,
        steep.options(),
    );
    assert!(
        matches!(r, Err(e) if e.row == 1 && matches!(e.error, TickError::NonFiniteOutput { .. }))
    );
}

#[test]
fn loaders_refuse_absurd_origins_and_subnormal_stiffness() {
    // Reproducer 7: origins of 1e308 and k = 5e-324 loaded, then every call returned NaN.
    let far = ARM_URDF.replacen("xyz=\"0.8 0 0\"", "xyz=\"1e308 0 0\"", 1);
    assert!(matches!(
        urdf::from_str(&far, ARM_TOML, None, "tip"),
        Err(LoadError::InvalidValue {
            field: "origin",
            ..
        })
    ));
    let tiny = ARM_TOML.replacen("2e5", "5e-324", 1);
    assert!(matches!(
        urdf::from_str(ARM_URDF, &tiny, None, "tip"),
        Err(LoadError::NonPositiveStiffness { axis: 2, .. })
    ));
    assert!(matches!(
        ModelBuilder::new().spring([1.0, 5e-324, 1.0]),
        Err(BuildError::NonPositiveStiffness { axis: 1, .. })
    ));
    let robot = SerialRobot::from_str(ARM_URDF, ARM_TOML, None, "tip").unwrap();
    let drive_toml = "[[joint]]\nname = \"j1\"\nstiffness = 5e-324\n";
    assert!(matches!(
        drive::from_str(&robot, ARM_URDF, drive_toml),
        Err(LoadError::InvalidValue {
            field: "stiffness",
            ..
        })
    ));
}

#[test]
fn lenient_loaders_are_strict_now() {
    // Item 9: a fourth stiffness value was dropped silently; an empty file gave a rigid
    // robot; a revolute joint without <limit> got (0, 0); unknown CSV columns were ignored.
    let four = "[[virtual_joint]]\nlink = \"l1\"\nk = [1e6, 1e6, 1e6, -5]\n";
    let err = stiffness::from_str(four).unwrap_err();
    assert!(err.to_string().contains("expected 3 values"), "{err}");
    for empty in [
        "",
        "# nothing\n",
        "[[joint]]\nname = \"j1\"\nstiffness = 1e5\n",
    ] {
        let err = stiffness::from_str(empty).unwrap_err();
        assert!(err.to_string().contains("no [[virtual_joint]]"), "{err}");
    }
    assert!(stiffness::from_path("/dev/null").is_err());
    let no_limit = ARM_URDF.replacen(
        "<limit lower=\"-3\" upper=\"3\" effort=\"100\" velocity=\"1\"/>",
        "",
        1,
    );
    assert!(matches!(
        urdf::from_str(&no_limit, ARM_TOML, None, "tip"),
        Err(LoadError::InvalidLimit {
            lower: 0.0,
            upper: 0.0,
            ..
        })
    ));
    let csv = "x,y,force_axis,force,dx,dy,dzz\n0,0,0,1,0,0,0\n";
    assert_eq!(
        map_csv::fit_static_str(csv, ForceUnit::Newton, LengthUnit::Metre, None, 1e-6).unwrap_err(),
        LoadError::UnknownColumn {
            column: "dzz".to_string()
        }
    );
}

#[test]
fn python_and_c_share_one_validation() {
    // Item 8: values Python accepted and C refused are refused by the core itself.
    let map = ComplianceMap::new(
        vec![0.1, 0.3],
        vec![-0.1, 0.1],
        2,
        2,
        vec![1e-6; 16],
        vec![0.0; 16],
    )
    .unwrap();
    let model = parallel::Model::new(ParallelRobot2::paper(), map, PAPER_MASS).unwrap();
    for tol in [f64::NAN, f64::INFINITY, -1.0] {
        assert!(matches!(
            model.clone().with_fixed_point(3, tol),
            Err(BuildError::InvalidParameter {
                what: "tolerance",
                ..
            })
        ));
    }
    let robot = SerialRobot::from_str(ARM_URDF, ARM_TOML, None, "tip").unwrap();
    let mut data = Data::new(&robot.model);
    let w = Vector6::new(100.0, 50.0, 0.0, 0.0, 0.0, 0.0);
    for tol in [f64::INFINITY, f64::NAN] {
        assert!(matches!(
            vjm::joint_correction(&robot.model, &mut data, &[0.3], &w, 10, tol),
            Err(TickError::NonFinite {
                what: "tolerance",
                ..
            })
        ));
    }
    assert!(matches!(
        vjm::joint_correction(&robot.model, &mut data, &[0.3], &w, 10, -1.0),
        Err(TickError::InvalidArgument {
            what: "tolerance",
            ..
        })
    ));
    let cal = deflect_core::compensation::SensorCalibration {
        weight: -50.0,
        ..Default::default()
    };
    assert!(matches!(
        cal.validate(),
        Err(BuildError::InvalidParameter { what: "weight", .. })
    ));
}

#[test]
fn joint_correction_is_bounded_and_stops_when_it_stalls() {
    // Item 10: joint_correction(..., 10**6, 0.0) ran all 1e6 iterations (4.2 s).
    let robot = SerialRobot::from_str(ARM_URDF, ARM_TOML, None, "tip").unwrap();
    let mut data = Data::new(&robot.model);
    let w = Vector6::new(100.0, 50.0, -80.0, 0.0, 0.0, 0.0);
    assert!(matches!(
        vjm::joint_correction(&robot.model, &mut data, &[0.3], &w, 1_000_000, 0.0),
        Err(TickError::Budget { .. })
    ));
    // One joint cannot cancel a 3-D deflection: the fixed point is reached, then it stops.
    let c = vjm::joint_correction(&robot.model, &mut data, &[0.3], &w, 256, 0.0).unwrap();
    assert!(c.stalled && !c.converged && c.iterations < 20, "{c:?}");
}

#[test]
fn contour_geometry_refuses_degenerate_inputs() {
    // Item 10: a zero force gave 0.0 rad, a zero step gave pi; a negative-definite K passed.
    let k = Matrix2::new(2e5, 0.0, 0.0, 1e5);
    assert!(matches!(
        contour::edge_direction(&k, &Vector2::new(1e-3, 0.0), &Vector2::zeros()),
        Err(TickError::InvalidArgument { .. })
    ));
    assert!(matches!(
        contour::edge_direction(&k, &Vector2::zeros(), &Vector2::new(1.0, 2.0)),
        Err(TickError::InvalidArgument { .. })
    ));
    let negative = -k;
    assert!(matches!(
        contour::Model::new(TracerConfig::new(1e-3, 2.0, 20.0), &negative),
        Err(BuildError::Singular { .. })
    ));
    let indefinite = Matrix2::new(1e5, 0.0, 0.0, -1e5);
    let model = contour::Model::new(TracerConfig::new(1e-3, 2.0, 20.0), &k).unwrap();
    let mut data = contour::Data::new(&model);
    assert!(matches!(
        data.set_stiffness(&indefinite),
        Err(TickError::Singular { .. })
    ));
    assert_eq!(data.stiffness(), &k);
}

#[test]
fn identification_streams_and_has_a_measurement_budget() {
    // Reproducer 6: N = 2e5 samples needed N^2 memory (11.5 TB) and panicked.
    let robot = SerialRobot::from_str(ARM_URDF, ARM_TOML, None, "tip").unwrap();
    let q = [0.3];
    let m = TcpMeasurement {
        q: &q,
        wrench: Vector6::new(100.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        deflection: Vector6::zeros(),
        translation_only: false,
    };
    let many = vec![m; MAX_MEASUREMENTS + 1];
    assert!(matches!(
        identification::identify_from_tcp(&robot.model, &many, false),
        Err(BuildError::Budget { .. })
    ));
    // The accumulator folds rows block by block: 100 000 exact rows recover x exactly.
    let x_true = [0.5, -2.0, 3.25];
    let mut acc = LeastSquaresAccumulator::new(3);
    for i in 0..100_000u32 {
        let t = f64::from(i) * 1e-3;
        let row = [t.sin(), t.cos(), 1.0];
        let b = row.iter().zip(&x_true).map(|(a, x)| a * x).sum();
        acc.push(&row, b).unwrap();
    }
    let fit = acc.finish().unwrap();
    assert_eq!(fit.rank, 3);
    for (x, t) in fit.x.iter().zip(&x_true) {
        assert!((x - t).abs() < 1e-12, "{x} vs {t}");
    }
    assert!(fit.residual_rms < 1e-12);
}

#[test]
fn fit_statistics_are_finite_or_the_fit_is_refused() {
    // Fuzz reproducer fuzz/regressions/static_csv/crash-2ad00472...: one force level of 5e125
    // N overflowed (a - c)^2 in the condition number, which became inf; the map loaded, was
    // saved as JSON with `null` for it and could not be read back.
    let mut csv = String::from("x,y,force_axis,force,dx,dy\n");
    for (x, y) in [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)] {
        for f in 0..2 {
            for force in ["50", "150", "5e125"] {
                csv.push_str(&format!("{x},{y},{f},{force},0.001,-0.002\n"));
            }
        }
    }
    let map =
        map_csv::fit_static_str(&csv, ForceUnit::Newton, LengthUnit::Metre, None, 1e-6).unwrap();
    let fit = map.fit_stats().unwrap();
    assert!(
        fit.iter()
            .flat_map(|n| &n.condition)
            .all(|c| c.is_finite() && *c > 1e120)
    );
    let json = deflect_core::io::map_json::to_string(&map).unwrap();
    assert_eq!(deflect_core::io::map_json::from_str(&json).unwrap(), map);
    // Displacements whose squared residuals overflow: refused, not NaN statistics.
    let mut csv = String::from("x,y,force_axis,force,dx\n");
    for (x, y) in [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)] {
        for (force, dx) in [(1, 1e200), (2, -1e200), (3, 1e200)] {
            csv.push_str(&format!("{x},{y},0,{force},{dx:e}\n"));
        }
    }
    let r = map_csv::fit_static_str(&csv, ForceUnit::Newton, LengthUnit::Metre, None, 1e-6);
    assert!(
        matches!(r, Err(LoadError::Build(BuildError::NonFinite { .. }))),
        "{r:?}"
    );
}

/// Issue 28: joint positions past MAX_JOINT_POSITION, a deflection rotation past pi, a NaN
/// in a batch row's ignored z, a sub-normal rate, an endless motion: typed errors, not
/// finite nonsense or NaN.
#[test]
fn silent_cases_are_typed_errors() {
    let model = ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .spring([1e4, 1e5, 1e5])
        .unwrap()
        .fixed(Isometry3::translation(0.5, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap();
    let mut data = Data::new(&model);
    for q in [1e300, -2e6] {
        assert!(matches!(
            vjm::forward(&model, &mut data, &[q]),
            Err(TickError::InvalidArgument { value, .. }) if value == q
        ));
    }
    assert!(vjm::forward(&model, &mut data, &[vjm::MAX_JOINT_POSITION]).is_ok());
    assert!(matches!(
        vjm::commanded_pose(&Isometry3::identity(), &Vector6::repeat(1e300)),
        Err(TickError::InvalidArgument { .. })
    ));
    assert!(matches!(
        vjm::commanded_pose(
            &Isometry3::identity(),
            &Vector6::new(0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0)
        ),
        Err(TickError::NonFinite { index: 1, .. })
    ));
    let map = map_csv::from_path(
        format!(
            "{}/../../data/paksoy2025_compliance_oc.csv",
            env!("CARGO_MANIFEST_DIR")
        ),
        ForceUnit::Newton,
        LengthUnit::Millimetre,
    )
    .unwrap();
    let mut out = [0.0; 4];
    let pos = [0.2, 0.0, 0.0, 0.2, 0.01, f64::NAN];
    let e = map
        .displacement_batch(&pos, 3, &[100.0, 0.0, 100.0, 0.0], &mut out, map.options())
        .unwrap_err();
    assert_eq!(e.row, 1);
    assert!(matches!(e.error, TickError::NonFinite { index: 2, .. }));
    assert!(deflect_core::compliance_map::planar_position(&[0.2, 0.0, f64::NAN]).is_err());
    assert_eq!(
        deflect_core::compliance_map::planar_position(&[0.2, 0.1, 9.0]).unwrap(),
        [0.2, 0.1]
    );
    let lim = Limits::new(1e-300, 1.0, 1.0).unwrap();
    assert!(matches!(
        Trajectory::line(Vector2::new(0.0, 0.0), Vector2::new(0.1, 0.0), &lim),
        Err(BuildError::InvalidParameter { .. })
    ));
    let ok = y_line(0.42);
    assert!(matches!(
        ok.tick_count(5e-324),
        Err(TickError::InvalidArgument {
            what: "rate_hz",
            ..
        })
    ));
}
