"""The robust-design example's figure: mean and spread of Y against the target with the three
estimates of t_min (drawn in the house style of :mod:`driver.plotting`)."""
from __future__ import annotations

from typing import Any

import numpy as np

from driver.deck import Params

__all__ = ["fits_figure"]


def fits_figure(p: Params, r: dict[str, Any]):
    """The section's results on one page: mean and spread of Y against the target, the three
    estimates of t_min (driver.plotting.robust_design_figure)."""
    from driver import plotting
    b = np.array(p.true_coeffs, float)
    sx = p.sigma_x
    t = np.linspace(min(r["t22"].min(), r["t24_targets"].min()) - 1.0,
                    max(r["t22"].max(), r["t24_targets"].max()) + 1.0, 401)
    exact_sigma = np.sqrt((b[1] + 2 * b[2] * t) ** 2 * sx ** 2 + 2 * b[2] ** 2 * sx ** 4)
    quad = lambda c: c[0] + c[1] * t + c[2] * t * t  # noqa: E731
    means = {"known relation (2.1)": quad(b), "dual response fit (2.7)": quad(r["eq27"]),
             "Taguchi fit (2.11)": quad(r["eq211"])}
    spreads = {"tolerance analysis of (2.1), eq. (2.2)": exact_sigma,
               "dual response fit (2.8)": np.exp(quad(r["eq28"])),
               "Taguchi fit (2.12)": np.exp(quad(r["eq212"])),
               "tolerance analysis of (2.7), eq. (2.14)": np.array([r["sigma_at"](x) for x in t])}
    if p.printed_eq212 is not None:
        spreads["(2.12) as printed (mostly off the scale)"] = np.exp(np.clip(quad(np.array(p.printed_eq212, float)), -700, 700))
    points = {"Table 2.2 (dual response)": (r["t22"], r["mean22"], r["std22"]),
              "Table 2.5 (Taguchi)": (r["t24_targets"], r["mean25"], r["std25"])}
    tmins = {"true (2.2)": r["eq22_tmin"], "dual response (2.9)": r["eq29"], "Taguchi (2.13)": r["eq213"],
             "tolerance analysis (2.15)": r["eq215"]}
    return plotting.robust_design_figure(t, means, spreads, points, tmins, sx,
                                         title=p.title or "Taylor's robust-design example")
