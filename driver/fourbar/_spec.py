"""The ``&fourbar`` keys (with their checks), axis labels, sweep headline columns, and the budget
estimate of a run.

Lengths in any consistent unit; angles in degrees in decks and tables; crank speed in rad/s,
accelerations in rad/s^2."""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from driver._deck import GroupSpec, Key, Params, positive
from driver._limits import Estimate
from driver._study import contract_doc
from driver.fourbar import _forces as forces

__all__ = ['SPEC', 'LABELS', 'SWEEP_BEST', 'SWEEP_PLOT', 'SUMMARY_SETTINGS', 'BAND', 'MAX_ANGLE', 'band_of', 'estimate']


MAX_ANGLE = 1.0e6   # |crank angle| [deg] a deck may give (ulp of 1e6 is 1.2e-10 deg)


BAND = (40.0, 120.0)  # transmission-angle band recommended by the paper [deg]: transmission_band_deg's default


def _band_check(v: Any) -> str | None:
    """Key check of ``transmission_band_deg``: two angles 0 <= min < max <= 180 [deg]."""
    if len(v) != 2:
        return f"give two angles, the band's minimum and maximum in deg (got {len(v)} values)"
    lo, hi = v
    if not (0.0 <= lo < hi <= 180.0):
        return f"the band needs 0 <= min < max <= 180 deg (got {lo:g}, {hi:g})"
    return None


def band_of(p: Mapping[str, Any]) -> tuple[float, float]:
    """The deck's transmission-angle band (min, max) [deg] (the paper's 40-120 deg by default)."""
    v = p.get("transmission_band_deg") if hasattr(p, "get") else None
    return (float(v[0]), float(v[1])) if v is not None and len(v) == 2 else BAND


def _check(p: Params) -> None:
    """Cross-key checks: step, range, and what the listing method can do."""
    if p.step_deg == 0:
        raise p.error("step_deg", "must not be 0 (the crank angle would never advance)")
    for key in ("start_deg", "stop_deg"):
        if abs(p[key]) > MAX_ANGLE:
            raise p.error(key, f"|{p[key]:g}| deg is beyond {MAX_ANGLE:g} deg: a crank angle that large has lost "
                               "its fraction of a degree in double precision (the motion repeats every 360 deg)")
    span = p.stop_deg - p.start_deg
    if span * p.step_deg < 0:
        raise p.error("step_deg", f"steps away from stop_deg ({p.start_deg:g} -> {p.stop_deg:g} "
                                  f"with step {p.step_deg:g})")
    if abs(span / p.step_deg) > 5_000_000:
        raise p.error("step_deg", "more than 5e6 crank positions; use a coarser step")
    if p.method == "listing":
        for key in ("start_deg", "stop_deg", "step_deg"):
            if not float(p[key]).is_integer():
                raise p.error(key, "method='listing' steps in whole degrees like the published program "
                                   f"(got {p[key]:g}); use method='exact' for fractional angles")
        if "branch" in p.given and p.branch != "open":
            raise p.error("branch", "the listing computes one assembly only; branch applies to method='exact'")
    forces.check(p)


#: axis labels of summary columns and deck keys (driver._output.column_label): name -> (words, units)
LABELS = {"crank": ("crank length", "length units"), "coupler": ("coupler length", "length units"),
          "rocker": ("rocker length", "length units"),
          "fixed_link": ("ground link length", "length units"), "omega": ("crank speed", ""),
          "mu_min_deg": ("minimum transmission angle", "deg"), "mu_max_deg": ("maximum transmission angle", "deg"),
          "rocker_swing_deg": ("rocker swing", "deg"),
          "omega3_peak_rad_s": ("peak rocker speed (signed: the largest in size)", "rad/s"),
          "omega2_peak_rad_s": ("peak coupler speed (signed: the largest in size)", "rad/s"),
          "assembled_fraction": ("fraction of the turn assembled", "-"),
          "time_ratio": ("time ratio (slow / quick stroke)", "-"), **forces.LABELS}


