//! The pipeline of Paksoy, Dede and Kiper (2025) in simulation: static tests (sec. 3.1) ->
//! compliance map (sec. 3.2, Eq. 9-14) -> motions at 1-5 g with and without the D'Alembert
//! correction (sec. 3.3, Eq. 5) -> evaluation (Appendix C).

use deflect_core::compliance_map::{
    self, ComplianceMap, FitOptions, HoldOutAxis, Interpolation, Measurement, OutOfGrid,
    QueryOptions,
};
use deflect_core::dalembert::parallel;
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::motion::{Trajectory, paper_limits};
use nalgebra::{Vector2, Vector3};

use crate::SimError;
use crate::scenes::parallel::analysis::{LineMetrics, evaluate_line};
use crate::scenes::parallel::params::{Constraint, DT, RobotParams, linear_compliance};
use crate::scenes::parallel::robot::ParallelSim;

/// The paper's force levels: 5..25 kgf in 5 kgf steps \[N\], as the paper converts them (with
/// 9.81 m/s^2, like [`deflect_core::motion::PAPER_G`]; not a gravity of the simulation).
pub const STATIC_FORCES: [f64; 5] = [49.05, 98.1, 147.15, 196.2, 245.25];

/// Grid node (i, j), i = 1..3, j = 1..5 \[m\].
pub fn grid_node(i: usize, j: usize) -> Vector2<f64> {
    Vector2::new(0.122132 + 0.05 * i as f64, -0.1125 + 0.0375 * j as f64)
}

/// One simulated static reading.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct StaticReading {
    /// Node position \[m\].
    pub x: f64,
    /// Node position \[m\].
    pub y: f64,
    /// 0 = force along x, 1 = along y.
    pub axis: usize,
    /// Force \[N\].
    pub force: f64,
    /// Measured tool-point displacement \[m\].
    pub d: [f64; 2],
    /// Linearized model `J K^-1 J^T F` \[m\].
    pub d_linear: [f64; 2],
}

/// Settings of the static tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticOptions {
    /// Steps per force level.
    pub settle_steps: usize,
    /// Drive damping multiplier while settling.
    pub damping_scale: f64,
}

impl Default for StaticOptions {
    fn default() -> Self {
        Self {
            settle_steps: 250,
            damping_scale: 10.0,
        }
    }
}

/// Static test at `node`: forces `forces` \[N\] applied one after the other along `axis`,
/// motors locked; displacement of the tool point from its unloaded position.
pub fn static_test_node(
    params: &RobotParams,
    node: &Vector2<f64>,
    axis: usize,
    forces: &[f64],
    opts: &StaticOptions,
) -> Result<Vec<StaticReading>, SimError> {
    let mut sim = ParallelSim::new(*params, node)?;
    let c = linear_compliance(params, node)?;
    let w0 = sim.tool_point();
    let mut out = Vec::new();
    for &f in forces {
        let mut fv = Vector2::zeros();
        fv[axis] = f;
        let mut acc = Vector2::zeros();
        let avg = 20.min(opts.settle_steps);
        for k in 0..opts.settle_steps {
            sim.step_locked(&fv, opts.damping_scale);
            if k + avg >= opts.settle_steps {
                acc += (sim.tool_point() - w0).xy();
            }
        }
        let d = acc / avg as f64;
        let lin = c * fv;
        out.push(StaticReading {
            x: node.x,
            y: node.y,
            axis,
            force: f,
            d: [d.x, d.y],
            d_linear: [lin.x, lin.y],
        });
    }
    Ok(out)
}

/// The full static test of the paper: 15 nodes x 2 axes x 5 forces. `tick` is called after
/// each (node, axis).
pub fn static_tests(
    params: &RobotParams,
    opts: &StaticOptions,
    mut tick: impl FnMut(),
) -> Result<Vec<StaticReading>, SimError> {
    let mut out = Vec::new();
    for i in 1..=3 {
        for j in 1..=5 {
            for axis in 0..2 {
                out.extend(static_test_node(
                    params,
                    &grid_node(i, j),
                    axis,
                    &STATIC_FORCES,
                    opts,
                )?);
                tick();
            }
        }
    }
    Ok(out)
}

/// Agreement of simulated static compliance with `J K^-1 J^T`: worst and RMS of
/// `|d_sim - d_lin| / |d_lin|` over the readings with force at most `max_force` \[N\] (the
/// linear model is the small-load limit; at 245 N geometric nonlinearity adds about 0.5 %).
pub fn linear_agreement(readings: &[StaticReading], max_force: f64) -> (f64, f64) {
    let mut worst: f64 = 0.0;
    let mut sq = 0.0;
    let readings: Vec<&StaticReading> = readings.iter().filter(|r| r.force <= max_force).collect();
    for r in &readings {
        let e = ((r.d[0] - r.d_linear[0]).powi(2) + (r.d[1] - r.d_linear[1]).powi(2)).sqrt();
        let n = (r.d_linear[0].powi(2) + r.d_linear[1].powi(2)).sqrt();
        let rel = e / n.max(1e-15);
        worst = worst.max(rel);
        sq += rel * rel;
    }
    (worst, (sq / readings.len().max(1) as f64).sqrt())
}

