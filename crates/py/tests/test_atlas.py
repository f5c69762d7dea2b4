"""The stiffness-optimal posture and the workspace atlas: the sweep agrees with a brute scan,
unreachable tasks are reported (NaN, never zeros), and the atlas gives the same numbers, bit for
bit, locally, on a process pool, on a local Dask cluster (2 workers) and on a local Ray (2 CPUs);
a killed worker is an error naming its chunk."""

import math
import os
import signal
from concurrent.futures import Future, ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

import deflect
from conftest import KR300_TOML, KR300_URDF, REPO, ur5_urdf

Q0 = np.array([0.3, -1.2, 1.5, -1.9, -1.57, 0.4])
WRENCH = np.array([30.0, -20.0, 50.0, 0.0, 0.0, 0.0])
ANGLES = np.radians(np.arange(-180.0, 180.0, 10.0))


@pytest.fixture(scope="module")
def ur5():
    return deflect.SerialRobot.from_urdf(ur5_urdf(), REPO / "robots/ur5/ur5_stiffness.toml", "tool0")


@pytest.fixture(scope="module")
def tasks(ur5):
    t = ur5.forward(Q0)
    rng = np.random.default_rng(5)
    p = t[:3, 3] + rng.uniform(-0.15, 0.15, (23, 3))
    p[7] = [3.0, 0.0, 0.5]  # far out of reach
    return p, t[:3, 2]


def test_sweep_matches_a_brute_scan_and_the_model():
    # The KR 300: its TCP sits off the last joint's axis, so turning the tool about its axis
    # moves the whole arm and the deflection changes with the angle. (On the UR5 with the
    # tool on the flange axis only the last joint turns and a pure force deflects the same
    # at every angle: the sweep is flat there, as it should be.)
    kr300 = deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp")
    q0 = np.array([0.0, -0.9, 1.4, 0.0, 1.0708, 0.0])
    milling = np.array([-386.1, 386.1, -60.0, 0.0, 0.0, 0.0])
    t = kr300.forward(q0)
    r = deflect.posture_sweep(kr300, t[:3, 3], t[:3, 2], milling, angles=ANGLES, seeds=q0)
    best = r["best"]
    assert r["reachable"].sum() >= 20
    assert np.nanmax(r["measure"]) > 1.1 * best["measure"]
    i = r["best_index"]
    centre = np.degrees(r["angle"][i])
    fine = np.radians(np.arange(centre - 10.0, centre + 10.0 + 1e-9, 0.1))
    brute = deflect.posture_sweep(
        kr300, t[:3, 3], t[:3, 2], milling, angles=fine, seeds=r["q"][i], refine=False
    )
    k = np.nanargmin(brute["measure"])
    # Angles compare on the circle: the full-turn sweep wraps at +-180 degrees.
    gap = np.angle(np.exp(1j * (best["angle"] - brute["angle"][k])))
    assert abs(gap) <= np.radians(0.1) + 1e-9
    assert ANGLES[0] - np.radians(5.0) <= best["angle"] < ANGLES[0] + 2 * np.pi
    assert best["measure"] <= brute["measure"][k] + 1e-12
    # Each reported posture is the model's: its deflection is SerialRobot.deflection there.
    for j in np.flatnonzero(r["reachable"])[:5]:
        np.testing.assert_array_equal(r["deflection"][j], kr300.deflection(r["q"][j], milling))
        # |dp| summed in order (numpy's norm may reorder or fuse the sum: an ulp apart).
        dx, dy, dz = (float(v) for v in r["deflection"][j][:3])
        assert r["measure"][j] == math.sqrt(dx * dx + dy * dy + dz * dz)
    # Measures: along the z axis only is the |dz| of the same postures.
    along = deflect.posture_sweep(
        kr300, t[:3, 3], t[:3, 2], milling, angles=ANGLES, seeds=q0, measure=[[0.0, 0.0, 2.0]],
        refine=False,
    )
    ok = along["reachable"]
    np.testing.assert_array_equal(along["measure"][ok], np.abs(along["deflection"][ok, 2]))


def test_unreachable_is_reported_never_zero(ur5, tasks):
    p, axis = tasks
    r = deflect.posture_sweep(ur5, p[7], axis, WRENCH, angles=ANGLES, seeds=Q0)
    assert r["best"] is None and r["best_index"] is None
    assert not r["reachable"].any() and set(r["reach"]) == {"out_of_reach"}
    assert np.isnan(r["measure"]).all() and np.isnan(r["deflection"]).all()
    a = deflect.atlas(ur5, p[6:9], axis, WRENCH, angles=ANGLES, seeds=Q0)
    assert a.reachable.tolist() == [True, False, True]
    assert a.reachable_angles[1] == 0 and a.best_seed[1] == -1
    for field in ["best_angle", "best_measure", "best_deflection", "best_q", "compliance"]:
        assert np.isnan(getattr(a, field)[1]).all(), field
        assert np.isfinite(getattr(a, field)[[0, 2]]).all(), field


