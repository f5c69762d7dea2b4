//! The Delta scene's runs: the static tests on the 3-D grid, the fitted map, the move
//! uncorrected and corrected.

use deflect_core::compliance_map::{FitOptions, GridMap, GridMeasurement, fit_grid};
use deflect_core::dalembert::parallel::{self, Data, Model};
use deflect_core::mechanism::Mechanism;
use deflect_core::motion::{Limits, PoseLimits, PoseState, PoseTrajectory};
use nalgebra::{Isometry3, Matrix3, Vector3};
use serde::Serialize;

use super::options::DeltaOptions;
use super::robot::{DeltaParams, DeltaSim};
use crate::SimError;

/// One run of the move.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DeltaRun {
    /// With the corrector.
    pub corrected: bool,
    /// Largest distance of the platform from the straight path \[mm\].
    pub path_max_mm: f64,
    /// RMS distance \[mm\].
    pub path_rms_mm: f64,
    /// Largest distance from the planned point at the same tick \[mm\].
    pub track_max_mm: f64,
    /// Per tick: time \[s\], desired and actual platform centre \[m\].
    #[serde(skip)]
    pub samples: Vec<(f64, [f64; 3], [f64; 3])>,
}

/// Everything the scene produced.
#[derive(Debug, Clone)]
pub struct DeltaResult {
    /// Settings.
    pub options: DeltaOptions,
    /// Largest relative difference of the testbed's static compliance and the Delta's
    /// `J K^-1 J^T` at the grid's centre (three forces).
    pub static_rel_error: f64,
    /// The map fitted from the static tests.
    pub map: GridMap,
    /// Uncorrected, then corrected.
    pub runs: Vec<DeltaRun>,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
}

/// Damping multiplier of the static tests (readings do not depend on damping).
const STATIC_DAMPING: f64 = 30.0;
/// Step budget of one static test.
const STATIC_STEPS: usize = 20_000;

/// The testbed's static compliance at `p` against `J K^-1 J^T`: the largest relative
/// difference over forces of `force` N along x, y, z.
pub fn static_check(params: &DeltaParams, p: &Vector3<f64>, force: f64) -> Result<f64, SimError> {
    let d = params.delta;
    let q = d.ik(p)?;
    let j = d.jacobian(&mut (), &q)?;
    let c = j * Matrix3::identity() / params.k_drive * j.transpose();
    let mut worst = 0.0f64;
    for k in 0..3 {
        let mut f = Vector3::zeros();
        f[k] = force;
        let mut sim = DeltaSim::new(*params, p)?;
        let got = sim.static_deflection(&f, STATIC_DAMPING, STATIC_STEPS);
        let want = c * f;
        worst = worst.max((got - want).norm() / want.norm());
    }
    Ok(worst)
}

/// Static tests at every node of the grid: forces of +-`test_force` along x, y, z, the
/// platform's displacement each (motors locked), as readings to fit.
pub fn static_tests(opts: &DeltaOptions) -> Result<Vec<GridMeasurement>, SimError> {
    let axis = |k: usize| -> Vec<f64> {
        let n = opts.nodes[k].max(2);
        (0..n)
            .map(|i| {
                opts.grid_min[k] + (opts.grid_max[k] - opts.grid_min[k]) * i as f64 / (n - 1) as f64
            })
            .collect()
    };
    let (xs, ys, zs) = (axis(0), axis(1), axis(2));
    let mut nodes = Vec::new();
    for x in &xs {
        for y in &ys {
            for z in &zs {
                nodes.push(Vector3::new(*x, *y, *z));
            }
        }
    }
    let readings = crate::workers::parallel_map(&nodes, opts.jobs, |p| {
        let mut out = Vec::with_capacity(6);
        for k in 0..3 {
            for sign in [-1.0, 1.0] {
                let mut f = Vector3::zeros();
                f[k] = sign * opts.test_force;
                let mut sim = DeltaSim::new(opts.params, p)?;
                let d = sim.static_deflection(&f, STATIC_DAMPING, STATIC_STEPS);
                out.push(GridMeasurement::new(p.as_slice(), k, f[k], d.as_slice()));
            }
        }
        Ok::<_, SimError>(out)
    })?;
    let mut all = Vec::new();
    for r in readings {
        all.extend(r?);
    }
    Ok(all)
}

