"""The two chunk functions of a sweep, with one signature: ``fn(work, span) -> ChunkResult``.

* :func:`batch_rows` (work: a :class:`BatchPlan`): the summary rows of a chunk of cases in one
  call of the study's batch summary; the cases are never listed, their swept values are
  computed from the grid (product order, or zipped) in the worker.  A case with bad values
  (found per value and per combination of coupled keys when the plan was made) is a row with
  status 'bad input'.  With a filter and ``summary_rows = 'kept'`` in two steps: the columns
  the filter reads for every case, then the columns the tables show for the kept cases only.
* :func:`case_runs` (work: a :class:`CaseTask`): every case a complete deck, validated and run
  through the runner exactly as a single run, its files written (all cases, or the kept ones:
  deck, ``.out``, tidy Parquet table, JSON summary; all or none); one record row per case.

A :class:`Span` is a chunk of the sweep's chunk layout (its positions in the sequence of
cases) and the case numbers to compute there (all of them, or part: a resumed chunk's cases
left to run, or a half of a chunk whose worker died).  When the span names the record's
folder and covers its whole chunk, the worker writes the chunk's part of the resume record
itself (:func:`driver.sweep._resume.write_part`): the driver only merges what returns.

Each kind also says what a case whose worker died is (:func:`died`) and how the results of
parts of a chunk merge (:func:`merge`); :mod:`driver.sweep._executor` runs either kind alike.
"""
from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from driver._atomic import file_digest, output_set, own_folder, write_text
from driver._deck import DeckError, Params, RawGroup, validate
from driver._export import write_tidy
from driver._outcome import ExitCode
from driver._runner import compute, write_outputs
from driver._study import load_study
from driver._warnings import caught
from driver.sweep._keep import keep_mask
from driver.sweep._resume import Layout, json_default, write_part
from driver.sweep._spec import Case, CaseResult, Grid, case_deck_text, case_raw, iter_cases

__all__ = ["Span", "ChunkResult", "CaseTask", "BatchPlan", "case_runs", "batch_rows", "died", "merge", "run_chunk"]


@dataclass(frozen=True)
class Span:
    """A chunk of the layout (positions ``start``..``stop``-1 of the sweep's sequence of cases)
    and the case numbers (from 1) to compute there; ``part``: the record's folder when the
    worker writes the chunk's part ('' : the driver does)."""

    start: int
    stop: int
    cases: Sequence[int]
    part: str = ""

    def halves(self) -> tuple[Span, Span]:
        """The span's cases in two halves (whose worker writes no part)."""
        half = len(self.cases) // 2
        return replace(self, cases=self.cases[:half], part=""), replace(self, cases=self.cases[half:], part="")


@dataclass
class ChunkResult:
    """What a chunk function returns: the record rows of the cases it computed (a DataFrame of
    summary rows for a batch chunk, an Arrow table of case rows for a per-case chunk), counts,
    wall time [s], and the part the worker wrote ('' : none)."""

    start: int
    stop: int
    rows: Any
    n_ok: int = 0
    n_kept: int = 0
    n_failed: int = 0
    seconds: float = 0.0
    path: str = ""
    #: what a library warned while the chunk ran, in words (:mod:`driver._warnings`)
    warnings: tuple[str, ...] = ()

    @property
    def counts(self) -> dict[str, int]:
        return {"n_ok": self.n_ok, "n_kept": self.n_kept, "n_failed": self.n_failed}


def _write(res: ChunkResult, kind: str, signature: str, span: Span) -> ChunkResult:
    """The worker writes the chunk's part when the span asks it to (it covers the whole chunk)."""
    if span.part and len(span.cases) == span.stop - span.start:
        res.path = str(write_part(Path(span.part), res.rows, {"signature": signature, "kind": kind,
                                                              "start": span.start, "stop": span.stop, **res.counts}))
    return res


# ----------------------------------------------------------------------------- per-case runs

