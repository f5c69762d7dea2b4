//! The chip's force is continuous in the tool's position: the Lipschitz bound of
//! `machining::chip` (`|dF| <= W (|d_z| + sqrt(2) D / cell |d_xy|)`) checked with a bound on
//! `W` derived by hand from the coefficients, on the thin floor strip that made the
//! engagement's threshold jump by tens of newtons, and on random stocks; and a chip of one
//! depth everywhere gives the closed form of `cutting::average`.

use core::f64::consts::PI;

use deflect_core::machining::chip::ChipModel;
use deflect_core::machining::cutting::{self, Coefficients, Engagement, Tool};
use deflect_core::machining::engagement::{self, ANGLES, Chip, Probes};
use deflect_core::machining::stock::{Cutter, ZMap};
use nalgebra::{Vector2, Vector3};
use proptest::prelude::*;

const C: Coefficients = Coefficients::AL7075_T6_CARBIDE;

/// A bound on the force's Lipschitz constant in the depths, by hand: per unit depth and
/// radian the edges push with at most `|(F_t, F_r)| + |F_a|` <= `sqrt((K_tc c + K_te)^2 +
/// (K_rc c + K_re)^2) + K_ac c + K_ae` (the chip thickness `c sin(phi)` at most `c`), over at
/// most pi radians, times `N / (2 pi)`: `N / 2` times that.
fn w_bound(tool: &Tool, fz: f64) -> f64 {
    let planar = ((C.k_tc * fz + C.k_te).powi(2) + (C.k_rc * fz + C.k_re).powi(2)).sqrt();
    0.5 * f64::from(tool.flutes) * (planar + C.k_ac * fz + C.k_ae)
}

fn force(
    stock: &ZMap,
    probes: &Probes,
    model: &ChipModel,
    tip: &Vector3<f64>,
    fz: f64,
) -> Vector3<f64> {
    let mut chip = Chip::default();
    engagement::read(stock, probes, tip, &Vector3::x(), false, &mut chip);
    model.wrench(&chip, fz).0
}

#[test]
fn a_thin_floor_strip_moves_the_force_by_at_most_the_bound() {
    // The case of the reproducer: a floor strip 2 um thick beside the last pass (cut to
    // z = 0 within 8 mm of y = -10 mm), the 16 mm tool at z = 0 half on it.
    let (cell, strip) = (5.0e-4, 2.0e-6);
    let tool = Tool::new(0.016, 3, 0.0).unwrap();
    let mut z = ZMap::new(
        Vector2::new(0.0, -0.03),
        Vector2::new(0.08, 0.02),
        strip,
        cell,
    )
    .unwrap();
    let flat = Cutter::Flat { radius: 0.008 };
    let _ = z
        .cut(
            &flat,
            &Vector3::new(0.0, -0.01, 0.0),
            &Vector3::new(0.08, -0.01, 0.0),
        )
        .unwrap();
    let probes = Probes::new(0.008, cell);
    let model = ChipModel::new(&C, &tool, probes.count());
    let fz = 1.0e-4;
    let w = w_bound(&tool, fz);
    // W < 210 kN/m: a micrometre of height moves the force by less than 0.21 N, and a
    // micrometre sideways across a 2 um strip on 0.5 mm cells by less than a millinewton.
    assert!(w < 2.1e5, "{w}");
    let mut largest: f64 = 0.0;
    for k in 0..400 {
        // Tool positions across the strip's edge, 45 um apart.
        let p = Vector3::new(0.04, -0.004 + 4.5e-5 * k as f64, 0.0);
        let f0 = force(&z, &probes, &model, &p, fz);
        largest = largest.max(f0.norm());
        for d in [
            Vector3::new(1e-6, 0.0, 0.0),
            Vector3::new(0.0, 1e-6, 0.0),
            Vector3::new(0.0, 4.5e-7, 0.0),
            Vector3::new(0.0, 0.0, 1e-6),
            Vector3::new(0.0, 0.0, -1e-6),
            Vector3::new(7e-7, -7e-7, 0.0),
        ] {
            let f1 = force(&z, &probes, &model, &(p + d), fz);
            let bound = w * (d.z.abs() + 2f64.sqrt() * strip / cell * d.xy().norm());
            let change = (f1 - f0).norm();
            assert!(
                change <= bound + 1e-12,
                "at {p:?} + {d:?}: |dF| {change} N > {bound} N"
            );
            if d.z == 0.0 {
                // Sideways over a 2 um strip: below a millinewton (the threshold made 25.8 N).
                assert!(change < 1e-3, "{change}");
            }
        }
    }
    // The strip pushes: a force the size of its 2 um (tenths of a newton), not zero.
    assert!(largest > 0.01 && largest < 1.0, "{largest}");
}

