#!/usr/bin/env bash
# `make demo`: runs launch/demo.launch (the whole suite on the simulated Riseholme farm, headless, ending by
# itself with the evaluator's error table) from the build tree (build/devel), on its own master port.
# RVIZ=1 opens rviz; extra arguments are passed to roslaunch (e.g. robots:=2 duration:=120).
set -eo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${BUILD_DIR:-build}"
export PATH=/usr/bin:/bin:$PATH
export ROS_HOSTNAME="${ROS_HOSTNAME:-localhost}"
# shellcheck disable=SC1091
source "$BUILD_DIR/devel/setup.bash"
echo "== Riseholme topological map (config/maps/riseholme.tmap2) =="
"$BUILD_DIR/devel/lib/picker_localisation/tmap_info" config/maps/riseholme.tmap2
port=$((20000 + RANDOM % 20000))   # own master port: never collides with a running roscore
export ROS_MASTER_URI="http://localhost:$port"
rviz=false
[ "${RVIZ:-0}" = "1" ] && rviz=true
echo "== demo.launch (master port $port, rviz $rviz) =="
roslaunch -p "$port" picker_localisation demo.launch rviz:="$rviz" "$@"
rc=$?
# The evaluator is a required node: when it has printed the table it exits and roslaunch ends the demo with a
# red "REQUIRED process [evaluator] has died" banner. That is the normal end, not an error.
echo "== demo finished (the 'REQUIRED process [evaluator] has died' banner above is the normal end) =="
exit $rc
