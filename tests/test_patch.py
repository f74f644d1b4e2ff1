"""The patch test (cases.studies.convergence.patch): its strain error against closed forms, the
perturbed lattices, and every model on every family: the FEM baselines reproduce each affine
field to the spec's bound; the particle models' consistency error is what the table reports."""
import numpy as np
import pytest

from model import PRESETS
from model.errors import MeshError
from model.material import Material
from model.geometry import displacement_gradients
from model.mesh import cube, perturbed
from cases.studies.convergence import patch
from cases.studies.convergence.verification import spec

FEM = ("FEM P1", "fem-linear", "fem-corotated", "fem-neohookean")
PARTICLES = tuple(m for m in PRESETS if not m.startswith("fem-"))
LATTICES = ("five", "six", "bcc", "unstructured")


@pytest.fixture(scope="module")
def table():
    s = spec()
    return {(r["mesh"], r["model"]): r for r in patch.table(
        ("FEM P1",) + tuple(PRESETS), LATTICES, Material(10e3, 0.45))}, s["patch"]


def test_gradients_of_an_affine_field_are_exact_on_any_mesh():
    """The per-tetrahedron displacement gradients of an affine field u = A x + b equal A to within
    1e-15 on a perturbed six lattice."""
    m = perturbed(cube(4, 0.02, "six"), 0.3, 1)
    A = np.array([[1e-3, 2e-4, -3e-4], [5e-4, -1e-3, 0.0], [0.0, 7e-4, 2e-3]])
    g = displacement_gradients(m.points, m.tets, m.points @ A.T + 1e-3)
    assert np.abs(g - A).max() < 1e-15


def test_strain_error_of_a_doubled_strain_is_one_and_of_the_strain_zero():
    """On a perturbed bcc mesh the patch strain error is zero for the field of the target strain,
    still zero with a small rotation added, and exactly 1 (relative) for twice the target strain."""
    m = perturbed(cube(4, 0.02, "bcc"), 0.2, 0)
    eps = np.array([[0.0, 1e-4, 0.0], [1e-4, 0.0, 0.0], [0.0, 0.0, 0.0]])
    assert patch.strain_error(m, m.points @ eps.T, eps) < 1e-12
    assert patch.strain_error(m, 2 * m.points @ eps.T, eps) == pytest.approx(1.0, rel=1e-12)
    # a rotation adds no strain
    w = np.array([[0.0, -1e-4, 0.0], [1e-4, 0.0, 0.0], [0.0, 0.0, 0.0]])
    assert patch.strain_error(m, m.points @ (eps + w).T, eps) < 1e-12


def test_the_six_unit_strains_are_a_basis_of_the_symmetric_tensors():
    """The six unit strains are symmetric, have largest entry 1 in magnitude and span the six-
    dimensional space of symmetric 3x3 tensors."""
    e = np.array([u.ravel() for u in patch.unit_strains()])
    assert np.linalg.matrix_rank(e) == 6
    assert all(np.allclose(u, u.T) and np.abs(u).max() == 1.0 for u in patch.unit_strains())


def test_perturbed_keeps_the_boundary_and_moves_the_interior_within_bounds():
    """Perturbing a mesh moves every interior node and no boundary node, each coordinate by at most
    the amplitude times the node spacing, the same way for the same seed, keeping the lattice and
    the tetrahedra; an amplitude of 0.5 is refused with a MeshError."""
    m = cube(5, 0.02, "five")
    p = perturbed(m, 0.2, 3)
    moved = np.linalg.norm(p.points - m.points, axis=1) > 0
    inner = ~patch.boundary(m)
    assert moved[inner].all() and not moved[~inner].any()
    assert np.abs(p.points - m.points).max() <= 0.2 * 0.005 + 1e-15
    assert np.array_equal(p.points, perturbed(m, 0.2, 3).points)      # deterministic
    assert p.lattice == m.lattice and np.array_equal(p.tets, m.tets)
    with pytest.raises(MeshError, match="amplitude"):
        perturbed(m, 0.5)


def test_families_add_each_lattice_perturbed():
    """The patch-test families are the given lattices followed by the perturbed five, six and bcc
    lattices (the unstructured mesh gets no perturbed family)."""
    assert patch.families(LATTICES) == list(LATTICES) + [
        "five-perturbed", "six-perturbed", "bcc-perturbed"]


def test_fem_baselines_pass_the_patch_test_on_every_family(table):
    """Every FEM baseline (FEM P1, fem-linear, fem-corotated, fem-neohookean) completes the patch
    test on every family, regular and perturbed, with a strain error below the spec's exactness
    bound."""
    rows, p = table
    for fam in patch.families(LATTICES):
        for m in FEM:
            r = rows[(fam, m)]
            assert r["failed"] is None and r["patch_error"] < p["exact_below"], r


def test_particle_models_pass_on_regular_lattices_and_fail_on_perturbed_ones(table):
    """On the regular five and six lattices every particle model holds the affine field (as
    measured); with the interior nodes moved, or unstructured, each misses the strain by more
    than 1 %: its consistency error."""
    rows, p = table
    for m in PARTICLES:
        for fam in ("five", "six"):
            assert rows[(fam, m)]["patch_error"] < p["exact_below"], (fam, m)
        for fam in ("five-perturbed", "six-perturbed", "bcc-perturbed", "unstructured"):
            r = rows[(fam, m)]
            assert r["failed"] is None and r["patch_error"] > 0.01, (fam, m, r)
