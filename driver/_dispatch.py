"""Which engine runs a deck, decided here and nowhere else, and the run of a deck by it.

A deck with a ``&synthesis`` group is a synthesis (:mod:`driver.synthesis`), else one with an
``&optimize`` group an optimisation (:mod:`driver.optimize`), else one with a ``&sweep`` group
a sweep (:mod:`driver.sweep`), else one study run (:mod:`driver._runner`).  The command line
(:func:`driver._cli.run_deck`) runs every deck through :func:`run_deck`; the Python API refuses
a deck for the wrong entry point by :func:`engine_of`.  Nothing here prints: every engine
returns an :class:`~driver._outcome.Outcome`, and its ``--json`` record (:mod:`driver._record`)
and report page (:mod:`driver._report_page`) are made from that outcome.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from driver._atomic import output_set
from driver._deck import Deck
from driver._extras import require
from driver._outcome import ExitCode, Outcome, RunOutcome
from driver._runner import output_stem, run_study
from driver._warnings import caught

__all__ = ["ENGINES", "engine_of", "run_deck"]

#: the control groups that give a deck to an engine other than a single study run, in the
#: order they decide, with the Python function that runs such a deck
ENGINES = {"synthesis": "driver.synthesis.synthesise()", "optimize": "driver.optimize.optimize()",
           "sweep": "driver.run_sweep()"}


def engine_of(deck: Deck) -> str:
    """'synthesis', 'optimize' or 'sweep' (the deck's control group, in that order), else 'study'."""
    return next((g for g in ENGINES if g in deck.groups), "study")


def run_deck(deck: Deck, outdir: Path, formats: list[str], plot: bool | str, progress: bool = False, *,
             jobs: int | None = None, scheduler: Any = None, resume: bool = False, summary_json: bool = False,
             report: bool = False, notify: Callable[[str], None] | None = None,
             animation: str | None = None) -> Outcome:
    """Run ``deck`` by its engine and write its outputs to ``outdir``; ``summary_json`` also its
    ``<stem>.json``, ``report`` its report page ``<stem>.html`` (:mod:`driver._report_page`),
    both made from the engine's outcome once its run has written its outputs, ``animation``
    ('gif' or 'mp4') the mechanism's animation ``<stem>_animation.<fmt>`` (the report page's
    frames).  ``jobs``, ``scheduler`` and ``resume`` apply to sweeps and optimisations;
    ``notify(line)`` hears what cannot wait for the outcome (a sweep's Ctrl-C: the queued cases
    are cancelled).  Returns the engine's outcome, with what a library warned while the deck ran
    as warnings in words (:func:`driver._warnings.caught`); raises DeckError for bad input
    (nothing written) and :class:`~driver._extras.MissingExtra` for a missing optional package."""
    with caught() as said:
        outcome = _run(deck, outdir, formats, plot, progress, jobs=jobs, scheduler=scheduler, resume=resume,
                       summary_json=summary_json, report=report, notify=notify, animation=animation)
    for text in dict.fromkeys(said):
        outcome.warn(f"{deck.path}: {text}")
    return outcome


def _run(deck: Deck, outdir: Path, formats: list[str], plot: bool | str, progress: bool = False, *,
         jobs: int | None = None, scheduler: Any = None, resume: bool = False, summary_json: bool = False,
         report: bool = False, notify: Callable[[str], None] | None = None,
         animation: str | None = None) -> Outcome:
    kind = engine_of(deck)
    # the names of what is made from the outcome, known now: refused before the run, not after it
    after = (*((".html",) if report else ()), *((".json",) if summary_json and kind != "study" else ()),
             *((f"_animation.{animation}",) if animation else ()))
    stem = output_stem(outdir, deck.path, after) if after else None
    outcome: Outcome
    if kind in ("synthesis", "optimize"):
        # the engine's files and its --json record, all together or none (a sweep's cases are
        # put in place as they finish, for --resume: its record is written after them)
        with output_set(outdir):
            if kind == "synthesis":
                from driver import synthesis
                outcome = synthesis.run_synthesis_deck(deck, outdir, formats, plot, progress)
            else:
                from driver import optimize
                outcome = optimize.run_optimize_deck(deck, outdir, formats, plot, progress, jobs=jobs, resume=resume,
                                                     scheduler=scheduler)
            _record(outcome, stem, summary_json)
    elif kind == "sweep":
        require("parquet")   # sweeps keep their cases in Parquet: say so before importing them
        from driver import sweep
        outcome = sweep.run_sweep_deck(deck, outdir, formats, plot, progress, jobs=jobs, scheduler=scheduler,
                                       resume=resume, notify=notify, best=report or bool(animation))
    else:   # a single run writes its record with its other files (as driver.write does)
        outcome = run_study(deck, outdir, formats, plot, progress, summary_json=summary_json)
    if kind == "sweep":
        _record(outcome, stem, summary_json)
    if stem is not None and report:
        _report(deck, stem, outcome)
    if stem is not None and animation:
        _animation(deck, stem, outcome, animation)
    return outcome


def _record(outcome: Outcome, stem: Path | None, summary_json: bool) -> None:
    """Write the engine's ``--json`` record ``<stem>.json`` (a single run writes its own)."""
    if stem is not None and summary_json:
        from driver._record import write_record
        outcome.written.append(write_record(outcome, stem))


def _animation(deck: Deck, stem: Path, outcome: Outcome, fmt: str) -> None:
    """Write the mechanism's animation after the run; one that cannot be written (no ffmpeg for
    an MP4, a full disk) is an error message and exit status 1, the run's outputs stay."""
    from driver import _report_page as report_page
    if outcome.exit_code == ExitCode.BAD_INPUT:
        return
    try:
        path = report_page.write_animation(stem, outcome, fmt)
    except (KeyboardInterrupt, BrokenPipeError):
        raise
    except Exception as exc:
        outcome.error(f"{deck.path}: the animation could not be written: {exc.__class__.__name__}: {exc}")
        outcome.late_failure = True
        return
    if path is None:
        outcome.warn(f"{deck.path}: no mechanism to animate (--animation)")
    else:
        outcome.written.append(path)


def _report(deck: Deck, stem: Path, outcome: Outcome) -> None:
    """Write the deck's report page after its run (not after bad input: nothing is written then).
    For a single run a failure to build it is a run failure (it propagates); for a sweep,
    optimisation or synthesis it is an error message, and the deck's exit status becomes 1."""
    from driver import _report_page as report_page
    path = stem.with_name(stem.name + ".html")
    if isinstance(outcome, RunOutcome):
        outcome.written.append(report_page.write_report(path, report_page.page(outcome, deck)))
        return
    if outcome.exit_code == ExitCode.BAD_INPUT:
        return
    try:
        outcome.written.append(report_page.write_report(path, report_page.page(outcome, deck)))
    except (KeyboardInterrupt, BrokenPipeError):
        raise
    except Exception as exc:
        outcome.error(f"{deck.path}: the report page could not be written: {exc.__class__.__name__}: {exc}")
        outcome.late_failure = True
