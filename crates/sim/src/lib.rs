//! `deflect-sim`: a rapier3d-f64 testbed for the models of deflect-core, and the project's
//! main command.
//!
//! The scenes ([`scenes`]), one folder per domain, and the command of `deflect-sim` that runs
//! each:
//!
//! | scene | what | command |
//! |---|---|---|
//! | [`scenes::parallel`] | the D'Alembert trajectory correction of Paksoy, Dede and Kiper (2025) on the paper's 2-DoF five-bar: simulated static tests, the fitted compliance map ([`scenes::parallel::calibrate`]), the paper's evaluation (Appendix C) | `reproduce`, `static-test`, `fit`, `run` |
//! | [`scenes::delta`] | the Delta robot's D'Alembert correction at 5-10 g | `delta` |
//! | [`scenes::serial`] | any serial arm from a URDF and a stiffness file as a flexible arm, the 6-D D'Alembert corrector on it; the stiffness-optimal posture over a workspace ([`scenes::serial::atlas`]) | `serial`, `atlas` |
//! | [`scenes::milling`] | robot machining after Hähn and Weigold (sec. 2.2-2.6) on the flexible KR 300 R2500: the groove, any CAM program's offline, Cartesian, hybrid, axis-specific and combined (inertial) compensation, five-axis programs, the part maps | `milling` |
//! | [`scenes::contour`] | force-feedback contour tracing and shape recovery ("Shape recovery from robot contour tracking with force feedback", Eq. 10 and 21) by a 2R arm with compliant, backlashed joints | `contour` |
//! | (deflect-core's machining job) | a CAM program's offline pass on any arm, 2.5-D or five-axis, streamed; the compensated program for the controller (G-code, KRL, RAPID, URScript); the placement search | `job`, `place` |
//!
//! Shared by the scenes: the flexible arm built from any URDF ([`urdf_arm`], for milling and
//! serial), the MCAP writer ([`mcap_log`]) and the streamed NumPy archive ([`npz_stream`]),
//! the summary files and figures ([`summary`]), the plot style ([`plot_style`]), rapier
//! helpers and the 2 kHz servo step ([`rapier_util`]), seeded noise
//! ([`noise`]) and the worker threads for independent runs ([`workers`]). Gravity, where a
//! scene has it, is deflect-core's [`deflect_core::units::GRAVITY_Z_DOWN`].
#![deny(missing_docs)]
// No input may kill the process: errors are returned, never panicked (tests may unwrap).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

pub mod mcap_log;
pub mod noise;
pub mod npz_stream;
pub mod plot_style;
pub mod rapier_util;
pub mod scenes;
pub mod summary;
pub mod urdf_arm;
pub mod workers;

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
