"""Slider-crank study: a deck run (every crank speed and element count), the fixed-format .out
sections, the tidy table, the summary and the plotting hook.

Strains are printed in microstrain, angles in degrees, forces in N.
"""
from __future__ import annotations

from typing import Any, Literal, TypedDict

import numpy as np
from tqdm import tqdm

from driver._deck import Params
from driver._mechanism import Guide, Link, MechanismFrames
from driver._result import Figure, Result, Tidy
from driver._table import Cell, Column, render_table
from driver.slidercrank import _kernel as kernel
from driver.slidercrank._analysis import Case, run_case, static_onset
from driver.slidercrank._spec import (
    EULER_WARN,
    MIN_STEPS_PER_BENDING_PERIOD,
    MIN_STEPS_PER_REV,
    SIMEON1996,
    STATUS_TEXT,
    Model,
    model_of,
    rayleigh,
    section_shape,
)


def _f(x: float, d: int = 3) -> str:
    return f"{x:.{d}f}"


class Derived(TypedDict):
    """Constants of the model for the report header: first bending and axial frequencies
    [rad/s], Euler load [N], Rayleigh alpha [1/s] and beta [s], static buckling onset (crank
    speed [rad/s], crank angle [deg]) or None."""

    w_bend: float
    w_axial: float
    p_euler: float
    alpha: float
    beta: float
    onset: tuple[float, float] | None


def header_lines(params: Params, model: Model, derived: Derived) -> list[str]:
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
        ("yield strength", "Pa", f"{model.yield_strength:.4g}   ({model.yield_source})" if model.yield_strength
         else "not known (a custom rod: give yield_strength to check the stresses against it)"),
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


def status_text(c: Case, why: bool = True) -> str:
    if c.ok:
        return "ok"
    what, reason = STATUS_TEXT[c.status]
    text = f"{what} at theta2 = {c.fail_angle_deg:.2f} deg (revolution {c.fail_rev})"
    return f"{text}: {reason}" if why else text


def _unsettled(c: Case, tol: float) -> bool:
    return c.settle_strain is not None and c.settle_mid is not None and max(c.settle_strain, c.settle_mid) > tol


def _settle_text(c: Case) -> str:
    if c.settle_strain is None or c.settle_mid is None:   # set together, for runs of two revolutions or more
        return "-"
    return f"{100 * max(c.settle_strain, c.settle_mid):.3f}"


def _peak_table(cases: list[Case], tol: float) -> list[str]:
    cols = [Column("omega", "f", 7, 2), Column("tensile", "f", 9, 2), Column("theta2", "f", 7, 2),
            Column("el", "i", 4), Column("compress", "f", 9, 2), Column("theta2", "f", 7, 2),
            Column("el", "i", 4), Column("outer", "f", 9, 2), Column("middefl", "f", 8, 4),
            Column("N/P_E", "f", 6, 3), Column("settle%", "s", 8)]
    rows: list[list[Cell]] = []
    trailers: list[str] = []
    for c in cases:
        if c.ok:
            t, ta, te = c.peak(+1)
            p, pa, pe = c.peak(-1)
            rows.append([c.omega, t * 1e6, ta, te, p * 1e6, pa, pe, c.outer_peak() * 1e6,
                         float(np.abs(c.mid).max()) * 1e3, c.euler_ratio, _settle_text(c)])
            notes = (["NOT SETTLED"] if _unsettled(c, tol) else []) + \
                (["warning: N/P_E > 0.8"] if c.euler_ratio > EULER_WARN else [])
            trailers.append("; ".join(notes))
        else:
            rows.append([c.omega, "-", "-", "-", "-", "-", "-", "-", "-", c.euler_ratio, "-"])
            trailers.append(status_text(c, why=False))
    return ["Table 1  Peak axial strain of the rod over the last revolution",
            "         omega [rad/s]; strains in microstrain; theta2 [deg] where the peak occurs; el = element",
            "         (1 = crank end); outer = peak outer-fibre strain |eps| + c|kappa|; middefl = peak |midpoint",
            "         deflection| [mm]; N/P_E = peak rigid-body rod compression / Euler load; settle% = largest",
            "         change of strain or midpoint deflection between the last two revolutions, % of its peak",
            f"         (NOT SETTLED above {100 * tol:g} %: the printed revolution is not yet periodic)", ""] \
        + render_table(cols, rows, trailers)


