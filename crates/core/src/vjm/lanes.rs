//! Four springs at a time: the per-spring sums of the Cartesian compliance computed lane by
//! lane over springs (structure of arrays). The kernel is written once over [`Lanes`]: plain
//! `[f64; 4]` arithmetic on every target, and explicit AVX2 registers (through `pulp`, chosen
//! at run time with `std` on x86-64). Left to the compiler's straight-line vectoriser, the
//! plain form became a mix of 128-, 256- and 512-bit operations with shuffles and spills
//! (KR 300: half of `compliance`'s 350 ns); the explicit registers keep one vector operation
//! per lane operation. The two forms are the same operations in the same order (no fused
//! multiply-add), so they agree bit for bit.
//!
//! Each lane sums its springs in chain order and the four lanes are added at the end: a
//! different order of the same sums than one running total, equal to rounding (the VJM tests
//! compare with the reference walk and with Pinocchio at 1e-12 relative).

use core::ops::{Add, Mul, Sub};

use nalgebra::{Isometry3, Matrix3, Vector3};

use super::{Data, Model};

/// Lane-wise arithmetic: what the kernels' vectors of lanes need.
pub(crate) trait Arith:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self>
{
}
impl<T: Copy + Add<Output = T> + Sub<Output = T> + Mul<Output = T>> Arith for T {}

/// A way to hold four `f64` lanes: its vector type, and the conversions from and to arrays.
pub(crate) trait Lanes: Copy {
    /// Four lanes, with lane-wise arithmetic.
    type V: Arith;
    /// The lanes of `a`.
    fn load(self, a: [f64; 4]) -> Self::V;
    /// The lanes of `v` as an array.
    fn store(self, v: Self::V) -> [f64; 4];
    /// `x` in every lane.
    #[inline(always)]
    fn splat(self, x: f64) -> Self::V {
        self.load([x; 4])
    }
    /// `|v|` lane by lane.
    fn abs(self, v: Self::V) -> Self::V;
    /// The larger of `a` and `b` lane by lane (for finite lanes; which of the two a NaN lane
    /// gives is the instruction's).
    fn max(self, a: Self::V, b: Self::V) -> Self::V;
    /// `((l0 + l1) + l2) + l3`.
    #[inline(always)]
    fn total(self, v: Self::V) -> f64 {
        let [a, b, c, d] = self.store(v);
        ((a + b) + c) + d
    }
}

/// Plain arrays: every target, and the fallback without AVX2.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plain;

/// Four lanes of `f64`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct F4(pub [f64; 4]);

// Written out lane by lane (not through an iterator): the form the compiler's straight-line
// vectoriser turns into vector instructions where it can.
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

impl Lanes for Plain {
    type V = F4;
    #[inline(always)]
    fn load(self, a: [f64; 4]) -> F4 {
        F4(a)
    }
    #[inline(always)]
    fn store(self, v: F4) -> [f64; 4] {
        v.0
    }
    #[inline(always)]
    fn abs(self, v: F4) -> F4 {
        F4(v.0.map(f64::abs))
    }
    #[inline(always)]
    fn max(self, a: F4, b: F4) -> F4 {
        let ([a0, a1, a2, a3], [b0, b1, b2, b3]) = (a.0, b.0);
        F4([a0.max(b0), a1.max(b1), a2.max(b2), a3.max(b3)])
    }
}

/// AVX2 registers, with the token proving the CPU has them.
#[cfg(all(feature = "std", target_arch = "x86_64"))]
mod avx {
    use core::ops::{Add, Mul, Sub};

    use pulp::f64x4;
    use pulp::x86::V3;

    /// One AVX2 register of four `f64`.
    #[derive(Debug, Clone, Copy)]
    pub(crate) struct Avx4 {
        simd: V3,
        v: f64x4,
    }

    macro_rules! avxwise {
        ($trait:ident, $f:ident, $op:ident) => {
            impl $trait for Avx4 {
                type Output = Self;
                #[inline(always)]
                fn $f(self, o: Self) -> Self {
                    Self {
                        simd: self.simd,
                        v: self.simd.$op(self.v, o.v),
                    }
                }
            }
        };
    }
    avxwise!(Add, add, add_f64x4);
    avxwise!(Sub, sub, sub_f64x4);
    avxwise!(Mul, mul, mul_f64x4);

    impl super::Lanes for V3 {
        type V = Avx4;
        #[inline(always)]
        fn load(self, a: [f64; 4]) -> Avx4 {
            Avx4 {
                simd: self,
                v: pulp::cast(a),
            }
        }
        #[inline(always)]
        fn store(self, v: Avx4) -> [f64; 4] {
            pulp::cast(v.v)
        }
        #[inline(always)]
        fn abs(self, v: Avx4) -> Avx4 {
            Avx4 {
                simd: self,
                v: self.abs_f64x4(v.v),
            }
        }
        #[inline(always)]
        fn max(self, a: Avx4, b: Avx4) -> Avx4 {
            Avx4 {
                simd: self,
                v: pulp::Simd::max_f64s(self, a.v, b.v),
            }
        }
    }
}

