//! The inputs the commands share, read and checked before any work: text files and programs
//! by flag, the robot (a chain, or a rapier arm) from `--urdf`/`--stiffness` or the built-in
//! KR 300, the cutter and material of the tool flags, an APT program's tools. Every error
//! names the flag or the file.

use std::path::Path;

use deflect_core::LoadError;
use deflect_core::io::{stiffness, urdf};
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_sim::urdf_arm::{ArmSpec, KR300_STIFFNESS, KR300_URDF, arm_spec};

use crate::cli::{CliError, ToolArgs};

/// Largest input file read \[bytes\].
const MAX_FILE: u64 = 16 << 20;

/// Checks an input file given by `flag` before any work: it exists and is a regular file (a
/// directory, FIFO or device could fail late, block or never end). Otherwise a usage error
/// naming the flag, the path and what was `expected`.
pub fn input_file(flag: &str, path: &Path, expected: &str) -> Result<(), CliError> {
    let meta = std::fs::metadata(path).map_err(|e| {
        CliError::Usage(format!(
            "{flag} {}: cannot open the {expected}: {e}",
            path.display()
        ))
    })?;
    if meta.is_file() {
        Ok(())
    } else {
        Err(CliError::Usage(format!(
            "{flag} {}: not a regular file; expected the {expected}",
            path.display()
        )))
    }
}

/// A loader's error on the input file of `flag` as a failure naming the flag, the path and
/// what was `expected` (the loaders name the file only in their I/O errors).
pub fn load_error(flag: &str, path: &Path, expected: &str, e: LoadError) -> CliError {
    let detail = match e {
        LoadError::Io { message, .. } => format!("cannot read the {expected}: {message}"),
        other => format!("not a valid {expected}: {other}"),
    };
    CliError::Failure(format!("{flag} {}: {detail}", path.display()))
}

/// Reads a text file of `flag` (regular, at most 16 MiB): a usage error naming the flag and
/// the file otherwise.
pub(crate) fn read_text(flag: &str, path: &Path, expected: &str) -> Result<String, CliError> {
    let bytes = read_bytes(flag, path, expected)?;
    String::from_utf8(bytes).map_err(|e| {
        CliError::Failure(format!(
            "{flag} {}: cannot read the {expected}: not UTF-8 text: {e}",
            path.display()
        ))
    })
}

