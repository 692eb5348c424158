#!/usr/bin/env bash
# Reproduces Table II of Navigate-and-Seek with the offline runner: the three scenarios, every row, ten seeded
# runs each. Usage: scripts/table2.sh [OUT_DIR] [extra experiment options, e.g. --duration 300]
# Environment: BUILD_DIR (default build), RUNS (10), SEED (1), JOBS (2), MAP (config/maps/riseholme.tmap2).
# Writes OUT_DIR/<scenario>/{summary.csv,summary.md,errors.png,<method>/run_<k>.csv} and OUT_DIR/table2.md.
set -eo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${BUILD_DIR:-build}"
OUT="${1:-table2}"
shift || true
EXP="$BUILD_DIR/devel/lib/picker_localisation/experiment"
MAP="${MAP:-config/maps/riseholme.tmap2}"
start=$(date +%s)
mkdir -p "$OUT"
: > "$OUT/table2.md"
for scenario in single navigation multi; do
  "$EXP" --map "$MAP" --scenario "$scenario" --runs "${RUNS:-10}" --seed "${SEED:-1}" --jobs "${JOBS:-2}" \
    --out "$OUT/$scenario" "$@"
  cat "$OUT/$scenario/summary.md" >> "$OUT/table2.md"
  echo >> "$OUT/table2.md"
done
echo "table2: $OUT/table2.md in $(( $(date +%s) - start )) s wall"
