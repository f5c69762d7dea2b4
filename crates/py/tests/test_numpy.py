"""numpy habits: array-likes of any real dtype convert once, float64 C-contiguous input is read
in place (no copy), batch arguments broadcast a single row as numpy does, and wrong shapes name
the argument, the expected and the received shape.

Copies are counted with tracemalloc, which sees every allocation numpy makes (deflect's own
outputs are Rust buffers handed to numpy, not traced): an input that is converted shows up as
a peak of its float64 size, one read in place as (almost) nothing. tracemalloc cannot see a
copy made in Rust; the proof that there is none is a child process whose address space is
capped below the size of one copy (test_no_copy_is_proven_under_an_address_space_limit)."""

import json
import os
import subprocess
import sys
import tracemalloc

import numpy as np
import pytest

import deflect
from conftest import KR300_TOML, KR300_URDF, REPO

N = 100_000
RNG = np.random.default_rng(11)


@pytest.fixture(scope="module")
def cmap():
    return deflect.ComplianceMap.from_csv(REPO / "data/paksoy2025_compliance_oc.csv")


@pytest.fixture(scope="module")
def kr300():
    return deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp")


def points(n=N):
    return np.c_[RNG.uniform(0.18, 0.26, n), RNG.uniform(-0.07, 0.07, n)]


def traced_peak(f, *args):
    """Peak bytes traced while `f` runs, less its result's own (numpy's allocations are
    traced, and a large result is made by numpy), and the result."""
    tracemalloc.start()
    try:
        out = f(*args)
        return tracemalloc.get_traced_memory()[1] - out.nbytes, out
    finally:
        tracemalloc.stop()


def test_float64_c_contiguous_batches_are_read_without_a_copy(cmap, kr300):
    p, f = points(), RNG.uniform(-200.0, 200.0, (N, 2))
    peak, out = traced_peak(cmap.displacement_batch, p, f)
    assert out.shape == (N, 2)
    assert peak < 0.01 * (p.nbytes + f.nbytes), peak
    # The same data as float32 is converted, once: one float64 copy of each argument.
    p32, f32 = p.astype(np.float32), f.astype(np.float32)
    peak32, out32 = traced_peak(cmap.displacement_batch, p32, f32)
    assert p.nbytes + f.nbytes <= peak32 < 1.1 * (p.nbytes + f.nbytes), peak32
    np.testing.assert_array_equal(out32, cmap.displacement_batch(p32.astype(float), f32.astype(float)))

    q = RNG.uniform(-1.0, 1.0, (20_000, 6))
    w = RNG.uniform(-300.0, 300.0, (20_000, 6))
    peak, d = traced_peak(kr300.deflection_batch, q, w)
    assert d.shape == (20_000, 6)
    assert peak < 0.01 * (q.nbytes + w.nbytes), peak


def test_batches_broadcast_a_single_row(cmap, kr300):
    p, f = points(1000), RNG.uniform(-200.0, 200.0, (1000, 2))
    one_force = f[0]
    expected = cmap.displacement_batch(p, np.tile(one_force, (1000, 1)))
    np.testing.assert_array_equal(cmap.displacement_batch(p, one_force), expected)
    np.testing.assert_array_equal(cmap.displacement_batch(p, [one_force]), expected)
    np.testing.assert_array_equal(cmap.displacement_batch(p, tuple(one_force)), expected)
    one_point = p[3]
    np.testing.assert_array_equal(
        cmap.displacement_batch(one_point, f), cmap.displacement_batch(np.tile(one_point, (1000, 1)), f)
    )
    for i in [0, 500, 999]:
        np.testing.assert_array_equal(expected[i], cmap.displacement(p[i], one_force))

    q = RNG.uniform(-1.0, 1.0, (50, 6))
    w = RNG.uniform(-300.0, 300.0, 6)
    np.testing.assert_array_equal(kr300.deflection_batch(q, w), kr300.deflection_batch(q, np.tile(w, (50, 1))))
    np.testing.assert_array_equal(kr300.deflection_batch(q[0], [w, 2 * w])[1], kr300.deflection(q[0], 2 * w))


