"""Hooke-joint study: a deck run (analyse or optimise), the fixed-format .out, the tidy table, the
summary and result.dat.

Units as printed: angles in degrees, speeds in rpm, accelerations in rad/s^2.
"""
from __future__ import annotations

import math
import textwrap
from typing import TYPE_CHECKING

import numpy as np

from driver._deck import Params
from driver._result import Figure, Result, Tidy
from driver._runner import study_run
from driver._table import Cell, Column, fortran_f, render_table
from driver.ujoint._analysis import (
    TIE_RTOL,
    Chain,
    Design,
    StartRun,
    chain_of,
    evaluate,
    free_index,
    input_torque,
    objective_scale,
    optimise,
    output_speed,
    phases_for,
    pick_best,
    start_points,
    textbook,
    yoke_shifts,
)
from driver.ujoint._kernel import UJOINT_MODELS, ujoint_speed
from driver.ujoint._spec import BAND_TOL, CONVENTIONS, DEG, OPTIONS, ORIGINS, SPEC, joint_geometry, per_joint, phases_deg

if TYPE_CHECKING:
    from driver._mechanism import MechanismFrames


def _model_text(params: Params) -> str:
    if params.model == "exact":
        return ("exact chain: theta_(k+1) = theta_out,k + phi_k - rho_k, tan theta_out,k = "
                "cos beta_k tan theta_k")
    if params.phasing == "cumulative":
        return "paper, cumulative phasing (the text): joint k driven at theta + phi_1 + .. + phi_(k-1)"
    return "paper, eq. 13 as printed: joint k driven at theta + phi_(k-1)"


def _table_theta(params: Params) -> np.ndarray:
    """Input angles of the speed table [deg]: 0 to 360 in table_step."""
    return np.arange(0.0, 360.0 + 1e-9, params.table_step)


def _fmt(x: float | None, d: int = 4) -> str:
    return "n/a" if x is None else fortran_f(x, None, d)


def _es(x: float, d: int = 5) -> str:
    """Fortran ES editing (e.g. ES12.5 -> '3.08895E-08') for objectives spanning decades.

    (driver._table.fortran_f renders tiny values with 7+ decimals as '3E-8' through
    Decimal.__str__, so objective columns use this instead.)
    """
    if not math.isfinite(x):
        raise ValueError(f"non-finite objective {x!r}")
    return f"{x:.{d}E}"


def _objective_text(f: float, resolution: float | None, d: int = 5) -> str:
    """An objective value, or '<res' when it lies below the optimiser's resolution (ftol
    times the objective scale): below it the digits are the stopping point's noise."""
    if resolution is not None and f < resolution:
        return f"<{resolution:.1E}"
    return _es(f, d)


