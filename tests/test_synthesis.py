"""&synthesis: every synthesised linkage checked by the exact kernel (an independent solution of the loop).

* function generation recovers a known linkage from three of its own positions (the kernel's
  rocker angles fed to Freudenstein's equation give back the link lengths), meets its
  precision points exactly on the requested branch, and detects the other branch;
* least squares over many points of a four-bar's own function has zero residual;
* crank-rocker: every scanned family member that is a crank-rocker has the asked swing and time
  ratio by the kernel, and the reported member is the best of the family.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from driver import fourbar
from driver._cli import main
from driver._deck import RawGroup, validate
from driver.fourbar import _kernel as fourbar_kernel
from driver.synthesis import _crank_rocker as cr
from driver.synthesis import synthesise
from driver.synthesis._function import chebyshev, freudenstein, links_from_k

D, A, B, C = 1.0, 0.45, 1.1, 0.9     # a crank-rocker (Grashof: 0.45 + 1.1 < 1.0 + 0.9)


def _rocker_deg(theta_deg, branch=1):
    out, st = fourbar_kernel.fourbar_exact(np.radians(theta_deg), D, A, B, C, 1.0, 0.0, branch)
    assert np.all(st == 0)
    return np.degrees(out[:, 1])


def test_chebyshev_spacing_closed_form():
    x = chebyshev(1.0, 2.0, 3)
    assert x == pytest.approx([1.5 - 0.5 * math.sqrt(3) / 2, 1.5, 1.5 + 0.5 * math.sqrt(3) / 2], abs=1e-15)


def test_freudenstein_recovers_a_known_linkage():
    theta = np.array([20.0, 70.0, 130.0])
    k, _ = freudenstein(np.radians(theta), np.radians(_rocker_deg(theta)))
    a, b, c, reason = links_from_k(k, D)
    assert not reason
    assert (a, b, c) == pytest.approx((A, B, C), abs=1e-12)


def test_least_squares_of_a_four_bar_function_is_exact():
    theta = np.linspace(0.0, 350.0, 36)
    k, _ = freudenstein(np.radians(theta), np.radians(_rocker_deg(theta)))
    assert links_from_k(k, D)[:3] == pytest.approx((A, B, C), abs=1e-10)


def _pairs_deck(tmp_path, branch="open"):
    theta = np.array([20.0, 70.0, 130.0])
    psi = _rocker_deg(theta)
    text = ("&synthesis\n  task = 'function'\n"
            f"  x_values = {', '.join(repr(float(t)) for t in theta)}\n"
            f"  y_values = {', '.join(repr(float(v)) for v in psi)}\n"
            f"  crank_start_deg = 20.0, crank_range_deg = 110.0\n"
            f"  rocker_start_deg = {float(psi[0])!r}, rocker_range_deg = {float(psi[-1] - psi[0])!r}\n"
            f"  fixed_link = 1.0, branch = '{branch}'\n/\n")
    path = tmp_path / "fg.dat"
    path.write_text(text)
    return path


def test_function_generation_from_pairs_meets_points_on_its_branch(tmp_path):
    syn = synthesise(_pairs_deck(tmp_path))
    assert syn.failure is None
    fd = syn.design
    assert (fd.crank, fd.coupler, fd.rocker) == pytest.approx((A, B, C), abs=1e-12)
    assert np.max(np.abs(fd.point_error_deg)) < 1e-9
    assert syn.study_result is not None and "cannot be assembled" not in syn.study_result.text


def test_wrong_branch_is_detected_and_exits_1(tmp_path, capsys):
    path = _pairs_deck(tmp_path, branch="crossed")
    assert main([str(path), "-o", str(tmp_path / "out"), "-q"]) == 1
    assert "set branch = 'open'" in capsys.readouterr().err


def test_chebyshev_log10_error_vanishes_at_precision_points(tmp_path):
    path = tmp_path / "log.dat"
    path.write_text("&synthesis task = 'function', function = 'log10(x)', x_start = 1.0, x_stop = 2.0,\n"
                    " crank_start_deg = 45.0, crank_range_deg = 60.0, rocker_start_deg = 135.0,\n"
                    " rocker_range_deg = 90.0 /\n")
    syn = synthesise(path)
    fd = syn.design
    assert syn.failure is None
    # kernel: the rocker at the three Chebyshev crank angles equals the desired angles
    xs = chebyshev(1.0, 2.0, 3)
    crank = fd.crank_start_deg + (xs - 1.0) / 1.0 * 60.0
    out, st = fourbar_kernel.fourbar_exact(np.radians(crank), 1.0, fd.crank, fd.coupler, fd.rocker, 1.0, 0.0, 1)
    want = fd.rocker_start_deg + np.log10(xs) / math.log10(2.0) * 90.0
    assert np.all(st == 0)
    assert ((np.degrees(out[:, 1]) - want + 180) % 360 - 180) == pytest.approx(0.0, abs=1e-9)
    # the structural error between the points is not zero, and changes sign at each precision point
    err = fd.y_generated - fd.y_desired
    assert 1e-5 < np.max(np.abs(err)) < 1e-2
    assert np.count_nonzero(np.diff(np.sign(err[np.abs(err) > 1e-12]))) == 3


def test_crank_rocker_family_members_have_the_asked_swing_and_time_ratio():
    members = [m for m in cr.family(60.0, 1.25, 41) if m.crank_rocker]
    assert len(members) > 20
    for m in members[::4]:
        raw = RawGroup("fourbar", {"fixed_link": 10.0, "crank": m.crank * 10 / m.ground,
                                   "coupler": m.coupler * 10 / m.ground, "rocker": m.rocker * 10 / m.ground,
                                   "step_deg": 10.0}, {}, 1)
        ex = fourbar.extremes(validate(raw, fourbar.SPEC, "x"))
        turn = (ex.rocker_max_at - ex.rocker_min_at) % 360
        assert (ex.rocker_max - ex.rocker_min) % 360 == pytest.approx(60.0, abs=1e-7)
        assert max(turn, 360 - turn) / min(turn, 360 - turn) == pytest.approx(1.25, abs=1e-7)
        assert ex.mu_min == pytest.approx(m.mu_min_deg, abs=1e-7)


def test_crank_rocker_deck_reports_the_best_member(tmp_path):
    path = tmp_path / "cr.dat"
    path.write_text("&synthesis task = 'crank_rocker', swing_deg = 60, time_ratio = 1.25, fixed_link = 10 /\n")
    syn = synthesise(path)
    assert syn.failure is None
    assert syn.checks["swing_deg"] == pytest.approx(60.0, abs=1e-7)
    assert syn.checks["time_ratio"] == pytest.approx(1.25, abs=1e-7)
    fine = [m for m in cr.family(60.0, 1.25, 4001) if m.crank_rocker]
    assert syn.design.quality_deg >= max(m.quality_deg for m in fine) - 1e-9


def test_q1_family_on_the_line(tmp_path):
    path = tmp_path / "cr1.dat"
    path.write_text("&synthesis task = 'crank_rocker', swing_deg = 45, time_ratio = 1.0, fixed_link = 1 /\n")
    syn = synthesise(path)
    assert syn.failure is None and syn.checks["time_ratio"] == pytest.approx(1.0, abs=1e-7)


@pytest.mark.parametrize("body, key", [
    ("task = 'function', x_start = 1, x_stop = 2, crank_range_deg = 60, rocker_range_deg = 60", "function"),
    ("task = 'function', function = 'x', x_start = 1, x_stop = 1, crank_range_deg = 60, rocker_range_deg = 60", "x_stop"),
    ("task = 'function', function = 'open(x)', x_start = 1, x_stop = 2, crank_range_deg = 60, rocker_range_deg = 60", "function"),
    ("task = 'crank_rocker', swing_deg = 200, time_ratio = 1.2", "swing_deg"),
    ("task = 'crank_rocker', swing_deg = 50", "time_ratio"),
])
def test_bad_synthesis_decks_exit_2(tmp_path, capsys, body, key):
    path = tmp_path / "bad.dat"
    path.write_text(f"&synthesis {body} /\n")
    assert main([str(path), "-o", str(tmp_path / "out")]) == 2
    assert f"key '{key}'" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_path_generation_through_five_points_verified_by_the_kernel(tmp_path):
    from pathlib import Path
    text = (Path(__file__).resolve().parents[1] / "inputs" / "synthesis_path.dat").read_text()
    deck = tmp_path / "path.dat"
    deck.write_text(text.replace("maxiter = 200, popsize = 10", "maxiter = 60, popsize = 8"))
    syn = synthesise(deck)
    from driver.plotting import save_figure
    from driver.synthesis import synthesis_figures
    (figure,) = synthesis_figures(syn, "path")
    assert figure.name == "path" and save_figure(figure.draw(), tmp_path / "path_path.png").stat().st_size > 0
    assert syn.failure is None
    q = syn.design.parts
    targets = np.column_stack([syn.params.target_x, syn.params.target_y])
    # independent re-measurement: the coupler point at the reported crank angles, moved to the world frame
    th = np.radians(syn.design.theta_at_targets_deg)
    out, st = fourbar_kernel.fourbar_exact(th, q["ground"], q["crank"], q["coupler"], q["rocker"], 1.0, 0.0, 1)
    cp = fourbar_kernel.fourbar_coupler_point(th, out, st, q["crank"], 1.0, 0.0, q["u"], q["v"])[:, :2]
    g = math.radians(q["gamma_deg"])
    world = np.column_stack([q["x0"] + math.cos(g) * cp[:, 0] - math.sin(g) * cp[:, 1],
                             q["y0"] + math.sin(g) * cp[:, 0] + math.cos(g) * cp[:, 1]])
    assert np.all(st == 0)
    assert np.hypot(*(world - targets).T) == pytest.approx(syn.design.errors, abs=1e-12)
    assert syn.design.errors.max() < 1e-6
    # full rotation on one branch, inside the transmission band, by the exact analysis of the linkage deck
    raw = RawGroup("fourbar", {k: v for k, v in syn.linkage.items()}, {}, 1)
    p = validate(raw, fourbar.SPEC, "x")
    assert fourbar.grashof(p.fixed_link, p.crank, p.coupler, p.rocker).full_crank_rotation
    ex = fourbar.extremes(p)
    assert ex.assembled_fraction == 1.0 and not ex.toggles
    assert 30.0 <= ex.mu_min and ex.mu_max <= 150.0
