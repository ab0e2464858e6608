#!/usr/bin/env bash
# Builds and runs the distributed example (fricont_petsc.c) with 2 MPI ranks, and with 1,
# and checks that its events (W and q from the MUMPS Schur complement, traced through
# fricont_problem_new_condensed) equal those of fricont_problem_new on the same problem to
# 1e-10 relative. Also checks that a MUMPS failure (parallel analysis, INFOG(1) = -38) is
# caught and reported instead of tracing a zero W. Installs libpetsc-real-dev and
# openmpi-bin with apt-get when missing; needs target/release/libfricont.so (built here if
# missing). Last line: "N passed, M failed".
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$ROOT"
OUT="$ROOT/target/petsc-mumps"
mkdir -p "$OUT"
passed=0
failed=0
pass() { passed=$((passed + 1)); echo "ok   $*"; }
fail() { failed=$((failed + 1)); echo "FAIL $*"; }

if ! pkg-config --exists petsc 2>/dev/null || ! command -v mpirun >/dev/null; then
    echo "installing libpetsc-real-dev openmpi-bin ..."
    SUDO=""
    if [ "$(id -u)" != 0 ] && command -v sudo >/dev/null; then SUDO="sudo"; fi
    $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq \
        --no-install-recommends libpetsc-real-dev openmpi-bin libopenmpi-dev pkg-config >/dev/null
fi
if ! pkg-config --exists petsc || ! command -v mpirun >/dev/null; then
    echo "cannot install PETSc and Open MPI"; echo "0 passed, 1 failed"; exit 1
fi
[ -f target/release/libfricont.so ] || cargo build --release || { echo "0 passed, 1 failed"; exit 1; }

if mpicc -O2 -Wall -Wextra -Werror $(pkg-config --cflags petsc) -Iinclude examples-c/petsc-mumps/fricont_petsc.c \
    $(pkg-config --libs petsc) -Ltarget/release -Wl,-rpath,"$ROOT/target/release" -lfricont -lm \
    -o "$OUT/fricont_petsc" 2>"$OUT/build.log"; then
    pass "build fricont_petsc"
else
    fail "build fricont_petsc"; cat "$OUT/build.log"
fi

MPIRUN=(mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
# run LABEL NP ARGS...: exit status 0 and "agree" on the last line
run() {
    local label=$1 np=$2; shift 2
    local log="$OUT/$(echo "$label" | tr -c 'A-Za-z0-9_.-' '_').log"
    "${MPIRUN[@]}" -np "$np" "$OUT/fricont_petsc" "$@" >"$log" 2>&1
    local rc=$?
    if [ $rc -eq 0 ] && tail -1 "$log" | grep -q ': agree$'; then
        pass "$label: $(tail -1 "$log" | sed 's/.*: \([0-9]* events\); condensed/\1; condensed/')"
    else
        fail "$label (exit $rc)"; tail -20 "$log"
    fi
}
run "2 ranks, 64x8 elements" 2
run "1 rank, 32x4 elements" 1 -nx 32 -ny 4
run "2 ranks, 128x8 elements" 2 -nx 128 -ny 8
# MUMPS' parallel analysis fails on this matrix (INFOG(1) = -38) while PETSc would hand
# back a zero Schur complement: the example must stop with the MUMPS error.
log="$OUT/icntl28.log"
"${MPIRUN[@]}" -np 2 "$OUT/fricont_petsc" -mat_mumps_icntl_28 2 -mat_mumps_icntl_29 2 >"$log" 2>&1
rc=$?
if [ $rc -ne 0 ] && grep -q "MUMPS failed" "$log" && ! grep -q "agree" "$log"; then
    pass "a MUMPS failure is reported, not traced ($(grep -o 'INFOG(1) = -*[0-9]*' "$log" | head -1))"
else
    fail "MUMPS failure with ICNTL(28) = 2 (exit $rc)"; tail -20 "$log"
fi

echo "petsc-mumps: $passed passed, $failed failed"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