def _render(params: Params, chain: Chain, beta, rho, designs: list[Design], runs: list[StartRun],
            notes: list[str], warnings: list[str], failure: str | None) -> str:
    n = beta.size
    option = params.option
    exact = params.model == "exact"
    out = [" HOOKE-JOINT SHAFT CHAIN  (&ujoint; [Fajar]: Shaft Series Optimisation, SSO)", ""]
    hdr = [("deck", str(params.path)),
           ("model", _model_text(params)),
           ("joints", f"{n} on {n + 1} shafts; {n - 1} intermediate shaft(s), so {n - 1} phase(s)"),
           ("input speed", f"{fortran_f(params.rpm, None, 4)} rpm = {fortran_f(chain.omega, None, 6)} rad/s"),
           ("option", f"{option} ({OPTIONS[option]})"),
           ("objective", {"mean_square": "mean_square: U = mean over one revolution of (R - 1)^2, "
                                         "R = omega_out/omega_in [-]",
                          "rms": "rms: sqrt(mean (R - 1)^2) [-]",
                          "peak_to_peak": "peak_to_peak: max R - min R on the grid [-]"}[params.objective]),
           ("angle origin", f"{params.angle_origin}: theta = 0 with {ORIGINS[params.angle_origin][0]}"),
           ("grid", f"{params.n_grid} input angles per revolution ({ORIGINS[params.angle_origin][1]}): objective, "
                    "band, and the brackets of the root finding"),
           ("tables", f"speed table every {fortran_f(params.table_step, None, 4)} deg (table_step); tidy table "
                      + (f"(CSV, Parquet) at the {params.n_grid} grid angles (tidy_grid = 'n_grid')"
                         if params.tidy_grid == "n_grid" else "(CSV, Parquet) at the speed table's angles "
                                                              "(tidy_grid = 'table_step')")),
           ("phases", "phi (the paper's convention): 90 deg = yokes on the shaft in phase; "
                      + ("yoke phase delta_k = phi_k - phi_(k-1) - 90 (eq. 13: phi_k is absolute)"
                         if chain.model == UJOINT_MODELS["eq13"] else "yoke phase delta = phi - 90"))]
    if chain.load is not None:
        hdr.append(("output load", f"J = {params.load_inertia or 0.0:g} kg m^2, T_load = {params.load_torque or 0.0:g} N m "
                                   "(resisting); T_in = (J alpha_out + T_load) omega_out/omega_in (power balance, "
                                   "massless frictionless joints, constant input speed)"))
    if params.axes is not None:
        a = np.asarray(params.axes, float).reshape(-1, 3)
        for k, v in enumerate(a):
            hdr.append((f"shaft {k} axis", "  ".join(fortran_f(x, 10, 5) for x in v)))
    if rho is not None:
        hdr.append(("plane angles rho", "  ".join(fortran_f(x, None, 4) for x in rho) + " deg"))
    if option in (2, 3):
        hdr.append(("joint-angle bounds", _bounds_text(params, "beta", n)))
    if option in (1, 3):
        if n > 1:
            hdr.append(("phase bounds", _bounds_text(params, "phi", n - 1)))
        hdr.append(("multi-start", f"{params.n_starts} start(s): 1 = trial, others uniform in the "
                                   f"bounds (seed {params.seed}); SLSQP, analytic gradient, maxiter "
                                   f"{params.maxiter}, ftol {params.ftol:g} (relative)"))
    width = max(len(k) for k, _ in hdr)
    out += [f" {k:<{width}} : {v}" for k, v in hdr]
    out += [f" {'conventions':<{width}} : {line}" if i == 0 else f" {'':<{width}}   {line}"
            for i, line in enumerate(textwrap.wrap(CONVENTIONS, 100))] + [""]
    res = designs[1].extra.get("resolution") if len(designs) > 1 else None

    out.append(" DESIGNS (angles in deg)")
    cols = [Column("design", "s", 14)] + [Column(f"beta_{k + 1}", "f", 9, 4) for k in range(n)] + \
           [Column(f"phi_{k + 1}", "f", 9, 4) for k in range(n - 1)] + \
           [Column(f"delta_{k + 1}", "f", 9, 4) for k in range(n - 1)]
    rows = [[d.label, *d.beta, *d.phi, *(yoke_shifts(chain.model, d.phi) - 90.0)] for d in designs]
    out += render_table(cols, rows) + [""]

    out.append(" PERFORMANCE (under this deck's model and objective; rpm at the input speed)")
    cols = [Column("design", "s", 14), Column("objective", "s", 12), Column("U rpm^2", "s", 12),
            Column("p-p ratio", "f", 10, 6), Column("w_min rpm", "f", 10, 4),
            Column("w_max rpm", "f", 10, 4), Column("beta_e", "f", 8, 4), Column("beta_res", "s", 9),
            Column("peak acc", "f", 11, 6)]
    ures = res * params.rpm ** 2 if res is not None and params.objective == "mean_square" else None
    rows = [[d.label, _objective_text(d.objective, res), _objective_text(d.u_rpm2, ures), d.pp, d.w_min, d.w_max, d.beta_e,
             _fmt(d.beta_res), d.peak_acc] for d in designs]
    out += render_table(cols, rows)
    out += ["   beta_e [deg]: first-order residual angle, beta_e^2 = |sum beta_k^2 exp(2i gamma_k)| "
            "(p-p ratio ~ beta_e^2 [rad^2])",
            "   beta_res [deg]: the single joint the exact chain with these yoke phases equals (closed "
            "form; n/a unless every yoke shift is a multiple of 90 deg)",
            "   peak acc [rad/s^2]: max |d omega_out/dt| at constant input speed", ""]
    printed = next((d for d in designs if d.label == "paper printed"), None)
    if printed is not None and params.paper_u is not None:
        nit = f", {params.paper_nit} iterations" if params.paper_nit is not None else ""
        nfev = f", {params.paper_nfev} function evaluations" if params.paper_nfev is not None else ""
        out.append(f" The paper prints U = {params.paper_u:g}{nit}{nfev} for its optimum. That value "
                   "cannot be reproduced under any")
        out.append(" tested definition of U (see docs/ujoint.md); the row above evaluates the printed "
                   "design under this deck's objective.")
        out.append("")

    if runs:
        out += _render_runs(runs, designs[1], _free_names(option, n))
    out += _render_compare(params, chain, designs)
    out += _render_textbook(params, chain, designs)
    out += _render_speed_table(params, chain, designs, exact)
    out.append(" NOTES")
    all_notes = list(notes)
    if n >= 3 and not exact:
        all_notes.append("the paper optimises a phi_3 for three joints; it has no physical meaning (two "
                         "intermediate shafts, two phases) and is not used here")
    if not exact and len(designs) > 1 and abs(designs[1].mean_ratio - 1.0) > 1e-6:
        d = designs[1]
        text = (f"under the paper's model the {d.label}'s mean output speed is "
                f"{d.mean_ratio * params.rpm:.4f} rpm, not the input {params.rpm:g} rpm: an artefact "
                "(a real output shaft turns once per input turn)")
        if params.objective == "mean_square":
            share = (d.mean_ratio - 1.0) ** 2 / max(d.objective, 1e-300)
            text += f"; this bias is {share:.0%} of its objective"
            if option in (2, 3) and share > 0.5:
                text += ", which is why the search favours the smallest joint angles"
        all_notes.append(text)
    if not exact:
        all_notes.append("the paper's model drives every joint with the input angle plus a phase; the "
                         "intermediate shafts do not actually turn uniformly, so its residual is 4th "
                         "order in the angles (see the exact-model row of MODEL COMPARISON)")
    all_notes += [f"WARNING: {w}" for w in warnings]
    if not all_notes:
        all_notes.append("none")
    out += [f"  - {t}" for t in all_notes]
    if failure:
        out += ["", f" RUN FAILED: {failure}"]
    return "\n".join(out) + "\n"


