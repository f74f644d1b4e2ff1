"""A problem's refinement family: its mesh refined uniformly (each tetrahedron into eight)
until one level holds at least ``min_tets`` tetrahedra, with the problem carried to every
level as the FEM references carry it when they refine (``reference.discretisation``): a new
node on a boundary face whose three corners a component holds is held there, at the mean of
its edge's ends; tractions load the new boundary triangles that lie in the loaded ones;
gravity is a body force on any mesh; a reaction is summed over the nodes the selection's own
faces and edges hold (a new node whose parents are all selected)."""
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from model.bc import bc_arrays
from model.loads import boundary_facets
from model.mesh import TetMesh
from reference.discretisation import refine_with_data, skfem_mesh
from .case import SurfaceLoads, on_triangles

MIN_TETS = 100_000       # the family reaches at least this many tetrahedra (the bench's cube)
QUICK_LEVELS = 2         # a quick run's family: the mesh and one refinement
ON_TOL = 1e-9            # of the mesh's size: how far off a loaded triangle a facet may lie


@dataclass
class Level:
    """One mesh of the family: ``level`` refinements of the problem's mesh, its prescribed
    displacements {node: (ux, uy, uz)} [m], its loads and the first reaction measure's
    (nodes, axis) there (None where the problem measures no reaction)."""

    level: int
    mesh: TetMesh
    dirichlet: dict
    loads: SurfaceLoads
    reaction: tuple = None

    @cached_property
    def f_ext(self):
        """Consistent nodal forces (n, 3) [N] of the loads, or None (computed once: every
        law solved and timed on the level reads them)."""
        return self.loads.nodal_forces(self.mesh)


def levels_for(n_tets, min_tets=MIN_TETS, quick=False):
    """How many meshes the family holds: the mesh and its refinements up to the first with
    at least ``min_tets`` tetrahedra (a quick run: the first QUICK_LEVELS of those)."""
    count = 1
    while n_tets * 8 ** (count - 1) < min_tets:
        count += 1
    return min(count, QUICK_LEVELS) if quick else count


def family(spec, quick=False, min_tets=MIN_TETS):
    """[Level] of the checked problem ``spec``, coarsest first."""
    mesh = spec.mesh
    mask, vals = bc_arrays(spec.dirichlet, mesh.n_nodes)
    reaction = next(((m.nodes, m.axis) for m in spec.measures if m.kind == "reaction"), None)
    corners = [(mesh.points[s.faces], s.value) for s in spec.surfaces]
    gravity = None
    if spec.gravity:
        gravity = tuple(-spec.material.rho * spec.gravity * (k == spec.up) for k in range(3))
    m = skfem_mesh(mesh)
    W = None
    out = []
    for level in range(levels_for(mesh.n_tets, min_tets, quick)):
        if level:
            m, mask, vals, step = refine_with_data(m, mask, vals, None, 1)
            W = step if W is None else step @ W
        fine = mesh if not level else TetMesh(m.p.T.copy(), m.t.T.copy())
        out.append(Level(level, fine, _dirichlet(mask, vals),
                         _loads(fine, corners, gravity, ON_TOL * mesh.size),
                         None if reaction is None else (_selected(reaction[0], W,
                                                                  mesh.n_nodes),
                                                        reaction[1])))
    return out


def _dirichlet(mask, vals):
    nodes = np.flatnonzero(mask.any(axis=1))
    return {int(i): tuple(float(vals[i, k]) if mask[i, k] else None for k in range(3))
            for i in nodes}


def _loads(mesh, corners, gravity, tol):
    """The loads on a level: each traction on the boundary triangles whose centroid lies in
    one of the problem's loaded triangles."""
    tri = boundary_facets(mesh.tets)
    centroids = mesh.points[tri].mean(axis=1)
    surfaces = tuple((tri[on_triangles(centroids, c, tol)], value) for c, value in corners)
    return SurfaceLoads(surfaces=surfaces, points=mesh.points, body_force=gravity)


def _selected(nodes, W, n_coarse):
    """The nodes of a level in a selection of the coarse mesh's ``nodes``: those whose hats
    ``W`` (fine x coarse; the identity on the coarse mesh) weigh no node outside it."""
    if W is None:
        return np.asarray(nodes, dtype=np.int64)
    outside = np.ones(n_coarse)
    outside[nodes] = 0.0
    return np.flatnonzero(W @ outside == 0.0).astype(np.int64)
