#!/usr/bin/python3
"""The KGD hydraulic fracture from a finite notch, under a time-varying rate: a time-dependent reference.

    /usr/bin/python3 tools/kgd_notch.py RUN_DIR                 # a run against the notched reference
    /usr/bin/python3 tools/kgd_notch.py RUN --against BASE --compressible   # two runs, each against its own
    /usr/bin/python3 tools/kgd_notch.py --E 2e10 --nu 0.25 --mu 1e-4 --Q 2e-5 --notch 2 \
        --ramp 5 --times 50,100,300                             # the reference alone
    /usr/bin/python3 tools/kgd_notch.py --convergence           # refinement in space and time
    /usr/bin/python3 tools/kgd_notch.py --self-test             # ctest unit.KgdNotch.TendsToTheVertexAndKeepsItsOrder

Why. The vertex solutions (tools/kgd_plot.py, tools/kgd_transition.py) are self-similar: the crack
starts from nothing under a constant rate. A simulated KGD starts from a notch of length l0 that
holds no volume, its rate is ramped, and its fluid carries a virtual film. Those belong to the
set-up, not to the method's error. This solves the same model as the vertices (plane strain, zero
lag, zero toughness, Newtonian, no leak-off, an incompressible fluid) from the run's own start: a
notch of length l0, the run's rate Q(t) (constant, or a linear ramp from zero to Q), and
optionally the film, the w_v of a fluid width w + w_v, stored over the wetted length so that the
crack's opening holds V_injected - w_v (l - l0). A run compared with it carries only the
method's error. (Measured: the notch and the ramp fade fast. For kgd-paper-field's 2 m notch and
5 s ramp the solution is within 3e-4 of the vertex shifted by half the ramp from two notch
lengths on, and 44% longer at 8 s. The film's storage shortens the crack by about half its
volume fraction.)

Equations (E' = E/(1-nu^2), mu' = 12 mu, Q the TOTAL rate, each wing taking Q/2):
  elasticity   p(x) = E'/(4 pi) PV int_{-l}^{l} (dw/ds) ds / (x - s)
  lubrication  dw/dt + dq/dx = 0,  q = -(w^3/mu') dp/dx,  q(0+) = Q(t)/2,  q(l) = 0
  volume       int_0^l w dx = int_0^t Q/2 dt - w_v (l - l0)
  tip          w ~ beta_m (mu' dl/dt / E')^(1/3) (l - x)^(2/3),  beta_m = 2^(1/3) 3^(5/6)  (zero toughness)
In the frame xi = x/l that moves with the crack, with V(xi) = l int_xi^1 w the volume beyond xi,
the flux through x is q = dV/dt at fixed x = l' (xi w + W) + l dW/dt at fixed xi (W = int_xi^1 w),
so that the near-tip travelling wave (q = l' w) is kept at every scale and the time derivative is
taken where the solution changes slowly. Scaled by the end time t_r and the end rate Q_r
(tau = t/t_r, l = gamma L_r, w = eps_r L_r Omega, p = eps_r E' Pi, L_r = (E' Q_r^3 t_r^4/mu')^(1/6),
eps_r = (mu'/(E' t_r))^(1/3)):
  Pi_j - Pi_{j+1} = int hat_j gamma F / Omega^3,  F = gamma' (xi Omega + C) + gamma dC/dtau,
  C = int_xi^1 Omega,  gamma C(0) = V / (Q_r t_r),  Omega = beta_m gamma'^(1/3) gamma^(2/3) (1-xi)^(2/3) at the tip;
under a constant rate gamma = 0.6152 tau^(2/3) solves it (the M-vertex: F = gamma ((2/3) xi Omega + C)).

Method (ours): the space discretization is tools/kgd_transition.py's at Km = 0 (displacement
discontinuities graded to the tip, the tip element carrying the 2/3 asymptote, cell-averaged
elasticity, hat-weighted lubrication), whose Jacobian terms it reuses. Time is BDF2 on variable
steps (backward Euler for the first), with dC/dtau at fixed xi at the lubrication points. The
unknowns are ln Omega at the nodes and ln gamma' (so the crack never shortens), and each step is
solved by Newton with a line search. Steps are t (2^(1/STEPS_PER_DOUBLING) - 1), from 1e-4 of
that at the start, doubling each step, quartered when a step does not converge, and they land
on the times asked for. The start: at the time a vertex holding the injected volume would be
START_FRACTION l0 long, the notch holds that volume in the vertex's own shape (an exact state
of a propagating crack: the vertex of a smaller rate at the moment it is l0 long). A long notch
with little fluid then slows its tip sharply (the steps cut there). --convergence changes the
space resolution, the step and the start, and prints what moves (docs/verification.md quotes it).
"""
import argparse
import csv
import json
import math
import os
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # small dense solves: threads only contend
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import kgd_transition  # noqa: E402  (the mesh, the elasticity and the lubrication's Jacobian)

