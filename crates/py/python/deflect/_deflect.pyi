"""Type stubs of the compiled extension ``deflect._deflect``."""

from os import PathLike
from typing import List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]
StrPath = Union[str, PathLike]

class DeflectError(ValueError): ...
class LoadError(DeflectError): ...
class InputError(DeflectError): ...
class SingularError(DeflectError): ...
class ConvergenceError(DeflectError): ...

class SerialRobot:
    """A serial robot with virtual joints (VJM paper, Eq. 1-9). SI units, base frame."""

    @staticmethod
    def from_urdf(
        urdf_path: StrPath, stiffness_path: StrPath, tip_link: str, base_link: Optional[str] = None
    ) -> "SerialRobot": ...
    @staticmethod
    def from_strings(
        urdf: str, stiffness: str, tip_link: str, base_link: Optional[str] = None
    ) -> "SerialRobot": ...
    @property
    def dof(self) -> int: ...
    @property
    def joint_names(self) -> List[str]: ...
    @property
    def joint_limits(self) -> List[Tuple[float, float]]: ...
    @property
    def spring_names(self) -> List[str]: ...
    @property
    def base_link(self) -> str: ...
    @property
    def tip_link(self) -> str: ...
    def forward(self, q: FloatArray) -> FloatArray:
        """Rigid TCP pose, (4, 4)."""
    def deflection(self, q: FloatArray, wrench: FloatArray) -> FloatArray:
        """[dx, dy, dz, rx, ry, rz] [m, rad] under wrench [Fx, Fy, Fz, Mx, My, Mz] [N, N m]."""
    def spring_angles(self, q: FloatArray, wrench: FloatArray) -> FloatArray:
        """(n_springs, 3) elastic angles [rad] (Eq. 7)."""
    def compliance(self, q: FloatArray) -> FloatArray:
        """(6, 6) Cartesian compliance of the linearized model."""
    def joint_jacobian(self, q: FloatArray) -> FloatArray:
        """(6, dof) actuated-joint Jacobian, rows [v; w]."""
    def joint_correction(
        self, q: FloatArray, wrench: FloatArray, max_iterations: int = 10, tolerance: float = 1e-12
    ) -> FloatArray:
        """(dof,) axis-specific correction."""
    def deflection_batch(self, Q: FloatArray, W: FloatArray) -> FloatArray:
        """(N, dof), (N, 6) -> (N, 6); releases the GIL."""

def commanded_pose(target: FloatArray, deflection: FloatArray) -> FloatArray:
    """(4, 4) pose to command so that the deflected TCP lands on ``target``."""
