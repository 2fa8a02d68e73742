"""The one executor of sweeps: chunks run in this process, on a local pool of worker processes
or on a Dask cluster behind one function, :func:`execute`, for both kinds of chunk
(:mod:`driver.sweep._chunks`); and :func:`run_chunks`, a sweep's record filled by it.

One policy each, whatever the kind of chunk and wherever it runs:

* **Back-pressure.**  At most ``2 x workers`` chunks are in flight (on Dask ``workers`` is the
  cluster's threads); results are taken as they complete, so the driver's memory does not
  grow with the number of chunks.
* **Crashes.**  A worker that dies (SIGKILL, out of memory, a crash in a kernel) breaks the
  local pool: every chunk then in flight is suspect and is retried once, alone, in a fresh
  process.  A chunk that kills that process too is split in halves, each run alone the same
  way, down to the one case that crashes: that case alone is reported failed, with the
  reason; every other case completes.  On Dask a chunk the scheduler gives up on
  (``KilledWorker``) is split the same way.  No case is retried forever.
* **Ctrl-C.**  Worker processes ignore it (:func:`worker_init`) and exit when the driver dies.
  On an interrupt the driver tells ``notify`` at once, in the same words for the pool and for
  Dask ("interrupt: cancelling queued ..., finishing the running ones"), cancels the queued
  chunks, lets the running ones finish (their files and parts are complete) and re-raises:
  the command line exits 130.  In this process nothing is queued: the interrupt goes on at once.
  On the local pool the interrupt is noted and raised at the loop's own points
  (:func:`_deferred_interrupt`): raised inside ``concurrent.futures.wait`` it could leave a
  future's lock held, and the pool's shutdown then waited forever.
* **Small batch sweeps stay here.**  With ``first_here`` the first chunk runs in this process,
  timed, and so do the others when at that rate they would take less than
  :data:`POOL_MIN_SECONDS` of CPU (forking workers would cost more than it saves).
"""
from __future__ import annotations

import concurrent.futures as cf
import contextlib
import os
import secrets
import signal
import socket
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from driver._atomic import refuse_link
from driver.sweep._chunks import ChunkResult, Span, died, merge, run_chunk
from driver.sweep._plan import SMALL_SWEEP, SweepPlan, chunk_size
from driver.sweep._resume import Record, case_row_check, clean_temporaries

__all__ = ["Workers", "open_workers", "execute", "run_chunks", "Filled", "Ran", "worker_init", "check_shared_folder",
           "cluster_workers", "DIED", "POOL_MIN_SECONDS", "STREAM_ROWS"]

DIED = "worker process died running this case (killed, out of memory or a crash in a kernel); isolated and not retried"
#: below this much CPU time [s] for the chunks after the first, the worker pool is not started
POOL_MIN_SECONDS = 0.25
#: above this many rows (kept and failed cases) a batch sweep stops holding the rows its chunks
#: return: they stay in the record's parts, read one at a time for the tables (flat memory)
STREAM_ROWS = 20_000


# ----------------------------------------------------------------------------- where chunks run

def _watch_parent(ppid: int) -> None:
    while True:
        if os.getppid() != ppid:
            os._exit(1)
        time.sleep(0.5)


def worker_init() -> None:
    """Process-pool initializer: ignore Ctrl-C (the driver handles it) and exit with the driver."""
    import signal
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_watch_parent, args=(os.getppid(),), daemon=True).start()


