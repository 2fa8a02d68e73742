"""What a sweep reports: the summary frame (one row per case), the fixed-format ``.out``, the
warnings many cases repeat (printed once), the ``_cases`` tables, and the sweep's own files
written as one set, from rows in memory (:func:`write_sweep_files`) or streamed from the
record's parts (:func:`write_streamed`).

**Streamed tables.**  A batch sweep's rows (with ``summary_rows = 'kept'`` its kept and failed
cases) are in the parts of its resume record, one Parquet file per chunk, in case order.  Above
:data:`driver.sweep._executor.STREAM_ROWS` rows the driver stops holding them and
:func:`write_streamed` writes the ``.out``, the ``_summary`` CSV and the ``_summary`` Parquet file
reading one part at a time, so the driver's memory does not grow with the rows.  The files are
those the in-memory path writes: the same ``.out`` and CSV bytes, the same Parquet table (in one
row group per part); the ``.out`` table's column widths, which the widest cell decides, are
taken in a first pass that writes the body to a scratch file (the case column at the width of
the last case number) and only redone when a cell did not fit.  Parts whose columns differ in
type (bad-input rows turn a chunk's summary columns into objects) cannot be streamed this way;
:func:`write_streamed` then returns None and the caller reads the rows into memory.
"""
from __future__ import annotations

import json
import math
import shutil
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from driver import _expr as expr
from driver._atomic import atomic_open, output_set, write_text
from driver._deck import Deck, Params
from driver._export import write_tidy
from driver._outcome import ExitCode
from driver._output import column_label
from driver._table import Column, fixed_cells, render_block, render_text
from driver.sweep._spec import CaseResult

if TYPE_CHECKING:   # annotations only: pyarrow is imported where a table is read or written
    import pyarrow as pa

__all__ = ["summary_frame", "summary_settings", "sweep_text", "Warnings", "write_sweep_files", "write_streamed",
           "read_columns", "Streamed", "CasesTable", "TABLE_ALL_MAX", "CASES_TABLE_MAX", "CASES_TABLE_BYTES",
           "summary_figures", "plotted_columns", "with_plotted", "best_words"]

#: the sweep's .out lists every case up to this many cases (above: the kept and failed ones)
TABLE_ALL_MAX = 2000
#: the combined ``<stem>_cases`` tables are written up to this many written cases (above, the
#: cases' own Parquet files are the table: ``pyarrow.dataset.dataset(<stem>/, format="parquet")``)
CASES_TABLE_MAX = 2000
#: ... and up to this many bytes of them in the driver's memory
CASES_TABLE_BYTES = 256 * 2**20


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


def _summary_table(frame: pd.DataFrame, limit: int = TABLE_ALL_MAX, n_cases: int | None = None,
                   rows: str = "all") -> list[str]:
    """Fixed-format rendering of the summary frame (kept and failed cases only above ``limit``
    cases; ``frame`` may hold only those already, then ``n_cases`` is the study's total)."""
    n_cases = len(frame) if n_cases is None else n_cases
    show = frame if n_cases <= limit else frame[frame["kept"] | (frame["status"] != "ok")]
    cols, keys = table_columns(frame)
    cells = table_cells(show, cols, keys)
    widths = [max(c.width, len(c.header), n) for c, n in zip(cols, cell_widths(cells))]
    for c, w in zip(cols, widths):
        c.widened = w > c.width
    lines = ["".join(" " * c.sep + c.header.rjust(w) for c, w in zip(cols, widths)).rstrip()]
    lines += render_block(cols, cells, widths)
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


def table_cells(show: pd.DataFrame, cols: list[Column], keys: list[str]) -> list[np.ndarray]:
    """The .out table's cells of ``show``, column by column, each an array of str: '-' for a
    missing or non-finite value, yes/no for a truth value, the column's edit for a number, the
    text of anything else -- the cells ``Column.cell`` gives value by value.  The numbers of all
    columns with the same edit go through one :func:`driver._table.fixed_cells` call (a part of
    a streamed sweep has a few hundred rows: per-call costs would dominate column by column)."""
    out: list[Any] = [None] * len(cols)
    numbers: dict[tuple[int, str], list[tuple[int, np.ndarray]]] = {}
    for j, (c, k) in enumerate(zip(cols, keys)):
        s = show[k]
        arr = s.to_numpy() if isinstance(s.dtype, np.dtype) else None
        if arr is not None and arr.dtype.kind == "b":
            out[j] = np.where(arr, "yes", "no")
        elif arr is not None and arr.dtype.kind == "f" and c.kind == "f":
            numbers.setdefault((c.decimals, c.style), []).append((j, arr))
        elif arr is not None and arr.dtype.kind in "iu" and c.kind in "is":
            out[j] = arr.astype(str)
        elif c.kind == "s" and isinstance(s.dtype, pd.StringDtype) and s.dtype.na_value is np.nan:
            out[j] = np.asarray(s.to_numpy(dtype=object, na_value="-"), dtype=str)   # text; missing: '-'
        else:   # objects (text, or values of mixed kinds): value by value
            out[j] = np.array([_cell(c, v) for v in s.tolist()], dtype=str)
    for (decimals, style), group in numbers.items():
        values = np.concatenate([arr for _, arr in group])
        finite = np.isfinite(values)
        cells = fixed_cells(values[finite], decimals, style)
        if not finite.all():
            text = np.full(len(values), "-", dtype=object)
            text[finite] = cells
            cells = text.astype(str)
        at = 0
        for j, arr in group:
            out[j] = cells[at:at + len(arr)]
            at += len(arr)
    return out


