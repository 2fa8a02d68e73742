"""Function generation with Freudenstein's equation (a four-bar whose rocker angle follows y(x)).

With O_A at the origin, O_B at (d, 0), crank a at angle theta2 and rocker c at angle theta4
(both from the ground line, as in the kernel), loop closure squared gives Freudenstein's
equation

    K1 cos(theta4) - K2 cos(theta2) + K3 = cos(theta2 - theta4),
    K1 = d/a,  K2 = d/c,  K3 = (a^2 - b^2 + c^2 + d^2) / (2 a c),

linear in K.  x maps linearly to the crank angle (x_start -> crank_start_deg, x_stop ->
crank_start_deg + crank_range_deg) and y(x) to the rocker angle likewise.  Three precision
points give K in closed form (a 3x3 solve; Chebyshev spacing x_j = mid - half cos((2j-1) pi/6)
minimises the structural error of a quadratic fit); more points give the least-squares K.
The equation holds on both assembly branches, so the result is checked by the exact kernel
on the requested branch: the structural error curve, its maximum, and whether every
precision point is met on that branch.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["chebyshev", "freudenstein", "links_from_k", "FunctionDesign"]


def chebyshev(x0: float, xf: float, n: int) -> np.ndarray:
    """Chebyshev spacing of n precision points on [x0, xf] (ascending)."""
    j = np.arange(1, n + 1)
    return 0.5 * (x0 + xf) - 0.5 * (xf - x0) * np.cos((2 * j - 1) * np.pi / (2 * n))


def freudenstein(theta2: np.ndarray, theta4: np.ndarray) -> tuple[np.ndarray, float]:
    """K1, K2, K3 from crank and rocker angles [rad]: exact for three points, least squares for more.

    Returns (K, condition number of the system).
    """
    A = np.column_stack([np.cos(theta4), -np.cos(theta2), np.ones_like(theta2)])
    rhs = np.cos(theta2 - theta4)
    if len(theta2) == 3:
        return _cramer(A.tolist(), rhs.tolist()), float(np.linalg.cond(A))
    # normal equations summed exactly (math.fsum): the same bits whatever BLAS kernel is loaded
    cols = A.T.tolist()
    N = [[math.fsum(p * q for p, q in zip(ci, cj)) for cj in cols] for ci in cols]
    r = [math.fsum(p * q for p, q in zip(ci, rhs.tolist())) for ci in cols]
    return _cramer(N, r), float(np.linalg.cond(A))


def _cramer(A: list[list[float]], b: list[float]) -> np.ndarray:
    """The 3x3 solve by Cramer's rule in plain floats.

    Not np.linalg.solve: LAPACK's result changes in its last bits with the BLAS kernel
    (OPENBLAS_CORETYPE), and the linkage written to the .linkage.dat would with it.
    """
    def det(m: list[list[float]]) -> float:
        return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    D = det(A)
    if D == 0.0:
        return np.array([math.nan, math.nan, math.nan])
    out = []
    for j in range(3):
        m = [row[:] for row in A]
        for i in range(3):
            m[i][j] = b[i]
        out.append(det(m) / D)
    return np.array(out)


def links_from_k(k: np.ndarray, d: float) -> tuple[float, float, float, str]:
    """Signed crank a, coupler b, rocker c for ground d; reason text when no linkage exists.

    A negative a (c) is a crank (rocker) pointing the other way: the same linkage with that
    link's angles shifted by 180 deg.
    """
    k1, k2, k3 = (float(v) for v in k)
    if k1 == 0 or k2 == 0 or not (math.isfinite(k1) and math.isfinite(k2) and math.isfinite(k3)):
        return math.nan, math.nan, math.nan, "K1 or K2 is zero: a link of infinite length"
    a, c = d / k1, d / k2
    b2 = a * a + c * c + d * d - 2 * a * c * k3
    if b2 <= 0:
        return a, math.nan, c, f"no real coupler (b^2 = {b2:.6g} <= 0)"
    return a, math.sqrt(b2), c, ""


@dataclass
class FunctionDesign:
    """A synthesised function generator and its check by the exact kernel."""

    x_points: np.ndarray
    y_points: np.ndarray
    crank_points_deg: np.ndarray
    rocker_points_deg: np.ndarray
    k: np.ndarray
    cond: float
    crank: float
    coupler: float
    rocker: float
    crank_start_deg: float        # after a 180 deg shift when the signed crank was negative
    rocker_start_deg: float
    shifted: tuple[bool, bool] = (False, False)
    reason: str = ""
    x: np.ndarray = field(default_factory=lambda: np.zeros(0))
    y_desired: np.ndarray = field(default_factory=lambda: np.zeros(0))
    y_generated: np.ndarray = field(default_factory=lambda: np.zeros(0))
    rocker_error_deg: np.ndarray = field(default_factory=lambda: np.zeros(0))
    status: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int32))
    point_error_deg: np.ndarray = field(default_factory=lambda: np.zeros(0))
    other_branch_point_error_deg: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def max_error_y(self) -> float:
        ok = np.isfinite(self.y_generated)
        return float(np.max(np.abs(self.y_generated[ok] - self.y_desired[ok]))) if ok.any() else math.nan


def wrap180(deg: np.ndarray) -> np.ndarray:
    """Angles folded to [-180, 180)."""
    return (np.asarray(deg) + 180.0) % 360.0 - 180.0
