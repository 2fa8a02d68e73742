"""Hooke-joint (universal-joint) shaft chains: the paper's SSO package, corrected and extended.

[Fajar] (M. Fajar, "Optimasi kecepatan sudut keluaran kopeling universal pada poros seri"):
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
See docs/ujoint.md for what reproduces and what does not.
"""
from __future__ import annotations

import math
import re
import textwrap
from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np
import pandas as pd
from scipy.optimize import minimize
from tqdm import tqdm

from driver.deck import GroupSpec, Key, Params, non_empty, positive
from driver.export import with_units
from driver.limits import Estimate
from driver.kernels import (UJOINT_MODELS, UJOINT_OBJECTIVES, UJOINT_SUMMARY_COLUMNS, ujoint_equivalent,
                            ujoint_geometry, ujoint_objective, ujoint_speed, ujoint_summaries)
from driver.study import Figure, Result, keyword_run
from driver.table import Column, fortran_f, render_table

__all__ = ["SPEC", "run", "Chain", "Design", "evaluate", "optimise", "summarise_batch", "batch_applies", "BATCH_KEYS",
           "BAND_TOL", "NOT_REPRODUCIBLE"]

DEG = math.pi / 180.0
OPTIONS = {0: "analyse only", 1: "phases free, joint angles fixed",
           2: "joint angles free, phases fixed", 3: "joint angles and phases free"}
#: phases within this of a symmetric assembly count as sitting on it [rad]
SYM_TOL = 1e-7
#: how far a start is moved off the symmetric saddle [deg]
SADDLE_NUDGE = 1.0
#: reading precision of the paper's plotted bands [rpm] (it quotes whole rpm)
BAND_TOL = 1.0
#: the phases repeat every half turn (each joint's ratio depends on sin^2 of its input angle)
PHASE_PERIOD = 180.0
#: optima within this relative difference of the best objective tie (the mirror optima of a
#: symmetric chain differ only by rounding); ties are broken by TIE RULE in :func:`pick_best`
TIE_RTOL = 1e-6
#: tied end points closer than this are one optimum [deg] (the tie rule then takes the most
#: converged of them, so the reported digits do not depend on which start stopped first)
CLUSTER_TOL = 0.05
#: a start that ends within this of a bound counts as ended on it [rad]
BOUND_TOL = 1e-7
#: how the θ, ρ and output angles are measured (printed in --keys and every .out)
CONVENTIONS = (
    "theta (the input angle) and every shaft angle turn right-handed about their shaft's "
    "direction (input towards output; the 'axes' vectors); theta = 0 when joint 1's input yoke "
    "lies along the normal to the plane of joint 1. rho_k > 0 when the plane of joint k+1 is "
    "turned right-handed about shaft k from the plane of joint k. th_out is the last joint's "
    "output yoke angle from the normal to the plane of the last joint, in the sense of theta; "
    "it includes the phases (in phase: th_out = theta + 90 (n-1) deg + the joints' error)")

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
            doc="angle between the planes of joints k and k+1 about their shared shaft k, "
            "positive right-handed about the shaft's direction (input towards output) "
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
                "or theta+phi_(k-1) (eq. 13 as printed; the yoke phase of shaft k is then "
                "phi_k - phi_(k-1) - 90, and every derived figure uses it)"),
    option=Key("int", default=0, choices=(0, 1, 2, 3),
               doc="0 analyse, 1 phases free, 2 angles free (phases fixed), 3 both free"),
    objective=Key("str", default="mean_square", choices=("mean_square", "rms", "peak_to_peak"),
                  doc="mean (R-1)^2 over a revolution (the paper's U per omega_in^2), "
                  "its root, or max R - min R; R = omega_out/omega_in"),
    beta_lower=Key("floats", default=[0.0], units="deg", doc="lower bound(s) on joint angles"),
    beta_upper=Key("floats", default=[40.0], units="deg",
                   doc="upper bound(s) on joint angles (the paper: 40)"),
    phi_lower=Key("floats", default=[0.0], units="deg", doc="lower bound(s) on phases phi"),
    phi_upper=Key("floats", default=[180.0], units="deg",
                  doc="upper bound(s) on phases phi; bounds spanning 180 deg or more make the "
                  "phase periodic (searched without bounds, reported in [phi_lower, phi_lower+180))"),
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
             doc="SLSQP tolerance on the objective divided by its scale, the larger of the "
             "trial's value and a single joint's at the largest joint angle; objectives below "
             "ftol times the scale are reported as below the resolution"),
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


