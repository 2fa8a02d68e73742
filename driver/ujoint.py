"""Hooke-joint (universal-joint) shaft chains: the paper's SSO package, corrected and extended.

Seed 000 (M. Fajar, "Optimasi kecepatan sudut keluaran kopeling universal pada poros seri"):
three Hooke joints on four shafts, optimised with MATLAB fmincon in three options
(1 phases free, 2 angles free, 3 both).  This study

* evaluates the paper's model (every joint driven by the input angle plus a phase; eq. 13
  as printed or with cumulative phases as the text says) and the exact chain (each joint's
  output angle drives the next, with plane angles for non-coplanar 3-D chains), all in the
  Fortran kernel ``fortran/ujoint.f90``;
* runs the options with scipy SLSQP (the counterpart of fmincon's SQP) from the trial point
  and from seeded random starts, with the kernel's analytic gradient;
* reports trial, optimum and the paper's printed designs under the same objective, the
  fluctuation band, peak-to-peak ratio, closed-form equivalent angles and the peak output
  acceleration, and a speed table over the input angle.

Angles in the deck are degrees; the kernel works in radians.  Phases: the paper's phi
(90 deg = yokes on the intermediate shaft in phase) or the yoke phase delta = phi - 90 deg.
See ../shared/notes/ujoint.md for what reproduces and what does not.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.optimize import minimize
from tqdm import tqdm

from driver.deck import GroupSpec, Key, Params, non_empty, positive
from driver.export import with_units
from driver.limits import Estimate
from driver.kernels import (UJOINT_MODELS, UJOINT_OBJECTIVES, ujoint_equivalent, ujoint_geometry,
                            ujoint_objective, ujoint_speed)
from driver.study import Figure, Result, keyword_run
from driver.table import Column, fortran_f, render_table

__all__ = ["SPEC", "run", "Chain", "Design", "evaluate", "optimise", "BAND_TOL", "NOT_REPRODUCIBLE"]

DEG = math.pi / 180.0
OPTIONS = {0: "analyse only", 1: "phases free, joint angles fixed",
           2: "joint angles free, phases fixed", 3: "joint angles and phases free"}
#: phases within this of a symmetric assembly count as sitting on it [rad]
SYM_TOL = 1e-7
#: how far a start is moved off the symmetric saddle [deg]
SADDLE_NUDGE = 1.0
#: reading precision of the paper's plotted bands [rpm] (it quotes whole rpm)
BAND_TOL = 1.0

#: why the paper's printed results are not reproducible (published quantity -> why)
NOT_REPRODUCIBLE = {
    "x": "the printed optima are not reproducible: no tested definition of U (phase convention, exact or "
         "approximate kinematics, grid, units, aggregation) makes them stationary points; computed: the tool's optimum",
    "U": "the printed objective values are not reproducible under any tested definition of U; computed: the "
         "printed design evaluated under this deck's objective [rpm^2]",
    "iterations": "MATLAB fmincon's count; the tool runs scipy SLSQP from several starts (its counts are in the .out)",
    "evaluations": "MATLAB fmincon's count; the tool runs scipy SLSQP from several starts (its counts are in the .out)",
    "phi_3": "phi_3 does not exist: three joints on four shafts have two intermediate shafts, so two phases",
    "option1_band": "the paper reads 24-26 rpm loosely off its Figure 6; every model gives about 23-27 rpm for the "
                    "trial point (reported, not forced)",
}


def _open_angles(v) -> str | None:
    bad = [x for x in v if not -90.0 < x < 90.0]
    return (f"a joint angle must lie strictly between -90 and 90 deg (got {bad[0]})"
            if bad else None)


_KEYS = dict(
    beta=Key("floats", check=lambda v: non_empty(v) or _open_angles(v), units="deg",
             doc="operating angle of each joint (any count >= 1); the trial/start design. "
             "Omit when 'axes' gives the geometry."),
    phi=Key("floats", units="deg",
            doc="the paper's phases, one per intermediate shaft (n-1 values); "
            "90 = yokes in phase. Default: in phase"),
    delta=Key("floats", units="deg",
              doc="yoke phases instead of phi (0 = in phase; delta = phi - 90)"),
    rho=Key("floats", units="deg",
            doc="angle between the planes of joints k and k+1 about their shared shaft "
            "(n-1 values; exact model only; default coplanar)"),
    axes=Key("floats", units="-",
             doc="3-D chain: shaft direction vectors x,y,z of shafts 0..n (input first); "
             "gives beta and rho (exact model only)"),
    rpm=Key("float", default=25.0, check=positive, units="rpm",
            doc="input shaft speed (the paper: 25 rpm)"),
    model=Key("str", default="exact", choices=("paper", "exact"),
              doc="'paper': every joint driven by the input angle plus a phase; "
              "'exact': each joint's output drives the next"),
    phasing=Key("str", default="cumulative", choices=("cumulative", "eq13"),
                doc="paper model only: joint k at theta+phi_1+..+phi_(k-1) (the text) "
                "or theta+phi_(k-1) (eq. 13 as printed)"),
    option=Key("int", default=0, choices=(0, 1, 2, 3),
               doc="0 analyse, 1 phases free, 2 angles free (phases fixed), 3 both free"),
    objective=Key("str", default="mean_square", choices=("mean_square", "rms", "peak_to_peak"),
                  doc="mean (R-1)^2 over a revolution (the paper's U per omega_in^2), "
                  "its root, or max R - min R; R = omega_out/omega_in"),
    beta_lower=Key("floats", default=[0.0], units="deg", doc="lower bound(s) on joint angles"),
    beta_upper=Key("floats", default=[40.0], units="deg",
                   doc="upper bound(s) on joint angles (the paper: 40)"),
    phi_lower=Key("floats", default=[0.0], units="deg", doc="lower bound(s) on phases phi"),
    phi_upper=Key("floats", default=[180.0], units="deg", doc="upper bound(s) on phases phi"),
    n_starts=Key("int", default=16,
                 check=lambda v: positive(v) or ("at most 100000 starts" if v > 100_000 else None),
                 doc="multi-start: the trial point plus n_starts-1 seeded random starts"),
    seed=Key("int", default=0, doc="random seed of the multi-start (deterministic)"),
    n_grid=Key("int", default=360, check=lambda v: None if v >= 8 else "must be at least 8",
               doc="input angles per revolution for objective, band and peaks"),
    table_step=Key("float", default=10.0, check=positive, units="deg",
                   doc="input-angle step of the speed table"),
    maxiter=Key("int", default=200, check=positive, doc="SLSQP iteration limit per start"),
    ftol=Key("float", default=1e-12, check=positive,
             doc="SLSQP tolerance on the objective scaled by its trial value"),
    paper_beta=Key("floats", units="deg", doc="the paper's printed optimum: joint angles"),
    paper_phi=Key("floats", units="deg", doc="the paper's printed optimum: phases phi"),
    paper_u=Key("float", doc="the paper's printed objective value (for display only)"),
    paper_nit=Key("int", doc="the paper's printed iteration count"),
    paper_nfev=Key("int", doc="the paper's printed function evaluations"),
    paper_band=Key("floats", units="rpm", doc="the paper's trial band read off its plot: min, max"),
)


# --------------------------------------------------------------------------- model

@dataclass
class Chain:
    """Fixed description of a run: model code, objective code, plane angles, grid."""

    model: int
    kind: int
    rho: np.ndarray          # (n-1,) rad
    m: int                   # grid points per revolution
    rpm: float

    @property
    def omega(self) -> float:
        """Input speed [rad/s]."""
        return self.rpm * 2.0 * math.pi / 60.0


@dataclass
class Design:
    """One design evaluated: angles [deg] and its performance figures."""

    label: str
    beta: np.ndarray         # deg
    phi: np.ndarray          # deg (paper convention)
    objective: float = 0.0
    u_rpm2: float = 0.0
    pp: float = 0.0
    w_min: float = 0.0
    w_max: float = 0.0
    beta_e: float = 0.0
    beta_res: float | None = None
    peak_acc: float = 0.0
    mean_ratio: float = 1.0
    extra: dict = field(default_factory=dict)


def evaluate(chain: Chain, label: str, beta_deg, phi_deg, model: int | None = None) -> Design:
    """All headline figures of one design under ``chain`` (``model`` overrides its model)."""
    model = chain.model if model is None else model
    b = np.asarray(beta_deg, float) * DEG
    ph = np.asarray(phi_deg, float) * DEG
    f, _ = ujoint_objective(model, chain.kind, b, ph, chain.rho, chain.m, grad=False)
    ms, _ = ujoint_objective(model, UJOINT_OBJECTIVES["mean_square"], b, ph, chain.rho, chain.m, grad=False)
    theta = np.arange(chain.m) * (2.0 * math.pi / chain.m)
    ratio, dratio, _ = ujoint_speed(model, b, ph, chain.rho, theta)
    be, br = ujoint_equivalent(model, b, ph, chain.rho)
    return Design(label, np.asarray(beta_deg, float), np.asarray(phi_deg, float), float(f),
                  float(ms * chain.rpm ** 2), float(ratio.max() - ratio.min()),
                  float(chain.rpm * ratio.min()), float(chain.rpm * ratio.max()), be / DEG,
                  None if br is None else br / DEG, float(chain.omega ** 2 * np.abs(dratio).max()),
                  float(ratio.mean()))


@dataclass
class StartRun:
    """Outcome of one SLSQP start."""

    x0: np.ndarray
    x: np.ndarray
    f: float
    nit: int
    nfev: int
    njev: int
    success: bool
    message: str


def _symmetric(chain: Chain, phi_rad: np.ndarray) -> bool:
    """True when every phase shift is a multiple of 90 deg: the theta -> -theta symmetric
    assembly where the phase gradient vanishes identically (a saddle or a maximum)."""
    shift = phi_rad - (chain.rho if chain.model == UJOINT_MODELS["exact"] else 0.0)
    q = shift / (0.5 * math.pi)
    return bool(np.all(np.abs(q - np.round(q)) * 0.5 * math.pi < SYM_TOL))


def optimise(chain: Chain, option: int, beta0: np.ndarray, phi0: np.ndarray,
             lb: np.ndarray, ub: np.ndarray, starts: np.ndarray, maxiter: int,
             ftol: float, progress: bool = False) -> list[StartRun]:
    """SLSQP from every row of ``starts`` (free variables, rad) with the kernel gradient.

    beta0, phi0 [rad] hold the fixed variables; lb/ub the bounds of the free ones [rad].
    The objective is divided by its value at the first start so ``ftol`` is relative.
    """
    n = beta0.size
    free = _free_index(option, n)

    def full(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        z = np.concatenate([beta0, phi0])
        z[free] = x
        return z[:n], z[n:]

    b, p = full(starts[0])
    fref = ujoint_objective(chain.model, chain.kind, b, p, chain.rho, chain.m, grad=False)[0]
    fref = fref if fref > 1e-300 else 1.0

    def fun(x: np.ndarray) -> tuple[float, np.ndarray]:
        b, p = full(x)
        f, g = ujoint_objective(chain.model, chain.kind, b, p, chain.rho, chain.m)
        return f / fref, g[free] / fref

    bounds = list(zip(lb, ub))
    runs = []
    for x0 in tqdm(starts, desc="multi-start", unit="start", disable=not progress):
        res = minimize(fun, x0, jac=True, method="SLSQP", bounds=bounds,
                       options={"maxiter": maxiter, "ftol": ftol})
        x = np.clip(res.x, lb, ub)
        f = ujoint_objective(chain.model, chain.kind, *full(x), chain.rho, chain.m, grad=False)[0]
        runs.append(StartRun(x0, x, float(f), int(res.nit), int(res.nfev), int(getattr(res, "njev", 0)),
                             bool(res.success), str(res.message)))
    return runs


def _free_index(option: int, n: int) -> np.ndarray:
    """Indices of the free variables in [beta_1..beta_n, phi_1..phi_(n-1)]."""
    return {1: np.arange(n, 2 * n - 1), 2: np.arange(n), 3: np.arange(2 * n - 1)}[option]


# --------------------------------------------------------------------------- deck checks

def _per(params: Params, key: str, count: int, what: str) -> np.ndarray:
    """A bound key: one value for all, or exactly ``count`` values."""
    v = params[key]
    if len(v) == 1:
        return np.full(count, float(v[0]))
    if len(v) != count:
        raise params.error(key, f"give one value for all {what} or exactly {count} (got {len(v)})")
    return np.asarray(v, float)


def _geometry(params: Params) -> tuple[np.ndarray, np.ndarray | None]:
    """Joint angles [deg] and plane angles [deg or None] from beta/rho or axes."""
    if params.axes is not None:
        if params.beta is not None:
            raise params.error("axes", "give either 'beta' (with optional 'rho') or 'axes', not both")
        if params.rho is not None:
            raise params.error("rho", "'axes' already fixes the plane angles; remove 'rho'")
        a = np.asarray(params.axes, float)
        if a.size % 3 or a.size < 6:
            raise params.error("axes", "needs x,y,z of at least two shafts (a multiple of 3 values, "
                                       f"at least 6; got {a.size})")
        a = a.reshape(-1, 3)
        for k, v in enumerate(a):
            if not np.linalg.norm(v) > 0.0:
                raise params.error("axes", f"shaft {k} direction ({', '.join(map(str, v))}) has zero "
                                           "length; every shaft needs a nonzero direction")
        beta, rho, status = ujoint_geometry(a)
        if status != 0:
            k = int(np.argmax(beta >= 0.5 * math.pi))
            raise params.error("axes", f"joint {k + 1} bends by {beta[k] / DEG:.4f} deg; a joint angle "
                                       "must lie strictly between -90 and 90 deg")
        return beta / DEG, rho / DEG
    if params.beta is None:
        raise params.error(None, "give the joint angles 'beta' (deg) or the shaft directions 'axes'")
    beta = np.asarray(params.beta, float)
    rho = None
    if params.rho is not None:
        rho = np.asarray(params.rho, float)
        if rho.size != beta.size - 1:
            raise params.error("rho", f"a chain of {beta.size} joint(s) has {beta.size - 1} plane "
                                      f"angle(s) between successive joints; got {rho.size}")
    return beta, rho


def _phases(params: Params, n: int, key: str | None = None) -> np.ndarray:
    """The paper's phases phi [deg] (n-1,) from phi or delta (default: in phase)."""
    keys = [key] if key else ["phi", "delta"]
    given = [k for k in keys if params[k] is not None]
    if len(given) > 1:
        raise params.error("delta", "give the phases either as 'phi' (90 = in phase) or as "
                                    "'delta' (0 = in phase), not both")
    if not given:
        return np.full(n - 1, 90.0)
    k = given[0]
    v = np.asarray(params[k], float)
    if v.size != n - 1:
        extra = (" (the paper's phi_3 does not exist: three joints on four shafts leave two "
                 "intermediate shafts)" if v.size > n - 1 else "")
        raise params.error(k, f"a chain of {n} joint(s) has {n - 1} intermediate shaft(s), so "
                              f"{n - 1} phase(s); got {v.size}{extra}")
    return v + 90.0 if k == "delta" else v


