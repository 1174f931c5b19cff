#!/usr/bin/env bash
# Creates tests/.venv-ross with ROSS (PyPI ross-rotordynamics, needs Python >= 3.13) for
# tests/interop/ross_plain_journal.py; prints the venv's path. Not used by `cargo test`.
# PYTHON may name a Python 3.13 interpreter (default: python3.13).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
venv="$here/.venv-ross"
exec 9>"$here/.venv-ross.lock"
flock 9
if [ ! -x "$venv/bin/python" ]; then
  "${PYTHON:-python3.13}" -m venv "$venv"
fi
if [ ! -f "$venv/.complete" ]; then
  "$venv/bin/pip" install --quiet --disable-pip-version-check "ross-rotordynamics==3.1.0"
  touch "$venv/.complete"
fi
echo "$venv"
