#!/usr/bin/env bash
# Installs fricont under PREFIX:
#   PREFIX/bin/fricont                         the command line (crate fricont-cli)
#   PREFIX/lib/libfricont.so.X.Y.Z             soname libfricont.so.ABI, with the links
#                                              PREFIX/lib/libfricont.so.ABI and .../libfricont.so
#   PREFIX/lib/libfricont.a
#   PREFIX/include/fricont.h, fricont.hpp
#   PREFIX/lib/pkgconfig/fricont.pc
#   PREFIX/lib/cmake/fricont/fricontConfig.cmake, fricontConfigVersion.cmake
#   PREFIX/share/fricont/fortran/fricont.f90   the Fortran module (compile it with your
#                                              code: .mod files are per compiler)
#   PREFIX/share/fricont/matlab/               the MEX gateway, the .m functions, examples/
#   PREFIX/share/doc/fricont/                  README.md, CHANGELOG.md, LICENSE-MIT,
#                                              LICENSE-APACHE, docs/, examples/ (C, C++)
#
# The installed libraries and program are stripped (cargo's release profile keeps line
# tables for backtraces: libfricont.so is 19.7 MB as built, 3.9 MB stripped);
# FRICONT_INSTALL_DEBUG=1 installs them as built.
#
# Finding the library at run time: pkg-config's `Libs` carries -Wl,-rpath,PREFIX/lib
# (so `cc app.c $(pkg-config --cflags --libs fricont)` runs from any PREFIX without
# LD_LIBRARY_PATH), except for PREFIX=/usr, where the loader looks anyway;
# FRICONT_INSTALL_RPATH=0 leaves it out (then use ldconfig or LD_LIBRARY_PATH, see
# docs/bindings.md). As root, when PREFIX/lib is one of the loader's directories
# (/usr/local/lib on Debian), ldconfig is run to update its cache.
#
# ABI is the major version, or 0.MINOR before 1.0 (0.x releases may break the ABI; the
# rule of cargo-c). The soname is set on the installed copy with patchelf (Debian:
# apt-get install patchelf); target/release/libfricont.so itself keeps none, so that
# programs linked against the build tree keep finding it there.
#
# Usage: scripts/install.sh PREFIX      (FRICONT_NO_BUILD=1 skips cargo build)
set -euo pipefail
if [ $# -ne 1 ]; then
    echo "usage: scripts/install.sh PREFIX" >&2
    exit 2
fi
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PREFIX=$1
mkdir -p "$PREFIX"
PREFIX=$(cd "$PREFIX" && pwd)

for tool in patchelf strip; do
    if ! command -v "$tool" >/dev/null 2>&1; then
        echo "install.sh: $tool is needed (apt-get install patchelf binutils)" >&2
        exit 1
    fi
done
if [ "${FRICONT_NO_BUILD:-0}" != 1 ]; then
    # The whole workspace, as the README and scripts/test-all.sh build it: a narrower
    # selection (-p fricont -p fricont-cli) unifies dependency features differently and
    # would rebuild the library and the CLI each time one alternates with the other.
    (cd "$ROOT" && cargo build --release)
fi
LIB=${CARGO_TARGET_DIR:-$ROOT/target}/release
for f in "$LIB/libfricont.so" "$LIB/libfricont.a" "$LIB/fricont"; do
    [ -f "$f" ] || { echo "install.sh: $f is missing (cargo build --release)" >&2; exit 1; }
done

VERSION=$(sed -n 's/^version *= *"\([0-9.]*\)".*/\1/p' "$ROOT/Cargo.toml" | head -1)
MAJOR=${VERSION%%.*}
REST=${VERSION#*.}
MINOR=${REST%%.*}
if [ "$MAJOR" = 0 ]; then ABI=0.$MINOR; else ABI=$MAJOR; fi
# The system libraries a Rust static library needs on Linux (rustc --print
# native-static-libs for the GNU target).
NATIVE_LIBS="-lgcc_s -lutil -lrt -lpthread -lm -ldl -lc"
CMAKE_NATIVE_LIBS="gcc_s;util;rt;pthread;m;dl;c"
if [ "${FRICONT_INSTALL_RPATH:-1}" = 1 ] && [ "$PREFIX" != /usr ]; then
    RPATH_FLAG=' -Wl,-rpath,${libdir}'
else
    RPATH_FLAG=
fi

install -d "$PREFIX/bin" "$PREFIX/lib/pkgconfig" "$PREFIX/lib/cmake/fricont" "$PREFIX/include" \
    "$PREFIX/share/fricont/fortran" "$PREFIX/share/fricont/matlab/private" \
    "$PREFIX/share/fricont/matlab/examples" "$PREFIX/share/doc/fricont/docs" \
    "$PREFIX/share/doc/fricont/examples"
SO=$PREFIX/lib/libfricont.so.$VERSION
install -m 755 "$LIB/libfricont.so" "$SO"
install -m 755 "$LIB/fricont" "$PREFIX/bin/fricont"
install -m 644 "$LIB/libfricont.a" "$PREFIX/lib/libfricont.a"
if [ "${FRICONT_INSTALL_DEBUG:-0}" != 1 ]; then
    # As Debian's dh_strip does: shared library and program keep only the symbols
    # needed for linking, the static library loses its debug sections only.
    strip --strip-unneeded "$SO" "$PREFIX/bin/fricont"
    strip --strip-debug "$PREFIX/lib/libfricont.a"
fi
patchelf --set-soname "libfricont.so.$ABI" "$SO"
ln -sfn "libfricont.so.$VERSION" "$PREFIX/lib/libfricont.so.$ABI"
ln -sfn "libfricont.so.$ABI" "$PREFIX/lib/libfricont.so"
install -m 644 "$ROOT/include/fricont.h" "$ROOT/include/fricont.hpp" "$PREFIX/include/"
install -m 644 "$ROOT/fortran/fricont.f90" "$PREFIX/share/fricont/fortran/"
install -m 644 "$ROOT"/matlab/*.m "$ROOT/matlab/fricont_mex.c" "$PREFIX/share/fricont/matlab/"
install -m 644 "$ROOT"/matlab/private/*.m "$PREFIX/share/fricont/matlab/private/"
install -m 644 "$ROOT"/matlab/examples/*.m "$PREFIX/share/fricont/matlab/examples/"
install -m 644 "$ROOT/README.md" "$ROOT/CHANGELOG.md" "$ROOT/LICENSE-MIT" "$ROOT/LICENSE-APACHE" \
    "$PREFIX/share/doc/fricont/"
install -m 644 "$ROOT"/docs/*.md "$PREFIX/share/doc/fricont/docs/"
install -m 644 "$ROOT/examples-c/q1_rectangle.c" "$ROOT/examples-cpp/q1_rectangle.cpp" \
    "$PREFIX/share/doc/fricont/examples/"

subst() {
    sed -e "s|@PREFIX@|$PREFIX|g" -e "s|@VERSION@|$VERSION|g" -e "s|@MAJOR@|$MAJOR|g" \
        -e "s|@MINOR@|$MINOR|g" -e "s|@ABI@|$ABI|g" -e "s|@NATIVE_LIBS@|$NATIVE_LIBS|g" \
        -e "s|@CMAKE_NATIVE_LIBS@|$CMAKE_NATIVE_LIBS|g" -e "s|@RPATH_FLAG@|$RPATH_FLAG|g" "$1" >"$2"
    chmod 644 "$2"
}
subst "$ROOT/install/fricont.pc.in" "$PREFIX/lib/pkgconfig/fricont.pc"
subst "$ROOT/install/fricontConfig.cmake.in" "$PREFIX/lib/cmake/fricont/fricontConfig.cmake"
subst "$ROOT/install/fricontConfigVersion.cmake.in" \
    "$PREFIX/lib/cmake/fricont/fricontConfigVersion.cmake"

# The loader's cache: refreshed when PREFIX/lib is one of its directories and we may.
if command -v ldconfig >/dev/null 2>&1 &&
    ldconfig -v -N 2>/dev/null | grep -q "^$PREFIX/lib:"; then
    if [ "$(id -u)" = 0 ]; then ldconfig; else
        echo "install.sh: run 'sudo ldconfig' so that the loader finds libfricont.so.$ABI in $PREFIX/lib"
    fi
fi
echo "installed fricont $VERSION (soname libfricont.so.$ABI, $(du -sh "$SO" | cut -f1) library) under $PREFIX"
