#!/usr/bin/env bash
# Benchmark (not a ctest): the navigation scenario through the live ROS graph against the offline runner.
# For each seed 1..RUNS and each policy (estimated_node, nbs), launch/demo.launch runs farm_sim (1 picker, 1 robot,
# GNSS + LiDAR + RFID as the runner's navigation scenario: UWB and camera off), gnss_ingest, rfid_ranging,
# leg_detector, tpf_tracker, nbs_planner (the policy) and the evaluator; the runner scores `estimated_node` and
# `nbs` on the same seeds (`experiment --scenario navigation`). The planner drives the robot in closed loop, so
# the graph and the runner are two runs of the same system, not the same run: compare means over seeds.
# Prints one JSON object. Usage: scripts/bench_navigation_graph.sh [RUNS=5] [DURATION=600] [WORK_DIR]
# Environment: BUILD_DIR (default build), RATE (farm_sim rate factor, 4), MAP (config/maps/riseholme.tmap2).
set -eo pipefail
cd "$(dirname "$0")/.."
RUNS="${1:-5}"
DURATION="${2:-600}"
WORK="${3:-$(mktemp -d)}"
BUILD_DIR="${BUILD_DIR:-build}"
MAP="$(realpath "${MAP:-config/maps/riseholme.tmap2}")"
mkdir -p "$WORK"
WORK="$(realpath "$WORK")"
export PATH=/usr/bin:/bin:$PATH ROS_HOSTNAME=localhost ROS_HOME="${ROS_HOME:-$WORK/ros_home}"
mkdir -p "$ROS_HOME"
# shellcheck disable=SC1091
source "$BUILD_DIR/devel/setup.bash"
# The runner's navigation scenario: the first picker of config/pickers.yaml, UWB and camera off.
sed -e 's/^  uwb: true/  uwb: false/' -e 's/^  camera: true/  camera: false/' config/sim.yaml > "$WORK/sim_navigation.yaml"
python3 - config/pickers.yaml "$WORK/pickers_navigation.yaml" <<'EOF'
import sys, yaml
doc = yaml.safe_load(open(sys.argv[1]))
doc["pickers"] = doc["pickers"][:1]
yaml.safe_dump(doc, open(sys.argv[2], "w"))
EOF
for seed in $(seq 1 "$RUNS"); do
  for policy in estimated_node nbs; do
    port=$((20000 + RANDOM % 20000))
    ROS_MASTER_URI="http://localhost:$port" roslaunch -p "$port" picker_localisation demo.launch \
      map_file:="$MAP" sim_config:="$WORK/sim_navigation.yaml" pickers_file:="$WORK/pickers_navigation.yaml" \
      seed:="$seed" policy:="$policy" duration:="$DURATION" rate_factor:="${RATE:-4}" \
      output_csv:="$WORK/graph_${policy}_${seed}.csv" > "$WORK/graph_${policy}_${seed}.log" 2>&1 || true
    [ -s "$WORK/graph_${policy}_${seed}.csv" ] || { echo "no errors written: $WORK/graph_${policy}_${seed}.log" >&2; exit 1; }
  done
done
"$BUILD_DIR/devel/lib/picker_localisation/experiment" --map "$MAP" --scenario navigation --runs "$RUNS" --seed 1 \
  --duration "$DURATION" --methods estimated_node,nbs --out "$WORK/runner" > "$WORK/runner.log"
python3 - "$WORK" "$RUNS" "$MAP" "$DURATION" <<'EOF'
import csv, json, math, sys
work, runs, map_file, duration = sys.argv[1], int(sys.argv[2]), sys.argv[3], float(sys.argv[4])
def score(path):
    rows = list(csv.DictReader(open(path)))
    topo = [float(r["topological"]) for r in rows if float(r["topological"]) >= 0]
    lane = [int(r["in_true_lane"]) for r in rows if int(r["lane_applicable"])]
    return sum(topo) / len(topo), (sum(lane) / len(lane) if lane else math.nan)
out = {"map": map_file, "duration_s": duration, "seeds": list(range(1, runs + 1))}
for policy in ("estimated_node", "nbs"):
    graph = [score("%s/graph_%s_%d.csv" % (work, policy, s)) for s in range(1, runs + 1)]
    runner = [score("%s/runner/%s/run_%d.csv" % (work, policy, k)) for k in range(runs)]
    for name, per_seed in (("graph", graph), ("runner", runner)):
        out["%s_%s" % (name, policy)] = {
            "topological_mean": sum(t for t, _ in per_seed) / runs,
            "right_lane_share": sum(l for _, l in per_seed) / runs,
            "per_seed_topological": [round(t, 3) for t, _ in per_seed],
            "per_seed_right_lane": [round(l, 3) for _, l in per_seed]}
for name in ("graph", "runner"):
    en, nbs = out[name + "_estimated_node"], out[name + "_nbs"]
    out[name + "_estimated_node_over_nbs_topological"] = en["topological_mean"] / nbs["topological_mean"]
print(json.dumps(out, indent=1))
EOF
