"""The sweep's ``keep`` filter, once: parsed once per text, checked against the base deck's
summary before any case runs, and applied to rows by both chunk functions (case by case and
batch, :mod:`driver.sweep._chunks`) with the same rule."""
from __future__ import annotations

import functools
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from driver import _expr as expr

__all__ = ["keep_mask", "keep_columns", "check_keep"]


@functools.lru_cache(maxsize=32)
def _parsed(text: str) -> expr.Expr:
    return expr.parse(text)


def keep_mask(keep: str, rows: Any) -> np.ndarray:
    """The filter ``keep`` on summary rows (a DataFrame, or a mapping of column -> array): a
    boolean per row.  No filter keeps every row; a row whose figures are missing (a failed
    case) is not kept; a column absent from these rows (every case of a chunk failed) keeps
    none of them."""
    if not keep:
        return np.ones(len(rows) if hasattr(rows, "columns") else len(next(iter(rows.values()))), dtype=bool)
    try:
        return np.asarray(_parsed(keep).mask(rows), dtype=bool)
    except expr.ExprError:
        n = len(rows) if hasattr(rows, "columns") else len(next(iter(rows.values())))
        return np.zeros(n, dtype=bool)


def keep_columns(keep: str) -> set[str]:
    """The summary columns the filter reads (swept keys ``group.key`` and ``case`` are not)."""
    return {n for n in _parsed(keep).names if "." not in n and n != "case"} if keep else set()


def check_keep(keep: str, columns: Iterable[str], kinds: Mapping[str, str]) -> None:
    """Raise :class:`~driver._expr.ExprError` unless ``keep`` reads only ``columns`` and gives one
    number or logical per case (column kinds ``kinds``), before any case runs."""
    expr.parse(keep, columns).check_kinds(kinds)
