"""The ``&linkage`` keys (with their checks), axis labels, sweep headline columns and the budget
estimate of a run.

A mechanism is described as a textbook figure reads (docs/linkage.md): named ground pivots and
slider guides, a driver, then the class-II groups (dyads) in order, each attaching to points
already placed, and points on links (tracers, attachments, load points).  Lengths in any
consistent unit (metres when masses are given); angles in degrees in decks and tables."""
from __future__ import annotations

import math
from typing import Any

from driver._deck import GroupSpec, Key, Params
from driver._limits import Estimate
from driver._study import contract_doc

__all__ = ["SPEC", "LABELS", "SWEEP_BEST", "SWEEP_PLOT", "SUMMARY_SETTINGS", "DYAD_TYPES", "MAX_POSITIONS",
           "MAX_ANGLE", "estimate", "positions_count"]

#: dyad types a deck may name (PRR is an RRP group written from its other end)
DYAD_TYPES = ("rrr", "rrp", "prr", "rpr", "prp")
#: input positions one run may ask for (checked before anything is allocated)
MAX_POSITIONS = 5_000_000
#: |input| a deck may give [deg or length]
MAX_ANGLE = 1.0e6


def _finite(v: Any) -> str | None:
    vals = v if isinstance(v, list) else [v]
    return None if all(math.isfinite(x) for x in vals) else "must be finite"


def _pairs(v: Any) -> str | None:
    return _finite(v) or (None if len(v) % 2 == 0 else f"give pairs of numbers (got {len(v)} values)")


def _non_negative(v: Any) -> str | None:
    vals = v if isinstance(v, list) else [v]
    return _finite(v) or (None if all(x >= 0 for x in vals) else f"must not be negative (got {min(vals)})")


def _names(v: Any) -> str | None:
    for name in v:
        if not name or not name.replace("_", "").isalnum() or not name[0].isalpha() or len(name) > 24:
            return (f"{name!r} is not a name (letters, digits and '_', starting with a letter, at most 24 "
                    "characters)")
    return None


def positions_count(p: Params) -> float:
    """Input positions a deck asks for (inf when the range does not end)."""
    try:
        n = math.floor((p.stop - p.start) / p.step + 1e-9) + 1
    except (OverflowError, ZeroDivisionError, ValueError):
        return math.inf
    return float(max(n, 1))


def _check(p: Params) -> None:
    """Cross-key checks: the input range, then the mechanism (driver.linkage._spec_model.compile_deck)."""
    if p.step == 0:
        raise p.error("step", "must not be 0 (the input would never advance)")
    for key in ("start", "stop"):
        if abs(p[key]) > MAX_ANGLE:
            raise p.error(key, f"|{p[key]:g}| is beyond {MAX_ANGLE:g}")
    if (p.stop - p.start) * p.step < 0:
        raise p.error("step", f"steps away from stop ({p.start:g} -> {p.stop:g} with step {p.step:g})")
    n = positions_count(p)
    if n > MAX_POSITIONS:
        raise p.error("step", f"{n:.3g} input positions; at most {MAX_POSITIONS:g} (use a coarser step)")
    from driver.linkage._spec_model import check_turning_moment, compile_deck  # with file, line, key
    compile_deck(p)
    check_turning_moment(p)


#: axis labels of summary columns and deck keys (driver._output.column_label): name -> (words, units)
LABELS = {"stroke": ("stroke of the output", "length units or deg"),
          "time_ratio": ("time ratio (slow / quick stroke)", "-"),
          "mu_min_deg": ("smallest transmission angle", "deg"), "mu_max_deg": ("largest transmission angle", "deg"),
          "pressure_max_deg": ("largest pressure angle", "deg"),
          "assembled_fraction": ("fraction of the cycle assembled", "-"),
          "torque_peak": ("peak driving torque (or force)", "N m or N"),
          "torque_mean": ("mean driving torque (or force)", "N m or N"),
          "shaking_force_peak_N": ("peak shaking force", "N"),
          "energy_fluctuation_J": ("energy fluctuation", "J"), "flywheel_inertia_kgm2": ("flywheel inertia", "kg m^2")}

