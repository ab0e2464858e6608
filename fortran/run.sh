#!/usr/bin/env bash
# The Fortran binding's tests, built and run with gfortran: the module fricont
# (fortran/fricont.f90) and the example fortran/examples/trace_sample.f90 trace the
# sample problem; their events must equal those of the C interface
# (tests-install/trace_case.c), for the affine load and for a load computed by a Fortran
# bind(C) callback; fortran/tests/test_api.f90 checks the rest of the interface (also
# under valgrind).
source "$(dirname "$0")/../tests-install/common.sh"

need_cmd gfortran gfortran || { fail "gfortran available"; finish; }
ensure_release || { fail "cargo build --release"; finish; }
run_check "C reference events (tests-install/trace_case.c)" build_reference

FFLAGS="-std=f2008 -Wall -Wextra -Wno-compare-reals -Wno-unused-dummy-argument -Werror -fcheck=all -g -O1"
LINK=(-L"$LIBDIR" -lfricont -Wl,-rpath,"$LIBDIR")
F=$ROOT/fortran
cd "$WORK" || exit 1
run_check "module fricont compiles (-std=f2008 -Werror)" gfortran $FFLAGS -c "$F/fricont.f90"
run_check "example trace_sample builds" bash -c "gfortran $FFLAGS -c '$F/examples/case_reader.f90' \
    '$F/examples/trace_sample.f90' && gfortran -o trace_sample fricont.o case_reader.o \
    trace_sample.o ${LINK[*]}"
run_check "tests build" bash -c "gfortran $FFLAGS -c '$F/tests/test_api.f90' '$F/tests/test_stop.f90' &&
    gfortran -o test_api fricont.o case_reader.o test_api.o ${LINK[*]} &&
    gfortran -o test_stop fricont.o test_stop.o ${LINK[*]}"

if [ -x trace_sample ] && [ -f ref.txt ]; then
    run_check "affine load: events equal the C interface's" \
        bash -c "./trace_sample '$CASE' affine > aff.txt && source '$ROOT/tests-install/common.sh' &&
            compare_events ref.txt aff.txt"
    run_check "Fortran bind(C) load callback f0 + sinh(s) f1: events at asinh of the C ones" \
        bash -c "./trace_sample '$CASE' callback > cb.txt && source '$ROOT/tests-install/common.sh' &&
            compare_events ref.txt cb.txt 1e-9"
    if command -v valgrind >/dev/null 2>&1; then
        run_check "final procedures free every handle (valgrind: no definite leak)" \
            valgrind -q --leak-check=full --errors-for-leak-kinds=definite --error-exitcode=99 \
            ./trace_sample "$CASE" callback
    fi
fi
if [ -x test_api ]; then
    ./test_api "$CASE" >api.txt 2>&1
    rc=$?
    cat api.txt
    PASSED=$((PASSED + $(grep -c '^ok ' api.txt)))
    FAILED=$((FAILED + $(grep -c '^FAIL ' api.txt)))
    [ "$rc" -eq 0 ] || [ "$(grep -c '^FAIL ' api.txt)" -gt 0 ] || fail "test_api exited with $rc"
    if command -v valgrind >/dev/null 2>&1; then
        run_check "test_api under valgrind (monitors and callbacks: no invalid access, no definite leak)" \
            valgrind -q --leak-check=full --errors-for-leak-kinds=definite --error-exitcode=99 \
            ./test_api "$CASE"
    fi
fi
if [ -x test_stop ]; then
    run_check "no err argument: a failing call stops with the library's message" \
        bash -c "! ./test_stop > stop.out 2> stop.err && grep -q 'fricont: fricont_problem%create: A (CSR)' stop.err &&
            ! grep -q 'not reached' stop.out"
fi
finish