def peak_stress(model: Model, outer_strain: float) -> float:
    """The rod's peak stress [Pa] from its peak outer-fibre strain |eps| + c |kappa| [-], elastic
    (sigma = E eps): what it would carry if it stayed elastic."""
    return model.modulus * outer_strain


def yield_table(model: Model, rows: list[tuple[str, float, float | None]]) -> list[str]:
    """The .out's check of every model's peak stress against the rod's yield strength: one row per
    (model, crank speed [rad/s], peak outer-fibre stress [Pa] or None where the case failed)."""
    ys = model.yield_strength
    head = ["Table Y  Peak stress against the yield strength",
            "         stress = E x peak outer-fibre strain (|eps| + c|kappa|) [MPa], elastic; "
            + (f"yield strength {ys / 1e6:g} MPa ({model.yield_source})" if ys else
               "yield strength not known (give yield_strength)"),
            "         ratio = stress / yield strength; YIELDS: the rod would yield, and the elastic answer beyond",
            "         that point is not physical", ""]
    cols = [Column("model", "s", 9), Column("omega", "f", 7, 2), Column("stress", "f", 10, 2),
            Column("ratio", "s", 7)]
    table: list[list[Cell]] = []
    trailers: list[str] = []
    for name, w, st in rows:
        if st is None:
            table.append([name, w, "-", "-"])
            trailers.append("no stress (the case failed)")
            continue
        ratio = None if not ys else st / ys
        table.append([name, w, st / 1e6, "-" if ratio is None else f"{ratio:.3f}"])
        trailers.append("" if ratio is None else ("YIELDS" if ratio >= 1.0 else ""))
    return head + render_table(cols, table, trailers)


def yield_warnings(model: Model, rows: list[tuple[str, float, float | None]]) -> list[str]:
    """One warning per (model, speed) whose peak stress reaches the yield strength."""
    ys = model.yield_strength
    if not ys:
        return []
    return [f"{name} model, crank speed {w:g} rad/s: the rod passes yield: its peak outer-fibre stress "
            f"{st / 1e6:.4g} MPa (E x {st / model.modulus * 1e6:.0f} microstrain, if it stayed elastic) exceeds "
            f"the yield strength {ys / 1e6:g} MPa; the elastic answer beyond that point is not physical"
            for name, w, st in rows if st is not None and st >= ys]


def yield_strain(model: Model) -> tuple[float, str] | None:
    """The rod's yield strain sigma_y / E [microstrain] and what its yield strength is, for the
    figures; None without a yield strength."""
    if not model.yield_strength:
        return None
    return model.yield_strength / model.modulus * 1e6, f"{model.yield_strength / 1e6:g} MPa, {model.yield_source}"


def yield_summary(model: Model, stresses: list[float | None], prefix: str = "") -> dict[str, Any]:
    """The summary's stress columns of one model: the peak over the speeds [MPa], its ratio to the
    yield strength and whether it yields (None without a yield strength)."""
    known = [s for s in stresses if s is not None]
    peak = max(known) if known else None
    ys = model.yield_strength
    ratio = None if peak is None or not ys else peak / ys
    return {f"{prefix}peak_stress_MPa": None if peak is None else peak / 1e6,
            f"{prefix}yield_ratio": ratio, f"{prefix}yields": None if ratio is None else bool(ratio >= 1.0)}


