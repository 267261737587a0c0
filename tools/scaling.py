#!/usr/bin/python3
"""How cost grows with size: the solid, the fluid and the coupling, log-log.

    /usr/bin/python3 tools/scaling.py [--bin DIR] [--out DIR] [--quick]

Runs the three benchmarks over a range of sizes and prints, for each, the
cost per step against the size and the order of growth (the least-squares
slope of log cost against log size; 1 is linear):

- the solid (hfmpm-bench-solid --uncracked-only): wall time per step and
  particle-steps/s from about 1e3 to 1e6 particles, 1 and 2 threads;
- the fluid (hfmpm-bench-fluid): wall time per step against its particle count;
- the coupling (hfmpm-bench-coupling, stand-in sides, inproc and ipc,
  exchanging every step): overhead per step from 10 to 5,000 crack particles.

Prints the tables and writes them to OUT/scaling.md, with OUT/scaling-solid.png,
scaling-fluid.png and scaling-coupling.png (default OUT: docs/img). Needs matplotlib for the PNGs (Debian's
python3-matplotlib; without it the tables are still printed). The machine's
load shows in every figure: run it on a quiet machine, and read the slopes,
not the absolute times, on a busy one.
"""
import argparse
import math
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(cmd):
    try:
        out = subprocess.run(cmd, check=True, capture_output=True, text=True)
    except FileNotFoundError:
        sys.exit(f"scaling: {cmd[0]} not found; build first (cmake --build --preset release) or pass --bin")
    except subprocess.CalledProcessError as e:
        sys.exit(f"scaling: {' '.join(cmd)} failed (exit {e.returncode}): {e.stderr.strip()}")
    return out.stdout


def slope(xs, ys):
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    sxx = sum((a - mx) ** 2 for a in lx)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sxx if sxx > 0 else float("nan")


def solid(bindir, quick):
    cells = [16, 32, 64, 128] if quick else [16, 32, 64, 128, 256, 500]
    rows = []  # (particles, threads, seconds per step, particle-steps/s)
    for c in cells:
        particles = 4 * c * c
        steps = max(20, min(2000, int(4e7 / particles)))
        text = run([os.path.join(bindir, "hfmpm-bench-solid"), "--cells", str(c), "--steps", str(steps),
                    "--uncracked-only"])
        for line in text.splitlines():
            m = re.match(r"\| uncracked block \| (\d+) \| (\d) \| (\d+) \| ([\d.]+) \| ([\d.e+]+) \|", line)
            if m:
                n, threads, st, wall = int(m.group(1)), int(m.group(2)), int(m.group(3)), float(m.group(4))
                rows.append((n, threads, wall / st, n * st / wall))
    return rows


def fluid(bindir, quick):
    cells = [10, 100, 1000] if quick else [10, 100, 1000, 10000, 100000]
    text = run([os.path.join(bindir, "hfmpm-bench-fluid"), "--cells", ",".join(map(str, cells)), "--steps",
                "2000" if quick else "10000"])
    rows = []  # (particles, seconds per particle-step x particles = seconds per step)
    for line in text.splitlines():
        f = line.split()
        if len(f) == 5 and f[0].isdigit():
            particles, rate = int(f[1]), float(f[3])
            rows.append((particles, particles / rate))
    return rows


def coupling(bindir, quick):
    sizes = [10, 100, 1000] if quick else [10, 100, 1000, 5000]
    text = run([os.path.join(bindir, "hfmpm-bench-coupling"), "--particles", ",".join(map(str, sizes)),
                "--transports", "inproc,ipc", "--steps", "1000" if quick else "4000"])
    rows = []  # (crack particles, transport, overhead us per step), exchange and control every step
    for line in text.splitlines():
        m = re.match(r"\| (\d+) \| (\w+) \| 1 \| 1 \| [\d.]+ \| ([\d.]+) \|", line)
        if m:
            rows.append((int(m.group(1)), m.group(2), float(m.group(3))))
    return rows


def plot(path, title, xlabel, ylabel, series):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"scaling: matplotlib missing; {path} not drawn")
        return
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for label, xs, ys in series:
        ax.loglog(xs, ys, "o-", label=f"{label} (slope {slope(xs, ys):.2f})")
    # A line of slope 1 through the first series' first point, for the eye.
    xs, ys = series[0][1], series[0][2]
    ax.loglog([xs[0], xs[-1]], [ys[0], ys[0] * xs[-1] / xs[0]], "k:", label="linear")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"scaling: wrote {path}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bin", default=os.path.join(ROOT, "build", "release", "bin"))
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "img"))
    parser.add_argument("--quick", action="store_true", help="fewer and smaller sizes (a smoke run)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    lines = []

    s = solid(args.bin, args.quick)
    lines += ["## Solid (uncracked block, 2 x 2 particles per cell)", "",
              "| particles | threads | ms per step | particle-steps/s |", "|---|---|---|---|"]
    lines += [f"| {n} | {t} | {1e3 * sec:.3f} | {rate:.3g} |" for n, t, sec, rate in s]
    series = []
    for t in (1, 2):
        pts = [(n, sec) for n, tt, sec, _ in s if tt == t]
        if len(pts) > 1:
            series.append((f"{t} thread{'s' if t > 1 else ''}", [p[0] for p in pts], [p[1] for p in pts]))
            big = [(n, sec) for n, sec in pts if n >= 1e4]
            order = slope([p[0] for p in big], [p[1] for p in big]) if len(big) > 1 else float("nan")
            lines.append(f"\n{t} thread(s): time per step grows as N^{slope(series[-1][1], series[-1][2]):.2f} "
                         f"overall, N^{order:.2f} from 1e4 particles on.")
    plot(os.path.join(args.out, "scaling-solid.png"), "Solid: cost per step", "particles", "s per step", series)

    f = fluid(args.bin, args.quick)
    lines += ["", "## Fluid (filled channel, inlet and outlet flow, 1 thread)", "",
              "| particles | us per step |", "|---|---|"]
    lines += [f"| {n} | {1e6 * sec:.1f} |" for n, sec in f]
    if len(f) > 1:
        lines.append(f"\nTime per step grows as N^{slope([p[0] for p in f], [p[1] for p in f]):.2f}.")
        plot(os.path.join(args.out, "scaling-fluid.png"), "Fluid: cost per step", "fluid particles", "s per step",
             [("fluid", [p[0] for p in f], [p[1] for p in f])])

    c = coupling(args.bin, args.quick)
    lines += ["", "## Coupling overhead (stand-in sides, exchange and control round every step)", "",
              "| crack particles | transport | overhead (us per step) |", "|---|---|---|"]
    lines += [f"| {n} | {t} | {us:.1f} |" for n, t, us in c]
    series = []
    for t in ("inproc", "ipc"):
        pts = [(n, us) for n, tt, us in c if tt == t]
        if len(pts) > 1:
            series.append((t, [p[0] for p in pts], [p[1] * 1e-6 for p in pts]))
            lines.append(f"\n{t}: overhead grows as N^{slope(series[-1][1], series[-1][2]):.2f} "
                         "(a fixed wake-up cost plus the payload).")
    if series:
        plot(os.path.join(args.out, "scaling-coupling.png"), "Coupling: overhead per step", "crack particles",
             "s per step", series)

    text = "\n".join(lines) + "\n"
    print(text)
    with open(os.path.join(args.out, "scaling.md"), "w") as out:
        out.write(text)


if __name__ == "__main__":
    main()
