"""The four-bar batch summary: many designs in one kernel call (sweeps, &optimize), and the
summary of one deck (the same kernel row); with ``mass`` given, the force summary (issue 26:
peak, mean and RMS torque, peak pin forces, shaking force and moment, energy fluctuation and
flywheel inertia) the same way, in one call of the force-summary kernel."""
from __future__ import annotations

import math
from collections.abc import Callable, Collection, Mapping
from typing import Any

import numpy as np
import pandas as pd

from driver._deck import Params
from driver._study import batch_error, contract_doc
from driver.fourbar import _kernel as kernel
from driver.fourbar._analysis import CLASSES, PASS_BITS, SUMMARY_KEYS, param_matrix, summary_rows
from driver.fourbar._analysis_forces import counterweights, cw_radii, forces_at, props, scan_angles, stresses_at
from driver.fourbar._kernel import ForceParam
from driver.fourbar._spec import (
    BAND,
    FORCE_SUMMARY_DOC,
    LINKS,
    STRESS_SUMMARY_DOC,
    band_of,
    force_value,
    forces_active,
    sections_of,
    yields_of,
)

__all__ = ['BATCH_KEYS', 'BATCH_IGNORED', 'BATCH_INDEPENDENT', 'BATCH_PASSES', 'DETAIL', 'summarise_batch', 'batch_refusal',
           'summary_frame', 'summarise', 'summary_of',
           'FORCE_BATCH_KEYS', 'force_frame', 'force_summary', 'summarise_force_batch', 'batch_applies',
           'stress_summary']


#: deck keys a batch may vary (one value per design: the summary kernel's parameters); every
#: other key of &fourbar leaves the summary unchanged (alpha, step_deg, method, title,
#: coupler_point) and is accepted but ignored
BATCH_KEYS = SUMMARY_KEYS


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
    "rocker_omega_peak_rad_s": ("peaks",), "coupler_omega_peak_rad_s": ("peaks",), "assembled_fraction": (),
    "time_ratio": ("rocker",),
    "mu_min_at_deg": ("transmission",), "mu_max_at_deg": ("transmission",), "rocker_min_deg": ("rocker",),
    "rocker_min_at_deg": ("rocker",), "rocker_max_deg": ("rocker",), "rocker_max_at_deg": ("rocker",),
    "rocker_omega_peak_at_deg": ("peaks",), "coupler_omega_peak_at_deg": ("peaks",), "toggles_in_range": (),
    # decks that give masses: the force summary (summarise_force_batch), a pass of its own
    **{f"{pre}{c}": ("forces",) for pre in ("", "unbalanced_") for c in FORCE_SUMMARY_DOC},
    # decks that give link sections too: the link stresses (stress_summary, design by design)
    **{c: ("forces",) for c in STRESS_SUMMARY_DOC},
}


def _pass_mask(wanted: Collection[str] | None) -> int:
    """The kernel's pass bits for summary columns ``wanted`` (None: every pass)."""
    if wanted is None:
        return sum(PASS_BITS.values())
    return sum({PASS_BITS[p] for c in wanted for p in BATCH_PASSES.get(c, ()) if p in PASS_BITS})


#: kernel class codes -> (class name as grashof() prints it, full crank rotation)
GRASHOF_NAMES = {k: (CLASSES[k].name, CLASSES[k].full_crank_rotation) for k in CLASSES}