#: which way a summary column is better
SWEEP_BEST = {"mu_min_deg": "max", "pressure_max_deg": "min", "time_ratio": "max", "torque_peak": "min",
              "shaking_force_peak_N": "min", "flywheel_inertia_kgm2": "min"}

#: keys of the base deck the summary columns depend on beyond the mechanism itself
SUMMARY_SETTINGS = ("scan_points",)

#: what a sweep summary plots when its deck names none
SWEEP_PLOT = ("stroke", "time_ratio", "mu_min_deg", "pressure_max_deg", "assembled_fraction")

def _named(**kw: Any) -> Key:
    """A key holding names (strings checked by _names)."""
    return Key("strs", check=_names, **kw)


SPEC = GroupSpec(
    name="linkage",
    doc="any planar linkage: a driver and class-II groups (dyads RRR, RRP, PRR, RPR, PRP)",
    keys={
        "title": Key("str", default="", doc="free text echoed in the output"),
        # ---- the frame
        "pivots": _named(default=[], doc="names of the ground pivots"),
        "pivot_xy": Key("floats", default=[], units="length", check=_pairs,
                        doc="x, y of each ground pivot (pairs, in the order of pivots)"),
        "guides": _named(default=[], doc="names of the slider guides given here (lines fixed to the "
                                               "ground or to a link; an RPR group names its own slot)"),
        "guide_on": _named(default=None, doc="the link each guide is fixed to (default: 'ground' for all)"),
        "guide_xy": Key("floats", default=[], units="length", check=_pairs,
                        doc="a point of each guide (pairs) in its link's frame (the ground's: x, y)"),
        "guide_deg": Key("floats", default=[], units="deg", check=_finite,
                         doc="direction of each guide, ccw from its link's x-axis"),
        # ---- the driver
        "driver": Key("str", default="crank", choices=("crank", "slider"),
                      doc="'crank': a link turning about a ground pivot; 'slider': a block moving along a "
                          "ground guide"),
        "driver_joints": _named(required=True,
                             doc="crank: its ground pivot and the name of its pin; slider: its guide and the "
                                 "name of its pin"),
        "driver_link": Key("str", default="", doc="the driver link's name (default 'crank' or 'slider')"),
        "driver_length": Key("float", default=0.0, units="length", check=_finite,
                             doc="crank: pivot to pin (> 0); slider: the pin's offset to the left of the guide"),
        "omega": Key("float", default=1.0, units="rad/s or length/s", check=_finite,
                     doc="input speed: the crank's angular velocity (ccw +) or the slider's velocity"),
        "alpha": Key("float", default=0.0, units="rad/s^2 or length/s^2", check=_finite,
                     doc="input acceleration"),
        "start": Key("float", default=0.0, units="deg or length", doc="first input position"),
        "stop": Key("float", default=360.0, units="deg or length", doc="last input position (inclusive)"),
        "step": Key("float", required=True, units="deg or length", doc="input step"),
        # ---- the groups
        "dyads": Key("strs", default=[], choices=DYAD_TYPES,
                     doc="the type of each group, solved in this order: RRR, RRP, PRR, RPR, PRP"),
        "dyad_joints": _named(default=[],
                           doc="three names per group: its first and second attachment (points, or guides "
                               "for a P end) and the name of the new joint (RPR: of its new slot guide)"),
        "dyad_links": _named(default=[], doc="two link names per group, in the order of its letters"),
        "dyad_dims": Key("floats", default=[], units="length", check=_pairs,
                         doc="two numbers per group: RRR the two link lengths; RRP rod length, pin offset; "
                             "PRR pin offset, rod length; RPR slot offset, pin offset; PRP the pin's offsets "
                             "from the two guides"),
        "dyad_modes": Key("ints", default=None, check=lambda v: None if all(x in (1, -1) for x in v)
                          else "each mode is +1 or -1",
                          doc="assembly mode of each group (+1 or -1; docs/linkage.md; default +1)"),
        # ---- points on links
        "points": _named(default=[], doc="names of points fixed to moving links (tracers, attachments, "
                                               "load points)"),
        "point_on": _named(default=[], doc="the link of each point"),
        "point_uv": Key("floats", default=[], units="length", check=_pairs,
                        doc="each point in its link's frame: u along the link's x-axis, v to its left"),
        "output": Key("str", default="", doc="the output element for the summary: a slide (its block's link "
                                            "name) or a link (default: the last group's slide or link)"),
        "scan_points": Key("int", default=720, check=lambda v: None if 16 <= v <= 100_000
                           else "between 16 and 100000",
                           doc="input positions of the summary's scan of one cycle"),
        # ---- kinetostatics
        "bodies": _named(default=None, doc="links with mass (giving them runs the force analysis; "
                                                   "SI units)"),
        "mass": Key("floats", default=None, units="kg", check=_non_negative, doc="mass of each body"),
        "com_uv": Key("floats", default=None, units="m", check=_pairs,
                      doc="centre of mass of each body in its frame (pairs; default the frame's origin)"),
        "inertia": Key("floats", default=None, units="kg m^2", check=_non_negative,
                       doc="moment of inertia of each body about its centre of mass (default 0)"),
        "gravity": Key("floats", default=None, units="m/s^2", check=lambda v: _finite(v) or
                       (None if len(v) == 2 else "give gx, gy"), doc="gravity vector (default 0, -9.81)"),
        "loads": _named(default=None, doc="points where external forces act"),
        "load_xy": Key("floats", default=None, units="N", check=_pairs, doc="force at each load point (pairs)"),
        "torque_links": _named(default=None, doc="links with an external torque"),
        "torques": Key("floats", default=None, units="N m", check=_finite, doc="torque on each (ccw +)"),
        "guide_force_on": Key("str", default="", doc="the slider block a tabulated force acts on (along its "
                                                      "guide; the reaction on the guide's link)"),
        "guide_force_over": Key("str", default="input", choices=("input", "slide"),
                                doc="the table's abscissa: the input (deg or length) or the block's slide"),
        "guide_force_x": Key("floats", default=None, units="deg or length", check=_finite,
                             doc="abscissae of the force table (ascending)"),
        "guide_force": Key("floats", default=None, units="N (or Pa with guide_force_scale)", check=_finite,
                           doc="the force along the guide's direction at each abscissa"),
        "guide_force_scale": Key("float", default=1.0, units="m^2 or 1", check=_finite,
                                 doc="multiplies the table (a piston area when the table holds pressures)"),
        "cycle_deg": Key("float", default=360.0, units="deg", check=lambda v: None if v in (360.0, 720.0)
                         else "360 (one turn) or 720 (a four-stroke engine's cycle)",
                         doc="the load cycle of a crank: 360, or 720 for a four-stroke engine"),
        "speed_fluctuation": Key("float", default=0.02, units="1", check=lambda v: None if v > 0 and
                                 math.isfinite(v) else "must be positive",
                                 doc="coefficient of speed fluctuation C_s of the flywheel"),
        "turning_moment_deg": Key("floats", default=None, units="deg", check=_finite,
                                  doc="crank angles of a turning-moment diagram (one cycle, ascending)"),
        "turning_moment": Key("floats", default=None, units="N m", check=_finite,
                              doc="the diagram's torque at each angle (linear in between)"),
    },
    check=_check,
)


@contract_doc
def estimate(params: Params) -> Estimate:
    """Estimate the memory and work of a run from the keys alone, before it allocates.

    Per input position a table row (about 200 bytes of kernel output and 1 KB of text per
    element, 30 us of formatting per row) and the summary's scan of one cycle.

    %(estimate)s
    """
    p = params
    n = positions_count(p)
    elements = 1 + len(p.points) + len(p.dyads) * 3 + len(p.pivots)
    rows = Estimate((2000.0 + 600.0 * elements) * n + 5e6, (3e-5 + 5e-6 * elements) * n + 0.05, "step", "step",
                    f"{n:.4g} input positions")
    scan = Estimate(200.0 * elements * p.scan_points, 2e-7 * elements * p.scan_points, "scan_points",
                    "scan_points", f"a {p.scan_points}-point scan of one cycle")
    return rows + scan
