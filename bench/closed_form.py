"""Benchmark baseline only (not used by the tool): the four-bar summary's closed-form columns in
plain numpy, for a full turn of the crank ([0, 360] deg, the shipped design search's range).

Written apart from ``fortran/fourbar_summary.f90``, from the geometry alone and vectorised over
the linkages (numpy's own vectorised transcendental functions; no Python loop over linkages):
the Grashof class; the limit (toggle) crank angles, where |A O_B| = r + s or |r - s|, and the
assembled arcs between them; the transmission-angle extremes (|A O_B| is extreme at crank angle
0 or 180 deg, or at a limit); the rocker's extremes -- it stops where crank and coupler are
collinear (B at q + r or |q - r| from O_A: a triangle) or at a limit position (coupler and rocker
collinear: B on the line A O_B) -- its swing, and the time ratio of its strokes.  Each
candidate is a triangle: a square root and an arc tangent, nothing scanned.  A crank that turns
fully (no limit) takes the short path: its rocker stops at the two collinear positions of the
branch.  A crank that rocks between limits takes the candidates of its arcs in crank-angle order.

bench/bench_search.py and bench/run_all.py check it against the kernel on the shipped grid
(1e-9 deg, 1e-5 deg where a figure sits at a limit position, where the kernel's states are
evaluated 1e-12 rad inside the assembled arc) and time the kernel's closed-form passes against it.
Change-point linkages (lhs = rhs of Grashof's inequality) are not handled here (41 of the 102 400).
"""
from __future__ import annotations

import numpy as np

#: class codes as the kernel numbers them (fortran/fourbar_summary.f90 gr_*); the kernel splits change
#: points by which links turn (codes 4, 6, 7, 8), which this form does not handle: CHANGE_POINT marks them
DOUBLE_CRANK, CRANK_ROCKER, ROCKER_CRANK, DOUBLE_ROCKER, CHANGE_POINT, TRIPLE_ROCKER = range(6)
NO_CHAIN, FLAT_CHAIN = 9, 10   # the longest link longer than (equal to) the other three together
DEG = 180.0 / np.pi


