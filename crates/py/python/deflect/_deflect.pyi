"""Type stubs of the compiled extension ``deflect._deflect``."""

from os import PathLike
from typing import Any, ClassVar, Dict, List, NoReturn, Optional, Sequence, Tuple, Union, final

from typing_extensions import Self

import numpy as np
import numpy.typing as npt

__version__: str
#: Most samples a call that stores every tick may produce (2**22, 35 min at 2 kHz).
MAX_SAMPLES: int
#: Most ticks a motion may have at its sampling rate (2**40).
MAX_TICKS: int
#: Largest elastic angle of a spring the small-deflection model accepts [rad].
MAX_SPRING_ANGLE: float
#: Largest |joint position| any call accepts [rad or m] (1e6).
MAX_JOINT_POSITION: float
#: Longest planned motion [s] (1e6, 11.6 days).
MAX_DURATION: float
#: Most joints of a serial arm.
MAX_DOF: int
#: Most springs (virtual joints) of a serial arm.
MAX_SPRINGS: int
#: Most measurements of an identification or a compliance-map fit.
MAX_MEASUREMENTS: int
#: Most points of a planned polyline.
MAX_POINTS: int
#: Most angles of one posture sweep.
MAX_ANGLES: int
#: Most IK seeds (branches) of one posture sweep.
MAX_SEEDS: int
#: Most directions of a posture measure.
MAX_DIRECTIONS: int
#: Most force (and displacement) axes of a compliance map.
MAX_AXES: int
#: Most grid dimensions of a GridMap.
MAX_GRID_DIMS: int
#: Most nodes of a GridMap.
MAX_GRID_NODES: int
#: Cutting and edge coefficients of Al7075-T6 with a carbide end mill: (k_tc, k_rc, k_ac)
#: [N/m^2], (k_te, k_re, k_ae) [N/m] (Table 5 of Zhang et al., CJME 34, 2021).
AL7075_T6_CARBIDE: Tuple[float, float, float, float, float, float]
__all__ = [
    "MAX_SAMPLES",
    "MAX_TICKS",
    "MAX_SPRING_ANGLE",
    "MAX_JOINT_POSITION",
    "MAX_DURATION",
    "MAX_DOF",
    "MAX_SPRINGS",
    "MAX_MEASUREMENTS",
    "MAX_POINTS",
    "MAX_ANGLES",
    "MAX_SEEDS",
    "MAX_DIRECTIONS",
    "MAX_AXES",
    "MAX_GRID_DIMS",
    "MAX_GRID_NODES",
    "AL7075_T6_CARBIDE",
    "Dexels",
    "GcodeProgram",
    "ToolTable",
    "gcode_words",
    "MachiningJob",
    "MachiningResult",
    "FiveAxisResult",
    "PlacementProblem",
    "cutter_force",
    "milling_force",
    "DeflectError",
    "LoadError",
    "InputError",
    "SingularError",
    "ConvergenceError",
    "__version__",
    "SerialRobot",
    "commanded_pose",
    "SensorCalibration",
    "LowPass",
    "MovingAverage",
    "PilotControl",
    "OnlineCompensator",
    "project_normal_to_feed",
    "identify_stiffness_from_tcp",
    "identify_stiffness_from_frames",
    "identify_sensor",
    "ComplianceMap",
    "GridMap",
    "Delta",
    "DeltaCorrector",
    "DisplacementField",
    "Trajectory",
    "LinePlanner",
    "plan_line",
    "plan_polyline",
    "paper_limits",
    "ParallelRobot2",
    "DalembertCorrector",
    "CorrectedPath",
    "SerialDalembertCorrector",
    "CorrectedPoses",
    "PoseTrajectory",
    "plan_pose",
    "DriveTrain",
    "ContourTracer",
    "edge_direction",
    "edge_contact_force",
    "posture_sweep",
    "_atlas_chunk",
]

_ArrayLike = npt.ArrayLike
_FloatArray = npt.NDArray[np.float64]
_StrPath = Union[str, PathLike]

class DeflectError(ValueError): ...
class LoadError(DeflectError): ...
class InputError(DeflectError):
    """Wrong shape, dtype (complex, object, string arrays) or value (NaN/inf, out of range,
    negative or huge counts, budgets exceeded); the message names the argument."""
class SingularError(DeflectError): ...
class ConvergenceError(DeflectError): ...

@final
class SerialRobot:
    """A serial robot with virtual joints (VJM paper, Eq. 1-9). SI units, base frame."""

    def __reduce__(self) -> Tuple[Any, Tuple[Any]]:
        """Pickling and copy.deepcopy: the chain as plain values, rebuilt bit for bit."""
    @staticmethod
    def _from_state(state: Any) -> "SerialRobot": ...

    @staticmethod
    def from_urdf(
        urdf_path: _StrPath, stiffness_path: _StrPath, tip_link: str, base_link: Optional[str] = None
    ) -> "SerialRobot":
        """The chain from ``base_link`` (default: the URDF root) to ``tip_link``."""
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
    def forward(self, q: _ArrayLike, *, out: Optional[_FloatArray] = None) -> _FloatArray:
        """Rigid TCP pose, (4, 4)."""
    def deflection(
        self, q: _ArrayLike, wrench: _ArrayLike, *, out: Optional[_FloatArray] = None
    ) -> _FloatArray:
        """[dx, dy, dz, rx, ry, rz] [m, rad] under wrench [Fx, Fy, Fz, Mx, My, Mz] [N, N m].
        ``InputError`` for a load that turns a virtual joint beyond the small-deflection model."""
    def spring_angles(self, q: _ArrayLike, wrench: _ArrayLike) -> _FloatArray:
        """(n_springs, 3) elastic angles [rad] (Eq. 7)."""
    def compliance(self, q: _ArrayLike, *, out: Optional[_FloatArray] = None) -> _FloatArray:
        """(6, 6) Cartesian compliance of the linearized model."""
    def linear_deflection(
        self, q: _ArrayLike, wrench: _ArrayLike, *, out: Optional[_FloatArray] = None
    ) -> _FloatArray:
        """(6,) linearized deflection compliance(q) @ wrench [m, rad], one call."""
    def joint_jacobian(self, q: _ArrayLike) -> _FloatArray:
        """(6, dof) actuated-joint Jacobian, rows [v; w]."""
    def joint_correction(
        self, q: _ArrayLike, wrench: _ArrayLike, max_iterations: int = 10, tolerance: float = 1e-12
    ) -> _FloatArray:
        """(dof,) axis-specific correction. ``max_iterations`` 0..=256 and ``tolerance`` finite
        and >= 0 (``InputError`` otherwise); ``ConvergenceError`` when the residual stays above
        ``tolerance`` (the message says whether the iteration stalled at its fixed point)."""
    def forward_batch(self, Q: _ArrayLike, *, out: Optional[_FloatArray] = None) -> _FloatArray:
        """(N, dof) -> (N, 4, 4) rigid TCP poses; GIL released, every core for N >= 2048."""
    def compliance_batch(self, Q: _ArrayLike, *, out: Optional[_FloatArray] = None) -> _FloatArray:
        """(N, dof) -> (N, 6, 6) compliances; GIL released, every core for N >= 2048."""
    def deflection_batch(
        self, Q: _ArrayLike, W: _ArrayLike, *, out: Optional[_FloatArray] = None
    ) -> _FloatArray:
        """(N, dof), (N, 6) -> (N, 6) [m, rad]; a single row of either broadcasts over the
        other's rows. float64 C-contiguous input is read in place; the GIL is released and
        batches of N >= 2048 rows run on every core."""
    def equilibrium(
        self, q: _ArrayLike, wrench: _ArrayLike, max_iterations: int = 20, tolerance: float = 1e-12
    ) -> _FloatArray:
        """Deflection (6,) in static equilibrium (moments in the deflected pose), laid out as
        ``deflection``; Newton on the spring angles, ``ConvergenceError`` past the budget."""

