//! `deflect-sim`: a rapier3d-f64 testbed for the models of deflect-core, and the project's
//! main command.
//!
//! * The D'Alembert trajectory correction of Paksoy, Dede and Kiper (2025), "Enhancing
//!   trajectory-tracking accuracy of high-acceleration parallel robots by predicting
//!   compliant displacements": the 2-DoF planar parallel robot (OC / NC, upper / lower head)
//!   with compliant joints and finite-bandwidth servos ([`robot`]), simulated static tests, a
//!   fitted compliance map, the paper's motions at 1-5 g with and without correction
//!   ([`pipeline`]) and the paper's evaluation (Appendix C, [`analysis`], [`report`],
//!   [`output`]).
//! * The online force-based compensation of Hähn and Weigold (sec. 2.2-2.6) in a milling
//!   scenario on the flexible KR 300 R2500 ([`milling`]).
//! * Any serial arm from a URDF and a stiffness file as a flexible arm ([`urdf_arm`]) and the
//!   6-D D'Alembert corrector for serial arms at high acceleration on it ([`serial_scene`]).
//! * Force-feedback contour tracing and shape recovery ("Shape recovery from robot contour
//!   tracking with force feedback", Eq. 10 and 21) by a 2R arm with compliant, backlashed
//!   joints ([`contour_scene`]).
//!
//! Shared by all scenes: seeded noise ([`noise`]), rapier helpers ([`rapier_util`]), the
//! parallel job runner ([`jobs`]) and a small serial arm ([`serial`]). Gravity, where a scene
//! has it, is deflect-core's [`deflect_core::units::GRAVITY_Z_DOWN`].
#![deny(missing_docs)]
// No input may kill the process: errors are returned, never panicked (tests may unwrap).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

pub mod analysis;
pub mod atlas;
pub mod contour_scene;
pub mod jobs;
pub mod mcap_log;
pub mod milling;
pub mod noise;
pub mod output;
pub mod pipeline;
pub mod plot_style;
pub mod rapier_util;
pub mod report;
pub mod robot;
pub mod serial;
pub mod serial_scene;
pub mod urdf_arm;

use core::fmt;
use std::path::Path;

/// Any failure of the testbed, with a message.
#[derive(Debug, Clone, PartialEq)]
pub struct SimError(pub String);

impl SimError {
    /// An error with message `msg`.
    pub fn new(msg: impl Into<String>) -> Self {
        Self(msg.into())
    }

    /// A file error naming the file: "cannot `action` `path`: `e`", e.g. `action` = "write
    /// the summary CSV".
    pub fn file(path: &Path, action: &str, e: impl fmt::Display) -> Self {
        Self(format!("cannot {action} {}: {e}", path.display()))
    }
}

/// Writes `contents` to the file at `path` (`what` it is, e.g. "the summary CSV"); the error
/// names the file.
pub fn write_file(path: &Path, what: &str, contents: impl AsRef<[u8]>) -> Result<(), SimError> {
    std::fs::write(path, contents).map_err(|e| SimError::file(path, &format!("write {what}"), e))
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SimError {}

// No `From<std::io::Error>`: every file error goes through [`SimError::file`] and names its
// file.
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
    deflect_core::BuildError,
    deflect_core::TickError,
    deflect_core::LoadError,
    serde_json::Error,
    mcap::McapError
);
