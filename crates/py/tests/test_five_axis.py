"""Five-axis programs and cutters from Python: the ball-end force against scipy's own
integration of the edge written here from the geometry, the flat mill against the closed-form
milling force, APT and A/B/C G-code with their tool axes, pickling, bad input."""

import math
import pickle

import numpy as np
import pytest
from scipy import integrate

import deflect

K = np.array(deflect.AL7075_T6_CARBIDE)


def ball_element(kappa, phi, radius, feed, component):
    """One component of the force and moment per unit kappa and immersion on a ball."""
    k_tc, k_rc, k_ac, k_te, k_re, k_ae = K
    radial = np.array([math.sin(phi), math.cos(phi), 0.0])
    n = radial * math.sin(kappa) - np.array([0.0, 0.0, math.cos(kappa)])
    p = np.array([0.0, 0.0, radius]) + n * radius
    t = np.array([math.cos(phi), -math.sin(phi), 0.0])
    a = np.cross(t, n)
    h = max(float(np.dot(feed, n)), 0.0)
    f = (-t * (k_tc * h + k_te) - n * (k_rc * h + k_re) + a * (k_ac * h + k_ae)) * radius
    w = np.concatenate([f, np.cross(p, f)])
    return w[component]


def test_ball_end_mean_is_scipys_integral():
    radius, depth, flutes = 0.005, 0.003, 2
    feed = np.array([0.1e-3, 0.0, 0.0])
    top = math.acos(1.0 - depth / radius)
    force, moment = deflect.cutter_force(
        2 * radius, flutes, [[0.0, depth, 0.0, math.pi]], feed, shape="ball", helix=0.5
    )
    want = [
        integrate.dblquad(
            lambda phi, kappa: ball_element(kappa, phi, radius, feed, c),
            0.0,
            top,
            0.0,
            math.pi,
            epsabs=0.0,
            epsrel=1e-11,
        )[0]
        * flutes
        / (2 * math.pi)
        for c in range(6)
    ]
    got = np.concatenate([force, moment])
    assert np.linalg.norm(got[:3] - want[:3]) < 1e-6 * np.linalg.norm(want[:3])
    assert np.linalg.norm(got[3:] - want[3:]) < 1e-6 * np.linalg.norm(want[3:])


def test_flat_cutter_is_the_milling_force_and_instants_have_shapes():
    f, m = deflect.cutter_force(0.016, 3, [[0.0, 0.002, 0.5, math.pi]], [0.1e-3, 0, 0])
    want = deflect.milling_force(0.016, 3, 0.002, 0.1e-3, entry=0.5)
    np.testing.assert_allclose(f, want, rtol=1e-12)
    fi, mi = deflect.cutter_force(
        0.012, 2, np.array([[0.0, 0.004, 0.0, math.pi]]), [0.1e-3, 0, 0.02e-3],
        shape="bull-nose", corner_radius=0.002, helix=0.6, angles=np.linspace(0, 6, 5),
    )
    assert fi.shape == (5, 3) and mi.shape == (5, 3)
    with pytest.raises(deflect.DeflectError, match="corner_radius"):
        deflect.cutter_force(0.012, 2, [[0, 1e-3, 0, 1]], [1e-4, 0, 0], shape="bull-nose")
    with pytest.raises(deflect.DeflectError, match="band"):
        deflect.cutter_force(0.012, 2, [[2e-3, 1e-3, 0, 1]], [1e-4, 0, 0])
    with pytest.raises(deflect.DeflectError, match="bands"):
        deflect.cutter_force(0.012, 2, [[0, 1e-3, 0]], [1e-4, 0, 0])


APT = """UNITS/MM
MULTAX
LOADTL/4
CUTTER/8,4
SPINDL/10000,CLW
FEDRAT/MMPM,900
GOTO/10,0,5,0,0,1
GOTO/30,0,5,0.0,0.5,0.8660254
GOTO/50,10,5,0.5,0.0,0.8660254
FINI
"""


def test_apt_programs_carry_their_axes_cutters_and_pickle():
    p = deflect.GcodeProgram.from_apt_text(APT)
    assert p.is_multi_axis
    assert len(p) == 3
    np.testing.assert_allclose(p.end_axis[1], [0.0, 0.5, math.sqrt(3) / 2], atol=1e-7)
    np.testing.assert_array_equal(p.start_axis[1], p.end_axis[0])
    assert p.cutters == [(4, 0.008, "ball", 0.004, 4)]
    q = pickle.loads(pickle.dumps(p))
    assert q == p
    np.testing.assert_array_equal(q.end_axis, p.end_axis)
    assert q.cutters == p.cutters
    with pytest.raises(deflect.LoadError, match="line 2"):
        deflect.GcodeProgram.from_apt_text("UNITS/MM\nSPLINE/1,2\n")


