!> Hooke-joint (Cardan / universal-joint) shaft chains ([Fajar]: the "SSO" package).
!>
!> A chain of n joints joins n+1 shafts.  Joint k has the operating (bend) angle beta(k).
!> Angles are in radians throughout; speeds are dimensionless ratios omega_out/omega_in
!> (multiply by the input speed for rad/s or rpm), accelerations are d(ratio)/d(theta),
!> i.e. the output angular acceleration per omega_in**2 at constant input speed.
!>
!> Input angle convention: theta, the input yoke angle of joint 1, is measured from the
!> normal to the plane of the two shafts of joint 1 (the paper's eq. 5/8), so a single
!> joint gives  ratio = cos(beta)/(1 - sin(beta)**2 sin(theta)**2)  and
!> tan(theta_out) = cos(beta) tan(theta).
!>
!> Phase convention: phi(k) is the paper's phase of joint k+1 (90 deg = yokes on shaft k
!> in phase; the yoke phase delta = phi - 90 deg).  rho(k) is the signed angle between the
!> planes of joints k and k+1 about their shared shaft (0 for coplanar chains).  Arrays
!> phi and rho have n-1 entries (one per intermediate shaft; empty for a single joint).
!> Gradients are with respect to (beta(1..n), phi(1..n-1)): 2n-1 entries.
!>
!> Models (see docs/ujoint.md):
!>   model_eq13        the paper's eq. 13 as printed: joint k driven at theta + phi(k-1)
!>   model_cumulative  the paper's text: joint k driven at theta + phi(1) + ... + phi(k-1)
!>   model_exact       exact chain: theta(k+1) = theta_out(k) + phi(k) - rho(k), with
!>                     tan(theta_out(k)) = cos(beta(k)) tan(theta(k)); exact for
!>                     non-coplanar chains too (agrees with a 3-D vector model).
!>
!> chain_summaries evaluates many designs of one chain layout in one call (the batch path of
!> sweeps and optimisers) with the same procedures, so each row has a single design's bits.
!>
!> Internally the driving angle of each joint is carried as a unit complex number
!> (cos, sin), so the exact transfer needs one square root and no trigonometric call.
module ujoint
  use kinds, only: dp
  use vecmath, only: sincos_array, atan2_array
  implicit none
  private
  public :: chain_speed, chain_objective, chain_equivalent, chain_geometry, chain_summaries, chain_jet, &
            chain_roots, chain_input_torque

  !> model codes
  integer, parameter, public :: model_eq13 = 0, model_cumulative = 1, model_exact = 2
  !> objective codes: mean((R-1)**2), sqrt(mean((R-1)**2)), max(R) - min(R)
  integer, parameter, public :: obj_mean_square = 0, obj_rms = 1, obj_peak_to_peak = 2
  !> status codes of chain_equivalent (beta_res) and chain_geometry
  integer, parameter, public :: st_ok = 0, st_res_undefined = 1, st_zero_axis = 2, st_right_angle = 3
  !> result columns of chain_summaries
  integer, parameter, public :: nsum = 9
  !> passes of chain_summaries (bits)
  integer, parameter, public :: sum_objective = 1, sum_speed = 2, sum_equivalent = 4
  !> what chain_roots finds the roots of: R - 1 (speed ratio one), d2R/dtheta2 (extremes of the
  !> output acceleration), d T_in/d theta (extremes of the input torque of chain_input_torque)
  integer, parameter, public :: root_ratio_one = 1, root_accel_extreme = 2, root_torque_extreme = 3
  !> a chain whose ratio R stays within cv_tol of its range (max R - min R on the grid) turns its
  !> output uniformly but for round-off: its peak-acceleration angle and R = 1 angle are undefined
  real(dp), parameter, public :: cv_tol = 1.0e-13_dp
  !> root finding: bracket width [rad] and iteration cap of the Illinois regula falsi
  real(dp), parameter :: root_tol = 1.0e-12_dp
  integer, parameter :: root_maxit = 200

  real(dp), parameter :: pi = 3.14159265358979323846264338327950288_dp

