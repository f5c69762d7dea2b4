//! Where to put the workpiece in the cell: the placement (position, and turn about the
//! vertical) in a box the user gives for the least predicted deflection along the whole
//! program, with or without the spin optimisation of [`super::spin`].
//!
//! The program's nominal forces do not depend on the placement: [`Problem::new`] computes
//! them once (the nominal pass of [`super::spin::LoadPath`]); a candidate costs the pose IK
//! and the compliance at every station, for the seed's spin ([`Problem::evaluate`]) or for
//! every candidate spin (the dynamic programming of [`super::spin::plan_at`]). Its score is
//! the RMS of the [`super::spin::SpinMeasure`] over the cutting samples (and the largest); a
//! candidate whose stations the arm cannot reach within its limits and margins scores
//! infinity and names the program line.
//!
//! [`search`] evaluates a grid over the box (`steps` points per axis, an axis of one point at
//! the box's middle), then refines around the best point by a compass search: the neighbours
//! half a grid spacing away along each axis of more than one point, keeping the best, halving
//! the spacing each round. Every evaluation goes through the caller's `evaluate` (all local
//! cores: [`Problem::evaluate_all`]; a cluster: the Python bindings' executors), in batches
//! whose results do not depend on how they are split: local, Dask and Ray agree bit for bit.

use alloc::vec::Vec;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::Program;
use super::job::Job;
use super::spin::{self, LoadPath, SpinOptions};
use crate::error::{BuildError, JobError};

/// Most candidates of a grid: 2^20.
pub const MAX_GRID: usize = 1 << 20;
/// Most refinement rounds: 30 (a spacing 1e-9 of the grid's).
pub const MAX_REFINE: usize = 30;
/// Largest box coordinate \[m\]: 1 km.
pub const MAX_BOX: f64 = 1.0e3;

/// A placement: the workpiece origin `x, y, z` \[m\] in the base frame and the turn `yaw`
/// \[rad\] about the base's vertical (the job's own placement's rotation turned by it).
pub type Params = [f64; 4];

/// The box a placement is searched in, and the grid over it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlacementBox {
    /// Lower corner `x, y, z` \[m\], then the lowest `yaw` \[rad\].
    pub min: Params,
    /// Upper corner and highest yaw.
    pub max: Params,
    /// Grid points per axis (>= 1; 1: the middle).
    pub steps: [usize; 4],
}

impl PlacementBox {
    /// Checks the box (finite, `min <= max`, within [`MAX_BOX`] and a turn each way) and the
    /// grid's size (at most [`MAX_GRID`]).
    pub fn validate(&self) -> Result<(), BuildError> {
        for (index, (lo, hi)) in self.min.iter().zip(&self.max).enumerate() {
            let bound = if index < 3 {
                MAX_BOX
            } else {
                core::f64::consts::TAU
            };
            if !(lo.is_finite()
                && hi.is_finite()
                && lo <= hi
                && lo.abs() <= bound
                && hi.abs() <= bound)
            {
                return Err(BuildError::InvalidEntry {
                    what: "placement box (x, y, z in m within 1 km, yaw in rad within a turn; min <= max)",
                    index,
                    value: hi - lo,
                    expected: ">= 0 (max - min), both ends finite and in range",
                });
            }
        }
        let mut n = 1usize;
        for (index, &s) in self.steps.iter().enumerate() {
            if s == 0 {
                return Err(BuildError::InvalidEntry {
                    what: "placement grid points per axis",
                    index,
                    value: 0.0,
                    expected: ">= 1",
                });
            }
            n = n.saturating_mul(s);
        }
        if n > MAX_GRID {
            return Err(BuildError::Budget {
                what: "placement grid (points per axis multiplied)",
                budget: "MAX_GRID",
                limit: MAX_GRID,
                requested: n,
            });
        }
        Ok(())
    }

    /// The grid spacing per axis (0 for an axis of one point).
    pub fn spacing(&self) -> Params {
        let mut h = [0.0; 4];
        for (i, h) in h.iter_mut().enumerate() {
            let n = self.steps.get(i).copied().unwrap_or(1);
            let (lo, hi) = (
                self.min.get(i).copied().unwrap_or(0.0),
                self.max.get(i).copied().unwrap_or(0.0),
            );
            *h = if n > 1 {
                (hi - lo) / (n - 1) as f64
            } else {
                0.0
            };
        }
        h
    }

