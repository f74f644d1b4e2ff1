"""Writes cylinder.msh, the mesh of the worked example (cylinder.toml): a cylinder of radius
10 mm and height 20 mm standing on z = 0, its axis on z, in millimetres.

The cross-section is a Delaunay triangulation (scipy) of the centre and two rings of nodes,
extruded in four layers; each prism is split into three tetrahedra by the rule that makes
neighbouring prisms share their diagonals (the lowest node of a quadrilateral face joined to
the highest of the next layer), so the tetrahedra conform. The ends and the side are written
as Gmsh physical groups (bottom, top, side) and the volume as body, so that a problem may
select them by name.

    python examples/cylinder/make_mesh.py
"""
from pathlib import Path

import meshio
import numpy as np
from scipy.spatial import Delaunay

RADIUS_MM, HEIGHT_MM = 10.0, 20.0
RINGS = (6, 12)            # nodes on each ring, from the centre out (the centre is one node)
LAYERS = 4
HERE = Path(__file__).resolve().parent


def section():
    """The cross-section's nodes (k, 2) [mm] and triangles (t, 3)."""
    pts = [(0.0, 0.0)]
    for i, n in enumerate(RINGS, start=1):
        r = RADIUS_MM * i / len(RINGS)
        pts += [(r * np.cos(a), r * np.sin(a)) for a in 2 * np.pi * np.arange(n) / n]
    pts = np.array(pts)
    return pts, Delaunay(pts).simplices


def extruded(pts, tri):
    """Nodes (n, 3) [mm] and tetrahedra (m, 4) of the section extruded in LAYERS layers."""
    k = len(pts)
    z = np.linspace(0.0, HEIGHT_MM, LAYERS + 1)
    nodes = np.vstack([np.column_stack([pts, np.full(k, h)]) for h in z])
    tets = []
    for layer in range(LAYERS):
        for a, b, c in np.sort(tri, axis=1):      # a < b < c: the shared-diagonal rule
            lo, hi = layer * k, (layer + 1) * k
            tets += [(lo + a, lo + b, lo + c, hi + c), (lo + a, lo + b, hi + b, hi + c),
                     (lo + a, hi + a, hi + b, hi + c)]
    tets = np.array(tets)
    p = nodes[tets]
    negative = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]),
                         p[:, 3] - p[:, 0]) < 0
    tets[negative] = tets[negative][:, [0, 2, 1, 3]]     # written positively oriented
    return nodes, tets


def boundary(tets):
    """The boundary triangles (k, 3): faces of one tetrahedron only."""
    faces = tets[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3)
    _, inverse, counts = np.unique(np.sort(faces, axis=1), axis=0, return_inverse=True,
                                   return_counts=True)
    return faces[counts[inverse.ravel()] == 1]


def main():
    nodes, tets = extruded(*section())
    tri = boundary(tets)
    z = nodes[tri, 2]
    groups = {"bottom": (z == 0.0).all(axis=1), "top": (z == HEIGHT_MM).all(axis=1)}
    groups["side"] = ~(groups["bottom"] | groups["top"])
    faces = np.vstack([tri[on] for on in groups.values()])
    tags = np.concatenate([np.full(on.sum(), k + 1) for k, on in enumerate(groups.values())])
    body = len(groups) + 1
    mesh = meshio.Mesh(
        nodes, [("triangle", faces), ("tetra", tets)],
        cell_data={"gmsh:physical": [tags, np.full(len(tets), body)],
                   "gmsh:geometrical": [tags, np.full(len(tets), body)]},
        field_data={**{name: np.array([k + 1, 2]) for k, name in enumerate(groups)},
                    "body": np.array([body, 3])})
    meshio.write(HERE / "cylinder.msh", mesh, file_format="gmsh22", binary=False)
    print(f"cylinder.msh: {len(nodes)} nodes, {len(tets)} tetrahedra")


if __name__ == "__main__":
    main()
