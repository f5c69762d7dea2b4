"""Workspace compliance atlas: the stiffness-optimal posture at many tasks, on every local core
or on a cluster.

For every task (a TCP position, a tool axis, a process wrench) the rotation about the tool axis
is swept and the posture that deflects least is kept (``deflect.posture_sweep``, deflect-core's
``posture::sweep``). Locally the tasks run in one call on every core with the GIL released;
with an ``executor`` they are cut into chunks, each sent (the robot pickles) to a worker, and
put back together in order. Any ``concurrent.futures.Executor`` works (``ProcessPoolExecutor``,
a Dask ``Client`` or its ``get_executor()``, ``RayExecutor`` below); every way gives the same
numbers, bit for bit.
"""

from __future__ import annotations

import importlib
from concurrent.futures import Executor, Future
from dataclasses import dataclass
from typing import Any, Callable, List, Optional

import numpy as np

from ._deflect import DeflectError, SerialRobot, _atlas_chunk

__all__ = ["AtlasResult", "ChunkError", "RayExecutor", "atlas"]

#: Tasks per chunk sent to a worker when ``chunk_size`` is not given: about 0.1-1 s of work
#: per chunk for a 360-angle sweep, long enough to hide the scheduling cost of Dask or Ray
#: (~1 ms a task) and short enough to keep every worker busy to the end.
DEFAULT_CHUNK = 256

#: The point statuses in the order of their codes in a chunk's rows.
_STATUS = ("reachable", "out_of_reach", "singular", "joint_limit", "beyond_model")
_STATUS_TEXT = {
    "out_of_reach": "out of reach",
    "singular": "only singular postures",
    "joint_limit": "only postures past a joint limit",
    "beyond_model": "in reach but beyond the model's validity (a spring past MAX_SPRING_ANGLE)",
}


class ChunkError(DeflectError):
    """A chunk of an atlas (or a placement search) failed on its worker (a killed process, a lost node, an error
    raised there). The message names the chunk and its rows; no partial result is returned."""

    def __init__(self, chunk: int, rows: range, cause: BaseException, what: str = "atlas"):
        self.chunk = chunk
        self.rows = rows
        super().__init__(
            f"{what} chunk {chunk} (tasks {rows.start}..{rows.stop - 1}) failed: "
            f"{type(cause).__name__}: {cause}"
        )


@dataclass(frozen=True)
class AtlasResult:
    """Per task (N of them): whether any posture reaches it, and the best and worst ones.

    Tasks without a posture have ``reachable`` False and NaN everywhere else (never
    zeros); ``status`` says why: ``'out_of_reach'``, ``'singular'``, ``'joint_limit'``, or
    ``'beyond_model'`` (postures exist, but the wrench turns a spring past
    ``MAX_SPRING_ANGLE``, outside the small-deflection model: the task is reachable, its
    deflection cannot be predicted).
    Angles in rad about the tool axis (``deflect.posture_sweep``'s convention), measures and
    deflections in m (and rad for the rotational part), compliance in m/N, rad/(N m)."""

    reachable: np.ndarray  #: (N,) bool
    reachable_angles: np.ndarray  #: (N,) int: angles of the sweep with a posture
    best_angle: np.ndarray  #: (N,) [rad]
    best_measure: np.ndarray  #: (N,) [m]
    best_deflection: np.ndarray  #: (N, 6) [m, rad], base frame
    best_q: np.ndarray  #: (N, dof) [rad or m]
    worst_angle: np.ndarray  #: (N,) [rad]
    worst_measure: np.ndarray  #: (N,) [m]
    compliance: np.ndarray  #: (N, 6, 6) at the best posture
    best_seed: np.ndarray  #: (N,) int: the seed (IK branch) of the best posture, -1 if none
    #: (N,) str: 'reachable', 'out_of_reach', 'singular', 'joint_limit' or 'beyond_model'
    status: np.ndarray
    beyond_model_angles: np.ndarray  #: (N,) int: angles with a posture beyond the model

    def summary(self) -> str:
        """One line: how many tasks are reachable, and why the others are not."""
        names, counts = np.unique(self.status, return_counts=True)
        why = ", ".join(
            f"{c} {_STATUS_TEXT[str(k)]}" for k, c in zip(names, counts) if k != "reachable"
        )
        n = len(self.status)
        return f"reachable: {int(self.reachable.sum())} of {n}" + (f"; {why}" if why else "")

    @staticmethod
    def _from_rows(rows: np.ndarray, dof: int) -> "AtlasResult":
        n = rows.shape[0]
        code = rows[:, 0].astype(np.int64)
        reachable = code == 0
        seed = rows[:, 10 + dof + 38]
        return AtlasResult(
            reachable=reachable,
            reachable_angles=rows[:, 1].astype(np.int64),
            best_angle=rows[:, 2].copy(),
            best_measure=rows[:, 3].copy(),
            best_deflection=rows[:, 4:10].copy(),
            best_q=rows[:, 10 : 10 + dof].copy(),
            worst_angle=rows[:, 10 + dof].copy(),
            worst_measure=rows[:, 11 + dof].copy(),
            compliance=rows[:, 12 + dof : 48 + dof].reshape(n, 6, 6).copy(),
            best_seed=np.where(reachable, np.nan_to_num(seed, nan=-1.0), -1.0).astype(np.int64),
            status=np.array(_STATUS, dtype=object)[code].astype(str),
            beyond_model_angles=rows[:, 10 + dof + 39].astype(np.int64),
        )


