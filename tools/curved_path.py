#!/usr/bin/env python3
"""A reference path for a pressurised crack that turns in an anisotropic stress (issue 18).

The reference is an independent method: a displacement-discontinuity boundary-element solver
(Crouch and Starfield's constant elements) for a crack of straight segments in a plane-strain
body under a uniform far-field (in-situ) stress, its faces loaded by a uniform pressure, with
frictionless contact where the faces would interpenetrate. The body is the MPM test's plate
(+-5 m, its edges holding the in-situ stress: boundary elements whose induced traction is zero)
or, with --plate 0, an infinite plane. K_I and K_II at each tip come from the opening and
sliding of the elements nearest the tip (LEFM's square-root near-tip field, extrapolated to the
tip with the constant elements' own error fitted out; within 0.4% of the exact K at 40
elements on a straight crack, 0.05% at 80). The crack grows from both tips by steps of a given
length in the direction of maximum hoop stress (Erdogan and Sih). Growth is quasi-static: each
step is solved at the pressure the MPM run had at the check that grew that step, read from its
path file, so the two solve the same load history and differ only in the method.

  /usr/bin/python3 tools/curved_path.py --self-test
      the solver against exact K's: a pressurised Griffith crack, an inclined crack under
      tension (K_I, K_II, the first kink of -53.13 deg), refined twice; exits 1 on a failure
  /usr/bin/python3 tools/curved_path.py RUN.csv [RUN.csv ...] [--png F] [--step-fraction f]
      each MPM path file (written by hfmpm_solid_oblique_growth_test with HFMPM_PATH_OUT,
      HFMPM_OBLIQUE_CELLS=n) against the reference for its load history: where the end tip's
      path crosses y = 1.5 m, the headings at the end, the largest distance between the paths;
      the reference's own convergence in its step; a PNG of all the paths; with
      --max-distance s, exits 1 if hfmpm's new crack particles lie farther than s growth steps
      from the reference path (ctest: verification.CurvedPath.*).

Units SI. Stress positive in tension; the MPM test's case: E = 10 GPa, nu = 0.25, a 2 m crack
at 45 deg, sigma_xx = -2 MPa, sigma_yy = -6 MPa.
"""
import argparse
import csv
import math
import sys

import numpy as np

E, NU = 1e10, 0.25
G = E / (2 * (1 + NU))


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


def solve(points, stress, pressure, box=None, box_size=0.25):
    """Displacement discontinuities of the crack `points` (polyline, N+1 points) whose faces
    carry `pressure` in the far field `stress` = (sxx, syy, sxy). With box = (x0, x1, y0,
    y1) the body is that rectangle, its edges holding the far-field stress (the MPM test's
    traction edges): elements along the edges whose induced traction is zero."""
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
    sxx, syy, sxy = stress
    tx = sxx * nrm[:, 0] + sxy * nrm[:, 1]
    ty = sxy * nrm[:, 0] + syy * nrm[:, 1]
    b = np.zeros(2 * len(p0))
    b[0:2 * nc:2] = -(tx[:nc] * t[:nc, 0] + ty[:nc] * t[:nc, 1])  # shear traction free
    b[1:2 * nc:2] = -pressure - (tx[:nc] * nrm[:nc, 0] + ty[:nc] * nrm[:nc, 1])  # normal traction -p
    # Frictionless contact (the MPM's, where the pressure is below the normal stress): an
    # element whose faces would interpenetrate (Dn > 0) is held shut (Dn = 0) and its normal
    # traction left free; repeated until the set of shut elements no longer changes.
    shut = np.zeros(len(p0), dtype=bool)  # only crack elements are ever shut
    for _ in range(100):
        M, rhs = A.copy(), b.copy()
        rows = 2 * np.nonzero(shut)[0] + 1
        M[rows, :] = 0
        M[rows, rows] = 1
        rhs[rows] = 0
        D = np.linalg.solve(M, rhs)
        traction = A @ D - b  # the contact traction on shut elements (must press: < 0)
        now = (D[1::2] > 0) | (shut & (traction[1::2] < 0))
        now[nc:] = False
        if np.array_equal(now, shut):
            break
        shut = now
    return D[0:2 * nc:2], D[1:2 * nc:2], a[:nc]