BETA_M = 2 ** (1 / 3) * 3 ** (5 / 6)
STEPS_PER_DOUBLING = 16
START_FRACTION = 0.2
KM_MAX = 0.5  # the zero-toughness reference against a run: at Km = 0.5 the length is 0.33% shorter


class Notched(kgd_transition.Solver):
    """One time step of the notched KGD (see the module docstring), on kgd_transition's Km = 0 mesh."""

    def __init__(self, rho):
        super().__init__(0.0, rho)

    def set_step(self, dtau, gamma_n, gamma_nm1, c_n, c_nm1, omega, volume):
        """BDF2 coefficients for a step of dtau after one of dtau / omega (omega = 0: backward Euler)."""
        if omega <= 0:
            self.b = (1.0, -1.0, 0.0)
        else:
            self.b = ((1 + 2 * omega) / (1 + omega), -(1 + omega), omega * omega / (1 + omega))
        self.dtau, self.volume = dtau, volume
        self.hist_gamma = -(self.b[1] * gamma_n + self.b[2] * gamma_nm1)
        self.hist_c = self.b[1] * c_n + (self.b[2] * c_nm1 if c_nm1 is not None else 0.0)

    def unpack(self, y):
        """Omega (the tip element's value included), gamma, the tip amplitude; y = (ln Omega, ln gamma')."""
        np, N = self.np, self.N
        gdot = math.exp(y[N - 1])
        g = (self.dtau * gdot + self.hist_gamma) / self.b[0]
        self.gdot = gdot
        amp = BETA_M * gdot ** (1 / 3) * g ** (2 / 3)
        om = np.empty(N)
        om[:N - 1] = np.exp(y[:N - 1])
        om[N - 1] = amp * self.st ** self.alpha
        return om, g, amp

    def lub_coefficients(self, g):
        b0, dt = self.b[0], self.dtau
        return g * self.gdot, g * (self.gdot + g * b0 / dt), g * g * self.hist_c / dt

    def volume_target(self, g):
        return max(self.volume(g), 1e-300)

    def mean_pressure(self, y):
        """Pi averaged over the crack, weighted by the opening (cell averages at the nodes)."""
        om, g, amp = self.unpack(y)
        wt = om * (self.cell_hi - self.cell_lo)
        return float((self.pressure(om, amp, g) * wt).sum() / wt.sum())

    def observe(self, y):
        """gamma, Omega(0), Pi(0) and C at the lubrication points of the solved step."""
        om, g, amp = self.unpack(y)
        cn = self.cumulative(om, amp)
        o, c = self.at_points(om, amp, cn)
        p = self.pressure(om, amp, g)
        return g, om[0], self.inlet_pressure(p, self.lub_points(o, c, *self.lub_coefficients(g))), c


def tait_volume_ratio(p, K, c):
    """J = V / V0 of hfmpm's Tait fluid at pressure p (fluid/include/hfmpm/fluid/mpm/eos.hpp)."""
    return 1 - c * math.log1p(p / (c * K))


