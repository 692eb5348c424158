#!/usr/bin/env bash
# Soak run (a script, not a ctest): the demo graph (launch/demo.launch: farm_sim
# with every simulated sensor, gnss_ingest, per robot rfid_ranging / uwb_ranging / leg_detector / nbs_planner,
# tpf_tracker, evaluator) with PICKERS pickers for DURATION simulated seconds. Every node process's resident memory
# and CPU time are sampled from /proc every few wall seconds; the last line is one JSON object: per node the RSS after
# warm-up (the first quarter of the run), at the end and its maximum, the growth (end vs warm-up) and the trend
# (least-squares rise after warm-up) in %, the mean CPU
# in cores, whether every node was still alive at the end, and the evaluator's right-lane share over all pickers.
# Run it at a RATE the machine keeps up with (total CPU well below its cores): a saturated machine fills the
# subscriber queues, and their memory is not the nodes'.
# Usage: scripts/soak.sh [PICKERS=30] [DURATION=1800] [RATE=4] [ROBOTS=2] [WORK_DIR]
set -eo pipefail
cd "$(dirname "$0")/.."
PICKERS="${1:-30}"
DURATION="${2:-1800}"
RATE="${3:-4}"
ROBOTS="${4:-2}"
WORK="${5:-$(mktemp -d)}"
BUILD_DIR="${BUILD_DIR:-build}"
mkdir -p "$WORK"
WORK="$(realpath "$WORK")"
export PATH=/usr/bin:/bin:$PATH ROS_HOSTNAME=localhost ROS_HOME="$WORK/ros_home"
mkdir -p "$ROS_HOME"
# shellcheck disable=SC1091
source "$BUILD_DIR/devel/setup.bash"
python3 - "$PICKERS" > "$WORK/pickers.yaml" <<'PY'
import sys
print("pickers:")
for k in range(1, int(sys.argv[1]) + 1):
    print("  - id: picker_%d\n    gnss_topic: /pickers/picker_%d/fix\n    rfid_tags: [rfid_%04d]\n"
          "    uwb_tag: uwb_%04d" % (k, k, k, k))
PY
port=$((20000 + RANDOM % 20000))
export ROS_MASTER_URI="http://localhost:$port"
roslaunch -p "$port" picker_localisation demo.launch pickers_file:="$WORK/pickers.yaml" robots:="$ROBOTS" \
  duration:="$DURATION" rate_factor:="$RATE" > "$WORK/launch.log" 2>&1 &
launch=$!
trap 'kill -INT $launch 2>/dev/null || true' EXIT
# Sampler: every node process under roslaunch (named by its __name:=), RSS and utime+stime, every 5 wall s, until
# roslaunch ends. The evaluator is required: when it has scored DURATION simulated seconds, the launch ends.
python3 - "$launch" "$WORK/samples.csv" "$WORK/alive.txt" <<'PY'
import os, sys, time
launch, out, alive_out = int(sys.argv[1]), sys.argv[2], sys.argv[3]
tick = os.sysconf("SC_CLK_TCK")
def children(pid):
    try:
        with open("/proc/%d/task/%d/children" % (pid, pid)) as f:
            return [int(c) for c in f.read().split()]
    except OSError:
        return []
def name(pid):
    with open("/proc/%d/cmdline" % pid, "rb") as f:
        args = f.read().decode(errors="replace").split("\0")
    ns = ""
    with open("/proc/%d/environ" % pid, "rb") as f:
        for e in f.read().decode(errors="replace").split("\0"):
            if e.startswith("ROS_NAMESPACE="):
                ns = e[len("ROS_NAMESPACE="):].strip("/") + "/"
    for a in args:
        if a.startswith("__name:="):
            return ns.lstrip("/") + a[len("__name:="):]
    base = [os.path.basename(a) for a in args[:2] if a]
    return ns.lstrip("/") + (base[-1] if base else str(pid))
