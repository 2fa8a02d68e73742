"""Four-bar analysis: Grashof class, limit (toggle) angles, the closed-loop and listing states
through the kernel, the extremes over the crank range, and the tidy columns of the states."""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from driver._deck import Params
from driver._result import Tidy
from driver._study import batch_error
from driver.fourbar import _kernel as kernel
from driver.fourbar._kernel import Point, State, Summary, SummaryParam

if TYPE_CHECKING:   # annotations only: pandas is imported when a table is built
    import pandas as pd

__all__ = ['ST', 'CLASSES', 'LinkageClass', 'Grashof', 'grashof', 'limit_angles', 'assembly_intervals', 'Motion',
           'rocking_motions', 'crank_angles', 'exact_grid', 'coupler_point', 'listing_grid', 'deg360', 'Extremes',
           'toggles_in_range', 'extremes', 'TIDY_UNITS', 'tidy_frame', 'tidy_part', 'exact_columns', 'blame',
           'SUMMARY_KEYS', 'PASS_BITS', 'param_matrix', 'summary_rows']


ST = kernel.FOURBAR_STATUS


class LinkageClass(NamedTuple):
    """One class of :func:`grashof`: its name, whether the crank turns fully, whether the chain moves."""

    name: str
    full_crank_rotation: bool
    movable: bool = True


#: the classes by the summary kernel's code name (fortran/fourbar_summary.f90 gr_*): Grashof's four by
#: the shortest link, the non-Grashof triple-rocker, the change-point ones (S + L = P + Q) by the
#: shortest link the same way, and the two chains that cannot move
CLASSES: dict[str, LinkageClass] = {
    "double_crank": LinkageClass("double-crank (drag link)", True),
    "crank_rocker": LinkageClass("crank-rocker", True),
    "rocker_crank": LinkageClass("rocker-crank", False),
    "double_rocker": LinkageClass("Grashof double-rocker", False),
    "triple_rocker": LinkageClass("non-Grashof triple-rocker", False),
    "cp_double_crank": LinkageClass("change-point double-crank (special Grashof)", True),
    "cp_crank_rocker": LinkageClass("change-point crank-rocker (special Grashof)", True),
    "cp_rocker_crank": LinkageClass("change-point rocker-crank (special Grashof)", False),
    "cp_double_rocker": LinkageClass("change-point double-rocker (special Grashof)", False),
    "no_chain": LinkageClass("impossible chain", False, False),
    "flat_chain": LinkageClass("flat chain", False, False),
}


@dataclass
class Grashof:
    """Class of a four-bar from its link lengths: Grashof's, or a chain that cannot move.

    Grashof's classes are Norton's; a change-point linkage is named the same way by which of
    crank and rocker turn fully.

    Attributes
    ----------
    name : str
        The class: ``'crank-rocker'``, ``'double-crank (drag link)'``, ``'rocker-crank'``,
        ``'Grashof double-rocker'``, ``'non-Grashof triple-rocker'``, a change-point class
        (S + L = P + Q, named by its shortest link the same way: ``'change-point crank-rocker
        (special Grashof)'``, ...), ``'impossible chain'`` (the longest link is longer than the
        other three together: no position exists) or ``'flat chain'`` (it equals them: the
        chain lies flat in one position).
    condition : str
        The inequality that decides the class, with the lengths (``'S + L = ... < P + Q = ...'``;
        ``'L = ... > S + P + Q = ...'`` for a chain that cannot move).
    full_crank_rotation : bool
        The crank turns fully.
    movable : bool, default True
        The chain has a motion (False for an impossible or a flat chain).
    reason : str or None, default None
        Why a chain that cannot move has no motion, in words naming the longest link; None when
        it moves.
    """

    name: str
    condition: str
    full_crank_rotation: bool
    movable: bool = True
    reason: str | None = None


