"""Small numba helpers shared by the per-tetrahedron kernels, inlined into each kernel. They
write into preallocated arrays so that the element loops allocate nothing.

Conventions: ``d[a, b] = x_b - x_a`` (4, 4, 3) for the edges of one tetrahedron; ``c[j]``
(4, 3) is the doubled area vector of the face opposite vertex j, oriented as the gradient of
6V with respect to x_j, so that ``|c[j]| = 2 S_j`` and ``sum_j c[j] = 0``.
"""
import numpy as np
from numba import njit

# face opposite vertex j as (a, m, l) with c[j] = d[a, m] x d[a, l] = d(6V)/dx_j
FACE = np.array([(1, 3, 2), (0, 2, 3), (0, 3, 1), (0, 1, 2)], dtype=np.int64)


@njit(cache=True, inline="always")
def cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True, inline="always")
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def edges(x, tets, t, d):
    """d[a, b] = x_b - x_a for the corners of tetrahedron t; returns 6V, the signed volume
    times six (positive for a right-handed tetrahedron)."""
    for a in range(4):
        na = tets[t, a]
        for b in range(a + 1, 4):
            nb = tets[t, b]
            for k in range(3):
                e = x[nb, k] - x[na, k]
                d[a, b, k] = e
                d[b, a, k] = -e
    return (d[0, 1, 0] * (d[0, 2, 1] * d[0, 3, 2] - d[0, 2, 2] * d[0, 3, 1])
            + d[0, 1, 1] * (d[0, 2, 2] * d[0, 3, 0] - d[0, 2, 0] * d[0, 3, 2])
            + d[0, 1, 2] * (d[0, 2, 0] * d[0, 3, 1] - d[0, 2, 1] * d[0, 3, 0]))


@njit(cache=True, inline="always")
def face_vectors(d, c, cn):
    """c[j] = d(6V)/dx_j, the doubled area vector of the face opposite j, and cn[j] = |c[j]|."""
    for j in range(4):
        cross(d[FACE[j, 0], FACE[j, 1]], d[FACE[j, 0], FACE[j, 2]], c[j])
        cn[j] = np.sqrt(dot(c[j], c[j]))


@njit(cache=True, inline="always")
def inverse_lengths(d, iL):
    """iL[a, b] = 1 / |x_b - x_a| (symmetric; reciprocals so that the strain loops multiply)."""
    for a in range(4):
        iL[a, a] = 0.0
        for b in range(a + 1, 4):
            iL[a, b] = iL[b, a] = 1.0 / np.sqrt(dot(d[a, b], d[a, b]))


@njit(cache=True, inline="always")
def tet_frame(x, tets, t, d, c, cn, iL):
    """Everything the shear kernels take of tetrahedron t once: edges d, face vectors c with
    norms cn, reciprocal lengths iL; returns 6V."""
    V6 = edges(x, tets, t, d)
    face_vectors(d, c, cn)
    inverse_lengths(d, iL)
    return V6


@njit(cache=True, inline="always")
def apply_laplacian(M, d, ft):
    """ft[i] += sum_k M[i, k] x_k for a coefficient matrix whose rows sum to zero, computed
    from the edges d[0, k] so that no absolute position enters (no cancellation)."""
    for i in range(4):
        for k in range(3):
            ft[i, k] += M[i, 1] * d[0, 1, k] + M[i, 2] * d[0, 2, k] + M[i, 3] * d[0, 3, k]


@njit(cache=True, inline="always")
def scatter(tets, t, ft, out):
    """out[node of corner i] += ft[i]."""
    for i in range(4):
        n = tets[t, i]
        out[n, 0] += ft[i, 0]
        out[n, 1] += ft[i, 1]
        out[n, 2] += ft[i, 2]


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


@njit(cache=True, inline="always")
def deformation_gradient(x, tets, t, Dinv, F):
    """F = Ds Dm^-1 of tetrahedron t into F (3, 3); returns det F."""
    n0 = tets[t, 0]
    for i in range(3):
        e1 = x[tets[t, 1], i] - x[n0, i]
        e2 = x[tets[t, 2], i] - x[n0, i]
        e3 = x[tets[t, 3], i] - x[n0, i]
        for j in range(3):
            F[i, j] = e1 * Dinv[t, 0, j] + e2 * Dinv[t, 1, j] + e3 * Dinv[t, 2, j]
    return (F[0, 0] * (F[1, 1] * F[2, 2] - F[1, 2] * F[2, 1])
            - F[0, 1] * (F[1, 0] * F[2, 2] - F[1, 2] * F[2, 0])
            + F[0, 2] * (F[1, 0] * F[2, 1] - F[1, 1] * F[2, 0]))


@njit(cache=True, inline="always")
def add_piola_forces(P, Dinv, vol0, tets, t, out):
    """Nodal forces of a constant first Piola-Kirchhoff stress P: H = -V0 P Dm^-T gives the
    forces on corners 1..3 as its columns, corner 0 takes minus their sum."""
    n0 = tets[t, 0]
    for i in range(3):
        f0 = 0.0
        for c in range(3):
            h = -vol0[t] * (P[i, 0] * Dinv[t, c, 0] + P[i, 1] * Dinv[t, c, 1]
                            + P[i, 2] * Dinv[t, c, 2])
            out[tets[t, c + 1], i] += h
            f0 -= h
        out[n0, i] += f0


def deformation_gradients_numpy(x, tets, Dinv):
    """F (m, 3, 3) for every tetrahedron, vectorised."""
    X = x[tets]
    Ds = np.stack([X[:, 1] - X[:, 0], X[:, 2] - X[:, 0], X[:, 3] - X[:, 0]], axis=2)
    return Ds @ Dinv


def piola_forces_numpy(P, Dinv, vol0, tets, n_nodes):
    """Nodal forces (n, 3) of per-tetrahedron stresses P (m, 3, 3)."""
    H = -vol0[:, None, None] * P @ np.transpose(Dinv, (0, 2, 1))   # (m, 3, 3): columns f1..f3
    f = np.concatenate([-H.sum(axis=2)[:, None, :], np.transpose(H, (0, 2, 1))], axis=1)
    out = np.zeros((n_nodes, 3))
    np.add.at(out, tets, f)
    return out
