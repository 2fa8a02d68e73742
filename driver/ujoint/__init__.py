"""Hooke-joint (universal-joint) shaft chains: the paper's SSO package, corrected and extended.

[Fajar] (M. Fajar, "Optimasi kecepatan sudut keluaran kopeling universal pada poros seri"):
three Hooke joints on four shafts, optimised with MATLAB fmincon in three options
(1 phases free, 2 angles free, 3 both).  This study

* evaluates the paper's model (every joint driven by the input angle plus a phase; eq. 13
  as printed or with cumulative phases as the text says) and the exact chain (each joint's
  output angle drives the next, with plane angles for non-coplanar 3-D chains), all in the
  Fortran kernel ``fortran/ujoint.f90``;
* runs the options with scipy SLSQP (the counterpart of fmincon's SQP) from the trial point
  and from seeded random starts, with the kernel's analytic gradient;
* reports trial, optimum and the paper's printed designs under the same objective, the
  fluctuation band, peak-to-peak ratio, closed-form equivalent angles and the peak output
  acceleration, and a speed table over the input angle.

Angles in the deck are degrees; the kernel works in radians.  Phases: the paper's phi
(90 deg = yokes on the intermediate shaft in phase) or the yoke phase delta = phi - 90 deg.
See docs/ujoint.md for what reproduces and what does not.

The package, by job: ``spec`` (deck keys, checks, conventions, labels), ``analysis`` (one design
evaluated; the multi-start optimiser), ``report`` (the .out, tidy table, summary, result.dat,
figures), ``batch`` (many given designs in one kernel call: sweeps and &optimize); this module
runs a deck.
"""
from __future__ import annotations

import math

import numpy as np

from driver.deck import Params
from driver.limits import Estimate
from driver.runner import keyword_run
from driver.study import Figure, Result
from driver.ujoint.analysis import (BOUND_TOL, CLUSTER_TOL, PHASE_PERIOD, SADDLE_NUDGE, SYM_TOL, TIE_RTOL, Chain,
                                    Design, StartRun, _chain, _free_index, _starts, evaluate, objective_scale,
                                    optimise, phases_for, pick_best, yoke_shifts)
from driver.ujoint.batch import (BATCH_ELEMENTS, BATCH_IGNORED, BATCH_INDEPENDENT, BATCH_KEYS, BATCH_PASSES,
                                 batch_applies, summarise_batch)
from driver.ujoint.report import _figure, _render, _result_dat, _summary, _tidy
from driver.ujoint.spec import (BAND_TOL, CONVENTIONS, DEG, LABELS, NOT_REPRODUCIBLE, OPTIONS, SPEC, SWEEP_PLOT,
                                _geometry, _per, _phases, cross_check)

__all__ = ["SPEC", "run", "estimate", "Chain", "Design", "StartRun", "evaluate", "optimise", "objective_scale",
           "pick_best", "yoke_shifts", "phases_for", "cross_check", "summarise_batch", "batch_applies", "BATCH_KEYS",
           "BATCH_PASSES", "BATCH_IGNORED", "BATCH_INDEPENDENT", "BATCH_ELEMENTS", "LABELS", "SWEEP_PLOT", "BAND_TOL",
           "NOT_REPRODUCIBLE", "CONVENTIONS", "OPTIONS", "DEG", "SYM_TOL", "SADDLE_NUDGE", "PHASE_PERIOD", "TIE_RTOL",
           "CLUSTER_TOL", "BOUND_TOL"]


