"""The four-bar run beside the published listing tables (Lampiran 2-5 of [Soegihardjo 2003]), and
what the listing gets wrong."""
from __future__ import annotations

import math

import numpy as np

from driver import _published as record
from driver._deck import Params
from driver._published import cell, one_digit_apart
from driver._result import Result
from driver._table import fortran_f
from driver.fourbar._analysis import exact_columns, exact_grid

__all__ = ['LISTING_DEFECT', 'LISTING_PRECISION', 'exact_as_listed', 'compare']


#: why the published listing's rows for crank angles in (180, 360) deg are wrong (see :func:`audit`)
LISTING_DEFECT = ("the listing's quadrant test sends sigy > 0, sigx > 0 to sigma = 2 pi - |atan| (meant |atan|), "
                  "so rows 200-340 repeat the mirror position 360 - i and their speeds are wrong")


#: why a correct value may differ from a correct published row in its last printed digit
LISTING_PRECISION = ("the listing works in single precision with pi/180 = 0.0174532 and truncates angles "
                     "to whole degrees")


def exact_as_listed(p: Params, theta_deg: np.ndarray) -> dict[tuple[int, str], str]:
    """Print the closed-loop solution the way the published listing prints it.

    FORMAT 25: angles truncated to whole degrees, legacy F5.1 / F7.4: what the published table
    shows where it is right.

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys.
    theta_deg : numpy.ndarray
        Whole crank angles, deg.

    Returns
    -------
    dict of tuple to str
        (angle, column of the listing table) -> the printed cell (deg, length unit, rad/s);
        blank where the linkage cannot be placed.
    """
    out, status = exact_grid(p, theta_deg)
    cols = exact_columns(out, status)
    names = {"epsl": "coupler_deg", "phi": "rocker_deg", "beta": "transmission_deg", "xa": "xa", "ya": "ya",
             "xb": "xb", "yb": "yb", "omr": "coupler_omega_rad_s", "oms": "rocker_omega_rad_s"}
    res: dict[tuple[int, str], str] = {}
    for k, i in enumerate(np.asarray(theta_deg).astype(int)):
        res[(int(i), "i")] = str(int(i))
        for col, name in names.items():
            v = cols[name][k]
            if not np.isfinite(v):
                res[(int(i), col)] = ""
            elif col in ("epsl", "phi", "beta"):
                res[(int(i), col)] = fortran_f(math.trunc(v), None, 1, "legacy")
            else:
                res[(int(i), col)] = fortran_f(v, None, 4 if col in ("omr", "oms") else 1, "legacy")
    return res


def compare(params: Params, result: Result) -> list[dict]:
    """The run beside the published listing tables (Lampiran 2-5): one dict per printed cell."""
    cells = []
    for path in record.records("fourbar"):
        pub = record.read_listing(path)
        if not record.matches(pub.match, params):
            continue
        angles = np.array(sorted({int(r) for r in pub.cells["row"]}), float)
        correct = exact_as_listed(params, angles)
        if params.method == "listing":
            computed = {(int(r[0]), c): v for r in record.listing_rows(result.text)
                        for c, v in zip(record.LISTING_COLUMNS, r)}
        else:
            computed = correct
        for rec in record.printed_cells(pub.cells):
            key = (int(rec.row), rec.column)
            got = computed.get(key)
            wrong = correct.get(key) != rec.printed   # the published cell is not the correct answer
            if 180 < key[0] < 360:
                why = LISTING_DEFECT
            else:
                why = LISTING_PRECISION
            if got is None:
                cells.append(cell(pub.name, rec.row, rec.column, rec.printed, "", "departs",
                                   "the deck's crank angles (start_deg, step_deg) do not include this published row"))
            elif got == rec.printed:
                cells.append(cell(pub.name, rec.row, rec.column, rec.printed, got, "identical",
                                   f"erratum: correct value {correct.get(key)}; {why}" if wrong else ""))
            elif params.method == "exact" and not (why == LISTING_PRECISION
                                                   and not one_digit_apart(got, rec.printed, rec.column)):
                cells.append(cell(pub.name, rec.row, rec.column, rec.printed, got, "departs", why))
            else:
                cells.append(cell(pub.name, rec.row, rec.column, rec.printed, got, "differs", ""))
    return cells
