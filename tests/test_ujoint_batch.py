"""Batched Hooke-joint summaries (fortran/ujoint.f90 chain_summaries, ujoint.summarise_batch).

* the batch row equals the summary of a full single run of the same design (``run(...)``,
  option 0: the speed table's kernel calls, not the batch routine) bit for bit, for random
  chains of 1-4 joints under every model, objective and grid, phases as phi or delta, plane
  angles, symmetric assemblies where beta_res exists (hypothesis);
* closed forms: a single joint's band is cos(beta) .. 1/cos(beta); two equal joints in phase
  (exact chain) cancel;
* a Hooke-joint sweep takes the batch path and equals the per-case path; a base deck that
  optimises per case (option 1) does not take it;
* the generic &optimize deck evaluates its designs through the batch path only and reaches
  the known optimum of option 1;
* bad values are DeckErrors naming the key.
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from driver import ujoint
from driver._cli import main
from driver._deck import DeckError, Params

ROOT = Path(__file__).resolve().parents[1]


def base(**kw) -> Params:
    """A validated-looking &ujoint Params: SPEC defaults, ``kw`` given."""
    vals = {k: spec.default for k, spec in ujoint.SPEC.keys.items()}
    vals.update(kw)
    return Params("ujoint", Path("test.dat"), vals, {}, 1, given=set(kw))


def single(**kw) -> dict:
    """The summary of one full run (option 0) of the design ``kw``."""
    return ujoint.run(**kw).summary


def same(batch_row: pd.Series, summary: dict) -> None:
    """Every summary column equal, bit for bit (None in the run is NaN in the batch)."""
    assert list(batch_row.index) == list(summary), "same columns in the same order"
    for k, v in summary.items():
        b = batch_row[k]
        if v is None:
            assert math.isnan(b), k
        else:
            assert b == v, (k, b, v)


angle = st.floats(-60.0, 60.0, allow_nan=False).map(lambda x: round(x, 3))
phase = st.one_of(st.sampled_from([0.0, 90.0, 180.0, -90.0, 270.0]),
                  st.floats(-200.0, 200.0, allow_nan=False).map(lambda x: round(x, 3)))


@st.composite
def designs(draw):
    n = draw(st.integers(1, 4))
    nd = draw(st.integers(1, 4))
    model = draw(st.sampled_from(["exact", "paper"]))
    kw = {"model": model, "objective": draw(st.sampled_from(["mean_square", "rms", "peak_to_peak"])),
          "n_grid": draw(st.sampled_from([8, 9, 36, 90, 127, 360])),
          "rpm": draw(st.sampled_from([25.0, 1.0, 3000.0, 0.37]))}
    if model == "paper":
        kw["phasing"] = draw(st.sampled_from(["cumulative", "eq13"]))
    key = draw(st.sampled_from(["phi", "delta", None])) if n > 1 else None
    plane = model == "exact" and n > 1 and draw(st.booleans())
    rows = []
    for _ in range(nd):
        row = {"beta": [draw(angle) for _ in range(n)]}
        if key:
            row[key] = [draw(phase) for _ in range(n - 1)]
        if plane:
            row["rho"] = [draw(st.sampled_from([0.0, 90.0, 30.0, -45.5])) for _ in range(n - 1)]
        rows.append(row)
    return kw, rows


@settings(max_examples=60, deadline=None)
@given(designs())
def test_batch_equals_single_runs(case):
    kw, rows = case
    columns = {k: np.array([r[k] for r in rows]) for k in rows[0]}
    frame = ujoint.summarise_batch(base(**kw, **{k: v for k, v in rows[0].items()}), columns)
    assert len(frame) == len(rows)
    for i, r in enumerate(rows):
        same(frame.iloc[i], single(**kw, **r))


def test_element_columns_and_sweep_style_columns():
    """'phi(2)' sets one element of the base list; a 1-D column of a list key gives each design
    a one-element list (what a sweep sets)."""
    b = base(model="paper", beta=[15.0, 20.0, 9.0], phi=[30.0, 40.0], objective="mean_square")
    f = ujoint.summarise_batch(b, {"ujoint.phi(2)": [40.0, 90.0], "rpm": [25.0, 50.0]})
    same(f.iloc[0], single(model="paper", beta=[15.0, 20.0, 9.0], phi=[30.0, 40.0]))
    same(f.iloc[1], single(model="paper", beta=[15.0, 20.0, 9.0], phi=[30.0, 90.0], rpm=50.0))
    two = base(beta=[10.0, 25.0], delta=[5.0])
    f = ujoint.summarise_batch(two, {"delta": [0.0, 30.0]})
    same(f.iloc[1], single(beta=[10.0, 25.0], delta=[30.0]))
    assert f["phi_1_deg"].tolist() == [90.0, 120.0]
    one = ujoint.summarise_batch(base(beta=[20.0]), {"beta": [5.0, 20.0, 35.0]})
    assert one["beta_1_deg"].tolist() == [5.0, 20.0, 35.0] and "phi_1_deg" not in one


def test_three_d_chain_from_axes():
    axes = [0, 0, 1, 0.3, 0, 1, 0.3, 0.4, 2, 0, 0.2, 1]
    b = base(axes=axes)
    f = ujoint.summarise_batch(b, {"phi": np.array([[90.0, 90.0], [75.0, 100.0]])})
    same(f.iloc[1], single(axes=axes, phi=[75.0, 100.0]))
    with pytest.raises(DeckError, match="'axes' fix"):
        ujoint.summarise_batch(b, {"beta": [1.0]})


def test_closed_forms():
    """A single joint: R runs from cos(beta) to 1/cos(beta) (grid through 0 and 90 deg), the peak
    acceleration at the root of d2R/dtheta2 = 0 in closed form (not the grid's maximum, which lies
    below it); two equal joints with yokes in phase cancel exactly (exact chain)."""
    beta = np.array([5.0, 15.0, 30.0, 45.0])
    f = ujoint.summarise_batch(base(beta=[0.0], rpm=60.0, n_grid=360), {"beta": beta})
    c = np.cos(np.radians(beta))
    np.testing.assert_allclose(f["omega_out_min_rpm"], 60.0 * c, rtol=1e-14)
    np.testing.assert_allclose(f["omega_out_max_rpm"], 60.0 / c, rtol=1e-14)
    np.testing.assert_allclose(f["pp_ratio"], 1 / c - c, rtol=1e-13)
    # R' = c s2 sin 2t / d^2 (d = 1 - s2 sin^2 t) peaks where cos 2t (1 - s2 sin^2 t) + s2 sin^2 2t = 0,
    # a quadratic in x = cos 2t: x^2 - (2/s2 - 1) x - 2 = 0
    s2 = np.sin(np.radians(beta)) ** 2
    q = 2 / s2 - 1
    x = (q - np.sqrt(q * q + 8)) / 2
    peak = c * s2 * np.sqrt(1 - x * x) / (1 - s2 * (1 - x) / 2) ** 2
    np.testing.assert_allclose(f["peak_accel_rad_s2"], (2 * math.pi) ** 2 * peak, rtol=1e-12)
    np.testing.assert_allclose(f["peak_accel_at_deg"], np.degrees(np.arccos(x)) / 2, atol=1e-9)
    np.testing.assert_allclose(f["beta_e_deg"], beta, rtol=1e-14)   # one joint: beta_e = beta_res = beta
    np.testing.assert_allclose(f["beta_res_deg"], beta, rtol=1e-12)
    # two equal joints, yokes in phase on the intermediate shaft (phi = 90): constant velocity
    g = ujoint.summarise_batch(base(beta=[20.0, 20.0], phi=[90.0]), {"beta": np.array([[20.0, 20.0], [35.0, 35.0]])})
    assert (g["pp_ratio"] < 1e-14).all() and (g["objective"] < 1e-28).all()
    np.testing.assert_allclose(g["beta_res_deg"], 0.0, atol=1e-6)


def test_refusals_name_the_key():
    with pytest.raises(DeckError, match="option 1 optimises"):
        ujoint.summarise_batch(base(beta=[15.0, 20.0], option=1), {"rpm": [1.0]})
    with pytest.raises(DeckError, match=r"design 1: a joint angle must lie strictly between") as e:
        ujoint.summarise_batch(base(beta=[15.0, 20.0]), {"beta(2)": [10.0, 90.0]})
    assert e.value.key == "beta"
    with pytest.raises(DeckError, match="must be positive") as e:
        ujoint.summarise_batch(base(beta=[15.0]), {"rpm": [1.0, -2.0]})
    assert e.value.key == "rpm"
    with pytest.raises(DeckError, match="not a &ujoint key"):
        ujoint.summarise_batch(base(beta=[15.0]), {"option": [0]})
    with pytest.raises(DeckError, match="has 2 value"):
        ujoint.summarise_batch(base(beta=[15.0, 20.0]), {"beta(3)": [1.0]})
    with pytest.raises(DeckError, match="2 phase"):
        ujoint.summarise_batch(base(beta=[15.0, 20.0, 9.0]), {"phi": [90.0]})
    with pytest.raises(DeckError, match="plane angles need model = 'exact'"):
        ujoint.summarise_batch(base(beta=[15.0, 20.0], rho=[10.0]), {"model": ["exact", "paper"]})
    with pytest.raises(DeckError, match="different lengths"):
        ujoint.summarise_batch(base(beta=[15.0]), {"rpm": [1.0, 2.0], "n_grid": [8, 9, 10]})
    with pytest.raises(ValueError, match="must be one of"):
        ujoint.summarise_batch({**base(beta=[15.0])}, {"objective": ["max"]})
    empty = ujoint.summarise_batch(base(beta=[15.0]), {"rpm": np.array([])})
    assert len(empty) == 0 and "pp_ratio" in empty


SWEEP = """&ujoint
  beta = 12.0, 24.0, option = {option}, n_starts = 2, table_step = 30
