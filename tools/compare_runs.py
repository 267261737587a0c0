#!/usr/bin/env python3
"""Row-by-row differences between two KGD runs' history.csv files.

Usage: compare_runs.py REFERENCE_RUN OTHER_RUN [--sigma0 PA] [--notch M] [--every S]

Compares the output rows both runs share (times equal to 10 ms) once the
reference crack is three notch lengths long: half-length, mouth opening, net inlet pressure
(inlet pressure less sigma0) and fluid front, as OTHER / REFERENCE - 1. Prints
every row and the worst absolute difference of each. --every S keeps only
the rows at multiples of S seconds: runs written with fine rows
(output.interval_s=0.01) compared at a scene's own rows (0.25). Standard
library only.
"""
import argparse
import csv
import os
import sys


def read_history(run, need, prog):
    """RUN/history.csv's rows (dicts); exits naming the file if it cannot be read or lacks a column."""
    path = os.path.join(run, "history.csv")
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        sys.exit(f"{prog}: cannot read {path}: {e.strerror}")
    if rows and any(k not in rows[0] for k in need):
        sys.exit(f"{prog}: {path} lacks one of the columns {', '.join(need)}")
    return rows


def load(run):
    need = ("time_s", "crack_length_m", "mouth_opening_m", "inlet_pressure_pa", "front_position_m")
    return {round(float(r["time_s"]), 2): r for r in read_history(run, need, "compare_runs")}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("reference")
    parser.add_argument("other")
    parser.add_argument("--sigma0", type=float, default=1e5, help="confining stress, Pa (default 1e5)")
    parser.add_argument("--notch", type=float, default=0.15, help="notch length, m (default 0.15)")
    parser.add_argument("--every", type=float, default=0, help="compare only rows at multiples of this, s")
    args = parser.parse_args()
    if not (args.every >= 0):
        sys.exit(f"compare_runs: --every must be >= 0 s, not {args.every}")
    a, b = load(args.reference), load(args.other)
    names = ("half-length", "mouth opening", "net inlet pressure", "fluid front")
    worst = [0.0] * 4
    compared = 0
    for t in sorted(a):
        if t not in b:
            continue
        if args.every > 0 and abs(t / args.every - round(t / args.every)) > 1e-6:
            continue
        x, y = a[t], b[t]
        if float(x["crack_length_m"]) < 3 * args.notch:
            continue
        ref = (float(x["crack_length_m"]), float(x["mouth_opening_m"]),
               float(x["inlet_pressure_pa"]) - args.sigma0, float(x["front_position_m"]))
        oth = (float(y["crack_length_m"]), float(y["mouth_opening_m"]),
               float(y["inlet_pressure_pa"]) - args.sigma0, float(y["front_position_m"]))
        d = [o / r - 1 if r != 0 else float("inf") for o, r in zip(oth, ref)]
        worst = [max(w, abs(v)) for w, v in zip(worst, d)]
        compared += 1
        print(f"t {t:8.3f} s: " + ", ".join(f"{n} {v:+.4f}" for n, v in zip(names, d)))
    if compared == 0:
        sys.exit("compare_runs: no common output row once the crack is three notch lengths long")
    print(f"{compared} rows; worst: " + ", ".join(f"{n} {w:.4f}" for n, w in zip(names, worst)))


if __name__ == "__main__":
    main()
