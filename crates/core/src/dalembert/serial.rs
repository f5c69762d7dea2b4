//! The D'Alembert corrector for any serial arm, in 6-D (or the task an arm with fewer joints
//! controls: position, position and tool axis; [`Task`]): the inertial wrench of the payload and
//! tool (Paksoy, Dede and Kiper 2025, Eq. 3-5, with the moment part the five-bar's
//! translations do not need) through the virtual-joint deflection (Hähn and Weigold, Eq. 2-9,
//! exact or linearized) to the joints at which the loaded arm lands on the desired pose.
//!
//! Per tick, for a desired pose state (pose, velocity, acceleration, angular velocity and
//! acceleration, base frame) and an optional process wrench:
//!
//! ```text
//! r   = R c                                  centre of mass of the payload from the TCP
//! a_c = a + alpha x r + omega x (omega x r)  its acceleration
//! F   = -m a_c                               D'Alembert force (Eq. 5)
//! M   = r x F - (I_w alpha + omega x I_w omega),  I_w = R I R^T   (about the TCP)
//! ```
//!
//! and the command is the solution `q` of the loaded pose IK ([`pose_ik`] with the wrench
//! `[F; M] + process`): the arm commanded to `q` and deflected by that wrench reaches the
//! desired pose, to the IK tolerance.
//!
//! When the chain carries link masses (`Element::Mass`, from the URDF's `<inertial>`), the
//! arm's own inertia loads the springs too ([`vjm::Load::ExactWithArm`]): the joint rates and
//! accelerations of the tick come from the desired TCP motion through the rigid Jacobian at
//! the warm start, `qd = J^+ [v; w]`, `qdd = J^+ ([a; alpha] - Jd qd)`. On arms whose links
//! outweigh the payload (a cobot with a few kg, or a heavy arm at high acceleration) these
//! loads dominate the deflection. [`Model::with_gravity`] adds the weights (payload and
//! links) for a robot whose static sag is not calibrated out. The IK starts from the previous tick's joints
//! extrapolated linearly (the path moves smoothly), so a tick costs one or two loaded-pose
//! evaluations and one Jacobian. Bounded, allocation-free, never panics; statuses for
//! non-convergence, singularity, joint limits, non-finite input or output.

use nalgebra::{Isometry3, Matrix3, Vector3};

use crate::error::{BuildError, TickError, check_finite, check_output};
use crate::mechanism::pose_ik::{
    PoseIkOptions, Task, pose_ik, task_gram, task_jacobian, task_vector,
};
use crate::mechanism::{JOINT_LIMIT_TOLERANCE, check_limits};
use crate::motion::PoseState;
use crate::vjm::{self, Deflection, Load, MAX_DOF, Vector6};

/// Payload and tool beyond the TCP: mass \[kg\], centre of mass \[m\] and inertia tensor about
/// the centre of mass \[kg m^2\], both in the TCP frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Payload {
    /// Mass \[kg\], finite and >= 0.
    pub mass: f64,
    /// Centre of mass in the TCP frame \[m\].
    pub com: Vector3<f64>,
    /// Inertia about the centre of mass, TCP frame \[kg m^2\]: symmetric, positive
    /// semi-definite.
    pub inertia: Matrix3<f64>,
}

impl Payload {
    /// A point mass `mass` \[kg\] at `com` \[m\] (TCP frame).
    pub fn point(mass: f64, com: Vector3<f64>) -> Self {
        Self {
            mass,
            com,
            inertia: Matrix3::zeros(),
        }
    }