def test_abc_gcode_under_a_machine_gives_the_apt_axes():
    # Head-table with tool centre point control: B tilts the head about +y, C turns the
    # table about +z; the axis in the workpiece is (sin b cos c, -sin b sin c, cos b).
    machine = {
        "tcp": True,
        "rotaries": [
            {"word": "B", "carrier": "head", "direction": [0, 1, 0]},
            {"word": "C", "carrier": "table", "direction": [0, 0, 1], "limits": [-7, 7]},
        ],
    }
    apt = deflect.GcodeProgram.from_apt_text(APT)
    lines = ["G21 G90 F900"]
    for tip, v in zip(apt.end * 1e3, apt.end_axis):
        b, c = math.degrees(math.acos(v[2])), math.degrees(math.atan2(-v[1], v[0]))
        lines.append(f"G1 X{tip[0]:.12f} Y{tip[1]:.12f} Z{tip[2]:.12f} B{b:.12f} C{c:.12f}")
    g = deflect.GcodeProgram.from_text("\n".join(lines) + "\n", kinematics=machine)
    np.testing.assert_allclose(g.end, apt.end, atol=1e-12)
    np.testing.assert_allclose(g.end_axis, apt.end_axis, atol=1e-9)
    with pytest.raises(deflect.LoadError, match="kinematics"):
        deflect.GcodeProgram.from_text("G1 X1 B10 F100\n")
    bad = {"tcp": True, "rotaries": [machine["rotaries"][0]]}
    with pytest.raises(deflect.DeflectError, match="two rotary"):
        deflect.GcodeProgram.from_text("G1 X1 F100\n", kinematics=bad)
    same = {"tcp": True, "rotaries": [machine["rotaries"][0]] * 2}
    with pytest.raises(deflect.DeflectError, match="same word"):
        deflect.GcodeProgram.from_text("G1 X1 F100\n", kinematics=same)


def test_dexels_cut_the_closed_form_slot_and_a_program():
    stock = deflect.Dexels((0.0, -0.008, -0.008), (0.014, 0.008, 0.0), 0.25e-3)
    assert stock.shape == (56, 64, 32)
    full = stock.volume
    rays, removed = stock.cut("flat", 0.006, 0.01, (0.0035, 0, -0.002), (0, 0, 1),
                              (0.0105, 0, -0.002), (0, 0, 1))
    # The stadium of the 7 mm slot of a 6 mm end mill, 2 mm deep (sampled by the rays: within
    # its perimeter times the depth times a cell).
    want = (0.006 * 0.007 + math.pi * 0.003**2) * 0.002
    perimeter = 2 * 0.007 + 2 * math.pi * 0.003
    assert rays > 0 and abs(removed - want) < perimeter * 0.002 * 0.25e-3
    assert abs(full - stock.volume - removed) < 1e-15
    inside = stock.is_material([[0.007, 0.0, -0.001], [0.007, 0.0, -0.003], [0.007, 0.005, -0.001]])
    assert inside.tolist() == [False, True, True]
    p = deflect.GcodeProgram.from_apt_text(APT)
    _, v = stock.cut_program(p, "ball", 0.008, 0.02)
    assert v == 0.0  # the program runs above the block
    with pytest.raises(deflect.DeflectError, match="shape"):
        stock.cut("cone", 0.006, 0.01, (0, 0, 0), (0, 0, 1), (0, 0, 0), (0, 0, 1))
    with pytest.raises(deflect.DeflectError, match="axis"):
        stock.cut("flat", 0.006, 0.01, (0, 0, 0), (0, 0, 2), (0, 0, 0), (0, 0, 1))
    with pytest.raises(deflect.DeflectError):
        deflect.Dexels((0, 0, 0), (1, 1, 1), 1e-4)


SWARF = (
    "UNITS/MM\nSPINDL/12000,CLW\nRAPID\nGOTO/-12,-22,20,0,0,1\nRAPID\n"
    "GOTO/-12,-22,5,0,-0.2588190,0.9659258\nFEDRAT/MMPM,1200\n"
    "GOTO/-12,-22,-3,0,-0.2588190,0.9659258\nGOTO/60,-22,-3,0,-0.2588190,0.9659258\n"
    "GOTO/60,-22,10,0,0,1\nFINI\n"
)


def under_tcp(robot, q):
    """The workpiece frame 20 mm below the TCP at `q`, the TCP pointing down its z."""
    tcp = robot.forward(q)
    rot = tcp[:3, :3] @ np.diag([1.0, -1.0, -1.0]).T
    t = np.eye(4)
    t[:3, :3] = rot
    t[:3, 3] = tcp[:3, 3] - rot @ [0.0, 0.0, 0.02]
    return t


