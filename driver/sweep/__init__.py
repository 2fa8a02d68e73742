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
* ``<stem>.sweep/``: the resume record (:mod:`driver.sweep._resume`).

Cases run in this process (``-j 1``), in worker processes (``--jobs``, default all cores) or
on a Dask cluster (``--scheduler ADDRESS`` or Dask's ``scheduler-address`` configuration;
never the deck: a deck naming a scheduler is refused), in chunks whose size depends on the
number of cases only; results are ordered by case whatever the scheduling.  ``--resume``
skips what the resume record holds, verified.  A study with a batch path runs its
summary-only sweeps a chunk of cases per kernel call.

:func:`run_sweep_deck` reads as the package is built, one module a step:

1. :mod:`~driver.sweep._plan`: everything decided before a case runs (validation, the files'
   names, the batch path or case by case, the chunk policy);
2. :mod:`~driver.sweep._executor`: the one executor (this process, a local pool or Dask; one
   crash, Ctrl-C and back-pressure policy) running the chunk functions of
   :mod:`~driver.sweep._chunks` into the resume record of :mod:`~driver.sweep._resume`;
3. :mod:`~driver.sweep._assemble`: the tables (:mod:`~driver.sweep._report`) and the outcome,
   which carries the data.

Beside them: :mod:`~driver.sweep._spec` (the &sweep keys, the grid, cases, validation),
:mod:`~driver.sweep._keep` (the keep filter).  The ``--json`` record of a sweep is built from
its outcome by :mod:`driver._record`.
"""
from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from driver._deck import Deck
from driver._outcome import HTML, StreamedSummary, SweepOutcome
from driver.sweep._assemble import assemble
from driver.sweep._executor import open_workers, run_chunks
from driver.sweep._plan import chunk_size, plan_sweep
from driver.sweep._report import CASES_TABLE_MAX, CasesTable, summary_frame
from driver.sweep._resume import sweep_lock
from driver.sweep._spec import MAX_CASES, MAX_KEYS, SPEC, Case, build_cases, case_count, configured_scheduler

__all__ = ["SPEC", "Case", "build_cases", "run_sweep_deck", "chunk_size", "MAX_KEYS", "MAX_CASES", "summary_frame",
           "case_count", "CASES_TABLE_MAX", "SweepOutcome", "StreamedSummary"]


def run_sweep_deck(deck: Deck, outdir: Path, formats: list[str], plot: bool | str, progress: bool = False,
                   jobs: int | None = None, scheduler: Any = None, resume: bool = False,
                   notify: Callable[[str], None] | None = None, *, best: bool = False,
                   stream: bool = True) -> SweepOutcome:
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
        Also run the best kept case (``outcome.best``: its Result, for the report page).
    stream : bool, default True
        Let a batch sweep with too many rows to hold write its tables part by part (its
        summary then a lazy :class:`~driver._outcome.StreamedSummary`); False holds every row.

    Returns
    -------
    SweepOutcome
        Counts, failed cases, warnings as data, files written, wall time (s), the driver's CPU
        time per phase (s), and the data: ``summary``, ``cases``, ``text``, ``best_case``
        (and with ``best`` its Result, ``best``).

    Raises
    ------
    DeckError
        Bad input, before any case runs.
    MissingExtra
        Before running anything, when pyarrow (case files and summaries are Parquet) or, with
        a scheduler, Dask is not installed.
    """
    start_cpu = time.process_time()
    plan = plan_sweep(deck, Path(outdir), formats, plot, scheduler=scheduler, best=best, stream=stream)
    with sweep_lock(plan.outdir, plan.stem), \
            open_workers(jobs, scheduler or configured_scheduler(), notify) as workers:   # one run writes a sweep
        tables = CasesTable(plan.layout)
        ran = run_chunks(plan, workers, resume=resume, progress=progress, on_chunk=tables.add_chunk)
        return assemble(plan, ran, tables, workers.where, start_cpu)


def _notebook_html(outcome: SweepOutcome) -> str:
    """The outcome in a notebook: its report page's sections (driver._report_page, which stands
    above this engine: registered here, called when a notebook shows the outcome)."""
    from driver._report_page import outcome_fragment
    return outcome_fragment(outcome)


HTML[SweepOutcome] = _notebook_html
