"""Kernel checks of fortran/ujoint.f90 against closed forms and an independent 3-D vector model.

Truth here never comes from the code under test: single-joint closed forms (Shigley; the
docs/ujoint.md), the exact-cancellation condition (docs/ujoint.md), and a numpy 3-D rotation
model of the Cardan cross written in this file (notes section 6, steps 1-4).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from driver.ujoint._kernel import (
    UJOINT_MODELS,
    UJOINT_OBJECTIVES,
    ujoint_equivalent,
    ujoint_geometry,
    ujoint_objective,
    ujoint_speed,
)

D = math.pi / 180.0
EXACT, CUM, EQ13 = UJOINT_MODELS["exact"], UJOINT_MODELS["cumulative"], UJOINT_MODELS["eq13"]
THETA = np.linspace(0.0, 2.0 * math.pi, 721)


# ----------------------------------------------------------------------------- single joint

@pytest.mark.parametrize("model", [EXACT, CUM, EQ13])
@pytest.mark.parametrize("beta_deg", [5.0, 15.0, 30.0, 45.0, 60.0])
def test_single_joint_extremes(model, beta_deg):
    b = beta_deg * D
    r, _, _ = ujoint_speed(model, [b], [], None, THETA)
    # theta from the plane normal (eq. 8): minimum cos(beta) at 0 and 180 deg, maximum
    # 1/cos(beta) at 90 and 270 deg (the paper's text states the other convention)
    assert r.min() == pytest.approx(math.cos(b), rel=1e-13)
    assert r.max() == pytest.approx(1.0 / math.cos(b), rel=1e-13)
    assert r[0] == pytest.approx(math.cos(b), rel=1e-13)
    assert r[180] == pytest.approx(1.0 / math.cos(b), rel=1e-13)


@pytest.mark.parametrize("beta_deg", [10.0, 30.0, 55.0])
def test_single_joint_tan_law_and_acceleration(beta_deg):
    b = beta_deg * D
    r, dr, out = ujoint_speed(EXACT, [b], [], None, THETA)
    # tan(theta_out) = cos(beta) tan(theta), branch-continuous output angle
    want = THETA + np.arctan2((math.cos(b) - 1.0) * np.sin(THETA) * np.cos(THETA),
                              np.cos(THETA) ** 2 + math.cos(b) * np.sin(THETA) ** 2)
    assert np.allclose(out, want, atol=1e-14)
    assert np.allclose(np.tan(out[np.abs(np.cos(THETA)) > 1e-3]),
                       math.cos(b) * np.tan(THETA[np.abs(np.cos(THETA)) > 1e-3]), rtol=1e-12)
    # ratio and acceleration closed forms (theta from the plane normal)
    s2 = math.sin(b) ** 2
    assert np.allclose(r, math.cos(b) / (1 - s2 * np.sin(THETA) ** 2), rtol=1e-14)
    alpha = math.cos(b) * s2 * np.sin(2 * THETA) / (1 - s2 * np.sin(THETA) ** 2) ** 2
    assert np.allclose(dr, alpha, atol=1e-14)


@pytest.mark.parametrize("beta_deg, peak", [(15.0, 0.0694), (30.0, 0.2946)])
def test_single_joint_peak_acceleration_notes(beta_deg, peak):
    """Notes 5.1: exact peak output acceleration 0.0694 w^2 at 15 deg, 0.2946 w^2 at 30 deg."""
    th = np.linspace(0, math.pi, 20001)
    _, dr, _ = ujoint_speed(EXACT, [beta_deg * D], [], None, th)
    assert np.abs(dr).max() == pytest.approx(peak, abs=5e-5)


# ----------------------------------------------------------------------------- two joints

@pytest.mark.parametrize("beta_deg, paper_pp", [(20.0, 0.0039), (30.0, 0.020)])
def test_two_equal_joints_in_phase(beta_deg, paper_pp):
    """Exact chain: constant velocity; the paper's model: its known 4th-order residual
    (notes section 1: 0.39 % at 20 deg, 2.0 % at 30 deg)."""
    b = beta_deg * D
    r, dr, _ = ujoint_speed(EXACT, [b, b], [math.pi / 2], None, THETA)
    assert np.ptp(r) < 1e-14 and np.abs(dr).max() < 1e-13
    for model in (CUM, EQ13):
        rp, _, _ = ujoint_speed(model, [b, b], [math.pi / 2], None, THETA)
        # independent numpy form of the paper's eq. 11
        s2 = math.sin(b) ** 2
        want = (math.cos(b) / (1 - s2 * np.sin(THETA) ** 2)) * (math.cos(b) / (1 - s2 * np.cos(THETA) ** 2))
        assert np.allclose(rp, want, rtol=1e-14)
        assert np.ptp(rp) == pytest.approx(paper_pp, abs=1e-4 if beta_deg == 20 else 1e-3)


# ----------------------------------------------------------------------------- 3-D vector model

def _rot(axis: np.ndarray, ang: float) -> np.ndarray:
    """Rodrigues rotation matrix, right-handed about unit ``axis`` [rad]."""
    k = axis / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(ang) * K + (1 - math.cos(ang)) * K @ K


def vector_model_ratio(axes: np.ndarray, delta: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Independent oracle (numpy): speed ratio of a Cardan chain by 3-D cross-arm geometry.

    axes (n+1, 3) shaft directions; delta (n-1,) yoke phases [rad] about each intermediate
    shaft (0 = in phase); the input yoke at theta = 0 lies along the joint-1 plane normal
    (the first bent joint's normal when joint 1 is straight).
    Each joint: the output arm v is perpendicular to the input arm u and to its own shaft;
    omega_k/omega_(k-1) = -[(a_(k-1) x u).v] / [(a_k x v).u].
    """
    a = axes / np.linalg.norm(axes, axis=1)[:, None]
    n = len(a) - 1
    normals = [np.cross(a[k], a[k + 1]) for k in range(n)]
    first = next(w for w in normals if np.linalg.norm(w) > 1e-12)
    u0 = [first / np.linalg.norm(first)]
    v0 = []
    for k in range(n):
        v = np.cross(a[k + 1], u0[k])
        v0.append(v / np.linalg.norm(v))
        if k < n - 1:
            u0.append(_rot(a[k + 1], delta[k]) @ v0[k])
    out = np.empty(theta.size)
    for j, th in enumerate(theta):
        u = _rot(a[0], th) @ u0[0]
        ratio = 1.0
        for k in range(n):
            e1 = v0[k]
            e2 = np.cross(a[k + 1], e1)
            q = math.atan2(-u @ e1, u @ e2)
            v = math.cos(q) * e1 + math.sin(q) * e2
            ratio *= -(np.cross(a[k], u) @ v) / (np.cross(a[k + 1], v) @ u)
            if k < n - 1:
                u = _rot(a[k + 1], q) @ u0[k + 1]
        out[j] = ratio
    return out


