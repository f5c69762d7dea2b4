//! 6-D pose inverse kinematics of a serial chain by damped least squares, warm-started from
//! a seed, optionally of the *loaded* chain: the joints at which the TCP, deflected by a
//! wrench through the virtual-joint model (exact, Eq. 2-9 of Hähn and Weigold, or the
//! linearized compliance), lands on the target. The loaded problem is what a deflection
//! correction needs: command those joints and the compliant robot reaches the target.
//!
//! Each iteration evaluates the (loaded) pose and the rigid joint Jacobian `J` in one pass,
//! and steps `dq = J^T (J J^T + lambda^2 I)^-1 e` with the pose error
//! `e = [p_t - p; log(R_t R^T)]`, clipped to `max_step`.
//!
//! An arm with fewer than six joints cannot reach a 6-D pose; [`Task`] selects what it
//! controls: the TCP position always, and the rotations about the TCP frame's x, y, z axes
//! that are selected (position and tool axis: the tilts about x and y; a SCARA: the spin about
//! z). The unselected rows of `e` and `J` (rotation rows taken in the TCP frame, `R^T`) are
//! dropped from the least squares; the rotation left about them is reported
//! ([`PoseIkSolution::free_rotation`]), not refused. The loaded Jacobian differs from the
//! rigid one by the deflection's slope, far below 1 %: the iteration still converges, slightly
//! slower than Newton. Bounded: at most `max_iterations` steps. Allocation-free; the
//! workspace is the chain's [`Data`].

use nalgebra::{Isometry3, Matrix6};

use crate::error::{BuildError, TickError, check_finite, check_output, param};
use crate::vjm::{self, Data, Load, MAX_CORRECTION_ITERATIONS, MAX_DOF, Model, Vector6};

/// What [`pose_ik`] controls: the TCP position (always) and the rotations about the TCP
/// frame's `x`, `y`, `z` axes marked in `rotation` (the tool axis is the TCP's `z`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Task {
    /// Whether the rotation about the TCP frame's x, y, z axis is controlled.
    pub rotation: [bool; 3],
}

impl Task {
    /// The full pose (6 rows; at least 6 joints).
    pub const POSE: Self = Self {
        rotation: [true; 3],
    };
    /// Position and tool axis (5 rows): the spin about the tool axis is free (a 5-axis arm
    /// with a rotationally symmetric tool, a spindle).
    pub const POSITION_AND_AXIS: Self = Self {
        rotation: [true, true, false],
    };
    /// Position and the spin about the tool axis (4 rows): a SCARA, whose tool axis stays
    /// vertical.
    pub const POSITION_AND_SPIN: Self = Self {
        rotation: [false, false, true],
    };
    /// Position only (3 rows).
    pub const POSITION: Self = Self {
        rotation: [false; 3],
    };

    /// Rows of the task: 3 plus the controlled rotations.
    pub fn rank(&self) -> usize {
        3 + self.rotation.iter().filter(|&&r| r).count()
    }

    /// The largest of pose, position and axis, position for `dof` joints (6 or more: the
    /// pose; 5: position and axis; fewer: position), without looking at the arm. An arm whose
    /// five joints cannot tilt its tool both ways (the SO-101: pan, three parallel pitch
    /// joints, roll) or a SCARA controls [`Self::POSITION_AND_SPIN`]: [`largest_task`] finds
    /// what an arm controls at a pose.
    pub fn for_dof(dof: usize) -> Self {
        match dof {
            6.. => Self::POSE,
            5 => Self::POSITION_AND_AXIS,
            _ => Self::POSITION,
        }
    }

    /// Its name: `pose`, `position_and_axis`, `position_and_spin`, `position`, or the
    /// controlled rotation axes (`position_rx_ry`, ...).
    pub fn name(&self) -> &'static str {
        match self.rotation {
            [true, true, true] => "pose",
            [true, true, false] => "position_and_axis",
            [false, false, true] => "position_and_spin",
            [false, false, false] => "position",
            [true, false, false] => "position_rx",
            [false, true, false] => "position_ry",
            [true, false, true] => "position_rx_rz",
            [false, true, true] => "position_ry_rz",
        }
    }
}

impl Default for Task {
    /// [`Task::POSE`].
    fn default() -> Self {
        Self::POSE
    }
}

