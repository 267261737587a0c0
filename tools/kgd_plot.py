#!/usr/bin/python3
"""Compare a KGD run with the plane-strain hydraulic fracture solutions and plot it.

    /usr/bin/python3 tools/kgd_plot.py RUN_DIR [--out RUN_DIR/kgd.png]
    /usr/bin/python3 tools/kgd_plot.py RUN_DIR --E 1e7 --nu 0.25 --mu 0.01 --Q 2.5e-4 \
        --KIc 100 --sigma0 1e5 [--t0 0.05]

The physical parameters come from RUN_DIR/scene.json (the scene the run used, every default
filled in, written by every run): E, nu and K_Ic of the material at the crack's mouth, mu of
the fluid, Q = 2 x the inlet's flow rate (the half model's wing takes Q/2; the rate of a
ramp's end), sigma0 = -yy of the in-situ stress there, t0 = half the inlet ramp's duration
(the time shift of a linear ramp). A flag overrides the scene's value.

RUN_DIR is an `hfmpm run --out` directory (history.csv; solid.h5 and fluid.h5 for the
profiles at the end). Q is the TOTAL injection rate (both wings; the simulated wing takes
Q/2). Writes one PNG with four panels (mouth opening, half-length and net inlet pressure
against time with the M-vertex, K-vertex and Geertsma-de Klerk curves; width and net pressure
along the crack at the end) and prints the errors against the vertex the dimensionless
toughness Km selects, at the history rows where the crack is at least three times its
initial length. Uses Debian's python3-numpy, python3-matplotlib and python3-h5py
(tools/bootstrap.sh installs them).

--reference transition (the default) prints the errors against the solution at the run's Km
between the vertices (tools/kgd_transition.py: the same model, zero lag, no leak-off, solved
for any Km; it reduces to the vertices, within 0.04% for Km <= 0.1 and 0.1% for Km >= 10, and
covers 1 <= Km <= 4 where neither vertex applies); --reference vertex prints them against the
vertex Km selects, as before (nothing between Km = 1 and 4); --reference gdk against
Geertsma-de Klerk. The plots show all of them.

References (E' = E/(1-nu^2), mu' = 12 mu, K' = sqrt(32/pi) K_Ic, Q total):
  M-vertex (Spence and Sharp 1985; Adachi and Detournay 2002; Detournay 2004):
    l = 0.6152 (E' Q^3 t^4 / mu')^(1/6), w0 = 1.126 (mu' Q^3 t^2 / E')^(1/6),
    p0 = 0.545 (mu' E'^2 / t)^(1/3)
  K-vertex (uniform pressure, Sneddon's ellipse, LEFM, volume balance):
    l = 2 / pi^(2/3) (E' Q t / K')^(2/3), w0 = pi^(-1/3) (K'^2 Q t / E'^2)^(1/3),
    p0 = pi^(1/3) / 8 (K'^4 / (E' Q t))^(1/3)
  Geertsma and de Klerk (1969), q = Q/2 into one wing, G = E / (2 (1 + nu)):
    w0 = 1.32 (8 (1 - nu) mu q^3 / G)^(1/6) t^(1/3), l = 0.48 (8 G q^3 / ((1 - nu) mu))^(1/6) t^(2/3)
  Dimensionless toughness Km = K' / (E'^3 mu' Q)^(1/4): M-vertex for Km <~ 1, K-vertex for Km >~ 4.
  Between (and for every Km): tools/kgd_transition.py, l = gamma(Km) (E' Q^3 t^4 / mu')^(1/6),
    w0 = Omega0(Km) (mu' Q^3 t^2 / E')^(1/6), p0 = Pi0(Km) (mu' E'^2 / t)^(1/3).
t0 shifts the simulated time for a ramped injection (t_eff = t - t0; half the ramp time).
"""
import argparse
import json
import csv
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import kgd_transition  # noqa: E402  (the solution between the vertices; its table, standard library only)