def _crank_end_table(cases: list[Case], every_deg: float = 10.0) -> list[str]:
    grid = np.arange(0.0, 360.0 + 1e-9, every_deg)
    cols = [Column("theta2", "f", 7, 1)] + [Column(f"w={c.omega:g}", "f", 9, 2) for c in cases]
    series = []
    for c in cases:
        if c.ok:
            series.append(np.interp(grid, c.angle_deg, c.eps_1) * 1e6)
        else:
            series.append(None)
    rows = [[g] + [("-" if s is None else float(s[k])) for s in series] for k, g in enumerate(grid)]
    lines = ["Table 2  Axial strain of the crank-end element vs crank angle, last revolution (microstrain)",
             "         (one column per crank speed [rad/s], like the paper's Figure 10)", ""]
    lines += render_table(cols, rows)
    bad = [c for c in cases if not c.ok]
    for c in bad:
        lines.append(f"  w={c.omega:g}: {status_text(c, why=False)}; no strains reported")
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

    def change(new: float, old: float | None) -> Cell:
        return "-" if old is None else 100 * (new - old) / old

    for omega, cases in conv.items():
        rows: list[list[Cell]] = []
        trailers: list[str] = []
        prev: tuple[float, ...] | None = None
        for c in cases:
            le = 1e3 * length / c.n_elements
            if not c.ok:
                rows.append([c.n_elements, le] + ["-"] * 8)
                trailers.append(status_text(c, why=False))
                prev = None
                continue
            vals = (c.peak(+1)[0] * 1e6, c.peak(-1)[0] * 1e6, c.crank_end_peak(+1) * 1e6, c.crank_end_peak(-1) * 1e6)
            old: tuple[float | None, ...] = prev or (None,) * 4
            rows.append([c.n_elements, le] + [x for v, o in zip(vals, old) for x in (v, change(v, o))])
            trailers.append("")
            prev = vals
        lines += ["", f"  crank speed {omega:g} rad/s", ""] + render_table(cols, rows, trailers)
    lines += ["", "  Why the element strain needs many elements: the rigid-body axial force falls along the rod",
              "  (inertia of the rod itself), and an element strain is its average over the element, so the",
              "  crank-end element converges to the pin value only as 1/n (the paper's 700 elements). The",
              "  recovered pin strain removes that averaging error and is converged with a few elements."]
    return lines


def _tidy(model_name: str, cases: list[Case]) -> Tidy:
    frames: list[dict[str, Any]] = []
    for c in cases:
        if not c.ok:
            continue
        frames.append({
            "material": model_name, "omega_rad_s": c.omega, "n_elements": c.n_elements,
            "crank_angle_deg": c.angle_deg, "time_s": c.time,
            "eps_crank_end_microstrain": c.eps_1 * 1e6,
            "eps_max_microstrain": c.eps_max * 1e6,
            "eps_min_microstrain": c.eps_min * 1e6,
            "outer_fibre_max_microstrain": c.outer_max * 1e6,
            "n_rigid_crank_end_N": c.n_avg_1,
            "midpoint_deflection_mm": c.mid * 1e3,
            "slider_position_m": c.slider,
            "rod_elongation_um": c.elong * 1e6,
        })
    if not frames:
        return Tidy(records=[], columns=["material", "omega_rad_s", "n_elements", "crank_angle_deg"],
                    units={"n_elements": "1"})
    return Tidy(*frames, units={"n_elements": "1"})


def _summary(cases: list[Case], model: Model, section: bool = False) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for i, c in enumerate(cases, start=1):
        out[f"omega_{i}_rad_s"] = c.omega
        out[f"euler_ratio_{i}"] = c.euler_ratio
        out[f"buckled_{i}"] = not c.ok
        if c.ok:
            t, ta, _ = c.peak(+1)
            p, pa, _ = c.peak(-1)
            out.update({f"peak_tensile_{i}_microstrain": t * 1e6, f"peak_tensile_{i}_deg": ta,
                        f"peak_compressive_{i}_microstrain": p * 1e6, f"peak_compressive_{i}_deg": pa,
                        f"peak_stress_{i}_MPa": peak_stress(model, c.outer_peak()) / 1e6})
    good = [c for c in cases if c.ok]
    if good:
        best = max(good, key=lambda c: c.peak(+1)[0])
        worst = min(good, key=lambda c: c.peak(-1)[0])
        out.update({"peak_tensile_microstrain": best.peak(+1)[0] * 1e6, "peak_tensile_deg": best.peak(+1)[1],
                    "peak_compressive_microstrain": worst.peak(-1)[0] * 1e6,
                    "peak_compressive_deg": worst.peak(-1)[1]})
    out["euler_ratio_max"] = max(c.euler_ratio for c in cases)
    out["yield_strength_MPa"] = None if not model.yield_strength else model.yield_strength / 1e6
    out.update(yield_summary(model, [peak_stress(model, c.outer_peak()) if c.ok else None for c in cases]))
    if section:   # a section given by its shape (what a section optimisation varies)
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
        return lines + [f"  {status_text(case)}"]
    kin = kernel.slidercrank_rigid(np.array([case.omega * case.time[-1]]), case.omega,
                                    params.crank_radius, params.rod_length)[0]
    vals: list[tuple[str, str, float, Literal["q1", "q4", "x3", "phi2"]]] = [
            ("midpoint deflection from the chord (q1)", "m", float(case.mid[-1]), "q1"),
            ("rod elongation (q4)", "m", float(case.elong[-1]), "q4"),
            ("slider position (x3)", "m", float(case.slider[-1]), "x3"),
            ("rod angle, rigid (phi2)", "rad", float(kin[0]), "phi2")]
    cols = [Column("quantity", "s", 40), Column("unit", "s", 4), Column("this model", "s", 16)]
    if params.benchmark == "simeon1996":
        cols += [Column("Simeon 1996", "s", 16), Column("diff %", "f", 8, 3)]
    rows = []
    for name, unit, v, ref in vals:
        row: list[Cell] = [name, unit, f"{v:.9e}"]
        if params.benchmark == "simeon1996":
            r = SIMEON1996[ref]
            row += [f"{r:.9e}", 100 * (v - r) / abs(r)]
        rows.append(row)
    lines += render_table(cols, rows)
    if params.benchmark == "simeon1996":
        lines += ["", "  Reference: Simeon (1996), IVP test set 'crank' (MEBDFI, tol 1e-14): 2 lateral sine modes,",
                  "  quadratic axial field, full rigid-elastic coupling; this model is linear KED (eq. 23)."]
    return lines


