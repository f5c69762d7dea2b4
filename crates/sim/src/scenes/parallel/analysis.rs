//! The paper's evaluation of a marked path (Appendix C, Eq. C1-C6), applied to the simulated
//! tool-point path instead of a scanned laser mark.
//!
//! 1. The path (in mm) is expressed in a frame whose `u` axis runs along the desired segment
//!    and `v` across it, sorted by `u` and resampled at the scanner's pixel pitch
//!    `rho = 21.17 um` (1200 dpi) by linear interpolation: the "filtered path" `(u_j, v_j)`.
//! 2. Fitted line `f(u)`: the `p = 0` limit of Eq. C1, the least-squares line.
//! 3. Smoothing spline `s(u)` with `p = 0.01`, `w_j = 1`: our discrete version of Eq. C1 on
//!    the uniform pixel grid, `p sum (v_j - s_j)^2 + (1 - p) sum (Delta^2 s_j / rho^2)^2 rho`
//!    (the second-derivative integral by second differences; `u` in mm as in the paper), a
//!    pentadiagonal SPD system solved by banded Cholesky.
//! 4. Length (Eq. C2) between `(u_i, s(u_i))` and `(u_f, s(u_f))`; area between line and
//!    spline by Eq. C3-C6 (trapezoids of perpendicular distances `d_j` over projected steps
//!    `Delta p_j`).
//!
//! Besides the paper's figures we report the maximum and RMS perpendicular distance of the
//! raw path samples from the desired line ("path deviation").

/// Scanner pixel pitch \[mm\] (1200 dpi).
pub const PIXEL_PITCH_MM: f64 = 0.02117;
/// Smoothing parameter of the spline (Appendix C).
pub const SPLINE_P: f64 = 0.01;

/// Figures of one straight path.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct LineMetrics {
    /// Desired length \[mm\].
    pub desired_length_mm: f64,
    /// Length between the spline's end points, Eq. C2 \[mm\].
    pub length_mm: f64,
    /// Area between fitted line and spline, Eq. C6 \[mm^2\].
    pub area_mm2: f64,
    /// Largest perpendicular distance of a path sample from the desired line \[mm\].
    pub max_dev_mm: f64,
    /// RMS of the perpendicular distances \[mm\].
    pub rms_dev_mm: f64,
    /// Samples used.
    pub samples: usize,
}

/// Smoothing spline on a uniform grid of pitch `h` (see the module docs): solves
/// `(p I + (1 - p) / h^3 D^T D) s = p y` with `D` the second-difference operator.
pub fn smoothing_spline(y: &[f64], h: f64, p: f64) -> Vec<f64> {
    let n = y.len();
    if n < 3 || p >= 1.0 {
        return y.to_vec();
    }
    let lam = (1.0 - p) / (h * h * h);
    // Band of A = p I + lam D^T D: diagonals 0, 1, 2.
    let mut a0 = vec![0.0; n];
    let mut a1 = vec![0.0; n];
    let mut a2 = vec![0.0; n];
    for k in 0..n - 2 {
        // Row of D: [1, -2, 1] at k, k+1, k+2.
        let c = [1.0, -2.0, 1.0];
        for r in 0..3 {
            for s in r..3 {
                let v = lam * c[r] * c[s];
                match s - r {
                    0 => a0[k + r] += v,
                    1 => a1[k + r] += v,
                    _ => a2[k + r] += v,
                }
            }
        }
    }
    for d in &mut a0 {
        *d += p;
    }
    // Banded LDL^T (bandwidth 2).
    let mut d = vec![0.0; n];
    let mut l1 = vec![0.0; n];
    let mut l2 = vec![0.0; n];
    for i in 0..n {
        let mut di = a0[i];
        if i >= 1 {
            di -= l1[i - 1] * l1[i - 1] * d[i - 1];
        }
        if i >= 2 {
            di -= l2[i - 2] * l2[i - 2] * d[i - 2];
        }
        d[i] = di;
        if i + 1 < n {
            let mut v = a1[i];
            if i >= 1 {
                v -= l1[i - 1] * l2[i - 1] * d[i - 1];
            }
            l1[i] = v / di;
        }
        if i + 2 < n {
            l2[i] = a2[i] / di;
        }
    }
    // Solve L z = p y, D w = z, L^T s = w.
    let mut z: Vec<f64> = y.iter().map(|v| p * v).collect();
    for i in 0..n {
        if i >= 1 {
            z[i] -= l1[i - 1] * z[i - 1];
        }
        if i >= 2 {
            z[i] -= l2[i - 2] * z[i - 2];
        }
    }
    for i in 0..n {
        z[i] /= d[i];
    }
    for i in (0..n).rev() {
        if i + 1 < n {
            z[i] -= l1[i] * z[i + 1];
        }
        if i + 2 < n {
            z[i] -= l2[i] * z[i + 2];
        }
    }
    z
}

/// Least-squares line `v = a + b u`: `(a, b)`.
pub fn line_fit(u: &[f64], v: &[f64]) -> (f64, f64) {
    let n = u.len().max(1) as f64;
    let mu = u.iter().sum::<f64>() / n;
    let mv = v.iter().sum::<f64>() / n;
    let (mut suv, mut suu) = (0.0, 0.0);
    for (a, b) in u.iter().zip(v) {
        suv += (a - mu) * (b - mv);
        suu += (a - mu) * (a - mu);
    }
    let b = if suu > 0.0 { suv / suu } else { 0.0 };
    (mv - b * mu, b)
}

