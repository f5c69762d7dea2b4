"""deflect against its peers, back to back in one process: ratios and agreement.

Every peer is set up once, as its own documentation calls it, and only its computing call is
timed: Pinocchio's model and data are built once (then `computeFrameJacobian` per call),
scipy's interpolators once (then a call per batch), ruckig's `Ruckig`, `InputParameter` and
`Trajectory` once with the input filled (then `calculate` per plan, `at_time` per tick).
deflect's objects are likewise built once.

Run by hand on a quiet machine (not a test: nothing here asserts a time):

    .venv/bin/pip install pin scipy ruckig example-robot-data   # once
    .venv/bin/python benches/peers.py [--quick]

Each pair computes the same thing on the same inputs, and the table gives the median time per
call (or per point / row), the deflect/peer ratio (< 1: deflect is faster) and the largest
difference between the two results:

- UR5 compliance and deflection (example-robot-data's UR5, deflect's `robots/ur5` springs):
  Pinocchio with the springs as extra joints (three revolute joints per spring: the drive's
  axis and two bending axes), one `computeFrameJacobian` and `J K^-1 J^T w` in numpy, against
  `SerialRobot.linear_deflection` (and `compliance`), and per row in batches;
- compliance map (Paksoy, Dede and Kiper 2025, Eq. 9-14, OC map): scipy's
  RegularGridInterpolator (linear, and cubic: a different C1/C2 interpolant, so its agreement is
  the gap between two smooth fits, not a check) on the 8 coefficient fields, against
  `ComplianceMap.displacement` and `displacement_batch`;
- jerk-limited motion: ruckig's `calculate` (plan only) and `calculate` + `at_time` per tick at
  2 kHz, against `plan_line(..., rate_hz=None)` and `plan_line(...)` + `position`; ruckig's
  habit on both sides (one planner object re-planned in place), with the input points set once
  (`LinePlanner.start` / `end`, then `plan()`) and with new points set per plan
  (`plan(start, end)`); both sides called through a lambda; on a 1-D move
  and on the paper's 2-D y-line (deflect limits the path, ruckig each axis: with one axis
  moving both solve the same problem).
"""

import argparse
import os
import pathlib
import statistics
import sys
import time

# OpenBLAS's worker threads spin after each matrix product and take a core from the
# threaded batches measured next; neither side's timed work uses BLAS threads.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import deflect  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]


def median_time(fn, repeats, inner=1):
    """Median seconds per call of `fn` over `repeats` samples of `inner` calls each."""
    fn()  # warm up (first-call imports, caches)
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(inner):
            fn()
        samples.append((time.perf_counter() - t0) / inner)
    return statistics.median(samples)


def row(name, t_deflect, t_peer, unit_scale, unit, agreement):
    ratio = t_deflect / t_peer
    print(
        f"{name:<44} {t_deflect * unit_scale:>10.3f} {t_peer * unit_scale:>10.3f} {unit:<8}"
        f" {ratio:>7.3f}  {1 / ratio:>7.1f}x  "
        + ("n/a (exact vs linear model)" if agreement is None else f"{agreement:.1e}")
    )


def ur5_urdf():
    from importlib import metadata

    dist = metadata.distribution("example-robot-data")
    return pathlib.Path(
        dist.locate_file("cmeel.prefix/share/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf")
    )


def springs_of(toml_path):
    """(joint name, [k_axis, k_bend1, k_bend2]) per `[[virtual_joint]]` of a stiffness file."""
    import tomllib

    with open(toml_path, "rb") as f:
        return [(v["joint"], v["k"]) for v in tomllib.load(f)["virtual_joint"]]


