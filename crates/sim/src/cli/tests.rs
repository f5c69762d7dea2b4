//! The command line's ranges, defaults and checks.

use clap::{CommandFactory, Parser};

use super::*;
use deflect_sim::scenes::parallel::params;

fn parse(args: &[&str]) -> Command {
    let mut all = vec!["deflect-sim"];
    all.extend_from_slice(args);
    Cli::try_parse_from(all).unwrap().command.unwrap()
}

/// The ranges of each subcommand's flags.
fn ranged() -> [(&'static str, Vec<Range>); 5] {
    [
        ("reproduce", vec![MASS, G_LEVEL, FIXED_POINT, JOBS]),
        ("run", vec![G_LEVEL, MASS]),
        (
            "milling",
            vec![
                FEED,
                FORCE,
                CUT,
                RISE_MS,
                CYCLE_MS,
                LEAD_MS,
                ESTIMATE_ERROR,
                ID_POSES,
            ],
        ),
        ("contour", vec![STEP_MM, TARGET_FORCE, NOISE, JOBS]),
        (
            "serial",
            vec![PAYLOAD_MASS, SERIAL_G, SCALE, V_MAX, RAMP, TURN, JOBS],
        ),
    ]
}

#[test]
fn every_range_is_in_the_help_of_its_flag() {
    let mut cmd = Cli::command();
    cmd.build();
    for (sub, ranges) in ranged() {
        let sc = cmd.find_subcommand(sub).unwrap();
        for r in ranges {
            let long = r.flag.trim_start_matches("--");
            let arg = sc
                .get_arguments()
                .find(|a| a.get_long() == Some(long))
                .unwrap_or_else(|| panic!("{sub} {}", r.flag));
            let help = arg.get_help().unwrap().to_string();
            assert!(
                help.contains(&format!("Range: {}.", r.text())),
                "{sub} {}: {help}",
                r.flag
            );
        }
    }
}

#[test]
fn defaults_are_in_range() {
    ReproduceArgs::default().check().unwrap();
    for sub in [
        "reproduce",
        "static-test",
        "fit",
        "run",
        "milling",
        "contour",
        "serial",
    ] {
        parse(&[sub]).check().unwrap();
    }
    let Command::Reproduce(a) = parse(&["reproduce"]) else {
        panic!("reproduce");
    };
    let d = ReproduceArgs::default();
    assert_eq!(
        (a.mass, &a.g, a.fixed_point, a.jobs),
        (d.mass, &d.g, d.fixed_point, d.jobs)
    );
}

#[test]
fn ranges_match_the_scenes() {
    let t = deflect_sim::scenes::contour::TraceOptions::default();
    assert_eq!(
        (TARGET_FORCE.min, TARGET_FORCE.max),
        (t.contact_force, t.jam_force)
    );
    assert_eq!(
        deflect_sim::scenes::milling::MillingOptions::default().dt,
        params::DT
    );
    assert_eq!(CYCLE_MS.min, params::DT * 1e3);
}

#[test]
fn range_text_and_checks() {
    assert_eq!(CUT.text(), "[0.01, 5] s");
    assert_eq!(TARGET_FORCE.text(), "(1.5, 30) N");
    assert_eq!(JOBS.text(), "[1, 64]");
    assert!(CUT.check(0.01).is_ok() && CUT.check(5.0).is_ok());
    for v in [0.0099, 5.0001, f64::NAN, f64::INFINITY, -1.0] {
        assert_eq!(CUT.check(v).unwrap_err().code(), 2, "{v}");
    }
    assert!(TARGET_FORCE.check(1.5).is_err() && TARGET_FORCE.check(30.0).is_err());
    assert!(TARGET_FORCE.check(1.51).is_ok());
    assert_eq!(
        CUT.check(1e9).unwrap_err().message(),
        "--cut 1e9 is out of range: allowed [0.01, 5] s"
    );
    assert_eq!(
        JOBS.check_int(u64::MAX).unwrap_err().message(),
        format!("--jobs {} is out of range: allowed [1, 64]", u64::MAX)
    );
}

#[test]
fn cycle_is_a_whole_number_of_physics_steps() {
    for (v, ok) in [
        ("0.5", true),
        ("4", true),
        ("19.5", true),
        ("0.7", false),
        ("4.25", false),
    ] {
        let c = parse(&["milling", "--cycle-ms", v]);
        assert_eq!(c.check().is_ok(), ok, "{v}");
    }
}

#[test]
fn levels_are_distinct() {
    assert!(parse(&["reproduce", "--g", "5,1,3"]).check().is_ok());
    let e = parse(&["reproduce", "--g", "1,3,1"]).check().unwrap_err();
    assert_eq!(e.code(), 2);
    assert!(e.message().contains("--g 1 is given twice"), "{e:?}");
}
