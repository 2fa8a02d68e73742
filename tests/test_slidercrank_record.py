"""The slider-crank kernel records only what the study prints (issue 27, step 4).

``fields=False`` skips the three (elements x steps) strain/force fields and returns their
per-step profile, computed in Fortran while the step's strain column is at hand.  Truth: the
same kernel run with the fields recorded, reduced here by numpy (max/min/argmax/argmin over
the elements, a revolution-apart difference); and the study's figures (peaks with their
element and angle, crank-end strain, settling) from the profile equal the formulas on the
full field they replaced, ties included (numpy's argmax order over the (element, step) field).
"""
from __future__ import annotations

import numpy as np
import pytest

from driver.slidercrank import _kernel as slidercrank_kernel
from driver.slidercrank._analysis import PROFILE, Case, _settle

STEEL = dict(crank_radius=0.15, rod_length=0.3, rho_a=7870 * 64e-6, ea=2e11 * 64e-6, ei=2e11 * 3.413333333e-10,
             half_depth=0.004, slider_mass=0.075552, omega=150.0, dt=2.5e-5)


@pytest.mark.parametrize("nel", [1, 2, 5, 16])
@pytest.mark.parametrize("lag", [0, 37])
def test_profile_equals_the_fields_reduced(nel, lag):
    kw = dict(STEEL, n_elements=nel, n_steps=300, rec_start=50, n_rec=200, alpha=1.0, beta=1e-6)
    full = slidercrank_kernel.slidercrank_simulate(**kw)
    prof = slidercrank_kernel.slidercrank_simulate(**kw, fields=False, lag=lag)
    assert full["status"] == prof["status"] == 0
    assert prof["eps_ax"] is None and prof["eps_of"] is None and prof["n_avg"] is None
    e, o = full["eps_ax"], full["eps_of"]
    for key in ("mid", "slider", "elong", "q_end", "qd_end"):
        np.testing.assert_array_equal(prof[key], full[key])
    np.testing.assert_array_equal(prof["eps_1"], e[0])
    np.testing.assert_array_equal(prof["eps_2"], e[min(1, nel - 1)])
    np.testing.assert_array_equal(prof["eps_max"], e.max(axis=0))
    np.testing.assert_array_equal(prof["eps_min"], e.min(axis=0))
    np.testing.assert_array_equal(prof["eps_max_el"], e.argmax(axis=0))
    np.testing.assert_array_equal(prof["eps_min_el"], e.argmin(axis=0))
    np.testing.assert_array_equal(prof["outer_max"], o.max(axis=0))
    np.testing.assert_array_equal(prof["n_avg_1"], full["n_avg"][0])
    if lag:
        want = [np.abs(e[:, j] - e[:, j - lag]).max() if j >= lag else 0.0 for j in range(e.shape[1])]
        np.testing.assert_array_equal(prof["lag_change"], want)
    else:
        assert "lag_change" not in prof


def _case_from_field(e: np.ndarray, o: np.ndarray, angles: np.ndarray) -> Case:
    c = Case(100.0, e.shape[0], "ok", angle_deg=angles)
    c.eps_1, c.eps_2 = e[0], e[min(1, e.shape[0] - 1)]
    c.eps_max, c.eps_max_el, c.eps_min, c.eps_min_el = e.max(0), e.argmax(0), e.min(0), e.argmin(0)
    c.outer_max = o.max(0)
    return c


def _old_peak(e: np.ndarray, angles: np.ndarray, sign: int) -> tuple[float, float, int]:
    """The formula the profile replaced: numpy's argmax over the whole (element, step) field."""
    flat = np.argmax(sign * e)
    i, j = np.unravel_index(flat, e.shape)
    return float(e[i, j]), float(angles[j] % 360.0), int(i) + 1


def test_peaks_from_the_profile_equal_the_field_formulas_with_ties():
    rng = np.random.default_rng(7)
    angles = np.linspace(0.0, 360.0, 13)
    for trial in range(400):
        nel = int(rng.integers(1, 6))
        e = rng.integers(-3, 4, size=(nel, 13)).astype(float) * 1e-4   # coarse: many exact ties
        if trial % 5 == 0:
            e[e == 0] = -0.0
        o = np.abs(e) + rng.integers(0, 3, size=e.shape) * 1e-5
        c = _case_from_field(e, o, angles)
        for sign in (+1, -1):
            assert c.peak(sign) == _old_peak(e, angles, sign)
            old = e[0] if nel < 2 else 1.5 * e[0] - 0.5 * e[1]
            assert c.crank_end_peak(sign) == float(np.max(sign * old) * sign)
        assert c.outer_peak() == float(o.max())


def test_settling_from_the_profile_equals_the_field_formula():
    spr = 60
    kw = dict(STEEL, n_elements=8, n_steps=3 * spr, rec_start=spr, n_rec=2 * spr + 1, alpha=0.0, beta=0.0,
              start="rest")
    full = slidercrank_kernel.slidercrank_simulate(**kw)
    prof = slidercrank_kernel.slidercrank_simulate(**kw, fields=False, lag=spr)
    e = full["eps_ax"]

    def change(a, b):
        peak = float(np.abs(b).max())
        return float(np.abs(b - a).max()) / peak if peak > 0 else 0.0
    got = _settle(prof, spr)
    assert got["settle_strain"] == change(e[:, :spr + 1], e[:, spr:]) > 0
    assert got["settle_mid"] == change(full["mid"][:spr + 1], full["mid"][spr:])
    for name in PROFILE:
        assert len(got[name]) == spr + 1
