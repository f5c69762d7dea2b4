//! The machined surface of a dexel stock and a predicted part's deviation from it along the
//! surface's normal: each end of a ray's material interval that the cut made is a point of the
//! surface, read by the grid whose direction lies nearest the normal there (so a point is
//! read once, along a ray no more than 54.7 degrees off its normal); the normal is the
//! neighbouring rays' ends' slope. A predicted part's end of the same side on the same ray
//! gives the deviation: the distance along the ray times the normal's part along it, exact
//! for a surface that is locally plane and offset along its normal.
//!
//! Signs: positive where the predicted part keeps material the nominal one does not (left),
//! negative where it has lost some (overcut).

use alloc::vec::Vec;

use nalgebra::{ComplexField, Vector3};

use super::{Dexels, Intervals, across, at};
use crate::error::TickError;

/// A point of the machined surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// Where \[m\], workpiece frame.
    pub position: Vector3<f64>,
    /// Outward unit normal (out of the material).
    pub normal: Vector3<f64>,
    /// The predicted part's deviation along the normal \[m\]: > 0 material left, < 0 overcut.
    pub deviation: f64,
    /// The grid it is read along (0 x, 1 y, 2 z) and the ray's cell across it.
    pub ray: (usize, usize, usize),
    /// Whether the material lies below the point along the ray (its outward normal along
    /// the ray's direction).
    pub upper: bool,
}

/// Where the surface faces: the outward normal's largest component and its sign.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Face {
    /// +x.
    PlusX,
    /// -x.
    MinusX,
    /// +y.
    PlusY,
    /// -y.
    MinusY,
    /// +z: floors and the tops of the part.
    PlusZ,
    /// -z: undersides.
    MinusZ,
}

impl Face {
    /// All six, in order.
    pub const ALL: [Self; 6] = [
        Self::PlusX,
        Self::MinusX,
        Self::PlusY,
        Self::MinusY,
        Self::PlusZ,
        Self::MinusZ,
    ];

    /// "+x", "-x", ...
    pub fn name(&self) -> &'static str {
        match self {
            Self::PlusX => "+x",
            Self::MinusX => "-x",
            Self::PlusY => "+y",
            Self::MinusY => "-y",
            Self::PlusZ => "+z",
            Self::MinusZ => "-z",
        }
    }

    /// The face of a point.
    pub fn of(p: &SurfacePoint) -> Self {
        let upper = p.upper;
        match (p.ray.0, upper) {
            (0, true) => Self::PlusX,
            (0, false) => Self::MinusX,
            (1, true) => Self::PlusY,
            (1, false) => Self::MinusY,
            (_, true) => Self::PlusZ,
            (_, false) => Self::MinusZ,
        }
    }
}

/// The deviation's figures over a set of surface points.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeviationStats {
    /// Points.
    pub count: usize,
    /// Most material left \[m\] (>= 0).
    pub max_left: f64,
    /// Deepest overcut \[m\] (<= 0).
    pub max_overcut: f64,
    /// Root mean square \[m\].
    pub rms: f64,
}

impl DeviationStats {
    /// The figures of `points`.
    pub fn of<'a>(points: impl IntoIterator<Item = &'a SurfacePoint>) -> Self {
        let mut s = Self::default();
        let mut sum = 0.0;
        for p in points {
            s.count += 1;
            s.max_left = s.max_left.max(p.deviation);
            s.max_overcut = s.max_overcut.min(p.deviation);
            sum += p.deviation * p.deviation;
        }
        if s.count > 0 {
            s.rms = ComplexField::sqrt(sum / s.count as f64);
        }
        s
    }

    /// The largest deviation either way \[m\].
    pub fn max_abs(&self) -> f64 {
        self.max_left.max(-self.max_overcut)
    }
}

