"""The force analysis's part of a four-bar run's .out (issue 26, decks with ``mass``): the inputs
as used, the force table (one row per crank angle), the force summary and the Berkof-Lowen
balance, the tidy columns; and its figures (input torque, pin-force polars, shaking force),
drawn on demand.  Forces in N, torques and moments in N m (docs/fourbar.md, "Force analysis").
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from driver._deck import Params
from driver._result import Figure
from driver._table import Column, fortran_f, render_table
from driver.fourbar._analysis import ST
from driver.fourbar._analysis_forces import ForceAnalysis, analyse, props, tidy_columns
from driver.fourbar._batch import force_summary, stress_summary
from driver.fourbar._kernel import Force, Prop
from driver.fourbar._spec import LINKS, force_value, sections_of, yields_of

__all__ = ["force_section", "echo_lines", "table_lines", "summary_lines", "stress_lines", "yield_warnings", "figures"]


def force_section(p: Params, theta: np.ndarray, out: np.ndarray, status: np.ndarray,
                  part: dict[str, Any], chain: str | None = None) -> list[str]:
    """The force analysis's lines of the .out; its tidy columns are added to ``part`` (the run's
    tidy columns, :func:`driver.fourbar._analysis.tidy_part`; in place).
    ``chain``: the class of a chain that cannot move, said on its rows instead of 'not placed'."""
    fa = analyse(p, out, status)
    part.update(tidy_columns(fa))
    words = ["toggle: forces unbounded" if s == ST["toggle"] else (f"{chain}: no position" if chain else "not placed")
             for s in status]
    title = ("Force analysis (Newton-Euler, closed form; " +
             ("with the Berkof-Lowen counterweights" if fa.cw is not None else "links as given") + ")")
    lines = echo_lines(p) + table_lines(theta, fa.forces, fa.ok, words, title) + summary_lines(p, force_summary(p), fa)
    if sections_of(p) is not None:
        lines += stress_lines(p, stress_summary(p))
    return lines


def stress_lines(p: Params, s: dict[str, Any]) -> list[str]:
    """The link-stress lines of the .out: the sections, each link's peak |N|/A + |M|/Z and its crank
    angle, and with ``yield_strength`` each link's ratio to it and a verdict naming a link that
    yields (its elastic answer beyond that point is not physical).

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys with the sections (SI).
    s : dict
        The link-stress summary (``driver.fourbar._batch.stress_summary``).

    Returns
    -------
    list of str
        The lines (stresses in MPa).
    """
    sec = sections_of(p) or []
    out = ["", "  Link stresses (peak |N|/A + |M|/Z along each link: the force analysis's loads where they act,"
               " the scan above)",
           "    sections ............. " + "; ".join(f"{link} A = {sec[j]:g} m^2, Z = {sec[3 + j]:g} m^3"
                                                  for j, link in enumerate(LINKS))]
    if s[f"{LINKS[0]}_stress_peak_MPa"] is None:
        return out + ["    the stresses are not defined anywhere in the range"]
    out.append("    peak stress .......... " + ", ".join(
        f"{link} {s[f'{link}_stress_peak_MPa']:.4f} MPa at theta = {s[f'{link}_stress_peak_at_deg']:.2f} deg"
        for link in LINKS))
    ys = yields_of(p)
    if ys is not None:
        out.append("    yield strength ....... " + ", ".join(
            f"{link} {y / 1e6:g} MPa (peak {s[f'{link}_stress_peak_MPa'] * 1e6 / y:.3f} of it)"
            for link, y in zip(LINKS, ys)))
        out += [f"    PASSES YIELD: {w}" for w in yield_warnings(p, s)] or ["    every link stays below its yield strength"]
    return out


def yield_warnings(p: Params, s: dict[str, Any]) -> list[str]:
    """One line per link whose peak stress reaches its yield strength (none without
    ``yield_strength``): what the .out says and the run warns."""
    ys = yields_of(p)
    if ys is None or not s.get("yields"):
        return []
    return [f"the {link} passes yield: its peak stress {s[f'{link}_stress_peak_MPa']:.4g} MPa at theta = "
            f"{s[f'{link}_stress_peak_at_deg']:.2f} deg exceeds its yield strength {y / 1e6:g} MPa; the elastic "
            "answer beyond that point is not physical"
            for link, y in zip(LINKS, ys) if s[f"{link}_stress_peak_MPa"] * 1e6 >= y]


def table_lines(theta: np.ndarray, f: np.ndarray, ok: np.ndarray, status_words: list[str], title: str) -> list[str]:
    """Format the force table of the ``.out``: one row per crank angle.

    Parameters
    ----------
    theta : numpy.ndarray
        Crank angles, deg.
    f : numpy.ndarray
        (n, 12) forces in the order of ``driver.fourbar.forces.COLUMNS`` (N, N m).
    ok : numpy.ndarray
        (n,) bool: where the forces are defined.
    status_words : list of str
        The status of each row in words (printed where not ok).
    title : str
        The table's heading.

    Returns
    -------
    list of str
        The lines: forces in N to 3 decimals, torques in N m to 4.
    """
    whole = bool(np.all(np.isclose(theta, np.round(theta))))
    tcol = Column("theta", "i", 5, 0, 2) if whole else Column("theta", "f", 8, 3, 2)
    cols = [tcol, Column("T_in", "f", 10, 4)]
    cols += [Column(h, "f", 10, 3) for h in ("F_O2x", "F_O2y", "F_Ax", "F_Ay", "F_Bx", "F_By", "F_O4x", "F_O4y",
                                             "shake_x", "shake_y")]
    cols += [Column("shake_M", "f", 10, 4)]
    units = ["[deg]", "[N m]"] + ["[N]"] * 10 + ["[N m]"]
    rows, trailers = [], []
    for k in range(len(theta)):
        t = int(round(theta[k])) if whole else theta[k]
        if ok[k]:
            rows.append([t, *f[k]])
            trailers.append("")
        else:
            rows.append([t] + [None] * 12)
            trailers.append(status_words[k])
    lines = render_table(cols, rows, trailers)
    unit_line = "".join(" " * c.sep + u.rjust(max(c.width, len(c.header))) for c, u in zip(cols, units)).rstrip()
    return ["", f"  {title}", "", lines[0], unit_line] + lines[1:]


def echo_lines(p: Params) -> list[str]:
    """The force keys as used (defaults filled in), for the .out header."""
    pr = props(p)
    out = ["", "  Force analysis inputs (SI units; centre of mass from the first pin, angle off the link line)",
           "    link        mass [kg]   inertia [kg m2]   com distance [m]   com angle [deg]"]
    for i, name in enumerate(LINKS):
        out.append(f"    {name:<10}{pr[Prop.MASS + i]:>10.4f}{pr[Prop.INERTIA + i]:>17.6g}"
                   f"{pr[Prop.COM_DISTANCE + i]:>19.4f}{math.degrees(pr[Prop.COM_ANGLE + i]):>18.2f}")
    out.append(f"    gravity {pr[Prop.GRAVITY]:g} m/s^2 along -y; load torque on the rocker {pr[Prop.LOAD_TORQUE]:g} N m "
               f"(ccw +); load force at P ({pr[Prop.LOAD_FORCE_X]:g}, {pr[Prop.LOAD_FORCE_Y]:g}) N")
    return out


def summary_lines(p: Params, s: dict[str, Any], fa: ForceAnalysis) -> list[str]:
    """Format the words and numbers after the force table.

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys (lengths in m with ``mass``).
    s : dict
        The force summary (``driver.fourbar._batch.force_summary``).
    fa : ForceAnalysis
        The forces of the run.

    Returns
    -------
    list of str
        The lines (peaks in N and N m, energy fluctuation in J, flywheel inertia in kg m^2).
    """
    def fmt(v: float | None, unit: str, spec: str = ".4f") -> str:
        if v is None:
            return "n/a"
        return (fortran_f(v, None, int(spec[1:-1])) if spec.endswith("f") else f"{v:{spec}}") + f" {unit}"

    span = abs(p.stop_deg - p.start_deg)
    npts = min(36001, max(2, math.ceil(span / 0.1 - 1e-9) + 1))
    out = ["", f"  Force summary (a scan of the crank range in {span / (npts - 1):.4g} deg steps)" if span > 0
           else "  Force summary (the one crank angle of the range)"]
    if s["torque_peak_Nm"] is None:
        out.append("    the forces are not defined anywhere in the range (no assembly, or toggle throughout)")
        return out
    out += [f"    peak |input torque| .. {fmt(s['torque_peak_Nm'], 'N m')} at theta = {s['torque_peak_at_deg']:.2f} deg",
            f"    mean input torque .... {fmt(s['torque_mean_Nm'], 'N m')}, RMS {fmt(s['torque_rms_Nm'], 'N m')}",
            f"    peak pin forces ...... |F_O2| {fmt(s['F_O2_peak_N'], 'N', '.3f')}, |F_A| {fmt(s['F_A_peak_N'], 'N', '.3f')}, "
            f"|F_B| {fmt(s['F_B_peak_N'], 'N', '.3f')}, |F_O4| {fmt(s['F_O4_peak_N'], 'N', '.3f')}",
            f"    peak shaking force ... {fmt(s['shaking_force_peak_N'], 'N', '.3f')}, "
            f"peak |shaking moment| {fmt(s['shaking_moment_peak_Nm'], 'N m')}",
            f"    energy fluctuation ... dE = {fmt(s['energy_fluctuation_J'], 'J', '.5f')}",
            f"    flywheel inertia ..... dE / (C_s omega^2) = {fmt(s['flywheel_inertia_kgm2'], 'kg m^2', '.6g')} "
            f"(C_s = {force_value(p, 'speed_fluctuation'):g}, omega = {p.omega:g} rad/s)"]
    if s["torque_mean_Nm"] is None:
        out.append("    mean, RMS and dE need the forces everywhere in the range (a toggle or an unassembled "
                   "position lies in it)")
    if fa.cw is not None:
        cw = fa.cw
        out += ["", "  Shaking-force balance (Berkof-Lowen: counterweights on crank and rocker make the total "
                "centre of mass stationary)"]
        for i, name in enumerate(("crank", "rocker")):
            pin = "O2->A" if i == 0 else "O4->B"
            out.append(f"    {name} counterweight .. m r = {cw.mr[i]:.6f} kg m at {cw.angle_deg[i]:.3f} deg off {pin}; "
                       f"{cw.mass[i]:.4f} kg at r = {cw.radius[i]:g} m")
        pb = cw.props
        crank, rocker = 0, 2   # the links' offsets in each group of Prop
        out.append(f"    balanced links ....... crank {pb[Prop.MASS + crank]:.4f} kg, I = {pb[Prop.INERTIA + crank]:.6g} "
                   f"kg m2, com {pb[Prop.COM_DISTANCE + crank]:.4f} m at {math.degrees(pb[Prop.COM_ANGLE + crank]):.2f} "
                   f"deg; rocker {pb[Prop.MASS + rocker]:.4f} kg, I = {pb[Prop.INERTIA + rocker]:.6g} kg m2, com "
                   f"{pb[Prop.COM_DISTANCE + rocker]:.4f} m at {math.degrees(pb[Prop.COM_ANGLE + rocker]):.2f} deg")
        rows = [("peak |input torque| [N m]", "torque_peak_Nm", 4), ("RMS input torque [N m]", "torque_rms_Nm", 4),
                ("peak |F_O2| [N]", "F_O2_peak_N", 3), ("peak |F_A| [N]", "F_A_peak_N", 3),
                ("peak |F_B| [N]", "F_B_peak_N", 3), ("peak |F_O4| [N]", "F_O4_peak_N", 3),
                ("peak |shaking force| [N]", "shaking_force_peak_N", 3),
                ("peak |shaking moment| [N m]", "shaking_moment_peak_Nm", 4),
                ("energy fluctuation dE [J]", "energy_fluctuation_J", 5)]
        out.append(f"    {'':<28}{'unbalanced':>14}{'balanced':>14}{'change':>14}")
        for label, key, dec in rows:
            a, b = s.get("unbalanced_" + key), s.get(key)
            if a is None or b is None:
                continue
            out.append(f"    {label:<28}{fortran_f(a, 14, dec)}{fortran_f(b, 14, dec)}{fortran_f(b - a, 14, dec)}")
        if fa.ok.any():
            mg = np.sum(pb[Prop.MASS:Prop.MASS + 3]) * pb[Prop.GRAVITY]
            inert = (fa.forces[fa.ok, Force.SHAKING_X:Force.SHAKING_Y + 1] - np.array([0.0, -mg])
                     - np.array([pb[Prop.LOAD_FORCE_X], pb[Prop.LOAD_FORCE_Y]]))
            out.append(f"    balanced shaking force minus weight and load force: max {np.max(np.hypot(*inert.T)):.1e} N "
                       "over the table (zero but for round-off: the centre of mass does not move)")
    return out


def figures(p: Params, title: str, theta_grid: Any) -> list[Figure]:
    """List the force figures of a run: input torque, pin-force polar plots, shaking force.

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys (lengths in m with ``mass``).
    title : str
        The figures' title.
    theta_grid : callable
        ``theta_grid(p, theta_deg) -> (states, status)``, the exact grid
        (``driver.fourbar.exact_grid``), called when a figure is drawn (721 crank angles).

    Returns
    -------
    list of Figure
        ``torque``, ``pin_forces`` and ``shaking`` (drawn lazily).
    """
    def data() -> tuple[np.ndarray, ForceAnalysis]:
        theta = np.linspace(p.start_deg, p.stop_deg, 721)
        out, st = theta_grid(p, theta)
        return theta, analyse(p, out, st)

    def torque() -> Any:
        from driver import plotting
        from driver.fourbar import _figures as draw  # matplotlib: imported when a figure is drawn
        theta, fa = data()
        fig, ax = plotting.new_figure(1, 1, figsize=(8.0, 4.2))
        with plotting.style():
            draw.plot_torque(theta, fa, p, ax=ax[0], legend=False)
            plotting.suptitle(fig, f"{plotting.plain_text(title)}: input torque")
            fig.legend(*ax[0].get_legend_handles_labels(), loc="outside lower center", ncol=2, frameon=False)
        return fig

    def pins() -> Any:
        from driver import plotting
        from driver.fourbar import _figures as draw
        theta, fa = data()
        with plotting.style():
            fig, axes = plotting.new_figure(2, 2, figsize=(7.4, 7.8), subplot_kw={"projection": "polar"})
            draw.plot_pin_polars(fa, axes=axes, theta=theta)
            plotting.suptitle(fig, f"{plotting.plain_text(title)}: pin forces\n"
                                   "angle: the force's direction, radius: its magnitude [N]")
            fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=3, frameon=False)
        return fig

    def shaking() -> Any:
        from driver import plotting
        from driver.fourbar import _figures as draw
        theta, fa = data()
        with plotting.style():
            fig, axes = plotting.new_figure(1, 2, figsize=(9.0, 4.3))
            draw.plot_shaking(theta, fa, ax=axes[0], polar_ax=axes[1])
            plotting.suptitle(fig, f"{plotting.plain_text(title)}: shaking force on the frame")
            fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=2, frameon=False)
        return fig

    return [Figure("torque", torque), Figure("pin_forces", pins), Figure("shaking", shaking)]
