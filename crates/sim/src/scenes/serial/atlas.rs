//! `deflect-sim atlas`: the stiffness-optimal posture over a plane of the workspace.
//!
//! For every point of a grid on a horizontal plane, the rotation about the tool axis is swept
//! (deflect-core's `posture::sweep`: warm-started pose IK, joint limits, singularity margin,
//! exact virtual-joint deflection of Hähn and Weigold 2020, Eq. 2-9) and the posture that
//! deflects least under the process wrench is kept. The grid's rows run on worker threads;
//! the result does not depend on their number. Outputs: a compressed NumPy archive
//! (`atlas.npz`, SI units, read with `numpy.load`) and a heat map of the best deflection
//! (`atlas.png`).

use std::path::Path;

use deflect_core::SerialRobot;
use deflect_core::posture::{self, AnglePoint, PostureOptions, Reach};
use deflect_core::vjm::{Data, Vector6};
use indicatif::ProgressBar;
use nalgebra::Vector3;
use ndarray::{Array1, Array2};
use plotters::prelude::*;

use crate::SimError;
use crate::plot_style::{
    Area, CHART, Entry, LEGEND_FONT, canvas, figure, new_chart, perr, present,
};
use crate::workers::parallel_map;

/// What to map.
#[derive(Debug, Clone)]
pub struct AtlasTask {
    /// The robot.
    pub robot: SerialRobot,
    /// Its name in titles ("KR 300 R2500").
    pub name: String,
    /// Grid x coordinates \[m\], base frame.
    pub xs: Vec<f64>,
    /// Grid y coordinates \[m\].
    pub ys: Vec<f64>,
    /// Height of the plane \[m\].
    pub z: f64,
    /// Tool axis (the TCP z axis), base frame.
    pub tool_axis: Vector3<f64>,
    /// Process wrench at the TCP \[N, N m\], base frame.
    pub wrench: Vector6,
    /// Angles of the sweep \[rad\].
    pub angles: Vec<f64>,
    /// IK seed (one joint vector).
    pub seed: Vec<f64>,
}

/// The result at one grid point; NaN fields where nothing is reachable.
#[derive(Debug, Clone, PartialEq)]
pub struct AtlasPoint {
    /// The point's status: reachable, or the most telling reason it is not (a posture
    /// beyond the model's validity before a joint limit or a singularity, those before out
    /// of reach), as [`posture::SweepSummary::status`].
    pub status: Reach,
    /// Angles of the sweep with a posture.
    pub reachable_angles: usize,
    /// Angles with a posture whose deflection under the wrench is beyond the model (a
    /// spring past `MAX_SPRING_ANGLE`).
    pub beyond_model_angles: usize,
    /// Best angle about the tool axis \[rad\].
    pub best_angle: f64,
    /// Norm of the best translational deflection \[m\].
    pub best_measure: f64,
    /// Best deflection `[dp; dr]` \[m, rad\].
    pub best_deflection: [f64; 6],
    /// Joints of the best posture.
    pub best_q: Vec<f64>,
    /// Worst reachable angle \[rad\].
    pub worst_angle: f64,
    /// Its deflection norm \[m\].
    pub worst_measure: f64,
}

/// One per-point number of the archive.
type Field = dyn Fn(&AtlasPoint) -> f64;