def grashof(p: float, q: float, r: float, s: float) -> Grashof:
    """Classify a four-bar by Grashof's condition from its link lengths.

    The same rule and tolerance as the summary kernel (fortran/fourbar_summary.f90
    ``grashof_code``): first whether the chain closes at all (the longest link no longer than the
    other three together), then S + L against P + Q (S shortest, L longest), the class named by
    the shortest link; a change-point linkage (S + L = P + Q) by which of crank and rocker turn
    fully, a link among the shortest (ties counted) being one that does.

    Parameters
    ----------
    p, q, r, s : float
        Link lengths: ground (fixed link), crank, coupler, rocker, in one length unit.

    Returns
    -------
    Grashof
        The class, the condition with the lengths, whether the crank turns fully and whether
        the chain moves at all.

    Examples
    --------
    >>> from driver.fourbar import grashof
    >>> grashof(12, 5, 15, 9).name
    'crank-rocker'
    >>> g = grashof(12, 5, 150, 9)
    >>> g.name, g.full_crank_rotation, g.movable
    ('impossible chain', False, False)
    """
    links = {"ground": p, "crank": q, "coupler": r, "rocker": s}
    srt = sorted(links.values())
    short, long_ = srt[0], srt[-1]
    lhs, rhs = short + long_, srt[1] + srt[2]
    rest = srt[0] + srt[1] + srt[2]
    longest = max(links, key=lambda k: (links[k], -["ground", "crank", "coupler", "rocker"].index(k)))
    others = " + ".join(f"{v:g}" for k, v in links.items() if k != longest)
    word = {"ground": "fixed link"}.get(longest, longest)
    if long_ > rest + 1e-12 * rest:
        return Grashof(CLASSES["no_chain"].name, f"L = {long_:g} > S + P + Q = {rest:g}", False, False,
                       f"the longest link, the {word} ({long_:g}), is longer than the other three together "
                       f"({others} = {rest:g}): no position exists, at any crank angle")
    if long_ >= rest - 1e-12 * rest:
        return Grashof(CLASSES["flat_chain"].name, f"L = {long_:g} = S + P + Q = {rest:g}", False, False,
                       f"the longest link, the {word} ({long_:g}), is as long as the other three together "
                       f"({others} = {rest:g}): the chain closes only lying flat, in one position, and cannot move")
    tol = 1e-12 * rhs
    rel = "<" if lhs < rhs - tol else ("=" if abs(lhs - rhs) <= tol else ">")
    cond = f"S + L = {short:g} + {long_:g} = {lhs:g} {rel} P + Q = {rhs:g}"
    if lhs > rhs + tol:
        return Grashof(CLASSES["triple_rocker"].name, cond, False)
    if abs(lhs - rhs) <= tol:
        # change point: a link among the shortest (ties counted: a parallelogram's crank and rocker)
        # turns fully, so the crank turns when the ground or the crank is one, the rocker when the
        # ground or the rocker is
        tied = {k for k, v in links.items() if v <= short + 1e-12 * short}
        crank, rocker = bool(tied & {"ground", "crank"}), bool(tied & {"ground", "rocker"})
        code = "cp_" + {(True, True): "double_crank", (True, False): "crank_rocker", (False, True): "rocker_crank",
                        (False, False): "double_rocker"}[(crank, rocker)]
        return Grashof(CLASSES[code].name, cond, CLASSES[code].full_crank_rotation)
    shortest = min(links, key=lambda k: (links[k], ["ground", "crank", "rocker", "coupler"].index(k)))
    code = {"ground": "double_crank", "crank": "crank_rocker", "rocker": "rocker_crank", "coupler": "double_rocker"}[shortest]
    return Grashof(CLASSES[code].name, cond, CLASSES[code].full_crank_rotation)


def limit_angles(p: float, q: float, r: float, s: float) -> list[float]:
    """Find the crank angles of the limit (toggle) positions: |A O_B| = r + s or |r - s|.

    Parameters
    ----------
    p, q, r, s : float
        Link lengths: ground (fixed link), crank, coupler, rocker, in one length unit.

    Returns
    -------
    list of float
        The crank angles, deg in [0, 360), ascending; empty when the crank turns fully.
    """
    out = []
    for d in (r + s, abs(r - s)):
        c = (p * p + q * q - d * d) / (2 * p * q)
        if -1.0 <= c <= 1.0:
            a = math.degrees(math.acos(c))
            out += [a, (360.0 - a) % 360.0]
    return sorted(set(round(a, 10) for a in out))


