"""Deviatoric normal-stress candidate from the co-rotated strain of F = Ds Dm^-1.

F = R U (polar decomposition): U = sqrt(F^T F) is the strain with the rotation removed, as in
co-rotated FEM (M. Mueller and M. Gross, "Interactive virtual materials", GI 2004). Its
normal components along the material axes, less their mean, give a purely deviatoric normal
term:

    W = c_n G sum_T V0_T sum_i (U_ii - tr U / 3)^2.

Its stress: with A = dW/dU = 2 c_n G diag(U_ii - tr U / 3) and C = F^T F = V diag(sigma^2)
V^T, differentiating U^2 = C gives dW = B : dC with (V^T B V)_ij = (V^T A V)_ij /
(sigma_i + sigma_j), so P = dW/dF = 2 F B: the exact gradient, no rotation derivative needed.
Where ``normal_sbd`` measures the stretch |F e_i| of each material axis, this measures the
axis' stretch with the shear of the other axes removed; the two agree to first order.
"""
import numpy as np
from numba import njit

from . import register
from ._constant_strain import ConstantStrainTerm
from ._kernels import add_piola_forces, deformation_gradient, piola_forces_numpy
from .volume import FLAT


@njit(cache=True, fastmath=True)
def jacobi_eigh3(A, V):
    """Eigen-decomposition of the symmetric 3 x 3 ``A`` in place by cyclic Jacobi rotations:
    on return diag(A) holds the eigenvalues and the columns of ``V`` the eigenvectors. Robust
    where eigenvalues coincide (C = I at rest), and no LAPACK call per tetrahedron."""
    for i in range(3):
        for j in range(3):
            V[i, j] = 1.0 if i == j else 0.0
    for _ in range(20):
        off = A[0, 1] ** 2 + A[0, 2] ** 2 + A[1, 2] ** 2
        if off <= 1e-32 * (A[0, 0] ** 2 + A[1, 1] ** 2 + A[2, 2] ** 2):
            return
        for r in range(3):
            p, q = (0, 0, 1)[r], (1, 2, 2)[r]
            if abs(A[p, q]) <= 1e-18 * (abs(A[p, p]) + abs(A[q, q])):
                continue
            theta = (A[q, q] - A[p, p]) / (2.0 * A[p, q])
            t = (1.0 if theta >= 0.0 else -1.0) / (abs(theta) + np.sqrt(theta * theta + 1.0))
            c = 1.0 / np.sqrt(t * t + 1.0)
            sn = t * c
            for k in range(3):          # A <- A J (columns p, q)
                akp, akq = A[k, p], A[k, q]
                A[k, p], A[k, q] = c * akp - sn * akq, sn * akp + c * akq
            for k in range(3):          # A <- J^T A (rows p, q)
                apk, aqk = A[p, k], A[q, k]
                A[p, k], A[q, k] = c * apk - sn * aqk, sn * apk + c * aqk
            for k in range(3):          # V <- V J
                vkp, vkq = V[k, p], V[k, q]
                V[k, p], V[k, q] = c * vkp - sn * vkq, sn * vkp + c * vkq


