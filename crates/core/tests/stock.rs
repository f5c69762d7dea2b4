//! The z-map stock against hand-derived cuts: a straight slot leaves a groove of the tool's
//! width (within a cell) and of the programmed depth (exactly), the removed volume is the
//! swept area times the depth within the grid's resolution, a ramp's floor follows the tip,
//! a ball end mill leaves its circular profile.

use std::f64::consts::PI;

use deflect_core::BuildError;
use deflect_core::TickError;
use deflect_core::machining::engagement::{self, Chip, Probes};
use deflect_core::machining::stock::{
    Cutter, FOLLOW_TOLERANCE, Follower, MAX_CELLS, MAX_HELD, Step, ZMap,
};
use nalgebra::{Vector2, Vector3};

const CELL: f64 = 1.0e-4;

fn stock() -> ZMap {
    // 100 mm x 40 mm, top at z = 0, 0.1 mm cells.
    ZMap::new(Vector2::new(0.0, -0.02), Vector2::new(0.1, 0.02), 0.0, CELL).unwrap()
}

#[test]
fn a_slot_leaves_a_groove_of_the_tool_width_and_depth() {
    let mut z = stock();
    assert_eq!(z.shape(), (1000, 400));
    let (d, a, l) = (0.01, 0.002, 0.06);
    let flat = Cutter::Flat { radius: d / 2.0 };
    let above = Vector3::new(0.02, 0.0, 0.005);
    let down = Vector3::new(0.02, 0.0, -a);
    let end = Vector3::new(0.02 + l, 0.0, -a);
    let plunge = z.cut(&flat, &above, &down).unwrap();
    let slot = z.cut(&flat, &down, &end).unwrap();
    // Across the middle of the slot (x = 50 mm): the cells cut (by more than a nanometre:
    // the cells whose centre lies on the rim's band edge are cut by rounding) span D within
    // one cell, at depth a exactly.
    let i = 500;
    let cut: Vec<usize> = (0..400)
        .filter(|&j| z.height(i, j).unwrap() < -1e-9)
        .collect();
    let width = cut.len() as f64 * CELL;
    assert!(
        (width - d).abs() <= CELL * (1.0 + 1e-9),
        "groove width {width} m"
    );
    for &j in &cut {
        assert!((z.height(i, j).unwrap() + a).abs() < 1e-9);
    }
    let deepest = z.heights().iter().copied().fold(f64::INFINITY, f64::min);
    assert!((deepest + a).abs() < 1e-9, "{deepest}");
    // Volume: a (L D + pi R^2), within a times the outline's length times a cell.
    let r = d / 2.0;
    let exact = a * (l * d + PI * r * r);
    let outline = 2.0 * l + 2.0 * PI * r;
    let removed = plunge.volume + slot.volume;
    assert!(
        (removed - exact).abs() <= a * outline * CELL,
        "{removed} vs {exact}"
    );
    let total: f64 = z.heights().iter().map(|h| -h * CELL * CELL).sum();
    assert!((total - removed).abs() < 1e-15);
    // Cutting the same path again removes nothing.
    assert_eq!(z.cut(&flat, &down, &end).unwrap().cells, 0);
}