def yoke_shifts(model: int, phi_deg) -> np.ndarray:
    """The phase shift between joints k and k+1 of a design's phases [deg], in the
    cumulative/exact convention: phi itself, or phi_k - phi_(k-1) under eq. 13 as printed
    (where phi_k is the absolute phase of joint k+1)."""
    phi = np.asarray(phi_deg, float)
    return np.diff(phi, prepend=0.0) if model == UJOINT_MODELS["eq13"] else phi


def phases_for(model: int, shifts_deg) -> np.ndarray:
    """The phases [deg] that give the shifts ``shifts_deg`` under ``model`` (inverse of
    :func:`yoke_shifts`): the same physical assembly in another model's convention."""
    s = np.asarray(shifts_deg, float)
    return np.cumsum(s) if model == UJOINT_MODELS["eq13"] else s


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
    on_bound: np.ndarray = field(default_factory=lambda: np.empty(0, int))  # free-variable indices


def _symmetric(chain: Chain, phi_rad: np.ndarray) -> bool:
    """True when every phase shift is a multiple of 90 deg: the theta -> -theta symmetric
    assembly where the phase gradient vanishes identically (a saddle or a maximum)."""
    shift = phi_rad - (chain.rho if chain.model == UJOINT_MODELS["exact"] else 0.0)
    q = shift / (0.5 * math.pi)
    return bool(np.all(np.abs(q - np.round(q)) * 0.5 * math.pi < SYM_TOL))


def optimise(chain: Chain, option: int, beta0: np.ndarray, phi0: np.ndarray,
             lb: np.ndarray, ub: np.ndarray, starts: np.ndarray, maxiter: int,
             ftol: float, scale: float, progress: bool = False) -> list[StartRun]:
    """SLSQP from every row of ``starts`` (free variables, rad) with the kernel gradient.

    beta0, phi0 [rad] hold the fixed variables; lb/ub the bounds of the free ones [rad].
    The objective is divided by ``scale`` (:func:`objective_scale`, never 0) so ``ftol`` is
    relative.  Phases whose bounds span a period are searched unbounded and wrapped into
    [lb, lb + 180 deg): a bound there is no stopping point.
    """
    n = beta0.size
    free = _free_index(option, n)

    def full(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        z = np.concatenate([beta0, phi0])
        z[free] = x
        return z[:n], z[n:]

    fref = scale

    def fun(x: np.ndarray) -> tuple[float, np.ndarray]:
        b, p = full(x)
        f, g = ujoint_objective(chain.model, chain.kind, b, p, chain.rho, chain.m)
        return f / fref, g[free] / fref

    periodic = _periodic(option, n, lb, ub)
    bounds = [(None, None) if per else (a, b) for per, a, b in zip(periodic, lb, ub)]
    runs = []
    for x0 in tqdm(starts, desc="multi-start", unit="start", disable=not progress):
        res = minimize(fun, x0, jac=True, method="SLSQP", bounds=bounds,
                       options={"maxiter": maxiter, "ftol": ftol})
        x = np.where(periodic, lb + np.mod(res.x - lb, PHASE_PERIOD * DEG), np.clip(res.x, lb, ub))
        f = ujoint_objective(chain.model, chain.kind, *full(x), chain.rho, chain.m, grad=False)[0]
        on_bound = ~periodic & (lb < ub) & ((x - lb < BOUND_TOL) | (ub - x < BOUND_TOL))
        runs.append(StartRun(x0, x, float(f), int(res.nit), int(res.nfev), int(getattr(res, "njev", 0)),
                             bool(res.success), str(res.message), np.flatnonzero(on_bound)))
    return runs


def _periodic(option: int, n: int, lb: np.ndarray, ub: np.ndarray) -> np.ndarray:
    """Which free variables are phases whose bounds span a whole period (searched unbounded)."""
    is_phase = _free_index(option, n) >= n
    return is_phase & (ub - lb >= PHASE_PERIOD * DEG * (1.0 - 1e-12))


def objective_scale(chain: Chain, f_trial: float, beta_max_deg: float) -> float:
    """The objective's scale, which cannot vanish: the larger of the trial's value and a
    single joint's objective at the largest joint angle the run can reach (1 if that is 0)."""
    b = np.array([abs(beta_max_deg) * DEG])
    ref = ujoint_objective(chain.model, chain.kind, b, None, None, chain.m, grad=False)[0]
    scale = max(f_trial, ref)
    return scale if scale > 0.0 else 1.0


def pick_best(runs: list[StartRun], n_beta: int) -> int:
    """Index of the reported optimum among the starts (TIE RULE, deterministic).

    Converged starts within TIE_RTOL (relative) of the best objective tie (mirror optima
    agree to rounding; along a continuous family of optima the most converged start wins).  Among them the trial start (index 0) wins if it is there (so feeding an
    optimum back as the trial reproduces it); otherwise the smallest phases, compared
    lexicographically at 1e-6 deg, then the smallest joint angles; the tied starts within
    CLUSTER_TOL of that end point are one optimum, and the one of them with the lowest
    objective is reported (then the start order).  With no converged start, the lowest objective (a last iterate, reported as such).
    """
    ok = [k for k, r in enumerate(runs) if r.success]
    if not ok:
        return min(range(len(runs)), key=lambda k: runs[k].f)
    fbest = min(runs[k].f for k in ok)
    tied = [k for k in ok if runs[k].f <= fbest + TIE_RTOL * abs(fbest)]
    if 0 in tied:
        return 0

    def key(k: int) -> tuple:
        x = np.round(runs[k].x / DEG, 6)
        return (*x[n_beta:], *x[:n_beta], k)
    first = runs[min(tied, key=key)].x
    same = [k for k in tied if _distance_deg(runs[k].x, first, n_beta) < CLUSTER_TOL]
    return min(same, key=lambda k: (runs[k].f, k))


def _distance_deg(x: np.ndarray, y: np.ndarray, n_beta: int) -> float:
    """Largest difference between two points of the free variables [deg], phases modulo 180."""
    d = np.abs(x - y) / DEG
    d[n_beta:] = np.minimum(d[n_beta:] % PHASE_PERIOD, PHASE_PERIOD - d[n_beta:] % PHASE_PERIOD)
    return float(d.max(initial=0.0))


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
                 "intermediate shafts)" if n == 3 and v.size > n - 1 else "")
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
                 doc="Hooke-joint shaft chain: speed fluctuation, exact 3-D kinematics, SSO options 0-3. "
                 "Conventions: " + CONVENTIONS)


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
            starts, start_notes = _starts(params, option, beta, phi, lb, ub, chain)
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


