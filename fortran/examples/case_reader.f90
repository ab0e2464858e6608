!> A tiny reader of the exchange format (SPEC §7) for the Fortran example and tests:
!> Matrix Market coordinate files into 1-based CSR with default-integer indices (as a
!> Fortran FEM code stores them), vectors one number a line, and the meta.json keys
!> alpha_start, alpha_end and F (a number or an array).
module case_reader
    use, intrinsic :: iso_fortran_env, only: real64, error_unit
    implicit none
    private
    public :: csr_matrix, case_data, read_case

    type :: csr_matrix
        integer :: nrows = 0, ncols = 0
        logical :: symmetric = .false.   ! a "symmetric" file stores its lower triangle
        integer, allocatable :: row_ptr(:), col(:)
        real(real64), allocatable :: val(:)
    end type csr_matrix

    type :: case_data
        type(csr_matrix) :: a, n, t
        real(real64), allocatable :: f0(:), f1(:), gap(:), friction(:)
        real(real64) :: alpha_start = 0, alpha_end = 0
    end type case_data

contains

    subroutine die(msg)
        character(len=*), intent(in) :: msg
        write (error_unit, '(a)') msg
        error stop 2
    end subroutine die

    subroutine read_case(dir, c)
        character(len=*), intent(in) :: dir
        type(case_data), intent(out) :: c
        character(len=:), allocatable :: meta
        logical :: there
        call read_mtx(dir//'/A.mtx', c%a)
        call read_mtx(dir//'/N.mtx', c%n)
        call read_mtx(dir//'/T.mtx', c%t)
        call read_vec(dir//'/f0.txt', c%a%nrows, c%f0)
        call read_vec(dir//'/f1.txt', c%a%nrows, c%f1)
        inquire (file=dir//'/gap.txt', exist=there)
        if (there) then
            call read_vec(dir//'/gap.txt', c%n%nrows, c%gap)
        else
            allocate (c%gap(c%n%nrows), source=0.0_real64)
        end if
        call read_text(dir//'/meta.json', meta)
        c%alpha_start = json_number(meta, 'alpha_start')
        c%alpha_end = json_number(meta, 'alpha_end')
        call json_friction(meta, c%n%nrows, c%friction)
    end subroutine read_case

    subroutine read_mtx(path, m)
        character(len=*), intent(in) :: path
        type(csr_matrix), intent(out) :: m
        character(len=1024) :: line
        integer :: u, ios, nnz, k, i, pos
        integer, allocatable :: ri(:), ci(:), next(:)
        real(real64), allocatable :: v(:)
        open (newunit=u, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) call die('case_reader: cannot open '//path)
        read (u, '(a)') line
        if (index(line, '%%MatrixMarket') /= 1) error stop 'case_reader: not Matrix Market'
        m%symmetric = index(line, 'symmetric') > 0
        do
            read (u, '(a)') line
            if (line(1:1) /= '%') exit
        end do
        read (line, *) m%nrows, m%ncols, nnz
        allocate (ri(nnz), ci(nnz), v(nnz), m%row_ptr(m%nrows + 1), m%col(nnz), m%val(nnz))
        m%row_ptr = 0
        do k = 1, nnz
            read (u, *, iostat=ios) ri(k), ci(k), v(k)
            if (ios /= 0) call die('case_reader: short entry list in '//path)
            m%row_ptr(ri(k) + 1) = m%row_ptr(ri(k) + 1) + 1
        end do
        close (u)
        ! 1-based row pointers: row i holds positions row_ptr(i) .. row_ptr(i+1) - 1.
        m%row_ptr(1) = 1
        do i = 1, m%nrows
            m%row_ptr(i + 1) = m%row_ptr(i + 1) + m%row_ptr(i)
        end do
        next = m%row_ptr(1:m%nrows)
        do k = 1, nnz
            pos = next(ri(k))
            next(ri(k)) = pos + 1
            m%col(pos) = ci(k)
            m%val(pos) = v(k)
        end do
    end subroutine read_mtx

    subroutine read_vec(path, n, x)
        character(len=*), intent(in) :: path
        integer, intent(in) :: n
        real(real64), allocatable, intent(out) :: x(:)
        integer :: u, ios
        allocate (x(n))
        open (newunit=u, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) call die('case_reader: cannot open '//path)
        read (u, *, iostat=ios) x
        if (ios /= 0) call die('case_reader: too few numbers in '//path)
        close (u)
    end subroutine read_vec

    subroutine read_text(path, text)
        character(len=*), intent(in) :: path
        character(len=:), allocatable, intent(out) :: text
        integer :: u, ios, sz
        open (newunit=u, file=path, status='old', access='stream', form='unformatted', &
              action='read', iostat=ios)
        if (ios /= 0) call die('case_reader: cannot open '//path)
        inquire (unit=u, size=sz)
        allocate (character(len=sz) :: text)
        read (u) text
        close (u)
    end subroutine read_text

    ! The position just after "key": in text.
    integer function json_pos(text, key)
        character(len=*), intent(in) :: text, key
        integer :: at
        at = index(text, '"'//key//'"')
        if (at == 0) call die('case_reader: meta.json lacks '//key)
        json_pos = at + len(key) + 2
        json_pos = json_pos + index(text(json_pos:), ':')
    end function json_pos

    real(real64) function json_number(text, key)
        character(len=*), intent(in) :: text, key
        integer :: at, e
        at = json_pos(text, key)
        e = at + scan(text(at:), ',}') - 2
        read (text(at:e), *) json_number
    end function json_number

    subroutine json_friction(text, p, f)
        character(len=*), intent(in) :: text
        integer, intent(in) :: p
        real(real64), allocatable, intent(out) :: f(:)
        integer :: at, e
        at = json_pos(text, 'F')
        allocate (f(p))
        at = at + verify(text(at:), ' '//achar(9)//achar(10)//achar(13)) - 1
        if (text(at:at) == '[') then
            e = at + index(text(at:), ']') - 1
            read (text(at + 1:e - 1), *) f
        else
            f = json_number(text, 'F')
        end if
    end subroutine json_friction

end module case_reader
