"""The runner: deck -> study -> :class:`~driver._output.Result` -> output files, for one case.

Every way of running a study goes through here: the command line (:mod:`driver._cli`),
sweeps (:mod:`driver.sweep`) and the Python API.  The runner never prints and never
exits; it raises :class:`~driver._deck.DeckError` for bad input and returns what it did.
"""
from __future__ import annotations

import functools
import os
import re
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from driver import _blas as blas
from driver import _limits as limits
from driver._atomic import NAME_MAX, inside, output_set, remove_stale_temporaries, write_text
from driver._deck import Deck, DeckError, GroupSpec, Params, shown_value, validate
from driver._export import FORMATS, write_tidy
from driver._names import name_problem, shown
from driver._outcome import RunOutcome
from driver._result import Result
from driver._signatures import sign
from driver._study import ENGINES, Study, load_study, registered, study_names
from driver._table import TableValueError

__all__ = ["CONTROL_GROUPS", "CaseFailure", "RunOutcome", "available_studies", "study_of", "run_study", "write_outputs",
           "study_run",
           "output_stem", "check_finite", "compute", "numerical_error"]

#: groups handled by the driver's engines rather than by a study (driver._study.ENGINES)
CONTROL_GROUPS = tuple(ENGINES)


def available_studies() -> dict[str, Study]:
    """Every registered study (:data:`driver._study.REGISTRY`), by group name."""
    return registered()


def study_of(deck: Deck) -> tuple[Study, Params]:
    """The single study group of a deck, validated; DeckError otherwise."""
    studies = []
    for name, raw in deck.groups.items():
        if name in CONTROL_GROUPS:
            continue
        study = load_study(name)
        if study is None:
            known = ", ".join(f"&{g}" for g in study_names() + list(CONTROL_GROUPS))
            raise DeckError(deck.path, raw.line, None, f"unknown group &{name} (known groups: {known})")
        studies.append((study, raw))
    if not studies:
        raise DeckError(deck.path, None, None, "deck has no study group")
    if len(studies) > 1:
        names = ", ".join(f"&{raw.name} (line {raw.line})" for _, raw in studies)
        raise DeckError(deck.path, studies[1][1].line, None,
                        f"a deck describes one study; found {names}")
    study, raw = studies[0]
    return study, validate(raw, study.spec, deck.path)


def output_stem(outdir: str | Path, deck_path: str | Path, suffixes: Iterable[str] = (".out",)) -> Path:
    """``OUTDIR/<deck stem>``, refused (DeckError) unless every output named after it stays in OUTDIR
    and fits a file name: ``suffixes`` are what the run appends to the stem that it knows before
    running (the longest counts); a name known only later (a figure's) is checked when its file
    is opened (:class:`driver._atomic.NameTooLong`, before anything is renamed into place).

    A deck named ``..dat`` has the stem ``.``, ``...dat`` the stem ``..``: their outputs would
    land beside or above OUTDIR.  A name or folder holding control or bidi characters is refused
    (:mod:`driver._names`).
    """
    name = Path(deck_path).name
    stem = name[: -len(Path(name).suffix)] if Path(name).suffix else name
    candidate = Path(outdir) / stem
    why = name_problem(candidate, "the outputs' name (the output folder and the deck's stem)")
    if why:   # every output's name is printed and written: control and bidi characters are refused
        raise DeckError(shown(deck_path), None, None, why)
    if not stem or stem.strip(".") == "" or "/" in stem or "\\" in stem or not inside(outdir, candidate):
        raise DeckError(deck_path, None, None, f"outputs are named after the deck file, and {name!r} would name "
                        f"them outside the output folder {outdir}: rename the deck (e.g. case.dat)")
    longest = max(suffixes, key=lambda s: len(os.fsencode(s)))
    n, extra = len(os.fsencode(stem)), len(os.fsencode(longest))
    if n + extra > NAME_MAX:
        raise DeckError(deck_path, None, None, name_too_long(n, longest))
    return candidate


