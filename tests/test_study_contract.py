"""The study contract (driver._study): every registered study declares what it offers in one
:class:`~driver._study.Study`, the engines reach it only through that object, and adding a study
is one folder plus one registry line (shown with the example study in tests/example_study/).

Truth used here: the contract's own rules (types, required fields, batch keys that are deck
keys); for every shipped deck the budget estimate of its study; for each batch summary, the pass
table against the full summary (asking for one column computes exactly the value the full
summary has); and for the example pendulum an independent integration of its equation of motion
(scipy's solve_ivp on theta'' = -(3g / 2L) sin theta, written apart from its elliptic-integral
"kernel") and the textbook period ratio 2K(1/2)/pi = 1.1803406 at 90 deg amplitude.
"""
from __future__ import annotations

import ast
import dataclasses
import importlib
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

import driver
from driver import _deck as deck_module
from driver import _limits as limits
from driver._deck import DeckError, GroupSpec, Key, read_deck
from driver._limits import Estimate
from driver._runner import CONTROL_GROUPS, compute, study_of
from driver._signatures import render_stub
from driver._study import REGISTRY, REQUIRED_LAYERS, BatchSummary, Study, load_study, study_names
from driver.sweep import _plan as sweep_batch

ROOT = Path(__file__).resolve().parents[1]
INPUTS = ROOT / "inputs"
EXAMPLE = Path(__file__).resolve().parent / "example_study" / "pendulum"

#: every registered study: a new study is in every test below by its registry line alone
STUDIES = tuple(study_names())


def _decks_of(group: str) -> list[Path]:
    """Shipped single-study decks of ``group`` (no &sweep/&optimize/&synthesis)."""
    out = []
    for path in sorted(INPUTS.glob("*.dat")):
        groups = read_deck(path).groups
        if group in groups and not set(groups) & set(CONTROL_GROUPS):
            out.append(path)
    return out


# ----------------------------------------------------------------------------- the registry

def test_the_registry_is_an_explicit_list_and_names_every_study():
    assert study_names() == sorted(REGISTRY) == list(STUDIES) and len(STUDIES) >= 5
    for name in ("_cli", "_deck", "sweep", "optimize", "plotting", "_fortran", "_output", "_study", "fourbar._forces"):
        assert load_study(name) is None          # no module-name probing: what is not listed is no study
    assert set(driver.studies()) == set(STUDIES)


def test_a_registered_package_without_a_study_is_an_error_not_skipped(monkeypatch):
    monkeypatch.setitem(REGISTRY, "table", "driver._table")
    with pytest.raises(TypeError, match="binds no STUDY"):
        load_study("table")


def test_the_deck_reader_asks_the_registry_for_every_group(monkeypatch, tmp_path):
    """Studies and engines alike (group_spec); an unknown group is None (the runner names the
    known ones); a registered package that is broken is an error to see, not an unknown group."""
    from driver import sweep
    from driver._study import ENGINES, group_spec
    assert group_spec("sweep") is sweep.SPEC and set(ENGINES) == set(CONTROL_GROUPS)
    assert group_spec("fourbar") is load_study("fourbar").spec and group_spec("no_such_group") is None
    deck = tmp_path / "d.dat"
    deck.write_text("&broken x = 1 /\n")
    monkeypatch.setitem(REGISTRY, "broken", "driver._no_such_module")
    monkeypatch.delitem(deck_module._KNOWN, "broken", raising=False)
    with pytest.raises(ModuleNotFoundError, match="driver._no_such_module"):
        read_deck(deck)
    deck_module._KNOWN.pop("broken", None)
    deck.write_text("&unheard_of x = 1 /\n")
    with pytest.raises(DeckError, match="unknown group &unheard_of"):
        study_of(read_deck(deck))


# ----------------------------------------------------------------------------- every registered study

