#!/usr/bin/python3
"""The full stability sweep: extreme but valid inputs, each run checked, one summary table.

    /usr/bin/python3 tools/stability_sweep.py [--out DIR] [--bin DIR] [--only NAME...] [--jobs N] [--force]
        [--set KEY=VALUE ...]

Runs scenarios/stability-kgd.scene (a small coupled KGD fracture: 1.05 m x 2.1 m box,
h = 0.035 m, notch 0.15 m, 1.5 s) with one input, or a few, pushed per case (the list is
CASES below; `--only` takes names or PREFIX*), and sorts each run into
- "passed": it ended normally and every check holds;
- "blew up, detected": it exited non-zero, run.json says failed, and the message names the
  runaway: the solid's ("ran away at step", the particle, the face pressure and what to change)
  or the coupler's energy check ("energy is being created: at step", the kinetic energy against
  the fluid's work and what to change);
- "FAILED CHECK (which)": it ended normally but a check fails, or it failed in another way.
The checks are those of tests/coupled/stability_test.cpp (which says why each bound), on
history.csv, plus two on solid.h5:
  finite     every history column, and every array of every solid.h5 frame, is finite;
  ke         kinetic energy < 1e-2 of the work the inlet pressure has done (int p |dV|), once
             t > 2 x the end of the inlet ramp (quasi-static loading; a pressure inlet: t > end / 10);
  p>=0       inlet pressure never negative;
  injected   injected volume = integral of the ramped inlet rate, to the trapezoid error of
             the substep holding the ramp's kink (Q / t_ramp dt_max^2 / 8 + 1e-9 Q) (flow-rate
             ramp inlets only);
  volume     fluid volume > 0.5 x (injected + the fluid's volume at t = 0, which is virtual opening
             x initial fill here): the Tait compression at these pressures is under 10% for
             K >= 1 MPa;
  contact    the crack's faces interpenetrate by less than 1% of a cell (h / 100). solid.h5's
             crack width is clamped at 0 (Crack::width), so the signed opening
             (x_above - x_below) . n is taken from the faces' positions (frames/N/crackK_above,
             _below, crackK/normal), at the output frames only. Why h / 100: contact acts on the
             nodes; each face is moved by the nodes of the cell on its own side, so two faces in
             contact drift apart by about (strain) x h, and the strains here are up to about
             sigma0 / E = 1e-2. Without contact a shut crack would overlap by Sneddon's
             4 (sigma0 - p) a / E', 1 to 11 mm here (docs/stability.md).
A blown-up run's history is checked for finite values too (the output must stay readable).
Cases whose scene file does not exist are skipped with a note (scenarios/layered.scene, the
layer stiffness ratio, was being written when this tool was). Each run is OUT/NAME; a finished
run (completed or failed, same scene file and settings) is reused unless --force, so an
interrupted sweep resumes (after a rebuild use --force: the binaries are not compared).
Writes OUT/summary.md and OUT/summary.csv and prints the table; exits 1 if a check failed.
Uses the run helpers of tools/kgd_sweep.py and Debian's python3-h5py and python3-numpy.
"""
import argparse
import csv
import math
import os
import re
import signal
import sys
from concurrent.futures import ThreadPoolExecutor

from kgd_sweep import ROOT, die, get, get_all, hfmpm_path, on_sigterm, pick, run_case, stop_all, validate

SCENE = "scenarios/stability-kgd.scene"
LAYERED = "scenarios/layered.scene"
BODY = 1.05  # the scene's body: x in [0, 1.05], y in [-1.05, 1.05]
UNCONFINED = ['solid.mpm.regions=[{material: "rock" rectangle { x_min_m: 0 y_min_m: -1.05 x_max_m: 1.05 '
              'y_max_m: 1.05 }}]', "solid.mpm.tractions=[]", "fluid.mpm.initial_fill.pressure_pa=0",
              "fluid.mpm.lag_pressure_pa=0"]  # as tests/coupled/stability_test.cpp: no stress, no tractions


