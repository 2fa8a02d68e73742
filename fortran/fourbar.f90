!> Four-bar linkage kernels [Soegihardjo 2003].
!>
!> Geometry: crank pivot O_A at the origin, rocker pivot O_B at (p, 0).
!> p = fixed link, q = crank, r = coupler, s = rocker (any consistent length unit).
!> Crank angle theta from the ground line O_A->O_B, counter-clockwise positive.
!>
!> listing_table  the Lampiran 1 Fortran 77 program, modernised but keeping its
!>                single-precision arithmetic, constants, quadrant logic (including
!>                its quadrant defect for 180..360 deg) and whole-degree truncation,
!>                so that its rows are the published rows.
!> exact_states   closed-loop solution in double precision on a chosen branch:
!>                angles, transmission angle, joint positions, angular velocities
!>                and accelerations of coupler and rocker, with per-row status.
module fourbar
  use kinds, only: dp, sp
  use vecmath, only: sincos_array, atan2_array
  implicit none
  private
  public :: listing_table, exact_states, coupler_point
  ! building blocks of the batched summaries (fortran/fourbar_summary.f90); not wrapped by f2py
  public :: pose_block, rates_block, jerks_block, angles_block

  !> positions per block of the batched loops (the size of their local arrays)
  integer, parameter, public :: nb = 256

  !> status codes shared with driver/fourbar.py
  integer, parameter, public :: st_ok = 0, st_no_assembly = 1, st_toggle = 2, st_indeterminate = 3

