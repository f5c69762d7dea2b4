//! Four springs at a time: the per-spring sums of the Cartesian compliance computed lane by
//! lane over springs (structure of arrays), so that the compiler emits one vector operation
//! for four springs. The plain arithmetic on `[f64; 4]` becomes SSE2 pairs in the baseline
//! build and AVX2 / AVX-512 vectors in the versions chosen at run time (with `std`).
//!
//! Each lane sums its springs in chain order and the four lanes are added at the end: a
//! different order of the same sums than one running total, equal to rounding (the VJM tests
//! compare with the reference walk and with Pinocchio at 1e-12 relative).

use core::ops::{Add, Mul, Sub};

use nalgebra::{Isometry3, Matrix3, Matrix6, Vector3};

use super::{Data, Model};

/// Four lanes of `f64`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct F4(pub [f64; 4]);

impl F4 {
    /// `((l0 + l1) + l2) + l3`.
    #[inline(always)]
    fn total(self) -> f64 {
        let [a, b, c, d] = self.0;
        ((a + b) + c) + d
    }
}

// Written out lane by lane (not through an iterator): the form the compiler's straight-line
// vectoriser turns into one vector instruction.
macro_rules! lanewise {
    ($trait:ident, $f:ident, $op:tt) => {
        impl $trait for F4 {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                let ([a0, a1, a2, a3], [b0, b1, b2, b3]) = (self.0, o.0);
                Self([a0 $op b0, a1 $op b1, a2 $op b2, a3 $op b3])
            }
        }
    };
}
lanewise!(Add, add, +);
lanewise!(Sub, sub, -);
lanewise!(Mul, mul, *);

/// Three lanes-vectors: x, y, z of four springs.
#[derive(Debug, Clone, Copy, Default)]
struct V4 {
    x: F4,
    y: F4,
    z: F4,
}

impl V4 {
    #[inline(always)]
    fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }
}

/// The summed blocks of `C = sum_s J_s K_s^-1 J_s^T` for the springs of the last rigid pass
/// and the TCP at `p` (see [`super::compliance`] for the algebra): the six distinct entries
/// of the symmetric translation and rotation blocks and the translation-rotation block.
pub(super) fn compliance_sums(model: &Model, data: &Data, p: &Vector3<f64>) -> Matrix6<f64> {
    let (vv, vw, ww) = blocks(model, data, p);
    let sym = |e: [f64; 6]| Matrix3::new(e[0], e[1], e[2], e[1], e[3], e[4], e[2], e[4], e[5]);
    let (c_vv, c_ww) = (sym(vv), sym(ww));
    let c_vw = Matrix3::from_row_slice(&vw);
    let mut c = Matrix6::zeros();
    c.fixed_view_mut::<3, 3>(0, 0).copy_from(&c_vv);
    c.fixed_view_mut::<3, 3>(0, 3).copy_from(&c_vw);
    c.fixed_view_mut::<3, 3>(3, 0).copy_from(&c_vw.transpose());
    c.fixed_view_mut::<3, 3>(3, 3).copy_from(&c_ww);
    c
}