def solve(E, nu, mu, Q, notch, times, ramp=0.0, film=0.0, rho=4.0, per_doubling=STEPS_PER_DOUBLING,
          start_fraction=START_FRACTION, fluid=None):
    """[(t, half-length, mouth opening, net inlet pressure, Newton iterations)] at each of times.

    Q: the TOTAL rate (both wings) at the end of a linear ramp over [0, ramp] (ramp = 0: constant);
    notch: the initial half-length l0; film: the virtual film w_v (0: none); fluid: None (the
    vertices' incompressible fluid) or (K, tait_c, sigma0): the injected mass (rho0 Q t) fills
    J(sigma0 + p) of its volume, p the crack's mean net pressure (opening-weighted, from the step
    before: it changes by under 1e-3 of itself per step)."""
    times = sorted(float(t) for t in times)
    if not times or times[0] <= 0 or notch <= 0 or Q <= 0 or E <= 0 or mu <= 0 or not -1 < nu < 0.5:
        raise ValueError("kgd_notch: need times > 0, notch > 0, Q > 0, E > 0, mu > 0 and -1 < nu < 0.5")
    ep, mup, tr = E / (1 - nu * nu), 12 * mu, times[-1]
    Lr = (ep * Q ** 3 * tr ** 4 / mup) ** (1 / 6)
    er = (mup / (ep * tr)) ** (1 / 3)
    vscale = Q * tr  # gamma C(0) = V / (Q_r t_r)

    def injected(t):  # per wing
        if ramp > 0 and t < ramp:
            return 0.5 * Q * t * t / (2 * ramp)
        return 0.5 * Q * (t - 0.5 * ramp)

    sv = Notched(rho)
    np, N = sv.np, sv.N
    g0 = notch / Lr
    # start: the notch holding what has been injected by then, in the M-vertex's shape (an exact
    # state of a propagating crack: the vertex of a smaller rate at the moment it is l0 long)
    # from the time the vertex holding the injected volume would be start_fraction l0 long
    lo_t, hi_t, gamma_v = 1e-12 * times[0], times[0], kgd_transition.constants(0.0)[0]
    for _ in range(200):
        t = math.sqrt(lo_t * hi_t)
        t_eff = 2 * injected(t) / Q
        if gamma_v * (ep * Q ** 3 * t_eff ** 4 / mup) ** (1 / 6) > start_fraction * notch:
            hi_t = t
        else:
            lo_t = t
    t = lo_t
    vertex = kgd_transition.Solver(0.0, rho)
    vertex.solve()
    om_v, g_v, amp_v = vertex.unpack(vertex.y)  # gamma_v C_v(0) = 1/2
    ratio0 = 1.0 if fluid is None else tait_volume_ratio(fluid[2], fluid[0], fluid[1])  # compressed at sigma0
    scale = (injected(t) * ratio0 / vscale) / (g0 * vertex.cumulative(om_v, amp_v)[0])
    om0, amp0 = scale * om_v, scale * amp_v
    c_prev = sv.at_points(om0, amp0, sv.cumulative(om0, amp0))[1]
    gam, gam_prev, c_old, dt_prev = g0, g0, None, 0.0
    y = np.concatenate([np.log(om0[:N - 1]), [3 * math.log(amp0 / (BETA_M * g0 ** (2 / 3)))]])  # its speed from its tip
    grow = 2 ** (1 / per_doubling)
    out, k, cut, rejected, p_mean = [], 0, 1.0, 0, 0.0
    while k < len(times):
        # steps of t (grow - 1), from 1e-4 of that at the start, cut after a rejected step
        dt = cut * min(t * (grow - 1), 2 * dt_prev if dt_prev > 0 else 1e-4 * t)
        if times[k] - (t + dt) < 1e-9 * times[k] or t + dt > times[k]:
            dt = times[k] - t
        t_new = t + dt
        omega = dt / dt_prev if dt_prev > 0 else 0.0

        ratio = 1.0 if fluid is None else tait_volume_ratio(fluid[2] + p_mean, fluid[0], fluid[1])

        def volume(g, t_new=t_new, ratio=ratio):
            return max(injected(t_new) * ratio - film * (g - g0) * Lr, 1e-30 * vscale) / vscale

        sv.set_step(dt / tr, gam, gam_prev, c_prev, c_old, omega, volume)
        try:
            y_new, its, _ = sv.newton(y, 40, t_min=1e-4, tol=1e-11)
        except (RuntimeError, np.linalg.LinAlgError):
            # a sharp change (the tip stopping as the notch outruns its fluid): a shorter step
            rejected += 1
            cut *= 0.25
            if cut < 1e-6:
                raise RuntimeError(f"kgd_notch: no step converges at t = {t:.6g} s")
            continue
        cut = min(1.0, 2 * cut)
        y = y_new
        g, om_c, pi_c, c_new = sv.observe(y)
        if fluid is not None:
            p_mean = sv.mean_pressure(y) * er * ep
        gam_prev, gam, c_old, c_prev, dt_prev, t = gam, g, c_prev, c_new, dt, t_new
        if abs(t - times[k]) <= 1e-9 * times[k]:
            out.append((t, g * Lr, om_c * er * Lr, pi_c * er * ep, its))
            k += 1
    solve.rejected = rejected
    return out


