//! Shared fixtures of deflect's cross-crate tests, examples and benchmarks, and the fuzz
//! harnesses of its loaders ([`fuzz`]).

pub mod fuzz;
pub mod programs;

/// Path of a file shipped in the repository, from the workspace root.
pub fn repo_path(relative: &str) -> String {
    format!("{}/{relative}", env!("CARGO_MANIFEST_DIR"))
}

/// Uniform numbers in `[lo, hi)` from a xorshift generator seeded with `seed` (non-zero): the
/// same sequence on every machine, for the random rows of tests and benchmarks.
pub fn uniform(seed: u64) -> impl FnMut(f64, f64) -> f64 {
    let mut state = seed;
    move |lo, hi| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The shipped KR 300 R2500 model (URDF + Table 1 stiffnesses), chain base_link -> tcp.
pub fn kr300() -> deflect_core::SerialRobot {
    match deflect_core::SerialRobot::from_path(
        repo_path("robots/kr300/kr300_r2500.urdf"),
        repo_path("robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    ) {
        Ok(r) => r,
        Err(e) => panic!("the shipped KR 300 model must load: {e}"),
    }
}

/// A milling pose of the KR 300 model \[rad\]: flange pointing down, TCP 1.80 m in front of A1 and
/// 0.48 m above the base, tool axis horizontal.
pub const KR300_MILLING_POSE: [f64; 6] = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];

/// A 546 N milling force (the paper's largest) in the horizontal plane, base frame \[N, N m\].
pub const MILLING_WRENCH: [f64; 6] = [-386.1, 386.1, 0.0, 0.0, 0.0, 0.0];

/// Runs `tick(i)` `n` times after a warm-up and prints median / p99.9 / max wall time per tick
/// in ns (a mean hides the tail a servo loop cares about). A servo thread sleeps between ticks
/// and a SCHED_FIFO thread that never sleeps is throttled by the kernel (50 ms per second by
/// default), so it pauses 200 us every 256 ticks, outside the timed region.
pub fn latency_report(name: &str, n: usize, budget_ns: Option<f64>, mut tick: impl FnMut(usize)) {
    use std::time::{Duration, Instant};
    let mut ns = Vec::with_capacity(n);
    for i in 0..n.min(10_000) {
        tick(i); // warm-up
    }
    for i in 0..n {
        if i % 256 == 255 {
            std::thread::sleep(Duration::from_micros(200));
        }
        let t0 = Instant::now();
        tick(i);
        ns.push(t0.elapsed().as_nanos() as u64);
    }
    ns.sort_unstable();
    let at = |p: f64| {
        let k = ((ns.len().saturating_sub(1)) as f64 * p).round() as usize;
        ns.get(k).copied().unwrap_or(0)
    };
    let budget = budget_ns.map_or(String::new(), |b| format!("  (budget {b:.0} ns)"));
    println!(
        "{name:<38} ticks {n:>8}  median {:>7} ns  p99.9 {:>7} ns  max {:>8} ns{budget}",
        at(0.5),
        at(0.999),
        at(1.0)
    );
}

/// Asks for what a servo thread gets on a real-time controller: SCHED_FIFO priority 80 and
/// locked memory. Returns what was granted (a container may refuse).
pub fn realtime_setup() -> &'static str {
    #[allow(unsafe_code)] // reason: plain libc calls with valid arguments
    // SAFETY: `sched_param` is fully initialised; both calls only read their arguments.
    let (fifo, locked) = unsafe {
        let param = libc::sched_param { sched_priority: 80 };
        (
            libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) == 0,
            libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) == 0,
        )
    };
    match (fifo, locked) {
        (true, true) => "SCHED_FIFO 80, memory locked",
        (true, false) => "SCHED_FIFO 80, memory not locked",
        (false, true) => "normal scheduling (SCHED_FIFO refused), memory locked",
        (false, false) => "normal scheduling (SCHED_FIFO and mlockall refused)",
    }
}

