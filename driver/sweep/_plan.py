"""Everything a sweep decides before any case runs: the plan.

:func:`plan_sweep` validates the ``&sweep`` group and the base deck (bad input: DeckError, nothing
written), checks the filter and the plotted columns on the base deck's summary, names every
file the sweep will write, and chooses how the cases run:

* **the batch path** (:class:`~driver.sweep._chunks.BatchPlan`) when the study has one, every
  swept key is one its batch takes and no case needs its own files before the filter has run
  (``case_outputs`` 'none', or 'kept': the kept cases then get their files case by case);
  bad values are found without validating every case (each value of a key whose checks stand
  alone once, every combination of the others once);
* else **case by case** (:class:`~driver.sweep._chunks.CaseTask`): every case a complete deck,
  validated and run exactly as a single run.

**The chunk policy** (:func:`chunk_size`), one for both kinds of chunk: the cases per chunk are
a function of the number of cases (and the deck's ``chunk``) only, never of the workers or the
scheduler, because each chunk is one part of the resume record (:mod:`driver.sweep._resume`)
and ``--resume`` must find the same parts with any ``-j`` or on Dask.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from driver import _expr as expr
from driver._deck import Deck, DeckError, Params, RawGroup, validate
from driver._extras import require
from driver._runner import compute, output_stem, study_of
from driver.sweep._chunks import BatchPlan, CaseTask
from driver.sweep._keep import check_keep, keep_columns
from driver.sweep._report import summary_settings
from driver.sweep._resume import Layout, case_signature, layout_for, signature
from driver.sweep._spec import MAX_CASES, SPEC, Grid, checked_key, deck_key, grid_of, set_swept, split_key, validate_sweep

__all__ = ["SweepPlan", "plan_sweep", "chunk_size", "batchable", "batch_plan", "batch_signature", "wanted_columns",
           "BATCH_MAX_CASES", "MAX_CHUNKS", "SMALL_SWEEP", "CHUNK", "MIN_CHUNKS"]

#: largest batch sweep (no case is listed, so only the grid's size is limited)
BATCH_MAX_CASES = 10**10
#: a record has at most this many parts: above, chunks grow instead of multiplying (the driver's
#: work, a result to merge and a part in the record, is per chunk: 10^9 cases are 4096 chunks)
MAX_CHUNKS = 4096
#: largest number of cases per batch chunk below MAX_CHUNKS chunks: 0.05 s of four-bar kernel
#: time on one core for the filter's passes, 0.2 s with the peak speeds
CHUNK = 65536
#: chunks of a batch sweep below CHUNK * 8 cases (at least 64 cases each)
MIN_CHUNKS = 8
#: per kind of chunk: (fewest cases per chunk, most below MAX_CHUNKS chunks, chunks wanted).
#: A batch chunk is one kernel call (cheap per case: few, large chunks); a per-case chunk runs
#: whole decks and writes their files (dear per case: many small chunks, for balance and so
#: that an interrupt loses little)
CHUNK_RULES = {"batch": (64, CHUNK, MIN_CHUNKS), "cases": (1, 64, 128)}
#: a batch sweep of at most this many cases may run in the driver's process when it is cheap
#: (:func:`driver.sweep._executor.execute`): a crash in a kernel then ends the driver, so only small ones
SMALL_SWEEP = 1 << 18
#: largest number of combinations of coupled swept keys validated one by one
MAX_COMBOS = 20000


def chunk_size(n: int, kind: str, given: int = 0) -> int:
    """Choose the cases per chunk of a sweep of ``n`` cases.

    The deck's ``chunk`` when it gives one, else a function of ``n`` and the kind of chunk only
    (never of the workers: the chunks are the parts of the resume record, which ``--resume``
    finds again with any ``-j`` or scheduler).

    Parameters
    ----------
    n : int
        Cases of the sweep (or of its kept cases' files).
    kind : {'batch', 'cases'}
        The chunk function: batch rows, or per-case runs.
    given : int, default 0
        The deck's ``chunk`` (0: chosen here).

    Returns
    -------
    int
        Cases per chunk, at least 1; at most :data:`MAX_CHUNKS` chunks unless ``given``.

    Examples
    --------
    >>> from driver.sweep._plan import chunk_size
    >>> chunk_size(102_400, "batch"), chunk_size(10**9, "batch"), chunk_size(900, "cases"), chunk_size(18, "cases")
    (12800, 244141, 8, 1)
    """
    if given:
        return given
    lo, hi, wanted = CHUNK_RULES[kind]
    return max(min(hi, max(lo, -(-n // wanted))), -(-n // MAX_CHUNKS), 1)


@dataclass
class SweepPlan:
    """A sweep decided: its deck, study, grid, files and the work of its chunks."""

    deck: Deck
    sw: Params                      #: the validated &sweep group
    module: Any                     #: the study (:class:`driver._study.Study`)
    base: Params                    #: the validated base deck
    grid: Grid
    outdir: Path
    stem: str
    layout: Layout                  #: where the cases write their files
    plot: bool | str
    plotted: list[str]              #: plot_x / plot_y expressions
    shown_columns: list[str] | None  #: summary_columns given: the columns the tables show
    estimates: dict[int, float]     #: case -> estimated work [s] (the longest chunks start first)
    cases: CaseTask                 #: the per-case chunk's work (every case, or the kept ones' files)
    batch: BatchPlan | None         #: the batch chunk's work, when the sweep takes the batch path
    chunk: int                      #: cases per chunk of the sweep's record
    settings: dict[str, Any]        #: the base deck's settings the summary columns depend on
    best: bool = False              #: also run the best kept case for the outcome (``--report``)
    stream: bool = True             #: large batch tables written part by part, not held

    @property
    def n(self) -> int:
        return self.grid.n

    @property
    def names(self) -> list[str]:
        return self.grid.names

    @property
    def axes(self) -> list[tuple[str, list]]:
        return list(zip(self.grid.names, self.grid.values))

    @property
    def record(self) -> Path:
        """The resume record's folder."""
        return self.outdir / f"{self.stem}.sweep"


def plan_sweep(deck: Deck, outdir: Path, formats: list[str], plot: bool | str, *, scheduler: Any = None,
               best: bool = False, stream: bool = True) -> SweepPlan:
    """Plan the sweep of ``deck`` (a study group and a ``&sweep`` group) into ``outdir``;
    DeckError for bad input (nothing is written), MissingExtra for a missing package."""
    sw = validate(deck.groups["sweep"], SPEC, deck.path)
    require("parquet")
    if scheduler:
        require("dask")
    study_raw = {n: g for n, g in deck.groups.items() if n != "sweep"}
    module, base = study_of(Deck(deck.path, study_raw))   # the base deck must be valid on its own
    raw = study_raw[base.group]
    grid = grid_of(sw, base.group, module.spec)
    may_batch = batchable(module, grid.names, sw.keep, sw.case_outputs)
    _refuse_size(sw, grid, BATCH_MAX_CASES if may_batch else MAX_CASES)
    checked: set[tuple] = set()   # the values validate_sweep found good: batch_plan does not check them again
    estimates = validate_sweep(sw, raw, module, grid, checked)
    plotted = [v for v in [sw.plot_x, *sw.plot_y] if v]
    shown = _check_columns(sw, module, base, grid, plotted)
    # every name the sweep gives its files and folders, known before it runs (the longest counts)
    stem_path = output_stem(outdir, deck.path, (".out", ".sweep", "_summary.csv", "_summary.parquet", "_cases.csv",
                                                "_cases.parquet", *(("_summary.png",) if plot else ())))
    layout = layout_for(stem_path, grid.n)
    case_plot = plot if sw.case_plots else False
    cases = CaseTask(str(deck.path), raw, grid, layout, sw.keep, sw.case_outputs, formats, case_plot, _base_hash(raw),
                     case_signature(raw, grid.names, str(deck.path), sw.keep, sw.case_outputs, formats, case_plot,
                                    module))
    bplan = batch_plan(module, raw, str(deck.path), grid, sw.keep, sw.summary_rows, plotted, shown,
                       checked) if may_batch else None
    if bplan is None:
        _refuse_size(sw, grid, MAX_CASES)
    settings = summary_settings(module, base, {name.partition(".")[2] for name in grid.names})
    return SweepPlan(deck, sw, module, base, grid, Path(outdir), stem_path.name, layout, plot, plotted, shown,
                     estimates, cases, bplan, chunk_size(grid.n, "cases" if bplan is None else "batch", sw.chunk),
                     settings, best, stream)


def _refuse_size(sw: Params, grid: Grid, limit: int) -> None:
    if grid.n > limit:
        sizes = " x ".join(f"{len(v)} ({n})" for n, v in zip(grid.names, grid.values))
        raise sw.error("key1", f"{grid.n} cases ({sizes}) is beyond the {limit} cases one sweep deck "
                       "may have; split the sweep into several decks or coarsen the grid")


def _check_columns(sw: Params, module: Any, base: Params, grid: Grid, plotted: list[str]) -> list[str] | None:
    """Check the filter and the plotted columns on the base deck's summary before any case
    runs; returns the columns the tables show (summary_columns given), else None."""
    named = [("keep", sw.keep)] * bool(sw.keep) + [("plot_x", sw.plot_x)] * bool(sw.plot_x) + \
        [("plot_y", y) for y in sw.plot_y if y]
    if not (named or sw.summary_columns):
        return None
    probe = module.summarise(base) if module.summarise is not None else compute(module, base).summary
    columns = [*grid.names, *probe, "case"]
    kinds = {**expr.kinds_of({n: v[0] for n, v in zip(grid.names, grid.values) if len(v)}), **expr.kinds_of(probe),
             "case": "number"}
    for key, text in named:
        try:   # an old column name is answered with its new one (Study.renamed)
            refusal = module.renamed_in(sorted(expr.parse(text).names))
        except expr.ExprError:
            refusal = None
        if refusal:
            raise sw.error(key, refusal)
        try:
            if key == "keep":
                check_keep(text, columns, kinds)   # one number or logical per case, before any case runs
                continue
            e = expr.parse(text, columns)
            if text.strip() not in columns:   # a plotted column may hold text
                e.check_kinds(kinds)
            if not e.names:
                raise expr.ExprError("reads no column: a plot shows a column or an expression of columns", text[:60])
        except expr.ExprError as exc:
            raise sw.error(key, f"{exc.message}" + (f" (at '{exc.token}')" if exc.token else "")
                           + ("" if key == "keep" else f"; summary columns: {', '.join(columns)}")) from None
    if not sw.summary_columns:
        return None
    refusal = module.renamed_in(sw.summary_columns)
    if refusal:
        raise sw.error("summary_columns", refusal)
    unknown = [c for c in sw.summary_columns if c not in probe]
    if unknown:
        raise sw.error("summary_columns", f"'{unknown[0]}' is not a summary column of &{base.group} "
                       f"(summary columns: {', '.join(probe)})")
    # what the tables show: the columns asked for, and those the filter and the plot read
    read = {n for text in plotted for n in expr.parse(text, columns).names} | keep_columns(sw.keep)
    return [c for c in probe if c in set(sw.summary_columns) | read]


def _base_hash(raw: RawGroup) -> str:
    text = json.dumps(raw.values, sort_keys=True, default=str)
    return hashlib.sha256(f"{raw.name}:{text}".encode()).hexdigest()[:16]


# ----------------------------------------------------------------------------- the batch path

def batchable(module: Any, names: list[str], keep: str, case_outputs: str) -> bool:
    """Whether a sweep over ``names`` ('group.key', or 'group.key(i)': one element) can take the
    study's batch path: every key one the batch accepts, every element one of a key it names in
    ``elements``."""
    if module.batch is None or case_outputs == "all" or (case_outputs == "kept" and not keep):
        return False
    return all(split_key(n)[0] in module.batch.accepted
               and (split_key(n)[1] is None or split_key(n)[0] in module.batch.elements) for n in names)


def batch_signature(raw: RawGroup, grid: Grid, keep: str, rows: str, module: Any,
                    shown: list[str] | None = None) -> str:
    """The batch record's signature: :func:`driver.sweep._resume.signature` of what the rows depend on."""
    return signature(["batch", raw.name, raw.values, grid.names, grid.values, grid.zipped, keep, rows]
                     + ([shown] if shown is not None else []), module)


def wanted_columns(module: Any, keep: str, plotted: list[str], shown: list[str] | None
                   ) -> tuple[list[str] | None, list[str] | None]:
    """(columns every case needs, columns the shown rows need) of the study's batch summary,
    from its column -> pass table (``Study.batch.passes``): the filter's columns for every case; the
    shown rows also the plotted ones and ``shown`` (summary_columns; None: every column).
    (None, None) when the study declares no table (everything is computed)."""
    table = module.batch.passes if module.batch is not None else None
    if table is None:
        return None, None

    def names(text: str) -> set[str]:   # summary columns a plotted expression reads (as the filter's)
        return {n for n in expr.parse(text).names if "." not in n and n != "case"} if text else set()

    order = lambda cols: [c for c in table if c in cols] + sorted(c for c in cols if c not in table)
    filt = order(keep_columns(keep))
    if shown is None:
        return filt, None
    return filt, order(set(filt).union(*(names(t) for t in plotted)) | set(shown))


def _swap(raw: RawGroup, values: dict[str, Any]) -> RawGroup:
    v = dict(raw.values)
    for name, x in values.items():
        set_swept(v, name, x.item() if hasattr(x, "item") else x)
    return RawGroup(raw.name, v, raw.lines, raw.line)


def batch_plan(module: Any, raw: RawGroup, deck_path: str, grid: Grid, keep: str, rows: str,
               plotted: list[str] | None = None, shown: list[str] | None = None,
               checked: set[tuple] | None = None) -> BatchPlan | None:
    """The batch chunk's work for this sweep (see :func:`batchable`), or None when it must run
    case by case.  ``plotted``: the plot_x/plot_y expressions; ``shown``: summary_columns (None: all).
    Each value of an independent axis and each combination of the coupled axes' values is
    validated; bad ones become bad-input rows.  ``checked``: the keys
    (:func:`driver.sweep._spec.checked_key`) of the values validate_sweep already found good,
    not validated again (each costs a deck validation: 2 000 of them on a 1000 x 1000 sweep)."""
    done = checked or set()
    applies = module.batch.applies   # e.g. not for a base deck that optimises per case
    if applies is not None and not applies(validate(raw, module.spec, deck_path)):
        return None
    keys = [deck_key(n) for n in grid.names]
    independent = set(module.batch.independent)
    single: dict[str, dict[int, str]] = {}
    coupled = [i for i, k in enumerate(keys) if k not in independent]
    for i, (name, vals) in enumerate(zip(grid.names, grid.values)):
        if i in coupled:
            continue
        errs = {}
        for j, v in enumerate(vals):
            if checked_key({name: v}) in done:
                continue
            try:
                validate(_swap(raw, {name: v}), module.spec, deck_path)
            except DeckError as exc:
                errs[j] = str(exc)
        single[name] = errs
    coupled_errors: dict[tuple, str] = {}
    if coupled:
        if grid.zipped:
            combos = [tuple([j] * len(coupled)) for j in range(grid.n)]
        else:
            if math.prod(len(grid.values[i]) for i in coupled) > MAX_COMBOS:
                return None
            combos = list(itertools.product(*(range(len(grid.values[i])) for i in coupled)))
        if len(combos) > MAX_COMBOS:
            return None
        for combo in dict.fromkeys(combos):
            combo_values = {grid.names[i]: grid.values[i][j] for i, j in zip(coupled, combo)}
            if checked_key(combo_values) in done:
                continue
            try:
                validate(_swap(raw, combo_values), module.spec, deck_path)
            except DeckError as exc:
                coupled_errors[combo] = str(exc)
    p = BatchPlan(deck_path, raw, grid, keep, rows, single, coupled, coupled_errors)
    p.filter_columns, p.shown_columns = wanted_columns(module, keep, plotted or [], shown)
    p.signature = batch_signature(raw, grid, keep, rows, module, p.shown_columns)
    return p
