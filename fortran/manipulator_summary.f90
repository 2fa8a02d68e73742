!> Design summaries of many 2R arms in one call ([Ma'arif 2006], chapter 4): what a sweep or
!> an optimiser of &manipulator designs needs, for nd designs against one workspace of npt
!> points, without building a single table.
!>
!> Per design (l1, l2) [m] it composes the routines of module manipulator, so the physics
!> lives once and the figures are the ones a single run prints:
!>   design_indices  RI1, RI2, RI3, sum c2 and the reach conditions (4.4) over the workspace;
!>   inverse_kin     the joint angles at the design's target point on the elbow branch;
!>   torque_block    Craig's point-mass torques (2.52)/(2.53) at those angles, fed the
!>                   angles through degrees as the single run does (same bits);
!> and in closed form the tolerance box of Caro's formulation and its Monte Carlo check:
!>   with c2_i = cos(th2_i) at workspace point i the sensitivity blocks J_xi have unit
!>   columns, so S = sum J_xi^T J_xi = [[n, C], [C, n]] with C = sum c2_i (global measure)
!>   and S_i = [[1, c2_i], [c2_i, 1]] (per point).  The largest box is then
!>   dl1 = dl2 = eps / sqrt(2 (n + |C|))            (global)
!>   dl1 = dl2 = eps / sqrt(2 (1 + max_i |c2_i|))  (per point),
!>   and the error of a link-length error (a, b) is sqrt(n (a^2 + b^2) + 2 a b C) (global) or
!>   max_i sqrt(a^2 + b^2 + 2 a b c2_i) (per point, the extreme c2_i by the sign of a b):
!>   the Monte Carlo maximum over the shared unit samples costs a few flops per sample.
module manipulator_summary
  use kinds, only: dp
  use manipulator, only: design_indices, inverse_kin, block_trig, torque_block, st_ok
  implicit none
  private
  public :: design_summaries
  !> passes of design_summaries (bits): indices res(:, 1:5), target res(:, 6:10),
  !> tolerance box res(:, 11:14)
  integer, parameter, public :: ds_indices = 1, ds_target = 2, ds_tolerance = 4

  !> numpy's rad2deg / deg2rad constants (x * (180/pi), x * (pi/180)): the single run
  !> converts the IK angles to degrees and back before the torques
  real(dp), parameter :: pi = 3.141592653589793238462643383279502884_dp
  real(dp), parameter :: r2d = 180.0_dp/pi, d2r = pi/180.0_dp
  integer, parameter :: nb = 256           ! designs per block (block_trig / torque_block size)
  !> how far |c2| may exceed 1 and the point still count as reached (as inverse_kin)
  real(dp), parameter :: reach_tol = 1.0e-12_dp

contains

  !> Summaries of nd designs for the workspace points (x, y) [m].
  !> params(:, 1:2) l1, l2 [m] (positive)   params(:, 3:4) target point x, y [m]
  !> params(:, 5)   mass per length [kg/m] (m_i = value * l_i)   params(:, 6) g [m/s^2] along -y
  !> params(:, 7)   tolerance bound eps [m]
  !> branch: elbow branch of the IK (+1: th2 >= 0, -1: th2 <= 0); rates = (th1', th2' [rad/s],
  !> th1'', th2'' [rad/s^2]); measure 0: global error (Caro), 1: largest error at a point;
  !> unit(ns, 2): Monte Carlo samples in [-1, 1]^2 (the box is unit * dl).
  !> res(:, 1:3) RI1 (0 where sigma_min = 0), RI2, RI3     res(:, 4) sum c2 (design_indices)
  !> res(:, 5)   1 if the design meets the reach conditions at every point, else 0
  !> res(:, 6)   IK status at the target (st_ok = 0)       res(:, 7:8) th1, th2 there [deg]
  !> res(:, 9:10) tau1, tau2 [N m] at the target (0 where the status is not ok)
  !> res(:, 11)  1 if the IK reaches every workspace point (the tolerance box exists)
  !> res(:, 12:13) tolerance half-widths dl1, dl2 [m]      res(:, 14) Monte Carlo max error [m]
  !> (res(:, 12:14) are 0 where res(:, 11) = 0)
  !> passes: sum of ds_* bits; the columns of a pass not asked for are 0 (not computed).
  subroutine design_summaries(npt, x, y, nd, params, branch, rates, measure, ns, unit, passes, res)
    !f2py threadsafe
    integer, intent(in) :: npt, nd, branch, measure, ns, passes
    real(dp), intent(in) :: x(npt), y(npt), params(nd, 7), rates(4), unit(ns, 2)
    real(dp), intent(out) :: res(nd, 14)
    integer, allocatable :: reach(:), status(:)
    real(dp), allocatable :: csum(:), cmax(:), cmin(:), bad(:)
    real(dp) :: sc(nb, 4), a1(nb), a2(nb), m1(nb), m2(nb), gb(nb), qd1(nb), qd2(nb), qdd1(nb), qdd2(nb)
    real(dp) :: d2, c2, cc, tol1, fn
    integer :: i, k, k0, m
    allocate(reach(nd), status(nd), csum(nd), cmax(nd), cmin(nd), bad(nd))
    res = 0.0_dp
    ! robustness indices and the reach conditions (4.4)
    if (iand(passes, ds_indices) /= 0) then
      call design_indices(npt, x, y, nd, params(:, 1), params(:, 2), res(:, 1:3), res(:, 4), reach)
      res(:, 5) = real(reach, dp)
    end if
    ! joint angles at the target, then the torques block by block
    if (iand(passes, ds_target) /= 0) then
      call inverse_kin(nd, params(:, 1), params(:, 2), params(:, 3), params(:, 4), branch, &
                       res(:, 7), res(:, 8), status)
      res(:, 6) = real(status, dp)
      qd1 = rates(1); qd2 = rates(2); qdd1 = rates(3); qdd2 = rates(4)
      do k0 = 1, nd, nb
        m = min(nb, nd - k0 + 1)
        ! hot-loop: manipulator_summary angles and masses
        do i = 1, m
          k = k0 + i - 1
          res(k, 7) = res(k, 7)*r2d
          res(k, 8) = res(k, 8)*r2d
          a1(i) = res(k, 7)*d2r
          a2(i) = res(k, 8)*d2r
          m1(i) = params(k, 5)*params(k, 1)
          m2(i) = params(k, 5)*params(k, 2)
          gb(i) = params(k, 6)
        end do
        call block_trig(m, a1(1:m), a2(1:m), sc)
        call torque_block(m, params(k0:k0 + m - 1, 1), params(k0:k0 + m - 1, 2), m1(1:m), m2(1:m), gb(1:m), sc, &
                          qd1(1:m), qd2(1:m), qdd1(1:m), qdd2(1:m), res(k0:k0 + m - 1, 9), res(k0:k0 + m - 1, 10))
      end do
      where (status /= st_ok)
        res(:, 9) = 0.0_dp
        res(:, 10) = 0.0_dp
      end where
    end if
    ! the tolerance box where the design reaches every workspace point, and its Monte Carlo check
    if (iand(passes, ds_tolerance) /= 0) then
      ! the IK at every workspace point: reached or not, and c2_i = cos(th2_i) (clipped as inverse_kin)
      csum = 0.0_dp
      cmax = -1.0_dp
      cmin = 1.0_dp
      bad = 0.0_dp
      do i = 1, npt
        d2 = x(i)**2 + y(i)**2
        ! hot-loop: manipulator_summary workspace ik
        do k = 1, nd
          c2 = (d2 - params(k, 1)**2 - params(k, 2)**2)/(2.0_dp*params(k, 1)*params(k, 2))
          bad(k) = max(bad(k), merge(1.0_dp, 0.0_dp, abs(c2) > 1.0_dp + reach_tol))
          cc = max(-1.0_dp, min(1.0_dp, c2))
          csum(k) = csum(k) + cc
          cmax(k) = max(cmax(k), cc)
          cmin(k) = min(cmin(k), cc)
        end do
      end do
      ! the largest tolerance box (closed form) where the design reaches every point
      fn = real(npt, dp)
      ! hot-loop: manipulator_summary tolerance box
      do k = 1, nd
        res(k, 11) = 1.0_dp - bad(k)
        if (measure == 0) then
          tol1 = params(k, 7)/sqrt(2.0_dp*(fn + abs(csum(k))))
        else
          tol1 = params(k, 7)/sqrt(2.0_dp*(1.0_dp + max(abs(cmax(k)), abs(cmin(k)))))
        end if
        res(k, 12) = merge(tol1, 0.0_dp, bad(k) == 0.0_dp)
        res(k, 13) = res(k, 12)
      end do
      ! Monte Carlo: largest error over the samples, designs in blocks (the block's data stays
      ! in cache while the samples stream past; the inner loop runs across designs)
      do k0 = 1, nd, nb
        m = min(nb, nd - k0 + 1)
        if (measure == 0) then
          call mc_global(m, ns, unit, fn, res(k0:k0 + m - 1, 12), res(k0:k0 + m - 1, 13), csum(k0:k0 + m - 1), &
                         res(k0:k0 + m - 1, 14))
        else
          call mc_point(m, ns, unit, res(k0:k0 + m - 1, 12), res(k0:k0 + m - 1, 13), cmax(k0:k0 + m - 1), &
                        cmin(k0:k0 + m - 1), res(k0:k0 + m - 1, 14))
        end if
      end do
    end if
    deallocate(reach, status, csum, cmax, cmin, bad)
  end subroutine design_summaries

  !> Largest global error sqrt(n (a^2 + b^2) + 2 a b C), (a, b) = unit(k, :) * (dl1, dl2),
  !> over the ns samples, for m designs.
  subroutine mc_global(m, ns, unit, fn, dl1, dl2, csum, emax)
    integer, intent(in) :: m, ns
    real(dp), intent(in) :: unit(ns, 2), fn, dl1(m), dl2(m), csum(m)
    real(dp), intent(out) :: emax(m)
    real(dp) :: q(m), a, b
    integer :: j, k
    q = 0.0_dp
    do k = 1, ns
      ! hot-loop: manipulator_summary monte carlo global
      do j = 1, m
        a = unit(k, 1)*dl1(j)
        b = unit(k, 2)*dl2(j)
        q(j) = max(q(j), fn*(a*a + b*b) + 2.0_dp*csum(j)*a*b)
      end do
    end do
    emax = sqrt(q)
  end subroutine mc_global

  !> Largest error at a single point, max_i sqrt(a^2 + b^2 + 2 a b c2_i), over the samples.
  subroutine mc_point(m, ns, unit, dl1, dl2, cmax, cmin, emax)
    integer, intent(in) :: m, ns
    real(dp), intent(in) :: unit(ns, 2), dl1(m), dl2(m), cmax(m), cmin(m)
    real(dp), intent(out) :: emax(m)
    real(dp) :: q(m), a, b, ab
    integer :: j, k
    q = 0.0_dp
    do k = 1, ns
      ! hot-loop: manipulator_summary monte carlo per point
      do j = 1, m
        a = unit(k, 1)*dl1(j)
        b = unit(k, 2)*dl2(j)
        ab = a*b
        q(j) = max(q(j), a*a + b*b + 2.0_dp*max(ab*cmax(j), ab*cmin(j)))   ! the extreme c2_i by the sign of a b
      end do
    end do
    emax = sqrt(q)
  end subroutine mc_point

end module manipulator_summary
