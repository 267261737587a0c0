#!/usr/bin/env python3
"""Row-by-row differences between two KGD runs' history.csv files.

Usage: compare_runs.py REFERENCE_RUN OTHER_RUN [--sigma0 PA] [--notch M] [--every S] [--window S]
       compare_runs.py --self-test

Compares the output rows both runs share (times equal to 10 ms) once the
reference crack is three notch lengths long: half-length, mouth opening, net inlet pressure
(inlet pressure less sigma0) and fluid front, as OTHER / REFERENCE - 1. Prints
every row and the worst absolute difference of each. --every S keeps only
the rows at multiples of S seconds: runs written with fine rows
(output.interval_s=0.01) compared at a scene's own rows (0.25). --window S
compares each quantity's centred moving mean over S seconds instead of the
row itself: a crack grown in discrete steps has a sawtooth (tools/sawtooth.py),
and two runs whose steps fall at other times differ row by row by its phase;
the means over a growth cycle or more take the phase out and leave the trend.
Standard library only.
"""
import argparse
import csv
import math
import os
import sys
import tempfile


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


def moving_mean(t, y, window):
    """y's centred mean over [t_i - window / 2, t_i + window / 2] at every t_i (t ascending)."""
    means = []
    lo = hi = 0
    total = 0.0
    for ti in t:
        while hi < len(t) and t[hi] <= ti + window / 2:
            total += y[hi]
            hi += 1
        while t[lo] < ti - window / 2:
            total -= y[lo]
            lo += 1
        means.append(total / (hi - lo))
    return means


COLUMNS = ("crack_length_m", "mouth_opening_m", "inlet_pressure_pa", "front_position_m")


def load(run, sigma0, window):
    """{time rounded to 10 ms: (half-length, mouth opening, net inlet pressure, front)}, each
    the row's value or, with window > 0, its centred moving mean over window seconds."""
    rows = read_history(run, ("time_s",) + COLUMNS, "compare_runs")
    rows.sort(key=lambda r: float(r["time_s"]))
    t = [float(r["time_s"]) for r in rows]
    cols = [[float(r[c]) - (sigma0 if c == "inlet_pressure_pa" else 0) for r in rows] for c in COLUMNS]
    if window > 0:
        cols = [moving_mean(t, c, window) for c in cols]
    return {round(ti, 2): tuple(c[i] for c in cols) for i, ti in enumerate(t)}


NAMES = ("half-length", "mouth opening", "net inlet pressure", "fluid front")


def compare(a, b, notch, every, show=print):
    """Worst |b / a - 1| of each quantity over the rows both hold (at multiples of every, if
    > 0) once a's crack is three notch lengths long, and the number of rows compared."""
    worst = [0.0] * 4
    compared = 0
    for t in sorted(a):
        if t not in b:
            continue
        if every > 0 and abs(t / every - round(t / every)) > 1e-6:
            continue
        ref, oth = a[t], b[t]
        if ref[0] < 3 * notch:
            continue
        d = [o / r - 1 if r != 0 else float("inf") for o, r in zip(oth, ref)]
        worst = [max(w, abs(v)) for w, v in zip(worst, d)]
        compared += 1
        show(f"t {t:8.3f} s: " + ", ".join(f"{n} {v:+.4f}" for n, v in zip(NAMES, d)))
    return worst, compared


def discrete_toughness_run(folder, step, offset, q=4e-4, e_prime=1e7, k_ic=2.5e4, sigma0=1e5):
    """Writes folder/history.csv of a quasi-static toughness crack (uniform net pressure p on a
    half-length l: a wing stores pi p l^2 / E', K_I = p sqrt(pi l)) fed Q t and grown in steps
    of `step` on the lattice offset + k step whenever K_I reaches K_Ic: the sawtooth of discrete
    growth with no dynamics (docs/verification.md, "The floor a discrete step sets")."""
    os.makedirs(folder, exist_ok=True)
    length = offset
    with open(os.path.join(folder, "history.csv"), "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(("time_s",) + COLUMNS)
        for i in range(1, 501):
            t = 0.01 * i
            volume = q * t
            while volume * e_prime / (math.pi * (length + step) ** 2) * math.sqrt(math.pi * (length + step)) >= k_ic:
                length += step
            p = volume * e_prime / (math.pi * length ** 2)
            out.writerow((f"{t:.2f}", length, 4 * p * length / e_prime, p + sigma0, length))


def self_test():
    """Two discrete-growth runs whose steps fall half a step apart: row by row they differ by
    about the sawtooth's depth (1.5 step / l on the pressure, step / l on the length); their
    moving means over n >= 3 growth cycles agree within a quarter of step / l (a boxcar over n
    periods leaves at most depth / (4 n) of a sawtooth of that depth, twice that between two
    runs in opposite phase: 2 x 1.5 / 12 = 0.25 step / l)."""
    with tempfile.TemporaryDirectory() as tmp:
        step = 0.01
        a_dir, b_dir = os.path.join(tmp, "a"), os.path.join(tmp, "b")
        discrete_toughness_run(a_dir, step, 0.1)
        discrete_toughness_run(b_dir, step, 0.1 + step / 2)
        rows, _ = compare(load(a_dir, 1e5, 0), load(b_dir, 1e5, 0), 0.1, 0, show=lambda _: None)
        means, n = compare(load(a_dir, 1e5, 0.5), load(b_dir, 1e5, 0.5), 0.1, 0, show=lambda _: None)
    depth = step / 0.3   # step / l at the first compared rows (three notch lengths)
    print(f"compare_runs self-test: {n} rows; rows differ by {rows[0]:.4f} / {rows[2]:.4f} "
          f"(length / pressure), means over 0.5 s by {means[0]:.4f} / {means[2]:.4f}; step / l {depth:.4f}")
    failures = []
    if not rows[2] > 0.75 * depth:
        failures.append(f"the rows' pressures should differ by about 1.5 step / l, not {rows[2]:.4f}")
    if not (means[0] < 0.25 * depth and means[2] < 0.25 * depth):
        failures.append(f"the means should agree within a quarter of step / l, not {means[0]:.4f} / {means[2]:.4f}")
    for f in failures:
        print("FAIL: " + f)
    return 1 if failures else 0


def main():
    if "--self-test" in sys.argv[1:]:
        sys.exit(self_test())
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("reference")
    parser.add_argument("other")
    parser.add_argument("--sigma0", type=float, default=1e5, help="confining stress, Pa (default 1e5)")
    parser.add_argument("--notch", type=float, default=0.15, help="notch length, m (default 0.15)")
    parser.add_argument("--every", type=float, default=0, help="compare only rows at multiples of this, s")
    parser.add_argument("--window", type=float, default=0,
                        help="compare centred moving means over this many seconds (default 0: the rows)")
    args = parser.parse_args()
    if not (args.every >= 0):
        sys.exit(f"compare_runs: --every must be >= 0 s, not {args.every}")
    if not (args.window >= 0):
        sys.exit(f"compare_runs: --window must be >= 0 s, not {args.window}")
    a, b = load(args.reference, args.sigma0, args.window), load(args.other, args.sigma0, args.window)
    worst, compared = compare(a, b, args.notch, args.every)
    if compared == 0:
        sys.exit("compare_runs: no common output row once the crack is three notch lengths long")
    print(f"{compared} rows; worst: " + ", ".join(f"{n} {w:.4f}" for n, w in zip(NAMES, worst)))


if __name__ == "__main__":
    main()
