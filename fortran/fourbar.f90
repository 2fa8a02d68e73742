!> Four-bar linkage kernels (seed 001, Soegihardjo 2003).
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
  implicit none
  private
  public :: listing_table, exact_states

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
    real(dp), intent(out) :: out(n, 11)
    integer, intent(out) :: status(n)
    real(dp), parameter :: tol = 1.0e-13_dp
    real(dp) :: sgn, r2, s2, c, sn, ax, ay, dx, dy, d2, a, h2, h, bx, by
    real(dp) :: e2x, e2y, e3x, e3y, s23, c23, w2, w3, den2, den3, sinv, ok, placed
    integer :: k, st

    sgn = merge(1.0_dp, -1.0_dp, branch >= 0)
    r2 = r*r
    s2 = s*s
    do k = 1, n
      c = cos(theta(k))
      sn = sin(theta(k))
      ax = q*c
      ay = q*sn
      dx = p - ax
      dy = -ay
      d2 = max(dx*dx + dy*dy, tiny(1.0_dp))
      a = (d2 + r2 - s2)/(2*d2)
      h2 = r2/d2 - a*a
      st = merge(st_no_assembly, merge(st_toggle, st_ok, h2 <= tol), h2 < -tol)
      if (d2 <= (tol*(p + q))**2) then   ! A on O_B: B free on a circle if r = s, else impossible
        st = merge(st_indeterminate, st_no_assembly, abs(r - s) <= tol*(r + s))
      end if
      h2 = merge(0.0_dp, h2, st == st_indeterminate)
      h = sqrt(max(h2, 0.0_dp))
      bx = ax + a*dx - sgn*h*dy
      by = ay + a*dy + sgn*h*dx
      e2x = (bx - ax)/r
      e2y = (by - ay)/r
      e3x = (bx - p)/s
      e3y = by/s
      s23 = e2x*e3y - e2y*e3x            ! sin(theta3 - theta2)
      c23 = e2x*e3x + e2y*e3y            ! cos(theta3 - theta2)
      ok = merge(1.0_dp, 0.0_dp, st == st_ok)
      sinv = ok/merge(s23, 1.0_dp, st == st_ok)
      w2 = omega*q*(sn*e3x - c*e3y)/r*sinv
      w3 = omega*q*(sn*e2x - c*e2y)/s*sinv
      den2 = -r*s23
      den3 = s*s23
      placed = merge(1.0_dp, 0.0_dp, st == st_ok .or. st == st_toggle)
      out(k, 1) = atan2(e2y, e2x)*placed
      out(k, 2) = atan2(e3y, e3x)*placed
      out(k, 3) = atan2(abs(s23), c23)*placed
      out(k, 4) = ax
      out(k, 5) = ay
      out(k, 6) = bx*placed
      out(k, 7) = by*placed
      out(k, 8) = w2
      out(k, 9) = w3
      out(k, 10) = ok*(-q*alpha1*(sn*e3x - c*e3y) - q*omega*omega*(c*e3x + sn*e3y) &
                   - r*w2*w2*c23 + s*w3*w3)/merge(den2, 1.0_dp, st == st_ok)
      out(k, 11) = ok*(q*alpha1*(sn*e2x - c*e2y) + q*omega*omega*(c*e2x + sn*e2y) &
                   + r*w2*w2 - s*w3*w3*c23)/merge(den3, 1.0_dp, st == st_ok)
      status(k) = st
    end do
  end subroutine exact_states

end module fourbar