class RayExecutor(Executor):
    """``concurrent.futures`` on Ray: ``submit`` runs the function as a Ray task and returns
    its ``concurrent.futures.Future``. Needs ``ray`` (``pip install deflect-robotics[ray]``)
    and an initialised Ray (``ray.init(...)``, or a cluster address)."""

    def __init__(self, **options: Any):
        try:
            # Imported by name: Ray is optional, and type checkers (mypy, stubtest) must not
            # need it where it is not installed.
            ray = importlib.import_module("ray")
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError(
                "RayExecutor needs Ray: pip install 'deflect-robotics[ray]'"
            ) from e
        self._ray: Any = ray
        self._options = options
        self._remote: dict = {}

    def submit(self, fn: Callable, /, *args: Any, **kwargs: Any) -> Future:  # type: ignore[override]
        """Runs ``fn(*args, **kwargs)`` as a Ray task; its result arrives in the future."""
        remote = self._remote.get(fn)
        if remote is None:
            remote = self._ray.remote(**self._options)(fn) if self._options else self._ray.remote(fn)
            self._remote[fn] = remote
        return remote.remote(*args, **kwargs).future()


def _real_array(a: Any, what: str) -> np.ndarray:
    """``a`` as float64, refusing what is not real numbers (complex would lose its imaginary
    part with a warning only), as the compiled functions do."""
    from ._deflect import InputError

    try:
        x = np.asarray(a)
    except ValueError as e:
        raise InputError(f"{what}: not an array of numbers ({e})") from e
    if x.dtype.kind not in "biuf":
        raise InputError(
            f"{what}: expected an array of real numbers (float, int or bool dtype), got dtype "
            f"{x.dtype} with shape {x.shape}"
        )
    return x.astype(np.float64, copy=False)


def _run_chunk(*args: Any, **kwargs: Any) -> np.ndarray:
    """The chunk kernel as a plain Python function (Ray's ``remote`` takes no builtins);
    workers import it by name."""
    return _atlas_chunk(*args, **kwargs)


def _gather(
    pool: Executor, fn: Callable, chunks: List[range], args: Callable[[range], tuple], what: str, kwargs: Optional[dict] = None
) -> list:
    """Submits ``fn(*args(chunk), **kwargs)`` for every chunk and gathers the results in order;
    a chunk that fails (at submission or on its worker) raises ``ChunkError`` naming it, the
    chunks not yet run cancelled."""
    futures: List[Future] = []
    for k, r in enumerate(chunks):
        try:
            futures.append(pool.submit(fn, *args(r), **(kwargs or {})))
        except Exception as e:  # a broken pool refuses at submission
            for f in futures:
                f.cancel()
            raise ChunkError(k, r, e, what) from e
    parts = []
    for k, (r, f) in enumerate(zip(chunks, futures)):
        try:
            parts.append(f.result())
        except Exception as e:
            for g in futures[k + 1 :]:
                g.cancel()
            raise ChunkError(k, r, e, what) from e
    return parts