def cells(h, notch=None):
    """Cell size h in the same body: y = +-(k + 1/2) h with at least one cell between body and grid edge (as the
    scene: y = 0 midway between node rows), x_max two cells beyond the body; the notch (and the fluid's fill) at
    `notch` m when given, so that it stays at least 4 cells."""
    k = math.ceil(BODY / h + 1 - 1e-9)
    s = [f"solid.mpm.cell_size_m={h:g}", f"solid.mpm.grid.y_min_m={-(k + 0.5) * h:.10g}",
         f"solid.mpm.grid.y_max_m={(k + 0.5) * h:.10g}", f"solid.mpm.grid.x_max_m={math.ceil(BODY / h + 2 - 1e-9) * h:.10g}"]
    if notch:
        s += [f"solid.mpm.cracks=[{{x_m: [0, {notch:g}] y_m: [0, 0] start_is_tip: false end_is_tip: true}}]",
              f"fluid.mpm.initial_fill.front_m={notch:g}"]
    return s


# (name, what it pushes, settings, expected: "passes" / "blows up", scene)
CASES = [
    ("base", "the scene as it is", [], "passes"),
    ("K_1e6", "fluid bulk modulus 1 MPa (soft)", ["fluid.mpm.bulk_modulus_pa=1e6"], "passes"),
    ("K_1e7", "fluid bulk modulus 10 MPa", ["fluid.mpm.bulk_modulus_pa=1e7"], "passes"),
    ("K_1e8", "fluid bulk modulus 100 MPa", ["fluid.mpm.bulk_modulus_pa=1e8"], "passes"),
    ("K_3e8", "fluid bulk modulus 300 MPa", ["fluid.mpm.bulk_modulus_pa=3e8"], "passes"),
    ("K_1e9", "fluid bulk modulus 1 GPa", ["fluid.mpm.bulk_modulus_pa=1e9"], "passes"),
    ("K_2e9", "fluid bulk modulus 2 GPa (water)", ["fluid.mpm.bulk_modulus_pa=2e9"], "blows up"),
    ("K_3e8_step0.45", "fluid 300 MPa at half the coupled step (time.safety_factor 0.45)",
     ["fluid.mpm.bulk_modulus_pa=3e8", "time.safety_factor=0.45"], "passes"),
    ("K_2e9_step0.15", "water (2 GPa) at a sixth of the coupled step (time.safety_factor 0.15)",
     ["fluid.mpm.bulk_modulus_pa=2e9", "time.safety_factor=0.15"], "passes"),
    ("mu_1e-4", "viscosity 1e-4 Pa s", ["fluid.mpm.viscosity_pa_s=1e-4"], "passes"),
    ("mu_1e-3", "viscosity 1e-3 Pa s (water)", ["fluid.mpm.viscosity_pa_s=1e-3"], "passes"),
    ("mu_1e-1", "viscosity 0.1 Pa s", ["fluid.mpm.viscosity_pa_s=0.1"], "passes"),
    ("mu_1", "viscosity 1 Pa s", ["fluid.mpm.viscosity_pa_s=1"], "passes"),
    ("cfl_0.5", "solid cfl 0.5 (the validated limit) at safety factor 1",
     ["solid.mpm.cfl=0.5", "time.safety_factor=1"], "passes"),
    ("film_1e-8", "pre-opening 10 nm", ["fluid.mpm.virtual_opening_m=1e-8"], "blows up"),
    ("film_1e-6", "pre-opening 1 um", ["fluid.mpm.virtual_opening_m=1e-6"], "passes"),
    ("film_1e-3", "pre-opening 1 mm", ["fluid.mpm.virtual_opening_m=1e-3"], "passes"),
    ("film_3e-3", "pre-opening 3 mm", ["fluid.mpm.virtual_opening_m=3e-3"], "passes"),
    ("long", "10 x the end time (15 s)", ["time.end_s=15"], "passes"),
    ("h_0.0175", "small cells: h = 0.0175 m (notch 8.6 cells, 4 x the particles)", cells(0.0175), "passes"),
    ("h_0.05", "large cells: h = 0.05 m, notch 0.2 m (4 cells)", cells(0.05, 0.2), "passes"),
    ("h_0.07", "very large cells: h = 0.07 m (15 across the body), notch 0.28 m (4 cells)", cells(0.07, 0.28),
     "passes"),
    ("unconfined", "no confining stress (no initial stress, no edge tractions, fill and lag at 0 Pa)", UNCONFINED,
     "passes"),
    ("unconfined_K_1e6", "no confinement + fluid 1 MPa", UNCONFINED + ["fluid.mpm.bulk_modulus_pa=1e6"], "passes"),
    ("unconfined_K_1e8", "no confinement + fluid 100 MPa", UNCONFINED + ["fluid.mpm.bulk_modulus_pa=1e8"], "passes"),
    ("unconfined_mu_1e-4", "no confinement + viscosity 1e-4 Pa s", UNCONFINED + ["fluid.mpm.viscosity_pa_s=1e-4"],
     "passes"),
    ("unconfined_mu_1", "no confinement + viscosity 1 Pa s", UNCONFINED + ["fluid.mpm.viscosity_pa_s=1"], "passes"),
    ("unconfined_film_1e-3", "no confinement + pre-opening 1 mm", UNCONFINED + ["fluid.mpm.virtual_opening_m=1e-3"],
     "passes"),
    ("unconfined_cfl_0.5", "no confinement + cfl 0.5 at safety factor 1",
     UNCONFINED + ["solid.mpm.cfl=0.5", "time.safety_factor=1"], "passes"),
    ("unconfined_long", "no confinement + 10 x the end time", UNCONFINED + ["time.end_s=15"], "passes"),
    ("layered_ratio_10", "layer stiffness ratio 10 (layered.scene)", ("stiffness_ratio", 10), "passes", LAYERED),
    ("layered_ratio_100", "layer stiffness ratio 100 (layered.scene)", ("stiffness_ratio", 100), "passes", LAYERED),
]


