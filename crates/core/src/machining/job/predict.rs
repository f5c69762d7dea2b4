//! Stages 2 and 3 of the pass, one per arm: the joints (rigid pose IK for the uncompensated
//! arm, loaded pose IK for the compensated one, each warm-started from the joints of the
//! last two samples) and the prediction of where that arm's tool goes and what it cuts: the
//! fixed point of the force-deflection coupling on the arm's own stock (see the parent's
//! docs). The two arms do not share state: with two threads they run side by side.

use alloc::vec::Vec;

use nalgebra::{Isometry3, Matrix3, Matrix6, Point3, Translation3, Vector3};

use super::inertia::{self, Motion};
use super::nominal::Sample;
use super::warm::Warm;
use super::{
    COUPLING_TOLERANCE, Job, MAX_COUPLING_ITERATIONS, RunOptions, ToolModels, chip_wrench,
    engagement, rotate,
};
use crate::error::{JobError, TickError};
use crate::machining::Program;
use crate::machining::engagement::Chip;
use crate::machining::path;
use crate::machining::spin::{Cursor, SpinSchedule};
use crate::machining::stock::{Follower, ZMap};
use crate::vjm::{self, Data, Load, MAX_DOF, Vector6};

/// A correction of the linear coupling step \[m\] past which the arm's deflection is
/// evaluated exactly again: the linear model's error is below 1e-3 of the step at the
/// springs' small angles, so the coupling's steps stay exact to about 1e-8 m.
const RELINEARISE: f64 = 1.0e-5;

/// How an arm's chunk ended: the index and error of the first sample that failed.
pub(super) type Outcome = Result<(), (usize, JobError)>;

/// What one arm gives for one sample.
#[derive(Debug, Clone, Copy)]
pub(super) struct Out {
    /// The arm's joints (rigid IK or compensated) \[rad or m\].
    pub q: [f64; MAX_DOF],
    /// Deflection of the tip at the rigid joints under the nominal wrench (uncompensated arm
    /// only; zero for the other).
    pub deflection: Vector6,
    /// The payload's D'Alembert wrench, base frame (zero without the job's inertia).
    pub inertial_wrench: Vector6,
    /// Deflection of the tip at the rigid joints under the inertial loads alone
    /// (uncompensated arm with the job's inertia; zero otherwise).
    pub deflection_inertial: Vector6,
    /// The rigid pose at the joints, workpiece frame (the compensated arm's command).
    pub commanded: Isometry3<f64>,
    /// The predicted tip \[m\], workpiece frame.
    pub tip: Vector3<f64>,
    /// The force the tool feels there \[N\], workpiece frame.
    pub force: Vector3<f64>,
    /// The coupling's last step \[m\].
    pub residual: f64,
    /// The spin about the tool axis \[rad\].
    pub spin: f64,
}

pub(super) struct Arm<'a> {
    job: &'a Job,
    program: &'a Program,
    /// The last sample's move, fraction on it and programmed point \[m\].
    prev_at: Option<(usize, f64, Vector3<f64>)>,
    tools: &'a ToolModels,
    compensated: bool,
    data: Data,
    q: [f64; MAX_DOF],
    warm: Warm,
    to_base: Isometry3<f64>,
    to_work: Isometry3<f64>,
    pub stock: ZMap,
    tip: Option<Vector3<f64>>,
    /// How far the last tip moved beyond the programmed step \[m\] (the change of the
    /// deflection): the next sample's first guess repeats it.
    drift: Vector3<f64>,
    follower: Follower,
    chip: Chip,
    pub cell_updates: usize,
    spin: Cursor,
    /// The sample's inertial loads (with the job's inertia).
    motion: Option<Motion>,
}

