"""The linkage study against closed forms and identities: the offset slider-crank's
x = r cos(theta) + sqrt(l^2 - (r sin(theta) - e)^2) and its derivatives; the quick-return time
ratios (180 + 2 asin(d/r)) / (180 - 2 asin(d/r)) of the Whitworth deck (exactly 2) and
(180 + beta) / (180 - beta), beta = 2 asin(r/d), of a crank-shaper's lever; a static case
against virtual work; a turning-moment diagram's energy fluctuation by hand; and the summary's
stroke against the closed form (docs/linkage.md cites the texts)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import INPUTS
from driver._deck import read_deck, validate
from driver.linkage import SPEC, compile_deck, summarise
from driver.linkage._analysis import solve
from driver.linkage._analysis_frames import _origins
from driver.linkage._kernel import DriverCol, EnergyCol, LinkCol, PointCol, SlideCol, table_energy
from linkage_oracle import params_of


def _deck(stem: str):
    path = INPUTS / f"{stem}.dat"
    return validate(read_deck(path).groups["linkage"], SPEC, path)


@pytest.mark.parametrize("e,mode", [(0.0, 1), (0.012, 1), (-0.02, 1), (0.015, -1)])
def test_offset_slider_crank_closed_form(e, mode):
    r, l, w, al = 0.05, 0.2, 30.0, 7.0
    p = params_of(f"pivots='O2', pivot_xy=0,0, guides='bore', guide_xy=0,0, guide_deg=0\n"
                  f"driver_joints='O2','A', driver_length={r}, omega={w}, alpha={al}, start=0, stop=359, step=1\n"
                  f"dyads='RRP', dyad_joints='A','bore','B', dyad_links='rod','piston', dyad_dims={l},{e}, "
                  f"dyad_modes={mode}")
    m = solve(p)
    th = np.radians(m.x)
    u = r * np.sin(th) - e
    D = np.sqrt(l * l - u * u)
    x = r * np.cos(th) + mode * D
    up, upp = r * np.cos(th), -r * np.sin(th)
    x1 = -r * np.sin(th) - mode * u * up / D
    x2 = -r * np.cos(th) - mode * ((up * up + u * upp) / D + u * u * up * up / D**3)
    s = m.a.slides[:, :, 0]
    assert np.max(np.abs(s[:, SlideCol.S] - x)) <= 1e-15 * 4 * (r + l)
    assert np.max(np.abs(s[:, SlideCol.V] - w * x1)) <= 1e-12 * w * (r + l)
    assert np.max(np.abs(s[:, SlideCol.A] - (w * w * x2 + al * x1))) <= 1e-11 * (w * w + al) * (r + l)
    # the rod's angle: sin(phi) = (e - r sin theta) / l on the +x side
    phi = m.a.links[:, LinkCol.ANGLE, 2]
    assert np.max(np.abs(np.sin(phi) - (e - r * np.sin(th)) / l)) <= 1e-14
    # the summary's stroke: the distance between the dead centres, sqrt((l + r)^2 - e^2) - sqrt((l - r)^2 - e^2)
    if mode == 1:
        stroke = math.sqrt((l + r) ** 2 - e * e) - math.sqrt((l - r) ** 2 - e * e)
        assert summarise(p)["stroke"] == pytest.approx(stroke, rel=1e-10, abs=0)


def test_whitworth_time_ratio_is_two():
    """O2 is d = 100 mm above O4, crank r = 200 mm: (180 + 2 asin(1/2)) / (180 - 2 asin(1/2)) = 2;
    the ram's stroke is twice the lever arm O4-R (0.15 m) with its ways through O4."""
    s = summarise(_deck("linkage_whitworth"))
    assert s["time_ratio"] == pytest.approx(2.0, rel=1e-10)
    assert s["stroke"] == pytest.approx(0.30, rel=1e-10)


def test_crank_shaper_lever_time_ratio_and_swing():
    """The crank-shaper's slotted lever oscillates through beta = 2 asin(r/d) with the time ratio
    (180 + beta) / (180 - beta) (r = 100 mm, d = 300 mm)."""
    p = _deck("linkage_crank_shaper")
    values = dict(p)
    values["output"] = "lever"
    from driver._deck import Params
    q = Params(p.group, p.path, values, {k: p.line_of(k) for k in p}, p.line, p.given | {"output"})
    s = summarise(q)
    beta = 2 * math.degrees(math.asin(0.1 / 0.3))
    assert s["stroke"] == pytest.approx(beta, rel=1e-10)
    assert s["time_ratio"] == pytest.approx((180 + beta) / (180 - beta), rel=1e-10)