@dataclass
class CaseTask:
    """A per-case chunk's work (picklable: plain data only)."""

    deck_path: str
    raw: RawGroup
    grid: Grid
    layout: Layout
    keep: str
    case_outputs: str
    formats: list[str]
    plot: bool | str            #: the cases' own figures (only with --plot and case_plots)
    base_hash: str
    signature: str = ""
    kind = "cases"


def _kept_many(keep: str, results: list[CaseResult]) -> list[bool]:
    """The keep filter on a chunk of cases at once (vectorised over the chunk)."""
    ok = [r.status == ExitCode.OK for r in results]
    if not keep or not results:
        return ok
    rows = pd.DataFrame([{**r.values, **r.summary} for r in results])
    return [o and bool(k) for o, k in zip(ok, keep_mask(keep, rows))]


def compute_case(task: CaseTask, case: Case, module: Any) -> tuple[CaseResult, Any, Params | None]:
    """Validate and run (or only summarise) one case; never raises for a case failure."""
    t0, c0 = time.perf_counter(), time.process_time()
    res = CaseResult(case.index, case.values)
    result, params = None, None
    try:
        params = validate(case_raw(task.raw, case), module.spec, task.deck_path)
        full = task.case_outputs == "all" or (task.case_outputs == "kept" and not task.keep)
        if full or module.summarise is None:
            result = compute(module, params)
            res.summary = dict(result.summary)
            if result.failure and not result.design_failure:   # a design's own answer is no failed case
                res.status, res.error = ExitCode.FAILED, result.failure
        else:
            res.summary = dict(module.summarise(params))
    except DeckError as exc:   # bad input is refused before a sweep runs (validate_sweep): a case
        res.status, res.error = ExitCode.FAILED, f"bad input: {exc}"   # failing here fails, the others go on
    except Exception as exc:  # a case that fails is reported, the others go on
        res.status, res.error = ExitCode.FAILED, f"{exc.__class__.__name__}: {exc}"
    res.seconds, res.cpu = time.perf_counter() - t0, time.process_time() - c0
    return res, result, params


def _write_case(task: CaseTask, case: Case, res: CaseResult, result: Any, params: Params, module: Any) -> None:
    """Per-case files: deck, .out (+ extras, figures), tidy parquet, json summary; all or none."""
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        if result is None:
            result = compute(module, params)
            if result.failure and not result.design_failure:
                res.status, res.error = ExitCode.FAILED, result.failure
        res.warnings = list(result.warnings)
        stem = task.layout.stem(case.index)
        tidy = result.tidy.copy()
        for name, v in reversed(case.values.items()):
            tidy.insert(0, name, v)
        record = {"index": case.index, "values": case.values, "base": task.base_hash,
                  "status": res.status, "error": res.error, "summary": res.summary,
                  "kept": res.kept, "warnings": res.warnings}
        own_folder(stem.parent, Path(task.layout.root).parent)   # the case folders: made here, never links
        with output_set(stem.parent):   # the case's files together, or none
            written = [write_text(stem.with_suffix(".dat"),
                                  case_deck_text(task.raw.name, params, case, Path(task.deck_path)))]
            written += write_outputs(result, stem, [f for f in task.formats if f != "parquet"], task.plot, clean=False)
            written.append(write_tidy(tidy, stem, "parquet"))
            written.append(write_text(stem.with_suffix(".json"), json.dumps(record, default=json_default, indent=1)))
        res.files = sorted({Path(os.path.relpath(p, task.layout.root)).as_posix() for p in written})
        res.written = True
    except Exception as exc:
        res.status, res.error, res.kept = ExitCode.FAILED, f"{exc.__class__.__name__}: {exc}", False
    res.seconds += time.perf_counter() - t0
    res.cpu += time.process_time() - c0


