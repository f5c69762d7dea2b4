"""The offline pass over a program from Python: the slot's force against Altintas' closed
form (numpy), the deflection against the independent numpy VJM chain, the compensated arm on
the program, the compensated G-code read back, and every fault naming its program line."""

import io
import math
import re

import numpy as np
import pytest

import deflect
from conftest import KR300_POSE, REPO

SLOT = "G0 X-10 Y0 Z5\nS13000 M3\nG1 Z-2 F1500\nX70\nG0 Z5\n"


def placement_under_tcp(robot):
    """The workpiece frame 20 mm below the TCP at the start joints, its z along the tool
    axis reversed (the TCP points down the workpiece z)."""
    tcp = robot.forward(KR300_POSE)
    down = np.diag([1.0, -1.0, -1.0])  # pi about x
    rot = tcp[:3, :3] @ down.T
    t = np.eye(4)
    t[:3, :3] = rot
    t[:3, 3] = tcp[:3, 3] - rot @ [0.0, 0.0, 0.02]
    return t


def slot_job(kr300, **kwargs):
    """The job of the slot tests: the workpiece under the TCP, stock 80 x 60 mm."""
    return deflect.MachiningJob(
        kr300, placement_under_tcp(kr300), stock_min=(0.0, -0.03), stock_max=(0.08, 0.03), **kwargs
    )


@pytest.fixture(scope="module")
def slot_run(kr300):
    job = slot_job(kr300, cell=5e-4)
    program = deflect.GcodeProgram.from_text(SLOT, start=[0.0, 0.0, 0.02])
    return job.run(program, KR300_POSE)


