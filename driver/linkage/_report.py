"""A ``&linkage`` deck run: the .out file (the mechanism echoed, per-position tables of links,
points, slides, transmission and pressure angles, forces; the events and the summary), the
tidy long table, the summary and the figures."""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from driver._deck import Params
from driver._result import Figure, Result
from driver._runner import study_run
from driver._table import Column, render_table
from driver.linkage._analysis import JOINT_WORDS, Event, Motion, events, input_label, solve, tidy_frame
from driver.linkage._batch import summary_of, summary_rows
from driver.linkage._kernel import DriverCol, JointCol, LinkageStatus, LinkCol, PointCol, ShakeCol, SlideCol
from driver.linkage._kernel_program import Mechanism
from driver.linkage._spec import SPEC

__all__ = ["run", "mechanism_lines", "event_lines", "summary_lines", "tables", "deck_figures"]

#: value columns of one printed table (wider tables are split)
TABLE_WIDTH = 7


def _decimals(values: np.ndarray, digits: int = 6) -> int:
    """Decimals that give the largest |value| about ``digits`` significant digits (1..8)."""
    big = float(np.max(np.abs(values))) if values.size else 0.0
    if not (big > 0 and math.isfinite(big)):
        return 4
    return int(min(8, max(1, digits - 1 - math.floor(math.log10(big)))))


def _num(v: Any, digits: int = 6) -> str:
    """A number in words with at most ``digits`` significant digits (%g style; no '-0')."""
    text = f"{v:.{digits}g}"
    return "0" if float(text) == 0 else text


def _at(v: float) -> str:
    """An input position in words: 4 decimals (deg or length), no '-0'."""
    text = f"{v:.4f}"
    return "0.0000" if float(text) == 0 else text


def _scaled(v: float, scale: float) -> str:
    """``v`` in words, zero when below 1e-9 of ``scale`` (rounding of a quantity of that size)."""
    return _num(0.0 if abs(v) <= 1e-9 * abs(scale) else v)


def mechanism_lines(p: Params, mech: Mechanism) -> list[str]:
    """The mechanism as the deck describes it, and its Grübler count."""
    xname, xunit = input_label(mech)
    out = ["  Mechanism", "    links ............. " + ", ".join(mech.links)]
    piv = [f"{n} ({_num(u)}, {_num(v)})" for n, link, u, v in mech.points if link == 1]
    if piv:
        out.append("    ground pivots ..... " + ", ".join(piv))
    for name, link, x, y, ang in mech.guides:
        out.append(f"    guide {name:<12} on {mech.links[link - 1]} through ({_num(x)}, {_num(y)}) at "
                   f"{_num(math.degrees(ang))} deg")
    if mech.driver == "crank":
        anchor = mech.point_names[mech.driver_anchor - 1]
        out.append(f"    driver ............ crank '{mech.links[mech.driver_link - 1]}' {anchor} -> {mech.driver_pin}, "
                   f"length {_num(mech.driver_length)}; omega {_num(mech.omega)} rad/s, alpha {_num(mech.alpha)} rad/s^2")
    else:
        g = mech.guides[mech.driver_anchor - 1][0]
        out.append(f"    driver ............ slider '{mech.links[mech.driver_link - 1]}' on {g}, pin {mech.driver_pin} "
                   f"offset {_num(mech.driver_length)}; speed {_num(mech.omega)}, acceleration {_num(mech.alpha)}")
    for i, d in enumerate(mech.dyads, start=1):
        a, b, c = d.joints
        l1, l2 = d.links
        dims = {"rrr": f"{l1} {a}-{c} {_num(d.dims[0])}, {l2} {b}-{c} {_num(d.dims[1])}",
                "rrp": f"rod {l1} {a}-{c} {_num(d.dims[0])}, block {l2} on {b} (pin offset {_num(d.dims[1])})",
                "prr": f"block {l1} on {a} (pin offset {_num(d.dims[0])}), rod {l2} {b}-{c} {_num(d.dims[1])}",
                "rpr": f"{l1} about {a} with slot {c} (offset {_num(d.dims[0])}), block {l2} pinned at {b} "
                       f"(pin offset {_num(d.dims[1])})",
                "prp": f"block {l1} on {a} (offset {_num(d.dims[0])}), block {l2} on {b} (offset "
                       f"{_num(d.dims[1])}), pinned at {c}"}[d.kind]
        mode = "" if d.kind == "prp" else f", mode {d.mode:+d}"
        out.append(f"    group {i} {d.kind.upper():<3} ...... {dims}{mode}")
    for name, link, u, v in mech.points:
        if name in mech.tracers:
            out.append(f"    point {name:<12} on {mech.links[link - 1]} at u = {_num(u)}, v = {_num(v)}")
    n, j = len(mech.links), 1 + 3 * len(mech.dyads)
    out.append(f"    Grübler count ..... 3 (n - 1) - 2 j = 3 x {n - 1} - 2 x {j} = {3 * (n - 1) - 2 * j}")
    out.append(f"    inputs ............ {xname.replace('_deg', '')} from {_num(p.start)} to {_num(p.stop)} "
               f"{xunit} by {_num(p.step)}")
    return out