    /// Checks the values.
    pub fn validate(&self) -> Result<(), BuildError> {
        crate::error::param("payload mass", self.mass, self.mass >= 0.0, ">= 0 (kg)")?;
        for (what, v) in [
            ("payload com", self.com.as_slice()),
            ("payload inertia", self.inertia.as_slice()),
        ] {
            if let Some(index) = v.iter().position(|x| !x.is_finite()) {
                return Err(BuildError::NonFinite { what, index });
            }
        }
        let asym = (self.inertia - self.inertia.transpose()).amax();
        let scale = self.inertia.amax().max(f64::MIN_POSITIVE);
        if asym > 1e-9 * scale {
            return Err(BuildError::InvalidParameter {
                what: "payload inertia (asymmetry)",
                value: asym,
                expected: "a symmetric tensor",
            });
        }
        let eig = self.inertia.symmetric_eigenvalues();
        let min = eig.min();
        if min < -1e-9 * scale {
            return Err(BuildError::Singular {
                what: "payload inertia (not positive semi-definite)",
                measure: min,
            });
        }
        // A rigid body's principal moments obey the triangle inequality: each is at most
        // the sum of the other two (diag(1, 1, 5) is no body's inertia).
        let (sum, max) = (eig.sum(), eig.max());
        let excess = max - (sum - max);
        if excess > 1e-9 * scale {
            return Err(BuildError::InvalidParameter {
                what: "payload inertia (a principal moment exceeds the sum of the other two)",
                value: excess,
                expected: "principal moments with I1 + I2 >= I3 (a rigid body's)",
            });
        }
        Ok(())
    }

    /// The D'Alembert wrench `[F; M]` \[N, N m\] on the TCP (base frame, moment about the TCP)
    /// of this payload in the motion state `s`.
    pub fn inertial_wrench(&self, s: &PoseState) -> Vector6 {
        self.loading_wrench(s, &Vector3::zeros())
    }

    /// [`Self::inertial_wrench`] plus the payload's weight under `gravity` \[m/s^2\] (base
    /// frame): `F = -m (a_c - g)`.
    pub fn loading_wrench(&self, s: &PoseState, gravity: &Vector3<f64>) -> Vector6 {
        let r_mat = s.pose.rotation.to_rotation_matrix();
        let r = r_mat * self.com;
        let (w, al) = (s.angular_velocity, s.angular_acceleration);
        let a_c = s.acceleration - gravity + al.cross(&r) + w.cross(&w.cross(&r));
        let f = -a_c * self.mass;
        let i_w = r_mat.matrix() * self.inertia * r_mat.matrix().transpose();
        let m = r.cross(&f) - (i_w * al + w.cross(&(i_w * w)));
        Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
    }
}

/// The serial-arm corrector: chain, joint limits, payload, deflection model and IK settings,
/// validated once. Immutable.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    chain: vjm::Model,
    limits: [(f64, f64); MAX_DOF],
    payload: Payload,
    deflection: Deflection,
    ik: PoseIkOptions,
    link_inertia: bool,
    gravity: Vector3<f64>,
    limit_tolerance: f64,
}

impl Model {
    /// The corrector of `chain` (at least 3 joints) carrying `payload`; no joint limits, the
    /// exact model, default IK settings with the task the joints can control
    /// ([`Task::for_dof`]: the pose with 6 or more, position and tool axis with 5, position
    /// with 3 or 4; choose another with [`Self::with_ik_options`]), the payload's wrench only
    /// (as in the paper; see [`Self::with_link_inertia`]), no gravity.
    pub fn new(chain: vjm::Model, payload: Payload) -> Result<Self, BuildError> {
        if chain.dof() < 3 {
            return Err(BuildError::DofMismatch {
                what: "TCP position correction (needs at least 3 joints)",
                expected: 3,
                got: chain.dof(),
            });
        }
        payload.validate()?;
        let ik = PoseIkOptions {
            task: Task::for_dof(chain.dof()),
            ..PoseIkOptions::default()
        };
        Ok(Self {
            chain,
            limits: [(f64::NEG_INFINITY, f64::INFINITY); MAX_DOF],
            payload,
            deflection: Deflection::Exact,
            ik,
            link_inertia: false,
            gravity: Vector3::zeros(),
            limit_tolerance: JOINT_LIMIT_TOLERANCE,
        })
    }