def stiffness_ratio_sets(exe, scene, ratio):
    """Materials list with every material after the first at E_first / ratio (the first, where the scene's crack
    starts in layered.scene, keeps its E); the rest of each material as the scene has it."""
    tree, err = validate(exe, scene, [])
    if err:
        return None, f"{scene} does not validate: {err}"
    mats = get_all(tree, "solid.mpm.materials")
    if len(mats) < 2:
        return None, f"{scene} has {len(mats)} material(s): no layers to set a stiffness ratio between"
    e0 = get(mats[0], "youngs_modulus_pa")
    items = []
    for i, m in enumerate(mats):
        fields = []
        for key, vals in m.items():
            v = (e0 if i == 0 else e0 / ratio) if key == "youngs_modulus_pa" else vals[0]
            fields.append(f'{key}: "{v}"' if key == "name" else f"{key}: {v if isinstance(v, str) else repr(v)}")
        items.append("{" + " ".join(fields) + "}")
    return ["solid.mpm.materials=[" + ", ".join(items) + "]"], None


def ramp_volume(ramp, t):
    """Integral of the ramp TimeFunction (v0 before t0, linear to v1 at t1, v1 after) from 0 to t."""
    t0, v0, t1, v1 = (get(ramp, k, d) for k, d in (("t0", 0.0), ("v0", 0.0), ("t1", None), ("v1", 0.0)))

    def rate(x):
        return v0 if x <= t0 else v1 if x >= t1 else v0 + (v1 - v0) * (x - t0) / (t1 - t0)
    pts = sorted({0.0, t} | {x for x in (t0, t1) if 0 < x < t})
    return sum(0.5 * (rate(a) + rate(b)) * (b - a) for a, b in zip(pts, pts[1:]))


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    if not rows:
        return [], []
    return rows[0], [[float(x) for x in r] for r in rows[1:] if r]


def faces(path):
    """(every float array of every solid.h5 frame finite, the worst interpenetration relative to the same frame's
    largest opening as (depth m, ratio, t, x), the deepest one as (depth m, t, x))."""
    import h5py
    import numpy as np
    arrays, worst, deepest = [], (0.0, 0.0, math.nan, math.nan), (0.0, math.nan, math.nan)
    with h5py.File(path, "r") as f:
        for key in sorted(f["frames"]):
            frame = f["frames"][key]
            arrays.clear()
            frame.visititems(lambda n, o: arrays.append(o) if isinstance(o, h5py.Dataset) and o.dtype.kind == "f" else None)
            if not all(np.all(np.isfinite(o[()])) for o in arrays):
                return False, worst, deepest
            for name in frame:
                if not (name.startswith("crack") and name[5:].isdigit() and name + "_above" in frame):
                    continue
                above, below = frame[name + "_above/positions"][()], frame[name + "_below/positions"][()]
                d = np.einsum("ij,ij->i", above - below, frame[name + "/normal"][()][:, :2])
                i = int(np.argmin(d)) if len(d) else 0
                if not len(d) or d[i] >= 0:
                    continue
                t, x = float(frame.attrs["time_s"]), float(frame[name + "/positions"][i, 0])
                ratio = -d[i] / d.max() if d.max() > 0 else math.inf
                if ratio > worst[1]:
                    worst = (-float(d[i]), float(ratio), t, x)
                if -d[i] > deepest[0]:
                    deepest = (-float(d[i]), t, x)
    return True, worst, deepest


