//! The tools a multi-tool program uses, by their `T` number: each tool's cutter (diameter,
//! flutes, helix, flat / ball / bull-nose end), and its length, which a robot's TCP carries
//! (recorded, not applied: the program's points are the tool tip's). Read from LinuxCNC's
//! `.tbl` or from a TOML table by [`crate::io::tool_table`].

use alloc::string::String;
use alloc::vec::Vec;

use super::cutting::Tool;
use super::stock::Cutter;
use crate::error::BuildError;

/// Most tools one table holds: 1,000 (LinuxCNC's default pocket count is 56).
pub const MAX_TOOLS: usize = 1_000;

pub use super::profile::ToolShape;

/// One tool of a table.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolSpec {
    /// Its `T` number, `1..=MAX_TOOL_NUMBER`.
    pub number: u32,
    /// The cutter as the force model sees it (diameter \[m\], flutes, helix \[rad\]).
    pub tool: Tool,
    /// Flat, ball or bull-nose end.
    pub shape: ToolShape,
    /// Tool length \[m\] (the table's Z offset; recorded: a robot's TCP carries it).
    pub length: f64,
    /// The table's comment or name (may be empty).
    pub name: String,
}

impl ToolSpec {
    /// The cutter the z-map is lowered with. A bull-nose end cuts the z-map as a flat end
    /// mill of its diameter (the stock model has flat and ball ends; the corner's fillet,
    /// at most `corner_radius` high, is left out).
    pub fn cutter(&self) -> Cutter {
        let radius = 0.5 * self.tool.diameter;
        match self.shape {
            ToolShape::Ball => Cutter::Ball { radius },
            ToolShape::Flat | ToolShape::BullNose { .. } => Cutter::Flat { radius },
        }
    }

    /// Checks the number, the cutter, the shape and the length
    /// ([`BuildError::InvalidParameter`] naming the field).
    pub fn validate(&self) -> Result<(), BuildError> {
        let number = self.number;
        if !(1..=super::MAX_TOOL_NUMBER).contains(&number) {
            return Err(BuildError::InvalidParameter {
                what: "tool number",
                value: f64::from(number),
                expected: "1..=MAX_TOOL_NUMBER (99999)",
            });
        }
        self.tool.validate()?;
        if let ToolShape::BullNose { corner_radius } = self.shape
            && !(corner_radius > 0.0 && corner_radius < 0.5 * self.tool.diameter)
        {
            return Err(BuildError::InvalidParameter {
                what: "bull-nose corner radius",
                value: corner_radius,
                expected: "in (0, diameter / 2) m",
            });
        }
        if !(self.length.is_finite() && self.length.abs() <= super::MAX_COORDINATE) {
            return Err(BuildError::InvalidParameter {
                what: "tool length",
                value: self.length,
                expected: "finite, within +-1000 m",
            });
        }
        Ok(())
    }
}

/// Tools by number, each number once, at most [`MAX_TOOLS`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ToolTable {
    tools: Vec<ToolSpec>,
}

impl ToolTable {
    /// A checked table: each tool valid ([`ToolSpec::validate`]), no number twice
    /// ([`BuildError::InvalidEntry`] naming the index), at most [`MAX_TOOLS`].
    pub fn new(mut tools: Vec<ToolSpec>) -> Result<Self, BuildError> {
        if tools.len() > MAX_TOOLS {
            return Err(BuildError::Budget {
                what: "tools in a table",
                budget: "MAX_TOOLS",
                limit: MAX_TOOLS,
                requested: tools.len(),
            });
        }
        for t in &tools {
            t.validate()?;
        }
        tools.sort_by_key(|t| t.number);
        if let Some(w) = tools
            .windows(2)
            .find(|w| w.first().map(|t| t.number) == w.get(1).map(|t| t.number))
        {
            let n = w.first().map_or(0, |t| t.number);
            return Err(BuildError::InvalidEntry {
                what: "tool table (index: the tool number given twice)",
                index: n as usize,
                value: f64::from(n),
                expected: "each tool number once",
            });
        }
        Ok(Self { tools })
    }

    /// The tool numbered `number`, if the table has it.
    pub fn get(&self, number: u32) -> Option<&ToolSpec> {
        self.tools
            .binary_search_by_key(&number, |t| t.number)
            .ok()
            .and_then(|i| self.tools.get(i))
    }

    /// The tools, by increasing number.
    pub fn tools(&self) -> &[ToolSpec] {
        &self.tools
    }

    /// Whether the table is empty.
    pub fn is_empty(&self) -> bool {
        self.tools.is_empty()
    }

    /// The number of tools.
    pub fn len(&self) -> usize {
        self.tools.len()
    }
}
