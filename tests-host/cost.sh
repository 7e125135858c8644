#!/usr/bin/env bash
# Measures what gaitclip costs and prints it as Markdown (docs/cost.md's tables):
# instructions per sample and per stride on the emulated Cortex-M4 and M0 (QEMU with the
# qemu-insn-count plugin), flash / static RAM / stack of every firmware build, and host
# replay throughput (criterion) next to gaitmap's pipeline on the same real trace.
# Installs what a fresh Debian machine lacks: qemu-system-arm (apt), flip-link (cargo),
# gaitmap (PyPI, into tests-host/target/gaitmap-venv). Needs ../shared/datasets.
# Progress goes to stderr; the report alone to stdout.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
# The pinned toolchain with its Cortex-M targets: rustup adds them only when it installs the
# toolchain, not to one already there without them (as test-all.sh and `cargo emulate` do).
rustup toolchain install >&2
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

# A week at 100 Hz through `gaitclip replay` (a CSV streams in constant memory): 60 M samples
# of `ipol_gait_events`' walks, one after another on a clean 100 Hz clock, generated here
# (≈ 4.5 GB, deleted after) and replayed under GNU time for the peak resident memory.
echo "== a week at 100 Hz in constant memory (60 M samples)" >&2
if [ ! -x /usr/bin/time ]; then
  echo "GNU time is missing; installing it from Debian (apt-get install time)" >&2
  sudo_cmd=""; [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get install -y -qq time >&2
fi
week="$root/tests-host/target/cost/week.csv"
long_samples=60000000
python3 - "$datasets/ipol_gait_events" "$week" "$long_samples" <<'PY'
import glob, os, sys
src, out, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
rows = []
for f in sorted(glob.glob(os.path.join(src, "*.csv"))):
    if os.path.basename(f) in ("events.csv", "trials.csv"):
        continue
    with open(f) as fh:
        next(fh)
        rows.extend(line.rstrip("\n").split(",", 1)[1] for line in fh)
with open(out, "w") as o:
    o.write("t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n")
    block = 100_000
    for a in range(0, n, block):
        o.write("".join(f"{i / 100!r},{rows[i % len(rows)]}\n" for i in range(a, min(n, a + block))))
PY
week_bytes=$(stat -c %s "$week")
long_out=$(mktemp)
/usr/bin/time -f "%M %e" -o "$long_out" "target/$host/release/gaitclip" replay --json "$week" \
  | tail -1 > target/cost/week-summary.json
read -r long_kb long_s < "$long_out"
# The same walks as MCAP: the week's first day (8.64 M samples) written by `replay
# --mcap-out` (gaitclip's JSON IMU messages; that replay reads whole), then replayed.
day="$root/tests-host/target/cost/day.csv"
day_mcap="$root/tests-host/target/cost/day.mcap"
day_samples=8640000
head -n $((day_samples + 1)) "$week" > "$day"
rm -f "$week"
"target/$host/release/gaitclip" replay "$day" --mcap-out "$day_mcap" > /dev/null
rm -f "$day"
day_bytes=$(stat -c %s "$day_mcap")
/usr/bin/time -f "%M %e" -o "$long_out" "target/$host/release/gaitclip" replay --json "$day_mcap" \
  | tail -1 > target/cost/day-summary.json
read -r day_kb day_s < "$long_out"
rm -f "$day_mcap" "$long_out"
long_strides=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["summary"]["strides"])' target/cost/week-summary.json)
day_strides=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["summary"]["strides"])' target/cost/day-summary.json)

cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)
out=$(mktemp)
{
echo "Measured on $(date -u +%Y-%m-%d) on ${cpu:-$(uname -m)} ($(nproc) cores, $(uname -m)); $(rustc --version | cut -d' ' -f1-2); $(qemu-system-arm --version | head -1 | sed 's/ (.*//'); $(python3 --version)."
echo
echo "$report"
echo
echo "### Constant memory"
echo
echo "\`gaitclip replay --json\` of a week at 100 Hz: $long_samples samples of \`ipol_gait_events\`' walks one after another on a clean clock, a $((week_bytes / 1000000)) MB CSV; and of its first day written as MCAP, a $((day_bytes / 1000000)) MB file (the spool beside each, 64 bytes a sample: its first 8 MiB in memory, the rest on disk):"
echo
echo "| recording | samples | strides | peak resident memory | wall time | samples/s |"
echo "|---|---:|---:|---:|---:|---:|"
row='import sys; f,n,k,kb,s=sys.argv[1],int(sys.argv[2]),sys.argv[3],int(sys.argv[4]),float(sys.argv[5]); print(f"| {f} | {n} | {k} | {kb/1024:.1f} MiB | {s:.1f} s | {n/s:,.0f} |".replace(",", " "))'
python3 -c "$row" "a week (CSV)" "$long_samples" "$long_strides" "$long_kb" "$long_s"
python3 -c "$row" "a day (MCAP)" "$day_samples" "$day_strides" "$day_kb" "$day_s"
} > "$out"
cat "$out"
# The tables go into docs/cost.md between its markers: re-measuring is this command, not an
# edit. (They hold times, so no staleness test checks them; docs/cost.md says when.)
python3 - "$root/docs/cost.md" "$out" <<'PY'
import sys
page, out = sys.argv[1], open(sys.argv[2]).read().rstrip("\n")
text = open(page).read()
open_m, close_m = "<!-- written: bash tests-host/cost.sh -->", "<!-- end written -->"
a, b = text.index(open_m) + len(open_m), text.index(close_m)
open(page, "w").write(text[:a] + "\n" + out + "\n" + text[b:])
PY
echo "cost: wrote docs/cost.md" >&2
