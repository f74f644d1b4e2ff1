"""What the library's cases share: the paper's cube and lattice, bars meshed at a spacing and
their end faces."""
import numpy as np

from model import ModelError
from model.bc import Ramp, merge
from model.mesh import box
from model.mesh import cube
from model.paper_mesh import PAPER_NODES  # noqa: F401 (the paper's lattice, for the cases)
from ..framework import MM

CUBE_BCS = ("clamped", "sliding")    # the compressed cube's bases
CUBE_MM = 32.0                        # the paper's cube: its side, every cube case's
PUSH_MM = 1.7                         # the paper's push of its top, and its speed
SPEED_MM_S = 1.7
BAR_MM = (64.0, 16.0, 16.0)           # the bars (bending, torsion): length along x, section


def layers_mm(nodes_per_side, size_mm=CUBE_MM):
    """The y-layers of a cube's layer profile [mm]: its lattice's node planes (the paper's five
    at 0, 8, 16, 24, 32 mm on its 5 x 5 x 5 lattice)."""
    return np.linspace(0.0, size_mm, nodes_per_side).tolist()


PAPER_LAYERS_MM = tuple(layers_mm(PAPER_NODES))   # the paper's own five layers


def bench_mesh(target):
    """The 'five' cube of the paper's side whose tetrahedron count is closest to ``target``:
    the mesh the cost bench times a model on."""
    k = max(1, round((target / 5.0) ** (1.0 / 3.0)))
    return cube(k + 1, CUBE_MM * MM, "five")


def cube_boundary_sets(mesh, bc, size):
    """(driven, lateral, held) of a cube [0, size]^3 [m] pushed down on its top: the top
    nodes, moved in y; what the top holds laterally; and the mapping that holds the rest.

    ``clamped``: bottom fully fixed, top fully prescribed. ``sliding``: only y prescribed at top
    and bottom; the origin pinned and the node at (size, 0, 0) held in z remove rigid
    motions."""
    top, bottom = mesh.nodes_on_plane("y", size), mesh.nodes_on_plane("y", 0.0)
    if bc == "clamped":
        return top, (0.0, None, 0.0), {int(i): (0.0, 0.0, 0.0) for i in bottom}
    if bc != "sliding":
        raise ModelError(f"unknown boundary condition {bc!r}; choose from {', '.join(CUBE_BCS)}")
    held = [(int(i), (None, 0.0, None)) for i in bottom]
    origin = mesh.nodes_where(lambda p: np.all(np.abs(p) < 1e-9, axis=1))[0]
    corner_x = mesh.nodes_where(lambda p: (np.abs(p[:, 0] - size) < 1e-9)
                                & (np.abs(p[:, 1]) < 1e-9) & (np.abs(p[:, 2]) < 1e-9))[0]
    held += [(int(origin), (0.0, 0.0, 0.0)), (int(corner_x), (None, 0.0, 0.0))]
    return top, (None, None, None), merge(held)


def bar(family, length_mm, height_mm, width_mm, spacing_mm):
    """A box [0, L] x [0, H] x [0, W] (mm in, metres out) with nodes every ``spacing_mm``."""
    n = [int(round(d / spacing_mm)) + 1 for d in (length_mm, height_mm, width_mm)]
    return box(*n, length_mm * MM, height_mm * MM, width_mm * MM, scheme=family)


def face(mesh, x):
    """The nodes of the end face at x [m]."""
    return mesh.nodes_on_plane("x", x)


def paper_push(mesh, bc, push_mm=PUSH_MM):
    """The paper's push of the cube's top as a ramp: ``push_mm`` down at SPEED_MM_S, the base
    held as ``bc`` says (``cube_boundary_sets``)."""
    top, lateral, held = cube_boundary_sets(mesh, bc, CUBE_MM * MM)
    return Ramp(top, (lateral[0], -push_mm * MM, lateral[2]), push_mm / SPEED_MM_S, held=held)

