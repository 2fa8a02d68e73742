"""Benchmark: the nonlinear (co-rotational) rod kernel against the linear KED kernel, same case,
same process.

Case (issue 29): the paper's aluminium rod, 700 elements, 1440 steps per revolution, 4
revolutions at 29.32 rad/s (the buckled regime: about 1.7 Newton solves a step), Rayleigh
damping 2 %, quasi-static start, HHT-alpha -0.05, the last revolution recorded.  Target: the
nonlinear run within 25x the linear model's time for the same revolutions.  CPU time of this
process, the two kernels called alternately, medians of ``--repeat`` runs each; the ratio, not
the absolute time, is the claim (note the load: the script prints os.getloadavg()).  Also a row
of bench/run_all.py.

Run:  .venv/bin/python bench/bench_slidercrank_nl.py  [--smoke]
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from driver.slidercrank import MATERIALS, rayleigh
from driver.slidercrank import _kernel as slidercrank_kernel

R2, LEN, M_S, OMEGA = 0.125, 0.505, 0.95, 29.32
TARGET_RATIO = 25.0
SPR = 1440


def case(n_el: int, revs: int, omega: float = OMEGA, spr: int = SPR) -> tuple[Callable[[], dict], Callable[[], dict]]:
    """The linear and the nonlinear kernel call of the benchmark case (last revolution recorded)."""
    mat = MATERIALS["aluminium"]
    rho_a, ea = mat["density"] * mat["area"], mat["youngs_modulus"] * mat["area"]
    ei, half = mat["youngs_modulus"] * mat["second_moment"], mat["section_depth"] / 2
    wb, wa, _ = slidercrank_kernel.slidercrank_frequencies(rho_a, ea, ei, LEN, M_S)
    alpha, beta = rayleigh(0.02, wb, wa)
    dt = 2 * math.pi / (omega * spr)
    steps, rec = revs * spr, (revs - 1) * spr

    def linear() -> dict:
        return slidercrank_kernel.slidercrank_simulate(n_el, R2, LEN, rho_a, ea, ei, half, M_S, omega, dt, steps, rec, spr + 1,
                                            alpha, beta)

    def nonlinear() -> dict:
        return slidercrank_kernel.slidercrank_nl_simulate(n_el, R2, LEN, rho_a, ea, ei, half, M_S, omega, dt, steps, spr, rec,
                                               spr + 1, alpha, beta, hht=-0.05)

    return linear, nonlinear


def cpu_medians(a: Callable[[], object], b: Callable[[], object], repeat: int) -> tuple[float, float]:
    """Median CPU time [s] of this process for one call of ``a`` and one of ``b``, called
    alternately (after one warm-up call of each): other processes' load does not count."""
    a()
    b()
    ta, tb = [], []
    for _ in range(repeat):
        t0 = time.process_time()
        a()
        ta.append(time.process_time() - t0)
        t0 = time.process_time()
        b()
        tb.append(time.process_time() - t0)
    return statistics.median(ta), statistics.median(tb)


def main(argv: list[str] | None = None) -> dict[str, float]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--smoke", action="store_true", help="tiny case (40 elements, 2 revolutions, 1 repeat)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--omega", type=float, default=OMEGA, help="crank speed [rad/s] (default: the buckled 29.32)")
    args = ap.parse_args(argv)
    n_el, revs, repeat = (40, 2, 1) if args.smoke else (700, 4, args.repeat)
    omega = args.omega
    linear, nonlinear = case(n_el, revs, omega)
    check = nonlinear()
    assert check["status"] == 0, check["status"]
    steps = revs * SPR
    t_lin, t_nl = cpu_medians(linear, nonlinear, repeat)
    ratio = t_nl / t_lin
    solves = int(check["stats"][0]) / steps
    load = os.getloadavg()[0]
    print(f"slider-crank nonlinear vs linear rod: {n_el} elements, {revs} revolutions x {SPR} steps at {omega} rad/s "
          f"(CPU time, median of {repeat} interleaved; load {load:.2f})")
    print(f"  linear KED kernel      {1e3 * t_lin:10.1f} ms  ({1e3 * t_lin / revs:.1f} ms per revolution)")
    print(f"  nonlinear kernel       {1e3 * t_nl:10.1f} ms  ({1e3 * t_nl / revs:.1f} ms per revolution, "
          f"{solves:.2f} Newton solves per step)")
    print(f"  ratio nonlinear/linear {ratio:10.1f} x   target <= {TARGET_RATIO:g} x: "
          f"{'met' if ratio <= TARGET_RATIO else 'NOT met'}")
    return {"linear_s": t_lin, "nonlinear_s": t_nl, "ratio": ratio, "target_ratio": TARGET_RATIO,
            "solves_per_step": solves}


if __name__ == "__main__":
    main()