#[test]
fn a_ramp_floor_follows_the_tip_and_a_ball_leaves_its_profile() {
    // Ramp from (10, 0, 0) to (50, 0, -4) mm with a 10 mm flat mill: the cell centred at
    // (30.05, 0.05) mm is under the tool while the tip is within the half chord
    // sqrt(5^2 - 0.05^2) mm of its x, and is cut to the deepest tip height there, at the
    // far end of that stretch.
    let mut z = stock();
    let flat = Cutter::Flat { radius: 0.005 };
    let ramp = z.cut(
        &flat,
        &Vector3::new(0.01, 0.0, 0.0),
        &Vector3::new(0.05, 0.0, -0.004),
    );
    assert!(ramp.unwrap().cells > 0);
    let c = z.center(300, 200);
    assert!((c - Vector2::new(0.03005, 0.00005)).norm() < 1e-15);
    let half = (0.005f64 * 0.005 - c.y * c.y).sqrt();
    let want = -0.004 * (c.x + half - 0.01) / 0.04;
    assert!((z.height(300, 200).unwrap() - want).abs() < 1e-12);

    // A 10 mm ball along y = 0 at tip height -2 mm: the profile -2 mm + R - sqrt(R^2 - y^2).
    let mut z = stock();
    let ball = Cutter::Ball { radius: 0.005 };
    let slot = z.cut(
        &ball,
        &Vector3::new(0.02, 0.0, -0.002),
        &Vector3::new(0.08, 0.0, -0.002),
    );
    assert!(slot.unwrap().volume > 0.0);
    for j in [200, 210, 220, 230, 240, 245] {
        let y = z.center(500, j).y;
        let want = (-0.002 + 0.005 - (0.005f64 * 0.005 - y * y).sqrt()).min(0.0);
        assert!((z.height(500, j).unwrap() - want).abs() < 1e-12, "y = {y}");
    }
    // A ball ramp: the convex minimum inside the move.
    let mut z = stock();
    let ramp = z.cut(
        &ball,
        &Vector3::new(0.02, 0.0, 0.0),
        &Vector3::new(0.08, 0.0, -0.006),
    );
    assert!(ramp.unwrap().cells > 0);
    let (i, j) = (500, 230);
    let c = z.center(i, j);
    // By brute force over the move.
    let brute = (0..=200_000)
        .map(|k| {
            let t = f64::from(k) / 200_000.0;
            let p = Vector3::new(0.02 + 0.06 * t, 0.0, -0.006 * t);
            let d2 = (p.xy() - c).norm_squared();
            if d2 <= 0.005 * 0.005 {
                p.z + 0.005 - (0.005 * 0.005 - d2).sqrt()
            } else {
                f64::INFINITY
            }
        })
        .fold(f64::INFINITY, f64::min);
    assert!((z.height(i, j).unwrap() - brute.min(0.0)).abs() < 1e-9);
}

#[test]
fn budgets_and_bad_inputs_are_typed_errors() {
    let big = ZMap::new(Vector2::zeros(), Vector2::new(10.0, 10.0), 0.0, 1e-4);
    assert!(matches!(
        big,
        Err(BuildError::Budget { budget: "MAX_CELLS", limit, .. }) if limit == MAX_CELLS
    ));
    assert!(matches!(
        ZMap::new(Vector2::zeros(), Vector2::new(1.0, 1.0), 0.0, 0.0),
        Err(BuildError::InvalidParameter {
            what: "cell size",
            ..
        })
    ));
    assert!(matches!(
        ZMap::new(Vector2::zeros(), Vector2::new(-1.0, 1.0), 0.0, 1e-3),
        Err(BuildError::InvalidParameter {
            what: "stock x extent",
            ..
        })
    ));
    assert!(matches!(
        ZMap::new(
            Vector2::new(f64::NAN, 0.0),
            Vector2::new(1.0, 1.0),
            0.0,
            1e-3
        ),
        Err(BuildError::InvalidParameter { .. })
    ));
    let mut z = stock();
    let flat = Cutter::Flat { radius: 0.005 };
    assert!(matches!(
        z.cut(&flat, &Vector3::new(f64::NAN, 0.0, 0.0), &Vector3::zeros()),
        Err(TickError::NonFinite { .. })
    ));
    assert!(matches!(
        z.cut(
            &Cutter::Ball { radius: -1.0 },
            &Vector3::zeros(),
            &Vector3::x()
        ),
        Err(TickError::InvalidArgument { .. })
    ));
    // A move outside the stock cuts nothing.
    let far = z.cut(
        &flat,
        &Vector3::new(1.0, 1.0, -1.0),
        &Vector3::new(2.0, 1.0, -1.0),
    );
    assert_eq!(far.unwrap().cells, 0);
    assert!(z.height(1000, 0).is_none() && z.height(0, 400).is_none());
}