@dataclass
class Workers:
    """Where a sweep's chunks run: this process (``jobs`` 1), ``jobs`` local worker processes, or
    the Dask cluster of ``client``; ``notify(line)`` hears a Ctrl-C at once."""

    jobs: int = 1
    client: Any = None
    notify: Callable[[str], None] | None = None
    scheduler: Any = None   #: the scheduler as given (an address or a client)
    _shared: dict[str, bool] = field(default_factory=dict)

    @property
    def where(self) -> str:
        """Where the chunks run, in words (``"2 worker(s)"``, ``"dask ADDRESS"``)."""
        return f"dask {self.scheduler}" if self.client else f"{self.jobs} worker(s)"

    @property
    def threads(self) -> int:
        """Chunks that run at once: the local workers, or the sum of the cluster's threads."""
        return cluster_workers(self.client) if self.client else self.jobs

    def shares(self, folder: Path) -> bool:
        """Whether every worker writes into ``folder`` as this machine sees it (always locally;
        on Dask checked once per folder with probe files)."""
        if not self.client:
            return True
        key = str(folder)
        if key not in self._shared:
            try:
                check_shared_folder(self.client, Path(folder))
                self._shared[key] = True
            except OSError:
                self._shared[key] = False
        return self._shared[key]

    def require_shared(self, folder: Path) -> None:
        """OSError (one line) when the Dask workers cannot write ``folder`` (case files)."""
        if self.client:
            check_shared_folder(self.client, Path(folder))
            self._shared[str(folder)] = True

    def interrupted(self, what: str) -> None:
        """The one Ctrl-C notice, for the pool and for Dask alike."""
        if self.notify is not None:
            self.notify(f"interrupt: cancelling queued {what}, finishing the running ones")


@contextlib.contextmanager
def open_workers(jobs: int | None, scheduler: Any = None,
                 notify: Callable[[str], None] | None = None) -> Iterator[Workers]:
    """The workers of one sweep: ``scheduler`` (a Dask address, connected here and closed after,
    or a client) or ``jobs`` local processes (default all cores; 1: this process)."""
    if not scheduler:
        yield Workers(jobs or os.cpu_count() or 1, None, notify)
        return
    from dask.distributed import Client
    client = scheduler if not isinstance(scheduler, str) else Client(scheduler)
    try:
        yield Workers(jobs or os.cpu_count() or 1, client, notify, scheduler)
    finally:
        if isinstance(scheduler, str):
            client.close()


def cluster_workers(client: Any) -> int:
    """Cases a Dask cluster runs at once: the sum of its workers' threads (not this machine's cores)."""
    return max(1, sum(int(w.get("nthreads", 1)) for w in client.scheduler_info().get("workers", {}).values()))


def _probe_write(folder: str, token: str) -> str:
    """On a worker: write a probe file in the output folder; returns its name, or the error."""
    name = f".probe-{token}-{socket.gethostname()}-{os.getpid()}"
    try:
        Path(folder).mkdir(parents=True, exist_ok=True)
        (Path(folder) / name).write_text(token)
    except OSError as exc:
        return f"!{exc.strerror or exc}"
    return name


def _probe_remove(folder: str, token: str) -> None:
    for p in Path(folder).glob(f".probe-{token}-*"):
        p.unlink(missing_ok=True)


def check_shared_folder(client: Any, folder: Path) -> None:
    """OSError (one line) unless every Dask worker writes into ``folder`` as this machine sees it:
    each worker writes a probe file there and this process reads it back."""
    token = secrets.token_hex(8)
    folder.mkdir(parents=True, exist_ok=True)
    answers = client.run(_probe_write, str(folder), token)
    blind = []
    try:
        for worker, name in sorted(answers.items()):
            if name.startswith("!"):
                blind.append(f"{worker} cannot write there ({name[1:]})")
                continue
            try:
                ok = (folder / name).read_text() == token
            except OSError:
                ok = False
            if not ok:
                blind.append(f"{worker} wrote a probe file this machine cannot see")
    finally:
        _probe_remove(str(folder), token)
        with contextlib.suppress(Exception):
            client.run(_probe_remove, str(folder), token)
    if blind:
        more = f" (and {len(blind) - 1} more)" if len(blind) > 1 else ""
        raise OSError(0, f"the Dask workers do not share this output folder: {blind[0]}{more}; give -o a folder "
                         "on a file system every worker mounts at the same path, or case_outputs = 'none'", str(folder))


# ----------------------------------------------------------------------------- execution