def cross_check(params: Params) -> None:
    """Cross-key checks (DeckError naming the key)."""
    beta, rho = _geometry(params)
    n = beta.size
    exact = params.model == "exact"
    if not exact:
        for k in ("rho", "axes"):
            if params[k] is not None:
                raise params.error(k, "plane angles need model = 'exact' (the paper's model is coplanar)")
    elif "phasing" in params.given:
        raise params.error("phasing", "applies only to model = 'paper' (the exact chain has no "
                                      "phasing choice)")
    _phases(params, n)
    blo = _per(params, "beta_lower", n, "joints")
    bhi = _per(params, "beta_upper", n, "joints")
    for key, v in (("beta_lower", blo), ("beta_upper", bhi)):
        msg = _open_angles(v)
        if msg:
            raise params.error(key, msg.replace("a joint angle", "a joint-angle bound"))
    if np.any(blo > bhi):
        k = int(np.argmax(blo > bhi))
        raise params.error("beta_lower", f"lower bound {blo[k]} deg exceeds upper bound {bhi[k]} deg "
                                         f"for joint {k + 1}; need beta_lower <= beta_upper")
    if n > 1:
        plo = _per(params, "phi_lower", n - 1, "phases")
        phi_hi = _per(params, "phi_upper", n - 1, "phases")
        if np.any(plo > phi_hi):
            k = int(np.argmax(plo > phi_hi))
            raise params.error("phi_lower", f"lower bound {plo[k]} deg exceeds upper bound {phi_hi[k]} "
                                            f"deg for phase {k + 1}; need phi_lower <= phi_upper")
    if params.option == 1 and n < 2:
        raise params.error("option", "option 1 optimises phases, but a single joint has none; "
                                     "use option 0 or 2")
    if params.option in (2, 3) and params.axes is not None:
        raise params.error("option", "with 'axes' the joint angles follow from the geometry; "
                                     "only options 0 and 1 apply (give 'beta' and 'rho' to free them)")
    if params.paper_beta is not None:
        if len(params.paper_beta) != n:
            raise params.error("paper_beta", f"needs {n} joint angle(s); got {len(params.paper_beta)}")
        msg = _open_angles(params.paper_beta)
        if msg:
            raise params.error("paper_beta", msg)
    if params.paper_phi is not None:
        _phases(params, n, "paper_phi")
    if params.paper_band is not None and len(params.paper_band) != 2:
        raise params.error("paper_band", f"needs two values (min, max rpm); got {len(params.paper_band)}")


