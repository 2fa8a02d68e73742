"""The slider-crank figures: strain and deflection against crank angle, element convergence, the
time history of a benchmark run against its reference, and the nonlinear rod against the linear
one (strain, deflected shapes, lateral deflection per revolution).

Drawn in the house style (:mod:`driver.plotting`); this module imports matplotlib (the optional
[plot] extra), so the study imports it only when a figure is drawn.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from driver._deck import Params
from driver.plotting import new_figure, plain_text, styled, suptitle
from driver.slidercrank._analysis import Case, history
from driver.slidercrank._kernel import Shape
from driver.slidercrank._spec import Model


@styled
def slidercrank_strain_figure(series: Sequence[tuple[str, np.ndarray, np.ndarray]], title: str,
                              ylabel: str = "axial strain [microstrain]", above: dict[str, float] | None = None,
                              missing: Sequence[str] = (), ax=None,
                              yield_strain: tuple[float, str] | None = None) -> Figure:
    """A quantity against crank angle [deg], one line per case (label, angle, value): Figure 10.

    ``above`` maps the labels of cases whose rod compression exceeds the Euler load to that
    ratio N/P_E: their curves are dashed and flagged in the legend (a linear model draws
    them although the rod would buckle).  ``missing`` are one-line texts of cases not drawn (e.g. a speed that
    buckled): they are listed in the legend, so no speed silently disappears.  ``ax``: an axes
    to draw into (its figure is returned).  ``yield_strain``: (sigma_y / E [microstrain], what the
    yield strength is), marked on a strain figure.
    """
    from matplotlib.lines import Line2D
    above = above or {}
    if ax is None:
        fig, (ax,) = new_figure(1, 1, figsize=(7.4, 4.4))
    else:
        fig = ax.figure
    for label, x, y in series:
        flagged = label in above
        ax.plot(x, y, label=f"{label}: N = {above[label]:.2f} $P_E$, above the Euler load" if flagged else label,
                lw=1.2, ls="--" if flagged else "-")
    for text in missing:
        ax.add_line(Line2D([], [], ls="none", marker="x", color="C3", label=text))
    _yield_lines(ax, [y for _, _, y in series], yield_strain)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlim(0, 360)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlabel(r"crank angle $\theta_2$ [deg]")
    ax.set_ylabel(ylabel)
    handles, labels = ax.get_legend_handles_labels()
    # a long entry (a speed not drawn and why, the yield strain) gets the legend's whole width
    ncol = 1 if _longest_line(labels) > 48 else (3 if len(labels) > 4 else 2)
    fig.legend(handles, labels, loc="outside lower center", ncol=ncol, frameon=False, title="crank speed")
    ax.set_title(plain_text(title))
    return fig


@styled
def slidercrank_convergence_figure(series: dict[str, Any], title: str, axes=None) -> Figure:
    """An element-convergence study as an engineer reads it (the paper's Figures 8-9 redrawn).

    ``series``: per crank speed (its label) either ``(n, element)`` or ``(n, element, pin)``:
    the element counts and the peak tensile strain [microstrain] of the crank-end element (the
    paper's quantity, an element average) and, optionally, at the crank pin recovered from the
    first two elements.  Left: the strain against the number of elements (log axis), the
    finest mesh's value dotted.  Right: the size of the difference from the finest mesh [%] on
    log-log axes, with a slope -1 guide (an element average converges as 1/N) and the 0.1 %
    line.  ``axes``: two axes of the caller's figure to draw into."""
    if axes is None:
        fig, axes = new_figure(1, 2, figsize=(10.0, 4.8))
    else:
        fig = axes[0].figure
    ax_q, ax_e = axes[0], axes[1]
    one = len(series) == 1
    n_all: list[float] = []
    for k, (label, data) in enumerate(series.items()):
        n = np.asarray(data[0], dtype=float)
        kinds = [("crank-end element (the paper's quantity)", np.asarray(data[1], dtype=float), "-", "o")]
        if len(data) > 2 and data[2] is not None:
            kinds.append(("at the crank pin (recovered from two elements)", np.asarray(data[2], dtype=float), "--", "s"))
        colour = f"C{k % 10}"
        for j, (what, v, ls, mk) in enumerate(kinds):
            name = what if one else f"{label}: {what}"
            if n.size > 1:   # where it settles: every finer mesh within 0.1 % of the finest
                err_ = 100 * np.abs(v - v[np.argmax(n)]) / abs(v[np.argmax(n)])
                order = np.argsort(n)
                bad = np.nonzero(err_[order] > 0.1)[0]
                n_ok = n[order][bad[-1] + 1] if bad.size else n[order][0]
                name += f", within 0.1 % from N = {n_ok:g}" if n_ok < n.max() else ""
            ax_q.plot(n, v, ls=ls, marker=mk, ms=4, color=colour if one is False else f"C{j}", label=name,
                      mfc="white" if j else None)
            if n.size > 1:
                finest = v[np.argmax(n)]
                err = 100 * np.abs(v - finest) / abs(finest)
                use = (n < n.max()) & (err > 0)
                ax_e.plot(n[use], err[use], ls=ls, marker=mk, ms=4, color=colour if one is False else f"C{j}",
                          mfc="white" if j else None, label=name)
                if j == 0:
                    ax_q.axhline(finest, color="0.45", lw=0.8, ls=":", zorder=0,
                                 label=f"{'' if one else label + ': '}finest mesh, N = {n.max():g}: "
                                       f"{finest:.4g} microstrain")
        n_all += list(n)
    from matplotlib.ticker import FuncFormatter
    for ax in (ax_q, ax_e):
        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.set_xlabel("number of rod elements $N$")
    ax_q.set_ylabel("peak tensile strain [microstrain]")
    ax_q.set_title("peak strain against mesh size")
    ax_e.set_yscale("log")
    ax_e.set_ylabel("|difference from the finest mesh| [%]")
    ax_e.set_title("difference from the finest mesh")
    lines = [ln for ln in ax_e.lines if len(ln.get_xdata())]
    if lines:
        x0 = min(float(np.min(ln.get_xdata())) for ln in lines)
        y0 = max(float(ln.get_ydata()[0]) for ln in lines)
        xs = np.array([x0, max(n_all) / 2])
        ax_e.plot(xs, y0 * x0 / xs, color="0.5", lw=0.9, ls="-.", label="slope $-1$ (error $\\propto 1/N$)")
        pins = [ln for ln in lines if ln.get_linestyle() == "--" and len(ln.get_xdata()) > 1]
        if pins:   # the recovered pin strain is second order: a slope -2 guide through its second point
            x1, y1 = float(pins[0].get_xdata()[1]), float(pins[0].get_ydata()[1])
            xs2 = np.array([x1, max(n_all) / 2])
            ax_e.plot(xs2, 0.6 * y1 * (x1 / xs2) ** 2, color="0.5", lw=0.9, ls=(0, (1, 1.5)),
                      label="slope $-2$ (error $\\propto 1/N^2$)")
        ax_e.axhline(0.1, color="0.6", lw=0.8, ls=":")
        ax_e.annotate("0.1 %", (0.0, 0.1), xycoords=("axes fraction", "data"), xytext=(4, 3),
                      textcoords="offset points", fontsize=8, color="0.35")
    handles, names = ax_q.get_legend_handles_labels()
    more = [(h, t) for h, t in zip(*ax_e.get_legend_handles_labels()) if t.startswith("slope")]
    handles, names = handles + [h for h, _ in more], names + [t for _, t in more]
    fig.legend(handles, names, loc="outside lower center", ncol=1 if max(map(len, names)) > 60 else 2,
               frameon=False)
    if title:
        suptitle(fig, plain_text(title))
    return fig


@styled
def slidercrank_history_figure(time: np.ndarray, series: dict[str, np.ndarray], labels: dict[str, str],
                               reference: dict[str, tuple[float, float]], title: str, reference_label: str = "",
                               axes=None) -> Figure:
    """Quantities against time [s], one panel each (``series`` keyed like ``labels``, the axis
    words with units), with a reference value (time, value) marked where given: a benchmark's
    published end state beside the computed history."""
    if axes is None:
        fig, axes = new_figure(len(series), 1, sharex=True, figsize=(7.4, 2.4 * len(series) + 0.8))
    else:
        fig = axes[0].figure
    import re as _re
    model_label = "this model (linear KED, Newmark)"
    for ax, (key, y) in zip(axes, series.items()):
        ax.plot(time, y, color="C0", lw=1.2, label=model_label)
        if key in reference:
            t, v = reference[key]
            ax.plot([t], [v], "D", ms=7, mfc="white", mec="C3", mew=1.5, label=reference_label or "reference")
            m = _re.search(r"\[([^\]]+)\]\s*$", labels.get(key, ""))
            unit = f" {m.group(1)}" if m else ""
            mine = float(np.interp(t, time, y))
            # the two end values side by side, in the figure's own font, on a white ground beside the marker
            span = float(np.nanmax(time) - np.nanmin(time)) or 1.0
            ax.set_xlim(right=max(float(np.nanmax(time)), t) + 0.24 * span)   # room right of the curves
            ax.annotate(f"reference {v:.4g}{unit}\nthis model {mine:.4g}{unit}", (t, v), xytext=(12, 0),
                        textcoords="offset points", ha="left", va="center", fontsize=8.5, color="0.15",
                        bbox=dict(boxstyle="round,pad=0.3", fc="white", ec="C3", lw=0.8, alpha=0.9),
                        arrowprops=dict(arrowstyle="-", color="C3", lw=0.8), zorder=6)
        ax.set_ylabel(labels.get(key, key))
    axes[-1].set_xlabel("time $t$ [s]")
    handles, names = axes[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="outside lower center", ncol=2, frameon=False)
    if title:
        suptitle(fig, plain_text(title))
    return fig


def _yield_lines(ax, values: Sequence[np.ndarray], yield_strain: tuple[float, str] | None) -> None:
    """The rod's yield strain +-sigma_y / E [microstrain] with its words: drawn as two dotted lines
    where the curves come within a quarter of it, else named in the legend as off the scale (a
    strain beyond it is not physical: the rod would have yielded)."""
    if yield_strain is None:
        return
    from matplotlib.lines import Line2D
    eps, words = yield_strain
    top = max((float(np.nanmax(np.abs(v))) for v in values if np.size(v)), default=0.0)
    label = f"yield strain $\\pm${eps:.0f} microstrain\n({words})"   # its source on a line of its own
    if top >= 0.25 * eps:
        for sign in (1.0, -1.0):
            ax.axhline(sign * eps, color="C3", lw=0.9, ls=":", label=label if sign > 0 else None)
    else:
        ax.add_line(Line2D([], [], ls="none", label=f"{label}: off the scale"))


def _longest_line(labels: Sequence[str]) -> int:
    """The characters of the longest line of legend entries ``labels`` (an entry may have two)."""
    return max((len(line) for label in labels for line in label.split("\n")), default=0)


def _own_axes(ax, figsize: tuple[float, float]):
    """(figure, axes): the given axes and its figure, or a new house-style figure."""
    if ax is not None:
        return ax.figure, ax
    fig, axes = new_figure(1, 1, figsize=figsize)
    return fig, axes[0]


#: the two models in the nonlinear deck's figures: one style each, a key says which is which
NONLINEAR: dict[str, Any] = dict(lw=1.3, ls="-")
LINEAR: dict[str, Any] = dict(lw=1.0, ls="--", color="0.25")
BUCKLED = "#c0392b"
#: the rod's yield strain +-sigma_y / E (as :func:`_yield_lines` draws it)
YIELD: dict[str, Any] = dict(color="C3", lw=0.9, ls=":")


@styled
def slidercrank_nl_strain_figure(series: Sequence[tuple[str, np.ndarray, np.ndarray, np.ndarray]], title: str,
                                 buckled: dict[str, str] | None = None, axes=None,
                                 yield_strain: tuple[float, str] | None = None) -> Figure:
    """Crank-end axial strain [microstrain] against crank angle [deg], one panel per crank speed
    (label, angle, linear, nonlinear), each on its own scale: the nonlinear rod solid in the
    speed's colour, the linear model dashed dark grey (a key below says so).  A buckled rod's
    spike of thousands of microstrain cannot flatten the sub-buckling speeds.  ``buckled`` maps
    the labels of the speeds at which the nonlinear rod buckled to why (their panels are framed
    and titled in red).  ``axes``: one axes per speed to draw into.  ``yield_strain``
    (sigma_y / E [microstrain], its words) marked dotted on the panels whose curves come within a
    quarter of it, and named in the key (off the scale where no panel reaches it)."""
    from matplotlib.lines import Line2D
    buckled = buckled or {}
    n = len(series)
    ncols = 1 if n == 1 else 2
    nrows = int(np.ceil(n / ncols))
    if axes is None:
        fig, axes = new_figure(nrows, ncols, sharex=True, figsize=(10.0 if ncols == 2 else 7.4, 2.3 * nrows + 1.3))
        for extra in list(axes)[n:]:
            extra.set_visible(False)
    else:
        fig = axes[0].figure
    near_yield = False
    yield_words = (f"yield strain $\\pm${yield_strain[0]:.0f} microstrain\n({yield_strain[1]})"
                   if yield_strain is not None else "")
    for k, (ax, (label, x, lin, nl)) in enumerate(zip(axes, series)):
        ax.plot(x, nl, color=f"C{k % 10}", **NONLINEAR)
        ax.plot(x, lin, **LINEAR)
        if yield_strain is not None and max(float(np.nanmax(np.abs(v))) for v in (lin, nl)) >= 0.25 * yield_strain[0]:
            near_yield = True
            for sign in (1.0, -1.0):
                ax.axhline(sign * yield_strain[0], **YIELD, label=yield_words if sign > 0 else None)
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_xlim(0, 360)
        ax.set_xticks(np.arange(0, 361, 90))
        if label in buckled:
            ax.set_title(f"{label}: buckled ({buckled[label]})", fontsize=8.5, color=BUCKLED)
            for spine in ax.spines.values():
                spine.set_visible(True)
                spine.set_color(BUCKLED)
                spine.set_linewidth(1.4)
        else:
            ax.set_title(label, fontsize=9)
    shown = list(axes)[:n]
    for ax in shown:
        spec = ax.get_subplotspec()
        if spec is None or spec.is_last_row() or ax is shown[-1] or (ncols == 2 and ax is shown[-2] and n % 2 == 1):
            ax.set_xlabel("crank angle \u03b8\u2082 [deg]")
            ax.tick_params(labelbottom=True)
    fig.supylabel("crank-end axial strain [microstrain]", fontsize=9)
    key = [Line2D([], [], color="C0", **NONLINEAR), Line2D([], [], **LINEAR)]
    names = ["nonlinear rod (co-rotational), colour per speed", "linear model (the paper's)"]
    if buckled:
        key.append(Line2D([], [], color=BUCKLED, lw=1.4))
        names.append("frame: the nonlinear rod buckled at this speed")
    if yield_strain is not None:
        key.append(Line2D([], [], **YIELD) if near_yield else Line2D([], [], ls="none"))
        names.append(yield_words + ("" if near_yield else ": off the scale"))
    # two columns of short entries; a long one (the yield strain and its source) one a line
    fig.legend(key, names, loc="outside lower center", ncol=1 if _longest_line(names) > 60 else 2, frameon=False)
    suptitle(fig, plain_text(title))
    return fig


@styled
def slidercrank_nl_shapes_figure(series: Sequence[tuple[str, tuple[float, float], np.ndarray]], length: float,
                                 title: str, ax=None) -> Figure:
    """Lateral deflection [mm] along the rod [m] at the step of largest deflection (solid) and of
    largest crank-end compression (dotted), one colour per speed; true scale in mm (the axis
    is stretched, not the shape)."""
    from matplotlib.lines import Line2D
    fig, ax = _own_axes(ax, (8.6, 4.6))
    for k, (label, (a1, _a2), shapes) in enumerate(series):   # the dotted line's angle is not labelled
        s = np.linspace(0.0, length, shapes.shape[0])
        ax.plot(s, shapes[:, Shape.LARGEST_DEFLECTION] * 1e3, color=f"C{k % 10}", lw=1.2,
                label=f"{label}, \u03b8\u2082 = {a1:.0f}°")
        ax.plot(s, shapes[:, Shape.LARGEST_COMPRESSION] * 1e3, color=f"C{k % 10}", lw=0.8, ls=":")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("position along the rod from the crank pin [m]")
    ax.set_ylabel("lateral deflection from the chord [mm]")
    handles, labels = ax.get_legend_handles_labels()
    handles += [Line2D([], [], color="0.3", lw=1.2), Line2D([], [], color="0.3", lw=0.8, ls=":")]
    labels += ["solid: at the largest deflection", "dotted: at the largest crank-end compression"]
    ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    ax.set_title(plain_text(title))
    return fig


@styled
def slidercrank_nl_revolutions_figure(series: Sequence[tuple[str, np.ndarray]], title: str, ax=None) -> Figure:
    """Peak lateral deflection [mm] in each revolution, one line per speed (log scale)."""
    fig, ax = _own_axes(ax, (8.0, 4.2))
    for label, d in series:
        ax.plot(np.arange(1, len(d) + 1), d, "o-", ms=3, label=label)
    ax.set_yscale("log")
    ax.set_xlabel("revolution")
    ax.set_ylabel("peak lateral deflection [mm]")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False, title="crank speed")
    ax.set_title(plain_text(title))
    return fig


# ----------------------------------------------------------------------------- figures of a run
def history_figure(model: Model, params: Params, case: Case, alpha: float, beta: float, ref: dict | None):
    """Midpoint deflection and rod elongation against time of a benchmark run, with the
    reference end state (Simeon 1996) marked."""
    h = history(model, params, case.omega, case.n_elements, alpha, beta)
    refs = {}
    if ref is not None:
        refs = {"mid": (ref["t"], ref["q1"]), "elong": (ref["t"], ref["q4"])}
    return slidercrank_history_figure(
        h["time"], {"mid": h["mid"] * 1e3, "elong": h["elong"] * 1e6},
        {"mid": "midpoint deflection $q_1$ [mm]", "elong": "rod elongation $q_4$ [$\\mu$m]"},
        {k: (t, v * (1e3 if k == "mid" else 1e6)) for k, (t, v) in refs.items()},
        f"{'Simeon (1996) crank benchmark' if ref is not None else params.material}: {case.n_elements} elements "
        f"at {case.omega:g} rad/s, t = 0 to {params.end_time:g} s",
        "Simeon (1996), MEBDFI tol 1e-14")
