import meshio
import numpy as np
import pytest

from model.errors import MeshError
from model.mesh import SCHEMES, TetMesh, box, cube, folded_tets, read, write

L = 0.032


def boundary_faces(mesh):
    f = np.sort(mesh.tets[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3), axis=1)
    uniq, counts = np.unique(f, axis=0, return_counts=True)
    assert counts.max() <= 2, "a face is shared by more than two tetrahedra"
    return uniq[counts == 1]


@pytest.mark.parametrize("scheme,nodes,tets", [("five", 125, 320), ("six", 125, 384),
                                               ("bcc", 189, 768)])
def test_cube_counts(scheme, nodes, tets):
    """A cube of 5 nodes per side has 125 nodes and 320 tetrahedra with the five split, 125
    and 384 with the six split, and 189 and 768 with the bcc lattice."""
    m = cube(5, L, scheme)
    assert (m.n_nodes, m.n_tets) == (nodes, tets)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_cube_is_a_conforming_cube(scheme):
    """Every generated cube scheme gives positive tetrahedron volumes summing to L^3 to
    round-off, and its boundary faces (faces of one tetrahedron only) all lie on the cube's
    surface with a total area of 6 L^2, so the mesh conforms."""
    m = cube(5, L, scheme)
    assert m.volumes.min() > 0
    assert m.volumes.sum() == pytest.approx(L**3, rel=1e-12)
    # a conforming mesh of the cube has only faces on the cube's surface as boundary faces,
    # and their area adds up to 6 L^2
    bf = boundary_faces(m)
    p = m.points[bf]
    on_surface = ((np.isclose(p, 0.0, atol=1e-12) | np.isclose(p, L, atol=1e-12))
                  .all(axis=1)).any(axis=1)
    assert on_surface.all()
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
    assert area == pytest.approx(6 * L**2, rel=1e-12)


def test_unstructured_has_no_slivers_and_planar_layers():
    """The unstructured cube has a smallest radius ratio of at least 0.1, its nodes lie on
    five planar y-layers evenly spaced over [0, L], and a second call gives the same node
    coordinates."""
    m = cube(5, L, "unstructured")
    q = m.quality()
    assert q["radius_ratio_min"] >= 0.1
    assert np.allclose(np.unique(m.points[:, 1].round(12)), np.linspace(0, L, 5))
    assert np.array_equal(m.points, cube(5, L, "unstructured").points)  # deterministic


def test_box_and_node_sets():
    """A 6 x 3 x 2 box has 36 nodes; nodes_on_plane selects the 6 nodes on x = 0 and the 12
    on y = 0.02 by axis name or index, nodes_where the 18 with x > 0.05, and an unknown axis
    raises MeshError naming the axis."""
    m = box(6, 3, 2, 0.1, 0.02, 0.01, "six")
    assert m.n_nodes == 36
    assert len(m.nodes_on_plane("x", 0.0)) == 6
    assert len(m.nodes_on_plane(1, 0.02)) == 12
    assert len(m.nodes_where(lambda p: p[:, 0] > 0.05)) == 18
    with pytest.raises(MeshError, match="axis"):
        m.nodes_on_plane("w", 0.0)


def test_reorients_negative_tetrahedra():
    """A negatively oriented tetrahedron is re-oriented on construction: reoriented counts 1
    and its volume is +1/6."""
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    m = TetMesh(pts, np.array([[0, 2, 1, 3]]))
    assert m.reoriented == 1 and m.volumes[0] == pytest.approx(1 / 6)


@pytest.mark.parametrize("points,tets,match", [
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, np.nan]], [[0, 1, 2, 3]], "non-finite"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [[0, 1, 2, 4]], "outside"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1, 2, 3]], "zero volume"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [[0, 1, 2, 2]], "repeat"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [5, 5, 5]], [[0, 1, 2, 3]], "no tetrahedron"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1]], [[0, 1, 2, 3], [0, 1, 2, 4]],
     "duplicate nodes"),
    ([[0, 0], [1, 0]], [[0, 1, 0, 1]], "shape"),
])
def test_bad_meshes_are_named(points, tets, match):
    """TetMesh refuses each malformed input with a MeshError naming the defect: non-finite
    coordinates, node indices outside the points, zero volume, a node repeated in a
    tetrahedron, a node in no tetrahedron, duplicate nodes, and points that are not 3-D."""
    with pytest.raises(MeshError, match=match):
        TetMesh(np.array(points, dtype=float), np.array(tets))


def test_generator_arguments_are_checked():
    """cube raises MeshError for an unknown scheme, for fewer than 2 nodes per side and for a
    negative length, each message naming the bad argument."""
    with pytest.raises(MeshError, match="unknown mesh scheme"):
        cube(3, L, "seven")
    with pytest.raises(MeshError, match=r"nodes along x \(nx\) must be an integer >= 2"):
        cube(1, L)
    with pytest.raises(MeshError, match="positive length"):
        cube(3, -1.0)