@contract_doc
def summarise_batch(base: Mapping[str, Any], columns: Mapping[str, Any] | None = None,
                    detail: bool = False, wanted: Collection[str] | None = None) -> pd.DataFrame:
    """Summarise many four-bar designs in one Fortran call: one row per design.

    ``base``: a validated ``&fourbar`` Params (or any mapping with the BATCH_KEYS).
    ``columns``: {key: array of n values} for keys in BATCH_KEYS (``'fourbar.crank'`` is
    accepted for ``'crank'``); scalars broadcast.  Lengths in the deck's unit, ``omega``
    [rad/s], ``start_deg``/``stop_deg`` [deg], ``branch`` 'open'/'crossed' or +1/-1.
    Returns the columns of the single-case summary (``summarise``) with identical values
    (missing figures as NaN): grashof_class, full_crank_rotation, assemblable, mu_min_deg,
    mu_max_deg, meets_transmission_band (mu within the base deck's ``transmission_band_deg``),
    rocker_turns_fully, rocker_swing_deg, toggle_in_range,
    rocker_omega_peak_rad_s, coupler_omega_peak_rad_s, assembled_fraction, time_ratio (crank angle of the
    rocker's slower stroke over its quicker one, >= 1; missing unless the range holds a full
    turn, assembled throughout, without a toggle, with the rocker oscillating); with ``detail`` also the crank
    angles [deg] of those extremes, the rocker extreme positions [deg] and the number of
    toggle positions in the range.  ``wanted``: only these columns (names of the columns
    above; others are ignored), computed by only the kernel passes they need
    (:data:`BATCH_PASSES`) -- each with the same bits as in a full summary; None: all.
    A bad value raises DeckError (``base`` a deck's Params: deck, line and key of the base
    deck, the design's index in the message) or ValueError.  About 3 microseconds per design
    on one core with every column, 0.7 without the peak speeds (bench/bench_sweep.py).

    Parameters
    ----------
    base : mapping
        A validated ``&fourbar`` Params (or any mapping with the ``BATCH_KEYS``).
    columns : mapping of str to array, optional
        {key: n values} for keys in ``BATCH_KEYS``, in the deck's units (length unit, rad/s,
        deg); scalars broadcast.
    detail : bool, default False
        Also the crank angles of the extremes, rocker extreme positions (deg) and toggle counts.
    wanted : collection of str, optional
        Only these columns; None: all.

    Returns
    -------
    pandas.DataFrame
        One row per design, the columns above (units in their names: ``_deg``, ``_rad_s``).

    %(batch_raises)s
    """
    columns = {k.partition(".")[2] if k.startswith("fourbar.") else k: v for k, v in (columns or {}).items()}
    unknown = [k for k in columns if k not in BATCH_KEYS and k not in BATCH_IGNORED]
    if unknown:
        raise batch_error(base, unknown[0], f"not a &fourbar key the summary depends on ({', '.join(BATCH_KEYS)})")
    force_columns = {k: v for k, v in columns.items() if k in FORCE_BATCH_KEYS}
    columns = {k: v for k, v in columns.items() if k in BATCH_KEYS}
    sizes = {np.size(v) for v in columns.values() if np.ndim(v) > 0}
    if len(sizes) > 1:
        raise batch_error(base, None, f"batch columns have different lengths {sorted(sizes)}")
    n = sizes.pop() if sizes else 1
    res = kernel.fourbar_summaries(param_matrix(base, columns, n), _pass_mask(wanted))
    return _assemble(base, res, detail or (wanted is not None and any(c in DETAIL for c in wanted)), wanted,
                     force_columns)


def _assemble(base: Mapping[str, Any], res: np.ndarray, detail: bool, wanted: Collection[str] | None,
              force_columns: Mapping[str, Any]) -> pd.DataFrame:
    """The summary frame of kernel rows ``res`` (and the force columns when the deck gives masses)."""
    frame = summary_frame(res, detail, band_of(base), wanted)
    if forces_active(base) and (wanted is None or any(BATCH_PASSES.get(c) == ("forces",) for c in wanted)):
        # force columns when the deck gives masses, and someone reads one
        more = summarise_force_batch(base, force_columns)
        if sections_of(base) is not None:   # the link stresses, design by design
            n = len(res)
            designs = [{**dict(base), **{k: (v[i] if np.ndim(v) > 0 else v) for k, v in force_columns.items()}}
                       for i in range(n)]
            more = pd.concat([more, pd.DataFrame([stress_summary(d) for d in designs])], axis=1)
        if wanted is not None:
            more = more[[c for c in more.columns if c in set(wanted)]]
        frame = pd.concat([frame, more], axis=1)
    return frame


def batch_applies(base: Mapping[str, Any]) -> bool:
    """Tell whether designs on ``base`` take the batch path: not with link sections (their
    stresses are summarised design by design, case by case in a sweep)."""
    return sections_of(base) is None


