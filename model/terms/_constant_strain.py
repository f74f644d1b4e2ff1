"""What the calibrated terms written on the deformation gradient F = Ds Dm^-1 of each
tetrahedron share (``normal_sbd``, ``normal_corotated``): Dm^-1 at rest, F of any positions,
and the flattening check their kernels make (det F <= FLAT)."""
import numpy as np

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


class ConstantStrainTerm(RestShape, CalibratedTerm):
    """A CalibratedTerm with ``Dinv`` (m, 3, 3) and ``F(x, rows)``."""
