"""Benchmark: design searches at kernel speed (issue 13) and sweep parallelism.

1. The four-bar batch summary kernel alone (fortran/fourbar_summary.f90 through
   fourbar.summarise_batch): linkages per second on one core, median of 3, CPU time.
2. The shipped 102 400-linkage design search (inputs/fourbar_design_search.dat) through the
   sweep engine with 1 and 2 workers: wall time, rate, and the ratio of wall time to the pure
   batch-kernel time of the same designs measured in this run (target: within 2x).
3. With --big: a 10^7-linkage search (the same deck, 2442 crank values) on 2 workers in a
   fresh process: wall time (target < 120 s) and the driver's peak memory (target < 1 GiB).
4. Slider-crank material x speed matrix (per-case path) with 1 and 2 workers (target >= 1.8x).

Rates on a loaded machine are noisy: the kernel-only rate is CPU time of this process (not
wall time), the sweep rates are wall time; both are printed with the load average.

    .venv/bin/python bench/bench_sweep.py [--big] [--skip-slidercrank]
"""
from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from driver import fourbar, sweep  # noqa: E402
from driver.deck import read_deck, validate  # noqa: E402

DESIGN = ROOT / "inputs" / "fourbar_design_search.dat"


def design_columns(deck: Path) -> tuple[object, dict[str, np.ndarray]]:
    """The design search's base Params and its swept columns (every case)."""
    d = read_deck(deck)
    sw = validate(d.groups["sweep"], sweep.SPEC, d.path)
    base = validate(d.groups["fourbar"], fourbar.SPEC, d.path)
    axes = sweep._axes(sw, "fourbar", fourbar.SPEC)
    from driver.sweep_batch import Grid
    g = Grid([a[0] for a in axes], [a[1] for a in axes], False)
    return base, {k.partition(".")[2]: v for k, v in g.columns(0, g.n).items()}


def kernel_rate(base, cols: dict[str, np.ndarray]) -> float:
    """Median CPU seconds of summarise_batch over all the designs (3 runs)."""
    times = []
    for _ in range(3):
        t0 = time.process_time()
        fourbar.summarise_batch(base, cols)
        times.append(time.process_time() - t0)
    return statistics.median(times)


def timed_sweep(path: Path, out: Path, jobs: int, cpu: bool = False) -> float:
    """Wall time of a sweep (or, with ``cpu``, this process's CPU time: meaningful for jobs = 1)."""
    deck = read_deck(path)
    clock = time.process_time if cpu else time.perf_counter
    t0 = clock()
    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
        status = sweep.run_sweep_deck(deck, out, [], False, False, quiet=True, jobs=jobs)
    assert status in (0, 1), status
    return clock() - t0


BIG = """
import json, resource, sys, time
from pathlib import Path
from driver import sweep
from driver.deck import read_deck
deck = read_deck(Path(sys.argv[1]))
t0 = time.perf_counter()
status = sweep.run_sweep_deck(deck, Path(sys.argv[2]), [], False, False, quiet=True, jobs=2)
me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({"seconds": time.perf_counter() - t0, "status": status, "maxrss_kib": me.ru_maxrss,
                  "cpu": me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime}))
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--big", action="store_true", help="also the 10^7-linkage search (minutes)")
    ap.add_argument("--skip-slidercrank", action="store_true")
    args = ap.parse_args()
    print(f"cpu count {os.cpu_count()}, load average {os.getloadavg()[0]:.1f} at start")
    base, cols = design_columns(DESIGN)
    n = len(next(iter(cols.values())))
    k = kernel_rate(base, cols)
    print(f"four-bar batch summary kernel, {n} linkages, one core (CPU time, median of 3)")
    print(f"  {k:7.2f} s  {n / k:9.0f} linkages/s  {1e6 * k / n:6.2f} us/linkage")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        c1 = statistics.median(timed_sweep(DESIGN, tmp / f"c1{i}", 1, cpu=True) for i in range(3))
        t1 = min(timed_sweep(DESIGN, tmp / f"d1{i}", 1) for i in range(2))
        t2 = min(timed_sweep(DESIGN, tmp / f"d2{i}", 2) for i in range(2))
        print(f"design search {DESIGN.name} ({n} linkages)")
        print(f"  1 worker, CPU time  : {c1:7.2f} s  {n / c1:9.0f} linkages/s per core; "
              f"sweep / kernel CPU time {c1 / k:4.2f} (target <= 2)")
        print(f"  1 worker, wall time : {t1:7.2f} s  {n / t1:9.0f} linkages/s (best of 2)")
        print(f"  2 workers, wall time: {t2:7.2f} s  {n / t2:9.0f} linkages/s (best of 2)")
        print(f"  targets: >= 100 000 linkages/s on 2 cores: wall {'met' if n / t2 >= 1e5 else 'NOT met'}, "
              f"from CPU time (2 idle cores) {'met' if 2 * n / c1 >= 1e5 else 'NOT met'}; "
              f"sweep within 2x of the kernel: {'met' if c1 <= 2 * k else 'NOT met'}")
        if args.big:
            big = tmp / "big.dat"
            big.write_text(DESIGN.read_text().replace("count1 = 25", "count1 = 2442"))
            res = subprocess.run([sys.executable, "-c", BIG, str(big), str(tmp / "big")], capture_output=True,
                                 text=True, cwd=ROOT)
            r = json.loads(res.stdout.strip().splitlines()[-1])
            nb = 2442 * 64 * 64
            mib = r["maxrss_kib"] / 1024
            print(f"10^7 search ({nb} linkages), 2 workers: {r['seconds']:.1f} s wall, {nb / r['seconds']:.0f} linkages/s; "
                  f"CPU {r['cpu']:.1f} s (driver + workers), so {r['cpu'] / 2:.1f} s on 2 idle cores; "
                  f"driver peak memory {mib:.0f} MiB")
            print(f"  target < 120 s: wall {'met' if r['seconds'] < 120 else 'NOT met'}, "
                  f"CPU / 2 {'met' if r['cpu'] / 2 < 120 else 'NOT met'}; "
                  f"memory < 1 GiB: {'met' if mib < 1024 else 'NOT met'}")
        deck = ROOT / "inputs" / "slidercrank_matrix_sweep.dat"
        if not args.skip_slidercrank and deck.exists():
            s1 = statistics.median(timed_sweep(deck, tmp / f"s1{i}", 1) for i in range(3))
            s2 = statistics.median(timed_sweep(deck, tmp / f"s2{i}", 2) for i in range(3))
            print(f"slider-crank matrix ({deck.name}), median of 3 runs")
            print(f"  1 worker : {s1:7.2f} s")
            print(f"  2 workers: {s2:7.2f} s   speed-up {s1 / s2:4.2f}x, efficiency {s1 / s2 / 2:5.1%}")
            print(f"  target: speed-up >= 1.8x on 2 cores: {'met' if s1 / s2 >= 1.8 else 'NOT met'}")
    print(f"load average {os.getloadavg()[0]:.1f} at the end")


if __name__ == "__main__":
    main()
