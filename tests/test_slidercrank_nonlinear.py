"""The geometrically nonlinear connecting rod (model = 'nonlinear', fortran/slidercrank_nl.f90)
against independent truths: the elastica's closed form (complete elliptic integral), the linear
KED model in the small-amplitude limit, rigid-body statics for a stiff rod, the energy identity
of the undamped system, finite differences of the element's energy, and bad input."""
from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import ellipk

from driver.slidercrank import _kernel as slidercrank_kernel
from driver.slidercrank._spec import MATERIALS, rayleigh

ROOT = Path(__file__).resolve().parents[1]
AL = MATERIALS["aluminium"]
L, R2, MS = 0.505, 0.125, 0.95
EA, EI = AL["youngs_modulus"] * AL["area"], AL["youngs_modulus"] * AL["second_moment"]
RHOA, C = AL["density"] * AL["area"], AL["section_depth"] / 2


def elastica_midspan(ratio: float, length: float) -> float:
    """Mid-span deflection of the inextensible pinned-pinned elastica at P/P_E = ratio > 1:
    P/P_E = (2 K(k)/pi)^2 and delta = 2 k / lambda = k L / K(k), k = sin(alpha/2), K the
    complete elliptic integral of the first kind (scipy's ellipk takes m = k^2)."""
    m = brentq(lambda m: 2 * ellipk(m) / math.pi - math.sqrt(ratio), 1e-14, 0.999)
    return math.sqrt(m) / ellipk(m) * length


@pytest.mark.parametrize("ratio, n", [(1.015, 120), (1.06, 60), (1.2, 40)])
def test_static_post_buckling_reaches_the_elastica(ratio, n):
    p_e = math.pi ** 2 * EI / L ** 2
    mid, short, iters, status = slidercrank_kernel.slidercrank_column_static(n, L, EA, EI, ratio * p_e, L / 20)
    assert status == slidercrank_kernel.SLIDERCRANK_NL_STATUS["ok"], (status, iters)
    exact = elastica_midspan(ratio, L)
    assert abs(abs(mid) - exact) < 0.01 * exact, (mid, exact)
    assert short > 0


@pytest.mark.parametrize("ratio", [0.5, 0.95, 0.99])
def test_column_below_the_euler_load_stays_straight(ratio):
    p_e = math.pi ** 2 * EI / L ** 2
    mid, short, _, status = slidercrank_kernel.slidercrank_column_static(40, L, EA, EI, ratio * p_e, L / 20)
    assert status == 0
    assert abs(mid) < 1e-9 * L
    assert short == pytest.approx(ratio * p_e * L / EA, rel=1e-6)   # only the axial shortening P L / EA


def test_element_force_and_tangent_are_derivatives():
    """f = dU/dp and K_T = df/dp (central differences) at a large rotation and stretch."""
    le, ea, ei = 0.02, 1e6, 2.0
    p = np.array([1e-4, 2e-3, 0.3, -2e-4, 5e-3, -0.1])
    f, kt, _, _, en = slidercrank_kernel.slidercrank_corot_element(le, ea, ei, p)
    kt = np.tril(kt) + np.tril(kt, -1).T
    h = 1e-7
    for j in range(6):
        dp = np.zeros(6)
        dp[j] = h
        fp, _, _, _, ep = slidercrank_kernel.slidercrank_corot_element(le, ea, ei, p + dp, False)
        fm, _, _, _, em = slidercrank_kernel.slidercrank_corot_element(le, ea, ei, p - dp, False)
        assert (ep - em) / (2 * h) == pytest.approx(f[j], rel=1e-6, abs=1e-6 * np.abs(f).max())
        np.testing.assert_allclose((fp - fm) / (2 * h), kt[:, j], rtol=1e-5, atol=1e-6 * np.abs(kt).max())


