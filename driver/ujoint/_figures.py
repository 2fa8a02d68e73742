"""The Hooke-joint figures: output speed of every design against the input angle (Cartesian or
polar), the paper's band shaded; with a load on the output shaft, the input torque over a turn.

Drawn in the house style (:mod:`driver.plotting`); this module imports matplotlib (the optional
[plot] extra), so the study imports it only when a figure is drawn.
"""
from __future__ import annotations

from collections.abc import Sequence

import matplotlib
import matplotlib.colors
import matplotlib.ticker
import numpy as np
from matplotlib.figure import Figure

from driver.plotting import new_figure, plain_text, styled, suptitle
from driver.ujoint._analysis import Chain, Design, input_torque, output_speed, textbook

#: line styles of the Hooke-joint designs, by the label driver.ujoint gives them
_UJOINT_STYLES = {"trial": dict(color="C1", lw=1.4), "design": dict(color="C1", lw=1.4),
                  "optimum": dict(color="C0", lw=2.0), "last iterate": dict(color="C3", lw=1.6, ls="-."),
                  "paper printed": dict(color="C2", lw=1.2, ls=":")}


@styled
def ujoint_speed_figure(theta_deg: np.ndarray, rpm: float, curves: dict[str, np.ndarray],
                        polar: bool = False, band: Sequence[float] | None = None, title: str = "",
                        ax=None, origin: str = "theta from the normal to joint 1's plane",
                        ratio_one: dict[str, np.ndarray] | None = None) -> Figure:
    """Input and output shaft speed [rpm] against the input angle [deg], every design (trial,
    optimum, the paper's printed optimum) overlaid on one panel as in the paper's Figures 6-11,
    with the paper's trial band ``band`` = (min, max) [rpm] shaded when given.

    Cartesian or polar (angle = input angle, radius = speed); the polar radius starts near
    the slowest speed, not at 0, so a fluctuation of a fraction of an rpm stays visible (the
    empty centre says the radius does not start at 0).  ``origin`` says where the input angle is
    0 (the deck's angle_origin), in the axis label; ``ratio_one``: per design the input angles
    [deg] where its output speed equals the input's, marked on the input-speed line."""
    if ax is not None:   # the caller's axes (a polar one for polar = True)
        fig = ax.figure
    elif polar:
        fig = Figure(figsize=(7.4, 5.2), layout="constrained")
        ax = fig.add_subplot(1, 1, 1, projection="polar")
    else:
        fig, (ax,) = new_figure(1, 1, figsize=(7.4, 4.0))
    x = np.radians(theta_deg) if polar else theta_deg
    values = [rpm, *(float(v) for w in curves.values() for v in (np.min(w), np.max(w)))] + list(band or [])
    low, top = min(values), max(values)
    pad = 0.08 * max(top - low, 1e-3 * rpm)
    if band is not None:
        lo, hi = band
        text = f"paper's trial band {lo:g}-{hi:g} rpm (read off its plot)"
        if polar:
            ax.fill_between(x, lo, hi, color="0.5", alpha=0.15, lw=0, label=text)
        else:
            ax.axhspan(lo, hi, color="0.5", alpha=0.15, lw=0, label=text)
    for k, (label, w) in enumerate(curves.items()):
        style = _UJOINT_STYLES.get(label, dict(color=f"C{k + 4}", lw=1.4))
        ax.plot(x, w, label=f"{label}: output {np.min(w):.2f}-{np.max(w):.2f} rpm", **style)
    # the input speed last and on top: an optimum close to it must not hide it
    ax.plot(x, np.full_like(theta_deg, rpm, dtype=float), "k--", lw=1.1, zorder=5, label=f"input shaft {rpm:g} rpm")
    marks = np.concatenate([np.asarray(v, float) for v in (ratio_one or {}).values()] or [np.empty(0)])
    if marks.size:
        ax.plot(np.radians(marks) if polar else marks, np.full(marks.size, rpm), "o", ms=4, mfc="none", mec="k",
                zorder=4.5, label="output speed = input speed")   # under the input line (on top, zorder 5)
    if polar:
        ax.set_rlim(low - pad, top + pad)
        ax.set_rorigin(low - pad - 0.6 * (top - low + 2 * pad))
        ticks = [t for t in matplotlib.ticker.MaxNLocator(4).tick_values(low - pad, top + pad)
                 if low - pad <= t <= top + pad]
        ax.set_yticks(ticks)
        ax.set_yticklabels([])
        for t in ticks:   # radial labels cross the curves: drawn on a white patch, above them
            ax.text(np.radians(112.5), t, f"{t:g} rpm", fontsize=7.5, ha="center", va="center", zorder=6,
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.85))
        ax.set_xlabel(f"input angle [deg, {origin}]; radius: shaft speed [rpm], not starting at 0", fontsize=8)
        fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=2, frameon=False)
    else:
        ax.set_ylim(low - pad, top + pad)
        ax.set_ylabel("shaft speed [rpm]")
        ax.set_xlabel(f"input angle [deg, {origin}]")
        ax.set_xlim(0.0, 360.0)
        ax.set_xticks(np.arange(0, 361, 45))
        fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=2, frameon=False)
    suptitle(fig, f"{plain_text(title)}: Hooke-joint chain, input and output shaft speed" if title
                 else "Hooke-joint chain: input and output shaft speed")
    return fig