/// Fits the compliance map (Eq. 10-13) from static readings; bilinear, extrapolating.
pub fn fit_map(readings: &[StaticReading]) -> Result<ComplianceMap, SimError> {
    let ms: Vec<Measurement> = readings
        .iter()
        .map(|r| Measurement::new(r.x, r.y, r.axis, r.force, &r.d))
        .collect();
    let map = compliance_map::fit(&ms, &FitOptions::default())?;
    Ok(map.with_options(map_options()))
}

/// Query options used by the corrector: bilinear (Eq. 14), extrapolating beyond the grid.
pub fn map_options() -> QueryOptions {
    QueryOptions {
        interpolation: Interpolation::Bilinear,
        out_of_grid: OutOfGrid::Extrapolate,
    }
}

/// Prediction errors of a map on held-out data (JSON keys with their unit: `loo_rms_y_m`, ...).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct HeldOut {
    /// Leave-one-grid-line-out RMS error (deflect-core), along y, bilinear \[m\].
    #[serde(rename = "loo_rms_y_m")]
    pub loo_rms_y: f64,
    /// Same along x \[m\].
    #[serde(rename = "loo_rms_x_m")]
    pub loo_rms_x: f64,
    /// Static tests at the 8 cell centres (245 N along x and y): RMS error of the map \[m\].
    #[serde(rename = "centre_rms_m")]
    pub centre_rms: f64,
    /// Worst error at the cell centres \[m\].
    #[serde(rename = "centre_max_m")]
    pub centre_max: f64,
    /// RMS displacement there (for scale) \[m\].
    #[serde(rename = "centre_rms_displacement_m")]
    pub centre_rms_displacement: f64,
}

/// Held-out evaluation: deflect-core's leave-one-node-out and fresh static tests at the cell
/// centres.
pub fn held_out(
    params: &RobotParams,
    map: &ComplianceMap,
    opts: &StaticOptions,
) -> Result<HeldOut, SimError> {
    let forces = [245.25, 0.0, 0.0, 245.25];
    let ly = compliance_map::leave_one_node_out(map, &forces, HoldOutAxis::Y)?;
    let lx = compliance_map::leave_one_node_out(map, &forces, HoldOutAxis::X)?;
    let (mut sq, mut worst, mut sd, mut n) = (0.0, 0.0f64, 0.0, 0);
    for i in 1..3 {
        for j in 1..5 {
            let c = (grid_node(i, j) + grid_node(i + 1, j + 1)) / 2.0;
            for axis in 0..2 {
                let r = static_test_node(params, &c, axis, &[245.25], opts)?;
                for reading in r {
                    let mut f = [0.0; 2];
                    f[axis] = reading.force;
                    let mut pred = [0.0; 2];
                    map.displacement_with([c.x, c.y], &f, &mut pred, map_options())
                        .map_err(|e| SimError::new(e.to_string()))?;
                    let e = ((pred[0] - reading.d[0]).powi(2) + (pred[1] - reading.d[1]).powi(2))
                        .sqrt();
                    sq += e * e;
                    worst = worst.max(e);
                    sd += reading.d[0].powi(2) + reading.d[1].powi(2);
                    n += 1;
                }
            }
        }
    }
    Ok(HeldOut {
        loo_rms_y: ly.rms_bilinear,
        loo_rms_x: lx.rms_bilinear,
        centre_rms: (sq / n as f64).sqrt(),
        centre_max: worst,
        centre_rms_displacement: (sd / n as f64).sqrt(),
    })
}

/// The paper's three motions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum Motion {
    /// 100 mm along x at y = 0.
    XLine,
    /// 150 mm along y (at x = 222.132 mm).
    YLine,
    /// Isosceles triangle, legs of 63.6 mm (206..169 ms each), baseline along y.
    Triangle,
}

