"""Reports of an optimisation: the .out text, the optimum deck, history and evaluation tables, figure."""
from __future__ import annotations

import math
from typing import Any

import f90nml
import numpy as np
import pandas as pd

from driver._deck import Params
from driver._table import Column, render_table
from driver.optimize._evaluate import Evaluator, Record, rerun_agrees
from driver.optimize._methods import HistoryRow, MethodResult
from driver.optimize._problem import Problem

__all__ = ["optimum_deck", "report_text", "history_frame", "convergence_figure", "designs_figure", "stated_tolerance"]


def _g(v: Any) -> str:
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, float, np.floating, np.integer)):
        v = float(v)
        return f"{v:.10g}" if math.isfinite(v) else "-"
    return "-" if v is None else str(v)


def method_line(p: Problem) -> str:
    o = p.opts
    if o.method == "differential_evolution":
        return (f"differential_evolution (best1bin, seed {o.seed}, population {o.popsize} x {len(p.variables)}, "
                f"maxiter {o.maxiter}, tol {o.tol:g}, atol {o.atol:g}, polish {'yes' if o.polish else 'no'})")
    if o.method == "grid":
        return f"grid ({o.grid_count} points per variable, {o.grid_count ** len(p.variables)} designs)"
    src = f"Sobol' seed {o.seed}" if o.start == "sobol" else f"best points of a {o.grid_count}^n grid"
    return f"{o.method} multi-start ({o.starts} starts: the deck's design, then {src}; maxiter {o.maxiter})"


def optimum_deck(p: Problem, params: Params, rec: Record, converged: bool) -> str:
    """A complete deck of the optimum: the validated study group with the variables set."""
    values = {k: v for k, v in params.items() if v is not None and v != [] and v != ""}
    nml = f90nml.Namelist({p.study.name: values})
    word = "optimum" if converged else "best design found (NOT converged)"
    head = [f"! {word} of optimisation deck {p.deck.path}",
            f"! {p.objective_text} = {_g(rec.objective)}; " + ", ".join(f"{n} = {_g(x)}" for n, x in zip(p.names, rec.x))]
    return "\n".join(head) + "\n" + str(nml) + "\n"


def _constraint_rows(p: Problem, rec: Record) -> list[list]:
    rows = []
    for k, c in enumerate(p.constraints):
        value = _g(rec.values[k]) if c.numeric and rec.values and math.isfinite(rec.values[k]) else "-"
        m = rec.margins[k] if rec.margins else -math.inf
        tol = _g(rec.tols[k]) if c.numeric and rec.tols else "-"
        met = "NO" if not (rec.met and rec.met[k]) else ("yes" if m >= 0 or not c.numeric else "yes, within tol")
        rows.append([f"{k + 1}", c.text, value, _g(m) if math.isfinite(m) else "-", tol, met])
    return rows


def deterministic(p: Problem) -> bool:
    """The method has no BLAS-dependent step (differential evolution without polish, grid):
    its counts and history are the same on every machine and may be printed."""
    return p.opts.method == "grid" or (p.opts.method == "differential_evolution" and not p.opts.polish)


def lattice(p: Problem) -> bool:
    """The reported design is a lattice point (local methods, or the evolution's polish when it won)."""
    return not deterministic(p)


def x_text(p: Problem, i: int, v: float, on_lattice: bool) -> str:
    return p.x_text(i, v) if on_lattice else _g(v)


def settings_of(p: Problem) -> dict[str, Any]:
    """The base deck's settings the study's summary columns depend on (the four-bar's
    ``transmission_band_deg``) that are not design variables: the .out states them and the
    _evals table records them in its metadata."""
    from driver.sweep._report import summary_settings
    return summary_settings(p.study, p.base, {v.key for v in p.variables})


