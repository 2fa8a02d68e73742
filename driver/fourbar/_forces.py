"""Four-bar force analysis (issue 26): the part of the ``&fourbar`` study that runs when ``mass`` is given.

Joint forces, input torque, shaking force and moment per crank position (kernel
``fortran/fourbar_forces.f90``), the summary (peak, mean and RMS torque, peak pin forces,
shaking force and moment, energy fluctuation and flywheel inertia), Berkof-Lowen
shaking-force balancing (``balance = 'force'``), batch summaries for sweeps and
``&optimize``, and the figures.  Units: SI (lengths in metres when masses are given).
Sign conventions and the equations: docs/fourbar.md, section "Force analysis".

This module holds no physics of its own: the kernel solves the nine unknowns and
balances the linkage; here are the keys, checks, tables and figures.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from driver._deck import Key, Params, non_negative
from driver._result import Figure
from driver._table import Column, fortran_f, render_table
from driver.fourbar import _kernel as kernel

__all__ = ["KEYS", "check", "active", "props", "ForceAnalysis", "analyse", "COLUMNS", "tidy_columns",
           "table_lines", "summary_lines", "summary", "summarise_force_batch", "BATCH_KEYS", "figures",
           "plot_torque", "plot_pin_polars", "plot_shaking"]

ST_OK = kernel.FOURBAR_STATUS["ok"]
LINKS = ("crank", "coupler", "rocker")
#: a link length [m] beyond this with masses given is taken for a unit mistake (millimetres)
MAX_LENGTH_M = 100.0
#: com_distance or counterweight_radius beyond this many link lengths: a unit mismatch
MAX_COM_RATIO = 20.0
#: radius of gyration sqrt(I/m) beyond this many link lengths: a unit mismatch of the inertia
MAX_GYRATION_RATIO = 100.0


def _three(v: Any) -> str | None:
    return None if len(v) == 3 else f"give three values: crank, coupler, rocker (got {len(v)})"


def _finite(v: Any) -> str | None:
    vals = v if isinstance(v, list) else [v]
    return None if all(math.isfinite(x) for x in vals) else "must be finite"


def _three_non_negative(v: Any) -> str | None:
    return _three(v) or _finite(v) or non_negative(v)


KEYS: dict[str, Key] = {
    "mass": Key("floats", default=None, units="kg", check=_three_non_negative,
                doc="masses of crank, coupler, rocker; giving them runs the force analysis (lengths in metres)"),
    "inertia": Key("floats", default=None, units="kg m^2", check=_three_non_negative,
                   doc="moments of inertia about each link's centre of mass (default: slender bar, m L^2 / 12)"),
    "com_distance": Key("floats", default=None, units="m", check=_three_non_negative,
                        doc="centre of mass from the link's first pin: O2 (crank), A (coupler), O4 (rocker) "
                            "(default: mid-link)"),
    "com_angle_deg": Key("floats", default=None, units="deg", check=lambda v: _three(v) or _finite(v),
                         doc="centre of mass off the line to the link's second pin (A, B, B), ccw + (default 0)"),
    "gravity": Key("float", default=None, units="m/s^2", check=_finite,
                   doc="gravitational acceleration along -y (default 9.81)"),
    "load_torque": Key("float", default=None, units="N m", check=_finite,
                       doc="external torque on the rocker, ccw + (default 0)"),
    "load_force_x": Key("float", default=None, units="N", check=_finite,
                        doc="external force on the coupler at coupler_point, x (default 0)"),
    "load_force_y": Key("float", default=None, units="N", check=_finite,
                        doc="external force on the coupler at coupler_point, y (default 0)"),
    "speed_fluctuation": Key("float", default=None, units="1",
                             check=lambda v: None if v > 0 and math.isfinite(v) else f"must be positive (got {v})",
                             doc="coefficient of speed fluctuation C_s for the flywheel inertia dE / (C_s omega^2) "
                                 "(default 0.02)"),
    "balance": Key("str", default=None, choices=("none", "force"),
                   doc="'force': Berkof-Lowen counterweights on crank and rocker, balanced analysis reported too "
                       "(default 'none')"),
    "counterweight_radius": Key("floats", default=None, units="m",
                                check=lambda v: (None if len(v) == 2 else f"give two values: crank, rocker (got {len(v)})")
                                or (None if all(x > 0 for x in v) else "must be positive"),
                                doc="radius of the point-mass counterweights on crank and rocker (default: the "
                                    "crank and rocker lengths)"),
}
#: keys that mean nothing without ``mass``
DEPENDENT = tuple(k for k in KEYS if k != "mass")
#: the values of keys left out (their deck default is None, so a case deck written out by a sweep
#: carries only the keys a deck gave, and a deck without masses none of these)
DEFAULTS: dict[str, Any] = {"gravity": 9.81, "load_torque": 0.0, "load_force_x": 0.0, "load_force_y": 0.0,
                            "speed_fluctuation": 0.02, "balance": "none"}


def value(p: Mapping[str, Any], key: str) -> Any:
    """The value of force key ``key``: the deck's, or its default (DEFAULTS)."""
    v = p.get(key)
    return DEFAULTS.get(key) if v is None else v


