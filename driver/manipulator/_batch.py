"""Design summaries of many &manipulator designs in one kernel call: the batch path of sweeps
(driver.sweep._chunks.batch_rows) and optimisations (driver.optimize._evaluate).

:func:`summarise_batch` returns, one row per design deck, the columns of the single run's
summary (``run(...).summary``) plus nothing else: the workspace and C_rob figures, the torques
at the target and the tolerance box of every design, the first design's indices and status,
and the least torque along C_rob.  The per-design figures come from
fortran/manipulator_summary.f90 (RI1-RI3, the reach conditions, the IK and Craig torques at the
target, the closed-form tolerance box and its Monte Carlo check over the deck's samples), for
all designs in one call; the C_rob walk (Table 4.8) depends on none of the designs and is
computed once for every distinct target, mass per length and g.

A design that cannot reach the workspace or the target is a row like any other, with its
``design_status`` and missing figures (NaN here, None in :func:`summarise`): a sweep lists it,
an optimiser sees its constraint ``design_reaches_all`` violated.  (A single run refuses such a
deck design: its tables need a design that reaches.)
"""
from __future__ import annotations

import math
from collections.abc import Collection, Mapping
from typing import Any

import numpy as np
import pandas as pd

from driver._deck import Params
from driver._study import batch_error, contract_doc
from driver.manipulator import _kernel as kernel
from driver.manipulator._analysis import (
    STATUS,
    Conv,
    Workspace,
    design_list,
    design_status,
    design_torque_columns,
    round_half_up,
    sweep_columns,
    workspace_columns,
)
from driver.manipulator._kernel import SummaryParam, Torque
from driver.manipulator._tables import table_4_8

__all__ = ["BATCH_KEYS", "BATCH_IGNORED", "BATCH_INDEPENDENT", "BATCH_PASSES", "BATCH_PASS_SUFFIXES", "summarise_batch",
           "summarise"]

#: deck keys a batch may vary (one value per design deck; designs_l1/designs_l2 one length, or
#: an (n, k) array for k designs per deck); every other key is the base deck's
BATCH_KEYS = ("designs_l1", "designs_l2", "mass_per_length", "gravity", "target_x", "target_y", "tolerance_bound")
#: keys that change tables but not the summary (accepted and ignored)
BATCH_IGNORED = ("title", "ri2_levels", "crob_l1", "text_optimum_decimals")
#: keys whose deck checks do not involve other keys (a sweep validates each of their values once)
BATCH_INDEPENDENT = ("mass_per_length", "gravity", "tolerance_bound", "title", "crob_l1")

#: The column -> pass dependency table of the batch summary: the passes each column of
#: :func:`summarise_batch` needs -- the kernel's (fortran/manipulator_summary.f90 ds_*):
#: 'indices' (RI1-RI3, reach conditions), 'target' (IK and torques at the target),
#: 'tolerance' (the tolerance box and its Monte Carlo check), and 'walk' (the C_rob walk of
#: Table 4.8, in Python).  The workspace figures and the design's own lengths need none.
#: Per-design columns ``<design>_<suffix>`` are in :data:`BATCH_PASS_SUFFIXES`.
BATCH_PASSES: dict[str, tuple[str, ...]] = {
    "design_l1_m": (), "design_l2_m": (), "design_ri1": ("indices",), "design_ri2": ("indices",),
    "design_ri3": ("indices",), "design_ri2_excess": ("indices",), "design_reaches_all": ("indices",),
    "design_crob_residual_m2": (), "design_tau_sum_signed_Nm": ("target",),
    "design_torque_demand_Nm": ("target",), "design_peak_torque_Nm": ("target",),
    "design_status": ("indices", "target"), "sweep_min_l1_m": ("walk",),
    "sweep_min_l2_m": ("walk",), "sweep_min_row": ("walk",), "sweep_min_reaches_workspace": ("walk",),
}
BATCH_PASS_SUFFIXES: dict[str, tuple[str, ...]] = {
    "_tau1_Nm": ("target",), "_tau2_Nm": ("target",), "_dl_m": ("tolerance",), "_mc_max_m": ("tolerance",),
    "_reaches_workspace": ("tolerance",),
}


