"""Issue 35, item 4 (four-bar part): link stresses where a cross-section is given, and yield.

Truth written here apart from the kernel:

* a static linkage with massless links and a load torque T_L on the rocker: the coupler is a
  two-force member (pure axial force f along A->B, from the rocker's moments about O4), the
  crank carries f and the driver torque T = A x F_A, the rocker f and T_L, so the peak stresses
  are |N|/A + |M|/Z with M = T at O2, 0 along the coupler, T_L at O4;
* a moving linkage with inertia, gravity and a load force: the Newton-Euler oracle of
  tests/test_fourbar_forces.py (dense 9x9 solve) gives the pin forces; each link's section forces
  are summed here from its free body at 4001 cuts (plus both sides of every load point), the
  loads lumped as the force analysis models them.
"""
from __future__ import annotations

import numpy as np
import pytest

import driver
from test_fourbar_forces import com_states, cross, oracle_forces, oracle_kinematics

AREA = np.array([3e-5, 2e-5, 2.5e-5])
MODULUS = np.array([6e-8, 4e-8, 3e-8])


def run(**kw):
    base = dict(fixed_link=0.3, crank=0.1, coupler=0.35, rocker=0.25, step_deg=15,
                section_area=list(AREA), section_modulus=list(MODULUS))
    return driver.fourbar.run(**{k: v for k, v in {**base, **kw}.items() if v is not None})   # None: key left out


def test_static_two_force_coupler_and_end_moments():
    TL = 12.0
    r = run(mass=[0.0, 0.0, 0.0], omega=0.0, gravity=0.0, load_torque=TL)
    t = r.tidy
    kin = oracle_kinematics(np.radians(t["theta_deg"].to_numpy()), 0.3, 0.1, 0.35, 0.25, 0.0, 0.0, 1)
    A, B, O4 = kin["A"], kin["B"], np.array([0.3, 0.0])
    e2 = (B - A) / 0.35
    e1, e3 = A / 0.1, (B - O4) / 0.25
    f = -TL / cross(B - O4, e2)                     # (B - O4) x F_B = -T_L with F_B = f e2
    FB = f[:, None] * e2
    T = cross(A, FB)                                # crank: T = A x F_A, F_A = F_B
    crank = np.abs(np.sum(FB * e1, axis=1)) / AREA[0] + np.abs(T) / MODULUS[0]
    coupler = np.abs(f) / AREA[1]
    rocker = np.abs(np.sum(FB * e3, axis=1)) / AREA[2] + abs(TL) / MODULUS[2]
    ok = (t["status"] == "ok").to_numpy()
    for col, want in (("crank_stress_MPa", crank), ("coupler_stress_MPa", coupler), ("rocker_stress_MPa", rocker)):
        assert np.allclose(t[col].to_numpy()[ok], want[ok] / 1e6, rtol=1e-10), col
    assert np.allclose(t["input_torque_Nm"].to_numpy()[ok], T[ok], rtol=1e-10)


def oracle_link_stress(theta, p, q, r, s, w, al, pr, area, modulus, ncut=4001):
    """Peak |N|/A + |M|/Z of each link at each crank angle: the oracle's pin forces, each link's
    loads where they act, the section forces summed from the free body of the part before each cut."""
    kin = oracle_kinematics(theta, p, q, r, s, w, al, 1)
    coms, (P, _) = com_states(kin, p, pr)
    F = oracle_forces(theta, p, q, r, s, w, al, 1, pr)
    m, inertia = pr[0:3], pr[3:6]
    g = np.array([0.0, -pr[12]])
    TL, FL = pr[13], np.array([pr[14], pr[15]])
    O2, O4 = np.zeros(2), np.array([p, 0.0])
    out = np.zeros((len(theta), 3))
    for k in range(len(theta)):
        A, B = kin["A"][k], kin["B"][k]
        T, FO2, FA, FB, FO4 = F[k, 0], F[k, 1:3], F[k, 3:5], F[k, 5:7], F[k, 7:9]
        G = [c[0][k] for c in coms]
        inert = [-(m[i] * (coms[i][2][k] - g)) for i in range(3)]          # d'Alembert force plus weight
        couple = [-inertia[i] * kin["a"][i][k] for i in range(3)]
        links = [(O2, A, q, [(O2, FO2, T), (A, -FA, 0.0), (G[0], inert[0], couple[0])]),
                 (A, B, r, [(A, FA, 0.0), (B, -FB, 0.0), (G[1], inert[1], couple[1]), (P[k], FL, 0.0)]),
                 (O4, B, s, [(O4, FO4, TL), (B, FB, 0.0), (G[2], inert[2], couple[2])])]
        for i, (start, end, length, loads) in enumerate(links):
            e = (end - start) / length
            xi = np.array([np.dot(pt - start, e) for pt, _, _ in loads])
            cuts = np.unique(np.clip(np.concatenate([np.linspace(0, length, ncut), xi - 1e-12, xi + 1e-12]),
                                     0, length))
            best = 0.0
            for c in cuts:
                S = start + c * e
                Fx = sum((f for (pt, f, _), x in zip(loads, xi) if x < c), np.zeros(2))
                M = sum((cross(pt - S, f) + cpl for (pt, f, cpl), x in zip(loads, xi) if x < c), 0.0)
                best = max(best, abs(np.dot(Fx, e)) / area[i] + abs(M) / modulus[i])
            out[k, i] = best
    return out