@pytest.mark.parametrize("name", STUDIES)
def test_every_registered_study_satisfies_the_contract(name):
    s = load_study(name)
    assert isinstance(s, Study) and s.name == name and s.spec.name == name
    assert s.module.STUDY is s and s.package == REGISTRY[name]
    assert isinstance(s.spec, GroupSpec) and s.spec.keys and all(isinstance(k, Key) for k in s.spec.keys.values())
    assert callable(s.run) and callable(s.estimate)
    assert set(s.summary_settings) <= set(s.spec.keys)
    assert set(s.sweep_best.values()) <= {"max", "min"}
    for words, units in s.labels.values():
        assert isinstance(words, str) and words and isinstance(units, str)
    if s.batch is not None:
        assert set(s.batch.keys) | set(s.batch.ignored) | set(s.batch.independent) <= set(s.spec.keys)
        assert set(s.batch.elements) <= set(s.batch.keys)
        assert s.batch.passes is None or {p for ps in s.batch.passes.values() for p in ps} <= set(s.batch.pass_names)


@pytest.mark.parametrize("name", STUDIES)
def test_estimate_gives_sane_numbers_for_every_shipped_deck_of_the_study(name):
    s = load_study(name)
    decks = _decks_of(name)
    assert decks, f"no example deck of &{name} in inputs/"
    for path in decks:
        study, params = study_of(read_deck(path))
        assert study is s
        est = s.estimate(params)
        assert isinstance(est, Estimate), path
        assert math.isfinite(est.bytes) and math.isfinite(est.seconds), path
        assert 1e3 < est.bytes < 2**31 and 0 < est.seconds < limits.DEFAULT_WORK, (path, est)
        assert est.memory_key is None or est.memory_key in s.spec.keys, (path, est.memory_key)
        assert est.work_key is None or est.work_key in s.spec.keys, (path, est.work_key)
        assert limits.check(s, params) == est


#: the files every study package has (plus _kernel.py with a kernel, _batch.py with a batch path): private
#: modules behind the package's public names, one per layer of the contract (driver._study.LAYERS)
LAYOUT = {"__init__.py", *(f"{layer}.py" for layer in REQUIRED_LAYERS)}


def _check_layout(s: Study) -> None:
    """The study's package has one file per required layer (and _kernel/_batch when it declares a
    kernel/a batch path), each hook where its layer is, and a face without code."""
    folder = Path(s.module.__file__).parent
    files = {p.name for p in folder.glob("*.py")}
    need = LAYOUT | ({"_kernel.py"} if s.kernel is not None else set()) | ({"_batch.py"} if s.batch is not None else set())
    assert need <= files, sorted(need - files)
    assert s.figures == f"{s.package}._figures" and importlib.import_module(s.figures).__file__
    assert s.published is not None and s.published.__module__ == f"{s.package}._published"
    assert s.kernel is None or s.kernel.__name__ == f"{s.package}._kernel"
    assert s.run.__module__.startswith(f"{s.package}._report") and s.estimate.__module__ == f"{s.package}._spec"
    # the package's __init__ holds its public names and STUDY only: imports, __all__, assignments (no
    # code); run is its generated static signature to type checkers (``if TYPE_CHECKING:``); a name
    # imported on first use (PEP 562: a module-level ``__getattr__``, its static import under
    # ``if TYPE_CHECKING:``) keeps a run that does not use it from importing it
    init = ast.parse((folder / "__init__.py").read_text())
    kinds = {type(n) for n in init.body[1:] if not (_typed_run(n, s.package) or _lazy_name(n))}
    assert kinds <= {ast.ImportFrom, ast.Import, ast.Assign, ast.AnnAssign}, kinds
    assert any(_typed_run(n, s.package) for n in init.body), "run is not typed by the study's _keywords.pyi"
    assert (folder / "_keywords.pyi").is_file()


@pytest.mark.parametrize("name", STUDIES)
def test_every_study_has_the_one_layout(name):
    _check_layout(load_study(name))


