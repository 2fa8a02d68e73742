"""The linkage batch summary: many designs of one mechanism in one kernel call (sweeps,
&optimize), and the summary of one deck (the same kernel row).

A batch varies numbers only (the topology is the base deck's): each varied key (or list
element ``key(i)``) is applied to the base deck once per distinct value and compiled -- so
every design is checked exactly as a deck would be -- and the kernel's number vectors of the
designs are the base's plus the changes of their values (fortran/linkage.f90 summaries)."""
from __future__ import annotations

import math
import re
from collections.abc import Callable, Collection, Mapping
from typing import Any

import numpy as np
import pandas as pd

from driver._deck import DeckError, Params
from driver._study import contract_doc
from driver.linkage import _kernel as kernel
from driver.linkage._kernel import NSUM_DYAD, NSUM_LINK, NSUM_SLIDE, SummaryCol
from driver.linkage._kernel_program import Mechanism
from driver.linkage._spec_model import compile_deck

__all__ = ["design_numbers", "BATCH_KEYS", "BATCH_IGNORED", "BATCH_INDEPENDENT", "BATCH_ELEMENTS", "BATCH_PASSES",
           "ELEMENT_PASSES",
           "PASS_NAMES", "passes_for", "summarise_batch", "summarise",
           "summary_of", "summary_frame", "scan_of", "refusal"]

#: deck keys a batch may vary (numbers of the mechanism, its loads and the scan)
BATCH_KEYS = ("pivot_xy", "guide_xy", "guide_deg", "driver_length", "omega", "alpha", "dyad_dims", "dyad_modes",
              "point_uv", "mass", "com_uv", "inertia", "gravity", "load_xy", "torques", "guide_force_scale",
              "guide_force", "speed_fluctuation", "start", "stop", "turning_moment")
#: list keys whose single elements ('key(i)', 1-based) a batch may set
BATCH_ELEMENTS = ("pivot_xy", "guide_xy", "guide_deg", "dyad_dims", "dyad_modes", "point_uv", "mass", "com_uv",
                  "inertia", "gravity", "load_xy", "torques", "guide_force", "turning_moment")
#: keys accepted in a batch that leave the summary unchanged
BATCH_IGNORED = ("title", "step")
#: keys whose deck checks involve no other key that a batch may vary (a sweep validates each of
#: their values once): every number of the mechanism is checked on its own (its sign, its pairs;
#: the topology, which fixes the list lengths and which sign a group's numbers need, is the base
#: deck's); only start and stop are checked together (the range, the position count)
BATCH_INDEPENDENT = tuple(k for k in BATCH_KEYS if k not in ("start", "stop")) + ("title", "step")
_ELEMENT = re.compile(r"([a-z_]+)\((\d+)\)")


def _key_of(name: str) -> str:
    """The deck key of a batch column ('key' or 'key(i)')."""
    m = _ELEMENT.fullmatch(name)
    return m.group(1) if m else name


def scan_of(p: Mapping[str, Any], mech: Mechanism) -> tuple[float, float, bool]:
    """The summary's scan of one cycle: first input, span (rad for a crank: the load cycle;
    length for an input slider: start to stop) and whether it is periodic."""
    if mech.driver == "crank":
        return math.radians(float(p["start"])), math.radians(float(p["cycle_deg"])), True
    return float(p["start"]), float(p["stop"]) - float(p["start"]), False


def _with(base: Params, key: str, index: int | None, value: Any) -> Params:
    """``base`` with one key (or one element of a list key, 1-based) replaced, re-checked."""
    values = dict(base)
    if index is None:
        values[key] = value
    else:
        cur = list(base[key] if base[key] is not None else [])
        if not 1 <= index <= len(cur):
            raise base.error(key, f"element {index} does not exist ({key} has {len(cur)} values)")
        cur[index - 1] = value
        values[key] = cur
    q = Params(base.group, base.path, values, {k: base.line_of(k) for k in base}, base.line, base.given | {key})
    from driver.linkage._spec import SPEC
    k = SPEC.keys[key]
    if k.check is not None:
        msg = k.check(values[key])
        if msg:
            raise base.error(key, msg)
    return q


