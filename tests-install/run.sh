#!/usr/bin/env bash
# Install and discovery tests: scripts/install.sh puts fricont under a scratch PREFIX;
# then C, C++ and Fortran programs are built against that installed copy only, exactly as
# the docs recommend (`cc app.c $(pkg-config --cflags --libs fricont)`, no -Wl,-rpath
# of our own) and through CMake `find_package(fricont)` (shared and static), and run
# without LD_LIBRARY_PATH on the sample problem: their events must equal those of the
# same program built against the build tree. The installed PREFIX/bin/fricont must give
# the same events too. A second install without the rpath in fricont.pc
# (FRICONT_INSTALL_RPATH=0) checks the other documented ways to find the library at run
# time (-Wl,-rpath,$(pkg-config --variable=libdir fricont), LD_LIBRARY_PATH), and with
# FRICONT_INSTALL_DEBUG=1 that the debug information is kept on request.
source "$(dirname "$0")/common.sh"

need_cmd cc gcc || { fail "cc available"; finish; }
need_cmd pkg-config pkg-config || { fail "pkg-config available"; finish; }
need_cmd cmake cmake || { fail "cmake available"; finish; }
need_cmd patchelf patchelf || { fail "patchelf available"; finish; }
ensure_release || { fail "cargo build --release"; finish; }
run_check "C reference events (build tree)" build_reference

PREFIX=$WORK/prefix
run_check "scripts/install.sh PREFIX" bash "$ROOT/scripts/install.sh" "$PREFIX"
VERSION=$(sed -n 's/^version *= *"\([0-9.]*\)".*/\1/p' "$ROOT/Cargo.toml" | head -1)
MAJOR=${VERSION%%.*}
MINOR=$(echo "$VERSION" | cut -d. -f2)
if [ "$MAJOR" = 0 ]; then ABI=0.$MINOR; else ABI=$MAJOR; fi

soname_ok() {
    readelf -d "$PREFIX/lib/libfricont.so.$VERSION" | grep -q "SONAME.*\[libfricont.so.$ABI\]" &&
        [ "$(readlink "$PREFIX/lib/libfricont.so.$ABI")" = "libfricont.so.$VERSION" ] &&
        [ "$(readlink "$PREFIX/lib/libfricont.so")" = "libfricont.so.$ABI" ]
}
run_check "shared library carries the soname libfricont.so.$ABI (and the links)" soname_ok
DOC=$PREFIX/share/doc/fricont
run_check "installed files" test -f "$PREFIX/lib/libfricont.a" -a -f "$PREFIX/include/fricont.h" \
    -a -f "$PREFIX/include/fricont.hpp" -a -f "$PREFIX/share/fricont/fortran/fricont.f90" \
    -a -f "$PREFIX/lib/pkgconfig/fricont.pc" \
    -a -f "$PREFIX/lib/cmake/fricont/fricontConfig.cmake" \
    -a -f "$PREFIX/lib/cmake/fricont/fricontConfigVersion.cmake" \
    -a -f "$PREFIX/share/fricont/matlab/fricont_mex.c" \
    -a -f "$PREFIX/share/fricont/matlab/examples/trace_sample.m" -a -x "$PREFIX/bin/fricont" \
    -a -f "$DOC/README.md" -a -f "$DOC/CHANGELOG.md" -a -f "$DOC/LICENSE-MIT" \
    -a -f "$DOC/LICENSE-APACHE" -a -f "$DOC/docs/bindings.md" \
    -a -f "$DOC/examples/q1_rectangle.c" -a -f "$DOC/examples/q1_rectangle.cpp"
has_debug() { readelf -S "$1" | grep -q '\.debug_info'; }
stripped() { # no debug sections, smaller than built, the C interface still exported
    ! has_debug "$1" && [ "$(stat -c %s "$1")" -lt "$(stat -c %s "$2")" ] &&
        { [ "${3:-}" != dynamic ] || nm -D --defined-only "$1" | grep -q ' T fricont_path_run$'; }
}
run_check "libfricont.so.$VERSION stripped (exports kept), $(du -k "$PREFIX/lib/libfricont.so.$VERSION" | cut -f1) KiB" \
    stripped "$PREFIX/lib/libfricont.so.$VERSION" "$LIBDIR/libfricont.so" dynamic
run_check "libfricont.a and bin/fricont stripped" \
    bash -c "$(declare -f has_debug stripped); stripped '$PREFIX/lib/libfricont.a' '$LIBDIR/libfricont.a' &&
        stripped '$PREFIX/bin/fricont' '$LIBDIR/fricont'"

