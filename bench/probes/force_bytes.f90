!> Probe (bench/probe_force_bytes.py): what moving the four-bar force kernel's bytes costs on
!> this machine, with no arithmetic to speak of.  Not part of the tool.
!>
!> The force kernel (fortran/fourbar_forces.f90, joint_forces) reads per position a status
!> (int32) and 8 state columns (64 B) and writes 12 force columns (96 B), in blocks of 256
!> positions, every column a separate stream.  Three loops over n positions (Fortran-ordered
!> float64 arrays, plain stores as numpy's fill has them):
!>   fill   the 12 output columns filled one after another (the store floor of the bench row);
!>   move   per block of nb positions, the status and 8 columns read and the 12 written, one add,
!>          subtract or multiply each (the kernel's access pattern without its arithmetic);
!>   copy   8 input columns copied one after another into 8 output columns, the other 4 filled
!>          (numpy's copyto/fill reference of the bench row).
!> Each timed `repeat` times, interleaved; every repeat's times printed (the caller takes medians).
module force_bytes
  use kinds, only: dp
  use iso_fortran_env, only: int32
  implicit none
  private
  public :: fill, move, copy

contains

  subroutine fill(n, x, fout)
    integer, intent(in) :: n
    real(dp), intent(in) :: x
    real(dp), intent(inout) :: fout(n, 12)
    integer :: j, k
    do j = 1, 12
      do k = 1, n
        fout(k, j) = x
      end do
    end do
  end subroutine fill

  subroutine move(n, nb, st, states, fout)
    integer, intent(in) :: n, nb
    integer(int32), intent(in) :: st(n)
    real(dp), intent(in) :: states(n, 11)
    real(dp), intent(inout) :: fout(n, 12)
    integer :: k0, m
    do k0 = 1, n, nb
      m = min(nb, n - k0 + 1)
      call move_block(m, st(k0:k0 + m - 1), states(k0:k0 + m - 1, 4), states(k0:k0 + m - 1, 5), &
                      states(k0:k0 + m - 1, 6), states(k0:k0 + m - 1, 7), states(k0:k0 + m - 1, 8), &
                      states(k0:k0 + m - 1, 9), states(k0:k0 + m - 1, 10), states(k0:k0 + m - 1, 11), &
                      fout(k0:k0 + m - 1, 1), fout(k0:k0 + m - 1, 2), fout(k0:k0 + m - 1, 3), &
                      fout(k0:k0 + m - 1, 4), fout(k0:k0 + m - 1, 5), fout(k0:k0 + m - 1, 6), &
                      fout(k0:k0 + m - 1, 7), fout(k0:k0 + m - 1, 8), fout(k0:k0 + m - 1, 9), &
                      fout(k0:k0 + m - 1, 10), fout(k0:k0 + m - 1, 11), fout(k0:k0 + m - 1, 12))
    end do
  end subroutine move

  subroutine move_block(m, st, a, b, c, d, e, f, g, h, o1, o2, o3, o4, o5, o6, o7, o8, o9, o10, o11, o12)
    integer, intent(in) :: m
    integer(int32), intent(in) :: st(m)
    real(dp), intent(in) :: a(m), b(m), c(m), d(m), e(m), f(m), g(m), h(m)
    real(dp), intent(out) :: o1(m), o2(m), o3(m), o4(m), o5(m), o6(m), o7(m), o8(m), o9(m), o10(m), o11(m), o12(m)
    real(dp) :: ok
    integer :: k
    do k = 1, m
      ok = merge(1.0_dp, 0.0_dp, st(k) == 0)
      o1(k) = ok*(a(k) + b(k))
      o2(k) = c(k) + d(k)
      o3(k) = e(k) + f(k)
      o4(k) = g(k) + h(k)
      o5(k) = a(k) - b(k)
      o6(k) = c(k) - d(k)
      o7(k) = e(k) - f(k)
      o8(k) = g(k) - h(k)
      o9(k) = a(k)*b(k)
      o10(k) = c(k)*d(k)
      o11(k) = e(k)*f(k)
      o12(k) = g(k)*h(k)
    end do
  end subroutine move_block

  subroutine copy(n, x, states, fout)
    integer, intent(in) :: n
    real(dp), intent(in) :: x, states(n, 11)
    real(dp), intent(inout) :: fout(n, 12)
    integer :: j, k
    do j = 1, 8
      do k = 1, n
        fout(k, j) = states(k, j + 3)
      end do
    end do
    do j = 9, 12
      do k = 1, n
        fout(k, j) = x
      end do
    end do
  end subroutine copy
end module force_bytes

program probe_force_bytes
  use kinds, only: dp
  use iso_fortran_env, only: int32, int64
  use force_bytes, only: fill, move, copy
  implicit none
  integer :: n, repeat, r, i
  integer, parameter :: nb(2) = [256, 4096]
  real(dp), allocatable :: states(:, :), fout(:, :), t(:, :)
  integer(int32), allocatable :: st(:)
  integer(int64) :: t0, t1, rate
  character(len=32) :: arg
  n = 1000000
  repeat = 9
  if (command_argument_count() >= 1) then
    call get_command_argument(1, arg)
    read (arg, *) n
  end if
  if (command_argument_count() >= 2) then
    call get_command_argument(2, arg)
    read (arg, *) repeat
  end if
  allocate (states(n, 11), fout(n, 12), st(n), t(repeat, 4))
  call random_number(states)
  st = 0
  call fill(n, 0.0_dp, fout)
  call system_clock(count_rate=rate)
  do r = 1, repeat
    call system_clock(t0)
    call fill(n, real(r, dp), fout)
    call system_clock(t1)
    t(r, 1) = real(t1 - t0, dp)/rate
    do i = 1, 2
      call system_clock(t0)
      call move(n, nb(i), st, states, fout)
      call system_clock(t1)
      t(r, 1 + i) = real(t1 - t0, dp)/rate
    end do
    call system_clock(t0)
    call copy(n, real(r, dp), states, fout)
    call system_clock(t1)
    t(r, 4) = real(t1 - t0, dp)/rate
  end do
  ! every repeat's times [s] of fill, move256, move4096, copy, one line each (the caller takes
  ! medians), then a checksum that keeps the stores
  do r = 1, repeat
    print '(4(es12.5, 1x))', t(r, :)
  end do
  print '(es12.5)', sum(fout(1, :))
end program probe_force_bytes
