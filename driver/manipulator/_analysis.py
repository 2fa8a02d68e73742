"""The computations of a &manipulator run that are not tables: workspace and C_rob conventions,
optimum designs, joint angles at the target, the C_rob sweep's arm lengths and tolerance synthesis.

Physics (IK, Jacobian, indices, torques, positioning errors) is in fortran/manipulator.f90.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal
from typing import Any

import numpy as np

from driver._deck import Params
from driver.manipulator import _kernel as kernel

__all__ = ["STATUS", "SIGNIFICANT", "DESIGN_STATUS", "round_half_up", "percentile", "Workspace", "Conv", "optima",
           "tolerance_box", "design_status", "workspace_columns", "sweep_columns", "design_torque_columns"]

STATUS = kernel.MANIPULATOR_STATUS
#: significant digits of every number column outside report mode (the report's fixed decimals
#: would print a 1e-7 m tolerance as 0.000000 and a g of 3.71 as 3.7)
SIGNIFICANT = 6


def round_half_up(x: float, d: int) -> float:
    """Round half away from zero, as the report's printed values are.

    Parameters
    ----------
    x : float
        The value.
    d : int
        Decimals to keep.

    Returns
    -------
    float
        ``x`` rounded to ``d`` decimals, a half rounded away from zero.

    Examples
    --------
    >>> from driver.manipulator import round_half_up
    >>> round_half_up(0.125, 2), round_half_up(-0.125, 2), round(0.125, 2)   # Python's round: half to even
    (0.13, -0.13, 0.12)
    """
    q = Decimal(1).scaleb(-d)
    return float(Decimal(float(x)).quantize(q, rounding=ROUND_HALF_UP))


@dataclass
class Workspace:
    """Workspace points and the quantities derived from them (lengths in m).

    Attributes
    ----------
    x, y : numpy.ndarray
        Coordinates of the points P_i, base A at the origin, m.
    """

    x: np.ndarray
    y: np.ndarray

    @property
    def n(self) -> int:
        """Number of workspace points."""
        return int(self.x.size)

    @property
    def d2(self) -> np.ndarray:
        """Squared distances d^2(A, P_i) [m^2]."""
        return self.x ** 2 + self.y ** 2

    @property
    def r(self) -> float:
        """Smallest distance min d(A, P_i) from the base to a point [m]."""
        return float(np.sqrt(self.d2.min()))

    @property
    def R(self) -> float:
        """Largest distance max d(A, P_i) from the base to a point [m]."""
        return float(np.sqrt(self.d2.max()))

    @property
    def mean_d2(self) -> float:
        """Mean squared distance, mean d^2 = l1^2 + l2^2 on C_rob [m^2] (eq. 4.12)."""
        return float(self.d2.mean())


@dataclass
class Conv:
    """Which conventions to use: the report's (``report=True``) or the correct ones."""

    report: bool
    ws: Workspace

    @property
    def radius(self) -> float:
        """C_rob radius [m]: rounded to 3 dp in the report."""
        r = math.sqrt(self.ws.mean_d2)
        return round_half_up(r, 3) if self.report else r

    @property
    def c_pairs(self) -> float:
        """l1^2 + l2^2 for Table 4.2 and the optima: radius^2 (report) or mean d^2."""
        return self.radius ** 2 if self.report else self.ws.mean_d2

    @property
    def c_sweep(self) -> float:
        """l1^2 + l2^2 for Table 4.8: round(radius^2, 2) in the report (51.49)."""
        return round_half_up(self.radius ** 2, 2) if self.report else self.ws.mean_d2


def design_list(p: Params, conv: Conv) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Names and lengths [m] of the designs: from the deck or the optima on C_rob."""
    if p.designs_l1 is not None:
        names = p.design_names or [f"Design {i + 1}" for i in range(len(p.designs_l1))]
        return list(names), np.array(p.designs_l1, float), np.array(p.designs_l2, float)
    opt = optima(conv.c_pairs)
    l1 = np.array([opt["dexterity"][0], opt["manipulability"][0]])
    l2 = np.array([opt["dexterity"][1], opt["manipulability"][1]])
    if conv.report:  # Table 4.4 prints 2 dp and Tables 4.5-4.7 use the printed lengths
        l1 = np.array([round_half_up(v, 2) for v in l1])
        l2 = np.array([round_half_up(v, 2) for v in l2])
    return ["Dexterity", "Workspace"], l1, l2


#: values of the summary column ``design_status`` (the first design's), and what they mean
DESIGN_STATUS = {"ok": "reaches every workspace point and the target; RI1 defined",
                 "unreachable": "violates the reach conditions (4.4) at some workspace point",
                 "target_unreachable": "reaches the workspace but not the torque target point (no torques)",
                 "singular": "sigma_min of the sensitivity Jacobian is 0: RI1 undefined"}


def design_status(reach: bool, target_ok: bool, ri1: float) -> str:
    """The first design's status (a DESIGN_STATUS key): the first problem in that order."""
    return "unreachable" if not reach else "target_unreachable" if not target_ok else \
        "singular" if not ri1 > 0 else "ok"