class PinocchioCompliance:
    """C = J_s K^-1 J_s^T at the tool frame with the springs as extra Pinocchio joints.

    Each spring becomes three revolute joints RX, RY, RZ at zero angle, right after its
    actuated joint and in that joint's frame (the spring frame of the stiffness file, whose
    first axis is the joint axis), and the joints after it hang from the spring. One
    `computeFrameJacobian` (LOCAL_WORLD_ALIGNED) then gives every spring column: both
    libraries compute the same thing, in compiled code."""

    def __init__(self, urdf, toml_path, tip):
        import pinocchio as pin

        self.pin = pin
        src = pin.buildModelFromUrdf(str(urdf))
        springs = dict(springs_of(toml_path))
        k = np.array(list(springs.values()), dtype=float)
        assert np.all(k[:, 1] == k[:, 2]), "bending stiffnesses must be equal for this reference"
        m = pin.Model()
        hang = {0: 0}  # source joint -> the new joint its children hang from
        spring_joints, inv_k, q_pairs = [], [], []
        for jid in range(1, src.njoints):
            joint, name = src.joints[jid], src.names[jid]
            new = m.addJoint(hang[src.parents[jid]], joint, src.jointPlacements[jid], name)
            q_pairs.append((joint.idx_q, new))
            hang[jid] = new
            if name not in springs:
                continue
            kj = springs[name]
            ax = {"JointModelRX": 0, "JointModelRY": 1, "JointModelRZ": 2}[joint.shortname()]
            for c, jm in enumerate([pin.JointModelRX(), pin.JointModelRY(), pin.JointModelRZ()]):
                hang[jid] = m.addJoint(hang[jid], jm, pin.SE3.Identity(), f"{name}_spring_{c}")
                spring_joints.append(hang[jid])
                # The drive axis gets the torsional compliance, the two others the bending one.
                inv_k.append(1.0 / (kj[0] if c == ax else kj[1]))
        f = src.frames[src.getFrameId(tip)]
        self.tip = m.addFrame(pin.Frame(tip, hang[f.parentJoint], f.placement, pin.FrameType.OP_FRAME))
        self.model, self.data = m, m.createData()
        self.cols = np.array([m.joints[j].idx_v for j in spring_joints])
        self.inv_k = np.array(inv_k)
        self.src_q = np.array([s for s, _ in q_pairs])
        self.dst_q = np.array([m.joints[n].idx_q for _, n in q_pairs])
        self.q = pin.neutral(m)  # spring angles stay 0

    def compliance(self, q):
        self.q[self.dst_q] = q[self.src_q]
        j = self.pin.computeFrameJacobian(
            self.model, self.data, self.q, self.tip, self.pin.LOCAL_WORLD_ALIGNED
        )[:, self.cols]
        return (j * self.inv_k) @ j.T


