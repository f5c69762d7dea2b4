//! The shortest path over stations x candidate spins (see the parent's docs). Costs within
//! [`TIE`] of each other count as equal; ties go to the smaller change of spin, and at the end
//! to the spin nearest the seed's.

use alloc::vec;
use alloc::vec::Vec;

use nalgebra::{Isometry3, Matrix3, SMatrix, Translation3};

use super::loads::{Load, LoadPath, Station};
use super::{SpinCost, SpinOptions, SpinPlan, SpinSchedule};
use crate::error::{BuildError, JobError, TickError};
use crate::machining::job::Job;
use crate::mechanism::pose_ik;
use crate::vjm::{self, Data, Load as VjmLoad, MAX_DOF, Vector6};

/// One node (a station's candidate): its joints, whether they hold, its cost, its largest
/// measure, and the least cost of a path to it.
#[derive(Debug, Clone, Copy)]
struct Node {
    q: [f64; MAX_DOF],
    ok: bool,
    cost: f64,
    max: f64,
    value: f64,
}

impl Default for Node {
    fn default() -> Self {
        Self {
            q: [0.0; MAX_DOF],
            ok: false,
            cost: 0.0,
            max: 0.0,
            value: f64::INFINITY,
        }
    }
}

/// A constant spin along the program: its summed cost, its largest measure, whether every
/// node of it holds, linked to the one before.
#[derive(Debug, Clone, Copy)]
struct Column {
    sum: f64,
    max: f64,
    ok: bool,
}

/// Costs within this share of each other are equal: the spin changes for a real gain, not
/// for the rounding of an arm whose deflection the spin does not change (a SCARA's).
const TIE: f64 = 1.0e-9;

/// Whether cost `a` is below `b` by more than [`TIE`] of `b`.
fn less(a: f64, b: f64) -> bool {
    if b.is_finite() {
        a < b - TIE * b.abs()
    } else {
        a < b
    }
}

/// The largest joint difference \[rad or m\].
fn gap(a: &[f64; MAX_DOF], b: &[f64; MAX_DOF], dof: usize) -> f64 {
    a.iter()
        .zip(b)
        .take(dof)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The candidates in the order they are solved: the seed's spin, then outwards each way;
/// with each, the neighbour towards the seed's spin it may start from.
fn order(k: usize) -> Vec<(usize, Option<usize>)> {
    let c = k / 2;
    let mut out = vec![(c, None)];
    for j in c + 1..k {
        out.push((j, Some(j - 1)));
    }
    for j in (0..c).rev() {
        out.push((j, Some(j + 1)));
    }
    out
}

/// What a node solve needs and keeps.
struct Solver<'a> {
    job: &'a Job,
    placement: Isometry3<f64>,
    options: &'a SpinOptions,
    ik: crate::mechanism::PoseIkOptions,
    data: Data,
    dof: usize,
    refused: usize,
    last_error: Option<TickError>,
}

impl<'a> Solver<'a> {
    /// The solver for `job`'s arm (of `dof` joints) with the workpiece at `placement`, its
    /// pose IK held to `options`' singularity margin.
    fn new(job: &'a Job, placement: &Isometry3<f64>, options: &'a SpinOptions, dof: usize) -> Self {
        let mut ik = job.setup().ik;
        ik.min_sigma = options.min_sigma;
        Self {
            job,
            placement: *placement,
            options,
            ik,
            data: Data::new(job.model()),
            dof,
            refused: 0,
            last_error: None,
        }
    }