def optima(c: float) -> dict[str, tuple[float, float]]:
    """Find the dexterity and manipulability optima on the robust circle l1^2 + l2^2 = c.

    Parameters
    ----------
    c : float
        The circle's l1^2 + l2^2, m^2.

    Returns
    -------
    dict of str to tuple of float
        ``'dexterity'`` (l2 = l1 sqrt(2)/2) and ``'manipulability'`` (l1 = l2) -> (l1, l2), m.

    Examples
    --------
    >>> from driver.manipulator import optima
    >>> {k: tuple(round(v, 6) for v in lengths) for k, lengths in optima(3.0).items()}
    {'dexterity': (1.414214, 1.0), 'manipulability': (1.224745, 1.224745)}
    """
    return {"dexterity": (math.sqrt(2 * c / 3), math.sqrt(c / 3)),
            "manipulability": (math.sqrt(c / 2), math.sqrt(c / 2))}


# ----------------------------------------------------------------------------- tolerance synthesis

def _corner_patterns(l: int) -> np.ndarray:
    """The 2^(l-1) sign patterns of a box's corners up to an overall sign."""
    return np.array([(1.0,) + s for s in itertools.product((1.0, -1.0), repeat=l - 1)])


def _largest_box_two(mats: list[np.ndarray], eps: float) -> np.ndarray:
    """The largest box (u1, u2) of two half-widths inside every constraint, exactly.

    Each constraint's worst corner is s = (1, sign S12): S11 u1^2 + 2|S12| u1 u2 + S22 u2^2 <= eps^2.
    With r = u2 / u1 the largest u1^2 is eps^2 / max_S q_S(r), q_S(r) = S11 + 2|S12| r + S22 r^2,
    and the volume u1 u2 = eps^2 min_S r / q_S(r).  Each r / q_S(r) rises to its peak at
    r = sqrt(S11 / S22) and falls after it, so their minimum peaks either at one of those points or
    where two constraints cross (q_a(r) = q_b(r), a quadratic in r): every such r is tried and the
    largest volume kept.  No iteration, no tolerance, no dependence on the BLAS kernel.
    """
    a = [float(S[0, 0]) for S in mats]
    b = [2.0 * abs(float(S[0, 1])) for S in mats]
    c = [float(S[1, 1]) for S in mats]
    if min(a) <= 0.0 or min(c) <= 0.0:
        raise ValueError("a link length that moves no point: its tolerance is unbounded")
    peaks = [math.sqrt(ai / ci) for ai, ci in zip(a, c)]
    # below the smallest peak every bound rises, above the largest every one falls: the optimum
    # lies between them, and so does every candidate worth trying
    lo, hi = min(peaks), max(peaks)
    cand = list(peaks)
    for i, j in itertools.combinations(range(len(mats)), 2):
        qa, qb, qc = c[i] - c[j], b[i] - b[j], a[i] - a[j]        # qa r^2 + qb r + qc = 0
        if qa == 0.0:
            if qb != 0.0 and abs(qc) <= hi * abs(qb):
                cand.append(-qc / qb)
            continue
        disc = qb * qb - 4.0 * qa * qc
        if disc < 0.0:
            continue
        w = -0.5 * (qb + math.copysign(math.sqrt(disc), qb))    # the two roots without cancellation
        if abs(w) <= hi * abs(qa):
            cand.append(w / qa)
        if w != 0.0 and abs(qc) <= hi * abs(w):
            cand.append(qc / w)
    r = np.array([x for x in cand if lo <= x <= hi])
    q = (np.array(a)[:, None] + np.array(b)[:, None] * r + np.array(c)[:, None] * r * r).max(axis=0)
    k = int(np.argmax(r / q))
    u1 = eps / math.sqrt(float(q[k]))
    return np.array([u1, float(r[k]) * u1])