impl Motion {
    /// Short name.
    pub fn label(self) -> &'static str {
        match self {
            Self::XLine => "x-line",
            Self::YLine => "y-line",
            Self::Triangle => "triangle",
        }
    }

    /// Corner points \[m\].
    pub fn points(self) -> Vec<Vector2<f64>> {
        let xc = 0.222132;
        match self {
            Self::XLine => vec![Vector2::new(xc - 0.05, 0.0), Vector2::new(xc + 0.05, 0.0)],
            Self::YLine => vec![Vector2::new(xc, -0.075), Vector2::new(xc, 0.075)],
            Self::Triangle => {
                let x0 = xc - 0.025;
                vec![
                    Vector2::new(x0, -0.045),
                    Vector2::new(x0 + 0.045, 0.0),
                    Vector2::new(x0, 0.045),
                    Vector2::new(x0, -0.045),
                ]
            }
        }
    }

    /// Segments that are evaluated (the triangle's baseline is excluded, as in the paper).
    pub fn evaluated_segments(self) -> Vec<usize> {
        match self {
            Self::Triangle => vec![0, 1],
            _ => vec![0],
        }
    }

    /// The planned trajectory at `g` g (the paper's limits).
    pub fn trajectory(self, g: u8) -> Result<Trajectory<2>, SimError> {
        Ok(Trajectory::polyline(&self.points(), &paper_limits(g)?)?)
    }
}

/// One recorded servo tick.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Sample {
    /// Time \[s\].
    pub t: f64,
    /// Segment of the planned path.
    pub segment: usize,
    /// Whether the motion is still commanded (the laser is on).
    pub active: bool,
    /// Desired tool point \[m\].
    pub desired: [f64; 2],
    /// Commanded tool point (desired minus predicted displacement) \[m\].
    pub commanded: [f64; 2],
    /// Actual tool point after the step \[m\] (x, y, z).
    pub actual: [f64; 3],
    /// D'Alembert force `-m* a` \[N\].
    pub force: [f64; 2],
    /// Joint command \[rad\].
    pub q_cmd: [f64; 2],
    /// Motor angles \[rad\].
    pub q_motor: [f64; 2],
    /// Actuated link angles \[rad\].
    pub q_link: [f64; 2],
}

/// Evaluation of one run.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RunMetrics {
    /// Per evaluated segment.
    pub segments: Vec<LineMetrics>,
    /// Sum of the segments' areas \[mm^2\].
    pub area_mm2: f64,
    /// Length minus desired length of the first segment \[mm\] (Eq. C2).
    pub length_dev_mm: f64,
    /// Largest path deviation over the evaluated segments \[mm\].
    pub max_dev_mm: f64,
    /// RMS path deviation \[mm\].
    pub rms_dev_mm: f64,
    /// Largest tracking error |actual - desired| while commanded \[mm\].
    pub max_track_mm: f64,
    /// RMS tracking error \[mm\].
    pub rms_track_mm: f64,
}

/// One simulated run.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RunResult {
    /// Configuration label, e.g. "OC GU".
    pub config: String,
    /// Motion.
    pub motion: Motion,
    /// Acceleration level \[g\].
    pub g: u8,
    /// Whether the correction was on.
    pub corrected: bool,
    /// Mass parameter m* \[kg\].
    pub mass: f64,
    /// Evaluation.
    pub metrics: RunMetrics,
    /// Ticks.
    #[serde(skip)]
    pub samples: Vec<Sample>,
}

/// Settings of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunOptions {
    /// Mass parameter m* \[kg\].
    pub mass: f64,
    /// Fixed-point iterations of the corrector (0 = the paper's one-shot update).
    pub fixed_point: usize,
    /// Time simulated after the motion ends \[s\].
    pub tail: f64,
}

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            mass: parallel::PAPER_MASS,
            fixed_point: 0,
            tail: 0.05,
        }
    }
}

