"""Optimisation of any study: an ``&optimize`` group beside the study group.

See :mod:`driver.optimize._problem` for the deck keys.  Outputs for a deck ``<stem>.dat``:

* ``<stem>.out``: problem, method, result (converged or not -- a design is called an optimum
  only when the method converged), the optimum's constraint values and margins, the check of
  the optimum by the full study, infeasible designs counted by reason, and the history;
* ``<stem>.optimum.dat``: the optimum as a complete deck, and ``<stem>.optimum.out`` (plus tidy
  tables and figures when asked) from running that deck through the study;
* ``<stem>_history.csv``: the best feasible design after every generation / iteration;
* ``<stem>_evals.parquet``: every evaluated design (variables, feasibility and reason,
  objective, margins, the study's summary columns), also as CSV with ``--csv``;
* ``<stem>_convergence.png`` with ``--plot`` (``.svg``/``.pdf`` with ``--plot-format``).

While a run goes, each evaluation is appended to ``<stem>.journal.jsonl``; ``--resume``
replays the (deterministic) run from the journal, or from a finished run's ``_evals``
table, computing only designs not evaluated before.  Every journal line and table row carries
a checksum of its content, verified on resume: what fails is computed again, and the command
line says how many and why (:mod:`driver.optimize._journal`).  The journal is removed when the
outputs are complete.

Python API: :func:`optimize` returns an :class:`OptimizeOutcome` (``scipy.optimize``-like
fields ``x``, ``fun``, ``success``, ``message``, ``nfev``).
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from driver import _blas as blas
from driver._atomic import output_set, write_text
from driver._deck import Deck, read_deck
from driver._export import write_tidy
from driver._extras import require
from driver._outcome import ExitCode, Outcome
from driver._runner import compute, output_stem, write_outputs
from driver.optimize import _journal as journal_file
from driver.optimize import _report as report
from driver.optimize._evaluate import Evaluator, Record, design_params, rerun_agrees
from driver.optimize._methods import HistoryRow, MethodResult, run_method
from driver.optimize._problem import SPEC, Problem, problem_of

__all__ = ["SPEC", "OptimizeOutcome", "optimize", "run_optimize_deck", "problem_of"]

#: methods whose every step is free of BLAS (their evaluations are the deterministic kernel's): the
#: best design they evaluated is the same on every machine
DETERMINISTIC = ("differential_evolution", "grid")


def o_method(problem: Problem) -> str:
    return problem.opts.method


class DesignVector(dict):
    """A design: {'group.key': value} in the order of the variables, and an array
    (``np.asarray(x)``) with its ``names``."""

    @property
    def names(self) -> list[str]:
        return list(self.keys())

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        return np.array(list(self.values()), dtype=dtype or np.float64)


@dataclass
class OptimizeOutcome(Outcome):
    """Result of an optimisation, shaped like ``scipy.optimize.OptimizeResult``.

    Also an :class:`~driver._outcome.Outcome`: files written, warnings and errors as messages,
    notes.  Values are in the units of the deck keys and summary columns they name.

    Attributes
    ----------
    problem : Problem
        The problem the ``&optimize`` group declared (variables, objective, constraints).
    x : DesignVector or None
        Best feasible design, ``{'group.key': value}`` in the variables' deck units (and an
        array by ``np.asarray(x)``, names in ``x.names``); None when none is feasible.
    fun : float or None
        Its objective value, in the objective expression's units (not sign-flipped).
    success : bool
        The method converged and ``x`` is feasible: ``x`` is an optimum.
    message : str
        The method's words.
    nfev : int
        Designs evaluated (each distinct design once).
    best : Record or None
        The evaluation record of ``x``.
    check : Record or None
        The optimum re-run by the full study.
    method : MethodResult
        What the method returned (iterations, convergence, starts, polish).
    history : list of HistoryRow
        The best feasible design after each generation, iteration or grid batch.
    evaluator : Evaluator
        Every design evaluated (``evaluator.frame()``: feasibility, reason, margins, summary).
    study_result : Result or None
        The study's full run at the optimum.
    """

    problem: Problem
    x: dict[str, float] | None
    fun: float | None
    success: bool
    message: str
    nfev: int
    best: Record | None
    check: Record | None
    method: MethodResult
    history: list[HistoryRow]
    evaluator: Evaluator
    study_result: Any = None

    @property
    def status(self) -> int:
        """0 optimum, 1 not converged (``x`` the best feasible design found), 2 no feasible design."""
        return 0 if self.success else (2 if self.x is None else 1)

    @property
    def check_agrees(self) -> bool:
        """The full study's re-run of ``x`` agrees with its evaluation (True without a re-run)."""
        return self.best is None or self.check is None or rerun_agrees(self.best, self.check)

    @property
    def exit_code(self) -> ExitCode:
        """1 when the method failed or the optimum's re-run failed or differs, else 0.

        Failed: the method did not converge, or the optimum's full run by the study failed or
        differs from its evaluation (:attr:`check_agrees`).
        """
        failed = not self.success or not self.check_agrees or (
            self.check is not None and self.study_result is not None and bool(self.study_result.failure))
        return ExitCode.FAILED if failed else super().exit_code

    @property
    def nit(self) -> int:
        """Iterations: generations for differential evolution, all starts' for local methods."""
        return int(self.method.iterations)

    @property
    def constraints(self) -> list[dict]:
        """Constraint values and margins at x (empty without a feasible design)."""
        if self.best is None:
            return []
        r, out = self.best, []
        for k, c in enumerate(self.problem.constraints):
            kind = "equality" if c.equality else ("inequality" if c.sense else "condition")
            num = lambda v: (float(v) if v is not None and math.isfinite(v) else None)
            out.append({"constraint": c.text, "kind": kind,
                        "value": num(r.values[k]) if (c.numeric and r.values) else None,
                        "margin": num(r.margins[k]) if r.margins else None,
                        "tolerance": num(r.tols[k]) if (c.numeric and r.tols) else None,
                        "met": bool(r.met[k]) if r.met else False})
        return out

    def to_dict(self) -> dict:
        """Return the result as plain data: the ``--json`` record.

        Returns
        -------
        dict
            Scipy's fields, the constraints at ``x``, the starts of a local method and the
            polish of differential evolution (JSON-safe; values in their deck units).
        """
        p = self.problem
        rec = {"study": p.study.spec.name, "deck": str(p.deck.path), "objective": p.objective_text,
               "x": None if self.x is None else [float(v) for v in self.x.values()], "x_names": p.names,
               "fun": self.fun, "success": self.success, "status": self.status, "message": self.message,
               "nit": self.nit, "nfev": self.nfev, "constraint_tol": p.opts.constraint_tol,
               "constraints": self.constraints,
               "warnings": list(self.study_result.warnings) if self.study_result is not None else []}
        if self.method.starts:
            rec["starts"] = [{"start": r["start"], "x0": [float(v) for v in r["x0"]],
                              "end": [float(v) for v in r["x"]], "objective": _num(r["objective"]),
                              "feasible": bool(r["feasible"]), "settled": bool(r["settled"]),
                              "reached": bool(r.get("reached", False)), "method_success": bool(r["success"]),
                              "method_message": r["message"], "iterations": r["iterations"]} for r in self.method.starts]
        if self.method.polish is not None:
            rec["polish"] = self.method.polish["text"]
        return rec