/// Settings of [`pose_ik`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseIkOptions {
    /// Iteration budget, at most [`MAX_CORRECTION_ITERATIONS`].
    pub max_iterations: usize,
    /// Position tolerance \[m\].
    pub position_tolerance: f64,
    /// Orientation tolerance \[rad\].
    pub orientation_tolerance: f64,
    /// Damping `lambda` \[m/rad\]: keeps steps bounded near singularities.
    pub damping: f64,
    /// Largest joint step per iteration (Euclidean norm) \[rad or m\].
    pub max_step: f64,
    /// Singularity threshold on the (estimated) smallest singular value of the 6 x n joint
    /// Jacobian \[m/rad\] (rows mix m and rad; the position rows dominate on a robot arm).
    pub min_sigma: f64,
    /// What is controlled (default [`Task::POSE`]).
    pub task: Task,
}

impl Default for PoseIkOptions {
    /// 20 iterations, 1e-8 m and 1e-8 rad, damping 1e-6, steps of at most 0.5 rad,
    /// threshold 1e-3 m/rad, the full pose.
    fn default() -> Self {
        Self {
            max_iterations: 20,
            position_tolerance: 1.0e-8,
            orientation_tolerance: 1.0e-8,
            damping: 1.0e-6,
            max_step: 0.5,
            min_sigma: 1.0e-3,
            task: Task::POSE,
        }
    }
}

impl PoseIkOptions {
    /// Checks every setting.
    pub fn validate(&self) -> Result<(), BuildError> {
        if self.max_iterations == 0 || self.max_iterations > MAX_CORRECTION_ITERATIONS {
            return Err(BuildError::InvalidParameter {
                what: "max_iterations",
                value: self.max_iterations as f64,
                expected: "in 1..=MAX_CORRECTION_ITERATIONS (256)",
            });
        }
        param(
            "position_tolerance",
            self.position_tolerance,
            self.position_tolerance > 0.0,
            "> 0 (m)",
        )?;
        param(
            "orientation_tolerance",
            self.orientation_tolerance,
            self.orientation_tolerance > 0.0,
            "> 0 (rad)",
        )?;
        param("damping", self.damping, self.damping >= 0.0, ">= 0")?;
        param("max_step", self.max_step, self.max_step > 0.0, "> 0")?;
        param("min_sigma", self.min_sigma, self.min_sigma >= 0.0, ">= 0")?;
        Ok(())
    }
}

/// Result of [`pose_ik`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[must_use]
pub struct PoseIkSolution {
    /// Joints \[rad or m\]; entries past the dof are zero.
    pub q: [f64; MAX_DOF],
    /// Steps taken.
    pub iterations: usize,
    /// Position error left \[m\].
    pub position_error: f64,
    /// Orientation error left in the controlled rotations \[rad\] (all three for
    /// [`Task::POSE`]).
    pub orientation_error: f64,
    /// Rotation left about the axes the task leaves free \[rad\] (the norm of those
    /// components of the rotation vector, TCP frame; 0 for [`Task::POSE`]): what an arm with
    /// fewer joints cannot correct.
    pub free_rotation: f64,
    /// Estimated smallest singular value of the task's joint Jacobian at the solution.
    pub sigma_min: f64,
    /// Deflection `[dp; dr]` of the TCP at `q` under the load (zero for [`Load::Rigid`]).
    pub deflection: Vector6,
}

/// `J J^T` over the first `dof` columns (no transposed copy of the 6 x 8 Jacobian).
#[inline]
fn gram(j: &nalgebra::SMatrix<f64, 6, MAX_DOF>, dof: usize) -> Matrix6<f64> {
    let mut g = Matrix6::zeros();
    for col in j.column_iter().take(dof) {
        // Rank-one update with the column: g += col col^T.
        g.ger(1.0, &col, &col, 1.0);
    }
    g
}

