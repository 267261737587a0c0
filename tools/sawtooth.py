#!/usr/bin/env python3
"""How much a KGD run's inlet pressure and mouth opening swing about their trend.

Usage: sawtooth.py RUN [RUN ...] [--from S] [--to S] [--window S] [--sigma0 PA]

A crack that grows in discrete steps gives a sawtooth: each step dips the
inlet pressure, which then recovers until the next. Two runs whose steps fall
at other times (half the time step, another bulk modulus) then differ row by
row by up to the sawtooth's depth. For each run's history.csv this prints the
RMS and the largest |y / trend - 1| of the net inlet pressure (inlet pressure
less sigma0) and of the mouth opening, where the trend is y's mean over
[t - window / 2, t + window / 2], over the rows from --from to --to. Write the
run with fine rows (output.interval_s=0.01) for it to see the steps. Standard
library only.
"""
import argparse
import math
import sys

from compare_runs import moving_mean, read_history


def swing(t, y, start, end, window):
    """RMS and largest relative deviation of y from its centred moving mean."""
    devs = []
    for ti, yi, trend in zip(t, y, moving_mean(t, y, window)):
        if start <= ti <= end and trend != 0:
            devs.append(yi / trend - 1)
    if not devs:
        return None
    return math.sqrt(sum(d * d for d in devs) / len(devs)), max(abs(d) for d in devs), len(devs)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--from", dest="start", type=float, default=0, help="first row's time, s (default 0)")
    parser.add_argument("--to", dest="end", type=float, default=math.inf, help="last row's time, s (default: all)")
    parser.add_argument("--window", type=float, default=0.5, help="width of the moving mean, s (default 0.5)")
    parser.add_argument("--sigma0", type=float, default=1e5, help="confining stress, Pa (default 1e5)")
    args = parser.parse_args()
    if not (args.window > 0):
        sys.exit(f"sawtooth: --window must be > 0 s, not {args.window}")
    if not (args.end > args.start):
        sys.exit(f"sawtooth: --to ({args.end}) must be after --from ({args.start})")
    for run in args.runs:
        rows = read_history(run, ("time_s", "mouth_opening_m", "inlet_pressure_pa"), "sawtooth")
        if not rows:
            sys.exit(f"sawtooth: {run}/history.csv has no rows")
        t = [float(r["time_s"]) for r in rows]
        p = [float(r["inlet_pressure_pa"]) - args.sigma0 for r in rows]
        w = [float(r["mouth_opening_m"]) for r in rows]
        sp, sw = swing(t, p, args.start, args.end, args.window), swing(t, w, args.start, args.end, args.window)
        if sp is None or sw is None:
            sys.exit(f"sawtooth: {run} has no row from {args.start} s to {args.end} s")
        print(f"{run}: net inlet pressure RMS {sp[0]:.4f} largest {sp[1]:.4f}; "
              f"mouth opening RMS {sw[0]:.4f} largest {sw[1]:.4f} ({sp[2]} rows)")


if __name__ == "__main__":
    main()