def _num(v: Any) -> float | None:
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _probe(problem: Problem) -> None:
    """Run the deck's own design once: every expression must name columns of the study's summary.

    Only a clean run (no failure, no warning) proves a column does not exist; otherwise (a buckled
    rod has no strain peaks) a design whose summary lacks a column is infeasible, with that reason.
    """
    x = [base_value(problem, v) for v in problem.variables]
    try:
        params = design_params(problem, np.array(x))
        if problem.study.summarise is not None:
            summary, clean = dict(problem.study.summarise(params)), True
        else:       # through the runner: the budget and the finite-number checks apply here too
            result = compute(problem.study, params)
            summary, clean = dict(result.summary), not (result.failure or result.warnings)
    except Exception:    # the deck's design fails; names are checked per design (missing -> infeasible)
        return
    if not summary:
        return
    from driver import _expr as expr
    frame = pd.DataFrame([summary])
    o = problem.opts
    exprs = [("minimize" if problem.sense > 0 else "maximize", problem.objective)]
    nums = [n for n in range(1, 10) if o[f"constraint{n}"] is not None]
    exprs += [(f"constraint{n}", c.whole) for n, c in zip(nums, problem.constraints)]
    unknown = [c for c in o.summary_columns if c not in frame]
    if unknown and clean:
        raise o.error("summary_columns", f"unknown summary column '{unknown[0]}' of &{problem.raw.name} "
                                         f"(columns: {', '.join(frame.columns)})")
    for key, e in exprs:
        missing = [name for name in sorted(e.names) if name not in frame]
        renamed = problem.study.renamed
        if missing and missing[0] in renamed:
            raise o.error(key, f"summary column '{missing[0]}' of &{problem.raw.name} is now "
                               f"{renamed[missing[0]]}")
        if missing and clean:   # a clean run of the deck's design has every column its study writes
            raise o.error(key, f"unknown summary column '{missing[0]}' of &{problem.raw.name} "
                               f"(columns: {', '.join(frame.columns)})")
        if missing:             # e.g. a buckled rod has no strain peaks: checked design by design
            continue
        try:
            v = np.asarray(e.evaluate(frame))
            if key in ("minimize", "maximize") and v.dtype.kind not in "biuf":
                v.astype(np.float64)
        except (expr.ExprError, TypeError, ValueError) as exc:
            raise o.error(key, f"cannot be evaluated on the study's summary: {exc}") from None


