//! Example 2: the compliance map of the paper's over-constrained parallel robot (Tables II/III
//! of Paksoy et al.), queried between grid nodes, and the two interpolations compared by
//! leave-one-node-out cross-validation.
//!
//! Run: `cargo run --release --example 02_compliance_map`

use deflect_core::compliance_map::{HoldOutAxis, Interpolation, QueryOptions, leave_one_node_out};
use deflect_core::io::map_csv;
use deflect_core::units::{ForceUnit, LengthUnit};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = env!("CARGO_MANIFEST_DIR");
    for (name, file) in [
        ("OC", "paksoy2025_compliance_oc.csv"),
        ("NC", "paksoy2025_compliance_nc.csv"),
    ] {
        // The paper does not say in which unit its lines were fitted; newtons is our reading
        // (see data/README.md), passed explicitly.
        let path = format!("{root}/data/{file}");
        let map = map_csv::from_path(path, ForceUnit::Newton, LengthUnit::Millimetre)?;
        let mut d = [0.0; 2];
        // 5 g on the tuned 5 kg mass along y, at the workspace centre and between nodes.
        let force = [0.0, -5.0 * 5.0 * 9.81];
        for p in [[0.222132, 0.0], [0.2, 0.02]] {
            for interpolation in [Interpolation::Bilinear, Interpolation::Bicubic] {
                let opts = QueryOptions {
                    interpolation,
                    ..QueryOptions::default()
                };
                map.displacement_with(p, &force, &mut d, opts)?;
                println!(
                    "{name} at ({:.1}, {:.1}) mm, F = (0, {:.0}) N, {interpolation:?}: dx {:+.4} mm, dy {:+.4} mm",
                    p[0] * 1e3,
                    p[1] * 1e3,
                    force[1],
                    d[0] * 1e3,
                    d[1] * 1e3
                );
            }
        }
        // The static tests' loads: 5..25 kgf along x, then along y.
        let forces: Vec<f64> = (1..=5)
            .flat_map(|k| [k as f64 * 49.05, 0.0])
            .chain((1..=5).flat_map(|k| [0.0, k as f64 * 49.05]))
            .collect();
        let cv = leave_one_node_out(&map, &forces, HoldOutAxis::Y)?;
        println!(
            "{name} leave-one-node-out RMS: bilinear {:.2} um, bicubic {:.2} um -> {:?} predicts held-out nodes better\n",
            cv.rms_bilinear * 1e6,
            cv.rms_bicubic * 1e6,
            cv.better()
        );
    }
    Ok(())
}
