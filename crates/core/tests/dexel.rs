//! The tri-dexel stock against the analytic cross-sections of a flat slot and a ball-end
//! groove cut with the tool tilted 0, 30 and 60 degrees about the feed direction (the swept
//! solid's section is the tool's outline turned by the tilt: written here from the profile),
//! the removed volume of the vertical cuts in closed form, the z-map where both apply, a
//! turning axis, and bad input.

use deflect_core::machining::cutting::Tool;
use deflect_core::machining::dexel::{self, DexelTool, Dexels};
use deflect_core::machining::profile::{Profile, ToolShape};
use deflect_core::machining::stock::{Cutter, ZMap};
use deflect_core::{BuildError, TickError};
use nalgebra::{Vector2, Vector3};

const CELL: f64 = 0.25e-3;
const R: f64 = 3.0e-3;
const LENGTH: f64 = 10.0e-3;
const TIP_Z: f64 = -2.0e-3;

fn tool(shape: ToolShape) -> DexelTool {
    let t = Tool::new(2.0 * R, 2, 0.0).unwrap();
    DexelTool::new(&Profile::new(&t, shape).unwrap(), LENGTH).unwrap()
}

fn stock() -> Dexels {
    Dexels::block(
        Vector3::new(0.0, -8e-3, -8e-3),
        Vector3::new(14e-3, 8e-3, 0.0),
        CELL,
    )
    .unwrap()
}

/// The tool's radius at height `z` above its tip, from the profile's geometry.
fn radius(shape: ToolShape, z: f64) -> f64 {
    match shape {
        ToolShape::Flat => R,
        ToolShape::Ball if z < R => (R * R - (R - z) * (R - z)).sqrt(),
        _ => R,
    }
}

/// Whether the slot's cross-section (y, z) was cut: the tool's outline in the plane across
/// the feed, its axis tilted by `tilt` towards +y.
fn removed(shape: ToolShape, tilt: f64, y: f64, z: f64) -> bool {
    let (s, c) = tilt.sin_cos();
    let (wy, wz) = (y, z - TIP_Z);
    let axial = wy * s + wz * c;
    let lateral = wy * c - wz * s;
    (0.0..=LENGTH).contains(&axial) && lateral.abs() <= radius(shape, axial)
}

/// The cut interval along a line of the cross-section through `(y(u), z(u))`, by bisection
/// on `removed` from a fine scan (the cut set along a line is one interval: convex).
fn cut_interval(inside: &dyn Fn(f64) -> bool, lo: f64, hi: f64) -> Option<(f64, f64)> {
    let n = 4000;
    let xs: Vec<f64> = (0..=n)
        .map(|i| lo + (hi - lo) * f64::from(i) / f64::from(n))
        .collect();
    let first = xs.iter().position(|&x| inside(x))?;
    let last = xs.iter().rposition(|&x| inside(x))?;
    let edge = |mut a: f64, mut b: f64| {
        // a inside, b outside
        for _ in 0..80 {
            let m = 0.5 * (a + b);
            if inside(m) { a = m } else { b = m }
        }
        0.5 * (a + b)
    };
    let a = if first == 0 {
        lo
    } else {
        edge(xs[first], xs[first - 1])
    };
    let b = if last == n as usize {
        hi
    } else {
        edge(xs[last], xs[last + 1])
    };
    Some((a, b))
}

/// The ray's material complement within `[lo, hi]` (what was removed): one gap, or none.
fn gap(material: &[(f64, f64)], lo: f64, hi: f64) -> Option<(f64, f64)> {
    let mut edges = vec![lo];
    for &(a, b) in material {
        edges.push(a);
        edges.push(b);
    }
    edges.push(hi);
    let gaps: Vec<(f64, f64)> = edges
        .chunks(2)
        .map(|w| (w[0], w[1]))
        .filter(|(a, b)| b - a > 1e-12)
        .collect();
    assert!(gaps.len() <= 1, "{gaps:?}");
    gaps.first().copied()
}