/// The end of `side` (upper: an interval's top) in `ray` nearest `x`, within `reach`.
fn end_near(ray: &Intervals, upper: bool, x: f64, reach: f64) -> Option<f64> {
    ray.iter()
        .map(|&(a, b)| if upper { b } else { a })
        .filter(|e| ComplexField::abs(e - x) <= reach)
        .min_by(|a, b| ComplexField::abs(a - x).total_cmp(&ComplexField::abs(b - x)))
}

impl Dexels {
    /// The neighbouring ray's end of the same side near `x` (cell `(i, j)` moved by `di, dj`).
    fn neighbour(
        &self,
        (d, i, j): (usize, usize, usize),
        (di, dj): (isize, isize),
        upper: bool,
        x: f64,
    ) -> Option<f64> {
        let (i, j) = (i.checked_add_signed(di)?, j.checked_add_signed(dj)?);
        let (_, ray) = self.ray(d, i, j)?;
        end_near(ray, upper, x, 2.0 * self.cell)
    }

    /// The slope of the ends along one axis across the ray: central, else one-sided, else 0.
    fn slope(&self, d: usize, i: usize, j: usize, along_i: bool, upper: bool, x: f64) -> f64 {
        let step = |s: isize| {
            if along_i {
                self.neighbour((d, i, j), (s, 0), upper, x)
            } else {
                self.neighbour((d, i, j), (0, s), upper, x)
            }
        };
        match (step(-1), step(1)) {
            (Some(a), Some(b)) => (b - a) / (2.0 * self.cell),
            (None, Some(b)) => (b - x) / self.cell,
            (Some(a), None) => (x - a) / self.cell,
            (None, None) => 0.0,
        }
    }

    /// The machined surface of this (nominal) stock, each point with the deviation of
    /// `predicted` (the same block, cut otherwise) there: the predicted end of the same side
    /// nearest the nominal one along the ray, within `reach` \[m\] (larger than the largest
    /// deviation expected, smaller than the part's thinnest wall). A point whose ray has none
    /// (the material gone, or a sliver left) counts in the second value and is not listed.
    /// [`TickError::InvalidArgument`] when the blocks differ or `reach` is not finite and
    /// > 0.
    pub fn surface_deviation(
        &self,
        predicted: &Dexels,
        reach: f64,
    ) -> Result<(Vec<SurfacePoint>, usize), TickError> {
        if !(reach.is_finite() && reach > 0.0) {
            return Err(TickError::InvalidArgument {
                what: "surface deviation reach (m, finite and > 0)",
                value: reach,
            });
        }
        if self.n != predicted.n || self.cell != predicted.cell || self.min != predicted.min {
            return Err(TickError::InvalidArgument {
                what: "predicted stock (the nominal one's block, cell and shape)",
                value: predicted.cell,
            });
        }
        let mut points = Vec::new();
        let mut missing = 0usize;
        for d in 0..3 {
            let (u, v) = across(d);
            let (nu, nv) = (
                self.n.get(u).copied().unwrap_or(0),
                self.n.get(v).copied().unwrap_or(0),
            );
            let lo = at(&self.min, d);
            let hi = lo + self.cell * self.n.get(d).copied().unwrap_or(0) as f64;
            for i in 0..nu {
                for j in 0..nv {
                    let (Some((origin, ray)), Some((_, other))) =
                        (self.ray(d, i, j), predicted.ray(d, i, j))
                    else {
                        continue;
                    };
                    for &(a, b) in ray {
                        for (x, upper) in [(a, false), (b, true)] {
                            // The block's own faces are not machined.
                            if x <= lo + 1e-12 || x >= hi - 1e-12 {
                                continue;
                            }
                            let gu = self.slope(d, i, j, true, upper, x);
                            let gv = self.slope(d, i, j, false, upper, x);
                            // Read by the grid nearest the normal only.
                            if ComplexField::abs(gu) > 1.0 || ComplexField::abs(gv) > 1.0 {
                                continue;
                            }
                            let mut n = Vector3::zeros();
                            let sign = if upper { 1.0 } else { -1.0 };
                            if let Some(c) = n.get_mut(u) {
                                *c = -gu * sign;
                            }
                            if let Some(c) = n.get_mut(v) {
                                *c = -gv * sign;
                            }
                            if let Some(c) = n.get_mut(d) {
                                *c = sign;
                            }
                            let n = n.normalize();
                            let Some(y) = end_near(other, upper, x, reach) else {
                                missing += 1;
                                continue;
                            };
                            let along = (y - x) * sign;
                            let mut position = origin;
                            if let Some(c) = position.get_mut(d) {
                                *c = x;
                            }
                            points.push(SurfacePoint {
                                position,
                                normal: n,
                                deviation: along * ComplexField::abs(at(&n, d)),
                                ray: (d, i, j),
                                upper,
                            });
                        }
                    }
                }
            }
        }
        Ok((points, missing))
    }
}