def _trailers(m: Motion) -> list[str]:
    """Per row: the groups that are not assembled, in words."""
    out = []
    for k in range(len(m.x)):
        words = [f"{d.name}: {LinkageStatus(int(s)).what}" for d, s in zip(m.mech.dyads, m.a.status[k])
                 if s != LinkageStatus.ok]
        out.append("; ".join(words))
    return out


def _table(title: str, m: Motion, heads: Sequence[str], values: Sequence[np.ndarray], masks: Sequence[np.ndarray],
           unit: str, trailers: list[str]) -> list[str]:
    """One or more fixed-format tables of ``values`` (one array per column) against the input."""
    xname, xunit = input_label(m.mech)
    whole = bool(np.all(np.isclose(m.x, np.round(m.x))))
    lines: list[str] = []
    for c0 in range(0, len(heads), TABLE_WIDTH):
        hs, vs, ms = heads[c0:c0 + TABLE_WIDTH], values[c0:c0 + TABLE_WIDTH], masks[c0:c0 + TABLE_WIDTH]
        xcol = Column("input", "i", 7, 0, 2) if whole else Column("input", "f", 10, 4, 2)
        cols = [xcol]
        for h, v, mk in zip(hs, vs, ms):
            d = _decimals(v[mk]) if mk.any() else 4
            cols.append(Column(h[:12], "f", max(12, len(h[:12])), d, 1))
        rows = []
        for k in range(len(m.x)):
            rows.append([int(round(m.x[k])) if whole else m.x[k]] + [float(v[k]) if mk[k] else None
                                                                      for v, mk in zip(vs, ms)])
        part = "" if len(heads) <= TABLE_WIDTH else f" (part {c0 // TABLE_WIDTH + 1})"
        lines += ["", f"  {title}{part}  [{unit}; input in {xunit}]"] + render_table(cols, rows, trailers)
    return lines


