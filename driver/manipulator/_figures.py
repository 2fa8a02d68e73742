"""The manipulator figures: the (l1, l2) design space with its reach conditions, iso-RI2 ellipses,
C_rob and the optima, and the motor torques along C_rob.

Drawn in the house style (:mod:`driver.plotting`); this module imports matplotlib (the optional
[plot] extra), so the study imports it only when a figure is drawn.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import matplotlib
import matplotlib.cm
import matplotlib.colors
import matplotlib.ticker
import numpy as np
from matplotlib.figure import Figure

from driver._deck import Params
from driver.manipulator import _kernel as kernel
from driver.manipulator._analysis import Conv, Workspace, optima
from driver.plotting import new_figure, plain_text, styled, suptitle


def _ellipse_levels(levels: Sequence[float], n: int) -> list[float]:
    """The RI2 values whose ellipses the design-space figure draws: the deck's (its Table 4.1
    rows) and, as RI2 = sqrt(n) is the C_rob circle itself, three more so the family shows."""
    lo, hi = math.sqrt(n), math.sqrt(2 * n)
    extra = [lo + f * (hi - lo) for f in (0.05, 0.2, 0.5)]
    return sorted({round(float(v), 12) for v in [*levels, *extra] if 0.0 < v < hi})


def ri2_ellipses(ri2: float, n: int, c: float, samples: int = 721) -> list[tuple[np.ndarray, np.ndarray]]:
    """The two iso-RI2 ellipses (the report's eqs 4.14-4.17) as (l1, l2) [m] point arrays, cut to
    l1, l2 >= 0: in the 45-deg frame L1 = (l1 + l2)/sqrt2, L2 = (l1 - l2)/sqrt2 they are
    RI2^2 L1^2 + (2n - RI2^2) L2^2 = c and the same with the coefficients swapped (c = sum d^2 [m^2])."""
    phi = np.linspace(0.0, 2.0 * np.pi, samples)
    out = []
    for ca, cb in ((ri2 * ri2, 2 * n - ri2 * ri2), (2 * n - ri2 * ri2, ri2 * ri2)):
        P, Q = math.sqrt(c / ca) * np.cos(phi), math.sqrt(c / cb) * np.sin(phi)
        x, y = (P + Q) / math.sqrt(2.0), (P - Q) / math.sqrt(2.0)
        keep = (x >= -1e-9) & (y >= -1e-9)
        out.append((np.where(keep, x, np.nan), np.where(keep, y, np.nan)))
    return out


#: the offsets above sqrt(n) of the RI2 contours and colour bands (RI2 runs from sqrt(n) on C_rob to sqrt(2n))
RI2_STEPS = (0.0, 0.01, 0.05, 0.1, 0.2, 0.4, 0.8)


def _ri2_scale(n: int) -> tuple[matplotlib.colors.Colormap, matplotlib.colors.BoundaryNorm, np.ndarray]:
    """The one colour scale of RI2 in both panels: bands from sqrt(n) (C_rob) to sqrt(2n), a
    colour map without a pale end (every band visible on white)."""
    lo, hi = math.sqrt(n), math.sqrt(2 * n)
    bounds = np.unique(np.concatenate([[lo], [lo + s for s in RI2_STEPS if 0 < s < hi - lo], [hi]]))
    base = matplotlib.colormaps["viridis"]
    cmap = matplotlib.colors.ListedColormap(base(np.linspace(0.0, 0.85, len(bounds) - 1)), name="ri2")
    return cmap, matplotlib.colors.BoundaryNorm(bounds, cmap.N), bounds


@styled
def manipulator_design_space(r: float, R: float, radius: float, L1: np.ndarray, L2: np.ndarray,
                             ri2: np.ndarray, sum_d2: float, n: int, levels: Sequence[float],
                             optima: dict, names: Sequence[str], l1: np.ndarray, l2: np.ndarray,
                             title: str = "") -> Figure:
    """Design space (l1, l2) [m] of a 2R arm, like the report's Figures 4.2-4.11.

    Left: reach region |l1 - l2| <= r, l1 + l2 >= R (shaded), C_rob circle, iso-RI2 ellipses
    (eqs 4.14-4.17, c = sum d^2) coloured by their RI2, dexterity line l2 = l1 sqrt(2)/2,
    manipulability line l1 = l2, optima and chosen designs.  Right: RI2 over the design plane as
    colour bands with labelled contours, the same lines.  One colour bar (RI2) for both panels;
    the figure says what RI2 and C_rob are.
    """
    fig, axes = new_figure(1, 2, figsize=(11.0, 7.0))
    top = float(L1.max())
    g = np.linspace(0, top, 400)
    G1, G2 = np.meshgrid(g, g)
    ok = (np.abs(G1 - G2) <= r) & (G1 + G2 >= R)
    t = np.linspace(0, np.pi / 2, 200)
    cmap, norm, bounds = _ri2_scale(n)
    for k, ax in enumerate(axes):
        if k == 0:
            # filled regions as images inside the vector figure (their outlines are the lines drawn on top)
            ax.contourf(G1, G2, ok.astype(float), levels=[0.5, 1.5], colors=["#dce9f5"]).set_rasterized(True)
            ax.fill([], [], color="#dce9f5", label="reaches the whole workspace")
            ax.plot(g, g - r, "-", color="C0", lw=0.9, label="$|l_1 - l_2| = r$")
            ax.plot(g, g + r, "-", color="C0", lw=0.9)
            ax.plot(g, R - g, "-", color="C2", lw=0.9, label="$l_1 + l_2 = R$")
            for v in _ellipse_levels(levels, n):
                for k2, (x, y) in enumerate(ri2_ellipses(v, n, sum_d2)):
                    ax.plot(x, y, "--", lw=1.1, color=cmap(norm(v)), gid=f"iso-RI2 ellipse {v!r}",
                            label="iso-$RI_2$ ellipses (colour: $RI_2$)" if k2 == 0 and v == _ellipse_levels(levels, n)[0]
                            else None)
        else:
            field = np.clip(ri2, bounds[0], bounds[-1])
            ax.contourf(L1, L2, field, levels=bounds, cmap=cmap, norm=norm, alpha=0.9).set_rasterized(True)
            cs = ax.contour(L1, L2, ri2, levels=bounds[1:-1], colors="k", linewidths=0.5)
            # one label per contour, where it crosses the ray at 65 deg from the l1 axis (the contours
            # converge at the ends of C_rob: labels there would collide)
            spots: list[tuple[float, float]] = []
            for segs in cs.allsegs:
                pts = np.vstack([seg for seg in segs if len(seg)]) if any(len(seg) for seg in segs) else None
                if pts is not None:
                    ang = np.degrees(np.arctan2(pts[:, 1], pts[:, 0]))
                    inside = (pts[:, 0] > 0.05 * top) & (pts[:, 1] < 0.95 * top)
                    if inside.any():
                        k = int(np.argmin(np.where(inside, np.abs(ang - 65.0), np.inf)))
                        spot = (float(pts[k, 0]), float(pts[k, 1]))
                        if all(math.dist(spot, q) > 0.07 * top for q in spots):   # the colour bar names the rest
                            spots.append(spot)
            ax.clabel(cs, fontsize=7, fmt="%.3g", inline=True, inline_spacing=3, manual=spots)
        ax.plot(radius * np.cos(t), radius * np.sin(t), "-", color="C3", lw=1.8,
                label=f"$C_{{rob}}$: robust circle, radius {radius:.3f} m")
        ax.plot(g, g * np.sqrt(2) / 2, "--", color="m", lw=0.9, label="dexterity optimum line $l_2 = l_1\\sqrt{2}/2$")
        ax.plot(g, g, ":", color="k", lw=1.0, label="manipulability optimum line $l_1 = l_2$")
        for key, mk in (("dexterity", "ms"), ("manipulability", "ko")):
            ax.plot(*optima[key], mk, ms=6, mfc="none", mew=1.2)
        ax.plot(l1, l2, "*", color="C3", mec="k", mew=0.6, ms=12, label="chosen designs", zorder=6)
        for name, a, b in zip(names, l1, l2):
            ax.annotate(plain_text(name), (a, b), textcoords="offset points", xytext=(6, 5), fontsize=7.5, zorder=7,
                        bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.85))
        ax.set_xlim(0, top)
        ax.set_ylim(0, top)
        ax.set_aspect("equal")
        ax.set_xlabel("$l_1$ [m]")
        ax.set_ylabel("$l_2$ [m]")
    axes[0].set_title("reach conditions, $C_{rob}$ and iso-$RI_2$ ellipses")
    axes[1].set_title("$RI_2$ over the design plane")
    bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=list(axes), shrink=0.85, pad=0.02,
                       spacing="uniform")
    bar.set_label("robustness index $RI_2$ [-]")
    bar.set_ticks(list(bounds))
    bar.set_ticklabels([f"{v:.3g}" for v in bounds])
    words = (f"$RI_2$: the largest singular value of the sensitivity of the {n} workspace positions to "
             f"($l_1$, $l_2$), smallest ($\\sqrt{{n}}$ = {math.sqrt(n):.3g}) on $C_{{rob}}$: "
             "$l_1^2 + l_2^2$ = mean $d^2$")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=3, frameon=False,
               title=words, title_fontsize=8.5)
    if title:
        suptitle(fig, plain_text(title))
    return fig


@styled
def manipulator_torque_crob(l1: np.ndarray, tau1: np.ndarray, tau2: np.ndarray, c: float,
                            violates: np.ndarray | None = None, title: str = "") -> Figure:
    """Motor torques tau1, tau2 and their sum [N m] against l1 [m] along C_rob (Table 4.8).

    Rows where the target is out of reach are gaps; ``violates`` marks the rows (a boolean
    per row) whose design does not reach the whole workspace (the reach conditions
    |l1 - l2| <= r, l1 + l2 >= R fail): their points are crossed and named in the legend."""
    fig, (ax,) = new_figure(1, 1, figsize=(7.4, 3.8))
    total = tau1 + tau2
    for label, y in (("$\\tau_1$ (shoulder)", tau1), ("$\\tau_2$ (elbow)", tau2), ("$\\tau_1 + \\tau_2$", total)):
        ax.plot(l1, y, "-o", ms=2.5, lw=1.2, label=label)
    if violates is not None and np.any(violates):
        bad = np.asarray(violates, dtype=bool)
        for k, y in enumerate((tau1, tau2, total)):
            ax.plot(l1[bad], y[bad], "x", color="C3", ms=7, mew=1.5,
                    label="violates the workspace reach conditions" if k == 0 else None)
    ax.set_ylabel("motor torque [N m]")
    ax.set_xlabel(f"$l_1$ [m]  (on $C_{{rob}}$: $l_2 = \\sqrt{{{c:g} - l_1^2}}$ m)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    suptitle(fig, f"{plain_text(title)}: motor torques along the robust circle" if title
                 else "Motor torques along the robust circle")
    return fig


# ----------------------------------------------------------------------------- figures of a run
def design_space_figure(p: Params, ws: Workspace, conv: Conv, used: dict):
    """The (l1, l2) design space: reach conditions, iso-RI2 ellipses, C_rob, the optima and the designs."""
    field_l = np.linspace(0.05, ws.R + 1.0, 161)
    L1, L2 = np.meshgrid(field_l, field_l)
    ri = kernel.manipulator_design_indices(ws.x, ws.y, L1.ravel(), L2.ravel())[0][:, kernel.Index.RI2].reshape(L1.shape)
    levels = p.ri2_levels or [math.sqrt(ws.n)]
    return manipulator_design_space(ws.r, ws.R, math.sqrt(conv.c_pairs), L1, L2, ri, float(ws.d2.sum()), ws.n,
                                    levels, optima(conv.c_pairs), used["names"], used["l1"], used["l2"],
                                    title=p.title or p.path.stem)


def torque_figure(sweep: dict, conv: Conv, title: str = ""):
    """Motor torques along C_rob (Table 4.8), where the target is out of reach left blank."""
    return manipulator_torque_crob(sweep["l1"], np.where(sweep["ok"], sweep["tau"][:, kernel.Torque.TAU1], np.nan),
                                   np.where(sweep["ok"], sweep["tau"][:, kernel.Torque.TAU2], np.nan), conv.c_sweep,
                                   violates=sweep["ok"] & ~sweep["reach_all"], title=title)
