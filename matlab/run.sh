#!/usr/bin/env bash
# The MATLAB/Octave binding's tests: the MEX gateway matlab/fricont_mex.c built with
# Octave's `mkoctfile --mex`, then matlab/tests/test_fricont.m run in `octave --no-gui`
# on the sample problem. The events it traces (affine load; load function handles with
# and without derivative; A given as its lower triangle) must equal those of the C
# interface (tests-install/trace_case.c).
source "$(dirname "$0")/../tests-install/common.sh"

need_cmd octave octave || { fail "octave available"; finish; }
need_cmd mkoctfile liboctave-dev || { fail "mkoctfile (liboctave-dev) available"; finish; }
ensure_release || { fail "cargo build --release"; finish; }
run_check "C reference events (tests-install/trace_case.c)" build_reference

M=$ROOT/matlab
VERSION=$(sed -n 's/^version *= *"\([0-9.]*\)".*/\1/p' "$ROOT/Cargo.toml" | head -1)

# scripts/install.sh, then fricont_build.m from the installed copy, in Octave.
build_from_install() {
    need_cmd patchelf patchelf || return 1
    bash "$ROOT/scripts/install.sh" "$WORK/prefix" >/dev/null || return 1
    mkdir -p "$WORK/built"
    octave --no-gui --norc --no-window-system --eval \
        "addpath('$WORK/prefix/share/fricont/matlab'); fricont_build('$WORK/prefix', '$WORK/built'); \
         addpath('$WORK/built'); exit(double(~strcmp(fricont_mex('version'), '$VERSION')))"
}
cd "$WORK" || exit 1
run_check "fricont_mex.c compiles warning-free (-Wall -Wextra -Werror)" \
    gcc -std=c11 -fsyntax-only -Wall -Wextra -Werror $(mkoctfile -p INCFLAGS) \
    -I"$ROOT/include" "$M/fricont_mex.c"
run_check "mkoctfile --mex builds fricont_mex" \
    mkoctfile --mex -I"$ROOT/include" -L"$LIBDIR" -lfricont -Wl,-rpath,"$LIBDIR" \
    -o "$WORK/fricont_mex" "$M/fricont_mex.c"

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
    run_check "fricont_build(prefix, outdir) builds the gateway from an installed copy" \
        build_from_install
    run_check "affine load: events equal the C interface's" compare_events ref.txt affine.txt
    run_check "A as its lower triangle (storage 'lower'): the events of the full matrix with those entries" \
        compare_events full_of_lower.txt lower.txt 1e-15
    run_check "load function handle f0 + sinh(s) f1 with df: events at asinh of the C ones" \
        compare_events ref.txt handle.txt 1e-9
    run_check "load function handle without df: events at asinh of the C ones" \
        compare_events ref.txt handle_nodf.txt 1e-9
fi
finish
