"""Issue 35, item 4 (slider-crank part): the elastic rod beyond its material.

Truth written here: Young's modulus of each rod (the paper's Table 1a) and the yield strength of
the grade the tool assumes for it (docs/bibliography.md: 6061-T6 276 MPa, AISI 1045 hot rolled
310 MPa, AISI 1020 hot rolled 210 MPa); the stress a strain means is sigma = E eps, computed here
by hand from the tidy table's peak outer-fibre strain.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

import driver

E = {"aluminium": 7.17e10, "medium_carbon_steel": 20.68e10, "low_carbon_steel": 18.96e10}   # Table 1a [Pa]
YIELD = {"aluminium": 276e6, "medium_carbon_steel": 310e6, "low_carbon_steel": 210e6}       # assumed grades [Pa]
QUICK = dict(n_elements=16, revolutions=4, steps_per_rev=720)


def table_y(out: str) -> dict[tuple[str, float], tuple[float, str]]:
    """Table Y of the .out: (model, speed) -> (stress [MPa], verdict)."""
    lines = out.splitlines()
    k = next(i for i, l in enumerate(lines) if l.startswith("Table Y"))
    rows = {}
    for line in lines[k + 6:]:
        f = line.split()
        if len(f) < 4 or f[0] not in ("linear", "nonlinear"):
            break
        rows[(f[0], float(f[1]))] = (float(f[2]), f[4] if len(f) > 4 else "")
    return rows


@pytest.mark.parametrize("material", ["aluminium", "medium_carbon_steel", "low_carbon_steel"])
def test_linear_peak_stress_is_E_times_the_outer_fibre_strain(material):
    r = driver.slidercrank.run(material=material, speeds=[14.66, 29.32], **QUICK)
    t = r.tidy
    rows = table_y(r.out)
    for i, w in enumerate((14.66, 29.32), start=1):
        eps = t.loc[t["omega_rad_s"] == w, "outer_fibre_max_microstrain"].max() * 1e-6
        stress = E[material] * eps
        assert r.summary[f"peak_stress_{i}_MPa"] == pytest.approx(stress / 1e6, rel=1e-12)
        assert rows[("linear", w)][0] == pytest.approx(stress / 1e6, abs=0.006)
    peak = max(r.summary["peak_stress_1_MPa"], r.summary["peak_stress_2_MPa"])
    assert r.summary["yield_strength_MPa"] == YIELD[material] / 1e6
    assert r.summary["yield_ratio"] == pytest.approx(peak * 1e6 / YIELD[material], rel=1e-12)
    assert r.summary["yields"] is False
    assert f"yield strength {YIELD[material] / 1e6:g} MPa" in r.out


def test_a_yield_strength_below_the_stress_says_so_everywhere(tmp_path):
    base = dict(material="aluminium", speeds=[21.99], **QUICK)
    calm = driver.slidercrank.run(**base)
    stress = calm.summary["peak_stress_MPa"] * 1e6
    above = driver.slidercrank.run(**base, yield_strength=stress * 1.001)
    below = driver.slidercrank.run(**base, yield_strength=stress * 0.999)
    assert above.summary["yields"] is False and not any("passes yield" in w for w in above.warnings)
    assert below.summary["yields"] is True
    assert below.summary["yield_ratio"] == pytest.approx(1 / 0.999, rel=1e-12)
    assert any("passes yield" in w and "not physical" in w for w in below.warnings)
    assert table_y(below.out)[("linear", 21.99)][1] == "YIELDS" and "(deck)" in below.out
    paths = driver.write(below, tmp_path, json=True, report=True)
    rec = json.loads(next(p for p in paths if p.suffix == ".json").read_text())
    assert rec["summary"]["yields"] is True and any("passes yield" in m["text"] for m in rec["messages"])
    assert "passes yield" in next(p for p in paths if p.suffix == ".html").read_text()


def test_the_buckled_aluminium_rod_yields_in_the_nonlinear_model():
    r = driver.slidercrank.run(material="aluminium", speeds=[21.99, 29.32], model="nonlinear",
                               n_elements=16, revolutions=6)
    rows = table_y(r.out)
    nl = r.summary["nl_peak_stress_MPa"] * 1e6
    assert nl == pytest.approx(E["aluminium"] * r.tidy["outer_fibre_max_nonlinear_microstrain"].max() * 1e-6,
                               rel=1e-12)
    assert nl > YIELD["aluminium"] and r.summary["nl_yields"] is True
    assert rows[("nonlinear", 29.32)][1] == "YIELDS" and rows[("linear", 29.32)][1] == ""
    assert r.summary["yields"] is False          # the linear model stays far below: it cannot buckle
    assert any(w.startswith("nonlinear model, crank speed 29.32 rad/s: the rod passes yield") for w in r.warnings)


def test_a_custom_rod_without_a_yield_strength_is_not_judged():
    r = driver.slidercrank.run(area=27e-6, second_moment=2.025e-11, density=2660.0, youngs_modulus=7.17e10,
                               section_depth=3e-3, speeds=[14.66], **QUICK)
    assert r.summary["yield_strength_MPa"] is None and r.summary["yields"] is None
    assert "yield strength not known" in r.out and r.summary["peak_stress_MPa"] > 0


def test_a_yield_strength_in_mpa_is_refused_naming_the_key():
    with pytest.raises(driver.DeckError) as e:
        driver.slidercrank.run(material="aluminium", speeds=[14.66], yield_strength=276.0)
    assert e.value.key == "yield_strength" and "looks like MPa" in str(e.value)


def test_the_committed_nonlinear_aluminium_output_says_it_yields():
    from conftest import ROOT
    out = (ROOT / "outputs" / "slidercrank_nonlinear_aluminium.out").read_text()
    rows = table_y(out)
    assert rows[("nonlinear", 29.32)][1] == "YIELDS" and rows[("nonlinear", 25.13)][1] == "YIELDS"
    assert all(v[1] == "" for (m, _), v in rows.items() if m == "linear")
    assert np.isclose(rows[("nonlinear", 29.32)][0], 580, rtol=0.05)


@pytest.mark.parametrize("model", ["linear", "nonlinear"])
def test_the_strain_figure_marks_the_yield_strain(model):
    """sigma_y / E by hand drawn at both signs: the aluminium's 276 MPa / 71.7 GPa = 3849
    microstrain beside the buckled nonlinear rod; a deck's yield strength of 10 MPa (139
    microstrain) beside the linear model's crank-end strain of some 70."""
    pytest.importorskip("matplotlib")
    import matplotlib
    matplotlib.use("Agg")
    ys = YIELD["aluminium"] if model == "nonlinear" else 10e6
    r = driver.slidercrank.run(material="aluminium", speeds=[29.32], model=model, n_elements=16, revolutions=4,
                               **({} if model == "nonlinear" else {"yield_strength": ys}))
    name = "strain" if model == "linear" else "strain_linear_nonlinear"
    ax = r.figure(name).axes[0]
    eps = ys / E["aluminium"] * 1e6
    levels = sorted(float(line.get_ydata()[0]) for line in ax.get_lines()
                    if len(set(line.get_ydata())) == 1 and line.get_linestyle() == ":")
    assert levels == pytest.approx([-eps, eps], rel=1e-12)
    assert any("yield strain" in t and f"{ys / 1e6:g} MPa" in t for t in ax.get_legend_handles_labels()[1])
