//! The machined part against the nominal one as a heat map (the views of Hähn and Weigold's
//! Fig. 10-13): per z-map cell, the predicted height minus the nominal one, red where
//! material is left, blue where the tool cut too deep, white where they agree, grey where
//! neither part was cut. One panel per predicted part, one colour scale for all: symmetric,
//! saturating at the floors' deviation (cells both parts cut), so a wall shifted
//! sideways shows as a saturated band whatever its depth. The scale saturates at the 99th
//! percentile of the floors' deviation.

use std::path::Path;

use deflect_core::machining::engagement::MIN_DEPTH;
use deflect_core::machining::stock::ZMap;
use plotters::prelude::*;

use crate::SimError;
use crate::plot_style::{Area, CHART, LEGEND_FONT, canvas, figure, new_chart, perr, present};

/// Most blocks drawn along an axis: larger grids are drawn in blocks of cells, each showing
/// its cell of largest deviation.
pub const MAX_BLOCKS: usize = 240;

/// The deviation colour of `t` in \[-1, 1\]: blue through white to red.
pub fn deviation_color(t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let (end, a) = if t >= 0.0 {
        ((178.0, 24.0, 43.0), t)
    } else {
        ((33.0, 102.0, 172.0), -t)
    };
    let mix = |e: f64| (255.0 + (e - 255.0) * a).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(end.0), mix(end.1), mix(end.2))
}

/// Per cell: `Some(predicted - nominal)` \[m\] where either part is cut below `top`.
fn deviations(nominal: &ZMap, part: &ZMap, top: f64) -> Vec<Option<f64>> {
    let cut = |h: f64| h < top - MIN_DEPTH;
    nominal
        .heights()
        .iter()
        .zip(part.heights())
        .map(|(&n, &p)| (cut(n) || cut(p)).then_some(p - n))
        .collect()
}

/// The colour scale's limit \[m\]: the 99th percentile of the deviation's magnitude over the
/// cells both parts cut (the floors), at least 1 um. A percentile, not the maximum: a wall
/// cell the shifted tool only grazed counts as cut in both and would set the scale to the
/// full depth, washing out every floor.
fn floor_limit(nominal: &ZMap, parts: &[(&str, &ZMap)], top: f64) -> f64 {
    let cut = |h: f64| h < top - MIN_DEPTH;
    let mut d: Vec<f64> = parts
        .iter()
        .flat_map(|(_, p)| nominal.heights().iter().zip(p.heights()))
        .filter(|&(&n, &p)| cut(n) && cut(p))
        .map(|(n, p)| (p - n).abs())
        .collect();
    if d.is_empty() {
        return 1.0e-6;
    }
    let k = ((d.len() - 1) as f64 * 0.99).round() as usize;
    let (_, v, _) = d.select_nth_unstable_by(k, f64::total_cmp);
    v.max(1.0e-6)
}

/// Draws the heat map of each of `parts` (label, predicted z-map) against `nominal` (same
/// grid), stock top `top` \[m\], to `path`.
pub fn plot_part_deviation(
    path: &Path,
    title: &str,
    nominal: &ZMap,
    parts: &[(&str, &ZMap)],
    top: f64,
) -> Result<(), SimError> {
    let (nx, ny) = nominal.shape();
    let root = canvas(
        path,
        ((560 * parts.len().max(1) as u32 + 160).max(900), 600),
    )?;
    let (width, _) = root.dim_in_pixel();
    let title = shorten(title, width.saturating_sub(40), 18);
    let (plot, side) = figure(&root, &title, 18, &[])?;
    let (plot, side) = {
        let (w, _) = plot.dim_in_pixel();
        let _ = side;
        plot.split_horizontally(w.saturating_sub(150))
    };
    let limit = floor_limit(nominal, parts, top);
    let (o, c) = (nominal.origin(), nominal.cell());
    let bx = nx.div_ceil(MAX_BLOCKS).max(1);
    let by = ny.div_ceil(MAX_BLOCKS).max(1);
    let panels = plot.split_evenly((1, parts.len().max(1)));
    for (area, (label, part)) in panels.iter().zip(parts) {
        let dev = deviations(nominal, part, top);
        // The label in lines that fit the panel (split at "; " and ": "), each shortened in
        // the middle if it still does not.
        let (pw, _) = area.dim_in_pixel();
        let lines = wrap(label, pw.saturating_sub(16), 15);
        let head_px = 8 + 19 * lines.len() as u32;
        let (head, caption) = area.split_vertically(head_px);
        let font = ("sans-serif", 15).into_font().color(&BLACK);
        for (k, line) in lines.iter().enumerate() {
            head.draw(&Text::new(
                line.clone(),
                (8, 4 + 19 * k as i32),
                font.clone(),
            ))
            .map_err(perr)?;
        }
        // Equal scales on x and y: the part's shape, not the panel's.
        let (w, h) = caption.dim_in_pixel();
        let pw = f64::from(w.saturating_sub(CHART.label_areas.1 + 24).max(1));
        let ph = f64::from(h.saturating_sub(CHART.label_areas.0 + 24).max(1));
        let (sx, sy) = (nx as f64 * c * 1e3, ny as f64 * c * 1e3);
        let scale = (pw / sx).min(ph / sy);
        let (cx, cy) = ((o.x * 1e3) + 0.5 * sx, (o.y * 1e3) + 0.5 * sy);
        let (hx, hy) = (0.5 * pw / scale, 0.5 * ph / scale);
        let mut chart = new_chart(
            &caption,
            CHART,
            cx - hx..cx + hx,
            cy - hy..cy + hy,
            ("x [mm], workpiece", "y [mm], workpiece"),
        )?;
        let mut cells = Vec::new();
        for j0 in (0..ny).step_by(by) {
            for i0 in (0..nx).step_by(bx) {
                // The block's deviation of largest magnitude; grey if no cell was cut.
                let mut worst: Option<f64> = None;
                for j in j0..(j0 + by).min(ny) {
                    for i in i0..(i0 + bx).min(nx) {
                        if let Some(Some(d)) = dev.get(j * nx + i)
                            && worst.is_none_or(|w| d.abs() > w.abs())
                        {
                            worst = Some(*d);
                        }
                    }
                }
                let color = worst.map_or(RGBColor(225, 225, 225), |d| deviation_color(d / limit));
                let (x0, y0) = (o.x + i0 as f64 * c, o.y + j0 as f64 * c);
                let (x1, y1) = (
                    o.x + (i0 + bx).min(nx) as f64 * c,
                    o.y + (j0 + by).min(ny) as f64 * c,
                );
                cells.push(Rectangle::new(
                    [(x0 * 1e3, y0 * 1e3), (x1 * 1e3, y1 * 1e3)],
                    color.filled(),
                ));
            }
        }
        chart.draw_series(cells).map_err(perr)?;
    }
    draw_color_bar(&side, limit)?;
    present(&root, path)
}