# --------------------------------------------------------------------------- batch summaries

#: deck keys a batch may vary (one value per design); list keys as one value per design (a
#: single-element list, as a sweep sets them), a (designs, k) array of whole lists, or element
#: columns 'key(i)' (:data:`BATCH_ELEMENTS`)
BATCH_KEYS = ("beta", "phi", "delta", "rho", "rpm", "model", "phasing", "objective", "n_grid")
#: keys the summary of an option-0 run does not depend on (accepted, ignored)
BATCH_IGNORED = ("table_step", "n_starts", "seed", "maxiter", "ftol", "beta_lower", "beta_upper", "phi_lower",
                 "phi_upper", "paper_beta", "paper_phi", "paper_u", "paper_nit", "paper_nfev", "paper_band")
#: keys whose deck checks do not involve other keys (a sweep validates each of their values once)
BATCH_INDEPENDENT = ("rpm", "objective", "n_grid", "table_step", "n_starts", "seed", "maxiter", "ftol",
                     "paper_u", "paper_nit", "paper_nfev")
#: list keys a batch column may set one element of, as 'phi(2)' (1-based; the optimiser's variables)
BATCH_ELEMENTS = ("beta", "phi", "delta", "rho")
_ELEMENT = re.compile(r"([a-z_]+)\((\d+)\)")


def batch_applies(base: Mapping[str, Any]) -> bool:
    """Whether designs on ``base`` can take the batch path: option 0 only (options 1-3 run an
    optimisation per case, which the batch does not)."""
    return int(base["option"]) == 0


def _bad(base: Mapping[str, Any], key: str | None, message: str) -> Exception:
    """A DeckError at the key's deck line when ``base`` is a deck's Params, else a ValueError."""
    if isinstance(base, Params):
        return base.error(key, message)
    return ValueError(f"{key}: {message}" if key else message)


def _design_count(base: Mapping[str, Any], columns: dict[str, Any]) -> int:
    sizes = {np.shape(v)[0] for v in columns.values() if np.ndim(v) > 0}
    if len(sizes) > 1:
        raise _bad(base, None, f"batch columns have different lengths {sorted(sizes)}")
    return sizes.pop() if sizes else 1


