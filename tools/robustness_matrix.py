#!/usr/bin/python3
"""The robustness matrix (issue 19): KGD cases built from physics alone, run, judged.

    /usr/bin/python3 tools/robustness_matrix.py [--out hfmpm-out/matrix] [--only NAME,...]
                                                [--cells N] [--force]

Each case is a problem (proto/hfmpm/problem.proto) spanning Km from 1e-2 to 1e2, E from
5 MPa to 30 GPa, nu from 0.15 to 0.35, confinement from 0.1 to 20 MPa, mu from 1e-4 to 1 Pa s,
Q over two decades, lab and field scale. For each: `hfmpm scene` builds the scene (no setting
is made for any one case), `hfmpm run` runs it, and the errors against the plane-strain
solution at its Km (tools/kgd_transition.py: the self-similar KGD between the vertices, zero
lag, no leak-off) are taken at every history row from three notch lengths on: the tip's and
the fluid front's half-length, the mouth opening and the net inlet pressure. Every case is
judged; the column "vertex" names its regime: M (Km < 1), MK (1 <= Km <= 4), K (Km > 4). The
transition solution reduces to the vertices (within 0.04% at Km <= 0.1 and 0.1% at Km >= 10,
its Km^-4 correction), so it is the better reference for every Km; `--reference vertex`
judges the M and K cases against kgd_plot.vertices() as before (the MK ones still against the
transition solution), to compare with results recorded before it.

Writes OUT/matrix.csv (one row per case, appended as cases finish; a finished case is not
run again unless --force), OUT/matrix.md (the table) and OUT/matrix.png. The notch of each
case is a sixth of its expected final half-length, so the comparison covers the second half.
--cells overrides accuracy.cells_per_half_length (default: the builder's 20).
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import kgd_plot  # noqa: E402  (the vertices and the history reader)
import kgd_transition  # noqa: E402  (the solution between the vertices; its table, standard library only)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HFMPM = os.path.join(ROOT, "build", "release", "bin", "hfmpm")

LAB = dict(E=1e7, nu=0.25, rho=2500, sigma=1e5, mu=0.01, Q=2.5e-4, t=5.0)
FIELD = dict(E=2e10, nu=0.25, rho=2600, sigma=1e6, mu=1e-4, Q=2e-5, t=300.0)


def toughness_for(km, E, nu, mu, Q):
    """K_Ic that gives the dimensionless toughness km: Km = K' / (E'^3 mu' Q)^(1/4)."""
    ep = E / (1 - nu * nu)
    return km * (ep ** 3 * 12 * mu * Q) ** 0.25 / math.sqrt(32 / math.pi)


def case(name, base, km, **changes):
    c = dict(base)
    c.update(changes)
    c["name"], c["km"] = name, km
    c["KIc"] = toughness_for(km, c["E"], c["nu"], c["mu"], c["Q"])
    return c


def cases():
    out = []
    for km in (0.01, 0.1, 1, 2, 3, 10):  # 2 and 3 since 5 December (the transition's gap)
        out.append(case(f"lab-km{km:g}", LAB, km))
        out.append(case(f"field-km{km:g}", FIELD, km))
    # Km = 100 in the lab rock and fluid opens its crack by 45% of its length
    # (w0 / L = 0.732 Km^(4/3) (mu' / E' t)^(1/3) at the K-vertex), which
    # `hfmpm scene` refuses (small strain); water in a 50 MPa rock for 10 s: 4.5%.
    out.append(case("lab-km100", LAB, 100, E=5e7, mu=1e-4, t=10.0))
    out.append(case("field-km100", FIELD, 100))
    out += [
        case("lab-E5MPa", LAB, 0.1, E=5e6),
        case("lab-E50MPa", LAB, 0.1, E=5e7),
        case("field-E5GPa", FIELD, 0.1, E=5e9),
        case("field-E30GPa", FIELD, 0.1, E=3e10),
        case("field-nu0.15", FIELD, 0.1, nu=0.15),
        case("lab-nu0.35-km10", LAB, 10, nu=0.35),
        case("field-sigma20MPa", FIELD, 0.1, sigma=2e7),
        case("field-sigma5MPa-km10", FIELD, 10, sigma=5e6),
        case("lab-mu1", LAB, 0.01, mu=1.0),
        case("field-mu1e-3", FIELD, 0.1, mu=1e-3),
        case("lab-Q10x", LAB, 0.1, Q=2.5e-3),
        case("field-Q0.1x", FIELD, 0.1, Q=2e-6),
        case("field-Q10x-km10", FIELD, 10, Q=2e-4),
        case("lab-t20s", LAB, 0.1, t=20.0),
    ]
    return out


