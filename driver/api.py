"""The Python API: run a deck, a deck's text, a dict or keyword arguments, and get a result back.

    >>> import driver
    >>> r = driver.run("inputs/crank5.dat")                     # a deck file
    >>> r = driver.fourbar.run(fixed_link=12, crank=5, coupler=15, rocker=9, step_deg=20)
    >>> r = driver.run({"fourbar": {"fixed_link": 12, "crank": 5, "coupler": 15, "rocker": 9,
    ...                             "step_deg": 20}})
    >>> r.summary["mu_min_deg"], r.tidy.head(), r.figure("linkage")
    >>> s = driver.run_sweep("inputs/fourbar_paper_sweep.dat")   # a deck with a &sweep group
    >>> s = driver.run_sweep({"fourbar": {...}}, grid={"crank": [2, 3, 4, 5]}, jobs=1)
    >>> s.summary                                               # one row per case

Everything goes through the runner (:mod:`driver.runner`), exactly as the command line does:
the same deck validation, the same study code, the same output files when written.  Bad
input raises :class:`~driver.deck.DeckError` (a ValueError naming the deck, line and key).
"""
from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from driver.deck import Deck, DeckError, RawGroup
from driver.dispatch import ENGINES, engine_of
from driver.outcome import SweepOutcome
from driver.pydeck import DeckSource, deck_of, is_text, plain_value
from driver.runner import available_studies, run_study, write_outputs
from driver.study import Result

__all__ = ["run", "run_sweep", "write", "studies", "keys", "Result", "SweepResult", "DeckError", "DeckSource"]



# ----------------------------------------------------------------------------- single runs

def run(source: DeckSource, *, name: str | None = None, progress: bool = False) -> Result:
    """Run one study and return its :class:`~driver.study.Result` (nothing is written).

    ``source`` is a deck file (``"inputs/crank5.dat"``), a deck's text (``"&fourbar ... /"``)
    or a dict ``{"fourbar": {"crank": 5, ...}}`` with the deck's keys and units.  ``name`` is
    the output stem for :func:`write` (default: the deck's file stem, or the study
    group for text and dicts).  Raises :class:`DeckError` for bad input, with the deck, line
    and key; a deck with a ``&sweep`` group is run by :func:`run_sweep`.
    """
    deck = deck_of(source, name)
    engine = engine_of(deck)
    if engine != "study":
        raise DeckError(deck.path, deck.groups[engine].line or None, None,
                        f"this deck has a &{engine} group: run it with {ENGINES[engine]}")
    from_text = isinstance(source, str) and is_text(source)
    outcome = run_study(deck, None, [], False, progress=progress, name=None if from_text else name)
    if from_text:   # a deck's text has no file name: name the outputs after the study
        outcome.result.name = name or outcome.result.study
    return outcome.result


def write(result: Result, outdir: str | os.PathLike, formats: Iterable[str] = (), plot: bool | str = False,
          json: bool = False, name: str | None = None, report: bool = False) -> list[Path]:
    """Write the outputs the command line writes for a run's result: ``<outdir>/<name>.out`` and
    extra files, tidy tables in ``formats`` ('csv', 'parquet'), figures with ``plot`` (True for
    PNG, or 'svg', 'pdf'), the summary as ``<name>.json`` with ``json``, and the self-contained
    report page ``<name>.html`` with ``report`` (as ``--report``).  ``name`` defaults to the
    result's name (the deck's file stem).  Every file is written atomically; ``outdir`` is
    created when missing.  Returns the paths written."""
    stem = name or result.name or result.study or "result"
    if Path(stem).name != stem or stem in ("", ".", ".."):
        raise ValueError(f"output name {stem!r} must be a plain file stem, not a path")
    written = write_outputs(result, Path(outdir) / stem, list(formats), plot, summary_json=json)
    if report:
        from driver import report_page
        page = report_page.page_for_result(result, None, result.params)
        written.append(report_page.write_report(Path(outdir) / f"{stem}.html", page))
    return written


def studies() -> dict[str, str]:
    """The study groups this tool runs, with one line on each."""
    return {g: m.spec.doc for g, m in sorted(available_studies().items())}


def keys(group: str) -> pd.DataFrame:
    """The keys of a study group (the deck's and the keyword arguments'): kind, units, default,
    whether required, allowed values and what each means; one row per key."""
    from driver._study import load_study
    module = load_study(group.lstrip("&").lower())
    if module is None:
        raise KeyError(f"no study group &{group} (known: {', '.join(studies())})")
    rows = [{"key": k, "kind": key.kind, "units": key.units, "required": key.required,
             "default": None if key.required else key.default,
             "choices": ", ".join(map(str, key.choices)) if key.choices else "", "doc": key.doc}
            for k, key in module.spec.keys.items()]
    return pd.DataFrame(rows).set_index("key")


# ----------------------------------------------------------------------------- sweeps

#: what :func:`run_sweep` returns (the sweep engine's outcome, with its tables read back)
SweepResult = SweepOutcome


