"""The comparison of a run with the published record, cell by cell.

:func:`compare` runs a deck (in memory; nothing is written) and puts every published cell that
belongs to the deck's study and values (``published/``, read by :mod:`driver._published`) beside
the value the run computes, as a DataFrame with one row per published cell:

========  ===========================================================================
deck      the deck file
table     the published table, e.g. ``Lampiran 3 (crank 5)``, ``Table 4.8``
row       the published row label (crank angle, row number, design name, item)
column    the published column
printed   the value as printed (text)
computed  the run's value at the printed precision (text; empty when it has none)
status    ``identical`` (same text), ``agrees`` (within half a unit of the last printed
          digit, or the stated tolerance), ``not reproducible`` (a printed value known
          not to follow from the paper's own data and formulas), ``departs`` (the deck
          asks for the correct answer and the published one is wrong, for the reason
          given) or ``differs`` (a reproducible cell that does not agree: a defect)
reason    why a cell is not ``identical``/``agrees``, or why a reproduced printed value is
          wrong anyway (errata)
========  ===========================================================================

:func:`compare_text` renders the per-table agreement lines and every cell that does not agree,
as ``python -m driver --compare DECK...`` prints them; :func:`compare_decks` compares several decks
and returns a :class:`CompareOutcome` (the command line prints it).  Each study compares its own tables (its
``published.py``, declared as ``Study.published``; the cell primitives are in
:mod:`driver._published`); this module runs the deck and reports.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from driver import _published as published
from driver._deck import Params
from driver._outcome import ExitCode, Outcome
from driver._published import agrees_printed
from driver._pydeck import DeckSource, source_deck
from driver._result import Result
from driver._runner import study_of
from driver._study import load_study

__all__ = ["COLUMNS", "OK", "Comparison", "CompareOutcome", "agrees_printed", "compare", "compare_decks",
           "compare_result", "compare_text", "run_comparison", "totals_text"]

COLUMNS = ["deck", "table", "row", "column", "printed", "computed", "status", "reason"]
#: statuses that count as agreement (exit status 0)
OK = ("identical", "agrees", "not reproducible", "departs")


class _LazyResult:
    """The deck's :class:`Result`, computed on first use (a comparison of inputs needs no run)."""

    def __init__(self, run: Callable[[], Result]):
        self._run = run
        self._result: Result | None = None

    def __getattr__(self, name: str) -> Any:
        if self._result is None:
            self._result = self._run()
        return getattr(self._result, name)


class Comparison:
    """The comparison of one deck: ``frame`` (one row per published cell) and the run's result."""

    def __init__(self, deck: Path, group: str, frame: pd.DataFrame, params: Params | None, note: str = ""):
        self.deck, self.group, self.frame, self.params, self.note = deck, group, frame, params, note

    @property
    def variant(self) -> str:
        """The deck's mode or method (``mode = 'report'``), or '' for a study without one."""
        for key in ("mode", "method"):
            if self.params is not None and key in self.params:
                return f"{key} = '{self.params[key]}'"
        return ""

    @property
    def ok(self) -> bool:
        """Every reproducible cell agrees (no ``differs``)."""
        return not (self.frame["status"] == "differs").any()


def run_comparison(deck: DeckSource) -> Comparison:
    """Run ``deck`` (any :data:`~driver._pydeck.DeckSource`) in memory and compare it with its
    published tables (DeckError for bad input, TypeError for a source of another type)."""
    d = source_deck(deck)
    path = Path(d.path)
    from driver._runner import CONTROL_GROUPS
    for control in CONTROL_GROUPS:
        if control in d.groups:
            frame = pd.DataFrame(columns=COLUMNS)
            return Comparison(path, control, frame, None,
                              note=f"a &{control} deck runs the study over many cases or designs; the published tables "
                                   "belong to single-case decks (compare a case deck it writes instead)")
    study, params = study_of(d)
    group = study.name
    rows: list[dict] = []
    if study.published is not None:
        # the run is made only if a published comparison reads it: _LazyResult stands in for the
        # Result attribute by attribute, which Study.published's signature (a Result) cannot say
        rows = study.published(params, _LazyResult(lambda: study.run(params)))  # type: ignore[arg-type]
    frame = pd.DataFrame.from_records(rows, columns=COLUMNS[1:])
    frame.insert(0, "deck", str(path))
    return Comparison(path, group, frame, params)


