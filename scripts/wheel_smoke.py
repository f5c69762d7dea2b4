"""Smoke test of the built wheel in a fresh venv (run by scripts/test-all.sh): the distribution
`deflect-robotics` installs, imports as `deflect`, carries its metadata and computes the KR 300's
deflection under 750 N (1.693 mm along x, README example 1)."""

import importlib.metadata as md
import pathlib
import sys

import numpy as np

import deflect

repo = pathlib.Path(__file__).resolve().parents[1]
meta = md.metadata("deflect-robotics")
assert meta["License"] == "MIT OR Apache-2.0", meta["License"]
assert "numpy" in " ".join(md.requires("deflect-robotics") or []), md.requires("deflect-robotics")
# The wheel's module, not the checkout's sources.
assert "site-packages" in deflect.__file__, deflect.__file__
robot = deflect.SerialRobot.from_urdf(
    repo / "robots/kr300/kr300_r2500.urdf", repo / "robots/kr300/kr300_r2500_stiffness.toml", "tcp"
)
d = robot.deflection([0.0, -0.9, 1.4, 0.0, 1.0708, 0.0], [750, 0, 0, 0, 0, 0])
assert abs(d[0] - 1.693e-3) < 1e-5, d
print(f"wheel smoke test: deflect-robotics {md.version('deflect-robotics')} on Python "
      f"{sys.version_info.major}.{sys.version_info.minor}, dx = {d[0] * 1e3:.3f} mm")
