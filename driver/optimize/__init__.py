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

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from driver import _blas as blas
from driver._atomic import output_set, write_text
from driver._deck import Deck, DeckError, Params
from driver._export import write_tidy
from driver._extras import require
from driver._outcome import HTML, OptimizeOutcome, Optimum
from driver._pydeck import DeckSource, source_deck
from driver._result import Figure
from driver._runner import compute, output_stem, write_outputs
from driver.optimize import _journal as journal_file
from driver.optimize import _report as report
from driver.optimize._evaluate import Evaluator, Record, design_params, rerun_agrees
from driver.optimize._methods import HistoryRow, run_method
from driver.optimize._problem import SPEC, Problem, problem_of

__all__ = ["SPEC", "OptimizeOutcome", "Optimum", "optimize", "run_optimize_deck", "problem_of"]

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


def _probe(problem: Problem) -> None:
    """Run the deck's own design once: every expression must name columns of the study's summary.

    Only a clean run (no failure, no warning) proves a column does not exist; otherwise (a buckled
    rod has no strain peaks) a design whose summary lacks a column is infeasible, with that reason.
    """
    o = problem.opts
    for key, names in [("summary_columns", o.summary_columns),
                       ("minimize" if problem.sense > 0 else "maximize", sorted(problem.objective.names))]:
        refusal = problem.study.renamed_in(names)
        if refusal:
            raise o.error(key, refusal)
    nums = [n for n in range(1, 10) if o[f"constraint{n}"] is not None]
    for n, c in zip(nums, problem.constraints):
        refusal = problem.study.renamed_in(sorted(c.whole.names))
        if refusal:
            raise o.error(f"constraint{n}", refusal)
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
    exprs = [("minimize" if problem.sense > 0 else "maximize", problem.objective)]
    nums = [n for n in range(1, 10) if o[f"constraint{n}"] is not None]
    exprs += [(f"constraint{n}", c.whole) for n, c in zip(nums, problem.constraints)]
    unknown = [c for c in o.summary_columns if c not in frame]
    if unknown and clean:
        raise o.error("summary_columns", f"unknown summary column '{unknown[0]}' of &{problem.raw.name} "
                                         f"(columns: {', '.join(frame.columns)})")
    for key, e in exprs:
        missing = [name for name in sorted(e.names) if name not in frame]
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
def optimize(deck: DeckSource | Deck, outdir: str | os.PathLike | None = None, formats: list[str] | None = None,
             plot: bool | str = False, jobs: int | None = None, resume: bool = False,
             scheduler: Any = None, name: str | None = None) -> OptimizeOutcome:
    """Run an optimisation deck: a study group and an ``&optimize`` group.

    Parameters
    ----------
    deck : str, path-like, dict or Deck
        The deck, as every entry point takes one (``driver.DeckSource``): its file, its text
        (``"&fourbar ... / &optimize ... /"``), a dict of groups ``{"fourbar": {...},
        "optimize": {...}}`` (keys in the deck's units), or a parsed Deck.
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
    name : str, optional
        Output stem; default the deck's file stem, or for a deck's text or a dict its study
        group.

    Returns
    -------
    OptimizeOutcome
        ``x`` (the best feasible design in the variables' deck units), ``fun`` (the
        objective, in its expression's units), ``success``, ``status``, ``nit``, ``nfev``,
        the constraints at ``x`` and the files written.

    Raises
    ------
    DeckError
        Bad input (an unreadable file, a bad key or value, no ``&optimize`` group), before
        anything is computed or written.
    TypeError
        ``deck`` is not a deck source (a number, bytes, ...).
    """
    deck = source_deck(deck, name)
    if "optimize" not in deck.groups or "synthesis" in deck.groups:
        raise DeckError(deck.path, None, None, "an optimisation deck has a study group and an &optimize group"
                        + (" and no &synthesis group" if "synthesis" in deck.groups else
                           f" (found {', '.join('&' + g for g in deck.groups) or 'none'}); run a study deck "
                           "with driver.run"))
    problem = problem_of(deck)
    _probe(problem)
    formats = list(formats or [])
    stem = None if outdir is None else output_stem(Path(outdir), deck.path, _suffixes(formats, plot))
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
    name = Path(deck.path).stem if stem is None else stem.name
    outcome = OptimizeOutcome(problem, None if best is None else DesignVector(zip(problem.names, best.x)),
                              None if best is None else best.objective, bool(mres.converged and best is not None),
                              mres.message, len(ev.records), best, check, mres, history, ev, study_result=result,
                              name=name, check_agrees=best is None or check is None or rerun_agrees(best, check))
    _tables(outcome, params, [] if stem is None else [f"{stem.name}.optimum.dat"])
    if stem is not None:
        with output_set(stem.parent):   # the run's files all together, or none
            outcome.written = _write(outcome, stem, formats, plot)
        if journal is not None and journal.exists():
            journal.unlink()
    return outcome


