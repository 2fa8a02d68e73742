"""The input boundary, round two (issue 23): every reproducer of the campaign is a test.

A number is what Fortran list-directed input means by one and nothing else; an expression
is checked against the columns' kinds before any case runs; API values are checked by
size before they are converted.  Each refusal is exit 2 (or a DeckError) naming the deck,
the line and the key, and nothing is written.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import driver
from driver._cli import main
from driver._deck import DeckError, is_number, read_deck
from driver._expr import ExprError, parse

FOURBAR = """&fourbar
  fixed_link = 12.0, crank = 2.0, coupler = 15.0, rocker = 9.0
  omega = 5.0, step_deg = 60
/
"""
BASE = dict(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0, omega=5.0, step_deg=20)


def _refused(tmp_path, capsys, text: str, line: int, key: str, words: str = "", name: str = "d.dat") -> str:
    deck = tmp_path / name
    deck.write_text(text)
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out), "-q", "-j", "1", "--plot"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f"error: {deck}:{line}: key '{key}': "), err[0]
    assert words in err[0], err[0]
    assert not out.exists() or not any(out.rglob("*"))
    return err[0]


# ----------------------------------------------------------------------------- 1. numbers

@pytest.mark.parametrize("value,words", [
    ("5.0_8", "kind suffix"),            # f90nml reads 5.08
    ("1_5", "kind suffix"),              # 15
    ("'5_0'", "not a number"),           # float('5_0') == 50
    ("4+1", "arithmetic"),               # 4e+1
    ("360-7", "arithmetic"),             # 3.6e-5
    ("'\uff13\uff10'", "not a number"),  # fullwidth 30
    ("'\u0663\u0660'", "not a number"),  # Arabic-Indic 30
    ("0xfff", "not a number"),
    ("1" * 400, "digits"),
    ("1e", "exponent without digits"),
    ("2.5e-", "exponent without digits"),
    ("1d+", "exponent without digits"),
    ("1.0q3", "not a number"),
    ("(1, 2)", "complex"),
    ("abc", "not a number"),
    ("inf", "not a number"),
    ("nan", "not a number"),
])
def test_misread_numbers_are_deck_errors(tmp_path, capsys, value, words):
    text = FOURBAR.replace("crank = 2.0", f"crank = {value}")
    _refused(tmp_path, capsys, text, 2, "crank", words)


def test_no_namelist_debug_output_on_stdout(tmp_path, capsys):
    for value in ("3e", "1d+", "2.5e-"):
        deck = tmp_path / "d.dat"
        deck.write_text(FOURBAR.replace("step_deg = 60", f"step_deg = {value}"))
        assert main([str(deck), "-o", str(tmp_path / "o"), "-q"]) == 2
        cap = capsys.readouterr()
        assert cap.out == ""
        assert f"{deck}:3: key 'step_deg'" in cap.err


def test_repeat_count_of_a_repeat_count_is_refused(tmp_path, capsys):
    text = FOURBAR + "&sweep\n  key1 = 'fourbar.crank', values1 = 2*1*4.0\n/\n"
    _refused(tmp_path, capsys, text, 6, "values1", "repeat count applied to a repeat count")
    text = FOURBAR + "&sweep\n  key1 = 'fourbar.crank', values1 = 0*4.0\n/\n"
    _refused(tmp_path, capsys, text, 6, "values1", "repeat count 0")


def test_fortran_spellings_still_read():
    """What list-directed input does read: the same values as Fortran gives them."""
    deck = read_deck("x.dat", text="&fourbar\n fixed_link = 12, crank = 5., coupler = 1.5d1, rocker = .9E+1\n"
                                   " omega = +5.0e0, step_deg = 20 /\n&sweep key1 = 'fourbar.crank', "
                                   "values1 = 2*3.0, 4 /\n")
    g = deck.groups["fourbar"].values
    assert (g["fixed_link"], g["crank"], g["coupler"], g["rocker"], g["omega"]) == (12, 5.0, 15.0, 9.0, 5.0)
    assert deck.groups["sweep"].values["values1"] == [3.0, 3.0, 4]
    for good in ("5", "-5.", ".5", "5.0e-3", "5d0", "+1E+2", " 7 "):
        assert is_number(good), good
    for bad in ("5_0", "5.0_8", "4+1", "0x10", "inf", "nan", "\uff15", "1e", "", ".", "e5", "1" * 41):
        assert not is_number(bad), bad


@pytest.mark.parametrize("value,words", [
    ("5_0", "not a number"), ("\uff13\uff10", "not a number"), ("\u0663\u0660", "not a number"),
    (10**400, "not a finite number"), (-(10**400), "not a finite number"), (float("inf"), "not a finite"),
])
def test_api_values_are_numbers_as_decks_are(value, words):
    with pytest.raises(DeckError, match=words) as exc:
        driver.run({"fourbar": {**BASE, "crank": value}})
    assert exc.value.key == "crank"
    assert len(str(exc.value)) < 400   # a 400-digit integer is not echoed


def test_api_quoted_number_and_0d_array_read_as_the_number():
    a = driver.run({"fourbar": {**BASE, "crank": "5.0"}})
    b = driver.run({"fourbar": {**BASE, "crank": np.array(5.0)}})
    c = driver.run({"fourbar": {**BASE, "crank": np.float32(5.0)}})
    ref = driver.run({"fourbar": BASE})
    assert a.summary == b.summary == c.summary == ref.summary


def test_api_huge_and_nested_inputs_refused_by_size_first():
    import tracemalloc
    nested: list = [1.0]
    for _ in range(500):
        nested = [nested]
    with pytest.raises(DeckError, match="list inside a list"):
        driver.run({"fourbar": {**BASE, "crank": nested}})
    tracemalloc.start()
    try:
        with pytest.raises(DeckError, match="values"):
            driver.run({"fourbar": {**BASE, "coupler_point": range(10**9)}})
        with pytest.raises(DeckError, match="shape"):
            driver.run_sweep({"fourbar": BASE}, grid={"crank": np.broadcast_to(np.float64(1.0), (10**8,))})
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 50 * 2**20, peak   # the requests would need GBs if materialised


def test_api_formats_checked_before_any_case_runs(tmp_path):
    with pytest.raises(ValueError, match="unknown table format 'exe'"):
        driver.run_sweep({"fourbar": BASE}, grid={"crank": [2, 3]}, formats=["exe"], outdir=tmp_path / "o")
    assert not (tmp_path / "o").exists()


def test_huge_integer_in_a_sweep_value_is_a_short_deck_error():
    with pytest.raises(DeckError, match="not a finite number") as exc:
        driver.run_sweep({"fourbar": BASE}, grid={"crank": [10**400, 3]}, jobs=1)
    assert len(str(exc.value)) < 500


# ----------------------------------------------------------------------------- 4. expressions

SWEEP = FOURBAR + "&sweep\n  key1 = 'fourbar.crank', values1 = 2, 3\n  {line}\n/\n"


@pytest.mark.parametrize("line,key,words", [
    ("keep = 'min(mu_min_deg) > 1'", "keep", "two or more arguments"),
    ("keep = 'grashof_class * 2 > 1'", "keep", "arithmetic on text"),
    ("keep = \"'x'*1000000000 > 1\"", "keep", "arithmetic on text"),
    ("keep = 'grashof_class > 1'", "keep", "is text"),
    ("keep = 'mu_min_deg > 0 # and mu_min_deg < 0'", "keep", "'#'"),
    ("keep = '\uff4du_min_deg > 1'", "keep", "U+FF4D"),
    ("keep = 'mu_min_deg > 1_0'", "keep", "not a number"),
    ("keep = 'mu_min_deg > 0x10'", "keep", "not a number"),
    ("keep = 'mu_min_deg > " + "9" * 400 + "'", "keep", "digits"),
    ("keep = 'mu_min_deg > 9**9**9**9'", "keep", "not a finite number"),
    ("keep = 'grashof_class'", "keep", "gives text"),
    ("plot_y = 'min(mu_min_deg)'", "plot_y", "two or more arguments"),
    ("plot_y = 'grashof_class * 2'", "plot_y", "arithmetic on text"),
    ("plot_y = '1e308'", "plot_y", "reads no column"),
    ("plot_y = 'mu_min_deg + 1e400'", "plot_y", "not a finite"),
])
def test_sweep_expressions_type_checked_before_any_case(tmp_path, capsys, line, key, words):
    _refused(tmp_path, capsys, SWEEP.format(line=line), 7, key, words)


def test_good_expressions_still_run(tmp_path, capsys):
    deck = tmp_path / "s.dat"
    deck.write_text(SWEEP.format(line="keep = 'grashof_class == \"crank-rocker\" and mu_min_deg > 1'\n"
                                      "  plot_y = 'mu_max_deg - mu_min_deg'"))
    assert main([str(deck), "-o", str(tmp_path / "o"), "-q", "-j", "1"]) == 0


OPT = """&fourbar
  fixed_link = 10.0, crank = 3.0, coupler = 10.0, rocker = 8.0, omega = 5.0, step_deg = 10
