"""The Python API (driver.run, driver.<study>.run(**keys), Result, run_sweep) against the
command line and against closed forms."""
from __future__ import annotations

import ast
import json
import math
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import driver
from conftest import INPUTS, ROOT
from driver import _cli as cli
from driver._deck import read_deck
from driver._study import REGISTRY

CRANK5 = dict(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0, omega=5.0, step_deg=20)

# decks that take longer than a few seconds (still run in CI, marked slow)
SLOW = {"fourbar_design_search", "slidercrank_aluminium", "slidercrank_low_carbon_steel",
        "slidercrank_medium_carbon_steel", "slidercrank_matrix_sweep", "slidercrank_buckling",
        "slidercrank_convergence_aluminium", "slidercrank_convergence_low_carbon_steel",
        "slidercrank_convergence_medium_carbon_steel"}


def _decks(sweep: bool) -> list:
    out = []
    for p in sorted(INPUTS.glob("*.dat")):
        text = p.read_text().lower()
        if ("&sweep" in text) != sweep or "&optimize" in text or "&synthesis" in text or p.stem == "fourbar_design_search":
            continue   # optimisation and synthesis decks have their own API (driver.optimize, driver.synthesis); the design
                       # search takes minutes and runs the same sweep code as the other sweep decks
        marks = [pytest.mark.slow] if p.stem in SLOW else []
        out.append(pytest.param(p, id=p.stem, marks=marks))
    return out


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


# ----------------------------------------------------------------------------- surface

def test_import_driver_is_cheap_and_exports_a_small_documented_surface():
    code = ("import sys, driver; heavy = [m for m in ('pandas', 'matplotlib', 'driver._kernels') if m in sys.modules];"
            "print(heavy); print(sorted(driver.__all__))")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    heavy, names = res.stdout.splitlines()
    assert heavy == "[]"
    assert ast.literal_eval(names) == sorted(["run", "run_sweep", "write", "compare", "read_deck", "studies", "keys",
                                              "Result", "Figure", "SweepResult", "DriverError", "DeckError", "ExitCode",
                                              "Message", "RunOutcome", "FilesOutcome", "SweepOutcome"])
    for name in driver.__all__:
        obj = getattr(driver, name)
        assert obj.__doc__ and len(obj.__doc__) > 40, name
    assert set(driver.studies()) == set(REGISTRY)   # every registered study, by its registry line alone
    assert driver.fourbar.run.__doc__
    assert (Path(driver.__file__).parent / "py.typed").exists()
    with pytest.raises(AttributeError):
        _ = driver.no_such_thing
    with pytest.raises(AttributeError):
        _ = driver._kernels_not_there


def test_keys_lists_every_deck_key_with_units():
    keys = driver.keys("fourbar")
    assert keys.loc["omega", "units"] == "rad/s"
    assert bool(keys.loc["crank", "required"]) and not bool(keys.loc["omega", "required"])
    assert keys.loc["method", "default"] == "exact"
    with pytest.raises(KeyError):
        driver.keys("nope")


# ----------------------------------------------------------------------------- single runs

def test_keyword_run_equals_the_deck_and_the_closed_form_transmission_angle():
    r = driver.fourbar.run(**CRANK5, method="listing")
    deck = driver.run(INPUTS / "crank5.dat")
    pd.testing.assert_frame_equal(r.tidy, deck.tidy)
    assert r.summary == deck.summary
    assert r.name == "fourbar" and r.study == "fourbar" and deck.name == "crank5"
    assert deck.out == (ROOT / "outputs" / "crank5.out").read_text()
    # transmission angle extremes of a crank-rocker: at theta = 0 and 180 deg (law of cosines)
    mu = lambda d2: math.degrees(math.acos((15.0**2 + 9.0**2 - d2) / (2 * 15.0 * 9.0)))
    assert r.summary["mu_min_deg"] == pytest.approx(mu(7.0**2), abs=1e-9)
    assert r.summary["mu_max_deg"] == pytest.approx(mu(17.0**2), abs=1e-9)
    frame = r.summary_frame
    assert frame.shape == (1, len(r.summary)) and list(frame.columns) == list(r.summary)
    assert r.ok and r.warnings and "loop closure" in r.warnings[0]


