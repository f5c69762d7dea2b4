//! The mechanistic end-milling force model against the closed forms of the linear edge-force
//! model derived by hand (Altintas, "Manufacturing Automation", 2nd ed., 2012, ch. 2): the
//! per-revolution averages of slotting and of half immersion, up and down, the instantaneous
//! force as the sum over the edges in contact, the edge forces alone at zero feed.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use deflect_core::machining::cutting::{self, Coefficients, Engagement, Tool};
use deflect_core::{BuildError, TickError};
use nalgebra::Vector3;

const K: Coefficients = Coefficients::AL7075_T6_CARBIDE;

fn tool() -> Tool {
    // The paper's 16 mm three-flute end mill (Hähn and Weigold, sec. 3), straight flutes.
    Tool::new(0.016, 3, 0.0).unwrap()
}

fn rel(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

#[test]
fn slotting_averages_are_the_textbook_closed_forms() {
    let (n, a, c) = (3.0, 0.002, 0.1e-3);
    let got = cutting::average(&K, &tool(), &Engagement::slot(a, c)).unwrap();
    let want = Vector3::new(
        -n * a * K.k_rc * c / 4.0 - n * a * K.k_re / PI,
        n * a * K.k_tc * c / 4.0 + n * a * K.k_te / PI,
        n * a * K.k_ac * c / PI + n * a * K.k_ae / 2.0,
    );
    assert!(rel(&got, &want) < 1e-9, "{got} vs {want}");
    // The paper's conditions (25 mm/s at 13,000 rpm, 3 flutes: f_z = 38.5 um) in a 2 mm
    // deep slot: 44 N + 53 N (cutting + edge) = 97 N normal to the feed, 10 N + 51 N = 61 N
    // against it, by hand from the coefficients.
    let fz = 0.025 / (13000.0 / 60.0) / 3.0;
    let f = cutting::average(&K, &tool(), &Engagement::slot(0.002, fz)).unwrap();
    assert!((f.y - 97.2).abs() < 0.1 && (f.x + 60.5).abs() < 0.1, "{f}");
}

#[test]
fn half_immersion_averages_up_and_down_are_the_closed_forms() {
    let (n, a, c, d) = (3.0, 0.003, 0.08e-3, 0.016);
    let k = n * a / TAU;
    let up = Engagement::up_milling(d / 2.0, d, a, c);
    let down = Engagement::down_milling(d / 2.0, d, a, c);
    assert!((up.exit - FRAC_PI_2).abs() < 1e-15 && (down.entry - FRAC_PI_2).abs() < 1e-15);
    // Up milling, 0..pi/2.
    let want_up = Vector3::new(
        k * (c / 4.0 * (-2.0 * K.k_tc - PI * K.k_rc) - K.k_te - K.k_re),
        k * (c / 4.0 * (PI * K.k_tc - 2.0 * K.k_rc) + K.k_te - K.k_re),
        k * (K.k_ac * c + K.k_ae * FRAC_PI_2),
    );
    // Down milling, pi/2..pi.
    let want_down = Vector3::new(
        k * (c / 4.0 * (2.0 * K.k_tc - PI * K.k_rc) + K.k_te - K.k_re),
        k * (c / 4.0 * (PI * K.k_tc + 2.0 * K.k_rc) + K.k_te + K.k_re),
        k * (K.k_ac * c + K.k_ae * FRAC_PI_2),
    );
    let got_up = cutting::average(&K, &tool(), &up).unwrap();
    let got_down = cutting::average(&K, &tool(), &down).unwrap();
    assert!(rel(&got_up, &want_up) < 1e-9, "{got_up} vs {want_up}");
    assert!(
        rel(&got_down, &want_down) < 1e-9,
        "{got_down} vs {want_down}"
    );
    // Up plus down is the slot.
    let slot = cutting::average(&K, &tool(), &Engagement::slot(a, c)).unwrap();
    assert!(rel(&(got_up + got_down), &slot) < 1e-12);
}

#[test]
fn zero_feed_leaves_the_edge_forces_alone() {
    let (n, a) = (3.0, 0.002);
    let got = cutting::average(&K, &tool(), &Engagement::slot(a, 0.0)).unwrap();
    let want = Vector3::new(
        -n * a * K.k_re / PI,
        n * a * K.k_te / PI,
        n * a * K.k_ae / 2.0,
    );
    assert!(rel(&got, &want) < 1e-9, "{got} vs {want}");
    // And instantaneously: one edge at phi = pi/2 in a slot (the others out at 210, 330 deg).
    let f = cutting::force(&K, &tool(), &Engagement::slot(a, 0.0), FRAC_PI_2, 1).unwrap();
    let want = Vector3::new(-K.k_re * a, K.k_te * a, K.k_ae * a);
    assert!(rel(&f, &want) < 1e-12, "{f} vs {want}");
}

#[test]
fn the_instantaneous_force_is_the_sum_over_the_edges_in_contact() {
    let (a, c) = (0.002, 0.1e-3);
    let e = Engagement::slot(a, c);
    for angle in [0.3, 1.0, 2.5, 4.0, 6.0] {
        let mut want = Vector3::zeros();
        for j in 0..3 {
            let phi = (angle + f64::from(j) * TAU / 3.0) % TAU;
            if phi <= PI {
                let h = c * phi.sin();
                let ft = K.k_tc * a * h + K.k_te * a;
                let fr = K.k_rc * a * h + K.k_re * a;
                let fa = K.k_ac * a * h + K.k_ae * a;
                want += Vector3::new(
                    -ft * phi.cos() - fr * phi.sin(),
                    ft * phi.sin() - fr * phi.cos(),
                    fa,
                );
            }
        }
        let got = cutting::force(&K, &tool(), &e, angle, 1).unwrap();
        assert!(
            (got - want).norm() <= 1e-12 * want.norm(),
            "{angle}: {got} vs {want}"
        );
    }
}

#[test]
fn the_average_of_the_instantaneous_force_with_a_helix_is_the_closed_form() {
    // A 30 degree helix spreads each edge over the depth; per revolution the mean is unchanged.
    let helical = Tool::new(0.016, 3, 30f64.to_radians()).unwrap();
    let e = Engagement::down_milling(0.004, 0.016, 0.006, 0.05e-3);
    let steps = 7200;
    let mut sum = Vector3::zeros();
    for k in 0..steps {
        let angle = TAU * (f64::from(k) + 0.5) / f64::from(steps);
        sum += cutting::force(&K, &helical, &e, angle, 32).unwrap();
    }
    let mean = sum / f64::from(steps);
    let closed = cutting::average(&K, &helical, &e).unwrap();
    assert!(rel(&mean, &closed) < 2e-3, "{mean} vs {closed}");
    // The helix smooths the force: its peak over a revolution is lower than straight flutes'.
    let peak = |t: &Tool| {
        (0..720)
            .map(|k| {
                let angle = TAU * f64::from(k) / 720.0;
                cutting::force(&K, t, &e, angle, 32).unwrap().norm()
            })
            .fold(0.0, f64::max)
    };
    assert!(peak(&helical) < peak(&Tool::new(0.016, 3, 0.0).unwrap()));
}

#[test]
fn bad_tools_coefficients_and_engagements_are_typed_errors() {
    assert!(matches!(
        Tool::new(0.0, 3, 0.0),
        Err(BuildError::InvalidParameter {
            what: "tool diameter",
            ..
        })
    ));
    assert!(matches!(
        Tool::new(0.016, 0, 0.0),
        Err(BuildError::InvalidParameter { what: "flutes", .. })
    ));
    assert!(matches!(
        Tool::new(0.016, 3, 1.2),
        Err(BuildError::InvalidParameter {
            what: "helix angle",
            ..
        })
    ));
    assert!(matches!(
        Coefficients::new(1.0, -1.0, 0.0, 0.0, 0.0, 0.0),
        Err(BuildError::InvalidParameter { what: "k_rc", .. })
    ));
    let t = tool();
    for e in [
        Engagement {
            entry: 1.0,
            exit: 1.0,
            depth: 0.001,
            feed_per_tooth: 1e-4,
        },
        Engagement {
            entry: 0.0,
            exit: 4.0,
            depth: 0.001,
            feed_per_tooth: 1e-4,
        },
        Engagement::slot(-0.001, 1e-4),
        Engagement::slot(0.001, 0.1),
    ] {
        assert!(matches!(
            cutting::average(&K, &t, &e),
            Err(TickError::InvalidArgument { .. })
        ));
    }
    assert!(matches!(
        cutting::average(&K, &t, &Engagement::slot(f64::NAN, 1e-4)),
        Err(TickError::NonFinite { .. })
    ));
    let e = Engagement::slot(0.001, 1e-4);
    assert!(matches!(
        cutting::force(&K, &t, &e, 0.0, 0),
        Err(TickError::InvalidArgument { .. })
    ));
    assert!(matches!(
        cutting::force(&K, &t, &e, f64::INFINITY, 1),
        Err(TickError::NonFinite { .. })
    ));
}

#[test]
fn the_tool_frame_has_x_along_the_feed_and_z_along_the_axis() {
    let r = cutting::tool_frame(&Vector3::z(), &Vector3::new(2.0, 0.0, 0.5)).unwrap();
    assert!((r.matrix() - nalgebra::Matrix3::identity()).norm() < 1e-15);
    // A tool pointing along base -x (axis +x from tip to spindle... here -x), feed along +y.
    let r = cutting::tool_frame(&-Vector3::x(), &Vector3::y()).unwrap();
    assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
    assert!((r * Vector3::z() + Vector3::x()).norm() < 1e-15);
    assert!((r * Vector3::y() - (-Vector3::x()).cross(&Vector3::y())).norm() < 1e-15);
    assert!(cutting::tool_frame(&Vector3::z(), &Vector3::z()).is_none());
    assert!(cutting::tool_frame(&Vector3::zeros(), &Vector3::x()).is_none());
}

/// The mean cutting torque by hand: each edge's tangential force `(K_tc c sin(phi) + K_te) a`
/// acts at the radius, so over a revolution `N / (2 pi) int R (K_tc c sin + K_te) a dphi`:
/// for a slot `N R a (K_tc c / pi + K_te / 2)`, for the down-milling quarter (pi/2..pi)
/// `N R a (K_tc c + K_te pi / 2) / (2 pi)`. Numbers typed from the coefficients, not from
/// the code.
#[test]
fn the_mean_cutting_torque_is_the_hand_integral() {
    let c = Coefficients::AL7075_T6_CARBIDE;
    let tool = Tool::new(0.016, 3, 0.0).unwrap();
    let (a, fz) = (0.002, 1.0e-4);
    // 4.8e-5 m^2 * (76,701 / pi + 13,850) N/m = 4.8e-5 * 38,264.9 = 1.8367 N m
    let slot = 3.0 * 0.008 * 0.002 * (767.01e6 * 1.0e-4 / std::f64::consts::PI + 27.7e3 / 2.0);
    let got = cutting::average_torque(&c, &tool, &Engagement::slot(a, fz)).unwrap();
    assert!((got - slot).abs() <= 1e-12 * slot, "{got} vs {slot}");
    assert!((slot - 1.8367).abs() < 1e-4, "{slot}");
    let quarter = 3.0 * 0.008 * 0.002 * (767.01e6 * 1.0e-4 + 27.7e3 * std::f64::consts::FRAC_PI_2)
        / (2.0 * std::f64::consts::PI);
    let e = Engagement {
        entry: std::f64::consts::FRAC_PI_2,
        exit: std::f64::consts::PI,
        depth: a,
        feed_per_tooth: fz,
    };
    let got = cutting::average_torque(&c, &tool, &e).unwrap();
    assert!(
        (got - quarter).abs() <= 1e-12 * quarter,
        "{got} vs {quarter}"
    );
}

/// The helix lag by hand: with a 30 degree helix, the edge at height z trails its tip by
/// `2 tan(30 deg) z / D`; cut into two discs, the force is the straight-flute edge force of
/// each disc's depth at its own lagged immersion, summed (one flute, so that one edge is in
/// contact: no pitch to add).
#[test]
fn a_helical_edge_trails_its_tip_by_the_lag_of_each_disc() {
    let helical = Tool::new(0.016, 1, 30f64.to_radians()).unwrap();
    let (a, c) = (0.004, 0.1e-3);
    let e = Engagement::slot(a, c);
    let dz = a / 2.0;
    for angle in [0.9, 1.6, 2.8] {
        let mut want = Vector3::zeros();
        for k in 0..2 {
            let z = (f64::from(k) + 0.5) * dz;
            // tan(30 deg) = 1 / sqrt(3); D = 16 mm.
            let lag = 2.0 * z / (3f64.sqrt() * 0.016);
            let phi = angle - lag;
            if (0.0..=PI).contains(&phi) {
                let h = c * phi.sin();
                let ft = (K.k_tc * h + K.k_te) * dz;
                let fr = (K.k_rc * h + K.k_re) * dz;
                let fa = (K.k_ac * h + K.k_ae) * dz;
                want += Vector3::new(
                    -ft * phi.cos() - fr * phi.sin(),
                    ft * phi.sin() - fr * phi.cos(),
                    fa,
                );
            }
        }
        let got = cutting::force(&K, &helical, &e, angle, 2).unwrap();
        assert!(
            (got - want).norm() <= 1e-12 * want.norm(),
            "{angle}: {got} vs {want}"
        );
    }
}

/// Quarter immersion by hand: a radial width of D/4 engages up milling over
/// `0 .. acos(1/2) = pi/3` and down milling over `2 pi/3 .. pi`; the mean force is the force
/// law's antiderivative (`int sin cos = sin^2/2`, `int sin^2 = phi/2 - sin(2 phi)/4`) between
/// those angles, times `N a / (2 pi)`, written out here from the law, not from the code.
#[test]
fn quarter_immersion_up_and_down_are_the_antiderivative_between_their_angles() {
    let (n, a, c, d) = (3.0, 0.003, 0.08e-3, 0.016);
    let antiderivative = |p: f64| {
        let (s, co) = p.sin_cos();
        let s2 = p / 2.0 - (2.0 * p).sin() / 4.0;
        Vector3::new(
            -K.k_tc * c * s * s / 2.0 - K.k_te * s - K.k_rc * c * s2 + K.k_re * co,
            K.k_tc * c * s2 - K.k_te * co - K.k_rc * c * s * s / 2.0 - K.k_re * s,
            -K.k_ac * c * co + K.k_ae * p,
        ) * (n * a / TAU)
    };
    let up = Engagement::up_milling(d / 4.0, d, a, c);
    let down = Engagement::down_milling(d / 4.0, d, a, c);
    assert!(up.entry == 0.0 && (up.exit - PI / 3.0).abs() < 1e-15);
    assert!((down.entry - 2.0 * PI / 3.0).abs() < 1e-15 && down.exit == PI);
    for (e, from, to) in [(up, 0.0, PI / 3.0), (down, 2.0 * PI / 3.0, PI)] {
        let want = antiderivative(to) - antiderivative(from);
        let got = cutting::average(&K, &tool(), &e).unwrap();
        assert!(rel(&got, &want) < 1e-12, "{got} vs {want}");
    }
}
