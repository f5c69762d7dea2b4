"""Where to put the workpiece: the placement (position, and turn about the vertical) in a box
for the least predicted deflection along the whole program, on every local core or on a
cluster (deflect-core's ``machining::placement``).

A ``PlacementProblem`` holds the job, the program's nominal forces (computed once: they do
not depend on the placement) and the seed; ``place`` searches a grid over the box and refines
around its best point. Locally every batch runs in one call on every core with the GIL
released; with an ``executor`` (a ``concurrent.futures.Executor``, a Dask ``Client`` or
``deflect.atlas.RayExecutor``) each batch is cut into chunks, each sent (the problem pickles,
its loads as bytes) to a worker. Every way gives the same numbers, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, List, Optional, Sequence

import numpy as np

from ._deflect import InputError, PlacementProblem
from .atlas import _as_executor, _gather

__all__ = ["PlacementProblem", "PlacementResult", "place"]

#: Placements per chunk sent to a worker when ``chunk_size`` is not given (each costs the IK
#: and compliance along the program: milliseconds to a second).
DEFAULT_CHUNK = 8


@dataclass(frozen=True)
class PlacementResult:
    """The grid's placements and scores, and the best placement after the refinement.

    A placement is ``(x, y, z, yaw)``: the workpiece origin in the base frame [m] and the
    turn [rad] about the base's vertical of the job's own placement's rotation. Scores: RMS
    and largest predicted deflection [m] over the cutting samples (``inf`` where the arm
    cannot follow the program; ``line`` names where, 0 elsewhere)."""

    params: np.ndarray  #: (N, 4) the grid's placements, x fastest, then y, z, yaw
    rms: np.ndarray  #: (N,) [m]
    max: np.ndarray  #: (N,) [m]
    line: np.ndarray  #: (N,) int
    best: np.ndarray  #: (4,) the best placement
    best_rms: float  #: [m]
    best_max: float  #: [m]
    placement: np.ndarray  #: (4, 4) the best workpiece frame in the base frame
    evaluations: int  #: placements scored (grid and refinement)


def _evaluate_chunk(problem: PlacementProblem, params: np.ndarray) -> np.ndarray:
    """A chunk on a worker (a plain function: Ray's ``remote`` takes no builtins)."""
    return problem.evaluate(params)


def _check_chunk(chunk_size: Optional[int]) -> int:
    if chunk_size is None:
        return DEFAULT_CHUNK
    if isinstance(chunk_size, bool) or not (isinstance(chunk_size, (int, np.integer)) and chunk_size >= 1):
        raise InputError(f"chunk_size: expected an integer >= 1 (or None for {DEFAULT_CHUNK}), got {chunk_size!r}")
    return int(chunk_size)


def place(
    problem: PlacementProblem,
    box_min: Sequence[float],
    box_max: Sequence[float],
    steps: Sequence[int] = (5, 5, 1, 1),
    *,
    refine: int = 3,
    executor: Any = None,
    chunk_size: Optional[int] = None,
) -> PlacementResult:
    """The placement of least predicted deflection in ``[box_min, box_max]`` (each ``(x, y,
    z, yaw)``, m and rad): a grid of ``steps`` points per axis (1: the axis' middle), then
    ``refine`` rounds of a compass search around the best point (half the spacing each
    round). Without ``executor`` the batches run here on every core; with one they go out in
    chunks of ``chunk_size`` placements (None: ``DEFAULT_CHUNK``) and come back in order; a
    failed chunk raises ``ChunkError``. A box from which the arm follows the program nowhere
    raises ``InputError``."""
    size = _check_chunk(chunk_size)
    try:
        steps4 = [int(s) for s in steps]
    except (TypeError, ValueError) as e:
        raise InputError(f"steps: expected 4 integers >= 1, got {steps!r}") from e
    if len(steps4) != 4 or any(s < 1 for s in steps4):
        raise InputError(f"steps: expected 4 integers >= 1, got {steps!r}")
    evaluate = None
    if executor is not None:
        pool = _as_executor(executor)

        def evaluate(params: np.ndarray) -> np.ndarray:
            chunks: List[range] = [range(a, min(a + size, len(params))) for a in range(0, len(params), size)]
            parts = _gather(pool, _evaluate_chunk, chunks, lambda r: (problem, params[r.start : r.stop]), "placement")
            return np.concatenate(parts) if parts else np.zeros((0, 3))

    grid, scores, best, score, evaluations = problem._search(box_min, box_max, steps4, int(refine), evaluate)
    return PlacementResult(
        params=grid,
        rms=scores[:, 0].copy(),
        max=scores[:, 1].copy(),
        line=scores[:, 2].astype(np.int64),
        best=best,
        best_rms=float(score[0]),
        best_max=float(score[1]),
        placement=problem.placement(best),
        evaluations=int(evaluations),
    )
