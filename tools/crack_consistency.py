#!/usr/bin/python3
"""Is a coupled KGD run consistent with itself? Three checks on its last two frames.

    /usr/bin/python3 tools/crack_consistency.py RUN [--frame N]

A coupled run can miss its reference (the vertices, kgd_transition.py) because the solid, the
fluid or their coupling is wrong. These checks split the blame, each against the run's own
numbers only:

1. **Elasticity** (the solid). The opening a straight crack [-L, L] in an infinite plane-strain
   body takes under the face pressure the run's solid carries (net of the confining stress
   sigma0, symmetric about the mouth):
       w(x) = 4 / (pi E') sum_i p_i int_{s_i}^{s_i+1} ln |(a + b) / (a - b)| ds,
       a = sqrt(L^2 - x^2), b = sqrt(L^2 - s^2)
   (Sneddon and Lowengrub 1969, eq. for a symmetric load; the pressure piecewise constant over
   each crack particle's tributary length), against the run's width. A finite box and the
   grid make them differ by a few percent; a crack whose faces misread the body's opening
   differs by more, and unevenly.
2. **Lubrication** (the fluid). The flux Poiseuille gives for the run's width and pressure,
   q = -(w^3 / mu') dp/dx, against the flux that mass balance needs, q = Q/2 - d/dt int_0^x w,
   from two frames.
3. **Volume.** The crack's volume int_0^L w against the injected Q/2 (t - t0) per wing.

Reads RUN/solid.h5 (crack0: positions, width, pressure) and RUN/scene.json (through
kgd_plot.scene_parameters). Uses Debian's python3-numpy and python3-h5py.

    /usr/bin/python3 tools/crack_consistency.py RUN --odd-even

(any run with a fluid, KGD or not) prints instead, over every frame of RUN/fluid.h5, the odd-even
amplitude of the grown crack's opening: the largest |w_i - (w_(i-1) + w_(i+1)) / 2| over the
largest width, for the nodes whose neighbours both lie beyond the first crack's initial length,
the tip and the node before it left out. A smooth
opening has a few 1e-2 at most (kgd-paper-field: 0.025); a crack whose alternate
particles read shut and open approaches 0.5 (docs/verification.md, "Layered medium").
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import kgd_plot  # noqa: E402


def elastic_opening(x_at, edges, p_net, L, ep):
    """Opening at x_at of a crack [-L, L] under a symmetric piecewise-constant net pressure."""
    a = np.sqrt(max(L * L - x_at * x_at, 0.0))
    total = 0.0
    for i, p in enumerate(p_net):
        s = np.linspace(edges[i], edges[i + 1], 65)
        b = np.sqrt(np.maximum(L * L - s * s, 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            kernel = np.log(np.abs((a + b) / (a - b)))
        kernel[~np.isfinite(kernel)] = 0.0  # the log singularity at s = x is integrable
        total += p * np.trapz(kernel, s)
    return 4.0 / (np.pi * ep) * total


def odd_even(run):
    """The grown crack's odd-even amplitude over RUN/fluid.h5's frames: the worst, its time, and when it first
    passed 0.1."""
    import json
    import h5py
    try:
        with open(os.path.join(run, "scene.json")) as f:
            crack = json.load(f)["solid"]["mpm"]["cracks"][0]
    except (OSError, KeyError, IndexError, ValueError) as e:
        sys.exit(f"crack_consistency: {run}/scene.json: no first crack ({e})")
    xs, ys = np.asarray(crack["x_m"], float), np.asarray(crack["y_m"], float)
    notch = float(np.hypot(np.diff(xs), np.diff(ys)).sum())
    worst, at, first = 0.0, None, None
    path = os.path.join(run, "fluid.h5")
    try:
        with h5py.File(path, "r") as f:
            for k in sorted(f["frames"].keys()):
                g = f["frames"][k]
                s, w = g["nodes0"]["arc_length"][:], g["nodes0"]["width"][:]
                # Both neighbours grown (the notch's pre-opening ends at its tip), the tip and the
                # node before it left out (the tip's own curvature).
                i = np.arange(1, len(s) - 2)
                i = i[s[i - 1] > notch * (1 + 1e-9)]
                if len(i) < 3 or not w.max() > 0:
                    continue
                r = float((np.abs(w[i] - 0.5 * (w[i - 1] + w[i + 1]))).max() / w.max())
                t = float(g.attrs["time_s"])
                if r > worst:
                    worst, at = r, t
                if first is None and r > 0.1:
                    first = t
    except (OSError, KeyError) as e:
        sys.exit(f"crack_consistency: {path}: {e}")
    print(f"{run}: odd-even amplitude of the grown crack's opening (beyond {notch:g} m): worst {worst:.3f}"
          + (f" at t = {at:.4g} s" if at is not None else "") + "; above 0.1 "
          + (f"from t = {first:.4g} s" if first is not None else "never"))
    return worst


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run")
    ap.add_argument("--frame", type=int, default=-1, help="frame index (default: the last)")
    ap.add_argument("--odd-even", action="store_true", help="the grown crack's odd-even amplitude over every frame")
    a = ap.parse_args()
    if a.odd_even:
        odd_even(a.run)
        return
    import h5py

    prm = kgd_plot.scene_parameters(a.run)
    if not prm:
        sys.exit(f"crack_consistency: {a.run}/scene.json not found")
    ep = prm["E"] / (1 - prm["nu"] ** 2)
    mup = 12 * prm["mu"]
    path = os.path.join(a.run, "solid.h5")
    try:
        with h5py.File(path, "r") as f:
            keys = sorted(f["frames"].keys())
            if len(keys) < 2:
                sys.exit(f"crack_consistency: {path} has {len(keys)} frame(s); two are needed")
            i1 = a.frame if a.frame >= 0 else len(keys) + a.frame
            if not 1 <= i1 < len(keys):
                sys.exit(f"crack_consistency: --frame {a.frame}: {path} has frames 1 to {len(keys) - 1}")
            frames = []
            for k in (keys[i1 - 1], keys[i1]):
                g = f["frames"][k]
                c = g["crack0"]
                frames.append((float(g.attrs["time_s"]), c["positions"][:, 0], c["width"][:], c["pressure"][:]))
    except (OSError, KeyError) as e:
        sys.exit(f"crack_consistency: {path}: {e}")
    (t0f, x0, w0, _), (t, x, w, p) = frames
    L = x[-1]
    p_net = p - prm["sigma0"]
    edges = np.concatenate([[0.0], 0.5 * (x[1:] + x[:-1]), [L]])
    print(f"{a.run}: t = {t:.4g} s, L = {L:.4g} m, E' = {ep:.4g} Pa, mu' = {mup:.4g} Pa s, "
          f"sigma0 = {prm['sigma0']:.4g} Pa")
    print("1. elasticity: the run's width against the infinite body's opening under the run's face pressure")
    print("     x (m)   p_net (kPa)   w run (mm)   w elastic (mm)   ratio")
    ratios = []
    for i in range(0, len(x) - 1, max(1, (len(x) - 1) // 12)):
        we = elastic_opening(x[i], edges, p_net, L, ep)
        r = w[i] / we if we > 0 else float("nan")
        if we > 0:
            ratios.append(r)
        print(f"   {x[i]:7.4f}   {p_net[i] / 1e3:10.3f}   {w[i] * 1e3:10.4f}   {we * 1e3:14.4f}   {r:6.3f}")
    if ratios:
        print(f"   ratio from {min(ratios):.3f} to {max(ratios):.3f}")

    def volume_to(xx, ww, at):
        m = xx <= at
        xi = np.append(xx[m], at)
        wi = np.append(ww[m], np.interp(at, xx, ww))
        return np.trapz(wi, xi)

    q_half = prm["Q"] / 2
    dt = t - t0f
    print("2. lubrication: Poiseuille's flux for the run's width and pressure against mass balance's")
    print("     x (m)    w (mm)   q Poiseuille   q mass balance   ratio")
    for xv in np.linspace(0.1 * L, 0.9 * L, 9):
        i = int(np.clip(np.searchsorted(x, xv), 1, len(x) - 2))
        dpdx = (p[i + 1] - p[i - 1]) / (x[i + 1] - x[i - 1])
        q_lub = -(w[i] ** 3 / mup) * dpdx
        q_mass = q_half - (volume_to(x, w, x[i]) - volume_to(x0, w0, x[i])) / dt
        print(f"   {x[i]:7.4f}   {w[i] * 1e3:7.4f}   {q_lub:12.4e}   {q_mass:14.4e}   {q_lub / q_mass:6.3f}")
    v = np.trapz(w, x)
    injected = q_half * (t - prm["t0"])
    print(f"3. volume: the crack holds {v:.5g} m^2 per wing; injected {injected:.5g} (ratio {v / injected:.4f})")


if __name__ == "__main__":
    main()
