"""The per-case sweep engine: what a worker does with a chunk of cases, and how chunks are sent
to worker processes or a Dask cluster.

* A chunk is a list of case numbers; the worker computes each case's values from the grid
  (nothing per case is built in the driver), runs it through the runner exactly as a single
  run, writes its files (all cases, or the kept ones) and returns the summaries.
* Chunks go out with a bounded number in flight (back-pressure): the driver's memory does not
  grow with the number of cases.  With ``chunk = 0`` the first ``2 x workers`` cases go out one
  by one and the chunk size is chosen from the fastest of them once ``workers + 1`` have
  returned: some worker has then run its second case, so the time is a warm one (a worker's
  first case pays its cold imports).  On Dask ``workers`` is the cluster's threads.
* Local worker processes exit when the driver dies (:func:`driver.sweep._pool.worker_init`)
  and ignore Ctrl-C: the driver cancels queued chunks and lets the running ones finish.
* A worker that dies (SIGKILL, out of memory, a crash in a kernel) breaks the pool: every chunk
  then in flight is retried once, alone, in a fresh process.  A chunk that kills that process
  too is split in halves, each retried alone, down to the single case that crashes; that case
  is reported failed with the reason, the others complete.  No case is retried forever.
  On Dask: ``retries=1`` and ``as_completed``; a ``KilledWorker`` chunk's cases are failed.
"""
from __future__ import annotations

import concurrent.futures as cf
import json
import math
import os
import secrets
import socket
import time
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from driver._atomic import output_set, own_folder, write_text
from driver._deck import DeckError, Params, RawGroup, validate
from driver._export import write_tidy
from driver._outcome import ExitCode
from driver._runner import compute, write_outputs
from driver._study import load_study
from driver.sweep._keep import keep_mask
from driver.sweep._pool import run_pool, worker_init
from driver.sweep._spec import Case, CaseResult, Grid, case_deck_text, case_raw, iter_cases
from driver.sweep._store import Layout, json_default

__all__ = ["Task", "run_task", "auto_chunk", "execute", "cluster_workers", "check_shared_folder", "DIED"]

DIED = "worker process died running this case (killed, out of memory or a crash in a kernel); isolated and not retried"


@dataclass
class Task:
    """A chunk of cases for one worker (picklable: plain data only)."""

    deck_path: str
    raw: RawGroup
    grid: Grid
    indices: list[int]          # case numbers (from 1)
    layout: Layout
    keep: str
    case_outputs: str
    formats: list[str]
    plot: bool | str            # the cases' own figures (only with --plot and case_plots)
    base_hash: str

    def part(self, indices: list[int]) -> Task:
        return Task(self.deck_path, self.raw, self.grid, indices, self.layout, self.keep, self.case_outputs,
                    self.formats, self.plot, self.base_hash)


# ----------------------------------------------------------------------------- worker side

def _kept_many(keep: str, results: list[CaseResult]) -> list[bool]:
    """The keep filter on a chunk of cases at once (vectorised over the chunk)."""
    ok = [r.status == ExitCode.OK for r in results]
    if not keep or not results:
        return ok
    rows = pd.DataFrame([{**r.values, **r.summary} for r in results])
    return [o and bool(k) for o, k in zip(ok, keep_mask(keep, rows))]


def _compute(task: Task, case: Case, module) -> tuple[CaseResult, Any, Params | None]:
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


def _rel(path: Path, root: str) -> str:
    return Path(os.path.relpath(path, root)).as_posix()


def _write_case(task: Task, case: Case, res: CaseResult, result, params: Params, module) -> None:
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
        res.files = sorted({_rel(p, task.layout.root) for p in written})
        res.written = True
    except Exception as exc:
        res.status, res.error, res.kept = ExitCode.FAILED, f"{exc.__class__.__name__}: {exc}", False
    res.seconds += time.perf_counter() - t0
    res.cpu += time.process_time() - c0