def active(p: Mapping[str, Any]) -> bool:
    """Tell whether the deck asks for the force analysis (``mass`` given).

    Parameters
    ----------
    p : mapping
        ``&fourbar`` keys (validated Params or a plain mapping).

    Returns
    -------
    bool
        True when ``mass`` is given.
    """
    return p.get("mass") is not None


def _lengths(p: Mapping[str, Any]) -> tuple[float, float, float]:
    return float(p["crank"]), float(p["coupler"]), float(p["rocker"])


def check(p: Params) -> None:
    """Check the force keys against each other and the linkage (the four-bar SPEC's check calls it).

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys (lengths in m with ``mass``).

    Raises
    ------
    DeckError
        A force key without ``mass``, a load force without ``coupler_point``, ``method =
        'listing'`` with masses, or a detectable unit mismatch (a link over 100 m, ...).
    """
    if not active(p):
        for key in sorted((k for k in DEPENDENT if k in p.given), key=p.line_of):
            if key in p.given:
                raise p.error(key, "belongs to the force analysis, which runs only when 'mass' is given "
                                   "(mass = crank, coupler, rocker in kg)")
        return
    if p.method != "exact":
        raise p.error("mass", "the force analysis uses the closed-loop solution: set method = 'exact'")
    for key in ("fixed_link", "crank", "coupler", "rocker"):
        if p[key] > MAX_LENGTH_M:
            raise p.error(key, f"{p[key]:g} m: with masses given, lengths are in metres; this looks like "
                               "millimetres (a length unit mismatch)")
    lengths = _lengths(p)
    if p.com_distance is not None:
        for i, (d, L) in enumerate(zip(p.com_distance, lengths)):
            if d > MAX_COM_RATIO * L:
                raise p.error("com_distance", f"{d:g} m for the {LINKS[i]} is {d / L:.0f} times its length "
                                              f"{L:g} m: com_distance and the link lengths look like different "
                                              "units (metres are expected)")
    if p.inertia is not None:
        for i, (m, j, L) in enumerate(zip(p.mass, p.inertia, lengths)):
            if m > 0 and math.sqrt(j / m) > MAX_GYRATION_RATIO * L:
                raise p.error("inertia", f"the {LINKS[i]}'s radius of gyration sqrt(I/m) = {math.sqrt(j / m):.3g} m "
                                         f"is over {MAX_GYRATION_RATIO:g} times its length {L:g} m: inertia and the "
                                         "lengths look like different units (kg m^2 and m expected)")
    if p.coupler_point and max(abs(x) for x in p.coupler_point) > MAX_COM_RATIO * p.coupler:
        raise p.error("coupler_point", f"{max(abs(x) for x in p.coupler_point):g} m is over {MAX_COM_RATIO:g} times "
                                       f"the coupler length {p.coupler:g} m: coupler_point and the link lengths look "
                                       "like different units (metres are expected when masses are given)")
    if p.counterweight_radius is not None:
        if value(p, "balance") != "force":
            raise p.error("counterweight_radius", "is used only with balance = 'force'")
        for i, (rc, L) in enumerate(zip(p.counterweight_radius, (lengths[0], lengths[2]))):
            if rc > MAX_COM_RATIO * L:
                raise p.error("counterweight_radius", f"{rc:g} m is {rc / L:.0f} times the "
                                                      f"{('crank', 'rocker')[i]} length: a length unit mismatch?")
    fx, fy = value(p, "load_force_x"), value(p, "load_force_y")
    if (fx != 0.0 or fy != 0.0) and not p.coupler_point:
        key = "load_force_x" if fx != 0.0 else "load_force_y"
        raise p.error(key, "a load force acts at the coupler point: give coupler_point = u, v (m) to place it")


