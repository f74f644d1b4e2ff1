"""The discretisation shared by the FEM references: the scikit-fem mesh of a TetMesh, refinement
that carries the Dirichlet data along, the element's basis, the Dirichlet dofs, the input mesh's
hats at every dof, which input tetrahedron holds each refined one, and a field read at points.

The mesh and the boundary-condition format come from ``model``, nothing else does.
"""
import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementTetP1, ElementTetP2, ElementVector, MeshTet

from model.errors import ModelError
from .solvers import check_finite

ELEMENTS = {"P1": ElementTetP1, "P2": ElementTetP2}
INTORDER = {"P1": 1, "P2": 2}  # exact for the stiffness, and for a constant body force


def skfem_mesh(mesh):
    return MeshTet(np.ascontiguousarray(mesh.points.T), np.ascontiguousarray(mesh.tets.T))


class Region:
    """A prescribed displacement declared by geometry: ``fn(points (k, 3)) -> (k, 3)``, NaN
    where a component is free. Given as ``dirichlet_fn``, it decides every new boundary point
    of a refinement or a P2 midpoint by where it lies, whatever its facet's vertices: a
    punch declared this way is the same patch on every mesh, resolved ever finer as the
    reference refines (a plain ``dirichlet_fn`` only fills in facets whose vertices are all
    prescribed, so a patch would be the mesh's polygon of prescribed nodes)."""

    def __init__(self, fn):
        self.fn = fn

    def __call__(self, points):
        return self.fn(points)


def prescribed_edges(m, mask, vals, dirichlet_fn):
    """Which edges' new points (refined vertices, P2 midpoints) are prescribed, and to what.

    An edge is prescribed in component k when it lies on a boundary facet whose three vertices
    are all prescribed in k: a free face stays free even where two of its vertices are held.
    The value is ``dirichlet_fn(midpoint)`` when given (NaN there leaves the component free:
    how a caller keeps free a face that lies between two prescribed surfaces, e.g. the sides
    of a body one element thick), else the mean of the edge's two ends. A :class:`Region`
    decides every boundary edge by its midpoint alone.
    Returns (n_edges, 3) mask and values.
    """
    bf = m.boundary_facets()
    e = m.edges
    edge_mask = np.zeros((m.edges.shape[1], 3), dtype=bool)
    if isinstance(dirichlet_fn, Region):
        on = np.unique(m.f2e[:, bf].ravel())                  # every boundary edge
        given = _given(dirichlet_fn, 0.5 * (m.p[:, e[0, on]] + m.p[:, e[1, on]]).T)
        edge_mask[on] = ~np.isnan(given)
        edge_vals = np.zeros((m.edges.shape[1], 3))
        edge_vals[on] = np.where(edge_mask[on], given, 0.0)
        return edge_mask, edge_vals
    full = mask[m.facets[:, bf]].all(axis=0)                 # (n boundary facets, 3)
    for k in range(3):
        edge_mask[m.f2e[:, bf[full[:, k]]].ravel(), k] = True
    edge_vals = np.where(edge_mask, 0.5 * (vals[e[0]] + vals[e[1]]), 0.0)
    cand = np.flatnonzero(edge_mask.any(axis=1))
    if dirichlet_fn is not None and cand.size:
        given = _given(dirichlet_fn, 0.5 * (m.p[:, e[0, cand]] + m.p[:, e[1, cand]]).T)
        edge_mask[cand] &= ~np.isnan(given)
        edge_vals[cand] = np.where(edge_mask[cand], given, 0.0)
    return edge_mask, edge_vals


def _given(dirichlet_fn, points):
    given = np.asarray(dirichlet_fn(points), dtype=float)
    if given.shape != points.shape:
        raise ModelError(f"dirichlet_fn must return a {points.shape} array for "
                         f"{points.shape} points, got shape {given.shape}")
    return given


SNAP_BITS = 20      # the refinement's diagonal choice is taken on coordinates in 2^-20 of the size


def refined(m):
    """``m`` refined once (each tetrahedron into 8, the middle octahedron cut along its
    shortest diagonal), the diagonals chosen on the coordinates snapped to a 2^-SNAP_BITS grid
    of the mesh's size: a lattice's equal diagonals then tie exactly and are split alike on
    every processor and under any perturbation far below the grid, where the float lengths
    would let round-off pick (and move the reference at its discretisation error). The new
    points are the exact midpoints of the given coordinates."""
    size = float(np.ptp(m.p, axis=1).max()) or 1.0
    q = size * 2.0 ** -SNAP_BITS
    lo = m.p.min(axis=1, keepdims=True)
    snapped = type(m)(np.round((m.p - lo) / q), m.t).refined()
    p = np.hstack((m.p, m.p[:, m.edges].mean(axis=1)))
    return type(m)(p, snapped.t)


def refine_with_data(m, mask, vals, dirichlet_fn, levels):
    """Refine ``levels`` times, carrying the Dirichlet data to the new vertices (see
    :func:`prescribed_edges`).

    Also returns W (sparse, fine nodes x input nodes): the input mesh's P1 hat functions at
    every fine node, built as the mean of the two parents' rows (hats are linear on edges).
    """
    W = sp.identity(m.nvertices, format="csr")
    for _ in range(levels):
        nm, nv = prescribed_edges(m, mask, vals, dirichlet_fn)
        n_old = m.nvertices
        W = sp.vstack([W, 0.5 * (W[m.edges[0]] + W[m.edges[1]])], format="csr")
        m = refined(m)
        assert m.nvertices == n_old + len(nm)  # new vertices are the old edges' midpoints
        mask, vals = np.vstack([mask, nm]), np.vstack([vals, nv])
    return m, mask, vals, W