# ----------------------------------------------------------------------------- figures of a run
def speed_figure(chain: Chain, designs: list[Design], polar: bool, band: list[float] | None = None, title: str = "",
                 origin: str = "theta from the normal to joint 1's plane"):
    """The speed figure: every design overlaid, the paper's trial band (``paper_band``) shaded,
    the input angles where an output speed equals the input's marked; ``origin`` names the input
    angle's origin."""
    theta = np.arange(0.0, 360.0 + 1e-9, 1.0)
    curves = {d.label: output_speed(chain, d, theta)[0] for d in designs}
    ones = {d.label: textbook(chain, d).ratio_one for d in designs if d.label != "paper printed"}
    return ujoint_speed_figure(theta, chain.rpm, curves, polar=polar, band=band, title=title, origin=origin,
                               ratio_one=ones)


@styled
def ujoint_torque_figure(theta_deg: np.ndarray, curves: dict[str, np.ndarray], load_torque: float,
                         peaks: dict[str, tuple[np.ndarray, np.ndarray]] | None = None, title: str = "",
                         ax=None, origin: str = "theta from the normal to joint 1's plane",
                         load_text: str = "") -> Figure:
    """Input-shaft torque [N m] against the input angle [deg] of every design: what the input
    must supply to turn the output shaft's inertia and load at constant input speed.

    ``curves`` maps a design's label to its torque at ``theta_deg``; the load torque
    ``load_torque`` [N m] is drawn as the level the torque averages to over a turn (the input's
    mean power is the load's); ``peaks`` maps a label to the input angles [deg] and signed values
    [N m] of its peak magnitude (root-found, marked); ``load_text`` names the load in the title."""
    if ax is not None:
        fig = ax.figure
    else:
        fig, (ax,) = new_figure(1, 1, figsize=(7.4, 4.0))
    for k, (label, t) in enumerate(curves.items()):
        style = _UJOINT_STYLES.get(label, dict(color=f"C{k + 4}", lw=1.4))
        ax.plot(theta_deg, t, label=f"{label}: {np.min(t):.4g} to {np.max(t):.4g} N m, mean {np.mean(t[:-1]):.4g}",
                **style)
        at, value = (peaks or {}).get(label, (np.empty(0), np.empty(0)))
        if len(at):
            ax.plot(at, value, "o", ms=5, mfc="none", mec=style.get("color", "k"), zorder=4,
                    label=f"{label}: peak |T_in| {np.max(np.abs(value)):.4g} N m at {', '.join(f'{a:.1f}' for a in at)} deg")
    ax.axhline(load_torque, color="k", ls="--", lw=1.1, zorder=5,
               label=f"load torque {load_torque:g} N m (the mean input torque over a turn)")
    ax.set_xlim(0.0, 360.0)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlabel(f"input angle [deg, {origin}]")
    ax.set_ylabel("input torque T_in [N m]")
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=1, frameon=False, fontsize=8)
    what = f"Hooke-joint chain, input torque at constant input speed{': ' + load_text if load_text else ''}"
    suptitle(fig, f"{plain_text(title)}: {what}" if title else what)
    return fig


def torque_figure(chain: Chain, designs: list[Design], title: str = "",
                  origin: str = "theta from the normal to joint 1's plane"):
    """The input-torque figure of a chain with an output load (``chain.load``): every design's
    input torque over a turn (0.5 deg apart), its root-found peak marked, the load torque drawn."""
    assert chain.load is not None
    theta = np.arange(0.0, 360.0 + 1e-9, 0.5)
    curves = {d.label: input_torque(chain, d, theta) for d in designs}
    peaks = {}
    for d in designs:
        tb = textbook(chain, d)
        # a torque constant over the turn peaks everywhere: nothing to mark
        if tb.torque_peak is not None and 0 < len(tb.torque_peak_at) <= 8:
            peaks[d.label] = (np.asarray(tb.torque_peak_at, float), np.asarray(tb.torque_peak_signed, float))
    inertia, load = chain.load
    return ujoint_torque_figure(theta, curves, load, peaks=peaks, title=title, origin=origin,
                                load_text=f"output inertia {inertia:g} kg m^2, load {load:g} N m, {chain.rpm:g} rpm")