    /// Whether the link masses' inertial loads (`-m a_c` and `-(I alpha + omega x I omega)`
    /// per link, from the joint rates of the planned motion) enter the deflection as well
    /// (default off: only the payload's wrench does, as in Paksoy, Dede and Kiper 2025). On a
    /// heavy arm the links' own inertia bends it as much as the payload; the tick then also
    /// solves the joint rates and accelerations (about 1.7 us more on the KR 300). No effect
    /// on a chain without masses.
    #[must_use]
    pub fn with_link_inertia(mut self, on: bool) -> Self {
        self.link_inertia = on;
        self
    }

    /// Gravity \[m/s^2\], base frame (default zero): the payload's and the links' weights
    /// then load the springs as well, so the command also cancels the static sag.
    pub fn with_gravity(mut self, gravity: Vector3<f64>) -> Result<Self, BuildError> {
        if let Some(index) = gravity.iter().position(|v| !v.is_finite()) {
            return Err(BuildError::NonFinite {
                what: "gravity",
                index,
            });
        }
        self.gravity = gravity;
        Ok(self)
    }

    /// Whether the link masses' inertia is included.
    pub fn link_inertia(&self) -> bool {
        self.link_inertia
    }

    /// Gravity \[m/s^2\].
    pub fn gravity(&self) -> Vector3<f64> {
        self.gravity
    }

    /// Joint limits `(lower, upper)` \[rad or m\] per joint (one per joint, lower < upper;
    /// infinite bounds allowed): a command more than the limit tolerance
    /// ([`JOINT_LIMIT_TOLERANCE`] unless [`Self::with_limit_tolerance`] says otherwise) outside
    /// them is [`TickError::JointLimit`]; one within it is commanded as computed.
    pub fn with_joint_limits(mut self, limits: &[(f64, f64)]) -> Result<Self, BuildError> {
        if limits.len() != self.chain.dof() {
            return Err(BuildError::WrongLength {
                what: "joint limits",
                expected: self.chain.dof(),
                got: limits.len(),
            });
        }
        for (index, (dst, &(lo, hi))) in self.limits.iter_mut().zip(limits).enumerate() {
            if lo.is_nan() || hi.is_nan() || lo >= hi {
                return Err(BuildError::InvalidEntry {
                    what: "joint limits (lower must be below upper)",
                    index,
                    value: lo,
                    expected: "lower < upper",
                });
            }
            *dst = (lo, hi);
        }
        Ok(self)
    }

    /// Slack on the joint limits \[rad or m\], finite and >= 0 (default
    /// [`JOINT_LIMIT_TOLERANCE`], 1e-6: a motion starting on a limit lands past it by the
    /// IK's rounding; 0 compares exactly).
    pub fn with_limit_tolerance(mut self, tolerance: f64) -> Result<Self, BuildError> {
        crate::error::param(
            "joint limit tolerance",
            tolerance,
            tolerance >= 0.0,
            ">= 0 (rad or m)",
        )?;
        self.limit_tolerance = tolerance;
        Ok(self)
    }

    /// Slack on the joint limits \[rad or m\].
    pub fn limit_tolerance(&self) -> f64 {
        self.limit_tolerance
    }

    /// The deflection model to invert (default [`Deflection::Exact`]).
    #[must_use]
    pub fn with_deflection(mut self, deflection: Deflection) -> Self {
        self.deflection = deflection;
        self
    }

    /// IK settings (validated), with the task: at most as many rows as the chain has joints.
    pub fn with_ik_options(mut self, ik: PoseIkOptions) -> Result<Self, BuildError> {
        ik.validate()?;
        if ik.task.rank() > self.chain.dof() {
            return Err(BuildError::DofMismatch {
                what: "IK task rows (3 position + the controlled rotations) against the joints",
                expected: ik.task.rank(),
                got: self.chain.dof(),
            });
        }
        self.ik = ik;
        Ok(self)
    }

