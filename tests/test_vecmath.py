"""Accuracy of fortran/vecmath.f90 (the array sin/cos/atan2 of the kernels' hot loops)
against the C library's scalar functions (Python's math module), which are independent
implementations accurate to within an ulp."""
from __future__ import annotations

import math

import numpy as np
import pytest

from driver import _kernels

vm = _kernels.vecmath


def ulps(got: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """|got - ref| in units of the last place of ref (of the smallest normal for ref = 0)."""
    return np.abs(got - ref) / np.spacing(np.maximum(np.abs(ref), np.finfo(float).tiny))


@pytest.mark.parametrize("span", [1.0, 7.0, 100.0, 1e4, 1e5])
def test_sincos_within_two_ulp_of_libm(span):
    x = np.random.default_rng(int(span)).uniform(-span, span, 50_000)
    s, c = vm.sincos_array(x)
    rs = np.array([math.sin(v) for v in x])
    rc = np.array([math.cos(v) for v in x])
    assert ulps(s, rs).max() <= 2.0
    assert ulps(c, rc).max() <= 2.0


def test_sincos_exact_points_and_identity():
    x = np.array([0.0, math.pi / 6, math.pi / 2, math.pi, 3 * math.pi / 2, 2 * math.pi, -math.pi / 4])
    s, c = vm.sincos_array(x)
    assert s[0] == 0.0 and c[0] == 1.0
    np.testing.assert_allclose(s, [0, 0.5, 1, 0, -1, 0, -math.sqrt(0.5)], atol=3e-16)
    np.testing.assert_allclose(c, [1, math.sqrt(0.75), 0, -1, 0, 1, math.sqrt(0.5)], atol=3e-16)
    x = np.linspace(-50, 50, 10_001)
    s, c = vm.sincos_array(x)
    assert np.abs(s * s + c * c - 1).max() < 4e-16


def test_sincos_beyond_the_fast_range_and_non_finite():
    """Arguments past the vector reduction's range take the libm pass: exactly libm's result."""
    assert vm.sincos_fast_limit == 1e5
    x = np.array([0.5, 1e5 + 1, -3e6, 1e15, 1e300, -1e300, 2.0])
    s, c = vm.sincos_array(x)
    for v, sv, cv in zip(x, s, c):
        if abs(v) > 1e5:
            assert sv == math.sin(v) and cv == math.cos(v)
    s, c = vm.sincos_array(np.array([np.inf, -np.inf, np.nan, 1.0]))
    assert np.isnan(s[:3]).all() and np.isnan(c[:3]).all()
    assert s[3] == pytest.approx(math.sin(1.0), rel=3e-16)


def test_sincos_blocks_of_every_length():
    """Results do not depend on where an argument sits in the array (vector body, remainder)."""
    x = np.random.default_rng(5).uniform(-10, 10, 37)
    s_all, c_all = vm.sincos_array(x)
    for n in range(1, 37):
        s, c = vm.sincos_array(x[:n])
        assert np.array_equal(s, s_all[:n]) and np.array_equal(c, c_all[:n])


def test_atan2_within_two_ulp_of_libm_over_all_quadrants_and_scales():
    rng = np.random.default_rng(11)
    n = 100_000
    y = rng.normal(size=n) * 10.0 ** rng.uniform(-8, 8, n)
    x = rng.normal(size=n) * 10.0 ** rng.uniform(-8, 8, n)
    t = vm.atan2_array(y, x)
    r = np.array([math.atan2(a, b) for a, b in zip(y, x)])
    assert ulps(t, r).max() <= 2.0
    assert np.all(np.abs(t) <= math.pi)


def test_atan2_axes_and_diagonals():
    y = np.array([0.0, 1.0, -1.0, 0.0, 1.0, -1.0, 1.0, -1.0, 0.0, -0.0, 2.5])
    x = np.array([1.0, 0.0, 0.0, -1.0, 1.0, 1.0, -1.0, -1.0, 0.0, 1.0, 2.5])
    t = vm.atan2_array(y, x)
    ref = [math.atan2(a, b) for a, b in zip(y, x)]
    assert list(t) == ref                                # exact on the axes and diagonals
    assert math.copysign(1.0, t[9]) == -1.0              # atan2(-0, 1) = -0
