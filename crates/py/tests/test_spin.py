"""The spin about the tool axis chosen along a program (deflect-core's ``machining::spin``):
on the built-in job and the VJM paper's test workpiece (KR 300), the real CAM programs (KR 300
and UR10) and a SCARA. Every schedule holds the joint limits and both rate bounds sample by
sample with continuous joints; its predicted deflection is at most the seed's constant spin's
and the best constant spin's: in the search's own figures, and on the KR 300 in the exact
deflection of full runs (normal to the feed, computed here from the runs' arrays)."""

import math

import numpy as np
import pytest

import deflect
from conftest import REPO
from test_machining_job import JOB_PLACEMENT, JOB_SEED, REAL, SHARED, UR10_PLACEMENT, UR10_SEED, job_for, ur10

RATE = (1.0, 30.0)  # degrees per mm, per second: the defaults


def normal_rms(job_placement, r):
    """RMS of the tip's deflection normal to the feed over the cutting samples [m]."""
    cut = np.linalg.norm(r.force, axis=1) > 0
    dp = r.deflection[cut, :3] @ job_placement[:3, :3]  # base -> workpiece frame
    d = r.direction[cut]
    n = dp - d * np.sum(dp * d, axis=1, keepdims=True)
    return math.sqrt(np.mean(np.sum(n * n, axis=1)))


def check_schedule(r, limits, rate=RATE):
    """Limits, both rate bounds and continuity, sample by sample."""
    ds = np.linalg.norm(np.diff(r.position, axis=0), axis=1)
    dt = np.diff(r.time)
    turned = np.abs(np.diff(r.spin))
    assert np.all(turned <= math.radians(rate[0]) * 1e3 * ds + 1e-12)
    assert np.all(turned <= math.radians(rate[1]) * dt + 1e-12)
    lo, hi = np.array(limits).T
    for q in (r.q, r.q_commanded):
        assert np.all(q >= lo) and np.all(q <= hi)
    assert np.abs(np.diff(r.q_commanded, axis=0)).max() < 0.05, "continuous joints"


def check_plan(p):
    """The search's own figures: the optimised schedule deflects least."""
    opt, seed, best = p["optimised"], p["seed"], p["best_constant"]
    assert seed is not None and best is not None
    tie = 1 + 1e-9
    assert opt[0] <= best[0] * tie and best[0] <= seed[0] * tie


def builtin_job(kr300, **kwargs):
    return deflect.MachiningJob(kr300, JOB_PLACEMENT, stock_min=(0.005, -0.015), stock_max=(0.085, 0.045), **kwargs)


def test_the_builtin_jobs_optimised_spin_deflects_least(kr300):
    program = deflect.GcodeProgram.from_file(REPO / "data/groove_and_pocket.nc", start=[0, 0, 0.02])
    r = builtin_job(kr300, spin="optimize").run(program, JOB_SEED)
    p = r.spin_plan
    check_plan(p)
    check_schedule(r, kr300.joint_limits)
    keep = builtin_job(kr300).run(program, JOB_SEED)
    best = builtin_job(kr300, spin=math.degrees(p["best_constant_spin"])).run(program, JOB_SEED)
    e = [normal_rms(JOB_PLACEMENT, x) for x in (r, best, keep)]
    assert e[0] <= e[1] < e[2], e
    assert e[0] < 0.8 * e[2], e
    assert keep.spin_plan is None and np.all(keep.spin == 0.0)
    assert r.path_error("compensated")[0] < 1e-7
    # The uncompensated path error falls with the deflection (0.75 mm seed).
    assert r.path_error("uncompensated")[0] < 0.8 * keep.path_error("uncompensated")[0]


PAPER_PLACEMENT = np.array(
    [[-1.0, 0.0, 0.0, 2.52], [0.0, -1.0, 0.0, 0.07], [0.0, 0.0, 1.0, 0.92], [0.0, 0.0, 0.0, 1.0]]
)


def test_the_paper_workpieces_optimised_spin_deflects_least(kr300):
    """The VJM paper's test workpiece (deflect-sim milling's program and placement)."""
    program = deflect.GcodeProgram.from_file(REPO / "data/test_workpiece.nc", start=[0, 0, 0.02])
    make = lambda **kw: deflect.MachiningJob(kr300, PAPER_PLACEMENT, stock_min=(0, 0), stock_max=(0.14, 0.13), **kw)
    r = make(spin="optimize").run(program, JOB_SEED)
    check_plan(r.spin_plan)
    check_schedule(r, kr300.joint_limits)
    keep = make().run(program, JOB_SEED)
    assert normal_rms(PAPER_PLACEMENT, r) < normal_rms(PAPER_PLACEMENT, keep)