def tables(m: Motion) -> list[str]:
    """The per-position tables of a run."""
    mech, a = m.mech, m.a
    placed, ok = m.placed, m.ok
    trail = _trailers(m)
    none = [""] * len(m.x)
    links = mech.links[1:]
    out = _table("Link angles (ccw from the x-axis, 0..360)", m, links,
                 [np.mod(np.degrees(a.links[:, LinkCol.ANGLE, i]), 360.0) for i in range(1, len(mech.links))],
                 [placed] * len(links), "deg", trail)
    out += _table("Link angular velocities", m, links, [a.links[:, LinkCol.OMEGA, i] for i in range(1, len(mech.links))],
                  [ok] * len(links), "rad/s", none)
    out += _table("Link angular accelerations", m, links,
                  [a.links[:, LinkCol.ALPHA, i] for i in range(1, len(mech.links))], [ok] * len(links), "rad/s^2", none)
    pts = [(j, n) for j, (n, link, _, _) in enumerate(mech.points) if link != 1]
    heads, vals, masks = [], [], []
    for j, n in pts:
        heads += [f"x {n}", f"y {n}"]
        vals += [a.points[:, PointCol.X, j], a.points[:, PointCol.Y, j]]
        masks += [placed, placed]
    out += _table("Joint and point positions", m, heads, vals, masks, "length", none)
    heads, vals, masks = [], [], []
    for j, n in pts:
        heads += [f"vx {n}", f"vy {n}"]
        vals += [a.points[:, PointCol.VX, j], a.points[:, PointCol.VY, j]]
        masks += [ok, ok]
    out += _table("Joint and point velocities", m, heads, vals, masks, "length/s", none)
    heads, vals, masks = [], [], []
    for j, n in pts:
        heads += [f"ax {n}", f"ay {n}"]
        vals += [a.points[:, PointCol.AX, j], a.points[:, PointCol.AY, j]]
        masks += [ok, ok]
    out += _table("Joint and point accelerations", m, heads, vals, masks, "length/s^2", none)
    if mech.slides:
        heads, vals, masks = [], [], []
        for j, (n, _, _) in enumerate(mech.slides):
            heads += [f"s {n}", f"v {n}", f"a {n}"]
            vals += [a.slides[:, SlideCol.S, j], a.slides[:, SlideCol.V, j], a.slides[:, SlideCol.A, j]]
            masks += [placed, ok, ok]
        out += _table("Slides along their guides (displacement, rate, acceleration)", m, heads, vals, masks,
                      "length, length/s, length/s^2", none)
    heads = [("mu " if d.kind == "rrr" else "press ") + d.joints[2] for d in mech.dyads]
    out += _table("Transmission (mu) and pressure angles", m, heads,
                  [np.degrees(a.quality[:, i]) for i in range(len(mech.dyads))],
                  [a.status[:, i] == LinkageStatus.ok for i in range(len(mech.dyads))], "deg", trail)
    if mech.forces:
        drive = "torque" if mech.driver == "crank" else "force"
        heads = [f"driving {drive[0]}", "shake Fx", "shake Fy", "shake M"]
        vals = [a.driver[:, DriverCol.DRIVE], a.shaking[:, ShakeCol.FX], a.shaking[:, ShakeCol.FY],
                a.shaking[:, ShakeCol.M]]
        out += _table(f"Driving {drive} and shaking force and moment (about the origin)", m, heads, vals, [ok] * 4,
                      f"{'N m' if drive == 'torque' else 'N'}; N; N; N m", trail)
        heads, vals = [], []
        for i, d in enumerate(mech.dyads):
            for letter, c0 in (("A", JointCol.AX), ("B", JointCol.BX), ("C", JointCol.CX)):
                heads += [f"{letter}x {d.joints[2]}", f"{letter}y {d.joints[2]}"]
                vals += [a.joints[:, c0, i], a.joints[:, c0 + 1, i]]
        out += _table("Joint forces of each group (joints A, B, C: see below)", m, heads, vals, [ok] * len(heads), "N",
                      none)
        legend = ["", "  Joints of each group (force on the group's link from the other side; couples of sliding "
                  "pairs in the tidy table):"]
        for d in mech.dyads:
            words = JOINT_WORDS[d.kind]
            legend.append(f"    {d.name}: A {words[0].format(*d.joints)}; B {words[1].format(*d.joints)}; "
                          f"C {words[2].format(*d.joints)}")
        out += legend
    return out


