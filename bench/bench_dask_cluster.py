"""Benchmark: a large four-bar design search on a real Dask cluster (``dask scheduler`` +
``dask worker`` processes on loopback), the rate per worker, and what 10^9 linkages would need.

Starts a scheduler and 1, then 2, single-threaded worker processes on 127.0.0.1 (the same
commands docs/performance.md shows), runs ``python -m driver DECK --scheduler tcp://127.0.0.1:PORT`` on
a copy of ``inputs/fourbar_design_search.dat`` enlarged to about N linkages (``--linkages``,
default 10^7), and prints per run: wall time, linkages/s, linkages/s per worker, the driver's
peak memory and the bytes per linkage of the resume record (``outputs/<stem>.sweep/``). From
the 2-worker rate it estimates a 10^9-linkage search: worker-hours, wall time on W workers,
and disk for the resume record. Wall-clock figures need an idle machine: the load average is
printed at the start and the end.

    .venv/bin/python bench/bench_dask_cluster.py [--linkages 10000000] [--workers 1 2]
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DECK = ROOT / "inputs" / "fourbar_design_search.dat"
BIN = Path(sys.executable).parent


def free_port() -> int:
    """A TCP port free on the loopback interface now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_workers(address: str, n: int, timeout: float = 60.0) -> None:
    """Block until the scheduler at ``address`` reports ``n`` workers."""
    from dask.distributed import Client
    with Client(address, timeout=timeout) as client:
        client.wait_for_workers(n, timeout=timeout)


def cluster(workers: int, tmp: Path) -> tuple[str, list[subprocess.Popen]]:
    """Start ``dask scheduler`` and ``dask worker --nworkers W --nthreads 1`` on loopback."""
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    log = open(tmp / f"cluster{workers}.log", "w")
    sched = subprocess.Popen([str(BIN / "dask"), "scheduler", "--host", "127.0.0.1", "--port", str(port),
                              "--no-dashboard"], stdout=log, stderr=subprocess.STDOUT, cwd=tmp)
    time.sleep(2.0)
    work = subprocess.Popen([str(BIN / "dask"), "worker", address, "--nworkers", str(workers), "--nthreads", "1",
                             "--no-dashboard", "--local-directory", str(tmp / "dask-scratch")],
                            stdout=log, stderr=subprocess.STDOUT, cwd=ROOT)
    wait_workers(address, workers)
    return address, [work, sched]


def stop(procs: list[subprocess.Popen]) -> None:
    for p in procs:
        p.terminate()
        try:
            p.wait(timeout=20)
        except subprocess.TimeoutExpired:
            p.kill()


def big_deck(tmp: Path, linkages: int) -> tuple[Path, int]:
    """The design-search deck with its crank axis lengthened to about ``linkages`` cases."""
    text = DECK.read_text()
    per_crank = 64 * 64
    count = max(1, round(linkages / per_crank))
    assert "count1 = 25" in text, "inputs/fourbar_design_search.dat changed: update this benchmark"
    path = tmp / "dask_search.dat"
    path.write_text(text.replace("count1 = 25", f"count1 = {count}"))
    return path, count * per_crank


# the command line in a fresh process that reports its own peak memory (the driver's, not the workers')
DRIVER = """
import resource, sys
from driver._cli import main
rc = main(sys.argv[1:])
me = resource.getrusage(resource.RUSAGE_SELF)
print(f"maxrss_kib {me.ru_maxrss} cpu_s {me.ru_utime + me.ru_stime}", file=sys.stderr)
sys.exit(rc)
"""


def run(deck: Path, address: str, out: Path) -> tuple[float, float, float, int]:
    """Wall seconds, driver peak RSS [MiB], driver CPU seconds and resume-record bytes of one sweep."""
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-c", DRIVER, str(deck), "-o", str(out), "--scheduler", address,
                          "--quiet", "--max-work", "86400"], cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if res.returncode not in (0, 1):
        sys.exit(f"sweep failed ({res.returncode}): {res.stderr.strip()[-2000:]}")
    rss, cpu = re.findall(r"maxrss_kib (\d+) cpu_s ([0-9.]+)", res.stderr)[-1]
    record = sum(f.stat().st_size for f in (out / f"{deck.stem}.sweep").glob("*"))
    return wall, int(rss) / 1024, float(cpu), record


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--linkages", type=int, default=10**7)
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    args = ap.parse_args()
    if shutil.which("dask", path=str(BIN)) is None:
        sys.exit("dask is not installed in this environment: pip install '.[dask]'")
    print(f"cpu count {os.cpu_count()}, load average {os.getloadavg()[0]:.1f} at start")
    rates: dict[int, float] = {}
    record_per = driver_per = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        deck, n = big_deck(tmp, args.linkages)
        print(f"four-bar design search, {n} linkages (summaries only), on `dask scheduler` + "
              f"`dask worker --nthreads 1` processes on 127.0.0.1")
        for w in args.workers:
            address, procs = cluster(w, tmp)
            try:
                wall, mib, cpu, record = run(deck, address, tmp / f"out{w}")
            finally:
                stop(procs)
            rates[w] = n / wall
            record_per, driver_per = record / n, cpu / n
            print(f"  {w} worker{'s' if w > 1 else ' '}: {wall:7.1f} s wall  {n / wall:9.0f} linkages/s  "
                  f"{n / wall / w:9.0f} per worker;  driver: peak memory {mib:4.0f} MiB, CPU {cpu:5.1f} s;  "
                  f"resume record {record / n:5.1f} bytes/linkage")
            shutil.rmtree(tmp / f"out{w}", ignore_errors=True)
    w = max(rates)
    per_worker = rates[w] / w
    n9 = 10**9
    hours = n9 / per_worker / 3600
    floor = driver_per * n9 / 60       # the one driver receives and writes every chunk
    print(f"10^9 linkages at {per_worker:.0f} linkages/s per worker: {hours:.1f} worker-hours; "
          f"the driver's own work (receiving and writing rows, {1e9 * driver_per:.0f} ns/linkage) bounds the wall "
          f"time below by {floor:.0f} min: {max(hours * 60 / 16, floor):.0f} min on 16 workers, "
          f"{max(hours * 60 / 64, floor):.0f} min on 64; {n9 // 16384} chunks of 16 384 for the scheduler; "
          f"resume record ~{record_per * n9 / 1e9:.1f} GB on the client's disk; driver memory flat")
    print(f"load average {os.getloadavg()[0]:.1f} at the end")


if __name__ == "__main__":
    main()