# ----------------------------------------------------------------------------- against a run
def run_setup(run):
    """E, nu, mu, Q (total), KIc, sigma0, the notch, the ramp's end, the film and two_wing of a run."""
    import kgd_plot
    prm = kgd_plot.scene_parameters(run)
    if not prm:
        sys.exit(f"kgd_notch: {run} has no scene.json (every hfmpm run directory has one); "
                 "for the reference alone give --E ... --times")
    with open(os.path.join(run, "scene.json")) as f:
        scene = json.load(f)
    fluid = scene["fluid"]["mpm"]
    crack = scene["solid"]["mpm"]["cracks"][0]
    xs, ys = [float(v) for v in crack["x_m"]], [float(v) for v in crack["y_m"]]
    length = sum(math.hypot(xs[i + 1] - xs[i], ys[i + 1] - ys[i]) for i in range(len(xs) - 1))
    inlet = fluid["inlet"]["flow_rate_m2_s"]
    ramp = 0.0
    if "ramp" in inlet:
        r = inlet["ramp"]
        if float(r.get("t0", 0)) != 0 or float(r.get("v0", 0)) != 0:
            sys.exit("kgd_notch: only a ramp from zero at t = 0 is modelled")
        ramp = float(r["t1"])
    prm.update(notch=0.5 * length if prm.get("two_wing") else length, ramp=ramp,
               film=float(fluid.get("virtual_opening_m", 0.0)), bulk_modulus=float(fluid.get("bulk_modulus_pa", 0)),
               tait_c=float(fluid.get("tait_c", 0.0894)))
    return prm


def evaluate(run, rho, film_on, compressible=False):
    """A run's rows from three notch lengths on and the notched reference at them: (prm, fluid, rows), each row
    (t, (tip, front, mouth opening, net inlet pressure), (length, mouth opening, net inlet pressure) of the
    reference)."""
    import kgd_plot
    prm = run_setup(run)
    h = kgd_plot.read_history(os.path.join(run, "history.csv"))
    half = 0.5 if prm.get("two_wing") else 1.0
    tip = [half * v for v in h["crack_length_m"]]
    km = kgd_transition.km_of(prm["E"], prm["nu"], prm["mu"], prm["Q"], prm["KIc"])
    if km > KM_MAX:
        sys.exit(f"kgd_notch: {run}: Km = {km:.3g}; this reference has zero toughness and serves Km <= {KM_MAX:g} "
                 "(where the toughness moves the solution by at most 0.33%); use tools/kgd_plot.py")
    front = None if prm.get("two_wing") else h.get("front_position_m")  # two wings: no per-wing front in history.csv
    rows = [i for i, t in enumerate(h["time_s"]) if t > 0 and tip[i] >= 3 * prm["notch"]]
    if not rows:
        sys.exit(f"kgd_notch: {run}: the crack never reaches three notch lengths ({3 * prm['notch']:g} m)")
    fluid = None
    if compressible:
        if not prm["bulk_modulus"] > 0:
            sys.exit(f"kgd_notch: {run}: the scene's fluid has no bulk modulus; --compressible needs one")
        fluid = (prm["bulk_modulus"], prm["tait_c"], prm["sigma0"])
    prm["film_used"] = prm["film"] if film_on else 0.0
    times = [h["time_s"][i] for i in rows]
    ref = solve(prm["E"], prm["nu"], prm["mu"], prm["Q"], prm["notch"], times, prm["ramp"], prm["film_used"], rho,
                fluid=fluid)
    out = []
    for i, (tt, lr, wr, pr, _) in zip(rows, ref):
        sim = (tip[i], front[i] if front else float("nan"), h["mouth_opening_m"][i],
               h["inlet_pressure_pa"][i] - prm["sigma0"])
        out.append((tt, sim, (lr, wr, pr)))
    return prm, fluid, out


