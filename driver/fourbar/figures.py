"""The four-bar figures of a run: angle, speed and transmission curves, and the linkage drawn at
its limit positions (drawn in the house style of :mod:`driver.plotting`)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from driver.deck import Params
from driver.fourbar.analysis import ST, coupler_point, exact_columns, exact_grid, grashof, limit_angles, tidy_frame
from driver.fourbar.spec import band_of
from driver.study import Figure

__all__ = ['deck_figures', 'output_name']


def output_name(p: Params) -> str:
    """What the output link is called in figures: 'output crank' when it turns fully (a
    double-crank, a drag link), 'rocker' otherwise."""
    g = grashof(p.fixed_link, p.crank, p.coupler, p.rocker)
    return "output crank" if g.name.startswith("double-crank") else "rocker"


def deck_figures(p: Params, stem_title: str, listing: pd.DataFrame | None) -> list[Figure]:
    def curves():
        from driver import plotting   # matplotlib is the optional [plot] extra: import when drawing
        theta = np.linspace(p.start_deg, p.stop_deg, 721)
        out, st = exact_grid(p, theta)
        exact = tidy_frame("exact", theta, exact_columns(out, st), st)
        return plotting.fourbar_curves(exact, listing, stem_title, band=band_of(p), output=output_name(p))

    def linkage():
        from driver import plotting
        lo, hi = sorted((p.start_deg, p.stop_deg))
        # the deck's crank range when it is less than a turn (a function generator's design range)
        theta = np.linspace(lo, hi, 721) if hi - lo < 360.0 else np.linspace(0.0, 360.0, 721)
        out, st = exact_grid(p, theta)
        cp = coupler_point(p, theta, out, st)
        limits = []
        for a in limit_angles(p.fixed_link, p.crank, p.coupler, p.rocker):
            if theta[0] - 1e-9 <= a <= theta[-1] + 1e-9 or hi - lo >= 360.0:
                row, rst = exact_grid(p, np.array([a]))
                if rst[0] != ST["no_assembly"] and np.all(np.isfinite(row[0, 3:7])):
                    limits.append((a, row[0]))
        return plotting.fourbar_linkage(p.fixed_link, theta, out, st == ST["ok"], listing, stem_title,
                                        point=None if cp is None else cp[:, :2], output=output_name(p),
                                        limits=limits)

    return [Figure("curves", curves), Figure("linkage", linkage)]
