"""Machining from Python: a G-code program into SI arrays (hand-derived), every fault a
LoadError naming line and column, and the milling force against the textbook closed forms."""

import math

import numpy as np
import pytest

import deflect
from conftest import REPO

PROGRAM = """%
(groove and a full circle, mm)
N10 G21 G90 G17
N20 G0 X10 Y0 Z5
N30 G1 Z-2 F600 S13000 M3
N40 X50
N50 G2 X50 Y0 I10 J0
N60 G0 Z5
N70 M30
%
"""


def test_a_program_reads_into_si_arrays():
    p = deflect.GcodeProgram.from_text(PROGRAM)
    assert len(p) == 5
    np.testing.assert_array_equal(p.line, [4, 5, 6, 7, 8])
    assert p.kind == ["rapid", "linear", "linear", "arc", "rapid"]
    np.testing.assert_array_equal(p.end[0], [0.01, 0.0, 0.005])
    np.testing.assert_array_equal(p.end[2], [0.05, 0.0, -0.002])
    # The full circle about (60, 0) mm, clockwise, back at its start.
    np.testing.assert_allclose(p.center[3], [0.06, 0.0, -0.002], rtol=0, atol=1e-17)
    assert p.plane == [None, None, None, "xy", None]
    assert np.isnan(p.center[0]).all()
    assert p.sweep[3] == -2 * math.pi
    np.testing.assert_array_equal(p.end[3], p.start[3])
    np.testing.assert_allclose(p.feed, [0.0, 0.01, 0.01, 0.01, 0.0], rtol=1e-15)
    np.testing.assert_allclose(p.spindle[1:4], 13000 / 60, rtol=1e-15)
    np.testing.assert_allclose(p.length[3], 2 * math.pi * 0.01, rtol=1e-14)
    assert math.isclose(p.cutting_length, 0.007 + 0.04 + 2 * math.pi * 0.01, rel_tol=1e-14)
    assert "5 moves" in repr(p)


def test_files_inches_and_a_start_point(tmp_path):
    f = tmp_path / "part.nc"
    f.write_text("G1 X1 F10\n")
    p = deflect.GcodeProgram.from_file(f, start=[0.0, 0.0, 0.1], units="in")
    np.testing.assert_array_equal(p.start[0], [0.0, 0.0, 0.1])
    np.testing.assert_array_equal(p.end[0], [0.0254, 0.0, 0.1])
    p = deflect.GcodeProgram.from_file(REPO / "fuzz" / "corpus" / "gcode" / "seed_pocket.nc")
    assert len(p) > 5 and "arc" in p.kind


@pytest.mark.parametrize(
    "text, match",
    [
        ("G1 X10 D1 F100\n", "line 1, column 8: expected D: a word nothing on the line uses"),
        ("G41 G1 X1 F100\n", "line 1, column 1: expected G41: cutter radius compensation"),
        ("G0 X0 Y0\nG2 X10 Y0 I4 J0 F100\n", "line 2, column 4: expected an end point on the arc"),
        ("G1 X10\n", "feed rate F"),
        ("G0 X1 A5\n", "line 1, column 7: expected A: rotary"),
        ("o1 while [1]\no1 endwhile\n", "MAX_BLOCKS"),
    ],
)
def test_faults_are_load_errors_naming_line_and_column(text, match):
    with pytest.raises(deflect.LoadError, match=match) as e:
        deflect.GcodeProgram.from_text(text)
    assert isinstance(e.value, deflect.DeflectError)


def test_the_cam_dialect_tools_cycles_and_the_word_report():
    text = """%
G21 G90 G17 G94
T2 M6
S8000 M4
G0 X0 Y0 Z5
G98 G81 X10 Y0 Z-3 R1 F300
G80
G18 G2 X20 Z5 I5 K0
T5 M6 (G43 H5)
G43 H5 M3 M8
G4 P0.5
G1 X30 F600
M30
%
"""
    p = deflect.GcodeProgram.from_text(text)
    # The cycle: rapid over the hole at the start height, down to R, feed to Z, back up.
    assert p.kind[:5] == ["rapid", "rapid", "rapid", "linear", "rapid"]
    np.testing.assert_allclose(p.end[1], [0.01, 0.0, 0.005], atol=1e-15)
    np.testing.assert_allclose(p.end[3], [0.01, 0.0, -0.003], atol=1e-15)
    assert p.plane[5] == "zx" and p.kind[6] == "dwell" and p.dwell[6] == 0.5
    # M4 turns counter-clockwise (< 0); M6 stops the spindle; M3 turns it clockwise again.
    assert p.spindle[3] == -8000 / 60 and p.spindle[7] == 8000 / 60
    assert p.tools == [2, 5] and p.tool[0] == 2 and p.tool[-1] == 5
    words = {w[0]: w for w in p.words}
    assert words["G81"][1] == "honoured" and words["G81"][3] == 6
    assert words["G43"][1] == "recorded" and "TCP carries the tool length" in words["G43"][4]
    assert words["M8"][1] == "recorded" and words["M6"][2] == 2
    # A refused program still has its report.
    refused = deflect.gcode_words("G41 G1 X1 F100\nG0 B90\n")
    assert ("G41", "refused") == refused[0][:2] and any(w[0] == "B" and w[1] == "refused" for w in refused)


