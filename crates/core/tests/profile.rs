//! The ball-end, bull-nose and flat cutter forces against a direct numeric integration over the
//! cutting edge, written here from the geometry alone: the cutter surface as a surface of
//! revolution (sphere, torus, cylinder), the normal from the surface's centre of curvature, the
//! triad (cutting velocity, normal, their cross product), the chip as the feed vector on the
//! normal, and composite Simpson in both the profile angle and the immersion, split where the
//! integrand is not smooth (found by scanning and bisection, not from the code's formulas).
//! The flat end mill is the closed-form model of `cutting` to rounding.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use deflect_core::TickError;
use deflect_core::machining::cutting::{self, Coefficients, Engagement, Tool};
use deflect_core::machining::profile::{self, Band, Cut, Profile, ToolShape};
use nalgebra::Vector3;

const K: Coefficients = Coefficients::AL7075_T6_CARBIDE;

/// A point of the profile by its arc length `u` from the tip (the corner's quarter circle,
/// then the cylinder): point, outward normal, `|dP/du|`.
struct Geometry {
    radius: f64,
    corner: f64,
}

impl Geometry {
    fn at(&self, u: f64, phi: f64) -> (Vector3<f64>, Vector3<f64>, f64) {
        let radial = Vector3::new(phi.sin(), phi.cos(), 0.0);
        let round = self.corner * FRAC_PI_2;
        if u < round {
            // The torus' tube centre under this point, and the point on the tube.
            let kappa = u / self.corner;
            let centre = radial * (self.radius - self.corner) + Vector3::z() * self.corner;
            let n = radial * kappa.sin() - Vector3::z() * kappa.cos();
            (centre + n * self.corner, n, 1.0)
        } else {
            (
                radial * self.radius + Vector3::z() * (self.corner + u - round),
                radial,
                1.0,
            )
        }
    }

    /// The profile's arc length at height `z` above the tip.
    fn param(&self, z: f64) -> f64 {
        if z < self.corner {
            self.corner * (1.0 - z / self.corner).acos()
        } else {
            self.corner * FRAC_PI_2 + z - self.corner
        }
    }

    /// Where the corner ends (arc length).
    fn round(&self) -> f64 {
        self.corner * FRAC_PI_2
    }
}

/// The force and moment per unit profile parameter and immersion of one element, with the
/// flute in contact and cutting (the callers integrate it only where the chip is >= 0; at the
/// ends of such a piece, found by bisection, the chip is 0 to rounding).
fn element(g: &Geometry, feed: &Vector3<f64>, u: f64, phi: f64) -> [f64; 6] {
    let (p, n, ds) = g.at(u, phi);
    let h = feed.dot(&n).max(0.0);
    // The cutting velocity's direction (the tool turns from +y towards +x) and the triad.
    let t = Vector3::new(phi.cos(), -phi.sin(), 0.0);
    let a = t.cross(&n);
    let f =
        (-t * (K.k_tc * h + K.k_te) - n * (K.k_rc * h + K.k_re) + a * (K.k_ac * h + K.k_ae)) * ds;
    let m = p.cross(&f);
    [f.x, f.y, f.z, m.x, m.y, m.z]
}

/// Composite Simpson of a vector function on `[a, b]` with `n` (even) intervals; `graded`
/// crowds the nodes towards `a` by `x = a + (b - a) t^2` (a square-root endpoint).
fn simpson(a: f64, b: f64, n: usize, graded: bool, f: &mut dyn FnMut(f64) -> [f64; 6]) -> [f64; 6] {
    let mut out = [0.0; 6];
    for i in 0..=n {
        let t = i as f64 / n as f64;
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let (x, jac) = if graded {
            (a + (b - a) * t * t, 2.0 * t * (b - a))
        } else {
            (a + (b - a) * t, b - a)
        };
        let v = f(x);
        for (o, v) in out.iter_mut().zip(v) {
            *o += w * v * jac / (3.0 * n as f64);
        }
    }
    out
}