def expected_length(c):
    """The shorter vertex half-length at the end (what the builder sizes the run by)."""
    m, k, _ = kgd_plot.vertices(c["E"], c["nu"], c["mu"], c["Q"], c["KIc"], c["t"])
    return min(m[0], k[0])


def problem_text(c, both_wings=False):
    notch = expected_length(c) / 6
    return (f'name: "{c["name"]}"\n'
            f'rock {{ youngs_modulus_pa: {c["E"]:.6g} poisson_ratio: {c["nu"]:.6g} density_kg_m3: {c["rho"]:.6g} '
            f'toughness_pa_sqrt_m: {c["KIc"]:.6g} }}\n'
            f'in_situ {{ normal_to_crack_pa: {c["sigma"]:.6g} }}\n'
            f'fluid {{ viscosity_pa_s: {c["mu"]:.6g} }}\n'
            f'injection {{ total_rate_m2_s: {c["Q"]:.6g}{" both_wings: true" if both_wings else ""} }}\n'
            f'duration_s: {c["t"]:.6g}\n'
            f'notch_m: {notch:.6g}\n')


def regime(km):
    """M (Km < 1), MK (1 <= Km <= 4), K (Km > 4)."""
    return "M" if km < 1 else "K" if km > 4 else "MK"


def judge(run, c, reference="transition"):
    """Worst |error| from three notch lengths on: tip, front, opening, pressure; the regime.

    Against kgd_transition.transition() at the run's Km, or (reference "vertex") against the
    vertex of an M or K case (kgd_plot.vertices(); MK cases still against the transition)."""
    p = kgd_plot.scene_parameters(run)
    h = kgd_plot.read_history(os.path.join(run, "history.csv"))
    if p.get("two_wing"):  # both wings modelled: the half-length is half the crack
        h["crack_length_m"] = [0.5 * v for v in h["crack_length_m"]]
    km = kgd_plot.km(p["E"], p["nu"], p["mu"], p["Q"], p["KIc"])
    label = regime(km)
    worst = [0.0] * 4
    l0 = h["crack_length_m"][0]
    for i, t in enumerate(h["time_s"]):
        te = t - p["t0"]
        if te <= 0 or h["crack_length_m"][i] < 3 * l0:
            continue
        args = (p["E"], p["nu"], p["mu"], p["Q"], p["KIc"], te)
        if reference == "vertex" and label != "MK":
            ref = kgd_plot.vertices(*args)[0 if label == "M" else 1]
        else:
            ref = kgd_transition.transition(*args)
        sim = (h["crack_length_m"][i], h["front_position_m"][i], h["mouth_opening_m"][i],
               h["inlet_pressure_pa"][i] - p["sigma0"])
        refs = (ref[0], ref[0], ref[1], ref[2])
        worst = [max(w, abs((s - r) / r)) for w, s, r in zip(worst, sim, refs)]
    return km, label, worst, h["time_s"][-1]


