use deflect_sim::robot::*;
use nalgebra::Vector2;
#[test]
fn probe() {
    for (it, pgs) in [(1usize, 1usize), (1, 4), (1, 16), (1, 64), (2, 16), (4, 1)] {
        let mut p = RobotParams::new(Constraint::Nc, Head::Upper);
        p.solver_iterations = it;
        p.pgs_iterations = pgs;
        let mut worst: f64 = 0.0;
        let t0 = std::time::Instant::now();
        let mut steps = 0;
        for i in 1..=3 { for j in 1..=5 {
        let node = Vector2::new(0.122132 + 0.05 * i as f64, -0.1125 + 0.0375 * j as f64);
        for f in [Vector2::new(10.0, 0.0), Vector2::new(0.0, 10.0)] {
        let mut sim = ParallelSim::new(p, &node).unwrap();
        let w0 = sim.tool_point();
        for _ in 0..300 { sim.step_locked(&f, 10.0); steps += 1; }
        let d = (sim.tool_point() - w0).xy();
        let lin = linear_compliance(&p, &node).unwrap() * f;
        let rel = (d - lin).norm() / lin.norm();
        worst = worst.max(rel);
        }}}
        println!("it {it} pgs {pgs} worst rel {worst:.2e} {:?}/step", t0.elapsed() / steps);
    }
}