def bench_vjm(args):
    urdf, toml = ur5_urdf(), ROOT / "robots/ur5/ur5_stiffness.toml"
    robot = deflect.SerialRobot.from_urdf(urdf, toml, "tool0")
    peer = PinocchioCompliance(urdf, toml, "tool0")
    rng = np.random.default_rng(1)
    q = rng.uniform(-2.0, 2.0, 6)
    w = np.array([30.0, -20.0, 50.0, 2.0, -1.0, 0.5])

    c_d, c_p = robot.compliance(q), peer.compliance(q)
    agree_c = np.abs(c_d - c_p).max() / np.abs(c_p).max()
    t_d = median_time(lambda: robot.linear_deflection(q, w), args.repeats, args.inner)
    t_p = median_time(lambda: peer.compliance(q) @ w, args.repeats, args.inner)
    row("UR5 compliance + C w (linear_deflection)", t_d, t_p, 1e6, "us", agree_c)
    t_d = median_time(lambda: robot.compliance(q), args.repeats, args.inner)
    t_p = median_time(lambda: peer.compliance(q), args.repeats, args.inner)
    row("UR5 compliance (6, 6)", t_d, t_p, 1e6, "us", agree_c)

    n = args.rows
    qs = rng.uniform(-2.0, 2.0, (n, 6))
    ws = rng.uniform(-50.0, 50.0, (n, 6))
    d_batch = robot.compliance_batch(qs) @ ws[:, :, None]
    ref = np.array([peer.compliance(qs[i]) @ ws[i] for i in range(min(n, 200))])
    agree_b = np.abs(d_batch[: len(ref), :, 0] - ref).max() / np.abs(ref).max()
    t_d = median_time(lambda: robot.compliance_batch(qs), max(5, args.repeats // 2)) / n
    t_p = median_time(lambda: [peer.compliance(x) for x in qs[:2000]], 3) / 2000
    row(f"UR5 compliance, batch of {n} (per row)", t_d, t_p, 1e6, "us", agree_b)
    t_d = median_time(lambda: robot.deflection_batch(qs, ws), max(5, args.repeats // 2)) / n
    row(f"UR5 deflection_batch of {n} (per row) vs C w", t_d, t_p, 1e6, "us", None)


def bench_map(args):
    from scipy.interpolate import RegularGridInterpolator

    m = deflect.ComplianceMap.from_csv(ROOT / "data/paksoy2025_compliance_oc.csv")
    rng = np.random.default_rng(0)
    n = args.points
    p = np.column_stack([rng.uniform(m.x[0], m.x[-1], n), rng.uniform(m.y[0], m.y[-1], n)])
    f = rng.uniform(-250.0, 250.0, (n, 2))
    nx, ny = len(m.x), len(m.y)
    fields = np.concatenate([m.slopes.reshape(nx, ny, 4), m.offsets.reshape(nx, ny, 4)], axis=2)

    def scipy_of(rgi):
        def run(pp, ff):
            c = rgi(pp)
            s = c[:, :4].reshape(-1, 2, 2)
            o = c[:, 4:].reshape(-1, 2, 2)
            return np.einsum("ndf,nf->nd", s, ff) + o.sum(axis=2)
        return run

    for method, interp in [("linear", "bilinear"), ("cubic", "bicubic")]:
        if method == "cubic" and min(nx, ny) < 4:
            print(f"{'map ' + method:<44} skipped: scipy's cubic needs 4 nodes per axis, the "
                  f"grid has {nx} x {ny}")
            continue
        peer = scipy_of(RegularGridInterpolator((m.x, m.y), fields, method=method))
        d = m.displacement_batch(p, f, interpolation=interp)
        agree = np.abs(d - peer(p, f)).max() / np.abs(d).max()
        t_d = median_time(lambda: m.displacement_batch(p, f, interpolation=interp), args.repeats)
        t_p = median_time(lambda: peer(p, f), max(3, args.repeats // 4))
        row(f"map {interp} vs RGI {method}, batch of {n} (per pt)", t_d / n, t_p / n, 1e9, "ns", agree)
        p1, f1 = p[0], f[0]
        t_d = median_time(lambda: m.displacement(p1, f1, interpolation=interp), args.repeats, args.inner)
        t_p = median_time(lambda: peer(p1[None], f1[None]), args.repeats, max(1, args.inner // 20))
        row(f"map {interp} vs RGI {method}, one query", t_d, t_p, 1e6, "us",
            np.abs(m.displacement(p1, f1, interpolation=interp) - peer(p1[None], f1[None])[0]).max()
            / np.abs(d).max())


def bench_motion(args):
    import ruckig

    v, a, j = 1.2, 25.0, 600.0

    def ruckig_objects(start, end):
        """ruckig as its own examples call it: the Ruckig, InputParameter and Trajectory
        objects built and the input filled once; each plan is one `calculate`."""
        n = len(start)
        otg, inp, traj = ruckig.Ruckig(n), ruckig.InputParameter(n), ruckig.Trajectory(n)
        inp.current_position, inp.target_position = list(start), list(end)
        inp.current_velocity = inp.current_acceleration = [0.0] * n
        inp.target_velocity = inp.target_acceleration = [0.0] * n
        inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v] * n, [a] * n, [j] * n
        return otg, inp, traj

    # 1-D, and the paper's 150 mm y-line (x held: ruckig's per-axis limits and deflect's
    # path limits are then the same problem).
    for label, start, end in (
        ("1-D", [0.05], [0.35]),
        ("2-D y-line", [0.22, -0.075], [0.22, 0.075]),
    ):
        otg, inp, traj = ruckig_objects(start, end)
        otg.calculate(inp, traj)
        plan = deflect.plan_line(start, end, v, a, j, rate_hz=None)
        agree = abs(plan.duration - traj.duration) / traj.duration
        t_d = median_time(lambda: deflect.plan_line(start, end, v, a, j, rate_hz=None),
                          args.repeats, args.inner)
        t_p = median_time(lambda: otg.calculate(inp, traj), args.repeats, args.inner)
        row(f"{label} jerk-limited plan only (duration)", t_d, t_p, 1e6, "us", agree)
        # Both habits matched: one planner object re-planned in place per move, its input
        # points set once (ruckig's `InputParameter`; deflect's `LinePlanner.start / end`).
        planner = deflect.LinePlanner(len(start), v, a, j)
        planner.start, planner.end = start, end
        agree = abs(planner.plan() - traj.duration) / traj.duration
        t_d = median_time(lambda: planner.plan(), args.repeats, args.inner)
        t_p = median_time(lambda: otg.calculate(inp, traj), args.repeats, args.inner)
        row(f"{label} re-planned in place (LinePlanner.plan())", t_d, t_p, 1e6, "us", agree)

        # A new move per plan: both sides take the points from Python each time.
        def ruckig_new_move():
            inp.current_position, inp.target_position = start, end
            return otg.calculate(inp, traj)

        t_d = median_time(lambda: planner.plan(start, end), args.repeats, args.inner)
        t_p = median_time(ruckig_new_move, args.repeats, args.inner)
        row(f"{label} new points per plan (LinePlanner.plan(start, end))", t_d, t_p, 1e6, "us",
            agree)

        dt = 1.0 / 2000.0

        def ruckig_sampled():
            otg.calculate(inp, traj)
            k = int(np.floor(traj.duration / dt)) + 1
            return [traj.at_time(i * dt)[0] for i in range(k)]

        sampled = deflect.plan_line(start, end, v, a, j).position
        ref = np.array(ruckig_sampled())
        k = min(len(sampled), len(ref))
        agree = np.abs(sampled[:k] - ref[:k]).max() / np.abs(np.subtract(end, start)).max()
        t_d = median_time(lambda: deflect.plan_line(start, end, v, a, j).position,
                          max(5, args.repeats // 5))
        t_p = median_time(ruckig_sampled, max(5, args.repeats // 5))
        row(f"{label} plan + {len(sampled)} ticks at 2 kHz", t_d, t_p, 1e6, "us", agree)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats (a smoke run)")
    ap.add_argument("--only", choices=("vjm", "map", "motion"), action="append",
                    help="run only these groups (repeatable); all by default")
    ap.add_argument("--ur5-path", action="store_true",
                    help="print the UR5 URDF's path and exit (for DEFLECT_UR5_URDF, benches/vjm.rs)")
    args = ap.parse_args()
    if args.ur5_path:
        print(ur5_urdf())
        return
    args.repeats = 5 if args.quick else 41
    args.inner = 20 if args.quick else 200
    args.rows = 2_000 if args.quick else 20_000
    args.points = 10_000 if args.quick else 100_000
    print(f"deflect {deflect.__version__}, numpy {np.__version__}, Python {sys.version.split()[0]}")
    print(f"{'pair':<44} {'deflect':>10} {'peer':>10} {'unit':<8} {'ratio':>7}  {'speedup':>8}  "
          "max rel diff")
    for bench in (bench_vjm, bench_map, bench_motion):
        if args.only and bench.__name__.removeprefix("bench_") not in args.only:
            continue
        try:
            bench(args)
        except ImportError as e:
            print(f"{bench.__name__}: skipped, {e.name} is not installed (pip install pin scipy "
                  "ruckig example-robot-data)")


if __name__ == "__main__":
    main()