def test_gmsh_file_with_mixed_blocks(tmp_path):
    """read keeps only the tetrahedra of a Gmsh file that also holds vertex, line and
    triangle blocks and two tetra blocks, drops the node no tetrahedron uses, and returns the
    original node and tetrahedron counts with volume L^3."""
    m = cube(3, L, "six")
    tri = np.sort(m.tets[:, [0, 1, 2]], axis=1)[:5]
    extra = np.vstack([m.points, [[1.0, 1.0, 1.0]]])  # a geometry point no tetrahedron uses
    mio = meshio.Mesh(extra, [("vertex", np.array([[0], [len(extra) - 1]])),
                              ("line", m.tets[:4, :2]), ("triangle", tri),
                              ("tetra", m.tets[:20]), ("tetra", m.tets[20:])])
    path = tmp_path / "mixed.msh"
    meshio.write(path, mio, file_format="gmsh22", binary=False)
    back = read(path)
    assert (back.n_nodes, back.n_tets) == (m.n_nodes, m.n_tets)
    assert np.allclose(back.volumes.sum(), L**3)


def test_file_without_tetrahedra(tmp_path):
    """Reading a mesh file that holds only triangles raises MeshError saying it has no
    tetrahedra."""
    path = tmp_path / "surface.msh"
    meshio.write(path, meshio.Mesh(np.eye(3), [("triangle", np.array([[0, 1, 2]]))]),
                 file_format="gmsh22", binary=False)
    with pytest.raises(MeshError, match="no tetrahedra"):
        read(path)


def test_write_roundtrip_with_data(tmp_path):
    """write stores per-node and per-tetrahedron arrays in a .vtu file from which meshio
    reads them back unchanged."""
    m = cube(3, L, "five")
    path = tmp_path / "m.vtu"
    write(path, m, point_data={"u": m.points * 0.1}, cell_data={"p": m.volumes})
    back = meshio.read(path)
    assert np.allclose(back.point_data["u"], m.points * 0.1)
    assert np.allclose(back.cell_data["p"][0], m.volumes)


# ---------------------------------------------------------------- the paper's 374-tetrahedron mesh
def test_a_cube_has_74_triangulations_two_of_five_tetrahedra_each_filling_it():
    """De Loera, Rambau and Santos (Triangulations, 2010): the 3-cube has 74 triangulations
    without new vertices, 2 of 5 tetrahedra and 72 of 6."""
    from model.paper_mesh import cube_triangulations, face_diagonals, _CORNERS
    tris = cube_triangulations()
    assert len(tris) == 74 and sum(len(t) == 5 for t in tris) == 2
    for t in tris:
        vol = sum(abs(np.linalg.det(_CORNERS[list(s[1:])] - _CORNERS[s[0]])) / 6 for s in t)
        assert vol == pytest.approx(1.0, abs=1e-12)
    # a five split cuts all six faces along diagonals of one parity (its central tetrahedron)
    assert sorted(face_diagonals(t) for t in tris if len(t) == 5) == [(0,) * 6, (1,) * 6]


def test_the_delaunay_reconstruction_gives_374_tetrahedra_for_seeds_7_15_25_and_is_non_conforming():
    """Of seeds 0 to 25, exactly 7, 15 and 25 give a 374-tetrahedron Delaunay lattice of 5
    nodes a side; seed 7's mesh has 125 nodes and volume size^3 but unmatched interior faces,
    while the five and six cubes have none."""
    from model.paper_mesh import delaunay_lattice, unmatched_faces
    size = 0.032
    counts = {s: delaunay_lattice(5, size, s).n_tets for s in range(26)}
    assert [s for s, n in counts.items() if n == 374] == [7, 15, 25]
    m = delaunay_lattice(5, size, 7)
    assert m.n_nodes == 125 and m.volumes.sum() == pytest.approx(size**3, rel=1e-12)
    assert unmatched_faces(m, size) > 0          # cells cut a shared square differently
    assert unmatched_faces(cube(5, size, "five"), size) == 0
    assert unmatched_faces(cube(5, size, "six"), size) == 0


def test_the_mixed_split_is_conforming_with_ten_cells_in_five():
    """mixed_split with 10 five-tetrahedron cells gives a conforming cube of 125 nodes and
    374 tetrahedra of volume size^3, with 10 cells of five and 54 of six, and another seed
    gives another split. paper_size_meshes refuses a Delaunay seed that does not give 374
    tetrahedra, and mixed_split refuses more five-cells than the 64 cells."""
    from model.paper_mesh import mixed_split, paper_size_meshes, unmatched_faces
    size = 0.032
    m = mixed_split(5, size, 10, seed=0)
    assert (m.n_nodes, m.n_tets) == (125, 374)
    assert unmatched_faces(m, size) == 0
    assert m.volumes.sum() == pytest.approx(size**3, rel=1e-12)
    cell = np.floor(m.points[m.tets].mean(axis=1) / (size / 4)).astype(int)
    per_cell = np.unique(cell[:, 0] + 4 * cell[:, 1] + 16 * cell[:, 2], return_counts=True)[1]
    assert sorted(per_cell.tolist()) == [5] * 10 + [6] * 54
    assert not np.array_equal(m.tets, mixed_split(5, size, 10, seed=1).tets)
    with pytest.raises(MeshError, match="not the paper's 374"):
        paper_size_meshes(size, seeds=(0,), mixed_seeds=())
    with pytest.raises(MeshError, match="n_five must be between 0 and the 64 cells"):
        mixed_split(5, size, 65, seed=0)


