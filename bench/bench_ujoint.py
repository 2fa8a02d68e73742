"""Benchmark of the Hooke-joint kernel (fortran/ujoint.f90) against a plain numpy baseline.

Run: .venv/bin/python bench/bench_ujoint.py [--quick]

Measures, in the same run, for a 3-joint chain on a 360-point input-angle grid:
  * one objective evaluation (mean (R-1)^2), kernel vs numpy (exact chain and paper model);
  * one objective + gradient, kernel (analytic) vs numpy (central finite differences, what
    an optimiser without the kernel's gradient pays);
  * the wall time of a 64-start option-3 search (SLSQP, analytic gradient) vs the same
    search with the numpy objective and scipy's finite-difference gradient;
  * the batch path of sweeps and &optimize (ujoint.summarise_batch: many designs in one
    kernel call) against the per-case loops it replaces, in designs/s (CPU time): the
    single-design kernel calls of ujoint.evaluate, and validate + run per design (what a
    sweep or an optimiser pays without the batch path).
Prints medians over repeats, ratios, the issue's targets and whether they are met.
"""
from __future__ import annotations

import math
import sys
import time
import timeit
from pathlib import Path

import numpy as np
from scipy.optimize import minimize

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from driver import ujoint
from driver._deck import RawGroup, validate
from driver.ujoint import Chain, optimise
from driver.ujoint._kernel import UJOINT_MODELS, UJOINT_OBJECTIVES, ujoint_objective

D = math.pi / 180.0
M = 360
BETA = np.array([15.0, 20.0, 9.0]) * D
PHI = np.array([57.4233, 73.2749]) * D
RHO = np.array([10.0, -30.0]) * D
TARGET_EVAL_US = 5.0
TARGET_SEARCH_S = 0.5


def numpy_objective(model: str, beta: np.ndarray, phi: np.ndarray, rho: np.ndarray, m: int = M) -> float:
    """Baseline only (plain numpy, full grid): mean (R-1)^2 of the exact chain or the paper's
    cumulative model.  Not used by the tool; the kernel is the one implementation."""
    th = np.arange(m) * (2 * math.pi / m)
    t = th.copy()
    ratio = np.ones(m)
    for k, b in enumerate(beta):
        cb, s2 = math.cos(b), math.sin(b) ** 2
        st = np.sin(t)
        ratio *= cb / (1 - s2 * st * st)
        if k < beta.size - 1:
            if model == "exact":
                t = np.arctan2(cb * st, np.cos(t)) + phi[k] - rho[k]
            else:
                t = t + phi[k]
    return float(np.mean((ratio - 1) ** 2))


def numpy_fd_gradient(model: str, x: np.ndarray, rho: np.ndarray, h: float = 1e-7) -> np.ndarray:
    """Baseline only: central finite-difference gradient of numpy_objective."""
    n = (x.size + 1) // 2
    g = np.empty(x.size)
    for i in range(x.size):
        xp, xm = x.copy(), x.copy()
        xp[i] += h
        xm[i] -= h
        g[i] = (numpy_objective(model, xp[:n], xp[n:], rho) - numpy_objective(model, xm[:n], xm[n:], rho)) / (2 * h)
    return g


def median_us(fn, repeats: int, number: int) -> float:
    return float(np.median(timeit.repeat(fn, repeat=repeats, number=number))) / number * 1e6


def search_kernel(model: str, n_starts: int) -> tuple[float, float]:
    chain = Chain(UJOINT_MODELS[model], UJOINT_OBJECTIVES["mean_square"], np.zeros(2), M, 25.0)
    lb = np.r_[np.full(3, 10.0), np.zeros(2)] * D
    ub = np.r_[np.full(3, 40.0), np.full(2, 180.0)] * D
    rng = np.random.default_rng(3)
    starts = np.vstack([np.r_[30, 40, 40, 91, 91] * D, lb + (ub - lb) * rng.random((n_starts - 1, 5))])
    t0 = time.perf_counter()
    runs = optimise(chain, 3, np.r_[30, 40, 50] * D, np.r_[90, 90] * D, lb, ub, starts, 200, 1e-12)
    wall = time.perf_counter() - t0
    return wall, min(r.f for r in runs if r.success)


def search_numpy(model: str, n_starts: int) -> tuple[float, float]:
    lb = np.r_[np.full(3, 10.0), np.zeros(2)] * D
    ub = np.r_[np.full(3, 40.0), np.full(2, 180.0)] * D
    rng = np.random.default_rng(3)
    starts = np.vstack([np.r_[30, 40, 40, 91, 91] * D, lb + (ub - lb) * rng.random((n_starts - 1, 5))])
    rho = np.zeros(2)
    fref = numpy_objective(model, starts[0][:3], starts[0][3:], rho)
    best = math.inf
    t0 = time.perf_counter()
    for x0 in starts:
        res = minimize(lambda x: numpy_objective(model, x[:3], x[3:], rho) / fref, x0, method="SLSQP",
                       bounds=list(zip(lb, ub)), options={"maxiter": 200, "ftol": 1e-12})
        if res.success:
            best = min(best, res.fun * fref)
    return time.perf_counter() - t0, best