#[test]
fn tilted_slots_and_grooves_leave_the_analytic_cross_section() {
    for shape in [ToolShape::Flat, ToolShape::Ball] {
        for degrees in [0.0f64, 30.0, 60.0] {
            let tilt = degrees.to_radians();
            let axis = Vector3::new(0.0, tilt.sin(), tilt.cos());
            let mut d = stock();
            let (from, to) = (
                Vector3::new(3.5e-3, 0.0, TIP_Z),
                Vector3::new(10.5e-3, 0.0, TIP_Z),
            );
            let removal = d.cut(&tool(shape), &from, &axis, &to, &axis).unwrap();
            assert!(removal.rays > 0 && removal.volume > 0.0);
            // The rays through the cell centre x = 7.125 mm, far from the slot's ends: along
            // y (through each z) and along z (through each y), exact to the bisection.
            let [nx, ny, nz] = d.shape();
            let i = 28;
            let (x_origin, _) = d.ray(2, i, 0).unwrap();
            assert!((x_origin.x - 7.125e-3).abs() < 1e-15);
            let mut checked = 0;
            for k in 0..nz {
                // y-rays run along y, indexed by (z, x).
                let (o, material) = d.ray(1, k, i).unwrap();
                let want = cut_interval(&|y| removed(shape, tilt, y, o.z), -8e-3, 8e-3);
                let got = gap(material, -8e-3, 8e-3);
                match (want, got) {
                    (None, None) => {}
                    (Some(w), Some(g)) => {
                        assert!(
                            (w.0 - g.0).abs() < 1e-8 && (w.1 - g.1).abs() < 1e-8,
                            "{shape:?} {degrees} z {}: {w:?} vs {g:?}",
                            o.z
                        );
                        checked += 1;
                    }
                    // A gap thinner than the scan's step.
                    (w, g) => assert!(
                        w.or(g).is_some_and(|(a, b)| b - a < 1e-5),
                        "{shape:?} {degrees} z {}: {w:?} vs {g:?}",
                        o.z
                    ),
                }
            }
            for j in 0..ny {
                let (o, material) = d.ray(2, i, j).unwrap();
                let want = cut_interval(&|z| removed(shape, tilt, o.y, z), -8e-3, 0.0);
                let got = gap(material, -8e-3, 0.0);
                if let (Some(w), Some(g)) = (want, got) {
                    assert!(
                        (w.0 - g.0).abs() < 1e-8 && (w.1 - g.1).abs() < 1e-8,
                        "{shape:?} {degrees} y {}: {w:?} vs {g:?}",
                        o.y
                    );
                    checked += 1;
                } else {
                    assert!(
                        want.or(got).is_none_or(|(a, b)| b - a < 1e-5),
                        "{want:?} vs {got:?}"
                    );
                }
            }
            assert!(checked > 20, "{checked}");
            // A point's material (the nearest z-ray) is wrong only within a cell of the
            // analytic boundary.
            for a in 0..120 {
                for b in 0..60 {
                    let p = Vector3::new(
                        7.1e-3,
                        -7.9e-3 + 15.8e-3 * f64::from(a) / 119.0,
                        -7.9e-3 + 7.8e-3 * f64::from(b) / 59.0,
                    );
                    let want = !removed(shape, tilt, p.y, p.z);
                    if d.is_material(&p) != want {
                        let near = (0..32).any(|k| {
                            let t = f64::from(k) * std::f64::consts::TAU / 32.0;
                            // A neighbour a cell away on the other side of the wall.
                            removed(shape, tilt, p.y + CELL * t.cos(), p.z + CELL * t.sin()) == want
                        });
                        assert!(near, "{shape:?} {degrees}: {p} misread far from the wall");
                    }
                }
            }
            let _ = nx;
        }
    }
}