    /// The grid's points, x fastest, then y, z, yaw.
    pub fn grid(&self) -> Vec<Params> {
        let h = self.spacing();
        let [nx, ny, nz, nw] = self.steps;
        let at = |i: usize, k: usize| {
            let (lo, hi) = (
                self.min.get(i).copied().unwrap_or(0.0),
                self.max.get(i).copied().unwrap_or(0.0),
            );
            let n = self.steps.get(i).copied().unwrap_or(1);
            if n > 1 {
                lo + h.get(i).copied().unwrap_or(0.0) * k as f64
            } else {
                0.5 * (lo + hi)
            }
        };
        let mut out = Vec::new();
        for w in 0..nw {
            for z in 0..nz {
                for y in 0..ny {
                    for x in 0..nx {
                        out.push([at(0, x), at(1, y), at(2, z), at(3, w)]);
                    }
                }
            }
        }
        out
    }
}

/// How a placement scores.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Score {
    /// RMS of the measure over the cutting samples \[m\]; infinity where the arm cannot
    /// follow the program.
    pub rms: f64,
    /// The largest \[m\] (infinity likewise).
    pub max: f64,
    /// The program line where the arm could not follow it (0 where it can).
    pub line: usize,
}

impl Score {
    /// Whether the arm follows the program there.
    pub fn feasible(&self) -> bool {
        self.rms.is_finite()
    }
}

/// A placement search's problem: the job, the program's loads, the seed, the spin.
#[derive(Debug, Clone)]
pub struct Problem {
    job: Job,
    loads: LoadPath,
    seed: Vec<f64>,
    spin: SpinOptions,
    optimise: bool,
}

impl Problem {
    /// The problem of `job` (its placement's rotation is the one `yaw` turns) over `program`
    /// from the joints `seed`, the spin optimised along the program (`optimise`) or the
    /// seed's spin, both as `spin` says (its step and rates place the stations either way).
    /// Runs the nominal pass once.
    pub fn new(
        job: Job,
        program: &Program,
        seed: &[f64],
        spin: SpinOptions,
        optimise: bool,
    ) -> Result<Self, JobError> {
        spin.validate()?;
        crate::machining::job::check_seed(&job, seed)?;
        let loads = LoadPath::new(&job, program, spin.step, spin.per_metre, spin.per_second)?;
        Ok(Self::from_parts(job, loads, seed.to_vec(), spin, optimise))
    }

    /// A problem of its parts (a worker's copy: see [`Self::loads`]).
    pub fn from_parts(
        job: Job,
        loads: LoadPath,
        seed: Vec<f64>,
        spin: SpinOptions,
        optimise: bool,
    ) -> Self {
        Self {
            job,
            loads,
            seed,
            spin,
            optimise,
        }
    }

    /// The job.
    pub fn job(&self) -> &Job {
        &self.job
    }

    /// The program's loads and stations.
    pub fn loads(&self) -> &LoadPath {
        &self.loads
    }

    /// The seed joints.
    pub fn seed(&self) -> &[f64] {
        &self.seed
    }

    /// The spin options, and whether the spin is optimised.
    pub fn spin(&self) -> (SpinOptions, bool) {
        (self.spin, self.optimise)
    }

