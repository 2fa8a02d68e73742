"""A new study is one folder plus one registry line, for CI too (issue 34).

The example study (tests/example_study/pendulum) is copied into a scratch copy of this repository
as the real package ``driver/pendulum/``, the one line ``"pendulum": "driver.pendulum"`` is added
to ``driver._study.REGISTRY`` there, and the scratch repository -- its own ``driver``, imported
from the scratch tree, with the compiled kernels of this build -- runs the new study through

* the command line (a deck, its .out, tidy table, figure and summary JSON);
* a sweep on both engines: the batch path (many designs in one kernel call) and case by case
  (each case a run with its files), which must agree;
* ``&optimize`` (a length whose period is 2 s);
* ``--report`` (the report page of a run and of the optimisation);
* the lint gate: ``ruff check .`` and ``mypy`` as tests/test_lint.py runs them, and mypy refusing a
  misspelt key of ``driver.pendulum.run`` (the study's generated stub types it);
* the scratch repository's own tests that derive their list of studies from the registry (the
  contract, the layout, the dependency order), which now include the new study.

At the end the scratch tree differs from the copy in ``driver/_study.py`` (one line added) and
the new folder ``driver/pendulum/``, nothing else: no shared file names the new study.

Truth: the period of a uniform rod of length L pivoted at one end, released at rest from theta0,
is that of the simple pendulum of length 2L/3, T = 4 sqrt(2L / 3g) K(k), k = sin(theta0 / 2),
with K(k) = int_0^{pi/2} dphi / sqrt(1 - k^2 sin^2 phi) evaluated here by adaptive quadrature
(scipy.integrate.quad), apart from the study's ``ellipk`` "kernel".
"""
from __future__ import annotations

import difflib
import hashlib
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from conftest import ROOT

EXAMPLE = ROOT / "tests" / "example_study" / "pendulum"
G = 9.80665
#: the line a new study adds to driver/_study.py
REGISTRY_LINE = '    "pendulum": "driver.pendulum",\n'
#: what the scratch runs leave behind that is no source: caches and bytecode
CACHES = ("__pycache__", ".mypy_cache", ".ruff_cache", ".pytest_cache")

pytestmark = pytest.mark.slow


def period(length: float, amplitude_deg: float, g: float = G) -> float:
    """T = 4 sqrt(2L / 3g) K(sin(theta0/2)), K by quadrature (the independent truth)."""
    k = math.sin(math.radians(amplitude_deg) / 2.0)
    big_k, _ = quad(lambda phi: 1.0 / math.sqrt(1.0 - (k * math.sin(phi)) ** 2), 0.0, math.pi / 2, epsabs=0.0,
                    epsrel=1e-13, limit=200)
    return 4.0 * math.sqrt(2.0 * length / (3.0 * g)) * big_k


def _tracked_files() -> list[str]:
    proc = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, timeout=60)
    if proc.returncode != 0:
        pytest.skip("needs a git checkout of the repository (the scratch copy is its tracked files)")
    return [f for f in proc.stdout.decode().split("\0") if f]


def _snapshot(tree: Path) -> dict[str, str]:
    """{path relative to ``tree``: sha256} of every file but caches."""
    out = {}
    for p in sorted(tree.rglob("*")):
        if p.is_file() and not set(p.relative_to(tree).parts) & set(CACHES):
            out[p.relative_to(tree).as_posix()] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    """A scratch copy of the repository (its tracked files and this build's compiled kernels), a
    snapshot of it, then the new study: the example's folder as driver/pendulum and one registry line."""
    import driver._version
    from driver._fortran import _kernels

    tree = tmp_path_factory.mktemp("repo")
    for rel in _tracked_files():
        if (ROOT / rel).is_file():
            (tree / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / rel, tree / rel)
    for built in (Path(_kernels.__file__), Path(driver._version.__file__)):   # the build, not a source
        shutil.copy2(built, tree / "driver" / built.name)
    before = _snapshot(tree)
    assert "driver/pendulum/__init__.py" not in before and not any("pendulum" in f for f in before
                                                                   if f.startswith("driver/"))

    shutil.copytree(EXAMPLE, tree / "driver" / "pendulum", ignore=shutil.ignore_patterns(*CACHES))
    study = tree / "driver" / "_study.py"
    text = study.read_text()
    anchor = "REGISTRY: dict[str, str] = {\n"
    assert text.count(anchor) == 1
    study.write_text(text.replace(anchor, anchor + REGISTRY_LINE))
    return tree, before