def name_too_long(stem_bytes: int, suffix: str) -> str:
    """The words of the refusal of an output name: the stem's length, the suffix, the limit."""
    extra = len(os.fsencode(suffix))
    return (f"the deck's file name is {stem_bytes} bytes without '.dat'; its output <name>{suffix} would have "
            f"{stem_bytes + extra} and a file name may have {NAME_MAX} bytes: rename the deck (at most "
            f"{NAME_MAX - extra} bytes before '.dat' for this run)")


def study_suffixes(formats: list[str], summary_json: bool) -> tuple[str, ...]:
    """What a single-case run appends to the stem, known before it runs (figures' names are not)."""
    return (".out", *(f".{fmt}" for fmt in formats), *((".json",) if summary_json else ()))


def write_outputs(result: Result, stem: Path, formats: list[str], plot: bool | str,
                  summary_json: bool = False, clean: bool = True) -> list[Path]:
    """Write the .out file, extra files, tidy tables, figures (``plot``: True for PNG, or 'png',
    'svg', 'pdf') and the ``--json`` record as ``<stem>.json`` (when ``summary_json``;
    :func:`driver._record.result_record`) for one case.

    ``plot`` is False (no figures), True (PNG) or a format of :data:`driver._output.PLOT_FORMATS`.

    The files form one set (:func:`driver._atomic.output_set`): all are renamed into place
    together once every one is complete, or none is.  Stale temporaries of this stem left
    by a killed earlier run are removed first (``clean``; a sweep cleans its folder once).
    """
    if clean:
        remove_stale_temporaries(stem.parent, stem.name)
    written: list[Path] = []
    with output_set(stem.parent):
        written.append(write_text(stem.with_name(stem.name + ".out"), result.text))
        for suffix, text in result.extra.items():
            written.append(write_text(stem.with_name(stem.name + suffix), text))
        for fmt in formats:
            written.append(write_tidy(result.tidy, stem, fmt))
        if plot and result.figures:
            from driver.plotting import save_figure
            for fig in result.figures:
                written.append(save_figure(fig.draw(), stem.with_name(f"{stem.name}_{fig.name}.png"), plot))
        if summary_json:   # last: the record lists the files written with it
            from driver._record import record_text, result_record
            written.append(write_text(stem.with_name(stem.name + ".json"),
                                      record_text(result_record(result, written, stem.parent, stem.name))))
    # the set replaces an earlier run's: its tidy tables in formats not written now go
    for fmt in FORMATS:
        old = stem.with_name(f"{stem.name}.{fmt}")
        if fmt not in formats and len(os.fsencode(old.name)) <= NAME_MAX and old.is_file():   # else it cannot exist
            old.unlink()
    return written


#: exceptions that bad input can reach inside a study: they become deck errors in words
NUMERICAL = (ArithmeticError, FloatingPointError, np.linalg.LinAlgError, ValueError, MemoryError)

_WORDS = [(TableValueError, "a result that is not a finite number"),
          (ZeroDivisionError, "a division by zero"),
          (OverflowError, "a number beyond the range of floating point"),
          (FloatingPointError, "an invalid floating-point operation"),
          (np.linalg.LinAlgError, "a singular system of equations"),
          (MemoryError, "more memory than the machine has (see --max-memory)"),
          (ArithmeticError, "an arithmetic error"),
          (ValueError, "a value outside what the computation accepts")]

_NON_FINITE = re.compile(r"(?<![A-Za-z_])(nan|[+-]?inf(inity)?)(?![A-Za-z_])|\*\*\*\*", re.IGNORECASE)


class CaseFailure(DeckError):
    """A deck error for a case that was accepted and computed but failed: a numerical failure,
    or a non-finite number bound for a table (an optimiser counts such a design as failed, one
    the study refuses as input as not a valid design)."""


