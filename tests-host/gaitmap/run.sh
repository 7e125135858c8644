#!/usr/bin/env bash
# Runs bench_gaitmap.py in a virtual environment of its own (made and filled from PyPI on
# first use, under tests-host/target/) and passes its arguments on.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
venv="$here/../target/gaitmap-venv"
if [ ! -x "$venv/bin/python" ] || ! cmp -s "$here/requirements.txt" "$venv/requirements.txt"; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet --disable-pip-version-check -r "$here/requirements.txt" >&2
  cp "$here/requirements.txt" "$venv/requirements.txt"
fi
exec "$venv/bin/python" "$here/bench_gaitmap.py" "$@"
