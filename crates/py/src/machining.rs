//! Robot machining: a G-code program read into numpy arrays (`GcodeProgram`, deflect-core's
//! `io::gcode`) and the mechanistic end-milling force (`milling_force`, deflect-core's
//! `machining::cutting`). Everything SI: m, m/s, rev/s, N.

use deflect_core::io::gcode::{self, Dialect, GcodeOptions, WordStatus, WordUse};
use deflect_core::io::points_csv;
use deflect_core::machining::cutting::{self, Coefficients, Engagement, MAX_DISCS, Tool};
use deflect_core::machining::{Motion, Move, Operation, PathControl, Plane, Program};
use deflect_core::motion::MAX_SAMPLES;
use deflect_core::units::LengthUnit;
use nalgebra::Vector3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::InputError;
use crate::args;
use crate::arrays::{try_rows, vector, vector_upto};
use crate::errors::{build_err, load_err, tick_err};
use crate::scalars::{count, real};

/// One move as pickled: line, kind (0 rapid, 1 linear, 2 arc, 3 dwell), start, end, arc
/// centre (NaN for other moves), (plane 0 xy / 1 zx / 2 yz, sweep [rad] or dwell [s]),
/// (feed, spindle, tool), (path control 0 G61 / 1 G61.1 / 2 G64, P, Q).
type MoveState = (
    usize,
    u8,
    [f64; 3],
    [f64; 3],
    [f64; 3],
    (u8, f64),
    (f64, f64, u32),
    (u8, f64, f64),
);

/// A word of the report: word, status, count, first line, meaning.
type WordState = (String, String, usize, usize, String);

/// A program as pickled: its moves and its word report.
type ProgramState = (Vec<MoveState>, Vec<WordState>, Vec<(String, usize)>);

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
        kinematics: None,
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
        Ok(Self { inner, words })
    }
}

#[pymethods]
impl GcodeProgram {
    /// Reads a G-code file. `start` (3,) [m]: where the tool is before the first move
    /// (default the origin); `units`: "mm" or "in" until the program says G21 or G20;
    /// `dialect`: "linuxcnc", "grbl" or "fanuc"; `block_delete`: skip the lines starting with
    /// '/' (default False: they run, as on LinuxCNC).
    #[staticmethod]
    #[pyo3(signature = (path, *, start=None, units="mm", dialect="linuxcnc", block_delete=false))]
    fn from_file(
        py: Python<'_>,
        path: std::path::PathBuf,
        start: Option<&Bound<'_, PyAny>>,
        units: &str,
        dialect: &str,
        block_delete: bool,
    ) -> PyResult<Self> {
        let o = options(start, units, dialect, block_delete)?;
        let text = py
            .detach(|| deflect_core::io::read_text_lossy(&path))
            .map_err(load_err)?;
        Self::read(py, &text, &o)
    }

    /// Same as `from_file`, from the program's text.
    #[staticmethod]
    #[pyo3(signature = (text, *, start=None, units="mm", dialect="linuxcnc", block_delete=false))]
    fn from_text(
        py: Python<'_>,
        #[pyo3(from_py_with = args::text::text)] text: String,
        start: Option<&Bound<'_, PyAny>>,
        units: &str,
        dialect: &str,
        block_delete: bool,
    ) -> PyResult<Self> {
        let o = options(start, units, dialect, block_delete)?;
        Self::read(py, &text, &o)
    }

    /// Reads a tool points CSV file: one straight move per row from the previous point (the
    /// first from `start`), columns `x_mm,y_mm,z_mm` (or `x_m,y_m,z_m`), `feed_mm_min` (or
    /// `feed_m_s`; 0 for a rapid move) and `spindle_rpm`. `LoadError` naming the row.
    #[staticmethod]
    #[pyo3(signature = (path, *, start=None))]
    fn from_points_file(
        path: std::path::PathBuf,
        start: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let o = options(start, "mm", "linuxcnc", false)?;
        let inner = points_csv::from_path(&path, &o).map_err(load_err)?;
        Ok(Self {
            inner,
            words: Vec::new(),
        })
    }

    /// Same as `from_points_file`, from the CSV text.
    #[staticmethod]
    #[pyo3(signature = (text, *, start=None))]
    fn from_points_text(
        #[pyo3(from_py_with = args::text::text)] text: String,
        start: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let o = options(start, "mm", "linuxcnc", false)?;
        let inner = points_csv::from_str(&text, &o).map_err(load_err)?;
        Ok(Self {
            inner,
            words: Vec::new(),
        })
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
        Ok((
            rebuild,
            (state, me.words.iter().map(word_state).collect(), ops),
        ))
    }