def run_task(task: Task) -> list[CaseResult]:
    """Run a chunk of cases: the unit of work sent to a process or a Dask worker.

    Parameters
    ----------
    task : Task
        The cases (plain, picklable data: the deck's study group, the grid, the case numbers).

    Returns
    -------
    list of CaseResult
        One per case, in order: status, error, summary (units in the column names), kept,
        the files written and the case's wall and CPU time (s).
    """
    module = load_study(task.raw.name)
    writable = lambda res, result: result is not None or res.status == ExitCode.OK
    cases = list(iter_cases(task.grid, task.indices))
    if task.case_outputs == "all":
        # write each case as soon as it is computed: an interrupt loses at most one case
        results = []
        for c in cases:
            res, result, params = _compute(task, c, module)
            res.kept = _kept_many(task.keep, [res])[0]
            if params is not None and writable(res, result):
                _write_case(task, c, res, result, params, module)
            results.append(res)
        return results
    computed = [_compute(task, c, module) for c in cases]
    results = [r for r, _, _ in computed]
    for r, k in zip(results, _kept_many(task.keep, results)):
        r.kept = k
    if task.case_outputs == "kept":
        for case, (res, result, params) in zip(cases, computed):
            if res.kept and params is not None and writable(res, result):
                _write_case(task, case, res, result, params, module)
    return results


def died(task: Task, reason: str = DIED) -> list[CaseResult]:
    """The cases of a chunk whose worker died: failed, with their values and the reason."""
    return [CaseResult(c.index, c.values, ExitCode.FAILED, reason, kept=False) for c in iter_cases(task.grid, task.indices)]


# ----------------------------------------------------------------------------- file system of Dask workers

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
        try:
            client.run(_probe_remove, str(folder), token)
        except Exception:
            pass
    if blind:
        more = f" (and {len(blind) - 1} more)" if len(blind) > 1 else ""
        raise OSError(0, f"the Dask workers do not share this output folder: {blind[0]}{more}; give -o a folder "
                         "on a file system every worker mounts at the same path, or case_outputs = 'none'", str(folder))


# ----------------------------------------------------------------------------- execution

def auto_chunk(seconds_per_case: float, n_cases: int, workers: int, target: float = 0.1) -> int:
    """Choose the cases per task: enough for about ``target`` of work, but at least 4 tasks per worker.

    Parameters
    ----------
    seconds_per_case : float
        Time of one warm case, s.
    n_cases : int
        Cases of the sweep.
    workers : int
        Worker processes (or a Dask cluster's threads).
    target : float, default 0.1
        Work per task, s.

    Returns
    -------
    int
        Cases per task, at least 1.

    Examples
    --------
    >>> from driver.sweep import auto_chunk
    >>> auto_chunk(0.001, 10_000, 2), auto_chunk(0.001, 100, 2), auto_chunk(1.0, 100, 2)
    (100, 13, 1)
    """
    by_time = math.ceil(target / max(seconds_per_case, 1e-6))
    by_balance = math.ceil(n_cases / (4 * max(workers, 1)))
    return max(1, min(by_time, by_balance))


def cluster_workers(client: Any) -> int:
    """Cases a Dask cluster runs at once: the sum of its workers' threads (not this machine's cores)."""
    return max(1, sum(int(w.get("nthreads", 1)) for w in client.scheduler_info().get("workers", {}).values()))


def _alone(task: Task) -> list[CaseResult]:
    """A chunk whose worker died, run alone in a fresh process; if that dies too, each half is
    run alone the same way, down to the case that crashes, which is reported failed."""
    pool = cf.ProcessPoolExecutor(max_workers=1, initializer=worker_init)
    try:
        return pool.submit(run_task, task).result()
    except cf.process.BrokenProcessPool:
        pass
    finally:
        pool.shutdown(wait=True)
    if len(task.indices) == 1:
        return died(task)
    half = len(task.indices) // 2
    return _alone(task.part(task.indices[:half])) + _alone(task.part(task.indices[half:]))


