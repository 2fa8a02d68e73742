"""A four-bar deck run: the listing's output file (``method = 'listing'``) and its audit against
the closed loop, or the closed-loop table with accelerations, coupler point and forces
(``method = 'exact'``); the summary lines, tidy table, summary and figures."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from driver._deck import Params
from driver._result import Figure, Result, Tidy
from driver._runner import study_run
from driver._table import Column, fortran_f, render_table
from driver.fourbar._analysis import (
    ST,
    TIDY_UNITS,
    Extremes,
    Grashof,
    assembly_intervals,
    coupler_point,
    crank_angles,
    deg360,
    exact_columns,
    exact_grid,
    extremes,
    grashof,
    limit_angles,
    listing_grid,
    rocking_motions,
    summary_rows,
    tidy_frame,
    tidy_part,
)
from driver.fourbar._batch import summary_of
from driver.fourbar._kernel import Listing, Point, State
from driver.fourbar._spec import SPEC, band_of, force_value, forces_active

if TYPE_CHECKING:   # annotations only: pandas is imported when a table is built
    import pandas as pd

    from driver._mechanism import MechanismFrames

__all__ = ["run", "listing_text", "exact_table", "summary_lines", "audit", "deck_figures", "output_name", "animation_frames"]


def _echo(p: Params) -> list[str]:
    """Deck inputs echoed in the English header of exact runs."""
    rows = [("fixed link O2-O4", p.fixed_link, ""), ("crank (driver) O2-A", p.crank, ""),
            ("coupler A-B", p.coupler, ""), ("rocker (output) O4-B", p.rocker, ""),
            ("crank speed", p.omega, "rad/s"), ("crank acceleration", p.alpha, "rad/s^2")]
    return [f"  {name:<24}{fortran_f(v, 12, 4)} {u}".rstrip() for name, v, u in rows]


def listing_text(p: Params, table: np.ndarray, status: np.ndarray) -> tuple[list[str], list[Column]]:
    """The listing's output file: its header (format 15), column line and rows (format 25);
    and the table's columns."""
    head = ["", "", "",
            f"  panjang OA-OB (fixed link):  {fortran_f(p.fixed_link, 5, 2, 'legacy')}",
            f"  panjang poros engkol (crank/driver):  {fortran_f(p.crank, 5, 2, 'legacy')}",
            f"  panjang batang penghubung (coupler):  {fortran_f(p.coupler, 5, 2, 'legacy')}",
            f"  panjang batang ayun (rocker/output link):  {fortran_f(p.rocker, 5, 2, 'legacy')}",
            f"  kecepatan sudut poros engkol (rad/detik):  {fortran_f(p.omega, 5, 2, 'legacy')}",
            ""]
    # format 25: (2x,i3,2x,7(f5.1,2x),3x,2(f7.4,3x))
    cols = ([Column("i", "i", 3, 0, 2)] + [Column(h, "f", 5, 1, 2, "legacy") for h in ("epsl", "phi", "beta", "xa", "ya", "xb")]
            + [Column("yb", "f", 5, 1, 2, "legacy"), Column("omr", "f", 7, 4, 5, "legacy"),
               Column("oms", "f", 7, 4, 3, "legacy")])
    rows, trailers = [], []
    for row, st in zip(table, status):
        if st == ST["no_assembly"]:
            rows.append([int(row[Listing.THETA])] + [None] * 9)
            trailers.append("cannot be assembled: the listing's arccos argument leaves [-1, 1]")
        elif st == ST["toggle"]:
            rows.append([int(row[Listing.THETA])] + list(row[Listing.EPSL:Listing.YB + 1]) + [None, None])
            trailers.append("toggle: sin(phi - epsl) = 0, velocities unbounded")
        else:
            rows.append([int(row[Listing.THETA])] + list(row[Listing.EPSL:]))
            trailers.append("")
    lines = render_table(cols, rows, trailers)
    return head + [lines[0], ""] + lines[1:], cols


