#!/usr/bin/env bash
# Two "hosts" on one machine: the node in this network namespace (host A, 10.99.0.1) and Cyclone
# DDS peers in a child namespace (host B, 10.99.0.2), joined only by a veth pair: discovery
# (multicast) and data cross it. Call under `unshare -n` (nothing reaches the real network; no
# named namespaces, so nothing is left behind).
# Args: ROTOR_TWIN_BIN PYTHON OUT_DIR
set -u
bin="$1"; py="$2"; out="$3"
here="$(cd "$(dirname "$0")" && pwd)"
ip link set lo up
# host B: waits for its end of the veth pair, then runs the peers
unshare -n bash -c '
  : > "$3/b_ready"
  for i in $(seq 100); do ip link show vb >/dev/null 2>&1 && break; sleep 0.05; done
  ip link set lo up
  ip addr add 10.99.0.2/24 dev vb
  ip link set vb up multicast on
  ip -o addr show > "$3/b_addr.txt"
  sleep 2
  timeout 60 "$1" "$2/peer.py" 6 963.42 > "$3/peer.json" 2> "$3/peer.err"
  timeout 20 "$1" "$2/peer.py" 2 963.42 --warnings-only > "$3/late.json" 2> "$3/late.err"
  ip -s -o link show vb > "$3/b_link.txt"
' host_b "$py" "$here" "$out" &
b=$!
# the child must have entered its own namespace before its end of the link is moved there (seen
# once under load: the link moved before unshare, so host B never got it)
for i in $(seq 200); do [ -e "$out/b_ready" ] && break; sleep 0.05; done
ip link add va type veth peer name vb
ip link set vb netns "$b"
ip addr add 10.99.0.1/24 dev va
ip link set va up multicast on
"$bin" node --ros-args -p model:=linear > "$out/node.out" 2> "$out/node.err" &
node=$!
wait "$b"; echo "host b exit $?" >> "$out/peer.err"
kill -INT "$node"
wait "$node"; echo "node exit $?" >> "$out/node.err"