def numerical_error(params: Params, exc: BaseException) -> CaseFailure:
    """The deck error for a numerical failure reached from ``params``.

    A study may declare ``blame(params, exc) -> (key, message) | None`` to name the key; otherwise
    the error is placed at the group and lists the keys the deck gave.
    """
    study = load_study(params.group)
    blamed = study.blame(params, exc) if study is not None and study.blame is not None else None
    if blamed and blamed[0] is not None and blamed[0] not in params.given:
        # the deck does not have the key: the error is placed at the group, the default named
        key, words = blamed
        e = params.error(None, f"{words} (key '{key}' is not in the deck: its default, "
                               f"{shown_value(params.get(key))}, applies)")
    elif blamed:
        e = params.error(*blamed)
    else:
        words = next(w for cls, w in _WORDS if isinstance(exc, cls))
        detail = str(exc).strip().splitlines()[0][:120] if str(exc).strip() else exc.__class__.__name__
        given = ", ".join(sorted(params.given)) or "none"
        e = params.error(None, f"the values of &{params.group} lead to {words} ({detail}); this case cannot "
                         f"be computed (keys given: {given})")
    return CaseFailure(e.path, e.line, e.key, e.message)


def check_finite(result: Result, params: Params) -> Result:
    """DeckError when a NaN, an infinity or a '****' overflow field would reach a table."""
    texts = [("the .out table", result.text), *((f"the {s} file", x) for s, x in result.extra.items())]
    for what, text in texts:
        m = _NON_FINITE.search(text)
        if m:
            line = text.count("\n", 0, m.start()) + 1
            found = m.group(0)
            kind = ("a field of asterisks (a number too wide for its column)" if found.startswith("*") else
                    "a value that is not a number" if "nan" in found.lower() else "an infinity")
            raise numerical_error(params, TableValueError(f"{kind} would be written on line {line} of {what}"))
    pending = result.tidy_pending
    if pending is not None:   # columns not yet a DataFrame (pandas not needed): checked as arrays
        bad = [c for c in [pending.infinite_column()] if c is not None]
    else:
        num = result.tidy.select_dtypes("number") if result.tidy is not None else None
        bad = [] if num is None or not num.size or np.isfinite(num.to_numpy(dtype=float, na_value=0.0)).all() else \
            [c for c in num.columns if not np.isfinite(num[c].to_numpy(dtype=float, na_value=0.0)).all()]
    if bad:
        raise numerical_error(params, TableValueError(f"non-finite values in column {bad[0]} of the tidy table"))
    return result


def compute(study: Study, params: Params, progress: bool = False,
            budget: limits.Budget | None = None) -> Result:
    """``study.run(params)`` within the budget (:mod:`driver._limits`; ``budget`` default this
    process's), with numerical failures turned into deck errors and the result checked for
    non-finite numbers (no NaN, inf or '****' ever reaches a table)."""
    limits.check(study, params, lim=budget)   # absurd requests are refused before anything is allocated
    try:
        with np.errstate(all="ignore"), blas.one_thread():   # one BLAS thread: the same digits on any machine
            result = study.run(params, progress=progress)
    except DeckError:
        raise
    except NUMERICAL as exc:
        raise numerical_error(params, exc) from None
    result.params = params
    return check_finite(result, params)


def run_study(deck: Deck, outdir: Path | None, formats: list[str], plot: bool | str,
              progress: bool = False, summary_json: bool = False, name: str | None = None) -> RunOutcome:
    """Validate and run the deck's study; write its outputs to ``outdir`` (None: write nothing)
    as ``<name>.*`` (default: the deck's file stem).  Returns the result, the files written, and
    the result's warnings and failure as messages naming the deck.

    Raises DeckError for bad input (nothing is written then); other exceptions are run failures.
    """
    study, params = study_of(deck)
    result = compute(study, params, progress=progress)
    result.name, result.study = name or Path(deck.path).stem, params.group
    written = [] if outdir is None else write_outputs(
        result, output_stem(outdir, deck.path if name is None else f"{name}.dat", study_suffixes(formats, summary_json)),
        formats, plot, summary_json)
    outcome = RunOutcome(result=result, written=written)
    for w in result.warnings:
        if w != result.failure:   # a failure is reported once, as the error
            outcome.warn(f"{deck.path}: {w}")
    if result.failure:
        outcome.error(f"{deck.path}: {result.failure}")
    return outcome