def tip_k(ds, dn, a, at_end, last=6):
    """K_I and K_II at a tip, in the tip's frame (x1 out of the crack, x2 to its left), from
    the near-tip field's opening w = 8 K_I sqrt(r / 2 pi) / E' (and sliding with K_II): the
    apparent K at the centres of the elements 1..last from the tip (the tip element 0, a
    constant standing for a square root, left out) is fitted by K + c d / r + b r, d the tip
    element's length. The d / r term is the constant elements' error (the apparent K of a
    Griffith crack is 1 + 0.128 d / r times the exact at every refinement), the r term the
    field's next order. Both tips use the same formula with the elements' signs (-D is the
    jump above the crack less below)."""
    n = len(ds)
    idx = list(range(n - 1, -1, -1)) if at_end else list(range(n))
    ep = 2 * G / (1 - NU)  # E' = E / (1 - nu^2)
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


COLUMNS = ("record", "tip", "step", "pressure_pa", "x_m", "y_m", "k1_pa_sqrt_m", "k2_pa_sqrt_m", "h_m")


def read_run(path):
    """An MPM path file (HFMPM_PATH_OUT): its growth records, its final crack and its cell size.
    A file that cannot be read, lacks a column or holds a value that is not a number stops the
    tool with a message naming the file, the line and what is expected."""
    growth, plane, h = [], [], None
    try:
        f = open(path)
    except OSError as e:
        sys.exit(f"curved_path: cannot read {path}: {e.strerror}")
    with f:
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
    returns False if any run's new crack particles lie farther than that many growth steps
    from the reference path."""
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

        rows.append({"cells": round(1 / h), "h": h, "steps": (n_start, n_end),
                     "p": (min(g["p"] for g in growth), max(g["p"] for g in growth)),
                     "mpm": (crossing(mpm, 1.5), -crossing(mpm, -1.5, from_end=False)),
                     "ref": [(crossing(refs[f], 1.5), -crossing(refs[f], -1.5, from_end=False)) for f in fractions],
                     "inf": crossing(infinite, 1.5),
                     "dist": (worst(mpm[len(mpm) - n_end:]) / step, worst(mpm[:n_start]) / step),
                     "heading": (heading(mpm, 2 * h), heading(ref, 2 * h))})
        curves.append((round(1 / h), mpm, ref))
    fr_txt = " / ".join(f"{f:g}" for f in fractions)
    print(f"Where the end tip's path crosses y = +1.5 m (x from the crack's centre, m; the start tip's crossing of "
          f"y = -1.5 m, mirrored, after the slash); the reference in the MPM's plate (+-{plate:g} m, traction "
          f"edges) at growth steps of {fr_txt} times the MPM's, and in an infinite body; the largest distance of "
          "hfmpm's new crack particles from the reference path in units of the MPM's growth step:")
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


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="*", help="path files written with HFMPM_PATH_OUT")
    ap.add_argument("--self-test", action="store_true")
    ap.add_argument("--png", help="draw the paths")
    ap.add_argument("--max-distance", type=float,
                    help="fail (exit 1) if a run's new crack particles lie farther than this many of its growth "
                         "steps from the reference path")
    ap.add_argument("--plate", type=float, default=5.0,
                    help="the body's half-width in m (the MPM test's plate: 5), 0 for an infinite body")
    ap.add_argument("--step-fraction", default="1",
                    help="the reference's growth step as fractions of the MPM's, comma-separated (the last is "
                         "the one compared; default 1)")
    args = ap.parse_args()
    if args.self_test:
        sys.exit(0 if self_test() else 1)
    if not args.runs:
        ap.error("give path files or --self-test")
    try:
        fractions = [float(f) for f in args.step_fraction.split(",")]
    except ValueError:
        ap.error(f"--step-fraction: comma-separated numbers in (0, 1], got {args.step_fraction!r}")
    if not all(0 < f <= 1 for f in fractions):
        ap.error(f"--step-fraction: each fraction must be in (0, 1], got {args.step_fraction!r}")
    if args.plate < 0:
        ap.error(f"--plate: a half-width in m, 0 for an infinite body; got {args.plate}")
    sys.exit(0 if compare(args.runs, args.png, fractions, args.plate, args.max_distance) else 1)


if __name__ == "__main__":
    main()
