#!/usr/bin/env python3
"""Reference paths for a crack that turns in an anisotropic in-situ stress: a dry crack under a
given pressure history (issue 18), and a fluid-driven crack in the toughness regime.

The reference is an independent method: a displacement-discontinuity boundary-element solver
(Crouch and Starfield's constant elements) for a crack of straight segments in a plane-strain
body under a uniform far-field (in-situ) stress, its faces loaded by a uniform pressure, with
contact where the faces would interpenetrate (frictionless, or Coulomb friction mu: a shut face
carries shear up to mu times its contact stress). The body is the MPM test's plate (+-5 m, its
edges holding the in-situ stress: boundary elements whose induced traction is zero) or, with
--plate 0, an infinite plane. K_I and K_II at each tip come from the opening and sliding of the
elements nearest the tip (LEFM's square-root near-tip field, extrapolated to the tip with the
constant elements' own error fitted out; within 0.4% of the exact K at 40 elements on a straight
crack, 0.05% at 80). The crack grows from both tips by steps of a given length in the direction
of maximum hoop stress (Erdogan and Sih).

Dry growth (path files): each step is solved at the pressure the MPM run had at the check that
grew that step, read from its path file, so the two solve the same load history and differ only
in the method.

Fluid-driven growth (--fluid): a straight notch of half-length a0 at theta deg from x, centred
at the origin, in the in-situ compressions sigma_H (along the azimuth, deg from x) and sigma_h,
fluid injected at Q (m^2/s). The fluid is incompressible, leaks off nowhere and wets the whole
crack at one pressure p (no lag). At each step p is the lowest pressure at which a tip reaches
K_Ic: by default sqrt(K_I^2 + K_II^2) = K_Ic, the energy release rate (K_I^2 + K_II^2) / E' at
G_c (hfmpm grows on J >= J_Ic); with --criterion hoop, the maximum hoop stress's equivalent
cos^3(th/2) K_I - 1.5 cos(th/2) sin(th) K_II at the kink th. For fixed contact states K and the
crack's volume V are linear in p (two solves: the in-situ stress alone, a unit pressure); the
crack is tried open everywhere first, and with contact where its faces would interpenetrate.
The step's time is t = V / Q. A crack already past K_Ic at the fluid it holds grows without
injection (no time passes). V is the opening integrated over the crack, the constant elements'
excess volume (a quarter of the tip element's length at each tip) taken out. A notch whose
in-situ shear alone brings it to K_Ic (|tau| sqrt(pi a0) >= K_Ic, frictionless) grows in shear
before any fluid drives it; that is not a toughness-dominated fluid-driven path, and the tool
says so and stops (exit 2; --dry-growth continue grows it anyway, the fluid then held at or
above --p-floor, 0 by default). path_distance() gives, from another script, how far hfmpm's tip
points lie from the reference path of the same tip, in growth steps.

  /usr/bin/python3 tools/curved_path.py --self-test [dry|fluid]
      the solver against closed forms (both parts by default), exits 1 on a failure. dry: a
      pressurised Griffith crack, an inclined crack under tension (K_I, K_II, the first kink of
      -53.13 deg), refined twice; a crack shut by the in-situ stress; short kinks. fluid: the
      fluid-driven notch along sigma_H (p = sigma_h + K_Ic / sqrt(pi a) and V = 2 pi (1 - nu^2)
      (p - sigma_h) a^2 / E at every step, a straight path); at 30 deg under isotropic stress
      (straight, point-symmetric); at 30 deg under anisotropic stress (K_I, K_II and the first
      kink against the closed form, point symmetry, the heading turning toward sigma_H at every
      step; the hoop criterion); Coulomb friction on a shut crack (K_II = (|tau| - mu |sigma_n|)
      sqrt(pi a), the largest slip 4 (1 - nu^2)(|tau| - mu |sigma_n|) a / E; held where
      |tau| < mu |sigma_n|); a notch its in-situ shear brings to K_Ic stopped; path_distance.
  /usr/bin/python3 tools/curved_path.py RUN.csv [RUN.csv ...] [--png F] [--step-fraction f]
      each MPM path file (written by hfmpm_solid_oblique_growth_test with HFMPM_PATH_OUT,
      HFMPM_OBLIQUE_CELLS=n) against the reference for its load history: where the end tip's
      path crosses y = 1.5 m, the headings at the end, the largest distance between the paths;
      the reference's own convergence in its step; a PNG of all the paths; with
      --max-distance s, exits 1 if a tip cut by hfmpm's growth lies farther than s growth steps
      from the reference path (ctest: verification.CurvedPath.*).
  /usr/bin/python3 tools/curved_path.py --fluid --E 2e10 --nu 0.25 --KIc 1e6 --sigma-H 20.5e6
          --sigma-h 20e6 --azimuth 0 --theta 30 --a0 5 --Q 1e-3 --ds 0.5 --steps 30
          [--mu 0.6] [--criterion hoop] [--plate 5] [--csv F] [--png F]
          [--tips HFMPM.csv [--tips-origin x,y] [--max-distance s]]
      the fluid-driven path, a row per step: t, p, each tip's position, K_I, K_II (in the tip's
      frame) and kink; --csv writes step, t_s, p_pa, tip, x_m, y_m, K_I, K_II, kink_deg,
      length_m (tip to tip along the crack; step k: the crack after k steps, as it grows);
      --tips, hfmpm's tip points (tip, x, y; or a run directory: its solid.h5's last frame)
      against it.

Units SI. Stress positive in tension inside the solver (sigma_H, sigma_h on the command line are
compressive magnitudes); the MPM test's dry case: E = 10 GPa, nu = 0.25, a 2 m crack at 45 deg,
sigma_xx = -2 MPa, sigma_yy = -6 MPa.
"""
import argparse
import csv
import math
import os
import sys

import numpy as np

E, NU = 1e10, 0.25
G = E / (2 * (1 + NU))
EP = 2 * G / (1 - NU)  # E' = E / (1 - nu^2)


def influence(p0, p1):
    """The 2N x 2N matrix of the shear and normal traction at each element's centre (rows
    [tau_0, sigma_0, tau_1, ...] in that element's frame) from unit shear and normal
    displacement discontinuities of each element (columns [Ds_0, Dn_0, ...]; Crouch and
    Starfield's signs: D = u(below) - u(above), so an open crack has Dn < 0)."""
    n = len(p0)
    c = 0.5 * (p0 + p1)
    d = p1 - p0
    a = 0.5 * np.hypot(d[:, 0], d[:, 1])
    t = d / (2 * a)[:, None]
    nrm = np.stack([-t[:, 1], t[:, 0]], axis=1)
    k0 = 1 / (4 * math.pi * (1 - NU))
    # local coordinates of centre i in the frame of element j: [i, j]
    dx = c[:, None, :] - c[None, :, :]
    x = dx[..., 0] * t[None, :, 0] + dx[..., 1] * t[None, :, 1]
    y = dx[..., 0] * nrm[None, :, 0] + dx[..., 1] * nrm[None, :, 1]
    aj = a[None, :]
    xm, xp = x - aj, x + aj
    r1, r2 = xm**2 + y**2, xp**2 + y**2
    fxy = k0 * (y / r1 - y / r2)
    fxx = k0 * (xm / r1 - xp / r2)
    fyy = -fxx
    fxyy = k0 * ((xm**2 - y**2) / r1**2 - (xp**2 - y**2) / r2**2)
    fyyy = 2 * y * k0 * (xm / r1**2 - xp / r2**2)
    # local stresses of unit Ds and unit Dn
    s_ds = (2 * G * (2 * fxy + y * fxyy), 2 * G * (-y * fxyy), 2 * G * (fyy + y * fyyy))
    s_dn = (2 * G * (fyy + y * fyyy), 2 * G * (fyy - y * fyyy), 2 * G * (-y * fxyy))
    A = np.zeros((2 * n, 2 * n))
    for col, (sxx, syy, sxy) in enumerate((s_ds, s_dn)):
        # rotate to global: sigma_g = R sigma_l R^T, R = [t_j n_j]
        tj0, tj1 = t[None, :, 0], t[None, :, 1]
        nj0, nj1 = nrm[None, :, 0], nrm[None, :, 1]
        gxx = sxx * tj0 * tj0 + 2 * sxy * tj0 * nj0 + syy * nj0 * nj0
        gyy = sxx * tj1 * tj1 + 2 * sxy * tj1 * nj1 + syy * nj1 * nj1
        gxy = sxx * tj0 * tj1 + sxy * (tj0 * nj1 + nj0 * tj1) + syy * nj0 * nj1
        ti0, ti1 = t[:, None, 0], t[:, None, 1]
        ni0, ni1 = nrm[:, None, 0], nrm[:, None, 1]
        tx, ty = gxx * ni0 + gxy * ni1, gxy * ni0 + gyy * ni1  # traction on i
        A[0::2, col::2] = tx * ti0 + ty * ti1
        A[1::2, col::2] = tx * ni0 + ty * ni1
    return A, t, nrm, a


def box_elements(box, size):
    """The edges of the rectangle box = (x0, x1, y0, y1) as elements of about `size`,
    counter-clockwise."""
    x0, x1, y0, y1 = box
    corners = [np.array(c, float) for c in ((x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0))]
    out = [corners[0]]
    for a, b in zip(corners[:-1], corners[1:]):
        m = max(1, int(round(np.linalg.norm(b - a) / size)))
        out += [a + (b - a) * (j / m) for j in range(1, m + 1)]
    return np.array(out)


OPEN, STICK = 0, 2  # an element's contact state: open, shut and slipping (+1 / -1, the sign of Ds), stuck


