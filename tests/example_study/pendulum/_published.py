"""The run beside a published table: the complete elliptic integral K of Abramowitz and Stegun's
Table 17.1 (by modular angle alpha), to 10 decimals.  The period ratio of a pendulum released
from theta0 is T / T0 = 2 K / pi with alpha = theta0 / 2, so a run at amplitude 60, 90 or 120 deg
prints K(30 deg), K(45 deg) or K(60 deg) as its period ratio times pi / 2."""
from __future__ import annotations

import math

from driver._deck import Params
from driver._published import numeric_cell
from driver._result import Result

__all__ = ["K_PRINTED", "compare"]

#: K(alpha) as printed, by modular angle alpha [deg]
K_PRINTED = {30: "1.6857503548", 45: "1.8540746773", 60: "2.1565156475"}


def compare(params: Params, result: Result) -> list[dict]:
    """The run's K = (T / T0) pi / 2 beside the printed K of its modular angle (none when the
    table has no row for the run's amplitude)."""
    alpha = params.amplitude_deg / 2.0
    printed = K_PRINTED.get(round(alpha)) if float(alpha).is_integer() else None
    if printed is None:
        return []
    k = result.summary["period_ratio"] * math.pi / 2.0
    return [numeric_cell("Abramowitz and Stegun, Table 17.1", f"alpha = {alpha:g} deg", "K", printed, k, None, None)]
