!> Slider-crank with a rigid crank and an elastic connecting rod ([Andalas],
!> Univ. Andalas): kineto-elastodynamic (KED) finite-element model of the rod,
!> Newmark average-acceleration time integration, banded Cholesky solver.
!>
!> Units: SI throughout (m, kg, s, N, Pa, rad).
!>
!> Mechanism: crank O-A of radius r2 turning counter-clockwise at constant
!> speed omega (theta2 = omega*t), rod A-C of length L, slider C on the +X axis.
!> Rigid kinematics (paper eqs. 2-10, corrected: docs/slidercrank.md):
!>   theta3 = asin(-r2 sin theta2 / L), x4 = r2 cos theta2 + L cos theta3.
!>
!> FE model (docs/slidercrank.md): n equal two-node frame elements with
!> nodal (u, v, theta) = axial, transverse displacement and rotation, measured
!> from the rigid configuration in rod axes (x along A->C).  Consistent mass
!> (eq. 26) and stiffness (eq. 29, entry (5,3) = -6EI/L^2).
!> Boundary conditions: node 0 (crank pin) u = v = 0, theta free; node n
!> (slider) carries the global X displacement U_X of the slider (U_Y = 0 on the
!> guide), u_n = cos(theta3) U_X, v_n = -sin(theta3) U_X, theta free.  The
!> slider mass msl (slider + its bearing) is lumped on U_X.
!> Generalised coordinates q (nq = 3n): q(1) = theta_0; q(3j-1:3j+1) =
!> (u_j, v_j, theta_j) for j = 1..n-1; q(3n-1) = theta_n; q(3n) = U_X.
!> Half bandwidth kd = 5 in this ordering.
!>
!> Equation of motion (eq. 30 with eq. 23: normal, Coriolis and tangential
!> terms neglected):  M q'' + C q' + (K + K_G) q = Q(t),
!>   Q = -T^T M_rod u_r'' - msl A_h e_X,   C = alpha M + beta K (Rayleigh),
!> u_r'' the rigid acceleration of the rod nodes in rod axes, A_h the slider
!> acceleration.  K_G (optional) is the geometric stiffness of the rigid-body
!> axial force, element-averaged.
!>
!> Fast path (linear, no K_G): every matrix entry except those of U_X is
!> constant, so the leading (nq-1) block of the Newmark matrix is factored once
!> and U_X enters through a 1x1 Schur complement whose coupling column is
!> cos(theta3) e_u - sin(theta3) e_v with e_u, e_v constant (A^-1 e_u and
!> A^-1 e_v are precomputed).  General path: the whole banded matrix is
!> assembled and factored every step (used with K_G).
module slidercrank
  use kinds, only: dp
  implicit none
  private
  public :: simulate, assemble_matrices, rigid_states, axial_force_at, analytic_frequencies
  !> building blocks shared with the geometrically nonlinear rod (fortran/slidercrank_nl.f90)
  !> (not wrapped for Python: fortran/meson.build lists them after f2py's skip:)
  public :: rigid_kin, element_matrices, element_map, apply_ops, band_cholesky, band_solve

  !> half bandwidth of the banded matrices in q ordering
  integer, parameter, public :: kd = 5
  !> status codes shared with driver/kernels.py (SLIDERCRANK_STATUS) and driver/slidercrank/
  integer, parameter, public :: st_ok = 0, st_buckled = 1, st_diverged = 2, st_not_spd = 3, &
                                st_bad_args = 4
  !> rows of simulate's per-step profile prof(n_prof, nrec)
  integer, parameter, public :: prof_eps_1 = 1, prof_eps_2 = 2, prof_eps_max = 3, prof_eps_max_el = 4, &
                                prof_eps_min = 5, prof_eps_min_el = 6, prof_outer_max = 7, &
                                prof_n_avg_1 = 8, prof_lag_change = 9, n_prof = 9
  real(dp), parameter :: pi = 3.14159265358979323846_dp

contains

  ! ------------------------------------------------------------------ rigid body

  !> Rigid kinematics at crank angle theta2 [rad] for constant crank speed omega [rad/s].
  !> kin = (theta3, theta3', theta3'', x4, A_h, aA_par, aA_perp):
  !> rod angle [rad], its rate [rad/s] and acceleration [rad/s^2], slider position [m],
  !> slider acceleration [m/s^2], crank-pin acceleration along and across the rod [m/s^2].
  subroutine rigid_kin(theta2, omega, r2, rl, kin)
    real(dp), intent(in) :: theta2, omega, r2, rl
    real(dp), intent(out) :: kin(7)
    real(dp) :: s2, c2, s3, c3, th3, th3d, th3dd, ax, ay
    s2 = sin(theta2)
    c2 = cos(theta2)
    th3 = asin(-r2*s2/rl)
    s3 = sin(th3)
    c3 = cos(th3)
    th3d = -r2*omega*c2/(rl*c3)
    th3dd = (r2*omega**2*s2 + rl*th3d**2*s3)/(rl*c3)
    ax = -r2*omega**2*c2
    ay = -r2*omega**2*s2
    kin(1) = th3
    kin(2) = th3d
    kin(3) = th3dd
    kin(4) = r2*c2 + rl*c3
    kin(5) = -r2*omega**2*c2 - rl*(th3dd*s3 + th3d**2*c3)
    kin(6) = ax*c3 + ay*s3
    kin(7) = -ax*s3 + ay*c3
  end subroutine rigid_kin

  !> Rigid-body axial force N(s) = n0 + n1 s + n2 s^2 [N] (tension positive) at arc length s
  !> [m] from the crank pin, from d'Alembert statics of the rod (mass per length rhoa) plus
  !> the slider msl; the guide force F_g follows from moments about the crank pin.
  pure subroutine axial_coeffs(kin, rl, rhoa, msl, nc)
    real(dp), intent(in) :: kin(7), rl, rhoa, msl
    real(dp), intent(out) :: nc(3)
    real(dp) :: s3, c3, fg, acpar, acperp
    s3 = sin(kin(1))
    c3 = cos(kin(1))
    acpar = kin(5)*c3
    acperp = -kin(5)*s3
    fg = (rhoa*(kin(7)*rl**2/2 + kin(3)*rl**3/3) + rl*msl*acperp)/(rl*c3)
    nc(1) = -(rhoa*(kin(6)*rl - kin(2)**2*rl**2/2) + msl*acpar - fg*s3)
    nc(2) = rhoa*kin(6)
    nc(3) = -rhoa*kin(2)**2/2
  end subroutine axial_coeffs

  !> N(s) from its coefficients.
  pure function axial_force(s, nc) result(n)
    real(dp), intent(in) :: s, nc(3)
    real(dp) :: n
    n = nc(1) + s*(nc(2) + s*nc(3))
  end function axial_force

  !> Element average of N(s) over [sa, sb] (exact).
  pure function axial_force_avg(sa, sb, nc) result(n)
    real(dp), intent(in) :: sa, sb, nc(3)
    real(dp) :: n
    n = nc(1) + nc(2)*(sa + sb)/2 + nc(3)*(sa*sa + sa*sb + sb*sb)/3
  end function axial_force_avg

  !> Rigid kinematics at n crank angles theta2(n) [rad]; out(k, :) as rigid_kin's kin.
  subroutine rigid_states(n, theta2, omega, r2, rl, out)
    integer, intent(in) :: n
    real(dp), intent(in) :: theta2(n), omega, r2, rl
    real(dp), intent(out) :: out(n, 7)
    integer :: k
    real(dp) :: kin(7)
    do k = 1, n
      call rigid_kin(theta2(k), omega, r2, rl, kin)
      out(k, :) = kin
    end do
  end subroutine rigid_states

  !> Rigid-body axial force N [N] at ns stations s(ns) [m] for n crank angles theta2(n).
  subroutine axial_force_at(n, ns, theta2, s, omega, r2, rl, rhoa, msl, out)
    integer, intent(in) :: n, ns
    real(dp), intent(in) :: theta2(n), s(ns), omega, r2, rl, rhoa, msl
    real(dp), intent(out) :: out(ns, n)
    integer :: k, j
    real(dp) :: kin(7), nc(3)
    do k = 1, n
      call rigid_kin(theta2(k), omega, r2, rl, kin)
      call axial_coeffs(kin, rl, rhoa, msl, nc)
      do j = 1, ns
        out(j, k) = axial_force(s(j), nc)
      end do
    end do
  end subroutine axial_force_at

  !> Closed-form first natural frequencies [rad/s] of the rod at theta2 = 0:
  !> bending, pinned-pinned: w_b = pi^2 sqrt(EI/(rhoA L^4));
  !> axial, fixed at A with the slider mass msl at C: w_a = (x/L) sqrt(EA/rhoA),
  !> x the first root of x tan x = rhoA L / msl (Newton on x sin x - mu cos x).
  !> Euler load pi^2 EI / L^2 [N] of the pinned-pinned rod.
  subroutine analytic_frequencies(rhoa, ea, ei, rl, msl, w_bend, w_axial, p_euler)
    real(dp), intent(in) :: rhoa, ea, ei, rl, msl
    real(dp), intent(out) :: w_bend, w_axial, p_euler
    real(dp) :: mu, x, f, fp
    integer :: it
    w_bend = pi**2*sqrt(ei/(rhoa*rl**4))
    p_euler = pi**2*ei/rl**2
    mu = rhoa*rl/msl
    x = min(sqrt(mu), 1.2_dp)
    do it = 1, 60
      f = x*sin(x) - mu*cos(x)
      fp = sin(x) + x*cos(x) + mu*sin(x)
      x = x - f/fp
      x = min(max(x, 1.0e-12_dp), 0.5_dp*pi - 1.0e-12_dp)
      if (abs(f) < 1.0e-15_dp*max(1.0_dp, mu)) exit
    end do
    w_axial = x/rl*sqrt(ea/rhoa)
  end subroutine analytic_frequencies

  ! ------------------------------------------------------------------ elements

  !> Consistent mass (eq. 26), stiffness (eq. 29) and unit-force geometric stiffness
  !> of a frame element of length le; DOF order (u1, v1, th1, u2, v2, th2).
  subroutine element_matrices(le, rhoa, ea, ei, me, ke, kg1)
    real(dp), intent(in) :: le, rhoa, ea, ei
    real(dp), intent(out) :: me(6, 6), ke(6, 6), kg1(6, 6)
    real(dp) :: m, k, b, g
    me = 0
    ke = 0
    kg1 = 0
    m = rhoa*le
    me(1, 1) = m/3; me(4, 4) = m/3; me(1, 4) = m/6; me(4, 1) = m/6
    me(2, 2) = m*13/35; me(5, 5) = m*13/35
    me(3, 3) = m*le**2/105; me(6, 6) = m*le**2/105
    me(2, 3) = m*11*le/210; me(5, 6) = -m*11*le/210
    me(2, 5) = m*9/70
    me(2, 6) = -m*13*le/420; me(3, 5) = m*13*le/420
    me(3, 6) = -m*le**2/140
    k = ea/le
    ke(1, 1) = k; ke(4, 4) = k; ke(1, 4) = -k; ke(4, 1) = -k
    b = ei/le**3
    ke(2, 2) = 12*b; ke(5, 5) = 12*b; ke(2, 5) = -12*b
    ke(3, 3) = 4*b*le**2; ke(6, 6) = 4*b*le**2; ke(3, 6) = 2*b*le**2
    ke(2, 3) = 6*b*le; ke(2, 6) = 6*b*le; ke(3, 5) = -6*b*le; ke(5, 6) = -6*b*le
    g = 1/(30*le)
    kg1(2, 2) = 36*g; kg1(5, 5) = 36*g; kg1(2, 5) = -36*g
    kg1(3, 3) = 4*le**2*g; kg1(6, 6) = 4*le**2*g; kg1(3, 6) = -le**2*g
    kg1(2, 3) = 3*le*g; kg1(2, 6) = 3*le*g; kg1(3, 5) = -3*le*g; kg1(5, 6) = -3*le*g
    call symmetrize(me)
    call symmetrize(ke)
    call symmetrize(kg1)
  end subroutine element_matrices

  subroutine symmetrize(a)
    real(dp), intent(inout) :: a(6, 6)
    integer :: i, j
    do j = 1, 6
      do i = j + 1, 6
        a(i, j) = a(j, i)      ! every matrix is filled in its upper triangle
      end do
    end do
  end subroutine symmetrize

  !> q indices and coefficients of the six local DOFs of element e (1..nel).
  !> idx = 0 marks a constrained DOF (crank pin u, v).  Shared with slidercrank_nl.f90.
  pure subroutine element_map(e, nel, c3, s3, idx, cf)
    integer, intent(in) :: e, nel
    real(dp), intent(in) :: c3, s3
    integer, intent(out) :: idx(6)
    real(dp), intent(out) :: cf(6)
    integer :: node, k
    cf = 1
    do k = 0, 1
      node = e - 1 + k
      if (node == 0) then
        idx(3*k + 1) = 0
        idx(3*k + 2) = 0
        idx(3*k + 3) = 1
        cf(3*k + 1) = 0
        cf(3*k + 2) = 0
      else if (node == nel) then
        idx(3*k + 1) = 3*nel
        idx(3*k + 2) = 3*nel
        idx(3*k + 3) = 3*nel - 1
        cf(3*k + 1) = c3
        cf(3*k + 2) = -s3
      else
        idx(3*k + 1) = 3*node - 1
        idx(3*k + 2) = 3*node
        idx(3*k + 3) = 3*node + 1
      end if
    end do
  end subroutine element_map

  !> Banded (lower, kd = 5) assembly of  sum_e T^T (se + nbar(e) kg1) T  + dslider e_X e_X^T.
  subroutine assemble_band(nel, nq, se, kg1, nbar, use_g, c3, s3, dslider, ab)
    integer, intent(in) :: nel, nq
    real(dp), intent(in) :: se(6, 6), kg1(6, 6), nbar(nel), c3, s3, dslider
    logical, intent(in) :: use_g
    real(dp), intent(out) :: ab(kd + 1, nq)
    integer :: e, a, b, idx(6)
    real(dp) :: cf(6), s(6, 6)
    ab = 0
    s = se
    do e = 1, nel
      call element_map(e, nel, c3, s3, idx, cf)
      if (use_g) s = se + nbar(e)*kg1
      do b = 1, 6
        if (idx(b) == 0) cycle
        do a = 1, 6
          if (idx(a) == 0 .or. idx(a) < idx(b)) cycle
          ab(1 + idx(a) - idx(b), idx(b)) = ab(1 + idx(a) - idx(b), idx(b)) + cf(a)*cf(b)*s(a, b)
        end do
      end do
    end do
    ab(1, nq) = ab(1, nq) + dslider
  end subroutine assemble_band

  !> r = T^T [ Me (T qm - load*ur'') + Ke T qk + Kg(nbar) T qg ] + msl (qm_X - load*A_h) e_X
  !> (the inertia, stiffness and rigid-body load terms of the equation of motion).
  !> The mesh is uniform, so the assembled consistent Me and Ke act on interior nodes as
  !> constant three-node stencils (the sums of the element rows 4-6 of element j and 1-3 of
  !> element j+1, simplified with the element symmetries); the end nodes take one element.
  !> The rarely used K_G term is applied element by element.
  subroutine apply_ops(nel, nq, qm, qk, qg, use_g, load, kin, le, me, ke, kg1, nbar, msl, r)
    integer, intent(in) :: nel, nq
    real(dp), intent(in) :: qm(nq), qk(nq), qg(nq), load, kin(7), le
    real(dp), intent(in) :: me(6, 6), ke(6, 6), kg1(6, 6), nbar(nel), msl
    logical, intent(in) :: use_g
    real(dp), intent(out) :: r(nq)
    real(dp) :: xu(0:nel), xv(0:nel), xt(0:nel), yu(0:nel), yv(0:nel), yt(0:nel)
    real(dp) :: xg(6), f(6), c3, s3, w2, th3dd, ru, rv, rt
    real(dp) :: m11, m14, m22, m23, m25, m26, m33, m35, m36, m56, k11, k22, k23, k33, k36
    integer :: j, e
    c3 = cos(kin(1))
    s3 = sin(kin(1))
    w2 = kin(2)**2
    th3dd = kin(3)
    m11 = me(1, 1); m14 = me(1, 4)
    m22 = me(2, 2); m23 = me(2, 3); m25 = me(2, 5); m26 = me(2, 6); m33 = me(3, 3); m35 = me(3, 5)
    m36 = me(3, 6); m56 = me(5, 6)
    k11 = ke(1, 1); k22 = ke(2, 2); k23 = ke(2, 3); k33 = ke(3, 3); k36 = ke(3, 6)
    ! nodal values in rod axes; x = T qm - load * rigid acceleration, y = T qk
    xu(0) = 0; xv(0) = 0; xt(0) = qm(1)
    yu(0) = 0; yv(0) = 0; yt(0) = qk(1)
    ! hot-loop: slidercrank apply_ops gather
    do j = 1, nel - 1
      xu(j) = qm(3*j - 1); xv(j) = qm(3*j); xt(j) = qm(3*j + 1)
      yu(j) = qk(3*j - 1); yv(j) = qk(3*j); yt(j) = qk(3*j + 1)
    end do
    xu(nel) = c3*qm(nq); xv(nel) = -s3*qm(nq); xt(nel) = qm(nq - 1)
    yu(nel) = c3*qk(nq); yv(nel) = -s3*qk(nq); yt(nel) = qk(nq - 1)
    if (abs(load) > 0) then
      ! hot-loop: slidercrank apply_ops rigid load
      do j = 0, nel
        xu(j) = xu(j) - load*(kin(6) - j*le*w2)
        xv(j) = xv(j) - load*(kin(7) + j*le*th3dd)
        xt(j) = xt(j) - load*th3dd
      end do
    end if
    ! crank-pin node: only its rotation is free (row 3 of element 1)
    r(1) = m23*xv(0) + m33*xt(0) + m35*xv(1) + m36*xt(1) + k23*(yv(0) - yv(1)) + k33*yt(0) + k36*yt(1)
    ! hot-loop: slidercrank apply_ops stencil
    do j = 1, nel - 1
      r(3*j - 1) = m14*(xu(j - 1) + xu(j + 1)) + 2*m11*xu(j) + k11*(2*yu(j) - yu(j - 1) - yu(j + 1))
      r(3*j) = m25*(xv(j - 1) + xv(j + 1)) + m26*(xt(j + 1) - xt(j - 1)) + 2*m22*xv(j) &
               + k22*(2*yv(j) - yv(j - 1) - yv(j + 1)) + k23*(yt(j + 1) - yt(j - 1))
      r(3*j + 1) = m26*(xv(j - 1) - xv(j + 1)) + m36*(xt(j - 1) + xt(j + 1)) + 2*m33*xt(j) &
                   + k23*(yv(j - 1) - yv(j + 1)) + k36*(yt(j - 1) + yt(j + 1)) + 2*k33*yt(j)
    end do
    ! slider node: rows 4-6 of element nel, rotated onto U_X
    j = nel
    ru = m14*xu(j - 1) + m11*xu(j) + k11*(yu(j) - yu(j - 1))
    rv = m25*xv(j - 1) + m35*xt(j - 1) + m22*xv(j) + m56*xt(j) - k22*(yv(j - 1) - yv(j)) - k23*(yt(j - 1) + yt(j))
    rt = m26*xv(j - 1) + m36*xt(j - 1) + m56*xv(j) + m33*xt(j) + k23*(yv(j - 1) - yv(j)) + k36*yt(j - 1) &
         + k33*yt(j)
    r(nq) = c3*ru - s3*rv + msl*(qm(nq) - load*kin(5))
    r(nq - 1) = rt
    if (use_g) then
      do e = 1, nel
        j = e - 1
        if (j == 0) then
          xg(1:3) = [0.0_dp, 0.0_dp, qg(1)]
        else
          xg(1:3) = qg(3*j - 1:3*j + 1)
        end if
        if (e == nel) then
          xg(4:6) = [c3*qg(nq), -s3*qg(nq), qg(nq - 1)]
        else
          xg(4:6) = qg(3*e - 1:3*e + 1)
        end if
        f = nbar(e)*matmul(kg1, xg)
        if (j == 0) then
          r(1) = r(1) + f(3)
        else
          r(3*j - 1:3*j + 1) = r(3*j - 1:3*j + 1) + f(1:3)
        end if
        if (e == nel) then
          r(nq) = r(nq) + c3*f(4) - s3*f(5)
          r(nq - 1) = r(nq - 1) + f(6)
        else
          r(3*e - 1:3*e + 1) = r(3*e - 1:3*e + 1) + f(4:6)
        end if
      end do
    end if
  end subroutine apply_ops

  ! ------------------------------------------------------------------ banded Cholesky

  !> In-place Cholesky A = L L^T of an SPD band matrix in lower storage
  !> ab(1 + i - j, j) = A(i, j), j <= i <= min(n, j + kd).  On exit ab(1, j) holds the
  !> reciprocal 1/L(j, j) (band_solve multiplies: no division in the substitutions) and
  !> ab(1 + i, j) = L(j + i, j).  info = 0 on success, otherwise the column whose pivot
  !> was not positive.
  subroutine band_cholesky(n, ab, info)
    integer, intent(in) :: n
    real(dp), intent(inout) :: ab(kd + 1, n)
    integer, intent(out) :: info
    integer :: j, i, k, kn
    real(dp) :: ajj
    info = 0
    do j = 1, n
      ajj = ab(1, j)
      if (.not. (ajj > 0)) then
        info = j
        return
      end if
      ajj = 1/sqrt(ajj)
      ab(1, j) = ajj
      if (j <= n - kd) then     ! full-width column: fixed trip counts (unrolled), same operations
        ab(2:kd + 1, j) = ab(2:kd + 1, j)*ajj
        do i = 1, kd
          do k = i, kd
            ab(1 + k - i, j + i) = ab(1 + k - i, j + i) - ab(1 + k, j)*ab(1 + i, j)
          end do
        end do
        cycle
      end if
      kn = n - j
      ab(2:kn + 1, j) = ab(2:kn + 1, j)*ajj
      do i = 1, kn
        do k = i, kn
          ab(1 + k - i, j + i) = ab(1 + k - i, j + i) - ab(1 + k, j)*ab(1 + i, j)
        end do
      end do
    end do
  end subroutine band_cholesky

  !> Solve L L^T x = b with the factor of band_cholesky; b is overwritten by x.
  subroutine band_solve(n, ab, b)
    integer, intent(in) :: n
    real(dp), intent(in) :: ab(kd + 1, n)
    real(dp), intent(inout) :: b(n)
    integer :: j, i
    real(dp) :: s
    do j = 1, n - kd          ! full-width columns: fixed trip count (unrolled by the compiler)
      b(j) = b(j)*ab(1, j)
      do i = 1, kd
        b(j + i) = b(j + i) - ab(1 + i, j)*b(j)
      end do
    end do
    do j = max(1, n - kd + 1), n
      b(j) = b(j)*ab(1, j)
      do i = 1, n - j
        b(j + i) = b(j + i) - ab(1 + i, j)*b(j)
      end do
    end do
    do j = n, max(1, n - kd + 1), -1
      s = b(j)
      do i = 1, n - j
        s = s - ab(1 + i, j)*b(j + i)
      end do
      b(j) = s*ab(1, j)
    end do
    do j = n - kd, 1, -1
      s = b(j)
      do i = 1, kd
        s = s - ab(1 + i, j)*b(j + i)
      end do
      b(j) = s*ab(1, j)
    end do
  end subroutine band_solve

  !> Latency-friendly form of a band_cholesky factor for repeated solves with one matrix:
  !> d(j) = 1/L(j, j), lf(i, j) = L(j, j - i) d(j) (rows, forward), lb(i, j) = L(j + i, j) d(j)
  !> (columns, backward); entries outside the matrix are zero.
  subroutine band_prepare(n, ab, d, lf, lb)
    integer, intent(in) :: n
    real(dp), intent(in) :: ab(kd + 1, n)
    real(dp), intent(out) :: d(n), lf(kd, n), lb(kd, n)
    integer :: i, j
    d = ab(1, :)
    lf = 0
    lb = 0
    do j = 1, n
      do i = 1, kd
        if (j - i >= 1) lf(i, j) = ab(1 + i, j - i)*d(j)
        if (j + i <= n) lb(i, j) = ab(1 + i, j)*d(j)
      end do
    end do
  end subroutine band_prepare

  !> Solve L L^T x = b with band_prepare's arrays; b is overwritten by x.  Each unknown
  !> waits on its neighbour through one multiply-add only (the nearest term is added last).
  subroutine band_solve_prepared(n, d, lf, lb, b)
    integer, intent(in) :: n
    real(dp), intent(in) :: d(n), lf(kd, n), lb(kd, n)
    real(dp), intent(inout) :: b(n)
    integer :: j, i, m
    real(dp) :: t
    m = min(kd, n)
    do j = 1, m                    ! head rows: fewer than kd neighbours, furthest first
      t = d(j)*b(j)
      do i = j - 1, 1, -1
        t = t - lf(i, j)*b(j - i)
      end do
      b(j) = t
    end do
    do j = m + 1, n
      b(j) = ((((d(j)*b(j) - lf(5, j)*b(j - 5)) - lf(4, j)*b(j - 4)) - lf(3, j)*b(j - 3)) &
              - lf(2, j)*b(j - 2)) - lf(1, j)*b(j - 1)
    end do
    do j = n, n - m + 1, -1        ! tail rows of the back substitution
      t = d(j)*b(j)
      do i = n - j, 1, -1
        t = t - lb(i, j)*b(j + i)
      end do
      b(j) = t
    end do
    do j = n - m, 1, -1
      b(j) = ((((d(j)*b(j) - lb(5, j)*b(j + 5)) - lb(4, j)*b(j + 4)) - lb(3, j)*b(j + 3)) &
              - lb(2, j)*b(j + 2)) - lb(1, j)*b(j + 1)
    end do
  end subroutine band_solve_prepared

  ! ------------------------------------------------------------------ public assembly

  !> Banded (lower, kd = 5) mass mb and stiffness kb of the rod model in q coordinates at
  !> crank angle theta2 [rad]; mb includes the slider mass msl on U_X; with geom = 1, kb
  !> includes K_G of the element-averaged rigid axial force at crank speed omega [rad/s].
  subroutine assemble_matrices(nel, nq, r2, rl, rhoa, ea, ei, msl, theta2, omega, geom, mb, kb)
    integer, intent(in) :: nel, nq, geom
    real(dp), intent(in) :: r2, rl, rhoa, ea, ei, msl, theta2, omega
    real(dp), intent(out) :: mb(6, nq), kb(6, nq)   ! 6 = kd + 1 (f2py needs a literal)
    real(dp) :: me(6, 6), ke(6, 6), kg1(6, 6), kin(7), nbar(nel), le, nc(3)
    integer :: e
    mb = 0
    kb = 0
    if (nq /= 3*nel .or. nel < 1) return
    le = rl/nel
    call element_matrices(le, rhoa, ea, ei, me, ke, kg1)
    call rigid_kin(theta2, omega, r2, rl, kin)
    call axial_coeffs(kin, rl, rhoa, msl, nc)
    do e = 1, nel
      nbar(e) = axial_force_avg((e - 1)*le, e*le, nc)
    end do
    call assemble_band(nel, nq, me, kg1, nbar, .false., cos(kin(1)), sin(kin(1)), msl, mb)
    call assemble_band(nel, nq, ke, kg1, nbar, geom /= 0, cos(kin(1)), sin(kin(1)), 0.0_dp, kb)
  end subroutine assemble_matrices

  ! ------------------------------------------------------------------ time integration

  !> Time integration of the elastic rod over nsteps steps of dt [s] from theta2 = 0.
  !>
  !> dynamic    1: Newmark average acceleration; 0: quasi-static K q = Q every step
  !> start_mode 0 rest (q = q' = 0), 1 quasi-static (q = K^-1 Q, q' by central difference
  !>            of the quasi-static solution), 2 given (q_init, qd_init)
  !> geom       1: add K_G(N) of the rigid-body axial force; the static tangent K + K_G is
  !>            checked every step and its loss of definiteness reported as buckling
  !> fast       1: constant-leading-block + Schur path when geom = 0; 0: general path
  !> alpha, beta  Rayleigh damping C = alpha M + beta K [1/s, s]
  !> half_depth outer-fibre distance c [m] for the bending strain |eps| + c |kappa|
  !>
  !> Recorded for steps k = rec_start .. rec_start + nrec - 1 (k = 0 is the start):
  !> eps_ax(e, j) element axial strain (u_e - u_{e-1})/le; eps_of(e, j) outer-fibre
  !> strain |eps| + c |kappa| with kappa = (th_e - th_{e-1})/le; n_avg(e, j) element-averaged
  !> rigid-body axial force [N] -- these three fields only when nrf = nrec (nrf = 0: not
  !> recorded, the profile below is what a study prints); mid(j) midpoint deflection from the
  !> chord A-C [m]; slider(j) slider position x4 + U_X [m]; elong(j) rod elongation u_n [m];
  !> prof(:, j) the per-step profile of the fields (rows prof_*): axial strain of elements 1
  !> and 2 (element 1 again when nel = 1), the largest and smallest axial strain and their
  !> elements (the first such element, as a real), the largest outer-fibre strain, n_avg of
  !> element 1; with lag > 0 also prof_lag_change: max over e of |eps_ax(e, j) - eps_ax(e, j - lag)|
  !> (recorded steps; 0 for j <= lag), from a ring of the last lag strain columns.
  !> q_end, qd_end: final state.  status: st_ok, st_buckled (static tangent lost
  !> definiteness), st_diverged (elastic translation > L/20, rotation > 0.25 rad, or NaN), st_not_spd, st_bad_args;
  !> fail_step: the step where it happened.
  subroutine simulate(nel, nq, nrec, nrf, r2, rl, rhoa, ea, ei, half_depth, msl, omega, dt, nsteps, &
                      rec_start, alpha, beta, start_mode, dynamic, geom, fast, lag, q_init, qd_init, &
                      eps_ax, eps_of, n_avg, mid, slider, elong, prof, q_end, qd_end, status, fail_step)
    !f2py threadsafe
    integer, intent(in) :: nel, nq, nrec, nrf, nsteps, rec_start, start_mode, dynamic, geom, fast, lag
    real(dp), intent(in) :: r2, rl, rhoa, ea, ei, half_depth, msl, omega, dt, alpha, beta
    real(dp), intent(in) :: q_init(nq), qd_init(nq)
    real(dp), intent(out) :: eps_ax(nel, nrf), eps_of(nel, nrf), n_avg(nel, nrf)
    real(dp), intent(out) :: mid(nrec), slider(nrec), elong(nrec), q_end(nq), qd_end(nq)
    real(dp), intent(out) :: prof(9, nrec)   ! 9 = n_prof (f2py needs the literal)
    integer, intent(out) :: status, fail_step
    real(dp), allocatable :: ring(:, :)

    real(dp), allocatable :: q(:), qd(:), qdd(:), qn(:), r(:), w1(:), w2(:), zero(:)
    real(dp), allocatable :: ab(:, :), at(:, :), afac(:, :), zu(:), zv(:), eu(:), ev(:), tmp(:)
    real(dp), allocatable :: fd(:), flf(:, :), flb(:, :)
    real(dp) :: me(6, 6), ke(6, 6), kg1(6, 6), se(6, 6), kin(7), nbar(nel), nzero(nel)
    real(dp) :: le, a0, a1, a2, a3, a4, a5, ck, cm, t, c3, s3, h
    real(dp) :: uu, uv, vv, d44, d45, d55, by, bz, den, ux, limit
    integer :: k, info, nl, idx(6), a, j0, j
    real(dp) :: cf(6)
    logical :: use_g, use_fast, dyn

    status = st_ok
    fail_step = -1
    eps_ax = 0
    eps_of = 0
    n_avg = 0
    mid = 0
    slider = 0
    elong = 0
    prof = 0
    q_end = 0
    qd_end = 0
    if (nel < 1 .or. nq /= 3*nel .or. nsteps < 0 .or. dt <= 0 .or. (nrf /= 0 .and. nrf /= nrec) &
        .or. lag < 0) then
      status = st_bad_args
      return
    end if
    allocate (ring(nel, max(lag, 1)))
    use_g = geom /= 0
    dyn = dynamic /= 0
    use_fast = fast /= 0 .and. .not. use_g
    nl = nq - 1
    j0 = max(1, nl - 3)
    le = rl/nel
    limit = rl/20
    nzero = 0
    allocate (q(nq), qd(nq), qdd(nq), qn(nq), r(nq), w1(nq), w2(nq), zero(nq), tmp(nq))
    allocate (ab(kd + 1, nq), at(kd + 1, nq))
    zero = 0
    call element_matrices(le, rhoa, ea, ei, me, ke, kg1)

    if (dyn) then
      a0 = 4/dt**2
      a1 = 2/dt
      a2 = 4/dt
      a3 = 1
      a4 = 1
      a5 = 0
      ck = 1 + a1*beta
      cm = a0 + a1*alpha
    else
      a0 = 0; a1 = 0; a2 = 0; a3 = 0; a4 = 0; a5 = 0
      ck = 1
      cm = 0
    end if
    se = ck*ke + cm*me

    ! ---- fast path: factor the constant leading block once, precompute A^-1 e_u, A^-1 e_v
    if (use_fast) then
      allocate (afac(kd + 1, nq), zu(nl), zv(nl), eu(nl), ev(nl))
      call assemble_band(nel, nq, se, kg1, nzero, .false., 1.0_dp, 0.0_dp, cm*msl, afac)
      call band_cholesky(nl, afac(:, 1:nl), info)
      if (info /= 0) then
        status = st_not_spd
        fail_step = 0
        return
      end if
      eu = 0
      ev = 0
      call element_map(nel, nel, 1.0_dp, 0.0_dp, idx, cf)
      do a = 1, 6
        if (a == 4 .or. a == 5 .or. idx(a) == 0) cycle
        eu(idx(a)) = eu(idx(a)) + se(a, 4)
        ev(idx(a)) = ev(idx(a)) + se(a, 5)
      end do
      zu = eu
      zv = ev
      allocate (fd(nl), flf(kd, nl), flb(kd, nl))
      call band_prepare(nl, afac(:, 1:nl), fd, flf, flb)
      deallocate (afac)
      call band_solve_prepared(nl, fd, flf, flb, zu)
      call band_solve_prepared(nl, fd, flf, flb, zv)
      uu = dot_product(eu, zu)
      uv = dot_product(eu, zv)
      vv = dot_product(ev, zv)
      d44 = se(4, 4)
      d45 = se(4, 5)
      d55 = se(5, 5)
    end if

    ! ---- initial state
    call rigid_kin(0.0_dp, omega, r2, rl, kin)
    call element_nbar(nel, le, rl, rhoa, msl, kin, nbar)
    select case (start_mode)
    case (1)
      h = dt
      call quasi_static_solve(nel, nq, r2, rl, rhoa, msl, omega, le, use_g, me, ke, kg1, zero, at, &
                              info, -h, tmp)
      if (info /= 0) then
        status = merge(st_buckled, st_not_spd, use_g)
        fail_step = 0
        return
      end if
      call quasi_static_solve(nel, nq, r2, rl, rhoa, msl, omega, le, use_g, me, ke, kg1, zero, at, &
                              info, h, qd)
      if (info /= 0) then
        status = merge(st_buckled, st_not_spd, use_g)
        fail_step = 0
        return
      end if
      qd = (qd - tmp)/(2*h)
      call quasi_static_solve(nel, nq, r2, rl, rhoa, msl, omega, le, use_g, me, ke, kg1, zero, at, &
                              info, 0.0_dp, q)
      if (info /= 0) then
        status = merge(st_buckled, st_not_spd, use_g)
        fail_step = 0
        return
      end if
    case (2)
      q = q_init
      qd = qd_init
    case default
      q = 0
      qd = 0
    end select
    qdd = 0
    if (dyn) then
      ! q'' from the equation of motion: M q'' = Q - C q' - (K + K_G) q
      w1 = -alpha*qd
      w2 = -beta*qd - q
      tmp = -q
      call apply_ops(nel, nq, w1, w2, tmp, use_g, 1.0_dp, kin, le, me, ke, kg1, nbar, msl, qdd)
      call assemble_band(nel, nq, me, kg1, nbar, .false., cos(kin(1)), sin(kin(1)), msl, at)
      call band_cholesky(nq, at, info)
      if (info /= 0) then
        status = st_not_spd
        fail_step = 0
        return
      end if
      call band_solve(nq, at, qdd)
    end if
    if (rec_start == 0) call record_step(nel, nq, nrec, nrf, 1, q, kin, le, rl, rhoa, msl, half_depth, &
                                         eps_ax, eps_of, n_avg, mid, slider, elong, prof, lag, ring)

    ! ---- time loop
    do k = 1, nsteps
      t = k*dt
      call rigid_kin(omega*t, omega, r2, rl, kin)
      c3 = cos(kin(1))
      s3 = sin(kin(1))
      if (use_g) then
        call element_nbar(nel, le, rl, rhoa, msl, kin, nbar)
        call assemble_band(nel, nq, ke, kg1, nbar, .true., c3, s3, 0.0_dp, at)
        call band_cholesky(nq, at, info)
        if (info /= 0) then
          status = st_buckled
          fail_step = k
          exit
        end if
      end if
      if (dyn) then
        ! hot-loop: slidercrank newmark predictor
        do j = 1, nq
          w1(j) = (a0 + alpha*a1)*q(j) + (a2 + alpha*a4)*qd(j) + (a3 + alpha*a5)*qdd(j)
          w2(j) = beta*(a1*q(j) + a4*qd(j) + a5*qdd(j))
        end do
        call apply_ops(nel, nq, w1, w2, zero, .false., 1.0_dp, kin, le, me, ke, kg1, nbar, msl, r)
      else
        call apply_ops(nel, nq, zero, zero, zero, .false., 1.0_dp, kin, le, me, ke, kg1, nbar, msl, r)
      end if
      if (use_fast) then
        qn(1:nl) = r(1:nl)
        call band_solve_prepared(nl, fd, flf, flb, qn(1:nl))
        by = c3*dot_product(eu(j0:nl), qn(j0:nl)) - s3*dot_product(ev(j0:nl), qn(j0:nl))
        bz = c3*c3*uu - 2*c3*s3*uv + s3*s3*vv
        den = c3*c3*d44 - 2*c3*s3*d45 + s3*s3*d55 + cm*msl - bz
        ux = (r(nq) - by)/den
        ! hot-loop: slidercrank schur correction
        do j = 1, nl
          qn(j) = qn(j) - ux*(c3*zu(j) - s3*zv(j))
        end do
        qn(nq) = ux
      else
        if (dyn .or. .not. use_g) then
          call assemble_band(nel, nq, se, kg1, nbar, use_g, c3, s3, cm*msl, ab)
          call band_cholesky(nq, ab, info)
          if (info /= 0) then
            status = st_not_spd
            fail_step = k
            exit
          end if
          qn = r
          call band_solve(nq, ab, qn)
        else
          qn = r
          call band_solve(nq, at, qn)
        end if
      end if
      if (dyn) then
        ! hot-loop: slidercrank newmark update
        do j = 1, nq
          h = a0*(qn(j) - q(j)) - a2*qd(j) - a3*qdd(j)
          qd(j) = qd(j) + 0.5_dp*dt*(qdd(j) + h)
          qdd(j) = h
          q(j) = qn(j)
        end do
      else
        q = qn
      end if
      if (.not. small_motion(nq, q, limit)) then
        status = st_diverged
        fail_step = k
        exit
      end if
      if (k >= rec_start .and. k < rec_start + nrec) &
        call record_step(nel, nq, nrec, nrf, k - rec_start + 1, q, kin, le, rl, rhoa, msl, &
                          half_depth, eps_ax, eps_of, n_avg, mid, slider, elong, prof, lag, ring)
    end do
    q_end = q
    qd_end = qd

  end subroutine simulate

  !> True while every elastic translation is within limit [m] and every elastic rotation
  !> within 0.25 rad (beyond that a small-displacement model has lost its meaning); false
  !> also for NaN.
  logical function small_motion(nq, q, limit)
    integer, intent(in) :: nq
    real(dp), intent(in) :: q(nq), limit
    integer :: j
    real(dp) :: tmax, rmax
    tmax = abs(q(nq))
    rmax = max(abs(q(1)), abs(q(nq - 1)))
    ! hot-loop: slidercrank small_motion
    do j = 1, nq/3 - 1
      tmax = max(tmax, abs(q(3*j - 1)), abs(q(3*j)))
      rmax = max(rmax, abs(q(3*j + 1)))
    end do
    small_motion = tmax <= limit .and. rmax <= 0.25_dp
  end function small_motion

  !> Element-averaged rigid-body axial force nb(e) [N] for the rigid state kin.
  subroutine element_nbar(nel, le, rl, rhoa, msl, kin, nb)
    integer, intent(in) :: nel
    real(dp), intent(in) :: le, rl, rhoa, msl, kin(7)
    real(dp), intent(out) :: nb(nel)
    integer :: e
    real(dp) :: nc(3)
    call axial_coeffs(kin, rl, rhoa, msl, nc)
    do e = 1, nel
      nb(e) = axial_force_avg((e - 1)*le, e*le, nc)
    end do
  end subroutine element_nbar

  !> Quasi-static solution (K + K_G) qs = Q at time tq [s]; at returns the factor.
  subroutine quasi_static_solve(nel, nq, r2, rl, rhoa, msl, omega, le, use_g, me, ke, kg1, zero, at, &
                                info, tq, qs)
    integer, intent(in) :: nel, nq
    real(dp), intent(in) :: r2, rl, rhoa, msl, omega, le, me(6, 6), ke(6, 6), kg1(6, 6), zero(nq), tq
    logical, intent(in) :: use_g
    real(dp), intent(out) :: at(kd + 1, nq), qs(nq)
    integer, intent(out) :: info
    real(dp) :: kq(7), nb(nel)
    call rigid_kin(omega*tq, omega, r2, rl, kq)
    call element_nbar(nel, le, rl, rhoa, msl, kq, nb)
    call apply_ops(nel, nq, zero, zero, zero, .false., 1.0_dp, kq, le, me, ke, kg1, nb, msl, qs)
    call assemble_band(nel, nq, ke, kg1, nb, use_g, cos(kq(1)), sin(kq(1)), 0.0_dp, at)
    call band_cholesky(nq, at, info)
    if (info /= 0) return
    call band_solve(nq, at, qs)
  end subroutine quasi_static_solve

  !> Store the outputs of one recorded step in column j (see simulate): the fields when
  !> nrf > 0, always the scalars and the profile; ring(:, mod(j - 1, lag) + 1) holds the
  !> strain column of recorded step j - lag on entry (lag > 0) and that of step j on return.
  subroutine record_step(nel, nq, nrec, nrf, j, q, kin, le, rl, rhoa, msl, half_depth, &
                         eps_ax, eps_of, n_avg, mid, slider, elong, prof, lag, ring)
    integer, intent(in) :: nel, nq, nrec, nrf, j, lag
    real(dp), intent(in) :: q(nq), kin(7), le, rl, rhoa, msl, half_depth
    real(dp), intent(inout) :: eps_ax(nel, nrf), eps_of(nel, nrf), n_avg(nel, nrf)
    real(dp), intent(inout) :: mid(nrec), slider(nrec), elong(nrec), prof(9, nrec)   ! 9 = n_prof
    real(dp), intent(inout) :: ring(nel, max(lag, 1))
    integer :: ee, m, emax, emin, slot
    real(dp) :: ua, ub, ta, tb, ep, ka, vn, va, vb, cc, ss, nc(3), inv, c1, c2, third
    real(dp) :: ecol(nel), ocol(nel), vmax, vmin, omax, dmax
    call axial_coeffs(kin, rl, rhoa, msl, nc)
    cc = cos(kin(1))
    ss = sin(kin(1))
    inv = 1/le
    third = 1.0_dp/3
    c1 = nc(2)*le
    c2 = nc(3)*le*le
    if (nrf > 0) then
      ! hot-loop: slidercrank record_step axial force
      do ee = 1, nel
        ! element average of N over [(ee-1) le, ee le]: sa^2 + sa sb + sb^2 = le^2 (3 ee^2 - 3 ee + 1)
        n_avg(ee, j) = nc(1) + c1*(ee - 0.5_dp) + c2*(real(ee, dp)*(ee - 1) + third)
      end do
    end if
    ! hot-loop: slidercrank record_step strains
    do ee = 2, nel - 1
      ep = (q(3*ee - 1) - q(3*ee - 4))*inv
      ka = (q(3*ee + 1) - q(3*ee - 2))*inv
      ecol(ee) = ep
      ocol(ee) = abs(ep) + half_depth*abs(ka)
    end do
    do ee = 1, nel, max(1, nel - 1)      ! the two end elements (one when nel = 1)
      ua = 0
      ta = q(1)
      if (ee > 1) then
        m = 3*ee - 4
        ua = q(m)
        ta = q(m + 2)
      end if
      if (ee == nel) then
        ub = cc*q(nq)
        tb = q(nq - 1)
      else
        ub = q(3*ee - 1)
        tb = q(3*ee + 1)
      end if
      ep = (ub - ua)*inv
      ka = (tb - ta)*inv
      ecol(ee) = ep
      ocol(ee) = abs(ep) + half_depth*abs(ka)
    end do
    if (nrf > 0) then
      eps_ax(:, j) = ecol
      eps_of(:, j) = ocol
    end if
    ! the profile: extremes with the first element reaching them (numpy's argmax order)
    vmax = ecol(1)
    vmin = ecol(1)
    omax = ocol(1)
    emax = 1
    emin = 1
    do ee = 2, nel
      if (ecol(ee) > vmax) then
        vmax = ecol(ee)
        emax = ee
      end if
      if (ecol(ee) < vmin) then
        vmin = ecol(ee)
        emin = ee
      end if
      omax = max(omax, ocol(ee))
    end do
    prof(prof_eps_1, j) = ecol(1)
    prof(prof_eps_2, j) = ecol(min(2, nel))
    prof(prof_eps_max, j) = vmax
    prof(prof_eps_max_el, j) = emax
    prof(prof_eps_min, j) = vmin
    prof(prof_eps_min_el, j) = emin
    prof(prof_outer_max, j) = omax
    prof(prof_n_avg_1, j) = nc(1) + c1*0.5_dp + c2*third
    if (lag > 0) then
      slot = mod(j - 1, lag) + 1
      dmax = 0
      if (j > lag) then
        do ee = 1, nel
          dmax = max(dmax, abs(ecol(ee) - ring(ee, slot)))
        end do
      end if
      prof(prof_lag_change, j) = dmax
      ring(:, slot) = ecol
    end if
    vn = -ss*q(nq)
    if (mod(nel, 2) == 0) then
      m = nel/2
      mid(j) = q(3*m) - 0.5_dp*vn
    else
      m = (nel + 1)/2          ! element holding the midpoint, nodes m-1 and m
      if (m == 1) then
        va = 0
        ta = q(1)
      else
        va = q(3*(m - 1))
        ta = q(3*(m - 1) + 1)
      end if
      if (m == nel) then
        vb = vn
        tb = q(nq - 1)
      else
        vb = q(3*m)
        tb = q(3*m + 1)
      end if
      mid(j) = 0.5_dp*(va + vb) + le/8*(ta - tb) - 0.5_dp*vn
    end if
    slider(j) = kin(4) + q(nq)
    elong(j) = cc*q(nq)
  end subroutine record_step

end module slidercrank