    /// The joints of spin `theta` at `position` from `seed`, if they hold (limits less the
    /// margin, the singularity margin, within the joint step of `seed` unless it is the
    /// user's seed: a branch hint, not a neighbour).
    fn joints(
        &mut self,
        position: &nalgebra::Vector3<f64>,
        axis: &nalgebra::Vector3<f64>,
        theta: f64,
        seed: &[f64; MAX_DOF],
        neighbour: bool,
    ) -> Option<[f64; MAX_DOF]> {
        let setup = self.job.setup();
        let tilted = match crate::machining::five_axis::orientation(&setup.tool_orientation, axis) {
            Ok(r) => r,
            Err(e) => {
                self.last_error = Some(e);
                return None;
            }
        };
        let target = self.placement
            * Isometry3::from_parts(
                Translation3::from(*position),
                SpinSchedule::turn(&tilted, theta),
            );
        let model = self.job.model();
        let solved = pose_ik(
            model,
            &mut self.data,
            &target,
            seed.get(..self.dof).unwrap_or(&[]),
            &Vector6::zeros(),
            VjmLoad::Rigid,
            &self.ik,
        );
        let q = match solved {
            Ok(s) => s.q,
            Err(e) => {
                self.last_error = Some(e);
                return None;
            }
        };
        let margin = self.options.limit_margin;
        let inside = q
            .iter()
            .zip(self.job.limits())
            .all(|(q, (lo, hi))| *q >= lo + margin && *q <= hi - margin);
        if !inside {
            self.last_error = Some(TickError::InvalidArgument {
                what: "spin: joints within the limits less the margin",
                value: theta,
            });
            return None;
        }
        if neighbour && gap(&q, seed, self.dof) > self.options.max_joint_step {
            self.last_error = Some(TickError::InvalidArgument {
                what: "spin: joints on the branch they started from (a jump)",
                value: theta,
            });
            return None;
        }
        Some(q)
    }

    /// The joints of spin `theta` at station `st` from `seed` (see [`Self::joints`]) and
    /// their deflection map, if they hold; the failure kept in `last_error` otherwise.
    #[inline]
    fn node(
        &mut self,
        st: &Station,
        theta: f64,
        seed: &[f64; MAX_DOF],
        neighbour: bool,
    ) -> Option<([f64; MAX_DOF], SMatrix<f64, 3, 6>)> {
        self.joints(&st.position, &st.axis, theta, seed, neighbour)
            .and_then(|q| match self.map(&q) {
                Ok(a) => Some((q, a)),
                Err(e) => {
                    self.last_error = Some(e);
                    None
                }
            })
    }

    /// The deflection map of joints `q`: `A` (3 x 6) with `dp = A w`, workpiece frame.
    fn map(&mut self, q: &[f64; MAX_DOF]) -> Result<SMatrix<f64, 3, 6>, TickError> {
        let c = vjm::compliance(
            self.job.model(),
            &mut self.data,
            q.get(..self.dof).unwrap_or(&[]),
        )?;
        let r: Matrix3<f64> = self.placement.rotation.to_rotation_matrix().into_inner();
        let rt = r.transpose();
        let mut a = SMatrix::<f64, 3, 6>::zeros();
        let tt = rt * c.fixed_view::<3, 3>(0, 0) * r;
        let tr = rt * c.fixed_view::<3, 3>(0, 3) * r;
        a.fixed_view_mut::<3, 3>(0, 0).copy_from(&tt);
        a.fixed_view_mut::<3, 3>(0, 3).copy_from(&tr);
        Ok(a)
    }
}

/// A node's cost and largest measure over its loads (weights `w` before, `1 - w` after).
fn cost(
    options: &SpinOptions,
    a: &SMatrix<f64, 3, 6>,
    before: &[Load],
    after: &[Load],
) -> (f64, f64) {
    let (mut sum, mut max) = (0.0f64, 0.0f64);
    let mut add = |l: &Load, weight: f64| {
        let m = options.measure.of(&(a * l.wrench()), &l.direction());
        sum += weight * m * m;
        max = max.max(m);
    };
    for l in before {
        add(l, f64::from(l.weight));
    }
    for l in after {
        add(l, 1.0 - f64::from(l.weight));
    }
    (sum, max)
}

