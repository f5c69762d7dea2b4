"""Corner blending from Python: the blended path stays within its tolerance of the programmed
corner (distance to the polyline by numpy) and is faster than the exact stop, the program's
G64 P is the same tolerance given directly, the choice survives pickling, and bad values
raise."""

import pickle

import numpy as np
import pytest

import deflect
from conftest import KR300_POSE
from test_machining_job import slot_job

# An L in air 5 mm above the stock at 3 m/min: (-10, 0) -> (20, 0) -> (20, 20) mm.
L_PATH = "G0 X-10 Y0 Z5\nG1 X20 F3000\nY20\n"
CORNERS = np.array([[-0.01, 0.0], [0.02, 0.0], [0.02, 0.02]])


def program(text=L_PATH):
    return deflect.GcodeProgram.from_text(text, start=[-0.01, 0.0, 0.005])


def polyline_distance(xy):
    """Each point's distance [m] to the nearest of the L's two segments."""
    best = np.full(len(xy), np.inf)
    for a, b in zip(CORNERS[:-1], CORNERS[1:]):
        d = b - a
        t = np.clip((xy - a) @ d / (d @ d), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(xy - (a + t[:, None] * d), axis=1))
    return best


def test_a_blend_stays_within_its_tolerance_and_is_faster(kr300):
    stop = slot_job(kr300).run(program(), KR300_POSE)
    blend = slot_job(kr300, blending=1e-4).run(program(), KR300_POSE)
    # The exact stop is on the polyline; the blend leaves it (by microns: the distance to the
    # polyline is the smaller of the two runs' cubic ramp distances), never by more than 0.1 mm.
    assert polyline_distance(stop.position[:, :2]).max() < 1e-9
    off = polyline_distance(blend.position[:, :2])
    assert 1e-6 < off.max() <= 1e-4 * (1 + 1e-9)
    assert blend.time[-1] < stop.time[-1] - 0.01


def test_g64_p_is_the_same_tolerance_and_g61_stops(kr300):
    given = slot_job(kr300, blending=1e-4).run(program(), KR300_POSE)
    from_program = slot_job(kr300, blending="program").run(program("G64 P0.1\n" + L_PATH), KR300_POSE)
    np.testing.assert_array_equal(given.position, from_program.position)
    stop = slot_job(kr300).run(program(), KR300_POSE)
    exact = slot_job(kr300, blending="program").run(program("G61\n" + L_PATH), KR300_POSE)
    np.testing.assert_array_equal(stop.position, exact.position)


def test_blending_survives_pickling(kr300):
    for choice in ("stop", "program", 2e-4):
        job = slot_job(kr300, blending=choice)
        back = pickle.loads(pickle.dumps(job))
        text = "G64 P0.2\n" + L_PATH
        np.testing.assert_array_equal(
            job.run(program(text), KR300_POSE).position, back.run(program(text), KR300_POSE).position
        )


@pytest.mark.parametrize("bad", ["blend", -1e-4, float("nan"), 0.5])
def test_bad_blending_raises(kr300, bad):
    with pytest.raises(deflect.DeflectError, match="blending"):
        slot_job(kr300, blending=bad)
