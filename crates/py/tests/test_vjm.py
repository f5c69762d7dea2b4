"""deflect.SerialRobot against hand-derived values and an independent numpy reading of the
VJM paper's Eq. 1-9 (conftest.NumpyChain)."""

import math
import threading

import numpy as np
import pytest

import deflect
from conftest import KR300_POSE, KR300_TOML, KR300_URDF, NumpyChain, ur5_urdf

RNG = np.random.default_rng(20261122)


def test_kr300_matches_independent_numpy_model(kr300, kr300_ref):
    assert kr300.dof == 6
    assert kr300.joint_names == ["a1", "a2", "a3", "a4", "a5", "a6"]
    for _ in range(20):
        q = KR300_POSE + RNG.uniform(-0.5, 0.5, 6)
        w = np.concatenate([RNG.uniform(-800, 800, 3), RNG.uniform(-80, 80, 3)])
        np.testing.assert_allclose(kr300.forward(q), kr300_ref.forward(q), atol=1e-12)
        np.testing.assert_allclose(kr300.deflection(q, w), kr300_ref.deflection(q, w), rtol=1e-9, atol=1e-15)


def test_kr300_milling_load_figure(kr300):
    # 546 N in the horizontal plane: the paper reports up to 1.4 mm uncompensated.
    d = kr300.deflection(KR300_POSE, np.array([-386.1, 386.1, 0, 0, 0, 0]))
    assert np.linalg.norm(d[:3]) == pytest.approx(1.443e-3, rel=2e-3)


def test_compliance_is_the_derivative_of_deflection(kr300):
    """Central differences of the exact model reproduce C column by column."""
    q = KR300_POSE
    c = kr300.compliance(q)
    np.testing.assert_allclose(c, c.T, atol=1e-20)
    for j, h in enumerate([10.0] * 3 + [1.0] * 3):
        e = np.zeros(6)
        e[j] = h
        col = (kr300.deflection(q, e) - kr300.deflection(q, -e)) / (2 * h)
        np.testing.assert_allclose(col, c[:, j], rtol=1e-6, atol=1e-13)


def test_batch_equals_single(kr300):
    n = 50
    Q = KR300_POSE + RNG.uniform(-0.3, 0.3, (n, 6))
    W = RNG.uniform(-500, 500, (n, 6))
    out = kr300.deflection_batch(Q, W)
    assert out.shape == (n, 6)
    for i in range(n):
        np.testing.assert_array_equal(out[i], kr300.deflection(Q[i], W[i]))
    # Non-contiguous views work too.
    np.testing.assert_array_equal(kr300.deflection_batch(Q[::2], W[::2]), out[::2])


def test_single_calls_read_every_vector_layout(kr300):
    """Contiguous float64 vectors are copied at once, anything else element by element or
    through numpy: the same numbers either way."""
    q = KR300_POSE + RNG.uniform(-0.3, 0.3, 6)
    w = RNG.uniform(-500, 500, 6)
    want = kr300.linear_deflection(q, w)
    wide = np.zeros((2, 12))
    wide[0, ::2], wide[1, ::2] = q, w
    fortran = np.asfortranarray(np.stack([q, w]))
    layouts = [
        (wide[0, ::2], wide[1, ::2]),  # strided views
        (q[::-1].copy()[::-1], w[::-1].copy()[::-1]),  # negative strides
        (fortran[0], fortran[1]),  # rows of a Fortran-ordered array
        (list(q), tuple(w)),
        (np.ascontiguousarray(q), np.ascontiguousarray(w)),
        # Past the plain-ndarray check: a subclass, a big-endian float64 and an equal float64
        # dtype that is not numpy's own descriptor go through rust-numpy's checked cast or numpy.
        (q.view(Subclass), w.view(Subclass)),
        (q.astype(">f8"), w.astype(">f8")),
        (q.view(np.dtype("f8", metadata={"unit": "rad"})), w.view(np.dtype("f8", metadata={}))),
    ]
    for a, b in layouts:
        np.testing.assert_array_equal(kr300.linear_deflection(a, b), want)
    np.testing.assert_array_equal(kr300.forward(wide[0, ::2]), kr300.forward(q))
    single = q.astype(np.float32)
    np.testing.assert_array_equal(
        kr300.linear_deflection(single, w), kr300.linear_deflection(single.astype(np.float64), w)
    )
    with pytest.raises(deflect.DeflectError):
        kr300.linear_deflection(q[:5], w)
    with pytest.raises(deflect.DeflectError):
        kr300.linear_deflection(wide[0, ::2][:5], w)
    # A float64 array of one more dimension or none is refused, not read as its numbers.
    for bad in [q[None, :], np.float64(1.0), np.zeros(())]:
        with pytest.raises(deflect.DeflectError):
            kr300.linear_deflection(bad, w)
        with pytest.raises(deflect.DeflectError):
            kr300.linear_deflection(q, bad)


class Subclass(np.ndarray):
    """An ndarray subclass: not a plain `numpy.ndarray`, still read as one."""


def test_batch_runs_in_threads(kr300):
    Q = np.tile(KR300_POSE, (2000, 1))
    W = np.tile([100.0, 0, 0, 0, 0, 0], (2000, 1))
    results = [None] * 4

    def work(i):
        results[i] = kr300.deflection_batch(Q, W)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        np.testing.assert_array_equal(r, results[0])


