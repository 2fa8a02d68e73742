!> Planar 2R manipulator kernels (seed 004, robust dimensional synthesis, chapter 4).
!>
!> Geometry: base A at the origin, link lengths l1, l2, joint angles th1 (from the
!> x axis) and th2 (relative, elbow), counter-clockwise positive, radians.  End
!> effector e = l1 (c1, s1) + l2 (c12, s12)  (report eq. 2.18).  Gravity acts
!> along -y.  All routines are vectorised: one row per configuration / design.
!>
!> arm_states      Jacobian (4.18), manipulability w = |det J| (4.30), condition
!>                 number sigma_max/sigma_min, and Craig's point-mass torques (2.52/2.53)
!> craig_torques   the torques alone
!> inverse_kin     closed-form IK on a chosen elbow branch, with per-row status
!> design_indices  robustness indices RI1, RI2, RI3 (2.19, 2.25, 2.26) of designs for
!>                 a workspace of points, and whether each design reaches every point
!> position_errors positioning error of the workspace points for sampled link-length
!>                 errors at fixed joint angles (exactly linear in the errors)
module manipulator
  use kinds, only: dp
  implicit none
  private
  public :: arm_states, craig_torques, inverse_kin, design_indices, position_errors

  !> status codes shared with driver/manipulator.py
  integer, parameter, public :: st_ok = 0, st_unreachable = 1, st_degenerate = 2

