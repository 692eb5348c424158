#!/bin/bash
# bench_fleet runs end to end (its own rosmaster, gnss_ingest, tpf_tracker): its last line is one JSON object
# with every field the issue names, and every fix published in the window became a belief (both ways of
# listening). Functional only: no figure of speed is asserted here.
set -euo pipefail
bench="$1"
# The two processes listened to both ways, and gnss_ingest inside the tracker's process (picker_fleet).
for mode in "--listen per_picker" "--listen fleet" "--listen fleet --trackers in_process"; do
  out=$("$bench" --pickers 5 --rate 2 --duration 3 --warmup 1 --particles 200 $mode 2>/dev/null | tail -1)
  echo "$out"
  python3 - "$out" <<'PY'
import json, sys
d = json.loads(sys.argv[1])
for k in ["pickers", "rate_hz", "duration_s", "particles", "cpu_cores", "rss_mb", "latency_p50_ms",
          "latency_p99_ms", "observations", "beliefs"]:
    assert k in d, "missing " + k
assert d["pickers"] == 5 and d["particles"] == 200, d
assert d["observations"] >= 25, d      # 5 pickers x 2 Hz x 3 s (first and last may fall outside)
assert d["beliefs"] == d["observations"], d
assert d["rss_mb"] > 0 and d["cpu_cores"] >= 0 and d["latency_p99_ms"] >= d["latency_p50_ms"] > 0, d
PY
done
echo "bench_fleet: OK"