def cell_widths(cells: list[np.ndarray]) -> list[int]:
    """The longest text of each column's cells (0 for none)."""
    return [int(np.strings.str_len(cj).max()) if len(cj) else 0 for cj in cells]


def _cell(c: Column, v: Any) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    return str(v) if c.kind == "s" else c.cell(v)


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


def best_words(module: Any, metric: str | None) -> str:
    """Why a sweep's best case (:attr:`~driver._outcome.SweepOutcome.best_case`) is the best, in
    words: ``'largest minimum transmission angle'`` by its ``best_metric``, or ``'the first
    kept case'`` (None)."""
    if metric is None:
        return "the first kept case"
    sense = module.sweep_best.get(metric) if module is not None else None
    return ("largest " if sense == "max" else "smallest ") + column_label(module, metric).split(" [")[0]


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


#: a streamed sweep's CSV and .out are written in blocks of whole parts of at least this many
#: rows (the last block: what remains); the driver holds one block (4096 rows of the shipped
#: search: about 18 MiB more than a part at a time, and about 1.5x less CPU per row than that)
STREAM_BLOCK_ROWS = 4096

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


# ----------------------------------------------------------------------------- tables streamed from the record

class Streamed:
    """What the caller needs after a streamed write: the failed cases (the first
    :data:`FAILED_LISTED`, in case order), their count, and whether any was bad input."""

    def __init__(self) -> None:
        self.failed: list[tuple[int, dict, str]] = []
        self.n_failed = 0
        self.bad_input = False
        self.n_kept = 0
        self.n_rows = 0
        #: the summary table's schema metadata (pandas columns, attrs), as written
        self.metadata: dict[bytes, bytes] = {}


def _origins(schema: pa.Schema) -> dict[str, str]:
    """Column -> the pandas dtype it was written from (an object column of numbers is 'object')."""
    meta = schema.pandas_metadata or {}
    return {c["name"]: c["numpy_type"] for c in meta.get("columns", []) if c.get("name") is not None}


def _uniform(paths: list[Path]) -> pa.Schema | None:
    """The parts' common schema (without the record's metadata), or None when the parts' columns
    differ in name, type or the dtype they were written from."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    first = pq.read_schema(paths[0])
    for p in paths[1:]:
        s = pq.read_schema(p)
        if not s.equals(first, check_metadata=False) or _origins(s) != _origins(first):
            return None
    origins = _origins(first)
    for f in first:   # an object column of logicals with a short name: its width depends on every row
        if origins.get(f.name) == "object" and pa.types.is_boolean(f.type) and len(f.name) < 6:
            return None
    meta = {k: v for k, v in (first.metadata or {}).items() if k != b"sweep"}
    return first.with_metadata(meta)


def _frame(table: pa.Table, origins: dict[str, str]) -> pd.DataFrame:
    """A part as the DataFrame its worker returned: object columns as Python objects again."""
    frame = table.to_pandas()
    for name, kind in origins.items():
        if kind == "object" and name in frame.columns:
            frame[name] = pd.Series(table.column(name).to_pylist(), dtype=object)
    return frame


def write_streamed(outdir: Path, stem: str, paths: list[Path], deck: Deck, sw: Params, base: Params,
                   axes: list[tuple[str, list]], names: list[str], n_cases: int, plot: bool | str = False,
                   module: Any = None, settings: dict[str, Any] | None = None) -> Streamed | None:
    """Write ``<stem>.out`` and ``<stem>_summary.{csv,parquet}`` from the record parts ``paths``
    (case order; each with rows), one part at a time, and with ``plot`` the summary figure (its
    rows are read back for it), all renamed into place together.  ``settings``
    (:func:`summary_settings`) go into the Parquet metadata as pandas writes a frame's attrs.
    Returns None, writing nothing, when the parts' columns differ in type (see the module)."""
    schema = _uniform(paths)
    if schema is None:
        return None
    if settings:   # as DataFrame.to_parquet records attrs (with_settings)
        schema = schema.with_metadata({**(schema.metadata or {}),
                                       b"PANDAS_ATTRS": json.dumps({"summary_settings": dict(settings)}).encode()})
    result = Streamed()
    result.metadata = dict(schema.metadata or {})
    table = _StreamedTable(paths, _origins(schema), names, n_cases > TABLE_ALL_MAX)
    with tempfile.TemporaryFile("w+", dir=outdir, prefix=f".{stem}.body.") as body, output_set(outdir):
        with atomic_open(outdir / f"{stem}_summary.csv", "wb") as csv, \
                atomic_open(outdir / f"{stem}_summary.parquet", "wb") as pfh:
            table.first_pass(schema, csv, pfh, body, result)
        with atomic_open(outdir / f"{stem}.out", "w") as out:
            out.write("\n".join(head_lines(deck, sw, base, axes, n_cases, result.n_kept, result.n_failed)) + "\n")
            table.write(out, body)
            tail = ([not_listed_line(n_cases - table.shown, sw.summary_rows)] if table.shown < n_cases else []) \
                + failed_lines(result.failed, result.n_failed)
            if tail:
                out.write("\n".join(tail) + "\n")
        if plot:   # the figure needs its rows together: read back for it
            write_sweep_plot(outdir, stem, plot, sw, names, module, read_columns(paths))
    return result


