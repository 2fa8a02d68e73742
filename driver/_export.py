"""The one tidy-table exporter: a pandas frame to CSV or Parquet, atomically.

Tidy means one row per output point (crank angle, time step, design, ...) and
one column per quantity, with units in the column names (``rocker_omega_rad_s``) or,
where a name cannot say it (``xa`` is in the deck's length unit), in
``frame.attrs["units"]`` (:func:`with_units`; Parquet files keep it in their
metadata).  CSV and Parquet read back with the same dtypes and values: floats
are written in shortest round-trip form and always as floats (``30.0``, never
``30``), strings are quoted only when they must be.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from driver._atomic import atomic_open
from driver._extras import available, require

if TYPE_CHECKING:   # annotations only: keeps `python -m driver --help` light
    import pandas as pd
    import pyarrow as pa

__all__ = ["FORMATS", "write_tidy", "csv_bytes", "with_units", "unit_of", "json_safe"]

FORMATS = ("csv", "parquet")


#: units read from a column name's suffix (longest suffix first)
SUFFIX_UNITS = (("_rad_s2", "rad/s^2"), ("_rad_s", "rad/s"), ("_m_s2", "m/s^2"), ("_per_s2", "length/s^2"),
                ("_per_s", "length/s"), ("_microstrain", "1e-6"), ("_deg", "deg"), ("_rpm", "rpm"),
                ("_Nm", "N m"), ("_MPa", "MPa"), ("_m2", "m^2"), ("_mm", "mm"), ("_um", "um"), ("_kg", "kg"), ("_m", "m"),
                ("_N", "N"), ("_s", "s"))


def unit_of(name: str, dtype: Any = None) -> str | None:
    """The unit a column name says (``rocker_omega_rad_s`` -> 'rad/s'); '' for text and logicals;
    None when a numeric column's name does not say it."""
    for suffix, unit in SUFFIX_UNITS:
        if name.endswith(suffix):
            return unit
    import pandas as pd

    if dtype is not None and not (pd.api.types.is_numeric_dtype(dtype) and not pd.api.types.is_bool_dtype(dtype)):
        return ""
    return None


def with_units(frame: pd.DataFrame, units: dict[str, str] | None = None) -> pd.DataFrame:
    """Record every column's unit in ``frame.attrs["units"]`` (in place; returns the frame).

    ``units`` gives those the names do not say ('length' = the deck's length unit,
    '1' = dimensionless); the rest come from the name's suffix, '' for text and logicals.
    """
    given = dict(units or {})
    frame.attrs["units"] = {c: given[c] if c in given else unit_of(c, frame[c].dtype) for c in frame.columns}
    return frame


def _csv_name(name: str) -> str:
    """A header cell, quoted only when it needs to be (as pandas does)."""
    return f'"{name.replace(chr(34), 2 * chr(34))}"' if any(c in name for c in ',"\n\r') else name


def _cells(col: pa.Array | pa.ChunkedArray) -> pa.Array | pa.ChunkedArray:
    """One column as CSV cell text (nulls stay null, written as empty cells)."""
    import pyarrow as pa
    import pyarrow.compute as pc

    t = col.type
    if pa.types.is_floating(t):
        values = pc.cast(col, pa.float64())
        text = pc.cast(values, pa.string())
        x = values.to_numpy(zero_copy_only=False)
        whole = np.isfinite(x) & (np.floor(x) == x)
        if whole.any():   # '30' would read back as an integer: write '30.0' (exponent forms are floats)
            plain = pc.and_(pa.array(whole), pc.invert(pc.match_substring(text, "e")))
            text = pc.if_else(plain, pc.binary_join_element_wise(text, ".0", ""), text)
        return text
    if pa.types.is_string(t) or pa.types.is_large_string(t):
        text = pc.cast(col, pa.string())
        quoted = pc.binary_join_element_wise('"', pc.replace_substring(text, '"', '""'), '"', "")
        return pc.if_else(pc.match_substring_regex(text, '[,"\r\n]'), quoted, text)
    if pa.types.is_boolean(t) or pa.types.is_integer(t) or pa.types.is_null(t):
        return pc.cast(col, pa.string())
    raise TypeError(f"no CSV form for {t}")


def write_csv_arrow(table: pa.Table, fh: Any, batch_rows: int = 1 << 16, header: bool = True) -> None:
    """CSV rows built column-wise by Arrow compute and written from its buffers, a batch of
    rows at a time (no Python per row; memory bounded by the batch)."""
    import pyarrow.compute as pc

    if header:
        fh.write((",".join(_csv_name(c) for c in table.column_names) + "\n").encode())
    if table.num_columns == 0:
        return
    for batch in table.to_batches(max_chunksize=batch_rows):
        if batch.num_rows == 0:
            continue
        cells = [_cells(batch.column(i)) for i in range(batch.num_columns)]
        rows = pc.binary_join_element_wise(*cells, ",", null_handling="replace", null_replacement="")
        rows = pc.binary_join_element_wise(pc.fill_null(rows, ""), "\n", "")
        offsets = np.frombuffer(rows.buffers()[1], dtype=np.int32)[rows.offset:rows.offset + len(rows) + 1]
        fh.write(memoryview(rows.buffers()[2])[offsets[0]:offsets[-1]])


def write_tidy(frame: pd.DataFrame, path_stem: str | Path, fmt: str) -> Path:
    """Write ``frame`` to ``<path_stem>.<fmt>`` (csv or parquet) atomically.

    Both read back with pandas' defaults to the same dtypes and values (text columns
    that are entirely empty read from CSV as missing); Parquet also keeps ``frame.attrs``
    (the units)."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown table format {fmt!r} (choose {', '.join(FORMATS)})")
    path = Path(f"{path_stem}.{fmt}")
    if fmt == "parquet":
        require("parquet")
    if fmt == "csv":
        table = None
        if available("parquet"):   # Arrow builds the CSV about 4x faster than pandas (large sweeps)
            import pyarrow as pa
            try:
                table = pa.Table.from_pandas(frame, preserve_index=False)
                [_cells(table.column(i).slice(0, 0)) for i in range(table.num_columns)]
            except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError, TypeError):
                table = None   # a column mixing types: let pandas stringify it
        if table is not None:
            with atomic_open(path, "wb") as fh:
                write_csv_arrow(table, fh)
        else:
            with atomic_open(path, "w") as fh:
                frame.to_csv(fh, index=False, lineterminator="\n")
    else:
        with atomic_open(path, "wb") as fh:
            frame.to_parquet(fh, index=False)
    return path


def csv_bytes(table: pa.Table, header: bool = True) -> bytes:
    """The CSV that :func:`write_tidy` writes for a frame whose Arrow form is ``table`` (with the
    header line, or only the rows: pieces of one CSV built as they arrive, e.g. a sweep's
    ``_cases`` table).  TypeError for a column type without a CSV form here."""
    import io
    buf = io.BytesIO()
    write_csv_arrow(table, buf, header=header)
    return buf.getvalue()


def json_safe(value: Any) -> Any:
    """``value`` with numpy scalars and arrays made plain and non-finite floats made None
    (JSON has no NaN or Infinity; a missing figure is ``null``)."""
    if isinstance(value, dict):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [json_safe(v) for v in (value.tolist() if isinstance(value, np.ndarray) else value)]
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer, int)):
        return int(value)
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    if value is None or isinstance(value, str):
        return value
    if isinstance(value, Path):
        return str(value)
    return str(value)
