"""Benchmark: design searches at kernel speed (issue 13) and sweep parallelism.

1. The four-bar batch summary kernel alone (fortran/fourbar_summary.f90 through
   fourbar.summarise_batch): linkages per second on one core, median of 3, CPU time.
2. The shipped 102 400-linkage design search (inputs/fourbar_design_search.dat) through the
   sweep engine with 1 and 2 workers: wall time, rate, and the ratio of wall time to the pure
   batch-kernel time of the same designs measured in this run (target: within 2x).
3. With --big: a 10^7-linkage search (the same deck, 2442 crank values) on 2 workers in a
   fresh process: wall time (target < 120 s) and the driver's peak memory (target < 1 GiB).
4. Slider-crank material x speed matrix (per-case path) with 1 and 2 workers (target >= 1.8x),
   each run in a fresh process, with CPU-time accounting (the machine is shared, so wall times
   alone mislead): the CPU time of every case in its worker (from the resume record), the
   driver's own CPU time, the workers' CPU time beyond their cases (start-up, imports,
   transfer), and the speed-up these predict on two idle cores, beside the measured one.

Rates on a loaded machine are noisy: the kernel-only rate is CPU time of this process (not
wall time), the sweep rates are wall time; both are printed with the load average.

    .venv/bin/python bench/bench_sweep.py [--big] [--skip-slidercrank]
"""
from __future__ import annotations

import argparse
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
from driver._deck import read_deck, validate  # noqa: E402

DESIGN = ROOT / "inputs" / "fourbar_design_search.dat"


def design_columns(deck: Path) -> tuple[object, dict[str, np.ndarray]]:
    """The design search's base Params and its swept columns (every case)."""
    d = read_deck(deck)
    sw = validate(d.groups["sweep"], sweep.SPEC, d.path)
    base = validate(d.groups["fourbar"], fourbar.SPEC, d.path)
    from driver.sweep._spec import Grid, swept_axes
    axes = swept_axes(sw, "fourbar", fourbar.SPEC)
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
    status = sweep.run_sweep_deck(deck, out, [], False, False, jobs=jobs).status
    assert status in (0, 1), status
    return clock() - t0


BIG = """
import json, resource, sys, time
from pathlib import Path
from driver import sweep
from driver._deck import read_deck
deck = read_deck(Path(sys.argv[1]))
t0 = time.perf_counter()
status = sweep.run_sweep_deck(deck, Path(sys.argv[2]), [], False, False, jobs=2).status
me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({"seconds": time.perf_counter() - t0, "status": status, "maxrss_kib": me.ru_maxrss,
                  "cpu": me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime}))
"""


CASES = """
import json, resource, sys, time
from pathlib import Path
import pyarrow.parquet as pq
from driver import sweep
from driver._deck import read_deck
deck = read_deck(Path(sys.argv[1]))
out, jobs = Path(sys.argv[2]), int(sys.argv[3])
t0, c0 = time.perf_counter(), time.process_time()
outcome = sweep.run_sweep_deck(deck, out, [], False, False, jobs=jobs)
status = outcome.status
wall, me = time.perf_counter() - t0, time.process_time() - c0
kids = resource.getrusage(resource.RUSAGE_CHILDREN)
rows = {}
for p in sorted((out / (deck.path.stem + ".sweep")).glob("part-*.parquet")):
    t = pq.read_table(p, columns=["case", "cpu", "seconds"]).to_pydict()
    rows.update({c: (cpu, s) for c, cpu, s in zip(t["case"], t["cpu"], t["seconds"])})
print(json.dumps({"status": status, "wall": wall, "driver_cpu": me, "workers_cpu": kids.ru_utime + kids.ru_stime,
                  "cases": rows, "phases": outcome.phases}))
"""


