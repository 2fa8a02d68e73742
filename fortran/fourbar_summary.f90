!> Batched four-bar summaries: the headline figures of many linkages in one call.
!>
!> For each linkage (one row of params) the figures a design search filters on, over the
!> crank range [lo, hi] of the deck (only one turn matters: the motion is 360 deg periodic):
!> class (Grashof's, or a chain that cannot move), assemblability and the assembled fraction of the range, transmission-angle
!> extremes, rocker extremes and swing, toggle (limit) positions in the range, and the peak
!> coupler and rocker angular velocities with their crank angles.  Every state is computed by
!> fourbar::exact_states (the one place the loop-closure physics lives); this module only
!> decides where to evaluate it:
!>
!> * assembled intervals: bounded by the limit crank angles, where |A O_B| = r + s or |r - s|
!>   (closed form, acos);
!> * transmission angle mu: a function of d = |A O_B| only, d monotonic on [0, 180] and
!>   [180, 360] deg, so its extremes sit at interval ends or at 0 / 180 deg (closed form);
!> * rocker extremes: omega3 = 0 exactly where crank and coupler are collinear, i.e. B on the
!>   circle |O_A B| = q + r or |q - r| and on the circle |O_B B| = s (closed form); between
!>   consecutive candidates the rocker angle is monotonic, so it is unwrapped exactly with
!>   the sign of omega3 at the midpoint;
!> * peak speeds (no toggle in the range): the extremes of omega sit where the angular
!>   acceleration alpha = d omega / dt vanishes (crank speed constant).  The range is cut into
!>   a grid of at most 1 deg (as before); a coarse scan evaluates every coarse_every-th grid
!>   point in one vectorised kernel call, and a coarse interval is refined to the 1 deg grid
!>   unless, for both speeds, alpha keeps one strict sign at its ends AND the cubic Hermite
!>   model of omega over it (end values and end slopes alpha) has a slope that stays above
!>   half the smaller end slope (smooth).  A refined 1 deg interval whose ends agree in sign
!>   but fail the same test is bisected (to 1/1024 deg) looking for a hidden pair of roots.
!>   Each sign change of alpha is refined by Illinois regula falsi to 1e-12 rad, all brackets
!>   of a linkage in one kernel call per iteration.  The coarse test is checked against a
!>   dense brute-force oracle (tests/test_fourbar_peaks.py); wherever it refines, the
!>   brackets are those of a plain 1 deg scan, so the figures are bit-identical to it;
!> * time ratio (a full turn, assembled throughout, no toggle, rocker oscillating): the crank
!>   turns a = (crank angle of the upper rocker extreme - that of the lower) mod 360 on one
!>   stroke and 360 - a on the other; the ratio is the slower over the quicker, >= 1.
!>
!> Velocities are evaluated for a unit crank speed and scaled by omega (they are linear in it).
!>
!> Passes: the caller names the figures it needs (a bit mask, pass_*); the Grashof class, the
!> toggle count and the assembled fraction (closed form) are always computed, the transmission
!> angle (pass_transmission, closed form), the rocker extremes, swing and time ratio
!> (pass_rocker, kernel states at the candidates) and the peak speeds (pass_peaks, the scan
!> above) only when asked; the columns of a pass not run are 0.  A figure does not depend on
!> which other passes ran.
module fourbar_summary
  use kinds, only: dp
  use fourbar, only: exact_states, st_ok, st_no_assembly, st_toggle, st_indeterminate
  implicit none
  private
  public :: summaries

  !> params columns
  integer, parameter, public :: npar = 8
  !> result columns (see summaries)
  integer, parameter, public :: ncol = 19
  !> Class codes shared with driver/fourbar/_batch.py (GRASHOF_NAMES): Grashof's classes by the
  !> shortest link; the change-point (S + L = P + Q) classes the same way (the crank turns fully
  !> when the ground or the crank is the shortest); and two chains that cannot move: the longest
  !> link longer than the other three together (no position exists: gr_no_chain) or equal to them
  !> (the chain lies flat, one position: gr_flat_chain)
  integer, parameter, public :: gr_double_crank = 0, gr_crank_rocker = 1, gr_rocker_crank = 2, &
                                gr_double_rocker = 3, gr_cp_double_crank = 4, gr_triple_rocker = 5, &
                                gr_cp_crank_rocker = 6, gr_cp_rocker_crank = 7, gr_cp_double_rocker = 8, &
                                gr_no_chain = 9, gr_flat_chain = 10
  !> passes (bits of summaries' passes argument)
  integer, parameter, public :: pass_transmission = 1, pass_rocker = 2, pass_peaks = 4, pass_all = 7
  !> with pass_peaks: the previous peak search (every 1 deg grid point, no bisection below 1 deg),
  !> kept as the baseline of bench/bench_sweep.py and of the tests
  integer, parameter, public :: pass_dense_scan = 8

  real(dp), parameter :: pi = 3.14159265358979323846_dp, twopi = 2*pi
  real(dp), parameter :: rad = pi/180.0_dp
  integer, parameter :: maxc = 64          ! candidates per linkage (at most ~20 are used)
  integer, parameter :: maxscan = 364      ! 1 deg scan of one turn (+ ends)
  integer, parameter :: maxbr = 64         ! speed brackets per linkage
  real(dp), parameter :: scan_step = 1.0_dp   ! [deg] the fine grid
  integer, parameter :: coarse_every = 6      ! coarse scan: every 6th fine point (6 deg)
  integer, parameter :: max_depth = 10        ! bisections of a suspicious 1 deg interval

contains

  !> Summaries of n linkages.
  !> params(:, 1:4) p (ground), q (crank), r (coupler), s (rocker) [length]
  !> params(:, 5)   crank speed omega [rad/s]
  !> params(:, 6:7) first and last crank angle of the range [deg] (either order)
  !> params(:, 8)   branch: >= 0 open, < 0 crossed
  !> res(:, 1)  Grashof class code (gr_*)        res(:, 2)  1 if assemblable somewhere in the range
  !> res(:, 3)  assembled fraction of the range   res(:, 4:5) min transmission angle, its crank angle [deg]
  !> res(:, 6:7) max transmission angle, its crank angle [deg]
  !> res(:, 8:9) rocker angle [deg, 0..360) at its lower extreme, crank angle [deg]
  !> res(:, 10:11) rocker upper extreme, crank angle [deg]
  !> res(:, 12) rocker swing [deg] (360 when it turns fully)   res(:, 13) 1 if the rocker turns fully
  !> res(:, 14) number of toggle (limit) crank angles in the range
  !> res(:, 15:16) peak rocker angular velocity [rad/s] (signed) and its crank angle [deg]
  !> res(:, 17:18) peak coupler angular velocity and its crank angle (peaks 0 when res(:, 14) > 0)
  !> res(:, 19) time ratio of the rocker's strokes (crank angle of the slower over the quicker, >= 1);
  !>            0 unless the range holds a full turn, assembled throughout, without a toggle, and
  !>            the rocker oscillates
  !> Figures that do not exist (not assemblable) are 0; the caller masks them with res(:, 2) / res(:, 14).
  !> passes: sum of pass_* bits: 4:7 (pass_transmission), 8:13 and 19 (pass_rocker), 15:18
  !> (pass_peaks) are computed only when their bit is set (else 0); 1:3 and 14 always.
  subroutine summaries(n, params, passes, res)
    !f2py threadsafe
    integer, intent(in) :: n
    real(dp), intent(in) :: params(n, 8)      ! npar columns (literal for f2py)
    integer, intent(in) :: passes
    real(dp), intent(out) :: res(n, 19)        ! ncol columns
    real(dp) :: row(ncol)
    integer :: i
    do i = 1, n
      call one_linkage(params(i, 1), params(i, 2), params(i, 3), params(i, 4), params(i, 5), &
                       params(i, 6), params(i, 7), params(i, 8), passes, row)
      res(i, :) = row
    end do
  end subroutine summaries

  !> Class from the link lengths (same rule and tolerance as driver/fourbar/_analysis.py grashof()).
  pure integer function grashof_code(p, q, r, s) result(code)
    real(dp), intent(in) :: p, q, r, s
    real(dp) :: l(4), lhs, rhs, tol, rest
    integer :: i, ishort
    logical :: crank_turns, rocker_turns
    l = [p, q, s, r]                   ! tie order of the Python rule: ground, crank, rocker, coupler
    ishort = 1
    do i = 2, 4
      if (l(i) < l(ishort)) ishort = i
    end do
    call sort(l, 4)                    ! a sorted copy
    lhs = l(1) + l(4)
    rhs = l(2) + l(3)
    rest = l(1) + l(2) + l(3)          ! the three shorter links together
    tol = 1.0e-12_dp*rhs
    if (l(4) > rest + 1.0e-12_dp*rest) then
      code = gr_no_chain               ! the longest link spans more than the other three: no position
    else if (l(4) >= rest - 1.0e-12_dp*rest) then
      code = gr_flat_chain             ! only lying flat, stretched along the longest link: no motion
    else if (lhs > rhs + tol) then
      code = gr_triple_rocker
    else if (abs(lhs - rhs) <= tol) then
      ! change point: a link among the shortest (ties counted: a parallelogram's crank and rocker)
      ! turns fully; the crank turns when the ground or the crank is one, the rocker when the
      ! ground or the rocker is
      crank_turns = min(p, q) <= l(1) + 1.0e-12_dp*l(1)
      rocker_turns = min(p, s) <= l(1) + 1.0e-12_dp*l(1)
      if (crank_turns .and. rocker_turns) then
        code = gr_cp_double_crank
      else if (crank_turns) then
        code = gr_cp_crank_rocker
      else if (rocker_turns) then
        code = gr_cp_rocker_crank
      else
        code = gr_cp_double_rocker
      end if
    else
      select case (ishort)
      case (1)
        code = gr_double_crank
      case (2)
        code = gr_crank_rocker
      case (3)
        code = gr_rocker_crank
      case default
        code = gr_double_rocker
      end select
    end if
  end function grashof_code

  !> Limit (toggle) crank angles in [0, 360) deg, sorted, duplicates removed.
  pure subroutine limit_angles(p, q, r, s, lim, nlim)
    real(dp), intent(in) :: p, q, r, s
    real(dp), intent(out) :: lim(4)
    integer, intent(out) :: nlim
    real(dp) :: dd(2), c, a, cand(4)
    integer :: k, nc, i
    dd = [r + s, abs(r - s)]
    nc = 0
    do k = 1, 2
      c = (p*p + q*q - dd(k)*dd(k))/(2*p*q)
      if (c >= -1.0_dp .and. c <= 1.0_dp) then
        a = acos(c)/rad
        cand(nc + 1) = a
        cand(nc + 2) = modulo(360.0_dp - a, 360.0_dp)
        nc = nc + 2
      end if
    end do
    call sort(cand, nc)
    nlim = 0
    do i = 1, nc
      if (nlim > 0) then
        if (abs(cand(i) - lim(nlim)) <= 1.0e-9_dp) cycle
      end if
      nlim = nlim + 1
      lim(nlim) = cand(i)
    end do
  end subroutine limit_angles

  !> Append every angle base + 360 k inside the open interval (a, b) to list(1:nl).
  pure subroutine add_periodic(base, a, b, list, nl)
    real(dp), intent(in) :: base, a, b
    real(dp), intent(inout) :: list(:)
    integer, intent(inout) :: nl
    real(dp) :: t
    t = base + 360.0_dp*ceiling((a - base)/360.0_dp)
    if (t <= a) t = t + 360.0_dp
    do while (t < b .and. nl < size(list))
      nl = nl + 1
      list(nl) = t
      t = t + 360.0_dp
    end do
  end subroutine add_periodic

  !> Insertion sort of x(1:m) ascending.
  pure subroutine sort(x, m)
    real(dp), intent(inout) :: x(:)
    integer, intent(in) :: m
    real(dp) :: t
    integer :: i, j
    do i = 2, m
      t = x(i)
      j = i - 1
      do while (j >= 1)
        if (x(j) <= t) exit
        x(j + 1) = x(j)
        j = j - 1
      end do
      x(j + 1) = t
    end do
  end subroutine sort

  !> Distance |A O_B| at crank angle t [deg].
  pure real(dp) function dist(p, q, t)
    real(dp), intent(in) :: p, q, t
    dist = sqrt(max(p*p + q*q - 2*p*q*cos(t*rad), 0.0_dp))
  end function dist

  !> Transmission angle [deg] for |A O_B| = d, d clamped to the assemblable range.
  pure real(dp) function mu_of(r, s, d)
    real(dp), intent(in) :: r, s, d
    real(dp) :: dc
    dc = min(max(d, abs(r - s)), r + s)
    mu_of = acos(min(1.0_dp, max(-1.0_dp, (r*r + s*s - dc*dc)/(2*r*s))))/rad
  end function mu_of

  !> All figures of one linkage (see summaries for the columns).
  subroutine one_linkage(p, q, r, s, omega, t0, t1, branch_r, passes, row)
    real(dp), intent(in) :: p, q, r, s, omega, t0, t1, branch_r
    integer, intent(in) :: passes
    real(dp), intent(out) :: row(ncol)
    real(dp) :: lo, hi, hie, lim(4), bp(maxc), ia(maxc), ib(maxc), zer(4), cand(maxc), tt(2*maxc)
    real(dp) :: st(2*maxc, 11), u(maxc), dd(2), x, y2, phi, t, mid, total, d, dmin, dmax
    real(dp) :: umin, umax, tumin, tumax, ushift, c1, delta, sg, tc, dtol
    integer :: stat(2*maxc), nlim, nbp, niv, nz, nc, i, j, k, branch, ntog, nt, kmin, kmax
    logical :: okm, first, want_mu, want_rocker

    row = 0.0_dp
    want_mu = iand(passes, pass_transmission) /= 0
    want_rocker = iand(passes, pass_rocker) /= 0
    branch = merge(1, -1, branch_r >= 0.0_dp)
    lo = min(t0, t1)
    hi = max(t0, t1)
    hie = min(hi, lo + 360.0_dp)
    row(1) = real(grashof_code(p, q, r, s), dp)
    call limit_angles(p, q, r, s, lim, nlim)
    ntog = 0
    do i = 1, nlim
      kmin = ceiling((lo - lim(i))/360.0_dp)
      kmax = floor((hi - lim(i))/360.0_dp)
      ntog = ntog + max(0, kmax - kmin + 1)
    end do
    row(14) = real(ntog, dp)

    if (hie <= lo) then                 ! a single crank angle
      call single_angle(p, q, r, s, omega, lo, branch, passes, row)
      return
    end if

    ! ---- assembled intervals: cut [lo, hie] at the limit angles, test each piece's midpoint
    nbp = 1
    bp(1) = lo
    do i = 1, nlim
      call add_periodic(lim(i), lo, hie, bp, nbp)
    end do
    nbp = nbp + 1
    bp(nbp) = hie
    call sort(bp, nbp)
    niv = 0
    do i = 1, nbp - 1
      if (bp(i + 1) <= bp(i)) cycle
      d = dist(p, q, 0.5_dp*(bp(i) + bp(i + 1)))
      okm = d >= abs(r - s) .and. d <= r + s
      if (.not. okm) cycle
      if (niv > 0) then
        if (ib(niv) == bp(i)) then      ! touches the previous piece (toggle inside): merge
          ib(niv) = bp(i + 1)
          cycle
        end if
      end if
      niv = niv + 1
      ia(niv) = bp(i)
      ib(niv) = bp(i + 1)
    end do
    if (niv == 0) return                ! not assemblable anywhere in the range
    row(2) = 1.0_dp
    total = 0.0_dp
    do i = 1, niv
      total = total + (ib(i) - ia(i))
    end do
    row(3) = min(1.0_dp, total/(hie - lo))
    ! a full turn whose first and last intervals meet at lo = hie - 360 is one motion: join them
    ! (crank angles below lo are reported one turn up)
    if (niv > 1 .and. hie - lo >= 360.0_dp .and. ia(1) == lo .and. ib(niv) == hie) then
      ia(1) = ia(niv) - 360.0_dp
      niv = niv - 1
    end if

    if (want_mu .or. want_rocker) then
      call motion()
      if (want_mu) then
        row(4) = mu_of(r, s, dmin)
        row(6) = mu_of(r, s, dmax)
      else
        row(5) = 0.0_dp
        row(7) = 0.0_dp
      end if
      if (want_rocker) call rocker_figures()
    end if

    ! ---- peak speeds: only without a toggle in the range (then the range is one interval)
    if (iand(passes, pass_peaks) /= 0 .and. ntog == 0 .and. niv == 1) &
      call peaks(p, q, r, s, omega, lo, hie, branch, iand(passes, pass_dense_scan) /= 0, row)

  contains

    !> Transmission-angle and rocker extremes over the assembled intervals (candidates in
    !> closed form, states at the candidates only for the rocker).
    subroutine motion()
      ! ---- crank angles where omega3 = 0 (crank and coupler collinear), any branch
      nz = 0
      dd = [q + r, abs(q - r)]
      do k = 1, 2
        if (dd(k) <= 0.0_dp) cycle
        x = (dd(k)*dd(k) + p*p - s*s)/(2*p)
        y2 = dd(k)*dd(k) - x*x
        if (y2 < 0.0_dp) cycle
        do j = -1, 1, 2
          phi = atan2(j*sqrt(y2), x)/rad
          if (k == 2 .and. r > q) phi = phi + 180.0_dp   ! folded with the coupler longer: B opposite A
          nz = nz + 1
          zer(nz) = modulo(phi, 360.0_dp)
        end do
      end do

      ! ---- per interval: candidates (ends, 0/180 deg, omega3 zeros, inner breakpoints) and midpoints
      first = .true.
      umin = 0; umax = 0; tumin = 0; tumax = 0
      dmin = huge(1.0_dp); dmax = -1.0_dp
      dtol = 1.0e-12_dp*(p + q)
      do i = 1, niv
        nc = 1
        cand(1) = ia(i)
        call add_periodic(0.0_dp, ia(i), ib(i), cand, nc)
        call add_periodic(180.0_dp, ia(i), ib(i), cand, nc)
        do k = 1, nz
          call add_periodic(zer(k), ia(i), ib(i), cand, nc)
        end do
        do k = 1, nlim
          call add_periodic(lim(k), ia(i), ib(i), cand, nc)
        end do
        nc = nc + 1
        cand(nc) = ib(i)
        call sort(cand, nc)
        ! transmission angle: extremes of d among the candidates (ascending, first wins ties)
        do j = 1, nc
          d = dist(p, q, cand(j))
          tc = cand(j)
          if (tc < lo) tc = tc + 360.0_dp
          ! ties within rounding (e.g. the two crank angles of one limit) go to the smaller angle
          if (d < dmin - dtol .or. (abs(d - dmin) <= dtol .and. tc < row(5))) then
            dmin = min(d, dmin)
            row(5) = tc
          end if
          if (d > dmax + dtol .or. (abs(d - dmax) <= dtol .and. tc < row(7))) then
            dmax = max(d, dmax)
            row(7) = tc
          end if
        end do
        if (.not. want_rocker) cycle
        ! states at candidates and midpoints in one kernel call (unit crank speed)
        nt = 0
        do j = 1, nc
          nt = nt + 1
          tt(nt) = cand(j)
          if (j < nc) then
            nt = nt + 1
            tt(nt) = 0.5_dp*(cand(j) + cand(j + 1))
          end if
        end do
        call states_at(nt, tt, p, q, r, s, branch, ia(i), ib(i), st, stat)
        ! unwrap the rocker angle along the interval: monotonic between candidates
        u(1) = st(1, 2)
        do j = 1, nc - 1
          sg = st(2*j, 9)                 ! omega3 at the midpoint
          delta = st(2*j + 1, 2) - st(2*j - 1, 2)
          delta = delta - twopi*anint(delta/twopi)          ! in [-pi, pi]
          if (sg > 0.0_dp .and. delta < -1.0e-9_dp) delta = delta + twopi
          if (sg < 0.0_dp .and. delta > 1.0e-9_dp) delta = delta - twopi
          u(j + 1) = u(j) + delta
        end do
        ! a later interval is placed on the turn nearest to the first one's centre
        if (first) then
          ushift = 0.0_dp
        else
          c1 = 0.5_dp*(umin + umax)
          ushift = twopi*anint((c1 - u(1))/twopi)
        end if
        do j = 1, nc
          t = u(j) + ushift
          tc = cand(j)
          if (tc < lo) tc = tc + 360.0_dp
          if (first .and. j == 1) then
            umin = t; umax = t; tumin = tc; tumax = tc
          else
            if (t < umin .or. (t == umin .and. tc < tumin)) then
              umin = t; tumin = tc
            end if
            if (t > umax .or. (t == umax .and. tc < tumax)) then
              umax = t; tumax = tc
            end if
          end if
        end do
        first = .false.
      end do
    end subroutine motion

    !> Rocker extremes, swing, full turn and time ratio from the unwrapped extremes.
    subroutine rocker_figures()
      row(8) = fold360(umin/rad)
      row(9) = tumin
      row(10) = fold360(umax/rad)
      row(11) = tumax
      if (row(3) >= 1.0_dp .and. niv == 1 .and. (umax - umin) >= twopi - 1.0e-6_dp) then
        row(13) = 1.0_dp
        row(12) = 360.0_dp
      else
        row(12) = (umax - umin)/rad
      end if

      ! ---- time ratio: a full turn without toggles, the rocker oscillating
      if (hie - lo >= 360.0_dp .and. row(3) >= 1.0_dp .and. niv == 1 .and. ntog == 0 .and. &
          row(13) == 0.0_dp) then
        t = modulo(tumax - tumin, 360.0_dp)
        if (t > 0.0_dp .and. t < 360.0_dp) row(19) = max(t, 360.0_dp - t)/min(t, 360.0_dp - t)
      end if
    end subroutine rocker_figures
  end subroutine one_linkage

  !> Rocker angle folded into [0, 360) [deg].
  pure real(dp) function fold360(a)
    real(dp), intent(in) :: a
    fold360 = modulo(a, 360.0_dp)
    if (fold360 >= 360.0_dp - 1.0e-9_dp) fold360 = 0.0_dp
  end function fold360

  !> exact_states at crank angles tt(1:m) [deg], unit crank speed and no crank acceleration.
  !> A point the kernel finds just outside the assemblable set (rounding at a limit angle) or
  !> indeterminate is re-evaluated 1e-12 rad inside the interval [a, b].
  subroutine states_at(m, tt, p, q, r, s, branch, a, b, st, stat)
    integer, intent(in) :: m, branch
    real(dp), intent(in) :: tt(m), p, q, r, s, a, b
    real(dp), intent(inout) :: st(:, :)
    integer, intent(inout) :: stat(:)
    real(dp) :: th(m), out(m, 11), one(1), o1(1, 11)
    integer :: ist(m), s1(1), j
    th = tt*rad
    call exact_states(m, th, p, q, r, s, 1.0_dp, 0.0_dp, branch, out, ist)
    do j = 1, m
      if (ist(j) == st_no_assembly .or. ist(j) == st_indeterminate) then
        one(1) = th(j) + merge(1.0e-12_dp, -1.0e-12_dp, tt(j) <= 0.5_dp*(a + b))
        call exact_states(1, one, p, q, r, s, 1.0_dp, 0.0_dp, branch, o1, s1)
        out(j, :) = o1(1, :)
        ist(j) = s1(1)
      end if
    end do
    st(1:m, :) = out
    stat(1:m) = ist
  end subroutine states_at

  !> The whole summary at one crank angle (a range of zero length): the passes asked for.
  subroutine single_angle(p, q, r, s, omega, t, branch, passes, row)
    real(dp), intent(in) :: p, q, r, s, omega, t
    integer, intent(in) :: branch, passes
    real(dp), intent(inout) :: row(ncol)
    real(dp) :: th(1), out(1, 11)
    integer :: ist(1)
    th(1) = t*rad
    call exact_states(1, th, p, q, r, s, 1.0_dp, 0.0_dp, branch, out, ist)
    if (ist(1) /= st_ok .and. ist(1) /= st_toggle) return
    row(2:3) = 1.0_dp
    if (iand(passes, pass_transmission) /= 0) then
      row(4) = mu_of(r, s, dist(p, q, t))
      row(5) = t
      row(6:7) = row(4:5)
    end if
    if (iand(passes, pass_rocker) /= 0) then
      row(8) = fold360(out(1, 2)/rad)
      row(9) = t
      row(10:11) = row(8:9)
    end if
    if (iand(passes, pass_peaks) /= 0 .and. nint(row(14)) == 0 .and. ist(1) == st_ok) then
      row(15) = omega*out(1, 9)
      row(16) = t
      row(17) = omega*out(1, 8)
      row(18) = t
    end if
  end subroutine single_angle

  !> omega3, alpha3, omega2, alpha2 (unit crank speed) and status at crank angles t(1:np) [rad].
  !> work: the caller's buffer of at least 11 np values (viewed here as exact_states' (np, 11)
  !> output, so neither a copy-in/out temporary nor a heap-allocated automatic array is made).
  subroutine speeds_at(np, t, p, q, r, s, branch, work, w3, a3, w2, a2, ist)
    integer, intent(in) :: np, branch
    real(dp), intent(in) :: t(np), p, q, r, s
    real(dp), intent(inout) :: work(np, 11)
    real(dp), intent(inout) :: w3(np), a3(np), w2(np), a2(np)
    integer, intent(inout) :: ist(np)
    call exact_states(np, t, p, q, r, s, 1.0_dp, 0.0_dp, branch, work, ist)
    w3 = work(:, 9)
    a3 = work(:, 11)
    w2 = work(:, 8)
    a2 = work(:, 10)
  end subroutine speeds_at

  !> Whether omega has no extremum in an interval of length h [rad] with end values fa, fb and
  !> end slopes da, db (alpha at unit crank speed = d omega / d theta): the ends' slopes share a
  !> strict sign and the slope of the cubic Hermite model of omega, a quadratic
  !> A (1 - x) + B x + c x (1 - x) with the interval's mean slope, stays above half the smaller
  !> end slope.  False sends the interval to a finer scan.
  pure logical function smooth(fa, fb, da, db, h)
    real(dp), intent(in) :: fa, fb, da, db, h
    real(dp) :: sg, a, b, c, xs, qmin
    smooth = .false.
    if (.not. (da*db > 0.0_dp)) return
    sg = sign(1.0_dp, da)
    a = sg*da
    b = sg*db
    c = 6.0_dp*(sg*(fb - fa)/h - 0.5_dp*(a + b))
    qmin = min(a, b)
    if (c < 0.0_dp) then
      xs = 0.5_dp + (b - a)/(2.0_dp*c)
      if (xs > 0.0_dp .and. xs < 1.0_dp) qmin = min(qmin, a*(1.0_dp - xs) + b*xs + c*xs*(1.0_dp - xs))
    end if
    smooth = qmin >= 0.5_dp*min(a, b)
  end function smooth

  !> Peak |omega3| and |omega2| over [lo, hie] (assembled throughout, no toggle): the grid of
  !> at most 1 deg, scanned coarsely and refined where needed (module header), then every
  !> sign change of the matching angular acceleration refined to 1e-12 rad.
  subroutine peaks(p, q, r, s, omega, lo, hie, branch, dense, row)
    real(dp), intent(in) :: p, q, r, s, omega, lo, hie
    integer, intent(in) :: branch
    logical, intent(in) :: dense
    real(dp), intent(inout) :: row(ncol)
    real(dp) :: th(maxscan), w(maxscan, 4), tg(maxscan), g(maxscan, 4), wk(11*maxscan), h
    real(dp) :: ba(maxbr), bb(maxbr), fa(maxbr), fb(maxbr), tx(maxbr), ox(maxbr, 4)
    real(dp) :: best(2), bestat(2), v
    integer :: ci(maxscan), gi(maxscan), ist(maxscan), isx(maxbr), bcol(maxbr), side(maxbr)
    real(dp) :: okc(maxscan), hc, da, db, sg, av, bv, cv, qv, xs, qm
    integer :: rj(maxscan), m, nco, ng, nref, k, ka, kb, nb, it, j, jr, c, live

    m = min(maxscan, max(2, ceiling((hie - lo)/scan_step) + 1))
    h = (hie - lo)/(m - 1)
    ! hot-loop: fourbar_summary scan angles
    do k = 1, m
      th(k) = (lo + (k - 1)*h)*rad
    end do
    th(m) = hie*rad
    ! the coarse scan (first and last grid points included) in one kernel call
    nco = 0
    k = 1
    do
      nco = nco + 1
      ci(nco) = k
      if (k == m) exit
      k = min(k + coarse_every, m)
    end do
    do j = 1, nco
      tg(j) = th(ci(j))
    end do
    call speeds_at(nco, tg(1:nco), p, q, r, s, branch, wk, g(1:nco, 1), g(1:nco, 2), g(1:nco, 3), &
                   g(1:nco, 4), ist(1:nco))
    do j = 1, nco
      w(ci(j), :) = g(j, :)
    end do
    ! the smooth test (see smooth) of every coarse interval, both speeds, in one loop
    ! hot-loop: fourbar_summary coarse test
    do j = 1, nco - 1
      hc = tg(j + 1) - tg(j)
      okc(j) = 1.0_dp
      do c = 1, 2
        da = g(j, 2*c)
        db = g(j + 1, 2*c)
        sg = sign(1.0_dp, da)
        av = sg*da
        bv = sg*db
        cv = 6.0_dp*(sg*(g(j + 1, 2*c - 1) - g(j, 2*c - 1))/hc - 0.5_dp*(av + bv))
        qv = min(av, bv)
        xs = 0.5_dp + (bv - av)/(2.0_dp*min(cv, -tiny(1.0_dp)))
        qm = merge(min(qv, av*(1.0_dp - xs) + bv*xs + cv*xs*(1.0_dp - xs)), qv, &
                   cv < 0.0_dp .and. xs > 0.0_dp .and. xs < 1.0_dp)
        okc(j) = okc(j)*merge(1.0_dp, 0.0_dp, da*db > 0.0_dp .and. qm >= 0.5_dp*qv)
      end do
    end do
    ! the grid points inside every coarse interval that is not smooth for both speeds
    ng = 0
    nref = 0
    do j = 1, nco - 1
      ka = ci(j)
      kb = ci(j + 1)
      if (okc(j) > 0.0_dp .and. kb - ka >= 2 .and. .not. dense) cycle
      nref = nref + 1
      rj(nref) = j
      do k = ka + 1, kb - 1
        ng = ng + 1
        gi(ng) = k
        tg(ng) = th(k)
      end do
    end do
    if (ng > 0) then
      call speeds_at(ng, tg(1:ng), p, q, r, s, branch, wk, g(1:ng, 1), g(1:ng, 2), g(1:ng, 3), &
                     g(1:ng, 4), ist(1:ng))
      do j = 1, ng
        w(gi(j), :) = g(j, :)
      end do
    end if
    ! brackets of alpha sign changes on the grid of the refined intervals, both speeds (grid
    ! order, as a full scan)
    nb = 0
    do c = 1, 2
      do jr = 1, nref
        do k = ci(rj(jr)), ci(rj(jr) + 1) - 1
          if (w(k, 2*c)*w(k + 1, 2*c) < 0.0_dp) then
            call add_bracket(th(k), th(k + 1), w(k, 2*c), w(k + 1, 2*c), c)
          else if (dense) then
            cycle
          else if (.not. smooth(w(k, 2*c - 1), w(k + 1, 2*c - 1), w(k, 2*c), w(k + 1, 2*c), th(k + 1) - th(k))) then
            call hidden(th(k), th(k + 1), w(k, 2*c - 1), w(k + 1, 2*c - 1), w(k, 2*c), w(k + 1, 2*c), c, 1)
          end if
        end do
      end do
    end do
    ! Illinois regula falsi, every bracket advanced in one kernel call per iteration
    do it = 1, 60
      live = 0
      do j = 1, nb
        if (bb(j) - ba(j) > 1.0e-12_dp) then
          live = live + 1
        end if
        tx(j) = (ba(j)*fb(j) - bb(j)*fa(j))/(fb(j) - fa(j))
        tx(j) = min(max(tx(j), ba(j)), bb(j))
      end do
      if (live == 0) exit
      call speeds_at(nb, tx(1:nb), p, q, r, s, branch, wk, ox(1:nb, 1), ox(1:nb, 2), ox(1:nb, 3), &
                     ox(1:nb, 4), isx(1:nb))
      do j = 1, nb
        if (bb(j) - ba(j) <= 1.0e-12_dp) cycle
        v = ox(j, 2*bcol(j))
        if (v == 0.0_dp) then
          ba(j) = tx(j); bb(j) = tx(j); fa(j) = 0; fb(j) = 0
          cycle
        end if
        if (sign(1.0_dp, v) == sign(1.0_dp, fa(j))) then
          ba(j) = tx(j); fa(j) = v
          if (side(j) == -1) fb(j) = 0.5_dp*fb(j)
          side(j) = -1
        else
          bb(j) = tx(j); fb(j) = v
          if (side(j) == 1) fa(j) = 0.5_dp*fa(j)
          side(j) = 1
        end if
      end do
    end do
    ! final points: the converged roots
    do j = 1, nb
      tx(j) = 0.5_dp*(ba(j) + bb(j))
    end do
    if (nb > 0) call speeds_at(nb, tx(1:nb), p, q, r, s, branch, wk, ox(1:nb, 1), ox(1:nb, 2), ox(1:nb, 3), &
                               ox(1:nb, 4), isx(1:nb))
    ! pick the largest |omega| among the range ends and the refined roots (earliest on ties)
    do c = 1, 2
      best(c) = w(1, 2*c - 1)
      bestat(c) = th(1)
      if (abs(w(m, 2*c - 1)) > abs(best(c))) then
        best(c) = w(m, 2*c - 1); bestat(c) = th(m)
      end if
    end do
    do j = 1, nb
      c = bcol(j)
      v = ox(j, 2*c - 1)
      if (isx(j) /= st_ok) cycle
      if (abs(v) > abs(best(c)) .or. (abs(v) == abs(best(c)) .and. tx(j) < bestat(c))) then
        best(c) = v
        bestat(c) = tx(j)
      end if
    end do
    row(15) = omega*best(1)
    row(16) = bestat(1)/rad
    row(17) = omega*best(2)
    row(18) = bestat(2)/rad

  contains

    subroutine add_bracket(a, b, da, db, col)
      real(dp), intent(in) :: a, b, da, db
      integer, intent(in) :: col
      if (nb >= maxbr) return
      nb = nb + 1
      ba(nb) = a; bb(nb) = b
      fa(nb) = da; fb(nb) = db
      bcol(nb) = col
      side(nb) = 0
    end subroutine add_bracket

    !> A grid interval whose ends agree in the sign of alpha but which is not smooth: bisected
    !> (max_depth levels) looking for a hidden pair of sign changes, each one a bracket.
    recursive subroutine hidden(a, b, ya, yb, da, db, col, depth)
      real(dp), intent(in) :: a, b, ya, yb, da, db
      integer, intent(in) :: col, depth
      real(dp) :: tm(1), o(1, 4), o1(11), ym, dm
      integer :: sm(1)
      if (depth > max_depth) return
      tm(1) = 0.5_dp*(a + b)
      call speeds_at(1, tm, p, q, r, s, branch, o1, o(:, 1), o(:, 2), o(:, 3), o(:, 4), sm)
      if (sm(1) /= st_ok) return
      ym = o(1, 2*col - 1)
      dm = o(1, 2*col)
      if (da*dm < 0.0_dp) then
        call add_bracket(a, tm(1), da, dm, col)
      else if (.not. smooth(ya, ym, da, dm, tm(1) - a)) then
        call hidden(a, tm(1), ya, ym, da, dm, col, depth + 1)
      end if
      if (dm*db < 0.0_dp) then
        call add_bracket(tm(1), b, dm, db, col)
      else if (.not. smooth(ym, yb, dm, db, b - tm(1))) then
        call hidden(tm(1), b, ym, yb, dm, db, col, depth + 1)
      end if
    end subroutine hidden

  end subroutine peaks

end module fourbar_summary