# Nothing below may see the build tree: no -I/-L to it, no LD_LIBRARY_PATH, and no
# -Wl,-rpath but the one pkg-config gives.
unset LD_LIBRARY_PATH
export PKG_CONFIG_PATH=$PREFIX/lib/pkgconfig
uses_installed() { # the program loads the installed soname, from PREFIX
    readelf -d "$1" | grep -q "NEEDED.*\[libfricont.so.$ABI\]" &&
        ldd "$1" | grep -q "libfricont.so.$ABI => $PREFIX/lib/"
}
cd "$WORK" || exit 1

# --- pkg-config ---------------------------------------------------------------------
run_check "pkg-config --modversion fricont = $VERSION" \
    test "$(pkg-config --modversion fricont)" = "$VERSION"
run_check "C program: cc app.c \$(pkg-config --cflags --libs fricont) builds" \
    bash -c "cc -std=c11 -Wall -Wextra -Wpedantic -Werror '$ROOT/tests-install/trace_case.c' \
        \$(pkg-config --cflags --libs fricont) -o pc_trace_case"
if [ -x pc_trace_case ]; then
    run_check "pkg-config build runs without LD_LIBRARY_PATH, on the installed libfricont.so.$ABI" \
        uses_installed pc_trace_case
    run_check "pkg-config build: events equal the build tree's" \
        bash -c "./pc_trace_case '$CASE' > pc.txt && cmp pc.txt ref.txt"
fi
run_check "installed examples q1_rectangle.c and .cpp via pkg-config: the build tree's C output" \
    bash -c "cc -std=c99 -O2 '$DOC/examples/q1_rectangle.c' \$(pkg-config --cflags --libs fricont) \
        -lm -o pc_q1 && c++ -std=c++17 -O2 -Wall -Wextra -Wpedantic -Werror \
        '$DOC/examples/q1_rectangle.cpp' \$(pkg-config --cflags --libs fricont) -o pc_q1cpp &&
        cc -std=c99 -O2 -I'$ROOT/include' '$ROOT/examples-c/q1_rectangle.c' \
        -L'$LIBDIR' -Wl,-rpath,'$LIBDIR' -lfricont -lm -o tree_q1 &&
        ./pc_q1 > q1_pc.txt && ./pc_q1cpp > q1_pccpp.txt && ./tree_q1 > q1_tree.txt &&
        cmp q1_pc.txt q1_tree.txt && cmp q1_pccpp.txt q1_tree.txt && grep -q 'stick  -> slip+' q1_pc.txt"
if command -v g++ >/dev/null 2>&1; then
    run_check "C++ wrapper test via pkg-config (installed fricont.hpp)" \
        bash -c "g++ -std=c++17 -Wall -Wextra -Wpedantic -Werror -I'$ROOT/cpp-tests' \
            '$ROOT/cpp-tests/test_wrapper.cpp' \$(pkg-config --cflags --libs fricont) \
            -pthread -o pc_cpp && ./pc_cpp '$CASE' ref.txt"
fi
if command -v gfortran >/dev/null 2>&1; then
    run_check "Fortran module from the installed source via pkg-config" \
        bash -c "gfortran -std=f2008 -O1 -c \"\$(pkg-config --variable=fortran_module_source fricont)\" \
            '$ROOT/fortran/examples/case_reader.f90' '$ROOT/fortran/examples/trace_sample.f90' &&
            gfortran -o pc_fortran fricont.o case_reader.o trace_sample.o \$(pkg-config --libs fricont) &&
            ./pc_fortran '$CASE' > pcf.txt && source '$ROOT/tests-install/common.sh' &&
            compare_events ref.txt pcf.txt"
fi

# --- The other documented ways, with fricont.pc without rpath ---------------------------
P2=$WORK/prefix2
run_check "install with FRICONT_INSTALL_RPATH=0 FRICONT_INSTALL_DEBUG=1" \
    env FRICONT_NO_BUILD=1 FRICONT_INSTALL_RPATH=0 FRICONT_INSTALL_DEBUG=1 \
    bash "$ROOT/scripts/install.sh" "$P2"
