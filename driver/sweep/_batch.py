"""Streaming sweeps for studies with a batch path (``summarise_batch``): the design-search engine.

Used by :func:`driver.sweep.run_sweep_deck` when the study has a batch path, every swept key
is one the batch takes (the study's ``BATCH_KEYS``, or a key its summary ignores) and no case
needs its own files before the filter has run (``case_outputs`` 'none', or 'kept': the kept
cases are then run one by one for their files).

* Cases are never listed: a chunk is a range of case numbers, its swept values computed
  from the grid (``np.unravel_index`` in ``itertools.product`` order) in the worker.
* Bad values are found without validating every case: each value of a key whose checks
  stand alone (the study's ``BATCH_INDEPENDENT``) is validated once with the base deck, and
  every combination of the other swept keys once; a case is bad input when any of its parts
  is, with that part's error.
* Chunks go out with a bounded number in flight (back-pressure); each returned chunk is
  written at once as one part file of the Parquet dataset ``<outdir>/<stem>.sweep/``
  (only kept and failed rows with ``summary_rows = 'kept'``), with its case range and counts
  in the file's metadata.  The dataset is the resume record: a chunk is complete when its
  part is there; parts from another base deck, grid, filter or tool build are discarded
  (the ``signature``: hash of the base deck's study group, the &sweep axes, keep and
  summary_rows, the package version and the bytes of the study module and of the kernel
  extension).  Parts are written atomically; stray temporary files are removed on start.
* Worker processes exit when the driver dies (a watchdog thread on the parent pid) and
  ignore Ctrl-C (the driver cancels queued chunks).  A chunk whose worker dies is retried
  once alone in a fresh process; if that dies too its cases are reported failed with the
  reason and the study completes.  On Dask: ``retries=1`` and ``as_completed``.
"""
from __future__ import annotations

import concurrent.futures as cf
import contextlib
import hashlib
import itertools
import json
import re
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from driver import _expr as expr
from driver._atomic import DIGEST_CHARS, atomic_open, file_digest, own_folder, refuse_link
from driver._deck import DeckError, RawGroup, validate
from driver._study import load_study
from driver.sweep import _store as store
from driver.sweep._engine import check_shared_folder
from driver.sweep._keep import keep_columns, keep_mask
from driver.sweep._pool import run_pool, worker_init
from driver.sweep._spec import Grid

__all__ = ["Grid", "BatchPlan", "batchable", "plan", "run", "worker_init", "chunk_rows", "MAX_CASES", "StreamedRows"]

#: largest number of cases per task below MAX_CHUNKS chunks: 0.05 s of four-bar kernel time on one
#: core for the filter's passes, 0.2 s with the peak speeds; smaller sweeps have 8 chunks
CHUNK = 65536
#: chunks of a sweep below CHUNK * 8 cases (at least 64 cases each)
MIN_CHUNKS = 8
#: a sweep of at most this many cases may run in the driver's process when it is cheap
#: (:func:`execute`): a crash in a kernel then ends the driver, so only small ones
SMALL_SWEEP = 1 << 18
#: below this much CPU time [s] for the chunks after the first, the worker pool is not started
POOL_MIN_SECONDS = 0.25
#: above CHUNK * MAX_CHUNKS cases the chunks grow instead of multiplying: the driver's work (a
#: result to merge, a part in the record) is per chunk, so 10^9 cases are 4096 chunks, not 15 259
MAX_CHUNKS = 4096
#: largest batch sweep (no case is listed, so only the grid's size is limited)
MAX_CASES = 10**10
#: largest number of combinations of coupled swept keys validated one by one
MAX_COMBOS = 20000
DIED = "worker process died twice computing this chunk (killed, out of memory or a crash in a kernel)"


@dataclass
class BatchPlan:
    """Everything a worker needs for any chunk (plain data, picklable)."""

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


