//! The unknown objects of the contour scene: outlines in the plane (a disk or a polygon,
//! convex or not), their distances and penetration depths for the penalty contact, and the
//! default set of objects to trace.

use deflect_core::contour::shape;
use nalgebra::Vector2;
use serde::Serialize;

/// An unknown rigid object in the plane.
#[derive(Debug, Clone, Serialize)]
pub enum Outline {
    /// A disk: centre \[m\], radius \[m\].
    Circle {
        /// Centre \[m\].
        center: [f64; 2],
        /// Radius \[m\].
        radius: f64,
    },
    /// A closed polygon (convex or not), counter-clockwise vertices \[m\].
    Polygon {
        /// Vertices \[m\].
        vertices: Vec<[f64; 2]>,
    },
}

/// A point `[x, y]` as a vector.
pub(crate) fn v2(p: &[f64; 2]) -> Vector2<f64> {
    Vector2::new(p[0], p[1])
}

impl Outline {
    fn verts(vertices: &[[f64; 2]]) -> Vec<Vector2<f64>> {
        vertices.iter().map(v2).collect()
    }

    /// Distance of `p` to the outline \[m\].
    pub fn distance(&self, p: &Vector2<f64>) -> f64 {
        match self {
            Self::Circle { center, radius } => shape::distance_to_circle(p, &v2(center), *radius),
            Self::Polygon { vertices } => shape::distance_to_polygon(p, &Self::verts(vertices)),
        }
    }

    /// Signed distance \[m\]: positive outside, negative inside.
    pub fn signed_distance(&self, p: &Vector2<f64>) -> f64 {
        match self {
            Self::Circle { center, radius } => (p - v2(center)).norm() - radius,
            Self::Polygon { vertices } => {
                let v = Self::verts(vertices);
                let d = shape::distance_to_polygon(p, &v);
                if shape::inside_polygon(p, &v) { -d } else { d }
            }
        }
    }

    /// For a point inside: penetration depth \[m\] and the unit direction into the object (the
    /// direction of the force the tool exerts on it).
    pub fn penetration(&self, p: &Vector2<f64>) -> Option<(f64, Vector2<f64>)> {
        match self {
            Self::Circle { center, radius } => {
                let d = p - v2(center);
                let n = d.norm();
                (n < *radius && n > 0.0).then(|| (radius - n, -d / n))
            }
            Self::Polygon { vertices } => {
                let v = Self::verts(vertices);
                if !shape::inside_polygon(p, &v) {
                    return None;
                }
                let mut best = (f64::INFINITY, Vector2::zeros());
                for i in 0..v.len() {
                    let (a, b) = (v[i], v[(i + 1) % v.len()]);
                    let ab = b - a;
                    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                    let q = a + ab * t;
                    let d = (p - q).norm();
                    if d < best.0 {
                        best = (d, q);
                    }
                }
                let (d, q) = best;
                (d > 0.0).then(|| (d, (p - q) / d))
            }
        }
    }

    /// Points along the outline for plots \[m\] (closed: the first point repeats).
    pub fn polyline(&self) -> Vec<Vector2<f64>> {
        match self {
            Self::Circle { center, radius } => (0..=180)
                .map(|k| {
                    let a = k as f64 * core::f64::consts::TAU / 180.0;
                    v2(center) + Vector2::new(a.cos(), a.sin()) * *radius
                })
                .collect(),
            Self::Polygon { vertices } => {
                let mut v = Self::verts(vertices);
                if let Some(f) = v.first().copied() {
                    v.push(f);
                }
                v
            }
        }
    }

    /// Perimeter \[m\].
    pub fn perimeter(&self) -> f64 {
        match self {
            Self::Circle { radius, .. } => core::f64::consts::TAU * radius,
            Self::Polygon { .. } => self
                .polyline()
                .windows(2)
                .map(|w| (w[1] - w[0]).norm())
                .sum(),
        }
    }
}

/// One object to trace: its outline and where the tracer starts (out of contact), approaching
/// along +x.
#[derive(Debug, Clone, Serialize)]
pub struct ObjectSpec {
    /// Short name ("circle", "rectangle", "l_shape").
    pub name: String,
    /// The true outline.
    pub outline: Outline,
    /// Start point of the tool \[m\].
    pub start: [f64; 2],
}

/// The default objects: a disk of 60 mm radius, a 160 x 110 mm rectangle with sharp corners
/// and a non-convex L (150 x 150 mm, arms 70 mm wide), spread over the arm's workspace.
pub fn default_objects() -> Vec<ObjectSpec> {
    vec![
        ObjectSpec {
            name: "circle".into(),
            outline: Outline::Circle {
                center: [0.60, 0.30],
                radius: 0.06,
            },
            start: [0.50, 0.30],
        },
        ObjectSpec {
            name: "rectangle".into(),
            outline: Outline::Polygon {
                vertices: vec![[0.50, -0.06], [0.66, -0.06], [0.66, 0.05], [0.50, 0.05]],
            },
            start: [0.46, 0.0],
        },
        ObjectSpec {
            name: "l_shape".into(),
            outline: Outline::Polygon {
                vertices: vec![
                    [0.45, -0.42],
                    [0.60, -0.42],
                    [0.60, -0.35],
                    [0.52, -0.35],
                    [0.52, -0.27],
                    [0.45, -0.27],
                ],
            },
            start: [0.41, -0.38],
        },
    ]
}
