"""Inertia in the machining job from Python: the spindle's D'Alembert wrench against Eq. 3-5 by
numpy, its deflection against ``SerialRobot.deflection`` (another call path), nothing counted
is the plain job bit for bit, bad masses raise, and the inertia survives pickling."""

import pickle

import numpy as np
import pytest

import deflect
from conftest import KR300_POSE
from test_machining_job import placement_under_tcp, slot_job

# In air: a line and a circle 5 mm above the stock at 3 m/min.
AIR = "G0 X-10 Y0 Z5\nG1 X20 F3000\nG2 X20 Y0 I10\nG1 X40 Y10\n"
COM = np.array([0.0, 0.0, -0.2])


def air_program():
    return deflect.GcodeProgram.from_text(AIR, start=[0.0, 0.0, 0.02])


def test_the_spindle_wrench_is_eq_3_to_5_and_its_deflection_the_robots(kr300):
    job = slot_job(kr300).with_inertia(60.0, com=COM)
    r = job.run(air_program(), KR300_POSE)
    placement = placement_under_tcp(kr300)
    rot = placement[:3, :3]
    moving = np.linalg.norm(r.tool_acceleration, axis=1) > 0.1
    assert moving.sum() > 10
    for k in np.flatnonzero(moving)[::7]:
        a = rot @ r.tool_acceleration[k]
        tcp = kr300.forward(r.q[k])
        # The commanded pose's orientation is the target's; the rigid one at q is the same.
        arm = tcp[:3, :3] @ COM
        f = -60.0 * a
        expected = np.concatenate([f, np.cross(arm, f)])
        np.testing.assert_allclose(r.inertial_wrench[k], expected, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(
            r.deflection_inertial[k], kr300.deflection(r.q[k], r.inertial_wrench[k]), rtol=1e-9, atol=1e-15
        )
    # On the circle (line 3, radius 10 mm, at 50 mm/s) the acceleration reaches v^2 / r.
    on_circle = r.line == 3
    assert np.linalg.norm(r.tool_acceleration[on_circle], axis=1).max() >= 0.05**2 / 0.01 * (1 - 1e-6)
    # No cutting: the compensated prediction stays on the program.
    assert np.abs(r.actual_compensated - r.position).max() < 1e-8


def test_nothing_counted_is_the_plain_job_and_a_real_spindle_is_not(kr300):
    program = deflect.GcodeProgram.from_text(
        "G0 X-10 Y0 Z5\nS13000 M3\nG1 Z-2 F1500\nX40\nG0 Z5\n", start=[0.0, 0.0, 0.02]
    )
    plain = slot_job(kr300).run(program, KR300_POSE)
    zero = slot_job(kr300).with_inertia(0.0, com=COM).run(program, KR300_POSE)
    np.testing.assert_array_equal(plain.q_commanded, zero.q_commanded)
    np.testing.assert_array_equal(plain.actual_compensated, zero.actual_compensated)
    assert not zero.deflection_inertial.any()
    heavy = slot_job(kr300).with_inertia(60.0, com=COM, links=True).run(program, KR300_POSE)
    assert np.abs(heavy.q_commanded - plain.q_commanded).max() > 1e-9
    assert np.abs(heavy.deflection_inertial[:, :3]).max() > 1e-6


@pytest.mark.parametrize(
    "kwargs",
    [
        {"mass": -1.0},
        {"mass": float("nan")},
        {"mass": 10.0, "inertia": np.diag([1.0, 1.0, 5.0])},
        {"mass": 10.0, "inertia": np.diag([1.0, 1.0, -0.5])},
        {"mass": 10.0, "com": [np.inf, 0.0, 0.0]},
    ],
)
def test_bad_masses_and_inertias_raise(kr300, kwargs):
    with pytest.raises(deflect.DeflectError):
        slot_job(kr300).with_inertia(**kwargs)


def test_the_inertia_survives_pickling(kr300):
    job = slot_job(kr300).with_inertia(60.0, com=COM, inertia=np.diag([0.9, 0.9, 0.2]), links=True)
    back = pickle.loads(pickle.dumps(job))
    assert back == job
    assert back != slot_job(kr300)
    a = job.run(air_program(), KR300_POSE)
    b = back.run(air_program(), KR300_POSE)
    np.testing.assert_array_equal(a.q_commanded, b.q_commanded)