contains

  !> Shift applied to the driving angle between joint k and joint k+1 (radians) and its
  !> derivative pattern: model_exact and model_cumulative shift by phi(k) (minus rho(k)
  !> for exact); model_eq13 by phi(k) - phi(k-1) (phi(0) = 0).
  subroutine shifts(model, n, phi, rho, cs, sn)
    integer, intent(in) :: model, n
    real(dp), intent(in) :: phi(n - 1), rho(n - 1)
    real(dp), intent(out) :: cs(n), sn(n)
    real(dp) :: s, prev
    integer :: k
    prev = 0.0_dp
    do k = 1, n - 1
      if (model == model_exact) then
        s = phi(k) - rho(k)
      else if (model == model_eq13) then
        s = phi(k) - prev
        prev = phi(k)
      else
        s = phi(k)
      end if
      cs(k) = cos(s)
      sn(k) = sin(s)
    end do
    cs(n) = 1.0_dp
    sn(n) = 0.0_dp
  end subroutine shifts

  !> Values (and optionally gradients) of ln R at m points given by (c, s) = (cos, sin) of
  !> the input angle.  rat(j) = R, dlth(j) = d ln R / d theta; if want_grad /= 0 also
  !> dlp(j, :) = d ln R / d(beta(1..n), phi(1..n-1)) (dlp is not set when want_grad = 0).
  !> thout(j): output angle of the last joint (exact model only; 0 otherwise) if want_out.
  subroutine propagate(model, n, beta, phi, rho, m, c0, s0, want_grad, want_out, &
                       rat, dlth, dlp, thout)
    integer, intent(in) :: model, n, m, want_grad, want_out
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), c0(m), s0(m)
    real(dp), intent(out) :: rat(m), dlth(m), dlp(m, 2*n - 1), thout(m)
    real(dp) :: c(m), s(m), dth(m), dtp(m, 2*n - 1), cn(m), sq(m)
    real(dp) :: cs(n), sn(n), cb, sb, s2, d, r, a, isd, x, y, tanb, ty(m), tx(m), ta(m), shift
    integer :: j, k, p
    logical :: exact

    exact = (model == model_exact)
    call shifts(model, n, phi, rho, cs, sn)
    c = c0
    s = s0
    rat = 1.0_dp
    dlth = 0.0_dp
    dth = 1.0_dp
    if (want_grad /= 0) then
      dlp = 0.0_dp
      dtp = 0.0_dp
    end if
    thout = 0.0_dp
    do k = 1, n
      cb = cos(beta(k))
      sb = sin(beta(k))
      s2 = sb*sb
      tanb = sb/cb
      ! hot-loop: ujoint propagate ratio
      do j = 1, m
        d = 1.0_dp - s2*s(j)*s(j)
        r = cb/d
        a = 2.0_dp*s2*s(j)*c(j)/d              ! d ln r / d theta_k
        rat(j) = rat(j)*r
        dlth(j) = dlth(j) + a*dth(j)
        sq(j) = d
        cn(j) = r
      end do
      if (want_grad /= 0) then
        do p = 1, 2*n - 1
          ! hot-loop: ujoint propagate grad chain
          do j = 1, m
            dlp(j, p) = dlp(j, p) + 2.0_dp*s2*s(j)*c(j)/sq(j)*dtp(j, p)
          end do
        end do
        ! hot-loop: ujoint propagate dbeta
        do j = 1, m                               ! d ln r / d beta_k
          dlp(j, k) = dlp(j, k) - tanb + 2.0_dp*sb*cb*s(j)*s(j)/sq(j)
        end do
      end if
      if (exact .and. want_out /= 0) then
        ! output angle of joint k minus its input angle, atan2 of the whole grid by vecmath
        ! hot-loop: ujoint propagate out-angle args
        do j = 1, m
          ty(j) = (cb - 1.0_dp)*s(j)*c(j)
          tx(j) = c(j)*c(j) + cb*s(j)*s(j)
        end do
        call atan2_array(m, ty, tx, ta)
        shift = 0.0_dp
        if (k < n) shift = atan2(sn(k), cs(k))
        ! hot-loop: ujoint propagate out-angle
        do j = 1, m
          thout(j) = thout(j) + ta(j) + shift
        end do
      end if
      if (k == n) exit
      ! transfer to joint k+1
      if (exact) then
        if (want_grad /= 0) then
          do p = 1, 2*n - 1
            ! hot-loop: ujoint propagate dtheta chain
            do j = 1, m
              dtp(j, p) = cn(j)*dtp(j, p)
            end do
          end do
          ! hot-loop: ujoint propagate dtheta dbeta
          do j = 1, m                             ! d theta_out / d beta_k
            dtp(j, k) = dtp(j, k) - sb*s(j)*c(j)/sq(j)
          end do
          ! hot-loop: ujoint propagate dtheta dphi
          do j = 1, m
            dtp(j, n + k) = dtp(j, n + k) + 1.0_dp
          end do
        end if
        ! hot-loop: ujoint propagate exact transfer
        do j = 1, m
          dth(j) = cn(j)*dth(j)
          isd = 1.0_dp/sqrt(sq(j))
          x = c(j)*isd
          y = cb*s(j)*isd
          c(j) = x*cs(k) - y*sn(k)
          s(j) = x*sn(k) + y*cs(k)
        end do
      else
        if (want_grad /= 0) then
          ! hot-loop: ujoint propagate dphi
          do j = 1, m
            dtp(j, n + k) = dtp(j, n + k) + 1.0_dp
          end do
          if (model == model_eq13 .and. k > 1) then
            ! hot-loop: ujoint propagate eq13 dphi
            do j = 1, m
              dtp(j, n + k - 1) = dtp(j, n + k - 1) - 1.0_dp
            end do
          end if
        end if
        ! hot-loop: ujoint propagate shift
        do j = 1, m
          x = c(j)
          y = s(j)
          c(j) = x*cs(k) - y*sn(k)
          s(j) = x*sn(k) + y*cs(k)
        end do
      end if
    end do
  end subroutine propagate

  !> Speed ratio R = omega_out/omega_in, dR/dtheta (output angular acceleration per
  !> omega_in**2 at constant input speed) and the output shaft angle (exact model; zero
  !> for the paper models, which do not define it) at input angles theta(1..m) [rad].
  subroutine chain_speed(model, n, beta, phi, rho, m, theta, ratio, dratio, thout)
    integer, intent(in) :: model, n, m
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), theta(m)
    real(dp), intent(out) :: ratio(m), dratio(m), thout(m)
    real(dp) :: dlth(m), dlp(m, 2*n - 1), c(m), s(m)
    !f2py threadsafe
    call sincos_array(m, theta, s, c)
    call propagate(model, n, beta, phi, rho, m, c, s, 0, 1, ratio, dlth, dlp, thout)
    dratio = ratio*dlth
    if (model == model_exact) thout = thout + theta
  end subroutine chain_speed

  !> Objective over a uniform grid of m input angles theta_j = 2 pi (j-1)/m covering one
  !> revolution, and (want_grad /= 0) its gradient with respect to beta(1..n) and
  !> phi(1..n-1); zeros when want_grad = 0.
  !> kind: obj_mean_square f = mean (R-1)**2 (the paper's U per omega_in**2),
  !>       obj_rms f = sqrt of that, obj_peak_to_peak f = max R - min R on the grid.
  !> R has period pi in theta, so for even m only the first m/2 points are evaluated;
  !> the result is identical to the full grid.
  subroutine chain_objective(model, kind, n, beta, phi, rho, m, want_grad, f, grad)
    integer, intent(in) :: model, kind, n, m, want_grad
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1)
    real(dp), intent(out) :: f, grad(2*n - 1)
    real(dp), allocatable :: c(:), s(:), rat(:), dlth(:), dlp(:, :), thout(:)
    integer :: mh, j, jmax, jmin, g
    !f2py threadsafe
    mh = m
    if (mod(m, 2) == 0) mh = m/2
    allocate (c(mh), s(mh), rat(mh), dlth(mh), thout(mh))
    ! the grid's angles (in thout, unused by the objective), then their sines and cosines
    ! in one vectorised pass (vecmath)
    ! hot-loop: ujoint objective grid
    do j = 1, mh
      thout(j) = (2.0_dp*pi/real(m, dp))*real(j - 1, dp)
    end do
    call sincos_array(mh, thout, s, c)
    g = 0
    if (want_grad /= 0 .and. kind /= obj_peak_to_peak) g = 1
    if (g == 1) then
      allocate (dlp(mh, 2*n - 1))
    else
      allocate (dlp(1, 1))
    end if
    if (g == 1) then
      call propagate(model, n, beta, phi, rho, mh, c, s, 1, 0, rat, dlth, dlp, thout)
    else
      call propagate_nograd(model, n, beta, phi, rho, mh, c, s, rat)
    end if
    grad = 0.0_dp
    f = objective_value(kind, mh, rat)
    if (want_grad == 0) return
    if (kind == obj_peak_to_peak) then
      jmax = maxloc(rat, 1)
      jmin = minloc(rat, 1)
      call p2p_grad(model, n, beta, phi, rho, c(jmax), s(jmax), c(jmin), s(jmin), grad)
      return
    end if
    do j = 1, 2*n - 1
      grad(j) = 2.0_dp*sum((rat - 1.0_dp)*rat*dlp(:, j))/real(mh, dp)
    end do
    if (kind == obj_rms) then
      if (f > 0.0_dp) then
        grad = grad/(2.0_dp*f)
      else
        grad = 0.0_dp
      end if
    end if
  end subroutine chain_objective

  !> Headline figures of nd designs of one chain layout in one call: the batch path of sweeps
  !> and optimisers (driver/ujoint summarise_batch).  The designs share the joint count n, the
  !> model, the objective kind and the grid of m input angles; design i is
  !> x(i, :) = beta(1..n), phi(1..n-1), rho(1..n-1) [rad] (3n-2 columns; phi and rho as in
  !> chain_speed).  Each row holds exactly what chain_objective (without gradient),
  !> chain_speed on theta_j = 2 pi (j-1)/m (j = 1..m) and chain_equivalent give for that
  !> design alone: the same procedures on the same grid, so the same bits.
  !>   res(i, 1)  objective of kind (dimensionless; over the first m/2 angles for even m)
  !>   res(i, 2:3) min and max of R = omega_out/omega_in on the grid
  !>   res(i, 4)  max |dR/dtheta| over the turn [1/rad] (times omega_in**2: peak output angular
  !>              acceleration at constant input speed): the grid's largest, refined where
  !>              d2R/dtheta2 changes sign between its neighbours (root to 1e-12 rad)
  !>   res(i, 5)  beta_e [rad]; res(i, 6) beta_res [rad], 0 unless res(i, 7) = st_ok
  !>   res(i, 7)  status of beta_res (chain_equivalent with tolerance tol [rad])
  !>   (a chain with max R - min R < cv_tol on the grid turns its output uniformly but for
  !>   round-off: res(i, 4) is the grid's largest and res(i, 8:9) are -1, undefined)
  !>   res(i, 8)  the input angle of res(i, 4) [rad, 0..2 pi, from the normal to joint 1's plane]:
  !>              of the grid angles within 1e-9 of the largest |dR/dtheta| (the peak's mirror
  !>              and half-turn images), the first from theta0 on
  !>   res(i, 9)  the first input angle from theta0 on [rad, 0..2 pi) where R = 1 (R has period
  !>              pi: the first sign change of R - 1 on theta0 + 2 pi j/m, j = 0..m/2, refined
  !>              to 1e-12 rad); -1 where R - 1 keeps its sign
  !> theta0 [rad] is the input angle the caller counts from (its angle origin).
  !> The sines and cosines of the grid are taken once for all designs.
  !> passes: sum of sum_* bits -- sum_objective (res(:, 1)), sum_speed (res(:, 2:4)),
  !> sum_equivalent (res(:, 5:7)); the columns of a pass not asked for are 0 (not computed);
  !> res(:, 8:9) belong to sum_speed.
  subroutine chain_summaries(model, kind, n, nd, x, m, tol, theta0, passes, res)
    integer, intent(in) :: model, kind, n, nd, m, passes
    real(dp), intent(in) :: x(nd, 3*n - 2), tol, theta0
    real(dp), intent(out) :: res(nd, 9)                ! nsum columns (literal for f2py)
    real(dp), allocatable :: th(:), c(:), s(:), rat(:), ratf(:), dlth(:), dlp(:, :), thout(:), acc(:)
    real(dp) :: beta(n), phi(n - 1), rho(n - 1), be, br, peak, at, one
    integer :: i, j, mh, st
    !f2py threadsafe
    mh = m
    if (mod(m, 2) == 0) mh = m/2
    allocate (th(m), c(m), s(m), rat(mh), ratf(m), dlth(m), dlp(m, 2*n - 1), thout(m), acc(m))
    ! the grid of chain_objective (its first mh angles) and of the speed table
    ! hot-loop: ujoint summaries grid
    do j = 1, m
      th(j) = (2.0_dp*pi/real(m, dp))*real(j - 1, dp)
    end do
    call sincos_array(m, th, s, c)
    do i = 1, nd
      beta = x(i, 1:n)
      phi = x(i, n + 1:2*n - 1)
      rho = x(i, 2*n:3*n - 2)
      res(i, :) = 0.0_dp
      if (iand(passes, sum_objective) /= 0) then
        call propagate_nograd(model, n, beta, phi, rho, mh, c(1:mh), s(1:mh), rat)
        res(i, 1) = objective_value(kind, mh, rat)
      end if
      if (iand(passes, sum_speed) /= 0) then
        call propagate(model, n, beta, phi, rho, m, c, s, 0, 0, ratf, dlth, dlp, thout)
        ! hot-loop: ujoint summaries acceleration
        do j = 1, m
          acc(j) = abs(ratf(j)*dlth(j))
        end do
        res(i, 2) = minval(ratf)
        res(i, 3) = maxval(ratf)
        if (res(i, 3) - res(i, 2) < cv_tol) then   ! a constant-velocity chain: no peak, R = 1 throughout
          res(i, 4) = maxval(acc)
          res(i, 8) = -1.0_dp
          res(i, 9) = -1.0_dp
        else
          call refine_peak(model, n, beta, phi, rho, m, th, acc, theta0, peak, at)
          res(i, 4) = peak
          res(i, 8) = at
          call first_ratio_one(model, n, beta, phi, rho, m, theta0, one)
          res(i, 9) = one
        end if
      end if
      if (iand(passes, sum_equivalent) /= 0) then
        call chain_equivalent(model, n, beta, phi, rho, tol, be, br, st)
        res(i, 5) = be
        res(i, 6) = br
        res(i, 7) = real(st, dp)
      end if
    end do
  end subroutine chain_summaries

  !> The objective of kind ``kind`` from the ratios rat(1..m) of a uniform grid: mean (R-1)**2,
  !> its root, or max R - min R (the one place both chain_objective and chain_summaries take it).
  pure function objective_value(kind, m, rat) result(f)
    integer, intent(in) :: kind, m
    real(dp), intent(in) :: rat(m)
    real(dp) :: f
    if (kind == obj_peak_to_peak) then
      f = maxval(rat) - minval(rat)
    else
      f = sum((rat - 1.0_dp)**2)/real(m, dp)
      if (kind == obj_rms) f = sqrt(f)
    end if
  end function objective_value

  !> Gradient of max R - min R from the two extreme grid points (ca, sa) and (cb, sb).
  subroutine p2p_grad(model, n, beta, phi, rho, ca, sa, cb, sb, grad)
    integer, intent(in) :: model, n
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), ca, sa, cb, sb
    real(dp), intent(out) :: grad(2*n - 1)
    real(dp) :: c2(2), s2(2), r2(2), dl2(2), dp2(2, 2*n - 1), th2(2)
    c2 = [ca, cb]
    s2 = [sa, sb]
    call propagate(model, n, beta, phi, rho, 2, c2, s2, 1, 0, r2, dl2, dp2, th2)
    grad = r2(1)*dp2(1, :) - r2(2)*dp2(2, :)
  end subroutine p2p_grad

  !> Ratio only (the hot path of the optimisers): rat(j) = R at (cos, sin) = (c0, s0).
  subroutine propagate_nograd(model, n, beta, phi, rho, m, c0, s0, rat)
    integer, intent(in) :: model, n, m
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), c0(m), s0(m)
    real(dp), intent(out) :: rat(m)
    real(dp) :: c(m), s(m), cs(n), sn(n), cb, s2, d, isd, x, y
    integer :: j, k
    call shifts(model, n, phi, rho, cs, sn)
    c = c0
    s = s0
    rat = 1.0_dp
    do k = 1, n
      cb = cos(beta(k))
      s2 = sin(beta(k))**2
      if (k == n) then
        ! hot-loop: ujoint nograd last joint
        do j = 1, m
          rat(j) = rat(j)*cb/(1.0_dp - s2*s(j)*s(j))
        end do
      else if (model == model_exact) then
        ! hot-loop: ujoint nograd exact transfer
        do j = 1, m
          d = 1.0_dp - s2*s(j)*s(j)
          isd = 1.0_dp/sqrt(d)
          rat(j) = rat(j)*cb*isd*isd
          x = c(j)*isd
          y = cb*s(j)*isd
          c(j) = x*cs(k) - y*sn(k)
          s(j) = x*sn(k) + y*cs(k)
        end do
      else
        ! hot-loop: ujoint nograd shift
        do j = 1, m
          rat(j) = rat(j)*cb/(1.0_dp - s2*s(j)*s(j))
          x = c(j)
          y = s(j)
          c(j) = x*cs(k) - y*sn(k)
          s(j) = x*sn(k) + y*cs(k)
        end do
      end if
    end do
  end subroutine propagate_nograd

  !> R = omega_out/omega_in (r0), dR/dtheta (r1, 1/rad) and d2R/dtheta2 (r2, 1/rad**2) at
  !> (cos, sin) = (c0, s0) of m input angles, in closed form: with theta_k the driving angle of
  !> joint k, ln R = sum_k ln r_k(theta_k), r_k = cos b_k / (1 - sin(b_k)**2 sin(theta_k)**2),
  !>   d ln r_k/d theta_k   = a_k = sin(b_k)**2 sin(2 theta_k) / d_k,  d_k = 1 - sin(b_k)**2 sin(theta_k)**2
  !>   d2 ln r_k/d theta_k2 = b_k = (2 sin(b_k)**2 cos(2 theta_k) d_k + (sin(b_k)**2 sin(2 theta_k))**2) / d_k**2
  !> and the driving angles' derivatives carried forward: the exact chain drives joint k+1 with
  !> joint k's output, theta'_(k+1) = r_k theta'_k, theta''_(k+1) = r_k a_k theta'_k**2 + r_k theta''_k;
  !> the paper's models with the input angle plus a phase (theta'_k = 1, theta''_k = 0).  Then
  !> R' = R (ln R)', R'' = R ((ln R)'**2 + (ln R)'').
  subroutine jet(model, n, beta, phi, rho, m, c0, s0, r0, r1, r2)
    integer, intent(in) :: model, n, m
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), c0(m), s0(m)
    real(dp), intent(out) :: r0(m), r1(m), r2(m)
    real(dp) :: c(m), s(m), t1(m), t2(m), l1(m), l2(m), cs(n), sn(n)
    real(dp) :: cb, s2, d, r, a, b, sc, cc, isd, x, y
    integer :: j, k
    call shifts(model, n, phi, rho, cs, sn)
    c = c0
    s = s0
    t1 = 1.0_dp
    t2 = 0.0_dp
    r0 = 1.0_dp
    l1 = 0.0_dp
    l2 = 0.0_dp
    do k = 1, n
      cb = cos(beta(k))
      s2 = sin(beta(k))**2
      do j = 1, m
        d = 1.0_dp - s2*s(j)*s(j)
        r = cb/d
        sc = 2.0_dp*s(j)*c(j)
        cc = c(j)*c(j) - s(j)*s(j)
        a = s2*sc/d
        b = (2.0_dp*s2*cc*d + (s2*sc)**2)/(d*d)
        r0(j) = r0(j)*r
        l1(j) = l1(j) + a*t1(j)
        l2(j) = l2(j) + b*t1(j)*t1(j) + a*t2(j)
        if (k == n) cycle
        if (model == model_exact) then
          t2(j) = r*a*t1(j)*t1(j) + r*t2(j)
          t1(j) = r*t1(j)
          isd = 1.0_dp/sqrt(d)
          x = c(j)*isd
          y = cb*s(j)*isd
        else
          x = c(j)
          y = s(j)
        end if
        c(j) = x*cs(k) - y*sn(k)
        s(j) = x*sn(k) + y*cs(k)
      end do
    end do
    r1 = r0*l1
    r2 = r0*(l1*l1 + l2)
  end subroutine jet

  !> R, dR/dtheta and d2R/dtheta2 (see jet) at input angles theta(1..m) [rad, from the normal to
  !> joint 1's plane]: the output angular velocity per omega_in, and at constant input speed the
  !> output acceleration per omega_in**2 and its rate per omega_in**3.
  subroutine chain_jet(model, n, beta, phi, rho, m, theta, r0, r1, r2)
    integer, intent(in) :: model, n, m
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), theta(m)
    real(dp), intent(out) :: r0(m), r1(m), r2(m)
    real(dp) :: c(m), s(m)
    !f2py threadsafe
    call sincos_array(m, theta, s, c)
    call jet(model, n, beta, phi, rho, m, c, s, r0, r1, r2)
  end subroutine chain_jet

  !> Input torque [N m] at constant input speed omega [rad/s] driving an output shaft of moment of
  !> inertia inertia [kg m**2] against a constant load torque load [N m] (resisting the output's
  !> rotation), the joints massless and frictionless: by power balance
  !>   T_in omega_in = (J alpha_out + T_load) omega_out,  so  T_in = (J omega**2 R' + T_load) R,
  !> at input angles theta(1..m) [rad]; dtorque = d T_in / d theta [N m/rad].
  subroutine chain_input_torque(model, n, beta, phi, rho, m, theta, omega, inertia, load, torque, dtorque)
    integer, intent(in) :: model, n, m
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), theta(m), omega, inertia, load
    real(dp), intent(out) :: torque(m), dtorque(m)
    real(dp) :: r0(m), r1(m), r2(m), jw2
    !f2py threadsafe
    call chain_jet(model, n, beta, phi, rho, m, theta, r0, r1, r2)
    jw2 = inertia*omega*omega
    torque = (jw2*r1 + load)*r0
    dtorque = jw2*(r2*r0 + r1*r1) + load*r1
  end subroutine chain_input_torque

  !> The function whose roots chain_roots finds, at (cos, sin) = (c0, s0) of m angles:
  !> root_ratio_one R - 1, root_accel_extreme R'', root_torque_extreme
  !> coef(1) (R'' R + R'**2) + coef(2) R' (coef = J omega**2 [kg m**2/s**2], T_load [N m]).
  subroutine root_function(model, n, beta, phi, rho, what, coef, m, c0, s0, f)
    integer, intent(in) :: model, n, what, m
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), coef(2), c0(m), s0(m)
    real(dp), intent(out) :: f(m)
    real(dp) :: r0(m), r1(m), r2(m)
    call jet(model, n, beta, phi, rho, m, c0, s0, r0, r1, r2)
    select case (what)
    case (root_ratio_one)
      f = r0 - 1.0_dp
    case (root_accel_extreme)
      f = r2
    case default
      f = coef(1)*(r2*r0 + r1*r1) + coef(2)*r1
    end select
  end subroutine root_function

  !> The root in [a, b] of the root function, whose values fa, fb at the ends differ in sign:
  !> Illinois regula falsi (a bisection step when a step stalls) to a bracket of root_tol [rad].
  real(dp) function bracketed_root(model, n, beta, phi, rho, what, coef, a, b, fa, fb) result(x)
    integer, intent(in) :: model, n, what
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), coef(2), a, b, fa, fb
    real(dp) :: xa, xb, ya, yb, fx(1), w
    integer :: it, side
    xa = a
    xb = b
    ya = fa
    yb = fb
    side = 0
    do it = 1, root_maxit
      w = xb - xa
      if (w <= root_tol) exit
      x = xb - yb*(xb - xa)/(yb - ya)
      if (.not. (x > xa .and. x < xb) .or. mod(it, 8) == 0) x = 0.5_dp*(xa + xb)
      call root_function(model, n, beta, phi, rho, what, coef, 1, [cos(x)], [sin(x)], fx)
      if (fx(1) == 0.0_dp) then
        xa = x
        xb = x
        exit
      end if
      if ((fx(1) > 0.0_dp) .eqv. (yb > 0.0_dp)) then
        xb = x
        yb = fx(1)
        if (side == 1) ya = 0.5_dp*ya
        side = 1
      else
        xa = x
        ya = fx(1)
        if (side == -1) yb = 0.5_dp*yb
        side = -1
      end if
    end do
    x = 0.5_dp*(xa + xb)
  end function bracketed_root

  !> Every root in [0, 2 pi) of the root function ``what`` (root_ratio_one, root_accel_extreme or
  !> root_torque_extreme; coef as root_function): each sign change between neighbours of the
  !> grid theta_j = 2 pi (j-1)/m (the last interval wrapping to 2 pi), refined to root_tol [rad]
  !> by bracketed_root, and each grid angle where the function is exactly 0; ascending, the
  !> first nroots entries of roots [rad] (two roots inside one grid interval are not seen).
  subroutine chain_roots(model, n, beta, phi, rho, what, coef, m, roots, nroots)
    integer, intent(in) :: model, n, what, m
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), coef(2)
    real(dp), intent(out) :: roots(m)
    integer, intent(out) :: nroots
    real(dp) :: th(m), c(m), s(m), f(m), a, b, fb, x
    integer :: j
    !f2py threadsafe
    do j = 1, m
      th(j) = (2.0_dp*pi/real(m, dp))*real(j - 1, dp)
    end do
    call sincos_array(m, th, s, c)
    call root_function(model, n, beta, phi, rho, what, coef, m, c, s, f)
    nroots = 0
    roots = 0.0_dp
    do j = 1, m
      a = th(j)
      if (j < m) then
        b = th(j + 1)
        fb = f(j + 1)
      else
        b = 2.0_dp*pi
        fb = f(1)
      end if
      if (f(j) == 0.0_dp) then
        x = a
      else if ((f(j) > 0.0_dp .and. fb < 0.0_dp) .or. (f(j) < 0.0_dp .and. fb > 0.0_dp)) then
        x = bracketed_root(model, n, beta, phi, rho, what, coef, a, b, f(j), fb)
        if (x >= 2.0_dp*pi) x = x - 2.0_dp*pi
      else
        cycle
      end if
      nroots = nroots + 1
      roots(nroots) = x
    end do
  end subroutine chain_roots

  !> The peak of |dR/dtheta| over the turn from its values acc(1..m) on the grid th: of the grid
  !> angles within 1e-9 of the largest (a peak's mirror and half-turn images), the first from
  !> theta0 on, refined where d2R/dtheta2 changes sign between its neighbours (bracketed_root);
  !> peak [1/rad] and its angle at [rad, 0..2 pi).
  subroutine refine_peak(model, n, beta, phi, rho, m, th, acc, theta0, peak, at)
    integer, intent(in) :: model, n, m
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), th(m), acc(m), theta0
    real(dp), intent(out) :: peak, at
    real(dp) :: h, a, b, f(2), x, r0(1), r1(1), r2(1), top, dist, best
    real(dp), parameter :: none(2) = 0.0_dp
    integer :: j, i
    top = maxval(acc)
    j = maxloc(acc, 1)
    best = 4.0_dp*pi
    do i = 1, m
      if (acc(i) < top*(1.0_dp - 1.0e-9_dp)) cycle
      dist = modulo(th(i) - theta0, 2.0_dp*pi)
      if (dist < best) then
        best = dist
        j = i
      end if
    end do
    peak = acc(j)
    at = th(j)
    if (m < 3 .or. peak == 0.0_dp) return
    h = 2.0_dp*pi/real(m, dp)
    a = th(j) - h
    b = th(j) + h
    call root_function(model, n, beta, phi, rho, root_accel_extreme, none, 2, [cos(a), cos(b)], &
                       [sin(a), sin(b)], f)
    if (.not. ((f(1) > 0.0_dp .and. f(2) < 0.0_dp) .or. (f(1) < 0.0_dp .and. f(2) > 0.0_dp))) return
    x = bracketed_root(model, n, beta, phi, rho, root_accel_extreme, none, a, b, f(1), f(2))
    call jet(model, n, beta, phi, rho, 1, [cos(x)], [sin(x)], r0, r1, r2)
    if (abs(r1(1)) >= peak) then
      peak = abs(r1(1))
      at = modulo(x, 2.0_dp*pi)
    end if
  end subroutine refine_peak

  !> The first input angle from theta0 on [rad, 0..2 pi) where R = 1: R has period pi, so the
  !> first sign change of R - 1 on the half-turn grid theta0 + 2 pi j/m (j = 0..ceiling(m/2)),
  !> refined by bracketed_root; -1 when there is none.
  subroutine first_ratio_one(model, n, beta, phi, rho, m, theta0, one)
    integer, intent(in) :: model, n, m
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), theta0
    real(dp), intent(out) :: one
    real(dp) :: t(m/2 + 2), c(m/2 + 2), s(m/2 + 2), f(m/2 + 2)
    real(dp), parameter :: none(2) = 0.0_dp
    integer :: j, mh
    mh = m/2 + 2
    do j = 1, mh
      t(j) = theta0 + (2.0_dp*pi/real(m, dp))*real(j - 1, dp)
    end do
    call sincos_array(mh, t, s, c)
    call root_function(model, n, beta, phi, rho, root_ratio_one, none, mh, c, s, f)
    one = -1.0_dp
    do j = 1, mh - 1
      if (f(j) == 0.0_dp) then
        one = modulo(t(j), 2.0_dp*pi)
        return
      end if
      if ((f(j) > 0.0_dp .and. f(j + 1) < 0.0_dp) .or. (f(j) < 0.0_dp .and. f(j + 1) > 0.0_dp)) then
        one = modulo(bracketed_root(model, n, beta, phi, rho, root_ratio_one, none, t(j), t(j + 1), &
                                    f(j), f(j + 1)), 2.0_dp*pi)
        return
      end if
    end do
  end subroutine first_ratio_one

  !> Closed-form equivalent angles [rad].
  !> beta_e: first-order residual angle, beta_e**2 = |sum_k beta_k**2 exp(2i gamma_k)| with
  !>   gamma_1 = 0 and gamma_{k+1} = gamma_k + (shift of the model); the ratio's
  !>   peak-to-peak is about beta_e**2.
  !> beta_res: the single Hooke joint that the EXACT chain equals when every shift between
  !>   successive joints (the model's: phi(k) - rho(k) exact, phi(k) cumulative,
  !>   phi(k) - phi(k-1) eq13) is a multiple of 90 deg (tolerance tol [rad]): the exact chain
  !>   with those shifts; cos(beta_res) = min(K, 1/K), K built
  !>   from the tan-law composition.  status = st_res_undefined (beta_res = 0) otherwise.
  subroutine chain_equivalent(model, n, beta, phi, rho, tol, beta_e, beta_res, status)
    integer, intent(in) :: model, n
    real(dp), intent(in) :: beta(n), phi(n - 1), rho(n - 1), tol
    real(dp), intent(out) :: beta_e, beta_res
    integer, intent(out) :: status
    real(dp) :: cs(n), sn(n), gam, re, im, kk, sh, q
    integer :: k
    call shifts(model, n, phi, rho, cs, sn)
    gam = 0.0_dp
    re = 0.0_dp
    im = 0.0_dp
    do k = 1, n
      re = re + beta(k)**2*cos(2.0_dp*gam)
      im = im + beta(k)**2*sin(2.0_dp*gam)
      gam = gam + atan2(sn(k), cs(k))
    end do
    beta_e = sqrt(sqrt(re*re + im*im))
    ! exact composition: tan t -> cos(beta) tan t, then a quarter-turn shift -> -1/tan
    status = st_ok
    kk = 1.0_dp
    do k = 1, n
      kk = kk*cos(beta(k))
      if (k == n) exit
      sh = atan2(sn(k), cs(k))           ! the model's shift between joints k and k+1
      q = sh/(0.5_dp*pi)
      if (abs(q - real(nint(q), dp))*0.5_dp*pi > tol) then
        status = st_res_undefined
        exit
      end if
      if (mod(abs(nint(q)), 2) == 1) kk = 1.0_dp/kk
    end do
    if (status == st_ok) then
      beta_res = acos(min(kk, 1.0_dp/kk))
    else
      beta_res = 0.0_dp
    end if
  end subroutine chain_equivalent

  !> Joint angles and plane angles of a 3-D chain from shaft direction vectors
  !> axes(:, 1..n+1) (input shaft first; any nonzero length).  beta(k) = angle between
  !> shafts k and k+1 [rad, 0..pi]; rho(k) = signed angle from the plane of joint k to that
  !> of joint k+1, right-handed about shaft k+1 (k = 1..n-1).  A straight joint (beta = 0)
  !> has no plane; it takes its neighbour's.  status: st_zero_axis if an axis has zero
  !> length, st_right_angle if a joint angle is 90 deg or more, else st_ok.
  subroutine chain_geometry(n, axes, beta, rho, status)
    integer, intent(in) :: n
    real(dp), intent(in) :: axes(3, n + 1)
    real(dp), intent(out) :: beta(n), rho(n - 1)
    integer, intent(out) :: status
    real(dp) :: a(3, n + 1), nrm(3, n), w(3), len
    logical :: has(n), got(n)
    integer :: k, kk
    status = st_ok
    beta = 0.0_dp
    rho = 0.0_dp
    do k = 1, n + 1
      len = sqrt(sum(axes(:, k)**2))
      if (len <= 0.0_dp) then
        status = st_zero_axis
        return
      end if
      a(:, k) = axes(:, k)/len
    end do
    do k = 1, n
      w = cross(a(:, k), a(:, k + 1))
      len = sqrt(sum(w**2))
      beta(k) = atan2(len, dot_product(a(:, k), a(:, k + 1)))
      has(k) = len > 1.0e-12_dp
      if (has(k)) then
        nrm(:, k) = w/len
      else
        nrm(:, k) = 0.0_dp
      end if
      if (beta(k) >= 0.5_dp*pi) status = st_right_angle
    end do
    ! straight joints borrow the plane of the nearest bent joint (earlier first)
    got = has
    do k = 1, n
      if (has(k)) cycle
      do kk = k - 1, 1, -1
        if (has(kk)) then
          nrm(:, k) = nrm(:, kk)
          got(k) = .true.
          exit
        end if
      end do
      if (got(k)) cycle
      do kk = k + 1, n
        if (has(kk)) then
          nrm(:, k) = nrm(:, kk)
          got(k) = .true.
          exit
        end if
      end do
    end do
    do k = 1, n - 1
      if (.not. (got(k) .and. got(k + 1))) cycle
      w = cross(nrm(:, k), nrm(:, k + 1))
      rho(k) = atan2(dot_product(w, a(:, k + 1)), dot_product(nrm(:, k), nrm(:, k + 1)))
    end do
  end subroutine chain_geometry

  !> Vector cross product u x v.
  pure function cross(u, v) result(x)
    real(dp), intent(in) :: u(3), v(3)
    real(dp) :: x(3)
    x = [u(2)*v(3) - u(3)*v(2), u(3)*v(1) - u(1)*v(3), u(1)*v(2) - u(2)*v(1)]
  end function cross

end module ujoint