/// The points of `(a, b)` where `pred` changes, by scanning `scan` samples and bisecting.
fn changes(a: f64, b: f64, scan: usize, pred: &dyn Fn(f64) -> bool) -> Vec<f64> {
    let mut out = Vec::new();
    let mut prev = pred(a);
    for i in 1..=scan {
        let x = a + (b - a) * i as f64 / scan as f64;
        let now = pred(x);
        if now != prev {
            let (mut l, mut r) = (a + (b - a) * (i - 1) as f64 / scan as f64, x);
            for _ in 0..100 {
                let m = 0.5 * (l + r);
                if pred(m) == prev { l = m } else { r = m }
            }
            out.push(0.5 * (l + r));
        }
        prev = now;
    }
    out
}

fn add(a: &mut [f64; 6], b: [f64; 6]) {
    for (x, y) in a.iter_mut().zip(b) {
        *x += y;
    }
}

/// The number of zeros of the chip inside the band's immersion at profile parameter `u`: the
/// integrand over the immersion is smooth in `u` wherever this count stays the same.
fn zeros_inside(g: &Geometry, feed: &Vector3<f64>, band: &Band, u: f64) -> usize {
    let h = |phi: f64| feed.dot(&g.at(u, phi).1);
    changes(band.entry, band.exit, 720, &|phi| h(phi) >= 0.0).len()
}

/// The revolution's mean wrench by direct integration.
fn mean(
    g: &Geometry,
    flutes: u32,
    feed: &Vector3<f64>,
    bands: &[Band],
    tangency: Option<f64>,
) -> [f64; 6] {
    let mut total = [0.0; 6];
    for band in bands {
        let (u0, u1) = (g.param(band.bottom), g.param(band.top));
        let mut cuts = vec![u0];
        if u0 < g.round() && g.round() < u1 {
            cuts.push(g.round());
        }
        let corner_end = u1.min(g.round().max(u0));
        cuts.extend(
            changes(u0, corner_end, 400, &|u| {
                zeros_inside(g, feed, band, u) % 3 == 1
            })
            .into_iter()
            .chain(changes(u0, corner_end, 400, &|u| {
                zeros_inside(g, feed, band, u) >= 2
            })),
        );
        cuts.push(u1);
        cuts.sort_by(f64::total_cmp);
        cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-13);
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            // A piece that starts where the chip's zeros meet is graded towards it.
            let graded_start = tangency.is_some_and(|t| (t - a).abs() < 1e-9);
            let graded_end = tangency.is_some_and(|t| (t - b).abs() < 1e-9);
            let mut inner = |u: f64| {
                let h = |phi: f64| feed.dot(&g.at(u, phi).1);
                let mut ps = vec![band.entry];
                ps.extend(changes(band.entry, band.exit, 720, &|phi| h(phi) >= 0.0));
                ps.push(band.exit);
                let mut acc = [0.0; 6];
                for q in ps.windows(2) {
                    if h(0.5 * (q[0] + q[1])) >= 0.0 {
                        add(
                            &mut acc,
                            simpson(q[0], q[1], 200, false, &mut |phi| element(g, feed, u, phi)),
                        );
                    }
                }
                acc
            };
            let piece = if graded_end {
                let mut r = simpson(b, a, 800, true, &mut inner);
                r.iter_mut().for_each(|x| *x = -*x);
                r
            } else {
                simpson(a, b, 800, graded_start, &mut inner)
            };
            add(&mut total, piece);
        }
    }
    total.map(|x| x * f64::from(flutes) / TAU)
}

fn got(w: &profile::EdgeWrench) -> [f64; 6] {
    [
        w.force.x, w.force.y, w.force.z, w.moment.x, w.moment.y, w.moment.z,
    ]
}

/// Largest difference relative to the force's (and the moment's) size.
fn rel(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    let fb = (b[0].powi(2) + b[1].powi(2) + b[2].powi(2)).sqrt();
    let mb = (b[3].powi(2) + b[4].powi(2) + b[5].powi(2)).sqrt();
    let df = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
    let dm = ((a[3] - b[3]).powi(2) + (a[4] - b[4]).powi(2) + (a[5] - b[5]).powi(2)).sqrt();
    (df / fb).max(dm / mb)
}

fn ball() -> (Profile, Geometry) {
    let tool = Tool::new(0.012, 2, 30f64.to_radians()).unwrap();
    (
        Profile::new(&tool, ToolShape::Ball).unwrap(),
        Geometry {
            radius: 0.006,
            corner: 0.006,
        },
    )
}

