"""What a sweep reports: the summary frame (one row per case), the fixed-format ``.out``, the
warnings many cases repeat (printed once), and the sweep's own files written as one set."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from driver import _expr as expr
from driver._atomic import atomic_open, output_set, write_text
from driver._deck import Deck, Params
from driver._export import write_tidy
from driver._outcome import ExitCode
from driver._output import column_label
from driver._table import Column, render_table
from driver.sweep._spec import CaseResult

__all__ = ["summary_frame", "summary_settings", "sweep_text", "Warnings", "write_sweep_files", "summary_figures",
           "plotted_columns", "with_plotted"]


def summary_settings(module: Any, base: Params, swept: set[str] | None = None) -> dict[str, Any]:
    """The base deck's settings the study's summary columns depend on (``Study.summary_settings``,
    e.g. the four-bar's ``transmission_band_deg`` behind ``meets_transmission_band``), as
    {key: value}; keys in ``swept`` (swept per case, so in the table's own columns) are left out.
    The sweep's ``.out`` prints them and its Parquet summary records them in its metadata."""
    swept = swept or set()
    out: dict[str, Any] = {}
    for key in module.summary_settings if module is not None else ():
        if key in base and key not in swept:
            v = base[key]
            out[key] = [float(x) for x in v] if isinstance(v, (list, tuple)) else v
    return out


def with_settings(frame: pd.DataFrame, settings: dict[str, Any]) -> pd.DataFrame:
    """``frame`` recording ``settings`` in ``frame.attrs["summary_settings"]`` (Parquet keeps
    attrs in its schema metadata, key ``PANDAS_ATTRS``, so the table states the band its
    ``meets_transmission_band`` column was computed with).  A shallow copy: the caller's frame
    is left as it was."""
    if not settings:
        return frame
    out = frame.copy(deep=False)
    out.attrs = {**frame.attrs, "summary_settings": dict(settings)}
    return out


def summary_frame(results: list[CaseResult], names: list[str]) -> pd.DataFrame:
    """Tabulate a sweep's cases: one row per case.

    Parameters
    ----------
    results : list of CaseResult
        What the workers returned.
    names : list of str
        The swept keys, ``'group.key'``.

    Returns
    -------
    pandas.DataFrame
        Case, swept keys, status, error, kept and the study's headline figures (units in
        their names).
    """
    rows = []
    for r in results:
        row = {"case": r.index, **{n: r.values[n] for n in names},
               "status": {ExitCode.OK: "ok", ExitCode.FAILED: "failed", ExitCode.BAD_INPUT: "bad input"}[r.status],
               "kept": bool(r.kept and r.status == ExitCode.OK)}
        row.update(r.summary)
        row["error"] = r.error
        rows.append(row)
    return pd.DataFrame(rows)


def _summary_table(frame: pd.DataFrame, limit: int = 2000, n_cases: int | None = None,
                   rows: str = "all") -> list[str]:
    """Fixed-format rendering of the summary frame (kept and failed cases only above ``limit``
    cases; ``frame`` may hold only those already, then ``n_cases`` is the study's total)."""
    n_cases = len(frame) if n_cases is None else n_cases
    show = frame if n_cases <= limit else frame[frame["kept"] | (frame["status"] != "ok")]
    cols, keys = table_columns(frame)
    lines = render_table(cols, table_values(show, cols, keys))
    if len(show) < n_cases:
        lines.append(not_listed_line(n_cases - len(show), rows))
    return lines


def not_listed_line(count: int, rows: str) -> str:
    where = "are in the _summary table only" if rows == "all" else "are not listed (summary_rows = 'kept')"
    return f"  ({count} cases not kept {where})"


def table_columns(frame: pd.DataFrame) -> tuple[list[Column], list[str]]:
    """The .out table's columns of a summary frame (kind and width from each column's dtype)."""
    cols, keys = [], []
    for name in frame.columns:
        if name in ("error",):
            continue
        s = frame[name]
        if pd.api.types.is_bool_dtype(s) or len(s) == 0 or (
                s.dtype == object and s.map(lambda v: isinstance(v, (bool, np.bool_))).all()):
            cols.append(Column(name, "s", max(4, len(name)), 0))
        elif pd.api.types.is_integer_dtype(s):
            cols.append(Column(name, "i", max(5, len(name)), 0))
        elif pd.api.types.is_numeric_dtype(s):
            cols.append(Column(name, "f", max(10, len(name)), 4))
        else:
            cols.append(Column(name, "s", max(6, len(name)), 0))
        keys.append(name)
    return cols, keys


def table_values(show: pd.DataFrame, cols: list[Column], keys: list[str]) -> list[list]:
    """The .out table's rows of ``show``: values, '-' for a missing or non-finite one."""
    rows = []
    for values in zip(*(show[k].tolist() for k in keys)):   # column-wise: no Series per row
        row = []
        for c, v in zip(cols, values):
            if v is None or (isinstance(v, float) and not math.isfinite(v)):
                row.append("-")
            elif isinstance(v, (bool, np.bool_)):
                row.append("yes" if v else "no")
            elif c.kind == "s":
                row.append(str(v))
            else:
                row.append(v)
        rows.append(row)
    return rows


class Warnings:
    """The cases' warnings, counted as they arrive: a warning many cases repeat is printed once,
    with how many cases gave it and their range (not 31 identical lines for a 31-case sweep)."""

    def __init__(self) -> None:
        self.by_text: dict[str, list[int]] = {}   # text -> [count, first case, last case]

    def add(self, r: CaseResult) -> None:
        for w in dict.fromkeys(r.warnings):
            c = self.by_text.setdefault(w, [0, r.index, r.index])
            c[0] += 1
            c[1], c[2] = min(c[1], r.index), max(c[2], r.index)

    def lines(self, path: Path, n_cases: int) -> list[str]:
        """One warning text per distinct warning: the deck, the cases that gave it, the words."""
        out = []
        for w, (count, lo, hi) in self.by_text.items():
            where = (f"case {lo}" if count == 1 else
                     f"{count} cases ({lo}..{hi})" if count < n_cases else f"all {count} cases")
            out.append(f"{path}: {where}: {w}")
        return out


def write_sweep_files(outdir: Path, stem: str, table: pd.DataFrame, cases: Any, text: str,
                      plot: bool | str, sw: Params, names: list[str], module: Any, shown: pd.DataFrame,
                      settings: dict[str, Any] | None = None) -> None:
    """The sweep's own files, all renamed into place together or none: ``<stem>_summary`` tables,
    ``<stem>_cases`` tables (``cases``: a DataFrame, an (Arrow table, CSV bytes) pair, or None),
    ``<stem>.out`` and, with ``plot``, the summary figure.  ``settings`` (:func:`summary_settings`)
    go into the summary's Parquet metadata."""
    table = with_settings(table, settings or {})
    with output_set(outdir):
        for fmt in ("csv", "parquet"):
            write_tidy(table, outdir / f"{stem}_summary", fmt)
        if isinstance(cases, tuple):   # (Arrow table, its CSV): built while the cases ran
            import pyarrow.parquet as pq
            table, csv = cases
            with atomic_open(outdir / f"{stem}_cases.csv", "wb") as fh:
                fh.write(csv)
            with atomic_open(outdir / f"{stem}_cases.parquet", "wb") as fh:
                pq.write_table(table, fh)
        elif cases is not None:
            for fmt in ("csv", "parquet"):
                write_tidy(cases, outdir / f"{stem}_cases", fmt)
        write_text(outdir / f"{stem}.out", text)
        if plot:   # the summary only (the cases' own figures with case_plots = .true.)
            write_sweep_plot(outdir, stem, plot, sw, names, module, shown)


def write_sweep_plot(outdir: Path, stem: str, plot: bool | str, sw: Params, names: list[str], module: Any,
                     shown: pd.DataFrame) -> None:
    """The sweep's summary figure(s) of the rows ``shown`` (:func:`summary_figures`)."""
    from driver.plotting import save_figure
    for k, fig in enumerate(summary_figures(shown, sw, names, module, stem)):
        save_figure(fig, outdir / f"{stem}_summary{'' if k == 0 else f'_{k + 1}'}.png", plot)


def with_plotted(shown: pd.DataFrame, sw: Params) -> pd.DataFrame:
    """``shown`` with a column for each plotted expression (``plot_x``, ``plot_y``) it lacks."""
    shown = shown.copy()
    for name in [sw.plot_x, *sw.plot_y]:   # a plotted expression becomes a column
        if name and name not in shown.columns:
            shown[name] = expr.parse(name).evaluate(shown)
    return shown


def plotted_columns(shown: pd.DataFrame, sw: Params, module: Any) -> list[str]:
    """The summary columns a sweep plots: the deck's ``plot_y``, else the study's first ``sweep_plot``."""
    return [y for y in sw.plot_y if y in shown] or [c for c in module.sweep_plot if c in shown][:1]


def summary_figures(shown: pd.DataFrame, sw: Params, names: list[str], module: Any, stem: str) -> list[Any]:
    """The sweep's summary figure(s) of the rows ``shown`` (what ``--plot`` writes and the report
    page shows): maps of the plotted columns over a grid of 2-3 numeric keys, else the summary
    lines and strips (:func:`driver.plotting.sweep_summary`)."""
    from driver.plotting import is_grid, sweep_maps, sweep_summary
    shown = with_plotted(shown, sw)
    labels = {c: column_label(module, c) for c in shown.columns}
    searched = searched_values(sw, module)
    if is_grid(shown, names) and not sw.zip:   # a design space: maps over the keys, not strips
        ys = plotted_columns(shown, sw, module)
        return list(sweep_maps(shown, names, ys[:3], labels, module.sweep_best, stem, sw.summary_rows == "kept",
                               searched=searched))
    n_cases = math.prod(len(v) for v in searched.values()) if searched and not sw.zip else None
    return [sweep_summary(shown, names, sw.plot_x, sw.plot_y, stem, labels, module.sweep_plot, searched=searched,
                          n_cases=n_cases)]


def searched_values(sw: Params, module: Any) -> dict[str, np.ndarray]:
    """The values each numeric key of the sweep was searched over (its grid), for the figures:
    their axes span the searched space, not only the rows tabulated."""
    from driver.sweep._spec import grid_of
    try:
        grid = grid_of(sw, module.name, module.spec)
    except Exception:   # the figures draw without (a deck the sweep already checked; never fatal)
        return {}
    out = {}
    for name, values in zip(grid.names, grid.values):
        arr = np.asarray(values)
        if arr.dtype.kind in "fiu":
            out[name] = arr.astype(float)
    return out


def sweep_text(deck: Deck, sw: Params, base: Params, axes: list[tuple[str, list]], n_cases: int,
                frame: pd.DataFrame, n_kept: int, failed: list[tuple[int, dict, str]], rows: str) -> str:
    """The sweep's fixed-format .out: axes, counts, the summary table, failed cases."""
    lines = head_lines(deck, sw, base, axes, n_cases, n_kept, len(failed))
    lines += _summary_table(frame, n_cases=n_cases, rows=rows)
    lines += failed_lines(failed, len(failed))
    return "\n".join(lines) + "\n"


def head_lines(deck: Deck, sw: Params, base: Params, axes: list[tuple[str, list]], n_cases: int,
               n_kept: int, n_failed: int) -> list[str]:
    """The .out's lines before the summary table: axes, settings, counts."""
    lines = [f"  sweep over &{base.group} from deck {deck.path}", ""]
    for name, values in axes:
        vals = list(dict.fromkeys(values))   # deck order
        fmt = lambda v: v if isinstance(v, str) else f"{v:.6g}"
        shown = (", ".join(map(fmt, vals[:8])) if len(vals) <= 8 else
                 f"{fmt(vals[0])}, {fmt(vals[1])}, ..., {fmt(vals[-1])} ({len(vals)} values)")
        lines.append(f"    {name:<28} {shown}")
    from driver._study import load_study  # settings of the base deck the summary columns depend on
    swept = {name.partition(".")[2] for name, _ in axes}
    for key, v in summary_settings(load_study(base.group), base, swept).items():
        lines.append(f"    {key:<28} " + (", ".join(f"{x:g}" for x in v) if isinstance(v, (list, tuple)) else f"{v}")
                     + "   (base deck; used by the summary columns)")
    lines += [f"    {'cases':<28} {n_cases} ({'zipped' if sw.zip else 'full grid'})",
              f"    {'case outputs':<28} {sw.case_outputs}" + (f"   keep: {sw.keep}" if sw.keep else ""),
              f"    {'kept':<28} {n_kept}",
              f"    {'failed':<28} {n_failed}", ""]
    return lines


#: the .out lists at most this many failed cases (all are in the _summary table's status column)
FAILED_LISTED = 1000


def failed_lines(failed: list[tuple[int, dict, str]], n_failed: int) -> list[str]:
    """The .out's lines after the table: the first :data:`FAILED_LISTED` of ``n_failed`` failed
    cases (``failed``: at least those, in case order)."""
    if not n_failed:
        return []
    lines = ["", "  Failed cases"]
    for index, values, error in failed[:FAILED_LISTED]:
        vals = ", ".join(f"{k} = {v!r}" for k, v in values.items())
        lines.append(f"    case {index} ({vals}): {error}")
    if n_failed > FAILED_LISTED:
        lines.append(f"    ... and {n_failed - FAILED_LISTED} more (status column of the _summary table)")
    return lines
