"""Tetrahedral meshes: a validated data class, structured generators, and file I/O via meshio.

SI units (metres) throughout; convert millimetres at the edge.
"""
from dataclasses import dataclass, field
import itertools

import numpy as np
from scipy.spatial import Delaunay, cKDTree

from .errors import MeshError
from .geometry import dihedral_angles, edges as unique_edges, radius_ratio, signed_volumes

# relative to the bounding-box diagonal
DUPLICATE_TOL = 1e-9
# relative to the mean |V|: below this a tetrahedron is degenerate
DEGENERATE_VOLUME_TOL = 1e-10
# below this radius ratio (1 regular, 0 flat) a tetrahedron is a sliver: its stiffness
# dominates a calibration and its stable step
SLIVER_RADIUS_RATIO = 0.05
# dihedral angles outside this range make a tetrahedron flat or needle-like even where its
# radius ratio passes (a cap or a wedge): they cut the explicit stable step too
DIHEDRAL_RANGE_DEG = (3.0, 175.0)


def _first(ids, k=10):
    ids = list(map(int, ids))
    return ", ".join(map(str, ids[:k])) + (f" ... ({len(ids)} in all)" if len(ids) > k else "")


def folded_tets(points, tets):
    """The positively oriented tetrahedra that lie on the same side of a face they share with
    a neighbour (a fold), or that share a face with more than one other (not a manifold):
    sorted indices, empty for a valid mesh."""
    m = len(tets)
    local = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
    faces = np.sort(tets[:, local].reshape(-1, 3), axis=1)
    opposite = tets.reshape(-1)                     # the vertex opposite face k of tet t
    owner = np.repeat(np.arange(m), 4)
    order = np.lexsort(faces.T[::-1])
    f = faces[order]
    same = np.all(f[1:] == f[:-1], axis=1)
    bad = set()
    triple = same[1:] & same[:-1]                   # three tets on one face
    bad.update(owner[order[1:-1][triple]].tolist())
    i = order[:-1][same]
    j = order[1:][same]
    p = points
    a, b, c = (p[faces[i, k]] for k in range(3))
    normal = np.cross(b - a, c - a)
    side_i = np.einsum("ij,ij->i", p[opposite[i]] - a, normal)
    side_j = np.einsum("ij,ij->i", p[opposite[j]] - a, normal)
    fold = side_i * side_j > 0
    bad.update(owner[i[fold]].tolist())
    bad.update(owner[j[fold]].tolist())
    return np.array(sorted(bad), dtype=np.int64)


