"""The optimisation methods (scipy.optimize), all driven through one :class:`Evaluator`.

* ``differential_evolution``: the whole population (or all trial vectors of a generation)
  is one call of the evaluator (``vectorized=True``), so a study's batch path or worker
  processes see a batch; constraints use scipy's feasibility rules (a feasible design beats
  an infeasible one; between infeasible ones the smaller total violation wins).
* ``slsqp`` / ``trust-constr``: multi-start local searches in bound-normalised coordinates,
  from the deck's own design and a seeded scrambled Sobol' set (or the best feasible points
  of a grid); gradients are forward differences, all n+1 points of one Jacobian evaluated in
  one batch; the objective is divided by its magnitude at the start, so the stopping
  tolerance (tol x 1e-3) is relative.
* ``grid``: every point of a grid_count^n grid, in batches.

Whatever the method, the reported design is the best *feasible* design the run evaluated
(ties: the design evaluated first wins), and it is called an optimum only when the method
says it converged.
"""
from __future__ import annotations

import itertools
import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import Bounds, NonlinearConstraint, differential_evolution, minimize
from scipy.stats import qmc

from driver.optimize.evaluate import FAILED_OBJECTIVE, Evaluator

__all__ = ["MethodResult", "HistoryRow", "run_method"]

GRID_BATCH = 4096


@dataclass
class HistoryRow:
    """Best feasible design after one generation / iteration / grid batch."""

    step: str          # 'generation 12', 'start 3 iteration 4', 'grid batch 2'
    evals: int         # designs evaluated so far
    objective: float   # best feasible objective so far (NaN while none is feasible)
    x: tuple[float, ...]
    feasible: bool


@dataclass
class MethodResult:
    """What a method reports about itself (the optimum is chosen from the evaluator)."""

    converged: bool
    message: str
    iterations: int
    scipy_nfev: int
    starts: list[dict] = field(default_factory=list)   # local methods: one entry per start


def _snapshot(ev: Evaluator, step: str, history: list[HistoryRow]) -> None:
    best = ev.best()
    if best is None:
        least = ev.least_infeasible()
        history.append(HistoryRow(step, len(ev.records), math.nan, least.x if least else (), False))
    else:
        history.append(HistoryRow(step, len(ev.records), best.objective, best.x, True))


# ----------------------------------------------------------------------------- differential evolution

def _de(ev: Evaluator, history: list[HistoryRow]) -> MethodResult:
    p, o = ev.problem, ev.problem.opts
    sense = p.sense

    def energies(x: np.ndarray) -> np.ndarray:
        X = np.asarray(x).T if np.ndim(x) == 2 else np.atleast_2d(x)
        recs = ev.evaluate(X)
        f = np.array([sense * r.objective if math.isfinite(r.objective) else math.inf for r in recs])
        return f if np.ndim(x) == 2 else f[0]

    def violations(x: np.ndarray) -> np.ndarray:
        X = np.asarray(x).T if np.ndim(x) == 2 else np.atleast_2d(x)
        v = np.array([[0.0 if r.feasible else r.violation] for r in ev.evaluate(X)])
        return v.T if np.ndim(x) == 2 else v[0]

    gen = [0]

    def callback(intermediate_result) -> None:
        gen[0] += 1
        _snapshot(ev, f"generation {gen[0]}", history)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # scipy notes when polishing cannot improve; reported below
        res = differential_evolution(
            energies, list(zip(p.lower, p.upper)), constraints=NonlinearConstraint(violations, -np.inf, 0.0),
            strategy="best1bin", maxiter=o.maxiter, popsize=o.popsize, tol=o.tol, atol=o.atol,
            mutation=(0.5, 1.0), recombination=0.7, rng=o.seed, polish=o.polish, init="latinhypercube",
            updating="deferred", vectorized=True, callback=callback)
    best = ev.best()
    feasible = best is not None
    converged = bool(res.success) and feasible
    msg = str(res.message)
    if not feasible:
        msg += "; no feasible design was found"
    return MethodResult(converged, msg, int(res.nit), int(res.nfev))


# ----------------------------------------------------------------------------- local multi-start

def _grid_points(p, count: int) -> np.ndarray:
    axes = [np.linspace(v.lower, v.upper, count) for v in p.variables]
    return np.array(list(itertools.product(*axes)), dtype=np.float64)


def _grid(ev: Evaluator, history: list[HistoryRow]) -> MethodResult:
    X = _grid_points(ev.problem, ev.problem.opts.grid_count)
    for b, i in enumerate(range(0, len(X), GRID_BATCH), 1):
        ev.evaluate(X[i:i + GRID_BATCH])
        _snapshot(ev, f"grid batch {b}", history)
    best = ev.best()
    if best is None:
        return MethodResult(False, f"none of the {len(X)} grid points is feasible", 1, len(X))
    return MethodResult(True, f"exhaustive over the {len(X)}-point grid (resolution of the grid only)", 1, len(X))


