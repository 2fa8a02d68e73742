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

Everything goes through the runner (:mod:`driver._runner`), exactly as the command line does:
the same deck validation, the same study code, the same output files when written.  Bad
input raises :class:`~driver._deck.DeckError` (a ValueError naming the deck, line and key).
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

from driver._deck import Deck, DeckError, RawGroup
from driver._dispatch import ENGINES, engine_of
from driver._outcome import SweepOutcome
from driver._pydeck import DeckSource, deck_of, is_text, plain_value
from driver._result import Result
from driver._runner import available_studies, run_study, write_outputs

__all__ = ["run", "run_sweep", "write", "studies", "keys", "Result", "SweepResult", "DeckError", "DeckSource"]



# ----------------------------------------------------------------------------- single runs

def run(source: DeckSource, *, name: str | None = None, progress: bool = False) -> Result:
    """Run one study deck and return its result (nothing is written).

    The deck goes through the runner exactly as on the command line (``python -m driver
    DECK``): the same validation, the same study code, the same tables.

    Parameters
    ----------
    source : str, path-like or dict
        A deck file (``"inputs/crank5.dat"``), a deck's text (``"&fourbar ... /"``) or a dict
        of groups ``{"fourbar": {"crank": 5, ...}}``, with the deck's keys in the deck's units
        (``driver.keys(group)`` lists them with their units).
    name : str, optional
        Output stem for :func:`write`; default the deck's file stem, or the study group for a
        deck's text or a dict.
    progress : bool, default False
        Show a progress bar on the terminal.

    Returns
    -------
    Result
        The run's fixed-format text, tidy table, summary, figures and warnings; units are in
        the tidy and summary column names (``rocker_omega_rad_s``) or ``tidy.attrs["units"]``.

    Raises
    ------
    DeckError
        Bad input (names the deck, line and key), or a deck with a ``&sweep``, ``&optimize``
        or ``&synthesis`` group (run those with :func:`run_sweep`, ``driver.optimize.optimize``
        or ``driver.synthesis.synthesise``).

    See Also
    --------
    run_sweep : Run a study over many cases.
    write : Write a result's files as the command line does.

    Examples
    --------
    >>> import driver
    >>> r = driver.run({"fourbar": {"fixed_link": 12, "crank": 5, "coupler": 15, "rocker": 9,
    ...                             "step_deg": 20}})
    >>> r.study, r.name, r.ok
    ('fourbar', 'fourbar', True)
    >>> r = driver.run("inputs/crank5.dat")
    >>> r.name, r.summary["grashof_class"]
    ('crank5', 'crank-rocker')
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
          json: bool = False, name: str | None = None, report: bool = False,
          animation: str | None = None) -> list[Path]:
    """Write the files the command line writes for a run's result.

    Every file is written atomically; ``outdir`` is created when missing.

    Parameters
    ----------
    result : Result
        What :func:`run` or ``driver.<study>.run`` returned.
    outdir : str or path-like
        Folder to write into.
    formats : iterable of str, default ()
        Tidy table formats: ``'csv'``, ``'parquet'`` (``<name>.csv``, ...).
    plot : bool or str, default False
        Write the figures: True for PNG, or ``'svg'``, ``'pdf'``.
    json : bool, default False
        Also write the summary as ``<name>.json`` (as ``--json``).
    name : str, optional
        Output stem, a plain file name; default the result's name (the deck's file stem).
    report : bool, default False
        Also write the self-contained report page ``<name>.html`` (as ``--report``).
    animation : {None, 'gif', 'mp4'}, optional
        Also write the mechanism's animation ``<name>_animation.gif`` (or ``.mp4``, which needs
        ffmpeg) from the frames the report page plays (as ``--animation``).

    Returns
    -------
    list of pathlib.Path
        The files written, in order, ``<outdir>/<name>.out`` first.

    Raises
    ------
    ValueError
        ``name`` is a path rather than a file stem, or a table, figure or animation format is unknown.

    Examples
    --------
    >>> import driver
    >>> r = driver.fourbar.run(fixed_link=12, crank=5, coupler=15, rocker=9, step_deg=20)
    >>> [p.name for p in driver.write(r, tmp_path, formats=["csv"], json=True)]
    ['fourbar.out', 'fourbar.csv', 'fourbar.json']
    """
    stem = name or result.name or result.study or "result"
    if Path(stem).name != stem or stem in ("", ".", ".."):
        raise ValueError(f"output name {stem!r} must be a plain file stem, not a path")
    written = write_outputs(result, Path(outdir) / stem, list(formats), plot, summary_json=json)
    if report:
        from driver import _report_page as report_page
        from driver._outcome import RunOutcome
        page = report_page.page(RunOutcome(result=result))
        written.append(report_page.write_report(Path(outdir) / f"{stem}.html", page))
    if animation:
        from driver import _report_page as report_page
        from driver._outcome import RunOutcome
        path = report_page.write_animation(Path(outdir) / stem, RunOutcome(result=result), animation)
        if path is not None:
            written.append(path)
    return written


def studies() -> dict[str, str]:
    """List the study groups this tool runs.

    Returns
    -------
    dict of str to str
        Namelist group (``'fourbar'``) -> one line on what the study does, in name order.

    Examples
    --------
    >>> import driver
    >>> sorted(driver.studies())
    ['fourbar', 'linkage', 'manipulator', 'robust_example', 'slidercrank', 'ujoint']
    """
    return {g: m.spec.doc for g, m in sorted(available_studies().items())}


def keys(group: str) -> pd.DataFrame:
    """Tabulate the keys of a study group: the deck's keys and the keyword arguments of its ``run``.

    Parameters
    ----------
    group : str
        The study's namelist group, e.g. ``'fourbar'`` (a leading ``&`` and any case accepted).

    Returns
    -------
    pandas.DataFrame
        One row per key, indexed by key: ``kind``, ``units`` (the SPEC's: ``'rad/s'``; ``'1'``
        or ``'-'`` dimensionless; ``'length'`` the four-bar's free length unit; empty for
        text, counts and switches), ``required``, ``default``, ``choices`` and ``doc``.

    Raises
    ------
    KeyError
        No study has that group.

    Examples
    --------
    >>> import driver
    >>> driver.keys("fourbar").loc["omega", ["units", "default"]].tolist()
    ['rad/s', 1.0]
    """
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

#: what :func:`run_sweep` returns (the sweep engine's outcome, which carries its tables):
#: :class:`driver._outcome.SweepOutcome`, documented there
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
    """Run a study over many cases and return the sweep's summary and counts.

    Either ``source`` is a deck with a ``&sweep`` group, or ``grid`` gives the keys to vary in
    Python with the ``&sweep`` options as keywords.  Files are written to ``outdir`` exactly as
    ``python -m driver DECK -o OUTDIR`` writes them; without ``outdir`` they go to a temporary
    folder that is removed once the sweep is done.  The result carries the tables as the
    engine built them (nothing is read back from the folder).

    Parameters
    ----------
    source : str, path-like or dict
        A deck file, a deck's text or a dict of groups (with a ``"sweep"`` entry unless
        ``grid`` is given); keys in the deck's units.
    grid : mapping of str to sequence, optional
        The keys to vary and their values, ``{"crank": [2, 3, 4, 5]}`` (``"group.key"`` or the
        study's key alone; arrays welcome), in the keys' deck units.
    zip : bool, optional
        Vary the keys together (case k takes value k of each) instead of over their product.
    keep : str, optional
        A filter on the summary columns in the deck expression language
        (``"mu_min_deg > 15"``): the cases kept.
    case_outputs : {'all', 'kept', 'none'}, optional
        Which cases get their own ``.out``/``.parquet``/``.json`` files; default ``'all'``.
    summary_rows : {'all', 'kept'}, optional
        Which cases go into the ``_summary`` tables; default ``'all'``.
    chunk : int, optional
        Cases per task; default 0, chosen by the tool.
    outdir : str or path-like, optional
        Folder for the sweep's files; default a temporary folder, removed afterwards.
    name : str, optional
        Output stem; default the deck's file stem.
    jobs : int, optional
        Worker processes; default all cores, 1 runs in this process.
    scheduler : str or dask.distributed.Client, optional
        A Dask scheduler address or client to run the cases on.
    resume : bool, default False
        Reuse the cases a previous run into ``outdir`` completed (verified, never believed).
    formats : iterable of str, default ()
        Tidy table formats of the case files: ``'csv'``, ``'parquet'``.
    plot : bool, default False
        Write the sweep's figures (PNG).
    progress : bool, default False
        Show a progress bar on the terminal.

    Returns
    -------
    SweepResult
        ``summary`` (one row per case: the swept keys, status, kept, the study's headline
        figures with units in their names; with ``outdir``, a batch sweep too large to hold
        gives a lazy :class:`~driver._outcome.StreamedSummary`), ``kept``, ``cases``, ``out``,
        ``best_case``, ``status`` (the command line's exit status) and the counts ``n_cases``,
        ``n_ok``, ``n_kept``, ``n_failed``; ``seconds`` the cases' wall time in s.

    Raises
    ------
    DeckError
        Bad input (an unknown key, a filter that is not an expression on the summary
        columns, no ``&sweep`` group and no ``grid``), before any case runs.
    ValueError
        ``jobs`` below 1 or an unknown table format.

    See Also
    --------
    run : Run one case.

    Examples
    --------
    >>> import driver
    >>> s = driver.run_sweep({"fourbar": {"fixed_link": 12, "crank": 2, "coupler": 15, "rocker": 9,
    ...                                   "step_deg": 20}}, grid={"crank": [2, 3, 4, 5]}, jobs=1)
    >>> s.n_cases, s.status, s.summary["fourbar.crank"].tolist()
    (4, 0, [2, 3, 4, 5])
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
    from driver._export import FORMATS
    if isinstance(formats, str):
        formats = [formats]
    formats = list(formats)
    bad = [f for f in formats if f not in FORMATS]
    if bad:   # checked before any case runs
        raise ValueError(f"unknown table format {bad[0]!r} (choose {', '.join(FORMATS)})")
    from driver import sweep

    with contextlib.ExitStack() as stack:
        if outdir is None:   # the tables in memory: the files go with the temporary folder
            where = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="driver_sweep_")))
        else:
            where = Path(outdir)
        outcome = sweep.run_sweep_deck(deck, where, list(formats), plot, progress, jobs=jobs, scheduler=scheduler,
                                       resume=resume, stream=outdir is not None)
    if outdir is None:   # the files were in a temporary folder, now gone
        outcome.outdir, outcome.written = None, []
    return outcome