def _random_chain(rng: np.random.Generator, n: int, max_deg: float = 35.0) -> np.ndarray:
    a = [rng.normal(size=3)]
    a[0] /= np.linalg.norm(a[0])
    for _ in range(n):
        perp = np.cross(a[-1], rng.normal(size=3))
        perp /= np.linalg.norm(perp)
        a.append(_rot(perp, rng.uniform(3.0, max_deg) * D) @ a[-1])
    return np.array(a)


@pytest.mark.parametrize("seed", range(6))
def test_exact_chain_matches_vector_model(seed):
    rng = np.random.default_rng(seed)
    n = 2 + seed % 3
    axes = _random_chain(rng, n)
    delta = rng.uniform(-math.pi, math.pi, n - 1)
    beta, rho, status = ujoint_geometry(axes)
    assert status == 0
    # geometry against numpy
    a = axes / np.linalg.norm(axes, axis=1)[:, None]
    assert np.allclose(beta, np.arccos(np.clip(np.sum(a[:-1] * a[1:], axis=1), -1, 1)), atol=1e-12)
    th = np.linspace(0.0, 2 * math.pi, 73)
    want = vector_model_ratio(axes, delta, th)
    r, _, _ = ujoint_speed(EXACT, beta, delta + math.pi / 2, rho, th)
    assert np.max(np.abs(r - want)) < 1e-13


