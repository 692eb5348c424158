#!/usr/bin/env bash
# The installed package (cmake --install into a fresh prefix, or the install space of catkin_make install) is
# usable on its own: every launch file of the install space loads (roslaunch --dump-params resolves every
# $(find ...), arg and included file there), the nodes and scripts the launch files start are installed and
# executable, and rosrun finds a tool.
# usage: check_install.sh BUILD_DIR (installs it into a temporary prefix) | check_install.sh --prefix INSTALL_SPACE
set -u
if [ "$1" = "--prefix" ]; then
  prefix="$2"
else
  build="$1"
  prefix="$(mktemp -d)"
  trap 'rm -rf "$prefix" "$prefix.log"' EXIT
  cmake --install "$build" --prefix "$prefix" > "$prefix.log" 2>&1 || { echo "FAIL: cmake --install"; tail -5 "$prefix.log"; exit 1; }
fi
share="$prefix/share/picker_localisation"
# Only the install space (no source tree, no devel space) on the package path.
run() { env -i PATH=/usr/bin:/bin HOME="$prefix" ROS_HOME="$prefix/ros" ROS_PACKAGE_PATH="$prefix/share:/usr/share" \
  CMAKE_PREFIX_PATH="$prefix:/usr" LD_LIBRARY_PATH="$prefix/lib" ROS_MASTER_URI=http://localhost:11399 "$@"; }
fail=0
n=0
for f in "$share"/launch/*.launch; do
  n=$((n + 1))
  if ! out=$(run roslaunch --dump-params "$f" 2>&1); then
    echo "FAIL: $(basename "$f"): $(echo "$out" | tail -3 | tr '\n' ' ')"
    fail=1
  fi
done
[ "$n" -ge 10 ] || { echo "FAIL: only $n launch files installed"; fail=1; }
# Every node type a launch file starts exists in the install space and is executable.
for type in $(grep -ho 'type="[^"$]*"' "$share"/launch/*.launch | sed 's/type="\(.*\)"/\1/' | sort -u); do
  exe="$prefix/lib/picker_localisation/$type"
  case "$type" in robot_state_publisher|rviz|record|play) continue ;; esac
  [ -x "$exe" ] || { echo "FAIL: launch files start '$type', not installed as $exe"; fail=1; }
done
out=$(run rosrun picker_localisation tmap_info "$share/config/maps/riseholme.tmap2" 2>&1)
echo "$out" | grep -q '^nodes: 138$' || { echo "FAIL: rosrun tmap_info from the install space: $out"; fail=1; }
[ "$fail" -eq 0 ] && echo "ok: $n launch files load from the install space; their nodes are installed; rosrun works"
exit $fail