def _passes(wanted: Collection[str] | None) -> set[str]:
    """The passes columns ``wanted`` need (None: all)."""
    if wanted is None:
        return {"indices", "target", "tolerance", "walk"}
    out: set[str] = set()
    for c in wanted:
        if c in BATCH_PASSES:
            out.update(BATCH_PASSES[c])
        elif c.startswith("sweep_min_"):   # every column of the C_rob walk
            out.add("walk")
        else:
            out.update(*(p for sfx, p in BATCH_PASS_SUFFIXES.items() if c.endswith(sfx)))
    return out


#: C_rob walks cached per distinct (target, mass per length, g) and base deck: an optimiser
#: asks for the same one at every population
_WALKS: dict[tuple, dict[str, Any]] = {}


def _as_params(base: Mapping[str, Any]) -> Params:
    if isinstance(base, Params):
        return base
    from pathlib import Path
    return Params("manipulator", Path("batch"), dict(base), {}, 1)


def _with(p: Params, **values: Any) -> Params:
    """``p`` with some values replaced (same deck lines)."""
    return Params(p.group, p.path, {**p, **values}, p._lines, p.line, p.given)


def _column(base: Mapping[str, Any], key: str, v: Any, n: int, check) -> np.ndarray:
    a = np.broadcast_to(np.asarray(v, dtype=np.float64), (n,))
    bad = ~np.isfinite(a) | ~check(a)
    if bad.any():
        i = int(np.argmax(bad))
        raise batch_error(base, key, f"design {i} has {float(a[i])!r}")
    return a


def _lengths(base: Mapping[str, Any], columns: dict[str, Any], n: int, conv: Conv
             ) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Design names and lengths l1, l2 (n, k) [m]: swept, the base deck's, or the optima on C_rob."""
    if "designs_l1" not in columns and "designs_l2" not in columns:
        names, l1, l2 = design_list(_as_params(base), conv)
        return names, np.broadcast_to(l1, (n, l1.size)), np.broadcast_to(l2, (n, l2.size))
    out = []
    for key in ("designs_l1", "designs_l2"):
        v = columns[key] if key in columns else base[key]
        if v is None:
            raise batch_error(base, key, "designs_l1 and designs_l2 must be given together")
        a = np.asarray(v, dtype=np.float64)
        a = a.reshape(n, -1) if key in columns else np.broadcast_to(a.ravel(), (n, a.size))
        bad = ~np.isfinite(a) | ~(a > 0)
        if bad.any():
            i = int(np.argmax(bad.any(1)))
            raise batch_error(base, key, f"design {i} has {a[i].tolist()!r} (lengths must be positive and finite)")
        out.append(a)
    l1, l2 = out
    if l1.shape != l2.shape:
        raise batch_error(base, "designs_l2", f"gives {l2.shape[1]} lengths per design but designs_l1 gives {l1.shape[1]}")
    k = l1.shape[1]
    names = base["design_names"]
    if names is not None and len(names) != k:
        raise batch_error(base, "design_names", f"gives {len(names)} names for {k} designs")
    return list(names or [f"Design {i + 1}" for i in range(k)]), l1, l2


def _walk(p: Params, conv: Conv, tx: float, ty: float, mpl: float, g: float) -> dict[str, Any]:
    """Summary columns of the C_rob walk (Table 4.8) for one target, mass per length and g."""
    key = (p.path, tuple(sorted((k, repr(v)) for k, v in p.items() if k != "title")), tx, ty, mpl, g)
    if key not in _WALKS:
        if len(_WALKS) > 4096:
            _WALKS.clear()
        _, sweep = table_4_8(_with(p, target_x=tx, target_y=ty, mass_per_length=mpl, gravity=g), conv)
        _WALKS[key] = sweep_columns(sweep)
    return _WALKS[key]