def _bounds_text(params: Params, base: str, count: int) -> str:
    lo = per_joint(params, f"{base}_lower", count, "")
    hi = per_joint(params, f"{base}_upper", count, "")
    return "  ".join(f"[{fortran_f(a, None, 4)}, {fortran_f(b, None, 4)}]" for a, b in zip(lo, hi)) + " deg"


def _free_names(option: int, n: int) -> list[str]:
    names = [f"beta_{k + 1}" for k in range(n)] + [f"phi_{k + 1}" for k in range(n - 1)]
    return [names[i] for i in free_index(option, n)]


def _family(runs: list[StartRun], pick: StartRun, n_beta: int, resolution: float) -> tuple[int, np.ndarray]:
    """Converged starts that tie with the best objective (as in :func:`pick_best`), and their
    distinct end points [deg] (rounded to 0.01 deg; phases taken modulo 180 deg)."""
    fbest = min(r.f for r in runs if r.success)
    tol = max(TIE_RTOL * abs(fbest), resolution)
    good = [r for r in runs if r.success and r.f <= fbest + tol]
    x = np.array([r.x for r in good]) / DEG
    x[:, n_beta:] %= 180.0
    x = np.round(x, 2)
    x[np.isclose(x, 180.0)] = 0.0
    return len(good), np.unique(x, axis=0)


def _render_runs(runs: list[StartRun], best: Design, names: list[str]) -> list[str]:
    idx = best.extra["index"]
    pick = best.extra["run"]
    ok = sum(r.success for r in runs)
    n_beta = sum(name.startswith("beta") for name in names)
    res = best.extra["resolution"]
    close, distinct = _family(runs, pick, n_beta, res) if ok else (0, np.empty((0, len(names))))
    out = [" OPTIMISER (scipy SLSQP per start; objective values unscaled)"]
    cols = [Column("start", "i", 5), Column("objective", "s", 14), Column("iter", "i", 5),
            Column("f-evals", "i", 7), Column("status", "s", 9)]
    rows = [[k + 1, _objective_text(r.f, res, 7), r.nit, r.nfev, "converged" if r.success else "FAILED"]
            for k, r in enumerate(runs)]
    trail = []
    for k, r in enumerate(runs):
        t = ["<- best"] if k + 1 == idx else ([r.message] if not r.success else [])
        if r.on_bound.size:
            t.append("at bound: " + " ".join(names[i] for i in r.on_bound))
        trail.append("  ".join(t))
    out += render_table(cols, rows, trail)
    ended = sum(r.on_bound.size > 0 for r in runs)
    out += [f"   best start {idx}: {pick.nit} iterations, {pick.nfev} function evaluations "
            f"({pick.njev} gradient evaluations); all starts: {sum(r.nit for r in runs)} iterations, "
            f"{sum(r.nfev for r in runs)} evaluations",
            f"   {ok} of {len(runs)} start(s) converged; {close} reached the best objective "
            f"(within {TIE_RTOL:g} relative or the resolution {res:.1E}) at {len(distinct)} distinct "
            "point(s) (0.01 deg; phases mod 180)",
            f"   {ended} of {len(runs)} start(s) ended on a bound (listed 'at bound'); phases whose "
            "bounds span 180 deg are periodic and searched without bounds, so no phase bound stops a start",
            f"   tie rule: among optima within {TIE_RTOL:g} relative of the best, the trial start's end "
            "point, else the smallest phases (lexicographic), then the smallest joint angles"]
    if len(distinct) > 1:
        out.append("   distinct optima (a family: the objective does not single out one design), first 8 [deg]:")
        out += render_table([Column(nm, "f", 10, 2) for nm in names], distinct[:8])
    out.append("")
    return out


