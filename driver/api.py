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
import io
import os
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Sequence, Union

import numpy as np
import pandas as pd

from driver.deck import MAX_DECK_BYTES, MAX_VALUES, Deck, DeckError, RawGroup, shown_value, read_deck
from driver.runner import available_studies, run_study
from driver.study import Result

__all__ = ["run", "run_sweep", "studies", "keys", "Result", "SweepResult", "DeckError", "DeckSource"]

#: what :func:`run` and :func:`run_sweep` accept: a deck file, a deck's text, or {group: {key: value}}
DeckSource = Union[str, os.PathLike, Mapping[str, Mapping[str, Any]]]


# ----------------------------------------------------------------------------- decks from Python

def _plain(value: Any, where: str, key: str | None = None, depth: int = 0) -> Any:
    """A Python/numpy value as the deck reader's plain types (lists for sequences).

    Sizes are checked from ``len()`` and ``shape`` before anything is converted (a
    ``range(10**9)`` is refused, not materialised); a list of lists is one level deep at most
    (a deck value is a number, a string, a logical or a list of them)."""
    if isinstance(value, np.ndarray):
        if value.ndim == 0:
            return _plain(value.item(), where, key, depth)
        if value.size > MAX_VALUES or value.ndim > 1:
            raise DeckError(where, None, key, f"array of shape {value.shape}: a deck value is at most a flat "
                            f"list of {MAX_VALUES} values")
        value = value.tolist()
    if isinstance(value, (list, tuple, range)):
        if len(value) > MAX_VALUES:
            raise DeckError(where, None, key, f"{len(value)} values; at most {MAX_VALUES} are read per key "
                            "(checked before anything is converted)")
        if depth >= 1:
            raise DeckError(where, None, key, "a list inside a list: a deck value is a number, a string, "
                            "a logical or a flat list of them")
        return [_plain(v, where, key, depth + 1) for v in value]
    if isinstance(value, np.generic):
        return _plain(value.item(), where, key, depth)
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, str) and len(value) > MAX_DECK_BYTES:
        raise DeckError(where, None, key, f"a text of {len(value)} characters; a deck is at most {MAX_DECK_BYTES}")
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    raise DeckError(where, None, key, f"value {shown_value(value)} of type {type(value).__name__} is not a deck value "
                                       "(give numbers, strings, logicals or lists of them)")


def _group_from_dict(group: str, values: Mapping[str, Any], label: str) -> RawGroup:
    if not isinstance(values, Mapping):
        raise DeckError(label, None, None, f"group &{group} must be a dict of keys, got {type(values).__name__}")
    plain = {}
    for k, v in values.items():
        if not isinstance(k, str):
            raise DeckError(label, None, None, f"key {k!r} of &{group} is not a name")
        plain[k.lower()] = _plain(v, label, k.lower())
    return RawGroup(group, plain, {}, 0)


def _is_text(source: str) -> bool:
    return "\n" in source or source.lstrip().startswith(("&", "$", "!"))


def _deck(source: DeckSource | Deck, name: str | None) -> Deck:
    """The deck for ``source``: a file path, a deck's text, a {group: {key: value}} dict."""
    if isinstance(source, Deck):
        return source
    if isinstance(source, Mapping):
        if not source:
            raise DeckError(name or "<dict>", None, None, "deck has no study group")
        named = [str(g).lower().lstrip("&") for g in source]
        label = name or next((g for g in named if g != "sweep"), "sweep")
        groups = {}
        for g, values in source.items():
            g = str(g).lower().lstrip("&")
            groups[g] = _group_from_dict(g, values, label)
        return Deck(Path(label), groups)
    if isinstance(source, str) and _is_text(source):
        return read_deck(Path(name or "deck"), text=source)
    if isinstance(source, (str, os.PathLike)):
        return read_deck(Path(source))
    raise TypeError(f"a deck is a path, a deck's text or a dict of groups, not {type(source).__name__}")


# ----------------------------------------------------------------------------- single runs

def run(source: DeckSource, *, name: str | None = None, progress: bool = False) -> Result:
    """Run one study and return its :class:`~driver.study.Result` (nothing is written).

    ``source`` is a deck file (``"inputs/crank5.dat"``), a deck's text (``"&fourbar ... /"``)
    or a dict ``{"fourbar": {"crank": 5, ...}}`` with the deck's keys and units.  ``name`` is
    the output stem for :meth:`Result.write` (default: the deck's file stem, or the study
    group for text and dicts).  Raises :class:`DeckError` for bad input, with the deck, line
    and key; a deck with a ``&sweep`` group is run by :func:`run_sweep`.
    """
    deck = _deck(source, name)
    for group, how in (("sweep", "driver.run_sweep()"), ("optimize", "driver.optimize.optimize()"),
                       ("synthesis", "driver.synthesis.synthesise()")):
        if group in deck.groups:
            raise DeckError(deck.path, deck.groups[group].line or None, None,
                            f"this deck has a &{group} group: run it with {how}")
    from_text = isinstance(source, str) and _is_text(source)
    outcome = run_study(deck, None, [], False, progress=progress, name=None if from_text else name)
    if from_text:   # a deck's text has no file name: name the outputs after the study
        outcome.result.name = name or outcome.result.study
    return outcome.result


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

@dataclass
class SweepResult:
    """What a sweep produced.

    summary   one row per case: case number, the swept keys, status, kept, the study's
              headline figures (units in the column names), error
    cases     the tidy rows of every case that wrote its outputs, a column per swept key
              (None when no case did)
    text      the fixed-format summary ``.out``
    status    0 all cases ok, 1 a case failed, 2 a case had bad values (as the command line)
    warnings  the cases' warnings and errors, one line each
    outdir    where the files are (None: they were written to a temporary folder, now gone)
    """

    summary: pd.DataFrame
    cases: pd.DataFrame | None
    text: str
    status: int
    warnings: list[str] = field(default_factory=list)
    outdir: Path | None = None
    name: str = ""

    @property
    def out(self) -> str:
        """The fixed-format summary ``.out`` text."""
        return self.text

    @property
    def ok(self) -> bool:
        """True when every case succeeded."""
        return self.status == 0

    @property
    def kept(self) -> pd.DataFrame:
        """The summary rows of the cases the deck's ``keep`` filter kept (all ok cases without one)."""
        return self.summary[self.summary["kept"].astype(bool)]

    def __repr__(self) -> str:
        n, ok = len(self.summary), int((self.summary["status"] == "ok").sum()) if len(self.summary) else 0
        return (f"<SweepResult {self.name!r}: {n} cases, {ok} ok, {len(self.kept)} kept; status {self.status}"
                + (f"; files in {self.outdir}" if self.outdir else "") + ">")


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
        vals = _plain(vals, label, key)
        values[f"values{k}"] = vals if isinstance(vals, list) else [vals]
    values.update({k: _plain(v, label, k) for k, v in options.items() if v is not None})
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
    deck = _deck(source, name)
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
        err, out = io.StringIO(), io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
            status = sweep.run_sweep_deck(deck, where, list(formats), plot, progress, quiet=True,
                                          jobs=jobs, scheduler=scheduler, resume=resume)
        summary = pd.read_parquet(where / f"{stem}_summary.parquet")
        cases_path = where / f"{stem}_cases.parquet"
        cases = pd.read_parquet(cases_path) if cases_path.exists() else None
        text = (where / f"{stem}.out").read_text()
    messages = [line for line in err.getvalue().splitlines() if line.startswith(("warning:", "error:"))]
    return SweepResult(summary, cases, text, status, messages, None if outdir is None else Path(outdir), stem)
