"""The one plotting module: figures fit for a textbook, drawn without pyplot or a screen.

Every builder returns a matplotlib :class:`~matplotlib.figure.Figure` drawn inside the
project's style (:data:`STYLE`, applied with ``matplotlib.rc_context`` -- no global state
is changed, no backend is selected); :func:`save_figure` writes it atomically as PNG, SVG
or PDF with fixed metadata, so the same inputs give the same bytes.  Studies wrap builders
in :class:`driver.study.Figure` so nothing is drawn unless ``--plot`` is given.  Axes carry
names and units; matplotlib is the optional ``[plot]`` extra.
"""
from __future__ import annotations

import contextlib
import functools
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping, Sequence

from driver.extras import require

require("plot")   # a clear message naming the [plot] extra when matplotlib is missing
import matplotlib  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib import colormaps  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from driver.atomic import atomic_open  # noqa: E402


__all__ = ["STYLE", "FIGURE_FORMATS", "figure_format", "style", "styled", "new_figure", "save_figure", "line_panels",
           "quantity_label", "break_wraps"]

#: the house style: applied around every builder and every save, never globally
STYLE = {
    "figure.dpi": 110, "savefig.dpi": 110, "font.size": 9, "axes.titlesize": 9.5, "axes.labelsize": 9,
    "legend.fontsize": 8, "xtick.labelsize": 8, "ytick.labelsize": 8, "figure.titlesize": 10.5,
    "axes.grid": True, "grid.alpha": 0.3, "axes.spines.top": False, "axes.spines.right": False,
    "legend.framealpha": 0.9, "lines.linewidth": 1.4, "svg.hashsalt": "mechanism-driver",
    "svg.fonttype": "path", "pdf.fonttype": 42, "path.simplify": False,
}
#: figure file formats of --plot-format
FIGURE_FORMATS = ("png", "svg", "pdf")
_METADATA = {"png": {"Software": None}, "svg": {"Date": None, "Creator": None},
             "pdf": {"CreationDate": None, "ModDate": None, "Creator": None, "Producer": None}}


def figure_format(plot: bool | str) -> str:
    """The file format a ``plot`` option asks for: True means PNG, a string names the format."""
    fmt = plot if isinstance(plot, str) else "png"
    if fmt not in FIGURE_FORMATS:
        raise ValueError(f"unknown figure format {fmt!r} (choose {', '.join(FIGURE_FORMATS)})")
    return fmt


@contextlib.contextmanager
def style(**overrides: Any) -> Iterator[None]:
    """Draw inside this context to get the house style; rcParams are restored on exit."""
    with matplotlib.rc_context({**STYLE, **overrides}):
        yield


def styled(builder: Callable[..., Figure]) -> Callable[..., Figure]:
    """Run a figure builder inside :func:`style` (fonts and lines are fixed when drawn)."""
    @functools.wraps(builder)
    def wrapper(*args, **kwargs):
        with style():
            return builder(*args, **kwargs)
    return wrapper