def test_non_contiguous_and_integer_inputs_give_the_same_numbers(cmap, kr300):
    p = points(2000)
    f = np.round(RNG.uniform(-200.0, 200.0, (2000, 2)))
    ref = cmap.displacement_batch(p, f)
    np.testing.assert_array_equal(cmap.displacement_batch(np.asfortranarray(p), f), ref)
    np.testing.assert_array_equal(cmap.displacement_batch(p, f.astype(np.int32)), ref)
    wide = np.zeros((2000, 4))
    wide[:, ::2] = p
    np.testing.assert_array_equal(cmap.displacement_batch(wide[:, ::2], f), ref)
    np.testing.assert_array_equal(cmap.displacement_batch(p.tolist(), f.tolist()), ref)
    q = np.zeros((4, 6))
    np.testing.assert_array_equal(
        kr300.deflection_batch(q, np.ones((4, 6), dtype=np.int64) * 100),
        kr300.deflection_batch(q, np.full((4, 6), 100.0)),
    )


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda m, r: m.displacement_batch(np.zeros((5, 2)), np.zeros((3, 2))), "P has 5 rows and F has 3"),
        (lambda m, r: m.displacement_batch(np.zeros((5, 4)), np.zeros((5, 2))), r"P: expected .*\(N, 2 or 3\).*got \(5, 4\)"),
        (lambda m, r: m.displacement_batch(np.zeros((5, 2)), np.zeros((5, 2, 1))), r"F: expected .*got \(5, 2, 1\)"),
        (lambda m, r: m.displacement_batch(np.zeros((5, 2), complex), np.zeros((5, 2))), "P: .*complex"),
        (lambda m, r: m.displacement_batch(np.zeros((5, 2), object), np.zeros((5, 2))), "P: .*object"),
        (lambda m, r: r.deflection_batch(np.zeros((4, 6)), np.zeros((3, 6))), "Q has 4 rows and W has 3"),
        (lambda m, r: r.deflection_batch(np.zeros((4, 5)), np.zeros((4, 6))), r"Q: expected .*\(N, 6\).*got \(4, 5\)"),
    ],
)
def test_wrong_batches_name_the_argument_and_both_shapes(cmap, kr300, call, match):
    with pytest.raises(deflect.InputError, match=match):
        call(cmap, kr300)


def test_batches_on_every_core_match_the_single_calls(kr300):
    n = 5000  # above the threading threshold (2048 rows)
    q = RNG.uniform(-1.0, 1.0, (n, 6))
    w = RNG.uniform(-300.0, 300.0, (n, 6))
    d = kr300.deflection_batch(q, w)
    f = kr300.forward_batch(q)
    c = kr300.compliance_batch(q)
    assert d.shape == (n, 6) and f.shape == (n, 4, 4) and c.shape == (n, 6, 6)
    for i in [0, 1, 2499, 2500, 4999]:
        np.testing.assert_array_equal(d[i], kr300.deflection(q[i], w[i]))
        np.testing.assert_array_equal(f[i], kr300.forward(q[i]))
        np.testing.assert_array_equal(c[i], kr300.compliance(q[i]))
    # The first failing row is named, whichever thread met it.
    q[4000, 2] = np.nan
    q[3000, 1] = np.inf
    for call in [lambda: kr300.deflection_batch(q, w), lambda: kr300.forward_batch(q),
                 lambda: kr300.compliance_batch(q)]:
        with pytest.raises(deflect.InputError, match="row 3000"):
            call()
    # The threads take pieces of the rows in order: a failure in the first piece wins over
    # later ones, and a batch without failures still fills every row.
    q[10, 0] = np.nan
    for call in [lambda: kr300.deflection_batch(q, w), lambda: kr300.forward_batch(q),
                 lambda: kr300.compliance_batch(q)]:
        with pytest.raises(deflect.InputError, match="row 10[^0-9]"):
            call()


def test_displacement_field_is_the_map_at_a_fixed_load(cmap):
    """ComplianceMap.field(force): position-only queries equal to the map under that load,
    single and batched, pickled exactly; bad loads raise InputError naming the force."""
    import copy
    import pickle

    force = np.array([-120.0, 245.25])
    field = cmap.field(force)
    assert isinstance(field, deflect.DisplacementField)
    np.testing.assert_array_equal(field.force, force)
    P = points(5000)
    np.testing.assert_array_equal(field.displacement_batch(P), cmap.displacement_batch(P, force))
    for p in P[:50]:
        np.testing.assert_array_equal(field.displacement(p), cmap.displacement(p, force))
    # Node values are Eq. 9-10 at the nodes.
    s, o = cmap.slopes, cmap.offsets
    np.testing.assert_allclose(field.node_values, s @ force + o.sum(axis=3), rtol=1e-14, atol=1e-18)
    for back in (pickle.loads(pickle.dumps(field)), copy.deepcopy(field)):
        np.testing.assert_array_equal(back.displacement_batch(P), field.displacement_batch(P))
    with pytest.raises(deflect.InputError, match="force"):
        cmap.field([1.0])
    with pytest.raises(deflect.InputError, match="force"):
        cmap.field([1.0, np.nan])
    with pytest.raises(deflect.InputError, match="x"):
        field.displacement([0.5, 0.0])