#: a column with more distinct values than this is applied through its affine map (below)
AFFINE_FROM = 16


def _design(base: Params, key: str, index: int | None, value: Any, b: np.ndarray, u: int,
            inverse: np.ndarray) -> np.ndarray:
    """The kernel row of the base deck with one value changed (checked as a deck would be)."""
    try:
        q = _with(base, key, index, value)
        mq = compile_deck(q)
    except DeckError as exc:
        i = int(np.argmax(inverse == u))
        raise DeckError(exc.path, exc.line, exc.key, f"design {i}: {exc.message}") from None
    nq = np.concatenate([mq.numbers(), np.zeros(3)])
    if len(nq) != len(b):
        raise base.error(key, "changes the mechanism's layout (a batch varies numbers only)")
    xq, sq, _ = scan_of(q, mq)
    nq[-3:] = (xq, sq, float(q["speed_fluctuation"]))
    return nq


def design_numbers(base: Params, mech: Mechanism, columns: Mapping[str, Any], n: int) -> np.ndarray:
    """(n, numbers + 3) kernel rows: the base design's numbers plus each varied value's change.

    A column with few distinct values is compiled once per value (every design checked as a
    deck).  One with many (an optimiser's, a fine grid's) goes through its affine map: the
    kernel numbers depend on a deck number linearly (a copy, degrees to radians, an offset
    summed with another), which three compiled values establish and check; its values are then
    checked by the key's own check and the mechanism's at the column's two extremes (its checks
    are bounds: every value between two valid ones is valid); a column whose map is not affine
    is compiled value by value."""
    b = np.concatenate([mech.numbers(), np.zeros(3)])
    x0, span, _ = scan_of(base, mech)
    b[-3:] = (x0, span, float(base["speed_fluctuation"]))
    rows = np.tile(b, (n, 1))
    for name, vals in columns.items():
        m = _ELEMENT.fullmatch(name)
        key, index = (m.group(1), int(m.group(2))) if m else (name, None)
        vals = np.broadcast_to(np.asarray(vals), (n,))
        uniq, inverse = np.unique(vals, return_inverse=True)
        numeric = uniq.dtype.kind in "fiu"
        if numeric and len(uniq) > AFFINE_FROM:
            lo, hi = float(uniq[0]), float(uniq[-1])
            nlo = _design(base, key, index, lo, b, 0, inverse)
            nhi = _design(base, key, index, hi, b, len(uniq) - 1, inverse)
            mid = float(uniq[len(uniq) // 2])
            nmid = _design(base, key, index, mid, b, len(uniq) // 2, inverse)
            slope = (nhi - nlo) / (hi - lo)
            pred = nlo + slope * (mid - lo)
            if np.all(np.abs(pred - nmid) <= 1e-12 * (np.abs(nmid) + np.abs(nlo) + np.abs(nhi) + 1e-300)):
                from driver.linkage._spec import SPEC
                check = SPEC.keys[key].check
                for u, v in enumerate(uniq):
                    if index is not None:
                        whole = list(base[key])
                        whole[index - 1] = float(v)
                    msg = check(whole if index is not None else float(v)) if check is not None else None
                    if msg:
                        i = int(np.argmax(inverse == u))
                        raise base.error(key, f"design {i}: {msg}")
                # only the kernel numbers the key moves (one or two of the design's)
                moved = np.flatnonzero((nlo != b) | (slope != 0.0))
                rows[:, moved] += (nlo - b)[moved] + slope[moved] * (uniq[inverse] - lo)[:, None]
                continue
        delta = np.empty((len(uniq), len(b)))
        for u, v in enumerate(uniq):
            delta[u] = _design(base, key, index, v.item() if hasattr(v, "item") else v, b, u, inverse) - b
        moved = np.flatnonzero(np.any(delta != 0.0, axis=0))
        rows[:, moved] += delta[:, moved][inverse]
    return rows   # C order: each design's numbers contiguous, as the kernel reads them


@contract_doc
def summarise_batch(base: Mapping[str, Any], columns: Mapping[str, Any] | None = None,
                    wanted: Collection[str] | None = None) -> pd.DataFrame:
    """Summarise many designs of one mechanism in one Fortran call: one row per design.

    Parameters
    ----------
    base : Params
        A validated ``&linkage`` deck: the mechanism whose numbers the designs change.
    columns : mapping of str to array, optional
        {key or 'key(i)': n values} for keys in ``BATCH_KEYS`` (elements of ``BATCH_ELEMENTS``),
        in the deck's units; ``'linkage.key'`` is accepted for ``'key'``; scalars broadcast.
    wanted : collection of str, optional
        Only these summary columns; the kernel runs only the passes they need (:data:`BATCH_PASSES`,
        the per-element columns by their prefix), each giving the same values as in a full summary.

    Returns
    -------
    pandas.DataFrame
        One row per design: the columns of :func:`summarise` (units in their names; missing
        figures NaN).

    %(batch_raises)s
    """
    if not isinstance(base, Params):
        raise TypeError("base must be a validated &linkage deck (Params)")
    columns = {k.partition(".")[2] if k.startswith("linkage.") else k: v for k, v in (columns or {}).items()}
    for k in columns:
        m = _ELEMENT.fullmatch(k)
        key = m.group(1) if m else k
        if key in BATCH_IGNORED:
            continue
        if key not in BATCH_KEYS or (m and key not in BATCH_ELEMENTS):
            raise base.error(key if key in base else None, f"{k!r} is not a &linkage number a batch may vary "
                                                             f"({', '.join(BATCH_KEYS)})")
    columns = {k: v for k, v in columns.items() if _key_of(k) not in BATCH_IGNORED}
    sizes = {np.size(v) for v in columns.values() if np.ndim(v) > 0}
    if len(sizes) > 1:
        raise base.error(None, f"batch columns have different lengths {sorted(sizes)}")
    n = sizes.pop() if sizes else 1
    mech = compile_deck(base)
    rows = kernel.summaries(mech, design_numbers(base, mech, columns, n), base["scan_points"], mech.driver == "crank",
                            passes=passes_for(wanted))
    return summary_frame(base, mech, rows, wanted)


#: the summary's columns -> the kernel passes they need (fortran/linkage.f90 summaries; the
#: study's part of "compute only what the deck asks for").  Columns with no pass are always
#: computed (the assembly counts); the per-element columns (one per link, slide or group, named
#: after it) take their pass from their prefix (:data:`ELEMENT_PASSES`).
BATCH_PASSES: dict[str, tuple[str, ...]] = {
    "assembled_fraction": (), "assemblable": (), "toggle_in_range": (),
    **{c: ("output",) for c in ("output_min", "output_min_at", "output_max", "output_max_at", "stroke", "time_ratio")},
    **{c: ("quality",) for c in ("mu_min_deg", "mu_min_at", "mu_max_deg", "mu_max_at", "pressure_max_deg")},
    **{c: ("forces",) for c in ("torque_peak", "torque_peak_at", "torque_mean", "torque_rms", "shaking_force_peak_N",
                                 "shaking_moment_peak_Nm", "energy_fluctuation_J", "flywheel_inertia_kgm2")},
}
#: prefixes of the per-element columns -> their pass
ELEMENT_PASSES = {"omega_peak_": "peaks", "alpha_peak_": "peaks", "slide_min_": "peaks", "slide_max_": "peaks",
                  "slide_rate_peak_": "peaks", "slide_accel_peak_": "peaks", "mu_min_deg_": "quality",
                  "mu_max_deg_": "quality", "pressure_min_deg_": "quality", "pressure_max_deg_": "quality"}
#: the kernel's passes by name (the pass names of the study's batch summary)
PASS_NAMES = {"output": kernel.Pass.OUTPUT, "quality": kernel.Pass.QUALITY, "peaks": kernel.Pass.PEAKS,
              "forces": kernel.Pass.FORCES}


def passes_for(wanted: Collection[str] | None) -> kernel.Pass:
    """The kernel passes summary columns ``wanted`` need (None: every pass)."""
    if wanted is None:
        return kernel.Pass.ALL
    bits = kernel.Pass(0)
    for c in wanted:
        names = BATCH_PASSES.get(c)
        if names is None:
            names = tuple(ps for pre, ps in ELEMENT_PASSES.items() if c.startswith(pre))[:1]
        for name in names:
            bits |= PASS_NAMES[name]
    return bits


def summary_frame(p: Mapping[str, Any], mech: Mechanism, res: np.ndarray,
                  wanted: Collection[str] | None = None) -> pd.DataFrame:
    """Kernel rows -> the summary columns (the one place both paths go through); only the
    columns ``wanted`` (None: all), in the summary's order."""
    c = SummaryCol
    crank = mech.driver == "crank"
    xin = np.degrees if crank else (lambda v: v)
    whole = res[:, c.ASSEMBLED_FRACTION] >= 1.0
    some = res[:, c.ASSEMBLED_FRACTION] > 0
    has = lambda v, m: np.where(m, v, np.nan)
    out_is_link = mech.output[0] == 1
    ou = np.degrees if out_is_link else (lambda v: v)
    rrr = any(d.kind == "rrr" for d in mech.dyads) & some
    sliding = any(d.kind != "rrr" for d in mech.dyads) & some

    def output(col: int, unit: Callable[[np.ndarray], np.ndarray]) -> Callable[[], np.ndarray]:
        # an output link that turns fully has no extremes (the kernel leaves them 0)
        full_turn = out_is_link & whole & (res[:, c.STROKE] == 0.0) & (res[:, c.OUTPUT_MAX] == 0.0)
        return lambda: has(unit(res[:, col]), whole & ~full_turn)

    # each column made only when asked for (a design search asks for a few of many)
    cols: dict[str, Callable[[], Any]] = {
        "assembled_fraction": lambda: res[:, c.ASSEMBLED_FRACTION],
        "assemblable": lambda: whole,
        "toggle_in_range": lambda: res[:, c.TOGGLES] > 0,
        "output_min": output(c.OUTPUT_MIN, ou), "output_min_at": output(c.OUTPUT_MIN_AT, xin),
        "output_max": output(c.OUTPUT_MAX, ou), "output_max_at": output(c.OUTPUT_MAX_AT, xin),
        "stroke": output(c.STROKE, ou),
        "time_ratio": lambda: has(res[:, c.TIME_RATIO], whole & (res[:, c.TIME_RATIO] > 0)),
        "mu_min_deg": lambda: has(np.degrees(res[:, c.MU_MIN]), rrr),
        "mu_min_at": lambda: has(xin(res[:, c.MU_MIN_AT]), rrr),
        "mu_max_deg": lambda: has(np.degrees(res[:, c.MU_MAX]), rrr),
        "mu_max_at": lambda: has(xin(res[:, c.MU_MAX_AT]), rrr),
        "pressure_max_deg": lambda: has(np.degrees(res[:, c.PRESSURE_MAX]), sliding),
    }
    # the force columns are always there (a stable schema for sweeps): NaN without bodies, the
    # energy and flywheel NaN for an input slider too
    forced, cranked = some & mech.forces, whole & (mech.forces and crank)
    cols |= {"torque_peak": lambda: has(res[:, c.TORQUE_PEAK], forced),
             "torque_peak_at": lambda: has(xin(res[:, c.TORQUE_PEAK_AT]), forced),
             "torque_mean": lambda: has(res[:, c.TORQUE_MEAN], whole & mech.forces),
             "torque_rms": lambda: has(res[:, c.TORQUE_RMS], whole & mech.forces),
             "shaking_force_peak_N": lambda: has(res[:, c.SHAKING_FORCE_PEAK], forced),
             "shaking_moment_peak_Nm": lambda: has(res[:, c.SHAKING_MOMENT_PEAK], forced),
             "energy_fluctuation_J": lambda: has(res[:, c.ENERGY_FLUCTUATION], cranked),
             "flywheel_inertia_kgm2": lambda: has(res[:, c.FLYWHEEL_INERTIA], cranked & (res[:, c.FLYWHEEL_INERTIA] > 0))}
    column = lambda j, m, unit=(lambda v: v): (lambda: has(unit(res[:, j]), m))
    base = len(SummaryCol)
    for i, name in enumerate(mech.links[1:]):
        j = base + NSUM_LINK * i
        cols[f"omega_peak_{name}_rad_s"] = column(j, some)
        cols[f"alpha_peak_{name}_rad_s2"] = column(j + 1, some)
    base += NSUM_LINK * (len(mech.links) - 1)
    for i, (name, _, _) in enumerate(mech.slides):
        j = base + NSUM_SLIDE * i
        cols[f"slide_min_{name}"] = column(j, whole)
        cols[f"slide_max_{name}"] = column(j + 1, whole)
        cols[f"slide_rate_peak_{name}"] = column(j + 2, some)
        cols[f"slide_accel_peak_{name}"] = column(j + 3, some)
    base += NSUM_SLIDE * mech.nslides
    for i, d in enumerate(mech.dyads):
        j = base + NSUM_DYAD * i
        word = "mu" if d.kind == "rrr" else "pressure"
        cols[f"{word}_min_deg_{d.joints[2]}"] = column(j, some, np.degrees)
        cols[f"{word}_max_deg_{d.joints[2]}"] = column(j + 1, some, np.degrees)
    names = list(cols) if wanted is None else [k for k in cols if k in set(wanted)]
    return pd.DataFrame({k: cols[k]() for k in names}, index=pd.RangeIndex(len(res)))


def refusal(row: Mapping[str, Any]) -> str | None:
    """Why the study's own run would refuse a design of a summary row: never (a linkage that
    cannot be assembled is reported, not refused)."""
    return None


def summary_rows(p: Params, mech: Mechanism | None = None) -> tuple[Mechanism, np.ndarray]:
    """The kernel's summary row of one deck: (mechanism, (1, width) row)."""
    mech = mech or compile_deck(p)
    return mech, kernel.summaries(mech, design_numbers(p, mech, {}, 1), p.scan_points, mech.driver == "crank")


@contract_doc
def summarise(params: Params) -> dict:
    """Summarise one deck: the headline figures only, without the tables.

    %(summarise)s
    """
    return summary_of(params)


def summary_of(p: Params, rows: tuple[Mechanism, np.ndarray] | None = None) -> dict:
    """Headline figures of one deck as a dict (missing -> None)."""
    mech, res = rows or summary_rows(p)
    row = summary_frame(p, mech, res).iloc[0].to_dict()
    out = {k: (None if isinstance(v, float) and math.isnan(v) else
               bool(v) if isinstance(v, (bool, np.bool_)) else
               float(v) if isinstance(v, np.floating) else v) for k, v in row.items()}
    if p.turning_moment is not None:
        from driver.linkage._analysis_flywheel import table_flywheel
        tm = table_flywheel(p)
        out |= {"table_torque_mean_Nm": tm.mean, "table_energy_fluctuation_J": tm.fluctuation,
                "table_flywheel_inertia_kgm2": tm.inertia}
    return out
