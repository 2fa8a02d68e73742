"""The example study's "kernel": numpy/scipy in place of a Fortran module (example only).

Every function works on whole arrays.  Angles in radians, lengths in m, times in s.
"""
from __future__ import annotations

import numpy as np
from scipy import special


def periods(length: np.ndarray, gravity: np.ndarray, theta0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(period, small-angle period) [s] of a uniform rod of ``length`` pivoted at one end,
    released at rest from ``theta0``: T = 4 sqrt(2L/3g) K(m), m = sin^2(theta0/2)."""
    w0 = np.sqrt(1.5 * np.asarray(gravity, float) / np.asarray(length, float))
    m = np.sin(0.5 * np.asarray(theta0, float)) ** 2
    return 4.0 * special.ellipk(m) / w0, 2.0 * np.pi / w0


def swing(length: float, gravity: float, theta0: float, t: np.ndarray) -> np.ndarray:
    """theta(t) [rad] from release at rest: theta = 2 asin(k sn(K - w0 t | k^2)), k = sin(theta0/2)."""
    w0 = np.sqrt(1.5 * gravity / length)
    k = np.sin(0.5 * theta0)
    sn, _, _, _ = special.ellipj(special.ellipk(k * k) - w0 * np.asarray(t, float), k * k)
    return 2.0 * np.arcsin(np.clip(k * sn, -1.0, 1.0))
