//! The look of every PNG the testbed writes (plotters): one palette ([`color`]: the same
//! meaning has the same colour in every figure), the legend in a column right of the plot
//! area ([`figure`], [`legend_split`]: it never covers data), tick labels without "-0.0"
//! ([`tick_label`]) and axes with units.

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use crate::SimError;

/// What a series shows; [`color`] gives its colour, the same in every figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The reference: desired / nominal path, true outline.
    Desired,
    /// Without correction or compensation (uncorrected, uncompensated, raw).
    Uncorrected,
    /// With the correction or compensation (D'Alembert, Cartesian compensation, Eq. 10).
    Corrected,
    /// Compensation with pilot control (milling).
    Pilot,
    /// Compensation without sensor calibration (milling).
    Uncalibrated,
    /// Parallel robot OC, upper head.
    OcUpper,
    /// Parallel robot OC, lower head.
    OcLower,
    /// Parallel robot NC, upper head.
    NcUpper,
    /// Parallel robot NC, lower head.
    NcLower,
    /// Identified from frame-pair rotations.
    FramePairs,
    /// Identified from 6-D TCP deflections.
    TcpDeflection,
    /// Guide lines (leg changes, cutter entry and exit, ratio 1), drawn dashed: not data.
    Guide,
}

/// The palette (Okabe-Ito and Tol colours, distinct for colour-blind readers).
pub fn color(role: Role) -> RGBColor {
    match role {
        Role::Desired => RGBColor(0, 0, 0),
        Role::Uncorrected => RGBColor(213, 94, 0),
        Role::Corrected => RGBColor(0, 114, 178),
        Role::Pilot => RGBColor(0, 158, 115),
        Role::Uncalibrated => RGBColor(153, 153, 51),
        Role::OcUpper => RGBColor(230, 159, 0),
        Role::OcLower => RGBColor(86, 180, 233),
        Role::NcUpper => RGBColor(204, 121, 167),
        Role::NcLower => RGBColor(136, 34, 85),
        Role::FramePairs => RGBColor(68, 170, 153),
        Role::TcpDeflection => RGBColor(140, 86, 75),
        Role::Guide => RGBColor(90, 90, 90),
    }
}

/// The role of a parallel-robot configuration label ("OC GU", "NC GL", ...).
pub fn config_role(label: &str) -> Role {
    match label {
        "OC GU" => Role::OcUpper,
        "OC GL" => Role::OcLower,
        "NC GU" => Role::NcUpper,
        _ => Role::NcLower,
    }
}

/// A configuration label in words: "OC GU" -> "OC robot, upper head".
pub fn config_words(label: &str) -> String {
    let mut it = label.split(' ');
    let (mech, head) = (it.next().unwrap_or(label), it.next().unwrap_or(""));
    let head = match head {
        "GU" => "upper head",
        "GL" => "lower head",
        other => other,
    };
    format!("{mech} robot, {head}")
}

/// A tick label for `v` on an axis spanning `span`: the fewest decimals (up to 6) that show
/// `v` to 1e-6 of the span, float noise rounded, and never "-0" or "-0.0".
pub fn tick_label(v: f64, span: f64) -> String {
    let tol = (span.abs() * 1e-6).max(f64::MIN_POSITIVE);
    let mut s = format!("{v:.6}");
    for d in 0..=6 {
        let c = format!("{v:.d$}");
        if c.parse::<f64>().is_ok_and(|p| (p - v).abs() <= tol) {
            s = c;
            break;
        }
    }
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

/// A plotting error as a [`SimError`].
pub fn perr<E: std::fmt::Display>(e: E) -> SimError {
    SimError::new(format!("plot: {e}"))
}

const FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the embedded font for plotters (once).
pub fn register_font() {
    use std::sync::Once;
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// A drawing area of the PNG backend.
pub type Area<'b> = DrawingArea<BitMapBackend<'b>, Shift>;

/// A PNG canvas of `size` pixels at `path`, filled white (font registered).
pub fn canvas(path: &Path, size: (u32, u32)) -> Result<Area<'_>, SimError> {
    register_font();
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(perr)?;
    Ok(root)
}

/// Writes the PNG of `root` to `path` (the file it was created on); the error names the file.
pub fn present(root: &Area<'_>, path: &Path) -> Result<(), SimError> {
    root.present()
        .map_err(|e| SimError::file(path, "write the PNG plot", e))
}

/// A 2-D chart of `f64` axes.
pub type Chart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// How a legend entry's swatch is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Swatch {
    /// A solid line of this width.
    Line(u32),
    /// A dashed line of this width.
    Dashed(u32),
    /// A filled circle.
    Marker,
    /// A cross.
    Cross,
    /// A filled triangle pointing up.
    Arrow,
    /// A vertical error bar with caps.
    Bar,
}

/// One legend entry.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// Text.
    pub label: String,
    /// Colour.
    pub color: RGBColor,
    /// Swatch.
    pub swatch: Swatch,
}

