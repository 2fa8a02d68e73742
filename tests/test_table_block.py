"""The block formatter (issue 37): ``fixed_cells`` and ``render_block`` give, one call per column
of a block (``render_text``: the block's text at once), the text the per-value formatter gives
(``fortran_f``, ``render_table``), checked on
awkward values (exact ties, doubles next to a tie, values that round to zero, signed zeros,
subnormals, values beyond 2**50 scaled, huge ones), on random values of every magnitude, and
against an independent oracle: Decimal's half-up rounding of the double's exact value.  The
sweep's ``.out`` table built column by column equals the one built row by row before."""
from decimal import ROUND_HALF_UP, Decimal, localcontext

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from driver._table import Column, TableValueError, fixed_cells, fortran_f, render_block, render_table, render_text
from driver.sweep._report import _summary_table, table_cells, table_columns

AWKWARD = [0.5, 1.5, 2.5, -0.5, -2.5, 0.00005, -0.00005, 0.00015, 0.00025, 1.00005, 0.125, -0.125, 0.0625,
           0.049999999999999996, 0.05, 0.15, 0.25, 0.35, 0.44999999999999996, 9.99995, 99999.99995, 0.99995,
           -0.0, 0.0, 5e-324, -5e-324, 1e-300, 2.0 ** 50 / 1e4, 2.0 ** 52 / 1e4, 2.0 ** 53, 1e15, 1e16, 1e300,
           -1e300, 123456789.12345, 1.7976931348623157e308, 4.35, 4.45, -1.005, 2.675, 1e-4, -1e-4]


def decimal_f(x: float, d: int, legacy: bool = False) -> str:
    """Oracle: the exact value of the double rounded half away from zero by Decimal."""
    with localcontext() as ctx:
        ctx.prec = 400
        t = format(Decimal(x).quantize(Decimal(1).scaleb(-d), rounding=ROUND_HALF_UP), "f")
    if t.startswith("-") and Decimal(t) == 0:
        t = t[1:]
    if legacy and d:
        t = t.replace("-0.", "-.", 1) if t.startswith("-0.") else (t[1:] if t.startswith("0.") else t)
    return t + ("." if d == 0 else "")


def values(seed: int = 7) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.concatenate([AWKWARD,
                           rng.standard_normal(4000) * 10.0 ** rng.integers(-9, 13, 4000),
                           np.round(rng.uniform(-100, 100, 4000), 5),            # near ties at 4 decimals
                           rng.integers(-10**6, 10**6, 4000) / 2.0 ** rng.integers(1, 22, 4000)])  # exact ties


@pytest.mark.parametrize("style", ["modern", "legacy"])
@pytest.mark.parametrize("d", [0, 1, 2, 3, 4, 5, 8, 12, 15, 16])
def test_fixed_cells_equal_the_per_value_formatter(d, style):
    x = values()
    assert fixed_cells(x, d, style).tolist() == [fortran_f(v, None, d, style) for v in x.tolist()]


@pytest.mark.parametrize("d", [0, 1, 4, 6])
def test_fixed_cells_equal_decimal_half_up(d):
    x = values(11)
    x = x[np.abs(x) < 1e30]   # the oracle's text of 1e300 is the same, only slow to build
    assert fixed_cells(x, d).tolist() == [decimal_f(v, d) for v in x.tolist()]
    assert fixed_cells(x, d, "legacy").tolist() == [decimal_f(v, d, True) for v in x.tolist()]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(allow_nan=False, allow_infinity=False), min_size=1, max_size=40),
       st.integers(0, 9), st.sampled_from(["modern", "legacy"]))
def test_fixed_cells_on_drawn_doubles(xs, d, style):
    assert fixed_cells(np.array(xs), d, style).tolist() == [fortran_f(v, None, d, style) for v in xs]


def test_fixed_cells_refuse_non_finite_and_keep_shape_rules():
    with pytest.raises(TableValueError):
        fixed_cells(np.array([1.0, np.nan]), 4)
    with pytest.raises(TableValueError):
        fixed_cells(np.array([np.inf]), 2)
    assert fixed_cells(np.array([]), 4).tolist() == []


def test_render_block_equals_render_table():
    rng = np.random.default_rng(3)
    cols = [Column("case", "i", 5, 0), Column("a long header", "f", 8, 3), Column("x", "f", 10, 4, sep=1),
            Column("tag", "s", 6, 0)]
    rows = [[int(i), float(rng.standard_normal() * 10.0 ** rng.integers(-3, 9)), float(rng.uniform(-1, 1)),
             ["ok", "", "failed"][i % 3]] for i in range(300)]
    want = render_table(cols, rows)
    cells = [[c.cell(v) for v in col] for c, col in zip(cols, zip(*rows))]
    widths = [max(c.width, len(c.header), *(len(v) for v in cj)) for c, cj in zip(cols, cells)]
    head = "".join(" " * c.sep + c.header.rjust(w) for c, w in zip(cols, widths)).rstrip()
    assert [head, *render_block(cols, cells, widths)] == want