def commanded_pose(target: _ArrayLike, deflection: _ArrayLike) -> _FloatArray:
    """(4, 4) pose to command so that the deflected TCP lands on ``target``, a rigid transform
    (finite, bottom row 0 0 0 1, a proper rotation within 1e-9; ``InputError`` otherwise)."""

@final
class GridMap:
    """Compliance map over a grid of 1-4 dimensions (task-space x, y, z [m] or joint angles
    [rad]): the per-node lines of Paksoy et al. 2025 (Eq. 9-13) blended multilinearly (Eq. 14
    in N-D) or by a C1 cubic Hermite interpolation. ``slopes``/``offsets`` have the shape
    (n_0, ..., n_{N-1}, n_displacement, n_force). JSON ``format_version`` 2 (version 1, a 2-D
    map, is read too)."""

    def __new__(
        cls,
        axes: Sequence[_ArrayLike],
        n_force: int,
        n_displacement: int,
        slopes: _ArrayLike,
        offsets: _ArrayLike,
        *,
        names: Optional[Sequence[str]] = None,
        interpolation: str = "multilinear",
        out_of_grid: str = "error",
    ) -> Self: ...
    @staticmethod
    def fit(
        points: _ArrayLike,
        force_axis: _ArrayLike,
        force: _ArrayLike,
        displacement: _ArrayLike,
        *,
        names: Optional[Sequence[str]] = None,
        n_force: Optional[int] = None,
        position_tolerance: float = 1e-6,
        interpolation: str = "multilinear",
        out_of_grid: str = "error",
    ) -> "GridMap":
        """Eq. 10-13 at every node of the N-D grid of the readings' distinct coordinates."""
    @staticmethod
    def fit_csv(
        path: _StrPath,
        force_unit: str = "N",
        length_unit: str = "mm",
        n_force: Optional[int] = None,
        position_tolerance: float = 1e-6,
        interpolation: str = "multilinear",
        out_of_grid: str = "error",
    ) -> "GridMap":
        """Static tests from CSV whose ``<name>_<m|mm|rad|deg>`` columns name the grid axes."""
    @staticmethod
    def from_map(map: ComplianceMap) -> "GridMap": ...
    def to_json(self) -> str: ...
    def save_json(self, path: _StrPath) -> None: ...
    @staticmethod
    def from_json(source: Union[str, PathLike]) -> "GridMap": ...
    def __reduce__(self) -> Tuple[Any, Tuple[str]]: ...
    def __eq__(self, value: object, /) -> bool: ...
    __hash__: ClassVar[None]  # type: ignore[assignment]
    def with_options(
        self, interpolation: Optional[str] = None, out_of_grid: Optional[str] = None
    ) -> "GridMap": ...
    def displacement(
        self,
        point: _ArrayLike,
        force: _ArrayLike,
        *,
        interpolation: Optional[str] = None,
        out_of_grid: Optional[str] = None,
        out: Optional[_FloatArray] = None,
    ) -> _FloatArray: ...
    def displacement_batch(
        self,
        P: _ArrayLike,
        F: _ArrayLike,
        *,
        interpolation: Optional[str] = None,
        out_of_grid: Optional[str] = None,
        out: Optional[_FloatArray] = None,
    ) -> _FloatArray: ...
    @property
    def dims(self) -> int: ...
    @property
    def names(self) -> List[str]: ...
    @property
    def axes(self) -> List[_FloatArray]: ...
    @property
    def n_force(self) -> int: ...
    @property
    def n_displacement(self) -> int: ...
    @property
    def interpolation(self) -> str: ...
    @property
    def out_of_grid(self) -> str: ...
    @property
    def slopes(self) -> _FloatArray: ...
    @property
    def offsets(self) -> _FloatArray: ...

@final
class ComplianceMap:
    """Compliance map from static tests (Paksoy et al. 2025, Eq. 9-14): per-node lines
    ``disp_d = sum_f (slope[d, f] * F_f + offset[d, f])`` blended bilinearly (Eq. 14) or with a
    C1 cubic Hermite interpolation. SI: positions m, forces N, displacements m.

    ``interpolation``: ``"bilinear"`` | ``"bicubic"``; ``out_of_grid``: ``"error"`` |
    ``"clamp"`` | ``"extrapolate"``. Bad input raises ``InputError``, bad files ``LoadError``.
    """

    @staticmethod
    def from_csv(
        path: _StrPath,
        force_unit: str = "N",
        length_unit: str = "mm",
        interpolation: str = "bilinear",
        out_of_grid: str = "error",
    ) -> "ComplianceMap":
        """Paper-format table (columns x_mm, y_mm, m, n, o, p, s, u, v, w)."""
    @staticmethod
    def from_csv_text(
        text: str,
        force_unit: str = "N",
        length_unit: str = "mm",
        interpolation: str = "bilinear",
        out_of_grid: str = "error",
    ) -> "ComplianceMap": ...
    @staticmethod
    def fit(
        positions: _ArrayLike,
        force_axis: _ArrayLike,
        force: _ArrayLike,
        displacement: Optional[_ArrayLike] = None,
        *,
        upper: Optional[_ArrayLike] = None,
        lower: Optional[_ArrayLike] = None,
        spacing: Optional[float] = None,
        extension: float = 0.0,
        n_force: Optional[int] = None,
        position_tolerance: float = 1e-6,
        interpolation: str = "bilinear",
        out_of_grid: str = "error",
    ) -> "ComplianceMap":
        """Least-squares lines per node (Eq. 10-13) from (N, 2) positions [m], (N,) force axes,
        (N,) forces [N] and (N, n_disp) displacements [m] (or upper/lower two-point form)."""
    @staticmethod
    def fit_csv(
        path: _StrPath,
        force_unit: str = "N",
        length_unit: str = "mm",
        n_force: Optional[int] = None,
        position_tolerance: float = 1e-6,
        interpolation: str = "bilinear",
        out_of_grid: str = "error",
    ) -> "ComplianceMap":
        """Static-test CSV: x, y, force_axis, force, dx, dy[, dz, rx, ry, rz]."""
    def to_json(self) -> str:
        """Versioned JSON (format_version 1, SI units recorded)."""
    def save_json(self, path: _StrPath) -> None:
        """Writes to_json() to the file at path."""
    @staticmethod
    def from_json(source: Union[str, PathLike]) -> "ComplianceMap":
        """JSON text (starting with '{') or a path to the file."""
    def __reduce__(self) -> Tuple[Any, Tuple[str]]:
        """Pickling and copy.deepcopy through the JSON (exact)."""
    def with_options(
        self, interpolation: Optional[str] = None, out_of_grid: Optional[str] = None
    ) -> "ComplianceMap": ...
    def displacement(
        self,
        position: _ArrayLike,
        force: _ArrayLike,
        *,
        interpolation: Optional[str] = None,
        out_of_grid: Optional[str] = None,
        out: Optional[_FloatArray] = None,
    ) -> _FloatArray:
        """(n_displacement,) [m] at position (2,) or (3,) [m] (z ignored) under force [N]."""
    def displacement_batch(
        self,
        P: _ArrayLike,
        F: _ArrayLike,
        *,
        interpolation: Optional[str] = None,
        out_of_grid: Optional[str] = None,
        out: Optional[_FloatArray] = None,
    ) -> _FloatArray:
        """(N, 2|3) [m], (N, n_force) [N] -> (N, n_displacement) [m]; a single row of either
        broadcasts over the other's rows. float64 C-contiguous input is read in place; the
        GIL is released."""
    def cross_validate(self, forces: _ArrayLike, axis: str = "y") -> Dict[str, Any]:
        """Leave-one-node-out RMS [m] of bilinear vs bicubic."""
    @property
    def residuals(self) -> Optional[List[Dict[str, Any]]]:
        """Per-node fit statistics, or None if the map was not fitted."""
    @property
    def x(self) -> _FloatArray: ...
    @property
    def y(self) -> _FloatArray: ...
    @property
    def n_force(self) -> int: ...
    @property
    def n_displacement(self) -> int: ...
    @property
    def interpolation(self) -> str: ...
    @property
    def out_of_grid(self) -> str: ...
    @property
    def slopes(self) -> _FloatArray:
        """(nx, ny, n_displacement, n_force) [m/N]."""
    @property
    def offsets(self) -> _FloatArray:
        """(nx, ny, n_displacement, n_force) [m]."""
    def field(self, force: _ArrayLike) -> "DisplacementField":
        """The displacement field under a fixed force (n_force,) [N]: node values computed once."""

