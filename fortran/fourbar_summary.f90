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
!>   point in one vectorised kernel call.  A coarse interval is taken as it stands when, for
!>   each speed, either alpha keeps one strict sign at its ends AND the cubic Hermite model of
!>   omega over it (end values and end slopes alpha) has a slope that stays above half the
!>   smaller end slope (smooth: no extremum inside), or alpha changes sign at its ends AND the
!>   model's slope, a quadratic, is monotonic with a margin (|its curvature term| at most half
!>   the ends' slope difference: one clean crossing, a bracket as it stands).  Any other
!>   interval is refined to the 1 deg grid; a refined 1 deg interval whose ends agree in sign
!>   but fail the smooth test is bisected (to 1/1024 deg) looking for a hidden pair of roots.
!>   Each sign change of alpha is a bracket whose root is found by safeguarded Newton steps
!>   on alpha (rtsafe: a bisection where a step would leave the bracket or not halve the step
!>   before last), its derivative the jerk from fourbar::jerks_block, started at the root of
!>   the Hermite model's slope; a root is taken when the Newton step is at most newton_tol
!>   (1e-7 rad): the next iterate, within about 1e-14 rad of the root, omega there from the
!>   Taylor polynomial at the last point.  About two evaluations per root on the shipped search
!>   (69 per linkage: 61 coarse, 8 Newton), where the previous search (1 deg brackets, Illinois
!>   regula falsi to 1e-12 rad, a final point) took about 108; the peaks agree with it to
!>   about 1e-13 relative (tests/test_fourbar_peaks.py: against a dense brute-force oracle, and
!>   against the 1 deg scan of pass_dense_scan on the shipped grid);
!> * time ratio (a full turn, assembled throughout, no toggle, rocker oscillating): the crank
!>   turns a = (crank angle of the upper rocker extreme - that of the lower) mod 360 on one
!>   stroke and 360 - a on the other; the ratio is the slower over the quicker, >= 1.
!>
!> Velocities are evaluated for a unit crank speed and scaled by omega (they are linear in it).
!>
!> Batched (issue 37): the linkages are taken lb at a time.  For each block the closed-form
!> part runs linkage by linkage (class, limits, assembled intervals, candidates); the states
!> the rocker figures need -- the rocker angle at every candidate of every linkage of the block,
!> and the rocker speed's sign halfway between candidates -- are then evaluated in one batched
!> call of fourbar's pose/angles/rates stages (each position with its own linkage), and the
!> figures are finished linkage by linkage.  Bit for bit the figures of the linkage-by-linkage
!> evaluation, with less work: the states' stages give the same bits alone as inside
!> exact_states; |A O_B| is evaluated (libm cos) only at the candidates where an extreme or a
!> tie of it can sit (interval ends, limits, 0/180 deg, and a crank/coupler collinear angle
!> closer to one of those than a tie allows), and is exactly p -+ q at multiples of 180 deg;
!> atan2 of the collinear angles once per pair (atan2 is odd in y); and for a Grashof
!> crank-rocker without limits (its rocker swings less than half a turn, so the sign of the
!> rocker speed between candidates is that of the step) no speeds halfway.  The peak speeds
!> evaluate only the angular rates they need (no angles).
!>
!> Passes: the caller names the figures it needs (a bit mask, pass_*); the Grashof class, the
!> toggle count and the assembled fraction (closed form) are always computed, the transmission
!> angle (pass_transmission, closed form), the rocker extremes, swing and time ratio
!> (pass_rocker, kernel states at the candidates) and the peak speeds (pass_peaks, the scan
!> above) only when asked; the columns of a pass not run are 0.  A figure does not depend on
!> which other passes ran.
module fourbar_summary
  use kinds, only: dp
  use fourbar, only: exact_states, pose_block, rates_block, jerks_block, angles_block, nblk => nb, st_ok, &
                     st_no_assembly, st_toggle, &
                     st_indeterminate
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
  !> with pass_peaks: the previous peak scan (every 1 deg grid point, no bisection below 1 deg; its
  !> brackets' roots found as above), kept as the baseline of bench/bench_sweep.py and of the tests
  integer, parameter, public :: pass_dense_scan = 8

  real(dp), parameter :: pi = 3.14159265358979323846_dp, twopi = 2*pi
  real(dp), parameter :: rad = pi/180.0_dp
  integer, parameter :: maxc = 64          ! candidates per linkage (at most ~20 are used)
  integer, parameter :: maxscan = 364      ! 1 deg scan of one turn (+ ends)
  integer, parameter :: maxbr = 64         ! speed brackets per linkage
  real(dp), parameter :: scan_step = 1.0_dp   ! [deg] the fine grid
  integer, parameter :: coarse_every = 6      ! coarse scan: every 6th fine point (6 deg)
  integer, parameter :: max_depth = 10        ! bisections of a suspicious 1 deg interval
  integer, parameter :: lb = 128              ! linkages per block of the batched evaluation
  integer, parameter :: maxiv = 8             ! assembled intervals of one linkage (at most 5)
  integer, parameter :: maxcl = 64            ! candidates of one linkage, all its intervals
  ! candidate kinds: where |A O_B| can be extreme (evaluated) or not (a collinear angle, evaluated
  ! only near one of the others)
  integer, parameter :: ck_end = 1, ck_fixed = 2, ck_zero = 3

  !> one linkage's plan between the closed-form part and the batched states
  type :: plan
    real(dp) :: p, q, r, s, lo, hie, sgn
    integer :: branch, niv, nc(maxiv), q0, m0, nq, nm
    logical :: states, fast, peaks
    real(dp) :: omega
    real(dp) :: cand(maxcl), ia(maxiv), ib(maxiv)
    integer :: kind(maxcl), c0(maxiv)
  end type plan

  integer, parameter :: lbp = 32              ! linkages per batched peak search
  !> one linkage's peak search (peaks_block): its grid, coarse and refined speeds (w(:, k): omega3,
  !> alpha3, omega2, alpha2 at grid point k, together in memory), brackets: [ba, bb] with alpha
  !> fa at its lower end (its sign tells the ends apart), of speed bcol (1 rocker, 2 coupler), the next point (then the root) tx,
  !> omega at the root wr, state (br_*)
  type :: peakplan
    real(dp) :: p, q, r, s, sgn, omega, lo, hie, h
    integer :: branch, row, m, nco, nref, nb
    integer :: ci(maxscan), rj(maxscan), bcol(maxbr), state(maxbr)
    real(dp) :: w(4, maxscan), ba(maxbr), bb(maxbr), fa(maxbr), tx(maxbr), wr(maxbr), dxo(maxbr)
  end type peakplan
  !> a bracket's state: its root still sought, found (tx, wr), or lost (a state not ok on the way)
  integer, parameter :: br_open = 0, br_root = 1, br_lost = 2
  !> a root is taken when the Newton step from a point is at most newton_tol [rad]: the next
  !> iterate, within about newton_tol**2 of the root (quadratic convergence), and omega there from
  !> the point's Taylor polynomial (omega, alpha, jerk), exact to O(newton_tol**3)
  real(dp), parameter :: newton_tol = 1.0e-7_dp

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
    type(plan), allocatable :: pl(:)
    type(peakplan), allocatable :: pk(:)
    real(dp), allocatable :: rows(:, :), qc(:, :), qm(:, :)
    ! the peak search's queues and work space (peaks_block), allocated once for lbp linkages
    real(dp), allocatable :: qs(:, :), qg(:, :), sd(:, :), okc(:)
    integer, allocatable :: who(:, :)
    real(dp) :: par(npar)
    integer :: i0, m, l, nq, nm, npk
    ! per block: the plans, the rows, and the two queues of states (columns: crank angle [rad],
    ! p, q, r, s, branch sign, then the result and the status): the rocker angle at the
    ! candidates, the rocker speed halfway between them
    allocate (pl(lb), pk(lbp), rows(ncol, lb), qc(lb*maxcl, 8), qm(lb*maxcl + maxcl, 8))   ! qm: room for halfway
    if (iand(passes, pass_peaks) /= 0) allocate (qs(maxscan*lbp + maxbr*lbp, 13), qg(maxscan*lbp, 11), &
      who(maxscan*lbp + maxbr*lbp, 2), sd(2*maxscan*lbp, 5), okc(2*maxscan*lbp))
    do i0 = 1, n, lb
      m = min(lb, n - i0 + 1)
      nq = 0
      nm = 0
      do l = 1, m
        par = params(i0 + l - 1, :)
        call prepare(par, passes, pl(l), rows(:, l), qc, nq, qm, nm)
      end do
      call batch_states(nq, qc, .false.)
      call batch_states(nm, qm, .true.)
      npk = 0
      do l = 1, m
        call finish(params(i0 + l - 1, 5), passes, pl(l), rows(:, l), qc, qm)
        if (pl(l)%peaks) then
          npk = npk + 1
          pk(npk)%p = pl(l)%p
          pk(npk)%q = pl(l)%q
          pk(npk)%r = pl(l)%r
          pk(npk)%s = pl(l)%s
          pk(npk)%sgn = pl(l)%sgn
          pk(npk)%omega = pl(l)%omega
          pk(npk)%lo = pl(l)%lo
          pk(npk)%hie = pl(l)%hie
          pk(npk)%branch = pl(l)%branch
          pk(npk)%row = l
          if (npk == lbp) then
            call peaks_block(npk, pk, iand(passes, pass_dense_scan) /= 0, rows, qs, qg, who, sd, okc)
            npk = 0
          end if
        end if
      end do
      if (npk > 0) call peaks_block(npk, pk, iand(passes, pass_dense_scan) /= 0, rows, qs, qg, who, sd, okc)
      res(i0:i0 + m - 1, :) = transpose(rows(:, 1:m))
    end do
  end subroutine summaries

  !> States of the n positions queued in q (columns 1-6: crank angle [rad], p, q, r, s, branch
  !> sign) at unit crank speed: column 7 the rocker angle [rad] (rates: the rocker speed
  !> [rad/s]), column 8 the status code; in blocks of nb positions, each with its own linkage.
  subroutine batch_states(n, q, rates)
    integer, intent(in) :: n
    real(dp), intent(inout), contiguous :: q(:, :)
    logical, intent(in) :: rates
    real(dp) :: sn(nblk), c(nblk), xa(nblk), ya(nblk), xb(nblk), yb(nblk), e2x(nblk), e2y(nblk), e3x(nblk), e3y(nblk), &
                s23(nblk), c23(nblk), w2(nblk), a2(nblk), a3(nblk)
    integer :: k0, m
    do k0 = 1, n, nblk
      m = min(nblk, n - k0 + 1)
      call pose_block(m, q(k0:k0 + m - 1, 1), q(k0:k0 + m - 1, 2), q(k0:k0 + m - 1, 3), q(k0:k0 + m - 1, 4), &
                      q(k0:k0 + m - 1, 5), q(k0:k0 + m - 1, 6), sn, c, xa, ya, xb, yb, e2x, e2y, e3x, e3y, &
                      s23, c23, q(k0:k0 + m - 1, 8))
      if (rates) then
        call rates_block(m, q(k0:k0 + m - 1, 3), q(k0:k0 + m - 1, 4), q(k0:k0 + m - 1, 5), 1.0_dp, 0.0_dp, &
                         sn, c, e2x, e2y, e3x, e3y, s23, c23, q(k0:k0 + m - 1, 8), w2, q(k0:k0 + m - 1, 7), a2, a3)
      else
        call angles_block(m, e2x, e2y, e3x, e3y, s23, c23, q(k0:k0 + m - 1, 8), q(k0:k0 + m - 1, 7))
      end if
    end do
  end subroutine batch_states

  !> The closed-form part of one linkage's summary (see summaries for the columns): class,
  !> limits, toggles, assembled intervals and, for the transmission and rocker passes, the
  !> candidate crank angles of each interval; the states the rocker figures need are queued
  !> (qc: the candidates, qm: halfway between them) for the block's batched evaluation.
  subroutine prepare(par, passes, pl, row, qc, nq, qm, nm)
    real(dp), intent(in) :: par(npar)
    integer, intent(in) :: passes
    type(plan), intent(out) :: pl
    real(dp), intent(out) :: row(ncol)
    real(dp), intent(inout) :: qc(:, :), qm(:, :)
    integer, intent(inout) :: nq, nm
    real(dp) :: p, q, r, s, lo, hi, hie, lim(4), bp(maxc), zer(4), dd(2), x, y2, phi, t, d, total, tz
    integer :: nlim, nbp, nz, nc, c0, i, j, k, ntog, kmin, kmax
    logical :: okm, want_mu, want_rocker

    p = par(1)
    q = par(2)
    r = par(3)
    s = par(4)
    row = 0.0_dp
    want_mu = iand(passes, pass_transmission) /= 0
    want_rocker = iand(passes, pass_rocker) /= 0
    pl%p = p
    pl%q = q
    pl%r = r
    pl%s = s
    pl%branch = merge(1, -1, par(8) >= 0.0_dp)
    pl%sgn = real(pl%branch, dp)
    pl%niv = 0
    pl%peaks = .false.
    pl%states = .false.
    pl%fast = .false.
    pl%nq = 0
    pl%nm = 0
    lo = min(par(6), par(7))
    hi = max(par(6), par(7))
    hie = min(hi, lo + 360.0_dp)
    pl%lo = lo
    pl%hie = hie
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
      call single_angle(p, q, r, s, par(5), lo, pl%branch, passes, row)
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
    do i = 1, nbp - 1
      if (bp(i + 1) <= bp(i)) cycle
      d = dist(p, q, 0.5_dp*(bp(i) + bp(i + 1)))
      okm = d >= abs(r - s) .and. d <= r + s
      if (.not. okm) cycle
      if (pl%niv > 0) then
        if (pl%ib(pl%niv) == bp(i)) then      ! touches the previous piece (toggle inside): merge
          pl%ib(pl%niv) = bp(i + 1)
          cycle
        end if
      end if
      pl%niv = pl%niv + 1
      pl%ia(pl%niv) = bp(i)
      pl%ib(pl%niv) = bp(i + 1)
    end do
    if (pl%niv == 0) return             ! not assemblable anywhere in the range
    row(2) = 1.0_dp
    total = 0.0_dp
    do i = 1, pl%niv
      total = total + (pl%ib(i) - pl%ia(i))
    end do
    row(3) = min(1.0_dp, total/(hie - lo))
    ! a full turn whose first and last intervals meet at lo = hie - 360 is one motion: join them
    ! (crank angles below lo are reported one turn up)
    if (pl%niv > 1 .and. hie - lo >= 360.0_dp .and. pl%ia(1) == lo .and. pl%ib(pl%niv) == hie) then
      pl%ia(1) = pl%ia(pl%niv) - 360.0_dp
      pl%niv = pl%niv - 1
    end if
    if (.not. (want_mu .or. want_rocker)) return

    ! ---- crank angles where omega3 = 0 (crank and coupler collinear), any branch; atan2 once
    ! per pair (it is odd in y)
    nz = 0
    dd = [q + r, abs(q - r)]
    do k = 1, 2
      if (dd(k) <= 0.0_dp) cycle
      x = (dd(k)*dd(k) + p*p - s*s)/(2*p)
      y2 = dd(k)*dd(k) - x*x
      if (y2 < 0.0_dp) cycle
      tz = atan2(sqrt(y2), x)
      do j = -1, 1, 2
        phi = (j*tz)/rad
        if (k == 2 .and. r > q) phi = phi + 180.0_dp   ! folded with the coupler longer: B opposite A
        nz = nz + 1
        zer(nz) = modulo(phi, 360.0_dp)
      end do
    end do

    ! ---- per interval: candidates (ends, 0/180 deg, omega3 zeros, inner breakpoints), sorted
    c0 = 0
    do i = 1, pl%niv
      nc = 1
      pl%cand(c0 + 1) = pl%ia(i)
      pl%kind(c0 + 1) = ck_end
      call add_kind(0.0_dp, ck_fixed)
      call add_kind(180.0_dp, ck_fixed)
      do k = 1, nz
        call add_kind(zer(k), ck_zero)
      end do
      do k = 1, nlim
        call add_kind(lim(k), ck_fixed)
      end do
      nc = nc + 1
      pl%cand(c0 + nc) = pl%ib(i)
      pl%kind(c0 + nc) = ck_end
      call sort_kinds(pl%cand(c0 + 1:c0 + nc), pl%kind(c0 + 1:c0 + nc), nc)
      pl%c0(i) = c0
      pl%nc(i) = nc
      c0 = c0 + nc
    end do
    if (.not. want_rocker) return

    ! ---- the rocker's states: every candidate; halfway between them the sign of the rocker
    ! speed, except for a Grashof crank-rocker that turns fully (it swings less than half a turn)
    pl%states = .true.
    pl%fast = nint(row(1)) == gr_crank_rocker .and. nlim == 0
    pl%q0 = nq
    pl%m0 = nm
    do i = 1, pl%niv
      do j = 1, pl%nc(i)
        t = pl%cand(pl%c0(i) + j)
        call push(qc, nq, t*rad)
        if (j < pl%nc(i) .and. .not. pl%fast) &
          call push(qm, nm, (0.5_dp*(t + pl%cand(pl%c0(i) + j + 1)))*rad)
      end do
    end do
    pl%nq = nq - pl%q0
    pl%nm = nm - pl%m0

  contains

    !> add_periodic for the current interval's candidates, with their kind
    subroutine add_kind(base, kind)
      real(dp), intent(in) :: base
      integer, intent(in) :: kind
      integer :: before, jj
      before = nc
      call add_periodic(base, pl%ia(i), pl%ib(i), pl%cand(c0 + 1:c0 + maxcl - c0 - 1), nc)
      do jj = before + 1, nc
        pl%kind(c0 + jj) = kind
      end do
    end subroutine add_kind

    subroutine push(qq, nn, th)
      real(dp), intent(inout) :: qq(:, :)
      integer, intent(inout) :: nn
      real(dp), intent(in) :: th
      nn = nn + 1
      qq(nn, 1) = th
      qq(nn, 2) = p
      qq(nn, 3) = q
      qq(nn, 4) = r
      qq(nn, 5) = s
      qq(nn, 6) = pl%sgn
    end subroutine push
  end subroutine prepare

  !> The rest of one linkage's summary from its plan and the batched states: the transmission
  !> extremes, the rocker extremes (unwrapped along each interval), swing, full turn and time
  !> ratio, and the peak speeds (their own scan, when asked).
  subroutine finish(omega, passes, pl, row, qc, qm)
    real(dp), intent(in) :: omega
    integer, intent(in) :: passes
    type(plan), intent(inout) :: pl
    real(dp), intent(inout) :: row(ncol)
    real(dp), intent(inout) :: qc(:, :), qm(:, :)
    real(dp) :: dmin, dmax, dtol, d, tc, thr, umin, umax, tumin, tumax
    integer :: i, j, jj, c0, nc
    logical :: want_mu, want_rocker, near

    if (pl%niv == 0) return
    want_mu = iand(passes, pass_transmission) /= 0
    want_rocker = iand(passes, pass_rocker) /= 0
    if (want_mu .or. want_rocker) then
      ! transmission angle: extremes of d among the candidates (ascending, first wins ties);
      ! a collinear angle is evaluated only where a tie with an end, a limit or 0/180 deg is
      ! possible (d is monotone between those, so elsewhere it is no extreme and ties none)
      dmin = huge(1.0_dp)
      dmax = -1.0_dp
      dtol = 1.0e-12_dp*(pl%p + pl%q)
      thr = 1.0e-3_dp*(pl%p + pl%q)/sqrt(pl%p*pl%q)/rad
      do i = 1, pl%niv
        c0 = pl%c0(i)
        nc = pl%nc(i)
        do j = 1, nc
          if (pl%kind(c0 + j) == ck_zero) then
            near = .false.
            do jj = 1, nc
              if (pl%kind(c0 + jj) /= ck_zero .and. abs(pl%cand(c0 + jj) - pl%cand(c0 + j)) <= thr) near = .true.
            end do
            if (.not. near) cycle
          end if
          d = dist(pl%p, pl%q, pl%cand(c0 + j))
          tc = pl%cand(c0 + j)
          if (tc < pl%lo) tc = tc + 360.0_dp
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
      end do
      if (want_mu) then
        row(4) = mu_of(pl%r, pl%s, dmin)
        row(6) = mu_of(pl%r, pl%s, dmax)
      else
        row(5) = 0.0_dp
        row(7) = 0.0_dp
      end if
      if (want_rocker) then
        call unwrap(pl, qc, qm, umin, umax, tumin, tumax)
        if (pl%fast .and. umax - umin >= pi - 1.0e-3_dp) then
          ! nearly half a turn: take the rocker speed's sign halfway after all
          call halfway(pl, qm)
          pl%fast = .false.
          call unwrap(pl, qc, qm, umin, umax, tumin, tumax)
        end if
        call rocker_figures(row, pl, umin, umax, tumin, tumax)
      end if
    end if

    ! ---- peak speeds: only without a toggle in the range (then the range is one interval);
    ! searched for the block's linkages together (peaks_block)
    pl%peaks = iand(passes, pass_peaks) /= 0 .and. nint(row(14)) == 0 .and. pl%niv == 1
    pl%omega = omega
  end subroutine finish

  !> The rocker's angle unwrapped along each assembled interval of a plan (monotonic between
  !> candidates: the sign of the rocker speed halfway decides the direction, unless the plan is
  !> fast), a later interval placed on the turn nearest to the first one's centre; its
  !> extremes [rad] and their crank angles [deg].  A state the kernel finds just outside the
  !> assemblable set (rounding at a limit angle) or indeterminate is re-evaluated 1e-12 rad
  !> inside the interval.
  subroutine unwrap(pl, qc, qm, umin, umax, tumin, tumax)
    type(plan), intent(in) :: pl
    real(dp), intent(inout) :: qc(:, :), qm(:, :)
    real(dp), intent(out) :: umin, umax, tumin, tumax
    real(dp) :: u(maxcl), ushift, c1, delta, sg, t, tc, a, b
    integer :: i, j, c0, nc, kq, km
    logical :: first
    first = .true.
    umin = 0
    umax = 0
    tumin = 0
    tumax = 0
    kq = pl%q0
    km = pl%m0
    do i = 1, pl%niv
      c0 = pl%c0(i)
      nc = pl%nc(i)
      a = pl%ia(i)
      b = pl%ib(i)
      call retry(qc, kq + 1, kq + nc, 2)
      if (.not. pl%fast) call retry(qm, km + 1, km + nc - 1, 9)
      u(1) = qc(kq + 1, 7)
      do j = 1, nc - 1
        sg = 0.0_dp
        if (.not. pl%fast) sg = qm(km + j, 7)            ! omega3 at the midpoint
        delta = qc(kq + j + 1, 7) - qc(kq + j, 7)
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
        tc = pl%cand(c0 + j)
        if (tc < pl%lo) tc = tc + 360.0_dp
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
      kq = kq + nc
      if (.not. pl%fast) km = km + nc - 1
    end do

  contains

    !> queue rows k1..k2 whose state is not placed: again 1e-12 rad inside [a, b], the queue's
    !> value taken from column col of exact_states' out (2 the rocker angle, 9 its speed)
    subroutine retry(qq, k1, k2, col)
      real(dp), intent(inout) :: qq(:, :)
      integer, intent(in) :: k1, k2, col
      real(dp) :: one(1), o1(1, 11)
      integer :: s1(1), k
      do k = k1, k2
        if (nint(qq(k, 8)) == st_no_assembly .or. nint(qq(k, 8)) == st_indeterminate) then
          one(1) = qq(k, 1) + merge(1.0e-12_dp, -1.0e-12_dp, qq(k, 1)/rad <= 0.5_dp*(a + b))
          call exact_states(1, one, pl%p, pl%q, pl%r, pl%s, 1.0_dp, 0.0_dp, pl%branch, o1, s1)
          qq(k, 7) = o1(1, col)
          qq(k, 8) = real(s1(1), dp)
        end if
      end do
    end subroutine retry
  end subroutine unwrap

  !> Queue-free evaluation of a plan's halfway states (a fast plan whose swing turned out near
  !> half a turn): appended to qm after the block's, the plan pointing at them.
  subroutine halfway(pl, qm)
    type(plan), intent(inout) :: pl
    real(dp), intent(inout) :: qm(:, :)
    real(dp) :: th(maxcl)
    real(dp), allocatable :: o(:, :)
    integer, allocatable :: st(:)
    integer :: i, j, n, c0
    n = 0
    do i = 1, pl%niv
      c0 = pl%c0(i)
      do j = 1, pl%nc(i) - 1
        n = n + 1
        th(n) = (0.5_dp*(pl%cand(c0 + j) + pl%cand(c0 + j + 1)))*rad
      end do
    end do
    allocate (o(n, 11), st(n))
    call exact_states(n, th(1:n), pl%p, pl%q, pl%r, pl%s, 1.0_dp, 0.0_dp, pl%branch, o, st)
    pl%m0 = size(qm, 1) - n
    qm(pl%m0 + 1:pl%m0 + n, 1) = th(1:n)
    qm(pl%m0 + 1:pl%m0 + n, 7) = o(:, 9)
    qm(pl%m0 + 1:pl%m0 + n, 8) = real(st, dp)
    pl%nm = n
  end subroutine halfway

  !> Rocker extremes, swing, full turn and time ratio from the unwrapped extremes.
  subroutine rocker_figures(row, pl, umin, umax, tumin, tumax)
    real(dp), intent(inout) :: row(ncol)
    type(plan), intent(in) :: pl
    real(dp), intent(in) :: umin, umax, tumin, tumax
    real(dp) :: t
    row(8) = fold360(umin/rad)
    row(9) = tumin
    row(10) = fold360(umax/rad)
    row(11) = tumax
    if (row(3) >= 1.0_dp .and. pl%niv == 1 .and. (umax - umin) >= twopi - 1.0e-6_dp) then
      row(13) = 1.0_dp
      row(12) = 360.0_dp
    else
      row(12) = (umax - umin)/rad
    end if

    ! ---- time ratio: a full turn without toggles, the rocker oscillating
    if (pl%hie - pl%lo >= 360.0_dp .and. row(3) >= 1.0_dp .and. pl%niv == 1 .and. nint(row(14)) == 0 .and. &
        row(13) == 0.0_dp) then
      t = modulo(tumax - tumin, 360.0_dp)
      if (t > 0.0_dp .and. t < 360.0_dp) row(19) = max(t, 360.0_dp - t)/min(t, 360.0_dp - t)
    end if
  end subroutine rocker_figures

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

  !> sort (the same insertion sort, so the same order) of x(1:m), carrying each value's kind along.
  pure subroutine sort_kinds(x, kind, m)
    real(dp), intent(inout) :: x(:)
    integer, intent(inout) :: kind(:)
    integer, intent(in) :: m
    real(dp) :: t
    integer :: i, j, kt
    do i = 2, m
      t = x(i)
      kt = kind(i)
      j = i - 1
      do while (j >= 1)
        if (x(j) <= t) exit
        x(j + 1) = x(j)
        kind(j + 1) = kind(j)
        j = j - 1
      end do
      x(j + 1) = t
      kind(j + 1) = kt
    end do
  end subroutine sort_kinds

  !> Distance |A O_B| at crank angle t [deg].
  pure real(dp) function dist(p, q, t)
    real(dp), intent(in) :: p, q, t
    dist = sqrt(max(p*p + q*q - 2*p*q*cos_deg(t), 0.0_dp))
  end function dist

  !> cos(t rad) for t [deg]: libm's, but at a whole multiple of 180 deg (|t| <= 1e6) its exact
  !> value +-1, which libm returns there too (the argument's rounding moves cos by far less than
  !> half an ulp) -- without the call.
  pure real(dp) function cos_deg(t)
    real(dp), intent(in) :: t
    real(dp) :: k
    k = anint(t/180.0_dp)
    if (k*180.0_dp == t .and. abs(t) <= 1.0e6_dp) then
      cos_deg = merge(1.0_dp, -1.0_dp, modulo(k, 2.0_dp) == 0.0_dp)
    else
      cos_deg = cos(t*rad)
    end if
  end function cos_deg

  !> Transmission angle [deg] for |A O_B| = d, d clamped to the assemblable range.
  pure real(dp) function mu_of(r, s, d)
    real(dp), intent(in) :: r, s, d
    real(dp) :: dc
    dc = min(max(d, abs(r - s)), r + s)
    mu_of = acos(min(1.0_dp, max(-1.0_dp, (r*r + s*s - dc*dc)/(2*r*s))))/rad
  end function mu_of


  !> Rocker angle folded into [0, 360) [deg].
  pure real(dp) function fold360(a)
    real(dp), intent(in) :: a
    fold360 = modulo(a, 360.0_dp)
    if (fold360 >= 360.0_dp - 1.0e-9_dp) fold360 = 0.0_dp
  end function fold360


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

  !> omega3, alpha3, omega2, alpha2 (unit crank speed) and status at crank angles t(1:np) [rad]:
  !> fourbar's pose and rates stages only (the angles are not needed), the bits of exact_states'.
  subroutine speeds_at(np, t, p, q, r, s, branch, w3, a3, w2, a2, ist)
    integer, intent(in) :: np, branch
    real(dp), intent(in) :: t(np), p, q, r, s
    real(dp), intent(inout) :: w3(np), a3(np), w2(np), a2(np)
    integer, intent(inout) :: ist(np)
    real(dp) :: pb(nblk), qb(nblk), rb(nblk), sb(nblk), gb(nblk), sn(nblk), c(nblk), xa(nblk), ya(nblk), xb(nblk), yb(nblk), &
                e2x(nblk), e2y(nblk), e3x(nblk), e3y(nblk), s23(nblk), c23(nblk), st(nblk)
    integer :: k0, m
    m = min(nblk, np)
    pb(1:m) = p
    qb(1:m) = q
    rb(1:m) = r
    sb(1:m) = s
    gb(1:m) = merge(1.0_dp, -1.0_dp, branch >= 0)
    do k0 = 1, np, nblk
      m = min(nblk, np - k0 + 1)
      call pose_block(m, t(k0:k0 + m - 1), pb, qb, rb, sb, gb, sn, c, xa, ya, xb, yb, e2x, e2y, e3x, e3y, &
                      s23, c23, st)
      call rates_block(m, qb, rb, sb, 1.0_dp, 0.0_dp, sn, c, e2x, e2y, e3x, e3y, s23, c23, st, &
                       w2(k0:k0 + m - 1), w3(k0:k0 + m - 1), a2(k0:k0 + m - 1), a3(k0:k0 + m - 1))
      ist(k0:k0 + m - 1) = nint(st(1:m))
    end do
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

  !> smooth() of ns grid steps at once: sd(j, 1:5) a step's fa, fb, da, db and h; ok(j) 1 where
  !> smooth(fa, fb, da, db, h), else 0 (the same arithmetic, branch-free so that it vectorises).
  subroutine smooth_steps(ns, sd, ok)
    integer, intent(in) :: ns
    real(dp), intent(in) :: sd(:, :)
    real(dp), intent(inout) :: ok(:)
    real(dp) :: da, db, sg, a, b, cc, xs, qmin
    integer :: j
    ! hot-loop: fourbar_summary smooth steps
    do j = 1, ns
      da = sd(j, 3)
      db = sd(j, 4)
      sg = sign(1.0_dp, da)
      a = sg*da
      b = sg*db
      cc = 6.0_dp*(sg*(sd(j, 2) - sd(j, 1))/sd(j, 5) - 0.5_dp*(a + b))
      qmin = min(a, b)
      xs = 0.5_dp + (b - a)/merge(2.0_dp*cc, -1.0_dp, cc < 0.0_dp)
      qmin = merge(min(qmin, a*(1.0_dp - xs) + b*xs + cc*xs*(1.0_dp - xs)), qmin, &
                   cc < 0.0_dp .and. xs > 0.0_dp .and. xs < 1.0_dp)
      ok(j) = merge(1.0_dp, 0.0_dp, da*db > 0.0_dp .and. qmin >= 0.5_dp*min(a, b))
    end do
  end subroutine smooth_steps

  !> Peak |omega3| and |omega2| over [lo, hie] (assembled throughout, no toggle) of the n
  !> linkages of pk (one block): the coarse scan, refined to the 1 deg grid where needed (module
  !> header); every sign change of the matching angular acceleration is a bracket whose root is
  !> found by safeguarded Newton steps on alpha (its derivative, the jerk, from the kernel),
  !> started at the root of the cubic Hermite model's slope.  Each stage evaluates the speeds of
  !> every linkage of the block in one batched call (the coarse scan, the refined grid points,
  !> each Newton iteration of the brackets not yet converged).
  subroutine peaks_block(n, pk, dense, rows, qs, qg, who, sd, okc)
    integer, intent(in) :: n
    type(peakplan), intent(inout) :: pk(:)
    logical, intent(in) :: dense
    real(dp), intent(inout) :: rows(:, :)
    ! queues (rows of batch_speeds) and work space for up to lbp linkages: qs the coarse scan and
    ! the Newton iterations; qg the refined grid points; who a queued row's linkage and bracket;
    ! sd, okc the smooth test's steps
    real(dp), intent(inout), contiguous :: qs(:, :), qg(:, :), sd(:, :), okc(:)
    integer, intent(inout) :: who(:, :)
    real(dp) :: tg(maxscan), g(maxscan, 4)
    real(dp) :: hc, da, db, sg, av, bv, cv, qv, xs, qm, v, wv, jv, dx, tn, best(2), bestat(2)
    integer :: l, k, j, c, nq, nco, ka, kb, jr, it, iq, nr, ns

    ! ---- the coarse scan (first and last grid points included) of every linkage, one call
    nq = 0
    do l = 1, n
      pk(l)%m = min(maxscan, max(2, ceiling((pk(l)%hie - pk(l)%lo)/scan_step) + 1))
      pk(l)%h = (pk(l)%hie - pk(l)%lo)/(pk(l)%m - 1)
      nco = 0
      k = 1
      do
        nco = nco + 1
        pk(l)%ci(nco) = k
        nq = nq + 1
        qs(nq, 1) = grid_angle(pk(l), k)
        if (k == pk(l)%m) exit
        k = min(k + coarse_every, pk(l)%m)
      end do
      pk(l)%nco = nco
      pk(l)%nb = 0
      call fill(pk(l), nq - nco + 1, nq)
    end do
    call batch_speeds(nq, qs, .false.)
    iq = 0
    do l = 1, n   ! (a linkage's coarse points are consecutive rows of qs)
      do j = 1, pk(l)%nco
        pk(l)%w(:, pk(l)%ci(j)) = qs(iq + j, 7:10)
      end do
      iq = iq + pk(l)%nco
    end do

    ! ---- the coarse test of every coarse interval, both speeds: smooth (see smooth: no extremum
    ! inside), or one clean crossing (alpha changes sign at the ends and the Hermite model's
    ! slope, a quadratic, is monotonic with a margin: one root, a bracket as it stands); any other
    ! interval is refined: its 1 deg grid points, of every linkage, in one call
    iq = 0
    nq = 0
    do l = 1, n
      nco = pk(l)%nco
      do j = 1, nco
        tg(j) = qs(iq + j, 1)
        g(j, :) = qs(iq + j, 7:10)
      end do
      iq = iq + nco
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
          okc(j) = okc(j)*merge(1.0_dp, 0.0_dp, (da*db > 0.0_dp .and. qm >= 0.5_dp*qv) .or. &
                                (da*db < 0.0_dp .and. abs(cv) <= 0.5_dp*(av - bv)))
        end do
      end do
      pk(l)%nref = 0
      nr = nq
      do j = 1, nco - 1
        ka = pk(l)%ci(j)
        kb = pk(l)%ci(j + 1)
        if (okc(j) > 0.0_dp .and. kb - ka >= 2 .and. .not. dense) then
          do c = 1, 2
            if (g(j, 2*c)*g(j + 1, 2*c) < 0.0_dp) call add_bracket(pk(l), tg(j), tg(j + 1), g(j, 2*c - 1), &
                                                                   g(j + 1, 2*c - 1), g(j, 2*c), g(j + 1, 2*c), c)
          end do
          cycle
        end if
        pk(l)%nref = pk(l)%nref + 1
        pk(l)%rj(pk(l)%nref) = j
        do k = ka + 1, kb - 1
          nq = nq + 1
          qg(nq, 1) = grid_angle(pk(l), k)
        end do
      end do
      if (nq > nr) call fill_q(qg, pk(l), nr + 1, nq)
    end do
    if (nq > 0) then
      call batch_speeds(nq, qg, .false.)
      iq = 0
      do l = 1, n   ! (a linkage's refined points are consecutive rows of qg, in the order queued)
        do jr = 1, pk(l)%nref
          do k = pk(l)%ci(pk(l)%rj(jr)) + 1, pk(l)%ci(pk(l)%rj(jr) + 1) - 1
            iq = iq + 1
            pk(l)%w(:, k) = qg(iq, 7:10)
          end do
        end do
      end do
    end if

    ! ---- brackets of alpha sign changes on the grid of the refined intervals, both speeds; a
    ! suspicious step bisected (hidden), linkage by linkage.  The smooth test of every such grid
    ! step first, all linkages and both speeds in one vectorised loop (one step at a time, its
    ! two divisions would wait on each other)
    ns = 0
    if (.not. dense) then
      do l = 1, n
        do c = 1, 2
          do jr = 1, pk(l)%nref
            do k = pk(l)%ci(pk(l)%rj(jr)), pk(l)%ci(pk(l)%rj(jr) + 1) - 1
              ns = ns + 1
              sd(ns, 1) = pk(l)%w(2*c - 1, k)
              sd(ns, 2) = pk(l)%w(2*c - 1, k + 1)
              sd(ns, 3) = pk(l)%w(2*c, k)
              sd(ns, 4) = pk(l)%w(2*c, k + 1)
              sd(ns, 5) = grid_angle(pk(l), k + 1) - grid_angle(pk(l), k)
            end do
          end do
        end do
      end do
      call smooth_steps(ns, sd, okc)
    end if
    ns = 0
    do l = 1, n
      do c = 1, 2
        do jr = 1, pk(l)%nref
          do k = pk(l)%ci(pk(l)%rj(jr)), pk(l)%ci(pk(l)%rj(jr) + 1) - 1
            ns = ns + 1
            associate (w => pk(l)%w)
              if (w(2*c, k)*w(2*c, k + 1) < 0.0_dp) then
                call add_bracket(pk(l), grid_angle(pk(l), k), grid_angle(pk(l), k + 1), w(2*c - 1, k), &
                                 w(2*c - 1, k + 1), w(2*c, k), w(2*c, k + 1), c)
              else if (dense) then
                cycle
              else if (okc(ns) == 0.0_dp) then
                call hidden(pk(l), grid_angle(pk(l), k), grid_angle(pk(l), k + 1), w(2*c - 1, k), w(2*c - 1, k + 1), &
                            w(2*c, k), w(2*c, k + 1), c, 1)
              end if
            end associate
          end do
        end do
      end do
    end do

    ! ---- the roots: safeguarded Newton (rtsafe) on alpha, every open bracket of every linkage
    ! advanced in one call per iteration.  A Newton step that would leave the bracket, or that
    ! would not halve the step before last, is a bisection; the bracket shrinks with every point.
    do it = 1, 100
      nq = 0
      do l = 1, n
        nr = nq
        do j = 1, pk(l)%nb
          if (pk(l)%state(j) /= br_open) cycle
          nq = nq + 1
          qs(nq, 1) = pk(l)%tx(j)
          who(nq, 1) = l
          who(nq, 2) = j
        end do
        if (nq > nr) call fill(pk(l), nr + 1, nq)
      end do
      if (nq == 0) exit
      call batch_speeds(nq, qs, .true.)
      do iq = 1, nq
        l = who(iq, 1)
        j = who(iq, 2)
        c = pk(l)%bcol(j)
        associate (ba => pk(l)%ba(j), bb => pk(l)%bb(j), fa => pk(l)%fa(j), &
                   tx => pk(l)%tx(j), dxo => pk(l)%dxo(j), state => pk(l)%state(j), wr => pk(l)%wr(j))
          if (nint(qs(iq, 11)) /= st_ok) then
            state = br_lost
            cycle
          end if
          wv = qs(iq, 5 + 2*c)
          v = qs(iq, 6 + 2*c)
          jv = qs(iq, 11 + c)
          if (v == 0.0_dp) then
            state = br_root
            wr = wv
            cycle
          end if
          if (sign(1.0_dp, v) == sign(1.0_dp, fa)) then   ! (alpha keeps its sign at each end)
            ba = tx
          else
            bb = tx
          end if
          dx = -v/jv
          tn = tx + dx
          if (.not. (tn > ba .and. tn < bb) .or. abs(2.0_dp*dx) > abs(dxo)) then
            dx = 0.5_dp*(bb - ba)
            tn = ba + dx
            if (dx <= 0.5e-12_dp) then   ! (bisected to 1e-12 rad: the point taken)
              state = br_root
              wr = wv
              cycle
            end if
          else if (abs(dx) <= newton_tol) then
            state = br_root
            tx = tn
            wr = wv + dx*(v + 0.5_dp*jv*dx)
            cycle
          end if
          dxo = dx
          tx = tn
        end associate
      end do
    end do

    ! pick the largest |omega| among the range ends and the roots (earliest on ties)
    do l = 1, n
      associate (w => pk(l)%w, m => pk(l)%m)
        do c = 1, 2
          best(c) = w(2*c - 1, 1)
          bestat(c) = grid_angle(pk(l), 1)
          if (abs(w(2*c - 1, m)) > abs(best(c))) then
            best(c) = w(2*c - 1, m); bestat(c) = grid_angle(pk(l), m)
          end if
        end do
      end associate
      do j = 1, pk(l)%nb
        if (pk(l)%state(j) /= br_root) cycle
        c = pk(l)%bcol(j)
        v = pk(l)%wr(j)
        if (abs(v) > abs(best(c)) .or. (abs(v) == abs(best(c)) .and. pk(l)%tx(j) < bestat(c))) then
          best(c) = v
          bestat(c) = pk(l)%tx(j)
        end if
      end do
      rows(15, pk(l)%row) = pk(l)%omega*best(1)
      rows(16, pk(l)%row) = bestat(1)/rad
      rows(17, pk(l)%row) = pk(l)%omega*best(2)
      rows(18, pk(l)%row) = bestat(2)/rad
    end do

  contains

    !> the linkage's parameters in queue rows k1..k2 of qs
    subroutine fill(pl1, k1, k2)
      type(peakplan), intent(in) :: pl1
      integer, intent(in) :: k1, k2
      call fill_q(qs, pl1, k1, k2)
    end subroutine fill
  end subroutine peaks_block

  !> A linkage's parameters (p, q, r, s, branch sign) in rows k1..k2 of a speeds queue.
  subroutine fill_q(q, pl1, k1, k2)
    real(dp), intent(inout) :: q(:, :)
    type(peakplan), intent(in) :: pl1
    integer, intent(in) :: k1, k2
    q(k1:k2, 2) = pl1%p
    q(k1:k2, 3) = pl1%q
    q(k1:k2, 4) = pl1%r
    q(k1:k2, 5) = pl1%s
    q(k1:k2, 6) = pl1%sgn
  end subroutine fill_q

  !> The k-th angle [rad] of a linkage's peak-search grid (its last point exactly the range's end).
  pure real(dp) function grid_angle(pk, k)
    type(peakplan), intent(in) :: pk
    integer, intent(in) :: k
    if (k == pk%m) then
      grid_angle = pk%hie*rad
    else
      grid_angle = (pk%lo + (k - 1)*pk%h)*rad
    end if
  end function grid_angle

  !> The speeds of the n positions queued in q (columns 1-6: crank angle [rad], p, q, r, s,
  !> branch sign) at unit crank speed: columns 7-10 omega3, alpha3, omega2, alpha2 (the order of
  !> speeds_at), 11 the status code, and with jerk 12-13 d alpha3 / d theta, d alpha2 / d theta;
  !> blocks of nblk positions, each with its own linkage.
  subroutine batch_speeds(n, q, jerk)
    integer, intent(in) :: n
    real(dp), intent(inout), contiguous :: q(:, :)
    logical, intent(in) :: jerk
    real(dp) :: sn(nblk), c(nblk), xa(nblk), ya(nblk), xb(nblk), yb(nblk), e2x(nblk), e2y(nblk), e3x(nblk), &
                e3y(nblk), s23(nblk), c23(nblk)
    integer :: k0, m
    do k0 = 1, n, nblk
      m = min(nblk, n - k0 + 1)
      call pose_block(m, q(k0:k0 + m - 1, 1), q(k0:k0 + m - 1, 2), q(k0:k0 + m - 1, 3), q(k0:k0 + m - 1, 4), &
                      q(k0:k0 + m - 1, 5), q(k0:k0 + m - 1, 6), sn, c, xa, ya, xb, yb, e2x, e2y, e3x, e3y, &
                      s23, c23, q(k0:k0 + m - 1, 11))
      call rates_block(m, q(k0:k0 + m - 1, 3), q(k0:k0 + m - 1, 4), q(k0:k0 + m - 1, 5), 1.0_dp, 0.0_dp, &
                       sn, c, e2x, e2y, e3x, e3y, s23, c23, q(k0:k0 + m - 1, 11), q(k0:k0 + m - 1, 9), &
                       q(k0:k0 + m - 1, 7), q(k0:k0 + m - 1, 10), q(k0:k0 + m - 1, 8))
      if (jerk) call jerks_block(m, q(k0:k0 + m - 1, 3), q(k0:k0 + m - 1, 4), q(k0:k0 + m - 1, 5), 1.0_dp, 0.0_dp, &
                                 sn, c, e2x, e2y, e3x, e3y, s23, c23, q(k0:k0 + m - 1, 11), q(k0:k0 + m - 1, 9), &
                                 q(k0:k0 + m - 1, 7), q(k0:k0 + m - 1, 10), q(k0:k0 + m - 1, 8), &
                                 q(k0:k0 + m - 1, 13), q(k0:k0 + m - 1, 12))
    end do
  end subroutine batch_speeds

  !> A bracket [a, b] of a sign change of alpha (speed col: 1 rocker, 2 coupler), omega ya, yb and
  !> alpha da, db at its ends: its first point the root of the slope of omega's cubic Hermite
  !> model, A (1 - x) + B x + C x (1 - x) with x = (t - a)/(b - a), A = da, B = db and C from the
  !> mean slope (one root in (0, 1), the ends' slopes having opposite signs); the secant's root
  !> where that is not found.
  subroutine add_bracket(pk, a, b, ya, yb, da, db, col)
    type(peakplan), intent(inout) :: pk
    real(dp), intent(in) :: a, b, ya, yb, da, db
    integer, intent(in) :: col
    real(dp) :: h, cc, beta, disc, sq, x
    if (pk%nb >= maxbr) return
    pk%nb = pk%nb + 1
    pk%ba(pk%nb) = a; pk%bb(pk%nb) = b
    pk%fa(pk%nb) = da
    pk%bcol(pk%nb) = col
    pk%state(pk%nb) = br_open
    pk%dxo(pk%nb) = 2.0_dp*(b - a)
    h = b - a
    cc = 6.0_dp*((yb - ya)/h - 0.5_dp*(da + db))
    ! slope da + beta x - cc x^2 = 0
    beta = db - da + cc
    x = da/(da - db)
    disc = beta*beta + 4.0_dp*da*cc
    if (cc /= 0.0_dp .and. disc >= 0.0_dp) then
      sq = beta + sign(sqrt(disc), beta)
      if (sq /= 0.0_dp) then
        if (sq/(2.0_dp*cc) > 0.0_dp .and. sq/(2.0_dp*cc) < 1.0_dp) then
          x = sq/(2.0_dp*cc)
        else if (-2.0_dp*da/sq > 0.0_dp .and. -2.0_dp*da/sq < 1.0_dp) then
          x = -2.0_dp*da/sq
        end if
      end if
    end if
    pk%tx(pk%nb) = a + x*h
  end subroutine add_bracket

  !> A grid interval whose ends agree in the sign of alpha but which is not smooth: bisected
  !> (max_depth levels) looking for a hidden pair of sign changes, each one a bracket.
  recursive subroutine hidden(pk, a, b, ya, yb, da, db, col, depth)
    type(peakplan), intent(inout) :: pk
    real(dp), intent(in) :: a, b, ya, yb, da, db
    integer, intent(in) :: col, depth
    real(dp) :: tm(1), o(1, 4), ym, dm
    integer :: sm(1)
    if (depth > max_depth) return
    tm(1) = 0.5_dp*(a + b)
    call speeds_at(1, tm, pk%p, pk%q, pk%r, pk%s, pk%branch, o(:, 1), o(:, 2), o(:, 3), o(:, 4), sm)
    if (sm(1) /= st_ok) return
    ym = o(1, 2*col - 1)
    dm = o(1, 2*col)
    if (da*dm < 0.0_dp) then
      call add_bracket(pk, a, tm(1), ya, ym, da, dm, col)
    else if (.not. smooth(ya, ym, da, dm, tm(1) - a)) then
      call hidden(pk, a, tm(1), ya, ym, da, dm, col, depth + 1)
    end if
    if (dm*db < 0.0_dp) then
      call add_bracket(pk, tm(1), b, ym, yb, dm, db, col)
    else if (.not. smooth(ym, yb, dm, db, b - tm(1))) then
      call hidden(pk, tm(1), b, ym, yb, dm, db, col, depth + 1)
    end if
  end subroutine hidden

end module fourbar_summary