def exact_table(p: Params, theta: np.ndarray, out: np.ndarray, status: np.ndarray,
                cp: np.ndarray | None = None, chain: Grashof | None = None) -> list[str]:
    """Fixed-format exact table: the listing's ten columns (angles rounded) plus accelerations,
    and the coupler point's position and speed when the deck defines one (``cp`` from
    kernel.fourbar_coupler_point).  ``chain``: the linkage's class (:func:`grashof`); the rows of
    a chain that cannot move say its class instead of the distance that fails."""
    whole = np.all(np.isclose(theta, np.round(theta)))
    tcol = Column("theta", "i", 5, 0, 2) if whole else Column("theta", "f", 8, 3, 2)
    # headers: the tidy columns' names without their unit (on the line below)
    cols = [tcol, Column("coupler", "f", 7, 1), Column("rocker", "f", 7, 1), Column("transmission", "f", 7, 1)]
    cols += [Column(h, "f", 9, 4) for h in ("xa", "ya", "xb", "yb")]
    cols += ([Column(h, "f", 10, 4) for h in ("coupler_omega", "rocker_omega")]
             + [Column(h, "f", 11, 4) for h in ("coupler_alpha", "rocker_alpha")])
    units = ["[deg]", "[deg]", "[deg]", "[deg]", "", "", "", "", "[rad/s]", "[rad/s]", "[rad/s2]", "[rad/s2]"]
    if cp is not None:
        cols += [Column("xp", "f", 9, 4), Column("yp", "f", 9, 4), Column("vp", "f", 10, 4)]
        units += ["", "", "[len/s]"]
        extra = np.column_stack([cp[:, Point.X], cp[:, Point.Y], np.hypot(cp[:, Point.VX], cp[:, Point.VY])])
    ang = np.column_stack([deg360(out[:, State.COUPLER_ANGLE]), deg360(out[:, State.ROCKER_ANGLE]),
                           np.degrees(out[:, State.TRANSMISSION_ANGLE])])
    rows, trailers = [], []
    d = np.hypot(p.fixed_link - out[:, State.XA], out[:, State.YA])
    pins, rates = slice(State.XA, State.YB + 1), slice(State.XA, State.ROCKER_ALPHA + 1)
    for k in range(len(theta)):
        t = int(round(theta[k])) if whole else theta[k]
        if status[k] == ST["indeterminate"]:
            rows.append([t, None, None, None, out[k, State.XA], out[k, State.YA]] + [None] * 6)
            trailers.append("indeterminate: crank pin A on the rocker pivot O4, B free on a circle")
        elif status[k] == ST["no_assembly"]:
            rows.append([t, None, None, None, out[k, State.XA], out[k, State.YA]] + [None] * 6)
            trailers.append(f"{chain.name}: {'no position exists' if chain.name == 'impossible chain' else 'no motion'}"
                            if chain is not None and not chain.movable else
                            f"cannot be assembled: |A O4| = {d[k]:.4f} outside "
                            f"[{abs(p.coupler - p.rocker):g}, {p.coupler + p.rocker:g}]")
        elif status[k] == ST["toggle"]:
            rows.append([t, *ang[k], *out[k, pins]] + [None] * 4)
            trailers.append("toggle: coupler and rocker collinear, velocity unbounded")
        else:
            rows.append([t, *ang[k], *out[k, rates]])
            trailers.append("")
        if cp is not None:
            placed = status[k] in (ST["ok"], ST["toggle"])
            rows[-1] += [extra[k, 0] if placed else None, extra[k, 1] if placed else None,
                         extra[k, 2] if status[k] == ST["ok"] else None]
    lines = render_table(cols, rows, trailers)
    unit_line = "".join(" " * c.sep + u.rjust(max(c.width, len(c.header))) for c, u in zip(cols, units)).rstrip()
    return [lines[0], unit_line] + lines[1:]


def _rotation(p: Params, g: Grashof) -> str:
    """The crank's rotation in words: none (a chain that cannot move), a full turn (through the
    change points of a change-point linkage, where the links lie in line), or limited by the
    limit (toggle) crank angles."""
    lim = limit_angles(p.fixed_link, p.crank, p.coupler, p.rocker)
    angles = ", ".join(f"{a:.3f}" for a in lim) + " deg"
    if not g.movable:
        return "none: " + ("the chain cannot be assembled at any crank angle" if g.name == "impossible chain"
                           else "the chain lies flat in one position")
    if g.full_crank_rotation:
        return "full turn" + (f", through the change point(s) at {angles} (the links in line)" if lim else "")
    return "limited: limit (toggle) crank angles " + angles


