!> Batched four-bar summaries: the headline figures of many linkages in one call.
!>
!> For each linkage (one row of params) the figures a design search filters on, over the
!> crank range [lo, hi] of the deck (only one turn matters: the motion is 360 deg periodic):
!> Grashof class, assemblability and the assembled fraction of the range, transmission-angle
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
!> * peak speeds (no toggle in the range): a 1 deg scan of the whole range in one vectorised
!>   kernel call, then each sign change of the angular acceleration (crank speed constant,
!>   so alpha = d omega / dt vanishes at a speed extremum) refined by Illinois regula falsi
!>   to 1e-12 rad, all brackets of a linkage in one kernel call per iteration;
!> * time ratio (a full turn, assembled throughout, no toggle, rocker oscillating): the crank
!>   turns a = (crank angle of the upper rocker extreme - that of the lower) mod 360 on one
!>   stroke and 360 - a on the other; the ratio is the slower over the quicker, >= 1.
!>
!> Velocities are evaluated for a unit crank speed and scaled by omega (they are linear in it).
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
  !> Grashof class codes shared with driver/fourbar.py
  integer, parameter, public :: gr_double_crank = 0, gr_crank_rocker = 1, gr_rocker_crank = 2, &
                                gr_double_rocker = 3, gr_change_point = 4, gr_triple_rocker = 5

  real(dp), parameter :: pi = 3.14159265358979323846_dp, twopi = 2*pi
  real(dp), parameter :: rad = pi/180.0_dp
  integer, parameter :: maxc = 64          ! candidates per linkage (at most ~20 are used)
  integer, parameter :: maxscan = 364      ! 1 deg scan of one turn (+ ends)
  integer, parameter :: maxbr = 64         ! speed brackets per linkage
  real(dp), parameter :: scan_step = 1.0_dp   ! [deg]

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
  subroutine summaries(n, params, res)
    !f2py threadsafe
    integer, intent(in) :: n
    real(dp), intent(in) :: params(n, 8)      ! npar columns (literal for f2py)
    real(dp), intent(out) :: res(n, 19)        ! ncol columns
    real(dp) :: row(ncol)
    integer :: i
    do i = 1, n
      call one_linkage(params(i, 1), params(i, 2), params(i, 3), params(i, 4), params(i, 5), &
                       params(i, 6), params(i, 7), params(i, 8), row)
      res(i, :) = row
    end do
  end subroutine summaries

  !> Grashof class from the link lengths (same rule and tolerance as driver/fourbar.py grashof()).
  pure integer function grashof_code(p, q, r, s) result(code)
    real(dp), intent(in) :: p, q, r, s
    real(dp) :: l(4), lhs, rhs, tol
    integer :: i, ishort
    l = [p, q, s, r]                   ! tie order of the Python rule: ground, crank, rocker, coupler
    ishort = 1
    do i = 2, 4
      if (l(i) < l(ishort)) ishort = i
    end do
    call sort(l, 4)                    ! a sorted copy
    lhs = l(1) + l(4)
    rhs = l(2) + l(3)
    tol = 1.0e-12_dp*rhs
    if (lhs > rhs + tol) then
      code = gr_triple_rocker
    else if (abs(lhs - rhs) <= tol) then
      code = gr_change_point
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
  subroutine one_linkage(p, q, r, s, omega, t0, t1, branch_r, row)
    real(dp), intent(in) :: p, q, r, s, omega, t0, t1, branch_r
    real(dp), intent(out) :: row(ncol)
    real(dp) :: lo, hi, hie, lim(4), bp(maxc), ia(maxc), ib(maxc), zer(4), cand(maxc), tt(2*maxc)
    real(dp) :: st(2*maxc, 11), u(maxc), dd(2), x, y2, phi, t, mid, total, d, dmin, dmax
    real(dp) :: umin, umax, tumin, tumax, ushift, c1, delta, sg, tc, dtol
    integer :: stat(2*maxc), nlim, nbp, niv, nz, nc, i, j, k, branch, ntog, nt, kmin, kmax
    logical :: okm, first

    row = 0.0_dp
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
      call single_angle(p, q, r, s, omega, lo, branch, row)
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
    row(4) = mu_of(r, s, dmin)
    row(6) = mu_of(r, s, dmax)
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

    ! ---- peak speeds: only without a toggle in the range (then the range is one interval)
    if (ntog == 0 .and. niv == 1) call peaks(p, q, r, s, omega, lo, hie, branch, row)
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

  !> The whole summary at one crank angle (a range of zero length).
  subroutine single_angle(p, q, r, s, omega, t, branch, row)
    real(dp), intent(in) :: p, q, r, s, omega, t
    integer, intent(in) :: branch
    real(dp), intent(inout) :: row(ncol)
    real(dp) :: th(1), out(1, 11)
    integer :: ist(1)
    th(1) = t*rad
    call exact_states(1, th, p, q, r, s, 1.0_dp, 0.0_dp, branch, out, ist)
    if (ist(1) /= st_ok .and. ist(1) /= st_toggle) return
    row(2:3) = 1.0_dp
    row(4) = mu_of(r, s, dist(p, q, t))
    row(5) = t
    row(6:7) = row(4:5)
    row(8) = fold360(out(1, 2)/rad)
    row(9) = t
    row(10:11) = row(8:9)
    if (nint(row(14)) == 0 .and. ist(1) == st_ok) then
      row(15) = omega*out(1, 9)
      row(16) = t
      row(17) = omega*out(1, 8)
      row(18) = t
    end if
  end subroutine single_angle

  !> Peak |omega3| and |omega2| over [lo, hie] (assembled throughout, no toggle): 1 deg scan,
  !> then every sign change of the matching angular acceleration refined to 1e-12 rad.
  subroutine peaks(p, q, r, s, omega, lo, hie, branch, row)
    real(dp), intent(in) :: p, q, r, s, omega, lo, hie
    integer, intent(in) :: branch
    real(dp), intent(inout) :: row(ncol)
    real(dp) :: th(maxscan), out(maxscan, 11), h
    real(dp) :: ba(maxbr), bb(maxbr), fa(maxbr), fb(maxbr), tx(maxbr), ox(maxbr, 11)
    real(dp) :: best(2), bestat(2), v
    integer :: ist(maxscan), isx(maxbr), bcol(maxbr), side(maxbr), m, k, nb, it, j, c, live
    integer, parameter :: wcol(2) = [9, 8], acol(2) = [11, 10]   ! omega3 / alpha3, omega2 / alpha2

    m = min(maxscan, max(2, ceiling((hie - lo)/scan_step) + 1))
    h = (hie - lo)/(m - 1)
    ! the whole scan in one (vectorised) kernel call
    ! hot-loop: fourbar_summary scan angles
    do k = 1, m
      th(k) = (lo + (k - 1)*h)*rad
    end do
    th(m) = hie*rad
    call exact_states(m, th(1:m), p, q, r, s, 1.0_dp, 0.0_dp, branch, out(1:m, :), ist(1:m))
    ! brackets of alpha sign changes, both columns
    nb = 0
    do c = 1, 2
      do k = 1, m - 1
        if (out(k, acol(c))*out(k + 1, acol(c)) < 0.0_dp .and. nb < maxbr) then
          nb = nb + 1
          ba(nb) = th(k); bb(nb) = th(k + 1)
          fa(nb) = out(k, acol(c)); fb(nb) = out(k + 1, acol(c))
          bcol(nb) = c
          side(nb) = 0
        end if
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
      call exact_states(nb, tx(1:nb), p, q, r, s, 1.0_dp, 0.0_dp, branch, ox(1:nb, :), isx(1:nb))
      do j = 1, nb
        if (bb(j) - ba(j) <= 1.0e-12_dp) cycle
        v = ox(j, acol(bcol(j)))
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
    if (nb > 0) call exact_states(nb, tx(1:nb), p, q, r, s, 1.0_dp, 0.0_dp, branch, ox(1:nb, :), isx(1:nb))
    ! pick the largest |omega| among the range ends and the refined roots (earliest on ties)
    do c = 1, 2
      best(c) = out(1, wcol(c))
      bestat(c) = th(1)
      if (abs(out(m, wcol(c))) > abs(best(c))) then
        best(c) = out(m, wcol(c)); bestat(c) = th(m)
      end if
    end do
    do j = 1, nb
      c = bcol(j)
      v = ox(j, wcol(c))
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
  end subroutine peaks

end module fourbar_summary
