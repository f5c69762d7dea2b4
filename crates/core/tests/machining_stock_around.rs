//! A stock around a program: the feed moves' bounding box grown by the margin, by hand.

use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::machining::job::Stock;

fn program(text: &str) -> deflect_core::machining::Program {
    gcode::from_str(text, &GcodeOptions::default()).unwrap()
}

#[test]
fn the_feed_moves_box_grown_by_the_margin() {
    // A plunge at the origin, a line to x = 30 mm, then a full clockwise circle of radius 10 mm
    // about (40, 0): sampled every 5 degrees from its start at 180 degrees, so its extremes
    // (x 30..50, y -10..10) are samples. A rapid far away does not count.
    let p = program("G0 X0 Y0 Z1\nG1 Z-1 F100\nG1 X30\nG2 X30 Y0 I10 J0\nG0 Z5\nG0 X500 Y500\n");
    let (lo, hi) = Stock::around(&p, 0.008).unwrap();
    let expect = [(lo.x, -0.008), (lo.y, -0.018), (hi.x, 0.058), (hi.y, 0.018)];
    for (got, want) in expect {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
}

#[test]
fn a_program_without_feed_moves_has_none() {
    let p = program("G0 X10 Y10 Z5\nG0 X20\n");
    assert!(Stock::around(&p, 0.008).is_none());
}