def chunk_size(n: int) -> int:
    """Cases per chunk of a batch sweep of ``n`` cases: a function of ``n`` only (not of the
    workers), so ``--resume`` works with any ``-j``; at most :data:`MAX_CHUNKS` chunks."""
    if n > CHUNK * MAX_CHUNKS:
        return -(-n // MAX_CHUNKS)
    return min(CHUNK, max(64, -(-n // MIN_CHUNKS)))


def _signature(raw: RawGroup, grid: Grid, keep: str, rows: str, module, shown: list[str] | None = None) -> str:
    """The batch record's signature: :func:`driver.sweep._store.signature` of what the rows depend on."""
    return store.signature(["batch", raw.name, raw.values, grid.names, grid.values, grid.zipped, keep, rows]
                           + ([shown] if shown is not None else []), module)


def _swap(raw: RawGroup, values: dict[str, Any]) -> RawGroup:
    v = dict(raw.values)
    for name, x in values.items():
        v[name.partition(".")[2]] = x.item() if hasattr(x, "item") else x
    return RawGroup(raw.name, v, raw.lines, raw.line)


def batchable(module, names: list[str], keep: str, case_outputs: str) -> bool:
    """Whether a sweep over ``names`` ('group.key') can take the study's batch path."""
    if module.batch is None or case_outputs == "all" or (case_outputs == "kept" and not keep):
        return False
    return all(n.partition(".")[2] in module.batch.accepted for n in names)


def wanted_columns(module, keep: str, plotted: list[str], shown: list[str] | None
                   ) -> tuple[list[str] | None, list[str] | None]:
    """(columns every case needs, columns the shown rows need) of the study's batch summary,
    from its column -> pass table (``Study.batch.passes``): the filter's columns for every case; the
    shown rows also the plotted ones and ``shown`` (summary_columns; None: every column).
    (None, None) when the study declares no table (everything is computed)."""
    table = module.batch.passes if module.batch is not None else None
    if table is None:
        return None, None
    def names(text: str) -> set[str]:   # summary columns a plotted expression reads (as the filter's)
        return {n for n in expr.parse(text).names if "." not in n and n != "case"} if text else set()

    order = lambda cols: [c for c in table if c in cols] + sorted(c for c in cols if c not in table)
    filt = order(keep_columns(keep))
    if shown is None:
        return filt, None
    return filt, order(set(filt).union(*(names(t) for t in plotted)) | set(shown))


def plan(module, raw: RawGroup, deck_path: str, grid: Grid, keep: str, rows: str,
         plotted: list[str] | None = None, shown: list[str] | None = None) -> BatchPlan | None:
    """A batch plan for this sweep (see :func:`batchable`), or None when it must run case by case.
    ``plotted``: the plot_x/plot_y expressions; ``shown``: summary_columns (None: all)."""
    applies = module.batch.applies   # e.g. not for a base deck that optimises per case
    if applies is not None and not applies(validate(raw, module.spec, deck_path)):
        return None
    keys = [n.partition(".")[2] for n in grid.names]
    independent = set(module.batch.independent)
    single: dict[str, dict[int, str]] = {}
    coupled = [i for i, k in enumerate(keys) if k not in independent]
    for i, (name, vals) in enumerate(zip(grid.names, grid.values)):
        if i in coupled:
            continue
        errs = {}
        for j, v in enumerate(vals):
            try:
                validate(_swap(raw, {name: v}), module.spec, deck_path)
            except DeckError as exc:
                errs[j] = str(exc)
        single[name] = errs
    coupled_errors: dict[tuple, str] = {}
    if coupled:
        if grid.zipped:
            combos = [tuple([j] * len(coupled)) for j in range(grid.n)]
        else:
            combos = list(itertools.product(*(range(len(grid.values[i])) for i in coupled)))
        if len(combos) > MAX_COMBOS:
            return None
        for combo in dict.fromkeys(combos):
            combo_values = {grid.names[i]: grid.values[i][j] for i, j in zip(coupled, combo)}
            try:
                validate(_swap(raw, combo_values), module.spec, deck_path)
            except DeckError as exc:
                coupled_errors[combo] = str(exc)
    p = BatchPlan(deck_path, raw, grid, keep, rows, single, coupled, coupled_errors)
    p.filter_columns, p.shown_columns = wanted_columns(module, keep, plotted or [], shown)
    p.signature = _signature(raw, grid, keep, rows, module, p.shown_columns)
    return p


# ----------------------------------------------------------------------------- worker side

@dataclass
class ChunkResult:
    """One computed chunk: its rows (all, or kept and failed) and counts."""

    start: int
    stop: int
    frame: pd.DataFrame
    n_ok: int = 0
    n_kept: int = 0
    n_failed: int = 0
    seconds: float = 0.0
    errors: list[str] = field(default_factory=list)
    written: bool = False       # its part is in the record already (the worker wrote it)
    path: str = ""              # ... at this path


def _summaries(module, base, cols: dict[str, np.ndarray], rows: np.ndarray, wanted: list[str] | None,
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


def chunk_rows(p: BatchPlan, start: int, stop: int, folder: str = "") -> ChunkResult:
    """Summaries of cases start+1..stop (the unit of work of a worker); with ``folder`` the
    worker also writes the chunk's part of the resume record there (the driver then only merges
    the rows it returns: the kept and failed ones with ``rows = 'kept'``).

    With a filter and ``rows = 'kept'`` in two steps: the columns the filter reads for every
    case (``p.filter_columns``), then the columns the tables show (``p.shown_columns``) for the
    kept cases only; so a column nobody asks for is never computed, and the kept rows hold
    the same values as a single summary of every column would give."""
    t0 = time.perf_counter()
    module = load_study(p.raw.name)
    if module is None:   # a plan is only made for a registered study (plan() read its spec)
        raise LookupError(f"no registered study &{p.raw.name}")
    n = stop - start
    cols = p.grid.columns(start, stop)
    idx = p.grid.indices(start, stop)
    bad = np.zeros(n, dtype=bool)
    err = None
    for i, name in enumerate(p.grid.names):
        for j, msg in p.single_errors.get(name, {}).items():
            hit = idx[i] == j
            if hit.any():
                err = np.full(n, "", dtype=object) if err is None else err
                err[hit & ~bad] = msg
                bad |= hit
    if p.coupled_errors:
        keys = list(zip(*(idx[i] for i in p.coupled)))
        for k, key in enumerate(keys):
            coupled_msg = p.coupled_errors.get(tuple(int(x) for x in key))
            if coupled_msg and not bad[k]:
                err = np.full(n, "", dtype=object) if err is None else err
                err[k] = coupled_msg
                bad[k] = True
    if err is None:
        err = np.full(n, "", dtype=object)
    base = validate(p.raw, module.spec, p.deck_path)
    every = np.arange(n)
    two_step = bool(p.keep) and p.rows == "kept" and p.filter_columns is not None
    if two_step and not bad.any():   # the common case: the filter on plain arrays, no full frame
        first = _summaries(module, base, cols, every, p.filter_columns, None)
        data = {"case": np.arange(start + 1, stop + 1, dtype=np.int64), **cols,
                **{c: first[c].to_numpy() for c in first.columns}}
        mask = keep_mask(p.keep, data)
        shown = np.flatnonzero(mask)
        out = _frame(start, stop, cols, bad, err, _summaries(module, base, cols, shown, p.shown_columns, None), shown)
        out["kept"] = True
        res = ChunkResult(start, stop, out, n, len(shown), 0)
        return _finish(res, p, folder, t0)
    if two_step:
        first = _summaries(module, base, cols, every, p.filter_columns, bad)
    else:
        wanted = None if p.shown_columns is None else list(dict.fromkeys([*(p.filter_columns or []),
                                                                          *p.shown_columns]))
        first = _summaries(module, base, cols, every, wanted, bad)
    frame = _frame(start, stop, cols, bad, err, first)
    mask = ~bad
    if p.keep:
        mask &= keep_mask(p.keep, frame)
    frame["kept"] = mask
    res = ChunkResult(start, stop, frame, int((~bad).sum()), int(mask.sum()), int(bad.sum()))
    if p.rows == "kept":
        shown = np.flatnonzero(mask | bad)
        if two_step:   # the shown rows' columns, for those rows only
            summ = _summaries(module, base, cols, shown, p.shown_columns, bad)
            out = _frame(start, stop, cols, bad, err, summ, shown)
            out["kept"] = mask[shown]
            res.frame = out
        else:
            res.frame = frame.iloc[shown].reset_index(drop=True)
    elif p.shown_columns is not None:   # the filter's columns that are not shown go
        res.frame = frame[[c for c in frame.columns if c not in set(p.filter_columns or ()) - set(p.shown_columns)]]
    return _finish(res, p, folder, t0)


def _finish(res: ChunkResult, p: BatchPlan, folder: str, t0: float) -> ChunkResult:
    """Write the chunk's part when the worker owns the record's folder; time the chunk."""
    if folder:
        res.path = str(write_part(Path(folder), res, p.signature))
        res.written = True
    res.seconds = time.perf_counter() - t0
    return res


def _frame(start: int, stop: int, cols: dict[str, np.ndarray], bad: np.ndarray, err: np.ndarray,
           summ: pd.DataFrame, rows: np.ndarray | None = None) -> pd.DataFrame:
    """The rows of a chunk (all, or ``rows``): case, swept values, status, kept, summary, error."""
    case = np.arange(start + 1, stop + 1, dtype=np.int64)
    pick = (lambda a: a) if rows is None else (lambda a: a[rows])
    frame = pd.DataFrame({"case": pick(case), **{k: pick(v) for k, v in cols.items()}})
    frame["status"] = np.where(pick(bad), "bad input", "ok").astype(object)
    frame["kept"] = False
    summ.index = frame.index
    frame = pd.concat([frame, summ], axis=1)
    frame["error"] = pick(err)
    return frame


# ----------------------------------------------------------------------------- dataset (resume record)

_PART = re.compile(rf"^part-(\d{{12}})-([0-9a-f]{{{DIGEST_CHARS}}})\.parquet$")


def _part_name(start: int, digest: str) -> str:
    """A part's name: its first case and the checksum of its bytes (verified on resume)."""
    return f"part-{start:012d}-{digest}.parquet"


def clean(folder: Path, signature: str, resume: bool, damaged: list[int] | None = None) -> dict[int, dict]:
    """Remove stray temporaries (and, without resume or on a signature change, old parts, and
    parts whose bytes fail their checksum: their case counts are appended to ``damaged``);
    returns {start: metadata (with its 'path')} of the complete chunks kept."""
    done: dict[int, dict] = {}
    damaged = damaged if damaged is not None else []
    refuse_link(folder)   # never list or delete where a link points
    if not folder.exists():
        return done
    for f in folder.iterdir():
        if f.name.startswith(".") and f.name.endswith(".tmp"):
            f.unlink(missing_ok=True)
            continue
        if not f.name.startswith("part-"):
            continue
        meta = None
        m = _PART.match(f.name)
        if resume and m:
            with contextlib.suppress(Exception):
                raw = pq.read_schema(f).metadata or {}
                meta = json.loads(raw.get(b"sweep", b"{}"))
        if m and meta and meta.get("signature") == signature and int(meta["start"]) == int(m.group(1)):
            if file_digest(f) == m.group(2):
                done[int(meta["start"])] = {**meta, "path": str(f)}
                continue
            damaged.append(int(meta["stop"]) - int(meta["start"]))
        f.unlink(missing_ok=True)
    return done


def write_part(folder: Path, res: ChunkResult, signature: str) -> Path:
    table = pa.Table.from_pandas(res.frame, preserve_index=False)
    meta = {"signature": signature, "start": res.start, "stop": res.stop, "n_ok": res.n_ok,
            "n_kept": res.n_kept, "n_failed": res.n_failed, "n_rows": len(res.frame)}
    table = table.replace_schema_metadata({**(table.schema.metadata or {}), b"sweep": json.dumps(meta).encode()})
    own_folder(folder, folder.parent)
    buf = pa.BufferOutputStream()
    pq.write_table(table, buf)
    data = buf.getvalue().to_pybytes()
    path = folder / _part_name(res.start, hashlib.sha256(data).hexdigest()[:DIGEST_CHARS])
    with atomic_open(path, "wb") as fh:
        fh.write(data)
    return path


def read_rows(paths: list[Path]) -> pd.DataFrame:
    frames = [pq.read_table(p).to_pandas() for p in paths]
    frames = [f for f in frames if len(f)]
    if not frames:
        return pd.DataFrame()
    return pd.concat(frames, ignore_index=True) if len(frames) > 1 else frames[0]


# ----------------------------------------------------------------------------- execution

def _died(p: BatchPlan, start: int, stop: int) -> ChunkResult:
    frame = pd.DataFrame({"case": np.arange(start + 1, stop + 1, dtype=np.int64), **p.grid.columns(start, stop)})
    frame["status"] = "failed"
    frame["kept"] = False
    frame["error"] = DIED
    return ChunkResult(start, stop, frame, 0, 0, stop - start)


def _alone(p: BatchPlan, start: int, stop: int, folder: str = "") -> ChunkResult:
    """Retry of a chunk whose worker died: alone in a fresh process."""
    with cf.ProcessPoolExecutor(max_workers=1, initializer=worker_init) as pool:
        try:
            return pool.submit(chunk_rows, p, start, stop, folder).result()
        except cf.process.BrokenProcessPool:
            return _died(p, start, stop)


def execute(p: BatchPlan, todo: list[tuple[int, int]], jobs: int, scheduler: Any,
            on_result, in_flight: int = 0, folder: str = "", adaptive: bool = False,
            notify: Callable[[str], None] | None = None) -> None:
    """Run chunks ``todo`` [(start, stop)]; ``on_result(ChunkResult)`` as each completes.
    ``folder``: the record's folder, where the workers write their chunks' parts (on Dask only
    when every worker sees it; otherwise the result comes back unwritten).  ``adaptive`` (the
    deck sets no chunk size): a sweep of at most :data:`SMALL_SWEEP` cases runs its first chunk
    in this process and the rest too when, at that chunk's CPU time, they would take less than
    :data:`POOL_MIN_SECONDS` (the worker pool is started only when it pays).  ``notify(line)`` is
    told at once when Ctrl-C cancels the queued chunks of workers (:func:`~driver.sweep._pool.run_pool`)."""
    if not todo:
        return
    if scheduler:
        _execute_dask(p, todo, scheduler, on_result, in_flight, folder)
        return
    if jobs <= 1:
        for s, e in todo:
            on_result(chunk_rows(p, s, e, folder))
        return
    if adaptive and p.grid.n <= SMALL_SWEEP and POOL_MIN_SECONDS > 0:
        # a small sweep: the first chunk here, timed; the rest here too when the pool would not pay
        # for starting its workers (forking them costs tens of ms of CPU each)
        c0 = time.process_time()
        on_result(chunk_rows(p, *todo[0], folder))
        todo = todo[1:]
        if (time.process_time() - c0) * len(todo) < POOL_MIN_SECONDS:
            for s, e in todo:
                on_result(chunk_rows(p, s, e, folder))
            return
    queue: Iterator[tuple[int, int]] = iter(todo)
    run_pool(lambda: next(queue, None), lambda pool, rng: pool.submit(chunk_rows, p, rng[0], rng[1], folder),
             lambda rng: _alone(p, rng[0], rng[1], folder), lambda rng, res, pending: on_result(res), jobs,
             in_flight or 2 * jobs, "chunks", notify=notify)


def _execute_dask(p: BatchPlan, todo: list[tuple[int, int]], scheduler: Any, on_result, in_flight: int,
                  folder: str = "") -> None:
    from dask.distributed import Client, as_completed
    from distributed.scheduler import KilledWorker
    client = scheduler if not isinstance(scheduler, str) else Client(scheduler)
    try:
        if folder:   # workers write their parts only where this machine reads them back
            try:
                check_shared_folder(client, Path(folder))
            except OSError:
                folder = ""
        workers = max(1, len(client.scheduler_info().get("workers", {})))
        limit = in_flight or 2 * workers
        queue = iter(todo)
        ranges: dict[Any, tuple[int, int]] = {}
        pdata = client.scatter(p, broadcast=True)

        def submit(rng):
            fut = client.submit(chunk_rows, pdata, *rng, folder, pure=False, retries=1)
            ranges[fut] = rng
            return fut

        ac = as_completed([submit(r) for r in itertools.islice(queue, limit)])
        for fut in ac:
            rng = ranges.pop(fut)
            try:
                on_result(fut.result())
            except KilledWorker:
                on_result(_died(p, *rng))
            nxt = next(queue, None)
            if nxt is not None:
                ac.add(submit(nxt))
    finally:
        if isinstance(scheduler, str):
            client.close()


@dataclass
class StreamedRows:
    """The rows of a batch sweep too many to hold in the driver: the record's parts that hold
    rows, in case order (each a Parquet file of the rows its chunk returned)."""

    paths: list[Path]
    n_rows: int

    def __len__(self) -> int:
        return self.n_rows


def run(p: BatchPlan, folder: Path, jobs: int, scheduler: Any, resume: bool, progress: bool,
        chunk: int = 0, announce=None, stream_rows: int = 0, notify: Callable[[str], None] | None = None
        ) -> tuple[pd.DataFrame | StreamedRows, dict[str, int], int]:
    """Run the whole batch sweep; returns (rows, counts, chunk size).  ``announce(resumed, damaged)``
    is called before anything runs with the number of cases found complete in the record and the
    case counts of its parts that failed their checksum (dropped: their cases run again).

    ``stream_rows``: above this many returned rows (kept and failed ones with ``rows = 'kept'``)
    the driver stops holding them and returns a :class:`StreamedRows` (the record's parts, read
    back one at a time by the table writers: driver memory stays flat); 0: always a DataFrame."""
    n = p.grid.n
    # the layout depends on the grid only (not on the workers), so --resume works with any -j
    size = chunk or chunk_size(n)
    damaged: list[int] = []
    done = clean(folder, p.signature, resume, damaged)
    # a resumed chunk counts only if it covers exactly one chunk of this run's layout
    ranges = [(s, min(s + size, n)) for s in range(0, n, size)]
    complete = {s for s, m in done.items() if s % size == 0 and m["stop"] == min(s + size, n)}
    for s in set(done) - complete:
        Path(done[s]["path"]).unlink(missing_ok=True)
    paths = {s: Path(done[s]["path"]) for s in complete}
    counts = {"ok": 0, "kept": 0, "failed": 0}
    n_rows = 0   # rows of the resumed chunks and those returned
    for s in complete:
        for k in counts:
            counts[k] += int(done[s][f"n_{k}"])
        n_rows += int(done[s]["n_rows"]) if "n_rows" in done[s] else _part_rows(Path(done[s]["path"]))
    resumed = sum(min(s + size, n) - s for s in complete)
    todo = [r for r in ranges if r[0] not in complete]
    if announce:
        announce(resumed, damaged)
    own_folder(folder, folder.parent)
    bar = _progress(n, resumed, progress)

    merged: dict[int, pd.DataFrame] | None = {}   # the rows each chunk returned; None: streamed
    if stream_rows and n_rows > stream_rows:
        merged = None

    def on_result(res: ChunkResult) -> None:
        nonlocal merged, n_rows
        path = res.path if res.written else str(write_part(folder, res, p.signature))
        paths[res.start] = Path(path)   # a chunk whose worker died, or Dask workers that do not see the folder
        n_rows += len(res.frame)
        if merged is not None:
            merged[res.start] = res.frame
            if stream_rows and n_rows > stream_rows:   # too many to hold: the parts are the rows from now on
                merged = None
        counts["ok"] += res.n_ok
        counts["kept"] += res.n_kept
        counts["failed"] += res.n_failed
        if bar is not None:
            bar.update(res.stop - res.start)

    try:
        execute(p, todo, jobs, scheduler, on_result, folder=str(folder), adaptive=not chunk, notify=notify)
    finally:
        if bar is not None:
            bar.close()
    if merged is None:
        return StreamedRows([paths[s] for s in sorted(paths) if _part_rows(paths[s])], n_rows), counts, size
    # the rows: those of the resumed chunks from the record, the others as the workers returned them
    frames = {s: pq.read_table(paths[s]).to_pandas() for s in sorted(complete)}
    frames.update(merged)
    parts = [frames[s] for s in sorted(frames) if len(frames[s])]
    rows = pd.DataFrame() if not parts else parts[0] if len(parts) == 1 else pd.concat(parts, ignore_index=True)
    return rows, counts, size


def _part_rows(path: Path) -> int:
    return pq.read_metadata(path).num_rows


def _progress(n: int, initial: int, progress: bool):
    """A tqdm bar, or None without progress (tqdm is not even imported then)."""
    if not progress:
        return None
    from tqdm import tqdm
    return tqdm(total=n, initial=initial, unit="case", dynamic_ncols=True)