contains

  !> The published program, one row per crank angle i = istart, istart+incr, ...
  !> table(:, 1..10) = i, epsl, phi, beta (whole degrees, truncated as printed),
  !> xa, ya, xb, yb, omr, oms (rad/s); all evaluated in default REAL (sp).
  !> status(k) = 1 where the arccos arguments leave [-1, 1] (the listing would
  !> print NaN), 2 where sin(phi - epsilon) = 0 (its velocities divide by zero).
  subroutine listing_table(p, q, r, s, omq, istart, incr, n, table, status)
    real(dp), intent(in) :: p, q, r, s, omq
    integer, intent(in) :: istart, incr, n
    real(dp), intent(out) :: table(n, 10)
    integer, intent(out) :: status(n)
    real(sp) :: ps, qs, rs, ss, omqs
    real(sp) :: w, d, sigy, sigx, sigma, gam, gamma, epsilon, bet, beta, phi, xb, yb
    real(sp) :: xa, ya, omr, oms, iphi, ibeta, iepsilon
    integer :: i, k

    ps = real(p, sp); qs = real(q, sp); rs = real(r, sp); ss = real(s, sp)
    omqs = real(omq, sp)
    do k = 1, n
      i = istart + (k - 1)*incr
      status(k) = st_ok
      table(k, :) = 0.0_dp
      table(k, 1) = real(i, dp)
      w = real(i, sp)*0.0174532_sp
      d = sqrt(ps**2 + qs**2 - 2*ps*qs*cos(w))
      sigy = -qs*sin(w)
      sigx = ps - qs*cos(w)
      if (sigx == 0.0_sp .and. sigy == 0.0_sp) then
        status(k) = st_no_assembly
        cycle
      end if
      sigma = abs(atan(sigy/sigx))
      if ((sigy < 0) .and. (sigx < 0)) then
        sigma = sigma + 3.1415927_sp
      else if ((sigy > 0) .and. (sigx < 0)) then
        sigma = abs(sigma + 1.5707963_sp)
      else
        sigma = 6.2831853_sp - sigma
      end if
      gam = (d**2 + rs**2 - ss**2)/(2*d*rs)
      bet = (rs**2 + ss**2 - d**2)/(2*rs*ss)
      if (abs(gam) > 1.0_sp .or. abs(bet) > 1.0_sp) then
        status(k) = st_no_assembly
        cycle
      end if
      gamma = -atan(gam/sqrt(-gam*gam + 1)) + 1.5707963_sp
      epsilon = gamma + sigma - 6.2831853_sp
      beta = -atan(bet/sqrt(-bet*bet + 1)) + 1.5707963_sp
      phi = sigma + gamma + beta - 6.2831853_sp
      xb = ps - ss*cos(3.1415927_sp - phi)
      yb = ss*sin(3.1415927_sp - phi)
      ! subroutine velocity: epsilon lives in COMMON /sdt/, so its wrap to
      ! 0..2pi here is seen by the main program's iepsilon below.
      call listing_velocity(omqs, qs, rs, ss, w, sigma, gamma, beta, epsilon, omr, oms, status(k))
      iphi = real(int((sigma + gamma + beta - 6.2831853_sp)/.0174532_sp), sp)
      if (iphi < 0) iphi = 360 + iphi
      ibeta = real(int(beta/.0174532_sp), sp)
      iepsilon = real(int(epsilon/.0174532_sp), sp)
      if (iepsilon < 0) iepsilon = 360 + iepsilon
      xa = qs*cos(w)
      ya = qs*sin(w)
      table(k, 2:10) = real([iepsilon, iphi, ibeta, xa, ya, xb, yb, omr, oms], dp)
    end do
  end subroutine listing_table

  !> The listing's subroutine velocity (eqs. 20-21), phi local, epsilon shared.
  subroutine listing_velocity(omq, q, r, s, w, sigma, gamma, beta, epsilon, omr, oms, status)
    real(sp), intent(in) :: omq, q, r, s, w, sigma, gamma, beta
    real(sp), intent(inout) :: epsilon
    real(sp), intent(out) :: omr, oms
    integer, intent(inout) :: status
    real(sp) :: phi, den
    phi = sigma + gamma + beta - 6.2831853_sp
    if (phi < 0) phi = 6.2831853_sp + phi
    if (epsilon < 0) epsilon = 6.2831853_sp + epsilon
    den = sin(phi - epsilon)
    if (den == 0.0_sp) then
      status = st_toggle
      omr = 0.0_sp
      oms = 0.0_sp
      return
    end if
    omr = (omq*q*sin(w - phi))/(r*den)
    oms = (omq*q*sin(w - epsilon))/(s*den)
  end subroutine listing_velocity

  !> Closed-loop position, velocity and acceleration analysis.
  !> theta(n)   crank angles [rad]; omega [rad/s], alpha1 [rad/s^2] crank speed/acceleration
  !> branch     +1 open (B left of the directed line A->O_B), -1 crossed
  !> out(:, 1)  coupler angle theta2 [rad, atan2 range]   out(:, 2) rocker angle theta3 [rad]
  !> out(:, 3)  transmission angle mu in [0, pi] [rad]
  !> out(:, 4:7) xa, ya, xb, yb [length]
  !> out(:, 8:9) coupler and rocker angular velocity [rad/s]
  !> out(:, 10:11) coupler and rocker angular acceleration [rad/s^2]
  !> out and status are overwritten (intent inout so callers can reuse buffers).
  !> status(k)  0 ok, 1 cannot be assembled (row zeroed except xa, ya),
  !>            2 toggle: coupler and rocker collinear, velocities unbounded (set to 0)
  !>            3 indeterminate: crank pin A on the rocker pivot O_B with r = s (B free on a circle);
  !>              zeroed like status 1
  subroutine exact_states(n, theta, p, q, r, s, omega, alpha1, branch, out, status)
    !f2py threadsafe
    integer, intent(in) :: n
    real(dp), intent(in) :: theta(n)
    real(dp), intent(in) :: p, q, r, s, omega, alpha1
    integer, intent(in) :: branch
    real(dp), intent(inout) :: out(n, 11)
    !f2py intent(in,out) :: out
    integer, intent(inout) :: status(n)
    !f2py intent(in,out) :: status
    real(dp) :: pb(nb), qb(nb), rb(nb), sb(nb), gb(nb), sblk(nb)
    integer :: k0, m

    ! one linkage: its lengths and branch sign as the blocks' per-position arrays
    pb = p
    qb = q
    rb = r
    sb = s
    gb = merge(1.0_dp, -1.0_dp, branch >= 0)
    ! Blocks of nb positions: the block's transcendental functions are evaluated on whole
    ! arrays (vecmath) and its temporaries stay in cache.  Each output column is passed as
    ! its own dummy argument, so the compiler knows the columns do not overlap and
    ! vectorises the block's loops writing straight into out.
    do k0 = 1, n, nb
      m = min(nb, n - k0 + 1)
      call exact_block(m, theta(k0:k0 + m - 1), pb, qb, rb, sb, gb, omega, alpha1, &
                       out(k0:k0 + m - 1, 1), out(k0:k0 + m - 1, 2), out(k0:k0 + m - 1, 3), &
                       out(k0:k0 + m - 1, 4), out(k0:k0 + m - 1, 5), out(k0:k0 + m - 1, 6), &
                       out(k0:k0 + m - 1, 7), out(k0:k0 + m - 1, 8), out(k0:k0 + m - 1, 9), &
                       out(k0:k0 + m - 1, 10), out(k0:k0 + m - 1, 11), sblk)
      status(k0:k0 + m - 1) = nint(sblk(1:m))
    end do
  end subroutine exact_states

  !> One block of exact_states (see there), m <= nb positions, each position with its own linkage
  !> (p, q, r, s and the branch sign sgn = +1/-1 per position: the batched summaries evaluate the
  !> candidate crank angles of many linkages in one call).  The three stages -- positions
  !> (pose_block), rates (rates_block) and angles (angles_block) -- are the one place the loop
  !> closure lives; callers that need only some of them (the summaries' rocker angles, the peak
  !> speeds) call those stages alone and get the same bits.
  subroutine exact_block(m, theta, p, q, r, s, sgn, omega, alpha1, th2, th3, mu, xa, ya, xb, yb, &
                         w2o, w3o, a2o, a3o, status)
    integer, intent(in) :: m
    real(dp), intent(in) :: theta(m), p(m), q(m), r(m), s(m), sgn(m), omega, alpha1
    real(dp), intent(out) :: th2(m), th3(m), mu(m), xa(m), ya(m), xb(m), yb(m), w2o(m), w3o(m), &
                             a2o(m), a3o(m)   ! the eleven columns of exact_states' out
    real(dp), intent(out) :: status(m)   ! status code as a real: keeps the loops in one vector width
    real(dp) :: sn(nb), c(nb), e2x(nb), e2y(nb), e3x(nb), e3y(nb), s23(nb), c23(nb)
    call pose_block(m, theta, p, q, r, s, sgn, sn, c, xa, ya, xb, yb, e2x, e2y, e3x, e3y, s23, c23, status)
    call rates_block(m, q, r, s, omega, alpha1, sn, c, e2x, e2y, e3x, e3y, s23, c23, status, w2o, w3o, a2o, a3o)
    call angles_block(m, e2x, e2y, e3x, e3y, s23, c23, status, th3, th2, mu)
  end subroutine exact_block

  !> Positions of m <= nb crank angles theta [rad], each of its own linkage p, q, r, s on branch
  !> sgn (+1 open, -1 crossed): sin and cos of theta, the pins A = (xa, ya) and B = (xb, yb)
  !> (B zeroed where not placed), the unit vectors e2 = A->B and e3 = O_B->B, sin and cos of
  !> theta3 - theta2, and the status code (st_*, as a real).
  !> Every loop here is free of calls: the transcendental functions are evaluated on the
  !> whole block by vecmath before the main loop, so the loops vectorise by construction (not
  !> by the inliner's grace).
  subroutine pose_block(m, theta, p, q, r, s, sgn, sn, c, xa, ya, xb, yb, e2x, e2y, e3x, e3y, s23, c23, status)
    integer, intent(in) :: m
    real(dp), intent(in) :: theta(m), p(m), q(m), r(m), s(m), sgn(m)
    real(dp), intent(out) :: sn(m), c(m), xa(m), ya(m), xb(m), yb(m), e2x(m), e2y(m), e3x(m), e3y(m), &
                             s23(m), c23(m), status(m)
    real(dp), parameter :: tol = 1.0e-13_dp
    real(dp) :: r2, s2, ax, ay, dx, dy, d2, a, h2, h, bx, by, placed
    real(dp) :: st, isno, istog, isdeg, degst, dmin2
    ! st_ok = 0 is the value left when no flag is set
    real(dp), parameter :: none_ = st_no_assembly, tog_ = st_toggle, ind_ = st_indeterminate
    integer :: k
    call sincos_array(m, theta, sn, c)
    ! hot-loop: fourbar pose_block
    do k = 1, m
      r2 = r(k)*r(k)
      s2 = s(k)*s(k)
      dmin2 = (tol*(p(k) + q(k)))**2
      ! A on O_B: B free on a circle if r = s (indeterminate), else impossible
      degst = merge(ind_, none_, abs(r(k) - s(k)) <= tol*(r(k) + s(k)))
      ax = q(k)*c(k)
      ay = q(k)*sn(k)
      dx = p(k) - ax
      dy = -ay
      d2 = max(dx*dx + dy*dy, tiny(1.0_dp))
      a = (d2 + r2 - s2)/(2*d2)
      h2 = r2/d2 - a*a
      ! status flags as 0/1 reals (single comparisons keep the loop vectorisable)
      isno = merge(1.0_dp, 0.0_dp, h2 < -tol)                   ! cannot be assembled
      istog = merge(1.0_dp, 0.0_dp, h2 <= tol)*(1.0_dp - isno)  ! coupler and rocker collinear
      isdeg = merge(1.0_dp, 0.0_dp, d2 <= dmin2)                ! A on O_B
      st = (1.0_dp - isdeg)*(none_*isno + tog_*istog) + isdeg*degst
      h2 = h2*(1.0_dp - isdeg)
      h = sqrt(max(h2, 0.0_dp))
      bx = ax + a*dx - sgn(k)*h*dy
      by = ay + a*dy + sgn(k)*h*dx
      e2x(k) = (bx - ax)/r(k)
      e2y(k) = (by - ay)/r(k)
      e3x(k) = (bx - p(k))/s(k)
      e3y(k) = by/s(k)
      s23(k) = e2x(k)*e3y(k) - e2y(k)*e3x(k)            ! sin(theta3 - theta2)
      c23(k) = e2x(k)*e3x(k) + e2y(k)*e3y(k)            ! cos(theta3 - theta2)
      placed = (1.0_dp - isno)*(1.0_dp - isdeg)
      xa(k) = ax
      ya(k) = ay
      xb(k) = bx*placed
      yb(k) = by*placed
      status(k) = st
    end do
  end subroutine pose_block

  !> Angular velocities w2o, w3o [rad/s] and accelerations a2o, a3o [rad/s^2] of coupler and
  !> rocker from pose_block's results (crank speed omega, acceleration alpha1; zero unless ok).
  subroutine rates_block(m, q, r, s, omega, alpha1, sn, c, e2x, e2y, e3x, e3y, s23, c23, status, &
                         w2o, w3o, a2o, a3o)
    integer, intent(in) :: m
    real(dp), intent(in) :: q(m), r(m), s(m), omega, alpha1, sn(m), c(m), e2x(m), e2y(m), e3x(m), e3y(m), &
                            s23(m), c23(m), status(m)
    real(dp), intent(out) :: w2o(m), w3o(m), a2o(m), a3o(m)
    real(dp) :: w2, w3, den2, den3, sinv, ok
    integer :: k
    ! hot-loop: fourbar rates_block
    do k = 1, m
      ok = merge(1.0_dp, 0.0_dp, status(k) == real(st_ok, dp))
      sinv = ok/(ok*s23(k) + (1.0_dp - ok))
      w2 = omega*q(k)*(sn(k)*e3x(k) - c(k)*e3y(k))/r(k)*sinv
      w3 = omega*q(k)*(sn(k)*e2x(k) - c(k)*e2y(k))/s(k)*sinv
      den2 = -r(k)*s23(k)
      den3 = s(k)*s23(k)
      w2o(k) = w2
      w3o(k) = w3
      a2o(k) = ok*(-q(k)*alpha1*(sn(k)*e3x(k) - c(k)*e3y(k)) - q(k)*omega*omega*(c(k)*e3x(k) + sn(k)*e3y(k)) &
                   - r(k)*w2*w2*c23(k) + s(k)*w3*w3)/(ok*den2 + (1.0_dp - ok))
      a3o(k) = ok*(q(k)*alpha1*(sn(k)*e2x(k) - c(k)*e2y(k)) + q(k)*omega*omega*(c(k)*e2x(k) + sn(k)*e2y(k)) &
                   + r(k)*w2*w2 - s(k)*w3*w3*c23(k))/(ok*den3 + (1.0_dp - ok))
    end do
  end subroutine rates_block

  !> Angular jerks j2o, j3o [rad/s^3] of coupler and rocker (the time derivatives of rates_block's
  !> accelerations; crank speed omega, acceleration alpha1, no crank jerk) from pose_block's and
  !> rates_block's results; zero unless ok.  The loop closure differentiated once more:
  !> i r (j2 - w2^3) e2 - i s (j3 - w3^3) e3 = q (i omega^3 + 3 omega alpha1) e1 + 3 r w2 a2 e2
  !> - 3 s w3 a3 e3 (e1, e2, e3 the unit vectors of crank, coupler, rocker), solved like the
  !> velocities (the same determinant s23).
  subroutine jerks_block(m, q, r, s, omega, alpha1, sn, c, e2x, e2y, e3x, e3y, s23, c23, status, &
                         w2, w3, a2, a3, j2o, j3o)
    integer, intent(in) :: m
    real(dp), intent(in) :: q(m), r(m), s(m), omega, alpha1, sn(m), c(m), e2x(m), e2y(m), e3x(m), e3y(m), &
                            s23(m), c23(m), status(m), w2(m), w3(m), a2(m), a3(m)
    real(dp), intent(out) :: j2o(m), j3o(m)
    real(dp) :: ok, sinv, o3, oa, t2, t3
    integer :: k
    o3 = omega*omega*omega
    oa = 3.0_dp*omega*alpha1
    ! hot-loop: fourbar jerks_block
    do k = 1, m
      ok = merge(1.0_dp, 0.0_dp, status(k) == real(st_ok, dp))
      sinv = ok/(ok*s23(k) + (1.0_dp - ok))
      t2 = 3.0_dp*r(k)*w2(k)*a2(k)
      t3 = 3.0_dp*s(k)*w3(k)*a3(k)
      j2o(k) = ok*((q(k)*(o3*(c(k)*e3y(k) - sn(k)*e3x(k)) + oa*(c(k)*e3x(k) + sn(k)*e3y(k))) + t2*c23(k) - t3) &
                   /r(k)*sinv + w2(k)*w2(k)*w2(k))
      j3o(k) = ok*((q(k)*(o3*(c(k)*e2y(k) - sn(k)*e2x(k)) + oa*(c(k)*e2x(k) + sn(k)*e2y(k))) + t2 - t3*c23(k)) &
                   /s(k)*sinv + w3(k)*w3(k)*w3(k))
    end do
  end subroutine jerks_block

  !> Rocker angle th3 [rad] from pose_block's results, and with the optional th2, mu the coupler
  !> angle and the transmission angle in [0, pi] (an unplaced row has y = 0 and x = 0 or a unit
  !> vector; its angles are then zeroed).
  subroutine angles_block(m, e2x, e2y, e3x, e3y, s23, c23, status, th3, th2, mu)
    integer, intent(in) :: m
    real(dp), intent(in) :: e2x(m), e2y(m), e3x(m), e3y(m), s23(m), c23(m), status(m)
    real(dp), intent(out) :: th3(m)
    real(dp), intent(out), optional :: th2(m), mu(m)
    real(dp) :: ys(nb, 3), keep(nb), placed
    real(dp), parameter :: none_ = st_no_assembly, ind_ = st_indeterminate, tog_ = st_toggle
    integer :: k
    ! hot-loop: fourbar angle inputs and mask
    do k = 1, m
      placed = merge(1.0_dp, 0.0_dp, status(k) == real(st_ok, dp) .or. status(k) == tog_)
      ys(k, 1) = e2y(k)*placed
      ys(k, 2) = e3y(k)*placed
      ys(k, 3) = abs(s23(k))*placed
      keep(k) = merge(0.0_dp, 1.0_dp, status(k) == none_ .or. status(k) == ind_)
    end do
    call atan2_array(m, ys(:, 2), e3x, th3)
    ! hot-loop: fourbar rocker angle zeroed where unplaced
    do k = 1, m
      th3(k) = th3(k)*keep(k)
    end do
    if (present(th2)) then
      call atan2_array(m, ys(:, 1), e2x, th2)
      ! hot-loop: fourbar coupler angle zeroed where unplaced
      do k = 1, m
        th2(k) = th2(k)*keep(k)
      end do
    end if
    if (present(mu)) then
      call atan2_array(m, ys(:, 3), c23, mu)
      ! hot-loop: fourbar transmission angle zeroed where unplaced
      do k = 1, m
        mu(k) = mu(k)*keep(k)
      end do
    end if
  end subroutine angles_block

  !> A point P fixed to the coupler: P = A + u e2 + v n2, with e2 the unit vector A->B and
  !> n2 its left normal (u along the coupler, v to its left; length units of the linkage).
  !> From exact_states' output: pout(:, 1:2) position, pout(:, 3:4) velocity [length/s],
  !> pout(:, 5:6) acceleration [length/s^2] (crank speed omega, acceleration alpha1).
  !> Rows whose status is not 0 (ok) or 2 (toggle; position only) are zeroed.
  subroutine coupler_point(n, theta, q, omega, alpha1, u, v, states, status, pout)
    integer, intent(in) :: n
    real(dp), intent(in) :: theta(n), q, omega, alpha1, u, v, states(n, 11)
    integer, intent(in) :: status(n)
    real(dp), intent(out) :: pout(n, 6)
    integer :: k0, m
    ! blocks of nb rows, columns passed separately (see exact_states)
    do k0 = 1, n, nb
      m = min(nb, n - k0 + 1)
      call coupler_block(m, theta(k0:k0 + m - 1), q, omega, alpha1, u, v, status(k0:k0 + m - 1), &
                         states(k0:k0 + m - 1, 1), states(k0:k0 + m - 1, 4), states(k0:k0 + m - 1, 5), &
                         states(k0:k0 + m - 1, 8), states(k0:k0 + m - 1, 10), &
                         pout(k0:k0 + m - 1, 1), pout(k0:k0 + m - 1, 2), pout(k0:k0 + m - 1, 3), &
                         pout(k0:k0 + m - 1, 4), pout(k0:k0 + m - 1, 5), pout(k0:k0 + m - 1, 6))
    end do
  end subroutine coupler_point

  !> One block of coupler_point (m <= 256): coupler angle th2, crank pin (xa, ya), coupler
  !> angular velocity w2 and acceleration a2 in; position, velocity, acceleration of P out.
  subroutine coupler_block(m, theta, q, omega, alpha1, u, v, status, th2, xa, ya, w2, a2, &
                           px, py, vx, vy, ax, ay)
    integer, intent(in) :: m
    integer, intent(in) :: status(m)
    real(dp), intent(in) :: theta(m), q, omega, alpha1, u, v, th2(m), xa(m), ya(m), w2(m), a2(m)
    real(dp), intent(out) :: px(m), py(m), vx(m), vy(m), ax(m), ay(m)
    real(dp) :: s2(nb), c2(nb), sn(nb), c(nb), okb(nb), placedb(nb), rx, ry
    integer :: k
    ! hot-loop: fourbar coupler masks
    do k = 1, m      ! row masks as reals: the main loop then works in one vector width
      placedb(k) = merge(1.0_dp, 0.0_dp, status(k) == st_ok .or. status(k) == st_toggle)
      okb(k) = merge(1.0_dp, 0.0_dp, status(k) == st_ok)
    end do
    call sincos_array(m, th2, s2, c2)
    call sincos_array(m, theta, sn, c)
    ! hot-loop: fourbar coupler_block
    do k = 1, m
      rx = u*c2(k) - v*s2(k)            ! P - A
      ry = u*s2(k) + v*c2(k)
      px(k) = placedb(k)*(xa(k) + rx)
      py(k) = placedb(k)*(ya(k) + ry)
      ! v_P = v_A + w2 x (P - A);  a_P = a_A + a2 x (P - A) - w2^2 (P - A)
      vx(k) = okb(k)*(-q*omega*sn(k) - w2(k)*ry)
      vy(k) = okb(k)*(q*omega*c(k) + w2(k)*rx)
      ax(k) = okb(k)*(-q*(alpha1*sn(k) + omega*omega*c(k)) - a2(k)*ry - w2(k)*w2(k)*rx)
      ay(k) = okb(k)*(q*(alpha1*c(k) - omega*omega*sn(k)) + a2(k)*rx - w2(k)*w2(k)*ry)
    end do
  end subroutine coupler_block

end module fourbar
