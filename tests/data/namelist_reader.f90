!> gfortran's own namelist reader, for tests/test_fortran_reader.py: the oracle the deck reader
!> (driver/_deck.py) is compared with.  Reads blocks from standard input -- a line with the
!> number of records n, then n records -- and reads each block as one namelist group &g from an
!> internal file (so one bad block cannot desynchronise the next).  Prints per block either
!>     ERR <gfortran's message>
!> or
!>     OK
!>     x <bits of x as 16 hex digits>
!>     a <bits of a(1) .. a(na)>
!>     l <T or F>
!>     s <len_trim(s)> <s>
!>     c <len_trim(c(i))> <c(i)>        (one line per element)
!> and then a line END.  Every variable starts at a sentinel, so what a block leaves unset shows.
!> After a failed read the runtime is settled (see settle) so that no block depends on the one
!> before it.
module namelist_reader_vars
  use kinds, only: dp
  implicit none
  private
  public :: dp, na, nc, reclen, x, a, l, s, c, reset
  integer, parameter :: na = 8, nc = 4, reclen = 400
  real(dp) :: x, a(na)
  logical :: l
  character(len=80) :: s, c(nc)
contains
  subroutine reset()
    x = -1.25e300_dp
    a = -1.25e300_dp
    l = .false.
    s = '~'
    c = '~'
  end subroutine reset
end module namelist_reader_vars

program namelist_reader
  use namelist_reader_vars
  implicit none
  namelist /g/ x, a, l, s, c
  character(len=reclen), allocatable :: buf(:)
  character(len=500) :: msg
  integer :: n, ios, i
  integer(selected_int_kind(18)) :: bits
  do
    read(*, *, iostat=ios) n
    if (ios /= 0) exit
    allocate(buf(n))
    do i = 1, n
      read(*, '(a)') buf(i)
    end do
    call reset()
    msg = ''
    read(buf, nml=g, iostat=ios, iomsg=msg)
    if (ios /= 0) then
      write(*, '(a)') 'ERR ' // trim(msg)
      call settle()
    else
      write(*, '(a)') 'OK'
      write(*, '(a,z16.16)') 'x ', transfer(x, bits)
      write(*, '(a)', advance='no') 'a'
      do i = 1, na
        write(*, '(1x,z16.16)', advance='no') transfer(a(i), bits)
      end do
      write(*, '(a)') ''
      write(*, '(a,l1)') 'l ', l
      write(*, '(a,i0,1x,a)') 's ', len_trim(s), trim(s)
      do i = 1, nc
        write(*, '(a,i0,1x,a)') 'c ', len_trim(c(i)), trim(c(i))
      end do
    end if
    write(*, '(a)') 'END'
    deallocate(buf)
  end do
contains
  !> After a failed read, gfortran's runtime may carry state (a pending repeat count) into the
  !> next read of an internal file: read a known group until it reads right, so that every block
  !> is read from a clean state.
  subroutine settle()
    character(len=40) :: canary(1)
    integer :: tries, ios2
    canary(1) = '&g x = 1.5, l = .true. /'
    do tries = 1, 5
      call reset()
      read(canary, nml=g, iostat=ios2)
      if (ios2 == 0 .and. x == 1.5_dp .and. l .and. all(a == -1.25e300_dp)) return
    end do
    error stop 'namelist_reader: the runtime does not settle after a failed read'
  end subroutine settle
end program namelist_reader