def test_damped_element_tangent_is_the_derivative_of_the_damped_force():
    """With stiffness-proportional damping of the deformation rates, f = f_el(p) + bd B(p)^T K_l B(p) pd:
    the tangent at rate_weight 0 is df/dp at fixed rates (central differences; not symmetric: the
    variation of B in the deformation rates), and the rate_weight part is (1/bd) df/dpd."""
    le, ea, ei, bd = 0.02, 1e6, 2.0, 3e-3
    p = np.array([1e-4, 2e-3, 0.3, -2e-4, 5e-3, -0.1])
    pd = np.array([0.3, -1.2, 40.0, -0.5, 2.0, -25.0])      # fast turns: the buckled rod's rates
    f, kt, _, _, _ = slidercrank_kernel.slidercrank_corot_element(le, ea, ei, p, True, pd, bd)
    f_el, _, _, _, _ = slidercrank_kernel.slidercrank_corot_element(le, ea, ei, p, False)
    assert np.abs(f - f_el).max() > 1e-3 * np.abs(f_el).max()            # the damping force counts here
    h = 1e-7
    fd_p, fd_pd = np.zeros((6, 6)), np.zeros((6, 6))
    for j in range(6):
        dp = np.zeros(6)
        dp[j] = h
        fd_p[:, j] = (slidercrank_kernel.slidercrank_corot_element(le, ea, ei, p + dp, False, pd, bd)[0]
                      - slidercrank_kernel.slidercrank_corot_element(le, ea, ei, p - dp, False, pd, bd)[0]) / (2 * h)
        fd_pd[:, j] = (slidercrank_kernel.slidercrank_corot_element(le, ea, ei, p, False, pd + dp, bd)[0]
                       - slidercrank_kernel.slidercrank_corot_element(le, ea, ei, p, False, pd - dp, bd)[0]) / (2 * h)
    np.testing.assert_allclose(kt, fd_p, rtol=1e-5, atol=1e-6 * np.abs(kt).max())
    assert np.abs(kt - kt.T).max() > 1e-4 * np.abs(kt).max()              # not symmetric
    kt1 = slidercrank_kernel.slidercrank_corot_element(le, ea, ei, p, True, pd, bd, rate_weight=1.0)[1]
    np.testing.assert_allclose(bd * (kt1 - kt), fd_pd, rtol=1e-5, atol=1e-6 * np.abs(fd_pd).max())


def test_newton_converges_quadratically_on_the_buckled_rod():
    """With the consistent tangent (damping included) a step converges in one Newton solve whenever
    the predictor is close.  40 elements, 3 revolutions: below the onset every step takes one
    solve; on the buckled rods, whose elements turn fast, well under two (a tangent without the
    damping's geometric variation converges only linearly there: 1.04, 2.07 and 1.82 solves a step
    in these three cases)."""
    out = {}
    for mat, omega in (("aluminium", 21.99), ("aluminium", 25.13), ("medium_carbon_steel", 29.32)):
        m = MATERIALS[mat]
        ea, ei, rhoa = m["youngs_modulus"] * m["area"], m["youngs_modulus"] * m["second_moment"], m["density"] * m["area"]
        al, be = rayleigh(0.02, *slidercrank_kernel.slidercrank_frequencies(rhoa, ea, ei, L, MS)[:2])
        spr, revs = 1440, 3
        dt = 2 * math.pi / (omega * spr)
        r = slidercrank_kernel.slidercrank_nl_simulate(40, R2, L, rhoa, ea, ei, m["section_depth"] / 2, MS, omega, dt, revs * spr,
                                            spr, (revs - 1) * spr, spr + 1, al, be, hht=-0.05)
        assert r["status"] == 0
        out[mat, omega] = r["stats"][0] / (revs * spr)
    assert out["aluminium", 21.99] < 1.001, out
    assert out["aluminium", 25.13] < 1.7 and out["medium_carbon_steel", 29.32] < 1.4, out


def test_small_displacements_reproduce_the_linear_frame_element():
    le, ea, ei = 0.02, 1e6, 2.0
    _, kt, _, _, _ = slidercrank_kernel.slidercrank_corot_element(le, ea, ei, np.zeros(6))
    b = ei / le ** 3
    k0 = np.array([[ea / le, 0, 0, -ea / le, 0, 0], [0, 12 * b, 6 * b * le, 0, -12 * b, 6 * b * le],
                   [0, 6 * b * le, 4 * b * le ** 2, 0, -6 * b * le, 2 * b * le ** 2],
                   [-ea / le, 0, 0, ea / le, 0, 0], [0, -12 * b, -6 * b * le, 0, 12 * b, -6 * b * le],
                   [0, 6 * b * le, 2 * b * le ** 2, 0, -6 * b * le, 4 * b * le ** 2]])
    np.testing.assert_allclose(np.tril(kt), np.tril(k0), rtol=1e-12, atol=1e-9 * ea / le)


