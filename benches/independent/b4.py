#!/usr/bin/env python3
"""B4 (seed paper §4.2) with PS-MPM and PL-MPM: an implementation independent of psmpm.

Python + numpy only (meshio to read psmpm's mesh.vtu). Nothing here is ported
from psmpm's Rust code: the Powell–Sabin basis is built from
/work/shared/docs/ps-splines.md (the "exact PS construction, checked"), the time
step from the seed paper, eqs. (13)–(31), with the conventions psmpm documents in
docs/driver.md (full velocity gradient in the F update). The conventions that
psmpm does not document and that were read from one formula in its src/ are
listed in README.md and marked [code] below.

The benchmark (paper §4.2, eqs. (40)–(47)):
  u_x = u0 sin(2π x0) sin(ω t),  u_y = u0 sin(2π y0) sin(ω t + π),  ω = π √(E/ρ0),
  neo-Hookean (eq. (27)), ρ0 = 1e3, E = 1e7, ν = 0.3, u0 = 0.05, body force of
  eqs. (42)–(46), roller walls (v_x = 0 on x = 0, 1; v_y = 0 on y = 0, 1),
  consistent mass, dt = 2.5e-5, t_end = 0.02 (800 steps), error: eq. (47).

Usage:
  python3 b4.py --basis ps --mesh DIR/mesh.vtu --particles 256 --t-end 0.02
  python3 b4.py --selftest --mesh DIR/mesh.vtu        # checks of the PS basis
"""

import argparse
import json
import math
import sys
import time

import numpy as np

# ---------------------------------------------------------------------------
# Problem constants (paper §4.2)
# ---------------------------------------------------------------------------

RHO0 = 1e3
YOUNG = 1e7
POISSON = 0.3
U0 = 0.05
DT = 2.5e-5
# eq. (44), plane strain
LAMBDA = YOUNG * POISSON / ((1.0 + POISSON) * (1.0 - 2.0 * POISSON))
MU = YOUNG / (2.0 * (1.0 + POISSON))
OMEGA = math.pi * math.sqrt(YOUNG / RHO0)


def exact_displacement(x0, t):
    """eqs. (40)-(41); sin(ωt + π) taken as −sin(ωt) [code: so that it is 0 at t = 0]."""
    s = math.sin(OMEGA * t)
    u = np.empty_like(x0)
    u[:, 0] = U0 * np.sin(2.0 * math.pi * x0[:, 0]) * s
    u[:, 1] = U0 * np.sin(2.0 * math.pi * x0[:, 1]) * (-s)
    return u


def exact_velocity(x0, t):
    """Time derivative of eqs. (40)-(41) (the scene's `initial_velocity = exact`)."""
    c = math.cos(OMEGA * t)
    v = np.empty_like(x0)
    v[:, 0] = U0 * OMEGA * np.sin(2.0 * math.pi * x0[:, 0]) * c
    v[:, 1] = -U0 * OMEGA * np.sin(2.0 * math.pi * x0[:, 1]) * c
    return v


def body_force(x0, t):
    """Body force per unit mass, eqs. (42)-(46) as printed, at the reference
    position x0 and the start-of-step time [code: src/studies/exact.rs, src/effect.rs]."""
    u = exact_displacement(x0, t)
    s = math.sin(OMEGA * t)
    dxx = 1.0 + 2.0 * U0 * math.pi * np.cos(2.0 * math.pi * x0[:, 0]) * s  # eq. (45)
    dyy = 1.0 + 2.0 * U0 * math.pi * np.cos(2.0 * math.pi * x0[:, 1]) * (-s)  # eq. (46)
    ln_j = np.log(dxx * dyy)
    common = 4.0 * MU / RHO0 - YOUNG / RHO0
    nonlinear = LAMBDA * (ln_j - 1.0) - MU
    pi2 = math.pi * math.pi
    g = np.empty_like(x0)
    g[:, 0] = pi2 * u[:, 0] * (common - 4.0 * nonlinear / (RHO0 * dxx * dxx))  # eq. (42)
    g[:, 1] = pi2 * u[:, 1] * (common - 4.0 * nonlinear / (RHO0 * dyy * dyy))  # eq. (43)
    return g


def neo_hookean(F):
    """eq. (27): σ = (λ ln J / J) I + (μ / J)(F Fᵀ − I), plane strain (2×2 F),
    λ, μ of eq. (44) [code: src/material.rs]."""
    J = F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]  # eq. (23)
    FFt = F[:, :, None, 0] * F[:, None, :, 0] + F[:, :, None, 1] * F[:, None, :, 1]
    iso = LAMBDA * np.log(J) / J
    sig = FFt - np.eye(2)
    sig *= (MU / J)[:, None, None]
    sig[:, 0, 0] += iso
    sig[:, 1, 1] += iso
    return sig, J


# ---------------------------------------------------------------------------
# Mesh
# ---------------------------------------------------------------------------