class Body:
    """The boundary-element system of a crack (a polyline) in a plane-strain body under the
    far-field (in-situ) stress `stress` = (sxx, syy, sxy), its faces loaded by a uniform
    pressure p: A D = b0 + p bp, rows [tau_0, sigma_0, tau_1, ...] of the crack's elements, then
    the plate's edges (box = (x0, x1, y0, y1): elements along the edges whose induced traction is
    zero, so that the edges hold the far-field stress). ep = E / (1 - nu^2): the stresses, the
    K's and the contact do not depend on the elastic constants, the discontinuities D scale with
    1 / E' (ep=None: this module's E, NU).

    Contact: a crack element is open (both tractions its loads: shear 0, normal -p), or shut
    (Dn = 0, its normal traction free; the contact stress sigma_c = sigma_n + p must press, < 0).
    A shut element slips (its shear traction mu |sigma_c|, against its slip) or, with friction,
    sticks (Ds = 0: a crack loaded once, in proportion, has not slipped where it sticks); with
    mu = 0 every shut element slips freely."""

    def __init__(self, points, stress, box=None, box_size=0.25, ep=None):
        p = np.asarray(points, dtype=float)
        p0, p1 = p[:-1], p[1:]
        nc = len(p0)
        if box is not None:
            q = box_elements(box, box_size)
            p0, p1 = np.vstack([p0, q[:-1]]), np.vstack([p1, q[1:]])
        A, t, nrm, a = influence(p0, p1)
        if box is not None:
            # A uniform discontinuity around a closed contour moves its inside as a rigid body and
            # stresses nothing: the edges' equations are singular in three rigid modes. A spring of
            # 1e-9 of the diagonal on the edge elements fixes them without changing the traction
            # (the K's of the self-test's cracks change by less than 1e-6 relative).
            edge = np.arange(2 * nc, 2 * len(p0))
            A[edge, edge] += 1e-9 * np.abs(A[edge, edge]).max()
        if ep is not None:
            A *= ep / EP
        sxx, syy, sxy = stress
        tx = sxx * nrm[:, 0] + sxy * nrm[:, 1]
        ty = sxy * nrm[:, 0] + syy * nrm[:, 1]
        self.b0 = np.zeros(2 * len(p0))
        self.b0[0:2 * nc:2] = -(tx[:nc] * t[:nc, 0] + ty[:nc] * t[:nc, 1])  # shear traction free
        self.b0[1:2 * nc:2] = -(tx[:nc] * nrm[:nc, 0] + ty[:nc] * nrm[:nc, 1])  # normal traction -p
        self.bp = np.zeros(2 * len(p0))
        self.bp[1:2 * nc:2] = -1.0
        self.A, self.nc, self.a, self.ep = A, nc, a[:nc], EP if ep is None else float(ep)

    def rhs(self, p):
        return self.b0 + p * self.bp

    def constrained(self, mode, mu, b):
        """The matrix and right-hand side(s) b (rows first) with the shut elements' rows
        replaced: Dn = 0; slipping (mode s = +-1) tau - s mu sigma_c = 0; stuck Ds = 0."""
        M, b = self.A.copy(), np.array(b, dtype=float)
        slip = np.nonzero((mode == 1) | (mode == -1))[0]
        if mu > 0 and len(slip):
            rs, rn = 2 * slip, 2 * slip + 1
            smu = (mode[slip] * mu)[:, None]
            M[rs, :] = self.A[rs, :] - smu * self.A[rn, :]
            b[rs] = b[rs] - (smu if b.ndim == 2 else smu[:, 0]) * b[rn]
        stuck = 2 * np.nonzero(mode == STICK)[0]
        shut = 2 * np.nonzero(mode != OPEN)[0] + 1
        for rows in (stuck, shut):
            M[rows, :] = 0
            M[rows, rows] = 1
            b[rows] = 0
        return M, b

    def update(self, mode, D, p, mu):
        """The contact states that the solution D at pressure p calls for: an open element whose
        faces interpenetrate (Dn > 0) shuts; a shut one whose contact stress pulls (>= 0)
        opens; with friction, a stuck one whose shear exceeds mu |sigma_c| slips against it, a
        slipping one whose slip turns against its friction sticks."""
        nc = self.nc
        r = self.A[:2 * nc] @ D - self.rhs(p)[:2 * nc]  # tau, sigma_c on shut elements
        dsl, dn, tau, sig = D[0:2 * nc:2], D[1:2 * nc:2], r[0::2], r[1::2]
        new = mode.copy()
        shut = (dn > 0) | ((mode != OPEN) & (sig < 0))  # Dn of a shut element is 0 to round-off
        closing = shut & (mode == OPEN)
        new[closing] = np.where(dsl[closing] < 0, -1, 1) if mu > 0 else 1
        new[~shut] = OPEN
        if mu > 0:
            held = (mode != OPEN) & (new != OPEN)
            slips = held & (mode == STICK) & (np.abs(tau) > mu * np.abs(sig) * (1 + 1e-9))
            new[slips] = np.where(tau[slips] > 0, -1, 1)
            new[held & ((mode == 1) | (mode == -1)) & (mode * dsl < 0)] = STICK
        return new

    def equilibrium(self, p, mu=0.0, mode=None, max_iter=100):
        """D at pressure p, repeating the solve until the contact states no longer change."""
        mode = np.zeros(self.nc, dtype=int) if mode is None else mode.copy()
        for _ in range(max_iter):
            M, b = self.constrained(mode, mu, self.rhs(p))
            D = np.linalg.solve(M, b)
            now = self.update(mode, D, p, mu)
            if np.array_equal(now, mode):
                break
            mode = now
        return D, mode


def solve(points, stress, pressure, box=None, box_size=0.25, mu=0.0, ep=None):
    """Displacement discontinuities (Ds, Dn per crack element, and the elements' half-lengths)
    of the crack `points` (polyline, N+1 points) whose faces carry `pressure` in the far field
    `stress` = (sxx, syy, sxy), with contact (Coulomb friction mu; 0: frictionless). With box =
    (x0, x1, y0, y1) the body is that rectangle, its edges holding the far-field stress (the
    MPM test's traction edges). See Body."""
    body = Body(points, stress, box, box_size, ep)
    D, _ = body.equilibrium(pressure, mu)
    nc = body.nc
    return D[0:2 * nc:2], D[1:2 * nc:2], body.a


def tip_k(ds, dn, a, at_end, last=6, ep=None):
    """K_I and K_II at a tip, in the tip's frame (x1 out of the crack, x2 to its left), from
    the near-tip field's opening w = 8 K_I sqrt(r / 2 pi) / E' (and sliding with K_II): the
    apparent K at the centres of the elements 1..last from the tip (the tip element 0, a
    constant standing for a square root, left out) is fitted by K + c d / r + b r, d the tip
    element's length. The d / r term is the constant elements' error (the apparent K of a
    Griffith crack is 1 + 0.128 d / r times the exact at every refinement), the r term the
    field's next order. Both tips use the same formula with the elements' signs (-D is the
    jump above the crack less below). ep: the body's E' (None: this module's). K is linear in
    the D's."""
    n = len(ds)
    idx = list(range(n - 1, -1, -1)) if at_end else list(range(n))
    ep = EP if ep is None else ep
    d = 2 * a[idx[0]]
    r_along, rows, k1s, k2s = 0.0, [], [], []
    for m, e in enumerate(idx[: last + 1]):
        r = r_along + a[e]
        r_along += 2 * a[e]
        if m == 0:
            continue
        f = ep * math.sqrt(2 * math.pi) / (8 * math.sqrt(r))
        rows.append([1.0, d / r, r])
        k1s.append(-dn[e] * f)
        k2s.append(-ds[e] * f)
    basis = np.array(rows)
    c1 = np.linalg.lstsq(basis, np.array(k1s), rcond=None)[0]
    c2 = np.linalg.lstsq(basis, np.array(k2s), rcond=None)[0]
    return float(c1[0]), float(c2[0])


def kink_angle(k1, k2):
    """Maximum hoop stress (Erdogan and Sih): the kink from the tip's direction, rad."""
    if abs(k2) < 1e-12 * abs(k1):
        return 0.0
    return 2 * math.atan((k1 - math.sqrt(k1 * k1 + 8 * k2 * k2)) / (4 * k2))


def straight(center, angle, half, n):
    c = np.asarray(center, float)
    u = np.array([math.cos(angle), math.sin(angle)])
    return [c + u * s for s in np.linspace(-half, half, n + 1)]


STRESS = (-2e6, -6e6, 0.0)  # the MPM test's in-situ stress, Pa (sigma_xx, sigma_yy, sigma_xy)


def refine(path, m=8):
    """The boundary elements of a path (a polyline of straight growth steps, the initial crack
    at the same spacing): each step split in m equal elements, so that the tip fit (6
    elements) stays within the tip's own step, after its kink. Uniform on purpose: grading
    the elements away from the tips moved a Griffith crack's K by 0.7-4% (constant elements'
    error reaches the tip from coarse elements behind it)."""
    pts = [np.asarray(q, float) for q in path]
    out = [pts[0]]
    for a, b in zip(pts[:-1], pts[1:]):
        out += [a + (b - a) * (j / m) for j in range(1, m + 1)]
    return out


def grow(path, stress, pressures, step, box=None):
    """Grows the crack `path` (a polyline) from both tips by `step` per growth step, the k-th
    at pressures[k], in the maximum-hoop-stress direction. Returns the log of every growth
    decision and the final path."""
    pts = [np.asarray(q, float) for q in path]
    log = []
    for k, p in enumerate(pressures):
        elements = refine(pts)
        ds, dn, a = solve(elements, stress, p, box)
        new = []
        for at_end in (False, True):
            k1, k2 = tip_k(ds, dn, a, at_end)
            tip, prev = (pts[-1], pts[-2]) if at_end else (pts[0], pts[1])
            d = (tip - prev) / np.linalg.norm(tip - prev)
            th = kink_angle(k1, k2)
            c, s = math.cos(th), math.sin(th)
            dnew = np.array([c * d[0] - s * d[1], s * d[0] + c * d[1]])
            new.append(tip + step * dnew)
            log.append({"step": k + 1, "at_end": at_end, "pressure": p, "k1": k1, "k2": k2,
                        "kink_deg": math.degrees(th), "x": float(new[-1][0]), "y": float(new[-1][1])})
        pts = [new[0]] + pts + [new[1]]
    return log, pts


