"""The printed results of section 2.3 of [Ma'arif 2006]: what mode = 'report' and mode = 'exact'
change and why, the printed values that do not reproduce, and the run beside them."""
from __future__ import annotations

from driver import _published as record
from driver._deck import Params
from driver._published import numeric_cell
from driver._result import Result
from driver.robust_example._spec import MODE_REASONS

__all__ = ["NOT_REPRODUCIBLE", "compare"]


#: printed results of section 2.3 that the printed data do not give, (item, index) -> why
NOT_REPRODUCIBLE = {
    **{("eq212", i): "(2.12) printed coefficients are corrupt: the fit to ln(std) of Table 2.5 gives 29.3118, "
                     "-4.65146, 0.155077; the printed ones give sigma_Y(10) = 0.0004 instead of 0.18 and "
                     "t_min = 15.026 (a transcription error)" for i in range(3)},
    ("std25", 1): "last printed digit: the sample std of the Table 2.4 row is 0.00381881 (prints 0.0038188)",
    ("std25", 2): "last printed digit: the sample std of the Table 2.4 row is 0.18513509 (prints 0.1851351)",
}


def compare(params: Params, result: Result) -> list[dict]:
    """The run beside the printed results of section 2.3: one dict per printed value."""
    tidy = result.tidy
    values = {(str(i), int(k)): float(v) for i, k, v in zip(tidy["item"], tidy["index"], tidy["value"])}
    exact = params.mode == "exact"
    cells = []
    for path in record.records("robust_example"):
        pub = record.read_blocks(path)
        for rec in record.printed_cells(pub.cells):
            item, index = str(rec.row).rstrip("]").split("[")
            key = (item, int(index))
            departs = MODE_REASONS.get(item, "follows from the unrounded fits") if exact else None
            cells.append(numeric_cell(f"Section 2.3 {rec.note}", rec.row, "value", rec.printed, values.get(key),
                                       NOT_REPRODUCIBLE.get(key), departs))
    return cells