#: axis labels of summary columns and deck keys (driver.study.column_label): name -> (words, units);
#: {i} is the number of a joint in the chain
LABELS = {"rpm": ("input shaft speed", "rpm"), "objective": ("objective (optimum)", "-"),
          "objective_trial": ("objective (trial)", "-"), "pp_ratio": ("peak-to-peak speed ratio", "-"),
          "omega_out_min_rpm": ("minimum output speed", "rpm"), "omega_out_max_rpm": ("maximum output speed", "rpm"),
          "beta_e_deg": ("equivalent joint angle", "deg"), "beta_res_deg": ("resultant joint angle", "deg"),
          "peak_accel_rad_s2": ("peak output acceleration", "rad/s^2"), "iterations": ("iterations", "-"),
          "evaluations": ("objective evaluations", "-"), "beta_{i}_deg": ("joint angle beta{i}", "deg"),
          "phi_{i}_deg": ("phase angle phi{i}", "deg")}
#: what a sweep summary plots when its deck names no plot_y
SWEEP_PLOT = ("omega_out_min_rpm", "omega_out_max_rpm", "pp_ratio", "beta_e_deg", "peak_accel_rad_s2", "objective")


SPEC = GroupSpec("ujoint", _KEYS, check=cross_check,
                 doc="Hooke-joint shaft chain: speed fluctuation, exact 3-D kinematics, SSO options 0-3")


