"""Batched 2R design summaries (fortran/manipulator_summary.f90 through manipulator.summarise_batch)
against independent truth:

* the single run (``run(...).summary``: tables built from the IK, design-index, torque and
  positioning-error kernels and the SLSQP/closed-form tolerance box) equals the batch row for
  every column to the last printed digit -- the first design's torque, indices and C_rob
  residual to the last bit -- for random workspaces and designs in both modes (hypothesis);
* designs a run refuses (unreachable workspace or target) get their status from the reach
  conditions |l1 - l2| <= d <= l1 + l2 written here, never a NaN in a table;
* a singular design (every point at the stretched arm) in closed form;
* a sweep deck takes the batch path and equals the per-case path; the optimiser evaluates a
  population in one kernel call and never case by case.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from driver import manipulator
from driver._cli import main
from driver._deck import DeckError, Params
from driver.manipulator import BATCH_KEYS, SPEC, summarise, summarise_batch
from driver.manipulator import _kernel as manipulator_kernel

ROOT = Path(__file__).resolve().parents[1]
#: what the bit-exact comparison covers (an optimiser's finite differences see these)
BITWISE = ("design_l1_m", "design_l2_m", "design_ri1", "design_ri2", "design_ri3", "design_ri2_excess",
           "design_crob_residual_m2", "design_tau_sum_signed_Nm")


def params(**kw) -> Params:
    """A validated-looking &manipulator Params (SPEC defaults, values from kw)."""
    vals = {k: spec.default for k, spec in SPEC.keys.items()}
    vals.update({"points_x": [1.0, 2.0, 3.0, 4.0], "points_y": [5.0, 7.0, 7.0, 6.0], "mc_samples": 300})
    vals.update(kw)
    return Params("manipulator", Path("test.dat"), vals, {}, 1)


def reaches(l1: float, l2: float, x, y, tol: float = 1e-9) -> bool | None:
    """Reach conditions (4.4) at every point (test oracle); None within ``tol`` of the boundary."""
    d = np.hypot(np.asarray(x), np.asarray(y))
    margin = np.minimum(d - abs(l1 - l2), l1 + l2 - d)
    if np.abs(margin).min() < tol * max(1.0, d.max()):
        return None
    return bool((margin > 0).all())


def printed(v) -> str:
    """A summary value as a table prints it (6 significant digits, the .out's SIGNIFICANT)."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    if isinstance(v, (bool, np.bool_, str)):
        return str(v)
    return f"{float(v):.6g}"


def assert_row_equals_run(row: pd.Series, one: dict) -> None:
    assert list(row.index) == list(one), (list(row.index), list(one))
    for k, v in one.items():
        b = row[k]
        if k in BITWISE:
            assert (v is None and pd.isna(b)) or v == b, (k, v, b)
        else:
            assert printed(v) == printed(b), (k, v, b)
            if isinstance(v, float) and v is not None:
                assert b == pytest.approx(v, rel=1e-12, abs=1e-15), (k, v, b)


coord = st.floats(-6.0, 6.0, allow_nan=False).filter(lambda v: abs(v) > 0.05)
length = st.floats(0.3, 9.0, allow_nan=False)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(pts=st.lists(st.tuples(coord, coord), min_size=1, max_size=5),
       designs=st.lists(st.tuples(length, length), min_size=1, max_size=6),
       mode=st.sampled_from(["exact", "report"]), elbow=st.sampled_from([1, -1]),
       measure=st.sampled_from(["global", "per_point"]), g=st.sampled_from([9.8, 0.0, 3.71]),
       mpl=st.floats(0.5, 20.0))
def test_batch_equals_single_run(pts, designs, mode, elbow, measure, g, mpl):
    """Every design that a single run accepts gives the run's summary; the others their status."""
    x, y = [p[0] for p in pts], [p[1] for p in pts]
    base = params(points_x=x, points_y=y, mode=mode, elbow=elbow, error_measure=measure, gravity=g,
                  mass_per_length=mpl, designs_l1=[5.0], designs_l2=[4.0])
    arr = np.array(designs)
    batch = summarise_batch(base, {"designs_l1": arr[:, 0], "designs_l2": arr[:, 1]})
    assert len(batch) == len(designs)
    for i, (l1, l2) in enumerate(designs):
        truth = reaches(l1, l2, x, y)
        assume(truth is not None)
        row = batch.iloc[i]
        assert bool(row["design_reaches_all"]) == truth
        one_p = params(points_x=x, points_y=y, mode=mode, elbow=elbow, error_measure=measure, gravity=g,
                       mass_per_length=mpl, designs_l1=[l1], designs_l2=[l2])
        if not truth:
            assert row["design_status"] == "unreachable"
            assert pd.isna(row["design_1_dl_m"]) and not row["design_1_reaches_workspace"]
            with pytest.raises(DeckError, match="violates the reach conditions"):
                manipulator.run(one_p)
            continue
        d0 = math.hypot(x[0], y[0])      # the target: the first workspace point
        assert row["design_status"] in ("ok", "singular")
        assert abs(l1 - l2) - 1e-9 <= d0 <= l1 + l2 + 1e-9
        assert_row_equals_run(row, manipulator.run(one_p).summary)
        assert_row_equals_run(row, summarise(one_p))


def test_several_designs_per_deck_and_the_optima():
    """k designs per deck ((n, k) columns) and the default optima on C_rob, both modes."""
    for mode in ("exact", "report"):
        base = params(mode=mode, mc_samples=2000)
        one = manipulator.run(base).summary
        assert_row_equals_run(summarise_batch(base).iloc[0], one)
        assert "dexterity_tau1_Nm" in one and "workspace_mc_max_m" in one
    l1 = np.array([[5.61, 4.86], [5.0, 5.2]])
    l2 = np.array([[3.97, 4.86], [4.5, 4.3]])
    batch = summarise_batch(params(design_names=["A", "B"], designs_l1=[1.0, 1.0], designs_l2=[1.0, 1.0]),
                            {"designs_l1": l1, "designs_l2": l2})
    for i in range(2):
        one = manipulator.run(params(design_names=["A", "B"], designs_l1=list(l1[i]), designs_l2=list(l2[i])))
        assert_row_equals_run(batch.iloc[i], one.summary)


def test_swept_target_masses_gravity_and_bound():
    base = params(designs_l1=[5.61], designs_l2=[3.97], mc_samples=500)
    cols = {"target_x": [1.0, 2.0, 3.0, 1.0], "target_y": [5.0, 7.0, 7.0, 5.0], "gravity": [9.8, 9.8, 0.0, 1.62],
            "mass_per_length": [10.0, 4.0, 10.0, 12.5], "tolerance_bound": [0.01, 0.002, 0.01, 1e-5]}
    batch = summarise_batch(base, cols)
    for i in range(4):
        one = manipulator.run(params(designs_l1=[5.61], designs_l2=[3.97], mc_samples=500,
                                     **{k: v[i] for k, v in cols.items()}))
        assert_row_equals_run(batch.iloc[i], one.summary)
    # the C_rob walk depends on the target, masses and g: rows 1 and 4 share the target only
    assert batch["sweep_min_tau_sum_signed_Nm"].nunique() == 4


def test_target_out_of_reach_and_singular_designs():
    """A target the design cannot reach: no torques (the run refuses the deck); a workspace on
    one circle of the stretched arm's radius: sigma_min = 0, RI1 undefined, RI2 = sqrt(2n)."""
    base = params(designs_l1=[5.61], designs_l2=[3.97])
    row = summarise_batch(base, {"target_x": [0.5], "target_y": [0.5]}).iloc[0]
    assert row["design_status"] == "target_unreachable" and bool(row["design_reaches_all"])
    assert pd.isna(row["design_tau_sum_signed_Nm"]) and pd.isna(row["design_1_tau1_Nm"])
    assert row["design_1_dl_m"] > 0                      # the tolerance box does not need the target
    with pytest.raises(DeckError, match="out of reach of every design"):
        manipulator.run(params(designs_l1=[5.61], designs_l2=[3.97], target_x=0.5, target_y=0.5))
    x, y = [3.0, 4.0, 5.0, 0.0], [4.0, 3.0, 0.0, 5.0]    # |P_i| = 5 = l1 + l2
    sing = params(points_x=x, points_y=y, designs_l1=[3.0], designs_l2=[2.0])
    row = summarise_batch(sing).iloc[0]
    assert row["design_status"] == "singular" and pd.isna(row["design_ri1"])
    assert row["design_ri2"] == pytest.approx(math.sqrt(8.0), rel=1e-15)
    assert row["design_1_dl_m"] == pytest.approx(0.01 / math.sqrt(2 * 8.0), rel=1e-12)   # eps / (sqrt2 RI2)
    assert_row_equals_run(row, manipulator.run(sing).summary)
    # the stretched arm's Monte Carlo error is |a + b| sqrt(n) at most: (dl1 + dl2) sqrt(n) bounds it
    assert row["design_1_mc_max_m"] <= 2 * row["design_1_dl_m"] * 2.0 * (1 + 1e-12)


def test_monte_carlo_against_numpy():
    """The Monte Carlo maximum (scanned over the samples' convex hull in (u1^2 + u2^2, u1 u2))
    against the errors of every sample summed point by point in numpy."""
    for measure, ns, (l1, l2) in [("global", 5000, (5.0, 4.5)), ("per_point", 5000, (5.0, 4.5)),
                                  ("global", 100000, (6.1, 3.3)), ("per_point", 100000, (4.2, 5.9))]:
        b = params(designs_l1=[l1], designs_l2=[l2], mc_samples=ns, mc_seed=7, error_measure=measure)
        row = summarise_batch(b).iloc[0]
        th1, th2, st_ = manipulator_kernel.manipulator_ik(l1, l2, b.points_x, b.points_y, b.elbow)
        unit = np.random.default_rng(7).uniform(-1.0, 1.0, size=(ns, 2)) * row["design_1_dl_m"]
        ex = unit[:, :1] * np.cos(th1) + unit[:, 1:] * np.cos(th1 + th2)
        ey = unit[:, :1] * np.sin(th1) + unit[:, 1:] * np.sin(th1 + th2)
        e2 = ex ** 2 + ey ** 2
        err = np.sqrt(e2.sum(1)) if measure == "global" else np.sqrt(e2.max(1))
        assert row["design_1_mc_max_m"] == pytest.approx(err.max(), rel=1e-13)
        assert row["design_1_mc_max_m"] <= 0.01 * (1 + 1e-12)     # the box keeps the bound


def test_batch_input_errors():
    base = params(designs_l1=[5.0], designs_l2=[4.5])
    with pytest.raises(DeckError, match="test.dat:1: key 'designs_l1': design 1 has"):
        summarise_batch(base, {"designs_l1": [5.0, -1.0]})
    with pytest.raises(DeckError, match="key 'gravity': design 0 has nan"):
        summarise_batch(base, {"manipulator.gravity": [np.nan]})
    with pytest.raises(DeckError, match="different lengths"):
        summarise_batch(base, {"gravity": [1.0, 2.0], "mass_per_length": [1.0, 2.0, 3.0]})
    with pytest.raises(DeckError, match="key 'points_x': not a &manipulator key"):
        summarise_batch(base, {"points_x": [1.0]})
    with pytest.raises(DeckError, match="key 'target_x': design 1: the target point is the base"):
        summarise_batch(base, {"target_x": [1.0, 0.0], "target_y": [5.0, 0.0]})
    f = summarise_batch(base, {"title": "x", "gravity": np.linspace(0, 10, 5)})
    assert len(f) == 5 and (f["design_status"] == "ok").all()
    assert len(summarise_batch(base, {"gravity": []})) == 0
    assert set(BATCH_KEYS) <= set(SPEC.keys)


SWEEP = """&manipulator
  points_x = 1, 2, 3, 4
  points_y = 5, 7, 7, 6
  designs_l1 = 5.0, designs_l2 = 4.5
  mc_samples = 400
/
&sweep key1 = 'manipulator.designs_l1', start1 = {lo1}, stop1 = 6.5, count1 = 7
       key2 = 'manipulator.designs_l2', start2 = {lo2}, stop2 = 5.0, count2 = 6
       key3 = 'manipulator.gravity', values3 = 9.8, 3.71
       keep = 'design_status == "ok" and design_tau_sum_signed_Nm < 4200'
       case_outputs = '{outputs}' /
"""


def sweep_rows(tmp_path: Path, outputs: str, lo1: float = 4.5, lo2: float = 3.6) -> tuple[int, pd.DataFrame, str]:
    path = tmp_path / f"sw_{outputs}.dat"
    path.write_text(SWEEP.format(outputs=outputs, lo1=lo1, lo2=lo2))
    out = tmp_path / outputs
    rc = main([str(path), "-o", str(out), "-j", "1"])
    return rc, pd.read_parquet(out / f"sw_{outputs}_summary.parquet"), (out / f"sw_{outputs}.out").read_text()


def test_sweep_takes_the_batch_path_and_equals_case_by_case(tmp_path, capsys):
    rc, batch, text_b = sweep_rows(tmp_path, "none")
    assert rc == 0 and "batch path" in capsys.readouterr().out
    assert (tmp_path / "none" / "sw_none.sweep").is_dir()
    rc, single, text_s = sweep_rows(tmp_path, "all")
    assert rc == 0 and len(batch) == len(single) == 84 and batch["kept"].sum() > 0
    pd.testing.assert_frame_equal(batch, single, check_dtype=False, rtol=1e-12)
    assert "nan" not in text_b.lower() and text_b.replace("none", "all") == text_s.replace("none", "all")


def test_sweep_with_unreachable_designs(tmp_path):
    """Short links cannot reach the workspace: the batch lists them with their status; the
    per-case path with case files runs each deck and refuses them as bad input."""
    rc, batch, text = sweep_rows(tmp_path, "none", lo1=1.0, lo2=1.0)
    assert rc == 0 and len(batch) == 84
    un = batch["design_status"] == "unreachable"
    truth = np.array([reaches(a, b, [1, 2, 3, 4], [5, 7, 7, 6]) for a, b in
                      zip(batch["manipulator.designs_l1"], batch["manipulator.designs_l2"])])
    assert un.sum() > 10 and (un.to_numpy() == (truth == False)).all()   # noqa: E712 (elementwise on an array)
    assert not batch.loc[un, "kept"].any()
    # torques exist where the target (1, 5) is reached, whether or not the whole workspace is
    at_target = np.array([reaches(a, b, [1], [5]) for a, b in
                          zip(batch["manipulator.designs_l1"], batch["manipulator.designs_l2"])])
    assert (batch["design_tau_sum_signed_Nm"].notna().to_numpy() == at_target).all()
    assert (batch["design_1_dl_m"].isna() == un).all()
    assert "nan" not in text.lower()
    rc, single, _ = sweep_rows(tmp_path, "all", lo1=1.0, lo2=1.0)
    assert rc == 1
    failed = single["status"] != "ok"
    assert (failed.to_numpy() == un.to_numpy()).all()
    assert single.loc[failed, "error"].str.contains("violates the reach conditions").all()
    cols = [c for c in single.columns if c not in ("status", "error")]
    pd.testing.assert_frame_equal(batch.loc[~un, cols], single.loc[~failed, cols], check_dtype=False, rtol=1e-12)


def test_optimiser_evaluates_populations_in_one_call(tmp_path, monkeypatch):
    from driver.optimize import _evaluate as evaluate
    calls = []
    real = manipulator_kernel.manipulator_design_summaries

    def counted(x, y, prm, *a, **kw):
        calls.append(len(prm))
        return real(x, y, prm, *a, **kw)

    def never(*a, **kw):
        raise AssertionError("a design evaluated case by case")

    monkeypatch.setattr(manipulator_kernel, "manipulator_design_summaries", counted)
    monkeypatch.setattr(evaluate, "evaluate_cases", never)
    out = tmp_path / "o"
    monkeypatch.chdir(ROOT)     # the deck named as the committed run named it (the .out quotes it)
    assert main(["inputs/optimize_manipulator_torque.dat", "-o", str(out), "-q"]) == 0
    evals = pd.read_parquet(out / "optimize_manipulator_torque_evals.parquet")
    assert sum(calls) >= len(evals) and max(calls) > 1
    assert len(calls) < len(evals)            # populations, not designs, per call
    # the run equals the committed one: the .out and the optimum's deck byte for byte; the evaluations
    # (the SLSQP path, which follows the BLAS kernel) by the outputs test's rule for path records
    from test_outputs_fresh import same_path_record
    for name in ("optimize_manipulator_torque.out", "optimize_manipulator_torque.optimum.dat"):
        assert (out / name).read_bytes() == (ROOT / "outputs" / name).read_bytes(), name
    committed = pd.read_parquet(ROOT / "outputs" / "optimize_manipulator_torque_evals.parquet")
    assert same_path_record(evals, committed, sense=1)


def test_per_case_summaries_equal_runs(tmp_path, capsys):
    """A key the batch does not take (elbow) sends the sweep case by case: with case_outputs
    'none' each case is ``summarise`` (one batch row), with 'all' a full run: the same rows."""
    text = ("&manipulator points_x = 1, 2, 3, 4, points_y = 5, 7, 7, 6, designs_l1 = 5.0, designs_l2 = 4.5,\n"
            "  mc_samples = 300 /\n&sweep key1 = 'manipulator.elbow', values1 = 1, -1\n"
            "  key2 = 'manipulator.designs_l1', values2 = 4.8, 5.2, 5.6\n  case_outputs = '{o}' /\n")
    frames = []
    for o in ("none", "all"):
        path = tmp_path / f"{o}.dat"
        path.write_text(text.format(o=o))
        assert main([str(path), "-o", str(tmp_path / o), "-j", "1"]) == 0
        assert "batch path" not in capsys.readouterr().out
        frames.append(pd.read_parquet(tmp_path / o / f"{o}_summary.parquet"))
    pd.testing.assert_frame_equal(frames[0], frames[1], check_dtype=False, rtol=1e-12)
    assert frames[0]["design_tau_sum_signed_Nm"].nunique() == 6     # both elbows differ