def vertices(E, nu, mu, Q, KIc, t):
    """(M-vertex, K-vertex, Geertsma-de Klerk) at t; a vertex that does not exist (no viscosity:
    no M-vertex and no Geertsma-de Klerk; no toughness: no K-vertex) is all NaN."""
    ep = E / (1 - nu * nu)
    mup = 12 * mu
    kp = math.sqrt(32 / math.pi) * KIc
    nan = float("nan")
    m = (nan, nan, nan)
    if mup > 0:
        m = (0.6152 * (ep * Q ** 3 * t ** 4 / mup) ** (1 / 6), 1.126 * (mup * Q ** 3 * t * t / ep) ** (1 / 6),
             0.545 * (mup * ep * ep / t) ** (1 / 3))
    k = (nan, nan, nan)
    if kp > 0:
        k = (2 / math.pi ** (2 / 3) * (ep * Q * t / kp) ** (2 / 3),
             math.pi ** (-1 / 3) * (kp * kp * Q * t / ep ** 2) ** (1 / 3),
             math.pi ** (1 / 3) / 8 * (kp ** 4 / (ep * Q * t)) ** (1 / 3))
    q = Q / 2
    G = E / (2 * (1 + nu))
    gdk = (nan, nan)
    if mu > 0:
        gdk = (0.48 * (8 * G * q ** 3 / ((1 - nu) * mu)) ** (1 / 6) * t ** (2 / 3),
               1.32 * (8 * (1 - nu) * mu * q ** 3 / G) ** (1 / 6) * t ** (1 / 3))
    return m, k, gdk


def km(E, nu, mu, Q, KIc):
    """Km = K' / (E'^3 mu' Q)^(1/4); infinite for an inviscid fluid in a tough rock."""
    return kgd_transition.km_of(E, nu, mu, Q, KIc)


def finite(values):
    """The finite ones of values (a vertex that does not exist is NaN)."""
    return [v for v in values if math.isfinite(v)]


def read_history(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"kgd_plot: {path} has no rows")
    need = ["time_s", "crack_length_m", "mouth_opening_m", "inlet_pressure_pa"]
    for key in need:
        if key not in rows[0]:
            sys.exit(f"kgd_plot: {path} has no column '{key}' (columns: {', '.join(rows[0])})")
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def scene_parameters(run):
    """E, nu, mu, Q, KIc, sigma0 and t0 of a KGD run, from RUN/scene.json."""
    path = os.path.join(run, "scene.json")
    if not os.path.exists(path):
        return {}
    with open(path) as f:
        scene = json.load(f)
    mpm = scene.get("solid", {}).get("mpm")
    fluid = scene.get("fluid", {}).get("mpm")
    if not mpm or not fluid or not mpm.get("cracks"):
        sys.exit(f"kgd_plot: {path} is not a KGD scene (an MPM solid with a crack and an MPM fluid); give the flags")
    crack = mpm["cracks"][0]
    # Where the fluid enters: the first point (a mouth), or the inlet vertex
    # of a crack inside the body (two wings; the half-length is half the crack).
    at = int(crack.get("inlet_vertex", 0))
    mouth = (float(crack["x_m"][at]), float(crack["y_m"][at]))
    region = None  # the last region that holds the mouth, as the solver assigns material
    for r in mpm.get("regions", []):
        box = r.get("rectangle") or {}
        layer = r.get("layer") or {}
        if box and box["x_min_m"] <= mouth[0] <= box["x_max_m"] and box["y_min_m"] <= mouth[1] <= box["y_max_m"]:
            region = r
        elif layer and layer["y_min_m"] <= mouth[1] <= layer["y_max_m"]:
            region = r
    if region is None:
        sys.exit(f"kgd_plot: no region of {path} holds the crack's mouth {mouth}; give the flags")
    material = next(m for m in mpm["materials"] if m["name"] == region["material"])
    inlet = fluid.get("inlet", {}).get("flow_rate_m2_s")
    if not inlet:
        sys.exit(f"kgd_plot: {path} has no flow-rate inlet; give --Q")
    if "ramp" in inlet:
        q, t0 = float(inlet["ramp"]["v1"]), 0.5 * (float(inlet["ramp"]["t1"]) - float(inlet["ramp"].get("t0", 0)))
    elif "constant" in inlet:
        q, t0 = float(inlet["constant"]), 0.0
    else:
        sys.exit(f"kgd_plot: {path}: the inlet's rate is neither a constant nor a ramp; give --Q and --t0")
    symmetric = any("symmetry_x_m" in c and abs(float(c["symmetry_x_m"]) - mouth[0]) < 1e-12
                    for c in mpm.get("constraints", []))
    stress = region.get("initial_stress", {})
    return {"E": float(material["youngs_modulus_pa"]), "nu": float(material["poisson_ratio"]),
            "KIc": float(material.get("toughness_pa_sqrt_m", 0)), "mu": float(fluid["viscosity_pa_s"]),
            "Q": (2 if symmetric else 1) * q, "sigma0": -float(stress.get("yy_pa", 0)), "t0": t0,
            "two_wing": "inlet_vertex" in crack, "inlet_x": mouth[0]}


