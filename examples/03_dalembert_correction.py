"""Example 3 (Python twin of 03_dalembert_correction.rs): the paper's 150 mm y-line at 1..5 g
corrected at 2 kHz with D'Alembert forces (m* = 5 kg) and the OC compliance map."""

import pathlib

import numpy as np

import deflect

ROOT = pathlib.Path(__file__).resolve().parents[1]
cmap = deflect.ComplianceMap.from_csv(ROOT / "data/paksoy2025_compliance_oc.csv", out_of_grid="clamp")
corrector = deflect.DalembertCorrector(cmap, deflect.ParallelRobot2(), mass=5.0, iterations=3, tolerance=1e-12)
print("g   duration [ms]  ticks  max |correction| [mm]  max |F_D| [N]  clamped ticks")
for g in range(1, 6):
    traj = deflect.plan_line([0.222132, -0.075], [0.222132, 0.075], *deflect.paper_limits(g))
    out = corrector.correct(traj)  # GIL released, one row per 2 kHz tick
    corr = np.linalg.norm(out.commanded - out.desired, axis=1).max() * 1e3
    force = np.linalg.norm(out.force, axis=1).max()
    print(f"{g}   {traj.duration * 1e3:13.1f}  {len(traj):5d}  {corr:21.4f}  {force:13.1f}  {len(out.flagged_ticks):13d}")
