"""Fortran F editing in both styles, against hand-worked Fortran output."""
import math

import pytest

from driver._table import Column, TableValueError, fortran_f, render_table


@pytest.mark.parametrize("x,w,d,modern,legacy", [
    (0.0, 5, 1, "  0.0", "   .0"),
    (-1e-6, 5, 1, "  0.0", "   .0"),          # rounds to zero: no sign
    (-0.3, 5, 1, " -0.3", "  -.3"),
    (-0.80940, 7, 4, "-0.8094", " -.8094"),
    (12.0, 5, 2, "12.00", "12.00"),
    (2.0, 5, 2, " 2.00", " 2.00"),
    (0.25, 5, 1, "  0.3", "   .3"),            # ties round away from zero
    (-2.5001, 7, 4, "-2.5001", "-2.5001"),
    (3e-8, 12, 8, "  0.00000003", "   .00000003"),   # never exponent notation
    (-4e-12, 12, 8, "  0.00000000", "   .00000000"),
])
def test_f_editing(x, w, d, modern, legacy):
    assert fortran_f(x, w, d) == modern
    assert fortran_f(x, w, d, "legacy") == legacy


def test_huge_values_are_written_in_full():
    text = fortran_f(1e300, 8, 4)
    assert text.endswith(".0000") and len(text) == 301 + 5 and "E" not in text


def test_non_finite_never_reaches_a_table():
    for bad in (math.nan, math.inf, -math.inf):
        with pytest.raises(TableValueError):
            fortran_f(bad, 8, 3)


def test_overflow_widens_the_column_instead_of_stars():
    col = Column("x", "f", 5, 1)
    lines = render_table([col], [[1.0], [123456.7]])
    assert col.widened
    assert "*" not in "".join(lines)
    assert lines[2].strip() == "123456.7"
    assert len({len(l) for l in lines[1:]}) == 1  # still aligned
