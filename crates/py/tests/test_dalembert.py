"""deflect.DalembertCorrector: the paper's 2 kHz D'Alembert correction loop from Python."""

import numpy as np
import pytest

import deflect
from conftest import REPO

OC = REPO / "data" / "paksoy2025_compliance_oc.csv"
HEADER = "i,j,x_mm,y_mm,m,n,o,p,s,u,v,w\n"


def constant_table(tmp_path, m=0.0, o=0.0, s=0.0, v=0.0):
    """The paper's 3 x 5 grid with the same lines everywhere (mm per N, no offsets)."""
    rows = [
        f"{i},{j},{122.132 + 50 * i},{-112.5 + 37.5 * j},{m},0,{o},0,{s},0,{v},0\n"
        for i in range(1, 4)
        for j in range(1, 6)
    ]
    p = tmp_path / "const.csv"
    p.write_text(HEADER + "".join(rows))
    return deflect.ComplianceMap.from_csv(p, force_unit="N", length_unit="mm", out_of_grid="clamp")


def test_zero_map_leaves_path_unchanged(tmp_path):
    robot = deflect.ParallelRobot2()
    corr = deflect.DalembertCorrector(constant_table(tmp_path), robot, mass=5.0, iterations=3)
    v, a, j = deflect.paper_limits(5)
    traj = deflect.plan_line([0.172132, 0.0], [0.272132, 0.0], v, a, j)
    out = corr.correct(traj)
    np.testing.assert_array_equal(out.commanded, traj.position)
    np.testing.assert_array_equal(out.joints[10], robot.ik(traj.position[10]))


def test_constant_map_gives_c_m_a(tmp_path):
    # mm/N slopes -> m/N: 2e-3 mm/N = 2e-6 m/N.
    corr = deflect.DalembertCorrector(
        constant_table(tmp_path, m=2e-3, o=-0.5e-3, s=0.3e-3, v=4e-3), deflect.ParallelRobot2(), mass=5.0
    )
    a = np.array([3 * 9.81, -2 * 9.81])
    x = np.array([0.2, 0.01])
    t = corr.step(x, a)
    C = np.array([[2e-6, -0.5e-6], [0.3e-6, 4e-6]])
    np.testing.assert_allclose(t["force"], -5.0 * a)
    np.testing.assert_allclose(t["commanded"], x + C @ (5.0 * a), rtol=0, atol=1e-17)
    assert t["model_status"] == "inside"


def test_fixed_point_and_batch_equal_step():
    cmap = deflect.ComplianceMap.from_csv(OC, force_unit="N", length_unit="mm", out_of_grid="clamp")
    corr = deflect.DalembertCorrector(cmap, deflect.ParallelRobot2(), mass=5.0, iterations=20, tolerance=1e-14)
    v, a, j = deflect.paper_limits(5)
    traj = deflect.plan_polyline([[0.19, -0.05], [0.25, 0.0], [0.19, 0.05], [0.19, -0.05]], v, a, j)
    out = corr.correct(traj)
    assert out.commanded.shape == (len(traj), 2)
    np.testing.assert_array_equal(out.position, out.commanded)  # the old name still reads
    for i in range(0, len(traj), 97):
        t = corr.step(traj.position[i], traj.acceleration[i])
        np.testing.assert_array_equal(t["commanded"], out.commanded[i])
        np.testing.assert_array_equal(t["joints"], out.joints[i])
        # The map's own prediction at the command lands on the desired path.
        reached = out.commanded[i] + cmap.displacement(out.commanded[i], out.force[i])
        np.testing.assert_allclose(reached, traj.position[i], atol=1e-12)
    # Sub-millimetre corrections at 5 g with m* = 5 kg, force unit read as N.
    corr_mm = np.linalg.norm(out.commanded - out.desired, axis=1).max() * 1e3
    assert 0.01 < corr_mm < 2.0


def test_bad_inputs(tmp_path):
    cmap = deflect.ComplianceMap.from_csv(OC)  # out_of_grid="error"
    corr = deflect.DalembertCorrector(cmap, deflect.ParallelRobot2())
    assert corr.mass == 5.0
    with pytest.raises(deflect.InputError, match="out of|outside"):
        corr.step([0.15, 0.0], [9.81, 0.0])
    with pytest.raises(deflect.InputError, match="position"):
        corr.step([np.nan, 0.0], [9.81, 0.0])
    with pytest.raises(deflect.InputError, match=r"expected shape \(2,\)"):
        corr.step([0.2, 0.0, 0.0], [9.81, 0.0])
    with pytest.raises(deflect.InputError, match="mass"):
        deflect.DalembertCorrector(cmap, deflect.ParallelRobot2(), mass=-1.0)
    v, a, j = deflect.paper_limits(1)
    traj3 = deflect.plan_line([0.2, 0.0, 0.0], [0.25, 0.0, 0.0], v, a, j)
    with pytest.raises(deflect.InputError, match="2-D trajectory"):
        corr.correct(traj3)
