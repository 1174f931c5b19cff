#!/usr/bin/env bash
# A fleet route over Zenoh between two "hosts" (issue 17), and the direct DDS route for comparison.
# A benchmark script, not part of `cargo test`. As root:
#   ZENOH_BRIDGE=PATH bash tests/interop/zenoh_route.sh [SAMPLES] [THROUGHPUT_S] [OUT_DIR]
# (PATH: a zenoh-bridge-ros2dds binary; none: only the phases without bridges)
# (SAMPLES speed commands, default 200; THROUGHPUT_S seconds of counting journal states, default 10;
# ROTOR_TWIN_BIN overrides target/release/rotor-twin.)
#
# Host A (this script's private network namespace, 10.99.0.1) runs the node (built-in microturbine,
# nonlinear film, state_rate_hz 1000) and a zenoh-bridge-ros2dds; host B (a child namespace,
# 10.99.0.2) runs a bridge and a Cyclone DDS peer (zenoh_peer.py). The two hosts share only a veth
# pair, inside `unshare -n`: nothing reaches the real network. The bridges talk Zenoh over TCP
# (B connects to A's tcp/10.99.0.1:7447), multicast scouting off; on each host every DDS participant
# is confined to loopback (the node: ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST; Cyclone, i.e. the
# bridge and the peer: CYCLONEDDS_URI naming only `lo`); the bridges route only the twins' topics
# (.*/rotor_twin/.*) and /diagnostics (allow lists). Phases, each printed as one JSON line (in OUT_DIR):
#   closed  no bridge: a peer on B NOT confined (it searches the veth by multicast) sends speeds for
#           8 s; it must receive 0 journal states, and no UDP packet from A may be on the veth
#   zenoh   both bridges: latency of SAMPLES speed commands (speed -> first JournalState carrying
#           it, one command every 50 ms) and journal-state throughput; packets on the veth by kind
#           (UDP must be 0: the only traffic is Zenoh's TCP)
#   stopped the bridges stopped: the peer on B receives 0 journal states in 5 s
#   direct  no bridge, nothing confined: the node and the peer find each other by DDS multicast
#           across the veth (as tests/interop/two_hosts_scenario.sh): the same latency and throughput
#
# The bridge is neither in the repository nor built by cargo here (its build is ~324 crates with
# the trimmed features, ~600 without; Cyclone DDS is built by cmake inside cyclors). Install it once
# with tests/interop/setup-zenoh-bridge.sh (it says what it needs), then point ZENOH_BRIDGE at it.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
if [ "${ZENOH_ROUTE_INNER:-}" != 1 ]; then
  bridge="${ZENOH_BRIDGE:-$(command -v zenoh-bridge-ros2dds || true)}"
  # ZENOH_BRIDGE=none: only the closed and direct phases (a check of the DDS side of this script)
  [ -x "$bridge" ] || [ "$bridge" = none ] || {
    echo "zenoh_route.sh: no zenoh-bridge-ros2dds (ZENOH_BRIDGE; tests/interop/setup-zenoh-bridge.sh)" >&2
    exit 2
  }
  bin="${ROTOR_TWIN_BIN:-$root/target/release/rotor-twin}"
  [ -x "$bin" ] || { echo "zenoh_route.sh: no $bin (cargo build --release)" >&2; exit 2; }
  py="$(bash "$here/setup-venv.sh")/bin/python"
  out="${3:-$(mktemp -d /tmp/zenoh_route.XXXXXX)}"
  mkdir -p "$out"
  out="$(cd "$out" && pwd)"
  exec unshare -n env ZENOH_ROUTE_INNER=1 ZENOH_BRIDGE="$bridge" ROTOR_TWIN_BIN="$bin" PY="$py" \
    OUT="$out" bash "$0" "${1:-200}" "${2:-10}"
fi

# ---- inside the outer private namespace: this is host A ----
samples="$1"; tput_s="$2"
bridge="$ZENOH_BRIDGE"; bin="$ROTOR_TWIN_BIN"; py="$PY"; out="$OUT"
cd "$out"
ip link set lo up multicast on
unshare -n sleep 100000 &
hostb=$!
for _ in $(seq 200); do
  [ "$(readlink /proc/$hostb/ns/net)" != "$(readlink /proc/self/ns/net)" ] && break; sleep 0.05
done
inb() { nsenter -t "$hostb" -n "$@"; }
ip link add va type veth peer name vb
ip link set vb netns "$hostb"
ip addr add 10.99.0.1/24 dev va
ip link set va up multicast on
inb ip link set lo up multicast on
inb ip addr add 10.99.0.2/24 dev vb
inb ip link set vb up multicast on
pids=()
node=
# SIGTERM: a background job of a script ignores SIGINT unless it installs its own handler
cleanup() {
  for p in "${pids[@]}" $node "$hostb"; do kill -TERM "$p" 2> /dev/null || true; done
  wait 2> /dev/null || true
}
trap cleanup EXIT
inb ip -o addr show vb > b_addr.txt