/// Sweeps every grid point (rows of x on `threads` threads), advancing `bar` per row.
/// Points come back x-major: index `i * ys.len() + j`.
pub fn compute(
    task: &AtlasTask,
    threads: usize,
    bar: &ProgressBar,
) -> Result<Vec<AtlasPoint>, SimError> {
    let model = &task.robot.model;
    let dof = model.dof();
    let options = PostureOptions::default();
    let rows = parallel_map(
        &task.xs,
        threads,
        |&x| -> Result<Vec<AtlasPoint>, SimError> {
            let mut data = Data::new(model);
            let mut out = vec![AnglePoint::default(); task.angles.len()];
            let row = task
                .ys
                .iter()
                .map(|&y| {
                    let s = posture::sweep(
                        model,
                        &mut data,
                        &task.robot.joint_limits,
                        &Vector3::new(x, y, task.z),
                        &task.tool_axis,
                        &task.wrench,
                        &task.angles,
                        &task.seed,
                        &options,
                        &mut out,
                    )
                    .map_err(|e| {
                        SimError::new(format!("atlas at ({x}, {y}, {}) m: {e}", task.z))
                    })?;
                    let worst = s.worst_index.and_then(|k| out.get(k));
                    Ok(match s.best {
                        Some(b) => AtlasPoint {
                            status: s.status,
                            reachable_angles: s.reachable,
                            beyond_model_angles: s.beyond_model,
                            best_angle: b.angle,
                            best_measure: b.measure,
                            best_deflection: core::array::from_fn(|k| b.deflection[k]),
                            best_q: b.q.iter().take(dof).copied().collect(),
                            worst_angle: worst.map_or(f64::NAN, |w| w.angle),
                            worst_measure: worst.map_or(f64::NAN, |w| w.measure),
                        },
                        None => AtlasPoint {
                            status: s.status,
                            reachable_angles: 0,
                            beyond_model_angles: s.beyond_model,
                            best_angle: f64::NAN,
                            best_measure: f64::NAN,
                            best_deflection: [f64::NAN; 6],
                            best_q: vec![f64::NAN; dof],
                            worst_angle: f64::NAN,
                            worst_measure: f64::NAN,
                        },
                    })
                })
                .collect::<Result<Vec<_>, SimError>>();
            bar.inc(1);
            row
        },
    )?;
    let mut all = Vec::with_capacity(task.xs.len() * task.ys.len());
    for r in rows {
        all.extend(r?);
    }
    Ok(all)
}

/// Writes `atlas.npz`: `x` (nx,), `y` (ny,), `z`, `tool_axis` (3,), `wrench` (6,), `angles`
/// (n,) \[rad\], and per grid point, shaped (nx, ny) or (nx, ny, k): `reachable` (0/1),
/// `status` (0 reachable, 1 out of reach, 2 singular, 3 joint limit, 4 beyond the model's
/// validity: `posture::Reach::code`), `reachable_angles`, `beyond_model_angles`, `best_angle` \[rad\], `best_measure` \[m\], `best_deflection` (6) [m,
/// rad], `best_q` (dof) \[rad or m\], `worst_angle` \[rad\], `worst_measure` \[m\].
pub fn write_npz(path: &Path, task: &AtlasTask, points: &[AtlasPoint]) -> Result<(), SimError> {
    let err = |e: &dyn std::fmt::Display| SimError::file(path, "write the atlas archive", e);
    let file = std::fs::File::create(path).map_err(|e| err(&e))?;
    let mut npz = ndarray_npy::NpzWriter::new_compressed(file);
    let (nx, ny) = (task.xs.len(), task.ys.len());
    let grid = |f: &dyn Fn(&AtlasPoint) -> f64| {
        Array2::from_shape_vec((nx, ny), points.iter().map(f).collect())
    };
    let stack = |k: usize, f: &dyn Fn(&AtlasPoint) -> Vec<f64>| {
        ndarray::Array3::from_shape_vec((nx, ny, k), points.iter().flat_map(f).collect())
    };
    let dof = task.robot.model.dof();
    let shape = |e: ndarray::ShapeError| err(&e);
    let mut add1 = |name: &str, a: Array1<f64>| npz.add_array(name, &a).map_err(|e| err(&e));
    add1("x", Array1::from_vec(task.xs.clone()))?;
    add1("y", Array1::from_vec(task.ys.clone()))?;
    add1("z", Array1::from_vec(vec![task.z]))?;
    add1(
        "tool_axis",
        Array1::from_iter(task.tool_axis.iter().copied()),
    )?;
    add1("wrench", Array1::from_iter(task.wrench.iter().copied()))?;
    add1("angles", Array1::from_vec(task.angles.clone()))?;
    let fields: [(&str, &Field); 8] = [
        ("reachable", &|p: &AtlasPoint| {
            f64::from(u8::from(p.reachable_angles > 0))
        }),
        ("status", &|p: &AtlasPoint| f64::from(p.status.code())),
        ("reachable_angles", &|p: &AtlasPoint| {
            p.reachable_angles as f64
        }),
        ("beyond_model_angles", &|p: &AtlasPoint| {
            p.beyond_model_angles as f64
        }),
        ("best_angle", &|p: &AtlasPoint| p.best_angle),
        ("best_measure", &|p: &AtlasPoint| p.best_measure),
        ("worst_angle", &|p: &AtlasPoint| p.worst_angle),
        ("worst_measure", &|p: &AtlasPoint| p.worst_measure),
    ];
    for (name, f) in fields {
        npz.add_array(name, &grid(f).map_err(shape)?)
            .map_err(|e| err(&e))?;
    }
    npz.add_array(
        "best_deflection",
        &stack(6, &|p| p.best_deflection.to_vec()).map_err(shape)?,
    )
    .map_err(|e| err(&e))?;
    npz.add_array("best_q", &stack(dof, &|p| p.best_q.clone()).map_err(shape)?)
        .map_err(|e| err(&e))?;
    npz.finish().map_err(|e| err(&e))?;
    Ok(())
}

