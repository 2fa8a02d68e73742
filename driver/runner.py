"""The runner: deck -> study -> :class:`~driver.study.Result` -> output files, for one case.

Every way of running a study goes through here: the command line (:mod:`driver.cli`),
sweeps (:mod:`driver.sweep`) and the Python API.  The runner never prints and never
exits; it raises :class:`~driver.deck.DeckError` for bad input and returns what it did.
"""
from __future__ import annotations

import pkgutil
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType

import driver
from driver.atomic import write_text
from driver.deck import Deck, DeckError, Params
from driver.deck import validate
from driver.export import write_tidy
from driver.study import Result, load_study

__all__ = ["CONTROL_GROUPS", "Outcome", "available_studies", "study_of", "run_study", "write_outputs"]

#: groups handled by the driver itself rather than by a study module
CONTROL_GROUPS = ("sweep", "optimize", "synthesis")


def available_studies() -> dict[str, ModuleType]:
    """Every study module in the package, by group name."""
    found = {}
    for info in pkgutil.iter_modules(driver.__path__):
        module = load_study(info.name)
        if module is not None:
            found[info.name] = module
    return found


def study_of(deck: Deck) -> tuple[ModuleType, Params]:
    """The single study group of a deck, validated; DeckError otherwise."""
    studies = []
    for name, raw in deck.groups.items():
        if name in CONTROL_GROUPS:
            continue
        module = load_study(name)
        if module is None:
            known = ", ".join(f"&{g}" for g in sorted(available_studies()) + list(CONTROL_GROUPS))
            raise DeckError(deck.path, raw.line, None, f"unknown group &{name} (known groups: {known})")
        studies.append((module, raw))
    if not studies:
        raise DeckError(deck.path, None, None, "deck has no study group")
    if len(studies) > 1:
        names = ", ".join(f"&{raw.name} (line {raw.line})" for _, raw in studies)
        raise DeckError(deck.path, studies[1][1].line, None,
                        f"a deck describes one study; found {names}")
    module, raw = studies[0]
    return module, validate(raw, module.SPEC, deck.path)


def write_outputs(result: Result, stem: Path, formats: list[str], plot: bool) -> list[Path]:
    """Write the .out file, extra files, tidy tables and figures for one case (all atomic)."""
    written = [write_text(stem.with_name(stem.name + ".out"), result.text)]
    for suffix, text in result.extra.items():
        written.append(write_text(stem.with_name(stem.name + suffix), text))
    for fmt in formats:
        written.append(write_tidy(result.tidy, stem, fmt))
    if plot and result.figures:
        from driver.plotting import save_figure
        for fig in result.figures:
            written.append(save_figure(fig.draw(), stem.with_name(f"{stem.name}_{fig.name}.png")))
    return written


@dataclass
class Outcome:
    """What one single-case run did: its result and the files written (for the caller to report)."""

    result: Result
    written: list[Path] = field(default_factory=list)


def run_study(deck: Deck, outdir: Path | None, formats: list[str], plot: bool,
              progress: bool = False) -> Outcome:
    """Validate and run the deck's study; write its outputs to ``outdir`` (None: write nothing).

    Raises DeckError for bad input (nothing is written then); other exceptions are run failures.
    """
    module, params = study_of(deck)
    result = module.run(params, progress=progress)
    written = [] if outdir is None else write_outputs(result, Path(outdir) / Path(deck.path).stem, formats, plot)
    return Outcome(result, written)
