//! The per-revolution force of a chip whose depth varies with the immersion angle: the
//! mechanistic model of [`super::cutting`] integrated over the engaged angles with each
//! angle's own axial depth.
//!
//! Per unit depth and radian of immersion, the edges in contact at `phi` push on the tool
//! with (tool frame, `c` the feed per tooth; Altintas, "Manufacturing Automation", 2nd ed.,
//! ch. 2, as in [`super::cutting`])
//!
//! ```text
//! f_x = -K_tc c sin cos - K_te cos - K_rc c sin^2 - K_re sin
//! f_y =  K_tc c sin^2   + K_te sin - K_rc c sin cos - K_re cos
//! f_z =  K_ac c sin     + K_ae
//! ```
//!
//! and the revolution's mean force is `N / (2 pi) int_0^pi a(phi) f(phi) dphi`. The depth
//! `a(phi)` is the piecewise-linear interpolation of the probes' depths
//! ([`super::engagement::Chip`]): `a = sum_k a_k hat_k(phi)` with the hat functions of the
//! probe angles, so the integral is `sum_k a_k w_k` with weights `w_k = N / (2 pi) int hat_k
//! f dphi` in closed form, computed once per tool ([`ChipModel::new`]). For a depth the same
//! at every angle the hats sum to 1 and the force is [`super::cutting::average`]'s closed form
//! to rounding. Each angle's force acts halfway up its depth (the moment about the tip is
//! `sum_k a_k^2 / 2 z x w_k`) and its tangential part at the radius gives the cutting torque
//! about the axis.
//!
//! The force is linear in the depths, so a change of every depth by at most `e` changes it by
//! at most [`ChipModel::lipschitz`]`(c) e`: with [`super::engagement`]'s bound on the depths,
//! a change `d` of the tool's position changes the force by at most
//! `W(c) (|d_z| + sqrt(2) D / cell |d_xy|)` (`D` the largest depth read), for the same stock.

use nalgebra::{ComplexField, Vector3};

use super::cutting::{Coefficients, Tool};
use super::engagement::{ANGLES, Chip, ChipKind, angle};

/// The closed-form integrals of one probe's hat function against the model's angular terms:
/// `[1, sin, cos, sin^2, sin cos]`.
fn hat_integrals(k: usize, count: usize) -> [f64; 5] {
    let step = angle(1, count);
    let phi = angle(k, count);
    // First and second antiderivatives of sin(w x) and cos(w x).
    let sin_w = |w: f64, x: f64| {
        (
            -ComplexField::cos(w * x) / w,
            -ComplexField::sin(w * x) / (w * w),
        )
    };
    let cos_w = |w: f64, x: f64| {
        (
            ComplexField::sin(w * x) / w,
            -ComplexField::cos(w * x) / (w * w),
        )
    };
    // int_a^b (x - a)/h g + int_b^c (c - x)/h g, from g's antiderivatives G and GG:
    // G(b) - (GG(b) - GG(a))/h and -G(b) + (GG(c) - GG(b))/h.
    let hat = |g: &dyn Fn(f64) -> (f64, f64)| {
        let (gb, ggb) = g(phi);
        let mut total = 0.0;
        if k > 0 {
            let (_, gga) = g(phi - step);
            total += gb - (ggb - gga) / step;
        }
        if k + 1 < count {
            let (_, ggc) = g(phi + step);
            total += -gb + (ggc - ggb) / step;
        }
        total
    };
    let ends = usize::from(k > 0) + usize::from(k + 1 < count);
    let one = 0.5 * step * ends as f64;
    let sin = hat(&|x| sin_w(1.0, x));
    let cos = hat(&|x| cos_w(1.0, x));
    let cos2 = hat(&|x| cos_w(2.0, x));
    let sin2 = hat(&|x| sin_w(2.0, x));
    // sin^2 = (1 - cos 2x) / 2, sin cos = sin 2x / 2.
    [one, sin, cos, 0.5 * (one - cos2), 0.5 * sin2]
}

/// One tool's weights of the probes (see the module docs): per probe, the mean force per metre
/// of depth, split into the part proportional to the feed per tooth (`cut`, \[N/m per m\])
/// and the edge part (`edge`, \[N/m\]), tool frame, and the same for the torque about the axis.
#[derive(Debug, Clone, PartialEq)]
pub struct ChipModel {
    /// The probe angles (entries from it on are 0).
    count: usize,
    /// Per axis (x, y, z of the tool frame), per probe.
    cut: [[f64; ANGLES]; 3],
    edge: [[f64; ANGLES]; 3],
    torque_cut: [f64; ANGLES],
    torque_edge: [f64; ANGLES],
}

