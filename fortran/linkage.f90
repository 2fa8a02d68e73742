!> Any planar linkage built from a driver and class-II Assur groups (dyads): kinematics,
!> kinetostatics (dyad by dyad, closed form), flywheel energy and batched summaries (issue 38).
!>
!> The mechanism is a program the Python layer (driver/linkage/_model.py) compiles from a deck:
!>
!>   links   1 = ground (the world frame), 2.. the moving links.  Every link has a frame: an
!>           origin and an x-axis (the unit vector (c, s)), with the origin's velocity and
!>           acceleration and the link's omega and alpha (ccw +).
!>   points  fixed to a link at (u, v) in its frame (ground: world coordinates):
!>           ipts(p) link, rpts(p, 1:2) u, v.
!>   guides  lines fixed to a link: through (gx, gy) in its frame at angle ga [rad] off its
!>           x-axis: igd(g) link, rgd(g, 1:3) gx, gy, ga.
!>   driver  idrv = (kind, anchor, link, slider); rdrv = (length or offset, rate, rate2)
!>           crank  (kind 1): link turns about ground point 'anchor' at the input angle x [rad];
!>                  its x-axis points at the pin (distance rdrv(1)); rate omega [rad/s],
!>                  rate2 alpha [rad/s^2].  Frame: origin the pivot.
!>           slider (kind 2): link slides along ground guide 'anchor'; its origin (the pin) is
!>                  at Pg + x u + e n (e = rdrv(1), n the left normal of the guide direction u);
!>                  rate v [length/s], rate2 a [length/s^2]; x-axis along u.
!>   dyads   idy(d, :) = (kind, a1, a2, link1, link2, slider), rdy(d, :) = (d1, d2, mode)
!>           RRR (1): a1, a2 points; link1 = a1 -> J3 (length d1), link2 = a2 -> J3 (d2).
!>                  mode +1: J3 left of the directed line a1 -> a2.  Frames: origins a1, a2,
!>                  x-axes towards J3.
!>           RRP (2): a1 a point, a2 a guide; link1 the rod a1 -> J3 (length d1), link2 the
!>                  block whose pin J3 runs on the line offset d2 to the left of the guide;
!>                  mode +1: J3 ahead of the foot of a1 along the guide.  (A PRR group is
!>                  this one with its links named the other way round.)  Block frame: origin
!>                  J3, x-axis along the guide.  Slide s: J3 along the guide from its point.
!>           RPR (3): a1, a2 points; link1 turns about a1 and carries a slot (a line offset
!>                  d1 to the left of its x-axis, along it); link2, the block pinned at a2,
!>                  slides in it.  mode +1: a2 ahead of the foot of a1 along the slot.
!>                  Frames: origins a1, a2, x-axes along the slot.  Slide s: a2 along the
!>                  slot from the foot of a1.
!>           PRP (4): a1, a2 guides; link1 slides on a1, link2 on a2, pinned together at J3,
!>                  J3 offset d1 left of guide a1 and d2 left of guide a2.  Frames: origin
!>                  J3, x-axes along the guides.  Slides s1, s2 of J3 along the guides.
!>           slider: the first slide column of the dyad (0: none); PRP uses two.
!>
!> Per position (columns of the outputs, positions first, Fortran order):
!>   lk(k, 1:3, l)  angle [rad, atan2 range], omega [rad/s], alpha [rad/s^2] of link l
!>   pk(k, 1:6, p)  x, y, vx, vy, ax, ay of point p
!>                  (the ground's columns -- link 1 and its points -- are not written: they are
!>                  constant, and the caller fills them once per buffer)
!>   sk(k, 1:3, j)  slide, slide rate and slide acceleration of slide j (relative to its guide)
!>   qa(k, d)       RRR: transmission angle between the two links at J3 [0, pi];
!>                  RRP: pressure angle between the rod and the guide [0, pi/2];
!>                  RPR: pressure angle atan(|offset| / |slide|); PRP: between n1 and u2 [rad]
!>   st(k, d)       0 ok, 1 cannot be assembled, 2 toggle (the dyad's two constraint directions
!>                  are parallel: velocities unbounded, set to 0), 3 indeterminate, 4 not placed
!>                  (a link it attaches to is not placed)
!> Rows of a dyad that is not placed are zero; rates are zero downstream of a toggle.
!>
!> Branch continuity: each dyad keeps its assembly mode, except where the motion passes
!> through a position at which both assemblies of a dyad meet and goes on (a change point):
!> there the assembly whose new joint is nearer to the quadratic extrapolation of the three
!> previous positions is taken, and kept from there on (positions must be in order).
!>
!> Forces (want bit 2): link l has mass rl(l, 1), centre of mass (rl(l, 2), rl(l, 3)) in its
!> frame, inertia rl(l, 4) about it; gravity grav(1:2) [m/s^2]; forces rld(i, 1:2) [N] at
!> points ild(i); torques rtq(l) [N m] on links; a force along a slider guide from a table
!> (ift, tab, rft: see guide_force).  Dyads are solved from the last to the first, each in
!> closed form from its two links' equations; the driver last.
!>   fk(k, 1:9, d)  the dyad's joints A, B, C, each (fx, fy, couple) [N, N m]:
!>                  RRR  A force on link1 at a1, B on link2 at a2, C link1 on link2 at J3;
!>                  RRP  A on the rod at a1, B guide on the block (normal force, couple),
!>                       C rod on block at J3;
!>                  RPR  A on link1 at a1, B on the block at a2, C link1 on the block
!>                       (normal force at a2, couple);
!>                  PRP  A guide a1 on link1, B guide a2 on link2, C link1 on link2 at J3.
!>   fd(k, 1:4)     crank: ground on crank at the pivot (fx, fy), 0, driving torque [N m];
!>                  slider: guide on the block (fx, fy normal), couple, driving force [N]
!>   sh(k, 1:3)     shaking force (x, y) [N]: the resultant of the forces the mechanism
!>                  exerts on the frame (joints, guide-force reactions, the driver's
!>                  reaction), and its moment about the world origin [N m]
module linkage
  use kinds, only: dp
  use vecmath, only: sincos_array, atan2_array
  implicit none
  private
  public :: analyse, table_energy, summaries

  integer, parameter, public :: st_ok = 0, st_no_assembly = 1, st_toggle = 2, st_indeterminate = 3, &
                                st_unplaced = 4
  !> status of a call of analyse: done, or refused (its arrays do not agree: a wrapper's mistake)
  integer, parameter, public :: call_ok = 0, call_bad_args = 1
  integer, parameter, public :: dy_rrr = 1, dy_rrp = 2, dy_rpr = 3, dy_prp = 4
  integer, parameter, public :: drv_crank = 1, drv_slider = 2
  !> want bits of analyse: what it computes besides the kinematics, and which outputs it writes
  !> (an output not asked for is not written: the caller's array keeps what it held; the status
  !> is always written)
  integer, parameter, public :: want_continuity = 1, want_forces = 2, want_angles = 4, want_link_rates = 8, &
                                want_points = 16, want_point_rates = 32, want_quality = 64, want_slides = 128
  !> every kinematic output
  integer, parameter, public :: want_kinematics = 252
  !> passes of summaries: the output's extremes (stroke, time ratio); the transmission and
  !> pressure angles; the links' and slides' peaks; the forces (torque, shaking, flywheel)
  integer, parameter, public :: pass_output = 1, pass_quality = 2, pass_peaks = 4, pass_forces = 8
  !> columns of a summary row before the per-element columns (see summaries), and per element
  integer, parameter, public :: nsum_head = 22, nsum_link = 2, nsum_slide = 4, nsum_dyad = 2
  !> columns of table_energy's result
  integer, parameter, public :: nenergy = 8

  !> rows of a block: its work arrays (the links' frames, the groups' attachments) stay in cache
  !> (112: measured against 64, 80, 96 and 128 with bench/bench_linkage.py's sizes, the best
  !> median at 200 000 inputs and no worse at 3600; 32 and 256 were slower)
  integer, parameter :: nb = 112
  real(dp), parameter :: tol = 1.0e-13_dp
  !> extremes within this fraction of the scale are ties: the first (the earliest input) is taken
  real(dp), parameter :: tie_rel = 1.0e-12_dp
  real(dp), parameter :: pi = 3.14159265358979323846_dp
  ! pose columns of a link in a block
  integer, parameter :: p_ox = 1, p_oy = 2, p_c = 3, p_s = 4, p_vx = 5, p_vy = 6, p_w = 7, p_ax = 8, &
                        p_ay = 9, p_al = 10, p_ok = 11, p_rt = 12, npose = 12
  ! attachment columns: a point uses 1:8, a guide 1:15
  integer, parameter :: natt = 15
  ! per-dyad extra columns of a block: status; y, x of the quality angle; slide 1 (s, rate,
  ! acceleration); slide 2; the new joint (x, y) and the other assembly's (x, y)
  integer, parameter :: nex = 13

contains

  ! ======================================================================== analysis

  !> Positions, velocities, accelerations (and forces with want bit 2) at the inputs x(1:n)
  !> (crank angle [rad] or slide [length], in order).  See the module header.  The mechanism's
  !> program comes packed (two arrays, so a call passes few arguments):
  !>   iprog: ng, nld, nt, then idrv(4), ipts(np), igd(ng), idy(nd, 6), ild(nld), ift(4)
  !>   rprog: rpts(np, 2), rgd(ng, 3), rdrv(3), rdy(nd, 3), rl(nl, 4), grav(2), rld(nld, 2),
  !>          rtq(nl), rft(3), tab(nt, 2) (column-major; the numbers of summaries' designs)
  !> info: 0, or call_bad_args when the arrays do not agree (sizes, force rows): nothing written.
  subroutine analyse(n, nl, np, nd, ns, nf, ni, nr, x, iprog, rprog, want, lk, pk, sk, qa, st, fk, fd, sh, info)
    !f2py threadsafe
    integer, intent(in) :: n, nl, np, nd, ns, nf, ni, nr, want   ! nf: rows of the force outputs (n, or 1 unused)
    real(dp), intent(in) :: x(n), rprog(nr)
    integer, intent(in) :: iprog(ni)
    ! outputs: overwritten (intent inout so that callers can reuse their buffers)
    real(dp), intent(inout) :: lk(n, 3, nl), pk(n, 6, np), sk(n, 3, ns), qa(n, nd), fk(nf, 9, nd), fd(nf, 4), &
                               sh(nf, 3)
    !f2py intent(in,out) :: lk, pk, sk, qa, fk, fd, sh
    integer, intent(inout) :: st(n, nd)
    !f2py intent(in,out) :: st
    integer, intent(out) :: info
    real(dp), allocatable :: pose(:, :, :), att(:, :, :, :)
    integer :: ng, nld, nt, i0(6), r0(10)
    info = call_bad_args
    if (ni < 3) return
    ng = iprog(1)
    nld = iprog(2)
    nt = iprog(3)
    if (ng < 1 .or. nld < 1 .or. nt < 1 .or. ni /= 3 + 4 + np + ng + 6*nd + nld + 4 .or. &
        nr /= 2*np + 3*ng + 3 + 3*nd + 4*nl + 2 + 2*nld + nl + 3 + 2*nt) return
    if (iand(want, want_forces) /= 0 .and. nf < n) return
    ! where each array starts in the packed program: passed in place (sequence association, no copy)
    i0 = [4, 8, 8 + np, 8 + np + ng, 8 + np + ng + 6*nd, 8 + np + ng + 6*nd + nld]
    r0(1) = 1
    r0(2) = r0(1) + 2*np      ! rgd
    r0(3) = r0(2) + 3*ng      ! rdrv
    r0(4) = r0(3) + 3         ! rdy
    r0(5) = r0(4) + 3*nd      ! rl
    r0(6) = r0(5) + 4*nl      ! grav
    r0(7) = r0(6) + 2         ! rld
    r0(8) = r0(7) + 2*nld     ! rtq
    r0(9) = r0(8) + nl        ! rft
    r0(10) = r0(9) + 3        ! tab
    info = call_ok
    allocate (pose(nb, npose, nl), att(nb, natt, 2, nd))
    call analyse_core(n, nl, np, ng, nd, ns, nld, nt, nf, x, iprog(i0(1)), rprog(r0(3)), iprog(i0(2)), rprog(r0(1)), &
                      iprog(i0(3)), rprog(r0(2)), iprog(i0(4)), rprog(r0(4)), rprog(r0(5)), rprog(r0(6)), &
                      iprog(i0(5)), rprog(r0(7)), rprog(r0(8)), iprog(i0(6)), rprog(r0(10)), rprog(r0(9)), want, 0, 0, &
                      lk, pk, sk, qa, st, fk, fd, sh, pose, att, .true.)
  end subroutine analyse

  !> analyse's work, with the block work arrays of the caller (summaries makes them once for
  !> all its designs): pose(nb, npose, nl) and att(nb, natt, 2, nd), overwritten.  asel, rsel:
  !> the links whose angles (want_angles) and rates (want_link_rates) are written: 0 all, l > 0
  !> link l only (the summaries' output link).  fresh: pose is new (else it holds an earlier
  !> call's of the same mechanism and number of inputs: the ground's frame and the crank's
  !> constant columns are kept, its design-dependent ones rewritten).
  subroutine analyse_core(n, nl, np, ng, nd, ns, nld, nt, nf, x, idrv, rdrv, ipts, rpts, igd, rgd, idy, rdy, &
                          rl, grav, ild, rld, rtq, ift, tab, rft, want, asel, rsel, lk, pk, sk, qa, st, fk, fd, &
                          sh, pose, att, fresh)
    integer, intent(in) :: n, nl, np, ng, nd, ns, nld, nt, nf   ! nf: rows of the force outputs (n, or 1 unused)
    integer, intent(in) :: asel, rsel
    logical, intent(in) :: fresh
    real(dp), intent(in) :: x(n), rdrv(3), rpts(np, 2), rgd(ng, 3), rdy(nd, 3), rl(nl, 4), grav(2)
    integer, intent(in) :: idrv(4), ipts(np), igd(ng), idy(nd, 6), ild(nld), ift(4), want
    real(dp), intent(in) :: rld(nld, 2), rtq(nl), tab(nt, 2), rft(3)
    ! outputs: overwritten (intent inout so that callers can reuse their buffers)
    real(dp), intent(inout) :: lk(n, 3, nl), pk(n, 6, np), sk(n, 3, ns), qa(n, nd), fk(nf, 9, nd), fd(nf, 4), &
                               sh(nf, 3)
    integer, intent(inout) :: st(n, nd)
    real(dp), intent(inout) :: pose(nb, npose, nl), att(nb, natt, 2, nd)
    real(dp), allocatable :: modes(:, :), chr(:, :, :)
    real(dp) :: ring(3, 4, nd)
    integer :: d, first, k0, m, flagk, mb
    logical :: cont, store

    ! each group's assembly: one row (constant over the inputs) until the continuity scan flips
    ! one somewhere; only then one row per input (no n-long pass, no n-long read, in the common case)
    allocate (modes(1, nd))
    do d = 1, nd
      modes(1, d) = merge(1.0_dp, -1.0_dp, rdy(d, 3) >= 0.0_dp)
    end do
    cont = iand(want, want_continuity) /= 0 .and. n >= 4
    ! first pass: each block checks in cache whether any group might change assembly (the
    ! continuity test below without a flip so far); only then are the new joints stored and scanned
    store = .false.
    flagk = 0
    ring = 0.0_dp
    allocate (chr(1, 4, nd))
    ! block work arrays, made once: link frames, and the groups' attachments (those on the ground
    ! -- pivots, fixed guides -- are constant and filled here once)
    mb = min(nb, n)   ! the rows a block uses
    if (fresh) then
      pose(1:mb, :, 1) = 0.0_dp
      pose(1:mb, p_c, 1) = 1.0_dp
      pose(1:mb, p_ok, 1) = 1.0_dp
      pose(1:mb, p_rt, 1) = 1.0_dp
    end if
    ! a crank's frame but its direction is constant too: filled here once, each block writes (c, s)
    if (idrv(1) == drv_crank) then
      if (fresh) then
        pose(1:mb, :, idrv(3)) = 0.0_dp
        pose(1:mb, p_c, idrv(3)) = 1.0_dp
        pose(1:mb, p_ok, idrv(3)) = 1.0_dp
        pose(1:mb, p_rt, idrv(3)) = 1.0_dp
      end if
      pose(1:mb, p_ox, idrv(3)) = rpts(idrv(2), 1)
      pose(1:mb, p_oy, idrv(3)) = rpts(idrv(2), 2)
      pose(1:mb, p_w, idrv(3)) = rdrv(2)
      pose(1:mb, p_al, idrv(3)) = rdrv(3)
    end if
    do d = 1, nd
      if (idy(d, 1) == dy_prp) then
        if (igd(idy(d, 2)) == 1) call guide_of(mb, 1, rgd(idy(d, 2), :), pose(:, :, 1), att(:, :, 1, d))
      else if (ipts(idy(d, 2)) == 1) then
        call point_of(mb, 1, rpts(idy(d, 2), :), pose(:, :, 1), att(:, :, 1, d))
      end if
      if (idy(d, 1) == dy_rrp .or. idy(d, 1) == dy_prp) then
        if (igd(idy(d, 3)) == 1) call guide_of(mb, 1, rgd(idy(d, 3), :), pose(:, :, 1), att(:, :, 2, d))
      else if (ipts(idy(d, 3)) == 1) then
        call point_of(mb, 1, rpts(idy(d, 3), :), pose(:, :, 1), att(:, :, 2, d))
      end if
    end do
    call solve_rows(1)
    if (.not. cont .or. flagk == 0) return
    deallocate (chr)
    allocate (chr(n, 4, nd))
    store = .true.
    call solve_rows(1)
    call expand_modes()
    do d = 1, nd
      if (idy(d, 1) == dy_prp) cycle
      first = 0
      call follow(n, st(:, d), chr(:, :, d), modes(:, d), first)
      if (first > 0) call solve_rows(first)
    end do

  contains

    !> modes as one row per input (the continuity scan flips them from a row on).
    subroutine expand_modes()
      real(dp) :: m1(nd)
      m1 = modes(1, :)
      deallocate (modes)
      allocate (modes(n, nd))
      do d = 1, nd
        modes(:, d) = m1(d)
      end do
    end subroutine expand_modes

    !> Rows k1..n in blocks of nb.
    subroutine solve_rows(k1)
      integer, intent(in) :: k1
      do k0 = k1, n, nb
        m = min(nb, n - k0 + 1)
        call solve_block(m, k0, n, nl, np, ng, nd, ns, nld, nt, nf, x, idrv, rdrv, ipts, rpts, igd, rgd, idy, &
                         rdy, rl, grav, ild, rld, rtq, ift, tab, rft, want, asel, rsel, modes, cont, store, chr, &
                         ring, flagk, pose, att, lk, pk, sk, qa, st, fk, fd, sh)
      end do
    end subroutine solve_rows

  end subroutine analyse_core

  !> The continuity test of one group over one block, in cache, assuming no flip so far: flagk
  !> becomes the first input (global row) where the other assembly's new joint is nearer than
  !> the chosen one to the quadratic extrapolation of the three previous joints (ring: the
  !> chosen joints of the block before, carried over).
  subroutine prescan(m, k0, n, ex, st, ring, flagk)
    integer, intent(in) :: m, k0, n, st(n)
    real(dp), intent(in) :: ex(nb, nex)
    real(dp), intent(inout) :: ring(3, 4)
    integer, intent(inout) :: flagk
    real(dp) :: ch(6, 4), px, py, ec, ea, flag(nb), any_flag   ! flags as reals: one vector width
    integer :: k, kg, c, j
    ! the block's first three rows extrapolate from the ring (the block before's last three)
    do c = 1, 4
      ch(1:3, c) = ring(:, c)
      ch(4:3 + min(m, 3), c) = ex(1:min(m, 3), 9 + c)
    end do
    any_flag = 0.0_dp
    do k = 1, min(m, 3)
      j = k + 3
      px = 3.0_dp*(ch(j - 1, 1) - ch(j - 2, 1)) + ch(j - 3, 1)
      py = 3.0_dp*(ch(j - 1, 2) - ch(j - 2, 2)) + ch(j - 3, 2)
      ec = (ch(j, 1) - px)**2 + (ch(j, 2) - py)**2
      ea = (ch(j, 3) - px)**2 + (ch(j, 4) - py)**2
      flag(k) = merge(1.0_dp, 0.0_dp, ea < ec)
      any_flag = max(any_flag, flag(k))
    end do
    ! the rest from the block itself (the chosen joint in ex(:, 10:11), the other in ex(:, 12:13))
    ! hot-loop: linkage continuity pre-scan
    do k = 4, m
      px = 3.0_dp*(ex(k - 1, 10) - ex(k - 2, 10)) + ex(k - 3, 10)
      py = 3.0_dp*(ex(k - 1, 11) - ex(k - 2, 11)) + ex(k - 3, 11)
      ec = (ex(k, 10) - px)**2 + (ex(k, 11) - py)**2
      ea = (ex(k, 12) - px)**2 + (ex(k, 13) - py)**2
      flag(k) = merge(1.0_dp, 0.0_dp, ea < ec)
      any_flag = max(any_flag, flag(k))
    end do
    if (any_flag > 0.0_dp) then   ! rare: look at the positions flagged
      do k = 1, m
        kg = k0 + k - 1
        if (flag(k) == 0.0_dp .or. kg < 4) cycle
        if (all(st(kg - 3:kg) == st_ok .or. st(kg - 3:kg) == st_toggle) .and. st(kg) == st_ok) then
          flagk = kg
          exit
        end if
      end do
    end if
    ! the ring: the last three rows (with the ring's own when the block has fewer)
    do c = 1, 4
      do k = 1, 3
        j = m - 3 + k
        if (j >= 1) then
          ring(k, c) = ex(j, 9 + c)
        else
          ring(k, c) = ring(k + m, c)
        end if
      end do
    end do
  end subroutine prescan

  !> The continuity scan of one dyad over the current solution: where the other assembly's
  !> new joint (chr(k, 3:4)) is nearer than the chosen one (chr(k, 1:2)) to the quadratic
  !> extrapolation of the three previous chosen joints, the mode flips from k on.  first: the
  !> first position flipped (0: none).  Sequential by nature (each choice depends on the last).
  subroutine follow(n, st, chr, modes, first)
    integer, intent(in) :: n, st(n)
    real(dp), intent(in) :: chr(n, 4)
    real(dp), intent(inout) :: modes(n)
    integer, intent(inout) :: first
    real(dp) :: cx(4), cy(4), px, py, ec, ea, ax, ay, par
    logical :: okk(4)
    integer :: k, j
    par = 1.0_dp
    cx = 0.0_dp
    cy = 0.0_dp
    okk = .false.
    do k = 1, n
      if (par > 0.0_dp) then
        cx(4) = chr(k, 1); cy(4) = chr(k, 2); ax = chr(k, 3); ay = chr(k, 4)
      else
        cx(4) = chr(k, 3); cy(4) = chr(k, 4); ax = chr(k, 1); ay = chr(k, 2)
      end if
      okk(4) = st(k) == st_ok .or. st(k) == st_toggle
      if (k >= 4 .and. st(k) == st_ok .and. all(okk)) then
        px = 3.0_dp*(cx(3) - cx(2)) + cx(1)
        py = 3.0_dp*(cy(3) - cy(2)) + cy(1)
        ec = (cx(4) - px)**2 + (cy(4) - py)**2
        ea = (ax - px)**2 + (ay - py)**2
        if (ea < ec) then
          par = -par
          if (first == 0) first = k
          modes(k:n) = -modes(k:n)
          cx(4) = ax
          cy(4) = ay
        end if
      end if
      do j = 1, 3
        cx(j) = cx(j + 1)
        cy(j) = cy(j + 1)
        okk(j) = okk(j + 1)
      end do
    end do
  end subroutine follow

  !> One block of analyse: rows k0..k0+m-1 (m <= nb).
  subroutine solve_block(m, k0, n, nl, np, ng, nd, ns, nld, nt, nf, x, idrv, rdrv, ipts, rpts, igd, rgd, idy, &
                         rdy, rl, grav, ild, rld, rtq, ift, tab, rft, want, asel, rsel, modes, cont, store, chr, &
                         ring, flagk, pose, att, lk, pk, sk, qa, st, fk, fd, sh)
    integer, intent(in) :: m, k0, n, nl, np, ng, nd, ns, nld, nt, nf, asel, rsel
    real(dp), intent(in) :: x(n), rdrv(3), rpts(np, 2), rgd(ng, 3), rdy(nd, 3), rl(nl, 4), grav(2)
    integer, intent(in) :: idrv(4), ipts(np), igd(ng), idy(nd, 6), ild(nld), ift(4), want
    real(dp), intent(in) :: rld(nld, 2), rtq(nl), tab(nt, 2), rft(3)
    !> each group's assembly: (n, nd) one per input, or (1, nd) the same at every input
    real(dp), intent(in) :: modes(:, :)
    logical, intent(in) :: cont, store
    real(dp), intent(inout) :: chr(:, :, :), ring(3, 4, nd)
    integer, intent(inout) :: flagk
    real(dp), intent(inout) :: pose(nb, npose, nl), att(nb, natt, 2, nd)
    real(dp), intent(inout) :: lk(n, 3, nl), pk(n, 6, np), sk(n, 3, ns), qa(n, nd), fk(nf, 9, nd), fd(nf, 4), &
                               sh(nf, 3)
    integer, intent(inout) :: st(n, nd)
    real(dp) :: a1(nb, natt), ex(nb, nex), mode(nb)
    real(dp) :: wk(nb, 3, nl), rx(nb, 9), tmp(nb), drf(nb, 4), fx(nb), fy(nb), q(nb), okr(nb)
    integer :: l, p, dd, kind, k1, s0, c
    logical :: forces, slides
    k1 = k0 + m - 1
    forces = iand(want, want_forces) /= 0
    slides = iand(want, want_slides) /= 0 .or. forces   ! a guide force over the slide reads them
    ! driver (the ground's frame, pose(:, :, 1), is set once by analyse)
    l = idrv(3)
    if (idrv(1) == drv_crank) then
      call sincos_array(m, x(k0:k1), pose(:, p_s, l), pose(:, p_c, l))   ! the rest of its frame is constant
    else
      call guide_of(m, igd(idrv(2)), rgd(idrv(2), :), pose(:, :, igd(idrv(2))), a1)
      call slider_pose(m, x(k0:k1), rdrv(1), rdrv(2), rdrv(3), a1, pose(:, :, l))
      if (idrv(4) > 0 .and. slides) then
        sk(k0:k1, 1, idrv(4)) = x(k0:k1)
        sk(k0:k1, 2, idrv(4)) = rdrv(2)
        sk(k0:k1, 3, idrv(4)) = rdrv(3)
      end if
    end if
    ! dyads in order; an attachment on a moving link is evaluated here, one on the ground was
    ! filled by analyse
    do dd = 1, nd
      kind = idy(dd, 1)
      if (kind == dy_prp) then
        l = igd(idy(dd, 2))
        if (l /= 1) call guide_of(m, l, rgd(idy(dd, 2), :), pose(:, :, l), att(:, :, 1, dd))
      else
        l = ipts(idy(dd, 2))
        if (l /= 1) call point_of(m, l, rpts(idy(dd, 2), :), pose(:, :, l), att(:, :, 1, dd))
      end if
      if (kind == dy_rrp .or. kind == dy_prp) then
        l = igd(idy(dd, 3))
        if (l /= 1) call guide_of(m, l, rgd(idy(dd, 3), :), pose(:, :, l), att(:, :, 2, dd))
      else
        l = ipts(idy(dd, 3))
        if (l /= 1) call point_of(m, l, rpts(idy(dd, 3), :), pose(:, :, l), att(:, :, 2, dd))
      end if
      if (size(modes, 1) == 1) then
        mode(1:m) = modes(1, dd)
      else
        mode(1:m) = modes(k0:k1, dd)
      end if
      select case (kind)
      case (dy_rrr)
        call dyad_rrr(m, rdy(dd, 1), rdy(dd, 2), mode(1:m), att(:, :, 1, dd), att(:, :, 2, dd), &
                      pose(:, :, idy(dd, 4)), pose(:, :, idy(dd, 5)), ex)
      case (dy_rrp)
        call dyad_rrp(m, rdy(dd, 1), rdy(dd, 2), mode(1:m), att(:, :, 1, dd), att(:, :, 2, dd), &
                      pose(:, :, idy(dd, 4)), pose(:, :, idy(dd, 5)), ex)
      case (dy_rpr)
        call dyad_rpr(m, rdy(dd, 1), mode(1:m), att(:, :, 1, dd), att(:, :, 2, dd), pose(:, :, idy(dd, 4)), &
                      pose(:, :, idy(dd, 5)), ex)
      case default
        call dyad_prp(m, rdy(dd, 1), rdy(dd, 2), att(:, :, 1, dd), att(:, :, 2, dd), pose(:, :, idy(dd, 4)), &
                      pose(:, :, idy(dd, 5)), ex)
      end select
      st(k0:k1, dd) = nint(ex(1:m, 1))
      if (iand(want, want_quality) /= 0) call atan2_array(m, ex(:, 2), ex(:, 3), qa(k0:k1, dd))
      s0 = idy(dd, 6)
      if (s0 > 0 .and. slides) then
        sk(k0:k1, 1, s0) = ex(1:m, 4)
        sk(k0:k1, 2, s0) = ex(1:m, 5)
        sk(k0:k1, 3, s0) = ex(1:m, 6)
        if (kind == dy_prp) then
          sk(k0:k1, 1, s0 + 1) = ex(1:m, 7)
          sk(k0:k1, 2, s0 + 1) = ex(1:m, 8)
          sk(k0:k1, 3, s0 + 1) = ex(1:m, 9)
        end if
      end if
      if (cont .and. kind /= dy_prp) then
        if (store) then
          do c = 1, 4
            chr(k0:k1, c, dd) = ex(1:m, 9 + c)
          end do
        else if (flagk == 0) then
          call prescan(m, k0, n, ex, st(:, dd), ring(:, :, dd), flagk)
        end if
      end if
    end do
    ! moving links: angle (an unplaced link's frame is (1, 0): angle 0; a crank's is its input
    ! brought into (-pi, pi], no arctangent), omega, alpha; the ground's are filled once by the caller
    do l = 2, nl
      if (iand(want, want_angles) /= 0 .and. (asel == 0 .or. l == asel)) then
        if (l == idrv(3) .and. idrv(1) == drv_crank) then
          call wrap_angle(m, x(k0:k1), lk(k0:k1, 1, l))
        else
          call atan2_array(m, pose(:, p_s, l), pose(:, p_c, l), lk(k0:k1, 1, l))
        end if
      end if
      if (iand(want, want_link_rates) /= 0 .and. (rsel == 0 .or. l == rsel)) &
        call copy2(m, pose(:, p_w, l), pose(:, p_al, l), lk(k0:k1, 2, l), lk(k0:k1, 3, l))
    end do
    ! points on moving links, written straight into the outputs (the ground's: by the caller)
    do p = 1, np
      if (ipts(p) == 1) cycle
      if (iand(want, want_points) /= 0 .and. iand(want, want_point_rates) /= 0) then   ! one pass
        call point_out(m, rpts(p, 1), rpts(p, 2), pose(:, :, ipts(p)), pk(k0:k1, 1, p), pk(k0:k1, 2, p), &
                       pk(k0:k1, 3, p), pk(k0:k1, 4, p), pk(k0:k1, 5, p), pk(k0:k1, 6, p))
      else if (iand(want, want_points) /= 0) then
        call point_at(m, rpts(p, 1), rpts(p, 2), pose(:, :, ipts(p)), pk(k0:k1, 1, p), pk(k0:k1, 2, p))
      else if (iand(want, want_point_rates) /= 0) then
        call point_rates(m, rpts(p, 1), rpts(p, 2), pose(:, :, ipts(p)), pk(k0:k1, 3, p), pk(k0:k1, 4, p), &
                         pk(k0:k1, 5, p), pk(k0:k1, 6, p))
      end if
    end do
    if (.not. forces) return
    ! ---- forces: each link's known load, the dyads from the last, then the driver
    wk(1:m, :, 1) = 0.0_dp
    do l = 2, nl
      call inertia_load(m, rl(l, :), grav, rtq(l), pose(:, :, l), wk(:, :, l))
    end do
    q(1:m) = 0.0_dp
    do p = 1, nld
      l = ipts(ild(p))
      call point_of(m, l, rpts(ild(p), :), pose(:, :, l), a1)
      fx(1:m) = rld(p, 1)
      fy(1:m) = rld(p, 2)
      call apply(m, a1(:, 1), a1(:, 2), fx, fy, q, pose(:, :, l), wk(:, :, l))
    end do
    if (ift(1) > 0) then
      ! the table's force along the block's x-axis at its origin; the reaction on the guide's link
      l = ift(1)
      call guide_force(m, k0, n, ift(3), x, sk(:, 1, max(ift(4), 1)), nt, tab, rft, tmp)
      fx(1:m) = tmp(1:m)*pose(1:m, p_c, l)
      fy(1:m) = tmp(1:m)*pose(1:m, p_s, l)
      call apply(m, pose(:, p_ox, l), pose(:, p_oy, l), fx, fy, q, pose(:, :, l), wk(:, :, l))
      fx(1:m) = -fx(1:m)
      fy(1:m) = -fy(1:m)
      call apply(m, pose(:, p_ox, l), pose(:, p_oy, l), fx, fy, q, pose(:, :, ift(2)), wk(:, :, ift(2)))
    end if
    do dd = nd, 1, -1
      kind = idy(dd, 1)
      select case (kind)
      case (dy_rrr)
        call force_rrr(m, rdy(dd, 1), pose(:, :, idy(dd, 4)), pose(:, :, idy(dd, 5)), wk(:, :, idy(dd, 4)), &
                       wk(:, :, idy(dd, 5)), rx)
        call react(ipts(idy(dd, 2)), pose(:, p_ox, idy(dd, 4)), pose(:, p_oy, idy(dd, 4)), 1)
        call react(ipts(idy(dd, 3)), pose(:, p_ox, idy(dd, 5)), pose(:, p_oy, idy(dd, 5)), 4)
      case (dy_rrp)
        call force_rrp(m, pose(:, :, idy(dd, 4)), pose(:, :, idy(dd, 5)), wk(:, :, idy(dd, 4)), &
                       wk(:, :, idy(dd, 5)), rx)
        call react(ipts(idy(dd, 2)), pose(:, p_ox, idy(dd, 4)), pose(:, p_oy, idy(dd, 4)), 1)
        call react(igd(idy(dd, 3)), pose(:, p_ox, idy(dd, 5)), pose(:, p_oy, idy(dd, 5)), 4)
      case (dy_rpr)
        call force_rpr(m, pose(:, :, idy(dd, 4)), pose(:, :, idy(dd, 5)), wk(:, :, idy(dd, 4)), &
                       wk(:, :, idy(dd, 5)), rx)
        call react(ipts(idy(dd, 2)), pose(:, p_ox, idy(dd, 4)), pose(:, p_oy, idy(dd, 4)), 1)
        call react(ipts(idy(dd, 3)), pose(:, p_ox, idy(dd, 5)), pose(:, p_oy, idy(dd, 5)), 4)
      case default
        call force_prp(m, pose(:, :, idy(dd, 4)), pose(:, :, idy(dd, 5)), wk(:, :, idy(dd, 4)), &
                       wk(:, :, idy(dd, 5)), rx)
        call react(igd(idy(dd, 2)), pose(:, p_ox, idy(dd, 4)), pose(:, p_oy, idy(dd, 4)), 1)
        call react(igd(idy(dd, 3)), pose(:, p_ox, idy(dd, 4)), pose(:, p_oy, idy(dd, 4)), 4)
      end select
      fk(k0:k1, :, dd) = rx(1:m, :)
    end do
    ! the driver, and its reaction on the frame
    l = idrv(3)
    call force_driver(m, idrv(1), pose(:, :, l), wk(:, :, l), drf)
    fd(k0:k1, :) = drf(1:m, :)
    if (idrv(1) == drv_crank) then
      fx(1:m) = -drf(1:m, 1)
      fy(1:m) = -drf(1:m, 2)
      q(1:m) = -drf(1:m, 4)
    else
      fx(1:m) = -drf(1:m, 1) - drf(1:m, 4)*pose(1:m, p_c, l)
      fy(1:m) = -drf(1:m, 2) - drf(1:m, 4)*pose(1:m, p_s, l)
      q(1:m) = -drf(1:m, 3)
    end if
    call apply(m, pose(:, p_ox, l), pose(:, p_oy, l), fx, fy, q, pose(:, :, 1), wk(:, :, 1))
    ! rows where a link is not placed or its rates are unknown (a toggle) carry no forces
    okr(1:m) = 1.0_dp
    do l = 2, nl
      okr(1:m) = okr(1:m)*pose(1:m, p_rt, l)
    end do
    do c = 1, 3
      sh(k0:k1, c) = wk(1:m, c, 1)*okr(1:m)
    end do
    do dd = 1, nd
      do c = 1, 9
        fk(k0:k1, c, dd) = fk(k0:k1, c, dd)*okr(1:m)
      end do
    end do
    do c = 1, 4
      fd(k0:k1, c) = fd(k0:k1, c)*okr(1:m)
    end do

  contains

    !> The reaction of the dyad's joint (columns c0..c0+2 of rx: force and couple on the
    !> dyad) applied, reversed, to link lk_ at point (px_, py_).
    subroutine react(lk_, px_, py_, c0)
      integer, intent(in) :: lk_, c0
      real(dp), intent(in) :: px_(nb), py_(nb)
      fx(1:m) = -rx(1:m, c0)
      fy(1:m) = -rx(1:m, c0 + 1)
      q(1:m) = -rx(1:m, c0 + 2)
      call apply(m, px_, py_, fx, fy, q, pose(:, :, lk_), wk(:, :, lk_))
    end subroutine react

  end subroutine solve_block

  !> f(1:m): the guide force of the table (scaled by rft(2)) at rows k0..k0+m-1, its abscissa
  !> the input (over = 1, period rft(1)) or the slide s (over = 2).
  subroutine guide_force(m, k0, n, over, x, s, nt, tab, rft, f)
    integer, intent(in) :: m, k0, n, over, nt
    real(dp), intent(in) :: x(n), s(n), tab(nt, 2), rft(3)
    real(dp), intent(inout) :: f(nb)
    integer :: k
    do k = 1, m
      if (over == 1) then
        f(k) = rft(2)*interp(nt, tab, x(k0 + k - 1), rft(1))
      else
        f(k) = rft(2)*interp(nt, tab, s(k0 + k - 1), 0.0_dp)
      end if
    end do
  end subroutine guide_force

  !> Linear interpolation in tab(:, 1) (ascending) -> tab(:, 2); with period > 0, x is first
  !> brought into [tab(1, 1), tab(1, 1) + period); outside the table the end value holds.
  pure real(dp) function interp(nt, tab, x, period)
    integer, intent(in) :: nt
    real(dp), intent(in) :: tab(nt, 2), x, period
    real(dp) :: xv, t
    integer :: lo, hi, mid
    xv = x
    if (period > 0.0_dp) xv = tab(1, 1) + modulo(x - tab(1, 1), period)
    if (xv <= tab(1, 1)) then
      interp = tab(1, 2)
      return
    end if
    if (xv >= tab(nt, 1)) then
      interp = tab(nt, 2)
      return
    end if
    lo = 1
    hi = nt
    do while (hi - lo > 1)
      mid = (lo + hi)/2
      if (tab(mid, 1) <= xv) then
        lo = mid
      else
        hi = mid
      end if
    end do
    t = (xv - tab(lo, 1))/(tab(hi, 1) - tab(lo, 1))
    interp = tab(lo, 2) + t*(tab(hi, 2) - tab(lo, 2))
  end function interp

  ! ======================================================================== kinematics blocks

  !> b1 = a1, b2 = a2 over m rows.
  subroutine copy2(m, a1, a2, b1, b2)
    integer, intent(in) :: m
    real(dp), intent(in) :: a1(nb), a2(nb)
    real(dp), intent(inout) :: b1(m), b2(m)
    b1(1:m) = a1(1:m)
    b2(1:m) = a2(1:m)
  end subroutine copy2

  !> x brought into (-pi, pi]: a crank's angle from its input, as atan2(sin x, cos x) gives it.
  subroutine wrap_angle(m, x, a)
    integer, intent(in) :: m
    real(dp), intent(in) :: x(m)
    real(dp), intent(inout) :: a(m)
    real(dp), parameter :: twopi = 2*pi, magic = 6755399441055744.0_dp   ! 1.5 * 2**52: rounds to nearest
    real(dp) :: t
    integer :: k
    ! hot-loop: linkage crank angle
    do k = 1, m
      t = x(k) - twopi*((x(k)*(1.0_dp/twopi) + magic) - magic)
      a(k) = merge(t + twopi, t, t <= -pi)
    end do
  end subroutine wrap_angle

  !> A point (u, v) of a moving link straight into six output columns: position, velocity,
  !> acceleration (zero where the link is not placed; rates zero where they are unknown).
  subroutine point_out(m, u, v, pose, x, y, vx, vy, ax, ay)
    integer, intent(in) :: m
    real(dp), intent(in) :: u, v, pose(nb, npose)
    real(dp), intent(inout) :: x(m), y(m), vx(m), vy(m), ax(m), ay(m)
    real(dp) :: rx, ry, ok, w, al
    integer :: k
    ! hot-loop: linkage point out
    do k = 1, m
      ok = pose(k, p_ok)
      rx = u*pose(k, p_c) - v*pose(k, p_s)
      ry = u*pose(k, p_s) + v*pose(k, p_c)
      w = pose(k, p_w)
      al = pose(k, p_al)
      x(k) = ok*(pose(k, p_ox) + rx)
      y(k) = ok*(pose(k, p_oy) + ry)
      vx(k) = pose(k, p_vx) - w*ry
      vy(k) = pose(k, p_vy) + w*rx
      ax(k) = pose(k, p_ax) - al*ry - w*w*rx
      ay(k) = pose(k, p_ay) + al*rx - w*w*ry
    end do
  end subroutine point_out

  !> The position of a point (u, v) of a moving link straight into two output columns (zero
  !> where the link is not placed).
  subroutine point_at(m, u, v, pose, x, y)
    integer, intent(in) :: m
    real(dp), intent(in) :: u, v, pose(nb, npose)
    real(dp), intent(inout) :: x(m), y(m)
    real(dp) :: ok, rx, ry
    integer :: k
    ! hot-loop: linkage point position
    do k = 1, m
      ok = pose(k, p_ok)
      rx = u*pose(k, p_c) - v*pose(k, p_s)
      ry = u*pose(k, p_s) + v*pose(k, p_c)
      x(k) = ok*(pose(k, p_ox) + rx)
      y(k) = ok*(pose(k, p_oy) + ry)
    end do
  end subroutine point_at

  !> The velocity and acceleration of a point (u, v) of a moving link straight into four output
  !> columns (zero where its rates are unknown).
  subroutine point_rates(m, u, v, pose, vx, vy, ax, ay)
    integer, intent(in) :: m
    real(dp), intent(in) :: u, v, pose(nb, npose)
    real(dp), intent(inout) :: vx(m), vy(m), ax(m), ay(m)
    real(dp) :: rx, ry, w, al
    integer :: k
    ! hot-loop: linkage point rates
    do k = 1, m
      rx = u*pose(k, p_c) - v*pose(k, p_s)
      ry = u*pose(k, p_s) + v*pose(k, p_c)
      w = pose(k, p_w)
      al = pose(k, p_al)
      vx(k) = pose(k, p_vx) - w*ry
      vy(k) = pose(k, p_vy) + w*rx
      ax(k) = pose(k, p_ax) - al*ry - w*w*rx
      ay(k) = pose(k, p_ay) + al*rx - w*w*ry
    end do
  end subroutine point_rates

  !> The input slider's pose: its pin at Pg + x u + e n on the ground guide g (columns of
  !> guide_of), velocity v u, acceleration a u.
  subroutine slider_pose(m, x, e, v, a, g, pose)
    integer, intent(in) :: m
    real(dp), intent(in) :: x(m), e, v, a, g(nb, natt)
    real(dp), intent(inout) :: pose(nb, npose)
    integer :: k
    ! hot-loop: linkage slider pose
    do k = 1, m
      pose(k, p_ox) = g(k, 1) + x(k)*g(k, 3) - e*g(k, 4)
      pose(k, p_oy) = g(k, 2) + x(k)*g(k, 4) + e*g(k, 3)
      pose(k, p_c) = g(k, 3)
      pose(k, p_s) = g(k, 4)
      pose(k, p_vx) = v*g(k, 3)
      pose(k, p_vy) = v*g(k, 4)
      pose(k, p_w) = 0.0_dp
      pose(k, p_ax) = a*g(k, 3)
      pose(k, p_ay) = a*g(k, 4)
      pose(k, p_al) = 0.0_dp
      pose(k, p_ok) = 1.0_dp
      pose(k, p_rt) = 1.0_dp
    end do
  end subroutine slider_pose

  !> A point (u, v) of link l: a(:, 1:8) = x, y, vx, vy, ax, ay, placed, rates known.
  !> On the ground (link 1) (u, v) are world coordinates.  Zero where the link is not placed.
  subroutine point_of(m, l, uv, pose, a)
    integer, intent(in) :: m, l
    real(dp), intent(in) :: uv(2), pose(nb, npose)
    real(dp), intent(inout) :: a(nb, natt)
    real(dp) :: u, v, rx, ry, ok, w, al
    integer :: k
    u = uv(1)
    v = uv(2)
    if (l == 1) then
      a(1:m, 1) = u
      a(1:m, 2) = v
      a(1:m, 3:6) = 0.0_dp
      a(1:m, 7:8) = 1.0_dp
      return
    end if
    ! hot-loop: linkage point
    do k = 1, m
      ok = pose(k, p_ok)
      rx = u*pose(k, p_c) - v*pose(k, p_s)
      ry = u*pose(k, p_s) + v*pose(k, p_c)
      w = pose(k, p_w)
      al = pose(k, p_al)
      a(k, 1) = ok*(pose(k, p_ox) + rx)
      a(k, 2) = ok*(pose(k, p_oy) + ry)
      a(k, 3) = pose(k, p_vx) - w*ry
      a(k, 4) = pose(k, p_vy) + w*rx
      a(k, 5) = pose(k, p_ax) - al*ry - w*w*rx
      a(k, 6) = pose(k, p_ay) + al*rx - w*w*ry
      a(k, 7) = ok
      a(k, 8) = pose(k, p_rt)
    end do
  end subroutine point_of

  !> A guide of link l: a(:, 1:15) = Pg (x, y), u (x, y), the link's origin (x, y), its
  !> velocity (x, y), omega, its acceleration (x, y), alpha, 0, placed, rates known.
  subroutine guide_of(m, l, g, pose, a)
    integer, intent(in) :: m, l
    real(dp), intent(in) :: g(3), pose(nb, npose)
    real(dp), intent(inout) :: a(nb, natt)
    real(dp) :: gx, gy, cg, sg
    integer :: k
    gx = g(1)
    gy = g(2)
    cg = cos(g(3))
    sg = sin(g(3))
    if (l == 1) then
      a(1:m, 1) = gx
      a(1:m, 2) = gy
      a(1:m, 3) = cg
      a(1:m, 4) = sg
      a(1:m, 5:13) = 0.0_dp
      a(1:m, 14:15) = 1.0_dp
      return
    end if
    ! hot-loop: linkage guide
    do k = 1, m
      a(k, 1) = pose(k, p_ox) + gx*pose(k, p_c) - gy*pose(k, p_s)
      a(k, 2) = pose(k, p_oy) + gx*pose(k, p_s) + gy*pose(k, p_c)
      a(k, 3) = cg*pose(k, p_c) - sg*pose(k, p_s)
      a(k, 4) = cg*pose(k, p_s) + sg*pose(k, p_c)
      a(k, 5) = pose(k, p_ox)
      a(k, 6) = pose(k, p_oy)
      a(k, 7) = pose(k, p_vx)
      a(k, 8) = pose(k, p_vy)
      a(k, 9) = pose(k, p_w)
      a(k, 10) = pose(k, p_ax)
      a(k, 11) = pose(k, p_ay)
      a(k, 12) = pose(k, p_al)
      a(k, 13) = 0.0_dp
      a(k, 14) = pose(k, p_ok)
      a(k, 15) = pose(k, p_rt)
    end do
  end subroutine guide_of

  !> RRR: J3 = P + a d + mode h d_perp (d = Q - P), the closure of fourbar::exact_states.
  subroutine dyad_rrr(m, l1, l2, mode, p, q, o1, o2, ex)
    integer, intent(in) :: m
    real(dp), intent(in) :: l1, l2, mode(m), p(nb, natt), q(nb, natt)
    real(dp), intent(inout) :: o1(nb, npose), o2(nb, npose), ex(nb, nex)
    real(dp) :: r2, s2, dx, dy, d2, a, h2, h, jx, jy, e1x, e1y, e2x, e2y, a1x, a1y, a2x, a2y
    real(dp) :: isno, istog, isdeg, st, degst, dmin2, inok, placed, ok, det, dvx, dvy, w1, w2, cx, cy, &
                al1, al2, sgn, rt, id2, idet, il1, il2
    integer :: k
    ! one division per position for each of d2 and det, the link lengths' reciprocals once
    r2 = l1*l1
    s2 = l2*l2
    il1 = 1.0_dp/l1
    il2 = 1.0_dp/l2
    dmin2 = (tol*(l1 + l2))**2
    degst = merge(real(st_indeterminate, dp), real(st_no_assembly, dp), abs(l1 - l2) <= tol*(l1 + l2))
    ! hot-loop: linkage dyad rrr
    do k = 1, m
      sgn = mode(k)
      inok = p(k, 7)*q(k, 7)
      rt = p(k, 8)*q(k, 8)
      dx = q(k, 1) - p(k, 1)
      dy = q(k, 2) - p(k, 2)
      d2 = max(dx*dx + dy*dy, tiny(1.0_dp))
      id2 = 1.0_dp/d2
      a = (d2 + r2 - s2)*(0.5_dp*id2)
      h2 = r2*id2 - a*a
      isno = merge(1.0_dp, 0.0_dp, h2 < -tol)
      istog = merge(1.0_dp, 0.0_dp, h2 <= tol)*(1.0_dp - isno)
      isdeg = merge(1.0_dp, 0.0_dp, d2 <= dmin2)
      st = (1.0_dp - isdeg)*(st_no_assembly*isno + st_toggle*istog) + isdeg*degst
      st = inok*st + (1.0_dp - inok)*st_unplaced
      h2 = h2*(1.0_dp - isdeg)
      h = sqrt(max(h2, 0.0_dp))
      jx = p(k, 1) + a*dx - sgn*h*dy
      jy = p(k, 2) + a*dy + sgn*h*dx
      placed = inok*(1.0_dp - isno)*(1.0_dp - isdeg)
      ok = placed*(1.0_dp - istog)*rt
      a1x = jx - p(k, 1)
      a1y = jy - p(k, 2)
      a2x = jx - q(k, 1)
      a2y = jy - q(k, 2)
      e1x = a1x*il1
      e1y = a1y*il1
      e2x = a2x*il2
      e2y = a2y*il2
      ! w1 A1_perp - w2 A2_perp = vQ - vP, det = A1 x A2 (zero at the toggle)
      det = ok*(a1x*a2y - a1y*a2x) + (1.0_dp - ok)
      idet = ok/det
      dvx = q(k, 3) - p(k, 3)
      dvy = q(k, 4) - p(k, 4)
      w1 = (dvx*a2x + dvy*a2y)*idet
      w2 = (dvx*a1x + dvy*a1y)*idet
      cx = q(k, 5) - p(k, 5) + w1*w1*a1x - w2*w2*a2x
      cy = q(k, 6) - p(k, 6) + w1*w1*a1y - w2*w2*a2y
      al1 = (cx*a2x + cy*a2y)*idet
      al2 = (cx*a1x + cy*a1y)*idet
      o1(k, p_ox) = p(k, 1)*placed
      o1(k, p_oy) = p(k, 2)*placed
      o1(k, p_c) = e1x*placed + (1.0_dp - placed)
      o1(k, p_s) = e1y*placed
      o1(k, p_vx) = p(k, 3)*ok
      o1(k, p_vy) = p(k, 4)*ok
      o1(k, p_w) = w1
      o1(k, p_ax) = p(k, 5)*ok
      o1(k, p_ay) = p(k, 6)*ok
      o1(k, p_al) = al1
      o1(k, p_ok) = placed
      o1(k, p_rt) = ok
      o2(k, p_ox) = q(k, 1)*placed
      o2(k, p_oy) = q(k, 2)*placed
      o2(k, p_c) = e2x*placed + (1.0_dp - placed)
      o2(k, p_s) = e2y*placed
      o2(k, p_vx) = q(k, 3)*ok
      o2(k, p_vy) = q(k, 4)*ok
      o2(k, p_w) = w2
      o2(k, p_ax) = q(k, 5)*ok
      o2(k, p_ay) = q(k, 6)*ok
      o2(k, p_al) = al2
      o2(k, p_ok) = placed
      o2(k, p_rt) = ok
      ex(k, 1) = st
      ex(k, 2) = abs(e1x*e2y - e1y*e2x)*placed
      ex(k, 3) = e1x*e2x + e1y*e2y
      ex(k, 10) = jx*placed
      ex(k, 11) = jy*placed
      ex(k, 12) = (jx + 2*sgn*h*dy)*placed
      ex(k, 13) = (jy - 2*sgn*h*dx)*placed
    end do
  end subroutine dyad_rrr

  !> RRP: the rod p -> J3 (length l1); J3 on the line offset e to the left of the guide g.
  subroutine dyad_rrp(m, l1, e, mode, p, g, o1, o2, ex)
    integer, intent(in) :: m
    real(dp), intent(in) :: l1, e, mode(m), p(nb, natt), g(nb, natt)
    real(dp), intent(inout) :: o1(nb, npose), o2(nb, npose), ex(nb, nex)
    real(dp) :: ux, uy, nx, ny, wx, wy, sf, hh, disc, root, s, jx, jy, a1x, a1y, sgn, inok, rt
    real(dp) :: isno, istog, st, placed, ok, det, rx, ry, vqx, vqy, dvx, dvy, w1, sd, aqx, aqy, cx, cy, al1, sdd
    real(dp) :: wk, ak, il1, idet
    integer :: k
    il1 = 1.0_dp/l1
    ! hot-loop: linkage dyad rrp
    do k = 1, m
      sgn = mode(k)
      inok = p(k, 7)*g(k, 14)
      rt = p(k, 8)*g(k, 15)
      ux = g(k, 3)
      uy = g(k, 4)
      nx = -uy
      ny = ux
      wx = p(k, 1) - g(k, 1)
      wy = p(k, 2) - g(k, 2)
      sf = wx*ux + wy*uy
      hh = wx*nx + wy*ny - e
      disc = 1.0_dp - (hh*il1)**2
      isno = merge(1.0_dp, 0.0_dp, disc < -tol)
      istog = merge(1.0_dp, 0.0_dp, disc <= tol)*(1.0_dp - isno)
      st = st_no_assembly*isno + st_toggle*istog
      st = inok*st + (1.0_dp - inok)*st_unplaced
      root = l1*sqrt(max(disc, 0.0_dp))
      s = sf + sgn*root
      placed = inok*(1.0_dp - isno)
      ok = placed*(1.0_dp - istog)*rt
      jx = g(k, 1) + e*nx + s*ux
      jy = g(k, 2) + e*ny + s*uy
      a1x = jx - p(k, 1)
      a1y = jy - p(k, 2)
      ! the guide link's point at J3
      rx = jx - g(k, 5)
      ry = jy - g(k, 6)
      wk = g(k, 9)
      ak = g(k, 12)
      vqx = g(k, 7) - wk*ry
      vqy = g(k, 8) + wk*rx
      ! w1 A1_perp - sd u = vQ - vP;  det = A1 . u (zero with the rod square to the guide)
      det = ok*(a1x*ux + a1y*uy) + (1.0_dp - ok)
      idet = ok/det
      dvx = vqx - p(k, 3)
      dvy = vqy - p(k, 4)
      ! Cramer with c1 = A1_perp, c2 = -u: w1 = (r x c2) / det, sd = (c1 x r) / det
      w1 = (-dvx*uy + dvy*ux)*idet
      sd = (-(a1y*dvy + a1x*dvx))*idet
      aqx = g(k, 10) - ak*ry - wk*wk*rx
      aqy = g(k, 11) + ak*rx - wk*wk*ry
      cx = aqx + 2*wk*sd*nx - p(k, 5) + w1*w1*a1x
      cy = aqy + 2*wk*sd*ny - p(k, 6) + w1*w1*a1y
      al1 = (-cx*uy + cy*ux)*idet
      sdd = (-(a1y*cy + a1x*cx))*idet
      o1(k, p_ox) = p(k, 1)*placed
      o1(k, p_oy) = p(k, 2)*placed
      o1(k, p_c) = a1x*il1*placed + (1.0_dp - placed)
      o1(k, p_s) = a1y*il1*placed
      o1(k, p_vx) = p(k, 3)*ok
      o1(k, p_vy) = p(k, 4)*ok
      o1(k, p_w) = w1
      o1(k, p_ax) = p(k, 5)*ok
      o1(k, p_ay) = p(k, 6)*ok
      o1(k, p_al) = al1
      o1(k, p_ok) = placed
      o1(k, p_rt) = ok
      o2(k, p_ox) = jx*placed
      o2(k, p_oy) = jy*placed
      o2(k, p_c) = ux*placed + (1.0_dp - placed)
      o2(k, p_s) = uy*placed
      o2(k, p_vx) = (p(k, 3) - w1*a1y)*ok
      o2(k, p_vy) = (p(k, 4) + w1*a1x)*ok
      o2(k, p_w) = wk*ok
      o2(k, p_ax) = (p(k, 5) - al1*a1y - w1*w1*a1x)*ok
      o2(k, p_ay) = (p(k, 6) + al1*a1x - w1*w1*a1y)*ok
      o2(k, p_al) = ak*ok
      o2(k, p_ok) = placed
      o2(k, p_rt) = ok
      ex(k, 1) = st
      ! pressure angle: between the rod and the guide
      ex(k, 2) = abs(a1x*uy - a1y*ux)*placed
      ex(k, 3) = abs(a1x*ux + a1y*uy)
      ex(k, 4) = s*placed
      ex(k, 5) = sd
      ex(k, 6) = sdd
      ex(k, 10) = jx*placed
      ex(k, 11) = jy*placed
      ex(k, 12) = (jx - 2*sgn*root*ux)*placed
      ex(k, 13) = (jy - 2*sgn*root*uy)*placed
    end do
  end subroutine dyad_rrp

  !> RPR: link 1 turns about p and carries the slot (offset e to the left of its x-axis); the
  !> block pinned at q slides in it.  u = (s b - e b_perp) / |b|^2, b = q - p,
  !> s = mode sqrt(|b|^2 - e^2) (q ahead of the foot of p along the slot for mode +1).
  subroutine dyad_rpr(m, e, mode, p, q, o1, o2, ex)
    integer, intent(in) :: m
    real(dp), intent(in) :: e, mode(m), p(nb, natt), q(nb, natt)
    real(dp), intent(inout) :: o1(nb, npose), o2(nb, npose), ex(nb, nex)
    real(dp) :: bx, by, d2, disc, s, ux, uy, nx, ny, sgn, inok, rt, isno, istog, isdeg, st, placed, ok, det
    real(dp) :: dvx, dvy, w1, sd, cx, cy, al1, sdd, dd, bl, dmin, idd, ibl, idet
    integer :: k
    ! hot-loop: linkage dyad rpr
    do k = 1, m
      sgn = mode(k)
      inok = p(k, 7)*q(k, 7)
      rt = p(k, 8)*q(k, 8)
      bx = q(k, 1) - p(k, 1)
      by = q(k, 2) - p(k, 2)
      d2 = bx*bx + by*by
      dd = max(d2, tiny(1.0_dp))
      idd = 1.0_dp/dd
      bl = sqrt(dd)
      ibl = 1.0_dp/bl
      dmin = tol*max(abs(e), bl)
      ! q on p with no offset: the slot may point anywhere
      isdeg = merge(1.0_dp, 0.0_dp, bl <= dmin .or. d2 == 0.0_dp)
      disc = 1.0_dp - (e*ibl)**2
      isno = merge(1.0_dp, 0.0_dp, disc < -tol)*(1.0_dp - isdeg)
      istog = merge(1.0_dp, 0.0_dp, disc <= tol)*(1.0_dp - isno)*(1.0_dp - isdeg)
      st = st_no_assembly*isno + st_toggle*istog + st_indeterminate*isdeg
      st = inok*st + (1.0_dp - inok)*st_unplaced
      s = sgn*bl*sqrt(max(disc, 0.0_dp))
      ux = (s*bx + e*by)*idd
      uy = (s*by - e*bx)*idd
      nx = -uy
      ny = ux
      placed = inok*(1.0_dp - isno)*(1.0_dp - isdeg)
      ok = placed*(1.0_dp - istog)*rt
      ! w1 b_perp + sd u = vQ - vP;  det = b_perp x u = -s (zero at the toggle)
      det = ok*(-s) + (1.0_dp - ok)
      idet = ok/det
      dvx = q(k, 3) - p(k, 3)
      dvy = q(k, 4) - p(k, 4)
      w1 = (dvx*uy - dvy*ux)*idet
      sd = (-by*dvy - bx*dvx)*idet
      cx = q(k, 5) - p(k, 5) + w1*w1*bx - 2*w1*sd*nx
      cy = q(k, 6) - p(k, 6) + w1*w1*by - 2*w1*sd*ny
      al1 = (cx*uy - cy*ux)*idet
      sdd = (-by*cy - bx*cx)*idet
      o1(k, p_ox) = p(k, 1)*placed
      o1(k, p_oy) = p(k, 2)*placed
      o1(k, p_c) = ux*placed + (1.0_dp - placed)
      o1(k, p_s) = uy*placed
      o1(k, p_vx) = p(k, 3)*ok
      o1(k, p_vy) = p(k, 4)*ok
      o1(k, p_w) = w1
      o1(k, p_ax) = p(k, 5)*ok
      o1(k, p_ay) = p(k, 6)*ok
      o1(k, p_al) = al1
      o1(k, p_ok) = placed
      o1(k, p_rt) = ok
      o2(k, p_ox) = q(k, 1)*placed
      o2(k, p_oy) = q(k, 2)*placed
      o2(k, p_c) = ux*placed + (1.0_dp - placed)
      o2(k, p_s) = uy*placed
      o2(k, p_vx) = q(k, 3)*ok
      o2(k, p_vy) = q(k, 4)*ok
      o2(k, p_w) = w1
      o2(k, p_ax) = q(k, 5)*ok
      o2(k, p_ay) = q(k, 6)*ok
      o2(k, p_al) = al1
      o2(k, p_ok) = placed
      o2(k, p_rt) = ok
      ex(k, 1) = st
      ex(k, 2) = abs(e)*placed
      ex(k, 3) = abs(s)
      ex(k, 4) = s*placed
      ex(k, 5) = sd
      ex(k, 6) = sdd
      ! continuity: the slot's point at distance |b| from p, and the other assembly's
      ex(k, 10) = (p(k, 1) + bl*ux)*placed
      ex(k, 11) = (p(k, 2) + bl*uy)*placed
      ex(k, 12) = (p(k, 1) + bl*(-s*bx + e*by)*idd)*placed
      ex(k, 13) = (p(k, 2) + bl*(-s*by - e*bx)*idd)*placed
    end do
  end subroutine dyad_rpr

  !> PRP: J3 on the line offset e1 left of guide g1 and on the line offset e2 left of g2.
  subroutine dyad_prp(m, e1, e2, g1, g2, o1, o2, ex)
    integer, intent(in) :: m
    real(dp), intent(in) :: e1, e2, g1(nb, natt), g2(nb, natt)
    real(dp), intent(inout) :: o1(nb, npose), o2(nb, npose), ex(nb, nex)
    real(dp) :: u1x, u1y, u2x, u2y, n1x, n1y, n2x, n2y, rx, ry, det, s1, s2, jx, jy, inok, rt, par, isdeg
    real(dp) :: st, placed, ok, v1x, v1y, v2x, v2y, dvx, dvy, sd1, sd2, a1x, a1y, a2x, a2y, cx, cy, sdd1, sdd2
    real(dp) :: r1x, r1y, r2x, r2y, w1, w2, al1, al2, dt, scale, idt
    integer :: k
    ! hot-loop: linkage dyad prp
    do k = 1, m
      inok = g1(k, 14)*g2(k, 14)
      rt = g1(k, 15)*g2(k, 15)
      u1x = g1(k, 3)
      u1y = g1(k, 4)
      u2x = g2(k, 3)
      u2y = g2(k, 4)
      n1x = -u1y
      n1y = u1x
      n2x = -u2y
      n2y = u2x
      rx = (g2(k, 1) + e2*n2x) - (g1(k, 1) + e1*n1x)
      ry = (g2(k, 2) + e2*n2y) - (g1(k, 2) + e1*n1y)
      ! s1 u1 - s2 u2 = r;  det = u1 x (-u2)
      det = -(u1x*u2y - u1y*u2x)
      scale = abs(rx) + abs(ry) + abs(e1) + abs(e2)
      par = merge(1.0_dp, 0.0_dp, abs(det) <= tol)
      isdeg = par*merge(1.0_dp, 0.0_dp, abs(rx*n1x + ry*n1y) <= 1.0e-12_dp*scale)
      st = par*(st_no_assembly*(1.0_dp - isdeg) + st_indeterminate*isdeg)
      st = inok*st + (1.0_dp - inok)*st_unplaced
      placed = inok*(1.0_dp - par)
      ok = placed*rt
      dt = placed*det + (1.0_dp - placed)
      idt = placed/dt
      s1 = (-rx*u2y + ry*u2x)*idt
      s2 = (u1x*ry - u1y*rx)*idt
      jx = g1(k, 1) + e1*n1x + s1*u1x
      jy = g1(k, 2) + e1*n1y + s1*u1y
      r1x = jx - g1(k, 5)
      r1y = jy - g1(k, 6)
      r2x = jx - g2(k, 5)
      r2y = jy - g2(k, 6)
      w1 = g1(k, 9)
      w2 = g2(k, 9)
      al1 = g1(k, 12)
      al2 = g2(k, 12)
      v1x = g1(k, 7) - w1*r1y
      v1y = g1(k, 8) + w1*r1x
      v2x = g2(k, 7) - w2*r2y
      v2y = g2(k, 8) + w2*r2x
      dvx = v2x - v1x
      dvy = v2y - v1y
      dt = ok*det + (1.0_dp - ok)
      idt = ok/dt
      sd1 = (-dvx*u2y + dvy*u2x)*idt
      sd2 = (u1x*dvy - u1y*dvx)*idt
      a1x = g1(k, 10) - al1*r1y - w1*w1*r1x + 2*w1*sd1*n1x
      a1y = g1(k, 11) + al1*r1x - w1*w1*r1y + 2*w1*sd1*n1y
      a2x = g2(k, 10) - al2*r2y - w2*w2*r2x + 2*w2*sd2*n2x
      a2y = g2(k, 11) + al2*r2x - w2*w2*r2y + 2*w2*sd2*n2y
      cx = a2x - a1x
      cy = a2y - a1y
      sdd1 = (-cx*u2y + cy*u2x)*idt
      sdd2 = (u1x*cy - u1y*cx)*idt
      o1(k, p_ox) = jx*placed
      o1(k, p_oy) = jy*placed
      o1(k, p_c) = u1x*placed + (1.0_dp - placed)
      o1(k, p_s) = u1y*placed
      o1(k, p_vx) = (v1x + sd1*u1x)*ok
      o1(k, p_vy) = (v1y + sd1*u1y)*ok
      o1(k, p_w) = w1*ok
      o1(k, p_ax) = (a1x + sdd1*u1x)*ok
      o1(k, p_ay) = (a1y + sdd1*u1y)*ok
      o1(k, p_al) = al1*ok
      o1(k, p_ok) = placed
      o1(k, p_rt) = ok
      o2(k, p_ox) = jx*placed
      o2(k, p_oy) = jy*placed
      o2(k, p_c) = u2x*placed + (1.0_dp - placed)
      o2(k, p_s) = u2y*placed
      o2(k, p_vx) = (v1x + sd1*u1x)*ok
      o2(k, p_vy) = (v1y + sd1*u1y)*ok
      o2(k, p_w) = w2*ok
      o2(k, p_ax) = (a1x + sdd1*u1x)*ok
      o2(k, p_ay) = (a1y + sdd1*u1y)*ok
      o2(k, p_al) = al2*ok
      o2(k, p_ok) = placed
      o2(k, p_rt) = ok
      ex(k, 1) = st
      ex(k, 2) = abs(n1x*u2y - n1y*u2x)*placed
      ex(k, 3) = abs(n1x*u2x + n1y*u2y)
      ex(k, 4) = s1
      ex(k, 5) = sd1
      ex(k, 6) = sdd1
      ex(k, 7) = s2
      ex(k, 8) = sd2
      ex(k, 9) = sdd2
    end do
  end subroutine dyad_prp

  ! ======================================================================== forces

  !> The known load of a link from its own motion, gravity and its applied torque tq:
  !> W = m (g - a_G), and its moment about the link's origin, tq - I alpha + (G - O) x W;
  !> w(:, 1:3) = Wx, Wy, M.
  subroutine inertia_load(m, props, grav, tq, pose, w)
    integer, intent(in) :: m
    real(dp), intent(in) :: props(4), grav(2), tq, pose(nb, npose)
    real(dp), intent(inout) :: w(nb, 3)
    real(dp) :: ms, gu, gv, ic, rx, ry, om, al, agx, agy, wx, wy
    integer :: k
    ms = props(1)
    gu = props(2)
    gv = props(3)
    ic = props(4)
    ! hot-loop: linkage inertia load
    do k = 1, m
      rx = gu*pose(k, p_c) - gv*pose(k, p_s)
      ry = gu*pose(k, p_s) + gv*pose(k, p_c)
      om = pose(k, p_w)
      al = pose(k, p_al)
      agx = pose(k, p_ax) - al*ry - om*om*rx
      agy = pose(k, p_ay) + al*rx - om*om*ry
      wx = ms*(grav(1) - agx)
      wy = ms*(grav(2) - agy)
      w(k, 1) = wx
      w(k, 2) = wy
      w(k, 3) = tq - ic*al + (rx*wy - ry*wx)
    end do
  end subroutine inertia_load

  !> Adds a force (fx, fy) at (px, py) and a couple q to a link's load (moment about its origin).
  subroutine apply(m, px, py, fx, fy, q, pose, w)
    integer, intent(in) :: m
    real(dp), intent(in) :: px(nb), py(nb), fx(nb), fy(nb), q(nb), pose(nb, npose)
    real(dp), intent(inout) :: w(nb, 3)
    integer :: k
    ! hot-loop: linkage apply
    do k = 1, m
      w(k, 1) = w(k, 1) + fx(k)
      w(k, 2) = w(k, 2) + fy(k)
      w(k, 3) = w(k, 3) + (px(k) - pose(k, p_ox))*fy(k) - (py(k) - pose(k, p_oy))*fx(k) + q(k)
    end do
  end subroutine apply

  !> RRR: link 1 from its origin a1 to J3 (length l1), link 2 from its origin a2 to J3.
  !> Unknowns F1 (on link 1 at a1), F2 (on link 2 at a2), F3 (link 1 on link 2 at J3):
  !>   c1 x F1 = -M1@J3,  c2 x F1 = c2 x S + M2@J3   (c_i = a_i - J3, S = -(W1 + W2)),
  !>   F2 = S - F1,  F3 = F1 + W1;  M_i@J3 = M_i + c_i x W_i (M_i about the origin a_i).
  subroutine force_rrr(m, l1, o1, o2, w1, w2, rx)
    integer, intent(in) :: m
    real(dp), intent(in) :: l1, o1(nb, npose), o2(nb, npose), w1(nb, 3), w2(nb, 3)
    real(dp), intent(inout) :: rx(nb, 9)
    real(dp) :: jx, jy, c1x, c1y, c2x, c2y, b1, b2, sx, sy, det, f1x, f1y, ok
    integer :: k
    ! hot-loop: linkage force rrr
    do k = 1, m
      ok = o1(k, p_rt)*o2(k, p_rt)
      jx = o1(k, p_ox) + l1*o1(k, p_c)
      jy = o1(k, p_oy) + l1*o1(k, p_s)
      c1x = o1(k, p_ox) - jx
      c1y = o1(k, p_oy) - jy
      c2x = o2(k, p_ox) - jx
      c2y = o2(k, p_oy) - jy
      sx = -(w1(k, 1) + w2(k, 1))
      sy = -(w1(k, 2) + w2(k, 2))
      b1 = -(w1(k, 3) + (c1x*w1(k, 2) - c1y*w1(k, 1)))
      b2 = (c2x*sy - c2y*sx) + (w2(k, 3) + (c2x*w2(k, 2) - c2y*w2(k, 1)))
      det = ok*(c1x*c2y - c1y*c2x) + (1.0_dp - ok)
      f1x = ok*(b1*c2x - c1x*b2)/det
      f1y = ok*(b1*c2y - c1y*b2)/det
      rx(k, 1) = f1x
      rx(k, 2) = f1y
      rx(k, 3) = 0.0_dp
      rx(k, 4) = ok*(sx - f1x)
      rx(k, 5) = ok*(sy - f1y)
      rx(k, 6) = 0.0_dp
      rx(k, 7) = ok*(f1x + w1(k, 1))
      rx(k, 8) = ok*(f1y + w1(k, 2))
      rx(k, 9) = 0.0_dp
    end do
  end subroutine force_rrr

  !> RRP: the rod (link 1, origin a1) and the block (link 2, origin J3, x-axis u along the guide).
  !>   u . F1 = -u . (W1 + W2),  c1 x F1 = -M1@J3  (c1 = a1 - J3);
  !>   F3 = F1 + W1 (rod on block), N = -(F3 + W2) . n, couple Q = -M2 (guide on block).
  subroutine force_rrp(m, o1, o2, w1, w2, rx)
    integer, intent(in) :: m
    real(dp), intent(in) :: o1(nb, npose), o2(nb, npose), w1(nb, 3), w2(nb, 3)
    real(dp), intent(inout) :: rx(nb, 9)
    real(dp) :: ux, uy, c1x, c1y, cu, b1, det, f1x, f1y, f3x, f3y, nn, ok
    integer :: k
    ! hot-loop: linkage force rrp
    do k = 1, m
      ok = o1(k, p_rt)*o2(k, p_rt)
      ux = o2(k, p_c)
      uy = o2(k, p_s)
      c1x = o1(k, p_ox) - o2(k, p_ox)
      c1y = o1(k, p_oy) - o2(k, p_oy)
      cu = -((w1(k, 1) + w2(k, 1))*ux + (w1(k, 2) + w2(k, 2))*uy)
      b1 = -(w1(k, 3) + (c1x*w1(k, 2) - c1y*w1(k, 1)))
      ! [ux uy; -c1y c1x] F1 = [cu; b1]
      det = ok*(ux*c1x + uy*c1y) + (1.0_dp - ok)
      f1x = ok*(cu*c1x - uy*b1)/det
      f1y = ok*(ux*b1 + c1y*cu)/det
      f3x = f1x + w1(k, 1)
      f3y = f1y + w1(k, 2)
      nn = -((f3x + w2(k, 1))*(-uy) + (f3y + w2(k, 2))*ux)
      rx(k, 1) = f1x
      rx(k, 2) = f1y
      rx(k, 3) = 0.0_dp
      rx(k, 4) = -ok*nn*uy
      rx(k, 5) = ok*nn*ux
      rx(k, 6) = -ok*w2(k, 3)
      rx(k, 7) = ok*f3x
      rx(k, 8) = ok*f3y
      rx(k, 9) = 0.0_dp
    end do
  end subroutine force_rrp

  !> RPR: link 1 (origin a1, slot along u) and the block (link 2, origin a2).
  !>   N = (M1 + M2@a2 ...) / s: the moments of link 1 about a1 and of the block about a2 give
  !>   Q = -M2 and b x (N n) = M1 + M2 with b = a2 - a1, b x n = s;
  !>   F1 = N n - W1, F2 = -N n - W2.
  subroutine force_rpr(m, o1, o2, w1, w2, rx)
    integer, intent(in) :: m
    real(dp), intent(in) :: o1(nb, npose), o2(nb, npose), w1(nb, 3), w2(nb, 3)
    real(dp), intent(inout) :: rx(nb, 9)
    real(dp) :: ux, uy, nx, ny, bx, by, s, nn, ok
    integer :: k
    ! hot-loop: linkage force rpr
    do k = 1, m
      ok = o1(k, p_rt)*o2(k, p_rt)
      ux = o1(k, p_c)
      uy = o1(k, p_s)
      nx = -uy
      ny = ux
      bx = o2(k, p_ox) - o1(k, p_ox)
      by = o2(k, p_oy) - o1(k, p_oy)
      s = ok*(bx*ux + by*uy) + (1.0_dp - ok)
      nn = ok*(w1(k, 3) + w2(k, 3))/s
      rx(k, 1) = ok*(nn*nx - w1(k, 1))
      rx(k, 2) = ok*(nn*ny - w1(k, 2))
      rx(k, 3) = 0.0_dp
      rx(k, 4) = ok*(-nn*nx - w2(k, 1))
      rx(k, 5) = ok*(-nn*ny - w2(k, 2))
      rx(k, 6) = 0.0_dp
      rx(k, 7) = nn*nx
      rx(k, 8) = nn*ny
      rx(k, 9) = -ok*w2(k, 3)
    end do
  end subroutine force_rpr

  !> PRP: blocks 1 and 2 (origins J3, x-axes u1, u2): N1 n1 + N2 n2 = -(W1 + W2),
  !> couples Q_i = -M_i, F3 = N1 n1 + W1 (block 1 on block 2).
  subroutine force_prp(m, o1, o2, w1, w2, rx)
    integer, intent(in) :: m
    real(dp), intent(in) :: o1(nb, npose), o2(nb, npose), w1(nb, 3), w2(nb, 3)
    real(dp), intent(inout) :: rx(nb, 9)
    real(dp) :: n1x, n1y, n2x, n2y, sx, sy, det, a, b, ok
    integer :: k
    ! hot-loop: linkage force prp
    do k = 1, m
      ok = o1(k, p_rt)*o2(k, p_rt)
      n1x = -o1(k, p_s)
      n1y = o1(k, p_c)
      n2x = -o2(k, p_s)
      n2y = o2(k, p_c)
      sx = -(w1(k, 1) + w2(k, 1))
      sy = -(w1(k, 2) + w2(k, 2))
      det = ok*(n1x*n2y - n1y*n2x) + (1.0_dp - ok)
      a = ok*(sx*n2y - sy*n2x)/det
      b = ok*(n1x*sy - n1y*sx)/det
      rx(k, 1) = a*n1x
      rx(k, 2) = a*n1y
      rx(k, 3) = -ok*w1(k, 3)
      rx(k, 4) = b*n2x
      rx(k, 5) = b*n2y
      rx(k, 6) = -ok*w2(k, 3)
      rx(k, 7) = ok*(a*n1x + w1(k, 1))
      rx(k, 8) = ok*(a*n1y + w1(k, 2))
      rx(k, 9) = 0.0_dp
    end do
  end subroutine force_prp

  !> The driver's link with its known load w: crank (origin the pivot) f = (F_pivot, 0, T),
  !> F = -W, T = -M; slider (origin the pin, x-axis u) f = (N n, Q, P), P = -W . u,
  !> N = -W . n, Q = -M.
  subroutine force_driver(m, kind, pose, w, f)
    integer, intent(in) :: m, kind
    real(dp), intent(in) :: pose(nb, npose), w(nb, 3)
    real(dp), intent(inout) :: f(nb, 4)
    real(dp) :: ux, uy, nn
    integer :: k
    if (kind == drv_crank) then
      do k = 1, m
        f(k, 1) = -w(k, 1)
        f(k, 2) = -w(k, 2)
        f(k, 3) = 0.0_dp
        f(k, 4) = -w(k, 3)
      end do
    else
      do k = 1, m
        ux = pose(k, p_c)
        uy = pose(k, p_s)
        nn = -(w(k, 1)*(-uy) + w(k, 2)*ux)
        f(k, 1) = -nn*uy
        f(k, 2) = nn*ux
        f(k, 3) = -w(k, 3)
        f(k, 4) = -(w(k, 1)*ux + w(k, 2)*uy)
      end do
    end if
  end subroutine force_driver

  ! ======================================================================== energy

  !> Energy of a turning-moment diagram given as a table: torque tq(1:nt) [N m] at crank
  !> angles th(1:nt) [rad] (ascending, one cycle from th(1) to th(nt)), linear in between
  !> (the integrals are exact for that).  With cs the coefficient of speed fluctuation and
  !> omega the mean speed [rad/s]:
  !>   res(1) mean torque [N m] = (integral of T) / (th(nt) - th(1))
  !>   res(2) energy fluctuation dE [J]: max - min of E(th) = integral of (T - mean) from th(1)
  !>   res(3) flywheel inertia dE / (cs omega^2) [kg m^2] (0 when cs or omega is 0)
  !>   res(4), res(5) the angles of the energy's maximum and minimum [rad]
  !>   res(6) the work of one cycle [J]; res(7), res(8) the largest and smallest torque [N m]
  subroutine table_energy(nt, th, tq, cs, omega, res)
    integer, intent(in) :: nt
    real(dp), intent(in) :: th(nt), tq(nt), cs, omega
    real(dp), intent(out) :: res(8)   ! nenergy
    call energy_of(nt, th, tq, .false., cs, omega, res)
  end subroutine table_energy

  !> table_energy's work; periodic: the samples are one cycle without its end point, and the
  !> last interval closes the cycle (th(1) + period, tq(1)) with period = nt * step.
  subroutine energy_of(nt, th, tq, periodic, cs, omega, res)
    integer, intent(in) :: nt
    real(dp), intent(in) :: th(nt), tq(nt), cs, omega
    logical, intent(in) :: periodic
    real(dp), intent(out) :: res(nenergy)
    real(dp) :: work, span, tm, e, ea, t0, t1, x0, x1, f0, f1, xz, ez, emax, emin, xmax, xmin
    integer :: k, nseg
    res = 0.0_dp
    if (nt < 2) return
    nseg = nt - 1
    if (periodic) nseg = nt
    if (periodic) then
      span = (th(nt) - th(1))*real(nt, dp)/real(nt - 1, dp)
    else
      span = th(nt) - th(1)
    end if
    if (span <= 0.0_dp) return
    work = 0.0_dp
    do k = 1, nseg
      call seg(k, x0, x1, f0, f1)
      work = work + 0.5_dp*(f0 + f1)*(x1 - x0)
    end do
    tm = work/span
    e = 0.0_dp
    emax = 0.0_dp
    emin = 0.0_dp
    xmax = th(1)
    xmin = th(1)
    do k = 1, nseg
      call seg(k, x0, x1, f0, f1)
      t0 = f0 - tm
      t1 = f1 - tm
      ea = e
      e = e + 0.5_dp*(t0 + t1)*(x1 - x0)
      ! an extremum of E inside the segment where T - mean changes sign
      if (t0*t1 < 0.0_dp) then
        xz = t0/(t0 - t1)
        ez = ea + t0*xz*(x1 - x0)*0.5_dp
        call keep(ez, x0 + xz*(x1 - x0))
      end if
      call keep(e, x1)
    end do
    res(1) = tm
    res(2) = emax - emin
    if (cs > 0.0_dp .and. omega /= 0.0_dp) res(3) = res(2)/(cs*omega*omega)
    res(4) = xmax
    res(5) = xmin
    res(6) = work
    res(7) = maxval(tq)
    res(8) = minval(tq)

  contains

    subroutine seg(k, a, b, fa, fb)
      integer, intent(in) :: k
      real(dp), intent(out) :: a, b, fa, fb
      a = th(k)
      fa = tq(k)
      if (k < nt) then
        b = th(k + 1)
        fb = tq(k + 1)
      else
        b = th(1) + span
        fb = tq(1)
      end if
    end subroutine seg

    subroutine keep(v, at)
      real(dp), intent(in) :: v, at
      if (v > emax) then
        emax = v
        xmax = at
      end if
      if (v < emin) then
        emin = v
        xmin = at
      end if
    end subroutine keep

  end subroutine energy_of

  ! ======================================================================== summaries

  !> Summaries of nds designs of one mechanism (one topology, the numbers varying) in one call.
  !> Each design's numbers are one column of prm (contiguous), packed in this order (see
  !> driver/linkage/_kernel_program.py):
  !>   rpts (np x 2, column-major), rgd (ng x 3), rdrv (3), rdy (nd x 3), rl (nl x 4), grav (2),
  !>   rld (nld x 2), rtq (nl), rft (3), tab (nt x 2), then scan: x0, span, cs.
  !> The scan: nscan inputs from x0 over span (periodic = 1: a crank's cycle, without the end
  !> point; 0: both ends).  iout = (kind, index): the output element, 1 a link's angle, 2 a slide.
  !> want as analyse (forces when the deck gives masses); passes: the sum of the pass_* bits to
  !> run (a pass not run leaves its columns 0; the others are the same whichever passes run).
  !> res(:, i) the summary row of design i: nsum_head columns, then nsum_link per moving link (2..nl),
  !> nsum_slide per slide, nsum_dyad per dyad:
  !>   1 assembled fraction (all dyads st_ok)    2 positions not assembled   3 toggle positions
  !>   4, 5 output minimum and its input          6, 7 output maximum and its input
  !>   8 stroke (max - min)                       9 time ratio (>= 1; 0: none)
  !>   10, 11 smallest and largest transmission angle of the RRR dyads [rad] (0: none)
  !>   12 largest pressure angle of the sliding dyads [rad]
  !>   13, 14 peak |driving torque or force| (signed) and its input
  !>   15, 16 mean and RMS driving torque or force    17 peak |shaking force|
  !>   18 peak |shaking moment|    19 energy fluctuation [J]   20 flywheel inertia [kg m^2]
  !>   21, 22 input of the smallest and largest transmission angle
  !>   per link: peak omega, peak alpha (signed: the largest in size)
  !>   per slide: minimum, maximum, peak rate, peak acceleration
  !>   per dyad: smallest and largest transmission or pressure angle [rad]
  !> Extremes of the output are refined between scan points on the quintic Hermite model
  !> (position and its first and second derivatives at both ends); peak rates (omega, slide rate)
  !> on the cubic Hermite model (the rate and its derivative, from the acceleration); peaks of the
  !> other quantities by the parabola through three scan points.  Figures that need the whole cycle assembled (stroke, time
  !> ratio, torque mean, energy) are 0 unless it is.
  subroutine summaries(nds, nr, prm, nl, np, ng, nd, ns, nld, nt, idrv, ipts, igd, idy, ild, ift, nscan, &
                       periodic, iout, want, passes, ncol, res)
    !f2py threadsafe
    integer, intent(in) :: nds, nr, nl, np, ng, nd, ns, nld, nt, nscan, periodic, want, passes, ncol
    real(dp), intent(in) :: prm(nr, nds)
    integer, intent(in) :: idrv(4), ipts(np), igd(ng), idy(nd, 6), ild(nld), ift(4), iout(2)
    real(dp), intent(out) :: res(ncol, nds)
    real(dp) :: rpts(np, 2), rgd(ng, 3), rdrv(3), rdy(nd, 3), rl(nl, 4), grav(2), rld(nld, 2), rtq(nl), &
                rft(3), tab(nt, 2), x0, span, cs, h
    real(dp), allocatable :: x(:), lk(:, :, :), pk(:, :, :), sk(:, :, :), qa(:, :), fk(:, :, :), fd(:, :), &
                             sh(:, :), y(:), dy(:), ddy(:), row(:), en(:)
    logical, allocatable :: okrow(:)
    real(dp), allocatable :: pose(:, :, :), att(:, :, :, :)
    integer, allocatable :: st(:, :), flags(:, :)
    integer :: i, k, o, l, j, d, c, n, nok, wk, asel, rsel
    logical :: whole, do_out, do_q, do_pk, do_f
    n = max(nscan, 2)
    ! the outputs the passes read (never the points): the output's angle and rates (a link) or
    ! its slide; the transmission and pressure angles; every link's rates and the slides; forces
    do_out = iand(passes, pass_output) /= 0
    do_q = iand(passes, pass_quality) /= 0
    do_pk = iand(passes, pass_peaks) /= 0
    do_f = iand(passes, pass_forces) /= 0 .and. iand(want, want_forces) /= 0
    wk = iand(want, want_continuity)
    if (do_f) wk = ior(wk, want_forces)
    if (do_q) wk = ior(wk, want_quality)
    if (do_pk) wk = ior(wk, want_link_rates + want_slides)
    asel = -1
    rsel = -1
    if (do_out .and. iout(1) == 1) then
      wk = ior(wk, want_angles + want_link_rates)
      asel = iout(2)
      rsel = iout(2)
    else if (do_out) then
      wk = ior(wk, want_slides)
    end if
    if (do_pk) rsel = 0
    allocate (x(n), lk(n, 3, nl), pk(n, 6, np), sk(n, 3, max(ns, 1)), qa(n, nd), fk(n, 9, nd), fd(n, 4), &
              sh(n, 3), st(n, nd), y(n), dy(n), ddy(n), row(ncol), en(nenergy), okrow(n), flags(n, 3))
    allocate (pose(nb, npose, nl), att(nb, natt, 2, nd))   ! the blocks' work arrays, once for all designs
    sk = 0.0_dp   ! a mechanism without slides is given one inert slide, never written by analyse
    do i = 1, nds
      o = 0
      call take(rpts, 2*np)
      call take(rgd, 3*ng)
      call take(rdrv, 3)
      call take(rdy, 3*nd)
      call take(rl, 4*nl)
      call take(grav, 2)
      call take(rld, 2*nld)
      call take(rtq, nl)
      call take(rft, 3)
      call take(tab, 2*nt)
      x0 = prm(o + 1, i)
      span = prm(o + 2, i)
      cs = prm(o + 3, i)
      if (periodic == 1) then
        h = span/real(n, dp)
      else
        h = span/real(n - 1, dp)
      end if
      do k = 1, n
        x(k) = x0 + h*real(k - 1, dp)
      end do
      call analyse_core(n, nl, np, ng, nd, max(ns, 1), nld, nt, n, x, idrv, rdrv, ipts, rpts, igd, rgd, idy, &
                        rdy, rl, grav, ild, rld, rtq, ift, tab, rft, wk, asel, rsel, lk, pk, sk, qa, st, fk, fd, &
                        sh, pose, att, i == 1)
      row = 0.0_dp
      ! per row: some group not ok, not placed (neither ok nor a toggle), at a toggle
      flags = 0
      do d = 1, nd
        do k = 1, n
          flags(k, 1) = ior(flags(k, 1), merge(1, 0, st(k, d) /= st_ok))
          flags(k, 2) = ior(flags(k, 2), merge(1, 0, st(k, d) /= st_ok .and. st(k, d) /= st_toggle))
          flags(k, 3) = ior(flags(k, 3), merge(1, 0, st(k, d) == st_toggle))
        end do
      end do
      okrow = flags(:, 1) == 0
      nok = n - sum(flags(:, 1))
      row(1) = real(nok, dp)/real(n, dp)
      row(2) = real(sum(flags(:, 2)), dp)
      row(3) = real(sum(flags(:, 3)), dp)
      whole = nok == n
      if (do_out) call output_pass()
      if (do_q) call quality_pass()
      if (do_pk) call peaks_pass()
      if (do_f .and. nok > 0) call forces_pass()
      res(:, i) = row
    end do

  contains

    !> The output element: position y and its derivatives over the input; its extremes, stroke
    !> and time ratio (the whole cycle assembled).
    subroutine output_pass()
      if (iout(1) == 1) then
        call unwrap(n, lk(:, 1, iout(2)), y)
        dy = lk(:, 2, iout(2))
      else
        y = sk(:, 1, iout(2))
        dy = sk(:, 2, iout(2))
      end if
      ! derivatives over the input: y' = rate / w, y'' = (acceleration - a y') / w^2
      if (iout(1) == 1) then
        ddy = lk(:, 3, iout(2))
      else
        ddy = sk(:, 3, iout(2))
      end if
      if (rdrv(2) /= 0.0_dp) then
        dy = dy/rdrv(2)
        ddy = (ddy - rdrv(3)*dy)/rdrv(2)**2
      else
        dy = 0.0_dp
        ddy = 0.0_dp
      end if
      if (whole) call output_extremes()
    end subroutine output_pass

    !> The transmission and pressure angles: each group's range, the RRR groups' extremes with
    !> their inputs, the sliding groups' largest.
    subroutine quality_pass()
      row(10) = 0.0_dp
      row(11) = 0.0_dp
      c = 0
      do d = 1, nd
        call min_max(n, qa(:, d), st(:, d) == st_ok, periodic == 1, &
                     row(nsum_head + nsum_link*(nl - 1) + nsum_slide*ns + nsum_dyad*(d - 1) + 1), &
                     row(nsum_head + nsum_link*(nl - 1) + nsum_slide*ns + nsum_dyad*(d - 1) + 2), h, x0)
        if (idy(d, 1) == dy_rrr) then
          call min_max_at(n, qa(:, d), st(:, d) == st_ok, periodic == 1, h, x0, row, c)
        else
          row(12) = max(row(12), row(nsum_head + nsum_link*(nl - 1) + nsum_slide*ns + nsum_dyad*(d - 1) + 2))
        end if
      end do
    end subroutine quality_pass

    !> Each link's peak omega and alpha, each slide's range and peak rate and acceleration.
    !> The rates' peaks are refined on the cubic Hermite model (each rate and its derivative
    !> over the input, from the acceleration); the accelerations' by the parabola.
    subroutine peaks_pass()
      do l = 2, nl
        j = nsum_head + nsum_link*(l - 2)
        row(j + 1) = rate_peak(n, lk(:, 2, l), lk(:, 3, l), rdrv(2), rdrv(3), okrow, periodic == 1, h)
        row(j + 2) = peak(n, lk(:, 3, l), okrow, periodic == 1)
      end do
      do l = 1, ns
        j = nsum_head + nsum_link*(nl - 1) + nsum_slide*(l - 1)
        if (whole) then
          row(j + 1) = minval(sk(:, 1, l))
          row(j + 2) = maxval(sk(:, 1, l))
        end if
        row(j + 3) = rate_peak(n, sk(:, 2, l), sk(:, 3, l), rdrv(2), rdrv(3), okrow, periodic == 1, h)
        row(j + 4) = peak(n, sk(:, 3, l), okrow, periodic == 1)
      end do
    end subroutine peaks_pass

    !> The driving torque's peak, mean and RMS, the shaking force's and moment's peaks, the
    !> energy fluctuation and the flywheel.
    subroutine forces_pass()
      call peak_at(n, fd(:, 4), okrow, periodic == 1, h, x0, row(13), row(14))
      row(17) = maxval(hypot(sh(:, 1), sh(:, 2)))
      row(18) = maxval(abs(sh(:, 3)))
      if (whole) then
        if (periodic == 1) then
          row(15) = sum(fd(:, 4))/real(n, dp)
          row(16) = sqrt(sum(fd(:, 4)**2)/real(n, dp))
          call energy_of(n, x, fd(:, 4), .true., cs, rdrv(2), en)
          row(19) = en(2)
          row(20) = en(3)
        else
          row(15) = (0.5_dp*(fd(1, 4) + fd(n, 4)) + sum(fd(2:n - 1, 4)))/real(n - 1, dp)
          row(16) = sqrt((0.5_dp*(fd(1, 4)**2 + fd(n, 4)**2) + sum(fd(2:n - 1, 4)**2))/real(n - 1, dp))
        end if
      end if
    end subroutine forces_pass

    subroutine take(a, cnt)
      integer, intent(in) :: cnt
      real(dp), intent(out) :: a(*)
      if (cnt > 0) a(1:cnt) = prm(o + 1:o + cnt, i)
      o = o + cnt
    end subroutine take

    !> Extremes of the output y over the scan, refined on the quintic Hermite model, the stroke
    !> and the time ratio (periodic scans).  An output link that turns fully has none.
    subroutine output_extremes()
      real(dp) :: best(2), at(2), v, t, ang, yend, tie
      integer :: kk, k2, nseg
      if (periodic == 1 .and. iout(1) == 1) then
        ! a link that comes back turned by a multiple of 2 pi turns fully
        if (abs(anint((y(n) + h*dy(n) - y(1))/(2*pi))) > 0.0_dp) return
      end if
      best(1) = y(1)
      best(2) = y(1)
      at = x(1)
      do kk = 2, n
        if (y(kk) < best(1)) then
          best(1) = y(kk)
          at(1) = x(kk)
        end if
        if (y(kk) > best(2)) then
          best(2) = y(kk)
          at(2) = x(kk)
        end if
      end do
      nseg = n - 1
      if (periodic == 1) nseg = n
      do kk = 1, nseg
        k2 = kk + 1
        yend = 0.0_dp
        if (k2 > n) then
          k2 = 1
        end if
        yend = y(k2)
        if (dy(kk)*dy(k2) < 0.0_dp) then
          call hermite_extremum(y(kk), yend, dy(kk)*h, dy(k2)*h, ddy(kk)*h*h, ddy(k2)*h*h, t, v)
          ! the earliest of equal extremes (a 720 deg cycle repeats the motion: ties within rounding)
          tie = 1.0e-12_dp*(abs(best(2) - best(1)) + abs(v))
          if (v < best(1) - tie .or. (abs(v - best(1)) <= tie .and. x(kk) + t*h < at(1))) then
            best(1) = v
            at(1) = x(kk) + t*h
          end if
          if (v > best(2) + tie .or. (abs(v - best(2)) <= tie .and. x(kk) + t*h < at(2))) then
            best(2) = v
            at(2) = x(kk) + t*h
          end if
        end if
      end do
      row(4) = best(1)
      row(5) = at(1)
      row(6) = best(2)
      row(7) = at(2)
      row(8) = best(2) - best(1)
      if (periodic == 1) then
        ! the kinematic period of a crank is one turn (a 720 deg load cycle holds two strokes each)
        ang = modulo(at(2) - at(1), 2*pi)
        if (ang > 0.0_dp .and. ang < 2*pi) row(9) = max(ang, 2*pi - ang)/min(ang, 2*pi - ang)
      end if
    end subroutine output_extremes

    !> Smallest and largest transmission angle of an RRR dyad and their inputs (c counts the
    !> RRR dyads seen: the first sets the figures, later ones extend them).
    subroutine min_max_at(nn, v, okv, per, hh, xx0, r, cnt)
      integer, intent(in) :: nn
      real(dp), intent(in) :: v(nn), hh, xx0
      logical, intent(in) :: okv(nn), per
      real(dp), intent(inout) :: r(:)
      integer, intent(inout) :: cnt
      real(dp) :: lo, hi, xlo, xhi
      call extreme(nn, v, okv, per, -1.0_dp, hh, xx0, lo, xlo)
      call extreme(nn, v, okv, per, 1.0_dp, hh, xx0, hi, xhi)
      if (.not. any(okv)) return
      if (cnt == 0 .or. lo < r(10)) then
        r(10) = lo
        r(21) = xlo
      end if
      if (cnt == 0 .or. hi > r(11)) then
        r(11) = hi
        r(22) = xhi
      end if
      cnt = cnt + 1
    end subroutine min_max_at

  end subroutine summaries

  !> The extremum of the quintic Hermite interpolant on [0, 1] with end values y0, y1, first
  !> derivatives d0, d1 and second derivatives s0, s1 (per unit of the interval), where the slope
  !> changes sign (d0 d1 < 0): t and the value.  Newton on the slope, kept inside its bracket
  !> (bisection when a step leaves it).
  pure subroutine hermite_extremum(y0, y1, d0, d1, s0, s1, t, v)
    real(dp), intent(in) :: y0, y1, d0, d1, s0, s1
    real(dp), intent(out) :: t, v
    real(dp) :: lo, hi, f, fp, flo, tn
    integer :: it
    lo = 0.0_dp
    hi = 1.0_dp
    flo = d0
    ! the cubic Hermite's estimate: the linear zero of the slope
    t = d0/(d0 - d1)
    do it = 1, 60
      call slope(t, f, fp)
      if (f == 0.0_dp) exit
      if (sign(1.0_dp, f) == sign(1.0_dp, flo)) then
        lo = t
        flo = f
      else
        hi = t
      end if
      tn = t - f/fp
      if (.not. (tn > lo .and. tn < hi)) tn = 0.5_dp*(lo + hi)
      if (abs(tn - t) <= 1.0e-15_dp) then
        t = tn
        exit
      end if
      t = tn
    end do
    v = (1.0_dp - 10.0_dp*t**3 + 15.0_dp*t**4 - 6.0_dp*t**5)*y0 + (t - 6.0_dp*t**3 + 8.0_dp*t**4 - 3.0_dp*t**5)*d0 &
        + 0.5_dp*(t**2 - 3.0_dp*t**3 + 3.0_dp*t**4 - t**5)*s0 + 0.5_dp*(t**3 - 2.0_dp*t**4 + t**5)*s1 &
        + (-4.0_dp*t**3 + 7.0_dp*t**4 - 3.0_dp*t**5)*d1 + (10.0_dp*t**3 - 15.0_dp*t**4 + 6.0_dp*t**5)*y1

  contains

    pure subroutine slope(tt, f, fp)
      real(dp), intent(in) :: tt
      real(dp), intent(out) :: f, fp
      f = (-30.0_dp*tt**2 + 60.0_dp*tt**3 - 30.0_dp*tt**4)*y0 + (1.0_dp - 18.0_dp*tt**2 + 32.0_dp*tt**3 &
          - 15.0_dp*tt**4)*d0 + 0.5_dp*(2.0_dp*tt - 9.0_dp*tt**2 + 12.0_dp*tt**3 - 5.0_dp*tt**4)*s0 &
          + 0.5_dp*(3.0_dp*tt**2 - 8.0_dp*tt**3 + 5.0_dp*tt**4)*s1 + (-12.0_dp*tt**2 + 28.0_dp*tt**3 &
          - 15.0_dp*tt**4)*d1 + (30.0_dp*tt**2 - 60.0_dp*tt**3 + 30.0_dp*tt**4)*y1
      fp = (-60.0_dp*tt + 180.0_dp*tt**2 - 120.0_dp*tt**3)*y0 + (-36.0_dp*tt + 96.0_dp*tt**2 - 60.0_dp*tt**3)*d0 &
           + 0.5_dp*(2.0_dp - 18.0_dp*tt + 36.0_dp*tt**2 - 20.0_dp*tt**3)*s0 &
           + 0.5_dp*(6.0_dp*tt - 24.0_dp*tt**2 + 20.0_dp*tt**3)*s1 + (-24.0_dp*tt + 84.0_dp*tt**2 &
           - 60.0_dp*tt**3)*d1 + (60.0_dp*tt - 180.0_dp*tt**2 + 120.0_dp*tt**3)*y1
    end subroutine slope

  end subroutine hermite_extremum

  !> Unwrapped angle: consecutive values differ by less than pi.
  pure subroutine unwrap(n, a, y)
    integer, intent(in) :: n
    real(dp), intent(in) :: a(n)
    real(dp), intent(out) :: y(n)
    real(dp) :: turns(n)
    integer :: k
    ! the whole turns to take off each step, then the running sum (in the same order of operations)
    do k = 2, n
      turns(k) = 2*pi*anint((a(k) - a(k - 1))/(2*pi))
    end do
    y(1) = a(1)
    do k = 2, n
      y(k) = y(k - 1) + (a(k) - a(k - 1)) - turns(k)
    end do
  end subroutine unwrap

  !> The value of v largest in size (signed) over the rows okv, refined by the parabola through
  !> the neighbouring scan points.
  real(dp) function peak(n, v, okv, per)
    integer, intent(in) :: n
    real(dp), intent(in) :: v(n)
    logical, intent(in) :: okv(n), per
    real(dp) :: at
    call peak_at(n, v, okv, per, 1.0_dp, 0.0_dp, peak, at)
  end function peak

  !> The value of a rate v (a link's omega or a slide's rate) largest in size (signed) over the
  !> rows okv, refined on the cubic Hermite model of the two scan intervals (step h) beside the
  !> largest scan value where the rate's derivative over the input changes sign.  That derivative
  !> comes from the acceleration a: v = g' w and a = g'' w^2 + g' al (w, al: the driver's rate
  !> and acceleration), so dv/dx = g'' w = (a - v al / w) / w (no refinement when w = 0: every
  !> rate is 0).
  real(dp) function rate_peak(n, v, a, w0, al0, okv, per, h)
    integer, intent(in) :: n
    real(dp), intent(in) :: v(n), a(n), w0, al0, h
    logical, intent(in) :: okv(n), per
    real(dp) :: w(n), sgn, e, d0, d1
    integer :: k, k0, k1, side
    rate_peak = 0.0_dp
    if (.not. any(okv)) return
    w = abs(v)
    ! the first of the largest within rounding, as peak_at
    k = findloc(okv .and. w >= maxval(w, mask=okv)*(1.0_dp - tie_rel), .true., 1)
    rate_peak = v(k)
    sgn = sign(1.0_dp, v(k))
    if (w0 == 0.0_dp) return
    do side = -1, 0
      k0 = k + side
      k1 = k0 + 1
      if (per) then
        if (k0 < 1) k0 = n
        if (k1 > n) k1 = 1
      end if
      if (k0 < 1 .or. k1 > n) cycle
      if (.not. (okv(k0) .and. okv(k1))) cycle
      d0 = (a(k0) - v(k0)*(al0/w0))/w0
      d1 = (a(k1) - v(k1)*(al0/w0))/w0
      if (.not. (d0*d1 < 0.0_dp)) cycle
      e = cubic_extremum(v(k0), v(k1), d0*h, d1*h)
      if (sgn*e > sgn*rate_peak) rate_peak = e
    end do
  end function rate_peak

  !> The extremum of the cubic Hermite interpolant on [0, 1] with end values y0, y1 and first
  !> derivatives d0, d1 (per unit of the interval) of opposite signs: its slope, a quadratic,
  !> has exactly one zero in (0, 1), taken in closed form (the root formula without cancellation).
  pure real(dp) function cubic_extremum(y0, y1, d0, d1) result(v)
    real(dp), intent(in) :: y0, y1, d0, d1
    real(dp) :: c2, c1, q, t, ta, tb
    ! p'(t) = c2 t^2 + c1 t + d0
    c2 = 6.0_dp*(y0 - y1) + 3.0_dp*(d0 + d1)
    c1 = -6.0_dp*(y0 - y1) - 4.0_dp*d0 - 2.0_dp*d1
    if (c2 == 0.0_dp) then
      t = -d0/c1
    else
      q = -0.5_dp*(c1 + sign(sqrt(max(c1*c1 - 4.0_dp*c2*d0, 0.0_dp)), c1))
      ta = q/c2
      tb = d0/q
      ! the zero inside the interval (the other, if real, lies outside)
      if (abs(ta - 0.5_dp) <= abs(tb - 0.5_dp)) then
        t = ta
      else
        t = tb
      end if
    end if
    t = min(max(t, 0.0_dp), 1.0_dp)
    v = (2.0_dp*t**3 - 3.0_dp*t**2 + 1.0_dp)*y0 + (t**3 - 2.0_dp*t**2 + t)*d0 + (3.0_dp*t**2 - 2.0_dp*t**3)*y1 &
        + (t**3 - t**2)*d1
  end function cubic_extremum

  !> peak with the input at which it occurs (scan step h from x0).
  subroutine peak_at(n, v, okv, per, h, x0, val, at)
    integer, intent(in) :: n
    real(dp), intent(in) :: v(n), h, x0
    logical, intent(in) :: okv(n), per
    real(dp), intent(out) :: val, at
    real(dp) :: w(n)
    integer :: k
    w = abs(v)
    if (.not. any(okv)) then
      val = 0.0_dp
      at = x0
      return
    end if
    ! the first of the largest within rounding (a symmetric motion's +peak and -peak tie: which
    ! one is larger in the last bits must not choose the sign printed)
    k = findloc(okv .and. w >= maxval(w, mask=okv)*(1.0_dp - tie_rel), .true., 1)
    call parabola(n, v, okv, per, k, h, x0, sign(1.0_dp, v(k)), val, at)
  end subroutine peak_at

  !> Minimum and maximum of v over the rows okv, parabola-refined.
  subroutine min_max(n, v, okv, per, lo, hi, h, x0)
    integer, intent(in) :: n
    real(dp), intent(in) :: v(n), h, x0
    logical, intent(in) :: okv(n), per
    real(dp), intent(out) :: lo, hi
    real(dp) :: at
    call extreme(n, v, okv, per, -1.0_dp, h, x0, lo, at)
    call extreme(n, v, okv, per, 1.0_dp, h, x0, hi, at)
  end subroutine min_max

  !> The maximum (sgn = 1) or minimum (sgn = -1) of v over okv, parabola-refined, and its input.
  subroutine extreme(n, v, okv, per, sgn, h, x0, val, at)
    integer, intent(in) :: n
    real(dp), intent(in) :: v(n), sgn, h, x0
    logical, intent(in) :: okv(n), per
    real(dp), intent(out) :: val, at
    real(dp) :: best
    integer :: k
    if (.not. any(okv)) then
      val = 0.0_dp
      at = x0
      return
    end if
    best = maxval(sgn*v, mask=okv)
    ! the first of the extremes within rounding of the best (ties in the last bits choose nothing)
    k = findloc(okv .and. sgn*v >= best - tie_rel*(maxval(abs(v), mask=okv)), .true., 1)
    call parabola(n, v, okv, per, k, h, x0, sgn, val, at)
  end subroutine extreme

  !> The vertex of the parabola through v(k-1), v(k), v(k+1) (neighbours wrapping round when
  !> per), kept when it lies within half a step of k and beyond v(k) in the direction sgn.
  subroutine parabola(n, v, okv, per, k, h, x0, sgn, val, at)
    integer, intent(in) :: n, k
    real(dp), intent(in) :: v(n), h, x0, sgn
    logical, intent(in) :: okv(n), per
    real(dp), intent(out) :: val, at
    integer :: km, kp
    real(dp) :: a, b, t
    val = v(k)
    at = x0 + h*real(k - 1, dp)
    km = k - 1
    kp = k + 1
    if (per) then
      if (km < 1) km = n
      if (kp > n) kp = 1
    end if
    if (km < 1 .or. kp > n) return
    if (.not. (okv(km) .and. okv(kp))) return
    a = 0.5_dp*(v(kp) + v(km)) - v(k)
    b = 0.5_dp*(v(kp) - v(km))
    if (sgn*a >= 0.0_dp) return
    t = -b/(2.0_dp*a)
    if (abs(t) > 0.5_dp) return
    if (sgn*(v(k) - b*b/(4.0_dp*a)) < sgn*v(k)) return
    val = v(k) - b*b/(4.0_dp*a)
    at = at + t*h
  end subroutine parabola

end module linkage