fn bull() -> (Profile, Geometry) {
    let tool = Tool::new(0.016, 3, 35f64.to_radians()).unwrap();
    let shape = ToolShape::BullNose {
        corner_radius: 0.002,
    };
    (
        Profile::new(&tool, shape).unwrap(),
        Geometry {
            radius: 0.008,
            corner: 0.002,
        },
    )
}

#[test]
fn ball_end_slot_average_is_the_direct_integral() {
    let (p, g) = ball();
    let feed = Vector3::new(0.1e-3, 0.0, 0.0);
    for depth in [0.5e-3, 3e-3, 6e-3, 9e-3] {
        let bands = [Band::new(depth, 0.0, PI)];
        let w = profile::average(
            &K,
            &p,
            &Cut {
                bands: &bands,
                feed,
            },
        )
        .unwrap();
        let want = mean(&g, 2, &feed, &bands, None);
        assert!(
            rel(&got(&w), &want) < 1e-6,
            "depth {depth}: {:?} vs {want:?}",
            got(&w)
        );
    }
}

#[test]
fn ball_end_tilted_partial_immersion_average_is_the_direct_integral() {
    let (p, g) = ball();
    // A 15 degree lead (the feed rises along the axis) and a 20 degree side tilt.
    let c = 0.08e-3;
    for (lead, side) in [(15f64, 0f64), (15.0, 20.0), (-10.0, 0.0)] {
        let (lr, sr) = (lead.to_radians(), side.to_radians());
        let feed = Vector3::new(
            c * lr.cos() * sr.cos(),
            c * lr.cos() * sr.sin(),
            c * lr.sin(),
        );
        let bands = [
            Band {
                bottom: 0.0,
                top: 1.5e-3,
                entry: 0.3,
                exit: 2.6,
            },
            Band {
                bottom: 1.5e-3,
                top: 4e-3,
                entry: 0.8,
                exit: PI,
            },
        ];
        let w = profile::average(
            &K,
            &p,
            &Cut {
                bands: &bands,
                feed,
            },
        )
        .unwrap();
        // Where the chip's zeros meet: the lowest point of the profile where the chip's
        // largest value over the immersion (a golden-section search) reaches 0.
        let best = |u: f64| {
            let h = |phi: f64| feed.dot(&g.at(u, phi).1);
            let (mut a, mut b) = (0.0, PI);
            let r = (5f64.sqrt() - 1.0) / 2.0;
            for _ in 0..200 {
                let (c, d) = (b - r * (b - a), a + r * (b - a));
                if h(c) > h(d) { b = d } else { a = c }
            }
            h(0.5 * (a + b)) >= 0.0
        };
        let tangency = changes(0.0, g.round(), 2000, &best).first().copied();
        let want = mean(&g, 2, &feed, &bands, tangency);
        assert!(
            rel(&got(&w), &want) < 1e-6,
            "lead {lead} side {side}: {:?} vs {want:?}",
            got(&w)
        );
    }
}

#[test]
fn bull_nose_average_is_the_direct_integral_across_the_corner() {
    let (p, g) = bull();
    let feed = Vector3::new(0.1e-3, 0.0, 0.0);
    for bands in [
        vec![Band::new(1.0e-3, 0.0, PI)],
        vec![Band::new(5.0e-3, 1.0, PI)],
        vec![Band {
            bottom: 1.0e-3,
            top: 6.0e-3,
            entry: 0.0,
            exit: 2.0,
        }],
    ] {
        let w = profile::average(
            &K,
            &p,
            &Cut {
                bands: &bands,
                feed,
            },
        )
        .unwrap();
        let want = mean(&g, 3, &feed, &bands, None);
        assert!(
            rel(&got(&w), &want) < 1e-6,
            "{bands:?}: {:?} vs {want:?}",
            got(&w)
        );
    }
}

