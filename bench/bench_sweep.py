"""Benchmark: sweep execution (issue 6).

1. Four-bar design grid (summary only per case, as the design-search deck): cases per
   second with 1 and 2 workers, parallel efficiency, and the per-case overhead of the
   sweep machinery against a plain in-process loop over the same cases (baseline
   measured in the same run).  Also the effect of the chunk size.
2. Slider-crank material x speed matrix (inputs/slidercrank_matrix_sweep.dat), with 1
   and 2 workers: speed-up and efficiency.

Targets: per-case overhead below 1 ms for chunked small cases; at least 1.8x speed-up
on 2 cores for the slider-crank matrix.

    .venv/bin/python bench/bench_sweep.py [--n 10000] [--skip-slidercrank]
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import tempfile
import time
from pathlib import Path

from driver import sweep
from driver.deck import read_deck, validate

ROOT = Path(__file__).resolve().parents[1]


def grid_deck(folder: Path, n: int, chunk: int = 0) -> Path:
    k = max(2, round(n ** (1 / 3)))
    text = f"""&fourbar fixed_link = 12.0, crank = 3.0, coupler = 15.0, rocker = 9.0, omega = 5.0, step_deg = 10 /
&sweep key1 = 'fourbar.crank', start1 = 1, stop1 = 7, count1 = {k}
       key2 = 'fourbar.coupler', start2 = 6, stop2 = 20, count2 = {k}
       key3 = 'fourbar.rocker', start3 = 4, stop3 = 16, count3 = {k}
       keep = 'meets_band_40_120 and rocker_swing_deg >= 60'
       case_outputs = 'none', summary_rows = 'kept', chunk = {chunk} /
"""
    path = folder / f"grid_{chunk}.dat"
    path.write_text(text)
    return path


def timed_sweep(path: Path, out: Path, jobs: int) -> float:
    deck = read_deck(path)
    t0 = time.perf_counter()
    import contextlib
    import io
    with contextlib.redirect_stderr(io.StringIO()):   # per-case physics warnings are not the point here
        status = sweep.run_sweep_deck(deck, out, [], False, False, quiet=True, jobs=jobs)
    elapsed = time.perf_counter() - t0
    assert status in (0, 1, 2)
    return elapsed


def plain_loop(path: Path) -> tuple[float, int]:
    """Baseline: the same cases' summaries in a plain loop, no sweep machinery."""
    from driver import fourbar
    deck = read_deck(path)
    sw = validate(deck.groups["sweep"], sweep.SPEC, deck.path)
    cases = sweep.build_cases(sw, "fourbar", fourbar.SPEC)
    raw = deck.groups["fourbar"]
    t0 = time.perf_counter()
    for c in cases:
        p = validate(sweep._case_raw(raw, c), fourbar.SPEC, deck.path)
        try:
            fourbar.summarise(p)
        except Exception:
            pass
    return time.perf_counter() - t0, len(cases)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="four-bar grid size (10^5 for the full deck)")
    ap.add_argument("--skip-slidercrank", action="store_true")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = grid_deck(tmp, args.n)
        base, n = plain_loop(path)
        t1 = timed_sweep(path, tmp / "o1", 1)
        t2 = timed_sweep(path, tmp / "o2", 2)
        print(f"four-bar grid, {n} linkages (summary per case), cpu count {os.cpu_count()}")
        print(f"  plain loop (baseline)  : {base:7.2f} s  {n / base:8.0f} cases/s  {1e3 * base / n:6.3f} ms/case")
        print(f"  sweep, 1 worker        : {t1:7.2f} s  {n / t1:8.0f} cases/s  overhead {1e3 * (t1 - base) / n:+6.3f} ms/case")
        print(f"  sweep, 2 workers       : {t2:7.2f} s  {n / t2:8.0f} cases/s  speed-up {t1 / t2:4.2f}x, efficiency {t1 / t2 / 2:5.1%}")
        over = (t1 - base) / n
        print(f"  target: per-case overhead < 1 ms: {'met' if over < 1e-3 else 'NOT met'} ({1e3 * over:.3f} ms)")
        print("  chunk size (2 workers): chunk, seconds, overhead per case vs plain loop / 2")
        for chunk in (1, 10, 100, 0):
            p = grid_deck(tmp, min(n, 4000), chunk)
            b, m = plain_loop(p)
            t = timed_sweep(p, tmp / f"c{chunk}", 2)
            label = "auto" if chunk == 0 else str(chunk)
            print(f"    {label:>5}  {t:7.2f} s   {1e3 * (t - b / 2) / m:+7.3f} ms/case")
        deck = ROOT / "inputs" / "slidercrank_matrix_sweep.dat"
        if not args.skip_slidercrank and deck.exists():
            s1 = statistics.median(timed_sweep(deck, tmp / f"s1{k}", 1) for k in range(3))
            s2 = statistics.median(timed_sweep(deck, tmp / f"s2{k}", 2) for k in range(3))
            print(f"slider-crank matrix ({deck.name}), median of 3 runs")
            print(f"  1 worker : {s1:7.2f} s")
            print(f"  2 workers: {s2:7.2f} s   speed-up {s1 / s2:4.2f}x, efficiency {s1 / s2 / 2:5.1%}")
            print(f"  target: speed-up >= 1.8x on 2 cores: {'met' if s1 / s2 >= 1.8 else 'NOT met'}")


if __name__ == "__main__":
    main()