@final
class DisplacementField:
    """A ComplianceMap evaluated once at a fixed load: position-only queries that equal
    ``map.displacement(position, force)``. Built by ``ComplianceMap.field(force)``."""

    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]:
        """Pickling and copy.deepcopy as ``map.field(force)`` (exact)."""
    def displacement(self, position: _ArrayLike) -> _FloatArray:
        """(n_displacement,) [m] at (x, y) [m]."""
    def displacement_batch(self, P: _ArrayLike) -> _FloatArray:
        """(N, 2) or (N, 3) positions [m] -> (N, n_displacement) [m]; GIL released."""
    @property
    def force(self) -> _FloatArray:
        """The load (n_force,) [N]."""
    @property
    def node_values(self) -> _FloatArray:
        """(nx, ny, n_displacement) [m] node displacements under the load."""
    @property
    def map(self) -> ComplianceMap:
        """The map the field was computed from."""

_Limit = Union[float, _ArrayLike]

@final
class Trajectory:
    """A motion in 1..=8 coordinates: a plan (exact at any t) with its ticks at ``rate_hz``
    (computed on first access; ``rate_hz`` None: plan only), or the user's own samples."""
    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]:
        """Pickling and ``copy.deepcopy``: planned again from its points and limits, or
        rebuilt from its samples (exact)."""
    @staticmethod
    def from_samples(
        position: _ArrayLike, rate_hz: float, acceleration: Optional[_ArrayLike] = None
    ) -> "Trajectory":
        """(n, d) positions at ``rate_hz``; derivatives by second-order finite differences."""
    def at(self, t: Union[float, _ArrayLike]) -> Dict[str, Any]:
        """State at ``t`` [s] (a number or (m,), at most MAX_SAMPLES): t, position, velocity,
        acceleration, jerk. Before 0 the start at rest, from ``duration`` on the end at rest
        (a controller holds the end states); planned trajectories only."""
    def sampled(self, rate_hz: float) -> "Trajectory": ...
    @property
    def t(self) -> _FloatArray: ...
    @property
    def position(self) -> _FloatArray: ...
    @property
    def velocity(self) -> _FloatArray: ...
    @property
    def acceleration(self) -> _FloatArray: ...
    @property
    def jerk(self) -> _FloatArray: ...
    @property
    def duration(self) -> float: ...
    @property
    def dim(self) -> int: ...
    @property
    def rate_hz(self) -> Optional[float]: ...
    @property
    def is_planned(self) -> bool: ...
    def __len__(self) -> int: ...

@final
class LinePlanner:
    """One straight-line plan in ``dim`` coordinates (1..=8) re-planned in place per move
    (ruckig's ``calculate(input, trajectory)`` habit); path limits validated once. Set
    ``start`` / ``end`` and call ``plan()``, or pass the points to ``plan(start, end)``.

    A planner is mutable state, as a numpy ``Generator`` is: give each thread its own (or
    hold a lock around each call); a call while another thread's call on the same planner
    runs raises ``RuntimeError("Already borrowed")``."""
    def __new__(cls, dim: int, v_max: float, a_max: float, j_max: float) -> "LinePlanner": ...
    def plan(self, start: Optional[_ArrayLike] = None, end: Optional[_ArrayLike] = None) -> float:
        """Re-plans from ``start`` to ``end`` in place (bit for bit ``plan_line``) and returns
        the duration [s]; a point not given is the input's (``start`` / ``end``, ruckig's
        ``InputParameter``). On error the previous plan and input are kept."""
    def at(self, t: Union[float, _ArrayLike]) -> Dict[str, Any]:
        """State of the current plan at ``t`` [s], as ``Trajectory.at``."""
    def trajectory(self, rate_hz: Optional[float] = 2000.0) -> Trajectory:
        """A copy of the current plan, as ``plan_line`` returns it."""
    def __getnewargs__(self) -> Tuple[int, float, float, float]: ...
    def __getstate__(self) -> Tuple[List[float], List[float], List[float], List[float]]: ...
    def __setstate__(
        self, state: Tuple[List[float], List[float], List[float], List[float]]
    ) -> None: ...
    @property
    def duration(self) -> float: ...
    @property
    def dim(self) -> int: ...
    @property
    def limits(self) -> Tuple[float, float, float]: ...
    @property
    def start(self) -> List[float]:
        """Input start point: what ``plan()`` plans from."""
    @start.setter
    def start(self, value: _ArrayLike) -> None: ...
    @property
    def end(self) -> List[float]:
        """Input end point: what ``plan()`` plans to."""
    @end.setter
    def end(self, value: _ArrayLike) -> None: ...

def plan_line(
    start: _ArrayLike,
    end: _ArrayLike,
    v_max: _Limit,
    a_max: _Limit,
    j_max: _Limit,
    rate_hz: Optional[float] = 2000.0,
) -> Trajectory:
    """1..=8 coordinates; numbers limit the path (Euclidean norms), arrays each coordinate.
    At most 2**22 ticks: ``InputError`` (before allocating) for a longer motion or rate."""
def plan_polyline(
    points: _ArrayLike,
    v_max: Optional[_Limit] = None,
    a_max: Optional[_Limit] = None,
    j_max: Optional[_Limit] = None,
    rate_hz: Optional[float] = 2000.0,
    segment_limits: Optional[_ArrayLike] = None,
) -> Trajectory:
    """(n, d) points; limits as ``plan_line`` or per segment, (n - 1, 3)."""
def paper_limits(g_level: int) -> Tuple[float, float, float]:
    """(v_max, a_max, j_max) reproducing the paper's motion durations at 1..5 g."""

@final
class PoseTrajectory:
    """A 6-D rest-to-rest pose motion: straight line and a turn about a fixed axis, synchronised."""
    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]:
        """Pickling and ``copy.deepcopy``: ``plan_pose`` with the same arguments (exact)."""
    def at(self, t: Union[float, _ArrayLike]) -> Dict[str, Any]:
        """State at ``t`` [s] (a number or (m,), at most MAX_SAMPLES): t, pose (4, 4),
        velocity, acceleration, angular_velocity, angular_acceleration. Before 0 the start
        pose at rest, from ``duration`` on the end pose at rest."""
    def sampled(self, rate_hz: float) -> "PoseTrajectory": ...
    @property
    def t(self) -> _FloatArray: ...
    @property
    def pose(self) -> _FloatArray: ...
    @property
    def velocity(self) -> _FloatArray: ...
    @property
    def acceleration(self) -> _FloatArray: ...
    @property
    def angular_velocity(self) -> _FloatArray: ...
    @property
    def angular_acceleration(self) -> _FloatArray: ...
    @property
    def start(self) -> _FloatArray: ...
    @property
    def end(self) -> _FloatArray: ...
    @property
    def axis(self) -> _FloatArray: ...
    @property
    def angle(self) -> float: ...
    @property
    def duration(self) -> float: ...
    @property
    def rate_hz(self) -> Optional[float]: ...
    def __len__(self) -> int: ...

