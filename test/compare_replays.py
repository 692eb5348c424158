#!/usr/bin/python3
"""Compares the outputs of two replays of one bag (replay.launch output_bag / output_csv).

usage: compare_replays.py OUT1.bag OUT2.bag ERR1.csv ERR2.csv
Beliefs (stamp, picker, MAP node, support, masses, particle count) must be identical up to the evaluator's
last sample minus a margin (later ones may be cut by the launch ending); the error CSVs must be identical.
Exit status 0 when they agree, 1 otherwise; prints what it compared.
"""
import sys

import rosbag

MARGIN = 3.0  # s before the end that both runs certainly processed


def beliefs(path):
    out = {}
    with rosbag.Bag(path) as bag:
        for topic, msg, _ in bag.read_messages():
            if not topic.endswith("/belief"):
                continue
            out.setdefault(msg.picker_id, []).append(
                (round(msg.header.stamp.to_sec(), 6), msg.estimated_node, tuple(msg.nodes),
                 tuple(round(m, 12) for m in msg.masses), msg.particle_count))
    return out


def csv_rows(path):
    with open(path) as f:
        return [line.rstrip("\n") for line in f]


def main(argv):
    if len(argv) != 5:
        sys.stderr.write(__doc__)
        return 2
    e1, e2 = csv_rows(argv[3]), csv_rows(argv[4])
    ok = True
    if len(e1) < 10:
        print("FAIL: only %d error rows in %s" % (len(e1), argv[3]))
        ok = False
    if e1 != e2:
        diff = next((i for i, (a, b) in enumerate(zip(e1, e2)) if a != b), min(len(e1), len(e2)))
        print("FAIL: error CSVs differ (%d vs %d rows), first at row %d:\n  %s\n  %s" %
              (len(e1), len(e2), diff, e1[diff] if diff < len(e1) else "-", e2[diff] if diff < len(e2) else "-"))
        ok = False
    else:
        print("errors: %d rows identical" % len(e1))
    header = e1[0].split(",") if e1 else []
    stamp_col = header.index("stamp") if "stamp" in header else 0
    end = max(float(r.split(",")[stamp_col]) for r in e1[1:]) if len(e1) > 1 else 0.0
    b1, b2 = beliefs(argv[1]), beliefs(argv[2])
    if sorted(b1) != sorted(b2) or not b1:
        print("FAIL: pickers with beliefs differ: %s vs %s" % (sorted(b1), sorted(b2)))
        return 1
    for picker in sorted(b1):
        s1 = [b for b in b1[picker] if b[0] <= end - MARGIN]
        s2 = [b for b in b2[picker] if b[0] <= end - MARGIN]
        if len(s1) < 5:
            print("FAIL: %s: only %d beliefs before %.1f s" % (picker, len(s1), end - MARGIN))
            ok = False
        if s1 != s2:
            diff = next((i for i, (a, b) in enumerate(zip(s1, s2)) if a != b), min(len(s1), len(s2)))
            print("FAIL: %s: beliefs differ (%d vs %d), first at #%d: %s vs %s" %
                  (picker, len(s1), len(s2), diff, s1[diff][:2] if diff < len(s1) else "-",
                   s2[diff][:2] if diff < len(s2) else "-"))
            ok = False
        else:
            print("%s: %d beliefs identical up to %.1f s" % (picker, len(s1), end - MARGIN))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
