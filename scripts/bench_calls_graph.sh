#!/usr/bin/env bash
# Benchmark (not a ctest): the call scenario through the live ROS graph against the offline runner.
# For each seed 1..RUNS, launch/demo.launch calls:=true runs farm_sim (PICKERS pickers filling trays and calling,
# ROBOTS robots waiting for calls; GNSS, LiDAR and RFID as the runner's call scenario: UWB and camera off),
# gnss_ingest, rfid_ranging, leg_detector, tpf_tracker, an nbs_planner per robot and the dispatcher, whose
# ~calls_log records every call; the runner runs `nbs` on the same seeds (`experiment --scenario calls`, idle
# robots positioned by the planner as in the graph). The robots drive in closed loop, so the graph and the runner
# are two runs of the same system, not the same run: compare means over seeds. Scored from the dispatcher's own
# times (call to arrival as the dispatcher declared it); the truth-based scores (wrong lanes, false arrivals) are
# the runner's. Prints one JSON object.
# Usage: scripts/bench_calls_graph.sh [RUNS=1] [DURATION=1800] [PICKERS=12] [ROBOTS=4] [WORK_DIR]
# Environment: BUILD_DIR (build), RATE (farm_sim rate factor, 1), MAP (config/maps/riseholme.tmap2).
set -eo pipefail
cd "$(dirname "$0")/.."
RUNS="${1:-1}"
DURATION="${2:-1800}"
PICKERS="${3:-12}"
ROBOTS="${4:-4}"
WORK="${5:-$(mktemp -d)}"
BUILD_DIR="${BUILD_DIR:-build}"
MAP="$(realpath "${MAP:-config/maps/riseholme.tmap2}")"
mkdir -p "$WORK"
WORK="$(realpath "$WORK")"
export PATH=/usr/bin:/bin:$PATH ROS_HOSTNAME=localhost ROS_HOME="${ROS_HOME:-$WORK/ros_home}"
mkdir -p "$ROS_HOME"
# shellcheck disable=SC1091
source "$BUILD_DIR/devel/setup.bash"
# The runner's call scenario: UWB and camera off; its pickers: config/pickers.yaml's, then picker_<i> with tags.
sed -e 's/^  uwb: true/  uwb: false/' -e 's/^  camera: true/  camera: false/' config/sim.yaml > "$WORK/sim_calls.yaml"
python3 - config/pickers.yaml "$WORK/pickers_calls.yaml" "$PICKERS" <<'EOF'
import sys, yaml
doc = yaml.safe_load(open(sys.argv[1]))
n = int(sys.argv[3])
pickers = doc["pickers"][:n]
for i in range(len(pickers) + 1, n + 1):
    pickers.append({"id": "picker_%d" % i, "gnss_topic": "/pickers/picker_%d/fix" % i,
                    "rfid_tags": ["rfid_000%d" % i], "uwb_tag": "uwb_000%d" % i})
doc["pickers"] = pickers
yaml.safe_dump(doc, open(sys.argv[2], "w"))
EOF
for seed in $(seq 1 "$RUNS"); do
  port=$((20000 + RANDOM % 20000))
  rm -f "$WORK/graph_calls_${seed}.csv"
  ROS_MASTER_URI="http://localhost:$port" roslaunch -p "$port" picker_localisation demo.launch calls:=true \
    map_file:="$MAP" sim_config:="$WORK/sim_calls.yaml" pickers_file:="$WORK/pickers_calls.yaml" robots:="$ROBOTS" \
    seed:="$seed" duration:="$DURATION" rate_factor:="${RATE:-1}" calls_log:="$WORK/graph_calls_${seed}.csv" \
    > "$WORK/graph_${seed}.log" 2>&1 || true
  [ -s "$WORK/graph_calls_${seed}.csv" ] || { echo "no calls logged: $WORK/graph_${seed}.log" >&2; exit 1; }
done
"$BUILD_DIR/devel/lib/picker_localisation/experiment" --map "$MAP" --scenario calls --runs "$RUNS" --seed 1 \
  --duration "$DURATION" --pickers-count "$PICKERS" --robots "$ROBOTS" --methods nbs \
  --sim-config "$WORK/sim_calls.yaml" --out "$WORK/runner" > "$WORK/runner.log"
python3 - "$WORK" "$RUNS" "$MAP" "$DURATION" <<'EOF'
import csv, json, math, sys
work, runs, map_file, duration = sys.argv[1], int(sys.argv[2]), sys.argv[3], float(sys.argv[4])
def summary(times, calls):
    return {"calls": calls, "arrived": len(times),
            "call_to_arrival_mean_s": sum(times) / len(times) if times else math.nan}
def graph(seed):
    rows = list(csv.DictReader(open("%s/graph_calls_%d.csv" % (work, seed))))
    origin = 100.0  # ROS time of the simulated t = 0 (farm_sim's start_time)
    rows = [r for r in rows if float(r["called"]) <= origin + duration]
    return summary([float(r["call_to_arrival_s"]) for r in rows if r["call_to_arrival_s"]], len(rows))
def runner(k):
    rows = list(csv.DictReader(open("%s/runner/nbs/calls_%d.csv" % (work, k))))
    return summary([float(r["arrival_s"]) for r in rows if math.isfinite(float(r["arrival_s"]))], len(rows))
out = {"map": map_file, "duration_s": duration, "seeds": list(range(1, runs + 1)),
       "graph": [graph(s) for s in range(1, runs + 1)], "runner": [runner(k) for k in range(runs)]}
for name in ("graph", "runner"):
    per = out[name]
    out[name + "_mean"] = {key: sum(p[key] for p in per) / runs for key in per[0]}
g, r = out["graph_mean"]["call_to_arrival_mean_s"], out["runner_mean"]["call_to_arrival_mean_s"]
out["graph_over_runner_call_to_arrival"] = g / r if r else math.nan
print(json.dumps(out, indent=1))
EOF
