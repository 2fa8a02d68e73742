"""&optimize: reported optima checked against independent truth.

* the four-bar design problem against the committed 10^5-point grid search of the same
  problem (outputs/fourbar_design_search_summary.csv) and a brute-force box around the optimum;
* local methods against a closed form (Freudenstein-free: the transmission angle at theta = 0);
* bad decks refused before anything runs; failing designs counted, never fatal; a run that
  does not converge says so and exits 1; --resume replays a run without recomputing.
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from driver import fourbar
from driver._cli import main
from driver._deck import DeckError, RawGroup, read_deck, validate
from driver.optimize import optimize

ROOT = Path(__file__).resolve().parents[1]
DECK = ROOT / "inputs" / "optimize_fourbar_design.dat"


def _fourbar_summary(crank: float, coupler: float, rocker: float) -> dict:
    raw = RawGroup("fourbar", {"fixed_link": 12.0, "crank": float(crank), "coupler": float(coupler),
                               "rocker": float(rocker), "omega": 5.0, "step_deg": 10.0}, {}, 1)
    return fourbar.summarise(validate(raw, fourbar.SPEC, "x.dat"))


def _feasible(s: dict) -> bool:
    return bool(s["meets_transmission_band"]) and s["rocker_swing_deg"] is not None and s["rocker_swing_deg"] >= 60


@pytest.fixture(scope="module")
def design(tmp_path_factory):
    out = tmp_path_factory.mktemp("opt")
    return optimize(DECK, out, jobs=1), out


def test_design_problem_beats_the_grid_search_with_few_evaluations(design):
    oc, _ = design
    assert oc.success
    grid = pd.read_csv(ROOT / "outputs" / "fourbar_design_search_summary.csv")   # 102400 designs, kept rows
    grid_best = grid["mu_min_deg"].max()
    assert grid_best == pytest.approx(55.2846, abs=1e-3)
    assert oc.fun >= grid_best
    assert oc.nfev <= 0.05 * 25 * 64 * 64


def test_design_optimum_checked_by_the_exact_kernel_and_a_brute_force_box(design):
    oc, _ = design
    x = oc.x
    s = _fourbar_summary(x["fourbar.crank"], x["fourbar.coupler"], x["fourbar.rocker"])
    assert _feasible(s) and s["grashof_class"] == "crank-rocker"
    assert s["mu_min_deg"] == pytest.approx(oc.fun, abs=1e-12)
    # closed form of the minimum transmission angle of a crank-rocker (A nearest O_B, theta = 0)
    p, q, r, t = 12.0, x["fourbar.crank"], x["fourbar.coupler"], x["fourbar.rocker"]
    assert oc.fun == pytest.approx(math.degrees(math.acos((r * r + t * t - (p - q) ** 2) / (2 * r * t))), abs=1e-9)
    # no feasible design in a +-1 % box around the optimum is better by more than the stopping tolerance
    best = -np.inf
    for f in np.linspace(0.99, 1.01, 5):
        for g in np.linspace(0.99, 1.01, 5):
            for h in np.linspace(0.99, 1.01, 5):
                s = _fourbar_summary(q * f, r * g, t * h)
                if _feasible(s):
                    best = max(best, s["mu_min_deg"])
    assert best <= oc.fun + 0.05


def test_design_outputs_say_optimum_and_verify_it(design):
    oc, out = design
    text = (out / "optimize_fourbar_design.out").read_text()
    assert "Result: CONVERGED" in text and "agrees with the evaluation" in text
    deck = read_deck(out / "optimize_fourbar_design.optimum.dat")
    assert "optimize" not in deck.groups
    assert deck.groups["fourbar"].values["crank"] == pytest.approx(oc.x["fourbar.crank"], rel=1e-12)
    assert (out / "optimize_fourbar_design.optimum.out").exists()
    hist = pd.read_csv(out / "optimize_fourbar_design_history.csv")
    assert hist["objective"].dropna().is_monotonic_increasing
    assert hist["objective"].iloc[-1] == pytest.approx(oc.fun)
    evals = pd.read_parquet(out / "optimize_fourbar_design_evals.parquet")
    assert len(evals) == oc.nfev and evals["eval"].is_unique
    assert evals.loc[evals["feasible"], "objective"].max() == pytest.approx(oc.fun)
    assert not (out / "optimize_fourbar_design.journal.jsonl").exists()


def test_resume_replays_without_computing(design, tmp_path):
    oc, out = design
    for f in out.iterdir():
        (tmp_path / f.name).write_bytes(f.read_bytes())
    again = optimize(DECK, tmp_path, jobs=1, resume=True)
    assert again.evaluator.computed == 0
    assert again.x == oc.x and again.nfev == oc.nfev


def _deck(tmp_path, body: str, study: str | None = None) -> Path:
    study = study or "&fourbar fixed_link = 12, crank = 3, coupler = 15, rocker = 9, omega = 5, step_deg = 10 /"
    path = tmp_path / "opt.dat"
    path.write_text(f"{study}\n&optimize\n{body}\n/\n")
    return path


@pytest.mark.parametrize("method", ["slsqp", "trust-constr"])
def test_local_methods_reach_the_closed_form(tmp_path, method):
    """mu_min of a crank-rocker = 45 deg: coupler r from r^2 - 2 s cos45 r + s^2 - (p - q)^2 = 0."""
    path = _deck(tmp_path, f"var1 = 'fourbar.coupler', lower1 = 10, upper1 = 20\n"
                           f"minimize = '(mu_min_deg - 45)**2'\nmethod = '{method}', starts = 3, tol = 1e-6")
    oc = optimize(path, tmp_path / "out", jobs=1)
    p, q, s = 12.0, 3.0, 9.0
    c = math.cos(math.radians(45))
    r = s * c + math.sqrt(s * s * c * c - s * s + (p - q) ** 2)
    assert oc.success
    assert oc.x["fourbar.coupler"] == pytest.approx(r, abs=1e-4)


def test_failing_designs_are_counted_not_fatal(tmp_path):
    # cranks longer than the others: many designs cannot turn or assemble
    path = _deck(tmp_path, "var1 = 'fourbar.crank', lower1 = 1, upper1 = 30\n"
                           "maximize = 'mu_min_deg'\nconstraint1 = 'grashof_class == \"crank-rocker\"'\n"
                           "method = 'grid', grid_count = 30")
    oc = optimize(path, tmp_path / "out", jobs=1)
    assert oc.success
    text = (tmp_path / "out" / "opt.out").read_text()
    assert "violates constraint1" in text
    bad = sum(1 for r in oc.evaluator.records if not r.feasible)
    assert bad > 0 and oc.nfev == 30
    # independent: the best crank-rocker of the grid by direct evaluation
    best = max((s["mu_min_deg"], c) for c in np.linspace(1, 30, 30)
               for s in [_fourbar_summary(c, 15, 9)] if s["grashof_class"] == "crank-rocker")
    assert oc.fun == best[0] and oc.x["fourbar.crank"] == best[1]


def test_not_converged_exits_1_and_never_says_optimum(tmp_path, capsys):
    path = _deck(tmp_path, "var1 = 'fourbar.crank', lower1 = 1, upper1 = 5\n"
                           "var2 = 'fourbar.rocker', lower2 = 4, upper2 = 12\n"
                           "maximize = 'mu_min_deg'\nmaxiter = 2, tol = 0, atol = 0")
    assert main([str(path), "-o", str(tmp_path / "out"), "-q", "-j", "1"]) == 1
    assert "did not converge" in capsys.readouterr().err
    text = (tmp_path / "out" / "opt.out").read_text()
    assert "NOT CONVERGED" in text and "not an optimum" in text
    assert "NOT converged" in (tmp_path / "out" / "opt.optimum.dat").read_text()


@pytest.mark.parametrize("body, key, words", [
    ("var1 = 'fourbar.crank', lower1 = 1, upper1 = 5\nmaximize = 'mu_minimum'", "maximize", "unknown summary column"),
    ("var1 = 'fourbar.crank', lower1 = 1, upper1 = 5\nmaximize = '__import__(\"os\")'", "maximize", "not allowed"),
    ("var1 = 'fourbar.crank', lower1 = 5, upper1 = 1\nmaximize = 'mu_min_deg'", "upper1", "must exceed"),
    ("var1 = 'fourbar.crank', lower1 = 1\nmaximize = 'mu_min_deg'", "var1", "needs upper1"),
    ("var1 = 'fourbar.method', lower1 = 1, upper1 = 2\nmaximize = 'mu_min_deg'", "var1", "not a real number"),
    ("var1 = 'fourbar.cranks', lower1 = 1, upper1 = 2\nmaximize = 'mu_min_deg'", "var1", "no key"),
    ("var1 = 'fourbar.crank', lower1 = 1, upper1 = 2\nmaximize = 'mu_min_deg', minimize = 'mu_max_deg'",
     "maximize", "exactly one"),
    ("var1 = 'fourbar.crank', lower1 = 1, upper1 = 2\nvar2 = 'fourbar.rocker', lower2 = 1, upper2 = 2\n"
     "maximize = 'mu_min_deg', method = 'grid', grid_count = 100000", "grid_count", "max_evals"),
    ("var1 = 'fourbar.crank', lower1 = 1, upper1 = 2\nmaximize = 'mu_min_deg'\nconstraint1 = 'x[0] > 1'",
     "constraint1", "not allowed"),
    ("var1 = 'fourbar.crank(1)', lower1 = 1, upper1 = 2\nmaximize = 'mu_min_deg'", "var1", "one number, not a list"),
    ("var1 = 'fourbar.coupler_point(3)', lower1 = 1, upper1 = 2\nmaximize = 'mu_min_deg'", "var1", "element 3"),
])
def test_bad_decks_exit_2_and_write_nothing(tmp_path, capsys, body, key, words):
    path = _deck(tmp_path, body)
    out = tmp_path / "out"
    assert main([str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"key '{key}'" in err and words in err
    assert not out.exists()


def test_sweep_and_optimize_together_refused(tmp_path):
    path = _deck(tmp_path, "var1 = 'fourbar.crank', lower1 = 1, upper1 = 2\nmaximize = 'mu_min_deg'\n/\n"
                           "&sweep key1 = 'fourbar.rocker', values1 = 8, 9")
    with pytest.raises(DeckError, match="not both"):
        optimize(path)


def test_ujoint_through_the_generic_group_finds_the_study_optimum(tmp_path):
    oc = optimize(ROOT / "inputs" / "optimize_ujoint_option1.dat", tmp_path, jobs=1)
    assert oc.success
    # the study's own option-1 optimiser (ujoint_option1.out): U = 1.16795E-04 at phi = 90, 90 deg
    text = (ROOT / "outputs" / "ujoint_option1.out").read_text()
    assert "optimum    15.0000    20.0000     9.0000    90.0000    90.0000" in text
    assert "1.16795E-04" in text
    assert oc.fun == pytest.approx(1.16795e-4, rel=5e-6)
    assert oc.x["ujoint.phi(1)"] == pytest.approx(90.0, abs=0.01)
    assert oc.x["ujoint.phi(2)"] == pytest.approx(90.0, abs=0.01)


def test_manipulator_least_torque_robust_design_beats_the_walk_along_crob(tmp_path):
    from scipy.optimize import minimize_scalar

    from driver import manipulator
    oc = optimize(ROOT / "inputs" / "optimize_manipulator_torque.dat", tmp_path, jobs=1)
    assert oc.success
    l1, l2 = oc.x["manipulator.designs_l1"], oc.x["manipulator.designs_l2"]
    # on C_rob (eq. 4.12) within the stated tolerance, constraint_tol x max(1, |a|, |b|) = 1e-7 x 47.25
    assert l1 * l1 + l2 * l2 == pytest.approx(47.25, abs=1e-7 * 47.25 * 1.001)
    assert oc.check.summary["design_ri2"] == pytest.approx(2.0, abs=1e-5)   # RI2 = sqrt(n) there
    # the report's walk along C_rob in 0.25 m steps (Table 4.8) finds no less torque
    walk = oc.study_result.summary["sweep_min_tau_sum_signed_Nm"]   # every torque > 0 here: a demand too
    assert oc.fun <= walk
    # independent search: one variable, the angle along C_rob, bounded scalar minimisation
    deck = read_deck(ROOT / "inputs" / "optimize_manipulator_torque.dat")
    raw = deck.groups["manipulator"]

    def torque(t: float) -> float:
        values = dict(raw.values, designs_l1=[47.25 ** 0.5 * math.cos(t)], designs_l2=[47.25 ** 0.5 * math.sin(t)])
        p = validate(RawGroup("manipulator", values, raw.lines, raw.line), manipulator.SPEC, "x.dat")
        return manipulator.run(p).summary["design_torque_demand_Nm"]

    t0 = math.atan2(l2, l1)
    res = minimize_scalar(torque, bounds=(t0 - 0.05, t0 + 0.05), method="bounded", options={"xatol": 1e-7})
    assert oc.fun == pytest.approx(res.fun, abs=1e-3)
    assert math.atan2(l2, l1) == pytest.approx(res.x, abs=1e-4)


@pytest.mark.slow
def test_slidercrank_lightest_rod_is_bound_by_the_euler_constraint(tmp_path):
    """Width fixed: the lightest depth is where N_peak / P_E = 1/3; found again by bisection on the study."""
    from scipy.optimize import brentq

    from driver import slidercrank
    text = (ROOT / "inputs" / "optimize_slidercrank_section.dat").read_text()
    text = text.replace("  var2 = 'slidercrank.section_depth', lower2 = 2e-3, upper2 = 20e-3\n", "")
    text = text.replace("var1 = 'slidercrank.section_width', lower1 = 6e-3, upper1 = 20e-3",
                        "var1 = 'slidercrank.section_depth', lower1 = 2e-3, upper1 = 20e-3")
    text = text.replace("section_width = 9e-3, section_depth = 3e-3", "section_width = 6e-3, section_depth = 8e-3")
    text = text.replace("n_elements = 20", "n_elements = 10")
    text = text.replace("method = 'differential_evolution', seed = 1, tol = 1e-4, atol = 0",
                        "method = 'slsqp', starts = 2, tol = 1e-6")
    path = tmp_path / "sc.dat"
    path.write_text(text)
    oc = optimize(path, tmp_path / "out", jobs=1)
    assert oc.success
    raw = read_deck(path).groups["slidercrank"]

    def ratio(h: float) -> float:
        p = validate(RawGroup("slidercrank", dict(raw.values, section_depth=h), raw.lines, raw.line),
                     slidercrank.SPEC, "x.dat")
        return slidercrank.run(p).summary["euler_ratio_max"] - 1 / 3

    h = brentq(ratio, 4e-3, 8e-3, xtol=1e-12)
    assert oc.x["slidercrank.section_depth"] == pytest.approx(h, rel=1e-5)
    assert oc.fun == pytest.approx(2660 * 6e-3 * h * 0.505, rel=1e-5)     # rho w h L


def test_grid_started_local_search_and_partial_journal_resume(tmp_path):
    """start = 'grid': the best grid points start SLSQP; an interrupted run's journal is replayed."""
    body = ("var1 = 'fourbar.coupler', lower1 = 10, upper1 = 20\n"
            "minimize = '(mu_min_deg - 45)**2'\nmethod = 'slsqp', start = 'grid', grid_count = 6, starts = 2")
    path = _deck(tmp_path, body)
    out = tmp_path / "out"
    oc = optimize(path, out, jobs=1)
    assert oc.success
    c = math.cos(math.radians(45))
    assert oc.x["fourbar.coupler"] == pytest.approx(9 * c + math.sqrt(81 * c * c - 81 + 81), abs=1e-4)
    # the grid's six points were evaluated first
    evals = pd.read_parquet(out / "opt_evals.parquet")
    assert list(evals["fourbar.coupler"].iloc[:6]) == pytest.approx(list(np.linspace(10, 20, 6)))
    # an interrupted run: a journal holding the first half of the evaluations (as the run appends them)
    from driver.optimize import _journal as journal
    half = evals.iloc[: len(evals) // 2]
    lines = [journal.line(journal.record(oc.problem.fingerprint(), oc.problem.code_digest(), [float(v)], "ok", "",
                          {k[len("summary."):]: (None if isinstance(row[k], float) and math.isnan(row[k])
                                                 else (row[k].item() if hasattr(row[k], "item") else row[k]))
                           for k in evals.columns if k.startswith("summary.")}))
             for v, (_, row) in zip(half["fourbar.coupler"], half.iterrows())]
    (out / "opt_evals.parquet").unlink()
    (out / "opt.journal.jsonl").write_text("".join(lines) + "{\"cut by an interrupt")
    again = optimize(path, out, jobs=1, resume=True)
    assert again.evaluator.computed == len(evals) - len(half)
    assert again.x == oc.x and again.nfev == oc.nfev
    assert not (out / "opt.journal.jsonl").exists()


#: a small slider-crank problem (no batch path: every design is one integration, case by case)
SC_SMALL = """&slidercrank
  material = 'aluminium'
  section_width = 9e-3, section_depth = 3e-3
  speeds = 29.32
  n_elements = 4, steps_per_rev = 720, revolutions = 1
  geometric_stiffness = .true.
/
&optimize
  var1 = 'slidercrank.section_width', lower1 = 6e-3, upper1 = 20e-3
  var2 = 'slidercrank.section_depth', lower2 = 2e-3, upper2 = 20e-3
  minimize = 'rod_mass_kg'
  constraint1 = 'euler_ratio_max <= 1/3'
  method = 'differential_evolution', seed = 3, popsize = 4, maxiter = 3, tol = 0, atol = 0
/
"""


def _trace(oc) -> tuple:
    """Everything a run decided: designs in evaluation order with their results, and the history."""
    recs = [(r.x, r.status, r.feasible, r.objective, r.margins) for r in oc.evaluator.records]
    hist = [(h.step, h.evals, h.objective, h.x, h.feasible) for h in oc.history]
    return oc.x, oc.fun, oc.nfev, recs, hist


def test_differential_evolution_same_run_in_one_process_worker_processes_and_on_dask(tmp_path, monkeypatch):
    """A study without a batch path: each generation goes case by case to worker processes or a
    Dask LocalCluster (submitted at once, gathered in order); the run is the same design for
    design, generation for generation, as in one process."""
    distributed = pytest.importorskip("distributed")
    import os

    from driver import slidercrank
    from driver.optimize import _evaluate as evaluate
    # a LocalCluster with worker processes sets OMP/MKL/OPENBLAS_NUM_THREADS=1 in this process's
    # environment; later tests' subprocesses must not inherit that (SLSQP results follow OpenBLAS's
    # thread count in the last bits, and the committed outputs are compared byte for byte)
    for name in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MALLOC_TRIM_THRESHOLD_"):
        monkeypatch.setenv(name, os.environ.get(name, ""))   # recorded: undone after the test
        if not os.environ[name]:
            monkeypatch.delenv(name)
    assert not hasattr(slidercrank, "summarise_batch")
    path = tmp_path / "sc.dat"
    path.write_text(SC_SMALL)
    serial = optimize(path, None, jobs=1)
    assert set(serial.evaluator.routes) == {"serial"}
    assert serial.nfev == 4 * 2 * (3 + 1) and len(serial.history) == 3
    monkeypatch.setattr(evaluate, "POOL_MIN_SECONDS", 0.0)   # every batch after the first to the pool
    pooled = optimize(path, None, jobs=2)
    assert pooled.evaluator.routes.get("processes", 0) >= 3 * 8
    assert _trace(pooled) == _trace(serial)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=":0") as cluster:
        with distributed.Client(cluster) as client:
            on_dask = optimize(path, None, scheduler=client)
            routes = on_dask.evaluator.routes     # (a lone design is computed here, not shipped)
            assert set(routes) <= {"dask", "serial"} and routes["dask"] >= 3 * 8
            assert _trace(on_dask) == _trace(serial)
        # --scheduler on the command line is the one used (an address: the run connects itself)
        out = tmp_path / "cli"
        main([str(path), "-o", str(out), "-q", "--scheduler", cluster.scheduler_address])
    ref = tmp_path / "ref"
    main([str(path), "-o", str(ref), "-q", "-j", "1"])
    for name in ("sc.out", "sc_history.csv", "sc.optimum.dat"):
        assert (out / name).read_text() == (ref / name).read_text()
    a, b = pd.read_parquet(out / "sc_evals.parquet"), pd.read_parquet(ref / "sc_evals.parquet")
    pd.testing.assert_frame_equal(a, b)