def same(a, b):
    for name in a.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_local_and_executors_agree_bit_for_bit(ur5, tasks):
    p, axis = tasks
    local = deflect.atlas(ur5, p, axis, WRENCH, angles=ANGLES, seeds=Q0)
    assert local.best_measure.shape == (23,) and local.compliance.shape == (23, 6, 6)
    np.testing.assert_array_equal(local.compliance[0], ur5.compliance(local.best_q[0]))
    with ThreadPoolExecutor(2) as pool:
        same(deflect.atlas(ur5, p, axis, WRENCH, angles=ANGLES, seeds=Q0, executor=pool, chunk_size=5), local)
    with ProcessPoolExecutor(2) as pool:
        same(deflect.atlas(ur5, p, axis, WRENCH, angles=ANGLES, seeds=Q0, executor=pool, chunk_size=4), local)


def test_dask_local_cluster_agrees(ur5, tasks):
    distributed = pytest.importorskip("distributed")
    p, axis = tasks
    local = deflect.atlas(ur5, p, axis, WRENCH, angles=ANGLES, seeds=Q0)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        same(deflect.atlas(ur5, p, axis, WRENCH, angles=ANGLES, seeds=Q0, executor=client, chunk_size=6), local)


def test_ray_agrees(ur5, tasks):
    ray = pytest.importorskip("ray")
    p, axis = tasks
    local = deflect.atlas(ur5, p, axis, WRENCH, angles=ANGLES, seeds=Q0)
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        got = deflect.atlas(ur5, p, axis, WRENCH, angles=ANGLES, seeds=Q0,
                            executor=deflect.RayExecutor(), chunk_size=6)
    finally:
        ray.shutdown()
    same(got, local)


def test_a_killed_worker_is_an_error_naming_its_chunk(ur5, tasks):
    p, axis = tasks
    with ProcessPoolExecutor(1) as pool:
        pid = pool.submit(os.getpid).result()
        os.kill(pid, signal.SIGKILL)
        with pytest.raises(deflect.ChunkError, match=r"atlas chunk 0 \(tasks 0\.\.9\) failed: BrokenProcessPool"):
            deflect.atlas(ur5, p, axis, WRENCH, angles=ANGLES, seeds=Q0, executor=pool, chunk_size=10)

    class DiesOnChunk2(ThreadPoolExecutor):
        def __init__(self):
            super().__init__(2)
            self.n = 0

        def submit(self, fn, /, *args, **kwargs):
            self.n += 1
            if self.n != 3:
                return super().submit(fn, *args, **kwargs)
            f = Future()
            f.set_exception(RuntimeError("worker lost"))
            return f

    with DiesOnChunk2() as pool, pytest.raises(deflect.ChunkError, match=r"chunk 2 \(tasks 10\.\.14\)") as e:
        deflect.atlas(ur5, p, axis, WRENCH, angles=ANGLES, seeds=Q0, executor=pool, chunk_size=5)
    assert e.value.chunk == 2 and e.value.rows == range(10, 15)
    assert isinstance(e.value, deflect.DeflectError)


def test_bad_input_is_refused_before_anything_is_sent(ur5, tasks):
    p, axis = tasks

    class Refuses(ThreadPoolExecutor):
        def submit(self, *a, **k):
            raise AssertionError("nothing may be sent")

    with Refuses() as pool:
        for kwargs, match in [
            (dict(positions=p[:, :2]), "positions"),
            (dict(wrenches=np.ones(5)), "wrenches"),
            (dict(tool_axes=np.ones((3, 3))), "do not broadcast"),
            (dict(measure="sideways"), "measure"),
            (dict(angles=[]), "angles"),
            (dict(chunk_size=0), "chunk_size"),
            (dict(seeds=np.ones(5)), "seeds"),
        ]:
            args = dict(positions=p, tool_axes=axis, wrenches=WRENCH, angles=ANGLES, seeds=Q0,
                        executor=pool)
            args.update(kwargs)
            with pytest.raises(deflect.InputError, match=match):
                deflect.atlas(ur5, **args)
    with pytest.raises(TypeError, match="executor"):
        deflect.atlas(ur5, p, axis, WRENCH, executor=object())


def test_atlas_result_pickles(ur5, tasks):
    import pickle

    p, axis = tasks
    a = deflect.atlas(ur5, p[:3], axis, WRENCH, angles=ANGLES, seeds=Q0)
    same(pickle.loads(pickle.dumps(a)), a)