/// The heat-map colour of `t` in \[0, 1\]: dark blue (stiff) through teal and green to yellow
/// (soft), a perceptually ordered ramp close to viridis.
pub fn heat_color(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let s = t * (STOPS.len() - 1) as f64;
    let k = (s.floor() as usize).min(STOPS.len() - 2);
    let f = s - k as f64;
    let (a, b) = (STOPS[k], STOPS[k + 1]);
    let mix = |u: f64, v: f64| (u + (v - u) * f).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The title of the heat map, in words.
pub fn title(task: &AtlasTask) -> String {
    let f = Vector3::new(task.wrench[0], task.wrench[1], task.wrench[2]).norm();
    let a = task.tool_axis / task.tool_axis.norm();
    format!(
        "{}: smallest TCP deflection under {f:.0} N over the rotation about the tool axis \
         ({:.2}, {:.2}, {:.2}), plane z = {:.2} m",
        task.name, a.x, a.y, a.z, task.z
    )
}

/// Draws `atlas.png`: the best deflection \[mm\] per grid cell (grey: unreachable), a colour
/// bar in the column right of the plot, the best cell outlined.
pub fn plot_heat_map(path: &Path, task: &AtlasTask, points: &[AtlasPoint]) -> Result<(), SimError> {
    let mm: Vec<f64> = points.iter().map(|p| p.best_measure * 1e3).collect();
    heat_map(
        path,
        &HeatMap {
            title: &title(task),
            xs: &task.xs,
            ys: &task.ys,
            mm: &mm,
            bar: "best |dp| [mm]",
            axes: ("x [m], base frame", "y [m], base frame"),
        },
    )
}

/// A heat map over an x-y grid: `mm[k]` at `(xs[k / ys.len()], ys[k % ys.len()])`, NaN or
/// infinite where nothing reaches.
#[derive(Debug, Clone, Copy)]
pub struct HeatMap<'a> {
    /// The title.
    pub title: &'a str,
    /// The grid's x and y values.
    pub xs: &'a [f64],
    /// See `xs`.
    pub ys: &'a [f64],
    /// The values \[mm\], x-major.
    pub mm: &'a [f64],
    /// The colour bar's label.
    pub bar: &'a str,
    /// The axes' labels.
    pub axes: (&'a str, &'a str),
}