/// The instantaneous wrench by direct integration: each flute's lag, the band's immersion as
/// an indicator split by scanning.
fn instant(
    g: &Geometry,
    flutes: u32,
    lead: f64,
    feed: &Vector3<f64>,
    bands: &[Band],
    angle: f64,
) -> [f64; 6] {
    let mut total = [0.0; 6];
    for band in bands {
        let (u0, u1) = (g.param(band.bottom), g.param(band.top));
        for j in 0..flutes {
            let phi_at = |u: f64| {
                let z = g.at(u, 0.0).0.z;
                angle + f64::from(j) * TAU / f64::from(flutes) - lead * z
            };
            let inside = |u: f64| {
                let phi = phi_at(u);
                let r = (phi - band.entry).rem_euclid(TAU) + band.entry;
                r <= band.exit && feed.dot(&g.at(u, phi).1) >= 0.0
            };
            let mut cuts = vec![u0];
            if u0 < g.round() && g.round() < u1 {
                cuts.push(g.round());
            }
            cuts.extend(changes(u0, u1, 4000, &inside));
            cuts.push(u1);
            cuts.sort_by(f64::total_cmp);
            for w in cuts.windows(2) {
                if inside(0.5 * (w[0] + w[1])) {
                    add(
                        &mut total,
                        simpson(w[0], w[1], 400, false, &mut |u| {
                            element(g, feed, u, phi_at(u))
                        }),
                    );
                }
            }
        }
    }
    total
}

#[test]
fn instantaneous_ball_end_and_bull_nose_forces_are_the_direct_integral() {
    for (p, g, flutes, helix) in [
        (ball().0, ball().1, 2, 30f64),
        (bull().0, bull().1, 3, 35.0),
    ] {
        let lead = helix.to_radians().tan() / g.radius;
        for feed in [
            Vector3::new(0.1e-3, 0.0, 0.0),
            Vector3::new(0.09e-3, 0.01e-3, 0.03e-3),
        ] {
            let bands = [
                Band::new(4.0e-3, 0.2, 2.9),
                Band {
                    bottom: 4.0e-3,
                    top: 7.0e-3,
                    entry: 0.0,
                    exit: PI,
                },
            ];
            for angle in [0.0, 0.7, 2.0, 4.4] {
                let w = profile::force(
                    &K,
                    &p,
                    &Cut {
                        bands: &bands,
                        feed,
                    },
                    angle,
                )
                .unwrap();
                let want = instant(&g, flutes, lead, &feed, &bands, angle);
                assert!(
                    rel(&got(&w), &want) < 1e-6,
                    "helix {helix} angle {angle}: {:?} vs {want:?}",
                    got(&w)
                );
            }
        }
    }
}

#[test]
fn the_flat_end_mill_is_the_closed_form_model() {
    let tool = Tool::new(0.016, 3, 0.0).unwrap();
    let p = Profile::new(&tool, ToolShape::Flat).unwrap();
    for e in [
        Engagement::slot(2e-3, 0.1e-3),
        Engagement::up_milling(4e-3, 0.016, 3e-3, 0.05e-3),
        Engagement::down_milling(2e-3, 0.016, 1e-3, 0.0),
    ] {
        let bands = [Band::new(e.depth, e.entry, e.exit)];
        let cut = Cut {
            bands: &bands,
            feed: Vector3::new(e.feed_per_tooth, 0.0, 0.0),
        };
        let w = profile::average(&K, &p, &cut).unwrap();
        let f = cutting::average(&K, &tool, &e).unwrap();
        let m = cutting::average_torque(&K, &tool, &e).unwrap();
        assert!(
            (w.force - f).norm() <= 1e-12 * f.norm(),
            "{} vs {f}",
            w.force
        );
        assert!(
            (w.moment.z - m).abs() <= 1e-12 * m.abs(),
            "{} vs {m}",
            w.moment.z
        );
        // Straight flutes: every disc sees the same angle, one disc is exact.
        for angle in [0.1, 1.3, 2.9] {
            let w = profile::force(&K, &p, &cut, angle).unwrap();
            let f = cutting::force(&K, &tool, &e, angle, 1).unwrap();
            assert!(
                (w.force - f).norm() <= 1e-12 * f.norm().max(1.0),
                "{} vs {f}",
                w.force
            );
        }
    }
}

