"""The one tidy-table exporter: a pandas frame to CSV or Parquet, atomically.

Tidy means one row per output point (crank angle, time step, design, ...) and
one column per quantity, with units in the column names (``omega3_rad_s``).
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from driver.atomic import atomic_open

__all__ = ["FORMATS", "write_tidy"]

FORMATS = ("csv", "parquet")


def write_tidy(frame: pd.DataFrame, path_stem: str | Path, fmt: str) -> Path:
    """Write ``frame`` to ``<path_stem>.<fmt>`` (csv or parquet) atomically."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown table format {fmt!r} (choose {', '.join(FORMATS)})")
    path = Path(f"{path_stem}.{fmt}")
    if fmt == "csv":
        with atomic_open(path, "w") as fh:
            frame.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
    else:
        with atomic_open(path, "wb") as fh:
            frame.to_parquet(fh, index=False)
    return path
