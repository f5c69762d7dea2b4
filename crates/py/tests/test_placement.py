"""The placement search (deflect-core's ``machining::placement``) on the built-in job: the
same result, bit for bit, here on every core, on a process pool, a Dask cluster and Ray; the
search against an exhaustive grid at its finest spacing; the problem pickles with its loads;
bad boxes and settings are InputErrors."""

import pickle
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import deflect
from conftest import REPO
from test_machining_job import JOB_PLACEMENT, JOB_SEED

BOX = ((2.25, -0.2, 0.85, -0.3), (2.55, 0.2, 0.99, 0.3))


@pytest.fixture(scope="module")
def problems(kr300):
    program = deflect.GcodeProgram.from_file(REPO / "data/groove_and_pocket.nc", start=[0, 0, 0.02])
    make = lambda spin: deflect.MachiningJob(
        kr300, JOB_PLACEMENT, stock_min=(0.005, -0.015), stock_max=(0.085, 0.045), spin=spin
    )
    return {s: deflect.PlacementProblem(make(s), program, JOB_SEED) for s in ("keep", "optimize")}


def same(a, b):
    for name in a.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_the_search_matches_an_exhaustive_grid(problems):
    p = problems["keep"]
    found = deflect.place(p, BOX[0], BOX[1], (3, 3, 3, 3), refine=2)
    # The finest spacing the two rounds reach: a quarter of the grid's.
    axes = [np.linspace(lo, hi, 9) for lo, hi in zip(*BOX)]
    grid = np.array(np.meshgrid(*axes, indexing="ij")).reshape(4, -1).T
    scores = p.evaluate(grid)
    k = np.nanargmin(np.where(np.isfinite(scores[:, 0]), scores[:, 0], np.inf))
    assert found.best_rms <= scores[k, 0] * (1 + 1e-12), (found.best, grid[k])
    np.testing.assert_allclose(found.best, grid[k], atol=1e-12)
    assert found.evaluations < 81 + 2 * 8 + 1
    assert found.placement.shape == (4, 4)
    # The placement is the search's: the job's rotation turned by yaw, at (x, y, z).
    c, s = np.cos(found.best[3]), np.sin(found.best[3])
    turn = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    np.testing.assert_allclose(found.placement[:3, :3], turn @ JOB_PLACEMENT[:3, :3], atol=1e-12)
    np.testing.assert_allclose(found.placement[:3, 3], found.best[:3], atol=0)


def test_local_pool_dask_and_ray_agree_bit_for_bit(problems):
    p = problems["optimize"]
    steps = (2, 2, 1, 2)
    local = deflect.place(p, BOX[0], BOX[1], steps, refine=1)
    assert np.isfinite(local.rms).all()
    copy = pickle.loads(pickle.dumps(p))
    same(deflect.place(copy, BOX[0], BOX[1], steps, refine=1), local)
    with ProcessPoolExecutor(2) as pool:
        same(deflect.place(p, BOX[0], BOX[1], steps, refine=1, executor=pool, chunk_size=3), local)
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        same(deflect.place(p, BOX[0], BOX[1], steps, refine=1, executor=client, chunk_size=2), local)
    ray = pytest.importorskip("ray")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        got = deflect.place(p, BOX[0], BOX[1], steps, refine=1, executor=deflect.RayExecutor(), chunk_size=2)
    finally:
        ray.shutdown()
    same(got, local)


def test_the_optimised_spin_scores_at_most_the_seeds_everywhere(problems):
    grid = np.array([[2.4, 0.0, 0.92, 0.0], [2.3, 0.1, 0.9, 0.2], [2.5, -0.1, 0.95, -0.2]])
    keep, opt = problems["keep"].evaluate(grid), problems["optimize"].evaluate(grid)
    assert np.all(opt[:, 0] <= keep[:, 0] * (1 + 1e-9))


def test_bad_boxes_and_settings_are_refused(problems, kr300):
    p = problems["keep"]
    with pytest.raises(deflect.InputError, match="outside reach"):
        deflect.place(p, (6.0, 6.0, 0.9, 0.0), (7.0, 7.0, 0.9, 0.0), (2, 2, 1, 1))
    with pytest.raises(deflect.InputError, match="placement box"):
        deflect.place(p, (2.5, 0.0, 0.9, 0.0), (2.4, 0.0, 0.9, 0.0), (2, 1, 1, 1))
    with pytest.raises(deflect.InputError, match="placement box"):
        deflect.place(p, (2.4, 0.0, 0.9, float("nan")), (2.5, 0.0, 0.9, 0.0), (2, 1, 1, 1))
    with pytest.raises(deflect.InputError, match="steps"):
        deflect.place(p, BOX[0], BOX[1], (0, 1, 1, 1))
    with pytest.raises(deflect.InputError, match="chunk_size"):
        deflect.place(p, BOX[0], BOX[1], (1, 1, 1, 1), executor=object(), chunk_size=0)
    program = deflect.GcodeProgram.from_text("G0 X0 Y0 Z5\n", start=[0, 0, 0.02])
    constant = deflect.MachiningJob(kr300, JOB_PLACEMENT, stock_min=(0, 0), stock_max=(0.01, 0.01), spin=30.0)
    with pytest.raises(deflect.InputError, match="constant"):
        deflect.PlacementProblem(constant, program, JOB_SEED)