def _as_executor(executor: Any) -> Executor:
    """A Dask ``Client`` gives its executor; anything with ``submit`` is used as it is."""
    if hasattr(executor, "get_executor") and not isinstance(executor, Executor):
        # Every call computes (Dask would otherwise hand back an earlier call's futures for
        # equal arguments, a cache the caller did not ask for).
        return executor.get_executor(pure=False)
    if not hasattr(executor, "submit"):
        raise TypeError(
            f"executor: expected a concurrent.futures.Executor, a dask.distributed.Client or "
            f"deflect.atlas.RayExecutor, got {type(executor).__name__}"
        )
    return executor


def atlas(
    robot: SerialRobot,
    positions: Any,
    tool_axes: Any,
    wrenches: Any,
    *,
    angles: Any = None,
    seeds: Any = None,
    measure: Any = None,
    refine: bool = True,
    min_sigma: float = 1e-3,
    executor: Any = None,
    chunk_size: Optional[int] = None,
) -> AtlasResult:
    """The stiffness-optimal posture at every task.

    ``positions`` (N, 3) [m], ``tool_axes`` (N, 3) or (3,) and ``wrenches`` (N, 6) or (6,)
    [N, N m] (a single row broadcasts), all in the robot's base frame; ``angles``, ``seeds``,
    ``measure``, ``refine`` and ``min_sigma`` as ``deflect.posture_sweep``. Without
    ``executor`` the tasks run here on every core (GIL released). With one (a
    ``concurrent.futures.Executor``, a ``dask.distributed.Client``, or ``RayExecutor()``),
    they go out in chunks of ``chunk_size`` tasks (an integer >= 1; None for
    ``DEFAULT_CHUNK`` = 256; checked even without an executor) and come back in order; a
    failed chunk raises ``ChunkError`` naming it. Bad input raises ``deflect.InputError``
    before anything is sent.
    """
    from ._deflect import InputError

    # chunk_size is checked whether or not an executor uses it: a wrong value is a mistake
    # either way (0 is not "automatic": None is).
    if chunk_size is None:
        chunk_size = DEFAULT_CHUNK
    elif isinstance(chunk_size, bool) or not (
        isinstance(chunk_size, (int, np.integer)) and chunk_size >= 1
    ):
        raise InputError(
            f"chunk_size: expected an integer >= 1 (or None for {DEFAULT_CHUNK}), "
            f"got {chunk_size!r}"
        )
    p = _real_array(positions, "positions")
    if p.ndim != 2 or p.shape[1] != 3:
        raise InputError(f"positions: expected shape (N, 3), got {p.shape}")
    n = p.shape[0]
    options = dict(angles=angles, seeds=seeds, measure=measure, refine=refine, min_sigma=min_sigma)
    dof = robot.dof
    if executor is None:
        return AtlasResult._from_rows(_atlas_chunk(robot, p, tool_axes, wrenches, **options), dof)
    t = _real_array(tool_axes, "tool_axes")
    w = _real_array(wrenches, "wrenches")
    # Validate everything here, on one task, before any work is sent out.
    _atlas_chunk(robot, p[:0], t if t.ndim == 1 else t[:0], w if w.ndim == 1 else w[:0], **options)
    if t.ndim == 2 and t.shape[0] != n or w.ndim == 2 and w.shape[0] != n:
        raise InputError(
            f"positions, tool_axes, wrenches: {n}, {t.shape[0] if t.ndim == 2 else 1} and "
            f"{w.shape[0] if w.ndim == 2 else 1} rows do not broadcast together"
        )
    pool = _as_executor(executor)
    chunks: List[range] = [range(a, min(a + chunk_size, n)) for a in range(0, n, chunk_size)]

    def args(r: range) -> tuple:
        sl = slice(r.start, r.stop)
        return (robot, p[sl], t[sl] if t.ndim == 2 else t, w[sl] if w.ndim == 2 else w)

    parts = _gather(pool, _run_chunk, chunks, args, "atlas", options)
    rows = np.concatenate(parts) if parts else np.zeros((0, 50 + dof))
    return AtlasResult._from_rows(rows, dof)
