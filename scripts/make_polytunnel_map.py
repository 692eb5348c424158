#!/usr/bin/env python3
"""Writes a synthetic polytunnel farm as a tmap2 file (JSON, which LCAS tmap2 readers and ours accept as YAML):
LANES lanes of NODES nodes each, LANE_SPACING m apart, NODE_SPACING m between nodes, a headland node at both
ends of every lane joined to its neighbours' (nodes r<lane>_<k> tagged row_<lane>, H<lane>, T<lane>).
Used by the benchmarks for farms we do not ship (large maps, long lanes).
Usage: make_polytunnel_map.py OUT.tmap2 [LANES=200] [NODES=100] [LANE_SPACING=1.5] [NODE_SPACING=1.0]"""
import json
import sys


def edge(src, dst):
    return {"edge_id": src + "_" + dst, "node": dst, "action": "move_base"}


def node(name, x, y, neighbours, tag=None):
    meta = {"map": "polytunnels", "node": name, "pointset": "polytunnels"}
    if tag:
        meta["tag"] = [tag]
    pose = {"position": {"x": x, "y": y, "z": 0.0}, "orientation": {"w": 1.0, "x": 0.0, "y": 0.0, "z": 0.0}}
    return {"meta": meta, "node": {"name": name, "pose": pose, "edges": [edge(name, n) for n in neighbours]}}


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    lanes = int(sys.argv[2]) if len(sys.argv) > 2 else 200
    per = int(sys.argv[3]) if len(sys.argv) > 3 else 100
    lane_spacing = float(sys.argv[4]) if len(sys.argv) > 4 else 1.5
    node_spacing = float(sys.argv[5]) if len(sys.argv) > 5 else 1.0
    nodes = []
    for lane in range(lanes):
        y = lane_spacing * lane
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
            nodes.append(node("r%d_%d" % (lane, k), node_spacing * (k + 1), y, nb, "row_%03d" % lane))
        for head, x, k in (("H", 0.0, 0), ("T", node_spacing * (per + 1), per - 1)):
            nb = ["r%d_%d" % (lane, k)]
            if lane > 0:
                nb.append("%s%d" % (head, lane - 1))
            if lane < lanes - 1:
                nb.append("%s%d" % (head, lane + 1))
            nodes.append(node("%s%d" % (head, lane), x, y, nb))
    doc = {"name": "polytunnels", "metric_map": "polytunnels", "pointset": "polytunnels",
           "transformation": {"child": "topo_map", "parent": "map",
                              "rotation": {"w": 1.0, "x": 0.0, "y": 0.0, "z": 0.0},
                              "translation": {"x": 0.0, "y": 0.0, "z": 0.0}},
           "meta": {"last_updated": "generated"}, "nodes": nodes}
    with open(out, "w") as f:
        json.dump(doc, f)
    print("%s: %d nodes, %d lanes" % (out, len(nodes), lanes))


if __name__ == "__main__":
    main()
