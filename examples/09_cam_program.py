"""Example 9 in Python: a CAM program with two tools on the KR 300 (examples/09_cam_program.rs).

Reads a program as LinuxCNC reads it, prints its word report, maps its T1 and T2 to a 10 mm
and a 6 mm end mill with a LinuxCNC tool table, and runs the offline pass with each move cut by
the tool in the spindle.

Run: python examples/09_cam_program.py
"""

from pathlib import Path

import numpy as np

import deflect

ROOT = Path(__file__).resolve().parent.parent
RS = ROOT / "examples" / "09_cam_program.rs"
# The program and the table are the Rust example's, read from its source.
SOURCE = RS.read_text()
PROGRAM = SOURCE.split('const PROGRAM: &str = "')[1].split('";')[0]
TOOLS = SOURCE.split('const TOOLS: &str = "')[1].split('";')[0].encode().decode("unicode_escape")

program = deflect.GcodeProgram.from_text(PROGRAM, start=[0.0, 0.0, 0.02])
for word, status, count, line, meaning in program.words:
    print(f"{word:<12} {status:<9} {count:>5} {line:>5}  {meaning}")
print(f"{len(program)} moves; tools {program.tools}")

robot = deflect.SerialRobot.from_urdf(
    ROOT / "robots/kr300/kr300_r2500.urdf", ROOT / "robots/kr300/kr300_r2500_stiffness.toml", "tcp"
)
placement = np.eye(4)
placement[:3, :3] = np.diag([-1.0, -1.0, 1.0])  # pi about z
placement[:3, 3] = [2.45, 0.02, 0.92]
tools = deflect.ToolTable.from_text(TOOLS, flutes=2)
job = deflect.MachiningJob(robot, placement, stock_min=(-0.005, 0.0), stock_max=(0.075, 0.05), tools=tools)
result = job.run(program, [0.0, -0.9, 1.4, 0.0, -0.5, 0.0])
for number, diameter, *_, name in tools.tools:
    mine = result.tool == number
    force = np.linalg.norm(result.force[mine], axis=1).max()
    print(f"T{number} ({name}, {diameter * 1e3:.0f} mm): largest force {force:.1f} N")
print("path error max: uncompensated %.3f mm, compensated %.6f mm"
      % (result.path_error("uncompensated")[0] * 1e3, result.path_error("compensated")[0] * 1e3))
