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
    integer, parameter :: nb = 256
    real(dp) :: sgn, sblk(nb)
    integer :: k0, m

    sgn = merge(1.0_dp, -1.0_dp, branch >= 0)
    ! Blocks of nb positions: the block's transcendental functions are evaluated on whole
    ! arrays (vecmath) and its temporaries stay in cache.  Each output column is passed as
    ! its own dummy argument, so the compiler knows the columns do not overlap and
    ! vectorises the block's loops writing straight into out.
    do k0 = 1, n, nb
      m = min(nb, n - k0 + 1)
      call exact_block(m, theta(k0:k0 + m - 1), p, q, r, s, omega, alpha1, sgn, &
                       out(k0:k0 + m - 1, 1), out(k0:k0 + m - 1, 2), out(k0:k0 + m - 1, 3), &
                       out(k0:k0 + m - 1, 4), out(k0:k0 + m - 1, 5), out(k0:k0 + m - 1, 6), &
                       out(k0:k0 + m - 1, 7), out(k0:k0 + m - 1, 8), out(k0:k0 + m - 1, 9), &
                       out(k0:k0 + m - 1, 10), out(k0:k0 + m - 1, 11), sblk)
      status(k0:k0 + m - 1) = nint(sblk(1:m))
    end do
  end subroutine exact_states

  !> One block of exact_states (see there); m <= nb = 256 (the size of the caller's local arrays).
  !> Every loop here is free of calls: the transcendental functions are evaluated on the
  !> whole block by vecmath before and after the main loop, so the loops vectorise by
  !> construction (not by the inliner's grace).
  subroutine exact_block(m, theta, p, q, r, s, omega, alpha1, sgn, th2, th3, mu, xa, ya, xb, yb, &
                         w2o, w3o, a2o, a3o, status)
    integer, intent(in) :: m
    real(dp), intent(in) :: theta(m), p, q, r, s, omega, alpha1, sgn
    real(dp), intent(out) :: th2(m), th3(m), mu(m), xa(m), ya(m), xb(m), yb(m), w2o(m), w3o(m), &
                             a2o(m), a3o(m)   ! the eleven columns of exact_states' out
    real(dp), intent(inout) :: status(256)   ! status code as a real: keeps the loop in one vector width
    real(dp), parameter :: tol = 1.0e-13_dp
    real(dp) :: r2, s2, c, sn, ax, ay, dx, dy, d2, a, h2, h, bx, by
    real(dp) :: e2x, e2y, e3x, e3y, s23, c23, w2, w3, den2, den3, sinv, ok, placed
    real(dp) :: st, isno, istog, isdeg, degst, dmin2, ys(256, 3), xs(256, 3), sns(256), cs(256), keep(256)
    ! st_ok = 0 is the value left when no flag is set
    real(dp), parameter :: none_ = st_no_assembly, tog_ = st_toggle, ind_ = st_indeterminate
    integer :: k
    r2 = r*r
    s2 = s*s
    dmin2 = (tol*(p + q))**2
    ! A on O_B: B free on a circle if r = s (indeterminate), else impossible
    degst = merge(ind_, none_, abs(r - s) <= tol*(r + s))
    call sincos_array(m, theta, sns, cs)
    ! hot-loop: fourbar exact_block
    do k = 1, m
      sn = sns(k)
      c = cs(k)
      ax = q*c
      ay = q*sn
      dx = p - ax
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
      bx = ax + a*dx - sgn*h*dy
      by = ay + a*dy + sgn*h*dx
      e2x = (bx - ax)/r
      e2y = (by - ay)/r
      e3x = (bx - p)/s
      e3y = by/s
      s23 = e2x*e3y - e2y*e3x            ! sin(theta3 - theta2)
      c23 = e2x*e3x + e2y*e3y            ! cos(theta3 - theta2)
      ok = (1.0_dp - isno)*(1.0_dp - istog)*(1.0_dp - isdeg)
      sinv = ok/(ok*s23 + (1.0_dp - ok))
      w2 = omega*q*(sn*e3x - c*e3y)/r*sinv
      w3 = omega*q*(sn*e2x - c*e2y)/s*sinv
      den2 = -r*s23
      den3 = s*s23
      placed = (1.0_dp - isno)*(1.0_dp - isdeg)
      ys(k, 1) = e2y*placed
      xs(k, 1) = e2x
      ys(k, 2) = e3y*placed
      xs(k, 2) = e3x
      ys(k, 3) = abs(s23)*placed
      xs(k, 3) = c23
      xa(k) = ax
      ya(k) = ay
      xb(k) = bx*placed
      yb(k) = by*placed
      w2o(k) = w2
      w3o(k) = w3
      a2o(k) = ok*(-q*alpha1*(sn*e3x - c*e3y) - q*omega*omega*(c*e3x + sn*e3y) &
                   - r*w2*w2*c23 + s*w3*w3)/(ok*den2 + (1.0_dp - ok))
      a3o(k) = ok*(q*alpha1*(sn*e2x - c*e2y) + q*omega*omega*(c*e2x + sn*e2y) &
                   + r*w2*w2 - s*w3*w3*c23)/(ok*den3 + (1.0_dp - ok))
      status(k) = st
    end do
    ! angles: an unplaced row has y = 0 and x = 0 or a unit vector; its angle is then zeroed
    ! hot-loop: fourbar angle mask
    do k = 1, m
      keep(k) = merge(0.0_dp, 1.0_dp, status(k) == none_ .or. status(k) == ind_)
    end do
    call atan2_array(m, ys(:, 1), xs(:, 1), th2)
    call atan2_array(m, ys(:, 2), xs(:, 2), th3)
    call atan2_array(m, ys(:, 3), xs(:, 3), mu)
    ! hot-loop: fourbar angles zeroed where unplaced
    do k = 1, m
      th2(k) = th2(k)*keep(k)
      th3(k) = th3(k)*keep(k)
      mu(k) = mu(k)*keep(k)
    end do
  end subroutine exact_block

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
    integer, parameter :: nb = 256
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
    real(dp) :: s2(256), c2(256), sn(256), c(256), okb(256), placedb(256), rx, ry
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
