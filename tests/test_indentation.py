"""Indentation poses one problem on every mesh and for every model: the punch (a flat face and
a sloping rim) is one displacement field declared by geometry, prescribed at the models' nodes
and, through a reference.discretisation.Region, at every boundary point of every refinement."""
import numpy as np

from cases.library.indentation import (CASE, DEPTH_MM, PATCH_MM, RIM_MM, SIZE_MM, in_patch,
                                       punch)
from cases.running.runner import reaction_along
from reference import linear
from reference.linear import dof_component
from reference.discretisation import Region
from model.units import MM

SPACING = 8.0     # coarse: the face is one lattice cell, resolved by the refinements


def punch_force(family, dirichlet_fn):
    s = CASE.settings(spacing_mm=SPACING)
    mesh = CASE.mesh(family, s)
    conv = linear.converged(mesh, s.material, CASE.dirichlet(mesh, "clamped", s), levels=1,
                            dirichlet_fn=dirichlet_fn, solver="direct")
    return reaction_along(conv.result.reaction, CASE.driven(mesh, "clamped", s)), \
        conv.error_estimate


def test_the_punch_is_its_face_and_a_rim_sloping_to_the_free_surface():
    """The punch field presses top-face points inside the patch to the full depth, falls linearly
    over the rim to zero at its outer edge, leaves points beyond the rim or below the top free
    (NaN), and holds the base at zero."""
    c, top = SIZE_MM / 2 * MM, SIZE_MM * MM
    half = PATCH_MM / 2 * MM
    pts = np.array([[c, top, c], [c + half, top, c - half],
                    [c + half + RIM_MM / 2 * MM, top, c],          # half-way down the rim
                    [c + half + RIM_MM * MM, top, c],              # the rim's outer edge
                    [c + half + RIM_MM * MM + 1e-4, top, c],       # just beyond it
                    [c, top - 1e-3, c], [c, 0.0, c]])
    assert in_patch(pts).tolist() == [True, True, False, False, False, False, False]
    u = punch(pts)
    assert np.array_equal(u[0], [0.0, -DEPTH_MM * MM, 0.0])
    assert np.array_equal(u[1], [0.0, -DEPTH_MM * MM, 0.0])
    assert np.allclose(u[2], [0.0, -DEPTH_MM * MM / 2, 0.0], rtol=0, atol=1e-15)
    assert np.allclose(u[3], 0.0, rtol=0, atol=1e-15)        # held: the surface is closed
    assert np.isnan(u[4]).all() and np.isnan(u[5]).all()
    assert np.array_equal(u[6], [0.0, 0.0, 0.0])


def test_the_models_prescribe_the_references_field_at_their_nodes():
    """The references are given a Region wrapping the punch field, and on the five and unstructured
    meshes the models' prescribed nodes are exactly those where the punch field is defined, with
    its values; on the unstructured mesh some top nodes lie on the rim and are pressed part-way
    down."""
    s = CASE.settings()
    given = CASE.dirichlet_fn(None, "clamped", s)
    assert isinstance(given, Region) and given.fn is punch
    for family in ("five", "unstructured"):
        mesh = CASE.mesh(family, s)
        d = CASE.dirichlet(mesh, "clamped", s)
        field = punch(mesh.points)
        held = np.flatnonzero(~np.isnan(field).any(axis=1))
        assert sorted(d) == held.tolist()
        assert np.array_equal(np.array([d[i] for i in held.tolist()]), field[held])
    # on the unstructured mesh some top nodes lie on the rim: prescribed part-way down
    ys = [v[1] for v in d.values()]
    assert any(-DEPTH_MM * MM < y < 0 for y in ys)


def test_every_mesh_poses_the_same_punch():
    """The converged linear reference's punch reactions on the five, six, bcc and unstructured
    meshes agree pairwise to within the sum of their error estimates."""
    forces = {f: punch_force(f, CASE.dirichlet_fn(None, "clamped", None))
              for f in ("five", "six", "bcc", "unstructured")}
    for a, (fa, ea) in forces.items():
        for b, (fb, eb) in forces.items():
            assert abs(fa / fb - 1) <= ea + eb, (a, b, forces)


def _face_only(points):
    """The punch's face alone held at full depth (no rim), the base clamped: a patch whose
    edge falls between the nodes of the coarse lattice."""
    out = np.full(points.shape, np.nan)
    out[np.abs(points[:, 1]) <= 1e-9] = 0.0
    out[in_patch(points)] = (0.0, -DEPTH_MM * MM, 0.0)
    return out


def test_a_region_decides_new_boundary_points_by_where_they_lie():
    """In a P2 solve a Region holds every vertical dof under the punch face at the full depth, also
    those of facets whose other vertices are free, whereas a plain dirichlet function leaves some
    of them unheld; there are more such dofs than mesh nodes under the face."""
    # P2 dofs on the top face inside the face are held, though their facets' other vertices
    # are free: what a plain dirichlet_fn (the facet rule) does not do
    s = CASE.settings(spacing_mm=SPACING)
    mesh = CASE.mesh("five", s)
    pts = mesh.points
    given = _face_only(pts)
    d = {int(i): tuple(given[i]) for i in np.flatnonzero(~np.isnan(given).any(axis=1))}
    for fn, all_held in ((Region(_face_only), True), (_face_only, False)):
        r = linear.solve(mesh, s.material, d, element="P2", dirichlet_fn=fn, solver="direct")
        under = (dof_component(r.basis) == 1) & in_patch(r.basis.doflocs.T)
        assert under.sum() > len(mesh.nodes_on_plane("y", 0.032)[in_patch(
            mesh.points[mesh.nodes_on_plane("y", 0.032)])])
        held = np.isclose(r.dofs[under], -DEPTH_MM * 1e-3, rtol=1e-12)
        assert bool(held.all()) is all_held