def _lazy_name(node: ast.stmt) -> bool:
    """A PEP 562 ``def __getattr__(name)`` or an ``if TYPE_CHECKING:`` block of imports only (no else)."""
    if isinstance(node, ast.FunctionDef):
        return node.name == "__getattr__"
    return (isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING"
            and not node.orelse and all(isinstance(b, (ast.Import, ast.ImportFrom)) for b in node.body))


def _typed_run(node: ast.stmt, package: str) -> bool:
    """``if TYPE_CHECKING: from <package>._keywords import run`` / ``else: from <package>._<module> import run``."""
    return (isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING"
            and len(node.body) == len(node.orelse) == 1
            and all(isinstance(b, ast.ImportFrom) and [a.name for a in b.names] == ["run"]
                    for b in (*node.body, *node.orelse))
            and isinstance(node.body[0], ast.ImportFrom)
            and (node.body[0].module == f"{package}._keywords" or (node.body[0].level, node.body[0].module) == (1, "_keywords")))


def study_references(source: str, names: tuple[str, ...]) -> list[str]:
    """Where ``source`` (a module's code) names one of the studies ``names`` the way per-study code
    does: an import of ``driver.<name>`` or a dotted ``driver.<name>`` (in code or in a string), a
    ``&<name>`` group in a string, the name as a string compared against (``==``, ``in`` and their
    collections, a ``match`` case), or a dict keyed by two study names or more (a per-study table).
    A bare word is no reference: a study's name may be an ordinary word of the shared code too
    (a synthesis's "linkage" is no &linkage).  Docstrings are not code."""
    tree = ast.parse(source)
    names_set = set(names)
    found: list[str] = []
    alternatives = "|".join(map(re.escape, names))
    dotted = re.compile(rf"\bdriver\.({alternatives})\b")
    group = re.compile(rf"&({alternatives})\b")
    docstrings = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr) \
                and isinstance(body[0].value, ast.Constant) and isinstance(body[0].value.value, str):
            docstrings.add(id(body[0].value))

    def strings(node: ast.AST) -> list[str]:
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            return [node.value]
        if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            return [s for e in node.elts for s in strings(e)]
        return []

    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [f"import {a.name}" for a in node.names if dotted.search(a.name)]
        elif isinstance(node, ast.ImportFrom) and node.module:
            mods = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            found += [f"from {node.module} import" for m in mods[:1] if any(dotted.search(x) for x in mods)]
        elif isinstance(node, ast.Attribute) and dotted.search(ast.unparse(node)) and \
                isinstance(node.value, ast.Name) and node.value.id == "driver":
            found.append(ast.unparse(node))
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
            found += [f"string {node.value!r}" for rx in (dotted, group) if rx.search(node.value)]
        elif isinstance(node, ast.Compare):
            found += [f"compares with {v!r}" for part in (node.left, *node.comparators) for v in strings(part)
                      if v in names_set]
        elif isinstance(node, ast.MatchValue):
            found += [f"case {v!r}" for v in strings(node.value) if v in names_set]
        elif isinstance(node, ast.Dict):
            keys = [k.value for k in node.keys if isinstance(k, ast.Constant) and k.value in names_set]
            if len(keys) >= 2:
                found.append(f"a table keyed by {sorted(keys)}")
    return found


def test_the_reference_finder_sees_per_study_code():
    names = ("fourbar", "linkage")
    assert study_references('"""A linkage page."""\nlinkage = 1\nSection("linkage")\nx.linkage_deck\n', names) == []
    seen = study_references(
        "import driver.fourbar\nfrom driver.linkage import run\nimport driver\ndriver.fourbar.run()\n"
        "importlib.import_module('driver.linkage')\nmsg = 'see &fourbar'\nif study == 'linkage': pass\n"
        "ok = g in ('fourbar', 'x')\nT = {'fourbar': 1, 'linkage': 2}\n"
        "match g:\n    case 'fourbar':\n        pass\n", names)
    assert len(seen) == 9, seen   # every line after "import driver" once