def base_value(problem: Problem, v) -> float:
    """The deck's own value of variable ``v``."""
    val = problem.base[v.key]
    if isinstance(val, list):
        val = val[(v.index or 1) - 1]
    return float(val)


@blas.one_thread()
def optimize(deck: Deck | str | Path, outdir: Path | None = None, formats: list[str] | None = None,
             plot: bool | str = False, jobs: int | None = None, resume: bool = False,
             scheduler: Any = None) -> OptimizeOutcome:
    """Run an optimisation deck: a study group and an ``&optimize`` group.

    Parameters
    ----------
    deck : Deck, str or path-like
        The deck, or its file.
    outdir : path-like, optional
        Where to write the outputs (``<stem>.out``, the optimum's deck and run, the history);
        None writes nothing.
    formats : list of str, optional
        Tidy table formats: ``'csv'``, ``'parquet'``.
    plot : bool, default False
        Write the figures.
    jobs : int, optional
        Worker processes for the design evaluations; default all cores.
    resume : bool, default False
        Reuse the evaluation journal in ``outdir`` (verified, never believed).
    scheduler : str or dask.distributed.Client, optional
        A Dask scheduler address or client (from the command line or Dask's configuration,
        never from the deck): each batch of designs is spread over its workers.

    Returns
    -------
    OptimizeOutcome
        ``x`` (the best feasible design in the variables' deck units), ``fun`` (the
        objective, in its expression's units), ``success``, ``status``, ``nit``, ``nfev``,
        the constraints at ``x`` and the files written.

    Raises
    ------
    DeckError
        Bad input, before anything is computed or written.
    """
    if not isinstance(deck, Deck):
        deck = read_deck(deck)
    problem = problem_of(deck)
    _probe(problem)
    formats = list(formats or [])
    stem = None if outdir is None else output_stem(outdir, deck.path, _suffixes(formats, plot))
    journal = None if stem is None else journal_file.journal_path(stem)
    found = journal_file.read(problem, stem) if (resume and stem is not None) else journal_file.Resumed()
    if journal is not None and journal.exists() and not resume:
        journal.unlink()
    njobs = jobs if jobs is not None else problem.opts.jobs
    history: list[HistoryRow] = []
    if scheduler is None:
        from driver.sweep import configured_scheduler
        scheduler = configured_scheduler() or None
    with Evaluator(problem, njobs, journal, found.rows, scheduler) as ev:
        ev.resume_note = found.note()
        mres = run_method(ev, history)
    best = mres.best if mres.best is not None else (ev.best() if o_method(problem) in DETERMINISTIC else None)
    if best is None and o_method(problem) not in DETERMINISTIC and mres.starts:
        # no start settled on a feasible design: the best feasible design evaluated, on the lattice
        cand = ev.best()
        best = None if cand is None else ev.evaluate(problem.snap(cand.x)[None, :])[0]
        best = best if best is not None and best.feasible else None
    check, result, params = None, None, None
    if best is not None:
        params = design_params(problem, np.array(best.x))
        result = compute(problem.study, params)
        probe = Evaluator(problem, 1)
        rec = Record(0, best.x, "failed" if result.failure else "ok", result.failure or "", dict(result.summary))
        probe._score([rec])
        check = rec
    outcome = OptimizeOutcome(problem, None if best is None else DesignVector(zip(problem.names, best.x)),
                              None if best is None else best.objective, bool(mres.converged and best is not None),
                              mres.message, len(ev.records), best, check, mres, history, ev, study_result=result)
    if stem is not None:
        with output_set(stem.parent):   # the run's files all together, or none
            outcome.written = _write(outcome, stem, params, formats, plot, njobs)
        if journal is not None and journal.exists():
            journal.unlink()
    return outcome


