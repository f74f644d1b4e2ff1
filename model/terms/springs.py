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
from ._blocks import B, blocked_tets
from ._threads import split_of


# fast maths without contraction or reciprocals: a product rounds before it is added, in the
# serial kernel as in the threaded twin that stores it, whether or not the compiler inlines the
# one into the other (the twin's bit-for-bit promise); a collapsed edge divides by zero (inf,
# then reported) rather than raising
FAST = {"nnan", "ninf", "nsz", "afn"}


@njit(inline="always", fastmath=FAST, error_model="numpy")
def spring_force(x, first, second, rest, k, s):
    """Edge s's force f = k (l - l0) / l d on its first node (minus that on its second), and
    its length l (0: collapsed)."""
    i, j = first[s], second[s]
    d0, d1, d2 = x[j, 0] - x[i, 0], x[j, 1] - x[i, 1], x[j, 2] - x[i, 2]
    ln = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    f = k[s] * (ln - rest[s]) / ln  # tension pulls j towards i
    return ln, (f * d0, f * d1, f * d2)


@njit(cache=True, fastmath=FAST, error_model="numpy")
def spring_forces(x, first, second, rest, k, out):
    """Linear springs f = k (l - l0) on every edge (its nodes first[s], second[s]); returns
    the first collapsed edge, or -1. The force on a run of edges with one first node (the
    edges come sorted by it) is summed in registers, in the same order as one addition into
    ``out`` per edge: no other edge of the run touches that node, so the bits are those of
    :func:`spring_forces_reference`, without a store-to-load wait per edge."""
    m = first.shape[0]
    if m == 0:
        return -1
    i = first[0]
    a0, a1, a2 = out[i, 0], out[i, 1], out[i, 2]
    x0, x1, x2 = x[i, 0], x[i, 1], x[i, 2]
    for s in range(m):
        if first[s] != i:
            out[i, 0], out[i, 1], out[i, 2] = a0, a1, a2
            i = first[s]
            a0, a1, a2 = out[i, 0], out[i, 1], out[i, 2]
            x0, x1, x2 = x[i, 0], x[i, 1], x[i, 2]
        j = second[s]
        d0, d1, d2 = x[j, 0] - x0, x[j, 1] - x1, x[j, 2] - x2
        ln = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if ln <= 0.0:
            out[i, 0], out[i, 1], out[i, 2] = a0, a1, a2
            return s
        f = k[s] * (ln - rest[s]) / ln
        a0 += f * d0
        a1 += f * d1
        a2 += f * d2
        out[j, 0] -= f * d0
        out[j, 1] -= f * d1
        out[j, 2] -= f * d2
    out[i, 0], out[i, 1], out[i, 2] = a0, a1, a2
    return -1


@njit(cache=True, fastmath=FAST, error_model="numpy")
def spring_forces_reference(x, edge, rest, k, out):
    """spring_forces on the (m, 2) edges: the kernel's reference implementation."""
    for s in range(edge.shape[0]):
        i, j = edge[s, 0], edge[s, 1]
        d0, d1, d2 = x[j, 0] - x[i, 0], x[j, 1] - x[i, 1], x[j, 2] - x[i, 2]
        ln = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if ln <= 0.0:
            return s
        f = k[s] * (ln - rest[s]) / ln
        out[i, 0] += f * d0
        out[i, 1] += f * d1
        out[i, 2] += f * d2
        out[j, 0] -= f * d0
        out[j, 1] -= f * d1
        out[j, 2] -= f * d2
    return -1


@njit(cache=True, fastmath=FAST, error_model="numpy")
def spring_range(x, first, second, rest, k, start, stop, late, route, buf, out):
    """spring_forces over the edges of blocks [start, stop) of B edges, the forces of routed
    ends into buf (the threaded mode's twin: model.terms._threads.SplitBlocks; a second
    end's force is stored negated, which adds to the bits of the serial subtraction)."""
    blk = start
    while blk < stop:
        lo = blk * B
        if not late[blk]:       # a run of blocks without a routed end: the serial kernel
            while blk < stop and not late[blk]:
                blk += 1
            hi = min(blk * B, first.shape[0])
            bad = spring_forces(x, first[lo:hi], second[lo:hi], rest[lo:hi], k[lo:hi], out)
            if bad >= 0:
                return lo + bad
            continue
        hi = min(lo + B, first.shape[0])
        for s in range(lo, hi):
            ln, g = spring_force(x, first, second, rest, k, s)
            if ln <= 0.0:
                return s
            i, j = first[s], second[s]
            ri, rj = route[blk * 2 * B + s - lo], route[blk * 2 * B + B + s - lo]
            if ri < 0:
                out[i, 0] += g[0]
                out[i, 1] += g[1]
                out[i, 2] += g[2]
            else:
                buf[ri, 0], buf[ri, 1], buf[ri, 2] = g[0], g[1], g[2]
            if rj < 0:
                out[j, 0] -= g[0]
                out[j, 1] -= g[1]
                out[j, 2] -= g[2]
            else:
                buf[rj, 0], buf[rj, 1], buf[rj, 2] = -g[0], -g[1], -g[2]
        blk += 1
    return -1


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
        if mesh.n_nodes >= 2**31:
            raise ValueError("more than 2**31 nodes")
        # each end in an int32 array of its own: at 1e6 tetrahedra the (m, 2) int64 edges'
        # traffic cost the kernel a quarter of its time
        self._ends = tuple(np.ascontiguousarray(self.edge[:, c], dtype=np.int32) for c in (0, 1))

    def kernel(self):
        return spring_forces, (*self._ends, self.rest, self.k)

    def reference_kernel(self):
        return spring_forces_reference, (self.edge, self.rest, self.k)

    def threaded_kernel(self):
        # the routes of the edges taken B at a time, as the blocked kernels' elements
        return split_of(self, blocked_tets(self.edge), len(self.edge), self.mesh.n_nodes).kernel(
            spring_range, self.kernel()[1])

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
