"""Benchmark: four-bar force kernel (issue 26) against the kinematics kernel it follows.

10^6 crank positions.  Issue 26's target: the force analysis costs no more than 2x the
kinematics kernel per position.  Both are timed in this one process, interleaved, medians
(fresh output arrays for both; the force kernel reads the kinematics' states).  A plain
numpy version of the same closed form is timed too, as a reference.  Run:

    .venv/bin/python bench/bench_fourbar_forces.py [--n 1000000] [--repeat 9]
"""
from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from driver.fourbar import _kernel as fourbar_kernel

LINK = (0.30, 0.10, 0.35, 0.25, 20.0, 3.0)
PROPS = np.array([0.5, 1.2, 0.9, 4e-4, 1.2e-2, 4.7e-3, 0.05, 0.175, 0.125, 0.1, 0.2, -0.3, 9.81, 5.0, 10.0, -20.0,
                  0.175, 0.05])


def numpy_forces(out: np.ndarray, p, q, r, s, w, al, pr) -> np.ndarray:
    """Benchmark baseline only (not used by the tool): the kernel's closed form in plain numpy."""
    xa, ya, xb, yb, w2, w3, a2, a3 = (out[:, j] for j in range(3, 11))
    m1, m2, m3, i1, i2, i3 = pr[:6]
    k = pr[6:9, None] * np.stack([np.cos(pr[9:12]), np.sin(pr[9:12])], axis=1)
    c1, s1 = xa / q, ya / q
    e2x, e2y, e3x, e3y = (xb - xa) / r, (yb - ya) / r, (xb - p) / s, yb / s
    g1x, g1y = k[0, 0] * c1 - k[0, 1] * s1, k[0, 0] * s1 + k[0, 1] * c1
    g2x, g2y = k[1, 0] * e2x - k[1, 1] * e2y, k[1, 0] * e2y + k[1, 1] * e2x
    g3x, g3y = k[2, 0] * e3x - k[2, 1] * e3y, k[2, 0] * e3y + k[2, 1] * e3x
    g = pr[12]
    r1x, r1y = m1 * (-al * g1y - w * w * g1x), m1 * (al * g1x - w * w * g1y + g)
    r2x = m2 * (-al * ya - w * w * xa - a2 * g2y - w2 * w2 * g2x)
    r2y = m2 * (al * xa - w * w * ya + a2 * g2x - w2 * w2 * g2y + g)
    r3x, r3y = m3 * (-a3 * g3y - w3 * w3 * g3x), m3 * (a3 * g3x - w3 * w3 * g3y + g)
    h1 = i1 * al + g1x * r1y - g1y * r1x
    h2 = i2 * a2 + g2x * r2y - g2y * r2x
    h3 = i3 * a3 + g3x * r3y - g3y * r3x
    u, v = pr[16], pr[17]
    rhox, rhoy = u * e2x - v * e2y, u * e2y + v * e2x
    mm3 = h3 - pr[13]
    mm2 = rhox * pr[15] - rhoy * pr[14] - h2
    bx, by, cx, cy = xb - p, yb, xb - xa, yb - ya
    det = bx * cy - by * cx
    fbx, fby = (mm3 * cx - bx * mm2) / det, (cy * mm3 - by * mm2) / det
    fo4x, fo4y = r3x - fbx, r3y - fby
    fax, fay = r2x + fbx - pr[14], r2y + fby - pr[15]
    t = h1 + xa * fay - ya * fax
    fo2x, fo2y = r1x + fax, r1y + fay
    return np.column_stack([t, fo2x, fo2y, fax, fay, fbx, fby, fo4x, fo4y, -(fo2x + fo4x), -(fo2y + fo4y),
                            -p * fo4y - t])


def interleaved(fns: list, repeat: int) -> list[float]:
    """Median wall time [s] of each function, the calls interleaved (same load for all)."""
    for f in fns:
        f()
    times: list[list[float]] = [[] for _ in fns]
    for _ in range(repeat):
        for i, f in enumerate(fns):
            t0 = time.perf_counter()
            f()
            times[i].append(time.perf_counter() - t0)
    return [statistics.median(t) for t in times]


def main(argv: list[str] | None = None) -> dict[str, float]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=9)
    args = ap.parse_args(argv)
    theta = np.linspace(0.0, 2 * np.pi, args.n)
    p, q, r, s, w, al = LINK
    out, st = fourbar_kernel.fourbar_exact(theta, *LINK, 1)
    f = fourbar_kernel.fourbar_joint_forces(out, st, *LINK, PROPS)
    ok = st == 0
    ref = numpy_forces(out, *LINK, PROPS)
    assert np.allclose(f[ok], ref[ok], rtol=1e-12, atol=1e-9)
    t_kin, t_force, t_np = interleaved([lambda: fourbar_kernel.fourbar_exact(theta, *LINK, 1),
                                        lambda: fourbar_kernel.fourbar_joint_forces(out, st, *LINK, PROPS),
                                        lambda: numpy_forces(out, *LINK, PROPS)], args.repeat)
    ns = {k: 1e9 * t / args.n for k, t in (("kinematics", t_kin), ("forces", t_force), ("numpy", t_np))}
    ratio = t_force / t_kin
    print(f"four-bar force kernel, {args.n} positions, median of {args.repeat} interleaved "
          f"(cpu count {os.cpu_count()}, one thread, load {os.getloadavg()[0]:.2f})")
    print(f"  kinematics kernel (exact_states)  : {ns['kinematics']:8.1f} ns/position")
    print(f"  force kernel (joint_forces)       : {ns['forces']:8.1f} ns/position   "
          f"({ratio:.2f} x kinematics; target <= 2: {'met' if ratio <= 2 else 'NOT met'})")
    print(f"  numpy, same closed form (reference): {ns['numpy']:8.1f} ns/position   "
          f"({t_np / t_force:.1f} x the force kernel)")
    print("  limits: the force kernel reads 8 state columns and writes 12 (160 bytes per position); "
          "no transcendental function per position, 8 divisions")
    return ns | {"ratio": ratio}


if __name__ == "__main__":
    main()
