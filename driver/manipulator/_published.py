"""The manipulator run beside the published tables of [Ma'arif 2006], chapter 4."""
from __future__ import annotations

from typing import TYPE_CHECKING

from driver._deck import Params
from driver.manipulator._report import table_frame
from driver.manipulator._tables import NOT_REPRODUCIBLE, REASONS, TEXT_REASONS, TIDY_NAMES

if TYPE_CHECKING:
    from driver._result import Result

__all__ = ["compare"]


def compare(params: Params, result: Result) -> list[dict]:
    """The run beside the report's Tables 4.1-4.8 and text values: one dict per printed cell."""
    from driver import _published as record  # the comparison's reader: imported when a comparison runs
    from driver._published import numeric_cell
    exact = params.mode == "exact"

    def text_values() -> dict[str, float | None]:
        s = result.summary
        out = {"r_squared": s["r_m"] ** 2, "R_squared": s["R_m"] ** 2, "crob_radius": s["crob_radius_m"],
               "crob_c_sweep": s["crob_radius_m"] ** 2,
               "dexterity_l1": s["dexterity_l1_m"], "dexterity_l2": s["dexterity_l2_m"],
               "manipulability_l1": s["manipulability_l1_m"], "manipulability_l2": s["manipulability_l2_m"],
               "manipulability_l1_t44": None,
               "min_total_torque": s.get("sweep_min_tau_sum_signed_Nm"), "min_total_l1": s.get("sweep_min_l1_m"),
               "min_total_l2": s.get("sweep_min_l2_m")}
        t44 = table_frame(result.tidy, "4.4")
        if len(t44) > 1:
            out["manipulability_l1_t44"] = float(t44["l1_m"].iloc[1])
        return out

    cells = []
    for path in record.records("manipulator"):
        pub = record.read_blocks(path)
        if not record.matches(pub.match, params):
            continue
        tidy, values = result.tidy, text_values()
        for rec in record.printed_cells(pub.cells):
            table = str(rec.table)
            if table == "Text values":
                value = values.get(str(rec.row))
                why_exact = TEXT_REASONS.get(str(rec.row), "follows from the cells above") if exact else None
                cells.append(numeric_cell(table, rec.row, "value", rec.printed, value, None, why_exact))
                continue
            number = table.split()[-1]
            key_t = "4.1" if number == "4.3" else number
            rows = table_frame(tidy, key_t)
            label = str(rec.row)
            if label.endswith("."):
                k = int(label[:-1]) - 1
            else:
                k = next((i for i, v in enumerate(rows["label"]) if v == label), -1)
            value = None
            if 0 <= k < len(rows):
                name = TIDY_NAMES.get(rec.column, rec.column)
                v = rows[name].iloc[k] if name in rows else None   # a blank printed cell has no tidy row
                value = None if v is None else float(v)
            flagged = NOT_REPRODUCIBLE.get((key_t, label, rec.column, rec.printed))
            departs = REASONS.get((key_t, rec.column), "follows from the cells above") if exact else None
            cells.append(numeric_cell(table, label, rec.column, rec.printed, value, flagged, departs))
    return cells
