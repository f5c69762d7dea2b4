//! Building and validating a virtual-joint model: bad elements and inputs are typed errors, a
//! workspace of another model is refused, a model rebuilt from its elements computes the same.

use approx::assert_relative_eq;
use deflect_core::vjm::{self, Data, Element, Vector6};
use deflect_core::{BuildError, ModelBuilder, TickError};
use nalgebra::{Isometry3, Vector3};

mod fixtures;

const INF: f64 = f64::INFINITY;

fn w(f: [f64; 6]) -> Vector6 {
    Vector6::from_row_slice(&f)
}

#[test]
fn bad_inputs_are_typed_errors() {
    let model = fixtures::planar_2r();
    let mut data = Data::new(&model);
    assert_eq!(
        vjm::forward(&model, &mut data, &[0.0]),
        Err(TickError::WrongLength {
            what: "q",
            expected: 2,
            got: 1
        })
    );
    assert_eq!(
        vjm::deflection(
            &model,
            &mut data,
            &[0.0, f64::NAN],
            &Vector6::zeros(),
            vjm::Load::Exact
        ),
        Err(TickError::NonFinite {
            what: "q",
            index: 1
        })
    );
    assert_eq!(
        vjm::deflection(
            &model,
            &mut data,
            &[0.0, 0.0],
            &w([0.0, 0.0, f64::INFINITY, 0.0, 0.0, 0.0]),
            vjm::Load::Exact
        ),
        Err(TickError::NonFinite {
            what: "wrench",
            index: 2
        })
    );
    assert_eq!(
        vjm::compliance(&model, &mut data, &[0.0, 0.0, 0.0]).unwrap_err(),
        TickError::WrongLength {
            what: "q",
            expected: 2,
            got: 3
        }
    );
}

