"""Property-based tests (hypothesis): any valid mesh, in any node and vertex order, gives finite
forces that conserve momentum for every conservative preset; any corrupted mesh raises
MeshError and nothing else."""
import numpy as np
import pytest
from hypothesis import assume, given, strategies as st

from model import PRESETS, Material, build
from model.terms import registered
from model.errors import MeshError, ModelError
from model.geometry import signed_volumes
from model.mesh import SCHEMES, TetMesh, box



@st.composite
def valid_meshes(draw):
    """A box of 2-4 nodes per side in any scheme and size, its nodes moved at random by up to
    0.15 of the spacing, its nodes renumbered, its tetrahedra reordered and each one's
    vertices permuted (so about half are negatively ordered on input)."""
    n = [draw(st.integers(2, 4)) for _ in range(3)]
    lengths = [draw(st.floats(1e-3, 1.0)) for _ in range(3)]
    assume(max(lengths) / min(lengths) <= 8)
    scheme = draw(st.sampled_from(SCHEMES))
    spacing = [length / (k - 1) for length, k in zip(lengths, n)]
    # the generator's stated limit (model.mesh.box): draw only what it can build
    assume(scheme != "unstructured" or max(spacing) / min(spacing) <= 4)
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    base = box(*n, *lengths, scheme=scheme, seed=seed % 7)
    h = min(lengths) / (max(n) - 1)
    amplitude = draw(st.floats(0.0, 0.15))
    pts = base.points + amplitude * h * rng.uniform(-1, 1, base.points.shape)
    v0, v = base.volumes, signed_volumes(pts, base.tets)
    assume((v > 0.2 * v0).all())               # the perturbation inverted nothing
    perm = rng.permutation(base.n_nodes)        # new index of each old node
    inverse = np.argsort(perm)
    tets = perm[base.tets][rng.permutation(base.n_tets)]
    tets = np.take_along_axis(tets, np.argsort(rng.random(tets.shape), axis=1), axis=1)
    return TetMesh(pts[inverse], tets)


# the particle presets (the FEM baselines are tested in test_solvers) whose terms all have an
# energy: the shear term by its reading, any other term by its class
CONSERVATIVE = [p for p in PRESETS if not p.startswith("fem-") and all(
    q.get("reading") == "variational" if t == "shear" else registered()[t].conservative
    for t, q in PRESETS[p])]


def test_the_conservative_presets_are_the_expected_ones(small_mesh):
    """The literal readings are not conservative, the variational one and the springs are;
    a preset added later is classified by its terms, as the model itself says."""
    assert {"pbcm-variational", "pbcm-variational+normal", "msm", "msm+volume"} \
        <= set(CONSERVATIVE)
    assert not {"pbcm-corner", "pbcm-balanced"} & set(CONSERVATIVE)
    for p in PRESETS:
        if not p.startswith("fem-"):
            assert build(p, small_mesh, Material(E=1e4, nu=0.3)).conservative == \
                (p in CONSERVATIVE), p


@given(mesh=valid_meshes(), nu=st.floats(0.0, 0.49), E=st.floats(1e2, 1e6),
       preset=st.sampled_from(CONSERVATIVE), strain=st.floats(1e-4, 0.05),
       seed=st.integers(0, 2**32 - 1))
def test_random_valid_meshes_give_finite_forces_that_conserve_momentum(mesh, nu, E, preset,
                                                                        strain, seed):
    """For every conservative particle preset on any random valid mesh (perturbed, renumbered,
    tetrahedra and vertices reordered) at a random small deformation, the forces are finite and
    non-zero, their sum and net torque vanish to round-off, and the forces at rest vanish."""
    try:
        pm = build(preset, mesh, Material(E=E, nu=nu))
    except ModelError as exc:   # e.g. one cell: the normal term adds nothing to fit
        assume("pass a number for c" not in str(exc))
        raise
    assert pm.conservative
    rng = np.random.default_rng(seed)
    h = mesh.size / np.cbrt(mesh.n_nodes)
    x = mesh.points + strain * h * rng.standard_normal(mesh.points.shape)
    assume((signed_volumes(x, mesh.tets) > 0).all())
    f = pm.forces(x)
    assert np.isfinite(f).all() and np.abs(f).max() > 0
    scale = np.linalg.norm(f, axis=1).sum()
    assert np.linalg.norm(f.sum(axis=0)) <= 1e-11 * scale
    r = x - x.mean(axis=0)
    arm = (np.linalg.norm(r, axis=1) * np.linalg.norm(f, axis=1)).sum()
    assert np.linalg.norm(np.cross(r, f).sum(axis=0)) <= 1e-10 * arm
    assert np.abs(pm.forces(mesh.points)).max() <= 1e-10 * scale  # no force at rest


CORRUPTIONS = ("nan", "inf", "degenerate", "repeated-node", "duplicate-node", "unused-node",
               "index-high", "index-negative", "fractional-index", "flat-points", "no-tets",
               "duplicate-tet")


@given(n=st.integers(2, 3), scheme=st.sampled_from(("five", "six", "bcc")),
       size=st.floats(1e-3, 1.0), corruption=st.sampled_from(CORRUPTIONS),
       seed=st.integers(0, 2**32 - 1))
def test_random_invalid_meshes_raise_mesh_error_and_nothing_else(n, scheme, size, corruption,
                                                                 seed):
    """Each corruption of a valid box mesh (a NaN or infinite coordinate, a degenerate, repeated-
    node or duplicate tetrahedron, a duplicated or unused node, an out-of-range, negative or
    fractional index, 2-D points, no tetrahedra) makes TetMesh raise MeshError and no other
    exception."""
    rng = np.random.default_rng(seed)
    base = box(n, n, n, size, size, size, scheme=scheme)
    pts, tets = base.points.copy(), base.tets.copy()
    i, node = rng.integers(len(tets)), rng.integers(len(pts))
    if corruption in ("nan", "inf"):
        pts[node, rng.integers(3)] = np.nan if corruption == "nan" else np.inf
    elif corruption == "degenerate":          # four coplanar nodes of the bottom face
        bottom = np.flatnonzero(np.isclose(pts[:, 1], 0.0))
        tets = np.vstack([tets, rng.choice(bottom, 4, replace=False)])
    elif corruption == "repeated-node":
        tets[i, rng.integers(1, 4)] = tets[i, 0]
    elif corruption == "duplicate-node":      # a copy of a node, used by one tetrahedron
        pts = np.vstack([pts, pts[tets[i, 0]]])
        tets[i, 0] = len(pts) - 1
    elif corruption == "unused-node":
        pts = np.vstack([pts, pts.max(axis=0) + size])
    elif corruption == "index-high":
        tets[i, rng.integers(4)] = len(pts) + rng.integers(0, 5)
    elif corruption == "index-negative":
        tets[i, rng.integers(4)] = -1 - rng.integers(0, 5)
    elif corruption == "fractional-index":
        tets = tets.astype(float)
        tets[i, 0] += 0.5
    elif corruption == "flat-points":
        pts = pts[:, :2]
    elif corruption == "no-tets":
        tets = tets[:0]
    elif corruption == "duplicate-tet":
        tets = np.vstack([tets, tets[i][rng.permutation(4)]])
    with pytest.raises(MeshError):
        TetMesh(pts, tets)