    /// The chain.
    pub fn chain(&self) -> &vjm::Model {
        &self.chain
    }
    /// The payload.
    pub fn payload(&self) -> &Payload {
        &self.payload
    }
    /// The deflection model.
    pub fn deflection(&self) -> Deflection {
        self.deflection
    }
    /// The IK settings.
    pub fn ik_options(&self) -> &PoseIkOptions {
        &self.ik
    }
    /// Joint limits, one per joint.
    pub fn joint_limits(&self) -> &[(f64, f64)] {
        self.limits.get(..self.chain.dof()).unwrap_or(&[])
    }
}

/// The serial corrector's workspace and memory: the chain's [`vjm::Data`] and the last four
/// ticks' joints (the next tick's IK starts from their cubic extrapolation).
#[derive(Debug, Clone)]
pub struct Data {
    /// Workspace of the chain.
    pub vjm: vjm::Data,
    last: [f64; MAX_DOF],
    before: [f64; MAX_DOF],
    earlier: [f64; MAX_DOF],
    earliest: [f64; MAX_DOF],
    ticks: usize,
    qd: [f64; MAX_DOF],
    qdd: [f64; MAX_DOF],
}

impl Data {
    /// A workspace for `model`, seeded at zero joints (set a real seed with
    /// [`Self::set_seed`]: the robot's joints at the start of the motion).
    pub fn new(model: &Model) -> Self {
        Self {
            vjm: vjm::Data::new(&model.chain),
            last: [0.0; MAX_DOF],
            before: [0.0; MAX_DOF],
            earlier: [0.0; MAX_DOF],
            earliest: [0.0; MAX_DOF],
            ticks: 0,
            qd: [0.0; MAX_DOF],
            qdd: [0.0; MAX_DOF],
        }
    }

    /// Whether this workspace was made for `model`'s dimensions.
    pub fn check(&self, model: &Model) -> bool {
        self.vjm.check(&model.chain)
    }

    /// Restarts the warm start from joints `q` (extra entries ignored, missing ones 0).
    pub fn set_seed(&mut self, q: &[f64]) {
        let mut s = [0.0; MAX_DOF];
        for (d, v) in s.iter_mut().zip(q) {
            *d = *v;
        }
        self.last = s;
        self.before = s;
        self.earlier = s;
        self.earliest = s;
        self.ticks = 0;
    }

    /// The last tick's joints.
    pub fn joints(&self) -> [f64; MAX_DOF] {
        self.last
    }
}

/// What the serial corrector reports beyond the common [`Tick`] fields: the landing error of
/// the predicted loaded pose and the singularity distance at the command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diagnostics {
    /// Position error of the predicted loaded pose \[m\] (within the IK tolerance).
    pub position_error: f64,
    /// Orientation error of the predicted loaded pose in the controlled rotations \[rad\].
    pub orientation_error: f64,
    /// Rotation of the predicted loaded pose about the axes the task leaves free \[rad\]
    /// (0 for the full pose): what the arm cannot correct.
    pub free_rotation: f64,
    /// Estimated smallest singular value of the joint Jacobian at the command.
    pub sigma_min: f64,
}

/// One corrected tick of a serial arm: desired TCP pose, commanded (rigid) TCP pose (what the
/// joints put the TCP at without load), joint command \[rad or m\] (entries past the dof are
/// zero), the wrench `[F; M]` \[N, N m\] the correction cancels (base frame at the TCP:
/// D'Alembert plus process) as the load, the predicted deflection `[dp; dr]` \[m, rad\] at the
/// command under it, the IK steps of the tick and [`Diagnostics`].
pub type Tick = super::Tick<Isometry3<f64>, Vector6, [f64; MAX_DOF], Diagnostics>;

/// A solution this far from the warm start \[rad or m\] gets its link loads' joint rates
/// recomputed at the solution (see [`step`]).
pub(crate) const RATE_REFRESH: f64 = 1.0e-7;