def compare(run, rho, film_on, compressible=False):
    prm, fluid, rows = evaluate(run, rho, film_on, compressible)
    t0 = 0.5 * prm["ramp"]
    print(f"{run}: E {prm['E']:g} Pa, nu {prm['nu']:g}, mu {prm['mu']:g} Pa s, Q {prm['Q']:g} m^2/s (total), "
          f"ramp {prm['ramp']:g} s, notch {prm['notch']:g} m, film {prm['film_used']:g} m"
          + (f", fluid K {prm['bulk_modulus']:g} Pa at sigma0 {prm['sigma0']:g} Pa" if fluid else "")
          + "; rows from three notch lengths on")
    print(f"{'t (s)':>8} {'l ref':>8} {'tip':>7} {'front':>7} {'w0':>7} {'p0':>7} | {'Km: tip':>7} {'front':>7} "
          f"{'w0':>7} {'p0':>7}")
    worst = [0.0] * 8
    for tt, sim, (lr, wr, pr) in rows:
        m = kgd_transition.transition(prm["E"], prm["nu"], prm["mu"], prm["Q"], prm["KIc"], tt - t0)
        e = [(sim[0] - lr) / lr, (sim[1] - lr) / lr, (sim[2] - wr) / wr, (sim[3] - pr) / pr,
             (sim[0] - m[0]) / m[0], (sim[1] - m[0]) / m[0], (sim[2] - m[1]) / m[1], (sim[3] - m[2]) / m[2]]
        worst = [max(a, abs(b)) if b == b else a for a, b in zip(worst, e)]
        print(f"{tt:8.3f} {lr:8.4f} " + " ".join(f"{v:+7.3f}" for v in e[:4]) + " | "
              + " ".join(f"{v:+7.3f}" for v in e[4:]))
    print(f"worst against the notched reference: tip {worst[0]:.3f}, front {worst[1]:.3f}, opening {worst[2]:.3f}, "
          f"pressure {worst[3]:.3f}; against the solution at the run's Km (t - {t0:g} s, tools/kgd_transition.py): "
          f"tip {worst[4]:.3f}, front {worst[5]:.3f}, opening {worst[6]:.3f}, pressure {worst[7]:.3f}")
    return worst


def against(run, base, rho, film_on, compressible):
    """Two runs of one set-up (another fluid stiffness, step, ...), row by row at the times both have: how far
    apart the runs are, how far apart their references are, and how far apart their errors against their own
    references are (front, mouth opening, net inlet pressure; the worst over the common rows)."""
    _, _, a = evaluate(run, rho, film_on, compressible)
    _, _, b = evaluate(base, rho, film_on, compressible)
    by_time = {round(t, 6): (sim, ref) for t, sim, ref in b}
    common = [(sim, ref, by_time[round(t, 6)]) for t, sim, ref in a if round(t, 6) in by_time]
    if not common:
        sys.exit(f"kgd_notch: {run} and {base} have no output time in common from three notch lengths on")
    runs, refs, errors = [0.0] * 3, [0.0] * 3, [0.0] * 3
    for sim, ref, (sim_b, ref_b) in common:
        for k, j in enumerate((1, 2, 3)):  # front, opening, pressure; the reference's length is its front
            r = 0 if j == 1 else j - 1
            runs[k] = max(runs[k], abs(sim[j] / sim_b[j] - 1))
            refs[k] = max(refs[k], abs(ref[r] / ref_b[r] - 1))
            errors[k] = max(errors[k], abs((sim[j] / ref[r]) / (sim_b[j] / ref_b[r]) - 1))
    print(f"{run} against {base}, {len(common)} rows from three notch lengths on (front / opening / pressure), "
          f"{'compressible' if compressible else 'incompressible'} references:")
    print("  the runs differ by              " + " / ".join(f"{100 * v:.1f}%" for v in runs))
    print("  their references differ by      " + " / ".join(f"{100 * v:.1f}%" for v in refs))
    print("  their errors against their own  " + " / ".join(f"{100 * v:.1f}%" for v in errors))