def test_engine_dead_centres_and_stroke():
    """The engine deck's piston: top and bottom dead centres at theta = asin(e / (l + r)) and
    180 + asin(e / (l - r)), stroke sqrt((l + r)^2 - e^2) - sqrt((l - r)^2 - e^2)."""
    s = summarise(_deck("linkage_engine"))
    r, l, e = 0.05, 0.20, 0.005
    assert s["output_max_at"] == pytest.approx(math.degrees(math.asin(e / (l + r))), abs=1e-7)
    assert s["output_min_at"] == pytest.approx(180 + math.degrees(math.asin(e / (l - r))), abs=1e-7)
    assert s["stroke"] == pytest.approx(math.sqrt((l + r) ** 2 - e * e) - math.sqrt((l - r) ** 2 - e * e),
                                        rel=1e-10)
    assert s["time_ratio"] == pytest.approx((180 + math.degrees(math.asin(e / (l - r)) - math.asin(e / (l + r))))
                                            / (180 - math.degrees(math.asin(e / (l - r)) - math.asin(e / (l + r)))),
                                            rel=1e-9)


@pytest.mark.parametrize("stem", ["linkage_stephenson3", "linkage_inverted_slider_crank", "linkage_watt2"])
def test_static_driving_torque_is_virtual_work(stem):
    """At rest (omega = alpha = 0) the driving torque balances gravity, the loads and the
    torques: T + sum(F . dr/dtheta) + sum(m g . dr_G/dtheta) + sum(tau dphi/dtheta) = 0, the
    derivatives by five-point central differences of the kernel's own positions."""
    p = _deck(stem)
    values = dict(p)
    values["omega"], values["alpha"] = 0.0, 0.0
    from driver._deck import Params
    q = Params(p.group, p.path, values, {k: p.line_of(k) for k in p}, p.line, p.given)
    mech = compile_deck(q)
    h = 1e-3
    origins = _origins(mech)
    g = np.array(mech.gravity)
    for theta in (17.0, 133.0, 251.0):
        x = theta + math.degrees(h) * np.array([-2.0, -1.0, 0.0, 1.0, 2.0])
        m = solve(q, x, mech)
        assert m.ok.all()
        d = lambda v: (-v[4] + 8 * v[3] - 8 * v[1] + v[0]) / (12 * h)
        work, scale = 0.0, 0.0
        for l in range(2, len(mech.links) + 1):
            mass, gu, gv = mech.body[l - 1][:3]
            j = mech.point_index(origins[l]) - 1
            th = m.a.links[:, LinkCol.ANGLE, l - 1]
            gx = m.a.points[:, PointCol.X, j] + gu * np.cos(th) - gv * np.sin(th)
            gy = m.a.points[:, PointCol.Y, j] + gu * np.sin(th) + gv * np.cos(th)
            term = mass * (g[0] * d(gx) + g[1] * d(gy)) + mech.torque[l - 1] * d(np.unwrap(th))
            work += term
            scale += abs(term)
        for i, (fx, fy) in zip(mech.load_points, mech.load_xy):
            term = fx * d(m.a.points[:, PointCol.X, i - 1]) + fy * d(m.a.points[:, PointCol.Y, i - 1])
            work += term
            scale += abs(term)
        T = m.a.driver[2, DriverCol.DRIVE]
        assert abs(T + work) <= 1e-8 * scale, (stem, theta, T, -work)


def test_turning_moment_table_energy_by_hand():
    """A torque pulse: 0 up to 90 deg, linear to 1000 N m at 135 deg, back to 0 at 180 deg, 0 to
    360 deg.  Mean 125 N m; the energy fluctuation is the pulse's area above the mean,
    0.5 x 875 x (pi/2 x 0.875) J; I = dE / (C_s omega^2)."""
    th = np.radians([0.0, 90.0, 135.0, 180.0, 360.0])
    tq = np.array([0.0, 0.0, 1000.0, 0.0, 0.0])
    r = table_energy(th, tq, 0.02, 50.0)
    de = 0.5 * 875.0 * (math.pi / 2 * 0.875)
    assert r[EnergyCol.MEAN_TORQUE] == pytest.approx(125.0, rel=1e-14)
    assert r[EnergyCol.ENERGY_FLUCTUATION] == pytest.approx(de, rel=1e-13)
    assert r[EnergyCol.FLYWHEEL_INERTIA] == pytest.approx(de / (0.02 * 2500.0), rel=1e-13)
    assert math.degrees(r[EnergyCol.AT_MIN]) == pytest.approx(90 + 45 * 0.125, rel=1e-12)
    assert math.degrees(r[EnergyCol.AT_MAX]) == pytest.approx(180 - 45 * 0.125, rel=1e-12)