def _case_results(task: CaseTask, cases: list[Case]) -> list[CaseResult]:
    module = load_study(task.raw.name)
    writable = lambda res, result: result is not None or res.status == ExitCode.OK
    if task.case_outputs == "all":
        # write each case as soon as it is computed: an interrupt loses at most one case
        results = []
        for c in cases:
            res, result, params = compute_case(task, c, module)
            res.kept = _kept_many(task.keep, [res])[0]
            if params is not None and writable(res, result):
                _write_case(task, c, res, result, params, module)
            results.append(res)
        return results
    computed = [compute_case(task, c, module) for c in cases]
    results = [r for r, _, _ in computed]
    for r, k in zip(results, _kept_many(task.keep, results)):
        r.kept = k
    if task.case_outputs == "kept":
        for case, (res, result, params) in zip(cases, computed):
            if res.kept and params is not None and writable(res, result):
                _write_case(task, case, res, result, params, module)
    return results


#: the per-case record's row: status and kept as the tables show them, values and files as JSON,
#: the digest of each file written (verified on resume), times, and the case's own record
_STATUS = {ExitCode.OK: "ok", ExitCode.FAILED: "failed", ExitCode.BAD_INPUT: "bad input"}


def case_table(results: list[CaseResult], layout: Layout) -> Any:
    """The per-case record rows of ``results`` (an Arrow table; digests of the files as written)."""
    import pyarrow as pa
    root = Path(layout.root)
    return pa.table({
        "case": pa.array([r.index for r in results], pa.int64()),
        "status": pa.array([_STATUS.get(r.status, "failed") for r in results], pa.string()),
        "kept": pa.array([bool(r.kept and r.status == ExitCode.OK) for r in results], pa.bool_()),
        "values": pa.array([json.dumps(r.values, default=json_default) for r in results], pa.string()),
        "files": pa.array([json.dumps(r.files) for r in results], pa.string()),
        "digests": pa.array([json.dumps([file_digest(root / f) for f in r.files]) for r in results], pa.string()),
        "seconds": pa.array([float(r.seconds) for r in results], pa.float64()),
        "cpu": pa.array([float(r.cpu) for r in results], pa.float64()),
        "record": pa.array([json.dumps({"status": r.status, "error": r.error, "summary": r.summary,
                                        "warnings": r.warnings}, default=json_default) for r in results], pa.string()),
    })


def _case_chunk(span: Span, results: list[CaseResult], layout: Layout, seconds: float) -> ChunkResult:
    ok = [r.status == ExitCode.OK for r in results]
    return ChunkResult(span.start, span.stop, case_table(results, layout), sum(ok),
                       sum(o and bool(r.kept) for o, r in zip(ok, results)), len(ok) - sum(ok), seconds)


def case_runs(task: CaseTask, span: Span) -> ChunkResult:
    """Run a chunk of cases (the per-case chunk function): the unit of work of a worker.

    Parameters
    ----------
    task : CaseTask
        The cases' common work (plain, picklable data: the deck's study group, the grid).
    span : Span
        The chunk and the case numbers to run.

    Returns
    -------
    ChunkResult
        One record row per case, in order: status, kept, values, the files written and their
        digests, the case's wall and CPU time (s), and its summary, error and warnings.
    """
    t0 = time.perf_counter()
    results = _case_results(task, list(iter_cases(task.grid, span.cases)))
    return _write(_case_chunk(span, results, task.layout, time.perf_counter() - t0), task.kind, task.signature, span)


# ----------------------------------------------------------------------------- batch rows

@dataclass
class BatchPlan:
    """A batch chunk's work: everything a worker needs for any chunk (plain data, picklable)."""

    deck_path: str
    raw: RawGroup
    grid: Grid
    keep: str
    rows: str                                   # 'all' or 'kept'
    single_errors: dict[str, dict[int, str]]    # swept key -> {value index: error}
    coupled: list[int]                          # axes validated together
    coupled_errors: dict[tuple, str]            # value-index tuple of the coupled axes -> error
    signature: str = ""
    #: summary columns computed for every case (those the filter reads); None: all
    filter_columns: list[str] | None = None
    #: summary columns of the rows the tables show (kept rows with rows = 'kept'); None: all
    shown_columns: list[str] | None = None
    kind = "batch"


