//! Latency harness: per-tick wall time of the real-time paths over 1e6 consecutive ticks,
//! reported as median, p99.9 and max (a mean hides the tail a servo loop cares about).
//! `cargo bench --bench latency` (optionally `-- N` ticks).

use std::hint::black_box;
use std::time::Instant;

use deflect_core::vjm::{self, Data, Vector6};
use deflect_tests::{KR300_MILLING_POSE, MILLING_WRENCH, kr300};

/// Runs `tick(i)` `n` times and prints median / p99.9 / max in ns.
pub fn report(name: &str, n: usize, budget_ns: f64, mut tick: impl FnMut(usize)) {
    let mut ns = Vec::with_capacity(n);
    for i in 0..n.min(10_000) {
        tick(i); // warm-up
    }
    for i in 0..n {
        let t0 = Instant::now();
        tick(i);
        ns.push(t0.elapsed().as_nanos() as u64);
    }
    ns.sort_unstable();
    let q = |p: f64| ns[((ns.len() - 1) as f64 * p).round() as usize];
    println!(
        "{name:<28} ticks {n:>8}  median {:>7} ns  p99.9 {:>7} ns  max {:>8} ns  (budget {budget_ns:.0} ns)",
        q(0.5),
        q(0.999),
        ns[ns.len() - 1]
    );
}

fn main() {
    let n: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    // A 2 kHz servo tick leaves 500 us for everything.
    let budget = 500_000.0;
    let robot = kr300();
    let model = &robot.model;
    let mut data = Data::new(model);
    let w = Vector6::from_row_slice(&MILLING_WRENCH);
    let mut q = KR300_MILLING_POSE;
    println!("deflect latency harness: KR 300 model (6 joints, 11 virtual joints)");
    report("vjm::deflection", n, budget, |i| {
        q[0] = 1e-6 * (i % 1000) as f64;
        black_box(vjm::deflection(model, &mut data, black_box(&q), &w).ok());
    });
    report("vjm::compliance", n, budget, |i| {
        q[0] = 1e-6 * (i % 1000) as f64;
        black_box(vjm::compliance(model, &mut data, black_box(&q)).ok());
    });
    report("vjm::joint_correction(1)", n / 10, budget, |i| {
        q[0] = 1e-6 * (i % 1000) as f64;
        black_box(vjm::joint_correction(model, &mut data, black_box(&q), &w, 1, 0.0).ok());
    });
}
