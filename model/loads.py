"""Loads as consistent nodal forces of P1 shape functions: what the particle model receives
for a traction on a face or a body force (the FEM references integrate the same loads)."""
import numpy as np

from .errors import ModelError

FACES = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])


def boundary_facets(tets):
    """The boundary triangles (k, 3) of a tetrahedral mesh (faces that belong to one
    tetrahedron only)."""
    f = tets[:, FACES].reshape(-1, 3)
    _, inv, counts = np.unique(np.sort(f, axis=1), axis=0, return_inverse=True,
                               return_counts=True)
    return f[counts[inv.ravel()] == 1]


def traction_forces(mesh, axis, at, value, tol=None):
    """Nodal forces (n, 3) [N] of a uniform traction ``value`` (3,) [Pa] on the boundary
    facets in the plane x_axis = ``at``: each triangle gives a third of traction x area to
    each of its vertices (exact for P1 shape functions)."""
    tol = 1e-9 * mesh.size if tol is None else tol
    tri = boundary_facets(mesh.tets)
    on = (np.abs(mesh.points[tri, axis] - at) <= tol).all(axis=1)
    if not on.any():
        raise ModelError(f"no boundary face in the plane {'xyz'[axis]} = {at!r} m to carry a "
                         "traction; check the plane against the mesh's bounding box")
    p = mesh.points[tri[on]]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    f = np.zeros_like(mesh.points)
    np.add.at(f, tri[on].ravel(), np.repeat(area / 3, 3)[:, None] * np.asarray(value, float))
    return f


def body_forces(mesh, b):
    """Nodal forces (n, 3) [N] of a constant body force ``b`` (3,) [N/m^3]: a quarter of
    b V0 to each vertex of every tetrahedron."""
    f = np.zeros_like(mesh.points)
    np.add.at(f, mesh.tets.ravel(), np.repeat(mesh.volumes / 4, 4)[:, None]
              * np.asarray(b, float))
    return f
