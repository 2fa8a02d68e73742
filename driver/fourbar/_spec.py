"""The ``&fourbar`` keys (with their checks), axis labels, sweep headline columns, and the budget
estimate of a run.

Lengths in any consistent unit; angles in degrees in decks and tables; crank speed in rad/s,
accelerations in rad/s^2.  The force analysis's keys (issue 26: ``mass`` and the keys that mean
nothing without it) run it when ``mass`` is given; then lengths are in metres and everything is
SI (docs/fourbar.md, section "Force analysis")."""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from driver._deck import GroupSpec, Key, Params, non_negative, positive
from driver._limits import Estimate
from driver._study import contract_doc

__all__ = ['SPEC', 'LABELS', 'RENAMED', 'SWEEP_BEST', 'SWEEP_PLOT', 'SUMMARY_SETTINGS', 'BAND', 'MAX_ANGLE', 'band_of',
           'estimate', 'FORCE_KEYS', 'FORCE_DEFAULTS', 'FORCE_SUMMARY_DOC', 'STRESS_SUMMARY_DOC', 'LINKS',
           'force_value', 'forces_active', 'force_check', 'moving_lengths', 'sections_of', 'yields_of']


MAX_ANGLE = 1.0e6   # |crank angle| [deg] a deck may give (ulp of 1e6 is 1.2e-10 deg)


BAND = (40.0, 120.0)  # transmission-angle band recommended by the paper [deg]: transmission_band_deg's default


def _band_check(v: Any) -> str | None:
    """Key check of ``transmission_band_deg``: two angles 0 <= min < max <= 180 [deg]."""
    if len(v) != 2:
        return f"give two angles, the band's minimum and maximum in deg (got {len(v)} values)"
    lo, hi = v
    if not (0.0 <= lo < hi <= 180.0):
        return f"the band needs 0 <= min < max <= 180 deg (got {lo:g}, {hi:g})"
    return None


def band_of(p: Mapping[str, Any]) -> tuple[float, float]:
    """The deck's transmission-angle band (min, max) [deg] (the paper's 40-120 deg by default)."""
    v = p.get("transmission_band_deg") if hasattr(p, "get") else None
    return (float(v[0]), float(v[1])) if v is not None and len(v) == 2 else BAND


# ----------------------------------------------------------------------------- the force analysis's keys

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


def _positive(v: Any) -> str | None:
    return None if all(math.isfinite(x) and x > 0 for x in v) else "must be positive and finite"


#: a yield strength below this [Pa] is taken for a unit mistake (MPa given for Pa)
MIN_YIELD_PA = 1.0e5


def _yield_check(v: Any) -> str | None:
    if len(v) not in (1, 3):
        return f"give one value for every link, or three: crank, coupler, rocker (got {len(v)})"
    bad = _positive(v)
    if bad:
        return bad
    if min(v) < MIN_YIELD_PA:
        return (f"{min(v):g} Pa is below {MIN_YIELD_PA:g} Pa: yield strengths are in Pa (250 MPa is 2.5e8); "
                "this looks like MPa")
    return None


FORCE_KEYS: dict[str, Key] = {
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
    "section_area": Key("floats", default=None, units="m^2", check=lambda v: _three(v) or _positive(v),
                        doc="cross-section area of crank, coupler, rocker; with section_modulus each link's peak "
                            "normal stress |N|/A + |M|/Z over the range (the force analysis's loads)"),
    "section_modulus": Key("floats", default=None, units="m^3", check=lambda v: _three(v) or _positive(v),
                           doc="elastic section modulus I/c of crank, coupler, rocker for in-plane bending"),
    "yield_strength": Key("floats", default=None, units="Pa", check=_yield_check,
                          doc="yield strength of the links' material (one value, or crank, coupler, rocker); "
                              "with the sections a link whose peak stress reaches it is reported as yielding"),
    "counterweight_radius": Key("floats", default=None, units="m",
                                check=lambda v: (None if len(v) == 2 else f"give two values: crank, rocker (got {len(v)})")
                                or (None if all(x > 0 for x in v) else "must be positive"),
                                doc="radius of the point-mass counterweights on crank and rocker (default: the "
                                    "crank and rocker lengths)"),
}
#: force keys that mean nothing without ``mass``
FORCE_DEPENDENT = tuple(k for k in FORCE_KEYS if k != "mass")
#: the values of keys left out (their deck default is None, so a case deck written out by a sweep
#: carries only the keys a deck gave, and a deck without masses none of these)
FORCE_DEFAULTS: dict[str, Any] = {"gravity": 9.81, "load_torque": 0.0, "load_force_x": 0.0, "load_force_y": 0.0,
                            "speed_fluctuation": 0.02, "balance": "none"}