@dataclass
class TetMesh:
    """A validated tetrahedral mesh.

    Parameters
    ----------
    points : (n, 3) float64 array of node coordinates [m].
    tets : (m, 4) int array of node indices. Negatively oriented tetrahedra are re-oriented
        (v1 and v2 swapped); the count is kept in ``reoriented``.
    lattice : for a generated box, ``(scheme, seed, (hx, hy, hz))``: the lattice it repeats
        (what a calibration patch of the same lattice is built from); None otherwise.
    """

    points: np.ndarray
    tets: np.ndarray
    lattice: tuple = field(default=None, compare=False)
    reoriented: int = field(default=0, init=False)
    _edges: tuple = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        pts = np.asarray(self.points)
        if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) == 0:
            raise MeshError(f"points must be an (n, 3) array, got shape {pts.shape}")
        if not np.issubdtype(pts.dtype, np.number):
            raise MeshError(f"points must be numeric, got dtype {pts.dtype}")
        pts = np.ascontiguousarray(pts, dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(pts).all(axis=1))
        if bad.size:
            raise MeshError(f"non-finite (NaN or inf) coordinates at nodes {_first(bad)}")
        tets = np.asarray(self.tets)
        if tets.ndim != 2 or tets.shape[1] != 4 or len(tets) == 0:
            raise MeshError(f"tets must be an (m, 4) array of node indices, got shape {tets.shape}")
        if not np.issubdtype(tets.dtype, np.integer):
            if np.issubdtype(tets.dtype, np.floating) and np.all(tets == np.round(tets)):
                tets = tets.astype(np.int64)
            else:
                raise MeshError(f"tets must hold integer node indices, got dtype {tets.dtype}")
        tets = np.ascontiguousarray(tets, dtype=np.int64)
        out = np.flatnonzero(((tets < 0) | (tets >= len(pts))).any(axis=1))
        if out.size:
            raise MeshError(f"tetrahedra {_first(out)} reference node indices outside "
                            f"0..{len(pts) - 1}")
        srt = np.sort(tets, axis=1)
        rep = np.flatnonzero((np.diff(srt, axis=1) == 0).any(axis=1))
        if rep.size:
            raise MeshError(f"tetrahedra {_first(rep)} repeat a node (degenerate)")
        _, first, counts = np.unique(srt, axis=0, return_index=True, return_counts=True)
        if (counts > 1).any():
            raise MeshError(f"tetrahedra {_first(first[counts > 1])} appear more than once")
        unref = np.setdiff1d(np.arange(len(pts)), tets.ravel())
        if unref.size:
            raise MeshError(f"nodes {_first(unref)} belong to no tetrahedron: remove them "
                            "(model.mesh.read drops them for you)")
        diag = np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))
        pairs = cKDTree(pts).query_pairs(DUPLICATE_TOL * diag, output_type="ndarray")
        if len(pairs):
            raise MeshError(f"duplicate nodes (coincident within {DUPLICATE_TOL:g} of the size): "
                            + ", ".join(f"{a}={b}" for a, b in pairs[:10]))
        vol = signed_volumes(pts, tets)
        deg = np.flatnonzero(np.abs(vol) <= DEGENERATE_VOLUME_TOL * np.abs(vol).mean())
        if deg.size:
            raise MeshError(f"tetrahedra {_first(deg)} have zero volume (degenerate); "
                            "remove or re-mesh them")
        neg = vol < 0
        if neg.any():
            tets[neg] = tets[neg][:, [0, 2, 1, 3]]
        folded = folded_tets(pts, tets)
        if folded.size:
            raise MeshError(f"tetrahedra {_first(folded)} overlap a neighbour across a shared "
                            "face (the mesh is folded: a node pushed through a face); "
                            "re-orienting them would hide it: fix or re-mesh them")
        self.points, self.tets, self.reoriented = pts, tets, int(neg.sum())
        self.points.flags.writeable = False
        self.tets.flags.writeable = False

    @property
    def n_nodes(self):
        return len(self.points)

    @property
    def n_tets(self):
        return len(self.tets)

    @property
    def volumes(self):
        """Rest volume of each tetrahedron (positive)."""
        return signed_volumes(self.points, self.tets)

    @property
    def edges(self):
        """Unique undirected edges (k, 2), read-only; sorted once per ``tets`` array (the
        studies ask for them again and again)."""
        if self._edges is None or self._edges[0] is not self.tets:
            e = unique_edges(self.tets)
            e.flags.writeable = False
            self._edges = (self.tets, e)
        return self._edges[1]

    @property
    def mean_edge(self):
        """The mean length of the edges at rest [m]: the mesh size h the solvers scale by."""
        d = self.points[self.edges[:, 1]] - self.points[self.edges[:, 0]]
        return float(np.linalg.norm(d, axis=1).mean())

    @property
    def size(self):
        """Diagonal of the bounding box."""
        return float(np.linalg.norm(self.points.max(axis=0) - self.points.min(axis=0)))

    def slivers(self):
        """The tetrahedra whose radius ratio is below ``SLIVER_RADIUS_RATIO``, sorted."""
        return np.flatnonzero(radius_ratio(self.points, self.tets) < SLIVER_RADIUS_RATIO)

    def warnings(self, k=5):
        """What a run on this mesh should be told before computing: slivers (radius ratio below
        SLIVER_RADIUS_RATIO) and tetrahedra with a dihedral angle outside DIHEDRAL_RANGE_DEG,
        each with its worst ``k`` ids and values, and the tetrahedra read inverted (re-oriented);
        [] for a sound mesh."""
        out = []
        rr = radius_ratio(self.points, self.tets)
        thin = np.flatnonzero(rr < SLIVER_RADIUS_RATIO)
        if thin.size:
            worst = thin[np.argsort(rr[thin])][:k]
            out.append(f"{thin.size} sliver(s) (radius ratio below {SLIVER_RADIUS_RATIO:g}), "
                       "the worst: " + ", ".join(f"tetrahedron {i} ({rr[i]:.3g})"
                                                for i in worst)
                       + "; a calibrated model (c = auto) refuses them and they cut the "
                       "explicit stable step: re-mesh them")
        dih = dihedral_angles(self.points, self.tets)
        lo, hi = DIHEDRAL_RANGE_DEG
        off = np.maximum(lo - dih.min(axis=1), dih.max(axis=1) - hi)
        bad = np.flatnonzero(off > 0)
        if bad.size:
            worst = bad[np.argsort(-off[bad])][:k]
            out.append(f"{bad.size} tetrahedra with a dihedral angle outside {lo:g}-{hi:g} "
                       "deg, the worst: " + ", ".join(
                           f"tetrahedron {i} ({dih[i].min():.3g}-{dih[i].max():.3g} deg)"
                           for i in worst))
        if self.reoriented:
            out.append(f"{self.reoriented} tetrahedra were read with a negative orientation and "
                       "re-oriented: check the exporter's node order")
        return out

    def quality(self):
        """Quality summary: volume, radius ratio (1 regular, 0 sliver), dihedral angles."""
        rr = radius_ratio(self.points, self.tets)
        dih = dihedral_angles(self.points, self.tets)
        return {"nodes": self.n_nodes, "tets": self.n_tets, "volume": float(self.volumes.sum()),
                "radius_ratio_min": float(rr.min()), "radius_ratio_mean": float(rr.mean()),
                "dihedral_min_deg": float(dih.min()), "dihedral_max_deg": float(dih.max())}

    def nodes_where(self, predicate):
        """Indices of the nodes whose coordinates satisfy ``predicate(points) -> bool array``."""
        mask = np.asarray(predicate(self.points), dtype=bool)
        if mask.shape != (self.n_nodes,):
            raise MeshError(f"node predicate must return {self.n_nodes} booleans, got shape "
                            f"{mask.shape}")
        return np.flatnonzero(mask)

    def nodes_on_plane(self, axis, value, tol=None):
        """Nodes with coordinate ``axis`` (0, 1, 2 or 'x', 'y', 'z') within ``tol`` of ``value``.

        ``tol`` defaults to 1e-6 of the bounding-box diagonal.
        """
        ax = {"x": 0, "y": 1, "z": 2}.get(axis, axis)
        if ax not in (0, 1, 2):
            raise MeshError(f"axis must be 0, 1, 2 or 'x', 'y', 'z', got {axis!r}")
        tol = 1e-6 * self.size if tol is None else tol
        return self.nodes_where(lambda p: np.abs(p[:, ax] - value) <= tol)

    def locate(self, points, candidates=32):
        """``(tets, bary)``: for each of ``points`` (k, 3) [m] at rest, the tetrahedron that
        holds it and its barycentric coordinates (k, 4) there, so that a nodal field u is
        ``(bary[:, :, None] * u[tets_nodes]).sum(1)``: P1 interpolation (see
        :meth:`interpolate`). The ``candidates`` tetrahedra with the nearest centroids are
        tried; a point in none of them is outside the mesh, an error."""
        pts = np.asarray(points, float).reshape(-1, 3)
        centroids = self.points[self.tets].mean(axis=1)
        _, near = cKDTree(centroids).query(pts, k=min(candidates, self.n_tets))
        near = near.reshape(len(pts), -1)
        corners = self.points[self.tets[near]]                   # (k, c, 4, 3)
        # solve [x1-x0, x2-x0, x3-x0] l = p - x0 for every candidate
        A = np.swapaxes(corners[:, :, 1:] - corners[:, :, :1], -1, -2)
        lam = np.linalg.solve(A, (pts[:, None, :] - corners[:, :, 0])[..., None])[..., 0]
        bary = np.concatenate([1 - lam.sum(-1, keepdims=True), lam], axis=-1)
        worst = bary.min(axis=-1)                                # >= 0 inside
        pick = worst.argmax(axis=1)
        rows = np.arange(len(pts))
        outside = np.flatnonzero(worst[rows, pick] < -1e-9)
        if outside.size:
            raise MeshError(f"points {_first(outside)} are outside the mesh (first at "
                            f"{pts[outside[0]].tolist()} m); give points inside it at rest")
        return near[rows, pick], bary[rows, pick]

    def interpolate(self, u, located):
        """The nodal field ``u`` (n, d) at the points ``located`` = :meth:`locate`'s answer,
        by the P1 basis of the holding tetrahedron."""
        tets, bary = located
        return np.einsum("kj,kjd->kd", bary, np.asarray(u)[self.tets[tets]])


