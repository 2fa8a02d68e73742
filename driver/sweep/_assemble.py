"""The last step of a sweep: its chunks' rows assembled into the sweep's own files and its
outcome, which carries the data (the summary table, the ``_cases`` table, the ``.out`` text and,
when asked, the run of the best kept case).

* Case by case: every case's row from the resume record (memory: the rows the tables show,
  not every case's result), the ``_cases`` table built while the cases ran.
* Batch: the rows the chunks returned (and the resumed chunks' parts), or, when they were too
  many to hold, the tables written part by part from the record and the summary a lazy
  :class:`~driver._outcome.StreamedSummary`; with ``case_outputs = 'kept'`` the kept cases'
  own files, whose failures turn their rows failed.
"""
from __future__ import annotations

import time
from collections import Counter
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from driver import _expr as expr
from driver._atomic import remove_stale_temporaries
from driver._deck import validate
from driver._outcome import ExitCode, StreamedSummary, SweepOutcome
from driver._output import best_index
from driver._runner import compute
from driver.sweep._executor import Ran
from driver.sweep._plan import SweepPlan
from driver.sweep._report import (
    TABLE_ALL_MAX,
    CasesTable,
    Warnings,
    plotted_columns,
    read_columns,
    summary_frame,
    sweep_text,
    with_plotted,
    with_settings,
    write_streamed,
    write_sweep_files,
)
from driver.sweep._resume import SHARD, clean_temporaries, remove_stale_case_files
from driver.sweep._spec import CaseResult, case_at, case_raw

__all__ = ["assemble", "FAILED_SHOWN"]

#: the most failed cases a sweep reports one by one (the others are counted; all are in the .out)
FAILED_SHOWN = 20


@dataclass
class Tables:
    """The tables of a sweep before they are written: the ``_summary`` rows (``table``), the
    rows the ``.out`` and the figure show (``frame``), the ``_cases`` table, the ``.out`` text,
    the failed cases and counts, and the cases that wrote files (None: not tracked)."""

    table: pd.DataFrame
    frame: pd.DataFrame
    cases: Any
    text: str
    failed: list[tuple[int, dict, str]]
    n_ok: int
    n_kept: int
    has_files: np.ndarray | None
    bad_input: bool = False