def test_deck_text_and_dict_sources():
    text = "&fourbar\n fixed_link = 12, crank = 5, coupler = 15, rocker = 9\n omega = 5, step_deg = 20 /\n"
    a = driver.run(text)
    b = driver.run({"fourbar": {**CRANK5, "step_deg": np.int64(20), "omega": np.float64(5.0)}})
    c = driver.fourbar.run(**CRANK5)
    pd.testing.assert_frame_equal(a.tidy, b.tidy)
    pd.testing.assert_frame_equal(a.tidy, c.tidy)
    assert a.name == "fourbar"
    assert driver.run(text, name="mine").name == "mine"
    legacy = driver.run((INPUTS / "crank5_terminal.dat").read_text())
    assert legacy.tidy.equals(driver.run(INPUTS / "crank5.dat").tidy)


def test_bad_input_raises_deck_error_with_line_and_key():
    with pytest.raises(driver.DeckError) as err:
        driver.run("&fourbar\n fixed_link = 12, crank = 5, coupler = 15\n rocker = -9, step_deg = 20 /\n")
    assert (err.value.line, err.value.key) == (3, "rocker") and "positive" in err.value.message
    assert isinstance(err.value, ValueError)
    with pytest.raises(driver.DeckError, match="crank_length.*unknown key"):
        driver.fourbar.run(**CRANK5, crank_length=3)
    with pytest.raises(driver.DeckError, match="missing"):
        driver.fourbar.run(fixed_link=12, crank=5, coupler=15, step_deg=20)
    with pytest.raises(driver.DeckError, match="not a deck value"):
        driver.fourbar.run(**{**CRANK5, "crank": object()})
    with pytest.raises(driver.DeckError, match="cannot read deck"):
        driver.run(ROOT / "inputs" / "no_such_deck.dat")
    with pytest.raises(driver.DeckError, match="run_sweep"):
        driver.run(INPUTS / "fourbar_paper_sweep.dat")
    with pytest.raises(driver.DeckError, match="optimize"):
        driver.run(INPUTS / "optimize_fourbar_design.dat")
    with pytest.raises(driver.DeckError, match="synthesise"):
        driver.run(INPUTS / "synthesis_crank_rocker.dat")
    with pytest.raises(TypeError):
        driver.fourbar.run(read_deck(INPUTS / "crank5.dat"), crank=3)
    with pytest.raises(TypeError):
        driver.run(42)


def test_every_study_runs_from_keyword_arguments():
    for deck_name in ("crank5_exact", "ujoint_analyse", "manipulator_case1_exact", "robust_example",
                      "slidercrank_simeon1996"):
        deck = read_deck(INPUTS / f"{deck_name}.dat")
        (group, raw), = deck.groups.items()
        by_keys = getattr(driver, group).run(**raw.values)
        by_deck = driver.run(INPUTS / f"{deck_name}.dat")
        pd.testing.assert_frame_equal(by_keys.tidy, by_deck.tidy, obj=deck_name)
        assert json.dumps(by_keys.summary, default=str) == json.dumps(by_deck.summary, default=str)


def test_figures_on_demand_and_write(tmp_path):
    r = driver.fourbar.run(**CRANK5)
    assert r.figure_names == ["curves", "linkage"]
    fig = r.figure("linkage")
    assert type(fig).__name__ == "Figure" and fig.get_dpi() == 150
    with pytest.raises(LookupError):
        r.figure("nope")
    written = driver.write(r, tmp_path / "new", formats=["csv", "parquet"], plot=True, json=True, name="c5")
    names = sorted(p.name for p in written)
    assert names == ["c5.csv", "c5.json", "c5.out", "c5.parquet", "c5_curves.png", "c5_linkage.png"]
    assert (tmp_path / "new" / "c5.out").read_text() == r.out
    with pytest.raises(ValueError):
        driver.write(r, tmp_path, name="../escape")


