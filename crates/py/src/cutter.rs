//! The mechanistic milling forces: the flat end mill's (`milling_force`, deflect-core's
//! `machining::cutting`) and any cutter's along its edge (`cutter_force`, deflect-core's
//! `machining::profile`: flat, ball and bull-nose ends, tilted to the feed). SI: m, rad, N.

use deflect_core::machining::cutting::{self, Coefficients, Engagement, MAX_DISCS, Tool};
use deflect_core::machining::profile::{self, Band, Cut, EdgeWrench, MAX_BANDS, Profile};
use deflect_core::machining::tools::ToolShape;
use deflect_core::motion::MAX_SAMPLES;
use nalgebra::Vector3;
use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::prelude::*;

use crate::InputError;
use crate::arrays::{check_count, matrix, try_rows, vector, vector_upto};
use crate::errors::{build_err, tick_err};
use crate::scalars::{count, real};

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

/// The wrench of a cut on a flat, ball or bull-nose end mill [N, N m], tool frame (x along
/// the feed's part across the axis, z along the tool axis towards the spindle), about the tool
/// tip: the edge discretised along the cutter's profile, each element's chip `h = f . n`
/// (`f_x sin(phi) sin(kappa)` for a tool not tilted to the feed), its cutting and edge forces
/// (Lee and Altintas' ball-end model; the flat mill is its kappa = 90 degree case).
///
/// `diameter` [m], `flutes`; `bands` (n, 4): rows (bottom, top, entry, exit), the heights
/// [m] above the tip along the axis and the immersion [rad] clockwise from +y each band cuts
/// over (0 <= entry < 2 pi, entry < exit <= entry + 2 pi); `feed` (3,): the feed per tooth
/// [m] as a vector in the tool frame (its z part is the tilt's). `shape`: "flat", "ball" or
/// "bull-nose" (with `corner_radius` [m]); `helix` [rad]; `coefficients` as for
/// `milling_force`. Without `angles`: the revolution's mean `(force (3,), moment (3,))`; with
/// `angles` (m,) [rad] (edge 0's angle at the tip): the instantaneous `(force (m, 3),
/// moment (m, 3))`.
#[pyfunction]
#[pyo3(signature = (diameter, flutes, bands, feed, *, shape="flat", corner_radius=None, helix=None, coefficients=None, angles=None),
       text_signature = "(diameter, flutes, bands, feed, *, shape='flat', corner_radius=None, helix=0.0, coefficients=None, angles=None)")]
#[allow(clippy::too_many_arguments)] // reason: the documented Python keyword arguments
fn cutter_force<'py>(
    py: Python<'py>,
    diameter: &Bound<'py, PyAny>,
    flutes: &Bound<'py, PyAny>,
    bands: &Bound<'py, PyAny>,
    feed: &Bound<'py, PyAny>,
    shape: &str,
    corner_radius: Option<&Bound<'py, PyAny>>,
    helix: Option<&Bound<'py, PyAny>>,
    coefficients: Option<&Bound<'py, PyAny>>,
    angles: Option<&Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let flutes = u32::try_from(count(flutes, "flutes")?).unwrap_or(u32::MAX);
    let helix = helix.map_or(Ok(0.0), |h| real(h, "helix"))?;
    let tool = Tool::new(real(diameter, "diameter")?, flutes, helix).map_err(build_err)?;
    let corner_radius = corner_radius
        .map(|r| real(r, "corner_radius"))
        .transpose()?;
    let shape = self::shape(shape, corner_radius)?;
    let profile = Profile::new(&tool, shape).map_err(build_err)?;
    let k = self::coefficients(coefficients)?;
    let rows = matrix(bands, "bands", None, Some(4))?;
    let rows = rows.as_array();
    check_count("bands", rows.nrows(), "rows", MAX_BANDS, "MAX_BANDS")?;
    let bands: Vec<Band> = rows
        .rows()
        .into_iter()
        .map(|r| {
            let at = |i: usize| r.get(i).copied().unwrap_or(f64::NAN);
            Band {
                bottom: at(0),
                top: at(1),
                entry: at(2),
                exit: at(3),
            }
        })
        .collect();
    let f = vector(feed, "feed", 3)?;
    let cut = Cut {
        bands: &bands,
        feed: Vector3::from_column_slice(&f),
    };
    let pair = |w: EdgeWrench| {
        (
            w.force.as_slice().to_vec().into_pyarray(py).into_any(),
            w.moment.as_slice().to_vec().into_pyarray(py).into_any(),
        )
    };
    let Some(angles) = angles else {
        let w = py
            .detach(|| profile::average(&k, &profile, &cut))
            .map_err(tick_err)?;
        return Ok(pair(w));
    };
    let angles = vector_upto(angles, "angles", MAX_SAMPLES, "MAX_SAMPLES")?;
    let mut force = try_rows(angles.len(), 3, "the forces")?;
    let mut moment = try_rows(angles.len(), 3, "the moments")?;
    py.detach(|| {
        for ((fo, mo), &angle) in force.chunks_mut(3).zip(moment.chunks_mut(3)).zip(&angles) {
            let w = profile::force(&k, &profile, &cut, angle)?;
            fo.copy_from_slice(w.force.as_slice());
            mo.copy_from_slice(w.moment.as_slice());
        }
        Ok::<_, deflect_core::TickError>(())
    })
    .map_err(tick_err)?;
    let n = angles.len();
    let to = |v: Vec<f64>| -> PyResult<Bound<'py, PyAny>> {
        let a = Array2::from_shape_vec((n, 3), v)
            .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
        Ok(a.into_pyarray(py).into_any())
    };
    Ok((to(force)?, to(moment)?))
}

/// A cutter's end from its name: "flat", "ball" or "bull-nose" (which, alone, takes
/// `corner_radius` [m]; the core checks its range).
pub(crate) fn shape(name: &str, corner_radius: Option<f64>) -> PyResult<ToolShape> {
    match (name, corner_radius) {
        ("flat", None) => Ok(ToolShape::Flat),
        ("ball", None) => Ok(ToolShape::Ball),
        ("bull-nose", Some(r)) => Ok(ToolShape::BullNose { corner_radius: r }),
        ("bull-nose", None) => Err(InputError::new_err(
            "shape \"bull-nose\" needs corner_radius [m]",
        )),
        (s, _) => Err(InputError::new_err(format!(
            "shape must be \"flat\", \"ball\" or \"bull-nose\" (corner_radius only with \
             \"bull-nose\"), got {s:?}"
        ))),
    }
}

/// Adds the force functions and the coefficient set to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(milling_force, m)?)?;
    m.add_function(wrap_pyfunction!(cutter_force, m)?)?;
    let k = Coefficients::AL7075_T6_CARBIDE;
    m.add(
        "AL7075_T6_CARBIDE",
        (k.k_tc, k.k_rc, k.k_ac, k.k_te, k.k_re, k.k_ae),
    )?;
    Ok(())
}