/// The least cost of a path to each node of `cur` from the nodes of `prev` (at most `steps`
/// candidates away, joints within `max_step`; ties to the smaller change of spin), each
/// node's predecessor pushed onto `parent` (the first station's nodes start paths).
fn link(
    cur: &mut [Node],
    prev: &[Node],
    first: bool,
    steps: usize,
    max_step: f64,
    dof: usize,
    parent: &mut Vec<u16>,
) {
    let k = cur.len();
    for (j, node) in cur.iter_mut().enumerate() {
        node.value = f64::INFINITY;
        let mut from = j;
        if node.ok && first {
            node.value = node.cost;
        } else if node.ok {
            let mut best = (f64::INFINITY, usize::MAX);
            let (lo, hi) = (
                j.saturating_sub(steps),
                (j + steps).min(k.saturating_sub(1)),
            );
            for (jp, p) in prev.iter().enumerate().take(hi + 1).skip(lo) {
                let links = p.ok && p.value.is_finite() && gap(&node.q, &p.q, dof) <= max_step;
                let better = less(p.value, best.0)
                    || (!less(best.0, p.value) && jp.abs_diff(j) < best.1.abs_diff(j));
                if links && better {
                    best = (p.value, jp);
                }
            }
            if best.1 != usize::MAX {
                node.value = best.0 + node.cost;
                from = best.1;
            }
        }
        parent.push(u16::try_from(from).unwrap_or(u16::MAX));
    }
}

/// [`plan_at`] at the job's own placement, optimising.
pub fn plan(
    job: &Job,
    loads: &LoadPath,
    seed: &[f64],
    options: &SpinOptions,
) -> Result<SpinPlan, JobError> {
    plan_at(job, &job.setup().placement, loads, seed, options, true)
}

/// The spin schedule of least predicted deflection for `job`'s arm with the workpiece at
/// `placement` (the job's own, or a candidate of a placement search), from the joints `seed`
/// near the first station (they pick the IK branch), over the stations and loads of `loads`
/// (built for `options`' step and rates). With `optimise` false only the seed's spin is
/// followed (what a placement search without spin optimisation evaluates). Errors name the
/// station's line where no candidate holds.
pub fn plan_at(
    job: &Job,
    placement: &Isometry3<f64>,
    loads: &LoadPath,
    seed: &[f64],
    options: &SpinOptions,
    optimise: bool,
) -> Result<SpinPlan, JobError> {
    options.validate()?;
    check_loads(loads, options)?;
    let dof = job.model().dof();
    crate::machining::job::check_seed(job, seed)?;
    let job = &*job.at_seed(seed)?;
    let candidates = if optimise {
        options.candidates()
    } else {
        vec![0.0]
    };
    let stations = loads.stations();
    let n = stations.len();
    let mut solver = Solver::new(job, placement, options, dof);
    let mut user_seed = [0.0; MAX_DOF];
    for (d, s) in user_seed.iter_mut().zip(seed) {
        *d = *s;
    }
    let mut search = Search::new(candidates, n)?;
    let mut budget_prev = 0.0;
    for (i, st) in stations.iter().enumerate() {
        search.solve(&mut solver, i, st, loads.around(i), &user_seed);
        // The steps the budget since the last station allows.
        let steps = if i == 0 {
            0
        } else {
            nalgebra::ComplexField::floor(((st.budget - budget_prev) / options.step) + 1e-9)
                .clamp(0.0, search.k() as f64) as usize
        };
        budget_prev = st.budget;
        search.link(i, steps, options.max_joint_step, dof);
        if search.cur.iter().all(|c| !c.value.is_finite()) {
            return Err(JobError::AtLine {
                line: st.line,
                time: st.time,
                error: solver.last_error.unwrap_or(TickError::InvalidArgument {
                    what: "spin: no candidate linked to the station before",
                    value: st.time,
                }),
            });
        }
        core::mem::swap(&mut search.prev, &mut search.cur);
    }
    let end = search.end();
    let (spins, largest) = search.backtrack(end.1, n);
    let loaded = loads.loads.len().max(1) as f64;
    let rms = |sum: f64| nalgebra::ComplexField::sqrt(sum / loaded);
    let best_constant = search.best_constant(&rms);
    let seed_cost = search
        .columns
        .get(search.center)
        .filter(|c| c.ok)
        .map(|c| SpinCost {
            rms: rms(c.sum),
            max: c.max,
        });
    let budgets = stations.iter().map(|s| s.budget).collect();
    Ok(SpinPlan {
        schedule: SpinSchedule::new(budgets, spins, options.per_metre, options.per_second)?,
        optimised: SpinCost {
            rms: rms(end.0),
            max: largest,
        },
        seed: seed_cost,
        best_constant,
        candidates: search.candidates,
        stations: n,
        refused: solver.refused,
        measure: options.measure,
    })
}

