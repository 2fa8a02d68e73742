"""The textbook closed forms a run is compared with (``python -m driver compare``): there is no
published table of this study; where a deck's mechanism is one of the textbook forms, its
summary is set beside the closed form [Uicker 2011]:

* an offset slider-crank (the first group an RRP or PRR from the crank pin onto a ground guide,
  its slide the output): stroke sqrt((l + r)^2 - e^2) - sqrt((l - r)^2 - e^2) and time ratio
  (180 + b) / (180 - b), b = asin(e / (l - r)) - asin(e / (l + r)) [deg];
* a slotted-lever quick-return base (the first group an RPR with its lever about a ground pivot,
  the block on the crank pin, the slot through the pivot; the lever the output): the lever's
  swing 2 asin(r / d) and time ratio (180 + b) / (180 - b), b = 2 asin(r / d), when the crank
  pivot lies outside the crank circle (d > r)."""
from __future__ import annotations

import math

from driver._deck import Params
from driver._published import cell
from driver._result import Result
from driver.linkage._kernel_program import Mechanism
from driver.linkage._spec_model import compile_deck

__all__ = ["compare", "closed_forms"]

TABLE = "closed forms [Uicker 2011]"


def closed_forms(p: Params, mech: Mechanism) -> dict[str, float]:
    """The closed-form figures of the deck's mechanism when it is a textbook form, by summary
    column (empty otherwise)."""
    if mech.driver != "crank" or not mech.dyads:
        return {}
    d = mech.dyads[0]
    pivot = mech.points[mech.driver_anchor - 1]
    r = mech.driver_length
    pin = mech.driver_pin
    if d.kind in ("rrp", "prr") and d.joints[0 if d.kind == "rrp" else 1] == pin and mech.output == (2, d.slide):
        gname = d.joints[1 if d.kind == "rrp" else 0]
        g = next(gd for gd in mech.guides if gd[0] == gname)
        if g[1] != 1:
            return {}
        l, off = d.d1, d.d2
        ux, uy = math.cos(g[4]), math.sin(g[4])
        e = (pivot[2] - g[2]) * -uy + (pivot[3] - g[3]) * ux - off   # the pivot's distance from the pin's line
        if not abs(e) < l - r:
            return {}
        b = math.degrees(math.asin(abs(e) / (l - r)) - math.asin(abs(e) / (l + r)))
        return {"stroke": math.sqrt((l + r) ** 2 - e * e) - math.sqrt((l - r) ** 2 - e * e),
                "time_ratio": (180 + b) / (180 - b)}
    if d.kind == "rpr" and d.joints[1] == pin and d.d1 == 0.0 and mech.output == (1, d.k1):
        lever = mech.points[d.a1 - 1]
        if lever[1] != 1:
            return {}
        dist = math.hypot(lever[2] - pivot[2], lever[3] - pivot[3])
        if not dist > r:
            return {}
        b = 2 * math.degrees(math.asin(r / dist))
        return {"stroke": b, "time_ratio": (180 + b) / (180 - b)}
    return {}


def compare(params: Params, result: Result) -> list[dict]:
    """Set the run's summary beside the closed forms of its mechanism (one dict per figure).

    Parameters
    ----------
    params : Params
        The validated ``&linkage`` deck.
    result : Result
        Its run.

    Returns
    -------
    list of dict
        One comparison cell per closed-form figure (none when the mechanism is not a textbook
        form): identical when the run prints the closed form's six significant digits.
    """
    out = []
    for column, value in closed_forms(params, compile_deck(params)).items():
        got = result.summary.get(column)
        printed = f"{value:.6g}"
        computed = "" if got is None else f"{got:.6g}"
        out.append(cell(TABLE, column, column, printed, computed, "identical" if computed == printed else "differs",
                        "" if computed == printed else "the run's summary against the closed form"))
    return out