def _render_compare(params: Params, chain: Chain, designs: list[Design]) -> list[str]:
    """Trial and optimum under the other models, and the paper's trial band if given."""
    models = [("paper eq. 13 as printed", "eq13"), ("paper cumulative phases", "cumulative"),
              ("exact chain", "exact")]
    if params.model == "exact" and (params.rho is not None or params.axes is not None):
        models = [("exact chain", "exact")]   # the paper's models are coplanar
    out = [" MODEL COMPARISON (same joint angles and yoke phases delta, each model's phi; omega_out band "
           "in rpm, p-p ratio)"]
    cols = [Column("design", "s", 14), Column("model", "s", 25), Column("w_min rpm", "f", 10, 4),
            Column("w_max rpm", "f", 10, 4), Column("p-p ratio", "f", 10, 6), Column("objective", "s", 12)]
    rows: list[list[Cell]] = []
    for d in designs:
        for label, code in models:
            m = UJOINT_MODELS[code]
            e = evaluate(chain, d.label, d.beta, phases_for(m, yoke_shifts(chain.model, d.phi)), model=m)
            rows.append([d.label, label, e.w_min, e.w_max, e.pp, _es(e.objective)])
    out += render_table(cols, rows)
    if params.paper_band is not None:
        lo, hi = params.paper_band
        t = designs[0]
        inside = abs(t.w_min - lo) < BAND_TOL and abs(t.w_max - hi) < BAND_TOL
        out.append(f"   the paper reads the trial band as {lo:g}-{hi:g} rpm off its plot; this model gives "
                   f"{t.w_min:.2f}-{t.w_max:.2f} rpm: "
                   + (f"reproduced to the plot's reading precision (+-{BAND_TOL:g} rpm; the paper quotes whole rpm)"
                      if inside else
                      "NOT reproduced; the discrepancy is reported, not forced"))
    out.append("")
    return out


#: decimals of the textbook angles of a design the deck gives (roots to 1e-12 rad, 6e-11 deg) and of a
#: design an optimiser found: its variables are known to the optimiser's tolerance, and the angle of
#: a small fluctuation's peak moved by 1e-7 deg with the BLAS kernel (ujoint_option3's optimum)
ANGLE_DECIMALS = {"given": 9, "searched": 3}


def _angles(values: np.ndarray, decimals: int = ANGLE_DECIMALS["given"]) -> str:
    """Input angles [deg] for the .out, to ``decimals`` (:data:`ANGLE_DECIMALS`)."""
    return ", ".join(f"{v:.{decimals}f}" for v in values) if len(values) else "none"