/// The machined surface as a triangle mesh: the points of each grid joined to their
/// neighbours' of the same side (within two cells along the ray), wound with the outward
/// normal. The grids' patches meet where the normal turns past 45 degrees between two
/// directions; they are not stitched (a viewer shows them side by side).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SurfaceMesh {
    /// The surface points (vertices).
    pub points: Vec<SurfacePoint>,
    /// Triangles as indices into `points`.
    pub triangles: Vec<[u32; 3]>,
}

impl SurfaceMesh {
    /// The mesh of `points` from [`Dexels::surface_deviation`] of a stock with cell `cell`
    /// \[m\] (the points in the order it gives them). [`TickError::Budget`] past `u32`
    /// vertices.
    pub fn new(points: Vec<SurfacePoint>, cell: f64) -> Result<Self, TickError> {
        if points.len() > u32::MAX as usize {
            return Err(TickError::Budget {
                what: "surface mesh vertices",
                budget: "u32::MAX",
                limit: u32::MAX as f64,
                requested: points.len() as f64,
            });
        }
        // The points sorted by ray; each ray's points found by binary search.
        let mut order: Vec<u32> = (0..points.len() as u32).collect();
        let key = |k: &u32| points.get(*k as usize).map(|p| (p.ray, p.upper));
        order.sort_by_key(key);
        let find = |ray: (usize, usize, usize), upper: bool, x: f64| -> Option<u32> {
            let start = order.partition_point(|k| key(k) < Some((ray, upper)));
            order
                .get(start..)?
                .iter()
                .take_while(|k| key(k) == Some((ray, upper)))
                .filter_map(|&k| {
                    let p = points.get(k as usize)?;
                    let e = ComplexField::abs(at(&p.position, ray.0) - x);
                    (e <= 2.0 * cell).then_some((k, e))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(k, _)| k)
        };
        let mut triangles = Vec::new();
        for (k, p) in points.iter().enumerate() {
            let (d, i, j) = p.ray;
            let x = at(&p.position, d);
            let right = find((d, i + 1, j), p.upper, x);
            let up = find((d, i, j + 1), p.upper, x);
            let diag = find((d, i + 1, j + 1), p.upper, x);
            let k = k as u32;
            let mut push = |t: [u32; 3]| {
                let v = |n: u32| points.get(n as usize).map(|p| (p.position, p.normal));
                if let (Some(a), Some(b), Some(c)) = (v(t[0]), v(t[1]), v(t[2])) {
                    let face = (b.0 - a.0).cross(&(c.0 - a.0));
                    if face.dot(&(a.1 + b.1 + c.1)) < 0.0 {
                        triangles.push([t[0], t[2], t[1]]);
                    } else {
                        triangles.push(t);
                    }
                }
            };
            match (right, up, diag) {
                (Some(r), Some(u), Some(g)) => {
                    push([k, r, g]);
                    push([k, g, u]);
                }
                (Some(r), Some(u), None) => push([k, r, u]),
                (Some(r), None, Some(g)) => push([k, r, g]),
                (None, Some(u), Some(g)) => push([k, g, u]),
                _ => {}
            }
        }
        Ok(Self { points, triangles })
    }
}
