!> Four-bar force analysis (issue 26): joint forces, input torque, shaking force and moment,
!> Berkof-Lowen shaking-force balancing and batched force summaries.
!>
!> Frame: crank pivot O2 at the origin, rocker pivot O4 at (p, 0); y up, gravity along -y.
!> Links: 1 crank O2->A (length q), 2 coupler A->B (r), 3 rocker O4->B (s); the kinematic
!> states are those of fourbar::exact_states (the one place the loop closure lives).
!>
!> Link i has mass m_i, moment of inertia I_i about its centre of mass G_i, and G_i at
!> distance d_i from the link's first pin (O2, A, O4) at angle phi_i counter-clockwise off
!> the line to its second pin (A, B, B).
!>
!> Unknowns per position (9): F_O2 (ground on crank), F_A (crank on coupler), F_B (coupler
!> on rocker), F_O4 (ground on rocker), T (driver torque on the crank, ccw +).
!> With R_i = m_i (a_Gi - g) (g = (0, -gravity)) and h_i = I_i alpha_i + (G_i - pin_i) x R_i:
!>   rocker moments about O4:   (B - O4) x F_B = h_3 - T_load
!>   coupler moments about A:   (B - A)  x F_B = (P - A) x F_load - h_2
!>   -> F_B by Cramer's rule (determinant (B - O4) x (B - A), zero only at a toggle)
!>   F_O4 = R_3 - F_B,   F_A = R_2 + F_B - F_load,   F_O2 = R_1 + F_A,
!>   T = h_1 + A x F_A  (crank moments about O2),
!>   shaking force -(F_O2 + F_O4), shaking moment about O2  -p F_O4,y - T.
!> The load torque (on the rocker) and the load force (at the coupler point P) come from
!> outside the frame; the motor's reaction -T acts on the frame.
module fourbar_forces
  use kinds, only: dp
  use fourbar, only: exact_states, st_ok
  implicit none
  private
  public :: joint_forces, berkof_lowen, force_summaries, link_stresses

  !> props columns: masses, inertias, com distances, com angles [rad], gravity, loads, load point
  integer, parameter, public :: nprop = 18
  !> force columns: T, F_O2, F_A, F_B, F_O4 (x, y), shaking force (x, y), shaking moment
  integer, parameter, public :: nforce = 12
  !> batch parameter and result columns (see force_summaries)
  integer, parameter, public :: nbpar = 31, nbres = 13
  real(dp), parameter :: pi = 3.14159265358979323846_dp
  real(dp), parameter :: rad = pi/180.0_dp
  integer, parameter :: nb = 256

