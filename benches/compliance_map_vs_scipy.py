"""Times deflect.ComplianceMap.displacement_batch against scipy's RegularGridInterpolator.

Same 1e5 queries (positions inside the OC grid of Paksoy et al. 2025, forces -250..250 N)
for both. The scipy pipeline interpolates the 8 coefficient fields (4 slopes + 4 offsets of
Eq. 10) with one linear RegularGridInterpolator call and combines them with the forces
(Eq. 9); deflect does the same inside one Rust call. Best of `REPEATS` runs each.

    .venv/bin/python benches/compliance_map_vs_scipy.py
"""

import pathlib
import time

import numpy as np
from scipy.interpolate import RegularGridInterpolator

import deflect

ROOT = pathlib.Path(__file__).resolve().parents[1]
N = 100_000
REPEATS = 20


def best(fn):
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main():
    m = deflect.ComplianceMap.from_csv(ROOT / "data" / "paksoy2025_compliance_oc.csv")
    rng = np.random.default_rng(0)
    P = np.column_stack([rng.uniform(m.x[0], m.x[-1], N), rng.uniform(m.y[0], m.y[-1], N)])
    F = rng.uniform(-250.0, 250.0, (N, 2))

    nx, ny = len(m.x), len(m.y)
    fields = np.concatenate([m.slopes.reshape(nx, ny, 4), m.offsets.reshape(nx, ny, 4)], axis=2)
    rgi = RegularGridInterpolator((m.x, m.y), fields, method="linear")

    def scipy_run():
        c = rgi(P)
        S = c[:, :4].reshape(N, 2, 2)
        O = c[:, 4:].reshape(N, 2, 2)
        return np.einsum("ndf,nf->nd", S, F) + O.sum(axis=2)

    t_deflect, d = best(lambda: m.displacement_batch(P, F))
    t_bicubic, _ = best(lambda: m.displacement_batch(P, F, interpolation="bicubic"))
    t_scipy, s = best(scipy_run)
    err = np.abs(d - s).max()
    print(f"queries: {N}")
    print(f"deflect bilinear batch: {t_deflect * 1e3:8.3f} ms  ({t_deflect / N * 1e9:6.1f} ns/query)")
    print(f"deflect bicubic batch:  {t_bicubic * 1e3:8.3f} ms  ({t_bicubic / N * 1e9:6.1f} ns/query)")
    print(f"scipy RGI linear:       {t_scipy * 1e3:8.3f} ms  ({t_scipy / N * 1e9:6.1f} ns/query)")
    print(f"ratio scipy / deflect (bilinear): {t_scipy / t_deflect:.1f}x (target >= 20x)")
    print(f"max |deflect - scipy| = {err:.3e} m")
    assert err < 1e-12


if __name__ == "__main__":
    main()
