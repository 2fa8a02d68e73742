"""One &pendulum deck run: the period, the half swing tabulated, the summary and the figure."""
from __future__ import annotations

import pandas as pd

from driver._deck import Params
from driver._export import with_units
from driver._result import Figure, Result
from driver._runner import study_run
from driver._table import Column, render_table

from ._analysis import half_swing
from ._batch import summarise
from ._spec import SPEC

__all__ = ["run"]


@study_run(SPEC)
def run(params: Params, progress: bool = False) -> Result:
    """Period and half swing of the deck's rod."""
    p = params
    s = summarise(p)
    t, theta = half_swing(p, s["period_s"])
    lines = [f"  rigid pendulum: uniform rod L = {p.length:g} m, g = {p.gravity:g} m/s^2, "
             f"amplitude {p.amplitude_deg:g} deg" + (f" -- {p.title}" if p.title else ""), "",
             f"    period ............... {s['period_s']:.6f} s",
             f"    small-angle period ... {s['small_angle_period_s']:.6f} s (ratio {s['period_ratio']:.6f})", ""]
    lines += render_table([Column("t [s]", "f", 10, 5), Column("theta [deg]", "f", 12, 4)], zip(t, theta))
    tidy = with_units(pd.DataFrame({"time_s": t, "theta_deg": theta}))
    return Result(text="\n".join(lines) + "\n", tidy=tidy, summary=s,
                  figures=[Figure("swing", lambda: _figures().swing_figure(t, theta, p.title or "rigid pendulum"))])


def _figures():
    """The figure module, imported when a figure is drawn (matplotlib is the optional [plot] extra)."""
    from . import _figures as figures
    return figures
