"""Batch sweeps compute only what the deck asks for (issue 27).

The columns named by ``keep``, ``plot_x``/``plot_y`` and ``summary_columns`` decide which
kernel passes run, through each study's column -> pass table (``BATCH_PASSES``):

* the shipped design search (filter on the transmission band and the rocker swing) runs the
  transmission and rocker passes for all 102 400 linkages and the peak-speed pass for the 408
  kept ones only -- counted by a spy on the kernel, the outputs equal to the committed ones;
* ``summary_columns`` narrows the tables (plus what keep and the plot read); the values equal
  those of a sweep without it; a name that is not a summary column is refused (exit 2, key);
* for the Hooke-joint and manipulator batch summaries, every column asked for alone has the
  bits of the full summary, and the kernel runs only the passes of the table.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from driver import manipulator, ujoint
from driver._cli import main
from driver._deck import Params
from driver.fourbar import _kernel as fourbar_kernel
from driver.manipulator import _kernel as manipulator_kernel
from driver.ujoint import _kernel as ujoint_kernel

ROOT = Path(__file__).resolve().parents[1]
P = fourbar_kernel.FOURBAR_PASSES


@pytest.fixture
def spy(monkeypatch):
    """Every fourbar_summaries call of this process: [(rows, passes)]."""
    calls: list[tuple[int, int]] = []
    real = fourbar_kernel.fourbar_summaries

    def wrapped(params, passes=7):
        calls.append((len(params), int(passes)))
        return real(params, passes)

    monkeypatch.setattr(fourbar_kernel, "fourbar_summaries", wrapped)
    return calls


def test_shipped_search_runs_the_peak_pass_for_the_kept_linkages_only(tmp_path, spy, monkeypatch):
    out = tmp_path / "o"
    monkeypatch.chdir(ROOT)   # the deck's path as the committed .out gives it
    assert main(["inputs/fourbar_design_search.dat", "-o", str(out), "-q", "-j", "1"]) == 0
    rows = lambda want: sum(n for n, bits in spy if bits == want)
    assert rows(P["transmission"] | P["rocker"]) == 102400     # the filter's columns, every linkage
    # the table's columns for the kept ones (and the base deck's one summary, naming the columns)
    assert rows(P["transmission"] | P["rocker"] | P["peaks"]) == 408 + 1
    assert sum(n for n, _ in spy) == 102400 + 408 + 1
    for name in ("fourbar_design_search.out", "fourbar_design_search_summary.csv"):
        assert (out / name).read_bytes() == (ROOT / "outputs" / name).read_bytes()


SWEEP = """&fourbar fixed_link = 12.0, crank = 3.0, coupler = 15.0, rocker = 9.0, omega = 5.0, step_deg = 10 /
&sweep
  key1 = 'fourbar.crank',   start1 = 1.0, stop1 = 7.0,  count1 = 13
  key2 = 'fourbar.coupler', start2 = 6.0, stop2 = 20.0, count2 = 15
  key3 = 'fourbar.rocker',  start3 = 4.0, stop3 = 16.0, count3 = 15
  case_outputs = 'none', summary_rows = '{rows}'
  keep = 'rocker_swing_deg >= 40'{extra}
