"""Slider-crank: a deck's run (:func:`run`: the linear model, or with ``model = 'nonlinear'`` both).
The nonlinear run takes every speed in both models and writes the .out
sections (linear and nonlinear side by side, per-revolution deflection, Newton statistics,
onset search), the tidy table, the summary and the figures.

Strains printed in microstrain, deflections in mm, angles in degrees.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from tqdm import tqdm

from driver._deck import Params
from driver._result import Figure, Result, Tidy
from driver._runner import study_run
from driver._table import Cell, Column, render_table
from driver.slidercrank._analysis import Case, run_case, static_onset
from driver.slidercrank._analysis_nl import IRREGULAR, NLCase, onset_search, run_nl_case
from driver.slidercrank._kernel import NonlinearStatus
from driver.slidercrank._report import (
    Derived,
    figures_module,
    header_lines,
    peak_stress,
    run_linear,
    status_text,
    yield_strain,
    yield_summary,
    yield_table,
    yield_warnings,
)
from driver.slidercrank._spec import SPEC, Model, model_of, rayleigh


def nl_status_text(c: NLCase) -> str:
    status = NonlinearStatus[c.status]   # the kernel's status table: its words
    what, why = status.what, status.why
    where = f"at step {c.fail_step} (theta2 = {c.fail_angle_deg:.2f} deg, revolution {c.fail_rev})"
    if c.status == "no_convergence":
        where += f" after {c.fail_iter} Newton solves and {c.deepest_cut} step halvings"
    return f"{what} {where}: {why}"


def verdict(c: NLCase, tol: float, limit: float) -> str:
    if c.collapsed:
        return "COLLAPSE"
    if not c.ok:
        return "FAILED"
    if c.grows(tol):
        return "GROWS"
    kind = "irregular" if c.scatter > IRREGULAR else "bounded"
    return f"BUCKLED, {kind}" if c.buckled(tol, limit) else kind


def _side_by_side(pairs: list[tuple[Case, NLCase]], tol: float, limit: float) -> list[str]:
    cols = [Column("omega", "f", 7, 2), Column("lin tens", "f", 9, 2), Column("nl tens", "f", 9, 2),
            Column("lin comp", "f", 9, 2), Column("nl comp", "f", 9, 2), Column("lin outer", "f", 9, 1),
            Column("nl outer", "f", 9, 1), Column("lin lat", "f", 8, 3), Column("nl lat", "f", 8, 3),
            Column("N/P_E", "f", 6, 3), Column("growth%", "f", 8, 2), Column("spread%", "f", 8, 1)]
    rows: list[list[Cell]] = []
    trailers: list[str] = []
    for lin, nl in pairs:
        row: list[Any] = [nl.omega]
        lin_vals = ([lin.peak(+1)[0] * 1e6, lin.peak(-1)[0] * 1e6, lin.outer_peak() * 1e6,
                     float(np.abs(lin.mid).max()) * 1e3] if lin.ok else ["-"] * 4)
        nl_vals = ([nl.peak(+1)[0] * 1e6, nl.peak(-1)[0] * 1e6, float(nl.eps_of.max()) * 1e6,
                    nl.peak_lateral * 1e3] if nl.ok else ["-"] * 4)
        for a, b in zip(lin_vals, nl_vals):
            row += [a, b]
        row += [lin.euler_ratio, 100 * nl.growth if nl.ok else "-", 100 * nl.scatter if nl.ok else "-"]
        rows.append(row)
        trailers.append(verdict(nl, tol, limit))
    head = ["Table 5  Linear (the paper's KED model) and geometrically nonlinear rod, last revolution",
            "         omega [rad/s]; tens/comp = peak tensile/compressive axial strain, outer = peak outer-fibre",
            "         strain |eps| + c|kappa| (microstrain); lat = peak lateral deflection [mm] (linear: midpoint",
            "         from the chord; nonlinear: largest over the rod); N/P_E = peak rigid-body compression / Euler",
            "         load; growth% = mean growth per revolution of the per-revolution peak lateral deflection",
            f"         (Table 6; medians of the last revolutions against those before; GROWS above {100 * tol:g} %);",
            "         spread% = max/min - 1 of those peaks (irregular above "
            f"{100 * IRREGULAR:g} %); BUCKLED = lateral deflection above {1e3 * limit:.1f} mm", ""]
    return head + render_table(cols, rows, trailers)


def _per_revolution(cases: list[NLCase]) -> list[str]:
    nrev = max(len(c.rev_lat) for c in cases)
    cols = [Column("omega", "f", 7, 2)] + [Column(f"rev {k + 1}", "f", 8, 3) for k in range(nrev)]
    rows: list[list[Cell]] = []
    trailers: list[str] = []
    for c in cases:
        done = min(nrev, max(c.steps_done - 1, 0) // c.steps_per_rev + 1) if c.steps_done else 0
        rows.append([c.omega] + [float(c.rev_lat[k]) * 1e3 if k < done else "-" for k in range(nrev)])
        trailers.append("" if c.ok else NonlinearStatus[c.status].what)
    return ["Table 6  Peak lateral deflection of the nonlinear rod in each revolution [mm]", ""] + \
        render_table(cols, rows, trailers)


def _newton_table(cases: list[NLCase], params: Params) -> list[str]:
    cols = [Column("omega", "f", 7, 2), Column("steps", "i", 7), Column("solves", "i", 8),
            Column("per step", "f", 8, 3), Column("max", "i", 4), Column("cuts", "i", 5), Column("deepest", "i", 7)]
    rows: list[list[Cell]] = []
    trailers: list[str] = []
    for c in cases:
        rows.append([c.omega, c.steps_done, c.solves, c.solves / max(c.steps_done, 1), c.max_solves, c.cuts,
                     c.deepest_cut])
        trailers.append("" if c.ok else nl_status_text(c))
    return ["Table 7  Newton iterations and step control of the nonlinear runs",
            "         solves = Newton solves in all; max = most in one step; cuts = time steps halved",
            f"         (deepest = most halvings of one step, of {params.max_step_cuts} allowed); tolerance "
            f"{params.newton_tolerance:g} (relative residual)", ""] + render_table(cols, rows, trailers)


def _strain_curves(pairs: list[tuple[Case, NLCase]], every_deg: float = 30.0) -> list[str]:
    grid = np.arange(0.0, 360.0 + 1e-9, every_deg)
    cols = [Column("theta2", "f", 7, 1)]
    series = []
    for lin, nl in pairs:
        cols += [Column(f"L{lin.omega:g}", "f", 9, 2), Column(f"N{nl.omega:g}", "f", 9, 2)]
        series += [np.interp(grid, lin.angle_deg, lin.eps_1) * 1e6 if lin.ok else None,
                   np.interp(grid, nl.angle_deg, nl.eps_ax[0]) * 1e6 if nl.ok else None]
    rows = [[g] + ["-" if s is None else float(s[k]) for s in series] for k, g in enumerate(grid)]
    return ["Table 8  Axial strain of the crank-end element vs crank angle, last revolution (microstrain):",
            "         L<omega> linear model, N<omega> nonlinear rod", ""] + render_table(cols, rows)


def _onset_lines(onset: dict[str, tuple[float, float] | None], params: Params, static: tuple[float, float] | None,
                 limit: float) -> list[str]:
    grid = ", ".join(f"{w:g}" for w in sorted(set(params.onset_speeds)))
    lines = [f"Table 9  Dynamic-buckling onset of the nonlinear rod ({params.onset_elements} elements, "
             f"{params.revolutions} revolutions per speed,", f"         grid {grid} rad/s, bisected to 0.05 rad/s)", ""]
    st = "none below 1e6 rad/s" if static is None else f"{static[0]:.2f} rad/s"
    lines.append(f"  linear model with K_G: static buckling onset (K + K_G singular)   {st}")
    for what, text in (("buckled", f"nonlinear: lateral deflection first above {1e3 * limit:.1f} mm"),
                       ("grows", "nonlinear: response first grows from revolution to revolution")):
        br = onset[what]
        if br is None:
            val = f"not on the grid (up to {max(params.onset_speeds):g} rad/s)"
        elif br[0] == 0.0:
            val = f"already at the lowest grid speed {br[1]:g} rad/s"
        else:
            val = f"between {br[0]:.2f} and {br[1]:.2f} rad/s"
        lines.append(f"  {text:<66} {val}")
    return lines


def _tidy(material: str, pairs: list[tuple[Case, NLCase]]) -> Tidy:
    frames: list[dict[str, Any]] = []
    for lin, nl in pairs:
        if not nl.ok:
            continue
        frame: dict[str, Any] = {
            "material": material, "omega_rad_s": nl.omega, "n_elements": nl.n_elements,
            "crank_angle_deg": nl.angle_deg,
            "eps_crank_end_nonlinear_microstrain": nl.eps_ax[0] * 1e6,
            "eps_max_nonlinear_microstrain": nl.eps_ax.max(axis=0) * 1e6,
            "eps_min_nonlinear_microstrain": nl.eps_ax.min(axis=0) * 1e6,
            "outer_fibre_max_nonlinear_microstrain": nl.eps_of.max(axis=0) * 1e6,
            "lateral_max_nonlinear_mm": nl.lat_max * 1e3,
            "midspan_nonlinear_mm": nl.mid * 1e3}
        if lin.ok and len(lin.angle_deg) == len(nl.angle_deg):
            frame["eps_crank_end_linear_microstrain"] = lin.eps_1 * 1e6
            frame["midpoint_linear_mm"] = lin.mid * 1e3
        frames.append(frame)
    if not frames:
        return Tidy(records=[], columns=["material", "omega_rad_s", "n_elements", "crank_angle_deg"],
                    units={"n_elements": "1"})
    return Tidy(*frames, units={"n_elements": "1"})


def _buckled_words(nl: NLCase, tol: float, limit: float) -> str:
    """Why the nonlinear rod counts as buckled at this speed, in a few words for a figure."""
    if nl.grows(tol):
        return f"grows {100 * nl.growth:.0f} % per revolution"
    return f"lateral deflection {nl.peak_lateral * 1e3:.3g} mm > {limit * 1e3:.3g} mm"


def _summary(pairs: list[tuple[Case, NLCase]], tol: float, limit: float,
             onset: dict[str, tuple[float, float] | None] | None, model: Model) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for i, (lin, nl) in enumerate(pairs, start=1):
        out[f"omega_{i}_rad_s"] = nl.omega
        out[f"euler_ratio_{i}"] = lin.euler_ratio
        if nl.ok:
            out[f"nl_peak_tensile_{i}_microstrain"] = nl.peak(+1)[0] * 1e6
            out[f"nl_peak_compressive_{i}_microstrain"] = nl.peak(-1)[0] * 1e6
            out[f"nl_peak_lateral_{i}_mm"] = nl.peak_lateral * 1e3
            out[f"nl_growth_{i}"] = nl.growth
        out[f"nl_buckled_{i}"] = nl.buckled(tol, limit)
    out["euler_ratio_max"] = max(lin.euler_ratio for lin, _ in pairs)
    good = [nl for _, nl in pairs if nl.ok]
    if good:
        out["nl_peak_lateral_mm"] = max(c.peak_lateral for c in good) * 1e3
        out["nl_peak_outer_microstrain"] = max(float(c.eps_of.max()) for c in good) * 1e6
    out["n_buckled"] = sum(nl.buckled(tol, limit) for _, nl in pairs)
    out["buckled"] = out["n_buckled"] > 0
    out["yield_strength_MPa"] = None if not model.yield_strength else model.yield_strength / 1e6
    rows = _stress_rows(model, pairs)
    out.update(yield_summary(model, [s for m, _, s in rows if m == "linear"]))
    out.update(yield_summary(model, [s for m, _, s in rows if m == "nonlinear"], "nl_"))
    if onset:
        for what, br in onset.items():
            if br is not None:
                out[f"onset_{what}_rad_s"] = br[1]
    return out


def run_nonlinear(params: Params, progress: bool = False) -> Result:
    """Every crank speed of the deck in the linear and the nonlinear model; the onset search when
    the deck gives onset_speeds."""
    model = model_of(params)
    w_bend, w_axial, p_euler = model.frequencies()
    alpha, beta = rayleigh(params.damping_ratio, w_bend, w_axial)
    n = params.n_elements
    static = static_onset(model, n)
    derived = Derived(w_bend=w_bend, w_axial=w_axial, p_euler=p_euler, alpha=alpha, beta=beta, onset=static)
    tol, limit = params.growth_tolerance, params.large_deflection * model.length
    pairs: list[tuple[Case, NLCase]] = []
    for w in tqdm(params.speeds, desc="slidercrank nonlinear", unit="speed", disable=not progress):
        pairs.append((run_case(model, params, w, n, alpha, beta, p_euler),
                      run_nl_case(model, params, w, n, alpha, beta)))
    onset = onset_search(model, params, alpha, beta) if params.onset_speeds else None
    nls = [nl for _, nl in pairs]

    text = header_lines(params, model, derived)
    text += ["  nonlinear rod: co-rotational Euler-Bernoulli frame elements (same mesh, masses, damping and",
             "  inertia loading); Newmark average acceleration with Newton iterations on the consistent",
             "  tangent (the damping's included), a step halved when Newton fails; banded LU solves",
             "  (fortran/slidercrank_nl.f90)",
             f"  time integration: HHT-alpha, alpha = {params.hht_alpha:g}"
             + (" (Newmark average acceleration)" if params.hht_alpha == 0 else
                " (damps the unresolved high frequencies; 0 = Newmark average acceleration)"),
             f"  growth tolerance {tol:g} per revolution (medians of the last revolutions); buckled",
             f"  above {params.large_deflection:g} L lateral deflection", ""]
    text += _side_by_side(pairs, tol, limit) + [""] + _per_revolution(nls) + [""] + _newton_table(nls, params) + \
        [""] + _strain_curves(pairs) + [""]
    if onset is not None:
        text += _onset_lines(onset, params, static, limit) + [""]
    rows = _stress_rows(model, pairs)
    text += yield_table(model, rows) + [""]
    warnings: list[str] = yield_warnings(model, rows)
    failure = None
    for lin, nl in pairs:
        if nl.status in ("no_convergence", "not_spd"):
            failure = f"crank speed {nl.omega:g} rad/s, {nl.n_elements} elements, nonlinear: {nl_status_text(nl)}"
            warnings.append(failure)
        elif nl.collapsed:
            warnings.append(f"crank speed {nl.omega:g} rad/s: {nl_status_text(nl)}")
        if not lin.ok:
            warnings.append(f"crank speed {lin.omega:g} rad/s, linear model: {status_text(lin)}")
        if nl.cuts:
            warnings.append(f"crank speed {nl.omega:g} rad/s: {nl.cuts} time step(s) halved for Newton convergence "
                            f"(deepest {nl.deepest_cut} halvings)")
    text += ["Notes",
             "  * Both models share the mesh, masses, damping, inertia loading and time step; the nonlinear rod",
             "    follows large lateral deflections (axial strain from the element chord, geometric stiffness",
             "    from the actual axial force), which the linear model cannot.",
             "  * Growth: per-revolution peaks of Table 6; a bounded response may still be buckled (a large",
             "    lateral deflection every revolution that the tension half of the turn straightens again).",
             "  * The answer for the paper's rods, with numbers: docs/slidercrank.md, 'Does the rod buckle?'."]
    irregular = [f"{nl.omega:g}" for nl in nls if nl.ok and nl.scatter > IRREGULAR]
    if irregular:
        text += [f"  * Irregular ({', '.join(irregular)} rad/s): the buckled rod's motion does not repeat from one",
                 "    revolution to the next, so its last revolution is one sample of a range (Table 6), and anything",
                 "    that perturbs the motion (Newton tolerance, time step, mesh) changes its numbers within that",
                 "    range: read them as magnitudes, not to their last digit."]
    if warnings:
        text += ["", "Warnings"] + [f"  * {w}" for w in warnings]
    figures = []
    good = [(lin, nl) for lin, nl in pairs if nl.ok and lin.ok]
    if good:
        buckled = {f"{nl.omega:g} rad/s": _buckled_words(nl, tol, limit) for _, nl in good if nl.buckled(tol, limit)}
        figures.append(Figure("strain_linear_nonlinear", lambda: figures_module().slidercrank_nl_strain_figure(
            [(f"{nl.omega:g} rad/s", lin.angle_deg, lin.eps_1 * 1e6, nl.eps_ax[0] * 1e6) for lin, nl in good],
            f"{params.material}: crank-end axial strain, linear model and nonlinear rod, per crank speed",
            buckled=buckled, yield_strain=yield_strain(model))))
    okn = [nl for nl in nls if nl.ok]
    if okn:
        figures.append(Figure("shapes", lambda: figures_module().slidercrank_nl_shapes_figure(
            [(f"{c.omega:g} rad/s", c.shape_deg, c.shapes) for c in okn], model.length,
            f"{params.material}: lateral deflection at the worst crank angles")))
    figures.append(Figure("lateral_per_revolution", lambda: figures_module().slidercrank_nl_revolutions_figure(
        [(f"{c.omega:g} rad/s", c.rev_lat[:max(c.steps_done - 1, 0) // c.steps_per_rev + 1] * 1e3)
         for c in nls if c.steps_done], f"{params.material}: peak lateral deflection per revolution")))
    return Result(text="\n".join(text) + "\n", tidy=_tidy(params.material, pairs),
                  summary=_summary(pairs, tol, limit, onset, model), warnings=warnings, failure=failure,
                  figures=figures, data=_rod_data(okn))


def _rod_data(okn: list[NLCase]) -> dict[str, Any]:
    """The deflected rod the report page animates: the fastest speed whose nonlinear run
    finished, its nodes' lateral deflection [m] over the recorded revolution (``lateral``:
    (nodes, frames) at crank angles ``angle_deg``)."""
    if not okn:
        return {}
    c = max(okn, key=lambda nl: nl.omega)
    if not c.frames.size:
        return {}
    return {"rod": {"omega_rad_s": c.omega, "n_elements": c.n_elements, "angle_deg": np.asarray(c.frame_deg),
                    "lateral_m": np.asarray(c.frames)}}


def _stress_rows(model: Model, pairs: list[tuple[Case, NLCase]]) -> list[tuple[str, float, float | None]]:
    """(model, crank speed [rad/s], peak outer-fibre stress E eps [Pa] or None) of both models at
    every speed, for the yield check."""
    rows: list[tuple[str, float, float | None]] = []
    for lin, nl in pairs:
        rows.append(("linear", lin.omega, peak_stress(model, lin.outer_peak()) if lin.ok else None))
        rows.append(("nonlinear", nl.omega, peak_stress(model, float(nl.eps_of.max())) if nl.ok else None))
    return rows


@study_run(SPEC)
def run(params: Params, progress: bool = False) -> Result:
    """Simulate a slider-crank with an elastic connecting rod at one or more crank speeds.

    The paper's linear kineto-elastodynamic finite-element model integrated with Newmark's rule
    (:func:`run_linear`), or with ``model = 'nonlinear'`` the co-rotational rod beside it
    (:func:`run_nonlinear`): peak axial strain per crank speed, the crank-end strain against
    crank angle, the Euler-load ratio and, with geometric stiffness, buckling.  SI units (m,
    kg, Pa, rad/s, s); strains are reported in microstrain.
    """
    if params.model == "nonlinear":
        return run_nonlinear(params, progress)
    return run_linear(params, progress)