#[test]
fn vertical_cuts_remove_the_closed_form_volume_and_agree_with_the_z_map() {
    let (h, len) = (-TIP_Z, 7e-3);
    for (shape, cutter) in [
        (ToolShape::Flat, Cutter::Flat { radius: R }),
        (ToolShape::Ball, Cutter::Ball { radius: R }),
    ] {
        let mut d = stock();
        let (from, to) = (
            Vector3::new(3.5e-3, 0.0, TIP_Z),
            Vector3::new(10.5e-3, 0.0, TIP_Z),
        );
        let before = d.volume();
        let r = d
            .cut(&tool(shape), &from, &Vector3::z(), &to, &Vector3::z())
            .unwrap();
        assert!((before - d.volume() - r.volume).abs() < 1e-18);
        // Flat: the slot's outline (a stadium) times the depth. Ball: the circular segment
        // of depth h along the move and a spherical cap of depth h at the two ends together.
        let (want, perimeter) = match shape {
            ToolShape::Flat => (
                (2.0 * R * len + std::f64::consts::PI * R * R) * h,
                2.0 * len + std::f64::consts::TAU * R,
            ),
            _ => {
                let w = (2.0 * R * h - h * h).sqrt();
                let segment = R * R * ((R - h) / R).acos() - (R - h) * w;
                let cap = std::f64::consts::PI * h * h * (3.0 * R - h) / 3.0;
                (segment * len + cap, 2.0 * len + std::f64::consts::TAU * w)
            }
        };
        // The z-rays sample the outline at cell centres: within the perimeter times the depth
        // times a cell.
        assert!(
            (r.volume - want).abs() < perimeter * h * CELL,
            "{shape:?}: {} vs {want}",
            r.volume
        );
        assert!(
            (r.volume - want).abs() < 0.02 * want,
            "{shape:?}: {} vs {want}",
            r.volume
        );
        // The z-map of the same cells: the heights agree where no rim averaging applies.
        let mut z = ZMap::new(
            Vector2::new(0.0, -8e-3),
            Vector2::new(14e-3, 8e-3),
            0.0,
            CELL,
        )
        .unwrap();
        let _ = z.cut(&cutter, &from, &to).unwrap();
        let (zx, zy) = z.shape();
        let mut compared = 0;
        for i in 0..zx {
            for j in 0..zy {
                let c = z.center(i, j);
                let (o, material) = d.ray(2, i, j).unwrap();
                assert!((o.x - c.x).abs() < 1e-15 && (o.y - c.y).abs() < 1e-15);
                // Away from the rim (the z-map averages the cells it crosses).
                let along = c.x.clamp(from.x, to.x);
                let dist = ((c.x - along).powi(2) + c.y.powi(2)).sqrt();
                if (dist - R).abs() < 1.5 * CELL {
                    continue;
                }
                let top = material.last().map_or(-8e-3, |m| m.1);
                let zh = z.height(i, j).unwrap();
                assert!(
                    (top - zh).abs() < 1e-9,
                    "{shape:?} ({i}, {j}): dexel {top} z-map {zh}"
                );
                compared += 1;
            }
        }
        assert!(compared > 1000, "{compared}");
    }
}

#[test]
fn a_turning_axis_sweeps_between_its_ends() {
    let t = tool(ToolShape::Ball);
    let mut d = stock();
    let p = Vector3::new(7e-3, 0.0, TIP_Z);
    let a0 = Vector3::z();
    let tilt = 40f64.to_radians();
    let a1 = Vector3::new(0.0, tilt.sin(), tilt.cos());
    let _ = d.cut(&t, &p, &a0, &p, &a1).unwrap();
    // Both end poses are cut out; a point that no intermediate tool holds (dilated by a
    // quarter cell, the pieces' bound) is not.
    for a in 0..80 {
        for b in 0..40 {
            let q = Vector3::new(
                7.1e-3,
                -7.9e-3 + 15.8e-3 * f64::from(a) / 79.0,
                -7.9e-3 + 7.8e-3 * f64::from(b) / 39.0,
            );
            let held = |k: usize, grow: f64| {
                let s = tilt * k as f64 / 400.0;
                let axis = Vector3::new(0.0, s.sin(), s.cos());
                let w = q - p;
                let z = w.dot(&axis);
                (-grow..=LENGTH + grow).contains(&z)
                    && (w - axis * z).norm() <= radius(ToolShape::Ball, z.clamp(0.0, LENGTH)) + grow
            };
            // Read along the z-ray through q's cell: within a cell of q laterally.
            let in_any = (0..=400).any(|k| held(k, 0.25 * CELL + CELL));
            let in_ends = held(0, -CELL) || held(400, -CELL);
            if in_ends {
                assert!(!d.is_material(&q), "{q} in an end pose");
            }
            if !in_any {
                assert!(d.is_material(&q), "{q} outside every pose");
            }
        }
    }
}