FIELDS = ["case", "Km", "vertex", "E_pa", "nu", "sigma_pa", "mu_pa_s", "Q_m2_s", "duration_s", "status", "wall_s",
          "tip_err", "front_err", "opening_err", "pressure_err", "within_5_5_10"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "hfmpm-out", "matrix"))
    ap.add_argument("--only", help="comma-separated case names")
    ap.add_argument("--cells", type=float, help="accuracy.cells_per_half_length (default: the builder's)")
    ap.add_argument("--force", action="store_true", help="run finished cases again")
    ap.add_argument("--reference", choices=("transition", "vertex"), default="transition",
                    help="judge against the transition solution at each Km (default) or, for M and K cases, "
                         "the vertex (kgd_plot.vertices())")
    ap.add_argument("--list", action="store_true", help="print the cases and stop")
    ap.add_argument("--both-wings", action="store_true",
                    help="build every case with both wings and a well inside the body (injection.both_wings)")
    a = ap.parse_args()
    todo = cases()
    if a.list:
        for c in todo:
            print(f'{c["name"]:24s} Km {c["km"]:<6g} E {c["E"]:.3g} nu {c["nu"]} sigma {c["sigma"]:.3g} '
                  f'mu {c["mu"]:.3g} Q {c["Q"]:.3g} t {c["t"]:g} K_Ic {c["KIc"]:.3g}')
        return
    if a.only:
        names = set(a.only.split(","))
        unknown = names - {c["name"] for c in todo}
        if unknown:
            sys.exit(f"robustness_matrix: unknown case(s) {sorted(unknown)}; --list shows them")
        todo = [c for c in todo if c["name"] in names]
    os.makedirs(os.path.join(a.out, "cases"), exist_ok=True)
    table = os.path.join(a.out, "matrix.csv")
    done = {}
    if os.path.exists(table):
        with open(table) as f:
            done = {r["case"]: r for r in csv.DictReader(f)}
    for c in todo:
        if c["name"] in done and not a.force:
            continue
        base = os.path.join(a.out, "cases", c["name"])
        text = problem_text(c, a.both_wings)
        if a.cells:
            text += f"accuracy {{ cells_per_half_length: {a.cells:g} }}\n"
        with open(base + ".problem", "w") as f:
            f.write(text)
        built = subprocess.run([HFMPM, "scene", base + ".problem", "--out", base + ".scene"], capture_output=True,
                               text=True)
        row = dict(case=c["name"], Km=f'{c["km"]:g}', E_pa=c["E"], nu=c["nu"], sigma_pa=c["sigma"], mu_pa_s=c["mu"],
                   Q_m2_s=c["Q"], duration_s=c["t"])
        if built.returncode != 0:
            row.update(status="refused by the builder: " + built.stderr.strip().replace("\n", " "), vertex="")
        else:
            run = os.path.join(a.out, "runs", c["name"])
            start = time.time()
            r = subprocess.run([HFMPM, "run", base + ".scene", "--out", run, "--quiet"], capture_output=True, text=True)
            row["wall_s"] = f"{time.time() - start:.1f}"
            if r.returncode != 0:
                lines = r.stderr.strip().splitlines() or ["?"]
                failed = [x for x in lines if "run failed:" in x]
                row.update(status="failed: " + (failed[0].split("run failed:", 1)[1].strip() if failed else lines[-1]),
                           vertex="")
            else:
                km, vertex, worst, _ = judge(run, c, a.reference)
                row.update(status="completed", vertex=vertex)
                for key, w in zip(("tip_err", "front_err", "opening_err", "pressure_err"), worst):
                    row[key] = f"{w:.4f}"
                row["within_5_5_10"] = "yes" if worst[1] <= 0.05 and worst[2] <= 0.05 and worst[3] <= 0.10 else "no"
        done[c["name"]] = row
        with open(table, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=FIELDS)
            w.writeheader()
            for r in done.values():
                w.writerow({k: r.get(k, "") for k in FIELDS})
        print(f'{row["case"]:24s} {row.get("status", "")[:60]:60s} wall {row.get("wall_s", "-")} s  '
              f'tip {row.get("tip_err", "")} front {row.get("front_err", "")} opening {row.get("opening_err", "")} '
              f'pressure {row.get("pressure_err", "")}', flush=True)
    write_report(a.out, done)


def write_report(out, rows):
    lines = ["| case | Km | vertex | status | wall (s) | tip | front | opening | pressure | front, opening 5%, pressure 10% |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows.values():
        pct = lambda k: f"{100 * float(r[k]):.1f}%" if r.get(k) else ""  # noqa: E731
        lines.append(f'| {r["case"]} | {r["Km"]} | {r.get("vertex", "")} | {r.get("status", "")} | {r.get("wall_s", "")} | '
                     f'{pct("tip_err")} | {pct("front_err")} | {pct("opening_err")} | {pct("pressure_err")} | '
                     f'{r.get("within_5_5_10", "")} |')
    judged = [r for r in rows.values() if r.get("within_5_5_10")]
    walls = [float(r["wall_s"]) for r in rows.values() if r.get("wall_s")]
    lines.append("")
    lines.append(f'{sum(r["within_5_5_10"] == "yes" for r in judged)} of {len(judged)} judged cases within the bounds; '
                 f'{len(rows)} cases, total wall {sum(walls):.0f} s')
    with open(os.path.join(out, "matrix.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = [r["case"] for r in rows.values()]
    fig, ax = plt.subplots(figsize=(12, 5))
    for j, (key, label) in enumerate((("front_err", "front"), ("opening_err", "mouth opening"),
                                      ("pressure_err", "net inlet pressure"), ("tip_err", "tip"))):
        vals = [100 * float(r[key]) if r.get(key) else 0 for r in rows.values()]
        ax.bar([i + 0.2 * j for i in range(len(names))], vals, width=0.2, label=label)
    ax.axhline(5, color="k", ls=":", lw=1)
    ax.axhline(10, color="k", ls="--", lw=1)
    ax.set_xticks([i + 0.3 for i in range(len(names))])
    ax.set_xticklabels(names, rotation=70, ha="right", fontsize=7)
    ax.set_ylabel("worst |error| from 3 notch lengths on (%)")
    ax.set_title("Robustness matrix: KGD scenes built from physics alone, against the solution at their Km")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "matrix.png"), dpi=110)


if __name__ == "__main__":
    main()
