//! `sin` and `cos` of a joint's half angle for the chain's rotations, inline: the library
//! call (`sincos`, behind a PLT jump) was 13 % of [`super::compliance`] and 9 % of
//! [`super::deflection`] on the KR 300 (perf). Cody-Waite reduction by pi/2 in two parts and
//! the minimax kernels of fdlibm (`__kernel_sin`, `__kernel_cos`, Sun Microsystems 1993,
//! error below 1 ulp on [-pi/4, pi/4]); within 2 ulp of the library for |x| <= 2^19 pi/2,
//! the library itself beyond (and for non-finite input).

#![allow(clippy::excessive_precision)] // reason: fdlibm's constants, digit for digit as published

use core::ops::{Add, Mul, Sub};

use nalgebra::{Quaternion, Unit, UnitQuaternion, Vector3};

use super::lanes::Lanes;

const S1: f64 = -1.666_666_666_666_663_243_48e-1;
const S2: f64 = 8.333_333_333_322_489_461_24e-3;
const S3: f64 = -1.984_126_982_985_794_931_34e-4;
const S4: f64 = 2.755_731_370_707_006_767_89e-6;
const S5: f64 = -2.505_076_025_340_686_341_95e-8;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;
const C1: f64 = 4.166_666_666_666_660_190_37e-2;
const C2: f64 = -1.388_888_888_887_410_957_49e-3;
const C3: f64 = 2.480_158_728_947_672_941_78e-5;
const C4: f64 = -2.755_731_435_139_066_330_35e-7;
const C5: f64 = 2.087_572_321_298_174_827_90e-9;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;
/// 2 / pi.
const INV_PIO2: f64 = core::f64::consts::FRAC_2_PI;
/// pi/2 in two parts: the first 33 bits (k * PIO2_1 is exact for |k| < 2^20) and the rest.
const PIO2_1: f64 = 1.570_796_326_734_125_614_17;
const PIO2_1T: f64 = 6.077_100_506_506_192_249_32e-11;
/// 1.5 * 2^52: adding it rounds to an integer held in the low mantissa bits.
const SHIFT: f64 = 6_755_399_441_055_744.0;
/// Largest |x| reduced here.
const REDUCE_MAX: f64 = 823_550.0; // 2^19 * pi/2

/// fdlibm's `__kernel_sin`, written once for plain numbers and lanes.
#[inline(always)]
fn kernel_sin<T: Copy + Add<Output = T> + Mul<Output = T>>(x: T, k: impl Fn(f64) -> T) -> T {
    let z = x * x;
    let v = z * x;
    let r = k(S2) + z * (k(S3) + z * (k(S4) + z * (k(S5) + z * k(S6))));
    x + v * (k(S1) + z * r)
}

/// fdlibm's `__kernel_cos`, written once for plain numbers and lanes.
#[inline(always)]
fn kernel_cos<T: Copy + Add<Output = T> + Sub<Output = T> + Mul<Output = T>>(
    x: T,
    k: impl Fn(f64) -> T,
) -> T {
    let z = x * x;
    let w = z * z;
    let r = z * (k(C1) + z * (k(C2) + z * k(C3))) + w * w * (k(C4) + z * (k(C5) + z * k(C6)));
    let hz = k(0.5) * z;
    let one_minus = k(1.0) - hz;
    one_minus + (((k(1.0) - one_minus) - hz) + z * r)
}

/// The quadrant's `(sin x, cos x)` from the kernels' `s`, `c` of the reduced argument and the
/// shifted quotient `t`.
#[inline(always)]
fn quadrant(t: f64, s: f64, c: f64) -> (f64, f64) {
    match t.to_bits() & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// `(sin x, cos x)`.
#[inline(always)]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    let k = |v: f64| v;
    if x.abs() <= core::f64::consts::FRAC_PI_4 {
        return (kernel_sin(x, k), kernel_cos(x, k));
    }
    if x.is_nan() || x.abs() > REDUCE_MAX {
        return nalgebra::ComplexField::sin_cos(x);
    }
    // Nearest multiple k of pi/2 by the 1.5 * 2^52 shift (|k| < 2^20): `t`'s low mantissa
    // bits are k in two's complement, so its last two bits are the quadrant.
    let t = x * INV_PIO2 + SHIFT;
    let k = t - SHIFT;
    let r = (x - k * PIO2_1) - k * PIO2_1T;
    let one = |v: f64| v;
    quadrant(t, kernel_sin(r, one), kernel_cos(r, one))
}