/// The loaded pose IK of one tick from `seed`, with the link loads of `data.qd`, `data.qdd`
/// when `arm`.
fn solve(
    model: &Model,
    data: &mut Data,
    pose: &nalgebra::Isometry3<f64>,
    seed: &[f64],
    wrench: &Vector6,
    arm: bool,
) -> Result<crate::mechanism::pose_ik::PoseIkSolution, TickError> {
    let dof = model.chain.dof();
    let motion = vjm::ArmMotion {
        qd: data.qd.get(..dof).unwrap_or(&[]),
        qdd: data.qdd.get(..dof).unwrap_or(&[]),
        gravity: model.gravity,
    };
    let load = Load::new(model.deflection, arm.then_some(motion));
    pose_ik(
        &model.chain,
        &mut data.vjm,
        pose,
        seed,
        wrench,
        load,
        &model.ik,
    )
}

/// `Jt (J Jt + lambda^2 I)^-1 x` over the first `dof` columns of `j`, a task's rows
/// ([`task_gram`]: the rows it leaves free decoupled).
fn dls_solve(
    j: &nalgebra::SMatrix<f64, 6, MAX_DOF>,
    task: Task,
    dof: usize,
    x: &Vector6,
    lambda2: f64,
) -> Option<[f64; MAX_DOF]> {
    let g = task_gram(j, task, dof) + nalgebra::Matrix6::identity() * lambda2;
    let y = g.cholesky()?.solve(x);
    let mut out = [0.0; MAX_DOF];
    for (o, col) in out.iter_mut().zip(j.column_iter()).take(dof) {
        *o = col.dot(&y);
    }
    Some(out)
}

/// The tick's joint rates and accelerations from the desired TCP motion, at `q` (the warm
/// start), into `data.qd` and `data.qdd` (see [`joint_rates`]).
fn joint_motion(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    desired: &PoseState,
) -> Result<(), TickError> {
    joint_rates(
        &model.chain,
        &mut data.vjm,
        &model.ik,
        q,
        desired,
        (&mut data.qd, &mut data.qdd),
    )
}

/// The joint rates and accelerations `(qd, qdd)` of the desired TCP motion at joints `q`:
/// `qd = J^+ [v; w]`, `qdd = J^+ ([a; alpha] - Jd qd)` (damped least squares with `ik`'s
/// damping, over the rows of `ik`'s task). What the link masses' loads of
/// [`vjm::Load::ExactWithArm`] need; the machining job's inertial loads use it too.
pub(crate) fn joint_rates(
    chain: &vjm::Model,
    vjm_data: &mut vjm::Data,
    ik: &PoseIkOptions,
    q: &[f64],
    desired: &PoseState,
    (qd, qdd): (&mut [f64; MAX_DOF], &mut [f64; MAX_DOF]),
) -> Result<(), TickError> {
    let dof = chain.dof();
    let lambda2 = ik.damping * ik.damping;
    vjm::joint_jacobian(chain, vjm_data, q)?;
    let singular = TickError::Singular {
        what: "joint Jacobian (joint rates of the link inertia)",
        sigma_min: 0.0,
    };
    // The task's rows only: an arm with fewer joints follows the position (and the rotations
    // it controls), and its joint rates are those of that motion, not a least-squares
    // compromise with the rotation it cannot make.
    // (The full pose stays in the base frame, the same least squares without the turn.)
    let task = ik.task;
    let full = task == Task::POSE;
    let rotation = vjm_data.tcp.rotation;
    let rows = |x: Vector6| {
        if full {
            x
        } else {
            task_vector(&x, &rotation, task)
        }
    };
    let j = if full {
        vjm_data.jacobian
    } else {
        task_jacobian(&vjm_data.jacobian, &rotation, task, dof)
    };
    let (v, w) = (desired.velocity, desired.angular_velocity);
    let twist = rows(Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z));
    *qd = dls_solve(&j, task, dof, &twist, lambda2).ok_or(singular)?;
    let bias = vjm::tcp_acceleration_bias(chain, vjm_data, q, qd.get(..dof).unwrap_or(&[]))?;
    let (a, al) = (desired.acceleration, desired.angular_acceleration);
    let x = rows(Vector6::new(a.x, a.y, a.z, al.x, al.y, al.z) - bias);
    *qdd = dls_solve(&j, task, dof, &x, lambda2).ok_or(singular)?;
    check_output("joint rates", qd.as_slice())?;
    check_output("joint accelerations", qdd.as_slice())
}