def case_run(deck: Path, out: Path, jobs: int) -> dict:
    """One per-case sweep in a fresh process: wall, driver CPU, workers' CPU, per-case CPU."""
    res = subprocess.run([sys.executable, "-c", CASES, str(deck), str(out), str(jobs)], capture_output=True,
                         text=True, cwd=ROOT, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def list_schedule(costs: list[float], workers: int) -> float:
    """Makespan of running ``costs`` in this order, each on the first free worker."""
    free = [0.0] * workers
    for c in costs:
        i = free.index(min(free))
        free[i] += c
    return max(free)


def slidercrank_matrix(tmp: Path) -> None:
    """Wall times, and the CPU-time accounting that predicts the speed-up on two idle cores:
    one worker runs in the driver's process (prepare + cases + finish, all serial); with two,
    the driver prepares and finishes alone and the cases run on two workers (their makespan
    from each case's CPU time, in the order the engine started them), the driver's own CPU
    while they run and the workers' CPU beyond their cases sharing the two cores."""
    deck = ROOT / "inputs" / "slidercrank_matrix_sweep.dat"
    one = [case_run(deck, tmp / f"s1{i}", 1) for i in range(3)]
    two = [case_run(deck, tmp / f"s2{i}", 2) for i in range(3)]
    med = lambda runs, f: statistics.median(f(r) for r in runs)
    w1, w2 = med(one, lambda r: r["wall"]), med(two, lambda r: r["wall"])
    print(f"slider-crank matrix ({deck.name}, 18 cases), a fresh process per run, median of 3")
    print(f"  wall time : 1 worker {w1:6.2f} s, 2 workers {w2:6.2f} s   measured speed-up {w1 / w2:4.2f}x "
          f"(load average {os.getloadavg()[0]:.1f}: wall times on a shared machine are not the idle ones)")
    ph = lambda key: (lambda r: r["phases"][key])
    cases = lambda r: [r["cases"][str(k)][0] for k in sorted(map(int, r["cases"]))]
    prep1, run1, fin1 = med(one, ph("prepare_cpu")), med(one, ph("run_cpu")), med(one, ph("finish_cpu"))
    prep2, drv2, fin2 = med(two, ph("prepare_cpu")), med(two, ph("run_cpu")), med(two, ph("finish_cpu"))
    total2 = med(two, lambda r: sum(cases(r)))
    extra2 = med(two, lambda r: r["workers_cpu"] - sum(cases(r)))
    span2 = med(two, lambda r: list_schedule(cases(r), 2))
    print("  CPU time [s]     prepare   cases (sum)   driver while running   workers beyond cases   finish")
    print(f"  1 worker         {prep1:7.2f}   {run1:11.2f}   (in the cases)         -                      {fin1:6.2f}")
    print(f"  2 workers        {prep2:7.2f}   {total2:11.2f}   {drv2:20.2f}   {extra2:20.2f}   {fin2:6.2f}")
    run2 = max(span2, (total2 + drv2 + max(extra2, 0.0)) / 2)
    pred1, pred2 = prep1 + run1 + fin1, prep2 + run2 + fin2
    print(f"  cases on 2 workers: makespan {span2:.2f} s (ideal {total2 / 2:.2f} s); prepare + finish "
          f"{prep2 + fin2:.2f} s run alone (Amdahl: at most {(prep1 + run1 + fin1) / (prep2 + fin2 + run1 / 2):.2f}x)")
    print(f"  on 2 idle cores (from CPU times): 1 worker {pred1:.2f} s, 2 workers {pred2:.2f} s = {pred1 / pred2:4.2f}x "
          f"(target >= 1.8x: {'met' if pred1 / pred2 >= 1.8 else 'NOT met'}); measured wall: "
          f"{'met' if w1 / w2 >= 1.8 else 'NOT met'}")


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
        print(f"  -j 2, wall time     : {t2:7.2f} s  {n / t2:9.0f} linkages/s (best of 2; a search this small runs "
              "in the driver when the worker pool would not pay, see driver.sweep._executor.POOL_MIN_SECONDS)")
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
        if not args.skip_slidercrank:
            slidercrank_matrix(tmp)
    print(f"load average {os.getloadavg()[0]:.1f} at the end")


if __name__ == "__main__":
    main()
