"""Sweeps: a ``&sweep`` group turns a deck into a study over many cases.

    &fourbar  fixed_link = 12, crank = 2, coupler = 15, rocker = 9, omega = 5, step_deg = 20 /
    &sweep
      key1 = 'fourbar.crank',   values1 = 2, 3, 4, 5          ! a list ...
      key2 = 'fourbar.coupler', start2 = 14, stop2 = 16, count2 = 3   ! ... or start/stop/count
      zip  = .false.            ! .false.: full grid; .true.: keys varied together
      keep = 'meets_transmission_band and rocker_swing_deg > 60'   ! optional filter on the summary
      case_outputs = 'all'      ! per-case files for 'all', 'kept' or 'none' of the cases
    /

Every case is a complete deck (the study group with the swept values), validated
and run exactly as a single run would be.  Outputs, for a deck ``<stem>.dat``:

* ``<stem>/case_0001.{dat,out,parquet,json}``: the case deck, its ``.out``, its tidy
  table and its summary (sweeps of more than 1000 cases: in folders of 1000 cases,
  ``<stem>/000001-001000/case_000001.*``);
* ``<stem>.out``: a fixed-format summary table (one row per case) and failed cases;
* ``<stem>_summary.{csv,parquet}``: one row per case (swept keys + headline figures);
* ``<stem>_cases.{csv,parquet}``: the tidy tables of the written cases, with a
  column for every swept key (up to :data:`CASES_TABLE_MAX` written cases and
  :data:`CASES_TABLE_BYTES`);
* ``<stem>.sweep/``: the resume record (:mod:`driver.sweep._store`).

Cases run in worker processes (``--jobs``, default all cores) or on a Dask
cluster (``--scheduler ADDRESS`` or Dask's ``scheduler-address`` configuration; never
the deck: a deck naming a scheduler is refused), in chunks sized so that scheduling
costs little (:mod:`driver.sweep._engine`); results are ordered by case whatever the
scheduling.  ``--resume`` skips cases whose row is in the resume record and whose files
are all there.  A study with a batch path runs its summary-only sweeps on
:mod:`driver.sweep._batch`.

The package: :mod:`~driver.sweep._spec` (the &sweep keys, the grid, cases, validation),
:mod:`~driver.sweep._keep` (the keep filter), :mod:`~driver.sweep._engine` (the per-case
engine: workers and scheduling), :mod:`~driver.sweep._batch` (the batch engine),
:mod:`~driver.sweep._pool` (the local worker pool of both), :mod:`~driver.sweep._store` (case
files and the resume record), :mod:`~driver.sweep._report` (summary tables and text).
"""
from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from driver import _expr as expr
from driver._atomic import refuse_link, remove_stale_temporaries
from driver._deck import Deck, Params, RawGroup, validate
from driver._extras import require
from driver._outcome import HTML, ExitCode, SweepOutcome
from driver._runner import compute, output_stem, study_of
from driver.sweep import _batch as batch_path
from driver.sweep import _engine as engine
from driver.sweep import _store as store
from driver.sweep import _stream as stream
from driver.sweep._engine import Task, auto_chunk, run_task
from driver.sweep._keep import check_keep, keep_columns
from driver.sweep._report import Warnings, summary_frame, summary_settings, sweep_text, write_sweep_files
from driver.sweep._spec import (
    MAX_CASES,
    MAX_KEYS,
    SPEC,
    Case,
    CaseResult,
    build_cases,
    case_count,
    configured_scheduler,
    grid_of,
    validate_sweep,
)

__all__ = ["SPEC", "Case", "build_cases", "run_sweep_deck", "run_task", "auto_chunk", "MAX_KEYS", "MAX_CASES",
           "summary_frame", "case_count", "CASES_TABLE_MAX", "SweepOutcome"]

