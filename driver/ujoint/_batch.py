"""Hooke-joint study: the batch path of sweeps and &optimize (many given designs, one kernel call).

See :func:`summarise_batch`; the kernel routine is ``chain_summaries`` in fortran/ujoint.f90.
"""
from __future__ import annotations

import math
import re
from collections.abc import Collection, Mapping
from typing import Any

import numpy as np
import pandas as pd

from driver._study import batch_error
from driver.ujoint._kernel import (
    UJOINT_MODELS,
    UJOINT_OBJECTIVES,
    UJOINT_PASSES,
    UJOINT_SUMMARY_COLUMNS,
    ujoint_geometry,
    ujoint_summaries,
)
from driver.ujoint._spec import DEG, KEYS, loads, origin_deg

#: deck keys a batch may vary (one value per design); list keys as one value per design (a
#: single-element list, as a sweep sets them), a (designs, k) array of whole lists, or element
#: columns 'key(i)' (:data:`BATCH_ELEMENTS`)
BATCH_KEYS = ("beta", "phi", "delta", "rho", "rpm", "model", "phasing", "objective", "n_grid")
#: keys the summary of an option-0 run does not depend on (accepted, ignored)
BATCH_IGNORED = ("table_step", "tidy_grid", "n_starts", "seed", "maxiter", "ftol", "beta_lower", "beta_upper",
                 "phi_lower", "phi_upper", "paper_beta", "paper_phi", "paper_u", "paper_nit", "paper_nfev", "paper_band")
#: keys whose deck checks do not involve other keys (a sweep validates each of their values once)
BATCH_INDEPENDENT = ("rpm", "objective", "n_grid", "table_step", "n_starts", "seed", "maxiter", "ftol",
                     "paper_u", "paper_nit", "paper_nfev")
#: The column -> pass dependency table of the batch summary: the kernel passes of
#: chain_summaries (fortran/ujoint.f90) each column of :func:`summarise_batch` needs; columns
#: with none are the design's own values.  ``beta_<k>_deg``/``phi_<k>_deg`` (one per joint and
#: shaft) need none either.
BATCH_PASSES: dict[str, tuple[str, ...]] = {
    "objective": ("objective",), "objective_trial": ("objective",), "pp_ratio": ("speed",),
    "omega_out_min_rpm": ("speed",), "omega_out_max_rpm": ("speed",), "beta_e_deg": ("equivalent",),
    "beta_res_deg": ("equivalent",), "peak_accel_rad_s2": ("speed",), "peak_accel_at_deg": ("speed",),
    "ratio_one_at_deg": ("speed",), "converged": (), "iterations": (),
    "evaluations": (),
}

#: list keys a batch column may set one element of, as 'phi(2)' (1-based; the optimiser's variables)
BATCH_ELEMENTS = ("beta", "phi", "delta", "rho")
_ELEMENT = re.compile(r"([a-z_]+)\((\d+)\)")


def _deck_deg(theta_rad: np.ndarray, origin: float, period: float) -> np.ndarray:
    """Kernel input angles [rad, from the normal] as the deck's [deg from its origin, in [0, period)]
    (the association of driver.ujoint._analysis.Chain.deck_deg: the same bits)."""
    d = np.mod(np.asarray(theta_rad, float) / DEG - origin, period)
    return np.where(d >= period - 1e-9, 0.0, d)


def batch_applies(base: Mapping[str, Any]) -> bool:
    """Tell whether designs on ``base`` can take the batch path.

    Parameters
    ----------
    base : mapping
        ``&ujoint`` keys (validated Params or a plain mapping).

    Returns
    -------
    bool
        True for option 0 without a load on the output shaft (options 1-3 run an optimisation
        per case, and the input torque of ``load_inertia``/``load_torque`` is found case by case).
    """
    return int(base["option"]) == 0 and loads(base) is None


def _design_count(base: Mapping[str, Any], columns: dict[str, Any]) -> int:
    sizes = {np.shape(v)[0] for v in columns.values() if np.ndim(v) > 0}
    if len(sizes) > 1:
        raise batch_error(base, None, f"batch columns have different lengths {sorted(sizes)}")
    return sizes.pop() if sizes else 1


