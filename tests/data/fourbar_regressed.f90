!> Regression fixture for tests/test_vectorisation.py, not built: the four-bar kernel as it was
!> before the vectorisation guard (commit 0ebfc2d), with exact_block's main loop marked.  Its
!> per-element calls of the elemental vsincos (three call sites) are not inlined by gfortran 12,
!> so that loop is not vectorised (3.7x slower); the guard must report it.
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
    real(dp) :: sgn, blk(nb, 11), sblk(nb)
    integer :: k0, m

    sgn = merge(1.0_dp, -1.0_dp, branch >= 0)
    ! Work in blocks of nb positions held in fixed-size local arrays, so the
    ! compiler can prove the eleven output columns independent and vectorise.
    do k0 = 1, n, nb
      m = min(nb, n - k0 + 1)
      call exact_block(m, theta(k0:k0 + m - 1), p, q, r, s, omega, alpha1, sgn, blk, sblk)
      out(k0:k0 + m - 1, :) = blk(1:m, :)
      status(k0:k0 + m - 1) = nint(sblk(1:m))
    end do
  end subroutine exact_states

  !> One block of exact_states (see there); m <= size of the local arrays of the caller.
  subroutine exact_block(m, theta, p, q, r, s, omega, alpha1, sgn, out, status)
    integer, intent(in) :: m
    real(dp), intent(in) :: theta(m), p, q, r, s, omega, alpha1, sgn
    real(dp), intent(inout) :: out(256, 11)
    real(dp), intent(inout) :: status(256)   ! status code as a real: keeps the loop in one vector width
    real(dp), parameter :: tol = 1.0e-13_dp
    real(dp) :: r2, s2, c, sn, ax, ay, dx, dy, d2, a, h2, h, bx, by
    real(dp) :: e2x, e2y, e3x, e3y, s23, c23, w2, w3, den2, den3, sinv, ok, placed
    real(dp) :: st, isno, istog, isdeg, degst, dmin2, ys(256, 3), xs(256, 3)
    ! st_ok = 0 is the value left when no flag is set
    real(dp), parameter :: none_ = st_no_assembly, tog_ = st_toggle, ind_ = st_indeterminate
    integer :: k, j
    r2 = r*r
    s2 = s*s
    dmin2 = (tol*(p + q))**2
    ! A on O_B: B free on a circle if r = s (indeterminate), else impossible
    degst = merge(ind_, none_, abs(r - s) <= tol*(r + s))
    ! hot-loop: exact_block main loop
    do k = 1, m
      call vsincos(theta(k), sn, c)
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
      out(k, 4) = ax
      out(k, 5) = ay
      out(k, 6) = bx*placed
      out(k, 7) = by*placed
      out(k, 8) = w2
      out(k, 9) = w3
      out(k, 10) = ok*(-q*alpha1*(sn*e3x - c*e3y) - q*omega*omega*(c*e3x + sn*e3y) &
                   - r*w2*w2*c23 + s*w3*w3)/(ok*den2 + (1.0_dp - ok))
      out(k, 11) = ok*(q*alpha1*(sn*e2x - c*e2y) + q*omega*omega*(c*e2x + sn*e2y) &
                   + r*w2*w2 - s*w3*w3*c23)/(ok*den3 + (1.0_dp - ok))
      status(k) = st
    end do
    ! angles in a second pass: one call site, so vatan2 is inlined and vectorised
    ! (an unplaced row has y = 0 and x = 0 or a unit vector; its angle is then zeroed)
    do j = 1, 3
      do k = 1, m
        out(k, j) = vatan2(ys(k, j), xs(k, j))*merge(0.0_dp, 1.0_dp, status(k) == none_ .or. status(k) == ind_)
      end do
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
    real(dp) :: c2, s2, rx, ry, w2, a2, ok, placed, c, sn
    integer :: k
    do k = 1, n
      placed = merge(1.0_dp, 0.0_dp, status(k) == st_ok .or. status(k) == st_toggle)
      ok = merge(1.0_dp, 0.0_dp, status(k) == st_ok)
      call vsincos(states(k, 1), s2, c2)
      call vsincos(theta(k), sn, c)
      rx = u*c2 - v*s2                  ! P - A
      ry = u*s2 + v*c2
      w2 = states(k, 8)
      a2 = states(k, 10)
      pout(k, 1) = placed*(states(k, 4) + rx)
      pout(k, 2) = placed*(states(k, 5) + ry)
      ! v_P = v_A + w2 x (P - A);  a_P = a_A + a2 x (P - A) - w2^2 (P - A)
      pout(k, 3) = ok*(-q*omega*sn - w2*ry)
      pout(k, 4) = ok*(q*omega*c + w2*rx)
      pout(k, 5) = ok*(-q*(alpha1*sn + omega*omega*c) - a2*ry - w2*w2*rx)
      pout(k, 6) = ok*(q*(alpha1*c - omega*omega*sn) + a2*rx - w2*w2*ry)
    end do
  end subroutine coupler_point

  !> sin and cos of x [rad], branch-free so that loops calling it vectorise.
  !> Cody-Waite reduction by pi/2 in three parts (fdlibm constants), then the
  !> fdlibm kernel polynomials on |r| <= pi/4.  Accurate to ~1 ulp for |x| < 1e5.
  elemental subroutine vsincos(x, s, c)
    real(dp), intent(in) :: x
    real(dp), intent(out) :: s, c
    real(dp), parameter :: twoopi = 6.36619772367581382433e-01_dp
    real(dp), parameter :: pio2_1 = 1.57079632673412561417e+00_dp, pio2_2 = 6.07710050630396597660e-11_dp, &
                           pio2_2t = 2.02226624879595063154e-21_dp
    real(dp), parameter :: magic = 6755399441055744.0_dp   ! 1.5 * 2**52: adding/subtracting rounds to nearest
    real(dp), parameter :: s1 = -1.66666666666666324348e-01_dp, s2 = 8.33333333332248946124e-03_dp, &
      s3 = -1.98412698298579493134e-04_dp, s4 = 2.75573137070700676789e-06_dp, &
      s5 = -2.50507602534068634195e-08_dp, s6 = 1.58969099521155010221e-10_dp
    real(dp), parameter :: c1 = 4.16666666666666019037e-02_dp, c2 = -1.38888888888741095749e-03_dp, &
      c3 = 2.48015872894767294178e-05_dp, c4 = -2.75573143513906633035e-07_dp, &
      c5 = 2.08757232129817482790e-09_dp, c6 = -1.13596475577881948265e-11_dp
    real(dp) :: kf, m, r, z, sr, cr
    kf = (x*twoopi + magic) - magic                     ! nearest integer k
    r = ((x - kf*pio2_1) - kf*pio2_2) - kf*pio2_2t
    m = kf - 4.0_dp*(((kf*0.25_dp - 0.375_dp) + magic) - magic)   ! k mod 4 in {0,1,2,3}
    z = r*r
    sr = r + r*z*(s1 + z*(s2 + z*(s3 + z*(s4 + z*(s5 + z*s6)))))
    cr = 1.0_dp - 0.5_dp*z + z*z*(c1 + z*(c2 + z*(c3 + z*(c4 + z*(c5 + z*c6)))))
    s = merge(cr, sr, m == 1.0_dp .or. m == 3.0_dp)*merge(-1.0_dp, 1.0_dp, m >= 2.0_dp)
    c = merge(sr, cr, m == 1.0_dp .or. m == 3.0_dp)*merge(-1.0_dp, 1.0_dp, m == 1.0_dp .or. m == 2.0_dp)
  end subroutine vsincos

  !> atan2(y, x) [rad] in (-pi, pi], branch-free (Cephes atan rational on [0, 1]).
  elemental function vatan2(y, x) result(t)
    real(dp), intent(in) :: y, x
    real(dp) :: t
    real(dp), parameter :: pio2 = 1.57079632679489661923_dp, pio4 = 0.78539816339744830962_dp, &
                           pi = 3.14159265358979323846_dp, morebits = 6.123233995736765886130e-17_dp
    real(dp), parameter :: p0 = -8.750608600031904122785e-01_dp, p1 = -1.615753718733365076637e+01_dp, &
      p2 = -7.500855792314704667340e+01_dp, p3 = -1.228866684490136173410e+02_dp, &
      p4 = -6.485021904942025371773e+01_dp
    real(dp), parameter :: q0 = 2.485846490142306297962e+01_dp, q1 = 1.650270098316988542046e+02_dp, &
      q2 = 4.328810604912902668951e+02_dp, q3 = 4.853903996359136964868e+02_dp, &
      q4 = 1.945506571482613964425e+02_dp
    real(dp) :: ax, ay, mn, mx, u, v, z, base, big   ! big: 1 or 0 (a real keeps one vector width)
    ax = abs(x)
    ay = abs(y)
    mx = max(ax, ay)
    mn = min(ax, ay)
    u = mn/max(mx, tiny(1.0_dp))                      ! in [0, 1]
    big = merge(1.0_dp, 0.0_dp, u > 0.66_dp)
    v = big*((u - 1.0_dp)/(u + 1.0_dp)) + (1.0_dp - big)*u
    base = big*pio4
    z = v*v
    z = z*((((p0*z + p1)*z + p2)*z + p3)*z + p4)/(((((z + q0)*z + q1)*z + q2)*z + q3)*z + q4)
    t = base + (v*z + v + big*(0.5_dp*morebits))
    t = merge(pio2 - t, t, ay > ax)
    t = merge(pi - t, t, x < 0.0_dp)
    t = sign(t, y)
  end function vatan2

end module fourbar
