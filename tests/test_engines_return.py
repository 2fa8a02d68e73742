"""Engines return, only the command line prints (issue 25).

- No module of the driver other than the command line (driver/_cli.py, driver/__main__.py) prints
  or writes to sys.stdout/sys.stderr: an ast walk, with a self-check that it finds each form.
- The comparison (driver._compare.compare_decks) returns a CompareOutcome; its fields are checked
  against the published cells (crank2..5: 190 cells each, all identical, as printed in
  published/; crank5_exact: 50 cells depart, 48 of them the listing's quadrant defect).
- A sweep's Ctrl-C notice reaches the callback the caller supplies, at once (while a running task
  has not finished), and the library is silent without one.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

from conftest import INPUTS, ROOT
from driver import _compare as compare
from driver import _published as published
from driver._cli import main
from driver._compare import CompareOutcome
from driver._outcome import ExitCode

DRIVER = ROOT / "driver"
#: the command line prints (that is its job); nothing else may
PRINTERS = {"_cli.py": "the command line: the one place that prints outcomes",
            "__main__.py": "python -m driver: hands over to the command line"}
#: module -> reason, for a module that must print anyway (none today)
ALLOWED: dict[str, str] = {}

STREAMS = {"stdout", "stderr", "__stdout__", "__stderr__"}
PRINTING = {("traceback", "print_exc"), ("traceback", "print_exception"), ("traceback", "print_stack")}


def printing_sites(source: str) -> list[tuple[int, str]]:
    """(line, what) for every print call, use of sys.stdout/sys.stderr (attribute or imported
    name) and traceback printer in ``source``."""
    sites = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "print":
            sites.append((node.lineno, "print()"))
        elif isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
            if node.value.id == "sys" and node.attr in STREAMS:
                sites.append((node.lineno, f"sys.{node.attr}"))
            elif (node.value.id, node.attr) in PRINTING:
                sites.append((node.lineno, f"{node.value.id}.{node.attr}"))
        elif isinstance(node, ast.ImportFrom) and node.module in ("sys", "traceback"):
            for alias in node.names:
                if alias.name in STREAMS or (node.module, alias.name) in PRINTING:
                    sites.append((node.lineno, f"from {node.module} import {alias.name}"))
    return sorted(sites)


def test_the_detector_finds_every_form_of_printing():
    source = ("import sys, traceback\nfrom sys import stderr\nprint('x')\nsys.stdout.write('x')\n"
              "print('x', file=sys.stderr)\nf = sys.__stderr__\ntraceback.print_exc()\n"
              "def g(out=sys.stdout):\n    pass\nlog = lambda s: None\nlog('fine')\n")
    assert printing_sites(source) == [(2, "from sys import stderr"), (3, "print()"), (4, "sys.stdout"),
                                      (5, "print()"), (5, "sys.stderr"), (6, "sys.__stderr__"),
                                      (7, "traceback.print_exc"), (8, "sys.stdout")]


def test_only_the_command_line_prints():
    found = []
    for path in sorted(DRIVER.rglob("*.py")):
        rel = path.relative_to(DRIVER).as_posix()
        if rel in PRINTERS or rel in ALLOWED:
            continue
        found += [f"driver/{rel}:{line}: {what}" for line, what in printing_sites(path.read_text())]
    assert found == [], "engines return outcomes; only driver/_cli.py prints:\n" + "\n".join(found)
    # the allow-list names real modules, each with a reason
    for rel, reason in {**PRINTERS, **ALLOWED}.items():
        assert (DRIVER / rel).is_file() and reason


# ----------------------------------------------------------------------------- the comparison's outcome

def test_compare_decks_returns_the_comparisons_totals_and_errors(write_deck, capsys):
    bad = write_deck("&fourbar crank = 1 /\n")
    decks = [INPUTS / f"crank{c}.dat" for c in (2, 3, 4, 5)] + [bad, INPUTS / "crank5_exact.dat"]
    parts: list[CompareOutcome] = []
    outcome = compare.compare_decks(decks, on_deck=parts.append)
    assert capsys.readouterr() == ("", "")   # the engine prints nothing
    assert isinstance(outcome, CompareOutcome)
    # one comparison per good deck, in order; the listing decks reproduce all 190 published cells
    assert [c.deck for c in outcome.comparisons] == [d for d in decks if d != bad]
    for c, name in zip(outcome.comparisons, ("Lampiran 2 (crank 2)", "Lampiran 2 (crank 3)",
                                             "Lampiran 3 (crank 4)", "Lampiran 3 (crank 5)")):
        assert c.group == "fourbar" and c.variant == "method = 'listing'" and c.ok
        assert len(c.frame) == 190 and (c.frame["status"] == "identical").all()
        assert set(c.frame["table"]) == {name}
        assert len(c.frame) == len(published.read_listing(published.PUBLISHED_DIR / f"crank{name[-2]}.out").cells)
    exact = outcome.comparisons[-1]
    departs = exact.frame[exact.frame["status"] == "departs"]
    assert exact.ok and len(departs) == 50 and departs["reason"].str.contains("quadrant").sum() == 48
    # the totals per study and method, as the command line prints them under "Total"
    assert outcome.totals == [
        "  &fourbar method = 'listing' (4 decks): 760/760 cells identical",
        "  &fourbar method = 'exact' (1 deck): 140/190 reproducible cells agree; 50 depart from the published "
        "values (the deck asks for the correct answer)"]
    # the bad deck: one error naming its file, line and key; exit status 2
    assert [m.level for m in outcome.messages] == ["error"]
    assert str(bad) in outcome.messages[0].text and "fixed_link" in outcome.messages[0].text
    assert outcome.bad_input and not outcome.failed and outcome.exit_code == ExitCode.BAD_INPUT
    # each deck reached the callback on its own, in order, without the totals
    assert [len(p.comparisons) for p in parts] == [1, 1, 1, 1, 0, 1] and not any(p.totals for p in parts)
    assert [p.exit_code for p in parts] == [0, 0, 0, 0, 2, 0]


def test_compare_outcome_exit_codes(monkeypatch, tmp_path):
    one = compare.compare_decks([INPUTS / "crank5.dat"])
    assert one.exit_code == ExitCode.OK and not one.messages and one.totals == []   # totals: two decks or more
    real = compare.run_comparison

    def failing(deck):
        if Path(deck).name == "crank3.dat":
            raise RuntimeError("boom")
        return real(deck)

    monkeypatch.setattr(compare, "run_comparison", failing)
    out = compare.compare_decks([INPUTS / "crank3.dat", INPUTS / "crank2.dat"])
    assert out.failed and out.exit_code == ExitCode.FAILED and len(out.comparisons) == 1
    assert [str(m) for m in out.messages] == [f"error: {INPUTS / 'crank3.dat'}: run failed: RuntimeError: boom"]
    assert out.totals == []   # one deck compared: no totals
    monkeypatch.setattr(published, "PUBLISHED_DIR", tmp_path / "nowhere")
    heard: list[CompareOutcome] = []
    gone = compare.compare_decks([INPUTS / "crank5.dat"], on_deck=heard.append)
    assert gone.exit_code == ExitCode.FAILED and heard == [gone] and gone.comparisons == []
    assert "published tables are not installed" in gone.messages[0].text


def test_cli_prints_the_outcome_stdout_and_stderr_apart(write_deck, capsys):
    bad = write_deck("&fourbar crank = 1 /\n")
    assert main(["--compare", str(INPUTS / "crank2.dat"), str(bad), str(INPUTS / "crank3.dat")]) == 2
    out, err = capsys.readouterr()
    errata = " of the reproduced printed cells are wrong (errata): a deck asking for the correct answer lists them " \
             "with the reason"
    lines = out.splitlines()
    assert lines[:2] + lines[3:5] + lines[6:] == [
        f"{INPUTS / 'crank2.dat'}: &fourbar", "  Lampiran 2 (crank 2): 190/190 cells identical",
        f"{INPUTS / 'crank3.dat'}: &fourbar", "  Lampiran 2 (crank 3): 190/190 cells identical",
        "Total", "  &fourbar method = 'listing' (2 decks): 380/380 cells identical"]
    for line in (lines[2], lines[5]):   # at least the 48 cells of the quadrant defect (rows 200-340, 6 columns)
        n, rest = line.strip().split(" ", 1)
        assert int(n) >= 48 and " " + rest == errata
    assert err.count("\n") == 1 and err.startswith(f"error: {bad}:") and "fixed_link" in err


# ----------------------------------------------------------------------------- Ctrl-C notices

SWEEP = """&fourbar
  fixed_link = 12.0, crank = 2.0, coupler = 15.0, rocker = 9.0
  omega = 5.0, step_deg = 20, method = 'exact'
