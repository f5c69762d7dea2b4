use deflect_sim::robot::*;
use nalgebra::Vector2;
#[test]
fn probe() {
    for it in [2usize, 4] {
        let mut p = RobotParams::new(Constraint::Nc, Head::Upper);
        p.solver_iterations = it;
        let mut worst: f64 = 0.0;
        for i in 1..=3 { for j in 1..=5 {
        let node = Vector2::new(0.122132 + 0.05 * i as f64, -0.1125 + 0.0375 * j as f64);
        for f in [Vector2::new(245.0, 0.0), Vector2::new(0.0, 245.0)] {
        let mut sim = ParallelSim::new(p, &node).unwrap();
        let w0 = sim.tool_point();
        for _ in 0..600 { sim.step_locked(&f, 10.0); }
        let d = (sim.tool_point() - w0).xy();
        let lin = linear_compliance(&p, &node).unwrap() * f;
        let rel = (d - lin).norm() / lin.norm();
        worst = worst.max(rel);
        if i == 3 && j == 5 { println!("it {it} sim={:.5?} lin={:.5?}", d*1e3, lin*1e3); }
        }}}
        println!("it {it} worst rel {worst:.2e}");
    }
}
