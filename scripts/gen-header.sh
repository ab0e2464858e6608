#!/usr/bin/env bash
# Regenerates include/fricont.h from src/ffi/ with the cbindgen library pinned in
# Cargo.toml (dev-dependency) and cbindgen.toml. Commit the result: the test
# `cargo test --release --test header` fails while the committed header is stale.
set -euo pipefail
cd "$(dirname "$0")/.."
UPDATE_HEADER=1 cargo test --release --test header -- --quiet
echo "wrote include/fricont.h"
