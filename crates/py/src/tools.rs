//! `ToolTable`: a program's `T` numbers mapped to cutters (deflect-core's
//! `machining::tools`, read by `io::tool_table`): LinuxCNC's `.tbl` or the TOML form.

use deflect_core::io::tool_table::{self, TblOptions};
use deflect_core::machining::cutting::Tool;
use deflect_core::machining::tools::{ToolShape, ToolSpec, ToolTable as CoreTable};
use deflect_core::units::LengthUnit;
use pyo3::prelude::*;

use crate::InputError;
use crate::errors::{build_err, load_err};

/// One tool as Python sees it and pickles it: (number, diameter [m], flutes, helix [rad],
/// shape "flat" / "ball" / "bull-nose", corner radius [m] (0 unless bull-nose), length [m],
/// name).
pub(crate) type ToolState = (u32, f64, u32, f64, String, f64, f64, String);

/// A tool table: each tool's number, cutter (diameter [m], flutes, helix [rad], flat / ball /
/// bull-nose end with its corner radius [m]), length [m] (recorded: a robot's TCP carries
/// it) and name. Read from LinuxCNC's `.tbl` (`T1 P1 D6 Z0 ;comment`, in `units`; flutes and
/// helix are not in a `.tbl`: `flutes`, `helix` [rad] serve every tool, ends flat) or from
/// the TOML form (`units = "mm"`, `[[tool]] number, diameter, flutes, helix_deg, shape,
/// corner_radius, length, name`). `MachiningJob(tools=...)` cuts each move with the tool in
/// the spindle.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct ToolTable {
    pub(crate) inner: CoreTable,
}

fn tbl_options(units: &str, flutes: u32, helix: f64) -> PyResult<TblOptions> {
    let units = match units {
        "mm" => LengthUnit::Millimetre,
        "in" => LengthUnit::Inch,
        "m" => LengthUnit::Metre,
        other => {
            return Err(InputError::new_err(format!(
                "units must be \"mm\", \"in\" or \"m\" (the .tbl's length unit), got {other:?}"
            )));
        }
    };
    Ok(TblOptions {
        units,
        flutes,
        helix,
    })
}

pub(crate) fn tool_state(t: &ToolSpec) -> ToolState {
    let corner = match t.shape {
        ToolShape::BullNose { corner_radius } => corner_radius,
        _ => 0.0,
    };
    (
        t.number,
        t.tool.diameter,
        t.tool.flutes,
        t.tool.helix,
        t.shape.name().to_string(),
        corner,
        t.length,
        t.name.clone(),
    )
}

pub(crate) fn from_states(states: Vec<ToolState>) -> PyResult<CoreTable> {
    let tools = states
        .into_iter()
        .map(|(number, diameter, flutes, helix, shape, corner, length, name)| {
            let shape = match shape.as_str() {
                "flat" => ToolShape::Flat,
                "ball" => ToolShape::Ball,
                "bull-nose" => ToolShape::BullNose {
                    corner_radius: corner,
                },
                other => {
                    return Err(InputError::new_err(format!(
                        "tool T{number}: shape {other:?}; expected \"flat\", \"ball\" or \"bull-nose\""
                    )));
                }
            };
            Ok(ToolSpec {
                number,
                tool: Tool {
                    diameter,
                    flutes,
                    helix,
                },
                shape,
                length,
                name,
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    CoreTable::new(tools).map_err(build_err)
}

#[pymethods]
impl ToolTable {
    /// Reads a tool table file: the TOML form when the name ends in `.toml`, LinuxCNC's
    /// `.tbl` otherwise (`units`, `flutes` and `helix` [rad] for the `.tbl`).
    #[staticmethod]
    #[pyo3(signature = (path, *, units="mm", flutes=3, helix=0.0))]
    fn from_file(
        py: Python<'_>,
        path: std::path::PathBuf,
        units: &str,
        flutes: u32,
        helix: f64,
    ) -> PyResult<Self> {
        let o = tbl_options(units, flutes, helix)?;
        let inner = py
            .detach(|| tool_table::from_path(&path, &o))
            .map_err(load_err)?;
        Ok(Self { inner })
    }

    /// Same as `from_file`, from the text: `format` "tbl" (LinuxCNC's) or "toml".
    #[staticmethod]
    #[pyo3(signature = (text, *, format="tbl", units="mm", flutes=3, helix=0.0))]
    fn from_text(
        #[pyo3(from_py_with = crate::args::text::text)] text: String,
        format: &str,
        units: &str,
        flutes: u32,
        helix: f64,
    ) -> PyResult<Self> {
        let text = text.as_str();
        let inner = match format {
            "tbl" => tool_table::tbl_from_str(text, &tbl_options(units, flutes, helix)?),
            "toml" => tool_table::toml_from_str(text),
            other => {
                return Err(InputError::new_err(format!(
                    "format must be \"tbl\" or \"toml\", got {other:?}"
                )));
            }
        }
        .map_err(load_err)?;
        Ok(Self { inner })
    }

    /// Pickling and copy.deepcopy: the tools as plain values, rebuilt and checked.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (Vec<ToolState>,))> {
        let rebuild = slf.get_type().getattr("_from_state")?;
        Ok((rebuild, (slf.get().tools(),)))
    }

    /// The table of a pickled state (see `__reduce__`), checked.
    #[staticmethod]
    fn _from_state(state: Vec<ToolState>) -> PyResult<Self> {
        Ok(Self {
            inner: from_states(state)?,
        })
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.inner == other.inner
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    fn __repr__(&self) -> String {
        let numbers: Vec<String> = self
            .inner
            .tools()
            .iter()
            .map(|t| format!("T{}", t.number))
            .collect();
        format!("ToolTable({})", numbers.join(", "))
    }

    /// The tool numbers, ascending.
    #[getter]
    fn numbers(&self) -> Vec<u32> {
        self.inner.tools().iter().map(|t| t.number).collect()
    }

    /// Every tool: (number, diameter [m], flutes, helix [rad], shape, corner radius [m],
    /// length [m], name), by number.
    #[getter]
    fn tools(&self) -> Vec<ToolState> {
        self.inner.tools().iter().map(tool_state).collect()
    }
}

/// Adds `ToolTable` to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ToolTable>()
}
