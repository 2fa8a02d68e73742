"""The &pendulum keys, their labels and headline columns, and the run's budget estimate."""
from __future__ import annotations

from driver._deck import GroupSpec, Key, Params, positive
from driver._limits import Estimate
from driver._study import contract_doc

__all__ = ["SPEC", "LABELS", "SWEEP_PLOT", "SWEEP_BEST", "MAX_AMPLITUDE_DEG", "estimate"]

#: amplitudes a deck may give [deg]: 0 < theta0 < 180 (at 180 deg the rod balances upright)
MAX_AMPLITUDE_DEG = 179.0


def _amplitude(v: float) -> str | None:
    return None if 0.0 < v <= MAX_AMPLITUDE_DEG else f"must be in (0, {MAX_AMPLITUDE_DEG:g}] deg"


def _points(v: int) -> str | None:
    return None if 2 <= v <= 100_000 else "must be 2 to 100000"


SPEC = GroupSpec("pendulum", {
    "length": Key("float", required=True, check=positive, units="m", doc="rod length L (uniform rod, pivot at one end)"),
    "gravity": Key("float", default=9.80665, check=positive, units="m/s^2", doc="gravitational acceleration g"),
    "amplitude_deg": Key("float", required=True, check=_amplitude, units="deg", doc="release angle theta0 from the vertical"),
    "points": Key("int", default=13, check=_points, doc="time points of the tabulated half swing"),
    "title": Key("str", default="", doc="free text for the output"),
}, doc="rigid pendulum (uniform rod) at finite amplitude: period and swing")

#: axis labels of summary columns and deck keys: name -> (words, units)
LABELS = {"period_s": ("period", "s"), "small_angle_period_s": ("small-angle period", "s"),
          "period_ratio": ("period over small-angle period", "-"), "amplitude_deg": ("amplitude", "deg")}

#: what a sweep plots when its deck names no plot_y, and which end of a column is the better design
SWEEP_PLOT = ("period_s", "period_ratio")
SWEEP_BEST = {"period_ratio": "min"}


@contract_doc
def estimate(params: Params) -> Estimate:
    """Estimate the memory and work of a run from the keys alone: about 200 bytes and 2 us per
    tabulated point, plus a fixed 1 MB / 10 ms.

    %(estimate)s
    """
    n = float(params.points)
    return Estimate(1e6 + 200.0 * n, 0.01 + 2e-6 * n, "points", "points", f"{n:.0f} time points")
