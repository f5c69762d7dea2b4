//! The predicted part in 3-D as a picture: the machined surface seen obliquely from above
//! (orthographic, 35 degrees of elevation, the workpiece x to the right and back), each
//! triangle coloured by its vertices' mean deviation along the normal (red material left,
//! blue overcut, white on the nominal part: [`super::part_map::deviation_color`]) and shaded
//! by a light from the viewer's upper left so the shape reads. One panel per predicted part,
//! one colour scale for all, symmetric and saturating at the 99th percentile of the
//! deviations.

use std::path::Path;

use deflect_core::machining::dexel::surface::SurfaceMesh;
use nalgebra::Vector3;
use plotters::prelude::*;

use super::part_map::{deviation_color, wrap};
use crate::SimError;
use crate::plot_style::{Area, LEGEND_FONT, canvas, figure, perr, present};

/// The view: right, up and towards-the-viewer directions (workpiece frame).
fn view() -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let (az, el) = ((-35f64).to_radians(), 35f64.to_radians());
    let toward = Vector3::new(el.cos() * az.sin(), -el.cos() * az.cos(), el.sin());
    let right = Vector3::z().cross(&toward).normalize();
    let up = toward.cross(&right);
    (right, up, toward)
}

/// The colour scale's end \[m\]: the 99th percentile of every part's deviation (a few
/// points at the cut's edges, where a surface ends, would otherwise wash the rest out), at
/// least 1 um.
pub fn scale(parts: &[(&str, &SurfaceMesh)]) -> f64 {
    let mut all: Vec<f64> = parts
        .iter()
        .flat_map(|(_, m)| m.points.iter().map(|p| p.deviation.abs()))
        .filter(|d| d.is_finite())
        .collect();
    all.sort_by(f64::total_cmp);
    let k = (all.len() as f64 * 0.99) as usize;
    all.get(k.min(all.len().saturating_sub(1)))
        .copied()
        .unwrap_or(0.0)
        .max(1.0e-6)
}

/// Draws `parts` (label, mesh) side by side into the PNG at `path`.
pub fn plot_part_view(
    path: &Path,
    title: &str,
    parts: &[(&str, &SurfaceMesh)],
) -> Result<(), SimError> {
    let root = canvas(
        path,
        ((620 * parts.len().max(1) as u32 + 170).max(900), 620),
    )?;
    let (plot, _) = figure(&root, title, 18, &[])?;
    let (w, _) = plot.dim_in_pixel();
    let (plot, side) = plot.split_horizontally(w.saturating_sub(160));
    let limit = scale(parts);
    let (right, up, toward) = view();
    let light = (toward + up * 0.6 - right * 0.4).normalize();
    // The same extent in every panel: all parts' points.
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for (_, m) in parts {
        for p in &m.points {
            let s = [p.position.dot(&right), p.position.dot(&up)];
            for k in 0..2 {
                lo[k] = lo[k].min(s[k]);
                hi[k] = hi[k].max(s[k]);
            }
        }
    }
    let panels = plot.split_evenly((1, parts.len().max(1)));
    for (area, (label, mesh)) in panels.iter().zip(parts) {
        let (pw, ph) = area.dim_in_pixel();
        let lines = wrap(label, pw.saturating_sub(16), 15);
        let font = ("sans-serif", 15).into_font().color(&BLACK);
        for (k, line) in lines.iter().enumerate() {
            area.draw(&Text::new(
                line.clone(),
                (8, 4 + 19 * k as i32),
                font.clone(),
            ))
            .map_err(perr)?;
        }
        let top = 12 + 19 * lines.len() as i32;
        let (aw, ah) = (
            f64::from(pw.saturating_sub(24)),
            f64::from(ph.saturating_sub(top as u32 + 12)),
        );
        let span = [(hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9)];
        let px = (aw / span[0]).min(ah / span[1]);
        let to_px = |p: &Vector3<f64>| {
            let (sx, sy) = (p.dot(&right) - lo[0], p.dot(&up) - lo[1]);
            (
                12 + (sx * px + 0.5 * (aw - span[0] * px)) as i32,
                top + (ah - sy * px - 0.5 * (ah - span[1] * px)) as i32,
            )
        };
        // Far triangles first.
        let mut order: Vec<(f64, usize)> = mesh
            .triangles
            .iter()
            .enumerate()
            .filter_map(|(k, t)| {
                let depth: Option<f64> = t
                    .iter()
                    .map(|&v| mesh.points.get(v as usize).map(|p| p.position.dot(&toward)))
                    .sum();
                depth.map(|d| (d, k))
            })
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, k) in order {
            let Some(t) = mesh.triangles.get(k) else {
                continue;
            };
            let vs: Vec<_> = t
                .iter()
                .filter_map(|&v| mesh.points.get(v as usize))
                .collect();
            let [a, b, c] = vs.as_slice() else { continue };
            let dev = (a.deviation + b.deviation + c.deviation) / 3.0;
            let normal = (a.normal + b.normal + c.normal).normalize();
            let shade = 0.55 + 0.45 * normal.dot(&light).abs();
            let RGBColor(r, g, bl) = deviation_color(dev / limit);
            let dim = |v: u8| (f64::from(v) * shade).round().clamp(0.0, 255.0) as u8;
            let color = RGBColor(dim(r), dim(g), dim(bl));
            let points = vec![to_px(&a.position), to_px(&b.position), to_px(&c.position)];
            area.draw(&Polygon::new(points, color.filled()))
                .map_err(perr)?;
        }
    }
    draw_color_bar(&side, limit)?;
    present(&root, path)
}

/// The colour bar of the deviation scale, `limit` \[m\] at its ends.
fn draw_color_bar(side: &Area<'_>, limit: f64) -> Result<(), SimError> {
    let (x0, y0, bw, bh) = (16, 70, 22, 300);
    for i in 0..bh {
        let t = 1.0 - 2.0 * f64::from(i) / f64::from(bh - 1);
        side.draw(&Rectangle::new(
            [(x0, y0 + i), (x0 + bw, y0 + i + 1)],
            deviation_color(t).filled(),
        ))
        .map_err(perr)?;
    }
    let font = ("sans-serif", LEGEND_FONT).into_font().color(&BLACK);
    for (text, dy) in [("deviation along", -44), ("the normal [mm]", -26)] {
        side.draw(&Text::new(text, (x0, y0 + dy), font.clone()))
            .map_err(perr)?;
    }
    for (t, dy, note) in [
        (1.0, 0, " left"),
        (0.0, bh / 2, ""),
        (-1.0, bh - 1, " overcut"),
    ] {
        let label = format!("{:+.3}{note}", t * limit * 1e3);
        side.draw(&Text::new(label, (x0 + bw + 6, y0 + dy - 7), font.clone()))
            .map_err(perr)?;
    }
    Ok(())
}