def summary_lines(p: Params, g: Grashof, ex: Extremes | None) -> list[str]:
    """Words and numbers after an exact table."""
    out = ["", "  Summary (closed-loop solution, branch = " + p.branch + ")",
           f"    Grashof class ........ {g.name}  ({g.condition})",
           "    crank rotation ....... " + _rotation(p, g)]
    if ex is None:
        out.append("    the linkage cannot be assembled anywhere in the requested range")
        return out
    lo, hi = band_of(p)
    meets = lo <= ex.mu_min and ex.mu_max <= hi
    out += [f"    transmission angle ... min {ex.mu_min:.2f} deg at theta = {ex.mu_min_at:.2f}, "
            f"max {ex.mu_max:.2f} deg at theta = {ex.mu_max_at:.2f}",
            f"    {lo:g}-{hi:g} deg band ...... " + ("met" if meets else "NOT met"),
            ("    rocker ............... turns fully (no extreme positions)" if ex.rocker_turns else
             f"    rocker positions ..... {ex.rocker_min:.3f} deg (theta = {ex.rocker_min_at:.3f}) to "
             f"{ex.rocker_max:.3f} deg (theta = {ex.rocker_max_at:.3f}); swing "
             f"{ex.rocker_swing:.3f} deg")]
    if ex.toggles:
        out.append("    peak speeds .......... unbounded at the toggle positions (theta = "
                   + ", ".join(f"{a:.3f}" for a in ex.toggles) + " deg)")
    else:
        out += [f"    peak rocker speed .... {ex.rocker_omega_peak:.4f} rad/s at theta = {ex.rocker_omega_peak_at:.2f} deg",
                f"    peak coupler speed ... {ex.coupler_omega_peak:.4f} rad/s at theta = {ex.coupler_omega_peak_at:.2f} deg"]
    if ex.assembled_fraction < 1.0:
        out.append(f"    assemblable .......... about {100 * ex.assembled_fraction:.1f} % of the requested range")
    return out


def audit(p: Params, theta: np.ndarray, table: np.ndarray, lst_status: np.ndarray,
          out: np.ndarray, status: np.ndarray) -> tuple[list[str], str | None, dict[str, np.ndarray]]:
    """Rows of the listing that violate loop closure, compared with the exact solution; the
    lines, the warning (None: every row closes) and the closure columns (``theta_deg``,
    ``ab_length``, ``ab_deviation``, ``loop_not_closed``)."""
    ab = np.hypot(table[:, Listing.XB] - table[:, Listing.XA], table[:, Listing.YB] - table[:, Listing.YA])
    dev = ab - p.coupler
    good = (lst_status == ST["ok"]) & (status == ST["ok"])
    bad = good & (np.abs(dev) > 1e-4 * p.coupler)
    lines = ["", "  Audit of the listing against the closed loop (method = 'exact', branch = 'open')"]
    frame = {"theta_deg": theta, "ab_length": ab, "ab_deviation": dev, "loop_not_closed": bad}
    if not bad.any():
        lines.append(f"    every row closes the loop: |AB| = coupler within {np.max(np.abs(dev[good]), initial=0):.2e}")
        return lines, None, frame
    worst = int(np.argmax(np.where(bad, np.abs(dev), -1)))
    cols = [Column("i", "i", 5, 0), Column("|AB|", "f", 9, 4), Column("dev", "f", 9, 4),
            Column("xb lst", "f", 8, 3), Column("yb lst", "f", 8, 3), Column("xb", "f", 8, 3),
            Column("yb", "f", 8, 3), Column("oms lst", "f", 9, 4), Column("rocker_omega", "f", 12, 4)]
    rows = [[int(theta[k]), ab[k], dev[k], table[k, Listing.XB], table[k, Listing.YB], out[k, State.XB],
             out[k, State.YB], table[k, Listing.OMS], out[k, State.ROCKER_OMEGA]] for k in np.flatnonzero(bad)]
    lines += [f"    {int(bad.sum())} of {len(theta)} rows have a coupler length |AB| different from "
              f"the deck's {p.coupler:g}; largest deviation {dev[worst]:+.4f} at i = {int(theta[worst])}:"]
    lines += ["  " + l for l in render_table(cols, rows)]
    lines += ["    Why: for crank angles in (180, 360) deg the listing's quadrant test sends",
              "    sigy > 0, sigx > 0 to 'sigma = 2 pi - |atan|' (meant: |atan|), so those rows",
              "    repeat the positions of 360 - i (mirror image) and their velocities are",
              "    wrong; the transmission angle column is still right (it depends on |A O_B| only).",
              "    Use method = 'exact' for correct values (columns 'xb', 'yb', 'rocker_omega' above)."]
    warn = (f"listing rows violate loop closure at {int(bad.sum())} crank angles "
            f"(largest |AB| deviation {dev[worst]:+.4f} at {int(theta[worst])} deg); see the audit in the .out")
    return lines, warn, frame


