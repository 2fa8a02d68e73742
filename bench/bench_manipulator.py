"""Benchmark of the 2R manipulator kernels (issue 5): not a test.

1. Jacobian + manipulability + condition number + Craig torques on 10^5 configurations:
   Fortran kernel (driver.manipulator_kernel.manipulator_arm_states) vs a plain numpy baseline, same run.
   Target: at most 0.04 us per configuration (issue 12; was 0.05).
2. Monte Carlo tolerance check with 10^6 samples (sampling + positioning errors at the 4
   workspace points + max and 99th percentile): kernel vs numpy.  Target: under 1 s.
3. Design summaries (issue 13): manipulator.summarise_batch over 10^4 designs of the
   least-torque deck (inputs/optimize_manipulator_torque.dat, 1000 Monte Carlo samples) in one
   kernel call vs the per-case loop a sweep or an optimiser ran before (one run() per design
   deck, its summary), both in this process: designs/s and the ratio (CPU time, medians).

Run: .venv/bin/python bench/bench_manipulator.py [--repeat N]
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from driver.manipulator import _kernel as manipulator_kernel
from timing import median_time as timeit

DECK = Path(__file__).resolve().parents[1] / "inputs" / "optimize_manipulator_torque.dat"


def numpy_arm_states(l1, l2, th1, th2, qd, qdd, m1, m2, g):
    """Baseline only (plain numpy): the same quantities as the Fortran arm_states kernel."""
    s1, c1, s2, c2 = np.sin(th1), np.cos(th1), np.sin(th2), np.cos(th2)
    s12, c12 = s1 * c2 + c1 * s2, c1 * c2 - s1 * s2
    a, b = -l1 * s1 - l2 * s12, -l2 * s12
    c, d = l1 * c1 + l2 * c12, l2 * c12
    jac = np.stack([a, b, c, d], 1)
    det = np.abs(a * d - b * c)
    t = a * a + b * b + c * c + d * d
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = np.where(det > 0, (t + np.sqrt(np.maximum(t * t - 4 * det * det, 0))) / (2 * det), 0.0)
    m2l = m2 * l1 * l2
    w1, w2, a1, a2 = qd[:, 0], qd[:, 1], qdd[:, 0], qdd[:, 1]
    tau1 = (m2 * l2 * l2 * (a1 + a2) + m2l * c2 * (2 * a1 + a2) + (m1 + m2) * l1 * l1 * a1
            - m2l * s2 * w2 * w2 - 2 * m2l * s2 * w1 * w2 + m2 * l2 * g * c12 + (m1 + m2) * l1 * g * c1)
    tau2 = m2l * c2 * a1 + m2l * s2 * w1 * w1 + m2 * l2 * g * c12 + m2 * l2 * l2 * (a1 + a2)
    return jac, det, kappa, np.stack([tau1, tau2], 1)


def numpy_position_errors(th1, th2, dl):
    """Baseline only (plain numpy): global and per-point positioning errors."""
    u1 = np.stack([np.cos(th1), np.sin(th1)], 1)             # (k, 2)
    u2 = np.stack([np.cos(th1 + th2), np.sin(th1 + th2)], 1)
    e = dl[:, 0, None, None] * u1[None] + dl[:, 1, None, None] * u2[None]   # (ns, k, 2)
    e2 = (e * e).sum(2)
    return np.stack([np.sqrt(e2.sum(1)), np.sqrt(e2.max(1))], 1)


def design_batch(n: int, n_case: int, repeat: int) -> tuple[float, float]:
    """CPU seconds per design: (batch summaries of n designs in one call, one run() per design
    deck for n_case of them), medians of ``repeat`` interleaved rounds; the batch rows are
    checked against the runs first."""
    from driver import manipulator
    from driver._deck import Params, read_deck, validate
    d = read_deck(DECK)
    base = validate(d.groups["manipulator"], manipulator.SPEC, d.path)
    rng = np.random.default_rng(3)
    l1, l2 = rng.uniform(4.5, 6.5, n), rng.uniform(3.8, 5.0, n)    # designs that reach the workspace
    cols = {"designs_l1": l1, "designs_l2": l2}
    def deck(i: int):
        return Params(base.group, base.path, {**base, "designs_l1": [float(l1[i])], "designs_l2": [float(l2[i])]},
                      {}, base.line)

    frame = manipulator.summarise_batch(base, cols)
    for i in range(min(n_case, 5)):
        s = manipulator.run(deck(i)).summary
        assert s["design_tau_sum_signed_Nm"] == frame["design_tau_sum_signed_Nm"].iloc[i]

    def per_case():
        for i in range(n_case):
            manipulator.run(deck(i))

    tb, tc = [], []
    for _ in range(repeat):
        t0 = time.process_time()
        manipulator.summarise_batch(base, cols)
        tb.append((time.process_time() - t0) / n)
        t0 = time.process_time()
        per_case()
        tc.append((time.process_time() - t0) / n_case)
    return statistics.median(tb), statistics.median(tc)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=9)
    ap.add_argument("-n", type=int, default=100_000)
    ap.add_argument("--samples", type=int, default=1_000_000)
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    n = args.n
    l1, l2 = rng.uniform(1, 7, n), rng.uniform(1, 7, n)
    th1, th2 = rng.uniform(-np.pi, np.pi, n), rng.uniform(-np.pi, np.pi, n)
    qd = np.asfortranarray(rng.uniform(-2, 2, (n, 2)))
    qdd = np.asfortranarray(rng.uniform(-2, 2, (n, 2)))
    m1, m2 = 10 * l1, 10 * l2

    ker = manipulator_kernel.manipulator_arm_states(l1, l2, th1, th2, qd, qdd, m1, m2, 9.8)
    ref = numpy_arm_states(l1, l2, th1, th2, qd, qdd, m1, m2, 9.8)
    for a, b in zip(ker, ref):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9)

    tk = timeit(lambda: manipulator_kernel.manipulator_arm_states(l1, l2, th1, th2, qd, qdd, m1, m2, 9.8), args.repeat)
    tn = timeit(lambda: numpy_arm_states(l1, l2, th1, th2, qd, qdd, m1, m2, 9.8), args.repeat)
    per_k, per_n = tk / n * 1e6, tn / n * 1e6
    print(f"Jacobian + manipulability + condition number + torques, {n} configurations "
          f"(median of {args.repeat}):")
    print(f"  Fortran kernel : {tk * 1e3:8.3f} ms  = {per_k:.4f} us/config")
    print(f"  numpy baseline : {tn * 1e3:8.3f} ms  = {per_n:.4f} us/config")
    print(f"  speed-up       : {tn / tk:.2f}x")
    print(f"  target <= 0.04 us/config: {'MET' if per_k <= 0.04 else 'NOT MET'}")

    # Monte Carlo tolerance check, case 1 dexterity design, 4 workspace points
    x, y = np.array([1.0, 2, 3, 4]), np.array([5.0, 7, 7, 6])
    a1, a2, _ = manipulator_kernel.manipulator_ik(5.61, 3.97, x, y, 1)
    ri2 = np.sqrt(4 + abs(np.cos(a2).sum()))
    dl = 0.01 / (np.sqrt(2) * ri2)
    ns = args.samples

    def mc_kernel():
        u = np.random.default_rng(1).uniform(-dl, dl, (ns, 2))
        e = manipulator_kernel.manipulator_position_errors(a1, a2, u)[:, 0]
        return e.max(), np.percentile(e, 99)

    def mc_numpy():
        u = np.random.default_rng(1).uniform(-dl, dl, (ns, 2))
        e = numpy_position_errors(a1, a2, u)[:, 0]
        return e.max(), np.percentile(e, 99)

    assert np.allclose(mc_kernel(), mc_numpy())
    rep = max(3, args.repeat // 3)
    mk, mn = timeit(mc_kernel, rep), timeit(mc_numpy, rep)
    emax, p99 = mc_kernel()
    print(f"Monte Carlo tolerance check, {ns} samples x 4 points (median of {rep}), "
          f"max error {emax:.6f} m <= bound 0.01 m, p99 {p99:.6f} m:")
    print(f"  Fortran kernel : {mk * 1e3:8.1f} ms  (sampling + errors + max + p99)")
    print(f"  numpy baseline : {mn * 1e3:8.1f} ms")
    print(f"  speed-up       : {mn / mk:.2f}x")
    print(f"  target < 1 s: {'MET' if mk < 1.0 else 'NOT MET'}")

    nb, nc = 10_000, 100
    tb, tc = design_batch(nb, nc, max(3, args.repeat // 3))
    print(f"Design summaries, {DECK.name} (1000 Monte Carlo samples per design), CPU time, medians:")
    print(f"  batch, {nb} designs in one call : {tb * 1e6:9.2f} us/design  {1 / tb:10.0f} designs/s")
    print(f"  one run() per design ({nc})      : {tc * 1e6:9.2f} us/design  {1 / tc:10.0f} designs/s")
    print(f"  ratio                           : {tc / tb:.0f}x")


if __name__ == "__main__":
    main()
