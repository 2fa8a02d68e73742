"""The best case of a sweep, run in full when asked (``--report``): what the report page draws.

The best case is the kept, ok case with the best value of the first plotted column
(:func:`driver.sweep._report.plotted_columns`) where the study says which way is better
(``Study.sweep_best``), else the first kept case.  It is run again by the study (a sweep keeps
summaries, not every case's tables and figures), from its case deck as the sweep built it.
"""
from __future__ import annotations

from typing import Any

import pandas as pd

from driver._deck import Params, RawGroup, validate
from driver._outcome import SweepOutcome
from driver._output import column_label
from driver._runner import compute
from driver.sweep._report import plotted_columns, with_plotted
from driver.sweep._spec import Grid, case_at, case_raw

__all__ = ["best_row", "attach_best"]


def best_row(summary: pd.DataFrame, sw: Params, module: Any) -> tuple[Any, str]:
    """The summary index of the best case and why it is the best, in words; (None, '') when no
    case is ok and kept."""
    from driver.plotting import best_index
    shown = with_plotted(summary, sw)
    ok = shown[shown["status"] == "ok"] if "status" in shown else shown
    kept = ok[ok["kept"].astype(bool)] if "kept" in ok else ok
    wanted = plotted_columns(shown, sw, module)
    sense = module.sweep_best.get(wanted[0]) if wanted else None
    best = best_index(ok, wanted[0], sense) if wanted else None
    if best is not None:
        return best, ("largest " if sense == "max" else "smallest ") + column_label(module, wanted[0]).split(" [")[0]
    if len(kept):
        return kept.index[0], "the first kept case"
    return None, ""


def attach_best(oc: SweepOutcome, summary: pd.DataFrame, sw: Params, module: Any, raw: RawGroup, grid: Grid) -> None:
    """Run the best case of the sweep in full and put it on the outcome (``best``, ``best_case``,
    ``best_by``); nothing when no case is ok and kept."""
    index, why = best_row(summary, sw, module)
    if index is None:
        return
    case = case_at(grid, int(summary.loc[index, "case"]))
    result = compute(module, validate(case_raw(raw, case), module.spec, sw.path))
    result.name, result.study = f"{oc.name}_case{case.index}", module.name
    oc.best, oc.best_case, oc.best_by = result, case.index, why