@study_run(SPEC)
def run(params: Params, progress: bool = False) -> Result:
    """Analyse a planar four-bar linkage driven by its crank over a range of crank angles.

    ``method = 'exact'`` solves the loop on the requested branch: angles, angular velocities and
    accelerations of coupler and rocker, the Grashof class, limit and toggle positions, the
    transmission angle and a summary; ``method = 'listing'`` runs the published program cell for
    cell and audits it.  With ``mass`` the force analysis is added (joint forces, input torque,
    shaking force and moment).  Link lengths are in any one consistent unit (metres when
    ``mass`` is given); angles in degrees, crank speed in rad/s.

    Examples
    --------
    >>> import driver
    >>> r = driver.fourbar.run(fixed_link=12, crank=5, coupler=15, rocker=9, step_deg=20)
    >>> r.summary["grashof_class"], round(r.summary["mu_min_deg"], 3)
    ('crank-rocker', 17.852)
    >>> r.tidy.shape
    (19, 15)
    """
    p = params
    theta = crank_angles(p)
    g = grashof(p.fixed_link, p.crank, p.coupler, p.rocker)
    out, status = exact_grid(p, theta)
    cp = coupler_point(p, theta, out, status)
    rows = summary_rows(p)   # the summary kernel, once: the .out's headline figures and the summary
    ex = extremes(p, rows[0])
    chain = None if g.movable else g.name.replace(" ", "_")   # the tidy rows' status of a chain that cannot move
    exact_part = tidy_part("exact", theta, exact_columns(out, status, cp, p.coupler), status, chain=chain)
    warnings: list[str] = []
    failure = run_failure(p, g, ex)
    title = p.title or f"{p.path.stem}"
    if p.method == "listing":
        table, lst_status = listing_grid(p)
        lines, _ = listing_text(p, table, lst_status)
        alines, warn, closure = audit(p, theta, table, lst_status, out, status)
        lines += alines + summary_lines(p, g, ex)
        if warn:
            warnings.append(warn)
        lst_cols = dict(zip(["coupler_deg", "rocker_deg", "transmission_deg", "xa", "ya", "xb", "yb",
                             "coupler_omega_rad_s", "rocker_omega_rad_s"], table[:, Listing.EPSL:].T))
        lst_cols["ab_error"] = np.where(lst_status == ST["ok"], closure["ab_deviation"], np.nan)
        listed = tidy_part("listing", theta, lst_cols, lst_status, closure["loop_not_closed"], chain=chain)
        tidy = Tidy(listed, exact_part, units=TIDY_UNITS)
        listing_part: dict[str, Any] | None = listed
    else:
        listing_part = None
        lines = [f"  four-bar linkage: closed-loop analysis (method = exact, branch = {p.branch})",
                 f"  deck: {p.path}" + (f" -- {p.title}" if p.title else ""), ""] + _echo(p) + [""]
        lines += exact_table(p, theta, out, status, cp, g) + summary_lines(p, g, ex)
        if cp is not None:
            lines += [f"    coupler point P ...... u = {p.coupler_point[0]:g} along A->B, v = {p.coupler_point[1]:g} "
                      "to its left; xp, yp its position, vp its speed [length/s]"]
        if forces_active(p):   # the force analysis's modules: imported by the decks that give masses
            from driver.fourbar._report_forces import force_section
            lines += force_section(p, theta, out, status, exact_part, None if g.movable else g.name)
        for k in np.flatnonzero(status == ST["no_assembly"])[:1 if failure is None else 0]:
            warnings.append(f"the linkage cannot be assembled at {int((status == ST['no_assembly']).sum())} "
                            f"of {len(theta)} crank angles (first at {theta[k]:g} deg)")
        tidy = Tidy(exact_part, units=TIDY_UNITS)
    if failure:
        lines += ["", f"  FAILED: {failure}"]
    summary = summary_of(p, rows)
    figs = deck_figures(p, title, listing_part)
    if forces_active(p):   # a link past its yield strength: said in the .out (force_section) and warned
        from driver.fourbar._report_forces import figures as force_figures
        from driver.fourbar._report_forces import yield_warnings
        warnings += yield_warnings(p, summary)
        figs += force_figures(p, title, exact_grid)
    return Result(text="\n".join(lines) + "\n", tidy=tidy, summary=summary, warnings=warnings, failure=failure,
                  figures=figs, design_failure=failure is not None)