impl ChipModel {
    /// The weights of `tool` in a material of `coefficients` (both validated by their
    /// owners; a clockwise cutter, as [`super::cutting`]) for chips of `count` probe angles
    /// ([`super::engagement::Probes::count`]; clamped to `2..=ANGLES`).
    pub fn new(coefficients: &Coefficients, tool: &Tool, count: usize) -> Self {
        let count = count.clamp(2, ANGLES);
        let c = coefficients;
        let scale = f64::from(tool.flutes.max(1)) / core::f64::consts::TAU;
        let radius = 0.5 * tool.diameter;
        let mut m = Self {
            count,
            cut: [[0.0; ANGLES]; 3],
            edge: [[0.0; ANGLES]; 3],
            torque_cut: [0.0; ANGLES],
            torque_edge: [0.0; ANGLES],
        };
        for k in 0..count {
            let [one, s, co, ss, sc] = hat_integrals(k, count);
            let cut = [
                -c.k_tc * sc - c.k_rc * ss,
                c.k_tc * ss - c.k_rc * sc,
                c.k_ac * s,
            ];
            let edge = [
                -c.k_te * co - c.k_re * s,
                c.k_te * s - c.k_re * co,
                c.k_ae * one,
            ];
            for axis in 0..3 {
                if let (Some(w), Some(v)) = (
                    m.cut.get_mut(axis).and_then(|a| a.get_mut(k)),
                    cut.get(axis),
                ) {
                    *w = v * scale;
                }
                if let (Some(w), Some(v)) = (
                    m.edge.get_mut(axis).and_then(|a| a.get_mut(k)),
                    edge.get(axis),
                ) {
                    *w = v * scale;
                }
            }
            if let Some(w) = m.torque_cut.get_mut(k) {
                *w = radius * c.k_tc * s * scale;
            }
            if let Some(w) = m.torque_edge.get_mut(k) {
                *w = radius * c.k_te * one * scale;
            }
        }
        m
    }

    /// The mean force on the tool \[N\] and its moment about the tip \[N m\] (tool frame,
    /// clockwise cutter) of `chip` at feed per tooth `feed_per_tooth` \[m\]; zero for a
    /// plunge. The chip's probes are this model's (`chip.count` is not read). Allocation-free;
    /// finite for finite depths.
    pub fn wrench(&self, chip: &Chip, feed_per_tooth: f64) -> (Vector3<f64>, Vector3<f64>) {
        if chip.kind == ChipKind::Plunge {
            return (Vector3::zeros(), Vector3::zeros());
        }
        let fz = feed_per_tooth;
        // Sums over the probes, branch-free (they vectorise): a w and a^2 / 2 w per axis.
        let mut force = [0.0; 3];
        let mut lever = [0.0; 3];
        for axis in 0..3 {
            let (Some(cut), Some(edge)) = (self.cut.get(axis), self.edge.get(axis)) else {
                continue;
            };
            let (mut f, mut l) = (0.0, 0.0);
            let n = self.count;
            for ((&a, &c), &e) in chip.depth.iter().zip(cut).zip(edge).take(n) {
                let w = c * fz + e;
                f += w * a;
                l += w * (0.5 * a * a);
            }
            if let (Some(fo), Some(lo)) = (force.get_mut(axis), lever.get_mut(axis)) {
                *fo = f;
                *lo = l;
            }
        }
        let mut torque = 0.0;
        for ((&a, &c), &e) in chip
            .depth
            .iter()
            .zip(&self.torque_cut)
            .zip(&self.torque_edge)
            .take(self.count)
        {
            torque += (c * fz + e) * a;
        }
        let [fx, fy, fz_] = force;
        let [lx, ly, _] = lever;
        // z x lever = (-lever_y, lever_x, 0).
        (Vector3::new(fx, fy, fz_), Vector3::new(-ly, lx, torque))
    }

    /// The force's Lipschitz constant in the depths \[N/m\] at feed per tooth
    /// `feed_per_tooth` \[m\]: `sum_k |w_k|`, so depths that each change by at most `e` \[m\]
    /// change the force by at most `lipschitz * e` \[N\].
    pub fn lipschitz(&self, feed_per_tooth: f64) -> f64 {
        let [cx, cy, cz] = &self.cut;
        let [ex, ey, ez] = &self.edge;
        let mut sum = 0.0;
        for k in 0..self.count {
            let w = |c: &[f64; ANGLES], e: &[f64; ANGLES]| {
                c.get(k).copied().unwrap_or(0.0) * feed_per_tooth + e.get(k).copied().unwrap_or(0.0)
            };
            sum += Vector3::new(w(cx, ex), w(cy, ey), w(cz, ez)).norm();
        }
        sum
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::indexing_slicing)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    #[test]
    fn the_hats_integrate_each_term_over_the_half_turn() {
        // sum_k int hat_k g = int_0^pi g: pi, 2, 0, pi/2, 0.
        let mut sum = [0.0; 5];
        for k in 0..ANGLES {
            for (s, v) in sum.iter_mut().zip(hat_integrals(k, ANGLES)) {
                *s += v;
            }
        }
        // The same for a coarser set of probes.
        let mut coarse = [0.0; 5];
        for k in 0..40 {
            for (s, v) in coarse.iter_mut().zip(hat_integrals(k, 40)) {
                *s += v;
            }
        }
        let expected = [PI, 2.0, 0.0, PI / 2.0, 0.0];
        for ((s, c), e) in sum.iter().zip(coarse).zip(expected) {
            assert!((s - e).abs() < 1e-12, "{sum:?}");
            assert!((c - e).abs() < 1e-12, "{coarse:?}");
        }
        // One interior hat against the midpoint rule on 20,000 steps.
        let k = 37;
        let angle = |k: usize| angle(k, ANGLES);
        let (a, c) = (angle(k - 1), angle(k + 1));
        let n = 20_000;
        let mut q = [0.0; 5];
        for i in 0..n {
            let x = a + (c - a) * (i as f64 + 0.5) / n as f64;
            let hat = 1.0 - (x - angle(k)).abs() / angle(1);
            let (s, co) = x.sin_cos();
            for (qq, g) in q.iter_mut().zip([1.0, s, co, s * s, s * co]) {
                *qq += hat * g * (c - a) / n as f64;
            }
        }
        for (h, qq) in hat_integrals(k, ANGLES).iter().zip(q) {
            assert!((h - qq).abs() < 1e-10, "{h} {qq}");
        }
    }
}