def report_text(p: Problem, ev: Evaluator, mres: MethodResult, history: list[HistoryRow],
                best: Record | None, check: Record | None, files: list[str], jobs: int,
                warnings: list[str] | None = None) -> str:
    """The optimisation's .out file.

    Everything printed is the same on every machine (BLAS kernel, thread count, CPU): designs
    from a BLAS-dependent method (SLSQP, trust-constr) are lattice points polished by a
    deterministic pattern search, every value is the study's (deterministic) kernel at the
    printed design, and counts of iterations and evaluations -- which follow the floating-point
    path -- are printed only for methods without such a step (the tables keep them).
    """
    o = p.opts
    det = deterministic(p)
    on_lat = best is not None and not (o.method == "differential_evolution" and
                                       (mres.polish is None or mres.polish.get("record") is None))
    on_lat = on_lat and o.method != "grid"
    L = [f"  optimisation of &{p.study.name} from deck {p.deck.path}", ""]
    epi = "   (max-min form: solved as its epigraph by the gradient method)" if p.terms and o.method in (
        "slsqp", "trust-constr") or (p.terms and o.polish) else ""
    L += [f"    method ............... {method_line(p)}",
          f"    objective ............ {p.objective_text}{epi}"]
    for c in p.constraints:
        kind = ("equality, met within its tolerance" if c.equality else
                "inequality, margin in its units" if c.sense else "condition, met or not")
        L.append(f"    constraint ........... {c.text}   ({kind})")
    for key, v in settings_of(p).items():   # a setting of the deck the summary columns depend on
        shown = ", ".join(f"{x:g}" for x in v) if isinstance(v, (list, tuple)) else f"{v}"
        L.append(f"    setting .............. {key} = {shown}   (base deck; used by the summary columns)")
    if any(c.numeric for c in p.constraints):
        L.append(f"    feasibility .......... a constraint a >= b, a <= b or a == b is met when violated by at most "
                 f"constraint_tol x max(1, |a|, |b|), constraint_tol = {o.constraint_tol:g}")
    if det:
        L.append("    precision ............ every step of the method is free of BLAS: the design is the best one it "
                 "evaluated (the optimum to the method's tol/atol), its values the study's at that design")
    else:
        L.append(f"    precision ............ the design is a point of the lattice of the 'step' column (resolution "
                 f"{o.resolution:g} of each range), polished there by a deterministic pattern search; its values are "
                 "the study's at that design.  The path of the gradient method (iterations, evaluations, the ends "
                 "before the polish) follows the floating-point path and is in the _history and _evals tables only")
    L.append("")
    cols = [Column("variable", "s", 24, 0, 4), Column("lower", "s", 14, 0, 2), Column("upper", "s", 14, 0, 2),
            Column("deck value", "s", 14, 0, 2)]
    if not det:
        cols.append(Column("step", "s", 8, 0, 2))
    cols.append(Column("optimum" if mres.converged else "best found", "s", 18, 0, 2))
    rows = []
    for i, v in enumerate(p.variables):
        base = p.base[v.key]
        base = base[(v.index or 1) - 1] if isinstance(base, list) else base
        row = [v.name, _g(v.lower), _g(v.upper), _g(base)]
        if not det:
            row.append(f"{p.steps[i]:.0e}")
        rows.append(row + [x_text(p, i, best.x[i], on_lat) if best else "-"])
    L += render_table(cols, rows) + [""]
    status = "CONVERGED" if mres.converged else "NOT CONVERGED"
    L += [f"  Result: {status} -- {mres.message}"]
    unsettled = [w for w in (warnings or []) if "not settled" in w.lower()]
    if best is not None and unsettled:
        L += ["    BUT NOT SETTLED: the optimum's full run has not settled (its values are those of a run "
              "that needs more revolutions; see the warnings below)"]
    if best is None:
        least = ev.least_infeasible()
        L += ["    no feasible design was found; nothing is reported as an optimum."]
        if least is not None and det:
            L += ["    least infeasible design: " + ", ".join(f"{n} = {_g(x)}" for n, x in zip(p.names, least.x))
                  + f" ({least.why})"]
    else:
        what = "optimum" if mres.converged else "best feasible design (not an optimum: the method did not converge)"
        L += [f"    {what}",
              f"    objective ............ {p.objective.text} = {_g(best.objective)}"]
    if mres.polish is not None:
        L += [f"    polish ............... {mres.polish['text']}"]
    if det:
        n_bad = sum(1 for r in ev.records if not r.feasible)
        L += [f"    evaluations .......... {len(ev.records)} designs; {mres.iterations} "
              f"{'generations' if o.method == 'differential_evolution' else 'iterations'}",
              f"    infeasible designs ... {n_bad}"]
        for why, count in ev.reasons().items():
            L.append(f"      {count:>8}  {why}")
    L.append("")
    if best is not None and p.constraints:
        L += ["  Constraints at the " + ("optimum" if mres.converged else "best design")]
        cols = [Column("#", "s", 3, 0, 4), Column("constraint", "s", 40, 0, 2), Column("value", "s", 16, 0, 2),
                Column("margin", "s", 16, 0, 2), Column("tolerance", "s", 10, 0, 2), Column("met", "s", 15, 0, 2)]
        L += render_table(cols, _constraint_rows(p, best)) + [""]
    if best is not None and check is not None:
        same = rerun_agrees(best, check)
        L += ["  Check: the design re-run as a complete deck by the full study",
              f"    {files[0] if files else ''}",
              f"    objective {_g(check.objective)}, feasible {_g(check.feasible)}, margins "
              + (", ".join(_g(m) for m in check.margins) or "-")
              + ("  -- agrees with the evaluation" if same else "  -- DIFFERS from the evaluation")]
        L += [f"    warning: {w}" for w in (warnings or [])] + [""]
    if mres.starts:
        L += ["  Local starts (where each ended follows the method's floating-point path: the _history table has it)",
              "    reached = its end, polished on the lattice, is feasible and within tol x max(1, |f|) of the best"]
        cols = [Column("start", "s", 5, 0, 4)] + [Column(f"{n} (start)", "s", 16, 0, 2) for n in p.names] + [
            Column("outcome", "s", 40, 0, 2)]
        rows = []
        for r in mres.starts:
            if r.get("reached"):
                word = "reached the optimum"
            elif r["settled"] and r["feasible"]:
                word = f"another local optimum, f = {r['objective']:.6g}"
            elif r["feasible"]:
                word = "feasible, did not settle"
            else:
                word = "ended infeasible"
            rows.append([str(r["start"])] + [_g(x) for x in r["x0"]] + [word])
        L += render_table(cols, rows) + [""]
    if det:
        L += ["  History: best feasible design after each " +
              {"differential_evolution": "generation", "grid": "grid batch"}.get(o.method, "iteration")]
        cols = [Column("step", "s", 24, 0, 4), Column("evals", "s", 8, 0, 2), Column("objective", "s", 16, 0, 2)] + [
            Column(n, "s", 16, 0, 2) for n in p.names]
        rows = [[h.step, str(h.evals), _g(h.objective) if h.feasible else "none feasible"] + [_g(x) for x in h.x]
                for h in _thin(history)]
        L += render_table(cols, rows)
        if len(history) > len(_thin(history)):
            L.append(f"    ({len(history)} rows in all; the _history table has every one)")
    else:
        L.append("  History: in the _history table (its rows follow the method's floating-point path)")
    return "\n".join(L).rstrip() + "\n"


