"""The pendulum's computation through its kernel: periods of many rods at once, and one half swing."""
from __future__ import annotations

import numpy as np

from driver._deck import Params

from . import _kernel as kernel

__all__ = ["periods", "half_swing"]


def periods(length: np.ndarray, gravity: np.ndarray, amplitude_deg: np.ndarray) -> dict[str, np.ndarray]:
    """Period [s], small-angle period [s] and their ratio of rods of ``length`` [m] under ``gravity``
    [m/s^2] released at rest from ``amplitude_deg`` [deg] (arrays of one value per rod)."""
    t, t0 = kernel.periods(length, gravity, np.radians(amplitude_deg))
    return {"period_s": t, "small_angle_period_s": t0, "period_ratio": t / t0}


def half_swing(p: Params, period: float) -> tuple[np.ndarray, np.ndarray]:
    """The deck's ``points`` times [s] over half a ``period`` and the angle there [deg]: from
    release at +amplitude to -amplitude."""
    t = np.linspace(0.0, 0.5 * period, p.points)
    return t, np.degrees(kernel.swing(p.length, p.gravity, np.radians(p.amplitude_deg), t))
