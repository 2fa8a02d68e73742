"""Slider-crank with an elastic connecting rod [Andalas]: the &slidercrank study.

Rigid crank, elastic rod meshed with frame elements, slider on its guide; kineto-elastodynamic
(KED) finite-element model integrated with Newmark's average-acceleration rule.  The physics
(kinematics, rigid-body axial force, element matrices, banded Cholesky, the whole time loop)
lives in ``fortran/slidercrank.f90``; this module validates the deck, runs the cases, and
writes the paper's results: peak axial strain per crank speed, strain of the crank-end
element against crank angle (Figure 10), the element-convergence study (Figures 8-9), the
Euler-load ratio of every case and, with geometric stiffness, buckling.

Units in decks: SI (m, kg, Pa, rad/s, s).  Strains are reported in microstrain.

The package, by job: ``spec`` (deck keys, materials, the model a deck describes, checks),
``analysis`` (one case through the kernel, settling, static buckling onset), ``report`` (the
.out sections, tidy table, summary); this module runs a deck.  Cases are heavy (a time
integration each), so the study has no batch path: a sweep runs them one per task.
"""
from __future__ import annotations

import math

from tqdm import tqdm

from driver.deck import Params
from driver.limits import Estimate
from driver.slidercrank.analysis import Case, _run_case, history, simeon_initial_state, static_onset
from driver.slidercrank.report import (_benchmark_lines, _convergence_table, _crank_end_table, _header, _peak_notes,
                                       _peak_table, _plotting, _status_text, _summary, _tidy, _unsettled)
from driver.slidercrank.spec import (EULER_WARN, LABELS, MATERIALS, MIN_STEPS_PER_BENDING_PERIOD, MIN_STEPS_PER_REV,
                                     PAPER_SPEEDS, SIMEON1996, SPEC, STATUS_TEXT, SWEEP_PLOT, Model, _model, _shape,
                                     min_steps_per_rev, rayleigh)
from driver.runner import keyword_run
from driver.study import Figure, Result

__all__ = ["SPEC", "run", "estimate", "MATERIALS", "PAPER_SPEEDS", "SIMEON1996", "simeon_initial_state",
           "min_steps_per_rev", "rayleigh", "static_onset", "STATUS_TEXT", "Model", "Case", "LABELS", "SWEEP_PLOT"]


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


@keyword_run
def run(params: Params, progress: bool = False) -> Result:
    """Run every crank speed (and element count) of the deck; see the module docstring."""
    if params.model == "nonlinear":
        from driver.slidercrank.report_nl import run_nonlinear
        return run_nonlinear(params, progress)
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
    if good and params.end_time <= 0:
        above = {f"{c.omega:g} rad/s": c.euler_ratio for c in good if c.euler_ratio > 1.0}
        missing = [f"{c.omega:g} rad/s: {_status_text(c).split(' (')[0].lower()}, not drawn" for c in cases if not c.ok]
        stiffness = "K + K_G" if params.geometric_stiffness else "linear model"
        figures.append(Figure("strain", lambda: _plotting().slidercrank_strain_figure(
            [(f"{c.omega:g} rad/s", c.angle_deg, c.eps_1 * 1e6) for c in good],
            f"{params.material}: crank-end element axial strain ({stiffness})", above=above, missing=missing)))
        figures.append(Figure("deflection", lambda: _plotting().slidercrank_strain_figure(
            [(f"{c.omega:g} rad/s", c.angle_deg, c.mid * 1e3) for c in good],
            f"{params.material}: midpoint deflection ({stiffness})", ylabel="midpoint deflection [mm]",
            above=above, missing=missing)))
    if params.end_time > 0 and cases[0].ok:   # a benchmark run: its time history against the reference
        c0 = cases[0]
        ref = SIMEON1996 if params.benchmark == "simeon1996" else None
        figures.append(Figure("history", lambda: _history_figure(model, params, c0, alpha, beta, ref)))
    if conv:
        series = {f"{w:g} rad/s": ([c.n_elements for c in cs if c.ok], [c.peak(+1)[0] * 1e6 for c in cs if c.ok],
                                   [c.crank_end_peak(+1) * 1e6 for c in cs if c.ok])
                  for w, cs in conv.items()}
        speeds = ", ".join(series)
        figures.append(Figure("convergence", lambda: plotting().slidercrank_convergence_figure(
            series, f"{params.material} rod at {speeds}: convergence of the peak tensile strain with the mesh")))
    return Result(text="\n".join(text) + "\n", tidy=_tidy(params.material, list(done.values())),
                  summary=_summary(cases, model if _shape(params)[1] else None), warnings=warnings, failure=failure, figures=figures)


def _history_figure(model: Model, params: Params, case: Case, alpha: float, beta: float, ref: dict | None):
    """Midpoint deflection and rod elongation against time of a benchmark run, with the
    reference end state (Simeon 1996) marked."""
    h = history(model, params, case.omega, case.n_elements, alpha, beta)
    refs = {}
    if ref is not None:
        refs = {"mid": (ref["t"], ref["q1"]), "elong": (ref["t"], ref["q4"])}
    return _plotting().slidercrank_history_figure(
        h["time"], {"mid": h["mid"] * 1e3, "elong": h["elong"] * 1e6},
        {"mid": "midpoint deflection $q_1$ [mm]", "elong": "rod elongation $q_4$ [$\\mu$m]"},
        {k: (t, v * (1e3 if k == "mid" else 1e6)) for k, (t, v) in refs.items()},
        f"{'Simeon (1996) crank benchmark' if ref is not None else params.material}: {case.n_elements} elements "
        f"at {case.omega:g} rad/s, t = 0 to {params.end_time:g} s",
        "Simeon (1996), MEBDFI tol 1e-14")