/// [`read_text`] for a G-code program: bytes that are not UTF-8 (a Latin-1 comment of a
/// European post) become U+FFFD, as LinuxCNC reads bytes.
pub(crate) fn read_program(flag: &str, path: &Path) -> Result<String, CliError> {
    let bytes = read_bytes(flag, path, "G-code program")?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// A program file read by its extension: APT / CL data (`.apt`, `.cl`, `.cls`,
/// `.aptsource`) or G-code (anything else), every error naming the flag and the file; with
/// the cutters an APT program defines (`CUTTER/`; none for G-code).
pub(crate) fn program_and_cutters(
    flag: &str,
    path: &Path,
    options: &deflect_core::io::gcode::GcodeOptions,
) -> Result<
    (
        deflect_core::machining::Program,
        Vec<deflect_core::io::apt::AptCutter>,
    ),
    CliError,
> {
    let text = read_program(flag, path)?;
    let apt = path.extension().and_then(|e| e.to_str()).is_some_and(|e| {
        matches!(
            e.to_ascii_lowercase().as_str(),
            "apt" | "cl" | "cls" | "aptsource"
        )
    });
    let read = if apt {
        deflect_core::io::apt::from_str(&text, options).map(|p| (p.program, p.cutters))
    } else {
        deflect_core::io::gcode::from_str(&text, options).map(|p| (p, Vec::new()))
    };
    read.map_err(|e| CliError::Failure(format!("{flag} {}: {e}", path.display())))
}

/// The bytes of an input file of at most `MAX_FILE` bytes, every error naming the flag.
fn read_bytes(flag: &str, path: &Path, expected: &str) -> Result<Vec<u8>, CliError> {
    input_file(flag, path, expected)?;
    let len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    if len > MAX_FILE {
        return Err(CliError::Usage(format!(
            "{flag} {}: {len} bytes; expected the {expected} of at most {MAX_FILE} bytes",
            path.display()
        )));
    }
    std::fs::read(path).map_err(|e| {
        CliError::Failure(format!(
            "{flag} {}: cannot read the {expected}: {e}",
            path.display()
        ))
    })
}

/// A robot read for `atlas` and `job`: the chain, its name for messages, whether it is the
/// built-in KR 300.
pub(crate) struct LoadedRobot {
    pub robot: deflect_core::SerialRobot,
    pub name: String,
    pub builtin: bool,
}

/// Reads `--urdf`/`--stiffness` (default: the built-in KR 300) and builds the chain from
/// `--base` to `--tip` (default "tcp" on the KR 300, else the URDF's deepest leaf); every
/// error names the flag or the file.
pub(crate) fn load_robot(
    urdf_path: Option<&Path>,
    stiffness_path: Option<&Path>,
    base: Option<&str>,
    tip: Option<&str>,
) -> Result<LoadedRobot, CliError> {
    const URDF: &str = "robot URDF";
    const STIFF: &str = "stiffness TOML (deflect's virtual-joint format)";
    let builtin = urdf_path.is_none();
    let (urdf_text, stiff_text) = match (urdf_path, stiffness_path) {
        (Some(u), Some(s)) => (
            read_text("--urdf", u, URDF)?,
            read_text("--stiffness", s, STIFF)?,
        ),
        _ => (KR300_URDF.to_string(), KR300_STIFFNESS.to_string()),
    };
    let name = urdf_path.map_or("the built-in KR 300 URDF".to_string(), |p| {
        format!("--urdf {}", p.display())
    });
    let parsed = urdf::parse(&urdf_text)
        .map_err(|e| CliError::Failure(format!("{name}: not a valid {URDF}: {e}")))?;
    let tip = match (tip, builtin) {
        (Some(t), _) => t.to_string(),
        (None, true) => "tcp".to_string(),
        (None, false) => {
            deepest_leaf(&parsed, base).map_err(|e| CliError::Usage(format!("--tip: {e}")))?
        }
    };
    let robot = deflect_core::SerialRobot::from_str(&urdf_text, &stiff_text, base, &tip)
        .map_err(|e| CliError::Failure(format!("{name}, tip {tip}: {e}")))?;
    Ok(LoadedRobot {
        robot,
        name: if builtin {
            "KR 300 R2500".to_string()
        } else {
            parsed.name.clone()
        },
        builtin,
    })
}

/// The deepest leaf link of the URDF (the default tip); an error naming the candidates if two
/// are equally deep.
pub(crate) fn deepest_leaf(robot: &urdf_rs::Robot, base: Option<&str>) -> Result<String, String> {
    let parent_of = |link: &str| {
        robot
            .joints
            .iter()
            .find(|j| j.child.link == link)
            .map(|j| j.parent.link.as_str())
    };
    let mut best: Vec<(usize, &str)> = Vec::new();
    for l in &robot.links {
        if robot.joints.iter().any(|j| j.parent.link == l.name) {
            continue;
        }
        let (mut depth, mut at) = (0usize, l.name.as_str());
        while Some(at) != base {
            match parent_of(at) {
                Some(p) if depth <= robot.joints.len() => {
                    depth += 1;
                    at = p;
                }
                _ => break,
            }
        }
        best.push((depth, l.name.as_str()));
    }
    best.sort_by_key(|b| std::cmp::Reverse(b.0));
    match best.as_slice() {
        [(d, name), (d2, other), ..] if d == d2 => Err(format!(
            "the URDF has several deepest leaf links ({name}, {other}, ...): name the TCP link \
             with --tip"
        )),
        [(_, name), ..] => Ok((*name).to_string()),
        [] => Err("the URDF has no links".into()),
    }
}

/// An arm read for the rapier scenes (`serial`, `milling`): its bodies and model, the parsed
/// URDF, the TCP link, its name in messages (the flag and file) and whether it is built in.
pub(crate) struct ArmFiles {
    pub spec: ArmSpec,
    pub parsed: urdf_rs::Robot,
    pub tip: String,
    pub urdf_name: String,
    pub builtin: bool,
}

/// Reads `--urdf`/`--stiffness` (default: the built-in KR 300) and builds the arm from
/// `--base` to `--tip` (default "tcp" on the KR 300, else the URDF's deepest leaf); each file
/// is checked alone first, so that an error names the file it is in.
pub(crate) fn load_arm(
    urdf_path: Option<&Path>,
    stiffness_path: Option<&Path>,
    base: Option<&str>,
    tip: Option<&str>,
) -> Result<ArmFiles, CliError> {
    const URDF: &str = "robot URDF";
    const STIFF: &str = "stiffness TOML (deflect's virtual-joint format)";
    let builtin = urdf_path.is_none();
    let urdf_text = match urdf_path {
        Some(p) => read_text("--urdf", p, URDF)?,
        None => KR300_URDF.to_string(),
    };
    let stiff_text = match stiffness_path {
        Some(p) => read_text("--stiffness", p, STIFF)?,
        None => KR300_STIFFNESS.to_string(),
    };
    let urdf_name = urdf_path.map_or("the built-in KR 300 URDF".to_string(), |p| {
        format!("--urdf {}", p.display())
    });
    let stiff_name = stiffness_path.map_or("the built-in KR 300 stiffness file".to_string(), |p| {
        format!("--stiffness {}", p.display())
    });
    let parsed = urdf::parse(&urdf_text)
        .map_err(|e| CliError::Failure(format!("{urdf_name}: not a valid {URDF}: {e}")))?;
    stiffness::from_str(&stiff_text)
        .map_err(|e| CliError::Failure(format!("{stiff_name}: not a valid {STIFF}: {e}")))?;
    let tip = match (tip, builtin) {
        (Some(t), _) => t.to_string(),
        (None, true) => "tcp".to_string(),
        (None, false) => {
            deepest_leaf(&parsed, base).map_err(|e| CliError::Usage(format!("--tip: {e}")))?
        }
    };
    let spec = arm_spec(&urdf_text, &stiff_text, base, &tip).map_err(|e| {
        CliError::Failure(format!("{urdf_name} with {stiff_name}, tip {tip}: {}", e.0))
    })?;
    Ok(ArmFiles {
        spec,
        parsed,
        tip,
        urdf_name,
        builtin,
    })
}

/// The tool table of an APT program's `CUTTER/` statements after `LOADTL` (the last per tool
/// number; the flutes and helix of --flutes/--helix, the length of --flute-length), or none.
pub(crate) fn apt_tools(
    (flutes, helix, length): (u32, f64, f64),
    cutters: &[deflect_core::io::apt::AptCutter],
    name: &str,
) -> Result<Option<deflect_core::machining::tools::ToolTable>, CliError> {
    use deflect_core::machining::tools::{ToolSpec, ToolTable};
    if cutters.iter().all(|c| c.tool == 0) {
        return Ok(None);
    }
    let mut specs: Vec<ToolSpec> = Vec::new();
    for c in cutters.iter().filter(|c| c.tool > 0) {
        let tool = Tool::new(c.diameter, flutes, helix)
            .map_err(|e| CliError::Failure(format!("{name} line {}: CUTTER: {e}", c.line)))?;
        let spec = ToolSpec {
            // T0 (a cutter before any LOADTL) is the program's tool before any change.
            number: c.tool,
            tool,
            shape: c.shape,
            length,
            name: format!("CUTTER line {}", c.line),
        };
        specs.retain(|s| s.number != c.tool);
        specs.push(spec);
    }
    ToolTable::new(specs)
        .map(Some)
        .map_err(|e| CliError::Failure(format!("{name}: its CUTTER statements: {e}")))
}

/// The cutter and the material of `--diameter/--flutes/--helix` and `--coefficients` (ranges
/// checked by [`crate::cli::ToolArgs::check`]; the core's checks name what else is wrong).
pub(crate) fn tool_and_material(a: &ToolArgs) -> Result<(Tool, Coefficients), CliError> {
    let tool = Tool::new(a.diameter * 1e-3, a.flutes, a.helix.to_radians())
        .map_err(|e| CliError::Usage(format!("--diameter/--flutes/--helix: {e}")))?;
    let coefficients = match a.coefficients.as_deref() {
        Some(&[tc, rc, ac, te, re, ae]) => {
            Coefficients::new(tc * 1e6, rc * 1e6, ac * 1e6, te * 1e3, re * 1e3, ae * 1e3)
                .map_err(|e| CliError::Usage(format!("--coefficients: {e}")))?
        }
        Some(_) => return Err(CliError::Usage("--coefficients: expected 6 values".into())),
        None => Coefficients::AL7075_T6_CARBIDE,
    };
    Ok((tool, coefficients))
}
