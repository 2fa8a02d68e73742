"""Slider-crank figures: strain and deflection against crank angle, the element convergence, and the
time history of a benchmark run against its reference (drawn in the house style of
:mod:`driver.plotting`)."""
from __future__ import annotations

from driver.deck import Params
from driver.slidercrank.analysis import Case, history
from driver.slidercrank.spec import Model

__all__ = ["history_figure"]


def history_figure(model: Model, params: Params, case: Case, alpha: float, beta: float, ref: dict | None):
    """Midpoint deflection and rod elongation against time of a benchmark run, with the
    reference end state (Simeon 1996) marked."""
    from driver import plotting   # matplotlib is the optional [plot] extra: imported when drawn
    h = history(model, params, case.omega, case.n_elements, alpha, beta)
    refs = {}
    if ref is not None:
        refs = {"mid": (ref["t"], ref["q1"]), "elong": (ref["t"], ref["q4"])}
    return plotting.slidercrank_history_figure(
        h["time"], {"mid": h["mid"] * 1e3, "elong": h["elong"] * 1e6},
        {"mid": "midpoint deflection $q_1$ [mm]", "elong": "rod elongation $q_4$ [$\\mu$m]"},
        {k: (t, v * (1e3 if k == "mid" else 1e6)) for k, (t, v) in refs.items()},
        f"{'Simeon (1996) crank benchmark' if ref is not None else params.material}: {case.n_elements} elements "
        f"at {case.omega:g} rad/s, t = 0 to {params.end_time:g} s",
        "Simeon (1996), MEBDFI tol 1e-14")
