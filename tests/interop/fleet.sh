#!/usr/bin/env bash
# Fleet benchmark (not a test): N twins of the built-in microturbine in one private network
# namespace (ROS namespaces /fleet1 … /fleetN), sharing one film-table cache (node parameter
# film_cache_dir), driven at one speed by a Cyclone DDS peer. Reports each twin's start time (its
# own log: film tables ready in X s, node up X s after start; and when the script saw it) and its
# own diagnostics (real-time factor, lag, falling_behind warnings; after 5 s of warm-up, the warnings
# stamped in the warm-up counted apart). Usage (as root):
#   bash tests/interop/fleet.sh [N=4] [SECONDS=20] [warm|cold] [RPM=9000]
# warm: the cache is filled first by one node alone (its cold start is reported); cold: the fleet
# starts on an empty cache. FLEET_CACHE_DIR reuses a cache directory; FLEET_OUT keeps the logs;
# FLEET_BIN runs another build. Also reported: the CPU time of each twin and of its threads over
# the window after the warm-up (utime + stime), in cores and per simulated second.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
n="${1:-4}"; seconds="${2:-20}"; mode="${3:-warm}"; rpm="${4:-9000}"
py="$(bash "$root/tests/interop/setup-venv.sh")/bin/python"
bin="$root/target/release/rotor-twin"
[ -x "$bin" ] || (cd "$root" && cargo build --release)
# FLEET_BIN=a:b:… runs twin k on build ((k-1) mod count): an A/B comparison under the same load
IFS=: read -r -a bins <<< "${FLEET_BIN:-$bin}"
bin="${bins[0]}"
cache="${FLEET_CACHE_DIR:-$(mktemp -d)/film-cache}"
out="${FLEET_OUT:-$(mktemp -d)}"
mkdir -p "$out"
# the CPU window: from the peer's warm-up (5 s) to 1 s before its end
cpu_from=6; cpu_span=$(( seconds > 8 ? seconds - 7 : 1 ))
speed=$(awk -v r="$rpm" 'BEGIN { printf "%.4f", r * 3.141592653589793 / 30 }')
for k in $(seq 1 "$n"); do echo "${bins[$(( (k - 1) % ${#bins[@]} ))]}"; done > "$out/bins"
echo "fleet: $n twins, $seconds s at $rpm rpm, $mode cache $cache, logs in $out (load $(cut -d' ' -f1-3 /proc/loadavg))"

