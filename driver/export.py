"""The one tidy-table exporter: a pandas frame to CSV or Parquet, atomically.

Tidy means one row per output point (crank angle, time step, design, ...) and
one column per quantity, with units in the column names (``omega3_rad_s``).
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from driver.atomic import atomic_open
from driver.extras import available, require

if TYPE_CHECKING:   # annotations only: keeps `python -m driver --help` light
    import pandas as pd

__all__ = ["FORMATS", "write_tidy"]

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
