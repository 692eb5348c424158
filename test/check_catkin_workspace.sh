#!/usr/bin/env bash
# The route a ROS user takes, in a fresh catkin workspace in a temporary folder, from a clean environment (nothing
# of the `make` build or its devel space): this source tree linked into src/, `catkin_make` builds it,
# `catkin_make run_tests` runs a gtest and a rostest and catkin_test_results finds 0 errors and 0 failures, the
# devel space's rosrun finds a tool, and `catkin_make install` gives an install space in which every launch file
# loads and every node a launch file starts is installed (test/check_install.sh --prefix). `make test` runs
# every test already; running them all a second time here would double CI's time, so two stand for the route.
# usage: check_catkin_workspace.sh PACKAGE_DIR
set -u
pkg="$(cd "$1" && pwd -P)"
ws="$(mktemp -d)"
trap 'rm -rf "$ws"' EXIT
mkdir -p "$ws/src"
ln -s "$pkg" "$ws/src/picker_localisation"
jobs="$(nproc)"
run() { (cd "$ws" && env -i PATH=/usr/bin:/bin HOME="$ws" ROS_HOME="$ws/ros_home" ROS_LANG_DISABLE=genlisp \
  ROS_HOSTNAME=localhost "$@"); }
step() { # name log command...
  local name="$1" log="$ws/$2"; shift 2
  if run "$@" > "$log" 2>&1; then echo "ok: $name"; else echo "FAIL: $name"; tail -30 "$log"; exit 1; fi
}
step "catkin_make" make.log catkin_make -j"$jobs" -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3
step "catkin_make run_tests (test_topology, map_server rostest)" run_tests.log catkin_make -j"$jobs" \
  run_tests_picker_localisation_gtest_test_topology run_tests_picker_localisation_rostest_test_map_server.test
summary="$(run catkin_test_results build/test_results 2>&1 | tail -1)"
echo "$summary"
case "$summary" in
  "Summary: "*" 0 errors, 0 failures"*) ;;
  *) echo "FAIL: catkin_test_results"; run catkin_test_results --verbose build/test_results | tail -30; exit 1 ;;
esac
tests="$(printf '%s' "$summary" | sed -n 's/^Summary: \([0-9]*\) tests.*/\1/p')"
[ "${tests:-0}" -ge 10 ] || { echo "FAIL: only '${tests}' test results (want the gtest's and the rostest's)"; exit 1; }
out="$(run bash -c "source devel/setup.bash && rosrun picker_localisation tmap_info \
  '$pkg/config/maps/riseholme.tmap2'" 2>&1)"
printf '%s\n' "$out" | grep -q '^nodes: 138$' || { echo "FAIL: rosrun tmap_info from the devel space: $out"; exit 1; }
echo "ok: rosrun from the workspace's devel space"
step "catkin_make install" install.log catkin_make -j"$jobs" install
"$pkg/test/check_install.sh" --prefix "$ws/install"
