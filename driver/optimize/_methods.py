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
from typing import Any

import numpy as np
from scipy.optimize import Bounds, NonlinearConstraint, differential_evolution, minimize
from scipy.stats import qmc

from driver.optimize._evaluate import FAILED_OBJECTIVE, Evaluator

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
    best: Any = None       # the reported design's record when the method chose it (polished), else None
    polish: dict | None = None   # differential evolution with polish: what the polish did


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
        # vectorized=True: 'energies' maps a population (n, S) to S values, and bounds are (min, max)
        # per variable; scipy-stubs types both for the scalar call with one (lower, upper) pair
        res = differential_evolution(
            energies, list(zip(p.lower, p.upper)),  # type: ignore[arg-type]
            constraints=NonlinearConstraint(violations, -np.inf, 0.0),
            strategy="best1bin", maxiter=o.maxiter, popsize=o.popsize, tol=o.tol, atol=o.atol,
            mutation=(0.5, 1.0), recombination=0.7, rng=o.seed, polish=False, init="latinhypercube",
            updating="deferred", vectorized=True, callback=callback)
    best = ev.best()
    feasible = best is not None
    converged = bool(res.success) and feasible
    msg = str(res.message)
    if not feasible:
        msg += "; no feasible design was found"
    out = MethodResult(converged, msg, int(res.nit), int(res.nfev))
    out.best = best     # the evolution's best member (the polish's evaluations do not count unless it wins)
    if o.polish:
        out.polish = _de_polish(ev, best, history)
        if out.polish.get("record") is not None:
            out.best = out.polish["record"]
    return out


def _de_polish(ev: Evaluator, best, history: list[HistoryRow]) -> dict:
    """After the evolution: SLSQP from the best feasible member (constraints, equalities and the
    epigraph of a max-min objective as in the local methods), then the lattice polish; the
    result replaces the member only when it is feasible and at least as good.  Says what happened."""
    p = ev.problem
    if best is None:
        return {"record": None, "text": "not run: the evolution found no feasible design to start from"}
    u0 = (np.array(best.x) - p.lower) / (p.upper - p.lower)
    runs, _, _ = _local_runs(ev, u0[None, :], history, "SLSQP", label="polish")
    r = runs[0]
    rec = r["record"]
    word = "from the best feasible member"   # SLSQP's own message follows the path (the BLAS kernel)
    if not rec.feasible:
        return {"record": None, "text": f"failed: SLSQP {word}; its lattice-polished end is infeasible "
                                        f"({rec.why}); the evolution's best member is reported"}
    if not r["settled"]:
        return {"record": None, "text": f"failed: SLSQP {word}; the lattice polish did not settle; "
                                        "the evolution's best member is reported"}
    gain = p.sense * (best.objective - rec.objective)
    if gain < 0:
        return {"record": None, "text": f"no improvement: SLSQP {word}; its polished end "
                                        f"{p.objective.text} = {rec.objective:.10g} is worse than the member's "
                                        f"{best.objective:.10g}; the evolution's best member is reported"}
    return {"record": rec, "text": f"improved {p.objective.text} from {best.objective:.10g} (evolution) to "
                                   f"{rec.objective:.10g} (SLSQP {word}, then the lattice polish)"}


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
    base_values: list[float] = []
    for v in p.variables:
        val = p.base[v.key]
        if isinstance(val, list):
            val = val[(v.index or 1) - 1]
        base_values.append(float(val) if val is not None else math.nan)
    base = np.array(base_values)
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


# ----------------------------------------------------------------------------- lattice polish

#: pattern-search step multiples (of the lattice step), coarse to fine, and moves allowed per level
POLISH_LEVELS = (64, 16, 4, 1)
POLISH_MOVES = 100
#: up to this many variables the polish looks at all 3^n - 1 neighbours, beyond at the 2n compass ones
POLISH_FULL_N = 4
#: a polish stuck on an infeasible point searches the whole box of +-POLISH_BOX[n] steps around it
#: (n variables: 25^2 - 1 = 624, 9^3 - 1 = 728 designs; not beyond 3 variables)
POLISH_BOX = {1: 64, 2: 12, 3: 4}