class Mesh:
    """Main triangulation: vertices, counter-clockwise triangles, edges."""

    def __init__(self, points, tris):
        self.p = np.asarray(points, dtype=float)[:, :2].copy()
        t = np.asarray(tris, dtype=np.int64).copy()
        a, b, c = self.p[t[:, 0]], self.p[t[:, 1]], self.p[t[:, 2]]
        cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
        cw = cross < 0
        t[cw, 1], t[cw, 2] = t[cw, 2].copy(), t[cw, 1].copy()
        self.t = t
        self.nv, self.nt = len(self.p), len(t)
        # edges: local edge j of triangle e joins t[e, j] and t[e, (j+1) % 3]
        edge_of = {}
        self.edges = []  # (v_a, v_b) with v_a < v_b
        self.edge_tris = []  # list of (triangle, local edge)
        self.tri_edge = np.zeros((self.nt, 3), dtype=np.int64)
        for e in range(self.nt):
            for j in range(3):
                va, vb = t[e, j], t[e, (j + 1) % 3]
                key = (min(va, vb), max(va, vb))
                if key not in edge_of:
                    edge_of[key] = len(self.edges)
                    self.edges.append(key)
                    self.edge_tris.append([])
                k = edge_of[key]
                self.edge_tris[k].append((e, j))
                self.tri_edge[e, j] = k
        self.edge_of = edge_of
        self.boundary_edge = np.array([len(et) == 1 for et in self.edge_tris])
        # affine maps to barycentric coordinates of the main triangles
        self.bary_map = affine_inverse(self.p[t[:, 0]], self.p[t[:, 1]], self.p[t[:, 2]])

    def vertex_tris(self):
        vt = [[] for _ in range(self.nv)]
        for e in range(self.nt):
            for k in range(3):
                vt[self.t[e, k]].append(e)
        return vt

    def vertex_edges(self):
        ve = [[] for _ in range(self.nv)]
        for k, (a, b) in enumerate(self.edges):
            ve[a].append(k)
            ve[b].append(k)
        return ve


def affine_inverse(a, b, c):
    """For triangles (a, b, c) (arrays (n, 2)): A (n, 3, 3) with τ = A [x, y, 1]."""
    n = len(a)
    m = np.empty((n, 3, 3))
    m[:, 0, :] = np.stack([a[:, 0], b[:, 0], c[:, 0]], axis=1)
    m[:, 1, :] = np.stack([a[:, 1], b[:, 1], c[:, 1]], axis=1)
    m[:, 2, :] = 1.0
    return np.linalg.inv(m)


def barycentric(A, x):
    """τ = A [x, y, 1] for per-point maps A (n, 3, 3) and points x (n, 2)."""
    return A[:, :, 0] * x[:, 0:1] + A[:, :, 1] * x[:, 1:2] + A[:, :, 2]


def bernstein2(tau):
    """The quadratic Bernstein polynomials 2!/(i!j!k!) τ1^i τ2^j τ3^k of points with
    barycentric coordinates tau (P, 3), in the order τ1², τ2², τ3², 2τ1τ2, 2τ2τ3,
    2τ1τ3: values (P, 6) and derivatives ∂B/∂τ_m (P, 6, 3)."""
    t1, t2, t3 = tau[:, 0], tau[:, 1], tau[:, 2]
    B = np.stack([t1 * t1, t2 * t2, t3 * t3, 2 * t1 * t2, 2 * t2 * t3, 2 * t1 * t3], axis=1)
    z = np.zeros(len(tau))
    dB = np.stack(
        [
            np.stack([2 * t1, z, z], axis=1),
            np.stack([z, 2 * t2, z], axis=1),
            np.stack([z, z, 2 * t3], axis=1),
            np.stack([2 * t2, 2 * t1, z], axis=1),
            np.stack([z, 2 * t3, 2 * t2], axis=1),
            np.stack([2 * t3, z, 2 * t1], axis=1),
        ],
        axis=1,
    )
    return B, dB


def read_mesh(path):
    import meshio

    m = meshio.read(path)
    return Mesh(m.points, m.cells_dict["triangle"])


# ---------------------------------------------------------------------------
# Boundary of the unit square (the mesh's tags are geometric: left x = 0,
# right x = 1, bottom y = 0, top y = 1)
# ---------------------------------------------------------------------------

WALLS = {  # name: (normal n, offset c: the line n·x = c, fixed component)
    "left": (np.array([-1.0, 0.0]), 0.0, 0),
    "right": (np.array([1.0, 0.0]), 1.0, 0),
    "bottom": (np.array([0.0, -1.0]), 0.0, 1),
    "top": (np.array([0.0, 1.0]), 1.0, 1),
}
GEOM_TOL = 1e-12


def vertex_walls(mesh):
    """Walls through each boundary vertex (only vertices of boundary edges)."""
    on_boundary = np.zeros(mesh.nv, dtype=bool)
    for k, (a, b) in enumerate(mesh.edges):
        if mesh.boundary_edge[k]:
            on_boundary[a] = on_boundary[b] = True
    walls = [[] for _ in range(mesh.nv)]
    for i in np.nonzero(on_boundary)[0]:
        for name, (n, c, _) in WALLS.items():
            if abs(n @ mesh.p[i] - c) < GEOM_TOL:
                walls[i].append(name)
    return walls


