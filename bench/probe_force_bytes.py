"""Probe: what moving the four-bar force kernel's bytes costs here, against the kernel itself.

The force kernel (``fourbar_joint_forces``) reads a status and 8 state columns (68 B) and writes
12 force columns (96 B) per position.  Issue 37 asks it to cost at most 1.6x its store floor
(numpy filling the 96 B, the bench row in ``run_all.py --only fourbar``).  This probe compiles
``bench/probes/force_bytes.f90`` with the kernels' native flags and times, in one process,
plain-store loops that move the same bytes with no arithmetic to speak of (see the Fortran
file): ``fill`` (the 12 columns, one stream at a time), ``move`` (the kernel's access pattern:
blocks of 256 or 4096 positions, every column its own stream, one add or multiply per output)
and ``copy`` (8 columns copied, 4 filled, one stream pair at a time).  Then the kernel and numpy's
fill are timed in this process (medians, interleaved) for comparison.  Not a guarded row: it
shows why the 1.6x target is below what the memory system allows on this machine.

    .venv/bin/python bench/probe_force_bytes.py [--n 1000000] [--repeat 9]
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
FLAGS = ["-O3", "-march=native", "-mprefer-vector-width=512", "-ffp-contract=off", "-fno-trapping-math"]


def probe(n: int, repeat: int) -> dict[str, float]:
    """ns/position of the probe's loops (medians of the times the Fortran program prints)."""
    gfortran = shutil.which("gfortran")
    if gfortran is None:
        raise SystemExit("gfortran is needed to compile the probe")
    with tempfile.TemporaryDirectory() as tmp:
        exe = Path(tmp) / "force_bytes"
        subprocess.run([gfortran, *FLAGS, "-J", tmp, str(ROOT / "fortran" / "kinds.f90"),
                        str(ROOT / "bench" / "probes" / "force_bytes.f90"), "-o", str(exe)], check=True)
        out = subprocess.run([str(exe), str(n), str(repeat)], check=True, capture_output=True, text=True).stdout
    runs = np.array([[float(v) for v in line.split()] for line in out.splitlines()[:repeat]])
    return dict(zip(("fill", "move256", "move4096", "copy"), np.median(runs, axis=0) / n * 1e9))


def kernel(n: int, repeat: int) -> dict[str, float]:
    """ns/position of the force kernel (out=) and of numpy's fill of its buffer, interleaved."""
    from bench_fourbar_forces import PROPS
    from driver.fourbar import _kernel as fourbar_kernel
    link = (0.30, 0.10, 0.35, 0.25, 20.0, 3.0)
    theta = np.linspace(0.0, 2 * np.pi, n)
    states, status = fourbar_kernel.fourbar_exact(theta, *link, 1)
    fout = np.empty((n, 12), order="F")
    fns = {"kernel": lambda: fourbar_kernel.fourbar_joint_forces(states, status, *link, PROPS, out=fout),
           "numpy fill": lambda: fout.fill(0.0)}
    times: dict[str, list[float]] = {k: [] for k in fns}
    for f in fns.values():
        f()
    for _ in range(repeat):
        for k, f in fns.items():
            t0 = time.perf_counter()
            f()
            times[k].append(time.perf_counter() - t0)
    return {k: statistics.median(v) / n * 1e9 for k, v in times.items()}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=9)
    args = ap.parse_args(argv)
    k = kernel(args.n, args.repeat)
    p = probe(args.n, args.repeat)
    load = " ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"force kernel's bytes, {args.n} positions, medians of {args.repeat}   [load average {load}]")
    print(f"  this process:  force kernel {k['kernel']:.2f} ns/position, numpy fill (the store floor) "
          f"{k['numpy fill']:.2f}: {k['kernel'] / k['numpy fill']:.2f}x   (target <= 1.6x)")
    print(f"  Fortran probe: plain-store fill {p['fill']:.2f}; the kernel's reads and writes without its arithmetic "
          f"{p['move256']:.2f} (blocks of 256) / {p['move4096']:.2f} (4096): {p['move256'] / p['fill']:.2f}x / "
          f"{p['move4096'] / p['fill']:.2f}x its fill; 8 columns copied + 4 filled {p['copy']:.2f} "
          f"({p['copy'] / p['fill']:.2f}x)")


if __name__ == "__main__":
    main()
