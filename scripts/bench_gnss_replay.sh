#!/usr/bin/env bash
# Benchmark (not a ctest): GNSS only, through the ROS graph on a replayed bag, against the node nearest the raw fix.
# 1. farm_sim (3 pickers, GNSS only, config/sim.yaml's Table I errors, seed S) is recorded to a bag;
# 2. the bag is replayed through launch/replay.launch (gnss_ingest -> tpf_tracker -> evaluator);
# 3. the offline runner scores `raw_fix` (node nearest the latest accepted fix), `khan_connected` and `gnss_tpf` on
#    the same seed and map (same pickers and fixes: the simulator is shared, see docs/readme/eval.md).
# Prints one JSON object. Usage: scripts/bench_gnss_replay.sh MAP [DURATION=900] [SEED=1] [WORK_DIR]
# Environment: BUILD_DIR (default build), RATE (farm_sim rate factor, 10), REPLAY_RATE (5),
#   SENSORS: gnss (default, as above) | lidar_rfid: the patrolling robot's lasers and RFID reader are simulated and
#   recorded too, the replay runs leg_detector and rfid_ranging, gnss_ingest associates the people and learns the
#   GNSS biases, and the runner scores khan_connected and rfid_lidar_gnss.
#   SIM_CONFIG: the simulator config the sensor switches are applied to (default config/sim.yaml; another farm's walks
#   or GNSS errors, e.g. scripts/bench_lane_variants.sh's variants); the runner then reads the same file.
set -eo pipefail
cd "$(dirname "$0")/.."
MAP="$(realpath "${1:?usage: bench_gnss_replay.sh MAP [DURATION] [SEED] [WORK_DIR]}")"
DURATION="${2:-900}"
SEED="${3:-1}"
WORK="${4:-$(mktemp -d)}"
BUILD_DIR="${BUILD_DIR:-build}"
mkdir -p "$WORK"
WORK="$(realpath "$WORK")"
export PATH=/usr/bin:/bin:$PATH ROS_HOSTNAME=localhost ROS_HOME="${ROS_HOME:-$WORK/ros_home}"
mkdir -p "$ROS_HOME"
# shellcheck disable=SC1091
source "$BUILD_DIR/devel/setup.bash"
# GNSS only: every other simulated sensor off (the pickers' walks and GNSS errors do not depend on them).
SENSORS="${SENSORS:-gnss}"
SIM_BASE="${SIM_CONFIG:-config/sim.yaml}"
RUNNER_SIM=()
REGEX="/tf|/tf_static|/pickers/[^/]+/(fix|ground_truth)"
METHODS=raw_fix,khan_connected,gnss_tpf
if [ "$SENSORS" = lidar_rfid ]; then
  sed -e 's/^  uwb: true/  uwb: false/' -e 's/^  camera: true/  camera: false/' "$SIM_BASE" > "$WORK/sim_gnss_only.yaml"
  REGEX="$REGEX|/robot_[0-9]+/(scan_front|scan_rear|rfid|ground_truth)"
  METHODS=khan_connected,rfid_lidar_gnss
else
  sed -e 's/^  laser: true/  laser: false/' -e 's/^  rfid: true/  rfid: false/' -e 's/^  uwb: true/  uwb: false/' \
      -e 's/^  camera: true/  camera: false/' "$SIM_BASE" > "$WORK/sim_gnss_only.yaml"
fi
if [ -n "$SIM_CONFIG" ]; then RUNNER_SIM=(--sim-config "$WORK/sim_gnss_only.yaml"); fi
own_master() {  # log args...
  local log="$WORK/$1.log"; shift
  local port=$((20000 + RANDOM % 20000))
  ROS_MASTER_URI="http://localhost:$port" roslaunch -p "$port" "$@" > "$log" 2>&1 || true
}
# farm_sim holds its clock for 3 wall s (start_delay) while the recorder discovers its topics, so the bag holds the
# simulation from its first message as the runner sees it. A bag that started 4.5 s late (the recorder waits to hear
# the clock, then finds the topics; 10 simulated s per wall s at rate 10) gave the trackers fewer fixes before the first ambiguous person;
# one association decided differently made graph and runner diverge for minutes.
cat > "$WORK/record.launch" <<EOF
<launch>
  <include file="\$(find picker_localisation)/launch/farm_sim.launch">
    <arg name="map_file" value="$MAP"/>
    <arg name="sim_config" value="$WORK/sim_gnss_only.yaml"/>
    <arg name="duration" value="$DURATION"/>
    <arg name="rate_factor" value="${RATE:-10}"/>
    <arg name="seed" value="$SEED"/>
    <arg name="required" value="true"/>
    <arg name="start_delay" value="3"/>
  </include>
  <include file="\$(find picker_localisation)/launch/record.launch">
    <arg name="bag" value="$WORK/gnss.bag"/>
    <arg name="regex" value="$REGEX"/>
  </include>
</launch>
EOF
own_master record "$WORK/record.launch"
sleep 2
[ -s "$WORK/gnss.bag" ] || { echo "no bag recorded: $WORK/record.log" >&2; exit 1; }
own_master replay picker_localisation replay.launch bag:="$WORK/gnss.bag" rate:="${REPLAY_RATE:-5}" \
  map_file:="$MAP" output_csv:="$WORK/graph_errors.csv"
[ -s "$WORK/graph_errors.csv" ] || { echo "replay wrote no errors: $WORK/replay.log" >&2; exit 1; }
"$BUILD_DIR/devel/lib/picker_localisation/experiment" --map "$MAP" --scenario multi --runs 1 --seed "$SEED" \
  --duration "$DURATION" --methods "$METHODS" --out "$WORK/runner" "${RUNNER_SIM[@]}" > "$WORK/runner.log"
python3 - "$WORK/graph_errors.csv" "$WORK/runner/summary.csv" "$MAP" "$DURATION" "$SEED" "$SENSORS" <<'EOF'
import csv, json, math, sys
graph, summary, map_file, duration, seed = sys.argv[1:6]
rows = list(csv.DictReader(open(graph)))
def col(*names):
    for n in names:
        if rows and n in rows[0]:
            return n
    raise SystemExit("graph CSV lacks %s: %s" % (names, list(rows[0]) if rows else []))
topo, lane_ok, lane_app = col("topological_error", "topological"), col("in_true_lane"), col("lane_applicable")
t = [float(r[topo]) for r in rows if float(r[topo]) >= 0]
lane = [int(r[lane_ok]) for r in rows if int(r[lane_app])]
out = {"map": map_file, "duration_s": float(duration), "seed": int(seed), "sensors": sys.argv[6],
       "graph_tpf": {"samples": len(rows), "topological_mean": sum(t) / len(t),
                     "right_lane_share": sum(lane) / len(lane) if lane else math.nan}}
for r in csv.DictReader(open(summary)):
    out["runner_" + r["method"]] = {"topological_mean": float(r["topological_mean"]),
                                    "right_lane_share": float(r["right_lane_share"])}
raw = out.get("runner_raw_fix")
if raw:
    out["graph_over_raw_topological"] = out["graph_tpf"]["topological_mean"] / raw["topological_mean"]
    out["graph_minus_raw_right_lane"] = out["graph_tpf"]["right_lane_share"] - raw["right_lane_share"]
print(json.dumps(out, indent=1))
EOF
