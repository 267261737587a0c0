#!/usr/bin/python3
"""Run time against error for the viscosity-dominated KGD scene: one command, a grid of settings.

    /usr/bin/python3 tools/kgd_sweep.py [--out DIR] [--bin DIR] [--quick] [--only NAME...] [--force]

Runs scenarios/kgd-viscosity.scene (or --scene) once per case below, one run at a time (wall
times must not be contended; do not run anything else meanwhile), and for each run takes
- the worst |error| of half-length, mouth opening and net inlet pressure (and of the fluid
  front) against the M-vertex over the history rows with L >= 3 L0, as tools/kgd_plot.py
  computes them (its `vertices`), with E, nu, K_Ic, mu, Q (total, 2 x the wing's ramped
  rate), the confining stress and t0 (half the ramp) read from the validated scene;
- the wall time and the solid / fluid / coupling split from run.json.
Writes OUT/sweep.csv, OUT/sweep.md (the Markdown table, also printed) and OUT/sweep.png (error
against wall time, log-log, Pareto fronts marked). Each run is OUT/NAME; a run whose
sweep-case.json, history.csv and run.json say it completed with the same scene and settings is
reused (an interrupted sweep resumes), unless --force (use it after a rebuild: the binaries are
not part of what is compared). Failed runs are rerun.

The grid: one-at-a-time variations around the scene's own settings, plus a few combinations.
Cell sizes keep the box, the notch and the crack between two node rows: the grid's y bounds
become +-(k + 1/2) h (k the smallest with at least 3 cells between the body and the grid's
edge, as the scene has) and x_max the body plus 3 cells, so y = 0 is never a node row.

--quick runs the CI-size scene (kgd-viscosity-ci.scene) to 3.5 s (the first rows with
L >= 3 L0) with a subset of the cases: a few minutes, to test the tool, not to choose settings.
Uses Python's standard library, Debian's python3-numpy/-matplotlib (the PNG) and
tools/kgd_plot.py. tools/stability_sweep.py imports the run helpers below.
"""
import argparse
import csv
import hashlib
import json
import math
import os
import signal
import subprocess
import sys
import time

TOOLS = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(TOOLS)
RUNNING = set()  # the runs in progress (Popen), so an interrupted sweep can stop them
STOPPING = []  # set when the sweep is interrupted: runs ending then are not recorded as finished
OUTPUTS = ("history.csv", "run.json", "solid.h5", "fluid.h5", "solid.xmf", "fluid.xmf", "sweep-case.json")


# ---------------------------------------------------------------- shared run helpers
def die(msg):
    sys.exit(f"{os.path.basename(sys.argv[0])}: {msg}")


def hfmpm_path(bin_dir):
    """The hfmpm program in bin_dir, with its sides beside it (it launches them from its own folder)."""
    exe = os.path.join(bin_dir, "hfmpm")
    if not os.path.isdir(bin_dir):
        die(f"--bin {bin_dir}: no such directory (build with `cmake --preset release && cmake --build "
            f"--preset release`, or point --bin at a copy of build/release/bin)")
    for name in ("hfmpm", "hfmpm-solid", "hfmpm-fluid"):
        p = os.path.join(bin_dir, name)
        if not (os.path.isfile(p) and os.access(p, os.X_OK)):
            die(f"--bin {bin_dir}: no executable {name} there (hfmpm starts hfmpm-solid and hfmpm-fluid "
                f"from its own directory)")
    return exe


def set_args(sets):
    out = []
    for s in sets:
        out += ["--set", s]
    return out


def scene_tree(value):
    """`hfmpm validate --json`'s scene -> nested dicts in which every key maps to a list (a
    repeated field's elements, or the one value), numbers as floats (JSON carries 64-bit
    integers as strings), enums as their names."""
    if isinstance(value, dict):
        return {k: [scene_tree(x) for x in v] if isinstance(v, list) else [scene_tree(v)] for k, v in value.items()}
    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, str):
        try:
            return float(value)  # an int64 as a string; names and enum values stay strings
        except ValueError:
            return value
    return value


def get(tree, path, default=None, index=0):
    """The value at a dotted path: the first element of each repeated level, element `index` of the last."""
    cur = tree
    parts = path.split(".")
    for i, part in enumerate(parts):
        k = index if i == len(parts) - 1 else 0
        if not isinstance(cur, dict) or len(cur.get(part, [])) <= k:
            return default
        cur = cur[part][k]
    return cur


