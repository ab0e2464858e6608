#!/usr/bin/env bash
# Builds and runs the C tests of fricont against target/release/libfricont.so (build it
# first with `cargo build --release`; built here if missing). Installs libsuitesparse-dev
# (CHOLMOD, for the reference check) with apt-get when it is missing. Runs the test
# binaries again built with AddressSanitizer + UndefinedBehaviorSanitizer, the threads
# test built with ThreadSanitizer, and the plain binaries under valgrind when valgrind is
# installed (three separate passes: the sanitizers and valgrind do not mix). Any report
# fails its test. Exits non-zero on any failure; the last line is "N passed, M failed".
#
#   c-tests/run.sh            from the repository root or anywhere
#   FRICONT_CASES=DIR         where the sample cases live (default tests/data
#                             in the repository)
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
CASES="${FRICONT_CASES:-$ROOT/tests/data}"
OUT="$ROOT/target/c-tests"
LIBDIR="$ROOT/target/release"
mkdir -p "$OUT"
passed=0
failed=0
pass() { passed=$((passed + 1)); echo "ok   $*"; }
fail() { failed=$((failed + 1)); echo "FAIL $*"; }

# --- prerequisites -------------------------------------------------------------------------
if [ ! -f /usr/include/suitesparse/cholmod.h ]; then
    echo "installing libsuitesparse-dev (CHOLMOD) ..."
    SUDO=""
    if [ "$(id -u)" != 0 ] && command -v sudo >/dev/null; then SUDO="sudo"; fi
    $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libsuitesparse-dev >/dev/null
    if [ ! -f /usr/include/suitesparse/cholmod.h ]; then
        echo "cannot install libsuitesparse-dev"; echo "0 passed, 1 failed"; exit 1
    fi
fi
if [ ! -f "$LIBDIR/libfricont.so" ]; then
    cargo build --release || { echo "0 passed, 1 failed"; exit 1; }
fi

