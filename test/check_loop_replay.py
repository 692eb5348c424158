#!/usr/bin/python3
"""Checks a looped replay (check_replay.sh, last step): listens while replay.launch plays a bag with -l.

usage: check_loop_replay.py WALL_SECONDS
Subscribes (arrival order, wall time) to the fleet's beliefs, /observations, /person_observations, the error
samples and /diagnostics, until every check below holds or WALL_SECONDS have passed (a generous deadline: a loaded
machine is slow). The clock jumps back at each start of the bag. Passes when, after the first jump:
  - every picker's beliefs continue (>= 10 beliefs spanning >= 15 s of stamps on the new time line);
  - observations of gnss, rfid, uwb and the LiDAR people still arrive;
  - the evaluator samples the new time line;
  - gnss_ingest, rfid_ranging, uwb_ranging, leg_detector, tpf_tracker and the evaluator each report the jump
    ("clock jumps back" >= 1 in their diagnostics).
Exit status 0 when all hold, 1 otherwise; prints what it found.
"""
import sys
import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from picker_localisation.msg import Observation, PickerBeliefArray, TrackingError

JUMP = 10.0  # s: a stamp this far below the newest one seen is the clock jumping back


def main():
    wall = float(sys.argv[1]) if len(sys.argv) > 1 else 60.0
    rospy.init_node("check_loop_replay", anonymous=True)
    beliefs, observations, errors, jumps_by_node = [], [], [], {}

    def on_beliefs(m):
        for b in m.beliefs:
            if b.estimated_node:  # a filter reset by the jump publishes an empty belief until it re-initialises
                beliefs.append((time.time(), b.picker_id, b.header.stamp.to_sec()))

    def on_observation(m):
        observations.append((time.time(), m.sensor, m.header.stamp.to_sec()))

    def on_error(m):
        errors.append((time.time(), m.header.stamp.to_sec()))

    def on_diagnostics(m):
        for s in m.status:
            for kv in s.values:
                if kv.key.startswith("clock jumps back"):
                    name = s.name.split(":")[0].strip("/ ")
                    jumps_by_node[name] = max(jumps_by_node.get(name, 0), int(float(kv.value)))

    subs = [rospy.Subscriber("/pickers/beliefs", PickerBeliefArray, on_beliefs, queue_size=100),
            rospy.Subscriber("/observations", Observation, on_observation, queue_size=1000),
            rospy.Subscriber("/person_observations", Observation, on_observation, queue_size=1000),
            rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=100)]
    for p in ("picker_1", "picker_2", "picker_3"):
        subs.append(rospy.Subscriber("/pickers/%s/error" % p, TrackingError, on_error, queue_size=100))
    end = time.time() + wall
    while time.time() < end and not rospy.is_shutdown():
        time.sleep(0.5)
        if evaluate(list(beliefs), list(observations), list(errors), dict(jumps_by_node), report=False):
            break
    return 0 if evaluate(list(beliefs), list(observations), list(errors), dict(jumps_by_node), report=True) else 1


def evaluate(beliefs, observations, errors, jumps_by_node, report):
    """True when every check holds on these messages (copies: the subscribers keep appending); prints each
    check when `report`."""
    # The first jump: the first belief stamped JUMP s below the newest before it.
    newest, jump_wall = -1e18, None
    for w, _, s in beliefs:
        if s < newest - JUMP:
            jump_wall = w
            break
        newest = max(newest, s)
    old_line = newest  # stamps of the first pass reach this; the new time line starts far below it
    ok = True

    def check(cond, what):
        nonlocal ok
        if report:
            print(("ok: " if cond else "FAIL: ") + what)
        ok = ok and cond

    check(jump_wall is not None, "the clock jumped back (%d beliefs)" % len(beliefs))
    if jump_wall is None:
        return False
    for p in sorted({b[1] for b in beliefs}):
        # Beliefs on the new time line (stamped well below the first pass's newest), in the second pass.
        run = []
        for w, q, s in beliefs:
            if q != p or w < jump_wall or s >= old_line - JUMP:  # another picker, the first pass, stragglers
                continue
            if run and s < run[-1] - JUMP:
                break  # the next loop
            run.append(s)
        span = (max(run) - min(run)) if run else 0.0
        check(len(run) >= 10 and span >= 15.0,
              "%s: %d beliefs on the new time line, spanning %.1f s of stamps" % (p, len(run), span))
    for sensor in ("gnss", "rfid", "uwb", "lidar"):
        n = sum(1 for w, s, _ in observations if s == sensor and w >= jump_wall)
        check(n >= 1, "%s observations after the jump: %d" % (sensor, n))
    n = sum(1 for w, _ in errors if w >= jump_wall + 2.0)
    check(n >= 5, "evaluator error samples after the jump: %d" % n)
    for node in ("gnss_ingest", "rfid_ranging", "uwb_ranging", "leg_detector", "tpf_tracker", "evaluator"):
        seen = {k: v for k, v in jumps_by_node.items() if node in k}
        check(bool(seen) and min(seen.values()) >= 1, "%s reports the jump: %s" % (node, seen or "no status"))
    return ok


if __name__ == "__main__":
    sys.exit(main())