impl<'a> Arm<'a> {
    /// `seed` has the model's dof (checked by the caller).
    pub fn new(
        job: &'a Job,
        program: &'a Program,
        tools: &'a ToolModels,
        stock: ZMap,
        seed: &[f64],
        compensated: bool,
    ) -> Self {
        let mut q = [0.0; MAX_DOF];
        for (d, s) in q.iter_mut().zip(seed) {
            *d = *s;
        }
        Self {
            job,
            program,
            prev_at: None,
            tools,
            compensated,
            data: Data::new(&job.model),
            q,
            warm: Warm::new(seed),
            to_base: job.setup.placement,
            to_work: job.setup.placement.inverse(),
            stock,
            tip: None,
            drift: Vector3::zeros(),
            follower: Follower::new(),
            chip: Chip::default(),
            cell_updates: 0,
            spin: Cursor::default(),
            motion: None,
        }
    }

    /// Every sample of a chunk, into `out`; the index and error of the first that fails.
    pub fn process(
        &mut self,
        noms: &[Sample],
        out: &mut Vec<Out>,
    ) -> Result<(), (usize, JobError)> {
        for (k, n) in noms.iter().enumerate() {
            match self.advance(n) {
                Ok(o) => out.push(o),
                Err(error) => {
                    return Err((
                        k,
                        JobError::AtLine {
                            line: n.path.line,
                            time: n.path.time,
                            error,
                        },
                    ));
                }
            }
        }
        Ok(())
    }

    /// Cuts what the follower holds back (before the stock is handed on).
    pub fn flush(&mut self) -> Result<(), TickError> {
        self.cell_updates += self.follower.flush(&mut self.stock)?.cells;
        Ok(())
    }

    /// The joints at one sample (see [`Warm::solve`]).
    fn joints(&mut self, n: &Sample, spin: f64) -> Result<(), TickError> {
        let job = self.job;
        let setup = &job.setup;
        let orientation = if spin == 0.0 {
            setup.tool_orientation
        } else {
            SpinSchedule::turn(&setup.tool_orientation, spin)
        };
        let target =
            self.to_base * Isometry3::from_parts(Translation3::from(n.path.position), orientation);
        self.motion = job.inertia.as_ref().map(|i| {
            let state = inertia::pose_state(&self.to_base.rotation, &n.path, &target);
            Motion::new(i, state)
        });
        let (model, ik, dof) = (&job.model, &job.setup.ik, job.model.dof());
        match (&mut self.motion, self.compensated) {
            (None, true) => {
                self.warm
                    .solve(job, &mut self.data, &target, &n.wrench, Load::Exact)?;
            }
            (None, false) => {
                self.warm
                    .solve(job, &mut self.data, &target, &Vector6::zeros(), Load::Rigid)?;
            }
            (Some(m), true) => {
                // The link loads' joint rates at the warm start; at the solution again when it
                // moved away (as the serial corrector's tick does).
                let seed = self.warm.seed(dof);
                m.rates_at(model, &mut self.data, ik, seed.get(..dof).unwrap_or(&[]))?;
                let wrench = n.wrench + m.wrench;
                self.warm
                    .solve(job, &mut self.data, &target, &wrench, m.load(model))?;
                let moved = self
                    .warm
                    .q
                    .iter()
                    .zip(&seed)
                    .take(dof)
                    .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
                if m.has_links(model) && moved > crate::dalembert::serial::RATE_REFRESH {
                    let q = self.warm.q;
                    m.rates_at(model, &mut self.data, ik, q.get(..dof).unwrap_or(&[]))?;
                    self.warm
                        .refine(job, &mut self.data, &target, &wrench, m.load(model))?;
                }
            }
            (Some(m), false) => {
                self.warm
                    .solve(job, &mut self.data, &target, &Vector6::zeros(), Load::Rigid)?;
                let q = self.warm.q;
                m.rates_at(model, &mut self.data, ik, q.get(..dof).unwrap_or(&[]))?;
            }
        }
        self.q = self.warm.q;
        Ok(())
    }