def plan_pose(
    start: _ArrayLike,
    end: _ArrayLike,
    linear: Tuple[float, float, float],
    angular: Tuple[float, float, float],
    rate_hz: Optional[float] = 2000.0,
) -> PoseTrajectory:
    """linear (v [m/s], a [m/s^2], j [m/s^3]), angular (w [rad/s], alpha [rad/s^2], [rad/s^3])."""

@final
class Delta:
    """The 3-DoF Delta robot of Clavel: platform centre p (3,) [m] (z up, platform below),
    joints q (3,) [rad] (arm angles from the horizontal, positive down), elbows out."""

    def __new__(
        cls,
        base_radius: float,
        platform_radius: float,
        arm: float,
        forearm: float,
        min_sigma: float = 0.01,
    ) -> Self: ...
    @staticmethod
    def pick_and_place() -> "Delta": ...
    def __reduce__(self) -> Tuple[Any, Tuple[float, float, float, float, float]]: ...
    def __eq__(self, value: object, /) -> bool: ...
    __hash__: ClassVar[None]  # type: ignore[assignment]
    def ik(self, p: _ArrayLike) -> _FloatArray: ...
    def fk(self, q: _ArrayLike) -> _FloatArray: ...
    def jacobian(self, q: _ArrayLike) -> _FloatArray: ...
    def singularity_distance(self, q: _ArrayLike) -> float: ...
    @property
    def base_radius(self) -> float: ...
    @property
    def platform_radius(self) -> float: ...
    @property
    def arm(self) -> float: ...
    @property
    def forearm(self) -> float: ...

@final
class DeltaCorrector:
    """The paper's D'Alembert corrector on a Delta from a 3-D compliance map (GridMap over
    x, y, z with 3 force and 3 displacement axes)."""

    def __new__(
        cls, grid_map: GridMap, delta: Delta, mass: float, iterations: int = 0, tolerance: float = 0.0
    ) -> Self: ...
    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]: ...
    @property
    def mass(self) -> float: ...
    def step(self, position: _ArrayLike, acceleration: _ArrayLike) -> Dict[str, Any]: ...

@final
class ParallelRobot2:
    """The paper's 2-DoF planar parallel robot; p = C - O [m], q = (theta_A, theta_B) [rad]."""
    def __new__(
        cls,
        link: float = 0.150, half_width: float = 0.090, min_sigma: float = 0.020) -> Self: ...
    def __reduce__(self) -> Tuple[Any, Tuple[float, float, float]]:
        """Pickling and copy.deepcopy through the constructor arguments (exact)."""
    def ik(self, p: _ArrayLike) -> _FloatArray: ...
    def fk(self, q: _ArrayLike) -> _FloatArray: ...
    def jacobian(self, q: _ArrayLike) -> _FloatArray: ...
    def singularity_distance(self, q: _ArrayLike) -> float: ...
    @property
    def reach(self) -> float: ...

@final
class CorrectedPath:
    """Output of DalembertCorrector.correct: one row per tick."""
    t: _FloatArray
    desired: _FloatArray
    commanded: _FloatArray
    joints: _FloatArray
    force: _FloatArray
    displacement: _FloatArray
    flagged_ticks: List[int]
    @property
    def position(self) -> _FloatArray:
        """The old name of ``commanded``."""

@final
class DalembertCorrector:
    """D'Alembert correction of the paper's five-bar from a compliance map; for a serial arm,
    ``SerialDalembertCorrector``."""
    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]:
        """Pickling and ``copy.deepcopy``: its configuration; the copy starts from its first tick."""
    def __new__(
        cls,
        compliance_map: ComplianceMap,
        mechanism: ParallelRobot2,
        mass: float = 5.0,
        iterations: int = 0,
        tolerance: float = 0.0,
    ) -> Self: ...
    @property
    def mass(self) -> float: ...
    def step(
        self, position: _ArrayLike, acceleration: _ArrayLike, seed: Optional[_ArrayLike] = None
    ) -> Dict[str, Any]:
        """One tick; the IK starts from the last tick's joints, or from ``seed`` (2,) [rad]."""
    def correct(self, trajectory: Trajectory) -> CorrectedPath: ...

@final
class CorrectedPoses:
    """Output of SerialDalembertCorrector.correct: one row per tick, base frame."""
    t: _FloatArray
    desired: _FloatArray
    commanded: _FloatArray
    joints: _FloatArray
    wrench: _FloatArray
    deflection: _FloatArray
    iterations: npt.NDArray[np.uint32]
    position_error: _FloatArray
    orientation_error: _FloatArray
    free_rotation: _FloatArray

@final
class SerialDalembertCorrector:
    """The D'Alembert corrector for a serial arm (a SerialRobot with >= 3 joints): the pose,
    or the task an arm with fewer joints controls."""
    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]:
        """Pickling and ``copy.deepcopy``: its configuration; the copy starts from ``seed``."""
    def __new__(
        cls,
        robot: SerialRobot,
        mass: float,
        com: Optional[_ArrayLike] = None,
        inertia: Optional[_ArrayLike] = None,
        model: str = "exact",
        joint_limits: Optional[_ArrayLike] = None,
        max_iterations: int = 20,
        position_tolerance: float = 1e-8,
        orientation_tolerance: float = 1e-8,
        seed: Optional[_ArrayLike] = None,
        link_inertia: bool = False,
        gravity: Optional[_ArrayLike] = None,
        task: str = "auto",
    ) -> Self: ...
    @property
    def dof(self) -> int: ...
    @property
    def joint_names(self) -> List[str]: ...
    @property
    def link_inertia(self) -> bool: ...
    @property
    def gravity(self) -> _FloatArray: ...
    @property
    def task(self) -> str: ...
    @property
    def mass(self) -> float: ...
    @property
    def model(self) -> str: ...
    @property
    def joints(self) -> _FloatArray: ...
    def reset(self, q: _ArrayLike) -> None: ...
    def step(
        self,
        pose: _ArrayLike,
        velocity: Optional[_ArrayLike] = None,
        acceleration: Optional[_ArrayLike] = None,
        angular_velocity: Optional[_ArrayLike] = None,
        angular_acceleration: Optional[_ArrayLike] = None,
        process_wrench: Optional[_ArrayLike] = None,
        t: Optional[float] = None,
    ) -> Dict[str, Any]:
        """One tick; ``step(**trajectory.at(t))`` works."""
    def correct(
        self, trajectory: PoseTrajectory, process_wrench: Optional[_ArrayLike] = None
    ) -> CorrectedPoses: ...

@final
class SensorCalibration:
    """Force/torque sensor calibration (VJM paper Eq. 12-20); SI units, sensor frame."""
    def __reduce__(self) -> Tuple[Any, Tuple[Any]]:
        """Pickling and ``copy.deepcopy``: every number, exact, validated on the way back."""
    @staticmethod
    def _from_state(state: Any) -> "SensorCalibration": ...
    def __new__(
        cls,
        force_offset: Optional[_ArrayLike] = None,
        moment_offset: Optional[_ArrayLike] = None,
        weight: float = 0.0,
        center_of_gravity: Optional[_ArrayLike] = None,
        residual: Optional[_ArrayLike] = None,
        sensor_to_tcp: Optional[_ArrayLike] = None,
    ) -> Self: ...
    @property
    def force_offset(self) -> _FloatArray: ...
    @property
    def moment_offset(self) -> _FloatArray: ...
    @property
    def weight(self) -> float: ...
    @property
    def center_of_gravity(self) -> _FloatArray: ...
    @property
    def residual(self) -> _FloatArray: ...
    @property
    def sensor_to_tcp(self) -> _FloatArray: ...
    def unloaded_reading(self, rotation: _ArrayLike) -> _FloatArray: ...
    def compensate(self, reading: _ArrayLike, rotation: _ArrayLike) -> _FloatArray:
        """Eq. 18."""
    def to_tcp_frame(self, wrench: _ArrayLike) -> _FloatArray:
        """Eq. 19-20."""
    def tcp_wrench_base(self, reading: _ArrayLike, tcp: _ArrayLike) -> _FloatArray: ...