def test_summary_json_from_the_command_line(tmp_path):
    """--json: the four-bar extremes and the Hooke-joint optimum are machine-readable."""
    assert cli.main([str(INPUTS / "crank5_exact.dat"), str(INPUTS / "ujoint_option1.dat"),
                     "-o", str(tmp_path), "-q", "--json"]) == 0
    rec = json.loads((tmp_path / "crank5_exact.json").read_text())
    assert rec["study"] == "fourbar" and rec["name"] == "crank5_exact" and rec["ok"] is True
    mu = lambda d2: math.degrees(math.acos((15.0**2 + 9.0**2 - d2) / (2 * 15.0 * 9.0)))
    assert rec["summary"]["mu_min_deg"] == pytest.approx(mu(49.0), abs=1e-9)
    assert rec["summary"]["mu_max_deg"] == pytest.approx(mu(289.0), abs=1e-9)
    uj = json.loads((tmp_path / "ujoint_option1.json").read_text())
    dat = (tmp_path / "ujoint_option1.result.dat").read_text()
    fval = float(next(l for l in dat.splitlines() if l.startswith("fval")).split("=")[1])
    x = [float(v) for v in next(l for l in dat.splitlines() if l.startswith("x ")).split("=")[1].split()]
    assert uj["summary"]["objective"] == pytest.approx(fval, rel=1e-9)
    assert [uj["summary"][f"phi_{k}_deg"] for k in (1, 2)] == pytest.approx(x[3:], abs=1e-6)
    assert uj["summary"]["converged"] is True
    # no NaN ever reaches the JSON: missing figures are null
    nan = driver.fourbar.run(fixed_link=1, crank=5, coupler=1, rocker=1, step_deg=90)
    assert "NaN" not in driver.write(nan, tmp_path, json=True)[-1].read_text()


# ----------------------------------------------------------------------------- API == command line

@pytest.mark.parametrize("path", _decks(sweep=False))
def test_api_and_command_line_write_identical_files(path, tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)   # decks named as in the committed outputs (inputs/...)
    path = path.relative_to(ROOT)
    a, b = tmp_path / "cli", tmp_path / "api"
    assert cli.main([str(path), "-o", str(a), "-q", "--csv", "--format", "parquet", "--json"]) in (0, 1)
    r = driver.run(path)
    driver.write(r, b, formats=["csv", "parquet"], json=True)
    fa, fb = _files(a), _files(b)
    assert list(fa) == list(fb)
    for name in fa:
        if name.endswith(".parquet"):   # parquet embeds the writer's version: compare the tables
            pd.testing.assert_frame_equal(pd.read_parquet(a / name), pd.read_parquet(b / name))
        else:
            assert fa[name] == fb[name], name