def _render_textbook(params: Params, chain: Chain, designs: list[Design]) -> list[str]:
    """Where each design's speed ratio is one, where its output acceleration peaks and how high,
    and with a load its input torque: by root finding on the closed form (1e-12 rad)."""
    origin = ORIGINS[params.angle_origin][1]
    out = [f" TEXTBOOK FIGURES over one input turn (input angles in deg, {origin}; roots of the kernel's "
           "closed form to 1e-12 rad)"]
    for d in designs:
        if d.label == "paper printed":
            continue
        tb = textbook(chain, d)
        places = ANGLE_DECIMALS["searched" if d.label in ("optimum", "last iterate") else "given"]
        out.append(f"   {d.label}:" + ("" if places == ANGLE_DECIMALS["given"] else
                                      f" (angles to {places} decimals: the design is known to the optimiser's tolerance)"))
        if tb.uniform:
            out.append("     omega_out = omega_in (ratio one) throughout: a constant-velocity chain to the printed "
                       "p-p ratio (below 5e-7); no crossing of one and no acceleration peak resolved")
            if tb.torque_mean is not None:
                out.append(f"     input torque: constant over the turn, {tb.torque_mean:.10f} N m")
            continue
        out.append(f"     omega_out = omega_in (ratio one) at theta = {_angles(tb.ratio_one, places)}")
        out.append(f"     peak output acceleration |alpha_out| = {tb.accel_peak:.10f} rad/s^2 at theta = "
                   f"{_angles(tb.accel_peak_at, places)}" + ("" if not len(tb.accel_peak_signed) else
                                                    " (signed: " + ", ".join(f"{a:+.10f}" for a in tb.accel_peak_signed)
                                                    + ")"))
        if tb.torque_peak is not None:
            out.append(f"     input torque: peak |T_in| = {tb.torque_peak:.10f} N m at theta = "
                       f"{_angles(tb.torque_peak_at, places)}; mean over the turn {tb.torque_mean:.10f} N m")
    return out + [""]


def _render_speed_table(params: Params, chain: Chain, designs: list[Design], exact: bool) -> list[str]:
    th = _table_theta(params)
    shown = [d for d in designs if d.label != "paper printed"]
    out = [" SPEED TABLE over the input angle (omega_in = "
           f"{fortran_f(params.rpm, None, 4)} rpm constant; acc = d omega_out/dt; "
           f"{ORIGINS[params.angle_origin][1]})"]
    cols = [Column("theta_in", "f", 9, 2)]
    data = []
    for d in shown:
        w, a, to = output_speed(chain, d, th)
        tag = {"optimum": "opt", "last iterate": "last", "fixed design": "fixed"}.get(d.label, d.label)
        cols += [Column(f"{tag} w_out", "f", 12, 5), Column(f"{tag} ratio", "f", 11, 7),
                 Column(f"{tag} acc", "f", 11, 6)]
        data += [w, w / params.rpm, a]
        if exact:
            cols.append(Column(f"{tag} th_out", "f", 11, 4))
            data.append(to)
        if chain.load is not None:
            cols.append(Column(f"{tag} T_in", "f", 12, 6))
            data.append(input_torque(chain, d, th))
    rows = [[t, *(c[i] for c in data)] for i, t in enumerate(th)]
    out += render_table(cols, rows)
    out.append(f"   units: theta_in, th_out [deg, {ORIGINS[params.angle_origin][1]}]; w_out [rpm]; ratio [-]; "
               "acc [rad/s^2]" + ("; T_in [N m]" if chain.load is not None else ""))
    out.append("")
    return out


def _tidy(params: Params, chain: Chain, designs: list[Design]) -> Tidy:
    """One row per design and input angle: the n_grid angles or the speed table's (tidy_grid),
    from the deck's angle origin (said in every row's angle_origin)."""
    theta = np.arange(chain.m) * (360.0 / chain.m) if params.tidy_grid == "n_grid" else _table_theta(params)
    parts = []
    for d in designs:
        w, a, to = output_speed(chain, d, theta)
        part = {"design": d.label, "theta_in_deg": theta, "angle_origin": params.angle_origin,
                "omega_in_rpm": chain.rpm, "omega_out_rpm": w, "ratio": w / chain.rpm, "alpha_out_rad_s2": a}
        if chain.model == UJOINT_MODELS["exact"]:
            part["theta_out_deg"] = to
        if chain.load is not None:
            part["input_torque_Nm"] = input_torque(chain, d, theta)
        parts.append(part)
    return Tidy(*parts, units={"ratio": "1"})


def _summary(chain: Chain, trial: Design, best: Design | None, runs: list[StartRun], failure: str | None) -> dict:
    d = best if best is not None else trial
    s = {"objective": d.objective, "objective_trial": trial.objective, "pp_ratio": d.pp,
         "omega_out_min_rpm": d.w_min, "omega_out_max_rpm": d.w_max, "beta_e_deg": d.beta_e,
         "beta_res_deg": d.beta_res,   # None when the closed form does not apply
         "peak_accel_rad_s2": d.peak_acc, "peak_accel_at_deg": d.peak_acc_at, "ratio_one_at_deg": d.ratio_one_at,
         "converged": failure is None,
         "iterations": sum(r.nit for r in runs), "evaluations": sum(r.nfev for r in runs)}
    if chain.load is not None:
        tb = textbook(chain, d)
        s.update({"input_torque_peak_Nm": tb.torque_peak,
                  "input_torque_peak_at_deg": float(tb.torque_peak_at[0]) if len(tb.torque_peak_at) else None,
                  "input_torque_mean_Nm": tb.torque_mean})
    s.update({f"beta_{k + 1}_deg": float(v) for k, v in enumerate(d.beta)})
    s.update({f"phi_{k + 1}_deg": float(v) for k, v in enumerate(d.phi)})
    return s