@final
class LowPass:
    def __reduce__(self) -> NoReturn:
        """``TypeError``: the per-tick state does not pickle; send the constructor's arguments."""
    def __copy__(self) -> Self:
        """An exact copy, state included."""
    def __deepcopy__(self, memo: Any, /) -> Self:
        """An exact copy, state included."""
    def __new__(
        cls, cutoff_hz: float, dt: float) -> Self: ...
    def step(self, x: _ArrayLike) -> _FloatArray: ...
    @property
    def alpha(self) -> float: ...
    @property
    def delay_samples(self) -> float: ...
    @property
    def delay_seconds(self) -> float: ...
    def reset(self) -> None: ...

@final
class MovingAverage:
    def __reduce__(self) -> NoReturn:
        """``TypeError``: the per-tick state does not pickle; send the constructor's arguments."""
    def __copy__(self) -> Self:
        """An exact copy, state included."""
    def __deepcopy__(self, memo: Any, /) -> Self:
        """An exact copy, state included."""
    def __new__(
        cls, window: int, dt: float) -> Self: ...
    def step(self, x: _ArrayLike) -> _FloatArray: ...
    @property
    def delay_samples(self) -> float: ...
    @property
    def delay_seconds(self) -> float: ...
    def reset(self) -> None: ...

@final
class PilotControl:
    def __reduce__(self) -> NoReturn:
        """``TypeError``: the per-tick state does not pickle; send the constructor's arguments."""
    def __copy__(self) -> Self:
        """An exact copy, state included."""
    def __deepcopy__(self, memo: Any, /) -> Self:
        """An exact copy, state included."""
    def __new__(
        cls, threshold: float = 150.0, ramp: float = 0.08, dt: float = 0.004) -> Self: ...
    def step(self, measured: _ArrayLike, estimated: _ArrayLike) -> _FloatArray: ...
    @property
    def weight(self) -> float: ...
    def reset(self) -> None: ...

def project_normal_to_feed(r: _ArrayLike, v: _ArrayLike) -> Tuple[_FloatArray, bool]:
    """Eq. 10-11."""

@final
class OnlineCompensator:
    def __reduce__(self) -> NoReturn:
        """``TypeError``: the per-tick state does not pickle; send the constructor's arguments."""
    def __copy__(self) -> Self:
        """An exact copy, state included."""
    def __deepcopy__(self, memo: Any, /) -> Self:
        """An exact copy, state included."""
    def __new__(
        cls,
        robot: SerialRobot,
        dt: float = 0.004,
        calibration: Optional[SensorCalibration] = None,
        lowpass_cutoff_hz: float = 10.0,
        moving_average_window: int = 5,
        pilot: Optional[_ArrayLike] = (150.0, 0.08),
        project_on_feed: bool = True,
        max_correction: float = 3.0e-3,
        max_rate: float = 0.05,
        output: str = "cartesian",
    ) -> Self: ...
    @property
    def delay_samples(self) -> float: ...
    @property
    def delay_seconds(self) -> float: ...
    def step(
        self,
        q: _ArrayLike,
        reading: _ArrayLike,
        estimated: Optional[_ArrayLike] = None,
        feed_velocity: Optional[_ArrayLike] = None,
    ) -> Dict[str, Any]: ...
    def reset(self) -> None: ...

def identify_stiffness_from_tcp(
    robot: SerialRobot, Q: _ArrayLike, W: _ArrayLike, D: _ArrayLike, translation_only: bool = False, all_axes: bool = False
) -> Dict[str, Any]:
    """At most 100000 measurements (``InputError`` beyond)."""
def identify_stiffness_from_frames(
    robot: SerialRobot, Q: _ArrayLike, W: _ArrayLike, springs: _ArrayLike, rotations: _ArrayLike, all_axes: bool = False
) -> Dict[str, Any]:
    """``springs``: (N,) virtual-joint indices. At most 100000 measurements."""
def identify_sensor(
    rotations: _ArrayLike, readings: _ArrayLike, fit_polynomial: bool = False, sensor_to_tcp: Optional[_ArrayLike] = None
) -> Tuple[SensorCalibration, Dict[str, Any]]: ...

@final
class DriveTrain:
    """Drive-train errors of a serial robot (contour-tracking paper, Eq. 3-13). Wrenches are the
    wrench the tool exerts on the environment (base frame); torques are drive torques."""
    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]:
        """Pickling and ``copy.deepcopy``: its constructor's arguments, the robot with them (exact)."""
    def __new__(
        cls,
        robot: SerialRobot,
        stiffness: _ArrayLike,
        backlash: Optional[_ArrayLike] = None,
        masses: Optional[Sequence[Tuple[int, float, _ArrayLike]]] = None,
        gravity: Optional[_ArrayLike] = None,
        torque_deadband: float = 0.0,
        max_condition: float = 1.0e6,
    ) -> Self:
        """``gravity`` defaults to (0, 0, -9.80665) m/s^2 (standard gravity down base z)."""
    @staticmethod
    def from_urdf(robot: SerialRobot, urdf_path: _StrPath, drive_path: _StrPath) -> "DriveTrain": ...
    @staticmethod
    def from_strings(robot: SerialRobot, urdf: str, drive_toml: str) -> "DriveTrain": ...
    @property
    def stiffness(self) -> List[float]: ...
    @property
    def backlash(self) -> List[float]: ...
    @property
    def masses(self) -> List[Tuple[int, float, Tuple[float, float, float]]]: ...
    @property
    def gravity(self) -> Tuple[float, float, float]: ...
    def gravity_torques(self, q: _ArrayLike) -> _FloatArray: ...
    def contact_torques(self, q: _ArrayLike, wrench: _ArrayLike) -> _FloatArray: ...
    def joint_torques(self, q: _ArrayLike, wrench: _ArrayLike) -> _FloatArray: ...
    def correct_joints(self, q: _ArrayLike, wrench: _ArrayLike) -> _FloatArray:
        """Eq. 10: theta - sgn(u) theta_b - u / K."""
    def compensated_forward(self, q: _ArrayLike, wrench: _ArrayLike) -> _FloatArray: ...
    def cartesian_stiffness(self, q: _ArrayLike, planar: Optional[str] = None) -> _FloatArray:
        """Eq. 12: K = J^-T K_theta J^-1 (6x6, or planar "xy" 2x2 / "xyrz" 3x3)."""

@final
class ContourTracer:
    """Force-feedback contour tracing (Figures 3-4): step(position, force) -> (command, state)."""
    def __reduce__(self) -> NoReturn:
        """``TypeError``: the per-tick state does not pickle; send the constructor's arguments."""
    def __copy__(self) -> Self:
        """An exact copy, state included."""
    def __deepcopy__(self, memo: Any, /) -> Self:
        """An exact copy, state included."""
    def __new__(
        cls,
        stiffness: _ArrayLike,
        step: float,
        contact_force: float,
        jam_force: float,
        *,
        target_force: Optional[float] = None,
        approach_direction: _ArrayLike = (1.0, 0.0),
        approach_step: Optional[float] = None,
        bias_samples: int = 10,
        stop_radius: Optional[float] = None,
        clockwise: bool = False,
        max_turn: float = 0.7853981633974483,
        min_motion_fraction: float = 0.25,
        jam_margin: float = 0.8,
        min_step_fraction: float = 0.1,
        max_bisections: int = 6,
        max_jam_steps: int = 10,
        max_approach_steps: int = 10000,
        max_steps: int = 100000,
    ) -> Self: ...
    def set_stiffness(self, stiffness: _ArrayLike) -> None: ...
    def step(self, position: _ArrayLike, force: _ArrayLike) -> Tuple[_FloatArray, str]: ...
    @property
    def state(self) -> str: ...
    @property
    def finished(self) -> bool: ...
    @property
    def contact(self) -> bool: ...
    @property
    def tool(self) -> Optional[Tuple[float, float]]: ...
    @property
    def force(self) -> Optional[Tuple[float, float]]: ...
    @property
    def bias(self) -> Tuple[float, float]: ...
    @property
    def start(self) -> Optional[Tuple[float, float]]: ...
    def stats(self) -> Dict[str, Any]: ...

