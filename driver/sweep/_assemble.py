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
from typing import Any

import numpy as np
import pandas as pd

from driver._atomic import remove_stale_temporaries
from driver._deck import validate
from driver._outcome import ExitCode, StreamedSummary, SweepOutcome
from driver._runner import compute
from driver.sweep._executor import Ran
from driver.sweep._plan import SweepPlan
from driver.sweep._report import (
    TABLE_ALL_MAX,
    CasesTable,
    Warnings,
    read_columns,
    summary_frame,
    sweep_text,
    with_settings,
    write_streamed,
    write_sweep_files,
)
from driver.sweep._resume import SHARD, clean_temporaries, remove_stale_case_files
from driver.sweep._spec import CaseResult, case_at, case_raw

__all__ = ["assemble", "FAILED_SHOWN"]

#: the most failed cases a sweep reports one by one (the others are counted; all are in the .out)
FAILED_SHOWN = 20


def assemble(plan: SweepPlan, ran: Ran, tables: CasesTable, where: str, start_cpu: float) -> SweepOutcome:
    """Write the sweep's tables from what its chunks left (``ran``), and return its outcome:
    counts, failed cases, warnings, the files written, the data, the driver's CPU per phase."""
    c0 = time.process_time()
    main = ran.main
    run_cpu = main.cpu + (ran.kept.cpu if ran.kept else 0.0)
    oc = SweepOutcome(deck=str(plan.deck.path), name=plan.stem, outdir=plan.outdir, n_cases=plan.n,
                      workers=where, batch=plan.batch is not None, chunk=plan.chunk, n_resumed=main.resumed,
                      seconds=main.wall + (ran.kept.wall if ran.kept else 0.0))
    oc.phases.update(prepare_cpu=c0 - start_cpu - run_cpu, run_wall=oc.seconds, run_cpu=run_cpu, chunk=plan.chunk,
                     chunks=-(-plan.n // plan.chunk), rows=main.n_rows)
    if ran.resume:
        oc.notes.append(f"resume: {main.resumed} of {plan.n} cases complete, {plan.n - main.resumed} to run")
    _say_redone(oc, plan, main.record.redone, "cases")
    remove_stale_temporaries(plan.outdir, plan.stem)
    if plan.batch is None:
        _case_tables(plan, ran, tables, oc)
    else:
        _batch_tables(plan, ran, tables, oc)
    oc.written += [plan.outdir / f"{plan.stem}.out",
                   *(plan.outdir / f"{plan.stem}_summary.{fmt}" for fmt in ("csv", "parquet"))]
    _best(plan, oc)
    oc.phases["finish_cpu"] = time.process_time() - c0
    return oc


# ----------------------------------------------------------------------------- case by case

def _case_tables(plan: SweepPlan, ran: Ran, tables: CasesTable, oc: SweepOutcome) -> None:
    """The tables of a per-case sweep, from its record (the rows shown, not every result)."""
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
    frame = summary_frame(shown, plan.names) if shown else _empty(plan)
    if plan.shown_columns is not None:   # summary_columns: the tables show only those (and keep's, plot's)
        fixed = {"case", "status", "kept", "error", *plan.names}
        frame = frame[[c for c in frame.columns if c in fixed or c in set(plan.shown_columns)]]
    table = frame if sw.summary_rows == "all" else frame[frame["kept"] | (frame["status"] != "ok")]
    failed = [(r.index, r.values, r.error) for r in shown if r.status != ExitCode.OK]
    text = sweep_text(plan.deck, sw, plan.base, plan.axes, n, frame, n_kept, failed, sw.summary_rows)
    cases = tables.table(written)
    write_sweep_files(plan.outdir, plan.stem, table, cases, text, plan.plot, sw, plan.names, plan.module, frame,
                      plan.settings())
    remove_stale_case_files(plan.layout, has_files)
    clean_temporaries(plan.layout)   # of workers of a killed earlier run that outlived its start
    if cases is None and written:
        for fmt in ("csv", "parquet"):   # an earlier, smaller run's table would no longer match the cases
            (plan.outdir / f"{plan.stem}_cases.{fmt}").unlink(missing_ok=True)
    for line in warnings.lines(plan.deck.path, n):
        oc.warn(line)
    oc.n_ok, oc.n_kept = n_ok, n_kept
    _failed(plan, oc, failed, bad_input=any(r.status == ExitCode.BAD_INPUT for r in shown))
    _data(plan, oc, table, cases, text)


def _empty(plan: SweepPlan) -> pd.DataFrame:
    return pd.DataFrame(columns=["case", *plan.names, "status", "kept", "error"])


# ----------------------------------------------------------------------------- batch

def _batch_tables(plan: SweepPlan, ran: Ran, tables: CasesTable, oc: SweepOutcome) -> None:
    """The tables of a batch sweep: streamed from the record, or from the rows in memory."""
    sw, n, main = plan.sw, plan.n, ran.main
    if main.rows is None:   # too many rows to hold: the tables written part by part from the record
        paths = main.record.paths(with_rows=True)
        res = write_streamed(plan.outdir, plan.stem, paths, plan.deck, sw, plan.base, plan.axes, plan.names, n,
                             plan.plot, plan.module, plan.settings())
        if res is not None:
            if n <= 10 * SHARD * SHARD:
                remove_stale_case_files(plan.layout, np.zeros(n + 1, dtype=bool))
            oc.n_ok, oc.n_kept = n - res.n_failed, res.n_kept
            _failed(plan, oc, res.failed, n_failed=res.n_failed, bad_input=res.bad_input)
            oc.summary, oc.text = StreamedSummary(paths, res.metadata, res.n_rows), None
            return
        rows = read_columns(paths)   # parts of differing column types: in memory after all
    else:
        rows = main.frame()
    if rows.empty:
        rows = _empty(plan)
    cases = None
    has_files = np.zeros(n + 1, dtype=bool) if n <= 10 * SHARD * SHARD else None
    if ran.kept is not None:   # the kept cases' own files: their failures turn their rows failed
        kept = ran.kept
        if ran.resume:
            done = kept.resumed
            oc.notes.append(f"resume: {done} of {len(ran.kept_cases)} kept cases' files complete, "
                            f"{len(ran.kept_cases) - done} to write")
        _say_redone(oc, plan, kept.record.redone, "kept cases' files")
        results = list(kept.record.results())
        written = [r.index for r in results if r.files]
        if has_files is not None:
            has_files[written] = True
        cases = tables.table(written)
        for r in results:
            if r.status != ExitCode.OK:
                cells: list[str | bool | None] = ["failed", False, r.error]
                rows.loc[rows["case"] == r.index, ["status", "kept", "error"]] = cells
    bad = rows[rows["status"] != "ok"]
    failed = [(int(r["case"]), {k: r[k] for k in plan.names}, r["error"]) for _, r in bad.iterrows()]
    text = sweep_text(plan.deck, sw, plan.base, plan.axes, n, rows, int(rows["kept"].sum()), failed,
                      sw.summary_rows)
    write_sweep_files(plan.outdir, plan.stem, rows, cases, text, plan.plot, sw, plan.names, plan.module, rows,
                      plan.settings())
    if has_files is not None:
        remove_stale_case_files(plan.layout, has_files)
    oc.n_ok, oc.n_kept = n - len(failed), int(rows["kept"].sum())
    _failed(plan, oc, failed, bad_input=bool((bad["status"] == "bad input").any()))
    _data(plan, oc, rows, cases, text)


# ----------------------------------------------------------------------------- the outcome

def _data(plan: SweepPlan, oc: SweepOutcome, table: pd.DataFrame, cases: Any, text: str) -> None:
    """The tables on the outcome as they were written (what pandas reads back from them)."""
    import pyarrow as pa
    settings = plan.settings()
    summary = pa.Table.from_pandas(with_settings(table, settings), preserve_index=False).to_pandas()
    summary.attrs = {"summary_settings": dict(settings)} if settings else {}
    oc.summary = summary
    if isinstance(cases, tuple):   # (Arrow table, its CSV)
        oc.cases = cases[0].to_pandas()
    elif cases is not None:
        oc.cases = pa.Table.from_pandas(cases, preserve_index=False).to_pandas()
    oc.text = text


def _say_redone(oc: SweepOutcome, plan: SweepPlan, redone: Counter[str], what: str) -> None:
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
    its run: the Result the report page shows."""
    streamed = isinstance(oc.summary, StreamedSummary)
    if oc.summary is None or (streamed and not plan.best):
        return
    columns = list(oc.summary.columns)
    metric = _metric(plan, oc.summary, columns)
    if streamed:
        assert isinstance(oc.summary, StreamedSummary)
        frame = oc.summary.kept(["case", "status", *([metric] if metric else [])])
    else:
        assert isinstance(oc.summary, pd.DataFrame)
        frame = oc.summary[oc.summary["kept"].astype(bool)]
    frame = frame[frame["status"] == "ok"]
    if not len(frame):
        return
    sense = plan.module.sweep_best.get(metric) if metric else None
    values = pd.to_numeric(frame[metric], errors="coerce") if sense in ("min", "max") else None
    if values is not None and values.notna().any():
        at = int(np.argmax(values.fillna(-np.inf)) if sense == "max" else np.argmin(values.fillna(np.inf)))
        oc.best_case, oc.best_metric = int(frame["case"].iloc[at]), metric
    else:
        oc.best_case = int(frame["case"].iloc[0])
    if plan.best:
        case = case_at(plan.grid, oc.best_case)
        try:
            params = validate(case_raw(plan.cases.raw, case), plan.module.spec, plan.deck.path)
            oc.best = compute(plan.module, params)
            oc.best.name, oc.best.study = f"{plan.stem}_case{oc.best_case}", params.group
        except Exception as exc:   # the report page says so; the sweep itself is complete
            oc.warn(f"{plan.deck.path}: the best case {oc.best_case} could not be run for the report: "
                    f"{exc.__class__.__name__}: {exc}")


def _metric(plan: SweepPlan, summary: Any, columns: list[str]) -> str | None:
    """The summary column the best case is judged by: the first plotted one (``plot_y``), else
    the study's ``sweep_plot`` columns, else the first numeric one (the report page's maps)."""
    if isinstance(summary, StreamedSummary):
        import pyarrow as pa
        import pyarrow.parquet as pq
        schema = pq.read_schema(summary.paths[0]) if summary.paths else pa.schema([])
        numeric_type = {f.name: pa.types.is_integer(f.type) or pa.types.is_floating(f.type) for f in schema}
        is_number = lambda c: numeric_type.get(c, False)
    else:
        is_number = lambda c: (pd.api.types.is_numeric_dtype(summary[c])
                               and not pd.api.types.is_bool_dtype(summary[c]))
    keys = set(plan.names)
    numeric = [c for c in columns if c not in keys and c not in ("case", "kept") and is_number(c)]
    wanted = [y for y in plan.sw.plot_y if y in numeric] or [c for c in plan.module.sweep_plot if c in numeric][:2] \
        or numeric[:1]
    return wanted[0] if wanted else None