def _starts(ev: Evaluator) -> np.ndarray:
    """Start points in normalised coordinates: the deck's design, then Sobol' or grid points."""
    p, o = ev.problem, ev.problem.opts
    lo, hi = p.lower, p.upper
    base = []
    for v in p.variables:
        val = p.base[v.key]
        if isinstance(val, list):
            val = val[(v.index or 1) - 1]
        base.append(float(val) if val is not None else math.nan)
    base = np.array(base)
    starts = []
    if np.all(np.isfinite(base)) and np.all((base >= lo) & (base <= hi)):
        starts.append((base - lo) / (hi - lo))
    if o.start == "grid":
        X = _grid_points(p, o.grid_count)
        recs = []
        for i in range(0, len(X), GRID_BATCH):
            recs += ev.evaluate(X[i:i + GRID_BATCH])
        order = sorted(recs, key=lambda r: (not r.feasible, p.sense * r.objective if r.feasible else r.violation,
                                            r.index))
        starts += [(np.array(r.x) - lo) / (hi - lo) for r in order[: max(0, o.starts - len(starts))]]
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")   # balance properties need 2^m points; any count is fine here
            u = qmc.Sobol(len(p.variables), scramble=True, rng=o.seed).random(max(0, o.starts - len(starts)))
        starts += list(u)
    return np.array(starts[: o.starts])


def _local(ev: Evaluator, history: list[HistoryRow]) -> MethodResult:
    p, o = ev.problem, ev.problem.opts
    lo, hi = p.lower, p.upper
    span = hi - lo
    n = len(p.variables)
    h = 1e-6

    def to_x(u: np.ndarray) -> np.ndarray:
        return lo + np.clip(u, 0.0, 1.0) * span

    def stencil(u: np.ndarray):
        """Records at u and at the n forward (or backward, at the upper bound) points, in one batch."""
        u = np.clip(np.asarray(u, dtype=np.float64), 0.0, 1.0)
        steps = np.where(u + h <= 1.0, h, -h)
        U = np.vstack([u] + [u + steps[i] * np.eye(n)[i] for i in range(n)])
        return ev.evaluate(to_x(U)), steps

    def fvals(recs) -> np.ndarray:
        return np.array([p.sense * r.objective if math.isfinite(r.objective) and r.status == "ok"
                         else FAILED_OBJECTIVE for r in recs])

    def mvals(recs) -> np.ndarray:
        return np.array([[m if math.isfinite(m) else -1e3 for m in r.margins] for r in recs]).reshape(len(recs), -1)

    scale = [1.0]   # objective scale of the current start: ftol is relative to |f(start)|
    fun = lambda u: float(fvals(ev.evaluate(to_x(np.atleast_2d(u))))[0]) / scale[0]

    def jac(u):
        recs, steps = stencil(u)
        f = fvals(recs)
        return (f[1:] - f[0]) / steps / scale[0]

    cons_fun = lambda u: mvals(ev.evaluate(to_x(np.atleast_2d(u))))[0]

    def cons_jac(u):
        recs, steps = stencil(u)
        m = mvals(recs)
        return ((m[1:] - m[0]) / steps[:, None]).T

    starts = _starts(ev)
    method = "SLSQP" if o.method == "slsqp" else "trust-constr"
    runs, nit, nfev = [], 0, 0
    for s, u0 in enumerate(starts, 1):
        it = [0]
        f0 = fvals(ev.evaluate(to_x(np.atleast_2d(u0))))[0]
        scale[0] = abs(f0) if 0 < abs(f0) < FAILED_OBJECTIVE else 1.0

        def callback(*args, **kw) -> None:
            it[0] += 1
            _snapshot(ev, f"start {s} iteration {it[0]}", history)

        kw = {}
        if p.constraints:
            if method == "SLSQP":
                kw["constraints"] = [{"type": "ineq", "fun": cons_fun, "jac": cons_jac}]
            else:
                kw["constraints"] = [NonlinearConstraint(cons_fun, 0.0, np.inf, jac=cons_jac)]
        options = {"maxiter": o.maxiter}
        if method == "SLSQP":
            options["ftol"] = max(o.tol * 1e-3, 1e-12)
        else:
            options.update({"gtol": max(o.tol * 1e-3, 1e-10), "xtol": 1e-10})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = minimize(fun, u0, jac=jac, bounds=Bounds(np.zeros(n), np.ones(n)), method=method,
                           callback=callback, options=options, **kw)
        rec = ev.evaluate(to_x(np.atleast_2d(res.x)))[0]
        runs.append({"start": s, "x0": tuple(to_x(u0)), "x": rec.x, "objective": rec.objective,
                     "feasible": rec.feasible, "success": bool(res.success), "message": str(res.message),
                     "iterations": int(getattr(res, "nit", it[0]))})
        nit += int(getattr(res, "nit", it[0]))
        nfev += int(getattr(res, "nfev", 0))
        _snapshot(ev, f"start {s} end", history)
    best = ev.best()
    good = [r for r in runs if r["success"] and r["feasible"]]
    if best is None:
        return MethodResult(False, f"no start found a feasible design ({len(runs)} starts)", nit, nfev, runs)
    if not good:
        return MethodResult(False, f"no start converged to a feasible design ({len(runs)} starts)", nit, nfev, runs)
    top = min(good, key=lambda r: (p.sense * r["objective"], r["start"]))
    # the best design evaluated (possibly a finite-difference neighbour) must be the converged one's
    tol = o.tol * max(1.0, abs(top["objective"])) + o.atol
    converged = p.sense * (top["objective"] - best.objective) <= tol
    msg = (f"{len(good)} of {len(runs)} starts converged to feasible designs; best from start {top['start']}"
           if converged else
           "the best design evaluated is better than every converged start by more than the tolerance")
    return MethodResult(bool(converged), msg, nit, nfev, runs)


def run_method(ev: Evaluator, history: list[HistoryRow]) -> MethodResult:
    """Run the deck's method on the evaluator; history gets one row per generation/iteration."""
    method = ev.problem.opts.method
    if method == "differential_evolution":
        return _de(ev, history)
    if method == "grid":
        return _grid(ev, history)
    return _local(ev, history)
