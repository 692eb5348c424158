#!/usr/bin/env bash
# Benchmark (not a ctest): resident memory of one tpf_tracker on a large generated farm (a large map
# must not stop a node: per-tracker memory must grow with the map, not its square). Starts a roscore, a tracker on the map, feeds
# it 20 observations, prints one JSON object with the RSS after start-up and after fusing.
# Usage: scripts/bench_map_memory.sh [LANES=200] [NODES=100] [WORK_DIR]   (200 x 100: 20,400 nodes)
set -eo pipefail
cd "$(dirname "$0")/.."
LANES="${1:-200}"; NODES="${2:-100}"; WORK="${3:-$(mktemp -d)}"
BUILD_DIR="${BUILD_DIR:-build}"
mkdir -p "$WORK"
export PATH=/usr/bin:/bin:$PATH ROS_HOSTNAME=localhost ROS_HOME="$WORK/ros_home"
export ROS_MASTER_URI="http://localhost:$((20000 + RANDOM % 20000))"
# shellcheck disable=SC1091
source "$BUILD_DIR/devel/setup.bash"
python3 scripts/make_polytunnel_map.py "$WORK/farm.tmap2" "$LANES" "$NODES" > /dev/null
roscore -p "${ROS_MASTER_URI##*:}" > "$WORK/roscore.log" 2>&1 &
core=$!
trap 'kill $tracker $core 2>/dev/null || true' EXIT
sleep 4
rosparam load config/tpf.yaml /bench_tracker
"$BUILD_DIR/devel/lib/picker_localisation/tpf_tracker" __name:=bench_tracker _picker_id:=picker_1 \
  _map_file:="$WORK/farm.tmap2" _ordering_latency:=0.0 > "$WORK/tracker.log" 2>&1 &
tracker=$!
for _ in $(seq 60); do grep -q "tpf_tracker picker_1" "$WORK/tracker.log" 2>/dev/null && break; sleep 1; done
sleep 2
rss_start=$(awk '/VmRSS/ {print $2}' /proc/$tracker/status)
python3 - <<'PY'
import rospy, time
from picker_localisation.msg import Observation
rospy.init_node("bench_map_memory_feed")
pub = rospy.Publisher("/observations", Observation, queue_size=20)
time.sleep(1.5)
nan = float("nan")
for k in range(20):
    o = Observation()
    o.header.stamp = rospy.Time.now()
    o.header.frame_id = "map"
    o.sensor, o.picker_id, o.identifying = "gnss", "picker_1", True
    o.nodes = ["r%d_%d" % (lane, 10 + k) for lane in (1, 2, 3)]
    o.likelihood = [0.5, 1.0, 0.5]
    o.position.x = o.position.y = o.position.z = nan
    pub.publish(o)
    time.sleep(0.2)
PY
sleep 2
rss_fused=$(awk '/VmRSS/ {print $2}' /proc/$tracker/status)
nodes=$(( LANES * (NODES + 2) ))
awk -v n="$nodes" -v a="$rss_start" -v b="$rss_fused" 'BEGIN {
  printf "{\"map_nodes\": %d, \"tracker_rss_mb_after_start\": %.1f, \"tracker_rss_mb_after_20_observations\": %.1f}\n", n, a / 1024, b / 1024 }'