# ---------------------------------------------------------------------------------------------
# Fluid-driven growth in the toughness regime


def in_situ(sigma_H, sigma_h, azimuth_deg):
    """(sxx, syy, sxy), tension positive, of the compressive magnitudes sigma_H along the azimuth
    (deg from x) and sigma_h across it."""
    c, s = math.cos(math.radians(azimuth_deg)), math.sin(math.radians(azimuth_deg))
    return (-(sigma_H * c * c + sigma_h * s * s), -(sigma_H * s * s + sigma_h * c * c), -(sigma_H - sigma_h) * c * s)


CRITERIA = ("energy", "hoop")


def k_equivalent(k1, k2, criterion="energy"):
    """The K compared with K_Ic. energy: sqrt(K_I^2 + K_II^2), the energy release rate
    G = (K_I^2 + K_II^2) / E' against G_c = K_Ic^2 / E' (the J >= J_Ic growth of hfmpm; K_I
    below 0, where a solve's contact states are not yet settled, counts as 0); hoop:
    cos^3(th/2) K_I - 1.5 cos(th/2) sin(th) K_II at the kink angle th, the maximum hoop stress
    against its value in mode I."""
    if criterion == "energy":
        return math.hypot(max(k1, 0.0), k2)  # a tip pressed shut has K_I = 0
    th = kink_angle(k1, k2)
    return math.cos(th / 2) ** 3 * k1 - 1.5 * math.cos(th / 2) * math.sin(th) * k2


def first_critical(ks, p_lo, kic, criterion):
    """The lowest pressure p >= p_lo at which a tip's K_eq(k0 + p k1) reaches kic, for tips
    ks = [(k0, k1), ...] (K linear in p; K_eq is convex in K, so above p_lo it crosses kic at
    most once); inf if it never does."""
    def worst(p):
        return max(k_equivalent(k0[0] + p * k1[0], k0[1] + p * k1[1], criterion) for k0, k1 in ks)

    if worst(p_lo) >= kic:
        return p_lo
    slope = max(math.hypot(*k1) for _, k1 in ks)
    if slope == 0:
        return math.inf
    step = kic / slope
    for _ in range(200):
        if worst(p_lo + step) >= kic:
            break
        step *= 2
    else:
        return math.inf
    lo, hi = p_lo, p_lo + step
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (lo, mid) if worst(mid) >= kic else (mid, hi)
    return hi


def linear_in_p(body, mode, mu):
    """The solution for a fixed set of contact states as a function of the pressure: D = D0 +
    p D1 (two solves: the in-situ stress alone and a unit pressure), the K's at both tips
    (K = k0 + p k1), the crack's volume v0 + p v1 and, per crack element, the tractions r0 + p r1
    (shear, normal) that decide its state."""
    nc, w = body.nc, 2 * body.a
    M, b = body.constrained(mode, mu, np.stack([body.b0, body.bp], axis=1))
    X = np.linalg.solve(M, b)
    D0, D1 = X[:, 0], X[:, 1]
    v0, v1 = -float(D0[1:2 * nc:2] @ w), -float(D1[1:2 * nc:2] @ w)
    ks = [(tip_k(D0[0:2 * nc:2], D0[1:2 * nc:2], body.a, end, ep=body.ep),
           tip_k(D1[0:2 * nc:2], D1[1:2 * nc:2], body.a, end, ep=body.ep)) for end in (False, True)]
    # The constant elements' volume is that of a crack a quarter of the tip element longer at
    # each tip (a Griffith crack's is (1 + d / 2a) times the exact at 16-512 elements): taken
    # out with dV/da = dG/dp = 2 (K_I dK_I/dp + K_II dK_II/dp) / E' at an open tip (within
    # 0.04% of the exact volume at 64 elements, 4e-6 at 128)
    for (k0, k1), e in zip(ks, (0, nc - 1)):
        if mode[e] == OPEN:
            c = 2 * body.a[e] / (2 * body.ep)
            v0 -= c * (k0[0] * k1[0] + k0[1] * k1[1])
            v1 -= c * (k1[0] * k1[0] + k1[1] * k1[1])
    r0 = body.A[:2 * nc] @ D0 - body.b0[:2 * nc]
    r1 = body.A[:2 * nc] @ D1 - body.bp[:2 * nc]
    return {"D0": D0, "D1": D1, "ks": ks, "v": (v0, v1), "r": (r0, r1), "mode": mode}


def settle(body, mode, mu, p, max_iter=100):
    """The contact states at pressure p (from `mode` on) and the solution in them (linear_in_p)."""
    seen = set()
    for _ in range(max_iter):
        lin = linear_in_p(body, mode, mu)
        now = body.update(mode, lin["D0"] + p * lin["D1"], p, mu)
        if np.array_equal(now, mode):
            return lin
        if now.tobytes() in seen:
            print(f"curved_path: the contact states cycle at p = {p:.6g} Pa; taking the last", file=sys.stderr)
            return lin
        seen.add(now.tobytes())
        mode = now
    print(f"curved_path: the contact states did not settle in {max_iter} solves at p = {p:.6g} Pa", file=sys.stderr)
    return lin


def next_event(body, lin, mu, p):
    """The lowest pressure above p at which an element of lin's set of contact states changes
    state: a shut element's contact stress reaches 0, an open one's Dn reaches 0, a stuck one's
    shear mu |sigma_c|, a slipping one's slip 0; inf if none does."""
    nc, mode = body.nc, lin["mode"]
    (r0, r1), D0, D1 = lin["r"], lin["D0"][:2 * nc], lin["D1"][:2 * nc]
    cands = []

    def up(f0, f1, where):  # where f0 + q f1 rises through 0
        m = where & (f1 > 0)
        cands.extend((-f0[m] / f1[m]).tolist())

    shut = mode != OPEN
    up(r0[1::2], r1[1::2], shut)
    up(D0[1::2], D1[1::2], ~shut)
    if mu > 0:
        for sg in (1, -1):
            up(sg * r0[0::2] + mu * r0[1::2], sg * r1[0::2] + mu * r1[1::2], mode == STICK)
        s = np.where(np.abs(mode) == 1, mode, 0)
        up(-s * D0[0::2], -s * D1[0::2], np.abs(mode) == 1)
    later = [q for q in cands if q > p]
    return min(later) if later else math.inf


def lowest_pressure(body, mode, mu, p0, h, root, tol, scale, max_iter=200):
    """The lowest pressure p >= p0 at which h(lin, p) >= 0 on the settled solution (h rising
    with p): Newton on the piecewise-linear problem, each trial the root of h in the current
    set of contact states (root(lin, p): the lowest q >= p with h >= 0 in that set, inf if
    none; then the set's next change), kept within a bracket; the states settled at each trial
    from `mode` (the same start each time: a settled set depends on where its search began only
    where elements meet at a kink, and should not on the trials before). Returns p and lin."""
    lin = settle(body, mode, mu, p0)
    if h(lin, p0) >= 0:
        return p0, lin
    lo, hi, pk, hk = p0, math.inf, p0, h(lin, p0)
    for _ in range(max_iter):
        if hk < 0:
            trial = root(lin, pk)
            if math.isinf(trial):
                trial = next_event(body, lin, mu, pk) + 1e-9 * scale
        else:  # the set at pk has h >= 0: its root below pk
            a_, b_ = lo, pk
            if h(lin, a_) >= 0:
                trial = 0.5 * (a_ + b_)
            else:
                for _ in range(200):
                    m = 0.5 * (a_ + b_)
                    if m in (a_, b_):
                        break
                    a_, b_ = (a_, m) if h(lin, m) >= 0 else (m, b_)
                trial = b_
        if not lo < trial < hi:
            if math.isinf(hi):
                if math.isinf(trial):
                    raise RuntimeError("no pressure satisfies the condition (nothing changes as it rises)")
                trial = max(trial, lo + 1e-9 * scale)
            else:
                trial = 0.5 * (lo + hi)
        lin = settle(body, mode, mu, trial)
        pk, hk = trial, h(lin, trial)
        if abs(hk) <= tol:
            return pk, lin
        if hk >= 0:
            hi = pk
        else:
            lo = pk
        if not math.isinf(hi) and hi - lo <= 1e-13 * max(abs(hi), scale):
            return hi, settle(body, mode, mu, hi)
    raise RuntimeError(f"the pressure did not converge in {max_iter} trials")


