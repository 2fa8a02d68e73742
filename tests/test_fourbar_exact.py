"""Exact four-bar kernel against identities and closed forms (independent of the kernel's own algebra).

* loop closure |AB| = coupler and |B O_B| = rocker, branch side of B;
* velocities and accelerations against finite differences of positions;
* agreement with the published program where that program is right (0..180 deg);
* transmission-angle and rocker extremes, limit angles and Grashof class in closed form.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from driver.fourbar import _kernel as fourbar_kernel
from driver.fourbar import grashof, limit_angles

OK = fourbar_kernel.FOURBAR_STATUS["ok"]
length = st.floats(0.5, 10.0, allow_nan=False)


def states(theta, p, q, r, s, omega=1.0, alpha=0.0, branch=1):
    return fourbar_kernel.fourbar_exact(np.asarray(theta, float), p, q, r, s, omega, alpha, branch)


@settings(max_examples=150, deadline=None)
@given(p=length, q=length, r=length, s=length, branch=st.sampled_from([1, -1]))
def test_loop_closure_and_branch_side(p, q, r, s, branch):
    theta = np.linspace(0.0, 2 * np.pi, 721)
    out, status = states(theta, p, q, r, s, branch=branch)
    ok = status == OK
    ax, ay, bx, by = out[ok, 3], out[ok, 4], out[ok, 5], out[ok, 6]
    scale = max(p, q, r, s)
    assert np.allclose(np.hypot(bx - ax, by - ay), r, atol=1e-12 * scale, rtol=0)
    assert np.allclose(np.hypot(bx - p, by), s, atol=1e-12 * scale, rtol=0)
    # B on the left (open) / right (crossed) of the directed line A -> O_B
    side = (p - ax) * (by - ay) - (0 - ay) * (bx - ax)
    assert np.all(branch * side >= -1e-9 * scale**2)
    # rows that cannot be assembled are exactly those with |A O_B| outside [|r-s|, r+s]
    d = np.hypot(p - q * np.cos(theta), q * np.sin(theta))
    clear = (d < abs(r - s) - 1e-9 * scale) | (d > r + s + 1e-9 * scale)
    assert np.all(status[clear & (d > 1e-12 * scale)] == fourbar_kernel.FOURBAR_STATUS["no_assembly"])
    # A on O_B (p = q at theta = 0): B is indeterminate, never reported as a position
    if r == s:
        assert np.all(status[d < 1e-12 * scale] == fourbar_kernel.FOURBAR_STATUS["indeterminate"])
    inside = (d > abs(r - s) + 1e-6 * scale) & (d < r + s - 1e-6 * scale) & (d > 1e-6 * scale)
    assert np.all(status[inside] == OK)


@settings(max_examples=120, deadline=None)
@given(p=length, q=length, r=length, s=length, branch=st.sampled_from([1, -1]),
       omega=st.floats(-20, 20).filter(lambda w: abs(w) > 0.1), alpha=st.floats(-50, 50))
def test_velocity_and_acceleration_are_derivatives_of_position(p, q, r, s, branch, omega, alpha):
    theta = np.linspace(0.05, 2 * np.pi - 0.05, 97)
    h = 1e-5
    out, st0 = states(theta, p, q, r, s, omega, alpha, branch)
    op, stp = states(theta + h, p, q, r, s, omega, alpha, branch)
    om, stm = states(theta - h, p, q, r, s, omega, alpha, branch)
    good = (st0 == OK) & (stp == OK) & (stm == OK) & (np.sin(out[:, 2]) > 0.2)  # FD error grows near toggles
    if not good.any():
        return
    for col, wcol in ((0, 7), (1, 8)):
        dang = np.angle(np.exp(1j * (op[good, col] - om[good, col]))) / (2 * h)  # d(angle)/d(theta)
        assert np.allclose(out[good, wcol], omega * dang, rtol=1e-5, atol=1e-6 * (1 + abs(omega)) / np.sin(out[good, 2]) ** 2)
        # alpha_k = omega^2 g'(theta) + alpha g(theta), g = d(angle)/d(theta) = w_k / omega
        g = out[good, wcol] / omega
        gp = (op[good, wcol] - om[good, wcol]) / omega / (2 * h)
        scale = (1 + omega**2 + abs(alpha)) / np.sin(out[good, 2]) ** 3
        assert np.allclose(out[good, wcol + 2], omega**2 * gp + alpha * g, rtol=1e-4, atol=1e-5 * scale)


@pytest.mark.parametrize("crank", [2, 3, 4, 5])
def test_exact_agrees_with_listing_from_0_to_180(crank):
    """The listing is right for 0..180 deg: truncated angles, positions and speeds agree."""
    table, lst = fourbar_kernel.fourbar_listing(12.0, crank, 15.0, 9.0, 5.0, 0, 20, 10)   # 0..180
    out, st_ = states(table[:, 0] * 0.0174532, 12.0, crank, 15.0, 9.0, 5.0)  # the listing's own degree constant
    assert np.all(lst == OK) and np.all(st_ == OK)
    ang = np.column_stack([np.degrees(out[:, 0]) % 360, np.degrees(out[:, 1]) % 360, np.degrees(out[:, 2])])
    assert np.all((ang >= table[:, 1:4] - 1e-3) & (ang < table[:, 1:4] + 1 + 1e-3))
    assert np.allclose(out[:, 3:7], table[:, 4:8], atol=2e-5)
    assert np.allclose(out[:, 7:9], table[:, 8:10], atol=2e-5)


@pytest.mark.parametrize("q", [2.0, 3.0, 4.0, 5.0])
def test_transmission_and_rocker_extremes_in_closed_form(q, write_deck):
    """Crank-rocker: mu extremes at |A O_B| = p -/+ q; rocker extremes with crank and coupler collinear."""
    from driver._deck import read_deck, validate
    from driver.fourbar import SPEC, extremes
    p, r, s = 12.0, 15.0, 9.0
    deck = write_deck(f"&fourbar fixed_link={p}, crank={q}, coupler={r}, rocker={s}, step_deg=10 /\n")
    ex = extremes(validate(read_deck(deck).groups["fourbar"], SPEC, deck))
    mu = lambda d: math.degrees(math.acos((r * r + s * s - d * d) / (2 * r * s)))
    assert ex.mu_min == pytest.approx(mu(p - q), abs=1e-7)
    assert ex.mu_max == pytest.approx(mu(p + q), abs=1e-7)
    rocker = lambda e: math.degrees(math.acos((e * e - p * p - s * s) / (2 * p * s)))  # |O_A B| = e
    assert ex.rocker_min == pytest.approx(rocker(r + q), abs=1e-6)
    assert ex.rocker_max == pytest.approx(rocker(r - q), abs=1e-6)


@pytest.mark.parametrize("lengths,name,full", [
    ((12, 5, 15, 9), "crank-rocker", True),
    ((2, 5, 4.5, 4), "double-crank (drag link)", True),
    ((8, 6, 2, 7), "Grashof double-rocker", False),
    ((8, 7, 6, 2), "rocker-crank", False),
    ((10, 6, 7, 8), "non-Grashof triple-rocker", False),
    ((4, 2, 4, 2), "change-point double-crank (special Grashof)", True),   # a parallelogram
])
def test_grashof_classes(lengths, name, full):
    g = grashof(*lengths)
    assert (g.name, g.full_crank_rotation) == (name, full)


@pytest.mark.parametrize("lengths", [(10, 6, 7, 8), (8, 6, 2, 7)])
def test_assembly_changes_exactly_at_the_closed_form_limit_angles(lengths):
    lims = limit_angles(*lengths)
    assert lims
    for a in lims:
        t = np.radians([a - 1e-4, a + 1e-4])
        _, st_ = states(t, *lengths)
        assert sorted(st_) == [OK, fourbar_kernel.FOURBAR_STATUS["no_assembly"]]


def test_kinds_dp_is_double():
    from driver import _kernels
    assert int(_kernels.kinds.dp) == 8 and int(_kernels.kinds.sp) == 4


def test_branches_are_mirror_images_about_line_A_OB():
    theta = np.linspace(0, 2 * np.pi, 37)
    o, _ = states(theta, 12, 5, 15, 9, branch=1)
    c, _ = states(theta, 12, 5, 15, 9, branch=-1)
    assert np.allclose(o[:, 2], c[:, 2])                     # same transmission angle
    mid_o = o[:, 5:7] + c[:, 5:7]                            # B_open + B_crossed = 2 * foot point on A-O_B
    foot = mid_o / 2 - o[:, 3:5]
    d = np.column_stack([12 - o[:, 3], -o[:, 4]])
    assert np.allclose(foot[:, 0] * d[:, 1] - foot[:, 1] * d[:, 0], 0, atol=1e-9)


def test_vectorised_trig_matches_libm():
    """The kernel's branch-free sincos/atan2 against numpy (libm) over a wide angle range."""
    rng = np.random.default_rng(1)
    theta = np.concatenate([rng.uniform(-2e4, 2e4, 20000), np.linspace(-10, 10, 20001),
                            np.arange(-8, 9) * np.pi / 4])
    out, st_ = states(theta, 12.0, 5.0, 15.0, 9.0)
    assert np.all(st_ == OK)
    assert np.max(np.abs(out[:, 3] - 5.0 * np.cos(theta))) < 5.0 * 4e-16 * (1 + np.abs(theta).max() / 1e3)
    assert np.max(np.abs(out[:, 4] - 5.0 * np.sin(theta))) < 5.0 * 4e-16 * (1 + np.abs(theta).max() / 1e3)
    e2 = (out[:, 5] - out[:, 3], out[:, 6] - out[:, 4])
    assert np.max(np.abs(np.angle(np.exp(1j * (out[:, 0] - np.arctan2(e2[1], e2[0])))))) < 1e-15
    assert np.max(np.abs(np.angle(np.exp(1j * (out[:, 1] - np.arctan2(out[:, 6], out[:, 5] - 12.0)))))) < 1e-15


