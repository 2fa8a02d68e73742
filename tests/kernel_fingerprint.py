"""SHA-256 of the raw float64 results of every kernel on fixed inputs (a test helper).

``python tests/kernel_fingerprint.py`` prints them as JSON for whichever installed
``driver`` it imports; test_install compares the portable wheel's fingerprint with
the native editable build's: the kernels must agree to the last bit.
"""
from __future__ import annotations

import hashlib
import json

import numpy as np

from driver import kernels as k


def _h(*arrays) -> str:
    d = hashlib.sha256()
    for a in arrays:
        d.update(np.ascontiguousarray(np.asarray(a, dtype=np.float64)).tobytes())
    return d.hexdigest()


def fingerprint() -> dict[str, str]:
    """One hash per kernel family, inputs chosen to exercise every code path (vector loops included)."""
    rng = np.random.default_rng(20261125)
    theta = np.concatenate([np.linspace(0, 2 * np.pi, 2001), rng.uniform(-50, 50, 4003)])
    out = {}
    table, st = k.fourbar_listing(12.0, 5.0, 15.0, 9.0, 5.0, 0, 20, 19)
    out["fourbar_listing"] = _h(table, st)
    for branch in (1, -1):
        s, st = k.fourbar_exact(theta, 12.0, 5.0, 15.0, 9.0, 5.0, 0.7, branch)
        out[f"fourbar_exact{branch:+d}"] = _h(s, st, k.fourbar_coupler_point(theta, s, st, 5.0, 5.0, 0.7, 7.5, 2.0))
    n = 3001
    l1, l2 = rng.uniform(0.2, 1.0, n), rng.uniform(0.2, 1.0, n)
    th1, th2 = rng.uniform(-np.pi, np.pi, n), rng.uniform(-np.pi, np.pi, n)
    jac, w, kappa, tau = k.manipulator_arm_states(l1, l2, th1, th2, (1.3, -0.4), (0.2, 2.0))
    out["manipulator_arm_states"] = _h(jac, w, kappa, tau, k.manipulator_torques(l1, l2, th1, th2))
    x, y = rng.uniform(-1.5, 1.5, n), rng.uniform(-1.5, 1.5, n)
    out["manipulator_ik"] = _h(*k.manipulator_ik(l1, l2, x, y, 1), *k.manipulator_ik(l1, l2, x, y, -1))
    px, py = rng.uniform(0.1, 0.6, 9), rng.uniform(0.1, 0.6, 9)
    out["manipulator_design_indices"] = _h(*k.manipulator_design_indices(px, py, l1[:500] + 0.6, l2[:500] + 0.6))
    out["manipulator_position_errors"] = _h(k.manipulator_position_errors(th1[:9], th2[:9],
                                                                            rng.normal(0, 1e-3, (2000, 2))))
    beta, phi, rho = np.radians([12.0, 25.0, 9.0]), np.radians([80.0, 100.0]), np.radians([20.0, -35.0])
    for name, code in k.UJOINT_MODELS.items():
        r = k.ujoint_speed(code, beta, phi, rho, theta)
        f, g = k.ujoint_objective(code, k.UJOINT_OBJECTIVES["mean_square"], beta, phi, rho, 720)
        out[f"ujoint_{name}"] = _h(*r, f, g)
    # the Simeon (1996) steel rod: A = 64 mm^2, I = 3.41e-10 m^4, rho = 7870, E = 200 GPa, 150 rad/s
    sc = k.slidercrank_simulate(16, 0.15, 0.3, 7870 * 64e-6, 2e11 * 64e-6, 2e11 * 3.413333333e-10, 0.004,
                                0.075552, 150.0, 2.5e-5, 800, 400, 400, alpha=1.0, beta=1e-6)
    assert sc["status"] == k.SLIDERCRANK_STATUS["ok"], sc["status"]
    out["slidercrank_simulate"] = _h(*(sc[n] for n in ("eps_ax", "eps_of", "n_avg", "mid", "slider", "elong")),
                                     sc["status"])
    return out


if __name__ == "__main__":
    print(json.dumps(fingerprint(), indent=1, sort_keys=True))
