"""The offline pass over a program from Python: the slot's force against Altintas' closed
form (numpy), the deflection against the independent numpy VJM chain, the compensated arm on
the program, the compensated G-code read back, and every fault naming its program line."""

import math

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


def test_the_slot_force_is_the_closed_form_and_the_deflection_the_numpy_chain(slot_run, kr300_ref):
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
    # The deflection under the job's wrench at the job's joints, by the numpy chain.
    ref = kr300_ref.deflection(r.q[mid], r.wrench[mid])
    np.testing.assert_allclose(r.deflection[mid], ref, rtol=1e-9, atol=1e-15)
    # The compensated arm lands on the program; the uncompensated one is off by tenths.
    un_max, _ = r.path_error("uncompensated")
    co_max, _ = r.path_error("compensated")
    assert un_max > 2e-5 and co_max < 1e-7
    s_un = r.surface_error("uncompensated")
    s_co = r.surface_error("compensated")
    assert s_un["floor_max"] > 1e-5 and s_co["floor_max"] < 1e-6
    # The uncompensated groove is pushed sideways: a wall's worth of area cut on one side
    # and left on the other; the compensated one matches to the cell.
    assert s_un["material_left"] > 0 and s_co["material_left"] == s_co["overcut"] == 0
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
    fn, (state, words) = program.__reduce__()
    state[3] = (state[3][0], state[3][1], (1.0, 1.0, 1.0), *state[3][3:])
    with pytest.raises(deflect.InputError, match="MAX_GAP"):
        fn(state, words)
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
    with pytest.raises(deflect.InputError, match="program line 3 .*rapid move .*0.050 mm into"):
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
