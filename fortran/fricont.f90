!> fricont: exact path-following of discrete 2D contact problems with Coulomb friction.
!>
!> The Fortran 2008 interface over the C ABI (include/fricont.h). Compile this file with
!> your program and link with -lfricont (`pkg-config --cflags --libs fricont`).
!>
!> * `type(fricont_problem)`: A (symmetric positive definite, n x n), N and T (p x n) in
!>   CSR with 1-based indices as Fortran codes store them (default `index_base = 1`;
!>   default-integer or int64 index arrays). Friction, gap, r are set by type-bound
!>   procedures. The arrays are only read during the call (the library copies them).
!> * `type(fricont_path)`: a load on a problem, traced by `start`, `step`, `run`;
!>   `event`, `event_state`, `piece`, `solutions_at` read what it found.
!> * Numbering: everything this module returns counts from 1 (events, transitions,
!>   contact nodes, pieces, solutions); every argument `k` counts from 1 as well.
!> * Errors: every procedure has an optional `type(fricont_error), intent(out) :: err`
!>   (the fortran-lang/stdlib convention): when present it receives the status and the
!>   library's message; when absent, a failing call stops the program with the message
!>   (written to stderr, then `error stop 1`). Step outcomes (`FRICONT_TRANSITION`, ...,
!>   `FRICONT_END`) are not errors.
!> * Handles are freed by `free` or by the final procedure when the variable goes out of
!>   scope (not at the end of a main program: call `free` there). Do not copy a problem
!>   or path variable with `=`: intrinsic assignment would share the handle (the defined
!>   assignment of this module stops with a message instead).
!> * Load callbacks are Fortran functions with the `bind(C)` interfaces
!>   `fricont_load_fn` / `fricont_weights_fn`; they must return a nonzero code instead
!>   of stopping the program. `user_data` (from `c_loc` of a `target` variable) reaches
!>   them unchanged.
!> * A progress monitor (`path%set_monitor`) is a Fortran function of the interface
!>   `fricont_monitor_fn` (no bind(C) needed: the module calls it through its own
!>   trampoline, with 1-based event numbers); returning .true. stops `run` with the end
!>   reason FRICONT_END_STOPPED, and the next `run` continues from there.
!>
!> Signs and units: lambda_n <= 0 is compressive; (N u)_i <= g_i is non-penetration;
!> forces are in the units of A u.
module fricont
    use, intrinsic :: iso_c_binding, only: c_int32_t, c_int64_t, c_int, c_double, c_bool, c_char, &
        c_ptr, c_funptr, c_null_ptr, c_null_funptr, c_null_char, c_size_t, c_loc, c_funloc, &
        c_associated, c_f_pointer
    use, intrinsic :: iso_fortran_env, only: int32, int64, real64, error_unit
    implicit none
    private

    ! ---- Status codes (fricont_status) ---------------------------------------------------
    integer, parameter, public :: FRICONT_OK = 0
    integer, parameter, public :: FRICONT_TRANSITION = 1
    integer, parameter, public :: FRICONT_FOLD = 2
    integer, parameter, public :: FRICONT_BIFURCATION = 3
    integer, parameter, public :: FRICONT_END = 4
    integer, parameter, public :: FRICONT_ERR_NULL = -101
    integer, parameter, public :: FRICONT_ERR_LENGTH = -102
    integer, parameter, public :: FRICONT_ERR_RANGE = -103
    integer, parameter, public :: FRICONT_ERR_ORDER = -104
    integer, parameter, public :: FRICONT_ERR_UNAVAILABLE = -105
    integer, parameter, public :: FRICONT_ERR_CSR = -201
    integer, parameter, public :: FRICONT_ERR_NONFINITE = -202
    integer, parameter, public :: FRICONT_ERR_NOT_SYMMETRIC = -203
    integer, parameter, public :: FRICONT_ERR_NOT_SPD = -204
    integer, parameter, public :: FRICONT_ERR_RANK_DEFICIENT = -205
    integer, parameter, public :: FRICONT_ERR_SOLVE_FAILED = -301
    integer, parameter, public :: FRICONT_ERR_NUMERICAL = -302
    integer, parameter, public :: FRICONT_ERR_OUT_OF_MEMORY = -303
    integer, parameter, public :: FRICONT_ERR_CALLBACK = -401
    integer, parameter, public :: FRICONT_ERR_CALLBACK_VALUE = -402
    integer, parameter, public :: FRICONT_ERR_SOLVE_CALLBACK = -403
    integer, parameter, public :: FRICONT_ERR_PANIC = -501
    integer, parameter, public :: FRICONT_ERR_POISONED = -502
    ! ---- Node classes (fricont_class) ----------------------------------------------------
    integer, parameter, public :: FRICONT_OPEN = 0
    integer, parameter, public :: FRICONT_STICK = 1
    integer, parameter, public :: FRICONT_SLIP_PLUS = 2
    integer, parameter, public :: FRICONT_SLIP_MINUS = 3
    ! ---- Storage of A (fricont_storage) --------------------------------------------------
    integer, parameter, public :: FRICONT_STORAGE_FULL = 0
    integer, parameter, public :: FRICONT_STORAGE_LOWER = 1
    integer, parameter, public :: FRICONT_STORAGE_UPPER = 2
    ! ---- End reasons (fricont_end_reason) ------------------------------------------------
    integer, parameter, public :: FRICONT_END_NONE = 0
    integer, parameter, public :: FRICONT_END_WINDOW = 1
    integer, parameter, public :: FRICONT_END_MAX_STEPS = 2
    integer, parameter, public :: FRICONT_END_CLOSED_LOOP = 3
    integer, parameter, public :: FRICONT_END_BIFURCATION = 4
    integer, parameter, public :: FRICONT_END_FAILED = 5
    integer, parameter, public :: FRICONT_END_STOPPED = 6
    ! ---- How the start was reached (fricont_start_route) ----------------------------------
    integer, parameter, public :: FRICONT_START_SOLVED = 0
    integer, parameter, public :: FRICONT_START_NEARBY = 1
    integer, parameter, public :: FRICONT_START_ZERO_LOAD = 2
    integer, parameter, public :: FRICONT_START_OPEN = 3
    ! ---- Extended precision modes (fricont_problem_set_extended_precision) ---------------
    integer, parameter, public :: FRICONT_EXTENDED_AUTO = 0
    integer, parameter, public :: FRICONT_EXTENDED_ON = 1
    integer, parameter, public :: FRICONT_EXTENDED_OFF = 2

    public :: fricont_load_fn, fricont_weights_fn, fricont_solve_fn, fricont_monitor_fn
    public :: fricont_class_name, fricont_end_reason_name, fricont_start_route_name
    public :: fricont_status_name, fricont_version

    !> The error argument: `status` (a negative fricont_status, or FRICONT_OK) and the
    !> library's message.
    type, public :: fricont_error
        integer :: status = FRICONT_OK
        character(len=:), allocatable :: message
    contains
        procedure :: ok => error_ok
    end type fricont_error

    !> One node changing class at a transition point (1-based index, transition, node).
    type, public :: fricont_event
        integer(int64) :: index = 0
        integer(int64) :: transition = 0
        real(real64) :: alpha = 0
        integer(int64) :: node = 0
        integer :: from = FRICONT_OPEN
        integer :: to = FRICONT_OPEN
        logical :: fold = .false.
        logical :: bifurcation = .false.
        real(real64) :: residual = 0
    end type fricont_event

    !> A point of the solution curve: u (n values), lambda_n, lambda_t, classes (p values).
    type, public :: fricont_state
        real(real64) :: alpha = 0
        real(real64) :: residual = 0
        real(real64), allocatable :: u(:), lambda_n(:), lambda_t(:)
        integer(c_int32_t), allocatable :: classes(:)
    end type fricont_state

    !> A traced smooth piece.
    type, public :: fricont_piece
        real(real64) :: alpha_from = 0
        real(real64) :: alpha_to = 0
        integer :: direction = 0
        integer :: orientation = 0
        integer :: det_sign = 0
        integer(c_int32_t), allocatable :: classes(:)
    end type fricont_piece

    !> A candidate continuation at a bifurcation (or a piece leaving the start point):
    !> the classes of its nodes, the sign of d alpha / ds along it (0: vertical) and
    !> whether it keeps the path's orientation.
    type, public :: fricont_branch
        integer :: direction = 0
        logical :: orientation_preserving = .false.
        integer(c_int32_t), allocatable :: classes(:)
    end type fricont_branch

    !> A contact problem (owns a fricont_problem handle).
    type, public :: fricont_problem
        type(c_ptr), private :: h = c_null_ptr
    contains
        procedure, private :: problem_create_i32, problem_create_i64
        generic :: create => problem_create_i32, problem_create_i64
        procedure :: create_condensed => problem_create_condensed
        procedure :: create_solve => problem_create_solve
        procedure, private :: problem_set_friction_scalar, problem_set_friction_nodes
        generic :: set_friction => problem_set_friction_scalar, problem_set_friction_nodes
        procedure :: set_gap => problem_set_gap
        procedure :: set_r => problem_set_r
        procedure :: set_threads => problem_set_threads
        procedure :: set_extended_precision => problem_set_extended_precision
        procedure :: extended_precision => problem_extended_precision
        procedure :: build => problem_build
        procedure :: n => problem_n
        procedure :: p => problem_p
        procedure :: r => problem_r
        procedure :: is_created => problem_is_created
        procedure :: free => problem_free
        procedure, private :: problem_assign
        generic :: assignment(=) => problem_assign
        final :: problem_final
    end type fricont_problem

    !> A load path on a problem (owns a fricont_path handle).
    type, public :: fricont_path
        type(c_ptr), private :: h = c_null_ptr
        integer(int64), private :: n = 0, p = 0
    contains
        procedure :: create_affine => path_create_affine
        procedure :: create_basis => path_create_basis
        procedure :: create_general => path_create_general
        procedure :: set_window => path_set_window
        procedure :: set_max_steps => path_set_max_steps
        procedure :: set_zero_tol => path_set_zero_tol
        procedure :: set_max_alpha_step => path_set_max_alpha_step
        procedure :: set_monitor => path_set_monitor
        procedure :: start => path_start
        procedure :: step => path_step
        procedure :: run => path_run
        procedure :: end_reason => path_end_reason
        procedure :: start_route => path_start_route
        procedure :: callback_code => path_callback_code
        procedure :: event_count => path_event_count
        procedure :: event => path_event
        procedure :: events => path_events
        procedure :: event_state => path_event_state
        procedure :: start_state => path_start_state
        procedure :: current => path_current
        procedure :: piece_count => path_piece_count
        procedure :: piece => path_piece
        procedure :: solutions_at => path_solutions_at
        procedure :: solution => path_solution
        procedure :: branch_count => path_branch_count
        procedure :: branch => path_branch
        procedure :: choose_branch => path_choose_branch
        procedure :: is_created => path_is_created
        procedure :: free => path_free
        procedure, private :: path_assign
        generic :: assignment(=) => path_assign
        final :: path_final
    end type fricont_path

    ! ---- The C structs (bind(C) mirrors of include/fricont.h) ---------------------------
    type, bind(C) :: c_csr
        integer(c_int64_t) :: nrows, ncols, nnz
        type(c_ptr) :: row_ptr, col_idx, values
        integer(c_int64_t) :: index_base
    end type c_csr

    type, bind(C) :: c_event
        integer(c_int64_t) :: index, transition
        real(c_double) :: alpha
        integer(c_int64_t) :: node
        integer(c_int32_t) :: from, to
        logical(c_bool) :: fold, bifurcation
        real(c_double) :: residual
    end type c_event

    type, bind(C) :: c_state
        real(c_double) :: alpha = 0, residual = 0
        type(c_ptr) :: u = c_null_ptr
        integer(c_int64_t) :: u_len = 0
        type(c_ptr) :: lambda_n = c_null_ptr
        integer(c_int64_t) :: lambda_n_len = 0
        type(c_ptr) :: lambda_t = c_null_ptr
        integer(c_int64_t) :: lambda_t_len = 0
        type(c_ptr) :: classes = c_null_ptr
        integer(c_int64_t) :: classes_len = 0
    end type c_state

    type, bind(C) :: c_piece
        real(c_double) :: alpha_from, alpha_to
        integer(c_int32_t) :: direction, orientation, det_sign
    end type c_piece

    type, bind(C) :: c_branch
        integer(c_int32_t) :: direction
        logical(c_bool) :: orientation_preserving
    end type c_branch

    type, bind(C) :: c_solution
        integer(c_int64_t) :: piece
        logical(c_bool) :: continuum
    end type c_solution

    abstract interface
        !> A general load: write f(alpha) (or f'(alpha)) into f(1:n); return 0, or a
        !> nonzero code to abort the step (never stop the program from here).
        function fricont_load_fn(alpha, f, n, user_data) bind(C) result(code)
            import :: c_double, c_int64_t, c_int32_t, c_ptr
            real(c_double), value :: alpha
            integer(c_int64_t), value :: n
            real(c_double), intent(out) :: f(n)
            type(c_ptr), value :: user_data
            integer(c_int32_t) :: code
        end function fricont_load_fn
        !> Basis weights: write phi_j(alpha) into phi(1:k) and phi_j'(alpha) into
        !> dphi(1:k); same return contract.
        function fricont_weights_fn(alpha, phi, dphi, k, user_data) bind(C) result(code)
            import :: c_double, c_int64_t, c_int32_t, c_ptr
            real(c_double), value :: alpha
            integer(c_int64_t), value :: k
            real(c_double), intent(out) :: phi(k), dphi(k)
            type(c_ptr), value :: user_data
            integer(c_int32_t) :: code
        end function fricont_weights_fn
        !> The host's solve with A (see problem%create_solve): overwrite x(1:n, 1:ncols)
        !> (leading dimension ldx) with A^-1 x; return 0, > 0 (recoverable) or < 0 (fatal).
        function fricont_solve_fn(user_data, n, ncols, x, ldx) bind(C) result(code)
            import :: c_int64_t, c_int, c_ptr, c_double
            type(c_ptr), value :: user_data
            integer(c_int64_t), value :: n, ncols, ldx
            real(c_double), intent(inout) :: x(ldx, ncols)
            integer(c_int) :: code
        end function fricont_solve_fn
        !> A progress monitor (see path%set_monitor), called by path%run after each
        !> transition point: `alpha` of the point, `transitions` traced so far, the new
        !> events first_event..last_event (1-based, for path%event; one per node that
        !> changed class), `user_data` as given to set_monitor. Return .false. to go on,
        !> .true. to stop the path (FRICONT_END_STOPPED). It may read the path (event,
        !> event_state, ...) but must not free it, nor stop the program.
        function fricont_monitor_fn(alpha, transitions, first_event, last_event, user_data) &
            result(stop_path)
            import :: real64, int64, c_ptr
            real(real64), intent(in) :: alpha
            integer(int64), intent(in) :: transitions, first_event, last_event
            type(c_ptr), intent(in) :: user_data
            logical :: stop_path
        end function fricont_monitor_fn
    end interface

    ! The monitor and its user data, allocated by set_monitor and owned by the library
    ! (deallocated by monitor_free when replaced, removed or the path is freed).
    type :: monitor_box
        procedure(fricont_monitor_fn), pointer, nopass :: f => null()
        type(c_ptr) :: user_data = c_null_ptr
    end type monitor_box

    ! ---- The C functions (private) -------------------------------------------------------
    interface
        function c_problem_new(a, storage, n, t, out) bind(C, name="fricont_problem_new")
            import :: c_csr, c_int32_t, c_ptr
            type(c_csr), intent(in) :: a, n, t
            integer(c_int32_t), value :: storage
            type(c_ptr), intent(out) :: out
            integer(c_int32_t) :: c_problem_new
        end function
        subroutine c_problem_free(h) bind(C, name="fricont_problem_free")
            import :: c_ptr
            type(c_ptr), value :: h
        end subroutine
        function c_problem_set_friction(h, f) bind(C, name="fricont_problem_set_friction")
            import :: c_ptr, c_double, c_int32_t
            type(c_ptr), value :: h
            real(c_double), value :: f
            integer(c_int32_t) :: c_problem_set_friction
        end function
        function c_problem_set_friction_nodes(h, f, len) &
            bind(C, name="fricont_problem_set_friction_nodes")
            import :: c_ptr, c_double, c_int32_t, c_int64_t
            type(c_ptr), value :: h
            real(c_double), intent(in) :: f(*)
            integer(c_int64_t), value :: len
            integer(c_int32_t) :: c_problem_set_friction_nodes
        end function
        function c_problem_set_gap(h, g, len) bind(C, name="fricont_problem_set_gap")
            import :: c_ptr, c_double, c_int32_t, c_int64_t
            type(c_ptr), value :: h
            real(c_double), intent(in) :: g(*)
            integer(c_int64_t), value :: len
            integer(c_int32_t) :: c_problem_set_gap
        end function
        function c_problem_set_r(h, r) bind(C, name="fricont_problem_set_r")
            import :: c_ptr, c_double, c_int32_t
            type(c_ptr), value :: h
            real(c_double), value :: r
            integer(c_int32_t) :: c_problem_set_r
        end function
        function c_problem_set_threads(h, threads) bind(C, name="fricont_problem_set_threads")
            import :: c_ptr, c_int64_t, c_int32_t
            type(c_ptr), value :: h
            integer(c_int64_t), value :: threads
            integer(c_int32_t) :: c_problem_set_threads
        end function
        function c_problem_new_condensed(p, w, ldw, out) &
            bind(C, name="fricont_problem_new_condensed")
            import :: c_int64_t, c_int32_t, c_ptr
            integer(c_int64_t), value :: p, ldw
            type(c_ptr), value :: w
            type(c_ptr), intent(out) :: out
            integer(c_int32_t) :: c_problem_new_condensed
        end function
        function c_problem_new_solve(n, solve, user, free_fn, max_block, nm, t, out) &
            bind(C, name="fricont_problem_new_solve")
            import :: c_int64_t, c_int32_t, c_ptr, c_funptr, c_csr
            integer(c_int64_t), value :: n, max_block
            type(c_funptr), value :: solve, free_fn
            type(c_ptr), value :: user
            type(c_csr), intent(in) :: nm, t
            type(c_ptr), intent(out) :: out
            integer(c_int32_t) :: c_problem_new_solve
        end function
        function c_problem_build(h) bind(C, name="fricont_problem_build")
            import :: c_ptr, c_int32_t
            type(c_ptr), value :: h
            integer(c_int32_t) :: c_problem_build
        end function
        function c_problem_dims(h, n, p) bind(C, name="fricont_problem_dims")
            import :: c_ptr, c_int32_t, c_int64_t
            type(c_ptr), value :: h
            integer(c_int64_t), intent(out) :: n, p
            integer(c_int32_t) :: c_problem_dims
        end function
        function c_problem_r(h, r, default_r) bind(C, name="fricont_problem_r")
            import :: c_ptr, c_int32_t, c_double
            type(c_ptr), value :: h
            real(c_double), intent(out) :: r, default_r
            integer(c_int32_t) :: c_problem_r
        end function
        function c_path_new_affine(h, f0, f1, n, out) bind(C, name="fricont_path_new_affine")
            import :: c_ptr, c_int32_t, c_int64_t, c_double
            type(c_ptr), value :: h
            real(c_double), intent(in) :: f0(*), f1(*)
            integer(c_int64_t), value :: n
            type(c_ptr), intent(out) :: out
            integer(c_int32_t) :: c_path_new_affine
        end function
        function c_path_new_basis(h, vectors, n, k, weights, user_data, free_fn, out) &
            bind(C, name="fricont_path_new_basis")
            import :: c_ptr, c_int32_t, c_int64_t, c_double, c_funptr
            type(c_ptr), value :: h
            real(c_double), intent(in) :: vectors(*)
            integer(c_int64_t), value :: n, k
            type(c_funptr), value :: weights, free_fn
            type(c_ptr), value :: user_data
            type(c_ptr), intent(out) :: out
            integer(c_int32_t) :: c_path_new_basis
        end function
        function c_path_new_general(h, n, f, df, user_data, free_fn, out) &
            bind(C, name="fricont_path_new_general")
            import :: c_ptr, c_int32_t, c_int64_t, c_funptr
            type(c_ptr), value :: h
            integer(c_int64_t), value :: n
            type(c_funptr), value :: f, df, free_fn
            type(c_ptr), value :: user_data
            type(c_ptr), intent(out) :: out
            integer(c_int32_t) :: c_path_new_general
        end function
        subroutine c_path_free(h) bind(C, name="fricont_path_free")
            import :: c_ptr
            type(c_ptr), value :: h
        end subroutine
        function c_path_set_window(h, a0, a1) bind(C, name="fricont_path_set_window")
            import :: c_ptr, c_int32_t, c_double
            type(c_ptr), value :: h
            real(c_double), value :: a0, a1
            integer(c_int32_t) :: c_path_set_window
        end function
        function c_path_set_max_steps(h, m) bind(C, name="fricont_path_set_max_steps")
            import :: c_ptr, c_int32_t, c_int64_t
            type(c_ptr), value :: h
            integer(c_int64_t), value :: m
            integer(c_int32_t) :: c_path_set_max_steps
        end function
        function c_path_set_zero_tol(h, t) bind(C, name="fricont_path_set_zero_tol")
            import :: c_ptr, c_int32_t, c_double
            type(c_ptr), value :: h
            real(c_double), value :: t
            integer(c_int32_t) :: c_path_set_zero_tol
        end function
        function c_path_set_max_alpha_step(h, s) bind(C, name="fricont_path_set_max_alpha_step")
            import :: c_ptr, c_int32_t, c_double
            type(c_ptr), value :: h
            real(c_double), value :: s
            integer(c_int32_t) :: c_path_set_max_alpha_step
        end function
        function c_path_set_monitor(h, f, user_data, free_fn) &
            bind(C, name="fricont_path_set_monitor")
            import :: c_ptr, c_int32_t, c_funptr
            type(c_ptr), value :: h, user_data
            type(c_funptr), value :: f, free_fn
            integer(c_int32_t) :: c_path_set_monitor
        end function
        function c_path_start(h, alpha, guess, len) bind(C, name="fricont_path_start")
            import :: c_ptr, c_int32_t, c_int64_t, c_double
            type(c_ptr), value :: h
            real(c_double), value :: alpha
            type(c_ptr), value :: guess
            integer(c_int64_t), value :: len
            integer(c_int32_t) :: c_path_start
        end function
        function c_path_step(h) bind(C, name="fricont_path_step")
            import :: c_ptr, c_int32_t
            type(c_ptr), value :: h
            integer(c_int32_t) :: c_path_step
        end function
        function c_path_run(h) bind(C, name="fricont_path_run")
            import :: c_ptr, c_int32_t
            type(c_ptr), value :: h
            integer(c_int32_t) :: c_path_run
        end function
        function c_path_end_reason(h, r) bind(C, name="fricont_path_end_reason")
            import :: c_ptr, c_int32_t
            type(c_ptr), value :: h
            integer(c_int32_t), intent(out) :: r
            integer(c_int32_t) :: c_path_end_reason
        end function
        function c_path_start_route(h, r) bind(C, name="fricont_path_start_route")
            import :: c_ptr, c_int32_t
            type(c_ptr), value :: h
            integer(c_int32_t), intent(out) :: r
            integer(c_int32_t) :: c_path_start_route
        end function
        function c_path_callback_code(h, c) bind(C, name="fricont_path_callback_code")
            import :: c_ptr, c_int32_t
            type(c_ptr), value :: h
            integer(c_int32_t), intent(out) :: c
            integer(c_int32_t) :: c_path_callback_code
        end function
        function c_path_event_count(h, c) bind(C, name="fricont_path_event_count")
            import :: c_ptr, c_int32_t, c_int64_t
            type(c_ptr), value :: h
            integer(c_int64_t), intent(out) :: c
            integer(c_int32_t) :: c_path_event_count
        end function
        function c_path_event(h, k, e) bind(C, name="fricont_path_event")
            import :: c_ptr, c_int32_t, c_int64_t, c_event
            type(c_ptr), value :: h
            integer(c_int64_t), value :: k
            type(c_event), intent(out) :: e
            integer(c_int32_t) :: c_path_event
        end function
        function c_path_event_state(h, k, s) bind(C, name="fricont_path_event_state")
            import :: c_ptr, c_int32_t, c_int64_t, c_state
            type(c_ptr), value :: h
            integer(c_int64_t), value :: k
            type(c_state), intent(inout) :: s
            integer(c_int32_t) :: c_path_event_state
        end function
        function c_path_start_state(h, s) bind(C, name="fricont_path_start_state")
            import :: c_ptr, c_int32_t, c_state
            type(c_ptr), value :: h
            type(c_state), intent(inout) :: s
            integer(c_int32_t) :: c_path_start_state
        end function
        function c_path_current(h, s) bind(C, name="fricont_path_current")
            import :: c_ptr, c_int32_t, c_state
            type(c_ptr), value :: h
            type(c_state), intent(inout) :: s
            integer(c_int32_t) :: c_path_current
        end function
        function c_path_piece_count(h, c) bind(C, name="fricont_path_piece_count")
            import :: c_ptr, c_int32_t, c_int64_t
            type(c_ptr), value :: h
            integer(c_int64_t), intent(out) :: c
            integer(c_int32_t) :: c_path_piece_count
        end function
        function c_path_piece(h, k, pc, classes, len) bind(C, name="fricont_path_piece")
            import :: c_ptr, c_int32_t, c_int64_t, c_piece
            type(c_ptr), value :: h
            integer(c_int64_t), value :: k
            type(c_piece), intent(out) :: pc
            integer(c_int32_t), intent(out) :: classes(*)
            integer(c_int64_t), value :: len
            integer(c_int32_t) :: c_path_piece
        end function
        function c_path_branch_count(h, c) bind(C, name="fricont_path_branch_count")
            import :: c_ptr, c_int32_t, c_int64_t
            type(c_ptr), value :: h
            integer(c_int64_t), intent(out) :: c
            integer(c_int32_t) :: c_path_branch_count
        end function
        function c_path_branch(h, k, b, classes, len) bind(C, name="fricont_path_branch")
            import :: c_ptr, c_int32_t, c_int64_t, c_branch
            type(c_ptr), value :: h
            integer(c_int64_t), value :: k
            type(c_branch), intent(out) :: b
            integer(c_int32_t), intent(out) :: classes(*)
            integer(c_int64_t), value :: len
            integer(c_int32_t) :: c_path_branch
        end function
        function c_path_choose_branch(h, k) bind(C, name="fricont_path_choose_branch")
            import :: c_ptr, c_int32_t, c_int64_t
            type(c_ptr), value :: h
            integer(c_int64_t), value :: k
            integer(c_int32_t) :: c_path_choose_branch
        end function
        function c_problem_set_extended_precision(h, mode) &
            bind(C, name="fricont_problem_set_extended_precision")
            import :: c_ptr, c_int32_t
            type(c_ptr), value :: h
            integer(c_int32_t), value :: mode
            integer(c_int32_t) :: c_problem_set_extended_precision
        end function
        function c_problem_extended_precision(h, extended, w_condition) &
            bind(C, name="fricont_problem_extended_precision")
            import :: c_ptr, c_int32_t, c_double
            type(c_ptr), value :: h
            integer(c_int32_t), intent(out) :: extended
            real(c_double), intent(out) :: w_condition
            integer(c_int32_t) :: c_problem_extended_precision
        end function
        function c_path_solutions_at(h, alpha, c) bind(C, name="fricont_path_solutions_at")
            import :: c_ptr, c_int32_t, c_int64_t, c_double
            type(c_ptr), value :: h
            real(c_double), value :: alpha
            integer(c_int64_t), intent(out) :: c
            integer(c_int32_t) :: c_path_solutions_at
        end function
        function c_path_solution(h, k, info, s) bind(C, name="fricont_path_solution")
            import :: c_ptr, c_int32_t, c_int64_t, c_solution, c_state
            type(c_ptr), value :: h
            integer(c_int64_t), value :: k
            type(c_solution), intent(out) :: info
            type(c_state), intent(inout) :: s
            integer(c_int32_t) :: c_path_solution
        end function
        function c_status_str(st) bind(C, name="fricont_status_str")
            import :: c_ptr, c_int32_t
            integer(c_int32_t), value :: st
            type(c_ptr) :: c_status_str
        end function
        function c_class_name(c) bind(C, name="fricont_class_name")
            import :: c_ptr, c_int32_t
            integer(c_int32_t), value :: c
            type(c_ptr) :: c_class_name
        end function
        function c_end_reason_name(r) bind(C, name="fricont_end_reason_name")
            import :: c_ptr, c_int32_t
            integer(c_int32_t), value :: r
            type(c_ptr) :: c_end_reason_name
        end function
        function c_start_route_name(r) bind(C, name="fricont_start_route_name")
            import :: c_ptr, c_int32_t
            integer(c_int32_t), value :: r
            type(c_ptr) :: c_start_route_name
        end function
        function c_version() bind(C, name="fricont_version")
            import :: c_ptr
            type(c_ptr) :: c_version
        end function
        function c_last_error_message(buf, len) bind(C, name="fricont_last_error_message")
            import :: c_char, c_size_t
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_size_t), value :: len
            integer(c_size_t) :: c_last_error_message
        end function
    end interface