def props(p: Mapping[str, Any]) -> np.ndarray:
    """Pack the kernel's 18 link and load properties from the deck, defaults filled in.

    Parameters
    ----------
    p : mapping
        ``&fourbar`` keys with ``mass``.

    Returns
    -------
    numpy.ndarray
        (18,): masses [kg], inertias about the centres of mass [kg m^2], com distances [m]
        and angles [rad] of crank, coupler, rocker; gravity [m/s^2]; load torque [N m]; load
        force x, y [N]; the coupler point's u, v [m].
    """
    lengths = np.array(_lengths(p))
    m = np.asarray(p["mass"], dtype=float)
    d = np.asarray(p["com_distance"], dtype=float) if p.get("com_distance") is not None else lengths / 2
    inertia = (np.asarray(p["inertia"], dtype=float) if p.get("inertia") is not None
               else m * lengths ** 2 / 12.0)
    ang = np.radians(p["com_angle_deg"]) if p.get("com_angle_deg") is not None else np.zeros(3)
    u, v = p.get("coupler_point") or (0.0, 0.0)
    return np.concatenate([m, inertia, d, ang, [value(p, "gravity"), value(p, "load_torque"),
                                                value(p, "load_force_x"), value(p, "load_force_y"), u, v]])


def cw_radii(p: Mapping[str, Any]) -> tuple[float, float]:
    """Counterweight radii on crank and rocker [m] (deck, or the link lengths)."""
    r = p.get("counterweight_radius")
    return (float(r[0]), float(r[1])) if r else (float(p["crank"]), float(p["rocker"]))


@dataclass
class Counterweights:
    """Berkof-Lowen counterweights: mass x radius [kg m], angle off the link line [deg, ccw +],
    radius [m] and mass [kg], crank then rocker; ``props`` of the balanced linkage."""

    mr: tuple[float, float]
    angle_deg: tuple[float, float]
    radius: tuple[float, float]
    mass: tuple[float, float]
    props: np.ndarray


def counterweights(p: Mapping[str, Any]) -> Counterweights:
    """The Berkof-Lowen counterweights of the deck's linkage (kernel berkof_lowen)."""
    radii = cw_radii(p)
    pb, cw = kernel.fourbar_berkof_lowen(p["crank"], p["coupler"], p["rocker"], props(p), radii)
    ang = np.degrees([cw[1], cw[3]])
    ang = np.where(np.abs(ang) < 1e-9, 0.0, ang)
    return Counterweights((float(cw[0]), float(cw[2])), (float(ang[0]), float(ang[1])), radii,
                          (float(cw[4]), float(cw[5])), pb)


#: tidy column names of the force kernel's twelve columns (issue 26 fixes them)
COLUMNS = ("input_torque_Nm", "F_O2_x_N", "F_O2_y_N", "F_A_x_N", "F_A_y_N", "F_B_x_N", "F_B_y_N",
           "F_O4_x_N", "F_O4_y_N", "shaking_force_x_N", "shaking_force_y_N", "shaking_moment_Nm")
UNITS = {c: ("N m" if c.endswith("_Nm") else "N") for c in COLUMNS}


@dataclass
class ForceAnalysis:
    """Forces at the table's crank angles.

    Attributes
    ----------
    forces : numpy.ndarray
        (n, 12) in ``COLUMNS`` order: input torque [N m]; F_O2, F_A, F_B, F_O4 (x, y) [N];
        shaking force (x, y) [N]; shaking moment [N m]; zero where not defined.
    ok : numpy.ndarray
        (n,) bool: where the forces are defined (assembled, no toggle).
    unbalanced : numpy.ndarray or None
        With ``balance = 'force'``: the forces of the linkage as given (the analysed one
        carries the counterweights).
    cw : Counterweights or None
        The Berkof-Lowen counterweights, with ``balance = 'force'``.
    """

    forces: np.ndarray
    ok: np.ndarray
    unbalanced: np.ndarray | None = None
    cw: Counterweights | None = None