# waits (at most $3 s) until each log in $2… says "up"; prints "log seconds" as it sees them
wait_up() {
  local t0="$1" limit="$2"; shift 2
  local pending=("$@")
  while [ ${#pending[@]} -gt 0 ]; do
    local rest=()
    for f in "${pending[@]}"; do
      if grep -q " up on ROS domain" "$f" 2>/dev/null; then
        echo "$f $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')"
      else rest+=("$f"); fi
    done
    pending=("${rest[@]+"${rest[@]}"}")
    if [ ${#pending[@]} -gt 0 ]; then
      if awk -v a="$t0" -v b="$(date +%s.%N)" -v l="$limit" 'BEGIN { exit !(b - a > l) }'; then
        echo "timeout ${pending[*]}"; return 0
      fi
      sleep 0.05
    fi
  done
}
export -f wait_up

timeout $((seconds + 900)) unshare -n bash -c "
  set -u
  ip link set lo up
  if [ '$mode' = warm ]; then
    t0=\$(date +%s.%N)
    '$bin' node --ros-args -r __ns:=/fill -p film_cache_dir:='$cache' 2> '$out/fill.err' > /dev/null &
    p=\$!
    wait_up \$t0 600 '$out/fill.err' > '$out/fill.seen'
    kill -INT \$p; wait \$p || true
  fi
  t0=\$(date +%s.%N)
  pids=()
  for k in \$(seq 1 $n); do
    b=\$(sed -n \${k}p '$out/bins')
    \$b node --ros-args -r __ns:=/fleet\$k -p film_cache_dir:='$cache' 2> '$out/twin'\$k.err > /dev/null &
    pids+=(\$!)
  done
  logs=(); for k in \$(seq 1 $n); do logs+=('$out/twin'\$k.err); done
  wait_up \$t0 600 \"\${logs[@]}\" > '$out/seen'
  '$py' '$root/tests/interop/fleet_peer.py' $n $seconds $speed > '$out/peer.jsonl' 2> '$out/peer.err' &
  peer=\$!
  # CPU time of every twin and of each of its threads (utime + stime, /proc/PID/task/*/stat) over
  # the peer's window after its warm-up, and the load average then
  cpu_snapshot() {
    echo \"time \$(date +%s.%N) load \$(cut -d' ' -f1-3 /proc/loadavg)\"
    for p in \"\${pids[@]}\"; do for t in /proc/\$p/task/*/stat; do echo \"\$p \$(cat \$t 2>/dev/null)\"; done; done
  }
  sleep $cpu_from; cpu_snapshot > '$out/cpu0'; sleep $cpu_span; cpu_snapshot > '$out/cpu1'
  wait \$peer
  kill -INT \"\${pids[@]}\"
  for p in \"\${pids[@]}\"; do wait \$p || true; done
"

# the report: per twin its start and its own diagnostics
"$py" - "$out" "$n" "$mode" <<'PY'
import json, re, sys, pathlib
out, n, mode = pathlib.Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
def start(log):
    text = log.read_text() if log.exists() else ""
    t = re.search(r"film tables ready in ([0-9.]+) s \(([^)]*)\)", text)
    up = re.search(r"up on ROS domain \d+ ([0-9.]+) s after start", text)
    origin = t.group(2).split(" ")[0].rstrip(",") if t else "?"
    return (float(t.group(1)) if t else None), (float(up.group(1)) if up else None), origin
seen = {}
for line in (out / "seen").read_text().splitlines() if (out / "seen").exists() else []:
    path, _, s = line.rpartition(" ")
    seen[pathlib.Path(path).stem] = s
if mode == "warm":
    tab, up, origin = start(out / "fill.err")
    print(f"cache fill (one node alone): tables {tab} s ({origin}), up {up} s after start")
peer = {}
for line in (out / "peer.jsonl").read_text().splitlines() if (out / "peer.jsonl").exists() else []:
    d = json.loads(line); peer[d["twin"]] = d
print("twin     tables_s origin  up_s  seen_s reports rtf_min rtf_median rtf<0.99 lag_max_s falling_behind (warm-up) wakes/report")
ups, rtfs, behind, behind_warmup = [], [], 0, 0
for k in range(1, n + 1):
    tab, up, origin = start(out / f"twin{k}.err")
    d = peer.get(f"fleet{k}", {})
    ups += [up] if up is not None else []
    rtfs += [d["rtf_min"]] if d.get("rtf_min") is not None else []
    behind += d.get("falling_behind", 0)
    behind_warmup += d.get("falling_behind_warmup", 0)
    print(f"fleet{k:<3} {tab!s:>8} {origin:<7} {up!s:>5} {seen.get(f'twin{k}', '-'):>7} {d.get('reports', 0):>7} "
          f"{d.get('rtf_min')!s:>7} {d.get('rtf_median')!s:>10} {d.get('rtf_below_0_99', '-')!s:>8} {d.get('lag_max_s')!s:>9} {d.get('falling_behind', 0):>14} {'(' + str(d.get('falling_behind_warmup', '-')) + ')':>9} {d.get('wakes_median')!s:>12}")
def cpu(path):
    """(time, load, {pid: {tid: (thread name, ticks)}}) of a snapshot"""
    lines = path.read_text().splitlines() if path.exists() else []
    if not lines:
        return None
    head = lines[0].split()
    tasks = {}
    for line in lines[1:]:
        pid, _, stat = line.partition(" ")
        if ")" not in stat:
            continue
        tid, _, rest = stat.partition(" (")
        name, _, fields = rest.rpartition(") ")
        f = fields.split()
        tasks.setdefault(pid, {})[tid] = (name, int(f[11]) + int(f[12]))
    return float(head[1]), " ".join(head[3:6]), tasks
c0, c1 = cpu(out / "cpu0"), cpu(out / "cpu1")
if c0 and c1:
    span = c1[0] - c0[0]
    per_twin, per_name, by_bin = [], {}, {}
    # the build each twin ran (pids in start order, as in bins)
    order = [l.split()[0] for l in (out / "cpu1").read_text().splitlines()[1:]]
    order = list(dict.fromkeys(order))
    names = (out / "bins").read_text().split()
    bins = {pid: names[i] for i, pid in enumerate(order) if i < len(names)}
    for pid, tasks in c1[2].items():
        before = c0[2].get(pid, {})
        total = 0
        for tid, (name, ticks) in tasks.items():
            d = ticks - before.get(tid, (name, 0))[1]
            total += d
            per_name[name] = per_name.get(name, 0) + d
        per_twin.append(total / 100 / span)
        by_bin.setdefault(bins.get(pid, "?"), []).append(total / 100 / span)
    rtf_med = [peer[f"fleet{k}"]["rtf_median"] for k in range(1, n + 1) if peer.get(f"fleet{k}", {}).get("rtf_median")]
    mean = sum(per_twin) / len(per_twin)
    sim = sum(rtf_med) / len(rtf_med) if rtf_med else None
    print(f"cpu over {span:.1f} s (load {c0[1]} -> {c1[1]}): per twin mean {mean:.3f} core, min {min(per_twin):.3f}, max {max(per_twin):.3f}; "
          f"all {sum(per_twin):.2f} cores" + (f"; per simulated second {mean / sim:.3f} s (mean real-time factor {sim:.3f})" if sim else ""))
    if len(by_bin) > 1:
        for b, v in by_bin.items():
            print(f"  build {b}: {len(v)} twins, mean {sum(v) / len(v):.3f} core")
    print("  by thread, mean core per twin: " + ", ".join(f"{k} {v / 100 / span / len(per_twin):.3f}"
          for k, v in sorted(per_name.items(), key=lambda e: -e[1]) if v > 0))
if ups:
    print(f"summary: {len(ups)}/{n} up, start median {sorted(ups)[len(ups)//2]:.2f} s, max {max(ups):.2f} s; "
          f"real-time factor min {min(rtfs) if rtfs else None}; falling_behind warnings {behind} after the "
          f"warm-up, {behind_warmup} in it")
PY
