"""Crank-rocker for a given rocker swing and time ratio: the closed-form family and its best member.

The textbook construction: with the rocker pivot O_B at the origin and unit rocker, the two
rocker extremes B1, B2 are a chord of the rocker circle subtending the swing psi.  At the
extremes crank and coupler are collinear (folded: |O_A B1| = b - a; extended: |O_A B2| = b + a),
and the crank turns 180 + alpha between them, alpha = 180 (Q - 1)/(Q + 1) for the time ratio Q.
So O_A sees the chord B1 B2 under the angle alpha: it lies on a circle through B1 and B2 (on the
line through them when Q = 1).  Every point of that locus is one linkage:

    a = (L_ext - L_fold)/2,  b = (L_ext + L_fold)/2,  c = 1,  d = |O_A O_B|,

scaled to the deck's ground length, for the points of the locus from which B1 and B2 lie on one
side of the ground line (one assembly branch).  The family is scanned on both arcs (O_A beyond the chord
from O_B, and between), every member's transmission angle is known in closed form (extremes at
theta = 0 and 180: |A O_B| = d - a and d + a), and the member maximising the worse of mu_min and
180 - mu_max is refined with a bounded scalar search.  Members that are not crank-rockers are
excluded.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

__all__ = ["Member", "family", "best_member", "alpha_deg"]


def alpha_deg(q: float) -> float:
    """Crank-angle offset [deg] of time ratio q: the crank turns 180 + alpha and 180 - alpha."""
    return 180.0 * (q - 1.0) / (q + 1.0)


@dataclass(frozen=True)
class Member:
    """One linkage of the family (ground d = 1 before scaling) and its transmission angles."""

    arc: int          # +1: O_A beyond the chord (away from O_B), -1: between chord and O_B; 0 for Q = 1
    t: float          # position on the locus, (0, 1)
    crank: float
    coupler: float
    rocker: float
    ground: float
    mu_min_deg: float
    mu_max_deg: float
    crank_rocker: bool

    @property
    def quality_deg(self) -> float:
        """The worse deviation from a right angle, as an angle: min(mu_min, 180 - mu_max)."""
        return min(self.mu_min_deg, 180.0 - self.mu_max_deg)

    def scaled(self, ground: float) -> tuple[float, float, float]:
        k = ground / self.ground
        return self.crank * k, self.coupler * k, self.rocker * k


def _mu(b: float, c: float, x: float) -> float:
    return math.degrees(math.acos(max(-1.0, min(1.0, (b * b + c * c - x * x) / (2 * b * c)))))


def member(swing_deg: float, q: float, arc: int, t: float) -> Member | None:
    """The family member at position t in (0, 1) of the given arc (None at degenerate points)."""
    half = math.radians(swing_deg) / 2
    b1 = np.array([-math.sin(half), math.cos(half)])
    b2 = np.array([math.sin(half), math.cos(half)])
    h = 2 * math.sin(half)
    al = math.radians(alpha_deg(q))
    if al <= 1e-12:
        # Q = 1: O_A on the line B1 B2 beyond B2, at distance s = h tan(pi t / 2)
        s = h * math.tan(0.5 * math.pi * t)
        oa = b2 + s * (b2 - b1) / h
    else:
        R = 0.5 * h / math.sin(al)
        centre = np.array([0.0, math.cos(half) + arc * R * math.cos(al)])
        # the arc on the centre's side: angles from the centre between the chord ends
        e1, e2 = b1 - centre, b2 - centre
        a1, a2 = math.atan2(e1[1], e1[0]), math.atan2(e2[1], e2[0])
        if arc > 0:   # arc above the chord, from B2 counter-clockwise to B1
            span = (a1 - a2) % (2 * math.pi)
            ang = a2 + t * span
        else:         # arc below the chord, from B1 counter-clockwise to B2
            span = (a2 - a1) % (2 * math.pi)
            ang = a1 + t * span
        oa = centre + R * np.array([math.cos(ang), math.sin(ang)])
    # both extremes on one side of the ground line O_A O_B (one assembly branch); otherwise the
    # two collinear positions belong to different branches and the swing is not B1 -> B2
    side = lambda pt: oa[0] * pt[1] - oa[1] * pt[0]
    if side(b1) * side(b2) <= 0:
        return None
    # math.hypot, not np.linalg.norm: the norm goes through BLAS, whose kernel (OPENBLAS_CORETYPE)
    # changes its last bits -- and the refined member with them
    l1 = math.hypot(float(oa[0] - b1[0]), float(oa[1] - b1[1]))
    l2 = math.hypot(float(oa[0] - b2[0]), float(oa[1] - b2[1]))
    fold, ext = min(l1, l2), max(l1, l2)
    a, b, c, d = 0.5 * (ext - fold), 0.5 * (ext + fold), 1.0, math.hypot(float(oa[0]), float(oa[1]))
    if a <= 1e-9 or d <= 1e-9 or not math.isfinite(d):
        return None
    links = sorted([a, b, c, d])
    cr = a == links[0] and links[0] + links[3] < links[1] + links[2]
    mu_lo = _mu(b, c, d - a) if abs(b - c) <= abs(d - a) <= b + c else math.nan
    mu_hi = _mu(b, c, d + a) if abs(b - c) <= d + a <= b + c else math.nan
    return Member(arc if al > 1e-12 else 0, t, a, b, c, d, mu_lo, mu_hi, bool(cr))


def family(swing_deg: float, q: float, n: int) -> list[Member]:
    """n members per arc, evenly in t (the closed-form family searched)."""
    arcs = (1, -1) if alpha_deg(q) > 1e-12 else (0,)
    out = []
    for arc in arcs:
        for t in (np.arange(n) + 0.5) / n:
            m = member(swing_deg, q, arc, float(t))
            if m is not None:
                out.append(m)
    return out


def best_member(swing_deg: float, q: float, members: list[Member]) -> Member | None:
    """The crank-rocker of the family with the best transmission angle, refined between scan points."""
    ok = [m for m in members if m.crank_rocker and math.isfinite(m.quality_deg)]
    if not ok:
        return None
    top = max(ok, key=lambda m: (m.quality_deg, -m.arc, -m.t))
    same = sorted(m.t for m in members if m.arc == top.arc)
    i = same.index(top.t)
    lo = same[i - 1] if i > 0 else top.t / 2
    hi = same[i + 1] if i + 1 < len(same) else (1 + top.t) / 2

    def neg(t: float) -> float:
        m = member(swing_deg, q, top.arc or 1, t)
        return -m.quality_deg if (m is not None and m.crank_rocker and math.isfinite(m.quality_deg)) else 1e3

    res = minimize_scalar(neg, bounds=(lo, hi), method="bounded", options={"xatol": 1e-12})
    refined = member(swing_deg, q, top.arc or 1, float(res.x))
    if refined is not None and refined.crank_rocker and refined.quality_deg >= top.quality_deg:
        return refined
    return top
