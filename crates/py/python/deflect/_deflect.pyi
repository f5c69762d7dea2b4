"""Type stubs of the compiled extension ``deflect._deflect``."""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]
StrPath = Union[str, PathLike]

class DeflectError(ValueError): ...
class LoadError(DeflectError): ...
class InputError(DeflectError):
    """Wrong shape, dtype (complex, object, string arrays) or value (NaN/inf, out of range,
    negative or huge counts, budgets exceeded); the message names the argument."""
class SingularError(DeflectError): ...
class ConvergenceError(DeflectError): ...

class SerialRobot:
    """A serial robot with virtual joints (VJM paper, Eq. 1-9). SI units, base frame."""

    def __reduce__(self) -> Tuple[Any, Tuple[Any]]:
        """Pickling and copy.deepcopy: the chain as plain values, rebuilt bit for bit."""
    @staticmethod
    def _from_state(state: Any) -> "SerialRobot": ...

    @staticmethod
    def from_urdf(
        urdf_path: StrPath, stiffness_path: StrPath, tip_link: str, base_link: Optional[str] = None
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
    def forward(self, q: ArrayLike) -> FloatArray:
        """Rigid TCP pose, (4, 4)."""
    def deflection(self, q: ArrayLike, wrench: ArrayLike) -> FloatArray:
        """[dx, dy, dz, rx, ry, rz] [m, rad] under wrench [Fx, Fy, Fz, Mx, My, Mz] [N, N m].
        ``InputError`` for a load that turns a virtual joint beyond the small-deflection model."""
    def spring_angles(self, q: ArrayLike, wrench: ArrayLike) -> FloatArray:
        """(n_springs, 3) elastic angles [rad] (Eq. 7)."""
    def compliance(self, q: ArrayLike) -> FloatArray:
        """(6, 6) Cartesian compliance of the linearized model."""
    def joint_jacobian(self, q: ArrayLike) -> FloatArray:
        """(6, dof) actuated-joint Jacobian, rows [v; w]."""
    def joint_correction(
        self, q: ArrayLike, wrench: ArrayLike, max_iterations: int = 10, tolerance: float = 1e-12
    ) -> FloatArray:
        """(dof,) axis-specific correction. ``max_iterations`` 0..=256 and ``tolerance`` finite
        and >= 0 (``InputError`` otherwise); ``ConvergenceError`` when the residual stays above
        ``tolerance`` (the message says whether the iteration stalled at its fixed point)."""
    def deflection_batch(self, Q: ArrayLike, W: ArrayLike) -> FloatArray:
        """(N, dof), (N, 6) -> (N, 6); releases the GIL."""
    def equilibrium(
        self, q: ArrayLike, wrench: ArrayLike, max_iterations: int = 20, tolerance: float = 1e-12
    ) -> FloatArray:
        """Deflection (6,) in static equilibrium (moments in the deflected pose), laid out as
        ``deflection``; Newton on the spring angles, ``ConvergenceError`` past the budget."""

def commanded_pose(target: ArrayLike, deflection: ArrayLike) -> FloatArray:
    """(4, 4) pose to command so that the deflected TCP lands on ``target``, a rigid transform
    (finite, bottom row 0 0 0 1, a proper rotation within 1e-9; ``InputError`` otherwise)."""

class ComplianceMap:
    """Compliance map from static tests (Paksoy et al. 2025, Eq. 9-14): per-node lines
    ``disp_d = sum_f (slope[d, f] * F_f + offset[d, f])`` blended bilinearly (Eq. 14) or with a
    C1 cubic Hermite interpolation. SI: positions m, forces N, displacements m.

    ``interpolation``: ``"bilinear"`` | ``"bicubic"``; ``out_of_grid``: ``"error"`` |
    ``"clamp"`` | ``"extrapolate"``. Bad input raises ``InputError``, bad files ``LoadError``.
    """

    @staticmethod
    def from_csv(
        path: StrPath,
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
        positions: ArrayLike,
        force_axis: ArrayLike,
        force: ArrayLike,
        displacement: Optional[ArrayLike] = None,
        *,
        upper: Optional[ArrayLike] = None,
        lower: Optional[ArrayLike] = None,
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
        path: StrPath,
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
    def save_json(self, path: StrPath) -> None:
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
        position: ArrayLike,
        force: ArrayLike,
        *,
        interpolation: Optional[str] = None,
        out_of_grid: Optional[str] = None,
    ) -> FloatArray:
        """(n_displacement,) [m] at position (2,) or (3,) [m] (z ignored) under force [N]."""
    def displacement_batch(
        self,
        P: ArrayLike,
        F: ArrayLike,
        *,
        interpolation: Optional[str] = None,
        out_of_grid: Optional[str] = None,
    ) -> FloatArray:
        """(N, 2|3), (N, n_force) -> (N, n_displacement); releases the GIL."""
    def cross_validate(self, forces: ArrayLike, axis: str = "y") -> Dict[str, Any]:
        """Leave-one-node-out RMS [m] of bilinear vs bicubic."""
    @property
    def residuals(self) -> Optional[List[Dict[str, Any]]]:
        """Per-node fit statistics, or None if the map was not fitted."""
    @property
    def x(self) -> FloatArray: ...
    @property
    def y(self) -> FloatArray: ...
    @property
    def n_force(self) -> int: ...
    @property
    def n_displacement(self) -> int: ...
    @property
    def interpolation(self) -> str: ...
    @property
    def out_of_grid(self) -> str: ...
    @property
    def slopes(self) -> FloatArray:
        """(nx, ny, n_displacement, n_force) [m/N]."""
    @property
    def offsets(self) -> FloatArray:
        """(nx, ny, n_displacement, n_force) [m]."""

Limit = Union[float, ArrayLike]

class Trajectory:
    """A motion in 1..=8 coordinates: a plan (exact at any t) with its ticks at ``rate_hz``
    (computed on first access; ``rate_hz`` None: plan only), or the user's own samples."""
    @staticmethod
    def from_samples(
        position: ArrayLike, rate_hz: float, acceleration: Optional[ArrayLike] = None
    ) -> "Trajectory":
        """(n, d) positions at ``rate_hz``; derivatives by second-order finite differences."""
    def at(self, t: Union[float, ArrayLike]) -> Dict[str, Any]:
        """State at ``t`` (a number or (m,)): t, position, velocity, acceleration, jerk."""
    def sampled(self, rate_hz: float) -> "Trajectory": ...
    @property
    def t(self) -> FloatArray: ...
    @property
    def position(self) -> FloatArray: ...
    @property
    def velocity(self) -> FloatArray: ...
    @property
    def acceleration(self) -> FloatArray: ...
    @property
    def jerk(self) -> FloatArray: ...
    @property
    def duration(self) -> float: ...
    @property
    def dim(self) -> int: ...
    @property
    def rate_hz(self) -> Optional[float]: ...
    @property
    def is_planned(self) -> bool: ...
    def __len__(self) -> int: ...

def plan_line(
    start: ArrayLike,
    end: ArrayLike,
    v_max: Limit,
    a_max: Limit,
    j_max: Limit,
    rate_hz: Optional[float] = 2000.0,
) -> Trajectory:
    """1..=8 coordinates; numbers limit the path (Euclidean norms), arrays each coordinate.
    At most 2**22 ticks: ``InputError`` (before allocating) for a longer motion or rate."""
def plan_polyline(
    points: ArrayLike,
    v_max: Optional[Limit] = None,
    a_max: Optional[Limit] = None,
    j_max: Optional[Limit] = None,
    rate_hz: Optional[float] = 2000.0,
    segment_limits: Optional[ArrayLike] = None,
) -> Trajectory:
    """(n, d) points; limits as ``plan_line`` or per segment, (n - 1, 3)."""
def paper_limits(g_level: int) -> Tuple[float, float, float]:
    """(v_max, a_max, j_max) reproducing the paper's motion durations at 1..5 g."""

class PoseTrajectory:
    """A 6-D rest-to-rest pose motion: straight line and a turn about a fixed axis, synchronised."""
    def at(self, t: Union[float, ArrayLike]) -> Dict[str, Any]:
        """t, pose (4, 4), velocity, acceleration, angular_velocity, angular_acceleration."""
    def sampled(self, rate_hz: float) -> "PoseTrajectory": ...
    @property
    def t(self) -> FloatArray: ...
    @property
    def pose(self) -> FloatArray: ...
    @property
    def velocity(self) -> FloatArray: ...
    @property
    def acceleration(self) -> FloatArray: ...
    @property
    def angular_velocity(self) -> FloatArray: ...
    @property
    def angular_acceleration(self) -> FloatArray: ...
    @property
    def start(self) -> FloatArray: ...
    @property
    def end(self) -> FloatArray: ...
    @property
    def axis(self) -> FloatArray: ...
    @property
    def angle(self) -> float: ...
    @property
    def duration(self) -> float: ...
    @property
    def rate_hz(self) -> Optional[float]: ...
    def __len__(self) -> int: ...

def plan_pose(
    start: ArrayLike,
    end: ArrayLike,
    linear: Tuple[float, float, float],
    angular: Tuple[float, float, float],
    rate_hz: Optional[float] = 2000.0,
) -> PoseTrajectory:
    """linear (v [m/s], a [m/s^2], j [m/s^3]), angular (w [rad/s], alpha [rad/s^2], [rad/s^3])."""

class ParallelRobot2:
    """The paper's 2-DoF planar parallel robot; p = C - O [m], q = (theta_A, theta_B) [rad]."""
    def __init__(self, link: float = 0.150, half_width: float = 0.090, min_sigma: float = 0.020) -> None: ...
    def __reduce__(self) -> Tuple[Any, Tuple[float, float, float]]:
        """Pickling and copy.deepcopy through the constructor arguments (exact)."""
    def ik(self, p: ArrayLike) -> FloatArray: ...
    def fk(self, q: ArrayLike) -> FloatArray: ...
    def jacobian(self, q: ArrayLike) -> FloatArray: ...
    def singularity_distance(self, q: ArrayLike) -> float: ...
    @property
    def reach(self) -> float: ...

class CorrectedPath:
    """Output of DalembertCorrector.correct: one row per tick."""
    t: FloatArray
    desired: FloatArray
    commanded: FloatArray
    joints: FloatArray
    force: FloatArray
    displacement: FloatArray
    flagged_ticks: List[int]
    @property
    def position(self) -> FloatArray:
        """The old name of ``commanded``."""

class DalembertCorrector:
    """D'Alembert correction of the paper's five-bar from a compliance map; for a serial arm,
    ``SerialDalembertCorrector``."""
    def __init__(
        self,
        compliance_map: ComplianceMap,
        mechanism: ParallelRobot2,
        mass: float = 5.0,
        iterations: int = 0,
        tolerance: float = 0.0,
    ) -> None: ...
    @property
    def mass(self) -> float: ...
    def step(
        self, position: ArrayLike, acceleration: ArrayLike, seed: Optional[ArrayLike] = None
    ) -> Dict[str, Any]:
        """One tick; the IK starts from the last tick's joints, or from ``seed`` (2,) [rad]."""
    def correct(self, trajectory: Trajectory) -> CorrectedPath: ...

class CorrectedPoses:
    """Output of SerialDalembertCorrector.correct: one row per tick, base frame."""
    t: FloatArray
    desired: FloatArray
    commanded: FloatArray
    joints: FloatArray
    wrench: FloatArray
    deflection: FloatArray
    iterations: npt.NDArray[np.uint32]
    position_error: FloatArray
    orientation_error: FloatArray

class SerialDalembertCorrector:
    """The 6-D D'Alembert corrector for a serial arm (a SerialRobot with >= 6 joints)."""
    def __init__(
        self,
        robot: SerialRobot,
        mass: float,
        com: Optional[ArrayLike] = None,
        inertia: Optional[ArrayLike] = None,
        model: str = "exact",
        joint_limits: Optional[ArrayLike] = None,
        max_iterations: int = 20,
        position_tolerance: float = 1e-8,
        orientation_tolerance: float = 1e-8,
        seed: Optional[ArrayLike] = None,
        link_inertia: bool = False,
        gravity: Optional[ArrayLike] = None,
    ) -> None: ...
    @property
    def dof(self) -> int: ...
    @property
    def joint_names(self) -> List[str]: ...
    @property
    def link_inertia(self) -> bool: ...
    @property
    def gravity(self) -> FloatArray: ...
    @property
    def mass(self) -> float: ...
    @property
    def model(self) -> str: ...
    @property
    def joints(self) -> FloatArray: ...
    def reset(self, q: ArrayLike) -> None: ...
    def step(
        self,
        pose: ArrayLike,
        velocity: Optional[ArrayLike] = None,
        acceleration: Optional[ArrayLike] = None,
        angular_velocity: Optional[ArrayLike] = None,
        angular_acceleration: Optional[ArrayLike] = None,
        process_wrench: Optional[ArrayLike] = None,
        t: Optional[float] = None,
    ) -> Dict[str, Any]:
        """One tick; ``step(**trajectory.at(t))`` works."""
    def correct(
        self, trajectory: PoseTrajectory, process_wrench: Optional[ArrayLike] = None
    ) -> CorrectedPoses: ...

class SensorCalibration:
    """Force/torque sensor calibration (VJM paper Eq. 12-20); SI units, sensor frame."""
    def __init__(
        self,
        force_offset: Optional[ArrayLike] = None,
        moment_offset: Optional[ArrayLike] = None,
        weight: float = 0.0,
        center_of_gravity: Optional[ArrayLike] = None,
        residual: Optional[ArrayLike] = None,
        sensor_to_tcp: Optional[ArrayLike] = None,
    ) -> None: ...
    @property
    def force_offset(self) -> FloatArray: ...
    @property
    def moment_offset(self) -> FloatArray: ...
    @property
    def weight(self) -> float: ...
    @property
    def center_of_gravity(self) -> FloatArray: ...
    @property
    def residual(self) -> FloatArray: ...
    @property
    def sensor_to_tcp(self) -> FloatArray: ...
    def unloaded_reading(self, rotation: ArrayLike) -> FloatArray: ...
    def compensate(self, reading: ArrayLike, rotation: ArrayLike) -> FloatArray:
        """Eq. 18."""
    def to_tcp_frame(self, wrench: ArrayLike) -> FloatArray:
        """Eq. 19-20."""
    def tcp_wrench_base(self, reading: ArrayLike, tcp: ArrayLike) -> FloatArray: ...

class LowPass:
    def __init__(self, cutoff_hz: float, dt: float) -> None: ...
    def step(self, x: ArrayLike) -> FloatArray: ...
    @property
    def alpha(self) -> float: ...
    @property
    def delay_samples(self) -> float: ...
    @property
    def delay_seconds(self) -> float: ...
    def reset(self) -> None: ...

class MovingAverage:
    def __init__(self, window: int, dt: float) -> None: ...
    def step(self, x: ArrayLike) -> FloatArray: ...
    @property
    def delay_samples(self) -> float: ...
    @property
    def delay_seconds(self) -> float: ...
    def reset(self) -> None: ...

class PilotControl:
    def __init__(self, threshold: float = 150.0, ramp: float = 0.08, dt: float = 0.004) -> None: ...
    def step(self, measured: ArrayLike, estimated: ArrayLike) -> FloatArray: ...
    @property
    def weight(self) -> float: ...
    def reset(self) -> None: ...

def project_normal_to_feed(r: ArrayLike, v: ArrayLike) -> Tuple[FloatArray, bool]:
    """Eq. 10-11."""

class OnlineCompensator:
    def __init__(
        self,
        robot: SerialRobot,
        dt: float = 0.004,
        calibration: Optional[SensorCalibration] = None,
        lowpass_cutoff_hz: float = 10.0,
        moving_average_window: int = 5,
        pilot: Optional[ArrayLike] = (150.0, 0.08),
        project_on_feed: bool = True,
        max_correction: float = 3.0e-3,
        max_rate: float = 0.05,
        output: str = "cartesian",
    ) -> None: ...
    @property
    def delay_samples(self) -> float: ...
    @property
    def delay_seconds(self) -> float: ...
    def step(
        self,
        q: ArrayLike,
        reading: ArrayLike,
        estimated: Optional[ArrayLike] = None,
        feed_velocity: Optional[ArrayLike] = None,
    ) -> Dict[str, Any]: ...
    def reset(self) -> None: ...

def identify_stiffness_from_tcp(
    robot: SerialRobot, Q: ArrayLike, W: ArrayLike, D: ArrayLike, translation_only: bool = False, all_axes: bool = False
) -> Dict[str, Any]:
    """At most 100000 measurements (``InputError`` beyond)."""
def identify_stiffness_from_frames(
    robot: SerialRobot, Q: ArrayLike, W: ArrayLike, springs: ArrayLike, rotations: ArrayLike, all_axes: bool = False
) -> Dict[str, Any]:
    """``springs``: (N,) virtual-joint indices. At most 100000 measurements."""
def identify_sensor(
    rotations: ArrayLike, readings: ArrayLike, fit_polynomial: bool = False, sensor_to_tcp: Optional[ArrayLike] = None
) -> Tuple[SensorCalibration, Dict[str, Any]]: ...

class DriveTrain:
    """Drive-train errors of a serial robot (contour-tracking paper, Eq. 3-13). Wrenches are the
    wrench the tool exerts on the environment (base frame); torques are drive torques."""
    def __init__(
        self,
        robot: SerialRobot,
        stiffness: ArrayLike,
        backlash: Optional[ArrayLike] = None,
        masses: Optional[Sequence[Tuple[int, float, ArrayLike]]] = None,
        gravity: Optional[ArrayLike] = None,
        torque_deadband: float = 0.0,
        max_condition: float = 1.0e6,
    ) -> None:
        """``gravity`` defaults to (0, 0, -9.80665) m/s^2 (standard gravity down base z)."""
    @staticmethod
    def from_urdf(robot: SerialRobot, urdf_path: StrPath, drive_path: StrPath) -> "DriveTrain": ...
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
    def gravity_torques(self, q: ArrayLike) -> FloatArray: ...
    def contact_torques(self, q: ArrayLike, wrench: ArrayLike) -> FloatArray: ...
    def joint_torques(self, q: ArrayLike, wrench: ArrayLike) -> FloatArray: ...
    def correct_joints(self, q: ArrayLike, wrench: ArrayLike) -> FloatArray:
        """Eq. 10: theta - sgn(u) theta_b - u / K."""
    def compensated_forward(self, q: ArrayLike, wrench: ArrayLike) -> FloatArray: ...
    def cartesian_stiffness(self, q: ArrayLike, planar: Optional[str] = None) -> FloatArray:
        """Eq. 12: K = J^-T K_theta J^-1 (6x6, or planar "xy" 2x2 / "xyrz" 3x3)."""

class ContourTracer:
    """Force-feedback contour tracing (Figures 3-4): step(position, force) -> (command, state)."""
    def __init__(
        self,
        stiffness: ArrayLike,
        step: float,
        contact_force: float,
        jam_force: float,
        *,
        target_force: Optional[float] = None,
        approach_direction: ArrayLike = (1.0, 0.0),
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
    ) -> None: ...
    def set_stiffness(self, stiffness: ArrayLike) -> None: ...
    def step(self, position: ArrayLike, force: ArrayLike) -> Tuple[FloatArray, str]: ...
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

def edge_direction(stiffness: ArrayLike, step: ArrayLike, force: ArrayLike) -> float:
    """Eq. 21: the edge angle from a commanded step and the steady-state force."""
def edge_contact_force(stiffness: ArrayLike, step: ArrayLike, edge_angle: float) -> FloatArray:
    """Eq. 16-20: the contact force of a step blocked by an edge."""