def compare_result(deck: str | Path, params: Params, result: Result) -> pd.DataFrame:
    """The comparison of a run already made (``params`` validated, ``result`` computed from
    them) with the published record: the frame of :func:`compare`, without running again."""
    study = load_study(params.group)
    rows = study.published(params, result) if study is not None and study.published is not None else []
    frame = pd.DataFrame.from_records(rows, columns=COLUMNS[1:])
    frame.insert(0, "deck", str(deck))
    return frame


def compare(deck: DeckSource) -> pd.DataFrame:
    """Compare a deck's run with the published record, cell by cell.

    Parameters
    ----------
    deck : str, path-like or dict
        The deck to run, as every entry point takes one (``driver.DeckSource``): its file (one of
        the shipped decks whose case is in ``published/``, or any deck: a deck no published
        table belongs to gives an empty frame), its text, or a dict of groups.

    Returns
    -------
    pandas.DataFrame
        One row per published cell, columns :data:`COLUMNS`: ``deck``, ``table``, ``row``,
        ``column``, ``printed`` (the published text), ``computed`` (the run's value, in the
        table's own unit), ``status`` (``identical``, ``agrees``, ``departs`` with a reason,
        or ``differs``: a defect) and ``reason``.

    Raises
    ------
    DeckError
        The deck has bad input (or its file cannot be read).
    TypeError
        ``deck`` is not a deck source.

    Examples
    --------
    >>> import driver
    >>> frame = driver.compare("inputs/crank5.dat")   # doctest: +SKIP
    >>> frame["status"].value_counts()                # doctest: +SKIP
    """
    return run_comparison(deck).frame


def compare_text(cmp: Comparison) -> list[str]:
    """Terminal lines: one agreement line per published table, then every cell that is not
    ``identical``/``agrees`` with its printed and computed values and reason."""
    f = cmp.frame
    lines = [f"{cmp.deck}: &{cmp.group}"]
    if cmp.note:
        return lines + [f"  {cmp.note}"]
    if f.empty:
        lines.append("  no published table belongs to this deck (its study or values are not in published/)")
        return lines
    for table, t in f.groupby("table", sort=False):
        lines.append("  " + _table_line(str(table), t))
    odd = f[~f["status"].isin(["identical", "agrees"])]
    if not odd.empty:
        w = max(len(s) for s in odd["table"])
        for (status, reason), g in odd.groupby(["status", "reason"], sort=False):
            verb = {"departs": "depart", "differs": "differ"}.get(str(status), status) if len(g) > 1 else status
            lines.append(f"  {len(g)} cell{'s' if len(g) > 1 else ''} {verb}" + (f": {reason}" if reason else ""))
            lines.append(f"    {'table':<{w}}  {'row':>5}  {'column':<8} {'printed':>10} {'computed':>10}")
            for r in g.itertuples():
                # every cell is text (driver._published.cell); pandas cannot know it, hence !s
                lines.append(f"    {r.table!s:<{w}}  {r.row!s:>5}  {r.column!s:<8} {r.printed!s:>10} {r.computed or '-'!s:>10}")
    errata = f[(f["status"].isin(["identical", "agrees"])) & f["reason"].str.startswith("erratum")]
    if not errata.empty:
        lines.append(f"  {len(errata)} of the reproduced printed cells are wrong (errata): a deck asking for the "
                     "correct answer lists them with the reason")
    return lines


def totals_text(comparisons: list[Comparison]) -> list[str]:
    """One total line per study over several decks."""
    lines = []
    by_group: dict[tuple[str, str], list[pd.DataFrame]] = {}
    for c in comparisons:
        if not c.frame.empty:
            by_group.setdefault((c.group, c.variant), []).append(c.frame)
    for (group, variant), frames in by_group.items():
        f = pd.concat(frames, ignore_index=True)
        what = f"&{group}" + (f" {variant}" if variant else "")
        lines.append(f"  {what} ({len(frames)} deck{'s' if len(frames) > 1 else ''}): "
                     + _table_line("", f).lstrip(": "))
    return lines


