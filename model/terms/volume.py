"""Volume term, the paper's equations 6 to 8.

gamma_vol = (V - V0) / V, p = -K gamma_vol, f_i = (p / 3) sum_{faces at i} S_f n_f = p dV/dx_i,
the exact gradient of U = K [(V - V0) - V0 ln(V / V0)].
"""
import numpy as np
from numba import njit

from . import Term, register
from ._blocks import B, blocked_tets
from ._kernels import add_to, cross, dot, sub, vec, volume_gradient_numpy
from ._threads import split_of

# V / V0 below this is a flattened tetrahedron (the energy's log barrier is meaningless there)
FLAT = 1e-6


@njit(cache=True, inline="always")
def volume_tet(x, tets, vol0, K, t):
    """Tetrahedron t's pressure forces on its four nodes (p dV/dx_i, p = -K (V - V0) / V),
    and whether it is flattened below FLAT V0 (then the forces are not computed)."""
    n0, n1, n2, n3 = tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3]
    x0 = vec(x, n0)
    d01, d02, d03 = sub(vec(x, n1), x0), sub(vec(x, n2), x0), sub(vec(x, n3), x0)
    c1, c2, c3 = cross(d02, d03), cross(d03, d01), cross(d01, d02)   # d(6V)/dx_1..3
    V6 = dot(d01, c1)
    if V6 <= FLAT * 6.0 * vol0[t]:
        z = (0.0, 0.0, 0.0)
        return True, z, z, z, z
    p6 = -K * (V6 - 6.0 * vol0[t]) / (6.0 * V6)   # p / 6: c_j is d(6V)/dx_j
    return (False, (-p6 * (c1[0] + c2[0] + c3[0]), -p6 * (c1[1] + c2[1] + c3[1]),
                    -p6 * (c1[2] + c2[2] + c3[2])),
            (p6 * c1[0], p6 * c1[1], p6 * c1[2]), (p6 * c2[0], p6 * c2[1], p6 * c2[2]),
            (p6 * c3[0], p6 * c3[1], p6 * c3[2]))


# without fastmath: its contraction of a product into the addition differs between the
# serial kernel (which adds into the nodes) and its twin (which stores), and the two-thread
# mode must equal the serial forces bit for bit
@njit(cache=True)
def volume_forces(x, tets, vol0, K, out):
    """f_i = p dV/dx_i, p = -K (V - V0) / V, for every tetrahedron; returns the first one
    flattened below FLAT V0, or -1."""
    for t in range(tets.shape[0]):
        flat, f0, f1, f2, f3 = volume_tet(x, tets, vol0, K, t)
        if flat:
            return t
        add_to(out, tets[t, 0], f0)
        add_to(out, tets[t, 1], f1)
        add_to(out, tets[t, 2], f2)
        add_to(out, tets[t, 3], f3)
    return -1


@njit(cache=True)
def volume_range(x, tets, vol0, K, first, stop, late, route, buf, out):
    """volume_forces over the tetrahedra of blocks [first, stop) of B, the forces of routed
    corners into buf (the threaded mode's twin: model.terms._threads.SplitBlocks); a run of
    blocks without a routed corner is the serial kernel's."""
    blk = first
    while blk < stop:
        lo = blk * B
        if not late[blk]:
            while blk < stop and not late[blk]:
                blk += 1
            hi = min(blk * B, tets.shape[0])
            bad = volume_forces(x, tets[lo:hi], vol0[lo:hi], K, out)
            if bad >= 0:
                return lo + bad
            continue
        for t in range(lo, min(lo + B, tets.shape[0])):
            flat, f0, f1, f2, f3 = volume_tet(x, tets, vol0, K, t)
            if flat:
                return t
            for c, f in enumerate((f0, f1, f2, f3)):
                r = route[blk * 4 * B + c * B + t - lo]
                if r < 0:
                    add_to(out, tets[t, c], f)
                else:
                    buf[r, 0], buf[r, 1], buf[r, 2] = f
        blk += 1
    return -1


@register
class Volume(Term):
    """Pressure from the signed volume change of each tetrahedron (paper eqs. 6-8)."""

    name = "volume"
    conservative = True
    checks_inversion = True

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        self.K = self.scale * material.K
        self.vol0 = mesh.volumes

    def kernel(self):
        return volume_forces, (self.mesh.tets, self.vol0, self.K)

    def threaded_kernel(self):
        # the routes of the tetrahedra taken B at a time, as the blocked kernels'
        return split_of(self, blocked_tets(self.mesh.tets), self.mesh.n_tets,
                        self.mesh.n_nodes).kernel(volume_range, self.kernel()[1])

    def forces_numpy(self, x):
        V, dV = volume_gradient_numpy(x, self.mesh.tets)
        p = -self.K * (V - self.vol0) / V
        out = np.zeros_like(x)
        np.add.at(out, self.mesh.tets, p[:, None, None] * dV)
        return out

    def energy(self, x):
        V, _ = volume_gradient_numpy(x, self.mesh.tets)
        return float(np.sum(self.K * ((V - self.vol0) - self.vol0 * np.log(V / self.vol0))))