def _thin(history: list[HistoryRow], limit: int = 60) -> list[HistoryRow]:
    """Rows for the .out: all of a short history, else the first, every change of the best, the last."""
    if len(history) <= limit:
        return history
    keep = [0] + [i for i in range(1, len(history)) if history[i].objective != history[i - 1].objective
                  or history[i].x != history[i - 1].x] + [len(history) - 1]
    keep = sorted(set(keep))
    if len(keep) > limit:
        keep = sorted(set(keep[:: math.ceil(len(keep) / limit)] + [len(history) - 1]))
    return [history[i] for i in keep]


def history_frame(p: Problem, history: list[HistoryRow]) -> pd.DataFrame:
    """One row per generation / iteration: the best feasible design so far (tidy)."""
    rows = []
    for h in history:
        row = {"step": h.step, "evals": h.evals, "feasible": h.feasible,
               "objective": h.objective if h.feasible else np.nan}
        row.update({n: (h.x[i] if h.x else np.nan) for i, n in enumerate(p.names)})
        rows.append(row)
    return pd.DataFrame(rows, columns=["step", "evals", "feasible", "objective"] + p.names)


def stated_tolerance(p: Problem, best: float) -> tuple[float, str]:
    """The objective tolerance the deck states, in the objective's unit, at the final best
    ``best``, and how: differential evolution stops when the population's spread falls below
    ``tol x |mean| + atol``; the local methods and a grid judge 'reached the optimum' within
    ``tol x max(1, |best|)`` (:func:`driver.optimize._methods.objective_tol`)."""
    o = p.opts
    if o.method == "differential_evolution":
        return o.tol * abs(best) + o.atol, f"tol x |best| + atol = {o.tol:g} x {abs(best):.6g} + {o.atol:g}"
    return o.tol * max(1.0, abs(best)), f"tol x max(1, |best|) = {o.tol:g} x {max(1.0, abs(best)):.6g}"