def test_a_deck_never_names_the_scheduler(tmp_path, capsys):
    path = tmp_path / "sc.dat"
    path.write_text(SC_SMALL.replace("  method = ", "  scheduler = 'tcp://10.0.0.1:8786'\n  method = "))
    assert main([str(path), "-o", str(tmp_path / "out")]) == 2
    assert "scheduler" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_over_budget_and_non_finite_designs_are_infeasible_with_reasons(tmp_path, monkeypatch):
    """Per-design runs go through the runner: a design over the work budget is refused before it
    runs, counted by reason, and never ends the run (a Dask worker gets the budget with the cases)."""
    from driver import _limits as limits
    from driver import slidercrank
    path = tmp_path / "sc.dat"
    path.write_text(SC_SMALL.replace("var2 = 'slidercrank.section_depth', lower2 = 2e-3, upper2 = 20e-3",
                             "var2 = 'slidercrank.section_depth', lower2 = 2e-3, upper2 = 20e-3\n"
                             "  var3 = 'slidercrank.speeds', lower3 = 10, upper3 = 30"))
    real = slidercrank.estimate

    def estimate(params):   # a fast design counts as an absurd one between 25 and 29 rad/s (the deck's own
        est = real(params)  # design, 29.32, is within the budget: a run whose own design is not is refused)
        return limits.Estimate(est.bytes, 1e9 if 25 < params.speeds[0] < 29 else est.seconds, est.memory_key,
                               "speeds", "a test's stand-in")
    run = slidercrank.run

    def run_nan(params, progress=False):   # a slow design writes a NaN into its table
        result = run(params, progress)
        return dataclasses.replace(result, text=result.text + "   nan\n") if params.speeds[0] < 12 else result
    monkeypatch.setattr(slidercrank, "STUDY", dataclasses.replace(slidercrank.STUDY, estimate=estimate, run=run_nan))
    oc = optimize(path, tmp_path / "out", jobs=1)
    nan = [r for r in oc.evaluator.records if r.x[2] < 12 and r.status != "bad_input"]
    assert nan and all(r.status == "failed" and "not a finite number" in r.reason for r in nan)
    refused = [r for r in oc.evaluator.records if r.status == "refused"]
    assert refused and all(25 < r.x[2] < 29 for r in refused)
    assert all(r.status != "refused" for r in oc.evaluator.records if not 25 < r.x[2] < 29)
    assert all(not r.feasible and r.why.startswith("refused, over the budget") for r in refused)
    text = (tmp_path / "out" / "sc.out").read_text()
    assert f"{len(refused):>8}  refused, over the budget of one run: speeds:" in text