def execute(work: Any, spans: Iterable[Span], on_result: Callable[[ChunkResult], None], workers: Workers, *,
            first_here: bool = False, in_flight: int = 0) -> None:
    """Run the chunks ``spans`` of ``work`` (a :class:`~driver.sweep._chunks.BatchPlan` or
    :class:`~driver.sweep._chunks.CaseTask`, started in that order) where ``workers`` say;
    ``on_result`` gets each chunk's result as it completes (in any order).  See the module
    docstring for the policies."""
    what = "cases" if work.kind == "cases" else "chunks"   # as the Ctrl-C notice names them
    todo = iter(spans)
    if not workers.client and workers.jobs > 1 and first_here and POOL_MIN_SECONDS > 0:
        first = next(todo, None)
        if first is None:
            return
        c0 = time.process_time()
        on_result(run_chunk(work, first))
        rest = list(todo)
        if (time.process_time() - c0) * len(rest) < POOL_MIN_SECONDS:
            for span in rest:
                on_result(run_chunk(work, span))
            return
        todo = iter(rest)
    if workers.client:
        _dask(work, todo, on_result, workers, in_flight or 2 * workers.threads, what)
    elif workers.jobs > 1:
        _pool(work, todo, on_result, workers, in_flight or 2 * workers.jobs, what)
    else:
        for span in todo:
            on_result(run_chunk(work, span))


def _isolate(work: Any, span: Span, alone: Callable[[Span], ChunkResult | None]) -> ChunkResult:
    """A chunk whose worker died, run alone; if that dies too, each half alone the same way,
    down to the case that crashes, which is reported failed with the reason."""
    res = alone(span)
    if res is not None:
        return res
    if len(span.cases) == 1:
        return died(work, span, DIED)
    a, b = span.halves()
    return merge(span, [_isolate(work, a, alone), _isolate(work, b, alone)])


def _alone_in_a_process(work: Any) -> Callable[[Span], ChunkResult | None]:
    def alone(span: Span) -> ChunkResult | None:
        pool = cf.ProcessPoolExecutor(max_workers=1, initializer=worker_init)
        try:
            return pool.submit(run_chunk, work, span).result()
        except cf.process.BrokenProcessPool:
            return None
        finally:
            pool.shutdown(wait=True)
    return alone


#: the longest a Ctrl-C on the local pool waits to be raised [s] (a latency, never a result)
INTERRUPT_POLL_S = 0.1


@contextlib.contextmanager
def _deferred_interrupt() -> Iterator[threading.Event]:
    """Ctrl-C noted in an event instead of raised wherever the main thread is: ``wait`` of
    :mod:`concurrent.futures` takes each future's lock in turn, and a KeyboardInterrupt raised
    between two of them leaves one held, so the pool's result thread and its shutdown wait
    forever.  Only where Python's own handler is in force, in the main thread."""
    hit = threading.Event()
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
        yield hit
        return
    old = signal.signal(signal.SIGINT, lambda signum, frame: hit.set())
    try:
        yield hit
    finally:
        signal.signal(signal.SIGINT, old)


def _pool(work: Any, todo: Iterator[Span], on_result: Callable[[ChunkResult], None], workers: Workers,
          limit: int, what: str) -> None:
    """The local worker pool: ``limit`` chunks in flight; a dead worker's chunks isolated."""
    pool = cf.ProcessPoolExecutor(max_workers=workers.jobs, initializer=worker_init)
    pending: dict[cf.Future, Span] = {}
    alone = _alone_in_a_process(work)
    with _deferred_interrupt() as interrupted:
        try:
            while True:
                if interrupted.is_set():
                    raise KeyboardInterrupt
                suspects: list[Span] = []
                while len(pending) < limit and not suspects:
                    span = next(todo, None)
                    if span is None:
                        break
                    try:
                        pending[pool.submit(run_chunk, work, span)] = span
                    except cf.process.BrokenProcessPool:   # a worker died since the last wait
                        suspects.append(span)
                if not pending and not suspects:   # every chunk sent and returned
                    break
                if not suspects:
                    done, _ = cf.wait(pending, timeout=INTERRUPT_POLL_S, return_when=cf.FIRST_COMPLETED)
                    for fut in done:
                        span = pending.pop(fut)
                        try:
                            res = fut.result()
                        except cf.process.BrokenProcessPool:
                            suspects.append(span)
                            continue
                        on_result(res)
                if suspects:   # every chunk in flight is suspect: each is retried once, alone
                    suspects += list(pending.values())
                    pending.clear()
                    pool.shutdown(wait=False, cancel_futures=True)
                    for span in sorted(suspects, key=lambda s: s.start):
                        on_result(_isolate(work, span, alone))
                    pool = cf.ProcessPoolExecutor(max_workers=workers.jobs, initializer=worker_init)
        except KeyboardInterrupt:
            workers.interrupted(what)
            pool.shutdown(wait=True, cancel_futures=True)
            raise
        finally:
            pool.shutdown(wait=True)


