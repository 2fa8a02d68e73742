"""Benchmark: the linkage kernel (fortran/linkage.f90) against the four-bar kernel, against
pylinkage's numba solver on the same Watt II six-bar, and its batch summary.

Ratios are measured in one process, kernel and baseline interleaved, medians of CPU time
(bench/run_all.py's rows ``linkage ...``).  Targets (issue 38):

* kernel cost per group-position at most 2x the four-bar kernel's per position (the same
  four-bar written as a crank and one RRR group: positions, velocities, accelerations,
  transmission angle; reused output buffers on both sides);
* at least 20x pylinkage's numba kinematics step (positions, velocities, accelerations:
  ``Linkage.step_fast_with_kinematics``) on the Watt II six-bar, and faster than its
  positions-only ``step_fast``;
* a 10^6-design six-bar summary sweep end to end in under 10 s of wall time on two cores
  (``--sweep``: the command line on a generated &sweep deck, wall clock).

pylinkage (and numba) are not project dependencies: ``pip install pylinkage numba`` into the
venv for these rows; without them the rows are skipped with the reason.  Run:

    .venv/bin/python bench/bench_linkage.py [--n 200000] [--repeat 7] [--sweep]
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from driver._deck import read_deck, validate  # noqa: E402
from driver.fourbar import _kernel as fourbar_kernel  # noqa: E402
from driver.linkage import SPEC, compile_deck  # noqa: E402
from driver.linkage import _kernel as linkage_kernel  # noqa: E402

FOURBAR_DECK = "pivots='O2','O4', pivot_xy=0,0, 12,0\ndriver_joints='O2','A', driver_length=5, omega=5, step=1\n" \
               "dyads='RRR', dyad_joints='A','O4','B', dyad_links='coupler','rocker', dyad_dims=15,9"


def interleaved(kernel: Callable[[], object], baseline: Callable[[], object], repeat: int) -> tuple[float, float]:
    """Median CPU time [s] of one kernel call and one baseline call, measured alternately."""
    kernel()
    baseline()
    tk, tb = [], []
    for _ in range(repeat):
        t0 = time.process_time()
        kernel()
        tk.append(time.process_time() - t0)
        t0 = time.process_time()
        baseline()
        tb.append(time.process_time() - t0)
    return statistics.median(tk), statistics.median(tb)


def params(text: str, name: str = "bench.dat"):
    deck = read_deck(name, "&linkage\n" + text + "\n/\n")
    return validate(deck.groups["linkage"], SPEC, name)


def watt2():
    path = ROOT / "inputs" / "linkage_watt2.dat"
    return validate(read_deck(path).groups["linkage"], SPEC, path)


def versus_fourbar(n: int, repeat: int) -> tuple[float, float]:
    """(linkage, four-bar) CPU seconds per position of the crank5 four-bar (one group)."""
    mech = compile_deck(params(FOURBAR_DECK))
    theta = np.linspace(0.0, 2 * np.pi, n)
    out = np.empty((n, 11), order="F")
    sts = np.empty(n, dtype=np.int32)
    a = linkage_kernel.analyse(mech, theta, forces=False)
    fourbar_kernel.fourbar_exact(theta, 12.0, 5.0, 15.0, 9.0, 5.0, 0.0, out=out, status=sts)
    assert np.allclose(a.links[:, 1, 3], out[:, 8], rtol=1e-12, atol=1e-12)
    # the linkage kernel with its output buffers reused too (the four-bar's are): the module's
    # call with the arrays the wrapper would pass, kept from one call to the next
    call = linkage_kernel.reusable_call(mech, theta, forces=False)
    tk, tb = interleaved(call, lambda: fourbar_kernel.fourbar_exact(theta, 12.0, 5.0, 15.0, 9.0, 5.0, 0.0, out=out,
                                                                    status=sts), repeat)
    return tk / n, tb / n


def pylinkage_watt2():
    """The Watt II deck as a pylinkage Linkage (crank, RRR, a point fixed on the rocker, RRR),
    started near the deck's assembly; None with the reason when pylinkage is not installed."""
    try:
        import warnings
        warnings.simplefilter("ignore")
        from pylinkage.actuators import Crank
        from pylinkage.components import Ground
        from pylinkage.dyads import FixedDyad, RRRDyad
        from pylinkage.simulation import Linkage
    except ImportError as exc:
        return None, f"pylinkage not installed ({exc.name}): pip install pylinkage numba"
    try:
        import numba  # noqa: F401
    except ImportError:
        return None, "numba not installed: pylinkage's fast path would run as plain Python"
    p = watt2()
    mech = compile_deck(p)
    a = linkage_kernel.analyse(mech, np.array([0.0]), forces=False)
    pt = {n: a.points[0, 0:2, j] for j, n in enumerate(mech.point_names)}
    O2, O4, O6 = Ground(0.0, 0.0, name="O2"), Ground(0.30, 0.0, name="O4"), Ground(0.256, 0.126, name="O6")
    crank = Crank(anchor=O2, radius=0.10, angular_velocity=0.0, initial_angle=0.0, name="A")
    B = RRRDyad(crank.output, O4, distance1=0.35, distance2=0.30, x=float(pt["B"][0]), y=float(pt["B"][1]), name="B")
    C = FixedDyad(anchor1=O4, anchor2=B, distance=0.15, angle=math.pi, name="C")
    D = RRRDyad(C, O6, distance1=0.214, distance2=0.189, x=float(pt["D"][0]), y=float(pt["D"][1]), name="D")
    link = Linkage([O2, O4, O6, crank, B, C, D], name="Watt II")
    return (link, crank, mech, pt), ""