/// The shipped OC compliance map of Paksoy et al. (force unit N, lengths mm), clamped at the
/// grid boundary: the map the 2 kHz benchmarks and examples drive.
pub fn paper_oc_map_clamped() -> deflect_core::compliance_map::ComplianceMap {
    use deflect_core::compliance_map::{OutOfGrid, QueryOptions};
    use deflect_core::units::{ForceUnit, LengthUnit};
    let path = repo_path("data/paksoy2025_compliance_oc.csv");
    match deflect_core::io::map_csv::from_path(path, ForceUnit::Newton, LengthUnit::Millimetre) {
        Ok(m) => m.with_options(QueryOptions {
            out_of_grid: OutOfGrid::Clamp,
            ..QueryOptions::default()
        }),
        Err(e) => panic!("the shipped OC table must load: {e}"),
    }
}

/// The paper's 150 mm y-line (x = 222.132 mm) planned at 5 g.
pub fn paper_y_line_5g() -> deflect_core::motion::Trajectory<2> {
    use nalgebra::Vector2;
    let limits = match deflect_core::motion::paper_limits(5) {
        Ok(l) => l,
        Err(e) => panic!("paper limits: {e}"),
    };
    match deflect_core::motion::Trajectory::line(
        Vector2::new(0.222132, -0.075),
        Vector2::new(0.222132, 0.075),
        &limits,
    ) {
        Ok(t) => t,
        Err(e) => panic!("the y-line must plan: {e}"),
    }
}

/// A pose motion of the KR 300 from its milling pose: 0.33 m and 0.3 rad about the base z
/// axis, at about 1 g (linear 2 m/s, 9.81 m/s^2, 200 m/s^3; angular 1.5 rad/s, 8 rad/s^2,
/// 100 rad/s^3).
pub fn kr300_pose_motion() -> deflect_core::motion::PoseTrajectory {
    use deflect_core::motion::{Limits, PoseLimits, PoseTrajectory};
    use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
    let robot = kr300();
    let mut data = deflect_core::vjm::Data::new(&robot.model);
    let start = match deflect_core::vjm::forward(&robot.model, &mut data, &KR300_MILLING_POSE) {
        Ok(t) => t,
        Err(e) => panic!("forward kinematics: {e}"),
    };
    let end = Isometry3::from_parts(
        Translation3::from(start.translation.vector + Vector3::new(0.1, 0.3, -0.1)),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.0, 0.3)) * start.rotation,
    );
    let limits = match (Limits::new(2.0, 9.81, 200.0), Limits::new(1.5, 8.0, 100.0)) {
        (Ok(linear), Ok(angular)) => PoseLimits { linear, angular },
        _ => panic!("valid limits"),
    };
    match PoseTrajectory::line(&start, &end, &limits) {
        Ok(t) => t,
        Err(e) => panic!("the pose motion must plan: {e}"),
    }
}

/// The virtual-joint model of a serial arm as the displacement model of the paper's generic
/// corrector ([`deflect_core::dalembert::parallel`]): the D'Alembert force acts at the TCP
/// (plus a constant moment), and the displacement is the TCP translation of the exact
/// deflection at the joints `q`. A user's own [`DisplacementModel`] looks like this; the
/// tests check the generic corrector with it, and the latency harness times it against the
/// serial corrector, which solves the same problem as one loaded pose IK.
///
/// [`DisplacementModel`]: deflect_core::dalembert::parallel::DisplacementModel
#[derive(Debug, Clone)]
pub struct VjmDisplacement {
    /// The arm.
    pub model: deflect_core::vjm::Model,
    /// D'Alembert moment \[N m\], base frame; zero for pure translations.
    pub moment: nalgebra::Vector3<f64>,
}

impl<const J: usize> deflect_core::dalembert::parallel::DisplacementModel<3, J>
    for VjmDisplacement
{
    type Data = deflect_core::vjm::Data;

    fn new_data(&self) -> Self::Data {
        deflect_core::vjm::Data::new(&self.model)
    }

    fn check(&self) -> Result<(), deflect_core::BuildError> {
        if self.model.dof() == J {
            Ok(())
        } else {
            Err(deflect_core::BuildError::DofMismatch {
                what: "VjmDisplacement (joint count J)",
                expected: self.model.dof(),
                got: J,
            })
        }
    }

    fn displacement(
        &self,
        data: &mut Self::Data,
        _position: &nalgebra::Vector3<f64>,
        q: &nalgebra::SVector<f64, J>,
        force: &nalgebra::Vector3<f64>,
    ) -> Result<(nalgebra::Vector3<f64>, deflect_core::Placement), deflect_core::TickError> {
        use deflect_core::vjm::{self, Load, Vector6};
        let m = self.moment;
        let w = Vector6::new(force.x, force.y, force.z, m.x, m.y, m.z);
        let d = vjm::deflection(&self.model, data, q.as_slice(), &w, Load::Exact)?;
        Ok((
            nalgebra::Vector3::new(d.x, d.y, d.z),
            deflect_core::Placement::Inside,
        ))
    }

    fn needs_joints(&self) -> bool {
        true
    }
}

