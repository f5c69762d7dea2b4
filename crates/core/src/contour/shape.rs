//! Judging recovered contours: the RMS and largest distance of points to a shape (the
//! distances are [`crate::geometry`]'s, re-exported here).

pub use crate::geometry::{
    distance_to_circle, distance_to_polygon, distance_to_segment, inside_polygon,
};

use nalgebra::Vector2;

/// RMS and largest of the distances of `points` to a shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeError {
    /// Root mean square distance \[m\].
    pub rms: f64,
    /// Largest distance \[m\].
    pub max: f64,
    /// Number of points.
    pub count: usize,
}

/// RMS and max of `distance(p)` over `points` (zeros for no points).
pub fn shape_error<'a>(
    points: impl IntoIterator<Item = &'a Vector2<f64>>,
    distance: impl Fn(&Vector2<f64>) -> f64,
) -> ShapeError {
    let (mut sum, mut max, mut count) = (0.0, 0.0f64, 0usize);
    for p in points {
        let d = distance(p);
        sum += d * d;
        max = max.max(d);
        count += 1;
    }
    let rms = if count > 0 {
        nalgebra::ComplexField::sqrt(sum / count as f64)
    } else {
        0.0
    };
    ShapeError { rms, max, count }
}
