"""Small numba helpers shared by the per-tetrahedron kernels. They write into preallocated
arrays so that the element loops allocate nothing."""
import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True, inline="always")
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def gather(x, tets, t, xt):
    """Copy the four corner positions of tetrahedron t into xt (4, 3)."""
    for i in range(4):
        n = tets[t, i]
        xt[i, 0] = x[n, 0]
        xt[i, 1] = x[n, 1]
        xt[i, 2] = x[n, 2]


@njit(cache=True, inline="always")
def volume_gradient(xt, e, g):
    """Signed volume of the tetrahedron xt (4, 3); dV/dx_i into g (4, 3). e is (3, 3) scratch."""
    for k in range(3):
        e[0, k] = xt[1, k] - xt[0, k]
        e[1, k] = xt[2, k] - xt[0, k]
        e[2, k] = xt[3, k] - xt[0, k]
    cross(e[1], e[2], g[1])
    cross(e[2], e[0], g[2])
    cross(e[0], e[1], g[3])
    for k in range(3):
        g[1, k] /= 6.0
        g[2, k] /= 6.0
        g[3, k] /= 6.0
        g[0, k] = -(g[1, k] + g[2, k] + g[3, k])
    return dot(e[0], g[1])


def volume_gradient_numpy(x, tets):
    """Vectorised signed volumes (m,) and dV/dx (m, 4, 3)."""
    x0, x1, x2, x3 = (x[tets[:, i]] for i in range(4))
    e1, e2, e3 = x1 - x0, x2 - x0, x3 - x0
    g = np.stack([np.zeros_like(e1), np.cross(e2, e3), np.cross(e3, e1), np.cross(e1, e2)], 1) / 6
    g[:, 0] = -g[:, 1:].sum(axis=1)
    return np.einsum("ij,ij->i", e1, g[:, 1]), g