@contract_doc
def summarise_batch(base: Mapping[str, Any], columns: Mapping[str, Any] | None = None,
                    wanted: Collection[str] | None = None) -> pd.DataFrame:
    """Summarise many &manipulator design decks in one Fortran call: one row per deck.

    ``base``: a validated ``&manipulator`` Params.  ``columns``: {key: n values} for keys in
    BATCH_KEYS (``'manipulator.gravity'`` is accepted for ``'gravity'``); scalars broadcast;
    ``designs_l1``/``designs_l2`` n lengths [m] (one design per deck) or an (n, k) array.
    Lengths [m], ``mass_per_length`` [kg/m], ``gravity`` [m/s^2], target [m], tolerance bound [m].
    Returns the columns of the single run's summary with its values (to the last printed
    digit; the first design's torque and indices to the last bit), missing figures as NaN,
    and ``design_status`` (analysis.DESIGN_STATUS) saying why a figure is missing.
    A bad value raises DeckError (deck, line and key of the base deck; the design's index in the
    message) or ValueError for a plain mapping.  About 0.5 us per design on one core
    (bench/bench_manipulator.py), a tenth of it in the kernel.  ``wanted``: only these
    columns, computed by only the passes they need (:data:`BATCH_PASSES`; the same values as
    in a full summary); None: all.

    Parameters
    ----------
    base : mapping
        A validated ``&manipulator`` Params.
    columns : mapping of str to array, optional
        {key: n values} for keys in ``BATCH_KEYS``, in the deck's units (m, kg/m, m/s^2).
    wanted : collection of str, optional
        Only these columns; None: all.

    Returns
    -------
    pandas.DataFrame
        One row per deck: the single run's summary columns (units in their names: ``_m``,
        ``_Nm``), missing figures as NaN, and ``design_status``.

    %(batch_raises)s
    """
    out = _arrays(base, columns, wanted)
    if wanted is not None:
        names = set(wanted)
        out = {k: v for k, v in out.items() if k in names}
    return pd.DataFrame(out)