def dof_hats(basis, W):
    """Sparse (N dofs x input nodes): the input mesh's P1 hats at every dof's location
    (vertex dofs take their node's row of W, P2 edge dofs the mean of their ends' rows)."""
    H = W
    dofs = [basis.nodal_dofs]
    if basis.edge_dofs.size:
        e = basis.mesh.edges
        H = sp.vstack([W, 0.5 * (W[e[0]] + W[e[1]])], format="csr")
        dofs.append(basis.edge_dofs)
    dof_index = np.concatenate([np.concatenate([d[k] for d in dofs]) for k in range(3)])
    place = sp.csr_matrix((np.ones(len(dof_index)), (dof_index, np.arange(len(dof_index)))),
                          shape=(basis.N, len(dof_index)))
    return place @ sp.vstack([H, H, H], format="csr")


def element_basis(m, element, intorder=None):
    if element not in ELEMENTS:
        raise ModelError(f"element must be one of {', '.join(ELEMENTS)}, got {element!r}")
    return Basis(m, ElementVector(ELEMENTS[element]()), intorder=intorder or INTORDER[element])


def dirichlet_dofs(basis, mask, vals, dirichlet_fn):
    """Prescribed dof indices and the full vector of their values. For P2 the midpoint dofs
    follow :func:`prescribed_edges`."""
    D = [basis.nodal_dofs.T[mask]]
    x = np.zeros(basis.N)
    x[basis.nodal_dofs.T[mask]] = vals[mask]
    if basis.edge_dofs.size:
        em, ev = prescribed_edges(basis.mesh, mask, vals, dirichlet_fn)
        dofs = basis.edge_dofs.T
        D.append(dofs[em])
        x[dofs[em]] = ev[em]
    return np.concatenate(D), x


def parent_of(m_fine, W, coarse_tets):
    """Index of the input tetrahedron containing each fine one: the input nodes whose hats do
    not vanish on a fine tetrahedron are exactly its parent's four vertices."""
    if m_fine.nelements == len(coarse_tets):
        return np.arange(len(coarse_tets))
    S = (W[m_fine.t[0]] + W[m_fine.t[1]] + W[m_fine.t[2]] + W[m_fine.t[3]]).tocsr()
    S.sort_indices()
    if not np.all(np.diff(S.indptr) == 4):
        raise AssertionError("a refined tetrahedron straddles two input tetrahedra")
    def key(t):  # one opaque, consistently ordered scalar per row of four node indices
        return np.ascontiguousarray(t, dtype=np.int64).view(np.dtype((np.void, 32))).ravel()

    fine_key = key(S.indices.reshape(-1, 4))
    coarse_key = key(np.sort(coarse_tets, axis=1))
    order = np.argsort(coarse_key)
    return order[np.searchsorted(coarse_key[order], fine_key)]


INSIDE = 1e-12     # how far inside its tetrahedron a point on a face is moved to be probed
PROBE_CHUNK = 256  # points probed at once (scikit-fem searches every element for a batch it
                   # cannot place: the chunk bounds that search's memory)


def probe(basis, dofs, points):
    """The vector field ``dofs`` of ``basis`` at arbitrary ``points`` (k, 3) inside the mesh:
    its basis functions evaluated there (k, 3), not nodal values interpolated. scikit-fem
    places a point in a tetrahedron to machine epsilon, so that a point on a face can fall
    outside every tetrahedron by round-off; in a chunk of points where that happens, the
    points within INSIDE of a face are moved INSIDE into the tetrahedron that holds them
    (``TetMesh.locate``; barycentric coordinates, a move far below the field's round-off),
    the other chunks probed as given."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    values = np.empty((len(pts), 3))
    mesh = None             # the TetMesh that places points, made at the first chunk needing it
    for lo in range(0, len(pts), PROBE_CHUNK):
        chunk = pts[lo:lo + PROBE_CHUNK]
        try:
            matrix = basis.probes(np.ascontiguousarray(chunk.T))
        except ValueError:
            if mesh is None:
                from model.mesh import TetMesh
                mesh = TetMesh(basis.mesh.p.T, basis.mesh.t.T)
            matrix = basis.probes(np.ascontiguousarray(_inside(mesh, chunk).T))
        values[lo:lo + PROBE_CHUNK] = (matrix @ dofs).reshape(3, len(chunk)).T
    return check_finite("displacement at the probed points", values)


def _inside(mesh, points):
    """``points`` moved into the tetrahedra of the TetMesh ``mesh`` that hold them (a
    MeshError for a point outside the mesh beyond round-off)."""
    tets, bary = mesh.locate(points)
    near = bary.min(axis=1) < INSIDE
    bary = np.maximum(bary, INSIDE)
    bary /= bary.sum(axis=1, keepdims=True)
    moved = np.einsum("kj,kjd->kd", bary, mesh.points[mesh.tets[tets]])
    return np.where(near[:, None], moved, points)
