"""Without the optional extras the core runs, and each optional feature says which extra it needs."""
from __future__ import annotations

import subprocess
import sys

import pytest

from conftest import INPUTS, ROOT

# Runs the command line with the named top-level modules made unimportable (as if not installed).
BLOCK = """
import sys, importlib.abc
class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in {blocked!r}:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
sys.meta_path.insert(0, Block())
from driver._cli import main
sys.exit(main({args!r}))
"""


def run_without(blocked, args, cwd):
    code = BLOCK.format(blocked=set(blocked), args=list(args))
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True, text=True)


def deck(tmp_path, name):
    """The repository deck copied to tmp_path/inputs/ (the .out files name the deck's path)."""
    (tmp_path / "inputs").mkdir(exist_ok=True)
    (tmp_path / "inputs" / f"{name}.dat").write_text((INPUTS / f"{name}.dat").read_text())
    return f"inputs/{name}.dat"


@pytest.mark.parametrize("name", ["crank5", "ujoint_option1", "manipulator_case1_exact", "slidercrank_simeon1996"])
def test_core_runs_without_any_extra(tmp_path, name):
    res = run_without({"matplotlib", "pyarrow", "dask", "distributed"}, [deck(tmp_path, name), "--csv"], tmp_path)
    assert res.returncode in (0, 1), res.stderr   # 1: an optimiser's documented non-convergence
    assert "Traceback" not in res.stderr and "No module named" not in res.stderr
    assert (tmp_path / "outputs" / f"{name}.out").read_text() == (ROOT / "outputs" / f"{name}.out").read_text()
    assert (tmp_path / "outputs" / f"{name}.csv").stat().st_size > 0


@pytest.mark.parametrize("blocked, option, extra", [
    ("matplotlib", ["--plot"], "plot"),
    ("pyarrow", ["--format", "parquet"], "parquet"),
    ("distributed", ["--scheduler", "tcp://127.0.0.1:1"], "dask"),
])
def test_option_names_its_extra_and_writes_nothing(tmp_path, blocked, option, extra):
    res = run_without({blocked}, [deck(tmp_path, "crank5"), *option], tmp_path)
    assert res.returncode == 2
    assert f"pip install 'mechanism-driver[{extra}]'" in res.stderr and "Traceback" not in res.stderr
    assert not (tmp_path / "outputs").exists()


def test_sweep_names_the_parquet_extra(tmp_path):
    res = run_without({"pyarrow"}, [deck(tmp_path, "fourbar_paper_sweep"), "-j", "1"], tmp_path)
    assert res.returncode == 1
    assert "pip install 'mechanism-driver[parquet]'" in res.stderr and "Traceback" not in res.stderr
    assert not (tmp_path / "outputs").exists()