/
&sweep key1 = 'fourbar.crank', values1 = 2, 3, 4, 5, 6
       key2 = 'fourbar.rocker', values2 = 8, 9, 10 /
"""


@pytest.fixture
def interrupted_sweep(tmp_path, monkeypatch):
    """A 15-case per-case sweep whose 6th case raises KeyboardInterrupt in its worker (the workers
    are forked after the patch); the driver gets it from the case's future."""
    from driver.sweep import _chunks as chunks
    real = chunks.compute_case

    def compute(task, case, module):
        if case.index == 6:
            raise KeyboardInterrupt
        return real(task, case, module)

    monkeypatch.setattr(chunks, "compute_case", compute)
    path = tmp_path / "sw.dat"
    path.write_text(SWEEP)
    return path


NOTICE = "interrupt: cancelling queued cases, finishing the running ones"


def test_cli_prints_the_interrupt_notice_then_exits_130(interrupted_sweep, tmp_path, capsys):
    assert main([str(interrupted_sweep), "-o", str(tmp_path / "o"), "-q", "-j", "2"]) == 130
    assert capsys.readouterr().err.splitlines() == [
        NOTICE, "interrupted: finished outputs are complete; no partial file was left"]


def test_the_engine_is_silent_without_a_callback_and_tells_one(interrupted_sweep, tmp_path, capsys):
    from driver._deck import read_deck
    from driver._dispatch import run_deck
    deck = read_deck(interrupted_sweep)
    with pytest.raises(KeyboardInterrupt):
        run_deck(deck, tmp_path / "a", [], False, jobs=2)
    assert capsys.readouterr() == ("", "")
    heard: list[str] = []
    with pytest.raises(KeyboardInterrupt):
        run_deck(deck, tmp_path / "b", [], False, jobs=2, notify=heard.append)
    assert heard == [NOTICE] and capsys.readouterr() == ("", "")
