"""Benchmark: start-up of the command line (issue 37).

What a lecturer running twenty decks in a loop, a test suite or a sweep worker waits for is the
process, not the study: a small deck's work is a few milliseconds.  Each contender runs as its
own process, contenders interleaved round by round (after one warm-up round), and its CPU time
(user + system, of the process and anything it waited for: ``RUSAGE_CHILDREN``) is taken; the
median over the rounds is set against the median of ``python -c "import numpy"`` measured in the
same rounds.  Targets: each small deck at most 2x ``import numpy``; ``--help`` and
``--examples`` at most 1.5x.

Two ways of running the tool are measured:

* as configured: ``python -m driver`` in this environment.  In a development checkout
  (``.ci/setup``: meson-python's editable install) every run checks the build with ninja; the
  editable loader writes no bytecode (and ``PYTHONDONTWRITEBYTECODE`` may be set) but reads
  what ``.ci/setup`` compiled (``compileall``), so only sources edited since are compiled
  afresh;
* bytecode cached, as an installed package runs: the same processes with their bytecode
  written to and read from a scratch ``PYTHONPYCACHEPREFIX`` (the editable loader's bytecode
  switch turned back on in the measured process only; nothing is written into the checkout).

``--modules`` also lists what a run imports beyond numpy and what each remaining third-party
import costs (``python -c "import numpy, X"`` against ``import numpy``).

    .venv/bin/python bench/bench_startup.py [--repeat 9] [--modules]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: the small decks of the issue: the published four-bar listing, a manipulator case, an
#: option-0 (analyse only) Hooke-joint chain
DECKS = {"crank5": "inputs/crank5.dat", "manipulator case 1": "inputs/manipulator_case1_exact.dat",
         "U-joint option 0": "inputs/ujoint_analyse.dat"}
#: target: at most this many times the CPU of `import numpy`
TARGETS = {"--help": 1.5, "--examples": 1.5, **{k: 2.0 for k in DECKS}}
#: the heavy optional packages a small deck must not import unless its path uses them
HEAVY = ("pandas", "scipy", "pyarrow", "matplotlib", "jinja2", "dask", "distributed", "tqdm")

#: the measured process with bytecode cached: meson-python's editable loader (a development
#: checkout) overrides set_data to write no bytecode; an installed package has its bytecode
_CACHED = """
import runpy, sys
try:
    import _mechanism_driver_editable_loader as loader
    if "set_data" in vars(loader.SourceFileLoader):
        del loader.SourceFileLoader.set_data
except ImportError:
    pass
if sys.argv[1:2] == ["-c"]:
    exec(sys.argv[2])
else:
    sys.argv = ["driver", *sys.argv[1:]]
    runpy.run_module("driver", run_name="__main__", alter_sys=True)
"""

#: run a contender in-process and print the top-level packages it imported beyond numpy
_MODULES = """
import json, runpy, sys, io, contextlib
import numpy
before = set(sys.modules)
sys.argv = ["driver", *sys.argv[1:]]
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    try:
        runpy.run_module("driver", run_name="__main__", alter_sys=True)
    except SystemExit:
        pass
new = sorted(set(sys.modules) - before)
print(json.dumps({"modules": new}))
"""


def load() -> str:
    return "load average {:.1f} {:.1f} {:.1f}".format(*os.getloadavg())


def commands(outdir: Path) -> dict[str, list[str]]:
    """Each contender's arguments after the interpreter."""
    out = {"import numpy": ["-c", "import numpy"], "--help": ["--help"], "--examples": ["--examples"]}
    for name, deck in DECKS.items():
        out[name] = [deck, "-o", str(outdir), "-q"]
    return out


def _argv(args: list[str], cached: bool) -> list[str]:
    if cached:
        return [sys.executable, "-c", _CACHED, *args]
    return [sys.executable, *args] if args[:1] == ["-c"] else [sys.executable, "-m", "driver", *args]


def _env(cached: bool, prefix: Path) -> dict[str, str]:
    env = dict(os.environ)
    if cached:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = str(prefix)
    return env