def force_value(p: Mapping[str, Any], key: str) -> Any:
    """The value of force key ``key``: the deck's, or its default (FORCE_DEFAULTS)."""
    v = p.get(key)
    return FORCE_DEFAULTS.get(key) if v is None else v


def forces_active(p: Mapping[str, Any]) -> bool:
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


def moving_lengths(p: Mapping[str, Any]) -> tuple[float, float, float]:
    """Crank, coupler and rocker length of the deck (m with ``mass``)."""
    return float(p["crank"]), float(p["coupler"]), float(p["rocker"])


def force_check(p: Params) -> None:
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
    if not forces_active(p):
        for key in sorted((k for k in FORCE_DEPENDENT if k in p.given), key=p.line_of):
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
    lengths = moving_lengths(p)
    if p.com_distance is not None:
        for i, (d, L) in enumerate(zip(p.com_distance, lengths)):
            if d > MAX_COM_RATIO * L:
                raise p.error("com_distance", f"{d:g} m for the {LINKS[i]} is {d / L:.3g} times its length "
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
        if force_value(p, "balance") != "force":
            raise p.error("counterweight_radius", "is used only with balance = 'force'")
        for i, (rc, L) in enumerate(zip(p.counterweight_radius, (lengths[0], lengths[2]))):
            if rc > MAX_COM_RATIO * L:
                raise p.error("counterweight_radius", f"{rc:g} m is {rc / L:.3g} times the "
                                                      f"{('crank', 'rocker')[i]} length: a length unit mismatch?")
    if (p.section_area is None) != (p.section_modulus is None):
        key = "section_area" if p.section_area is not None else "section_modulus"
        raise p.error(key, "the link stresses need both section_area (m^2) and section_modulus (m^3)")
    if p.yield_strength is not None and p.section_area is None:
        raise p.error("yield_strength", "is compared with the link stresses, which need section_area and "
                                        "section_modulus")
    fx, fy = force_value(p, "load_force_x"), force_value(p, "load_force_y")
    if (fx != 0.0 or fy != 0.0) and not p.coupler_point:
        key = "load_force_x" if fx != 0.0 else "load_force_y"
        raise p.error(key, "a load force acts at the coupler point: give coupler_point = u, v (m) to place it")


#: the force summary's columns and what they are (units in brackets)
FORCE_SUMMARY_DOC = {
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

#: the link-stress summary's columns (decks with section_area and section_modulus) and what they are
STRESS_SUMMARY_DOC = {
    **{f"{link}_stress_peak_MPa": f"peak normal stress |N|/A + |M|/Z in the {link} [MPa]" for link in LINKS},
    **{f"{link}_stress_peak_at_deg": f"crank angle of the {link}'s peak stress [deg]" for link in LINKS},
    "yield_ratio_max": "largest peak stress over the link's yield strength [1]",
    "yields": "a link's peak stress reaches its yield strength []",
}


#: axis labels of the force summary columns: name -> (words, units)
FORCE_LABELS = {name: (doc.rsplit(" [", 1)[0], doc.rsplit(" [", 1)[1].rstrip("]"))
                for name, doc in (FORCE_SUMMARY_DOC | STRESS_SUMMARY_DOC).items()}
#: ... and of the same columns of the linkage without its counterweights (balance = 'force')
FORCE_LABELS |= {f"unbalanced_{name}": (f"{words}, without counterweights", unit)
                 for name, (words, unit) in list(FORCE_LABELS.items())}


def sections_of(p: Mapping[str, Any]) -> list[float] | None:
    """The link sections of the deck for the kernel's link_stresses: the areas of crank, coupler,
    rocker [m^2], then their section moduli [m^3]; None without section_area."""
    if p.get("section_area") is None or p.get("section_modulus") is None:
        return None
    return [float(x) for x in (*p["section_area"], *p["section_modulus"])]


def yields_of(p: Mapping[str, Any]) -> list[float] | None:
    """The yield strength of crank, coupler and rocker [Pa] (one deck value for all), or None."""
    v = p.get("yield_strength")
    if v is None:
        return None
    return [float(v[0])] * 3 if len(v) == 1 else [float(x) for x in v]


# ----------------------------------------------------------------------------- the group

def _check(p: Params) -> None:
    """Cross-key checks: step, range, and what the listing method can do."""
    if p.step_deg == 0:
        raise p.error("step_deg", "must not be 0 (the crank angle would never advance)")
    for key in ("start_deg", "stop_deg"):
        if abs(p[key]) > MAX_ANGLE:
            raise p.error(key, f"|{p[key]:g}| deg is beyond {MAX_ANGLE:g} deg: a crank angle that large has lost "
                               "its fraction of a degree in double precision (the motion repeats every 360 deg)")
    span = p.stop_deg - p.start_deg
    if span * p.step_deg < 0:
        raise p.error("step_deg", f"steps away from stop_deg ({p.start_deg:g} -> {p.stop_deg:g} "
                                  f"with step {p.step_deg:g})")
    if abs(span / p.step_deg) > 5_000_000:
        raise p.error("step_deg", "more than 5e6 crank positions; use a coarser step")
    if p.method == "listing":
        for key in ("start_deg", "stop_deg", "step_deg"):
            if not float(p[key]).is_integer():
                raise p.error(key, "method='listing' steps in whole degrees like the published program "
                                   f"(got {p[key]:g}); use method='exact' for fractional angles")
        if "branch" in p.given and p.branch != "open":
            raise p.error("branch", "the listing computes one assembly only; branch applies to method='exact'")
    force_check(p)


#: axis labels of summary columns and deck keys (driver._output.column_label): name -> (words, units)
LABELS = {"crank": ("crank length", "length units"), "coupler": ("coupler length", "length units"),
          "rocker": ("rocker length", "length units"),
          "fixed_link": ("ground link length", "length units"), "omega": ("crank speed", ""),
          "mu_min_deg": ("minimum transmission angle", "deg"), "mu_max_deg": ("maximum transmission angle", "deg"),
          "rocker_swing_deg": ("rocker swing", "deg"),
          "rocker_omega_peak_rad_s": ("peak rocker speed (signed: the largest in size)", "rad/s"),
          "coupler_omega_peak_rad_s": ("peak coupler speed (signed: the largest in size)", "rad/s"),
          "assembled_fraction": ("fraction of the turn assembled", "-"),
          "time_ratio": ("time ratio (slow / quick stroke)", "-"), **FORCE_LABELS}


#: columns renamed (old -> new) when every name came to say its link in words (issue 35; the
#: paper's listing numbered the coupler 2 and the rocker 3, textbooks 3 and 4): an old name in a
#: deck, a sweep filter or an &optimize expression is refused with the new one named
RENAMED = {"omega3_peak_rad_s": "rocker_omega_peak_rad_s", "omega2_peak_rad_s": "coupler_omega_peak_rad_s",
           "omega3_peak_at_deg": "rocker_omega_peak_at_deg", "omega2_peak_at_deg": "coupler_omega_peak_at_deg",
           "omega2_rad_s": "coupler_omega_rad_s", "omega3_rad_s": "rocker_omega_rad_s",
           "alpha2_rad_s2": "coupler_alpha_rad_s2", "alpha3_rad_s2": "rocker_alpha_rad_s2"}


#: which way a summary column is better (the design-space maps star the best kept design)
SWEEP_BEST = {"mu_min_deg": "max", "mu_max_deg": "min", "rocker_swing_deg": "max", "rocker_omega_peak_rad_s": "min",
              "coupler_omega_peak_rad_s": "min"}


#: keys of the base deck the summary columns depend on (transmission_band_deg: meets_transmission_band):
#: a sweep's and an optimisation's .out state them, their summary/evals Parquet tables record them
SUMMARY_SETTINGS = ("transmission_band_deg",)


#: what a sweep summary plots when its deck names no plot_y
SWEEP_PLOT = ("mu_min_deg", "mu_max_deg", "rocker_swing_deg", "rocker_omega_peak_rad_s", "coupler_omega_peak_rad_s",
              "assembled_fraction")


SPEC = GroupSpec(
    name="fourbar",
    doc="planar four-bar linkage driven by its crank at constant speed",
    keys={
        "fixed_link": Key("float", required=True, check=positive, units="length", doc="ground link O2-O4 (the paper's O_A-O_B)"),
        "crank": Key("float", required=True, check=positive, units="length", doc="input link O2-A"),
        "coupler": Key("float", required=True, check=positive, units="length", doc="coupler A-B"),
        "rocker": Key("float", required=True, check=positive, units="length", doc="output link O4-B"),
        "omega": Key("float", default=1.0, units="rad/s", doc="crank angular velocity (ccw positive)"),
        "alpha": Key("float", default=0.0, units="rad/s^2", doc="crank angular acceleration (exact method)"),
        "step_deg": Key("float", required=True, units="deg", doc="crank-angle step"),
        "start_deg": Key("float", default=0.0, units="deg", doc="first crank angle"),
        "stop_deg": Key("float", default=360.0, units="deg", doc="last crank angle (inclusive)"),
        "method": Key("str", default="exact", choices=("exact", "listing"),
                      doc="'listing' = published program cell for cell; 'exact' = closed loop"),
        "branch": Key("str", default="open", choices=("open", "crossed"),
                      doc="'open': B left of the line A->O4; 'crossed': mirror assembly"),
        "transmission_band_deg": Key("floats", default=list(BAND), units="deg", check=_band_check,
                                     doc="the transmission-angle band a design should keep to (min, max): the "
                                         "summary's meets_transmission_band, the .out and the figures use it; "
                                         "default the paper's 40, 120"),
        "coupler_point": Key("floats", default=None, units="length",
                             check=lambda v: None if len(v) == 2 else f"give two numbers u, v (got {len(v)})",
                             doc="a point P on the coupler: u along A->B, v to its left; adds its path, "
                                 "velocity and acceleration (exact method)"),
        "title": Key("str", default="", doc="free text echoed in the output"),
        **FORCE_KEYS,   # the force analysis, run when 'mass' is given
    },
    check=_check,
)


@contract_doc
def estimate(params: Params) -> Estimate:
    """Estimate the memory and work of a run from the keys alone, before it allocates.

    Per crank angle a table row
    (text, two tidy frames, kernel columns; about 2 KB and 50 us of Python formatting), and the
    summary kernel's 1 deg scan of at most one turn (the motion is periodic; about 30 us).

    %(estimate)s
    """
    p = params
    try:
        n = float(math.floor((p.stop_deg - p.start_deg) / p.step_deg + 1e-9) + 1)
    except (OverflowError, ZeroDivisionError, ValueError):
        n = math.inf
    n = max(n, 1.0)
    span = min(abs(p.stop_deg - p.start_deg), 360.0) / 1.0 + 1.0
    range_key = "start_deg" if "start_deg" in p.given else ("stop_deg" if "stop_deg" in p.given else "step_deg")
    k = 2.5 if forces_active(p) else 1.0   # the force table and columns: 13 more cells and 24 columns per row
    rows = Estimate(k * 2000.0 * n + 5e6, k * 5e-5 * n + 0.05, "step_deg", "step_deg", f"{n:.4g} crank angles")
    grid = Estimate(500.0 * span, 1e-6 * span, range_key, range_key,
                    f"a {span:.4g}-point scan of one turn for the summary")
    return rows + grid