def edge_direction(stiffness: _ArrayLike, step: _ArrayLike, force: _ArrayLike) -> float:
    """Eq. 21: the edge angle from a commanded step and the steady-state force."""
def edge_contact_force(stiffness: _ArrayLike, step: _ArrayLike, edge_angle: float) -> _FloatArray:
    """Eq. 16-20: the contact force of a step blocked by an edge."""

def posture_sweep(
    robot: SerialRobot,
    position: _ArrayLike,
    tool_axis: _ArrayLike,
    wrench: _ArrayLike,
    *,
    angles: Optional[_ArrayLike] = None,
    seeds: Optional[_ArrayLike] = None,
    measure: Union[None, str, _ArrayLike] = None,
    refine: bool = True,
    min_sigma: float = 0.001,
) -> Dict[str, Any]:
    """The rotation about the tool axis that deflects least: per angle [rad] the reach, the
    measure [m], the deflection (n, 6) [m, rad] and the joints (n, dof); ``best`` (or None),
    ``best_index``, ``worst_index``."""

def _atlas_chunk(
    robot: SerialRobot,
    positions: _ArrayLike,
    tool_axes: _ArrayLike,
    wrenches: _ArrayLike,
    angles: Optional[_ArrayLike] = None,
    seeds: Optional[_ArrayLike] = None,
    measure: Union[None, str, _ArrayLike] = None,
    refine: bool = True,
    min_sigma: float = 0.001,
) -> _FloatArray:
    """One chunk of ``deflect.atlas``: (N, 10 + dof + 39) rows."""

@final
class Dexels:
    """A block of stock as three grids of rays, cut exactly by a tool at any orientation."""
    def __new__(cls, min: _ArrayLike, max: _ArrayLike, cell: float) -> "Dexels": ...
    def cut(
        self,
        shape: str,
        diameter: float,
        length: float,
        start: _ArrayLike,
        start_axis: _ArrayLike,
        end: _ArrayLike,
        end_axis: _ArrayLike,
        *,
        corner_radius: Optional[float] = None,
    ) -> Tuple[int, float]:
        """Sweeps the tool: (rays updated, volume removed [m^3])."""
    def cut_program(
        self,
        program: "GcodeProgram",
        shape: str,
        diameter: float,
        length: float,
        *,
        corner_radius: Optional[float] = None,
    ) -> Tuple[int, float]:
        """Cuts every move of the program: (rays updated, volume removed [m^3])."""
    def is_material(self, points: _ArrayLike) -> npt.NDArray[np.bool_]:
        """Whether each point (n, 3) [m] is material."""
    @property
    def volume(self) -> float:
        """The material's volume [m^3]."""
    @property
    def shape(self) -> Tuple[int, int, int]:
        """Cells along x, y, z."""

@final
class GcodeProgram:
    """A machining program read from RS274/NGC G-code as LinuxCNC reads it: its moves as
    arrays, SI, in the program's machine frame."""
    @staticmethod
    def from_file(
        path: _StrPath,
        *,
        start: Optional[_ArrayLike] = None,
        units: str = "mm",
        dialect: str = "linuxcnc",
        block_delete: bool = False,
        kinematics: Optional[Dict[str, Any]] = None,
    ) -> "GcodeProgram":
        """Reads a G-code file; ``start`` (3,) [m] before the first move, ``units`` "mm" | "in",
        ``dialect`` "linuxcnc" | "grbl" | "fanuc", ``block_delete`` skips "/" lines,
        ``kinematics`` a five-axis machine whose A B C turn the tool axis."""
    @staticmethod
    def from_text(
        text: str,
        *,
        start: Optional[_ArrayLike] = None,
        units: str = "mm",
        dialect: str = "linuxcnc",
        block_delete: bool = False,
        kinematics: Optional[Dict[str, Any]] = None,
    ) -> "GcodeProgram":
        """Same as ``from_file``, from the program's text."""
    @staticmethod
    def from_apt_file(
        path: _StrPath, *, start: Optional[_ArrayLike] = None, units: str = "mm"
    ) -> "GcodeProgram":
        """Reads an APT / CL file: GOTO with tool vectors, FEDRAT, RAPID, CIRCLE, SPINDL,
        LOADTL, CUTTER, MULTAX, UNITS, FINI."""
    @staticmethod
    def from_apt_text(
        text: str, *, start: Optional[_ArrayLike] = None, units: str = "mm"
    ) -> "GcodeProgram":
        """Same as ``from_apt_file``, from the program's text."""
    @staticmethod
    def from_points_file(path: _StrPath, *, start: Optional[_ArrayLike] = None) -> "GcodeProgram":
        """Tool points CSV: one straight move per row (x_mm/y_mm/z_mm or x_m/..., feed_mm_min
        or feed_m_s, 0 for rapid, spindle_rpm)."""
    @staticmethod
    def from_points_text(text: str, *, start: Optional[_ArrayLike] = None) -> "GcodeProgram":
        """Same as ``from_points_file``, from the CSV text."""
    def __reduce__(self) -> Tuple[Any, Tuple[Any, Any, Any, Any, Any]]:
        """Pickling and copy.deepcopy: the moves, tool axes, cutters and the word report,
        rebuilt bit for bit."""
    @staticmethod
    def _from_state(
        state: Any, words: Any, operations: Any = ..., axes: Any = ..., cutters: Any = ...
    ) -> "GcodeProgram": ...
    @property
    def start_axis(self) -> _FloatArray:
        """Tool axis at each move's start (n, 3), unit, tip towards spindle."""
    @property
    def end_axis(self) -> _FloatArray:
        """Tool axis at each move's end (n, 3)."""
    @property
    def is_multi_axis(self) -> bool:
        """Whether any move's tool axis leaves +z."""
    @property
    def cutters(self) -> List[Tuple[int, float, str, float, int]]:
        """APT cutters: (tool, diameter [m], shape, corner_radius [m], line)."""
    def __eq__(self, value: object, /) -> bool: ...
    __hash__: ClassVar[None]  # type: ignore[assignment]
    def __len__(self) -> int: ...
    @property
    def operations(self) -> List[Tuple[str, int, int]]:
        """The program's operations (a CAM toolpath each: a tool change or a comment line
        standing alone between moves starts one): `(name, first_move, first_line)` in order."""
    @property
    def line(self) -> npt.NDArray[np.uint64]:
        """The program line of each move (1-based), (n,)."""
    @property
    def kind(self) -> List[str]:
        """"rapid", "linear", "arc" or "dwell" per move."""
    @property
    def start(self) -> _FloatArray:
        """Start points (n, 3) [m]."""
    @property
    def end(self) -> _FloatArray:
        """End points (n, 3) [m]."""
    @property
    def center(self) -> _FloatArray:
        """Arc centres (n, 3) [m]; NaN for other moves."""
    @property
    def plane(self) -> List[Optional[str]]:
        """Each arc's plane, "xy" | "zx" | "yz"; None for other moves."""
    @property
    def sweep(self) -> _FloatArray:
        """Signed arc sweeps (n,) [rad] about the plane's normal; 0 for other moves."""
    @property
    def dwell(self) -> _FloatArray:
        """Dwell times (n,) [s]; 0 for other moves."""
    @property
    def feed(self) -> _FloatArray:
        """Programmed feeds (n,) [m/s]; 0 for rapids and dwells."""
    @property
    def spindle(self) -> _FloatArray:
        """Spindle speeds (n,) [rev/s]; < 0 counter-clockwise (M4), 0 while off."""
    @property
    def tool(self) -> npt.NDArray[np.uint32]:
        """The tool in the spindle at each move (n,); 0 for none."""
    @property
    def tools(self) -> List[int]:
        """The tool numbers the moves use, ascending."""
    @property
    def path_control(self) -> List[str]:
        """"G61", "G61.1" or "G64" per move."""
    @property
    def blend_tolerance(self) -> _FloatArray:
        """The G64 P tolerance of each move (n,) [m]."""
    @property
    def length(self) -> _FloatArray:
        """Path lengths (n,) [m]."""
    @property
    def cutting_length(self) -> float:
        """Total length of the feed moves [m]."""
    @property
    def words(self) -> List[Tuple[str, str, int, int, str]]:
        """Every word the program uses: (word, status, count, first_line, meaning)."""