# --------------------------------------------------------------------------- run

def _chain(params: Params, rho_deg: np.ndarray | None, n: int, model: str | None = None) -> Chain:
    model = model or (params.model if params.model == "exact" else params.phasing)
    rho = np.zeros(n - 1) if rho_deg is None else np.asarray(rho_deg, float) * DEG
    return Chain(UJOINT_MODELS[model], UJOINT_OBJECTIVES[params.objective], rho, params.n_grid, params.rpm)


def _model_text(params: Params) -> str:
    if params.model == "exact":
        return ("exact chain: theta_(k+1) = theta_out,k + phi_k - rho_k, tan theta_out,k = "
                "cos beta_k tan theta_k")
    if params.phasing == "cumulative":
        return "paper, cumulative phasing (the text): joint k driven at theta + phi_1 + .. + phi_(k-1)"
    return "paper, eq. 13 as printed: joint k driven at theta + phi_(k-1)"


def _starts(params: Params, option: int, beta: np.ndarray, phi: np.ndarray, lb: np.ndarray,
            ub: np.ndarray, chain: Chain) -> tuple[np.ndarray, list[str]]:
    """Start points [rad] (trial first, clipped into the bounds) and notes on what was done."""
    n = beta.size
    free = _free_index(option, n)
    x_trial = np.concatenate([beta, phi])[free] * DEG
    notes = []
    x0 = np.clip(x_trial, lb, ub)
    names = [f"beta_{k + 1}" for k in range(n)] + [f"phi_{k + 1}" for k in range(n - 1)]
    for j in np.flatnonzero(x0 != x_trial):
        notes.append(f"trial {names[free[j]]} = {x_trial[j] / DEG:g} deg lies outside its bounds "
                     f"[{lb[j] / DEG:g}, {ub[j] / DEG:g}]; the search starts from {x0[j] / DEG:g} "
                     "(fmincon would have started infeasible)")
    nph = int(np.sum(free >= n))
    if nph:
        ph_full = np.concatenate([beta, phi])[n:] * DEG
        ph_full[free[free >= n] - n] = x0[free >= n]
        if _symmetric(chain, ph_full):
            iph = np.flatnonzero(free >= n)
            step = SADDLE_NUDGE * DEG
            x0[iph] = np.where(x0[iph] + step <= ub[iph], x0[iph] + step, x0[iph] - step)
            notes.append(f"the trial phases sit on the symmetric assembly (all shifts multiples of "
                         f"90 deg) where the phase gradient vanishes identically (a saddle for "
                         f"free phases); start 1 is moved {SADDLE_NUDGE:g} deg off it")
    rng = np.random.default_rng(params.seed)
    rand = lb + (ub - lb) * rng.random((params.n_starts - 1, lb.size))
    return np.vstack([x0, rand]), notes


