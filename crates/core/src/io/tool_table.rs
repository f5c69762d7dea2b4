//! Tool tables (`std`): a program's `T` numbers mapped to cutters, in LinuxCNC's `.tbl` form
//! or in a TOML form that says everything about each cutter.
//!
//! LinuxCNC's `.tbl` (one tool a line, words in any order, `;` starts the comment):
//!
//! ```text
//! T1 P1 D6 Z45.2 ;6 mm flat end mill
//! T2 P2 D10 ;10 mm
//! ```
//!
//! `T` (number) is required; `D` is the diameter and `Z` the tool length, in the table's unit
//! ([`TblOptions::units`], mm by default: LinuxCNC's machine unit); `P` (pocket), `X` `Y` `A`
//! `B` `C` `U` `V` `W` (other offsets), `I` `J` `Q` (lathe angles and orientation) are read
//! and not used. A `.tbl` says nothing of flutes, helix or the end's shape: every tool takes
//! [`TblOptions::flutes`] and [`TblOptions::helix`] and a flat end.
//!
//! The TOML form (lengths in its `units`, angles in degrees):
//!
//! ```toml
//! units = "mm"             # "mm" or "inch": diameter, corner_radius, length
//! [[tool]]
//! number = 1
//! diameter = 6.0
//! flutes = 3
//! helix_deg = 30.0         # optional, default 0
//! shape = "bull-nose"      # "flat" (default), "ball" or "bull-nose"
//! corner_radius = 0.5      # bull-nose only
//! length = 45.2            # optional, default 0
//! name = "6 mm torus"      # optional
//! ```

use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use serde::Deserialize;

use crate::error::LoadError;
use crate::machining::cutting::Tool;
use crate::machining::tools::{MAX_TOOLS, ToolShape, ToolSpec, ToolTable};
use crate::units::LengthUnit;

/// What a `.tbl` does not say.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TblOptions {
    /// The table's length unit (LinuxCNC's machine unit). Default: mm.
    pub units: LengthUnit,
    /// Flutes of every tool. Default: 3.
    pub flutes: u32,
    /// Helix angle of every tool \[rad\]. Default: 0.
    pub helix: f64,
}

impl Default for TblOptions {
    fn default() -> Self {
        Self {
            units: LengthUnit::Millimetre,
            flutes: 3,
            helix: 0.0,
        }
    }
}

fn invalid(element: String, field: &'static str, expected: &str, got: String) -> LoadError {
    LoadError::InvalidValue {
        element,
        field,
        expected: expected.to_string(),
        got,
    }
}