contains

  !> Joint forces of the linkage at n positions.
  !> states(n, 11), status(n) from fourbar::exact_states at crank speed omega [rad/s] and
  !> acceleration alpha1 [rad/s^2] (the crank pin A = q (cos theta, sin theta) is in states).
  !> props(1:3) masses m1, m2, m3 [kg]; props(4:6) inertias about the centres of mass [kg m^2];
  !> props(7:9) com distances [m]; props(10:12) com angles [rad]; props(13) gravity [m/s^2];
  !> props(14) load torque on the rocker [N m]; props(15:16) load force at P [N];
  !> props(17:18) P on the coupler: u along A->B, v to its left [m].
  !> fout(:, 1) input torque [N m]; fout(:, 2:9) F_O2, F_A, F_B, F_O4 (x, y) [N];
  !> fout(:, 10:11) shaking force [N]; fout(:, 12) shaking moment about O2 [N m].
  !> Rows whose status is not st_ok (no assembly, toggle, indeterminate) are zero.
  !> fout is the caller's buffer (every element overwritten), as exact_states' out: a caller
  !> that calls again and again reuses it instead of touching fresh memory each call.
  subroutine joint_forces(n, states, status, p, q, r, s, omega, alpha1, props, fout)
    !f2py threadsafe
    integer, intent(in) :: n
    real(dp), intent(in) :: states(n, 11)
    integer, intent(in) :: status(n)
    real(dp), intent(in) :: p, q, r, s, omega, alpha1, props(18)
    real(dp), intent(inout) :: fout(n, 12)
    !f2py intent(in,out) :: fout
    integer :: k0, m
    real(dp) :: com(6)
    ! com offsets in link axes, d (cos phi, sin phi): once per call, not per block (six libm calls)
    com = [props(7)*cos(props(10)), props(7)*sin(props(10)), props(8)*cos(props(11)), props(8)*sin(props(11)), &
           props(9)*cos(props(12)), props(9)*sin(props(12))]
    ! blocks of nb rows, columns passed separately (see fourbar::exact_states)
    do k0 = 1, n, nb
      m = min(nb, n - k0 + 1)
      call forces_block(m, status(k0:k0 + m - 1), p, q, r, s, omega, alpha1, props, com, &
                        states(k0:k0 + m - 1, 4), states(k0:k0 + m - 1, 5), &
                        states(k0:k0 + m - 1, 6), states(k0:k0 + m - 1, 7), &
                        states(k0:k0 + m - 1, 8), states(k0:k0 + m - 1, 9), &
                        states(k0:k0 + m - 1, 10), states(k0:k0 + m - 1, 11), &
                        fout(k0:k0 + m - 1, 1), fout(k0:k0 + m - 1, 2), fout(k0:k0 + m - 1, 3), &
                        fout(k0:k0 + m - 1, 4), fout(k0:k0 + m - 1, 5), fout(k0:k0 + m - 1, 6), &
                        fout(k0:k0 + m - 1, 7), fout(k0:k0 + m - 1, 8), fout(k0:k0 + m - 1, 9), &
                        fout(k0:k0 + m - 1, 10), fout(k0:k0 + m - 1, 11), fout(k0:k0 + m - 1, 12))
    end do
  end subroutine joint_forces

  !> One block of joint_forces (m <= nb): pins A = (xa, ya), B = (xb, yb), coupler and rocker
  !> angular velocities w2, w3 and accelerations a2, a3 in; the twelve force columns out; com the
  !> centres of mass in link axes (k1x, k1y, k2x, k2y, k3x, k3y: d_i (cos phi_i, sin phi_i)).
  !> The loop body is straight-line arithmetic (no transcendental function: the link
  !> directions are the unit vectors between the pins), so it vectorises.
  subroutine forces_block(m, status, p, q, r, s, omega, alpha1, props, com, xa, ya, xb, yb, w2, w3, a2, a3, &
                          tq, fo2x, fo2y, fax, fay, fbx, fby, fo4x, fo4y, shx, shy, shm)
    integer, intent(in) :: m, status(m)
    real(dp), intent(in) :: p, q, r, s, omega, alpha1, props(18), com(6)
    real(dp), intent(in) :: xa(m), ya(m), xb(m), yb(m), w2(m), w3(m), a2(m), a3(m)
    real(dp), intent(out) :: tq(m), fo2x(m), fo2y(m), fax(m), fay(m), fbx(m), fby(m), fo4x(m), fo4y(m), &
                             shx(m), shy(m), shm(m)
    real(dp) :: m1, m2, m3, i1, i2, i3, grav, tl, flx, fly, u, v
    real(dp) :: k1x, k1y, k2x, k2y, k3x, k3y, w1s
    real(dp) :: okb(nb), ok, c1, s1, e2x, e2y, e3x, e3y, g1x, g1y, g2x, g2y, g3x, g3y
    real(dp) :: r1x, r1y, r2x, r2y, r3x, r3y, h1, h2, h3, rhox, rhoy, bx, by, cx, cy, det, mm2, mm3
    real(dp) :: fbxk, fbyk, faxk, fayk, fo4xk, fo4yk, tqk, w2s, w3s
    integer :: k
    m1 = props(1); m2 = props(2); m3 = props(3)
    i1 = props(4); i2 = props(5); i3 = props(6)
    k1x = com(1); k1y = com(2); k2x = com(3); k2y = com(4); k3x = com(5); k3y = com(6)
    grav = props(13); tl = props(14); flx = props(15); fly = props(16); u = props(17); v = props(18)
    w1s = omega*omega
    ! hot-loop: fourbar_forces status mask
    do k = 1, m
      okb(k) = merge(1.0_dp, 0.0_dp, status(k) == st_ok)
    end do
    ! hot-loop: fourbar_forces forces_block
    do k = 1, m
      ok = okb(k)
      c1 = xa(k)/q
      s1 = ya(k)/q
      e2x = (xb(k) - xa(k))/r
      e2y = (yb(k) - ya(k))/r
      e3x = (xb(k) - p)/s
      e3y = yb(k)/s
      ! G_i - pin_i: the link direction turned by phi_i, times d_i
      g1x = k1x*c1 - k1y*s1
      g1y = k1x*s1 + k1y*c1
      g2x = k2x*e2x - k2y*e2y
      g2y = k2x*e2y + k2y*e2x
      g3x = k3x*e3x - k3y*e3y
      g3y = k3x*e3y + k3y*e3x
      w2s = w2(k)*w2(k)
      w3s = w3(k)*w3(k)
      ! R_i = m_i (a_Gi - g):  a_G = a_pin + alpha x (G - pin) - w^2 (G - pin)
      r1x = m1*(-alpha1*g1y - w1s*g1x)
      r1y = m1*(alpha1*g1x - w1s*g1y + grav)
      r2x = m2*(-alpha1*ya(k) - w1s*xa(k) - a2(k)*g2y - w2s*g2x)
      r2y = m2*(alpha1*xa(k) - w1s*ya(k) + a2(k)*g2x - w2s*g2y + grav)
      r3x = m3*(-a3(k)*g3y - w3s*g3x)
      r3y = m3*(a3(k)*g3x - w3s*g3y + grav)
      ! h_i = I_i alpha_i + (G_i - pin_i) x R_i
      h1 = i1*alpha1 + (g1x*r1y - g1y*r1x)
      h2 = i2*a2(k) + (g2x*r2y - g2y*r2x)
      h3 = i3*a3(k) + (g3x*r3y - g3y*r3x)
      ! load point P - A = u e2 + v n2
      rhox = u*e2x - v*e2y
      rhoy = u*e2y + v*e2x
      mm3 = h3 - tl                                ! (B - O4) x F_B
      mm2 = (rhox*fly - rhoy*flx) - h2             ! (B - A) x F_B
      bx = xb(k) - p
      by = yb(k)
      cx = xb(k) - xa(k)
      cy = yb(k) - ya(k)
      det = ok*(bx*cy - by*cx) + (1.0_dp - ok)
      fbxk = ok*(mm3*cx - bx*mm2)/det
      fbyk = ok*(cy*mm3 - by*mm2)/det
      fo4xk = ok*(r3x - fbxk)
      fo4yk = ok*(r3y - fbyk)
      faxk = ok*(r2x + fbxk - flx)
      fayk = ok*(r2y + fbyk - fly)
      tqk = ok*(h1 + xa(k)*fayk - ya(k)*faxk)
      fbx(k) = fbxk
      fby(k) = fbyk
      fo4x(k) = fo4xk
      fo4y(k) = fo4yk
      fax(k) = faxk
      fay(k) = fayk
      fo2x(k) = ok*(r1x + faxk)
      fo2y(k) = ok*(r1y + fayk)
      tq(k) = tqk
      shx(k) = -(fo2x(k) + fo4xk)
      shy(k) = -(fo2y(k) + fo4yk)
      shm(k) = -p*fo4yk - tqk
    end do
  end subroutine forces_block

  !> Peak normal stress in each moving link at n positions, from the joint forces fout (joint_forces
  !> with the same states, omega, alpha1 and props): each link a straight prismatic bar between
  !> its pins with area section(i) [m^2] and elastic section modulus section(3 + i) [m^3] for
  !> in-plane bending (i = 1 crank, 2 coupler, 3 rocker).  Its loads are those of the force
  !> analysis's free bodies, where they act: the pin forces at the pins (crank: F_O2 at O2 and
  !> -F_A at A; coupler: F_A at A, -F_B at B and the load force at P; rocker: F_O4 at O4 and
  !> F_B at B), the driver torque T on the crank at O2 and the load torque on the rocker at O4,
  !> and the link's inertia force and weight -R_i at its centre of mass G_i (R_i from the link's
  !> force balance: R_1 = F_O2 - F_A, R_2 = F_A - F_B + F_load, R_3 = F_O4 + F_B) with the couple
  !> -I_i alpha_i there.  Cut at a distance xi from the first pin along the pin line, the part
  !> before the cut carries the axial force N and bending moment M; with the loads lumped at
  !> points, N is constant and M linear between them, so |N|/A + |M|/Z peaks on one side of a
  !> load point or at a pin: those cuts are evaluated (a load beyond the pins, projected off the
  !> bar, counts as before or after every cut).  sout(k, i): the peak |N|/A + |M|/Z of link i
  !> at position k [Pa]; 0 where status is not st_ok.
  subroutine link_stresses(n, states, status, p, q, r, s, alpha1, props, fout, section, sout)
    !f2py threadsafe
    integer, intent(in) :: n
    real(dp), intent(in) :: states(n, 11)
    integer, intent(in) :: status(n)
    real(dp), intent(in) :: p, q, r, s, alpha1, props(18), fout(n, 12), section(6)
    real(dp), intent(out) :: sout(n, 3)
    real(dp) :: xa, ya, xb, yb, ex, ey, kx, ky, gx, gy, ux, uy, lpx(4), lpy(4), lfx(4), lfy(4), lc(4)
    real(dp) :: fo2x, fo2y, fax, fay, fbx, fby, fo4x, fo4y, flx, fly
    integer :: k
    flx = props(15)
    fly = props(16)
    sout = 0.0_dp
    do k = 1, n
      if (status(k) /= st_ok) cycle
      xa = states(k, 4); ya = states(k, 5); xb = states(k, 6); yb = states(k, 7)
      fo2x = fout(k, 2); fo2y = fout(k, 3); fax = fout(k, 4); fay = fout(k, 5)
      fbx = fout(k, 6); fby = fout(k, 7); fo4x = fout(k, 8); fo4y = fout(k, 9)
      ! crank O2 -> A: F_O2 and T at O2, -F_A at A, -R_1 and -I_1 alpha_1 at G_1
      ex = xa/q; ey = ya/q
      kx = props(7)*cos(props(10)); ky = props(7)*sin(props(10))
      gx = kx*ex - ky*ey; gy = kx*ey + ky*ex
      lpx(1:3) = [0.0_dp, xa, gx]; lpy(1:3) = [0.0_dp, ya, gy]
      lfx(1:3) = [fo2x, -fax, -(fo2x - fax)]; lfy(1:3) = [fo2y, -fay, -(fo2y - fay)]
      lc(1:3) = [fout(k, 1), 0.0_dp, -props(4)*alpha1]
      sout(k, 1) = bar_stress(3, lpx, lpy, lfx, lfy, lc, 0.0_dp, 0.0_dp, ex, ey, q, section(1), section(4))
      ! coupler A -> B: F_A at A, -F_B at B, -R_2 and -I_2 alpha_2 at G_2, the load force at P
      ex = (xb - xa)/r; ey = (yb - ya)/r
      kx = props(8)*cos(props(11)); ky = props(8)*sin(props(11))
      gx = xa + kx*ex - ky*ey; gy = ya + kx*ey + ky*ex
      ux = xa + props(17)*ex - props(18)*ey; uy = ya + props(17)*ey + props(18)*ex
      lpx = [xa, xb, gx, ux]; lpy = [ya, yb, gy, uy]
      lfx = [fax, -fbx, -(fax - fbx + flx), flx]; lfy = [fay, -fby, -(fay - fby + fly), fly]
      lc = [0.0_dp, 0.0_dp, -props(5)*states(k, 10), 0.0_dp]
      sout(k, 2) = bar_stress(4, lpx, lpy, lfx, lfy, lc, xa, ya, ex, ey, r, section(2), section(5))
      ! rocker O4 -> B: F_O4 and the load torque at O4, F_B at B, -R_3 and -I_3 alpha_3 at G_3
      ex = (xb - p)/s; ey = yb/s
      kx = props(9)*cos(props(12)); ky = props(9)*sin(props(12))
      gx = p + kx*ex - ky*ey; gy = kx*ey + ky*ex
      lpx(1:3) = [p, xb, gx]; lpy(1:3) = [0.0_dp, yb, gy]
      lfx(1:3) = [fo4x, fbx, -(fo4x + fbx)]; lfy(1:3) = [fo4y, fby, -(fo4y + fby)]
      lc(1:3) = [props(14), 0.0_dp, -props(6)*states(k, 11)]
      sout(k, 3) = bar_stress(3, lpx, lpy, lfx, lfy, lc, p, 0.0_dp, ex, ey, s, section(3), section(6))
    end do
  end subroutine link_stresses

  !> The peak |N|/A + |M|/Z [Pa] along a bar from (x0, y0) in the unit direction (ex, ey) of length
  !> len under nl point loads: forces (fx, fy) [N] at (px, py) [m] and couples c [N m].  Cuts on
  !> both sides of every load's projection xi_j = (P_j - start) . e clamped to [0, len]; the part
  !> before a cut holds the loads with xi_j below it (strictly, or up to it), and its resultant
  !> force and moment about the cut point are the section's N (along e) and M.
  pure real(dp) function bar_stress(nl, px, py, fx, fy, c, x0, y0, ex, ey, len, area, modulus) result(peak)
    integer, intent(in) :: nl
    real(dp), intent(in) :: px(nl), py(nl), fx(nl), fy(nl), c(nl), x0, y0, ex, ey, len, area, modulus
    real(dp) :: xi(nl), cut, sx, sy, nx, ny, m, st
    integer :: i, j, side
    do j = 1, nl
      xi(j) = (px(j) - x0)*ex + (py(j) - y0)*ey
    end do
    peak = 0.0_dp
    do i = 1, nl
      cut = min(max(xi(i), 0.0_dp), len)
      sx = x0 + cut*ex
      sy = y0 + cut*ey
      do side = 0, 1
        nx = 0.0_dp
        ny = 0.0_dp
        m = 0.0_dp
        do j = 1, nl
          if (xi(j) < cut .or. (side == 1 .and. xi(j) <= cut)) then
            nx = nx + fx(j)
            ny = ny + fy(j)
            m = m + (px(j) - sx)*fy(j) - (py(j) - sy)*fx(j) + c(j)
          end if
        end do
        st = abs(nx*ex + ny*ey)/area + abs(m)/modulus
        peak = max(peak, st)
      end do
    end do
  end function bar_stress

  !> Berkof-Lowen shaking-force balance by counterweights on the crank and the rocker.
  !> The total centre of mass is stationary when (complex link vectors, z_i = d_i e^(i phi_i))
  !>   m1 z1 = m2 q (z2 / r - 1)     and     m3 z3 = -m2 s z2 / r,
  !> so each counterweight's mass x radius (in the link's axes) is the required first moment
  !> minus the link's own.  cw_radius(1:2): where the point-mass counterweights sit on the
  !> crank and the rocker [m] (> 0).
  !> cw(1:2) crank counterweight mass x radius [kg m] and angle off O2->A [rad];
  !> cw(3:4) the same for the rocker (angle off O4->B); cw(5:6) the two counterweight masses [kg].
  !> pbal: props of the balanced linkage (crank and rocker mass, inertia about the new centre
  !> of mass and com position changed; everything else copied).
  subroutine berkof_lowen(q, r, s, props, cw_radius, pbal, cw)
    real(dp), intent(in) :: q, r, s, props(18), cw_radius(2)
    real(dp), intent(out) :: pbal(18), cw(6)
    real(dp) :: z2x, z2y, req1x, req1y, req3x, req3y, c1x, c1y, c3x, c3y
    z2x = props(8)*cos(props(11))
    z2y = props(8)*sin(props(11))
    req1x = props(2)*q*(z2x/r - 1.0_dp)
    req1y = props(2)*q*z2y/r
    req3x = -props(2)*s*z2x/r
    req3y = -props(2)*s*z2y/r
    c1x = req1x - props(1)*props(7)*cos(props(10))
    c1y = req1y - props(1)*props(7)*sin(props(10))
    c3x = req3x - props(3)*props(9)*cos(props(12))
    c3y = req3y - props(3)*props(9)*sin(props(12))
    cw(1) = hypot(c1x, c1y)
    cw(2) = atan2(c1y, c1x)
    cw(3) = hypot(c3x, c3y)
    cw(4) = atan2(c3y, c3x)
    cw(5) = cw(1)/cw_radius(1)
    cw(6) = cw(3)/cw_radius(2)
    pbal = props
    call add_point_mass(props(1), props(4), props(7), cw(5), cw_radius(1), req1x, req1y, &
                        pbal(1), pbal(4), pbal(7), pbal(10))
    call add_point_mass(props(3), props(6), props(9), cw(6), cw_radius(2), req3x, req3y, &
                        pbal(3), pbal(6), pbal(9), pbal(12))
  end subroutine berkof_lowen

  !> A link (mass m, inertia ic about its com at d e^(i phi) from its pin) plus a point mass mc at
  !> radius rc: new mass, inertia about the new com, com distance and angle.  The new first
  !> moment (zx, zy) is the required one, passed in so it is exact rather than re-summed (the
  !> counterweight's angle is the one that makes it so; phi enters only through it).
  pure subroutine add_point_mass(m, ic, d, mc, rc, zx, zy, mn, icn, dn, phin)
    real(dp), intent(in) :: m, ic, d, mc, rc, zx, zy
    real(dp), intent(out) :: mn, icn, dn, phin
    real(dp) :: ipin
    mn = m + mc
    ipin = ic + m*d*d + mc*rc*rc      ! about the pin
    if (mn > 0.0_dp) then
      dn = hypot(zx, zy)/mn
    else
      dn = 0.0_dp
    end if
    phin = atan2(zy, zx)
    icn = ipin - mn*dn*dn
  end subroutine add_point_mass

  !> Force summaries of nd linkages over a scan of each one's crank range (one turn at most
  !> resolves the motion; the scan steps at most 0.1 deg, at most 36001 points).
  !> params(:, 1:4) p, q, r, s [m]; (:, 5:6) omega [rad/s], alpha [rad/s^2];
  !> (:, 7:8) first and last crank angle [deg]; (:, 9) branch (>= 0 open, < 0 crossed);
  !> (:, 10:27) props as joint_forces (com angles in rad); (:, 28) speed fluctuation C_s;
  !> (:, 29) balance (1: Berkof-Lowen counterweights added first, 0: as given);
  !> (:, 30:31) counterweight radii on crank and rocker [m].
  !> res(:, 1) fraction of the scan where the forces are defined (assembled, no toggle)
  !> res(:, 2:3) peak |input torque| [N m] and its crank angle [deg]
  !> res(:, 4:5) mean and RMS input torque over the range [N m] (trapezoid in the crank angle)
  !> res(:, 6:9) peak |F_O2|, |F_A|, |F_B|, |F_O4| [N]
  !> res(:, 10:11) peak |shaking force| [N], peak |shaking moment| [N m]
  !> res(:, 12) energy fluctuation: max - min of the integral of (T - mean T) over the crank angle [J]
  !> res(:, 13) flywheel inertia dE / (C_s omega^2) [kg m^2]
  !> Peaks are over the defined positions; mean, RMS and dE only when the whole scan is
  !> defined (else 0; res(:, 1) < 1 says so); the flywheel inertia only with omega /= 0.
  subroutine force_summaries(nd, params, res)
    !f2py threadsafe
    integer, intent(in) :: nd
    real(dp), intent(in) :: params(nd, 31)
    real(dp), intent(out) :: res(nd, 13)
    integer, parameter :: maxpts = 36001
    real(dp), allocatable :: th(:), st(:, :), fo(:, :)
    integer, allocatable :: sts(:)
    real(dp) :: props(18), pb(18), cw(6), span, h, lo, hi, tmean, e, emin, emax, acc, rms
    integer :: i, n, k, nok, kpk
    allocate (th(maxpts), st(maxpts, 11), fo(maxpts, 12), sts(maxpts))
    do i = 1, nd
      lo = params(i, 7)
      hi = params(i, 8)
      span = abs(hi - lo)
      n = min(maxpts, max(2, ceiling(span/0.1_dp - 1.0e-9_dp) + 1))
      if (span == 0.0_dp) n = 1
      h = 0.0_dp
      if (n > 1) h = (hi - lo)/real(n - 1, dp)
      do k = 1, n
        th(k) = (lo + h*real(k - 1, dp))*rad
      end do
      props = params(i, 10:27)
      if (params(i, 29) > 0.5_dp) then
        call berkof_lowen(params(i, 2), params(i, 3), params(i, 4), props, params(i, 30:31), pb, cw)
        props = pb
      end if
      call exact_states(n, th(1:n), params(i, 1), params(i, 2), params(i, 3), params(i, 4), params(i, 5), &
                        params(i, 6), merge(1, -1, params(i, 9) >= 0.0_dp), st(1:n, :), sts(1:n))
      call joint_forces(n, st(1:n, :), sts(1:n), params(i, 1), params(i, 2), params(i, 3), &
                        params(i, 4), params(i, 5), params(i, 6), props, fo(1:n, :))
      res(i, :) = 0.0_dp
      nok = count(sts(1:n) == st_ok)
      res(i, 1) = real(nok, dp)/real(n, dp)
      if (nok == 0) cycle
      kpk = maxloc(abs(fo(1:n, 1)), 1, mask=sts(1:n) == st_ok)
      res(i, 2) = abs(fo(kpk, 1))
      res(i, 3) = th(kpk)/rad
      res(i, 6) = maxval(hypot(fo(1:n, 2), fo(1:n, 3)))
      res(i, 7) = maxval(hypot(fo(1:n, 4), fo(1:n, 5)))
      res(i, 8) = maxval(hypot(fo(1:n, 6), fo(1:n, 7)))
      res(i, 9) = maxval(hypot(fo(1:n, 8), fo(1:n, 9)))
      res(i, 10) = maxval(hypot(fo(1:n, 10), fo(1:n, 11)))
      res(i, 11) = maxval(abs(fo(1:n, 12)))
      if (nok < n) cycle
      if (n == 1) then
        res(i, 4) = fo(1, 1)
        res(i, 5) = abs(fo(1, 1))
        cycle
      end if
      ! trapezoid means over the range (uniform steps)
      acc = 0.5_dp*(fo(1, 1) + fo(n, 1)) + sum(fo(2:n - 1, 1))
      tmean = acc/real(n - 1, dp)
      rms = 0.5_dp*(fo(1, 1)**2 + fo(n, 1)**2) + sum(fo(2:n - 1, 1)**2)
      res(i, 4) = tmean
      res(i, 5) = sqrt(rms/real(n - 1, dp))
      ! energy fluctuation: E(theta) = integral of (T - mean) d theta, trapezoid, max - min
      e = 0.0_dp
      emin = 0.0_dp
      emax = 0.0_dp
      do k = 2, n
        e = e + 0.5_dp*(fo(k - 1, 1) + fo(k, 1) - 2*tmean)*abs(h)*rad
        emin = min(emin, e)
        emax = max(emax, e)
      end do
      res(i, 12) = emax - emin
      if (params(i, 5) /= 0.0_dp .and. params(i, 28) > 0.0_dp) then
        res(i, 13) = res(i, 12)/(params(i, 28)*params(i, 5)**2)
      end if
    end do
  end subroutine force_summaries

end module fourbar_forces
