"""Hooke-joint figures: output speed of every design against the input angle (Cartesian or polar),
the paper's band shaded (drawn in the house style of :mod:`driver.plotting`)."""
from __future__ import annotations

import numpy as np

from driver.ujoint.analysis import Chain, Design, output_speed

__all__ = ["speed_figure"]


def speed_figure(chain: Chain, designs: list[Design], polar: bool, band: list[float] | None = None, title: str = ""):
    """The speed figure: every design overlaid, the paper's trial band (``paper_band``) shaded."""
    from driver.plotting import ujoint_speed_figure
    theta = np.arange(0.0, 360.0 + 1e-9, 1.0)
    curves = {d.label: output_speed(chain, d, theta)[0] for d in designs}
    return ujoint_speed_figure(theta, chain.rpm, curves, polar=polar, band=band, title=title)
