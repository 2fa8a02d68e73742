!> Real kinds used by every kernel.  sp exists only for the faithful
!> reproduction of single-precision heritage programs (four-bar listing).
module kinds
  implicit none
  private
  public :: dp, sp
  integer, parameter :: dp = selected_real_kind(15, 307)
  integer, parameter :: sp = selected_real_kind(6, 37)
end module kinds