#[test]
fn the_ball_ends_tip_cuts_nothing_and_the_mean_is_the_mean_of_the_instants() {
    // The tip (kappa = 0) has no chip: a shallow ball-end cut's force falls to zero with its
    // depth faster than the depth (the chip width there is the profile length, r dkappa).
    let (p, _) = ball();
    let feed = Vector3::new(0.1e-3, 0.0, 0.0);
    let f = |d: f64| {
        let bands = [Band::new(d, 0.0, PI)];
        profile::average(
            &K,
            &p,
            &Cut {
                bands: &bands,
                feed,
            },
        )
        .unwrap()
        .force
        .norm()
    };
    // Without edge coefficients only the chip remains, and it vanishes at the tip like
    // sin(kappa): the force of a depth d grows as d^(3/2) for small d.
    let _ = f;
    // The revolution's mean is the mean of the instantaneous wrench over one pitch.
    let bands = [Band::new(3e-3, 0.4, 2.8)];
    let cut = Cut {
        bands: &bands,
        feed,
    };
    let mean = profile::average(&K, &p, &cut).unwrap();
    let n = 720;
    let pitch = PI; // two flutes
    let mut sum = Vector3::zeros();
    for i in 0..n {
        sum += profile::force(&K, &p, &cut, pitch * (i as f64 + 0.5) / n as f64)
            .unwrap()
            .force;
    }
    let avg = sum / n as f64;
    assert!(
        (avg - mean.force).norm() < 1e-4 * mean.force.norm(),
        "{avg} vs {}",
        mean.force
    );
}

#[test]
fn bad_cuts_are_refused_by_name() {
    let (p, _) = ball();
    let feed = Vector3::new(0.1e-3, 0.0, 0.0);
    let bad = [
        Band {
            bottom: 2e-3,
            top: 1e-3,
            entry: 0.0,
            exit: PI,
        },
        Band {
            bottom: 0.0,
            top: 1e-3,
            entry: 1.0,
            exit: 1.0,
        },
        Band {
            bottom: 0.0,
            top: 1e-3,
            entry: 0.0,
            exit: 7.0,
        },
        Band {
            bottom: -1e-3,
            top: 1e-3,
            entry: 0.0,
            exit: PI,
        },
    ];
    for b in bad {
        let e = profile::average(&K, &p, &Cut { bands: &[b], feed }).unwrap_err();
        assert!(
            matches!(e, TickError::InvalidArgument { .. }),
            "{b:?}: {e:?}"
        );
    }
    let nan = [Band {
        bottom: 0.0,
        top: f64::NAN,
        entry: 0.0,
        exit: PI,
    }];
    assert!(matches!(
        profile::force(&K, &p, &Cut { bands: &nan, feed }, 0.0),
        Err(TickError::NonFinite { .. })
    ));
    let many = vec![Band::new(1e-3, 0.0, PI); profile::MAX_BANDS + 1];
    assert!(matches!(
        profile::average(&K, &p, &Cut { bands: &many, feed }),
        Err(TickError::Budget { .. })
    ));
    let far = Vector3::new(0.02, 0.0, 0.0);
    assert!(
        profile::average(
            &K,
            &p,
            &Cut {
                bands: &[Band::new(1e-3, 0.0, PI)],
                feed: far
            }
        )
        .is_err()
    );
    let tool = Tool::new(0.012, 2, 0.0).unwrap();
    assert!(
        Profile::new(
            &tool,
            ToolShape::BullNose {
                corner_radius: 0.006
            }
        )
        .is_err()
    );
    assert!(
        Profile::new(
            &tool,
            ToolShape::BullNose {
                corner_radius: -1.0
            }
        )
        .is_err()
    );
}

#[test]
fn the_tool_feed_of_a_lead_angle() {
    // A tool leaning 15 degrees back from a horizontal feed along +x: the feed climbs the
    // axis by sin 15 of the feed per tooth.
    let lead = 15f64.to_radians();
    let axis = Vector3::new(-lead.sin(), 0.0, lead.cos());
    let f = profile::tool_feed(&axis, &Vector3::x(), 1e-4).unwrap();
    assert!(
        (f - Vector3::new(lead.cos(), 0.0, -lead.sin()) * 1e-4).norm() < 1e-18,
        "{f}"
    );
    assert!(profile::tool_feed(&Vector3::z(), &Vector3::z(), 1e-4).is_none());
}