def new_figure(nrows: int = 1, ncols: int = 1, **kw) -> tuple[Figure, np.ndarray]:
    """A figure and a flat array of axes (no pyplot state is kept)."""
    fig = Figure(figsize=kw.pop("figsize", (6.4 * ncols, 3.2 * nrows)), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    return fig, axes.ravel()


def save_figure(fig: Figure | Callable[[], Figure], path: str | Path) -> Path:
    """Write ``fig`` (or what a builder returns) to ``path`` atomically, in the format its suffix
    names (png, svg, pdf), with fixed metadata: the same figure gives the same bytes."""
    path = Path(path)
    fmt = figure_format(path.suffix.lstrip(".").lower())
    with matplotlib.rc_context(STYLE):
        if callable(fig) and not isinstance(fig, Figure):
            fig = fig()
        with atomic_open(path, "wb") as fh:
            fig.savefig(fh, format=fmt, metadata=_METADATA[fmt])
    return path


_UNITS = (("_microstrain", "µε"), ("_rad_s2", "rad/s²"), ("_rad_s", "rad/s"), ("_deg", "deg"), ("_rpm", "rpm"),
          ("_mm", "mm"), ("_nm", "N m"), ("_n_m", "N m"), ("_m", "m"), ("_n", "N"), ("_s", "s"), ("_kg", "kg"),
          ("_pct", "%"))


def quantity_label(name: str, units: Mapping[str, str] | None = None) -> str:
    """An axis label from a column name: words and units (``omega3_peak_rad_s`` -> ``omega3 peak
    [rad/s]``; ``slidercrank.speeds`` -> ``speeds [rad/s]`` with ``units`` from the deck SPEC)."""
    if units and name in units:
        base = name.split(".")[-1].replace("_", " ")
        return f"{base} [{units[name]}]" if units[name] else base
    base = name.split(".")[-1]
    for suffix, unit in _UNITS:
        if base.endswith(suffix) and len(base) > len(suffix):
            return f"{base[: -len(suffix)].replace('_', ' ')} [{unit}]"
    return base.replace("_", " ")


def break_wraps(y: np.ndarray, period: float = 360.0) -> np.ndarray:
    """``y`` with NaN where consecutive values jump by more than half a period (an angle wrapping
    from 360 to 0), so a line plot shows no vertical jump there."""
    y = np.asarray(y, dtype=float).copy()
    if y.size > 1:
        jump = np.abs(np.diff(y)) > 0.5 * period
        y = np.insert(y, np.flatnonzero(jump) + 1, np.nan)
    return y


def _wrapped(x: np.ndarray, y: np.ndarray, period: float = 360.0) -> tuple[np.ndarray, np.ndarray]:
    """x and y with a NaN point inserted at every wrap of y (see :func:`break_wraps`)."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if y.size < 2:
        return x, y
    idx = np.flatnonzero(np.abs(np.diff(y)) > 0.5 * period) + 1
    return np.insert(x, idx, np.nan), np.insert(y, idx, np.nan)


@styled
def line_panels(x: np.ndarray, panels: Sequence[tuple[str, dict[str, np.ndarray]]], xlabel: str,
                title: str = "", styles: dict[str, dict] | None = None) -> Figure:
    """Stacked panels sharing x: each panel is (ylabel, {label: y}); NaN gaps break lines."""
    fig, axes = new_figure(len(panels), 1, sharex=True, figsize=(7.0, 2.2 * len(panels) + 0.6))
    for ax, (ylabel, series) in zip(axes, panels):
        for label, y in series.items():
            ax.plot(x, y, label=label, **(styles or {}).get(label, {}))
        ax.set_ylabel(ylabel)
        if len(series) > 1:
            ax.legend(loc="best")
    axes[-1].set_xlabel(xlabel)
    if title:
        fig.suptitle(title)
    return fig


# ----------------------------------------------------------------------------- fourbar

@styled
def fourbar_curves(exact, listing, title: str) -> Figure:
    """Angles [deg], transmission angle [deg] and angular velocities [rad/s] against crank angle.

    ``exact`` and ``listing`` are tidy frames from driver.fourbar; listing rows are drawn as
    markers over the exact curves so the listing's defect is visible.  Angles that wrap from
    360 to 0 deg are drawn without the vertical jump.
    """
    panels = [("coupler, rocker angle [deg]", [("coupler_deg", "coupler"), ("rocker_deg", "rocker")]),
              ("transmission angle μ [deg]", [("transmission_deg", "μ")]),
              ("angular velocity [rad/s]", [("omega2_rad_s", "coupler"), ("omega3_rad_s", "rocker")])]
    fig, axes = new_figure(3, 1, sharex=True, figsize=(7.0, 7.4))
    colors = {"coupler_deg": "C0", "rocker_deg": "C1", "transmission_deg": "C2",
              "omega2_rad_s": "C0", "omega3_rad_s": "C1"}
    for k, (ax, (label, keys)) in enumerate(zip(axes, panels)):
        for key, name in keys:
            x, y = exact["theta_deg"].to_numpy(float), exact[key].to_numpy(float)
            if k == 0:
                x, y = _wrapped(x, y)
            ax.plot(x, y, color=colors[key], label=f"{name} (exact)")
            if listing is not None:
                ax.plot(listing["theta_deg"], listing[key], "o", ms=4, mfc="none", color=colors[key],
                        label=f"{name} (published listing)")
        ax.set_ylabel(label)
    axes[1].axhspan(40, 120, color="C2", alpha=0.08, label="recommended 40-120 deg")
    for ax in axes:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    axes[-1].set_xlabel("crank angle [deg]")
    axes[-1].set_xlim(float(exact["theta_deg"].min()), float(exact["theta_deg"].max()))
    fig.suptitle(f"{title}: four-bar kinematics")
    return fig


@styled
def fourbar_linkage(ground: float, theta: np.ndarray, out: np.ndarray, ok: np.ndarray,
                    listing, title: str, n_poses: int = 6, point: np.ndarray | None = None) -> Figure:
    """The linkage drawn at a few crank angles with the paths of A and B (exact), and the
    path of a coupler point (``point``: (n, 2) positions) when the deck defines one.
    Coordinates in the deck's length unit; the legend sits beside the mechanism."""
    fig, (ax,) = new_figure(1, 1, figsize=(8.2, 5.0))
    ax.plot(out[:, 3], out[:, 4], color="0.6", lw=0.8, label="path of A")
    bx = np.where(ok, out[:, 5], np.nan)
    by = np.where(ok, out[:, 6], np.nan)
    ax.plot(bx, by, color="C3", lw=1.2, label="path of B (exact)")
    if point is not None:
        ax.plot(np.where(ok, point[:, 0], np.nan), np.where(ok, point[:, 1], np.nan), color="C4", lw=1.2,
                ls="--", label="coupler point P")
    if listing is not None:
        ax.plot(listing["xb"], listing["yb"], "x", color="k", ms=5, label="B (published listing)")
    idx = np.flatnonzero(ok)
    cmap = colormaps["viridis"]
    for j, k in enumerate(idx[np.linspace(0, len(idx) - 1, n_poses, endpoint=False).astype(int)] if len(idx) else []):
        xs = [0.0, out[k, 3], out[k, 5], ground]
        ys = [0.0, out[k, 4], out[k, 6], 0.0]
        ax.plot(xs, ys, "-o", color=cmap(j / max(1, n_poses - 1)), ms=3, lw=1.4, label=f"crank at {theta[k]:.0f}°")
    ax.plot([0.0, ground], [0.0, 0.0], color="k", lw=2.5)
    ax.plot([0.0, ground], [0.0, 0.0], "^", color="k", ms=9, label="pivots O_A, O_B")
    ax.set_aspect("equal")
    ax.set_xlabel("x [deck length unit]")
    ax.set_ylabel("y [deck length unit]")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    ax.set_title(f"{title}: linkage positions")
    return fig


# ----------------------------------------------------------------------------- manipulator

def ri2_closed_form(l1: np.ndarray, l2: np.ndarray, sum_d2: float, n: int) -> np.ndarray:
    """RI2 of design (l1, l2) [m] over n workspace points with sum of d_i^2 = ``sum_d2`` [m^2]:
    RI2^2 = n + |sum_d2 - n (l1^2 + l2^2)| / (2 l1 l2) (the report's eq. 2.25 with the inverse
    kinematics substituted; its iso-lines are the ellipses of eqs. 4.14-4.17)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.sqrt(n + np.abs(sum_d2 - n * (l1 * l1 + l2 * l2)) / (2.0 * l1 * l2))


@styled
def manipulator_design_space(r: float, R: float, radius: float, L1: np.ndarray, L2: np.ndarray,
                             ri2: np.ndarray, sum_d2: float, n: int, levels: Sequence[float],
                             optima: dict, names: Sequence[str], l1: np.ndarray, l2: np.ndarray,
                             title: str = "") -> Figure:
    """Design space (l1, l2) [m] of a 2R arm, like the report's Figures 4.2-4.11.

    Left: reach region |l1 - l2| <= r, l1 + l2 >= R (shaded), C_rob circle, iso-RI2 ellipses
    (eqs 4.14-4.17, closed form, c = sum d^2; levels above sqrt(n) when only sqrt(n) is given,
    whose ellipse is C_rob itself), dexterity line l2 = l1 sqrt(2)/2, manipulability line l1 = l2,
    optima and chosen designs.  Right: RI2 from the kernel over the design plane.
    """
    fig, axes = new_figure(1, 2, figsize=(11.5, 5.4))
    top = float(L1.max())
    g = np.linspace(1e-3, top, 500)
    G1, G2 = np.meshgrid(g, g)
    ok = (np.abs(G1 - G2) <= r) & (G1 + G2 >= R)
    base = float(np.sqrt(n))
    iso = sorted({float(v) for v in levels if v > base + 1e-12} or {base + d for d in (0.01, 0.05, 0.1, 0.2, 0.4)})
    t = np.linspace(0, np.pi / 2, 200)
    for k, ax in enumerate(axes):
        if k == 0:
            ax.contourf(G1, G2, ok.astype(float), levels=[0.5, 1.5], colors=["#cfe3f7"])
            ax.plot(g, g - r, "b-", lw=0.8, label="|l1 − l2| = r")
            ax.plot(g, g + r, "b-", lw=0.8)
            ax.plot(g, R - g, "g-", lw=0.8, label="l1 + l2 = R")
            cs = ax.contour(G1, G2, ri2_closed_form(G1, G2, sum_d2, n), levels=iso, colors="0.35",
                            linestyles=":", linewidths=0.9)
            ax.clabel(cs, fontsize=7, fmt="RI2=%.2f")
            ax.plot([], [], ":", color="0.35", label="iso-RI2 ellipses")
        else:
            cs = ax.contour(L1, L2, ri2, levels=base + np.array([0.001, 0.01, 0.05, 0.1, 0.2, 0.4, 0.8]),
                            linewidths=0.7, cmap="viridis")
            ax.clabel(cs, fontsize=7, fmt="%.3f")
        ax.plot(radius * np.cos(t), radius * np.sin(t), "r-", lw=1.2, label=f"C_rob (radius {radius:.3f} m)")
        ax.plot(g, g * np.sqrt(2) / 2, "m--", lw=0.8, label="dexterity l2 = l1 √2/2")
        ax.plot(g, g, "k--", lw=0.8, label="manipulability l1 = l2")
        for key, mk in (("dexterity", "ms"), ("manipulability", "ko")):
            ax.plot(*optima[key], mk, ms=5, mfc="none")
        ax.plot(l1, l2, "r*", ms=9, label="chosen designs")
        for name, a, b in zip(names, l1, l2):
            ax.annotate(name, (a, b), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ax.set_xlim(0, top)
        ax.set_ylim(0, top)
        ax.set_aspect("equal")
        ax.set_xlabel("l1 [m]")
        ax.set_ylabel("l2 [m]")
    axes[0].set_title("reach region, C_rob, iso-RI2 ellipses")
    axes[1].set_title("RI2 over the design plane (kernel)")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=4)
    if title:
        fig.suptitle(title)
    return fig


@styled
def manipulator_torque_crob(l1: np.ndarray, tau1: np.ndarray, tau2: np.ndarray, c: float,
                            reach: np.ndarray | None = None) -> Figure:
    """Motor torques tau1, tau2 and their sum [N m] against l1 [m] along C_rob (Table 4.8);
    rows that violate the workspace reach conditions (4.4) are marked."""
    fig, (ax,) = new_figure(1, 1, figsize=(7.0, 3.8))
    total = tau1 + tau2
    for y, label in ((tau1, "τ1"), (tau2, "τ2"), (total, "τ1 + τ2")):
        ax.plot(l1, y, label=label)
    if reach is not None and (~reach).any():
        bad = ~np.asarray(reach, bool)
        for y in (tau1, tau2, total):
            ax.plot(l1[bad], y[bad], "x", color="C3", ms=5)
        ax.plot([], [], "x", color="C3", label="violates the reach conditions (4.4)")
    ax.set_xlabel(f"l1 [m]   (l2 = √({c:g} − l1²))")
    ax.set_ylabel("torque [N m]")
    ax.legend(loc="best")
    ax.set_title("Motor torques along C_rob")
    return fig


# ----------------------------------------------------------------------------- sweep

def _informative(frame, x: str, columns: Sequence[str]) -> list[str]:
    """Columns worth a panel: not constant, not equal to x, not a repeat of an earlier column."""
    keep, seen = [], []
    xv = frame[x].to_numpy() if x in frame else None
    for c in columns:
        v = frame[c].to_numpy(dtype=float, na_value=np.nan)
        finite = v[np.isfinite(v)]
        if finite.size == 0 or np.ptp(finite) == 0.0:
            continue
        if xv is not None and np.issubdtype(np.asarray(xv).dtype, np.number) and np.allclose(v, xv, equal_nan=True):
            continue
        if any(np.array_equal(v, s, equal_nan=True) for s in seen):
            continue
        keep.append(c)
        seen.append(v)
    return keep


@styled
def sweep_summary(frame, keys: Sequence[str], x: str = "", ys: Sequence[str] = (), title: str = "",
                  units: Mapping[str, str] | None = None) -> Figure:
    """Summary of a sweep: chosen (or the informative numeric) headline figures against a swept key.

    Axes are labelled with names and units (``units``: swept key -> unit from the deck SPEC;
    summary columns carry theirs in their names).  Without ``ys`` the panels are the numeric
    summary columns that vary and do not repeat x or each other (at most six).  With one
    numeric x the figures are drawn as lines over the cases; a boolean ``kept`` column, when
    some cases are not kept, is shown as filled vs hollow markers.
    """
    import pandas as pd
    x = x or next((k for k in keys if pd.api.types.is_numeric_dtype(frame[k])), "case")
    numeric = [c for c in frame.columns if c not in (x, "case") and pd.api.types.is_numeric_dtype(frame[c])
               and not pd.api.types.is_bool_dtype(frame[c]) and c not in keys]
    ys = list(ys) or _informative(frame, x, numeric)[:6] or numeric[:1]
    fig, axes = new_figure(len(ys), 1, sharex=True, figsize=(7.0, 1.9 * len(ys) + 1.0))
    kept = frame["kept"].astype(bool) if "kept" in frame else pd.Series(True, index=frame.index)
    others = [k for k in keys if k != x]
    many = len(frame) > 2000 or (others and frame.groupby(others).ngroups > 12)
    groups = [("", frame)] if (many or not others) else frame.groupby(others, sort=False)
    if many:
        others = []
    for ax, y in zip(axes, ys):
        if many:   # a design-space search: every case as a dot, kept cases circled
            ax.plot(frame[x], frame[y], ".", ms=1, color="0.6", alpha=0.3, rasterized=True)
            if not kept.all():
                ax.plot(frame.loc[kept, x], frame.loc[kept, y], "o", ms=3, mfc="none", color="C3", label="kept")
        else:
            for label, g in groups:
                g = g.sort_values(x)
                ax.plot(g[x], g[y], "-" if len(frame) <= 2000 else "", marker="o" if len(frame) <= 200 else ".",
                        ms=3, lw=1,
                        label=", ".join(f"{quantity_label(k, units)} = {v}" for k, v in
                                        zip(others, label if isinstance(label, tuple) else (label,))) or None)
            if not kept.all():
                ax.plot(frame.loc[kept, x], frame.loc[kept, y], "o", ms=4, mfc="none", color="k", label="kept")
        ax.set_ylabel(quantity_label(y, units))
    if others or not kept.all():
        axes[0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    axes[-1].set_xlabel(quantity_label(x, units))
    fig.suptitle(f"{title}: sweep summary" if title else "sweep summary")
    return fig


# ----------------------------------------------------------------------------- ujoint

@styled
def ujoint_speed_figure(theta_deg: np.ndarray, rpm: float, curves: dict[str, np.ndarray],
                        polar: bool = False, band: Sequence[float] | None = None) -> Figure:
    """Input and output shaft speed [rpm] against the input angle [deg]: every design (trial,
    optimum, the paper's printed design) overlaid on one panel, as the paper's Figures 6-11
    overlay trial and optimum; ``band`` (min, max rpm) is the paper's trial band read off its
    plot.  Polar: the radius starts just below the slowest speed, so a fluctuation of a
    fraction of an rpm stays visible; the radial axis is in rpm."""
    low = min(float(np.min(w)) for w in curves.values())
    top = max(float(np.max(w)) for w in curves.values())
    if band is not None:
        low, top = min(low, band[0]), max(top, band[1])
    low, top = min(low, rpm), max(top, rpm)
    pad = 0.08 * max(top - low, 2e-3 * rpm)
    if polar:
        fig = Figure(figsize=(6.4, 6.4), layout="constrained")
        ax = fig.add_subplot(1, 1, 1, projection="polar")
        x = np.radians(theta_deg)
    else:
        fig, (ax,) = new_figure(1, 1, figsize=(7.4, 4.2))
        x = theta_deg
    styles = ["-", "--", "-.", ":"]
    if band is not None:
        if polar:
            tt = np.linspace(0, 2 * np.pi, 361)
            ax.fill_between(tt, band[0], band[1], color="C7", alpha=0.15, label=f"paper's trial band {band[0]:g}-{band[1]:g} rpm")
        else:
            ax.axhspan(band[0], band[1], color="C7", alpha=0.15, label=f"paper's trial band {band[0]:g}-{band[1]:g} rpm")
    ax.plot(x, np.full_like(theta_deg, rpm, dtype=float), color="k", lw=1.0, ls=(0, (2, 2)), label=f"input shaft {rpm:g} rpm")
    for k, (label, w) in enumerate(curves.items()):
        ax.plot(x, w, lw=1.6, color=f"C{k}", ls=styles[k % len(styles)],
                label=f"{label}: {w.min():.2f}-{w.max():.2f} rpm")
    if polar:
        ax.set_rlim(max(0.0, low - pad), top + pad)
        ax.set_rlabel_position(22.5)
        ax.set_title("output shaft speed over one input revolution (radius in rpm)", pad=12)
        fig.legend(loc="outside lower center", ncol=2)
    else:
        ax.set_ylim(low - pad, top + pad)
        ax.set_ylabel("shaft speed [rpm]")
        ax.set_xlabel("input shaft angle θ [deg]")
        ax.set_xlim(0.0, 360.0)
        ax.set_xticks(np.arange(0, 361, 45))
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.suptitle("Hooke-joint chain: input and output shaft speed")
    return fig


# ----------------------------------------------------------------------------- slidercrank

@styled
def slidercrank_strain_figure(series: Sequence[tuple[str, np.ndarray, np.ndarray]], title: str,
                              ylabel: str = "axial strain [µε]", buckled: Sequence[str] = (),
                              over_euler: Mapping[str, float] | None = None) -> Figure:
    """A quantity against crank angle [deg], one line per case (label, angle, value): Figure 10.

    ``buckled`` names the cases that buckled (no curve; said on the figure); ``over_euler`` maps
    a case label to its peak compression over the Euler load when above 1 (the linear model's
    numbers there are not physical): those curves are dashed and flagged in the legend."""
    fig, axes = new_figure(1, 1, figsize=(7.6, 4.0))
    ax = axes[0]
    over = dict(over_euler or {})
    for label, x, y in series:
        flag = f" (N/P_E = {over[label]:.2f}: above the Euler load)" if label in over else ""
        ax.plot(x, y, label=label + flag, lw=1.2, ls="--" if label in over else "-")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlim(0, 360)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlabel("crank angle θ₂ [deg]")
    ax.set_ylabel(ylabel)
    if buckled:
        ax.text(0.01, 0.02, "buckled (no curve): " + ", ".join(buckled), transform=ax.transAxes, fontsize=8,
                color="C3", va="bottom")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax.set_title(title)
    return fig


@styled
def slidercrank_convergence_figure(series: dict[str, tuple[list[int], list[float]]], title: str) -> Figure:
    """Peak strain [µε] against element count and its percentage change (the paper's Figures 8-9)."""
    fig, axes = new_figure(2, 1, sharex=True, figsize=(7.0, 5.0))
    for label, (n, peak) in series.items():
        n, peak = np.asarray(n, dtype=float), np.asarray(peak, dtype=float)
        axes[0].plot(n, peak, "o-", ms=3, label=label)
        if n.size > 1:
            axes[1].plot(n[1:], 100 * np.diff(peak) / peak[:-1], "o-", ms=3, label=label)
    axes[0].set_xscale("log")
    axes[0].set_ylabel("peak tensile strain [µε]")
    axes[1].set_ylabel("change from previous count [%]")
    axes[1].set_xlabel("number of elements")
    axes[0].legend(loc="best")
    fig.suptitle(title)
    return fig