def _rank(p, r) -> tuple:
    """Order of designs in the polish: feasible (within tolerance) by objective, then infeasible
    by total violation."""
    if r.feasible:
        return (0, p.sense * r.objective)
    return (1, r.violation if math.isfinite(r.violation) else math.inf)


def _better(p, new, cur) -> bool:
    """The polish moves to ``new`` when it restores feasibility, lowers an infeasible design's
    violation, or improves a feasible objective by more than polish_tol (a gain below the
    method's own stopping precision is noise, and chasing it would only wander)."""
    a, b = _rank(p, new), _rank(p, cur)
    if a[0] != b[0] or a[0] == 1:
        return a < b
    return b[1] - a[1] > polish_tol(p, cur.objective)


def polish_tol(p, f: float) -> float:
    """Least gain of a polish move: the local methods' own stopping precision, 1e-3 x tol relative."""
    return max(p.opts.tol * 1e-3, 1e-12) * max(1.0, abs(f))


def lattice_polish(ev: Evaluator, x: np.ndarray, history: list[HistoryRow], label: str):
    """Deterministic pattern search on the problem's lattice from the lattice point nearest ``x``.

    Every design it evaluates is a lattice point, and the evaluations are the study's
    deterministic kernel: two runs whose optimiser ended a few lattice steps apart (a last-bit
    difference of the BLAS kernel, say) end at the same lattice point, so the reported design and
    every number computed from it are the same on every machine.  A move goes to the best of the
    2n neighbours at +-m steps when it ranks strictly better (feasible first, then objective; ties:
    the first neighbour in a fixed order); m runs through POLISH_LEVELS.

    Returns (record, settled): settled is False when a level used up its POLISH_MOVES moves.
    """
    p = ev.problem
    h = p.steps
    cur = ev.evaluate(p.snap(x)[None, :])[0]
    settled = True
    n = len(h)
    if n <= POLISH_FULL_N:   # every neighbour of the lattice cube: follows ridges a compass search cannot
        dirs = [np.array(d, dtype=np.float64) for d in itertools.product((-1, 0, 1), repeat=n) if any(d)]
    else:                    # compass directions
        dirs = [sgn * np.eye(n)[i] for i in range(n) for sgn in (-1.0, 1.0)]
    def descend(cur, levels):
        ok = True
        for m in levels:
            for _ in range(POLISH_MOVES):
                X = [p.snap(np.array(cur.x, dtype=np.float64) + m * h * d) for d in dirs]
                recs = ev.evaluate(np.array(X))
                top = min(recs, key=lambda r: _rank(p, r))     # min is stable: the first of equals
                if _better(p, top, cur):
                    cur = top
                else:
                    break
            else:
                ok = False
        return cur, ok

    cur, settled = descend(cur, POLISH_LEVELS)
    if not cur.feasible and n in POLISH_BOX:
        # stuck infeasible: a thin feasible wedge (an equality band against a bound) runs in a direction
        # no single cube step follows; every lattice point of the box +-POLISH_BOX steps, in one batch
        r = np.arange(-POLISH_BOX[n], POLISH_BOX[n] + 1, dtype=np.float64)
        box = [np.array(d) for d in itertools.product(r, repeat=n) if any(d)]
        recs = ev.evaluate(np.array([p.snap(np.array(cur.x, dtype=np.float64) + h * d) for d in box]))
        top = min(recs, key=lambda q: _rank(p, q))
        if _better(p, top, cur):
            cur, settled = descend(top, (1,))
    _snapshot(ev, f"{label} lattice polish", history)
    return cur, settled


# ----------------------------------------------------------------------------- local multi-start