# ---------------------------------------------------------------------------
# Powell–Sabin refinement (ps-splines.md §1; paper §3.1)
# ---------------------------------------------------------------------------


class PSRefinement:
    def __init__(self, mesh, split="incentre"):
        self.mesh = mesh
        p, t = mesh.p, mesh.t
        # Split point Z: the incentre, barycentric (a, b, c) ∝ lengths of the
        # opposite edges (or the centroid, (1/3, 1/3, 1/3), the thesis' tables).
        if split == "incentre":
            l0 = np.linalg.norm(p[t[:, 1]] - p[t[:, 2]], axis=1)
            l1 = np.linalg.norm(p[t[:, 2]] - p[t[:, 0]], axis=1)
            l2 = np.linalg.norm(p[t[:, 0]] - p[t[:, 1]], axis=1)
            w = np.stack([l0, l1, l2], axis=1)
        elif split == "centroid":
            w = np.ones((mesh.nt, 3))
        else:
            raise ValueError(split)
        self.zb = w / w.sum(axis=1, keepdims=True)  # (nt, 3)
        self.z = np.einsum("ek,ekd->ed", self.zb, p[t])  # (nt, 2)
        # Edge points R: the intersection of Z_t Z_t' with the edge (interior),
        # the midpoint (boundary). s = parameter from edges[k][0] to edges[k][1].
        ne = len(mesh.edges)
        self.edge_s = np.empty(ne)
        for k, (va, vb) in enumerate(mesh.edges):
            if mesh.boundary_edge[k]:
                self.edge_s[k] = 0.5
                continue
            (e1, _), (e2, _) = mesh.edge_tris[k]
            A, B = p[va], p[vb]
            Z1, Z2 = self.z[e1], self.z[e2]
            # A + s (B − A) = Z1 + r (Z2 − Z1)
            mat = np.array([[B[0] - A[0], Z1[0] - Z2[0]], [B[1] - A[1], Z1[1] - Z2[1]]])
            s, r = np.linalg.solve(mat, Z1 - A)
            assert 0.0 < s < 1.0 and 0.0 < r < 1.0, (k, s, r)
            self.edge_s[k] = s
        self.r = (1.0 - self.edge_s)[:, None] * p[[a for a, _ in mesh.edges]] + self.edge_s[
            :, None
        ] * p[[b for _, b in mesh.edges]]
        # λ_k of R_kl on the local edges of every triangle: lam[e, k, l] is the
        # weight of V_k in R_kl = lam[e,k,l] V_k + lam[e,l,k] V_l.
        self.lam = np.zeros((mesh.nt, 3, 3))
        self.tri_r = np.zeros((mesh.nt, 3, 3, 2))  # R_kl coordinates
        for e in range(mesh.nt):
            for j in range(3):
                k, l = j, (j + 1) % 3
                ed = mesh.tri_edge[e, j]
                va, vb = mesh.edges[ed]
                s = self.edge_s[ed]
                wa, wb = 1.0 - s, s
                if t[e, k] == va:
                    lk, ll = wa, wb
                else:
                    lk, ll = wb, wa
                self.lam[e, k, l], self.lam[e, l, k] = lk, ll
                self.tri_r[e, k, l] = self.tri_r[e, l, k] = self.r[ed]
        # The 6 sub-triangles (V_k, R_kl, Z), ordered by (k, l) in SUBS.
        self.sub_map = np.empty((mesh.nt, 6, 3, 3))
        for si, (k, l) in enumerate(SUBS):
            a = p[t[:, k]]
            b = self.tri_r[np.arange(mesh.nt), k, l]
            self.sub_map[:, si] = affine_inverse(a, b, self.z)


SUBS = [(0, 1), (0, 2), (1, 2), (1, 0), (2, 0), (2, 1)]  # sub-triangle (V_k, R_kl, Z)


# ---------------------------------------------------------------------------
# Control triangles (ps-splines.md §2; thesis 3.5.2)
# ---------------------------------------------------------------------------


def convex_hull(points):
    """Andrew's monotone chain, counter-clockwise, collinear points dropped."""
    pts = sorted(set(map(tuple, points)))
    if len(pts) <= 2:
        return np.array(pts)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for q in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], q) <= 1e-15:
            lower.pop()
        lower.append(q)
    for q in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], q) <= 1e-15:
            upper.pop()
        upper.append(q)
    return np.array(lower[:-1] + upper[:-1])


def line_intersection(n1, c1, n2, c2):
    m = np.array([n1, n2])
    if abs(np.linalg.det(m)) < 1e-14:
        return None
    return np.linalg.solve(m, np.array([c1, c2]))


