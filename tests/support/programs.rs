//! Generated machining programs (G-code, mm) on sloped and 3-D floors: what the tolerance
//! tests and the throughput benchmark run, written as a CAM system would write them.

use std::fmt::Write as _;

/// Zig-zag passes along x over a floor sloped along the feed, as
/// `../shared/machining/sloped_floor_zigzag.nc` is: `passes` passes `length` long, `stepover`
/// apart, the floor at `z = -depth - slope x` (mm; the tool goes down to the floor first).
pub fn sloped_zigzag(passes: usize, length: f64, stepover: f64, depth: f64, slope: f64) -> String {
    let mut g = String::from("G21 G90 G17\nS2000 M3\nG0 X0 Y0 Z5\n");
    let _ = writeln!(g, "G1 X0 Y0 Z{:.4} F508", -depth);
    let z = |x: f64| -depth - slope * x;
    for k in 0..passes {
        let y = k as f64 * stepover;
        let (a, b) = if k % 2 == 0 {
            (0.0, length)
        } else {
            (length, 0.0)
        };
        if k > 0 {
            let _ = writeln!(g, "G1 X{a:.4} Y{y:.4} Z{:.4}", z(a));
        }
        let _ = writeln!(g, "G1 X{b:.4} Y{y:.4} Z{:.4}", z(b));
    }
    g.push_str("G0 Z5\nM5\nM2\n");
    g
}

/// A raster over the surface `z = surface(x, y)` (mm): lines along x from `x0` to `x1`,
/// `stepover` apart from `y0` to `y1`, a point every `step`, zig-zag, at `feed` mm/min, the
/// tool's tip on the surface, with tool 1.
#[allow(clippy::too_many_arguments)]
pub fn raster(
    surface: impl Fn(f64, f64) -> f64,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    stepover: f64,
    step: f64,
    feed: f64,
    rpm: f64,
) -> String {
    let mut g = String::new();
    let _ = write!(
        g,
        "G21 G90 G17\nT1 M6\nS{rpm:.0} M3\nG0 X{x0:.4} Y{y0:.4} Z5\n"
    );
    let _ = writeln!(g, "G1 Z{:.4} F{feed:.0}", surface(x0, y0));
    let lines = ((y1 - y0) / stepover).round() as usize;
    let points = ((x1 - x0) / step).round() as usize;
    for k in 0..=lines {
        let y = y0 + k as f64 * stepover;
        for i in 0..=points {
            let i = if k % 2 == 0 { i } else { points - i };
            let x = x0 + i as f64 * step;
            let _ = writeln!(g, "G1 X{x:.4} Y{y:.4} Z{:.4}", surface(x, y));
        }
    }
    g.push_str("G0 Z5\nM5\nM2\n");
    g
}

/// A spherical bowl of `radius` sunk `depth` into the stock's top (mm), the surface a ball
/// end mill's tip follows.
pub fn bowl(radius: f64, depth: f64) -> impl Fn(f64, f64) -> f64 {
    // The sphere through the rim (z = 0 at r = radius) with its lowest point at -depth.
    let sphere = (radius * radius + depth * depth) / (2.0 * depth);
    move |x: f64, y: f64| {
        let r2 = x * x + y * y;
        if r2 >= radius * radius {
            0.0
        } else {
            sphere - depth - (sphere * sphere - r2).sqrt()
        }
    }
}

/// A wavy free-form floor `amplitude` mm high around `-depth` (the 3-D raster of the
/// benchmark).
pub fn waves(depth: f64, amplitude: f64) -> impl Fn(f64, f64) -> f64 {
    move |x: f64, y: f64| -depth + amplitude * (x / 11.0).sin() * (y / 17.0).cos()
}