/// A followed tool cuts what the plain sweep cuts, within `FOLLOW_TOLERANCE`: random walks
/// of a flat and a ball end mill (steps up to a cell, nanometre wobble and real descents in
/// z, turns, stops, tool changes) on two copies of a stock.
#[test]
fn a_followed_tool_cuts_what_the_sweep_cuts() {
    let mut rnd = {
        let mut state = 0x9e3779b97f4a7c15u64;
        move |lo: f64, hi: f64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
        }
    };
    for cutter in [
        Cutter::Flat { radius: 0.004 },
        Cutter::Ball { radius: 0.003 },
    ] {
        let mut exact = ZMap::new(Vector2::zeros(), Vector2::new(0.04, 0.04), 0.0, 5.0e-4).unwrap();
        let mut followed = exact.clone();
        let mut follower = Follower::new();
        let mut p = Vector3::new(0.02, 0.02, -0.001);
        let mut last = p;
        let mut heading: f64 = 0.0;
        for k in 0..3000 {
            heading += rnd(-0.3, 0.3);
            let step = if k % 97 == 0 { 0.0 } else { rnd(0.0, 6.0e-4) };
            let dz = match k % 5 {
                0 => rnd(-3.0e-6, 3.0e-6),
                1 => rnd(-2.0e-9, 2.0e-9),
                _ => rnd(-1.0e-10, 1.0e-10),
            };
            p += Vector3::new(heading.cos() * step, heading.sin() * step, dz);
            p.x = p.x.clamp(0.002, 0.038);
            p.y = p.y.clamp(0.002, 0.038);
            p.z = p.z.clamp(-0.003, 0.0);
            // A tool change now and then: the follower sweeps the whole footprint again.
            let c = if k % 500 == 250 {
                Cutter::Flat { radius: 0.002 }
            } else {
                cutter
            };
            let _ = exact.cut(&c, &last, &p).unwrap();
            let _ = follower.cut_to(&mut followed, &c, &p).unwrap();
            last = p;
        }
        let worst = exact
            .heights()
            .iter()
            .zip(followed.heights())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f64, f64::max);
        assert!(worst <= FOLLOW_TOLERANCE, "{cutter:?}: {worst:e}");
    }
}