def test_linear_deflection_is_compliance_times_wrench(kr300):
    q = np.array([0.1, -0.9, 1.4, 0.2, 1.07, -0.3])
    w = np.array([-386.1, 386.1, 20.0, 1.0, -2.0, 0.5])
    # C @ w to rounding: the deflection pass sums each spring's first-order turn (the same
    # sum as C, in another order), so components that cancel differ by ulps of the largest.
    cw = kr300.compliance(q) @ w
    np.testing.assert_allclose(kr300.linear_deflection(q, w), cw, rtol=1e-13, atol=1e-15 * np.abs(cw).max())
    # Lists of numpy scalars (float subclasses) read like floats.
    np.testing.assert_array_equal(kr300.linear_deflection(list(q), list(w)), kr300.linear_deflection(q, w))
    with pytest.raises(deflect.InputError, match="wrench"):
        kr300.linear_deflection(q, [0.0, 0.0, np.inf, 0.0, 0.0, 0.0])


_NO_COPY_CHILD = r"""
import json, os, resource, sys
import numpy as np
import deflect

repo = sys.argv[1]
m = deflect.ComplianceMap.from_csv(os.path.join(repo, "data/paksoy2025_compliance_oc.csv"))
robot = deflect.SerialRobot.from_urdf(
    os.path.join(repo, "robots/kr300/kr300_r2500.urdf"),
    os.path.join(repo, "robots/kr300/kr300_r2500_stiffness.toml"),
    "tcp",
)
rng = np.random.default_rng(3)
# Built in place, without temporaries: nothing freed is left for a copy to reuse.
n = 4_000_000  # (n, 2) float64: 64 MB, one copy of P
p = rng.random((n, 2))
p *= [0.08, 0.14]
p += [0.18, -0.07]
f = np.array([150.0, -80.0])
out = np.zeros((n, 2))
k = 1_000_000  # (k, 6) float64: 48 MB, one copy of Q
q = rng.random((k, 6))
q *= 0.2
q += [-0.1, -1.0, 1.3, -0.1, 0.9708, -0.1]
w = np.array([-386.1, 386.1, 120.0, 0.0, 0.0, 0.0])
dout = np.zeros((k, 6))
p32, q32 = p.astype(np.float32), q.astype(np.float32)
# Every code path once, threads and their allocator arenas included, before the cap.
m.displacement_batch(p[:50_000], f, out=out[:50_000])
robot.deflection_batch(q[:5_000], w, out=dout[:5_000])
size = os.sysconf("SC_PAGE_SIZE") * int(open("/proc/self/statm").read().split()[0])
headroom = 24 << 20  # below one copy of either input
resource.setrlimit(resource.RLIMIT_AS, (size + headroom, resource.RLIM_INFINITY))
res = {}
for name, call in [
    ("map_in_place", lambda: m.displacement_batch(p, f, out=out)),
    ("vjm_in_place", lambda: robot.deflection_batch(q, w, out=dout)),
    ("map_float32", lambda: m.displacement_batch(p32, f, out=out)),
    ("vjm_float32", lambda: robot.deflection_batch(q32, w, out=dout)),
]:
    try:
        call()
        res[name] = "ok"
    except MemoryError:
        res[name] = "MemoryError"
print(json.dumps(res))
"""


def _mapping_env(threshold):
    """A child's environment where every allocation of `threshold` bytes or more is its own
    mmap (glibc's threshold fixed) in one malloc arena, BLAS on one thread."""
    return dict(
        os.environ,
        OPENBLAS_NUM_THREADS="1",
        OMP_NUM_THREADS="1",
        MALLOC_MMAP_THRESHOLD_=str(threshold),
        MALLOC_ARENA_MAX="1",
    )