/// The lane loop, compiled once per instruction set (with `std`).
#[cfg_attr(
    feature = "std",
    multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx2+fma", "x86_64+avx2+fma"))
)]
fn blocks(model: &Model, data: &Data, p: &Vector3<f64>) -> ([f64; 6], [f64; 9], [f64; 6]) {
    let n = model.springs;
    let mut vv = [F4::default(); 6];
    let mut vw = [F4::default(); 9];
    let mut ww = [F4::default(); 6];
    // Whole chunks of four: past the spring count the workspace holds identity frames and
    // the model zero compliances, which add exactly zero.
    let frames = data.spring_frames.chunks_exact(4);
    let compliances = model.spring_compliance.chunks_exact(4);
    for (fs, cs) in frames.zip(compliances).take(n.div_ceil(4)) {
        let (Ok(fs), Ok(cs)) = (
            <&[Isometry3<f64>; 4]>::try_from(fs),
            <&[Vector3<f64>; 4]>::try_from(cs),
        ) else {
            continue; // unreachable: chunks of four
        };
        let q = fs.each_ref().map(|f| f.rotation.coords);
        let o = fs.each_ref().map(|f| f.translation.vector);
        let (qw, qx, qy, qz) = (
            q.map(|v| v.w),
            q.map(|v| v.x),
            q.map(|v| v.y),
            q.map(|v| v.z),
        );
        let (ox, oy, oz) = (o.map(|v| v.x), o.map(|v| v.y), o.map(|v| v.z));
        let c0 = cs.each_ref().map(|c| c.x);
        let c1 = cs.each_ref().map(|c| c.y);
        let c2 = cs.each_ref().map(|c| c.z);
        let (w, x, y, z) = (F4(qw), F4(qx), F4(qy), F4(qz));
        let (c0, c1, c2) = (F4(c0), F4(c1), F4(c2));
        // Rotation matrix of the unit quaternion (columns: the spring's axes in world axes).
        let two = F4([2.0; 4]);
        let (ww_, xx, yy, zz) = (w * w, x * x, y * y, z * z);
        let (xy, xz, yz) = (x * y, x * z, y * z);
        let (wx, wy, wz) = (w * x, w * y, w * z);
        let u = V4 {
            x: ww_ + xx - yy - zz,
            y: two * (xy + wz),
            z: two * (xz - wy),
        };
        let v = V4 {
            x: two * (xy - wz),
            y: ww_ - xx + yy - zz,
            z: two * (yz + wx),
        };
        let t = V4 {
            x: two * (xz + wy),
            y: two * (yz - wx),
            z: ww_ - xx - yy + zz,
        };
        // A = R diag(c) R^T, six distinct entries.
        let g = |i: F4, j: F4, k: F4, l: F4, m: F4, n: F4| c0 * i * j + c1 * k * l + c2 * m * n;
        let a = [
            g(u.x, u.x, v.x, v.x, t.x, t.x),
            g(u.x, u.y, v.x, v.y, t.x, t.y),
            g(u.x, u.z, v.x, v.z, t.x, t.z),
            g(u.y, u.y, v.y, v.y, t.y, t.y),
            g(u.y, u.z, v.y, v.z, t.y, t.z),
            g(u.z, u.z, v.z, v.z, t.z, t.z),
        ];
        let r = V4 {
            x: F4([p.x; 4]) - F4(ox),
            y: F4([p.y; 4]) - F4(oy),
            z: F4([p.z; 4]) - F4(oz),
        };
        let [a0, a1, a2, a3, a4, a5] = a;
        // B = S A (S = [r]x), column j = r x A_j.
        let b0 = r.cross(V4 {
            x: a0,
            y: a1,
            z: a2,
        });
        let b1 = r.cross(V4 {
            x: a1,
            y: a3,
            z: a4,
        });
        let b2 = r.cross(V4 {
            x: a2,
            y: a4,
            z: a5,
        });
        // S A S^T = -(S A) S: six entries.
        let dv = [
            b2.x * r.y - b1.x * r.z,
            b0.x * r.z - b2.x * r.x,
            b1.x * r.x - b0.x * r.y,
            b0.y * r.z - b2.y * r.x,
            b1.y * r.x - b0.y * r.y,
            b1.z * r.x - b0.z * r.y,
        ];
        for (acc, d) in vv.iter_mut().zip(dv) {
            *acc = *acc + d;
        }
        for (acc, d) in ww.iter_mut().zip(a) {
            *acc = *acc + d;
        }
        // The translation-rotation block -B, row by row.
        let b = [b0.x, b1.x, b2.x, b0.y, b1.y, b2.y, b0.z, b1.z, b2.z];
        for (acc, d) in vw.iter_mut().zip(b) {
            *acc = *acc - d;
        }
    }
    (vv.map(F4::total), vw.map(F4::total), ww.map(F4::total))
}