    /// The program of a pickled state (see `__reduce__`), checked.
    #[staticmethod]
    #[pyo3(signature = (state, words, operations=Vec::new()))]
    fn _from_state(
        state: Vec<MoveState>,
        words: Vec<WordState>,
        operations: Vec<(String, usize)>,
    ) -> PyResult<Self> {
        let moves = state
            .into_iter()
            .enumerate()
            .map(|(i, m)| from_move_state(i, m))
            .collect::<PyResult<Vec<_>>>()?;
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
        Ok(Self { inner, words })
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

    /// Every word the program uses: `(word, status, count, first_line, meaning)`, status
    /// "honoured" (it shapes the moves), "recorded" (read without motion: coolant,
    /// overrides, tool lengths) or "refused"; empty for a points CSV.
    #[getter]
    fn words(&self) -> Vec<WordState> {
        self.words.iter().map(word_state).collect()
    }
}

fn move_state(m: &Move) -> MoveState {
    let nan = [f64::NAN; 3];
    let (kind, center, plane, sweep) = match m.motion {
        Motion::Rapid => (0u8, nan, 0u8, 0.0),
        Motion::Linear => (1, nan, 0, 0.0),
        Motion::Arc {
            plane,
            center,
            sweep,
        } => (
            2,
            center.into(),
            match plane {
                Plane::Xy => 0,
                Plane::Zx => 1,
                Plane::Yz => 2,
            },
            sweep,
        ),
        Motion::Dwell { seconds } => (3, nan, 0, seconds),
    };
    let control = match m.path_control {
        PathControl::ExactPath => (0u8, 0.0, 0.0),
        PathControl::ExactStop => (1, 0.0, 0.0),
        PathControl::Blend {
            tolerance,
            naive_tolerance,
        } => (2, tolerance, naive_tolerance),
    };
    (
        m.line,
        kind,
        m.start.into(),
        m.end.into(),
        center,
        (plane, sweep),
        (m.feed, m.spindle, m.tool),
        control,
    )
}

fn from_move_state(i: usize, s: MoveState) -> PyResult<Move> {
    let (line, kind, start, end, center, (plane, sweep), (feed, spindle, tool), (control, p, q)) =
        s;
    let bad = |what: &str, got: u8, expected: &str| {
        InputError::new_err(format!(
            "pickled program, move {i}: {what} {got}; expected {expected}"
        ))
    };
    let plane = match plane {
        0 => Plane::Xy,
        1 => Plane::Zx,
        2 => Plane::Yz,
        k => return Err(bad("plane", k, "0 (xy), 1 (zx) or 2 (yz)")),
    };
    let motion = match kind {
        0 => Motion::Rapid,
        1 => Motion::Linear,
        2 => Motion::Arc {
            plane,
            center: Vector3::from(center),
            sweep,
        },
        3 => Motion::Dwell { seconds: sweep },
        k => {
            return Err(bad(
                "kind",
                k,
                "0 (rapid), 1 (linear), 2 (arc) or 3 (dwell)",
            ));
        }
    };
    let path_control = match control {
        0 => PathControl::ExactPath,
        1 => PathControl::ExactStop,
        2 => PathControl::Blend {
            tolerance: p,
            naive_tolerance: q,
        },
        k => return Err(bad("path control", k, "0 (G61), 1 (G61.1) or 2 (G64)")),
    };
    Ok(Move {
        spindle,
        tool,
        path_control,
        ..Move::new(line, motion, Vector3::from(start), Vector3::from(end), feed)
    })
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

/// The milling force on a flat end mill [N], tool frame (x along the feed, z along the tool
/// axis towards the spindle, y = z x x; the force the workpiece exerts on the tool), from
/// the mechanistic model (linear edge forces, chip thickness `h = f_z sin(phi)`).
///
/// `diameter` [m], `flutes`, axial `depth` [m], `feed_per_tooth` [m], immersion from `entry`
/// to `exit` [rad] (clockwise from +y: a slot is 0..pi, up milling starts at 0, down milling
/// ends at pi), `helix` [rad]. `coefficients`: (k_tc, k_rc, k_ac [N/m^2], k_te, k_re, k_ae
/// [N/m]); default Al7075-T6 with a carbide tool (`AL7075_T6_CARBIDE`). Without `angles` the
/// average over a revolution (3,); with `angles` (m,) [rad] (edge 0's angle at the tip) the
/// instantaneous forces (m, 3), the depth cut into `discs` axial discs for the helix.
#[pyfunction]
#[pyo3(signature = (diameter, flutes, depth, feed_per_tooth, *, entry=None, exit=None, helix=None, coefficients=None, angles=None, discs=None),
       text_signature = "(diameter, flutes, depth, feed_per_tooth, *, entry=0.0, exit=3.141592653589793, helix=0.0, coefficients=None, angles=None, discs=1)")]