def versus_pylinkage(n: int, repeat: int) -> tuple[float, float, float] | str:
    """(linkage kinematics, pylinkage kinematics, pylinkage positions) CPU s per position of the
    Watt II six-bar; or the reason the rows are skipped."""
    built, why = pylinkage_watt2()
    if built is None:
        return why
    link, crank, mech, pt = built
    dt = 2 * math.pi / n
    crank.angular_velocity = dt
    link.set_input_velocity(crank, 10.0, 0.0)
    link.compile()
    theta = dt * np.arange(1, n + 1)
    pos, vel, acc = link.step_fast_with_kinematics(iterations=n, dt=1.0)
    a = linkage_kernel.analyse(mech, theta, forces=False)
    names = [c.name for c in link.components]
    jd = mech.point_index("D") - 1
    kd = names.index("D")
    # the same mechanism, the same assembly: positions agree (pylinkage's velocities follow its own
    # conventions and are not compared)
    err = float(np.max(np.abs(pos[:, kd, :] - a.points[:, 0:2, jd])))
    assert err < 1e-9, f"pylinkage's D differs from the kernel's by {err:.3g}"
    del a

    ours = linkage_kernel.reusable_call(mech, theta, forces=False)

    def theirs() -> object:
        link.set_coords([(float(x), float(y)) for x, y in pos[-1]]) if hasattr(link, "set_coords") else None
        return link.step_fast_with_kinematics(iterations=n, dt=1.0)

    tk, tb = interleaved(ours, theirs, repeat)
    _, tp = interleaved(ours, lambda: link.step_fast(iterations=n, dt=1.0), repeat)
    return tk / n, tb / n, tp / n


def batch_summary(nd: int, scan: int, repeat: int) -> float:
    """CPU seconds per design of the Watt II batch summary (kinematics, scan of ``scan`` points)."""
    from driver._deck import Params
    from driver.linkage import summarise_batch
    p = watt2()
    values = dict(p)
    values["scan_points"] = scan
    values["bodies"] = None
    for k in ("mass", "com_uv", "inertia", "gravity", "torque_links", "torques"):
        values[k] = None
    q = Params(p.group, p.path, values, {k: p.line_of(k) for k in p}, p.line,
               {k for k in p.given if k not in ("bodies", "mass", "com_uv", "inertia", "gravity", "torque_links",
                                                "torques")} | {"scan_points"})
    col = {"dyad_dims(3)": np.linspace(0.20, 0.23, nd)}
    summarise_batch(q, col)
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        summarise_batch(q, col)
        times.append(time.process_time() - t0)
    return statistics.median(times) / nd


SWEEP_DECK = """&linkage
  title = 'Watt II: 10^6 designs'
  pivots = 'O2', 'O4', 'O6', pivot_xy = 0, 0,   0.30, 0,   0.256, 0.126
  driver_joints = 'O2', 'A', driver_length = 0.10, omega = 10.0, step = 10
  dyads = 'RRR', 'RRR', dyad_joints = 'A', 'O4', 'B',   'C', 'O6', 'D'
  dyad_links = 'coupler', 'rocker', 'link5', 'link6'
  dyad_dims = 0.35, 0.30, 0.214, 0.189, dyad_modes = 1, -1
  points = 'C', point_on = 'rocker', point_uv = -0.15, 0
  scan_points = {scan}
/
&sweep
  key1 = 'linkage.driver_length', start1 = 0.06, stop1 = 0.12, count1 = {c1}
  key2 = 'linkage.omega', start2 = 5.0, stop2 = 15.0, count2 = {c2}
  keep = 'time_ratio >= 1.384 and stroke >= 29.8'
  case_outputs = 'none'
  summary_rows = 'kept'
/
"""


def sweep_wall(c1: int, c2: int, scan: int) -> float:
    """Wall seconds of the command line on a c1 x c2 Watt II summary sweep (all cores)."""
    with tempfile.TemporaryDirectory() as tmp:
        deck = Path(tmp) / "watt2_sweep.dat"
        deck.write_text(SWEEP_DECK.format(c1=c1, c2=c2, scan=scan))
        t0 = time.perf_counter()
        run = subprocess.run([sys.executable, "-m", "driver", "-q", "-o", str(Path(tmp) / "out"), str(deck)],
                             cwd=ROOT, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        assert run.returncode == 0, run.stderr[-2000:]
    return wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=200_000)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--sweep", action="store_true", help="also the 10^6-design sweep through the command line")
    args = ap.parse_args()
    load = os.getloadavg()[0]
    print(f"bench_linkage: {os.cpu_count()} cpus, load {load:.2f}; CPU time, medians of {args.repeat} interleaved")
    lk, fb = versus_fourbar(args.n, args.repeat)
    print(f"  four-bar as a group: {lk * 1e9:7.1f} ns/group-position vs four-bar kernel {fb * 1e9:7.1f} ns/position: "
          f"{lk / fb:5.2f}x (target <= 2)")
    r = versus_pylinkage(args.n, max(3, args.repeat // 2))
    if isinstance(r, str):
        print(f"  pylinkage rows skipped: {r}")
    else:
        ours, kin, pos = r
        print(f"  Watt II six-bar: {ours * 1e9:7.1f} ns/position; pylinkage kinematics {kin * 1e9:8.1f} ns "
              f"({kin / ours:6.1f}x, target >= 20), positions only {pos * 1e9:8.1f} ns ({pos / ours:5.1f}x, target > 1)")
    for scan in (720, 90):
        print(f"  Watt II batch summary, {scan}-point scan: {batch_summary(2000, scan, 3) * 1e6:8.2f} us/design")
    if args.sweep:
        wall = sweep_wall(1000, 1000, 72)
        print(f"  10^6-design Watt II sweep (72-point scans), command line: {wall:6.2f} s wall (target < 10)")


if __name__ == "__main__":
    main()
