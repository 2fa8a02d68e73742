"""Large arrays cross the f2py boundary without hidden copies (docs/build.md, pitfall 2.2).

numpy reports its data buffers to tracemalloc, so the peak allocation during a call shows
whether f2py (or the wrapper) copied an input: it equals the array's size when it did.
"""
from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from driver.fourbar import _kernel as fourbar_kernel
from driver.manipulator import _kernel as manipulator_kernel


def peak_alloc(fn) -> int:
    tracemalloc.start()
    tracemalloc.reset_peak()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_fourbar_reused_buffers_are_not_copied():
    n = 200_000
    theta = np.linspace(0, 2 * np.pi, n)
    out = np.empty((n, 11), order="F")
    status = np.empty(n, dtype=np.int32)
    fourbar_kernel.fourbar_exact(theta, 12, 5, 15, 9, 5, out=out, status=status)   # warm up
    assert peak_alloc(lambda: fourbar_kernel.fourbar_exact(theta, 12, 5, 15, 9, 5, out=out, status=status)) < out.nbytes // 20


def test_fourbar_refuses_a_c_ordered_buffer_instead_of_copying_it():
    n = 1000
    out = np.empty((n, 11))               # C order: f2py must not silently work on a copy
    with pytest.raises(ValueError):
        fourbar_kernel.fourbar_exact(np.zeros(n), 12, 5, 15, 9, 5, out=out, status=np.empty(n, dtype=np.int32))


def test_fourbar_forces_reuse_the_callers_buffer():
    """Issue 37: the force kernel takes out= as the kinematics kernel does: the same values as a
    fresh array, written into the caller's buffer (no allocation of the output, no copy), and a
    buffer f2py would copy is refused."""
    n = 200_000
    lk = (0.30, 0.10, 0.35, 0.25, 20.0, 3.0)
    props = np.array([0.5, 1.2, 0.9, 4e-4, 1.2e-2, 4.7e-3, 0.05, 0.175, 0.125, 0.1, 0.2, -0.3, 9.81, 5.0, 10.0, -20.0,
                      0.175, 0.05])
    states, status = fourbar_kernel.fourbar_exact(np.linspace(0, 2 * np.pi, n), *lk)
    fresh = fourbar_kernel.fourbar_joint_forces(states, status, *lk, props)
    out = np.full((n, 12), np.nan, order="F")
    got = fourbar_kernel.fourbar_joint_forces(states, status, *lk, props, out=out)
    assert got is out
    np.testing.assert_array_equal(out, fresh)
    assert peak_alloc(lambda: fourbar_kernel.fourbar_joint_forces(states, status, *lk, props, out=out)) < out.nbytes // 20
    for bad in (np.empty((n, 12)), np.empty((n, 11), order="F"), np.empty((n, 12), order="F", dtype=np.float32)):
        with pytest.raises(ValueError):
            fourbar_kernel.fourbar_joint_forces(states, status, *lk, props, out=bad)


def test_manipulator_monte_carlo_samples_are_not_copied():
    ns = 400_000
    dl = np.asfortranarray(np.random.default_rng(0).uniform(-1e-3, 1e-3, (ns, 2)))
    th1, th2 = np.radians([30.0, 50.0, 70.0]), np.radians([60.0, 40.0, 20.0])
    manipulator_kernel.manipulator_position_errors(th1, th2, dl)
    peak = peak_alloc(lambda: manipulator_kernel.manipulator_position_errors(th1, th2, dl))
    assert peak < 1.5 * dl.nbytes          # the (ns, 2) result only, no copy of the input


def test_manipulator_arm_states_reused_buffers_are_not_copied():
    n = 100_000
    rng = np.random.default_rng(2)
    l1, l2 = rng.uniform(1, 7, n), rng.uniform(1, 7, n)
    th1, th2 = rng.uniform(-np.pi, np.pi, n), rng.uniform(-np.pi, np.pi, n)
    fresh = manipulator_kernel.manipulator_arm_states(l1, l2, th1, th2)
    out = (np.empty((n, 4), order="F"), np.empty(n), np.empty(n), np.empty((n, 2), order="F"))
    got = manipulator_kernel.manipulator_arm_states(l1, l2, th1, th2, out=out)
    assert all(a is b for a, b in zip(got, out))                     # returned in place
    for a, b in zip(got, fresh):
        assert np.array_equal(a, b)
    # only the broadcast inputs (qd, qdd, masses: 6 columns) are allocated, no output
    assert peak_alloc(lambda: manipulator_kernel.manipulator_arm_states(l1, l2, th1, th2, out=out)) < 7 * 8 * n
    with pytest.raises(ValueError):
        manipulator_kernel.manipulator_arm_states(l1, l2, th1, th2, out=(np.empty((n, 4)),) + out[1:])   # C order
