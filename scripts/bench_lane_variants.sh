#!/usr/bin/env bash
# Benchmark (not a ctest): GNSS-only beliefs on farms, walks and GNSS errors unlike the shipped ones, in the offline
# runner, against the node nearest the raw fix -- per variant and per picker. A belief must never be worse than no
# filter: per variant the mean right-lane share of gnss_tpf >= raw_fix's and its mean topological error <=, and no
# picker more than 0.2 below its own raw fix's lane share. Seeded: a run repeats exactly.
# Usage: scripts/bench_lane_variants.sh [RUNS=16] [DURATION=900] [WORK_DIR]
# Environment: SEED (first seed, default 1; runs take SEED..SEED+RUNS-1: SEED=17 gives the held-out seeds 17..32 on
#   which no default was chosen), BUILD_DIR (default build), TPF_CONFIG (default config/tpf.yaml), METHODS (raw_fix,khan_connected,gnss_tpf),
#   VARIANTS (space-separated names of the list below; default all),
#   GRAPH_VARIANTS (space-separated names): these variants also go through the ROS graph, on each seed of
#   GRAPH_SEEDS (space-separated, default "1"; scripts/bench_gnss_replay.sh: farm_sim recorded to a bag, replayed
#   through gnss_ingest -> tpf_tracker -> evaluator; ~5 min wall per variant and seed), reported per picker as
#   graph_tpf against the runner's raw_fix and gnss_tpf of the same seeds.
# Variants (maps from scripts/make_polytunnel_map.py; sim configs are config/sim.yaml with these changes):
#   farms:  two_tunnels  12 untagged lanes x 135 m, 1.5 m apart, two tunnels, rotated 23 deg
#           narrow       8 tagged lanes x 60 m, 1.2 m apart
#           wide         6 untagged lanes x 100 m, 3 m apart, rotated -60 deg
#           riseholme    the shipped map
#   errors: table1       Table I (offset U(0, 3.5) m + drift 2.5 m, 300 s)
#           gm_slow      Gauss-Markov only, 2 m per axis, 600 s correlation
#           gm_fast      Gauss-Markov only, 3.5 m per axis, 60 s correlation, redrawn after every blackout
#   walks:  serpentine   the paper's walk (turning back mid-lane with p_reverse 0.1 per minute)
#           skip_stops   every other lane, a long stop (mean 3 min) at 2 % of the lane nodes
#           out_and_back each lane walked to its far end and back by the same lane, turning back twice as often
set -eo pipefail
cd "$(dirname "$0")/.."
RUNS="${1:-16}"
DURATION="${2:-900}"
WORK="${3:-$(mktemp -d)}"
BUILD_DIR="${BUILD_DIR:-build}"
TPF_CONFIG="${TPF_CONFIG:-config/tpf.yaml}"
METHODS="${METHODS:-raw_fix,khan_connected,gnss_tpf}"
SEED="${SEED:-1}"
mkdir -p "$WORK"
python3 scripts/make_polytunnel_map.py "$WORK/two_tunnels.tmap2" 12 46 1.5 3.0 --tunnels 2 --rotation-deg 23 \
  --untagged --name two_tunnels > /dev/null