def convergence_figure(p: Problem, history: pd.DataFrame, evals: pd.DataFrame, title: str):
    """How the search converged (driver.plotting.convergence_plot): best feasible objective, its
    gap to the final best in units of the stated tolerance (drawn until it is within it), and the
    constraint violation, against designs evaluated; the objective named in words with its unit,
    in the axis label and the title."""
    from driver import plotting
    from driver._output import expression_label
    words = expression_label(p.study, p.objective.text)
    feas = evals[evals["feasible"].astype(bool)]["objective"].dropna()
    tol, how = (None, "")
    if len(feas):
        tol, how = stated_tolerance(p, float(feas.min() if p.sense > 0 else feas.max()))
    sense = "minimize" if p.sense > 0 else "maximize"
    return plotting.convergence_plot(history, evals, words, sense, tolerance=tol, tolerance_words=how,
                                     title=f"{plotting.plain_text(title)}: {sense} {plotting.wrap(words, 70)}")


def designs_figure(p: Problem, evals: pd.DataFrame, title: str, x: dict[str, float] | None = None,
                   fun: float | None = None):
    """The designs evaluated, over the first two design variables (the objective against the one
    variable of a one-variable problem): feasible ones coloured by the objective, infeasible ones
    grey crosses, the reported design ``x`` (objective ``fun``) starred (a scatter: an optimiser's
    designs are not on a grid)."""
    from driver import plotting
    from driver._output import column_label, expression_label
    objective = expression_label(p.study, p.objective.text)
    vx = p.names[0]
    vy = p.names[1] if len(p.names) > 1 else "objective"
    ok = evals["feasible"].astype(bool)
    feas, bad = evals[ok], evals[~ok]
    with plotting.style():
        fig, (ax,) = plotting.new_figure(1, 1, figsize=(6.4, 4.4))
        ax.plot(bad[vx], bad[vy], "x", ms=3, color="0.6", label="infeasible designs",
                rasterized=len(bad) > plotting.RASTER_POINTS)
        sc = ax.scatter(feas[vx], feas[vy], c=feas["objective"], s=10, cmap="viridis", label="feasible designs",
                        rasterized=len(feas) > plotting.RASTER_POINTS)
        if len(feas):
            cb = fig.colorbar(sc, ax=ax)
            cb.set_label(plotting.wrap(objective, 40))
            plotting.plain_numbers(cb.ax)
        if x is not None:
            ax.plot([x[vx]], [x[vy] if vy != "objective" else fun], "*", ms=16, color="C3", mec="k", label="optimum")
        ax.set_xlabel(column_label(p.study, vx))
        ax.set_ylabel(column_label(p.study, vy) if vy != "objective" else objective)
        plotting.plain_numbers(ax)
        ax.legend(loc="best")
        ax.set_title(plotting.plain_text(f"{title}: designs evaluated"))
    return fig