def assembly_intervals(p: float, q: float, r: float, s: float) -> list[tuple[float, float]] | None:
    """Find the crank-angle intervals over which the linkage assembles.

    From the closed form (r - s)^2 <= |A O_B|^2 = p^2 + q^2 - 2 p q cos(theta) <= (r + s)^2;
    each interval ends at two limit (toggle) positions.  An interval through 0 deg is one
    interval (lo < 0 < hi), not two; a Grashof double-rocker gives two, mirror images about
    the ground line (separate motions: one cannot reach the other without taking the linkage
    apart).

    Parameters
    ----------
    p, q, r, s : float
        Link lengths: ground (fixed link), crank, coupler, rocker, in one length unit.

    Returns
    -------
    list of tuple of float, or None
        The intervals ``(lo, hi)`` of crank angle, deg; None when the crank turns fully,
        ``[]`` when the linkage cannot be assembled at all.

    Examples
    --------
    >>> from driver.fourbar import assembly_intervals
    >>> assembly_intervals(12, 5, 15, 9) is None          # a crank-rocker: the crank turns
    True
    >>> [(round(lo, 4), round(hi, 4)) for lo, hi in assembly_intervals(10, 8, 3, 6)]  # a double-rocker
    [(14.3615, 58.7516), (301.2484, 345.6385)]
    """
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
    """One motion of a linkage whose crank cannot turn fully.

    The crank swings from ``lo`` to ``hi`` on the deck's assembly branch, reverses at the limit
    position and swings back on the other branch (at a limit the two branches meet: B lies on
    the line A-O_B).

    Attributes
    ----------
    lo, hi : float
        The limit crank angles of the swing, deg.
    theta : numpy.ndarray
        The crank angles in the order they are passed, deg.
    out : numpy.ndarray
        The kernel's states there, (n, 11) (columns of ``driver.fourbar._kernel.fourbar_exact``:
        angles in rad, positions in the deck's length unit, rad/s, rad/s^2).
    status : numpy.ndarray
        The kernel's status per sample (0 ok).
    branch : numpy.ndarray
        +1 (open) or -1 (crossed) per sample.
    stroke : numpy.ndarray
        0 for the forward swing, 1 for the return, per sample.
    """

    lo: float
    hi: float
    theta: np.ndarray
    out: np.ndarray
    status: np.ndarray
    branch: np.ndarray
    stroke: np.ndarray


def rocking_motions(p: Params, n_stroke: int = 181) -> list[Motion] | None:
    """Trace the to-and-fro motions of a linkage whose crank cannot turn fully.

    Per assembly interval (:func:`assembly_intervals`), ``n_stroke`` samples forward on the
    deck's branch and ``n_stroke`` back on the other, the ends a hair inside the limit angles
    (at the limit itself round-off may put A a ulp beyond reach).  Positions only: the
    kernel's velocities assume the deck's constant crank speed (reversed on the return).

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys (lengths, ``branch``, ``omega`` in rad/s).
    n_stroke : int, default 181
        Samples per swing, cosine-spaced (dense at the limits).

    Returns
    -------
    list of Motion, or None
        One motion per assembly interval; None when the crank turns fully.
    """
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
        o1, s1 = kernel.fourbar_exact(np.radians(fwd), p.fixed_link, p.crank, p.coupler, p.rocker,
                                      p.omega, p.alpha, first)
        o2, s2 = kernel.fourbar_exact(np.radians(fwd[::-1]), p.fixed_link, p.crank, p.coupler, p.rocker,
                                      -p.omega, p.alpha, -first)
        motions.append(Motion(lo, hi, np.concatenate([fwd, fwd[::-1]]), np.vstack([o1, o2]),
                              np.concatenate([s1, s2]),
                              np.repeat([first, -first], n_stroke), np.repeat([0, 1], n_stroke)))
    return motions


def crank_angles(p: Params) -> np.ndarray:
    """Return the deck's crank angles (Fortran DO semantics: start, start + step, ... <= stop).

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys (``start_deg``, ``step_deg``, ``stop_deg``, deg).

    Returns
    -------
    numpy.ndarray
        The crank angles, deg.
    """
    n = int(math.floor((p.stop_deg - p.start_deg) / p.step_deg + 1e-9)) + 1
    return p.start_deg + p.step_deg * np.arange(n)


