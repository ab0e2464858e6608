#!/usr/bin/env bash
# The MATLAB/Octave binding's tests: the MEX gateway matlab/fricont_mex.c built by
# fricont_build() from the build tree (Octave's `mkoctfile --mex`), then
# matlab/tests/test_fricont.m run in `octave --no-gui` on the sample problem. The events
# it traces (affine load; load function handles with and without derivative; A given as
# its lower triangle) must equal those of the C interface (tests-install/trace_case.c),
# and so must the transition table printed by the example matlab/examples/trace_sample.m.
# test_fricont.m itself checks monitors (a stop after 3 transition points against the
# unmonitored run, fricont_resume, errors in the monitor) and max_alpha_step (a narrow
# load bump at its analytic alpha).
# fricont_build() is also run from an installed copy (scripts/install.sh).
source "$(dirname "$0")/../tests-install/common.sh"

need_cmd octave octave || { fail "octave available"; finish; }
need_cmd mkoctfile liboctave-dev || { fail "mkoctfile (liboctave-dev) available"; finish; }
ensure_release || { fail "cargo build --release"; finish; }
run_check "C reference events (tests-install/trace_case.c)" build_reference

M=$ROOT/matlab
VERSION=$(sed -n 's/^version *= *"\([0-9.]*\)".*/\1/p' "$ROOT/Cargo.toml" | head -1)

# octave_eval CODE: runs CODE in Octave (no GUI, no user startup file).
octave_eval() { octave --no-gui --norc --no-window-system --eval "$1"; }
# runpath MEXFILE: the run-time search path recorded in the MEX file.
runpath() { readelf -d "$1" | sed -n 's/.*(RUNPATH).*\[\(.*\)\]/\1/p; s/.*(RPATH).*\[\(.*\)\]/\1/p'; }

# fricont_build() from the build tree: no argument, the library of this repository.
build_from_tree() {
    octave_eval "addpath('$M'); fricont_build([], '$WORK'); \
        exit(double(~strcmp(fricont_mex('version'), '$VERSION')))" &&
        [ "$(runpath "$WORK"/fricont_mex.mex)" = "$(cd "$LIBDIR" && pwd -P)" ]
}
# scripts/install.sh, then fricont_build() from the installed copy: PREFIX/lib.
build_from_install() {
    need_cmd patchelf patchelf || return 1
    bash "$ROOT/scripts/install.sh" "$WORK/prefix" >/dev/null || return 1
    mkdir -p "$WORK/built"
    octave_eval "addpath('$WORK/prefix/share/fricont/matlab'); fricont_build([], '$WORK/built'); \
         addpath('$WORK/built'); exit(double(~strcmp(fricont_mex('version'), '$VERSION')))" &&
        [ "$(runpath "$WORK"/built/fricont_mex.mex)" = "$(cd "$WORK/prefix/lib" && pwd -P)" ]
}
# compare_table REF OUT: the example's transition table (# alpha node from -> to ...)
# against the C interface's events: same nodes and classes, alpha within 1e-10 relative.
compare_table() {
    awk -v rtol=1e-10 '
        function abs(x) { return x < 0 ? -x : x }
        FNR == NR { if ($1 == "event") { n++; a[n] = $4; node[n] = $5; from[n] = $6; to[n] = $7
                    fold[n] = $8 } else if ($1 == "end") reason = $2; next }
        $1 ~ /^[0-9]+$/ && $5 == "->" {
            m++
            if (abs($2 - a[m]) > rtol * (abs(a[m]) > 1 ? abs(a[m]) : 1) || $3 != node[m] ||
                $4 != from[m] || $6 != to[m] || (($0 ~ / fold/) != (fold[m] == 1))) {
                print "row " m ": " $0 " vs alpha " a[m] " node " node[m] " " from[m] " -> " to[m]; bad = 1
            }
        }
        /the path ends:/ { ends = $NF }
        END {
            if (m != n || n == 0) { print m " rows, " n " events"; bad = 1 }
            if (ends != reason) { print "ends: " ends " vs " reason; bad = 1 }
            exit bad
        }' "$1" "$2"
}
cd "$WORK" || exit 1
run_check "fricont_mex.c compiles warning-free (-Wall -Wextra -Werror)" \
    gcc -std=c11 -fsyntax-only -Wall -Wextra -Werror $(mkoctfile -p INCFLAGS) \
    -I"$ROOT/include" "$M/fricont_mex.c"
run_check "fricont_build() from the build tree links target/release (rpath)" build_from_tree

if ls "$WORK"/fricont_mex.mex* >/dev/null 2>&1 && [ -f ref.txt ]; then
    timeout 600 octave --no-gui --norc --no-window-system --eval \
        "addpath('$M'); addpath('$M/tests'); addpath('$WORK'); \
         f = test_fricont('$CASE', '$WORK'); exit(double(f > 0))" >oct.txt 2>oct.err
    rc=$?
    grep -v -e 'X11 DISPLAY' -e 'disabling GUI' -e 'preparing to exit' oct.err | head -20
    cat oct.txt
    PASSED=$((PASSED + $(grep -c '^ok ' oct.txt)))
    FAILED=$((FAILED + $(grep -c '^FAIL ' oct.txt)))
    [ "$rc" -eq 0 ] || [ "$(grep -c '^FAIL ' oct.txt)" -gt 0 ] || fail "octave exited with $rc"
    grep -q 'matlab test_fricont:' oct.txt || fail "test_fricont.m ran to its end"
    run_check "fricont_build() from an installed copy links PREFIX/lib (rpath)" build_from_install
    run_check "example matlab/examples/trace_sample.m: its table equals the C interface's events" \
        bash -c "$(declare -f octave_eval compare_table); \
            octave_eval \"addpath('$WORK'); addpath('$M/examples'); trace_sample\" > example.txt &&
            cat example.txt && compare_table ref.txt example.txt"
    run_check "affine load: events equal the C interface's" compare_events ref.txt affine.txt
    run_check "A as its lower triangle (storage 'lower'): the events of the full matrix with those entries" \
        compare_events full_of_lower.txt lower.txt 1e-15
    run_check "load function handle f0 + sinh(s) f1 with df: events at asinh of the C ones" \
        compare_events ref.txt handle.txt 1e-9
    run_check "load function handle without df: events at asinh of the C ones" \
        compare_events ref.txt handle_nodf.txt 1e-9
fi
finish