/// Draws a [`HeatMap`] (grey: unreachable), a colour bar in the column right of the plot, the
/// smallest cell outlined.
pub fn heat_map(path: &Path, m: &HeatMap<'_>) -> Result<(), SimError> {
    let root = canvas(path, (1100, 760))?;
    let mm = m.mm;
    let (lo, hi) = mm
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(*v), h.max(*v))
        });
    let span = if hi > lo { hi - lo } else { 1.0 };
    let bar_entry = format!("{} (colour bar)", m.bar);
    let entries = [
        Entry::new(
            &bar_entry,
            crate::plot_style::Role::Guide,
            crate::plot_style::Swatch::Marker,
        ),
        Entry::new(
            "unreachable",
            crate::plot_style::Role::Guide,
            crate::plot_style::Swatch::Marker,
        ),
        Entry::new(
            "best placement (outlined)",
            crate::plot_style::Role::Guide,
            crate::plot_style::Swatch::Marker,
        ),
    ];
    let (plot, side) = figure(&root, m.title, 18, &entries)?;
    let half = |v: &[f64]| {
        if v.len() > 1 {
            0.5 * (v[1] - v[0]).abs()
        } else {
            0.05
        }
    };
    let (hx, hy) = (half(m.xs), half(m.ys));
    let xr = m.xs.iter().fold(f64::INFINITY, |a, b| a.min(*b)) - hx
        ..m.xs.iter().fold(f64::NEG_INFINITY, |a, b| a.max(*b)) + hx;
    let yr = m.ys.iter().fold(f64::INFINITY, |a, b| a.min(*b)) - hy
        ..m.ys.iter().fold(f64::NEG_INFINITY, |a, b| a.max(*b)) + hy;
    let mut chart = new_chart(&plot, CHART, xr, yr, m.axes)?;
    let best = mm
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map(|(k, _)| k);
    let ny = m.ys.len();
    for (k, v) in mm.iter().enumerate() {
        let (Some(x), Some(y)) = (m.xs.get(k / ny.max(1)), m.ys.get(k % ny.max(1))) else {
            continue;
        };
        let color = if v.is_finite() {
            heat_color((v - lo) / span)
        } else {
            RGBColor(200, 200, 200)
        };
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(x - hx, y - hy), (x + hx, y + hy)],
                color.filled(),
            )))
            .map_err(perr)?;
        if best == Some(k) {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x - hx, y - hy), (x + hx, y + hy)],
                    RED.stroke_width(3),
                )))
                .map_err(perr)?;
        }
    }
    draw_color_bar(&side, m.bar, (lo, span))?;
    present(&root, path)
}

/// The colour bar of `bar` from `lo` over `span` \[mm\], and the unreachable and best swatches.
fn draw_color_bar(side: &Area<'_>, bar: &str, (lo, span): (f64, f64)) -> Result<(), SimError> {
    // The colour bar: 200 px high, ticks at the ends and the middle.
    let (x0, y0, w, h) = (16, 40, 22, 240);
    for i in 0..h {
        let t = 1.0 - f64::from(i) / f64::from(h - 1);
        side.draw(&Rectangle::new(
            [(x0, y0 + i), (x0 + w, y0 + i + 1)],
            heat_color(t).filled(),
        ))
        .map_err(perr)?;
    }
    let font = ("sans-serif", LEGEND_FONT).into_font().color(&BLACK);
    side.draw(&Text::new(bar, (x0, y0 - 24), font.clone()))
        .map_err(perr)?;
    for (t, dy) in [(1.0, 0), (0.5, h / 2), (0.0, h - 1)] {
        // Three decimals: micrometres.
        let label = format!("{:.3}", lo + t * span);
        side.draw(&Text::new(label, (x0 + w + 8, y0 + dy - 7), font.clone()))
            .map_err(perr)?;
    }
    side.draw(&Rectangle::new(
        [(x0, y0 + h + 20), (x0 + w, y0 + h + 36)],
        RGBColor(200, 200, 200).filled(),
    ))
    .map_err(perr)?;
    side.draw(&Text::new(
        "unreachable",
        (x0 + w + 8, y0 + h + 21),
        font.clone(),
    ))
    .map_err(perr)?;
    side.draw(&Rectangle::new(
        [(x0, y0 + h + 46), (x0 + w, y0 + h + 62)],
        RED.stroke_width(3),
    ))
    .map_err(perr)?;
    side.draw(&Text::new(
        "best placement",
        (x0 + w + 8, y0 + h + 47),
        font,
    ))
    .map_err(perr)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_heat_ramp_runs_from_dark_blue_to_yellow_and_brightens_monotonically() {
        assert_eq!(heat_color(0.0), RGBColor(68, 1, 84));
        assert_eq!(heat_color(1.0), RGBColor(253, 231, 37));
        assert_eq!(heat_color(f64::NAN), heat_color(0.0));
        assert_eq!(heat_color(2.0), heat_color(1.0));
        let luma =
            |c: RGBColor| 0.299 * f64::from(c.0) + 0.587 * f64::from(c.1) + 0.114 * f64::from(c.2);
        let mut last = -1.0;
        for k in 0..=100 {
            let l = luma(heat_color(f64::from(k) / 100.0));
            assert!(l >= last - 0.5, "{k}: {l} after {last}");
            last = l;
        }
    }
}
