"""Deviatoric normal-stress candidate from the stretches along the material axes.

M. Mueller, N. Chentanez, T.-Y. Kim and M. Macklin, "Strain based dynamics", Proc. ACM
SIGGRAPH/Eurographics Symposium on Computer Animation 2014, constrain each tetrahedron's
stretches along the rest axes, s_i = |F e_i| with F = Ds Dm^-1 (the columns of F), apart from
its shears. Their deviation from the mean stretch gives a purely deviatoric normal term:

    W = c_n G sum_T V0_T sum_i (s_i - mean s)^2,   P = dW/dF: column i = 2 c_n G (s_i - mean) F e_i / s_i,

zero under rigid motion (left rotations of F) and uniform scaling. The axes are the material
(rest) axes, so on a cube they are the cube's: the normal stresses of the paper's experiment.
"""
import numpy as np
from numba import njit

from . import register
from ._constant_strain import ConstantStrainTerm
from ._kernels import add_piola_forces, deformation_gradient, piola_forces_numpy
from .volume import FLAT


@njit(cache=True, fastmath=True)
def axis_stretch_forces(x, tets, Dinv, vol0, kG, out):
    for t in range(tets.shape[0]):
        F, J = deformation_gradient(x, tets, t, Dinv)
        if J <= FLAT:
            return t
        s0 = np.sqrt(F[0][0] ** 2 + F[1][0] ** 2 + F[2][0] ** 2)
        s1 = np.sqrt(F[0][1] ** 2 + F[1][1] ** 2 + F[2][1] ** 2)
        s2 = np.sqrt(F[0][2] ** 2 + F[1][2] ** 2 + F[2][2] ** 2)
        mean = (s0 + s1 + s2) / 3.0
        a0, a1, a2 = 2.0 * kG * (s0 - mean) / s0, 2.0 * kG * (s1 - mean) / s1, \
            2.0 * kG * (s2 - mean) / s2
        P = ((a0 * F[0][0], a1 * F[0][1], a2 * F[0][2]),
             (a0 * F[1][0], a1 * F[1][1], a2 * F[1][2]),
             (a0 * F[2][0], a1 * F[2][1], a2 * F[2][2]))
        add_piola_forces(P, Dinv, vol0, tets, t, out)
    return -1


@register
class NormalSBD(ConstantStrainTerm):
    """Deviation of the stretches along the material axes (after Mueller et al. 2014)."""

    name = "normal_sbd"

    def kernel_args(self, k):
        return axis_stretch_forces, (self.mesh.tets, self.Dinv, self.vol0, k * self.G)

    def _stretch(self, x, rows=slice(None)):
        F = self.F(x, rows)
        return F, np.linalg.norm(F, axis=1)          # s_i = |column i|

    def calibration_residuals(self, x, rows):
        """s_i - mean s (r, 3) of the tetrahedra ``rows``, weights G V0."""
        _, s = self._stretch(x, rows)
        return s - s.mean(axis=1, keepdims=True), self.G * self.vol0[rows]

    def forces_numpy(self, x):
        F, s = self._stretch(x)
        a = 2 * self.scale * self.coef * self.G * (s - s.mean(axis=1, keepdims=True)) / s
        return piola_forces_numpy(F * a[:, None, :], self.Dinv, self.vol0, self.mesh.tets,
                                  self.mesh.n_nodes)