/// Refuses `loads` built for another candidate step or other rate bounds than `options`'.
fn check_loads(loads: &LoadPath, options: &SpinOptions) -> Result<(), BuildError> {
    if loads.step != options.step
        || loads.per_metre != options.per_metre
        || loads.per_second != options.per_second
    {
        return Err(BuildError::InvalidParameter {
            what: "spin loads (built for another candidate step or rate bounds)",
            value: loads.step,
            expected: "the options' step and rates",
        });
    }
    Ok(())
}

/// The search's state over the stations: the candidate spins \[rad\] and their solve order,
/// the nodes of the station before and of this one, each node's predecessor and largest
/// measure (station-major, a row of candidates per station), and the constant spins.
struct Search {
    candidates: Vec<f64>,
    /// The seed's spin's index in `candidates`.
    center: usize,
    solve_order: Vec<(usize, Option<usize>)>,
    prev: Vec<Node>,
    cur: Vec<Node>,
    parent: Vec<u16>,
    node_max: Vec<f32>,
    columns: Vec<Column>,
}

impl Search {
    /// The state for `n` stations of `candidates` ([`BuildError::Budget`] when the nodes'
    /// allocation is refused).
    fn new(candidates: Vec<f64>, n: usize) -> Result<Self, BuildError> {
        let k = candidates.len();
        let center = k / 2;
        let prev = vec![Node::default(); k];
        let cur = vec![Node::default(); k];
        let mut parent: Vec<u16> = Vec::new();
        let mut node_max: Vec<f32> = Vec::new();
        if parent.try_reserve_exact(n * k).is_err() || node_max.try_reserve_exact(n * k).is_err() {
            return Err(BuildError::Budget {
                what: "spin search nodes (the allocation was refused)",
                budget: "MAX_STATIONS",
                limit: super::MAX_STATIONS,
                requested: n,
            });
        }
        let columns = vec![
            Column {
                sum: 0.0,
                max: 0.0,
                ok: true,
            };
            k
        ];
        let solve_order = order(k);
        Ok(Self {
            candidates,
            center,
            solve_order,
            prev,
            cur,
            parent,
            node_max,
            columns,
        })
    }

    /// How many candidate spins.
    #[inline]
    fn k(&self) -> usize {
        self.candidates.len()
    }

