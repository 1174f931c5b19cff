#!/usr/bin/env bash
# Issue 17: a long replay's wall time, real-time factor and peak memory (a script, not a test).
# Usage: tests/bench/replay_long_bag.sh SECONDS [WORKDIR] [BINARY]
# Writes a synthetic bag held at 9,000 rpm (developed whip after ≈ 6 s; 16 probe samples a
# revolution; reused if WORKDIR/bagSECONDS exists), replays it with --fast and the output bag
# written, and prints the bag's length, the messages, the wall time, the real-time factor and
# the peak RSS (/usr/bin/time -v).
set -euo pipefail
secs=${1:?seconds of bag}
work=${2:-/tmp/replay_long_bag}
bin=${3:-target/release/rotor-twin}
mkdir -p "$work"
bag="$work/bag$secs"
if [ ! -d "$bag" ]; then
  "$bin" synth-bag --out "$bag" --film table --from-rpm 9000 --hold-start "$secs" --ramp 0 --hold-end 0
fi
out="$work/out$secs"
rm -rf "$out"
/usr/bin/time -v "$bin" replay "$bag" --fast --out "$out" --json >"$work/report$secs.json" 2>"$work/time$secs.txt"
python3 - "$work/report$secs.json" "$work/time$secs.txt" <<'PY'
import json, re, sys
r = json.load(open(sys.argv[1]))
t = open(sys.argv[2]).read()
rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1))
wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", t).group(1)
print(f"bag {r['bag_duration_s']:.1f} s, {r['messages_in']} messages in, {r['messages_out']} out")
print(f"replay wall time {r['wall_time_s']:.1f} s ({r['real_time_factor']:.2f}x real time); process {wall}")
print(f"peak RSS {rss / 1024:.1f} MB")
for n in r.get("notes", []):
    print("note:", n)
PY
