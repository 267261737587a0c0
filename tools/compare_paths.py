#!/usr/bin/python3
"""How far apart two runs' crack paths lie: the convergence of a path in the step, the grid or a setting.

    /usr/bin/python3 tools/compare_paths.py A B [--cell 1.0]

A and B are run directories (each with a solid.h5), or directories of runs (as
tools/layered_sweep.py writes them: one subdirectory per case), in which case every case
present in both is compared. For each pair, the final crack path of crack 0 of each run is
read, and over the shorter path (the one that ends first in arc length) the distance of each of
its crack particles from the other path's polyline is taken, up to the end of the shorter path.
Prints, per case, both reaches (arc length), the largest and the mean distance in metres and in
cells (--cell, the grid's cell size, default 1 m as in the layered scenes), and where along the
shorter path the largest lies. Exit 0; a case missing its solid.h5 is reported, not fatal.
"""

import argparse
import math
import os
import sys

import layered_sweep


def final_path(run):
    xs, ys = layered_sweep.final_path(run)  # crack 0 in the last frame of solid.h5
    return list(zip(xs, ys))


def arc(path):
    s = [0.0]
    for (ax, ay), (bx, by) in zip(path, path[1:]):
        s.append(s[-1] + math.hypot(bx - ax, by - ay))
    return s


def distance_to(path, x, y):
    """Distance of (x, y) from the polyline `path`."""
    best = math.inf
    for (ax, ay), (bx, by) in zip(path, path[1:]):
        dx, dy = bx - ax, by - ay
        n2 = dx * dx + dy * dy
        t = 0.0 if n2 == 0 else max(0.0, min(1.0, ((x - ax) * dx + (y - ay) * dy) / n2))
        best = min(best, math.hypot(x - ax - t * dx, y - ay - t * dy))
    return best


def compare(a, b, cell):
    pa, pb = final_path(a), final_path(b)
    la, lb = arc(pa)[-1], arc(pb)[-1]
    short, other = (pa, pb) if la <= lb else (pb, pa)
    s = arc(short)
    d = [distance_to(other, x, y) for x, y in short]
    worst = max(range(len(d)), key=lambda i: d[i])
    return la, lb, d[worst], sum(d) / len(d), s[worst]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--cell", type=float, default=1.0, help="m, the grid's cell size (default 1)")
    args = ap.parse_args()
    if os.path.exists(os.path.join(args.a, "solid.h5")):
        cases = [("", args.a, args.b)]
    else:
        names = sorted(n for n in os.listdir(args.a) if os.path.isdir(os.path.join(args.a, n)))
        cases = [(n, os.path.join(args.a, n), os.path.join(args.b, n)) for n in names
                 if os.path.isdir(os.path.join(args.b, n))]
    if not cases:
        sys.exit("compare_paths: no run (a directory with solid.h5) or common case in %s and %s" % (args.a, args.b))
    print("| case | reach A (m) | reach B (m) | largest distance (m) | (cells) | at arc (m) | mean distance (cells) |")
    print("|---|---|---|---|---|---|---|")
    for name, a, b in cases:
        try:
            la, lb, worst, mean, where = compare(a, b, args.cell)
        except (OSError, KeyError) as e:
            print("| %s | %s |" % (name or a, "not compared: %s" % e))
            continue
        print("| %s | %.2f | %.2f | %.3f | %.3f | %.2f | %.3f |" % (name or a, la, lb, worst, worst / args.cell, where,
                                                                  mean / args.cell))


if __name__ == "__main__":
    main()