def _suffixes(formats: list[str], plot: bool | str) -> tuple[str, ...]:
    """What a run appends to the deck's stem, known before it runs (the optimum's figures are not)."""
    return (".out", ".optimum.dat", ".optimum.out", "_history.csv", "_evals.parquet", journal_file.SUFFIX,
            *(s for fmt in formats for s in (f"_evals.{fmt}", f"_history.{fmt}", f".optimum.{fmt}")),
            *(("_convergence.png",) if plot else ()))


def _write(oc: OptimizeOutcome, stem: Path, params, formats: list[str], plot: bool | str, jobs: int) -> list[Path]:
    p, ev = oc.problem, oc.evaluator
    written: list[Path] = []
    files: list[str] = []
    if oc.best is not None:
        opt_stem = stem.with_name(stem.name + ".optimum")
        written.append(write_text(opt_stem.with_suffix(".optimum.dat"),
                                  report.optimum_deck(p, params, oc.best, oc.success)))
        files = [str(Path(opt_stem.name + ".dat"))]
        written += write_outputs(oc.study_result, opt_stem, formats, plot)
    evals = ev.frame()
    evals.insert(1, "base", p.fingerprint())
    journal_file.stamp(evals, p)   # bound to the problem and the code, verified on --resume
    if report.settings_of(p):   # the band behind summary.meets_transmission_band, with the table
        evals.attrs["summary_settings"] = report.settings_of(p)
    hist = report.history_frame(p, oc.history)
    text = report.report_text(p, ev, oc.method, oc.history, oc.best, oc.check, files,
                              ev.jobs, list(oc.study_result.warnings) if oc.study_result is not None else [])
    written.append(write_text(stem.with_name(stem.name + ".out"), text))
    written.append(write_tidy(hist, stem.with_name(stem.name + "_history"), "csv"))
    for fmt in dict.fromkeys(["parquet"] + formats):
        written.append(write_tidy(evals, stem.with_name(stem.name + "_evals"), fmt))
    if "parquet" in formats:
        written.append(write_tidy(hist, stem.with_name(stem.name + "_history"), "parquet"))
    if plot:
        from driver.plotting import save_figure
        fig = report.convergence_figure(p, hist, evals, Path(p.deck.path).stem)
        written.append(save_figure(fig, stem.with_name(stem.name + "_convergence.png"), plot))
    return written