def get_all(tree, path):
    parent, _, last = path.rpartition(".")
    node = get(tree, parent) if parent else tree
    return node.get(last, []) if isinstance(node, dict) else []


def validate(exe, scene, sets):
    """(scene tree with the overrides applied, None) or (None, hfmpm's message)."""
    r = subprocess.run([exe, "validate", scene, "--json"] + set_args(sets), capture_output=True, text=True, cwd=ROOT)
    if r.returncode != 0:
        return None, (r.stderr.strip() or r.stdout.strip() or f"hfmpm validate exited {r.returncode}")
    return scene_tree(json.loads(r.stdout)), None


def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def run_case(exe, scene, out, sets, timeout_s, force=False, reuse_failed=False):
    """Runs `hfmpm run SCENE --out OUT --quiet --set ...` unless a finished run with the same scene and
    settings is there. Returns {rc, reused, manifest, stderr, out}."""
    with open(os.path.join(ROOT, scene), "rb") as f:  # an edited scene is a new case; a rebuilt binary is not (--force)
        digest = hashlib.sha1(f.read()).hexdigest()
    key = {"scene": os.path.relpath(os.path.join(ROOT, scene), ROOT), "sha1": digest, "sets": list(sets)}
    marker = os.path.join(out, "sweep-case.json")
    done = read_json(marker)
    manifest = read_json(os.path.join(out, "run.json"))
    if not force and done and done.get("key") == key and manifest and os.path.isfile(os.path.join(out, "history.csv")):
        ok = manifest.get("status") == "completed" or (reuse_failed and manifest.get("status") == "failed")
        if ok:
            return {"rc": done.get("rc"), "reused": True, "manifest": manifest, "stderr": done.get("stderr", ""),
                    "out": out}
    os.makedirs(out, exist_ok=True)
    for name in OUTPUTS:  # nothing stale may be read as this run's result
        try:
            os.remove(os.path.join(out, name))
        except FileNotFoundError:
            pass
    argv = [exe, "run", scene, "--out", out, "--quiet"] + set_args(sets)
    proc = subprocess.Popen(argv, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    RUNNING.add(proc)
    try:
        so, se = proc.communicate(timeout=timeout_s)
    except (subprocess.TimeoutExpired, KeyboardInterrupt) as e:
        os.killpg(proc.pid, signal.SIGTERM)  # this run's hfmpm and the sides it started, nothing else
        try:
            so, se = proc.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            so, se = proc.communicate()
        if isinstance(e, KeyboardInterrupt):
            raise
        se = (se or "") + f"\n(killed by the sweep after {timeout_s:g} s: --timeout)"
    finally:
        RUNNING.discard(proc)
    if STOPPING:
        raise KeyboardInterrupt
    with open(os.path.join(out, "sweep-stdout.txt"), "w") as f:
        f.write(so or "")
    with open(os.path.join(out, "sweep-stderr.txt"), "w") as f:
        f.write(se or "")
    rc = proc.returncode
    with open(marker, "w") as f:
        json.dump({"key": key, "rc": rc, "stderr": (se or "")[-4000:], "argv": argv}, f, indent=1)
    return {"rc": rc, "reused": False, "manifest": read_json(os.path.join(out, "run.json")), "stderr": se or "",
            "out": out}


def on_sigterm(signum, frame):
    raise KeyboardInterrupt  # stop the runs too (they run in their own sessions), as for Ctrl-C


def stop_all():
    """Stops the runs in progress (their hfmpm and the sides it started, by process group) after a Ctrl-C."""
    STOPPING.append(True)
    for proc in list(RUNNING):
        try:
            os.killpg(proc.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass


def pick(names, only, what="case"):
    """The case names --only selects (exact names or prefixes ending in '*'); refuses unknown ones."""
    if not only:
        return list(names)
    chosen = []
    for o in only:
        hit = [n for n in names if n == o or (o.endswith("*") and n.startswith(o[:-1]))]
        if not hit:
            die(f"--only {o}: no such {what}; the {what}s are: {', '.join(names)}")
        chosen += [n for n in hit if n not in chosen]
    return [n for n in names if n in chosen]


# ---------------------------------------------------------------- the KGD sweep
def grid_for(tree, h, margin_cells=3):
    """--set values for cell size h: the same body, notch and box; y = 0 midway between node rows."""
    xmin = get(tree, "solid.mpm.grid.x_min_m")
    if abs(xmin) > 1e-12:
        die("the cell-size cases need the grid to start at x = 0 (the symmetry plane)")
    rect = [get(r, "rectangle") for r in get_all(tree, "solid.mpm.regions")]
    body_x = max(r["x_max_m"][0] for r in rect)
    body_y = max(max(r["y_max_m"][0], -r["y_min_m"][0]) for r in rect)
    k = math.ceil(body_y / h + margin_cells - 0.5 - 1e-9)
    y = (k + 0.5) * h
    x = math.ceil(body_x / h + margin_cells - 1e-9) * h
    return [f"solid.mpm.cell_size_m={h:g}", f"solid.mpm.grid.y_min_m={-y:.10g}", f"solid.mpm.grid.y_max_m={y:.10g}",
            f"solid.mpm.grid.x_max_m={x:.10g}"]


def uniform_particles(tree, n):
    """--set value: the scene's largest region (its body) alone, with n x n particles per cell everywhere
    (kgd-viscosity has 1 in the far field and 2 x 2 around the crack). Derived from the validated scene,
    so it follows the scene's body, material and in-situ stress."""
    regions = get_all(tree, "solid.mpm.regions")
    if not regions or any("rectangle" not in r for r in regions):
        die("the particles-per-cell case needs the scene's regions to be rectangles")

    def area(r):
        b = r["rectangle"][0]
        return (b["x_max_m"][0] - b["x_min_m"][0]) * (b["y_max_m"][0] - b["y_min_m"][0])

    body = max(regions, key=area)

    def numbers(d):
        return " ".join(f"{k}: {v[0]:.10g}" for k, v in d.items())
    stress = f" initial_stress {{ {numbers(body['initial_stress'][0])} }}" if "initial_stress" in body else ""
    return (f'solid.mpm.regions=[{{material: "{body["material"][0]}" rectangle {{ {numbers(body["rectangle"][0])} }}'
            f"{stress} particles_per_cell: {n}}}]")


# name: (settings, a cell size h or None, which sweeps: "both", "full" or "quick").
# The full sweep varies one setting at a time around kgd-viscosity.scene's own (h = 0.04 m,
# cfl 0.5, exchange every step, in-process, 1 particle per cell in the far field and 2 x 2
# around the crack, the method derived: density scaling 13 and grid damping 3.6 /s at its
# cell); the quick one around the CI scene's (h = 0.035 m, cfl 0.4, ipc).
CASES = {
    "base": ([], None, "both"),
    "h0.07": ([], 0.07, "full"), "h0.05": ([], 0.05, "both"), "h0.035": ([], 0.035, "full"),
    "h0.03": ([], 0.03, "full"),
    "cfl0.3": (["solid.mpm.cfl=0.3"], None, "full"), "cfl0.4": (["solid.mpm.cfl=0.4"], None, "full"),
    "cfl0.5": (["solid.mpm.cfl=0.5"], None, "quick"),
    "ds3": (["solid.mpm.density_scaling=3"], None, "full"), "ds30": (["solid.mpm.density_scaling=30"], None, "full"),
    "damp0": (["solid.mpm.damping.grid_alpha_per_s=0"], None, "full"),
    "damp20": (["solid.mpm.damping.grid_alpha_per_s=20"], None, "full"),
    "xi2": (["coupling.exchange_interval=2"], None, "both"), "xi4": (["coupling.exchange_interval=4"], None, "full"),
    "ipc": (["coupling.transport=IPC"], None, "full"),
    "inproc": (["coupling.transport=INPROC"], None, "quick"),
    "ppc2": ([lambda tree: uniform_particles(tree, 2)], None, "full"),  # derived from the scene
    "h0.035_cfl0.4": (["solid.mpm.cfl=0.4"], 0.035, "full"),
}
QUICK_END_S = 3.5


def kgd_params(tree):
    mat = get(tree, "solid.mpm.materials")
    ramp = get(tree, "fluid.mpm.inlet.flow_rate_m2_s.ramp")
    if not mat or not ramp or get(mat, "toughness_pa_sqrt_m") is None:
        die("the scene needs a flow-rate ramp inlet and a material with toughness_pa_sqrt_m (a KGD scene)")
    return {"E": get(mat, "youngs_modulus_pa"), "nu": get(mat, "poisson_ratio"), "KIc": get(mat, "toughness_pa_sqrt_m"),
            "mu": get(tree, "fluid.mpm.viscosity_pa_s"), "Q": 2 * get(ramp, "v1"),
            "t0": 0.5 * (get(ramp, "t0", 0.0) + get(ramp, "t1")),
            "sigma0": -get(tree, "solid.mpm.regions.initial_stress.yy_pa", 0.0)}


def kgd_errors(hist, p):
    """Worst |error| of (length, opening, net pressure, front) once L >= 3 L0, as kgd_plot.py computes them."""
    import kgd_plot
    km = kgd_plot.km(p["E"], p["nu"], p["mu"], p["Q"], p["KIc"])
    vertex = 0 if km < 1 else 1 if km > 4 else None
    if vertex is None:
        die(f"Km = {km:.3g} is between the vertices: no reference to compare with")
    L0, front = hist["crack_length_m"][0], hist.get("front_position_m")
    worst, last, n = [0.0] * 4, [math.nan] * 3, 0
    for i, t in enumerate(hist["time_s"]):
        te = t - p["t0"]
        if te <= 0 or hist["crack_length_m"][i] < 3 * L0:
            continue
        ref = kgd_plot.vertices(p["E"], p["nu"], p["mu"], p["Q"], p["KIc"], te)[vertex]
        sim = (hist["crack_length_m"][i], hist["mouth_opening_m"][i], hist["inlet_pressure_pa"][i] - p["sigma0"])
        err = [(s - r) / r for s, r in zip(sim, ref)]
        if front:
            err.append((front[i] - ref[0]) / ref[0])
        worst = [max(w, abs(e)) for w, e in zip(worst, err)] + worst[len(err):]
        last, n = err[:3], n + 1
    nan = [math.nan] * 4
    return {"rows": n, "worst": worst if n else nan, "end": last, "front": bool(front)}


def pareto(points):
    """Indices of the points no other point beats in every coordinate (all minimised)."""
    keep = []
    for i, a in enumerate(points):
        if not any(all(b[k] <= a[k] for k in range(len(a))) and any(b[k] < a[k] for k in range(len(a)))
                   for j, b in enumerate(points) if j != i):
            keep.append(i)
    return keep


def pct(x):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{100 * x:.1f}%"


def plot(rows, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ok = [r for r in rows if r["status"] == "completed" and r["rows_compared"]]
    panels = (("worst |error| of half-length and mouth opening", lambda r: max(r["err_length"], r["err_opening"])),
              ("worst |error| of net inlet pressure", lambda r: r["err_pressure"]))
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
    for ax, (label, err) in zip(axes, panels):
        pts = [(r["wall_s"], max(err(r), 1e-4)) for r in ok]
        front = sorted(pareto(pts), key=lambda i: pts[i][0])
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o", color="0.55", ms=5, label="run")
        if front:
            ax.loglog([pts[i][0] for i in front], [pts[i][1] for i in front], "r-o", ms=7, drawstyle="steps-post",
                      label="Pareto front (no run both faster and closer)")
        for r, p in zip(ok, pts):
            ax.annotate(r["name"], p, textcoords="offset points", xytext=(4, 3), fontsize=7)
        ax.set(xlabel="wall time (s)", ylabel=label)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 epilog="cases: " + ", ".join(CASES))
    ap.add_argument("--scene", help="scene (default scenarios/kgd-viscosity.scene; with --quick kgd-viscosity-ci.scene)")
    ap.add_argument("--out", help="output folder (default hfmpm-out/kgd-sweep, or hfmpm-out/kgd-sweep-quick)")
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "release", "bin"),
                    help="folder with hfmpm, hfmpm-solid, hfmpm-fluid (default build/release/bin)")
    ap.add_argument("--quick", action="store_true",
                    help=f"CI-size scene to {QUICK_END_S:g} s, a subset of the cases: tests the tool in minutes")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="run only these cases (NAME or PREFIX*)")
    ap.add_argument("--force", action="store_true", help="rerun cases that have a finished run")
    ap.add_argument("--timeout", type=float, default=3600, help="seconds per run before it is killed (default 3600)")
    ap.add_argument("--spread", type=float, default=0.05,
                    help="run-to-run spread of the wall time (default 0.05, measured: docs/performance.md): runs "
                         "within it of the fastest one meeting the targets tie, and a tie keeps the scene's settings")
    ap.add_argument("--targets", type=float, nargs=3, metavar=("LENGTH", "OPENING", "PRESSURE"),
                    help="error targets for the recommendation (default the issue's: 0.05 0.05 0.10; "
                         "with --quick the CI size's 0.10 0.10 0.20)")
    a = ap.parse_args()
    if a.timeout <= 0:
        die(f"--timeout {a.timeout:g}: must be > 0 seconds")
    if not 0 <= a.spread < 1:
        die(f"--spread {a.spread}: a fraction in [0, 1), e.g. 0.05")
    a.targets = a.targets or ([0.10, 0.10, 0.20] if a.quick else [0.05, 0.05, 0.10])
    if any(not 0 < x < 10 for x in a.targets):
        die(f"--targets {' '.join(map(str, a.targets))}: fractions, each in (0, 10), e.g. 0.05 0.05 0.10")
    scene = a.scene or os.path.join("scenarios", "kgd-viscosity-ci.scene" if a.quick else "kgd-viscosity.scene")
    if not os.path.isfile(os.path.join(ROOT, scene)):
        die(f"--scene {scene}: no such file (paths are relative to {ROOT})")
    out = os.path.abspath(a.out or os.path.join(ROOT, "hfmpm-out", "kgd-sweep-quick" if a.quick else "kgd-sweep"))
    exe = hfmpm_path(os.path.abspath(a.bin))
    names = pick([n for n, c in CASES.items() if c[2] in ("both", "quick" if a.quick else "full")], a.only)
    common = [f"time.end_s={QUICK_END_S:g}"] if a.quick else []
    tree, err = validate(exe, scene, common)
    if err:
        die(f"{scene} does not validate: {err}")
    p = kgd_params(tree)
    import kgd_plot  # beside this file: Python puts a script's folder first on its path
    t_end = get(tree, "time.end_s")
    L_end = kgd_plot.vertices(p["E"], p["nu"], p["mu"], p["Q"], p["KIc"], t_end - p["t0"])[0][0]
    L0, h0 = get(tree, "solid.mpm.cracks.x_m", index=1), get(tree, "solid.mpm.cell_size_m")
    print(f"kgd_sweep: {scene}{' (quick: to %g s)' % QUICK_END_S if a.quick else ''}, E = {p['E']:g}, "
          f"nu = {p['nu']:g}, K_Ic = {p['KIc']:g}, mu = {p['mu']:g}, Q = {p['Q']:g} (total), "
          f"sigma0 = {p['sigma0']:g}, t0 = {p['t0']:g}; {len(names)} runs into {out}", file=sys.stderr)
    rows = []
    for i, name in enumerate(names):
        sets, h, _ = CASES[name]
        sets = common + (grid_for(tree, h) if h else []) + [x(tree) if callable(x) else x for x in sets]
        hh = h or h0
        row = {"name": name, "settings": " ".join(s for s in sets if not s.startswith("time.end_s")) or "(scene)",
               "h_m": hh, "notch_cells": L0 / hh, "cells_per_final_half_length": L_end / hh}
        _, verr = validate(exe, scene, sets)
        if verr:
            die(f"case {name}: the settings do not validate: {verr}")
        print(f"[{i + 1}/{len(names)}] {name}: {row['settings']} ...", end=" ", flush=True, file=sys.stderr)
        t_start = time.time()
        res = run_case(exe, scene, os.path.join(out, name), sets, a.timeout)
        m = res["manifest"] or {}
        row["status"] = m.get("status", f"no run.json (exit {res['rc']})")
        print(("reused" if res["reused"] else f"{time.time() - t_start:.0f} s") + f", {row['status']}",
              file=sys.stderr)
        row.update({k: m.get(k, math.nan) for k in ("wall_s", "steps", "solid_compute_s", "fluid_compute_s")})
        row["coupling_s"] = m.get("coupling_overhead_us_per_step", math.nan) * m.get("steps", math.nan) * 1e-6
        row["error"] = m.get("error", res["stderr"].strip().splitlines()[-1] if res["stderr"].strip() else "")
        e = {"rows": 0, "worst": [math.nan] * 4, "end": [math.nan] * 3, "front": False}
        if row["status"] == "completed":
            try:
                e = kgd_errors(kgd_plot.read_history(os.path.join(res["out"], "history.csv")), p)
            except SystemExit as ex:  # read_history refuses an empty or odd file
                row["error"] = str(ex)
        row["rows_compared"] = e["rows"]
        for k, v in zip(("length", "opening", "pressure", "front"), e["worst"]):
            row["err_" + k] = v
        for k, v in zip(("length", "opening", "pressure"), e["end"]):
            row["end_err_" + k] = v
        rows.append(row)
    done = [r for r in rows if r["status"] == "completed" and r["rows_compared"]]
    front = pareto([(r["wall_s"], r["err_length"], r["err_opening"], r["err_pressure"]) for r in done])
    for i, r in enumerate(done):
        r["pareto"] = i in front
    write_outputs(rows, out, scene, a.quick, p, a.targets, a.spread)