def check(out, tree, has_h5):
    """Failed checks (list of strings) and measured figures (dict) of a completed run."""
    header, data = read_csv(os.path.join(out, "history.csv"))
    fails, figs = [], {"rows": len(data), "t_end": data[-1][0] if data else math.nan}
    if len(data) < 10:
        return [f"rows: {len(data)} history rows (< 10)"], figs
    col = {k: [r[i] for r in data] for i, k in enumerate(header)}
    bad = [header[i] for i in range(len(header)) if not all(math.isfinite(r[i]) for r in data)]
    if bad:
        fails.append("finite: non-finite " + ", ".join(bad))
    t, p, inj, vol, ke, dt = (col[k] for k in ("time_s", "inlet_pressure_pa", "injected_volume_m2", "fluid_volume_m2",
                                               "kinetic_energy_j", "dt_s"))
    figs["p_min"], figs["p_end"], figs["L_end"] = min(p), p[-1], col["crack_length_m"][-1]
    if min(p) < 0:
        fails.append(f"p>=0: inlet pressure {min(p):.3g} Pa at t = {t[p.index(min(p))]:.3g} s")
    ramp = get(tree, "fluid.mpm.inlet.flow_rate_m2_s.ramp")
    if ramp is not None:
        rate = abs(get(ramp, "v1", 0.0) - get(ramp, "v0", 0.0)) / (get(ramp, "t1") - get(ramp, "t0", 0.0))
        q = max(abs(get(ramp, "v1", 0.0)), abs(get(ramp, "v0", 0.0)))
        tol = rate * max(dt) ** 2 / 8 + 1e-9 * q
        dev = [abs(v - ramp_volume(ramp, ti)) for v, ti in zip(inj, t)]
        figs["inj_dev"] = max(dev) / max(tol, 1e-300)
        if max(dev) > tol:
            i = dev.index(max(dev))
            fails.append(f"injected: off the ramp's integral by {dev[i]:.3g} m^2 at t = {t[i]:.3g} s (bound {tol:.2g})")
        t_quiet = 2 * get(ramp, "t1")
    else:
        figs["inj_dev"] = math.nan  # a pressure inlet: no rate to integrate
        t_quiet = 0.1 * get(tree, "time.end_s")  # a pressure inlet: after the first tenth of the run
    film = vol[0]  # the fluid's volume at t = 0: virtual opening x fill (+ any inlet pre-opening), at the fill pressure
    ratio = [v / (i + film) if i + film > 0 else math.inf for v, i in zip(vol, inj)]
    figs["vol_min"], figs["vol_max"] = min(ratio), max(ratio)
    if min(ratio) <= 0.5:
        i = ratio.index(min(ratio))
        fails.append(f"volume: fluid volume {ratio[i]:.3g} x its zero-pressure volume at t = {t[i]:.3g} s")
    work, worst_ke, at = 0.0, 0.0, math.nan
    for i in range(len(t)):
        if i:  # |dV|: a pressure inlet can take fluid back; count the energy through the inlet either way
            work += 0.5 * (p[i] + p[i - 1]) * abs(inj[i] - inj[i - 1])
        if t[i] > t_quiet:
            r = ke[i] / work if work > 0 else math.inf
            if r > worst_ke:
                worst_ke, at = r, t[i]
    figs["ke_ratio"] = worst_ke
    if worst_ke >= 1e-2:
        fails.append(f"ke: kinetic energy {worst_ke:.3g} x the inlet work at t = {at:.3g} s (bound 1e-2)")
    if has_h5:
        finite, (d, r, tt, x), deep = faces(os.path.join(out, "solid.h5"))
        figs.update(pen_m=d, pen_ratio=r, pen_t=tt, pen_x=x, deep_m=deep[0], deep_t=deep[1], deep_x=deep[2])
        if not finite:
            fails.append("finite: non-finite values in solid.h5")
        h = get(tree, "solid.mpm.cell_size_m")
        figs["deep_h"] = deep[0] / h
        if deep[0] > 0.01 * h:
            fails.append(f"contact: faces interpenetrate by {deep[0] * 1e6:.3g} um = {deep[0] / h:.2g} h (bound 0.01 h) "
                         f"at t = {deep[1]:.3g} s, x = {deep[2]:.3g} m")
    return fails, figs