def grashof(p: np.ndarray, q: np.ndarray, r: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Grashof class code per linkage (the shortest link by the tie order ground, crank, rocker, coupler)."""
    short = np.minimum(np.minimum(p, q), np.minimum(r, s))
    lhs = short + np.maximum(np.maximum(p, q), np.maximum(r, s))
    rhs = (p + q + r + s) - lhs
    tol = 1e-12 * rhs
    code = np.where(p == short, DOUBLE_CRANK, np.where(q == short, CRANK_ROCKER,
                                                       np.where(s == short, ROCKER_CRANK, DOUBLE_ROCKER)))
    code = np.where(np.abs(lhs - rhs) <= tol, CHANGE_POINT, code)
    code = np.where(lhs > rhs + tol, TRIPLE_ROCKER, code)
    longest = np.maximum(np.maximum(p, q), np.maximum(r, s))
    rest = (p + q + r + s) - longest
    code = np.where(longest >= rest * (1 - 1e-12), FLAT_CHAIN, code)
    return np.where(longest > rest * (1 + 1e-12), NO_CHAIN, code)


def rocker_at(t: np.ndarray, p, q, r, s, branch) -> np.ndarray:
    """The rocker angle [rad] at crank angles t [rad] on ``branch`` (B from the triangle A B O_B)."""
    ax, ay = q * np.cos(t), q * np.sin(t)
    dx, dy = p - ax, -ay
    d2 = dx * dx + dy * dy
    a = (d2 + r * r - s * s) / (2 * d2)
    h = np.sqrt(np.maximum(r * r / d2 - a * a, 0.0))
    return np.arctan2(ay + a * dy + branch * h * dx, ax + a * dx - branch * h * dy - p)


def _collinear(p, q, r, s, branch):
    """The four crank angles [rad] where crank and coupler are collinear (extended: B at q + r from
    O_A; folded: |q - r|), the rocker angle there [rad] and whether that position is on ``branch``."""
    th, ro, on = [], [], []
    for dd, fold in ((q + r), None), (np.abs(q - r), r > q):
        x = (dd * dd + p * p - s * s) / (2 * p)
        y2 = dd * dd - x * x
        y = np.sqrt(np.maximum(y2, 0.0))
        real = (y2 >= 0) & (dd > 0)
        for by in (y, -y):
            bx = x
            phi = np.arctan2(by, bx) if fold is None else np.arctan2(np.where(fold, -by, by), np.where(fold, -bx, bx))
            ax, ay = q * np.cos(phi), q * np.sin(phi)
            side = (p - ax) * (by - ay) + ay * (bx - ax)   # (O_B - A) x (B - A): the branch's sign
            th.append(phi)
            ro.append(np.arctan2(by, bx - p))
            on.append(real & (branch * side > 0))
    return th, ro, on


def summary(p: np.ndarray, q: np.ndarray, r: np.ndarray, s: np.ndarray, branch: float = 1.0) -> dict[str, np.ndarray]:
    """The closed-form columns for a full crank turn on one assembly branch (+1 open, -1 crossed):
    grashof, assemblable, assembled_fraction, toggles_in_range, mu_min_deg, mu_max_deg,
    rocker_min_deg, rocker_max_deg (in [0, 360)), rocker_swing_deg (360 when it turns fully),
    rocker_turns, time_ratio (0 where it does not exist)."""
    n = p.size
    code = grashof(p, q, r, s)
    out: dict[str, np.ndarray] = {"grashof": code}
    # |A O_B| = d(theta) grows from |p - q| (theta = 0) to p + q (180); assembled where |r - s| <= d <= r + s
    lo, hi = np.abs(r - s), r + s
    c_hi = (p * p + q * q - hi * hi) / (2 * p * q)          # limit where d = r + s
    c_lo = (p * p + q * q - lo * lo) / (2 * p * q)          # limit where d = |r - s|
    has_hi, has_lo = np.abs(c_hi) <= 1, np.abs(c_lo) <= 1
    a_hi = np.arccos(np.clip(c_hi, -1, 1))
    a_lo = np.arccos(np.clip(c_lo, -1, 1))
    start = np.where(has_lo, a_lo, 0.0)                      # the assembled arc in [0, pi]
    stop = np.where(has_hi, a_hi, np.pi)
    d_mid = np.sqrt(p * p + q * q - 2 * p * q * np.cos(0.5 * (start + stop)))
    ok = (stop > start) & (d_mid >= lo) & (d_mid <= hi)
    out["assemblable"] = ok.astype(float)
    out["assembled_fraction"] = np.where(ok, (stop - start) / np.pi, 0.0)
    out["toggles_in_range"] = (2.0 * has_hi - (has_hi & (c_hi == -1)) + 2.0 * has_lo - (has_lo & (c_lo == -1)))
    cos_mu = lambda d: np.clip((r * r + s * s - d * d) / (2 * r * s), -1, 1)
    out["mu_min_deg"] = np.where(ok, DEG * np.arccos(cos_mu(np.where(has_lo, lo, np.abs(p - q)))), 0.0)
    out["mu_max_deg"] = np.where(ok, DEG * np.arccos(cos_mu(np.where(has_hi, hi, p + q))), 0.0)

    umin, umax = np.zeros(n), np.zeros(n)
    tmin, tmax = np.zeros(n), np.zeros(n)
    turns = ok & (code == DOUBLE_CRANK)
    full = ok & ~has_hi & ~has_lo & ~turns
    # a crank that turns fully (no limit): the rocker stops at the branch's two collinear positions,
    # extended (B at q + r from O_A) and folded (|q - r|); of B = (x, +-y) the branch's side
    f = np.flatnonzero(full)
    if f.size:
        P, Q, R, S = p[f], q[f], r[f], s[f]
        ends = []
        for dd, away in ((Q + R), 1.0), (np.abs(Q - R), np.where(R > Q, -1.0, 1.0)):
            x = (dd * dd + P * P - S * S) / (2 * P)
            y = np.sqrt(np.maximum(dd * dd - x * x, 0.0))
            ax, ay = away * Q * x / dd, away * Q * y / dd          # A on the line O_A B (B at +y)
            side = (P - ax) * (y - ay) + ay * (x - ax)             # (O_B - A) x (B - A) for B at +y
            by = np.where(branch * side > 0, y, -y)
            ends.append((x, by, away))
        (x1, y1, w1), (x2, y2, w2) = ends
        u1, u2 = np.arctan2(y1, x1 - P), np.arctan2(y2, x2 - P)
        du = np.mod(u2 - u1 + np.pi, 2 * np.pi) - np.pi
        first_max = du < 0
        umax[f] = np.where(first_max, u1, u1 + du)
        umin[f] = np.where(first_max, u1 + du, u1)
        # the crank turns from one stop to the other through the angle between the two A's
        turn = np.arctan2(w1 * w2 * (x1 * y2 - y1 * x2), w1 * w2 * (x1 * x2 + y1 * y2))
        tmax[f] = np.where(first_max, 0.0, turn)
        tmin[f] = np.where(first_max, turn, 0.0)
    # a crank that rocks between limits: candidates of each assembled arc in crank-angle order
    g = np.flatnonzero(ok & ~full & ~turns)
    if g.size:
        P, Q, R, S = p[g], q[g], r[g], s[g]
        ah, al, hh, hl = a_hi[g], a_lo[g], has_hi[g], has_lo[g]
        th, ro, on = (np.stack(v, 1) for v in _collinear(P, Q, R, S, branch))
        lim_t, lim_u = [], []
        for a, has, d, out_sign in ((ah, hh, hi[g], 1.0), (al, hl, lo[g], np.where(R > S, -1.0, 1.0))):
            for t in (a, 2 * np.pi - a):
                ax, ay = Q * np.cos(t), Q * np.sin(t)   # A; B on the line A O_B at S from O_B
                lim_t.append(np.where(has, t, np.nan))
                lim_u.append(np.arctan2(out_sign * ay / d, out_sign * (ax - P) / d))
        cand_t = np.concatenate([np.stack(lim_t, 1), np.where(on, np.mod(th, 2 * np.pi), np.nan)], 1)
        cand_u = np.concatenate([np.stack(lim_u, 1), ro], 1)
        # an arc through crank angle 0 (0 assembled, 180 not) is one motion from -a_hi to a_hi
        wrap = hh & ~hl
        key = np.where(wrap[:, None] & (cand_t > np.pi), cand_t - 2 * np.pi, cand_t)
        two = hh & hl                                        # two arcs: [a_lo, a_hi], [2pi - a_hi, 2pi - a_lo]
        arc2 = two[:, None] & (key > np.pi)
        order = np.argsort(np.where(np.isnan(key), np.inf, key + 10 * arc2), axis=1)
        key = np.take_along_axis(key, order, 1)
        u = np.take_along_axis(cand_u, order, 1)
        arc2 = np.take_along_axis(arc2, order, 1)
        valid = ~np.isnan(key)
        # the rocker angle halfway between neighbours, so that no unwrapping step reaches half a turn
        mid = 0.5 * (key[:, 1:] + key[:, :-1])
        um = rocker_at(np.where(np.isnan(mid), 0.0, mid), P[:, None], Q[:, None], R[:, None], S[:, None], branch)
        k2 = np.empty((g.size, 2 * key.shape[1] - 1))
        k2[:, 0::2], k2[:, 1::2] = key, np.where(arc2[:, 1:] == arc2[:, :-1], mid, np.nan)
        u2 = np.empty_like(k2)
        u2[:, 0::2], u2[:, 1::2] = u, um
        a2 = np.empty(k2.shape, dtype=bool)
        a2[:, 0::2], a2[:, 1::2] = arc2, arc2[:, 1:]
        key, u, arc2 = k2, u2, a2
        valid = ~np.isnan(key)
        step = np.mod(np.diff(u, axis=1) + np.pi, 2 * np.pi) - np.pi
        step = np.where(valid[:, 1:] & (arc2[:, 1:] == arc2[:, :-1]), step, 0.0)
        un = u[:, :1] + np.concatenate([np.zeros((g.size, 1)), np.cumsum(step, axis=1)], 1)
        # the second arc's own unwrapping, then placed on the turn nearest the first arc's centre
        first2 = np.argmax(arc2 & valid, axis=1)
        base2 = np.take_along_axis(u, first2[:, None], 1)[:, 0]
        off2 = np.take_along_axis(un, first2[:, None], 1)[:, 0]
        in1 = valid & ~arc2
        c1 = 0.5 * (np.where(in1, un, np.inf).min(1) + np.where(in1, un, -np.inf).max(1))
        shift2 = base2 + 2 * np.pi * np.round((c1 - base2) / (2 * np.pi)) - off2
        un = np.where(arc2, un + shift2[:, None], un)
        kmax = np.argmax(np.where(valid, un, -np.inf), axis=1)
        kmin = np.argmin(np.where(valid, un, np.inf), axis=1)
        umax[g] = np.take_along_axis(un, kmax[:, None], 1)[:, 0]
        umin[g] = np.take_along_axis(un, kmin[:, None], 1)[:, 0]
        tmax[g] = np.take_along_axis(key, kmax[:, None], 1)[:, 0]
        tmin[g] = np.take_along_axis(key, kmin[:, None], 1)[:, 0]
    moves = ok & ~turns
    out["rocker_turns"] = turns.astype(float)
    out["rocker_swing_deg"] = np.where(turns, 360.0, np.where(moves, DEG * (umax - umin), 0.0))
    out["rocker_min_deg"] = np.where(moves, np.mod(DEG * umin, 360.0), 0.0)
    out["rocker_max_deg"] = np.where(moves, np.mod(DEG * umax, 360.0), 0.0)
    t = np.mod(DEG * (tmax - tmin), 360.0)
    tt = np.minimum(t, 360.0 - t)
    out["time_ratio"] = np.where(full & (tt > 0), np.maximum(t, 360.0 - t) / np.where(tt > 0, tt, 1.0), 0.0)
    return out
