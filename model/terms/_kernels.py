"""Small numba helpers shared by the per-tetrahedron kernels, inlined into each kernel, and
the tetrahedron's combinatorics.

Conventions: ``d_ab = x_b - x_a`` for the edges of one tetrahedron; ``c_j`` is the doubled
area vector of the face opposite vertex j, oriented as the gradient of 6V with respect to
x_j, so that ``|c_j| = 2 S_j`` and ``sum_j c_j = 0``.
"""
import numpy as np
from numba import njit

# face opposite vertex j as (a, m, l) with c_j = d_am x d_al = d(6V)/dx_j
FACE = np.array([(1, 3, 2), (0, 2, 3), (0, 3, 1), (0, 1, 2)], dtype=np.int64)


# (a, j, m, l) of the 24 shear combinations: corner, tip, in-plane edge end, other base vertex
COMBOS = np.array([(a, j, m, l) for a in range(4) for j in range(4) if j != a
                   for m in range(4) if m not in (a, j)
                   for l in range(4) if l not in (a, j, m)], dtype=np.int64)


# 3-vectors as tuples: numba keeps them in registers, where small arrays would live in memory
@njit(cache=True, inline="always")
def vec(x, n):
    """Row n of x (n, 3) as a tuple."""
    return (x[n, 0], x[n, 1], x[n, 2])


@njit(cache=True, inline="always")
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(cache=True, inline="always")
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True, inline="always")
def axpy(k, a, y):
    """y + k a."""
    return (y[0] + k * a[0], y[1] + k * a[1], y[2] + k * a[2])


@njit(cache=True, inline="always")
def lin(p, a, q, b):
    """p a + q b."""
    return (p * a[0] + q * b[0], p * a[1] + q * b[1], p * a[2] + q * b[2])


@njit(cache=True, inline="always")
def add_to(out, n, f):
    """out[n] += f."""
    out[n, 0] += f[0]
    out[n, 1] += f[1]
    out[n, 2] += f[2]


def volume_gradient_numpy(x, tets):
    """Vectorised signed volumes (m,) and dV/dx (m, 4, 3)."""
    x0, x1, x2, x3 = (x[tets[:, i]] for i in range(4))
    e1, e2, e3 = x1 - x0, x2 - x0, x3 - x0
    g = np.stack([np.zeros_like(e1), np.cross(e2, e3), np.cross(e3, e1), np.cross(e1, e2)], 1) / 6
    g[:, 0] = -g[:, 1:].sum(axis=1)
    return np.einsum("ij,ij->i", e1, g[:, 1]), g


# --- constant-strain tetrahedra (the explicit FEM baselines) ---------------------------------

def rest_shape_inverse(points, tets):
    """Dm^-1 (m, 3, 3) with Dm = [X1 - X0, X2 - X0, X3 - X0] (edges as columns)."""
    X = points[tets]
    Dm = np.stack([X[:, 1] - X[:, 0], X[:, 2] - X[:, 0], X[:, 3] - X[:, 0]], axis=2)
    return np.linalg.inv(Dm)


# 3 x 3 matrices as tuples of rows (F0, F1, F2)
@njit(cache=True, inline="always")
def deformation_gradient(x, tets, t, Dinv):
    """F = Ds Dm^-1 of tetrahedron t as rows, and det F: row i of F is
    sum_c (x_c - x_0)[i] (row c of Dm^-1)."""
    x0 = vec(x, tets[t, 0])
    e1, e2, e3 = sub(vec(x, tets[t, 1]), x0), sub(vec(x, tets[t, 2]), x0), sub(vec(x, tets[t, 3]), x0)
    r0, r1, r2 = vec(Dinv[t], 0), vec(Dinv[t], 1), vec(Dinv[t], 2)
    F = (lin(e1[0], r0, 1.0, lin(e2[0], r1, e3[0], r2)),
         lin(e1[1], r0, 1.0, lin(e2[1], r1, e3[1], r2)),
         lin(e1[2], r0, 1.0, lin(e2[2], r1, e3[2], r2)))
    return F, dot(F[0], cross(F[1], F[2]))


@njit(cache=True, inline="always")
def cofactor(F):
    """cof(F) = det(F) F^-T: row i is the cross product of the two other rows (cyclic)."""
    return cross(F[1], F[2]), cross(F[2], F[0]), cross(F[0], F[1])


@njit(cache=True, inline="always")
def add_piola_forces(P, Dinv, vol0, tets, t, out):
    """Nodal forces of a constant first Piola-Kirchhoff stress P (rows): H = -V0 P Dm^-T, so
    the force on corner c + 1 has components -V0 P_i . (row c of Dm^-1); corner 0 takes minus
    their sum."""
    f0 = (0.0, 0.0, 0.0)
    for c in range(3):
        r = vec(Dinv[t], c)
        f = (-vol0[t] * dot(P[0], r), -vol0[t] * dot(P[1], r), -vol0[t] * dot(P[2], r))
        add_to(out, tets[t, c + 1], f)
        f0 = sub(f0, f)
    add_to(out, tets[t, 0], f0)


def deformation_gradients_numpy(x, tets, Dinv):
    """F (m, 3, 3) for every tetrahedron, vectorised."""
    X = x[tets]
    Ds = np.stack([X[:, 1] - X[:, 0], X[:, 2] - X[:, 0], X[:, 3] - X[:, 0]], axis=2)
    return Ds @ Dinv


def piola_tet_forces(P, Dinv, vol0):
    """The forces (m, 4, 3) of per-tetrahedron stresses P (m, 3, 3) on each tetrahedron's four
    corners: -V0 P Dm^-T gives corners 1..3 as columns, corner 0 takes minus their sum."""
    H = -vol0[:, None, None] * P @ np.transpose(Dinv, (0, 2, 1))   # (m, 3, 3): columns f1..f3
    return np.concatenate([-H.sum(axis=2)[:, None, :], np.transpose(H, (0, 2, 1))], axis=1)


def piola_forces_numpy(P, Dinv, vol0, tets, n_nodes):
    """Nodal forces (n, 3) of per-tetrahedron stresses P (m, 3, 3)."""
    out = np.zeros((n_nodes, 3))
    np.add.at(out, tets, piola_tet_forces(P, Dinv, vol0))
    return out
