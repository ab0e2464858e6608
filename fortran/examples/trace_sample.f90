!> Traces a problem in the exchange format with the fricont Fortran module and prints
!> its events, one a line:
!>
!>   start <alpha> <residual>
!>   event <index> <transition> <alpha> <node> <from> <to> <fold> <bifurcation>
!>   end <reason> <number of pieces>
!>
!> Usage: trace_sample CASE_DIR [affine | callback]
!>   affine    f(alpha) = f0 + alpha f1 given as two vectors (the default);
!>   callback  f(s) = f0 + sinh(s) f1 computed by a Fortran load function registered as
!>             a bind(C) callback; traced over s in [asinh(alpha_start), asinh(alpha_end)]
!>             and printed with alpha = sinh(s), so both modes print the same events.
module sample_load
    use, intrinsic :: iso_c_binding, only: c_double, c_int64_t, c_int32_t, c_ptr, &
        c_f_pointer
    use, intrinsic :: iso_fortran_env, only: real64
    implicit none
    private
    public :: load_data, sinh_load, sinh_dload

    !> What the callback needs, reached through user_data.
    type :: load_data
        real(real64), allocatable :: f0(:), f1(:)
        integer :: calls = 0
    end type load_data

contains

    !> f(s) = f0 + sinh(s) f1.
    function sinh_load(s, f, n, user_data) bind(C) result(code)
        real(c_double), value :: s
        integer(c_int64_t), value :: n
        real(c_double), intent(out) :: f(n)
        type(c_ptr), value :: user_data
        integer(c_int32_t) :: code
        type(load_data), pointer :: d
        call c_f_pointer(user_data, d)
        if (size(d%f0) /= n) then
            code = 1      ! never stop inside a callback: return a code
            return
        end if
        f = d%f0 + sinh(s)*d%f1
        d%calls = d%calls + 1
        code = 0
    end function sinh_load

    !> f'(s) = cosh(s) f1.
    function sinh_dload(s, f, n, user_data) bind(C) result(code)
        real(c_double), value :: s
        integer(c_int64_t), value :: n
        real(c_double), intent(out) :: f(n)
        type(c_ptr), value :: user_data
        integer(c_int32_t) :: code
        type(load_data), pointer :: d
        call c_f_pointer(user_data, d)
        f = cosh(s)*d%f1
        code = 0
    end function sinh_dload

end module sample_load

program trace_sample
    use, intrinsic :: iso_c_binding, only: c_loc
    use, intrinsic :: iso_fortran_env, only: real64, output_unit
    use fricont
    use case_reader, only: case_data, read_case
    use sample_load, only: load_data, sinh_load, sinh_dload
    implicit none
    character(len=4096) :: dir
    character(len=16) :: mode
    type(case_data) :: c

    if (command_argument_count() < 1) error stop 'usage: trace_sample CASE_DIR [affine|callback]'
    call get_command_argument(1, dir)
    mode = 'affine'
    if (command_argument_count() >= 2) call get_command_argument(2, mode)
    call read_case(trim(dir), c)
    call trace(c, trim(mode))

contains

    ! In a subroutine, so that the final procedures free the handles on return.
    subroutine trace(c, mode)
        type(case_data), intent(in) :: c
        character(len=*), intent(in) :: mode
        type(fricont_problem) :: prob
        type(fricont_path) :: path
        type(fricont_event), allocatable :: ev(:)
        type(fricont_state) :: start
        type(load_data), target :: ld
        integer :: k, reason, storage
        logical :: mapped

        ! A, N and T exactly as read: 1-based CSR with default-integer indices.
        storage = FRICONT_STORAGE_FULL
        if (c%a%symmetric) storage = FRICONT_STORAGE_LOWER
        call prob%create(c%a%row_ptr, c%a%col, c%a%val, c%n%row_ptr, c%n%col, c%n%val, &
                         c%t%row_ptr, c%t%col, c%t%val, storage=storage)
        call prob%set_friction(c%friction)
        call prob%set_gap(c%gap)

        mapped = mode == 'callback'
        if (mapped) then
            ld%f0 = c%f0
            ld%f1 = c%f1
            call path%create_general(prob, sinh_load, sinh_dload, user_data=c_loc(ld))
            call path%set_window(asinh(c%alpha_start), asinh(c%alpha_end))
            call path%start(asinh(c%alpha_start))
        else if (mode == 'affine') then
            call path%create_affine(prob, c%f0, c%f1)
            call path%set_window(c%alpha_start, c%alpha_end)
            call path%start(c%alpha_start)
        else
            error stop 'trace_sample: mode is affine or callback'
        end if
        call prob%free()          ! the path keeps what it needs
        call path%run(reason)

        call path%start_state(start)
        write (output_unit, '(a,1x,es24.17e2,1x,es10.3)') 'start', to_alpha(start%alpha, mapped), &
            start%residual
        ev = path%events()
        do k = 1, size(ev)
            write (output_unit, '(a,2(1x,i0),1x,es24.17e2,1x,i0,2(1x,a),2(1x,i0))') 'event', &
                ev(k)%index, ev(k)%transition, to_alpha(ev(k)%alpha, mapped), ev(k)%node, &
                fricont_class_name(ev(k)%from), fricont_class_name(ev(k)%to), &
                merge(1, 0, ev(k)%fold), merge(1, 0, ev(k)%bifurcation)
        end do
        write (output_unit, '(a,1x,a,1x,i0)') 'end', fricont_end_reason_name(reason), &
            path%piece_count()
        if (mapped .and. ld%calls == 0) error stop 'trace_sample: the load callback was not called'
    end subroutine trace

    ! The printed alpha: sinh(s) for the callback load, so that both modes agree.
    real(real64) function to_alpha(a, mapped)
        real(real64), intent(in) :: a
        logical, intent(in) :: mapped
        to_alpha = a
        if (mapped) to_alpha = sinh(a)
    end function to_alpha

end program trace_sample
