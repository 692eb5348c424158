#!/usr/bin/python3
"""Prints the robot's URDF with every link and joint name prefixed by "<robot_id>/".

Used by launch files:  <param name="robot_description" command="$(find picker_localisation)/scripts/robot_description.py robot_1"/>
An optional second argument names another template (default: config/robot/thorvald.urdf.in).
"""
import os
import sys


def main():
    if len(sys.argv) < 2 or sys.argv[1] in ("-h", "--help"):
        sys.stderr.write("usage: robot_description.py ROBOT_ID [TEMPLATE]\n")
        return 1
    robot_id = sys.argv[1].strip("/")
    here = os.path.dirname(os.path.abspath(__file__))
    template = sys.argv[2] if len(sys.argv) > 2 else os.path.join(here, "..", "config", "robot", "thorvald.urdf.in")
    try:
        with open(template) as f:
            text = f.read()
    except OSError as e:
        sys.stderr.write("robot_description.py: %s: %s\n" % (template, e.strerror))
        return 2
    sys.stdout.write(text.replace("@PREFIX@", robot_id + "/" if robot_id else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