def gcode_words(text: str, *, dialect: str = "linuxcnc") -> List[Tuple[str, str, int, int, str]]:
    """The word report of a program's text (also of one the reader refuses)."""

@final
class ToolTable:
    """Tools by number: cutter, end shape, length, name (LinuxCNC .tbl or TOML)."""
    @staticmethod
    def from_file(
        path: _StrPath, *, units: str = "mm", flutes: int = 3, helix: float = 0.0
    ) -> "ToolTable":
        """Reads a .tbl (or a .toml table)."""
    @staticmethod
    def from_text(
        text: str, *, format: str = "tbl", units: str = "mm", flutes: int = 3, helix: float = 0.0
    ) -> "ToolTable":
        """Same as ``from_file``, from the text; ``format`` "tbl" | "toml"."""
    def __reduce__(self) -> Tuple[Any, Tuple[Any]]:
        """Pickling and copy.deepcopy: the tools as plain values."""
    @staticmethod
    def _from_state(state: Any) -> "ToolTable": ...
    def __eq__(self, value: object, /) -> bool: ...
    __hash__: ClassVar[None]  # type: ignore[assignment]
    def __len__(self) -> int: ...
    @property
    def numbers(self) -> List[int]:
        """The tool numbers, ascending."""
    @property
    def tools(self) -> List[Tuple[int, float, int, float, str, float, float, str]]:
        """(number, diameter [m], flutes, helix [rad], shape, corner radius [m], length [m], name)."""

@final
class MachiningJob:
    """A robot-machining job without its program: arm, workpiece placement, tool, material,
    stock and how the program is driven (see the class docstring of the module)."""
    def __new__(
        cls,
        robot: SerialRobot,
        placement: _ArrayLike,
        *,
        stock_min: _ArrayLike,
        stock_max: _ArrayLike,
        stock_top: float = 0.0,
        cell: float = 0.0005,
        tool_orientation: Optional[_ArrayLike] = None,
        diameter: float = 0.016,
        flutes: int = 3,
        helix: float = 0.0,
        coefficients: Optional[_ArrayLike] = None,
        rate_hz: float = 250.0,
        acceleration: float = 2.0,
        jerk: float = 20.0,
        rapid_speed: float = 0.25,
        corner_angle: float = 0.017453292519943295,
        blending: Union[str, float] = "stop",
        tools: Union[ToolTable, _StrPath, None] = None,
        spindle_rpm: Optional[float] = None,
        rapid_skim: float = 0.0001,
        spin: Union[str, float] = "keep",
        spin_step: float = 5.0,
        spin_rate: Tuple[float, float] = (1.0, 30.0),
        spin_measure: str = "normal",
    ) -> Self: ...
    def run(self, program: GcodeProgram, seed: _ArrayLike) -> "MachiningResult":
        """The offline pass: forces, deflection, compensated joints, the part three ways."""
    def run_five_axis(
        self,
        program: GcodeProgram,
        seed: _ArrayLike,
        depth: float = 0.05,
        shape: str = "flat",
        corner_radius: Optional[float] = None,
        length: float = 0.03,
        slices: int = 32,
        angles: int = 180,
    ) -> "FiveAxisResult":
        """The five-axis pass: the program's tool axis, the cutter's force along its edge on a
        tri-dexel stock, tip and tilt compensated, the parts cut in 3-D."""
    def with_inertia(
        self,
        mass: float,
        com: Optional[_ArrayLike] = None,
        inertia: Optional[_ArrayLike] = None,
        links: bool = False,
    ) -> "MachiningJob":
        """The job with the tool and spindle's inertia (mass [kg], com (3,) [m], inertia (3, 3)
        [kg m^2], TCP frame) and, with links, the link masses' loads in the planned motion."""
    def __reduce__(self) -> Tuple[Any, Tuple[Any]]:
        """Pickling and copy.deepcopy: the robot and the setup, rebuilt bit for bit."""
    @staticmethod
    def _from_state(state: Any) -> "MachiningJob": ...
    def __eq__(self, value: object, /) -> bool: ...
    __hash__: ClassVar[None]  # type: ignore[assignment]

@final
class PlacementProblem:
    """A placement search's problem: a job (its spin setting: "keep" or "optimize"), a
    program and the seed joints; the program's nominal forces computed once."""
    def __new__(cls, job: MachiningJob, program: GcodeProgram, seed: _ArrayLike) -> Self: ...
    def evaluate(self, params: _ArrayLike, threads: Optional[int] = None) -> _FloatArray:
        """Scores (m, 3) of placements (m, 4): RMS, largest deflection [m], line."""
    def placement(self, params: _ArrayLike) -> _FloatArray:
        """The workpiece frame (4, 4) of a placement (x, y, z, yaw)."""
    def _search(
        self,
        box_min: _ArrayLike,
        box_max: _ArrayLike,
        steps: Sequence[int],
        refine: int,
        evaluate: Optional[Any] = None,
    ) -> Tuple[_FloatArray, _FloatArray, _FloatArray, _FloatArray, int]: ...
    @property
    def size(self) -> Tuple[int, int, int]:
        """Samples of the run, of them cutting, stations of the search."""
    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]:
        """Pickling: the job, the loads as bytes, the seed."""
    @staticmethod
    def _from_state(job: MachiningJob, loads: bytes, seed: List[float]) -> "PlacementProblem": ...

@final
class FiveAxisResult:
    """What MachiningJob.run_five_axis predicts: samples as arrays, the tools' errors, the
    parts' machined surfaces with the deviation along the normal."""
    def __len__(self) -> int: ...
    @property
    def time(self) -> npt.NDArray[np.float64]: ...
    @property
    def line(self) -> npt.NDArray[np.uint64]: ...
    @property
    def bands(self) -> npt.NDArray[np.uint64]: ...
    @property
    def spin(self) -> npt.NDArray[np.float64]: ...
    @property
    def position(self) -> npt.NDArray[np.float64]: ...
    @property
    def axis(self) -> npt.NDArray[np.float64]: ...
    @property
    def force(self) -> npt.NDArray[np.float64]: ...
    @property
    def wrench(self) -> npt.NDArray[np.float64]: ...
    @property
    def q(self) -> npt.NDArray[np.float64]: ...
    @property
    def q_commanded(self) -> npt.NDArray[np.float64]: ...
    @property
    def uncompensated_tip(self) -> npt.NDArray[np.float64]: ...
    @property
    def uncompensated_axis(self) -> npt.NDArray[np.float64]: ...
    @property
    def compensated_tip(self) -> npt.NDArray[np.float64]: ...
    @property
    def compensated_axis(self) -> npt.NDArray[np.float64]: ...
    @property
    def ray_updates(self) -> int: ...
    @property
    def rapid_volume(self) -> float: ...
    def errors(self, part: str) -> Dict[str, Any]:
        """max_position, rms_position [m], max_axis [rad], line over the cutting samples."""
    def surface(self, part: str = "compensated", reach: Optional[float] = None) -> Dict[str, Any]:
        """position, normal, deviation [m], face, unmatched of the machined surface."""
    def write_ply(
        self,
        path: Union[str, "PathLike[str]"],
        part: str = "compensated",
        reach: Optional[float] = None,
        ascii: bool = False,
    ) -> None:
        """The machined surface as a PLY mesh, the deviation as each vertex's quality."""