def triangle_from_lines(lines):
    """Vertices of the triangle bounded by three half-planes n·x ≤ c (or None)."""
    (n1, c1), (n2, c2), (n3, c3) = lines
    q1 = line_intersection(n2, c2, n3, c3)  # opposite line 1
    q2 = line_intersection(n3, c3, n1, c1)
    q3 = line_intersection(n1, c1, n2, c2)
    if q1 is None or q2 is None or q3 is None:
        return None
    tri = np.array([q1, q2, q3])
    # bounded triangle: each vertex satisfies the third inequality strictly
    if n1 @ q1 > c1 - 1e-14 or n2 @ q2 > c2 - 1e-14 or n3 @ q3 > c3 - 1e-14:
        return None
    return tri


def signed_area2(q):
    return (q[1, 0] - q[0, 0]) * (q[2, 1] - q[0, 1]) - (q[2, 0] - q[0, 0]) * (q[1, 1] - q[0, 1])


def control_triangle(ps_points, walls):
    """Smallest-area triangle sharing two or three edges with the convex hull of
    the PS points (thesis 3.5.2). For a boundary vertex the walls through it must
    be among those edges: one edge on the boundary line (straight boundary), or
    both boundary lines through the corner (Q¹ = V_i)."""
    hull = convex_hull(ps_points)
    m = len(hull)
    lines = []
    for j in range(m):
        a, b = hull[j], hull[(j + 1) % m]
        d = b - a
        n = np.array([d[1], -d[0]]) / np.hypot(d[0], d[1])  # outward (hull is CCW)
        lines.append((n, float(n @ a)))
    required = []
    for name in walls:
        n, c, _ = WALLS[name]
        hits = [j for j, (nj, cj) in enumerate(lines) if np.allclose(nj, n, atol=1e-12) and abs(cj - c) < 1e-12]
        assert len(hits) == 1, (name, lines)
        required.append(hits[0])
    scale = np.max(np.ptp(ps_points, axis=0))
    best, best_area = None, np.inf

    def consider(tri, used):
        nonlocal best, best_area
        if tri is None or not all(r in used for r in required):
            return
        area = abs(signed_area2(tri)) / 2
        if area < 1e-12 * scale * scale:
            return
        if area < best_area:
            best, best_area = tri, area

    # three hull edges
    for i in range(m):
        for j in range(i + 1, m):
            for k in range(j + 1, m):
                consider(triangle_from_lines([lines[i], lines[j], lines[k]]), (i, j, k))
    # two hull edges; the third orthogonal to their bisector, pushed out to the
    # farthest PS point
    for i in range(m):
        for j in range(i + 1, m):
            (ni, ci), (nj, cj) = lines[i], lines[j]
            d = ni + nj
            if np.hypot(d[0], d[1]) < 1e-12:
                continue
            n3 = -d / np.hypot(d[0], d[1])  # wedge bisector direction, away from the apex
            c3 = float(np.max(ps_points @ n3))
            consider(triangle_from_lines([lines[i], lines[j], (n3, c3)]), (i, j))
    assert best is not None
    if signed_area2(best) < 0:
        best = best[[0, 2, 1]]
    return best


def triplets(q, v):
    """ps-splines.md §3: (α, β, γ) of the three functions of a control triangle
    q (3, 2) at vertex v; returns α (3,), grad (3, 2)."""
    (x1, y1), (x2, y2), (x3, y3) = q
    d = (x2 - x1) * (y3 - y1) - (x3 - x1) * (y2 - y1)
    beta = np.array([y2 - y3, y3 - y1, y1 - y2]) / d
    gamma = np.array([x3 - x2, x1 - x3, x2 - x1]) / d
    A = affine_inverse(q[0:1], q[1:2], q[2:3])[0]
    alpha = A @ np.array([v[0], v[1], 1.0])
    return alpha, np.stack([beta, gamma], axis=1)


# ---------------------------------------------------------------------------
# The PS basis (ps-splines.md §4; paper eqs. (32)-(38))
# ---------------------------------------------------------------------------


