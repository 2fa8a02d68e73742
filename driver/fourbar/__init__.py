"""Four-bar linkage study [Soegihardjo 2003]: the ``&fourbar`` group.

``method = 'listing'`` runs the published Fortran 77 program (Lampiran 1), kept
cell-for-cell, and audits it against the closed loop; ``method = 'exact'``
(default) solves the loop on the requested branch in double precision and adds
accelerations, Grashof class, limit and toggle positions and a summary.

Lengths in any consistent unit; angles in degrees in decks and tables; crank
speed in rad/s, accelerations in rad/s^2.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Collection, Mapping

import numpy as np
import pandas as pd

from driver.fourbar import forces
from driver import kernels
from driver.limits import Estimate
from driver.deck import GroupSpec, Key, Params, positive
from driver.export import with_units
from driver.runner import keyword_run
from driver.study import Figure, Result
from driver.table import Column, fortran_f, render_table

__all__ = ["SPEC", "run", "summarise", "summarise_batch", "BATCH_KEYS", "grashof", "limit_angles", "exact_grid",
           "listing_grid", "exact_as_listed"]

ST = kernels.FOURBAR_STATUS
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

#: why the published listing's rows for crank angles in (180, 360) deg are wrong (see :func:`audit`)
LISTING_DEFECT = ("the listing's quadrant test sends sigy > 0, sigx > 0 to sigma = 2 pi - |atan| (meant |atan|), "
                  "so rows 200-340 repeat the mirror position 360 - i and their speeds are wrong")
#: why a correct value may differ from a correct published row in its last printed digit
LISTING_PRECISION = ("the listing works in single precision with pi/180 = 0.0174532 and truncates angles "
                     "to whole degrees")


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
    forces.check(p)


#: axis labels of summary columns and deck keys (driver.study.column_label): name -> (words, units)
LABELS = {"crank": ("crank length", "length units"), "coupler": ("coupler length", "length units"),
          "rocker": ("rocker length", "length units"),
          "fixed_link": ("ground link length", "length units"), "omega": ("crank speed", ""),
          "mu_min_deg": ("minimum transmission angle", "deg"), "mu_max_deg": ("maximum transmission angle", "deg"),
          "rocker_swing_deg": ("rocker swing", "deg"), "omega3_peak_rad_s": ("peak rocker speed (signed: the largest in size)", "rad/s"),
          "omega2_peak_rad_s": ("peak coupler speed (signed: the largest in size)", "rad/s"),
          "assembled_fraction": ("fraction of the turn assembled", "-"),
          "time_ratio": ("time ratio (slow / quick stroke)", "-"), **forces.LABELS}
#: which way a summary column is better (the design-space maps star the best kept design)
SWEEP_BEST = {"mu_min_deg": "max", "mu_max_deg": "min", "rocker_swing_deg": "max", "omega3_peak_rad_s": "min",
              "omega2_peak_rad_s": "min"}
#: keys of the base deck the summary columns depend on (transmission_band_deg: meets_transmission_band):
#: a sweep's and an optimisation's .out state them, their summary/evals Parquet tables record them
SUMMARY_SETTINGS = ("transmission_band_deg",)
#: what a sweep summary plots when its deck names no plot_y
SWEEP_PLOT = ("mu_min_deg", "mu_max_deg", "rocker_swing_deg", "omega3_peak_rad_s", "omega2_peak_rad_s",
              "assembled_fraction")


SPEC = GroupSpec(
    name="fourbar",
    doc="planar four-bar linkage driven by its crank at constant speed",
    keys={
        "fixed_link": Key("float", required=True, check=positive, units="length", doc="ground link O_A-O_B"),
        "crank": Key("float", required=True, check=positive, units="length", doc="input link O_A-A"),
        "coupler": Key("float", required=True, check=positive, units="length", doc="coupler A-B"),
        "rocker": Key("float", required=True, check=positive, units="length", doc="output link O_B-B"),
        "omega": Key("float", default=1.0, units="rad/s", doc="crank angular velocity (ccw positive)"),
        "alpha": Key("float", default=0.0, units="rad/s^2", doc="crank angular acceleration (exact method)"),
        "step_deg": Key("float", required=True, units="deg", doc="crank-angle step"),
        "start_deg": Key("float", default=0.0, units="deg", doc="first crank angle"),
        "stop_deg": Key("float", default=360.0, units="deg", doc="last crank angle (inclusive)"),
        "method": Key("str", default="exact", choices=("exact", "listing"),
                      doc="'listing' = published program cell for cell; 'exact' = closed loop"),
        "branch": Key("str", default="open", choices=("open", "crossed"),
                      doc="'open': B left of the line A->O_B; 'crossed': mirror assembly"),
        "transmission_band_deg": Key("floats", default=list(BAND), units="deg", check=_band_check,
                                     doc="the transmission-angle band a design should keep to (min, max): the "
                                         "summary's meets_transmission_band, the .out and the figures use it; "
                                         "default the paper's 40, 120"),
        "coupler_point": Key("floats", default=None, units="length",
                             check=lambda v: None if len(v) == 2 else f"give two numbers u, v (got {len(v)})",
                             doc="a point P on the coupler: u along A->B, v to its left; adds its path, "
                                 "velocity and acceleration (exact method)"),
        "title": Key("str", default="", doc="free text echoed in the output"),
        **forces.KEYS,   # the force analysis (driver/fourbar/forces.py), run when 'mass' is given
    },
    check=_check,
)


# ----------------------------------------------------------------------------- analysis

@dataclass
class Grashof:
    """Grashof classification of a four-bar (Norton's classes)."""

    name: str
    condition: str
    full_crank_rotation: bool


def grashof(p: float, q: float, r: float, s: float) -> Grashof:
    """Class from link lengths (p ground, q crank, r coupler, s rocker)."""
    links = {"ground": p, "crank": q, "coupler": r, "rocker": s}
    srt = sorted(links.values())
    short, long_ = srt[0], srt[-1]
    lhs, rhs = short + long_, srt[1] + srt[2]
    tol = 1e-12 * rhs
    cond = f"S + L = {short:g} + {long_:g} = {lhs:g} {'<' if lhs < rhs - tol else ('=' if abs(lhs - rhs) <= tol else '>')} P + Q = {rhs:g}"
    if lhs > rhs + tol:
        return Grashof("non-Grashof triple-rocker", cond, False)
    if abs(lhs - rhs) <= tol:
        return Grashof("change-point (special Grashof)", cond, True)
    shortest = min(links, key=lambda k: (links[k], ["ground", "crank", "rocker", "coupler"].index(k)))
    names = {"ground": ("double-crank (drag link)", True), "crank": ("crank-rocker", True),
             "rocker": ("rocker-crank", False), "coupler": ("Grashof double-rocker", False)}
    name, full = names[shortest]
    return Grashof(name, cond, full)


def limit_angles(p: float, q: float, r: float, s: float) -> list[float]:
    """Crank angles [deg, 0..360) where |A O_B| = r + s or |r - s| (toggle / assembly limits)."""
    out = []
    for d in (r + s, abs(r - s)):
        c = (p * p + q * q - d * d) / (2 * p * q)
        if -1.0 <= c <= 1.0:
            a = math.degrees(math.acos(c))
            out += [a, (360.0 - a) % 360.0]
    return sorted(set(round(a, 10) for a in out))


def assembly_intervals(p: float, q: float, r: float, s: float) -> list[tuple[float, float]] | None:
    """Crank-angle intervals [deg] over which the linkage assembles, from the closed form
    (r - s)^2 <= |A O_B|^2 = p^2 + q^2 - 2 p q cos(theta) <= (r + s)^2; each ends at two limit
    (toggle) positions.  None when the crank turns fully; [] when it cannot be assembled at all.
    An interval through 0 deg is one interval (lo < 0 < hi), not two; a Grashof double-rocker
    gives two, mirror images about the ground line (separate motions: one cannot reach the
    other without taking the linkage apart)."""
    c_lo = (p * p + q * q - (r + s) ** 2) / (2 * p * q)   # cos(theta) at |A O_B| = r + s
    c_hi = (p * p + q * q - (r - s) ** 2) / (2 * p * q)   # cos(theta) at |A O_B| = |r - s|
    eps = 1e-12
    if c_lo <= -1.0 + eps and c_hi >= 1.0 - eps:
        return None
    if c_lo > c_hi or c_lo > 1.0 or c_hi < -1.0:
        return []
    t1 = math.degrees(math.acos(max(-1.0, min(1.0, c_lo))))   # extended limit (r + s)
    t2 = math.degrees(math.acos(max(-1.0, min(1.0, c_hi))))   # folded limit |r - s|
    if c_lo > -1.0 + eps and c_hi >= 1.0 - eps:
        return [(-t1, t1)]                  # rocks through 0 deg between its extended limits
    if c_lo <= -1.0 + eps:
        return [(t2, 360.0 - t2)]           # rocks through 180 deg between its folded limits
    return [(t2, t1), (360.0 - t1, 360.0 - t2)]


@dataclass
class Motion:
    """One motion of a linkage whose crank cannot turn: the crank swings from ``lo`` to ``hi``
    on the deck's assembly branch, reverses at the limit position and swings back on the other
    branch (at a limit the two branches meet: B lies on the line A-O_B).

    ``theta`` [deg] the crank angles in the order they are passed, ``out``/``status`` the
    kernel's states there, ``branch`` +1 (open) or -1 (crossed) per sample, ``stroke`` 0 for
    the forward swing and 1 for the return."""

    lo: float
    hi: float
    theta: np.ndarray
    out: np.ndarray
    status: np.ndarray
    branch: np.ndarray
    stroke: np.ndarray


def rocking_motions(p: Params, n_stroke: int = 181) -> list[Motion] | None:
    """The motions of the deck's linkage when its crank cannot turn fully (None when it can):
    per assembly interval (:func:`assembly_intervals`), ``n_stroke`` samples forward on the
    deck's branch and ``n_stroke`` back on the other, the ends a hair inside the limit angles
    (at the limit itself round-off may put A a ulp beyond reach).  Positions only: the
    kernel's velocities assume the deck's constant crank speed (reversed on the return)."""
    spans = assembly_intervals(p.fixed_link, p.crank, p.coupler, p.rocker)
    if spans is None:
        return None
    first = 1 if p.branch == "open" else -1
    motions = []
    for lo, hi in spans:
        pad = 1e-7 * max(1.0, hi - lo)
        # cosine spacing: samples gather at the limits, where B moves fast for a little crank
        # motion (and a crank driven to and fro slows there to reverse)
        fwd = lo + pad + (hi - lo - 2 * pad) * 0.5 * (1.0 - np.cos(np.linspace(0.0, math.pi, n_stroke)))
        o1, s1 = kernels.fourbar_exact(np.radians(fwd), p.fixed_link, p.crank, p.coupler, p.rocker,
                                       p.omega, p.alpha, first)
        o2, s2 = kernels.fourbar_exact(np.radians(fwd[::-1]), p.fixed_link, p.crank, p.coupler, p.rocker,
                                       -p.omega, p.alpha, -first)
        motions.append(Motion(lo, hi, np.concatenate([fwd, fwd[::-1]]), np.vstack([o1, o2]),
                              np.concatenate([s1, s2]),
                              np.repeat([first, -first], n_stroke), np.repeat([0, 1], n_stroke)))
    return motions


def crank_angles(p: Params) -> np.ndarray:
    """The requested crank angles [deg] (Fortran DO semantics: start, start+step, ... <= stop)."""
    n = int(math.floor((p.stop_deg - p.start_deg) / p.step_deg + 1e-9)) + 1
    return p.start_deg + p.step_deg * np.arange(n)


def exact_grid(p: Params, theta_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closed-loop states at ``theta_deg`` (kernel columns, see kernels.fourbar_exact)."""
    return kernels.fourbar_exact(np.radians(theta_deg), p.fixed_link, p.crank, p.coupler, p.rocker,
                                 p.omega, p.alpha, 1 if p.branch == "open" else -1)


def coupler_point(p: Params, theta_deg: np.ndarray, out: np.ndarray, status: np.ndarray) -> np.ndarray | None:
    """Position, velocity and acceleration of the deck's coupler point (None if it has none)."""
    if not p.coupler_point:
        return None
    u, v = p.coupler_point
    return kernels.fourbar_coupler_point(np.radians(theta_deg), out, status, p.crank, p.omega, p.alpha, u, v)


def listing_grid(p: Params) -> tuple[np.ndarray, np.ndarray]:
    """The published program's rows for the deck's crank angles."""
    start, step = int(p.start_deg), int(p.step_deg)
    n = len(crank_angles(p))
    return kernels.fourbar_listing(p.fixed_link, p.crank, p.coupler, p.rocker, p.omega, start, step, n)


def _deg360(rad: np.ndarray) -> np.ndarray:
    """Radians -> degrees in [0, 360), with values that round to 360.0 folded to 0."""
    d = np.mod(np.degrees(rad), 360.0)
    return np.where(d >= 359.95, d - 360.0, d)


@dataclass
class Extremes:
    """Headline figures over the analysed crank range (exact solution), from the batch kernel."""

    mu_min: float
    mu_min_at: float
    mu_max: float
    mu_max_at: float
    rocker_min: float
    rocker_min_at: float
    rocker_max: float
    rocker_max_at: float
    w3_peak: float
    w3_peak_at: float
    w2_peak: float
    w2_peak_at: float
    assembled_fraction: float
    rocker_turns: bool = False
    toggles: tuple[float, ...] = ()
    rocker_swing: float = 0.0


def toggles_in_range(p: float, q: float, r: float, s: float, lo: float, hi: float) -> tuple[float, ...]:
    """Limit (toggle) crank angles [deg] inside [lo, hi], every turn (a + 360 k), ascending."""
    out = []
    for a in limit_angles(p, q, r, s):
        k0, k1 = math.ceil((lo - a) / 360.0), math.floor((hi - a) / 360.0)
        out += [a + 360.0 * k for k in range(k0, min(k1, k0 + 1000) + 1)]
    return tuple(sorted(out))


def extremes(p: Params) -> Extremes | None:
    """Transmission-angle, rocker-position and speed extremes over the deck's crank range.

    One row of the batch kernel (fortran/fourbar_summary.f90, see :func:`summarise_batch`),
    so a single run and a sweep report the same figures: transmission-angle and rocker
    extremes in closed form, peak speeds from a 1 deg scan refined to 1e-12 rad.
    None when the linkage cannot be assembled anywhere in the range.
    """
    lo, hi = sorted((p.start_deg, p.stop_deg))
    row = kernels.fourbar_summaries(_param_matrix(p, {}, 1))[0]
    if not row[1]:
        return None
    toggles = toggles_in_range(p.fixed_link, p.crank, p.coupler, p.rocker, lo, hi)
    return Extremes(row[3], row[4], row[5], row[6], row[7], row[8], row[9], row[10],
                    row[14], row[15], row[16], row[17], row[2], bool(row[12]), toggles, row[11])


# ----------------------------------------------------------------------------- batch summaries

#: deck keys a batch may vary (one value per design); every other key of &fourbar leaves the
#: summary unchanged (alpha, step_deg, method, title, coupler_point) and is accepted but ignored
BATCH_KEYS = ("fixed_link", "crank", "coupler", "rocker", "omega", "start_deg", "stop_deg", "branch")
BATCH_IGNORED = ("alpha", "step_deg", "method", "title", "coupler_point")
#: keys whose deck checks do not involve other keys (a sweep validates each of their values once)
BATCH_INDEPENDENT = ("fixed_link", "crank", "coupler", "rocker", "omega", "alpha", "title", "coupler_point")

#: The column -> pass dependency table of the batch summary (the study's part of "compute only
#: what the deck asks for"): for each column of :func:`summarise_batch` (``detail`` columns
#: included), the kernel passes of fortran/fourbar_summary.f90 it needs.  Columns with no pass
#: are closed form and always computed (Grashof class, assembly, toggles); 'transmission' is
#: closed form too, 'rocker' evaluates the states at the rocker's candidate extremes, 'peaks'
#: scans the range for the speed extremes (about 80 % of the kernel time when asked).
BATCH_PASSES: dict[str, tuple[str, ...]] = {
    "grashof_class": (), "full_crank_rotation": (), "assemblable": (),
    "mu_min_deg": ("transmission",), "mu_max_deg": ("transmission",), "meets_transmission_band": ("transmission",),
    "rocker_turns_fully": ("rocker",), "rocker_swing_deg": ("rocker",), "toggle_in_range": (),
    "omega3_peak_rad_s": ("peaks",), "omega2_peak_rad_s": ("peaks",), "assembled_fraction": (),
    "time_ratio": ("rocker",),
    "mu_min_at_deg": ("transmission",), "mu_max_at_deg": ("transmission",), "rocker_min_deg": ("rocker",),
    "rocker_min_at_deg": ("rocker",), "rocker_max_deg": ("rocker",), "rocker_max_at_deg": ("rocker",),
    "omega3_peak_at_deg": ("peaks",), "omega2_peak_at_deg": ("peaks",), "toggles_in_range": (),
    # decks that give masses: the force summary (driver/fourbar/forces.py), a pass of its own
    **{f"{pre}{c}": ("forces",) for pre in ("", "unbalanced_") for c in forces.SUMMARY_DOC},
}
#: the kernel's pass bits (fortran/fourbar_summary.f90 pass_*)
PASS_BITS = {"transmission": kernels.FOURBAR_PASSES["transmission"], "rocker": kernels.FOURBAR_PASSES["rocker"],
             "peaks": kernels.FOURBAR_PASSES["peaks"]}


def _pass_mask(wanted: Collection[str] | None) -> int:
    """The kernel's pass bits for summary columns ``wanted`` (None: every pass)."""
    if wanted is None:
        return sum(PASS_BITS.values())
    return sum({PASS_BITS[p] for c in wanted for p in BATCH_PASSES.get(c, ()) if p in PASS_BITS})


#: kernel Grashof codes -> (class name as grashof() prints it, full crank rotation)
GRASHOF_NAMES = {"double_crank": ("double-crank (drag link)", True), "crank_rocker": ("crank-rocker", True),
                 "rocker_crank": ("rocker-crank", False), "double_rocker": ("Grashof double-rocker", False),
                 "change_point": ("change-point (special Grashof)", True),
                 "triple_rocker": ("non-Grashof triple-rocker", False)}


def _bad(base: Mapping[str, Any], key: str | None, message: str) -> Exception:
    """A DeckError at the key's deck line when ``base`` is a deck's Params, else a ValueError."""
    if isinstance(base, Params):
        return base.error(key, message)
    return ValueError(f"{key}: {message}" if key else message)


def _param_matrix(base: Mapping[str, Any], columns: Mapping[str, Any], n: int) -> np.ndarray:
    """The kernel's (n, 8) parameter matrix: base values, overridden column by column."""
    cols = {}
    for key in BATCH_KEYS:
        v = columns.get(key, base[key])
        if key == "branch":
            v = np.asarray(v)
            if v.dtype.kind in "US":
                bad = ~np.isin(v, ("open", "crossed"))
                if bad.any():
                    raise _bad(base, "branch", f"must be 'open' or 'crossed' (got {v[np.argmax(bad)]!r})")
                v = np.where(v == "open", 1.0, -1.0)
        v = np.broadcast_to(np.asarray(v, dtype=np.float64), (n,))
        bad = ~np.isfinite(v)
        if key in ("fixed_link", "crank", "coupler", "rocker"):
            bad |= ~(v > 0)
        if bad.any():
            i = int(np.argmax(bad))
            raise _bad(base, key, f"design {i} has {float(v[i])!r} (lengths must be positive, all values finite)")
        cols[key] = v
    m = np.empty((n, 8), dtype=np.float64, order="F")
    for j, key in enumerate(BATCH_KEYS):
        m[:, j] = cols[key]
    return m


def summarise_batch(base: Mapping[str, Any], columns: Mapping[str, Any] | None = None,
                    detail: bool = False, wanted: Collection[str] | None = None) -> pd.DataFrame:
    """Summaries of many four-bar designs in one Fortran call: one row per design.

    ``base``: a validated ``&fourbar`` Params (or any mapping with the BATCH_KEYS).
    ``columns``: {key: array of n values} for keys in BATCH_KEYS (``'fourbar.crank'`` is
    accepted for ``'crank'``); scalars broadcast.  Lengths in the deck's unit, ``omega``
    [rad/s], ``start_deg``/``stop_deg`` [deg], ``branch`` 'open'/'crossed' or +1/-1.
    Returns the columns of the single-case summary (``summarise``) with identical values
    (missing figures as NaN): grashof_class, full_crank_rotation, assemblable, mu_min_deg,
    mu_max_deg, meets_transmission_band (mu within the base deck's ``transmission_band_deg``), rocker_turns_fully, rocker_swing_deg, toggle_in_range,
    omega3_peak_rad_s, omega2_peak_rad_s, assembled_fraction, time_ratio (crank angle of the
    rocker's slower stroke over its quicker one, >= 1; missing unless the range holds a full
    turn, assembled throughout, without a toggle, with the rocker oscillating); with ``detail`` also the crank
    angles [deg] of those extremes, the rocker extreme positions [deg] and the number of
    toggle positions in the range.  ``wanted``: only these columns (names of the columns
    above; others are ignored), computed by only the kernel passes they need
    (:data:`BATCH_PASSES`) -- each with the same bits as in a full summary; None: all.
    A bad value raises DeckError (``base`` a deck's Params: deck, line and key of the base
    deck, the design's index in the message) or ValueError.  About 3 microseconds per design
    on one core with every column, 0.7 without the peak speeds (bench/bench_sweep.py).
    """
    columns = {k.partition(".")[2] if k.startswith("fourbar.") else k: v for k, v in (columns or {}).items()}
    unknown = [k for k in columns if k not in BATCH_KEYS and k not in BATCH_IGNORED]
    if unknown:
        raise _bad(base, unknown[0], f"not a &fourbar key the summary depends on ({', '.join(BATCH_KEYS)})")
    force_columns = {k: v for k, v in columns.items() if k in forces.BATCH_KEYS}
    columns = {k: v for k, v in columns.items() if k in BATCH_KEYS}
    sizes = {np.size(v) for v in columns.values() if np.ndim(v) > 0}
    if len(sizes) > 1:
        raise _bad(base, None, f"batch columns have different lengths {sorted(sizes)}")
    n = sizes.pop() if sizes else 1
    res = kernels.fourbar_summaries(_param_matrix(base, columns, n), _pass_mask(wanted))
    frame = _frame(res, detail or (wanted is not None and any(c in _DETAIL for c in wanted)), band_of(base), wanted)
    if forces.active(base) and (wanted is None or any(BATCH_PASSES.get(c) == ("forces",) for c in wanted)):
        # force columns (driver/fourbar/forces.py) when the deck gives masses, and someone reads one
        more = forces.summarise_force_batch(base, force_columns)
        if wanted is not None:
            more = more[[c for c in more.columns if c in set(wanted)]]
        frame = pd.concat([frame, more], axis=1)
    return frame


#: the columns of summarise_batch(detail=True) only
_DETAIL = ("mu_min_at_deg", "mu_max_at_deg", "rocker_min_deg", "rocker_min_at_deg", "rocker_max_deg",
           "rocker_max_at_deg", "omega3_peak_at_deg", "omega2_peak_at_deg", "toggles_in_range")


def _frame(res: np.ndarray, detail: bool = False, band: tuple[float, float] = BAND,
           wanted: Collection[str] | None = None) -> pd.DataFrame:
    """Kernel rows -> the summary columns (vectorised; the one place both paths go through);
    with ``wanted``, only those columns are built."""
    c = dict(zip(kernels.FOURBAR_SUMMARY_COLUMNS, res.T))
    ok = c["assemblable"] > 0
    lut = [GRASHOF_NAMES[kernels.FOURBAR_GRASHOF[k]] for k in range(len(GRASHOF_NAMES))]
    tog = lambda: ok & (c["toggles_in_range"] > 0)
    has = lambda v, m=None: np.where(ok if m is None else m, v, np.nan)
    lo, hi = band
    build: dict[str, Callable[[], Any]] = {
        "grashof_class": lambda: np.array([n for n, _ in lut], dtype=object)[c["grashof"].astype(int)],
        "full_crank_rotation": lambda: np.array([f for _, f in lut])[c["grashof"].astype(int)],
        "assemblable": lambda: ok,
        "mu_min_deg": lambda: has(c["mu_min_deg"]), "mu_max_deg": lambda: has(c["mu_max_deg"]),
        "meets_transmission_band": lambda: ok & (c["mu_min_deg"] >= lo) & (c["mu_max_deg"] <= hi),
        "rocker_turns_fully": lambda: ok & (c["rocker_turns"] > 0),
        "rocker_swing_deg": lambda: has(c["rocker_swing_deg"]),
        "toggle_in_range": tog,
        "omega3_peak_rad_s": lambda: has(c["omega3_peak_rad_s"], ok & ~tog()),
        "omega2_peak_rad_s": lambda: has(c["omega2_peak_rad_s"], ok & ~tog()),
        "assembled_fraction": lambda: np.where(ok, c["assembled_fraction"], 0.0),
        "time_ratio": lambda: np.where(ok & (c["time_ratio"] > 0), c["time_ratio"], np.nan)}
    if detail:
        build |= {"mu_min_at_deg": lambda: has(c["mu_min_at_deg"]), "mu_max_at_deg": lambda: has(c["mu_max_at_deg"]),
                  "rocker_min_deg": lambda: has(c["rocker_min_deg"]),
                  "rocker_min_at_deg": lambda: has(c["rocker_min_at_deg"]),
                  "rocker_max_deg": lambda: has(c["rocker_max_deg"]),
                  "rocker_max_at_deg": lambda: has(c["rocker_max_at_deg"]),
                  "omega3_peak_at_deg": lambda: has(c["omega3_peak_at_deg"], ok & ~tog()),
                  "omega2_peak_at_deg": lambda: has(c["omega2_peak_at_deg"], ok & ~tog()),
                  "toggles_in_range": lambda: c["toggles_in_range"].astype(int)}
    keys = build if wanted is None else [k for k in build if k in set(wanted)]
    return pd.DataFrame({k: build[k]() for k in keys}, index=pd.RangeIndex(len(res)))


# ----------------------------------------------------------------------------- tables

def _echo(p: Params) -> list[str]:
    """Deck inputs echoed in the English header of exact runs."""
    rows = [("fixed link O_A-O_B", p.fixed_link, ""), ("crank (driver) O_A-A", p.crank, ""),
            ("coupler A-B", p.coupler, ""), ("rocker (output) O_B-B", p.rocker, ""),
            ("crank speed", p.omega, "rad/s"), ("crank acceleration", p.alpha, "rad/s^2")]
    return [f"  {name:<24}{fortran_f(v, 12, 4)} {u}".rstrip() for name, v, u in rows]


def listing_text(p: Params, table: np.ndarray, status: np.ndarray) -> list[str]:
    """The listing's output file: its header (format 15), column line and rows (format 25)."""
    head = ["", "", "",
            f"  panjang OA-OB (fixed link):  {fortran_f(p.fixed_link, 5, 2, 'legacy')}",
            f"  panjang poros engkol (crank/driver):  {fortran_f(p.crank, 5, 2, 'legacy')}",
            f"  panjang batang penghubung (coupler):  {fortran_f(p.coupler, 5, 2, 'legacy')}",
            f"  panjang batang ayun (rocker/output link):  {fortran_f(p.rocker, 5, 2, 'legacy')}",
            f"  kecepatan sudut poros engkol (rad/detik):  {fortran_f(p.omega, 5, 2, 'legacy')}",
            ""]
    # format 25: (2x,i3,2x,7(f5.1,2x),3x,2(f7.4,3x))
    cols = ([Column("i", "i", 3, 0, 2)] + [Column(h, "f", 5, 1, 2, "legacy") for h in ("epsl", "phi", "beta", "xa", "ya", "xb")]
            + [Column("yb", "f", 5, 1, 2, "legacy"), Column("omr", "f", 7, 4, 5, "legacy"), Column("oms", "f", 7, 4, 3, "legacy")])
    rows, trailers = [], []
    for row, st in zip(table, status):
        if st == ST["no_assembly"]:
            rows.append([int(row[0])] + [None] * 9)
            trailers.append("cannot be assembled: the listing's arccos argument leaves [-1, 1]")
        elif st == ST["toggle"]:
            rows.append([int(row[0])] + list(row[1:8]) + [None, None])
            trailers.append("toggle: sin(phi - epsl) = 0, velocities unbounded")
        else:
            rows.append([int(row[0])] + list(row[1:]))
            trailers.append("")
    lines = render_table(cols, rows, trailers)
    return head + [lines[0], ""] + lines[1:], cols


def exact_table(p: Params, theta: np.ndarray, out: np.ndarray, status: np.ndarray,
                cp: np.ndarray | None = None) -> list[str]:
    """Fixed-format exact table: the listing's ten columns (angles rounded) plus accelerations,
    and the coupler point's position and speed when the deck defines one (``cp`` from
    kernels.fourbar_coupler_point)."""
    whole = np.all(np.isclose(theta, np.round(theta)))
    tcol = Column("theta", "i", 5, 0, 2) if whole else Column("theta", "f", 8, 3, 2)
    cols = [tcol, Column("coupler", "f", 7, 1), Column("rocker", "f", 7, 1), Column("transm", "f", 7, 1)]
    cols += [Column(h, "f", 9, 4) for h in ("xa", "ya", "xb", "yb")]
    cols += [Column(h, "f", 10, 4) for h in ("omega2", "omega3")] + [Column(h, "f", 11, 4) for h in ("alpha2", "alpha3")]
    units = ["[deg]", "[deg]", "[deg]", "[deg]", "", "", "", "", "[rad/s]", "[rad/s]", "[rad/s2]", "[rad/s2]"]
    if cp is not None:
        cols += [Column("xp", "f", 9, 4), Column("yp", "f", 9, 4), Column("vp", "f", 10, 4)]
        units += ["", "", "[len/s]"]
        extra = np.column_stack([cp[:, 0], cp[:, 1], np.hypot(cp[:, 2], cp[:, 3])])
    ang = np.column_stack([_deg360(out[:, 0]), _deg360(out[:, 1]), np.degrees(out[:, 2])])
    rows, trailers = [], []
    d = np.hypot(p.fixed_link - out[:, 3], out[:, 4])
    for k in range(len(theta)):
        t = int(round(theta[k])) if whole else theta[k]
        if status[k] == ST["indeterminate"]:
            rows.append([t, None, None, None, out[k, 3], out[k, 4]] + [None] * 6)
            trailers.append("indeterminate: crank pin A on the rocker pivot O_B, B free on a circle")
        elif status[k] == ST["no_assembly"]:
            rows.append([t, None, None, None, out[k, 3], out[k, 4]] + [None] * 6)
            trailers.append(f"cannot be assembled: |A O_B| = {d[k]:.4f} outside "
                            f"[{abs(p.coupler - p.rocker):g}, {p.coupler + p.rocker:g}]")
        elif status[k] == ST["toggle"]:
            rows.append([t, *ang[k], *out[k, 3:7]] + [None] * 4)
            trailers.append("toggle: coupler and rocker collinear, velocity unbounded")
        else:
            rows.append([t, *ang[k], *out[k, 3:11]])
            trailers.append("")
        if cp is not None:
            placed = status[k] in (ST["ok"], ST["toggle"])
            rows[-1] += [extra[k, 0] if placed else None, extra[k, 1] if placed else None,
                         extra[k, 2] if status[k] == ST["ok"] else None]
    lines = render_table(cols, rows, trailers)
    unit_line = "".join(" " * c.sep + u.rjust(max(c.width, len(c.header))) for c, u in zip(cols, units)).rstrip()
    return [lines[0], unit_line] + lines[1:]


def summary_lines(p: Params, g: Grashof, ex: Extremes | None) -> list[str]:
    """Words and numbers after an exact table."""
    lim = limit_angles(p.fixed_link, p.crank, p.coupler, p.rocker)
    out = ["", "  Summary (closed-loop solution, branch = " + p.branch + ")",
           f"    Grashof class ........ {g.name}  ({g.condition})",
           "    crank rotation ....... " + ("full turn" if not lim else
                                           "limited: limit (toggle) crank angles " +
                                           ", ".join(f"{a:.3f}" for a in lim) + " deg")]
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
        out += [f"    peak rocker speed .... {ex.w3_peak:.4f} rad/s at theta = {ex.w3_peak_at:.2f} deg",
                f"    peak coupler speed ... {ex.w2_peak:.4f} rad/s at theta = {ex.w2_peak_at:.2f} deg"]
    if ex.assembled_fraction < 1.0:
        out.append(f"    assemblable .......... about {100 * ex.assembled_fraction:.1f} % of the requested range")
    return out


def audit(p: Params, theta: np.ndarray, table: np.ndarray, lst_status: np.ndarray,
          out: np.ndarray, status: np.ndarray) -> tuple[list[str], str | None, pd.DataFrame]:
    """Rows of the listing that violate loop closure, compared with the exact solution."""
    ab = np.hypot(table[:, 6] - table[:, 4], table[:, 7] - table[:, 5])
    dev = ab - p.coupler
    good = (lst_status == ST["ok"]) & (status == ST["ok"])
    bad = good & (np.abs(dev) > 1e-4 * p.coupler)
    lines = ["", "  Audit of the listing against the closed loop (method = 'exact', branch = 'open')"]
    frame = pd.DataFrame({"theta_deg": theta, "ab_length": ab, "ab_deviation": dev, "loop_not_closed": bad})
    if not bad.any():
        lines.append(f"    every row closes the loop: |AB| = coupler within {np.max(np.abs(dev[good]), initial=0):.2e}")
        return lines, None, frame
    worst = int(np.argmax(np.where(bad, np.abs(dev), -1)))
    cols = [Column("i", "i", 5, 0), Column("|AB|", "f", 9, 4), Column("dev", "f", 9, 4),
            Column("xb lst", "f", 8, 3), Column("yb lst", "f", 8, 3), Column("xb", "f", 8, 3),
            Column("yb", "f", 8, 3), Column("oms lst", "f", 9, 4), Column("omega3", "f", 9, 4)]
    rows = [[int(theta[k]), ab[k], dev[k], table[k, 6], table[k, 7], out[k, 5], out[k, 6], table[k, 9], out[k, 8]]
            for k in np.flatnonzero(bad)]
    lines += [f"    {int(bad.sum())} of {len(theta)} rows have a coupler length |AB| different from "
              f"the deck's {p.coupler:g}; largest deviation {dev[worst]:+.4f} at i = {int(theta[worst])}:"]
    lines += ["  " + l for l in render_table(cols, rows)]
    lines += ["    Why: for crank angles in (180, 360) deg the listing's quadrant test sends",
              "    sigy > 0, sigx > 0 to 'sigma = 2 pi - |atan|' (meant: |atan|), so those rows",
              "    repeat the positions of 360 - i (mirror image) and their velocities are",
              "    wrong; the transmission angle column is still right (it depends on |A O_B| only).",
              "    Use method = 'exact' for correct values (columns 'xb', 'yb', 'omega3' above)."]
    warn = (f"listing rows violate loop closure at {int(bad.sum())} crank angles "
            f"(largest |AB| deviation {dev[worst]:+.4f} at {int(theta[worst])} deg); see the audit in the .out")
    return lines, warn, frame


# ----------------------------------------------------------------------------- tidy + figures

def exact_as_listed(p: Params, theta_deg: np.ndarray) -> dict[tuple[int, str], str]:
    """The closed-loop solution at whole crank angles ``theta_deg`` printed the way the listing prints
    (FORMAT 25: angles truncated to whole degrees, legacy F5.1 / F7.4), keyed by (angle, column of
    the listing table): what the published table shows where it is right.  Blank where the linkage
    cannot be placed."""
    out, status = exact_grid(p, theta_deg)
    cols = _exact_columns(out, status)
    names = {"epsl": "coupler_deg", "phi": "rocker_deg", "beta": "transmission_deg", "xa": "xa", "ya": "ya",
             "xb": "xb", "yb": "yb", "omr": "omega2_rad_s", "oms": "omega3_rad_s"}
    res: dict[tuple[int, str], str] = {}
    for k, i in enumerate(np.asarray(theta_deg).astype(int)):
        res[(int(i), "i")] = str(int(i))
        for col, name in names.items():
            v = cols[name][k]
            if not np.isfinite(v):
                res[(int(i), col)] = ""
            elif col in ("epsl", "phi", "beta"):
                res[(int(i), col)] = fortran_f(math.trunc(v), None, 1, "legacy")
            else:
                res[(int(i), col)] = fortran_f(v, None, 4 if col in ("omr", "oms") else 1, "legacy")
    return res


#: units of the tidy columns whose names do not say them ('length': the deck's length unit)
TIDY_UNITS = {"xa": "length", "ya": "length", "xb": "length", "yb": "length", "xp": "length", "yp": "length",
              "ab_error": "length"}


def tidy_frame(method: str, theta: np.ndarray, cols: dict[str, np.ndarray], status: np.ndarray,
               not_closed: np.ndarray | None = None) -> pd.DataFrame:
    """One row per crank angle; status in words ('loop_not_closed' where ``not_closed``: a
    listing row whose |AB| is not the coupler length); unassemblable cells left empty (NaN)."""
    words = np.array(["ok", "cannot_assemble", "toggle", "indeterminate", "loop_not_closed"])[
        np.where(not_closed, 4, status) if not_closed is not None else status]
    frame = pd.DataFrame({"method": method, "theta_deg": theta, **cols, "status": words})
    return with_units(frame, TIDY_UNITS)


def _exact_columns(out: np.ndarray, status: np.ndarray, cp: np.ndarray | None = None,
                   coupler: float | None = None) -> dict[str, np.ndarray]:
    vals = {"coupler_deg": _deg360(out[:, 0]), "rocker_deg": _deg360(out[:, 1]),
            "transmission_deg": np.degrees(out[:, 2]), "xa": out[:, 3], "ya": out[:, 4],
            "xb": out[:, 5], "yb": out[:, 6], "omega2_rad_s": out[:, 7], "omega3_rad_s": out[:, 8],
            "alpha2_rad_s2": out[:, 9], "alpha3_rad_s2": out[:, 10]}
    if coupler is not None:   # loop closure of the solution: |AB| - coupler (round-off only)
        vals["ab_error"] = np.hypot(out[:, 5] - out[:, 3], out[:, 6] - out[:, 4]) - coupler
    if cp is not None:
        vals.update({"xp": cp[:, 0], "yp": cp[:, 1], "vxp_per_s": cp[:, 2], "vyp_per_s": cp[:, 3],
                     "axp_per_s2": cp[:, 4], "ayp_per_s2": cp[:, 5]})
    nope = (status == ST["no_assembly"]) | (status == ST["indeterminate"])
    tog = status == ST["toggle"]
    for k, v in vals.items():
        v = v.copy()
        if k not in ("xa", "ya"):
            v[nope] = np.nan
        if k.startswith(("omega", "alpha", "vxp", "vyp", "axp", "ayp")):
            v[tog] = np.nan
        vals[k] = v
    return vals


def output_name(p: Params) -> str:
    """What the output link is called in figures: 'output crank' when it turns fully (a
    double-crank, a drag link), 'rocker' otherwise."""
    g = grashof(p.fixed_link, p.crank, p.coupler, p.rocker)
    return "output crank" if g.name.startswith("double-crank") else "rocker"


def _figures(p: Params, stem_title: str, listing: pd.DataFrame | None) -> list[Figure]:
    def curves():
        from driver import plotting   # matplotlib is the optional [plot] extra: import when drawing
        theta = np.linspace(p.start_deg, p.stop_deg, 721)
        out, st = exact_grid(p, theta)
        exact = tidy_frame("exact", theta, _exact_columns(out, st), st)
        return plotting.fourbar_curves(exact, listing, stem_title, band=band_of(p), output=output_name(p))

    def linkage():
        from driver import plotting
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
            return plotting.fourbar_linkage(p.fixed_link, theta, out, st == ST["ok"], None, stem_title,
                                            output=output_name(p), motions=drawn)
        limits = []
        for a in limit_angles(p.fixed_link, p.crank, p.coupler, p.rocker):
            if theta[0] - 1e-9 <= a <= theta[-1] + 1e-9 or hi - lo >= 360.0:
                row, rst = exact_grid(p, np.array([a]))
                if rst[0] != ST["no_assembly"] and np.all(np.isfinite(row[0, 3:7])):
                    limits.append((a, row[0]))
        return plotting.fourbar_linkage(p.fixed_link, theta, out, st == ST["ok"], listing, stem_title,
                                        point=None if cp is None else cp[:, :2], output=output_name(p),
                                        limits=limits)

    return [Figure("curves", curves), Figure("linkage", linkage)]


def estimate(params: Params) -> Estimate:
    """Memory and work of a run from the keys alone (driver.limits): per crank angle a table row
    (text, two tidy frames, kernel columns; about 2 KB and 50 us of Python formatting), and the
    summary kernel's 1 deg scan of at most one turn (the motion is periodic; about 30 us)."""
    p = params
    try:
        n = float(math.floor((p.stop_deg - p.start_deg) / p.step_deg + 1e-9) + 1)
    except (OverflowError, ZeroDivisionError, ValueError):
        n = math.inf
    n = max(n, 1.0)
    span = min(abs(p.stop_deg - p.start_deg), 360.0) / 1.0 + 1.0
    range_key = "start_deg" if "start_deg" in p.given else ("stop_deg" if "stop_deg" in p.given else "step_deg")
    k = 2.5 if forces.active(p) else 1.0   # the force table and columns: 13 more cells and 24 columns per row
    rows = Estimate(k * 2000.0 * n + 5e6, k * 5e-5 * n + 0.05, "step_deg", "step_deg", f"{n:.4g} crank angles")
    grid = Estimate(500.0 * span, 1e-6 * span, range_key, range_key,
                    f"a {span:.4g}-point scan of one turn for the summary")
    return rows + grid


def blame(params: Params, exc: BaseException) -> tuple[str, str] | None:
    """The key and words for a numerical failure of a run (driver.runner.numerical_error)."""
    p = params
    g = grashof(p.fixed_link, p.crank, p.coupler, p.rocker)
    if p.method == "listing" and g.name.startswith("change-point"):
        return ("method", f"the listing's formulas divide 0 by 0 for this change-point linkage ({g.condition}) "
                          "where it folds flat, so its table has no finite value there; use method = 'exact' "
                          "(the closed-loop solution names both branches at the fold)")
    return None


# ----------------------------------------------------------------------------- run

@keyword_run
def run(params: Params, progress: bool = False) -> Result:
    """Analyse one four-bar deck (see module docstring)."""
    p = params
    theta = crank_angles(p)
    g = grashof(p.fixed_link, p.crank, p.coupler, p.rocker)
    out, status = exact_grid(p, theta)
    cp = coupler_point(p, theta, out, status)
    ex = extremes(p)
    exact_frame = tidy_frame("exact", theta, _exact_columns(out, status, cp, p.coupler), status)
    warnings: list[str] = []
    title = p.title or f"{p.path.stem}"
    if p.method == "listing":
        table, lst_status = listing_grid(p)
        lines, _ = listing_text(p, table, lst_status)
        alines, warn, closure = audit(p, theta, table, lst_status, out, status)
        lines += alines + summary_lines(p, g, ex)
        if warn:
            warnings.append(warn)
        lst_cols = dict(zip(["coupler_deg", "rocker_deg", "transmission_deg", "xa", "ya", "xb", "yb",
                             "omega2_rad_s", "omega3_rad_s"], table[:, 1:].T))
        lst_cols["ab_error"] = np.where(lst_status == ST["ok"], closure["ab_deviation"].to_numpy(), np.nan)
        listing_frame = tidy_frame("listing", theta, lst_cols, lst_status, closure["loop_not_closed"].to_numpy())
        tidy = with_units(pd.concat([listing_frame, exact_frame], ignore_index=True), TIDY_UNITS)
    else:
        listing_frame = None
        lines = [f"  four-bar linkage: closed-loop analysis (method = exact, branch = {p.branch})",
                 f"  deck: {p.path}" + (f" -- {p.title}" if p.title else ""), ""] + _echo(p) + [""]
        lines += exact_table(p, theta, out, status, cp) + summary_lines(p, g, ex)
        if cp is not None:
            lines += [f"    coupler point P ...... u = {p.coupler_point[0]:g} along A->B, v = {p.coupler_point[1]:g} "
                      "to its left; xp, yp its position, vp its speed [length/s]"]
        if forces.active(p):
            lines += _force_section(p, theta, out, status, exact_frame)
        for k in np.flatnonzero(status == ST["no_assembly"])[:1]:
            warnings.append(f"the linkage cannot be assembled at {int((status == ST['no_assembly']).sum())} "
                            f"of {len(theta)} crank angles (first at {theta[k]:g} deg)")
        tidy = exact_frame
    summary = _summary(p)
    figs = _figures(p, title, listing_frame) + (forces.figures(p, title, exact_grid) if forces.active(p) else [])
    return Result(text="\n".join(lines) + "\n", tidy=tidy, summary=summary, warnings=warnings, figures=figs)


def _force_section(p: Params, theta: np.ndarray, out: np.ndarray, status: np.ndarray,
                   frame: pd.DataFrame) -> list[str]:
    """The force analysis's lines of the .out; its columns are added to ``frame`` (in place)."""
    fa = forces.analyse(p, out, status)
    for name, values in forces.tidy_columns(fa).items():
        frame[name] = values
    with_units(frame, TIDY_UNITS)
    words = ["toggle: forces unbounded" if s == ST["toggle"] else "not placed" for s in status]
    title = ("Force analysis (Newton-Euler, closed form; " +
             ("with the Berkof-Lowen counterweights" if fa.cw is not None else "links as given") + ")")
    return (forces.echo_lines(p) + forces.table_lines(theta, fa.forces, fa.ok, words, title)
            + forces.summary_lines(p, forces.summary(p), fa))


def summarise(params: Params) -> dict:
    """Headline figures only (what a sweep needs when it writes no per-case files)."""
    return _summary(params)


def _summary(p: Params) -> dict:
    """Headline figures for sweeps: one row of :func:`summarise_batch` as a dict (missing -> None)."""
    row = summarise_batch(p).iloc[0].to_dict()
    return {k: (None if isinstance(v, float) and math.isnan(v) else
                bool(v) if isinstance(v, (bool, np.bool_)) else
                float(v) if isinstance(v, np.floating) else v) for k, v in row.items()}