def test_shared_modules_hold_no_per_study_code():
    """plotting keeps the house style and the shared figures, compare the comparison machinery,
    kernels the loader, the page its generic sections: none of them imports, names or branches on
    a study group (:func:`study_references`)."""
    files = [ROOT / "driver" / f"{m}.py" for m in ("plotting", "_compare", "_fortran", "_published", "_runner",
                                                     "_limits", "_record", "_mechanism")]
    for path in files + sorted((ROOT / "driver" / "_report_page").glob("*.py")):   # the page is a package
        assert not study_references(path.read_text(), STUDIES), (path.stem, study_references(path.read_text(), STUDIES))


def _same(a: pd.Series, b: pd.Series) -> bool:
    if pd.api.types.is_numeric_dtype(a) and pd.api.types.is_numeric_dtype(b):
        return bool(np.array_equal(a.to_numpy(float), b.to_numpy(float), equal_nan=True))
    return a.astype(object).where(a.notna(), None).tolist() == b.astype(object).where(b.notna(), None).tolist()


@pytest.mark.parametrize("name", [n for n in STUDIES if (s := load_study(n)) is not None and s.batch is not None
                                  and s.batch.passes is not None])
def test_batch_pass_table_agrees_with_the_summary_columns(name):
    """Each column a pass table names, asked for alone, has the value the full summary gives it
    (a column whose pass the table forgot would come back zero or missing); the headline
    columns a study plots and ranks are columns of its summary."""
    s = load_study(name)
    assert s.batch is not None and s.batch.passes is not None
    checked = 0
    for path in _decks_of(name):
        _, params = study_of(read_deck(path))
        if s.batch.applies is not None and not s.batch.applies(params):
            continue
        full = s.batch.fn(params, {})
        tabled = [c for c in full.columns if c in s.batch.passes]
        assert tabled, path
        assert not [c for c in s.batch.passes if c not in full.columns and not _optional(s, c)], path
        for c in tabled:
            alone = s.batch.fn(params, {}, wanted=[c])
            assert list(alone.columns) == [c], (path, c)
            assert _same(alone[c], full[c]), (path, c)
        for c in (*s.sweep_plot, *s.sweep_best):
            assert c in full.columns, (path, c)
        checked += 1
    assert checked


def _optional(s: Study, column: str) -> bool:
    """Columns of a pass table a deck may not produce: the four-bar's detail columns and its
    force columns (decks that give masses); the manipulator's C_rob walk minimum."""
    if s.name == "fourbar":
        from driver.fourbar._batch import DETAIL
        return column in DETAIL or s.batch.passes[column] == ("forces",)
    return False


@pytest.mark.parametrize("name", [n for n in STUDIES if (s := load_study(n)) is not None and s.summarise is not None])
def test_summarise_gives_the_run_summary(name):
    s = load_study(name)
    assert s.summarise is not None
    study, params = study_of(read_deck(_decks_of(name)[0]))
    quick, full = s.summarise(params), compute(study, params).summary
    assert list(quick) == list(full)
    for k, v in quick.items():   # floats to 1e-12: the manipulator's Monte Carlo maximum differs in the last bit
        if isinstance(v, float) and isinstance(full[k], float):
            assert v == pytest.approx(full[k], rel=1e-12, abs=0.0, nan_ok=True), k
        else:
            assert v == full[k], k


# ----------------------------------------------------------------------------- the contract's own checks

def _spec(name: str = "toy") -> GroupSpec:
    return GroupSpec(name, {"a": Key("float", default=1.0), "b": Key("float", default=2.0)})


def _run(params, progress=False):
    raise AssertionError("not run")


def _est(params):
    return Estimate(1e6, 0.1)


def test_a_study_without_estimate_cannot_register():
    with pytest.raises(TypeError, match="estimate is required"):
        Study(name="toy", package=__name__, spec=_spec(), run=_run, estimate=None)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="run is required"):
        Study(name="toy", package=__name__, spec=_spec(), run="run", estimate=_est)  # type: ignore[arg-type]