def forces_at(p: Mapping[str, Any], out: np.ndarray, status: np.ndarray, pr: np.ndarray) -> np.ndarray:
    """Kernel forces for states ``out``/``status`` (from the deck's exact grid) and props ``pr``."""
    return kernel.fourbar_joint_forces(out, status, p["fixed_link"], p["crank"], p["coupler"], p["rocker"],
                                        p["omega"], p["alpha"], pr)


def analyse(p: Params, out: np.ndarray, status: np.ndarray) -> ForceAnalysis:
    """Analyse the joint forces, input torque and shaking at the deck's crank angles.

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys (lengths in m with ``mass``).
    out, status : numpy.ndarray
        The deck's exact grid (``driver.fourbar.exact_grid``).

    Returns
    -------
    ForceAnalysis
        Forces in N, torques and moments in N m, per crank angle.
    """
    given = forces_at(p, out, status, props(p))
    if value(p, "balance") != "force":
        return ForceAnalysis(given, status == ST_OK)
    cw = counterweights(p)
    return ForceAnalysis(forces_at(p, out, status, cw.props), status == ST_OK, given, cw)


def tidy_columns(fa: ForceAnalysis) -> dict[str, np.ndarray]:
    """Return the force columns of the tidy table.

    Parameters
    ----------
    fa : ForceAnalysis
        The forces of a run.

    Returns
    -------
    dict of str to numpy.ndarray
        Tidy column (units in the name: ``input_torque_Nm``, ``F_O2_x_N``) -> values, NaN
        where the forces are not defined (no assembly or toggle); with balancing, the
        linkage as given follows in columns prefixed ``unbalanced_``.
    """
    cols = {c: np.where(fa.ok, fa.forces[:, j], np.nan) for j, c in enumerate(COLUMNS)}
    if fa.unbalanced is not None:
        cols |= {"unbalanced_" + c: np.where(fa.ok, fa.unbalanced[:, j], np.nan) for j, c in enumerate(COLUMNS)}
    return cols


# ----------------------------------------------------------------------------- .out text

def table_lines(theta: np.ndarray, f: np.ndarray, ok: np.ndarray, status_words: list[str], title: str) -> list[str]:
    """Format the force table of the ``.out``: one row per crank angle.

    Parameters
    ----------
    theta : numpy.ndarray
        Crank angles, deg.
    f : numpy.ndarray
        (n, 12) forces in ``COLUMNS`` order (N, N m).
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
        out.append(f"    {name:<10}{pr[i]:>10.4f}{pr[3 + i]:>17.6g}{pr[6 + i]:>19.4f}{math.degrees(pr[9 + i]):>18.2f}")
    out.append(f"    gravity {pr[12]:g} m/s^2 along -y; load torque on the rocker {pr[13]:g} N m (ccw +); "
               f"load force at P ({pr[14]:g}, {pr[15]:g}) N")
    return out


# ----------------------------------------------------------------------------- summaries

#: deck keys a force batch may vary, in the kernel's parameter order where they map to one column
BATCH_KEYS = ("fixed_link", "crank", "coupler", "rocker", "omega", "alpha", "start_deg", "stop_deg", "branch",
              "mass", "inertia", "com_distance", "com_angle_deg", "gravity", "load_torque", "load_force_x",
              "load_force_y", "coupler_point", "speed_fluctuation", "balance", "counterweight_radius")


def _row(p: Mapping[str, Any]) -> np.ndarray:
    """One row of the batch kernel's (31) parameters from a deck-like mapping."""
    pr = props(p)
    bal = 1.0 if value(p, "balance") == "force" else 0.0
    return np.concatenate([[p["fixed_link"], p["crank"], p["coupler"], p["rocker"], p["omega"], p.get("alpha", 0.0),
                            p.get("start_deg", 0.0), p.get("stop_deg", 360.0),
                            1.0 if p.get("branch", "open") == "open" else -1.0],
                           pr, [value(p, "speed_fluctuation"), bal, *cw_radii(p)]])