#[test]
fn bad_stocks_tools_and_cuts_are_refused() {
    let z = Vector3::zeros();
    let one = Vector3::new(1e-2, 1e-2, 1e-2);
    assert!(matches!(
        Dexels::block(z, one, 0.0),
        Err(BuildError::InvalidParameter { .. })
    ));
    assert!(matches!(
        Dexels::block(one, z, 1e-3),
        Err(BuildError::InvalidParameter { .. })
    ));
    assert!(matches!(
        Dexels::block(z, Vector3::new(f64::NAN, 1.0, 1.0), 1e-3),
        Err(BuildError::InvalidParameter { .. })
    ));
    // A metre cube at 0.1 mm: 3e8 rays, past MAX_RAYS.
    let e = Dexels::block(z, Vector3::new(1.0, 1.0, 1.0), 1e-4).unwrap_err();
    assert!(
        matches!(
            e,
            BuildError::Budget {
                budget: "MAX_RAYS",
                ..
            }
        ),
        "{e}"
    );
    const { assert!(dexel::MAX_RAYS <= dexel::MAX_INTERVALS) };
    let t = Tool::new(6e-3, 2, 0.0).unwrap();
    let ball = Profile::new(&t, ToolShape::Ball).unwrap();
    assert!(
        DexelTool::new(&ball, 1e-3).is_err(),
        "shorter than its corner"
    );
    let mut d = Dexels::block(z, one, 1e-3).unwrap();
    let tool = DexelTool::new(&ball, 5e-3).unwrap();
    let p = Vector3::new(5e-3, 5e-3, 5e-3);
    let e = d
        .cut(&tool, &p, &Vector3::new(0.0, 0.0, 2.0), &p, &Vector3::z())
        .unwrap_err();
    assert!(matches!(e, TickError::InvalidArgument { .. }), "{e:?}");
    let e = d
        .cut(
            &tool,
            &Vector3::new(f64::NAN, 0.0, 0.0),
            &Vector3::z(),
            &p,
            &Vector3::z(),
        )
        .unwrap_err();
    assert!(matches!(e, TickError::NonFinite { .. }), "{e:?}");
    let e = d
        .cut(&tool, &p, &Vector3::z(), &p, &-Vector3::z())
        .unwrap_err();
    assert!(matches!(e, TickError::InvalidArgument { .. }), "{e:?}");
}