def run_failure(p: Params, g: Grashof, ex: Extremes | None) -> str | None:
    """Why a run produced no motion, or None: a chain that cannot move (its class's reason), or a
    linkage that assembles nowhere in the deck's crank range (with where it does assemble).  The
    run then exits 1 (docs/fourbar.md, "Chains that cannot close")."""
    if not g.movable:
        return f"{g.name}: {g.reason}"
    if ex is None:
        spans = assembly_intervals(p.fixed_link, p.crank, p.coupler, p.rocker)
        where = "" if not spans else " (it assembles for crank angles " + ", ".join(
            f"{lo:.3f} to {hi:.3f}" for lo, hi in spans) + " deg)"
        lo, hi = sorted((p.start_deg, p.stop_deg))
        return f"the linkage cannot be assembled anywhere in the requested crank range {lo:g} to {hi:g} deg{where}"
    return None


def output_name(p: Params) -> str:
    """What the output link is called in figures: 'output crank' when it turns fully (a
    double-crank, a drag link), 'rocker' otherwise."""
    g = grashof(p.fixed_link, p.crank, p.coupler, p.rocker)
    return "output crank" if "double-crank" in g.name else "rocker"


def length_units(p: Params) -> str:
    """The deck's length unit in words: metres when it gives masses (the force analysis is in SI
    units), else '' (any consistent unit)."""
    return "m" if forces_active(p) else ""


def counterweight_view(p: Params) -> dict[str, tuple[float, float]] | None:
    """The Berkof-Lowen counterweights a ``balance = 'force'`` deck adds, as drawings show them:
    ``radius`` [m], ``angle_deg`` off the link line and ``mass`` [kg] of (crank, output link);
    None for a deck that does not balance."""
    if not forces_active(p) or force_value(p, "balance") != "force":
        return None
    from driver.fourbar._analysis_forces import counterweights as berkof_lowen  # decks that give masses only
    cw = berkof_lowen(p)
    return {"radius": cw.radius, "angle_deg": cw.angle_deg, "mass": cw.mass}