def exact_grid(p: Params, theta_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Solve the closed loop at the given crank angles on the deck's branch.

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys (lengths, ``omega`` rad/s, ``alpha`` rad/s^2, ``branch``).
    theta_deg : numpy.ndarray
        Crank angles, deg.

    Returns
    -------
    states : numpy.ndarray
        (n, 11): coupler, rocker and transmission angle [rad]; xa, ya, xb, yb [length];
        coupler and rocker angular velocity [rad/s] and acceleration [rad/s^2]
        (``driver.fourbar._kernel.fourbar_exact``).
    status : numpy.ndarray
        (n,): 0 ok, 1 cannot be assembled, 2 toggle, 3 indeterminate.
    """
    return kernel.fourbar_exact(np.radians(theta_deg), p.fixed_link, p.crank, p.coupler, p.rocker,
                                 p.omega, p.alpha, 1 if p.branch == "open" else -1)


def coupler_point(p: Params, theta_deg: np.ndarray, out: np.ndarray, status: np.ndarray) -> np.ndarray | None:
    """Compute position, velocity and acceleration of the deck's coupler point.

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys (``coupler_point`` u, v in the length unit).
    theta_deg : numpy.ndarray
        Crank angles, deg.
    out, status : numpy.ndarray
        The states at ``theta_deg`` (:func:`exact_grid`).

    Returns
    -------
    numpy.ndarray or None
        (n, 6): x, y [length], vx, vy [length/s], ax, ay [length/s^2]; None when the deck
        has no coupler point.
    """
    if not p.coupler_point:
        return None
    u, v = p.coupler_point
    return kernel.fourbar_coupler_point(np.radians(theta_deg), out, status, p.crank, p.omega, p.alpha, u, v)


def listing_grid(p: Params) -> tuple[np.ndarray, np.ndarray]:
    """Run the published program (Lampiran 1) for the deck's crank angles.

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys.

    Returns
    -------
    table : numpy.ndarray
        (n, 10), single precision as printed: crank angle, epsl, phi, beta [whole deg,
        truncated]; xa, ya, xb, yb [length]; omr, oms [rad/s].
    status : numpy.ndarray
        (n,): 0 ok, 1 not assemblable, 2 velocities divide by zero.
    """
    start, step = int(p.start_deg), int(p.step_deg)
    n = len(crank_angles(p))
    return kernel.fourbar_listing(p.fixed_link, p.crank, p.coupler, p.rocker, p.omega, start, step, n)


def deg360(rad: np.ndarray) -> np.ndarray:
    """Radians -> degrees in [0, 360), with values that round to 360.0 folded to 0."""
    d = np.mod(np.degrees(rad), 360.0)
    return np.where(d >= 359.95, d - 360.0, d)


# ----------------------------------------------------------------------------- the summary kernel

#: the summary kernel's parameters, in its column order (fortran/fourbar_summary.f90): deck keys
SUMMARY_KEYS = tuple(c.name.lower() for c in SummaryParam)


#: the kernel's pass bits (fortran/fourbar_summary.f90 pass_*)
PASS_BITS = {"transmission": kernel.FOURBAR_PASSES["transmission"], "rocker": kernel.FOURBAR_PASSES["rocker"],
             "peaks": kernel.FOURBAR_PASSES["peaks"]}


def param_matrix(base: Mapping[str, Any], columns: Mapping[str, Any], n: int) -> np.ndarray:
    """The summary kernel's (n, 8) parameter matrix (:data:`SUMMARY_KEYS`): base values, overridden column by
    column; a bad value raises DeckError at its deck line (``base`` a deck's Params) or ValueError."""
    cols = {}
    for key in SUMMARY_KEYS:
        v = columns.get(key, base[key])
        if key == "branch":
            v = np.asarray(v)
            if v.dtype.kind in "US":
                bad = ~np.isin(v, ("open", "crossed"))
                if bad.any():
                    raise batch_error(base, "branch", f"must be 'open' or 'crossed' (got {v[np.argmax(bad)]!r})")
                v = np.where(v == "open", 1.0, -1.0)
        v = np.broadcast_to(np.asarray(v, dtype=np.float64), (n,))
        bad = ~np.isfinite(v)
        if key in ("fixed_link", "crank", "coupler", "rocker"):
            bad |= ~(v > 0)
        if bad.any():
            i = int(np.argmax(bad))
            raise batch_error(base, key, f"design {i} has {float(v[i])!r} (lengths must be positive, all values finite)")
        cols[key] = v
    m = np.empty((n, len(SummaryParam)), dtype=np.float64, order="F")
    for j, key in enumerate(SUMMARY_KEYS):
        m[:, j] = cols[key]
    return m


def summary_rows(p: Params) -> np.ndarray:
    """The summary kernel's row of one deck, every pass: (1, 19) (fortran/fourbar_summary.f90)."""
    return kernel.fourbar_summaries(param_matrix(p, {}, 1), sum(PASS_BITS.values()))


@dataclass
class Extremes:
    """Headline figures over the analysed crank range (exact solution), from the batch kernel.

    Attributes
    ----------
    mu_min, mu_max : float
        Smallest and largest transmission angle, deg.
    mu_min_at, mu_max_at : float
        Crank angles where they occur, deg.
    rocker_min, rocker_max : float
        Extreme rocker angles, deg.
    rocker_min_at, rocker_max_at : float
        Crank angles where they occur, deg.
    rocker_omega_peak, coupler_omega_peak : float
        Peak rocker and coupler angular velocity (signed), rad/s.
    rocker_omega_peak_at, coupler_omega_peak_at : float
        Crank angles where they occur, deg.
    assembled_fraction : float
        Fraction of the range where the linkage assembles, dimensionless.
    rocker_turns : bool
        The rocker turns fully (a double crank).
    toggles : tuple of float
        Limit (toggle) crank angles inside the range, deg.
    rocker_swing : float
        Rocker swing angle, deg.
    """

    mu_min: float
    mu_min_at: float
    mu_max: float
    mu_max_at: float
    rocker_min: float
    rocker_min_at: float
    rocker_max: float
    rocker_max_at: float
    rocker_omega_peak: float
    rocker_omega_peak_at: float
    coupler_omega_peak: float
    coupler_omega_peak_at: float
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


def extremes(p: Params, row: np.ndarray | None = None) -> Extremes | None:
    """Find the transmission-angle, rocker-position and speed extremes over the deck's crank range.

    One row of the batch kernel (fortran/fourbar_summary.f90, see :func:`summarise_batch`),
    so a single run and a sweep report the same figures: transmission-angle and rocker
    extremes in closed form, peak speeds from a 6 deg scan (refined to 1 deg where an extremum
    may hide) and Newton roots of the angular acceleration.

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys.
    row : numpy.ndarray, optional
        The deck's row of the summary kernel when the caller has it
        (:func:`summary_rows`); computed otherwise.

    Returns
    -------
    Extremes or None
        The extremes (deg, rad/s); None when the linkage cannot be assembled anywhere in
        the range.
    """
    lo, hi = sorted((p.start_deg, p.stop_deg))
    if row is None:
        row = summary_rows(p)[0]
    if not row[Summary.ASSEMBLABLE]:
        return None
    toggles = toggles_in_range(p.fixed_link, p.crank, p.coupler, p.rocker, lo, hi)
    c = Summary
    return Extremes(row[c.MU_MIN_DEG], row[c.MU_MIN_AT_DEG], row[c.MU_MAX_DEG], row[c.MU_MAX_AT_DEG],
                    row[c.ROCKER_MIN_DEG], row[c.ROCKER_MIN_AT_DEG], row[c.ROCKER_MAX_DEG], row[c.ROCKER_MAX_AT_DEG],
                    row[c.ROCKER_OMEGA_PEAK_RAD_S], row[c.ROCKER_OMEGA_PEAK_AT_DEG], row[c.COUPLER_OMEGA_PEAK_RAD_S],
                    row[c.COUPLER_OMEGA_PEAK_AT_DEG], row[c.ASSEMBLED_FRACTION], bool(row[c.ROCKER_TURNS]), toggles,
                    row[c.ROCKER_SWING_DEG])


#: units of the tidy columns whose names do not say them ('length': the deck's length unit)
TIDY_UNITS = {"xa": "length", "ya": "length", "xb": "length", "yb": "length", "xp": "length", "yp": "length",
              "ab_error": "length"}


def tidy_frame(method: str, theta: np.ndarray, cols: dict[str, np.ndarray], status: np.ndarray,
               not_closed: np.ndarray | None = None, chain: str | None = None) -> pd.DataFrame:
    """Build the tidy table of a run: one row per crank angle.

    Parameters
    ----------
    method : str
        ``'exact'`` or ``'listing'`` (the ``method`` column).
    theta : numpy.ndarray
        Crank angles, deg (the ``theta_deg`` column).
    cols : dict of str to numpy.ndarray
        Further columns, units in their names or in ``TIDY_UNITS`` (positions: length).
    status : numpy.ndarray
        Kernel status per row (0 ok, 1 cannot assemble, 2 toggle, 3 indeterminate).
    not_closed : numpy.ndarray, optional
        True for a listing row whose |AB| is not the coupler length (``loop_not_closed``).
    chain : str, optional
        The status word of the rows without a position of a chain that cannot move
        (``'impossible_chain'``, ``'flat_chain'``) instead of ``'cannot_assemble'``.

    Returns
    -------
    pandas.DataFrame
        The table, status in words; unassemblable cells left empty (NaN); units in
        ``attrs["units"]``.
    """
    return Tidy(tidy_part(method, theta, cols, status, not_closed, chain), units=TIDY_UNITS).frame()


def tidy_part(method: str, theta: np.ndarray, cols: dict[str, np.ndarray], status: np.ndarray,
              not_closed: np.ndarray | None = None, chain: str | None = None) -> dict[str, Any]:
    """The columns of :func:`tidy_frame` (numpy arrays, no pandas): a part of a run's
    :class:`driver._result.Tidy`."""
    words = np.array(["ok", chain or "cannot_assemble", "toggle", "indeterminate", "loop_not_closed"])[
        np.where(not_closed, 4, status) if not_closed is not None else status]
    return {"method": method, "theta_deg": theta, **cols, "status": words}


def exact_columns(out: np.ndarray, status: np.ndarray, cp: np.ndarray | None = None,
                   coupler: float | None = None) -> dict[str, np.ndarray]:
    s = State
    vals = {"coupler_deg": deg360(out[:, s.COUPLER_ANGLE]), "rocker_deg": deg360(out[:, s.ROCKER_ANGLE]),
            "transmission_deg": np.degrees(out[:, s.TRANSMISSION_ANGLE]), "xa": out[:, s.XA], "ya": out[:, s.YA],
            "xb": out[:, s.XB], "yb": out[:, s.YB], "coupler_omega_rad_s": out[:, s.COUPLER_OMEGA],
            "rocker_omega_rad_s": out[:, s.ROCKER_OMEGA], "coupler_alpha_rad_s2": out[:, s.COUPLER_ALPHA],
            "rocker_alpha_rad_s2": out[:, s.ROCKER_ALPHA]}
    if coupler is not None:   # loop closure of the solution: |AB| - coupler (round-off only)
        vals["ab_error"] = np.hypot(out[:, s.XB] - out[:, s.XA], out[:, s.YB] - out[:, s.YA]) - coupler
    if cp is not None:
        vals.update({"xp": cp[:, Point.X], "yp": cp[:, Point.Y], "vxp_per_s": cp[:, Point.VX],
                     "vyp_per_s": cp[:, Point.VY], "axp_per_s2": cp[:, Point.AX], "ayp_per_s2": cp[:, Point.AY]})
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


def blame(params: Params, exc: BaseException) -> tuple[str, str] | None:
    """The key and words for a numerical failure of a run (driver._runner.numerical_error)."""
    p = params
    g = grashof(p.fixed_link, p.crank, p.coupler, p.rocker)
    if p.method == "listing" and g.name.startswith("change-point"):
        return ("method", f"the listing's formulas divide 0 by 0 for this change-point linkage ({g.condition}) "
                          "where it folds flat, so its table has no finite value there; use method = 'exact' "
                          "(the closed-loop solution names both branches at the fold)")
    return None