def _list_column(base: Mapping[str, Any], key: str, whole: Any, elements: dict[int, Any], nd: int) -> np.ndarray | None:
    """(nd, k) float values of list key ``key`` [deg]: the base deck's list, or the batch's
    whole lists, with the batch's element columns set; None when neither gives the key."""
    if whole is not None:
        a = np.asarray(whole, dtype=np.float64)
        a = a[:, None] if a.ndim == 1 else (a.reshape(1, 1) if a.ndim == 0 else a)
        if a.ndim != 2:
            raise batch_error(base, key, f"a batch column of lists must be (designs, values); got shape {a.shape}")
        a = np.broadcast_to(a, (nd, a.shape[1]))
    elif base.get(key) is not None:
        a = np.broadcast_to(np.asarray(base[key], dtype=np.float64), (nd, len(base[key])))
    elif elements:
        raise batch_error(base, key, f"'{key}(i)' sets one element of '{key}', which the base deck does not give")
    else:
        return None
    if elements:
        a = a.copy()
        for i, v in elements.items():
            if not 1 <= i <= a.shape[1]:
                raise batch_error(base, key, f"'{key}({i})': '{key}' has {a.shape[1]} value(s)")
            a[:, i - 1] = np.broadcast_to(np.asarray(v, dtype=np.float64), (nd,))
    bad = ~np.isfinite(a)
    if bad.any():
        i = int(np.argmax(bad.any(axis=1)))
        raise batch_error(base, key, f"design {i} has a non-finite value")
    return a


def _choice_column(base: Mapping[str, Any], key: str, columns: dict[str, Any], nd: int) -> np.ndarray:
    v = np.broadcast_to(np.asarray(columns.get(key, base[key]), dtype=object), (nd,))
    allowed = KEYS[key].choices
    assert allowed is not None   # called for the choice keys only
    bad = ~np.isin(v, allowed)
    if bad.any():
        raise batch_error(base, key, f"must be one of {', '.join(map(repr, allowed))} (got {v[np.argmax(bad)]!r})")
    return v


def _codes(values: np.ndarray, table: dict[str, int]) -> np.ndarray:
    """Kernel codes of choice values (one lookup per distinct value)."""
    if values.size == 0:
        return np.zeros(0, dtype=np.int64)
    if values.strides == (0,) or (values == values[0]).all():
        return np.full(values.shape, table[values[0]], dtype=np.int64)
    uniq, inverse = np.unique(values.astype(str), return_inverse=True)
    return np.array([table[u] for u in uniq], dtype=np.int64)[inverse.ravel()]


def _number_column(base: Mapping[str, Any], key: str, columns: dict[str, Any], nd: int) -> np.ndarray:
    v = np.broadcast_to(np.asarray(columns.get(key, base[key]), dtype=np.float64), (nd,))
    if key == "rpm":
        bad = ~(np.isfinite(v) & (v > 0))
        what = "must be positive and finite"
    else:   # n_grid
        bad = ~(np.isfinite(v) & (v >= 8) & (v == np.round(v)))
        what = "must be a whole number of at least 8"
    if bad.any():
        i = int(np.argmax(bad))
        raise batch_error(base, key, f"design {i} has {float(v[i])!r}: {what}")
    return v


