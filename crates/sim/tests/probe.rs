use deflect_sim::robot::*;
use nalgebra::Vector2;
#[test]
fn probe() {
    for it in [1usize, 2, 4, 8] {
        let mut p = RobotParams::new(Constraint::Nc, Head::Upper);
        p.solver_iterations = it;
        let node = Vector2::new(0.272, 0.075);
        let mut sim = ParallelSim::new(p, &node).unwrap();
        let w0 = sim.tool_point();
        let t0 = std::time::Instant::now();
        let f = Vector2::new(0.0, 245.0);
        for _ in 0..2000 { sim.step_locked(&f, 10.0); }
        let d = sim.tool_point() - w0;
        println!("it {it} sim={:.5?} {:?}/step", d.xy()*1e3, t0.elapsed()/2000);
    }
}
