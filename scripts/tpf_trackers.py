#!/usr/bin/python3
"""Starts one tpf_tracker per picker listed in a pickers file (config/pickers.yaml).

Adding a picker is one entry in the pickers file: no code or launch edit. Each picker gets its own node
(`tpf_tracker_<id>`, in this script's namespace), its own private parameters and its own topics
(/pickers/<id>/...). Used by launch/trackers.launch:

  <node pkg="picker_localisation" type="tpf_trackers.py" name="tpf_trackers"
        args="--pickers-file F --map-file M --tpf-params P"/>

Per tracker it sets the private parameters picker_id, tpf_params_file, map_file (when given), and any
`tpf:` mapping of the picker's entry (e.g. `tpf: {num_particles: 2000}`) as overrides, then launches the
node with roslaunch's script API (respawned when it dies). On shutdown it stops the trackers it started.
"""
import argparse
import os
import signal
import sys
import time

import rosgraph
import roslaunch.core
import roslaunch.scriptapi
import yaml


def read_pickers(path):
    with open(path) as f:
        doc = yaml.safe_load(f) or {}
    pickers = doc.get("pickers") if isinstance(doc, dict) else None
    if not isinstance(pickers, list) or not pickers:
        raise ValueError("%s: expected a non-empty list under 'pickers'" % path)
    ids = []
    for k, entry in enumerate(pickers):
        if not isinstance(entry, dict) or not entry.get("id"):
            raise ValueError("%s: picker entry %d has no id" % (path, k))
        if entry["id"] in ids:
            raise ValueError("%s: duplicate picker id '%s'" % (path, entry["id"]))
        ids.append(str(entry["id"]))
    return pickers


def main(argv):
    argv = [a for a in argv if ":=" not in a]  # roslaunch adds __name:= / __log:=
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pickers-file", required=True)
    parser.add_argument("--map-file", default="")
    parser.add_argument("--tpf-params", default="")
    parser.add_argument("--output", default="screen", choices=["screen", "log"])
    parser.add_argument("--no-respawn", action="store_true")
    args = parser.parse_args(argv)
    try:
        pickers = read_pickers(args.pickers_file)
    except (OSError, ValueError, yaml.YAMLError) as e:
        sys.stderr.write("tpf_trackers: %s\n" % e)
        return 2

    namespace = os.environ.get("ROS_NAMESPACE", "/")
    if not namespace.endswith("/"):
        namespace += "/"
    master = rosgraph.Master("/tpf_trackers")
    launch = roslaunch.scriptapi.ROSLaunch()
    launch.start()
    processes = []
    for entry in pickers:
        pid = str(entry["id"])
        name = "tpf_tracker_" + pid
        base = namespace + name + "/"
        if args.tpf_params:
            master.setParam(base + "tpf_params_file", args.tpf_params)
        if args.map_file:
            master.setParam(base + "map_file", args.map_file)
        overrides = entry.get("tpf") or {}
        if not isinstance(overrides, dict):
            sys.stderr.write("tpf_trackers: picker %s: 'tpf' must be a mapping, ignored\n" % pid)
            overrides = {}
        for key, value in overrides.items():
            master.setParam(base + str(key), value)
        master.setParam(base + "picker_id", pid)
        node = roslaunch.core.Node("picker_localisation", "tpf_tracker", name=name, namespace=namespace,
                                   output=args.output, respawn=not args.no_respawn, respawn_delay=1.0)
        processes.append((pid, launch.launch(node)))
        print("tpf_trackers: started %s%s for picker %s" % (namespace, name, pid))

    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    while not stop:
        time.sleep(0.2)
    launch.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
