#!/usr/bin/python3
"""Writes rviz/picker_localisation.rviz for N pickers and K robots (defaults: config/pickers.yaml, 1 robot).

usage: make_rviz_config.py [--pickers FILE] [--robots K] [--out FILE]
Per picker: belief markers (graph coloured by mass, label), estimate (pose with covariance), ground truth
(simulation). Per robot: robot model, both scans, people markers, planner candidates. Plus the map and tf.
"""
import argparse
import colorsys
import os

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))


def colour(i, n):
    r, g, b = colorsys.hsv_to_rgb(i / max(n, 1), 0.8, 1.0)
    return "%d; %d; %d" % (r * 255, g * 255, b * 255)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pickers", default=os.path.join(HERE, "..", "config", "pickers.yaml"))
    ap.add_argument("--robots", type=int, default=1)
    ap.add_argument("--out", default=os.path.join(HERE, "..", "rviz", "picker_localisation.rviz"))
    a = ap.parse_args()
    with open(a.pickers) as f:
        ids = [p["id"] for p in yaml.safe_load(f)["pickers"]]
    displays = [
        {"Class": "rviz/Grid", "Name": "Grid", "Enabled": True, "Cell Size": 5, "Plane Cell Count": 12,
         "Color": "160; 160; 164", "Alpha": 0.4, "Offset": {"X": 20, "Y": -15, "Z": 0}, "Value": True},
        {"Class": "rviz/MarkerArray", "Name": "Topological map", "Enabled": True,
         "Marker Topic": "/topological_map/markers", "Queue Size": 100, "Value": True},
        {"Class": "rviz/TF", "Name": "TF", "Enabled": False, "Show Names": False, "Marker Scale": 1, "Value": False},
    ]
    for i, pid in enumerate(ids):
        c = colour(i, len(ids))
        displays.append({"Class": "rviz/Group", "Name": pid, "Enabled": True, "Value": True, "Displays": [
            {"Class": "rviz/MarkerArray", "Name": "Belief", "Enabled": True,
             "Marker Topic": "/pickers/%s/markers" % pid, "Queue Size": 100, "Value": True},
            {"Class": "rviz/PoseWithCovariance", "Name": "Estimate", "Enabled": True,
             "Topic": "/pickers/%s/estimate" % pid, "Shape": "Axes", "Axes Length": 1.5, "Axes Radius": 0.15,
             "Covariance": {"Value": True, "Position": {"Alpha": 0.3, "Color": c, "Scale": 1, "Value": True},
                            "Orientation": {"Value": False}}, "Value": True},
            {"Class": "rviz/Pose", "Name": "Ground truth", "Enabled": True,
             "Topic": "/pickers/%s/ground_truth" % pid, "Shape": "Arrow", "Color": c, "Alpha": 1,
             "Shaft Length": 0.8, "Shaft Radius": 0.12, "Head Length": 0.4, "Head Radius": 0.25, "Value": True},
        ]})
    for k in range(1, a.robots + 1):
        r = "robot_%d" % k
        displays.append({"Class": "rviz/Group", "Name": r, "Enabled": True, "Value": True, "Displays": [
            {"Class": "rviz/RobotModel", "Name": "Robot model", "Enabled": True,
             "Robot Description": "%s/robot_description" % r, "TF Prefix": "", "Visual Enabled": True,
             "Alpha": 1, "Value": True},
            {"Class": "rviz/LaserScan", "Name": "Scan front", "Enabled": True, "Topic": "/%s/scan_front" % r,
             "Style": "Points", "Size (Pixels)": 3, "Color Transformer": "FlatColor", "Color": "0; 255; 0",
             "Queue Size": 10, "Value": True},
            {"Class": "rviz/LaserScan", "Name": "Scan rear", "Enabled": True, "Topic": "/%s/scan_rear" % r,
             "Style": "Points", "Size (Pixels)": 3, "Color Transformer": "FlatColor", "Color": "255; 255; 0",
             "Queue Size": 10, "Value": True},
            {"Class": "rviz/MarkerArray", "Name": "People", "Enabled": True,
             "Marker Topic": "/%s/people/markers" % r, "Queue Size": 100, "Value": True},
            {"Class": "rviz/MarkerArray", "Name": "Planner", "Enabled": True,
             "Marker Topic": "/%s/nbs_candidates" % r, "Queue Size": 100, "Value": True},
        ]})
    config = {
        "Panels": [{"Class": "rviz/Displays", "Name": "Displays", "Property Tree Widget": {"Expanded": None,
                                                                                        "Splitter Ratio": 0.5}}],
        "Visualization Manager": {
            "Class": "", "Displays": displays, "Enabled": True, "Name": "root",
            "Global Options": {"Background Color": "48; 48; 48", "Default Light": True, "Fixed Frame": "map",
                               "Frame Rate": 30},
            "Tools": [{"Class": "rviz/MoveCamera"}, {"Class": "rviz/Select"}, {"Class": "rviz/Measure"}],
            "Value": True,
            "Views": {"Current": {"Class": "rviz/TopDownOrtho", "Angle": 0, "Name": "Current View",
                                  "Near Clip Distance": 0.01, "Scale": 16, "Target Frame": "<Fixed Frame>",
                                  "X": 22, "Y": -17, "Invert Z Axis": False}, "Saved": None},
        },
        "Window Geometry": {"Displays": {"collapsed": False}, "Height": 800, "Width": 1280, "X": 0, "Y": 0},
    }
    with open(a.out, "w") as f:
        f.write("# Generated by scripts/make_rviz_config.py (%d pickers, %d robot(s)); edit the script, not this file.\n"
                % (len(ids), a.robots))
        yaml.safe_dump(config, f, default_flow_style=False, sort_keys=False)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