def row_by_row(show: pd.DataFrame) -> list[str]:
    """The sweep table as it was built before: values row by row, each cell by Column.cell."""
    cols, keys = table_columns(show)
    rows = []
    for vals in zip(*(show[k].tolist() for k in keys)):
        row = []
        for c, v in zip(cols, vals):
            if v is None or (isinstance(v, float) and not np.isfinite(v)):
                row.append("-")
            elif isinstance(v, (bool, np.bool_)):
                row.append("yes" if v else "no")
            else:
                row.append(str(v) if c.kind == "s" else v)
        rows.append(row)
    return render_table(cols, rows)


def test_sweep_table_equals_the_row_by_row_table():
    rng = np.random.default_rng(5)
    n = 500
    x = rng.standard_normal(n) * 10.0 ** rng.integers(-6, 10, n)
    x[::17] = np.nan
    x[5] = -0.0
    x[6] = 0.00005
    x[7] = -2.5e-5
    frame = pd.DataFrame({"case": np.arange(1, n + 1), "fourbar.crank": np.round(rng.uniform(1, 7, n), 5),
                          "status": np.where(np.arange(n) % 50 == 0, "failed", "ok"),
                          "kept": rng.uniform(size=n) < 0.5, "swing_deg": x,
                          "class": pd.Series(rng.choice(["crank-rocker", "double-rocker"], n)).where(
                              np.arange(n) % 11 != 3),   # text with missing values
                          "mixed": pd.Series([None if i % 7 == 0 else float(i) / 3 for i in range(n)], dtype=object),
                          "error": [""] * n})
    assert _summary_table(frame) == row_by_row(frame)
    cols, keys = table_columns(frame)
    assert [c.tolist() for c in table_cells(frame.iloc[:0], cols, keys)] == [[] for _ in keys]


def test_render_block_of_no_rows():
    assert render_block([Column("a"), Column("b", "i")], [[], []], [10, 5]) == []


TEXTS = st.text(st.sampled_from(["a", "Z", "-", ".", " ", "7", "\t", "\x1f", "\u00e9", "\u4e2d"]), max_size=6)


@settings(max_examples=80, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 9)), min_size=1, max_size=5),
       st.integers(1, 30), st.data())
def test_render_text_equals_the_row_by_row_table(shape, n, data):
    """``render_text`` against ``render_table``'s lines (cell by cell, rstrip per line) on drawn
    text cells: blanks and other whitespace rstrip removes (tab, unit separator) at either end
    (lines that must be stripped), non-ASCII text, empty cells, zero widths and zero separators."""
    cols = [Column(f"c{j}", "s", w, 0, sep=sep) for j, (sep, w) in enumerate(shape)]
    cells = [data.draw(st.lists(TEXTS.filter(lambda t, w=c.width: len(t) <= w), min_size=n, max_size=n))
             for c in cols]
    want = render_table(cols, list(zip(*cells)), header=False)
    assert render_text(cols, cells, [c.width for c in cols]) == "".join(line + "\n" for line in want)


@pytest.mark.parametrize("end", [" ", "\t", "\n", "\x0b", "\x0c", "\r", "\x1c", "\x1f", "x"])
def test_render_text_strips_what_rstrip_strips(end):
    """A line ending in any of the ASCII whitespace rstrip removes is stripped as render_block strips it."""
    cols = [Column("a", "s", 3, 0), Column("b", "s", 3, 0)]
    cells = [["1", "22", "333"], ["ab" + end, "c", "d" + end]]
    want = render_table(cols, list(zip(*cells)), header=False)
    assert render_text(cols, cells, [3, 3]) == "".join(line + "\n" for line in want)


def test_render_text_of_a_sweep_block():
    """The streamed sweep's body: fixed_cells columns and yes/no columns, the block's text equals
    the row-by-row table's lines, and no rows give no text."""
    rng = np.random.default_rng(9)
    frame = pd.DataFrame({"case": np.arange(1, 2001), "x": rng.standard_normal(2000) * 1e3,
                          "kept": rng.uniform(size=2000) < 0.5, "status": ["ok"] * 2000})
    cols, keys = table_columns(frame)
    cells = table_cells(frame, cols, keys)
    widths = [max(c.width, len(c.header), *(len(v) for v in cj)) for c, cj in zip(cols, cells)]
    assert render_text(cols, cells, widths) == "".join(line + "\n" for line in row_by_row(frame)[1:])
    assert render_text(cols, [[] for _ in cols], widths) == ""
