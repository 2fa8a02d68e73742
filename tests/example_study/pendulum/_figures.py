"""The example study's figure, in the house style (driver.plotting)."""
from __future__ import annotations

import numpy as np

from driver import plotting


def swing_figure(t: np.ndarray, theta_deg: np.ndarray, title: str, ax=None):
    """theta [deg] against time [s] over half a swing."""
    return plotting.line_panels(t, [("angle [deg]", {"theta": theta_deg})], "time [s]", title,
                                axes=None if ax is None else [ax])
