"""deflect: predict and cancel the compliant deflection of robots.

All quantities are SI (m, N, N m, rad, s, kg) unless a loader is told otherwise.
Every error raised for bad input derives from ``ValueError`` through ``DeflectError``.
"""

from ._deflect import (
    ConvergenceError,
    DeflectError,
    InputError,
    LoadError,
    SerialRobot,
    SingularError,
    __version__,
    commanded_pose,
)

__all__ = [
    "ConvergenceError",
    "DeflectError",
    "InputError",
    "LoadError",
    "SerialRobot",
    "SingularError",
    "__version__",
    "commanded_pose",
]