def fluid_state(body, v_in, kic, criterion="energy", mu=0.0, p_floor=0.0):
    """The crack `body` holding the injected fluid volume v_in (m^2) at the moment it grows.
    The fluid is incompressible, leaks off nowhere and wets the whole crack at one pressure p (no
    lag), which it cannot pull below p_floor (its cavitation pressure, 0 by default). The volume
    balance gives the pressure at which the crack holds v_in (the volume: the opening integrated
    over the crack), or p_floor if that is lower (a crack opened wider than its fluid fills, by
    the sliding of its faces, holds a dry cavity at p_floor) or if nothing has been injected. If
    a tip's K_eq already reaches K_Ic there, the crack grows without injection (no time passes:
    'past'); otherwise injection raises p to the lowest pressure at which a tip reaches K_Ic,
    and the injected volume to the crack's volume there.

    For a fixed set of contact states D, K and V are linear in p (two solves: the in-situ stress
    alone and a unit pressure). The crack open everywhere is tried first: p from K (or from V,
    if the crack is past K_Ic at the injected volume), accepted if no faces interpenetrate there
    and the tips are below K_Ic at the lowest pressure at which none do.
    Otherwise each trial pressure comes from the linear solution in the current contact states,
    which are then settled at it, from open (lowest_pressure). Returns p, the injected volume V,
    the crack's own volume at p (held), the K's at both tips, 'past', the contact states and D."""
    scale = max(np.abs(body.b0).max(), kic / math.sqrt((2 * body.a).sum()))
    nc = body.nc

    def volume(lin, p):
        return lin["v"][0] + p * lin["v"][1]

    def k_at(lin, p):
        return [(k0[0] + p * k1[0], k0[1] + p * k1[1]) for k0, k1 in lin["ks"]]

    def excess(lin, p):
        return max(k_equivalent(a, b, criterion) for a, b in k_at(lin, p)) - kic

    def k_root(lin, p):
        return first_critical(lin["ks"], p, kic, criterion)

    def state(lin, p, p_start):
        past = p == p_start and excess(lin, p) > 1e-9 * kic
        held = volume(lin, p)
        return {"p": p, "V": max(v_in, held) if p > p_start else v_in, "held": held, "K": k_at(lin, p),
                "past": past, "mode": lin["mode"], "D": lin["D0"] + p * lin["D1"]}

    # open everywhere
    lin = linear_in_p(body, np.zeros(nc, dtype=int), mu)

    d0, d1 = lin["D0"][1:2 * nc:2], lin["D1"][1:2 * nc:2]

    def shut_nowhere(p):
        return not (d0 + p * d1 > 0).any()

    opening = d1 < 0  # the pressure from which no faces interpenetrate
    p_lo = max(p_floor, float((-d0[opening] / d1[opening]).max()) if opening.any() else math.inf)
    p_c = k_root(lin, p_lo) if math.isfinite(p_lo) else math.inf
    if math.isfinite(p_c) and p_c > p_lo and shut_nowhere(p_c):
        if volume(lin, p_c) >= v_in:
            return state(lin, p_c, -math.inf)  # injection brought it there
        v0, v1 = lin["v"]
        p_v = (v_in - v0) / v1 if v1 > 0 else math.inf
        if p_floor <= p_v < math.inf and shut_nowhere(p_v):
            return state(lin, p_v, p_v)
    # with contact
    zero = np.zeros(nc, dtype=int)
    if v_in > 0:
        def over(lin, p):
            return volume(lin, p) - v_in

        def v_root(lin, p):
            v0, v1 = lin["v"]
            return max(p, (v_in - v0) / v1) if v1 > 0 else math.inf

        p_start, lin = lowest_pressure(body, zero, mu, p_floor, over, v_root, 1e-10 * v_in, scale)
    else:
        p_start = p_floor
    p, lin = lowest_pressure(body, zero, mu, p_start, excess, k_root, 1e-9 * kic, scale)
    return state(lin, p, p_start)


class DryGrowth(Exception):
    """The crack grows before fluid drives it (see fluid_path); .rows: the rows up to and
    including that step."""

    def __init__(self, message, rows):
        super().__init__(message)
        self.rows = rows


def notch_loads(sigma_H, sigma_h, azimuth, theta):
    """The in-situ normal stress (compressive magnitude) and shear on a plane at theta deg."""
    sxx, syy, sxy = in_situ(sigma_H, sigma_h, azimuth)
    c, s = math.cos(math.radians(theta)), math.sin(math.radians(theta))
    n, t = (-s, c), (c, s)
    tx, ty = sxx * n[0] + sxy * n[1], sxy * n[0] + syy * n[1]
    return -(tx * n[0] + ty * n[1]), tx * t[0] + ty * t[1]


def fluid_path(E, nu, kic, sigma_H, sigma_h, azimuth, theta, a0, Q, ds, steps, mu=0.0, criterion="energy",
               plate=0.0, per_step=8, p_floor=0.0, dry_growth="stop", out=None):
    """The path of a fluid-driven crack in the toughness regime: a straight notch of half-length
    a0 at theta deg from x, centred at the origin, in the in-situ stress sigma_H (compressive
    magnitude, Pa, along azimuth deg from x) and sigma_h, fluid injected at Q (m^2/s) into it;
    both tips grow by ds per step in the maximum-hoop-stress direction, at the pressure and time
    of fluid_state (criterion: 'energy' or 'hoop', see k_equivalent; mu: Coulomb friction on shut
    faces; p_floor: the fluid's cavitation pressure). The body is an infinite plane, or with
    plate > 0 the square +-plate (edges holding the in-situ stress). The notch is meshed at
    about ds and each growth step is split in per_step elements (8: the tip fit stays within
    the tip's step).

    Returns the rows (one per tip and step 0..steps: the crack after that many steps, at the
    moment it grows: step, t_s, p_pa, tip, x_m, y_m of the tip, K_I, K_II in the tip's frame
    at p, kink_deg of the next step, length_m tip to tip along the crack; also past: grew
    without injection, V_m2: the fluid injected, held_m2: the crack's volume) and the final
    crack. A crack that grows with no fluid in it, or from a tip pressed shut (K_I = 0: in
    shear, as a notch whose in-situ shear alone brings it to K_Ic does), is not driven by the
    fluid; with dry_growth='stop' that raises DryGrowth. out: a callable given each step's rows."""
    ep = E / (1 - nu * nu)
    stress = in_situ(sigma_H, sigma_h, azimuth)
    box = None if plate <= 0 else (-plate, plate, -plate, plate)
    pts = straight((0, 0), math.radians(theta), a0, max(1, int(round(2 * a0 / ds))))
    rows, v_in = [], 0.0
    for k in range(steps + 1):
        body = Body(refine(pts, per_step), stress, box, plate / 20, ep)
        st = fluid_state(body, v_in, kic, criterion, mu, p_floor)
        mode, v_in = st["mode"], st["V"]
        length = float(sum(np.linalg.norm(b - a) for a, b in zip(pts[:-1], pts[1:])))
        new = []
        for (k1, k2), at_end in zip(st["K"], (False, True)):
            tip, prev = (pts[-1], pts[-2]) if at_end else (pts[0], pts[1])
            d = (tip - prev) / np.linalg.norm(tip - prev)
            th = kink_angle(k1, k2)
            c, s = math.cos(th), math.sin(th)
            new.append(tip + ds * np.array([c * d[0] - s * d[1], s * d[0] + c * d[1]]))
            rows.append({"step": k, "t_s": v_in / Q, "p_pa": st["p"], "tip": "end" if at_end else "start",
                         "x_m": float(tip[0]), "y_m": float(tip[1]), "K_I": k1, "K_II": k2,
                         "kink_deg": math.degrees(th), "length_m": length, "past": st["past"],
                         "V_m2": v_in, "held_m2": st["held"]})
        if out:
            out(rows[-2:])
        shut = [t for t, e in (("start", 0), ("end", body.nc - 1)) if mode[e] != OPEN]
        if dry_growth == "stop" and (v_in <= 0 or shut):
            keq = max(k_equivalent(r["K_I"], r["K_II"], criterion) for r in rows[-2:])
            why = (f"the {' and '.join(shut)} tip{'s' if len(shut) > 1 else ''} pressed shut (K_I = 0)" if shut
                   else "no fluid in the crack")
            msg = (f"step {k}: the crack reaches K_Ic with {why}, at p = {st['p']:.6g} Pa, K_eq = "
                   f"{keq / kic:.3g} K_Ic: it grows before the fluid drives it, in shear, and its path is not a "
                   "toughness-dominated fluid-driven one.")
            if k == 0:
                sn, tau = notch_loads(sigma_H, sigma_h, azimuth, theta)
                ka = abs(tau) * math.sqrt(math.pi * a0)
                s2 = max(abs(math.sin(math.radians(2 * (theta - azimuth)))), 1e-300)
                msg += (f" The notch carries an in-situ normal stress of {sn:.6g} Pa and a shear of {abs(tau):.6g} "
                        f"Pa: in an infinite plane K_II = |tau| sqrt(pi a0) = {ka:.4g} Pa m^0.5 = {ka / kic:.3g} K_Ic "
                        "wherever its faces slide freely (shut without friction, or open; friction, which holds "
                        "them only while shut, delays the slip to p = sigma_n - (|tau| - K_Ic / sqrt(pi a0)) / mu, "
                        "still below the opening pressure sigma_n). A fluid-driven start needs |tau| sqrt(pi a0) "
                        f"below K_Ic: (sigma_H - sigma_h) below {2 * kic / (math.sqrt(math.pi * a0) * s2):.4g} Pa "
                        f"at this angle and length, or K_Ic above {ka:.4g}.")
            raise DryGrowth(msg + " (--dry-growth continue grows it anyway.)", rows)
        if k < steps:
            if box is not None and any(max(abs(q[0]), abs(q[1])) >= plate for q in new):
                raise ValueError(f"step {k + 1} takes a tip out of the plate (+-{plate:g} m)")
            pts = [new[0]] + pts + [new[1]]
    return rows, pts


FLUID_COLUMNS = ("step", "t_s", "p_pa", "tip", "x_m", "y_m", "K_I", "K_II", "kink_deg", "length_m")


def tip_paths(rows):
    """{tip: (n, 2) array of its positions, step by step} of fluid_path's rows (or read from
    their CSV); the first point is the notch's end."""
    if isinstance(rows, str):
        with open(rows) as f:
            rows = [{"tip": r["tip"], "step": int(r["step"]), "x_m": float(r["x_m"]), "y_m": float(r["y_m"])}
                    for r in csv.DictReader(f)]
    out = {}
    for tip in ("start", "end"):
        mine = sorted((r for r in rows if r["tip"] == tip), key=lambda r: r["step"])
        out[tip] = np.array([(r["x_m"], r["y_m"]) for r in mine])
    return out