def summarise_batch(base: Mapping[str, Any], columns: Mapping[str, Any] | None = None,
                    wanted: Collection[str] | None = None) -> pd.DataFrame:
    """Summarise many Hooke-joint designs, one Fortran call per chain layout: one row per design.

    What it computes: for each design the figures of an option-0 run (``run(...).summary``:
    the design evaluated as given, nothing optimised), with identical values -- objective and
    objective_trial (the deck's objective over ``n_grid`` input angles per revolution,
    dimensionless), pp_ratio (max R - min R, R = omega_out/omega_in), omega_out_min_rpm and
    omega_out_max_rpm [rpm] at the input speed ``rpm``, beta_e_deg and beta_res_deg [deg]
    (closed-form equivalent angles; NaN where beta_res is undefined), peak_accel_rad_s2
    [rad/s^2] (max |d omega_out/dt| at constant input speed), converged (True), iterations
    and evaluations (0), beta_<k>_deg and phi_<k>_deg [deg] (the paper's phases, also when
    the design gives ``delta``).  The deck's own options 1-3 optimise inside each case; the
    batch path evaluates given designs (sweeps and the generic ``&optimize`` group) and
    refuses a base deck with option 1-3.

    ``base``: a validated ``&ujoint`` Params (or a mapping with its keys).  ``columns``:
    {key: values} for keys in BATCH_KEYS (``'ujoint.rpm'`` is accepted for ``'rpm'``);
    scalars broadcast.  Angles in degrees (as in the deck), ``rpm`` [rpm], ``model``,
    ``phasing``, ``objective`` as in the deck.  List keys (beta, phi, delta, rho): a 1-D
    column gives each design a single-element list (as a sweep does), a (designs, k) array
    whole lists, and ``'phi(2)'`` sets one element of the base deck's list.  A 3-D chain
    given by ``axes`` in the base deck keeps its geometry (beta and rho cannot vary then).
    A bad value raises DeckError (``base`` a deck's Params: deck, line and key of the base
    deck, the design's index in the message) or ValueError.  About 4 microseconds per
    3-joint design at 360 angles on one core (bench/bench_ujoint.py).  ``wanted``: only these
    columns, computed by only the kernel passes they need (:data:`BATCH_PASSES`; the same bits
    as in a full summary); None: all.

    Parameters
    ----------
    base : mapping
        A validated ``&ujoint`` Params (or a mapping with its keys), option 0.
    columns : mapping of str to array, optional
        {key: values} for keys in ``BATCH_KEYS``, in the deck's units (deg, rpm).
    wanted : collection of str, optional
        Only these summary columns; None: all.

    Returns
    -------
    pandas.DataFrame
        One row per design, the columns above (units in their names).

    Raises
    ------
    DeckError
        A bad value, when ``base`` is a deck's Params (deck, line and key of the base deck).
    ValueError
        A bad value otherwise.
    """
    if not batch_applies(base):
        raise batch_error(base, "option", f"option {base['option']} optimises inside each case; the batch path "
                                         "evaluates given designs (option 0)")
    cols: dict[str, Any] = {}
    elems: dict[str, dict[int, Any]] = {}
    for k, v in (columns or {}).items():
        k = k.partition(".")[2] if k.startswith("ujoint.") else k
        m = _ELEMENT.fullmatch(k)
        if m and m.group(1) in BATCH_ELEMENTS:
            elems.setdefault(m.group(1), {})[int(m.group(2))] = v
        elif k in BATCH_KEYS:
            cols[k] = v
        elif k not in BATCH_IGNORED:
            raise batch_error(base, k, f"not a &ujoint key the summary depends on ({', '.join(BATCH_KEYS)}; "
                                      f"elements of {', '.join(BATCH_ELEMENTS)} as 'key(i)')")
    nd = _design_count(base, {**cols, **{f"{k}({i})": v for k, e in elems.items() for i, v in e.items()}})
    axes = base.get("axes") is not None
    if axes and ({"beta", "rho"} & (set(cols) | set(elems))):
        raise batch_error(base, "axes", "the base deck's 'axes' fix the joint and plane angles; a batch cannot vary "
                                       "'beta' or 'rho' then")
    if axes:   # as joint_geometry (the base deck is valid): kernel radians -> degrees
        b_rad, r_rad, _ = ujoint_geometry(np.asarray(base["axes"], dtype=np.float64).reshape(-1, 3))
        beta: np.ndarray = np.broadcast_to(b_rad / DEG, (nd, b_rad.size))
        rho: np.ndarray | None = np.broadcast_to(r_rad / DEG, (nd, r_rad.size))
    else:
        given_beta = _list_column(base, "beta", cols.get("beta"), elems.get("beta", {}), nd)
        if given_beta is None:
            raise batch_error(base, None, "give the joint angles 'beta' (deg) or the shaft directions 'axes'")
        beta = given_beta
        rho = _list_column(base, "rho", cols.get("rho"), elems.get("rho", {}), nd)
    n = beta.shape[1]
    bad = ~((beta > -90.0) & (beta < 90.0))
    if bad.any():
        i = int(np.argmax(bad.any(axis=1)))
        raise batch_error(base, "beta", f"design {i}: a joint angle must lie strictly between -90 and 90 deg "
                                       f"(got {beta[i][bad[i]][0]})")
    given = {k for k in ("phi", "delta") if k in cols or k in elems or base.get(k) is not None}
    if len(given) > 1:
        raise batch_error(base, "delta", "give the phases either as 'phi' (90 = in phase) or as 'delta' "
                                        "(0 = in phase), not both")
    if given:
        key = given.pop()
        given_phi = _list_column(base, key, cols.get(key), elems.get(key, {}), nd)
        assert given_phi is not None   # the key is given
        phi = given_phi
        if phi.shape[1] != n - 1:
            raise batch_error(base, key, f"a chain of {n} joint(s) has {n - 1} intermediate shaft(s), so "
                                        f"{n - 1} phase(s); got {phi.shape[1]}")
        if key == "delta":
            phi = phi + 90.0
    else:
        phi = np.full((nd, n - 1), 90.0)
    if rho is not None and rho.shape[1] != n - 1:
        raise batch_error(base, "rho", f"a chain of {n} joint(s) has {n - 1} plane angle(s) between successive "
                                      f"joints; got {rho.shape[1]}")
    model = _choice_column(base, "model", cols, nd)
    phasing = _choice_column(base, "phasing", cols, nd)
    exact = model == "exact"
    if rho is not None and not exact.all():
        raise batch_error(base, "axes" if axes else "rho", "plane angles need model = 'exact' (the paper's model "
                                                          "is coplanar)")
    if exact.any() and ("phasing" in cols or "phasing" in getattr(base, "given", ())):
        raise batch_error(base, "phasing", "applies only to model = 'paper' (the exact chain has no phasing choice)")
    code = _codes(np.where(exact, "exact", phasing), UJOINT_MODELS)
    kind = _codes(_choice_column(base, "objective", cols, nd), UJOINT_OBJECTIVES)
    rpm = _number_column(base, "rpm", cols, nd)
    origin = origin_deg(base)
    grid = _number_column(base, "n_grid", cols, nd).astype(np.int64)
    res = np.empty((nd, len(UJOINT_SUMMARY_COLUMNS)))
    rho_rad = None if rho is None else rho * DEG
    layout = np.stack([code, kind, grid])
    groups: list[tuple[np.ndarray, slice | np.ndarray]]
    if nd == 0:
        groups = []
    elif (layout == layout[:, :1]).all():
        groups = [(layout[:, 0], slice(None))]
    else:
        keys, inverse = np.unique(layout, axis=1, return_inverse=True)
        groups = [(keys[:, g], np.flatnonzero(inverse.ravel() == g)) for g in range(keys.shape[1])]
    names = None if wanted is None else set(wanted)
    passes = (sum(UJOINT_PASSES.values()) if names is None else
              sum({UJOINT_PASSES[p] for c in names for p in BATCH_PASSES.get(c, ())}))
    for (c, k, m), rows in groups:
        res[rows] = ujoint_summaries(int(c), int(k), beta[rows] * DEG, phi[rows] * DEG,
                                     None if rho_rad is None else rho_rad[rows], int(m), passes=passes,
                                     theta0=origin * DEG)
    r = dict(zip(UJOINT_SUMMARY_COLUMNS, res.T))
    omega = rpm * 2.0 * math.pi / 60.0      # the association of Chain.omega (same bits)
    defined = r["beta_res_status"] == 0
    out = {"objective": r["objective"], "objective_trial": r["objective"],
           "pp_ratio": r["ratio_max"] - r["ratio_min"],
           "omega_out_min_rpm": rpm * r["ratio_min"], "omega_out_max_rpm": rpm * r["ratio_max"],
           "beta_e_deg": r["beta_e"] / DEG,
           "beta_res_deg": np.where(defined, r["beta_res"] / DEG, np.nan),
           "peak_accel_rad_s2": omega ** 2 * r["dratio_abs_max"],
           "peak_accel_at_deg": np.where(r["dratio_abs_max_at"] < 0, np.nan,
                                         _deck_deg(r["dratio_abs_max_at"], origin, 360.0)),
           "ratio_one_at_deg": np.where(r["ratio_one_at"] < 0, np.nan, _deck_deg(r["ratio_one_at"], origin, 180.0)),
           "converged": np.ones(nd, bool), "iterations": np.zeros(nd, np.int64),
           "evaluations": np.zeros(nd, np.int64)}
    out.update({f"beta_{k + 1}_deg": beta[:, k] for k in range(n)})
    out.update({f"phi_{k + 1}_deg": phi[:, k] for k in range(n - 1)})
    if names is not None:
        out = {k: v for k, v in out.items() if k in names}
    return pd.DataFrame(out, index=pd.RangeIndex(nd))