#: the combined ``<stem>_cases`` tables are written up to this many written cases (above, the
#: cases' own Parquet files are the table: ``pyarrow.dataset.dataset(<stem>/, format="parquet")``)
CASES_TABLE_MAX = 2000
#: ... and up to this many bytes of them in the driver's memory
CASES_TABLE_BYTES = 256 * 2**20
#: the sweep's .out lists every case up to this many cases (above: the kept and failed ones)
TABLE_ALL_MAX = 2000
#: the most failed cases a sweep reports one by one (the others are counted; all are in the .out)
FAILED_SHOWN = 20


def _base_hash(raw: RawGroup) -> str:
    text = json.dumps(raw.values, sort_keys=True, default=str)
    return hashlib.sha256(f"{raw.name}:{text}".encode()).hexdigest()[:16]


def run_sweep_deck(deck: Deck, outdir: Path, formats: list[str], plot: bool | str, progress: bool = False,
                   jobs: int | None = None, scheduler: Any = None, resume: bool = False,
                   notify: Callable[[str], None] | None = None, best: bool = False) -> SweepOutcome:
    """Run a deck with a &sweep group and write its files; print nothing.

    Parameters
    ----------
    deck : Deck
        The read deck: one study group and a ``&sweep`` group.
    outdir : pathlib.Path
        Where to write.
    formats : list of str
        Tidy table formats of the case files: ``'csv'``, ``'parquet'``.
    plot : bool or str
        Write the sweep's figures (``True`` or a figure format: ``'png'``, ``'svg'``, ``'pdf'``).
    progress : bool, default False
        Show a progress bar on stderr.
    jobs : int, optional
        Worker processes; default all cores, 1 runs in this process.
    scheduler : str or dask.distributed.Client, optional
        A Dask scheduler address or client.
    resume : bool, default False
        Reuse the cases a previous run completed (verified, never believed).
    notify : callable, optional
        ``notify(line)`` hears what cannot wait for the outcome: on Ctrl-C, that the queued cases
        are cancelled while the running ones finish (the command line prints it on stderr at
        once). Default: nothing is said, the ``KeyboardInterrupt`` being the news.
    best : bool, default False
        Also run the best case in full (``outcome.best``: what the report page draws).

    Returns
    -------
    SweepOutcome
        Counts, failed cases, warnings as data, files written, wall time (s) and the driver's
        CPU time per phase (s).

    Raises
    ------
    DeckError
        Bad input, before any case runs.
    MissingExtra
        Before running anything, when pyarrow (case files and summaries are Parquet) or, with
        a scheduler, Dask is not installed.
    """
    start_cpu = time.process_time()
    sw = validate(deck.groups["sweep"], SPEC, deck.path)
    require("parquet")
    if scheduler or sw.scheduler:
        require("dask")
    study_raw = {n: g for n, g in deck.groups.items() if n != "sweep"}
    module, base_params = study_of(Deck(deck.path, study_raw))   # the base deck must be valid on its own
    raw = study_raw[base_params.group]
    grid = grid_of(sw, base_params.group, module.spec)
    names = grid.names
    axes = list(zip(grid.names, grid.values))
    batchable = batch_path.batchable(module, names, sw.keep, sw.case_outputs)
    limit = batch_path.MAX_CASES if batchable else MAX_CASES
    if grid.n > limit:
        sizes = " x ".join(f"{len(v)} ({n})" for n, v in axes)
        raise sw.error("key1", f"{grid.n} cases ({sizes}) is beyond the {limit} cases one sweep deck "
                       "may have; split the sweep into several decks or coarsen the grid")
    estimates = validate_sweep(sw, raw, module, grid)
    named = [(k, v) for k, v in [("keep", sw.keep), ("plot_x", sw.plot_x)] + [("plot_y", y) for y in sw.plot_y] if v]
    shown_columns: list[str] | None = None
    if named or sw.summary_columns:   # check the filter and plotted columns on the base deck's summary first
        probe = (module.summarise(base_params) if module.summarise is not None
                 else compute(module, base_params).summary)
        columns = [*names, *probe, "case"]
        kinds = {**expr.kinds_of({n: v[0] for n, v in axes if len(v)}), **expr.kinds_of(probe), "case": "number"}
        for key, text in named:
            try:
                if key == "keep":
                    check_keep(text, columns, kinds)   # one number or logical per case, before any case runs
                    continue
                e = expr.parse(text, columns)
                if text.strip() not in columns:   # a plotted column may hold text
                    e.check_kinds(kinds)
                if not e.names:
                    raise expr.ExprError("reads no column: a plot shows a column or an expression of columns",
                                         text[:60])
            except expr.ExprError as exc:
                raise sw.error(key, f"{exc.message}" + (f" (at '{exc.token}')" if exc.token else "")
                               + ("" if key == "keep" else f"; summary columns: {', '.join(columns)}")) from None
        if sw.summary_columns:
            unknown = [c for c in sw.summary_columns if c not in probe]
            if unknown:
                raise sw.error("summary_columns", f"'{unknown[0]}' is not a summary column of &{base_params.group} "
                               f"(summary columns: {', '.join(probe)})")
            # what the tables show: the columns asked for, and those the filter and the plot read
            read = {n for k, text in named if k != "keep" for n in expr.parse(text, columns).names} | keep_columns(sw.keep)
            shown_columns = [c for c in probe if c in set(sw.summary_columns) | read]
    # every name the sweep gives its files and folders, known before it runs (the longest counts)
    stem_path = output_stem(outdir, deck.path, (".out", ".sweep", "_summary.csv", "_summary.parquet", "_cases.csv",
                                                "_cases.parquet", *(("_summary.png",) if plot else ())))
    scheduler = scheduler or configured_scheduler()
    jobs = jobs or os.cpu_count() or 1
    layout = store.layout_for(stem_path, grid.n)
    case_plot = plot if sw.case_plots else False

    def task_of(indices: list[int], case_outputs: str = sw.case_outputs) -> Task:
        return Task(str(deck.path), raw, grid, indices, layout, sw.keep, case_outputs, formats, case_plot,
                    _base_hash(raw))

    run = _Run(deck, sw, base_params, module, grid, outdir, stem_path.name, layout, task_of, plot, progress,
               jobs, scheduler, resume, start_cpu)
    run.notify = notify
    run.shown_columns = shown_columns
    sig = store.case_signature(raw, names, str(deck.path), sw.keep, sw.case_outputs, formats, case_plot, module)
    if batchable:
        bplan = batch_path.plan(module, raw, str(deck.path), grid, sw.keep, sw.summary_rows,
                                 plotted=[v for k, v in named if k != "keep"], shown=shown_columns)
    else:
        bplan = None
    with store.sweep_lock(outdir, stem_path.name):   # one run at a time writes a sweep's files
        oc = run.batch(bplan, sig) if bplan is not None else run.cases(sig, estimates)
    oc.study, oc.sweep = base_params.group, sw
    if best and oc.summary is not None:
        from driver.sweep._best import attach_best
        summary = oc.summary.to_pandas() if hasattr(oc.summary, "to_pandas") else oc.summary
        attach_best(oc, summary, sw, module, raw, grid)
    return oc


