#!/usr/bin/env bash
# Installs fricont under PREFIX:
#   PREFIX/lib/libfricont.so.X.Y.Z   (soname libfricont.so.ABI, with the links
#   PREFIX/lib/libfricont.so.ABI and PREFIX/lib/libfricont.so)
#   PREFIX/lib/libfricont.a
#   PREFIX/include/fricont.h, fricont.hpp
#   PREFIX/lib/pkgconfig/fricont.pc
#   PREFIX/lib/cmake/fricont/fricontConfig.cmake, fricontConfigVersion.cmake
#   PREFIX/share/fricont/fortran/fricont.f90   (the Fortran module, compile it with
#                                               your code: .mod files are per compiler)
#   PREFIX/share/fricont/matlab/               (the MEX gateway and the .m functions)
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

if ! command -v patchelf >/dev/null 2>&1; then
    echo "install.sh: patchelf is needed to set the soname (apt-get install patchelf)" >&2
    exit 1
fi
if [ "${FRICONT_NO_BUILD:-0}" != 1 ]; then
    (cd "$ROOT" && cargo build --release --lib)
fi
LIB=$ROOT/target/release
for f in "$LIB/libfricont.so" "$LIB/libfricont.a"; do
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

install -d "$PREFIX/lib/pkgconfig" "$PREFIX/lib/cmake/fricont" "$PREFIX/include" \
    "$PREFIX/share/fricont/fortran" "$PREFIX/share/fricont/matlab/private"
install -m 755 "$LIB/libfricont.so" "$PREFIX/lib/libfricont.so.$VERSION"
patchelf --set-soname "libfricont.so.$ABI" "$PREFIX/lib/libfricont.so.$VERSION"
ln -sfn "libfricont.so.$VERSION" "$PREFIX/lib/libfricont.so.$ABI"
ln -sfn "libfricont.so.$ABI" "$PREFIX/lib/libfricont.so"
install -m 644 "$LIB/libfricont.a" "$PREFIX/lib/libfricont.a"
install -m 644 "$ROOT/include/fricont.h" "$ROOT/include/fricont.hpp" "$PREFIX/include/"
install -m 644 "$ROOT/fortran/fricont.f90" "$PREFIX/share/fricont/fortran/"
install -m 644 "$ROOT"/matlab/*.m "$ROOT/matlab/fricont_mex.c" "$PREFIX/share/fricont/matlab/"
install -m 644 "$ROOT"/matlab/private/*.m "$PREFIX/share/fricont/matlab/private/"

subst() {
    sed -e "s|@PREFIX@|$PREFIX|g" -e "s|@VERSION@|$VERSION|g" -e "s|@MAJOR@|$MAJOR|g" \
        -e "s|@MINOR@|$MINOR|g" -e "s|@ABI@|$ABI|g" -e "s|@NATIVE_LIBS@|$NATIVE_LIBS|g" \
        -e "s|@CMAKE_NATIVE_LIBS@|$CMAKE_NATIVE_LIBS|g" "$1" >"$2"
    chmod 644 "$2"
}
subst "$ROOT/install/fricont.pc.in" "$PREFIX/lib/pkgconfig/fricont.pc"
subst "$ROOT/install/fricontConfig.cmake.in" "$PREFIX/lib/cmake/fricont/fricontConfig.cmake"
subst "$ROOT/install/fricontConfigVersion.cmake.in" \
    "$PREFIX/lib/cmake/fricont/fricontConfigVersion.cmake"
echo "installed fricont $VERSION (soname libfricont.so.$ABI) under $PREFIX"
