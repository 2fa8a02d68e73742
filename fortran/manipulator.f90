!> Planar 2R manipulator kernels ([Ma'arif 2006], robust dimensional synthesis, chapter 4).
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
  use vecmath, only: sincos_array
  implicit none
  private
  public :: arm_states, craig_torques, inverse_kin, design_indices, position_errors
  public :: block_trig, torque_block   ! blocks of the batch routines (fortran/manipulator_summary.f90)

  !> status codes shared with driver/manipulator.py
  integer, parameter, public :: st_ok = 0, st_unreachable = 1, st_degenerate = 2

contains

  !> Jacobian J (row-major in jac(:,1..4) = J11, J12, J21, J22), w = |det J| = l1 l2 |s2|,
  !> kappa = sigma_max / sigma_min (0 where J is singular: caller marks it), and joint
  !> torques tau(:,1..2) [N m] of Craig's point-mass 2R arm (masses m1, m2 [kg] at the
  !> link ends), joint rates qd(:,1..2) [rad/s], accelerations qdd(:,1..2) [rad/s^2],
  !> gravity g [m/s^2] along -y.
  !> Processed in blocks of nb configurations: sin/cos of a block by vecmath, then
  !> call-free loops (vectorised by construction).  The outputs are overwritten (intent
  !> inout, so callers can reuse buffers and skip the page faults of fresh arrays).
  subroutine arm_states(n, l1, l2, th1, th2, qd, qdd, m1, m2, g, jac, w, kappa, tau)
    integer, intent(in) :: n
    real(dp), intent(in) :: l1(n), l2(n), th1(n), th2(n), qd(n, 2), qdd(n, 2), m1(n), m2(n), g
    real(dp), intent(inout) :: jac(n, 4), w(n), kappa(n), tau(n, 2)   ! overwritten (reusable buffers)
    !f2py intent(in,out) :: jac, w, kappa, tau
    integer, parameter :: nb = 256
    real(dp) :: sc(nb, 4), s12, c12, a, b, c, d, t, det, disc, gb(nb)
    integer :: k, k0, m, i
    !f2py threadsafe
    gb = g
    do k0 = 1, n, nb
      m = min(nb, n - k0 + 1)
      call block_trig(m, th1(k0:k0 + m - 1), th2(k0:k0 + m - 1), sc)
      ! hot-loop: manipulator arm_states
      do i = 1, m
        k = k0 + i - 1
        s12 = sc(i, 1)*sc(i, 4) + sc(i, 2)*sc(i, 3)
        c12 = sc(i, 2)*sc(i, 4) - sc(i, 1)*sc(i, 3)
        a = -l1(k)*sc(i, 1) - l2(k)*s12; b = -l2(k)*s12
        c = l1(k)*sc(i, 2) + l2(k)*c12;  d = l2(k)*c12
        jac(k, 1) = a; jac(k, 2) = b; jac(k, 3) = c; jac(k, 4) = d
        det = abs(a*d - b*c)
        w(k) = det
        t = a*a + b*b + c*c + d*d
        disc = sqrt(max(t*t - 4.0_dp*det*det, 0.0_dp))
        kappa(k) = merge((t + disc)/(2.0_dp*merge(det, 1.0_dp, det > 0.0_dp)), 0.0_dp, det > 0.0_dp)
      end do
      call torque_block(m, l1(k0:k0 + m - 1), l2(k0:k0 + m - 1), m1(k0:k0 + m - 1), m2(k0:k0 + m - 1), &
                        gb(1:m), sc, qd(k0:k0 + m - 1, 1), qd(k0:k0 + m - 1, 2), qdd(k0:k0 + m - 1, 1), &
                        qdd(k0:k0 + m - 1, 2), tau(k0:k0 + m - 1, 1), tau(k0:k0 + m - 1, 2))
    end do
  end subroutine arm_states

  !> Torques alone (same model and units as arm_states).
  subroutine craig_torques(n, l1, l2, th1, th2, qd, qdd, m1, m2, g, tau)
    integer, intent(in) :: n
    real(dp), intent(in) :: l1(n), l2(n), th1(n), th2(n), qd(n, 2), qdd(n, 2), m1(n), m2(n), g
    real(dp), intent(out) :: tau(n, 2)
    integer, parameter :: nb = 256
    real(dp) :: sc(nb, 4), gb(nb)
    integer :: k0, m
    !f2py threadsafe
    gb = g
    do k0 = 1, n, nb
      m = min(nb, n - k0 + 1)
      call block_trig(m, th1(k0:k0 + m - 1), th2(k0:k0 + m - 1), sc)
      call torque_block(m, l1(k0:k0 + m - 1), l2(k0:k0 + m - 1), m1(k0:k0 + m - 1), m2(k0:k0 + m - 1), &
                        gb(1:m), sc, qd(k0:k0 + m - 1, 1), qd(k0:k0 + m - 1, 2), qdd(k0:k0 + m - 1, 1), &
                        qdd(k0:k0 + m - 1, 2), tau(k0:k0 + m - 1, 1), tau(k0:k0 + m - 1, 2))
    end do
  end subroutine craig_torques

  !> sc(:, 1..4) = sin th1, cos th1, sin th2, cos th2 of one block (m <= 256).
  subroutine block_trig(m, th1, th2, sc)
    integer, intent(in) :: m
    real(dp), intent(in) :: th1(m), th2(m)
    real(dp), intent(out) :: sc(256, 4)
    call sincos_array(m, th1, sc(:, 1), sc(:, 2))
    call sincos_array(m, th2, sc(:, 3), sc(:, 4))
  end subroutine block_trig

  !> Report eqs (2.52)/(2.53) = Craig (1989) eq. 6.60, point masses at the link ends, for
  !> one block of m <= 256 configurations with sines and cosines sc from block_trig
  !> (g(m) per configuration: the batch summaries vary it by design).
  subroutine torque_block(m, l1, l2, m1, m2, g, sc, qd1, qd2, qdd1, qdd2, tau1, tau2)
    integer, intent(in) :: m
    real(dp), intent(in) :: l1(m), l2(m), m1(m), m2(m), g(m), sc(256, 4), qd1(m), qd2(m), qdd1(m), qdd2(m)
    real(dp), intent(out) :: tau1(m), tau2(m)
    real(dp) :: m2l1l2, c1, s2, c2, c12
    integer :: k
    ! hot-loop: manipulator torque_block
    do k = 1, m
      c1 = sc(k, 2)
      s2 = sc(k, 3)
      c2 = sc(k, 4)
      c12 = c1*c2 - sc(k, 1)*s2
      m2l1l2 = m2(k)*l1(k)*l2(k)
      tau1(k) = m2(k)*l2(k)*l2(k)*(qdd1(k) + qdd2(k)) + m2l1l2*c2*(2.0_dp*qdd1(k) + qdd2(k)) &
                + (m1(k) + m2(k))*l1(k)*l1(k)*qdd1(k) - m2l1l2*s2*qd2(k)*qd2(k) &
                - 2.0_dp*m2l1l2*s2*qd1(k)*qd2(k) + m2(k)*l2(k)*g(k)*c12 + (m1(k) + m2(k))*l1(k)*g(k)*c1
      tau2(k) = m2l1l2*c2*qdd1(k) + m2l1l2*s2*qd1(k)*qd1(k) + m2(k)*l2(k)*g(k)*c12 &
                + m2(k)*l2(k)*l2(k)*(qdd1(k) + qdd2(k))
    end do
  end subroutine torque_block

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
    real(dp) :: d2, sc, smax2, smin2, tol, lo2, hi2, out(nd)
    integer :: i, k
    !f2py threadsafe
    ! points outer, designs inner: the inner loop runs across independent designs (it
    ! vectorises; each design's sum keeps its order over the points)
    sumc2 = 0.0_dp
    out = 0.0_dp
    do i = 1, npt
      d2 = x(i)**2 + y(i)**2
      tol = 1.0e-12_dp*max(1.0_dp, d2)
      ! hot-loop: manipulator design_indices
      do k = 1, nd
        sumc2(k) = sumc2(k) + (d2 - l1(k)**2 - l2(k)**2)/(2.0_dp*l1(k)*l2(k))
        lo2 = (l1(k) - l2(k))**2 - tol
        hi2 = (l1(k) + l2(k))**2 + tol
        out(k) = max(out(k), merge(1.0_dp, 0.0_dp, d2 < lo2 .or. d2 > hi2))
      end do
    end do
    ! hot-loop: manipulator design_indices ri
    do k = 1, nd
      sc = sumc2(k)
      smax2 = real(npt, dp) + abs(sc)
      smin2 = real(npt, dp) - abs(sc)
      ri(k, 2) = sqrt(smax2)
      ri(k, 1) = merge(sqrt(smax2/merge(smin2, 1.0_dp, smin2 > 0.0_dp)), 0.0_dp, smin2 > 0.0_dp)
      ri(k, 3) = sqrt(smax2) + sqrt(2.0_dp*real(npt, dp))
    end do
    reach = nint(1.0_dp - out)
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
    real(dp) :: u1x(npt), u1y(npt), u2x(npt), u2y(npt), ex, ey, e2
    integer :: i, k
    !f2py threadsafe
    do i = 1, npt
      u1x(i) = cos(th1(i)); u1y(i) = sin(th1(i))
      u2x(i) = cos(th1(i) + th2(i)); u2y(i) = sin(th1(i) + th2(i))
    end do
    ! points outer, samples inner (vectorises across samples; each sample's sum keeps
    ! its order over the points): err(:, 1) accumulates the squared norm, err(:, 2) the max
    err = 0.0_dp
    do i = 1, npt
      ! hot-loop: manipulator position_errors
      do k = 1, ns
        ex = dl(k, 1)*u1x(i) + dl(k, 2)*u2x(i)
        ey = dl(k, 1)*u1y(i) + dl(k, 2)*u2y(i)
        e2 = ex*ex + ey*ey
        err(k, 1) = err(k, 1) + e2
        err(k, 2) = max(err(k, 2), e2)
      end do
    end do
    err = sqrt(err)
  end subroutine position_errors

end module manipulator