class PSBasis:
    """Quadratic Powell–Sabin B-splines, 3 per vertex (function 3 i + q)."""

    name = "ps"
    per_element = 9

    def __init__(self, mesh, split="incentre"):
        self.mesh = mesh
        ref = self.ref = PSRefinement(mesh, split)
        p, t = mesh.p, mesh.t
        vt, ve = mesh.vertex_tris(), mesh.vertex_edges()
        walls = vertex_walls(mesh)
        self.n = 3 * mesh.nv
        self.control = np.zeros((mesh.nv, 3, 2))
        self.alpha = np.zeros((mesh.nv, 3))
        self.grad = np.zeros((mesh.nv, 3, 2))
        # fixed[c]: functions whose coefficient of velocity component c is held
        # at zero (ps-splines.md §5: control points on a wall line).
        fixed = [set(), set()]
        for i in range(mesh.nv):
            v = p[i]
            pts = [v]
            pts += [0.5 * (v + ref.r[k]) for k in ve[i]]
            pts += [0.5 * (v + ref.z[e]) for e in vt[i]]
            pts = np.array(pts)
            q = control_triangle(pts, walls[i])
            self.control[i] = q
            self.alpha[i], self.grad[i] = triplets(q, v)
            for name in walls[i]:
                n, c, comp = WALLS[name]
                for k in range(3):
                    if abs(n @ q[k] - c) < 1e-12:
                        fixed[comp].add(3 * i + k)
        self.fixed = [np.array(sorted(f), dtype=np.int64) for f in fixed]
        # Bézier ordinates of the 9 functions of every triangle on its 6
        # sub-triangles: coef[e, s, f, b], b in BERNSTEIN order
        # (200, 020, 002, 110, 011, 101) on (V_k, R_kl, Z).
        nt = mesh.nt
        self.coef = np.zeros((nt, 6, 9, 6))
        self.functions = np.zeros((nt, 9), dtype=np.int64)
        for e in range(nt):
            V = p[t[e]]
            Z = ref.z[e]
            for kk in range(3):
                for q in range(3):
                    f = 3 * kk + q
                    self.functions[e, f] = 3 * t[e, kk] + q
                    fv = np.zeros(3)
                    gv = np.zeros((3, 2))
                    fv[kk] = self.alpha[t[e, kk], q]
                    gv[kk] = self.grad[t[e, kk], q]
                    self.coef[e, :, f, :] = hermite_ordinates(V, Z, ref.zb[e], ref.lam[e], ref.tri_r[e], fv, gv)
        self.sub_map = ref.sub_map
        # ∇τ_m per sub-triangle: (nt, 6, 3, 2)
        self.dtau = ref.sub_map[:, :, :, 0:2]

    def evaluate(self, x, elem):
        """Values (P, 9) and gradients (P, 9, 2) of the 9 functions of each
        particle's element; the function indices are self.functions[elem]."""
        P = len(x)
        # sub-triangle: the one in which x has the largest smallest barycentric
        best = np.full(P, -np.inf)
        sub = np.zeros(P, dtype=np.int64)
        tau = np.zeros((P, 3))
        for s in range(6):
            ts = barycentric(self.sub_map[elem, s], x)
            mn = ts.min(axis=1)
            better = mn > best
            best = np.where(better, mn, best)
            sub[better] = s
            tau[better] = ts[better]
        B, dB = bernstein2(tau)
        dtau = self.dtau[elem, sub]  # (P, 3, 2)
        dBx = dB[:, :, 0:1] * dtau[:, None, 0] + dB[:, :, 1:2] * dtau[:, None, 1] + dB[:, :, 2:3] * dtau[:, None, 2]
        C = self.coef[elem, sub]  # (P, 9, 6)
        # φ_f = Σ_b C_fb B_b, ∇φ_f = Σ_b C_fb ∇B_b (written out: faster than einsum)
        phi = C[:, :, 0] * B[:, None, 0]
        dphi = C[:, :, 0, None] * dBx[:, None, 0, :]
        for b in range(1, 6):
            phi += C[:, :, b] * B[:, None, b]
            dphi += C[:, :, b, None] * dBx[:, None, b, :]
        return phi, dphi


def hermite_ordinates(V, Z, zb, lam, R, f, g):
    """ps-splines.md §4: the 19 Bézier ordinates of the PS Hermite interpolant on
    one main triangle from values f (3,) and gradients g (3, 2) at its vertices;
    returned as the 6 ordinates (200, 020, 002, 110, 011, 101) of each of the 6
    sub-triangles (V_k, R_kl, Z) in SUBS order: (6, 6)."""
    bV = f
    bM = np.zeros((3, 3))  # bM[k, l] at M_kl = (V_k + R_kl)/2
    bS = np.zeros(3)  # at S_k = (V_k + Z)/2
    for k in range(3):
        bS[k] = f[k] + 0.5 * g[k] @ (Z - V[k])
        for l in range(3):
            if l != k:
                bM[k, l] = f[k] + 0.5 * g[k] @ (R[k, l] - V[k])
    bR = np.zeros((3, 3))
    bT = np.zeros((3, 3))
    for k in range(3):
        for l in range(3):
            if l != k:
                bR[k, l] = lam[k, l] * bM[k, l] + lam[l, k] * bM[l, k]
                bT[k, l] = lam[k, l] * bS[k] + lam[l, k] * bS[l]
    bZ = zb @ bS
    out = np.zeros((6, 6))
    for s, (k, l) in enumerate(SUBS):
        out[s] = [bV[k], bR[k, l], bZ, bM[k, l], bT[k, l], bS[k]]
    return out


class PLBasis:
    """Piecewise-linear Lagrange functions, one per vertex."""

    name = "pl"
    per_element = 3

    def __init__(self, mesh):
        self.mesh = mesh
        self.n = mesh.nv
        self.functions = mesh.t.copy()
        walls = vertex_walls(mesh)
        fixed = [set(), set()]
        for i in range(mesh.nv):
            for name in walls[i]:
                fixed[WALLS[name][2]].add(i)
        self.fixed = [np.array(sorted(f), dtype=np.int64) for f in fixed]
        self.grad = mesh.bary_map[:, :, 0:2]  # (nt, 3, 2)

    def evaluate(self, x, elem):
        phi = barycentric(self.mesh.bary_map[elem], x)
        return phi, self.grad[elem]


# ---------------------------------------------------------------------------
# Point location
# ---------------------------------------------------------------------------