# ----------------------------------------------------------------------------- checks
def self_test():
    """ctest unit.KgdNotch.TendsToTheVertexAndKeepsItsOrder (about 10 s)."""
    fails = 0

    def check(ok, what):
        nonlocal fails
        fails += 0 if ok else 1
        print(("ok   " if ok else "FAIL ") + what)

    def rel(sim, ref):
        return [(a - b) / b for a, b in zip(sim, ref)]

    # 1. a notch far shorter than the crack, a constant rate: the M-vertex (the space error of
    #    rho = 4 is 2e-4 against the refined table, kgd_transition --convergence)
    E, nu, mu, Q = 1e7, 0.25, 0.01, 5e-4
    ref = solve(E, nu, mu, Q, 1e-3, [1.0, 100.0])
    e = max(abs(v) for r in ref for v in rel(r[1:4], kgd_transition.transition(E, nu, mu, Q, 0.0, r[0])))
    check(e < 1e-3, f"a notch of 1 mm, l = {ref[0][1]:.3g} to {ref[1][1]:.3g} m: within 1e-3 of the M-vertex ({e:.1e})")
    # 2. second order in time: against the self-similar solution on the same mesh
    g4 = kgd_transition.solve(0.0, 4.0)[0][0]
    ep, mup = E / (1 - nu * nu), 12 * mu
    err = []
    for per in (8, 16):
        t, l = solve(E, nu, mu, Q, 1e-3, [10.0], per_doubling=per)[0][:2]
        err.append(abs(l / (g4 * (ep * Q ** 3 * t ** 4 / mup) ** (1 / 6)) - 1))
    check(3 < err[0] / err[1] < 5, f"BDF2: the length's error {err[0]:.2e} -> {err[1]:.2e} as the step halves "
          f"(ratio {err[0] / err[1]:.2f}, second order 4)")
    # 3. the paper's field case (a 2 m notch, a 5 s ramp): longer than the vertex while the
    #    notch holds the crack, within 1e-3 of it (time shifted by half the ramp) from two notch lengths on
    E, nu, mu, Q = 2e10, 0.25, 1e-4, 2e-5
    ref = solve(E, nu, mu, Q, 2.0, [8.0, 30.0, 100.0], ramp=5.0)
    e = [rel(r[1:4], kgd_transition.transition(E, nu, mu, Q, 0.0, r[0] - 2.5)) for r in ref]
    check(e[0][0] > 0.3, f"at 8 s the notch (2 m) holds the crack {100 * e[0][0]:.0f}% longer than the vertex")
    late = max(abs(v) for row in e[1:] for v in row)
    check(ref[1][1] > 4.0 and late < 1e-3,
          f"from two notch lengths on ({ref[1][1]:.2f} m at 30 s) within 1e-3 of the vertex ({late:.1e})")
    # 4. the film: the opening holds phi = w_v (l - l0) / V less; at fixed time the vertex's length
    #    goes as V^(1/2), so the crack is shorter by phi / 2
    wv = 2e-5
    lf, l0 = solve(E, nu, mu, Q, 2.0, [100.0], ramp=5.0, film=wv)[0][1], ref[2][1]
    phi = wv * (lf - 2.0) / (0.5 * Q * (100.0 - 2.5))
    check(abs((lf - l0) / l0 + phi / 2) < 0.15 * phi / 2,
          f"a film of {wv:g} m shortens the crack by {100 * (l0 - lf) / l0:.2f}%, phi / 2 = {50 * phi:.2f}%")
    # 5. a compressible fluid: the injected mass fills J of its volume, and at fixed time the
    #    vertex's length and opening go as V^(1/2): both shorter by about (1 - J) / 2
    E, nu, mu, Q, K, c, s0 = 1e7, 0.25, 0.01, 2.5e-4, 2e6, 0.0894, 1e5
    inc = solve(E, nu, mu, Q, 0.15, [5.0], ramp=0.05)[0]
    com = solve(E, nu, mu, Q, 0.15, [5.0], ramp=0.05, fluid=(K, c, s0))[0]
    j = tait_volume_ratio(s0 + com[3], K, c)  # about: the mean net pressure is below the inlet's
    dl, dw = com[1] / inc[1] - 1, com[2] / inc[2] - 1
    want = math.sqrt(j) - 1
    check(abs(dl - want) < 0.25 * abs(want) and abs(dw - want) < 0.25 * abs(want),
          f"kgd-viscosity-ci's set-up with K = 2 MPa: length {100 * dl:+.2f}%, opening {100 * dw:+.2f}% against the "
          f"incompressible fluid; J^(1/2) - 1 = {100 * (math.sqrt(j) - 1):+.2f}% at sigma0 + the inlet pressure")
    return fails