def test_geometry_flags_zero_axis_and_right_angle():
    assert ujoint_geometry([[1, 0, 0], [0, 0, 0], [1, 1, 0]])[2] == 2
    assert ujoint_geometry([[1, 0, 0], [0, 1, 0.01], [0, 1, 0.3]])[2] == 3


# ----------------------------------------------------------------------------- closed forms

@given(b1=st.floats(1, 40), b2=st.floats(1, 40), b3=st.floats(1, 40))
@settings(max_examples=40, deadline=None)
def test_beta_res_closed_form(b1, b2, b3):
    """Coplanar, in-phase: exactly one joint of cos(beta_res) = min(K, 1/K), K = c1 c3 / c2."""
    b = np.array([b1, b2, b3]) * D
    K = math.cos(b[0]) * math.cos(b[2]) / math.cos(b[1])
    c = min(K, 1 / K)
    _, br = ujoint_equivalent(EXACT, b, [math.pi / 2] * 2, None)
    assert math.cos(br) == pytest.approx(c, rel=1e-12, abs=1e-12)
    r, _, _ = ujoint_speed(EXACT, b, [math.pi / 2] * 2, None, THETA)
    assert np.ptp(r) == pytest.approx(1 / c - c, abs=1e-12)


def test_beta_e_out_of_plane_example():
    """Notes 5.2: (12, 8, 6) deg, third joint out of plane: exact p-p 0.01364,
    phasor |b1^2 - b2^2 - b3^2| = 0.01340."""
    b = np.array([12.0, 8.0, 6.0]) * D
    be, br = ujoint_equivalent(EXACT, b, [math.pi / 2] * 2, [0.0, math.pi / 2])
    assert be ** 2 == pytest.approx(abs(b[0] ** 2 - b[1] ** 2 - b[2] ** 2), rel=1e-12)
    assert be ** 2 == pytest.approx(0.01340, abs=5e-5)
    r, _, _ = ujoint_speed(EXACT, b, [math.pi / 2] * 2, [0.0, math.pi / 2], THETA)
    assert np.ptp(r) == pytest.approx(0.01364, abs=5e-5)
    assert br is not None   # shifts are multiples of 90 deg: the exact closed form applies


def test_beta_res_undefined_off_symmetry():
    assert ujoint_equivalent(EXACT, [0.2, 0.3], [1.0], None)[1] is None


@given(seed=st.integers(0, 10_000), rho=st.floats(-math.pi, math.pi), b=st.floats(1, 45))
@settings(max_examples=30, deadline=None)
def test_two_equal_joints_cv_when_yoke_follows_plane(seed, rho, b):
    """Fischer & Paul: equal angles and yoke phase = plane angle -> constant velocity."""
    r, _, _ = ujoint_speed(EXACT, [b * D, b * D], [math.pi / 2 + rho], [rho], THETA)
    assert np.ptp(r) < 1e-13


