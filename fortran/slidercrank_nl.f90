!> Slider-crank with a geometrically nonlinear connecting rod (issue 29): co-rotational
!> Euler-Bernoulli frame elements, Newmark average acceleration with Newton iterations on
!> the consistent tangent, step halving when Newton fails, banded LU solves.
!>
!> Units: SI throughout (m, kg, s, N, Pa, rad).
!>
!> Same mechanism, coordinates, boundary conditions, masses, damping and inertia loading
!> as the linear KED model (fortran/slidercrank.f90, docs/slidercrank.md): nodal (u, v, th)
!> are displacements from the rigid configuration in the rod frame (x along A->C), the
!> crank pin has u = v = 0, the slider node moves on the guide (u_n = cos(th3) U_X,
!> v_n = -sin(th3) U_X) with the slider mass on U_X, Rayleigh damping alpha M + beta K, load
!> Q = -M u_r'' - msl A_h e_X.  The elastic forces differ, and so does the stiffness-
!> proportional damping, which acts on each element's deformation rates (co-rotational,
!> beta B^T K_l B p'; the linear model's beta K0 q' would damp the finite rotations of a
!> buckled rod's elements, docs/slidercrank.md): each element's internal force and tangent come from the co-rotational
!> formulation (Crisfield 1991, ch. 7): the element chord from node a at (s_a + u_a, v_a)
!> to node b has length l and angle beta; local deformations
!>   ubar = l - le,  th1 = th_a - beta,  th2 = th_b - beta,
!> local forces N = EA ubar/le, (M1, M2) = EI/le [4 2; 2 4] (th1, th2), strain energy
!>   U_e = EA ubar^2/(2 le) + EI/(2 le) (4 th1^2 + 4 th1 th2 + 4 th2^2),
!> global force f = B^T (N, M1, M2) and the consistent tangent
!>   K_T = B^T K_l B + N z z^T / l + (M1 + M2)/l^2 (r z^T + z r^T),
!> r = (-c, -s, 0, c, s, 0), z = (s, -c, 0, -s, c, 0), c, s the chord's direction cosines.
!> At small displacements f -> K0 p (the linear frame element of eq. 29).
!>
!> Time step t_n -> t_n+1, HHT-alpha with parameter a in [-1/3, 0] (a = 0: Newmark average
!> acceleration, the linear model's rule): solve for q
!>   R(q) = M qdd + (1 + a) [alpha M qd + f(q, qd) - Q(t_n+1)] - a [same at t_n] = 0,
!>   f = f_int + the damping force of the deformation rates,
!>   Newmark beta_N = (1 - a)^2/4, gamma = 1/2 - a relating qdd, qd to q,
!> by Newton with S = dR/dq = (1/(beta_N h^2) + (1 + a) gamma alpha/(beta_N h)) M
!>   + (1 + a) [K_T(q) + gamma beta/(beta_N h) B^T K_l B + beta B^T K_l dB/dp p'], the last
!> term the variation of the deformation rates with the geometry (not symmetric: S is factored
!> by a band LU without pivoting; without it Newton converges only linearly on a buckled rod,
!> whose elements turn fast).  A solve whose residual lands within chord_ratio of the
!> tolerance is followed by one with the same factor (see newton_step).  a < 0 damps the
!> unresolved high frequencies (axial waves, the nearly massless end rotations) that the
!> average-acceleration rule keeps forever and the nonlinear coupling can feed.  Converged when
!> ||R||_2 <= tol (||Q||_2 + ||f_int||_2 + EI/L^2).  A step whose Newton iteration fails
!> (maxit solves, a pivot of S not positive, NaN) is retried as two half steps, up to
!> max_cuts halvings.
module slidercrank_nl
  use kinds, only: dp
  use slidercrank, only: rigid_kin, element_matrices, element_map, apply_ops, band_cholesky, band_solve, kd
  implicit none
  private
  public :: simulate_nl, column_static, element_corot, element_corot_d

  !> status codes shared with driver/kernels.py (SLIDERCRANK_NL_STATUS)
  !> entries of an element's state kept between its force and its tangent (element_force)
  integer, parameter :: nst = 8
  !> a Newton matrix is reused for one more solve when the residual is below chord_ratio times the tolerance
  real(dp), parameter :: chord_ratio = 1e2_dp
  integer, parameter, public :: nl_ok = 0, nl_limit = 2, nl_not_spd = 3, nl_bad_args = 4, &
                                nl_no_convergence = 5

contains

  !> Co-rotational element: force f(6), tangent kt(6,6) (if want_k), axial strain eps,
  !> mean curvature kap [1/m] and strain energy en [J] for the element displacements
  !> p = (u_a, v_a, th_a, u_b, v_b, th_b) [m, rad] in the rod frame, length le [m].
  !> B has rows r, e3 - z/l, e6 - z/l; K_l = diag(EA/le, EI/le [4 2; 2 4]).
  pure subroutine element_corot(le, ea, ei, p, want_k, f, kt, eps, kap, en)
    real(dp), intent(in) :: le, ea, ei, p(6)
    logical, intent(in) :: want_k
    real(dp), intent(out) :: f(6), kt(6, 6), eps, kap, en
    call element_corot_d(le, ea, ei, p, [0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp], 0.0_dp, 0.0_dp, &
                         want_k, f, kt, eps, kap, en)
  end subroutine element_corot

  !> element_corot with stiffness-proportional damping of the element's deformation rates:
  !> f adds bd B^T K_l B pd for the nodal velocities pd (rod frame) -- the co-rotational form
  !> of beta K0 q', which damps stretching and bending but not the element's rotation -- and kt
  !> adds cd B^T K_l B (cd = bd dpd/dp of the time rule) and, with bd /= 0, the variation of the
  !> damping force with the geometry at fixed rates (not symmetric).  kt is the full 6 x 6 matrix.
  pure subroutine element_corot_d(le, ea, ei, p, pd, bd, cd, want_k, f, kt, eps, kap, en)
    real(dp), intent(in) :: le, ea, ei, p(6), pd(6), bd, cd
    logical, intent(in) :: want_k
    real(dp), intent(out) :: f(6), kt(6, 6), eps, kap, en
    real(dp) :: st(nst)
    call element_force(le, ea, ei, p, pd, bd, f, eps, kap, en, st)
    kt = 0
    if (want_k) call element_tangent(le, ea, ei, bd, cd, st, kt)
  end subroutine element_corot_d

  !> The force half of element_corot_d: f, eps, kap, en, and the element's state st(nst) =
  !> (c, s, l, N, M1, M2, r.pd, z.pd) from which element_tangent forms kt without the
  !> square root and arc tangent (N, M1, M2 with the damping stresses).
  pure subroutine element_force(le, ea, ei, p, pd, bd, f, eps, kap, en, st)
    real(dp), intent(in) :: le, ea, ei, p(6), pd(6), bd
    real(dp), intent(out) :: f(6), eps, kap, en, st(nst)
    real(dp) :: dx, dy, l, ubar, c, s, beta, t1, t2, n, m1, m2, r(6), z(6), b2(6), b3(6)
    real(dp) :: ka, kb, d1, d2, d3, zp
    dx = le + p(4) - p(1)
    dy = p(5) - p(2)
    l = sqrt(dx*dx + dy*dy)
    ! l - le without cancellation (the strain is ~1e-5: l - le directly loses 5 digits)
    ubar = ((p(4) - p(1))*(2*le + p(4) - p(1)) + dy*dy)/(l + le)
    c = dx/l
    s = dy/l
    beta = atan2(dy, dx)
    t1 = p(3) - beta
    t2 = p(6) - beta
    eps = ubar/le
    kap = (t2 - t1)/le
    ka = ea/le
    kb = ei/le
    n = ea*eps
    m1 = kb*(4*t1 + 2*t2)
    m2 = kb*(2*t1 + 4*t2)
    en = 0.5_dp*n*ubar + kb*(2*t1*t1 + 2*t1*t2 + 2*t2*t2)
    r = [-c, -s, 0.0_dp, c, s, 0.0_dp]
    z = [s, -c, 0.0_dp, -s, c, 0.0_dp]
    b2 = -z/l
    b3 = b2
    b2(3) = 1
    b3(6) = 1
    d1 = 0
    zp = 0
    if (bd /= 0) then                ! deformation rates D = B pd, damping stresses bd K_l D
      d1 = dot_product(r, pd)
      d2 = dot_product(b2, pd)
      d3 = dot_product(b3, pd)
      zp = dot_product(z, pd)
      n = n + bd*ka*d1
      m1 = m1 + bd*kb*(4*d2 + 2*d3)
      m2 = m2 + bd*kb*(2*d2 + 4*d3)
    end if
    f = n*r + m1*b2 + m2*b3
    st = [c, s, l, n, m1, m2, d1, zp]
  end subroutine element_force

  !> The tangent half of element_corot_d from element_force's state st (see there).
  pure subroutine element_tangent(le, ea, ei, bd, cd, st, kt)
    real(dp), intent(in) :: le, ea, ei, bd, cd, st(nst)
    real(dp), intent(out) :: kt(6, 6)
    real(dp) :: l, c, s, r(6), z(6), b2(6), g, ka, kb, nl, k23, cm, c1, c2, g2(6)
    integer :: i, j
    c = st(1)
    s = st(2)
    l = st(3)
    r = [-c, -s, 0.0_dp, c, s, 0.0_dp]
    z = [s, -c, 0.0_dp, -s, c, 0.0_dp]
    kb = ei/le
    ka = (1 + cd)*(ea/le)            ! material part (1 + cd) B^T K_l B; geometric part from N, M1 + M2
    cm = (1 + cd)*kb
    ! K_T = B^T K_l B + N/l z z^T + g (r z^T + z r^T), written out with r and z zero on the
    ! rotations: translations ka r r^T + (12 kb/l^2 + N/l) z z^T + g (r z^T + z r^T); rotation
    ! columns -6 kb/l z + kb (4 e3 + 2 e6) and -6 kb/l z + kb (2 e3 + 4 e6).  Lower triangle
    ! first, then mirrored.
    kt = 0
    g = (st(5) + st(6))/(l*l)
    nl = st(4)/l + 12*cm/(l*l)
    k23 = -6*cm/l
    do j = 1, 5
      if (j == 3) cycle
      do i = j, 5
        if (i == 3) cycle
        kt(i, j) = ka*r(i)*r(j) + nl*z(i)*z(j) + g*(r(i)*z(j) + z(i)*r(j))
      end do
    end do
    kt(3, 1) = k23*z(1)
    kt(3, 2) = k23*z(2)
    kt(4, 3) = k23*z(4)
    kt(5, 3) = k23*z(5)
    do i = 1, 5
      if (i /= 3) kt(6, i) = k23*z(i)
    end do
    kt(3, 3) = 4*cm
    kt(6, 6) = 4*cm
    kt(6, 3) = 2*cm
    do j = 2, 6                      ! the upper triangle
      do i = 1, j - 1
        kt(i, j) = kt(j, i)
      end do
    end do
    if (bd == 0) return
    ! The damping force bd B^T K_l B pd also varies with the geometry at fixed rates pd: through
    ! B^T (the damping stresses are in N, M1, M2 above) and through the deformation rates
    ! D = B(p) pd:  d(r.pd) = (z.pd)/l z.dp,  d(b2.pd) = d(b3.pd) = ((r.pd) z + (z.pd) r).dp/l^2,
    ! so  bd B^T K_l dD/dp = bd [EA/le (z.pd)/l r z^T + 6 EI/le/l^2 (b2 + b3) ((r.pd) z + (z.pd) r)^T].
    ! Not symmetric (the time loop factors a general band); without it Newton converges only
    ! linearly once the buckled rod's elements turn fast (docs/slidercrank.md).
    c1 = bd*(ea/le)*st(8)/l
    c2 = 6*bd*kb/(l*l)
    g2 = st(7)*z + st(8)*r
    b2 = -2*z/l                      ! b2 + b3
    b2(3) = 1
    b2(6) = 1
    do j = 1, 6
      do i = 1, 6
        kt(i, j) = kt(i, j) + c1*r(i)*z(j) + c2*b2(i)*g2(j)
      end do
    end do
  end subroutine element_tangent

  !> Element displacements p(6) of element e from q (crank pin u = v = 0, slider node
  !> u = c3 U_X, v = -s3 U_X).
  pure subroutine gather(e, nel, nq, q, c3, s3, p, idx, cf)
    integer, intent(in) :: e, nel, nq
    real(dp), intent(in) :: q(nq), c3, s3
    real(dp), intent(out) :: p(6), cf(6)
    integer, intent(out) :: idx(6)
    integer :: a
    call element_map(e, nel, c3, s3, idx, cf)
    do a = 1, 6
      if (idx(a) == 0) then
        p(a) = 0
      else
        p(a) = cf(a)*q(idx(a))
      end if
    end do
  end subroutine gather

  !> Internal force fint(nq), with the co-rotational stiffness-proportional damping force of the
  !> rates qd (coefficient bd [s]; the slider node's rod-frame rate includes the frame's turn at
  !> th3d [rad/s]), and, if want_k, the tangent (cd weighting the damping part) added into the
  !> band ab times kscale; also the total strain energy [J] and each element's axial strain epse
  !> and mean curvature kape [1/m].  ab(ldab, nq): ldab = kd + 1, the lower triangle
  !> (ab(1 + i - j, j) = A(i, j), symmetric tangents: bd = 0), or ldab = 2 kd + 1, the general band
  !> (ab(kd + 1 + i - j, j) = A(i, j)).  Interior elements (2 .. nel-1) map onto
  !> six consecutive q entries 3e-4 .. 3e+1 with unit coefficients; the two end elements go
  !> through element_map.
  subroutine internal_forces(nel, nq, q, qd, th3d, bd, cd, c3, s3, le, ea, ei, want_k, kscale, ldab, fint, ab, &
                             energy, epse, kape, est)
    integer, intent(in) :: nel, nq, ldab
    real(dp), intent(in) :: q(nq), qd(nq), th3d, bd, cd, c3, s3, le, ea, ei, kscale
    logical, intent(in) :: want_k
    real(dp), intent(out) :: fint(nq), energy, epse(nel), kape(nel), est(nst, nel)
    real(dp), intent(inout) :: ab(ldab, nq)
    real(dp) :: p(6), pd(6), cf(6), f(6), eps, kap, en
    integer :: e, a, idx(6), o
    fint = 0
    energy = 0
    do e = 2, nel - 1
      o = 3*e - 5                       ! q index of the element's first entry, minus one
      call element_force(le, ea, ei, q(o + 1:o + 6), qd(o + 1:o + 6), bd, f, eps, kap, en, est(:, e))
      epse(e) = eps
      kape(e) = kap
      energy = energy + en
      fint(o + 1:o + 6) = fint(o + 1:o + 6) + f
    end do
    do e = 1, nel, nel - 1
      call gather(e, nel, nq, q, c3, s3, p, idx, cf)
      call gather(e, nel, nq, qd, c3, s3, pd, idx, cf)
      if (e == nel) then               ! the slider node moves in the turning rod frame at fixed U_X too
        pd(4) = pd(4) - s3*th3d*q(nq)
        pd(5) = pd(5) - c3*th3d*q(nq)
      end if
      call element_force(le, ea, ei, p, pd, bd, f, eps, kap, en, est(:, e))
      epse(e) = eps
      kape(e) = kap
      energy = energy + en
      do a = 1, 6
        if (idx(a) /= 0) fint(idx(a)) = fint(idx(a)) + cf(a)*f(a)
      end do
    end do
    if (want_k) call assemble_tangent(nel, nq, est, th3d, bd, cd, c3, s3, le, ea, ei, kscale, ldab, ab)
  end subroutine internal_forces

  !> Add kscale times the tangent of internal_forces (from its element states est) into the
  !> band ab(ldab, nq) (see there).
  subroutine assemble_tangent(nel, nq, est, th3d, bd, cd, c3, s3, le, ea, ei, kscale, ldab, ab)
    integer, intent(in) :: nel, nq, ldab
    real(dp), intent(in) :: est(nst, nel), th3d, bd, cd, c3, s3, le, ea, ei, kscale
    real(dp), intent(inout) :: ab(ldab, nq)
    real(dp) :: cf(6), kt(6, 6), v(6), r(6), b2(6), b3(6), d(3), l, kb
    integer :: e, a, b, idx(6), o, off, a0
    off = ldab - kd                   ! row of the diagonal
    a0 = 1                            ! first row a of column b assembled: all, or a >= b
    do e = 2, nel - 1
      o = 3*e - 5
      call element_tangent(le, ea, ei, bd, cd, est(:, e), kt)
      do b = 1, 6
        if (off == 1) a0 = b
        do a = a0, 6
          ab(off + a - b, o + b) = ab(off + a - b, o + b) + kscale*kt(a, b)
        end do
      end do
    end do
    do e = 1, nel, nel - 1
      call element_map(e, nel, c3, s3, idx, cf)
      call element_tangent(le, ea, ei, bd, cd, est(:, e), kt)
      do b = 1, 6
        if (idx(b) == 0) cycle
        do a = 1, 6
          if (idx(a) == 0 .or. (off == 1 .and. idx(a) < idx(b))) cycle
          ab(off + idx(a) - idx(b), idx(b)) = ab(off + idx(a) - idx(b), idx(b)) + kscale*cf(a)*cf(b)*kt(a, b)
        end do
      end do
      if (e == nel .and. bd /= 0) then
        ! the slider node's frame-turn rate -th3d (s3, c3) U_X depends on U_X itself: the damping
        ! force's derivative bd B^T K_l B v, v = dpd/dU_X, goes into column U_X
        l = est(3, e)
        r = [-est(1, e), -est(2, e), 0.0_dp, est(1, e), est(2, e), 0.0_dp]
        b2 = -[est(2, e), -est(1, e), 0.0_dp, -est(2, e), est(1, e), 0.0_dp]/l
        b3 = b2
        b2(3) = 1
        b3(6) = 1
        v = [0.0_dp, 0.0_dp, 0.0_dp, -s3*th3d, -c3*th3d, 0.0_dp]
        kb = ei/le
        d = [bd*(ea/le)*dot_product(r, v), bd*kb*(4*dot_product(b2, v) + 2*dot_product(b3, v)), &
             bd*kb*(2*dot_product(b2, v) + 4*dot_product(b3, v))]
        v = d(1)*r + d(2)*b2 + d(3)*b3
        do a = 1, 6
          if (idx(a) == 0) cycle
          if (off == 1 .and. idx(a) < nq) cycle
          ab(off + idx(a) - nq, nq) = ab(off + idx(a) - nq, nq) + kscale*cf(a)*v(a)
        end do
      end if
    end do
  end subroutine assemble_tangent

  !> Banded assembly of sum_e T^T (cm me + ck ke) T + cm msl e_X e_X^T into ab(ldab, nq):
  !> the lower triangle (ldab = kd + 1) or the general band (ldab = 2 kd + 1), as internal_forces.
  subroutine assemble_linear(nel, nq, me, ke, cm, ck, msl, c3, s3, ldab, ab)
    integer, intent(in) :: nel, nq, ldab
    real(dp), intent(in) :: me(6, 6), ke(6, 6), cm, ck, msl, c3, s3
    real(dp), intent(out) :: ab(ldab, nq)
    ab = 0
    call add_linear(nel, nq, me, ke, cm, ck, c3, s3, 1, nel, ldab, ab)
    ab(ldab - kd, nq) = ab(ldab - kd, nq) + cm*msl
  end subroutine assemble_linear

  !> Add the elements e1 .. e2 of assemble_linear (the slider mass not) into ab.
  subroutine add_linear(nel, nq, me, ke, cm, ck, c3, s3, e1, e2, ldab, ab)
    integer, intent(in) :: nel, nq, e1, e2, ldab
    real(dp), intent(in) :: me(6, 6), ke(6, 6), cm, ck, c3, s3
    real(dp), intent(inout) :: ab(ldab, nq)
    real(dp) :: se(6, 6), cf(6)
    integer :: e, a, b, idx(6), off
    off = ldab - kd
    se = cm*me + ck*ke
    do e = e1, e2
      call element_map(e, nel, c3, s3, idx, cf)
      do b = 1, 6
        if (idx(b) == 0) cycle
        do a = 1, 6
          if (idx(a) == 0 .or. (off == 1 .and. idx(a) < idx(b))) cycle
          ab(off + idx(a) - idx(b), idx(b)) = ab(off + idx(a) - idx(b), idx(b)) + cf(a)*cf(b)*se(a, b)
        end do
      end do
    end do
  end subroutine add_linear

  !> In-place LU factorisation A = L U without pivoting of a general band matrix with kd sub-
  !> and super-diagonals, ag(kd + 1 + i - j, j) = A(i, j).  On exit ag(kd + 1, j) = 1/U(j, j)
  !> (the solve multiplies), below it L (unit diagonal), above it U.  No pivoting: when the
  !> symmetric part of A is positive definite (the Newton matrix of a sound step: the mass term
  !> dominates) so is that of every Schur complement, and every pivot is positive; info = j at
  !> the first pivot that is not (the time loop then cuts the step, as for a failed Cholesky).
  subroutine band_lu(n, ag, info)
    integer, intent(in) :: n
    real(dp), intent(inout) :: ag(2*kd + 1, n)
    integer, intent(out) :: info
    integer :: j, i, k, m
    real(dp) :: rp, u
    info = 0
    do j = 1, n
      if (.not. (ag(kd + 1, j) > 0)) then
        info = j
        return
      end if
      rp = 1/ag(kd + 1, j)
      ag(kd + 1, j) = rp
      if (j <= n - kd) then           ! full-width column: fixed trip counts
        do i = 1, kd
          ag(kd + 1 + i, j) = ag(kd + 1 + i, j)*rp
        end do
        do k = 1, kd
          u = ag(kd + 1 - k, j + k)     ! U(j, j + k)
          do i = 1, kd
            ag(kd + 1 + i - k, j + k) = ag(kd + 1 + i - k, j + k) - ag(kd + 1 + i, j)*u
          end do
        end do
        cycle
      end if
      m = n - j
      do i = 1, m
        ag(kd + 1 + i, j) = ag(kd + 1 + i, j)*rp
      end do
      do k = 1, m
        u = ag(kd + 1 - k, j + k)
        do i = 1, m
          ag(kd + 1 + i - k, j + k) = ag(kd + 1 + i - k, j + k) - ag(kd + 1 + i, j)*u
        end do
      end do
    end do
  end subroutine band_lu

  !> Solve L U x = b with the factor of band_lu; b is overwritten by x.
  subroutine band_lu_solve(n, ag, b)
    integer, intent(in) :: n
    real(dp), intent(in) :: ag(2*kd + 1, n)
    real(dp), intent(inout) :: b(n)
    integer :: j, i
    real(dp) :: s
    do j = 1, n - kd
      do i = 1, kd
        b(j + i) = b(j + i) - ag(kd + 1 + i, j)*b(j)
      end do
    end do
    do j = max(1, n - kd + 1), n
      do i = 1, n - j
        b(j + i) = b(j + i) - ag(kd + 1 + i, j)*b(j)
      end do
    end do
    do j = n, max(1, n - kd + 1), -1
      s = b(j)
      do i = 1, n - j
        s = s - ag(kd + 1 - i, j + i)*b(j + i)
      end do
      b(j) = s*ag(kd + 1, j)
    end do
    do j = n - kd, 1, -1
      s = b(j)
      do i = 1, kd
        s = s - ag(kd + 1 - i, j + i)*b(j + i)
      end do
      b(j) = s*ag(kd + 1, j)
    end do
  end subroutine band_lu_solve

  !> Element strains and lateral deflections from the chord A-C, from the element strains epse
  !> and curvatures kape of internal_forces at q: eps(nel) axial strain, eof(nel) outer-fibre
  !> strain |eps| + c |kappa|, lat(0:nel) nodal lateral deflection from the chord [m].
  subroutine measures(nel, nq, q, c3, s3, le, half_depth, epse, kape, eps, eof, lat)
    integer, intent(in) :: nel, nq
    real(dp), intent(in) :: q(nq), c3, s3, le, half_depth, epse(nel), kape(nel)
    real(dp), intent(out) :: eps(nel), eof(nel), lat(0:nel)
    real(dp) :: xn, yn, ln, cc, ss
    integer :: e
    eps = epse
    ! hot-loop: slidercrank_nl outer-fibre strain
    do e = 1, nel
      eof(e) = abs(epse(e)) + half_depth*abs(kape(e))
    end do
    xn = nel*le + c3*q(nq)
    yn = -s3*q(nq)
    ln = sqrt(xn*xn + yn*yn)
    cc = xn/ln
    ss = yn/ln
    lat(0) = 0
    lat(nel) = 0
    do e = 1, nel - 1
      lat(e) = -ss*(e*le + q(3*e - 1)) + cc*q(3*e)
    end do
  end subroutine measures

  !> Secant predictor q = qn + ratio (qn - qprev).
  pure subroutine secant_predict(nq, qn, qprev, ratio, q)
    integer, intent(in) :: nq
    real(dp), intent(in) :: qn(nq), qprev(nq), ratio
    real(dp), intent(out) :: q(nq)
    integer :: j
    ! hot-loop: slidercrank_nl predictor
    do j = 1, nq
      q(j) = qn(j) + ratio*(qn(j) - qprev(j))
    end do
  end subroutine secant_predict

  !> Quadratic extrapolation over three equal steps, q = 3 qn - 3 qprev + qprev2.
  pure subroutine quadratic_predict(nq, qn, qprev, qprev2, q)
    integer, intent(in) :: nq
    real(dp), intent(in) :: qn(nq), qprev(nq), qprev2(nq)
    real(dp), intent(out) :: q(nq)
    integer :: j
    ! hot-loop: slidercrank_nl quadratic predictor
    do j = 1, nq
      q(j) = 3*(qn(j) - qprev(j)) + qprev2(j)
    end do
  end subroutine quadratic_predict

  !> Newmark rates (parameters bn, gn) of the trial state q over a step h from (qn, qdn, qddn):
  !> qdd = (q - qn - h qdn)/(bn h^2) - (1/(2 bn) - 1) qddn, qd = qdn + h ((1 - gn) qddn + gn qdd);
  !> and the inertia and damping operands w1 = qdd + ca qd (for M), w2 = cb qd (for K0).
  pure subroutine newmark_rates(nq, q, qn, qdn, qddn, bn, gn, h, ca, cb, qdd, qd, w1, w2)
    integer, intent(in) :: nq
    real(dp), intent(in) :: q(nq), qn(nq), qdn(nq), qddn(nq), bn, gn, h, ca, cb
    real(dp), intent(out) :: qdd(nq), qd(nq), w1(nq), w2(nq)
    real(dp) :: a0, a2, a3, g1
    integer :: j
    a0 = 1/(bn*h*h)
    a2 = 1/(bn*h)
    a3 = 1/(2*bn) - 1
    g1 = 1 - gn
    ! hot-loop: slidercrank_nl newmark rates
    do j = 1, nq
      qdd(j) = a0*(q(j) - qn(j)) - a2*qdn(j) - a3*qddn(j)
      qd(j) = qdn(j) + h*(g1*qddn(j) + gn*qdd(j))
      w1(j) = qdd(j) + ca*qd(j)
      w2(j) = cb*qd(j)
    end do
  end subroutine newmark_rates

  !> Time integration of the nonlinear rod over nsteps steps of dt [s] from theta2 = 0.
  !>
  !> start_mode 0 rest, 1 quasi-static (nonlinear static solution at t = 0, rate by central
  !>            difference of the static solutions at -dt and dt)
  !> alpha, beta  Rayleigh damping [1/s, s];  tol Newton tolerance (relative residual);
  !> maxit Newton solves per step; max_cuts step halvings allowed; spr steps per revolution
  !> (for the per-revolution peaks); want_energy 1: accumulate the energy balance.
  !>
  !> Recorded for steps k = rec_start .. rec_start + nrec - 1 (k = 0 is the start):
  !> eps_ax(e, j), eps_of(e, j) axial and outer-fibre strain; lat_max(j) largest |lateral
  !> deflection| from the chord [m]; mid(j) lateral deflection of the node nearest midspan;
  !> elong(j) rod elongation u_n [m]; slider(j) slider position [m]; energy(4, j) kinetic,
  !> strain energy, work of the loads Q (with the work of the time-varying slider-node mass
  !> coupling, see docs) and damping dissipation since the start [J] (zeros if want_energy = 0).
  !> rev_lat(r), rev_eps(r): peak |lateral deflection| and peak |axial strain| in revolution r.
  !> shapes(0:nel, 2): lateral deflection profile at the recorded step of largest lateral
  !> deflection and at the recorded step of largest crank-end compression; shape_step(2).
  !> frames(0:nel, nframe): the lateral deflection profile [m] at every frame_every-th recorded
  !> step (recorded steps 1, 1 + frame_every, ...; nframe = (nrec - 1)/frame_every + 1): the
  !> rod's nodes over the recorded revolution, drawn by the report page's animation.
  !> stats: (total Newton solves, most solves in one step, step cuts, deepest cut level,
  !>         steps completed); fail_step, fail_iter: the step and solves of a failure.
  subroutine simulate_nl(nel, nq, nrec, nrev, r2, rl, rhoa, ea, ei, half_depth, msl, omega, dt, &
                         nsteps, spr, rec_start, alpha, beta, hht, start_mode, tol, maxit, max_cuts, &
                         want_energy, frame_every, nframe, eps_ax, eps_of, lat_max, mid, elong, slider, &
                         energy, rev_lat, rev_eps, shapes, frames, shape_step, stats, status, fail_step, &
                         fail_iter)
    !f2py threadsafe
    integer, intent(in) :: nel, nq, nrec, nrev, nsteps, spr, rec_start, start_mode, maxit, max_cuts
    integer, intent(in) :: want_energy, frame_every, nframe
    real(dp), intent(in) :: r2, rl, rhoa, ea, ei, half_depth, msl, omega, dt, alpha, beta, hht, tol
    real(dp), intent(out) :: eps_ax(nel, nrec), eps_of(nel, nrec), lat_max(nrec), mid(nrec)
    real(dp), intent(out) :: elong(nrec), slider(nrec), energy(4, nrec), rev_lat(nrev), rev_eps(nrev)
    real(dp), intent(out) :: shapes(nel + 1, 2), frames(nel + 1, nframe)
    integer, intent(out) :: shape_step(2), stats(5), status, fail_step, fail_iter

    real(dp), allocatable :: q(:), qd(:), qdd(:), qn(:), qdn(:), qddn(:), fint(:), r(:), w1(:), w2(:)
    real(dp), allocatable :: qprev2(:), qprev(:), gn(:), gnew(:), gsave(:), epse(:), kape(:), epsx(:), kapx(:)
    real(dp), allocatable :: est(:, :)
    real(dp), allocatable :: ab(:, :), ag(:, :), agm(:, :), qm(:), zero(:), qs(:), eps(:), eof(:), lat(:)
    real(dp) :: me(6, 6), ke(6, 6), kg1(6, 6), kin(7), nb(nel), le, t, tn, h, a0, a1, a2, cm, ck
    real(dp) :: en, ekin, wext, wdamp, wold, best_lat, best_cmp, lv, rref, rnorm, c3, s3, kmax, hprev
    real(dp) :: bn, gn_, hprev2, cm_band
    integer :: nhist
    integer :: k, info, it, level, piece, revi, mid_node
    logical :: ok

    status = nl_ok
    fail_step = -1
    fail_iter = 0
    eps_ax = 0; eps_of = 0; lat_max = 0; mid = 0; elong = 0; slider = 0; energy = 0
    rev_lat = 0; rev_eps = 0; shapes = 0; frames = 0; shape_step = -1; stats = 0
    if (nel < 2 .or. nq /= 3*nel .or. nsteps < 0 .or. dt <= 0 .or. spr < 1 .or. maxit < 1 .or. &
        max_cuts < 0 .or. max_cuts > 30 .or. tol <= 0 .or. hht > 0 .or. hht < -1.0_dp/3 .or. &
        frame_every < 1 .or. nframe /= (max(nrec, 1) - 1)/frame_every + 1) then
      status = nl_bad_args
      return
    end if
    le = rl/nel
    kmax = max(ea/le, 12*ei/le**3)
    bn = (1 - hht)**2/4
    gn_ = 0.5_dp - hht
    nb = 0
    mid_node = nel/2
    allocate (q(nq), qd(nq), qdd(nq), qn(nq), qdn(nq), qddn(nq), fint(nq), r(nq), w1(nq), w2(nq))
    allocate (qprev2(nq), qprev(nq), gn(nq), gnew(nq), gsave(nq), epse(nel), kape(nel), epsx(nel), kapx(nel))
    allocate (est(nst, nel))
    allocate (ab(kd + 1, nq), ag(2*kd + 1, nq), agm(2*kd + 1, nq), qm(nq), zero(nq), qs(nq), eps(nel), eof(nel), lat(0:nel))
    zero = 0
    call element_matrices(le, rhoa, ea, ei, me, ke, kg1)
    best_lat = -1
    best_cmp = huge(1.0_dp)
    cm_band = -1
    ekin = 0; wext = 0; wdamp = 0

    ! ---- initial state
    q = 0
    qd = 0
    if (start_mode == 1) then
      call static_at(-dt, qs, info)
      if (info /= 0) then
        status = nl_not_spd; fail_step = 0; return
      end if
      qd = -qs
      call static_at(dt, qs, info)
      if (info /= 0) then
        status = nl_not_spd; fail_step = 0; return
      end if
      qd = (qd + qs)/(2*dt)
      call static_at(0.0_dp, q, info)
      if (info /= 0) then
        status = nl_not_spd; fail_step = 0; return
      end if
    end if
    ! qdd from the equation of motion: M qdd = Q - alpha M qd - f_int(q, qd) (with damping)
    call rigid_kin(0.0_dp, omega, r2, rl, kin)
    c3 = cos(kin(1)); s3 = sin(kin(1))
    w1 = -alpha*qd
    call apply_ops(nel, nq, w1, zero, zero, .false., 1.0_dp, kin, le, me, ke, kg1, nb, msl, r)
    call internal_forces(nel, nq, q, qd, kin(2), beta, 0.0_dp, c3, s3, le, ea, ei, .false., 1.0_dp, kd + 1, fint, ab, &
                         en, epse, kape, est)
    qdd = r - fint
    call assemble_linear(nel, nq, me, ke, 1.0_dp, 0.0_dp, msl, c3, s3, kd + 1, ab)
    call band_cholesky(nq, ab, info)
    if (info /= 0) then
      status = nl_not_spd; fail_step = 0; return
    end if
    call band_solve(nq, ab, qdd)
    call apply_ops(nel, nq, -qdd, zero, zero, .false., 0.0_dp, kin, le, me, ke, kg1, nb, msl, gn)
    if (want_energy /= 0) then
      call apply_ops(nel, nq, qd, zero, zero, .false., 0.0_dp, kin, le, me, ke, kg1, nb, msl, r)
      ekin = 0.5_dp*dot_product(qd, r)
    end if
    if (rec_start == 0) call record(1, 0, q, c3, s3, kin, en)

    ! ---- time loop
    do k = 1, nsteps
      tn = (k - 1)*dt
      level = 0
      piece = 0
      qn = q; qdn = qd; qddn = qdd
      gsave = gn
      if (k == 1) then
        qprev = q
        hprev = dt
        nhist = 0
      end if
      do while (piece < 2**level)
        h = dt/2**level
        t = tn + (piece + 1)*h
        call newton_step(t, h, ok, it)
        stats(1) = stats(1) + it
        stats(2) = max(stats(2), it)
        if (ok) then
          piece = piece + 1
          qprev2 = qprev
          hprev2 = hprev
          qprev = qn
          hprev = h
          nhist = nhist + 1
          qn = q; qdn = qd; qddn = qdd
          gn = gnew
          gsave = gn
        else
          q = qn; qd = qdn; qdd = qddn
          gn = gsave
          qprev = qn                     ! restart the predictor after a cut
          nhist = 0
          if (level >= max_cuts) then
            status = nl_no_convergence
            fail_step = k
            fail_iter = it
            stats(4) = max(stats(4), level)
            exit
          end if
          level = level + 1
          piece = 2*piece
          stats(3) = stats(3) + 1
          stats(4) = max(stats(4), level)
        end if
      end do
      if (status /= nl_ok) exit
      call rigid_kin(omega*k*dt, omega, r2, rl, kin)
      c3 = cos(kin(1)); s3 = sin(kin(1))
      call measures(nel, nq, q, c3, s3, le, half_depth, epse, kape, eps, eof, lat)
      lv = maxval(abs(lat))
      if (.not. (lv <= rl/2) .or. any(q /= q)) then
        status = nl_limit
        fail_step = k
        exit
      end if
      revi = min(nrev, (k - 1)/spr + 1)
      rev_lat(revi) = max(rev_lat(revi), lv)
      rev_eps(revi) = max(rev_eps(revi), maxval(abs(eps)))
      if (k >= rec_start .and. k < rec_start + nrec) then
        if (want_energy /= 0) call internal_forces(nel, nq, q, zero, 0.0_dp, 0.0_dp, 0.0_dp, c3, s3, le, ea, ei, &
                                                   .false., 1.0_dp, kd + 1, fint, ab, en, epsx, kapx, est)
        call record(k - rec_start + 1, k, q, c3, s3, kin, en)
      end if
      stats(5) = k
    end do

  contains

    !> One Newmark-Newton step from the state (qn, qdn, qddn) to time tt over hh; on success
    !> (q, qd, qdd) hold the new state; nit = Newton solves made.
    subroutine newton_step(tt, hh, success, nit)
      real(dp), intent(in) :: tt, hh
      logical, intent(out) :: success
      integer, intent(out) :: nit
      real(dp) :: kt_(7), cc, ss, e_, qnorm, rlast
      logical :: reused
      integer :: jj, inf
      success = .false.
      nit = 0
      reused = .false.
      rlast = huge(1.0_dp)
      call rigid_kin(omega*tt, omega, r2, rl, kt_)
      cc = cos(kt_(1)); ss = sin(kt_(1))
      ! HHT-alpha (Hilber, Hughes, Taylor 1977): Newmark beta = (1 - a)^2/4, gamma = 1/2 - a;
      ! a = 0 is the average-acceleration rule of the linear model
      a0 = 1/(bn*hh**2)
      a1 = gn_/(bn*hh)
      cm = a0 + (1 + hht)*a1*alpha
      ck = a1*beta                    ! weight of the damping tangent B^T K_l B (times 1 + a below)
      if (cm /= cm_band) then         ! the mass band of elements 1 .. nel-1 (only a step cut changes cm)
        agm = 0
        call add_linear(nel, nq, me, ke, cm, 0.0_dp, cc, ss, 1, nel - 1, 2*kd + 1, agm)
        cm_band = cm
      end if
      ! predictor: extrapolation of the displacements, quadratic over three equal steps, else
      ! secant q_n + (h/h_prev)(q_n - q_n-1) (displacements are smooth; rates and accelerations
      ! of the end rotations, which carry almost no inertia, are not)
      if (nhist >= 2 .and. hh == hprev .and. hh == hprev2) then
        call quadratic_predict(nq, qn, qprev, qprev2, q)
      else
        call secant_predict(nq, qn, qprev, hh/hprev, q)
      end if
      call apply_ops(nel, nq, zero, zero, zero, .false., 1.0_dp, kt_, le, me, ke, kg1, nb, msl, r)
      qnorm = sqrt(dot_product(r, r))
      do
        call newmark_rates(nq, q, qn, qdn, qddn, bn, gn_, hh, (1 + hht)*alpha, 0.0_dp, qdd, qd, w1, w2)
        ! r = M (qdd + (1+a) alpha qd) - (1+a) Q + (1+a) f(q, qd) - a g_n, f with the damping of
        ! the deformation rates, g_n = alpha M qd_n + f(q_n, qd_n) - Q_n (apply_ops' load scales -Q)
        call apply_ops(nel, nq, w1, zero, zero, .false., -(1 + hht), kt_, le, me, ke, kg1, nb, msl, r)
        ! the force (and each element's state, from which its tangent follows if a solve comes)
        call internal_forces(nel, nq, q, qd, kt_(2), beta, ck, cc, ss, le, ea, ei, .false., 1.0_dp, 2*kd + 1, &
                             fint, ag, e_, epse, kape, est)
        ! tolerance, and the round-off floor of a residual whose stiffest rows (12 EI/le^3,
        ! EA/le) multiply displacements of size max|q|
        rref = max(tol*(qnorm + sqrt(dot_product(fint, fint)) + ei/rl**2), &
                   16*epsilon(1.0_dp)*kmax*maxval(abs(q))*sqrt(real(nel, dp)))
        r = r + (1 + hht)*fint - hht*gn
        rnorm = sqrt(dot_product(r, r))
        if (.not. (rnorm == rnorm) .or. any(q /= q)) return
        if (rnorm <= rref) exit
        if (nit >= maxit) return
        ! The Newton matrix, factored afresh unless the last solve left the residual within
        ! chord_ratio of the tolerance: Newton's next correction is then ~1e-3 of the last and
        ! the matrix of the last iterate (one step of the same time step away) reduces the
        ! residual below the tolerance as well (checked: if it has not shrunk tenfold, the next
        ! solve refactors).  The converged state meets the same residual test either way.
        if (nit == 0 .or. rnorm > chord_ratio*rref .or. rnorm > 0.1_dp*rlast .or. reused) then
          ! mass band (the last element turns with the guide), then the tangent
          ag = agm
          call add_linear(nel, nq, me, ke, cm, 0.0_dp, cc, ss, nel, nel, 2*kd + 1, ag)
          ag(kd + 1, nq) = ag(kd + 1, nq) + cm*msl
          call assemble_tangent(nel, nq, est, kt_(2), beta, ck, cc, ss, le, ea, ei, 1 + hht, 2*kd + 1, ag)
          call band_lu(nq, ag, inf)
          if (inf /= 0) return
          reused = .false.
        else
          reused = .true.
        end if
        rlast = rnorm
        r = -r
        call band_lu_solve(nq, ag, r)
        q = q + r
        nit = nit + 1
      end do
      success = .true.
      ! g_n+1 = alpha M qd + f(q, qd) - Q for the next step (fint holds f of the converged state)
      call apply_ops(nel, nq, alpha*qd, zero, zero, .false., -1.0_dp, kt_, le, me, ke, kg1, nb, msl, gnew)
      gnew = gnew + fint
      if (want_energy /= 0) then
        ! trapezoidal work of the loads Q over the step, damping dissipation, and the work of
        ! the slider-node mass coupling that varies with theta3 (midpoint rate)
        w1 = 0.5_dp*(qd + qdn)
        w2 = q - qn
        call apply_ops(nel, nq, zero, zero, zero, .false., 1.0_dp, kt_, le, me, ke, kg1, nb, msl, r)
        wold = dot_product(r, w2)
        call rigid_kin(omega*(tt - hh), omega, r2, rl, kin)
        call apply_ops(nel, nq, zero, zero, zero, .false., 1.0_dp, kin, le, me, ke, kg1, nb, msl, fint)
        wext = wext + 0.5_dp*(wold + dot_product(fint, w2))
        call apply_ops(nel, nq, w1, zero, zero, .false., 0.0_dp, kt_, le, me, ke, kg1, nb, msl, r)
        call apply_ops(nel, nq, w1, zero, zero, .false., 0.0_dp, kin, le, me, ke, kg1, nb, msl, fint)
        wext = wext + 0.5_dp*dot_product(w1, r - fint)
        ! and of the guide turning with the rod frame: the strain energy depends on time through
        ! the slider node's map (u_n, v_n) = (c3, -s3) U_X; its change at fixed q (midpoint)
        w2 = 0.5_dp*(q + qn)
        call internal_forces(nel, nq, w2, zero, 0.0_dp, 0.0_dp, 0.0_dp, cc, ss, le, ea, ei, .false., 1.0_dp, &
                             kd + 1, fint, ab, e_, epsx, kapx, est)
        wext = wext + e_
        ! (the damping force at the midpoint state: f(q_mid, qd_mid) - f(q_mid, 0), kept in qs)
        call internal_forces(nel, nq, w2, w1, kt_(2), beta, 0.0_dp, cc, ss, le, ea, ei, .false., 1.0_dp, &
                             kd + 1, qs, ab, e_, epsx, kapx, est)
        qs = qs - fint
        call internal_forces(nel, nq, w2, zero, 0.0_dp, 0.0_dp, 0.0_dp, cos(kin(1)), sin(kin(1)), le, ea, ei, &
                             .false., 1.0_dp, kd + 1, fint, ab, e_, epsx, kapx, est)
        wext = wext - e_
        w2 = q - qn
        ! damping: (alpha M qd_mid + damping force at the midpoint) . dq
        call apply_ops(nel, nq, alpha*w1, zero, zero, .false., 0.0_dp, kt_, le, me, ke, kg1, nb, msl, r)
        wdamp = wdamp + dot_product(r + qs, w2)
        call apply_ops(nel, nq, qd, zero, zero, .false., 0.0_dp, kt_, le, me, ke, kg1, nb, msl, r)
        ekin = 0.5_dp*dot_product(qd, r)
      end if
    end subroutine newton_step

    !> Nonlinear static solution f_int(qq) = Q(tq) by Newton from qq = 0 (the rod near TDC is
    !> in tension and the tangent is positive definite).
    subroutine static_at(tq, qq, inf)
      real(dp), intent(in) :: tq
      real(dp), intent(out) :: qq(nq)
      integer, intent(out) :: inf
      real(dp) :: kq(7), cc, ss, e_, rr(nq), qload(nq)
      integer :: i
      call rigid_kin(omega*tq, omega, r2, rl, kq)
      cc = cos(kq(1)); ss = sin(kq(1))
      call apply_ops(nel, nq, zero, zero, zero, .false., 1.0_dp, kq, le, me, ke, kg1, nb, msl, qload)
      qq = 0
      inf = 0
      do i = 1, 50
        ab = 0
        call internal_forces(nel, nq, qq, zero, 0.0_dp, 0.0_dp, 0.0_dp, cc, ss, le, ea, ei, .true., 1.0_dp, kd + 1, fint, &
                             ab, e_, epsx, kapx, est)
        rr = qload - fint
        if (sqrt(dot_product(rr, rr)) <= 1e-12_dp*(sqrt(dot_product(qload, qload)) + ei/rl**2) &
            .and. i > 1) return
        call band_cholesky(nq, ab, inf)
        if (inf /= 0) return
        call band_solve(nq, ab, rr)
        qq = qq + rr
      end do
    end subroutine static_at

    !> Store the outputs of step kk in column jj.
    subroutine record(jj, kk, qq, cc, ss, kq, estrain)
      integer, intent(in) :: jj, kk
      real(dp), intent(in) :: qq(nq), cc, ss, kq(7), estrain
      real(dp) :: lv_
      call measures(nel, nq, qq, cc, ss, le, half_depth, epse, kape, eps, eof, lat)
      eps_ax(:, jj) = eps
      eps_of(:, jj) = eof
      lv_ = maxval(abs(lat))
      lat_max(jj) = lv_
      mid(jj) = lat(mid_node)
      if (mod(jj - 1, frame_every) == 0) frames(:, (jj - 1)/frame_every + 1) = lat
      elong(jj) = cc*qq(nq)
      slider(jj) = kq(4) + qq(nq)
      if (want_energy /= 0) energy(:, jj) = [ekin, estrain, wext, wdamp]
      if (lv_ > best_lat) then
        best_lat = lv_
        shapes(:, 1) = lat
        shape_step(1) = kk
      end if
      if (eps(1) < best_cmp) then
        best_cmp = eps(1)
        shapes(:, 2) = lat
        shape_step(2) = kk
      end if
    end subroutine record

  end subroutine simulate_nl

  !> Static pinned-pinned column under an end load P [N] (compression positive) along the
  !> rod axis: node 0 pinned, node nel on a roller along x.  Minimises the total potential
  !> U(q) + P U_X from a sine imperfection of amplitude amp [m] (the initial guess only) by
  !> Newton with a stiffness shift (K_T + mu K0 when K_T is not positive definite) and an
  !> Armijo backtracking line search, until ||R|| <= tol (P + EI/L^2) (or the round-off floor
  !> of simulate_nl) with K_T positive definite.  mid: lateral deflection of the midspan node [m] (nel even); shortening: -U_X
  !> [m]; iters: Newton solves; status nl_ok or nl_no_convergence.
  subroutine column_static(nel, nq, rl, ea, ei, p, amp, tol, maxit, q, mid, shortening, iters, status)
    integer, intent(in) :: nel, nq, maxit
    real(dp), intent(in) :: rl, ea, ei, p, amp, tol
    real(dp), intent(out) :: q(nq), mid, shortening
    integer, intent(out) :: iters, status
    real(dp), allocatable :: fint(:), r(:), d(:), qt(:), ab(:, :), ab0(:, :), k0(:, :), epsx(:), kapx(:), zero(:)
    real(dp), allocatable :: est(:, :)
    real(dp) :: me(6, 6), ke(6, 6), kg1(6, 6), le, pi, en, pot, pot_t, mu, step, rn, slope
    integer :: j, info, ls
    q = 0
    mid = 0
    shortening = 0
    iters = 0
    status = nl_bad_args
    if (nel < 2 .or. mod(nel, 2) /= 0 .or. nq /= 3*nel .or. tol <= 0 .or. maxit < 1) return
    status = nl_no_convergence
    pi = 4*atan(1.0_dp)
    le = rl/nel
    allocate (fint(nq), r(nq), d(nq), qt(nq), ab(kd + 1, nq), ab0(kd + 1, nq), k0(kd + 1, nq), epsx(nel), kapx(nel))
    allocate (zero(nq), est(nst, nel))
    zero = 0
    call element_matrices(le, 1.0_dp, ea, ei, me, ke, kg1)
    call assemble_linear(nel, nq, me, ke, 0.0_dp, 1.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, kd + 1, k0)
    q(1) = amp*pi/rl
    q(nq - 1) = -amp*pi/rl
    do j = 1, nel - 1
      q(3*j) = amp*sin(pi*j/nel)
      q(3*j + 1) = amp*pi/rl*cos(pi*j/nel)
    end do
    mu = 0
    do while (iters < maxit)
      ab0 = 0
      call internal_forces(nel, nq, q, zero, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, le, ea, ei, .true., 1.0_dp, &
                           kd + 1, fint, ab0, en, epsx, kapx, est)
      pot = en + p*q(nq)
      r = fint
      r(nq) = r(nq) + p
      rn = sqrt(dot_product(r, r))
      ! shift: none if K_T is positive definite, else grow mu until K_T + mu K0 is
      mu = 0
      do
        ab = ab0 + mu*k0
        call band_cholesky(nq, ab, info)
        if (info == 0) exit
        mu = max(2*mu, 1e-3_dp)
        if (mu > 1e6_dp) return
      end do
      if (rn <= max(tol*(abs(p) + ei/rl**2), &
                    16*epsilon(1.0_dp)*max(ea/le, 12*ei/le**3)*maxval(abs(q))*sqrt(real(nel, dp))) &
          .and. mu == 0) then
        status = nl_ok
        exit
      end if
      d = -r
      call band_solve(nq, ab, d)
      slope = dot_product(d, r)
      step = 1
      do ls = 1, 40
        qt = q + step*d
        call internal_forces(nel, nq, qt, zero, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, le, ea, ei, .false., &
                             1.0_dp, kd + 1, fint, ab, en, epsx, kapx, est)
        pot_t = en + p*qt(nq)
        if (pot_t <= pot + 1e-4_dp*step*slope .or. mu == 0 .and. ls == 1 .and. rn < 1e-6_dp*abs(p)) exit
        step = step/2
      end do
      q = qt
      iters = iters + 1
    end do
    mid = q(3*(nel/2))
    shortening = -q(nq)
  end subroutine column_static

end module slidercrank_nl
