"""Four-bar synthesis: a ``&synthesis`` deck designs a linkage, the exact kernel checks it.

    &synthesis
      task = 'function'                    ! Freudenstein function generation
      function = 'log10(x)', x_start = 1, x_stop = 2     ! or x_values = ..., y_values = ...
      crank_start_deg = 45, crank_range_deg = 60, rocker_start_deg = 135, rocker_range_deg = 60
      points = 3                           ! 3: closed form at Chebyshev points; more: least squares
      fixed_link = 1.0, omega = 1.0, step_deg = 5, branch = 'open'
    /

    &synthesis
      task = 'crank_rocker', swing_deg = 60, time_ratio = 1.2, fixed_link = 10
    /

Outputs for ``<stem>.dat``: ``<stem>.out`` (the synthesis and its check by the exact kernel),
``<stem>.linkage.dat`` (the linkage as a complete &fourbar deck) and everything a run of that
deck writes (``<stem>.linkage.out``, tidy tables, with ``--plot`` the linkage figure), and
``<stem>_error.csv`` (function generation: the structural error curve) or ``<stem>_family.csv``
(crank-rocker: the family searched).  A synthesis whose linkage the kernel rejects (wrong
branch, cannot be assembled over the range, not a crank-rocker) is reported and exits 1.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import f90nml
import numpy as np
import pandas as pd

from driver import _blas as blas
from driver import _expr as expr
from driver import fourbar
from driver._atomic import output_set, write_text
from driver._deck import Deck, DeckError, GroupSpec, Key, Params, RawGroup, positive, validate
from driver._export import write_tidy
from driver._outcome import SynthesisOutcome
from driver._pydeck import DeckSource, source_deck
from driver._result import Figure
from driver._runner import compute, output_stem, write_outputs
from driver.fourbar import _kernel as fourbar_kernel
from driver.synthesis import _budget
from driver.synthesis import _crank_rocker as cr
from driver.synthesis._function import FunctionDesign, chebyshev, freudenstein, links_from_k, wrap180

__all__ = ["SPEC", "Synthesis", "SynthesisOutcome", "synthesise", "synthesis_figures", "run_synthesis_deck"]

ST = fourbar_kernel.FOURBAR_STATUS


def _check(p: Params) -> None:
    if p.task == "function":
        if (p.function is None) == (p.x_values is None):
            raise p.error("function", "function generation needs function = 'expression in x' or "
                                      "x_values/y_values, not both")
        if p.x_values is not None:
            if p.y_values is None or len(p.y_values) != len(p.x_values):
                raise p.error("y_values", "needs one y for every x in x_values")
            if len(p.x_values) < 3:
                raise p.error("x_values", f"at least 3 precision points (got {len(p.x_values)})")
            if len(set(p.x_values)) != len(p.x_values):
                raise p.error("x_values", "precision points repeat an x")
        else:
            for key in ("x_start", "x_stop"):
                if p[key] is None:
                    raise p.error(key, "needed with function")
            if p.x_start == p.x_stop:
                raise p.error("x_stop", "must differ from x_start")
        for key in ("crank_range_deg", "rocker_range_deg"):
            if p[key] is None:
                raise p.error(key, "needed for function generation")
            if not 0 < abs(p[key]) < 360:
                raise p.error(key, "must be between 0 and 360 deg in size")
    elif p.task == "path":
        if p.target_x is None or p.target_y is None or len(p.target_x) != len(p.target_y):
            raise p.error("target_y" if p.target_x is not None else "target_x",
                          "path generation needs target_x and target_y of equal length")
        if len(p.target_x) < 2:
            raise p.error("target_x", "at least two target points")
        if len(p.target_x) > 100:
            raise p.error("target_x", "at most 100 target points")
        if p.timing_deg is not None and len(p.timing_deg) != len(p.target_x):
            raise p.error("timing_deg", f"needs one crank angle per target ({len(p.target_x)})")
        if not 0 <= p.transmission_min_deg < p.transmission_max_deg <= 180:
            raise p.error("transmission_max_deg", "the band needs 0 <= min < max <= 180")
    else:
        for key in ("swing_deg", "time_ratio"):
            if p[key] is None:
                raise p.error(key, "needed for task = 'crank_rocker'")
        if not 0 < p.swing_deg < 180:
            raise p.error("swing_deg", "must be between 0 and 180 deg")
        if not 1 <= p.time_ratio <= 10:
            raise p.error("time_ratio", "must be between 1 and 10")


def _between(lo: float, hi: float):
    return lambda v: None if lo <= v <= hi else f"must be between {lo:g} and {hi:g} (got {v})"


SPEC = GroupSpec(
    name="synthesis",
    doc="four-bar synthesis: function generation (Freudenstein) or a crank-rocker for a swing and time ratio",
    keys={
        "task": Key("str", required=True, choices=("function", "crank_rocker", "path"),
                    doc="'function': rocker angle follows y(x); 'crank_rocker': given swing and time ratio; "
                        "'path': coupler point through or near target points"),
        "fixed_link": Key("float", default=1.0, check=positive, units="length", doc="ground link (sets the scale)"),
        "omega": Key("float", default=1.0, units="rad/s", doc="crank speed of the linkage deck"),
        "step_deg": Key("float", default=5.0, check=positive, units="deg", doc="crank step of the linkage deck"),
        "branch": Key("str", default="open", choices=("open", "crossed"), doc="assembly branch to design for"),
        "title": Key("str", default="", doc="free text"),
        "function": Key("str", doc="y(x) in the deck expression language, e.g. 'log10(x)' or 'x**2'"),
        "x_start": Key("float", doc="first x of the range"),
        "x_stop": Key("float", doc="last x of the range"),
        "x_values": Key("floats", doc="precision points x (instead of function)"),
        "y_values": Key("floats", doc="y at the precision points"),
        "crank_start_deg": Key("float", default=0.0, units="deg", doc="crank angle at x_start"),
        "crank_range_deg": Key("float", units="deg", doc="crank rotation from x_start to x_stop"),
        "rocker_start_deg": Key("float", default=90.0, units="deg", doc="rocker angle at y(x_start)"),
        "rocker_range_deg": Key("float", units="deg", doc="rocker rotation from y(x_start) to y(x_stop)"),
        "points": Key("int", default=3, check=_between(3, 10000),
                      doc="precision points at Chebyshev spacing: 3 closed form, more least squares"),
        "error_points": Key("int", default=201, check=_between(11, 100000), doc="samples of the structural error"),
        "swing_deg": Key("float", units="deg", doc="crank-rocker: rocker swing"),
        "time_ratio": Key("float", doc="crank-rocker: slow stroke / fast stroke crank angle (>= 1)"),
        "family_points": Key("int", default=721, check=_between(11, 100000),
                             doc="crank-rocker: members scanned per arc of the family"),
        "target_x": Key("floats", units="length", doc="path: x of the target points (world frame)"),
        "target_y": Key("floats", units="length", doc="path: y of the target points"),
        "timing_deg": Key("floats", units="deg",
                          doc="path: prescribed crank angles of the targets, relative to the first (0, ...)"),
        "full_rotation": Key("bool", default=True, doc="path: the crank must turn fully (Grashof, crank shortest)"),
        "transmission_min_deg": Key("float", default=30.0, units="deg", doc="path: least transmission angle"),
        "transmission_max_deg": Key("float", default=150.0, units="deg", doc="path: largest transmission angle"),
        "length_min": Key("float", check=positive, units="length",
                          doc="path: shortest link (default: a tenth of the targets' extent)"),
        "length_max": Key("float", check=positive, units="length",
                          doc="path: longest link and pivot offset (default: 4 x the targets' extent)"),
        "samples": Key("int", default=360, check=_between(36, 100000), doc="path: crank positions per turn"),
        "seed": Key("int", default=1, doc="path: seed of differential evolution (runs are deterministic)"),
        "maxiter": Key("int", default=1000, check=_between(1, 100000), doc="path: generations"),
        "popsize": Key("int", default=15, check=_between(2, 1000), doc="path: population per variable"),
        "tolerance": Key("float", default=1e-3, check=positive, units="length",
                         doc="path: largest target error accepted as 'through the points'"),
        "min_link_fraction": Key("float", default=0.05, check=_between(0.0, 1.0),
                                 doc="a link shorter than this fraction of the ground is named a poor design "
                                     "(crank-rocker: the member returned has every link at least this long)"),
        "poor_transmission_deg": Key("float", default=30.0, check=_between(0.0, 90.0), units="deg",
                                     doc="a design whose worse transmission angle, min(mu_min, 180 - mu_max), "
                                         "is below this is named a poor design"),
    },
    check=_check,
)


@dataclass
class Synthesis:
    """A synthesis result: the linkage deck, the study run of it, and the report.

    Attributes
    ----------
    params : Params
        The validated ``&synthesis`` group.
    linkage : dict or None
        The linkage's ``&fourbar`` deck values (lengths in the deck's length unit, angles in
        deg); None when no linkage was found.
    text : str
        The report (``<stem>.out``).
    failure : str or None
        Why the design failed its check by the exact kernel; None on success.
    table : pandas.DataFrame
        The task's table (structural error, family or targets).
    table_name : str
        Its file suffix (``'_error'``, ``'_family'``, ``'_targets'``).
    study_result : Result or None
        The four-bar study's run of the linkage.
    design : object
        The task's design object (function, family member or path design).
    checks : dict of str to float
        The checks of the design, units in the names where they have one (``swing_deg``,
        ``mu_min_deg``; ``time_ratio`` dimensionless; a path's ``rms`` and ``max_error`` in the
        length unit of the targets, a function's ``max_error_y`` in the units of y).
    warnings : list of str
        A degenerate or poor design, in words.
    """

    params: Params
    linkage: dict[str, Any] | None   # the linkage deck's values; None when no linkage was found
    text: str
    failure: str | None
    table: pd.DataFrame
    table_name: str
    study_result: Any = None
    design: Any = None
    checks: dict[str, float] = field(default_factory=dict)
    #: degenerate or poor design, in words (also in the .out and the --json record)
    warnings: list[str] = field(default_factory=list)


def _quality_warnings(p: Params, ground: float, links: dict[str, float], mu_min: float | None,
                      mu_max: float | None) -> list[str]:
    """A link shorter than min_link_fraction of the ground; a transmission angle poorer than
    poor_transmission_deg (min(mu_min, 180 - mu_max))."""
    out = []
    short = [f"{k} {v:.6g}" for k, v in links.items() if v < p.min_link_fraction * ground]
    if short:
        out.append(f"poor design: {', '.join(short)} shorter than {p.min_link_fraction:g} x the ground "
                   f"({ground:.6g}) (min_link_fraction)")
    if mu_min is not None and mu_max is not None and math.isfinite(mu_min) and math.isfinite(mu_max):
        q = min(mu_min, 180.0 - mu_max)
        if q < p.poor_transmission_deg:
            out.append(f"poor design: transmission angle {mu_min:.4f} .. {mu_max:.4f} deg, "
                       f"min(mu_min, 180 - mu_max) = {q:.4f} deg < {p.poor_transmission_deg:g} deg "
                       "(poor_transmission_deg): the coupler pushes the rocker nearly along it")
    return out


# ----------------------------------------------------------------------------- function generation

def _y_of(p: Params, x: np.ndarray) -> np.ndarray:
    try:
        e = expr.parse(p.function, ["x"])
    except expr.ExprError as exc:
        raise p.error("function", str(exc)) from None
    with np.errstate(all="ignore"):
        y = np.asarray(e.evaluate({"x": np.asarray(x, dtype=float)}), dtype=float)
    return y


def _distinct_angles(p: Params, th2: np.ndarray, th4: np.ndarray) -> None:
    """Deck error when two precision points share a crank angle or a rocker angle (their
    Freudenstein equations coincide: no unique linkage), naming the key that makes them so."""
    def gap(a: np.ndarray) -> float:
        a = np.sort(np.asarray(a, dtype=float))
        return float(np.min(np.diff(a))) if a.size > 1 else math.inf
    if not gap(th2) > 1e-9:
        raise p.error("crank_range_deg", f"the precision points' crank angles coincide (range "
                      f"{p.crank_range_deg:g} deg): no unique linkage; give a crank range of a few degrees at least")
    if not gap(th4) > 1e-9:
        key = "function" if p.function else ("y_values" if p.x_values is not None else "rocker_range_deg")
        if not abs(p.rocker_range_deg) > 1e-9:
            key = "rocker_range_deg"
        raise p.error(key, "two precision points have the same rocker angle (y(x) is flat between them, or the "
                      "rocker range is nil): no unique linkage through them")


def _synthesise_function(p: Params) -> Synthesis:
    d = p.fixed_link
    if p.x_values is not None:
        xs, ys = np.array(p.x_values, float), np.array(p.y_values, float)
        order = np.argsort(xs)
        xs, ys = xs[order], ys[order]
        x0, xf = (p.x_start, p.x_stop) if p.x_start is not None and p.x_stop is not None else (xs[0], xs[-1])
        y_end = np.interp([x0, xf], xs, ys)
        curve = lambda x: np.interp(x, xs, ys)
        how = f"{len(xs)} given precision points"
    else:
        x0, xf = p.x_start, p.x_stop
        xs = chebyshev(x0, xf, p.points)
        ys = _y_of(p, xs)
        y_end = _y_of(p, np.array([x0, xf]))
        curve = lambda x: _y_of(p, x)
        how = f"{p.points} precision points at Chebyshev spacing"
    if not np.all(np.isfinite(ys)) or not np.all(np.isfinite(y_end)):
        raise p.error("function", "y(x) is not finite at every precision point and range end")
    y0, yf = float(y_end[0]), float(y_end[1])
    if y0 == yf:
        raise p.error("function", "y(x_start) = y(x_stop): the rocker range cannot be mapped")
    phi = lambda x: p.crank_start_deg + (np.asarray(x) - x0) / (xf - x0) * p.crank_range_deg
    psi = lambda y: p.rocker_start_deg + (np.asarray(y) - y0) / (yf - y0) * p.rocker_range_deg
    th2, th4 = np.radians(phi(xs)), np.radians(psi(ys))
    _distinct_angles(p, th2, th4)
    try:
        k, cond = freudenstein(th2, th4)
    except np.linalg.LinAlgError:
        cond = math.inf
    if not (math.isfinite(cond) and cond < 1e12):   # a degenerate set of precision points: bad input
        raise p.error("crank_range_deg", f"the precision points give a singular Freudenstein system (condition "
                      f"number {cond:.3g}); spread the crank and rocker angles apart")
    a, b, c, reason = links_from_k(k, d)
    fd = FunctionDesign(xs, ys, phi(xs), psi(ys), k, cond, abs(a), b, abs(c),
                        p.crank_start_deg + (180.0 if a < 0 else 0.0), p.rocker_start_deg + (180.0 if c < 0 else 0.0),
                        (bool(a < 0), bool(c < 0)), reason)
    lines = [f"  four-bar synthesis: function generation (Freudenstein), {how}",
             f"  deck: {p.path}" + (f" -- {p.title}" if p.title else ""), "",
             f"    y(x) ................. {p.function if p.function else 'given points (linear between them)'}",
             f"    x range .............. {x0:.10g} .. {xf:.10g}   y range {y0:.10g} .. {yf:.10g}",
             f"    crank ................ {p.crank_start_deg:g} deg + {p.crank_range_deg:g} deg over the x range",
             f"    rocker ............... {p.rocker_start_deg:g} deg + {p.rocker_range_deg:g} deg over the y range",
             f"    branch ............... {p.branch}", "",
             "  Precision points",
             "         x                  y          crank [deg]     rocker [deg]"]
    lines += [f"  {x:12.6f}  {y:17.10g}  {t2:15.6f}  {t4:15.6f}" for x, y, t2, t4 in zip(xs, ys, phi(xs), psi(ys))]
    lines += ["", f"  Freudenstein K1 = {k[0]:.10g}, K2 = {k[1]:.10g}, K3 = {k[2]:.10g} "
                  f"({'exact solve' if len(xs) == 3 else 'least squares'}, condition number {cond:.3g})"]
    linkage = None
    failure = None
    table = pd.DataFrame()
    warnings: list[str] = []
    if reason:
        failure = f"no four-bar satisfies these precision points: {reason}"
        lines += [f"  {failure}"]
    else:
        if fd.shifted[0] or fd.shifted[1]:
            lines += ["  signed solution " + f"a = {a:.10g}, c = {c:.10g}: " +
                      " and ".join(w for w, s in zip(("the crank", "the rocker"), fd.shifted) if s) +
                      " point the other way (angles + 180 deg)"]
        lines += [f"  linkage: ground {d:.10g}, crank {fd.crank:.10g}, coupler {fd.coupler:.10g}, rocker {fd.rocker:.10g}"]
        # the exact kernel on the requested branch over the x range, and at the precision points on both branches
        sgn = 1 if p.branch == "open" else -1
        x = np.linspace(x0, xf, p.error_points)
        crank_deg = fd.crank_start_deg + (x - x0) / (xf - x0) * p.crank_range_deg
        out, st = fourbar_kernel.fourbar_exact(np.radians(crank_deg), d, fd.crank, fd.coupler, fd.rocker, 1.0, 0.0, sgn)
        desired_psi = fd.rocker_start_deg + (curve(x) - y0) / (yf - y0) * p.rocker_range_deg
        err = wrap180(np.degrees(out[:, fourbar_kernel.State.ROCKER_ANGLE]) - desired_psi)
        err = np.where(st == ST["ok"], err, np.nan)
        y_gen = curve(x) + err / p.rocker_range_deg * (yf - y0)
        fd.x, fd.y_desired, fd.y_generated, fd.rocker_error_deg, fd.status = x, curve(x), y_gen, err, st
        pc = fd.crank_start_deg + (xs - x0) / (xf - x0) * p.crank_range_deg
        pr = fd.rocker_start_deg + (ys - y0) / (yf - y0) * p.rocker_range_deg
        for s, attr in ((sgn, "point_error_deg"), (-sgn, "other_branch_point_error_deg")):
            o2, s2 = fourbar_kernel.fourbar_exact(np.radians(pc), d, fd.crank, fd.coupler, fd.rocker, 1.0, 0.0, s)
            psi2 = np.degrees(o2[:, fourbar_kernel.State.ROCKER_ANGLE])
            setattr(fd, attr, np.where(s2 == ST["ok"], wrap180(psi2 - pr), np.nan))
        worst = int(np.nanargmax(np.abs(err))) if np.isfinite(err).any() else 0
        tol_deg = 1e-6 if len(xs) == 3 else math.inf
        bad = np.flatnonzero(st != ST["ok"])
        lines += ["", f"  Check by the exact kernel ({p.branch} branch, {p.error_points} points over the x range)"]
        lines += ["    precision point   rocker error, this branch [deg]   other branch [deg]"]
        lines += [f"    {xx:15.6f}   {e1:31.3e}   {e2:18.3e}".replace("nan", "  -")
                  for xx, e1, e2 in zip(xs, fd.point_error_deg, fd.other_branch_point_error_deg)]
        chain = fourbar.grashof(d, fd.crank, fd.coupler, fd.rocker)
        lines += [f"    class of the linkage:  {chain.name} ({chain.condition}); the crank "
                  + ("turns fully" if chain.full_crank_rotation else "does not turn fully")]
        if not chain.movable:   # Freudenstein's K solve gives lengths, not a chain that closes
            failure = f"the linkage cannot move ({chain.name}): {chain.reason}"
        elif len(bad):
            failure = (f"the linkage cannot run the x range on the {p.branch} branch: "
                       f"{len(bad)} of {len(x)} points cannot be assembled or are at a toggle "
                       f"(first at x = {x[bad[0]]:.6g})")
        elif len(xs) == 3 and not np.all(np.abs(fd.point_error_deg) < tol_deg):
            other_ok = np.all(np.abs(fd.other_branch_point_error_deg) < tol_deg)
            failure = ("the precision points are met on the other assembly branch: set branch = '"
                       + ("crossed" if p.branch == "open" else "open") + "'") if other_ok else \
                      "the precision points lie on different assembly branches (branch defect)"
        if failure is None:
            lines += [f"    structural error: max |y_generated - y(x)| = {fd.max_error_y:.6e} at x = {x[worst]:.6g}"
                      f"  (rocker {err[worst]:+.6f} deg); every point of the range assembled, no toggle"]
        else:
            lines += [f"    FAILED: {failure}"]
        linkage = {"fixed_link": d, "crank": fd.crank, "coupler": fd.coupler, "rocker": fd.rocker,
                   "omega": p.omega, "step_deg": p.step_deg, "start_deg": float(fd.crank_start_deg),
                   "stop_deg": float(fd.crank_start_deg + p.crank_range_deg), "branch": p.branch}
        if p.crank_range_deg < 0:
            linkage["step_deg"] = -p.step_deg
        table = pd.DataFrame({"x": x, "crank_deg": crank_deg, "y_desired": fd.y_desired, "y_generated": y_gen,
                              "structural_error": y_gen - fd.y_desired, "rocker_error_deg": err,
                              "status": np.array(["ok", "cannot_assemble", "toggle", "indeterminate"])[st]})
        good = st == ST["ok"]
        mu = np.degrees(out[good, fourbar_kernel.State.TRANSMISSION_ANGLE]) if good.any() else np.array([])
        warnings = _quality_warnings(p, d, {"crank": fd.crank, "coupler": fd.coupler, "rocker": fd.rocker},
                                     float(mu.min()) if mu.size else None, float(mu.max()) if mu.size else None)
        lines += [f"  WARNING: {w} (over the x range)" if "transmission" in w else f"  WARNING: {w}" for w in warnings]
    return Synthesis(p, linkage, "\n".join(lines), failure, table, "_error", design=fd,
                     checks={"max_error_y": fd.max_error_y}, warnings=warnings)


# ----------------------------------------------------------------------------- crank-rocker

def _synthesise_crank_rocker(p: Params) -> Synthesis:
    members = cr.family(p.swing_deg, p.time_ratio, p.family_points)
    frac = p.min_link_fraction
    usable = lambda m: min(m.crank, m.coupler, m.rocker) >= frac * m.ground
    free = cr.best_member(p.swing_deg, p.time_ratio, members)
    best = cr.best_member(p.swing_deg, p.time_ratio, [m for m in members if usable(m)])
    if best is not None and not usable(best):     # the refinement stepped below the fraction
        best = max((m for m in members if usable(m) and m.crank_rocker and math.isfinite(m.quality_deg)),
                   key=lambda m: (m.quality_deg, -m.arc, -m.t))
    warnings: list[str] = []
    edge = free is not None and _at_family_end(members, free)
    if free is not None and edge:
        limit = 90.0 - p.swing_deg / 2 if cr.alpha_deg(p.time_ratio) <= 1e-12 else free.quality_deg
        how = ("the closed form for time ratio 1: 90 - swing/2" if cr.alpha_deg(p.time_ratio) <= 1e-12
               else "approached at the family's end")
        warnings.append(f"no interior optimum: the transmission quality rises towards the end of the family, "
                        f"where the shortest link ({min(free.crank, free.coupler, free.rocker) / free.ground:.3g} "
                        f"of the ground at the last member scanned) shrinks to nothing; its limit is {limit:.6f} deg "
                        f"({how}).  Returned: the best member whose links are all at least "
                        f"min_link_fraction = {frac:g} of the ground")
    elif free is not None and best is not None and free is not best and not usable(free):
        warnings.append(f"the best member has a link shorter than min_link_fraction = {frac:g} of the ground "
                        f"(quality {free.quality_deg:.6f} deg); returned: the best member whose links reach it")
    al = cr.alpha_deg(p.time_ratio)
    lines = ["  four-bar synthesis: crank-rocker for a rocker swing and a time ratio",
             f"  deck: {p.path}" + (f" -- {p.title}" if p.title else ""), "",
             f"    rocker swing ......... {p.swing_deg:g} deg",
             f"    time ratio ........... {p.time_ratio:g}  (crank turns 180 + {al:.6g} and 180 - {al:.6g} deg)",
             "    family ............... O_A on the "
             + ("line through the rocker extremes" if al <= 1e-12 else
                "circle through the rocker extremes seeing them under alpha")
             + "; "
             f"{len(members)} members scanned ({p.family_points} per arc)",
             f"    crank-rockers ........ {sum(m.crank_rocker for m in members)} of them", ""]
    table = pd.DataFrame([{"arc": m.arc, "t": m.t, "crank": m.crank * p.fixed_link / m.ground,
                           "coupler": m.coupler * p.fixed_link / m.ground, "rocker": m.rocker * p.fixed_link / m.ground,
                           "fixed_link": p.fixed_link, "crank_rocker": m.crank_rocker, "mu_min_deg": m.mu_min_deg,
                           "mu_max_deg": m.mu_max_deg, "quality_deg": m.quality_deg} for m in members])
    failure: str | None
    if best is None:
        failure = ("no member of the family is a crank-rocker" if free is None else
                   f"no crank-rocker member has every link at least min_link_fraction = {frac:g} of the ground")
        return Synthesis(p, None, "\n".join(lines + [f"  {failure}"]), failure, table, "_family", warnings=warnings)
    a, b, c = best.scaled(p.fixed_link)
    lines += ["  Family (every tenth member of each arc; the _family table has all)",
              "     arc        t       crank     coupler      rocker   crank-rocker   mu_min   mu_max   quality"]
    for arc in sorted(set(table["arc"]), reverse=True):
        sub = table[table["arc"] == arc]
        for _, r in sub.iloc[:: max(1, len(sub) // 10)].iterrows():
            mm = lambda v: f"{v:8.3f}" if math.isfinite(v) else "       -"
            lines.append(f"  {int(r.arc):6d}  {r.t:7.4f}  {r.crank:10.5f}  {r.coupler:10.5f}  {r.rocker:10.5f}"
                         f"   {'yes' if r.crank_rocker else 'no':>12} {mm(r.mu_min_deg)} {mm(r.mu_max_deg)}"
                         f" {mm(r.quality_deg)}")
    lines += ["", f"  Best member (arc {best.arc}, t = {best.t:.10f}): min(mu_min, 180 - mu_max) = {best.quality_deg:.6f} deg",
              f"  linkage: ground {p.fixed_link:.10g}, crank {a:.10g}, coupler {b:.10g}, rocker {c:.10g}",
              f"    transmission angle {best.mu_min_deg:.6f} .. {best.mu_max_deg:.6f} deg (closed form)"]
    linkage = {"fixed_link": p.fixed_link, "crank": a, "coupler": b, "rocker": c, "omega": p.omega,
               "step_deg": p.step_deg, "branch": p.branch}
    # check by the exact kernel: swing, time ratio, transmission angle over a full turn
    raw = RawGroup("fourbar", dict(linkage), {}, p.line)
    fp = validate(raw, fourbar.SPEC, p.path)
    ex = fourbar.extremes(fp)
    failure = None
    checks: dict[str, float] = {}
    if ex is None or ex.assembled_fraction < 1.0 or ex.toggles:
        failure = "the exact kernel cannot run the linkage over a full turn"
    else:
        swing = (ex.rocker_max - ex.rocker_min) % 360.0
        turn = (ex.rocker_max_at - ex.rocker_min_at) % 360.0
        q = max(turn, 360 - turn) / min(turn, 360 - turn)
        checks = {"swing_deg": swing, "time_ratio": q, "mu_min_deg": ex.mu_min, "mu_max_deg": ex.mu_max}
        lines += ["", f"  Check by the exact kernel ({p.branch} branch, full turn): swing {swing:.9f} deg "
                      f"(asked {p.swing_deg:g}), time ratio {q:.9f} (asked {p.time_ratio:g}), "
                      f"transmission angle {ex.mu_min:.6f} .. {ex.mu_max:.6f} deg"]
        if abs(swing - p.swing_deg) > 1e-6 or abs(q - p.time_ratio) > 1e-6 * p.time_ratio:
            failure = "the exact kernel does not confirm the swing and time ratio"
            lines += [f"    FAILED: {failure}"]
    warnings += _quality_warnings(p, p.fixed_link, {"crank": a, "coupler": b, "rocker": c},
                                  best.mu_min_deg, best.mu_max_deg)
    lines += [f"  WARNING: {w}" for w in warnings]
    return Synthesis(p, linkage, "\n".join(lines), failure, table, "_family", design=best, checks=checks,
                     warnings=warnings)


def _at_family_end(members: list, m) -> bool:
    """The member lies in the first or last scan interval of its arc (the quality's best is at an end)."""
    same = sorted(x.t for x in members if x.arc == m.arc)
    return bool(same) and (m.t <= same[0] or m.t >= same[-1] or
                           (len(same) > 1 and (m.t < same[1] or m.t > same[-2])))


# ----------------------------------------------------------------------------- path generation

def _synthesise_path(p: Params) -> Synthesis:
    from driver.synthesis import _path as pg
    targets = np.column_stack([p.target_x, p.target_y]).astype(float)
    ext = float(max(np.ptp(targets, axis=0))) or 1.0
    pp = pg.PathProblem(targets, None if p.timing_deg is None else np.array(p.timing_deg, float) - p.timing_deg[0],
                        1 if p.branch == "open" else -1, p.full_rotation,
                        (p.transmission_min_deg, p.transmission_max_deg),
                        p.length_min or 0.1 * ext, p.length_max or 4.0 * ext, p.samples)
    if pp.length_min >= pp.length_max:
        raise p.error("length_max", f"must exceed length_min ({pp.length_min:g})")
    design, converged, message, nfev = pg.solve(pp, p.seed, p.maxiter, p.popsize)
    q = design.parts
    lines = ["  four-bar synthesis: path generation (coupler point through or near target points)",
             f"  deck: {p.path}" + (f" -- {p.title}" if p.title else ""), "",
             f"    targets .............. {len(targets)}" + (" with prescribed crank angles" if pp.timing_deg is not None
                                                            else " (timing free)"),
             f"    branch ............... {p.branch}; full crank rotation {'required' if p.full_rotation else 'not required'}",
             f"    transmission band .... {p.transmission_min_deg:g} .. {p.transmission_max_deg:g} deg",
             f"    link lengths ......... {pp.length_min:.6g} .. {pp.length_max:.6g}",
             f"    search ............... differential evolution (seed {p.seed}, popsize {p.popsize}, maxiter "
             f"{p.maxiter}) then least squares from its best distinct designs: {nfev} designs; evolution "
             f"{'converged' if converged else 'stopped'} ({message})",
             "",
             f"  linkage: ground {q['ground']:.10g}, crank {q['crank']:.10g}, coupler {q['coupler']:.10g}, "
             f"rocker {q['rocker']:.10g}",
             f"    crank pivot O_A = ({q['x0']:.10g}, {q['y0']:.10g}), ground direction {q['gamma_deg']:.10g} deg; "
             f"coupler point u = {q['u']:.10g}, v = {q['v']:.10g}"]
    if pp.timing_deg is not None:
        lines.append(f"    crank angle at the first target {q['theta1_deg'] % 360:.10g} deg (deck frame)")
    lines += ["", "  Targets (world frame) and the coupler point's distance to them, by the exact kernel",
              "         x             y         error   crank angle [deg, deck frame]"]
    lines += [f"  {tx:12.6f}  {ty:12.6f}  {e:12.3e}  {t:10.4f}"
              for (tx, ty), e, t in zip(targets, design.errors, design.theta_at_targets_deg)]
    lines += [f"  RMS error {design.rms:.6e}, largest {design.errors.max():.6e} (tolerance {p.tolerance:g})"]
    failure = None
    if design.violation > 0:
        failure = f"no design met the constraints (violation {design.violation:.3g}): assembly, rotation or band"
    elif design.errors.max() > p.tolerance:
        failure = (f"the coupler point misses a target by {design.errors.max():.4g} > tolerance {p.tolerance:g}: "
                   "the best design found passes near, not through, the points")
    linkage = {"fixed_link": q["ground"], "crank": q["crank"], "coupler": q["coupler"], "rocker": q["rocker"],
               "omega": p.omega, "step_deg": p.step_deg, "branch": p.branch,
               "coupler_point": [q["u"], q["v"]],
               # the band the synthesis asked for: the linkage's summary and figures judge it by it
               "transmission_band_deg": [p.transmission_min_deg, p.transmission_max_deg]}
    # the full turn by the exact kernel: assembly, Grashof class, transmission band
    fp = validate(RawGroup("fourbar", dict(linkage), {}, p.line), fourbar.SPEC, p.path)
    g = fourbar.grashof(fp.fixed_link, fp.crank, fp.coupler, fp.rocker)
    ex = fourbar.extremes(fp)
    if not g.movable:
        lines += [f"  Check over a full turn: {g.name} ({g.condition})"]
        failure = failure or f"the linkage cannot move ({g.name}): {g.reason}"
    if ex is not None:
        lines += [f"  Check over a full turn: {g.name}; assembled {100 * ex.assembled_fraction:.1f} % of the turn; "
                  f"transmission angle {ex.mu_min:.4f} .. {ex.mu_max:.4f} deg"]
        if p.full_rotation and (ex.assembled_fraction < 1.0 or ex.toggles):
            failure = failure or "the exact kernel cannot turn the crank fully"
    if failure:
        lines += [f"    FAILED: {failure}"]
    warnings = _quality_warnings(p, q["ground"], {"crank": q["crank"], "coupler": q["coupler"], "rocker": q["rocker"]},
                                 None if ex is None else ex.mu_min, None if ex is None else ex.mu_max)
    lines += [f"  WARNING: {w}" for w in warnings]
    table = pd.DataFrame({"target_x": targets[:, 0], "target_y": targets[:, 1], "error": design.errors,
                          "crank_deg": design.theta_at_targets_deg})
    return Synthesis(p, linkage, "\n".join(lines), failure, table, "_targets", design=design,
                     checks={"rms": design.rms, "max_error": float(design.errors.max())}, warnings=warnings)


# ----------------------------------------------------------------------------- run

@blas.one_thread()
def synthesise(deck: DeckSource | Deck, name: str | None = None) -> Synthesis:
    """Run a &synthesis deck: design the linkage, check it, and run its &fourbar deck.

    Parameters
    ----------
    deck : str, path-like, dict or Deck
        The deck (a ``&synthesis`` group only), as every entry point takes one
        (``driver.DeckSource``): its file, its text, a dict ``{"synthesis": {...}}`` (keys in
        the deck's units), or a parsed Deck.
    name : str, optional
        The deck's name in messages and titles; default its file stem, or ``synthesis``.

    Returns
    -------
    Synthesis
        The linkage (lengths in the deck's length unit), the exact kernel's checks, the
        report, and the four-bar study's run of the linkage; nothing is written.

    Raises
    ------
    DeckError
        Bad input (an unreadable file, a bad key or value), another group beside
        ``&synthesis``, degenerate path targets, or work or memory beyond the budget
        (``--max-work``, ``--max-memory``), before anything is computed.
    TypeError
        ``deck`` is not a deck source (a number, bytes, ...).
    """
    deck = source_deck(deck, name)
    others = [g for g in deck.groups if g != "synthesis"]
    if others:
        raw = deck.groups[others[0]]
        raise DeckError(deck.path, raw.line, None, f"a &synthesis deck has no other group (found &{others[0]}); "
                                                   "it writes the &fourbar deck of its linkage")
    p = validate(deck.groups["synthesis"], SPEC, deck.path)
    _budget.admit(p)   # over the budget, or degenerate targets: refused before anything is computed
    syn = {"function": _synthesise_function, "crank_rocker": _synthesise_crank_rocker, "path": _synthesise_path}[p.task](p)
    if syn.linkage is not None:
        fp = validate(RawGroup("fourbar", dict(syn.linkage, title=p.title or f"{Path(deck.path).stem} ({p.task} synthesis)"),
                               {}, p.line), fourbar.SPEC, deck.path)
        syn.study_result = compute(fourbar.STUDY, fp)
        syn.linkage = {k: v for k, v in fp.items() if v is not None and v != [] and v != ""}
    return syn


def _path_figure(syn: Synthesis, title: str) -> Any:
    """The linkage, its coupler curve and the target points, in the linkage deck's frame."""
    from driver.fourbar import _figures as fourbar_figures
    q = syn.design.parts
    theta = np.linspace(0.0, 360.0, 721)
    out, st = fourbar_kernel.fourbar_exact(np.radians(theta), q["ground"], q["crank"], q["coupler"], q["rocker"], 1.0, 0.0,
                                    1 if syn.params.branch == "open" else -1)
    cp = fourbar_kernel.fourbar_coupler_point(np.radians(theta), out, st, q["crank"], 1.0, 0.0, q["u"], q["v"])
    return fourbar_figures.fourbar_linkage(q["ground"], theta, out, st == ST["ok"], None, title, point=cp[:, :2],
                                           targets=path_targets(syn))


def path_targets(syn: Synthesis) -> np.ndarray:
    """The target points of a path synthesis in its linkage deck's frame (crank pivot at the
    origin, ground along +x): (k, 2), in the targets' length unit."""
    from driver.synthesis import _path as pg
    targets = np.column_stack([syn.params.target_x, syn.params.target_y]).astype(float)
    pp = pg.PathProblem(targets, None, 1, False, (0.0, 180.0), 1.0, 1.0)
    return pg.to_kernel_frame(pp, syn.design.x)


def _error_figure(syn: Synthesis, title: str) -> Any:
    """Function generation: the desired and generated y(x) and the structural error, the
    precision points marked where the two meet."""
    from driver import plotting
    fd = syn.design
    fig = plotting.line_panels(fd.x, [("y", {"desired y(x)": fd.y_desired, "generated": fd.y_generated}),
                                      ("structural error", {"error": fd.y_generated - fd.y_desired})],
                               "x", title=f"{title}: function generation")
    # the precision points: where the generated function meets y(x) (zero structural error)
    top, err = fig.axes
    top.plot(fd.x_points, fd.y_points, "o", ms=6, mfc="white", mec="k", zorder=5, label="precision points")
    err.plot(fd.x_points, np.zeros_like(fd.x_points), "o", ms=6, mfc="white", mec="k", zorder=5,
             label="precision points")
    err.axhline(0.0, color="0.5", lw=0.8)
    top.legend()
    err.legend()
    return fig


def synthesis_figures(syn: Synthesis, title: str) -> list[Figure]:
    """List the synthesis's own figures, drawn on demand.

    Parameters
    ----------
    syn : Synthesis
        The synthesis (:func:`synthesise`).
    title : str
        The figures' title (the deck's stem).

    Returns
    -------
    list of Figure
        The structural error of a function generation (``'error'``), the linkage and its
        coupler curve through the targets of a path generation (``'path'``); none for a
        crank-rocker.
    """
    if syn.design is None:
        return []
    if syn.params.task == "function" and len(syn.design.x):
        return [Figure("error", lambda: _error_figure(syn, title))]
    if syn.params.task == "path":
        return [Figure("path", lambda: _path_figure(syn, title))]
    return []


def run_synthesis_deck(deck: Deck, outdir: Path, formats: list[str], plot: bool | str, progress: bool = False,
                       **_: Any) -> SynthesisOutcome:
    """Synthesise a linkage and write its files: the command line's entry.

    Parameters
    ----------
    deck : Deck
        The read deck.
    outdir : pathlib.Path
        Where to write.
    formats : list of str
        Tidy table formats of the linkage's run: ``'csv'``, ``'parquet'``.
    plot : bool or str
        Write the figures (``True`` or a figure format: ``'png'``, ``'svg'``, ``'pdf'``).
    progress : bool, default False
        Unused (a synthesis shows no progress bar); the engines' common signature.
    **_ : dict
        Options of other engines, ignored.

    Returns
    -------
    SynthesisOutcome
        The linkage, its tables and its run, the files written, the warnings and the failure
        as data (the :class:`Synthesis` as ``value``).

    Raises
    ------
    DeckError
        Bad input.
    """
    syn = synthesise(deck)
    stem = output_stem(outdir, deck.path, (".out", ".linkage.dat", ".linkage.out", f"{syn.table_name}.csv",
                                           *(f".linkage.{fmt}" for fmt in formats),
                                           *(("_error.png", "_path.png") if plot else ())))
    text = syn.text.rstrip() + "\n"
    if syn.linkage is not None:
        text += f"\n  linkage deck {stem.name}.linkage.dat; its exact analysis in {stem.name}.linkage.out\n"
    outcome = SynthesisOutcome(failure=syn.failure, value=syn, name=stem.name, text=text,
                               figures=synthesis_figures(syn, Path(deck.path).stem))
    if syn.linkage is not None:
        head = f"! four-bar synthesised by {deck.path} ({syn.params.task})" + (
            "" if syn.failure is None else f"; FAILED CHECK: {syn.failure}")
        outcome.linkage_deck = head + "\n" + str(f90nml.Namelist({"fourbar": syn.linkage})) + "\n"
    written = []
    with output_set(stem.parent):   # the deck's files all together, or none
        if syn.linkage is not None:
            written.append(write_text(stem.with_name(stem.name + ".linkage.dat"), outcome.linkage_deck))
            written += write_outputs(syn.study_result, stem.with_name(stem.name + ".linkage"), formats, plot)
        written.append(write_text(stem.with_name(stem.name + ".out"), text))
        if len(syn.table):
            written.append(write_tidy(syn.table, stem.with_name(stem.name + syn.table_name), "csv"))
        if plot:
            from driver import plotting
            for fig in outcome.figures:
                written.append(plotting.save_figure(fig.draw(), stem.with_name(f"{stem.name}_{fig.name}.png"), plot))
    outcome.written = written
    for w in syn.warnings:
        outcome.warn(f"{deck.path}: {w}")
    if syn.failure:
        outcome.error(f"{deck.path}: {syn.failure}")
    return outcome
