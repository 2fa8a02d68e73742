"""Exact mode and the kernels against independent truth: FK, a Newton-Euler computation written
here, numpy SVD, finite differences and closed forms of the tolerance box."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from driver._deck import read_deck
from driver._runner import study_of
from driver.manipulator import _kernel as manipulator_kernel
from driver.manipulator import table_frame, tolerance_box
from driver.manipulator._analysis import percentile, sensitivity_blocks

ROOT = Path(__file__).resolve().parents[1]


def fk(l1, l2, th1, th2):
    """Forward kinematics (test oracle): end-effector position [m]."""
    return (l1 * np.cos(th1) + l2 * np.cos(th1 + th2), l1 * np.sin(th1) + l2 * np.sin(th1 + th2))


def newton_euler(l1, l2, m1, m2, g, q, qd, qdd):
    """Test oracle: joint torques of point masses at the link ends by Newton-Euler / d'Alembert.

    The torque at a joint balances the moments about that joint of m (a + g y_hat) of every
    mass beyond it (planar cross product), with accelerations from differentiating the
    mass positions analytically.
    """
    t1, t2 = q
    w1, w2 = qd
    a1, a2 = qdd
    p1 = np.array([l1 * math.cos(t1), l1 * math.sin(t1)])
    u2 = np.array([math.cos(t1 + t2), math.sin(t1 + t2)])
    n2 = np.array([-u2[1], u2[0]])
    acc1 = l1 * (a1 * np.array([-p1[1], p1[0]]) / l1 - w1 ** 2 * p1 / l1)
    acc2 = acc1 + l2 * ((a1 + a2) * n2 - (w1 + w2) ** 2 * u2)
    p2 = p1 + l2 * u2
    f1 = m1 * (acc1 + np.array([0.0, g]))
    f2 = m2 * (acc2 + np.array([0.0, g]))
    cross = lambda r, f: r[0] * f[1] - r[1] * f[0]
    return cross(p1, f1) + cross(p2, f2), cross(p2 - p1, f2)


@pytest.fixture(scope="module")
def exact_runs():
    out = {}
    for case in ("1", "2"):
        module, params = study_of(read_deck(ROOT / "inputs" / f"manipulator_case{case}_exact.dat"))
        out[case] = (module.run(params), params)
    return out


def test_exact_angles_reach_the_target(exact_runs):
    for res, p in exact_runs.values():
        for key in ("4.5", "4.8"):
            t = table_frame(res.tidy, key).dropna(subset=["theta1_deg"])
            assert len(t) > 0
            x, y = fk(t["l1_m"].to_numpy(), t["l2_m"].to_numpy(), np.radians(t["theta1_deg"]),
                      np.radians(t["theta2_deg"]))
            np.testing.assert_allclose(x, p.target_x, atol=1e-9)
            np.testing.assert_allclose(y, p.target_y, atol=1e-9)
            assert (t["theta2_deg"] >= 0).all()   # elbow +1


def test_exact_torques_match_newton_euler(exact_runs):
    for res, p in exact_runs.values():
        for key in ("4.7", "4.8"):
            ang = table_frame(res.tidy, "4.5" if key == "4.7" else key)
            tq = table_frame(res.tidy, key)
            for (_, a), (_, b) in zip(ang.iterrows(), tq.iterrows()):
                if np.isnan(a["theta1_deg"]):
                    continue
                l1, l2 = a["l1_m"], a["l2_m"]
                ref = newton_euler(l1, l2, 10 * l1, 10 * l2, 9.8, np.radians([a["theta1_deg"], a["theta2_deg"]]),
                                   p.joint_rates, p.joint_accels)
                np.testing.assert_allclose([b["tau1_Nm"], b["tau2_Nm"]], ref, rtol=1e-11, atol=1e-8)


def test_exact_mode_uses_mean_d2():
    for case, c in (("1", 47.25), ("2", 51.5)):
        module, params = study_of(read_deck(ROOT / "inputs" / f"manipulator_case{case}_exact.dat"))
        s = module.run(params).summary
        assert s["crob_c_m2"] == c
        assert s["dexterity_l1_m"] == pytest.approx(math.sqrt(2 * c / 3), rel=1e-15)
        assert s["manipulability_l1_m"] == pytest.approx(math.sqrt(c / 2), rel=1e-15)


angles = st.floats(-math.pi, math.pi, allow_nan=False)
lengths = st.floats(0.1, 10.0, allow_nan=False)
rates = st.floats(-3.0, 3.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(lengths, lengths, angles, angles, rates, rates, rates, rates, st.floats(0.1, 50.0), st.floats(0.1, 50.0))
def test_kernel_torques_property(l1, l2, t1, t2, w1, w2, a1, a2, m1, m2):
    tau = manipulator_kernel.manipulator_torques(l1, l2, t1, t2, (w1, w2), (a1, a2), m1, m2, 9.81)
    ref = newton_euler(l1, l2, m1, m2, 9.81, (t1, t2), (w1, w2), (a1, a2))
    np.testing.assert_allclose(tau[0], ref, rtol=1e-10, atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(lengths, lengths, angles, angles)
def test_jacobian_manipulability_condition(l1, l2, t1, t2):
    jac, w, kappa, tau = manipulator_kernel.manipulator_arm_states(l1, l2, t1, t2)
    h = 1e-6
    J = np.array([[(fk(l1, l2, t1 + h, t2)[i] - fk(l1, l2, t1 - h, t2)[i]) / (2 * h),
                   (fk(l1, l2, t1, t2 + h)[i] - fk(l1, l2, t1, t2 - h)[i]) / (2 * h)] for i in range(2)])
    np.testing.assert_allclose(jac[0].reshape(2, 2), J, atol=1e-6 * max(l1, l2))
    assert w[0] == pytest.approx(l1 * l2 * abs(math.sin(t2)), rel=1e-9, abs=1e-12)
    Ja = np.array([[-l1 * math.sin(t1) - l2 * math.sin(t1 + t2), -l2 * math.sin(t1 + t2)],
                   [l1 * math.cos(t1) + l2 * math.cos(t1 + t2), l2 * math.cos(t1 + t2)]])   # eq. 4.18
    if abs(math.sin(t2)) > 1e-3:
        assert kappa[0] == pytest.approx(np.linalg.cond(Ja), rel=1e-7)


@settings(max_examples=60, deadline=None)
@given(lengths, lengths, angles, angles, st.sampled_from([1, -1]))
def test_ik_round_trip(l1, l2, t1, t2, branch):
    x, y = fk(l1, l2, t1, t2)
    if math.hypot(x, y) < 1e-6:
        return
    th1, th2, status = manipulator_kernel.manipulator_ik(l1, l2, x, y, branch)
    assert status[0] == 0
    xx, yy = fk(l1, l2, th1[0], th2[0])
    assert xx == pytest.approx(x, abs=1e-6 * (l1 + l2)) and yy == pytest.approx(y, abs=1e-6 * (l1 + l2))
    assert th2[0] * branch >= -1e-12


def test_ik_status_out_of_reach_and_degenerate():
    th1, th2, status = manipulator_kernel.manipulator_ik([1.0, 1.0, 0.0], [1.0, 1.0, 1.0], [5.0, 0.0, 1.0], [0.0, 0.0, 0.0], 1)
    assert list(status) == [1, 2, 2]


def test_design_indices_match_svd():
    x, y = np.array([1.0, 2, 4, 5]), np.array([4.0, 8, 8, 4])
    l1, l2 = np.array([5.85, 3.0, 6.5]), np.array([4.16, 6.52, 3.04])
    ri, sumc2, reach = manipulator_kernel.manipulator_design_indices(x, y, l1, l2)
    for k in range(3):
        th1, th2, st_ = manipulator_kernel.manipulator_ik(l1[k], l2[k], x, y, 1)
        Jx = sensitivity_blocks(th1, th2).reshape(-1, 2)
        s = np.linalg.svd(Jx, compute_uv=False)
        assert ri[k, 1] == pytest.approx(s[0], rel=1e-12)
        assert ri[k, 0] == pytest.approx(s[0] / s[1], rel=1e-10)
        assert ri[k, 2] == pytest.approx(s[0] + np.linalg.norm(Jx), rel=1e-12)
    assert list(reach) == [1, 1, 1]


@pytest.mark.parametrize("measure", ["global", "per_point"])
def test_tolerance_box_worst_corner_on_bound_and_monte_carlo(measure):
    x, y = np.array([1.0, 2, 3, 4]), np.array([5.0, 7, 7, 6])
    eps = 0.01
    th1, th2, _ = manipulator_kernel.manipulator_ik(5.61, 3.97, x, y, 1)
    blocks = sensitivity_blocks(th1, th2)
    box = tolerance_box(blocks, eps, measure)
    dl = box["closed"]
    np.testing.assert_allclose(box["u"], dl, rtol=1e-12)         # the largest box over all corners
    if measure == "global":
        ri2 = np.linalg.svd(blocks.reshape(-1, 2), compute_uv=False)[0]
        np.testing.assert_allclose(dl, eps / (math.sqrt(2) * ri2), rtol=1e-12)
    # independent corner check in numpy: the worst corner sits on the bound
    corners = np.array([[1, 1], [1, -1], [-1, 1], [-1, -1]]) * dl
    per_point = np.einsum("kij,nj->nki", blocks, corners)       # (corner, point, xy)
    err = np.sqrt((per_point ** 2).sum((1, 2))) if measure == "global" else \
        np.sqrt((per_point ** 2).sum(2)).max(1)
    assert err.max() == pytest.approx(eps, rel=1e-12)
    # Monte Carlo through the kernel stays within the bound
    rng = np.random.default_rng(1)
    e = manipulator_kernel.manipulator_position_errors(th1, th2, rng.uniform(-1, 1, (20000, 2)) * dl)
    assert e[:, 0 if measure == "global" else 1].max() <= eps * (1 + 1e-12)
    # and a slightly larger box breaks it at a corner
    e = manipulator_kernel.manipulator_position_errors(th1, th2, corners * 1.001)
    assert e[:, 0 if measure == "global" else 1].max() > eps


def test_study_tolerance_rows(exact_runs):
    for res, p in exact_runs.values():
        t = table_frame(res.tidy, "tolerance")
        assert len(t) == 2
        np.testing.assert_allclose(t["worst_corner_m"], p.tolerance_bound, rtol=1e-12)
        assert (t["mc_max_m"] <= p.tolerance_bound).all()
        assert (t["mc_p99_m"] < t["mc_max_m"]).all()
        np.testing.assert_allclose(t["dl1_m"], p.tolerance_bound / (math.sqrt(2) * t["ri2"]), rtol=1e-12)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.floats(-8, 8), st.floats(-8, 8)), min_size=1, max_size=6),
       st.floats(0.5, 6.0), st.floats(0.5, 6.0), st.sampled_from(["global", "per_point"]))
def test_tolerance_box_property(points, l1, l2, measure):
    """Random workspaces and designs: the largest box equals the l = 2 closed form and SLSQP's (the
    oracle), and the worst corner (computed here in numpy) sits on the bound."""
    x = np.array([p[0] for p in points])
    y = np.array([p[1] for p in points])
    d = np.hypot(x, y)
    if (d < abs(l1 - l2) + 1e-3).any() or (d > l1 + l2 - 1e-3).any() or (d < 1e-3).any():
        return
    th1, th2, status = manipulator_kernel.manipulator_ik(l1, l2, x, y, 1)
    assert (status == 0).all()
    blocks = sensitivity_blocks(th1, th2)
    box = tolerance_box(blocks, 0.02, measure)
    assert box["converged"]
    np.testing.assert_allclose(box["u"], box["closed"], rtol=1e-12)
    mats = [blocks.reshape(-1, 2).T @ blocks.reshape(-1, 2)] if measure == "global" else [b.T @ b for b in blocks]
    np.testing.assert_allclose(box["u"], _slsqp_box(mats, 0.02), rtol=1e-5)   # the oracle
    corners = np.array([[1, 1], [1, -1]]) * box["closed"]
    e = np.einsum("kij,nj->nki", blocks, corners)
    worst = np.sqrt((e ** 2).sum((1, 2))).max() if measure == "global" else np.sqrt((e ** 2).sum(2)).max()
    assert worst == pytest.approx(0.02, rel=1e-10)


def _slsqp_box(mats: list[np.ndarray], eps: float) -> np.ndarray:
    """Test oracle, written apart from the tool's enumeration: the largest two-length box by
    scipy's SLSQP over every corner pattern, from several starts (the tool's method until 2026-12)."""
    from scipy.optimize import minimize
    pats = np.array([[1.0, 1.0], [1.0, -1.0]])
    scale = eps / math.sqrt(max(m.trace() for m in mats))
    best = None
    for start in ([0.5, 0.5], [0.1, 2.0], [2.0, 0.1]):
        res = minimize(lambda v: -np.sum(np.log(v)), np.array(start), method="SLSQP", jac=lambda v: -1.0 / v,
                       constraints=[{"type": "ineq", "fun": lambda v: np.array(
                           [1.0 - (s * v * scale) @ S @ (s * v * scale) / eps ** 2 for S in mats for s in pats])}],
                       bounds=[(1e-9, None)] * 2, options={"ftol": 1e-14, "maxiter": 1000})
        if res.success and (best is None or res.fun < best.fun):
            best = res
    assert best is not None
    return best.x * scale


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0.05, 5.0), st.floats(0.05, 5.0), st.floats(-0.95, 0.95)), min_size=1, max_size=5),
       st.floats(1e-3, 0.1))
def test_largest_two_length_box_against_slsqp_and_a_scan(consts, eps):
    """Per-point constraints with any S11, S22 and correlation (not only a 2R arm's unit columns, where
    the closed form is already the optimum): the tool's box is on the bound, its volume is SLSQP's
    (the oracle) to 1e-7 and at least a dense scan of the ratio u2/u1 (so no better box exists)."""
    blocks = []
    for s11, s22, rho in consts:   # J = L^T with S = J^T J = [[s11, c], [c, s22]]
        c = rho * math.sqrt(s11 * s22)
        L = np.linalg.cholesky(np.array([[s11, c], [c, s22]]))
        blocks.append(L.T)
    blocks = np.array(blocks)
    mats = [b.T @ b for b in blocks]
    u = tolerance_box(blocks, eps, "per_point")["u"]
    worst = max((s * u) @ S @ (s * u) for S in mats for s in np.array([[1.0, 1.0], [1.0, -1.0]]))
    assert math.sqrt(worst) == pytest.approx(eps, rel=1e-12)
    ref = _slsqp_box(mats, eps)
    assert u[0] * u[1] >= ref[0] * ref[1] * (1 - 1e-7)
    r = np.geomspace(1e-4, 1e4, 200_001)
    q = np.max([S[0, 0] + 2 * abs(S[0, 1]) * r + S[1, 1] * r * r for S in mats], axis=0)
    assert u[0] * u[1] >= eps ** 2 * (r / q).max() * (1 - 1e-12)


def test_crossing_constraints_beat_the_closed_form():
    """Two constraints whose single optima each break the other: the largest box lies where they
    cross, above the closed form's scaled-down box (worked by hand: S_a = diag(1, 4), S_b = diag(4, 1);
    by symmetry r = 1 and u1 = u2 = eps/sqrt(5), volume eps^2/5; the closed form takes S_a's own optimum
    (eps/sqrt2, eps/sqrt8), which S_b's corner (17/8 eps^2) scales by sqrt(8/17): volume 2 eps^2/17)."""
    blocks = np.array([np.diag([1.0, 2.0]), np.diag([2.0, 1.0])])
    box = tolerance_box(blocks, 0.01, "per_point")
    np.testing.assert_allclose(box["u"], [0.01 / math.sqrt(5)] * 2, rtol=1e-14)
    assert np.prod(box["closed"]) == pytest.approx(2 * 0.01 ** 2 / 17, rel=1e-12)