def estimate(params: Params) -> Estimate:
    """Memory and work of a run from the keys alone (driver.limits).

    Per input angle of the grid and joint about 200 bytes of kernel arrays and 20 ns per
    objective evaluation; SLSQP evaluates objective and gradient about (variables + 1) times per
    iteration for every start; each speed-table row costs about 1 KB and 20 us to format.
    """
    p = params
    joints = max(len(p.beta or []), len(p.phi or []) + 1, 2)
    m = float(p.n_grid)
    try:
        rows = math.floor(360.0 / p.table_step + 1e-9) + 1.0
    except (OverflowError, ZeroDivisionError):
        rows = math.inf
    evals = 0.0 if p.option == 0 else float(p.n_starts) * p.maxiter * (2 * joints + 1)
    mem = Estimate(200.0 * m * joints + 5e6, 2e-8 * m * joints * (evals + 10), "n_grid",
                   "n_starts" if p.option else "n_grid", f"{m:.4g} grid angles x {joints} joints"
                   + (f", about {evals:.3g} objective evaluations" if evals else ""))
    table = Estimate(1000.0 * rows * joints, 2e-5 * rows * joints, "table_step", "table_step",
                     f"{rows:.4g} speed-table rows")
    return mem + table


@keyword_run
def run(params: Params, progress: bool = False) -> Result:
    """Analyse (option 0) or optimise (options 1-3) the chain of the deck."""
    beta, rho = _geometry(params)
    n = beta.size
    phi = _phases(params, n)
    chain = _chain(params, rho, n)
    trial = evaluate(chain, "trial" if params.option else "design", beta, phi)
    designs = [trial]
    warnings: list[str] = []
    notes: list[str] = []
    runs: list[StartRun] = []
    failure = None
    best = None
    option = params.option
    if option:
        free = _free_index(option, n)
        lo = np.concatenate([_per(params, "beta_lower", n, "joints"),
                             _per(params, "phi_lower", n - 1, "phases") if n > 1 else []])
        hi = np.concatenate([_per(params, "beta_upper", n, "joints"),
                             _per(params, "phi_upper", n - 1, "phases") if n > 1 else []])
        lb, ub = lo[free] * DEG, hi[free] * DEG
        beta_max = max(np.max(np.abs(beta)), np.max(np.abs(hi[:n])) if option in (2, 3) else 0.0)
        scale = objective_scale(chain, trial.objective, beta_max)
        z = np.concatenate([beta, phi])
        if np.all(lb == ub):
            z[free] = lb / DEG
            best = evaluate(chain, "fixed design", z[:n], z[n:])
            best.extra = {"run": None, "index": None}
            designs.append(best)
            notes.append("equal bounds fix every free variable: the fixed design is evaluated, "
                         "not optimised (no multi-start)")
        else:
            starts, start_notes = _starts(params, option, beta, phi, lb, ub, chain)
            notes += start_notes
            runs = optimise(chain, option, beta * DEG, phi * DEG, lb, ub, starts, params.maxiter,
                            params.ftol, scale, progress)
            ok = any(r.success for r in runs)
            ipick = pick_best(runs, int(np.sum(free < n)))
            pick = runs[ipick]
            z[free] = pick.x / DEG
            best = evaluate(chain, "optimum" if ok else "last iterate", z[:n], z[n:])
            best.extra = {"run": pick, "index": ipick + 1, "scale": scale,
                          "resolution": params.ftol * scale}
            designs.append(best)
            if not ok:
                failure = (f"the optimiser did not converge from any of {len(runs)} start(s) "
                           f"(best start: {pick.message}); no optimum is reported")
                warnings.append(failure)
    printed = None
    if params.paper_beta is not None or params.paper_phi is not None:
        pb = np.asarray(params.paper_beta if params.paper_beta is not None else beta, float)
        pp = _phases(params, n, "paper_phi") if params.paper_phi is not None else phi
        printed = evaluate(chain, "paper printed", pb, pp)
        designs.append(printed)
    text = _render(params, chain, beta, rho, designs, runs, notes, warnings, failure)
    tidy = _tidy(chain, designs)
    summary = _summary(trial, best, runs, failure)
    extra = {".result.dat": _result_dat(params, chain, designs, best, runs)} if best is not None else {}
    title = params.path.stem if getattr(params, "path", None) else ""
    figures = [Figure("speed", lambda: _figure(chain, designs, False, params.paper_band, title)),
               Figure("polar", lambda: _figure(chain, designs, True, params.paper_band, title))]
    return Result(text=text, tidy=tidy, summary=summary, warnings=warnings, failure=failure,
                  figures=figures, extra=extra)
