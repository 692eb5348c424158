#!/usr/bin/env bash
# `make demo`: runs the package's demo from the build tree (build/devel). RVIZ=1 opens rviz.
set -eo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${BUILD_DIR:-build}"
export PATH=/usr/bin:/bin:$PATH
export ROS_HOSTNAME="${ROS_HOSTNAME:-localhost}"
# shellcheck disable=SC1091
source "$BUILD_DIR/devel/setup.bash"
echo "== Riseholme topological map (config/maps/riseholme.tmap2) =="
"$BUILD_DIR/devel/lib/picker_localisation/tmap_info" config/maps/riseholme.tmap2
if [ "${RVIZ:-0}" = "1" ]; then
  port=$((20000 + RANDOM % 20000))   # own master port: never collides with a running roscore
  export ROS_MASTER_URI="http://localhost:$port"
  roslaunch -p "$port" picker_localisation map_view.launch
fi