def _both(omega: float, n: int = 20, spr: int = 1440, revs: int = 2, ea: float = EA, ei: float = EI,
          damping: bool = True) -> tuple[dict, dict, float]:
    wb, wa, _ = slidercrank_kernel.slidercrank_frequencies(RHOA, ea, ei, L, MS)
    al, be = rayleigh(0.02, wb, wa) if damping else (0.0, 0.0)
    dt = 2 * math.pi / (omega * spr)
    ns, rs = revs * spr, (revs - 1) * spr
    lin = slidercrank_kernel.slidercrank_simulate(n, R2, L, RHOA, ea, ei, C, MS, omega, dt, ns, rs, spr + 1, al, be)
    nl = slidercrank_kernel.slidercrank_nl_simulate(n, R2, L, RHOA, ea, ei, C, MS, omega, dt, ns, spr, rs, spr + 1, al, be)
    assert lin["status"] == 0 and nl["status"] == 0
    return lin, nl, dt


def _curve_gap(omega: float) -> float:
    lin, nl, _ = _both(omega)
    e_lin, e_nl = lin["eps_ax"][0], nl["eps_ax"][0]
    return float(np.abs(e_nl - e_lin).max() / np.abs(e_lin).max())


def test_small_amplitude_limit_matches_the_linear_model():
    """At the paper's lowest speed the crank-end strain curves agree within 1 %, and closer as
    the speed falls (the nonlinear terms grow with the load, i.e. with omega^2)."""
    gaps = [_curve_gap(w) for w in (2.88, 5.76, 11.52)]
    assert gaps[-1] < 0.01
    assert gaps[0] < gaps[1] < gaps[2]


def test_stiff_rod_carries_the_rigid_body_axial_force():
    """E x 1000: the elastic response is quasi-static and the crank-end element's force EA eps
    equals the element average of the rigid-body N(s) (statics, Simpson exact for quadratic N)."""
    n = 10
    ea, ei = EA * 1000, EI * 1000
    _, nl, dt = _both(21.99, n=n, ea=ea, ei=ei)
    spr = 1440
    theta = 21.99 * dt * (spr + np.arange(spr + 1))
    s = np.array([0.0, L / (2 * n), L / n])
    nr = slidercrank_kernel.slidercrank_axial_force(theta, s, 21.99, R2, L, RHOA, MS)
    n_avg = (nr[0] + 4 * nr[1] + nr[2]) / 6
    force = ea * nl["eps_ax"][0]
    assert np.abs(force - n_avg).max() < 2e-3 * np.abs(n_avg).max()


def test_energy_balance_closes_to_the_integrator_error():
    """Damping off: kinetic + strain energy equals the start's plus the work of the loads Q and
    of the moving guide, to the trapezoidal rule's O(dt^2) over three revolutions."""
    def imbalance(spr: int) -> float:
        dt = 2 * math.pi / (21.99 * spr)
        ns = 3 * spr
        r = slidercrank_kernel.slidercrank_nl_simulate(20, R2, L, RHOA, EA, EI, C, MS, 21.99, dt, ns, spr, 0, ns + 1,
                                            energy=True)
        assert r["status"] == 0
        t, u, w, d = r["energy"]
        assert not d.any()
        return float(np.abs(t + u - w - (t[0] + u[0])).max() / np.abs(w).max())
    coarse, fine = imbalance(720), imbalance(1440)
    assert fine < 1e-5
    assert 3.5 < coarse / fine < 4.5


def test_energy_balance_with_damping():
    spr = 1440
    wb, wa, _ = slidercrank_kernel.slidercrank_frequencies(RHOA, EA, EI, L, MS)
    al, be = rayleigh(0.02, wb, wa)
    dt = 2 * math.pi / (18.85 * spr)
    ns = 2 * spr
    r = slidercrank_kernel.slidercrank_nl_simulate(20, R2, L, RHOA, EA, EI, C, MS, 18.85, dt, ns, spr, 0, ns + 1, al, be,
                                        energy=True)
    t, u, w, d = r["energy"]
    assert d[-1] > 0
    assert np.abs(t + u - w + d - (t[0] + u[0])).max() < 1e-4 * np.abs(w).max()


def _deck(tmp_path: Path, body: str) -> Path:
    deck = tmp_path / "nl.dat"
    deck.write_text("&slidercrank\n  material = 'aluminium'\n  model = 'nonlinear'\n" + body + "/\n")
    return deck


def _run(deck: Path, out: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "driver", str(deck), "-o", str(out)], capture_output=True,
                          text=True, cwd=ROOT)