# ---------------------------------------------------------------- structured generators

# corners of the unit cell, index = i + 2 j + 4 k
_CORNERS = np.array([(i, j, k) for k in (0, 1) for j in (0, 1) for i in (0, 1)])
# five tetrahedra: the central one on the even corners, four cut off at the odd ones
_FIVE_EVEN = np.array([[1, 0, 3, 5], [2, 0, 6, 3], [4, 0, 5, 6], [7, 3, 6, 5], [0, 3, 5, 6]])
# Kuhn (Freudenthal) split: six tetrahedra around the diagonal 0-7, one per axis order
_SIX = np.array([[0, 1 << p[0], (1 << p[0]) | (1 << p[1]), 7]
                 for p in itertools.permutations(range(3))])


def _lattice(nx, ny, nz, lx, ly, lz):
    for axis, v in zip("xyz", (nx, ny, nz)):
        if not isinstance(v, (int, np.integer, float)) or int(v) != v or v < 2:
            raise MeshError(f"the number of nodes along {axis} (n{axis}) must be an integer "
                            f">= 2, got {v!r}")
    for axis, v in zip("xyz", (lx, ly, lz)):
        if not isinstance(v, (int, np.integer, float)) or not np.isfinite(v) or v <= 0:
            raise MeshError(f"the length along {axis} (l{axis}) must be a positive length in "
                            f"metres, got {v!r}")
    nx, ny, nz = int(nx), int(ny), int(nz)
    g = np.meshgrid(np.linspace(0, lx, nx), np.linspace(0, ly, ny), np.linspace(0, lz, nz),
                    indexing="ij")
    pts = np.stack([a.ravel(order="F") for a in g], axis=1)  # index i + nx (j + ny k)
    cells = np.array([(i, j, k) for k in range(nz - 1) for j in range(ny - 1)
                      for i in range(nx - 1)])
    c = cells[:, None, :] + _CORNERS[None, :, :]
    corner_ids = c[..., 0] + nx * (c[..., 1] + ny * c[..., 2])  # (cells, 8)
    return pts, cells, corner_ids