    fn advance(&mut self, n: &Sample) -> Result<Out, TickError> {
        let spin = match &self.job.spin {
            Some(schedule) => self.spin.advance(schedule, &n.step, n.path.time),
            None => 0.0,
        };
        self.joints(n, spin)?;
        if n.settled {
            self.flush()?;
        }
        let job = self.job;
        let model = &job.model;
        let q = self.q;
        let qs = q.get(..job.model.dof()).unwrap_or(&[]);
        // The loaded tip under the nominal wrench: the coupling's first anchor.
        let (deflection, commanded, deflection_inertial) = if self.compensated {
            // The loaded IK's last pass: the rigid pose to command, the loaded one on target.
            (
                Vector6::zeros(),
                self.to_work * self.data.tcp,
                Vector6::zeros(),
            )
        } else {
            let d = vjm::deflection(model, &mut self.data, qs, &n.wrench, Load::Exact)?;
            let di = match &self.motion {
                Some(m) => {
                    let di = vjm::deflection(model, &mut self.data, qs, &m.wrench, m.load(model))?;
                    // Both parts in one deflection: the coupling's first anchor.
                    let w = n.wrench + m.wrench;
                    vjm::deflection(model, &mut self.data, qs, &w, m.load(model))?;
                    di
                }
                None => Vector6::zeros(),
            };
            (d, Isometry3::identity(), di)
        };
        let tip_at = |data: &Data, to_work: &Isometry3<f64>| {
            (to_work * Point3::from(data.tcp_deflected.translation.vector)).coords
        };
        let (inertial_wrench, anchor_wrench) = match &self.motion {
            Some(m) => (m.wrench, n.wrench + m.wrench),
            None => (Vector6::zeros(), n.wrench),
        };
        let anchor = (anchor_wrench, tip_at(&self.data, &self.to_work));
        let (tip, force, residual) = self.couple(n, qs, anchor)?;
        let Some(tm) = self.tools.get(n.tool) else {
            return Err(TickError::InvalidArgument {
                what: "tool index",
                value: n.tool as f64,
            });
        };
        if n.via {
            self.cut_between(n, &tip)?;
        }
        let removed = self
            .follower
            .step_to(&mut self.stock, &tm.cutter, &tip, n.cut)?;
        self.cell_updates += removed.cells;
        self.prev_at = Some((n.path.move_index, n.path.fraction, n.path.position));
        // A tool change or a jump restarts the guess from the program's step.
        self.drift = match self.tip {
            Some(t) if n.step.norm() > 0.0 => tip - t - n.step,
            _ => Vector3::zeros(),
        };
        if self.drift.norm() > DRIFT_LIMIT || self.drift.iter().any(|v| !v.is_finite()) {
            self.drift = Vector3::zeros();
        }
        self.tip = Some(tip);
        Ok(Out {
            q,
            deflection,
            inertial_wrench,
            deflection_inertial,
            commanded,
            tip,
            force,
            residual,
            spin,
        })
    }

    /// Cuts this arm's stock through the points where the program bends between the last
    /// sample and `n` (as the nominal stock was, [`path::between`]), each moved by this
    /// arm's offset from the program, interpolated along the path from the last tip's to
    /// `tip`'s.
    fn cut_between(&mut self, n: &Sample, tip: &Vector3<f64>) -> Result<(), TickError> {
        let (Some((m0, f0, p0)), Some(t0)) = (self.prev_at, self.follower.tip()) else {
            return Ok(());
        };
        self.flush()?;
        let (off0, off1) = (t0 - p0, tip - n.path.position);
        let (program, tools) = (self.program, self.tools);
        let (stock, follower) = (&mut self.stock, &mut self.follower);
        let (mut failed, mut cells) = (None, 0usize);
        let here = (n.path.move_index, n.path.fraction);
        path::between(program, (m0, f0), here, |w, m, share| {
            let Some(tm) = program
                .moves
                .get(m)
                .and_then(|mv| tools.get(tools.find(mv.tool)))
            else {
                return;
            };
            if failed.is_some() {
                return;
            }
            match follower.cut_to(stock, &tm.cutter, &(w + off0 + (off1 - off0) * share)) {
                Ok(r) => cells += r.cells,
                Err(e) => failed = Some(e),
            }
        });
        self.cell_updates += cells;
        failed.map_or(Ok(()), Err)
    }

