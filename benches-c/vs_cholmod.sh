#!/usr/bin/env bash
# The whole `fricont trace DIR --json` process against CHOLMOD reading and factorising the
# same A.mtx, alternately, ROUNDS times (default 3), and the ratios of each round
# (issue 11's acceptance: whole trace <= 2x CHOLMOD read + factor; set-up <= 1.5x CHOLMOD's
# factorisation). Needs libsuitesparse-dev and a release build of the CLI.
#
#   bash benches-c/vs_cholmod.sh /tmp/fricont-bench-setup/rect-481x321 [ROUNDS]
#
# (`cargo bench --bench setup` generates that directory.)
set -euo pipefail
dir=${1:?usage: vs_cholmod.sh DIR [ROUNDS]}
rounds=${2:-3}
root=$(cd "$(dirname "$0")/.." && pwd)
exe="${CARGO_TARGET_DIR:-$root/target}/release/fricont"
[ -x "$exe" ] || cargo build --release -p fricont-cli --manifest-path "$root/Cargo.toml"
ref=$(mktemp -d)/cholmod_setup_time
cc -O2 -I/usr/include/suitesparse "$root/benches-c/cholmod_setup_time.c" -lcholmod -o "$ref"
json=$(mktemp)
for r in $(seq "$rounds"); do
    c=$("$ref" "$dir" | awk '/cholmod read_s/ {print $3, $5 + $7, $3 + $5 + $7}')
    read -r c_read c_fact c_all <<<"$c"
    t0=$(date +%s.%N)
    out=$("$exe" trace "$dir" --json "$json" | tail -1)
    t1=$(date +%s.%N)
    f_all=$(echo "$t1 - $t0" | bc -l)
    f_setup=$(echo "$out" | sed -n 's/.*setup \([0-9.]*\) s.*/\1/p')
    printf 'round %d: CHOLMOD read %.2f s, read+analyse+factorise %.2f s | fricont trace --json %.2f s (set-up %.2f s) | whole/CHOLMOD %.2f, set-up/CHOLMOD analyse+factorise %.2f\n' \
        "$r" "$c_read" "$c_all" "$f_all" "$f_setup" "$(echo "$f_all / $c_all" | bc -l)" "$(echo "$f_setup / $c_fact" | bc -l)"
done
rm -f "$json"