def _mirror_x(local):
    """Map cell-corner indices through the mirror i -> 1 - i."""
    return local ^ 1


def box(nx, ny, nz, lx, ly, lz, scheme="five", seed=0):
    """A box [0, lx] x [0, ly] x [0, lz] with nx x ny x nz lattice nodes.

    Schemes: ``five`` (5 tetrahedra per cell, mirrored in alternating cells so faces conform),
    ``five-unmirrored`` (every cell split alike: the faces' diagonals cross, not conforming;
    a control for the mirror, not one of ``SCHEMES``), ``six`` (Kuhn split), ``bcc`` (body-centred lattice: cell centres added) and
    ``unstructured`` (Delaunay of a lattice perturbed within its y-layers, sliver-free).

    Limits of ``unstructured``: a draw is kept only without slivers (radius ratio below 0.1);
    where the lattice spacings lx / (nx - 1), ly / (ny - 1), lz / (nz - 1) differ by a factor
    of 8 or more, no draw may qualify and MeshError says so (up to a factor of 7.5 every seed
    tried on 2-4 nodes per side qualified): keep the spacings within a factor of 4.
    """
    pts, cells, ids = _lattice(nx, ny, nz, lx, ly, lz)
    if scheme == "five":
        odd = cells.sum(axis=1) % 2 == 1
        local = np.where(odd[:, None, None], _mirror_x(_FIVE_EVEN)[None], _FIVE_EVEN[None])
        tets = np.take_along_axis(ids[:, None, :], local, axis=2).reshape(-1, 4)
    elif scheme == "five-unmirrored":
        tets = ids[:, _FIVE_EVEN].reshape(-1, 4)
    elif scheme == "six":
        tets = ids[:, _SIX].reshape(-1, 4)
    elif scheme == "bcc":
        pts, tets = _bcc(pts, cells, ids, (nx, ny, nz), (lx, ly, lz))
    elif scheme == "unstructured":
        pts, tets = _perturbed_delaunay(pts, (nx, ny, nz), (lx, ly, lz), seed)
    else:
        raise MeshError(f"unknown mesh scheme {scheme!r}; choose one of {', '.join(SCHEMES)}")
    neg = signed_volumes(pts, tets) < 0  # generate right-handed tetrahedra directly
    tets[neg] = tets[neg][:, [0, 2, 1, 3]]
    h = tuple(float(v) for v in np.array([lx, ly, lz]) / (np.array([nx, ny, nz]) - 1))
    return TetMesh(pts, tets, lattice=(scheme, int(seed), h))