@njit(cache=True, fastmath=True)
def corotated_normal_forces(x, tets, Dinv, vol0, kG, out):
    C = np.empty((3, 3))
    V = np.empty((3, 3))
    B = np.empty((3, 3))
    sig = np.empty(3)
    a = np.empty(3)
    for t in range(tets.shape[0]):
        F, J = deformation_gradient(x, tets, t, Dinv)
        if J <= FLAT:
            return t
        for i in range(3):
            for j in range(3):
                C[i, j] = F[0][i] * F[0][j] + F[1][i] * F[1][j] + F[2][i] * F[2][j]
        jacobi_eigh3(C, V)
        for i in range(3):
            sig[i] = np.sqrt(C[i, i])
        trU = sig[0] + sig[1] + sig[2]
        # A = dW/dU = 2 kG diag(U_ii - tr U / 3), U_ii = sum_p V_ip^2 sigma_p
        for i in range(3):
            a[i] = 2.0 * kG * (V[i, 0] ** 2 * sig[0] + V[i, 1] ** 2 * sig[1]
                               + V[i, 2] ** 2 * sig[2] - trU / 3.0)
        # B = V Bt V^T with Bt_pq = (V^T A V)_pq / (sigma_p + sigma_q)
        for i in range(3):
            for j in range(3):
                B[i, j] = 0.0
        for p in range(3):
            for q in range(3):
                bt = (V[0, p] * a[0] * V[0, q] + V[1, p] * a[1] * V[1, q]
                      + V[2, p] * a[2] * V[2, q]) / (sig[p] + sig[q])
                for i in range(3):
                    for j in range(3):
                        B[i, j] += V[i, p] * bt * V[j, q]
        P = ((2.0 * (F[0][0] * B[0, 0] + F[0][1] * B[1, 0] + F[0][2] * B[2, 0]),
              2.0 * (F[0][0] * B[0, 1] + F[0][1] * B[1, 1] + F[0][2] * B[2, 1]),
              2.0 * (F[0][0] * B[0, 2] + F[0][1] * B[1, 2] + F[0][2] * B[2, 2])),
             (2.0 * (F[1][0] * B[0, 0] + F[1][1] * B[1, 0] + F[1][2] * B[2, 0]),
              2.0 * (F[1][0] * B[0, 1] + F[1][1] * B[1, 1] + F[1][2] * B[2, 1]),
              2.0 * (F[1][0] * B[0, 2] + F[1][1] * B[1, 2] + F[1][2] * B[2, 2])),
             (2.0 * (F[2][0] * B[0, 0] + F[2][1] * B[1, 0] + F[2][2] * B[2, 0]),
              2.0 * (F[2][0] * B[0, 1] + F[2][1] * B[1, 1] + F[2][2] * B[2, 1]),
              2.0 * (F[2][0] * B[0, 2] + F[2][1] * B[1, 2] + F[2][2] * B[2, 2])))
        add_piola_forces(P, Dinv, vol0, tets, t, out)
    return -1


def stretch_numpy(F):
    """U = sqrt(F^T F) for a stack of F, with the eigenvalues sigma and vectors V of U."""
    lam, V = np.linalg.eigh(np.transpose(F, (0, 2, 1)) @ F)
    sig = np.sqrt(lam)
    return (V * sig[:, None, :]) @ np.transpose(V, (0, 2, 1)), sig, V


@register
class NormalCorotated(ConstantStrainTerm):
    """Deviation of the co-rotated normal strains U_ii along the material axes."""

    name = "normal_corotated"

    def kernel_args(self, k):
        return corotated_normal_forces, (self.mesh.tets, self.Dinv, self.vol0, k * self.G)

    def calibration_residuals(self, x, rows):
        """U_ii - tr U / 3 (r, 3) of the tetrahedra ``rows``, weights G V0."""
        U, _, _ = stretch_numpy(self.F(x, rows))
        d = np.diagonal(U, axis1=1, axis2=2)
        return d - d.mean(axis=1, keepdims=True), self.G * self.vol0[rows]

    def forces_numpy(self, x):
        F = self.F(x)
        U, sig, V = stretch_numpy(F)
        d = np.diagonal(U, axis1=1, axis2=2)
        A = 2 * self.scale * self.coef * self.G * (d - d.mean(axis=1, keepdims=True))
        At = np.einsum("mip,mi,miq->mpq", V, A, V)                 # V^T diag(A) V
        Bt = At / (sig[:, :, None] + sig[:, None, :])
        B = V @ Bt @ np.transpose(V, (0, 2, 1))
        return piola_forces_numpy(2 * F @ B, self.Dinv, self.vol0, self.mesh.tets,
                                  self.mesh.n_nodes)