def execute(order: Iterable[int], n_todo: int, task_of: Callable[[list[int]], Task], jobs: int, scheduler: Any,
            chunk: int, on_result: Callable[[list[CaseResult]], None], in_flight: int = 0,
            notify: Callable[[str], None] | None = None) -> int:
    """Run the cases ``order`` (case numbers, started in that order) in chunks; ``on_result``
    gets each chunk's results as it completes.  Returns the chunk size used.  ``notify(line)`` is
    told at once when Ctrl-C cancels the queued cases of workers (:func:`~driver.sweep._pool.run_pool`)."""
    it = iter(order)
    if not scheduler and (jobs <= 1 or n_todo <= 1):
        if not chunk:   # time two cases (the second is warm), then chunks of ~0.1 s
            times = []
            for idx in [i for _, i in zip(range(2), it)]:
                res = run_task(task_of([idx]))
                times.append(min(r.seconds for r in res))
                on_result(res)
            chunk = auto_chunk(min(times or [1.0]), max(n_todo - 2, 0), 1)
        while True:
            cs = [i for _, i in zip(range(chunk), it)]
            if not cs:
                return chunk
            on_result(run_task(task_of(cs)))
    if scheduler:
        return _execute_dask(it, n_todo, task_of, scheduler, chunk, on_result, in_flight, notify)
    return _execute_pool(it, n_todo, task_of, jobs, chunk, on_result, in_flight, notify)


class _Feed:
    """The chunks to send: the first ``2 x workers`` cases alone (to time a warm case) when the
    chunk size is not given, then chunks of the chosen size, generated lazily."""

    def __init__(self, it, n_todo: int, workers: int, chunk: int):
        self.it, self.n_todo, self.workers, self.chunk = it, n_todo, workers, chunk
        self.probes = deque([i] for _, i in zip(range(2 * workers), it)) if not chunk else deque()
        self.n_probes = len(self.probes)
        self.times: list[float] = []

    def next(self) -> list[int] | None:
        if self.probes:
            return self.probes.popleft()
        if not self.chunk:
            return None   # waiting for the warm time
        cs = [i for _, i in zip(range(self.chunk), self.it)]
        return cs or None

    def returned(self, task: Task, results: list[CaseResult], pending: int) -> None:
        if self.chunk:
            return
        if len(task.indices) == 1 and results and results[0].status == ExitCode.OK:
            self.times.append(results[0].seconds)
        if len(self.times) >= min(self.workers + 1, self.n_probes) or (not pending and not self.probes):
            # a warm case: choose the chunk once
            self.chunk = auto_chunk(min(self.times or [1.0]), max(self.n_todo - self.n_probes, 0), self.workers)


def _execute_pool(it, n_todo: int, task_of, jobs: int, chunk: int, on_result, in_flight: int,
                  notify: Callable[[str], None] | None = None) -> int:
    feed = _Feed(it, n_todo, jobs, chunk)

    def source() -> Task | None:
        cs = feed.next()
        return None if cs is None else task_of(cs)

    def took(task: Task, res: list[CaseResult], in_flight: int) -> None:
        on_result(res)
        feed.returned(task, res, in_flight)

    run_pool(source, lambda pool, task: pool.submit(run_task, task), _alone, took, jobs,
             in_flight or 2 * jobs, "cases", order=lambda t: t.indices[0], notify=notify)
    return feed.chunk or 1


def _execute_dask(it, n_todo: int, task_of, scheduler: Any, chunk: int, on_result, in_flight: int,
                  notify: Callable[[str], None] | None = None) -> int:
    from dask.distributed import Client, as_completed
    from distributed.scheduler import KilledWorker
    client = scheduler if not isinstance(scheduler, str) else Client(scheduler)
    pending: dict[Any, Task] = {}
    try:
        workers = cluster_workers(client)
        feed = _Feed(it, n_todo, workers, chunk)
        limit = in_flight or 2 * workers
        ac = as_completed()

        def fill() -> None:
            while len(pending) < limit:
                cs = feed.next()
                if cs is None:
                    return
                task = task_of(cs)
                fut = client.submit(run_task, task, pure=False, retries=1)
                pending[fut] = task
                ac.add(fut)

        fill()
        while pending:
            fut = next(ac)
            task = pending.pop(fut)
            try:
                res = fut.result()
            except KilledWorker:
                res = died(task, DIED.replace("isolated and not retried", "Dask gave up after its retries"))
            on_result(res)
            feed.returned(task, res, len(pending))
            fill()
    except KeyboardInterrupt:
        if notify is not None:
            notify("interrupt: cancelling queued cases, finishing the running ones")
        client.cancel(list(pending))
        raise
    finally:
        if isinstance(scheduler, str):
            client.close()
    return feed.chunk or 1
