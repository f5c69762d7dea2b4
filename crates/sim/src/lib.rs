//! `deflect-sim`: a rapier3d-f64 testbed for the D'Alembert trajectory correction of Paksoy et
//! al. (`shared/papers/002_cf21300bacbb0f8b.txt`): the 2-DoF planar parallel robot (OC / NC,
//! upper / lower head) with compliant joints and finite-bandwidth servos, simulated static
//! tests, a fitted compliance map, the paper's motions at 1-5 g with and without correction,
//! and the paper's evaluation (Appendix C).

pub mod analysis;
pub mod contour_output;
pub mod contour_scene;
pub mod milling;
pub mod milling_output;
pub mod output;
pub mod pipeline;
pub mod report;
pub mod robot;
pub mod serial;

use core::fmt;

/// Any failure of the testbed, with a message.
#[derive(Debug, Clone, PartialEq)]
pub struct SimError(pub String);

impl SimError {
    /// An error with message `msg`.
    pub fn new(msg: impl Into<String>) -> Self {
        Self(msg.into())
    }
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SimError {}

macro_rules! from_error {
    ($($t:ty),*) => {$(
        impl From<$t> for SimError {
            fn from(e: $t) -> Self {
                Self(e.to_string())
            }
        }
    )*};
}

from_error!(
    deflect_core::mechanism::MechanismError,
    deflect_core::motion::MotionError,
    deflect_core::dalembert::CorrectorError,
    deflect_core::compliance_map::ComplianceMapError,
    std::io::Error,
    serde_json::Error,
    mcap::McapError
);