def batch_designs(nd: int, seed: int = 5) -> tuple[object, np.ndarray]:
    """The base deck (exact 3-joint chain, plane angles RHO) and nd random phase pairs [deg]."""
    raw = RawGroup("ujoint", {"beta": list(BETA / D), "phi": list(PHI / D), "rho": list(RHO / D)}, {}, 1)
    base = validate(raw, ujoint.SPEC, "bench.dat")
    return base, np.random.default_rng(seed).uniform(0.0, 180.0, (nd, 2))


def batch_rates(nd: int, n_run: int, repeat: int) -> dict[str, float]:
    """Designs per CPU second: the batch path, the per-design kernel calls, validate + run."""
    base, phis = batch_designs(nd)
    chain = Chain(UJOINT_MODELS["exact"], UJOINT_OBJECTIVES["mean_square"], np.asarray(base["rho"]) * D, M, 25.0)
    beta = np.asarray(base["beta"])
    frame = ujoint.summarise_batch(base, {"phi": phis})
    for i in range(3):   # the batch rows are the per-case figures (tests/test_ujoint_batch.py: all of them)
        d = ujoint.evaluate(chain, "x", beta, phis[i])
        assert (frame["objective"][i], frame["peak_accel_rad_s2"][i]) == (d.objective, d.peak_acc)

    def cpu(fn) -> float:
        times = []
        for _ in range(repeat):
            t0 = time.process_time()
            fn()
            times.append(time.process_time() - t0)
        return float(np.median(times))

    def runs() -> None:
        for ph in phis[:n_run]:
            raw = RawGroup("ujoint", {"beta": base["beta"], "phi": list(ph), "rho": base["rho"]}, {}, 1)
            ujoint.run(validate(raw, ujoint.SPEC, "bench.dat"))
    return {"batch": nd / cpu(lambda: ujoint.summarise_batch(base, {"phi": phis})),
            "evaluate": nd / cpu(lambda: [ujoint.evaluate(chain, "x", beta, ph) for ph in phis]),
            "run": n_run / cpu(runs)}


def main() -> None:
    quick = "--quick" in sys.argv
    rep = 5 if quick else 9
    print(f"ujoint benchmark: 3 joints x {M} grid points; medians of {rep} repeats\n")
    print(f"{'case':<44}{'kernel':>12}{'numpy':>12}{'ratio':>9}")
    results = {}
    for model in ("exact", "cumulative"):
        code = UJOINT_MODELS[model]
        rho = RHO if model == "exact" else np.zeros(2)
        k_f = median_us(lambda code=code, rho=rho: ujoint_objective(code, 0, BETA, PHI, rho, M, grad=False), rep, 2000)
        k_g = median_us(lambda code=code, rho=rho: ujoint_objective(code, 0, BETA, PHI, rho, M, grad=True), rep, 2000)
        n_f = median_us(lambda model=model, rho=rho: numpy_objective(model, BETA, PHI, rho), rep, 200)
        x = np.r_[BETA, PHI]
        n_g = median_us(lambda model=model, x=x, rho=rho: (numpy_objective(model, BETA, PHI, rho),
                                                           numpy_fd_gradient(model, x, rho)), rep, 20)
        print(f"{model + ': objective [us]':<44}{k_f:12.2f}{n_f:12.2f}{n_f / k_f:9.1f}")
        print(f"{model + ': objective + gradient [us]':<44}{k_g:12.2f}{n_g:12.2f}{n_g / k_g:9.1f}")
        results[model] = k_f
    print()
    for model in ("cumulative", "exact"):
        walls = [search_kernel(model, 64)[0] for _ in range(3 if quick else 5)]
        wk = float(np.median(walls))
        wn, fn = search_numpy(model, 64)
        fk = search_kernel(model, 64)[1]
        print(f"{model + ': 64-start option-3 search [s]':<44}{wk:12.3f}{wn:12.3f}{wn / wk:9.1f}"
              f"   best f kernel {fk:.2e}, numpy+FD {fn:.2e}")
        results["search_" + model] = wk
    print()
    worst = max(results["exact"], results["cumulative"])
    print(f"target: objective evaluation <= {TARGET_EVAL_US} us: worst {worst:.2f} us -> "
          f"{'MET' if worst <= TARGET_EVAL_US else 'NOT MET'}")
    ws = max(results["search_exact"], results["search_cumulative"])
    print(f"target: 64-start option-3 search < {TARGET_SEARCH_S} s: worst {ws:.3f} s -> "
          f"{'MET' if ws < TARGET_SEARCH_S else 'NOT MET'}")
    nd = 2000 if quick else 20000
    r = batch_rates(nd, 50 if quick else 200, 3 if quick else 5)
    print(f"\nbatch path (exact chain, 3 joints x {M} angles, {nd} designs; CPU time, median):")
    print(f"  summarise_batch (one kernel call)        {r['batch']:12,.0f} designs/s")
    print(f"  per-design kernel calls (evaluate)       {r['evaluate']:12,.0f} designs/s   "
          f"batch {r['batch'] / r['evaluate']:.1f}x")
    print(f"  validate + run per design (per-case path){r['run']:12,.0f} designs/s   "
          f"batch {r['batch'] / r['run']:.0f}x")


if __name__ == "__main__":
    main()
