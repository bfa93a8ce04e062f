! The same from Fortran through iso_c_binding: the interface below declares
! the three C functions of mpmvv_mms.h it calls.
program ring
  use iso_c_binding
  implicit none
  interface
    function mpmvv_mms_create(name, count, settings) bind(c, name="mpmvv_mms_create")
      import :: c_ptr, c_int, c_char
      character(kind=c_char), dimension(*), intent(in) :: name
      integer(c_int), value :: count
      type(c_ptr), dimension(*), intent(in) :: settings
      type(c_ptr) :: mpmvv_mms_create
    end function
    function mpmvv_mms_body_force(solution, t, n, x, b) bind(c, name="mpmvv_mms_body_force")
      import :: c_ptr, c_int, c_double, c_size_t
      type(c_ptr), value :: solution
      real(c_double), value :: t
      integer(c_size_t), value :: n
      real(c_double), dimension(*), intent(in) :: x
      real(c_double), dimension(*), intent(out) :: b
      integer(c_int) :: mpmvv_mms_body_force
    end function
    subroutine mpmvv_mms_destroy(solution) bind(c, name="mpmvv_mms_destroy")
      import :: c_ptr
      type(c_ptr), value :: solution
    end subroutine
  end interface
  character(kind=c_char, len=14), target :: setting = "amplitude=0.5" // c_null_char
  type(c_ptr) :: settings(1), solution
  real(c_double) :: x(6) = [1.0d0, 0.0d0, 0.8d0, 0.5d0, -0.3d0, -0.9d0], b(6)
  integer :: p
  settings(1) = c_loc(setting)
  solution = mpmvv_mms_create("ring" // c_null_char, 1_c_int, settings)
  if (.not. c_associated(solution)) stop 1
  if (mpmvv_mms_body_force(solution, 0.25d0, 3_c_size_t, x, b) /= 0) stop 1
  do p = 0, 2
    write (*, '(a, 4es25.17)') 'b ', x(2 * p + 1), x(2 * p + 2), b(2 * p + 1), b(2 * p + 2)
  end do
  call mpmvv_mms_destroy(solution)
end program
