//! Pose IK warm-started along a path (the joints of both predictions' arms, and of the
//! five-axis pass): each sample's solve starts from the joints the last two solutions
//! extrapolate to.

use nalgebra::Isometry3;

use super::{Job, in_limits};
use crate::error::TickError;
use crate::mechanism::pose_ik;
use crate::vjm::{Data, Load, MAX_DOF, Vector6};

/// Pose IK warm-started along a path: from the joints the last two solutions extrapolate to
/// (from the last one's if that fails), the first from the seed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Warm {
    /// The last solution (the seed before the first) \[rad or m\].
    pub q: [f64; MAX_DOF],
    q_before: Option<[f64; MAX_DOF]>,
    /// Whether `q` is a sample's solution (not the seed): only then does the next sample
    /// extrapolate from it (a seed far from the first pose would throw the guess off).
    solved: bool,
}

impl Warm {
    /// Starting from `seed` (at most [`MAX_DOF`] joints).
    pub fn new(seed: &[f64]) -> Self {
        let mut q = [0.0; MAX_DOF];
        for (d, s) in q.iter_mut().zip(seed) {
            *d = *s;
        }
        Self {
            q,
            q_before: None,
            solved: false,
        }
    }

    /// The next solve's first guess: the last two solutions extrapolated (the last one, or
    /// the seed, before there are two).
    pub fn seed(&self, dof: usize) -> [f64; MAX_DOF] {
        let mut seed = self.q;
        if let Some(before) = self.q_before {
            for ((s, q), b) in seed.iter_mut().zip(self.q).zip(before).take(dof) {
                *s = 2.0 * q - b;
            }
        }
        seed
    }

    /// The joints at which the arm of `job` (rigid, or loaded by `wrench` as `load` says)
    /// puts its TCP on `target` (base frame), checked against the job's joint limits.
    pub fn solve(
        &mut self,
        job: &Job,
        data: &mut Data,
        target: &Isometry3<f64>,
        wrench: &Vector6,
        load: Load<'_>,
    ) -> Result<(), TickError> {
        let dof = job.model.dof();
        let seed = self.seed(dof);
        let solve = |data: &mut Data, seed: &[f64; MAX_DOF]| {
            loaded_ik(job, data, target, seed, (wrench, load))
        };
        let q = match solve(data, &seed) {
            Ok(q) => q,
            Err(_) if self.q_before.is_some() => solve(data, &self.q)?,
            Err(e) => return Err(e),
        };
        self.q_before = self.solved.then_some(self.q);
        self.solved = true;
        self.q = q;
        in_limits(self.q.get(..dof).unwrap_or(&[]), &job.limits)
    }

    /// [`Self::solve`] again from the last solution (a load that changed with it), in its
    /// place: the history the next guess extrapolates is kept.
    pub fn refine(
        &mut self,
        job: &Job,
        data: &mut Data,
        target: &Isometry3<f64>,
        wrench: &Vector6,
        load: Load<'_>,
    ) -> Result<(), TickError> {
        self.q = loaded_ik(job, data, target, &self.q, (wrench, load))?;
        in_limits(self.q.get(..job.model.dof()).unwrap_or(&[]), &job.limits)
    }
}

/// The pose IK of `job`'s arm onto `target` from `seed`, loaded by `wrench` as `load` says.
fn loaded_ik(
    job: &Job,
    data: &mut Data,
    target: &Isometry3<f64>,
    seed: &[f64; MAX_DOF],
    (wrench, load): (&Vector6, Load<'_>),
) -> Result<[f64; MAX_DOF], TickError> {
    let dof = job.model.dof();
    let seed = seed.get(..dof).unwrap_or(&[]);
    Ok(pose_ik(&job.model, data, target, seed, wrench, load, &job.setup.ik)?.q)
}