def _summaries(module: Any, base: Params, cols: dict[str, np.ndarray], rows: np.ndarray, wanted: list[str] | None,
               bad: np.ndarray | None) -> pd.DataFrame:
    """The study's batch summary of cases ``rows`` (indices into ``cols``; ``bad[rows]`` True
    where the case is bad input: a row of None), columns ``wanted`` (None: all)."""
    good = rows if bad is None else rows[~bad[rows]]
    sub = {k.partition(".")[2]: v[good] for k, v in cols.items()}
    summ = module.batch.fn(base, sub) if wanted is None else module.batch.fn(base, sub, wanted=wanted)
    if bad is not None and bad[rows].any():
        summ = summ.astype(object)
        full = pd.DataFrame(None, index=range(len(rows)), columns=summ.columns, dtype=object)
        full.iloc[np.flatnonzero(~bad[rows])] = summ.to_numpy()
        summ = full
    return summ


def _bad_input(p: BatchPlan, idx: list[np.ndarray], n: int) -> tuple[np.ndarray, np.ndarray]:
    """(bad, error) per case: bad input found per value and per combination of coupled keys."""
    bad = np.zeros(n, dtype=bool)
    err = np.full(n, "", dtype=object)
    for i, name in enumerate(p.grid.names):
        for j, msg in p.single_errors.get(name, {}).items():
            hit = idx[i] == j
            err[hit & ~bad] = msg
            bad |= hit
    if p.coupled_errors:
        for k, key in enumerate(zip(*(idx[i] for i in p.coupled))):
            coupled_msg = p.coupled_errors.get(tuple(int(x) for x in key))
            if coupled_msg and not bad[k]:
                err[k], bad[k] = coupled_msg, True
    return bad, err


def batch_rows(p: BatchPlan, span: Span) -> ChunkResult:
    """Summaries of the cases of ``span`` (the batch chunk function): the unit of work of a
    worker; with ``span.part`` the worker also writes the chunk's part of the resume record
    (the driver then only merges the rows it returns: the kept and failed ones with
    ``rows = 'kept'``).

    With a filter and ``rows = 'kept'`` in two steps: the columns the filter reads for every
    case (``p.filter_columns``), then the columns the tables show (``p.shown_columns``) for the
    kept cases only; so a column nobody asks for is never computed, and the kept rows hold
    the same values as a single summary of every column would give."""
    t0 = time.perf_counter()
    module = load_study(p.raw.name)
    if module is None:   # a plan is only made for a registered study (batch_plan() read its spec)
        raise LookupError(f"no registered study &{p.raw.name}")
    positions = np.asarray(span.cases, dtype=np.int64) - 1
    n = len(positions)
    cols = p.grid.columns_at(positions)
    bad, err = _bad_input(p, p.grid.indices_at(positions), n)
    case = positions + 1
    base = validate(p.raw, module.spec, p.deck_path)
    every = np.arange(n)
    two_step = bool(p.keep) and p.rows == "kept" and p.filter_columns is not None
    if two_step and not bad.any():   # the common case: the filter on plain arrays, no full frame
        first = _summaries(module, base, cols, every, p.filter_columns, None)
        mask = keep_mask(p.keep, {"case": case, **cols, **{c: first[c].to_numpy() for c in first.columns}})
        shown = np.flatnonzero(mask)
        out = _frame(case, cols, bad, err, _summaries(module, base, cols, shown, p.shown_columns, None), shown)
        out["kept"] = True
        res = ChunkResult(span.start, span.stop, out, n, len(shown), 0)
    else:
        if two_step:
            first = _summaries(module, base, cols, every, p.filter_columns, bad)
        else:
            wanted = None if p.shown_columns is None else list(dict.fromkeys([*(p.filter_columns or []),
                                                                              *p.shown_columns]))
            first = _summaries(module, base, cols, every, wanted, bad)
        frame = _frame(case, cols, bad, err, first)
        mask = ~bad
        if p.keep:
            mask &= keep_mask(p.keep, frame)
        frame["kept"] = mask
        res = ChunkResult(span.start, span.stop, frame, int((~bad).sum()), int(mask.sum()), int(bad.sum()))
        if p.rows == "kept":
            shown = np.flatnonzero(mask | bad)
            if two_step:   # the shown rows' columns, for those rows only
                out = _frame(case, cols, bad, err, _summaries(module, base, cols, shown, p.shown_columns, bad), shown)
                out["kept"] = mask[shown]
                res.rows = out
            else:
                res.rows = frame.iloc[shown].reset_index(drop=True)
        elif p.shown_columns is not None:   # the filter's columns that are not shown go
            hidden = set(p.filter_columns or ()) - set(p.shown_columns)
            res.rows = frame[[c for c in frame.columns if c not in hidden]]
    res.seconds = time.perf_counter() - t0
    return _write(res, p.kind, p.signature, span)