/// Whether the smallest singular value of `J` is at least `min_sigma`, decided exactly from the
/// Gram matrix `J J^T`: `J J^T - min_sigma^2 I` has a Cholesky factor iff every eigenvalue of
/// `J J^T` is above `min_sigma^2`. Returns `Ok(estimate)` or `Err(estimate)`, the estimate of
/// the smallest singular value being an upper bound from three inverse iterations on that
/// shifted matrix with a Rayleigh quotient (exact to a few percent; the decision does not
/// depend on it). Cheap enough per tick: one or two 6 x 6 factorisations and three solves.
fn singularity(jj: &Matrix6<f64>, min_sigma: f64) -> Result<f64, f64> {
    let shift = min_sigma * min_sigma;
    let estimate = |chol: &nalgebra::Cholesky<f64, nalgebra::U6>, shift: f64| {
        let mut v = Vector6::repeat(1.0 / nalgebra::ComplexField::sqrt(6.0f64));
        let mut rayleigh = 0.0;
        for _ in 0..3 {
            let w = chol.solve(&v);
            // v^T B^-1 v for the unit v: at most 1 / lambda_min(B), converging as the
            // square of the eigenvalue ratio.
            rayleigh = v.dot(&w);
            let n = w.norm();
            if !(n.is_finite() && n > 0.0 && rayleigh > 0.0) {
                return 0.0;
            }
            v = w / n;
        }
        nalgebra::ComplexField::sqrt(1.0 / rayleigh + shift)
    };
    match (jj - Matrix6::identity() * shift).cholesky() {
        Some(chol) => Ok(estimate(&chol, shift)),
        None => Err(jj.cholesky().map_or(0.0, |c| estimate(&c, 0.0))),
    }
}

/// `j` (6 x n, base frame) as the rows of `task`: position rows as they are, rotation rows
/// turned into the TCP frame (`R^T`, `rotation` the TCP's) and zeroed where the task leaves the
/// rotation free.
pub(crate) fn task_jacobian(
    j: &nalgebra::SMatrix<f64, 6, MAX_DOF>,
    rotation: &nalgebra::UnitQuaternion<f64>,
    task: Task,
    dof: usize,
) -> nalgebra::SMatrix<f64, 6, MAX_DOF> {
    let mut out = *j;
    let rt = rotation.inverse();
    for mut col in out.column_iter_mut().take(dof) {
        let at = |k: usize| col.get(k).copied().unwrap_or(0.0);
        let w = rt * nalgebra::Vector3::new(at(3), at(4), at(5));
        for (k, &c) in task.rotation.iter().enumerate() {
            if let Some(x) = col.get_mut(3 + k) {
                *x = if c {
                    w.get(k).copied().unwrap_or(0.0)
                } else {
                    0.0
                };
            }
        }
    }
    out
}

/// A 6-vector `[p; r]` (base frame) as the rows of `task` (see [`task_jacobian`]).
pub(crate) fn task_vector(
    x: &Vector6,
    rotation: &nalgebra::UnitQuaternion<f64>,
    task: Task,
) -> Vector6 {
    let r = rotation.inverse() * x.fixed_rows::<3>(3).into_owned();
    let mut out = *x;
    for (k, &c) in task.rotation.iter().enumerate() {
        if let Some(v) = out.get_mut(3 + k) {
            *v = if c {
                r.get(k).copied().unwrap_or(0.0)
            } else {
                0.0
            };
        }
    }
    out
}

/// `J J^T` of a task's rows with a unit diagonal on the rows it leaves free: they neither move
/// the joints (their entries are zero) nor count as a singular direction.
pub(crate) fn task_gram(
    j: &nalgebra::SMatrix<f64, 6, MAX_DOF>,
    task: Task,
    dof: usize,
) -> Matrix6<f64> {
    let mut g = gram(j, dof);
    for (k, &c) in task.rotation.iter().enumerate() {
        if !c && let Some(x) = g.get_mut((3 + k, 3 + k)) {
            *x = 1.0;
        }
    }
    g
}