def test_the_grbl_and_fanuc_dialects():
    freecad = "G0 X0 Y0\nG2 X10 Y0 I5 J0 K0.000 F200\n"
    with pytest.raises(deflect.LoadError, match="line 2, column 17: expected K: no K word on an arc in G17"):
        deflect.GcodeProgram.from_text(freecad)
    p = deflect.GcodeProgram.from_text(freecad, dialect="grbl")
    np.testing.assert_allclose(p.center[0], [0.005, 0.0, 0.0])  # G0 X0 Y0 goes nowhere
    haas = "G0 X0 Y0 Z5\nG81 X1 Y1 Z-1 R1 F100\nG80\nX5 Y5\n"
    with pytest.raises(deflect.LoadError, match="line 4.*no motion mode"):
        deflect.GcodeProgram.from_text(haas)
    # Fanuc: after G80 the axis words move in the last G0-G3 mode (here G0).
    p = deflect.GcodeProgram.from_text(haas, dialect="fanuc")
    assert p.kind[-1] == "rapid" and p.line[-1] == 4
    with pytest.raises(deflect.InputError, match="dialect"):
        deflect.GcodeProgram.from_text("G0 X1\n", dialect="mach3")


def test_bad_options_are_input_errors(tmp_path):
    with pytest.raises(deflect.InputError, match="units"):
        deflect.GcodeProgram.from_text("G0 X1\n", units="cm")
    with pytest.raises(deflect.InputError, match="start"):
        deflect.GcodeProgram.from_text("G0 X1\n", start=[0.0, 0.0])
    with pytest.raises(deflect.LoadError, match="start"):
        deflect.GcodeProgram.from_text("G0 X1\n", start=[np.nan, 0.0, 0.0])
    with pytest.raises(deflect.LoadError):
        deflect.GcodeProgram.from_file(tmp_path / "missing.nc")


def test_slot_average_is_the_closed_form():
    ktc, krc, kac, kte, kre, kae = deflect.AL7075_T6_CARBIDE
    n, a, c = 3, 0.002, 1e-4
    f = deflect.milling_force(0.016, n, a, c)
    want = [
        -n * a * krc * c / 4 - n * a * kre / math.pi,
        n * a * ktc * c / 4 + n * a * kte / math.pi,
        n * a * kac * c / math.pi + n * a * kae / 2,
    ]
    np.testing.assert_allclose(f, want, rtol=1e-9)
    # Own coefficients: only the tangential cutting one, in a half-immersion down cut.
    k = [1e9, 0, 0, 0, 0, 0]
    f = deflect.milling_force(0.016, 2, a, c, entry=math.pi / 2, coefficients=k)
    np.testing.assert_allclose(f, [2 * a / (2 * math.pi) * c / 4 * 2 * 1e9,
                                   2 * a / (2 * math.pi) * c / 4 * math.pi * 1e9, 0.0],
                               rtol=1e-9, atol=1e-12)


def test_instantaneous_forces_average_to_the_closed_form():
    angles = np.linspace(0, 2 * math.pi, 3600, endpoint=False) + math.pi / 3600
    f = deflect.milling_force(0.016, 3, 0.004, 5e-5, entry=1.0, helix=math.radians(30),
                              angles=angles, discs=16)
    assert f.shape == (3600, 3)
    mean = deflect.milling_force(0.016, 3, 0.004, 5e-5, entry=1.0, helix=math.radians(30))
    np.testing.assert_allclose(f.mean(axis=0), mean, rtol=3e-3)


@pytest.mark.parametrize(
    "kwargs, exc, match",
    [
        (dict(diameter=0.0), deflect.InputError, "tool diameter"),
        (dict(flutes=0), deflect.InputError, "flutes"),
        (dict(depth=-1e-3), deflect.InputError, "axial depth"),
        (dict(entry=2.0, exit=1.0), deflect.InputError, "exit angle"),
        (dict(coefficients=[1, 2, 3]), deflect.InputError, "coefficients"),
        (dict(coefficients=[1, -2, 3, 4, 5, 6]), deflect.InputError, "k_rc"),
        (dict(angles=[0.0], discs=0), deflect.InputError, "discs"),
        (dict(angles=np.zeros((2, 2))), deflect.InputError, "angles"),
        (dict(angles=np.broadcast_to(0.0, (10**12,))), deflect.InputError, "MAX_SAMPLES"),
        (dict(feed_per_tooth=complex(1, 1)), deflect.InputError, "feed_per_tooth"),
    ],
)
def test_bad_milling_inputs_are_typed_errors(kwargs, exc, match):
    args = dict(diameter=0.016, flutes=3, depth=0.002, feed_per_tooth=1e-4)
    args.update(kwargs)
    with pytest.raises(exc, match=match):
        deflect.milling_force(**args)
