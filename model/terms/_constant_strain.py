"""What the calibrated terms written on the deformation gradient F = Ds Dm^-1 of each
tetrahedron share (``normal_sbd``, ``normal_corotated``): Dm^-1 at rest, F of any positions,
and the flattening check their kernels make (det F <= FLAT)."""
import numpy as np
import scipy.sparse as sp

from . import CalibratedTerm
from ._kernels import deformation_gradients_numpy, rest_shape_inverse


class RestShape:
    """What every term written on F shares, calibrated or not (the FEM baselines too): ``Dinv``
    (m, 3, 3) at rest and ``F(x, rows)``; its kernels check flattening."""

    checks_inversion = True

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        self.Dinv = np.ascontiguousarray(rest_shape_inverse(mesh.points, mesh.tets))

    def F(self, x, rows=slice(None)):
        """F (r, 3, 3) of the tetrahedra ``rows`` at positions ``x``."""
        return deformation_gradients_numpy(np.asarray(x, dtype=float), self.mesh.tets[rows],
                                           self.Dinv[rows])

    def assemble_tangent(self, C, vol0):
        """The sparse d f / d x (3n x 3n) of per-tetrahedron forces f = -V0 P G^T from the
        stress tangents ``C`` (m, 3, 3, 3, 3) = dP_ij / dF_kl: K[(a, i), (b, k)] =
        -V0 sum_jl C_ijkl G_aj G_bl, with G (m, 4, 3) the gradients of the four nodes'
        shape functions (dF_kl / dx_bk = G_bl): per tetrahedron -V0 B^T C B with B (9, 12)
        the map from its nodes' 12 displacements to dF, summed into the mesh's pattern."""
        if getattr(self, "_tangent_pattern", None) is None:     # mesh-only work, once
            self._tangent_pattern = _TangentPattern(self.mesh.tets, self.mesh.n_nodes,
                                                    self.Dinv)
        p = self._tangent_pattern
        K = -vol0[:, None, None] * (p.Bt @ C.reshape(len(C), 9, 9) @ p.B)
        return p.matrix(K)


class _TangentPattern:
    """What assembling 12 x 12 element matrices on one mesh needs once: B (m, 9, 12), dF
    (row k*3+l) per nodal displacement (column b*3+k): G_bl; and where each element entry
    goes in the CSR pattern of the sum."""

    def __init__(self, tets, n_nodes, Dinv):
        m = len(tets)
        G = np.concatenate([-Dinv.sum(axis=1)[:, None, :], Dinv], axis=1)    # (m, 4, 3)
        B = np.zeros((m, 3, 3, 4, 3))
        for k in range(3):
            B[:, k, :, :, k] = np.transpose(G, (0, 2, 1))
        self.B = B.reshape(m, 9, 12)
        self.Bt = np.ascontiguousarray(np.transpose(self.B, (0, 2, 1)))
        dof = (3 * tets[:, :, None] + np.arange(3)).reshape(m, 12)
        rows = np.repeat(dof, 12, axis=1).ravel()
        cols = np.tile(dof, (1, 12)).ravel()
        key = rows.astype(np.int64) * (3 * n_nodes) + cols
        uniq, self.slot = np.unique(key, return_inverse=True)
        shape = (3 * n_nodes, 3 * n_nodes)
        self.indices = (uniq % shape[1]).astype(np.int32)
        self.indptr = np.searchsorted(uniq // shape[1], np.arange(shape[0] + 1)).astype(
            np.int32)
        self.shape = shape

    def matrix(self, K):
        """The CSR sum of the element matrices K (m, 12, 12)."""
        data = np.bincount(self.slot, weights=K.ravel(), minlength=len(self.indices))
        return sp.csr_matrix((data, self.indices, self.indptr), shape=self.shape)


class ConstantStrainTerm(RestShape, CalibratedTerm):
    """A CalibratedTerm with ``Dinv`` (m, 3, 3) and ``F(x, rows)``."""
