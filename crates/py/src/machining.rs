//! Robot machining programs: G-code, APT / CL data and tool points read into numpy arrays
//! (`GcodeProgram`, deflect-core's `io::gcode`, `io::apt`, `io::points_csv`), with the tool
//! axis of every move. Everything SI: m, m/s, rev/s.

use deflect_core::io::apt::{self, AptCutter};
use deflect_core::io::gcode::{self, Dialect, GcodeOptions, WordStatus, WordUse};
use deflect_core::io::points_csv;
use deflect_core::machining::tools::ToolShape;
use deflect_core::machining::{Motion, Operation, PathControl, Plane, Program};
use deflect_core::units::LengthUnit;
use nalgebra::Vector3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::InputError;
use crate::args;
use crate::arrays::{try_rows, vector};
use crate::errors::{build_err, load_err};
use crate::program_state::{
    CutterState, MoveState, ProgramState, WordState, corner, from_move_state, move_state,
};

/// A machining program read from RS274/NGC G-code as LinuxCNC reads it (tools, work
/// offsets, planes, canned cycles, parameters, subroutines, control flow): its moves as
/// arrays, SI, in the program's machine frame (= its own coordinates unless it sets work
/// offsets). `dialect`: "linuxcnc" (default), "grbl" (ignores an arc's off-plane centre
/// word), "fanuc" (axis words after G80 move in the last G0-G3 mode; '%' lines anywhere).
/// What has no meaning on a robot (cutter compensation, probing, threading, lathe modes,
/// rotary axes) raises `LoadError` naming the word, the line and the column. `words` lists
/// every word the program uses and what the reader does with it.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct GcodeProgram {
    pub(crate) inner: Program,
    words: Vec<WordUse>,
    cutters: Vec<AptCutter>,
}

fn dialect(name: &str) -> PyResult<Dialect> {
    Dialect::parse(name).ok_or_else(|| {
        InputError::new_err(format!(
            "dialect must be \"linuxcnc\", \"grbl\" or \"fanuc\", got {name:?}"
        ))
    })
}

fn options(
    start: Option<&Bound<'_, PyAny>>,
    units: &str,
    dialect_name: &str,
    block_delete: bool,
    kinematics: Option<&Bound<'_, PyAny>>,
) -> PyResult<GcodeOptions> {
    let units = match units {
        "mm" => LengthUnit::Millimetre,
        "in" => LengthUnit::Inch,
        other => {
            return Err(InputError::new_err(format!(
                "units must be \"mm\" or \"in\" (until the program says G21 or G20), got {other:?}"
            )));
        }
    };
    let start = match start {
        Some(s) => Vector3::from_column_slice(&vector(s, "start", 3)?),
        None => Vector3::zeros(),
    };
    Ok(GcodeOptions {
        start,
        units,
        dialect: dialect(dialect_name)?,
        block_delete,
        kinematics: crate::kinematics::kinematics(kinematics)?,
    })
}

fn word_state(w: &WordUse) -> WordState {
    (
        w.word.clone(),
        w.status.name().to_string(),
        w.count,
        w.first_line,
        w.meaning.clone(),
    )
}

/// The word report of a G-code program's text: `(word, status, count, first_line,
/// meaning)` per word, status "honoured" (it shapes the moves), "recorded" (no motion) or
/// "refused"; also for a program the reader refuses.
#[pyfunction]
#[pyo3(signature = (text, *, dialect="linuxcnc"))]
fn gcode_words(
    py: Python<'_>,
    #[pyo3(from_py_with = args::text::text)] text: String,
    dialect: &str,
) -> PyResult<Vec<WordState>> {
    let o = GcodeOptions {
        dialect: self::dialect(dialect)?,
        ..GcodeOptions::default()
    };
    let words = py.detach(|| gcode::words(&text, &o)).map_err(load_err)?;
    Ok(words.iter().map(word_state).collect())
}

