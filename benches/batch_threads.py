"""When a batch of the Python bindings goes on several threads, measured.

Every `*_batch` goes through one runner (crates/py/src/batch.rs): it splits the rows over the
cores once rows x the row's cost reaches 1 ms (PARALLEL_MIN_NS), with the row costs of
`batch::row_cost`. This script measures, on the installed wheel, the single-threaded cost of a
row of each kind (batches well below the threshold), and the wall time per row around and
above the threshold, so that the threshold and the row costs can be checked on any machine:

    .venv/bin/python benches/batch_threads.py

The thread overhead is the extra time of a batch just above the threshold against its rows'
single-threaded cost divided by the threads used.
"""

import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import deflect  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
KR300 = (
    os.path.join(ROOT, "robots/kr300/kr300_r2500.urdf"),
    os.path.join(ROOT, "robots/kr300/kr300_r2500_stiffness.toml"),
)
MAP = os.path.join(ROOT, "data/paksoy2025_compliance_oc.csv")
PARALLEL_MIN_NS = 1.0e6


def best_of(f, repeats=7):
    """The fastest of `repeats` runs [s]: the least disturbed by the rest of the machine."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def sweep(name, row_cost_ns, run, make):
    threshold = int(PARALLEL_MIN_NS / row_cost_ns)
    small = max(threshold // 8, 16)
    single = best_of(lambda: run(make(small))) / small * 1e9
    print(f"{name}: threshold {threshold} rows ({row_cost_ns:.0f} ns assumed per row)")
    print(f"  single-threaded, {small} rows: {single:8.1f} ns/row")
    threads = min(os.cpu_count() or 1, 8)
    for factor in (0.5, 0.99, 1.01, 2.0, 8.0):
        n = max(int(threshold * factor), 2)
        t = best_of(lambda: run(make(n)))
        on = n * row_cost_ns >= PARALLEL_MIN_NS
        ideal = n * single * 1e-9 / (threads if on else 1)
        extra = (t - ideal) * 1e6
        print(
            f"  {n:7d} rows ({'threads' if on else 'one    '}): {t / n * 1e9:8.1f} ns/row, "
            f"{t * 1e3:7.3f} ms, overhead vs ideal {extra:7.1f} us"
        )


def main():
    robot = deflect.SerialRobot.from_urdf(*KR300, tip_link="tcp")
    q0 = np.array([0.0, -0.9, 1.4, 0.0, 1.0708, 0.0])
    w = np.array([-386.1, 386.1, 0.0, 0.0, 0.0, 0.0])
    rng = np.random.default_rng(1)

    def poses(n):
        return q0 + 0.05 * rng.standard_normal((n, 6))

    sweep("SerialRobot.deflection_batch", 500.0, lambda q: robot.deflection_batch(q, w), poses)
    sweep("SerialRobot.forward_batch", 500.0, robot.forward_batch, poses)
    cmap = deflect.ComplianceMap.from_csv(MAP)
    force = np.array([0.0, -245.0])

    def points(n):
        lo, hi = np.array([0.18, -0.07]), np.array([0.26, 0.07])
        return lo + (hi - lo) * rng.random((n, 2))

    sweep("ComplianceMap.displacement_batch", 50.0, lambda p: cmap.displacement_batch(p, force), points)

    # Arguments that are not C-contiguous (a broadcast row, a strided view) are read block by
    # block (batch::BLOCK_ROWS rows at a time), never copied whole: same time per row.
    n = 1_000_000
    p = points(n)
    f = np.tile(force, (n, 1))
    strided = np.empty((n, 4))
    strided[:, ::2] = p
    print(f"ComplianceMap.displacement_batch, {n} rows, by layout of P and F:")
    for name, pp, ff in [
        ("C-contiguous      ", p, f),
        ("P strided         ", strided[:, ::2], f),
        ("P broadcast row   ", np.broadcast_to(p[0], (n, 2)), f),
        ("F broadcast row   ", p, force),
    ]:
        t = best_of(lambda: cmap.displacement_batch(pp, ff))
        print(f"  {name}: {t / n * 1e9:6.1f} ns/row")


if __name__ == "__main__":
    main()