python3 scripts/make_polytunnel_map.py "$WORK/narrow.tmap2" 8 30 1.2 2.0 --name narrow > /dev/null
python3 scripts/make_polytunnel_map.py "$WORK/wide.tmap2" 6 40 3.0 2.5 --rotation-deg -60 --untagged --name wide > /dev/null
cp config/maps/riseholme.tmap2 "$WORK/riseholme.tmap2"
sim_variant() {  # name error walk
  local out="$WORK/sim_$1.yaml"
  local e=() w=()
  case "$2" in
    table1) ;;
    gm_slow) e=(-e 's/^  offset_max: [0-9.]*/  offset_max: 0.0/' -e 's/^  drift_std: [0-9.]*/  drift_std: 2.0/'
                -e 's/^  drift_tau: [0-9.]*/  drift_tau: 600.0/') ;;
    gm_fast) e=(-e 's/^  offset_max: [0-9.]*/  offset_max: 0.0/' -e 's/^  drift_std: [0-9.]*/  drift_std: 3.5/'
                -e 's/^  drift_tau: [0-9.]*/  drift_tau: 60.0/'
                -e 's/^  redraw_after_blackout: false/  redraw_after_blackout: true/') ;;
  esac
  case "$3" in
    serpentine) ;;
    skip_stops) w=(-e 's/^  lane_order: [a-z_]*/  lane_order: skip_one/'
                   -e 's/^  long_stop_probability: [0-9.]*/  long_stop_probability: 0.02/') ;;
    out_and_back) w=(-e 's/^  lane_order: [a-z_]*/  lane_order: out_and_back/' -e 's/^  p_reverse: [0-9.]*/  p_reverse: 0.2/') ;;
  esac
  sed "${e[@]}" "${w[@]}" config/sim.yaml > "$out"
  echo "$out"
}
ALL="two_tunnels:table1:serpentine two_tunnels:gm_slow:skip_stops two_tunnels:gm_fast:out_and_back
narrow:table1:out_and_back narrow:gm_fast:serpentine narrow:gm_slow:skip_stops
wide:table1:skip_stops wide:gm_slow:serpentine wide:gm_fast:out_and_back
riseholme:table1:serpentine riseholme:gm_fast:skip_stops riseholme:gm_slow:out_and_back"
for v in $ALL; do
  IFS=: read -r farm error walk <<< "$v"
  name="${farm}_${error}_${walk}"
  if [ -n "$VARIANTS" ] && ! [[ " $VARIANTS " == *" $name "* ]]; then continue; fi
  sim="$(sim_variant "$name" "$error" "$walk")"
  "$BUILD_DIR/devel/lib/picker_localisation/experiment" --map "$WORK/$farm.tmap2" --scenario multi --runs "$RUNS" \
    --seed "$SEED" --duration "$DURATION" --methods "$METHODS" --sim-config "$sim" --tpf-config "$TPF_CONFIG" \
    --out "$WORK/$name" --jobs 2 > "$WORK/$name.log" 2>&1 || { echo "experiment failed: $WORK/$name.log" >&2; exit 1; }
done
python3 scripts/lane_share_report.py "$WORK" "$METHODS"
[ -n "$GRAPH_VARIANTS" ] || exit 0
GRAPH_SEEDS="${GRAPH_SEEDS:-1}"
for name in $GRAPH_VARIANTS; do
  farm="${name%%_*}"
  [ "$farm" = two ] && farm=two_tunnels
  [ -f "$WORK/sim_$name.yaml" ] || { echo "unknown variant $name (run it in the runner first)" >&2; exit 1; }
  for m in raw_fix gnss_tpf graph_tpf; do mkdir -p "$WORK/graph/$name/$m"; done
  k=0
  for seed in $GRAPH_SEEDS; do
    run="$WORK/graph_run_${name}_seed$seed"
    SIM_CONFIG="$WORK/sim_$name.yaml" scripts/bench_gnss_replay.sh "$WORK/$farm.tmap2" "$DURATION" "$seed" "$run" \
      > "$run.json"
    cp "$run/runner/raw_fix/run_0.csv" "$WORK/graph/$name/raw_fix/run_$k.csv"
    cp "$run/runner/gnss_tpf/run_0.csv" "$WORK/graph/$name/gnss_tpf/run_$k.csv"
    cp "$run/graph_errors.csv" "$WORK/graph/$name/graph_tpf/run_$k.csv"
    k=$((k + 1))
  done
done
echo
echo "Through the ROS graph (seeds $GRAPH_SEEDS):"
python3 scripts/lane_share_report.py "$WORK/graph" raw_fix,gnss_tpf,graph_tpf