#: which way a summary column is better (the design-space maps star the best kept design)
SWEEP_BEST = {"mu_min_deg": "max", "mu_max_deg": "min", "rocker_swing_deg": "max", "omega3_peak_rad_s": "min",
              "omega2_peak_rad_s": "min"}


#: keys of the base deck the summary columns depend on (transmission_band_deg: meets_transmission_band):
#: a sweep's and an optimisation's .out state them, their summary/evals Parquet tables record them
SUMMARY_SETTINGS = ("transmission_band_deg",)


#: what a sweep summary plots when its deck names no plot_y
SWEEP_PLOT = ("mu_min_deg", "mu_max_deg", "rocker_swing_deg", "omega3_peak_rad_s", "omega2_peak_rad_s",
              "assembled_fraction")


SPEC = GroupSpec(
    name="fourbar",
    doc="planar four-bar linkage driven by its crank at constant speed",
    keys={
        "fixed_link": Key("float", required=True, check=positive, units="length", doc="ground link O_A-O_B"),
        "crank": Key("float", required=True, check=positive, units="length", doc="input link O_A-A"),
        "coupler": Key("float", required=True, check=positive, units="length", doc="coupler A-B"),
        "rocker": Key("float", required=True, check=positive, units="length", doc="output link O_B-B"),
        "omega": Key("float", default=1.0, units="rad/s", doc="crank angular velocity (ccw positive)"),
        "alpha": Key("float", default=0.0, units="rad/s^2", doc="crank angular acceleration (exact method)"),
        "step_deg": Key("float", required=True, units="deg", doc="crank-angle step"),
        "start_deg": Key("float", default=0.0, units="deg", doc="first crank angle"),
        "stop_deg": Key("float", default=360.0, units="deg", doc="last crank angle (inclusive)"),
        "method": Key("str", default="exact", choices=("exact", "listing"),
                      doc="'listing' = published program cell for cell; 'exact' = closed loop"),
        "branch": Key("str", default="open", choices=("open", "crossed"),
                      doc="'open': B left of the line A->O_B; 'crossed': mirror assembly"),
        "transmission_band_deg": Key("floats", default=list(BAND), units="deg", check=_band_check,
                                     doc="the transmission-angle band a design should keep to (min, max): the "
                                         "summary's meets_transmission_band, the .out and the figures use it; "
                                         "default the paper's 40, 120"),
        "coupler_point": Key("floats", default=None, units="length",
                             check=lambda v: None if len(v) == 2 else f"give two numbers u, v (got {len(v)})",
                             doc="a point P on the coupler: u along A->B, v to its left; adds its path, "
                                 "velocity and acceleration (exact method)"),
        "title": Key("str", default="", doc="free text echoed in the output"),
        **forces.KEYS,   # the force analysis (driver/fourbar/_forces.py), run when 'mass' is given
    },
    check=_check,
)


@contract_doc
def estimate(params: Params) -> Estimate:
    """Estimate the memory and work of a run from the keys alone, before it allocates.

    Per crank angle a table row
    (text, two tidy frames, kernel columns; about 2 KB and 50 us of Python formatting), and the
    summary kernel's 1 deg scan of at most one turn (the motion is periodic; about 30 us).

    %(estimate)s
    """
    p = params
    try:
        n = float(math.floor((p.stop_deg - p.start_deg) / p.step_deg + 1e-9) + 1)
    except (OverflowError, ZeroDivisionError, ValueError):
        n = math.inf
    n = max(n, 1.0)
    span = min(abs(p.stop_deg - p.start_deg), 360.0) / 1.0 + 1.0
    range_key = "start_deg" if "start_deg" in p.given else ("stop_deg" if "stop_deg" in p.given else "step_deg")
    k = 2.5 if forces.active(p) else 1.0   # the force table and columns: 13 more cells and 24 columns per row
    rows = Estimate(k * 2000.0 * n + 5e6, k * 5e-5 * n + 0.05, "step_deg", "step_deg", f"{n:.4g} crank angles")
    grid = Estimate(500.0 * span, 1e-6 * span, range_key, range_key,
                    f"a {span:.4g}-point scan of one turn for the summary")
    return rows + grid