def test_the_slot_force_is_the_closed_form_and_the_deflection_the_numpy_chain(slot_run, kr300, kr300_ref):
    r = slot_run
    ktc, krc, kac, kte, kre, kae = deflect.AL7075_T6_CARBIDE
    n, a = 3, 0.002
    c = 0.025 / (13000 / 60 * 3)
    expected = np.array(
        [
            -n * a * krc * c / 4 - n * a * kre / math.pi,
            n * a * ktc * c / 4 + n * a * kte / math.pi,
            n * a * kac * c / math.pi + n * a * kae / 2,
        ]
    )
    mid = np.flatnonzero((r.line == 4) & (r.position[:, 0] > 0.035))[0]
    np.testing.assert_allclose(r.force[mid], expected, rtol=1e-9)
    np.testing.assert_allclose(r.engagement[mid], [0.0, math.pi, 0.002], rtol=1e-12)
    # The TCP wrench by hand (workpiece frame = tool frame for this +x feed, then rotated
    # into the base frame by the placement): the force acts halfway up the 2 mm depth, so its
    # moment about the tip is (0, 0, a/2) x F; the cutting torque about the axis is the mean
    # over a revolution of R (K_tc c sin(phi) + K_te) a per edge over the engaged half turn,
    # N R a (K_tc c / pi + K_te / 2), on the tool along +z (it resists the M3 spindle's turn,
    # clockwise seen from above).
    radius = 0.008
    torque = n * radius * a * (ktc * c / math.pi + kte / 2)
    moment = np.array([-a / 2 * expected[1], a / 2 * expected[0], torque])
    rot = placement_under_tcp(kr300)[:3, :3]
    np.testing.assert_allclose(r.wrench[mid][:3], rot @ expected, rtol=1e-9)
    np.testing.assert_allclose(r.wrench[mid][3:], rot @ moment, rtol=1e-9, atol=1e-12)
    # The deflection under the job's wrench at the job's joints, by the numpy chain.
    ref = kr300_ref.deflection(r.q[mid], r.wrench[mid])
    np.testing.assert_allclose(r.deflection[mid], ref, rtol=1e-9, atol=1e-15)
    # The compensated joints land the loaded tip on the program by the numpy chain too (not
    # the vjm::deflection that computed them): its rigid TCP at q_c plus its deflection there
    # under the same wrench is the programmed point, placed in the base frame.
    place = placement_under_tcp(kr300)
    for k in (mid, mid // 2, len(r) - 3):
        qc = r.q_commanded[k]
        loaded = kr300_ref.forward(qc)[:3, 3] + kr300_ref.deflection(qc, r.wrench[k])[:3]
        target = place[:3, :3] @ r.position[k] + place[:3, 3]
        assert np.linalg.norm(loaded - target) < 1e-7, (k, loaded - target)
    # The compensated arm lands on the program; the uncompensated one is off by tenths.
    un_max, _ = r.path_error("uncompensated")
    co_max, _ = r.path_error("compensated")
    assert un_max > 2e-5 and co_max < 1e-7
    s_un = r.surface_error("uncompensated")
    s_co = r.surface_error("compensated")
    assert s_un["floor_max"] > 1e-5 and s_co["floor_max"] < 1e-6
    # The uncompensated groove is pushed sideways: a strip of one wall left, the other cut
    # into (square millimetres); the compensated one matches to tens of square micrometres
    # (its tool within 1e-8 m of the program: a wall that far off along 80 mm is 800 um^2).
    assert s_un["overcut"] > 1e-6 and s_un["material_left"] > 1e-6
    assert s_co["material_left"] < 5e-11 and s_co["overcut"] < 1e-9
    assert r.nominal_surface.shape == (120, 160)
    assert r.commanded.shape == (len(r), 4, 4)
    assert r.q_commanded.shape == (len(r), 6)


def test_the_compensated_gcode_and_pilot_signal(slot_run):
    r = slot_run
    text = r.compensated_gcode(1e-6)
    back = deflect.GcodeProgram.from_text(text, start=r.commanded[0, :3, 3])
    assert 2 < len(back) < len(r) // 10
    # The floor of the slot is commanded deeper than programmed.
    assert back.end[:, 2].min() < -0.002 - 1e-5
    pilot = r.pilot_wrenches(0.04)
    np.testing.assert_array_equal(pilot[:-10], r.wrench[10:])
    header = r.samples_csv(0.04).splitlines()[0].split(",")
    assert header[:3] == ["time_s", "line", "x_m"] and "pilot_fz_n" in header
    with pytest.raises(deflect.InputError, match="lead"):
        r.pilot_wrenches(-1.0)
    with pytest.raises(deflect.InputError, match="tolerance"):
        r.compensated_gcode(float("nan"))


def test_faults_name_the_program_line(kr300):
    job = slot_job(kr300)
    off = deflect.GcodeProgram.from_text("G0 X-10 Y0 Z5\nG1 Z-2 F1500\nX70\n", start=[0, 0, 0.02])
    with pytest.raises(deflect.InputError, match="program line 3 .*spindle"):
        job.run(off, KR300_POSE)
    far = deflect.GcodeProgram.from_text("S13000 M3\nG0 Z5\nG0 X5000\n", start=[0, 0, 0.02])
    with pytest.raises(deflect.DeflectError, match="program line 3"):
        job.run(far, KR300_POSE)
    with pytest.raises(deflect.InputError, match="seed"):
        job.run(off, KR300_POSE[:5])
    with pytest.raises(deflect.InputError, match="tool orientation"):
        deflect.MachiningJob(
            kr300, np.eye(4), stock_min=(0, 0), stock_max=(1, 1), tool_orientation=np.eye(3)[[1, 2, 0]]
        )
    with pytest.raises(deflect.InputError, match="cell"):
        deflect.MachiningJob(kr300, np.eye(4), stock_min=(0, 0), stock_max=(1, 1), cell=0.0).run(
            off, KR300_POSE
        )
    with pytest.raises(deflect.InputError, match="placement"):
        deflect.MachiningJob(kr300, np.full((4, 4), np.nan), stock_min=(0, 0), stock_max=(1, 1))


def test_the_shipped_program_runs(kr300):
    job = deflect.MachiningJob(
        kr300,
        placement_under_tcp(kr300),
        stock_min=(0.005, -0.015),
        stock_max=(0.085, 0.045),
        cell=1e-3,
    )
    program = deflect.GcodeProgram.from_file(REPO / "data" / "groove_and_pocket.nc", start=[0, 0, 0.02])
    r = job.run(program, KR300_POSE)
    assert r.plunge_samples > 0  # the pocket's plunge
    # File lines of N50, N60 and the circles N100-N120.
    assert set(np.unique(r.line).tolist()) >= {7, 8, 12, 13, 14}
    assert r.path_error("compensated")[0] < 1e-7 < r.path_error("uncompensated")[0]


def test_programs_and_jobs_pickle_bit_for_bit(kr300):
    import copy
    import pickle

    program = deflect.GcodeProgram.from_file(REPO / "data" / "groove_and_pocket.nc", start=[0, 0, 0.02])
    back = pickle.loads(pickle.dumps(program))
    assert back == program and len(back) == len(program)
    np.testing.assert_array_equal(back.end, program.end)
    np.testing.assert_array_equal(back.center, program.center)
    job = slot_job(kr300, helix=0.3)
    again = pickle.loads(pickle.dumps(job))
    assert again == job and copy.deepcopy(job) == job
    slot = deflect.GcodeProgram.from_text(SLOT, start=[0.0, 0.0, 0.02])
    np.testing.assert_array_equal(again.run(slot, KR300_POSE).q_commanded, job.run(slot, KR300_POSE).q_commanded)
    # A tampered state is checked like any program: a gap between moves.
    fn, (state, words, ops, axes, cutters) = program.__reduce__()
    assert axes == [] and cutters == []  # a 3-axis G-code program: every axis +z, no CUTTER
    assert fn(state, words, ops, axes, cutters) == program
    state[3] = (state[3][0], state[3][1], (1.0, 1.0, 1.0), *state[3][3:])
    with pytest.raises(deflect.InputError, match="MAX_GAP"):
        fn(state, words, ops)
    # A job with a tool table and a hand-started spindle, and the table alone.
    table = deflect.ToolTable.from_text("T1 P1 D16\nT2 P2 D10 Z42 ;ten\n")
    job = slot_job(kr300, tools=table, spindle_rpm=12000.0)
    again = pickle.loads(pickle.dumps(job))
    assert again == job and again != slot_job(kr300, tools=table)
    assert pickle.loads(pickle.dumps(table)) == table and len(table) == 2


def slot_force(flutes, feed_per_tooth, depth=0.002):
    """Altintas' closed form of a slot's per-revolution force, tool frame (feed along x)."""
    ktc, krc, kac, kte, kre, kae = deflect.AL7075_T6_CARBIDE
    n, a, c = flutes, depth, feed_per_tooth
    return np.array(
        [
            -n * a * krc * c / 4 - n * a * kre / math.pi,
            n * a * ktc * c / 4 + n * a * kte / math.pi,
            n * a * kac * c / math.pi + n * a * kae / 2,
        ]
    )


def test_each_tool_cuts_with_its_own_cutter_and_m4_mirrors_the_force(kr300, tmp_path):
    program = deflect.GcodeProgram.from_text(
        "T1 M6\nS13000 M3\nG0 X-10 Y-15 Z5\nG1 Z-2 F1500\nX70\nG0 Z5\n"
        "T2 M6\nS13000 M4\nG0 X-10 Y15\nG1 Z-2\nX70\nG0 Z5\n",
        start=[0.0, 0.0, 0.02],
    )
    table = deflect.ToolTable.from_text("T1 P1 D16 ;16 mm\nT2 P2 D10 ;10 mm\n", flutes=3)
    r = slot_job(kr300, tools=table).run(program, KR300_POSE)
    v, rev = 0.025, 13000 / 60
    for line, flutes, mirror in [(5, 3, 1.0), (11, 3, -1.0)]:
        mid = np.flatnonzero((r.line == line) & (r.position[:, 0] > 0.035))[0]
        expected = slot_force(flutes, v / (rev * flutes)) * [1.0, mirror, 1.0]
        np.testing.assert_allclose(r.force[mid], expected, rtol=1e-9)
    assert set(r.tool.tolist()) == {1, 2} and r.spindle.min() == -rev
    # The compensated program changes tools and turns the spindle as the program does.
    back = deflect.GcodeProgram.from_text(r.compensated_gcode(1e-6), start=r.commanded[0, :3, 3])
    assert back.tools == [1, 2] and back.spindle.min() == -rev and back.spindle.max() == rev
    # The 10 mm slot is 10 mm wide: the nominal part's floor at y = 15 +- 4 mm, stock at 6 mm.
    z = r.nominal_surface
    j = lambda y: int(round((y + 0.03) / 5e-4 - 0.5))  # noqa: E731
    i = int(round((0.04) / 5e-4 - 0.5))
    assert z[j(0.019), i] == -0.002 and z[j(0.021), i] == 0.0
    assert z[j(-0.022), i] == -0.002 and z[j(-0.0235), i] == 0.0
    # Without the table the 16 mm tool serves both; a T the table lacks is refused where it cuts.
    with pytest.raises(deflect.InputError, match="program line 11 .*T2"):
        slot_job(kr300, tools=deflect.ToolTable.from_text("T1 P1 D16\n")).run(program, KR300_POSE)
    f = tmp_path / "tools.toml"
    f.write_text('units = "mm"\n[[tool]]\nnumber = 1\ndiameter = 16\nflutes = 3\n[[tool]]\nnumber = 2\ndiameter = 10\nflutes = 3\nshape = "ball"\n')
    r2 = slot_job(kr300, tools=f).run(program, KR300_POSE)
    assert r2.nominal_surface.min() == pytest.approx(-0.002)


def test_a_hand_started_spindle_cuts_at_its_speed(kr300):
    off = deflect.GcodeProgram.from_text("G0 X-10 Y0 Z5\nG1 Z-2 F1500\nX70\nG0 Z5\n", start=[0, 0, 0.02])
    with pytest.raises(deflect.InputError, match="--spindle-rpm, Python spindle_rpm="):
        slot_job(kr300).run(off, KR300_POSE)
    r = slot_job(kr300, spindle_rpm=13000.0).run(off, KR300_POSE)
    mid = np.flatnonzero((r.line == 3) & (r.position[:, 0] > 0.035))[0]
    np.testing.assert_allclose(r.force[mid], slot_force(3, 0.025 / (13000 / 60 * 3)), rtol=1e-9)
    with pytest.raises(deflect.InputError, match="hand spindle"):
        slot_job(kr300, spindle_rpm=-5.0)


def test_a_rapid_may_skim_the_stock_and_is_reported(kr300):
    skim = deflect.GcodeProgram.from_text("G0 X-10 Y0 Z-0.05\nS13000 M3\nG0 X70\n", start=[0, 0, 0.02])
    r = slot_job(kr300).run(skim, KR300_POSE)
    line, _, depth = r.rapid_contact
    assert line == 3 and depth == pytest.approx(5e-5, abs=1e-15)
    # Refused at the first cell deeper than the skim: one the rim crosses (its mean height).
    with pytest.raises(deflect.InputError, match=r"program line 3 .*rapid move .*0\.0[45]\d mm into"):
        slot_job(kr300, rapid_skim=4e-5).run(skim, KR300_POSE)
    assert slot_job(kr300).run(deflect.GcodeProgram.from_text(SLOT, start=[0, 0, 0.02]), KR300_POSE).rapid_contact is None


def test_a_points_csv_program_runs_like_its_gcode_twin(kr300):
    job = slot_job(kr300)
    points = deflect.GcodeProgram.from_points_text(
        "x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm\n-10,0,5,0,13000\n-10,0,-2,1500,13000\n70,0,-2,1500,13000\n",
        start=[0.0, 0.0, 0.02],
    )
    gcode = deflect.GcodeProgram.from_text("S13000 M3\nG0 X-10 Y0 Z5\nG1 Z-2 F1500\nX70\n", start=[0.0, 0.0, 0.02])
    a, b = job.run(points, KR300_POSE), job.run(gcode, KR300_POSE)
    np.testing.assert_array_equal(a.force, b.force)
    with pytest.raises(deflect.LoadError, match="spindle_rpm"):
        deflect.GcodeProgram.from_points_text("x_mm,y_mm,z_mm,feed_mm_min\n0,0,0,1\n")


# The KR 300 as deflect-sim job places it: the workpiece 2.45 m in front of the base, 0.92 m
# up, turned half a turn about z; the tool down from these joints.
JOB_PLACEMENT = np.array(
    [[-1.0, 0.0, 0.0, 2.45], [0.0, -1.0, 0.0, 0.02], [0.0, 0.0, 1.0, 0.92], [0.0, 0.0, 0.0, 1.0]]
)
JOB_SEED = [0.0, -0.9, 1.4, 0.0, -0.5, 0.0]


def job_for(kr300, program, diameter, margin=0.0, **kwargs):
    """A job whose stock is the program's feed moves' box grown by the tool radius."""
    kind = np.array(program.kind)
    feed = (kind != "rapid") & (kind != "dwell")
    pts = [program.start[feed, :2], program.end[feed, :2]]
    # XY arcs: points along them every few degrees.
    xy = np.array([p == "xy" for p in program.plane]) & (kind == "arc")
    for s, c, sweep in zip(program.start[xy], program.center[xy], program.sweep[xy]):
        a = np.linspace(0.0, sweep, max(2, int(abs(sweep) / 0.05) + 1))[:, None]
        r = (s - c)[:2]
        pts.append(c[:2] + np.hstack([np.cos(a) * r[0] - np.sin(a) * r[1], np.sin(a) * r[0] + np.cos(a) * r[1]]))
    pts = np.concatenate(pts)
    grow = diameter / 2 + margin
    return deflect.MachiningJob(
        kr300,
        JOB_PLACEMENT,
        stock_min=pts.min(axis=0) - grow,
        stock_max=pts.max(axis=0) + grow,
        diameter=diameter,
        **kwargs,
    )


def zigzag(passes, length, stepover, depth, slope):
    """Zig-zag passes on a floor sloped along the feed (mm), as the sloped-floor reproducer."""
    g = ["G21 G90 G17", "(Floor)", "S2000 M3", "G0 X0 Y0 Z5", f"G1 X0 Y0 Z{-depth:.4f} F508"]
    for k in range(passes):
        y = k * stepover
        a, b = (0.0, length) if k % 2 == 0 else (length, 0.0)
        if k:
            g.append(f"G1 X{a:.4f} Y{y:.4f} Z{-depth - slope * a:.4f}")
        g.append(f"G1 X{b:.4f} Y{y:.4f} Z{-depth - slope * b:.4f}")
    return "\n".join(g + ["G0 Z5", "M2", ""])


def test_operations_and_the_coupling_of_a_sloped_floor(kr300):
    text = zigzag(6, 8.0, 0.3, 3.0, 0.005) + ""
    # A second operation with a second tool, named by its comment.
    text = text.replace("G0 Z5\nM2", "G0 Z5\nT2 M6\n(Finish)\nS2000 M3\nG0 X0 Y0 Z2\nG1 Z-3.2 F300\nX8\nG0 Z5\nM2")
    program = deflect.GcodeProgram.from_text(text, start=[0.0, 0.0, 0.02])
    names = [name for name, _, _ in program.operations]
    assert names == ["Floor", "Finish"], program.operations
    import pickle

    assert pickle.loads(pickle.dumps(program)).operations == program.operations
    job = job_for(kr300, program, 0.016, cell=5e-4)
    r = job.run(program, JOB_SEED)
    # The compensated tool stays on the program to the IK's tolerance on the sloped floor,
    # its coupling converged; the uncompensated one is off by tenths of a millimetre.
    assert r.path_error("compensated")[0] < 1e-6 < 1e-4 < r.path_error("uncompensated")[0]
    assert r.deviations == []
    assert r.coupling_residual[:, 1].max() <= 1e-8
    ops = r.operations
    assert [o[0] for o in ops] == ["Floor", "Finish"]
    assert sum(o[2] for o in ops) == len(r)
    assert all(o[5] < 1e-6 for o in ops)
    np.testing.assert_array_equal(r.force_compensated.shape, (len(r), 3))


SHARED = REPO.parent / "shared" / "machining" / "real"
# Each real CAM program with the tool its comments name and what it needs (README).
REAL = [
    ("cambam__winder-UGS__electric_turtle.nc", 3.175, {}, {}),
    ("freecad-grbl_post__SergeyPopovGit-CNC__Top_board_for_manual_test.nc", 3.0, {"dialect": "grbl"}, {"spindle_rpm": 10000.0}),
    ("fusion360-generic-post__SergeyPopovGit-CNC__Heatsink_Bottom.tap", 3.175, {}, {}),
    ("fusion360-personal__shooshx-led_floor__1070_wall_27bit.nc", 2.7, {}, {}),
    ("pycam-0.5.1__winder-UGS__ShapeOko_Calibration_Pattern_01b.ngc", 1.0, {}, {"stock_top": 0.0005}),
    (
        "unknown-cam__CAMotics-examples__botomata_bottom.nc",
        6.35,
        {},
        {"tools": REPO / "data" / "botomata_tools.tbl", "rate_hz": 125.0, "rapid_skim": 0.0005},
    ),
]


@pytest.mark.skipif(not SHARED.is_dir(), reason="../shared/machining/real not found")
@pytest.mark.parametrize("name,diameter,read,run", REAL, ids=[r[0].split("__")[0] for r in REAL])
def test_real_cam_programs_are_compensated_onto_the_program(kr300, name, diameter, read, run):
    """Every real program the reader takes: the compensated prediction within 1 um of the
    program on every line (deflect-sim job's cell: the smallest tool / 12 in [0.1, 0.5] mm)."""
    program = deflect.GcodeProgram.from_file(SHARED / name, start=[0.0, 0.0, 0.02], **read)
    smallest = 1.5875 if "tools" in run else diameter
    cell = min(max(smallest / 12, 0.1), 0.5) * 1e-3
    job = job_for(kr300, program, diameter * 1e-3, cell=cell, flutes=2, **run)
    r = job.run(program, JOB_SEED)
    assert r.path_error("compensated")[0] <= 1e-6, r.deviations[:5]
    assert r.deviations == []
    assert r.path_error("uncompensated")[0] > 1e-4


def _krl_aggregate(text):
    """KRL's ``{E6POS: X 1, Y 2, ...}`` as a dict (the type prefix optional)."""
    body = text[text.index("{") + 1 : text.rindex("}")]
    body = body.split(":", 1)[1] if ":" in body else body
    return {k: float(v) for k, v in (kv.split() for kv in body.split(","))}


def _krl_frame(kv):
    """X, Y, Z [mm] and Rz(A) Ry(B) Rx(C) [deg] as a 4 x 4 matrix."""
    a, b, c = (math.radians(kv[k]) for k in "ABC")
    rz = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])
    ry = np.array([[math.cos(b), 0, math.sin(b)], [0, 1, 0], [-math.sin(b), 0, math.cos(b)]])
    rx = np.array([[1, 0, 0], [0, math.cos(c), -math.sin(c)], [0, math.sin(c), math.cos(c)]])
    t = np.eye(4)
    t[:3, :3] = rz @ ry @ rx
    t[:3, 3] = [kv["X"] * 1e-3, kv["Y"] * 1e-3, kv["Z"] * 1e-3]
    return t


