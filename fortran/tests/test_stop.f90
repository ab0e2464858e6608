!> Without an err argument a failing call stops the program with the library's message
!> (run.sh expects a nonzero exit status and "fricont:" on stderr).
program test_stop
    use fricont
    implicit none
    integer :: ptr(3) = [1, 2, 3], col(2) = [1, 9]
    double precision :: val(2) = [1d0, 1d0]
    type(fricont_problem) :: bad
    call bad%create(ptr, col, val, ptr, col, val, ptr, col, val)
    print '(a)', 'not reached'
end program test_stop