def _list_column(base: Mapping[str, Any], key: str, whole: Any, elements: dict[int, Any], nd: int) -> np.ndarray | None:
    """(nd, k) float values of list key ``key`` [deg]: the base deck's list, or the batch's
    whole lists, with the batch's element columns set; None when neither gives the key."""
    if whole is not None:
        a = np.asarray(whole, dtype=np.float64)
        a = a[:, None] if a.ndim == 1 else (a.reshape(1, 1) if a.ndim == 0 else a)
        if a.ndim != 2:
            raise _bad(base, key, f"a batch column of lists must be (designs, values); got shape {a.shape}")
        a = np.broadcast_to(a, (nd, a.shape[1]))
    elif base.get(key) is not None:
        a = np.broadcast_to(np.asarray(base[key], dtype=np.float64), (nd, len(base[key])))
    elif elements:
        raise _bad(base, key, f"'{key}(i)' sets one element of '{key}', which the base deck does not give")
    else:
        return None
    if elements:
        a = a.copy()
        for i, v in elements.items():
            if not 1 <= i <= a.shape[1]:
                raise _bad(base, key, f"'{key}({i})': '{key}' has {a.shape[1]} value(s)")
            a[:, i - 1] = np.broadcast_to(np.asarray(v, dtype=np.float64), (nd,))
    bad = ~np.isfinite(a)
    if bad.any():
        i = int(np.argmax(bad.any(axis=1)))
        raise _bad(base, key, f"design {i} has a non-finite value")
    return a


def _choice_column(base: Mapping[str, Any], key: str, columns: dict[str, Any], nd: int) -> np.ndarray:
    v = np.broadcast_to(np.asarray(columns.get(key, base[key]), dtype=object), (nd,))
    allowed = _KEYS[key].choices
    bad = ~np.isin(v, allowed)
    if bad.any():
        raise _bad(base, key, f"must be one of {', '.join(map(repr, allowed))} (got {v[np.argmax(bad)]!r})")
    return v


def _codes(values: np.ndarray, table: dict[str, int]) -> np.ndarray:
    """Kernel codes of choice values (one lookup per distinct value)."""
    if values.size == 0:
        return np.zeros(0, dtype=np.int64)
    if values.strides == (0,) or (values == values[0]).all():
        return np.full(values.shape, table[values[0]], dtype=np.int64)
    uniq, inverse = np.unique(values.astype(str), return_inverse=True)
    return np.array([table[u] for u in uniq], dtype=np.int64)[inverse.ravel()]


def _number_column(base: Mapping[str, Any], key: str, columns: dict[str, Any], nd: int) -> np.ndarray:
    v = np.broadcast_to(np.asarray(columns.get(key, base[key]), dtype=np.float64), (nd,))
    if key == "rpm":
        bad = ~(np.isfinite(v) & (v > 0))
        what = "must be positive and finite"
    else:   # n_grid
        bad = ~(np.isfinite(v) & (v >= 8) & (v == np.round(v)))
        what = "must be a whole number of at least 8"
    if bad.any():
        i = int(np.argmax(bad))
        raise _bad(base, key, f"design {i} has {float(v[i])!r}: {what}")
    return v