    /// The fixed point `t = tip(q, F(t))` from the last tip plus the programmed step (see
    /// [`Coupling`]). Returns the tip, the force there and the residual.
    fn couple(
        &mut self,
        n: &Sample,
        qs: &[f64],
        anchor: (Vector6, Vector3<f64>),
    ) -> Result<(Vector3<f64>, Vector3<f64>, f64), TickError> {
        let mut c = Coupling {
            anchor,
            compliance: None,
            evaluations: 0,
        };
        // The compensated tool's guess is the program's step (its tip belongs on the
        // program); the uncompensated one's repeats its last drift as well.
        let drift = if self.compensated {
            Vector3::zeros()
        } else {
            self.drift
        };
        let start = self.tip.map_or(n.path.position, |t| t + n.step + drift);
        // Fixed-point steps while they contract fast; the best point so far is kept.
        let mut t = start;
        // (point, its image, the force there, the residual)
        let mut best: Option<Trial> = None;
        loop {
            let (yt, ft) = self.phi(n, qs, &t, &mut c)?;
            let r = (yt - t).norm();
            let last = best.map_or(f64::INFINITY, |b| b.3);
            if r < last {
                best = Some((t, yt, ft, r));
            }
            if r <= COUPLING_TOLERANCE || c.evaluations >= MAX_COUPLING_ITERATIONS {
                return Ok((yt, ft, r));
            }
            if r > 0.5 * last {
                break;
            }
            t = yt;
        }
        let Some((bt, by, bf, _)) = best else {
            return Err(TickError::NonFiniteOutput {
                what: "predicted tip",
                index: 0,
            });
        };
        self.newton(n, qs, &mut c, (bt, by, bf))
    }

    /// The coupling's second phase, for a fixed point the plain steps approach slowly or not
    /// at all (the force changes faster with the position than the arm holds the tool):
    /// Newton's method on g(t) = phi(t) - t from the best `(point, image, force)` so far,
    /// its Jacobian by differences, with backtracking on |g|. Returns the tip, the force
    /// there and the residual \[m\].
    #[inline]
    fn newton(
        &mut self,
        n: &Sample,
        qs: &[f64],
        c: &mut Coupling,
        (mut t, mut y, mut force): (Vector3<f64>, Vector3<f64>, Vector3<f64>),
    ) -> Result<(Vector3<f64>, Vector3<f64>, f64), TickError> {
        let mut g = y - t;
        while c.evaluations + 4 <= MAX_COUPLING_ITERATIONS {
            let mut jac = Matrix3::identity() * -1.0;
            for axis in 0..3 {
                let mut te = t;
                if let Some(v) = te.get_mut(axis) {
                    *v += NEWTON_STEP;
                }
                let (ye, _) = self.phi(n, qs, &te, c)?;
                let column = (ye - te - g) / NEWTON_STEP;
                jac.set_column(axis, &column);
            }
            let Some(step) = jac.lu().solve(&-g) else {
                break;
            };
            let mut lambda = 1.0;
            let mut moved = false;
            while c.evaluations < MAX_COUPLING_ITERATIONS {
                let tn = t + step * lambda;
                let (yn, fnew) = self.phi(n, qs, &tn, c)?;
                let gn = yn - tn;
                if gn.norm() < g.norm() {
                    (t, y, force, g) = (tn, yn, fnew, gn);
                    moved = true;
                    break;
                }
                lambda *= 0.5;
                if lambda < 1.0e-3 {
                    break;
                }
            }
            if !moved || g.norm() <= COUPLING_TOLERANCE {
                break;
            }
        }
        Ok((y, force, g.norm()))
    }