def run_tips(run, a0, origin=(0.0, 0.0)):
    """hfmpm's tip points from a run directory: the crack particles of crack 0 in the last frame of
    RUN/solid.h5 farther than a0 from the well (origin), split at the particle nearest it into the
    start and the end wing. Needs h5py (Debian's python3-h5py)."""
    try:
        import h5py
    except ImportError:
        sys.exit("curved_path: reading a run directory needs h5py (apt-get install python3-h5py)")
    path = os.path.join(run, "solid.h5")
    try:
        with h5py.File(path, "r") as f:
            frames = sorted(f["frames"].keys())
            xy = np.asarray(f["frames"][frames[-1]]["crack0"]["positions"][()], float)
    except (OSError, KeyError, IndexError) as e:
        sys.exit(f"curved_path: {path}: no crack 0 in its frames ({e})")
    r = np.hypot(xy[:, 0] - origin[0], xy[:, 1] - origin[1])
    well = int(np.argmin(r))
    out = {"start": xy[:well][r[:well] > a0 * (1 + 1e-6)], "end": xy[well + 1:][r[well + 1:] > a0 * (1 + 1e-6)]}
    return {k: v for k, v in out.items() if len(v)}


def open_or_exit(path):
    """The file, opened for reading, or the tool stopped with a message naming it."""
    try:
        return open(path)
    except OSError as e:
        sys.exit(f"curved_path: cannot read {path}: {e.strerror}")


def read_tips(path):
    """hfmpm's tip points, {label: (n, 2) array}, from a CSV with a column tip and x, y (or x_m,
    y_m); a path file written with HFMPM_PATH_OUT gives its growth records."""
    with open_or_exit(path) as f:
        reader = csv.DictReader(f)
        names = reader.fieldnames or []
        cx = "x" if "x" in names else "x_m"
        cy = "y" if "y" in names else "y_m"
        if not {"tip", cx, cy} <= set(names):
            sys.exit(f"curved_path: {path}: expected columns tip and x, y (or x_m, y_m); got {', '.join(names)}")
        out = {}
        for row in reader:
            if row.get("record", "growth") != "growth":
                continue
            try:
                out.setdefault(row["tip"], []).append((float(row[cx]), float(row[cy])))
            except (TypeError, ValueError) as e:
                sys.exit(f"curved_path: {path}, line {reader.line_num}: {e}")
    return {k: np.array(v) for k, v in out.items()}


def path_distance(tips, reference, ds=None, origin=(0.0, 0.0)):
    """How far hfmpm's path lies from the reference: for each of hfmpm's tips (tips: {label:
    (n, 2) points} or a CSV for read_tips; origin: where hfmpm has the notch's centre) the
    largest distance of its points from the reference path of the same tip (reference:
    fluid_path's rows or their CSV; the same tip: the reference tip whose notch end is nearer the
    tip's first point), in growth steps (ds; default the reference's first step). A point past
    the reference's last tip counts its distance from that tip, so the reference should run at
    least as far. Returns {label: (reference tip, distance in steps)}."""
    if isinstance(tips, str):
        tips = read_tips(tips)
    ref = tip_paths(reference)
    if ds is None:
        ds = float(np.linalg.norm(ref["end"][1] - ref["end"][0]))
    out = {}
    for label, q in tips.items():
        q = np.asarray(q, float) - np.asarray(origin, float)
        if not len(q):
            continue
        near = min(ref, key=lambda t: np.linalg.norm(ref[t][0] - q[0]))
        out[label] = (near, max(distance_to(ref[near], x) for x in q) / ds)
    return out