/// Joints at which the TCP, loaded by `wrench` \[N, N m\] (base frame, moment about the TCP)
/// as `load` says ([`vjm::deflection`]; `wrench` is unused for [`Load::Rigid`]), reaches
/// `target`, from `seed` (see the module docs).
/// [`TickError::NotConverged`] when the budget ends first (e.g. an unreachable target),
/// [`TickError::Singular`] at a singular pose, [`TickError::WrongLength`] /
/// [`TickError::NonFinite`] for bad inputs. On success `data.tcp` is the rigid pose of the
/// solution (the pose to command).
pub fn pose_ik(
    model: &Model,
    data: &mut Data,
    target: &Isometry3<f64>,
    seed: &[f64],
    wrench: &Vector6,
    load: Load<'_>,
    options: &PoseIkOptions,
) -> Result<PoseIkSolution, TickError> {
    let dof = model.dof();
    let mut q = checked_seed(dof, seed, target)?;
    let lambda2 = options.damping * options.damping;
    let full = options.task == Task::POSE;
    let mut iterations = 0;
    // The task's Jacobian: the rigid one, its rotation rows in the TCP frame and the free
    // ones zero (unused for the full pose).
    let mut jt: nalgebra::SMatrix<f64, 6, MAX_DOF>;
    loop {
        let qs = q.get(..dof).unwrap_or(&[]);
        // One pass: the loaded pose, the deflection and the rigid Jacobian at `qs`.
        let deflection = vjm::deflection(model, data, qs, wrench, load)?;
        let pose = data.tcp_deflected;
        let ep = target.translation.vector - pose.translation.vector;
        let er = vjm::rotation_vector(&(target.rotation * pose.rotation.inverse()));
        let e6 = Vector6::new(ep.x, ep.y, ep.z, er.x, er.y, er.z);
        let (jac, e, oe, free) = if full {
            (&data.jacobian, e6, er.norm(), 0.0)
        } else {
            let (oe, free) = rotation_errors(&pose.rotation, &er, options.task);
            jt = task_jacobian(&data.jacobian, &pose.rotation, options.task, dof);
            (
                &jt,
                task_vector(&e6, &pose.rotation, options.task),
                oe,
                free,
            )
        };
        let jj = task_gram(jac, options.task, dof);
        let pe = ep.norm();
        if pe <= options.position_tolerance && oe <= options.orientation_tolerance {
            let s = singularity(&jj, options.min_sigma).map_err(|s| TickError::Singular {
                what: "joint Jacobian (pose IK)",
                sigma_min: s,
            })?;
            check_output("joints", &q)?;
            return Ok(PoseIkSolution {
                q,
                iterations,
                position_error: pe,
                orientation_error: oe,
                free_rotation: free,
                sigma_min: s,
                deflection,
            });
        }
        if iterations >= options.max_iterations {
            return Err(TickError::NotConverged {
                iterations,
                residual: pe + oe,
            });
        }
        let dq = damped_step(jac, &jj, &e, lambda2, options.max_step)?;
        for (qi, d) in q.iter_mut().zip(dq.iter()).take(dof) {
            *qi += d;
        }
        iterations += 1;
    }
}

/// The seed \[rad or m\] checked (length `dof`, finite, as the target) and copied into a
/// joint vector (zero past the dof).
#[inline]
fn checked_seed(
    dof: usize,
    seed: &[f64],
    target: &Isometry3<f64>,
) -> Result<[f64; MAX_DOF], TickError> {
    if seed.len() != dof {
        return Err(TickError::WrongLength {
            what: "seed",
            expected: dof,
            got: seed.len(),
        });
    }
    check_finite("seed", seed)?;
    check_finite("target translation", target.translation.vector.as_slice())?;
    check_finite("target rotation", target.rotation.coords.as_slice())?;
    let mut q = [0.0; MAX_DOF];
    for (dst, &s) in q.iter_mut().zip(seed) {
        *dst = s;
    }
    Ok(q)
}

/// The orientation error `er` \[rad\] (base frame) split in the TCP frame (`rotation` the
/// TCP's) by `task`: the norms of its controlled and of its free components.
#[inline]
fn rotation_errors(
    rotation: &nalgebra::UnitQuaternion<f64>,
    er: &nalgebra::Vector3<f64>,
    task: Task,
) -> (f64, f64) {
    let er_t = rotation.inverse() * er;
    let (mut on, mut off) = (0.0, 0.0);
    for (k, &c) in task.rotation.iter().enumerate() {
        let v = er_t.get(k).copied().unwrap_or(0.0);
        if c { on += v * v } else { off += v * v }
    }
    (
        nalgebra::ComplexField::sqrt(on),
        nalgebra::ComplexField::sqrt(off),
    )
}

