"""Benchmark: slider-crank KED kernel (Fortran) vs a plain numpy/scipy implementation.

Case: the paper's aluminium rod, 700 elements, 1440 steps per revolution, 29.32 rad/s,
Rayleigh damping 2 %, quasi-static start, every step's outputs recorded (one revolution).
Target (issue 4): one revolution in at most 100 ms and at least 10x faster than the baseline.

The baseline (class NumpyKED) is a BENCHMARK BASELINE ONLY: the same formulation as
fortran/slidercrank.f90 (consistent frame elements in the moving rod frame, slider node in
global X, Newmark average acceleration, Rayleigh damping), written the plain vectorised
numpy way: element gathers/scatters with fancy indexing and bincount, the banded Newmark
matrix re-assembled every step and solved with scipy.linalg.solveh_banded.  It is checked
against the kernel on a short run before timing.  It is slow, so only a short run of it is
timed and its per-step cost is scaled to a revolution.

Run:  .venv/bin/python bench/bench_slidercrank.py
"""
from __future__ import annotations

import math

import numpy as np
from scipy.linalg import solveh_banded

from driver.slidercrank import MATERIALS, rayleigh
from driver.slidercrank import _kernel as slidercrank_kernel
from timing import median_time

N_EL, SPR, OMEGA = 700, 1440, 29.32
R2, LEN, M_S = 0.125, 0.505, 0.95
TARGET_MS, TARGET_RATIO = 100.0, 10.0


def rigid(theta2: float, omega: float) -> tuple[float, ...]:
    """theta3, theta3', theta3'', A_h, crank-pin acceleration along/across the rod (baseline)."""
    s2, c2 = math.sin(theta2), math.cos(theta2)
    th3 = math.asin(-R2 * s2 / LEN)
    s3, c3 = math.sin(th3), math.cos(th3)
    th3d = -R2 * omega * c2 / (LEN * c3)
    th3dd = (R2 * omega ** 2 * s2 + LEN * th3d ** 2 * s3) / (LEN * c3)
    ax, ay = -R2 * omega ** 2 * c2, -R2 * omega ** 2 * s2
    a_h = -R2 * omega ** 2 * c2 - LEN * (th3dd * s3 + th3d ** 2 * c3)
    return th3, th3d, th3dd, a_h, ax * c3 + ay * s3, -ax * s3 + ay * c3


class NumpyKED:
    """Benchmark baseline only (see module docstring): numpy/scipy KED of the elastic rod."""

    def __init__(self, n: int, rho_a: float, ea: float, ei: float, omega: float, dt: float,
                 alpha: float, beta: float):
        self.n, self.nq, self.omega, self.dt = n, 3 * n, omega, dt
        self.alpha, self.beta = alpha, beta
        le = LEN / n
        self.le = le
        m, k = rho_a * le, ea / le
        b = ei / le ** 3
        me = np.zeros((6, 6))
        me[np.ix_([0, 3], [0, 3])] = m * np.array([[1 / 3, 1 / 6], [1 / 6, 1 / 3]])
        me[np.ix_([1, 2, 4, 5], [1, 2, 4, 5])] = m * np.array([
            [13 / 35, 11 * le / 210, 9 / 70, -13 * le / 420],
            [11 * le / 210, le ** 2 / 105, 13 * le / 420, -le ** 2 / 140],
            [9 / 70, 13 * le / 420, 13 / 35, -11 * le / 210],
            [-13 * le / 420, -le ** 2 / 140, -11 * le / 210, le ** 2 / 105]])
        ke = np.zeros((6, 6))
        ke[np.ix_([0, 3], [0, 3])] = k * np.array([[1, -1], [-1, 1]])
        ke[np.ix_([1, 2, 4, 5], [1, 2, 4, 5])] = b * np.array([
            [12, 6 * le, -12, 6 * le], [6 * le, 4 * le ** 2, -6 * le, 2 * le ** 2],
            [-12, -6 * le, 12, -6 * le], [6 * le, 2 * le ** 2, -6 * le, 4 * le ** 2]])
        self.me, self.ke = me, ke
        nq = self.nq
        node_dofs = [[nq, nq, 0]] + [[3 * j - 2, 3 * j - 1, 3 * j] for j in range(1, n)] + [[nq - 1, nq - 1, nq - 2]]
        node_dofs = np.array(node_dofs)
        self.idx = np.hstack([node_dofs[:-1], node_dofs[1:]])            # (n, 6); nq = constrained slot
        self.cf = np.ones((n, 6))
        self.cf[0, :2] = 0.0
        self.s_left = np.arange(n) * le
        self.s_right = self.s_left + le
        a, bb = np.meshgrid(np.arange(6), np.arange(6), indexing="ij")
        self.pa, self.pb = a.ravel(), bb.ravel()
        rows, cols = self.idx[:, self.pa], self.idx[:, self.pb]
        self.mask = (rows >= cols) & (rows < nq) & (cols < nq)
        self.flat = ((rows - cols) * nq + cols)[self.mask]
        self.a0, self.a1, self.a2 = 4 / dt ** 2, 2 / dt, 4 / dt

    def _set_slider(self, th3: float) -> None:
        self.cf[-1, 3], self.cf[-1, 4] = math.cos(th3), -math.sin(th3)

    def banded(self, se: np.ndarray, slider: float) -> np.ndarray:
        vals = (self.cf[:, self.pa] * self.cf[:, self.pb] * se[self.pa, self.pb])[self.mask]
        ab = np.bincount(self.flat, vals, minlength=6 * self.nq).reshape(6, self.nq)
        ab[0, -1] += slider
        return ab

    def apply(self, qm: np.ndarray, qk: np.ndarray, kin: tuple[float, ...], load: float = 1.0) -> np.ndarray:
        th3, th3d, th3dd, a_h, apar, aperp = kin
        ext = lambda q: np.append(q, 0.0)[self.idx] * self.cf
        ur = np.column_stack([apar - self.s_left * th3d ** 2, aperp + self.s_left * th3dd,
                              np.full(self.n, th3dd), apar - self.s_right * th3d ** 2,
                              aperp + self.s_right * th3dd, np.full(self.n, th3dd)])
        f = (ext(qm) - load * ur) @ self.me.T + ext(qk) @ self.ke.T
        r = np.bincount(self.idx.ravel(), (self.cf * f).ravel(), minlength=self.nq + 1)[: self.nq]
        r[-1] += M_S * (qm[-1] - load * a_h)
        return r

    def run(self, n_steps: int) -> np.ndarray:
        """Quasi-static start, n_steps Newmark steps; returns the crank-end element strain per step."""
        zero = np.zeros(self.nq)

        def qs(t: float) -> np.ndarray:
            kin = rigid(self.omega * t, self.omega)
            self._set_slider(kin[0])
            return solveh_banded(self.banded(self.ke, 0.0), self.apply(zero, zero, kin), lower=True)

        q, qd = qs(0.0), (qs(self.dt) - qs(-self.dt)) / (2 * self.dt)
        kin = rigid(0.0, self.omega)
        self._set_slider(kin[0])
        qdd = solveh_banded(self.banded(self.me, M_S), self.apply(-self.alpha * qd, -self.beta * qd - q, kin),
                            lower=True)
        ck, cm = 1 + self.a1 * self.beta, self.a0 + self.a1 * self.alpha
        se = ck * self.ke + cm * self.me
        eps = np.empty(n_steps)
        for k in range(1, n_steps + 1):
            kin = rigid(self.omega * k * self.dt, self.omega)
            self._set_slider(kin[0])
            w1 = (self.a0 + self.alpha * self.a1) * q + (self.a2 + self.alpha) * qd + qdd
            w2 = self.beta * (self.a1 * q + qd)
            qn = solveh_banded(self.banded(se, cm * M_S), self.apply(w1, w2, kin), lower=True)
            qdd_new = self.a0 * (qn - q) - self.a2 * qd - qdd
            qd = qd + self.dt * 0.5 * (qdd + qdd_new)
            qdd, q = qdd_new, qn
            eps[k - 1] = q[1] / self.le
        return eps