@final
class MachiningResult:
    """What ``MachiningJob.run`` predicts, SI, workpiece frame unless said."""
    def __len__(self) -> int: ...
    @property
    def time(self) -> _FloatArray:
        """Sample times (n,) [s]."""
    @property
    def line(self) -> npt.NDArray[np.uint64]:
        """Program line of each sample (n,)."""
    @property
    def rapid_contact(self) -> Optional[Tuple[int, float, float]]:
        """The deepest rapid contact with the stock: (line, time [s], depth [m]), or None."""
    @property
    def tool(self) -> npt.NDArray[np.uint32]:
        """The tool in the spindle at each sample (n,)."""
    @property
    def spindle(self) -> _FloatArray:
        """The program's spindle speed at each sample (n,) [rev/s]."""
    @property
    def position(self) -> _FloatArray:
        """Programmed tool tip (n, 3) [m]."""
    @property
    def direction(self) -> _FloatArray:
        """Unit feed direction of the programmed tool (n, 3)."""
    @property
    def engagement(self) -> _FloatArray:
        """(n, 3): first entry, last exit [rad], mean depth [m]; NaN off the side-milling cut."""
    @property
    def feed_per_tooth(self) -> _FloatArray:
        """Feed per tooth (n,) [m]."""
    @property
    def force(self) -> _FloatArray:
        """Per-revolution force on the tool, nominal cut (n, 3) [N]."""
    @property
    def force_uncompensated(self) -> _FloatArray:
        """Force the uncompensated tool feels where it is (n, 3) [N]."""
    @property
    def force_compensated(self) -> _FloatArray:
        """Force the compensated tool feels where it is (n, 3) [N]."""
    @property
    def coupling_residual(self) -> _FloatArray:
        """The last step of each prediction's force-deflection coupling (n, 2) [m]
        (uncompensated, compensated): at most 1e-8 m where the fixed point converged."""
    @property
    def deviations(self) -> List[Tuple[int, float, str]]:
        """Program lines where the compensated prediction leaves the program by more than
        1 um: `(line, largest distance [m], reason)`, reason "coupling" or "stock"."""
    @property
    def operations(self) -> List[Tuple[str, int, int, float, float, float]]:
        """Per operation `(name, first_line, samples, max_force [N],
        path_error_uncompensated [m], path_error_compensated [m])`."""
    @property
    def wrench(self) -> _FloatArray:
        """TCP wrench (n, 6) [N, N m], base frame, about the tool tip."""
    @property
    def deflection(self) -> _FloatArray:
        """Deflection [dp; dr] of the tip (n, 6) [m, rad], base frame."""
    @property
    def deflection_inertial(self) -> _FloatArray:
        """The inertial part of the deflection at q (n, 6) [m, rad], base frame."""
    @property
    def inertial_wrench(self) -> _FloatArray:
        """The tool and spindle's D'Alembert wrench (n, 6) [N, N m], base frame."""
    @property
    def tool_acceleration(self) -> _FloatArray:
        """The tool's planned acceleration (n, 3) [m/s^2]."""
    @property
    def q(self) -> _FloatArray:
        """Rigid pose-IK joints of the programmed path (n, dof)."""
    @property
    def q_commanded(self) -> _FloatArray:
        """Compensated joints (n, dof): the axis-specific command."""
    @property
    def commanded(self) -> _FloatArray:
        """Commanded poses (n, 4, 4), workpiece frame: the Cartesian command."""
    @property
    def actual_uncompensated(self) -> _FloatArray:
        """Predicted tool tip without compensation (n, 3) [m]."""
    @property
    def actual_compensated(self) -> _FloatArray:
        """Predicted tool tip with compensation (n, 3) [m]."""
    @property
    def nominal_surface(self) -> _FloatArray:
        """The part as programmed, heights (ny, nx) [m]."""
    @property
    def uncompensated_surface(self) -> _FloatArray:
        """The part the uncompensated arm cuts (ny, nx) [m]."""
    @property
    def compensated_surface(self) -> _FloatArray:
        """The part the compensated arm cuts (ny, nx) [m]."""
    @property
    def surface_grid(self) -> Tuple[Tuple[float, float], float]:
        """((x, y) of cell (0, 0)'s lower corner [m], cell edge [m])."""
    @property
    def plunge_samples(self) -> int:
        """Samples plunging into material (no side-milling force there)."""
    def path_error(self, part: str = "uncompensated") -> Tuple[float, float]:
        """(max, rms) [m] of the predicted tip's distance from the program (feed moves)."""
    def surface_error(self, part: str = "uncompensated") -> Dict[str, float]:
        """Floors (``floor_max``, ``floor_rms`` [m], cells both cut, > 0: material left) and
        walls (``material_left``, ``overcut`` [m^2]: areas cut by one part and not the other)."""
    def pilot_wrenches(self, lead: float = 0.04) -> _FloatArray:
        """Pilot-control wrenches (n, 6), base frame, ``lead`` [s] ahead."""
    def compensated_gcode(self, tolerance: float = 1e-6) -> str:
        """The compensated program as G-code text (mm)."""
    def robot_program(
        self,
        kind: str,
        *,
        command: str = "cartesian",
        tolerance: float = 1e-6,
        joint_tolerance: float = 1e-6,
        acceleration: float = 1.2,
        tool_mass: float = 1.0,
        name: str = "deflect_job",
    ) -> Dict[str, str]:
        """The compensated job as the robot controller's program, ``{file name: text}`` (the
        main file first): ``kind`` "krl" (``.src`` + ``.dat``), "rapid" (``.mod``),
        "urscript" (``.script``) or "csv"; ``command`` "cartesian" (the commanded TCP within
        ``tolerance`` [m]) or "joints" (the compensated joints, within ``joint_tolerance``
        [rad] for KRL and RAPID, every sample for URScript and CSV). KRL, RAPID and URScript
        need the robot's ``[controller]`` convention (``InputError`` naming the robot)."""
    @property
    def spin(self) -> _FloatArray:
        """The tool's spin about its own axis at each sample (n,) [rad]."""
    @property
    def spin_plan(self) -> Optional[Dict[str, Any]]:
        """What ``spin="optimize"`` found: the predicted deflection (rms, max) [m] of the
        ``optimised`` schedule, the ``seed``'s constant spin and the ``best_constant`` one
        (``best_constant_spin`` [rad]), ``stations``, ``candidates``, ``refused``, ``measure``,
        ``schedule`` (k, 2): spin budget and spin [rad] per station. None without it."""
    def samples_csv(self, lead: float = 0.04) -> str:
        """Every sample as CSV text, the pilot wrench ``lead`` [s] ahead."""

def cutter_force(
    diameter: float,
    flutes: int,
    bands: _ArrayLike,
    feed: _ArrayLike,
    *,
    shape: str = "flat",
    corner_radius: Optional[float] = None,
    helix: float = 0.0,
    coefficients: Optional[_ArrayLike] = None,
    angles: Optional[_ArrayLike] = None,
) -> Tuple[_FloatArray, _FloatArray]:
    """Force [N] and moment about the tip [N m] of a flat, ball or bull-nose cutter, tool
    frame: the revolution's mean (3,), (3,), or (m, 3), (m, 3) at ``angles``."""

def milling_force(
    diameter: float,
    flutes: int,
    depth: float,
    feed_per_tooth: float,
    *,
    entry: float = 0.0,
    exit: float = 3.141592653589793,
    helix: float = 0.0,
    coefficients: Optional[_ArrayLike] = None,
    angles: Optional[_ArrayLike] = None,
    discs: int = 1,
) -> _FloatArray:
    """Milling force [N], tool frame: the per-revolution average (3,), or (m, 3) at ``angles``."""
