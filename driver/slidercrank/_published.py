"""The slider-crank run beside the published record: Table 1 of [Andalas] (the rod data) and the
Simeon (1996) crank benchmark's reference end state."""
from __future__ import annotations

from driver import _published as record
from driver._deck import Params
from driver._published import cell
from driver._result import Result
from driver.slidercrank._spec import MATERIALS

__all__ = ["compare", "SIMEON_REL_TOL"]

#: relative tolerance of the Simeon (1996) comparison: the tool's linear KED model against the
#: reference's nonlinear modal model (docs/slidercrank.md)
SIMEON_REL_TOL = 5e-3


def compare(params: Params, result: Result) -> list[dict]:
    """The run beside Table 1 of [Andalas] and the Simeon (1996) reference solution."""
    cells = []
    for path in record.records("slidercrank"):
        pub = record.read_blocks(path)
        if not record.matches(pub.match, params):
            continue
        if "benchmark" in pub.match:       # the Simeon (1996) reference solution, from the run's Table 4
            printed_rows = {}
            for line in result.text.splitlines():
                for sym in ("q1", "q4", "x3", "phi2"):
                    if f"({sym})" in line:
                        printed_rows[sym] = float(line.split()[-3])
            ref = pub.cells[pub.cells["table"].str.startswith("Reference")]
            table = f"Simeon (1996) at t = {ref[ref['row'] == 't_s']['printed'].iloc[0]} s (within 0.5 %)"
            for rec in record.printed_cells(ref[ref["row"] != "t_s"]):
                sym = str(rec.row).split("_")[0]
                value = printed_rows.get(sym)
                if value is None:
                    cells.append(cell(table, rec.row, "", rec.printed, "", "differs", "the run has no such value"))
                    continue
                rel = (value - float(rec.printed)) / abs(float(rec.printed))
                comp = f"{value:.9e}" if abs(value) < 1e-3 else f"{value:.7f}"
                cells.append(cell(table, rec.row, "value", rec.printed, comp,
                                   "agrees" if abs(rel) <= SIMEON_REL_TOL else "differs",
                                   f"relative difference {100 * rel:+.3f} % (tolerance {100 * SIMEON_REL_TOL:g} %)"))
            continue
        material = params["material"]
        if material not in MATERIALS:
            continue                        # a custom rod: the paper's tables do not apply
        mat = dict(MATERIALS[material], length=params.rod_length)
        used = {"length_m": mat["length"], "area_m2": mat["area"], "second_moment_m4": mat["second_moment"],
                "density_kg_m3": mat["density"], "youngs_modulus_pa": mat["youngs_modulus"],
                "slider_mass_kg": params.slider_mass,
                "bearing_masses_kg": params.bearing_mass_crank + params.bearing_mass_slider,
                "crank_radius_m": params.crank_radius}
        for rec in record.printed_cells(pub.cells):
            if rec.table == "Table 1a" and rec.row != material:
                continue
            key = rec.column if rec.table == "Table 1a" else str(rec.row)
            value = float(used[key])
            same = abs(value - float(rec.printed)) <= 1e-12 * abs(float(rec.printed))
            cells.append(cell(str(rec.table), rec.row, rec.column if rec.table == "Table 1a" else "value",
                               rec.printed, f"{value:g}", "identical" if same else "departs",
                               "" if same else "the deck sets another value than the paper"))
    return cells
