//! Loaders (`std`): every file format deflect reads, apart from the algorithms that use what
//! they load. Each format has a `from_str` on the text and a `from_path` on a file; the
//! bindings and the testbed call these and never read files themselves. Files in units other
//! than SI say so (a parameter or a column name) and are converted here.
//!
//! | module | format | result |
//! |---|---|---|
//! | [`urdf`] (`urdf`) | URDF + stiffness TOML | [`crate::SerialRobot`] |
//! | [`stiffness`] (`urdf`) | stiffness TOML `[[virtual_joint]]` | specs |
//! | [`controller`] (`urdf`) | stiffness TOML `[controller]` | [`crate::controller::Convention`] |
//! | [`drive`] (`urdf`) | drive-train TOML `[[joint]]` + URDF masses | [`crate::drivetrain::Model`] |
//! | [`gcode`] | RS274/NGC G-code as LinuxCNC reads it (the CAM dialect and the NGC language) | [`crate::machining::Program`], a word report |
//! | [`points_csv`] | tool points with feed and spindle per row | [`crate::machining::Program`] |
//! | [`tool_table`] | LinuxCNC `.tbl`, or TOML | [`crate::machining::tools::ToolTable`] |
//! | [`job_out`] (writer) | compensated G-code, samples CSV | from [`crate::machining::job::Report`] |
//! | [`ply`] (writer) | the predicted part as a mesh with its deviation | from [`crate::machining::dexel::surface::SurfaceMesh`] |
//! | [`apt`] | APT / CL data with tool vectors (five-axis programs), cutters | [`crate::machining::Program`] |
//! | [`map_csv`] | the paper's coefficient tables; static tests to fit | [`crate::ComplianceMap`] |
//! | [`map_json`] | versioned JSON of a map (version 2: an N-D grid map) | [`crate::ComplianceMap`], [`crate::compliance_map::GridMap`] |
//! | [`grid_csv`] | static tests on a 1-4 D grid, axes named by their columns | [`crate::compliance_map::GridMap`] |

pub mod apt;
#[cfg(feature = "urdf")]
pub mod controller;
pub(crate) mod decimate;
#[cfg(feature = "urdf")]
pub mod drive;
pub mod gcode;
pub mod grid_csv;
pub mod job_out;
pub mod map_csv;
pub mod map_json;
#[cfg(feature = "urdf")]
mod origin;
pub mod ply;
pub mod points_csv;
pub mod robot_program;
#[cfg(feature = "urdf")]
pub mod stiffness;
pub mod tool_table;
#[cfg(feature = "urdf")]
pub mod urdf;
#[cfg(feature = "urdf")]
mod xml;

use std::path::Path;
use std::string::{String, ToString};

use crate::error::LoadError;

/// Largest text file (or text) a loader reads \[bytes\]: 16 MiB. A URDF with meshes
/// referenced by name, a stiffness file or a map table are kilobytes; a larger input is
/// refused before it is read or parsed ([`LoadError::TooLarge`]).
pub const MAX_FILE_BYTES: usize = 16 << 20;

/// Refuses a text over [`MAX_FILE_BYTES`].
pub(crate) fn check_size(what: &str, text: &str) -> Result<(), LoadError> {
    if text.len() > MAX_FILE_BYTES {
        return Err(LoadError::TooLarge {
            what: std::format!("{what} size (bytes)"),
            limit: MAX_FILE_BYTES,
            got: text.len(),
        });
    }
    Ok(())
}

/// Reads a whole text file of at most [`MAX_FILE_BYTES`] (UTF-8), naming it in the error:
/// what every loader reads its file with, for callers that keep the text (a program and its
/// word report).
pub fn read_text_file(path: &Path) -> Result<String, LoadError> {
    read_text(path)
}

/// [`read_text_file`] for a G-code program: bytes that are not UTF-8 (a Latin-1 comment of a
/// European post) become U+FFFD instead of refusing the file, as LinuxCNC reads bytes.
pub fn read_text_lossy(path: &Path) -> Result<String, LoadError> {
    match read_bytes(path) {
        Ok(bytes) => Ok(String::from_utf8_lossy(&bytes).into_owned()),
        Err(e) => Err(e),
    }
}

/// Reads a whole text file, naming it in the error; reads at most [`MAX_FILE_BYTES`] + 1
/// bytes, so a huge file is refused, not read, and only a regular file (a FIFO, device or
/// directory is refused before it is opened).
pub(crate) fn read_text(path: &Path) -> Result<String, LoadError> {
    let bytes = read_bytes(path)?;
    String::from_utf8(bytes).map_err(|e| LoadError::Io {
        path: path.display().to_string(),
        message: std::format!("not UTF-8 text: {e}"),
    })
}

/// The bytes of a file of at most [`MAX_FILE_BYTES`] (a larger or endless one refused).
fn read_bytes(path: &Path) -> Result<std::vec::Vec<u8>, LoadError> {
    use std::io::Read;
    let io = |e: std::io::Error| LoadError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    // Only a regular file: opening a FIFO blocks until a writer comes (forever, holding
    // Python's GIL), and a device or directory never reads as a file.
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(LoadError::Io {
            path: path.display().to_string(),
            message: "not a regular file (a directory, FIFO, socket or device)".into(),
        });
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = std::vec::Vec::new();
    file.take(MAX_FILE_BYTES as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() > MAX_FILE_BYTES {
        return Err(LoadError::TooLarge {
            what: std::format!(
                "{} size (bytes, read up to one past the limit)",
                path.display()
            ),
            limit: MAX_FILE_BYTES,
            got: bytes.len(),
        });
    }
    Ok(bytes)
}
