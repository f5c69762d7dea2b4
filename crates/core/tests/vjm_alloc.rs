//! The per-call VJM paths allocate nothing: a counting global allocator watches 1e4 calls.
//! One test function only, so no other test thread allocates meanwhile.

use deflect_core::TickError;
use deflect_core::vjm::{self, Data, Vector6};

mod common;
mod fixtures;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

#[test]
fn vjm_calls_do_not_allocate() {
    common::watch_this_thread();
    common::assert_counter_works();
    let b = fixtures::six_r(fixtures::Link::Spring([3.0e6, 3.0e6, 1.0e6]));
    let model = b.build().unwrap();
    let mut data = Data::new(&model);
    let wrench = Vector6::new(300.0, -200.0, -500.0, 10.0, 0.0, -5.0);
    let mut q = [0.1, -0.4, 0.9, 0.2, 0.6, -0.3];
    let mut sink = 0.0;

    let before = common::allocations();
    for i in 0..10_000 {
        q[0] = 1e-4 * i as f64;
        sink += vjm::forward(&model, &mut data, &q).unwrap().translation.x;
        sink += vjm::deflection(&model, &mut data, &q, &wrench, vjm::Load::Exact).unwrap()[0];
        sink += vjm::compliance(&model, &mut data, &q).unwrap()[(0, 0)];
        vjm::joint_jacobian(&model, &mut data, &q).unwrap();
        let rows = [&q[..]; 4];
        sink += vjm::exact_deflection_x4(&model, &data, rows, [&wrench; 4]).unwrap()[3][0];
        if i % 100 == 0 {
            sink += vjm::joint_correction(&model, &mut data, &q, &wrench, 3, 1e-12)
                .unwrap()
                .dq[0];
        }
        // Error paths allocate nothing either.
        let bad = vjm::deflection(&model, &mut data, &q[..5], &wrench, vjm::Load::Exact);
        assert!(matches!(bad, Err(TickError::WrongLength { .. })));
    }
    let after = common::allocations();
    assert!(sink.is_finite());
    assert_eq!(after - before, 0, "allocations on the per-call path");
}