def run_optimize_deck(deck: Deck, outdir: Path, formats: list[str], plot: bool | str, progress: bool = False,
                      jobs: int | None = None, resume: bool = False,
                      scheduler: Any = None, summary_json: bool = False, **_: Any) -> OptimizeOutcome:
    """Run an optimisation deck and write its outputs: the command line's entry.

    Parameters
    ----------
    deck : Deck
        The read deck.
    outdir : pathlib.Path
        Where to write.
    formats : list of str
        Tidy table formats: ``'csv'``, ``'parquet'``.
    plot : bool or str
        Write the figures (``True`` or a figure format: ``'png'``, ``'svg'``, ``'pdf'``).
    progress : bool, default False
        Show a progress bar on the terminal.
    jobs : int, optional
        Worker processes; default all cores.
    resume : bool, default False
        Reuse the evaluation journal in ``outdir``.
    scheduler : str or dask.distributed.Client, optional
        A Dask scheduler address or client.
    summary_json : bool, default False
        Also write ``<stem>.json``.
    **_ : dict
        Options of other engines, ignored.

    Returns
    -------
    OptimizeOutcome
        The outcome, with its warnings, errors and progress notes as data.

    Raises
    ------
    DeckError
        Bad input.
    MissingExtra
        Before running, when pyarrow is missing (the evaluation journal is Parquet) or, with a
        scheduler, Dask.
    """
    require("parquet")
    if scheduler:
        require("dask")
    oc = optimize(deck, outdir, formats, plot, jobs, resume, scheduler or None)
    if summary_json:
        stem = output_stem(outdir, deck.path, (".json",))
        oc.written.append(write_text(stem.with_name(stem.name + ".json"),
                                     json.dumps(oc.to_dict(), indent=1, allow_nan=False) + "\n"))
    if oc.evaluator.resume_note:
        oc.warn(f"{deck.path}: resume: {oc.evaluator.resume_note}")
    if oc.study_result is not None:
        for w in oc.study_result.warnings:
            oc.warn(f"{deck.path}: optimum: {w}")
    if oc.best is not None and oc.x is not None:   # x is the best design's
        word = "optimum" if oc.success else "best design (not converged)"
        oc.notes.append(f"{deck.path}: {word} {p_obj(oc)} after {oc.nfev} designs: "
                        + ", ".join(f"{k} = {v:.6g}" for k, v in oc.x.items()))
    ev = oc.evaluator
    if ev.computed:
        names = {"batch": "batch path", "dask": f"dask {ev.scheduler}", "processes": f"{ev.jobs} processes",
                 "serial": "this process"}
        how = ", ".join(f"{names[r]}: {n}" if len(ev.routes) > 1 else names[r] for r, n in ev.routes.items())
        oc.notes.append(f"{deck.path}: {ev.computed} designs computed ({len(ev.records) - ev.computed} replayed), "
                        f"{1e3 * ev.compute_seconds / ev.computed:.3f} ms per design ({how})")
    if not oc.success:
        oc.error(f"{deck.path}: optimisation did not converge: {oc.message}")
    elif oc.check is not None and oc.study_result is not None and oc.study_result.failure:
        oc.error(f"{deck.path}: the optimum's full run failed: {oc.study_result.failure}")
    if oc.best is not None and oc.check is not None and not oc.check_agrees:
        shown = [f"{v:.6g}" if math.isfinite(v) else "undefined" for v in (oc.check.objective, oc.best.objective)]
        oc.error(f"{deck.path}: the optimum re-run as a complete deck DIFFERS from its evaluation (objective "
                 f"{shown[0]} against {shown[1]}, feasible {oc.check.feasible} against {oc.best.feasible}): the "
                 "evaluation did not compute what the study computes, so no optimum is claimed")
    return oc


def p_obj(oc: OptimizeOutcome) -> str:
    return f"{oc.problem.objective.text} = {oc.fun:.6g}"