impl GcodeProgram {
    fn read(py: Python<'_>, text: &str, o: &GcodeOptions) -> PyResult<Self> {
        let (inner, words) = py
            .detach(|| {
                Ok::<_, deflect_core::LoadError>((
                    gcode::from_str(text, o)?,
                    gcode::words(text, o)?,
                ))
            })
            .map_err(load_err)?;
        Ok(Self {
            inner,
            words,
            cutters: Vec::new(),
        })
    }

    fn points(inner: Program) -> Self {
        Self {
            inner,
            words: Vec::new(),
            cutters: Vec::new(),
        }
    }

    fn apt(py: Python<'_>, text: &str, o: &GcodeOptions) -> PyResult<Self> {
        let p = py.detach(|| apt::from_str(text, o)).map_err(load_err)?;
        Ok(Self {
            inner: p.program,
            words: Vec::new(),
            cutters: p.cutters,
        })
    }
}

#[pymethods]
impl GcodeProgram {
    /// Reads a G-code file. `start` (3,) [m]: where the tool is before the first move
    /// (default the origin); `units`: "mm" or "in" until the program says G21 or G20;
    /// `dialect`: "linuxcnc", "grbl" or "fanuc"; `block_delete`: skip the lines starting with
    /// '/' (default False: they run, as on LinuxCNC); `kinematics`: a five-axis machine whose
    /// A B C words turn the tool axis, `{"tcp": bool, "rotaries": [rotary, rotary]}` with each
    /// rotary `{"word": "A"|"B"|"C", "carrier": "table"|"head", "direction": (3,), "point":
    /// (3,) [m], "limits": (lower, upper) [rad]}` (`tcp`: X Y Z are the tool tip in the
    /// workpiece; default None: A B C may only stay at 0).
    #[staticmethod]
    #[pyo3(signature = (path, *, start=None, units="mm", dialect="linuxcnc", block_delete=false, kinematics=None))]
    fn from_file(
        py: Python<'_>,
        path: std::path::PathBuf,
        start: Option<&Bound<'_, PyAny>>,
        units: &str,
        dialect: &str,
        block_delete: bool,
        kinematics: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let o = options(start, units, dialect, block_delete, kinematics)?;
        let text = py
            .detach(|| deflect_core::io::read_text_lossy(&path))
            .map_err(load_err)?;
        Self::read(py, &text, &o)
    }

    /// Same as `from_file`, from the program's text.
    #[staticmethod]
    #[pyo3(signature = (text, *, start=None, units="mm", dialect="linuxcnc", block_delete=false, kinematics=None))]
    fn from_text(
        py: Python<'_>,
        #[pyo3(from_py_with = args::text::text)] text: String,
        start: Option<&Bound<'_, PyAny>>,
        units: &str,
        dialect: &str,
        block_delete: bool,
        kinematics: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let o = options(start, units, dialect, block_delete, kinematics)?;
        Self::read(py, &text, &o)
    }

    /// Reads an APT / CL file (what CAM systems write for any machine): GOTO with tool
    /// vectors, FEDRAT, RAPID, CIRCLE, SPINDL, LOADTL, CUTTER, MULTAX, UNITS, FINI; an
    /// unknown statement raises `LoadError` naming its line. `start` (3,) [m]: where the
    /// tool is before the first move (unless FROM says); `units`: "mm" or "in" until UNITS/.
    #[staticmethod]
    #[pyo3(signature = (path, *, start=None, units="mm"))]
    fn from_apt_file(
        py: Python<'_>,
        path: std::path::PathBuf,
        start: Option<&Bound<'_, PyAny>>,
        units: &str,
    ) -> PyResult<Self> {
        let o = options(start, units, "linuxcnc", false, None)?;
        let text = py
            .detach(|| deflect_core::io::read_text_lossy(&path))
            .map_err(load_err)?;
        Self::apt(py, &text, &o)
    }