/// [`sin_cos`] of four values as lanes, each lane the value of [`sin_cos`] (only the sign of
/// a zero may differ): the reduction for every lane (for |x| < pi/4 it gives k = 0 and r = x
/// exactly, the direct path's argument), the kernels in the lanes, and the quadrant's signs
/// and swap as exact products with 0 and +-1 (`d = k mod 4` in [-2, 2], `sin = s (1 - |d|) +
/// c d (2 - |d|)`). Values the reduction does not cover as [`sin_cos`] does (past
/// `REDUCE_MAX`, non-finite, within 1e-12 of pi/4 where the direct path's bound falls) take
/// [`sin_cos`] lane by lane.
#[inline(always)]
pub(crate) fn sin_cos_lanes<L: Lanes>(l: L, x: [f64; 4]) -> (L::V, L::V) {
    let edge = |x: &f64| {
        x.is_nan() || x.abs() > REDUCE_MAX || (x.abs() - core::f64::consts::FRAC_PI_4).abs() < 1e-12
    };
    if x.iter().any(edge) {
        let v = x.map(sin_cos);
        return (l.load(v.map(|v| v.0)), l.load(v.map(|v| v.1)));
    }
    let k = |v: f64| l.splat(v);
    let (shift, one, two) = (k(SHIFT), k(1.0), k(2.0));
    let x = l.load(x);
    let q = (x * k(INV_PIO2) + shift) - shift;
    let r = (x - q * k(PIO2_1)) - q * k(PIO2_1T);
    let (s, c) = (kernel_sin(r, k), kernel_cos(r, k));
    // The quadrant: d = q - 4 round(q / 4), exact for |q| < 2^20.
    let d = q - k(4.0) * ((q * k(0.25) + shift) - shift);
    let ad = l.abs(d);
    let (a, b) = (one - ad, d * (two - ad));
    (s * a + c * b, c * a - s * b)
}

/// A rotation by `angle` \[rad\] about the unit `axis`, as nalgebra's
/// `UnitQuaternion::from_axis_angle` (`[cos(a/2), axis sin(a/2)]`) with the inline [`sin_cos`].
#[inline(always)]
pub(crate) fn axis_angle(axis: &Unit<Vector3<f64>>, angle: f64) -> UnitQuaternion<f64> {
    let (s, c) = sin_cos(angle * 0.5);
    UnitQuaternion::new_unchecked(Quaternion::from_parts(c, axis.as_ref() * s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn within_two_ulp_of_the_library() {
        let mut worst: f64 = 0.0;
        let mut check = |x: f64| {
            let (s, c) = sin_cos(x);
            let (es, ec) = (x.sin(), x.cos());
            // Errors in ulps of 1 (the scale of a unit quaternion's entries).
            let e = ((s - es).abs()).max((c - ec).abs()) / f64::EPSILON;
            worst = worst.max(e);
            assert!(e <= 2.0, "{x}: {s} {c} vs {es} {ec}");
        };
        for i in -200_000..=200_000 {
            check(i as f64 * 1.0e-4); // +-20 rad, every quadrant and boundary region
        }
        for k in -64..=64 {
            let b = k as f64 * core::f64::consts::FRAC_PI_4;
            for d in [-1e-12, -1e-15, 0.0, 1e-15, 1e-12] {
                check(b + d);
            }
        }
        for x in [1e3, -1234.5678, 8.2e5, 1e-300, -0.0, 0.0] {
            check(x);
        }
        // Beyond the reduction and non-finite: the library's values.
        for x in [1e6, -3e9, f64::NAN, f64::INFINITY] {
            let (s, c) = sin_cos(x);
            let (es, ec) = nalgebra::ComplexField::sin_cos(x);
            assert_eq!(
                (s.to_bits(), c.to_bits()),
                (es.to_bits(), ec.to_bits()),
                "{x}"
            );
        }
        assert!(worst > 0.0);
    }

    #[test]
    fn lanes_are_sin_cos() {
        let mut xs: [f64; 4] = [0.0; 4];
        let check = |x: [f64; 4]| {
            let plain = sin_cos_lanes(crate::vjm::lanes::Plain, x);
            for (i, x) in x.iter().enumerate() {
                let (s, c) = sin_cos(*x);
                // The same values (a zero's sign aside: 0.0 == -0.0; NaN for NaN).
                let same = |a: f64, b: f64| a == b || (a.is_nan() && b.is_nan());
                assert!(same(plain.0.0[i], s) && same(plain.1.0[i], c), "{x}");
            }
        };
        for i in -20_000..=20_000 {
            let x = i as f64 * 1.0e-3;
            xs = [x, -x * 0.7, x * 13.0, x.abs()];
            check(xs);
        }
        let edge = core::f64::consts::FRAC_PI_4;
        for x in [
            edge,
            -edge,
            edge.next_up(),
            edge.next_down(),
            -0.0,
            8.2e5,
            1e6,
            f64::NAN,
        ] {
            xs[0] = x;
            check(xs);
        }
    }

    #[test]
    fn axis_angle_is_nalgebras_to_rounding() {
        let axis = Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8));
        for i in -100..=100 {
            let a = i as f64 * 0.07;
            let ours = axis_angle(&axis, a);
            let theirs = UnitQuaternion::from_axis_angle(&axis, a);
            assert!(
                (ours.coords - theirs.coords).amax() <= 2.0 * f64::EPSILON,
                "{a}"
            );
        }
    }
}