class _Local:
    """The functions a local method (SLSQP, trust-constr) calls, for one problem, in normalised
    coordinates u in [0, 1]^n: objective, constraints and their forward-difference Jacobians,
    each point evaluated through the :class:`Evaluator`.

    Equalities go to the method as equalities; a max-min (min-max) objective as its epigraph:
    an extra unknown s, minimise s subject to s >= sense x term_j for every term (smooth where the
    terms are equal, which the min() form is not)."""

    #: forward-difference step in normalised coordinates
    STEP = 1e-6

    def __init__(self, ev: Evaluator):
        p = ev.problem
        self.ev, self.p = ev, p
        self.lo, self.span = p.lower, p.upper - p.lower
        self.n = len(p.variables)
        self.epi = bool(p.terms)
        self.ineq = [k for k, c in enumerate(p.constraints) if not c.equality]
        self.eq = [k for k, c in enumerate(p.constraints) if c.equality]
        self.scale = 1.0   # objective scale of the current start: ftol is relative to |f(start)|

    # ------------------------------------------------------------------ designs and their values
    def to_x(self, u: np.ndarray) -> np.ndarray:
        """Design values of normalised points (the epigraph unknown dropped, clipped into the box)."""
        return self.lo + np.clip(np.asarray(u)[..., :self.n], 0.0, 1.0) * self.span

    def one(self, u):
        """The record of one point."""
        return self.ev.evaluate(self.to_x(np.atleast_2d(np.asarray(u)[:self.n])))[0]

    def stencil(self, u: np.ndarray):
        """Records at u and at the n forward (or backward, at the upper bound) points, in one batch."""
        n, h = self.n, self.STEP
        u = np.clip(np.asarray(u[:n], dtype=np.float64), 0.0, 1.0)
        steps = np.where(u + h <= 1.0, h, -h)
        U = np.vstack([u] + [u + steps[i] * np.eye(n)[i] for i in range(n)])
        return self.ev.evaluate(self.to_x(U)), steps

    def fvals(self, recs) -> np.ndarray:
        """sense x objective of each record, failed designs at FAILED_OBJECTIVE."""
        return np.array([self.p.sense * r.objective if _computed(r) else FAILED_OBJECTIVE for r in recs])

    def tvals(self, recs) -> np.ndarray:
        """sense x term_j of each record (rows), failed designs at FAILED_OBJECTIVE."""
        p = self.p
        return np.array([[p.sense * t if (_computed(r) and math.isfinite(t)) else FAILED_OBJECTIVE for t in r.terms]
                         if r.terms else [FAILED_OBJECTIVE] * len(p.terms) for r in recs])

    def mvals(self, recs, which) -> np.ndarray:
        """Margins (inequalities) or signed residuals a - b (equalities) of the constraints ``which``."""
        rows = []
        for r in recs:
            row = []
            for k in which:
                c = self.p.constraints[k]
                m = r.margins[k] if r.margins else -1e3
                if c.equality:
                    m = r.signed[k] if r.signed else -1e3
                row.append(m if math.isfinite(m) else -1e3)
            rows.append(row)
        return np.array(rows, dtype=np.float64).reshape(len(recs), len(which))

    # ------------------------------------------------------------------ what the method calls
    def fun(self, z) -> float:
        if self.epi:
            return float(z[self.n])
        return float(self.fvals([self.one(z)])[0]) / self.scale

    def jac(self, z) -> np.ndarray:
        if self.epi:
            return np.concatenate([np.zeros(self.n), [1.0]])
        recs, steps = self.stencil(z)
        f = self.fvals(recs)
        return (f[1:] - f[0]) / steps / self.scale

    def gvals(self, z) -> np.ndarray:
        rec = self.one(z)
        parts = [self.mvals([rec], self.ineq)[0]]
        if self.epi:
            parts.append(float(z[self.n]) - self.tvals([rec])[0] / self.scale)
        return np.concatenate(parts)

    def gjac(self, z) -> np.ndarray:
        recs, steps = self.stencil(z)
        m = self.mvals(recs, self.ineq)
        J = ((m[1:] - m[0]) / steps[:, None]).T
        if self.epi:
            t = self.tvals(recs) / self.scale
            Jt = -((t[1:] - t[0]) / steps[:, None]).T
            J = np.vstack([np.hstack([J, np.zeros((len(self.ineq), 1))]),
                           np.hstack([Jt, np.ones((len(self.p.terms), 1))])])
        return J

    def hvals(self, z) -> np.ndarray:
        return self.mvals([self.one(z)], self.eq)[0]

    def hjac(self, z) -> np.ndarray:
        recs, steps = self.stencil(z)
        m = self.mvals(recs, self.eq)
        J = ((m[1:] - m[0]) / steps[:, None]).T
        return np.hstack([J, np.zeros((len(self.eq), 1))]) if self.epi else J

    def constraints(self, method: str) -> list[dict[str, object] | NonlinearConstraint]:
        """The constraints in the form ``method`` takes (SLSQP: dicts; trust-constr: objects)."""
        cons: list[dict[str, object] | NonlinearConstraint] = []
        has_ineq = bool(self.ineq) or self.epi
        if method == "SLSQP":
            if has_ineq:
                cons.append({"type": "ineq", "fun": self.gvals, "jac": self.gjac})
            if self.eq:
                cons.append({"type": "eq", "fun": self.hvals, "jac": self.hjac})
        else:
            if has_ineq:
                cons.append(NonlinearConstraint(self.gvals, 0.0, np.inf, jac=self.gjac))
            if self.eq:
                cons.append(NonlinearConstraint(self.hvals, 0.0, 0.0, jac=self.hjac))
        return cons

    def start(self, u0: np.ndarray) -> tuple[np.ndarray, Bounds]:
        """Take ``u0`` as the start: the objective scale from its record; the method's start point
        and bounds (the epigraph's s starts at the largest term)."""
        n = self.n
        r0 = self.one(u0)
        f0 = self.fvals([r0])[0]
        self.scale = abs(f0) if 0 < abs(f0) < FAILED_OBJECTIVE else 1.0
        z0 = np.asarray(u0, dtype=np.float64)
        lb, ub = np.zeros(n), np.ones(n)
        if self.epi:
            s0 = float(np.max(self.tvals([r0])[0])) / self.scale
            s0 = s0 if math.isfinite(s0) and abs(s0) < FAILED_OBJECTIVE / self.scale else 0.0
            z0 = np.concatenate([z0, [s0]])
            lb, ub = np.concatenate([lb, [-np.inf]]), np.concatenate([ub, [np.inf]])
        return z0, Bounds(lb, ub)


