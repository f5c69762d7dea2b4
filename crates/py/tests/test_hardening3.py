"""Hardening, round three: one regression test per reproducer of the third adversarial pass
(inputs accepted silently, files that block), each a typed error or the right value."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import deflect
from conftest import KR300_POSE

SLOT = "G21 G90\nG1 Z0 F600\nG1 X40\n"


@pytest.mark.parametrize(
    "call",
    [
        "deflect.GcodeProgram.from_file(f)",
        "deflect.GcodeProgram.from_points_file(f)",
        "deflect.GridMap.from_json(f)",
        "deflect.GridMap.fit_csv(f)",
    ],
)
def test_a_fifo_is_refused_within_a_second(tmp_path, call):
    fifo = tmp_path / "f"
    os.mkfifo(fifo)
    code = textwrap.dedent(
        f"""
        import deflect
        f = {str(fifo)!r}
        try:
            {call}
        except deflect.LoadError as e:
            print("LoadError:", e)
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=10)
    assert "LoadError:" in out.stdout and "not a regular file" in out.stdout, out
    assert str(fifo) in out.stdout


@pytest.mark.parametrize("start", [[np.nan, 0, 0], [np.inf, 0, 0], [0, 0, 1e300], [2000.0, 0, 0]])
def test_a_points_text_refuses_a_start_the_gcode_reader_refuses(start):
    text = "x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm\n10,0,0,600,10000\n"
    with pytest.raises(deflect.LoadError, match="start"):
        deflect.GcodeProgram.from_points_text(text, start=start)
    with pytest.raises(deflect.LoadError, match="start"):
        deflect.GcodeProgram.from_text(SLOT, start=start)


def test_a_csv_column_given_twice_is_refused(tmp_path):
    with pytest.raises(deflect.LoadError, match="x_mm .a second time"):
        deflect.GcodeProgram.from_points_text(
            "x_mm,x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm\n1,2,0,0,600,1000\n"
        )
    csv = tmp_path / "static.csv"
    csv.write_text("x_m,force_axis,force,dx,dx\n0,0,1,1e-6,2e-6\n1,0,1,1e-6,2e-6\n")
    with pytest.raises(deflect.LoadError, match="dx .a second time"):
        deflect.GridMap.fit_csv(csv)


def test_grid_map_slopes_must_have_their_exact_shape():
    axes = [np.linspace(0, 1, 4), np.linspace(0, 1, 3)]
    slopes = np.arange(4 * 3 * 2 * 2, dtype=float).reshape(4, 3, 2, 2) * 1e-7
    offsets = np.zeros((4, 3, 2, 2))
    m = deflect.GridMap(axes, 2, 2, slopes, offsets)
    np.testing.assert_array_equal(m.slopes, slopes)
    # The transpose has the same count: refused, not read in the wrong order.
    with pytest.raises(deflect.InputError, match=r"slopes.*\(4, 3, 2, 2\)"):
        deflect.GridMap(axes, 2, 2, slopes.T, offsets)


def test_a_lone_surrogate_is_an_input_error():
    for call in (
        lambda: deflect.GcodeProgram.from_text("G1 X1 F100 (\udc80)\n"),
        lambda: deflect.GcodeProgram.from_points_text("x_mm\udc80\n"),
        lambda: deflect.gcode_words("G0 X1\udc80"),
        lambda: deflect.ToolTable.from_text("T1 P1 D3 ;\udc80\n"),
    ):
        with pytest.raises(deflect.InputError, match="UTF-8"):
            call()


def test_an_arc_centre_past_a_kilometre_is_refused_where_it_is_read():
    with pytest.raises(deflect.LoadError, match="line 2.*arc centre"):
        deflect.GcodeProgram.from_text("G0 X900000\nG2 I900000 F100\n")


def test_the_delta_refuses_points_above_its_elbows_and_joints_past_the_limit():
    d = deflect.Delta.pick_and_place()
    with pytest.raises(deflect.InputError, match="above the plane of the elbows"):
        d.ik([0.0, 0.0, 0.5])
    p = np.array([0.05, -0.03, -0.8])
    np.testing.assert_allclose(d.fk(d.ik(p)), p, atol=1e-12)
    for q in (1e7, 1e300):
        for call in (d.fk, d.jacobian, d.singularity_distance):
            with pytest.raises(deflect.InputError, match="MAX_JOINT_POSITION"):
                call([q, 0.0, 0.0])
    with pytest.raises(deflect.InputError, match="base_radius"):
        deflect.Delta(5e-324, 0.045, 0.35, 0.8)


def test_a_denormal_tool_and_absurd_coefficients_are_refused(kr300):
    with pytest.raises(deflect.InputError, match="tool diameter"):
        deflect.milling_force(5e-324, 3, 0.004, 1e-4)
    k = list(deflect.AL7075_T6_CARBIDE)
    k[0] = 1e200
    with pytest.raises(deflect.InputError, match="k_tc"):
        deflect.milling_force(0.016, 3, 0.004, 1e-4, coefficients=k)
    with pytest.raises(deflect.InputError, match="k_tc"):
        deflect.MachiningJob(kr300, np.eye(4), stock_min=(0, 0), stock_max=(0.1, 0.1), coefficients=k)


def test_a_cell_too_coarse_for_the_tool_and_a_rate_below_one_hertz_are_refused(kr300):
    program = deflect.GcodeProgram.from_text(SLOT, start=[0, 0, 0.02])
    for cell in (1e300, 0.1, 0.0041):
        job = deflect.MachiningJob(kr300, np.eye(4), stock_min=(0, -0.03), stock_max=(0.08, 0.03), cell=cell)
        with pytest.raises(deflect.InputError, match="stock cell"):
            job.run(program, KR300_POSE)
    with pytest.raises(deflect.InputError, match="rate_hz"):
        deflect.MachiningJob(kr300, np.eye(4), stock_min=(0, 0), stock_max=(0.1, 0.1), rate_hz=1e-3)


def test_a_force_batch_past_its_budget_is_refused_at_once():
    angles = np.zeros(deflect.MAX_SAMPLES)
    with pytest.raises(deflect.InputError, match="MAX_FORCE_EVALUATIONS"):
        deflect.milling_force(0.016, 3, 0.004, 1e-4, angles=angles, discs=256)
    # Within the budget: computed.
    f = deflect.milling_force(0.016, 3, 0.004, 1e-4, angles=np.zeros(1000), discs=256)
    assert f.shape == (1000, 3) and np.isfinite(f).all()
