#!/usr/bin/env bash
# Latency benchmark (not a test): speed message → first journal state that reflects it, through
# an independent Cyclone DDS peer, in a private network namespace. Usage (as root):
#   bash tests/interop/latency.sh [SAMPLES] [MODEL]
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
samples="${1:-200}"; model="${2:-nonlinear}"
py="$(bash "$root/tests/interop/setup-venv.sh")/bin/python"
bin="$root/target/release/rotor-twin"
[ -x "$bin" ] || (cd "$root" && cargo build --release)
unshare -n bash -c "ip link set lo up
  '$bin' node --ros-args -p model:=$model -p state_rate_hz:=1000 > /dev/null 2>&1 &
  node=\$!
  sleep 1
  '$py' '$root/tests/interop/latency.py' $samples
  kill -INT \$node; wait \$node"
