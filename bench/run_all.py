"""Every kernel benchmark in one table: cost per unit, ratio against its numpy baseline
measured in the same run, and the target.

    .venv/bin/python bench/run_all.py            # full sizes (about a minute on an idle machine)
    .venv/bin/python bench/run_all.py --quick    # smaller sizes and fewer repeats

Kernel and baseline calls are interleaved (kernel, baseline, kernel, ...), timed by the
process's CPU time, and the median of each is taken, so a machine whose load changes
during the run slows both alike and the ratio stays meaningful.  Each baseline is checked against its kernel before timing
(except the nonlinear rod's, whose baseline is the other model: tests/test_slidercrank_nonlinear.py compares them).  The
detailed per-study benchmarks (bench_<study>.py) remain for the wider measurements
(fresh vs reused buffers, searches, sweeps).  Exit status 0 whether or not targets are met:
this reports, the test suite guards (tests/test_vectorisation.py).
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bench_fourbar
import bench_fourbar_forces
import bench_linkage
import bench_manipulator
import bench_slidercrank
import bench_slidercrank_nl
import bench_startup
import bench_ujoint
import closed_form
from driver import ujoint as ujoint_study
from driver.fourbar import _kernel as fourbar_kernel
from driver.manipulator import _kernel as manipulator_kernel
from driver.slidercrank import MATERIALS, rayleigh
from driver.slidercrank import _kernel as slidercrank_kernel
from driver.ujoint import _kernel as ujoint_kernel


@dataclass
class Row:
    """One benchmark line: cost per unit [s] of the kernel and its baseline, and targets."""
    name: str
    unit: str
    kernel_s: float
    baseline_s: float
    target_s: float | None        # at most this many seconds per unit
    target_ratio: float | None    # at least this many times faster than the baseline
    limit: str                    # what bounds the kernel
    floor_s: float | None = None  # time to just write the kernel's outputs (numpy fill), same run

    @property
    def ratio(self) -> float:
        return self.baseline_s / self.kernel_s

    def met(self) -> bool:
        return ((self.target_s is None or self.kernel_s <= self.target_s)
                and (self.target_ratio is None or self.ratio >= self.target_ratio))


def interleaved(kernel: Callable[[], object], baseline: Callable[[], object], repeat: int,
                kernel_per_round: int = 1, baseline_per_round: int = 1) -> tuple[float, float]:
    """Median CPU time [s] of this process for one kernel call and one baseline call,
    measured alternately (after one warm-up call of each).  CPU time, not wall time: on a
    shared machine other processes' load then does not count (their cache and memory
    traffic still does, which the interleaving spreads over both sides)."""
    kernel()
    baseline()
    tk, tb = [], []
    for _ in range(repeat):
        t0 = time.process_time()
        for _ in range(kernel_per_round):
            kernel()
        tk.append((time.process_time() - t0) / kernel_per_round)
        t0 = time.process_time()
        for _ in range(baseline_per_round):
            baseline()
        tb.append((time.process_time() - t0) / baseline_per_round)
    return statistics.median(tk), statistics.median(tb)


def write_floor(fill: Callable[[], object], repeat: int) -> float:
    """Median CPU time [s] of writing the same output bytes with numpy (a memory-traffic floor)."""
    fill()
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        fill()
        times.append(time.process_time() - t0)
    return statistics.median(times)


def fourbar(n: int, repeat: int) -> list[Row]:
    theta = np.linspace(0.0, 2 * np.pi, n)
    link = (12.0, 5.0, 15.0, 9.0, 5.0, 0.0)
    out = np.empty((n, 11), order="F")
    sts = np.empty(n, dtype=np.int32)
    fourbar_kernel.fourbar_exact(theta, *link, out=out, status=sts)
    ref = bench_fourbar.numpy_baseline(theta, *link, 1)
    for j in range(11):
        np.testing.assert_allclose(out[:, j], ref[j], rtol=1e-9, atol=1e-9)
    tk, tb = interleaved(lambda: fourbar_kernel.fourbar_exact(theta, *link, out=out, status=sts),
                         lambda: bench_fourbar.numpy_baseline(theta, *link, 1), repeat)
    floor = write_floor(lambda: (out.fill(0.0), sts.fill(0)), repeat)
    rows = [Row("four-bar exact states (reused buffers)", "ns/position", tk / n, tb / n, 20e-9, 5.0,
                "writes 92 B/position (11 float64 + int32 status); "
                "1 sincos + 3 atan2 + 20 divisions (9 of them in the atan2) + 1 sqrt",
                floor / n)]
    # issue 27: a caller that calls again and again passes out= buffers; the baseline is the default
    # path (no out=), new memory each call (first touch: page faults, above numpy's small-block cache)
    fourbar_kernel.fourbar_exact(theta, *link, out=out, status=sts)   # (the floor above zeroed it)
    np.testing.assert_array_equal(fourbar_kernel.fourbar_exact(theta, *link)[0], out)
    tk, tb = interleaved(lambda: fourbar_kernel.fourbar_exact(theta, *link, out=out, status=sts),
                         lambda: fourbar_kernel.fourbar_exact(theta, *link), repeat)
    rows.append(Row("four-bar exact, out= buffers vs fresh arrays", "ns/position",
                    tk / n, tb / n, None, 1.3 if 92 * n >= 1 << 20 else None,
                    "out= reuses the caller's buffers; the baseline's extra cost is the first touch of 92 B/position "
                    "of new memory (page faults)",
                    floor / n))
    u, v = 4.0, 2.0

    def coupler_numpy():
        c2, s2 = np.cos(out[:, 0]), np.sin(out[:, 0])
        rx, ry = u * c2 - v * s2, u * s2 + v * c2
        c, s = np.cos(theta), np.sin(theta)
        w2, a2 = out[:, 7], out[:, 9]
        q, om = link[1], link[4]
        return (out[:, 3] + rx, out[:, 4] + ry, -q * om * s - w2 * ry, q * om * c + w2 * rx,
                -q * om * om * c - a2 * ry - w2 * w2 * rx, -q * om * om * s + a2 * rx - w2 * w2 * ry)

    got = fourbar_kernel.fourbar_coupler_point(theta, out, sts, link[1], link[4], link[5], u, v)
    for j, col in enumerate(coupler_numpy()):
        np.testing.assert_allclose(got[:, j], col, rtol=1e-9, atol=1e-9)
    tk, tb = interleaved(lambda: fourbar_kernel.fourbar_coupler_point(theta, out, sts, link[1], link[4], link[5], u, v),
                         coupler_numpy, repeat)
    floor = write_floor(lambda: np.empty((n, 6), order="F").fill(0.0), repeat)
    rows.append(Row("four-bar coupler point", "ns/position", tk / n, tb / n, None, None,
                    "reads 44 B, writes 48 B/position (fresh array); 2 sincos", floor / n))
    # issue 26: the force kernel against the kinematics kernel it follows (the 'baseline' here),
    # both with fresh output arrays; target ratio 0.5 = forces cost at most 2x the kinematics
    lk = (0.30, 0.10, 0.35, 0.25, 20.0, 3.0)
    pr = bench_fourbar_forces.PROPS
    st_out, st_sts = fourbar_kernel.fourbar_exact(theta, *lk, 1)
    f = fourbar_kernel.fourbar_joint_forces(st_out, st_sts, *lk, pr)
    ok = st_sts == 0
    np.testing.assert_allclose(f[ok], bench_fourbar_forces.numpy_forces(st_out, *lk, pr)[ok], rtol=1e-9, atol=1e-9)
    tk, tb = interleaved(lambda: fourbar_kernel.fourbar_joint_forces(st_out, st_sts, *lk, pr),
                         lambda: fourbar_kernel.fourbar_exact(theta, *lk, 1), repeat)
    floor = write_floor(lambda: np.empty((n, 12), order="F").fill(0.0), repeat)
    rows.append(Row("four-bar joint forces (baseline: exact states)", "ns/position", tk / n, tb / n, None, 0.5,
                    "reads 64 B, writes 96 B/position (fresh array); no transcendental function, 8 divisions",
                    floor / n))
    # issue 37: out= as the kinematics kernel has it; both kernels on reused buffers, the force kernel
    # at most 1.5x the kinematics per position and 1.6x its own store floor (numpy filling its buffer)
    fout = np.empty((n, 12), order="F")
    kout, ksts = np.empty((n, 11), order="F"), np.empty(n, dtype=np.int32)
    np.testing.assert_array_equal(fourbar_kernel.fourbar_joint_forces(st_out, st_sts, *lk, pr, out=fout), f)
    tk, tb = interleaved(lambda: fourbar_kernel.fourbar_joint_forces(st_out, st_sts, *lk, pr, out=fout),
                         lambda: fourbar_kernel.fourbar_exact(theta, *lk, 1, out=kout, status=ksts), repeat)
    floor = write_floor(lambda: fout.fill(0.0), repeat)
    # for reference only (the target is the store floor): numpy reading the 8 state columns the kernel
    # reads (64 B) into 8 of its output columns and filling the other 4 (96 B written in all)
    moved = write_floor(lambda: (np.copyto(fout[:, :8], st_out[:, 3:]), fout[:, 8:].fill(0.0)), repeat)
    rows.append(Row("four-bar joint forces, out= (baseline: exact, out=)", "ns/position", tk / n, tb / n, None,
                    1 / 1.5, f"reused buffers both; reads 64 B, writes 96 B/position; target <= 1.5x the kinematics "
                    f"({tk / tb:.2f}x) and <= 1.6x its store floor ({tk / floor:.2f}x); numpy reading its 64 B and "
                    f"writing the 96 B: {moved / n * 1e9:.2f} ns ({tk / moved:.2f}x)", floor / n))
    return rows


def manipulator(n: int, samples: int, repeat: int) -> list[Row]:
    rng = np.random.default_rng(0)
    l1, l2 = rng.uniform(1, 7, n), rng.uniform(1, 7, n)
    th1, th2 = rng.uniform(-np.pi, np.pi, n), rng.uniform(-np.pi, np.pi, n)
    qd = np.asfortranarray(rng.uniform(-2, 2, (n, 2)))
    qdd = np.asfortranarray(rng.uniform(-2, 2, (n, 2)))
    m1, m2 = 10 * l1, 10 * l2
    ker = manipulator_kernel.manipulator_arm_states(l1, l2, th1, th2, qd, qdd, m1, m2, 9.8)
    ref = bench_manipulator.numpy_arm_states(l1, l2, th1, th2, qd, qdd, m1, m2, 9.8)
    for a, b in zip(ker, ref):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9)
    bufs = tuple(np.empty(shape, order="F") for shape in ((n, 4), n, n, (n, 2)))
    tk, tb = interleaved(lambda: manipulator_kernel.manipulator_arm_states(l1, l2, th1, th2, qd, qdd, m1, m2, 9.8, out=bufs),
                         lambda: bench_manipulator.numpy_arm_states(l1, l2, th1, th2, qd, qdd, m1, m2, 9.8),
                         repeat)
    fresh = write_floor(lambda: manipulator_kernel.manipulator_arm_states(l1, l2, th1, th2, qd, qdd, m1, m2, 9.8), repeat)
    floor = write_floor(lambda: [b.fill(0.0) for b in bufs], repeat)
    rows = [Row("2R manipulator: Jacobian, w, kappa, torques", "us/config", tk / n, tb / n, 0.04e-6, None,
                f"reused buffers; reads 80 B, writes 64 B/config; 2 sincos + 1 division + 1 sqrt; "
                f"with fresh output arrays {1e6 * fresh / n:.3f} us/config (their page faults)", floor / n)]
    a1, a2 = rng.uniform(-np.pi, np.pi, 4), rng.uniform(-np.pi, np.pi, 4)
    dl = np.asfortranarray(rng.uniform(-1e-3, 1e-3, (samples, 2)))
    np.testing.assert_allclose(manipulator_kernel.manipulator_position_errors(a1, a2, dl),
                               bench_manipulator.numpy_position_errors(a1, a2, dl), rtol=1e-12)
    tk, tb = interleaved(lambda: manipulator_kernel.manipulator_position_errors(a1, a2, dl),
                         lambda: bench_manipulator.numpy_position_errors(a1, a2, dl), repeat)
    rows.append(Row("2R manipulator: position errors, 4 points", "ns/sample", tk / samples, tb / samples,
                    None, None, "reads 16 B, writes 16 B/sample; 4 x 10 flops"))
    nb = max(64, n // 10)
    tb, tc = bench_manipulator.design_batch(nb, max(4, min(100, nb // 100)), max(3, repeat // 3))
    rows.append(Row("2R manipulator: design summaries (batch)", "us/design", tb, tc, None, 100.0,
                    f"baseline: one run() per design deck (the per-case path); {1 / tb:.0f} designs/s; "
                    "1000 Monte Carlo samples x 4 flops per design dominate"))
    return rows


def ujoint(repeat: int) -> list[Row]:
    m, beta, phi, rho = bench_ujoint.M, bench_ujoint.BETA, bench_ujoint.PHI, bench_ujoint.RHO
    code = ujoint_kernel.UJOINT_MODELS["exact"]
    f = ujoint_kernel.ujoint_objective(code, 0, beta, phi, rho, m, grad=False)
    f = f[0] if isinstance(f, tuple) else f
    assert math.isclose(f, bench_ujoint.numpy_objective("exact", beta, phi, rho), rel_tol=1e-10)
    tk, tb = interleaved(lambda: ujoint_kernel.ujoint_objective(code, 0, beta, phi, rho, m, grad=False),
                         lambda: bench_ujoint.numpy_objective("exact", beta, phi, rho), repeat,
                         kernel_per_round=200, baseline_per_round=20)
    rows = [Row("Hooke joint: objective, 3 joints x 360 angles", "us/objective", tk, tb, 5e-6, None,
                "180 points (period pi) x 3 joints: 1 division + 1 sqrt per point and joint; "
                "Python call overhead ~1 us")]
    # the batch path of sweeps and &optimize against the per-design kernel calls it replaces
    nd = 64 if repeat <= 2 else 2000
    base, phis = bench_ujoint.batch_designs(nd)
    chain = ujoint_study.Chain(code, ujoint_kernel.UJOINT_OBJECTIVES["mean_square"],
                               np.asarray(base["rho"]) * ujoint_study.DEG, m, 25.0)
    bdeg = np.asarray(base["beta"])
    frame = ujoint_study.summarise_batch(base, {"phi": phis})
    d = ujoint_study.evaluate(chain, "x", bdeg, phis[-1])
    assert (frame["objective"].iloc[-1], frame["pp_ratio"].iloc[-1]) == (d.objective, d.pp)
    tk, tb = interleaved(lambda: ujoint_study.summarise_batch(base, {"phi": phis}),
                         lambda: [ujoint_study.evaluate(chain, "x", bdeg, ph) for ph in phis], repeat)
    rows.append(Row("Hooke joint batch: summary vs per-design calls", "us/design", tk / nd, tb / nd, None, 3.0,
                    "per design: 180 + 360 points x 3 joints (objective grid, then ratio and dR/dtheta) and "
                    "the closed-form angles; the baseline makes 4 kernel calls per design"))
    return rows


def slidercrank(n_el: int, spr: int, base_steps: int, repeat: int) -> list[Row]:
    mat = MATERIALS["aluminium"]
    rho_a, ea = mat["density"] * mat["area"], mat["youngs_modulus"] * mat["area"]
    ei = mat["youngs_modulus"] * mat["second_moment"]
    omega, r2, length, ms = bench_slidercrank.OMEGA, bench_slidercrank.R2, bench_slidercrank.LEN, bench_slidercrank.M_S
    wb, wa, _ = slidercrank_kernel.slidercrank_frequencies(rho_a, ea, ei, length, ms)
    alpha, beta = rayleigh(0.02, wb, wa)
    dt = 2 * math.pi / (omega * spr)

    def kernel(n_steps: int = spr) -> dict:
        return slidercrank_kernel.slidercrank_simulate(n_el, r2, length, rho_a, ea, ei, 1.5e-3, ms, omega, dt, n_steps, 1,
                                            n_steps, alpha, beta)

    base = bench_slidercrank.NumpyKED(n_el, rho_a, ea, ei, omega, dt, alpha, beta)
    ref = kernel(base_steps)["eps_ax"][0]
    np.testing.assert_allclose(base.run(base_steps), ref, rtol=1e-6, atol=1e-12 * np.abs(ref).max())
    tk, tb = interleaved(kernel, lambda: base.run(base_steps), repeat)
    rows = [Row(f"slider-crank: {n_el} elements, {spr} steps", "ms/revolution", tk, tb / base_steps * spr,
                100e-3, 10.0, "sequential banded triangular solves (latency of 2 x 6 multiply-adds per unknown)")]

    # issue 27: the study records the per-step profile it prints, not the three strain/force fields
    def profile() -> dict:
        return slidercrank_kernel.slidercrank_simulate(n_el, r2, length, rho_a, ea, ei, 1.5e-3, ms, omega, dt, spr, 1,
                                            spr, alpha, beta, fields=False)
    full = kernel()
    np.testing.assert_array_equal(profile()["eps_max"], full["eps_ax"].max(axis=0))
    del full
    tk, tb = interleaved(profile, kernel, repeat)
    rows.append(Row("slider-crank: study's record vs all fields", "ms/revolution", tk, tb, None,
                    1.2 if 24 * n_el * spr >= 8 << 20 else None,
                    f"the baseline writes 3 x 8 B per element and step ({24 * n_el * spr / 2**20:.0f} MiB per call, "
                    "fresh memory: page faults); the profile 9 x 8 B per step"))
    return rows


def slidercrank_nl(n_el: int, revs: int, repeat: int) -> list[Row]:
    """The nonlinear (co-rotational) rod against the linear KED kernel on the same case (issue 29:
    at most 25x the linear model's time); the 'baseline' here is the linear kernel."""
    linear, nonlinear = bench_slidercrank_nl.case(n_el, revs)
    res = nonlinear()
    assert res["status"] == 0, res["status"]
    tk, tb = interleaved(nonlinear, linear, repeat)
    solves = res["stats"][0] / (revs * bench_slidercrank_nl.SPR)
    return [Row("slider-crank nonlinear rod (baseline: linear)", "ms/revolution", tk / revs, tb / revs, None,
                1 / bench_slidercrank_nl.TARGET_RATIO,
                f"{n_el} elements at {bench_slidercrank_nl.OMEGA} rad/s, {revs} revolution(s): nonlinear/linear time "
                f"{tk / tb:.1f}x (target <= {bench_slidercrank_nl.TARGET_RATIO:g}x); {solves:.2f} Newton solves per "
                "step, each residual the element forces (a sqrt and an atan2 each), each solve the tangent and a "
                "band LU (a latency chain like the linear model's solves)")]


def shipped_grid() -> np.ndarray:
    """The shipped design search's 102 400 linkages (inputs/fourbar_design_search.dat) as kernel rows."""
    c, k, r = np.meshgrid(np.linspace(1, 7, 25), np.linspace(6, 20, 64), np.linspace(4, 16, 64), indexing="ij")
    m = np.empty((c.size, 8), order="F")
    m[:, 0], m[:, 1], m[:, 2], m[:, 3], m[:, 4], m[:, 5], m[:, 6], m[:, 7] = 12, c.ravel(), k.ravel(), r.ravel(), 5, 0, 360, 1
    return m


def kernel_before(path: str) -> Any:
    """The four-bar summary routine of another build of the kernels (``_kernels*.so``, e.g. a main
    checkout's ``build/cp311/fortran/``), loaded beside this one under another package name."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("before_issue37._kernels", path)
    if spec is None or spec.loader is None:
        raise ImportError(path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.fourbar_summary.summaries


def search(repeat: int, before: str | None, n: int | None = None) -> list[Row]:
    """Issue 37: the design search's summary kernel on the shipped grid.  (1) The closed-form
    passes (class, assembly, toggles, transmission and rocker extremes, swing, time ratio) against
    the same columns in plain numpy (bench/closed_form.py, vectorised over the linkages; checked
    against the kernel first): target at most 3x.  (2) With ``before`` (the kernel build before
    issue 37): the peak-speed pass and the filter passes against that kernel in the same process,
    every figure compared bit for bit first: target >= 2x for the peak pass."""
    m = shipped_grid()
    if n is not None:
        m = np.asfortranarray(m[:: max(1, len(m) // n)])
    P, S = fourbar_kernel.FOURBAR_PASSES, fourbar_kernel.Summary
    closed = P["transmission"] | P["rocker"]
    got = fourbar_kernel.fourbar_summaries(m, closed)
    p, q, r, s = (np.ascontiguousarray(m[:, j]) for j in range(4))
    with np.errstate(divide="ignore", invalid="ignore"):
        ref = closed_form.summary(p, q, r, s)
        ok = ref["grashof"] != closed_form.CHANGE_POINT   # not handled by the numpy form (41 of 102 400)
        for name, col in (("grashof", S.GRASHOF), ("assemblable", S.ASSEMBLABLE), ("toggles_in_range", S.TOGGLES_IN_RANGE),
                          ("rocker_turns", S.ROCKER_TURNS), ("assembled_fraction", S.ASSEMBLED_FRACTION),
                          ("mu_min_deg", S.MU_MIN_DEG), ("mu_max_deg", S.MU_MAX_DEG), ("rocker_min_deg", S.ROCKER_MIN_DEG),
                          ("rocker_max_deg", S.ROCKER_MAX_DEG), ("rocker_swing_deg", S.ROCKER_SWING_DEG),
                          ("time_ratio", S.TIME_RATIO)):
            # 1e-5 deg: figures at a limit position, where the kernel's states are taken 1e-12 rad inside the arc
            np.testing.assert_allclose(np.nan_to_num(got[ok, col]), ref[name][ok], rtol=0, atol=1e-5, err_msg=name)
        tk, tb = interleaved(lambda: fourbar_kernel.fourbar_summaries(m, closed),
                             lambda: closed_form.summary(p, q, r, s), repeat)
    nl = len(m)
    rows = [Row("search: closed-form summary columns (baseline: numpy)", "us/linkage", tk / nl, tb / nl, None, 1 / 3,
                f"shipped grid ({nl} linkages): class, assembly, toggles, transmission and rocker extremes, swing, time "
                f"ratio; target <= 3x the numpy closed form ({tk / tb:.2f}x)")]
    if before is None:
        return rows
    old = kernel_before(before)
    # the class codes were split since (issue 35: change points by which links turn, 6-8 -> 4; chains
    # that cannot move, 9-10 -> 5, the triple-rocker they were counted as); every other figure bit for bit
    was = np.array([0, 1, 2, 3, 4, 5, 4, 4, 4, 5, 5], dtype=float)
    # the peak speeds' roots are Newton's since 2026-12 (docs/performance.md): the speeds to 1e-11
    # relative and their crank angles to 1e-8 deg, except linkages whose transmission angle touches
    # 0 within rounding at the range's end (a toggle the closed-form count misses; 5 on this grid)
    pk = [S.ROCKER_OMEGA_PEAK_RAD_S, S.ROCKER_OMEGA_PEAK_AT_DEG, S.COUPLER_OMEGA_PEAK_RAD_S, S.COUPLER_OMEGA_PEAK_AT_DEG]
    rest = [j for j in range(1, len(S)) if j not in pk]
    for bits in (closed, P["peaks"], closed | P["peaks"]):
        new, before = fourbar_kernel.fourbar_summaries(m, bits), old(m, bits)
        np.testing.assert_array_equal(was[new[:, 0].astype(int)], before[:, 0])
        np.testing.assert_array_equal(new[:, rest], before[:, rest])
        speed, at = new[:, pk[0::2]], new[:, pk[1::2]]
        far = ((np.abs(speed - before[:, pk[0::2]]) > 1e-11 * np.abs(before[:, pk[0::2]]))
               | (np.abs(at - before[:, pk[1::2]]) > 1e-8)).any(axis=1)
        assert far.sum() <= 5 and (new[far, S.MU_MIN_DEG] < 1e-5).all(), np.flatnonzero(far)
    tk, tb = interleaved(lambda: fourbar_kernel.fourbar_summaries(m, P["peaks"]), lambda: old(m, P["peaks"]), repeat)
    rows.append(Row("search: peak-speed pass (baseline: kernel before)", "us/linkage", tk / nl, tb / nl, None, 2.0,
                    "refined peak search of both speeds, a block of linkages per call, Newton roots: the same peaks "
                    "to 1e-11 relative"))
    tk, tb = interleaved(lambda: fourbar_kernel.fourbar_summaries(m, closed), lambda: old(m, closed), repeat)
    rows.append(Row("search: filter passes (baseline: kernel before)", "us/linkage", tk / nl, tb / nl, None, None,
                    "the shipped search's filter (transmission band, swing); the same bits as before"))
    return rows


def table(rows: int, repeat: int) -> list[Row]:
    """Issue 37: the sweep's ``.out`` table of a block of kept rows (the search's columns: case,
    three swept lengths, status, kept, eleven figures), built column by column (one formatting
    call per column: driver/_table.py fixed_cells and render_block) against the same table built
    value by value as before (the baseline: Column.cell per value, render_table per row; the
    same text is asserted first)."""
    import pandas as pd

    from driver._table import render_block, render_table
    from driver.sweep._report import cell_widths, table_cells, table_columns
    rng = np.random.default_rng(0)
    frame = pd.DataFrame({"case": np.arange(1, rows + 1) * 7, **{f"fourbar.{k}": np.round(rng.uniform(1, 20, rows), 4)
                                                                  for k in ("crank", "coupler", "rocker")},
                          "status": "ok", "kept": True,
                          **{f"figure_{j}": rng.standard_normal(rows) * 10.0 ** rng.integers(-2, 4, rows) for j in range(11)}})
    cols, keys = table_columns(frame)

    def per_column() -> list[str]:
        cells = table_cells(frame, cols, keys)
        widths = [max(c.width, len(c.header), n) for c, n in zip(cols, cell_widths(cells))]
        return ["".join(" " * c.sep + c.header.rjust(w) for c, w in zip(cols, widths)).rstrip(),
                *render_block(cols, cells, widths)]

    def per_value() -> list[str]:
        values = [["yes" if v is True else ("-" if isinstance(v, float) and not math.isfinite(v) else v)
                   for v in row] for row in zip(*(frame[k].tolist() for k in keys))]
        return render_table(cols, values)

    assert per_column() == per_value()
    tk, tb = interleaved(per_column, per_value, repeat)
    return [Row("sweep .out table, column by column (baseline: per value)", "us/row", tk / rows, tb / rows, None, None,
                f"{rows} rows x {len(cols)} columns (11 F10.4 figures): a value's text from integer digit columns, "
                "exact ties and products within an ulp of one through the per-value editing")]


def startup(repeat: int, both: bool = True) -> list[Row]:
    """Issue 37: the command line's CPU per process against ``python -c "import numpy"`` in the same
    rounds (bench/bench_startup.py: each a fresh process, interleaved, medians); the 'baseline' is
    ``import numpy``, so the ratio is numpy's time over the run's and the target its inverse."""
    rows = []
    modes = (("editable checkout", False), ("bytecode cached", True)) if both else (("as configured", False),)
    for label, cached in modes:
        med = bench_startup.measure(repeat, cached)
        base = med.pop("import numpy")
        for name, t in med.items():
            rows.append(Row(f"start-up, {label}: {name}", "ms/run", t, base, None, 1 / bench_startup.TARGETS[name],
                            f"a fresh `python -m driver` process ({label}): {t / base:.2f}x the CPU of "
                            f"`import numpy` (target <= {bench_startup.TARGETS[name]:g}x)"))
    return rows


SCALE = {"ns/position": 1e9, "ns/sample": 1e9, "us/config": 1e6, "us/objective": 1e6, "us/design": 1e6,
         "ms/revolution": 1e3, "ms/run": 1e3, "us/linkage": 1e6, "us/row": 1e6}


def linkage(sizes: tuple[int, ...], repeat: int) -> list[Row]:
    """The linkage kernel (issue 38), like with like (bench/bench_linkage.py): per group-position
    against the four-bar kernel (the same four-bar as a crank and one RRR group writing what the
    four-bar kernel writes; the Watt II six-bar per group), and the Watt II against pylinkage's
    numba kinematics step (each point's position, velocity and acceleration) and positions-only
    step (rows skipped, with the reason, when pylinkage or numba is not installed: they are not
    project dependencies); at each size of ``sizes`` (one turn at 0.1 deg: in cache; a long run:
    streamed to memory, where the store floor bounds the kernel)."""
    rows = []
    for n in sizes:
        f = bench_linkage.versus_fourbar(n, repeat)
        rows.append(Row(f"linkage: four-bar as a group, n = {n} (baseline: four-bar kernel)", "ns/position",
                        f["group"], f["fourbar"], None, 0.5, "target: at most 2x the four-bar kernel per "
                        "group-position (the same outputs, with branch continuity)", f["floor"]))
        rows.append(Row(f"linkage: Watt II per group, n = {n} (baseline: four-bar kernel)", "ns/position",
                        f["watt2_per_group"], f["fourbar"], None, 0.5, "target: at most 2x the four-bar kernel "
                        "per group-position (two groups, the same kinds of output)"))
        r = bench_linkage.versus_pylinkage(n, max(3, repeat // 2))
        if isinstance(r, str):
            print(f"linkage vs pylinkage skipped: {r}")
            continue
        rows.append(Row(f"linkage: Watt II, n = {n} (baseline: pylinkage numba kinematics)", "ns/position",
                        r["joints"], r["pylinkage"], None, 20.0, "each point's position, velocity and acceleration, "
                        "as pylinkage's step gives them", r["floor"]))
        rows.append(Row(f"linkage: Watt II, n = {n} (baseline: pylinkage positions only)", "ns/position",
                        r["positions"], r["pylinkage_positions"], None, 1.0, "each point's position"))
    return rows


def print_table(rows: list[Row]) -> None:
    print(f"{'benchmark':<46}{'unit':>14}{'kernel':>10}{'numpy':>12}{'ratio':>10}   target")
    for r in rows:
        k = SCALE[r.unit]
        tgt = []
        if r.target_s is not None:
            tgt.append(f"<= {r.target_s * k:g}")
        if r.target_ratio is not None:
            tgt.append(f">= {r.target_ratio:g}x")
        verdict = ("met" if r.met() else "NOT met") if tgt else "-"
        print(f"{r.name:<46}{r.unit:>14}{r.kernel_s * k:10.3f}{r.baseline_s * k:12.3f}{r.ratio:9.2f}x   "
              f"{', '.join(tgt) or '-'} {verdict if tgt else ''}")
    print("\nlimits (floor: numpy writing the same output bytes in the same run):")
    for r in rows:
        k = SCALE[r.unit]
        floor = (f"; floor {r.floor_s * k:.3f} {r.unit.split('/')[0]}, kernel at {r.kernel_s / r.floor_s:.1f}x the floor"
                 if r.floor_s else "")
        print(f"  {r.name}: {r.limit}{floor}")


def main(argv: list[str] | None = None) -> list[Row]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller sizes, fewer repeats")
    ap.add_argument("--smoke", action="store_true", help="tiny sizes (the test suite's check that this runs)")
    parts = ["fourbar", "manipulator", "ujoint", "slidercrank", "slidercrank_nl", "linkage", "search", "table",
             "startup"]
    ap.add_argument("--only", choices=parts, action="append", help="run only these parts (repeatable)")
    ap.add_argument("--before", metavar="SO", default=os.environ.get("BENCH_KERNEL_BEFORE"),
                    help="the _kernels extension built before issue 37 (e.g. a main checkout's build/cp311/fortran/"
                         "_kernels*.so): the search rows' 'before' baseline (default: $BENCH_KERNEL_BEFORE)")
    args = ap.parse_args(argv)
    only = set(args.only or parts)
    if args.smoke:
        sizes = dict(n=2048, samples=4096, n_el=20, spr=72, base_steps=4, repeat=2, nl_el=20, nl_revs=1)
    elif args.quick:
        sizes = dict(n=200_000, samples=200_000, n_el=700, spr=1440, base_steps=20, repeat=5, nl_el=700, nl_revs=2)
    else:
        sizes = dict(n=1_000_000, samples=1_000_000, n_el=700, spr=1440, base_steps=60, repeat=9, nl_el=700, nl_revs=4)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"bench/run_all.py: cpu count {os.cpu_count()}, load average {load:.2f} at start, one thread, CPU time, "
          f"medians of {sizes['repeat']} interleaved rounds\n")
    rows: list[Row] = []
    if "fourbar" in only:
        rows += fourbar(sizes["n"], sizes["repeat"])
    if "manipulator" in only:
        rows += manipulator(sizes["n"] // 10 if not args.smoke else sizes["n"], sizes["samples"], sizes["repeat"])
    if "ujoint" in only:
        rows += ujoint(sizes["repeat"])
    if "slidercrank" in only:
        rows += slidercrank(sizes["n_el"], sizes["spr"], sizes["base_steps"], max(3, sizes["repeat"] // 3))
    if "slidercrank_nl" in only:
        rows += slidercrank_nl(sizes["nl_el"], sizes["nl_revs"], max(3, sizes["repeat"] // 3))
    if "linkage" in only:
        rows += linkage((sizes["n"],) if args.smoke else bench_linkage.SIZES, sizes["repeat"])
    if "search" in only:
        rows += search(sizes["repeat"], args.before, 2048 if args.smoke else None)
    if "table" in only:
        rows += table(512 if args.smoke else 20_000, sizes["repeat"])
    if "startup" in only:
        rows += startup(1 if args.smoke else sizes["repeat"], both=not args.smoke)
    print_table(rows)
    return rows


if __name__ == "__main__":
    main()