def test_moving_linkage_against_the_free_bodies_cut_by_cut():
    pr_keys = dict(mass=[0.5, 1.2, 0.9], com_distance=[0.04, 0.2, 0.1], com_angle_deg=[10.0, -15.0, 5.0],
                   load_torque=5.0, load_force_x=10.0, load_force_y=-20.0, coupler_point=[0.2, 0.05],
                   omega=20.0, alpha=3.0)
    r = run(**pr_keys, step_deg=40)
    from driver.fourbar._analysis_forces import props
    pr = props(r.params)
    t = r.tidy
    theta = np.radians(t["theta_deg"].to_numpy())
    want = oracle_link_stress(theta, 0.3, 0.1, 0.35, 0.25, 20.0, 3.0, pr, AREA, MODULUS)
    got = t[["crank_stress_MPa", "coupler_stress_MPa", "rocker_stress_MPa"]].to_numpy() * 1e6
    assert np.allclose(got, want, rtol=1e-8)


def test_yield_is_said_in_the_out_summary_json_and_warnings(tmp_path):
    kw = dict(mass=[0.5, 1.2, 0.9], load_torque=5.0, omega=20.0)
    calm = run(**kw, yield_strength=[1e9])
    peak = max(calm.summary[f"{link}_stress_peak_MPa"] for link in ("crank", "coupler", "rocker"))
    assert calm.summary["yields"] is False and not any("yield" in w for w in calm.warnings)
    assert "every link stays below its yield strength" in calm.out
    ys = 0.9 * peak * 1e6
    hot = run(**kw, yield_strength=[ys])
    assert hot.summary["yields"] is True
    assert hot.summary["yield_ratio_max"] == pytest.approx(peak * 1e6 / ys, rel=1e-12)
    assert any("passes yield" in w for w in hot.warnings) and "PASSES YIELD" in hot.out
    # the scan's peak: never below any tabulated crank angle's stress
    for link in ("crank", "coupler", "rocker"):
        assert hot.summary[f"{link}_stress_peak_MPa"] >= np.nanmax(hot.tidy[f"{link}_stress_MPa"]) * (1 - 1e-12)
    paths = driver.write(hot, tmp_path, json=True, report=True)
    import json
    rec = json.loads((tmp_path / "fourbar.json").read_text())
    assert rec["summary"]["yields"] is True and any("passes yield" in m["text"] for m in rec["messages"])
    page = next(p for p in paths if p.suffix == ".html").read_text()
    assert "passes yield" in page


@pytest.mark.parametrize("kw, key", [
    (dict(section_modulus=None), "section_area"),
    (dict(yield_strength=[250.0]), "yield_strength"),            # MPa given for Pa
    (dict(section_area=[1e-5, 1e-5]), "section_area"),
])
def test_bad_section_input_names_the_key(kw, key):
    with pytest.raises(driver.DeckError) as e:
        run(mass=[0.5, 1.2, 0.9], **kw)
    assert e.value.key == key
