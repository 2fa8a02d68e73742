"""Slider-crank study: the &slidercrank deck keys, Table 1a materials, the model a deck describes
(section, masses, closed-form frequencies) and the deck's checks.

Units: SI (m, kg, Pa, rad/s, s).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, TypedDict

from driver._deck import GroupSpec, Key, Params, non_negative, positive
from driver._limits import Estimate
from driver._study import contract_doc
from driver.slidercrank import _kernel as kernel

#: Table 1a of the paper (columns re-ordered, docs/slidercrank.md); the depth is the
#: in-plane section depth used for the outer-fibre strain (weak axis in plane).
#: ``yield_strength`` [Pa] and ``grade``: the paper names no grade, so the tool assumes a common one
#: for each and says so (docs/bibliography.md): aluminium alloy 6061-T6, typical tensile yield
#: 276 MPa [ASM Vol. 2]; medium-carbon steel AISI 1045 and low-carbon steel AISI 1020, hot rolled,
#: minimum yield 310 and 210 MPa (SAE J1397, as tabulated by [Shigley], Table A-20).
MATERIALS: dict[str, dict[str, Any]] = {
    "aluminium": dict(area=27e-6, second_moment=2.025e-11, density=2660.0, youngs_modulus=7.17e10,
                      section_depth=3.0e-3, section="rectangle 9 x 3 mm, weak axis in plane",
                      yield_strength=276e6, grade="aluminium alloy 6061-T6 assumed, typical yield [ASM Vol. 2]"),
    "medium_carbon_steel": dict(area=22.5e-6, second_moment=1.1718e-11, density=7800.0,
                                youngs_modulus=20.68e10, section_depth=2.5e-3,
                                section="rectangle 9 x 2.5 mm, weak axis in plane",
                                yield_strength=310e6,
                                grade="AISI 1045 hot rolled assumed, minimum yield [Shigley] Table A-20"),
    "low_carbon_steel": dict(area=7.8965e-5, second_moment=4.9620e-10, density=7800.0,
                             youngs_modulus=18.96e10, section_depth=10.03e-3,
                             section="round bar D = 10.03 mm", yield_strength=210e6,
                             grade="AISI 1020 hot rolled assumed, minimum yield [Shigley] Table A-20"),
}
#: a yield strength below this [Pa] is taken for a unit mistake (MPa given for Pa)
MIN_YIELD_PA = 1.0e5
SECTION_KEYS = ("area", "second_moment", "density", "youngs_modulus", "section_depth")
#: the paper's six crank speeds [rad/s]
PAPER_SPEEDS = (11.52, 14.66, 18.85, 21.99, 25.13, 29.32)
#: time-step criterion: steps per period of the first bending mode, and per revolution
MIN_STEPS_PER_BENDING_PERIOD = 20
MIN_STEPS_PER_REV = 36
EULER_WARN = 0.8
MAX_ELEMENTS = 5000
#: what each failed case status means, (heading, why): the kernel's status table
#: (``driver.slidercrank.kernel.SimulateStatus``, fortran/slidercrank.f90)
STATUS_TEXT = {s.name: (s.what, s.why) for s in kernel.SimulateStatus if s != kernel.SimulateStatus.ok}

#: Simeon (1996) / IVP test set "crank": published initial values (ini = 1, consistent) of the
#: modal coordinates q1, q2 (lateral sin(pi x), sin(2 pi x)), q3, q4 (axial, quadratic: midpoint
#: and end node) and their rates, and the reference solution at t = 0.1 s (MEBDFI, tol 1e-14).
class Simeon1996(TypedDict):
    """The Simeon (1996) benchmark: geometry [m], crank speed [rad/s], initial modal state
    q0 [m, m, m, rad]-like amplitudes and rates qd0, and the end state at t [s]: q1, q4 [m],
    slider x3 [m], rod angle phi2 [rad]."""

    crank_radius: float
    rod_length: float
    speed: float
    q0: tuple[float, float, float, float]
    qd0: tuple[float, float, float, float]
    t: float
    q1: float
    q4: float
    x3: float
    phi2: float


SIMEON1996: Simeon1996 = {
    "crank_radius": 0.15, "rod_length": 0.30, "speed": 150.0,
    "q0": (0.0, 0.0, 0.103339863e-04, 0.169327969e-04),
    "qd0": (0.444896105, 0.463434311e-02, -0.178591076e-05, -0.268938672e-05),
    "t": 0.1, "q1": 1.893192899613509e-4, "q4": -8.363313279112129e-6,
    "x3": 0.1697373, "phi2": -0.3311735,
}


def _valid_count(v: Any) -> str | None:
    vals = v if isinstance(v, list) else [v]
    bad = [x for x in vals if not 1 <= x <= MAX_ELEMENTS]
    return f"must be between 1 and {MAX_ELEMENTS} elements (got {bad[0]})" if bad else None


def _damping(v: float) -> str | None:
    return None if 0 <= v < 1 else f"must be a fraction in [0, 1), e.g. 0.02 for 2 % (got {v})"


def _revs(v: int) -> str | None:
    return None if 1 <= v <= 1000 else f"must be between 1 and 1000 (got {v})"


def _fraction_tol(v: float) -> str | None:
    return None if 1e-14 <= v <= 1e-2 else f"must be between 1e-14 and 1e-2 (got {v})"


def _hht(v: float) -> str | None:
    return None if -1 / 3 <= v <= 0 else f"must be between -1/3 and 0 (got {v})"


def _iterations(v: int) -> str | None:
    return None if 1 <= v <= 200 else f"must be between 1 and 200 (got {v})"


def _cuts(v: int) -> str | None:
    return None if 0 <= v <= 20 else f"must be between 0 and 20 (got {v})"


_SECTION_DOC = "(default: from the named material's Table 1a column)"

_KEYS: dict[str, Key] = {
    "material": Key("str", default="custom", choices=("custom",) + tuple(MATERIALS),
                    doc="named rod of Table 1a (fills area, second_moment, density, youngs_modulus, "
                        "section_depth; keys given in the deck override it)"),
    "crank_radius": Key("float", default=0.125, check=positive, units="m", doc="r2 (Table 1b)"),
    "rod_length": Key("float", default=0.505, check=positive, units="m", doc="L3 (Table 1a)"),
    "area": Key("float", check=positive, units="m^2", doc=f"rod section area {_SECTION_DOC}"),
    "second_moment": Key("float", check=positive, units="m^4",
                         doc=f"in-plane second moment of area {_SECTION_DOC}"),
    "density": Key("float", check=positive, units="kg/m^3", doc=_SECTION_DOC),
    "youngs_modulus": Key("float", check=positive, units="Pa", doc=_SECTION_DOC),
    "section_depth": Key("float", check=positive, units="m",
                         doc=f"in-plane depth; outer fibre at depth/2 {_SECTION_DOC}"),
    "section_width": Key("float", check=positive, units="m",
                         doc="rectangular rod: out-of-plane width; with section_depth gives area = w h and "
                             "second_moment = w h^3/12 (instead of area and second_moment)"),
    "section_diameter": Key("float", check=positive, units="m",
                            doc="round rod: diameter d gives area = pi d^2/4, second_moment = pi d^4/64, "
                                "depth d (instead of area, second_moment and section_depth)"),
    "yield_strength": Key("float", units="Pa",
                          check=lambda v: positive(v) or (f"{v:g} Pa is below {MIN_YIELD_PA:g} Pa: yield strengths "
                                                          "are in Pa (276 MPa is 2.76e8); this looks like MPa"
                                                          if v < MIN_YIELD_PA else None),
                          doc="the rod's yield strength; its peak outer-fibre stress E eps is checked against it in "
                              "every model (default: the named material's assumed grade, docs/slidercrank.md: "
                              "aluminium 6061-T6 276 MPa, AISI 1045 310 MPa, AISI 1020 210 MPa; custom: none, no "
                              "check)"),
    "slider_mass": Key("float", default=0.9, check=positive, units="kg", doc="M (Table 1b)"),
    "bearing_mass_crank": Key("float", default=0.05, check=non_negative, units="kg",
                              doc="m_B at the crank pin (prescribed motion: does not load the rod)"),
    "bearing_mass_slider": Key("float", default=0.05, check=non_negative, units="kg",
                               doc="m_C, lumped with the slider on the guide"),
    "speeds": Key("floats", required=True, check=positive, units="rad/s",
                  doc="crank speeds; the paper's: 11.52, 14.66, 18.85, 21.99, 25.13, 29.32"),
    "n_elements": Key("int", default=700, check=_valid_count, doc="rod elements (the paper: 700)"),
    "element_counts": Key("ints", default=None, check=_valid_count,
                          doc="convergence study: element counts to run (e.g. 1, 2, 4, ..., 700)"),
    "steps_per_rev": Key("int", default=1440, check=positive, doc="time steps per crank revolution"),
    "revolutions": Key("int", default=4, check=_revs, doc="revolutions run; the last one is reported"),
    "settle_tolerance": Key("float", default=1e-3, check=positive, units="-",
                            doc="the reported revolution counts as settled (periodic) when strain and "
                                "midpoint deflection change by less than this fraction of their peak "
                                "between the last two revolutions"),
    "damping_ratio": Key("float", default=0.02, check=_damping,
                         doc="Rayleigh damping ratio at the first bending and first axial modes"),
    "start": Key("str", default="quasistatic", choices=("quasistatic", "rest", "simeon1996"),
                 doc="initial state: quasi-static solution, rest, or the Simeon (1996) benchmark's "
                     "published initial values"),
    "analysis": Key("str", default="dynamic", choices=("dynamic", "quasistatic"),
                    doc="Newmark integration, or quasi-static K u = Q at every step"),
    "geometric_stiffness": Key("bool", default=False,
                               doc="add K_G of the rigid-body axial force; report buckling"),
    "end_time": Key("float", default=0.0, check=non_negative, units="s",
                    doc="> 0: integrate from t = 0 to this time and report the end state "
                        "(benchmark mode, one speed) instead of the last revolution"),
    "benchmark": Key("str", default="none", choices=("none", "simeon1996"),
                     doc="compare the end state with a published reference solution"),
    "model": Key("str", default="linear", choices=("linear", "nonlinear"),
                 doc="rod model: the paper's linear KED frame elements, or geometrically nonlinear "
                     "co-rotational elements (large deflections; reported beside the linear model)"),
    "newton_tolerance": Key("float", default=1e-8, check=_fraction_tol, units="-",
                            doc="nonlinear model: Newton converged when the residual is below this "
                                "fraction of the load and internal-force norms"),
    "hht_alpha": Key("float", default=-0.05, check=_hht, units="-",
                     doc="nonlinear model: HHT-alpha parameter in [-1/3, 0]; 0 is Newmark average "
                         "acceleration (no numerical damping), < 0 damps the unresolved high frequencies"),
    "newton_max_iterations": Key("int", default=25, check=_iterations,
                                 doc="nonlinear model: Newton solves allowed per time step before the "
                                     "step is halved"),
    "max_step_cuts": Key("int", default=6, check=_cuts,
                         doc="nonlinear model: halvings of a time step allowed (0: none) before the run "
                             "stops with NO CONVERGENCE"),
    "growth_tolerance": Key("float", default=0.01, check=positive, units="-",
                            doc="nonlinear model: the response grows when the median per-revolution peak "
                                "lateral deflection of the last revolutions exceeds that of those before by more "
                                "than this fraction per revolution (docs/slidercrank.md)"),
    "large_deflection": Key("float", default=0.02, check=positive, units="-",
                            doc="nonlinear model: peak lateral deflection, as a fraction of the rod "
                                "length, counted as a buckled (large-deflection) rod"),
    "onset_speeds": Key("floats", default=None, check=positive, units="rad/s",
                        doc="nonlinear model: speed grid of the dynamic-buckling onset search (bisected "
                            "to 0.05 rad/s where the verdict changes); none: no search"),
    "onset_elements": Key("int", default=40, check=_valid_count,
                          doc="nonlinear model: rod elements of the onset search"),
}


@dataclass
class Model:
    """The rod and mechanism in SI units, with derived constants.

    Attributes
    ----------
    r2 : float
        Crank radius, m.
    length : float
        Rod length L3, m.
    area : float
        Rod section area, m^2.
    inertia : float
        In-plane second moment of area, m^4.
    density : float
        Rod density, kg/m^3.
    modulus : float
        Young's modulus, Pa.
    depth : float
        In-plane section depth (outer fibre at depth/2), m.
    slider_mass : float
        Slider mass M, kg.
    bearing_crank, bearing_slider : float
        Bearing masses at the crank pin and the slider, kg.
    sources : dict of str to str
        Where each value came from (the deck, a named material, a section shape).
    yield_strength : float or None
        The rod's yield strength, Pa; None: not known (a custom rod without ``yield_strength``).
    yield_source : str
        Where it came from (the deck, or the grade assumed for a named material).
    """

    r2: float
    length: float
    area: float
    inertia: float
    density: float
    modulus: float
    depth: float
    slider_mass: float
    bearing_crank: float
    bearing_slider: float
    sources: dict[str, str] = field(default_factory=dict)
    yield_strength: float | None = None
    yield_source: str = ""

    @property
    def rho_a(self) -> float:
        """Mass per unit length of the rod, density x area [kg/m]."""
        return self.density * self.area

    @property
    def ea(self) -> float:
        """Axial stiffness E A [N]."""
        return self.modulus * self.area

    @property
    def ei(self) -> float:
        """Bending stiffness E I [N m^2]."""
        return self.modulus * self.inertia

    @property
    def m_s(self) -> float:
        """Mass on the guide: slider + its bearing [kg]."""
        return self.slider_mass + self.bearing_slider

    def frequencies(self) -> tuple[float, float, float]:
        """Compute the first bending and axial frequencies and the Euler load (closed forms, kernel).

        Returns
        -------
        w_bend, w_axial : float
            First bending and first axial natural frequency, rad/s.
        p_euler : float
            Euler buckling load of the rod, N.
        """
        return kernel.slidercrank_frequencies(self.rho_a, self.ea, self.ei, self.length, self.m_s)


def section_shape(params: Params) -> tuple[dict[str, float], str]:
    """Section values from section_width (rectangle) or section_diameter (round bar), if given."""
    given = lambda k: k in params.given and params[k] is not None
    if given("section_diameter"):
        for k in ("section_width", "area", "second_moment", "section_depth"):
            if given(k):
                raise params.error(k, "section_diameter defines the whole section; do not give " + k)
        d = params.section_diameter
        return {"area": math.pi * d * d / 4, "second_moment": math.pi * d ** 4 / 64, "section_depth": d}, \
            f"round bar D = {d:g} m"
    if given("section_width"):
        for k in ("area", "second_moment"):
            if given(k):
                raise params.error(k, "section_width with section_depth defines the section; do not give " + k)
        if not given("section_depth"):
            raise params.error("section_width", "a rectangular section needs section_depth too (in-plane depth)")
        w, h = params.section_width, params.section_depth
        return {"area": w * h, "second_moment": w * h ** 3 / 12}, f"rectangle {w:g} x {h:g} m"
    return {}, ""


def model_of(params: Params) -> Model:
    values, sources = {}, {}
    table = MATERIALS.get(params.material, {})
    shape, shape_name = section_shape(params)
    for key in SECTION_KEYS:
        if key in shape:
            values[key], sources[key] = shape[key], shape_name
        elif key in params.given and params[key] is not None:
            values[key], sources[key] = params[key], "deck"
        elif key in table:
            values[key], sources[key] = table[key], "Table 1a"
        else:
            raise params.error(key, f"missing: give {key} or name a material "
                                    f"({', '.join(repr(m) for m in MATERIALS)})")
    ys: float | None
    if params.yield_strength is not None:
        ys, ysrc = float(params.yield_strength), "deck"
    else:
        ys, ysrc = table.get("yield_strength"), table.get("grade", "")
    return Model(params.crank_radius, params.rod_length, values["area"], values["second_moment"],
                 values["density"], values["youngs_modulus"], values["section_depth"], params.slider_mass,
                 params.bearing_mass_crank, params.bearing_mass_slider, sources, ys, ysrc)


def rayleigh(zeta: float, w1: float, w2: float) -> tuple[float, float]:
    """Compute the Rayleigh damping coefficients that give one damping ratio at two frequencies.

    Parameters
    ----------
    zeta : float
        Damping ratio, dimensionless.
    w1, w2 : float
        The two frequencies (first bending and first axial), rad/s.

    Returns
    -------
    alpha : float
        Mass-proportional coefficient, 1/s (C = alpha M + beta K).
    beta : float
        Stiffness-proportional coefficient, s.
    """
    return 2 * zeta * w1 * w2 / (w1 + w2), 2 * zeta / (w1 + w2)


def min_steps_per_rev(omega: float, w_bend: float) -> int:
    """Find the fewest time steps per crank revolution the time-step criterion allows.

    Newmark's average-acceleration rule is unconditionally stable but lengthens periods by
    about (w dt)^2 / 12: 20 steps per period of the first bending mode w_bend keep that error
    below 1 %.  Steps per bending period = steps_per_rev * omega / w_bend.

    Parameters
    ----------
    omega : float
        Crank speed, rad/s.
    w_bend : float
        First bending natural frequency of the rod, rad/s.

    Returns
    -------
    int
        Steps per revolution.
    """
    return max(MIN_STEPS_PER_REV, math.ceil(MIN_STEPS_PER_BENDING_PERIOD * w_bend / omega))


def _cross_check(params: Params) -> None:
    model = model_of(params)
    if model.r2 >= model.length:
        raise params.error("crank_radius", f"crank radius {model.r2:g} m is not shorter than the rod "
                                           f"({model.length:g} m): the slider-crank cannot turn; "
                                           "crank_radius must be < rod_length")
    w_bend, _, _ = model.frequencies()
    grid = list(params.onset_speeds or []) if params.model == "nonlinear" else []
    for key, omega in [("speeds", w) for w in params.speeds] + [("onset_speeds", w) for w in grid]:
        ratio = MIN_STEPS_PER_BENDING_PERIOD * w_bend / omega
        if not math.isfinite(ratio) or ratio > 1e9:   # e.g. speeds = 4.9e-324: refused before ceil() overflows
            raise params.error(key, f"crank speed {omega:g} rad/s is too slow to integrate: one revolution "
                                         f"would need more than 10^9 time steps ({MIN_STEPS_PER_BENDING_PERIOD} "
                                         f"per period of the first bending mode, {w_bend:.1f} rad/s)")
        need = min_steps_per_rev(omega, w_bend)
        if params.steps_per_rev < need:
            per = params.steps_per_rev * omega / w_bend
            raise params.error(
                "steps_per_rev" if key == "speeds" else key,
                f"time step too coarse: {params.steps_per_rev} steps per revolution at {omega:g} rad/s "
                f"give {per:.1f} steps per period of the first bending mode ({w_bend:.1f} rad/s); "
                f"the Newmark average-acceleration rule needs at least {MIN_STEPS_PER_BENDING_PERIOD} "
                f"(period error < 1 %) and at least {MIN_STEPS_PER_REV} per revolution: use "
                f"steps_per_rev >= {need}")
    if params.end_time > 0 and len(params.speeds) != 1:
        raise params.error("end_time", "benchmark mode (end_time > 0) runs one crank speed; "
                                       f"speeds lists {len(params.speeds)}")
    if params.end_time > 0 and params.element_counts:
        raise params.error("element_counts", "a convergence study reports last revolutions; "
                                             "remove element_counts or end_time")
    if params.model == "nonlinear":
        for key, bad, why in (("element_counts", bool(params.element_counts), "a convergence study"),
                              ("end_time", params.end_time > 0, "benchmark mode"),
                              ("analysis", params.analysis != "dynamic", "a quasi-static analysis"),
                              ("geometric_stiffness", params.geometric_stiffness,
                               "K_G (the nonlinear rod has its own geometric stiffness)"),
                              ("start", params.start == "simeon1996", "the Simeon start")):
            if bad:
                raise params.error(key, f"model = 'nonlinear' runs the last revolutions of each speed; "
                                        f"{why} is a linear-model option: remove {key}")
        if params.revolutions < 4:
            raise params.error("revolutions", "model = 'nonlinear' judges growth over the last four "
                                              f"revolutions: revolutions must be >= 4 (got {params.revolutions})")
        if params.n_elements < 2:
            raise params.error("n_elements", "model = 'nonlinear' needs at least 2 elements")
    elif params.onset_speeds:
        raise params.error("onset_speeds", "the dynamic-buckling onset search needs model = 'nonlinear'")
    if params.start == "simeon1996" or params.benchmark == "simeon1996":
        key = "start" if params.start == "simeon1996" else "benchmark"
        ref = SIMEON1996
        if not (math.isclose(model.r2, ref["crank_radius"]) and math.isclose(model.length, ref["rod_length"])
                and all(math.isclose(w, ref["speed"]) for w in params.speeds)):
            raise params.error(key, "the Simeon (1996) benchmark needs crank_radius = 0.15 m, "
                                    "rod_length = 0.30 m and speeds = 150 rad/s")
        if params.benchmark == "simeon1996" and params.end_time <= 0:
            raise params.error("end_time", "benchmark 'simeon1996' compares the state at end_time; "
                                           "set end_time = 0.1")


#: axis labels of summary columns and deck keys (driver._output.column_label): name -> (words, units);
#: {i} is the number of a crank speed in the deck's list
LABELS = {"speeds": ("crank speed", "rad/s"), "n_elements": ("rod elements", "-"),
          "omega_{i}_rad_s": ("crank speed {i}", "rad/s"), "euler_ratio_{i}": ("peak compression / Euler load, speed {i}", "-"),
          "peak_tensile_{i}_microstrain": ("peak tensile strain, speed {i}", "microstrain"),
          "peak_tensile_{i}_deg": ("crank angle of peak tension, speed {i}", "deg"),
          "peak_compressive_{i}_microstrain": ("peak compressive strain (negative), speed {i}", "microstrain"),
          "peak_compressive_{i}_deg": ("crank angle of peak compression, speed {i}", "deg"),
          "peak_tensile_microstrain": ("peak tensile strain", "microstrain"),
          "peak_tensile_deg": ("crank angle of peak tension", "deg"),
          "peak_compressive_microstrain": ("peak compressive strain (negative)", "microstrain"),
          "peak_compressive_deg": ("crank angle of peak compression", "deg"),
          "euler_ratio_max": ("peak compression / Euler load", "-"), "n_buckled": ("speeds buckled", "-"),
          "rod_mass_kg": ("rod mass", "kg"), "section_area_m2": ("rod section area", "m^2"),
          "section_width": ("section width", "m"), "section_depth": ("section depth", "m")}
#: what a sweep summary plots when its deck names no plot_y
SWEEP_PLOT = ("peak_tensile_microstrain", "peak_compressive_microstrain", "euler_ratio_max", "peak_tensile_deg",
              "peak_compressive_deg", "n_buckled")


SPEC = GroupSpec("slidercrank", _KEYS,
                 "slider-crank with a rigid crank and an elastic connecting rod (KED finite elements, Newmark)",
                 check=_cross_check)


@contract_doc
def estimate(params: Params) -> Estimate:
    """Estimate the memory and work of a run from the keys alone, before it allocates.

    Every (speed, element count)
    integrates n_steps Newmark steps over 3 (n + 1) degrees of freedom (banded, about 0.2 us per
    dof and step) and records the last two revolutions of states (to judge settling); the static
    buckling onset factors K + K_G some 2000 times (about 0.3 ms per dof in all).

    %(estimate)s
    """
    p = params
    counts = list(p.element_counts) if p.element_counts else [p.n_elements]
    work, mem, steps_max = 0.0, 0.0, 0.0
    for w in p.speeds:
        if p.end_time > 0:
            steps = p.end_time * w * p.steps_per_rev / (2 * math.pi) + 1.0
            rec = 1.0
        else:
            steps = float(p.revolutions) * p.steps_per_rev
            rec = (2.0 if p.revolutions >= 2 else 1.0) * p.steps_per_rev + 1.0
        steps_max = max(steps_max, steps)
        for n in counts:
            dof = 3.0 * (n + 1)
            work += 2e-7 * dof * steps
            mem = max(mem, dof * 8.0 * 40 + rec * (dof * 8.0 * 3 + 400.0))
    if p.model == "nonlinear":   # Newton, 1-2 solves of the assembled tangent a step: about 3.5e-7 s per
        work *= 3.0              # dof and step (the linear rate above is a generous bound), plus the linear
        grid = len(p.onset_speeds or ())    # run beside it; the onset search runs onset_elements, ~14 bisections
        work += (grid + 14 if grid else 0) * 6e-7 * 3.0 * (p.onset_elements + 1) * p.revolutions * p.steps_per_rev
    work += 3e-4 * 3.0 * (counts[-1] + 1)      # static_onset on the reported mesh
    key = "end_time" if p.end_time > 0 else ("steps_per_rev" if p.steps_per_rev > 100_000 else
                                             ("element_counts" if p.element_counts else "n_elements"))
    wkey = key if key != "n_elements" or len(p.speeds) < 100 else "speeds"
    return Estimate(mem + 5e6, work + 0.1, key, wkey,
                    f"{len(p.speeds)} speed(s) x {len(counts)} element count(s), up to {steps_max:.4g} time steps")