SCHEMES = ("five", "six", "bcc", "unstructured")


def cube(n, size, scheme="five", seed=0):
    """A cube of side ``size`` [m] with ``n`` nodes per side (see :func:`box`)."""
    return box(n, n, n, size, size, size, scheme, seed)


def perturbed(mesh, amplitude=0.2, seed=0):
    """``mesh`` with each interior node moved at random, every coordinate by up to
    ``amplitude`` x its shortest edge, the connectivity and the boundary nodes kept (an
    irregular patch of the same lattice: ``lattice`` is kept, so a model is calibrated on the
    regular lattice as it would be). Deterministic for a given seed; refused when a
    tetrahedron would invert."""
    if not 0.0 <= amplitude < 0.5:
        raise MeshError(f"amplitude must be in [0, 0.5) of the shortest edge, got {amplitude!r}")
    lo, hi = mesh.points.min(axis=0), mesh.points.max(axis=0)
    tol = 1e-9 * mesh.size
    inner = ~((np.abs(mesh.points - lo) < tol) | (np.abs(mesh.points - hi) < tol)).any(axis=1)
    e = mesh.edges
    length = np.linalg.norm(mesh.points[e[:, 0]] - mesh.points[e[:, 1]], axis=1)
    shortest = np.full(mesh.n_nodes, np.inf)
    np.minimum.at(shortest, e[:, 0], length)
    np.minimum.at(shortest, e[:, 1], length)
    rng = np.random.default_rng(seed)
    d = rng.uniform(-amplitude, amplitude, mesh.points.shape) * shortest[:, None]
    pts = mesh.points + np.where(inner[:, None], d, 0.0)
    if np.any(signed_volumes(pts, mesh.tets) <= 0):
        raise MeshError(f"perturbing by {amplitude} of the shortest edge inverts a tetrahedron: "
                        "take a smaller amplitude")
    return TetMesh(pts, mesh.tets, lattice=mesh.lattice)


def _bcc(pts, cells, ids, n, length):
    """Body-centred cubic tetrahedra: for each interior face, four tetrahedra between the two
    cell centres and the face's edges; each boundary face is a half-pyramid pair on its centre."""
    h = np.array(length) / (np.array(n) - 1)
    centres = (cells + 0.5) * h
    faces = {}  # face key -> (cell centre ids, four corner ids in cyclic order)
    for ci, c in enumerate(cells):
        cid = len(pts) + ci
        for axis in range(3):
            for side in (0, 1):
                sel = _CORNERS[:, axis] == side
                quad = ids[ci][sel]
                # cyclic order on the face: the two in-plane axes in the order (0,0),(1,0),(1,1),(0,1)
                q = _CORNERS[sel][:, [a for a in range(3) if a != axis]]
                order = [np.flatnonzero((q == v).all(axis=1))[0]
                         for v in ((0, 0), (1, 0), (1, 1), (0, 1))]
                key = (axis, c[axis] + side) + tuple(np.delete(c, axis))
                faces.setdefault(key, [[], quad[order]])[0].append(cid)
    tets = []
    for (centres_here, quad) in faces.values():
        if len(centres_here) == 2:
            c1, c2 = centres_here
            tets += [[c1, c2, quad[i], quad[(i + 1) % 4]] for i in range(4)]
        else:
            (c1,) = centres_here
            tets += [[c1, quad[0], quad[1], quad[2]], [c1, quad[0], quad[2], quad[3]]]
    return np.vstack([pts, centres]), np.array(tets)