def _sweep_group(grid: Mapping[str, Any], study: str, label: str, options: dict[str, Any]) -> RawGroup:
    from driver.sweep import MAX_KEYS
    if not grid:
        raise DeckError(label, None, None, "grid must name at least one key to vary")
    if len(grid) > MAX_KEYS:
        raise DeckError(label, None, None, f"a sweep varies at most {MAX_KEYS} keys (grid has {len(grid)})")
    values: dict[str, Any] = {}
    for k, (key, vals) in enumerate(grid.items(), start=1):
        key = str(key).lower()
        values[f"key{k}"] = key if "." in key else f"{study}.{key}"
        vals = plain_value(vals, label, key)
        values[f"values{k}"] = vals if isinstance(vals, list) else [vals]
    values.update({k: plain_value(v, label, k) for k, v in options.items() if v is not None})
    return RawGroup("sweep", values, {}, 0)


def run_sweep(source: DeckSource, grid: Mapping[str, Sequence[Any]] | None = None, *,
              zip: bool | None = None, keep: str | None = None, case_outputs: str | None = None,
              summary_rows: str | None = None, chunk: int | None = None,
              outdir: str | os.PathLike | None = None, name: str | None = None,
              jobs: int | None = None, scheduler: Any = None, resume: bool = False,
              formats: Iterable[str] = (), plot: bool = False, progress: bool = False) -> SweepResult:
    """Run a study over many cases and return the summary DataFrame (and more, :class:`SweepResult`).

    Either ``source`` is a deck with a ``&sweep`` group (file, text or dict with a "sweep"
    entry), or ``grid`` gives the keys to vary in Python, ``{"crank": [2, 3, 4, 5]}``
    (``"group.key"`` or the study's key alone; arrays welcome), with the &sweep options
    ``zip``, ``keep`` (a filter on the summary columns), ``case_outputs``, ``summary_rows``
    and ``chunk`` as keywords.  Execution options are the command line's: ``jobs`` worker
    processes (default all cores; 1 runs in this process), ``scheduler`` a Dask scheduler
    address or ``dask.distributed.Client``, ``resume``, ``formats``, ``plot``.

    Files are written to ``outdir`` exactly as ``python -m driver DECK -o OUTDIR`` writes
    them; without ``outdir`` they go to a temporary folder that is removed after the tables
    are read back.  Raises :class:`DeckError` for bad input before any case runs.
    """
    deck = deck_of(source, name)
    options = {"zip": zip, "keep": keep, "case_outputs": case_outputs, "summary_rows": summary_rows,
               "chunk": chunk}
    if grid is not None:
        if "sweep" in deck.groups:
            raise DeckError(deck.path, deck.groups["sweep"].line or None, None,
                            "the deck already has a &sweep group; give it or grid=, not both")
        studies_ = [g for g in deck.groups if g != "sweep"]
        study = studies_[0] if len(studies_) == 1 else ""
        deck = Deck(deck.path, {**deck.groups, "sweep": _sweep_group(grid, study, str(deck.path), options)})
    elif "sweep" not in deck.groups:
        raise DeckError(deck.path, None, None, "no &sweep group in the deck: give grid= (the keys to vary)")
    elif any(v is not None for v in options.values()):
        given = ", ".join(k for k, v in options.items() if v is not None)
        raise DeckError(deck.path, deck.groups["sweep"].line or None, None,
                        f"the deck's &sweep group sets the sweep; {given} apply only with grid=")
    engine = engine_of(deck)
    if engine != "sweep":   # a &sweep group beside an &optimize or &synthesis group
        raise DeckError(deck.path, deck.groups[engine].line or None, None,
                        f"this deck has a &{engine} group: run it with {ENGINES[engine]}")
    if jobs is not None and (isinstance(jobs, bool) or not isinstance(jobs, (int, np.integer)) or jobs < 1):
        raise ValueError(f"jobs must be a whole number of at least 1 (got {jobs!r})")
    from driver.export import FORMATS
    if isinstance(formats, str):
        formats = [formats]
    formats = list(formats)
    bad = [f for f in formats if f not in FORMATS]
    if bad:   # checked before any case runs
        raise ValueError(f"unknown table format {bad[0]!r} (choose {', '.join(FORMATS)})")
    from driver import sweep

    stem = Path(deck.path).stem
    with contextlib.ExitStack() as stack:
        if outdir is None:
            where = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="driver_sweep_")))
        else:
            where = Path(outdir)
        outcome = sweep.run_sweep_deck(deck, where, list(formats), plot, progress, jobs=jobs, scheduler=scheduler,
                                       resume=resume)
        outcome.summary = pd.read_parquet(where / f"{stem}_summary.parquet")
        cases_path = where / f"{stem}_cases.parquet"
        outcome.cases = pd.read_parquet(cases_path) if cases_path.exists() else None
        outcome.text = (where / f"{stem}.out").read_text()
    if outdir is None:   # the files were in a temporary folder, now gone
        outcome.outdir, outcome.written = None, []
    return outcome
