"""Tetrahedron geometry shared by the mesh, the force terms and the integrators."""
import numpy as np
from numba import njit


def signed_volumes(points, tets):
    """Signed volume of each tetrahedron, positive for a right-handed (v0, v1, v2, v3)."""
    x0, x1, x2, x3 = (points[tets[:, i]] for i in range(4))
    return np.einsum("ij,ij->i", x1 - x0, np.cross(x2 - x0, x3 - x0)) / 6.0


@njit(cache=True)
def min_signed_volume(x, tets):
    """Smallest signed volume and the tetrahedron holding it (a cheap inversion watch)."""
    vmin = np.inf
    imin = -1
    for t in range(tets.shape[0]):   # scalars only: no array per tetrahedron
        a, b, c, d = tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3]
        e10, e11, e12 = x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2]
        e20, e21, e22 = x[c, 0] - x[a, 0], x[c, 1] - x[a, 1], x[c, 2] - x[a, 2]
        e30, e31, e32 = x[d, 0] - x[a, 0], x[d, 1] - x[a, 1], x[d, 2] - x[a, 2]
        v = (e10 * (e21 * e32 - e22 * e31)
             - e11 * (e20 * e32 - e22 * e30)
             + e12 * (e20 * e31 - e21 * e30)) / 6.0
        if v < vmin:
            vmin = v
            imin = t
    return vmin, imin


def edges(tets):
    """Unique undirected edges (k, 2), sorted, of a tetrahedral mesh."""
    pairs = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)])
    e = np.sort(tets[:, pairs].reshape(-1, 2), axis=1)
    return np.unique(e, axis=0)


def smallest_heights(points, tets):
    """Smallest of the four heights h = 3 V / S of each tetrahedron."""
    vol = np.abs(signed_volumes(points, tets))
    faces = [(1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2)]
    areas = np.stack([
        0.5 * np.linalg.norm(np.cross(points[tets[:, b]] - points[tets[:, a]],
                                      points[tets[:, c]] - points[tets[:, a]]), axis=1)
        for a, b, c in faces], axis=1)
    return 3.0 * vol / areas.max(axis=1)


def radius_ratio(points, tets):
    """Normalised radius ratio 3 r_in / r_circ: 1 for a regular tetrahedron, 0 for a sliver."""
    x0, x1, x2, x3 = (points[tets[:, i]] for i in range(4))
    vol = np.abs(signed_volumes(points, tets))
    area = sum(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
               for a, b, c in ((x1, x2, x3), (x0, x2, x3), (x0, x1, x3), (x0, x1, x2)))
    r_in = 3.0 * vol / area
    # circumradius from the products of opposite edge lengths (Crelle's formula)
    a = np.linalg.norm(x1 - x0, axis=1) * np.linalg.norm(x3 - x2, axis=1)
    b = np.linalg.norm(x2 - x0, axis=1) * np.linalg.norm(x3 - x1, axis=1)
    c = np.linalg.norm(x3 - x0, axis=1) * np.linalg.norm(x2 - x1, axis=1)
    s = (a + b + c) / 2.0
    r_circ = np.sqrt(np.maximum(s * (s - a) * (s - b) * (s - c), 0.0)) / (6.0 * vol)
    return 3.0 * r_in / r_circ


def dihedral_angles(points, tets):
    """The six dihedral angles (m, 6) of each tetrahedron, in degrees."""
    x = points[tets]
    # outward normals of the face opposite each vertex
    n = np.empty((len(tets), 4, 3))
    for i, (a, b, c) in enumerate(((1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2))):
        ni = np.cross(x[:, b] - x[:, a], x[:, c] - x[:, a])
        ni *= np.sign(np.einsum("ij,ij->i", ni, x[:, a] - x[:, i]))[:, None]
        n[:, i] = ni / np.linalg.norm(ni, axis=1)[:, None]
    pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    cos = np.stack([-np.einsum("ij,ij->i", n[:, i], n[:, j]) for i, j in pairs], axis=1)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def displacement_gradients(points, tets, u):
    """The constant displacement gradient du_i / dx_k (m, 3, 3) of the linear interpolation of
    the nodal ``u`` (n, 3) over each tetrahedron: with the edge matrices D = x_a - x_0 and
    dU = u_a - u_0 (a = 1..3), dU = D (grad u)^T."""
    x = np.asarray(points, float)[tets]
    d = np.asarray(u, float)[tets]
    D = x[:, 1:] - x[:, :1]
    dU = d[:, 1:] - d[:, :1]
    return np.swapaxes(np.linalg.solve(D, dU), 1, 2)