def _computed(r) -> bool:
    """The design was computed and has a finite objective."""
    return r.status == "ok" and math.isfinite(r.objective)


def _method_options(o, method: str) -> dict[str, Any]:
    """scipy's options of the local method: its iteration limit and stopping precision."""
    options: dict[str, Any] = {"maxiter": o.maxiter}
    if method == "SLSQP":
        options["ftol"] = max(o.tol * 1e-3, 1e-12)
    else:
        options.update({"gtol": max(o.tol * 1e-3, 1e-10), "xtol": 1e-10})
    return options


def _minimise(loc: _Local, u0: np.ndarray, method: str, callback):
    """One run of the local method from ``u0`` (scipy's OptimizeResult)."""
    z0, bounds = loc.start(u0)
    kw: dict[str, Any] = {}
    cons = loc.constraints(method)
    if cons:
        kw["constraints"] = cons
    options = _method_options(loc.p.opts, method)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # method, constraints and options are chosen at run time: no single scipy-stubs overload
        return minimize(loc.fun, z0, jac=loc.jac, bounds=bounds, method=method,  # type: ignore[call-overload]
                        callback=callback, options=options, **kw)


def _local_run(loc: _Local, s: int, u0: np.ndarray, history: list[HistoryRow], method: str, label: str):
    """Start ``s`` from ``u0``: the method, then its end polished on the lattice when it is
    feasible or near it.  Returns (the run's row, scipy's result)."""
    ev = loc.ev
    it = [0]

    def callback(*args, **kw) -> None:
        it[0] += 1
        _snapshot(ev, f"{label} {s} iteration {it[0]}", history)

    res = _minimise(loc, u0, method, callback)
    end = loc.one(res.x)
    # the end and the best feasible design this start evaluated: the polish starts from the
    # better one (an iterate can beat the method's last point), on the lattice
    if end.feasible or _near(loc.p, end):   # feasible, or within a few tolerances of it: polished (restored first)
        rec, settled = lattice_polish(ev, np.array(end.x), history, f"{label} {s}")
    else:       # far from feasible: not polished; its end follows the floating-point path
        rec, settled = end, False
    run = {"start": s, "x0": tuple(loc.to_x(np.asarray(u0))), "x": rec.x, "objective": rec.objective,
           "feasible": rec.feasible, "settled": settled, "record": rec,
           "success": bool(res.success), "message": str(res.message),
           "method_x": end.x, "method_objective": end.objective,
           "iterations": int(getattr(res, "nit", it[0]))}
    return run, res


