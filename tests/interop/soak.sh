#!/usr/bin/env bash
# Soak (not a test: not part of `cargo test`): the node under sustained load for a bounded time in a
# private network namespace (loopback only), its resident memory sampled; fails if it grows.
# Load (tests/interop/load_peer.py --bad): probes at 4 kHz on /rotor_twin/probe, a PointStamped
# probe at 100 Hz, the speed ramped 400 → 900 → 400 rad/s every 60 s at 100 Hz, every 100th speed
# NaN, every 1000th stamped 1 h ahead, a malformed sample on each input every 2 s; the node records
# everything to a bag.
# Usage (as root): bash tests/interop/soak.sh [--minutes N] [--model nonlinear|linear] [--out DIR]
#                  [--no-record] [--bin PATH] [--record-max-bag-size BYTES]
# Prints the RSS samples' summary; DIR/rss.csv has them all (seconds, kB), DIR/peer.json the peer's
# counts. Flat means: the RSS at the end is within 5 % of the RSS after 6 minutes of warm-up
# (1 minute if the run is shorter than 10), and the least-squares slope over the second half of
# the run is below 0.1 % of that RSS per minute. The warm-up is the time the node's input readers
# take to fill their history (KeepLast 20,000 samples a topic, src/topics.rs: 200 s for the speed
# and the point probe at 100 Hz, 5 s for the probes at 4 kHz); from then on they hold at most that
# (measured without recording: 90.2 MiB at 360 s, 90.3 MiB at 602 s).
# --bin PATH: the rotor-twin binary to run (default target/release/rotor-twin; a copy lets you
# rebuild while a soak runs). --record-max-bag-size BYTES: the node's file size limit of the
# recording (its default, 256 MiB, if absent; 0: one file).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
minutes=30; model=nonlinear; out=""; record=1; bin="$root/target/release/rotor-twin"; max_size=""
while [ $# -gt 0 ]; do
  case "$1" in
    --minutes) minutes="$2"; shift 2 ;;
    --model) model="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --no-record) record=0; shift ;;
    --bin) bin="$2"; shift 2 ;;
    --record-max-bag-size) max_size="$2"; shift 2 ;;
    *) echo "soak.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -n "$out" ] || out="$(mktemp -d)"
mkdir -p "$out"
if [ -z "${ROTOR_TWIN_SOAK_INSIDE:-}" ]; then
  py="$(bash "$root/tests/interop/setup-venv.sh")/bin/python"
  [ -x "$bin" ] || (cd "$root" && cargo build --release)
  # every DDS participant in a private network namespace with loopback only
  exec env ROTOR_TWIN_SOAK_INSIDE=1 SOAK_PY="$py" SOAK_BIN="$bin" unshare -n \
    bash "$0" --minutes "$minutes" --model "$model" --out "$out" $([ "$record" = 1 ] || echo --no-record) \
    $([ -z "$max_size" ] || echo --record-max-bag-size "$max_size")
fi
ip link set lo up
seconds=$(python3 -c "print(int(float('$minutes') * 60))")
rec_args=(); [ "$record" = 1 ] && { rm -rf "$out/bag"; rec_args=(--record "$out/bag"); }
[ "$record" = 1 ] && [ -n "$max_size" ] && rec_args+=(--record-max-bag-size "$max_size")
"$SOAK_BIN" node "${rec_args[@]}" --ros-args -p model:="$model" \
  -p probe_point_topics:=probe_pulley_end=/plant/probe_b > "$out/node.out" 2> "$out/node.err" &
node=$!
sleep 2
"$SOAK_PY" "$root/tests/interop/load_peer.py" "$seconds" --bad --ramp 400:900:60 \
  > "$out/peer.json" 2> "$out/peer.err" &
peer=$!
echo "seconds,rss_kB" > "$out/rss.csv"
t0=$(date +%s)
while kill -0 "$peer" 2> /dev/null; do
  rss=$(awk '/^VmRSS/ {print $2}' "/proc/$node/status" 2> /dev/null || echo "")
  [ -n "$rss" ] || { echo "soak: the node is gone" >&2; break; }
  echo "$(( $(date +%s) - t0 )),$rss" >> "$out/rss.csv"
  sleep 10
done
wait "$peer" || echo "soak: peer exit $?" >&2
hwm=$(awk '/^VmHWM/ {print $2}' "/proc/$node/status" 2> /dev/null || echo 0)
kill -INT "$node"
node_rc=0; wait "$node" || node_rc=$?
echo "node exit $node_rc, peak RSS (VmHWM) $hwm kB" | tee -a "$out/node.err"
python3 - "$out" "$minutes" "$node_rc" <<'PY'
import csv, json, sys
out, minutes, node_rc = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
rows = [(int(r["seconds"]), int(r["rss_kB"])) for r in csv.DictReader(open(f"{out}/rss.csv"))]
warm = 360 if minutes >= 10 else 60
after = [r for r in rows if r[0] >= warm]
peer = json.load(open(f"{out}/peer.json"))
if len(after) < 3:
    sys.exit("soak: too few RSS samples after the warm-up")
base, end = after[0][1], after[-1][1]
half = [r for r in after if r[0] >= (after[0][0] + after[-1][0]) / 2]
n = len(half)
mx = sum(t for t, _ in half) / n; my = sum(v for _, v in half) / n
slope = sum((t - mx) * (v - my) for t, v in half) / sum((t - mx) ** 2 for t, _ in half) * 60
print(f"soak {minutes:g} min: RSS {rows[0][1] / 1024:.1f} MiB at {rows[0][0]} s, {base / 1024:.1f} MiB after "
      f"{warm} s warm-up, {end / 1024:.1f} MiB at the end ({100 * (end - base) / base:+.2f} %), max "
      f"{max(v for _, v in rows) / 1024:.1f} MiB; slope over the second half {slope:+.1f} kB/min "
      f"({100 * slope / base:+.3f} %/min); {len(rows)} samples")
print(f"load: {peer['sent_speeds']} speeds, {peer['sent_probes']} probes "
      f"({peer['sent_probes'] / (minutes * 60):.0f} /s), {peer['sent_points']} points, "
      f"{peer['malformed']} malformed; {peer['journal']} journal states, "
      f"{peer['nonfinite']} non-finite")
flat = abs(end - base) <= 0.05 * base and abs(slope) <= 0.001 * base
ok = flat and peer["nonfinite"] == 0 and node_rc == 0
print("soak: " + ("flat" if flat else "RSS NOT FLAT") + ("" if ok else " — FAILED"))
sys.exit(0 if ok else 1)
PY