def fluid_png(rows, final, png, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, axp) = plt.subplots(1, 2, figsize=(11, 5))
    final = np.asarray(final)
    ax.plot(final[:, 0], final[:, 1], "-", color="tab:blue", lw=1.2)
    for tip, col in (("start", "tab:orange"), ("end", "tab:green")):
        q = tip_paths(rows)[tip]
        ax.plot(q[:, 0], q[:, 1], ".", color=col, ms=3, label=f"{tip} tip")
    ax.set_aspect("equal")
    ax.grid(True, lw=0.3)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=9)
    end = [r for r in rows if r["tip"] == "end"]
    axp.plot([r["t_s"] for r in end], [r["p_pa"] / 1e6 for r in end], ".-", lw=0.8)
    axp.set_xlabel("t (s)")
    axp.set_ylabel("p at growth (MPa)")
    axp.grid(True, lw=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print(f"wrote {png}")


def self_test():
    """The solver against exact answers; each tolerance is what the refinement shows."""
    ok = True

    def check(name, got, want, tol):
        nonlocal ok
        err = abs(got - want) / abs(want)
        good = err <= tol
        ok &= good
        print(f"  {name}: {got:.6g} against {want:.6g}, error {100 * err:.2f}% (tolerance {100 * tol:.1f}%)"
              f"{'' if good else '  FAIL'}")
        return err

    errs = []
    for n in (40, 80, 160):
        print(f"a 2 m crack in {n} elements:")
        a, p = 1.0, 1e6
        pts = straight((0, 0), 0.3, a, n)
        ds, dn, el = solve(pts, (0, 0, 0), p)
        k1, k2 = tip_k(ds, dn, el, True)
        e1 = check("Griffith, pressure 1 MPa: K_I", k1, p * math.sqrt(math.pi * a), 0.01)
        print(f"  K_II {k2:.3g} (0 exact)")
        # 45 deg crack under sigma_yy = 1 MPa: K_I = K_II = sigma/2 sqrt(pi a); the end tip's kink -53.13 deg
        pts = straight((0, 0), math.pi / 4, a, n)
        ds, dn, el = solve(pts, (0, 1e6, 0), 0)
        kk = 0.5e6 * math.sqrt(math.pi * a)
        k1e, k2e = tip_k(ds, dn, el, True)
        k1s, k2s = tip_k(ds, dn, el, False)
        e2 = check("45 deg under tension, end tip: K_I", k1e, kk, 0.01)
        e3 = check("  K_II", k2e, kk, 0.01)
        check("  start tip K_I", k1s, kk, 0.01)
        check("  start tip K_II", k2s, kk, 0.01)
        check("  kink (deg)", math.degrees(kink_angle(k1e, k2e)), -53.130, 0.005)
        errs.append(max(e1, e2, e3))
    # Contact: the 45 deg crack shut by the test's in-situ stress (normal stress 4 MPa on it,
    # shear 2 MPa) with no pressure: frictionless faces carry no shear, so K_II = 2 MPa sqrt(pi a)
    # exactly, and K_I = 0 (the faces press).
    pts = straight((0, 0), math.pi / 4, 1.0, 80)
    ds, dn, el = solve(pts, STRESS, 0)
    k1, k2 = tip_k(ds, dn, el, True)
    print("45 deg crack shut by sigma_xx = -2, sigma_yy = -6 MPa, frictionless, 80 elements:")
    check("  |K_II|", abs(k2), 2e6 * math.sqrt(math.pi), 0.01)
    good = abs(k1) < 1e-3 * abs(k2) and np.all(dn <= 0)
    ok &= good
    print(f"  K_I / K_II {k1 / k2:+.2e} (0 exact; every element shut: {bool(np.all(dn == 0))})"
          f"{'' if good else '  FAIL'}")
    # A kinked crack: the 45 deg crack under tension with a kink of 0.02 a (elements of 0.002 a
    # throughout) against Cotterell and Rice's first-order kink solution, which is exact as the
    # kink's length goes to 0 where the T-stress vanishes (it does here: the crack is at 45 deg
    # to the load) up to its own O(theta^2) error: K_I within 1.5%, K_II within 2% of K at 20
    # deg; at the maximum-hoop-stress kink (-53.13 deg) K_I within 1.5% and K_II/K_I below 0.05
    # (the first-order solution's K_II is 0 there; the exact one's is not).
    def cotterell_rice(th, k1, k2):
        c, s = math.cos, math.sin
        return (0.25 * (3 * c(th / 2) + c(3 * th / 2)) * k1 - 0.75 * (s(th / 2) + s(3 * th / 2)) * k2,
                0.25 * (s(th / 2) + s(3 * th / 2)) * k1 + 0.25 * (c(th / 2) + 3 * c(3 * th / 2)) * k2)

    kk = 0.5e6 * math.sqrt(math.pi)
    for deg in (-20.0, -53.130):
        th = math.radians(deg)
        pts = straight((0, 0), math.pi / 4, 1.0, 1000)
        u = np.array([math.cos(math.pi / 4 + th), math.sin(math.pi / 4 + th)])
        pts += [pts[-1] + u * 0.002 * (i + 1) for i in range(10)]
        ds, dn, el = solve(pts, (0, 1e6, 0), 0)
        k1, k2 = tip_k(ds, dn, el, True)
        c1, c2 = cotterell_rice(th, kk, kk)
        print(f"kink of {deg:g} deg, 0.02 a long:")
        check("  K_I against the first-order kink solution", k1, c1, 0.015)
        if abs(deg) < 30:
            check("  K_II against the first-order kink solution", k2, c2, 0.02)
        else:
            good = abs(k2 / k1) < 0.05
            ok &= good
            print(f"  K_II/K_I {k2 / k1:+.4f} (first order 0; below 0.05){'' if good else '  FAIL'}")
    print(f"worst K error at 40 / 80 / 160 elements: {', '.join(f'{100 * e:.3f}%' for e in errs)}")
    if not errs[2] <= errs[0]:
        print("FAIL: the error does not fall under refinement")
        ok = False
    return ok


def fluid_self_test():
    """The fluid-driven mode and the friction against closed forms."""
    ok = True

    def check(name, got, want, tol, scale=None):
        nonlocal ok
        err = abs(got - want) / abs(want if scale is None else scale)
        good = err <= tol
        ok &= good
        print(f"  {name}: {got:.6g} against {want:.6g}, error {100 * err:.3g}% (tolerance {100 * tol:.3g}%)"
              f"{'' if good else '  FAIL'}")
        return err

    def require(name, good, text):
        nonlocal ok
        ok &= bool(good)
        print(f"  {name}: {text}{'' if good else '  FAIL'}")

    E_, nu, kic, Q = 2e10, 0.25, 1e6, 1e-3
    ep = E_ / (1 - nu * nu)

    def symmetry(rows):
        s = tip_paths(rows)
        return float(np.abs(s["start"] + s["end"]).max() / np.abs(s["end"]).max())

    # 1. a notch along sigma_H: Griffith at every step
    print("fluid-driven, toughness: a 2 m notch along sigma_H = 30 MPa, sigma_h = 20 MPa, K_Ic = 1 MPa m^0.5, "
          "E = 20 GPa, nu = 0.25, 4 steps of 0.125 m (128-192 elements):")
    rows, _ = fluid_path(E_, nu, kic, 30e6, 20e6, 0, 0, 1.0, Q, 0.125, 4)
    ends = [r for r in rows if r["tip"] == "end"]
    net = vol = pe = 0.0
    for r in ends:
        a = r["length_m"] / 2
        net = max(net, abs((r["p_pa"] - 20e6) / (kic / math.sqrt(math.pi * a)) - 1))
        pe = max(pe, abs(r["p_pa"] / (20e6 + kic / math.sqrt(math.pi * a)) - 1))
        vol = max(vol, abs(r["t_s"] * Q / (2 * math.pi * (r["p_pa"] - 20e6) * a * a / ep) - 1))
    r0 = ends[0]
    check("step 0: p - sigma_h against K_Ic / sqrt(pi a)", r0["p_pa"] - 20e6, kic / math.sqrt(math.pi), 0.01)
    check("  p against sigma_h + K_Ic / sqrt(pi a)", r0["p_pa"], 20e6 + kic / math.sqrt(math.pi), 0.01)
    check("  V = Q t against 2 pi (1 - nu^2) (p - sigma_h) a^2 / E", r0["t_s"] * Q,
          2 * math.pi * (r0["p_pa"] - 20e6) / ep, 0.01)
    require("every step (a = 1 to 1.5 m)", max(net, pe, vol) <= 0.01,
            f"worst error of p - sigma_h {100 * net:.3f}%, of p {100 * pe:.4f}%, of V {100 * vol:.4f}% (tolerance 1%)")
    dev = max(abs(r["y_m"]) for r in rows) / ends[-1]["x_m"]
    require("the path stays straight", dev <= 1e-9, f"largest |y| / x of the tips {dev:.1e} (below 1e-9)")
    require("time rises with the volume", all(b["t_s"] > a_["t_s"] for a_, b in zip(ends, ends[1:])),
            " -> ".join(f"{r['t_s']:.4g}" for r in ends) + " s")

    # 2. the notch at 30 deg under isotropic stress: straight, point-symmetric, Griffith
    print("the same notch at 30 deg under an isotropic 20 MPa:")
    rows, _ = fluid_path(E_, nu, kic, 20e6, 20e6, 0, 30, 1.0, Q, 0.125, 4)
    ratio = max(abs(r["K_II"] / r["K_I"]) for r in rows)
    kink = max(abs(r["kink_deg"]) for r in rows)
    require("K_II / K_I and the kinks", ratio <= 1e-6 and kink <= 1e-4,
            f"|K_II / K_I| at most {ratio:.1e} (below 1e-6), kinks at most {kink:.1e} deg (below 1e-4); Erdogan and "
            "Sih's kink for K_II = 0 is 0")
    head = max(abs(math.degrees(math.atan2(r["y_m"], r["x_m"])) - 30) for r in rows if r["tip"] == "end")
    require("the path stays on the notch's line", head <= 1e-6,
            f"the end tip's polar angle within {head:.1e} deg of 30")
    sym = symmetry(rows)
    require("point symmetry", sym <= 1e-6, f"|x_start + x_end| / |x_end| at most {sym:.1e} (below 1e-6)")
    check("step 0: p against sigma + K_Ic / sqrt(pi a)", rows[0]["p_pa"] - 20e6, kic / math.sqrt(math.pi), 0.01)

    # 3. the notch at 30 deg under anisotropic stress: K and the first kink against the closed
    # form, point symmetry, and the turn toward sigma_H
    sH, sh = 20.2e6, 20e6
    print(f"the notch at 30 deg under sigma_H = {sH / 1e6:g} MPa along x, sigma_h = {sh / 1e6:g} MPa, 8 steps:")
    rows, _ = fluid_path(E_, nu, kic, sH, sh, 0, 30, 1.0, Q, 0.125, 8)
    sn, tau = notch_loads(sH, sh, 0, 30)
    r0 = rows[1]
    sq = math.sqrt(math.pi)
    p_exact = sn + math.sqrt(kic ** 2 / math.pi - tau ** 2)  # (p - sigma_n)^2 + tau^2 = K_Ic^2 / (pi a)
    check("step 0: p - sigma_n against sqrt(K_Ic^2 / pi a - tau^2)", r0["p_pa"] - sn, p_exact - sn, 0.01)
    check("  K_I against (p - sigma_n) sqrt(pi a)", r0["K_I"], (r0["p_pa"] - sn) * sq, 0.01)
    check("  |K_II| against |tau| sqrt(pi a)", abs(r0["K_II"]), abs(tau) * sq, 0.01)
    es = math.degrees(kink_angle((p_exact - sn) * sq, abs(tau) * sq))
    check("  the first kink (deg) against Erdogan and Sih's for the exact K", -abs(r0["kink_deg"]), es, 0.005)
    q = tip_paths(rows)["end"]
    first = math.degrees(math.atan2(*(q[1] - q[0])[::-1])) - 30
    require("  the path's first kink is Erdogan and Sih's for the K computed",
            abs(first - math.degrees(kink_angle(r0["K_I"], r0["K_II"]))) <= 1e-9,
            f"{first:.6f} deg from the path, {math.degrees(kink_angle(r0['K_I'], r0['K_II'])):.6f} from the K's")
    sym = symmetry(rows)
    require("point symmetry", sym <= 1e-6, f"|x_start + x_end| / |x_end| at most {sym:.1e} (below 1e-6)")
    for tip in ("end", "start"):
        q = tip_paths(rows)[tip]
        d = q[1:] - q[:-1]
        ang = [30.0] + [abs(math.degrees(math.atan(v[1] / v[0]))) for v in d]
        require(f"the {tip} tip's heading turns toward sigma_H",
                all(b < a_ for a_, b in zip(ang, ang[1:])),
                "angle to sigma_H " + ", ".join(f"{x:.2f}" for x in ang) + " deg (falling at every step)")
    # the maximum-hoop-stress criterion at step 0: K_eq = K_Ic, p against the closed form
    rows_h, _ = fluid_path(E_, nu, kic, sH, sh, 0, 30, 1.0, Q, 0.125, 0, criterion="hoop")
    lo, hi = sn, sn + kic / sq
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if k_equivalent((mid - sn) * sq, abs(tau) * sq, "hoop") >= kic else (mid, hi)
    check("the hoop criterion, step 0: p - sigma_n against the closed form's", rows_h[1]["p_pa"] - sn, hi - sn, 0.01)
    check("  K_eq against K_Ic", k_equivalent(rows_h[1]["K_I"], rows_h[1]["K_II"], "hoop"), kic, 1e-6)

    # 4. Coulomb friction on a closed crack
    print("Coulomb friction: the 2 m crack at 45 deg shut by sigma_xx = -2, sigma_yy = -6 MPa (|sigma_n| = 4, "
          "|tau| = 2 MPa), E = 20 GPa, nu = 0.25:")
    for mu in (0.3, 0.6):
        for n in (80, 160):
            ds_, dn_, el = solve(straight((0, 0), math.pi / 4, 1.0, n), STRESS, 0, mu=mu, ep=ep)
            k1, k2 = tip_k(ds_, dn_, el, True, ep=ep)
            drive = 2e6 - mu * 4e6
            if drive > 0:
                print(f"  mu = {mu:g}, {n} elements (|tau| - mu |sigma_n| = {drive / 1e6:g} MPa):")
                check("  |K_II| against (|tau| - mu |sigma_n|) sqrt(pi a)", abs(k2), drive * sq, 0.02)
                check("  the largest slip against 4 (1 - nu^2) (|tau| - mu |sigma_n|) a / E", np.abs(ds_).max(),
                      4 * drive / ep, 0.02)
                require("  shut", np.all(dn_ == 0) and abs(k1) <= 1e-9 * abs(k2), f"K_I {k1:.2g}, every Dn 0")
            else:
                require(f"mu = {mu:g}, {n} elements: |tau| < mu |sigma_n| holds it", np.all(ds_ == 0) and k2 == 0,
                        f"largest slip {np.abs(ds_).max():.2g} m, K_II {k2:.2g}")
    # the notch the in-situ shear alone brings to K_Ic, without and with friction
    print("a notch whose in-situ shear alone brings it to K_Ic (a0 = 5 m at 30 deg, sigma_H = 30, sigma_h = 20 MPa):")
    sn, tau = notch_loads(30e6, 20e6, 0, 30)
    for mu in (0.0, 0.6):
        try:
            fluid_path(E_, nu, kic, 30e6, 20e6, 0, 30, 5.0, Q, 0.5, 3, mu=mu)
            require(f"mu = {mu:g}: stops as grown dry", False, "it did not stop")
        except DryGrowth as e:
            r = e.rows[-1]
            require(f"mu = {mu:g}: stops at step 0, grown dry", r["step"] == 0 and r["K_I"] == 0,
                    f"step {r['step']}, K_I {r['K_I']:.2g}")
            if mu == 0:
                check("    |K_II| against |tau| sqrt(pi a0)", abs(r["K_II"]), abs(tau) * math.sqrt(5 * math.pi), 0.01)
            else:
                check("    the pressure at which it slips against sigma_n - (|tau| - K_Ic / sqrt(pi a0)) / mu",
                      r["p_pa"], sn - (abs(tau) - kic / math.sqrt(5 * math.pi)) / mu, 0.01)
                check("    |K_II| against K_Ic", abs(r["K_II"]), kic, 0.01)

    # 5. the distance of a path from the reference
    ref = fluid_path(E_, nu, kic, 20.2e6, 20e6, 0, 30, 1.0, Q, 0.125, 4)[0]
    paths = tip_paths(ref)
    e = paths["end"]
    d = e[-1] - e[-2]
    nrm = np.array([-d[1], d[0]]) / np.linalg.norm(d)
    mine = {"a": paths["start"][::-1], "b": e + 0.1 * 0.125 * nrm}
    got = path_distance(mine, ref)
    require("path_distance: a copy of the start tip's path, the end tip's moved 0.1 step across its last step",
            got["a"][0] == "start" and got["a"][1] <= 1e-9 and got["b"][0] == "end" and abs(got["b"][1] - 0.1) <= 1e-6,
            f"{got['a'][1]:.2g} and {got['b'][1]:.6f} steps (tips matched: {got['a'][0]}, {got['b'][0]})")
    return ok


COLUMNS = ("record", "tip", "step", "pressure_pa", "x_m", "y_m", "k1_pa_sqrt_m", "k2_pa_sqrt_m", "h_m")


def read_run(path):
    """An MPM path file (HFMPM_PATH_OUT): its growth records, its final crack and its cell size.
    A file that cannot be read, lacks a column or holds a value that is not a number stops the
    tool with a message naming the file, the line and what is expected."""
    growth, plane, h = [], [], None
    with open_or_exit(path) as f:
        reader = csv.DictReader(f)
        missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            sys.exit(f"curved_path: {path}: not a path file written with HFMPM_PATH_OUT (missing columns: "
                     f"{', '.join(missing)})")
        for row in reader:
            try:
                h = float(row["h_m"])
                if row["record"] == "growth":
                    growth.append({"tip": row["tip"], "step": int(row["step"]), "p": float(row["pressure_pa"]),
                                   "x": float(row["x_m"]), "y": float(row["y_m"]),
                                   "k1": float(row["k1_pa_sqrt_m"]), "k2": float(row["k2_pa_sqrt_m"])})
                elif row["record"] == "plane":
                    plane.append((float(row["x_m"]), float(row["y_m"])))
                else:
                    raise ValueError(f"record {row['record']!r}, expected 'growth' or 'plane'")
            except (TypeError, ValueError) as e:
                sys.exit(f"curved_path: {path}, line {reader.line_num}: {e}")
    if not (h is not None and math.isfinite(h) and h > 0):
        sys.exit(f"curved_path: {path}: no cell size h_m > 0 (got {h})")
    if len(plane) < 2:
        sys.exit(f"curved_path: {path}: the final crack has {len(plane)} points; at least 2 expected")
    return growth, np.array(plane), h


def crossing(poly, y0, from_end=True):
    """x where the polyline first crosses y0, read from its end (or its start)."""
    q = poly[::-1] if from_end else poly
    for i in range(len(q) - 1):
        (xa, ya), (xb, yb) = q[i], q[i + 1]
        if (ya - y0) * (yb - y0) <= 0 and ya != yb:
            return xa + (y0 - ya) / (yb - ya) * (xb - xa)
    return float("nan")


def distance_to(poly, q):
    """Shortest distance from point q to the polyline."""
    best = float("inf")
    for i in range(len(poly) - 1):
        a, b = poly[i], poly[i + 1]
        ab = b - a
        s = min(1.0, max(0.0, float(np.dot(q - a, ab) / np.dot(ab, ab))))
        best = min(best, float(np.linalg.norm(a + s * ab - q)))
    return best


def heading(poly, span, at_end=True):
    q = poly[::-1] if at_end else poly
    tip = q[0]
    back = tip
    for r in q[1:]:
        back = r
        if np.linalg.norm(back - tip) >= span:
            break
    return math.degrees(math.atan2(tip[1] - back[1], tip[0] - back[0]))


def reference_for(growth, h, fraction, plate):
    """The reference path for an MPM run's load history: the pressure of its k-th end-tip
    growth as a function of the grown length, growth steps of `fraction` of the MPM's (a
    quarter cell), the initial crack meshed at the step."""
    mpm_step = 0.25 * h
    ends = sorted((g for g in growth if g["tip"] == "end"), key=lambda g: g["step"])
    lengths = [g["step"] * mpm_step for g in ends]
    ps = [g["p"] for g in ends]
    step = fraction * mpm_step
    n = int(round(len(ends) / fraction))

    def p_at(L):  # the pressure of the MPM check that grew the crack past length L
        for Lk, pk in zip(lengths, ps):
            if L <= Lk + 1e-12:
                return pk
        return ps[-1]

    pressures = [p_at((k + 1) * step) for k in range(n)]
    init = straight((0, 0), math.pi / 4, 1.0, int(round(2 / step)))
    # the MPM's plate [-b, b]^2 has the crack's centre at (h / 2, 0)
    box = None if plate <= 0 else (-plate - h / 2, plate - h / 2, -plate, plate)
    return grow(init, STRESS, pressures, step, box)


def compare(paths, png, fractions, plate, max_distance=None):
    """Each MPM path file against the reference for its load history. With max_distance,
    returns False if any run's growth steps (the tip each cut) lie farther than that many
    growth steps from the reference path."""
    rows, curves = [], []
    for path in paths:
        growth, plane, h = read_run(path)
        if not growth:
            sys.exit(f"curved_path: {path} has no growth records (written with HFMPM_PATH_OUT?)")
        mpm = plane - np.array([h / 2, 0.0])  # from the crack's centre
        refs = {}
        for fr in fractions:
            refs[fr] = np.array(reference_for(growth, h, fr, plate)[1])
        infinite = np.array(reference_for(growth, h, fractions[0], 0)[1]) if plate > 0 else refs[fractions[0]]
        ref = refs[fractions[-1]]
        n_end = sum(1 for g in growth if g["tip"] == "end")
        n_start = sum(1 for g in growth if g["tip"] == "start")
        step = 0.25 * h

        def worst(points):
            return max((distance_to(ref, q) for q in points), default=float("nan"))

        def grown(tip):  # the tip as each of its growth steps cut it, from the crack's centre
            return [np.array([g["x"] - h / 2, g["y"]]) for g in growth if g["tip"] == tip]

        rows.append({"cells": round(1 / h), "h": h, "steps": (n_start, n_end),
                     "p": (min(g["p"] for g in growth), max(g["p"] for g in growth)),
                     "mpm": (crossing(mpm, 1.5), -crossing(mpm, -1.5, from_end=False)),
                     "ref": [(crossing(refs[f], 1.5), -crossing(refs[f], -1.5, from_end=False)) for f in fractions],
                     "inf": crossing(infinite, 1.5),
                     "dist": (worst(grown("end")) / step, worst(grown("start")) / step),
                     "heading": (heading(mpm, 2 * h), heading(ref, 2 * h))})
        curves.append((round(1 / h), mpm, ref))
    fr_txt = " / ".join(f"{f:g}" for f in fractions)
    print(f"Where the end tip's path crosses y = +1.5 m (x from the crack's centre, m; the start tip's crossing of "
          f"y = -1.5 m, mirrored, after the slash); the reference in the MPM's plate (+-{plate:g} m, traction "
          f"edges) at growth steps of {fr_txt} times the MPM's, and in an infinite body; the largest distance of "
          "the tips hfmpm's growth steps cut from the reference path in units of the MPM's growth step:")
    print(f"| h | steps per tip | pressure at growth (MPa) | hfmpm | reference, steps {fr_txt} | infinite body | "
          "hfmpm - reference (end) | largest distance, end / start tip (growth steps) | heading at the end, hfmpm / "
          "reference (deg) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        ref_txt = " ; ".join(f"{a:.4f} / {b:.4f}" for a, b in r["ref"])
        print(f"| a/{r['cells']} | {r['steps'][0]} / {r['steps'][1]} | {r['p'][0] / 1e6:.2f}-{r['p'][1] / 1e6:.2f} | "
              f"{r['mpm'][0]:.4f} / {r['mpm'][1]:.4f} | {ref_txt} | {r['inf']:.4f} | "
              f"{r['mpm'][0] - r['ref'][-1][0]:+.4f} | {r['dist'][0]:.2f} / {r['dist'][1]:.2f} | "
              f"{r['heading'][0]:.2f} / {r['heading'][1]:.2f} |")
    if png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (full, zoom) = plt.subplots(1, 2, figsize=(10, 6.5), gridspec_kw={"width_ratios": [1, 1.4]})
        colours = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]
        for (cells, mpm, ref), col in zip(curves, colours):
            for ax in (full, zoom):
                ax.plot(mpm[:, 0], mpm[:, 1], "-", color=col, lw=1.3, label=f"hfmpm, h = a/{cells}")
                ax.plot(ref[:, 0], ref[:, 1], "--", color=col, lw=0.9,
                        label=f"boundary elements, a/{cells}'s pressures")
        for ax in (full, zoom):
            ax.axhline(1.5, color="0.7", lw=0.6)
            ax.grid(True, lw=0.3)
            ax.set_xlabel("x from the crack's centre (m)")
        full.set_aspect("equal")
        full.axhline(-1.5, color="0.7", lw=0.6)
        full.set_ylabel("y (m)")
        full.set_title("45 deg crack, pressurised;\nsigma_xx = -2, sigma_yy = -6 MPa", fontsize=9)
        zoom.set_xlim(0.5, 0.75)
        zoom.set_ylim(0.65, 2.0)
        zoom.set_title("the end tip's turn (x stretched)", fontsize=9)
        full.legend(fontsize=6, loc="lower right")
        fig.tight_layout()
        fig.savefig(png, dpi=110)
        print(f"wrote {png}")
    if max_distance is None:
        return True
    ok = True
    for r in rows:
        if not max(r["dist"]) <= max_distance:
            print(f"FAIL: at h = a/{r['cells']} hfmpm's path lies {max(r['dist']):.2f} growth steps from the "
                  f"reference (allowed {max_distance:g})")
            ok = False
    return ok


def run_fluid(args, ap):
    """--fluid: the reference path, its table, CSV and figure, and hfmpm's tips against it."""
    need = {"E": args.E, "nu": args.nu, "KIc": args.KIc, "sigma-H": args.sigma_H, "sigma-h": args.sigma_h,
            "azimuth": args.azimuth, "theta": args.theta, "a0": args.a0, "Q": args.Q, "ds": args.ds,
            "steps": args.steps}
    missing = [f"--{k}" for k, v in need.items() if v is None]
    if missing:
        ap.error(f"--fluid needs {', '.join(missing)}")
    for k in ("E", "KIc", "a0", "Q", "ds"):
        if not need[k] > 0:
            ap.error(f"--{k}: must be > 0, got {need[k]}")
    if not 0 <= args.nu < 0.5:
        ap.error(f"--nu: must be in [0, 0.5), got {args.nu}")
    if args.steps < 0 or args.mu < 0 or args.per_step < 7:
        ap.error("--steps and --mu must be >= 0, --per-step >= 7 (the tip fit takes 7 elements)")
    if args.sigma_H < args.sigma_h:
        print(f"curved_path: note: --sigma-H {args.sigma_H:g} is below --sigma-h {args.sigma_h:g}: the larger "
              f"compression is then across the azimuth", file=sys.stderr)
    plate = 0.0 if args.plate is None else args.plate
    sn, tau = notch_loads(args.sigma_H, args.sigma_h, args.azimuth, args.theta)
    ratio = abs(tau) * math.sqrt(math.pi * args.a0) / args.KIc
    print(f"Fluid-driven, toughness-dominated growth ({args.criterion} criterion, friction mu = {args.mu:g}, "
          f"{'an infinite plane' if plate <= 0 else f'the plate +-{plate:g} m'}): E = {args.E:g} Pa, nu = {args.nu:g}, "
          f"K_Ic = {args.KIc:g} Pa m^0.5, sigma_H = {args.sigma_H:g} Pa at {args.azimuth:g} deg, sigma_h = "
          f"{args.sigma_h:g} Pa; the notch: 2 x {args.a0:g} m at {args.theta:g} deg (in-situ normal stress "
          f"{sn:.6g} Pa, shear {abs(tau):.6g} Pa: |tau| sqrt(pi a0) = {ratio:.3g} K_Ic); Q = {args.Q:g} m^2/s; "
          f"{args.steps} steps of {args.ds:g} m, {args.per_step} elements each.")
    print("step  t (s)        p (Pa)          | start tip: x, y (m), K_I, K_II (Pa m^0.5), kink (deg) | "
          "end tip: the same")

    def show(pair):
        s, e = pair
        print(f"{s['step']:4d}  {s['t_s']:<12.6g} {s['p_pa']:<15.9g} | "
              + " | ".join(f"{r['x_m']:+.5f} {r['y_m']:+.5f} {r['K_I']:+.5e} {r['K_II']:+.5e} {r['kink_deg']:+8.3f}"
                           for r in pair)
              + ("  (past K_Ic: grows without injection)" if s["past"] else ""), flush=True)

    status, rows, final = 0, [], None
    try:
        rows, final = fluid_path(args.E, args.nu, args.KIc, args.sigma_H, args.sigma_h, args.azimuth, args.theta,
                                 args.a0, args.Q, args.ds, args.steps, mu=args.mu, criterion=args.criterion,
                                 plate=plate, per_step=args.per_step, p_floor=args.p_floor,
                                 dry_growth=args.dry_growth, out=show)
    except DryGrowth as e:
        print(f"curved_path: {e}", file=sys.stderr)
        rows, status = e.rows, 2
    except (ValueError, RuntimeError) as e:
        sys.exit(f"curved_path: {e}")
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(FLUID_COLUMNS)
            for r in rows:
                w.writerow([r["step"], f"{r['t_s']:.10g}", f"{r['p_pa']:.10g}", r["tip"], f"{r['x_m']:.10g}",
                            f"{r['y_m']:.10g}", f"{r['K_I']:.8g}", f"{r['K_II']:.8g}", f"{r['kink_deg']:.8g}",
                            f"{r['length_m']:.10g}"])
        print(f"wrote {args.csv}")
    if args.png and final is not None:
        fluid_png(rows, final, args.png, f"notch 2 x {args.a0:g} m at {args.theta:g} deg; sigma_H {args.sigma_H:g} Pa "
                  f"at {args.azimuth:g} deg, sigma_h {args.sigma_h:g} Pa")
    if args.tips and rows:
        try:
            origin = [float(v) for v in args.tips_origin.split(",")]
            assert len(origin) == 2
        except (ValueError, AssertionError):
            ap.error(f"--tips-origin: x,y in m, got {args.tips_origin!r}")
        tips = run_tips(args.tips, args.a0, origin) if os.path.isdir(args.tips) else args.tips
        got = path_distance(tips, rows, args.ds, origin)
        for label, (tip, d) in got.items():
            print(f"hfmpm's tip {label!r}: at most {d:.3f} growth steps from the reference's {tip} tip")
        if args.max_distance is not None and any(not d <= args.max_distance for _, d in got.values()):
            print(f"FAIL: farther than {args.max_distance:g} growth steps")
            status = status or 1
    sys.exit(status)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="*", help="path files written with HFMPM_PATH_OUT")
    ap.add_argument("--self-test", nargs="?", const="all", choices=("all", "dry", "fluid"),
                    help="the solver against closed forms (all: both parts)")
    ap.add_argument("--png", help="draw the paths")
    ap.add_argument("--max-distance", type=float,
                    help="fail (exit 1) if a tip a run's growth cut (with --fluid: hfmpm's crack particles, --tips) lies "
                         "farther than this many of its growth steps from the reference path")
    ap.add_argument("--plate", type=float, default=None,
                    help="the body's half-width in m, 0 for an infinite body (default: the MPM test's plate, 5; "
                         "with --fluid, 0)")
    ap.add_argument("--step-fraction", default="1",
                    help="the reference's growth step as fractions of the MPM's, comma-separated (the last is "
                         "the one compared; default 1)")
    fl = ap.add_argument_group("fluid-driven growth (--fluid)")
    fl.add_argument("--fluid", action="store_true", help="the fluid-driven, toughness-dominated reference path")
    fl.add_argument("--E", type=float, help="Young's modulus, Pa")
    fl.add_argument("--nu", type=float, help="Poisson's ratio (plane strain)")
    fl.add_argument("--KIc", type=float, help="fracture toughness, Pa m^0.5")
    fl.add_argument("--sigma-H", dest="sigma_H", type=float, help="the larger in-situ compression, Pa (> 0)")
    fl.add_argument("--sigma-h", dest="sigma_h", type=float, help="the smaller in-situ compression, Pa (> 0)")
    fl.add_argument("--azimuth", type=float, help="the direction of sigma_H, deg from x")
    fl.add_argument("--theta", type=float, help="the notch's direction, deg from x")
    fl.add_argument("--a0", type=float, help="the notch's half-length, m (centred at the origin)")
    fl.add_argument("--Q", type=float, help="the injection rate, m^2/s")
    fl.add_argument("--ds", type=float, help="the growth step of each tip, m")
    fl.add_argument("--steps", type=int, help="growth steps")
    fl.add_argument("--mu", type=float, default=0.0, help="Coulomb friction of shut faces (default 0)")
    fl.add_argument("--criterion", choices=CRITERIA, default="energy",
                    help="energy: sqrt(K_I^2 + K_II^2) = K_Ic (default; hfmpm's J = J_Ic); hoop: the maximum hoop "
                         "stress's equivalent K = K_Ic")
    fl.add_argument("--per-step", type=int, default=8, help="elements per growth step (default 8)")
    fl.add_argument("--p-floor", type=float, default=0.0,
                    help="the lowest fluid pressure, Pa (cavitation; default 0)")
    fl.add_argument("--dry-growth", choices=("stop", "continue"), default="stop",
                    help="a crack that reaches K_Ic before the fluid drives it (no fluid in it, or a tip pressed "
                         "shut): stop with exit status 2 (default) or grow it anyway")
    fl.add_argument("--csv", help="write the rows: step, t_s, p_pa, tip, x_m, y_m, K_I, K_II, kink_deg, length_m")
    fl.add_argument("--tips", help="hfmpm's tip points (CSV: tip, x, y or x_m, y_m; a HFMPM_PATH_OUT file; or a run "
                                   "directory, its solid.h5's last frame): their largest distance from the reference "
                                   "path of the same tip, in growth steps")
    fl.add_argument("--tips-origin", default="0,0", help="where hfmpm has the notch's centre, x,y in m (default 0,0)")
    args = ap.parse_args()
    if args.self_test:
        ok = True
        if args.self_test in ("all", "dry"):
            ok &= self_test()
        if args.self_test in ("all", "fluid"):
            ok &= fluid_self_test()
        sys.exit(0 if ok else 1)
    if args.plate is not None and args.plate < 0:
        ap.error(f"--plate: a half-width in m, 0 for an infinite body; got {args.plate}")
    if args.fluid:
        run_fluid(args, ap)
    if not args.runs:
        ap.error("give path files, --fluid or --self-test")
    try:
        fractions = [float(f) for f in args.step_fraction.split(",")]
    except ValueError:
        ap.error(f"--step-fraction: comma-separated numbers in (0, 1], got {args.step_fraction!r}")
    if not all(0 < f <= 1 for f in fractions):
        ap.error(f"--step-fraction: each fraction must be in (0, 1], got {args.step_fraction!r}")
    plate = 5.0 if args.plate is None else args.plate
    sys.exit(0 if compare(args.runs, args.png, fractions, plate, args.max_distance) else 1)


if __name__ == "__main__":
    main()