/// A computation over lanes, written once for every [`Lanes`].
pub(crate) trait LaneKernel {
    /// What it returns.
    type Output;
    /// Runs it in the lanes `l`. Implementations are `#[inline(always)]`, so that the
    /// arithmetic is compiled inside [`dispatch`]'s AVX2 function.
    fn run<L: Lanes>(self, l: L) -> Self::Output;
}

/// Runs `kernel` in AVX2 registers where the CPU has them (with `std` on x86-64: one cached
/// feature check), in plain arrays otherwise.
#[inline(always)]
pub(crate) fn dispatch<K: LaneKernel>(kernel: K) -> K::Output {
    #[cfg(all(feature = "std", target_arch = "x86_64"))]
    if let Some(simd) = pulp::x86::V3::try_new() {
        /// The kernel as pulp's closure, compiled with AVX2 enabled.
        struct Avx<K>(pulp::x86::V3, K);
        impl<K: LaneKernel> pulp::NullaryFnOnce for Avx<K> {
            type Output = K::Output;
            #[inline(always)]
            fn call(self) -> K::Output {
                self.1.run(self.0)
            }
        }
        return simd.vectorize(Avx(simd, kernel));
    }
    kernel.run(Plain)
}

/// Three lanes-vectors: x, y, z of four springs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct V4<T> {
    pub(crate) x: T,
    pub(crate) y: T,
    pub(crate) z: T,
}

impl<T: Arith> V4<T> {
    /// The cross product, lane by lane, in nalgebra's order of operations.
    #[inline(always)]
    pub(crate) fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }
}

/// The summed blocks of `C = sum_s J_s K_s^-1 J_s^T` for the springs of the last rigid pass
/// and the TCP at `p` (see [`super::compliance`] for the algebra): the six distinct entries
/// of the symmetric translation and rotation blocks and the translation-rotation block, into
/// `data.compliance`. Written in place: a matrix built on the stack and copied into `data`
/// cost a `memcpy` whose wide loads stalled on the element stores just made (a sixth of
/// `compliance`'s time, KR 300).
pub(super) fn compliance_sums(model: &Model, data: &mut Data, p: &Vector3<f64>) {
    let (vv, vw, ww) = blocks(model, data, p);
    let sym = |e: [f64; 6]| Matrix3::new(e[0], e[1], e[2], e[1], e[3], e[4], e[2], e[4], e[5]);
    let (c_vv, c_ww) = (sym(vv), sym(ww));
    let c_vw = Matrix3::from_row_slice(&vw);
    let c = &mut data.compliance;
    c.fixed_view_mut::<3, 3>(0, 0).copy_from(&c_vv);
    c.fixed_view_mut::<3, 3>(0, 3).copy_from(&c_vw);
    c.fixed_view_mut::<3, 3>(3, 0).copy_from(&c_vw.transpose());
    c.fixed_view_mut::<3, 3>(3, 3).copy_from(&c_ww);
}

/// The lane sums, in AVX2 registers where the CPU has them.
fn blocks(model: &Model, data: &Data, p: &Vector3<f64>) -> ([f64; 6], [f64; 9], [f64; 6]) {
    /// [`blocks_in`] as a lane kernel.
    struct Blocks<'a>(&'a Model, &'a Data, &'a Vector3<f64>);
    impl LaneKernel for Blocks<'_> {
        type Output = ([f64; 6], [f64; 9], [f64; 6]);
        #[inline(always)]
        fn run<L: Lanes>(self, l: L) -> Self::Output {
            blocks_in(l, self.0, self.1, self.2)
        }
    }
    dispatch(Blocks(model, data, p))
}

/// The lane loop over the springs, in the lanes `l`.
#[inline(always)]
fn blocks_in<L: Lanes>(
    l: L,
    model: &Model,
    data: &Data,
    p: &Vector3<f64>,
) -> ([f64; 6], [f64; 9], [f64; 6]) {
    let n = model.springs;
    let zero = l.splat(0.0);
    let mut vv = [zero; 6];
    let mut vw = [zero; 9];
    let mut ww = [zero; 6];
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
        let Terms { dv, a, b } = chunk_terms(l, fs, cs, p);
        for (acc, d) in vv.iter_mut().zip(dv) {
            *acc = *acc + d;
        }
        for (acc, d) in ww.iter_mut().zip(a) {
            *acc = *acc + d;
        }
        // The translation-rotation block -B, row by row.
        for (acc, d) in vw.iter_mut().zip(b) {
            *acc = *acc - d;
        }
    }
    let total = |v| l.total(v);
    (vv.map(total), vw.map(total), ww.map(total))
}

/// One chunk's terms of the sums, four springs in the lanes.
struct Terms<V> {
    /// The six distinct entries of `S A S^T` \[m^2 rad / (N m)\].
    dv: [V; 6],
    /// The six distinct entries of `A = R diag(c) R^T` \[rad / (N m)\].
    a: [V; 6],
    /// `B = S A` row by row \[m rad / (N m)\].
    b: [V; 9],
}