if [ -f "$P2/lib/pkgconfig/fricont.pc" ]; then
    run_check "FRICONT_INSTALL_DEBUG=1 keeps the debug information" has_debug "$P2/lib/libfricont.so.$VERSION"
    run_check "without the rpath: the documented failure, then -Wl,-rpath,\$(pkg-config --variable=libdir) and LD_LIBRARY_PATH run" \
        env PKG_CONFIG_PATH="$P2/lib/pkgconfig" bash -c "
            ! pkg-config --libs fricont | grep -q -e -Wl,-rpath &&
            cc -std=c11 '$ROOT/tests-install/trace_case.c' \$(pkg-config --cflags --libs fricont) -o nr_plain &&
            { ! ./nr_plain '$CASE' 2> nr.err; } && grep -q 'libfricont.so.$ABI: cannot open shared object file' nr.err &&
            LD_LIBRARY_PATH='$P2/lib' ./nr_plain '$CASE' > nr_ld.txt && cmp nr_ld.txt ref.txt &&
            cc -std=c11 '$ROOT/tests-install/trace_case.c' \$(pkg-config --cflags --libs fricont) \
                -Wl,-rpath,\$(pkg-config --variable=libdir fricont) -o nr_rpath &&
            ./nr_rpath '$CASE' > nr_rpath.txt && cmp nr_rpath.txt ref.txt"
fi

# --- CMake find_package ---------------------------------------------------------------
run_check "CMake find_package(fricont 0.1): configure and build" \
    bash -c "cmake -S '$ROOT/tests-install/cmake-consumer' -B cm -DCMAKE_PREFIX_PATH='$PREFIX' \
        -DCMAKE_BUILD_TYPE=Release -DFRICONT_EXAMPLE_SOURCE='$ROOT/examples-c/q1_rectangle.c' &&
        cmake --build cm"
if [ -x cm/trace_case_shared ]; then
    run_check "CMake fricont::fricont links the installed libfricont.so.$ABI" \
        uses_installed cm/trace_case_shared
    run_check "CMake fricont::fricont: events equal the build tree's" \
        bash -c "cm/trace_case_shared '$CASE' > cms.txt && cmp cms.txt ref.txt"
fi
if [ -x cm/trace_case_static ]; then
    run_check "CMake fricont::fricont_static: no libfricont.so needed" \
        bash -c "! readelf -d cm/trace_case_static | grep -q 'NEEDED.*libfricont'"
    run_check "CMake fricont::fricont_static: events equal the build tree's" \
        bash -c "cm/trace_case_static '$CASE' > cmst.txt && cmp cmst.txt ref.txt"
fi
if [ -x cm/example_shared ]; then
    run_check "CMake build of examples-c/q1_rectangle.c runs" \
        bash -c "cm/example_shared > q1_cm.txt && { [ ! -f q1_tree.txt ] || cmp q1_cm.txt q1_tree.txt; }"
fi
version_probe() { # version_probe REQUEST -> prints FOUND or NOTFOUND
    mkdir -p "vp_$1"
    printf 'cmake_minimum_required(VERSION 3.16)\nproject(vp NONE)\nfind_package(fricont %s QUIET)\nif(fricont_FOUND)\n  message(STATUS "probe:FOUND")\nelse()\n  message(STATUS "probe:NOTFOUND")\nendif()\n' \
        "$1" >"vp_$1/CMakeLists.txt"
    cmake -S "vp_$1" -B "vp_$1/b" -DCMAKE_PREFIX_PATH="$PREFIX" 2>&1 | sed -n 's/.*probe:\(.*\)/\1/p'
}
run_check "fricontConfigVersion: $VERSION EXACT found, $MAJOR.$((MINOR + 1)) and $((MAJOR + 1)).0 refused" \
    bash -c "$(declare -f version_probe); PREFIX='$PREFIX';
        [ \"\$(version_probe '$VERSION EXACT')\" = FOUND ] &&
        [ \"\$(version_probe $MAJOR.$((MINOR + 1)))\" = NOTFOUND ] &&
        [ \"\$(version_probe $((MAJOR + 1)).0)\" = NOTFOUND ]"

# --- The installed CLI agrees with the C interface ---------------------------------------
need_cmd python3 python3 || true
run_check "installed bin/fricont --version is $VERSION" \
    bash -c "[ \"\$('$PREFIX/bin/fricont' --version)\" = 'fricont $VERSION' ]"
run_check "installed bin/fricont trace --json: same events as the C interface" \
    bash -c "'$PREFIX/bin/fricont' trace '$CASE' --json cli.json > /dev/null &&
        python3 '$ROOT/tests-install/cjson_events.py' cli.json > cli.txt &&
        source '$ROOT/tests-install/common.sh' && compare_events ref.txt cli.txt"
finish