def _nearest(fks, pose):
    """The sample whose FK is nearest `pose`, with the position and rotation gaps."""
    k = np.argmin(np.linalg.norm(fks[:, :3, 3] - pose[:3, 3], axis=1))
    return k, np.linalg.norm(fks[k, :3, 3] - pose[:3, 3]), np.linalg.norm(fks[k, :3, :3] - pose[:3, :3])


def test_the_krl_reads_back_onto_the_compensated_joints(slot_run, kr300):
    """The KRL of the slot, parsed here: BASE (the .dat) times every LIN's E6POS is the FK
    of some sample's compensated joints (1e-6 m, 1e-6 rad); every PTP's E6AXIS, turned back
    by KUKA's signs (A1, A4, A6 against this URDF's axes), a sample's compensated joints
    (1e-9 rad); the files named after the program."""
    r = slot_run
    files = r.robot_program("krl")
    assert list(files) == ["deflect_job.src", "deflect_job.dat"]
    src, dat = files["deflect_job.src"], files["deflect_job.dat"]
    base = _krl_frame(_krl_aggregate(next(l for l in dat.splitlines() if "DEFLECT_BASE=" in l)))
    np.testing.assert_allclose(base, placement_under_tcp(kr300), atol=1e-9)
    fks = np.array([kr300.forward(q) for q in r.q_commanded])
    lins = [l for l in src.splitlines() if l.startswith("LIN ")]
    assert 3 <= len(lins) < len(r) // 4
    for line in lins:
        kv = _krl_aggregate(line)
        _, dp, dr = _nearest(fks, base @ _krl_frame(kv))
        assert dp < 1e-6 and dr < 1e-6, line
        # Near the milling pose (A2 -0.9, A3 1.4, A5 1.07 rad): the wrist in the basic area,
        # in front of the lower arm (A3 >= phi), A5 > 0: S = 2.
        assert kv["S"] == 2.0, line
    assert "; line 4," in src
    sign = np.array([-1.0, 1.0, 1.0, -1.0, 1.0, -1.0])
    joints = r.robot_program("krl", command="joints")["deflect_job.src"]
    rows = [_krl_aggregate(l) for l in joints.splitlines() if l.startswith("PTP ")]
    q = np.array([[math.radians(kv[f"A{i + 1}"]) for i in range(6)] for kv in rows]) * sign
    for row in q:
        assert np.abs(r.q_commanded - row).max(axis=1).min() <= 1e-9