    /// Station `i`'s nodes (at `st`, its loads before and after) solved into `cur` in the
    /// solve order, each from the station before's node of its spin, else its neighbour
    /// towards the seed's spin, else (the first station's seed spin) the user's `seed`.
    #[inline]
    fn solve(
        &mut self,
        solver: &mut Solver<'_>,
        i: usize,
        st: &Station,
        (before, after): (&[Load], &[Load]),
        user_seed: &[f64; MAX_DOF],
    ) {
        for &(j, towards) in &self.solve_order {
            let theta = self.candidates.get(j).copied().unwrap_or(0.0);
            let from_prev = self.prev.get(j).filter(|p| i > 0 && p.ok).map(|p| p.q);
            let from_neighbour = towards
                .and_then(|nb| self.cur.get(nb))
                .filter(|c| c.ok)
                .map(|c| c.q);
            let start = match (from_prev, from_neighbour, i, j == self.center) {
                (Some(q), _, _, _) | (None, Some(q), _, _) => Some((q, true)),
                (None, None, 0, true) => Some((*user_seed, false)),
                _ => None,
            };
            let node = start.and_then(|(s, neighbour)| solver.node(st, theta, &s, neighbour));
            let Some(slot) = self.cur.get_mut(j) else {
                continue;
            };
            *slot = Node::default();
            match node {
                Some((q, a)) => {
                    let (c, m) = cost(solver.options, &a, before, after);
                    *slot = Node {
                        q,
                        ok: true,
                        cost: c,
                        max: m,
                        value: f64::INFINITY,
                    };
                }
                None => solver.refused += 1,
            }
        }
    }

    /// Station `i`'s nodes linked to the station before's (at most `steps` candidates away,
    /// joints within `max_step`), their largest measures kept and the constant spins
    /// extended.
    #[inline]
    fn link(&mut self, i: usize, steps: usize, max_step: f64, dof: usize) {
        link(
            &mut self.cur,
            &self.prev,
            i == 0,
            steps,
            max_step,
            dof,
            &mut self.parent,
        );
        for ((node, column), p) in self.cur.iter().zip(self.columns.iter_mut()).zip(&self.prev) {
            self.node_max.push(node.max as f32);
            // The constant spin: every node holds, linked to the one before.
            let linked = i == 0 || (p.ok && gap(&node.q, &p.q, dof) <= max_step);
            column.ok = column.ok && node.ok && linked;
            column.sum += node.cost;
            column.max = column.max.max(node.max);
        }
    }

    /// The end of the path (the last station's nodes, in `prev` after the swap): the least
    /// cost and its candidate, the smallest spin on a tie.
    fn end(&self) -> (f64, usize) {
        let center = self.center;
        let mut end = (f64::INFINITY, center);
        for (j, node) in self.prev.iter().enumerate() {
            let v = node.value;
            if less(v, end.0) || (!less(end.0, v) && j.abs_diff(center) < end.1.abs_diff(center)) {
                end = (v, j);
            }
        }
        end
    }

    /// The spins \[rad\] of the `n` stations along the path ending at candidate `j`, and the
    /// largest measure on it.
    fn backtrack(&self, mut j: usize, n: usize) -> (Vec<f64>, f64) {
        let k = self.k();
        let mut spins = vec![0.0; n];
        let mut largest = 0.0f64;
        for (i, spin) in spins.iter_mut().enumerate().rev() {
            *spin = self.candidates.get(j).copied().unwrap_or(0.0);
            largest = largest.max(f64::from(
                self.node_max.get(i * k + j).copied().unwrap_or(0.0),
            ));
            j = usize::from(self.parent.get(i * k + j).copied().unwrap_or(0));
        }
        (spins, largest)
    }

    /// The constant spin of least cost among those that hold throughout (the smallest spin
    /// on a tie), with its cost (`rms` of a summed cost).
    fn best_constant(&self, rms: &dyn Fn(f64) -> f64) -> Option<(f64, SpinCost)> {
        let center = self.center;
        self.columns
            .iter()
            .zip(&self.candidates)
            .enumerate()
            .filter(|(_, (c, _))| c.ok)
            .min_by(|(a, (ca, _)), (b, (cb, _))| {
                if less(ca.sum, cb.sum) {
                    core::cmp::Ordering::Less
                } else if less(cb.sum, ca.sum) {
                    core::cmp::Ordering::Greater
                } else {
                    a.abs_diff(center).cmp(&b.abs_diff(center))
                }
            })
            .map(|(_, (c, angle))| {
                (
                    *angle,
                    SpinCost {
                        rms: rms(c.sum),
                        max: c.max,
                    },
                )
            })
    }
}