LOCATE_TOL = 1e-13


def locate(mesh, x, elem=None, chunk=8192):
    """Main triangle of every point. A point still inside (up to LOCATE_TOL) its
    previous element keeps it; the others take the lowest-index triangle that
    contains them up to LOCATE_TOL (a point on an edge: the lower index of its
    two triangles; matters for PL only, whose gradient jumps there)."""
    P = len(x)
    if elem is None:
        elem = np.zeros(P, dtype=np.int64)
        todo = np.arange(P)
    else:
        tau = barycentric(mesh.bary_map[elem], x)
        todo = np.nonzero(tau.min(axis=1) < -LOCATE_TOL)[0]
    elem = elem.copy()
    A = mesh.bary_map
    for c in range(0, len(todo), chunk):
        idx = todo[c : c + chunk]
        xs = x[idx]
        # (n, nt, 3)
        tau = A[None, :, :, 0] * xs[:, None, None, 0] + A[None, :, :, 1] * xs[:, None, None, 1] + A[None, :, :, 2]
        mn = tau.min(axis=2)
        # the lowest triangle index among those containing the point (a point
        # on an edge belongs to both of its triangles), else the nearest one
        inside = mn >= -LOCATE_TOL
        best = np.where(inside.any(axis=1), inside.argmax(axis=1), mn.argmax(axis=1))
        if np.any(mn[np.arange(len(idx)), best] < -1e-10):
            raise RuntimeError("a particle left the mesh")
        elem[idx] = best
    return elem


# ---------------------------------------------------------------------------
# Particles (lattice cell centres over the unit square; docs/scenes.md, the
# order checked against psmpm's first particle frame)
# ---------------------------------------------------------------------------


def lattice(n):
    """n × n particles at the centres of the cells of the unit square, x fastest;
    volume = cell area."""
    h = 1.0 / n
    c = (np.arange(n) + 0.5) * h
    X, Y = np.meshgrid(c, c)  # rows: y, columns: x -> x fastest
    x0 = np.stack([X.ravel(), Y.ravel()], axis=1)
    vol = np.full(n * n, h * h)
    return x0, vol


# ---------------------------------------------------------------------------
# The MPM step (paper eqs. (13)-(31); docs/driver.md "One step")
# ---------------------------------------------------------------------------


class Solver:
    """Dense solves of the constrained system, one per velocity component: the
    fixed coefficients are zero, the others solve the free block of M (the
    rows and columns of the fixed ones dropped; docs/driver.md point 3)."""

    def __init__(self, M, fixed, n):
        self.free = [np.setdiff1d(np.arange(n), fixed[c]) for c in range(2)]
        self.blocks = [M[np.ix_(f, f)] for f in self.free]

    def solve(self, rhs):
        out = np.zeros_like(rhs)
        for c in range(2):
            f = self.free[c]
            out[f, c] = np.linalg.solve(self.blocks[c], rhs[f, c])
        return out