seen = {}
with open(out, "w") as f:
    f.write("wall_s,node,pid,rss_kb,cpu_s\n")
    t0 = time.time()
    while os.path.exists("/proc/%d" % launch):
        for pid in children(launch):
            try:
                n = name(pid)
                if n.startswith("rosmaster") or n == "rosout":
                    continue
                with open("/proc/%d/status" % pid) as s:
                    rss = next(int(l.split()[1]) for l in s if l.startswith("VmRSS"))
                with open("/proc/%d/stat" % pid) as s:
                    fields = s.read().rsplit(")", 1)[1].split()
                cpu = (int(fields[11]) + int(fields[12])) / tick
            except (OSError, StopIteration, ValueError):
                continue
            seen[n] = time.time() - t0
            f.write("%.1f,%s,%d,%d,%.2f\n" % (time.time() - t0, n, pid, rss, cpu))
        f.flush()
        time.sleep(5)
with open(alive_out, "w") as f:
    last = max(seen.values()) if seen else 0
    for n, t in sorted(seen.items()):
        f.write("%s %d\n" % (n, 1 if last - t < 30 else 0))
PY
wait $launch || true
trap - EXIT
python3 - "$WORK/samples.csv" "$WORK/alive.txt" "$PICKERS" "$DURATION" "$RATE" "$ROBOTS" "$WORK/launch.log" <<'PY'
import csv, json, re, sys
samples, alive_file, pickers, duration, rate, robots, log = sys.argv[1:8]
rows = list(csv.DictReader(open(samples)))
alive = dict(l.split() for l in open(alive_file))
by_node = {}
for r in rows:
    by_node.setdefault(r["node"], []).append((float(r["wall_s"]), int(r["rss_kb"]), float(r["cpu_s"])))
end = max(t for v in by_node.values() for t, _, _ in v)
nodes = {}
for n, v in sorted(by_node.items()):
    warm = [s for s in v if s[0] >= end / 4]
    if len(warm) < 2:
        continue
    rss_warm, rss_end = warm[0][1] / 1024.0, v[-1][1] / 1024.0
    rss_max = max(s[1] for s in warm) / 1024.0
    cores = (v[-1][2] - v[0][2]) / max(v[-1][0] - v[0][0], 1e-9)
    # Trend: least-squares line through the RSS after warm-up, its rise over that span in % of the mean (a node
    # whose memory follows its load, uwb_ranging with the tags in range, fluctuates without growing).
    ts, rs = [s[0] for s in warm], [s[1] / 1024.0 for s in warm]
    mt, mr = sum(ts) / len(ts), sum(rs) / len(rs)
    var = sum((t - mt) ** 2 for t in ts)
    slope = sum((t - mt) * (r - mr) for t, r in zip(ts, rs)) / var if var > 0 else 0.0
    nodes[n] = {"rss_warm_mb": round(rss_warm, 1), "rss_end_mb": round(rss_end, 1), "rss_max_mb": round(rss_max, 1),
                "growth_pct": round(100.0 * (rss_end - rss_warm) / rss_warm, 1),
                "trend_pct": round(100.0 * slope * (ts[-1] - ts[0]) / mr, 1), "cpu_cores": round(cores, 3),
                "alive_at_end": alive.get(n) == "1"}
text = open(log, errors="replace").read()
# The evaluator keeps every sample for its table (memory grows with `duration` by design): not a robot node.
robot_nodes = {n: v for n, v in nodes.items() if n != "evaluator"}
m = re.search(r"^all\s+(\d+)\s+([\d.]+)\s+[\d.]+\s+([\d.]+)\s+[\d.]+\s+([\d.]+)", text, re.M)
print(json.dumps({"pickers": int(pickers), "duration_s": float(duration), "rate_factor": float(rate),
                  "robots": int(robots), "wall_s": round(end, 1),
                  "max_growth_pct_robot_nodes": max(v["growth_pct"] for v in robot_nodes.values()),
                  "max_trend_pct_robot_nodes": max(v["trend_pct"] for v in robot_nodes.values()),
                  "total_rss_end_mb": round(sum(v["rss_end_mb"] for v in nodes.values()), 1),
                  "total_cpu_cores": round(sum(v["cpu_cores"] for v in nodes.values()), 3),
                  "all_alive": all(v["alive_at_end"] for v in robot_nodes.values()),
                  "right_lane_share": float(m.group(4)) if m else None,
                  "euclidean_error_m": float(m.group(2)) if m else None,
                  "evaluator_finished": "REQUIRED process [evaluator" in text, "nodes": nodes}))
PY