def figures_module():
    """The study's figure module, imported when a figure is drawn (matplotlib is the optional [plot] extra)."""
    from driver.slidercrank import _figures as figures
    return figures


def run_linear(params: Params, progress: bool = False) -> Result:
    """Run every crank speed (and element count) of a linear-model deck (``model = 'linear'``):
    the paper's KED model; see the package docstring."""
    model = model_of(params)
    w_bend, w_axial, p_euler = model.frequencies()
    alpha, beta = rayleigh(params.damping_ratio, w_bend, w_axial)
    counts = list(params.element_counts) if params.element_counts else [params.n_elements]
    derived = Derived(w_bend=w_bend, w_axial=w_axial, p_euler=p_euler, alpha=alpha, beta=beta,
                   onset=static_onset(model, counts[-1]))
    jobs = [(w, n) for w in params.speeds for n in counts]
    done: dict[tuple[float, int], Case] = {}
    for w, n in tqdm(jobs, desc="slidercrank", unit="case", disable=not progress):
        done[(w, n)] = run_case(model, params, w, n, alpha, beta, p_euler)
    main_n = counts[-1] if params.element_counts else params.n_elements
    cases = [done[(w, main_n)] for w in params.speeds]

    text = header_lines(params, model, derived) + [""]
    warnings: list[str] = []
    failure = None
    if params.end_time > 0:
        text += _benchmark_lines(params, cases[0]) + [""]
    else:
        text += _peak_table(cases, params.settle_tolerance) + [""] + _crank_end_table(cases) + [""]
    conv = {w: [done[(w, n)] for n in counts] for w in params.speeds} if params.element_counts else {}
    if conv:
        text += _convergence_table(conv, model.length) + [""]
    stress_rows = [("linear", c.omega, peak_stress(model, c.outer_peak()) if c.ok else None) for c in cases]
    if params.end_time <= 0:
        text += yield_table(model, stress_rows) + [""]
        warnings += yield_warnings(model, stress_rows)
    for c in cases:
        if c.euler_ratio > EULER_WARN:
            msg = (f"crank speed {c.omega:g} rad/s: peak rod compression {c.peak_compression:.1f} N is "
                   f"{c.euler_ratio:.2f} of the Euler load {p_euler:.1f} N (> {EULER_WARN})")
            if not params.geometric_stiffness:
                msg += "; the linear model cannot show buckling: rerun with geometric_stiffness = .true."
            warnings.append(msg)
    for c in cases:
        if c.ok and _unsettled(c, params.settle_tolerance) and c.settle_strain is not None and c.settle_mid is not None:
            warnings.append(f"crank speed {c.omega:g} rad/s: the reported revolution has not settled: strain "
                            f"changes {100 * c.settle_strain:.3f} % and midpoint deflection "
                            f"{100 * c.settle_mid:.3f} % of their peaks between the last two revolutions "
                            f"(> {100 * params.settle_tolerance:g} %); run more revolutions")
    onset = derived["onset"]
    for c in done.values():
        if not c.ok:
            if params.geometric_stiffness and c.status in ("buckled", "diverged"):
                warnings.append(f"crank speed {c.omega:g} rad/s, {c.n_elements} elements: "
                                f"{status_text(c)}")
            else:
                failure = f"crank speed {c.omega:g} rad/s, {c.n_elements} elements: {status_text(c)}"
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
    if good and params.end_time <= 0:
        above = {f"{c.omega:g} rad/s": c.euler_ratio for c in good if c.euler_ratio > 1.0}
        missing = [f"{c.omega:g} rad/s: {status_text(c).split(' (')[0].lower()}, not drawn" for c in cases if not c.ok]
        stiffness = "K + K_G" if params.geometric_stiffness else "linear model"
        figures.append(Figure("strain", lambda: figures_module().slidercrank_strain_figure(
            [(f"{c.omega:g} rad/s", c.angle_deg, c.eps_1 * 1e6) for c in good],
            f"{params.material}: crank-end element axial strain ({stiffness})", above=above, missing=missing,
            yield_strain=yield_strain(model))))
        figures.append(Figure("deflection", lambda: figures_module().slidercrank_strain_figure(
            [(f"{c.omega:g} rad/s", c.angle_deg, c.mid * 1e3) for c in good],
            f"{params.material}: midpoint deflection ({stiffness})", ylabel="midpoint deflection [mm]",
            above=above, missing=missing)))
    if params.end_time > 0 and cases[0].ok:   # a benchmark run: its time history against the reference
        c0 = cases[0]
        ref = SIMEON1996 if params.benchmark == "simeon1996" else None
        figures.append(Figure("history", lambda: figures_module().history_figure(model, params, c0, alpha, beta, ref)))
    if conv:
        series = {f"{w:g} rad/s": ([c.n_elements for c in cs if c.ok], [c.peak(+1)[0] * 1e6 for c in cs if c.ok],
                                   [c.crank_end_peak(+1) * 1e6 for c in cs if c.ok])
                  for w, cs in conv.items()}
        speeds = ", ".join(series)
        figures.append(Figure("convergence", lambda: figures_module().slidercrank_convergence_figure(
            series, f"{params.material} rod at {speeds}: convergence of the peak tensile strain with the mesh")))
    return Result(text="\n".join(text) + "\n", tidy=_tidy(params.material, list(done.values())),
                  summary=_summary(cases, model, bool(section_shape(params)[1])), warnings=warnings, failure=failure,
                  figures=figures)