def event_lines(m: Motion, evs: list[Event]) -> list[str]:
    """The events of the run in words: assembly failures, toggles, dead centres."""
    xname, xunit = input_label(m.mech)
    word = {"no_assembly": "cannot be assembled", "toggle": "toggle (its two links' constraints parallel)",
            "indeterminate": "indeterminate (attachments coincide)", "dead_centre": "dead centre (output at rest)"}
    out = ["", "  Events (per group, at the run's inputs)"]
    if not evs:
        out.append("    none: every group assembled at every input, no toggle, no dead centre")
    by: dict[tuple[int, str], list[Event]] = {}
    for e in evs:
        by.setdefault((e.group, e.what), []).append(e)
    for (g, what), es in sorted(by.items()):
        spans = ", ".join(_at(e.first) if e.first == e.last else f"{_num(e.first, 7)}..{_num(e.last, 7)}"
                          for e in es[:12]) + (f" (and {len(es) - 12} more)" if len(es) > 12 else "")
        out.append(f"    group {g} ({es[0].name}): {word[what]} at input {spans} {xunit}")
    return out


def summary_lines(p: Params, mech: Mechanism, s: dict[str, Any]) -> list[str]:
    """The summary in words."""
    crank = mech.driver == "crank"
    xunit = "deg" if crank else "length"
    out = ["", f"  Summary (one {'cycle of ' + _num(p.cycle_deg) + ' deg' if crank else 'stroke'} of the input, "
               f"scanned at {p.scan_points} points)"]
    out.append(f"    assembled ............ {100 * s['assembled_fraction']:.2f} % of the cycle"
               + ("" if s["assemblable"] else " (figures needing the whole cycle are left out)"))
    if s["toggle_in_range"]:
        out.append("    toggles .............. in the cycle (velocities unbounded there)")
    unit = "deg" if mech.output[0] == 1 else "length"
    if s["stroke"] is not None:
        out.append(f"    output {mech.output_name:<14} min {_num(s['output_min'])} {unit} at {_at(s['output_min_at'])} "
                   f"{xunit}, max {_num(s['output_max'])} {unit} at {_at(s['output_max_at'])} {xunit}")
        out.append(f"    stroke ............... {_num(s['stroke'])} {unit}")
    elif s["assemblable"]:
        out.append(f"    output {mech.output_name:<14} turns fully (no stroke)")
    if s["time_ratio"] is not None:
        out.append(f"    time ratio ........... {s['time_ratio']:.5f} (slow stroke / quick stroke)")
    if s["mu_min_deg"] is not None:
        out.append(f"    transmission angle ... min {s['mu_min_deg']:.3f} deg at {_at(s['mu_min_at'])} {xunit}, "
                   f"max {s['mu_max_deg']:.3f} deg at {_at(s['mu_max_at'])} {xunit} (all RRR groups)")
    if s["pressure_max_deg"] is not None:
        out.append(f"    pressure angle ....... max {s['pressure_max_deg']:.3f} deg (all sliding groups)")
    for name in mech.links[1:]:
        w, al = s.get(f"omega_peak_{name}_rad_s"), s.get(f"alpha_peak_{name}_rad_s2")
        if w is not None:
            out.append(f"    link {name:<16} peak omega {_num(w)} rad/s, peak alpha {_num(al)} rad/s^2")
    for name, _, _ in mech.slides:
        v, a = s.get(f"slide_rate_peak_{name}"), s.get(f"slide_accel_peak_{name}")
        if v is not None:
            out.append(f"    slide {name:<15} peak rate {_num(v)}, peak acceleration {_num(a)}")
    if mech.forces:
        drive, du = ("torque", "N m") if crank else ("force", "N")
        if s.get("torque_peak") is not None:
            out.append(f"    driving {drive} ....... peak {_num(s['torque_peak'])} {du} at {_at(s['torque_peak_at'])} "
                       f"{xunit}")
        if s.get("torque_mean") is not None:
            out.append(f"    driving {drive} ....... mean {_scaled(s['torque_mean'], s['torque_rms'])} {du}, "
                       f"RMS {_num(s['torque_rms'])} {du}")
        if s.get("shaking_force_peak_N") is not None:
            out.append(f"    shaking .............. peak force {_num(s['shaking_force_peak_N'])} N, peak moment "
                       f"{_num(s['shaking_moment_peak_Nm'])} N m")
        if s.get("energy_fluctuation_J") is not None:
            fw = s.get("flywheel_inertia_kgm2")
            out.append(f"    flywheel ............. energy fluctuation {_num(s['energy_fluctuation_J'])} J"
                       + (f"; inertia {_num(fw)} kg m^2 for C_s = {p.speed_fluctuation:g}" if fw is not None else ""))
    if p.turning_moment is not None:
        out.append(f"    turning-moment table . mean torque {_num(s['table_torque_mean_Nm'])} N m, energy fluctuation "
                   f"{_num(s['table_energy_fluctuation_J'])} J"
                   + (f", flywheel inertia {_num(s['table_flywheel_inertia_kgm2'])} kg m^2 (C_s = "
                      f"{p.speed_fluctuation:g}, omega = {_num(p.omega)} rad/s)"
                      if s.get("table_flywheel_inertia_kgm2") is not None else ""))
    return out


