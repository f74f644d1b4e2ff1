"""Deviatoric normal-stress extension of docs/model.md: the per-corner edge-strain deviation.

The shear strains see no stretch along an edge. Per corner a, the three edge strains
eps_j = (|d_j| - |D_j|) / |D_j| (d_j = x_j - x_a, D_j at rest) and their mean eps_a give

    W = c_n G sum_T V0_T sum_a sum_j (eps_j - eps_a)^2,

zero under uniform scaling (purely deviatoric, the volume term keeps the pressure).
Registered as ``normal_edge``, its name beside the other candidate forms (the
``pbcm-variational+normal`` preset adds it to the variational reading).
"""
import numpy as np
from numba import njit

from . import CalibratedTerm, register
from ._blocks import (B, FLAG, INLINED, OPTIONS, OUT, SCRATCH, ahead, blocked, blocked_tets, first_flat, gather,
                      rsqrt, scatter, scatter_routed)
from ._threads import split_of
from ._kernels import axpy, dot, sub

# the three edges at each corner: (corner, other end)
CORNER_EDGES = np.array([[(a, j) for j in range(4) if j != a] for a in range(4)], dtype=np.int64)
# the six edges (p, q), p < q, in the order of the blocked kernel's reciprocal rest lengths
PAIRS = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)], dtype=np.int64)


@njit(**INLINED)
def normal_block(s, blk, vol0, inv_rest, coef_G):
    """The forces of block blk's lanes (model/terms/_blocks.py). Each edge pq's strain
    eps_pq = L_pq / R_pq - 1 belongs to both its corners, so the edge carries
    f_p += S_pq d_pq, f_q -= S_pq d_pq with S_pq = 2 c_n G V0 (2 eps_pq - mean_p - mean_q)
    / (R_pq L_pq), mean_a the mean strain of the three edges at a; 1 / L by
    :func:`model.terms._blocks.rsqrt`. Returns the count of lanes with a collapsed edge."""
    v0 = vol0[blk * B:(blk + 1) * B]
    iR = inv_rest[blk * 6 * B:(blk + 1) * 6 * B]
    n_flat = 0
    for i in range(B):
        x0 = (s[i], s[B + i], s[2 * B + i])
        x1 = (s[3 * B + i], s[4 * B + i], s[5 * B + i])
        x2 = (s[6 * B + i], s[7 * B + i], s[8 * B + i])
        x3 = (s[9 * B + i], s[10 * B + i], s[11 * B + i])
        d01, d02, d03 = sub(x1, x0), sub(x2, x0), sub(x3, x0)
        d12, d13, d23 = sub(x2, x1), sub(x3, x1), sub(x3, x2)
        l01, l02, l03 = dot(d01, d01), dot(d02, d02), dot(d03, d03)
        l12, l13, l23 = dot(d12, d12), dot(d13, d13), dot(d23, d23)
        margin = min(l01, l02, l03, l12, l13, l23)
        s[FLAG + i] = margin
        n_flat += margin <= 0.0
        iL01, iL02, iL03 = rsqrt(l01), rsqrt(l02), rsqrt(l03)
        iL12, iL13, iL23 = rsqrt(l12), rsqrt(l13), rsqrt(l23)
        L01, L02, L03 = l01 * iL01, l02 * iL02, l03 * iL03
        L12, L13, L23 = l12 * iL12, l13 * iL13, l23 * iL23
        r01, r02, r03 = iR[i], iR[B + i], iR[2 * B + i]
        r12, r13, r23 = iR[3 * B + i], iR[4 * B + i], iR[5 * B + i]
        e01, e02, e03 = L01 * r01 - 1.0, L02 * r02 - 1.0, L03 * r03 - 1.0
        e12, e13, e23 = L12 * r12 - 1.0, L13 * r13 - 1.0, L23 * r23 - 1.0
        m0 = (e01 + e02 + e03) / 3.0
        m1 = (e01 + e12 + e13) / 3.0
        m2 = (e02 + e12 + e23) / 3.0
        m3 = (e03 + e13 + e23) / 3.0
        k = 2.0 * coef_G * v0[i]
        S01 = k * (2.0 * e01 - m0 - m1) * r01 * iL01
        S02 = k * (2.0 * e02 - m0 - m2) * r02 * iL02
        S03 = k * (2.0 * e03 - m0 - m3) * r03 * iL03
        S12 = k * (2.0 * e12 - m1 - m2) * r12 * iL12
        S13 = k * (2.0 * e13 - m1 - m3) * r13 * iL13
        S23 = k * (2.0 * e23 - m2 - m3) * r23 * iL23
        f0 = axpy(S01, d01, axpy(S02, d02, (S03 * d03[0], S03 * d03[1], S03 * d03[2])))
        f1 = axpy(-S01, d01, axpy(S12, d12, (S13 * d13[0], S13 * d13[1], S13 * d13[2])))
        f2 = axpy(-S02, d02, axpy(-S12, d12, (S23 * d23[0], S23 * d23[1], S23 * d23[2])))
        f3 = axpy(-S03, d03, axpy(-S13, d13, (-S23 * d23[0], -S23 * d23[1], -S23 * d23[2])))
        for c in range(3):
            s[OUT + c * B + i] = f0[c]
            s[OUT + (3 + c) * B + i] = f1[c]
            s[OUT + (6 + c) * B + i] = f2[c]
            s[OUT + (9 + c) * B + i] = f3[c]
    return n_flat


