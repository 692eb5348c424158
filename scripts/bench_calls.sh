#!/usr/bin/env bash
# The call scenario (docs/readme/dispatch.md): pickers fill trays and call, robots answer through the dispatcher;
# per method the call-to-arrival time against the oracle's, wrong-lane entries per call, false arrivals. On the
# shipped map and on a farm like the one Khan et al. describe (12 lanes of 135 m, 1.5 m apart, generated).
# Usage: scripts/bench_calls.sh [RUNS] [DURATION_S] [PICKERS] [ROBOTS] [OUT_DIR]
# Environment: BUILD_DIR (build), METHODS (the scenario's default rows), FARMS ("riseholme long_lanes"),
# DISPATCHER_CONFIG (config/dispatcher.yaml), SIM_CONFIG (config/sim.yaml: e.g. calls.reported_row_share), JOBS (2),
# IDLE_ROBOTS (nbs: the planner positions robots serving no call, as nbs_planner does; stay: they wait),
# SEED (1: runs use seeds SEED .. SEED + RUNS - 1), TPF_CONFIG (config/tpf.yaml), GNSS_CONFIG
# (config/gnss_ingest.yaml: the association's options), NBS_CONFIG (config/nbs.yaml: the planner positioning idle
# robots, e.g. call_due_weight).
set -eo pipefail
cd "$(dirname "$0")/.."
RUNS="${1:-5}"
DURATION="${2:-1800}"
PICKERS="${3:-12}"
ROBOTS="${4:-4}"
OUT="${5:-$(mktemp -d)}"
BUILD_DIR="${BUILD_DIR:-build}"
METHODS="${METHODS:-oracle,raw_fix,khan_connected,estimated_node,nbs}"
FARMS="${FARMS:-riseholme long_lanes}"
mkdir -p "$OUT"
cp config/maps/riseholme.tmap2 "$OUT/riseholme.tmap2"
python3 scripts/make_polytunnel_map.py "$OUT/long_lanes.tmap2" 12 46 1.5 3.0 --name long_lanes > /dev/null
start=$(date +%s)
for farm in $FARMS; do
  "$BUILD_DIR/devel/lib/picker_localisation/experiment" --map "$OUT/$farm.tmap2" --scenario calls --runs "$RUNS" \
    --seed "${SEED:-1}" --duration "$DURATION" --pickers-count "$PICKERS" --robots "$ROBOTS" --methods "$METHODS" \
    --dispatcher-config "${DISPATCHER_CONFIG:-config/dispatcher.yaml}" --sim-config "${SIM_CONFIG:-config/sim.yaml}" \
    --tpf-config "${TPF_CONFIG:-config/tpf.yaml}" --gnss-config "${GNSS_CONFIG:-config/gnss_ingest.yaml}" \
    --nbs-config "${NBS_CONFIG:-config/nbs.yaml}" --idle-robots "${IDLE_ROBOTS:-nbs}" --jobs "${JOBS:-2}" --out "$OUT/$farm" \
    > "$OUT/$farm.log" 2>&1 || { echo "experiment failed: $OUT/$farm.log" >&2; exit 1; }
  cat "$OUT/$farm/summary.md"
  echo
done
echo "bench_calls: $OUT in $(( $(date +%s) - start )) s wall"