@study_run(SPEC)
def run(params: Params, progress: bool = False) -> Result:
    """Analyse a planar linkage built from a driver and class-II groups (dyads).

    Positions, velocities and accelerations of every joint and point, every link's angle,
    angular velocity and acceleration, every slide; assembly failures, toggles and dead centres
    per group; with ``bodies``, joint forces, the driving torque (or force) and the shaking force
    and moment; the summary (stroke, time ratio, transmission and pressure angles, peaks,
    flywheel).  Lengths in any one unit (metres with masses), angles in degrees.

    Examples
    --------
    >>> import driver
    >>> r = driver.linkage.run(pivots=["O2", "O4"], pivot_xy=[0, 0, 12, 0], driver_joints=["O2", "A"],
    ...                        driver_length=5, step=20, dyads=["RRR"], dyad_joints=["A", "O4", "B"],
    ...                        dyad_links=["coupler", "rocker"], dyad_dims=[15, 9])
    >>> round(r.summary["mu_min_deg"], 3)
    17.852
    """
    p = params
    m = solve(p)
    mech = m.mech
    rows = summary_rows(p, mech)
    s = summary_of(p, rows)
    evs = events(m)
    title = p.title or p.path.stem
    lines = [f"  planar linkage: {title}", f"  deck: {p.path}", ""] + mechanism_lines(p, mech)
    lines += tables(m) + event_lines(m, evs) + summary_lines(p, mech, s)
    warnings = []
    bad = ~m.placed
    if bad.any():
        k = int(np.argmax(bad))
        d = int(np.argmax(m.a.status[k] != LinkageStatus.ok))
        warnings.append(f"the linkage cannot be assembled at {int(bad.sum())} of {len(m.x)} inputs (first at "
                        f"{m.x[k]:g}: group {d + 1}, {mech.dyads[d].name}, "
                        f"{LinkageStatus(int(m.a.status[k, d])).what})")
    return Result(text="\n".join(lines) + "\n", tidy=tidy_frame(m), summary=s, warnings=warnings,
                  figures=deck_figures(p, title))


def deck_figures(p: Params, title: str) -> list[Figure]:
    """The figures of a run, drawn on demand: the mechanism at one pose with the tracer paths,
    the motion curves, the forces, the turning-moment diagram with the flywheel's energy band."""
    def draw(name: str) -> Any:
        from driver.linkage import _figures as figures  # matplotlib (the [plot] extra) only when drawn
        return getattr(figures, name)(p, title)

    figs = [Figure("linkage", lambda: draw("linkage_drawing")), Figure("curves", lambda: draw("motion_curves"))]
    from driver.linkage._spec_model import compile_deck
    mech = compile_deck(p)
    if mech.forces:
        figs.append(Figure("forces", lambda: draw("force_curves")))
    if (mech.forces and mech.driver == "crank") or p.turning_moment is not None:
        figs.append(Figure("turning_moment", lambda: draw("turning_moment")))
    return figs