/
&sweep key1 = 'ujoint.phi', start1 = 60, stop1 = 120, count1 = 7
       key2 = 'ujoint.rpm', values2 = 25, 1500
       key3 = 'ujoint.objective', values3 = 'mean_square', 'peak_to_peak'
       key4 = 'ujoint.model', values4 = 'exact', 'paper'
       keep = 'pp_ratio < 0.145'
       case_outputs = '{outputs}' /
"""


def _sweep(tmp_path: Path, outputs: str, option: int = 0) -> Path:
    path = tmp_path / "usw.dat"
    text = SWEEP.format(outputs=outputs, option=option)
    path.write_text(text if option == 0 else text.replace("count1 = 7", "count1 = 2"))   # 16 optimisations
    out = tmp_path / f"{outputs}{option}"
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 0
    return out


def _path_taken(out: Path, stem: str = "usw") -> str:
    """'batch' or 'case': the parts of the resume record <stem>.sweep/ say which kind of chunk
    ran (their metadata's kind: driver.sweep._resume)."""
    import json

    import pyarrow.parquet as pq
    kinds = {json.loads(pq.read_schema(p).metadata[b"sweep"])["kind"] for p in (out / f"{stem}.sweep").glob("part-*")}
    assert len(kinds) == 1, kinds
    return "case" if kinds == {"cases"} else "batch"


def test_sweep_takes_the_batch_path_and_equals_case_by_case(tmp_path):
    batch, single_ = _sweep(tmp_path, "none"), _sweep(tmp_path, "all")
    assert _path_taken(batch) == "batch" and _path_taken(single_) == "case"
    a = pd.read_parquet(batch / "usw_summary.parquet")
    b = pd.read_parquet(single_ / "usw_summary.parquet")
    assert len(a) == 56 and 0 < a["kept"].sum() < 56
    pd.testing.assert_frame_equal(a, b, check_dtype=False)
    ta = (batch / "usw.out").read_text().replace("case outputs                 none", "")
    tb = (single_ / "usw.out").read_text().replace("case outputs                 all", "")
    assert ta == tb
    # a base deck that optimises per case (option 1) runs case by case
    opt = _sweep(tmp_path, "none", option=1)
    assert _path_taken(opt) == "case" and len(pd.read_parquet(opt / "usw_summary.parquet")) == 16


def test_shipped_phasing_sweep_finds_the_cancelling_phases(tmp_path):
    """inputs/ujoint_phasing_sweep.dat: two equal joints run at constant velocity exactly when the
    yokes on the intermediate shaft lie in their joints' planes, phi = rho + 90 deg (mod 180)."""
    assert main([str(ROOT / "inputs" / "ujoint_phasing_sweep.dat"), "-o", str(tmp_path), "-q", "-j", "1"]) == 0
    assert _path_taken(tmp_path, "ujoint_phasing_sweep") == "batch"
    kept = pd.read_parquet(tmp_path / "ujoint_phasing_sweep_summary.parquet")
    kept = kept[kept["kept"]]
    got = sorted(zip(kept["ujoint.rho"], kept["ujoint.phi"]))
    assert got == [(rho, (rho + 90) % 180) for rho in (0, 30, 60, 90)]
    assert (kept["pp_ratio"] < 1e-14).all() and (kept["beta_res_deg"].abs() < 1e-6).all()


def test_optimize_evaluates_populations_in_one_call_and_finds_option_1(tmp_path, monkeypatch):
    from driver.optimize import optimize
    calls, runs = [], []
    real_batch, real_run = ujoint.summarise_batch, ujoint.run

    def counted_batch(b, columns=None):
        calls.append(len(next(iter(columns.values()))))
        return real_batch(b, columns)

    def counted_run(*a, **kw):
        runs.append(1)
        return real_run(*a, **kw)
    study = ujoint.STUDY   # the engines reach the study through its declaration (driver._study)
    monkeypatch.setattr(ujoint, "STUDY", dataclasses.replace(study, run=counted_run,
                                                             batch=dataclasses.replace(study.batch, fn=counted_batch)))
    oc = optimize(ROOT / "inputs" / "optimize_ujoint_option1.dat", tmp_path, jobs=1)
    assert oc.success
    # every design went through the batch path, a gradient stencil's new points in one call (at most
    # 2), a lattice-polish move's 3^2 - 1 = 8 neighbours in one call
    assert sum(calls) == oc.nfev and max(calls) == 8 and len(calls) < oc.nfev
    assert len(runs) <= 2                                # the probe of the deck's design and the final check
    # the known optimum of option 1: phases in phase (90, 90), U as the single run gives there
    assert oc.x["ujoint.phi(1)"] == pytest.approx(90.0, abs=0.01)
    assert oc.x["ujoint.phi(2)"] == pytest.approx(90.0, abs=0.01)
    at = real_run(model="paper", phasing="cumulative", beta=[15.0, 20.0, 9.0], phi=[90.0, 90.0]).summary
    assert oc.fun == pytest.approx(at["objective"], rel=1e-8)
