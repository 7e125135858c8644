#!/usr/bin/env bash
# Measures what gaitclip costs and prints it as Markdown (the README's cost tables):
# instructions per sample and per stride on the emulated Cortex-M4 and M0 (QEMU with the
# qemu-insn-count plugin), flash / static RAM / stack of every firmware build, and host
# replay throughput (criterion) next to gaitmap's pipeline on the same real trace.
# Installs what a fresh Debian machine lacks: qemu-system-arm (apt), flip-link (cargo),
# gaitmap (PyPI, into tests-host/target/gaitmap-venv). Needs ../shared/datasets.
# Progress goes to stderr; the report alone to stdout.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash boards/install-qemu >&2
bash boards/install-clang >&2
command -v flip-link >/dev/null 2>&1 || cargo install --locked flip-link >&2

datasets=$(cd "$root/.." && pwd)/shared/datasets
[ -d "$datasets" ] || { echo "cost: $datasets is missing (the real trace is read from there)" >&2; exit 2; }
trace="$datasets/gaitmap_walk/left.csv"

cd "$root/tests-host"
host=$(rustc -vV | sed -n 's/^host: //p')
mkdir -p target/cost
echo "== building the instruction-count plugin" >&2
cargo build --release --quiet -p qemu-insn-count >&2
echo "== host replay benchmark (criterion)" >&2
cargo bench --bench replay -- --noplot >&2
echo "== gaitmap on the same trace" >&2
bash gaitmap/run.sh "$trace" 204.8 5 > target/cost/gaitmap.json
echo "== instruction counts, sizes, stacks" >&2
report=$(cargo run --release --quiet --bin gaitclip -- cost \
  --plugin "target/$host/release/libqemu_insn_count.so" \
  --criterion target/criterion/replay/gaitmap_walk_left/new/estimates.json \
  --gaitmap target/cost/gaitmap.json \
  --datasets "$datasets")

cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)
echo "Measured on $(date -u +%Y-%m-%d) on ${cpu:-$(uname -m)} ($(nproc) cores, $(uname -m)); $(rustc --version | cut -d' ' -f1-2); $(qemu-system-arm --version | head -1 | sed 's/ (.*//'); $(python3 --version)."
echo
echo "$report"