def _result_dat(params: Params, chain: Chain, designs: list[Design], best: Design,
                runs: list[StartRun]) -> str:
    """The paper's post-processing 'save result': optimum, objective and its speed curve."""
    pick = best.extra["run"]
    fixed = pick is None
    lines = ["% result.dat of &ujoint (SSO post-processing 'save result'); angles in deg",
             f"% deck {params.path}; model {_model_text(params)}; objective {params.objective}",
             f"option     = {params.option}",
             "x          = " + " ".join(fortran_f(v, None, 6) for v in np.concatenate([best.beta, best.phi])),
             # below the optimiser's resolution the digits are the stopping point's noise (and change
             # with the BLAS kernel): the bound is written, as in the .out
             "fval       = " + (f"<{res:.1E}" if (res := best.extra.get("resolution")) is not None
                                and best.objective < res else f"{best.objective:.10e}"),
             f"exitflag   = {1 if fixed or pick.success else 0}",
             f"iterations = {0 if fixed else pick.nit}",
             f"funccount  = {1 if fixed else pick.nfev}",
             *(["% FIXED DESIGN: equal bounds fix every free variable; evaluated, not optimised"] if fixed
               else [] if pick.success else ["% NOT CONVERGED: x is the last iterate, not an optimum"]),
             f"% angle origin {params.angle_origin}: {ORIGINS[params.angle_origin][1]}",
             "% theta_in_deg  omega_in_rpm  omega_out_trial_rpm  omega_out_optimum_rpm"]
    th = np.arange(0.0, 360.0 + 1e-9, 1.0)
    w0 = output_speed(chain, designs[0], th)[0]
    w1 = output_speed(chain, best, th)[0]
    lines += [f"{fortran_f(t, 8, 2)} {fortran_f(params.rpm, 12, 6)} {fortran_f(a, 14, 8)} {fortran_f(b, 14, 8)}"
              for t, a, b in zip(th, w0, w1)]
    return "\n".join(lines) + "\n"


