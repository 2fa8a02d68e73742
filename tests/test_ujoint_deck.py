"""&ujoint through the CLI: bad input is a DeckError (exit 2, nothing written, file:line and
key named); a non-converged optimiser exits 1 and says so; the decks write their outputs."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from driver._cli import main

INPUTS = Path(__file__).resolve().parents[1] / "inputs"


def _deck(tmp_path: Path, body: str) -> Path:
    deck = tmp_path / "bad.dat"
    deck.write_text("! test deck\n&ujoint\n" + body + "\n/\n")
    return deck


@pytest.mark.parametrize("body, key, line, words", [
    ("  option = 0\n  beta = 15, 95, 9", "beta", 4, "strictly between -90 and 90"),
    ("  beta = 15, -90, 9", "beta", 3, "strictly between -90 and 90"),
    ("  beta = ", "beta", 3, "empty"),
    ("  beta = 15, 20, 9\n  option = 2\n  beta_lower = 30\n  beta_upper = 20", "beta_lower", 5,
     "exceeds upper bound"),
    ("  beta = 15, 20, 9\n  option = 1\n  phi_lower = 100, 0\n  phi_upper = 90, 180", "phi_lower", 5,
     "exceeds upper bound"),
    ("  beta = 15, 20, 9\n  phi = 30, 40, 50", "phi", 4, "phi_3 does not exist"),
    ("  beta = 15\n  delta = 10", "delta", 4, "0 phase(s)"),
    ("  model = 'exact'\n  beta = 15, 20\n  rho = 10, 20", "rho", 5, "1 plane"),
    ("  model = 'exact'\n  axes = 1,0,0, 0,0,0, 0,1,0", "axes", 4, "zero length"),
    ("  model = 'exact'\n  axes = 1,0,0, 0,1,0.01", "axes", 4, "strictly between -90 and 90"),
    ("  model = 'paper'\n  beta = 15, 20\n  rho = 10", "rho", 5, "model = 'exact'"),
    ("  beta = 15, 20\n  phi = 90\n  delta = 0", "delta", 5, "not both"),
    ("  beta = 15\n  option = 1", "option", 4, "single joint has none"),
    ("  beta = 15, 20\n  beta_upper = 95", "beta_upper", 4, "bound must lie strictly"),
    ("  beta = 15, 20\n  objective = 'max'", "objective", 4, "is not one of"),
])
def test_bad_input_is_a_deck_error(tmp_path, capsys, body, key, line, words):
    deck = _deck(tmp_path, body)
    out = tmp_path / "out"
    rc = main([str(deck), "-o", str(out)])
    err = capsys.readouterr().err
    assert rc == 2
    assert not out.exists() or not any(out.iterdir())
    assert f"{deck}:{line}" in err and f"key '{key}'" in err and words in err, err


def test_optimiser_failure_exits_1_and_says_so(tmp_path, capsys):
    deck = _deck(tmp_path, "  model='exact', option=3, beta=30,40,50, beta_lower=10, "
                           "n_starts=2, maxiter=1")
    rc = main([str(deck), "-o", str(tmp_path)])
    err = capsys.readouterr().err
    assert rc == 1 and "did not converge" in err
    assert err.count("did not converge") == 1   # printed once, as the error
    text = (tmp_path / "bad.out").read_text()
    assert "RUN FAILED" in text and "last iterate" in text
    assert "optimum " not in text.split("DESIGNS")[1].split("PERFORMANCE")[0]


def test_decks_write_outputs_without_nan(tmp_path, capsys):
    decks = [d for d in sorted(INPUTS.glob("ujoint_*.dat")) if "&sweep" not in d.read_text()]   # single runs
    assert len(decks) >= 4
    rc = main([*map(str, decks), "-o", str(tmp_path), "--csv"])
    assert rc == 0, capsys.readouterr().err
    for deck in decks:
        text = (tmp_path / f"{deck.stem}.out").read_text()
        assert "nan" not in text.lower().replace("n/a", "") and "****" not in text
        frame = pd.read_csv(tmp_path / f"{deck.stem}.csv")
        assert np.isfinite(frame.select_dtypes("number").to_numpy()).all()
        assert {"theta_in_deg", "omega_out_rpm", "alpha_out_rad_s2"} <= set(frame.columns)
    result = (tmp_path / "ujoint_option3.result.dat").read_text()
    assert result.splitlines()[3].startswith("x          =")


def test_steering_deck_3d_phasing(tmp_path, capsys):
    """The steering column's optimum cancels the fluctuation exactly (16.4^2 + 26.4^2 > 29.1^2)."""
    rc = main([str(INPUTS / "ujoint_steering.dat"), "-o", str(tmp_path), "--csv"])
    assert rc == 0
    frame = pd.read_csv(tmp_path / "ujoint_steering.csv")
    opt = frame[frame.design == "optimum"]
    trial = frame[frame.design == "trial"]
    assert np.ptp(opt.ratio) < 1e-6 < 0.1 < np.ptp(trial.ratio)
    # exact chain: output angle advances one revolution per input revolution
    assert math.isclose(opt.theta_out_deg.iloc[-1] - opt.theta_out_deg.iloc[0],
                        359.0, abs_tol=1e-6)