#: interior nodes of the rod drawn in the report page's animation when its deflection is known
ROD_NODES = 7


def animation_frames(params: Params, result: Result | None = None, n: int = 180) -> MechanismFrames:
    """The mechanism's positions at ``n`` crank angles over one turn, for the report page's animation
    (:class:`driver._mechanism.MechanismFrames`): crank pivot O, crank pin A and slider pin B from
    the kernel's rigid kinematics, the slider block on its guide and, with ``result``, the elastic
    rod bowed by its midpoint deflection (magnified; drawn as the parabola through it, at
    :data:`ROD_NODES` interior nodes)."""
    model = model_of(params)
    r, length = float(model.r2), float(model.length)
    theta = np.linspace(0.0, 360.0, n, endpoint=False)
    states = kernel.slidercrank_rigid(np.radians(theta), 1.0, r, length)
    a = np.column_stack([r * np.cos(np.radians(theta)), r * np.sin(np.radians(theta))])
    b = np.column_stack([states[:, 3], np.zeros_like(theta)])
    w, h = 0.5 * r, 0.25 * r   # the slider block
    corners = np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]])
    nodes, note = _rod_nodes(result, theta, length)
    if nodes is None:
        bow, note = _rod_bow(result, theta, length)
        if bow is not None:   # the rod's nodes on the parabola through the magnified midpoint deflection
            t = np.arange(1, ROD_NODES + 1) / (ROD_NODES + 1)
            nodes = (t, (4.0 * t * (1.0 - t))[:, None] * np.asarray(bow)[None, :])
    names = ["O", "A", "B", "K1", "K2", "K3", "K4"]
    parts = [np.zeros_like(a), a, b, *(b + c for c in corners)]
    rod: tuple[int, ...] = (1, 2)
    if nodes is not None:   # the rod through its interior nodes, each off the chord by its (magnified) deflection
        chord = b - a
        normal = np.column_stack([-chord[:, 1], chord[:, 0]]) / np.hypot(chord[:, 0], chord[:, 1])[:, None]
        where, lateral = nodes
        for j, (frac, off) in enumerate(zip(where, lateral), start=1):
            names.append(f"R{j}")
            parts.append(a + frac * chord + off[:, None] * normal)
        rod = (1, *range(7, 7 + len(where)), 2)
    x0, x1 = float(b[:, 0].min()) - w, float(b[:, 0].max()) + w
    caption = "The slider-crank over one crank turn, rigid positions from the kernel"
    return MechanismFrames(
        names=tuple(names), points=np.stack(parts, axis=1),
        links=(Link("crank", (0, 1)), Link("connecting rod", rod), Link("slider", (3, 4, 5, 6), body=True)),
        labels=tuple(f"{t:.0f}\u00b0" for t in theta), ground=(0,), joints=(1, 2), paths=(1,), frame_name="crank angle",
        guides=(Guide(np.array([[x0, -h / 2], [x1, -h / 2]]), "slider guide"),),
        units="m", caption=caption + ("; " + note if note else "") + ".")