/
&optimize
  var1 = 'fourbar.crank', lower1 = 2.0, upper1 = 4.0
  {line}
  method = 'slsqp', starts = 1, seed = 1, maxiter = 3
/
"""


@pytest.mark.parametrize("line,key,words", [
    ("maximize = 'mu_min_deg # + 1000'", "maximize", "'#'"),
    ("maximize = '9**9**9**9'", "maximize", "not a finite number"),
    ("minimize = 'log(0.0)/mu_min_deg'", "minimize", "not a finite number"),
    ("maximize = 'mu_min_deg'\n  constraint1 = 'grashof_class > 1'", "constraint1", "is text"),
    ("maximize = 'grashof_class'", "maximize", "cannot be evaluated"),
])
def test_optimize_expressions_are_deck_errors(tmp_path, capsys, line, key, words):
    text = OPT.format(line=line)
    n = text.splitlines().index(next(l for l in text.splitlines() if l.strip().startswith(key))) + 1
    _refused(tmp_path, capsys, text, n, key, words)


def test_no_inf_in_optimisation_evaluations(tmp_path, capsys):
    import pandas as pd
    deck = tmp_path / "o.dat"   # log(0) on every design: each evaluation undefined, none inf in a table
    deck.write_text(OPT.format(line="minimize = 'log(mu_min_deg - mu_min_deg)'"))
    main([str(deck), "-o", str(tmp_path / "out"), "-q", "-j", "1"])
    for f in (tmp_path / "out").glob("*_evals.*"):
        frame = pd.read_parquet(f) if f.suffix == ".parquet" else pd.read_csv(f)
        num = frame.select_dtypes("number").to_numpy(dtype=float)
        assert not np.isinf(num).any(), f.name
    for f in (tmp_path / "out").glob("*.csv"):
        assert "inf" not in f.read_text().lower(), f.name


def test_synthesis_function_comment_and_reduction_refused(tmp_path, capsys):
    base = ("&synthesis\n  task = 'function', function = 'log10(x)', x_start = 1.0, x_stop = 2.0\n"
            "  crank_start_deg = 45.0, crank_range_deg = 60.0\n  rocker_start_deg = 135.0, rocker_range_deg = 90.0\n"
            "  points = 3, fixed_link = 1.0, step_deg = 5, branch = 'open'\n/\n")
    _refused(tmp_path, capsys, base.replace("'log10(x)'", "'x # + 1'"), 2, "function", "'#'")
    _refused(tmp_path, capsys, base.replace("'log10(x)'", "'min(x)'"), 2, "function", "two or more")


def test_expression_kinds_unit():
    e = parse("a > 1 and b == 'x'")
    assert e.check_kinds({"a": "number", "b": "text"}) == "bool"
    with pytest.raises(ExprError) as exc:
        e.check_kinds({"a": "text", "b": "text"})
    assert exc.value.token == "a"
    assert parse("a * 2").check_kinds({"a": "bool"}) == "number"
    with pytest.raises(ExprError, match="gives text"):
        parse("b").check_kinds({"b": "text"})


# ----------------------------------------------------------------------------- 3. symbolic links

SWEEP_DECK = FOURBAR + "&sweep\n  key1 = 'fourbar.crank', values1 = 2, 3\n/\n"


@pytest.mark.parametrize("link", ["sw.sweep", "sw", "sw.sweep/cases"])
def test_a_link_in_place_of_a_sweep_folder_is_refused(tmp_path, capsys, link):
    victim = tmp_path / "victim"
    victim.mkdir()
    (victim / "part-r1-000001.parquet").write_text("not the tool's")
    (victim / "case_0001.out").write_text("not the tool's")
    before = sorted(p.name for p in victim.iterdir())
    deck = tmp_path / "sw.dat"
    deck.write_text(SWEEP_DECK)
    out = tmp_path / "out"
    (out / link).parent.mkdir(parents=True, exist_ok=True)
    (out / link).symlink_to(victim, target_is_directory=True)
    rc = main([str(deck), "-o", str(out), "-q", "-j", "1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 1 and len(err) == 1 and "symbolic link" in err[0] and link in err[0], err
    assert sorted(p.name for p in victim.iterdir()) == before
    assert (victim / "case_0001.out").read_text() == "not the tool's"


def test_a_link_in_place_of_an_output_file_is_replaced_not_followed(tmp_path, capsys):
    target = tmp_path / "target.txt"
    target.write_text("keep me")
    deck = tmp_path / "sw.dat"
    deck.write_text(SWEEP_DECK)
    out = tmp_path / "out"
    (out / "sw").mkdir(parents=True)
    (out / "sw.out").symlink_to(target)
    (out / "sw" / "case_0001.out").symlink_to(target)
    assert main([str(deck), "-o", str(out), "-q", "-j", "1"]) == 0
    assert target.read_text() == "keep me"
    assert not (out / "sw.out").is_symlink() and not (out / "sw" / "case_0001.out").is_symlink()
    # a resume reads no file through a link: the case is redone
    (out / "sw" / "case_0002.json").unlink()
    (out / "sw" / "case_0002.json").symlink_to(target)
    capsys.readouterr()
    assert main([str(deck), "-o", str(out), "-j", "1", "--resume"]) == 0
    assert "1 cases redone" in capsys.readouterr().err
    assert target.read_text() == "keep me" and not (out / "sw" / "case_0002.json").is_symlink()


def test_a_symlinked_outdir_given_by_the_user_works(tmp_path, capsys):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "link").symlink_to(real, target_is_directory=True)
    deck = tmp_path / "sw.dat"
    deck.write_text(SWEEP_DECK)
    assert main([str(deck), "-o", str(tmp_path / "link"), "-q", "-j", "1"]) == 0
    assert (real / "sw.out").is_file() and (real / "sw" / "case_0001.out").is_file()


# ----------------------------------------------------------------------------- 5. the rest

def test_concurrent_run_of_one_sweep_is_refused_with_one_line(tmp_path, capsys):
    from driver.sweep import _resume as store
    deck = tmp_path / "sw.dat"
    deck.write_text(SWEEP_DECK)
    out = tmp_path / "out"
    with store.sweep_lock(out, "sw"):   # another run holds the sweep
        assert main([str(deck), "-o", str(out), "-q", "-j", "1"]) == 1
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "another run is writing this sweep" in err[0]
    assert main([str(deck), "-o", str(out), "-q", "-j", "1"]) == 0


def test_concurrent_processes_one_waits_out(tmp_path):
    import subprocess
    import sys
    deck = tmp_path / "sw.dat"
    deck.write_text(SWEEP_DECK.replace("values1 = 2, 3", "start1 = 2, stop1 = 5, count1 = 24")
                    .replace("step_deg = 60", "step_deg = 1"))
    cmd = [sys.executable, "-m", "driver", str(deck), "-o", str(tmp_path / "out"), "-q", "-j", "1"]
    procs = [subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True) for _ in range(2)]
    results = [(p.wait(timeout=600), p.stderr.read()) for p in procs]
    for rc, err in results:
        assert rc == 0 or (rc == 1 and "another run is writing this sweep" in err and "cannot write" not in err), err
    assert any(rc == 0 for rc, _ in results)


OPTIMIZE_DECK = FOURBAR + """&optimize
  var1 = 'fourbar.coupler', lower1 = 10, upper1 = 20
  maximize = 'mu_min_deg', method = 'grid', grid_count = 3