def test_deck_turning_moment_reaches_the_summary():
    p = params_of("pivots='O2','O4', pivot_xy=0,0, 12,0\ndriver_joints='O2','A', driver_length=5, omega=50, step=30\n"
                  "dyads='RRR', dyad_joints='A','O4','B', dyad_links='coupler','rocker', dyad_dims=15,9\n"
                  "turning_moment_deg=0,90,135,180,360, turning_moment=0,0,1000,0,0, speed_fluctuation=0.02")
    s = summarise(p)
    de = 0.5 * 875.0 * (math.pi / 2 * 0.875)
    assert s["table_energy_fluctuation_J"] == pytest.approx(de, rel=1e-13)
    assert s["table_flywheel_inertia_kgm2"] == pytest.approx(de / (0.02 * 2500.0), rel=1e-13)


def test_engine_flywheel_is_the_energy_of_its_own_torque():
    """The engine deck's flywheel (the summary's, from the kernel's scan) against the energy of
    the same driving torque sampled finely and integrated by the table routine."""
    p = _deck("linkage_engine")
    s = summarise(p)
    x = np.linspace(0.0, 720.0, 14401)
    m = solve(p, x)
    r = table_energy(np.radians(x), m.a.driver[:, DriverCol.DRIVE], p.speed_fluctuation, p.omega)
    assert s["energy_fluctuation_J"] == pytest.approx(r[EnergyCol.ENERGY_FLUCTUATION], rel=2e-4)
    assert s["torque_mean"] == pytest.approx(r[EnergyCol.MEAN_TORQUE], rel=1e-4)


@pytest.mark.parametrize("step", [0.5, 5.0])
def test_parallelogram_stays_a_parallelogram_through_its_change_points(step):
    """A parallelogram four-bar (crank = rocker = r, coupler = ground = g) passes two change points
    a turn (theta = 0 and 180 deg: all pins on the ground line, where its parallelogram and
    anti-parallelogram assemblies meet).  Followed through them (branch continuity, the kernel's
    default), it stays the parallelogram: the rocker turns with the crank (its angle is the crank's)
    and the coupler stays parallel to the ground, at every input of two turns; the group's mode
    changes sign at each change point.  With the mode held fixed (continuity off) it turns into
    the anti-parallelogram after the first one, which the same check sees."""
    r, g = 3.0, 7.0
    text = (f"pivots='O2','O4', pivot_xy=0,0, {g},0\n"
            f"driver_joints='O2','A', driver_length={r}, omega=2.0, alpha=0.5, start={step / 2}, "
            f"stop={720 - step / 2}, step={step}\n"
            f"dyads='RRR', dyad_joints='A','O4','B', dyad_links='coupler','rocker', dyad_dims={g},{r}, dyad_modes=1")
    p = params_of(text)
    mech = compile_deck(p)
    m = solve(p, mech=mech)
    th = np.radians(m.x)
    wrap = lambda a: np.angle(np.exp(1j * a))   # angle differences into (-pi, pi]
    assert np.all(m.a.status[:, 0] == 0)
    assert np.max(np.abs(wrap(m.a.links[:, LinkCol.ANGLE, 3] - th))) <= 1e-9
    assert np.max(np.abs(wrap(m.a.links[:, LinkCol.ANGLE, 2]))) <= 1e-9
    # the rates: near a change point the group's velocity equations are near singular (its links
    # nearly in line; 0.25 deg away, the determinant is 4e-3 of its largest), which costs digits
    assert np.max(np.abs(m.a.links[:, LinkCol.OMEGA, 3] - 2.0)) <= 1e-8 * 2.0
    assert np.max(np.abs(m.a.links[:, LinkCol.ALPHA, 3] - 0.5)) <= 1e-6 * 4.5
    from driver.linkage import _kernel as kernel
    held = kernel.analyse(mech, th, continuity=False)
    assert np.max(np.abs(wrap(held.links[:, LinkCol.ANGLE, 3] - th))) > 0.1
