#!/usr/bin/env python3
"""Writes a synthetic polytunnel farm as a tmap2 file (JSON, which LCAS tmap2 readers and ours accept as YAML):
LANES lanes of NODES nodes each, LANE_SPACING m apart, NODE_SPACING m between nodes, a headland node at both
ends of every lane joined to its neighbours' (nodes r<lane>_<k> tagged row_<lane>, H<lane>, T<lane>).
Used by the benchmarks for farms we do not ship (large maps, long lanes, the farm variants of the GNSS-only
benchmark).
Usage: make_polytunnel_map.py OUT.tmap2 [LANES=200] [NODES=100] [LANE_SPACING=1.5] [NODE_SPACING=1.0]
         [--tunnels T] [--tunnel-gap M] [--rotation-deg D] [--untagged] [--name NAME]
  --tunnels T      the lanes are split into T tunnels of equal size (the last takes the rest); between two
                   tunnels the headlands are still joined, across an extra gap of --tunnel-gap m (default 2.0)
  --rotation-deg D the farm is rotated by D degrees counter-clockwise about the first headland node
  --untagged       no row_ tags: lanes are found from the graph alone (chains of lane nodes)"""
import argparse
import json
import math


def edge(src, dst):
    return {"edge_id": src + "_" + dst, "node": dst, "action": "move_base"}


def node(name, x, y, neighbours, tag, map_name):
    meta = {"map": map_name, "node": name, "pointset": map_name}
    if tag:
        meta["tag"] = [tag]
    pose = {"position": {"x": x, "y": y, "z": 0.0}, "orientation": {"w": 1.0, "x": 0.0, "y": 0.0, "z": 0.0}}
    return {"meta": meta, "node": {"name": name, "pose": pose, "edges": [edge(name, n) for n in neighbours]}}


def parse():
    parser = argparse.ArgumentParser(usage=__doc__)
    parser.add_argument("out")
    parser.add_argument("lanes", nargs="?", type=int, default=200)
    parser.add_argument("nodes", nargs="?", type=int, default=100)
    parser.add_argument("lane_spacing", nargs="?", type=float, default=1.5)
    parser.add_argument("node_spacing", nargs="?", type=float, default=1.0)
    parser.add_argument("--tunnels", type=int, default=1)
    parser.add_argument("--tunnel-gap", type=float, default=2.0)
    parser.add_argument("--rotation-deg", type=float, default=0.0)
    parser.add_argument("--untagged", action="store_true")
    parser.add_argument("--name", default="polytunnels")
    args = parser.parse_args()
    if args.lanes < 1 or args.nodes < 2 or args.lane_spacing <= 0 or args.node_spacing <= 0:
        parser.error("need LANES >= 1, NODES >= 2 and positive spacings")
    if not 1 <= args.tunnels <= args.lanes:
        parser.error("--tunnels must be in [1, LANES]")
    return args


def main():
    args = parse()
    lanes, per = args.lanes, args.nodes
    per_tunnel = lanes // args.tunnels
    cos_r, sin_r = math.cos(math.radians(args.rotation_deg)), math.sin(math.radians(args.rotation_deg))

    def place(x, y):
        return cos_r * x - sin_r * y, sin_r * x + cos_r * y

    nodes = []
    for lane in range(lanes):
        tunnel = min(lane // per_tunnel, args.tunnels - 1)
        y = args.lane_spacing * lane + args.tunnel_gap * tunnel
        tag = None if args.untagged else "row_%03d" % lane
        for k in range(per):
            nb = []
            if k > 0:
                nb.append("r%d_%d" % (lane, k - 1))
            if k < per - 1:
                nb.append("r%d_%d" % (lane, k + 1))
            if k == 0:
                nb.append("H%d" % lane)
            if k == per - 1:
                nb.append("T%d" % lane)
            nodes.append(node("r%d_%d" % (lane, k), *place(args.node_spacing * (k + 1), y), nb, tag, args.name))
        for head, x, k in (("H", 0.0, 0), ("T", args.node_spacing * (per + 1), per - 1)):
            nb = ["r%d_%d" % (lane, k)]
            if lane > 0:
                nb.append("%s%d" % (head, lane - 1))
            if lane < lanes - 1:
                nb.append("%s%d" % (head, lane + 1))
            nodes.append(node("%s%d" % (head, lane), *place(x, y), nb, None, args.name))
    doc = {"name": args.name, "metric_map": args.name, "pointset": args.name,
           "transformation": {"child": "topo_map", "parent": "map",
                              "rotation": {"w": 1.0, "x": 0.0, "y": 0.0, "z": 0.0},
                              "translation": {"x": 0.0, "y": 0.0, "z": 0.0}},
           "meta": {"last_updated": "generated"}, "nodes": nodes}
    with open(args.out, "w") as f:
        json.dump(doc, f)
    print("%s: %d nodes, %d lanes" % (args.out, len(nodes), lanes))


if __name__ == "__main__":
    main()