def test_crank_rocker_through_optimize_agrees_with_the_closed_form_family(tmp_path):
    """inputs/optimize_crank_rocker.dat states the textbook problem of
    inputs/synthesis_crank_rocker.dat (swing 60 deg, time ratio 1.25, ground 10, best
    transmission angle) over the four-bar keys; SLSQP from seeded starts, knowing nothing of the
    construction, must land on the closed-form family's best member.  Tolerances: swing and time
    ratio are held within 1e-6 by the deck's constraint pairs, which moves the optimum along the
    family by about 1e-5 (lengths) and its objective by < 1e-4 deg."""
    from driver.synthesis import _crank_rocker as cr
    from driver.synthesis import synthesise
    oc = optimize(ROOT / "inputs" / "optimize_crank_rocker.dat", None, jobs=1)
    assert oc.success
    syn = synthesise(ROOT / "inputs" / "synthesis_crank_rocker.dat")
    best = syn.design
    crank, coupler, rocker = best.scaled(10.0)
    assert oc.fun == pytest.approx(best.quality_deg, abs=1e-4)
    assert oc.x["fourbar.crank"] == pytest.approx(crank, rel=1e-5)
    assert oc.x["fourbar.coupler"] == pytest.approx(coupler, rel=1e-5)
    assert oc.x["fourbar.rocker"] == pytest.approx(rocker, rel=1e-5)
    # the optimum, re-run by the full study: swing and time ratio as asked, a crank-rocker
    s = oc.check.summary
    assert oc.check.feasible and s["grashof_class"] == "crank-rocker"
    # the deck's bands (1e-6) widened by the stated feasibility tolerance, 1e-7 x max(1, |a|, |b|)
    assert s["rocker_swing_deg"] == pytest.approx(60.0, abs=1e-6 + 1e-7 * 60.0 * 1.0001)
    assert s["time_ratio"] == pytest.approx(1.25, abs=1e-6 + 1e-7 * 1.25 * 1.0001)
    # no family member (a fine scan of both arcs, closed form) beats it beyond the band's slack
    fine = [m for m in cr.family(60.0, 1.25, 4001) if m.crank_rocker]
    assert oc.fun >= max(m.quality_deg for m in fine) - 1e-4
