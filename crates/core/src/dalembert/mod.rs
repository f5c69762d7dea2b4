//! D'Alembert trajectory correction (Paksoy, Dede and Kiper 2025, "Enhancing
//! trajectory-tracking accuracy of high-acceleration parallel robots by predicting compliant
//! displacements", sections 2-3.3): the planned motion's inertial load `F_D = -m a` (Eq. 5)
//! bends the robot by a displacement a stiffness model predicts, and the command is moved so
//! that the loaded robot lands on the desired path, every servo tick.
//!
//! Two correctors with the same tick shape (`Model`, `Data`, `step`) and the same tick result,
//! [`Tick`]:
//!
//! | module | robot and stiffness model | load | solve |
//! |---|---|---|---|
//! | [`parallel`] | any [`crate::mechanism::Mechanism`] (the paper's five-bar) with a compliance map (Eq. 9-14) | force `-m* a` of the tuned mass | `c = x_d - d(c, F)` (one shot, or a bounded fixed point), then IK |
//! | [`serial`] | any serial arm with its virtual-joint model (Hähn and Weigold, Eq. 2-9) | 6-D wrench of the payload (and of the links) | one loaded pose IK: the joints at which the deflected TCP lands on the pose |
//!
//! They stay two functions rather than one generic corrector: the serial corrector's single
//! Newton solve of the loaded pose is the limit of the paper's fixed point, reached in one or
//! two steps from its warm start, where the generic form would pay one full IK per
//! fixed-point iteration (the latency harness, `benches/latency.rs`, times both on the KR 300
//! with a point mass: 1.9-2.0 us for the serial tick against 7.2-7.3 us for the generic one),
//! and a 6-D pose is not a task point of a [`crate::mechanism::Mechanism`].

pub mod parallel;
pub mod serial;

/// One corrected tick of either corrector, generic over the task pose `P` (a task point
/// `SVector<f64, T>` or a TCP pose `Isometry3<f64>`), the load and displacement layout `W`,
/// the joint vector `Q` and the corrector's own diagnostics `S`; [`parallel::Tick`] and
/// [`serial::Tick`] name the two instances.
#[derive(Debug, Clone, Copy, PartialEq)]
#[must_use]
pub struct Tick<P, W, Q, S> {
    /// Desired (planned) task pose \[m, rad\].
    pub desired: P,
    /// Commanded task pose: where the joints put the rigid robot; the desired pose moved
    /// against the predicted displacement \[m, rad\].
    pub commanded: P,
    /// Joint command \[rad or m\].
    pub joints: Q,
    /// The load the correction cancels: the D'Alembert force `-m* a` \[N\] (parallel), or the
    /// wrench `[F; M]` \[N, N m\] on the TCP (serial: D'Alembert plus process).
    pub load: W,
    /// Predicted displacement of the task point at the command under `load` \[m, rad\].
    pub displacement: W,
    /// Solver iterations of the tick: fixed-point iterations (parallel; 0 = the paper's
    /// one-shot update) or loaded pose IK steps (serial).
    pub iterations: usize,
    /// What the corrector reports beyond these fields.
    pub diagnostics: S,
}