def estimate(params: Params) -> Estimate:
    """Memory and work of a run from the keys alone (driver.limits).

    Per input angle of the grid and joint about 200 bytes of kernel arrays and 20 ns per
    objective evaluation; SLSQP evaluates objective and gradient about (variables + 1) times per
    iteration for every start; each speed-table row costs about 1 KB and 20 us to format.
    """
    p = params
    joints = max(len(p.beta or []), len(p.phi or []) + 1, 2)
    m = float(p.n_grid)
    try:
        rows = math.floor(360.0 / p.table_step + 1e-9) + 1.0
    except (OverflowError, ZeroDivisionError):
        rows = math.inf
    evals = 0.0 if p.option == 0 else float(p.n_starts) * p.maxiter * (2 * joints + 1)
    mem = Estimate(200.0 * m * joints + 5e6, 2e-8 * m * joints * (evals + 10), "n_grid",
                   "n_starts" if p.option else "n_grid", f"{m:.4g} grid angles x {joints} joints"
                   + (f", about {evals:.3g} objective evaluations" if evals else ""))
    table = Estimate(1000.0 * rows * joints, 2e-5 * rows * joints, "table_step", "table_step",
                     f"{rows:.4g} speed-table rows")
    return mem + table


@keyword_run
def run(params: Params, progress: bool = False) -> Result:
    """Analyse (option 0) or optimise (options 1-3) the chain of the deck."""
    beta, rho = _geometry(params)
    n = beta.size
    phi = _phases(params, n)
    chain = _chain(params, rho, n)
    trial = evaluate(chain, "trial" if params.option else "design", beta, phi)
    designs = [trial]
    warnings: list[str] = []
    notes: list[str] = []
    runs: list[StartRun] = []
    failure = None
    best = None
    option = params.option
    if option:
        free = _free_index(option, n)
        lo = np.concatenate([_per(params, "beta_lower", n, "joints"),
                             _per(params, "phi_lower", n - 1, "phases") if n > 1 else []])
        hi = np.concatenate([_per(params, "beta_upper", n, "joints"),
                             _per(params, "phi_upper", n - 1, "phases") if n > 1 else []])
        lb, ub = lo[free] * DEG, hi[free] * DEG
        starts, start_notes = _starts(params, option, beta, phi, lb, ub, chain)
        notes += start_notes
        runs = optimise(chain, option, beta * DEG, phi * DEG, lb, ub, starts, params.maxiter, params.ftol,
                        progress)
        ok = [r for r in runs if r.success]
        ipick = min((k for k, r in enumerate(runs) if r.success or not ok), key=lambda k: runs[k].f)
        pick = runs[ipick]
        z = np.concatenate([beta, phi])
        z[free] = pick.x / DEG
        best = evaluate(chain, "optimum" if ok else "last iterate", z[:n], z[n:])
        best.extra = {"run": pick, "index": ipick + 1}
        designs.append(best)
        if not ok:
            failure = (f"the optimiser did not converge from any of {len(runs)} start(s) "
                       f"(best start: {pick.message}); no optimum is reported")
            warnings.append(failure)
    printed = None
    if params.paper_beta is not None or params.paper_phi is not None:
        pb = np.asarray(params.paper_beta if params.paper_beta is not None else beta, float)
        pp = _phases(params, n, "paper_phi") if params.paper_phi is not None else phi
        printed = evaluate(chain, "paper printed", pb, pp)
        designs.append(printed)
    text = _render(params, chain, beta, rho, designs, runs, notes, warnings, failure)
    tidy = _tidy(chain, designs)
    summary = _summary(trial, best, runs, failure)
    extra = {".result.dat": _result_dat(params, chain, designs, best, runs)} if best is not None else {}
    title = params.path.stem if getattr(params, "path", None) else ""
    figures = [Figure("speed", lambda: _figure(chain, designs, False, params.paper_band, title)),
               Figure("polar", lambda: _figure(chain, designs, True, params.paper_band, title))]
    return Result(text=text, tidy=tidy, summary=summary, warnings=warnings, failure=failure,
                  figures=figures, extra=extra)