@njit(**OPTIONS)
def normal_forces(x, tb, m, vol0, inv_rest, coef_G, out):
    """The per-corner edge-strain deviation forces, block by block; returns the first
    tetrahedron with a collapsed edge, or -1."""
    s = np.empty(SCRATCH)
    nb = (m + B - 1) // B
    for blk in range(nb):
        ahead(tb, blk, nb)
        ahead(vol0, blk, nb)
        ahead(inv_rest, blk, nb)
        gather(x, tb, blk, s)
        if normal_block(s, blk, vol0, inv_rest, coef_G) > 0:
            return first_flat(s, blk, m)
        scatter(out, tb, blk, m, s)
    return -1


@njit(**OPTIONS)
def normal_range(x, tb, m, vol0, inv_rest, coef_G, first, stop, late, route, buf, out):
    """normal_forces over the blocks [first, stop), the forces of routed corners into buf (the
    threaded mode's twin: model.terms._threads.SplitBlocks)."""
    s = np.empty(SCRATCH)
    nb = (m + B - 1) // B
    for blk in range(first, stop):
        ahead(tb, blk, nb)
        ahead(vol0, blk, nb)
        ahead(inv_rest, blk, nb)
        gather(x, tb, blk, s)
        if normal_block(s, blk, vol0, inv_rest, coef_G) > 0:
            return first_flat(s, blk, m)
        if late[blk]:
            scatter_routed(out, tb, blk, m, s, route, buf)
        else:
            scatter(out, tb, blk, m, s)
    return -1


@njit(cache=True, fastmath=True)
def normal_forces_reference(x, tets, vol0, rest_len, coef_G, out):
    """Corner by corner, tetrahedron by tetrahedron (the reference of ``normal_forces``)."""
    d = np.empty((3, 3))
    ln = np.empty(3)
    eps = np.empty(3)
    for t in range(tets.shape[0]):
        for a in range(4):
            na = tets[t, a]
            for r in range(3):
                nj = tets[t, CORNER_EDGES[a, r, 1]]
                for k in range(3):
                    d[r, k] = x[nj, k] - x[na, k]
                ln[r] = np.sqrt(d[r, 0] ** 2 + d[r, 1] ** 2 + d[r, 2] ** 2)
                if ln[r] <= 0.0:
                    return t
                eps[r] = ln[r] / rest_len[t, a, r] - 1.0
            mean = (eps[0] + eps[1] + eps[2]) / 3.0
            for r in range(3):
                # dW/deps_r = 2 c_n G V0 (eps_r - mean); the mean's own derivative sums to zero
                s = 2.0 * coef_G * vol0[t] * (eps[r] - mean) / (rest_len[t, a, r] * ln[r])
                nj = tets[t, CORNER_EDGES[a, r, 1]]
                for k in range(3):
                    out[nj, k] -= s * d[r, k]
                    out[na, k] += s * d[r, k]
    return -1


