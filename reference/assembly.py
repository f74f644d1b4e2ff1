"""The linear elastic stiffness of a vector H1 basis, assembled by a numba kernel.

scikit-fem's ``asm(linear_elasticity(lam, mu), basis)`` evaluates the form once per pair of
local basis functions in Python: 900 pairs for a P2 tetrahedron, so the time grows with the
pairs times the elements. This kernel takes the same basis (its quadrature, its gradients, its dof
numbering) and sums the same integrand element by element, so the matrix is scikit-fem's to
rounding (tests/test_reference.py compares them); only the loop moved to compiled code.

For u = phi_i e_a and v = phi_j e_b (a, b the components of local dofs i, j):

    lam div u div v + 2 mu eps(u) : eps(v)
        = lam d_a phi_i d_b phi_j + mu (delta_ab grad phi_i . grad phi_j + d_b phi_i d_a phi_j)
"""
import collections
import hashlib

import numpy as np
import scipy.sparse as sp
from numba import njit


@njit(cache=True)
def _elasticity_values(grad, comp, dx, lam, mu, out):
    """out[e, i, j] = the stiffness entry of local dofs i, j of element e; ``grad`` (nel, nqp,
    nb, 3) the scalar gradient of each local dof at each quadrature point, ``comp`` (nb,) its
    component, ``dx`` (nel, nqp) quadrature weight times |det J|."""
    nel, nqp, nb = grad.shape[0], grad.shape[1], grad.shape[2]
    for e in range(nel):
        for i in range(nb):
            a = comp[i]
            for j in range(i, nb):
                b = comp[j]
                k = 0.0
                for q in range(nqp):
                    gi, gj = grad[e, q, i], grad[e, q, j]
                    s = lam * gi[a] * gj[b] + mu * gi[b] * gj[a]
                    if a == b:
                        s += mu * (gi[0] * gj[0] + gi[1] * gj[1] + gi[2] * gj[2])
                    k += s * dx[e, q]
                out[e, i, j] = k
                out[e, j, i] = k


def scalar_gradients(basis):
    """(grad (nel, nqp, nb, 3), comp (nb,)) of a vector basis: each local dof's gradient is
    nonzero in one row only, the row of its component."""
    grads, comps = [], []
    for field in basis.basis:
        g = field[0].grad                               # (3, 3, nel, nqp)
        c = int(np.argmax(np.abs(g).sum(axis=(1, 2, 3))))
        grads.append(g[c])
        comps.append(c)
    return (np.ascontiguousarray(np.transpose(np.array(grads), (2, 3, 0, 1))),
            np.array(comps, dtype=np.int64))


def elasticity_matrix(basis, lam, mu):
    """The linear elastic stiffness matrix (CSR) of the vector basis ``basis`` with Lame
    constants ``lam``, ``mu``: scikit-fem's ``asm(linear_elasticity(lam, mu), basis)``."""
    grad, comp = scalar_gradients(basis)
    nel, nb = grad.shape[0], grad.shape[2]
    values = np.empty((nel, nb, nb))
    _elasticity_values(grad, comp, np.ascontiguousarray(basis.dx), float(lam), float(mu),
                       values)
    dofs = basis.element_dofs.T                          # (nel, nb)
    rows = np.repeat(dofs, nb, axis=1).ravel()
    cols = np.tile(dofs, (1, nb)).ravel()
    return sp.csr_matrix((values.ravel(), (rows, cols)), shape=(basis.N, basis.N))


# the last few stiffness matrices assembled, by mesh, element and Lame constants: a case solves
# one mesh under several boundary conditions
_STIFFNESS = collections.OrderedDict()
STIFFNESS_CACHE = 4


def stiffness(basis, lam, mu):
    """The linear elastic stiffness matrix (CSR) of ``basis``, reused when the same mesh,
    element and constants were assembled recently (the arrays are compared by content).
    Callers must not modify it."""
    m = basis.mesh
    key = (hashlib.blake2b(np.ascontiguousarray(m.p).tobytes()
                           + np.ascontiguousarray(m.t).tobytes(), digest_size=16).digest(),
           type(basis.elem).__name__, type(basis.elem.elem).__name__, basis.X.shape,
           float(lam), float(mu))
    if key in _STIFFNESS:
        _STIFFNESS.move_to_end(key)
        return _STIFFNESS[key]
    K = elasticity_matrix(basis, lam, mu)
    _STIFFNESS[key] = K
    while len(_STIFFNESS) > STIFFNESS_CACHE:
        _STIFFNESS.popitem(last=False)
    return K


__all__ = ["elasticity_matrix", "scalar_gradients", "stiffness"]