#: The UR10 over a table in front of it: the workpiece x along the base's -y, the tool down.
UR10_PLACEMENT = np.array(
    [[0.0, 1.0, 0.0, 0.86], [-1.0, 0.0, 0.0, 0.16], [0.0, 0.0, 1.0, 0.36], [0.0, 0.0, 0.0, 1.0]]
)
UR10_SEED = [0.0, -1.2, 1.6, -1.97, -1.5708, 0.0]


def ur10():
    from importlib import metadata

    dist = metadata.distribution("example-robot-data")
    urdf = dist.locate_file("cmeel.prefix/share/example-robot-data/robots/ur_description/urdf/ur10_robot.urdf")
    return deflect.SerialRobot.from_urdf(str(urdf), str(REPO / "robots/ur10/ur10_stiffness.toml"), "tool0")


def test_the_urscript_of_a_ur10_reads_back_onto_the_compensated_joints():
    """A UR10 (example-robot-data's URDF, the shipped UR convention) cuts the slot: every
    movel pose, in the controller's base frame (the URDF's `base`: base_link turned half a
    turn about z), is the FK of a sample's compensated joints (1e-6 m; the rotation vector by
    Rodrigues' formula, 1e-6); every servoj row a sample's joints (1e-9 rad), all of them."""
    robot = ur10()
    job = deflect.MachiningJob(robot, UR10_PLACEMENT, stock_min=(-0.01, -0.015), stock_max=(0.09, 0.015), cell=5e-4)
    program = deflect.GcodeProgram.from_text(SLOT, start=[0.0, 0.0, 0.02])
    r = job.run(program, UR10_SEED)
    script = r.robot_program("urscript")["deflect_job.script"]
    assert script.startswith("def deflect_job():") and script.rstrip().endswith("deflect_job()")
    turn = np.diag([-1.0, -1.0, 1.0, 1.0])  # the controller's base in base_link (and back)
    fks = np.array([robot.forward(q) for q in r.q_commanded])
    moves = re.findall(r"movel\(p\[([^\]]*)\], a=([^,]*), v=([^,]*), r=([^)]*)\)", script)
    assert 3 <= len(moves) < len(r) // 4
    for m in moves:
        p = np.array([float(x) for x in m[0].split(",")])
        angle = np.linalg.norm(p[3:])
        axis = p[3:] / angle if angle > 0 else np.array([0.0, 0.0, 1.0])
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        pose = np.eye(4)
        pose[:3, :3] = np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K  # Rodrigues
        pose[:3, 3] = p[:3]
        _, dp, dr = _nearest(fks, turn @ pose)
        assert dp < 1e-6 and dr < 1e-6
    assert float(moves[0][3]) == 0.0 and float(moves[-1][3]) == 0.0
    joints = r.robot_program("urscript", command="joints")["deflect_job.script"]
    rows = re.findall(r"servoj\(\[([^\]]*)\]", joints)
    assert len(rows) == len(r)
    q = np.array([[float(x) for x in row.split(",")] for row in rows])
    np.testing.assert_allclose(q, r.q_commanded, atol=1e-9, rtol=0)


def test_robot_programs_refuse_a_kind_a_convention_or_an_option(slot_run):
    r = slot_run
    with pytest.raises(deflect.InputError, match="kind"):
        r.robot_program("krl2")
    with pytest.raises(deflect.InputError, match="command"):
        r.robot_program("krl", command="both")
    with pytest.raises(deflect.InputError, match="tolerance"):
        r.robot_program("krl", tolerance=0.0)
    with pytest.raises(deflect.InputError, match="name"):
        r.robot_program("krl", name="1job")
    # The KR 300 runs KRL: RAPID and URScript are other controllers' languages.
    with pytest.raises(deflect.InputError, match="kuka's"):
        r.robot_program("urscript")
    # CSV needs no convention: the joints at every sample.
    csv = r.robot_program("csv", command="joints")["deflect_job.csv"]
    rows = np.loadtxt(io.StringIO(csv), delimiter=",", comments="#", skiprows=2)
    np.testing.assert_allclose(rows[:, 2:], r.q_commanded, rtol=0, atol=1e-15)
