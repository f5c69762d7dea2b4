"""deflect: predict and cancel the compliant deflection of robots.

All quantities are SI (m, N, N m, rad, s, kg) unless a loader is told otherwise.
Every error raised for bad input derives from ``ValueError`` through ``DeflectError``.
"""

from ._deflect import (
    ComplianceMap,
    ConvergenceError,
    CorrectedPath,
    DalembertCorrector,
    DeflectError,
    InputError,
    LoadError,
    ParallelRobot2,
    SerialRobot,
    SingularError,
    Trajectory,
    __version__,
    commanded_pose,
    paper_limits,
    plan_line,
    plan_polyline,
)

__all__ = [
    "ComplianceMap",
    "ConvergenceError",
    "CorrectedPath",
    "DalembertCorrector",
    "DeflectError",
    "InputError",
    "LoadError",
    "ParallelRobot2",
    "SerialRobot",
    "SingularError",
    "Trajectory",
    "__version__",
    "commanded_pose",
    "paper_limits",
    "plan_line",
    "plan_polyline",
]
