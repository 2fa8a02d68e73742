"""The robust-design example's figure: mean and spread of Y against the target with the
estimates of t_min.

Drawn in the house style (:mod:`driver.plotting`); this module imports matplotlib (the optional
[plot] extra), so the study imports it only when a figure is drawn.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure

from driver._deck import Params
from driver.plotting import new_figure, plain_text, styled, suptitle


@styled
def robust_design_figure(t: np.ndarray, means: dict[str, np.ndarray], spreads: dict[str, np.ndarray],
                         points: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]],
                         tmins: dict[str, float | None], sigma_x: float, title: str = "", axes=None) -> Figure:
    """Taylor's robust-design example: the mean of Y (top) and its spread (bottom, log axis)
    against the target t, every fitted curve beside the known relation's, the measured means
    and standard deviations as markers, and the estimates of the target of least spread as
    vertical lines.  ``means``/``spreads``: {label: values on ``t``}; ``points``: {label: (t,
    mean, std)}; ``tmins``: {label: t_min or None}.  ``axes``: two axes to draw into."""
    if axes is None:
        fig, axes = new_figure(2, 1, sharex=True, figsize=(7.6, 6.4))
    else:
        fig = axes[0].figure
    top, bot = axes
    styles = ["-", "--", "-.", ":", (0, (5, 1, 1, 1))]
    for k, (label, y) in enumerate(means.items()):
        top.plot(t, y, ls=styles[k % len(styles)], color=f"C{k}", lw=1.5, label=label)
    for k, (label, y) in enumerate(spreads.items()):
        printed = "printed" in label
        bot.plot(t, y, ls=":" if printed else styles[k % len(styles)], color="0.5" if printed else f"C{k}",
                 lw=1.2 if printed else 1.6, label=label)
    for k, (label, (pt, m, sd)) in enumerate(points.items()):
        mk = "os"[k % 2]
        top.plot(pt, m, mk, ms=6, mfc="white", mec="k", label=label)
        bot.plot(pt, sd, mk, ms=6, mfc="white", mec="k", label=label)
    for k, (label, tm) in enumerate(tmins.items()):
        if tm is not None and np.isfinite(tm):
            bot.axvline(tm, color=f"C{k}", lw=0.9, ls=(0, (2, 2)), alpha=0.9,
                        label=rf"$t_{{min}}$ {label} = {tm:.3f}")
    top.set_ylabel(r"mean of $Y$, $\mu_Y$")
    bot.set_ylabel(r"spread of $Y$, $\sigma_Y$ (log)")
    bot.set_yscale("log")
    bot.set_xlabel(rf"target $t$ (X varies about $t$ with $\sigma_x$ = {sigma_x:g})")
    finite = np.concatenate([y[np.isfinite(y) & (y > 0)] for label, y in spreads.items() if "printed" not in label]
                            + [sd for _, _, sd in points.values()])
    if finite.size:
        bot.set_ylim(max(finite.min() * 0.5, 1e-6), finite.max() * 3.0)
    top.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    bot.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    if title:
        suptitle(fig, plain_text(title))
    return fig


# ----------------------------------------------------------------------------- figures of a run
def fits_figure(p: Params, r: dict[str, Any]):
    """The section's results on one page: mean and spread of Y against the target, the three
    estimates of t_min (:func:`robust_design_figure`)."""
    b = np.array(p.true_coeffs, float)
    sx = p.sigma_x
    t = np.linspace(min(r["t22"].min(), r["t24_targets"].min()) - 1.0,
                    max(r["t22"].max(), r["t24_targets"].max()) + 1.0, 401)
    exact_sigma = np.sqrt((b[1] + 2 * b[2] * t) ** 2 * sx ** 2 + 2 * b[2] ** 2 * sx ** 4)
    quad = lambda c: c[0] + c[1] * t + c[2] * t * t
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
    return robust_design_figure(t, means, spreads, points, tmins, sx,
                                title=p.title or "Taylor's robust-design example")