lo_only='<CycloneDDS><Domain><General><Interfaces><NetworkInterface name="lo" multicast="true"/>'
lo_only+='</Interfaces></General></Domain></CycloneDDS>'
peer="$here/zenoh_peer.py"

start_node() { # $1: label; the remaining args: environment for the node
  local label="$1"; shift
  env "$@" "$bin" node --ros-args -p model:=nonlinear -p state_rate_hz:=1000.0 \
    > "node_$label.out" 2> "node_$label.err" &
  node=$!
  for _ in $(seq 600); do
    grep -q "waiting for /rotor_twin/speed" "node_$label.err" && break; sleep 0.1
  done
}
stop() { kill -TERM "$1"; wait "$1" || true; }
capture() { # $1: pcap file; capture on A's end of the veth
  tcpdump -i va -n -U -w "$1" > /dev/null 2>&1 &
  tcpd=$!; sleep 1
}
count() { tcpdump -r "$1" -n "$2" 2> /dev/null | wc -l; }

bridge_conf() { # $1: listen endpoints, $2: connect endpoints (JSON lists)
  cat <<EOF
{
  mode: "router",
  listen: { endpoints: $1 },
  connect: { endpoints: $2 },
  scouting: { multicast: { enabled: false } },
  plugins: {
    ros2dds: {
      domain: 0,
      allow: {
        publishers: [".*/rotor_twin/.*", "/diagnostics"],
        subscribers: [".*/rotor_twin/.*"],
        service_servers: [], service_clients: [], action_servers: [], action_clients: [],
      },
    },
  },
}
EOF
}

report() { # $1: phase, $2: the peer's JSON file, then pairs of key and (JSON) value
  local line="{\"phase\": \"$1\", \"peer\": $(cat "$2")"; shift 2
  while [ $# -gt 1 ]; do line+=", \"$1\": $2"; shift 2; done
  echo "$line}" | tee -a summary.jsonl
}
peer_b() { # $1: label; the rest: the peer's arguments. Confined to lo unless $UNCONFINED
  local label="$1"; shift
  if [ -n "${UNCONFINED:-}" ]; then inb timeout 600 "$py" "$peer" "$@" > "$label.json" 2> "$label.err"
  else inb env CYCLONEDDS_URI="$lo_only" timeout 600 "$py" "$peer" "$@" > "$label.json" 2> "$label.err"; fi
}

closed_phase() { # no bridge; the node confined to lo; an unconfined peer on B searches the veth
  start_node closed ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
  capture closed.pcap
  UNCONFINED=1 peer_b closed silence 8
  kill "$tcpd"; wait "$tcpd" || true
  report closed closed.json udp_from_a "$(count closed.pcap 'udp and src host 10.99.0.1')" \
    udp_from_b "$(count closed.pcap 'udp and src host 10.99.0.2')"
}

zenoh_phase() { # a bridge on each host, every DDS participant confined to lo; then bridges stopped
  bridge_conf '["tcp/10.99.0.1:7447"]' '[]' > bridge_a.json5
  bridge_conf '[]' '["tcp/10.99.0.1:7447"]' > bridge_b.json5
  local t0; t0=$(date +%s.%N)
  env CYCLONEDDS_URI="$lo_only" ROS_DISTRO=jazzy RUST_LOG=info "$bridge" -c bridge_a.json5 \
    > bridge_a.log 2>&1 &
  ba=$!; pids+=("$ba")
  # nsenter itself, not the inb function: $! must be the bridge (a function would run in a subshell)
  nsenter -t "$hostb" -n env CYCLONEDDS_URI="$lo_only" ROS_DISTRO=jazzy RUST_LOG=info "$bridge" \
    -c bridge_b.json5 > bridge_b.log 2>&1 &
  bb=$!; pids+=("$bb")
  capture zenoh.pcap
  peer_b zenoh latency "$samples" "$tput_s" --announce
  kill "$tcpd"; wait "$tcpd" || true
  report zenoh zenoh.json veth_udp "$(count zenoh.pcap udp)" \
    veth_tcp_7447 "$(count zenoh.pcap 'tcp port 7447')" \
    veth_other "$(count zenoh.pcap 'not udp and not tcp port 7447')" \
    bridges_start_to_end_s "$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')"
  stop "$bb"; stop "$ba"; pids=()
  peer_b stopped silence 5 --announce
  report stopped stopped.json
}

direct_phase() { # plain DDS across the veth (discovery by multicast), nothing confined
  start_node direct
  UNCONFINED=1 peer_b direct latency "$samples" "$tput_s"
  report direct direct.json
}

closed_phase
if [ "$bridge" != none ]; then zenoh_phase; fi
stop "$node"; node=
direct_phase
stop "$node"; node=
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg); results in $out" | tee -a summary.jsonl