/
"""


@pytest.mark.parametrize("rows", ["all", "kept"])
def test_summary_columns_narrow_the_tables_with_the_same_values(tmp_path, spy, rows):
    full, part = tmp_path / "full", tmp_path / "part"
    (tmp_path / "a.dat").write_text(SWEEP.format(rows=rows, extra=""))
    (tmp_path / "b.dat").write_text(SWEEP.format(rows=rows, extra=",\n  summary_columns = 'mu_min_deg'"))
    assert main([str(tmp_path / "a.dat"), "-o", str(full), "-q", "-j", "1"]) == 0
    spy.clear()
    assert main([str(tmp_path / "b.dat"), "-o", str(part), "-q", "-j", "1"]) == 0
    a, b = pd.read_parquet(full / "a_summary.parquet"), pd.read_parquet(part / "b_summary.parquet")
    assert list(b.columns) == ["case", "fourbar.crank", "fourbar.coupler", "fourbar.rocker", "status", "kept",
                               "mu_min_deg", "rocker_swing_deg", "error"]
    assert len(a) == len(b) and (len(b) == 13 * 15 * 15 if rows == "all" else 0 < len(b) < 13 * 15 * 15)
    pd.testing.assert_frame_equal(b, a[b.columns])
    # nobody asked for a peak speed: only the base deck's one summary (naming the columns) has them
    assert spy[0] == (1, 7) and all(not bits & P["peaks"] for _, bits in spy[1:])
    text = (part / "b.out").read_text()
    assert "mu_min_deg" in text and "rocker_omega_peak" not in text


def test_summary_columns_refuses_an_unknown_column(tmp_path, capsys):
    (tmp_path / "c.dat").write_text(SWEEP.format(rows="kept", extra=",\n  summary_columns = 'mu_min_dg'"))
    assert main([str(tmp_path / "c.dat"), "-o", str(tmp_path / "o"), "-q"]) == 2
    err = capsys.readouterr().err
    assert "summary_columns" in err and "mu_min_dg" in err and "c.dat" in err
    assert not (tmp_path / "o" / "c.out").exists()


def _ujoint_base(**kw) -> Params:
    vals = {k: spec.default for k, spec in ujoint.SPEC.keys.items()}
    vals.update(kw)
    return Params("ujoint", Path("test.dat"), vals, {}, 1, given=set(kw))


def test_ujoint_wanted_columns_have_the_full_bits_and_run_their_passes(monkeypatch):
    b = _ujoint_base(beta=[20.0, 30.0, 25.0], phi=[90.0, 90.0])
    rng = np.random.default_rng(2)
    cols = {"ujoint.phi(1)": rng.uniform(0, 180, 300), "ujoint.phi(2)": rng.uniform(0, 180, 300)}
    full = ujoint.summarise_batch(b, cols)
    seen: list[int] = []
    real = ujoint._batch.ujoint_summaries
    monkeypatch.setattr(ujoint._batch, "ujoint_summaries", lambda *a, passes=7, **k: (seen.append(passes),
                                                                                   real(*a, passes=passes, **k))[1])
    for c in full.columns:
        seen.clear()
        part = ujoint.summarise_batch(b, cols, wanted=[c])
        assert list(part.columns) == [c]
        pd.testing.assert_series_equal(part[c], full[c])
        need = {ujoint_kernel.UJOINT_PASSES[p] for p in ujoint.BATCH_PASSES.get(c, ())}
        assert seen == [sum(need)], c


def test_manipulator_wanted_columns_have_the_full_bits_and_run_their_passes(monkeypatch):
    from driver._deck import read_deck, validate
    d = read_deck(ROOT / "inputs" / "manipulator_design_search.dat")
    base = validate(d.groups["manipulator"], manipulator.SPEC, d.path)
    rng = np.random.default_rng(4)
    cols = {"designs_l1": rng.uniform(0.2, 1.2, 200), "designs_l2": rng.uniform(0.2, 1.2, 200)}
    full = manipulator.summarise_batch(base, cols)
    seen: list[int] = []
    real = manipulator_kernel.manipulator_design_summaries
    monkeypatch.setattr(manipulator_kernel, "manipulator_design_summaries",
                        lambda *a, passes=7, **k: (seen.append(passes), real(*a, passes=passes, **k))[1])
    for c in full.columns:
        seen.clear()
        part = manipulator.summarise_batch(base, cols, wanted=[c])
        assert list(part.columns) == [c]
        pd.testing.assert_series_equal(part[c], full[c])
        need = manipulator._batch._passes([c]) - {"walk"}
        assert seen == [sum(manipulator_kernel.MANIPULATOR_PASSES[p] for p in need)], c


def test_optimize_runs_only_the_passes_of_its_objective_constraints_and_summary_columns(tmp_path, spy, monkeypatch):
    """&optimize with summary_columns: the batch path computes what the objective, the
    constraints and summary_columns read (no peak speeds here), and finds the optimum of the
    committed run (outputs/optimize_fourbar_design.out, every column computed)."""
    text = (ROOT / "inputs" / "optimize_fourbar_design.dat").read_text()
    (tmp_path / "opt.dat").write_text(text.replace("method = 'differential_evolution'",
                                                   "summary_columns = 'time_ratio', method = 'differential_evolution'"))
    assert main([str(tmp_path / "opt.dat"), "-o", str(tmp_path / "o"), "-q"]) == 0
    assert spy and all(not bits & P["peaks"] for n, bits in spy if n > 1)
    evals = pd.read_parquet(tmp_path / "o" / "opt_evals.parquet")
    summ = sorted(c for c in evals.columns if c.startswith("summary."))
    assert summ == ["summary." + c for c in sorted(("meets_transmission_band", "mu_max_deg", "mu_min_deg",
                                                     "rocker_swing_deg", "time_ratio"))]
    ref = pd.read_parquet(ROOT / "outputs" / "optimize_fourbar_design_evals.parquet")
    assert len(evals) == len(ref)
    for c in ["fourbar.crank", "fourbar.coupler", "fourbar.rocker", "objective", "feasible", *summ]:
        pd.testing.assert_series_equal(evals[c], ref[c], check_names=False)