def test_the_cli_atlas_is_the_python_atlas(tmp_path):
    """`deflect-sim atlas` (release binary) writes the same numbers as deflect.atlas."""
    import subprocess

    out = tmp_path / "atlas"
    cmd = ["cargo", "run", "--release", "--quiet", "-p", "deflect-sim", "--", "atlas",
           "--region", "1.5:1.9:3,-0.3:0.3:3,0.2", "--angle-step", "15", "--out", str(out)]
    res = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=1800)
    assert res.returncode == 0, res.stderr
    z = np.load(out / "atlas.npz")
    kr300 = deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp")
    xs = 1.5 + (1.9 - 1.5) / 2 * np.arange(3)
    ys = -0.3 + (0.3 - -0.3) / 2 * np.arange(3)
    np.testing.assert_array_equal(z["x"], xs)
    np.testing.assert_array_equal(z["y"], ys)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    a = deflect.atlas(kr300, np.c_[X.ravel(), Y.ravel(), np.full(9, 0.2)], [0.0, 0.0, -1.0],
                      [-386.1, 386.1, 0, 0, 0, 0], angles=z["angles"],
                      seeds=[0.0, -0.9, 1.4, 0.0, 1.0708, 0.0])
    np.testing.assert_array_equal(z["angles"], np.radians(-180.0 + 15.0 * np.arange(24)))
    np.testing.assert_array_equal(z["best_measure"].ravel(), a.best_measure)
    np.testing.assert_array_equal(z["best_angle"].ravel(), a.best_angle)
    np.testing.assert_array_equal(z["best_q"].reshape(9, 6), a.best_q)
    np.testing.assert_array_equal(z["reachable"].ravel() == 1.0, a.reachable)


def _tool_orientation(z, theta):
    """The sweep's documented tool frame, written again in numpy: x the base x axis (y when
    the tool axis is near x) projected normal to the tool axis, turned by theta about it."""
    z = np.asarray(z, float) / np.linalg.norm(z)
    ref = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x0 = ref - z * (z @ ref)
    x0 /= np.linalg.norm(x0)
    y0 = np.cross(z, x0)
    c, s = math.cos(theta), math.sin(theta)
    return np.column_stack([c * x0 + s * y0, -s * x0 + c * y0, z])


def _rotation_vector(r):
    angle = math.acos(max(-1.0, min(1.0, (np.trace(r) - 1.0) / 2.0)))
    w = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    return w * (0.5 if angle < 1e-8 else angle / (2.0 * math.sin(angle)))


def _plain_ik(robot, target, q):
    """Damped least squares on the forward kinematics and the joint Jacobian: no sweep code."""
    q = np.array(q, float)
    for _ in range(200):
        t = robot.forward(q)
        e = np.r_[target[:3, 3] - t[:3, 3], _rotation_vector(target[:3, :3] @ t[:3, :3].T)]
        if np.linalg.norm(e) < 1e-13:
            return q
        j = robot.joint_jacobian(q)
        q = q + j.T @ np.linalg.solve(j @ j.T + 1e-12 * np.eye(6), e)
    return None


def test_sweep_best_agrees_with_an_independent_full_turn_scan():
    """Issue 28: the sweep's optimum against a scan written without any sweep code (numpy tool
    frames, a plain damped-least-squares IK continued along the full turn at every degree,
    the measure from SerialRobot.deflection), on a task whose best angle is no tie (the
    measure varies by more than 10 % over the turn). A wrong coarse optimum, a missed stretch
    of the turn or a wrong tool frame would each fail it."""
    kr300 = deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp")
    q0 = np.array([0.0, -0.9, 1.4, 0.0, 1.0708, 0.0])
    milling = np.array([-386.1, 386.1, -60.0, 0.0, 0.0, 0.0])
    t0 = kr300.forward(q0)
    axis = t0[:3, 2]
    r = deflect.posture_sweep(kr300, t0[:3, 3], axis, milling, angles=ANGLES, seeds=q0)
    best = r["best"]
    x_ref = _tool_orientation(axis, 0.0)
    theta0 = math.atan2(t0[:3, 0] @ x_ref[:, 1], t0[:3, 0] @ x_ref[:, 0])
    lims = np.array(kr300.joint_limits)
    q, scan = q0, []
    for k in range(361):
        theta = theta0 + math.radians(k)
        target = np.eye(4)
        target[:3, :3], target[:3, 3] = _tool_orientation(axis, theta), t0[:3, 3]
        sol = _plain_ik(kr300, target, q)
        if sol is None:
            continue
        q = sol
        # A revolute joint's equal angle a turn away, if that one is within its limits.
        sol = np.where(sol > lims[:, 1], sol - 2 * np.pi, np.where(sol < lims[:, 0], sol + 2 * np.pi, sol))
        if np.any(sol < lims[:, 0]) or np.any(sol > lims[:, 1]):
            continue
        scan.append((theta, np.linalg.norm(kr300.deflection(sol, milling)[:3])))
    scan = np.array(scan)
    # The joint limits close part of the turn to both (the sweep reaches 20-odd of its 36
    # angles): the scan's share of degrees is the sweep's share of angles.
    share = r["reachable"].mean()
    assert abs(len(scan) / 361 - share) < 0.1, (len(scan), share)
    assert scan[:, 1].max() > 1.1 * scan[:, 1].min()
    k = np.argmin(scan[:, 1])
    gap = np.angle(np.exp(1j * (best["angle"] - scan[k, 0])))
    # The sweep refines below the scan's degree: within a degree of the scan's best, and at
    # least as good.
    assert abs(gap) <= math.radians(1.0) + 1e-9, (math.degrees(best["angle"]), math.degrees(scan[k, 0]))
    assert best["measure"] <= scan[k, 1] + 1e-12
    assert best["measure"] >= scan[k, 1] - 1e-3 * scan[k, 1]
