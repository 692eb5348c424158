#!/usr/bin/env bash
# Issue "One options schema": a node given an out-of-range parameter stops with one FATAL line naming the key,
# the value and the allowed range (exit status 1); a node given an unknown parameter (a typo) warns once, naming
# the closest known key, and keeps running. Checked for leg_detector, gnss_ingest and tpf_tracker against a real
# rosmaster (and the FATAL line of uwb_ranging, rfid_ranging, camera_detector, topological_map_server, farm_sim and the evaluator). Usage: check_param_errors.sh PACKAGE_DIR (run through the devel space's env.sh).
set -u
pkg="$1"
map="$pkg/config/maps/riseholme.tmap2"
port=$((21000 + RANDOM % 20000))
export ROS_MASTER_URI="http://localhost:$port" ROS_HOSTNAME=localhost
export ROS_HOME="${ROS_HOME:-$(mktemp -d)}"
rosmaster --core -p "$port" > /dev/null 2>&1 &
master=$!
trap 'kill $master 2>/dev/null' EXIT
for _ in $(seq 300); do rosparam list > /dev/null 2>&1 && break; sleep 0.2; done  # up to a minute: a loaded machine
fail=0
# node args... : run until it exits, at most 60 s (a loaded machine), print stdout+stderr, return the exit status
# (124: still running) (its private parameters are deleted first: rosrun's _key:=value stays on the parameter server)
run() {
  local node="$1"; shift
  rosparam delete "/$node" > /dev/null 2>&1
  timeout 60 rosrun picker_localisation "$node" "$@" 2>&1 | sed 's/\x1b\[[0-9;]*m//g'
  return "${PIPESTATUS[0]}"
}
# pattern node args... : run until `pattern` is in its output (at most 60 s: a loaded machine) and 5 s more, or until
# it exits; print stdout+stderr, return the exit status (124: still running then; it is stopped)
run_until() {
  local pattern="$1" node="$2"; shift 2
  local log pid rc=124
  log="$(mktemp)"
  rosparam delete "/$node" > /dev/null 2>&1
  rosrun picker_localisation "$node" "$@" > "$log" 2>&1 &
  pid=$!
  for _ in $(seq 600); do
    grep -q -- "$pattern" "$log" && { sleep 5; break; }
    kill -0 "$pid" 2> /dev/null || break
    sleep 0.1
  done
  if kill -0 "$pid" 2> /dev/null; then
    kill "$pid"; wait "$pid" 2> /dev/null
  else
    wait "$pid"; rc=$?
  fi
  sed 's/\x1b\[[0-9;]*m//g' "$log"
  rm -f "$log"
  return $rc
}
common_gnss=(_pickers_file:="$pkg/config/pickers.yaml" _datum_file:="$pkg/config/datum.yaml" _map_file:="$map")
common_tpf=(_pickers_file:="$pkg/config/pickers.yaml" _map_file:="$map" _tpf_params_file:="$pkg/config/tpf.yaml")

expect_fatal() { # node key value pattern args...
  local node="$1" key="$2" value="$3" pattern="$4"; shift 4
  local out rc fatal
  out="$(run "$node" "_$key:=$value" "$@")"; rc=$?
  fatal="$(printf '%s\n' "$out" | grep -c 'FATAL')"
  if [ $rc -ne 1 ] || [ "$fatal" -ne 1 ] || ! printf '%s' "$out" | grep 'FATAL' | grep -q -- "$pattern"; then
    echo "FAIL: $node _$key:=$value: rc=$rc, $fatal FATAL line(s), want 1 matching '$pattern':"; printf '%s\n' "$out" | tail -5
    fail=1
  else
    echo "ok: $node _$key:=$value -> $(printf '%s\n' "$out" | grep FATAL | sed 's/.*]: //')"
  fi
}
expect_warning() { # node typo pattern args...
  local node="$1" typo="$2" pattern="$3"; shift 3
  local out rc
  out="$(run_until "$pattern" "$node" "_$typo:=10" "$@")"; rc=$?
  if [ $rc -ne 124 ] || [ "$(printf '%s\n' "$out" | grep -c -- "$pattern")" -ne 1 ] || printf '%s' "$out" | grep -q FATAL; then
    echo "FAIL: $node _$typo:=10: rc=$rc (want 124: still running 5 s after the warning), want one line matching '$pattern':"
    printf '%s\n' "$out" | tail -5
    fail=1
  else
    echo "ok: $node _$typo:=10 -> $(printf '%s\n' "$out" | grep -- "$pattern" | sed 's/.*]: //')"
  fi
}

expect_fatal leg_detector leg_threshold -1 "leg_threshold = -1: must be in \[0, 1\]" _map_file:="$map"
expect_warning leg_detector leg_treshold "unknown key 'leg_treshold' (did you mean 'leg_threshold'?)" _map_file:="$map"
expect_fatal gnss_ingest association_min_probability 0.3 "association_min_probability = 0.3: must be in (0.5, 1\]" \
  "${common_gnss[@]}"
expect_warning gnss_ingest association_min_probabilty \
  "unknown key 'association_min_probabilty' (did you mean 'association_min_probability'?)" "${common_gnss[@]}"
expect_fatal tpf_tracker num_particles 0 "num_particles = 0: must be in .1, 100000." "${common_tpf[@]}"
expect_warning tpf_tracker num_particle "unknown key 'num_particle' (did you mean 'num_particles'?)" "${common_tpf[@]}"
# The other front-ends: the FATAL line (their unknown-key warnings come from the same core::unknownKeys).
expect_fatal uwb_ranging p_min_uwb 2 "p_min_uwb = 2: must be in (0, 1\]" "${common_tpf[@]}"
expect_fatal rfid_ranging d50 -1 "d50 = -1: must be finite and > 0" "${common_tpf[@]}"
expect_fatal camera_detector resize 0 "resize = 0: must be in (0, 4\]"
expect_fatal topological_map_server node_scale 0 "node_scale = 0: must be finite and > 0" _map_file:="$map"
expect_fatal farm_sim clock_step 0 "clock_step = 0: must be finite and > 0" _map_file:="$map"
expect_fatal evaluator sample_rate -1 "sample_rate = -1: must be finite and > 0" _map_file:="$map"
expect_warning evaluator sampel_rate "unknown key 'sampel_rate' (did you mean 'sample_rate'?)" _map_file:="$map" \
  _pickers_file:="$pkg/config/pickers.yaml"
exit $fail