def _env() -> dict[str, str]:
    """The scratch repository's ``driver`` first: an editable install's finder is told to stand aside."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "MESONPY_EDITABLE_SKIP")}
    builds = [str(f._build_path) for f in sys.meta_path if hasattr(f, "_build_path")]   # meson-python's
    if builds:
        env["MESONPY_EDITABLE_SKIP"] = os.pathsep.join(builds)
    return env


def _run(tree: Path, *args: str, timeout: float = 900) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, *args], cwd=tree, env=_env(), capture_output=True, text=True,
                          timeout=timeout)


def _deck(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_scratch_repository_runs_its_own_driver_with_the_new_study(scratch):
    tree, _ = scratch
    proc = _run(tree, "-c", "import driver, driver.pendulum as p; print(driver.__file__); "
                            "print(driver.PUBLIC_MODULES); print(driver.studies()); print(p.STUDY)")
    assert proc.returncode == 0, proc.stderr
    where, public, studies, study = proc.stdout.splitlines()
    assert Path(where).resolve().is_relative_to(tree.resolve())
    assert "'pendulum'" in public and "'pendulum'" in studies and study.startswith("<Study &pendulum")


def test_command_line_run(scratch, tmp_path):
    tree, _ = scratch
    deck = _deck(tmp_path, "swing.dat", "&pendulum length = 0.8, amplitude_deg = 120, points = 5, title = 'new' /\n")
    proc = _run(tree, "-m", "driver", "-q", "-o", str(tmp_path / "out"), "--plot", "--json", "--csv",
                str(deck))
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "out"
    text = (out / "swing.out").read_text()
    printed = float(text.split("period ............... ")[1].split()[0])
    assert printed == pytest.approx(period(0.8, 120.0), abs=5e-7)        # printed to 6 decimals
    tidy = pd.read_csv(out / "swing.csv")
    assert len(tidy) == 5 and tidy["theta_deg"].iloc[0] == pytest.approx(120.0) \
        and tidy["theta_deg"].iloc[-1] == pytest.approx(-120.0, abs=1e-6)
    assert (out / "swing_swing.png").stat().st_size > 1000
    summary = json.loads((out / "swing.json").read_text())
    assert json.dumps(summary).count("period_ratio") >= 1
    bad = _deck(tmp_path, "bad.dat", "&pendulum length = 0.8, amplitude_deg = 200 /\n")
    proc = _run(tree, "-m", "driver", "-q", "-o", str(tmp_path / "bad"), str(bad))
    assert proc.returncode == 2 and "amplitude_deg" in proc.stderr and not (tmp_path / "bad").exists()


def test_sweep_on_both_engines(scratch, tmp_path):
    """The batch path (case_outputs = 'none': one kernel call) and the per-case engine (each case a
    run writing its files) give the same summary, and both the closed form's periods."""
    tree, _ = scratch
    base = "&pendulum length = 1.0, amplitude_deg = 30 /\n"
    grid = "key1 = 'pendulum.amplitude_deg', values1 = 10, 60, 150, key2 = 'pendulum.length', values2 = 0.5, 2.0"
    frames = {}
    for outputs in ("none", "all"):
        deck = _deck(tmp_path, f"grid_{outputs}.dat", base + f"&sweep {grid}, case_outputs = '{outputs}' /\n")
        out = tmp_path / f"out_{outputs}"
        proc = _run(tree, "-m", "driver", "-q", "-o", str(out), "--jobs", "1", str(deck))
        assert proc.returncode == 0, proc.stderr
        frames[outputs] = pd.read_csv(out / f"grid_{outputs}_summary.csv")
        cases = sorted((out / f"grid_{outputs}").glob("case_*.out")) if (out / f"grid_{outputs}").is_dir() else []
        assert len(cases) == (6 if outputs == "all" else 0), cases      # per case: a run's files each
        proc = _run(tree, "-c", f"import json, driver; s = driver.run_sweep({str(deck)!r}, jobs=1); "
                                "print(json.dumps([s.batch, s.n_ok, s.summary['period_s'].tolist()]))")
        assert proc.returncode == 0, proc.stderr
        batch_path, n_ok, periods = json.loads(proc.stdout)
        assert batch_path is (outputs == "none") and n_ok == 6, proc.stdout   # the engine the deck asks for ran
        assert np.allclose(periods, frames[outputs]["period_s"], rtol=1e-12)
    batch, per_case = frames["none"], frames["all"]
    assert len(batch) == 6 and (batch["status"] == "ok").all()
    for c in ("period_s", "small_angle_period_s", "period_ratio"):
        assert np.allclose(batch[c], per_case[c], rtol=1e-14, atol=0.0), c
    truth = [period(L, a) for a, L in zip(batch["pendulum.amplitude_deg"], batch["pendulum.length"])]
    assert np.allclose(batch["period_s"], truth, rtol=1e-9)


