"""Example 2 (Python twin of 02_compliance_map.rs): the paper's compliance maps queried
between nodes, bilinear vs bicubic, and leave-one-node-out cross-validation."""

import pathlib

import numpy as np

import deflect

ROOT = pathlib.Path(__file__).resolve().parents[1]
for name, file in [("OC", "paksoy2025_compliance_oc.csv"), ("NC", "paksoy2025_compliance_nc.csv")]:
    # Force unit of the published fit: newtons is our reading (see data/README.md).
    cmap = deflect.ComplianceMap.from_csv(ROOT / "data" / file, force_unit="N", length_unit="mm")
    force = np.array([0.0, -5.0 * 5.0 * 9.81])  # 5 g on m* = 5 kg, along y
    for p in ([0.222132, 0.0], [0.2, 0.02]):
        for interp in ("bilinear", "bicubic"):
            d = cmap.displacement(np.array(p), force, interpolation=interp)
            print(f"{name} at {np.round(np.array(p) * 1e3, 1)} mm, {interp}: d = {np.round(d * 1e3, 4)} mm")
    loads = np.array([[k * 49.05, 0.0] for k in range(1, 6)] + [[0.0, k * 49.05] for k in range(1, 6)])
    cv = cmap.cross_validate(loads, axis="y")
    print(
        f"{name} leave-one-node-out RMS: bilinear {cv['rms_bilinear'] * 1e6:.2f} um, "
        f"bicubic {cv['rms_bicubic'] * 1e6:.2f} um -> {cv['better']}\n"
    )
