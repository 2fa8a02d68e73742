"""The scripts in examples/ run as written, and what they print agrees with closed forms."""
from __future__ import annotations

import importlib.util
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT

EXAMPLES = ROOT / "examples"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(f"example_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _mu(crank: float, rocker: float, theta_deg: float, ground: float = 12.0, coupler: float = 15.0) -> float:
    """Transmission angle [deg] by the law of cosines on the diagonal A-O_B."""
    d2 = ground**2 + crank**2 - 2 * ground * crank * math.cos(math.radians(theta_deg))
    return math.degrees(math.acos((coupler**2 + rocker**2 - d2) / (2 * coupler * rocker)))


def test_every_example_is_tested():
    assert sorted(p.stem for p in EXAMPLES.glob("*.py")) == ["fourbar_plot", "sweep_dataframe", "ujoint_optimum"]


def test_fourbar_example_runs_as_a_script(tmp_path):
    res = subprocess.run([sys.executable, str(EXAMPLES / "fourbar_plot.py"), str(tmp_path)],
                         capture_output=True, text=True, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert f"transmission angle {_mu(5, 9, 0):.2f} .. {_mu(5, 9, 180):.2f} deg" in res.stdout
    assert (tmp_path / "fourbar_linkage.png").stat().st_size > 10_000


def test_ujoint_example_finds_the_quarter_turn_phasing(tmp_path, capsys):
    r = _load("ujoint_optimum").main(tmp_path)
    # alternating joints cancel best with the intermediate yokes turned a quarter turn
    assert [r.summary["phi_1_deg"], r.summary["phi_2_deg"]] == pytest.approx([90.0, 90.0], abs=1e-4)
    assert r.summary["objective"] < 0.05 * r.summary["objective_trial"]
    rec = json.loads((tmp_path / "ujoint_option1_api.json").read_text())
    assert rec["summary"]["phi_1_deg"] == r.summary["phi_1_deg"] and rec["ok"]
    assert "optimum phases 90.0000, 90.0000 deg" in capsys.readouterr().out


def test_sweep_example_dataframes_match_the_closed_form(tmp_path):
    paper, grid = _load("sweep_dataframe").main(tmp_path)
    assert list(paper.summary["fourbar.crank"]) == [2, 3, 4, 5]
    for row in paper.summary.itertuples():
        assert row.mu_min_deg == pytest.approx(_mu(row[2], 9.0, 0.0), abs=1e-9)
        assert row.mu_max_deg == pytest.approx(_mu(row[2], 9.0, 180.0), abs=1e-9)
    assert len(grid.summary) == 15 and (tmp_path / "fourbar_summary.csv").exists()
    crank_rocker = grid.summary[grid.summary["grashof_class"] == "crank-rocker"]
    assert len(crank_rocker) >= 8
    for _, row in crank_rocker.iterrows():
        assert row["mu_min_deg"] == pytest.approx(_mu(row["fourbar.crank"], row["fourbar.rocker"], 0.0), abs=1e-9)
    kept = (grid.summary["meets_transmission_band"] | (grid.summary["mu_min_deg"] > 30)) & (grid.summary["status"] == "ok")
    assert np.array_equal(grid.summary["kept"].to_numpy(), kept.to_numpy())