def test_optimize_and_report_pages(scratch, tmp_path):
    """&optimize finds the rod whose 60 deg swing takes 2 s (the closed form by brentq), and
    --report writes the page of the optimisation and of a run."""
    tree, _ = scratch
    deck = _deck(tmp_path, "two_seconds.dat",
                 "&pendulum length = 1.0, amplitude_deg = 60 /\n"
                 "&optimize var1 = 'pendulum.length', lower1 = 0.1, upper1 = 5.0\n"
                 "  minimize = '(period_s - 2.0)**2', method = 'slsqp', starts = 2, tol = 1e-14 /\n")
    out = tmp_path / "opt"
    proc = _run(tree, "-m", "driver", "-q", "-o", str(out), "--report", "--json", str(deck))
    assert proc.returncode == 0, proc.stderr
    record = json.loads((out / "two_seconds.json").read_text())
    record = record.get("optimize", record)   # the engine's own section (or the record itself)
    x = dict(zip(record["x_names"], record["x"]))
    best = brentq(lambda L: period(L, 60.0) - 2.0, 0.1, 5.0, xtol=1e-14)
    assert x["pendulum.length"] == pytest.approx(best, rel=1e-6)   # on the optimiser's 1e-7 lattice of the range
    optimum = (out / "two_seconds.optimum.out").read_text()        # the optimum re-run as a deck
    assert float(optimum.split("period ............... ")[1].split()[0]) == pytest.approx(2.0, abs=2e-6)
    page = (out / "two_seconds.html").read_text()
    assert "pendulum" in page and "period_s" in page
    run_deck = _deck(tmp_path, "page.dat", "&pendulum length = 0.5, amplitude_deg = 45 /\n")
    proc = _run(tree, "-m", "driver", "-q", "-o", str(out), "--report", str(run_deck))
    assert proc.returncode == 0, proc.stderr
    page = (out / "page.html").read_text()
    assert "pendulum" in page and f"{period(0.5, 45.0):.6f}" in page