/// The move from `opts.from` to `opts.to`, rest to rest, jerk-limited, peak `opts.g`.
pub fn plan(opts: &DeltaOptions) -> Result<PoseTrajectory, SimError> {
    let a = opts.g * 9.81;
    let limits = PoseLimits {
        linear: Limits::new(opts.v_max, a, a / opts.ramp)?,
        angular: Limits::new(1.0, 1.0, 10.0)?,
    };
    let start = Isometry3::translation(opts.from[0], opts.from[1], opts.from[2]);
    let end = Isometry3::translation(opts.to[0], opts.to[1], opts.to[2]);
    Ok(PoseTrajectory::line(&start, &end, &limits)?)
}

/// Distance of `p` from the segment `from`-`to` \[m\].
fn path_distance(opts: &DeltaOptions, p: &Vector3<f64>) -> f64 {
    let (a, b) = (Vector3::from(opts.from), Vector3::from(opts.to));
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
    (p - (a + ab * t)).norm()
}

/// One run of the move, corrected with `map` or not.
pub fn run(opts: &DeltaOptions, map: Option<&GridMap>) -> Result<DeltaRun, SimError> {
    let d = opts.params.delta;
    let traj = plan(opts)?;
    let dt = opts.params.dt;
    let n = traj.tick_count(1.0 / dt)?;
    let states: Vec<PoseState> = (0..n)
        .map(|k| traj.sample(traj.tick_time(1.0 / dt, k, n)))
        .collect::<Result<_, _>>()?;
    let start = Vector3::from(opts.from);
    let mut sim = DeltaSim::new(opts.params, &start)?;
    let corrector = match map {
        Some(m) => Some(Model::new(d, m.clone(), opts.mass)?),
        None => None,
    };
    let mut data = corrector.as_ref().map(Data::new);
    let tail = (opts.tail / dt).ceil() as usize;
    let (mut q_prev, mut qd_prev) = (d.ik(&start)?, Vector3::zeros());
    let mut samples = Vec::with_capacity(n + tail);
    let (mut worst, mut sq, mut track) = (0.0f64, 0.0, 0.0f64);
    for k in 0..n + tail {
        let s = states.get(k.min(n.saturating_sub(1))).copied();
        let Some(s) = s else { break };
        let x = s.pose.translation.vector;
        let a = if k < n {
            s.acceleration
        } else {
            Vector3::zeros()
        };
        let q = match (&corrector, data.as_mut()) {
            (Some(m), Some(dd)) => parallel::step(m, dd, &x, &a)?.joints,
            _ => d.ik(&x)?,
        };
        let qd = if k == 0 {
            Vector3::zeros()
        } else {
            (q - q_prev) / dt
        };
        let qdd = if k == 0 {
            Vector3::zeros()
        } else {
            (qd - qd_prev) / dt
        };
        sim.step_servo(&q, &qd, &qdd);
        let p = sim.platform_position();
        let e = path_distance(opts, &p) * 1e3;
        if k < n {
            worst = worst.max(e);
            sq += e * e;
            track = track.max((p - x).norm() * 1e3);
        }
        samples.push((k as f64 * dt, [x.x, x.y, x.z], [p.x, p.y, p.z]));
        q_prev = q;
        qd_prev = qd;
    }
    Ok(DeltaRun {
        corrected: map.is_some(),
        path_max_mm: worst,
        path_rms_mm: (sq / n.max(1) as f64).sqrt(),
        track_max_mm: track,
        samples,
    })
}

/// The scene: static check, static tests, fit, the move uncorrected and corrected.
pub fn delta(opts: &DeltaOptions) -> Result<DeltaResult, SimError> {
    let start = std::time::Instant::now();
    let centre = (Vector3::from(opts.grid_min) + Vector3::from(opts.grid_max)) / 2.0;
    let static_rel_error = static_check(&opts.params, &centre, opts.test_force)?;
    let readings = static_tests(opts)?;
    let names = ["x", "y", "z"].map(String::from).to_vec();
    let fit_options = FitOptions {
        n_force: 3,
        n_displacement: 3,
        position_tolerance: 1e-6,
    };
    let map = fit_grid(names, &readings, &fit_options)
        .map_err(|e| SimError::new(format!("Delta map fit: {e}")))?;
    let runs =
        crate::workers::parallel_map(&[false, true], opts.jobs, |&c| run(opts, c.then_some(&map)))?
            .into_iter()
            .collect::<Result<Vec<_>, _>>()?;
    Ok(DeltaResult {
        options: *opts,
        static_rel_error,
        map,
        runs,
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}