def _perturbed_delaunay(pts, n, length, seed, amplitude=0.35, min_radius_ratio=0.1, tries=8,
                        resamples=300):
    """Delaunay of a lattice whose nodes are moved at random within their y-layer (so layers
    stay planar) and tangentially on the boundary, without slivers (radius ratio below
    ``min_radius_ratio``). Whole draws are tried for seeds ``seed, seed + 1, ...`` (``tries``
    of them); beyond a few hundred nodes some sliver is almost certain, so then the nodes of
    the slivers of the first draw are drawn again, and again, until none is left (a few
    rounds measured on 425 to 5 000 nodes). Deterministic for a given seed."""
    h = np.array(length) / (np.array(n) - 1)
    lo, hi = np.zeros(3), np.array(length)
    on_bound = (np.isclose(pts, lo) | np.isclose(pts, hi))

    def triangulate(d):
        d[:, 1] = 0.0          # keep the y-layers planar
        d[on_bound] = 0.0      # keep boundary nodes on their faces
        p = pts + d
        tets = Delaunay(p, qhull_options="Qbb Qc Qz Q12").simplices
        vol = np.abs(signed_volumes(p, tets))
        tets = tets[vol > 1e-9 * h.prod()]  # flat hull tetrahedra of coplanar face nodes
        slivers = radius_ratio(p, tets) < min_radius_ratio
        whole = np.isclose(np.abs(signed_volumes(p, tets)).sum(), np.prod(length))
        return p, tets, slivers, whole

    for attempt in range(tries):
        rng = np.random.default_rng(seed + attempt)
        p, tets, slivers, whole = triangulate(rng.uniform(-amplitude, amplitude,
                                                          size=pts.shape) * h)
        if whole and not slivers.any():
            return p, tets
    rng = np.random.default_rng(seed)
    d = rng.uniform(-amplitude, amplitude, size=pts.shape) * h
    for _ in range(resamples):
        p, tets, slivers, whole = triangulate(d)
        if whole and not slivers.any():
            return p, tets
        again = np.unique(tets[slivers]) if slivers.any() else np.arange(len(pts))
        d[again] = rng.uniform(-amplitude, amplitude, size=(len(again), 3)) * h
    raise MeshError(f"no sliver-free perturbed Delaunay mesh found from seed {seed} ({tries} "
                    f"draws, {resamples} local redraws); try another seed")


# ---------------------------------------------------------------- file I/O

def read(path, file_format=None):
    """Read the tetrahedra of any meshio-readable file (Gmsh .msh, .vtu, ...).

    Other cell blocks (vertices, lines, triangles) are ignored and nodes that belong to no
    tetrahedron are dropped. Coordinates are taken as metres. ``file_format`` (a meshio
    format name, e.g. "gmsh") overrides the choice by extension.

    Raises MeshError naming the file and the formats tried for every unreadable input
    (missing, empty, garbage, truncated, unknown extension, no tetrahedra), never SystemExit.
    """
    return read_with_sets(path, file_format)[0]


