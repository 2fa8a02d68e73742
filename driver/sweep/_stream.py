"""The tables of a batch sweep whose rows are too many to hold: written part by part.

A batch sweep's rows (with ``summary_rows = 'kept'`` its kept and failed cases) are in the
parts of its resume record, one Parquet file per chunk, in case order.  Above
``STREAM_ROWS`` rows the driver stops holding them (:func:`driver.sweep._batch.run` returns a
:class:`~driver.sweep._batch.StreamedRows`) and :func:`write_streamed` writes the ``.out``, the
``_summary`` CSV and the ``_summary`` Parquet file reading one part at a time, so the driver's
memory does not grow with the rows.  The files are those the in-memory path writes: the same
``.out`` and CSV bytes, the same Parquet table (in one row group per part); the
``.out`` table's column widths, which the widest cell decides, are taken in a first pass that
writes the body to a scratch file (the case column at the width of the last case number) and
only redone when a cell did not fit.

Parts whose columns differ in type (bad-input rows turn a chunk's summary columns into
objects) cannot be streamed this way; :func:`write_streamed` then returns None and the caller
reads the rows into memory as before.
"""
from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path
from typing import Any

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from driver._atomic import atomic_open, output_set
from driver._deck import Deck, Params
from driver._table import Column
from driver.sweep._report import FAILED_LISTED, failed_lines, head_lines, not_listed_line, table_columns, table_values

__all__ = ["STREAM_ROWS", "write_streamed", "Streamed", "Parts"]

#: above this many rows (kept and failed cases) a batch sweep's tables are written part by part
STREAM_ROWS = 20_000
#: the .out lists every case up to this many cases (as :data:`driver.sweep.TABLE_ALL_MAX`)
TABLE_ALL_MAX = 2000


class Streamed:
    """What the caller needs after a streamed write: the failed cases (the first
    :data:`FAILED_LISTED`, in case order), their count, and whether any was bad input."""

    def __init__(self) -> None:
        self.failed: list[tuple[int, dict, str]] = []
        self.n_failed = 0
        self.bad_input = False
        self.n_kept = 0


def _origins(schema: pa.Schema) -> dict[str, str]:
    """Column -> the pandas dtype it was written from (an object column of numbers is 'object')."""
    meta = schema.pandas_metadata or {}
    return {c["name"]: c["numpy_type"] for c in meta.get("columns", []) if c.get("name") is not None}


def _uniform(paths: list[Path]) -> pa.Schema | None:
    """The parts' common schema (without the record's metadata), or None when the parts' columns
    differ in name, type or the dtype they were written from."""
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
    (:func:`driver.sweep._report.summary_settings`) go into the Parquet metadata as pandas
    writes a frame's attrs.  Returns None, writing nothing, when the parts' columns differ in
    type (see the module)."""
    from driver._export import write_csv_arrow
    schema = _uniform(paths)
    if schema is None:
        return None
    origins = _origins(schema)
    if settings:   # as DataFrame.to_parquet records attrs (driver.sweep._report.with_settings)
        schema = schema.with_metadata({**(schema.metadata or {}),
                                       b"PANDAS_ATTRS": json.dumps({"summary_settings": dict(settings)}).encode()})
    limit_rows = n_cases > TABLE_ALL_MAX   # above: the .out lists the kept and failed cases only
    result = Streamed()
    cols: list[Column] = []
    keys: list[str] = []
    with tempfile.TemporaryFile("w+", dir=outdir, prefix=f".{stem}.body.") as body, output_set(outdir):
        widths: list[int] = []
        need: list[int] = []
        shown = 0
        with atomic_open(outdir / f"{stem}_summary.csv", "wb") as csv, \
                atomic_open(outdir / f"{stem}_summary.parquet", "wb") as pfh:
            writer = pq.ParquetWriter(pfh, schema)
            try:
                for k, path in enumerate(paths):
                    table = pq.read_table(path)
                    table = table.replace_schema_metadata(schema.metadata)
                    writer.write_table(table)
                    write_csv_arrow(table, csv, header=k == 0)
                    frame = _frame(table, origins)
                    if k == 0:
                        cols, keys = table_columns(frame)
                        widths = [max(c.width, len(c.header)) for c in cols]
                        if "case" in keys:   # case numbers grow row by row: the last part's last one is widest
                            last = pq.read_table(paths[-1], columns=["case"]).column("case")
                            j = keys.index("case")
                            widths[j] = max(widths[j], len(str(int(last[len(last) - 1].as_py()))))
                        need = list(widths)
                    bad = frame["status"] != "ok"
                    result.n_kept += int(frame["kept"].sum())
                    show = frame[frame["kept"] | bad] if limit_rows else frame
                    shown += len(show)
                    for row in table_values(show, cols, keys):
                        cells = [c.cell(v) for c, v in zip(cols, row)]
                        need = [max(w, len(v)) for w, v in zip(need, cells)]
                        body.write("".join(" " * c.sep + v.rjust(w) for c, v, w in zip(cols, cells, widths))
                                   .rstrip() + "\n")
                    for _, r in frame[bad].iterrows():
                        result.n_failed += 1
                        result.bad_input |= r["status"] == "bad input"
                        if len(result.failed) < FAILED_LISTED:
                            result.failed.append((int(r["case"]), {k2: r[k2] for k2 in names}, r["error"]))
            finally:
                writer.close()
        with atomic_open(outdir / f"{stem}.out", "w") as out:
            head = head_lines(deck, sw, base, axes, n_cases, result.n_kept, result.n_failed)
            out.write("\n".join(head) + "\n")
            out.write("".join(" " * c.sep + c.header.rjust(w) for c, w in zip(cols, need)).rstrip() + "\n")
            if need == widths:
                body.seek(0)
                shutil.copyfileobj(body, out)
            else:   # a cell did not fit its column's width: every row again at the widths found
                for path in paths:
                    frame = _frame(pq.read_table(path), origins)
                    show = frame[frame["kept"] | (frame["status"] != "ok")] if limit_rows else frame
                    for row in table_values(show, cols, keys):
                        cells = [c.cell(v) for c, v in zip(cols, row)]
                        out.write("".join(" " * c.sep + v.rjust(w) for c, v, w in zip(cols, cells, need))
                                  .rstrip() + "\n")
            tail = ([not_listed_line(n_cases - shown, sw.summary_rows)] if shown < n_cases else []) \
                + failed_lines(result.failed, result.n_failed)
            if tail:
                out.write("\n".join(tail) + "\n")
        if plot:   # the figure needs its rows together: read back for it
            from driver.sweep._report import write_sweep_plot
            write_sweep_plot(outdir, stem, plot, sw, names, module, read_columns(paths))
    return result


def read_columns(paths: list[Path], columns: list[str] | None = None) -> pd.DataFrame:
    """The rows of ``paths`` (only ``columns``; None: all) as one frame, object columns as objects."""
    frames = []
    for p in paths:
        t = pq.read_table(p, columns=columns)
        frames.append(_frame(t, _origins(pq.read_schema(p))))
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


class Parts:
    """A lazy handle on a streamed sweep's summary rows, kept in the record's parts: read when
    asked (:meth:`to_pandas`)."""

    def __init__(self, paths: list[Path]):
        self.paths = list(paths)

    def to_pandas(self, columns: list[str] | None = None) -> pd.DataFrame:
        """The rows (only ``columns``; None: all) as one frame."""
        return read_columns(self.paths, columns)

    def __len__(self) -> int:
        return sum(pq.read_metadata(p).num_rows for p in self.paths)