def test_joint_correction_cancels_the_deflection(kr300):
    q = KR300_POSE
    w = np.array([-386.1, 386.1, -200.0, 0, 0, 0])
    dq = kr300.joint_correction(q, w, max_iterations=10, tolerance=1e-12)
    # The corrected, loaded robot puts its TCP on the rigid target.
    target = kr300.forward(q)
    d = kr300.deflection(q + dq, w)
    loaded = kr300.forward(q + dq)[:3, 3] + d[:3]
    np.testing.assert_allclose(loaded, target[:3, 3], atol=1e-11)
    # First order: dq = -J^+ delta.
    J = kr300.joint_jacobian(q)
    one = kr300.joint_correction(q, w, max_iterations=1, tolerance=1e-3)
    np.testing.assert_allclose(one, -np.linalg.pinv(J) @ kr300.deflection(q, w), rtol=1e-9, atol=1e-15)


def test_joint_jacobian_by_finite_differences(kr300):
    q = KR300_POSE
    J = kr300.joint_jacobian(q)
    h = 1e-6
    for j in range(6):
        dq = np.zeros(6)
        dq[j] = h
        dp = (kr300.forward(q + dq)[:3, 3] - kr300.forward(q - dq)[:3, 3]) / (2 * h)
        np.testing.assert_allclose(J[:3, j], dp, atol=1e-8)


def test_commanded_pose_inverts_the_deflection(kr300):
    q = KR300_POSE
    target = kr300.forward(q)
    d = kr300.deflection(q, np.array([300.0, -200, 100, 5, 0, 0]))
    cmd = deflect.commanded_pose(target, d)
    np.testing.assert_allclose(cmd[:3, 3], target[:3, 3] - d[:3], atol=1e-15)


def test_ur5_rigid_fk_matches_independent_computation(tmp_path):
    urdf = ur5_urdf()
    toml = tmp_path / "ur5_stiffness.toml"
    # Our choice of stiffnesses: harmonic-drive-like joints, about 1e4..1e5 N m/rad.
    toml.write_text(
        "".join(
            f'[[virtual_joint]]\nlink = "{link}"\nk = [{k * 3}, {k * 3}, {k}]\n'
            for link, k in [
                ("shoulder_link", 1.0e5),
                ("upper_arm_link", 8.0e4),
                ("forearm_link", 5.0e4),
                ("wrist_1_link", 2.0e4),
                ("wrist_2_link", 2.0e4),
                ("wrist_3_link", 1.5e4),
            ]
        )
    )
    robot = deflect.SerialRobot.from_urdf(urdf, toml, "tool0")
    ref = NumpyChain(urdf, toml, "tool0")
    assert robot.dof == 6 and robot.base_link == "world"
    # Hand check at zero: tool0 is at x = -(0.425 + 0.39225), y = -(0.10915 + 0.0823), z = 0.089159 - 0.09465
    # in the URDF's base_link frame (the UR5's upper arm and forearm point along -x at zero).
    t0 = robot.forward(np.zeros(6))
    np.testing.assert_allclose(t0[:3, 3], [0.81725, 0.19145, -0.005491], atol=1e-9)
    for _ in range(20):
        q = RNG.uniform(-math.pi, math.pi, 6)
        np.testing.assert_allclose(robot.forward(q), ref.forward(q), atol=1e-12)
        w = RNG.uniform(-100, 100, 6)
        np.testing.assert_allclose(robot.deflection(q, w), ref.deflection(q, w), rtol=1e-8, atol=1e-14)


def test_exceptions_are_value_errors(kr300, tmp_path):
    assert issubclass(deflect.DeflectError, ValueError)
    for cls in (deflect.LoadError, deflect.InputError, deflect.SingularError, deflect.ConvergenceError):
        assert issubclass(cls, deflect.DeflectError)
    with pytest.raises(deflect.InputError, match=r"q: expected shape \(6,\)"):
        kr300.deflection(np.zeros(5), np.zeros(6))
    with pytest.raises(deflect.InputError, match=r"q\[2\] is not finite"):
        kr300.deflection(np.array([0, 0, np.nan, 0, 0, 0.0]), np.zeros(6))
    with pytest.raises(deflect.InputError, match=r"wrench\[5\] is not finite"):
        kr300.deflection(KR300_POSE, np.array([0, 0, 0, 0, 0, np.inf]))
    with pytest.raises(deflect.InputError, match=r"W: expected shape \(N, 6\) or \(6,\), got \(3, 5\)"):
        kr300.deflection_batch(np.zeros((3, 6)), np.zeros((3, 5)))
    with pytest.raises(deflect.InputError, match="row 1"):
        kr300.deflection_batch(np.array([KR300_POSE, [np.nan] * 6]), np.zeros((2, 6)))
    with pytest.raises(deflect.LoadError, match="unknown link 'nope'"):
        deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "nope")
    bad = tmp_path / "bad.toml"
    bad.write_text('[[virtual_joint]]\nlink = "link_2"\nk = [1.0, -5.0, 1.0]\n')
    with pytest.raises(deflect.LoadError, match="virtual_joint #0 on link 'link_2'"):
        deflect.SerialRobot.from_urdf(KR300_URDF, bad, "tcp")
    with pytest.raises(deflect.LoadError, match="cannot read"):
        deflect.SerialRobot.from_urdf(tmp_path / "missing.urdf", KR300_TOML, "tcp")
    with pytest.raises(ValueError):
        kr300.compliance(np.zeros(7))


def test_spring_angles_follow_eq7(kr300):
    # A pure moment about the TCP reaches every spring unchanged (Eq. 6 with F = 0).
    q = KR300_POSE
    m = np.array([0.0, 0.0, 0.0, 30.0, -20.0, 10.0])
    angles = kr300.spring_angles(q, m)
    assert angles.shape == (11, 3)
    i = kr300.spring_names.index("spindle")
    k = np.array([1.9e5, 6.7e4, 9.1e4])
    assert np.linalg.norm(angles[i] * k) == pytest.approx(np.linalg.norm(m[3:]), rel=1e-12)