def read_with_sets(path, file_format=None):
    """``(mesh, sets)``: the TetMesh of :func:`read` and the file's named node sets,
    {name: sorted node indices of that mesh}: its point sets, its cell sets and (Gmsh) its
    physical groups, each as the nodes of its cells that belong to a tetrahedron (a surface
    group gives the nodes of its triangles). The first of these that names a set wins."""
    from pathlib import Path

    path = Path(path)
    m = _meshio_read(path, file_format)
    blocks = [c.data for c in m.cells if c.type == "tetra"]
    if not blocks:
        kinds = sorted({c.type for c in m.cells}) or ["none"]
        raise MeshError(f"{path} holds no tetrahedra (cell types: {', '.join(kinds)}); "
                        "export a volume mesh with 4-node tetrahedra")
    tets = np.vstack(blocks)
    pts = np.asarray(m.points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise MeshError(f"{path} is not a 3-D mesh (points of shape {pts.shape}); a 3-D "
                        "tetrahedral mesh is needed")
    if tets.size and (tets.min() < 0 or tets.max() >= len(pts)):
        raise MeshError(f"{path}: tetrahedra reference nodes outside 0..{len(pts) - 1}; the "
                        "file is truncated or inconsistent")
    used = np.unique(tets)
    remap = np.full(len(pts), -1)
    remap[used] = np.arange(len(used))
    try:
        mesh = TetMesh(pts[used], remap[tets])
    except MeshError as exc:
        raise MeshError(f"{path}: {exc}") from None
    sets = {}
    for name, nodes in _named_sets(m).items():
        kept = remap[np.unique(np.asarray(nodes, dtype=np.int64))]
        sets.setdefault(name, np.sort(kept[kept >= 0]))
    return mesh, sets


def _named_sets(m):
    """{name: file node indices} of a meshio Mesh: point sets, cell sets, Gmsh physical
    groups (the names of ``field_data``, matched on the tag and dimension of each block)."""
    out = {name: np.asarray(ids).ravel() for name, ids in (m.point_sets or {}).items()}
    for name, per_block in (m.cell_sets or {}).items():
        nodes = [m.cells[k].data[np.asarray(ids, dtype=np.int64)].ravel()
                 for k, ids in enumerate(per_block) if ids is not None and len(ids)]
        out.setdefault(name, np.concatenate(nodes) if nodes else np.zeros(0, np.int64))
    tags = (m.cell_data or {}).get("gmsh:physical")
    dims = {"vertex": 0, "line": 1, "triangle": 2, "quad": 2, "tetra": 3, "hexahedron": 3}
    for name, (tag, dim) in ((n, v[:2]) for n, v in (m.field_data or {}).items()
                             if tags is not None and len(v) >= 2):
        nodes = [c.data[np.asarray(t) == tag].ravel() for c, t in zip(m.cells, tags)
                 if dims.get(c.type) == dim]
        out.setdefault(name, np.concatenate(nodes) if nodes else np.zeros(0, np.int64))
    return out


def _meshio_read(path, file_format):
    """The meshio Mesh of ``path``, or a MeshError naming the file and the formats tried."""
    import contextlib
    import io

    import meshio

    if not path.is_file():
        raise MeshError(f"mesh file {path} does not exist" if not path.exists()
                        else f"mesh file {path} is not a file")
    if path.stat().st_size == 0:
        raise MeshError(f"mesh file {path} is empty")
    if file_format is None:
        tried = meshio.extension_to_filetypes.get(path.suffix.lower())
        if not tried:
            raise MeshError(f"cannot read mesh file {path}: the extension {path.suffix!r} is not "
                            "a mesh format meshio knows (e.g. .msh, .vtu, .vtk, .mesh, .inp); "
                            "rename it or pass file_format")
    else:
        tried = [file_format]
    said = io.StringIO()   # meshio prints to stdout and may call sys.exit on a bad file
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            return meshio.read(path, file_format=file_format)
    except (Exception, SystemExit) as exc:
        reason = " ".join((str(exc) if not isinstance(exc, SystemExit) else "").split()) \
            or " ".join(said.getvalue().split()) or type(exc).__name__
        raise MeshError(f"cannot read mesh file {path} as {' or '.join(tried)} (formats tried "
                        f"for {path.suffix or 'it'}): {reason[:300]}; is the file complete and "
                        "in that format?") from None


def write(path, mesh, point_data=None, cell_data=None):
    """Write ``mesh`` with optional per-node and per-tetrahedron arrays through meshio."""
    import meshio

    cd = {k: [np.asarray(v)] for k, v in (cell_data or {}).items()}
    meshio.write(path, meshio.Mesh(mesh.points, [("tetra", mesh.tets)],
                                   point_data=dict(point_data or {}), cell_data=cd))
