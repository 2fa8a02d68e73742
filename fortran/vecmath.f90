!> Whole-array sine/cosine and atan2 for the kernels' hot loops.
!>
!> Why this module exists: a loop vectorises only if its body holds no call the
!> compiler cannot inline.  An elemental helper called per element is inlined or
!> not at the whim of the inliner's size limits (the four-bar kernel lost its
!> vectorisation, 3.7x, when a third call site of its sincos helper appeared).
!> Here the loop lives inside the procedure and its body is straight-line
!> arithmetic (polynomials, merge, sqrt, min/max): it vectorises by construction,
!> whatever the caller looks like.  Callers pass whole blocks.
!>
!> Results are the same bits on every x86-64 build (no libmvec, no FMA contraction
!> with the project's -ffp-contract=off): the native and portable builds agree.
!>
!> sincos_array  fdlibm kernels: Cody-Waite reduction by pi/2 in three parts, then
!>               the degree-13/14 polynomials on |r| <= pi/4; within 1 ulp of the
!>               correctly rounded value for |x| <= 1e5 rad.  Larger (and non-finite)
!>               arguments are redone with the libm sin/cos in a second, rarely
!>               taken pass, so every argument gets a correct result.
!> atan2_array   Cephes atan rational on [0, 0.66] and (u-1)/(u+1) beyond, quadrant
!>               by merge; within 2 ulp for finite arguments.  atan2(+-0, x) = +-0
!>               for every x >= 0 or x = -0 (the signed zero of x is not looked at).
module vecmath
  use kinds, only: dp
  implicit none
  private
  public :: sincos_array, atan2_array

  !> largest |x| [rad] handled by the vector reduction (fdlibm's medium range is 2**19 pi/2)
  real(dp), parameter, public :: sincos_fast_limit = 1.0e5_dp

contains

  !> s(k) = sin(x(k)), c(k) = cos(x(k)), x in radians, k = 1..n.
  subroutine sincos_array(n, x, s, c)
    integer, intent(in) :: n
    real(dp), intent(in) :: x(n)
    real(dp), intent(out) :: s(n), c(n)
    real(dp), parameter :: twoopi = 6.36619772367581382433e-01_dp
    real(dp), parameter :: pio2_1 = 1.57079632673412561417e+00_dp, pio2_2 = 6.07710050630396597660e-11_dp, &
                           pio2_2t = 2.02226624879595063154e-21_dp
    real(dp), parameter :: magic = 6755399441055744.0_dp   ! 1.5 * 2**52: adding/subtracting rounds to nearest
    real(dp), parameter :: s1 = -1.66666666666666324348e-01_dp, s2 = 8.33333333332248946124e-03_dp, &
      s3 = -1.98412698298579493134e-04_dp, s4 = 2.75573137070700676789e-06_dp, &
      s5 = -2.50507602534068634195e-08_dp, s6 = 1.58969099521155010221e-10_dp
    real(dp), parameter :: c1 = 4.16666666666666019037e-02_dp, c2 = -1.38888888888741095749e-03_dp, &
      c3 = 2.48015872894767294178e-05_dp, c4 = -2.75573143513906633035e-07_dp, &
      c5 = 2.08757232129817482790e-09_dp, c6 = -1.13596475577881948265e-11_dp
    real(dp) :: kf, m, r, z, sr, cr, odd, xmax
    integer :: k
    xmax = 0.0_dp
    ! hot-loop: sincos_array
    do k = 1, n
      kf = (x(k)*twoopi + magic) - magic                  ! nearest integer to x / (pi/2)
      r = ((x(k) - kf*pio2_1) - kf*pio2_2) - kf*pio2_2t
      m = kf - 4.0_dp*(((kf*0.25_dp - 0.375_dp) + magic) - magic)   ! kf mod 4 in {0, 1, 2, 3}
      z = r*r
      sr = r + r*z*(s1 + z*(s2 + z*(s3 + z*(s4 + z*(s5 + z*s6)))))
      cr = 1.0_dp - 0.5_dp*z + z*z*(c1 + z*(c2 + z*(c3 + z*(c4 + z*(c5 + z*c6)))))
      odd = merge(1.0_dp, 0.0_dp, m == 1.0_dp .or. m == 3.0_dp)
      s(k) = merge(cr, sr, odd > 0.0_dp)*merge(-1.0_dp, 1.0_dp, m >= 2.0_dp)
      c(k) = merge(sr, cr, odd > 0.0_dp)*merge(-1.0_dp, 1.0_dp, m == 1.0_dp .or. m == 2.0_dp)
      xmax = max(xmax, abs(x(k)))
    end do
    ! NaN compares false: non-finite arguments also take the libm pass
    if (.not. (xmax <= sincos_fast_limit)) then
      do k = 1, n
        if (.not. (abs(x(k)) <= sincos_fast_limit)) then
          s(k) = sin(x(k))
          c(k) = cos(x(k))
        end if
      end do
    end if
  end subroutine sincos_array

  !> t(k) = atan2(y(k), x(k)) [rad] in [-pi, pi], k = 1..n.
  subroutine atan2_array(n, y, x, t)
    integer, intent(in) :: n
    real(dp), intent(in) :: y(n), x(n)
    real(dp), intent(out) :: t(n)
    real(dp), parameter :: pio2 = 1.57079632679489661923_dp, pio4 = 0.78539816339744830962_dp, &
                           pi = 3.14159265358979323846_dp, morebits = 6.123233995736765886130e-17_dp
    real(dp), parameter :: p0 = -8.750608600031904122785e-01_dp, p1 = -1.615753718733365076637e+01_dp, &
      p2 = -7.500855792314704667340e+01_dp, p3 = -1.228866684490136173410e+02_dp, &
      p4 = -6.485021904942025371773e+01_dp
    real(dp), parameter :: q0 = 2.485846490142306297962e+01_dp, q1 = 1.650270098316988542046e+02_dp, &
      q2 = 4.328810604912902668951e+02_dp, q3 = 4.853903996359136964868e+02_dp, &
      q4 = 1.945506571482613964425e+02_dp
    real(dp) :: ax, ay, mn, mx, u, v, z, a, big   ! big: 1 or 0 (a real keeps one vector width)
    integer :: k
    ! hot-loop: atan2_array
    do k = 1, n
      ax = abs(x(k))
      ay = abs(y(k))
      mx = max(ax, ay)
      mn = min(ax, ay)
      u = mn/max(mx, tiny(1.0_dp))                      ! in [0, 1]
      big = merge(1.0_dp, 0.0_dp, u > 0.66_dp)
      v = big*((u - 1.0_dp)/(u + 1.0_dp)) + (1.0_dp - big)*u
      z = v*v
      z = z*((((p0*z + p1)*z + p2)*z + p3)*z + p4)/(((((z + q0)*z + q1)*z + q2)*z + q3)*z + q4)
      a = big*pio4 + (v*z + v + big*(0.5_dp*morebits))
      a = merge(pio2 - a, a, ay > ax)
      a = merge(pi - a, a, x(k) < 0.0_dp)
      t(k) = sign(a, y(k))
    end do
  end subroutine atan2_array

end module vecmath
