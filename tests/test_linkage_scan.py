"""The batch summary does not depend on how finely the cycle is scanned, to the digits a sweep
prints: the Watt II six-bar's summary columns from a 72-point scan (the 10^6-design sweep of
bench/bench_linkage.py and docs/performance.md) agree with a 7200-point scan of the same designs
to half a unit of the fourth decimal the sweep's ``.out`` table prints, on 25 designs spread over
the bench's sweep ranges (crank length 0.06-0.12, link5 0.19-0.24).

Why a coarse scan can be exact: the output's extremes (stroke, time ratio) are refined between
scan points on the quintic Hermite model (the output angle and its first and second derivatives,
which the kernel computes exactly at every scan point); the links' peak angular velocities on the
cubic Hermite model (omega and its derivative from alpha); the least transmission angle of these
crank-rockers lies at a crank angle of 0 or 180 deg, on every scan.  The columns still refined by
the parabola through three scan points (peak alpha, the largest transmission angle) are
checked at the resolution where they do agree (360 points: within 5e-5 for the angle, not for
the peak alpha; docs/linkage.md says which).

Truth: the 7200-point scan (its refinements act on intervals of 0.05 deg: 1e-12 of the figures),
and for two designs the kernel's own kinematics sampled at 72 000 inputs without any refinement
(the extremes of the sampled output angle and omega, within the sampling error)."""
from __future__ import annotations

import numpy as np
import pytest

from driver.linkage import _kernel as kernel
from driver.linkage import compile_deck
from driver.linkage._batch import summarise_batch
from linkage_oracle import params_of

WATT = """pivots = 'O2', 'O4', 'O6', pivot_xy = 0, 0,   0.30, 0,   0.256, 0.126
  driver_joints = 'O2', 'A', driver_length = {length!r}, omega = 10.0, step = 10
  dyads = 'RRR', 'RRR', dyad_joints = 'A', 'O4', 'B',   'C', 'O6', 'D'
  dyad_links = 'coupler', 'rocker', 'link5', 'link6'
  dyad_dims = 0.35, 0.30, {link5!r}, 0.189, dyad_modes = 1, -1
  points = 'C', point_on = 'rocker', point_uv = -0.15, 0
  scan_points = {scan}"""
LENGTHS = np.linspace(0.06, 0.12, 5)
LINK5 = np.linspace(0.19, 0.24, 5)
#: half a unit of the fourth decimal: the sweep's .out prints its numbers to 4 decimals
PRINTED = 0.5e-4
#: the columns a 72-point scan gives to the printed digits
EXACT = ("output_min", "output_max", "stroke", "time_ratio", "mu_min_deg", "omega_peak_coupler_rad_s",
         "omega_peak_rocker_rad_s", "omega_peak_link5_rad_s", "omega_peak_link6_rad_s")
#: inputs of extremes [deg]: printed to 4 decimals too
EXACT_AT = ("output_min_at", "output_max_at", "mu_min_at")


def _summaries(scan: int):
    grid = np.meshgrid(LENGTHS, LINK5, indexing="ij")
    cols = {"driver_length": grid[0].ravel(), "dyad_dims(3)": grid[1].ravel()}
    return summarise_batch(params_of(WATT.format(length=0.10, link5=0.214, scan=scan)), cols)


@pytest.fixture(scope="module")
def fine():
    return _summaries(7200)


@pytest.mark.parametrize("scan", [72, 360])
def test_coarse_scan_gives_the_printed_digits(scan, fine):
    coarse = _summaries(scan)
    assert len(coarse) == 25 and coarse["assemblable"].all()
    for c in EXACT + EXACT_AT:
        err = np.abs(coarse[c].to_numpy(float) - fine[c].to_numpy(float))
        assert err.max() <= PRINTED, (scan, c, err.max())
    # the designs differ in every checked figure (a column that ignored the design would pass);
    # the least transmission angle is the first loop's (B's), set by the crank length alone
    for c in ("stroke", "time_ratio", "omega_peak_link6_rad_s"):
        assert fine[c].nunique() == 25, c
    assert fine["mu_min_deg"].nunique() == len(LENGTHS)


def test_parabola_refined_columns_at_their_resolution(fine):
    """The largest transmission angle (parabola-refined) agrees to the printed digits from 360
    points; the peak angular accelerations (parabola-refined: no derivative of alpha is computed)
    only to 1e-3 rad/s^2 at 360 points and 0.1 at 72 (docs/linkage.md, 'Scan resolution')."""
    c360, c72 = _summaries(360), _summaries(72)
    assert np.abs(c360["mu_max_deg"] - fine["mu_max_deg"]).max() <= PRINTED
    alphas = [c for c in fine.columns if c.startswith("alpha_peak_") and "crank" not in c]
    assert len(alphas) == 4
    for c in alphas:
        assert np.abs(c360[c] - fine[c]).max() <= 1e-3, c
        assert np.abs(c72[c] - fine[c]).max() <= 0.1, c


@pytest.mark.parametrize("length, link5", [(0.06, 0.24), (0.12, 0.19)])
def test_fine_scan_against_dense_samples(length, link5):
    """The 7200-point summary against the kernel's kinematics at 72 000 inputs, no refinement:
    the output link's extremes and every link's peak omega within the sampling error."""
    p = params_of(WATT.format(length=length, link5=link5, scan=7200))
    s = summarise_batch(p).iloc[0]
    mech = compile_deck(p)
    a = kernel.analyse(mech, np.linspace(0.0, 2 * np.pi, 72_000, endpoint=False), forces=False)
    names = list(mech.links)
    out = np.degrees(np.unwrap(a.links[:, kernel.LinkCol.ANGLE, names.index("link6")]))
    assert s["output_min"] == pytest.approx(out.min(), abs=1e-6)
    assert s["output_max"] == pytest.approx(out.max(), abs=1e-6)
    assert s["stroke"] == pytest.approx(out.max() - out.min(), abs=2e-6)
    for i, name in enumerate(names[1:], start=1):
        w = a.links[:, kernel.LinkCol.OMEGA, i]
        sampled = w[np.argmax(np.abs(w))]
        assert s[f"omega_peak_{name}_rad_s"] == pytest.approx(sampled, abs=1e-7), name
        assert abs(s[f"omega_peak_{name}_rad_s"]) >= abs(sampled) - 1e-12, name   # refined: never below a sample
