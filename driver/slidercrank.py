"""Slider-crank with an elastic connecting rod [Andalas]: the &slidercrank study.

Rigid crank, elastic rod meshed with frame elements, slider on its guide; kineto-elastodynamic
(KED) finite-element model integrated with Newmark's average-acceleration rule.  The physics
(kinematics, rigid-body axial force, element matrices, banded Cholesky, the whole time loop)
lives in ``fortran/slidercrank.f90``; this module validates the deck, runs the cases, and
writes the paper's results: peak axial strain per crank speed, strain of the crank-end
element against crank angle (Figure 10), the element-convergence study (Figures 8-9), the
Euler-load ratio of every case and, with geometric stiffness, buckling.

Units in decks: SI (m, kg, Pa, rad/s, s).  Strains are reported in microstrain.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from scipy.linalg import LinAlgError, cholesky_banded
from tqdm import tqdm

from driver import kernels
from driver.limits import Estimate
from driver.deck import GroupSpec, Key, Params, non_negative, positive
from driver.export import with_units
from driver.study import Figure, Result, keyword_run
from driver.table import Column, render_table

__all__ = ["SPEC", "run", "MATERIALS", "PAPER_SPEEDS", "SIMEON1996", "simeon_initial_state",
           "min_steps_per_rev", "rayleigh", "static_onset", "STATUS_TEXT"]

#: Table 1a of the paper (columns re-ordered, docs/slidercrank.md); the depth is the
#: in-plane section depth used for the outer-fibre strain (weak axis in plane).
MATERIALS: dict[str, dict[str, Any]] = {
    "aluminium": dict(area=27e-6, second_moment=2.025e-11, density=2660.0, youngs_modulus=7.17e10,
                      section_depth=3.0e-3, section="rectangle 9 x 3 mm, weak axis in plane"),
    "medium_carbon_steel": dict(area=22.5e-6, second_moment=1.1718e-11, density=7800.0,
                                youngs_modulus=20.68e10, section_depth=2.5e-3,
                                section="rectangle 9 x 2.5 mm, weak axis in plane"),
    "low_carbon_steel": dict(area=7.8965e-5, second_moment=4.9620e-10, density=7800.0,
                             youngs_modulus=18.96e10, section_depth=10.03e-3,
                             section="round bar D = 10.03 mm"),
}
SECTION_KEYS = ("area", "second_moment", "density", "youngs_modulus", "section_depth")
#: the paper's six crank speeds [rad/s]
PAPER_SPEEDS = (11.52, 14.66, 18.85, 21.99, 25.13, 29.32)
#: time-step criterion: steps per period of the first bending mode, and per revolution
MIN_STEPS_PER_BENDING_PERIOD = 20
MIN_STEPS_PER_REV = 36
EULER_WARN = 0.8
MAX_ELEMENTS = 5000
#: what each failed case status means (the kernel's triggers, fortran/slidercrank.f90)
STATUS_TEXT = {
    "buckled": ("STATIC INSTABILITY", "K + K_G lost definiteness (the rod buckles)"),
    "diverged": ("LIMIT L/20", "elastic deflection exceeded L/20 (or a rotation 0.25 rad): "
                               "the linear model is no longer valid"),
    "not_spd": ("NOT SPD", "the iteration matrix is not positive definite"),
    "bad_args": ("BAD ARGUMENTS", "the kernel refused its arguments"),
}

#: Simeon (1996) / IVP test set "crank": published initial values (ini = 1, consistent) of the
#: modal coordinates q1, q2 (lateral sin(pi x), sin(2 pi x)), q3, q4 (axial, quadratic: midpoint
#: and end node) and their rates, and the reference solution at t = 0.1 s (MEBDFI, tol 1e-14).
SIMEON1996 = {
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
}


# --------------------------------------------------------------------------- model


@dataclass
class Model:
    """The rod and mechanism in SI units, with derived constants."""

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

    @property
    def rho_a(self) -> float:
        return self.density * self.area

    @property
    def ea(self) -> float:
        return self.modulus * self.area

    @property
    def ei(self) -> float:
        return self.modulus * self.inertia

    @property
    def m_s(self) -> float:
        """Mass on the guide: slider + its bearing [kg]."""
        return self.slider_mass + self.bearing_slider

    def frequencies(self) -> tuple[float, float, float]:
        """First bending, first axial frequency [rad/s] and Euler load [N] (closed forms, kernel)."""
        return kernels.slidercrank_frequencies(self.rho_a, self.ea, self.ei, self.length, self.m_s)


def _shape(params: Params) -> tuple[dict[str, float], str]:
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


def _model(params: Params) -> Model:
    values, sources = {}, {}
    table = MATERIALS.get(params.material, {})
    shape, shape_name = _shape(params)
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
    return Model(params.crank_radius, params.rod_length, values["area"], values["second_moment"],
                 values["density"], values["youngs_modulus"], values["section_depth"], params.slider_mass,
                 params.bearing_mass_crank, params.bearing_mass_slider, sources)


def rayleigh(zeta: float, w1: float, w2: float) -> tuple[float, float]:
    """Rayleigh coefficients (alpha [1/s], beta [s]) giving ratio zeta at w1 and w2 [rad/s]."""
    return 2 * zeta * w1 * w2 / (w1 + w2), 2 * zeta / (w1 + w2)


def min_steps_per_rev(omega: float, w_bend: float) -> int:
    """Fewest steps per revolution at crank speed omega [rad/s] for the time-step criterion.

    Newmark's average-acceleration rule is unconditionally stable but lengthens periods by
    about (w dt)^2 / 12: 20 steps per period of the first bending mode w_bend keep that error
    below 1 %.  Steps per bending period = steps_per_rev * omega / w_bend.
    """
    return max(MIN_STEPS_PER_REV, math.ceil(MIN_STEPS_PER_BENDING_PERIOD * w_bend / omega))


def _cross_check(params: Params) -> None:
    model = _model(params)
    if model.r2 >= model.length:
        raise params.error("crank_radius", f"crank radius {model.r2:g} m is not shorter than the rod "
                                           f"({model.length:g} m): the slider-crank cannot turn; "
                                           "crank_radius must be < rod_length")
    w_bend, _, _ = model.frequencies()
    for omega in params.speeds:
        ratio = MIN_STEPS_PER_BENDING_PERIOD * w_bend / omega
        if not math.isfinite(ratio) or ratio > 1e9:   # e.g. speeds = 4.9e-324: refused before ceil() overflows
            raise params.error("speeds", f"crank speed {omega:g} rad/s is too slow to integrate: one revolution "
                                         f"would need more than 10^9 time steps ({MIN_STEPS_PER_BENDING_PERIOD} "
                                         f"per period of the first bending mode, {w_bend:.1f} rad/s)")
        need = min_steps_per_rev(omega, w_bend)
        if params.steps_per_rev < need:
            per = params.steps_per_rev * omega / w_bend
            raise params.error(
                "steps_per_rev",
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


#: axis labels of summary columns and deck keys (driver.study.column_label): name -> (words, units);
#: {i} is the number of a crank speed in the deck's list
LABELS = {"speeds": ("crank speed", "rad/s"), "n_elements": ("rod elements", "-"),
          "omega_{i}_rad_s": ("crank speed {i}", "rad/s"), "euler_ratio_{i}": ("peak compression / Euler load, speed {i}", "-"),
          "peak_tensile_{i}_microstrain": ("peak tensile strain, speed {i}", "microstrain"),
          "peak_tensile_{i}_deg": ("crank angle of peak tension, speed {i}", "deg"),
          "peak_compressive_{i}_microstrain": ("peak compressive strain, speed {i}", "microstrain"),
          "peak_compressive_{i}_deg": ("crank angle of peak compression, speed {i}", "deg"),
          "peak_tensile_microstrain": ("peak tensile strain", "microstrain"),
          "peak_tensile_deg": ("crank angle of peak tension", "deg"),
          "peak_compressive_microstrain": ("peak compressive strain", "microstrain"),
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


def simeon_initial_state(n_elements: int, length: float) -> tuple[np.ndarray, np.ndarray]:
    """Simeon's published initial modal values mapped onto the FE nodes (kernel q ordering).

    Lateral v(x) = q1 sin(pi x/L) + q2 sin(2 pi x/L) with rotations v'(x); axial u(x) the
    quadratic through (0, 0), (L/2, q3), (L, q4); the slider's U_X = q4 (theta3 = 0 at t = 0).
    """
    x = np.linspace(0.0, 1.0, n_elements + 1)

    def nodal(q: tuple[float, ...]) -> np.ndarray:
        v = q[0] * np.sin(np.pi * x) + q[1] * np.sin(2 * np.pi * x)
        th = (q[0] * np.pi * np.cos(np.pi * x) + q[1] * 2 * np.pi * np.cos(2 * np.pi * x)) / length
        u = q[2] * 4 * x * (1 - x) + q[3] * x * (2 * x - 1)
        out = np.zeros(3 * n_elements)
        out[0] = th[0]
        inner = np.column_stack([u[1:-1], v[1:-1], th[1:-1]]).ravel()
        out[1:1 + inner.size] = inner
        out[-2], out[-1] = th[-1], u[-1]
        return out

    return nodal(SIMEON1996["q0"]), nodal(SIMEON1996["qd0"])


def static_onset(model: Model, n_elements: int, step_deg: float = 10.0) -> tuple[float, float] | None:
    """Lowest constant crank speed [rad/s] at which the static tangent K + K_G of the rigid-body
    axial force loses definiteness at some crank angle, and that angle [deg] to the ``step_deg``
    scan; None if never (below 1e6 rad/s).

    The rigid-body axial force, hence K_G, scales with omega^2 at constant crank speed, so at
    each crank angle the onset is the largest t = omega^2 keeping K + t K_G(omega = 1) positive
    definite (bisection on the kernel's banded matrices, LAPACK Cholesky as the test); a
    ``step_deg`` scan finds the critical angle and a 1-deg scan around it the speed.  Near the
    critical angle the speed varies by ~1e-4 only and the Cholesky test is that noisy on fine
    meshes, so the speed is good to about 0.01 rad/s and the angle only to the coarse scan.
    """
    args = (n_elements, model.r2, model.length, model.rho_a, model.ea, model.ei, model.m_s)

    def omega_at(theta_deg: float) -> float:
        th = math.radians(theta_deg)
        k0 = kernels.slidercrank_matrices(*args, th, 0.0, False)[1]
        g = kernels.slidercrank_matrices(*args, th, 1.0, True)[1] - k0

        def definite(t: float) -> bool:
            try:
                cholesky_banded(k0 + t * g, lower=True, check_finite=False)
            except LinAlgError:
                return False
            return True

        lo, hi = 0.0, 1.0
        while definite(hi):
            lo, hi = hi, 4.0 * hi
            if hi > 1e12:
                return math.inf
        while hi - lo > 1e-8 * hi:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if definite(mid) else (lo, mid)
        return math.sqrt(0.5 * (lo + hi))

    grid = np.arange(0.0, 360.0, step_deg)
    w = np.array([omega_at(t) for t in grid])
    k = int(np.argmin(w))
    if not math.isfinite(w[k]):
        return None
    fine = grid[k] + np.arange(-step_deg + 1.0, step_deg - 0.5, 1.0)
    return float(min(w[k], min(omega_at(t) for t in fine))), float(grid[k] % 360.0)


# --------------------------------------------------------------------------- cases


@dataclass
class Case:
    """One run: crank speed, element count and its last-revolution (or end-state) results."""

    omega: float
    n_elements: int
    status: str
    dt: float = 0.0
    fail_angle_deg: float | None = None
    fail_rev: int | None = None
    angle_deg: np.ndarray | None = None
    time: np.ndarray | None = None
    eps_ax: np.ndarray | None = None
    eps_of: np.ndarray | None = None
    n_avg: np.ndarray | None = None
    mid: np.ndarray | None = None
    slider: np.ndarray | None = None
    elong: np.ndarray | None = None
    euler_ratio: float = 0.0
    peak_compression: float = 0.0
    settle_strain: float | None = None    # relative change between the last two revolutions
    settle_mid: float | None = None

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def crank_end_peak(self, sign: int) -> float:
        """Peak strain [-] at the crank pin itself (s = 0), recovered by linear extrapolation
        of the first two element strains (midpoints L/2n, 3L/2n); exact for a strain field
        linear in s.  Element averages converge as 1/n where N(s) varies; this converges fast."""
        e = self.eps_ax[0] if self.eps_ax.shape[0] < 2 else 1.5 * self.eps_ax[0] - 0.5 * self.eps_ax[1]
        return float(np.max(sign * e) * sign)

    def peak(self, sign: int) -> tuple[float, float, int]:
        """Peak tensile (sign=+1) or compressive (-1) axial strain [-], crank angle [deg], element."""
        flat = np.argmax(sign * self.eps_ax)
        e, j = np.unravel_index(flat, self.eps_ax.shape)
        return float(self.eps_ax[e, j]), float(self.angle_deg[j] % 360.0), int(e) + 1


def _run_case(model: Model, params: Params, omega: float, n_el: int, alpha: float, beta: float,
              p_euler: float) -> Case:
    spr = params.steps_per_rev
    dt = 2 * math.pi / (omega * spr)
    if params.end_time > 0:
        n_steps = max(1, round(params.end_time / dt))
        dt = params.end_time / n_steps
        rec_start, n_rec = n_steps, 1
    else:
        n_steps = params.revolutions * spr
        two = params.revolutions >= 2     # record the last two revolutions to judge settling
        rec_start, n_rec = (params.revolutions - (2 if two else 1)) * spr, (2 if two else 1) * spr + 1
    q0 = qd0 = None
    start = params.start
    if start == "simeon1996":
        q0, qd0 = simeon_initial_state(n_el, model.length)
        start = "given"
    res = kernels.slidercrank_simulate(
        n_el, model.r2, model.length, model.rho_a, model.ea, model.ei, model.depth / 2, model.m_s, omega,
        dt, n_steps, rec_start, n_rec, alpha, beta, start=start, dynamic=params.analysis == "dynamic",
        geometric_stiffness=params.geometric_stiffness, q_init=q0, qd_init=qd0)
    if params.end_time <= 0 and params.revolutions >= 2:
        res = _settle(res, spr)
        rec_start, n_rec = rec_start + spr, spr + 1
    steps = rec_start + np.arange(n_rec)
    theta = omega * dt * steps
    # peak rod compression from rigid-body statics over the reported revolution (N is quadratic in s)
    s = np.linspace(0.0, model.length, 41)
    n_rigid = kernels.slidercrank_axial_force(theta, s, omega, model.r2, model.length, model.rho_a, model.m_s)
    peak_c = max(0.0, float(-n_rigid.min()))
    status = {v: k for k, v in kernels.SLIDERCRANK_STATUS.items()}[res["status"]]
    case = Case(omega, n_el, status, dt, euler_ratio=peak_c / p_euler, peak_compression=peak_c)
    if status != "ok":
        t_fail = max(res["fail_step"], 0) * dt
        case.fail_angle_deg = math.degrees(omega * t_fail) % 360.0
        case.fail_rev = int(omega * t_fail // (2 * math.pi)) + 1
        return case
    case.time = dt * steps
    case.angle_deg = np.degrees(theta) - 360.0 * (params.revolutions - 1) if params.end_time <= 0 \
        else np.degrees(theta)
    for name in ("eps_ax", "eps_of", "n_avg", "mid", "slider", "elong"):
        setattr(case, name, res[name])
    case.settle_strain, case.settle_mid = res.get("settle_strain"), res.get("settle_mid")
    return case


def _settle(res: dict, spr: int) -> dict:
    """Split a two-revolution record: keep the last revolution, and measure how far it is from
    periodic: the largest change of the strain field and of the midpoint deflection between
    the two revolutions, relative to their peak in the last one."""
    out = dict(res)
    for name in ("eps_ax", "eps_of", "n_avg"):
        out[name] = res[name][:, spr:]
    for name in ("mid", "slider", "elong"):
        out[name] = res[name][spr:]

    def change(a: np.ndarray, b: np.ndarray) -> float:
        peak = float(np.abs(b).max())
        return float(np.abs(b - a).max()) / peak if peak > 0 else 0.0
    out["settle_strain"] = change(res["eps_ax"][:, :spr + 1], out["eps_ax"])
    out["settle_mid"] = change(res["mid"][:spr + 1], out["mid"])
    return out


# --------------------------------------------------------------------------- text


def _f(x: float, d: int = 3) -> str:
    return f"{x:.{d}f}"


def _header(params: Params, model: Model, derived: dict[str, float]) -> list[str]:
    mat = params.material if params.material != "custom" else "custom (section from the deck)"
    src = model.sources
    rows = [
        ("material", "", mat),
        ("crank radius r2", "m", f"{model.r2:g}"),
        ("rod length L3", "m", f"{model.length:g}"),
        ("section area A", "m^2", f"{model.area:.5g}   ({src['area']})"),
        ("second moment I", "m^4", f"{model.inertia:.5g}   ({src['second_moment']})"),
        ("density rho", "kg/m^3", f"{model.density:g}   ({src['density']})"),
        ("Young's modulus E", "Pa", f"{model.modulus:.5g}   ({src['youngs_modulus']})"),
        ("section depth (outer fibre at depth/2)", "m", f"{model.depth:g}   ({src['section_depth']})"),
        ("slider mass M", "kg", f"{model.slider_mass:g}"),
        ("bearing masses m_B (crank pin), m_C (slider)", "kg",
         f"{model.bearing_crank:g}, {model.bearing_slider:g}"),
        ("crank speeds", "rad/s", ", ".join(f"{w:g}" for w in params.speeds)),
        ("elements", "", ", ".join(map(str, params.element_counts)) if params.element_counts
         else str(params.n_elements)),
        ("steps per revolution", "", str(params.steps_per_rev)),
        ("revolutions (last one reported)" if params.end_time <= 0 else "end time", "" if params.end_time <= 0
         else "s", str(params.revolutions) if params.end_time <= 0 else f"{params.end_time:g}"),
        ("start", "", params.start),
        ("analysis", "", params.analysis),
        ("geometric stiffness K_G", "", "on" if params.geometric_stiffness else "off"),
        ("damping ratio (Rayleigh)", "", f"{params.damping_ratio:g}"),
    ]
    out = ["Slider-crank with an elastic connecting rod: KED finite elements, Newmark average acceleration",
           "[Andalas]; formulation and corrections: docs/slidercrank.md", "", "Inputs"]
    out += [f"  {name:<46} {('[' + u + ']') if u else '':<9} {val}" for name, u, val in rows]
    out += ["", "Model",
            "  rod: planar frame elements (axial + bending), consistent mass and stiffness (eqs. 26, 29",
            "  corrected); crank pin pinned, slider node on the guide (global X free, Y fixed) with",
            "  M + m_C lumped; rigid-body inertia loading in the rod frame (eq. 23); Rayleigh damping",
            f"  C = alpha M + beta K, alpha = {derived['alpha']:.5g} 1/s, beta = {derived['beta']:.5g} s",
            f"  first bending frequency (pinned-pinned)       {derived['w_bend']:10.2f} rad/s",
            f"  first axial frequency (fixed / slider mass)   {derived['w_axial']:10.2f} rad/s",
            f"  Euler load pi^2 EI / L^2 (pinned-pinned)      {derived['p_euler']:10.2f} N",
            _onset_line(derived["onset"]),
            f"  rod mass                                      {model.rho_a * model.length:10.4f} kg",
            f"  axial stiffness EA, bending stiffness EI      {model.ea:.5g} N, {model.ei:.5g} N m^2"]
    return out


def _onset_line(onset: tuple[float, float] | None) -> str:
    head = "  static buckling onset (K + K_G singular)      "
    if onset is None:
        return head + "      none below 1e6 rad/s"
    return head + f"{onset[0]:10.2f} rad/s near theta2 = {onset[1]:.0f} deg"


def _status_text(c: Case, why: bool = True) -> str:
    if c.ok:
        return "ok"
    what, reason = STATUS_TEXT[c.status]
    text = f"{what} at theta2 = {c.fail_angle_deg:.2f} deg (revolution {c.fail_rev})"
    return f"{text}: {reason}" if why else text


def _unsettled(c: Case, tol: float) -> bool:
    return c.settle_strain is not None and max(c.settle_strain, c.settle_mid) > tol


def _settle_text(c: Case) -> str:
    return "-" if c.settle_strain is None else f"{100 * max(c.settle_strain, c.settle_mid):.3f}"


def _peak_table(cases: list[Case], tol: float) -> list[str]:
    cols = [Column("omega", "f", 7, 2), Column("tensile", "f", 9, 2), Column("theta2", "f", 7, 2),
            Column("el", "i", 4), Column("compress", "f", 9, 2), Column("theta2", "f", 7, 2),
            Column("el", "i", 4), Column("outer", "f", 9, 2), Column("middefl", "f", 8, 4),
            Column("N/P_E", "f", 6, 3), Column("settle%", "s", 8)]
    rows, trailers = [], []
    for c in cases:
        if c.ok:
            t, ta, te = c.peak(+1)
            p, pa, pe = c.peak(-1)
            rows.append([c.omega, t * 1e6, ta, te, p * 1e6, pa, pe, float(c.eps_of.max()) * 1e6,
                         float(np.abs(c.mid).max()) * 1e3, c.euler_ratio, _settle_text(c)])
            notes = (["NOT SETTLED"] if _unsettled(c, tol) else []) + \
                (["warning: N/P_E > 0.8"] if c.euler_ratio > EULER_WARN else [])
            trailers.append("; ".join(notes))
        else:
            rows.append([c.omega, "-", "-", "-", "-", "-", "-", "-", "-", c.euler_ratio, "-"])
            trailers.append(_status_text(c, why=False))
    return ["Table 1  Peak axial strain of the rod over the last revolution",
            "         omega [rad/s]; strains in microstrain; theta2 [deg] where the peak occurs; el = element",
            "         (1 = crank end); outer = peak outer-fibre strain |eps| + c|kappa|; middefl = peak |midpoint",
            "         deflection| [mm]; N/P_E = peak rigid-body rod compression / Euler load; settle% = largest",
            "         change of strain or midpoint deflection between the last two revolutions, % of its peak",
            f"         (NOT SETTLED above {100 * tol:g} %: the printed revolution is not yet periodic)", ""] \
        + render_table(cols, rows, trailers)


def _crank_end_table(cases: list[Case], every_deg: float = 10.0) -> list[str]:
    grid = np.arange(0.0, 360.0 + 1e-9, every_deg)
    cols = [Column("theta2", "f", 7, 1)] + [Column(f"w={c.omega:g}", "f", 9, 2) for c in cases]
    series = []
    for c in cases:
        if c.ok:
            series.append(np.interp(grid, c.angle_deg, c.eps_ax[0]) * 1e6)
        else:
            series.append(None)
    rows = [[g] + [("-" if s is None else float(s[k])) for s in series] for k, g in enumerate(grid)]
    lines = ["Table 2  Axial strain of the crank-end element vs crank angle, last revolution (microstrain)",
             "         (one column per crank speed [rad/s], like the paper's Figure 10)", ""]
    lines += render_table(cols, rows)
    bad = [c for c in cases if not c.ok]
    for c in bad:
        lines.append(f"  w={c.omega:g}: {_status_text(c, why=False)}; no strains reported")
    return lines


def _convergence_table(conv: dict[float, list[Case]], length: float) -> list[str]:
    lines = ["Table 3  Element convergence: peak axial strain over the last revolution (microstrain) and",
             "         percentage change from the previous element count (like the paper's Figures 8-9)"]
    lines += ["         element: peak strain of the crank-end element (an element average, the paper's",
              "         quantity); at pin: strain at the crank pin recovered from the first two elements"]
    cols = [Column("elements", "i", 8), Column("le [mm]", "f", 8, 3), Column("tensile", "f", 9, 3),
            Column("change%", "f", 8, 3), Column("compress", "f", 9, 3), Column("change%", "f", 8, 3),
            Column("tens@pin", "f", 9, 3), Column("change%", "f", 8, 3), Column("comp@pin", "f", 9, 3),
            Column("change%", "f", 8, 3)]
    change = lambda new, old: "-" if old is None else 100 * (new - old) / old
    for omega, cases in conv.items():
        rows, trailers, prev = [], [], None
        for c in cases:
            le = 1e3 * length / c.n_elements
            if not c.ok:
                rows.append([c.n_elements, le] + ["-"] * 8)
                trailers.append(_status_text(c, why=False))
                prev = None
                continue
            vals = (c.peak(+1)[0] * 1e6, c.peak(-1)[0] * 1e6, c.crank_end_peak(+1) * 1e6, c.crank_end_peak(-1) * 1e6)
            old = prev or (None,) * 4
            rows.append([c.n_elements, le] + [x for v, o in zip(vals, old) for x in (v, change(v, o))])
            trailers.append("")
            prev = vals
        lines += ["", f"  crank speed {omega:g} rad/s", ""] + render_table(cols, rows, trailers)
    lines += ["", "  Why the element strain needs many elements: the rigid-body axial force falls along the rod",
              "  (inertia of the rod itself), and an element strain is its average over the element, so the",
              "  crank-end element converges to the pin value only as 1/n (the paper's 700 elements). The",
              "  recovered pin strain removes that averaging error and is converged with a few elements."]
    return lines


# --------------------------------------------------------------------------- run


def _tidy(model_name: str, cases: list[Case]) -> pd.DataFrame:
    frames = []
    for c in cases:
        if not c.ok:
            continue
        frames.append(pd.DataFrame({
            "material": model_name, "omega_rad_s": c.omega, "n_elements": c.n_elements,
            "crank_angle_deg": c.angle_deg, "time_s": c.time,
            "eps_crank_end_microstrain": c.eps_ax[0] * 1e6,
            "eps_max_microstrain": c.eps_ax.max(axis=0) * 1e6,
            "eps_min_microstrain": c.eps_ax.min(axis=0) * 1e6,
            "outer_fibre_max_microstrain": c.eps_of.max(axis=0) * 1e6,
            "n_rigid_crank_end_N": c.n_avg[0],
            "midpoint_deflection_mm": c.mid * 1e3,
            "slider_position_m": c.slider,
            "rod_elongation_um": c.elong * 1e6,
        }))
    if not frames:
        return with_units(pd.DataFrame(columns=["material", "omega_rad_s", "n_elements", "crank_angle_deg"]),
                          {"n_elements": "1"})
    return with_units(pd.concat(frames, ignore_index=True), {"n_elements": "1"})


def _summary(cases: list[Case], model: Model | None = None) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for i, c in enumerate(cases, start=1):
        out[f"omega_{i}_rad_s"] = c.omega
        out[f"euler_ratio_{i}"] = c.euler_ratio
        out[f"buckled_{i}"] = not c.ok
        if c.ok:
            t, ta, _ = c.peak(+1)
            p, pa, _ = c.peak(-1)
            out.update({f"peak_tensile_{i}_microstrain": t * 1e6, f"peak_tensile_{i}_deg": ta,
                        f"peak_compressive_{i}_microstrain": p * 1e6, f"peak_compressive_{i}_deg": pa})
    good = [c for c in cases if c.ok]
    if good:
        best = max(good, key=lambda c: c.peak(+1)[0])
        worst = min(good, key=lambda c: c.peak(-1)[0])
        out.update({"peak_tensile_microstrain": best.peak(+1)[0] * 1e6, "peak_tensile_deg": best.peak(+1)[1],
                    "peak_compressive_microstrain": worst.peak(-1)[0] * 1e6,
                    "peak_compressive_deg": worst.peak(-1)[1]})
    out["euler_ratio_max"] = max(c.euler_ratio for c in cases)
    if model is not None:   # a section given by its shape (what a section optimisation varies)
        out["rod_mass_kg"] = model.rho_a * model.length
        out["section_area_m2"] = model.area
    out["buckled"] = any(not c.ok for c in cases)
    out["n_buckled"] = sum(not c.ok for c in cases)
    return out


def _peak_notes(cases: list[Case]) -> list[str]:
    """Where the peaks of this run occur, from the table (not fixed text)."""
    good = [c for c in cases if c.ok]
    if not good:
        return []
    out = []
    for sign, name in ((+1, "tensile"), (-1, "compressive")):
        peaks = [c.peak(sign) for c in good]
        els = sorted({e for _, _, e in peaks})
        ang = [a for _, a, _ in peaks]
        where = f"element {els[0]}" if len(els) == 1 else "elements " + ", ".join(map(str, els))
        span = f"{min(ang):.1f}" if max(ang) - min(ang) < 0.05 else f"{min(ang):.1f} to {max(ang):.1f}"
        out.append(f"    The peak {name} strain of this run occurs in {where} (1 = crank end) at theta2 = "
                   f"{span} deg.")
    return out


def _benchmark_lines(params: Params, case: Case) -> list[str]:
    lines = ["Table 4  End state at t = " + f"{params.end_time:g} s", ""]
    if not case.ok:
        return lines + [f"  {_status_text(case)}"]
    kin = kernels.slidercrank_rigid(np.array([case.omega * case.time[-1]]), case.omega,
                                    params.crank_radius, params.rod_length)[0]
    vals = [("midpoint deflection from the chord (q1)", "m", float(case.mid[-1]), "q1"),
            ("rod elongation (q4)", "m", float(case.elong[-1]), "q4"),
            ("slider position (x3)", "m", float(case.slider[-1]), "x3"),
            ("rod angle, rigid (phi2)", "rad", float(kin[0]), "phi2")]
    cols = [Column("quantity", "s", 40), Column("unit", "s", 4), Column("this model", "s", 16)]
    if params.benchmark == "simeon1996":
        cols += [Column("Simeon 1996", "s", 16), Column("diff %", "f", 8, 3)]
    rows = []
    for name, unit, v, ref in vals:
        row = [name, unit, f"{v:.9e}"]
        if params.benchmark == "simeon1996":
            r = SIMEON1996[ref]
            row += [f"{r:.9e}", 100 * (v - r) / abs(r)]
        rows.append(row)
    lines += render_table(cols, rows)
    if params.benchmark == "simeon1996":
        lines += ["", "  Reference: Simeon (1996), IVP test set 'crank' (MEBDFI, tol 1e-14): 2 lateral sine modes,",
                  "  quadratic axial field, full rigid-elastic coupling; this model is linear KED (eq. 23)."]
    return lines


def estimate(params: Params) -> Estimate:
    """Memory and work of a run from the keys alone (driver.limits): every (speed, element count)
    integrates n_steps Newmark steps over 3 (n + 1) degrees of freedom (banded, about 0.2 us per
    dof and step) and records the last two revolutions of states (to judge settling); the static
    buckling onset factors K + K_G some 2000 times (about 0.3 ms per dof in all)."""
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
    work += 3e-4 * 3.0 * (counts[-1] + 1)      # static_onset on the reported mesh
    key = "end_time" if p.end_time > 0 else ("steps_per_rev" if p.steps_per_rev > 100_000 else
                                             ("element_counts" if p.element_counts else "n_elements"))
    wkey = key if key != "n_elements" or len(p.speeds) < 100 else "speeds"
    return Estimate(mem + 5e6, work + 0.1, key, wkey,
                    f"{len(p.speeds)} speed(s) x {len(counts)} element count(s), up to {steps_max:.4g} time steps")


@keyword_run
def run(params: Params, progress: bool = False) -> Result:
    """Run every crank speed (and element count) of the deck; see the module docstring."""
    model = _model(params)
    w_bend, w_axial, p_euler = model.frequencies()
    alpha, beta = rayleigh(params.damping_ratio, w_bend, w_axial)
    counts = list(params.element_counts) if params.element_counts else [params.n_elements]
    derived = dict(w_bend=w_bend, w_axial=w_axial, p_euler=p_euler, alpha=alpha, beta=beta,
                   onset=static_onset(model, counts[-1]))
    jobs = [(w, n) for w in params.speeds for n in counts]
    done: dict[tuple[float, int], Case] = {}
    for w, n in tqdm(jobs, desc="slidercrank", unit="case", disable=not progress):
        done[(w, n)] = _run_case(model, params, w, n, alpha, beta, p_euler)
    main_n = counts[-1] if params.element_counts else params.n_elements
    cases = [done[(w, main_n)] for w in params.speeds]

    text = _header(params, model, derived) + [""]
    warnings: list[str] = []
    failure = None
    if params.end_time > 0:
        text += _benchmark_lines(params, cases[0]) + [""]
    else:
        text += _peak_table(cases, params.settle_tolerance) + [""] + _crank_end_table(cases) + [""]
    conv = {w: [done[(w, n)] for n in counts] for w in params.speeds} if params.element_counts else {}
    if conv:
        text += _convergence_table(conv, model.length) + [""]
    for c in cases:
        if c.euler_ratio > EULER_WARN:
            msg = (f"crank speed {c.omega:g} rad/s: peak rod compression {c.peak_compression:.1f} N is "
                   f"{c.euler_ratio:.2f} of the Euler load {p_euler:.1f} N (> {EULER_WARN})")
            if not params.geometric_stiffness:
                msg += "; the linear model cannot show buckling: rerun with geometric_stiffness = .true."
            warnings.append(msg)
    for c in cases:
        if c.ok and _unsettled(c, params.settle_tolerance):
            warnings.append(f"crank speed {c.omega:g} rad/s: the reported revolution has not settled: strain "
                            f"changes {100 * c.settle_strain:.3f} % and midpoint deflection "
                            f"{100 * c.settle_mid:.3f} % of their peaks between the last two revolutions "
                            f"(> {100 * params.settle_tolerance:g} %); run more revolutions")
    onset = derived["onset"]
    for c in done.values():
        if not c.ok:
            if params.geometric_stiffness and c.status in ("buckled", "diverged"):
                warnings.append(f"crank speed {c.omega:g} rad/s, {c.n_elements} elements: "
                                f"{_status_text(c)}")
            else:
                failure = f"crank speed {c.omega:g} rad/s, {c.n_elements} elements: {_status_text(c)}"
                warnings.append(failure)
    le = model.length / max(counts)
    notes = ["Notes"]
    if params.end_time <= 0:
        notes += ["  * Strains: element axial strain (u_e - u_e-1)/le (the paper's 'regangan aksial'); tension",
                  "    positive."] + _peak_notes(cases) + [
                  "  * The paper publishes figures only; validation is against closed forms (quasi-static",
                  "    limit N(s)/EA, natural frequencies) and the Simeon (1996) benchmark (see tests).",
                  "  * Damping is not given in the paper: Rayleigh damping at the first bending and axial modes."]
    else:
        notes += [f"  * Benchmark mode: integrated from t = 0 to end_time with the time step {cases[0].dt:.6g} s.",
                  "  * Midpoint deflection is measured from the chord A-C; elongation is the axial elastic",
                  "    displacement of the slider end of the rod."]
    notes.append(f"  * Time-step criterion: >= {MIN_STEPS_PER_BENDING_PERIOD} steps per period of the first "
                 f"bending mode and >= {MIN_STEPS_PER_REV} per revolution.")
    if le < model.depth:
        notes.append(f"  * Elements ({le * 1e3:.3f} mm) are shorter than the section depth "
                     f"({model.depth * 1e3:g} mm), as in the paper's")
        notes.append("    700-element mesh; Euler-Bernoulli elements are used regardless (shear neglected).")
    notes.append("  * A case stops, and its numbers are not reported, on one of two named triggers: STATIC")
    notes.append("    INSTABILITY when the tangent stiffness K + K_G of the rigid-body axial force loses")
    notes.append("    definiteness (geometric stiffness on only), LIMIT L/20 when the elastic deflection exceeds")
    notes.append("    L/20 (or a rotation 0.25 rad), where the small-motion model is no longer valid.")
    if onset is not None:
        notes.append(f"  * Static buckling onset {onset[0]:.2f} rad/s (Model above): the lowest constant crank speed at")
        notes.append("    which K + K_G loses definiteness at some crank angle; it is a property of the rod, not of")
        notes.append("    the small-motion guard, which can trip earlier through dynamic amplification.")
    if params.geometric_stiffness:
        notes.append("  * Geometric stiffness on: K_G of the rigid-body axial force is part of the model.")
    else:
        notes.append("  * Geometric stiffness off (the paper's linear model, which cannot buckle); N/P_E is reported")
        notes.append("    for every case.")
    text += notes
    if warnings:
        text += ["", "Warnings"] + [f"  * {w}" for w in warnings]
    figures = []
    good = [c for c in cases if c.ok]
    plotting = _plotting   # imported when a figure is drawn (matplotlib is the optional [plot] extra)
    buckled = [f"{c.omega:g} rad/s" for c in cases if not c.ok]
    over = {f"{c.omega:g} rad/s": c.euler_ratio for c in good if c.euler_ratio > 1.0 and not params.geometric_stiffness}
    if good and params.end_time <= 0:
        above = {f"{c.omega:g} rad/s": c.euler_ratio for c in good if c.euler_ratio > 1.0}
        missing = [f"{c.omega:g} rad/s: {_status_text(c).split(' (')[0].lower()}, not drawn" for c in cases if not c.ok]
        stiffness = "K + K_G" if params.geometric_stiffness else "linear model"
        figures.append(Figure("strain", lambda: _plotting().slidercrank_strain_figure(
            [(f"{c.omega:g} rad/s", c.angle_deg, c.eps_ax[0] * 1e6) for c in good],
            f"{params.material}: crank-end element axial strain ({stiffness})", above=above, missing=missing)))
        figures.append(Figure("deflection", lambda: _plotting().slidercrank_strain_figure(
            [(f"{c.omega:g} rad/s", c.angle_deg, c.mid * 1e3) for c in good],
            f"{params.material}: midpoint deflection ({stiffness})", ylabel="midpoint deflection [mm]",
            above=above, missing=missing)))
    if conv:
        series = {f"{w:g} rad/s": ([c.n_elements for c in cs if c.ok], [c.peak(+1)[0] * 1e6 for c in cs if c.ok])
                  for w, cs in conv.items()}
        figures.append(Figure("convergence", lambda: plotting().slidercrank_convergence_figure(
            series, f"{params.material}: element convergence")))
    return Result(text="\n".join(text) + "\n", tidy=_tidy(params.material, list(done.values())),
                  summary=_summary(cases, model if _shape(params)[1] else None), warnings=warnings, failure=failure, figures=figures)


def _plotting():
    """driver.plotting, imported only when a figure is drawn (matplotlib is optional)."""
    from driver import plotting
    return plotting