#[test]
fn the_engagement_read_from_the_dexels_is_the_slots_and_its_force_the_closed_form() {
    use deflect_core::machining::cutting::{self, Coefficients, Engagement, tool_frame};
    use deflect_core::machining::profile::{self, Band, Cut};
    let flat = tool(ToolShape::Flat);
    let mut d = stock();
    // The slot cut up to x = 7 mm; the tool there, feeding on along +x.
    let (from, here) = (
        Vector3::new(3.5e-3, 0.0, TIP_Z),
        Vector3::new(7e-3, 0.0, TIP_Z),
    );
    let _ = d
        .cut(&flat, &from, &Vector3::z(), &here, &Vector3::z())
        .unwrap();
    let frame = tool_frame(&Vector3::z(), &Vector3::x()).unwrap();
    let mut bands = [Band::new(0.0, 0.0, 1.0); 64];
    let n = d
        .engagement(&flat, &here, &frame, 40, 360, &mut bands)
        .unwrap();
    // One band: the 2 mm under the top (its end found between the slices of 0.25 mm to a
    // millionth of one), over the front half.
    assert_eq!(n, 1, "{:?}", &bands[..n]);
    let b = bands[0];
    assert_eq!(b.bottom, 0.0);
    assert!((b.top - 2e-3).abs() < 0.25e-9, "{}", b.top);
    // The arc from 0 to pi to a few degrees (it may start just before 0: then its entry
    // reads in [pi, 2 pi) and its exit past 2 pi).
    let tau = std::f64::consts::TAU;
    let entry = if b.entry > std::f64::consts::PI {
        b.entry - tau
    } else {
        b.entry
    };
    let exit = b.exit - (b.entry - entry);
    assert!(
        entry.abs() < 3f64.to_radians() && (exit - std::f64::consts::PI).abs() < 3f64.to_radians(),
        "{b:?}"
    );
    // Its force is the full slot's closed form to the arc's ends.
    let k = Coefficients::AL7075_T6_CARBIDE;
    let t = Tool::new(2.0 * R, 2, 0.0).unwrap();
    let p = Profile::new(&t, ToolShape::Flat).unwrap();
    let c = 0.1e-3;
    let got = profile::average(
        &k,
        &p,
        &Cut {
            bands: &bands[..n],
            feed: Vector3::new(c, 0.0, 0.0),
        },
    )
    .unwrap();
    let want = cutting::average(&k, &t, &Engagement::slot(2e-3, c)).unwrap();
    assert!(
        (got.force - want).norm() < 0.03 * want.norm(),
        "{} vs {want}",
        got.force
    );
    // A tool in the air engages nothing; too many bands for the output is refused.
    let air = Vector3::new(7e-3, 0.0, 0.02);
    assert_eq!(
        d.engagement(&flat, &air, &frame, 40, 360, &mut bands)
            .unwrap(),
        0
    );
    assert!(
        d.engagement(&flat, &here, &frame, 40, 360, &mut [])
            .is_err()
    );
    assert!(
        d.engagement(&flat, &here, &frame, 0, 360, &mut bands)
            .is_err()
    );
    assert!(
        d.engagement(&flat, &here, &frame, 4096, 3600, &mut bands)
            .is_err()
    );
}

#[test]
fn a_ramp_cut_in_halves_is_the_ramp_for_every_cutter() {
    // The swept solid of a straight move is the union of its halves' (a fixed axis): each
    // ray's interval the same to rounding, whichever part of the tool (the end's corner,
    // the cylinder) bounds it. The ramp climbs along the axis' lean, so the move's part along
    // the axis (gamma) is not zero.
    let shapes = [
        ToolShape::Flat,
        ToolShape::Ball,
        ToolShape::BullNose {
            corner_radius: 1e-3,
        },
    ];
    for shape in shapes {
        let solid = tool(shape);
        let block = || {
            Dexels::block(
                Vector3::new(-6e-3, -8e-3, -6e-3),
                Vector3::new(20e-3, 8e-3, 0.0),
                CELL,
            )
            .unwrap()
        };
        let a = Vector3::new(-0.3634127, 0.0, 0.9316282).normalize();
        let (p, q) = (
            Vector3::new(0.0, 0.0, -3e-3),
            Vector3::new(14e-3, 0.0, 1e-3),
        );
        let m = (p + q) * 0.5;
        let mut whole = block();
        let mut halves = block();
        let _ = whole.cut(&solid, &p, &a, &q, &a).unwrap();
        let _ = halves.cut(&solid, &p, &a, &m, &a).unwrap();
        let _ = halves.cut(&solid, &m, &a, &q, &a).unwrap();
        let (pts, missing) = whole.surface_deviation(&halves, 4e-3).unwrap();
        let worst = pts.iter().map(|p| p.deviation.abs()).fold(0.0, f64::max);
        assert!(pts.len() > 500, "{shape:?}: {}", pts.len());
        assert!(
            worst < 1e-9 && missing == 0,
            "{shape:?}: {worst} ({missing} unmatched)"
        );
    }
}