    /// Same as `from_apt_file`, from the program's text.
    #[staticmethod]
    #[pyo3(signature = (text, *, start=None, units="mm"))]
    fn from_apt_text(
        py: Python<'_>,
        #[pyo3(from_py_with = args::text::text)] text: String,
        start: Option<&Bound<'_, PyAny>>,
        units: &str,
    ) -> PyResult<Self> {
        let o = options(start, units, "linuxcnc", false, None)?;
        Self::apt(py, &text, &o)
    }

    /// Reads a tool points CSV file: one straight move per row from the previous point (the
    /// first from `start`), columns `x_mm,y_mm,z_mm` (or `x_m,y_m,z_m`), `feed_mm_min` (or
    /// `feed_m_s`; 0 for a rapid move) and `spindle_rpm`, optionally `i,j,k` (the tool axis).
    /// `LoadError` naming the row.
    #[staticmethod]
    #[pyo3(signature = (path, *, start=None))]
    fn from_points_file(
        path: std::path::PathBuf,
        start: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let o = options(start, "mm", "linuxcnc", false, None)?;
        let inner = points_csv::from_path(&path, &o).map_err(load_err)?;
        Ok(Self::points(inner))
    }

    /// Same as `from_points_file`, from the CSV text.
    #[staticmethod]
    #[pyo3(signature = (text, *, start=None))]
    fn from_points_text(
        #[pyo3(from_py_with = args::text::text)] text: String,
        start: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let o = options(start, "mm", "linuxcnc", false, None)?;
        let inner = points_csv::from_str(&text, &o).map_err(load_err)?;
        Ok(Self::points(inner))
    }