#[test]
fn data_of_another_model_is_refused() {
    // A `Data` records the dof and springs of the model it was made for; every per-tick
    // function refuses it for a model of other dimensions.
    let two = fixtures::planar_2r();
    let one = ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .spring([INF, INF, 1.0e4])
        .unwrap()
        .fixed(Isometry3::translation(1.0, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap();
    assert_eq!((two.dof(), one.dof()), (2, 1));
    let mut data = Data::new(&two);
    assert!(data.check(&two));
    assert!(!data.check(&one));
    assert!(Data::new(&one).check(&one));
    assert!(!Data::new(&one).check(&two));
    let mismatch = TickError::ModelMismatch {
        what: "dof",
        expected: 1,
        got: 2,
    };
    let wr = w([0.0, 100.0, 0.0, 0.0, 0.0, 0.0]);
    // With q sized for either model: the model check comes first.
    for q in [&[0.3][..], &[0.3, -0.2][..]] {
        assert_eq!(vjm::forward(&one, &mut data, q).unwrap_err(), mismatch);
        assert_eq!(
            vjm::deflection(&one, &mut data, q, &wr, vjm::Load::Exact).unwrap_err(),
            mismatch
        );
        assert_eq!(vjm::compliance(&one, &mut data, q).unwrap_err(), mismatch);
        assert_eq!(
            vjm::joint_jacobian(&one, &mut data, q).unwrap_err(),
            mismatch
        );
        assert_eq!(
            vjm::joint_correction(&one, &mut data, q, &wr, 5, 1e-12).unwrap_err(),
            mismatch
        );
        assert_eq!(
            vjm::joint_delta(&one, &mut data, q, &wr).unwrap_err(),
            mismatch
        );
    }
    // The other way round, and the refused data still serves its own model.
    assert_eq!(
        vjm::forward(&two, &mut Data::new(&one), &[0.3, -0.2]).unwrap_err(),
        TickError::ModelMismatch {
            what: "dof",
            expected: 2,
            got: 1
        }
    );
    assert!(data.check(&two));
    vjm::deflection(&two, &mut data, &[0.3, -0.2], &wr, vjm::Load::Exact).unwrap();
    assert!(vjm::deflection(&one, &mut Data::new(&one), &[0.3], &wr, vjm::Load::Exact).is_ok());
}

#[test]
fn builder_rejects_bad_elements() {
    assert_eq!(
        ModelBuilder::new().revolute(Vector3::zeros()).unwrap_err(),
        BuildError::ZeroAxis { element: 0 }
    );
    assert_eq!(
        ModelBuilder::new()
            .fixed(Isometry3::translation(f64::NAN, 0.0, 0.0))
            .unwrap_err(),
        BuildError::NonFinite {
            what: "transform",
            index: 0
        }
    );
    let e = ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .spring([1.0, -2.0, 3.0])
        .unwrap_err();
    assert_eq!(
        e,
        BuildError::NonPositiveStiffness {
            element: 1,
            axis: 1,
            value: -2.0
        }
    );
    assert!(e.to_string().contains("about axis y is -2"));
    assert!(matches!(
        ModelBuilder::new().spring([1.0, f64::NAN, 1.0]),
        Err(BuildError::NonPositiveStiffness { axis: 1, .. })
    ));
    let mut b = ModelBuilder::new();
    for _ in 0..deflect_core::vjm::MAX_DOF {
        b = b.revolute(Vector3::z()).unwrap();
    }
    assert_eq!(
        b.revolute(Vector3::z()).unwrap_err(),
        BuildError::Capacity {
            what: "joints",
            capacity: deflect_core::vjm::MAX_DOF,
            got: deflect_core::vjm::MAX_DOF + 1
        }
    );
}

#[test]
fn spring_inside_a_link_is_undone_after_the_spring() {
    let frame = Isometry3::new(Vector3::new(0.1, 0.2, 0.3), Vector3::new(0.3, -0.2, 0.5));
    let model = ModelBuilder::new()
        .fixed(Isometry3::translation(1.0, 0.0, 0.0))
        .unwrap()
        .spring_at(frame, [1.0e4, 1.0e4, 1.0e4])
        .unwrap()
        .build()
        .unwrap();
    // Rigid FK is unchanged by the spring placement.
    let t = vjm::forward(&model, &mut Data::new(&model), &[]).unwrap();
    assert_relative_eq!(
        t.translation.vector,
        Vector3::new(1.0, 0.0, 0.0),
        epsilon = 1e-15
    );
    assert!(
        model
            .elements()
            .iter()
            .any(|e| matches!(e, Element::Spring { index: 0, .. }))
    );
}

#[test]
fn a_model_rebuilt_from_its_elements_computes_bit_for_bit_the_same() {
    let robot = fixtures::kr300();
    let model = &robot.model;
    let rebuilt = model
        .elements()
        .iter()
        .try_fold(ModelBuilder::new(), |b, e| b.element(*e))
        .and_then(|b| b.build())
        .unwrap();
    assert_eq!(rebuilt.elements(), model.elements());
    assert_eq!(rebuilt.mass_count(), 6);
    let q = [0.3, -0.8, 1.2, 0.5, 0.9, -0.4];
    let w = Vector6::new(-386.1, 386.1, -60.0, 12.0, -7.0, 3.0);
    let (mut a, mut b) = (Data::new(model), Data::new(&rebuilt));
    assert_eq!(
        vjm::deflection(model, &mut a, &q, &w, vjm::Load::Exact).unwrap(),
        vjm::deflection(&rebuilt, &mut b, &q, &w, vjm::Load::Exact).unwrap()
    );
    assert_eq!(
        vjm::compliance(model, &mut a, &q).unwrap(),
        vjm::compliance(&rebuilt, &mut b, &q).unwrap()
    );
    // A tampered element is refused, not normalized or clamped.
    let long_axis = Element::Revolute {
        axis: nalgebra::Unit::new_unchecked(Vector3::new(0.0, 0.0, 2.0)),
        index: 0,
    };
    assert!(matches!(
        ModelBuilder::new().element(long_axis),
        Err(BuildError::InvalidParameter { value, .. }) if value == 2.0
    ));
    let negative = Element::Spring {
        compliance: Vector3::new(1e-6, -1e-6, 0.0),
        index: 0,
        offset: Isometry3::identity(),
    };
    assert!(matches!(
        ModelBuilder::new().element(negative),
        Err(BuildError::NonPositiveStiffness { axis: 1, .. })
    ));
}