def test_misspelt_names_raise_when_the_study_is_declared():
    fn = lambda base, columns=None, wanted=None: pd.DataFrame()
    with pytest.raises(ValueError, match="'c' is not a key"):
        Study(name="toy", package=__name__, spec=_spec(), run=_run, estimate=_est, batch=BatchSummary(fn, keys=("a", "c")))
    with pytest.raises(ValueError, match="not a key"):
        Study(name="toy", package=__name__, spec=_spec(), run=_run, estimate=_est,
              batch=BatchSummary(fn, keys=("a",), independent=("bb",)))
    with pytest.raises(ValueError, match="pass 'peak' is not one of"):
        BatchSummary(fn, keys=("a",), passes={"x": ("peak",)}, pass_names=("peaks",))
    with pytest.raises(ValueError, match="both a batch key and ignored"):
        BatchSummary(fn, keys=("a",), ignored=("a",))
    with pytest.raises(ValueError, match="declares group &other"):
        Study(name="toy", package=__name__, spec=_spec("other"), run=_run, estimate=_est)
    with pytest.raises(ValueError, match="'max' or 'min'"):
        Study(name="toy", package=__name__, spec=_spec(), run=_run, estimate=_est, sweep_best={"x": "best"})
    with pytest.raises(ValueError, match="not a key"):
        Study(name="toy", package=__name__, spec=_spec(), run=_run, estimate=_est, summary_settings=("band",))
    with pytest.raises(TypeError, match=r"labels\['x'\]"):
        Study(name="toy", package=__name__, spec=_spec(), run=_run, estimate=_est, labels={"x": "words"})
    s = Study(name="toy", package=__name__, spec=_spec(), run=_run, estimate=_est, labels={"a": ("aa", "m")})
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.name = "other"                                   # frozen
    with pytest.raises(TypeError):
        s.labels["b"] = ("bb", "s")                        # read-only mapping


# ----------------------------------------------------------------------------- the example study

@pytest.fixture
def pendulum(monkeypatch):
    """Register the example study: the one line a new study adds to driver._study.REGISTRY."""
    monkeypatch.syspath_prepend(str(EXAMPLE.parents[1]))
    monkeypatch.setitem(REGISTRY, "pendulum", "example_study.pendulum")
    yield load_study("pendulum")
    deck_module._KNOWN.pop("pendulum", None)


def _ode_period_and_swing(length: float, g: float, theta0: float, t: np.ndarray) -> tuple[float, np.ndarray]:
    """Independent truth: integrate I theta'' = -m g (L/2) sin theta, I = m L^2 / 3, from rest."""
    w2 = 1.5 * g / length
    quarter = lambda _t, y: y[0]
    quarter.terminal, quarter.direction = True, -1
    sol = solve_ivp(lambda _t, y: [y[1], -w2 * math.sin(y[0])], (0.0, 100.0), [theta0, 0.0], events=quarter,
                    rtol=1e-12, atol=1e-14, dense_output=True)
    period = 4.0 * sol.t_events[0][0]
    half = solve_ivp(lambda _t, y: [y[1], -w2 * math.sin(y[0])], (0.0, float(t[-1])), [theta0, 0.0], t_eval=t,
                     rtol=1e-12, atol=1e-14)
    return period, half.y[0]


def test_adding_a_study_is_one_folder_and_one_registry_line(pendulum):
    """The example lives in one folder in exactly the house layout (every layer it needs, its
    generated stub fresh); no file of driver/ names it (tests/test_new_study.py runs it as a real
    package of a scratch repository)."""
    files = sorted(p.name for p in EXAMPLE.iterdir() if p.suffix in (".py", ".pyi"))
    assert files == ["__init__.py", "_analysis.py", "_batch.py", "_figures.py", "_kernel.py", "_keywords.pyi",
                     "_published.py", "_report.py", "_spec.py"]
    _check_layout(pendulum)
    assert (EXAMPLE / "_keywords.pyi").read_text() == render_stub(pendulum.spec)
    for src in (ROOT / "driver").rglob("*.py"):
        assert "pendulum" not in src.read_text(), src
    assert isinstance(pendulum, Study) and pendulum.name in study_names()
    assert pendulum.kernel is not None and pendulum.figures is not None
    assert "pendulum" in driver.studies() and list(driver.keys("pendulum").index)[:3] == ["length", "gravity",
                                                                                           "amplitude_deg"]


