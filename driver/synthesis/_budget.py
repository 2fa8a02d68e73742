"""What a ``&synthesis`` deck will cost, and the inputs no synthesis can use, known before it starts.

:func:`admit` refuses (a :class:`~driver._deck.DeckError` naming the key, exit 2) a synthesis
whose estimated memory or work exceeds the budget (:mod:`driver._limits`: ``--max-memory``,
``--max-work``) and path targets that make the search degenerate (two targets at one point,
all targets on one line), before anything is computed.

The estimates (:func:`estimate`) are upper-bound-like models from the keys alone, with per-item
costs measured on this project's kernels (2026, one core of a shared 2-core machine):

* path: differential evolution evaluates ``popsize x n_vars x (maxiter + 1)`` designs, each the
  exact kernel at ``samples`` crank angles and the distance of every target to the sampled
  curve (about 50 us + 0.15 us per sample + 0.03 us per sample and target); then
  :data:`~driver.synthesis._path.POLISH_STARTS` least-squares runs of at most
  :data:`~driver.synthesis._path.POLISH_MAX_NFEV` steps, each step one residual and one
  forward-difference Jacobian (n_unknowns + 1 residuals of about 60 us + 0.2 us per target);
* function generation: the exact kernel at ``error_points`` x values and a least-squares solve
  over ``points`` precision points;
* crank-rocker: ``2 x family_points`` members of the closed-form family (about 40 us each,
  most of it Python);
* and the four-bar run of the linkage found (the study's own estimate at the deck's
  ``step_deg``).
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from driver import _limits as limits
from driver._deck import DeckError, Params, RawGroup, validate
from driver._limits import Estimate

__all__ = ["admit", "estimate", "degenerate_targets"]

#: a target this close to another (relative to the targets' extent) is the same point
COINCIDENT = 1e-9
#: targets whose spread off their best line is below this fraction of their extent are collinear
COLLINEAR = 1e-9


def degenerate_targets(targets: np.ndarray, timing_deg: list[float] | None) -> tuple[str, str] | None:
    """(key, reason) when path targets leave the search nothing to fit, else None: two targets
    at one point (with free timing, or at one crank angle), or all targets on one straight line."""
    pts = np.asarray(targets, dtype=float)
    extent = float(np.max(np.ptp(pts, axis=0))) if len(pts) else 0.0
    if not extent > 0:
        return "target_x", "every target is the same point: a path needs at least two distinct points"
    for i in range(len(pts)):
        gaps = np.hypot(*(pts[i + 1:] - pts[i]).T)
        close = np.flatnonzero(gaps <= COINCIDENT * extent)
        for j in close + i + 1:
            if timing_deg is None or abs((timing_deg[j] - timing_deg[i]) % 360.0) <= 1e-9:
                how = "" if timing_deg is None else " at the same crank angle"
                return "target_x", (f"targets {i + 1} and {j + 1} are the same point ({pts[i, 0]:.6g}, {pts[i, 1]:.6g})"
                                    f"{how}: the coupler point would have to pass it twice; give distinct points "
                                    "(or, with timing_deg, the crank angles of a curve that crosses itself)")
    if len(pts) >= 3:
        centred = pts - pts.mean(axis=0)
        s = np.linalg.svd(centred, compute_uv=False)
        if s[1] <= COLLINEAR * s[0]:
            return "target_y", ("the targets lie on one straight line: the search is degenerate (a whole family of "
                                "linkages fits them equally well, and the least-squares stage has no isolated "
                                "solution); give points of the curve you want that do not all lie on one line")
    return None


def _linkage_run(p: Params) -> Estimate:
    """The four-bar study's run of the linkage found: its own estimate at the deck's step."""
    from driver import fourbar
    span = abs(p.crank_range_deg) if p.task == "function" and p.crank_range_deg else 360.0
    raw = RawGroup("fourbar", {"fixed_link": 1.0, "crank": 0.3, "coupler": 1.0, "rocker": 1.0, "omega": p.omega,
                               "step_deg": p.step_deg, "start_deg": 0.0, "stop_deg": span}, {}, p.line)
    try:
        est = fourbar.STUDY.estimate(validate(raw, fourbar.SPEC, p.path))
    except DeckError:   # the linkage's own run checks what it needs when it runs
        return Estimate(0.0, 0.0)
    return Estimate(est.bytes, est.seconds, "step_deg", "step_deg", f"the linkage's run: {est.detail}")


def estimate(p: Params) -> Estimate:
    """Memory [bytes] and work [s] of the synthesis ``p`` (a validated ``&synthesis`` group)."""
    from driver.synthesis import _path as pg
    if p.task == "path":
        n = len(p.target_x)
        nvars = 9 + (p.timing_deg is not None)
        designs = float(p.popsize) * nvars * (p.maxiter + 1)
        per_design = 50e-6 + p.samples * (0.15e-6 + 0.03e-6 * n)
        unknowns = 9 + (1 if p.timing_deg is not None else n)
        polish = pg.POLISH_STARTS * pg.POLISH_MAX_NFEV * (unknowns + 1) * (60e-6 + 0.2e-6 * n)
        de = designs * per_design
        key = ("samples" if p.samples > 360 else "maxiter") if de >= polish else "target_x"
        work = Estimate(3.0 * 8.0 * n * p.samples + 200.0 * p.samples + 50e6, de + polish,
                        "samples", key, f"{designs:.3g} designs of {p.samples} crank angles and {n} targets, "
                        f"then {pg.POLISH_STARTS} least-squares runs of up to {pg.POLISH_MAX_NFEV} steps")
    elif p.task == "function":
        work = Estimate(400.0 * p.error_points + 100.0 * p.points + 20e6,
                        0.05 + 2e-6 * p.error_points + 1e-5 * p.points, "error_points",
                        "error_points" if p.error_points * 2e-6 >= p.points * 1e-5 else "points",
                        f"{p.error_points} points of the structural error, {p.points} precision points")
    else:
        members = 2.0 * p.family_points
        work = Estimate(1500.0 * members + 20e6, 0.05 + 40e-6 * members, "family_points", "family_points",
                        f"{members:.3g} members of the family")
    return work + _linkage_run(p)


def admit(p: Params) -> Estimate:
    """Refuse, before anything is computed, a synthesis over the budget or with degenerate path
    targets (DeckError naming the key); returns the estimate."""
    if p.task == "path":
        bad = degenerate_targets(np.column_stack([p.target_x, p.target_y]), p.timing_deg)
        if bad is not None:
            raise p.error(*bad)
    est = estimate(p)
    if not (math.isfinite(est.bytes) and math.isfinite(est.seconds)):
        raise p.error(est.work_key, "the work of this synthesis cannot be estimated (a count out of range)")
    return limits.check(SimpleNamespace(estimate=estimate), p, "this synthesis ")