impl Entry {
    /// An entry of `role`'s colour.
    pub fn new(label: impl Into<String>, role: Role, swatch: Swatch) -> Self {
        Self {
            label: label.into(),
            color: color(role),
            swatch,
        }
    }
}

/// Legend font size \[px\].
pub const LEGEND_FONT: u32 = 14;
/// Legend row height \[px\].
const ROW: u32 = 22;
/// Swatch length plus gaps \[px\].
const SWATCH: u32 = 44;

/// The legend column's width \[px\] for labels `label_px` wide, at most half of `width`.
pub fn legend_width(width: u32, label_px: &[u32]) -> u32 {
    let widest = label_px.iter().copied().max().unwrap_or(0);
    (widest + SWATCH + 16).min(width / 2)
}

/// Splits an area `width` wide at `x0` into the plot part `[x0, x0 + width - legend)` and the
/// legend column right of it: the pixel x-ranges `(plot, legend)`, disjoint by construction.
pub fn legend_split(x0: i32, width: u32, legend: u32) -> (Range<i32>, Range<i32>) {
    let cut = x0 + (width.saturating_sub(legend)) as i32;
    (x0..cut, cut..x0 + width as i32)
}

/// A titled figure on `area` with a legend column of `entries` on the right: returns the
/// plot area and the legend area (draw the legend with [`draw_legend`]).
pub fn figure<'b>(
    area: &Area<'b>,
    title: &str,
    title_px: u32,
    entries: &[Entry],
) -> Result<(Area<'b>, Area<'b>), SimError> {
    let body = area.titled(title, ("sans-serif", title_px)).map_err(perr)?;
    let font: TextStyle<'_> = ("sans-serif", LEGEND_FONT).into();
    let label_px: Vec<u32> = entries
        .iter()
        .map(|e| body.estimate_text_size(&e.label, &font).map_or(0, |s| s.0))
        .collect();
    let (w, _) = body.dim_in_pixel();
    let legend = if entries.is_empty() {
        0
    } else {
        legend_width(w, &label_px)
    };
    let (plot, _) = legend_split(0, w, legend);
    let (left, right) = body.split_horizontally(plot.end);
    Ok((left, right))
}

/// Draws `entries` top-down in the legend column `area` (from [`figure`]).
pub fn draw_legend(area: &Area<'_>, entries: &[Entry]) -> Result<(), SimError> {
    let font = ("sans-serif", LEGEND_FONT).into_font().color(&BLACK);
    for (i, e) in entries.iter().enumerate() {
        let y = 20 + (i as u32 * ROW) as i32;
        let (x0, x1) = (8, 36);
        match e.swatch {
            Swatch::Line(w) => area
                .draw(&PathElement::new(
                    vec![(x0, y), (x1, y)],
                    e.color.stroke_width(w),
                ))
                .map_err(perr)?,
            Swatch::Dashed(w) => {
                for (a, b) in [(x0, x0 + 8), (x0 + 12, x0 + 20), (x0 + 24, x1)] {
                    area.draw(&PathElement::new(
                        vec![(a, y), (b, y)],
                        e.color.stroke_width(w),
                    ))
                    .map_err(perr)?;
                }
            }
            Swatch::Marker => area
                .draw(&Circle::new(((x0 + x1) / 2, y), 4, e.color.filled()))
                .map_err(perr)?,
            Swatch::Cross => area
                .draw(&Cross::new(((x0 + x1) / 2, y), 5, e.color.stroke_width(2)))
                .map_err(perr)?,
            Swatch::Arrow => {
                let c = (x0 + x1) / 2;
                area.draw(&Polygon::new(
                    vec![(c - 6, y + 5), (c + 6, y + 5), (c, y - 6)],
                    e.color.filled(),
                ))
                .map_err(perr)?;
            }
            Swatch::Bar => {
                let c = (x0 + x1) / 2;
                for pts in [
                    vec![(c, y - 8), (c, y + 8)],
                    vec![(c - 5, y - 8), (c + 5, y - 8)],
                    vec![(c - 5, y + 8), (c + 5, y + 8)],
                ] {
                    area.draw(&PathElement::new(pts, e.color.stroke_width(2)))
                        .map_err(perr)?;
                }
            }
        }
        area.draw(&Text::new(
            e.label.clone(),
            (x1 + 8, y - (LEGEND_FONT as i32) / 2 - 1),
            font.clone(),
        ))
        .map_err(perr)?;
    }
    Ok(())
}

/// Font sizes and label areas of a chart.
#[derive(Debug, Clone, Copy)]
pub struct ChartStyle {
    /// Caption font size (figure titles, panel captions).
    pub caption: u32,
    /// X and y label area sizes.
    pub label_areas: (u32, u32),
    /// Axis label font size.
    pub labels: u32,
}

