#!/usr/bin/env bash
# Runs every check of gaitclip, as CI does: formatting and clippy (-D warnings) in every
# workspace, the core's and the board glue's unit tests and docs on the host, release builds
# of every board (QEMU mps2-an386 and micro:bit, nRF52840-DK, its Bluetooth foot pod, Raspberry
# Pi Pico) and of the
# benchmark for both Cortex-M targets, and the host test suite (driver transactions, fixed
# point vs f64, fixtures, MCAP/CSV readers and the MCAP conformance files, bus faults, gaps,
# jitter and saturation, property tests, the fuzz corpus and regressions, real datasets when
# ../shared/datasets is present, the bit-exact QEMU runs of the M4 and M0 firmware, and the instruction counts of
# the cost benchmark), the Bluetooth foot pod against Bumble, and the Python wheel (python/)
# with its pytest suite beside gaitmap. The cost figures themselves come from tests-host/cost.sh.
# Installs what a fresh Debian machine lacks: qemu-system-arm, libclang and clang (apt) and
# flip-link (cargo).
# rustup installs the toolchain, targets and components named in rust-toolchain.toml; where
# that toolchain is already installed without them, rustup does not add them on its own, so
# the script asks it to (quick and idempotent when everything is there).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

echo "== toolchain: $(grep '^channel' rust-toolchain.toml) with its targets and components"
rustup toolchain install

bash "$root/boards/install-qemu"
# The Bluetooth firmware's bindgen needs libclang and clang.
bash "$root/boards/install-clang"
# The boards link through flip-link (stack-overflow protection); cargo installs it.
command -v flip-link >/dev/null 2>&1 || cargo install --locked flip-link

echo "== core library and board glue on the host: rustfmt, clippy, unit tests, docs"
cargo fmt --all --check
cargo clippy --all-targets -- -D warnings
log=$(mktemp)
cargo test 2>&1 | tee "$log"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps

echo "== firmware: clippy and release builds of every board and the benchmark, each for its target(s)"
# Every folder under boards/ with a .cargo/config.toml is a firmware package: built from its
# folder, it builds for the target(s) that file names (the benchmark for both).
for dir in "$root"/boards/*/; do
  [ -f "$dir/.cargo/config.toml" ] || continue
  echo "-- ${dir#"$root"/}"
  (cd "$dir" && cargo clippy --release -- -D warnings && cargo build --release)
done
cargo clippy --release -p gaitclip -p gaitclip-mpu6050 --target thumbv6m-none-eabi -- -D warnings

echo "== tests-host (and the qemu-insn-count plugin): rustfmt, clippy, tests"
cd "$root/tests-host"
cargo fmt --check
# The fuzz targets are their own workspace, built by cargo-fuzz on nightly (fuzz/run.sh); their
# bodies are in src/fuzzing.rs and their corpus is replayed by tests/fuzz_corpus.rs below.
cargo fmt --check --manifest-path fuzz/Cargo.toml
cargo clippy --workspace --all-targets -- -D warnings
cargo test --workspace 2>&1 | tee -a "$log"

echo "== Bluetooth: the foot pod (gaitclip pod) against Bumble's virtual controller and a Bumble central (pytest)"
# Bumble, pytest and what they pull in, pinned, in a venv of the project's own.
venv="$root/tests-host/target/ble-venv"
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install --quiet --disable-pip-version-check -r "$root/tests-host/ble/requirements.txt"
# The binary the cargo tests above built.
GAITCLIP="$root/tests-host/target/$(rustc -vV | sed -n 's/^host: //p')/debug/gaitclip" \
  "$venv/bin/python" -m pytest -q -p no:cacheprovider "$root/tests-host/ble" 2>&1 | tee -a "$log"

echo "== Python: the gaitclip wheel (PyO3, maturin) and its tests (pytest, gaitmap beside it)"
# maturin, pytest, pandas and gaitmap, pinned, in a venv of the project's own.
pyvenv="$root/tests-host/target/py-venv"
[ -x "$pyvenv/bin/python" ] || python3 -m venv "$pyvenv"
"$pyvenv/bin/pip" install --quiet --disable-pip-version-check -r "$root/python/requirements-test.txt"
# gaitmap's example-data loader downloads from GitHub; its sdist on PyPI carries the same
# files, which go where the loader looks first (GAITMAP_DATA_DIR/v<version>).
gmdata="$root/tests-host/target/gaitmap-data"
gmversion=$("$pyvenv/bin/python" -c 'import importlib.metadata as m; print(m.version("gaitmap"))')
if [ ! -f "$gmdata/v$gmversion/imu_sample.csv" ]; then
  "$pyvenv/bin/pip" download --quiet --disable-pip-version-check --no-binary :all: --no-deps \
    "gaitmap==$gmversion" -d "$gmdata/sdist"
  mkdir -p "$gmdata/v$gmversion"
  tar -xzf "$gmdata/sdist/gaitmap-$gmversion.tar.gz" -C "$gmdata/sdist"
  cp "$gmdata/sdist/gaitmap-$gmversion/example_data/"*.csv "$gmdata/v$gmversion/"
fi
# The wheel, built by maturin from this workspace in the dev profile (the crates the tests
# above compiled; `pip install ./python` builds the release one) and installed over any
# earlier one.
PATH="$pyvenv/bin:$PATH" MATURIN_PEP517_ARGS="--profile dev" \
  "$pyvenv/bin/pip" install --quiet --disable-pip-version-check --no-build-isolation \
  --no-deps --force-reinstall "$root/python"
GAITCLIP="$root/tests-host/target/$(rustc -vV | sed -n 's/^host: //p')/debug/gaitclip" \
  GAITMAP_DATA_DIR="$gmdata" \
  "$pyvenv/bin/python" -m pytest -q -p no:cacheprovider "$root/python/tests" 2>&1 | tee -a "$log"

# One closing line over every test binary and the pytest run.
awk '/^test result:/ { for (i = 1; i <= NF; i++) { if ($(i) ~ /^passed/) p += $(i-1); if ($(i) ~ /^failed/) f += $(i-1) } }
     /^[0-9]+ (passed|failed)/ && / in [0-9.]+s/ { for (i = 1; i <= NF; i++) { if ($(i) ~ /^passed/) p += $(i-1); if ($(i) ~ /^failed/) f += $(i-1) } }
     END { printf "tests: %d passed, %d failed\n", p, f }' "$log"
rm -f "$log"