/// Path of a file of the shared references next to the repository (`../shared/`, or the
/// folder `DEFLECT_SHARED` names): programs written by real CAM systems and the machining
/// reproducers, which are not ours to commit.
pub fn shared_path(relative: &str) -> String {
    match std::env::var("DEFLECT_SHARED") {
        Ok(dir) => format!("{dir}/{relative}"),
        Err(_) => format!("{}/../shared/{relative}", env!("CARGO_MANIFEST_DIR")),
    }
}

/// Joints near the start of a program on [`job_setup`]'s placement (`deflect-sim job`'s
/// seed): the KR 300's tool down over the table.
pub const JOB_SEED: [f64; 6] = [0.0, -0.9, 1.4, 0.0, -0.5, 0.0];

/// `deflect-sim job`'s setup of the KR 300: the workpiece 2.45 m in front of the base, 0.92 m
/// up, turned half a turn about z, the tool down; a 16 mm three-flute end mill in Al7075;
/// the stock over `[min, max]` \[m\] with its top at 0 and cells of `cell` \[m\]; the
/// default path and IK options.
pub fn job_setup(
    min: nalgebra::Vector2<f64>,
    max: nalgebra::Vector2<f64>,
    cell: f64,
) -> deflect_core::machining::job::Setup {
    use deflect_core::machining::cutting::{Coefficients, Tool};
    use deflect_core::machining::job::{RAPID_SKIM, Setup, Stock};
    let tool = match Tool::new(0.016, 3, 0.0) {
        Ok(t) => t,
        Err(e) => panic!("the 16 mm tool: {e}"),
    };
    Setup {
        placement: nalgebra::Isometry3::new(
            nalgebra::Vector3::new(2.45, 0.02, 0.92),
            nalgebra::Vector3::new(0.0, 0.0, std::f64::consts::PI),
        ),
        tool_orientation: Setup::tool_down(),
        tool,
        coefficients: Coefficients::AL7075_T6_CARBIDE,
        stock: Stock {
            min,
            max,
            top: 0.0,
            cell,
        },
        path: deflect_core::machining::path::PathOptions::default(),
        ik: deflect_core::mechanism::PoseIkOptions::default(),
        hand_spindle: None,
        rapid_skim: RAPID_SKIM,
    }
}

/// A G-code program in mm, the tool 20 mm above the workpiece origin before it starts.
pub fn read_mm(text: &str) -> deflect_core::machining::Program {
    let options = deflect_core::io::gcode::GcodeOptions {
        start: nalgebra::Vector3::new(0.0, 0.0, 0.02),
        units: deflect_core::units::LengthUnit::Millimetre,
        ..deflect_core::io::gcode::GcodeOptions::default()
    };
    match deflect_core::io::gcode::from_str(text, &options) {
        Ok(p) => p,
        Err(e) => panic!("the program must read: {e}"),
    }
}

/// The built-in job of `deflect-sim job` as the tests set it up: [`job_setup`] over the
/// stock (5, -15)..(85, 45) mm in 0.5 mm cells, the KR 300, `data/groove_and_pocket.nc`.
pub fn builtin_job() -> (
    deflect_core::machining::job::Job,
    deflect_core::machining::Program,
) {
    let text = match std::fs::read_to_string(repo_path("data/groove_and_pocket.nc")) {
        Ok(t) => t,
        Err(e) => panic!("the built-in program must read: {e}"),
    };
    let setup = job_setup(
        nalgebra::Vector2::new(0.005, -0.015),
        nalgebra::Vector2::new(0.085, 0.045),
        5.0e-4,
    );
    let robot = kr300();
    match deflect_core::machining::job::Job::new(robot.model.clone(), &robot.joint_limits, setup) {
        Ok(job) => (job, read_mm(&text)),
        Err(e) => panic!("the built-in job must build: {e}"),
    }
}