def deck_figures(p: Params, stem_title: str, listing_part: dict[str, Any] | pd.DataFrame | None) -> list[Figure]:
    """The figures of a run (drawn on demand): the curves and the linkage at its limit positions;
    for a chain that cannot move, its links laid out beside its longest (the gap seen).
    ``listing_part``: the listing's tidy columns (:func:`tidy_part`) or frame, for a listing run."""
    g = grashof(p.fixed_link, p.crank, p.coupler, p.rocker)
    chain = None if g.movable else f"{g.name}: {g.reason}"

    def listing_frame() -> pd.DataFrame | None:
        if listing_part is None or not isinstance(listing_part, dict):
            return listing_part
        return Tidy(listing_part, units=TIDY_UNITS).frame()

    def curves():
        from driver.fourbar import _figures as figures  # matplotlib is the optional [plot] extra: imported when drawn
        theta = np.linspace(p.start_deg, p.stop_deg, 721)
        out, st = exact_grid(p, theta)
        exact = tidy_frame("exact", theta, exact_columns(out, st), st)
        return figures.fourbar_curves(exact, listing_frame(), stem_title, band=band_of(p), output=output_name(p),
                                      chain=chain)

    def linkage():
        from driver.fourbar import _figures as figures
        if not g.movable:
            return figures.fourbar_chain({"fixed link": p.fixed_link, "crank": p.crank, "coupler": p.coupler,
                                          "rocker": p.rocker}, g.name, str(g.reason), stem_title,
                                          units=length_units(p))
        lo, hi = sorted((p.start_deg, p.stop_deg))
        # the deck's crank range when it is less than a turn (a function generator's design range)
        theta = np.linspace(lo, hi, 721) if hi - lo < 360.0 else np.linspace(0.0, 360.0, 721)
        out, st = exact_grid(p, theta)
        cp = coupler_point(p, theta, out, st)
        motions = rocking_motions(p) if hi - lo >= 360.0 else None
        if motions:   # a crank that cannot turn: it rocks between its limit positions
            drawn = []
            for m in motions:
                mp = coupler_point(p, m.theta, m.out, m.status)
                drawn.append({"lo": m.lo, "hi": m.hi, "theta": m.theta, "out": m.out, "stroke": m.stroke,
                              "branch": m.branch, "point": None if mp is None else mp[:, :2]})
            return figures.fourbar_linkage(p.fixed_link, theta, out, st == ST["ok"], None, stem_title,
                                           output=output_name(p), motions=drawn, units=length_units(p),
                                           counterweights=counterweight_view(p))
        limits = []
        for a in limit_angles(p.fixed_link, p.crank, p.coupler, p.rocker):
            if theta[0] - 1e-9 <= a <= theta[-1] + 1e-9 or hi - lo >= 360.0:
                row, rst = exact_grid(p, np.array([a]))
                if rst[0] != ST["no_assembly"] and np.all(np.isfinite(row[0, State.XA:State.YB + 1])):
                    limits.append((a, row[0]))
        return figures.fourbar_linkage(p.fixed_link, theta, out, st == ST["ok"], listing_frame(), stem_title,
                                       point=None if cp is None else cp[:, :2], output=output_name(p),
                                       limits=limits, units=length_units(p), counterweights=counterweight_view(p))

    return [Figure("curves", curves), Figure("linkage", linkage)]