def stress_summary(p: Mapping[str, Any]) -> dict[str, Any]:
    """The link stresses of one deck with sections over the force summary's scan of its range:
    the peak normal stress in each link [MPa] and its crank angle [deg], and with
    ``yield_strength`` the largest ratio of a peak to its link's yield strength and whether a
    link yields (:data:`STRESS_SUMMARY_DOC`; None where no position is defined).

    Parameters
    ----------
    p : mapping
        ``&fourbar`` keys with ``mass``, ``section_area`` and ``section_modulus`` (SI).

    Returns
    -------
    dict of str to float, bool or None
        The columns of ``STRESS_SUMMARY_DOC``.
    """
    theta = scan_angles(p)
    out, status = kernel.fourbar_exact(np.radians(theta), p["fixed_link"], p["crank"], p["coupler"], p["rocker"],
                                       p["omega"], p.get("alpha", 0.0), 1 if p.get("branch", "open") == "open" else -1)
    pr = counterweights(p).props if force_value(p, "balance") == "force" else props(p)
    stress = stresses_at(p, out, status, pr, forces_at(p, out, status, pr))
    ok = status == kernel.FOURBAR_STATUS["ok"]
    row: dict[str, Any] = {}
    peaks: list[float | None] = []
    for j, link in enumerate(LINKS):
        if stress is None or not ok.any():
            row[f"{link}_stress_peak_MPa"], row[f"{link}_stress_peak_at_deg"] = None, None
            peaks.append(None)
            continue
        k = int(np.argmax(np.where(ok, stress[:, j], -1.0)))
        row[f"{link}_stress_peak_MPa"], row[f"{link}_stress_peak_at_deg"] = float(stress[k, j] / 1e6), float(theta[k])
        peaks.append(float(stress[k, j]))
    ys = yields_of(p)
    if ys is None or any(v is None for v in peaks):
        row["yield_ratio_max"], row["yields"] = None, None
    else:
        ratio = max(float(v) / y for v, y in zip(peaks, ys) if v is not None)
        row["yield_ratio_max"], row["yields"] = ratio, bool(ratio >= 1.0)
    order = [f"{link}_stress_peak_MPa" for link in LINKS] + [f"{link}_stress_peak_at_deg" for link in LINKS]
    return {k: row[k] for k in (*order, "yield_ratio_max", "yields")}


#: the columns of summarise_batch(detail=True) only
DETAIL = ("mu_min_at_deg", "mu_max_at_deg", "rocker_min_deg", "rocker_min_at_deg", "rocker_max_deg",
           "rocker_max_at_deg", "rocker_omega_peak_at_deg", "coupler_omega_peak_at_deg", "toggles_in_range")


def summary_frame(res: np.ndarray, detail: bool = False, band: tuple[float, float] = BAND,
           wanted: Collection[str] | None = None) -> pd.DataFrame:
    """Kernel rows -> the summary columns (vectorised; the one place both paths go through);
    with ``wanted``, only those columns are built."""
    c = dict(zip(kernel.FOURBAR_SUMMARY_COLUMNS, res.T))
    ok = c["assemblable"] > 0
    lut = [GRASHOF_NAMES[kernel.FOURBAR_GRASHOF[k]] for k in range(len(kernel.FOURBAR_GRASHOF))]
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
        "rocker_omega_peak_rad_s": lambda: has(c["rocker_omega_peak_rad_s"], ok & ~tog()),
        "coupler_omega_peak_rad_s": lambda: has(c["coupler_omega_peak_rad_s"], ok & ~tog()),
        "assembled_fraction": lambda: np.where(ok, c["assembled_fraction"], 0.0),
        "time_ratio": lambda: np.where(ok & (c["time_ratio"] > 0), c["time_ratio"], np.nan)}
    if detail:
        build |= {"mu_min_at_deg": lambda: has(c["mu_min_at_deg"]), "mu_max_at_deg": lambda: has(c["mu_max_at_deg"]),
                  "rocker_min_deg": lambda: has(c["rocker_min_deg"]),
                  "rocker_min_at_deg": lambda: has(c["rocker_min_at_deg"]),
                  "rocker_max_deg": lambda: has(c["rocker_max_deg"]),
                  "rocker_max_at_deg": lambda: has(c["rocker_max_at_deg"]),
                  "rocker_omega_peak_at_deg": lambda: has(c["rocker_omega_peak_at_deg"], ok & ~tog()),
                  "coupler_omega_peak_at_deg": lambda: has(c["coupler_omega_peak_at_deg"], ok & ~tog()),
                  "toggles_in_range": lambda: c["toggles_in_range"].astype(int)}
    keys = build if wanted is None else [k for k in build if k in set(wanted)]
    return pd.DataFrame({k: build[k]() for k in keys}, index=pd.RangeIndex(len(res)))


def batch_refusal(row: Mapping[str, Any]) -> str | None:
    """Why the study's own run fails the design of a batch row, or None: a chain that cannot move
    (an impossible or a flat chain) has no position, so its run fails (exit 1); an &optimize design
    counts as infeasible with that reason on the batch path as it does case by case."""
    name = row.get("grashof_class")
    if name in (CLASSES["no_chain"].name, CLASSES["flat_chain"].name):
        return f"{name}: the chain cannot move (no position over the crank range)"
    return None


@contract_doc
def summarise(params: Params) -> dict:
    """Summarise one deck: the headline figures only, without the tables.

    What a sweep needs when it writes no per-case files.

    %(summarise)s
    """
    return summary_of(params)


