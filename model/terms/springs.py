"""Mass-spring baseline (docs/model.md "Mass-spring baseline").

Linear springs on the mesh edges with the stiffness rule of A. van Gelder, "Approximate
simulation of elastic membranes by triangulated spring meshes", J. Graphics Tools 3(2), 1998,
extended to tetrahedra as in docs/model.md:

    k_e = E * sum_{T at e} V0_T / L_e^2.

An isotropic spring network obeys the Cauchy relations: its effective Poisson ratio is 1/4
whatever nu is asked for (the reports show it).
"""
import numpy as np
from numba import njit

from . import Term, register
from ..geometry import edges
from ._threads import TwoThreads


@njit(cache=True, fastmath=True)
def spring_forces(x, edge, rest, k, out):
    """Linear springs f = k (l - l0) on every edge; returns the first collapsed edge, or -1."""
    for s in range(edge.shape[0]):
        i, j = edge[s, 0], edge[s, 1]
        d0, d1, d2 = x[j, 0] - x[i, 0], x[j, 1] - x[i, 1], x[j, 2] - x[i, 2]
        ln = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if ln <= 0.0:
            return s
        f = k[s] * (ln - rest[s]) / ln  # tension pulls j towards i
        out[i, 0] += f * d0
        out[i, 1] += f * d1
        out[i, 2] += f * d2
        out[j, 0] -= f * d0
        out[j, 1] -= f * d1
        out[j, 2] -= f * d2
    return -1


@njit(cache=True, fastmath=True)
def spring_edges(x, edge, rest, k, fe, flat, first, stop):
    """spring_forces for the edges [first, stop) into fe (m, 2, 3), collapsed ones flagged in
    flat (the two-thread mode's twin: node j's force is stored negated, which the gather adds
    to the same bits as the serial kernel's subtraction)."""
    n_flat = 0
    for s in range(first, stop):
        i, j = edge[s, 0], edge[s, 1]
        d0, d1, d2 = x[j, 0] - x[i, 0], x[j, 1] - x[i, 1], x[j, 2] - x[i, 2]
        ln = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if ln <= 0.0:
            flat[s] = 1
            n_flat += 1
            continue
        f = k[s] * (ln - rest[s]) / ln
        g0, g1, g2 = f * d0, f * d1, f * d2
        fe[s, 0, 0], fe[s, 0, 1], fe[s, 0, 2] = g0, g1, g2
        fe[s, 1, 0], fe[s, 1, 1], fe[s, 1, 2] = -g0, -g1, -g2
    return n_flat


def van_gelder_stiffness(mesh):
    """k_e = E sum of V0 over the tetrahedra at edge e / L_e^2, with E = 1."""
    e = edges(mesh.tets)
    pairs = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)])
    all_e = np.sort(mesh.tets[:, pairs].reshape(-1, 2), axis=1)
    index = np.searchsorted(e[:, 0] * mesh.n_nodes + e[:, 1], all_e[:, 0] * mesh.n_nodes + all_e[:, 1])
    vol = np.bincount(index, weights=np.repeat(mesh.volumes, 6), minlength=len(e))
    rest = np.linalg.norm(mesh.points[e[:, 1]] - mesh.points[e[:, 0]], axis=1)
    return e, rest, vol / rest**2


@register
class Springs(Term):
    """Edge springs with van Gelder's stiffness rule."""

    name = "springs"
    conservative = True

    fit_constant = "k_scale"   # the factor on van Gelder's stiffness

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        self.edge, self.rest, k = van_gelder_stiffness(mesh)
        self.k = self.scale * material.E * k

    def kernel(self):
        return spring_forces, (self.edge, self.rest, self.k)

    def threaded_kernel(self):
        if getattr(self, "_threads", None) is None:
            self._threads = TwoThreads(self.edge, self.mesh.n_nodes)
        return self._threads.kernel(spring_edges, self.kernel()[1])

    def degenerate_tets(self, bad):
        """The tetrahedra around the collapsed edge ``bad``."""
        e = self.edge[bad]
        return np.flatnonzero((self.mesh.tets == e[0]).any(axis=1)
                              & (self.mesh.tets == e[1]).any(axis=1)).tolist()

    def forces_numpy(self, x):
        d = x[self.edge[:, 1]] - x[self.edge[:, 0]]
        ln = np.linalg.norm(d, axis=1)
        f = (self.k * (ln - self.rest) / ln)[:, None] * d
        out = np.zeros_like(x)
        np.add.at(out, self.edge[:, 0], f)
        np.add.at(out, self.edge[:, 1], -f)
        return out

    def energy(self, x):
        ln = np.linalg.norm(x[self.edge[:, 1]] - x[self.edge[:, 0]], axis=1)
        return float(0.5 * np.sum(self.k * (ln - self.rest) ** 2))