contains

  !> Jacobian J (row-major in jac(:,1..4) = J11, J12, J21, J22), w = |det J| = l1 l2 |s2|,
  !> kappa = sigma_max / sigma_min (0 where J is singular: caller marks it), and joint
  !> torques tau(:,1..2) [N m] of Craig's point-mass 2R arm (masses m1, m2 [kg] at the
  !> link ends), joint rates qd(:,1..2) [rad/s], accelerations qdd(:,1..2) [rad/s^2],
  !> gravity g [m/s^2] along -y.
  subroutine arm_states(n, l1, l2, th1, th2, qd, qdd, m1, m2, g, jac, w, kappa, tau)
    integer, intent(in) :: n
    real(dp), intent(in) :: l1(n), l2(n), th1(n), th2(n), qd(n, 2), qdd(n, 2), m1(n), m2(n), g
    real(dp), intent(out) :: jac(n, 4), w(n), kappa(n), tau(n, 2)
    real(dp) :: s1, c1, s2, c2, s12, c12, a, b, c, d, t, det, disc
    integer :: k
    !f2py threadsafe
    do k = 1, n
      s1 = sin(th1(k)); c1 = cos(th1(k))
      s2 = sin(th2(k)); c2 = cos(th2(k))
      s12 = s1*c2 + c1*s2; c12 = c1*c2 - s1*s2
      a = -l1(k)*s1 - l2(k)*s12; b = -l2(k)*s12
      c = l1(k)*c1 + l2(k)*c12;  d = l2(k)*c12
      jac(k, 1) = a; jac(k, 2) = b; jac(k, 3) = c; jac(k, 4) = d
      det = abs(a*d - b*c)
      w(k) = det
      t = a*a + b*b + c*c + d*d
      disc = sqrt(max(t*t - 4.0_dp*det*det, 0.0_dp))
      if (det > 0.0_dp) then
        kappa(k) = (t + disc)/(2.0_dp*det)
      else
        kappa(k) = 0.0_dp
      end if
      call torque_one(l1(k), l2(k), m1(k), m2(k), g, c1, s2, c2, c12, qd(k, 1), qd(k, 2), &
                      qdd(k, 1), qdd(k, 2), tau(k, 1), tau(k, 2))
    end do
  end subroutine arm_states

  !> Torques alone (same model and units as arm_states).
  subroutine craig_torques(n, l1, l2, th1, th2, qd, qdd, m1, m2, g, tau)
    integer, intent(in) :: n
    real(dp), intent(in) :: l1(n), l2(n), th1(n), th2(n), qd(n, 2), qdd(n, 2), m1(n), m2(n), g
    real(dp), intent(out) :: tau(n, 2)
    real(dp) :: s1, c1, s2, c2, c12
    integer :: k
    !f2py threadsafe
    do k = 1, n
      s1 = sin(th1(k)); c1 = cos(th1(k))
      s2 = sin(th2(k)); c2 = cos(th2(k))
      c12 = c1*c2 - s1*s2
      call torque_one(l1(k), l2(k), m1(k), m2(k), g, c1, s2, c2, c12, qd(k, 1), qd(k, 2), &
                      qdd(k, 1), qdd(k, 2), tau(k, 1), tau(k, 2))
    end do
  end subroutine craig_torques

  !> Report eqs (2.52)/(2.53) = Craig (1989) eq. 6.60, point masses at the link ends.
  pure subroutine torque_one(l1, l2, m1, m2, g, c1, s2, c2, c12, qd1, qd2, qdd1, qdd2, tau1, tau2)
    real(dp), intent(in) :: l1, l2, m1, m2, g, c1, s2, c2, c12, qd1, qd2, qdd1, qdd2
    real(dp), intent(out) :: tau1, tau2
    real(dp) :: m2l1l2
    m2l1l2 = m2*l1*l2
    tau1 = m2*l2*l2*(qdd1 + qdd2) + m2l1l2*c2*(2.0_dp*qdd1 + qdd2) + (m1 + m2)*l1*l1*qdd1 &
           - m2l1l2*s2*qd2*qd2 - 2.0_dp*m2l1l2*s2*qd1*qd2 + m2*l2*g*c12 + (m1 + m2)*l1*g*c1
    tau2 = m2l1l2*c2*qdd1 + m2l1l2*s2*qd1*qd1 + m2*l2*g*c12 + m2*l2*l2*(qdd1 + qdd2)
  end subroutine torque_one

  !> Inverse kinematics of target (x, y) for arm (l1, l2) on elbow branch (+1: th2 >= 0,
  !> -1: th2 <= 0).  Angles in radians, th1 in (-pi, pi].  status 1: out of reach
  !> (|c2| > 1 beyond 1e-12, angles 0); 2: degenerate (a link of zero length or the
  !> target at the base, angles 0).
  subroutine inverse_kin(n, l1, l2, x, y, branch, th1, th2, status)
    integer, intent(in) :: n, branch
    real(dp), intent(in) :: l1(n), l2(n), x(n), y(n)
    real(dp), intent(out) :: th1(n), th2(n)
    integer, intent(out) :: status(n)
    real(dp) :: c2, s2, sgn
    integer :: k
    sgn = 1.0_dp
    if (branch < 0) sgn = -1.0_dp
    do k = 1, n
      th1(k) = 0.0_dp; th2(k) = 0.0_dp; status(k) = st_ok
      if (l1(k) <= 0.0_dp .or. l2(k) <= 0.0_dp .or. (x(k) == 0.0_dp .and. y(k) == 0.0_dp)) then
        status(k) = st_degenerate
        cycle
      end if
      c2 = (x(k)**2 + y(k)**2 - l1(k)**2 - l2(k)**2)/(2.0_dp*l1(k)*l2(k))
      if (abs(c2) > 1.0_dp + 1.0e-12_dp) then
        status(k) = st_unreachable
        cycle
      end if
      c2 = max(-1.0_dp, min(1.0_dp, c2))
      s2 = sgn*sqrt(max(0.0_dp, 1.0_dp - c2*c2))
      th2(k) = atan2(s2, c2)
      th1(k) = atan2(y(k), x(k)) - atan2(l2(k)*s2, l1(k) + l2(k)*c2)
      if (th1(k) <= -acos(-1.0_dp)) th1(k) = th1(k) + 2.0_dp*acos(-1.0_dp)
      if (th1(k) > acos(-1.0_dp)) th1(k) = th1(k) - 2.0_dp*acos(-1.0_dp)
    end do
  end subroutine inverse_kin

  !> Robustness indices of nd designs (l1, l2) for the npt workspace points (x, y).
  !> Sensitivity Jacobian J_x (2 npt x 2, eqs 2.22/2.23) gives S = J_x^T J_x =
  !> [[npt, sum c2], [sum c2, npt]] with c2_i = (d_i^2 - l1^2 - l2^2)/(2 l1 l2) (any
  !> elbow branch), so sigma_max^2 = npt + |sum c2|, sigma_min^2 = npt - |sum c2|.
  !> ri(:,1) = RI1 = sigma_max/sigma_min (0 where sigma_min = 0), ri(:,2) = RI2 = sigma_max
  !> (eq. 2.25, the algebraic expression, also evaluated off the reachable set),
  !> ri(:,3) = RI3 = sigma_max + ||J_x||_F.  sumc2(:) = sum c2.  reach(:) = 1 when the
  !> design reaches every point (|l1 - l2| <= d_i <= l1 + l2), else 0.
  subroutine design_indices(npt, x, y, nd, l1, l2, ri, sumc2, reach)
    integer, intent(in) :: npt, nd
    real(dp), intent(in) :: x(npt), y(npt), l1(nd), l2(nd)
    real(dp), intent(out) :: ri(nd, 3), sumc2(nd)
    integer, intent(out) :: reach(nd)
    real(dp) :: d2, sc, smax2, smin2, tol
    integer :: i, k
    !f2py threadsafe
    do k = 1, nd
      sc = 0.0_dp
      reach(k) = 1
      do i = 1, npt
        d2 = x(i)**2 + y(i)**2
        sc = sc + (d2 - l1(k)**2 - l2(k)**2)/(2.0_dp*l1(k)*l2(k))
        tol = 1.0e-12_dp*max(1.0_dp, d2)
        if (d2 < (l1(k) - l2(k))**2 - tol .or. d2 > (l1(k) + l2(k))**2 + tol) reach(k) = 0
      end do
      sumc2(k) = sc
      smax2 = real(npt, dp) + abs(sc)
      smin2 = real(npt, dp) - abs(sc)
      ri(k, 2) = sqrt(smax2)
      if (smin2 > 0.0_dp) then
        ri(k, 1) = sqrt(smax2/smin2)
      else
        ri(k, 1) = 0.0_dp
      end if
      ri(k, 3) = sqrt(smax2) + sqrt(2.0_dp*real(npt, dp))
    end do
  end subroutine design_indices

  !> Positioning errors for ns sampled link-length errors dl(:,1..2) of an arm held at
  !> the nominal joint angles (th1, th2) of the npt workspace points.  The error at point
  !> i is dl1 (c1i, s1i) + dl2 (c12i, s12i) (exact: e is linear in l at fixed angles).
  !> err(:,1) = global norm ||J_x dl||_2 over all points stacked (Caro's measure),
  !> err(:,2) = largest error at any single point.
  subroutine position_errors(npt, th1, th2, ns, dl, err)
    integer, intent(in) :: npt, ns
    real(dp), intent(in) :: th1(npt), th2(npt), dl(ns, 2)
    real(dp), intent(out) :: err(ns, 2)
    real(dp) :: u1x(npt), u1y(npt), u2x(npt), u2y(npt), ex, ey, e2, tot, big
    integer :: i, k
    !f2py threadsafe
    do i = 1, npt
      u1x(i) = cos(th1(i)); u1y(i) = sin(th1(i))
      u2x(i) = cos(th1(i) + th2(i)); u2y(i) = sin(th1(i) + th2(i))
    end do
    do k = 1, ns
      tot = 0.0_dp
      big = 0.0_dp
      do i = 1, npt
        ex = dl(k, 1)*u1x(i) + dl(k, 2)*u2x(i)
        ey = dl(k, 1)*u1y(i) + dl(k, 2)*u2y(i)
        e2 = ex*ex + ey*ey
        tot = tot + e2
        big = max(big, e2)
      end do
      err(k, 1) = sqrt(tot)
      err(k, 2) = sqrt(big)
    end do
  end subroutine position_errors

end module manipulator