/// The colour bar of the deviation scale, `limit` \[m\] at its ends, and the uncut swatch.
fn draw_color_bar(side: &Area<'_>, limit: f64) -> Result<(), SimError> {
    let (x0, y0, w, h) = (16, 60, 22, 300);
    for i in 0..h {
        let t = 1.0 - 2.0 * f64::from(i) / f64::from(h - 1);
        side.draw(&Rectangle::new(
            [(x0, y0 + i), (x0 + w, y0 + i + 1)],
            deviation_color(t).filled(),
        ))
        .map_err(perr)?;
    }
    let font = ("sans-serif", LEGEND_FONT).into_font().color(&BLACK);
    for (text, dy) in [("height above", -44), ("nominal [mm]", -26)] {
        side.draw(&Text::new(text, (x0, y0 + dy), font.clone()))
            .map_err(perr)?;
    }
    for (t, dy, note) in [(1.0, 0, " left"), (0.0, h / 2, ""), (-1.0, h - 1, " deep")] {
        let label = format!("{:+.3}{note}", t * limit * 1e3);
        side.draw(&Text::new(label, (x0 + w + 6, y0 + dy - 7), font.clone()))
            .map_err(perr)?;
    }
    side.draw(&Rectangle::new(
        [(x0, y0 + h + 20), (x0 + w, y0 + h + 36)],
        RGBColor(225, 225, 225).filled(),
    ))
    .map_err(perr)?;
    side.draw(&Text::new("uncut", (x0 + w + 6, y0 + h + 21), font))
        .map_err(perr)?;
    Ok(())
}

/// About how many characters of a sans-serif font of `px` pixels fit in `width` pixels.
fn chars_in(width: u32, px: u32) -> usize {
    (f64::from(width) / (0.55 * f64::from(px.max(1))))
        .floor()
        .max(8.0) as usize
}

/// `text` cut in the middle (with "...") to fit `width` pixels at `px`.
pub fn shorten(text: &str, width: u32, px: u32) -> String {
    let max = chars_in(width, px);
    let chars: Vec<char> = text.chars().collect();
    if chars.len() <= max {
        return text.to_string();
    }
    let keep = max.saturating_sub(3);
    let head = keep / 2;
    let tail = keep - head;
    let mut out: String = chars.iter().take(head).collect();
    out.push_str("...");
    out.extend(chars.iter().skip(chars.len() - tail));
    out
}

/// `text` in lines of at most `width` pixels at `px`: broken after "; " or ": " where a line
/// would not fit, each line still too long shortened in the middle.
pub fn wrap(text: &str, width: u32, px: u32) -> Vec<String> {
    let max = chars_in(width, px);
    let mut pieces: Vec<String> = Vec::new();
    for part in text.split_inclusive("; ") {
        for piece in part.split_inclusive(": ") {
            pieces.push(piece.to_string());
        }
    }
    let mut lines: Vec<String> = Vec::new();
    for piece in pieces {
        match lines.last_mut() {
            Some(l) if l.chars().count() + piece.chars().count() <= max => l.push_str(&piece),
            _ => lines.push(piece),
        }
    }
    lines
        .into_iter()
        .map(|l| shorten(l.trim_end(), width, px))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_deviation_ramp_is_white_at_zero_and_saturates() {
        assert_eq!(deviation_color(0.0), RGBColor(255, 255, 255));
        assert_eq!(deviation_color(1.0), RGBColor(178, 24, 43));
        assert_eq!(deviation_color(-1.0), RGBColor(33, 102, 172));
        assert_eq!(deviation_color(5.0), deviation_color(1.0));
        assert_eq!(deviation_color(f64::NAN), deviation_color(0.0));
    }

    #[test]
    fn long_titles_fit_their_width() {
        let long = "a/very/long/path/to/the/program/of/a/user/who/names/files/at/length/part.nc";
        let s = shorten(long, 200, 18);
        assert!(s.chars().count() <= chars_in(200, 18), "{s}");
        assert!(s.starts_with("a/very") && s.ends_with("part.nc") && s.contains("..."));
        assert_eq!(shorten("short", 200, 18), "short");
        let label =
            "compensated offline: floors max 0.001 mm, RMS 0.000 mm; walls 0 mm^2 left, 0 overcut";
        let lines = wrap(label, 300, 15);
        assert!(lines.len() >= 2, "{lines:?}");
        for l in &lines {
            assert!(l.chars().count() <= chars_in(300, 15), "{l}");
        }
        assert_eq!(lines.concat().replace(' ', ""), label.replace(' ', ""));
    }
}
