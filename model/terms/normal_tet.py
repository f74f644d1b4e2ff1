"""Deviatoric normal-stress candidate from edge Green strains over the whole tetrahedron.

H. Delingette, "Biquadratic and quadratic springs for modeling St Venant Kirchhoff
materials", ISBMS 2008, LNCS 5104, pp. 40-48, writes the StVK energy of a tetrahedron with
the Green strains of its six edges, E_e = (l_e^2 - L_e^2) / (2 L_e^2) (biquadratic springs).
Keeping only their deviation from the tetrahedron's mean makes a purely deviatoric normal term
(the volume term keeps the pressure):

    W = c_n G sum_T V0_T sum_e (E_e - mean_T E)^2,

zero under rigid motion and uniform scaling. Unlike ``normal_edge`` (docs/model.md's per-corner form,
three edges and engineering strain) each edge is counted once, against all six.
"""
import numpy as np
from numba import njit

from . import CalibratedTerm, register

EDGES = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)], dtype=np.int64)


@njit(cache=True, fastmath=True)
def tet_edge_forces(x, tets, vol0, rest_sq, kG, out):
    d = np.empty((6, 3))
    E = np.empty(6)
    for t in range(tets.shape[0]):
        mean = 0.0
        for e in range(6):
            i, j = tets[t, EDGES[e, 0]], tets[t, EDGES[e, 1]]
            for k in range(3):
                d[e, k] = x[j, k] - x[i, k]
            ln2 = d[e, 0] ** 2 + d[e, 1] ** 2 + d[e, 2] ** 2
            if ln2 <= 0.0:
                return t
            E[e] = 0.5 * (ln2 / rest_sq[t, e] - 1.0)
            mean += E[e] / 6.0
        for e in range(6):
            # dW/dE_e = 2 c_n G V0 (E_e - mean) and dE_e/dx_j = d_e / L_e^2
            s = 2.0 * kG * vol0[t] * (E[e] - mean) / rest_sq[t, e]
            i, j = tets[t, EDGES[e, 0]], tets[t, EDGES[e, 1]]
            for k in range(3):
                out[j, k] -= s * d[e, k]
                out[i, k] += s * d[e, k]
    return -1


@register
class NormalTet(CalibratedTerm):
    """Deviation of the six edge Green strains of each tetrahedron (after Delingette 2008)."""

    name = "normal_tet"

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        d = mesh.points[mesh.tets[:, EDGES[:, 1]]] - mesh.points[mesh.tets[:, EDGES[:, 0]]]
        self.rest_sq = np.ascontiguousarray(np.sum(d * d, axis=-1))

    def kernel_args(self, k):
        return tet_edge_forces, (self.mesh.tets, self.vol0, self.rest_sq, k * self.G)

    def _green(self, x, rows=slice(None)):
        tets = self.mesh.tets[rows]
        d = x[tets[:, EDGES[:, 1]]] - x[tets[:, EDGES[:, 0]]]
        return d, 0.5 * (np.sum(d * d, axis=-1) / self.rest_sq[rows] - 1.0)

    def calibration_residuals(self, x, rows):
        """E_e - mean E (r, 6) of the tetrahedra ``rows``, weights G V0."""
        _, E = self._green(x, rows)
        return E - E.mean(axis=1, keepdims=True), self.G * self.vol0[rows]

    def forces_numpy(self, x):
        d, E = self._green(np.asarray(x, dtype=float))
        s = 2 * self.scale * self.coef * self.G * self.vol0[:, None] \
            * (E - E.mean(axis=1, keepdims=True)) / self.rest_sq
        fj = -s[..., None] * d
        out = np.zeros_like(x)
        np.add.at(out, self.mesh.tets[:, EDGES[:, 1]], fj)
        np.add.at(out, self.mesh.tets[:, EDGES[:, 0]], -fj)
        return out
