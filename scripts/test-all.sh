#!/usr/bin/env bash
# Runs every test of fricont: formatting and lints, the Rust tests (unit, integration,
# header freshness), the C tests against the CHOLMOD reference, and the bindings.
# Installs what it needs (Debian packages) when missing. Exits non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."

need_pkgs=()
have_pkg() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
for p in libsuitesparse-dev valgrind pkg-config cmake patchelf gfortran octave liboctave-dev; do
  have_pkg "$p" || need_pkgs+=("$p")
done
if ((${#need_pkgs[@]})); then
  echo "== installing: ${need_pkgs[*]}"
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need_pkgs[@]}" >/dev/null
fi

echo "== cargo fmt --check"
cargo fmt --check
echo "== cargo clippy --all-targets -- -D warnings"
cargo clippy --release --all-targets -q -- -D warnings
echo "== cargo test --release"
cargo test --release
echo "== cargo build --release (library, CLI)"
cargo build --release -q

for suite in c-tests/run.sh cpp-tests/run.sh fortran/run.sh matlab/run.sh tests-install/run.sh; do
  echo "== $suite"
  bash "$suite"
done
echo "== all test suites passed"
