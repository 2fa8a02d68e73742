"""Path generation: a four-bar whose coupler point passes through (or near) given points.

Unknowns (world frame): crank pivot O_A = (x0, y0), ground direction gamma, ground d, crank a,
coupler b, rocker c, coupler point (u along A->B, v to its left) and, with prescribed timing,
the crank angle at the first point.  For a candidate the exact kernel places the linkage at
``samples`` crank angles over a full turn (or at the prescribed angles) on the deck's branch;
the error of a target is its distance to the sampled coupler curve (without timing; for the
reported design refined by a bounded search on the kernel's coupler point) or to the coupler
point at its crank angle (with timing).  The objective is the RMS error; a candidate that cannot be
assembled over the motion, is not a crank (full rotation when asked), or leaves the
transmission-angle band is penalised by its violation (scipy differential evolution, seeded),
then trust-region least squares with every target's crank angle free, from the best
distinct feasible designs the evolution evaluated.  Lengths are bounded by ``length_max`` (default: 4 x the targets'
extent) and a tenth of the extent from below.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import differential_evolution

from driver.fourbar import _kernel as fourbar_kernel

__all__ = ["PathProblem", "PathDesign", "solve", "evaluate"]

ST_OK = fourbar_kernel.FOURBAR_STATUS["ok"]
PENALTY = 1e3
#: least-squares runs from the best distinct designs of the evolution
POLISH_STARTS = 24
#: steps of one least-squares run at most (the shipped decks' converge within 20; the bound keeps
#: a run that cannot converge, and so the synthesis's work, finite and known in advance)
POLISH_MAX_NFEV = 300
#: weight of the pull towards the start in the least-squares stage (see polish)
REG = 1e-6


@dataclass
class PathProblem:
    targets: np.ndarray            # (n, 2) world coordinates
    timing_deg: np.ndarray | None  # crank angles of the targets relative to the first, or None
    branch: int
    full_rotation: bool
    mu_band: tuple[float, float]
    length_min: float
    length_max: float
    samples: int = 360


@dataclass
class PathDesign:
    """A linkage in the world frame and its errors."""

    x: np.ndarray                  # the design vector (see module docstring)
    rms: float
    errors: np.ndarray             # per target [length]
    violation: float
    theta_at_targets_deg: np.ndarray

    @property
    def parts(self) -> dict[str, float]:
        names = ["x0", "y0", "gamma_deg", "ground", "crank", "coupler", "rocker", "u", "v", "theta1_deg"]
        return dict(zip(names, (float(v) for v in self.x)))


def bounds(pp: PathProblem) -> list[tuple[float, float]]:
    lo, hi = pp.targets.min(0), pp.targets.max(0)
    pad = pp.length_max
    b = [(lo[0] - pad, hi[0] + pad), (lo[1] - pad, hi[1] + pad), (-180.0, 180.0)]
    b += [(pp.length_min, pp.length_max)] * 4
    b += [(-pp.length_max, pp.length_max), (-pp.length_max, pp.length_max)]
    if pp.timing_deg is not None:
        b.append((0.0, 360.0))
    return b


def to_kernel_frame(pp: PathProblem, x: np.ndarray) -> np.ndarray:
    """Targets in the kernel frame of design x (O_A at the origin, O_B on +x)."""
    g = math.radians(x[2])
    c, s = math.cos(g), math.sin(g)
    rel = pp.targets - x[:2]
    return np.column_stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]])


def evaluate(pp: PathProblem, x: np.ndarray) -> PathDesign:
    """Errors and constraint violation of one design (exact kernel on the deck's branch)."""
    x = np.asarray(x, dtype=float)
    d, a, b, c, u, v = x[3:9]
    viol = 0.0
    links = sorted([d, a, b, c])
    if pp.full_rotation:
        # Grashof with the crank shortest: the crank turns fully (crank-rocker or drag link)
        viol += max(0.0, links[0] + links[3] - links[1] - links[2]) + max(0.0, a - links[0])
    theta = np.linspace(0.0, 360.0, pp.samples, endpoint=False)
    if pp.timing_deg is not None:
        theta = np.concatenate([theta, x[9] + pp.timing_deg])
    out, st = fourbar_kernel.fourbar_exact(np.radians(theta), d, a, b, c, 1.0, 0.0, pp.branch)
    cp = fourbar_kernel.fourbar_coupler_point(np.radians(theta), out, st, a, 1.0, 0.0, u, v)
    ok = st == ST_OK
    tk = to_kernel_frame(pp, x)
    n = len(tk)
    if pp.full_rotation or pp.timing_deg is None:
        motion = np.ones(len(theta), bool)
    else:   # only the arc the targets span must run
        t = np.mod(x[9] + pp.timing_deg - x[9], 360.0)
        span = float(t.max())
        motion = np.zeros(len(theta), bool)
        motion[: pp.samples] = np.mod(theta[: pp.samples] - x[9], 360.0) <= span
        motion[pp.samples:] = True
    bad = motion & ~ok
    viol += float(bad.mean()) * 10.0
    mu = np.degrees(out[:, fourbar_kernel.State.TRANSMISSION_ANGLE])
    lo, hi = pp.mu_band
    if (motion & ok).any():
        m = mu[motion & ok]
        viol += max(0.0, lo - float(m.min())) / 90.0 + max(0.0, float(m.max()) - hi) / 90.0
    curve = cp[: pp.samples, :2]
    good = ok[: pp.samples]
    if pp.timing_deg is not None:
        pts = cp[pp.samples:, :2]
        err = np.hypot(*(pts - tk).T)
        err = np.where(ok[pp.samples:], err, 10 * pp.length_max)
        at = np.mod(x[9] + pp.timing_deg, 360.0)
    else:
        if good.any():
            dist = np.hypot(curve[None, good, 0] - tk[:, 0, None], curve[None, good, 1] - tk[:, 1, None])
            k = np.argmin(dist, axis=1)
            err = dist[np.arange(n), k]
            at = theta[: pp.samples][good][k]
        else:
            err = np.full(n, 10 * pp.length_max)
            at = np.zeros(n)
    rms = float(np.sqrt(np.mean(err ** 2)))
    return PathDesign(x, rms, err, viol, at)


def refine(pp: PathProblem, design: PathDesign) -> PathDesign:
    """Exact distance of each target to the coupler curve near its nearest sample (no timing)."""
    if pp.timing_deg is not None:
        return design
    from scipy.optimize import minimize_scalar
    x = design.x
    d, a, b, c, u, v = x[3:9]
    tk = to_kernel_frame(pp, x)
    step = 360.0 / pp.samples
    errs, ats = [], []
    for (tx, ty), t0, e0 in zip(tk, design.theta_at_targets_deg, design.errors):
        def dist(t: float, tx: float = tx, ty: float = ty) -> float:
            th = np.radians([t])
            out, st = fourbar_kernel.fourbar_exact(th, d, a, b, c, 1.0, 0.0, pp.branch)
            if st[0] != ST_OK:
                return math.inf
            p = fourbar_kernel.fourbar_coupler_point(th, out, st, a, 1.0, 0.0, u, v)[0]
            return math.hypot(p[0] - tx, p[1] - ty)
        with np.errstate(invalid="ignore", over="ignore"):   # dist is inf where the linkage cannot assemble
            r = minimize_scalar(dist, bounds=(t0 - step, t0 + step), method="bounded", options={"xatol": 1e-10})
        if r.fun < e0:
            errs.append(float(r.fun))
            ats.append(float(r.x) % 360.0)
        else:
            errs.append(float(e0))
            ats.append(float(t0))
    err = np.array(errs)
    return PathDesign(x, float(np.sqrt(np.mean(err ** 2))), err, design.violation, np.array(ats))


def polish(pp: PathProblem, design: PathDesign) -> PathDesign:
    """Least squares from the DE design with the crank angle of every target free (or the first
    one, with timing): residuals are coupler point - target, smooth in every unknown.  Kept only
    when it meets the constraints and lowers the error."""
    from scipy.optimize import least_squares
    n9 = 9
    b = bounds(pp)
    lo = np.array([v[0] for v in b[:n9]])
    hi = np.array([v[1] for v in b[:n9]])
    if pp.timing_deg is None:
        z0 = np.concatenate([design.x[:n9], design.theta_at_targets_deg])
        zlo = np.concatenate([lo, np.full(len(pp.targets), -np.inf)])
        zhi = np.concatenate([hi, np.full(len(pp.targets), np.inf)])
    else:
        z0 = design.x.copy()
        zlo = np.concatenate([lo, [-np.inf]])
        zhi = np.concatenate([hi, [np.inf]])
    z0 = np.clip(z0, zlo, zhi)

    def residuals(z: np.ndarray) -> np.ndarray:
        x = z[:n9]
        th = z[n9:] if pp.timing_deg is None else z[n9] + pp.timing_deg
        d, a, bb, c, u, v = x[3:9]
        rad = np.radians(th)
        out, st = fourbar_kernel.fourbar_exact(rad, d, a, bb, c, 1.0, 0.0, pp.branch)
        cp = fourbar_kernel.fourbar_coupler_point(rad, out, st, a, 1.0, 0.0, u, v)[:, :2]
        r = cp - to_kernel_frame(pp, np.concatenate([x, [0.0]]))
        r[st != ST_OK] = 10 * pp.length_max
        return r.ravel()

    # Levenberg-Marquardt (MINPACK: its own QR, no BLAS/LAPACK call, so the same bits whatever BLAS
    # kernel is loaded), unbounded; bounds checked after.  More unknowns than residuals: MINPACK needs
    # at least as many residuals, so a tiny pull towards the start (REG x (z - z0)) picks the solution
    # nearest the start from the family of exact ones, and changes an exact fit by ~REG^2 only.
    def padded(z: np.ndarray) -> np.ndarray:
        return np.concatenate([residuals(z), REG * (z - z0)])

    try:
        res = least_squares(padded, z0, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=POLISH_MAX_NFEV)
    except ValueError:
        return design
    if not (np.all(res.x[:n9] >= lo) and np.all(res.x[:n9] <= hi)):
        return design
    x = res.x[:n9] if pp.timing_deg is None else res.x
    if pp.timing_deg is None:
        x = np.concatenate([x, design.x[9:]])
    cand = refine(pp, evaluate(pp, x))
    if cand.violation <= design.violation and cand.rms < design.rms:
        return cand
    return design


def solve(pp: PathProblem, seed: int, maxiter: int, popsize: int,
          polish_starts: int = POLISH_STARTS) -> tuple[PathDesign, bool, str, int]:
    """Differential evolution on RMS error + penalty x violation, then least squares from the
    best distinct designs it evaluated; (best design, DE converged, message, evaluations)."""
    seen: list[tuple[float, tuple]] = []

    def fun(x: np.ndarray) -> float:
        r = evaluate(pp, x)
        val = r.rms + PENALTY * r.violation
        if r.violation == 0:
            seen.append((val, tuple(x)))
        return val

    # scipy-stubs types 'bounds' as one (lower, upper) pair; scipy takes (min, max) per variable, as here
    res = differential_evolution(fun, bounds(pp),  # type: ignore[arg-type]
                                 rng=seed, maxiter=maxiter, popsize=popsize, tol=1e-10,
                                 atol=1e-12, polish=False, init="sobol", mutation=(0.5, 1.0), recombination=0.9,
                                 strategy="best1bin")
    starts, keys = [], set()
    for _val, x in sorted(seen, key=lambda s: s[0]):
        key = tuple(np.round(np.asarray(x[3:9]) / pp.length_max, 2))
        if key not in keys:
            keys.add(key)
            starts.append(np.asarray(x))
        if len(starts) >= polish_starts:
            break
    best = refine(pp, evaluate(pp, res.x))
    for x0 in starts:
        cand = polish(pp, refine(pp, evaluate(pp, x0)))
        if cand.violation <= best.violation and cand.rms < best.rms:
            best = cand
    return best, bool(res.success), str(res.message), int(res.nfev)