/// A tool held back along lines: the held stock equals, cell for cell, a stock cut by
/// `ZMap::cut` along the moves the follower reports (from the last tip cut to the tip of each
/// `Restart` or `Cut`, and to the last tip at the end); a second follower told the same steps
/// (`step_to`) cuts a copy exactly the same; holds stay shorter than a cell and at most
/// `MAX_HELD` tips; and wherever `settle` keeps the move held, the chip read from the held
/// stock equals the chip read after cutting it (to the bit).
#[test]
fn a_held_tool_cuts_its_lines_as_single_moves_and_reads_never_see_the_difference() {
    let cell = 5.0e-4;
    for cutter in [
        Cutter::Flat { radius: 0.004 },
        Cutter::Ball { radius: 0.003 },
    ] {
        let r = cutter.radius();
        let mut held = ZMap::new(Vector2::zeros(), Vector2::new(0.06, 0.06), 0.0, cell).unwrap();
        let mut mirror = held.clone();
        let mut exact = held.clone();
        let (mut follower, mut other) = (Follower::new(), Follower::new());
        let probes = Probes::new(r, cell);
        let (mut chip_held, mut chip_cut) = (Chip::default(), Chip::default());
        let mut last_cut: Option<Vector3<f64>> = None;
        let mut tips: Vec<Vector3<f64>> = Vec::new();
        let (mut holds, mut settled_reads) = (0, 0);
        // Lines of a square spiral, sloped, sampled at 20-140 um (a cell is 500 um).
        let mut p = Vector3::new(0.03, 0.03, -0.0005);
        let mut k = 0usize;
        for (leg, heading) in [0.0f64, 90.0, 180.0, 270.0, 0.0, 90.0, 180.0, 270.0]
            .iter()
            .enumerate()
        {
            let dir = Vector3::new(heading.to_radians().cos(), heading.to_radians().sin(), 0.0);
            let step = 2.0e-5 + 2.0e-5 * (leg % 7) as f64;
            let length = 0.004 + 0.002 * leg as f64;
            let dz = if leg % 2 == 0 { -2.0e-6 } else { 1.0e-6 };
            let n = (length / step) as usize;
            for _ in 0..n {
                p += dir * step + Vector3::new(0.0, 0.0, dz);
                k += 1;
                // Before the read: settle; if it kept the move held, the read must not see it.
                let before = follower.held();
                let _ = follower.settle(&mut held, &p, &dir).unwrap();
                let _ = other.settle(&mut mirror, &p, &dir).unwrap();
                if before > 0 && follower.held() == 0 {
                    cut_held(&mut exact, &cutter, &mut last_cut, &mut tips);
                } else if before > 0 {
                    settled_reads += 1;
                    let mut flushed = held.clone();
                    let mut f = follower;
                    let _ = f.flush(&mut flushed).unwrap();
                    engagement::read(&held, &probes, &p, &dir, false, &mut chip_held);
                    engagement::read(&flushed, &probes, &p, &dir, false, &mut chip_cut);
                    assert_eq!(chip_held, chip_cut, "{cutter:?}: sample {k}");
                }
                let (_, step_taken) = follower.hold_to(&mut held, &cutter, &p).unwrap();
                let _ = other.step_to(&mut mirror, &cutter, &p, step_taken).unwrap();
                match step_taken {
                    Step::Hold => {
                        holds += 1;
                        tips.push(p);
                    }
                    Step::Restart => {
                        cut_held(&mut exact, &cutter, &mut last_cut, &mut tips);
                        tips.push(p);
                    }
                    Step::Cut => {
                        cut_held(&mut exact, &cutter, &mut last_cut, &mut tips);
                        let _ = exact.cut(&cutter, &last_cut.unwrap_or(p), &p).unwrap();
                        last_cut = Some(p);
                    }
                }
                assert_eq!(follower.held(), tips.len());
                assert!(tips.len() <= MAX_HELD);
                if let (Some(from), Some(to)) = (last_cut, tips.last()) {
                    assert!((to.xy() - from.xy()).norm() < cell);
                }
            }
        }
        cut_held(&mut exact, &cutter, &mut last_cut, &mut tips);
        let _ = follower.flush(&mut held).unwrap();
        let _ = other.flush(&mut mirror).unwrap();
        assert_eq!(held.heights(), mirror.heights(), "{cutter:?}");
        let worst = exact
            .heights()
            .iter()
            .zip(held.heights())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f64, f64::max);
        // The flat end mill's crescents leave cells within the follow tolerance.
        assert!(worst <= FOLLOW_TOLERANCE, "{cutter:?}: {worst:e}");
        // Most samples are held, and most reads happen with a move held.
        assert!(holds * 10 > k * 8, "{cutter:?}: {holds} of {k}");
        assert!(
            settled_reads * 10 > k * 7,
            "{cutter:?}: {settled_reads} of {k}"
        );
    }
}

/// Cuts the held tips of the test above as one move from the last tip cut.
fn cut_held(
    exact: &mut ZMap,
    cutter: &Cutter,
    last_cut: &mut Option<Vector3<f64>>,
    tips: &mut Vec<Vector3<f64>>,
) {
    if let (Some(from), Some(&to)) = (*last_cut, tips.last()) {
        let _ = exact.cut(cutter, &from, &to).unwrap();
        *last_cut = Some(to);
    }
    tips.clear();
}
