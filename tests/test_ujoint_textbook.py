"""Issue 35, item 3: the Hooke joint as textbooks ask about it.

Truth, written here apart from the kernel:

* a single joint of angle b, the input angle measured from the normal to the plane of the
  shafts (the paper's origin), turns its output at R = cos b / (1 - sin^2 b sin^2 t); measured
  from the plane (textbooks', 90 deg on) at R = cos b / (1 - sin^2 b cos^2 t);
* R = 1 where sin^2 t = 1 / (1 + cos b) (from the normal), cos^2 t = 1 / (1 + cos b) (the plane);
* R' = cos b sin^2 b sin 2t / d^2 (d = 1 - sin^2 b sin^2 t) peaks where x = cos 2t solves
  x^2 - (2 / sin^2 b - 1) x - 2 = 0 (the root in [-1, 1]);
* an output shaft of inertia J against a load torque T_L needs, by power balance through massless
  joints at constant input speed w, T_in = (J w^2 R' + T_L) R; over a turn its mean is T_L;
* chains: the independent 3-D vector model of tests/test_ujoint_kernel.py, differentiated by
  finite differences.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import driver
from driver.ujoint import kernel
from test_ujoint_kernel import _random_chain, vector_model_ratio

D = math.pi / 180.0
RAD_TOL_DEG = 1e-10 / D    # 1e-10 rad, in deg


def textbook_lines(out: str, label: str = "design") -> dict[str, list[float]]:
    """The TEXTBOOK FIGURES lines of a design in the .out, as numbers."""
    lines = out.splitlines()
    k = lines.index(f"   {label}:")
    got = {}
    for line in lines[k + 1:k + 4]:
        if "ratio one" in line:
            got["one"] = [float(v) for v in line.split("theta = ")[1].split(",")]
        elif "peak output acceleration" in line:
            got["acc"] = [float(line.split("= ")[1].split()[0])]
            got["acc_at"] = [float(v) for v in line.split("theta = ")[1].split(" (")[0].split(",")]
        elif "input torque" in line:
            got["torque"] = [float(line.split("= ")[1].split()[0])]
            got["torque_at"] = [float(v) for v in line.split("theta = ")[1].split(";")[0].split(",")]
            got["torque_mean"] = [float(line.split("turn ")[1].split()[0])]
    return got


def single_peak(b: float) -> tuple[float, float]:
    """(peak R' [1/rad], the angle from the normal [rad] in (0, 90 deg)) of one joint, closed form."""
    s2, c = math.sin(b) ** 2, math.cos(b)
    q = 2.0 / s2 - 1.0
    x = (q - math.sqrt(q * q + 8.0)) / 2.0
    t = 0.5 * math.acos(x)
    return c * s2 * math.sin(2 * t) / (1 - s2 * math.sin(t) ** 2) ** 2, t


@pytest.mark.parametrize("beta_deg", [5.0, 20.0, 37.0, 60.0])
@pytest.mark.parametrize("origin", ["normal", "plane"])
def test_single_joint_ratio_one_and_acceleration_peak_to_1e_10_rad(beta_deg, origin):
    b = beta_deg * D
    r = driver.ujoint.run(beta=[beta_deg], rpm=60.0, angle_origin=origin)
    w2 = (2 * math.pi) ** 2
    t1 = math.asin(1 / math.sqrt(1 + math.cos(b))) if origin == "normal" else math.acos(1 / math.sqrt(1 + math.cos(b)))
    want_one = sorted(np.degrees([t1, math.pi - t1, math.pi + t1, 2 * math.pi - t1]) % 360.0)
    got = textbook_lines(r.out)
    assert np.allclose(got["one"], want_one, atol=RAD_TOL_DEG)
    assert r.summary["ratio_one_at_deg"] == pytest.approx(want_one[0], abs=RAD_TOL_DEG)
    peak, tn = single_peak(b)
    at = math.degrees(tn) - (90.0 if origin == "plane" else 0.0)
    want_at = sorted(np.array([at, 180 - at, 180 + at, 360 - at]) % 360.0)
    assert r.summary["peak_accel_rad_s2"] == pytest.approx(w2 * peak, rel=1e-12)
    assert got["acc"][0] == pytest.approx(w2 * peak, rel=1e-9)
    assert np.allclose(got["acc_at"], want_at, atol=RAD_TOL_DEG)
    assert r.summary["peak_accel_at_deg"] == pytest.approx(want_at[0], abs=RAD_TOL_DEG)
    # the grid's largest (what the summary said before) lies below the peak
    th = np.radians(np.arange(360.0))
    s2 = math.sin(b) ** 2
    grid = np.abs(math.cos(b) * s2 * np.sin(2 * th) / (1 - s2 * np.sin(th) ** 2) ** 2).max()
    assert grid <= peak


@pytest.mark.parametrize("beta_deg", [15.0, 30.0])
def test_the_origin_is_where_textbooks_put_it(beta_deg):
    b = beta_deg * D
    rpm = 100.0
    normal = driver.ujoint.run(beta=[beta_deg], rpm=rpm, angle_origin="normal", tidy_grid="table_step")
    plane = driver.ujoint.run(beta=[beta_deg], rpm=rpm, angle_origin="plane", tidy_grid="table_step")
    for res, origin in ((normal, "normal"), (plane, "plane")):
        t = res.tidy
        th = np.radians(t["theta_in_deg"].to_numpy())
        trig = np.sin(th) if origin == "normal" else np.cos(th)
        want = math.cos(b) / (1 - math.sin(b) ** 2 * trig ** 2)
        assert np.allclose(t["ratio"], want, rtol=1e-13)
        assert (t["angle_origin"] == origin).all()
        # the output yoke: tan(out) = cos b tan(in) from the normal, tan(out) = tan(in) / cos b from the plane
        ok = np.abs(np.cos(th)) > 1e-3
        law = math.cos(b) * np.tan(th[ok]) if origin == "normal" else np.tan(th[ok]) / math.cos(b)
        assert np.allclose(np.tan(np.radians(t["theta_out_deg"].to_numpy()[ok])), law, rtol=1e-10)
    # theta = 0: the slowest output from the normal, the fastest from the plane
    assert normal.tidy["omega_out_rpm"].iloc[0] == pytest.approx(rpm * math.cos(b), rel=1e-14)
    assert plane.tidy["omega_out_rpm"].iloc[0] == pytest.approx(rpm / math.cos(b), rel=1e-14)
    # the band does not depend on where the angle is counted from
    for k in ("omega_out_min_rpm", "omega_out_max_rpm", "peak_accel_rad_s2"):
        assert plane.summary[k] == pytest.approx(normal.summary[k], rel=1e-12)
    # every table and figure says the origin
    assert "angle origin : plane" in plane.out and "theta from joint 1's plane" in plane.out
    assert "theta from the normal to joint 1's plane" in normal.out
    pytest.importorskip("matplotlib")
    for res, words in ((normal, "from the normal"), (plane, "from joint 1's plane")):
        for name in ("speed", "polar"):
            assert words in res.figure(name).axes[0].get_xlabel()


def test_input_torque_figure_by_power_balance():
    """With a load the run draws the input torque over a turn: its curve is the power balance
    written here (T_in = (J w^2 R' + T_L) R, from the plane: R = c / (1 - s2 cos^2 t)), the load
    torque is the drawn mean, and the marked peaks reach the curve's largest magnitude; without a
    load there is no such figure."""
    pytest.importorskip("matplotlib")
    beta_deg, inertia, load, rpm = 30.0, 0.5, 20.0, 600.0
    b, w = beta_deg * D, rpm * 2 * math.pi / 60
    r = driver.ujoint.run(beta=[beta_deg], rpm=rpm, load_inertia=inertia, load_torque=load, angle_origin="plane")
    (ax,) = r.figure("torque").axes
    c, s2 = math.cos(b), math.sin(b) ** 2
    curve = [ln for ln in ax.get_lines() if ln.get_label().startswith("design:")][0]
    t = np.radians(curve.get_xdata())
    d = 1 - s2 * np.cos(t) ** 2
    oracle = (inertia * w * w * (-c * s2 * np.sin(2 * t) / d ** 2) + load) * c / d
    assert np.allclose(curve.get_ydata(), oracle, rtol=1e-12, atol=1e-12 * (inertia * w * w + load))
    assert curve.get_xdata()[0] == 0.0 and curve.get_xdata()[-1] == 360.0
    mean = [ln for ln in ax.get_lines() if ln.get_label().startswith("load torque")][0]
    assert set(mean.get_ydata()) == {load} and np.mean(oracle[:-1]) == pytest.approx(load, rel=1e-9)
    marks = [ln for ln in ax.get_lines() if "peak |T_in|" in ln.get_label()][0]
    assert np.allclose(np.abs(marks.get_ydata()), np.abs(oracle).max(), rtol=1e-5)   # a 0.5 deg grid's max
    assert np.all(np.abs(marks.get_ydata()) >= np.abs(oracle).max() * (1 - 1e-12))    # the roots reach above it
    assert "from joint 1's plane" in ax.get_xlabel()
    assert "torque" not in {f.name for f in driver.ujoint.run(beta=[beta_deg], rpm=rpm).figures}


def test_tidy_grid_chooses_the_tidy_tables_angles():
    r = driver.ujoint.run(beta=[20.0, 10.0], phi=[60.0], n_grid=72, table_step=15.0)
    assert len(r.tidy) == 72 and "at the 72 grid angles (tidy_grid = 'n_grid')" in r.out
    r = driver.ujoint.run(beta=[20.0, 10.0], phi=[60.0], n_grid=72, table_step=15.0, tidy_grid="table_step")
    assert list(r.tidy["theta_in_deg"]) == list(np.arange(0.0, 360.0 + 1e-9, 15.0))
    assert "at the speed table's angles (tidy_grid = 'table_step')" in r.out


@pytest.mark.parametrize("beta_deg, inertia, load", [(30.0, 0.5, 20.0), (12.0, 2.0, 0.0), (45.0, 0.0, 7.5)])
def test_input_torque_by_power_balance(beta_deg, inertia, load):
    b = beta_deg * D
    rpm = 600.0
    w = rpm * 2 * math.pi / 60
    r = driver.ujoint.run(beta=[beta_deg], rpm=rpm, load_inertia=inertia, load_torque=load, angle_origin="plane")
    c, s2 = math.cos(b), math.sin(b) ** 2

    def torque(t: np.ndarray) -> np.ndarray:     # from the plane: R = c / (1 - s2 cos^2 t)
        d = 1 - s2 * np.cos(t) ** 2
        ratio = c / d
        dratio = -c * s2 * np.sin(2 * t) / d ** 2
        return (inertia * w * w * dratio + load) * ratio

    t = r.tidy
    assert np.allclose(t["input_torque_Nm"], torque(np.radians(t["theta_in_deg"].to_numpy())),
                       rtol=1e-12, atol=1e-12 * (inertia * w * w + load))
    # the peak: the oracle's own search, a dense grid refined by a bounded scalar minimisation
    th = np.linspace(0, 2 * math.pi, 20001)
    k = int(np.argmax(np.abs(torque(th))))
    best = minimize_scalar(lambda x: -abs(torque(np.array([x]))[0]), bounds=(th[k] - 1e-3, th[k] + 1e-3),
                           method="bounded", options={"xatol": 1e-12})
    peak = abs(torque(np.array([best.x]))[0])
    assert r.summary["input_torque_peak_Nm"] == pytest.approx(peak, rel=1e-10)
    at = r.summary["input_torque_peak_at_deg"]
    assert abs(torque(np.radians([at]))[0]) == pytest.approx(peak, rel=1e-10)
    # over a turn the kinetic energy of the output returns: the mean input torque is the load's
    assert r.summary["input_torque_mean_Nm"] == pytest.approx(load, abs=1e-9 * (1 + inertia * w * w))
    got = textbook_lines(r.out)
    assert got["torque"][0] == pytest.approx(peak, rel=1e-9)


def test_a_chains_jet_and_peak_against_the_vector_model():
    rng = np.random.default_rng(35)
    axes = _random_chain(rng, 3)
    delta = rng.uniform(-math.pi, math.pi, 2)
    beta, rho, _ = kernel.ujoint_geometry(axes)
    exact = kernel.UJOINT_MODELS["exact"]
    th = np.linspace(0.0, 2 * math.pi, 97)
    h = 1e-3
    f = [vector_model_ratio(axes, delta, th + k * h) for k in (-2, -1, 0, 1, 2)]
    d1 = (f[0] - 8 * f[1] + 8 * f[3] - f[4]) / (12 * h)
    d2 = (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h * h)
    r0, r1, r2 = kernel.ujoint_jet(exact, beta, delta + math.pi / 2, rho, th)
    assert np.max(np.abs(r0 - f[2])) < 1e-13
    assert np.max(np.abs(r1 - d1)) < 1e-9 and np.max(np.abs(r2 - d2)) < 1e-6
    # the run's peak output acceleration: the largest |R'| of the vector model anywhere, and R'' = 0 there
    r = driver.ujoint.run(axes=axes.ravel().tolist(), delta=list(np.degrees(delta)), rpm=60.0)
    w2 = (2 * math.pi) ** 2
    fine = np.linspace(0.0, 2 * math.pi, 20001)
    g = [vector_model_ratio(axes, delta, fine + k * h) for k in (-1, 1)]
    assert r.summary["peak_accel_rad_s2"] >= w2 * np.abs((g[1] - g[0]) / (2 * h)).max() * (1 - 1e-6)
    at = math.radians(r.summary["peak_accel_at_deg"])
    f = [vector_model_ratio(axes, delta, np.array([at + k * h])) for k in (-2, -1, 0, 1, 2)]
    curvature = (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h * h)
    assert abs(curvature[0]) < 1e-6 * max(1.0, r.summary["peak_accel_rad_s2"] / w2)
    slope = (f[0] - 8 * f[1] + 8 * f[3] - f[4]) / (12 * h)
    assert w2 * abs(slope[0]) == pytest.approx(r.summary["peak_accel_rad_s2"], rel=1e-8)
    # R = 1 there: the vector model's ratio at the reported angle
    one = math.radians(r.summary["ratio_one_at_deg"])
    assert vector_model_ratio(axes, delta, np.array([one]))[0] == pytest.approx(1.0, abs=1e-12)


def test_a_sweep_row_carries_the_same_figures_as_the_run():
    s = driver.run_sweep({"ujoint": {"beta": [25.0], "angle_origin": "plane"}}, grid={"beta": [10.0, 25.0]}, jobs=1)
    one = driver.ujoint.run(beta=[25.0], angle_origin="plane").summary
    row = s.summary.iloc[1]
    for k in ("peak_accel_rad_s2", "peak_accel_at_deg", "ratio_one_at_deg"):
        assert row[k] == one[k]


def test_bad_loads_are_refused_naming_the_key():
    with pytest.raises(driver.DeckError, match="load_inertia"):
        driver.ujoint.run(beta=[20.0], load_inertia=-1.0)
    with pytest.raises(driver.DeckError, match="angle_origin"):
        driver.ujoint.run(beta=[20.0], angle_origin="fastest")