class _StreamedTable:
    """The ``.out`` table of a streamed sweep: its rows written at the columns' default widths
    in a first pass over the parts (which also writes the CSV and Parquet summaries and counts
    the failed cases), and again at the widths found when a cell did not fit."""

    def __init__(self, paths: list[Path], origins: dict[str, str], names: list[str], limit_rows: bool):
        self.paths, self.origins, self.names, self.limit_rows = paths, origins, names, limit_rows
        self.cols: list[Column] = []
        self.keys: list[str] = []
        self.widths: list[int] = []   # the columns' widths before any row (the case column's: its last number)
        self.need: list[int] = []     # the widths the rows need
        self.shown = 0

    def _shown(self, frame: pd.DataFrame) -> pd.DataFrame:
        """The rows the .out lists: all, or (above TABLE_ALL_MAX cases) the kept and failed ones."""
        return frame[frame["kept"] | (frame["status"] != "ok")] if self.limit_rows else frame

    def _start(self, frame: pd.DataFrame) -> None:
        import pyarrow.parquet as pq
        self.cols, self.keys = table_columns(frame)
        self.widths = [max(c.width, len(c.header)) for c in self.cols]
        if "case" in self.keys:   # case numbers grow row by row: the last part's last one is widest
            last = pq.read_table(self.paths[-1], columns=["case"]).column("case")
            j = self.keys.index("case")
            self.widths[j] = max(self.widths[j], len(str(int(last[len(last) - 1].as_py()))))
        self.need = list(self.widths)

    def _lines(self, shown: pd.DataFrame, widths: list[int]) -> tuple[list[int], str]:
        """The widest cell per column of the listed rows ``shown`` and their lines (one
        formatting call per column)."""
        cells = table_cells(shown, self.cols, self.keys)
        need = cell_widths(cells)
        return need, render_text(self.cols, cells, [max(w, n) for w, n in zip(widths, need)])

    def first_pass(self, schema: pa.Schema, csv: Any, pfh: Any, body: Any, result: Streamed) -> None:
        """Every part once: into the Parquet summary (one row group per part), and a block of
        whole parts at a time (parts are added until the block holds :data:`STREAM_BLOCK_ROWS`
        rows: what one part costs beyond its rows is paid once per block) into the CSV summary
        and ``body``, with the block's failed cases and counts into ``result``."""
        import pyarrow as pa
        import pyarrow.parquet as pq
        writer = pq.ParquetWriter(pfh, schema)
        try:
            block: list[pa.Table] = []
            rows = 0
            for k, path in enumerate(self.paths):
                # (ParquetFile: the file alone, none of read_table's dataset layer; one thread for a part)
                with pq.ParquetFile(path) as part:
                    table = part.read(use_threads=False).replace_schema_metadata(schema.metadata)
                writer.write_table(table)
                if k == 0:   # the columns' kinds and widths from the first part's rows, as ever
                    self._start(_frame(table, self.origins))
                block.append(table)
                rows += table.num_rows
                if rows >= STREAM_BLOCK_ROWS or k == len(self.paths) - 1:
                    self._block(pa.concat_tables(block).combine_chunks() if len(block) > 1 else block[0], csv, body,
                                result)
                    block, rows = [], 0
        finally:
            writer.close()

    def _block(self, table: pa.Table, csv: Any, body: Any, result: Streamed) -> None:
        """One block of parts' rows into the CSV summary and ``body``; its counts and failed cases."""
        from driver._export import write_csv_arrow
        write_csv_arrow(table, csv, header=result.n_rows == 0)
        frame = _frame(table, self.origins)
        bad = frame["status"] != "ok"
        result.n_rows += len(frame)
        result.n_kept += int(frame["kept"].sum())
        shown = self._shown(frame)
        self.shown += len(shown)
        need, text = self._lines(shown, self.widths)
        self.need = [max(w, n) for w, n in zip(self.need, need)]
        body.write(text)
        for _, r in frame[bad].iterrows():
            result.n_failed += 1
            result.bad_input |= r["status"] == "bad input"
            if len(result.failed) < FAILED_LISTED:
                result.failed.append((int(r["case"]), {k2: r[k2] for k2 in self.names}, r["error"]))

    def write(self, out: Any, body: Any) -> None:
        """The table's header and rows into the .out: the first pass's body, or every row again
        at the widths found when a cell did not fit its column's width."""
        import pyarrow.parquet as pq
        out.write("".join(" " * c.sep + c.header.rjust(w) for c, w in zip(self.cols, self.need)).rstrip() + "\n")
        if self.need == self.widths:
            body.seek(0)
            shutil.copyfileobj(body, out)
            return
        for path in self.paths:
            out.write(self._lines(self._shown(_frame(pq.read_table(path), self.origins)), self.need)[1])


