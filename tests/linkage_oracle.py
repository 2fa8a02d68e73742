"""An independent implementation of a ``&linkage`` mechanism, written apart from the kernel
(fortran/linkage.f90) as a test oracle only.

It reads only the topology of the compiled deck (which link each point, guide and group joint
belongs to, the numbers the deck gives) and solves the physics its own way:

* positions: Newton's method on the loop equations of all links at once, in absolute
  coordinates (x, y, angle of every moving link's frame), started near the kernel's answer
  (the root it converges to is fixed by the equations; a start off the kernel's branch by a
  few per cent converges to the same root);
* velocities and accelerations: the constraint Jacobian, with the quadratic velocity terms
  written out per constraint;
* forces: Newton-Euler for every moving link at once, one linear system for every joint
  reaction, the driving torque or force (no group-by-group order).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

J = np.array([[0.0, -1.0], [1.0, 0.0]])


def rot(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s], [s, c]])


@dataclass
class Joint:
    kind: str          # 'R' or 'P'
    a: int             # link giving the reaction (index into links, 0 ground)
    b: int             # link receiving it
    point: tuple[int, float, float]      # the point of action: (link, u, v)
    guide: tuple[int, float, float, float] | None = None   # P: (link a, gx, gy, angle)


class Oracle:
    """The mechanism ``mech`` (driver.linkage._kernel_program.Mechanism) solved independently."""

    def __init__(self, mech):
        self.m = mech
        self.nl = len(mech.links)
        self.nq = 3 * (self.nl - 1)
        self.cons = []      # (kind, data)
        self.joints: list[Joint] = []
        pts = mech.points
        gds = mech.guides
        P = lambda i: (pts[i - 1][1] - 1, pts[i - 1][2], pts[i - 1][3])       # (link0, u, v)
        G = lambda i: (gds[i - 1][1] - 1, gds[i - 1][2], gds[i - 1][3], gds[i - 1][4])
        c = mech.driver_link - 1
        if mech.driver == "crank":
            piv = P(mech.driver_anchor)
            self.cons.append(("coinc", (piv, (c, 0.0, 0.0))))
            self.cons.append(("drive_angle", c))
            self.joints.append(Joint("R", 0, c, (c, 0.0, 0.0)))
        else:
            g = G(mech.driver_anchor)
            self.cons.append(("angle", (g[0], c, g[3])))
            self.cons.append(("online", (g, (c, 0.0, 0.0), mech.driver_length)))
            self.cons.append(("drive_slide", (g, (c, 0.0, 0.0))))
            self.joints.append(Joint("P", 0, c, (c, 0.0, 0.0), g))
        for d in mech.dyads:
            l1, l2 = d.k1 - 1, d.k2 - 1
            if d.kind == "rrr":
                pa, pb = P(d.a1), P(d.a2)
                self.cons += [("coinc", (pa, (l1, 0.0, 0.0))), ("coinc", (pb, (l2, 0.0, 0.0))),
                              ("coinc", ((l1, d.d1, 0.0), (l2, d.d2, 0.0)))]
                self.joints += [Joint("R", pa[0], l1, (l1, 0.0, 0.0)), Joint("R", pb[0], l2, (l2, 0.0, 0.0)),
                                Joint("R", l1, l2, (l2, d.d2, 0.0))]
            elif d.kind in ("rrp", "prr"):   # kernel order: rod l1 from point a1, block l2 on guide a2
                pa, g = P(d.a1), G(d.a2)
                self.cons += [("coinc", (pa, (l1, 0.0, 0.0))), ("coinc", ((l1, d.d1, 0.0), (l2, 0.0, 0.0))),
                              ("angle", (g[0], l2, g[3])), ("online", (g, (l2, 0.0, 0.0), d.d2))]
                self.joints += [Joint("R", pa[0], l1, (l1, 0.0, 0.0)), Joint("P", g[0], l2, (l2, 0.0, 0.0), g),
                                Joint("R", l1, l2, (l2, 0.0, 0.0))]
            elif d.kind == "rpr":
                pa, pb = P(d.a1), P(d.a2)
                slot = (l1, 0.0, 0.0, 0.0)
                self.cons += [("coinc", (pa, (l1, 0.0, 0.0))), ("coinc", (pb, (l2, 0.0, 0.0))),
                              ("angle", (l1, l2, 0.0)), ("online", (slot, (l2, 0.0, 0.0), d.d1))]
                self.joints += [Joint("R", pa[0], l1, (l1, 0.0, 0.0)), Joint("R", pb[0], l2, (l2, 0.0, 0.0)),
                                Joint("P", l1, l2, (l2, 0.0, 0.0), slot)]
            else:
                g1, g2 = G(d.a1), G(d.a2)
                self.cons += [("coinc", ((l1, 0.0, 0.0), (l2, 0.0, 0.0))), ("angle", (g1[0], l1, g1[3])),
                              ("angle", (g2[0], l2, g2[3])), ("online", (g1, (l1, 0.0, 0.0), d.d1)),
                              ("online", (g2, (l2, 0.0, 0.0), d.d2))]
                self.joints += [Joint("P", g1[0], l1, (l1, 0.0, 0.0), g1), Joint("P", g2[0], l2, (l2, 0.0, 0.0), g2),
                                Joint("R", l1, l2, (l2, 0.0, 0.0))]

    # ---------------------------------------------------------------- frames
    def frame(self, q: np.ndarray, l: int) -> tuple[np.ndarray, float]:
        if l == 0:
            return np.zeros(2), 0.0
        i = 3 * (l - 1)
        return q[i:i + 2], q[i + 2]

    def rate(self, qd: np.ndarray, l: int) -> tuple[np.ndarray, float]:
        return self.frame(qd, l)

    def point(self, q, pt):
        l, u, v = pt
        o, t = self.frame(q, l)
        return o + rot(t) @ np.array([u, v]) if l else np.array([u, v])

    def point_jac(self, q, pt) -> np.ndarray:
        l, u, v = pt
        jac = np.zeros((2, self.nq))
        if l == 0:
            return jac
        i = 3 * (l - 1)
        _, t = self.frame(q, l)
        jac[:, i:i + 2] = np.eye(2)
        jac[:, i + 2] = J @ rot(t) @ np.array([u, v])
        return jac

    def point_quad(self, q, qd, pt) -> np.ndarray:
        l, u, v = pt
        if l == 0:
            return np.zeros(2)
        _, t = self.frame(q, l)
        _, w = self.rate(qd, l)
        return -w * w * (rot(t) @ np.array([u, v]))

    def guide(self, q, g):
        l, gx, gy, ga = g
        o, t = self.frame(q, l)
        pg = o + rot(t) @ np.array([gx, gy]) if l else np.array([gx, gy])
        d = np.array([math.cos(t + ga), math.sin(t + ga)])
        return pg, d, J @ d

    # ---------------------------------------------------------------- constraints
    def residual(self, q, x):
        out = []
        for kind, c in self.cons:
            if kind == "coinc":
                out += list(self.point(q, c[0]) - self.point(q, c[1]))
            elif kind == "drive_angle":
                out.append(self.frame(q, c)[1] - x)
            elif kind == "angle":
                out.append(self.frame(q, c[1])[1] - self.frame(q, c[0])[1] - c[2])
            elif kind == "online":
                g, pt, e = c
                pg, d, n = self.guide(q, g)
                out.append(n @ (self.point(q, pt) - pg) - e)
            else:   # drive_slide
                g, pt = c
                pg, d, n = self.guide(q, g)
                out.append(d @ (self.point(q, pt) - pg) - x)
        return np.array(out)

    def jacobian(self, q):
        rows = []
        for kind, c in self.cons:
            if kind == "coinc":
                rows += list(self.point_jac(q, c[0]) - self.point_jac(q, c[1]))
            elif kind == "drive_angle":
                r = np.zeros(self.nq)
                r[3 * (c - 1) + 2] = 1.0
                rows.append(r)
            elif kind == "angle":
                r = np.zeros(self.nq)
                if c[1]:
                    r[3 * (c[1] - 1) + 2] += 1.0
                if c[0]:
                    r[3 * (c[0] - 1) + 2] -= 1.0
                rows.append(r)
            else:
                g, pt = c[0], c[1]
                pg, d, n = self.guide(q, g)
                w = self.point(q, pt) - pg
                gl = g[0]
                jpg = self.point_jac(q, (gl, g[1], g[2])) if gl else np.zeros((2, self.nq))
                jw = self.point_jac(q, pt) - jpg
                dn = -d if kind == "online" else n     # d(n)/d(theta_a) = -d, d(d)/d(theta_a) = n
                vec = n if kind == "online" else d
                r = vec @ jw
                if gl:
                    r[3 * (gl - 1) + 2] += dn @ w
                rows.append(r)
        return np.array(rows)

    def quad(self, q, qd):
        """The constraints' second time derivative at q'' = 0 and no input acceleration."""
        out = []
        for kind, c in self.cons:
            if kind == "coinc":
                out += list(self.point_quad(q, qd, c[0]) - self.point_quad(q, qd, c[1]))
            elif kind in ("drive_angle", "angle"):
                out.append(0.0)
            else:
                g, pt = c[0], c[1]
                pg, d, n = self.guide(q, g)
                gl = g[0]
                wa = self.rate(qd, gl)[1] if gl else 0.0
                w = self.point(q, pt) - pg
                gpt = (gl, g[1], g[2])
                wd = self.point_jac(q, pt) @ qd - (self.point_jac(q, gpt) @ qd if gl else 0.0)
                cq = self.point_quad(q, qd, pt) - (self.point_quad(q, qd, gpt) if gl else 0.0)
                if kind == "online":   # f = n . w: n'' = -a d - w^2 n, n' = -w d
                    out.append(-wa * wa * (n @ w) - 2 * wa * (d @ wd) + n @ cq)
                else:                  # f = d . w: d' = w n, d'' = a n - w^2 d
                    out.append(-wa * wa * (d @ w) + 2 * wa * (n @ wd) + d @ cq)
        return np.array(out)

    def drive_rows(self):
        """Indices of the constraint rows that hold the input."""
        rows, k = [], 0
        for kind, _ in self.cons:
            size = 2 if kind == "coinc" else 1
            if kind in ("drive_angle", "drive_slide"):
                rows.append(k)
            k += size
        return rows

    # ---------------------------------------------------------------- solve
    def solve(self, x, q0, rate=1.0, rate2=0.0, tol=1e-14):
        q = np.array(q0, dtype=float)
        for kind, c in self.cons:   # the input angle itself (a start off by 2 pi would linearise a full turn)
            if kind == "drive_angle":
                q[3 * (c - 1) + 2] = x
        for _ in range(60):
            f = self.residual(q, x)
            dq = np.linalg.solve(self.jacobian(q), -f)
            q += dq
            if np.max(np.abs(dq)) < tol * (1.0 + np.max(np.abs(q))):
                break
        jac = self.jacobian(q)
        rhs = np.zeros(self.nq)
        k = self.drive_rows()[0]
        rhs[k] = rate
        qd = np.linalg.solve(jac, rhs)
        rhs2 = -self.quad(q, qd)
        rhs2[k] += rate2
        qdd = np.linalg.solve(jac, rhs2)
        return q, qd, qdd

    def point_state(self, q, qd, qdd, pt):
        """Position, velocity, acceleration of a point."""
        jac = self.point_jac(q, pt)
        return self.point(q, pt), jac @ qd, jac @ qdd + self.point_quad(q, qd, pt)

    # ---------------------------------------------------------------- forces
    def forces(self, q, qd, qdd, gravity, loads, torques, guide_force=None):
        """Newton-Euler of every moving link at once.

        loads: [(point (link, u, v), (fx, fy))]; torques: {link: tau}; guide_force: (block link,
        guide link, F along the block's x-axis at its origin) or None.
        Returns (reactions per joint: (fx, fy, couple) on link b from link a, drive (T or P),
        shaking force (2,), shaking moment)."""
        m = self.m
        nmov = self.nl - 1
        cols = []
        for jt in self.joints:
            cols += [("f", jt, 0), ("f", jt, 1)] if jt.kind == "R" else [("n", jt, 0), ("q", jt, 0)]
        ncol = len(cols) + 1      # + the drive
        A = np.zeros((3 * nmov, ncol))
        b = np.zeros(3 * nmov)
        origin = lambda l: self.frame(q, l)[0]

        def put(link, F, at, couple, col):
            if link == 0:
                return
            i = 3 * (link - 1)
            r = at - origin(link)
            A[i, col] += F[0]
            A[i + 1, col] += F[1]
            A[i + 2, col] += r[0] * F[1] - r[1] * F[0] + couple

        for ci, (what, jt, comp) in enumerate(cols):
            at = self.point(q, jt.point)
            if what == "f":
                F = np.eye(2)[comp]
                put(jt.b, F, at, 0.0, ci)
                put(jt.a, -F, at, 0.0, ci)
            elif what == "n":
                _, d, n = self.guide(q, jt.guide)
                put(jt.b, n, at, 0.0, ci)
                put(jt.a, -n, at, 0.0, ci)
            else:
                put(jt.b, np.zeros(2), at, 1.0, ci)
                put(jt.a, np.zeros(2), at, -1.0, ci)
        c = m.driver_link - 1
        if m.driver == "crank":
            put(c, np.zeros(2), origin(c), 1.0, ncol - 1)
        else:
            _, d, _ = self.guide(q, (0, *m.guides[m.driver_anchor - 1][2:]))
            put(c, d, origin(c), 0.0, ncol - 1)
        # known side: m a_G - m g - loads, I alpha - moments of those about the origin
        shake_f = np.zeros(2)
        shake_m = 0.0
        cross = lambda r, f: r[0] * f[1] - r[1] * f[0]
        for l in range(1, self.nl):
            mass, gu, gv, inertia = m.body[l]
            rg, vg, ag = self.point_state(q, qd, qdd, (l, gu, gv))
            al = self.rate(qdd, l)[1]
            i = 3 * (l - 1)
            o = origin(l)
            need = mass * ag - mass * np.asarray(gravity)
            b[i:i + 2] += need
            b[i + 2] += inertia * al + cross(rg - o, need)
            shake_f += -mass * ag + mass * np.asarray(gravity)
            shake_m += -(cross(rg, mass * ag) + inertia * al) + cross(rg, mass * np.asarray(gravity))
        for pt, f in loads:
            i = 3 * (pt[0] - 1)
            at = self.point(q, pt)
            b[i:i + 2] -= f
            b[i + 2] -= cross(at - origin(pt[0]), f)
            shake_f += f
            shake_m += cross(at, f)
        for l, tau in torques.items():
            b[3 * (l - 1) + 2] -= tau
            shake_m += tau
        if guide_force is not None:
            blk, gl, F = guide_force
            o, t = self.frame(q, blk)
            f = F * np.array([math.cos(t), math.sin(t)])
            i = 3 * (blk - 1)
            b[i:i + 2] -= f
            if gl:
                i = 3 * (gl - 1)
                b[i:i + 2] += f
                b[i + 2] += cross(o - origin(gl), f)
        z = np.linalg.solve(A, b)
        out, k = [], 0
        for jt in self.joints:
            if jt.kind == "R":
                out.append((z[k], z[k + 1], 0.0))
            else:
                _, d, n = self.guide(q, jt.guide)
                out.append((z[k] * n[0], z[k] * n[1], z[k + 1]))
            k += 2
        return out, z[-1], shake_f, shake_m


def params_of(text: str, name: str = "deck.dat"):
    """Validated &linkage Params of a deck's body text (the group's lines)."""
    from driver._deck import read_deck, validate
    from driver.linkage import SPEC
    deck = read_deck(name, "&linkage\n" + text + "\n/\n")
    return validate(deck.groups["linkage"], SPEC, name)


def kernel_frames(motion) -> np.ndarray:
    """(n, 3 (links - 1)): each moving link's frame (origin x, y, angle) from the kernel's answer."""
    from driver.linkage._analysis_frames import _origins
    from driver.linkage._kernel import LinkCol, PointCol
    mech, a = motion.mech, motion.a
    org = _origins(mech)
    cols = []
    for l in range(2, len(mech.links) + 1):
        j = mech.point_index(org[l]) - 1
        cols += [a.points[:, PointCol.X, j], a.points[:, PointCol.Y, j], a.links[:, LinkCol.ANGLE, l - 1]]
    return np.column_stack(cols)