#[test]
fn one_depth_everywhere_is_the_closed_form() {
    let tool = Tool::new(0.016, 3, 0.3).unwrap();
    let (a, fz) = (0.004, 1.2e-4);
    let e = Engagement::slot(a, fz);
    let exact = cutting::average(&C, &tool, &e).unwrap();
    let torque = cutting::average_torque(&C, &tool, &e).unwrap();
    // With the finest probes, a 10 mm tool's on 0.5 mm cells and the coarsest.
    let probes = Probes::new(0.005, 5.0e-4);
    assert_eq!(probes.count(), 64);
    for count in [ANGLES, probes.count(), engagement::MIN_ANGLES] {
        let model = ChipModel::new(&C, &tool, count);
        let chip = Chip {
            depth: [a; ANGLES],
            count,
            ..Chip::default()
        };
        let (f, m) = model.wrench(&chip, fz);
        assert!(
            (f - exact).norm() <= 1e-9 * exact.norm(),
            "{count}: {f:?} {exact:?}"
        );
        assert!((m.z - torque).abs() <= 1e-9 * torque.abs(), "{count}");
    }
    let model = ChipModel::new(&C, &tool, ANGLES);
    let chip = Chip {
        depth: [a; ANGLES],
        ..Chip::default()
    };
    let (_, m) = model.wrench(&chip, fz);
    // The force acts halfway up the depth: m = (a / 2) z x F.
    let lever = Vector3::new(0.0, 0.0, 0.5 * a).cross(&exact);
    assert!((m.xy() - lever.xy()).norm() <= 1e-9 * lever.norm());
    // Half the angles (0..pi/2 at a, the rest 0; the hat at pi/2 carries half): the closed
    // form's up-milling force to the hat's width (half a probe step at the exit).
    let mut half = Chip::default();
    for (k, d) in half.depth.iter_mut().enumerate() {
        *d = if k <= 90 { a } else { 0.0 };
    }
    let (fh, _) = model.wrench(&half, fz);
    let step = PI / 180.0;
    let lo = cutting::average(
        &C,
        &tool,
        &Engagement {
            entry: 0.0,
            exit: PI / 2.0,
            depth: a,
            feed_per_tooth: fz,
        },
    )
    .unwrap();
    let hi = cutting::average(
        &C,
        &tool,
        &Engagement {
            entry: 0.0,
            exit: PI / 2.0 + step,
            depth: a,
            feed_per_tooth: fz,
        },
    )
    .unwrap();
    for i in 0..3 {
        let (l, h) = (lo[i].min(hi[i]), lo[i].max(hi[i]));
        assert!(
            fh[i] >= l - 1e-9 && fh[i] <= h + 1e-9,
            "{i}: {} not in [{l}, {h}]",
            fh[i]
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// Any stock (random heights on a 24 x 24 grid), any tool position on it, any change of
    /// up to 2 um: the force moves by at most the bound, `D` the largest clipped depth of any
    /// cell the probes can read.
    #[test]
    fn the_force_is_lipschitz_on_any_stock(
        heights in prop::collection::vec(-1.0e-3..3.0e-3f64, 24 * 24),
        x in 0.0105..0.0135f64, y in 0.0105..0.0135f64, zt in -1.0e-3..1.0e-3f64,
        dx in -2e-6..2e-6f64, dy in -2e-6..2e-6f64, dz in -2e-6..2e-6f64,
        angle in 0.0..core::f64::consts::TAU, fz in 0.0..2.0e-4f64,
    ) {
        let cell = 1.0e-3;
        // Every cell at its random height: a fresh map whose top is the highest, each cell
        // lowered by a flat cut at its centre narrower than the cell.
        let top = heights.iter().cloned().fold(f64::MIN, f64::max);
        let mut z = ZMap::new(Vector2::zeros(), Vector2::new(0.024, 0.024), top, cell).unwrap();
        for (k, h) in heights.iter().enumerate() {
            let c = z.center(k % 24, k / 24);
            let p = Vector3::new(c.x, c.y, *h);
            let _ = z.cut(&Cutter::Flat { radius: 1e-4 }, &p, &p).unwrap();
        }
        let tool = Tool::new(0.01, 2, 0.0).unwrap();
        let probes = Probes::new(0.005, cell);
        let model = ChipModel::new(&C, &tool, probes.count());
        let feed = Vector3::new(angle.cos(), angle.sin(), 0.0);
        let p = Vector3::new(x, y, zt);
        let d = Vector3::new(dx, dy, dz);
        let mut chip = Chip::default();
        engagement::read(&z, &probes, &p, &feed, false, &mut chip);
        let f0 = model.wrench(&chip, fz).0;
        engagement::read(&z, &probes, &(p + d), &feed, false, &mut chip);
        let f1 = model.wrench(&chip, fz).0;
        let deepest = heights.iter().fold(0.0f64, |m, h| m.max(h - zt.min(zt + dz)));
        let bound = w_bound(&tool, fz) * (dz.abs() + 2f64.sqrt() * deepest / cell * d.xy().norm());
        prop_assert!((f1 - f0).norm() <= bound * (1.0 + 1e-9) + 1e-12,
            "|dF| {} > {bound}", (f1 - f0).norm());
    }
}

/// Reports: a front crossed by twelve channels parallel to the feed is thirteen engaged arcs,
/// of which a contact keeps `MAX_ARCS`, the last running to the last engaged probe (the rest
/// merged into it, not dropped); and a stock half a micrometre above the tip reads as air in
/// the report (`MIN_DEPTH`, 1 um) while the force still feels it (no threshold in the force),
/// 1.5 um as contact.
#[test]
fn arcs_past_max_arcs_merge_into_the_last_and_min_depth_only_names_arcs() {
    use deflect_core::machining::engagement::{Contact, MAX_ARCS, MIN_DEPTH};
    let cell = 1.0e-4;
    let mut z = ZMap::new(
        Vector2::new(0.0, -0.012),
        Vector2::new(0.08, 0.012),
        0.002,
        cell,
    )
    .unwrap();
    let channel = Cutter::Flat { radius: 3.0e-4 };
    for k in 0..12 {
        let y = -0.0066 + 0.0012 * f64::from(k);
        let _ = z
            .cut(
                &channel,
                &Vector3::new(0.0, y, 0.0),
                &Vector3::new(0.08, y, 0.0),
            )
            .unwrap();
    }
    let c = engagement::contact(&z, 0.008, &Vector3::new(0.03, 0.0, 0.0), &Vector3::x());
    let Contact::Cutting { arcs, count } = c else {
        panic!("{c:?}")
    };
    assert_eq!(count, MAX_ARCS);
    for w in arcs.windows(2) {
        assert!(w[0].exit < w[1].entry, "{arcs:?}");
    }
    // The last arc runs to the front's last engaged probe: past the twelfth channel, at pi.
    assert!((arcs[MAX_ARCS - 1].exit - PI).abs() < 1e-12, "{arcs:?}");
    assert!(arcs[MAX_ARCS - 1].exit - arcs[MAX_ARCS - 1].entry > 0.5);

    let tool = Tool::new(0.016, 3, 0.0).unwrap();
    let probes = Probes::new(0.008, 5.0e-4);
    let model = ChipModel::new(&C, &tool, probes.count());
    for (top, engaged) in [(0.5 * MIN_DEPTH, false), (1.5 * MIN_DEPTH, true)] {
        let flat = ZMap::new(
            Vector2::new(0.0, -0.02),
            Vector2::new(0.08, 0.02),
            top,
            5.0e-4,
        )
        .unwrap();
        let mut chip = Chip::default();
        engagement::read(
            &flat,
            &probes,
            &Vector3::new(0.04, 0.0, 0.0),
            &Vector3::x(),
            false,
            &mut chip,
        );
        assert_eq!(chip.contact() != Contact::Air, engaged, "{top}");
        // The force of a slot `top` deep: linear in the depth, so the closed form scaled.
        let f = model.wrench(&chip, 1.0e-4).0;
        let full = cutting::average(&C, &tool, &Engagement::slot(top, 1.0e-4)).unwrap();
        assert!((f - full).norm() <= 1e-9 * full.norm(), "{f} vs {full}");
    }
}