def animation_frames(params: Params, result: Result | None = None, n: int = 180) -> MechanismFrames:
    """The linkage's positions at ``n`` crank angles over one turn, for the report page's animation
    (:class:`driver._mechanism.MechanismFrames`): the ground pivots O2 and O4, crank pin A, coupler
    pin B and coupler point P, from the kernel's closed-loop states; for a crank that cannot turn,
    its rocking motions (out on one assembly branch, back on the other) with their strokes in the
    frame labels, each motion a segment, and the limit positions dashed."""
    from driver._mechanism import Guide, Link, MechanismFrames  # the page's animation only
    motions = rocking_motions(params, max(8, n // 2 // max(
        1, len(assembly_intervals(params.fixed_link, params.crank, params.coupler, params.rocker) or [1]))))
    g = params.fixed_link
    chain = grashof(params.fixed_link, params.crank, params.coupler, params.rocker)
    phase: list[str] = []
    segments: list[tuple[int, int]] = []
    guides = [Guide(np.array([[0.0, 0.0], [g, 0.0]]), "fixed link")]
    if motions:   # a crank that cannot turn: it rocks between its limit positions, out on one
        # assembly branch and back on the other; each assembly interval a motion of its own
        theta = np.concatenate([m.theta for m in motions])
        out = np.vstack([m.out for m in motions])
        status = np.concatenate([m.status for m in motions])
        word = {1: "open", -1: "crossed"}
        tag = (lambda i: "") if len(motions) == 1 else (lambda i: f", motion {i + 1} of {len(motions)}")
        arrow = {0: "\u2192", 1: "\u2190"}   # forward stroke, return stroke
        phase = [f" {arrow[int(st)]} {word[int(b)]} assembly{tag(i)}"
                 for i, m in enumerate(motions) for st, b in zip(m.stroke, m.branch)]
        starts = np.cumsum([0] + [len(m.theta) for m in motions])
        segments = [(int(a), int(b)) for a, b in zip(starts[:-1], starts[1:])]
        for m in motions:   # the limit positions, where the crank reverses: O2-A-B-O4 dashed
            for ang, k in ((m.lo, 0), (m.hi, len(m.theta) // 2 - 1)):
                guides.append(Guide(np.vstack([[0.0, 0.0], m.out[k, 3:5], m.out[k, 5:7], [g, 0.0]]),
                                    f"limit position: crank angle {ang:.1f}\u00b0 (the crank reverses)", dashed=True))
    else:
        theta = np.linspace(0.0, 360.0, n, endpoint=False)
        out, status = exact_grid(params, theta)
    ok = (status != ST["no_assembly"]) & (status != ST["indeterminate"])
    cp = coupler_point(params, theta, out, status)
    names = ("O2", "A", "B", "O4") + (("P",) if cp is not None else ())
    pts = np.full((len(theta), len(names), 2), np.nan)
    pts[:, 0] = 0.0
    pts[:, 3] = (g, 0.0)
    pts[:, 1] = out[:, 3:5]
    pts[ok, 2] = out[ok, 5:7]
    if cp is not None:
        pts[ok, 4] = cp[ok, :2]
    coupler = Link("coupler", (1, 2, 4), body=True) if cp is not None else Link("coupler", (1, 2))
    links = [Link("crank", (0, 1)), coupler, Link(output_name(params), (3, 2))]
    masses: tuple[int, ...] = ()
    cw = counterweight_view(params)
    if cw is not None:   # the Berkof-Lowen counterweights ride on crank and output link, off their lines
        crank_dir = np.arctan2(pts[:, 1, 1], pts[:, 1, 0])
        out_dir = np.arctan2(pts[:, 2, 1], pts[:, 2, 0] - g)
        extra = []
        for k, (pivot, direction, name) in enumerate(((0, crank_dir, "crank counterweight"),
                                                      (3, out_dir, f"{output_name(params)} counterweight"))):
            radius, off, mass = cw["radius"][k], np.radians(cw["angle_deg"][k]), cw["mass"][k]
            if mass > 0 and radius > 0:
                at = pts[:, pivot] + radius * np.column_stack([np.cos(direction + off), np.sin(direction + off)])
                extra.append((f"{name} {mass:.3g} kg", at, pivot, k))
        if extra:
            pts = np.concatenate([pts, np.stack([e[1] for e in extra], axis=1)], axis=1)
            base = len(names)
            names = names + tuple(e[0] for e in extra)
            links += [Link(f"arm of the {e[0].rpartition(' ')[0].rpartition(' ')[0]}", (e[2], base + j),
                           colour=(0, 2)[e[3]]) for j, e in enumerate(extra)]
            masses = tuple(range(base, base + len(extra)))
    return MechanismFrames(
        names=names, points=pts, links=tuple(links), masses=masses,
        labels=tuple(f"{t:.0f}\u00b0" + (phase[k] if phase else "") for k, t in enumerate(np.round(theta, 6))),
        units=length_units(params),
        ground=(0, 3), joints=(1, 2), markers=(4,) if cp is not None else (), guides=tuple(guides),
        paths=(1, 2, 4) if cp is not None else (1, 2), segments=tuple(segments), frame_name="crank angle",
        caption="The linkage over " + ("its rocking motions between the limit positions (dashed)" if motions
                                       else "one crank turn") + ", positions from the kernel's closed loop."
        + (" Discs: the Berkof-Lowen counterweights of the force balance." if masses else ""),
        invalid_note=("the linkage cannot be assembled at this crank angle" if chain.movable
                      else f"{chain.name}: {chain.reason}"))