def summary_of(p: Params, res: np.ndarray | None = None) -> dict:
    """Headline figures for sweeps: one row of :func:`summarise_batch` as a dict (missing -> None).
    ``res``: the deck's :func:`summary_rows` when the caller has them (the kernel then runs once)."""
    row = _assemble(p, summary_rows(p) if res is None else res, False, None, {}).iloc[0].to_dict()
    return {k: (None if isinstance(v, float) and math.isnan(v) else
                bool(v) if isinstance(v, (bool, np.bool_)) else
                float(v) if isinstance(v, np.floating) else v) for k, v in row.items()}


# ----------------------------------------------------------------------------- the force summary (decks with mass)

#: deck keys a force batch may vary, in the kernel's parameter order where they map to one column
FORCE_BATCH_KEYS = ("fixed_link", "crank", "coupler", "rocker", "omega", "alpha", "start_deg", "stop_deg", "branch",
              "mass", "inertia", "com_distance", "com_angle_deg", "gravity", "load_torque", "load_force_x",
              "load_force_y", "coupler_point", "speed_fluctuation", "balance", "counterweight_radius")


def _force_row(p: Mapping[str, Any]) -> np.ndarray:
    """One row of the batch kernel's (31) parameters from a deck-like mapping."""
    pr = props(p)
    bal = 1.0 if force_value(p, "balance") == "force" else 0.0
    return np.concatenate([[p["fixed_link"], p["crank"], p["coupler"], p["rocker"], p["omega"], p.get("alpha", 0.0),
                            p.get("start_deg", 0.0), p.get("stop_deg", 360.0),
                            1.0 if p.get("branch", "open") == "open" else -1.0],
                           pr, [force_value(p, "speed_fluctuation"), bal, *cw_radii(p)]])


def force_frame(res: np.ndarray, prefix: str = "") -> pd.DataFrame:
    """Force-summary kernel rows -> the force summary columns (NaN where a figure does not exist)."""
    c = dict(zip(kernel.FOURBAR_FORCE_SUMMARY_COLUMNS, res.T))
    anyok = c["defined_fraction"] > 0
    full = c["defined_fraction"] >= 1.0
    out: dict[str, np.ndarray] = {}
    for name in FORCE_SUMMARY_DOC:
        v = c[name]
        mask = full if name in ("torque_mean_Nm", "torque_rms_Nm", "energy_fluctuation_J",
                                "flywheel_inertia_kgm2") else anyok
        if name == "flywheel_inertia_kgm2":
            mask = mask & (v > 0)
        out[prefix + name] = np.where(mask, v, np.nan)
    return pd.DataFrame(out)


def force_summary(p: Params) -> dict[str, Any]:
    """Summarise the forces of one deck: one row of the batch kernel.

    Parameters
    ----------
    p : Params
        Validated ``&fourbar`` keys (lengths in m with ``mass``).

    Returns
    -------
    dict of str to float or None
        ``FORCE_SUMMARY_DOC``'s figures, units in their names (``torque_peak_Nm``,
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
        {key: n values} for scalar keys in ``FORCE_BATCH_KEYS`` (``'fourbar.crank'`` accepted), or
        ``mass``/``inertia``/``com_distance``/``com_angle_deg`` as (n, 3) arrays, in the
        keys' deck units (kg, kg m^2, m, deg); scalars broadcast.

    Returns
    -------
    pandas.DataFrame
        One row per design, the columns of ``FORCE_SUMMARY_DOC`` (units in their names); with
        ``balance = 'force'`` of the balanced linkage, and the same columns prefixed
        ``unbalanced_`` for the linkage as given.
    """
    columns = {k.partition(".")[2] if k.startswith("fourbar.") else k: v for k, v in (columns or {}).items()}
    bad = [k for k in columns if k not in FORCE_BATCH_KEYS]
    if bad:
        raise ValueError(f"{bad[0]}: not a key the force summary depends on ({', '.join(FORCE_BATCH_KEYS)})")
    sizes = {len(v) for v in columns.values() if np.ndim(v) > 0}
    if len(sizes) > 1:
        raise ValueError(f"batch columns have different lengths {sorted(sizes)}")
    n = sizes.pop() if sizes else 1
    rows = np.empty((n, kernel.N_FORCE_PARAMS), order="F")
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
        rows[i] = _force_row(d)
    if not np.all(np.isfinite(rows)):
        raise ValueError("batch values must be finite")
    frame = force_frame(kernel.fourbar_force_summaries(rows))
    if rows[:, ForceParam.BALANCE].any():   # balanced designs: the figures without counterweights follow
        rows[:, ForceParam.BALANCE] = 0.0
        frame = pd.concat([frame, force_frame(kernel.fourbar_force_summaries(rows), "unbalanced_")], axis=1)
    return frame