def test_paper_meshes_take_the_lattice_checks():
    """The reconstructions check their size as every lattice does (one check, in
    model.mesh), and a whole number given as a float is a number of nodes."""
    from model.paper_mesh import delaunay_lattice, mixed_split
    with pytest.raises(MeshError, match=r"nodes along x \(nx\) must be an integer >= 2"):
        delaunay_lattice(1, 0.032, 7)
    with pytest.raises(MeshError, match="positive length"):
        mixed_split(5, -0.032, 10, 0)
    assert delaunay_lattice(5.0, 0.032, 7).n_tets == delaunay_lattice(5, 0.032, 7).n_tets


def test_a_folded_mesh_is_refused_naming_the_tetrahedra():
    """A node pushed through a face inverts its tetrahedra, which re-orientation would hide
    (a cube of 32 768 mm^3 measuring more): the mesh is refused, naming them; the four
    generated families pass."""
    m = cube(5, 0.032, "six")
    pts = m.points.copy()
    i = int(np.argmin(np.linalg.norm(pts - 0.016, axis=1)))
    pts[i] += [0.009, 0.0, 0.0]
    with pytest.raises(MeshError, match="folded") as err:
        TetMesh(pts, m.tets.copy())
    assert "tetrahedra " in str(err.value)
    for family in ("five", "six", "bcc", "unstructured"):
        c = cube(5, 0.032, family)
        assert folded_tets(c.points, c.tets).size == 0


def test_a_sliver_is_named_and_refused_for_calibration():
    """One nearly flat tetrahedron: ``slivers`` names it and a calibrated
    model refuses the mesh naming it, instead of a collapsed c; a given c still builds."""
    from model import build
    from model.errors import ModelError
    from model.material import Material
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0.34, 0.33, 0.335]]) * 0.01
    tets = np.array([[0, 1, 2, 3], [1, 2, 3, 4]])
    m = TetMesh(pts, tets)
    assert m.slivers().tolist() == [1]
    with pytest.raises(ModelError, match="tetrahedra 1 of the mesh are slivers"):
        build("pbcm-variational", m, Material(10e3, 0.45))
    build("shear(reading=variational, c=1) + volume", m, Material(10e3, 0.45))


def test_mesh_warnings_name_the_worst_slivers_and_dihedral_angles_before_computing(
        tmp_path, capsys):
    """A sliver (radius ratio below the threshold) and a flat tetrahedron (a dihedral angle
    outside the range) are named with their ids and values, the worst first, by the mesh and
    by `pbcm mesh`; a regular tetrahedron gives no warning."""
    from cases.cli import main
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1],
                    [2, 0, 0], [3, 0, 0], [2, 1, 0], [3, 1, 0.02]], float)
    regular = TetMesh(pts[:4], np.array([[0, 1, 2, 3]]))
    assert regular.warnings() == []
    mesh = TetMesh(pts, np.array([[0, 1, 2, 3], [4, 5, 6, 7]]))
    sliver, flat = mesh.warnings()
    assert sliver.startswith("1 sliver(s) (radius ratio below 0.05), the worst: tetrahedron 1 (")
    assert flat.startswith("1 tetrahedra with a dihedral angle outside 3-175 deg, the worst: "
                           "tetrahedron 1 (")
    path = tmp_path / "m.vtu"
    write(path, mesh)
    assert main(["mesh", str(path)]) == 0
    out = capsys.readouterr().out
    assert "warning: 1 sliver(s)" in out and "warning: 1 tetrahedra with a dihedral" in out


def test_unstructured_states_its_limit_and_keeps_within_it():
    """The unstructured generator builds every box whose spacings are within its stated
    factor of 4 (2-4 nodes per side, several seeds) and, beyond its limit (spacings 16 apart),
    refuses with MeshError naming what failed rather than returning slivers."""
    for n in ((2, 3, 2), (4, 2, 3), (3, 4, 4)):
        for lengths in ((1.0, 1.0, 1.0), (1.0, 0.5, 1.0), (1.0, 1.0, 0.25)):
            spacing = [length / (k - 1) for length, k in zip(lengths, n)]
            if max(spacing) / min(spacing) <= 4:
                for seed in range(3):
                    box(*n, *lengths, scheme="unstructured", seed=seed)
    with pytest.raises(MeshError, match="no sliver-free perturbed Delaunay mesh"):
        box(2, 3, 2, 1.0, 0.125, 1.0, scheme="unstructured", seed=0)