def simulate(basis, mesh, x0, vol0, steps, dt=DT, verbose=False):
    """Runs `steps` steps from the exact initial state; returns the RMS position
    error of eq. (47) and the final particle state."""
    P = len(x0)
    nb = basis.n
    x = x0.copy()
    u = np.zeros_like(x0)
    v = exact_velocity(x0, 0.0)  # initial velocity: the exact one at t = 0
    F = np.tile(np.eye(2), (P, 1, 1))
    sigma = np.zeros((P, 2, 2))
    vol = vol0.copy()
    mass = RHO0 * vol0  # m_p, constant
    elem = locate(mesh, x)
    sum_step_means = 0.0
    clock = time.time()
    for n in range(steps):
        t = n * dt  # from the step count [code: src/driver/mod.rs]
        # 1. locate and evaluate at x_p^t
        elem = locate(mesh, x, elem)
        phi, dphi = basis.evaluate(x, elem)
        fn = basis.functions[elem]  # (P, nf) global indices
        nf = fn.shape[1]
        # 2. eq. (13): M_ij = Σ_p m_p φ_i φ_j
        mp = mass[:, None, None] * phi[:, :, None] * phi[:, None, :]
        flat = (fn[:, :, None] * nb + fn[:, None, :]).ravel()
        M = np.bincount(flat, weights=mp.ravel(), minlength=nb * nb).reshape(nb, nb)
        # eq. (15): F^int_{k,i} = Σ_p V_p ∂φ_i/∂x_m σ_mk
        vs = vol[:, None, None] * sigma
        fint = dphi[:, :, 0, None] * vs[:, None, 0, :] + dphi[:, :, 1, None] * vs[:, None, 1, :]
        # eq. (16): F^body_{k,i} = Σ_p m_p φ_i g_k(x_p^0, t)
        g = body_force(x0, t)
        fbody = (mass[:, None] * g)[:, None, :] * phi[:, :, None]
        fp = fbody - fint  # (P, nf, 2)
        rhs = np.stack([np.bincount(fn.ravel(), weights=fp[:, :, c].ravel(), minlength=nb) for c in range(2)], axis=1)
        # 3. eq. (17): M a = F^trac − F^int + F^body, walls: fixed coefficients 0
        solver = Solver(M, basis.fixed, nb)
        a = solver.solve(rhs)
        # 4. eq. (18): v_p += Δt Σ a_j φ_j(x_p)
        v = v + dt * np.sum(phi[:, :, None] * a[fn], axis=1)
        # 5. eqs. (20)-(21): M v̂ = P, P_i = Σ_p m_p v_p φ_i(x_p)
        pp = (mass[:, None] * v)[:, None, :] * phi[:, :, None]
        mom = np.stack([np.bincount(fn.ravel(), weights=pp[:, :, c].ravel(), minlength=nb) for c in range(2)], axis=1)
        vh = solver.solve(mom)
        vhp = vh[fn]  # (P, nf, 2)
        # 6. eqs. (22)-(29), full velocity gradient (docs/driver.md):
        #    L_kl = Σ_j v̂_kj ∂φ_j/∂x_l (x_p^t),  F ← (I + Δt L) F
        L = np.sum(vhp[:, :, :, None] * dphi[:, :, None, :], axis=1)
        G = np.eye(2) + dt * L
        F = G[:, :, 0, None] * F[:, None, 0, :] + G[:, :, 1, None] * F[:, None, 1, :]
        sigma, J = neo_hookean(F)  # eqs. (23), (27)
        vol = J * vol0  # eq. (28)
        # 7. eqs. (30)-(31): x_p += Δt Σ v̂_i φ_i(x_p^t), u_p likewise
        dx = dt * np.sum(phi[:, :, None] * vhp, axis=1)
        x = x + dx
        u = u + dx
        # eq. (47): the squared position error at t_{n+1}, averaged over
        # particles; one sample per step, none at t = 0 [code: src/simulation.rs]
        exact = x0 + exact_displacement(x0, (n + 1) * dt)
        sum_step_means += np.mean(np.sum((x - exact) ** 2, axis=1))
        if verbose and (n + 1) % max(1, steps // 20) == 0:
            rms = math.sqrt(sum_step_means / (n + 1))
            print(f"step {n + 1:5d}  t = {(n + 1) * dt:.6f}  rms = {rms:.10e}  ({time.time() - clock:.1f} s)", file=sys.stderr)
    rms = math.sqrt(sum_step_means / steps)
    return rms, dict(x=x, u=u, v=v, F=F, sigma=sigma, vol=vol)


# ---------------------------------------------------------------------------
# Checks of the PS basis (ps-splines.md §6)
# ---------------------------------------------------------------------------


def selftest(mesh, seed=1):
    rng = np.random.default_rng(seed)
    ps = PSBasis(mesh)
    nb = ps.n
    report = {}
    # random points in every triangle
    k = 50
    e = np.repeat(np.arange(mesh.nt), k)
    w = rng.dirichlet([1, 1, 1], size=len(e))
    x = np.einsum("pk,pkd->pd", w, mesh.p[mesh.t[e]])
    phi, dphi = ps.evaluate(x, e)
    fn = ps.functions[e]
    report["partition_of_unity"] = float(np.abs(phi.sum(1) - 1).max())
    report["gradient_sum"] = float(np.abs(dphi.sum(1)).max())
    report["min_value"] = float(phi.min())
    Q = ps.control.reshape(-1, 2)  # control point of function 3 i + q
    lin = np.einsum("pf,pfd->pd", phi, Q[fn])
    report["linear_precision"] = float(np.abs(lin - x).max())
    glin = np.einsum("pfd,pfe->pde", dphi, Q[fn])
    report["linear_precision_gradient"] = float(np.abs(glin - np.eye(2)).max())
    # gradients against central differences
    hfd = 1e-6
    fd = np.zeros_like(dphi)
    for d in range(2):
        xp, xm = x.copy(), x.copy()
        xp[:, d] += hfd
        xm[:, d] -= hfd
        # keep the element fixed (the polynomial pieces extend smoothly inside
        # a sub-triangle; points near sub-edges are C¹ anyway)
        fp, _ = ps.evaluate(xp, e)
        fm, _ = ps.evaluate(xm, e)
        fd[:, :, d] = (fp - fm) / (2 * hfd)
    report["fd_gradient"] = float(np.abs(fd - dphi).max() / np.abs(dphi).max())

    # C¹ across every interior main edge and every sub-triangle edge: evaluate
    # the global functions from both sides of points on the edges.
    def global_eval(xq, eq, sq=None):
        val = np.zeros((len(xq), nb))
        grd = np.zeros((len(xq), nb, 2))
        if sq is None:
            ph, dph = ps.evaluate(xq, eq)
        else:
            ph, dph = eval_sub(ps, xq, eq, sq)
        rows = np.arange(len(xq))[:, None]
        val[rows, ps.functions[eq]] = ph
        grd[rows, ps.functions[eq]] = dph
        return val, grd

    jump_v = jump_g = 0.0
    ref = ps.ref
    s = rng.random(20)
    for kk, (va, vb) in enumerate(mesh.edges):
        if mesh.boundary_edge[kk]:
            continue
        xq = (1 - s)[:, None] * mesh.p[va] + s[:, None] * mesh.p[vb]
        (e1, _), (e2, _) = mesh.edge_tris[kk]
        v1, g1 = global_eval(xq, np.full(len(s), e1))
        v2, g2 = global_eval(xq, np.full(len(s), e2))
        jump_v = max(jump_v, np.abs(v1 - v2).max())
        jump_g = max(jump_g, np.abs(g1 - g2).max())
    # sub-triangle edges inside each triangle: V_k–Z (between (k,l) and (k,m)),
    # R_kl–Z (between (k,l) and (l,k))
    sub_index = {kl: i for i, kl in enumerate(SUBS)}
    for ee in range(mesh.nt):
        V = mesh.p[mesh.t[ee]]
        Z = ref.z[ee]
        for k in range(3):
            l, m = (k + 1) % 3, (k + 2) % 3
            xq = (1 - s)[:, None] * V[k] + s[:, None] * Z
            v1, g1 = global_eval(xq, np.full(len(s), ee), np.full(len(s), sub_index[(k, l)]))
            v2, g2 = global_eval(xq, np.full(len(s), ee), np.full(len(s), sub_index[(k, m)]))
            jump_v = max(jump_v, np.abs(v1 - v2).max())
            jump_g = max(jump_g, np.abs(g1 - g2).max())
            R = ref.tri_r[ee, k, l]
            xq = (1 - s)[:, None] * R + s[:, None] * Z
            v1, g1 = global_eval(xq, np.full(len(s), ee), np.full(len(s), sub_index[(k, l)]))
            v2, g2 = global_eval(xq, np.full(len(s), ee), np.full(len(s), sub_index[(l, k)]))
            jump_v = max(jump_v, np.abs(v1 - v2).max())
            jump_g = max(jump_g, np.abs(g1 - g2).max())
    report["c1_value_jump"] = float(jump_v)
    report["c1_gradient_jump"] = float(jump_g / np.abs(dphi).max())
    # Dirichlet: the fixed functions of each component span what vanishes on the walls
    report["functions"] = nb
    report["fixed_x"] = len(ps.fixed[0])
    report["fixed_y"] = len(ps.fixed[1])
    ok = (
        report["partition_of_unity"] < 1e-13
        and report["min_value"] > -1e-13
        and report["linear_precision"] < 1e-13
        and report["linear_precision_gradient"] < 1e-10
        and report["fd_gradient"] < 1e-6
        and report["c1_value_jump"] < 1e-13
        and report["c1_gradient_jump"] < 1e-12
    )
    report["ok"] = bool(ok)
    return report


def eval_sub(ps, x, elem, sub):
    """Evaluation on a given sub-triangle (for the C¹ check)."""
    tau = barycentric(ps.sub_map[elem, sub], x)
    B, dB = bernstein2(tau)
    dBx = np.einsum("pbm,pmd->pbd", dB, ps.dtau[elem, sub])
    C = ps.coef[elem, sub]
    return np.einsum("pfb,pb->pf", C, B), np.einsum("pfb,pbd->pfd", C, dBx)


# ---------------------------------------------------------------------------
# CLI
# ---------------------------------------------------------------------------


def make_basis(name, mesh, split="incentre"):
    return PSBasis(mesh, split) if name == "ps" else PLBasis(mesh)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", required=True, help="psmpm's mesh.vtu")
    ap.add_argument("--basis", choices=["ps", "pl"], default="ps")
    ap.add_argument("--particles", type=int, default=256, help="N: N × N particles (lattice cell centres)")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--steps", type=int)
    g.add_argument("--t-end", type=float, default=0.02)
    ap.add_argument("--dt", type=float, default=DT)
    ap.add_argument("--split", choices=["incentre", "centroid"], default="incentre", help="PS split points")
    ap.add_argument("--out", help="write the final particle state to this .npz")
    ap.add_argument("--json", action="store_true", help="print a JSON summary")
    ap.add_argument("--verbose", action="store_true")
    ap.add_argument("--selftest", action="store_true", help="check the PS basis on the mesh and exit")
    args = ap.parse_args(argv)
    mesh = read_mesh(args.mesh)
    if args.selftest:
        r = selftest(mesh)
        print(json.dumps(r, indent=1))
        return 0 if r["ok"] else 1
    steps = args.steps if args.steps is not None else int(round(args.t_end / args.dt))
    basis = make_basis(args.basis, mesh, args.split)
    x0, vol0 = lattice(args.particles)
    clock = time.time()
    rms, state = simulate(basis, mesh, x0, vol0, steps, dt=args.dt, verbose=args.verbose)
    secs = time.time() - clock
    if args.out:
        np.savez(args.out, x0=x0, **state)
    summary = dict(basis=args.basis, functions=basis.n, particles=len(x0), steps=steps, dt=args.dt, error=rms, seconds=secs)
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"{args.basis} · {basis.n} functions · {len(x0)} particles · {steps} steps of {args.dt:g}: rms position error {rms:.10e} ({secs:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