def read_columns(paths: list[Path], columns: list[str] | None = None) -> pd.DataFrame:
    """The rows of ``paths`` (only ``columns``; None: all) as one frame, object columns as objects."""
    import pyarrow.parquet as pq
    frames = []
    for p in paths:
        t = pq.read_table(p, columns=columns)
        frames.append(_frame(t, _origins(pq.read_schema(p))))
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


# ----------------------------------------------------------------------------- the _cases tables

class CasesTable:
    """The ``<stem>_cases`` tables, built from the written cases' Parquet files as the cases
    arrive (while the workers compute, off the critical path): their Arrow tables and CSV rows,
    up to :data:`CASES_TABLE_MAX` cases and :data:`CASES_TABLE_BYTES`."""

    def __init__(self, layout: Any):
        self.layout = layout
        self.pieces: dict[int, tuple[Any, bytes | None]] = {}
        self.nbytes = 0
        self.full = False   # beyond CASES_TABLE_MAX cases or CASES_TABLE_BYTES: no combined table

    def add_chunk(self, res: Any) -> None:
        """Add the cases of a per-case chunk's result (its record rows) that wrote files."""
        if self.full or not hasattr(res.rows, "column"):
            return
        files, cases = res.rows.column("files").to_pylist(), res.rows.column("case").to_pylist()
        self.add([c for c, f in zip(cases, files) if f != "[]"])

    def add(self, indices: list[int]) -> None:
        import pyarrow.parquet as pq

        from driver._export import csv_bytes
        for k in indices:
            if self.full:
                return
            t = pq.read_table(self.layout.stem(k).with_suffix(".parquet"))
            try:
                body = csv_bytes(t, header=False)
            except TypeError:
                body = None
            self.pieces[k] = (t, body)
            self.nbytes += t.nbytes + len(body or b"")
            if len(self.pieces) > CASES_TABLE_MAX or self.nbytes > CASES_TABLE_BYTES:
                self.full, self.pieces = True, {}   # the driver's memory stays bounded

    def table(self, written: list[int]) -> Any:
        """The combined table of cases ``written`` (in order): a DataFrame, or an (Arrow table, CSV
        bytes) pair when every case has the same columns; None above CASES_TABLE_MAX cases or
        CASES_TABLE_BYTES."""
        if not written or len(written) > CASES_TABLE_MAX or self.full:
            return None
        self.add([k for k in written if k not in self.pieces])
        if self.full:
            return None
        import pyarrow as pa

        from driver._export import csv_bytes
        parts = [self.pieces[k] for k in written]
        first = parts[0][0].schema
        bodies = [body for _, body in parts if body is not None]
        if len(bodies) == len(parts) and all(t.schema.equals(first, check_metadata=False) for t, _ in parts):
            table = pa.concat_tables([t for t, _ in parts])
            return table, csv_bytes(table.slice(0, 0)) + b"".join(bodies)
        return pd.concat([t.to_pandas() for t, _ in parts], ignore_index=True)