    /// Pickling and copy.deepcopy: the moves and the word report as plain values, rebuilt bit
    /// for bit and checked (`Program::validate`).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, ProgramState)> {
        let rebuild = slf.get_type().getattr("_from_state")?;
        let me = slf.get();
        let state = me.inner.moves.iter().map(move_state).collect();
        let ops = me
            .inner
            .operations
            .iter()
            .map(|o| (o.name.clone(), o.first_move))
            .collect();
        let axes = if me.inner.is_multi_axis() {
            me.inner
                .moves
                .iter()
                .map(|m| (m.start_axis.into(), m.end_axis.into()))
                .collect()
        } else {
            Vec::new()
        };
        let cutters = me
            .cutters
            .iter()
            .map(|c| (c.line, c.tool, c.diameter, corner(c)))
            .collect();
        Ok((
            rebuild,
            (
                state,
                me.words.iter().map(word_state).collect(),
                ops,
                axes,
                cutters,
            ),
        ))
    }

    /// The program of a pickled state (see `__reduce__`), checked.
    #[staticmethod]
    #[pyo3(signature = (state, words, operations=Vec::new(), axes=Vec::new(), cutters=Vec::new()))]
    fn _from_state(
        state: Vec<MoveState>,
        words: Vec<WordState>,
        operations: Vec<(String, usize)>,
        axes: Vec<([f64; 3], [f64; 3])>,
        cutters: Vec<CutterState>,
    ) -> PyResult<Self> {
        if !axes.is_empty() && axes.len() != state.len() {
            return Err(InputError::new_err(format!(
                "pickled program: {} tool axes for {} moves",
                axes.len(),
                state.len()
            )));
        }
        let mut moves = state
            .into_iter()
            .enumerate()
            .map(|(i, m)| from_move_state(i, m))
            .collect::<PyResult<Vec<_>>>()?;
        for (m, (a, b)) in moves.iter_mut().zip(axes) {
            m.start_axis = Vector3::from(a);
            m.end_axis = Vector3::from(b);
        }
        let cutters = cutters
            .into_iter()
            .map(|(line, tool, diameter, r)| {
                let shape = if r == 0.0 {
                    ToolShape::Flat
                } else if r == 0.5 * diameter {
                    ToolShape::Ball
                } else {
                    ToolShape::BullNose { corner_radius: r }
                };
                AptCutter {
                    line,
                    tool,
                    diameter,
                    shape,
                }
            })
            .collect();
        let operations = operations
            .into_iter()
            .map(|(name, first_move)| Operation { name, first_move })
            .collect();
        let inner = Program { moves, operations };
        inner.validate().map_err(build_err)?;
        let words = words
            .into_iter()
            .map(|(word, status, count, first_line, meaning)| {
                let status = match status.as_str() {
                    "honoured" => WordStatus::Honoured,
                    "recorded" => WordStatus::Recorded,
                    "refused" => WordStatus::Refused,
                    other => {
                        return Err(InputError::new_err(format!(
                            "pickled word report: status {other:?}; expected honoured, recorded or refused"
                        )));
                    }
                };
                Ok(WordUse {
                    word,
                    status,
                    count,
                    first_line,
                    meaning,
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        Ok(Self {
            inner,
            words,
            cutters,
        })
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.inner == other.inner
    }

    fn __len__(&self) -> usize {
        self.inner.moves.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "GcodeProgram({} moves, {:.3} m of cutting path)",
            self.inner.moves.len(),
            self.inner.cutting_length()
        )
    }

    /// The program's operations (a CAM toolpath each: a tool change or a comment line
    /// standing alone between moves starts one): `(name, first_move, first_line)` in order.
    #[getter]
    fn operations(&self) -> Vec<(String, usize, usize)> {
        self.inner
            .operations
            .iter()
            .map(|o| {
                let line = self.inner.moves.get(o.first_move).map_or(0, |m| m.line);
                (o.name.clone(), o.first_move, line)
            })
            .collect()
    }

    /// The program line of each move (1-based), (n,).
    #[getter]
    fn line<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| m.line as u64)).into_pyarray(py)
    }

    /// Each move's kind: "rapid", "linear", "arc" or "dwell", (n,) list.
    #[getter]
    fn kind(&self) -> Vec<&'static str> {
        self.inner
            .moves
            .iter()
            .map(|m| match m.motion {
                Motion::Rapid => "rapid",
                Motion::Linear => "linear",
                Motion::Arc { .. } => "arc",
                Motion::Dwell { .. } => "dwell",
            })
            .collect()
    }

    /// Start points (n, 3) [m].
    #[getter]
    fn start<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |m, o| o.copy_from_slice(m.start.as_slice()))
    }

    /// End points (n, 3) [m].
    #[getter]
    fn end<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |m, o| o.copy_from_slice(m.end.as_slice()))
    }

    /// Arc centres (n, 3) [m], level with the arc's start along its plane's normal; NaN for
    /// other moves.
    #[getter]
    fn center<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |m, o| match m.motion {
            Motion::Arc { center, .. } => o.copy_from_slice(center.as_slice()),
            _ => o.fill(f64::NAN),
        })
    }

    /// Each arc's plane: "xy" (G17), "zx" (G18), "yz" (G19); None for other moves.
    #[getter]
    fn plane(&self) -> Vec<Option<&'static str>> {
        self.inner
            .moves
            .iter()
            .map(|m| match m.motion {
                Motion::Arc { plane, .. } => Some(match plane {
                    Plane::Xy => "xy",
                    Plane::Zx => "zx",
                    Plane::Yz => "yz",
                }),
                _ => None,
            })
            .collect()
    }

    /// Signed arc sweeps (n,) [rad] about the plane's normal (> 0 counter-clockwise, G3; a
    /// helix of P turns sweeps P turns); 0 for other moves.
    #[getter]
    fn sweep<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| match m.motion {
            Motion::Arc { sweep, .. } => sweep,
            _ => 0.0,
        }))
        .into_pyarray(py)
    }

    /// Dwell times (n,) [s] (G4, a cycle's P); 0 for other moves.
    #[getter]
    fn dwell<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| match m.motion {
            Motion::Dwell { seconds } => seconds,
            _ => 0.0,
        }))
        .into_pyarray(py)
    }

    /// Programmed feeds (n,) [m/s] (inverse-time and per-revolution feeds as path speed);
    /// 0 for rapid moves and dwells.
    #[getter]
    fn feed<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| m.feed)).into_pyarray(py)
    }

    /// Spindle speeds (n,) [rev/s]: > 0 clockwise (M3), < 0 counter-clockwise (M4), 0 off.
    #[getter]
    fn spindle<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| m.spindle)).into_pyarray(py)
    }

    /// The tool in the spindle at each move (n,) (T and M6, or M61 Q); 0 for none.
    #[getter]
    fn tool<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| m.tool)).into_pyarray(py)
    }

    /// The tool numbers the moves use, ascending.
    #[getter]
    fn tools(&self) -> Vec<u32> {
        self.inner.tools()
    }

    /// The path control mode of each move: "G61", "G61.1" or "G64" (n,) list.
    #[getter]
    fn path_control(&self) -> Vec<&'static str> {
        self.inner
            .moves
            .iter()
            .map(|m| match m.path_control {
                PathControl::ExactPath => "G61",
                PathControl::ExactStop => "G61.1",
                PathControl::Blend { .. } => "G64",
            })
            .collect()
    }

    /// The G64 P tolerance of each move (n,) [m] (0: none given, or G61/G61.1).
    #[getter]
    fn blend_tolerance<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| match m.path_control {
            PathControl::Blend { tolerance, .. } => tolerance,
            _ => 0.0,
        }))
        .into_pyarray(py)
    }

    /// Path lengths of the moves (n,) [m] (arcs and helices along the curve).
    #[getter]
    fn length<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| m.length())).into_pyarray(py)
    }

    /// Total length of the feed moves [m] (rapids and dwells excluded).
    #[getter]
    fn cutting_length(&self) -> f64 {
        self.inner.cutting_length()
    }

    /// The tool axis at each move's start (n, 3), unit, tip towards spindle, workpiece
    /// frame: +z for a 3-axis program; between start and end the axis turns along the great
    /// circle.
    #[getter]
    fn start_axis<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |m, o| o.copy_from_slice(m.start_axis.as_slice()))
    }

    /// The tool axis at each move's end (n, 3).
    #[getter]
    fn end_axis<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |m, o| o.copy_from_slice(m.end_axis.as_slice()))
    }

    /// Whether any move's tool axis leaves +z (a five-axis program).
    #[getter]
    fn is_multi_axis(&self) -> bool {
        self.inner.is_multi_axis()
    }

    /// The cutters an APT program defines (`CUTTER/`): `(tool, diameter [m], shape,
    /// corner_radius [m], line)`, shape "flat", "ball" or "bull-nose"; empty for G-code.
    #[getter]
    fn cutters(&self) -> Vec<(u32, f64, &'static str, f64, usize)> {
        self.cutters
            .iter()
            .map(|c| (c.tool, c.diameter, c.shape.name(), corner(c), c.line))
            .collect()
    }

    /// Every word the program uses: `(word, status, count, first_line, meaning)`, status
    /// "honoured" (it shapes the moves), "recorded" (read without motion: coolant,
    /// overrides, tool lengths) or "refused"; empty for a points CSV.
    #[getter]
    fn words(&self) -> Vec<WordState> {
        self.words.iter().map(word_state).collect()
    }
}

impl GcodeProgram {
    fn rows<'py>(
        &self,
        py: Python<'py>,
        width: usize,
        fill: impl Fn(&deflect_core::machining::Move, &mut [f64]),
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.inner.moves.len();
        let mut out = try_rows(n, width, "the program's moves")?;
        for (m, o) in self.inner.moves.iter().zip(out.chunks_mut(width)) {
            fill(m, o);
        }
        let a = Array2::from_shape_vec((n, width), out)
            .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
        Ok(a.into_pyarray(py))
    }
}

/// Adds the machining classes and functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<GcodeProgram>()?;
    m.add_function(wrap_pyfunction!(gcode_words, m)?)?;
    crate::cutter::register(m)
}