/// Evaluates a path `points` ((x, y) \[m\]) that should follow the segment `start -> end` \[m\].
pub fn evaluate_line(points: &[[f64; 2]], start: [f64; 2], end: [f64; 2]) -> LineMetrics {
    let (dx, dy) = (end[0] - start[0], end[1] - start[1]);
    let len = (dx * dx + dy * dy).sqrt();
    let mut out = LineMetrics {
        desired_length_mm: len * 1e3,
        samples: points.len(),
        ..Default::default()
    };
    if points.len() < 4 || len <= 0.0 {
        return out;
    }
    let (ex, ey) = (dx / len, dy / len);
    // (u, v) in mm.
    let mut uv: Vec<(f64, f64)> = points
        .iter()
        .map(|p| {
            let (rx, ry) = (p[0] - start[0], p[1] - start[1]);
            ((rx * ex + ry * ey) * 1e3, (-rx * ey + ry * ex) * 1e3)
        })
        .collect();
    let mut max_dev: f64 = 0.0;
    let mut sq = 0.0;
    for (_, v) in &uv {
        max_dev = max_dev.max(v.abs());
        sq += v * v;
    }
    out.max_dev_mm = max_dev;
    out.rms_dev_mm = (sq / uv.len() as f64).sqrt();
    uv.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (u0, u1) = (uv[0].0, uv[uv.len() - 1].0);
    let n = ((u1 - u0) / PIXEL_PITCH_MM).floor() as usize + 1;
    if n < 4 {
        return out;
    }
    let mut us = Vec::with_capacity(n);
    let mut vs = Vec::with_capacity(n);
    let mut k = 0;
    for j in 0..n {
        let u = u0 + j as f64 * PIXEL_PITCH_MM;
        while k + 2 < uv.len() && uv[k + 1].0 < u {
            k += 1;
        }
        let (a, b) = (uv[k], uv[k + 1]);
        let t = if b.0 > a.0 {
            ((u - a.0) / (b.0 - a.0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        us.push(u);
        vs.push(a.1 + t * (b.1 - a.1));
    }
    let s = smoothing_spline(&vs, PIXEL_PITCH_MM, SPLINE_P);
    let (a, b) = line_fit(&us, &vs);
    let f = |u: f64| a + b * u;
    let (ui, uf) = (us[0], us[n - 1]);
    // Eq. C2 between the path's first and last points (u0, u1), the spline's ends for v.
    out.length_mm = ((u1 - u0).powi(2) + (s[n - 1] - s[0]).powi(2)).sqrt();
    // Eq. C3-C6.
    let bvec = (uf - ui, f(uf) - f(ui));
    let bn = (bvec.0 * bvec.0 + bvec.1 * bvec.1).sqrt();
    let mut area = 0.0;
    let mut prev: Option<(f64, f64)> = None;
    for j in 0..n {
        let c = (us[j] - ui, s[j] - f(ui));
        let d = (bvec.0 * c.1 - bvec.1 * c.0).abs() / bn;
        let p = (bvec.0 * c.0 + bvec.1 * c.1) / bn;
        if let Some((d0, p0)) = prev {
            area += 0.5 * (d0 + d) * (p - p0);
        }
        prev = Some((d, p));
    }
    out.area_mm2 = area;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_path_has_no_area_and_its_length() {
        let pts: Vec<[f64; 2]> = (0..=200).map(|k| [0.1 * k as f64 / 200.0, 0.0]).collect();
        let m = evaluate_line(&pts, [0.0, 0.0], [0.1, 0.0]);
        assert!((m.length_mm - 100.0).abs() < 0.03, "{m:?}");
        assert!(m.area_mm2 < 1e-9 && m.max_dev_mm < 1e-12);
    }

    #[test]
    fn sine_bump_area() {
        // v = A sin(pi u / L): area between its least-squares line and itself.
        let amp = 1e-4; // 0.1 mm
        let pts: Vec<[f64; 2]> = (0..=400)
            .map(|k| {
                let u = 0.1 * k as f64 / 400.0;
                [u, amp * (core::f64::consts::PI * u / 0.1).sin()]
            })
            .collect();
        let m = evaluate_line(&pts, [0.0, 0.0], [0.1, 0.0]);
        // Line at the mean 2A/pi; area = integral |A sin - 2A/pi| du over 100 mm.
        let mean = 2.0 * 0.1 / core::f64::consts::PI;
        let n = 100_000;
        let exact: f64 = (0..n)
            .map(|k| {
                let u = 100.0 * (k as f64 + 0.5) / n as f64;
                (0.1 * (core::f64::consts::PI * u / 100.0).sin() - mean).abs() * 100.0 / n as f64
            })
            .sum();
        assert!(
            (m.area_mm2 - exact).abs() < 0.02 * exact,
            "{} vs {exact}",
            m.area_mm2
        );
        assert!((m.max_dev_mm - 0.1).abs() < 1e-6);
    }
}