def cpu_of(argv: list[str], env: dict[str, str]) -> float:
    """CPU seconds (user + system) of one process and the processes it waited for."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(argv, cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime)


def measure(repeat: int, cached: bool, names: list[str] | None = None) -> dict[str, float]:
    """Median CPU seconds of each contender, interleaved round by round after a warm-up round."""
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        cmds = commands(tmp / "out")
        if names is not None:
            cmds = {k: v for k, v in cmds.items() if k in names or k == "import numpy"}
        env = _env(cached, tmp / "pycache")
        times: dict[str, list[float]] = {k: [] for k in cmds}
        for args in cmds.values():   # warm-up: caches, and the bytecode when cached
            cpu_of(_argv(args, cached), env)
        for _ in range(repeat):
            for k, args in cmds.items():
                times[k].append(cpu_of(_argv(args, cached), env))
    return {k: statistics.median(v) for k, v in times.items()}


def imported(args: list[str]) -> list[str]:
    """Modules a contender imports beyond numpy (run in a fresh process)."""
    res = subprocess.run([sys.executable, "-c", _MODULES, *args], cwd=ROOT, capture_output=True, text=True, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1])["modules"]


def third_party(mods: list[str]) -> dict[str, str]:
    """{package: the import statement's target list} for the installed (site-packages) packages
    among ``mods`` other than numpy and the tool: the package with the second-level modules the
    run imported (``scipy.optimize, scipy.linalg``), so that their cost is what the run paid."""
    import importlib.util
    out: dict[str, str] = {}
    for top in sorted({m.split(".")[0] for m in mods}):
        if top in ("numpy", "driver") or top.startswith("_") or top in sys.stdlib_module_names:
            continue
        spec = importlib.util.find_spec(top)
        if spec is None or "site-packages" not in str(spec.origin or ""):
            continue
        subs = sorted({".".join(m.split(".")[:2]) for m in mods if m.startswith(top + ".") and
                       not m.split(".")[1].startswith("_")})
        out[top] = ", ".join(subs or [top])
    return out


def module_costs(packages: dict[str, str], repeat: int) -> dict[str, float]:
    """CPU seconds each package (as the run imports it) adds to ``import numpy`` (median, interleaved)."""
    env = dict(os.environ)
    cmds = {"numpy": "import numpy", **{p: f"import numpy, {what}" for p, what in packages.items()}}
    times: dict[str, list[float]] = {k: [] for k in cmds}
    for _ in range(repeat + 1):
        for k, code in cmds.items():
            times[k].append(cpu_of([sys.executable, "-c", code], env))
    base = statistics.median(times["numpy"][1:])
    return {k: statistics.median(v[1:]) - base for k, v in times.items() if k != "numpy"}


def report(label: str, med: dict[str, float]) -> list[tuple[str, float, float, bool]]:
    base = med["import numpy"]
    print(f"  {label}: import numpy {base * 1e3:.0f} ms of CPU")
    rows = []
    for k, t in med.items():
        if k == "import numpy":
            continue
        ratio = t / base
        ok = ratio <= TARGETS[k]
        rows.append((k, t, ratio, ok))
        print(f"    {k:<22} {t * 1e3:7.1f} ms  {ratio:5.2f}x import numpy   (target <= {TARGETS[k]:g}x: "
              f"{'met' if ok else 'NOT met'})")
    return rows


def main(argv: list[str] | None = None) -> dict[str, dict[str, float]]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=9, help="rounds (medians), after one warm-up round")
    ap.add_argument("--modules", action="store_true", help="also list each run's imports and their cost")
    args = ap.parse_args(argv)
    print(f"start-up: CPU time of each process, medians of {args.repeat} interleaved rounds   "
          f"[{load()}, {os.cpu_count()} CPUs]")
    out = {}
    for label, cached in (("as configured (this environment)", False), ("bytecode cached (as installed)", True)):
        out[label] = med = measure(args.repeat, cached)
        report(label, med)
        print(f"    [{load()}]")
    if args.modules:
        print("imports beyond numpy:")
        third: dict[str, str] = {}
        for name, cmd in commands(Path(tempfile.gettempdir()) / "bench_startup_out").items():
            if name == "import numpy":
                continue
            mods = imported(cmd)
            tops = sorted({m.split(".")[0] for m in mods if not m.startswith(("driver", "_"))})
            heavy = [m for m in tops if m in HEAVY]
            mine = [m for m in mods if m.startswith("driver")]
            pkgs = third_party(mods)
            print(f"  {name:<22} {len(mine)} driver modules; installed packages: {', '.join(pkgs) or 'none'}; "
                  f"heavy: {', '.join(heavy) or 'none'}")
            third.update(pkgs)
        costs = module_costs(third, args.repeat)
        for k, v in costs.items():
            print(f"    {k:<20} adds {v * 1e3:6.1f} ms of CPU to import numpy (import {third[k]})")
    return out


if __name__ == "__main__":
    main()