/// One tick (see the module docs): the desired pose state `desired` (base frame) and an
/// optional process wrench `process` \[N, N m\] at the TCP (base frame, moment about the TCP).
pub fn step(
    model: &Model,
    data: &mut Data,
    desired: &PoseState,
    process: Option<&Vector6>,
) -> Result<Tick, TickError> {
    data.vjm.check_model(&model.chain)?;
    // The time is not used, but a NaN there is a broken caller all the same.
    check_finite("t", &[desired.t])?;
    let pose = &desired.pose;
    check_finite("desired position", pose.translation.vector.as_slice())?;
    check_finite("desired orientation", pose.rotation.coords.as_slice())?;
    check_finite("velocity", desired.velocity.as_slice())?;
    check_finite("acceleration", desired.acceleration.as_slice())?;
    check_finite("angular velocity", desired.angular_velocity.as_slice())?;
    check_finite(
        "angular acceleration",
        desired.angular_acceleration.as_slice(),
    )?;
    let mut wrench = model.payload.loading_wrench(desired, &model.gravity);
    if let Some(p) = process {
        check_finite("process wrench", p.as_slice())?;
        wrench += p;
    }
    check_output("inertial wrench", wrench.as_slice())?;
    let dof = model.chain.dof();
    // Warm start: the previous joints extrapolated by a cubic through the last four ticks
    // (lower orders until there are four). A jerk-limited path has piecewise constant jerk,
    // so the seed is exact to rounding except across a jerk switch, and most ticks need at
    // most one step.
    let (l, b, e, f) = (&data.last, &data.before, &data.earlier, &data.earliest);
    let mut seed = *l;
    for (i, s) in seed.iter_mut().enumerate().take(dof) {
        let at = |v: &[f64; MAX_DOF]| v.get(i).copied().unwrap_or(0.0);
        *s = match data.ticks {
            0 | 1 => at(l),
            2 => 2.0 * at(l) - at(b),
            3 => 3.0 * (at(l) - at(b)) + at(e),
            _ => 4.0 * (at(l) + at(e)) - 6.0 * at(b) - at(f),
        };
    }
    let arm = model.link_inertia && model.chain.mass_count() > 0;
    if arm {
        joint_motion(model, data, seed.get(..dof).unwrap_or(&[]), desired)?;
    }
    let mut solution = solve(
        model,
        data,
        pose,
        seed.get(..dof).unwrap_or(&[]),
        &wrench,
        arm,
    )?;
    // The link loads used the warm start's joint rates; when the solution moved away from it
    // (a jerk switch the extrapolation missed), take the rates at the solution and solve
    // again from there (usually no step): the landing error stays at the IK tolerance.
    let moved = solution
        .q
        .iter()
        .zip(&seed)
        .take(dof)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    if arm && moved > RATE_REFRESH {
        let q = solution.q;
        joint_motion(model, data, q.get(..dof).unwrap_or(&[]), desired)?;
        let iterations = solution.iterations;
        solution = solve(model, data, pose, q.get(..dof).unwrap_or(&[]), &wrench, arm)?;
        solution.iterations += iterations;
    }
    check_limits(
        solution.q.get(..dof).unwrap_or(&[]),
        model.joint_limits(),
        model.limit_tolerance,
    )?;
    // The rigid pose of the command (the loaded evaluation left the rigid TCP in data).
    let commanded = data.vjm.tcp;
    data.earliest = data.earlier;
    data.earlier = data.before;
    data.before = data.last;
    data.last = solution.q;
    data.ticks = data.ticks.saturating_add(1);
    Ok(Tick {
        desired: *pose,
        commanded,
        joints: solution.q,
        load: wrench,
        displacement: solution.deflection,
        iterations: solution.iterations,
        diagnostics: Diagnostics {
            position_error: solution.position_error,
            orientation_error: solution.orientation_error,
            free_rotation: solution.free_rotation,
            sigma_min: solution.sigma_min,
        },
    })
}