def _arrays(base: Mapping[str, Any], columns: Mapping[str, Any] | None,
            wanted: Collection[str] | None = None) -> dict[str, np.ndarray]:
    """The columns of :func:`summarise_batch` as numpy arrays (what :func:`summarise` reads);
    the passes ``wanted`` needs only (None: all)."""
    passes = _passes(wanted)
    p = _as_params(base)
    columns = {k.partition(".")[2] if k.startswith("manipulator.") else k: v for k, v in (columns or {}).items()}
    unknown = [k for k in columns if k not in BATCH_KEYS and k not in BATCH_IGNORED]
    if unknown:
        raise batch_error(base, unknown[0], f"not a &manipulator key the summary takes per design ({', '.join(BATCH_KEYS)})")
    columns = {k: v for k, v in columns.items() if k in BATCH_KEYS}
    sizes = {np.shape(v)[0] for v in columns.values() if np.ndim(v) > 0}
    if len(sizes) > 1:
        raise batch_error(base, None, f"batch columns have different lengths {sorted(sizes)}")
    n = sizes.pop() if sizes else 1
    if n == 0:
        return {k: v[:0] for k, v in _arrays(base, None).items()}
    ws = Workspace(np.asarray(p.points_x, dtype=np.float64), np.asarray(p.points_y, dtype=np.float64))
    conv = Conv(p.mode == "report", ws)
    names, l1, l2 = _lengths(base, columns, n, conv)
    k = l1.shape[1]
    if ("target_x" in columns or "target_y" in columns) and \
            (columns.get("target_x", p.target_x) is None or columns.get("target_y", p.target_y) is None):
        raise batch_error(base, "target_y" if "target_x" in columns else "target_x",
                         "target_x and target_y must be given together")
    tx0, ty0 = (p.target_x, p.target_y) if p.target_x is not None else (float(ws.x[0]), float(ws.y[0]))
    finite = lambda a: np.ones(a.shape, bool)
    tx = _column(base, "target_x", columns.get("target_x", tx0), n, finite)
    ty = _column(base, "target_y", columns.get("target_y", ty0), n, finite)
    if ((tx == 0.0) & (ty == 0.0)).any():
        i = int(np.argmax((tx == 0.0) & (ty == 0.0)))
        raise batch_error(base, "target_x", f"design {i}: the target point is the base (0, 0)")
    mpl = _column(base, "mass_per_length", columns.get("mass_per_length", p.mass_per_length), n, lambda a: a > 0)
    g = _column(base, "gravity", columns.get("gravity", p.gravity), n, lambda a: a >= 0)
    eps = _column(base, "tolerance_bound", columns.get("tolerance_bound", p.tolerance_bound), n, lambda a: a >= 1e-9)

    # every design of every deck in one kernel call (rows deck-major: deck i, design j -> i k + j)
    sp = SummaryParam
    prm = np.empty((n * k, len(sp)), dtype=np.float64, order="F")
    prm[:, sp.L1], prm[:, sp.L2] = l1.ravel(), l2.ravel()
    for col, v in ((sp.TARGET_X, tx), (sp.TARGET_Y, ty), (sp.MASS_PER_LENGTH, mpl), (sp.GRAVITY, g),
                   (sp.TOLERANCE_BOUND, eps)):
        prm[:, col] = np.repeat(v, k)
    rates = [*p.joint_rates, *p.joint_accels]
    unit = _mc_samples(p.mc_seed, p.mc_samples)
    bits = sum(b for k, b in kernel.MANIPULATOR_PASSES.items() if k in passes)
    res = kernel.manipulator_design_summaries(ws.x, ws.y, prm, p.elbow, rates, p.error_measure, unit, passes=bits)
    r = {c: res[:, i].reshape(n, k) for i, c in enumerate(kernel.MANIPULATOR_SUMMARY_COLUMNS)}
    ok = r["target_status"] == STATUS["ok"]
    tau1, tau2 = r["tau1"], r["tau2"]
    if conv.report and "target" in passes:
        tau1, tau2 = _report_torques(p, prm, r, n, k)

    out: dict[str, Any] = {c: np.full(n, v, dtype=object if isinstance(v, str) else None)
                           for c, v in workspace_columns(p, ws, conv).items()}
    nan = lambda v, m: np.where(m, v, np.nan)
    for j, name in enumerate(names):
        key = name.lower().replace(" ", "_")
        out[f"{key}_tau1_Nm"] = nan(tau1[:, j], ok[:, j])
        out[f"{key}_tau2_Nm"] = nan(tau2[:, j], ok[:, j])
    reached = r["reaches_points"] > 0
    for j, name in enumerate(names):
        key = name.lower().replace(" ", "_")
        out[f"{key}_dl_m"] = nan(r["dl1"][:, j], reached[:, j])
        out[f"{key}_mc_max_m"] = nan(r["mc_max"][:, j], reached[:, j])
        out[f"{key}_reaches_workspace"] = reached[:, j].copy()
    d1, d2 = l1[:, 0].copy(), l2[:, 0].copy()
    ri1, ri2, reach = r["ri1"][:, 0], r["ri2"][:, 0], r["reach"][:, 0] > 0
    out.update({"design_l1_m": d1, "design_l2_m": d2, "design_ri1": nan(ri1, ri1 > 0), "design_ri2": ri2.copy(),
                "design_ri3": r["ri3"][:, 0].copy(), "design_ri2_excess": ri2 - math.sqrt(ws.n),
                "design_reaches_all": reach, "design_crob_residual_m2": d1 * d1 + d2 * d2 - ws.mean_d2,
                **design_torque_columns(tau1[:, 0], tau2[:, 0], ok[:, 0]),
                "design_status": _status(reach, ok[:, 0], ri1)})
    if "walk" not in passes:
        return out
    # the C_rob walk: once per distinct target, mass per length and g
    codes = [np.unique(v, return_inverse=True) for v in (tx, ty, mpl, g)]
    flat = np.ravel_multi_index([c[1].ravel() for c in codes], [len(c[0]) for c in codes])
    first, inv = np.unique(flat, return_index=True, return_inverse=True)[1:]
    walks = [_walk(p, conv, float(tx[i]), float(ty[i]), float(mpl[i]), float(g[i])) for i in first]
    for c in ("sweep_min_tau_sum_signed_Nm", "sweep_min_l1_m", "sweep_min_l2_m", "sweep_min_row",
              "sweep_min_reaches_workspace"):
        vals = [w.get(c) for w in walks]
        if all(v is None for v in vals):
            continue
        kind = object if any(v is None for v in vals) else type(vals[0])
        out[c] = np.array(vals, dtype=kind)[inv.ravel()]
    return out


#: Monte Carlo samples that can be a box's worst, per (seed, count)
_SAMPLES: dict[tuple[int, int], np.ndarray] = {}