@njit(cache=True, fastmath=True)
def normal_strains(x, tets, rest_len, out):
    """eps_j - eps_a (m, 4, 3): each corner's edge strains less their mean."""
    for t in range(tets.shape[0]):
        for a in range(4):
            na = tets[t, a]
            mean = 0.0
            for r in range(3):
                nj = tets[t, CORNER_EDGES[a, r, 1]]
                ln = np.sqrt((x[nj, 0] - x[na, 0]) ** 2 + (x[nj, 1] - x[na, 1]) ** 2
                             + (x[nj, 2] - x[na, 2]) ** 2)
                out[t, a, r] = ln / rest_len[t, a, r] - 1.0
                mean += out[t, a, r]
            for r in range(3):
                out[t, a, r] -= mean / 3.0


def edge_vectors(x, tets):
    """d (m, 4, 3, 3): the three edge vectors at each corner."""
    return x[tets[:, CORNER_EDGES[..., 1]]] - x[tets[:, CORNER_EDGES[..., 0]]]


@register
class NormalEdge(CalibratedTerm):
    """Deviatoric edge-strain term at each corner; ``c`` is ``"auto"`` or a positive number."""

    name = "normal_edge"

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        self.rest_len = np.linalg.norm(edge_vectors(mesh.points, mesh.tets), axis=-1)
        rest = np.linalg.norm(mesh.points[mesh.tets[:, PAIRS[:, 1]]]
                              - mesh.points[mesh.tets[:, PAIRS[:, 0]]], axis=-1)
        self._blocked = (blocked_tets(mesh.tets), mesh.n_tets, blocked(self.vol0),
                         blocked(1.0 / rest))

    def kernel_args(self, k):
        return normal_forces, (*self._blocked, k * self.G)

    def threaded_kernel(self):
        return split_of(self, self._blocked[0], self.mesh.n_tets, self.mesh.n_nodes).kernel(
            normal_range, self.kernel()[1])

    def reference_kernel(self):
        k = self.kernel()[1][-1]          # the same checks (calibrated)
        return normal_forces_reference, (self.mesh.tets, self.vol0, self.rest_len, k)

    def calibration_residuals(self, x, rows):
        """The deviatoric edge strains (r, 4, 3) of the tetrahedra ``rows`` and their weights
        G V0: unit_energy = sum w (eps - mean)^2."""
        tets = self.mesh.tets[rows]
        out = np.empty((len(tets), 4, 3))
        normal_strains(np.ascontiguousarray(x, dtype=np.float64), tets, self.rest_len[rows],
                       out)
        return out, self.G * self.vol0[rows]

    def forces_numpy(self, x):
        d = edge_vectors(x, self.mesh.tets)
        ln = np.linalg.norm(d, axis=-1)
        eps = ln / self.rest_len - 1.0
        dev = eps - eps.mean(axis=2, keepdims=True)
        s = 2 * self.scale * self.coef * self.G * self.vol0[:, None, None] * dev \
            / (self.rest_len * ln)
        fj = -s[..., None] * d
        out = np.zeros_like(x)
        np.add.at(out, self.mesh.tets[:, CORNER_EDGES[..., 1]], fj)
        np.add.at(out, self.mesh.tets[:, CORNER_EDGES[..., 0]], -fj)
        return out
