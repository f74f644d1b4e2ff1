"""A user force term that lives outside the package: a worked example of the Term contract.

Run it with any case, composed with the paper's terms::

    pbcm run paper-cube --quick --term docs/example_term.py \
        --models "shear(reading=variational, c=auto) + normal_axis(c=auto) + volume"

or from Python::

    import model, model.terms
    model.terms.load_file("docs/example_term.py")
    pm = model.build("shear(reading=variational, c=auto) + normal_axis(c=auto) + volume",
                     mesh, material)

The term: the small-strain normal strains along the material axes, less their mean,

    W = c G sum_T V0_T sum_i (eps_ii - tr(eps) / 3)^2,   eps = sym(F) - I,  F = Ds Dm^-1,

with P = dW/dF = 2 c G diag(eps_ii - tr eps / 3). It is linear in x, so it is not invariant
under finite rotations (tests/test_user_terms.py shows it): what ``normal_corotated`` fixes.

What a term provides (``model.terms.Term``): ``name``, ``params`` and ``kernel()``, a numba
function ``fn(x, *args, out)`` that adds the forces into ``out`` and returns -1 (or the index of
a degenerate element); ``forces_numpy`` for the tests; ``energy`` when ``conservative``. With
``c="auto"`` the calibration hooks (``CalibratedTerm``): forces linear in ``coef``; the model
then fits c with the other auto terms so that the deviatoric Kelvin moduli of its relaxed
lattice patch are closest to 2G (``model.calibrate``); ``calibration_residuals(x, rows)`` ->
(r, w), with the energy at c = 1 equal to sum_t w_t sum_k r_tk^2, lets the tests check the
term's closed form. ``fit_constant`` names what
``pbcm fit`` reports.
"""
import numpy as np
from numba import njit

from model.terms import CalibratedTerm, register
from model.terms._kernels import (add_piola_forces, deformation_gradient,
                                  deformation_gradients_numpy, piola_forces_numpy,
                                  rest_shape_inverse)


@njit(cache=False)
def axis_normal_forces(x, tets, Dinv, vol0, kG, out):
    for t in range(tets.shape[0]):
        F, J = deformation_gradient(x, tets, t, Dinv)
        if J <= 0.0:
            return t
        mean = (F[0][0] + F[1][1] + F[2][2] - 3.0) / 3.0
        P = ((2.0 * kG * (F[0][0] - 1.0 - mean), 0.0, 0.0),
             (0.0, 2.0 * kG * (F[1][1] - 1.0 - mean), 0.0),
             (0.0, 0.0, 2.0 * kG * (F[2][2] - 1.0 - mean)))
        add_piola_forces(P, Dinv, vol0, tets, t, out)
    return -1


@register
class NormalAxis(CalibratedTerm):
    """Small-strain deviatoric normal strains along the material axes."""

    name = "normal_axis"
    # linear in x: a finite rotation strains it (the conformance gate checks what it claims)
    rotation_invariant = False
    angular_momentum = False

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        self.Dinv = np.ascontiguousarray(rest_shape_inverse(mesh.points, mesh.tets))

    def kernel_args(self, k):
        return axis_normal_forces, (self.mesh.tets, self.Dinv, self.vol0, k * self.G)

    def _dev_diag(self, x, rows=slice(None)):
        F = deformation_gradients_numpy(np.asarray(x, dtype=float), self.mesh.tets[rows],
                                        self.Dinv[rows])
        e = np.diagonal(F, axis1=1, axis2=2) - 1.0
        return e - e.mean(axis=1, keepdims=True)

    def calibration_residuals(self, x, rows):
        return self._dev_diag(x, rows), self.G * self.vol0[rows]

    def forces_numpy(self, x):
        P = np.zeros((self.mesh.n_tets, 3, 3))
        idx = np.arange(3)
        P[:, idx, idx] = 2 * self.scale * self.coef * self.G * self._dev_diag(x)
        return piola_forces_numpy(P, self.Dinv, self.vol0, self.mesh.tets, self.mesh.n_nodes)