/// The usual style: caption 20, label areas 45 x 70, labels 15.
pub const CHART: ChartStyle = ChartStyle {
    caption: 20,
    label_areas: (45, 70),
    labels: 15,
};

/// A chart on `area` (no caption: the figure's title is drawn by [`figure`]), axis ranges
/// `x`, `y`, axis descriptions with units `desc`, tick labels by [`tick_label`].
pub fn new_chart<'a, 'b>(
    area: &'a Area<'b>,
    style: ChartStyle,
    x: Range<f64>,
    y: Range<f64>,
    desc: (&str, &str),
) -> Result<Chart<'a, 'b>, SimError> {
    let (sx, sy) = (x.end - x.start, y.end - y.start);
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(style.label_areas.0)
        .y_label_area_size(style.label_areas.1)
        .build_cartesian_2d(x, y)
        .map_err(perr)?;
    let fx = move |v: &f64| tick_label(*v, sx);
    let fy = move |v: &f64| tick_label(*v, sy);
    chart
        .configure_mesh()
        .x_desc(desc.0)
        .y_desc(desc.1)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .label_style(("sans-serif", style.labels))
        .draw()
        .map_err(perr)?;
    Ok(chart)
}

/// A range `[lo, hi]` of `values` (finite ones) with `pad` of its span added on each side;
/// `fallback` when there are none, at least `min_span` wide.
pub fn padded_range(values: impl IntoIterator<Item = f64>, pad: f64, min_span: f64) -> Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return 0.0..min_span;
    }
    if hi - lo < min_span {
        let c = 0.5 * (lo + hi);
        lo = c - 0.5 * min_span;
        hi = c + 0.5 * min_span;
    }
    let p = pad * (hi - lo);
    lo - p..hi + p
}

/// Draws a line series, solid or dashed.
pub fn line(
    chart: &mut Chart<'_, '_>,
    pts: Vec<(f64, f64)>,
    c: RGBColor,
    width: u32,
    dashed: bool,
) -> Result<(), SimError> {
    if dashed {
        chart
            .draw_series(DashedLineSeries::new(pts, 8, 5, c.stroke_width(width)))
            .map_err(perr)?;
    } else {
        chart
            .draw_series(LineSeries::new(pts, c.stroke_width(width)))
            .map_err(perr)?;
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn ticks_never_read_negative_zero_and_round_float_noise() {
        assert_eq!(tick_label(-0.0, 1.0), "0");
        assert_eq!(tick_label(-1e-17, 0.2), "0");
        assert_eq!(tick_label(-0.00000001, 0.5), "0");
        assert_eq!(tick_label(0.30000000000000004, 1.0), "0.3");
        assert_eq!(tick_label(-75.00000000000001, 150.0), "-75");
        assert_eq!(tick_label(-0.25, 1.0), "-0.25");
        assert_eq!(tick_label(1.5, 10.0), "1.5");
        assert_eq!(tick_label(2.0, 10.0), "2");
    }

    #[test]
    fn ranges_cover_every_value() {
        let r = padded_range([1.0, -3.0, f64::NAN, 2.0], 0.05, 0.01);
        assert!(r.start < -3.0 && r.end > 2.0);
        let r = padded_range([0.0, 0.0], 0.0, 0.2);
        assert!((r.end - r.start - 0.2).abs() < 1e-12);
    }

    /// The legend column never overlaps the plotting area, checked on the pixel rectangles
    /// of a drawn chart: the split itself and a real figure with long labels.
    #[test]
    fn legend_is_outside_the_plotting_area() {
        for (w, l) in [(1000, 200), (800, 900), (300, 10)] {
            let (p, g) = legend_split(5, w, legend_width(w, &[l]));
            assert!(p.end <= g.start && p.start == 5 && g.end == 5 + w as i32);
        }
        register_font();
        let (w, h) = (900u32, 500u32);
        let mut buf = vec![0u8; (w * h * 3) as usize];
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let entries: Vec<Entry> = (0..6)
            .map(|i| {
                Entry::new(
                    format!("a rather long legend label number {i}"),
                    Role::Corrected,
                    Swatch::Line(2),
                )
            })
            .collect();
        let (plot, legend) = figure(&root, "title", 20, &entries).unwrap();
        let chart = new_chart(&plot, CHART, 0.0..1.0, -1.0..1.0, ("x [s]", "y [m]")).unwrap();
        let (px, py) = chart.plotting_area().get_pixel_range();
        let (lx, ly) = legend.get_pixel_range();
        draw_legend(&legend, &entries).unwrap();
        let disjoint = px.end <= lx.start || lx.end <= px.start;
        assert!(disjoint, "plot {px:?} x {py:?}, legend {lx:?} x {ly:?}");
        // The rows fit in the legend column's height.
        assert!(20 + entries.len() as i32 * ROW as i32 <= ly.end - ly.start);
        // Long labels still leave the plot at least half the width.
        assert!(px.end - px.start > (w / 3) as i32);
    }
}