contains

    ! ---- Errors --------------------------------------------------------------------------

    !> True when the call succeeded (status >= 0).
    elemental logical function error_ok(self)
        class(fricont_error), intent(in) :: self
        error_ok = self%status >= 0
    end function error_ok

    ! A NUL-terminated static C string as a Fortran string.
    function c_string(p) result(s)
        type(c_ptr), intent(in) :: p
        character(len=:), allocatable :: s
        character(kind=c_char), pointer :: chars(:)
        integer :: i
        if (.not. c_associated(p)) then
            s = ''
            return
        end if
        call c_f_pointer(p, chars, [huge(0)])
        i = 0
        do while (chars(i + 1) /= c_null_char)
            i = i + 1
        end do
        allocate (character(len=i) :: s)
        s = transfer(chars(1:i), s)
    end function c_string

    ! The calling thread's last error message.
    function last_message() result(s)
        character(len=:), allocatable :: s
        character(kind=c_char) :: probe(1)
        character(kind=c_char), allocatable :: buf(:)
        integer(c_size_t) :: len
        len = c_last_error_message(probe, 0_c_size_t)
        allocate (buf(len + 1))
        len = c_last_error_message(buf, len + 1)
        allocate (character(len=len) :: s)
        s = transfer(buf(1:len), s)
    end function last_message

    ! Reports a status: into err when present; else a negative status stops the program.
    subroutine handle(st, err, where)
        integer(c_int32_t), intent(in) :: st
        type(fricont_error), intent(out), optional :: err
        character(len=*), intent(in) :: where
        character(len=:), allocatable :: msg
        if (st < 0) then
            msg = last_message()
            if (len(msg) == 0) msg = c_string(c_status_str(st))
            msg = where//': '//msg
        else
            msg = ''
        end if
        if (present(err)) then
            err%status = st
            err%message = msg
        else if (st < 0) then
            call fail_stop(msg)
        end if
    end subroutine handle

    ! Stops the program with the message (Fortran 2008: the stop code must be constant).
    subroutine fail_stop(msg)
        character(len=*), intent(in) :: msg
        write (error_unit, '(2a)') 'fricont: ', msg
        error stop 1
    end subroutine fail_stop

    ! An error detected on the Fortran side (before any C call).
    subroutine usage_error(st, msg, err)
        integer, intent(in) :: st
        character(len=*), intent(in) :: msg
        type(fricont_error), intent(out), optional :: err
        if (present(err)) then
            err%status = st
            err%message = msg
        else
            call fail_stop(msg)
        end if
    end subroutine usage_error

    !> Name of a class code: "open", "stick", "slip+", "slip-" (or "unknown").
    function fricont_class_name(code) result(s)
        integer, intent(in) :: code
        character(len=:), allocatable :: s
        s = c_string(c_class_name(int(code, c_int32_t)))
    end function fricont_class_name

    !> Name of an end reason: "none", "window", "max_steps", "closed_loop",
    !> "bifurcation", "failed", "stopped" (or "unknown").
    function fricont_end_reason_name(code) result(s)
        integer, intent(in) :: code
        character(len=:), allocatable :: s
        s = c_string(c_end_reason_name(int(code, c_int32_t)))
    end function fricont_end_reason_name

    !> Name of a start route: "solved", "nearby", "zero_load", "open" (or "unknown").
    function fricont_start_route_name(code) result(s)
        integer, intent(in) :: code
        character(len=:), allocatable :: s
        s = c_string(c_start_route_name(int(code, c_int32_t)))
    end function fricont_start_route_name

    !> Description of a status code ("FRICONT_ERR_CSR: ...").
    function fricont_status_name(st) result(s)
        integer, intent(in) :: st
        character(len=:), allocatable :: s
        s = c_string(c_status_str(int(st, c_int32_t)))
    end function fricont_status_name

    !> The library's version "MAJOR.MINOR.PATCH".
    function fricont_version() result(s)
        character(len=:), allocatable :: s
        s = c_string(c_version())
    end function fricont_version

    ! ---- Problem -------------------------------------------------------------------------

    !> Creates the problem from condensed data (fricont_problem_new_condensed): w is
    !> W = B A^-1 B^T (2p x 2p, symmetric positive definite; rows/columns 1..p normal,
    !> p+1..2p tangential). Loads are then condensed vectors q = B A^-1 f of 2p entries,
    !> states carry no u (state%u is left unallocated) and n() is 0. W is checked at the
    !> first build (FRICONT_ERR_NOT_SYMMETRIC, FRICONT_ERR_NOT_SPD, FRICONT_ERR_NONFINITE).
    subroutine problem_create_condensed(self, w, err)
        class(fricont_problem), intent(inout) :: self
        real(real64), intent(in), contiguous, target :: w(:, :)
        type(fricont_error), intent(out), optional :: err
        call self%free()
        if (size(w, 1) /= size(w, 2) .or. mod(size(w, 1), 2) /= 0 .or. size(w, 1) < 2) then
            call usage_error(FRICONT_ERR_LENGTH, 'fricont_problem%create_condensed: w must '// &
                             'be 2p x 2p with p >= 1', err)
            return
        end if
        call handle(c_problem_new_condensed(int(size(w, 1)/2, c_int64_t), c_loc(w), &
                                            int(size(w, 1), c_int64_t), self%h), err, &
                    'fricont_problem%create_condensed')
    end subroutine problem_create_condensed

    !> Creates the problem from N, T (CSR, int64 indices, p x n) and the host's own solve
    !> with A (fricont_problem_new_solve): `solve` is a bind(C) function of the interface
    !> fricont_solve_fn that overwrites x(1:n, 1:ncols) (leading dimension ldx) with A^-1 x
    !> and returns 0, > 0 (recoverable: retried once) or < 0 (fatal). `user_data` is
    !> passed to it unchanged and must stay valid while the problem or a path made from it
    !> lives. W is formed by 2p solves in blocks of at most `max_block` (default 64)
    !> columns; u at a point costs one solve. `index_base`: 1 (default) or 0.
    subroutine problem_create_solve(self, n, solve, user_data, n_ptr, n_col, n_val, &
                                    t_ptr, t_col, t_val, max_block, index_base, err)
        class(fricont_problem), intent(inout) :: self
        integer(int64), intent(in) :: n
        procedure(fricont_solve_fn) :: solve
        type(c_ptr), intent(in) :: user_data
        integer(int64), intent(in), contiguous, target :: n_ptr(:), n_col(:), t_ptr(:), t_col(:)
        real(real64), intent(in), contiguous, target :: n_val(:), t_val(:)
        integer, intent(in), optional :: max_block, index_base
        type(fricont_error), intent(out), optional :: err
        type(c_csr) :: nm, t
        integer(c_int64_t) :: base, blk
        call self%free()
        base = 1
        if (present(index_base)) base = index_base
        blk = 64
        if (present(max_block)) blk = max_block
        if (size(n_ptr) < 1 .or. size(t_ptr) < 1 .or. size(n_col) /= size(n_val) .or. &
            size(t_col) /= size(t_val)) then
            call usage_error(FRICONT_ERR_LENGTH, 'fricont_problem%create_solve: malformed '// &
                             'CSR arrays of N or T', err)
            return
        end if
        nm = c_csr(size(n_ptr) - 1, n, size(n_col), c_loc(n_ptr), c_loc_or_null_i(n_col), &
                   c_loc_or_null_r(n_val), base)
        t = c_csr(size(t_ptr) - 1, n, size(t_col), c_loc(t_ptr), c_loc_or_null_i(t_col), &
                  c_loc_or_null_r(t_val), base)
        call handle(c_problem_new_solve(n, c_funloc(solve), user_data, c_null_funptr, blk, &
                                        nm, t, self%h), err, 'fricont_problem%create_solve')
    end subroutine problem_create_solve

    !> Creates the problem from A, N, T in CSR (int64 indices). n = size(a_ptr) - 1,
    !> p = size(n_ptr) - 1; N and T have n columns. `storage`: FRICONT_STORAGE_FULL
    !> (default), _LOWER or _UPPER. `index_base`: 1 (default, Fortran) or 0. Frees a
    !> handle the variable held before.
    subroutine problem_create_i64(self, a_ptr, a_col, a_val, n_ptr, n_col, n_val, &
                                  t_ptr, t_col, t_val, storage, index_base, err)
        class(fricont_problem), intent(inout) :: self
        integer(int64), intent(in), contiguous, target :: a_ptr(:), a_col(:), n_ptr(:), &
            n_col(:), t_ptr(:), t_col(:)
        real(real64), intent(in), contiguous, target :: a_val(:), n_val(:), t_val(:)
        integer, intent(in), optional :: storage, index_base
        type(fricont_error), intent(out), optional :: err
        type(c_csr) :: a, n, t
        integer(c_int64_t) :: base, nd, pd
        integer(c_int32_t) :: st, stor
        call self%free()
        base = 1
        if (present(index_base)) base = index_base
        stor = FRICONT_STORAGE_FULL
        if (present(storage)) stor = storage
        if (size(a_ptr) < 1 .or. size(n_ptr) < 1 .or. size(t_ptr) < 1) then
            call usage_error(FRICONT_ERR_LENGTH, 'fricont_problem%create: a row pointer '// &
                             'array is empty (it needs nrows + 1 entries)', err)
            return
        end if
        if (size(a_col) /= size(a_val) .or. size(n_col) /= size(n_val) .or. &
            size(t_col) /= size(t_val)) then
            call usage_error(FRICONT_ERR_LENGTH, 'fricont_problem%create: column index and '// &
                             'value arrays differ in length', err)
            return
        end if
        nd = size(a_ptr) - 1
        pd = size(n_ptr) - 1
        a = c_csr(nd, nd, size(a_col), c_loc(a_ptr), c_loc_or_null_i(a_col), &
                  c_loc_or_null_r(a_val), base)
        n = c_csr(pd, nd, size(n_col), c_loc(n_ptr), c_loc_or_null_i(n_col), &
                  c_loc_or_null_r(n_val), base)
        t = c_csr(size(t_ptr) - 1, nd, size(t_col), c_loc(t_ptr), c_loc_or_null_i(t_col), &
                  c_loc_or_null_r(t_val), base)
        st = c_problem_new(a, stor, n, t, self%h)
        call handle(st, err, 'fricont_problem%create')
    end subroutine problem_create_i64

    function c_loc_or_null_i(x) result(p)
        integer(int64), intent(in), contiguous, target :: x(:)
        type(c_ptr) :: p
        p = c_null_ptr
        if (size(x) > 0) p = c_loc(x)
    end function c_loc_or_null_i

    function c_loc_or_null_r(x) result(p)
        real(real64), intent(in), contiguous, target :: x(:)
        type(c_ptr) :: p
        p = c_null_ptr
        if (size(x) > 0) p = c_loc(x)
    end function c_loc_or_null_r

    !> As the int64 version, for default-integer (32-bit) index arrays.
    subroutine problem_create_i32(self, a_ptr, a_col, a_val, n_ptr, n_col, n_val, &
                                  t_ptr, t_col, t_val, storage, index_base, err)
        class(fricont_problem), intent(inout) :: self
        integer(int32), intent(in) :: a_ptr(:), a_col(:), n_ptr(:), n_col(:), t_ptr(:), &
            t_col(:)
        real(real64), intent(in), contiguous, target :: a_val(:), n_val(:), t_val(:)
        integer, intent(in), optional :: storage, index_base
        type(fricont_error), intent(out), optional :: err
        call problem_create_i64(self, int(a_ptr, int64), int(a_col, int64), a_val, &
                                int(n_ptr, int64), int(n_col, int64), n_val, &
                                int(t_ptr, int64), int(t_col, int64), t_val, &
                                storage, index_base, err)
    end subroutine problem_create_i32

    !> The same friction coefficient F >= 0 at every node (default 0).
    subroutine problem_set_friction_scalar(self, f, err)
        class(fricont_problem), intent(inout) :: self
        real(real64), intent(in) :: f
        type(fricont_error), intent(out), optional :: err
        call handle(c_problem_set_friction(self%h, f), err, 'fricont_problem%set_friction')
    end subroutine problem_set_friction_scalar

    !> One friction coefficient per node (p values, >= 0).
    subroutine problem_set_friction_nodes(self, f, err)
        class(fricont_problem), intent(inout) :: self
        real(real64), intent(in) :: f(:)
        type(fricont_error), intent(out), optional :: err
        real(real64) :: copy(max(size(f), 1))
        copy(1:size(f)) = f
        call handle(c_problem_set_friction_nodes(self%h, copy, size(f, kind=c_int64_t)), &
                    err, 'fricont_problem%set_friction')
    end subroutine problem_set_friction_nodes

    !> The initial normal gap g (p values, length units of u; default 0).
    subroutine problem_set_gap(self, g, err)
        class(fricont_problem), intent(inout) :: self
        real(real64), intent(in) :: g(:)
        type(fricont_error), intent(out), optional :: err
        real(real64) :: copy(max(size(g), 1))
        copy(1:size(g)) = g
        call handle(c_problem_set_gap(self%h, copy, size(g, kind=c_int64_t)), err, &
                    'fricont_problem%set_gap')
    end subroutine problem_set_gap

    !> The augmentation parameter r > 0 (force per length; solutions do not depend on it).
    subroutine problem_set_r(self, r, err)
        class(fricont_problem), intent(inout) :: self
        real(real64), intent(in) :: r
        type(fricont_error), intent(out), optional :: err
        call handle(c_problem_set_r(self%h, r), err, 'fricont_problem%set_r')
    end subroutine problem_set_r

    !> Threads of the set-up (factorisation of A and forming W) and, where 2p >= 2048, of
    !> the trace's dense passes (a private pool per call into a path; callbacks stay on
    !> the calling thread), 1..1024; default 1 (no thread is started). Results agree with
    !> one thread to rounding. FRICONT_ERR_RANGE outside 1..1024.
    subroutine problem_set_threads(self, threads, err)
        class(fricont_problem), intent(inout) :: self
        integer, intent(in) :: threads
        type(fricont_error), intent(out), optional :: err
        call handle(c_problem_set_threads(self%h, int(threads, c_int64_t)), err, &
                    'fricont_problem%set_threads')
    end subroutine problem_set_threads

    !> Whether W and the condensed loads are carried beyond double precision:
    !> FRICONT_EXTENDED_AUTO (the default: where the refinement is cheap, or W is
    !> ill-conditioned and it is affordable), FRICONT_EXTENDED_ON or FRICONT_EXTENDED_OFF;
    !> see fricont_problem_set_extended_precision in fricont.h. A change drops the
    !> factorisation (the next build factorises again). FRICONT_ERR_RANGE for another
    !> value (the setting is then unchanged).
    subroutine problem_set_extended_precision(self, mode, err)
        class(fricont_problem), intent(inout) :: self
        integer, intent(in) :: mode
        type(fricont_error), intent(out), optional :: err
        call handle(c_problem_set_extended_precision(self%h, int(mode, c_int32_t)), err, &
                    'fricont_problem%set_extended_precision')
    end subroutine problem_set_extended_precision

    !> True when the problem is traced in extended precision (builds it if needed, so it
    !> returns the build's errors too); `w_condition` receives the estimate of the 2-norm
    !> condition number of the equilibrated W (dimensionless, usually a lower bound
    !> within a few percent).
    logical function problem_extended_precision(self, w_condition, err)
        class(fricont_problem), intent(inout) :: self
        real(real64), intent(out), optional :: w_condition
        type(fricont_error), intent(out), optional :: err
        integer(c_int32_t) :: e
        real(c_double) :: k
        e = 0
        k = 0
        call handle(c_problem_extended_precision(self%h, e, k), err, &
                    'fricont_problem%extended_precision')
        problem_extended_precision = e /= 0
        if (present(w_condition)) w_condition = k
    end function problem_extended_precision

    !> Validates and factorises now (optional: paths build when needed).
    subroutine problem_build(self, err)
        class(fricont_problem), intent(inout) :: self
        type(fricont_error), intent(out), optional :: err
        call handle(c_problem_build(self%h), err, 'fricont_problem%build')
    end subroutine problem_build

    !> Number of dofs n.
    integer(int64) function problem_n(self, err)
        class(fricont_problem), intent(in) :: self
        type(fricont_error), intent(out), optional :: err
        integer(c_int64_t) :: n, p
        n = 0
        call handle(c_problem_dims(self%h, n, p), err, 'fricont_problem%n')
        problem_n = n
    end function problem_n

    !> Number of contact nodes p.
    integer(int64) function problem_p(self, err)
        class(fricont_problem), intent(in) :: self
        type(fricont_error), intent(out), optional :: err
        integer(c_int64_t) :: n, p
        p = 0
        call handle(c_problem_dims(self%h, n, p), err, 'fricont_problem%p')
        problem_p = p
    end function problem_p

    !> The augmentation parameter in use (builds the problem if needed); `default_r`
    !> receives its data-derived default 2p / trace(W).
    real(real64) function problem_r(self, default_r, err)
        class(fricont_problem), intent(inout) :: self
        real(real64), intent(out), optional :: default_r
        type(fricont_error), intent(out), optional :: err
        real(c_double) :: r, d
        r = 0
        d = 0
        call handle(c_problem_r(self%h, r, d), err, 'fricont_problem%r')
        problem_r = r
        if (present(default_r)) default_r = d
    end function problem_r

    !> True while the variable holds a handle.
    logical function problem_is_created(self)
        class(fricont_problem), intent(in) :: self
        problem_is_created = c_associated(self%h)
    end function problem_is_created

    !> Frees the handle (a no-op when there is none). Paths made from it stay valid.
    subroutine problem_free(self)
        class(fricont_problem), intent(inout) :: self
        if (c_associated(self%h)) call c_problem_free(self%h)
        self%h = c_null_ptr
    end subroutine problem_free

    subroutine problem_final(self)
        type(fricont_problem), intent(inout) :: self
        call problem_free(self)
    end subroutine problem_final

    subroutine problem_assign(lhs, rhs)
        class(fricont_problem), intent(inout) :: lhs
        class(fricont_problem), intent(in) :: rhs
        if (c_associated(rhs%h) .or. c_associated(lhs%h)) &
            error stop 'fricont: a fricont_problem cannot be copied (pass it as an argument)'
    end subroutine problem_assign

    ! ---- Path ----------------------------------------------------------------------------

    subroutine path_dims(self, problem, err)
        class(fricont_path), intent(inout) :: self
        class(fricont_problem), intent(in) :: problem
        type(fricont_error), intent(out), optional :: err
        integer(c_int64_t) :: n, p
        integer(c_int32_t) :: st
        call self%free()
        n = 0
        p = 0
        st = c_problem_dims(problem%h, n, p)
        call handle(st, err, 'fricont_path%create')
        self%n = n
        self%p = p
    end subroutine path_dims

    !> Creates a path with the affine load f(alpha) = f0 + alpha f1 (n values each).
    subroutine path_create_affine(self, problem, f0, f1, err)
        class(fricont_path), intent(inout) :: self
        class(fricont_problem), intent(inout) :: problem
        real(real64), intent(in) :: f0(:), f1(:)
        type(fricont_error), intent(out), optional :: err
        type(fricont_error) :: e
        real(real64) :: c0(max(size(f0), 1)), c1(max(size(f1), 1))
        call path_dims(self, problem, e)
        if (.not. e%ok()) then
            call handle(int(e%status, c_int32_t), err, 'fricont_path%create_affine')
            return
        end if
        if (size(f0) /= size(f1)) then
            call usage_error(FRICONT_ERR_LENGTH, 'fricont_path%create_affine: f0 and f1 '// &
                             'differ in length', err)
            return
        end if
        c0(1:size(f0)) = f0
        c1(1:size(f1)) = f1
        call handle(c_path_new_affine(problem%h, c0, c1, size(f0, kind=c_int64_t), self%h), &
                    err, 'fricont_path%create_affine')
    end subroutine path_create_affine

    !> Creates a path with f(alpha) = sum_j phi_j(alpha) vectors(:, j); `weights`
    !> (a bind(C) function, see fricont_weights_fn) gives phi and phi'. `user_data` is
    !> passed to it unchanged (c_loc of a target variable that outlives the path).
    subroutine path_create_basis(self, problem, vectors, weights, user_data, err)
        class(fricont_path), intent(inout) :: self
        class(fricont_problem), intent(inout) :: problem
        real(real64), intent(in) :: vectors(:, :)
        procedure(fricont_weights_fn) :: weights
        type(c_ptr), intent(in), optional :: user_data
        type(fricont_error), intent(out), optional :: err
        type(fricont_error) :: e
        type(c_ptr) :: ud
        real(real64), allocatable :: copy(:, :)
        call path_dims(self, problem, e)
        if (.not. e%ok()) then
            call handle(int(e%status, c_int32_t), err, 'fricont_path%create_basis')
            return
        end if
        ud = c_null_ptr
        if (present(user_data)) ud = user_data
        copy = vectors
        if (size(copy) == 0) then
            deallocate (copy)
            allocate (copy(1, 1))
        end if
        call handle(c_path_new_basis(problem%h, copy, size(vectors, 1, kind=c_int64_t), &
                                     size(vectors, 2, kind=c_int64_t), c_funloc(weights), &
                                     ud, c_null_funptr, self%h), err, &
                    'fricont_path%create_basis')
    end subroutine path_create_basis

    !> Creates a path with a general load computed by `f` (a bind(C) function, see
    !> fricont_load_fn), with its derivative `df` if given (else central differences).
    !> `user_data` is passed to both unchanged (c_loc of a target variable that outlives
    !> the path).
    subroutine path_create_general(self, problem, f, df, user_data, err)
        class(fricont_path), intent(inout) :: self
        class(fricont_problem), intent(inout) :: problem
        procedure(fricont_load_fn) :: f
        procedure(fricont_load_fn), optional :: df
        type(c_ptr), intent(in), optional :: user_data
        type(fricont_error), intent(out), optional :: err
        type(fricont_error) :: e
        type(c_ptr) :: ud
        type(c_funptr) :: dfp
        call path_dims(self, problem, e)
        if (.not. e%ok()) then
            call handle(int(e%status, c_int32_t), err, 'fricont_path%create_general')
            return
        end if
        ud = c_null_ptr
        if (present(user_data)) ud = user_data
        dfp = c_null_funptr
        if (present(df)) dfp = c_funloc(df)
        call handle(c_path_new_general(problem%h, self%n, c_funloc(f), dfp, ud, &
                                       c_null_funptr, self%h), err, &
                    'fricont_path%create_general')
    end subroutine path_create_general

    !> The alpha window (required before start): traced from alpha_start toward alpha_end.
    subroutine path_set_window(self, alpha_start, alpha_end, err)
        class(fricont_path), intent(inout) :: self
        real(real64), intent(in) :: alpha_start, alpha_end
        type(fricont_error), intent(out), optional :: err
        call handle(c_path_set_window(self%h, alpha_start, alpha_end), err, &
                    'fricont_path%set_window')
    end subroutine path_set_window

    !> The step limit (default 10000).
    subroutine path_set_max_steps(self, max_steps, err)
        class(fricont_path), intent(inout) :: self
        integer, intent(in) :: max_steps
        type(fricont_error), intent(out), optional :: err
        call handle(c_path_set_max_steps(self%h, int(max_steps, c_int64_t)), err, &
                    'fricont_path%set_max_steps')
    end subroutine path_set_max_steps

    !> The relative zero tolerance of guards (default 1e-11).
    subroutine path_set_zero_tol(self, tol, err)
        class(fricont_path), intent(inout) :: self
        real(real64), intent(in) :: tol
        type(fricont_error), intent(out), optional :: err
        call handle(c_path_set_zero_tol(self%h, tol), err, 'fricont_path%set_zero_tol')
    end subroutine path_set_zero_tol

    !> The largest alpha step (alpha units) of the step control of a nonlinear load
    !> (create_basis, create_general); default 1/8 of the window. A load feature narrower
    !> than the steps (a bump, a fast oscillation) can be stepped over; a largest step no
    !> longer than the narrowest feature cannot miss it. No effect on an affine load.
    !> Before start only. FRICONT_ERR_RANGE when not finite or <= 0, FRICONT_ERR_ORDER
    !> after the start.
    subroutine path_set_max_alpha_step(self, h, err)
        class(fricont_path), intent(inout) :: self
        real(real64), intent(in) :: h
        type(fricont_error), intent(out), optional :: err
        call handle(c_path_set_max_alpha_step(self%h, h), err, 'fricont_path%set_max_alpha_step')
    end subroutine path_set_max_alpha_step

    !> Sets the progress monitor that `run` calls after each transition point (replacing
    !> an earlier one), or removes it when `monitor` is absent. `monitor` has the interface
    !> fricont_monitor_fn (a module procedure, or any procedure that outlives the path);
    !> `user_data` (c_loc of a target variable that outlives the path, for instance the
    !> path itself) is passed to it unchanged. When it returns .true., `run` ends with the
    !> end reason FRICONT_END_STOPPED, keeping everything traced; the next `run` or `step`
    !> continues from there. `step` does not call it.
    subroutine path_set_monitor(self, monitor, user_data, err)
        class(fricont_path), intent(inout) :: self
        procedure(fricont_monitor_fn), optional :: monitor
        type(c_ptr), intent(in), optional :: user_data
        type(fricont_error), intent(out), optional :: err
        type(monitor_box), pointer :: box
        if (.not. present(monitor)) then
            call handle(c_path_set_monitor(self%h, c_null_funptr, c_null_ptr, c_null_funptr), &
                        err, 'fricont_path%set_monitor')
            return
        end if
        allocate (box)
        box%f => monitor
        if (present(user_data)) box%user_data = user_data
        ! The library owns box from here: it calls monitor_free exactly once (also when
        ! this call fails).
        call handle(c_path_set_monitor(self%h, c_funloc(monitor_trampoline), c_loc(box), &
                                       c_funloc(monitor_free)), err, 'fricont_path%set_monitor')
    end subroutine path_set_monitor

    ! The C monitor: calls the Fortran one with 1-based event numbers.
    function monitor_trampoline(alpha, transitions, first_event, end_event, box_ptr) &
        bind(C) result(code)
        real(c_double), value :: alpha
        integer(c_int64_t), value :: transitions, first_event, end_event
        type(c_ptr), value :: box_ptr
        integer(c_int32_t) :: code
        type(monitor_box), pointer :: box
        call c_f_pointer(box_ptr, box)
        code = 0
        if (box%f(alpha, int(transitions, int64), int(first_event + 1, int64), &
                  int(end_event, int64), box%user_data)) code = 1
    end function monitor_trampoline

    ! The finalizer of a monitor_box (called by the library).
    subroutine monitor_free(box_ptr) bind(C)
        type(c_ptr), value :: box_ptr
        type(monitor_box), pointer :: box
        call c_f_pointer(box_ptr, box)
        deallocate (box)
    end subroutine monitor_free

    !> Starts (or restarts) at alpha, from zero contact forces or from `guess` =
    !> (lambda_n(1:p), lambda_t(1:p)).
    subroutine path_start(self, alpha, guess, err)
        class(fricont_path), intent(inout) :: self
        real(real64), intent(in) :: alpha
        real(real64), intent(in), optional, target, contiguous :: guess(:)
        type(fricont_error), intent(out), optional :: err
        type(c_ptr) :: g
        integer(c_int64_t) :: len
        g = c_null_ptr
        len = 0
        if (present(guess)) then
            len = size(guess)
            if (len > 0) g = c_loc(guess)
        end if
        call handle(c_path_start(self%h, alpha, g, len), err, 'fricont_path%start')
    end subroutine path_start

    !> Advances to the next transition point or to the end; `outcome` receives
    !> FRICONT_TRANSITION, FRICONT_FOLD, FRICONT_BIFURCATION or FRICONT_END.
    subroutine path_step(self, outcome, err)
        class(fricont_path), intent(inout) :: self
        integer, intent(out), optional :: outcome
        type(fricont_error), intent(out), optional :: err
        integer(c_int32_t) :: st
        st = c_path_step(self%h)
        if (present(outcome)) outcome = max(int(st), 0)
        call handle(st, err, 'fricont_path%step')
    end subroutine path_step

    !> Steps until the path ends, calling the monitor (set_monitor), if any, after each
    !> transition point; `reason` receives the end reason (FRICONT_END_*;
    !> FRICONT_END_STOPPED when the monitor stopped it).
    subroutine path_run(self, reason, err)
        class(fricont_path), intent(inout) :: self
        integer, intent(out), optional :: reason
        type(fricont_error), intent(out), optional :: err
        integer(c_int32_t) :: st, r
        st = c_path_run(self%h)
        if (present(reason)) then
            r = FRICONT_END_NONE
            if (c_path_end_reason(self%h, r) /= FRICONT_OK) r = FRICONT_END_NONE
            reason = r
        end if
        call handle(st, err, 'fricont_path%run')
    end subroutine path_run

    !> Why the path ended (FRICONT_END_NONE while it goes on).
    integer function path_end_reason(self, err)
        class(fricont_path), intent(in) :: self
        type(fricont_error), intent(out), optional :: err
        integer(c_int32_t) :: r
        r = FRICONT_END_NONE
        call handle(c_path_end_reason(self%h, r), err, 'fricont_path%end_reason')
        path_end_reason = r
    end function path_end_reason

    !> How the start point was reached: FRICONT_START_SOLVED where the fixed-alpha solver
    !> found it, another FRICONT_START_* code where one of its fallbacks did (see
    !> fricont_path_start in fricont.h). Before the start: error FRICONT_ERR_ORDER (with
    !> err present the result is -1; without it the program stops).
    integer function path_start_route(self, err)
        class(fricont_path), intent(in) :: self
        type(fricont_error), intent(out), optional :: err
        integer(c_int32_t) :: r
        r = -1
        call handle(c_path_start_route(self%h, r), err, 'fricont_path%start_route')
        path_start_route = r
    end function path_start_route

    !> The nonzero code the last failing load callback returned (0 if none).
    integer function path_callback_code(self, err)
        class(fricont_path), intent(in) :: self
        type(fricont_error), intent(out), optional :: err
        integer(c_int32_t) :: c
        c = 0
        call handle(c_path_callback_code(self%h, c), err, 'fricont_path%callback_code')
        path_callback_code = c
    end function path_callback_code

    !> Number of events so far.
    integer(int64) function path_event_count(self, err)
        class(fricont_path), intent(in) :: self
        type(fricont_error), intent(out), optional :: err
        integer(c_int64_t) :: c
        c = 0
        call handle(c_path_event_count(self%h, c), err, 'fricont_path%event_count')
        path_event_count = c
    end function path_event_count

    !> Event k (1-based); its index, transition and node count from 1.
    type(fricont_event) function path_event(self, k, err) result(e)
        class(fricont_path), intent(in) :: self
        integer, intent(in) :: k
        type(fricont_error), intent(out), optional :: err
        type(c_event) :: ce
        integer(c_int32_t) :: st
        st = c_path_event(self%h, int(k - 1, c_int64_t), ce)
        call handle(st, err, 'fricont_path%event')
        if (st /= FRICONT_OK) return
        e = fricont_event(ce%index + 1, ce%transition + 1, ce%alpha, ce%node + 1, &
                          ce%from, ce%to, logical(ce%fold), logical(ce%bifurcation), &
                          ce%residual)
    end function path_event

    !> All events so far.
    function path_events(self, err) result(es)
        class(fricont_path), intent(in) :: self
        type(fricont_error), intent(out), optional :: err
        type(fricont_event), allocatable :: es(:)
        type(fricont_error) :: e
        integer(int64) :: count
        integer :: k
        allocate (es(0))
        count = path_event_count(self, e)
        if (e%ok()) then
            deallocate (es)
            allocate (es(count))
            do k = 1, int(count)
                es(k) = path_event(self, k, e)
                if (.not. e%ok()) exit
            end do
        end if
        if (present(err)) then
            err = e
        else if (.not. e%ok()) then
            call fail_stop(e%message)
        end if
    end function path_events

    ! Points a c_state at the (re)allocated arrays of state.
    function state_view(self, state) result(cs)
        class(fricont_path), intent(in) :: self
        type(fricont_state), intent(inout), target :: state
        type(c_state) :: cs
        if (allocated(state%u)) then
            if (size(state%u) /= self%n) deallocate (state%u)
        end if
        ! (no u for a problem made from condensed data: n = 0, u stays unallocated)
        if (.not. allocated(state%u) .and. self%n > 0) allocate (state%u(self%n))
        if (allocated(state%lambda_n)) then
            if (size(state%lambda_n) /= self%p) deallocate (state%lambda_n)
        end if
        if (.not. allocated(state%lambda_n)) allocate (state%lambda_n(max(self%p, 1_int64)))
        if (allocated(state%lambda_t)) then
            if (size(state%lambda_t) /= self%p) deallocate (state%lambda_t)
        end if
        if (.not. allocated(state%lambda_t)) allocate (state%lambda_t(max(self%p, 1_int64)))
        if (allocated(state%classes)) then
            if (size(state%classes) /= self%p) deallocate (state%classes)
        end if
        if (.not. allocated(state%classes)) allocate (state%classes(max(self%p, 1_int64)))
        cs%u = c_null_ptr
        if (self%n > 0) cs%u = c_loc(state%u)
        cs%u_len = self%n
        cs%lambda_n = c_loc(state%lambda_n)
        cs%lambda_n_len = self%p
        cs%lambda_t = c_loc(state%lambda_t)
        cs%lambda_t_len = self%p
        cs%classes = c_loc(state%classes)
        cs%classes_len = self%p
    end function state_view

    !> The full state at event k (1-based): u, lambda_n, lambda_t, the classes after it.
    subroutine path_event_state(self, k, state, err)
        class(fricont_path), intent(in) :: self
        integer, intent(in) :: k
        type(fricont_state), intent(inout), target :: state
        type(fricont_error), intent(out), optional :: err
        type(c_state) :: cs
        cs = state_view(self, state)
        call handle(c_path_event_state(self%h, int(k - 1, c_int64_t), cs), err, &
                    'fricont_path%event_state')
        state%alpha = cs%alpha
        state%residual = cs%residual
    end subroutine path_event_state

    !> The start point.
    subroutine path_start_state(self, state, err)
        class(fricont_path), intent(in) :: self
        type(fricont_state), intent(inout), target :: state
        type(fricont_error), intent(out), optional :: err
        type(c_state) :: cs
        cs = state_view(self, state)
        call handle(c_path_start_state(self%h, cs), err, 'fricont_path%start_state')
        state%alpha = cs%alpha
        state%residual = cs%residual
    end subroutine path_start_state

    !> The current point (may call the load callback).
    subroutine path_current(self, state, err)
        class(fricont_path), intent(inout) :: self
        type(fricont_state), intent(inout), target :: state
        type(fricont_error), intent(out), optional :: err
        type(c_state) :: cs
        cs = state_view(self, state)
        call handle(c_path_current(self%h, cs), err, 'fricont_path%current')
        state%alpha = cs%alpha
        state%residual = cs%residual
    end subroutine path_current

    !> Number of traced pieces (the last is the current one).
    integer(int64) function path_piece_count(self, err)
        class(fricont_path), intent(in) :: self
        type(fricont_error), intent(out), optional :: err
        integer(c_int64_t) :: c
        c = 0
        call handle(c_path_piece_count(self%h, c), err, 'fricont_path%piece_count')
        path_piece_count = c
    end function path_piece_count

    !> Piece k (1-based): its alpha range, direction, orientation and classes.
    type(fricont_piece) function path_piece(self, k, err) result(pc)
        class(fricont_path), intent(in) :: self
        integer, intent(in) :: k
        type(fricont_error), intent(out), optional :: err
        type(c_piece) :: cp
        integer(c_int32_t) :: st
        allocate (pc%classes(max(self%p, 1_int64)))
        st = c_path_piece(self%h, int(k - 1, c_int64_t), cp, pc%classes, self%p)
        call handle(st, err, 'fricont_path%piece')
        if (st /= FRICONT_OK) return
        pc%alpha_from = cp%alpha_from
        pc%alpha_to = cp%alpha_to
        pc%direction = cp%direction
        pc%orientation = cp%orientation
        pc%det_sign = cp%det_sign
    end function path_piece

    !> Number of candidate continuations at the last transition point: 0 unless it was a
    !> bifurcation and no step has been taken since (the path ended there with
    !> FRICONT_END_BIFURCATION, or the step that found it returned FRICONT_BIFURCATION);
    !> directly after `start`, the number of pieces leaving the start point toward the
    !> window's end when more than one does.
    integer(int64) function path_branch_count(self, err)
        class(fricont_path), intent(in) :: self
        type(fricont_error), intent(out), optional :: err
        integer(c_int64_t) :: c
        c = 0
        call handle(c_path_branch_count(self%h, c), err, 'fricont_path%branch_count')
        path_branch_count = c
    end function path_branch_count

    !> Candidate k (1-based, up to branch_count) at the last bifurcation (or start).
    !> FRICONT_ERR_RANGE for k out of range, FRICONT_ERR_ORDER before the start.
    type(fricont_branch) function path_branch(self, k, err) result(b)
        class(fricont_path), intent(in) :: self
        integer, intent(in) :: k
        type(fricont_error), intent(out), optional :: err
        type(c_branch) :: cb
        integer(c_int32_t) :: st
        allocate (b%classes(max(self%p, 1_int64)))
        st = c_path_branch(self%h, int(k - 1, c_int64_t), cb, b%classes, self%p)
        call handle(st, err, 'fricont_path%branch')
        if (st /= FRICONT_OK) return
        b%direction = cb%direction
        b%orientation_preserving = logical(cb%orientation_preserving)
    end function path_branch

    !> Continues along candidate k (1-based) of the last bifurcation instead of the branch
    !> the path took (or after it ended with FRICONT_END_BIFURCATION); directly after
    !> `start`, starts again on the k-th piece leaving the start point. The next `step` or
    !> `run` follows it. Only directly after the bifurcation (or start):
    !> FRICONT_ERR_ORDER otherwise, FRICONT_ERR_RANGE for k out of range. May call the
    !> load callback.
    subroutine path_choose_branch(self, k, err)
        class(fricont_path), intent(inout) :: self
        integer, intent(in) :: k
        type(fricont_error), intent(out), optional :: err
        call handle(c_path_choose_branch(self%h, int(k - 1, c_int64_t)), err, &
                    'fricont_path%choose_branch')
    end subroutine path_choose_branch

    !> Computes every traced solution at alpha; `count` receives their number (several
    !> past a fold, 0 if the path never reached alpha). Read them with `solution`.
    subroutine path_solutions_at(self, alpha, count, err)
        class(fricont_path), intent(inout) :: self
        real(real64), intent(in) :: alpha
        integer, intent(out) :: count
        type(fricont_error), intent(out), optional :: err
        integer(c_int64_t) :: c
        c = 0
        call handle(c_path_solutions_at(self%h, alpha, c), err, 'fricont_path%solutions_at')
        count = int(c)
    end subroutine path_solutions_at

    !> Solution k (1-based) of the last solutions_at: its state, the (1-based) piece it
    !> lies on, and whether that piece is a vertical continuum of solutions.
    subroutine path_solution(self, k, state, piece, continuum, err)
        class(fricont_path), intent(in) :: self
        integer, intent(in) :: k
        type(fricont_state), intent(inout), target :: state
        integer, intent(out), optional :: piece
        logical, intent(out), optional :: continuum
        type(fricont_error), intent(out), optional :: err
        type(c_state) :: cs
        type(c_solution) :: info
        cs = state_view(self, state)
        info%piece = -1
        info%continuum = .false.
        call handle(c_path_solution(self%h, int(k - 1, c_int64_t), info, cs), err, &
                    'fricont_path%solution')
        state%alpha = cs%alpha
        state%residual = cs%residual
        if (present(piece)) piece = int(info%piece) + 1
        if (present(continuum)) continuum = info%continuum
    end subroutine path_solution

    !> True while the variable holds a handle.
    logical function path_is_created(self)
        class(fricont_path), intent(in) :: self
        path_is_created = c_associated(self%h)
    end function path_is_created

    !> Frees the handle (a no-op when there is none).
    subroutine path_free(self)
        class(fricont_path), intent(inout) :: self
        if (c_associated(self%h)) call c_path_free(self%h)
        self%h = c_null_ptr
        self%n = 0
        self%p = 0
    end subroutine path_free

    subroutine path_final(self)
        type(fricont_path), intent(inout) :: self
        call path_free(self)
    end subroutine path_final

    subroutine path_assign(lhs, rhs)
        class(fricont_path), intent(inout) :: lhs
        class(fricont_path), intent(in) :: rhs
        if (c_associated(rhs%h) .or. c_associated(lhs%h)) &
            error stop 'fricont: a fricont_path cannot be copied (pass it as an argument)'
    end subroutine path_assign

end module fricont
