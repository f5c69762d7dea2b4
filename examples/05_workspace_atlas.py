"""Example 5 (Python twin of 05_workspace_atlas.rs): where on the table, and in which posture,
is the KR 300 stiff enough to mill? A workspace atlas under the milling load of the VJM paper.

For a grid of workpiece placements on a table 0.2 m above the robot base (x 1.4..2.2 m, y
-0.6..0.6 m), the tool pointing down, the rotation about the tool axis is swept (5 degree steps,
refined) and the posture that deflects least under the 546 N milling force (Hähn and Weigold,
sec. 3: -386.1 N in x, +386.1 N in y) is kept. Prints the heat map of the best deflection, the
best placement, and what choosing the posture gains over the worst one at each placement.
On every local core; pass `executor=` (a Dask Client, deflect.RayExecutor(), a process pool) to
`deflect.atlas` to run it on a cluster.

Run: python examples/05_workspace_atlas.py   (after `pip install ./crates/py`)
"""

import pathlib

import numpy as np

import deflect

ROOT = pathlib.Path(__file__).resolve().parents[1]
robot = deflect.SerialRobot.from_urdf(
    ROOT / "robots/kr300/kr300_r2500.urdf", ROOT / "robots/kr300/kr300_r2500_stiffness.toml", "tcp"
)
SEED = np.array([0.0, -0.9, 1.4, 0.0, 1.0708, 0.0])  # rad: the milling posture of example 1
MILLING = np.array([-386.1, 386.1, 0.0, 0.0, 0.0, 0.0])  # N, N m at the TCP, base frame
xs = 1.4 + 0.1 * np.arange(9)  # m (as the Rust twin computes them)
ys = -0.6 + 0.2 * np.arange(7)  # m
X, Y = np.meshgrid(xs, ys, indexing="ij")
positions = np.c_[X.ravel(), Y.ravel(), np.full(X.size, 0.2)]

atlas = deflect.atlas(
    robot,
    positions,
    tool_axes=[0.0, 0.0, -1.0],
    wrenches=MILLING,
    angles=np.radians(np.arange(-180.0, 180.0, 5.0)),
    seeds=SEED,
)
best = atlas.best_measure.reshape(X.shape) * 1e3  # mm
gain = (atlas.worst_measure / atlas.best_measure).reshape(X.shape)

print(f"reachable placements: {atlas.reachable.sum()} of {len(positions)}")
print("best |dp| [mm] under 546 N, rows x [m], columns y [m]:")
print("  x \\ y " + " ".join(f"{y:6.2f}" for y in ys))
for x, row in zip(xs, best):
    print(f"  {x:5.2f} " + " ".join("   ---" if np.isnan(v) else f"{v:6.3f}" for v in row))
shades = " .:-=+*#%@"
lo, hi = np.nanmin(best), np.nanmax(best)
print("heat map (' ' stiffest .. '@' softest):")
for row in best:
    print("  |" + "".join(shades[int((v - lo) / (hi - lo) * (len(shades) - 1))] * 2 for v in row) + "|")
k = int(np.nanargmin(atlas.best_measure))
print(
    f"best placement: x = {positions[k, 0]:.2f} m, y = {positions[k, 1]:.2f} m: "
    f"|dp| = {atlas.best_measure[k] * 1e3:.3f} mm at {np.degrees(atlas.best_angle[k]):.2f} deg "
    f"about the tool axis (worst angle there: {atlas.worst_measure[k] * 1e3:.3f} mm)"
)
print(f"choosing the angle: worst/best {np.nanmin(gain):.2f}..{np.nanmax(gain):.2f}x, "
      f"median {np.nanmedian(gain):.2f}x")