/
"""


def _named(tmp_path, text: str, stem_bytes: int) -> Path:
    deck = tmp_path / ("a" * stem_bytes + ".dat")
    deck.write_text(text)
    return deck


@pytest.mark.parametrize("text, options, longest", [
    (FOURBAR, ["--format", "parquet"], ".parquet"),         # a single case's tidy table
    (FOURBAR, ["--plot"], "_linkage.png"),                  # a figure's name, known only once computed
    (SWEEP_DECK, [], "_summary.parquet"),                   # a sweep's longest
    (OPTIMIZE_DECK, [], "_evals.parquet"),                  # an optimisation's longest (also .journal.jsonl)
])
def test_long_deck_names_at_the_limit(tmp_path, capsys, text, options, longest):
    """Only a deck whose outputs would have names over 255 bytes (NAME_MAX) is refused: its
    longest output name at exactly 255 bytes runs (the temporaries' names stay short); one byte
    more is exit 2 naming the deck and the limit, and nothing is written."""
    n = 255 - len(longest)
    (tmp_path / "fits").mkdir()
    deck = _named(tmp_path / "fits", text, n)
    out = tmp_path / "o"
    jobs = ["-j", "1"] if text != FOURBAR else []
    assert main([str(deck), "-o", str(out), "-q", *jobs, *options]) == 0
    assert (out / (deck.stem + longest)).is_file() and len((deck.stem + longest).encode()) == 255
    assert not [p for p in out.rglob("*") if p.name.endswith(".tmp")]
    (tmp_path / "over").mkdir()
    deck = _named(tmp_path / "over", text, n + 1)
    out = tmp_path / "o2"
    capsys.readouterr()
    assert main([str(deck), "-o", str(out), "-q", *jobs, *options]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {deck}: ") and f"<name>{longest} would have 256" in err and "255 bytes" in err, err
    assert ".tmp" not in err and err.count("\n") == 1
    assert not out.exists() or not any(out.rglob("*")), sorted(out.rglob("*"))


def test_a_long_name_below_the_old_fixed_allowance_runs(tmp_path):
    """Stems of 232-251 bytes were refused whatever the outputs (a fixed 24-byte allowance): a single
    case's .out of a 251-byte stem (the longest a .dat file can have) fits, exactly 255 bytes."""
    deck = _named(tmp_path, FOURBAR, 251)
    assert main([str(deck), "-o", str(tmp_path / "o"), "-q"]) == 0
    assert (tmp_path / "o" / (deck.stem + ".out")).is_file()


@pytest.mark.parametrize("char", ["\x1b", "\x00", "\x07", "\u2028"])
def test_control_characters_in_titles_are_refused(tmp_path, capsys, char):
    text = FOURBAR.replace("step_deg = 60", f"step_deg = 60, title = 'a{char}[31mb'")
    deck = tmp_path / "d.dat"
    deck.write_bytes(text.encode())
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert f"{deck}:3: key 'title'" in err and "control character" in err
    with pytest.raises(DeckError, match="control character"):
        driver.run({"fourbar": {**BASE, "title": f"x{char}y"}})


@pytest.mark.parametrize("title", ["$\\frac$", "$" + "{" * 300 + "x" + "}" * 300 + "$", "a$b$c", "$x^{$"])
def test_dollar_text_is_never_mathtext(tmp_path, capsys, title):
    deck = tmp_path / "t.dat"
    deck.write_text(FOURBAR.replace("step_deg = 60", f"step_deg = 60, title = '{title}'"))
    assert main([str(deck), "-o", str(tmp_path / "o"), "--plot", "-q"]) == 0
    assert "Traceback" not in capsys.readouterr().err
    from driver.plotting import plain_text
    assert plain_text(title).count("\\$") == title.count("$")


def test_dollar_in_a_sweep_file_name_and_design_names(tmp_path, capsys):
    from conftest import INPUTS
    deck = tmp_path / "s$x^{$.dat"
    deck.write_text(SWEEP_DECK)
    assert main([str(deck), "-o", str(tmp_path / "o"), "--plot", "-q", "-j", "1"]) == 0
    assert (tmp_path / "o" / "s$x^{$_summary.png").is_file()
    m = (INPUTS / "manipulator_case1_report.dat").read_text().replace("'Dexterity'", "'$\\frac{$'")
    (tmp_path / "m.dat").write_text(m)
    assert main([str(tmp_path / "m.dat"), "-o", str(tmp_path / "o"), "--plot", "-q"]) == 0
    err = capsys.readouterr().err
    assert "Traceback" not in err and "Warning" not in err


def test_no_matplotlib_warnings_reach_stderr(tmp_path, capfd):
    deck = tmp_path / "t.dat"   # glyphs missing from the font: matplotlib warns while drawing
    deck.write_text(FOURBAR.replace("step_deg = 60", "step_deg = 60, title = '\U0001F600 \u4e2d\u6587 \u0dc1'"))
    assert main([str(deck), "-o", str(tmp_path / "o"), "--plot", "-q"]) == 0
    err = capfd.readouterr().err
    assert "Warning" not in err and "site-packages" not in err, err


def test_compare_with_only_control_decks_says_so(capsys):
    from conftest import INPUTS
    assert main(["--compare", str(INPUTS / "fourbar_paper_sweep.dat"), str(INPUTS / "synthesis_path.dat")]) == 0
    out = capsys.readouterr().out
    total = out.split("Total", 1)[1]
    assert "no published cells" in total


@pytest.mark.parametrize("change,key", [
    (("crank_range_deg = 60.0", "crank_range_deg = 1e-300"), "crank_range_deg"),
    (("'log10(x)'", "'ceil(x)'"), "function"),
    (("rocker_range_deg = 90.0", "rocker_range_deg = 1e-300"), "rocker_range_deg"),
])
def test_degenerate_syntheses_are_deck_errors(tmp_path, capsys, change, key):
    from conftest import INPUTS
    text = (INPUTS / "synthesis_function_log.dat").read_text().replace(*change)
    line = next(i for i, l in enumerate(text.splitlines(), 1) if change[1] in l)
    _refused(tmp_path, capsys, text, line, key)


def test_unknown_keys_refused_before_the_namelist_reader(monkeypatch):
    """A group of 12 000 unknown keys: refused in the pre-scan, linear in the deck's size (the
    namelist library's work grows with the square of a group's keys: it is never reached)."""
    import driver._deck as deck_module

    def never(text):
        raise AssertionError("f90nml reached")
    monkeypatch.setattr(deck_module, "_f90nml_reads", never)
    keys = "".join(f"  k{i} = 1\n" for i in range(12_000))
    with pytest.raises(DeckError, match="unknown key in &fourbar") as exc:
        read_deck("big.dat", text="&fourbar\n  fixed_link = 12, crank = 5, coupler = 15, rocker = 9\n" + keys + "/\n")
    assert (exc.value.line, exc.value.key) == (3, "k0")
    with pytest.raises(DeckError, match="more than 200 keys") as exc:
        read_deck("big.dat", text="&nosuchgroup\n" + keys + "/\n")
    assert exc.value.line == 202


def test_a_text_column_may_still_be_plotted(tmp_path, capsys):
    """The kind check refuses expressions that misuse text, not a plotted text column itself."""
    deck = tmp_path / "sm.dat"
    deck.write_text(FOURBAR + "&sweep\n  key1 = 'fourbar.method', values1 = 'listing', 'exact'\n"
                              "  plot_x = 'fourbar.method', plot_y = 'mu_min_deg', 'grashof_class'\n/\n")
    assert main([str(deck), "-o", str(tmp_path / "o"), "--plot", "-q", "-j", "1"]) in (0, 1)
    assert (tmp_path / "o" / "sm_summary.png").is_file()
    assert "error" not in capsys.readouterr().err