#: summary columns and what they are
SUMMARY_DOC = {
    "torque_peak_Nm": "peak |input torque| over the range [N m]",
    "torque_peak_at_deg": "crank angle of the peak |input torque| [deg]",
    "torque_mean_Nm": "mean input torque over the range [N m]",
    "torque_rms_Nm": "RMS input torque over the range [N m]",
    "F_O2_peak_N": "peak |F_O2| [N]", "F_A_peak_N": "peak |F_A| [N]", "F_B_peak_N": "peak |F_B| [N]",
    "F_O4_peak_N": "peak |F_O4| [N]", "shaking_force_peak_N": "peak |shaking force| [N]",
    "shaking_moment_peak_Nm": "peak |shaking moment| [N m]",
    "energy_fluctuation_J": "energy fluctuation dE of the range [J]",
    "flywheel_inertia_kgm2": "flywheel inertia dE / (C_s omega^2) [kg m^2]",
}


#: axis labels of the summary columns (driver._output.column_label): name -> (words, units)
LABELS = {name: (doc.rsplit(" [", 1)[0], doc.rsplit(" [", 1)[1].rstrip("]")) for name, doc in SUMMARY_DOC.items()}


def frame_from_kernel(res: np.ndarray, prefix: str = "") -> pd.DataFrame:
    """Kernel rows -> summary columns (NaN where a figure does not exist)."""
    c = dict(zip(kernel.FOURBAR_FORCE_SUMMARY_COLUMNS, res.T))
    anyok = c["defined_fraction"] > 0
    full = c["defined_fraction"] >= 1.0
    out: dict[str, np.ndarray] = {}
    for name in SUMMARY_DOC:
        v = c[name]
        mask = full if name in ("torque_mean_Nm", "torque_rms_Nm", "energy_fluctuation_J",
                                "flywheel_inertia_kgm2") else anyok
        if name == "flywheel_inertia_kgm2":
            mask = mask & (v > 0)
        out[prefix + name] = np.where(mask, v, np.nan)
    return pd.DataFrame(out)


def summary(p: Params) -> dict[str, Any]:
    """Summarise the forces of one deck: one row of the batch kernel.

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys (lengths in m with ``mass``).

    Returns
    -------
    dict of str to float or None
        ``SUMMARY_DOC``'s figures, units in their names (``torque_peak_Nm``,
        ``energy_fluctuation_J``, ``flywheel_inertia_kgm2``), None where one does not exist;
        with ``balance = 'force'`` of the balanced linkage, and the linkage as given's
        prefixed ``unbalanced_``.
    """
    d = summarise_force_batch(p).iloc[0].to_dict()
    return {str(k): (None if isinstance(v, float) and math.isnan(v) else float(v)) for k, v in d.items()}


def summarise_force_batch(base: Mapping[str, Any], columns: Mapping[str, Any] | None = None) -> pd.DataFrame:
    """Summarise the forces of many designs in one Fortran call: one row per design.

    Parameters
    ----------
    base : mapping
        A validated ``&fourbar`` Params with ``mass`` given (lengths in m).
    columns : mapping of str to array, optional
        {key: n values} for scalar keys in ``BATCH_KEYS`` (``'fourbar.crank'`` accepted), or
        ``mass``/``inertia``/``com_distance``/``com_angle_deg`` as (n, 3) arrays, in the
        keys' deck units (kg, kg m^2, m, deg); scalars broadcast.

    Returns
    -------
    pandas.DataFrame
        One row per design, the columns of ``SUMMARY_DOC`` (units in their names); with
        ``balance = 'force'`` of the balanced linkage, and the same columns prefixed
        ``unbalanced_`` for the linkage as given.
    """
    columns = {k.partition(".")[2] if k.startswith("fourbar.") else k: v for k, v in (columns or {}).items()}
    bad = [k for k in columns if k not in BATCH_KEYS]
    if bad:
        raise ValueError(f"{bad[0]}: not a key the force summary depends on ({', '.join(BATCH_KEYS)})")
    sizes = {len(v) for v in columns.values() if np.ndim(v) > 0}
    if len(sizes) > 1:
        raise ValueError(f"batch columns have different lengths {sorted(sizes)}")
    n = sizes.pop() if sizes else 1
    rows = np.empty((n, 31), order="F")
    for i in range(n):
        d = dict(base)
        for k, v in columns.items():
            d[k] = v[i] if np.ndim(v) > 0 else v
        for key in ("fixed_link", "crank", "coupler", "rocker"):
            if not (float(d[key]) > 0):
                raise ValueError(f"{key}: design {i} has {d[key]!r} (lengths must be positive)")
        for key in ("mass", "inertia"):
            if d.get(key) is not None and np.any(np.asarray(d[key], dtype=float) < 0):
                raise ValueError(f"{key}: design {i} has a negative value")
        rows[i] = _row(d)
    if not np.all(np.isfinite(rows)):
        raise ValueError("batch values must be finite")
    frame = frame_from_kernel(kernel.fourbar_force_summaries(rows))
    if rows[:, 28].any():   # balanced designs: the figures without counterweights follow
        rows[:, 28] = 0.0
        frame = pd.concat([frame, frame_from_kernel(kernel.fourbar_force_summaries(rows), "unbalanced_")], axis=1)
    return frame