class _CasesTable:
    """The ``<stem>_cases`` tables, built from the written cases' Parquet files as the cases
    arrive (while the workers compute, off the critical path): their Arrow tables and CSV rows,
    up to :data:`CASES_TABLE_MAX` cases."""

    def __init__(self, layout: store.Layout):
        self.layout = layout
        self.pieces: dict[int, tuple[Any, bytes | None]] = {}
        self.nbytes = 0
        self.full = False   # beyond CASES_TABLE_MAX cases or CASES_TABLE_BYTES: no combined table

    def add(self, indices: list[int]) -> None:
        import pyarrow.parquet as pq

        from driver._export import csv_bytes
        for k in indices:
            if self.full:
                return
            t = pq.read_table(self.layout.stem(k).with_suffix(".parquet"))
            try:
                body = csv_bytes(t, header=False)
            except TypeError:
                body = None
            self.pieces[k] = (t, body)
            self.nbytes += t.nbytes + len(body or b"")
            if len(self.pieces) > CASES_TABLE_MAX or self.nbytes > CASES_TABLE_BYTES:
                self.full, self.pieces = True, {}   # the driver's memory stays bounded

    def table(self, written: list[int]) -> Any:
        """The combined table of cases ``written`` (in order): a DataFrame, or an (Arrow table, CSV
        bytes) pair when every case has the same columns; None above CASES_TABLE_MAX cases or
        CASES_TABLE_BYTES."""
        if not written or len(written) > CASES_TABLE_MAX or self.full:
            return None
        self.add([k for k in written if k not in self.pieces])
        if self.full:
            return None
        import pyarrow as pa

        from driver._export import csv_bytes
        parts = [self.pieces[k] for k in written]
        first = parts[0][0].schema
        bodies = [body for _, body in parts if body is not None]
        if len(bodies) == len(parts) and all(t.schema.equals(first, check_metadata=False) for t, _ in parts):
            table = pa.concat_tables([t for t, _ in parts])
            return table, csv_bytes(table.slice(0, 0)) + b"".join(bodies)
        return pd.concat([t.to_pandas() for t, _ in parts], ignore_index=True)