def write_outputs(rows, out, scene, quick, p, targets, spread):
    keys = ["name", "settings", "status", "h_m", "notch_cells", "cells_per_final_half_length", "steps", "wall_s",
            "solid_compute_s", "fluid_compute_s", "coupling_s", "rows_compared", "err_length", "err_opening",
            "err_pressure", "err_front", "end_err_length", "end_err_opening", "end_err_pressure", "pareto", "error"]
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "sweep.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, keys, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in keys})
    lines = ["| run | settings (`--set`) | cells per final half-length | wall (s) | solid / fluid / coupling | "
             "half-length | mouth opening | net pressure | fluid front | Pareto |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["status"] != "completed":
            lines.append(f"| {r['name']} | `{r['settings']}` | {r['cells_per_final_half_length']:.1f} | "
                         f"{r['wall_s']:.1f} | | **{r['status']}**: {r['error'][:160]} | | | | |")
            continue
        w = r["wall_s"]
        split = f"{100 * r['solid_compute_s'] / w:.0f}% / {100 * r['fluid_compute_s'] / w:.0f}% / " \
                f"{100 * r['coupling_s'] / w:.0f}%"
        errs = " | ".join(f"{pct(r['err_' + k])} ({pct(r['end_err_' + k])})" for k in ("length", "opening", "pressure"))
        lines.append(f"| {r['name']} | `{r['settings']}` | {r['cells_per_final_half_length']:.1f} | {w:.1f} | {split} | "
                     f"{errs} | {pct(r['err_front'])} | {'**yes**' if r.get('pareto') else ''} |")
    note = (f"Worst |error| against the M-vertex over the rows with L >= 3 L0 (at the end in brackets; "
            f"t shifted by t0 = {p['t0']:g} s). Pareto: no other run is both faster and closer on all three.")
    meet = sorted((r for r in rows if r["status"] == "completed" and r["rows_compared"] and
                   all(r["err_" + k] <= x for k, x in zip(("length", "opening", "pressure"), targets))),
                  key=lambda r: r["wall_s"])
    goal = "/".join(pct(x) for x in targets)
    note += (f"\n\nFastest run within {goal} (length/opening/pressure): **{meet[0]['name']}** ({meet[0]['wall_s']:.1f} s)"
             + (f"; then {', '.join(r['name'] for r in meet[1:4])}." if len(meet) > 1 else ".")) if meet else \
        f"\n\nNo run is within {goal} (length/opening/pressure)."
    if meet:
        # Wall times within the run-to-run spread of the fastest are a tie: a default is changed only
        # for a gain larger than the spread, so the scene's own settings win a tie.
        tied = [r for r in meet if r["wall_s"] <= (1 + spread) * meet[0]["wall_s"]]
        base = next((r for r in tied if r["name"] == "base"), None)
        note += (f" Within the {100 * spread:g}% run-to-run spread of its wall time (`--spread`): "
                 f"{', '.join(r['name'] for r in tied)}. "
                 + ("The scene's own settings (base) are among them: **keep them**." if base else
                    f"The scene's own settings are not: **{meet[0]['name']}** is the recommendation."))
    md = "\n".join(lines) + "\n\n" + note + "\n"
    with open(os.path.join(out, "sweep.md"), "w") as f:
        f.write(md)
    print(md)
    try:
        plot(rows, os.path.join(out, "sweep.png"),
             f"{os.path.basename(scene)}{' (quick)' if quick else ''}: worst error once L >= 3 L0 against wall time")
        print(f"kgd_sweep: wrote {out}/sweep.csv, sweep.md and sweep.png", file=sys.stderr)
    except ImportError as e:
        print(f"kgd_sweep: no plot ({e}; apt-get install python3-matplotlib)", file=sys.stderr)


if __name__ == "__main__":
    signal.signal(signal.SIGTERM, on_sigterm)
    try:
        main()
    except KeyboardInterrupt:
        stop_all()
        sys.exit("kgd_sweep: interrupted; finished runs are kept: the same command resumes")
