"""Volume term, the paper's equations 6 to 8.

gamma_vol = (V - V0) / V, p = -K gamma_vol, f_i = (p / 3) sum_{faces at i} S_f n_f = p dV/dx_i,
the exact gradient of U = K [(V - V0) - V0 ln(V / V0)].
"""
import numpy as np
from numba import njit

from . import Term, register
from ._kernels import gather, volume_gradient, volume_gradient_numpy

# V / V0 below this is a flattened tetrahedron (the energy's log barrier is meaningless there)
FLAT = 1e-6


@njit(cache=True)
def _forces(x, tets, vol0, K, out):
    xt, e, dV = np.empty((4, 3)), np.empty((3, 3)), np.empty((4, 3))
    for t in range(tets.shape[0]):
        gather(x, tets, t, xt)
        V = volume_gradient(xt, e, dV)
        if V <= FLAT * vol0[t]:
            return t
        p = -K * (V - vol0[t]) / V
        for i in range(4):
            for k in range(3):
                out[tets[t, i], k] += p * dV[i, k]
    return -1


@register
class Volume(Term):
    """Pressure from the signed volume change of each tetrahedron (paper eqs. 6-8)."""

    name = "volume"
    conservative = True

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        self.K = self.scale * material.K
        self.vol0 = mesh.volumes

    def _kernel_forces(self, x, out):
        return _forces(x, self.mesh.tets, self.vol0, self.K, out)

    def forces_numpy(self, x):
        V, dV = volume_gradient_numpy(x, self.mesh.tets)
        p = -self.K * (V - self.vol0) / V
        out = np.zeros_like(x)
        np.add.at(out, self.mesh.tets, p[:, None, None] * dV)
        return out

    def energy(self, x):
        V, _ = volume_gradient_numpy(x, self.mesh.tets)
        return float(np.sum(self.K * ((V - self.vol0) - self.vol0 * np.log(V / self.vol0))))
