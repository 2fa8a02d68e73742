"""The section's three estimates of t_min: quadratic fits of the dual-response and Taguchi data,
and the tolerance analysis of the known and the fitted relation (plain numpy: statistics, not
mechanism physics, so no Fortran kernel)."""
from __future__ import annotations

import math
from decimal import Decimal
from typing import Any

import numpy as np

from driver._deck import Params
from driver._errors import DriverError

__all__ = ["MAX_COND", "FitError", "quadratic_fit", "tmin", "stationary", "analyse"]


#: largest condition number of the normal equations X'X accepted for a quadratic fit
MAX_COND = 1e12


class FitError(DriverError, ValueError):
    """The targets do not determine a quadratic (singular or ill-conditioned normal equations)."""


def quadratic_fit(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Fit a least-squares quadratic b0 + b1 t + b2 t^2 through (t, y): B = (X'X)^-1 X'Y (eq. 2.4).

    Parameters
    ----------
    t : numpy.ndarray
        Abscissae (targets of X), in the units of the data.
    y : numpy.ndarray
        Ordinates (means, or ln of standard deviations).

    Returns
    -------
    numpy.ndarray
        (b0, b1, b2).

    Raises
    ------
    FitError
        X'X is singular or its condition number exceeds MAX_COND (targets too few or too
        close together for the digits of a double).

    Examples
    --------
    >>> import numpy as np
    >>> from driver.robust_example import quadratic_fit
    >>> b = quadratic_fit(np.array([0.0, 1.0, 2.0, 3.0]), np.array([1.0, 2.0, 5.0, 10.0]))  # y = 1 + t^2
    >>> [round(float(v), 9) + 0.0 for v in b]
    [1.0, 0.0, 1.0]
    """
    X = np.vander(np.asarray(t, float), 3, increasing=True)
    A = X.T @ X
    cond = np.linalg.cond(A)
    if not cond < MAX_COND:
        raise FitError(f"the normal equations of the quadratic fit are "
                       f"{'singular' if not np.isfinite(cond) else f'ill-conditioned (condition number {cond:.2g})'}: "
                       "the targets do not determine a quadratic")
    return np.linalg.solve(A, X.T @ np.asarray(y, float))


def tmin(b: np.ndarray) -> float:
    """-b1 / (2 b2): stationary point of a quadratic (eqs 2.9, 2.13, 2.15)."""
    return float(-b[1] / (2.0 * b[2]))


def _flat(b: np.ndarray, t: np.ndarray) -> bool:
    """b2 is zero to the fit's rounding: its term is below 1e-9 of the fitted values' size over
    the targets' span."""
    t = np.asarray(t, float)
    span = float(t.max() - t.min())
    size = float(np.max(np.abs(b[0] + b[1] * t + b[2] * t * t))) + abs(b[1]) * span
    return abs(b[2]) * span * span <= 1e-9 * max(size, 1e-300)


def stationary(b: np.ndarray, t: np.ndarray, need_minimum: bool) -> tuple[float | None, str]:
    """t_min of a fitted quadratic, or None with the reason in words.

    ``need_minimum``: the quadratic itself is minimised (ln sigma fits 2.8/2.12), so b2 must be
    positive; otherwise (tolerance analyses 2.2/2.14/2.15) only b2 != 0 is needed, as
    sigma_Y^2 = (b1 + 2 b2 t)^2 sigma_x^2 + 2 b2^2 sigma_x^4 is least at -b1/(2 b2) either way.
    """
    if _flat(b, t):
        return None, (f"no t_min: the fitted quadratic is flat (b2 = {b[2]:.3g} is rounding noise), "
                      "the data show no curvature")
    tm = tmin(b)
    if need_minimum and b[2] < 0:
        return None, (f"no t_min: b2 = {b[2]:.6g} < 0, the fitted quadratic has a maximum at t = {tm:.3f}; "
                      "the data show no robust target inside their range")
    return tm, ""


def _r(x: np.ndarray, d: int) -> np.ndarray:
    return np.array([float(Decimal(float(v)).quantize(Decimal(1).scaleb(-d), rounding="ROUND_HALF_UP"))
                     for v in np.atleast_1d(x)])


def analyse(p: Params, report: bool) -> dict[str, Any]:
    """Compute every section-2.3 result for one mode (see the module docstring).

    Parameters
    ----------
    p : Params
        Validated ``&robust_example`` keys.
    report : bool
        Fit the printed (rounded) statistics, as the report does (``mode = 'report'``).

    Returns
    -------
    dict
        The tables (``mean22``, ``std22``, ``t24``, ``mean25``, ``std25``), the fitted
        coefficients (``eq27``, ``eq28``, ``eq211``, ``eq212``), the estimates of t_min
        (``eq22_tmin``, ``eq29``, ``eq213``, ``eq215``, in the units of X, each with a
        ``_why`` when there is none) and ``sigma_at``, the std of Y at a target.

    Raises
    ------
    DeckError
        The data admit no fit (equal observations, targets too close), naming the key.
    """
    b = np.array(p.true_coeffs, float)
    sx = p.sigma_x
    out: dict[str, Any] = {"eq22_slope": (b[1], 2 * b[2]), "eq22_quartic": 2 * b[2] ** 2, "eq22_tmin": tmin(b)}
    t = np.array(p.dual_targets, float)
    y = np.array(p.dual_y, float).reshape(t.size, -1)
    mean, std = y.mean(1), y.std(1, ddof=1)
    if np.any(std <= 0):
        raise p.error("dual_y", "a target's observations are all equal: ln(std) is undefined")
    out.update(t22=t, mean22=mean, std22=std)
    try:
        out["eq27"] = quadratic_fit(t, mean)
        out["eq28"] = quadratic_fit(t, np.log(_r(std, 7) if report else std))
    except FitError as exc:
        raise p.error("dual_targets", str(exc)) from None
    out["eq29"], out["eq29_why"] = stationary(out["eq28"], t, need_minimum=True)
    tt, off = np.array(p.taguchi_targets, float), np.array(p.taguchi_offsets, float)
    yt = np.array(p.taguchi_y, float).reshape(tt.size, off.size, -1)
    t24 = yt.mean(2)
    out.update(t24_targets=tt, t24_offsets=off, t24=t24, levels=(tt[:, None] + off[None, :]))
    m25, s25 = t24.mean(1), t24.std(1, ddof=1)
    if np.any(s25 <= 0):
        raise p.error("taguchi_y", "a target's row means are all equal: ln(std) is undefined")
    out.update(mean25=m25, std25=s25)
    try:
        out["eq211"] = quadratic_fit(tt, _r(m25, 4) if report else m25)
        out["eq212"] = quadratic_fit(tt, np.log(_r(s25, 7) if report else s25))
    except FitError as exc:
        raise p.error("taguchi_targets", str(exc)) from None
    out["eq213"], out["eq213_why"] = stationary(out["eq212"], tt, need_minimum=True)
    b27 = out["eq27"]
    if report:  # (2.14) is written from the printed 6-significant-digit coefficients of (2.7)
        b27 = np.array([float(f"{v:.6g}") for v in b27])
    out["eq214_slope"] = (b27[1], 2 * b27[2])
    out["eq214_quartic"] = 2 * b27[2] ** 2
    out["eq215"], out["eq215_why"] = stationary(b27, t, need_minimum=False)
    out["sigma_at"] = lambda tx, bb=b27: math.sqrt((bb[1] + 2 * bb[2] * tx) ** 2 * sx ** 2 + 2 * bb[2] ** 2 * sx ** 4)
    return out
