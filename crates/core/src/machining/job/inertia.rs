//! Inertial loads of the machining job: the D'Alembert wrench of the tool and spindle and the
//! link masses' loads (Paksoy, Dede and Kiper 2025, Eq. 3-5; the serial form of
//! [`crate::dalembert::serial`]) added to the process wrench before the virtual-joint
//! deflection (Hähn and Weigold 2020, Eq. 2-9), so one deflection carries both.
//!
//! Per sample the planned motion of the tool is the path's: the tip at `p`, the feed
//! direction `T`, the path speed `v` and acceleration `a_t` along it and the curvature `k` of
//! the move ([`crate::machining::Move::curvature`]; in a corner blend the sum of both runs',
//! [`crate::machining::path::PathSample::acceleration_vector`]), in the base frame through
//! the placement `R`:
//!
//! ```text
//! velocity     = R T v
//! acceleration = R (T a_t + k v^2)
//! ```
//!
//! with the tool's orientation held (a 2.5-D program; a spin schedule's slow turn about the
//! tool axis is not counted). The joint rates of the link loads come from that motion at the
//! sample's joints ([`crate::dalembert::serial`]'s damped least squares over the IK's task).
//! Gravity is not counted: a machining robot's controller holds the static sag of its own
//! weight, and a sensor's is calibrated out (`SensorCalibration`).

use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use crate::dalembert::serial::Payload;
use crate::error::{BuildError, TickError};
use crate::machining::path::PathSample;
use crate::mechanism::PoseIkOptions;
use crate::motion::PoseState;
use crate::vjm::{self, ArmMotion, MAX_DOF, Vector6};

/// The inertia the job counts: the tool and spindle beyond the TCP and, when `links`, the
/// chain's link masses (the model's `Element::Mass` entries, from the URDF's `<inertial>`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inertia {
    /// Tool and spindle beyond the TCP: mass \[kg\], centre of mass and inertia about it, TCP
    /// frame ([`Payload::validate`]: mass >= 0, finite, a rigid body's inertia).
    pub payload: Payload,
    /// Whether the link masses' inertial loads join the payload's.
    pub links: bool,
}

impl Inertia {
    /// Checks the payload (see [`Payload::validate`]).
    pub fn validate(&self) -> Result<(), BuildError> {
        self.payload.validate()
    }

    /// Whether the job counts nothing: a massless payload and no link loads. Such a job runs
    /// the process wrench alone, bit for bit the job without inertia.
    pub fn is_zero(&self) -> bool {
        self.payload.mass == 0.0 && !self.links
    }
}

/// The planned motion of the tool at sample `s` (see the module docs): pose `target` (base
/// frame), velocity and acceleration through the placement's rotation `to_base`.
pub(super) fn pose_state(
    to_base: &UnitQuaternion<f64>,
    s: &PathSample,
    target: &Isometry3<f64>,
) -> PoseState {
    PoseState {
        t: s.time,
        pose: *target,
        velocity: to_base * (s.direction * s.speed),
        acceleration: to_base * s.acceleration_vector,
        angular_velocity: Vector3::zeros(),
        angular_acceleration: Vector3::zeros(),
    }
}

/// One arm's inertial state at a sample: the payload's D'Alembert wrench and the joint rates
/// of the link loads.
#[derive(Debug, Clone, Copy)]
pub(super) struct Motion {
    /// The planned motion.
    pub state: PoseState,
    /// The payload's D'Alembert wrench `[F; M]` \[N, N m\], base frame, about the TCP.
    pub wrench: Vector6,
    qd: [f64; MAX_DOF],
    qdd: [f64; MAX_DOF],
    links: bool,
}

impl Motion {
    /// The payload's wrench in `state`; the joint rates still zero.
    pub fn new(inertia: &Inertia, state: PoseState) -> Self {
        Self {
            wrench: inertia.payload.inertial_wrench(&state),
            state,
            qd: [0.0; MAX_DOF],
            qdd: [0.0; MAX_DOF],
            links: inertia.links,
        }
    }

    /// The joint rates of the planned motion at joints `q` (when the link loads count and the
    /// chain has masses).
    pub fn rates_at(
        &mut self,
        model: &vjm::Model,
        data: &mut vjm::Data,
        ik: &PoseIkOptions,
        q: &[f64],
    ) -> Result<(), TickError> {
        if !self.has_links(model) {
            return Ok(());
        }
        crate::dalembert::serial::joint_rates(
            model,
            data,
            ik,
            q,
            &self.state,
            (&mut self.qd, &mut self.qdd),
        )
    }

    /// Whether link loads join the wrench on `model`.
    pub fn has_links(&self, model: &vjm::Model) -> bool {
        self.links && model.mass_count() > 0
    }

    /// The exact deflection's load: the TCP wrench with the link loads of the rates last
    /// computed ([`Self::rates_at`]), or the TCP wrench alone.
    pub fn load(&self, model: &vjm::Model) -> vjm::Load<'_> {
        if !self.has_links(model) {
            return vjm::Load::Exact;
        }
        let dof = model.dof();
        vjm::Load::ExactWithArm(ArmMotion {
            qd: self.qd.get(..dof).unwrap_or(&[]),
            qdd: self.qdd.get(..dof).unwrap_or(&[]),
            gravity: Vector3::zeros(),
        })
    }
}
