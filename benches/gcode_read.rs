//! Criterion benchmark of the G-code reader: lines per second on a 3-D raster finishing
//! program of 16,389 lines (the size of a real mould program), written as a CAM system writes
//! it and as a parametric NGC program making the same moves with an O-word loop, next to
//! LinuxCNC's interpreter `rs274 -g FILE` on the same file in the same run (its documented
//! use; it prints every canonical move, so it does a little more than parse). Without `rs274`
//! on the PATH only deflect is timed. `cargo bench --bench gcode_read`.

use std::fmt::Write as _;
use std::hint::black_box;
use std::process::Command;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use deflect_core::io::gcode::{self, GcodeOptions};

/// Rows of the raster (each row: a plunge, many feed moves, a retract, a rapid).
const ROWS: usize = 105;
/// Points per row.
const POINTS: usize = 154;

/// The height of the mould surface at (x, y) [mm].
fn surface(x: f64, y: f64) -> f64 {
    -5.0 - 3.0 * (x / 17.0).sin() * (y / 23.0).cos() - 0.002 * (x - 60.0) * (y - 40.0)
}

/// The raster as a CAM post writes it: one line per point, modal G1 and F.
fn raster() -> String {
    let mut p = String::from(
        "%\n(raster finishing, ball end mill)\nG21 G90 G17 G94\nT1 M6\nS12000 M3 M8\nG0 Z10\n",
    );
    for r in 0..ROWS {
        let y = r as f64 * 0.8;
        let dir = if r % 2 == 0 { 1.0 } else { -1.0 };
        let x0 = if dir > 0.0 { 0.0 } else { 122.4 };
        let _ = writeln!(p, "G0 X{x0:.4} Y{y:.4}");
        let _ = writeln!(p, "G1 Z{:.4} F600", surface(x0, y));
        for k in 1..POINTS {
            let x = x0 + dir * k as f64 * 0.8;
            let _ = writeln!(p, "X{x:.4} Z{:.4} F2400", surface(x, y));
        }
        p.push_str("G0 Z10\n");
    }
    p.push_str("M5 M9\nM30\n%\n");
    p
}

/// The same raster as a parametric program: a while loop over the rows and the points.
fn parametric() -> String {
    let mut p = String::from("%\nG21 G90 G17 G94\nT1 M6\nS12000 M3 M8\nG0 Z10\n#1 = 0\n");
    let _ = writeln!(p, "o1 while [#1 LT {ROWS}]");
    p.push_str("  #2 = [#1 * 0.8]\n  #3 = [1 - 2 * [#1 MOD 2]]\n  #4 = [61.2 - 61.2 * #3]\n");
    p.push_str("  G0 X#4 Y#2\n  G1 Z[-5 - 3 * SIN[#4 / 17 * 57.29577951308232] * COS[#2 / 23 * 57.29577951308232] - 0.002 * [#4 - 60] * [#2 - 40]] F600\n");
    p.push_str("  #5 = 1\n");
    let _ = writeln!(p, "  o2 while [#5 LT {POINTS}]");
    p.push_str("    #6 = [#4 + #3 * #5 * 0.8]\n");
    p.push_str("    X#6 Z[-5 - 3 * SIN[#6 / 17 * 57.29577951308232] * COS[#2 / 23 * 57.29577951308232] - 0.002 * [#6 - 60] * [#2 - 40]] F2400\n");
    p.push_str(
        "    #5 = [#5 + 1]\n  o2 endwhile\n  G0 Z10\n  #1 = [#1 + 1]\no1 endwhile\nM5 M9\nM30\n%\n",
    );
    p
}

fn rs274() -> Option<String> {
    let out = Command::new("sh")
        .args(["-c", "command -v rs274"])
        .output()
        .ok()?;
    let p = String::from_utf8(out.stdout).ok()?.trim().to_string();
    (!p.is_empty()).then_some(p)
}

fn bench(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("deflect-gcode-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let options = GcodeOptions::default();
    for (name, text) in [("raster", raster()), ("parametric", parametric())] {
        let lines = text.lines().count();
        let moves = gcode::from_str(&text, &options).unwrap().moves.len();
        let file = dir.join(format!("{name}.ngc"));
        std::fs::write(&file, &text).unwrap();
        println!("{name}: {lines} lines, {moves} moves ({})", file.display());
        let mut g = c.benchmark_group(format!("gcode_read_{name}"));
        g.sample_size(20);
        // Lines per second of the CAM program; moves per second of the parametric one (its
        // 24 lines run about 80,000 times).
        g.throughput(Throughput::Elements(
            if name == "raster" { lines } else { moves } as u64,
        ));
        g.bench_function("deflect", |b| {
            b.iter(|| gcode::from_str(black_box(&text), &options).unwrap())
        });
        if let Some(rs274) = rs274() {
            g.bench_function("rs274", |b| {
                b.iter(|| {
                    let out = Command::new(&rs274)
                        .env("HOME", &dir)
                        .arg("-g")
                        .arg(&file)
                        .output()
                        .unwrap();
                    assert!(out.status.success());
                    out.stdout.len()
                })
            });
        } else {
            println!("rs274 not found: only deflect is timed");
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
