#!/usr/bin/env bash
# The C++ wrapper's tests: include/fricont.hpp compiled with -std=c++17 -Wall -Wextra
# -Wpedantic -Werror, run on the sample problem against the C interface's events, and
# run again under valgrind (no invalid access, no definite leak) when valgrind is there.
# The C++ example examples-cpp/q1_rectangle.cpp, built the same way, must print what
# its C twin examples-c/q1_rectangle.c prints (the same problem, the same events).
source "$(dirname "$0")/../tests-install/common.sh"

need_cmd g++ g++ || { fail "g++ available"; finish; }
ensure_release || { fail "cargo build --release"; finish; }
run_check "C reference events (tests-install/trace_case.c)" build_reference

CXXFLAGS="-std=c++17 -O1 -g -Wall -Wextra -Wpedantic -Werror"
run_check "fricont.h compiles as C++ alone" \
    bash -c "printf '#include <fricont.h>\nint main() { return fricont_version() == nullptr; }\n' |
        g++ $CXXFLAGS -I'$ROOT/include' -x c++ - -L'$LIBDIR' -lfricont \
            -Wl,-rpath,'$LIBDIR' -o '$WORK/h_only' && '$WORK/h_only'"
run_check "test_wrapper.cpp compiles (-Werror)" \
    g++ $CXXFLAGS -I"$ROOT/include" "$ROOT/cpp-tests/test_wrapper.cpp" \
    -L"$LIBDIR" -lfricont -Wl,-rpath,"$LIBDIR" -pthread -o "$WORK/test_wrapper"

run_check "examples-cpp/q1_rectangle.cpp (-Werror): the output of examples-c/q1_rectangle.c" \
    bash -c "g++ $CXXFLAGS -I'$ROOT/include' '$ROOT/examples-cpp/q1_rectangle.cpp' -L'$LIBDIR' \
            -lfricont -Wl,-rpath,'$LIBDIR' -o '$WORK/q1_cpp' &&
        cc -std=c99 -O1 -I'$ROOT/include' '$ROOT/examples-c/q1_rectangle.c' -L'$LIBDIR' \
            -lfricont -Wl,-rpath,'$LIBDIR' -lm -o '$WORK/q1_c' &&
        '$WORK/q1_cpp' > '$WORK/q1_cpp.txt' && '$WORK/q1_c' > '$WORK/q1_c.txt' &&
        diff '$WORK/q1_c.txt' '$WORK/q1_cpp.txt' && grep -q 'stick  -> slip+' '$WORK/q1_cpp.txt'"

if [ -x "$WORK/test_wrapper" ] && [ -f "$WORK/ref.txt" ]; then
    "$WORK/test_wrapper" "$CASE" "$WORK/ref.txt" >"$WORK/out.txt" 2>&1
    rc=$?
    cat "$WORK/out.txt"
    PASSED=$((PASSED + $(grep -c '^ok ' "$WORK/out.txt")))
    FAILED=$((FAILED + $(grep -c '^FAIL ' "$WORK/out.txt")))
    [ "$rc" -eq 0 ] || [ "$(grep -c '^FAIL ' "$WORK/out.txt")" -gt 0 ] ||
        fail "test_wrapper exited with $rc"
    if command -v valgrind >/dev/null 2>&1; then
        run_check "test_wrapper under valgrind (memcheck, definite leaks)" \
            valgrind -q --leak-check=full --errors-for-leak-kinds=definite \
            --error-exitcode=99 "$WORK/test_wrapper" "$CASE" "$WORK/ref.txt"
    fi
fi
finish
