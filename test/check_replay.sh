#!/usr/bin/env bash
# Replay is deterministic: a bag recorded from the simulated farm (record.launch), replayed twice through
# replay.launch, gives the same beliefs and errors both times. Usage: check_replay.sh [WORK_DIR]
set -u
work="${1:-$(mktemp -d)}"
mkdir -p "$work"
rm -f "$work"/*.bag "$work"/*.csv
export PATH=/usr/bin:$PATH ROS_HOSTNAME=localhost
here="$(cd "$(dirname "$0")" && pwd)"
launch_on_own_master() {  # log_name args...
  local log="$work/$1.log"; shift
  local port=$((20000 + RANDOM % 20000))
  ROS_MASTER_URI="http://localhost:$port" timeout 300 roslaunch -p "$port" "$@" >"$log" 2>&1
  local rc=$?
  [ $rc -eq 124 ] && { echo "FAIL: $log timed out"; tail -20 "$log"; exit 1; }
  return 0
}
echo "== recording the simulated farm (70 s simulated) =="
launch_on_own_master record "$here/replay_record.launch" bag:="$work/raw.bag"
[ -s "$work/raw.bag" ] || { echo "FAIL: no bag recorded"; tail -30 "$work/record.log"; exit 1; }
rosbag info "$work/raw.bag" | grep -E "duration|messages|topics" | head -3
for run in 1 2; do
  echo "== replay $run =="
  launch_on_own_master "replay$run" picker_localisation replay.launch bag:="$work/raw.bag" rate:=2.0 \
    duration:=45 output_csv:="$work/errors$run.csv" output_bag:="$work/out$run.bag"
  [ -s "$work/errors$run.csv" ] || { echo "FAIL: replay $run wrote no errors"; tail -30 "$work/replay$run.log"; exit 1; }
  grep -A8 "tracking errors" "$work/replay$run.log" | head -8
done
sleep 2  # let the output recorders close their bags
exec "$here/compare_replays.py" "$work/out1.bag" "$work/out2.bag" "$work/errors1.csv" "$work/errors2.csv"