def _dask(work: Any, todo: Iterator[Span], on_result: Callable[[ChunkResult], None], workers: Workers,
          limit: int, what: str) -> None:
    """A Dask cluster: ``limit`` chunks in flight, ``retries=1``; a chunk the scheduler gives up
    on (its workers died) isolated as on the pool."""
    from dask.distributed import as_completed
    from distributed.scheduler import KilledWorker
    client = workers.client
    shared = client.scatter(work, broadcast=True)
    pending: dict[Any, Span] = {}

    def alone(span: Span) -> ChunkResult | None:
        try:
            return client.submit(run_chunk, shared, span, pure=False).result()
        except KilledWorker:
            return None

    try:
        ac = as_completed()

        def fill() -> None:
            while len(pending) < limit:
                span = next(todo, None)
                if span is None:
                    return
                fut = client.submit(run_chunk, shared, span, pure=False, retries=1)
                pending[fut] = span
                ac.add(fut)

        fill()
        while pending:
            fut = next(ac)
            span = pending.pop(fut)
            try:
                res = fut.result()
            except KilledWorker:
                res = _isolate(work, replace(span), alone)
            on_result(res)
            fill()
    except KeyboardInterrupt:
        workers.interrupted(what)
        client.cancel(list(pending))
        raise


# ----------------------------------------------------------------------------- a sweep's record, filled

@dataclass
class Filled:
    """A record after its chunks ran: the cases it held complete, the counts of every chunk
    (resumed ones included), and the rows the chunks returned (batch), held by chunk start
    until there are too many (then None: they are in the record's parts)."""

    record: Record
    resumed: int
    counts: dict[str, int]
    rows: dict[int, Any] | None
    n_rows: int
    wall: float = 0.0
    cpu: float = 0.0
    #: what a library warned while the chunks ran, in words, each once (:mod:`driver._warnings`)
    warnings: list[str] = field(default_factory=list)

    def frame(self) -> pd.DataFrame:
        """The batch rows of every chunk in case order (resumed chunks' from their parts)."""
        import pyarrow.parquet as pq
        held = self.rows or {}
        frames = [held[s] if s in held else pq.read_table(self.record.parts[s].path).to_pandas()
                  for s in sorted(self.record.parts)]
        frames = [f for f in frames if len(f)]
        if not frames:
            return pd.DataFrame()
        return frames[0] if len(frames) == 1 else pd.concat(frames, ignore_index=True)


@dataclass
class Ran:
    """What :func:`run_chunks` left: the sweep's record, and on the batch path with
    ``case_outputs = 'kept'`` the kept cases' own record (their files)."""

    main: Filled
    resume: bool = False
    kept: Filled | None = None
    kept_cases: list[int] = field(default_factory=list)


