#!/usr/bin/env python3
"""Per variant and per picker right-lane share and topological error of the runner's methods against raw_fix.
Reads DIR/<variant>/<method>/run_<k>.csv (experiment --out DIR/<variant>). Prints one markdown table over the
variants and, per variant, the pickers whose share fell more than 0.2 below their own raw fix's.
Usage: lane_share_report.py DIR METHODS(comma-separated, raw_fix first)"""
import collections
import csv
import glob
import os
import sys


def picker_scores(path):
    acc = collections.defaultdict(lambda: [0, 0, 0.0, 0])  # right, applicable, topological sum, samples
    for r in csv.DictReader(open(path)):
        a = acc[r["picker_id"]]
        if int(r["topological"]) >= 0:
            a[2] += int(r["topological"])
            a[3] += 1
        if r["lane_applicable"] == "1":
            a[1] += 1
            a[0] += r["in_true_lane"] == "1"
    return {p: (a[0] / a[1] if a[1] else float("nan"), a[2] / a[3] if a[3] else float("nan"))
            for p, a in acc.items()}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    root, methods = sys.argv[1], sys.argv[2].split(",")
    variants = sorted(d for d in os.listdir(root) if os.path.isdir(os.path.join(root, d, methods[0])))
    print("| variant | pickers | " + " | ".join("%s lane / topo" % m for m in methods) +
          " | worst picker (lane - raw) | pickers > 0.2 below raw |")
    print("|---|---|" + "---|" * len(methods) + "---|---|")
    failures = []
    for v in variants:
        scores = collections.defaultdict(dict)
        for m in methods:
            for f in glob.glob(os.path.join(root, v, m, "run_*.csv")):
                run = os.path.basename(f)[4:-4]
                for picker, s in picker_scores(f).items():
                    scores[(int(run), picker)][m] = s
        keys = [k for k in sorted(scores) if all(m in scores[k] for m in methods)]
        cells, worst, below = [], {}, {}
        for m in methods:
            lane = [scores[k][m][0] for k in keys if scores[k][m][0] == scores[k][m][0]]
            topo = [scores[k][m][1] for k in keys]
            cells.append("%.3f / %.1f" % (sum(lane) / len(lane), sum(topo) / len(topo)))
        base = methods[0]
        tail = []
        for m in methods[1:]:
            d = [(scores[k][m][0] - scores[k][base][0], k) for k in keys if scores[k][base][0] == scores[k][base][0]]
            worst_d = min(d)
            bad = [x for x in d if x[0] < -0.2]
            tail.append("%s %.2f" % (m, worst_d[0]))
            below[m] = len(bad)
            if m == methods[-1]:
                failures += [(v, k, x) for x, k in bad]
        print("| %s | %d | %s | %s | %s |" % (v, len(keys), " | ".join(cells), ", ".join(tail),
                                             ", ".join("%s %d" % (m, below[m]) for m in methods[1:])))
    for v, k, x in failures:
        print("%s: run %d %s: %s %.2f below its raw fix" % (v, k[0], k[1], methods[-1], -x))


if __name__ == "__main__":
    main()
