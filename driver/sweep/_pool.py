"""The local worker pool of both sweep engines (per case, :mod:`driver.sweep._engine`; batch,
:mod:`driver.sweep._batch`): processes that ignore Ctrl-C and exit with the driver, a bounded
number of tasks in flight, and a task whose worker died retried once, alone."""
from __future__ import annotations

import concurrent.futures as cf
import os
import threading
import time
from collections.abc import Callable
from typing import Any

__all__ = ["run_pool", "worker_init"]


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


def run_pool(source: Callable[[], Any], submit: Callable[[cf.ProcessPoolExecutor, Any], cf.Future],
             alone: Callable[[Any], Any], on_result: Callable[[Any, Any, int], None], jobs: int, limit: int,
             what: str, order: Callable[[Any], Any] = lambda t: t, notify: Callable[[str], None] | None = None) -> None:
    """The local worker pool of both sweep engines, with a bounded number of tasks in flight.

    ``source()`` gives the next task (None: none now; with nothing in flight, the end);
    ``submit(pool, task)`` sends it; ``on_result(task, result, n_in_flight)`` takes each result as it
    comes.  When a worker dies every task in flight is suspect: each is retried once, alone, by
    ``alone(task)`` (in ``order``), and a fresh pool takes over.  Workers exit with the driver
    (:func:`worker_init`).  On Ctrl-C the queued tasks are cancelled and the running ones finish
    before the interrupt goes on; ``notify(line)`` (the command line's: a line on stderr) is told
    so at once, before that wait (default: nothing is said, the KeyboardInterrupt is the news)."""
    pool = cf.ProcessPoolExecutor(max_workers=jobs, initializer=worker_init)
    pending: dict[cf.Future, Any] = {}
    try:
        while True:
            suspects: list[Any] = []
            while len(pending) < limit and not suspects:
                task = source()
                if task is None:
                    break
                try:
                    pending[submit(pool, task)] = task
                except cf.process.BrokenProcessPool:   # a worker died since the last wait
                    suspects.append(task)
            if not pending and not suspects:   # every task sent and returned
                break
            if not suspects:
                done, _ = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
                for fut in done:
                    task = pending.pop(fut)
                    try:
                        res = fut.result()
                    except cf.process.BrokenProcessPool:
                        suspects.append(task)
                        continue
                    on_result(task, res, len(pending))
            if suspects:   # every task in flight is suspect: each is retried once, alone
                suspects += list(pending.values())
                pending.clear()
                pool.shutdown(wait=False, cancel_futures=True)
                for task in sorted(suspects, key=order):
                    on_result(task, alone(task), 0)
                pool = cf.ProcessPoolExecutor(max_workers=jobs, initializer=worker_init)
    except KeyboardInterrupt:
        if notify is not None:
            notify(f"interrupt: cancelling queued {what}, finishing the running ones")
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    finally:
        pool.shutdown(wait=True)
