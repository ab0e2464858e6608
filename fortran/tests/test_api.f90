!> Tests of the fricont Fortran module beyond the traced events (which run.sh compares
!> with the C interface): the err argument, 0- and 1-based CSR with 32- and 64-bit
!> indices, a failing Fortran callback, the basis load, solutions_at checked against the
!> equations evaluated here, the monitor (stop and resume, against the unmonitored run)
!> and the largest alpha step (a narrow bump found at its analytic alpha), bifurcations
!> (branches followed to the end, their states checked against the equations here) and
!> the extended-precision setting (W's condition estimate against a hand value).
!> Prints "ok NAME" / "FAIL NAME: why"; exits 1 on a failure.
module api_callbacks
    use, intrinsic :: iso_c_binding, only: c_double, c_int64_t, c_int32_t, c_ptr, &
        c_f_pointer
    use, intrinsic :: iso_fortran_env, only: real64, int64
    use fricont, only: fricont_path, fricont_event
    implicit none
    type :: stop_load
        real(real64), allocatable :: f0(:), f1(:)
        real(real64) :: stop_at = 0
    end type stop_load
    !> What the monitor saw: calls, wrong arguments or reads, the last event number.
    type :: monitor_log
        type(fricont_path), pointer :: path => null()
        integer(int64) :: stop_at = 3
        integer :: calls = 0, bad = 0
        integer(int64) :: last_transitions = 0, last_event = 0
    end type monitor_log
contains
    !> Checks its arguments against the path read from inside the call (the events
    !> first_event..last_event are new, at alpha, of transition point `transitions`) and
    !> stops at transition point stop_at.
    function logging_monitor(alpha, transitions, first_event, last_event, user_data) &
        result(stop_path)
        real(real64), intent(in) :: alpha
        integer(int64), intent(in) :: transitions, first_event, last_event
        type(c_ptr), intent(in) :: user_data
        logical :: stop_path
        type(monitor_log), pointer :: log
        type(fricont_event) :: e
        integer(int64) :: k
        call c_f_pointer(user_data, log)
        log%calls = log%calls + 1
        if (transitions /= log%last_transitions + 1 .or. first_event /= log%last_event + 1 &
            .or. last_event < first_event) log%bad = log%bad + 1
        if (log%path%event_count() /= last_event) log%bad = log%bad + 1
        do k = first_event, last_event
            e = log%path%event(int(k))
            if (e%alpha /= alpha .or. e%transition /= transitions .or. e%index /= k) &
                log%bad = log%bad + 1
        end do
        log%last_transitions = transitions
        log%last_event = last_event
        stop_path = transitions == log%stop_at
    end function logging_monitor

    !> A narrow bump of the normal load: (0.5 - 0.6 exp(-((alpha - 21.5/64)/2e-3)^2), 0).
    function bump_load(alpha, f, n, user_data) bind(C) result(code)
        real(c_double), value :: alpha
        integer(c_int64_t), value :: n
        real(c_double), intent(out) :: f(n)
        type(c_ptr), value :: user_data
        integer(c_int32_t) :: code
        f = 0
        f(1) = 0.5_c_double - 0.6_c_double*exp(-((alpha - 21.5_c_double/64)/2e-3_c_double)**2)
        code = 0
    end function bump_load

    !> f0 + alpha f1, but refuses (code 7) past stop_at.
    function refusing_load(alpha, f, n, user_data) bind(C) result(code)
        real(c_double), value :: alpha
        integer(c_int64_t), value :: n
        real(c_double), intent(out) :: f(n)
        type(c_ptr), value :: user_data
        integer(c_int32_t) :: code
        type(stop_load), pointer :: d
        call c_f_pointer(user_data, d)
        f = d%f0 + alpha*d%f1
        code = 0
        if (alpha > d%stop_at) code = 7
    end function refusing_load

    !> phi = (1, sinh(s)), phi' = (0, cosh(s)).
    function sinh_weights(s, phi, dphi, k, user_data) bind(C) result(code)
        real(c_double), value :: s
        integer(c_int64_t), value :: k
        real(c_double), intent(out) :: phi(k), dphi(k)
        type(c_ptr), value :: user_data
        integer(c_int32_t) :: code
        phi = [1.0_real64, sinh(s)]
        dphi = [0.0_real64, cosh(s)]
        code = 0
        if (k /= 2) code = 1
    end function sinh_weights

    !> The host's solve for A = diag(2, 1): x := diag(1/2, 1) x.
    function diag_solve(user_data, n, ncols, x, ldx) bind(C) result(code)
        use, intrinsic :: iso_c_binding, only: c_int
        type(c_ptr), value :: user_data
        integer(c_int64_t), value :: n, ncols, ldx
        real(c_double), intent(inout) :: x(ldx, ncols)
        integer(c_int) :: code
        x(1, :) = 0.5_c_double*x(1, :)
        code = 0
        if (n /= 2) code = -1
    end function diag_solve
end module api_callbacks

program test_api
    use, intrinsic :: iso_c_binding, only: c_loc
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf
    use, intrinsic :: iso_fortran_env, only: real64, int64
    use fricont
    use case_reader, only: case_data, csr_matrix, read_case
    use api_callbacks
    implicit none
    character(len=4096) :: dir
    type(case_data) :: c
    integer :: failures = 0

    call get_command_argument(1, dir)
    call read_case(trim(dir), c)
    call run_all(c)
    call host_input()
    ! (the cases beside the sample: DIR/../bifurcation-stop, DIR/../vertex-start)
    call bifurcations(dir(1:index(trim(dir), '/', back=.true.)))
    write (*, '(a,i0,a)') 'fortran test_api: ', failures, ' failed check(s)'
    if (failures > 0) error stop 1

contains

    subroutine check(name, cond, why)
        character(len=*), intent(in) :: name
        logical, intent(in) :: cond
        character(len=*), intent(in), optional :: why
        if (cond) then
            write (*, '(2a)') 'ok ', name
        else
            failures = failures + 1
            if (present(why)) then
                write (*, '(4a)') 'FAIL ', name, ': ', why
            else
                write (*, '(2a)') 'FAIL ', name
            end if
        end if
    end subroutine check

    function matvec(m, x) result(y)
        type(csr_matrix), intent(in) :: m
        real(real64), intent(in) :: x(:)
        real(real64), allocatable :: y(:)
        integer :: i, k
        allocate (y(m%nrows), source=0.0_real64)
        do i = 1, m%nrows
            do k = m%row_ptr(i), m%row_ptr(i + 1) - 1
                y(i) = y(i) + m%val(k)*x(m%col(k))
            end do
        end do
    end function matvec

    function matvec_t(m, x) result(y)
        type(csr_matrix), intent(in) :: m
        real(real64), intent(in) :: x(:)
        real(real64), allocatable :: y(:)
        integer :: i, k
        allocate (y(m%ncols), source=0.0_real64)
        do i = 1, m%nrows
            do k = m%row_ptr(i), m%row_ptr(i + 1) - 1
                y(m%col(k)) = y(m%col(k)) + m%val(k)*x(i)
            end do
        end do
    end function matvec_t

    subroutine make_problem(c, prob)
        type(case_data), intent(in) :: c
        type(fricont_problem), intent(inout) :: prob
        call prob%create(c%a%row_ptr, c%a%col, c%a%val, c%n%row_ptr, c%n%col, c%n%val, &
                         c%t%row_ptr, c%t%col, c%t%val)
        call prob%set_friction(c%friction)
        call prob%set_gap(c%gap)
    end subroutine make_problem

    subroutine run_all(c)
        type(case_data), intent(in) :: c
        type(fricont_problem) :: prob, prob0, bad
        type(fricont_path) :: path, refusing, basis
        type(fricont_error) :: err
        type(fricont_event), allocatable :: ev(:), evb(:)
        type(fricont_state) :: s
        type(fricont_piece) :: pc1, pc2
        integer(int64) :: n, p
        character(len=:), allocatable :: version
        type(stop_load), target :: sl
        integer :: count, piece, reason, k, i
        logical :: continuum, same
        real(real64) :: alpha, scale, tol
        real(real64), allocatable :: f(:), r(:), dn(:), dt(:)
        character(len=32) :: buf

        version = fricont_version()
        call check('version has three numbers', len(version) >= 5 .and. &
                   verify(version, '0123456789.') == 0, version)

        ! Bad CSR: a column index past n, reported through err, not a stop.
        block
            integer :: ptr(3), col(2)
            real(real64) :: val(2)
            ptr = [1, 2, 3]
            col = [1, 9]
            val = [1.0_real64, 1.0_real64]
            call bad%create(ptr, col, val, ptr, col, val, ptr, col, val, err=err)
            call check('bad CSR: status FRICONT_ERR_CSR', err%status == FRICONT_ERR_CSR, &
                       err%message)
            call check('bad CSR: message names the column', index(err%message, '9') > 0, &
                       err%message)
            call check('bad CSR: no handle', .not. bad%is_created())
        end block

        ! The sample through 1-based default-integer CSR (as read).
        call make_problem(c, prob)
        n = prob%n()
        p = prob%p()
        call check('dims', n == c%a%nrows .and. p == c%n%nrows)
        call check('r > 0', prob%r() > 0)

        ! The same data 0-based with int64 indices gives the same path.
        call prob0%create(int(c%a%row_ptr - 1, int64), int(c%a%col - 1, int64), c%a%val, &
                          int(c%n%row_ptr - 1, int64), int(c%n%col - 1, int64), c%n%val, &
                          int(c%t%row_ptr - 1, int64), int(c%t%col - 1, int64), c%t%val, &
                          index_base=0, err=err)
        call check('0-based int64 CSR accepted', err%ok(), err%message)
        call prob0%set_friction(c%friction)
        call prob0%set_gap(c%gap)

        call path%create_affine(prob, c%f0, c%f1)
        call path%set_window(c%alpha_start, c%alpha_end)
        call path%start(c%alpha_start)
        call path%run(reason)
        ev = path%events()
        call check('affine: ends at the window', reason == FRICONT_END_WINDOW)
        call check('affine: events found', size(ev) >= 2)
        call check('affine: the fixed-alpha solver found the start', &
                   path%start_route() == FRICONT_START_SOLVED, &
                   fricont_start_route_name(path%start_route()))
        block
            character(len=:), allocatable :: route_name, end_name, bad_name
            route_name = fricont_start_route_name(path%start_route())
            end_name = fricont_end_reason_name(reason)
            bad_name = fricont_end_reason_name(99)
            call check('affine: the names of the route and the end', &
                       route_name == 'solved' .and. end_name == 'window' .and. &
                       bad_name == 'unknown', route_name // ' ' // end_name // ' ' // bad_name)
        end block

        block
            type(fricont_path) :: p0
            type(fricont_event), allocatable :: e0(:)
            call p0%create_affine(prob0, c%f0, c%f1)
            call p0%set_window(c%alpha_start, c%alpha_end)
            call p0%start(c%alpha_start)
            call p0%run()
            e0 = p0%events()
            same = size(e0) == size(ev)
            if (same) same = all(e0%alpha == ev%alpha) .and. all(e0%node == ev%node)
            call check('0-based int64 CSR: same events', same)
        end block

        ! Pieces: one more than the events, contiguous in alpha.
        call check('pieces = events + 1', path%piece_count() == size(ev) + 1)
        same = .true.
        do k = 1, size(ev)
            pc1 = path%piece(k)
            pc2 = path%piece(k + 1)
            same = same .and. pc1%alpha_to == ev(k)%alpha .and. pc2%alpha_from == ev(k)%alpha
        end do
        call check('pieces meet at the events', same)

        ! solutions_at between events 1 and 2: checked against the equations here.
        if (size(ev) >= 2) then
            alpha = 0.5_real64*(ev(1)%alpha + ev(2)%alpha)
            call path%solutions_at(alpha, count)
            call check('solutions_at: one solution', count == 1)
            call path%solution(1, s, piece, continuum)
            call check('solutions_at: on piece 2, not a continuum', piece == 2 .and. &
                       .not. continuum)
            f = c%f0 + alpha*c%f1
            r = matvec(c%a, s%u) - f - matvec_t(c%n, s%lambda_n) - matvec_t(c%t, s%lambda_t)
            scale = maxval(abs(f))
            write (buf, '(es10.3)') maxval(abs(r))/scale
            call check('solutions_at: equilibrium A u = f + N''ln + T''lt', &
                       maxval(abs(r)) <= 1e-9_real64*scale, buf)
            dn = matvec(c%n, s%u) - c%gap
            dt = matvec(c%t, s%u)
            tol = 1e-9_real64*maxval(abs(s%u))
            same = .true.
            do i = 1, size(dn)
                select case (s%classes(i))
                case (FRICONT_STICK)
                    same = same .and. abs(dn(i)) <= tol .and. abs(dt(i)) <= tol
                case (FRICONT_OPEN)
                    same = same .and. dn(i) <= tol .and. s%lambda_n(i) == 0
                case (FRICONT_SLIP_PLUS, FRICONT_SLIP_MINUS)
                    same = same .and. abs(dn(i)) <= tol
                end select
            end do
            call check('solutions_at: contact conditions of each class', same)
        end if

        ! A Fortran callback that refuses past a point: err, code, end reason.
        if (size(ev) >= 3) then
            sl%f0 = c%f0
            sl%f1 = c%f1
            sl%stop_at = 0.5_real64*(ev(2)%alpha + ev(3)%alpha)
            call refusing%create_general(prob, refusing_load, user_data=c_loc(sl))
            call refusing%set_window(c%alpha_start, c%alpha_end)
            call refusing%start(c%alpha_start)
            call refusing%run(reason, err=err)
            call check('callback code 7: FRICONT_ERR_CALLBACK', &
                       err%status == FRICONT_ERR_CALLBACK, err%message)
            call check('callback code 7: kept by the path', refusing%callback_code() == 7)
            call check('callback code 7: path failed', reason == FRICONT_END_FAILED)
            call check('callback code 7: stepping again ends', &
                       refusing%end_reason() == FRICONT_END_FAILED)
        end if

        ! The basis load f = f0 + sinh(s) f1 with weights from a Fortran callback.
        call basis%create_basis(prob, reshape([c%f0, c%f1], [size(c%f0), 2]), sinh_weights)
        call basis%set_window(asinh(c%alpha_start), asinh(c%alpha_end))
        call basis%start(asinh(c%alpha_start))
        call basis%run(reason)
        evb = basis%events()
        same = size(evb) == size(ev)
        if (same) same = all(evb%node == ev%node) .and. &
                         all(abs(sinh(evb%alpha) - ev%alpha) <= &
                             1e-9_real64*max(1.0_real64, abs(ev%alpha)))
        call check('basis load: events at asinh of the affine ones', same)

        ! The monitor: stopping after the third transition point keeps the unmonitored
        ! run's first events; running again ends at the window with all of its events.
        block
            type(fricont_path), target :: mp
            type(monitor_log), target :: log
            type(fricont_event), allocatable :: em(:)
            character(len=:), allocatable :: rname
            call mp%create_affine(prob, c%f0, c%f1)
            call mp%set_window(c%alpha_start, c%alpha_end)
            log%path => mp
            call mp%set_monitor(logging_monitor, c_loc(log))
            call mp%start(c%alpha_start)
            call mp%run(reason)
            em = mp%events()
            k = mp%end_reason()
            rname = fricont_end_reason_name(reason)
            call check('monitor: stops after 3 transition points (FRICONT_END_STOPPED)', &
                       reason == FRICONT_END_STOPPED .and. k == FRICONT_END_STOPPED .and. &
                       log%calls == 3 .and. rname == 'stopped', rname)
            same = size(em) == log%last_event .and. size(em) < size(ev)
            if (same) same = all(em%alpha == ev(1:size(em))%alpha) .and. &
                             all(em%node == ev(1:size(em))%node) .and. &
                             em(size(em))%transition == 3 .and. ev(size(em) + 1)%transition == 4
            call check('monitor: the events at the stop are the unmonitored run''s first ones', same)
            call mp%run(reason)
            em = mp%events()
            same = size(em) == size(ev)
            if (same) same = all(em%alpha == ev%alpha) .and. all(em%node == ev%node) .and. &
                             all(em%to == ev%to)
            call check('monitor: running again ends at the window with the same events', &
                       same .and. reason == FRICONT_END_WINDOW .and. &
                       log%calls == ev(size(ev))%transition)
            call check('monitor: arguments and reads of the path inside the call', log%bad == 0)
            call mp%set_monitor()
        end block

        ! The largest alpha step: range errors, and a narrow bump of a general load on one
        ! node (A = I, N = [1 0], T = [0 1]; tests/core_oscillating.rs) that opens the node
        ! between 21.5/64 -+ 2e-3 sqrt(ln 1.2): steps of at most 1e-3 find both transitions.
        block
            type(fricont_problem) :: one
            type(fricont_path) :: bump
            type(fricont_event), allocatable :: eb(:)
            real(real64) :: ab, half
            call bump%create_affine(prob, c%f0, c%f1)
            call bump%set_max_alpha_step(0.0_real64, err=err)
            same = err%status == FRICONT_ERR_RANGE
            call bump%set_max_alpha_step(-1.0_real64, err=err)
            same = same .and. err%status == FRICONT_ERR_RANGE
            call bump%set_max_alpha_step(ieee_value(1.0_real64, ieee_quiet_nan), err=err)
            same = same .and. err%status == FRICONT_ERR_RANGE
            call bump%set_max_alpha_step(ieee_value(1.0_real64, ieee_positive_inf), err=err)
            call check('max_alpha_step 0, -1, NaN, inf: FRICONT_ERR_RANGE', &
                       same .and. err%status == FRICONT_ERR_RANGE, err%message)
            call one%create([1, 2, 3], [1, 2], [1.0_real64, 1.0_real64], [1, 2], [1], &
                            [1.0_real64], [1, 2], [2], [1.0_real64])
            call one%set_friction(0.3_real64)
            call bump%create_general(one, bump_load)
            call bump%set_window(-1.0_real64, 1.0_real64)
            call bump%set_max_alpha_step(1e-3_real64)
            call bump%start(-1.0_real64)
            call bump%set_max_alpha_step(1e-3_real64, err=err)
            call check('max_alpha_step after the start: FRICONT_ERR_ORDER', &
                       err%status == FRICONT_ERR_ORDER, err%message)
            call bump%run(reason)
            eb = bump%events()
            ab = 21.5_real64/64
            half = 2e-3_real64*sqrt(log(1.2_real64))
            same = size(eb) == 2 .and. reason == FRICONT_END_WINDOW
            if (same) same = abs(eb(1)%alpha - (ab - half)) <= 1e-10_real64 .and. &
                             abs(eb(2)%alpha - (ab + half)) <= 1e-10_real64 .and. &
                             eb(1)%from == FRICONT_STICK .and. eb(1)%to == FRICONT_OPEN .and. &
                             eb(2)%from == FRICONT_OPEN .and. eb(2)%to == FRICONT_STICK
            write (buf, '(i0,a)') size(eb), ' events'
            call check('max_alpha_step 1e-3: both transitions of a narrow bump at the analytic alpha', &
                       same, buf)
        end block

        ! Misuse through err: starting outside the window, a wrong guess length.
        call path%start(c%alpha_end + 10, err=err)
        call check('start outside the window: FRICONT_ERR_RANGE', err%status == FRICONT_ERR_RANGE, &
                   err%message)
        call path%start(c%alpha_start, guess=[1.0_real64, 2.0_real64], err=err)
        call check('guess of the wrong length: FRICONT_ERR_LENGTH', &
                   err%status == FRICONT_ERR_LENGTH, err%message)
        call prob%set_friction(-1.0_real64, err=err)
        call check('negative friction: FRICONT_ERR_RANGE', err%status == FRICONT_ERR_RANGE)
        call prob%set_threads(0, err=err)
        call check('0 threads: FRICONT_ERR_RANGE', err%status == FRICONT_ERR_RANGE, err%message)
        call prob%set_threads(2, err=err)
        call check('2 threads accepted', err%status == FRICONT_OK, err%message)
        call check('status name', &
                   index(fricont_status_name(FRICONT_ERR_CSR), 'FRICONT_ERR_CSR') == 1)
    end subroutine run_all

    !> The hosts' constructors on the block solved by hand (c-tests/status.c): A = diag(2, 1),
    !> N = [1 0], T = [0 1], F = 1/2, f = (1, alpha): stick with lambda = (-1, -alpha) up to
    !> alpha = 1/2, then slip+ with u_2 = alpha - 1/2. Condensed: W = diag(1/2, 1),
    !> q = (1/2, alpha).
    subroutine host_input()
        use, intrinsic :: iso_c_binding, only: c_null_ptr
        type(fricont_problem) :: cp, hp
        type(fricont_path) :: path
        type(fricont_event), allocatable :: ev(:)
        type(fricont_state) :: s
        type(fricont_error) :: err
        integer :: reason
        integer(int64) :: nd, pd
        real(real64) :: w(2, 2)
        w = reshape([0.5_real64, 0.0_real64, 0.0_real64, 1.0_real64], [2, 2])
        call cp%create_condensed(w)
        call cp%set_friction(0.5_real64)
        nd = cp%n()
        pd = cp%p()
        call check('condensed: n = 0, p = 1', nd == 0 .and. pd == 1)
        call path%create_affine(cp, [0.5_real64, 0.0_real64], [0.0_real64, 1.0_real64])
        call path%set_window(0.0_real64, 1.0_real64)
        call path%start(0.0_real64)
        call path%run(reason)
        ev = path%events()
        call check('condensed: one event at alpha = 1/2', size(ev) == 1 .and. &
                   abs(ev(1)%alpha - 0.5_real64) <= 1e-15_real64)
        call path%event_state(1, s, err)
        call check('condensed: event state without u', err%ok() .and. .not. allocated(s%u) .and. &
                   abs(s%lambda_n(1) + 1) <= 1e-15_real64 .and. &
                   abs(s%lambda_t(1) + 0.5_real64) <= 1e-15_real64, err%message)
        w(1, 2) = 0.1_real64
        call cp%create_condensed(w)
        call cp%build(err)
        call check('condensed: non-symmetric W gives FRICONT_ERR_NOT_SYMMETRIC', &
                   err%status == FRICONT_ERR_NOT_SYMMETRIC, err%message)
        call hp%create_solve(2_int64, diag_solve, c_null_ptr, [1_int64, 2_int64], [1_int64], &
                             [1.0_real64], [1_int64, 2_int64], [2_int64], [1.0_real64], max_block=1)
        call hp%set_friction(0.5_real64)
        call path%create_affine(hp, [1.0_real64, 0.0_real64], [0.0_real64, 1.0_real64])
        call path%set_window(0.0_real64, 1.0_real64)
        call path%start(0.0_real64)
        call path%run(reason)
        ev = path%events()
        call check('host solve: one event at alpha = 1/2', size(ev) == 1 .and. &
                   abs(ev(1)%alpha - 0.5_real64) <= 1e-15_real64)
        call path%current(s)
        call check('host solve: u at alpha = 1 is (0, 1/2)', allocated(s%u) .and. &
                   abs(s%u(1)) <= 1e-15_real64 .and. abs(s%u(2) - 0.5_real64) <= 1e-15_real64)
        ! Extended precision of the condensed W = diag(1/2, 1): condition 2, not
        ! ill-conditioned, so auto traces in double and on in double-double.
        block
            real(real64) :: kappa
            logical :: ext
            w(1, 2) = 0
            call cp%create_condensed(w)
            call cp%set_friction(0.5_real64)
            ext = cp%extended_precision(kappa)
            call check('W = diag(1/2, 1): condition estimate 2, auto traces in double', &
                       .not. ext .and. abs(kappa - 2) <= 1e-9_real64)
            call cp%set_extended_precision(FRICONT_EXTENDED_ON)
            ext = cp%extended_precision(kappa)
            call check('extended precision on: in double-double', ext)
            call cp%set_extended_precision(3, err)
            call check('extended precision mode 3: FRICONT_ERR_RANGE', &
                       err%status == FRICONT_ERR_RANGE, err%message)
        end block
    end subroutine host_input

    !> True when `s` (at its alpha) satisfies A u = f + N' lambda_n + T' lambda_t and the
    !> conditions of each node's class, to 1e-9 relative (evaluated here, from the case).
    logical function state_holds(c, s) result(ok)
        type(case_data), intent(in) :: c
        type(fricont_state), intent(in) :: s
        real(real64), allocatable :: f(:), r(:), dn(:), dt(:)
        real(real64) :: tu, tf, fi, ln, lt
        integer :: i
        f = c%f0 + s%alpha*c%f1
        r = matvec(c%a, s%u) - f - matvec_t(c%n, s%lambda_n) - matvec_t(c%t, s%lambda_t)
        ok = maxval(abs(r)) <= 1e-9_real64*maxval(abs(f))
        dn = matvec(c%n, s%u) - c%gap
        dt = matvec(c%t, s%u)
        tu = 1e-9_real64*maxval(abs(s%u))
        tf = 1e-9_real64*max(maxval(abs(s%lambda_n)), maxval(abs(s%lambda_t)))
        do i = 1, size(dn)
            fi = c%friction(min(i, size(c%friction)))
            ln = s%lambda_n(i)
            lt = s%lambda_t(i)
            ok = ok .and. ln <= tf .and. dn(i) <= tu .and. abs(lt) <= -fi*ln + tf
            select case (s%classes(i))
            case (FRICONT_OPEN)
                ok = ok .and. abs(ln) <= tf .and. abs(lt) <= tf
            case (FRICONT_STICK)
                ok = ok .and. abs(dn(i)) <= tu .and. abs(dt(i)) <= tu
            case (FRICONT_SLIP_PLUS)
                ok = ok .and. abs(dn(i)) <= tu .and. abs(lt - fi*ln) <= tf .and. dt(i) >= -tu
            case (FRICONT_SLIP_MINUS)
                ok = ok .and. abs(dn(i)) <= tu .and. abs(lt + fi*ln) <= tf .and. dt(i) <= tu
            end select
        end do
    end function state_holds

    !> tests/data/bifurcation-stop, a mirror-symmetric pair, stops at a bifurcation with
    !> three candidates (python/tests checks them against a brute-force enumeration):
    !> choose_branch(k) follows each to the window's end, the events before it kept, the
    !> states after it satisfying the equations. tests/data/vertex-start: three pieces
    !> leave the start point, the curves the brute force of tests/common finds, (open,
    !> slip+), (slip-, slip+), (stick, slip-); choose_branch(k) directly after the start
    !> starts on the k-th.
    subroutine bifurcations(data)
        character(len=*), intent(in) :: data
        type(case_data) :: b, v
        type(fricont_problem) :: prob
        type(fricont_path) :: path
        type(fricont_branch) :: cand(3), extra
        type(fricont_piece) :: pc
        type(fricont_state) :: s
        type(fricont_error) :: err
        type(fricont_event), allocatable :: ev0(:), ev(:)
        integer :: reason, k, j, np
        integer(int64) :: nb
        logical :: ok, found(3)
        character(len=64) :: why

        call read_case(data//'bifurcation-stop', b)
        call make_problem(b, prob)
        call path%create_affine(prob, b%f0, b%f1)
        call path%set_window(b%alpha_start, b%alpha_end)
        call path%start(b%alpha_start)
        call path%run(reason)
        nb = path%branch_count()
        call check('bifurcation: the path stops with three candidates', &
                   reason == FRICONT_END_BIFURCATION .and. nb == 3)
        if (nb /= 3) return
        ev0 = path%events()
        np = int(path%piece_count())
        do k = 1, 3
            cand(k) = path%branch(k)
        end do
        extra = path%branch(4, err)
        call check('branch 4 of 3: FRICONT_ERR_RANGE', err%status == FRICONT_ERR_RANGE, err%message)
        ok = .true.
        why = ''
        do k = 1, 3
            call path%start(b%alpha_start)
            call path%run(reason)
            call path%choose_branch(k)
            call path%run(reason)
            ev = path%events()
            pc = path%piece(np + 1)
            if (reason /= FRICONT_END_WINDOW .or. size(ev) <= size(ev0) .or. &
                any(pc%classes /= cand(k)%classes) .or. pc%direction /= cand(k)%direction) then
                ok = .false.
                write (why, '(a,i0)') 'branch ', k
                cycle
            end if
            ok = ok .and. all(ev(1:size(ev0))%alpha == ev0%alpha) .and. &
                 all(ev(1:size(ev0))%node == ev0%node) .and. ev(size(ev0) + 1)%bifurcation
            do j = size(ev0) + 1, size(ev)
                call path%event_state(j, s)
                if (.not. state_holds(b, s)) then
                    ok = .false.
                    write (why, '(a,i0,a,i0)') 'branch ', k, ' event ', j
                end if
            end do
        end do
        call check('choose_branch follows each candidate to the window''s end', ok, trim(why))
        call path%choose_branch(1, err)
        call check('choose_branch after the path moved on: FRICONT_ERR_ORDER', &
                   err%status == FRICONT_ERR_ORDER, err%message)

        call read_case(data//'vertex-start', v)
        call make_problem(v, prob)
        call path%create_affine(prob, v%f0, v%f1)
        call path%set_window(v%alpha_start, v%alpha_end)
        call path%start(v%alpha_start)
        nb = path%branch_count()
        call check('vertex start: three pieces leave it', nb == 3)
        if (nb /= 3) return
        found = .false.
        ok = .true.
        do k = 1, 3
            cand(k) = path%branch(k)
            ! (FRICONT codes: open 0, stick 1, slip+ 2, slip- 3)
            found(1) = found(1) .or. all(cand(k)%classes == [FRICONT_OPEN, FRICONT_SLIP_PLUS])
            found(2) = found(2) .or. all(cand(k)%classes == [FRICONT_SLIP_MINUS, FRICONT_SLIP_PLUS])
            found(3) = found(3) .or. all(cand(k)%classes == [FRICONT_STICK, FRICONT_SLIP_MINUS])
        end do
        call check('vertex start: the three curves of the brute force', all(found))
        do k = 1, 3
            call path%start(v%alpha_start)
            call path%choose_branch(k)
            call path%run(reason)
            pc = path%piece(1)
            ok = ok .and. reason == FRICONT_END_WINDOW .and. all(pc%classes == cand(k)%classes)
        end do
        call check('vertex start: choose_branch(k) starts on the k-th piece', ok)
    end subroutine bifurcations

end program test_api