def assemble(plan: SweepPlan, ran: Ran, cases_table: CasesTable, where: str, start_cpu: float) -> SweepOutcome:
    """Write the sweep's tables from what its chunks left (``ran``), and return its outcome:
    counts, failed cases, warnings, the files written, the data, the driver's CPU per phase."""
    c0 = time.process_time()
    main = ran.main
    run_cpu = main.cpu + (ran.kept.cpu if ran.kept else 0.0)
    oc = SweepOutcome(deck=str(plan.deck.path), name=plan.stem, outdir=plan.outdir, n_cases=plan.n,
                      workers=where, batch=plan.batch is not None, chunk=plan.chunk, n_resumed=main.resumed,
                      seconds=main.wall + (ran.kept.wall if ran.kept else 0.0), study=plan.base.group, sweep=plan.sw)
    oc.phases.update(prepare_cpu=c0 - start_cpu - run_cpu, run_wall=oc.seconds, run_cpu=run_cpu, chunk=plan.chunk,
                     chunks=-(-plan.n // plan.chunk), rows=main.n_rows)
    _say_resumed(plan, ran, oc)
    for text in dict.fromkeys([*main.warnings, *(ran.kept.warnings if ran.kept else [])]):
        oc.warn(f"{plan.deck.path}: {text}")
    remove_stale_temporaries(plan.outdir, plan.stem)
    if plan.batch is not None and main.rows is None and _streamed(plan, ran, oc):
        pass   # too many rows to hold: the tables were written part by part from the record
    else:
        tables = _batch_tables(plan, ran, cases_table) if plan.batch is not None else \
            _case_tables(plan, ran, cases_table, oc)
        write_sweep_files(plan.outdir, plan.stem, tables.table, tables.cases, tables.text, plan.plot, plan.sw,
                          plan.names, plan.module, tables.frame, plan.settings)
        _clean(plan, tables.has_files, written=tables.cases is not None)
        oc.n_ok, oc.n_kept = tables.n_ok, tables.n_kept
        _failed(plan, oc, tables.failed, bad_input=tables.bad_input)
        _data(plan, oc, tables)
    oc.written += [plan.outdir / f"{plan.stem}.out",
                   *(plan.outdir / f"{plan.stem}_summary.{fmt}" for fmt in ("csv", "parquet"))]
    _best(plan, oc)
    oc.phases["finish_cpu"] = time.process_time() - c0
    return oc


def _say_resumed(plan: SweepPlan, ran: Ran, oc: SweepOutcome) -> None:
    """The resume notes (how many cases were complete) and the redone warnings, of each record."""
    if ran.resume:
        oc.notes.append(f"resume: {ran.main.resumed} of {plan.n} cases complete, {plan.n - ran.main.resumed} to run")
    _say_redone(plan, oc, ran.main.record.redone, "cases")
    if ran.kept is not None:
        if ran.resume:
            done, k = ran.kept.resumed, len(ran.kept_cases)
            oc.notes.append(f"resume: {done} of {k} kept cases' files complete, {k - done} to write")
        _say_redone(plan, oc, ran.kept.record.redone, "kept cases' files")


def _clean(plan: SweepPlan, has_files: np.ndarray | None, written: bool) -> None:
    """Remove what is no longer the sweep's: case files of cases that write none now (or of
    another layout), stray temporaries of case files, and a ``_cases`` table that no longer
    matches the cases (too many for one table now)."""
    if has_files is not None:
        remove_stale_case_files(plan.layout, has_files)
        clean_temporaries(plan.layout)   # of workers of a killed earlier run that outlived its start
        if not written and has_files.any():
            for fmt in ("csv", "parquet"):
                (plan.outdir / f"{plan.stem}_cases.{fmt}").unlink(missing_ok=True)


# ----------------------------------------------------------------------------- case by case

def _case_tables(plan: SweepPlan, ran: Ran, cases_table: CasesTable, oc: SweepOutcome) -> Tables:
    """The tables of a per-case sweep, from its record (the rows shown, not every result); the
    warnings many cases repeat go on the outcome once each."""
    sw, n = plan.sw, plan.n
    retain_all = sw.summary_rows == "all" or n <= TABLE_ALL_MAX
    shown: list[CaseResult] = []
    has_files = np.zeros(n + 1, dtype=bool)
    warnings = Warnings()
    n_ok = n_kept = 0
    written: list[int] = []
    for r in ran.main.record.results():
        has_files[r.index] = bool(r.files)
        if r.files:
            written.append(r.index)
        warnings.add(r)
        n_ok += r.status == ExitCode.OK
        n_kept += bool(r.kept and r.status == ExitCode.OK)
        if retain_all or r.kept or r.status != ExitCode.OK:
            shown.append(r)
    for line in warnings.lines(plan.deck.path, n):
        oc.warn(line)
    frame = summary_frame(shown, plan.names) if shown else _empty(plan)
    if plan.shown_columns is not None:   # summary_columns: the tables show only those (and keep's, plot's)
        fixed = {"case", "status", "kept", "error", *plan.names}
        frame = frame[[c for c in frame.columns if c in fixed or c in set(plan.shown_columns)]]
    table = frame if sw.summary_rows == "all" else frame[frame["kept"] | (frame["status"] != "ok")]
    failed = [(r.index, r.values, r.error) for r in shown if r.status != ExitCode.OK]
    text = sweep_text(plan.deck, sw, plan.base, plan.axes, n, frame, n_kept, failed, sw.summary_rows)
    return Tables(table, frame, cases_table.table(written), text, failed, n_ok, n_kept, has_files,
                  any(r.status == ExitCode.BAD_INPUT for r in shown))


def _empty(plan: SweepPlan) -> pd.DataFrame:
    return pd.DataFrame(columns=["case", *plan.names, "status", "kept", "error"])


# ----------------------------------------------------------------------------- batch

def _streamed(plan: SweepPlan, ran: Ran, oc: SweepOutcome) -> bool:
    """The tables written part by part from the record, and a lazy summary on the outcome;
    False (nothing written) when the parts' columns differ in type."""
    paths = ran.main.record.paths(with_rows=True)
    res = write_streamed(plan.outdir, plan.stem, paths, plan.deck, plan.sw, plan.base, plan.axes, plan.names, plan.n,
                         plan.plot, plan.module, plan.settings)
    if res is None:
        return False
    _clean(plan, np.zeros(plan.n + 1, dtype=bool) if plan.n <= 10 * SHARD * SHARD else None, written=False)
    oc.n_ok, oc.n_kept = plan.n - res.n_failed, res.n_kept
    _failed(plan, oc, res.failed, n_failed=res.n_failed, bad_input=res.bad_input)
    oc.summary, oc.text = StreamedSummary(paths, res.metadata, res.n_rows), None
    return True


def _batch_tables(plan: SweepPlan, ran: Ran, cases_table: CasesTable) -> Tables:
    """The tables of a batch sweep from its rows in memory (or read from the record's parts);
    the kept cases' failures to write their own files turn their rows failed."""
    n, main = plan.n, ran.main
    rows = main.frame() if main.rows is not None else read_columns(main.record.paths(with_rows=True))
    if rows.empty:
        rows = _empty(plan)
    cases = None
    has_files = np.zeros(n + 1, dtype=bool) if n <= 10 * SHARD * SHARD else None
    if ran.kept is not None:   # the kept cases' own files
        results = list(ran.kept.record.results())
        written = [r.index for r in results if r.files]
        if has_files is not None:
            has_files[written] = True
        cases = cases_table.table(written)
        for r in results:
            if r.status != ExitCode.OK:
                cells: list[str | bool | None] = ["failed", False, r.error]
                rows.loc[rows["case"] == r.index, ["status", "kept", "error"]] = cells
    bad = rows[rows["status"] != "ok"]
    failed = [(int(r["case"]), {k: r[k] for k in plan.names}, r["error"]) for _, r in bad.iterrows()]
    n_kept = int(rows["kept"].sum())
    text = sweep_text(plan.deck, plan.sw, plan.base, plan.axes, n, rows, n_kept, failed, plan.sw.summary_rows)
    return Tables(rows, rows, cases, text, failed, n - len(failed), n_kept, has_files,
                  bool((bad["status"] == "bad input").any()))


# ----------------------------------------------------------------------------- the outcome

def _data(plan: SweepPlan, oc: SweepOutcome, tables: Tables) -> None:
    """The tables on the outcome as they were written (what pandas reads back from them)."""
    import pyarrow as pa
    summary = pa.Table.from_pandas(with_settings(tables.table, plan.settings), preserve_index=False).to_pandas()
    summary.attrs = {"summary_settings": dict(plan.settings)} if plan.settings else {}
    oc.summary = summary
    if isinstance(tables.cases, tuple):   # (Arrow table, its CSV)
        oc.cases = tables.cases[0].to_pandas()
    elif tables.cases is not None:
        oc.cases = pa.Table.from_pandas(tables.cases, preserve_index=False).to_pandas()
    oc.text = tables.text


def _say_redone(plan: SweepPlan, oc: SweepOutcome, redone: Counter[str], what: str) -> None:
    """One warning when a resume found record parts, rows or case files that failed
    verification: how many cases run again, and why."""
    if not redone:
        return
    k = sum(redone.values())
    oc.n_redone += k
    why = "; ".join(f"{c} because {w}" for w, c in redone.items())
    oc.warn(f"{plan.deck.path}: resume: {k} {what} redone ({why}): the record is verified, never believed")


def _failed(plan: SweepPlan, oc: SweepOutcome, failed: list[tuple[int, dict, str]], n_failed: int | None = None,
            bad_input: bool = False) -> None:
    """The failed cases on the outcome (``failed`` lists them, or the first ones of ``n_failed``;
    ``bad_input``: some had bad values), and an error message for each of the first few."""
    oc.failed, oc.n_failed, oc.bad_input = failed, len(failed) if n_failed is None else n_failed, bad_input
    for index, values, error in failed[:FAILED_SHOWN]:
        vals = ", ".join(f"{k} = {v!r}" for k, v in values.items())
        oc.error(f"{plan.deck.path}: case {index} ({vals}): {error}")
    if oc.n_failed > FAILED_SHOWN:
        oc.error(f"{plan.deck.path}: ... and {oc.n_failed - FAILED_SHOWN} more failed cases (see {plan.stem}.out)")


def _best(plan: SweepPlan, oc: SweepOutcome) -> None:
    """The best kept case (:attr:`~driver._outcome.SweepOutcome.best_case`) from the summary in
    memory (a streamed one is read only when the run was asked for), and with ``plan.best``
    its run: the Result the report page shows.  The rule is the design-space maps' (their
    star): the best value of the first plotted column (:func:`~driver.sweep._report.plotted_columns`)
    where the study says which end is better, else the first kept case."""
    summary = oc.summary
    if summary is None or (isinstance(summary, StreamedSummary) and not plan.best):
        return
    if isinstance(summary, StreamedSummary):   # the kept rows, only the columns the rule reads
        frame = summary.kept([c for c in summary.columns if c in _best_reads(plan)])
    else:
        frame = summary[summary["kept"].astype(bool)]
    frame = frame[frame["status"] == "ok"]
    if not len(frame):
        return
    shown = with_plotted(frame, plan.sw)
    wanted = plotted_columns(shown, plan.sw, plan.module)
    metric = wanted[0] if wanted else None
    at = best_index(shown, metric, plan.module.sweep_best.get(metric)) if metric else None
    if at is not None:
        oc.best_case, oc.best_metric = int(shown.loc[at, "case"]), metric
    else:
        oc.best_case = int(shown["case"].iloc[0])
    if plan.best:
        case = case_at(plan.grid, oc.best_case)
        try:
            params = validate(case_raw(plan.cases.raw, case), plan.module.spec, plan.deck.path)
            oc.best = compute(plan.module, params)
            oc.best.name, oc.best.study = f"{plan.stem}_case{oc.best_case}", params.group
        except Exception as exc:   # the report page says so; the sweep itself is complete
            oc.warn(f"{plan.deck.path}: the best case {oc.best_case} could not be run for the report: "
                    f"{exc.__class__.__name__}: {exc}")


def _best_reads(plan: SweepPlan) -> set[str]:
    """The summary columns the best-case rule reads: case, status, kept, the plotted columns
    and the columns their expressions read, the study's ``sweep_plot``."""
    plotted = [t for t in [plan.sw.plot_x, *plan.sw.plot_y] if t]
    return {"case", "status", "kept", *plotted, *plan.module.sweep_plot,
            *(n for t in plotted for n in expr.parse(t).names)}