def _local_runs(ev: Evaluator, starts: np.ndarray, history: list[HistoryRow], method: str,
                label: str = "start") -> tuple[list[dict], int, int]:
    """SLSQP / trust-constr from each start (normalised coordinates), each end polished on the
    lattice (:class:`_Local` says how the problem is put to the method).  Returns (one row per
    start, iterations, function evaluations of the method)."""
    loc = _Local(ev)
    runs, nit, nfev = [], 0, 0
    for s, u0 in enumerate(starts, 1):
        run, res = _local_run(loc, s, u0, history, method, label)
        runs.append(run)
        nit += run["iterations"]
        nfev += int(getattr(res, "nfev", 0))
        _snapshot(ev, f"{label} {s} end", history)
    return runs, nit, nfev


def _near(p, r) -> bool:
    """A method's end within a few tolerances of the constraints (conditions met; the objective may
    be undefined there, e.g. just across a reach boundary): worth polishing back to feasibility."""
    if r.status != "ok" or not r.margins:
        return False
    excess = 0.0
    for c, m, t, ok in zip(p.constraints, r.margins, r.tols, r.met):
        if not c.numeric:
            if not ok:
                return False
            continue
        if not math.isfinite(m):
            return False
        excess += max(0.0, -m - t)
    return excess <= 100.0 * max(sum(r.tols), 1e-300)


def objective_tol(p, best: float) -> float:
    """Objective tolerance of 'a start reached the optimum': tol x max(1, |f_best|) (deck units)."""
    return p.opts.tol * max(1.0, abs(best))


def _verdict(p, runs: list[dict]) -> tuple[dict | None, list[dict]]:
    """The best polished end (feasible, settled on the lattice) and the runs that reached it.

    A start reached the optimum when its polished end is feasible within constraint_tol, settled,
    and its objective is within objective_tol of the best: counts a last-bit change cannot flip."""
    good = [r for r in runs if r["feasible"] and r["settled"]]
    if not good:
        return None, []
    top = min(good, key=lambda r: (p.sense * r["objective"], r["start"]))
    tol = objective_tol(p, top["objective"])
    reached = [r for r in good if p.sense * (r["objective"] - top["objective"]) <= tol]
    for r in runs:
        r["reached"] = r in reached
    # reported: the first start that reached the optimum.  Not the very best end: ends within tol
    # of each other are equally optima at the stated precision, and which of them is best can
    # follow the last bits (a start that stopped elsewhere on a tolerance band's ridge)
    return min(reached, key=lambda r: r["start"]), reached


def _local(ev: Evaluator, history: list[HistoryRow]) -> MethodResult:
    p, o = ev.problem, ev.problem.opts
    method = "SLSQP" if o.method == "slsqp" else "trust-constr"
    runs, nit, nfev = _local_runs(ev, _starts(ev), history, method)
    for r in runs:
        r["reached"] = False
    top, reached = _verdict(p, runs)
    if top is None:
        if any(r["feasible"] for r in runs):
            return MethodResult(False, f"no start settled on a feasible design ({len(runs)} starts; the lattice "
                                       f"polish ran out of moves)", nit, nfev, runs)
        return MethodResult(False, f"no start found a feasible design ({len(runs)} starts)", nit, nfev, runs)
    msg = (f"{len(reached)} of {len(runs)} starts reached the optimum (feasible within constraint_tol, "
           f"objective within tol of the best); reported: start {top['start']}")
    res = MethodResult(True, msg, nit, nfev, runs)
    res.best = top["record"]
    return res


def run_method(ev: Evaluator, history: list[HistoryRow]) -> MethodResult:
    """Run the deck's method on the evaluator; history gets one row per generation/iteration."""
    method = ev.problem.opts.method
    if method == "differential_evolution":
        return _de(ev, history)
    if method == "grid":
        return _grid(ev, history)
    return _local(ev, history)