/// The damped least-squares step `dq = J^T (J J^T + lambda^2 I)^-1 e` \[rad or m\] for the
/// task's Jacobian `jac`, its Gram matrix `jj` and error `e` \[m, rad\], clipped to the norm
/// `max_step`.
#[inline]
fn damped_step(
    jac: &nalgebra::SMatrix<f64, 6, MAX_DOF>,
    jj: &Matrix6<f64>,
    e: &Vector6,
    lambda2: f64,
    max_step: f64,
) -> Result<nalgebra::SVector<f64, MAX_DOF>, TickError> {
    let g = jj + Matrix6::identity() * lambda2;
    let Some(chol) = g.cholesky() else {
        return Err(TickError::Singular {
            what: "joint Jacobian (pose IK)",
            sigma_min: 0.0,
        });
    };
    let y = chol.solve(e);
    let mut dq = jac.tr_mul(&y);
    let n = dq.norm();
    if !n.is_finite() {
        return Err(TickError::NonFiniteOutput {
            what: "pose IK step",
            index: 0,
        });
    }
    if n > max_step {
        dq *= max_step / n;
    }
    Ok(dq)
}

/// Smallest ratio of the smallest to the largest singular value of a task's Jacobian (position
/// rows divided by the TCP's distance from the base) for [`largest_task`] to count the task as
/// controlled: 0.02, a condition number of 50. A direction weaker than that (the SO-101's tool
/// tilt out of its plane, 0.4 % of its strongest) is reachable at the pose but not along a
/// path.
pub const MIN_TASK_CONDITION: f64 = 0.02;

/// The largest task the chain controls at joints `q`: the first of [`Task::POSE`],
/// [`Task::POSITION_AND_AXIS`], [`Task::POSITION_AND_SPIN`], [`Task::POSITION`] with no more
/// rows than joints whose Jacobian (rotation rows in the TCP frame, position rows divided by
/// the TCP's distance from the base so both are per radian) has singular values within
/// [`MIN_TASK_CONDITION`] of each other. A pose where even the position is that ill-conditioned
/// is [`TickError::Singular`]. An arm whose five joints cannot tilt its tool out of its plane
/// independently of its position (the SO-101: pan, three parallel pitch joints, roll) and a
/// SCARA get the position and spin. Setup-time (a singular value decomposition per task).
pub fn largest_task(model: &Model, data: &mut Data, q: &[f64]) -> Result<Task, TickError> {
    let dof = model.dof();
    vjm::joint_jacobian(model, data, q)?;
    let pose = data.tcp;
    let length = pose.translation.vector.norm().max(0.1);
    let rt = pose.rotation.inverse();
    let mut best = 0.0f64;
    for task in [
        Task::POSE,
        Task::POSITION_AND_AXIS,
        Task::POSITION_AND_SPIN,
        Task::POSITION,
    ] {
        if task.rank() > dof {
            continue;
        }
        // The task's rows, stacked at the top of a 6 x 8 matrix (the rest zero).
        let mut j = nalgebra::SMatrix::<f64, 6, MAX_DOF>::zeros();
        for (c, col) in data.jacobian.column_iter().enumerate().take(dof) {
            let at = |k: usize| col.get(k).copied().unwrap_or(0.0);
            let w = rt * nalgebra::Vector3::new(at(3), at(4), at(5));
            let mut row = 0;
            for k in 0..3 {
                if let Some(x) = j.get_mut((row, c)) {
                    *x = at(k) / length;
                }
                row += 1;
            }
            for (k, &on) in task.rotation.iter().enumerate() {
                if on {
                    if let Some(x) = j.get_mut((row, c)) {
                        *x = w.get(k).copied().unwrap_or(0.0);
                    }
                    row += 1;
                }
            }
        }
        let sv = j.transpose().svd(false, false).singular_values;
        let mut sorted = [0.0f64; 6];
        for (d, v) in sorted.iter_mut().zip(sv.iter()) {
            *d = *v;
        }
        let top = sorted.iter().copied().fold(0.0, f64::max);
        // The task's `rank` largest singular values: the smallest of them against the top.
        sorted.sort_unstable_by(|a, b| b.total_cmp(a));
        let low = sorted.get(task.rank() - 1).copied().unwrap_or(0.0);
        let ratio = if top > 0.0 { low / top } else { 0.0 };
        if ratio >= MIN_TASK_CONDITION {
            return Ok(task);
        }
        best = best.max(ratio);
    }
    Err(TickError::Singular {
        what: "joint Jacobian (every task ill-conditioned)",
        sigma_min: best,
    })
}