def summary_lines(p: Params, s: dict[str, Any], fa: ForceAnalysis) -> list[str]:
    """Format the words and numbers after the force table.

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys (lengths in m with ``mass``).
    s : dict
        The force summary (:func:`summary`).
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
            f"(C_s = {value(p, 'speed_fluctuation'):g}, omega = {p.omega:g} rad/s)"]
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
        out.append(f"    balanced links ....... crank {pb[0]:.4f} kg, I = {pb[3]:.6g} kg m2, com {pb[6]:.4f} m at "
                   f"{math.degrees(pb[9]):.2f} deg; rocker {pb[2]:.4f} kg, I = {pb[5]:.6g} kg m2, com {pb[8]:.4f} m at "
                   f"{math.degrees(pb[11]):.2f} deg")
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
            mg = np.sum(pb[:3]) * pb[12]
            inert = fa.forces[fa.ok, 9:11] - np.array([0.0, -mg]) - np.array([pb[14], pb[15]])
            out.append(f"    balanced shaking force minus weight and load force: max {np.max(np.hypot(*inert.T)):.1e} N "
                       "over the table (zero but for round-off: the centre of mass does not move)")
    return out


# ----------------------------------------------------------------------------- figures

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
        theta, fa = data()
        fig, ax = plotting.new_figure(1, 1, figsize=(7.0, 3.4))
        with plotting.style():
            plot_torque(theta, fa, p, ax=ax[0])
            fig.suptitle(f"{title}: input torque")
        return fig

    def pins() -> Any:
        from driver import plotting
        theta, fa = data()
        with plotting.style():
            fig, axes = plotting.new_figure(2, 2, figsize=(7.0, 7.0), subplot_kw={"projection": "polar"})
            plot_pin_polars(fa, axes=axes)
            fig.suptitle(f"{title}: pin forces (force on the pin, polar)")
        return fig

    def shaking() -> Any:
        from driver import plotting
        theta, fa = data()
        with plotting.style():
            fig, axes = plotting.new_figure(1, 2, figsize=(9.0, 4.0))
            plot_shaking(theta, fa, ax=axes[0], polar_ax=axes[1])
            fig.suptitle(f"{title}: shaking force on the frame")
        return fig

    return [Figure("torque", torque), Figure("pin_forces", pins), Figure("shaking", shaking)]


def plot_torque(theta: np.ndarray, fa: ForceAnalysis, p: Mapping[str, Any], ax: Any) -> Any:
    """Plot the input torque against crank angle, its mean, and the energy fluctuation dE.

    dE is shaded between the torque curve and the mean; with balancing the torque of the
    linkage without counterweights is dashed.

    Parameters
    ----------
    theta : numpy.ndarray
        Crank angles, deg.
    fa : ForceAnalysis
        The forces (:func:`analyse`).
    p : mapping
        The ``&fourbar`` keys.
    ax : matplotlib.axes.Axes
        The axes to draw into (crank angle in deg, torque in N m, dE in J in the legend).

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``.
    """
    t = np.where(fa.ok, fa.forces[:, 0], np.nan)
    ax.plot(theta, t, color="C0", label="input torque")
    if fa.ok.all() and len(theta) > 1:
        mean = np.trapezoid(t, theta) / (theta[-1] - theta[0])
        e = np.concatenate([[0.0], np.cumsum(0.5 * (t[1:] + t[:-1] - 2 * mean) * np.diff(np.radians(theta)))])
        ax.axhline(mean, color="C1", lw=1, label=f"mean {mean:.3f} N m")
        ax.fill_between(theta, t, mean, color="C0", alpha=0.15,
                        label=f"dE = {e.max() - e.min():.4g} J (max - min of the area)")
    if fa.unbalanced is not None:
        ax.plot(theta, np.where(fa.ok, fa.unbalanced[:, 0], np.nan), "--", color="C3", label="without counterweights")
    ax.set_xlabel("crank angle [deg]")
    ax.set_ylabel("input torque [N m]")
    ax.legend(fontsize=7, loc="best")
    return ax


def plot_pin_polars(fa: ForceAnalysis, axes: Any) -> Any:
    """Plot the force at each pin over the cycle on polar axes.

    Angle = direction of the force, radius = its magnitude in N; with balancing, the
    unbalanced linkage's dashed.

    Parameters
    ----------
    fa : ForceAnalysis
        The forces (:func:`analyse`).
    axes : sequence of matplotlib.axes.Axes
        Four polar axes: O2, A, B, O4.

    Returns
    -------
    sequence of matplotlib.axes.Axes
        ``axes``.
    """
    names = ("O2 (ground on crank)", "A (crank on coupler)", "B (coupler on rocker)", "O4 (ground on rocker)")
    for j, ax in enumerate(np.ravel(axes)[:4]):
        fx = np.where(fa.ok, fa.forces[:, 1 + 2 * j], np.nan)
        fy = np.where(fa.ok, fa.forces[:, 2 + 2 * j], np.nan)
        ax.plot(np.arctan2(fy, fx), np.hypot(fx, fy), color="C0", lw=1,
                label="balanced" if fa.unbalanced is not None else "as given")
        if fa.unbalanced is not None:
            bx = np.where(fa.ok, fa.unbalanced[:, 1 + 2 * j], np.nan)
            by = np.where(fa.ok, fa.unbalanced[:, 2 + 2 * j], np.nan)
            ax.plot(np.arctan2(by, bx), np.hypot(bx, by), color="C3", lw=1, ls="--", label="unbalanced")
        ax.set_title(f"F at {names[j]} [N]", fontsize=8)
    np.ravel(axes)[0].legend(fontsize=6, loc="lower left")
    return axes


def plot_shaking(theta: np.ndarray, fa: ForceAnalysis, ax: Any, polar_ax: Any | None = None) -> Any:
    """Plot the shaking force magnitude against crank angle, and its locus, before and after balancing.

    Parameters
    ----------
    theta : numpy.ndarray
        Crank angles, deg.
    fa : ForceAnalysis
        The forces (:func:`analyse`).
    ax : matplotlib.axes.Axes
        Axes for |shaking force| (N) against crank angle (deg).
    polar_ax : matplotlib.axes.Axes, optional
        Axes for the locus F_y against F_x (N, equal scales).

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``.
    """
    before = fa.unbalanced if fa.unbalanced is not None else fa.forces
    s = np.where(fa.ok[:, None], before[:, 9:11], np.nan)
    ax.plot(theta, np.hypot(*s.T), color="C0", label="unbalanced")
    if polar_ax is not None:
        polar_ax.plot(s[:, 0], s[:, 1], color="C0", label="unbalanced")
    if fa.unbalanced is not None:
        b = np.where(fa.ok[:, None], fa.forces[:, 9:11], np.nan)
        ax.plot(theta, np.hypot(*b.T), "--", color="C3", label="balanced (Berkof-Lowen)")
        if polar_ax is not None:
            polar_ax.plot(b[:, 0], b[:, 1], "o", ms=3, color="C3", label="balanced (Berkof-Lowen)")
    ax.set_xlabel("crank angle [deg]")
    ax.set_ylabel("|shaking force| [N]")
    ax.legend(fontsize=7)
    if polar_ax is not None:
        polar_ax.set_xlabel("shaking force x [N]")
        polar_ax.set_ylabel("shaking force y [N]")
        polar_ax.set_aspect("equal", adjustable="datalim")
    return ax