def tolerance_box(blocks: np.ndarray, eps: float, measure: str = "global") -> dict[str, Any]:
    """Find the largest tolerance box on the link lengths (Caro 2005, eq. 2.45).

    Feasible region: ||J_x du||_2 <= eps (``global``, J_x = blocks stacked) or
    max_i ||J_xi du||_2 <= eps (``per_point``), for every corner du = s * u of the box.
    Maximises prod u_i over all 2^(l-1) corner patterns: for l = 2 (the 2R arm) exactly, by
    trying every ratio u2/u1 at which the optimum can lie (`_largest_box_two`), and alongside
    the closed form u_i = eps / sqrt(2 S_ii (1 + |rho|)) of the binding corner; for l > 2 by
    SLSQP (scipy, imported only then).

    Parameters
    ----------
    blocks : numpy.ndarray
        (k, 2, l) sensitivity blocks J_xi: the position of point i per unit change of each
        of the l link lengths, dimensionless.
    eps : float
        Largest allowed positioning error, m.
    measure : {'global', 'per_point'}, default 'global'
        The error measure: all points stacked, or the worst point.

    Returns
    -------
    dict
        ``u`` the half-widths of the largest box (m), ``closed`` the closed form for l = 2 (m;
        else None), ``converged`` (True for l = 2) and ``message``.
    """
    k, _, l = blocks.shape
    pats = _corner_patterns(l)
    mats = [blocks.reshape(2 * k, l).T @ blocks.reshape(2 * k, l)] if measure == "global" \
        else [b.T @ b for b in blocks]

    def worst(u: np.ndarray) -> np.ndarray:
        return np.array([(s * u) @ S @ (s * u) for S in mats for s in pats])

    if l == 2:
        cand = []
        for S in mats:
            rho = abs(S[0, 1]) / math.sqrt(S[0, 0] * S[1, 1])
            cand.append(eps / np.sqrt(2 * np.diag(S) * (1 + rho)))
        # with several constraints (per point) the symmetric S_ii = 1 case keeps u1 = u2
        closed = min(cand, key=lambda u: float(np.prod(u)))
        closed = closed * min(1.0, eps / math.sqrt(worst(closed).max()))
        return {"u": _largest_box_two(mats, eps), "closed": closed, "converged": True,
                "message": "every ratio at which the largest box can lie was tried"}
    from scipy.optimize import minimize  # l > 2 only: a 2R arm's run imports no scipy

    scale = eps / math.sqrt(max(m.trace() for m in mats))     # work with v = u / scale ~ 1

    def neg_log_volume(v: np.ndarray) -> float:
        return -np.sum(np.log(v))

    def neg_log_volume_grad(v: np.ndarray) -> np.ndarray:
        return -1.0 / v

    def inside(v: np.ndarray) -> np.ndarray:
        return 1.0 - worst(v * scale) / eps ** 2

    # scipy-stubs types a constraint dict's 'fun' as scalar-valued; SLSQP takes a vector of them
    res = minimize(neg_log_volume, np.full(l, 0.5), method="SLSQP", jac=neg_log_volume_grad,  # type: ignore[call-overload]
                   constraints=[{"type": "ineq", "fun": inside}],
                   bounds=[(1e-9, None)] * l, options={"ftol": 1e-13, "maxiter": 500})
    res.x = res.x * scale
    return {"u": np.asarray(res.x), "closed": None, "converged": bool(res.success),
            "message": str(res.message)}


def percentile(values: np.ndarray, q: float) -> float:
    """The q-th percentile of ``values`` as numpy's default ('linear') method gives it, bit for bit.

    ``np.percentile`` partitions around ``np.unique`` of its indices, whose first call imports
    ``numpy.ma`` (about 12 ms, 8 % of a manipulator case's start-up); two partition points and
    numpy's own interpolation formula give the same double.

    Parameters
    ----------
    values : numpy.ndarray
        One-dimensional, finite, at least one value.
    q : float
        Percentile, 0 <= q <= 100.

    Returns
    -------
    float
        The percentile, in the units of ``values``.
    """
    n = values.size
    v = (n - 1) * (q / 100.0)                # numpy's virtual index of the 'linear' method
    i = min(max(int(math.floor(v)), 0), n - 1)
    j = min(i + 1, n - 1)
    s = np.partition(values, (i, j)) if j != i else np.partition(values, i)
    a, b, g = float(s[i]), float(s[j]), v - i
    diff = b - a                              # numpy's _lerp: from the nearer end
    return a + diff * g if g < 0.5 else b - diff * (1.0 - g)


def sensitivity_blocks(th1: np.ndarray, th2: np.ndarray) -> np.ndarray:
    """J_xi = [[c1, c12], [s1, s12]] per workspace point (eq. 2.23), shape (k, 2, 2)."""
    return np.stack([np.stack([np.cos(th1), np.cos(th1 + th2)], -1),
                     np.stack([np.sin(th1), np.sin(th1 + th2)], -1)], 1)