/// Runs `motion` at `g` g on the robot `params`, corrected with `map` if given.
pub fn run(
    params: &RobotParams,
    motion: Motion,
    g: u8,
    map: Option<&ComplianceMap>,
    opts: &RunOptions,
) -> Result<RunResult, SimError> {
    let traj = motion.trajectory(g)?;
    let mech = ParallelRobot2::paper();
    let start = traj.start();
    let mut sim = ParallelSim::new(*params, &start)?;
    if !(opts.mass.is_finite() && opts.mass >= 0.0) {
        return Err(SimError::new(format!(
            "mass parameter {} kg: expected finite and >= 0",
            opts.mass
        )));
    }
    // The corrector (Paksoy, Dede and Kiper (2025), sec. 3.3, Eq. 5) with its workspace, when
    // a map is given.
    let mut corrector = match map {
        Some(m) => {
            let view = m.view().with_options(map_options());
            let model = parallel::Model::new(mech, view, opts.mass)?
                .with_fixed_point(opts.fixed_point, 1e-9)?;
            let data = parallel::Data::new(&model);
            Some((model, data))
        }
        None => None,
    };
    let n_motion = (traj.duration() / DT).ceil() as usize + 1;
    let n_total = n_motion + (opts.tail / DT).ceil() as usize;
    let mut samples = Vec::with_capacity(n_total);
    let mut q_prev = sim.q_ref();
    let mut qd_prev = Vector2::zeros();
    for k in 0..n_total {
        let t = (k as f64 * DT).min(traj.duration());
        let state = traj.sample(t)?;
        let desired = state.position;
        let (commanded, force, q) = match corrector.as_mut() {
            Some((model, data)) => {
                data.set_seed(q_prev);
                let tick = parallel::step(model, data, &desired, &state.acceleration)?;
                (tick.commanded, tick.load, tick.joints)
            }
            None => (desired, -opts.mass * state.acceleration, mech.ik(&desired)?),
        };
        let qd = if k == 0 {
            Vector2::zeros()
        } else {
            (q - q_prev) / DT
        };
        let qdd = if k == 0 {
            Vector2::zeros()
        } else {
            (qd - qd_prev) / DT
        };
        sim.step_servo(&q, &qd, &qdd);
        q_prev = q;
        qd_prev = qd;
        let w: Vector3<f64> = sim.tool_point();
        let (ql, _) = sim.link_state();
        let qm = sim.motor_angles();
        samples.push(Sample {
            t: k as f64 * DT,
            segment: state.segment,
            active: k < n_motion,
            desired: [desired.x, desired.y],
            commanded: [commanded.x, commanded.y],
            actual: [w.x, w.y, w.z],
            force: [force.x, force.y],
            q_cmd: [q.x, q.y],
            q_motor: [qm.x, qm.y],
            q_link: [ql.x, ql.y],
        });
    }
    let metrics = evaluate_run(motion, &samples);
    Ok(RunResult {
        config: params.label(),
        motion,
        g,
        corrected: map.is_some(),
        mass: opts.mass,
        metrics,
        samples,
    })
}

/// The paper's figures and the path deviation of one run (samples while the motion is
/// commanded: the laser is on).
pub fn evaluate_run(motion: Motion, samples: &[Sample]) -> RunMetrics {
    let pts = motion.points();
    let mut segments = Vec::new();
    for s in motion.evaluated_segments() {
        let path: Vec<[f64; 2]> = samples
            .iter()
            .filter(|x| x.active && x.segment == s)
            .map(|x| [x.actual[0], x.actual[1]])
            .collect();
        segments.push(evaluate_line(
            &path,
            [pts[s].x, pts[s].y],
            [pts[s + 1].x, pts[s + 1].y],
        ));
    }
    let (mut max_t, mut sq_t, mut n) = (0.0f64, 0.0, 0);
    for x in samples.iter().filter(|x| x.active) {
        let e = ((x.actual[0] - x.desired[0]).powi(2) + (x.actual[1] - x.desired[1]).powi(2))
            .sqrt()
            * 1e3;
        max_t = max_t.max(e);
        sq_t += e * e;
        n += 1;
    }
    let total: usize = segments.iter().map(|s| s.samples).sum();
    RunMetrics {
        area_mm2: segments.iter().map(|s| s.area_mm2).sum(),
        length_dev_mm: segments
            .first()
            .map_or(0.0, |s| s.length_mm - s.desired_length_mm),
        max_dev_mm: segments.iter().map(|s| s.max_dev_mm).fold(0.0, f64::max),
        rms_dev_mm: (segments
            .iter()
            .map(|s| s.rms_dev_mm.powi(2) * s.samples as f64)
            .sum::<f64>()
            / total.max(1) as f64)
            .sqrt(),
        max_track_mm: max_t,
        rms_track_mm: (sq_t / n.max(1) as f64).sqrt(),
        segments,
    }
}

/// The configurations of the paper's Table I (OC/NC x upper/lower head).
pub fn configurations() -> Vec<RobotParams> {
    use crate::scenes::parallel::params::Head;
    let mut v = Vec::new();
    for c in [Constraint::Oc, Constraint::Nc] {
        for h in [Head::Upper, Head::Lower] {
            v.push(RobotParams::new(c, h));
        }
    }
    v
}

/// The compliance map the static tests would give if the robot were exactly linear: the
/// nodes' `J K^-1 J^T` (no offsets). For quick tests and as a reference.
pub fn linear_map(params: &RobotParams) -> Result<ComplianceMap, SimError> {
    let xs: Vec<f64> = (1..=3).map(|i| grid_node(i, 1).x).collect();
    let ys: Vec<f64> = (1..=5).map(|j| grid_node(1, j).y).collect();
    let mut slopes = Vec::new();
    for x in &xs {
        for y in &ys {
            let c = linear_compliance(params, &Vector2::new(*x, *y))?;
            // (node * n_displacement + d) * n_force + f
            slopes.extend_from_slice(&[c[(0, 0)], c[(0, 1)], c[(1, 0)], c[(1, 1)]]);
        }
    }
    let offsets = vec![0.0; slopes.len()];
    Ok(ComplianceMap::new(xs, ys, 2, 2, slopes, offsets)?.with_options(map_options()))
}