@given(seed=st.integers(0, 10_000))
@settings(max_examples=25, deadline=None)
def test_exact_chain_mean_ratio_is_one_and_phase_period(seed):
    """The output turns once per input turn (mean ratio 1); phases have period 180 deg."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 5))
    b = rng.uniform(0, 40, n) * D
    ph = rng.uniform(0, math.pi, n - 1)
    rh = rng.uniform(-math.pi, math.pi, n - 1)
    th = np.arange(256) * (2 * math.pi / 256)
    r, _, _ = ujoint_speed(EXACT, b, ph, rh, th)
    assert r.mean() == pytest.approx(1.0, abs=1e-12)
    for kind in UJOINT_OBJECTIVES.values():
        f1, _ = ujoint_objective(EXACT, kind, b, ph, rh, 360, grad=False)
        f2, _ = ujoint_objective(EXACT, kind, b, ph + math.pi, rh, 360, grad=False)
        assert f2 == pytest.approx(f1, rel=1e-9, abs=1e-15)


def test_objective_matches_numpy_on_full_grid():
    """The half-grid shortcut (period 180 deg) equals the full-revolution numpy mean."""
    b, ph, rh = np.array([15., 20., 9.]) * D, np.array([57., 73.]) * D, np.array([10., -30.]) * D
    th = np.arange(360) * (2 * math.pi / 360)
    for model in (EXACT, CUM, EQ13):
        r, _, _ = ujoint_speed(model, b, ph, rh if model == EXACT else None, th)
        f, _ = ujoint_objective(model, UJOINT_OBJECTIVES["mean_square"], b, ph,
                                rh if model == EXACT else None, 360, grad=False)
        assert f == pytest.approx(np.mean((r - 1) ** 2), rel=1e-12)
        f, _ = ujoint_objective(model, UJOINT_OBJECTIVES["peak_to_peak"], b, ph,
                                rh if model == EXACT else None, 360, grad=False)
        assert f == pytest.approx(np.ptp(r), rel=1e-12)


def test_paper_models_phasing_numpy():
    """eq. 13 as printed (theta + phi_2) and cumulative (theta + phi_1 + phi_2), in numpy."""
    b, ph = np.array([30., 40., 50.]) * D, np.array([70., 100.]) * D

    def r(bb, t):
        return np.cos(bb) / (1 - np.sin(bb) ** 2 * np.sin(t) ** 2)

    eq13 = r(b[0], THETA) * r(b[1], THETA + ph[0]) * r(b[2], THETA + ph[1])
    cum = r(b[0], THETA) * r(b[1], THETA + ph[0]) * r(b[2], THETA + ph[0] + ph[1])
    assert np.allclose(ujoint_speed(EQ13, b, ph, None, THETA)[0], eq13, rtol=1e-14)
    assert np.allclose(ujoint_speed(CUM, b, ph, None, THETA)[0], cum, rtol=1e-14)


# ----------------------------------------------------------------------------- gradients

@pytest.mark.parametrize("model", [EXACT, CUM, EQ13])
@pytest.mark.parametrize("kind", list(UJOINT_OBJECTIVES))
def test_gradient_against_finite_differences(model, kind):
    rng = np.random.default_rng(7)
    n = 4
    b = rng.uniform(5, 35, n) * D
    ph = rng.uniform(0, math.pi, n - 1)
    rh = rng.uniform(-1, 1, n - 1) if model == EXACT else None
    code = UJOINT_OBJECTIVES[kind]
    f, g = ujoint_objective(model, code, b, ph, rh, 360)
    x = np.concatenate([b, ph])
    h = 1e-6
    fd = []
    for i in range(x.size):
        xp, xm = x.copy(), x.copy()
        xp[i] += h
        xm[i] -= h
        fp = ujoint_objective(model, code, xp[:n], xp[n:], rh, 360, grad=False)[0]
        fm = ujoint_objective(model, code, xm[:n], xm[n:], rh, 360, grad=False)[0]
        fd.append((fp - fm) / (2 * h))
    assert g.size == 2 * n - 1
    assert np.allclose(g, fd, rtol=1e-6, atol=1e-9 * max(1.0, abs(f)))


@pytest.mark.parametrize("straight", [1, 2])
def test_straight_joint_borrows_a_plane(straight):
    """A joint with beta = 0 has no plane of its own; the chain still matches the vector model."""
    rng = np.random.default_rng(11 + straight)
    axes = _random_chain(rng, 3)
    axes = np.insert(axes, straight, axes[straight - 1], axis=0)   # repeat a shaft: straight joint
    delta = rng.uniform(-1.0, 1.0, 3)
    beta, rho, status = ujoint_geometry(axes)
    assert status == 0 and beta[straight - 1] == 0.0
    th = np.linspace(0.0, 2 * math.pi, 37)
    r, _, _ = ujoint_speed(EXACT, beta, delta + math.pi / 2, rho, th)
    assert np.max(np.abs(r - vector_model_ratio(axes, delta, th))) < 1e-13