@pytest.mark.parametrize("amplitude", [5.0, 90.0, 170.0])
def test_example_study_runs_through_the_driver_and_matches_the_equation_of_motion(pendulum, amplitude):
    import example_study.pendulum as pkg
    res = pkg.run(length=0.8, amplitude_deg=amplitude, points=9)    # keyword form: through the runner
    assert res.ok and res.study == "pendulum"
    period, theta = _ode_period_and_swing(0.8, 9.80665, math.radians(amplitude), res.tidy["time_s"].to_numpy())
    assert res.summary["period_s"] == pytest.approx(period, rel=1e-9)
    assert res.summary["small_angle_period_s"] == pytest.approx(2 * math.pi * math.sqrt(0.8 / 1.5 / 9.80665), rel=1e-14)
    assert np.allclose(res.tidy["theta_deg"], np.degrees(theta), atol=1e-6)
    assert res.tidy["theta_deg"].iloc[-1] == pytest.approx(-amplitude, abs=1e-6)   # half a period: the other side
    if amplitude == 90.0:
        assert res.summary["period_ratio"] == pytest.approx(1.1803406, abs=5e-8)   # 2 K(1/2) / pi, textbooks
        cells = pendulum.published(res.params, res)   # K(45 deg) of the published table, to its 10 decimals
        assert [(c["printed"], c["status"]) for c in cells] == [("1.8540746773", "identical")], cells
    else:
        assert pendulum.published(res.params, res) == []   # no row of the table for this amplitude


def test_example_study_deck_sweep_budget_and_figures(pendulum, tmp_path):
    from driver._cli import main
    deck = tmp_path / "swing.dat"
    deck.write_text("&pendulum length = 0.5, amplitude_deg = 60, title = 'example' /\n")
    assert main([str(deck), "-o", str(tmp_path / "out"), "-q", "--plot"]) == 0
    out = (tmp_path / "out" / "swing.out").read_text()
    assert "period" in out and (tmp_path / "out" / "swing_swing.png").is_file()
    bad = tmp_path / "bad.dat"
    bad.write_text("&pendulum length = 0.5, amplitude_deg = 200 /\n")
    assert main([str(bad), "-o", str(tmp_path / "bad"), "-q"]) == 2
    _, params = study_of(read_deck(deck))
    with pytest.raises(DeckError) as exc:                  # the budget applies to the new study too
        limits.check(pendulum, params, lim=limits.Budget(memory=1e3, work=1.0))
    assert exc.value.key == "points"
    grid = {"amplitude_deg": [10.0, 45.0, 90.0, 135.0], "length": [0.5, 2.0]}
    assert sweep_batch.batchable(pendulum, [f"pendulum.{k}" for k in grid], "", "none")
    fast = driver.run_sweep(str(deck), grid, jobs=1).summary
    slow = driver.run_sweep(str(deck), grid, jobs=1, case_outputs="all").summary     # case by case
    assert len(fast) == 8 and (fast["status"] == "ok").all()
    for c in ("period_s", "small_angle_period_s", "period_ratio"):
        assert np.allclose(fast[c].to_numpy(float), slow[c].to_numpy(float), rtol=1e-14, atol=0), c
    ode = [_ode_period_and_swing(L, 9.80665, math.radians(a), np.array([0.0, 0.1]))[0]
           for a, L in zip(fast["pendulum.amplitude_deg"], fast["pendulum.length"])]
    assert np.allclose(fast["period_s"], ode, rtol=1e-9)