@pytest.mark.skipif(not SHARED.is_dir(), reason="../shared/machining/real not found")
@pytest.mark.parametrize("name,diameter,read,run", REAL, ids=[r[0].split("__")[0] for r in REAL])
def test_the_real_programs_optimised_spin_on_the_kr300(kr300, name, diameter, read, run):
    program = deflect.GcodeProgram.from_file(SHARED / name, start=[0.0, 0.0, 0.02], **read)
    smallest = 1.5875 if "tools" in run else diameter
    cell = min(max(smallest / 12, 0.1), 0.5) * 1e-3
    r = job_for(kr300, program, diameter * 1e-3, cell=cell, flutes=2, spin="optimize", **run).run(program, JOB_SEED)
    check_plan(r.spin_plan)
    check_schedule(r, kr300.joint_limits)
    keep = job_for(kr300, program, diameter * 1e-3, cell=cell, flutes=2, **run).run(program, JOB_SEED)
    assert normal_rms(JOB_PLACEMENT, r) <= normal_rms(JOB_PLACEMENT, keep)
    assert r.path_error("compensated")[0] <= 1e-6


@pytest.mark.skipif(not SHARED.is_dir(), reason="../shared/machining/real not found")
@pytest.mark.parametrize("name,diameter,read,run", REAL, ids=[r[0].split("__")[0] for r in REAL])
def test_the_real_programs_spin_on_a_ur10_turns_only_its_wrist(name, diameter, read, run):
    """The UR10's tool axis is its last joint's: a spin turns wrist 3 alone, the arm does not
    change posture, and every candidate deflects alike (to the search's tie, 1e-9): the
    optimised schedule is the seed's spin, and holds the limits and rates."""
    robot = ur10()
    program = deflect.GcodeProgram.from_file(SHARED / name, start=[0.0, 0.0, 0.02], **read)
    smallest = 1.5875 if "tools" in run else diameter
    cell = min(max(smallest / 12, 0.1), 0.5) * 1e-3
    kind = np.array(program.kind)
    end = program.end[(kind != "rapid") & (kind != "dwell"), :2]
    grow = diameter * 5e-4
    job = deflect.MachiningJob(
        robot, UR10_PLACEMENT, stock_min=end.min(axis=0) - grow, stock_max=end.max(axis=0) + grow,
        diameter=diameter * 1e-3, cell=cell, flutes=2, spin="optimize", **run,
    )
    r = job.run(program, UR10_SEED)
    p = r.spin_plan
    check_plan(p)
    check_schedule(r, robot.joint_limits)
    assert p["optimised"][0] == pytest.approx(p["seed"][0], rel=1e-8)


def test_a_scara_refuses_the_spin_past_its_last_joint():
    """A SCARA's spin is its j4 alone: every candidate deflects alike and the seed's spin
    stays; from j4 near its limit the candidates past it (less the margin) are refused."""
    scara = deflect.SerialRobot.from_urdf(REPO / "robots/scara/scara4.urdf", REPO / "robots/scara/scara4_stiffness.toml", "tcp")
    program = deflect.GcodeProgram.from_text("G0 X-10 Y0 Z5\nS13000 M3\nG1 Z-2 F1500\nX70\nG0 Z5\n", start=[0, 0, 0.02])
    placement = np.eye(4)
    placement[:3, 3] = [0.18, 0.22, -0.02]
    make = lambda: deflect.MachiningJob(
        scara, placement, stock_min=(-0.01, -0.015), stock_max=(0.08, 0.015), diameter=0.006, flutes=2, spin="optimize"
    )
    r = make().run(program, [0.5, 1.0, 0.1, 0.0])
    p = r.spin_plan
    check_plan(p)
    assert p["optimised"][0] == pytest.approx(p["seed"][0], rel=1e-8)
    assert np.all(r.spin == 0.0)
    near = make().run(program, [0.5, 1.0, 0.1, 5.0])
    assert near.spin_plan["refused"] > 0
    check_schedule(near, scara.joint_limits)


def test_spin_arguments_are_checked():
    robot = ur10()
    for kw, match in [
        (dict(spin="twirl"), "spin"),
        (dict(spin="optimize", spin_rate=(0.0, 30.0)), "rate"),
        (dict(spin="optimize", spin_rate=(1.0, float("nan"))), "rate"),
        (dict(spin="optimize", spin_step=0.0), "step"),
        (dict(spin="optimize", spin_measure="sideways"), "spin_measure"),
        (dict(spin=float("inf")), "spin"),
    ]:
        with pytest.raises(deflect.InputError, match=match):
            deflect.MachiningJob(robot, UR10_PLACEMENT, stock_min=(0, 0), stock_max=(0.05, 0.05), **kw)
