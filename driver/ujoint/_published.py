"""The Hooke-joint run beside the published SSO results of [Fajar]."""
from __future__ import annotations

from typing import TYPE_CHECKING

from driver._deck import Params
from driver.ujoint._spec import BAND_TOL, NOT_REPRODUCIBLE

if TYPE_CHECKING:
    from driver._result import Result

__all__ = ["compare"]


def compare(params: Params, result: Result) -> list[dict]:
    """The run beside the paper's SSO results (options 1-3): one dict per printed value."""
    from driver import _published as record  # the comparison's reader: imported when a comparison runs
    from driver._published import cell
    cells = []
    for path in record.records("ujoint"):
        pub = record.read_blocks(path)
        if not record.matches(pub.match, params):
            continue
        t, s = result.tidy, result.summary
        trial = t[t["design"] == "trial"]
        printed_design = t[t["design"] == "paper printed"]
        option = pub.match.get("option", "?")
        for rec in record.printed_cells(pub.cells):
            q, table = str(rec.row), f"SSO option {option}"
            if q.startswith("trial_band"):
                value = float(trial["omega_out_rpm"].min() if q.endswith("min") else trial["omega_out_rpm"].max())
                comp = f"{value:.2f}"
                if abs(value - float(rec.printed)) <= BAND_TOL:   # the figure's reading precision
                    cells.append(cell(table, q, "rpm", rec.printed, comp, "agrees"))
                elif option == "1":
                    cells.append(cell(table, q, "rpm", rec.printed, comp, "not reproducible",
                                       NOT_REPRODUCIBLE["option1_band"]))
                else:
                    cells.append(cell(table, q, "rpm", rec.printed, comp, "differs", ""))
            elif q.startswith("x_"):
                name = q[2:]
                v = s.get(f"{name}_deg")
                comp = "" if v is None else f"{v:.4f}"
                why = NOT_REPRODUCIBLE["phi_3" if v is None and name == "phi_3" else "x"]
                cells.append(cell(table, q, "deg", rec.printed, comp, "not reproducible", why))
            elif q == "U":
                comp = ""
                if len(printed_design):
                    comp = f"{((printed_design['ratio'] - 1.0) ** 2).mean() * params.rpm ** 2:.4f}"
                cells.append(cell(table, q, "", rec.printed, comp, "not reproducible", NOT_REPRODUCIBLE["U"]))
            else:
                cells.append(cell(table, q, "", rec.printed, "", "not reproducible", NOT_REPRODUCIBLE[q]))
    return cells