@study_run(SPEC)
def run(params: Params, progress: bool = False) -> Result:
    """Analyse (option 0) or optimise (options 1-3) a chain of Hooke joints on a shaft line.

    The output-speed fluctuation of the chain over one input revolution (objective, band,
    peak-to-peak ratio, equivalent angles, peak output acceleration) for the given joint angles
    ``beta`` and phases ``phi`` (or ``delta``); options 1-3 minimise the objective over the
    phases, the angles or both with multi-start SLSQP.  Angles in degrees, speeds in rpm.

    Examples
    --------
    >>> import driver
    >>> r = driver.ujoint.run(beta=[10.0, 20.0], phi=[90.0], rpm=30.0)
    >>> round(r.summary["omega_out_min_rpm"], 4), round(r.summary["omega_out_max_rpm"], 4)
    (28.6257, 31.4403)
    """
    beta, rho = joint_geometry(params)
    n = beta.size
    phi = phases_deg(params, n)
    chain = chain_of(params, rho, n)
    trial = evaluate(chain, "trial" if params.option else "design", beta, phi)
    designs = [trial]
    warnings: list[str] = []
    notes: list[str] = []
    runs: list[StartRun] = []
    failure = None
    best = None
    option = params.option
    if option:
        free = free_index(option, n)
        lo = np.concatenate([per_joint(params, "beta_lower", n, "joints"),
                             per_joint(params, "phi_lower", n - 1, "phases") if n > 1 else []])
        hi = np.concatenate([per_joint(params, "beta_upper", n, "joints"),
                             per_joint(params, "phi_upper", n - 1, "phases") if n > 1 else []])
        lb, ub = lo[free] * DEG, hi[free] * DEG
        beta_max = max(np.max(np.abs(beta)), np.max(np.abs(hi[:n])) if option in (2, 3) else 0.0)
        scale = objective_scale(chain, trial.objective, beta_max)
        z = np.concatenate([beta, phi])
        if np.all(lb == ub):
            z[free] = lb / DEG
            best = evaluate(chain, "fixed design", z[:n], z[n:])
            best.extra = {"run": None, "index": None}
            designs.append(best)
            notes.append("equal bounds fix every free variable: the fixed design is evaluated, "
                         "not optimised (no multi-start)")
        else:
            starts, start_notes = start_points(params, option, beta, phi, lb, ub, chain)
            notes += start_notes
            runs = optimise(chain, option, beta * DEG, phi * DEG, lb, ub, starts, params.maxiter,
                            params.ftol, scale, progress)
            ok = any(r.success for r in runs)
            ipick = pick_best(runs, int(np.sum(free < n)))
            pick = runs[ipick]
            z[free] = pick.x / DEG
            best = evaluate(chain, "optimum" if ok else "last iterate", z[:n], z[n:])
            best.extra = {"run": pick, "index": ipick + 1, "scale": scale,
                          "resolution": params.ftol * scale}
            designs.append(best)
            if not ok:
                failure = (f"the optimiser did not converge from any of {len(runs)} start(s) "
                           f"(best start: {pick.message}); no optimum is reported")
                warnings.append(failure)
    printed = None
    if params.paper_beta is not None or params.paper_phi is not None:
        pb = np.asarray(params.paper_beta if params.paper_beta is not None else beta, float)
        pp = phases_deg(params, n, "paper_phi") if params.paper_phi is not None else phi
        printed = evaluate(chain, "paper printed", pb, pp)
        designs.append(printed)
    text = _render(params, chain, beta, rho, designs, runs, notes, warnings, failure)
    tidy = _tidy(params, chain, designs)
    summary = _summary(chain, trial, best, runs, failure)
    extra = {".result.dat": _result_dat(params, chain, designs, best, runs)} if best is not None else {}
    title = params.path.stem if getattr(params, "path", None) else ""
    origin = ORIGINS[params.angle_origin][1]
    figures = [Figure("speed", lambda: _figures().speed_figure(chain, designs, False, params.paper_band, title, origin)),
               Figure("polar", lambda: _figures().speed_figure(chain, designs, True, params.paper_band, title, origin))]
    if chain.load is not None:
        figures.append(Figure("torque", lambda: _figures().torque_figure(chain, designs, title, origin)))
    return Result(text=text, tidy=tidy, summary=summary, warnings=warnings, failure=failure,
                  figures=figures, extra=extra)


def _figures():
    """The study's figure module, imported when a figure is drawn (matplotlib is the optional [plot] extra)."""
    from driver.ujoint import _figures as figures
    return figures


#: the axonometric view of the shaft chain: turned by the azimuth about the vertical, then tilted
#: by the elevation (joint 1's plane is the x-y plane, the input shaft along x) [deg]
VIEW_AZIMUTH_DEG, VIEW_ELEVATION_DEG = 30.0, 20.0
#: the yokes' radius, in shaft lengths (every shaft is drawn one unit long)
YOKE_RADIUS = 0.22


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """The rotation matrix by ``angle`` [rad] about the unit vector ``axis`` (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def _chain_axes(params: Params, beta_deg: np.ndarray, rho_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The shafts' unit directions (n+1, 3) and the joints' plane normals (n, 3): the deck's
    ``axes`` when given, else built from the joint and plane angles (joint 1 in the x-y plane,
    successive bends alternating, a Z arrangement; the sign of a bend does not change a Hooke
    joint's motion, its cosine does)."""
    if params.axes is not None:
        a = np.asarray(params.axes, float).reshape(-1, 3)
        a = a / np.linalg.norm(a, axis=1)[:, None]
        normals, last = [], np.array([0.0, 0.0, 1.0])
        for k in range(len(a) - 1):
            c = np.cross(a[k], a[k + 1])
            last = c / np.linalg.norm(c) if np.linalg.norm(c) > 1e-12 else last
            normals.append(last)
        return a, np.array(normals)
    axes, normals = [np.array([1.0, 0.0, 0.0])], [np.array([0.0, 0.0, 1.0])]
    for k, b in enumerate(beta_deg):
        axes.append(_rotation(normals[k], (1 if k % 2 == 0 else -1) * b * DEG) @ axes[k])
        if k < len(beta_deg) - 1:
            normals.append(_rotation(axes[-1], rho_deg[k] * DEG) @ normals[k])
    return np.array(axes), np.array(normals)


