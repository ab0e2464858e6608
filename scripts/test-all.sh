#!/usr/bin/env bash
# Runs every test of fricont: formatting and lints, the Rust tests (unit, integration,
# header freshness), the C tests against the CHOLMOD reference, the distributed example
# (PETSc + MUMPS over 2 MPI ranks), and the bindings.
# Installs what it needs (Debian packages) when missing. Exits non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."

need_pkgs=()
have_pkg() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
for p in libsuitesparse-dev valgrind pkg-config cmake patchelf gfortran octave liboctave-dev \
  libpetsc-real-dev openmpi-bin libopenmpi-dev; do
  have_pkg "$p" || need_pkgs+=("$p")
done
# Debian's python3 needs python3-venv for `python3 -m venv` (a pyenv or python.org build has it).
python3 -c "import ensurepip" 2>/dev/null || need_pkgs+=(python3-venv)
if ((${#need_pkgs[@]})); then
  echo "== installing: ${need_pkgs[*]}"
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need_pkgs[@]}" >/dev/null
fi

echo "== cargo fmt --check"
cargo fmt --check
echo "== cargo clippy --workspace --all-targets -- -D warnings"
cargo clippy --release --workspace --all-targets -q -- -D warnings
echo "== cargo test --release"
cargo test --release
echo "== cargo build --release (library, CLI)"
cargo build --release -q

for suite in c-tests/run.sh examples-c/petsc-mumps/run.sh cpp-tests/run.sh fortran/run.sh matlab/run.sh \
  tests-install/run.sh; do
  echo "== $suite"
  bash "$suite"
done
echo "== python: build the package into a virtual environment (target/pyenv), run pytest"
PYENV="$PWD/target/pyenv"
[ -x "$PYENV/bin/python" ] || python3 -m venv "$PYENV"
"$PYENV/bin/python" -c "import maturin, numpy, scipy, skfem, matplotlib, pytest" 2>/dev/null ||
  "$PYENV/bin/pip" install -q maturin numpy scipy scikit-fem matplotlib pytest
# The wheel is built with the workspace's target directory (artefacts shared with the
# release build above) and without build isolation (maturin is in the environment).
PATH="$PYENV/bin:$PATH" CARGO_TARGET_DIR="$PWD/target" "$PYENV/bin/pip" install -q --no-build-isolation ./python
PATH="$PYENV/bin:$PATH" "$PYENV/bin/pytest" -q -p no:cacheprovider python/tests
echo "== all test suites passed"