def run_chunks(plan: SweepPlan, workers: Workers, *, resume: bool = False, progress: bool = False,
               on_chunk: Callable[[ChunkResult], None] | None = None) -> Ran:
    """Run the sweep's chunks into its resume record (verified first with ``resume``; every part
    removed without); then, on the batch path with ``case_outputs = 'kept'``, the kept cases'
    files case by case into their own record.  ``on_chunk`` sees each per-case chunk's result."""
    for folder in (plan.record, plan.record / "cases", Path(plan.layout.root)):
        refuse_link(folder)   # the sweep's own folders: never a link (OUTDIR itself may be one)
    work: Any = plan.batch or plan.cases
    if plan.batch is None:   # case by case: cases that write files, written where the workers see
        clean_temporaries(plan.layout)   # left by a killed earlier run of this deck
        check = case_row_check(plan.grid, plan.layout)
        record = Record(plan.record, plan.outdir, work.signature, "cases", plan.n, plan.chunk, check=check)
    else:
        record = Record(plan.record, plan.outdir, work.signature, "batch", plan.n, plan.chunk)
    stream = STREAM_ROWS if plan.batch is not None and plan.stream and plan.sw.case_outputs == "none" else 0
    main = _fill(work, record, workers, resume=resume, progress=progress, stream=stream, on_chunk=on_chunk,
                 estimates=plan.estimates,
                 first_here=plan.batch is not None and not plan.sw.chunk and plan.n <= SMALL_SWEEP)
    ran = Ran(main, resume)
    if plan.batch is not None and plan.sw.case_outputs == "kept" and main.counts["n_kept"]:
        rows = main.frame()
        ran.kept_cases = [int(c) for c in rows.loc[rows["kept"], "case"]]
        cases = np.asarray(ran.kept_cases, dtype=np.int64)
        clean_temporaries(plan.layout)
        kept = Record(plan.record / "cases", plan.outdir, plan.cases.signature, "cases", len(cases),
                      chunk_size(len(cases), "cases"), cases, case_row_check(plan.grid, plan.layout))
        ran.kept = _fill(plan.cases, kept, workers, resume=resume, progress=False, on_chunk=on_chunk)
    return ran


def _fill(work: Any, record: Record, workers: Workers, *, resume: bool, progress: bool, stream: int = 0,
          on_chunk: Callable[[ChunkResult], None] | None = None, estimates: dict[int, float] | None = None,
          first_here: bool = False) -> Filled:
    """Run the chunks ``record`` lacks (:meth:`~driver.sweep._resume.Record.open`) and add each
    result to it as it completes."""
    t0, c0 = time.perf_counter(), time.process_time()
    resumed = record.open(resume)
    counts = {"n_ok": 0, "n_kept": 0, "n_failed": 0}
    n_rows = 0
    for part in record.parts.values():   # the complete chunks' counts and rows, from their metadata
        for k in counts:
            counts[k] += int(part.meta.get(k, 0))
        n_rows += int(part.meta.get("n_rows", 0))
    todo = record.todo()
    writes = work.kind == "cases" and work.case_outputs != "none"
    if writes and todo:
        workers.require_shared(Path(work.layout.root))
    folder = str(record.folder) if todo and workers.shares(record.folder) else ""
    spans = [Span(s, e, cases, "" if s in record.reuse else folder) for s, e, cases in todo if len(cases)]
    for s, e, _ in [t for t in todo if not len(t[2])]:   # every case reused: the part assembled here
        record.add(s, e, None, "", {})
    if estimates and len(set(estimates.values())) > 1:   # longest first: the last chunk to start is short
        spans.sort(key=lambda sp: -sum(estimates.get(c, 0.0) for c in sp.cases))
    rows: dict[int, Any] | None = {} if not (stream and n_rows > stream) else None
    bar = None
    if progress:   # tqdm is not even imported without a bar
        from tqdm import tqdm
        bar = tqdm(total=record.n, initial=resumed, unit="case", dynamic_ncols=True)

    said: dict[str, None] = {}

    def on_result(res: ChunkResult) -> None:
        nonlocal rows, n_rows
        said.update(dict.fromkeys(res.warnings))
        record.add(res.start, res.stop, res.rows, res.path, res.counts)
        for k, v in res.counts.items():
            counts[k] += v
        n_rows += len(res.rows)
        if rows is not None and work.kind == "batch":
            rows[res.start] = res.rows
            if stream and n_rows > stream:   # too many to hold: the parts are the rows from now on
                rows = None
        if on_chunk is not None:
            on_chunk(res)
        if bar is not None:
            bar.update(res.n_ok + res.n_failed)

    try:
        execute(work, spans, on_result, workers, first_here=first_here)
    finally:
        if bar is not None:
            bar.close()
    record.finish()
    return Filled(record, resumed, counts, rows, n_rows, time.perf_counter() - t0, time.process_time() - c0,
                  list(said))