def test_lint_gate_and_the_new_study_typed(scratch, tmp_path):
    tree, _ = scratch
    proc = _run(tree, "-m", "ruff", "check", "--no-cache", ".", timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    cache = tmp_path / "mypy-cache"
    proc = _run(tree, "-m", "mypy", "--cache-dir", str(cache), timeout=1800)
    assert proc.returncode == 0 and "Success: no issues found" in proc.stdout, proc.stdout + proc.stderr
    calls = _deck(tmp_path, "calls.py", "import driver.pendulum\n"
                                        "driver.pendulum.run(length=1.0, amplitude_deg=30.0)\n"      # fine
                                        "driver.pendulum.run(lenght=1.0, amplitude_deg=30.0)\n"      # misspelt
                                        "driver.pendulum.run(length=1.0, amplitude_deg=30.0, points=2.5)\n")  # int key
    proc = _run(tree, "-m", "mypy", "--cache-dir", str(cache), "--follow-imports=silent", str(calls), timeout=1800)
    lines = sorted({int(line.split(":")[1]) for line in proc.stdout.splitlines() if ": error:" in line})
    assert lines == [3, 4], proc.stdout


def test_the_scratch_repositorys_tests_derive_the_new_study_from_the_registry(scratch):
    tree, _ = scratch
    proc = _run(tree, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rA",
                "tests/test_study_contract.py::test_every_registered_study_satisfies_the_contract",
                "tests/test_study_contract.py::test_every_study_has_the_one_layout",
                "tests/test_import_graph.py::test_every_study_package_keeps_the_one_dependency_order",
                "tests/test_keyword_signatures.py::test_each_study_has_its_static_signature_fresh_in_its_own_package",
                timeout=1800)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    for test in ("test_every_registered_study_satisfies_the_contract[pendulum]",
                 "test_every_study_has_the_one_layout[pendulum]",
                 "test_every_study_package_keeps_the_one_dependency_order[driver.pendulum]",
                 "test_each_study_has_its_static_signature_fresh_in_its_own_package[pendulum]"):
        assert any(line.startswith("PASSED tests/") and line.endswith("::" + test) for line in proc.stdout.splitlines()), \
            (test, proc.stdout[-3000:])


def test_the_snapshot_sees_a_change_an_addition_and_a_removal(tmp_path):
    for name in ("a.py", "b.py", "c.py"):
        (tmp_path / name).write_text(name)
    (tmp_path / "__pycache__").mkdir()
    before = _snapshot(tmp_path)
    (tmp_path / "a.py").write_text("changed")
    (tmp_path / "b.py").unlink()
    (tmp_path / "d.py").write_text("new")
    (tmp_path / "__pycache__" / "a.pyc").write_text("cache")   # caches are no source
    after = _snapshot(tmp_path)
    assert sorted(before) == ["a.py", "b.py", "c.py"] and sorted(after) == ["a.py", "c.py", "d.py"]
    assert before["a.py"] != after["a.py"] and before["c.py"] == after["c.py"]


def test_one_registry_line_and_one_folder_and_nothing_else(scratch):
    """Run last in this file: whatever the runs above wrote stays outside the tree (their outputs
    go to other folders), so the tree differs from the copy by the study alone."""
    tree, before = scratch
    after = _snapshot(tree)
    changed = sorted(f for f in before if f in after and before[f] != after[f])
    removed = sorted(set(before) - set(after))
    added = sorted(set(after) - set(before))
    assert changed == ["driver/_study.py"] and not removed, (changed, removed)
    assert added and all(f.startswith("driver/pendulum/") for f in added), added
    assert sorted(added) == sorted(f"driver/pendulum/{p.name}" for p in EXAMPLE.iterdir()
                                   if p.is_file() and p.suffix in (".py", ".pyi"))
    diff = [d for d in difflib.unified_diff((ROOT / "driver" / "_study.py").read_text().splitlines(keepends=True),
                                            (tree / "driver" / "_study.py").read_text().splitlines(keepends=True),
                                            n=0) if d[:1] in "+-" and not d.startswith(("+++", "---"))]
    assert diff == ["+" + REGISTRY_LINE]