def test_tolerance_box_three_variables():
    """General l: all 2^(l-1) corner patterns constrained; the box is on the bound and maximal."""
    rng = np.random.default_rng(3)
    blocks = rng.normal(size=(4, 2, 3))
    eps = 0.05
    box = tolerance_box(blocks, eps, "global")
    assert box["closed"] is None and box["converged"]
    u = box["u"]
    J = blocks.reshape(-1, 3)
    signs = np.array([[a, b, c] for a in (1, -1) for b in (1, -1) for c in (1, -1)])
    err = np.linalg.norm((signs * u) @ J.T, axis=1)
    assert err.max() == pytest.approx(eps, rel=1e-6)
    for i in range(3):   # growing any half-width breaks the bound
        v = u.copy()
        v[i] *= 1.01
        assert np.linalg.norm((signs * v) @ J.T, axis=1).max() > eps


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 3000), st.floats(0.0, 100.0), st.integers(0, 2**32 - 1), st.booleans())
def test_percentile_is_numpys_bit_for_bit(n, q, seed, ties):
    """The Monte Carlo p99 without np.percentile (whose np.unique imports numpy.ma): the same double
    as numpy's default method for any size and percentile, ties included."""
    rng = np.random.default_rng(seed)
    x = rng.integers(0, 5, n).astype(float) if ties else rng.standard_normal(n) * 10.0 ** rng.integers(-8, 8)
    assert percentile(x, q) == float(np.percentile(x, q))
    assert percentile(x, 99.0) == float(np.percentile(x, 99.0))