def _tables(oc: OptimizeOutcome, params: Params | None, files: list[str]) -> None:
    """The outcome's data, as its files hold it: the history and evaluations tables, the report
    text, the optimum (its deck and full run) and the figures (``files``: the optimum deck's
    name, as the report cites it; none when nothing is written)."""
    p, ev = oc.problem, oc.evaluator
    evals = ev.frame()
    evals.insert(1, "base", p.fingerprint())
    journal_file.stamp(evals, p)   # bound to the problem and the code, verified on --resume
    if report.settings_of(p):   # the band behind summary.meets_transmission_band, with the table
        evals.attrs["summary_settings"] = report.settings_of(p)
    hist = report.history_frame(p, oc.history)
    warnings = list(oc.study_result.warnings) if oc.study_result is not None else []
    oc.history_table, oc.evaluations = hist, evals
    oc.text = report.report_text(p, ev, oc.method, oc.history, oc.best, oc.check, files, ev.jobs, warnings)
    if oc.best is not None and oc.x is not None and params is not None:
        oc.optimum = Optimum(dict(oc.x), float(oc.best.objective), oc.constraints, oc.study_result, params,
                             report.optimum_deck(p, params, oc.best, oc.success), oc.success)
    title = Path(p.deck.path).stem
    x = None if oc.x is None else dict(oc.x)
    oc.figures = [Figure("convergence", lambda: report.convergence_figure(p, hist, evals, title)),
                  Figure("designs", lambda: report.designs_figure(p, evals, title, x, oc.fun))]


def _suffixes(formats: list[str], plot: bool | str) -> tuple[str, ...]:
    """What a run appends to the deck's stem, known before it runs (the optimum's figures are not)."""
    return (".out", ".optimum.dat", ".optimum.out", "_history.csv", "_evals.parquet", journal_file.SUFFIX,
            *(s for fmt in formats for s in (f"_evals.{fmt}", f"_history.{fmt}", f".optimum.{fmt}")),
            *(("_convergence.png", "_designs.png") if plot else ()))


def _write(oc: OptimizeOutcome, stem: Path, formats: list[str], plot: bool | str) -> list[Path]:
    """Write the outcome's files: the optimum's deck and run, the report, the tables, the figures."""
    written: list[Path] = []
    if oc.optimum is not None:
        opt_stem = stem.with_name(stem.name + ".optimum")
        written.append(write_text(opt_stem.with_suffix(".optimum.dat"), oc.optimum.deck))
        written += write_outputs(oc.optimum.result, opt_stem, formats, plot)
    assert oc.history_table is not None and oc.evaluations is not None
    written.append(write_text(stem.with_name(stem.name + ".out"), oc.text))
    written.append(write_tidy(oc.history_table, stem.with_name(stem.name + "_history"), "csv"))
    for fmt in dict.fromkeys(["parquet"] + formats):
        written.append(write_tidy(oc.evaluations, stem.with_name(stem.name + "_evals"), fmt))
    if "parquet" in formats:
        written.append(write_tidy(oc.history_table, stem.with_name(stem.name + "_history"), "parquet"))
    if plot:
        from driver.plotting import save_figure
        for fig in oc.figures:
            written.append(save_figure(fig.draw(), stem.with_name(f"{stem.name}_{fig.name}.png"), plot))
    return written


def run_optimize_deck(deck: Deck, outdir: Path, formats: list[str], plot: bool | str, progress: bool = False,
                      jobs: int | None = None, resume: bool = False,
                      scheduler: Any = None, **_: Any) -> OptimizeOutcome:
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


def _notebook_html(outcome: OptimizeOutcome) -> str:
    """The outcome in a notebook: its report page's sections (driver._report_page, which stands
    above this engine: registered here, called when a notebook shows the outcome)."""
    from driver._report_page import outcome_fragment
    return outcome_fragment(outcome)


HTML[OptimizeOutcome] = _notebook_html