/// Reads a LinuxCNC `.tbl` text (at most [`MAX_TOOLS`] tools).
pub fn tbl_from_str(text: &str, options: &TblOptions) -> Result<ToolTable, LoadError> {
    super::check_size("tool table", text)?;
    let unit = options.units.to_metre();
    let mut tools = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let element = || std::format!("tool table line {line}");
        let body = raw.split(';').next().unwrap_or("");
        let comment = raw.split_once(';').map_or("", |(_, c)| c.trim());
        if body.trim().is_empty() {
            continue;
        }
        let (mut number, mut diameter, mut length) = (None, None, 0.0);
        for word in body.split_whitespace() {
            let mut chars = word.chars();
            let letter = chars.next().unwrap_or(' ').to_ascii_uppercase();
            let value: f64 = chars.as_str().parse().map_err(|_| {
                invalid(
                    element(),
                    "word",
                    "a letter and a number (T1, D6.0)",
                    std::format!("{word:?}"),
                )
            })?;
            if !value.is_finite() {
                return Err(invalid(
                    element(),
                    "word",
                    "a finite number",
                    std::format!("{word:?}"),
                ));
            }
            match letter {
                'T' => {
                    if value.fract() != 0.0
                        || !(1.0..=f64::from(crate::machining::MAX_TOOL_NUMBER)).contains(&value)
                    {
                        return Err(invalid(
                            element(),
                            "T",
                            "a tool number in 1..=99999",
                            word.to_string(),
                        ));
                    }
                    number = Some(value as u32);
                }
                'D' => diameter = Some(value * unit),
                'Z' => length = value * unit,
                'P' | 'X' | 'Y' | 'A' | 'B' | 'C' | 'U' | 'V' | 'W' | 'I' | 'J' | 'Q' => {}
                _ => {
                    return Err(invalid(
                        element(),
                        "word",
                        "T, P, D, X, Y, Z, A, B, C, U, V, W, I, J or Q",
                        std::format!("{word:?}"),
                    ));
                }
            }
        }
        let Some(number) = number else {
            return Err(invalid(
                element(),
                "T",
                "a tool number T",
                "none".to_string(),
            ));
        };
        let Some(diameter) = diameter else {
            return Err(invalid(
                element(),
                "D",
                "the tool's diameter D > 0",
                "none".to_string(),
            ));
        };
        if tools.len() >= MAX_TOOLS {
            return Err(LoadError::TooLarge {
                what: "tool table tools".to_string(),
                limit: MAX_TOOLS,
                got: tools.len() + 1,
            });
        }
        tools.push(ToolSpec {
            number,
            tool: Tool {
                diameter,
                flutes: options.flutes,
                helix: options.helix,
            },
            shape: ToolShape::Flat,
            length,
            name: comment.to_string(),
        });
    }
    ToolTable::new(tools).map_err(LoadError::Build)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlTable {
    units: String,
    #[serde(default)]
    tool: Vec<TomlTool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlTool {
    number: u32,
    diameter: f64,
    flutes: u32,
    #[serde(default)]
    helix_deg: f64,
    #[serde(default)]
    shape: Option<String>,
    #[serde(default)]
    corner_radius: Option<f64>,
    #[serde(default)]
    length: f64,
    #[serde(default)]
    name: String,
}

/// Reads the TOML form (see the module docs).
pub fn toml_from_str(text: &str) -> Result<ToolTable, LoadError> {
    super::check_size("tool table", text)?;
    let t: TomlTable = toml::from_str(text).map_err(|e| LoadError::StiffnessParse {
        message: std::format!("tool table: {e}"),
    })?;
    let unit = match t.units.as_str() {
        "mm" => LengthUnit::Millimetre,
        "inch" | "in" => LengthUnit::Inch,
        "m" => LengthUnit::Metre,
        other => {
            return Err(LoadError::UnknownUnit {
                quantity: "length",
                unit: other.to_string(),
            });
        }
    }
    .to_metre();
    if t.tool.len() > MAX_TOOLS {
        return Err(LoadError::TooLarge {
            what: "tool table tools".to_string(),
            limit: MAX_TOOLS,
            got: t.tool.len(),
        });
    }
    let mut tools = Vec::with_capacity(t.tool.len());
    for (i, e) in t.tool.into_iter().enumerate() {
        let element = || std::format!("[[tool]] #{i} (T{})", e.number);
        let shape = match (e.shape.as_deref().unwrap_or("flat"), e.corner_radius) {
            ("flat", None) => ToolShape::Flat,
            ("ball", None) => ToolShape::Ball,
            ("bull-nose", Some(r)) => ToolShape::BullNose {
                corner_radius: r * unit,
            },
            ("bull-nose", None) => {
                return Err(invalid(
                    element(),
                    "corner_radius",
                    "a corner radius for a bull-nose tool",
                    "none".to_string(),
                ));
            }
            ("flat" | "ball", Some(r)) => {
                return Err(invalid(
                    element(),
                    "corner_radius",
                    "no corner radius (only shape = \"bull-nose\" has one)",
                    std::format!("{r}"),
                ));
            }
            (other, _) => {
                return Err(invalid(
                    element(),
                    "shape",
                    "\"flat\", \"ball\" or \"bull-nose\"",
                    std::format!("{other:?}"),
                ));
            }
        };
        tools.push(ToolSpec {
            number: e.number,
            tool: Tool {
                diameter: e.diameter * unit,
                flutes: e.flutes,
                helix: e.helix_deg.to_radians(),
            },
            shape,
            length: e.length * unit,
            name: e.name,
        });
    }
    ToolTable::new(tools).map_err(LoadError::Build)
}

/// Reads a tool table file: the TOML form when its name ends in `.toml`, LinuxCNC's `.tbl`
/// otherwise (at most [`super::MAX_FILE_BYTES`]).
pub fn from_path(path: &Path, options: &TblOptions) -> Result<ToolTable, LoadError> {
    let text = super::read_text(path)?;
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
    {
        toml_from_str(&text)
    } else {
        tbl_from_str(&text, options)
    }
}