def summarise_batch(base: Mapping[str, Any], columns: Mapping[str, Any] | None = None) -> pd.DataFrame:
    """Summaries of many Hooke-joint designs, one Fortran call per chain layout: one row per design.

    What it computes: for each design the figures of an option-0 run (``run(...).summary``:
    the design evaluated as given, nothing optimised), with identical values -- objective and
    objective_trial (the deck's objective over ``n_grid`` input angles per revolution,
    dimensionless), pp_ratio (max R - min R, R = omega_out/omega_in), omega_out_min_rpm and
    omega_out_max_rpm [rpm] at the input speed ``rpm``, beta_e_deg and beta_res_deg [deg]
    (closed-form equivalent angles; NaN where beta_res is undefined), peak_accel_rad_s2
    [rad/s^2] (max |d omega_out/dt| at constant input speed), converged (True), iterations
    and evaluations (0), beta_<k>_deg and phi_<k>_deg [deg] (the paper's phases, also when
    the design gives ``delta``).  The deck's own options 1-3 optimise inside each case; the
    batch path evaluates given designs (sweeps and the generic ``&optimize`` group) and
    refuses a base deck with option 1-3.

    ``base``: a validated ``&ujoint`` Params (or a mapping with its keys).  ``columns``:
    {key: values} for keys in BATCH_KEYS (``'ujoint.rpm'`` is accepted for ``'rpm'``);
    scalars broadcast.  Angles in degrees (as in the deck), ``rpm`` [rpm], ``model``,
    ``phasing``, ``objective`` as in the deck.  List keys (beta, phi, delta, rho): a 1-D
    column gives each design a single-element list (as a sweep does), a (designs, k) array
    whole lists, and ``'phi(2)'`` sets one element of the base deck's list.  A 3-D chain
    given by ``axes`` in the base deck keeps its geometry (beta and rho cannot vary then).
    A bad value raises DeckError (``base`` a deck's Params: deck, line and key of the base
    deck, the design's index in the message) or ValueError.  About 4 microseconds per
    3-joint design at 360 angles on one core (bench/bench_ujoint.py).
    """
    if not batch_applies(base):
        raise _bad(base, "option", f"option {base['option']} optimises inside each case; the batch path "
                                   "evaluates given designs (option 0)")
    cols: dict[str, Any] = {}
    elems: dict[str, dict[int, Any]] = {}
    for k, v in (columns or {}).items():
        k = k.partition(".")[2] if k.startswith("ujoint.") else k
        m = _ELEMENT.fullmatch(k)
        if m and m.group(1) in BATCH_ELEMENTS:
            elems.setdefault(m.group(1), {})[int(m.group(2))] = v
        elif k in BATCH_KEYS:
            cols[k] = v
        elif k not in BATCH_IGNORED:
            raise _bad(base, k, f"not a &ujoint key the summary depends on ({', '.join(BATCH_KEYS)}; "
                                f"elements of {', '.join(BATCH_ELEMENTS)} as 'key(i)')")
    nd = _design_count(base, {**cols, **{f"{k}({i})": v for k, e in elems.items() for i, v in e.items()}})
    axes = base.get("axes") is not None
    if axes and ({"beta", "rho"} & (set(cols) | set(elems))):
        raise _bad(base, "axes", "the base deck's 'axes' fix the joint and plane angles; a batch cannot vary "
                                 "'beta' or 'rho' then")
    if axes:   # as _geometry (the base deck is valid): kernel radians -> degrees
        b, r, _ = ujoint_geometry(np.asarray(base["axes"], dtype=np.float64).reshape(-1, 3))
        beta = np.broadcast_to(b / DEG, (nd, b.size))
        rho = np.broadcast_to(r / DEG, (nd, r.size))
    else:
        beta = _list_column(base, "beta", cols.get("beta"), elems.get("beta", {}), nd)
        if beta is None:
            raise _bad(base, None, "give the joint angles 'beta' (deg) or the shaft directions 'axes'")
        rho = _list_column(base, "rho", cols.get("rho"), elems.get("rho", {}), nd)
    n = beta.shape[1]
    bad = ~((beta > -90.0) & (beta < 90.0))
    if bad.any():
        i = int(np.argmax(bad.any(axis=1)))
        raise _bad(base, "beta", f"design {i}: a joint angle must lie strictly between -90 and 90 deg "
                                 f"(got {beta[i][bad[i]][0]})")
    given = {k for k in ("phi", "delta") if k in cols or k in elems or base.get(k) is not None}
    if len(given) > 1:
        raise _bad(base, "delta", "give the phases either as 'phi' (90 = in phase) or as 'delta' "
                                  "(0 = in phase), not both")
    if given:
        key = given.pop()
        phi = _list_column(base, key, cols.get(key), elems.get(key, {}), nd)
        if phi.shape[1] != n - 1:
            raise _bad(base, key, f"a chain of {n} joint(s) has {n - 1} intermediate shaft(s), so "
                                  f"{n - 1} phase(s); got {phi.shape[1]}")
        if key == "delta":
            phi = phi + 90.0
    else:
        phi = np.full((nd, n - 1), 90.0)
    if rho is not None and rho.shape[1] != n - 1:
        raise _bad(base, "rho", f"a chain of {n} joint(s) has {n - 1} plane angle(s) between successive "
                                f"joints; got {rho.shape[1]}")
    model = _choice_column(base, "model", cols, nd)
    phasing = _choice_column(base, "phasing", cols, nd)
    exact = model == "exact"
    if rho is not None and not exact.all():
        raise _bad(base, "axes" if axes else "rho", "plane angles need model = 'exact' (the paper's model "
                                                    "is coplanar)")
    if exact.any() and ("phasing" in cols or "phasing" in getattr(base, "given", ())):
        raise _bad(base, "phasing", "applies only to model = 'paper' (the exact chain has no phasing choice)")
    code = _codes(np.where(exact, "exact", phasing), UJOINT_MODELS)
    kind = _codes(_choice_column(base, "objective", cols, nd), UJOINT_OBJECTIVES)
    rpm = _number_column(base, "rpm", cols, nd)
    grid = _number_column(base, "n_grid", cols, nd).astype(np.int64)
    res = np.empty((nd, len(UJOINT_SUMMARY_COLUMNS)))
    rho_rad = None if rho is None else rho * DEG
    layout = np.stack([code, kind, grid])
    if nd == 0:
        groups = []
    elif (layout == layout[:, :1]).all():
        groups = [(layout[:, 0], slice(None))]
    else:
        keys, inverse = np.unique(layout, axis=1, return_inverse=True)
        groups = [(keys[:, g], np.flatnonzero(inverse.ravel() == g)) for g in range(keys.shape[1])]
    for (c, k, m), rows in groups:
        res[rows] = ujoint_summaries(int(c), int(k), beta[rows] * DEG, phi[rows] * DEG,
                                     None if rho_rad is None else rho_rad[rows], int(m))
    r = dict(zip(UJOINT_SUMMARY_COLUMNS, res.T))
    omega = rpm * 2.0 * math.pi / 60.0      # the association of Chain.omega (same bits)
    defined = r["beta_res_status"] == 0
    out = {"objective": r["objective"], "objective_trial": r["objective"],
           "pp_ratio": r["ratio_max"] - r["ratio_min"],
           "omega_out_min_rpm": rpm * r["ratio_min"], "omega_out_max_rpm": rpm * r["ratio_max"],
           "beta_e_deg": r["beta_e"] / DEG,
           "beta_res_deg": np.where(defined, r["beta_res"] / DEG, np.nan),
           "peak_accel_rad_s2": omega ** 2 * r["dratio_abs_max"],
           "converged": np.ones(nd, bool), "iterations": np.zeros(nd, np.int64),
           "evaluations": np.zeros(nd, np.int64)}
    out.update({f"beta_{k + 1}_deg": beta[:, k] for k in range(n)})
    out.update({f"phi_{k + 1}_deg": phi[:, k] for k in range(n - 1)})
    return pd.DataFrame(out)


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
           ("grid", f"{params.n_grid} input angles per revolution (theta from the normal to joint 1's plane)"),
           ("phases", "phi (the paper's convention): 90 deg = yokes on the shaft in phase; "
                      + ("yoke phase delta_k = phi_k - phi_(k-1) - 90 (eq. 13: phi_k is absolute)"
                         if chain.model == UJOINT_MODELS["eq13"] else "yoke phase delta = phi - 90"))]
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
    rows = [[d.label, _objective_text(d.objective, res), _objective_text(d.u_rpm2, ures), d.pp, d.w_min, d.w_max, d.beta_e, _fmt(d.beta_res),
             d.peak_acc] for d in designs]
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
    rows = []
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