class _Run:
    """One sweep run: the per-case path (:meth:`cases`) or the batch path (:meth:`batch`)."""

    def __init__(self, deck: Deck, sw: Params, base: Params, module, grid, outdir: Path, stem: str,
                 layout: store.Layout, task_of, plot, progress: bool, jobs: int, scheduler: Any,
                 resume: bool, start_cpu: float):
        self.deck, self.sw, self.base, self.module, self.grid = deck, sw, base, module, grid
        self.outdir, self.stem, self.layout, self.task_of = outdir, stem, layout, task_of
        self.plot, self.progress, self.jobs, self.scheduler, self.resume = plot, progress, jobs, scheduler, resume
        self.axes = list(zip(grid.names, grid.values))
        self.shown_columns: list[str] | None = None   # summary_columns given: the columns the tables show
        self.notify: Callable[[str], None] | None = None   # told at once of a Ctrl-C (run_sweep_deck)
        self.start_cpu = start_cpu
        self.outcome = SweepOutcome(deck=str(deck.path), name=stem, outdir=outdir, n_cases=grid.n,
                                    workers=self._where())

    def _where(self) -> str:
        return f"dask {self.scheduler}" if self.scheduler else f"{self.jobs} worker(s)"

    def _check_workers_see(self, writes_files: bool) -> None:
        """On Dask, when workers write case files: they must see this output folder."""
        if not (self.scheduler and writes_files):
            return
        from dask.distributed import Client
        client = self.scheduler if not isinstance(self.scheduler, str) else Client(self.scheduler)
        try:
            engine.check_shared_folder(client, Path(self.layout.root))
        finally:
            if isinstance(self.scheduler, str):
                client.close()

    # ------------------------------------------------------------------ per case
    def _refuse_links(self) -> None:
        """The sweep's own folders (record, cases) are never symbolic links: refused before any
        file is listed, written or removed there (OUTDIR itself may be one)."""
        for p in (self.outdir / f"{self.stem}.sweep", self.outdir / f"{self.stem}.sweep" / "cases",
                  Path(self.layout.root)):
            refuse_link(p)

    def cases(self, signature: str, estimates: dict[int, float]) -> SweepOutcome:
        sw, grid, layout, n = self.sw, self.grid, self.layout, self.grid.n
        names = grid.names
        oc = self.outcome
        self._refuse_links()
        store.clean_temporaries(layout)   # left by a killed earlier run of this deck
        remove_stale_temporaries(self.outdir, self.stem)
        record = store.Record(self.outdir / f"{self.stem}.sweep", signature, n)
        record.start(self.resume)
        done = record.scan(grid, layout) if self.resume else np.zeros(n + 1, dtype=bool)
        n_done = int(done[1:].sum())
        oc.n_resumed = n_done
        if self.resume:
            oc.notes.append(f"resume: {n_done} of {n} cases complete, {n - n_done} to run")
            self._say_redone(record)
        self._check_workers_see(sw.case_outputs != "none" and n_done < n)
        if estimates and len(set(estimates.values())) > 1:   # longest first: the last case to start is short
            order: Any = [i for i in sorted(estimates, key=lambda i: -estimates[i]) if not done[i]]
        else:
            order = (i for i in range(1, n + 1) if not done[i])
        from tqdm import tqdm
        bar = tqdm(total=n, initial=n_done, unit="case", disable=not self.progress, dynamic_ncols=True)
        pieces = _CasesTable(layout)

        def on_result(results: list[CaseResult]) -> None:
            record.append(results, layout)
            bar.update(len(results))
            pieces.add([r.index for r in results if r.files])   # while the workers compute

        t_start, c_start = time.perf_counter(), time.process_time()
        oc.phases["prepare_cpu"] = c_start - self.start_cpu
        try:
            chunk = engine.execute(order, n - n_done, self.task_of, self.jobs, self.scheduler, sw.chunk, on_result,
                                   notify=self.notify)
        finally:
            bar.close()
        elapsed = time.perf_counter() - t_start
        c_end = time.process_time()
        oc.phases.update(run_wall=elapsed, run_cpu=c_end - c_start, chunk=chunk)

        # the tables, from the resume record (memory: the rows shown, not every case's result)
        retain_all = sw.summary_rows == "all" or n <= TABLE_ALL_MAX
        shown: list[CaseResult] = []
        has_files = np.zeros(n + 1, dtype=bool)
        warnings = Warnings()
        n_ok = n_kept = 0
        written: list[int] = []
        for r in record.results():
            has_files[r.index] = bool(r.files)
            if r.files:
                written.append(r.index)
            warnings.add(r)
            n_ok += r.status == ExitCode.OK
            n_kept += bool(r.kept and r.status == ExitCode.OK)
            if retain_all or r.kept or r.status != ExitCode.OK:
                shown.append(r)
        shown.sort(key=lambda r: r.index)
        written.sort()
        frame = summary_frame(shown, names)
        if self.shown_columns is not None:   # summary_columns: the tables show only those (and keep's, plot's)
            fixed = {"case", "status", "kept", "error", *names}
            frame = frame[[c for c in frame.columns if c in fixed or c in set(self.shown_columns)]]
        table = frame if sw.summary_rows == "all" else frame[frame["kept"] | (frame["status"] != "ok")]
        failed = [r for r in shown if r.status != ExitCode.OK]
        text = sweep_text(self.deck, sw, self.base, self.axes, n, frame, n_kept,
                          [(r.index, r.values, r.error) for r in failed], sw.summary_rows)
        cases = pieces.table(written)
        write_sweep_files(self.outdir, self.stem, table, cases, text, self.plot, sw, names, self.module, frame,
                          self._settings())
        oc.summary, oc.text = table, text
        store.remove_stale_case_files(layout, has_files)
        store.clean_temporaries(layout)   # of workers of a killed earlier run that outlived its start
        oc.phases["finish_cpu"] = time.process_time() - c_end
        if cases is None and written:
            old = [self.outdir / f"{self.stem}_cases.{fmt}" for fmt in ("csv", "parquet")]
            for p in old:   # an earlier, smaller run's table would no longer match the cases
                p.unlink(missing_ok=True)
        for text in warnings.lines(self.deck.path, n):
            oc.warn(text)
        oc.n_ok, oc.n_kept, oc.seconds, oc.chunk = n_ok, n_kept, elapsed, chunk
        self._failed([(r.index, r.values, r.error) for r in failed],
                     bad_input=any(r.status == ExitCode.BAD_INPUT for r in failed))
        oc.written += [self.outdir / f"{self.stem}.out",
                       *(self.outdir / f"{self.stem}_summary.{fmt}" for fmt in ("csv", "parquet"))]
        return oc

    def _batch_streamed(self, rows: batch_path.StreamedRows, n: int, elapsed: float, chunk: int) -> bool:
        """The tables of a batch sweep written part by part from the record (:mod:`driver.sweep._stream`),
        on the outcome; False when the parts cannot be streamed (nothing written then)."""
        sw, names, oc = self.sw, self.grid.names, self.outcome
        remove_stale_temporaries(self.outdir, self.stem)
        res = stream.write_streamed(self.outdir, self.stem, rows.paths, self.deck, sw, self.base, self.axes, names, n,
                                    self.plot, self.module, self._settings())
        if res is None:
            return False
        oc.summary = stream.Parts(rows.paths)   # the streamed rows stay in the record's parts
        if n <= 10 * store.SHARD * store.SHARD:
            store.remove_stale_case_files(self.layout, np.zeros(n + 1, dtype=bool))
        oc.n_ok, oc.n_kept, oc.seconds, oc.chunk = n - res.n_failed, res.n_kept, elapsed, chunk
        self._failed(res.failed, n_failed=res.n_failed, bad_input=res.bad_input)
        oc.written += [self.outdir / f"{self.stem}.out",
                       *(self.outdir / f"{self.stem}_summary.{fmt}" for fmt in ("csv", "parquet"))]
        return True

    def _settings(self) -> dict:
        """The base deck's settings the summary columns depend on (recorded with the table)."""
        return summary_settings(self.module, self.base, {name.partition(".")[2] for name, _ in self.axes})

    def _say_redone(self, record: store.Record, what: str = "cases") -> None:
        """One warning when a resume found record parts or case files that failed their
        checksum: how many cases run again, and why."""
        redone = record.redone()
        if not redone and not record.damaged_parts:
            return
        k = sum(redone.values())
        self.outcome.n_redone += k
        why = "; ".join(f"{c} because {w}" for w, c in redone.items())
        parts = (f"{record.damaged_parts} damaged record part(s) dropped" + ("; " if why else "")
                 if record.damaged_parts else "")
        self.outcome.warn(f"{self.deck.path}: resume: {k} {what} redone ({parts}{why}): the record is verified, "
                          "never believed")

    def _failed(self, failed: list[tuple[int, dict, str]], n_failed: int | None = None, bad_input: bool = False,
                most: int = FAILED_SHOWN) -> None:
        """The failed cases on the outcome (``failed`` lists them, or the first ones of ``n_failed``;
        ``bad_input``: some had bad values), and an error message for each of the first ``most``."""
        oc = self.outcome
        oc.failed, oc.n_failed, oc.bad_input = failed, len(failed) if n_failed is None else n_failed, bad_input
        for index, values, error in failed[:most]:
            vals = ", ".join(f"{k} = {v!r}" for k, v in values.items())
            oc.error(f"{self.deck.path}: case {index} ({vals}): {error}")
        if oc.n_failed > most:
            oc.error(f"{self.deck.path}: ... and {oc.n_failed - most} more failed cases (see {self.stem}.out)")

    # ------------------------------------------------------------------ batch path
    def batch(self, bplan, signature: str) -> SweepOutcome:
        """A sweep on the study's batch path (driver.sweep._batch); same outputs as case by case.
        With case_outputs = 'kept' the kept cases then run case by case for their files, with
        their own resume record ``<stem>.sweep/cases/`` (:mod:`driver.sweep._store`)."""
        sw, names, n = self.sw, self.grid.names, bplan.grid.n
        oc = self.outcome
        oc.batch = True
        self._refuse_links()
        t_start, c_start = time.perf_counter(), time.process_time()
        oc.phases["prepare_cpu"] = c_start - self.start_cpu

        def announce(resumed: int, damaged: list[int]) -> None:
            oc.n_resumed = resumed
            if damaged:
                oc.n_redone += sum(damaged)
                oc.warn(f"resume: {sum(damaged)} cases redone: {len(damaged)} record part(s) failed their "
                        "checksum (the record is verified, never believed)")
            if self.resume:
                oc.notes.append(f"resume: {resumed} of {n} cases complete, {n - resumed} to run")

        # rows beyond STREAM_ROWS stay in the record's parts (driver memory flat); not with
        # case_outputs = 'kept', whose kept cases' failures rewrite their rows
        rows, counts, chunk = batch_path.run(bplan, self.outdir / f"{self.stem}.sweep", self.jobs, self.scheduler,
                                             self.resume, self.progress, sw.chunk, announce,
                                             stream_rows=stream.STREAM_ROWS if sw.case_outputs == "none" else 0,
                                             notify=self.notify)
        c_run = time.process_time()
        # the driver's CPU per phase (bench/bench_search.py): merging the chunks, then the tables
        oc.phases.update(run_cpu=c_run - c_start, chunk=chunk, chunks=-(-n // chunk), rows=len(rows))
        elapsed = time.perf_counter() - t_start
        if isinstance(rows, batch_path.StreamedRows):
            if self._batch_streamed(rows, n, elapsed, chunk):
                oc.phases["finish_cpu"] = time.process_time() - c_run
                return oc
            rows = stream.read_columns(rows.paths)   # parts of differing column types: in memory after all
        if rows.empty:
            rows = pd.DataFrame(columns=["case", *names, "status", "kept", "error"])
        cases = None
        has_files = np.zeros(n + 1, dtype=bool) if n <= 10 * store.SHARD * store.SHARD else None
        if sw.case_outputs == "kept" and counts["kept"]:   # the kept cases' own files, case by case
            kept = [int(c) for c in rows.loc[rows["kept"], "case"]]
            record = store.Record(self.outdir / f"{self.stem}.sweep" / "cases", signature, n, base=self.outdir)
            store.clean_temporaries(self.layout)
            record.start(self.resume)
            if self.resume:
                record.scan(self.grid, self.layout)
                self._say_redone(record, "kept cases' files")
            todo = [k for k in kept if not record.complete(k)]
            if self.resume:
                oc.notes.append(f"resume: {len(kept) - len(todo)} of {len(kept)} kept cases' files complete, "
                                f"{len(todo)} to write")
            self._check_workers_see(bool(todo))
            engine.execute(todo, len(todo), self.task_of, self.jobs, self.scheduler, 0,
                           lambda res: record.append(res, self.layout), notify=self.notify)
            wanted = set(kept)
            results = sorted((r for r in record.results() if r.index in wanted), key=lambda r: r.index)
            written = [r.index for r in results if r.files]
            if has_files is not None:
                has_files[written] = True
            cases = _CasesTable(self.layout).table(written)
            for r in results:
                if r.status != ExitCode.OK:
                    cells: list[str | bool | None] = ["failed", False, r.error]
                    rows.loc[rows["case"] == r.index, ["status", "kept", "error"]] = cells
        bad = rows[rows["status"] != "ok"]
        failed = [(int(r["case"]), {k: r[k] for k in names}, r["error"]) for _, r in bad.iterrows()]
        text = sweep_text(self.deck, sw, self.base, self.axes, n, rows, int(rows["kept"].sum()), failed,
                          sw.summary_rows)
        remove_stale_temporaries(self.outdir, self.stem)
        write_sweep_files(self.outdir, self.stem, rows, cases, text, self.plot, sw, names, self.module, rows,
                          self._settings())
        oc.summary, oc.text = rows, text
        if has_files is not None:
            store.remove_stale_case_files(self.layout, has_files)
        oc.phases["finish_cpu"] = time.process_time() - c_run
        oc.n_ok, oc.n_kept, oc.seconds, oc.chunk = n - len(failed), int(rows["kept"].sum()), elapsed, chunk
        self._failed(failed, bad_input=bool((bad["status"] == "bad input").any()))
        oc.written += [self.outdir / f"{self.stem}.out",
                       *(self.outdir / f"{self.stem}_summary.{fmt}" for fmt in ("csv", "parquet"))]
        return oc


def _notebook_html(outcome: SweepOutcome) -> str:
    """The outcome in a notebook: its report page's sections (driver._report_page, which stands
    above this engine: registered here, called when a notebook shows the outcome)."""
    from driver._report_page import outcome_fragment
    return outcome_fragment(outcome)


HTML[SweepOutcome] = _notebook_html
