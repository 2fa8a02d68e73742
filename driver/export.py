"""The one tidy-table exporter: a pandas frame to CSV or Parquet, atomically.

Tidy means one row per output point (crank angle, time step, design, ...) and
one column per quantity, with units in the column names (``omega3_rad_s``).
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from driver.atomic import atomic_open
from driver.extras import available, require

if TYPE_CHECKING:   # annotations only: keeps `python -m driver --help` light
    import pandas as pd

__all__ = ["FORMATS", "write_tidy", "json_safe", "summary_json_text"]

FORMATS = ("csv", "parquet")


def _csv_name(name: str) -> str:
    """A header cell, quoted only when it needs to be (as pandas does)."""
    return f'"{name.replace(chr(34), 2 * chr(34))}"' if any(c in name for c in ',"\n') else name


def write_tidy(frame: pd.DataFrame, path_stem: str | Path, fmt: str) -> Path:
    """Write ``frame`` to ``<path_stem>.<fmt>`` (csv or parquet) atomically."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown table format {fmt!r} (choose {', '.join(FORMATS)})")
    path = Path(f"{path_stem}.{fmt}")
    if fmt == "parquet":
        require("parquet")
    if fmt == "csv":
        table = None
        if available("parquet"):   # pyarrow writes CSV about 10x faster than pandas (large sweeps)
            import pyarrow as pa
            import pyarrow.csv as pacsv
            try:
                table = pa.Table.from_pandas(frame, preserve_index=False)
            except (pa.ArrowInvalid, pa.ArrowTypeError):   # a column mixing types: let pandas stringify it
                table = None
        if table is not None:
            with atomic_open(path, "wb") as fh:
                fh.write((",".join(_csv_name(c) for c in table.column_names) + "\n").encode())
                pacsv.write_csv(table, fh, pacsv.WriteOptions(include_header=False, quoting_style="needed"))
        else:
            with atomic_open(path, "w") as fh:
                frame.to_csv(fh, index=False, lineterminator="\n")
    else:
        with atomic_open(path, "wb") as fh:
            frame.to_parquet(fh, index=False)
    return path


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


def summary_json_text(result: Any) -> str:
    """The machine-readable summary of one run (``<stem>.json``): study, name, success,
    failure, warnings and the summary figures (units in their names)."""
    record = {"study": result.study, "name": result.name, "ok": result.failure is None,
              "failure": result.failure, "warnings": list(result.warnings),
              "summary": json_safe(result.summary)}
    return json.dumps(record, indent=1, allow_nan=False) + "\n"