    /// One evaluation of the coupling's map: the chip read at `t` on this arm's stock, its
    /// wrench, and the tip the arm deflects to under it (returned with the force).
    fn phi(
        &mut self,
        n: &Sample,
        qs: &[f64],
        t: &Vector3<f64>,
        c: &mut Coupling,
    ) -> Result<(Vector3<f64>, Vector3<f64>), TickError> {
        c.evaluations += 1;
        let model = &self.job.model;
        let Some(tm) = self.tools.get(n.tool) else {
            return Err(TickError::InvalidArgument {
                what: "tool index",
                value: n.tool as f64,
            });
        };
        let dir = n.path.direction;
        let ccw = n.counter_clockwise;
        self.cell_updates += self.follower.settle(&mut self.stock, t, &dir)?.cells;
        engagement::read(&self.stock, &tm.probes, t, &dir, ccw, &mut self.chip);
        let (f, w) = chip_wrench(&tm.chip, &self.chip, &dir, n.fz, ccw)?;
        let wrench = match &self.motion {
            Some(m) => rotate(&self.to_base, &w) + m.wrench,
            None => rotate(&self.to_base, &w),
        };
        let change = wrench - c.anchor.0;
        if change.iter().all(|v| *v == 0.0) {
            return Ok((c.anchor.1, f));
        }
        let compliance = match c.compliance {
            Some(m) => m,
            None => {
                let m = vjm::compliance(model, &mut self.data, qs)?;
                c.compliance = Some(m);
                m
            }
        };
        let shift = (compliance * change).fixed_rows::<3>(0).into_owned();
        if shift.norm() <= RELINEARISE {
            return Ok((c.anchor.1 + self.to_work.rotation * shift, f));
        }
        let load = self.motion.as_ref().map_or(Load::Exact, |m| m.load(model));
        vjm::deflection(model, &mut self.data, qs, &wrench, load)?;
        let tip = (self.to_work * Point3::from(self.data.tcp_deflected.translation.vector)).coords;
        c.anchor = (wrench, tip);
        crate::error::check_output("predicted tip", tip.as_slice())?;
        Ok((tip, f))
    }
}

/// The state of one sample's coupling: the wrench and tip of the last exact deflection, the
/// compliance at the joints once needed, and the evaluations so far.
struct Coupling {
    anchor: (Vector6, Vector3<f64>),
    compliance: Option<Matrix6<f64>>,
    evaluations: usize,
}

/// A point of the coupling, its image, the force there and the residual.
type Trial = (Vector3<f64>, Vector3<f64>, Vector3<f64>, f64);

/// Largest drift of the tip between samples the next first guess repeats \[m\]: past it
/// (the tool entering or leaving the stock) the guess is the programmed step alone.
const DRIFT_LIMIT: f64 = 1.0e-5;

/// The difference step of the coupling's Newton iteration \[m\]: far below a cell, far
/// above the rounding of the tip.
const NEWTON_STEP: f64 = 1.0e-7;

/// Both arms over a chunk, and `beside` (the nominal stage's next chunk): the three side by
/// side on threads when `options` allow and `std` is on, one after the other otherwise.
pub(super) fn both(
    unc: &mut Arm<'_>,
    comp: &mut Arm<'_>,
    noms: &[Sample],
    (out_u, out_c): (&mut Vec<Out>, &mut Vec<Out>),
    options: &RunOptions,
    beside: impl FnOnce() -> Option<(usize, JobError)> + Send,
) -> (Outcome, Outcome, Option<(usize, JobError)>) {
    #[cfg(feature = "std")]
    if options.threads > 1 && noms.len() > 1 {
        // Three fixed stages: scoped threads for two, the caller's for the third (no pool
        // needed, and the stages share nothing mutable).
        let panicked = |what: &'static str| {
            (
                0,
                JobError::AtLine {
                    line: noms.first().map_or(0, |n| n.path.line),
                    time: noms.first().map_or(0.0, |n| n.path.time),
                    error: TickError::InvalidArgument { what, value: 0.0 },
                },
            )
        };
        return std::thread::scope(|s| {
            let u = s.spawn(|| unc.process(noms, out_u));
            let b = s.spawn(beside);
            let rc = comp.process(noms, out_c);
            let ru = u
                .join()
                .unwrap_or_else(|_| Err(panicked("prediction thread (it panicked)")));
            // A thread that panicked (no path of the stages panics) ends the job with an
            // error, never with a chunk silently lost.
            let rb = b
                .join()
                .unwrap_or_else(|_| Some(panicked("nominal thread (it panicked)")));
            (ru, rc, rb)
        });
    }
    let _ = options;
    let (ru, rc) = (unc.process(noms, out_u), comp.process(noms, out_c));
    (ru, rc, beside())
}