# --- build ---------------------------------------------------------------------------------
WARN=(-Wall -Wextra -Wpedantic -Werror)
LINK=(-L"$LIBDIR" -Wl,-rpath,"$LIBDIR" -lfricont)
build() { # name, command...
    local name=$1; shift
    if "$@" 2>"$OUT/$name.build.log"; then pass "build $name"; else fail "build $name"; cat "$OUT/$name.build.log"; fi
}
C="cc -std=c99 -O1 -g -Iinclude -Ic-tests"
build header_c $C "${WARN[@]}" c-tests/header_a.c c-tests/header_b.c -o "$OUT/header_c" "${LINK[@]}"
build header_cpp c++ -std=c++17 -O1 -g -Iinclude "${WARN[@]}" c-tests/header_a.cpp c-tests/header_b.cpp -o "$OUT/header_cpp" "${LINK[@]}"
build status $C -D_POSIX_C_SOURCE=200809L "${WARN[@]}" c-tests/status.c c-tests/common.c -o "$OUT/status" "${LINK[@]}" -lm
build paths $C -D_POSIX_C_SOURCE=200809L "${WARN[@]}" c-tests/paths.c c-tests/common.c -o "$OUT/paths" "${LINK[@]}" -lm -lpthread
build cholmod_ref $C -I/usr/include/suitesparse "${WARN[@]}" c-tests/cholmod_ref.c c-tests/common.c -o "$OUT/cholmod_ref" "${LINK[@]}" -lcholmod -lm
build monitor $C "${WARN[@]}" c-tests/monitor.c c-tests/common.c -o "$OUT/monitor" "${LINK[@]}" -lm
build start_branches $C "${WARN[@]}" c-tests/start_branches.c c-tests/common.c -o "$OUT/start_branches" "${LINK[@]}" -lm
build csr_input $C "${WARN[@]}" c-tests/csr_input.c c-tests/common.c -o "$OUT/csr_input" "${LINK[@]}" -lm
build oom $C -D_POSIX_C_SOURCE=200809L "${WARN[@]}" c-tests/oom.c c-tests/common.c -o "$OUT/oom" "${LINK[@]}" -lm
build scales $C "${WARN[@]}" c-tests/scales.c c-tests/common.c -o "$OUT/scales" "${LINK[@]}" -lm
build extended_precision $C "${WARN[@]}" c-tests/extended_precision.c c-tests/common.c -o "$OUT/extended_precision" "${LINK[@]}" -lm
build q1_rectangle $C "${WARN[@]}" examples-c/q1_rectangle.c -o "$OUT/q1_rectangle" "${LINK[@]}" -lm
# The same programs with AddressSanitizer + UndefinedBehaviorSanitizer, against the same
# (uninstrumented) release libfricont.so: every access the C side makes to what fricont
# returns or reads is checked, and ASan's malloc sees (and LeakSanitizer reports) the
# library's allocations too. Any report ends the program with a nonzero status.
SAN=(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
ASAN_OUT="$OUT/asan"
mkdir -p "$ASAN_OUT"
build asan_header_c $C "${WARN[@]}" "${SAN[@]}" c-tests/header_a.c c-tests/header_b.c -o "$ASAN_OUT/header_c" "${LINK[@]}"
build asan_header_cpp c++ -std=c++17 -O1 -g -Iinclude "${WARN[@]}" "${SAN[@]}" c-tests/header_a.cpp c-tests/header_b.cpp -o "$ASAN_OUT/header_cpp" "${LINK[@]}"
build asan_status $C -D_POSIX_C_SOURCE=200809L "${WARN[@]}" "${SAN[@]}" c-tests/status.c c-tests/common.c -o "$ASAN_OUT/status" "${LINK[@]}" -lm
build asan_paths $C -D_POSIX_C_SOURCE=200809L "${WARN[@]}" "${SAN[@]}" c-tests/paths.c c-tests/common.c -o "$ASAN_OUT/paths" "${LINK[@]}" -lm -lpthread
build asan_cholmod_ref $C -I/usr/include/suitesparse "${WARN[@]}" "${SAN[@]}" c-tests/cholmod_ref.c c-tests/common.c -o "$ASAN_OUT/cholmod_ref" "${LINK[@]}" -lcholmod -lm
build asan_scales $C "${WARN[@]}" "${SAN[@]}" c-tests/scales.c c-tests/common.c -o "$ASAN_OUT/scales" "${LINK[@]}" -lm
build asan_extended_precision $C "${WARN[@]}" "${SAN[@]}" c-tests/extended_precision.c c-tests/common.c -o "$ASAN_OUT/extended_precision" "${LINK[@]}" -lm
build asan_q1_rectangle $C "${WARN[@]}" "${SAN[@]}" examples-c/q1_rectangle.c -o "$ASAN_OUT/q1_rectangle" "${LINK[@]}" -lm
# The threads test with ThreadSanitizer (see the TSan section below).
TSAN_OUT="$OUT/tsan"
mkdir -p "$TSAN_OUT"
build tsan_paths $C -D_POSIX_C_SOURCE=200809L "${WARN[@]}" -fsanitize=thread -fno-omit-frame-pointer c-tests/paths.c c-tests/common.c -o "$TSAN_OUT/paths" "${LINK[@]}" -lm -lpthread

# --- run -----------------------------------------------------------------------------------
# run LABEL BINARY ARGS...: the binary's own "N passed, M failed" line counts as one test.
run() {
    local label=$1; shift
    local log="$OUT/$(echo "$label" | tr -c 'A-Za-z0-9_.-' '_').log"
    if ! command -v "$1" >/dev/null; then fail "$label (not built)"; return; fi
    "$@" >"$log" 2>&1
    local rc=$?
    local line
    line=$(grep -E '[0-9]+ passed, [0-9]+ failed' "$log" | tail -1)
    if [ $rc -eq 0 ] && [ -n "$line" ] && echo "$line" | grep -q ' 0 failed'; then
        pass "$label: ${line#*: }"
    else
        fail "$label (exit $rc): ${line:-no result line}"; tail -30 "$log"
    fi
}
SAMPLE="$CASES/sample-rect30"
Q1="$OUT/q1case"
mkdir -p "$Q1"
run "header C99" "$OUT/header_c"
run "header C++17" "$OUT/header_cpp"
run "status codes" "$OUT/status"
# Out of memory under a 4 GiB address-space limit: a status, not an abort.
run "out of memory (ulimit -v 4 GiB, p = 20000)" bash -c "ulimit -v 4000000 && exec '$OUT/oom' 20000"
if "$OUT/q1_rectangle" --write "$Q1" >"$OUT/q1_rectangle.txt" 2>&1 && grep -q "stick  -> slip+" "$OUT/q1_rectangle.txt"; then
    pass "examples-c/q1_rectangle prints a transition table"
else
    fail "examples-c/q1_rectangle"; cat "$OUT/q1_rectangle.txt"
fi
run "CHOLMOD reference: Q1 example" "$OUT/cholmod_ref" "$Q1"
run "CHOLMOD reference: Q1 example, F = 1.2, 1-based, upper" "$OUT/cholmod_ref" "$Q1" --F 1.2 --base 1 --storage upper
if [ -f "$SAMPLE/meta.json" ]; then
    run "CHOLMOD reference: sample" "$OUT/cholmod_ref" "$SAMPLE" --events "$OUT/sample-events.txt"
    run "CHOLMOD reference: sample, 1-based, lower" "$OUT/cholmod_ref" "$SAMPLE" --base 1 --storage lower
    run "CHOLMOD reference: sample, upper, r = 10" "$OUT/cholmod_ref" "$SAMPLE" --storage upper --r 10
    run "CHOLMOD reference: sample, F = 0.9" "$OUT/cholmod_ref" "$SAMPLE" --F 0.9
    run "CHOLMOD reference: sample, F = 0" "$OUT/cholmod_ref" "$SAMPLE" --F 0
    # The hosts' constructors: condensed W and q by CHOLMOD, and CHOLMOD as the host's solve.
    # And the set-up on a private pool of 2 threads (the same events to rounding).
    for via in condensed solve threads; do
        if [ "$via" = threads ]; then set -- --threads 2; else set -- --via "$via"; fi
        run "CHOLMOD reference: sample, $*" "$OUT/cholmod_ref" "$SAMPLE" "$@" --events "$OUT/sample-events-$via.txt"
        if python3 - "$OUT/sample-events.txt" "$OUT/sample-events-$via.txt" <<'PY'
import sys
a = [l.split() for l in open(sys.argv[1]) if l.strip()]
b = [l.split() for l in open(sys.argv[2]) if l.strip()]
assert len(a) == len(b) and a, f"{len(a)} events from A, N, T; {len(b)} via the host's constructor"
for x, y in zip(a, b):
    # alpha to 1e-10 relative: the sample's event 3 is determined by the data to ~2e-11
    assert abs(float(x[0]) - float(y[0])) <= 1e-10 * max(1.0, abs(float(x[0]))), (x, y)
    assert x[1:] == y[1:], (x, y)
PY
        then pass "via $via: the events of the A, N, T constructor on the sample"; else fail "via $via: events differ from the A, N, T constructor's"; fi
    done
    run "loads and threads: sample" "$OUT/paths" "$SAMPLE"
    run "monitor, largest step, re-entrant callbacks: sample" "$OUT/monitor" "$SAMPLE"
    run "CSR input (int32 indices, duplicates): sample" "$OUT/csr_input" "$SAMPLE"
    # the same events as the CLI (when the CLI can trace)
    CLI="$LIBDIR/fricont"
    if [ -x "$CLI" ] && "$CLI" trace "$SAMPLE" --json "$OUT/sample-cli.json" >/dev/null 2>&1 && command -v python3 >/dev/null; then
        if python3 - "$OUT/sample-cli.json" "$OUT/sample-events.txt" <<'PY'
import json, sys
cli = json.load(open(sys.argv[1]))["events"]
c = [l.split() for l in open(sys.argv[2]) if l.strip()]
assert len(cli) == len(c), f"{len(cli)} CLI events, {len(c)} from C"
for e, l in zip(cli, c):
    a = float(l[0])
    assert abs(e["alpha"] - a) <= 1e-12 * max(1.0, abs(a)), (e, l)
    assert (e["node"], e["from"], e["to"]) == (int(l[1]), l[2], l[3]), (e, l)
PY
        then pass "the C API gives the CLI's events on the sample"; else fail "C API events differ from the CLI's"; fi
    else
        echo "skip the CLI comparison (no working target/release/fricont trace or no python3)"
    fi
else
    fail "sample case not found at $SAMPLE (set FRICONT_CASES)"
fi
run "loads and threads: Q1 example" "$OUT/paths" "$Q1"
run "branches at the start: vertex-start" "$OUT/start_branches" "$CASES/vertex-start"
if [ -f "$SAMPLE/meta.json" ]; then
    run "extreme scales of A: sample" "$OUT/scales" "$SAMPLE"
    run "extended precision: sample, tiny, host, condensed" "$OUT/extended_precision" "$SAMPLE"
fi
run "CHOLMOD reference: Q1 example, via condensed" "$OUT/cholmod_ref" "$Q1" --F 1.2 --via condensed
run "CHOLMOD reference: Q1 example, via solve, 1-based" "$OUT/cholmod_ref" "$Q1" --F 1.2 --via solve --base 1

# --- AddressSanitizer + UndefinedBehaviorSanitizer -----------------------------------------
# A separate pass (ASan and valgrind do not mix). halt_on_error: the first report fails
# the program; detect_leaks: LeakSanitizer at exit.
SANENV=(env ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:abort_on_error=0
    UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1)
run "asan+ubsan header C99" "${SANENV[@]}" "$ASAN_OUT/header_c"
run "asan+ubsan header C++17" "${SANENV[@]}" "$ASAN_OUT/header_cpp"
run "asan+ubsan status codes" "${SANENV[@]}" "$ASAN_OUT/status"
echo "skip out of memory under ASan: ASan reserves terabytes of virtual address space for its shadow memory, which a ulimit -v cannot grant; the oom test runs in the plain and the valgrind passes"
if "${SANENV[@]}" "$ASAN_OUT/q1_rectangle" --write "$OUT/q1case-asan" >"$OUT/asan_q1_rectangle.txt" 2>&1 &&
    grep -q "stick  -> slip+" "$OUT/asan_q1_rectangle.txt"; then
    pass "asan+ubsan examples-c/q1_rectangle"
else
    fail "asan+ubsan examples-c/q1_rectangle"; tail -30 "$OUT/asan_q1_rectangle.txt"
fi
run "asan+ubsan CHOLMOD reference: Q1 example, F = 1.2, 1-based, upper" "${SANENV[@]}" "$ASAN_OUT/cholmod_ref" "$Q1" --F 1.2 --base 1 --storage upper
run "asan+ubsan CHOLMOD reference: Q1 example, via solve" "${SANENV[@]}" "$ASAN_OUT/cholmod_ref" "$Q1" --via solve
run "asan+ubsan CHOLMOD reference: Q1 example, via condensed" "${SANENV[@]}" "$ASAN_OUT/cholmod_ref" "$Q1" --via condensed
run "asan+ubsan loads and threads: Q1 example" "${SANENV[@]}" "$ASAN_OUT/paths" "$Q1"
if [ -f "$SAMPLE/meta.json" ]; then
    run "asan+ubsan CHOLMOD reference: sample, threads 2" "${SANENV[@]}" "$ASAN_OUT/cholmod_ref" "$SAMPLE" --threads 2
    run "asan+ubsan loads and threads: sample" "${SANENV[@]}" "$ASAN_OUT/paths" "$SAMPLE"
    run "asan+ubsan extreme scales of A: sample" "${SANENV[@]}" "$ASAN_OUT/scales" "$SAMPLE"
    run "asan+ubsan extended precision" "${SANENV[@]}" "$ASAN_OUT/extended_precision" "$SAMPLE"
fi

# --- ThreadSanitizer ---------------------------------------------------------------------------
# The threads test (three paths traced at once from three host threads, two of them on one
# shared problem handle) built with -fsanitize=thread. The library is not instrumented:
# TSan sees its memory through the intercepted libc calls (memcpy, memset, malloc, free)
# and sees nothing of its own synchronisation (Rust's futex-based locks and atomics), so a
# race between fricont's threads would be a false positive. This test starts no thread
# inside the library, and runs clean without suppressions. Left out: the set-up on the
# library's private pool (fricont_problem_set_threads > 1), where TSan reports frees in
# rayon's workers after joins it cannot see (false positives), and the CHOLMOD reference
# (CHOLMOD's uninstrumented OpenMP gives the same kind of reports).
TSANENV=(env TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1)
run "tsan loads and threads: Q1 example" "${TSANENV[@]}" "$TSAN_OUT/paths" "$Q1"
if [ -f "$SAMPLE/meta.json" ]; then
    run "tsan loads and threads: sample" "${TSANENV[@]}" "$TSAN_OUT/paths" "$SAMPLE"
fi

# --- valgrind ------------------------------------------------------------------------------
if command -v valgrind >/dev/null; then
    VG=(valgrind -q --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite)
    run "valgrind header C99" "${VG[@]}" "$OUT/header_c"
    run "valgrind header C++17" "${VG[@]}" "$OUT/header_cpp"
    if "${VG[@]}" "$OUT/q1_rectangle" >"$OUT/valgrind_q1.txt" 2>&1; then
        pass "valgrind examples-c/q1_rectangle"
    else
        fail "valgrind examples-c/q1_rectangle"; tail -30 "$OUT/valgrind_q1.txt"
    fi
    run "valgrind status codes" "${VG[@]}" "$OUT/status"
    run "valgrind out of memory (ulimit -v 8 GiB)" bash -c "ulimit -v 8000000 && exec ${VG[*]} '$OUT/oom' 20000"
    run "valgrind CHOLMOD reference: Q1 example" "${VG[@]}" "$OUT/cholmod_ref" "$Q1"
    run "valgrind CHOLMOD reference: Q1 example, via solve" "${VG[@]}" "$OUT/cholmod_ref" "$Q1" --via solve
    run "valgrind CHOLMOD reference: Q1 example, via condensed" "${VG[@]}" "$OUT/cholmod_ref" "$Q1" --via condensed
    run "valgrind loads and threads: Q1 example" "${VG[@]}" "$OUT/paths" "$Q1"
    run "valgrind CSR input (int32 indices, duplicates): Q1 example" "${VG[@]}" "$OUT/csr_input" "$Q1"
    if [ -f "$SAMPLE/meta.json" ]; then
        run "valgrind CHOLMOD reference: sample" "${VG[@]}" "$OUT/cholmod_ref" "$SAMPLE"
        run "valgrind monitor, largest step, re-entrant callbacks: sample" "${VG[@]}" "$OUT/monitor" "$SAMPLE"
        run "valgrind branches at the start: vertex-start" "${VG[@]}" "$OUT/start_branches" "$CASES/vertex-start"
    fi
else
    echo "skip valgrind (not installed)"
fi

echo "c-tests: $passed passed, $failed failed"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
