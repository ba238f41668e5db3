#!/usr/bin/env bash
# Runs every fuzz target for SECONDS (default 20) from its seed corpus
# (fuzz/seeds/TARGET) into a scratch corpus, with cargo-fuzz on the stable
# toolchain (RUSTC_BOOTSTRAP lets it pass the sanitizer flags; a nightly
# toolchain works too). Prints one line per target: executions and result.
# A crash stops the script with libFuzzer's report and the crashing input
# under fuzz/artifacts/TARGET/. Memory is limited to 2 GiB (resident, and
# any single allocation): the targets cap dense reads at 512 MiB
# (topovox_io::set_dense_read_budget), so a small file claiming a huge
# grid must be refused or read sparsely, never allocated.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH="${1:-20}"
cargo fuzz --version >/dev/null 2>&1 || cargo install cargo-fuzz --locked
export RUSTC_BOOTSTRAP=1
cargo fuzz build -O
scratch="$(mktemp -d)"
for t in $(cargo fuzz list); do
    mkdir -p "$scratch/$t"
    log="$scratch/$t.log"
    if ! cargo fuzz run -O "$t" "$scratch/$t" "fuzz/seeds/$t" -- -max_total_time="$SECONDS_EACH" -timeout=10 -rss_limit_mb=2048 >"$log" 2>&1; then
        tail -40 "$log"
        echo "fuzz target $t FAILED (input saved under fuzz/artifacts/$t)"
        exit 1
    fi
    runs="$(grep -o 'Done [0-9]* runs' "$log" | tail -1 | grep -o '[0-9]*' || echo '?')"
    echo "$t: $runs executions in ${SECONDS_EACH} s, no crash"
done
rm -rf "$scratch"