def main() -> None:
    mat = MATERIALS["aluminium"]
    rho_a, ea, ei = mat["density"] * mat["area"], mat["youngs_modulus"] * mat["area"], \
        mat["youngs_modulus"] * mat["second_moment"]
    wb, wa, _ = slidercrank_kernel.slidercrank_frequencies(rho_a, ea, ei, LEN, M_S)
    alpha, beta = rayleigh(0.02, wb, wa)
    dt = 2 * math.pi / (OMEGA * SPR)

    def kernel(n_steps: int = SPR, rec: int = SPR) -> dict:
        return slidercrank_kernel.slidercrank_simulate(N_EL, R2, LEN, rho_a, ea, ei, 1.5e-3, M_S, OMEGA, dt, n_steps, 1, rec,
                                      alpha, beta)

    base = NumpyKED(N_EL, rho_a, ea, ei, OMEGA, dt, alpha, beta)
    # same formulation: compare the crank-end strain over a short run
    short = 60
    ref = kernel(short, short)["eps_ax"][0]
    got = base.run(short)
    diff = np.abs(got - ref).max() / np.abs(ref).max()
    print(f"baseline vs kernel, {short} steps, crank-end strain: max relative difference {diff:.2e}")
    kernel()                                            # warm-up
    t_kernel = median_time(kernel, 7)
    t_base_short = median_time(lambda: base.run(short), 3)
    t_base = t_base_short / short * SPR
    ratio = t_base / t_kernel
    print(f"case: aluminium rod, {N_EL} elements ({3 * N_EL} unknowns), {SPR} steps per revolution, "
          f"{OMEGA} rad/s, all steps recorded")
    print(f"kernel (Fortran, banded Cholesky once + Schur):  median {1e3 * t_kernel:8.1f} ms per revolution "
          f"(7 repeats)")
    print(f"baseline (numpy + scipy solveh_banded per step): median {1e3 * t_base:8.1f} ms per revolution "
          f"(3 repeats of {short} steps, scaled)")
    print(f"speed-up: {ratio:.1f}x")
    ok_time, ok_ratio = 1e3 * t_kernel <= TARGET_MS, ratio >= TARGET_RATIO
    print(f"target: <= {TARGET_MS:.0f} ms per revolution: {'met' if ok_time else 'NOT met'}; "
          f">= {TARGET_RATIO:.0f}x the baseline: {'met' if ok_ratio else 'NOT met'}")
    mem = 3 * 8 * N_EL * (SPR + 1) / 2 ** 20
    print(f"memory: banded matrices 6 x {3 * N_EL} doubles; recorded outputs {mem:.1f} MiB "
          "(3 arrays of elements x steps); no dense matrix")


if __name__ == "__main__":
    main()