    /// The workpiece frame of a placement: its origin at `x, y, z`, the job's rotation
    /// turned by `yaw` about the base's vertical.
    pub fn placement(&self, p: &Params) -> Isometry3<f64> {
        let base = self.job.setup().placement.rotation;
        Isometry3::from_parts(
            Translation3::new(p[0], p[1], p[2]),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), p[3]) * base,
        )
    }

    /// The score of one placement (infinite where the arm cannot follow the program).
    pub fn evaluate(&self, p: &Params) -> Score {
        let placement = self.placement(p);
        match spin::plan_at(
            &self.job,
            &placement,
            &self.loads,
            &self.seed,
            &self.spin,
            self.optimise,
        ) {
            Ok(plan) => {
                let c = if self.optimise {
                    Some(plan.optimised)
                } else {
                    plan.seed
                };
                match c {
                    Some(c) => Score {
                        rms: c.rms,
                        max: c.max,
                        line: 0,
                    },
                    None => Score {
                        rms: f64::INFINITY,
                        max: f64::INFINITY,
                        line: plan.stations,
                    },
                }
            }
            Err(e) => Score {
                rms: f64::INFINITY,
                max: f64::INFINITY,
                line: e.line().unwrap_or(0).max(1),
            },
        }
    }

    /// The scores of `params`, in order, on `threads` threads (each placement on one: the
    /// result does not depend on the count).
    #[cfg(feature = "std")]
    pub fn evaluate_all(&self, params: &[Params], threads: usize) -> Vec<Score> {
        let threads = threads.clamp(1, 256).min(params.len().max(1));
        if threads == 1 {
            return params.iter().map(|p| self.evaluate(p)).collect();
        }
        let next = core::sync::atomic::AtomicUsize::new(0);
        let mut out = alloc::vec![Score { rms: f64::NAN, max: f64::NAN, line: 0 }; params.len()];
        let parts: Vec<Vec<(usize, Score)>> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..threads)
                .map(|_| {
                    scope.spawn(|| {
                        let mut mine = Vec::new();
                        loop {
                            let i = next.fetch_add(1, core::sync::atomic::Ordering::Relaxed);
                            let Some(p) = params.get(i) else {
                                break;
                            };
                            mine.push((i, self.evaluate(p)));
                        }
                        mine
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_default())
                .collect()
        });
        for (i, s) in parts.into_iter().flatten() {
            if let Some(o) = out.get_mut(i) {
                *o = s;
            }
        }
        out
    }
}

/// What [`search`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Search {
    /// The grid's points and scores, in [`PlacementBox::grid`]'s order.
    pub grid: Vec<(Params, Score)>,
    /// The best placement and its score (after the refinement).
    pub best: (Params, Score),
    /// Placements evaluated.
    pub evaluations: usize,
}

/// Whether `a` scores better than `b` (a smaller RMS; ties to the earlier).
fn better(a: &Score, b: &Score) -> bool {
    a.rms < b.rms
}

/// Searches `bx` (see the module docs) with `refine` rounds of the compass search, each
/// batch of placements scored by `evaluate` (in order). [`BuildError`]s of the box; a box
/// where no grid point follows the program is [`JobError::AtLine`]-free
/// [`BuildError::InvalidParameter`] ("a placement box outside reach"); `evaluate`'s errors.
pub fn search<E>(
    bx: &PlacementBox,
    refine: usize,
    mut evaluate: impl FnMut(&[Params]) -> Result<Vec<Score>, E>,
) -> Result<Result<Search, BuildError>, E> {
    if let Err(e) = bx.validate() {
        return Ok(Err(e));
    }
    if refine > MAX_REFINE {
        return Ok(Err(BuildError::InvalidParameter {
            what: "placement refinement rounds",
            value: refine as f64,
            expected: "at most MAX_REFINE (30)",
        }));
    }
    let points = bx.grid();
    let scores = evaluate(&points)?;
    let mut evaluations = points.len();
    let grid: Vec<(Params, Score)> = points.into_iter().zip(scores).collect();
    let mut best: Option<(Params, Score)> = None;
    for (p, s) in &grid {
        if s.feasible() && best.as_ref().is_none_or(|(_, b)| better(s, b)) {
            best = Some((*p, *s));
        }
    }
    let Some(mut best) = best else {
        return Ok(Err(BuildError::InvalidParameter {
            what: "placement box (no grid point lets the arm follow the program: outside reach, \
                   the joint limits or the singularity margin)",
            value: grid.len() as f64,
            expected: "a box the arm reaches the program from",
        }));
    };
    let mut h = bx.spacing();
    for _ in 0..refine {
        for v in h.iter_mut() {
            *v *= 0.5;
        }
        let mut around = Vec::new();
        for axis in 0..4 {
            let step = h.get(axis).copied().unwrap_or(0.0);
            if step <= 0.0 {
                continue;
            }
            for sign in [-1.0, 1.0] {
                let mut p = best.0;
                if let (Some(v), Some(lo), Some(hi)) =
                    (p.get_mut(axis), bx.min.get(axis), bx.max.get(axis))
                {
                    *v = (*v + sign * step).clamp(*lo, *hi);
                }
                if p != best.0 {
                    around.push(p);
                }
            }
        }
        if around.is_empty() {
            break;
        }
        let scores = evaluate(&around)?;
        evaluations += around.len();
        for (p, s) in around.into_iter().zip(scores) {
            if s.feasible() && better(&s, &best.1) {
                best = (p, s);
            }
        }
    }
    Ok(Ok(Search {
        grid,
        best,
        evaluations,
    }))
}