#: interior nodes of the nonlinear rod drawn at most (every k-th node of the mesh)
MAX_ROD_NODES = 31


def _rod_nodes(result: Result | None, theta: np.ndarray, length: float) -> tuple[tuple[np.ndarray, np.ndarray] | None, str]:
    """The nonlinear rod's interior nodes at the animation's crank angles ``theta`` [deg], from
    the run's node deflections (``result.data['rod']``, the fastest speed that finished):
    (positions along the rod as fractions of its length, (nodes, frames) lateral deflection [m],
    magnified so the largest is 6 % of the rod, or at true scale when it is larger), and the
    words saying so; (None, '') for a run without them."""
    rod = getattr(result, "data", {}).get("rod") if result is not None else None
    if not rod:
        return None, ""
    lat = np.asarray(rod["lateral_m"], dtype=float)
    ang = np.asarray(rod["angle_deg"], dtype=float)
    n_el = lat.shape[0] - 1
    if n_el < 2 or lat.shape[1] < 2 or not np.isfinite(lat).all():
        return None, ""
    keep = np.unique(np.round(np.linspace(0, n_el, min(n_el, MAX_ROD_NODES + 1) + 1)).astype(int))[1:-1]
    peak = float(np.max(np.abs(lat)))
    scale = max(1.0, 0.06 * length / peak) if peak > 0 else 1.0
    at = np.mod(ang, 360.0)
    lateral = np.array([np.interp(theta, at, lat[i], period=360.0) for i in keep]) * scale
    size = "drawn at true scale" if scale == 1.0 else f"magnified {scale:.3g} times"
    words = (f"the rod through {len(keep)} of its {n_el - 1} interior nodes as the nonlinear run left them at "
             f"{rod['omega_rad_s']:g} rad/s ({size}; largest lateral deflection {peak * 1e3:.3g} mm)")
    return (keep / n_el, lateral), words


def _rod_bow(result: Result | None, theta: np.ndarray, length: float) -> tuple[np.ndarray | None, str]:
    """The elastic rod's midpoint deflection [m] at the animation's crank angles, magnified so
    its largest is 6 % of the rod (from the run's tidy table: the fastest crank speed that ran),
    and the words saying so; (None, '') without one."""
    tidy = getattr(result, "tidy", None)
    if tidy is None or "midpoint_deflection_mm" not in tidy or not len(tidy):
        return None, ""
    w = float(tidy["omega_rad_s"].max())
    rows = tidy[tidy["omega_rad_s"] == w]
    ang = np.mod(rows["crank_angle_deg"].to_numpy(dtype=float), 360.0)
    mid = rows["midpoint_deflection_mm"].to_numpy(dtype=float) * 1e-3
    order = np.argsort(ang)
    ang, mid = ang[order], mid[order]
    peak = float(np.max(np.abs(mid)))
    if not np.isfinite(peak) or peak <= 0:
        return None, ""
    scale = 0.06 * length / peak
    bow = np.interp(theta, ang, mid, period=360.0) * scale
    return bow, (f"rod deflection magnified {scale:.3g} times "
                 f"(midpoint deflection at {w:g} rad/s, largest {peak * 1e3:.3g} mm)")