def study_run(spec: GroupSpec) -> Callable[[Callable[..., Result]], Callable[..., Result]]:
    """Decorator of every study's entry point ``run(params, progress=False) -> Result``: the one
    place that makes it callable with validated Params (the runner's call) or with the keys of
    ``spec`` as keyword arguments, e.g. ``driver.fourbar.run(fixed_link=12, crank=5, coupler=15,
    rocker=9, step_deg=20)``.  Keywords are validated by the SPEC exactly like a deck (errors are
    :class:`driver._deck.DeckError`); the result is the runner's, as for a deck (:func:`run_study`,
    the outputs named after the study group).  ``help()``, IDEs and :func:`inspect.signature` see
    the keys with their types, units and defaults (:func:`driver._signatures.sign`); type checkers
    see them in the study's generated ``_keywords.pyi``."""
    def decorate(run: Callable[..., Result]) -> Callable[..., Result]:
        @functools.wraps(run)
        def wrapper(params: Any = None, /, progress: bool = False, **keys: Any) -> Result:
            if params is not None:
                if keys:
                    raise TypeError(f"{spec.name}.run() takes validated params or deck keys, not both")
                if isinstance(params, Params):
                    return run(params, progress=progress)
                return _positional_run(spec.name, params, progress)
            from driver._pydeck import deck_of  # decks from Python values: the API's calls only
            return run_study(deck_of({spec.name: keys}, None), None, [], False, progress=progress).result

        sign(wrapper, spec)
        return wrapper

    return decorate


def _positional_run(group: str, source: Any, progress: bool) -> Result:
    """A study's ``run`` given one positional argument other than Params: a dict of its keys
    (``{'crank': 5, ...}``), or a deck as :func:`driver.run` takes one (a dict of groups, a
    deck's text, a deck file) whose study group is ``group``; anything else is a TypeError that
    says what to pass."""
    what = (f"{group}.run() takes the deck's keys as keyword arguments ({group}.run(crank=5, ...)), a dict of "
            f"them, a &{group} deck (its text, its file, or {{'{group}': {{...}}}}), or validated Params")
    from driver._pydeck import deck_of, is_text
    if isinstance(source, Mapping):
        nested = [isinstance(v, Mapping) for v in source.values()]
        if source and not any(nested):          # the keys of this study
            return run_study(deck_of({group: dict(source)}, None), None, [], False, progress=progress).result
        if not all(nested):
            raise TypeError(f"{what}; this dict mixes groups ({{'{group}': {{...}}}}) and keys")
    elif not isinstance(source, (str, os.PathLike)):
        raise TypeError(f"{what}, not {type(source).__name__}")
    deck = deck_of(source, None)
    control = [g for g in ("synthesis", "optimize", "sweep") if g in deck.groups]
    if control:
        raise DeckError(deck.path, deck.groups[control[0]].line or None, None,
                        f"this deck has a &{control[0]} group: {group}.run() runs one &{group} deck (run the deck "
                        "with driver.run_sweep(), driver.optimize.optimize() or driver.synthesis.synthesise())")
    others = sorted(g for g in deck.groups if g != group)
    if others:
        raise DeckError(deck.path, deck.groups[others[0]].line or None, None,
                        f"a &{others[0]} group in a deck given to {group}.run(), which runs a &{group} deck "
                        f"(driver.run() runs a deck of any study)")
    result = run_study(deck, None, [], False, progress=progress).result
    if isinstance(source, str) and is_text(source):   # a deck's text has no file name: named after the study
        result.name = group
    return result