# --------------------------------------------------------------------------- outputs

def _table_theta(params: Params) -> np.ndarray:
    """Input angles of the speed table [deg]: 0 to 360 in table_step."""
    return np.arange(0.0, 360.0 + 1e-9, params.table_step)


def _speed(chain: Chain, d: Design, theta_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(omega_out [rpm], alpha_out [rad/s^2], theta_out [deg]) of design d at theta_deg."""
    r, dr, to = ujoint_speed(chain.model, d.beta * DEG, d.phi * DEG, chain.rho, theta_deg * DEG)
    return chain.rpm * r, chain.omega ** 2 * dr, to / DEG


def _fmt(x: float | None, d: int = 4) -> str:
    return "n/a" if x is None else fortran_f(x, None, d)


def _es(x: float, d: int = 5) -> str:
    """Fortran ES editing (e.g. ES12.5 -> '3.08895E-08') for objectives spanning decades.

    (driver.table.fortran_f renders tiny values with 7+ decimals as '3E-8' through
    Decimal.__str__, so objective columns use this instead.)
    """
    if not math.isfinite(x):
        raise ValueError(f"non-finite objective {x!r}")
    return f"{x:.{d}E}"


def _render(params: Params, chain: Chain, beta, rho, designs: list[Design], runs: list[StartRun],
            notes: list[str], warnings: list[str], failure: str | None) -> str:
    n = beta.size
    option = params.option
    exact = params.model == "exact"
    out = [" HOOKE-JOINT SHAFT CHAIN  (&ujoint; seed 000, Fajar: Shaft Series Optimisation, SSO)", ""]
    hdr = [("deck", str(params.path)),
           ("model", _model_text(params)),
           ("joints", f"{n} on {n + 1} shafts; {n - 1} intermediate shaft(s), so {n - 1} phase(s)"),
           ("input speed", f"{fortran_f(params.rpm, None, 4)} rpm = {fortran_f(chain.omega, None, 6)} rad/s"),
           ("option", f"{option} ({OPTIONS[option]})"),
           ("objective", {"mean_square": "mean_square: U = mean over one revolution of (R - 1)^2, "
                                         "R = omega_out/omega_in [-]",
                          "rms": "rms: sqrt(mean (R - 1)^2) [-]",
                          "peak_to_peak": "peak_to_peak: max R - min R on the grid [-]"}[params.objective]),
           ("grid", f"{params.n_grid} input angles per revolution (theta from the normal to joint 1's plane)"),
           ("phases", "phi (the paper's convention): 90 deg = yokes on the shaft in phase; "
                      "yoke phase delta = phi - 90")]
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
    out += [f" {k:<{width}} : {v}" for k, v in hdr] + [""]

    out.append(" DESIGNS (angles in deg)")
    cols = [Column("design", "s", 14)] + [Column(f"beta_{k + 1}", "f", 9, 4) for k in range(n)] + \
           [Column(f"phi_{k + 1}", "f", 9, 4) for k in range(n - 1)] + \
           [Column(f"delta_{k + 1}", "f", 9, 4) for k in range(n - 1)]
    rows = [[d.label, *d.beta, *d.phi, *(d.phi - 90.0)] for d in designs]
    out += render_table(cols, rows) + [""]

    out.append(" PERFORMANCE (under this deck's model and objective; rpm at the input speed)")
    cols = [Column("design", "s", 14), Column("objective", "s", 12), Column("U rpm^2", "s", 12),
            Column("p-p ratio", "f", 10, 6), Column("w_min rpm", "f", 10, 4),
            Column("w_max rpm", "f", 10, 4), Column("beta_e", "f", 8, 4), Column("beta_res", "s", 9),
            Column("peak acc", "f", 11, 6)]
    rows = [[d.label, _es(d.objective), _es(d.u_rpm2), d.pp, d.w_min, d.w_max, d.beta_e, _fmt(d.beta_res),
             d.peak_acc] for d in designs]
    out += render_table(cols, rows)
    out += ["   beta_e [deg]: first-order residual angle, beta_e^2 = |sum beta_k^2 exp(2i gamma_k)| "
            "(p-p ratio ~ beta_e^2 [rad^2])",
            "   beta_res [deg]: the single joint the exact chain equals (closed form; n/a unless every "
            "phi_k - rho_k is a multiple of 90 deg)",
            "   peak acc [rad/s^2]: max |d omega_out/dt| at constant input speed", ""]
    printed = next((d for d in designs if d.label == "paper printed"), None)
    if printed is not None and params.paper_u is not None:
        nit = f", {params.paper_nit} iterations" if params.paper_nit is not None else ""
        nfev = f", {params.paper_nfev} function evaluations" if params.paper_nfev is not None else ""
        out.append(f" The paper prints U = {params.paper_u:g}{nit}{nfev} for its optimum. That value "
                   "cannot be reproduced under any")
        out.append(" tested definition of U (see the study notes); the row above evaluates the printed "
                   "design under this deck's objective.")
        out.append("")

    if runs:
        out += _render_runs(runs, designs[1], _free_names(option, n))
    out += _render_compare(params, chain, designs)
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
    lo = _per(params, f"{base}_lower", count, "")
    hi = _per(params, f"{base}_upper", count, "")
    return "  ".join(f"[{fortran_f(a, None, 4)}, {fortran_f(b, None, 4)}]" for a, b in zip(lo, hi)) + " deg"


def _free_names(option: int, n: int) -> list[str]:
    names = [f"beta_{k + 1}" for k in range(n)] + [f"phi_{k + 1}" for k in range(n - 1)]
    return [names[i] for i in _free_index(option, n)]


def _family(runs: list[StartRun], pick: StartRun, n_beta: int) -> tuple[int, np.ndarray]:
    """Converged starts that reach the best objective, and their distinct end points [deg]
    (rounded to 0.01 deg; phases taken modulo 180 deg)."""
    tol = 1e-6 * abs(pick.f) + 1e-12
    good = [r for r in runs if r.success and r.f <= pick.f + tol]
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
    close, distinct = _family(runs, pick, n_beta) if ok else (0, np.empty((0, len(names))))
    out = [" OPTIMISER (scipy SLSQP per start; objective values unscaled)"]
    cols = [Column("start", "i", 5), Column("objective", "s", 14), Column("iter", "i", 5),
            Column("f-evals", "i", 7), Column("status", "s", 9)]
    rows = [[k + 1, _es(r.f, 7), r.nit, r.nfev, "converged" if r.success else "FAILED"] for k, r in enumerate(runs)]
    trail = ["<- best" if k + 1 == idx else (r.message if not r.success else "") for k, r in enumerate(runs)]
    out += render_table(cols, rows, trail)
    out += [f"   best start {idx}: {pick.nit} iterations, {pick.nfev} function evaluations "
            f"({pick.njev} gradient evaluations); all starts: {sum(r.nit for r in runs)} iterations, "
            f"{sum(r.nfev for r in runs)} evaluations",
            f"   {ok} of {len(runs)} start(s) converged; {close} reached the best objective "
            f"(within 1e-6 relative) at {len(distinct)} distinct point(s) (0.01 deg; phases mod 180)"]
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
    out = [" MODEL COMPARISON (same angles; omega_out band in rpm, p-p ratio)"]
    cols = [Column("design", "s", 14), Column("model", "s", 25), Column("w_min rpm", "f", 10, 4),
            Column("w_max rpm", "f", 10, 4), Column("p-p ratio", "f", 10, 6), Column("objective", "s", 12)]
    rows = []
    for d in designs:
        for label, code in models:
            e = evaluate(chain, d.label, d.beta, d.phi, model=UJOINT_MODELS[code])
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


def _render_speed_table(params: Params, chain: Chain, designs: list[Design], exact: bool) -> list[str]:
    th = _table_theta(params)
    shown = [d for d in designs if d.label != "paper printed"]
    out = [" SPEED TABLE over the input angle (omega_in = "
           f"{fortran_f(params.rpm, None, 4)} rpm constant; acc = d omega_out/dt)"]
    cols = [Column("theta_in", "f", 9, 2)]
    data = []
    for d in shown:
        w, a, to = _speed(chain, d, th)
        tag = {"optimum": "opt", "last iterate": "last"}.get(d.label, d.label)
        cols += [Column(f"{tag} w_out", "f", 12, 5), Column(f"{tag} ratio", "f", 11, 7),
                 Column(f"{tag} acc", "f", 11, 6)]
        data += [w, w / params.rpm, a]
        if exact:
            cols.append(Column(f"{tag} th_out", "f", 11, 4))
            data.append(to)
    rows = [[t, *(c[i] for c in data)] for i, t in enumerate(th)]
    out += render_table(cols, rows)
    out.append("   units: theta_in, th_out [deg]; w_out [rpm]; ratio [-]; acc [rad/s^2]")
    out.append("")
    return out


def _tidy(chain: Chain, designs: list[Design]) -> pd.DataFrame:
    theta = np.arange(chain.m) * (360.0 / chain.m)
    frames = []
    for d in designs:
        w, a, to = _speed(chain, d, theta)
        frame = pd.DataFrame({"design": d.label, "theta_in_deg": theta, "omega_in_rpm": chain.rpm,
                              "omega_out_rpm": w, "ratio": w / chain.rpm, "alpha_out_rad_s2": a})
        if chain.model == UJOINT_MODELS["exact"]:
            frame["theta_out_deg"] = to
        frames.append(frame)
    return with_units(pd.concat(frames, ignore_index=True), {"ratio": "1"})


def _summary(trial: Design, best: Design | None, runs: list[StartRun], failure: str | None) -> dict:
    d = best if best is not None else trial
    s = {"objective": d.objective, "objective_trial": trial.objective, "pp_ratio": d.pp,
         "omega_out_min_rpm": d.w_min, "omega_out_max_rpm": d.w_max, "beta_e_deg": d.beta_e,
         "beta_res_deg": d.beta_res,   # None when the closed form does not apply
         "peak_accel_rad_s2": d.peak_acc, "converged": failure is None,
         "iterations": sum(r.nit for r in runs), "evaluations": sum(r.nfev for r in runs)}
    s.update({f"beta_{k + 1}_deg": float(v) for k, v in enumerate(d.beta)})
    s.update({f"phi_{k + 1}_deg": float(v) for k, v in enumerate(d.phi)})
    return s


def _result_dat(params: Params, chain: Chain, designs: list[Design], best: Design,
                runs: list[StartRun]) -> str:
    """The paper's post-processing 'save result': optimum, objective and its speed curve."""
    pick = best.extra["run"]
    lines = ["% result.dat of &ujoint (SSO post-processing 'save result'); angles in deg",
             f"% deck {params.path}; model {_model_text(params)}; objective {params.objective}",
             f"option     = {params.option}",
             "x          = " + " ".join(fortran_f(v, None, 6) for v in np.concatenate([best.beta, best.phi])),
             f"fval       = {best.objective:.10e}",
             f"exitflag   = {1 if pick.success else 0}",
             f"iterations = {pick.nit}",
             f"funccount  = {pick.nfev}",
             *([] if pick.success else ["% NOT CONVERGED: x is the last iterate, not an optimum"]),
             "% theta_in_deg  omega_in_rpm  omega_out_trial_rpm  omega_out_optimum_rpm"]
    th = np.arange(0.0, 360.0 + 1e-9, 1.0)
    w0 = _speed(chain, designs[0], th)[0]
    w1 = _speed(chain, best, th)[0]
    lines += [f"{fortran_f(t, 8, 2)} {fortran_f(params.rpm, 12, 6)} {fortran_f(a, 14, 8)} {fortran_f(b, 14, 8)}"
              for t, a, b in zip(th, w0, w1)]
    return "\n".join(lines) + "\n"


def _figure(chain: Chain, designs: list[Design], polar: bool, band: list[float] | None = None, title: str = ""):
    """The speed figure: every design overlaid, the paper's trial band (``paper_band``) shaded."""
    from driver.plotting import ujoint_speed_figure
    theta = np.arange(0.0, 360.0 + 1e-9, 1.0)
    curves = {d.label: _speed(chain, d, theta)[0] for d in designs}
    return ujoint_speed_figure(theta, chain.rpm, curves, polar=polar, band=band, title=title)
