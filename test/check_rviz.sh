#!/usr/bin/env bash
# rviz loads rviz/picker_localisation.rviz under Xvfb and renders: the process stays up, the log reports no
# config/plugin errors, and a screenshot of the screen is not blank. Usage: check_rviz.sh OUT.png [LAUNCH [COLOUR...]]
# Each COLOUR (name=R,G,B) must cover at least 20 pixels of the screenshot (within 12 % fuzz): a display drawn in
# that colour rendered.
set -u
out="${1:-$(mktemp --suffix=.png)}"
launch="${2:-$(rospack find picker_localisation)/test/rviz_check.launch}"
shift 2 2>/dev/null || shift $#
colours_expected=("$@")
settle="${RVIZ_SETTLE:-12}"         # wall s before the first screenshot
deadline="${RVIZ_DEADLINE:-60}"     # wall s for rviz to render at all (a loaded machine), retried every 2 s
tries=$(( deadline > settle ? (deadline - settle) / 2 + 1 : 1 ))
export PATH=/usr/bin:$PATH
port=$((20000 + RANDOM % 20000))
export ROS_MASTER_URI="http://localhost:$port" ROS_HOSTNAME=localhost
log="$(mktemp)"; alive="$(mktemp)"
attempt() {
  : > "$alive"
  xvfb-run -a -s "-screen 0 1280x800x24" bash -c "
    roslaunch -p $port '$launch' > '$log' 2>&1 &
    sleep $settle
    for _ in \$(seq $tries); do
      import -window root '$out'
      std=\$(convert '$out' -colorspace Gray -format '%[fx:standard_deviation]' info: 2>/dev/null)
      colours=\$(convert '$out' -format '%k' info: 2>/dev/null)
      awk -v s=\"\$std\" -v c=\"\$colours\" 'BEGIN{exit !(s > 0.05 && c > 50)}' && break
      sleep 2
    done
    # [r]viz: the pattern must not match this script's own command line
    pgrep -f '[r]viz/rviz -d' >/dev/null && echo RVIZ_ALIVE > '$alive'
    rosnode kill -a >/dev/null 2>&1; sleep 1; kill %1 2>/dev/null; wait
  " >/dev/null 2>&1
}
# Debian's rviz under Xvfb aborted at start-up inside its own heap twice in five runs of the suite while a build
# loaded both cores ("malloc(): unaligned tcache chunk detected", "free(): invalid next size", exit code -6), and
# ran fine when started again; not reproduced with the same load in 14 starts alone. A crash by a signal gets up to
# two more starts, each said here; a third crash, or any other failure, fails the test.
for start in 1 2 3; do
  attempt
  grep -q "\[rviz-[0-9]*\] process has died .*exit code -" "$log" || break
  echo "start $start: rviz was killed by a signal: $(grep -m1 -E 'malloc|free\(\)|corrupt|Segmentation' "$log")"
done
fail=0
grep -q RVIZ_ALIVE "$alive" || { echo "FAIL: rviz is not running (once rendered, or after ${deadline} s)"; fail=1; }
if grep -E "PluginlibFactory: The plugin for class|Failed to load|ERROR" "$log" | grep -v -E "media_export|XDG_RUNTIME_DIR"; then
  echo "FAIL: errors in the rviz log above"; fail=1
fi
[ -s "$out" ] || { echo "FAIL: no screenshot"; exit 1; }
std="$(convert "$out" -colorspace Gray -format '%[fx:standard_deviation]' info:)"
colours="$(convert "$out" -format '%k' info:)"
echo "screenshot $out: grey std $std, $colours colours"
awk -v s="$std" 'BEGIN{exit !(s > 0.05)}' || { echo "FAIL: screenshot is nearly uniform"; fail=1; }
[ "$colours" -gt 50 ] || { echo "FAIL: too few colours"; fail=1; }
for expected in "${colours_expected[@]}"; do
  name="${expected%%=*}"; rgb="rgb(${expected#*=})"
  pixels="$(convert "$out" -fuzz 12% -fill black +opaque "$rgb" -fill white -opaque "$rgb" -colorspace Gray \
    -format '%[fx:round(mean*w*h)]' info:)"
  echo "$name $rgb: $pixels pixels"
  [ "${pixels:-0}" -ge 20 ] || { echo "FAIL: nothing drawn in $name $rgb"; fail=1; }
done
[ $fail -eq 0 ] || { echo "--- roslaunch log ---"; tail -40 "$log"; }
rm -f "$log" "$alive"
exit $fail