def test_newton_failure_is_reported_with_step_and_iterations(tmp_path):
    """Too large a step for the Newton iterations allowed (and no cuts): a named failure with the
    step and the iteration count, non-zero exit, and no NaN in the table."""
    deck = _deck(tmp_path, "  speeds = 29.32\n  n_elements = 10\n  steps_per_rev = 360, revolutions = 4\n"
                           "  newton_max_iterations = 1, max_step_cuts = 0\n")
    res = _run(deck, tmp_path / "out")
    assert res.returncode != 0
    assert "NO CONVERGENCE at step" in res.stderr and "after 1 Newton solves" in res.stderr
    text = (tmp_path / "out" / "nl.out").read_text()
    assert "NO CONVERGENCE" in text
    assert "nan" not in text.lower() and "inf " not in text.lower()


def test_step_cuts_rescue_a_coarse_step(tmp_path):
    deck = _deck(tmp_path, "  speeds = 29.32\n  n_elements = 10\n  steps_per_rev = 360, revolutions = 4\n"
                           "  newton_max_iterations = 4, max_step_cuts = 8\n")
    res = _run(deck, tmp_path / "out")
    assert res.returncode == 0, res.stderr
    text = (tmp_path / "out" / "nl.out").read_text()
    assert "time step(s) halved" in text


@pytest.mark.parametrize("line, key", [("element_counts = 2, 4", "element_counts"), ("end_time = 0.1", "end_time"),
                                       ("geometric_stiffness = .true.", "geometric_stiffness"),
                                       ("revolutions = 3", "revolutions"), ("newton_tolerance = 0.5", "newton_tolerance"),
                                       ("onset_speeds = 0.5, 30", "onset_speeds"), ("hht_alpha = -0.5", "hht_alpha")])
def test_linear_only_options_are_refused(tmp_path, line, key):
    deck = _deck(tmp_path, f"  speeds = 11.52\n  n_elements = 10\n  {line}\n")
    res = _run(deck, tmp_path / "out")
    assert res.returncode == 2
    assert key in res.stderr
    assert not (tmp_path / "out" / "nl.out").exists()


def test_growth_ratio_definition():
    from driver.slidercrank._analysis_nl import growth_ratio, scatter
    assert growth_ratio(np.ones(8)) == 0.0
    assert growth_ratio(np.array([2.0, 1.0] * 6)) == 0.0                 # period 2: steady
    assert growth_ratio(1.1 ** np.arange(12)) == pytest.approx(0.1)      # 10 % a revolution
    assert growth_ratio(np.array([1.0] * 10 + [3.0, 1.0])) == 0.0        # one large revolution is no trend
    assert growth_ratio(1.1 ** np.arange(4)) == pytest.approx(0.1)       # the fewest revolutions allowed
    assert scatter(np.array([9.0] * 4 + [1.0, 2.0, 1.0, 1.5] * 2)) == pytest.approx(1.0)


def test_nonlinear_figures_draw_the_given_curves_and_accept_axes():
    pytest.importorskip("matplotlib")
    from matplotlib.figure import Figure as MplFigure

    from driver.slidercrank import _figures as slidercrank_figures
    x = np.linspace(0.0, 360.0, 7)
    lin, nl = np.sin(np.radians(x)), 2 * np.sin(np.radians(x))
    fig = slidercrank_figures.slidercrank_nl_strain_figure([("10 rad/s", x, lin, nl)], "strain")
    solid, dashed = fig.axes[0].lines[:2]
    np.testing.assert_array_equal(solid.get_ydata(), nl)
    np.testing.assert_array_equal(dashed.get_ydata(), lin)
    assert dashed.get_linestyle() == "--"
    own = MplFigure()
    ax = own.subplots()
    shapes = np.column_stack([np.linspace(0, 1e-3, 5), np.zeros(5)])
    assert slidercrank_figures.slidercrank_nl_shapes_figure([("a", (90.0, 180.0), shapes)], 0.5, "s", ax=ax) is own
    np.testing.assert_allclose(ax.lines[0].get_ydata(), shapes[:, 0] * 1e3)   # drawn in mm
    np.testing.assert_allclose(ax.lines[0].get_xdata(), np.linspace(0, 0.5, 5))
    ax2 = MplFigure().subplots()
    slidercrank_figures.slidercrank_nl_revolutions_figure([("a", np.array([1.0, 2.0, 4.0]))], "r", ax=ax2)
    np.testing.assert_array_equal(ax2.lines[0].get_xdata(), [1, 2, 3])