def _mc_samples(seed: int, count: int) -> np.ndarray:
    """The run's Monte Carlo samples u in [-1, 1]^2 (same seed, same draws), reduced to those that
    can give the largest error.  The box is dl1 = dl2 = dl, so a sample's squared error is
    dl^2 (n alpha + 2 C beta) (global) or dl^2 max(alpha + 2 beta c2max, alpha + 2 beta c2min)
    (per point) with alpha = u1^2 + u2^2, beta = u1 u2: linear in (alpha, beta) for every design,
    so its maximum over the samples is at a vertex of their convex hull in (alpha, beta) --
    some dozens of the 10^5 samples, found once (scipy's Qhull) and scanned for every design."""
    key = (int(seed), int(count))
    if key not in _SAMPLES:
        unit = np.random.default_rng(seed).uniform(-1.0, 1.0, size=(count, 2))
        if count > 64:
            from scipy.spatial import ConvexHull, QhullError
            pts = np.stack([(unit ** 2).sum(1), unit[:, 0] * unit[:, 1]], 1)
            try:
                unit = unit[np.sort(ConvexHull(pts).vertices)]
            except (QhullError, ValueError):   # degenerate (all on a line): keep every sample
                pass
        if len(_SAMPLES) > 16:
            _SAMPLES.clear()
        _SAMPLES[key] = np.asfortranarray(unit)
    return _SAMPLES[key]


def _status(reach: np.ndarray, target_ok: np.ndarray, ri1: np.ndarray) -> np.ndarray:
    """analysis.design_status over arrays (the same order of the checks)."""
    out = np.full(reach.shape, "ok", dtype=object)
    out[~(ri1 > 0)] = design_status(True, True, 0.0)
    out[~target_ok] = design_status(True, False, 1.0)
    out[~reach] = design_status(False, True, 1.0)
    return out


def _report_torques(p: Params, prm: np.ndarray, r: dict[str, np.ndarray], n: int, k: int
                    ) -> tuple[np.ndarray, np.ndarray]:
    """mode = 'report': the torques of the report's Table 4.7 -- the printed Table 4.5 angles
    (printed_angles_deg, or the IK angles rounded to 2 dp with theta2 the interior angle)."""
    t1, t2 = r["theta1_deg"].ravel(), r["theta2_deg"].ravel()
    if p.printed_angles_deg is not None and len(p.printed_angles_deg) == 2 * k:
        used = np.tile(np.asarray(p.printed_angles_deg, dtype=np.float64).reshape(-1, 2), (n, 1))
    else:
        used = np.array([[round_half_up(a, 2), round_half_up(180.0 - abs(b), 2)] for a, b in zip(t1, t2)])
        used = used.reshape(-1, 2)
    sp = SummaryParam
    tau = np.empty((n * k, len(Torque)))
    for gv in np.unique(prm[:, sp.GRAVITY]):      # the torque kernel takes one g per call
        m = prm[:, sp.GRAVITY] == gv
        l1, l2, mpl = prm[m, sp.L1], prm[m, sp.L2], prm[m, sp.MASS_PER_LENGTH]
        tau[m] = kernel.manipulator_torques(l1, l2, np.radians(used[m, 0]), np.radians(used[m, 1]),
                                             p.joint_rates, p.joint_accels, mpl * l1, mpl * l2, float(gv))
    return tau[:, Torque.TAU1].reshape(n, k), tau[:, Torque.TAU2].reshape(n, k)


@contract_doc
def summarise(params: Params) -> dict[str, Any]:
    """Summarise the design of one deck: one row of :func:`summarise_batch`.

    What a sweep or an optimiser needs when it writes no per-case files.  Equals
    ``run(params).summary`` wherever a run succeeds, and also answers for a design the run
    refuses (one that cannot reach the workspace or the target), with its ``design_status``.

    %(summarise)s
    """
    out = {}
    for key, col in _arrays(params, None).items():
        v = col[0]
        if isinstance(v, float) and math.isnan(v):
            v = None
        elif isinstance(v, np.bool_):
            v = bool(v)
        elif isinstance(v, np.integer):
            v = int(v)
        elif isinstance(v, np.floating):
            v = float(v)
        out[key] = v
    if out.get("sweep_min_tau_sum_signed_Nm") is None:   # as a run: no C_rob row reaches the target
        for key in ("sweep_min_tau_sum_signed_Nm", "sweep_min_l1_m", "sweep_min_l2_m", "sweep_min_row",
                    "sweep_min_reaches_workspace"):
            out.pop(key, None)
    return out


def batch_refusal(row: Mapping[str, Any]) -> str | None:
    """Why the study's own run refuses the design of a batch row, or None: an optimiser ranks such a
    row as the case-by-case route does (the run refuses designs that violate the reach conditions)."""
    if row.get("design_status") == "unreachable":
        return ("designs_l1: design 1 violates the reach conditions |l1 - l2| <= r and l1 + l2 >= R: "
                "it cannot reach every workspace point")
    return None
