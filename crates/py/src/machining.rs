//! Robot machining: a G-code program read into numpy arrays (`GcodeProgram`, deflect-core's
//! `io::gcode`) and the mechanistic end-milling force (`milling_force`, deflect-core's
//! `machining::cutting`). Everything SI: m, m/s, rev/s, N.

use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::io::points_csv;
use deflect_core::machining::cutting::{self, Coefficients, Engagement, MAX_DISCS, Tool};
use deflect_core::machining::{Motion, Move, Program};
use deflect_core::motion::MAX_SAMPLES;
use deflect_core::units::LengthUnit;
use nalgebra::Vector3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::InputError;
use crate::arrays::{try_rows, vector, vector_upto};
use crate::errors::{build_err, load_err, tick_err};
use crate::scalars::{count, real};

/// One move as pickled: line, kind (0 rapid, 1 linear, 2 arc), start, end, arc centre (NaN
/// for straight moves), sweep, feed, spindle.
type MoveState = (usize, u8, [f64; 3], [f64; 3], [f64; 2], f64, f64, f64);

/// A machining program read from ISO G-code: its moves as arrays, SI, workpiece frame.
/// Supported: G0-G3 in G17 (arcs by I/J or R), G20/G21 (before the first length; mm
/// without either), G90/G91, F (per minute), S (rpm), M3/M5, M2/M30, N, comments and %;
/// G40/G49/G54/G80/G94 are accepted with no effect. Anything else raises `LoadError` naming
/// the line and the column. At most 1,000,000 lines.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct GcodeProgram {
    pub(crate) inner: Program,
}

fn options(start: Option<&Bound<'_, PyAny>>, units: &str) -> PyResult<GcodeOptions> {
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
    Ok(GcodeOptions { start, units })
}

#[pymethods]
impl GcodeProgram {
    /// Reads a G-code file. `start` (3,) [m]: where the tool is before the first move
    /// (default the origin); `units`: "mm" or "in" until the program says G21 or G20.
    #[staticmethod]
    #[pyo3(signature = (path, *, start=None, units="mm"))]
    fn from_file(
        path: std::path::PathBuf,
        start: Option<&Bound<'_, PyAny>>,
        units: &str,
    ) -> PyResult<Self> {
        let o = options(start, units)?;
        let inner = gcode::from_path(&path, &o).map_err(load_err)?;
        Ok(Self { inner })
    }

    /// Same as `from_file`, from the program's text.
    #[staticmethod]
    #[pyo3(signature = (text, *, start=None, units="mm"))]
    fn from_text(text: &str, start: Option<&Bound<'_, PyAny>>, units: &str) -> PyResult<Self> {
        let o = options(start, units)?;
        let inner = gcode::from_str(text, &o).map_err(load_err)?;
        Ok(Self { inner })
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
        let o = options(start, "mm")?;
        let inner = points_csv::from_path(&path, &o).map_err(load_err)?;
        Ok(Self { inner })
    }

    /// Same as `from_points_file`, from the CSV text.
    #[staticmethod]
    #[pyo3(signature = (text, *, start=None))]
    fn from_points_text(text: &str, start: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let o = options(start, "mm")?;
        let inner = points_csv::from_str(text, &o).map_err(load_err)?;
        Ok(Self { inner })
    }

    /// Pickling and copy.deepcopy: the moves as plain values, rebuilt bit for bit and
    /// checked (`Program::validate`).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (Vec<MoveState>,))> {
        let rebuild = slf.get_type().getattr("_from_state")?;
        let state = slf
            .get()
            .inner
            .moves
            .iter()
            .map(|m| {
                let (kind, center, sweep) = match m.motion {
                    Motion::Rapid => (0u8, [f64::NAN; 2], 0.0),
                    Motion::Linear => (1, [f64::NAN; 2], 0.0),
                    Motion::Arc { center, sweep } => (2, [center.x, center.y], sweep),
                };
                (
                    m.line,
                    kind,
                    [m.start.x, m.start.y, m.start.z],
                    [m.end.x, m.end.y, m.end.z],
                    center,
                    sweep,
                    m.feed,
                    m.spindle,
                )
            })
            .collect();
        Ok((rebuild, (state,)))
    }

    /// The program of a pickled state (see `__reduce__`), checked.
    #[staticmethod]
    fn _from_state(state: Vec<MoveState>) -> PyResult<Self> {
        let moves = state
            .into_iter()
            .enumerate()
            .map(|(i, (line, kind, start, end, center, sweep, feed, spindle))| {
                let motion = match kind {
                    0 => Motion::Rapid,
                    1 => Motion::Linear,
                    2 => Motion::Arc {
                        center: nalgebra::Vector2::new(center[0], center[1]),
                        sweep,
                    },
                    k => {
                        return Err(InputError::new_err(format!(
                            "pickled program, move {i}: kind {k}; expected 0 (rapid), 1 (linear) or 2 (arc)"
                        )));
                    }
                };
                Ok(Move {
                    line,
                    motion,
                    start: Vector3::from(start),
                    end: Vector3::from(end),
                    feed,
                    spindle,
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        let inner = Program { moves };
        inner.validate().map_err(build_err)?;
        Ok(Self { inner })
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

    /// The program line of each move (1-based), (n,).
    #[getter]
    fn line<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| m.line as u64)).into_pyarray(py)
    }

    /// Each move's kind: "rapid", "linear" or "arc", (n,) list.
    #[getter]
    fn kind(&self) -> Vec<&'static str> {
        self.inner
            .moves
            .iter()
            .map(|m| match m.motion {
                Motion::Rapid => "rapid",
                Motion::Linear => "linear",
                Motion::Arc { .. } => "arc",
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

    /// Arc centres (n, 2) [m] (x, y); NaN for straight moves.
    #[getter]
    fn center<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 2, |m, o| match m.motion {
            Motion::Arc { center, .. } => o.copy_from_slice(center.as_slice()),
            _ => o.fill(f64::NAN),
        })
    }

    /// Signed arc sweeps (n,) [rad] (> 0 counter-clockwise, G3); 0 for straight moves.
    #[getter]
    fn sweep<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| match m.motion {
            Motion::Arc { sweep, .. } => sweep,
            _ => 0.0,
        }))
        .into_pyarray(py)
    }

    /// Programmed feeds (n,) [m/s]; 0 for rapid moves.
    #[getter]
    fn feed<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| m.feed)).into_pyarray(py)
    }

    /// Spindle speeds (n,) [rev/s]; 0 while the spindle is off.
    #[getter]
    fn spindle<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| m.spindle)).into_pyarray(py)
    }

    /// Path lengths of the moves (n,) [m] (arcs and helices along the curve).
    #[getter]
    fn length<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.moves.iter().map(|m| m.length())).into_pyarray(py)
    }

    /// Total length of the feed moves [m] (rapids excluded).
    #[getter]
    fn cutting_length(&self) -> f64 {
        self.inner.cutting_length()
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
    m.add_function(wrap_pyfunction!(milling_force, m)?)?;
    let k = Coefficients::AL7075_T6_CARBIDE;
    m.add(
        "AL7075_T6_CARBIDE",
        (k.k_tc, k.k_rc, k.k_ac, k.k_te, k.k_re, k.k_ae),
    )?;
    Ok(())
}
