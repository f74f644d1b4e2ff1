"""Deviatoric normal-stress extension of docs/model.md: the per-corner edge-strain deviation.

The shear strains see no stretch along an edge. Per corner a, the three edge strains
eps_j = (|d_j| - |D_j|) / |D_j| (d_j = x_j - x_a, D_j at rest) and their mean eps_a give

    W = c_n G sum_T V0_T sum_a sum_j (eps_j - eps_a)^2,

zero under uniform scaling (purely deviatoric, the volume term keeps the pressure).
Registered as ``normal`` (the name of the ``pbcm-variational+normal`` preset) and as
``normal_edge``, its name beside the other candidate forms.
"""
import numpy as np
from numba import njit

from . import CalibratedTerm, register

# the three edges at each corner: (corner, other end)
CORNER_EDGES = np.array([[(a, j) for j in range(4) if j != a] for a in range(4)], dtype=np.int64)


@njit(cache=True, fastmath=True)
def normal_forces(x, tets, vol0, rest_len, coef_G, out):
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
class Normal(CalibratedTerm):
    """Deviatoric edge-strain term at each corner; ``c`` is ``"auto"`` or a positive number."""

    name = "normal"

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        self.rest_len = np.linalg.norm(edge_vectors(mesh.points, mesh.tets), axis=-1)

    def kernel_args(self, k):
        return normal_forces, (self.mesh.tets, self.vol0, self.rest_len, k * self.G)

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


@register
class NormalEdge(Normal):
    """docs/model.md's per-corner edge-strain deviation (the term ``normal``) by its candidate
    name."""

    name = "normal_edge"