def wing_lengths(run, inlet_x):
    """Per solid.h5 frame: (start wing, end wing) lengths along x from the inlet, or [] without h5py."""
    try:
        import h5py
    except ImportError:
        return []
    out = []
    with h5py.File(os.path.join(run, "solid.h5"), "r") as f:
        for key in sorted(f["frames"].keys()):
            x = f["frames"][key]["crack0/positions"][:, 0]
            out.append((inlet_x - x[0], x[-1] - inlet_x))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run", help="run directory (history.csv, scene.json, solid.h5, fluid.h5)")
    for name in ("E", "nu", "mu", "Q", "KIc", "sigma0", "t0"):
        ap.add_argument("--" + name, type=float, help="overrides the value from RUN/scene.json")
    ap.add_argument("--out", help="PNG path (default RUN/kgd.png)")
    ap.add_argument("--reference", choices=("transition", "vertex", "gdk"), default="transition",
                    help="print errors against the solution at the run's Km (tools/kgd_transition.py; default), "
                         "the vertex Km selects (none for 1 <= Km <= 4) or Geertsma-de Klerk (length and opening; "
                         "no pressure)")
    a = ap.parse_args()
    from_scene = scene_parameters(a.run)
    for name in ("E", "nu", "mu", "Q", "KIc", "sigma0", "t0"):
        if getattr(a, name) is None:
            if name not in from_scene:
                sys.exit(f"kgd_plot: --{name} is needed: {a.run}/scene.json is missing (runs write it since 3 December)")
            setattr(a, name, from_scene[name])
    print("parameters: " + ", ".join(f"{n} = {getattr(a, n):g}" for n in ("E", "nu", "mu", "Q", "KIc", "sigma0", "t0")))
    h = read_history(os.path.join(a.run, "history.csv"))
    two_wing = from_scene.get("two_wing", False)
    if two_wing:
        # Both wings modelled: the half-length is half the crack (their mean);
        # how far apart the two are is printed at the end.
        h["crack_length_m"] = [0.5 * v for v in h["crack_length_m"]]
        print("two wings from an interior inlet: half-length = crack length / 2")
    t = h["time_s"]
    L0 = h["crack_length_m"][0]
    kmv = km(a.E, a.nu, a.mu, a.Q, a.KIc)
    vertex = 0 if kmv < 1 else 1 if kmv > 4 else None
    print(f"Km = {kmv:.3g}: {'M-vertex' if vertex == 0 else 'K-vertex' if vertex == 1 else 'between the vertices'}")
    compare = vertex
    if a.reference == "gdk":
        compare = 2
        print("errors against Geertsma-de Klerk (q = Q/2 into the wing; no pressure reference)")
    elif a.reference == "transition":
        compare = 3
        print("errors against the solution at this Km (tools/kgd_transition.py)")

    def reference(te):
        if compare == 3:
            return kgd_transition.transition(a.E, a.nu, a.mu, a.Q, a.KIc, te)
        return vertices(a.E, a.nu, a.mu, a.Q, a.KIc, te)[compare]
    # The crack's tip leads the fluid front by the dry zone the discretization
    # leaves (up to a cell); a zero-lag vertex has the two at one point, so the
    # front's error is printed too (column "front err").
    front = h.get("front_position_m")
    print(f"{'t (s)':>8} {'L (m)':>8} {'L ref':>8} {'err':>7} {'front err':>9} {'w0 (mm)':>8} {'w0 ref':>8} {'err':>7} "
          f"{'p_net (kPa)':>11} {'ref':>8} {'err':>7}")
    worst = [0.0, 0.0, 0.0]
    worst_front = 0.0
    for i, ti in enumerate(t):
        te = ti - a.t0
        if te <= 0 or compare is None or h["crack_length_m"][i] < 3 * L0:
            continue
        ref = reference(te)
        if compare == 2:  # Geertsma-de Klerk: (length, opening); no pressure
            ref = (ref[0], ref[1], float("nan"))
        sim = (h["crack_length_m"][i], h["mouth_opening_m"][i], h["inlet_pressure_pa"][i] - a.sigma0)
        err = [(s - r) / r for s, r in zip(sim, ref)]
        err = [0.0 if math.isnan(e) else e for e in err]
        worst = [max(w, abs(e)) for w, e in zip(worst, err)]
        front_err = (front[i] - ref[0]) / ref[0] if front else float("nan")
        if front:
            worst_front = max(worst_front, abs(front_err))
        print(f"{ti:8.3f} {sim[0]:8.4f} {ref[0]:8.4f} {err[0]:+7.3f} {front_err:+9.3f} {1e3 * sim[1]:8.4f} "
              f"{1e3 * ref[1]:8.4f} {err[1]:+7.3f} {1e-3 * sim[2]:11.3f} {1e-3 * ref[2]:8.3f} {err[2]:+7.3f}")
    if compare is not None:
        print(f"worst |error| once L >= 3 L0: length {worst[0]:.3f}, opening {worst[1]:.3f}, pressure {worst[2]:.3f}"
              + (f"; fluid front {worst_front:.3f}" if front else ""))
    if two_wing:
        wings = wing_lengths(a.run, from_scene["inlet_x"])
        if wings:
            apart = max(abs(e - s) / (0.5 * (e + s)) for s, e in wings)
            print(f"wings: at the end {wings[-1][0]:.4f} m and {wings[-1][1]:.4f} m from the inlet; "
                  f"largest difference over the frames {apart:.4f} of their mean")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(2, 2, figsize=(11, 8))
    tt = [x for x in t if x - a.t0 > 0]
    refs = [vertices(a.E, a.nu, a.mu, a.Q, a.KIc, x - a.t0) for x in tt]
    trans = [kgd_transition.transition(a.E, a.nu, a.mu, a.Q, a.KIc, x - a.t0) for x in tt]
    ax[0, 0].plot(t, [1e3 * w for w in h["mouth_opening_m"]], "k.", ms=3, label="hfmpm")
    ax[0, 0].plot(tt, [1e3 * r[0][1] for r in refs], "b-", label="M-vertex")
    ax[0, 0].plot(tt, [1e3 * r[1][1] for r in refs], "r--", label="K-vertex")
    ax[0, 0].plot(tt, [1e3 * r[2][1] for r in refs], "g:", label="Geertsma-de Klerk (q = Q/2)")
    ax[0, 0].plot(tt, [1e3 * r[1] for r in trans], "m-", lw=1, label=f"solution at Km = {kmv:.3g}")
    ax[0, 0].set(xlabel="t (s)", ylabel="mouth opening (mm)")
    shown_w = ([1e3 * r[vertex if vertex is not None else 0][1] for r in refs] + [1e3 * r[2][1] for r in refs]
               + [1e3 * r[1] for r in trans])
    ax[0, 0].set_ylim(0, 1.3 * max(finite([1e3 * w for w in h["mouth_opening_m"]] + shown_w)))
    ax[0, 1].plot(t, h["crack_length_m"], "k.", ms=3, label="hfmpm (tip)")
    if front:
        ax[0, 1].plot(t, front, "c.", ms=2, label="hfmpm (fluid front)")
    ax[0, 1].plot(tt, [r[0][0] for r in refs], "b-", label="M-vertex")
    ax[0, 1].plot(tt, [r[1][0] for r in refs], "r--", label="K-vertex")
    ax[0, 1].plot(tt, [r[2][0] for r in refs], "g:", label="Geertsma-de Klerk")
    ax[0, 1].plot(tt, [r[0] for r in trans], "m-", lw=1, label=f"solution at Km = {kmv:.3g}")
    ax[0, 1].set(xlabel="t (s)", ylabel="half-length (m)")
    # Scale to the run and the selected vertex (the other can be far off).
    shown = [r[vertex if vertex is not None else 0][0] for r in refs] + [r[2][0] for r in refs] + [r[0] for r in trans]
    ax[0, 1].set_ylim(0, 1.3 * max(finite(h["crack_length_m"] + shown)))
    ax[1, 0].plot(t, [1e-3 * (p - a.sigma0) for p in h["inlet_pressure_pa"]], "k.", ms=3, label="hfmpm")
    ax[1, 0].plot(tt, [1e-3 * r[0][2] for r in refs], "b-", label="M-vertex")
    ax[1, 0].plot(tt, [1e-3 * r[1][2] for r in refs], "r--", label="K-vertex")
    ax[1, 0].plot(tt, [1e-3 * r[2] for r in trans], "m-", lw=1, label=f"solution at Km = {kmv:.3g}")
    ax[1, 0].set(xlabel="t (s)", ylabel="net inlet pressure (kPa)")
    # Limits from the run and from the references after the first tenth of
    # the run (the M-vertex pressure diverges as t -> 0).
    net = [1e-3 * (p - a.sigma0) for p in h["inlet_pressure_pa"]]
    late = ([1e-3 * r[v][2] for x, r in zip(tt, refs) for v in (0, 1) if x >= 0.1 * tt[-1]]
            + [1e-3 * r[2] for x, r in zip(tt, trans) if x >= 0.1 * tt[-1]])
    ax[1, 0].set_ylim(min(0.0, min(net)), 1.2 * max(finite(net + late)))
    try:
        import h5py
        with h5py.File(os.path.join(a.run, "solid.h5"), "r") as f:
            last = f["frames"][sorted(f["frames"].keys())[-1]]
            x = last["crack0/positions"][:, 0]
            ax[1, 1].plot(x, 1e3 * last["crack0/width"][:], "k.-", label="width (mm)")
            ax2 = ax[1, 1].twinx()
            ax2.plot(x, 1e-3 * (last["crack0/pressure"][:] - a.sigma0), "c.-", label="net face pressure (kPa)")
            ax2.set_ylabel("net face pressure (kPa)")
        ax[1, 1].set(xlabel="x (m)", ylabel="width (mm)", title=f"along the crack at t = {t[-1]:.3g} s")
    except (OSError, KeyError) as e:
        ax[1, 1].text(0.1, 0.5, f"no profile: {e}")
    for axis in ax.flat[:3]:
        axis.legend(fontsize=8)
        axis.grid(alpha=0.3)
    fig.suptitle(f"KGD: E = {a.E:g} Pa, nu = {a.nu:g}, mu = {a.mu:g} Pa s, Q = {a.Q:g} m^2/s (total), "
                 f"K_Ic = {a.KIc:g}, Km = {kmv:.3g}")
    fig.tight_layout()
    out = a.out or os.path.join(a.run, "kgd.png")
    fig.savefig(out, dpi=110)
    print(f"kgd_plot: wrote {out}")


if __name__ == "__main__":
    main()