def animation_frames(params: Params, result: Result | None = None, n: int = 180) -> MechanismFrames:
    """The shaft chain over one input turn, for the report page's animation
    (:class:`driver._mechanism.MechanismFrames`): an oblique view of the shafts (each drawn one
    unit long) and of one yoke per shaft, each turned by its shaft's angle from the kernel's exact
    chain (:func:`~driver.ujoint.kernel.ujoint_speed`, the chain up to that shaft) at the run's
    design (the optimum of an optimising ``result``, else the deck's).  Each frame's label gives
    the output shaft's deviation from uniform rotation."""
    from driver._mechanism import Link, MechanismFrames  # the page's animation only
    beta0, rho_given = joint_geometry(params)
    nj = beta0.size
    s = dict(getattr(result, "summary", None) or {})
    beta = np.array([s.get(f"beta_{k + 1}_deg", beta0[k]) for k in range(nj)], float)
    phi = np.array([s.get(f"phi_{k + 1}_deg", v) for k, v in enumerate(phases_deg(params, nj))], float)
    rho = np.zeros(nj - 1) if rho_given is None else np.asarray(rho_given, float)
    theta = np.linspace(0.0, 360.0, n, endpoint=False)
    th = np.radians(theta)
    exact = UJOINT_MODELS["exact"]
    psi = [th] + [ujoint_speed(exact, beta[:k] * DEG, phi[:k - 1] * DEG, rho[:k - 1] * DEG, th)[2]
                  for k in range(1, nj + 1)]
    axes, normals = _chain_axes(params, beta, rho)
    centres = [-axes[0]]                 # the input shaft's far end, the joints, the output shaft's end
    for k in range(nj + 1):
        centres.append(centres[-1] + axes[k])
    az, el = math.radians(VIEW_AZIMUTH_DEG), math.radians(VIEW_ELEVATION_DEG)

    def view(p: np.ndarray) -> np.ndarray:   # (..., 3) -> (..., 2): turned, tilted, depth dropped
        depth = -p[..., 0] * math.sin(az) + p[..., 2] * math.cos(az)
        return np.stack([p[..., 0] * math.cos(az) + p[..., 2] * math.sin(az),
                         p[..., 1] * math.cos(el) + depth * math.sin(el)], axis=-1)

    names = ["E0", *(f"J{k + 1}" for k in range(nj)), "E1"]
    parts = [np.broadcast_to(view(c), (n, 2)) for c in centres]
    shaft = ["input shaft", *(f"intermediate shaft {k}" for k in range(1, nj)), "output shaft"]
    links = [Link(shaft[k], (k, k + 1), colour=k) for k in range(nj + 1)]
    for k in range(nj + 1):   # the yoke of shaft k at its middle, at the shaft's angle from its joint plane's normal
        u = normals[max(k - 1, 0)]
        u = u - (u @ axes[k]) * axes[k]
        u /= np.linalg.norm(u)
        v = np.cross(axes[k], u)
        e = np.cos(psi[k])[:, None] * u + np.sin(psi[k])[:, None] * v
        mid = 0.5 * (centres[k] + centres[k + 1])
        names += [f"Y{k}a", f"Y{k}b"]
        parts += [view(mid + YOKE_RADIUS * e), view(mid - YOKE_RADIUS * e)]
        links.append(Link(f"yoke of the {shaft[k]}", (len(names) - 2, len(names) - 1), colour=k))
    dev = np.degrees(np.unwrap(psi[-1]) - th)
    dev = np.round(dev - dev.mean(), 2) + 0.0   # no '-0.00'
    design = "optimum" if params.option and result is not None else "deck's"
    model = "" if params.model == "exact" else (f" (the deck's model, '{params.model}', gives the output speed; "
                                                "the shafts' angles are the exact chain's)")
    return MechanismFrames(
        names=tuple(names), points=np.stack(parts, axis=1), links=tuple(links),
        labels=tuple(f"{t:.0f}\u00b0, output {d:+.2f}\u00b0 from uniform rotation" for t, d in zip(theta, dev)),
        joints=tuple(range(1, nj + 1)), paths=(nj + 2, len(names) - 2), frame_name="input shaft angle",
        caption=f"The shaft chain in an axonometric view (each shaft drawn one unit long, not to scale) at the {design} "
                f"design, each yoke turned by its shaft's angle in the kernel's exact chain{model}.")