def one(exe, out_root, case, a):
    name, what, sets, expect = case[:4]
    scene = case[4] if len(case) > 4 else SCENE
    row = {"name": name, "what": what, "expect": expect, "scene": scene, "figs": {}}
    if not os.path.isfile(os.path.join(ROOT, scene)):
        row.update(outcome="skipped", detail=f"{scene} does not exist (yet): case skipped")
        return row
    if isinstance(sets, tuple):  # ("stiffness_ratio", R): built from the scene's materials
        sets, err = stiffness_ratio_sets(exe, scene, sets[1])
        if err:
            row.update(outcome="skipped", detail=err)
            return row
    sets = list(a.set) + list(sets)
    row["sets"] = sets
    tree, err = validate(exe, scene, sets)
    if err:
        row.update(outcome="FAILED CHECK (invalid settings)", detail=err.splitlines()[-1][:300])
        return row
    res = run_case(exe, scene, os.path.join(out_root, name), sets, a.timeout, a.force, reuse_failed=True)
    m, msg = res["manifest"] or {}, ""
    status = m.get("status")
    row["steps"], row["wall_s"], row["reused"] = m.get("steps"), m.get("wall_s"), res["reused"]
    if res["rc"] == 0 and status == "completed":
        fails, row["figs"] = check(res["out"], tree, get(tree, "output.hdf5", True))
        row["outcome"] = "passed" if not fails else "FAILED CHECK (" + ", ".join(f.split(":")[0] for f in fails) + ")"
        row["detail"] = "; ".join(fails)
        return row
    msg = m.get("error") or res["stderr"].strip()[-600:] or f"exit {res['rc']}, run.json: {status}"
    readable = ""
    try:
        header, data = read_csv(os.path.join(res["out"], "history.csv"))
        readable = f"; history.csv readable, {len(data)} rows" + (
            "" if all(math.isfinite(x) for r in data for x in r) else ", with non-finite values")
    except (OSError, ValueError) as e:
        readable = f"; history.csv unreadable: {e}"
    runaway = re.search(r"ran away at step (\d+) \(t = ([^ )]+) s\).*?([\d.]+) cells in one step.*?"
                        r"Largest crack face pressure: ([^ ]+) Pa", msg)
    energy = re.search(r"energy is being created: at step (\d+) \(t = ([^ )]+) s\) the solid's kinetic energy is "
                       r"([^ ]+) J/m, ([^ ]+) x the energy", msg)
    if res["rc"] != 0 and status == "failed" and runaway:
        row["outcome"] = "blew up, detected"
        row["steps"] = int(runaway.group(1))  # run.json counts the steps of the last completed control round
        row["runaway"] = (f"ran away at step {runaway.group(1)} (t = {runaway.group(2)} s), a particle moved "
                          f"{runaway.group(3)} cells in a step; largest face pressure {float(runaway.group(4)):.3g} Pa")
    elif res["rc"] != 0 and status == "failed" and energy:  # the coupler's energy check (docs/stability.md)
        row["outcome"] = "blew up, detected"
        row["steps"] = int(energy.group(1))
        row["runaway"] = (f"energy check at step {energy.group(1)} (t = {energy.group(2)} s): kinetic energy "
                          f"{float(energy.group(3)):.3g} J/m, {float(energy.group(4)):.3g} x what the fluid can "
                          f"have given")
    else:
        row["outcome"] = f"FAILED CHECK (run ended: exit {res['rc']}, status {status})"
    row["detail"] = msg + readable
    return row