def _render_speed_table(params: Params, chain: Chain, designs: list[Design], exact: bool) -> list[str]:
    th = _table_theta(params)
    shown = [d for d in designs if d.label != "paper printed"]
    out = [" SPEED TABLE over the input angle (omega_in = "
           f"{fortran_f(params.rpm, None, 4)} rpm constant; acc = d omega_out/dt)"]
    cols = [Column("theta_in", "f", 9, 2)]
    data = []
    for d in shown:
        w, a, to = _speed(chain, d, th)
        tag = {"optimum": "opt", "last iterate": "last", "fixed design": "fixed"}.get(d.label, d.label)
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
    fixed = pick is None
    lines = ["% result.dat of &ujoint (SSO post-processing 'save result'); angles in deg",
             f"% deck {params.path}; model {_model_text(params)}; objective {params.objective}",
             f"option     = {params.option}",
             "x          = " + " ".join(fortran_f(v, None, 6) for v in np.concatenate([best.beta, best.phi])),
             f"fval       = {best.objective:.10e}",
             f"exitflag   = {1 if fixed or pick.success else 0}",
             f"iterations = {0 if fixed else pick.nit}",
             f"funccount  = {1 if fixed else pick.nfev}",
             *(["% FIXED DESIGN: equal bounds fix every free variable; evaluated, not optimised"] if fixed
               else [] if pick.success else ["% NOT CONVERGED: x is the last iterate, not an optimum"]),
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
