"""Four-bar force analysis through the kernel (issue 26), the part of a run with ``mass`` given:
the kernel's link and load properties packed from the deck (defaults filled in), the
Berkof-Lowen counterweights (``balance = 'force'``), and the joint forces, input torque, shaking
force and moment at the deck's crank angles with their tidy columns.  Units: SI (lengths in
metres when masses are given).  Sign conventions and the equations: docs/fourbar.md, section
"Force analysis".  No physics here: the kernel (``fortran/fourbar_forces.f90``) solves the nine
unknowns and balances the linkage.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from driver._deck import Params
from driver.fourbar import _kernel as kernel
from driver.fourbar._kernel import Counterweight
from driver.fourbar._spec import LINKS, force_value, moving_lengths, sections_of

__all__ = ["props", "cw_radii", "Counterweights", "counterweights", "COLUMNS", "STRESS_COLUMNS", "ForceAnalysis",
           "forces_at", "stresses_at", "scan_angles", "analyse", "tidy_columns"]

ST_OK = kernel.FOURBAR_STATUS["ok"]


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
    lengths = np.array(moving_lengths(p))
    m = np.asarray(p["mass"], dtype=float)
    d = np.asarray(p["com_distance"], dtype=float) if p.get("com_distance") is not None else lengths / 2
    inertia = (np.asarray(p["inertia"], dtype=float) if p.get("inertia") is not None
               else m * lengths ** 2 / 12.0)
    ang = np.radians(p["com_angle_deg"]) if p.get("com_angle_deg") is not None else np.zeros(3)
    u, v = p.get("coupler_point") or (0.0, 0.0)
    return np.concatenate([m, inertia, d, ang, [force_value(p, "gravity"), force_value(p, "load_torque"),
                                                force_value(p, "load_force_x"), force_value(p, "load_force_y"), u, v]])


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
    c = Counterweight
    ang = np.degrees([cw[c.CRANK_ANGLE], cw[c.ROCKER_ANGLE]])
    ang = np.where(np.abs(ang) < 1e-9, 0.0, ang)
    return Counterweights((float(cw[c.CRANK_MR]), float(cw[c.ROCKER_MR])), (float(ang[0]), float(ang[1])), radii,
                          (float(cw[c.CRANK_MASS]), float(cw[c.ROCKER_MASS])), pb)


#: tidy column names of the force kernel's twelve columns (issue 26 fixes them)
COLUMNS = ("input_torque_Nm", "F_O2_x_N", "F_O2_y_N", "F_A_x_N", "F_A_y_N", "F_B_x_N", "F_B_y_N",
           "F_O4_x_N", "F_O4_y_N", "shaking_force_x_N", "shaking_force_y_N", "shaking_moment_Nm")


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
    stresses : numpy.ndarray or None
        With ``section_area`` and ``section_modulus``: (n, 3) peak normal stress in crank,
        coupler and rocker [Pa] (of the analysed linkage), zero where not defined.
    """

    forces: np.ndarray
    ok: np.ndarray
    unbalanced: np.ndarray | None = None
    cw: Counterweights | None = None
    stresses: np.ndarray | None = None


#: tidy column names of the link stresses (decks with sections)
STRESS_COLUMNS = tuple(f"{link}_stress_MPa" for link in LINKS)


def forces_at(p: Mapping[str, Any], out: np.ndarray, status: np.ndarray, pr: np.ndarray) -> np.ndarray:
    """Kernel forces for states ``out``/``status`` (from the deck's exact grid) and props ``pr``."""
    return kernel.fourbar_joint_forces(out, status, p["fixed_link"], p["crank"], p["coupler"], p["rocker"],
                                        p["omega"], p["alpha"], pr)


def stresses_at(p: Mapping[str, Any], out: np.ndarray, status: np.ndarray, pr: np.ndarray,
                forces: np.ndarray) -> np.ndarray | None:
    """Peak normal stress in each link [Pa] (kernel link_stresses) for states ``out``/``status``,
    props ``pr`` and their joint ``forces``; None when the deck gives no sections."""
    section = sections_of(p)
    if section is None:
        return None
    return kernel.fourbar_link_stresses(out, status, p["fixed_link"], p["crank"], p["coupler"], p["rocker"],
                                        p["alpha"], pr, forces, np.array(section))


def scan_angles(p: Mapping[str, Any]) -> np.ndarray:
    """The crank angles [deg] of the force summary's scan of the deck's range: at most 0.1 deg
    apart, at most 36001 (fortran/fourbar_forces.f90 force_summaries)."""
    lo, hi = float(p["start_deg"]), float(p["stop_deg"])
    span = abs(hi - lo)
    if span == 0.0:
        return np.array([lo])
    n = min(36001, max(2, math.ceil(span / 0.1 - 1e-9) + 1))
    return lo + (hi - lo) / (n - 1) * np.arange(n)


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
    pr = props(p)
    given = forces_at(p, out, status, pr)
    if force_value(p, "balance") != "force":
        return ForceAnalysis(given, status == ST_OK, stresses=stresses_at(p, out, status, pr, given))
    cw = counterweights(p)
    balanced = forces_at(p, out, status, cw.props)
    return ForceAnalysis(balanced, status == ST_OK, given, cw, stresses_at(p, out, status, cw.props, balanced))


def tidy_columns(fa: ForceAnalysis) -> dict[str, np.ndarray]:
    """Return the force columns of the tidy table.

    Parameters
    ----------
    fa : ForceAnalysis
        The forces of a run.

    Returns
    -------
    dict of str to numpy.ndarray
        Tidy column (units in the name: ``input_torque_Nm``, ``F_O2_x_N``; with sections the
        link stresses ``crank_stress_MPa`` ...) -> values, NaN where the forces are not defined
        (no assembly or toggle); with balancing, the linkage as given follows in columns
        prefixed ``unbalanced_``.
    """
    cols = {c: np.where(fa.ok, fa.forces[:, j], np.nan) for j, c in enumerate(COLUMNS)}
    if fa.stresses is not None:
        cols |= {c: np.where(fa.ok, fa.stresses[:, j] / 1e6, np.nan) for j, c in enumerate(STRESS_COLUMNS)}
    if fa.unbalanced is not None:
        cols |= {"unbalanced_" + c: np.where(fa.ok, fa.unbalanced[:, j], np.nan) for j, c in enumerate(COLUMNS)}
    return cols
