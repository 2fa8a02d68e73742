"""Benchmark: the linkage kernel (fortran/linkage.f90) against the four-bar kernel, against
pylinkage's numba solver on the same Watt II six-bar, its batch summary and a 10^6-design sweep.

Ratios are measured in one process, kernel and baseline interleaved, medians of CPU time
(bench/run_all.py's rows ``linkage ...``).  Like is compared with like (issue 38):

* against the four-bar kernel (``fourbar_exact``: per position the coupler's and rocker's
  angles, rates and accelerations, both pins' positions, the transmission angle): the linkage
  writes the same quantities (``Want.ANGLES | LINK_RATES | POINTS | QUALITY``: every link's
  angle and rates, every point's position, each group's transmission angle), with branch
  continuity on (the four-bar kernel has none); cost per group-position (the four-bar as a crank
  and one RRR group; the Watt II six-bar, two groups, per group).  Target: at most 2x;
* against pylinkage's ``step_fast_with_kinematics`` (each joint's position, velocity and
  acceleration): the linkage writes each point's position, velocity and acceleration
  (``Want.JOINTS``); against its positions-only ``step_fast``: positions (``Want.POINTS``).
  Targets: at least 20x and more than 1x;
* the batch summary of the Watt II per design (a 72-point scan; the output pass a stroke and
  time-ratio search asks for, and every pass);
* a 10^6-design Watt II summary sweep through the command line (``--sweep``: wall clock, two
  workers).  Target: under 10 s.

Memory is treated alike: the linkage and the four-bar kernel write into ``out=`` buffers made
once; pylinkage makes its three output arrays (``np.empty``) in every call, and glibc hands
blocks that large back to the operating system when they are freed, so at 200 000 inputs each
of its calls first-touched 67 MB of fresh pages (about 11 000 page faults, 100-200 ns a
position of system time zeroing them) that the linkage never paid.  :func:`keep_freed_memory`
tells glibc to keep freed memory for reuse (``mallopt``), so pylinkage's arrays land on pages
already mapped, as the linkage's buffers do; the rows print both sides' page faults per call
(0 when alike).  pylinkage writes every component (the three ground pivots too: 42 float64 a
position against the linkage's 24), in its own layout (positions, then components, C order).

Two sizes: one crank turn at 0.1 deg (3600 inputs: every output stays in the core's cache) and
200 000 inputs (the outputs stream to memory).  The store floor is numpy writing the same
output bytes in the same run: at 200 000 inputs it is what bounds a kernel that writes 200
bytes a position.  pylinkage (and numba) are not project dependencies: ``pip install pylinkage
numba`` into the venv for those rows; without them the rows are skipped with the reason.  Run:

    .venv/bin/python bench/bench_linkage.py [--repeat 7] [--sweep]
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
from driver.linkage._kernel import Pass, Want  # noqa: E402

FOURBAR_DECK = "pivots='O2','O4', pivot_xy=0,0, 12,0\ndriver_joints='O2','A', driver_length=5, omega=5, step=1\n" \
               "dyads='RRR', dyad_joints='A','O4','B', dyad_links='coupler','rocker', dyad_dims=15,9"
#: what the four-bar kernel writes, as the linkage's outputs
LIKE_FOURBAR = Want.ANGLES | Want.LINK_RATES | Want.POINTS | Want.QUALITY
#: one crank turn at 0.1 deg (in cache) and a long run (streamed to memory)
SIZES = (3600, 200_000)


def interleaved(kernel: Callable[[], object], baseline: Callable[[], object], repeat: int,
                rounds: int = 1) -> tuple[float, float]:
    """Median CPU time [s] of one kernel call and one baseline call, measured alternately
    (``rounds`` calls of each per measurement)."""
    kernel()
    baseline()
    tk, tb = [], []
    for _ in range(repeat):
        t0 = time.process_time()
        for _ in range(rounds):
            kernel()
        tk.append((time.process_time() - t0) / rounds)
        t0 = time.process_time()
        for _ in range(rounds):
            baseline()
        tb.append((time.process_time() - t0) / rounds)
    return statistics.median(tk), statistics.median(tb)


def keep_freed_memory() -> str:
    """Have glibc keep freed memory for reuse, for the rest of the process (called by the
    pylinkage rows only, after their own out= buffers are made): blocks up to 32 MiB from the
    heap, and the heap never trimmed (the C int's largest threshold), so arrays made and freed
    call after call land on pages already mapped (as ``out=`` buffers do).  Returns what was
    done, or why not (another C library)."""
    import ctypes
    import ctypes.util
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError) as exc:
        return f"freed memory not kept ({exc}): pylinkage's rows include its page faults"
    m_trim_threshold, m_mmap_threshold = -1, -3
    if mallopt(m_mmap_threshold, 32 << 20) != 1 or mallopt(m_trim_threshold, (1 << 31) - 1) != 1:
        return "mallopt refused: pylinkage's rows include its page faults"
    return "freed memory kept for reuse (mallopt): both sides write into mapped pages"


def minor_faults(f: Callable[[], object], calls: int = 3) -> float:
    """Minor page faults per call of f (first touches of fresh memory; after a warm-up call)."""
    import resource
    f()
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(calls):
        f()
    return (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / calls


def rounds_for(n: int) -> int:
    """Calls per measurement: about 10^6 inputs (short calls are timed in bulk)."""
    return max(1, 1_000_000 // n)


def params(text: str, name: str = "bench.dat"):
    deck = read_deck(name, "&linkage\n" + text + "\n/\n")
    return validate(deck.groups["linkage"], SPEC, name)


def watt2():
    path = ROOT / "inputs" / "linkage_watt2.dat"
    return validate(read_deck(path).groups["linkage"], SPEC, path)


def store_floor(n: int, columns: int, repeat: int) -> float:
    """CPU seconds per position of numpy writing ``columns`` float64 and one int32 status per
    position into arrays of n rows (the bytes a call writes: the memory-traffic floor)."""
    a = np.zeros((n, columns), order="F")
    s = np.zeros(n, dtype=np.int32)
    r = rounds_for(n)

    def fill() -> None:
        for _ in range(r):
            a.fill(1.0)
            s.fill(0)

    fill()
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        fill()
        times.append((time.process_time() - t0) / r)
    return statistics.median(times) / n


def versus_fourbar(n: int, repeat: int) -> dict[str, float]:
    """CPU seconds per position: the four-bar kernel ('fourbar'), the same four-bar as a crank and
    one group writing what it writes ('group'), with every output ('group_all'), the Watt II
    six-bar writing the same kinds per group ('watt2_per_group'), and the store floor of the
    group's outputs ('floor')."""
    mech = compile_deck(params(FOURBAR_DECK))
    six = compile_deck(watt2())
    theta = np.linspace(0.0, 2 * np.pi, n)
    out = np.empty((n, 11), order="F")
    sts = np.empty(n, dtype=np.int32)
    a = linkage_kernel.analyse(mech, theta, forces=False)
    fourbar_kernel.fourbar_exact(theta, 12.0, 5.0, 15.0, 9.0, 5.0, 0.0, out=out, status=sts)
    assert np.allclose(a.links[:, 1, 3], out[:, fourbar_kernel.State.ROCKER_OMEGA], rtol=1e-12, atol=1e-12)
    r = rounds_for(n)

    def many(f: Callable[[], object]) -> Callable[[], None]:
        def g() -> None:
            for _ in range(r):
                f()
        return g

    fb = many(lambda: fourbar_kernel.fourbar_exact(theta, 12.0, 5.0, 15.0, 9.0, 5.0, 0.0, out=out, status=sts))
    like = many(linkage_kernel.reusable_call(mech, theta, forces=False, outputs=LIKE_FOURBAR))
    whole = many(linkage_kernel.reusable_call(mech, theta, forces=False))
    six_like = many(linkage_kernel.reusable_call(six, theta, forces=False, outputs=LIKE_FOURBAR))
    tl, tf = interleaved(like, fb, repeat)
    ta, tf2 = interleaved(whole, fb, repeat)
    t6, tf3 = interleaved(six_like, fb, repeat)
    per = n * r
    # the group's writes: 3 links x (angle, omega, alpha), 2 moving points x (x, y), 1 transmission angle
    return {"fourbar": statistics.median([tf, tf2, tf3]) / per, "group": tl / per, "group_all": ta / per,
            "watt2_per_group": t6 / per / 2, "floor": store_floor(n, 14, repeat)}


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
    return (link, crank, mech), ""


def versus_pylinkage(n: int, repeat: int) -> dict[str, float] | str:
    """CPU seconds per position of the Watt II six-bar: ours writing each point's position,
    velocity and acceleration ('joints') against pylinkage's kinematics step ('pylinkage'), ours
    writing positions ('positions') against its positions-only step ('pylinkage_positions'), and
    the store floor of our joints' outputs ('floor'); or the reason the rows are skipped."""
    built, why = pylinkage_watt2()
    if built is None:
        return why
    link, crank, mech = built
    memory = keep_freed_memory()   # pylinkage's per-call arrays on mapped pages, as our out= buffers
    dt = 2 * math.pi / n
    crank.angular_velocity = dt
    link.set_input_velocity(crank, 10.0, 0.0)
    link.compile()
    theta = dt * np.arange(1, n + 1)
    pos, vel, acc = link.step_fast_with_kinematics(iterations=n, dt=1.0)
    a = linkage_kernel.analyse(mech, theta, forces=False)
    names = [c.name for c in link.components]
    # the same mechanism, the same assembly: every joint's position, velocity and acceleration agree
    for name in ("A", "B", "C", "D"):
        j, k = mech.point_index(name) - 1, names.index(name)
        for theirs, cols in ((pos, (0, 1)), (vel, (2, 3)), (acc, (4, 5))):
            err = float(np.max(np.abs(theirs[:, k, :] - a.points[:, list(cols), j])))
            scale = float(np.max(np.abs(a.points[:, list(cols), j])))
            assert err <= 1e-7 * scale, f"pylinkage's {name} differs from the kernel's by {err:.3g} (of {scale:.3g})"
    del a
    r = rounds_for(n)

    def many(f: Callable[[], object]) -> Callable[[], None]:
        def g() -> None:
            for _ in range(r):
                f()
        return g

    joints1 = linkage_kernel.reusable_call(mech, theta, forces=False, outputs=Want.JOINTS)
    theirs1 = lambda: link.step_fast_with_kinematics(iterations=n, dt=1.0)
    joints = many(joints1)
    points = many(linkage_kernel.reusable_call(mech, theta, forces=False, outputs=Want.POINTS))
    tj, tk = interleaved(joints, many(theirs1), repeat)
    tp, tq = interleaved(points, many(lambda: link.step_fast(iterations=n, dt=1.0)), repeat)
    per = n * r
    return {"joints": tj / per, "pylinkage": tk / per, "positions": tp / per, "pylinkage_positions": tq / per,
            "floor": store_floor(n, 24, repeat), "faults": minor_faults(joints1),
            "pylinkage_faults": minor_faults(theirs1), "memory": memory}


def batch_summary(nd: int, scan: int, repeat: int) -> dict[str, float]:
    """CPU seconds per design of the Watt II batch summary (kinematics, a ``scan``-point scan):
    the output pass (stroke, time ratio) and every pass."""
    from driver.linkage._batch import design_numbers
    p = params(SWEEP_DECK.split("&sweep")[0].replace("&linkage", "").replace("/\n", "").format(scan=scan))
    mech = compile_deck(p)
    rows = design_numbers(p, mech, {"driver_length": np.linspace(0.06, 0.12, nd)}, nd)
    out = {}
    for name, passes in (("output", Pass.OUTPUT), ("all", Pass.ALL)):
        linkage_kernel.summaries(mech, rows[:10], scan, True, passes=passes)
        times = []
        for _ in range(repeat):
            t0 = time.process_time()
            linkage_kernel.summaries(mech, rows, scan, True, passes=passes)
            times.append(time.process_time() - t0)
        out[name] = statistics.median(times) / nd
    return out


#: the 10^6-design sweep: the Watt II's crank length and its link5 (an element of dyad_dims), a
#: search for the largest time ratio and swing of the output link (about a thousand designs kept)
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
  key2 = 'linkage.dyad_dims(3)', start2 = 0.19, stop2 = 0.24, count2 = {c2}
  keep = 'time_ratio >= 1.3844 and stroke >= 29.8'
  summary_columns = 'stroke', 'time_ratio', 'mu_min_deg', 'omega_peak_link6_rad_s'
  case_outputs = 'none'
  summary_rows = 'kept'
/
"""


def sweep_wall(c1: int, c2: int, scan: int, jobs: int = 2) -> tuple[float, str]:
    """Wall seconds of the command line on a c1 x c2 Watt II summary sweep, and its last line."""
    with tempfile.TemporaryDirectory() as tmp:
        deck = Path(tmp) / "watt2_sweep.dat"
        deck.write_text(SWEEP_DECK.format(c1=c1, c2=c2, scan=scan))
        t0 = time.perf_counter()
        run = subprocess.run([sys.executable, "-m", "driver", "-j", str(jobs), "-o", str(Path(tmp) / "out"),
                              str(deck)], cwd=ROOT, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        assert run.returncode == 0, run.stderr[-2000:]
    return wall, (run.stdout.strip().splitlines() or [""])[0]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--sweep", action="store_true", help="also the 10^6-design sweep through the command line")
    args = ap.parse_args(argv)
    print(f"bench_linkage: {os.cpu_count()} cpus, load {os.getloadavg()[0]:.2f}; CPU time, medians of "
          f"{args.repeat} interleaved")
    for n in SIZES:
        f = versus_fourbar(n, args.repeat)
        print(f"  n = {n}: four-bar kernel {f['fourbar'] * 1e9:6.1f} ns/position; as a group, like outputs "
              f"{f['group'] * 1e9:6.1f} ns ({f['group'] / f['fourbar']:4.2f}x, target <= 2), every output "
              f"{f['group_all'] * 1e9:6.1f} ns ({f['group_all'] / f['fourbar']:4.2f}x); Watt II per group "
              f"{f['watt2_per_group'] * 1e9:6.1f} ns ({f['watt2_per_group'] / f['fourbar']:4.2f}x); "
              f"store floor {f['floor'] * 1e9:5.1f} ns")
        r = versus_pylinkage(n, max(3, args.repeat // 2))
        if isinstance(r, str):
            print(f"  pylinkage rows skipped: {r}")
            continue
        print(f"  n = {n}: Watt II joints {r['joints'] * 1e9:6.1f} ns/position, pylinkage kinematics "
              f"{r['pylinkage'] * 1e9:7.1f} ns ({r['pylinkage'] / r['joints']:5.1f}x, target >= 20); positions "
              f"{r['positions'] * 1e9:6.1f} ns, pylinkage positions {r['pylinkage_positions'] * 1e9:7.1f} ns "
              f"({r['pylinkage_positions'] / r['positions']:5.1f}x, target > 1); store floor {r['floor'] * 1e9:5.1f} ns; "
              f"page faults per call {r['faults']:.0f} (ours), {r['pylinkage_faults']:.0f} (pylinkage's kinematics); "
              f"{r['memory']}")
    s = batch_summary(20000, 72, 3)
    print(f"  Watt II batch summary, 72-point scan: output pass {s['output'] * 1e6:6.2f} us/design, every pass "
          f"{s['all'] * 1e6:6.2f} us/design")
    if args.sweep:
        # 72-point scans give the sweep's printed columns to their 4 decimals (tests/test_linkage_scan.py);
        # the 1-deg scan for comparison
        for scan in (72, 360):
            wall, line = sweep_wall(1000, 1000, scan)
            print(f"  10^6-design Watt II sweep ({scan}-point scans), command line, 2 workers: {wall:6.2f} s wall "
                  f"(target < 10), load {os.getloadavg()[0]:.2f}\n    {line}")


if __name__ == "__main__":
    main()
