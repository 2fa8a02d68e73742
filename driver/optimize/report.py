"""Reports of an optimisation: the .out text, the optimum deck, history and evaluation tables, figure."""
from __future__ import annotations

import math
from typing import Any

import f90nml
import numpy as np
import pandas as pd

from driver.deck import Params
from driver.optimize.evaluate import Evaluator, Record
from driver.optimize.methods import HistoryRow, MethodResult
from driver.optimize.problem import Problem
from driver.table import Column, render_table

__all__ = ["optimum_deck", "report_text", "history_frame", "convergence_figure"]


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
    nml = f90nml.Namelist({p.study.SPEC.name: values})
    word = "optimum" if converged else "best design found (NOT converged)"
    head = [f"! {word} of optimisation deck {p.deck.path}",
            f"! {p.objective_text} = {_g(rec.objective)}; " + ", ".join(f"{n} = {_g(x)}" for n, x in zip(p.names, rec.x))]
    return "\n".join(head) + "\n" + str(nml) + "\n"


def _constraint_rows(p: Problem, rec: Record) -> list[list]:
    rows = []
    for k, c in enumerate(p.constraints):
        value = "-"
        if c.sense and rec.summary:
            frame = pd.DataFrame([rec.summary])
            for name in c.whole.names:
                if name not in frame:
                    frame[name] = np.nan
            try:
                value = _g(float(np.asarray(c.left.evaluate(frame), dtype=float)[0]))
            except (TypeError, ValueError):
                value = "-"
        m = rec.margins[k] if rec.margins else -math.inf
        rows.append([f"{k + 1}", c.text, value, _g(m) if math.isfinite(m) else "-", "yes" if rec.met and rec.met[k] else "NO"])
    return rows


def report_text(p: Problem, ev: Evaluator, mres: MethodResult, history: list[HistoryRow],
                best: Record | None, check: Record | None, files: list[str], jobs: int) -> str:
    """The optimisation's .out file."""
    o = p.opts
    L = [f"  optimisation of &{p.study.SPEC.name} from deck {p.deck.path}", ""]
    L += [f"    method ............... {method_line(p)}",
          f"    objective ............ {p.objective_text}"]
    for k, c in enumerate(p.constraints):
        kind = "inequality, margin in its units" if c.sense else "condition, met or not"
        L.append(f"    constraint ........... {c.text}   ({kind})")
    L.append("")
    cols = [Column("variable", "s", 24, 0, 4), Column("lower", "s", 14, 0, 2), Column("upper", "s", 14, 0, 2),
            Column("deck value", "s", 14, 0, 2), Column("optimum" if mres.converged else "best found", "s", 18, 0, 2)]
    rows = []
    for i, v in enumerate(p.variables):
        base = p.base[v.key]
        base = base[(v.index or 1) - 1] if isinstance(base, list) else base
        rows.append([v.name, _g(v.lower), _g(v.upper), _g(base), _g(best.x[i]) if best else "-"])
    L += render_table(cols, rows) + [""]
    status = "CONVERGED" if mres.converged else "NOT CONVERGED"
    L += [f"  Result: {status} -- {mres.message}"]
    if best is None:
        least = ev.least_infeasible()
        L += ["    no feasible design was evaluated; nothing is reported as an optimum."]
        if least is not None:
            L += ["    least infeasible design: " + ", ".join(f"{n} = {_g(x)}" for n, x in zip(p.names, least.x))
                  + f" ({least.why})"]
    else:
        what = "optimum" if mres.converged else "best feasible design evaluated (not an optimum: the method did not converge)"
        L += [f"    {what}",
              f"    objective ............ {p.objective.text} = {_g(best.objective)}  (evaluation {best.index + 1})"]
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
                Column("margin", "s", 16, 0, 2), Column("met", "s", 4, 0, 2)]
        L += render_table(cols, _constraint_rows(p, best)) + [""]
    if best is not None and check is not None:
        same = (check.feasible == best.feasible and
                (check.objective == best.objective or abs(check.objective - best.objective)
                 <= 1e-9 * max(1.0, abs(best.objective))))
        L += ["  Check: the design re-run as a complete deck by the full study",
              f"    {files[0] if files else ''}",
              f"    objective {_g(check.objective)}, feasible {_g(check.feasible)}, margins "
              + (", ".join(_g(m) for m in check.margins) or "-")
              + ("  -- agrees with the evaluation" if same else "  -- DIFFERS from the evaluation"), ""]
    if mres.starts:
        L += ["  Local starts"]
        cols = [Column("start", "s", 5, 0, 4)] + [Column(n, "s", 16, 0, 2) for n in p.names] + [
            Column("objective", "s", 16, 0, 2), Column("feasible", "s", 8, 0, 2), Column("converged", "s", 9, 0, 2),
            Column("iter", "s", 5, 0, 2)]
        rows = [[str(r["start"])] + [_g(x) for x in r["x"]] + [_g(r["objective"]), _g(r["feasible"]),
                                                                _g(r["success"]), str(r["iterations"])]
                for r in mres.starts]
        L += render_table(cols, rows) + [""]
    L += ["  History: best feasible design after each " +
          {"differential_evolution": "generation", "grid": "grid batch"}.get(o.method, "iteration")]
    cols = [Column("step", "s", 24, 0, 4), Column("evals", "s", 8, 0, 2), Column("objective", "s", 16, 0, 2)] + [
        Column(n, "s", 16, 0, 2) for n in p.names]
    rows = [[h.step, str(h.evals), _g(h.objective) if h.feasible else "none feasible"] + [_g(x) for x in h.x]
            for h in _thin(history)]
    L += render_table(cols, rows)
    if len(history) > len(_thin(history)):
        L.append(f"    ({len(history)} rows in all; the _history table has every one)")
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


def convergence_figure(p: Problem, history: pd.DataFrame, evals: pd.DataFrame, title: str):
    """How the search converged (driver.plotting.convergence_plot): best feasible objective, its
    gap to the final best on a log axis, and the constraint violation, against designs evaluated;
    the objective named in words with its unit."""
    from driver import plotting
    from driver.study import expression_label
    return plotting.convergence_plot(history, evals, expression_label(p.study, p.objective.text),
                                     "minimize" if p.sense > 0 else "maximize",
                                     title=plotting.plain_text(f"{title}: {p.objective_text}"))