@settings(max_examples=60, deadline=None)
@given(p=length, q=length, r=length, s=length, branch=st.sampled_from([1, -1]),
       u=st.floats(-10, 10), v=st.floats(-10, 10), omega=st.floats(0.5, 10), alpha=st.floats(-20, 20))
def test_coupler_point_is_rigid_with_the_coupler_and_its_derivatives(p, q, r, s, branch, u, v, omega, alpha):
    theta = np.linspace(0.05, 2 * np.pi - 0.05, 61)
    h = 1e-5

    def point(t):
        o, st_ = states(t, p, q, r, s, omega, alpha, branch)
        return fourbar_kernel.fourbar_coupler_point(t, o, st_, q, omega, alpha, u, v), o, st_

    cp, out, st0 = point(theta)
    ok = (st0 == OK) & (np.sin(out[:, 2]) > 0.2)
    if not ok.any():
        return
    a, b, pp = out[ok, 3:5], out[ok, 5:7], cp[ok, :2]
    scale = max(p, q, r, s, abs(u), abs(v))
    assert np.allclose(np.hypot(*(pp - a).T), math.hypot(u, v), atol=1e-11 * scale)
    assert np.allclose(np.hypot(*(pp - b).T), math.hypot(r - u, v), atol=1e-11 * scale)
    cross = (b - a)[:, 0] * (pp - a)[:, 1] - (b - a)[:, 1] * (pp - a)[:, 0]   # = r v: P left of A->B when v > 0
    assert np.allclose(cross, r * v, atol=1e-10 * scale**2)
    cpp, _, stp = point(theta + h)
    cpm, _, stm = point(theta - h)
    good = ok & (stp == OK) & (stm == OK)
    if not good.any():
        return
    vel = omega * (cpp[good, :2] - cpm[good, :2]) / (2 * h)                          # dP/dt at constant omega
    tol = 1e-5 * (1 + omega**2 + abs(alpha)) * scale / np.sin(out[good, 2])[:, None] ** 3
    assert np.all(np.abs(cp[good, 2:4] - vel) <= tol)
    # a_P = omega^2 d2P/dtheta2 + alpha dP/dtheta
    d2 = (cpp[good, :2] - 2 * cp[good, :2] + cpm[good, :2]) / h**2
    acc = omega**2 * d2 + alpha * (cpp[good, :2] - cpm[good, :2]) / (2 * h)
    assert np.all(np.abs(cp[good, 4:6] - acc) <= 1e3 * tol)
