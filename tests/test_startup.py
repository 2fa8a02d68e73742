"""Start-up (issue 37): a small deck imports only what its path uses.

Each deck runs in a fresh process (the command line, as a user runs it).  With pandas, scipy,
pyarrow, matplotlib, Jinja2 and Dask made unimportable (``sys.modules[name] = None``: an import
of them raises ImportError), the four-bar listing deck and an option-0 Hooke-joint deck write
the committed ``.out`` byte for byte, and so does a manipulator case (its largest tolerance box is
found without scipy since 2026-12).  A second check lists ``sys.modules`` after a run.  Nothing is timed here
(bench/bench_startup.py and bench/run_all.py measure the CPU against ``import numpy``).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("pandas", "scipy", "pyarrow", "matplotlib", "jinja2", "dask", "distributed")

#: run the command line with some packages made unimportable, then print the modules loaded
RUN = """
import json, runpy, sys
blocked = json.loads(sys.argv[1])
for name in blocked:
    sys.modules[name] = None          # import name -> ImportError
sys.argv = ["driver", *sys.argv[2:]]
code = 0
try:
    runpy.run_module("driver", run_name="__main__", alter_sys=True)
except SystemExit as exc:
    code = exc.code
print(json.dumps({"code": code, "modules": sorted(m for m, v in sys.modules.items() if v is not None)}),
      file=sys.stderr)
"""


def run(args: list[str], blocked: tuple[str, ...] = ()) -> tuple[int, list[str], str]:
    res = subprocess.run([sys.executable, "-c", RUN, json.dumps(list(blocked)), *args], cwd=ROOT,
                         capture_output=True, text=True, timeout=600)
    rec = json.loads(res.stderr.strip().splitlines()[-1])
    return rec["code"], rec["modules"], res.stdout


def tops(modules: list[str]) -> set[str]:
    return {m.split(".")[0] for m in modules}


@pytest.mark.parametrize("deck", ["crank5", "ujoint_analyse"])
def test_small_deck_without_the_heavy_packages(tmp_path, deck):
    code, modules, _ = run([f"inputs/{deck}.dat", "-o", str(tmp_path), "-q"], HEAVY)
    assert code == 0
    assert (tmp_path / f"{deck}.out").read_bytes() == (ROOT / "outputs" / f"{deck}.out").read_bytes()
    assert not tops(modules) & {*HEAVY, "tqdm"}


@pytest.mark.parametrize("deck", ["manipulator_case1_exact", "manipulator_case2_report"])
def test_manipulator_case_without_the_heavy_packages(tmp_path, deck):
    """A manipulator case (tables, tolerance box, Monte Carlo) imports none of the heavy packages:
    not scipy either (its largest box is exact, driver/manipulator/_analysis.py)."""
    code, modules, _ = run([f"inputs/{deck}.dat", "-o", str(tmp_path), "-q"], HEAVY)
    assert code == 0
    out = f"{deck}.out"
    assert (tmp_path / out).read_bytes() == (ROOT / "outputs" / out).read_bytes()
    assert not tops(modules) & {*HEAVY, "tqdm"}
    assert "numpy.ma" not in modules          # np.percentile's np.unique imports it (12 ms)
    assert "driver._mechanism" not in modules  # the report page's animation only
    assert "driver._published" not in modules  # the published-record reader: --compare only


def test_modules_after_a_four_bar_run(tmp_path):
    """sys.modules after crank5: numpy and the tool, f90nml (the deck reader), threadpoolctl (one
    BLAS thread); no pandas, scipy, pyarrow, matplotlib, Jinja2, Dask, tqdm; of the four-bar
    package not the force analysis (no masses) and not the published-record reader."""
    code, modules, _ = run(["inputs/crank5.dat", "-o", str(tmp_path), "-q"])
    assert code == 0
    assert not tops(modules) & {*HEAVY, "tqdm"}
    assert {"numpy", "f90nml", "threadpoolctl", "driver"} <= tops(modules)
    for absent in ("driver.fourbar._analysis_forces", "driver.fourbar._report_forces", "driver._published",
                   "driver._mechanism", "driver._pydeck", "driver.fourbar._figures", "driver.plotting"):
        assert absent not in modules, absent


def test_csv_still_written_when_asked(tmp_path):
    """The tidy table, deferred, is built when a format asks for it (pandas imported then)."""
    code, modules, _ = run(["inputs/crank5.dat", "-o", str(tmp_path), "-q", "--csv"])
    assert code == 0 and "pandas" in tops(modules)
    assert (tmp_path / "crank5.csv").read_text().splitlines()[0].startswith("method,theta_deg,")


@pytest.mark.parametrize("flag", ["--help", "--examples"])
def test_help_imports_no_numpy(flag):
    code, modules, text = run([flag])
    assert code == 0 and text.strip()
    assert "numpy" not in tops(modules) and not tops(modules) & set(HEAVY)
