#!/usr/bin/env bash
# Builds zenoh-bridge-ros2dds (Zenoh with zenoh-plugin-ros2dds linked in) for zenoh_route.sh,
# outside the repository. Usage:
#   bash tests/interop/setup-zenoh-bridge.sh SRC_DIR PREFIX [TARGET_DIR]
# SRC_DIR: a checkout of the eclipse-zenoh/zenoh-plugin-ros2dds repository at tag 1.9.0 (the
# plugin crate is on crates.io, the bridge's crate is not; that tag takes every zenoh crate from
# crates.io, while later commits of its main branch take zenoh from its git repository). It is not
# changed: the build runs in a copy, trimmed to what the route needs (zenoh with the TCP transport
# only, no QUIC/TLS/WebSocket/UDP/unix-socket links, no REST plugin: 324 crates instead of 604;
# release profile without LTO). The binary goes to PREFIX/bin/zenoh-bridge-ros2dds.
# Needs cmake (the cyclors crate builds Cyclone DDS with it), libclang-dev (bindgen) and a C
# compiler: `apt-get install -y cmake libclang-dev clang`. On a shared machine it builds with one
# job at nice 19 (CARGO_BUILD_JOBS overrides).
set -euo pipefail
src="$(cd "$1" && pwd)"; prefix="$2"; target="${3:-$prefix/build}"
grep -q '^version = "1.9.0"' "$src/Cargo.toml" || { echo "setup-zenoh-bridge.sh: $src is not tag 1.9.0" >&2; exit 2; }
work="$prefix/src"
rm -rf "$work"; mkdir -p "$work" "$prefix/bin"
cp -r "$src/." "$work/"
rm -f "$work/rust-toolchain.toml" # pins rustc 1.93.0; the installed stable builds it
python3 - "$work" <<'PY'
import sys
w = sys.argv[1]
def edit(path, old, new):
    s = open(f"{w}/{path}").read()
    assert old in s, f"{path}: {old!r} not found"
    open(f"{w}/{path}", "w").write(s.replace(old, new))
edit("Cargo.toml", 'zenoh = { version = "1.9.0", features = [',
     'zenoh = { version = "1.9.0", default-features = false, features = [\n  "transport_tcp",')
edit("Cargo.toml", 'zenoh-ext = { version = "1.9.0", features = [',
     'zenoh-ext = { version = "1.9.0", default-features = false, features = [')
edit("zenoh-bridge-ros2dds/Cargo.toml", "zenoh-plugin-rest = { workspace = true }\n", "")
edit("zenoh-bridge-ros2dds/src/main.rs",
     'plugins_mgr.declare_static_plugin::<zenoh_plugin_rest::RestPlugin, &str>("rest", true);',
     'tracing::warn!("the REST plugin is not in this build");')
PY
cd "$work"
start=$(date +%s)
CARGO_TARGET_DIR="$target" CARGO_BUILD_JOBS="${CARGO_BUILD_JOBS:-1}" \
  CARGO_PROFILE_RELEASE_LTO=false CARGO_PROFILE_RELEASE_CODEGEN_UNITS=16 \
  nice -n 19 cargo build --release -p zenoh-bridge-ros2dds
cp "$target/release/zenoh-bridge-ros2dds" "$prefix/bin/"
echo "built $prefix/bin/zenoh-bridge-ros2dds in $(( $(date +%s) - start )) s"
