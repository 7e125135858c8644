#!/usr/bin/env bash
# Runs every fuzz target (or those named) for a fixed number of executions (default
# 1 000 000 each):
#   bash tests-host/fuzz/run.sh [RUNS [TARGET...]]
# Needs a nightly toolchain (installed here with rustup if missing) and cargo-fuzz. Each
# target starts from its seed corpus in corpus/<target>/ (new inputs the fuzzer finds go to
# target/fuzz-corpus/, not into the repository). A crash stops the run and leaves its input
# in artifacts/<target>/: fix it, then copy the input to regressions/<target>/ so that the
# test command replays it from then on.
set -euo pipefail
runs=${1:-1000000}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(csv_reader mcap_reader core_pipeline)
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
cd "$here"
rustup toolchain list | grep -q '^nightly' || rustup toolchain install nightly --profile minimal
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
for t in "${targets[@]}"; do
  work="$here/target/fuzz-corpus/$t"
  mkdir -p "$work"
  echo "== $t: $runs executions"
  # The core's inputs are kept to 8 KiB (630 samples, 3 s at 200 Hz: a few strides and gaps)
  # so that 10⁶ executions take minutes, not an hour; the readers get 64 KiB.
  max_len=65536
  [ "$t" = core_pipeline ] && max_len=8192
  cargo +nightly fuzz run "$t" "$work" "corpus/$t" -- -runs="$runs" -max_len="$max_len" -timeout=10 2>&1 |
    tee "$here/target/fuzz-$t.log" | grep -E '^(#[0-9]+ +(DONE|INITED)|Done|==[0-9]+==|SUMMARY|artifact)' || true
  # libFuzzer's last status line: executions done and the coverage reached.
  grep -E '^Done [0-9]+ runs' "$here/target/fuzz-$t.log"
done
