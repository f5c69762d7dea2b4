//! Distances to segments, polygons and circles, and the point-in-polygon test: what the
//! contour tracer's judgement, the stock's follower, the program writers' decimation and the
//! job's outputs share. Allocation-free, any dimension for the segment.

use nalgebra::{SVector, Vector2};

/// Distance \[m\] from `p` to the segment `a`-`b`, in any dimension (2-D contours, 3-D tool
/// paths).
pub fn distance_to_segment<const D: usize>(
    p: &SVector<f64, D>,
    a: &SVector<f64, D>,
    b: &SVector<f64, D>,
) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// Distance \[m\] from `p` to the boundary of the closed polygon `vertices` (any order,
/// convex or not); infinity for no vertices.
pub fn distance_to_polygon(p: &Vector2<f64>, vertices: &[Vector2<f64>]) -> f64 {
    let n = vertices.len();
    (0..n)
        .filter_map(|i| {
            let a = vertices.get(i)?;
            let b = vertices.get((i + 1) % n)?;
            Some(distance_to_segment(p, a, b))
        })
        .fold(f64::INFINITY, f64::min)
}

/// Distance \[m\] from `p` to the circle of `radius` around `center`.
pub fn distance_to_circle(p: &Vector2<f64>, center: &Vector2<f64>, radius: f64) -> f64 {
    nalgebra::ComplexField::abs((p - center).norm() - radius)
}

/// `true` if `p` lies inside the closed polygon `vertices` (even-odd rule).
pub fn inside_polygon(p: &Vector2<f64>, vertices: &[Vector2<f64>]) -> bool {
    let n = vertices.len();
    let mut inside = false;
    for i in 0..n {
        let (Some(a), Some(b)) = (vertices.get(i), vertices.get((i + 1) % n)) else {
            continue;
        };
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}