def _frame(case: np.ndarray, cols: dict[str, np.ndarray], bad: np.ndarray, err: np.ndarray,
           summ: pd.DataFrame, rows: np.ndarray | None = None) -> pd.DataFrame:
    """The rows of a chunk (all, or ``rows``): case, swept values, status, kept, summary, error."""
    pick = (lambda a: a) if rows is None else (lambda a: a[rows])
    frame = pd.DataFrame({"case": pick(case), **{k: pick(v) for k, v in cols.items()}})
    frame["status"] = np.where(pick(bad), "bad input", "ok").astype(object)
    frame["kept"] = False
    summ.index = frame.index
    frame = pd.concat([frame, summ], axis=1)
    frame["error"] = pick(err)
    return frame


# ----------------------------------------------------------------------------- either kind

#: the chunk function of each kind of work
CHUNK_FUNCTIONS: dict[str, Callable[[Any, Span], ChunkResult]] = {"cases": case_runs, "batch": batch_rows}


def run_chunk(work: Any, span: Span) -> ChunkResult:
    """Run ``span`` with the chunk function of ``work``'s kind (what a worker is sent); what a
    library warned meanwhile comes back in words with the result, never on a worker's stderr."""
    with caught() as said:
        res = CHUNK_FUNCTIONS[work.kind](work, span)
    res.warnings = tuple(dict.fromkeys((*res.warnings, *said)))
    return res


def died(work: Any, span: Span, reason: str) -> ChunkResult:
    """The cases of ``span`` whose worker died: failed, with their values and ``reason``."""
    if work.kind == "cases":
        results = [CaseResult(c.index, c.values, ExitCode.FAILED, reason, kept=False)
                   for c in iter_cases(work.grid, span.cases)]
        return _case_chunk(span, results, work.layout, 0.0)
    positions = np.asarray(span.cases, dtype=np.int64) - 1
    frame = pd.DataFrame({"case": positions + 1, **work.grid.columns_at(positions)})
    frame["status"] = "failed"
    frame["kept"] = False
    frame["error"] = reason
    return ChunkResult(span.start, span.stop, frame, 0, 0, len(frame))


def merge(span: Span, parts: list[ChunkResult]) -> ChunkResult:
    """The results of parts of ``span`` (its halves, in case order) as the chunk's one result
    (no part written: the driver writes it)."""
    rows = [p.rows for p in parts]
    if isinstance(rows[0], pd.DataFrame):
        # the columns of a computed part (a part whose worker died has no summary columns)
        full = max(rows, key=lambda f: len(f.columns))
        merged = pd.concat(rows, ignore_index=True)
        order = [c for c in full.columns if c != "error"] + [c for c in merged.columns if c not in full.columns
                                                             and c != "error"] + ["error"]
        merged = merged[order]
    else:
        import pyarrow as pa
        merged = pa.concat_tables(rows)
    return ChunkResult(span.start, span.stop, merged, sum(p.n_ok for p in parts), sum(p.n_kept for p in parts),
                       sum(p.n_failed for p in parts), sum(p.seconds for p in parts),
                       warnings=tuple(dict.fromkeys(w for p in parts for w in p.warnings)))