@pytest.fixture(scope="module")
def swarf_run(kr300):
    q0 = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0]
    placement = under_tcp(kr300, q0)
    job = deflect.MachiningJob(
        kr300, placement, stock_min=(0.0, -0.03), stock_max=(0.08, 0.03), cell=1e-3
    )
    program = deflect.GcodeProgram.from_apt_text(SWARF)
    return job, program, placement, job.run_five_axis(program, q0)


def test_the_five_axis_swarf_cut_against_the_numpy_chain(swarf_run, kr300_ref):
    job, program, placement, r = swarf_run
    rot, origin = placement[:3, :3], placement[:3, 3]
    cutting = np.flatnonzero(r.bands > 0)
    assert len(cutting) > 100
    for k in cutting[:: len(cutting) // 7]:
        w = np.concatenate([rot @ r.wrench[k][:3], rot @ r.wrench[k][3:]])
        # The loaded tips by the numpy chain (not the VJM that computed them), back in the
        # workpiece frame: the compensated one on the program, the uncompensated as reported.
        loaded = kr300_ref.forward(r.q_commanded[k])[:3, 3] + kr300_ref.deflection(r.q_commanded[k], w)[:3]
        np.testing.assert_allclose(rot.T @ (loaded - origin), r.position[k], atol=2e-8)
        free = kr300_ref.forward(r.q[k])[:3, 3] + kr300_ref.deflection(r.q[k], w)[:3]
        np.testing.assert_allclose(rot.T @ (free - origin), r.uncompensated_tip[k], atol=1e-9)
    off = np.linalg.norm(r.uncompensated_tip[cutting] - r.position[cutting], axis=1)
    assert off.max() > 5e-5, off.max()
    # The program's tool axis in the target: the rigid TCP's z at q is minus the axis.
    k = cutting[len(cutting) // 2]
    z = rot.T @ kr300_ref.forward(r.q[k])[:3, 2]
    np.testing.assert_allclose(-z, r.axis[k], atol=1e-8)
    np.testing.assert_allclose(r.axis[k], [0.0, -0.2588190, 0.9659258], atol=1e-7)
    e = r.errors("compensated")
    assert e["max_position"] <= 1e-8 and e["max_axis"] <= 1e-8, e


def test_the_five_axis_parts_along_the_normal_and_as_ply(swarf_run, tmp_path):
    _, _, _, r = swarf_run
    comp = r.surface("compensated")
    unc = r.surface("uncompensated")
    assert len(comp["deviation"]) > 1000 and comp["unmatched"] == 0
    assert np.max(np.abs(comp["deviation"])) < 1e-8
    assert np.max(np.abs(unc["deviation"])) > 2e-5
    np.testing.assert_allclose(np.linalg.norm(comp["normal"], axis=1), 1.0, rtol=1e-12)
    assert set(comp["face"]) <= {"+x", "-x", "+y", "-y", "+z", "-z"}
    path = tmp_path / "part.ply"
    r.write_ply(path, "uncompensated", ascii=True)
    header = path.read_text().split("end_header\n")[0]
    assert f"element vertex {len(unc['deviation'])}\n" in header
    with pytest.raises(OSError):
        r.write_ply(tmp_path / "missing" / "part.ply")
    with pytest.raises(deflect.InputError, match="part"):
        r.surface("both")


def test_the_five_axis_spin_turns_about_the_programs_axis(swarf_run, kr300):
    _, program, placement, r = swarf_run
    q0 = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0]
    spun = deflect.MachiningJob(
        kr300, placement, stock_min=(0.0, -0.03), stock_max=(0.08, 0.03), cell=1e-3,
        spin=10.0,  # degrees
    ).run_five_axis(program, q0)
    np.testing.assert_allclose(spun.spin, math.radians(10.0), rtol=1e-15)
    k = int(np.flatnonzero(spun.bands > 0)[40])
    rot = placement[:3, :3]
    a, b = (rot.T @ kr300.forward(x[k])[:3, :3] for x in (r.q, spun.q))
    np.testing.assert_allclose(-b[:, 2], spun.axis[k], atol=1e-8)
    angle = math.atan2(np.cross(a[:, 0], b[:, 0]) @ a[:, 2], a[:, 0] @ b[:, 0])
    assert abs(abs(angle) - math.radians(10.0)) < 1e-7
    assert spun.errors("compensated")["max_position"] <= 1e-8


def test_five_axis_faults_are_typed(swarf_run, kr300):
    job, program, _, _ = swarf_run
    q0 = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0]
    with pytest.raises(deflect.DeflectError, match="depth"):
        job.run_five_axis(program, q0, depth=0.0)
    with pytest.raises(deflect.InputError, match="shape"):
        job.run_five_axis(program, q0, shape="cone")
    # The z-map pass refuses the tilted program rather than drop its axis.
    with pytest.raises(deflect.DeflectError, match="2.5-D"):
        job.run(program, q0)