@pytest.mark.parametrize("path", _decks(sweep=True))
def test_sweep_api_and_command_line_write_identical_tables(path, tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    path = path.relative_to(ROOT)
    a, b = tmp_path / "cli", tmp_path / "api"
    assert cli.main([str(path), "-o", str(a), "-q", "-j", "1"]) in (0, 1)
    s = driver.run_sweep(path, outdir=b, jobs=1)
    stem = path.stem
    assert s.out == (a / f"{stem}.out").read_text() == (b / f"{stem}.out").read_text()
    assert (a / f"{stem}_summary.csv").read_bytes() == (b / f"{stem}_summary.csv").read_bytes()
    pd.testing.assert_frame_equal(s.summary, pd.read_parquet(a / f"{stem}_summary.parquet"))


# ----------------------------------------------------------------------------- sweeps from Python

def test_sweep_grid_in_python_equals_the_sweep_deck_and_single_runs():
    base = {**CRANK5, "crank": 2.0, "method": "listing"}
    s = driver.run_sweep({"fourbar": base}, grid={"crank": np.arange(2, 6)}, jobs=1,
                         keep="mu_min_deg > 15")
    deck = driver.run_sweep(INPUTS / "fourbar_paper_sweep.dat", jobs=1)
    assert s.outdir is None and s.status == 0 and len(s.summary) == 4
    cols = [c for c in deck.summary.columns if c not in ("kept",)]
    pd.testing.assert_frame_equal(s.summary[cols], deck.summary[cols])
    for crank, row in zip((2, 3, 4, 5), s.summary.itertuples()):
        single = driver.fourbar.run(**{**base, "crank": crank}).summary
        assert row.mu_min_deg == single["mu_min_deg"] and row.rocker_swing_deg == single["rocker_swing_deg"]
        assert row.kept == (single["mu_min_deg"] > 15)
    assert list(s.kept["fourbar.crank"]) == [c for c in (2.0, 3.0, 4.0, 5.0)
                                            if driver.fourbar.run(**{**base, "crank": c}).summary["mu_min_deg"] > 15]
    assert set(s.cases["fourbar.crank"]) == {2, 3, 4, 5} and len(s.cases) == 4 * 2 * 19


def test_sweep_errors_are_deck_errors_before_any_case_runs(tmp_path):
    base = {"fourbar": {**CRANK5}}
    with pytest.raises(driver.DeckError, match="no key 'cranks'"):
        driver.run_sweep(base, grid={"cranks": [1, 2]}, outdir=tmp_path)
    with pytest.raises(driver.DeckError, match="not both"):
        driver.run_sweep(INPUTS / "fourbar_paper_sweep.dat", grid={"crank": [1, 2]})
    with pytest.raises(driver.DeckError, match="grid="):
        driver.run_sweep(base)
    with pytest.raises(driver.DeckError, match="only with grid"):
        driver.run_sweep(INPUTS / "fourbar_paper_sweep.dat", keep="mu_min_deg > 1")
    with pytest.raises(driver.DeckError, match="keep"):
        driver.run_sweep(base, grid={"crank": [1, 2]}, keep="__import__('os')")
    assert not list(tmp_path.iterdir())


# ----------------------------------------------------------------------------- matplotlib left alone

def test_plotting_leaves_the_users_backend_and_rcparams_alone(tmp_path):
    code = textwrap.dedent(f"""
        import sys, matplotlib
        matplotlib.use("svg")
        matplotlib.rcParams["font.size"] = 17.0
        matplotlib.rcParams["axes.grid"] = False
        before = dict(matplotlib.rcParams)
        import driver.plotting
        import driver
        r = driver.run({str(INPUTS / 'crank5.dat')!r})
        figs = [r.figure(n) for n in r.figure_names]
        driver.write(r, {str(tmp_path)!r}, plot=True)
        assert matplotlib.get_backend() == "svg", matplotlib.get_backend()
        after = dict(matplotlib.rcParams)
        changed = {{k for k in before if before[k] != after[k] and not (before[k] != before[k])}}
        assert not changed, changed
        assert "matplotlib.pyplot" not in sys.modules
        assert figs[0].axes[0].xaxis.get_gridlines()[0].get_visible()   # house style inside the figure
        assert figs[0].get_dpi() == 150
        print("ok")
    """)
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "ok"
    assert (tmp_path / "crank5_linkage.png").stat().st_size > 10_000


def test_no_library_module_switches_backend_or_global_rcparams():
    import ast
    for path in sorted((ROOT / "driver").glob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and node.attr in ("use", "rcParams", "pyplot"):
                base = node.value
                name = base.id if isinstance(base, ast.Name) else getattr(base, "attr", "")
                assert not (name == "matplotlib"), f"{path.name}:{node.lineno}: matplotlib.{node.attr}"
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                mods = [a.name for a in node.names] + [getattr(node, "module", None) or ""]
                assert not any(m and m.startswith("matplotlib.pyplot") for m in mods), f"{path.name}:{node.lineno}"