@dataclass(kw_only=True)
class CompareOutcome(Outcome):
    """A comparison of decks with the published record (:func:`compare_decks`).

    Attributes
    ----------
    comparisons : list of Comparison
        The decks compared, in order (:class:`Comparison`: one row per
        published cell, ``ok`` when no reproducible cell differs).
    totals : list of str
        One line per study (and mode or method) over the decks compared, as the command line
        prints them under "Total"; empty when fewer than two decks were compared.
    bad_input : bool
        A deck had bad input (its error is in ``messages``).
    failed : bool
        A run failed or the published tables are missing (the error is in ``messages``).
    """

    comparisons: list[Comparison] = field(default_factory=list)
    totals: list[str] = field(default_factory=list)
    bad_input: bool = False
    failed: bool = False

    @property
    def exit_code(self) -> ExitCode:
        """0 every reproducible cell agrees, 1 a cell differs or a run failed, 2 a deck had bad input."""
        differs = self.failed or not all(c.ok for c in self.comparisons)
        worst = ExitCode.BAD_INPUT if self.bad_input else ExitCode.FAILED if differs else ExitCode.OK
        return max(super().exit_code, worst)


def compare_decks(decks: list[Path], on_deck: Callable[[CompareOutcome], None] | None = None) -> CompareOutcome:
    """Compare every deck with the published record; nothing is printed or written.

    Returns a :class:`CompareOutcome`: the comparisons, the totals over the decks,
    an error message per deck that had bad input (exit status 2) or whose run failed (1), and exit
    status 1 when a reproducible cell differs.  ``on_deck`` (e.g. the command line's printer) gets
    each part as soon as it is known: each deck's own outcome, or the error that the published
    tables are missing; the totals are the returned outcome's alone."""
    from driver._deck import DeckError
    whole = CompareOutcome()
    if not published.PUBLISHED_DIR.is_dir():
        whole.error(f"the published tables are not installed ({published.PUBLISHED_DIR} is missing); "
                    "the install is incomplete: reinstall it (pip install --force-reinstall PATH-TO-THE-SOURCE-OR-WHEEL; "
                    "in a clone: bash .ci/setup)")
        whole.failed = True
        if on_deck is not None:
            on_deck(whole)
        return whole
    for deck in decks:
        part = CompareOutcome()
        try:
            part.comparisons.append(run_comparison(deck))
        except DeckError as exc:
            part.error(str(exc))
            part.bad_input = True
        except Exception as exc:  # a run failure: say so plainly
            part.error(f"{deck}: run failed: {exc.__class__.__name__}: {exc}")
            part.failed = True
        if on_deck is not None:
            on_deck(part)
        whole.comparisons += part.comparisons
        whole.messages += part.messages
        whole.bad_input |= part.bad_input
        whole.failed |= part.failed
    done = whole.comparisons
    if len(done) > 1:
        whole.totals = totals_text(done) or [
            f"  no published cells among these {len(done)} decks (sweep, optimisation and synthesis decks "
            "have none: compare the single-case decks a sweep writes instead)"]
    return whole


def _table_line(table: str, t: pd.DataFrame) -> str:
    counts = t["status"].value_counts()
    n = len(t)
    same = int(counts.get("identical", 0))
    ok = same + int(counts.get("agrees", 0))
    nr = int(counts.get("not reproducible", 0))
    reproducible = n - nr
    if same == n:
        text = f"{table}: {n}/{n} cells identical"
    elif reproducible == 0:
        text = f"{table}: no reproducible cells"
    elif ok == reproducible and not nr:
        text = f"{table}: {ok}/{n} cells agree" + (f" ({same} identical)" if same else "")
    else:
        text = f"{table}: {ok}/{reproducible} reproducible cells agree"
        if same and same != ok:
            text += f" ({same} identical)"
    extra = []
    if nr:
        extra.append(f"{nr} not reproducible (flagged)")
    if counts.get("departs", 0):
        nd = int(counts["departs"])
        extra.append(f"{nd} depart{'s' if nd == 1 else ''} from the published values (the deck asks for the correct answer)")
    if counts.get("differs", 0):
        extra.append(f"{int(counts['differs'])} DIFFER")
    return text + ("; " + "; ".join(extra) if extra else "")
