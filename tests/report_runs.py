"""Shipped decks run once per test session with ``--report``, for the figure and page tests.

:class:`ReportRuns` runs a deck in this process through the engine the command line uses
(``driver._dispatch.run_deck``, report page included) the first time a test asks for it, and
keeps its outcome and page: the browser tests, the figure-layout tests and the page-size test
share one run of each deck.  :func:`outcome_figures` lists every figure an outcome's files and
page hold (a run's, a sweep's maps and its best case's, an optimisation's and its optimum's, a
synthesis's and its linkage's), each with the column and key names of its run, so a label that
shows one of them raw can be caught.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from conftest import INPUTS

#: every shipped deck, by stem
SHIPPED = sorted(p.stem for p in INPUTS.glob("*.dat"))


@dataclass
class Run:
    """One deck's run: its outcome, its report page and its output folder."""

    stem: str
    outcome: Any
    page: Path
    outdir: Path


class ReportRuns:
    """Decks run on demand, once each, into ``root`` (``get(stem)``; ``text`` for a deck of the
    test's own, written as ``<stem>.dat`` first)."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.runs: dict[str, Run] = {}

    def get(self, stem: str, text: str | None = None) -> Run:
        if stem not in self.runs:
            from driver._deck import read_deck
            from driver._dispatch import run_deck
            from driver._outcome import ExitCode
            deck_path = INPUTS / f"{stem}.dat"
            if text is not None:
                deck_path = self.root / "decks" / f"{stem}.dat"
                deck_path.parent.mkdir(parents=True, exist_ok=True)
                deck_path.write_text(text)
            outdir = self.root / "out"
            outcome = run_deck(read_deck(deck_path), outdir, [], False, report=True)
            assert outcome.exit_code != ExitCode.BAD_INPUT, [str(m) for m in outcome.messages]
            assert not any("report page could not be written" in str(m) for m in outcome.messages), outcome.messages
            self.runs[stem] = Run(stem, outcome, outdir / f"{stem}.html", outdir)
        return self.runs[stem]


def _names(result: Any) -> set[str]:
    """Column and key names of a run: its summary, its tidy table, its deck keys."""
    names = set(result.summary or ())
    if result.tidy is not None:
        names |= {str(c) for c in result.tidy.columns}
    p = result.params
    if p is not None:
        keys = {str(k) for k in p.keys()}
        names |= keys | {f"{result.study}.{k}" for k in keys}
    return names


def outcome_figures(outcome: Any) -> list[tuple[str, Callable[[], Any], set[str]]]:
    """(name, draw, the run's column and key names) of every figure of ``outcome``."""
    from driver._outcome import OptimizeOutcome, RunOutcome, SweepOutcome, SynthesisOutcome
    out: list[tuple[str, Callable[[], Any], set[str]]] = []

    def of_result(r: Any, tag: str) -> None:
        names = _names(r)
        out.extend((f"{tag}{r.name}_{f.name}", f.draw, names) for f in r.figures)

    if isinstance(outcome, RunOutcome):
        of_result(outcome.result, "")
    elif isinstance(outcome, SweepOutcome):
        from driver._study import load_study
        from driver.sweep._report import summary_figures
        s = outcome.summary
        if s is not None and len(s):
            keys = [c for c in s.columns if c.partition(".")[0] == outcome.study]
            figs = summary_figures(s, outcome.sweep, keys, load_study(outcome.study), outcome.name)
            names = {str(c) for c in s.columns}
            out.extend((f"{outcome.name}_summary_{k + 1}", (lambda f=f: f), names) for k, f in enumerate(figs))
        if outcome.best is not None:
            of_result(outcome.best, "best case: ")
    elif isinstance(outcome, (OptimizeOutcome, SynthesisOutcome)):
        base = set()
        run = outcome.optimum.result if isinstance(outcome, OptimizeOutcome) and outcome.optimum else \
            getattr(outcome, "result", None)
        if run is not None:
            base = _names(run)
        out.extend((f"{outcome.name}_{f.name}", f.draw, base) for f in outcome.figures)
        if run is not None:
            of_result(run, "run: ")
    return out