def convergence(E=2e10, nu=0.25, mu=1e-4, Q=2e-5, notch=2.0, ramp=5.0, film=2e-6, times=(8.0, 50.0, 100.0, 300.0)):
    """Each resolution against the default (rho 4, 16 steps per doubling, started at 0.2 l0): kgd-paper-field's case."""
    print(f"E {E:g}, nu {nu:g}, mu {mu:g}, Q {Q:g} (total), notch {notch:g} m, ramp {ramp:g} s, film {film:g} m")
    base = None
    for rho, per, frac, what in ((4, STEPS_PER_DOUBLING, START_FRACTION, "default"),
                                 (8, STEPS_PER_DOUBLING, START_FRACTION, "rho doubled"),
                                 (4, 2 * STEPS_PER_DOUBLING, START_FRACTION, "steps doubled"),
                                 (4, STEPS_PER_DOUBLING, 0.5 * START_FRACTION, "started at half the length")):
        ref = solve(E, nu, mu, Q, notch, times, ramp, film, rho, per, frac)
        line = "  ".join(f"t {t:g}: l {l:.5f} w0 {w * 1e3:.6f} mm p0 {p:.1f} Pa" for t, l, w, p, _ in ref)
        print(f"{what:>27}: {line}  ({solve.rejected} steps cut)")
        if base is None:
            base = ref
        else:
            for label, rows in (("while the notch holds it", [j for j, r in enumerate(base) if r[1] < 2 * notch]),
                                ("from two notch lengths on", [j for j, r in enumerate(base) if r[1] >= 2 * notch])):
                if rows:
                    d = [max(abs(ref[j][i] - base[j][i]) / abs(base[j][i]) for j in rows) for i in (1, 2, 3)]
                    print(f"{'':>27}  change from the default {label}: length {d[0]:.1e}, opening {d[1]:.1e}, "
                          f"pressure {d[2]:.1e}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run", nargs="?", help="an hfmpm run directory (scene.json, history.csv)")
    ap.add_argument("--E", type=float)
    ap.add_argument("--nu", type=float)
    ap.add_argument("--mu", type=float)
    ap.add_argument("--Q", type=float, help="the TOTAL rate at the ramp's end (m^2/s)")
    ap.add_argument("--notch", type=float, help="the initial half-length (m)")
    ap.add_argument("--ramp", type=float, default=0.0, help="a linear ramp from 0 over [0, RAMP] s (default 0)")
    ap.add_argument("--film", type=float, default=0.0, help="the virtual film (m; a run's own by default)")
    ap.add_argument("--no-film", action="store_true", help="with a run: leave the scene's film out")
    ap.add_argument("--against", metavar="BASE_RUN",
                    help="with a run: compare it with another run of the same set-up row by row, each against its "
                         "own reference (the bulk-modulus table of docs/verification.md)")
    ap.add_argument("--compressible", action="store_true",
                    help="with a run: its fluid's Tait compression at sigma0 + the mean net pressure (the vertices' "
                         "fluid is incompressible)")
    ap.add_argument("--times", help="comma-separated times (s) for the reference alone")
    ap.add_argument("--rho", type=float, default=4.0, help="space resolution (kgd_transition's rho; default 4)")
    ap.add_argument("--convergence", action="store_true")
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    if a.self_test:
        sys.exit(self_test())
    if a.convergence:
        convergence()
        return
    if a.run:
        if a.against:
            against(a.run, a.against, a.rho, not a.no_film, a.compressible)
        else:
            compare(a.run, a.rho, not a.no_film, a.compressible)
        return
    need = [k for k in ("E", "nu", "mu", "Q", "notch", "times") if getattr(a, k) is None]
    if need:
        ap.error("without a run directory give " + ", ".join("--" + k for k in need))
    try:
        times = [float(v) for v in a.times.split(",")]
    except ValueError:
        ap.error(f"--times: '{a.times}' is not a comma-separated list of numbers")
    if a.ramp < 0 or a.film < 0:
        ap.error("--ramp and --film must be >= 0")
    try:
        rows = solve(a.E, a.nu, a.mu, a.Q, a.notch, times, a.ramp, a.film, a.rho)
    except (ValueError, RuntimeError) as e:
        sys.exit(str(e))
    w = csv.writer(sys.stdout)
    w.writerow(["time_s", "half_length_m", "mouth_opening_m", "net_inlet_pressure_pa"])
    for t, l, wo, p, _ in rows:
        w.writerow([f"{t:.6g}", f"{l:.6g}", f"{wo:.6g}", f"{p:.6g}"])


if __name__ == "__main__":
    main()