def target_point(p: Params, ws: Workspace) -> tuple[float, float]:
    if p.target_x is not None:
        return float(p.target_x), float(p.target_y)
    return float(ws.x[0]), float(ws.y[0])


def design_angles(p: Params, conv: Conv, l1: np.ndarray, l2: np.ndarray) -> dict[str, np.ndarray]:
    """Joint angles [deg] of the designs at the target: printed (Table 4.5) and used for torques."""
    tx, ty = target_point(p, conv.ws)
    th1, th2, st = kernel.manipulator_ik(l1, l2, tx, ty, p.elbow)
    t1, t2 = np.degrees(th1), np.degrees(th2)
    if conv.report:
        shown2 = 180.0 - np.abs(t2)             # interior angle between the links
        shown1 = t1
        if p.printed_angles_deg is not None:
            used = np.array(p.printed_angles_deg, float).reshape(-1, 2)
        else:
            used = np.array([[round_half_up(a, 2), round_half_up(b, 2)] for a, b in zip(shown1, shown2)])
        used1, used2 = used[:, 0], used[:, 1]
    else:
        shown1, shown2, used1, used2 = t1, t2, t1, t2
    return {"shown1": shown1, "shown2": shown2, "used1": used1, "used2": used2, "status": st}


def sweep_l1_values(p: Params, conv: Conv) -> np.ndarray:
    if p.sweep_count > 0:
        return p.sweep_l1_start + p.sweep_l1_step * np.arange(p.sweep_count)
    top = math.sqrt(conv.c_sweep)
    n = int(math.floor((top - p.sweep_l1_start) / p.sweep_l1_step + 1e-9)) + 1
    if n < 1:
        raise p.error("sweep_l1_start", f"{p.sweep_l1_start:g} m is beyond the C_rob radius {top:.4f} m: the sweep "
                                        "along C_rob would be empty (give a smaller start or a sweep_count)")
    return p.sweep_l1_start + p.sweep_l1_step * np.arange(n)


# ----------------------------------------------------------------------------- summary columns

def workspace_columns(p: Params, ws: Workspace, conv: Conv) -> dict[str, Any]:
    """Summary columns of the workspace and of C_rob (lengths [m], areas [m^2])."""
    opt = optima(conv.c_pairs)
    return {"mode": p.mode, "n_points": ws.n, "r_m": ws.r, "R_m": ws.R, "mean_d2_m2": ws.mean_d2,
            "crob_radius_m": conv.radius, "crob_c_m2": conv.c_pairs, "ri2_min": math.sqrt(ws.n),
            "dexterity_l1_m": opt["dexterity"][0], "dexterity_l2_m": opt["dexterity"][1],
            "manipulability_l1_m": opt["manipulability"][0], "manipulability_l2_m": opt["manipulability"][1]}


def sweep_columns(sweep: dict) -> dict[str, Any]:
    """Summary columns of the least signed sum tau1 + tau2 along C_rob (Table 4.8's 'total
    torque', as the report ranks it); none when no row reaches the target."""
    tot = np.where(sweep["ok"], sweep["tau"].sum(1), np.inf)
    if not np.isfinite(tot).any():
        return {}
    k = int(np.argmin(tot))
    return {"sweep_min_tau_sum_signed_Nm": float(tot[k]), "sweep_min_l1_m": float(sweep["l1"][k]),
            "sweep_min_l2_m": float(sweep["l2"][k]), "sweep_min_row": k + 1,
            "sweep_min_reaches_workspace": bool(sweep["reach_all"][k])}


def design_torque_columns(tau1: Any, tau2: Any, ok: Any) -> dict[str, Any]:
    """The design's torques at the target [N m]: the signed sum tau1 + tau2 (the report's 'total
    torque': a negative torque lowers it, so it is no measure of effort), the demand |tau1| + |tau2|
    and the peak max(|tau1|, |tau2|) (the arm holds one pose: no trajectory, so no peak over time).
    Scalars or arrays (the batch path); missing (None / NaN) where ``ok`` is false."""
    t1, t2 = np.asarray(tau1, dtype=float), np.asarray(tau2, dtype=float)
    cols = {"design_tau_sum_signed_Nm": t1 + t2, "design_torque_demand_Nm": np.abs(t1) + np.abs(t2),
            "design_peak_torque_Nm": np.fmax(np.abs(t1), np.abs(t2))}
    if np.ndim(t1) == 0:
        return {k: (float(v) if ok else None) for k, v in cols.items()}
    return {k: np.where(ok, v, np.nan) for k, v in cols.items()}