#[allow(clippy::too_many_arguments)] // reason: the documented Python keyword arguments
fn milling_force<'py>(
    py: Python<'py>,
    diameter: &Bound<'py, PyAny>,
    flutes: &Bound<'py, PyAny>,
    depth: &Bound<'py, PyAny>,
    feed_per_tooth: &Bound<'py, PyAny>,
    entry: Option<&Bound<'py, PyAny>>,
    exit: Option<&Bound<'py, PyAny>>,
    helix: Option<&Bound<'py, PyAny>>,
    coefficients: Option<&Bound<'py, PyAny>>,
    angles: Option<&Bound<'py, PyAny>>,
    discs: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let flutes = u32::try_from(count(flutes, "flutes")?).unwrap_or(u32::MAX);
    // The documented defaults (shown in the text signature): a slot, straight flutes, one disc.
    let or = |o: Option<&Bound<'py, PyAny>>, what: &str, default: f64| {
        o.map_or(Ok(default), |o| real(o, what))
    };
    let tool = Tool::new(
        real(diameter, "diameter")?,
        flutes,
        or(helix, "helix", 0.0)?,
    )
    .map_err(build_err)?;
    let k = self::coefficients(coefficients)?;
    let e = Engagement {
        entry: or(entry, "entry", 0.0)?,
        exit: or(exit, "exit", std::f64::consts::PI)?,
        depth: real(depth, "depth")?,
        feed_per_tooth: real(feed_per_tooth, "feed_per_tooth")?,
    };
    let Some(angles) = angles else {
        let f = cutting::average(&k, &tool, &e).map_err(tick_err)?;
        return Ok(f.as_slice().to_vec().into_pyarray(py).into_any());
    };
    let angles = vector_upto(angles, "angles", MAX_SAMPLES, "MAX_SAMPLES")?;
    let discs = discs.map_or(Ok(1), |d| count(d, "discs"))?;
    if !(1..=MAX_DISCS).contains(&discs) {
        return Err(InputError::new_err(format!(
            "discs: expected 1..={MAX_DISCS}, got {discs}"
        )));
    }
    cutting::check_force_evaluations(angles.len(), discs, &tool).map_err(tick_err)?;
    let mut out = try_rows(angles.len(), 3, "the forces")?;
    py.detach(|| {
        for (o, &angle) in out.chunks_mut(3).zip(&angles) {
            let f = cutting::force(&k, &tool, &e, angle, discs)?;
            o.copy_from_slice(f.as_slice());
        }
        Ok::<_, deflect_core::TickError>(())
    })
    .map_err(tick_err)?;
    let arr = Array2::from_shape_vec((angles.len(), 3), out)
        .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
    Ok(arr.into_pyarray(py).into_any())
}

/// `coefficients` as (k_tc, k_rc, k_ac, k_te, k_re, k_ae), default Al7075-T6 / carbide.
pub(crate) fn coefficients(c: Option<&Bound<'_, PyAny>>) -> PyResult<Coefficients> {
    match c {
        None => Ok(Coefficients::AL7075_T6_CARBIDE),
        Some(c) => {
            let v = vector(c, "coefficients", 6)?;
            let at = |i: usize| v.get(i).copied().unwrap_or(f64::NAN);
            Coefficients::new(at(0), at(1), at(2), at(3), at(4), at(5)).map_err(build_err)
        }
    }
}

/// Adds the machining classes and functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<GcodeProgram>()?;
    m.add_function(wrap_pyfunction!(gcode_words, m)?)?;
    m.add_function(wrap_pyfunction!(milling_force, m)?)?;
    let k = Coefficients::AL7075_T6_CARBIDE;
    m.add(
        "AL7075_T6_CARBIDE",
        (k.k_tc, k.k_rc, k.k_ac, k.k_te, k.k_re, k.k_ae),
    )?;
    Ok(())
}