/// The [`Terms`] of four springs (frames `fs`, compliances `cs` \[rad / (N m)\]) for the TCP
/// at `p` \[m\] (`S = [r]x`, `r` the lever from the spring to the TCP).
#[inline(always)]
fn chunk_terms<L: Lanes>(
    l: L,
    fs: &[Isometry3<f64>; 4],
    cs: &[Vector3<f64>; 4],
    p: &Vector3<f64>,
) -> Terms<L::V> {
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
    let (w, x, y, z) = (l.load(qw), l.load(qx), l.load(qy), l.load(qz));
    let (c0, c1, c2) = (l.load(c0), l.load(c1), l.load(c2));
    let [u, v, t] = rotation_columns(l, w, x, y, z);
    // A = R diag(c) R^T, six distinct entries.
    let g = |i, j, k, l, m, n| c0 * i * j + c1 * k * l + c2 * m * n;
    let a = [
        g(u.x, u.x, v.x, v.x, t.x, t.x),
        g(u.x, u.y, v.x, v.y, t.x, t.y),
        g(u.x, u.z, v.x, v.z, t.x, t.z),
        g(u.y, u.y, v.y, v.y, t.y, t.y),
        g(u.y, u.z, v.y, v.z, t.y, t.z),
        g(u.z, u.z, v.z, v.z, t.z, t.z),
    ];
    let r = V4 {
        x: l.splat(p.x) - l.load(ox),
        y: l.splat(p.y) - l.load(oy),
        z: l.splat(p.z) - l.load(oz),
    };
    let (dv, b) = lever_terms(r, a);
    Terms { dv, a, b }
}

/// The rotation matrix of the unit quaternions `w + x i + y j + z k`, as its columns (the
/// spring's axes in world axes, dimensionless).
#[inline(always)]
fn rotation_columns<L: Lanes>(l: L, w: L::V, x: L::V, y: L::V, z: L::V) -> [V4<L::V>; 3] {
    let two = l.splat(2.0);
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
    [u, v, t]
}

/// The lever terms of a spring with compliance `a` (the six entries of the symmetric `A`)
/// and lever `r` \[m\]: the six entries of `S A S^T` and the nine of `B = S A` row by row.
#[inline(always)]
fn lever_terms<V: Arith>(r: V4<V>, a: [V; 6]) -> ([V; 6], [V; 9]) {
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
    let b = [b0.x, b1.x, b2.x, b0.y, b1.y, b2.y, b0.z, b1.z, b2.z];
    (dv, b)
}

#[cfg(test)]
pub(crate) mod tests {
    use nalgebra::{Isometry3, UnitQuaternion, Vector3};

    use super::*;
    use crate::vjm::{Data, ModelBuilder, deflection};

    /// Six springs (a whole chunk of four and a partial one) on an oblique three-joint arm.
    pub(crate) fn arm() -> (Model, [f64; 3]) {
        let model = ModelBuilder::new()
            .fixed(Isometry3::translation(0.0, 0.0, 0.4))
            .unwrap()
            .revolute(Vector3::z())
            .unwrap()
            .spring([2.0e5, 3.0e5, 4.0e4])
            .unwrap()
            .fixed(Isometry3::from_parts(
                Vector3::new(0.1, 0.0, 0.2).into(),
                UnitQuaternion::from_euler_angles(-0.3, 0.1, 0.2),
            ))
            .unwrap()
            .spring([5.0e4, f64::INFINITY, 7.0e4])
            .unwrap()
            .revolute(Vector3::new(0.3, -0.5, 0.81).normalize())
            .unwrap()
            .spring([3.0e4, 6.0e4, 1.0e4])
            .unwrap()
            .fixed(Isometry3::translation(0.6, 0.05, 0.0))
            .unwrap()
            .spring([8.0e4, 2.0e4, 9.0e4])
            .unwrap()
            .revolute(Vector3::y())
            .unwrap()
            .spring([4.0e4, 4.5e4, 5.0e4])
            .unwrap()
            .fixed(Isometry3::translation(0.3, 0.0, -0.1))
            .unwrap()
            .spring([1.0e5, 1.0e5, 2.0e5])
            .unwrap()
            .build()
            .unwrap();
        (model, [0.7, -1.2, 0.15])
    }

    #[test]
    fn avx2_lanes_equal_the_plain_lanes_bit_for_bit() {
        let (model, q) = arm();
        let mut data = Data::new(&model);
        deflection::joint_jacobian(&model, &mut data, &q).unwrap();
        let p = data.tcp.translation.vector;
        let plain = blocks_in(Plain, &model, &data, &p);
        assert!(plain.0.iter().all(|v| *v != 0.0), "{plain:?}");
        #[cfg(all(feature = "std", target_arch = "x86_64"))]
        if let Some(simd) = pulp::x86::V3::try_new() {
            assert_eq!(blocks_in(simd, &model, &data, &p), plain);
        }
    }
}
