"""numpy's `out=` habit: results written into the caller's array, which is returned; the
array must be float64, C-contiguous, writeable and of the result's exact shape."""

import numpy as np
import pytest

import deflect
from conftest import KR300_POSE, REPO

RNG = np.random.default_rng(11)
W = np.array([-386.1, 386.1, 120.0, 3.0, -2.0, 1.0])


def _map():
    return deflect.ComplianceMap.from_csv(REPO / "data/paksoy2025_compliance_oc.csv")


def cases(kr300):
    q = KR300_POSE
    Q = KR300_POSE + RNG.uniform(-0.2, 0.2, (7, 6))
    Wb = RNG.uniform(-300.0, 300.0, (7, 6))
    m = _map()
    g = deflect.GridMap.from_map(m)
    P = np.column_stack([RNG.uniform(0.18, 0.26, 9), RNG.uniform(-0.07, 0.07, 9)])
    F = RNG.uniform(-200.0, 200.0, (9, 2))
    return [
        ("forward", lambda **k: kr300.forward(q, **k), (4, 4)),
        ("deflection", lambda **k: kr300.deflection(q, W, **k), (6,)),
        ("linear_deflection", lambda **k: kr300.linear_deflection(q, W, **k), (6,)),
        ("compliance", lambda **k: kr300.compliance(q, **k), (6, 6)),
        ("forward_batch", lambda **k: kr300.forward_batch(Q, **k), (7, 4, 4)),
        ("deflection_batch", lambda **k: kr300.deflection_batch(Q, Wb, **k), (7, 6)),
        ("compliance_batch", lambda **k: kr300.compliance_batch(Q, **k), (7, 6, 6)),
        ("map displacement", lambda **k: m.displacement(P[0], F[0], **k), (2,)),
        ("map displacement_batch", lambda **k: m.displacement_batch(P, F, **k), (9, 2)),
        ("grid displacement", lambda **k: g.displacement(P[0], F[0], **k), (2,)),
        ("grid displacement_batch", lambda **k: g.displacement_batch(P, F, **k), (9, 2)),
    ]


def test_out_receives_the_result_and_is_returned(kr300):
    for name, call, shape in cases(kr300):
        want = call()
        assert want.shape == shape, name
        out = np.full(shape, np.nan)
        got = call(out=out)
        assert got is out, name
        np.testing.assert_array_equal(out, want, err_msg=name)


def test_out_is_refused_unless_it_fits(kr300):
    for name, call, shape in cases(kr300):
        wrong_shape = np.empty((*shape[:-1], shape[-1] + 1))
        strided = np.empty((*shape[:-1], 2 * shape[-1]))[..., ::2]
        readonly = np.empty(shape)
        readonly.flags.writeable = False
        for bad, what in [
            (np.empty(shape, dtype=np.float32), "got dtype float32"),
            (wrong_shape, "got ("),
            (strided, "non-contiguous"),
            (readonly, "not writeable"),
            ([0.0] * shape[0], "got a list"),
        ]:
            with pytest.raises(deflect.InputError, match="out") as e:
                call(out=bad)
            assert what in str(e.value), (name, str(e.value))


def test_out_may_not_alias_an_input_of_the_same_call(kr300):
    Q = KR300_POSE + RNG.uniform(-0.2, 0.2, (5, 6))
    W6 = np.tile(W, (5, 1))
    before = W6.copy()
    with pytest.raises(deflect.InputError, match="out.*already borrowed"):
        kr300.deflection_batch(Q, W6, out=W6)
    np.testing.assert_array_equal(W6, before)
