"""Throughput of the workspace atlas (deflect.atlas) on the UR5, and where an evaluation's time
goes. Run by hand on a quiet machine (not a test):

    .venv/bin/python benches/atlas.py [--dask]

A pose evaluation is one angle of one task's sweep: the pose IK warm-started from the angle
before, the exact deflection under the wrench, and its measure. Reports evaluations per second
on every local core (and on a local 2-worker Dask cluster with --dask), then the per-evaluation
breakdown measured single-threaded: sweep (IK + deflection) per angle, deflection alone and
compliance alone per row, IK by difference.
"""

import argparse
import os
import pathlib
import statistics
import time

import numpy as np

import deflect

ROOT = pathlib.Path(__file__).resolve().parents[1]
Q0 = np.array([0.3, -1.2, 1.5, -1.9, -1.57, 0.4])
WRENCH = np.array([30.0, -20.0, 50.0, 1.0, -0.5, 0.2])


def ur5():
    from importlib import metadata

    urdf = metadata.distribution("example-robot-data").locate_file(
        "cmeel.prefix/share/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
    )
    return deflect.SerialRobot.from_urdf(urdf, ROOT / "robots/ur5/ur5_stiffness.toml", "tool0")


def median(fn, repeats=7):
    fn()
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def main():
    ap = argparse.ArgumentParser(description="deflect.atlas throughput")
    ap.add_argument("--dask", action="store_true", help="also on a local 2-worker Dask cluster")
    ap.add_argument("--tasks", type=int, default=512)
    args = ap.parse_args()
    robot = ur5()
    t = robot.forward(Q0)
    rng = np.random.default_rng(0)
    positions = t[:3, 3] + rng.uniform(-0.15, 0.15, (args.tasks, 3))
    angles = np.radians(np.arange(-180.0, 180.0, 1.0))
    evals = args.tasks * len(angles)
    print(f"UR5, {args.tasks} tasks x {len(angles)} angles = {evals} pose evaluations, "
          f"{os.cpu_count()} cores")
    for refine in (False, True):
        dt = median(lambda: deflect.atlas(robot, positions, t[:3, 2], WRENCH, angles=angles,
                                          seeds=Q0, refine=refine), 5)
        print(f"  local, every core, refine={refine!s:<5}: {dt:7.3f} s  {evals / dt:10.0f} evaluations/s")
    if args.dask:
        import distributed

        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as c, \
                distributed.Client(c) as client:
            for chunk in (16, 64, 256):
                dt = median(lambda: deflect.atlas(robot, positions, t[:3, 2], WRENCH, angles=angles,
                                                  seeds=Q0, executor=client, chunk_size=chunk), 3)
                print(f"  Dask LocalCluster 2 workers, chunk {chunk:>3}: {dt:7.3f} s  "
                      f"{evals / dt:10.0f} evaluations/s")
    # Single-threaded breakdown (below the threading thresholds: one task, 1000 rows).
    one = positions[:1]
    sweep = median(lambda: deflect.atlas(robot, one, t[:3, 2], WRENCH, angles=angles, seeds=Q0,
                                         refine=False), 21) / len(angles)
    r = deflect.posture_sweep(robot, one[0], t[:3, 2], WRENCH, angles=angles, seeds=Q0, refine=False)
    qs = r["q"][r["reachable"]][:1000]
    defl = median(lambda: robot.deflection_batch(qs, WRENCH), 21) / len(qs)
    comp = median(lambda: robot.compliance_batch(qs), 21) / len(qs)
    print("per evaluation, one thread:")
    print(f"  sweep (IK + deflection + measure) {sweep * 1e6:7.3f} us")
    print(f"  exact deflection                   {defl * 1e6:7.3f} us")
    print(f"  IK (by difference)                 {(sweep - defl) * 1e6:7.3f} us")
    print(f"  compliance (once per task, at the best angle) {comp * 1e6:7.3f} us")


if __name__ == "__main__":
    main()