def test_no_copy_is_proven_under_an_address_space_limit():
    """float64 C-contiguous batch input is read in place: with the process's address space
    capped at its size plus 24 MB, a batch over a 64 MB (48 MB) input still runs, while the
    same data as float32, which must be converted into a float64 copy, raises MemoryError.
    A copy made anywhere (numpy or Rust) counts against the cap."""
    # A fixed mmap threshold (every large block mapped on allocation, unmapped on free) and
    # one malloc arena (worker threads otherwise reserve 64 MB arenas, where a refused
    # mapping is retried): no memory already counted by the cap is left for a copy to reuse.
    # A copy in Rust would abort the child (infallible allocation), one in numpy raise.
    env = _mapping_env(131072)
    repo = str(REPO)
    proc = subprocess.run(
        [sys.executable, "-c", _NO_COPY_CHILD, repo], capture_output=True, text=True, timeout=120, env=env
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    res = json.loads(proc.stdout.strip().splitlines()[-1])
    assert res == {
        "map_in_place": "ok",
        "vjm_in_place": "ok",
        "map_float32": "MemoryError",
        "vjm_float32": "MemoryError",
    }, res


_MMAP_CHILD = r"""
import os, sys
import numpy as np
import deflect

repo = sys.argv[1]
robot = deflect.SerialRobot.from_urdf(
    os.path.join(repo, "robots/kr300/kr300_r2500.urdf"),
    os.path.join(repo, "robots/kr300/kr300_r2500_stiffness.toml"),
    "tcp",
)
m = deflect.ComplianceMap.from_csv(os.path.join(repo, "data/paksoy2025_compliance_oc.csv"))
rng = np.random.default_rng(5)
k = 400_000  # (k, 6) float64: 19 MB of joints, 98 blocks of 4,096 rows
q = rng.random((k, 6)) * 0.2 + [-0.1, -1.0, 1.3, -0.1, 0.9708, -0.1]
w = np.array([-386.1, 386.1, 120.0, 0.0, 0.0, 0.0])
dout = np.zeros((k, 6))
n = 1_600_000  # (n, 2) float64: 26 MB of points
p = rng.random((n, 2)) * [0.08, 0.14] + [0.18, -0.07]
f = np.array([150.0, -80.0])
out = np.zeros((n, 2))
# Every code path once (threads, arenas) before the marked calls.
robot.deflection_batch(q[:20_000], w, out=dout[:20_000])
robot.deflection_batch(q[:20_000], w)
m.displacement_batch(p[:50_000], f, out=out[:50_000])
for name, call in [
    ("vjm_out", lambda: robot.deflection_batch(q, w, out=dout)),
    ("vjm_new", lambda: robot.deflection_batch(q, w)),
    ("map_out", lambda: m.displacement_batch(p, f, out=out)),
]:
    os.write(2, f"BEGIN {name}\n".encode())
    call()
    os.write(2, f"END {name}\n".encode())
"""


def test_no_copy_block_by_block_either():
    """The address-space proof above does not see a copy made a few thousand rows at a time
    (a block is far below its headroom). Here every allocation of 64 KiB or more is its own
    mmap (glibc's threshold fixed, one arena) and strace lists them: a batch over 98 blocks of
    4,096 rows maps no more than its result and its threads' stacks, whatever its size."""
    import re
    import shutil

    if shutil.which("strace") is None:
        pytest.skip("strace is not installed (scripts/test-all.sh installs it as root)")
    env = _mapping_env(65536)
    trace = REPO / "target" / "strace-batch.txt"
    trace.parent.mkdir(exist_ok=True)
    proc = subprocess.run(
        ["strace", "-f", "-e", "trace=mmap,write", "-o", str(trace), sys.executable, "-c", _MMAP_CHILD, str(REPO)],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    maps, current = {}, None
    for line in trace.read_text().splitlines():
        marker = re.search(r'write\(2, "(BEGIN|END) (\w+)', line)
        if marker:
            current = marker.group(2) if marker.group(1) == "BEGIN" else None
            maps.setdefault(marker.group(2), [])
            continue
        size = re.search(r"mmap\(NULL, (\d+),", line)
        if current and size and int(size.group(1)) >= 65536:
            maps[current].append(int(size.group(1)))
    assert set(maps) == {"vjm_out", "vjm_new", "map_out"}, maps
    # In place: the worker threads' stacks only (a few), never one per block (98 or 390).
    assert len(maps["vjm_out"]) <= 8 and len(maps["map_out"]) <= 8, maps
    # A new result: one mapping of its 19 MB besides.
    assert len(maps["vjm_new"]) <= 9 and max(maps["vjm_new"]) >= 400_000 * 6 * 8, maps