def summary(rows):
    lines = ["| case | pushes | expected | outcome | steps | wall (s) | KE / inlet work | fluid vol / zero-p vol "
             "| min inlet p (Pa) | crack length at end (m) | deepest interpenetration | notes |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        f = r["figs"]
        num = (lambda k, fmt: (fmt % f[k]) if k in f and isinstance(f[k], float) and math.isfinite(f[k]) else "")
        pen = ""
        if "deep_m" in f:
            pen = "none" if f["deep_m"] <= 0 else f"{f['deep_m'] * 1e6:.3g} um = {100 * f['deep_h']:.2f}% h at " \
                                                  f"{f['deep_t']:.2f} s, x = {f['deep_x']:.3f} m"
        out = r["outcome"] if r["outcome"] in ("passed", "skipped") else f"**{r['outcome']}**"
        ok = (r["outcome"] == "passed") == (r["expect"] == "passes") or r["outcome"] == "skipped"
        wall = f"{r['wall_s']:.1f}" if isinstance(r.get("wall_s"), float) else ""
        note = r.get("detail", "").replace("|", "/").replace("\n", " ")
        if r["outcome"] == "blew up, detected":
            note = r["runaway"] + note[note.find("; history.csv"):]
        lines.append(f"| {r['name']} | {r['what']} | {r['expect']} | {out}{'' if ok else ' (UNEXPECTED)'} | "
                     f"{r.get('steps') if r.get('steps') is not None else ''} | {wall} | {num('ke_ratio', '%.2g')} | "
                     f"{num('vol_min', '%.3g')} - {num('vol_max', '%.3g')} | {num('p_min', '%.4g')} | {num('L_end', '%.3f')} | {pen} | "
                     f"{note} |")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0], epilog="cases: " + ", ".join(c[0] for c in CASES))
    ap.add_argument("--out", help="output folder (default hfmpm-out/stability-sweep)")
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "release", "bin"),
                    help="folder with hfmpm, hfmpm-solid, hfmpm-fluid (default build/release/bin)")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="run only these cases (NAME or PREFIX*)")
    ap.add_argument("--jobs", type=int, default=1, help="runs at a time (default 1; the runs are not timed)")
    ap.add_argument("--force", action="store_true", help="rerun cases that have a finished run")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a scene setting added to every case, before the case's own (e.g. coupling.scheme=IMPLICIT)")
    ap.add_argument("--timeout", type=float, default=3600, help="seconds per run before it is killed (default 3600)")
    a = ap.parse_args()
    if a.jobs < 1 or a.jobs > 8:
        die(f"--jobs {a.jobs}: must be 1 to 8 (each run takes up to 3 threads)")
    if a.timeout <= 0:
        die(f"--timeout {a.timeout:g}: must be > 0 seconds")
    try:
        import h5py  # noqa: F401
        import numpy  # noqa: F401
    except ImportError as e:
        die(f"{e}: apt-get install python3-h5py python3-numpy")
    exe = hfmpm_path(os.path.abspath(a.bin))
    out = os.path.abspath(a.out or os.path.join(ROOT, "hfmpm-out", "stability-sweep"))
    names = pick([c[0] for c in CASES], a.only)
    cases = [c for c in CASES if c[0] in names]
    print(f"stability_sweep: {len(cases)} cases into {out}, {a.jobs} at a time", file=sys.stderr)

    def job(c):
        r = one(exe, out, c, a)
        print(f"  {c[0]}: {r['outcome']}{' (reused)' if r.get('reused') else ''}", file=sys.stderr, flush=True)
        return r
    pool = ThreadPoolExecutor(max_workers=a.jobs)
    try:
        rows = list(pool.map(job, cases))
    except KeyboardInterrupt:
        pool.shutdown(wait=False, cancel_futures=True)
        stop_all()
        die("interrupted; finished runs are kept: the same command resumes")
    pool.shutdown()
    md = summary(rows)
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "summary.md"), "w") as f:
        f.write(md)
    keys = ["ke_ratio", "vol_min", "vol_max", "p_min", "p_end", "inj_dev", "pen_m", "pen_ratio", "pen_t", "pen_x",
            "deep_m", "deep_h", "deep_t", "deep_x", "L_end", "t_end"]
    with open(os.path.join(out, "summary.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "expected", "outcome", "steps", "wall_s"] + keys + ["settings", "detail"])
        for r in rows:
            w.writerow([r["name"], r["expect"], r["outcome"], r.get("steps", ""), r.get("wall_s", "")]
                       + [r["figs"].get(k, "") for k in keys] + [" ".join(r.get("sets", [])), r.get("detail", "")])
    print(md)
    unexpected = [r["name"] for r in rows if r["outcome"] != "skipped" and
                  (r["outcome"] == "passed") != (r["expect"] == "passes")]
    bad = [r["name"] for r in rows if r["outcome"].startswith("FAILED")]
    print(f"stability_sweep: {sum(r['outcome'] == 'passed' for r in rows)} passed, "
          f"{sum(r['outcome'] == 'blew up, detected' for r in rows)} blew up (detected), {len(bad)} failed a check"
          f"{' (' + ', '.join(bad) + ')' if bad else ''}, {sum(r['outcome'] == 'skipped' for r in rows)} skipped; "
          f"unexpected: {', '.join(unexpected) or 'none'}. Wrote {out}/summary.md and summary.csv", file=sys.stderr)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    signal.signal(signal.SIGTERM, on_sigterm)
    main()
