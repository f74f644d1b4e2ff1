"""Indentation: a 32 mm cube on a clamped base, pressed 2 mm by a rigid punch whose flat
8 x 8 mm face has a 4 mm sloping rim (the surface under the rim is pulled down linearly from
the face's depth to nothing), the pressed surface held by the punch (no slip), in load steps:
punch force, the surface profile along the centre line, and the peak shear stress under the
edge of the punch's face.

The punch is one displacement field declared by geometry (``punch``): each model prescribes
it at its top nodes, the references (a ``reference.discretisation.Region``) at every boundary point of
every refinement, so every mesh and every model poses the same continuum problem. The rim
keeps the prescribed field continuous: a square prescribed alone would be a different
problem for a model (whose free neighbours taper it over one element) and for a refined
reference (which resolves the step)."""
from dataclasses import dataclass

import numpy as np

from model.mesh import cube
from model.terms.shear import Shear
from ..measuring import metrics as M
from reference.discretisation import Region
from ..measuring.error_model import Scalar
from ..framework import Case, Knob, MM, Settings
from . import common

SIZE_MM, PATCH_MM, DEPTH_MM = common.CUBE_MM, 8.0, 2.0
RIM_MM = 4.0  # the width over which the punch's rim slopes from the face's depth to nothing
STEPS = 4     # load steps of every model and of the neo-Hookean reference
DEVIATES = 0.1  # a surface profile this far from FEM's (relative L2) is drawn in colour


@dataclass
class IndentationSettings(Settings):
    spacing_mm: float = 4.0
    steps: int = STEPS

    def problem(self):
        return {**super().problem(), "size_mm": SIZE_MM, "patch_mm": PATCH_MM,
                "rim_mm": RIM_MM, "depth_mm": DEPTH_MM, "spacing_mm": self.spacing_mm,
                "steps": self.steps, "punch": "square face and sloping rim declared by geometry"}


def in_patch(points, grow=0.0):
    """Whether points (k, 3) [m] lie on the top face inside the centred square patch (grown
    by ``grow`` m on each side)."""
    half, c = PATCH_MM * MM / 2 + grow + 1e-9, SIZE_MM * MM / 2
    return ((np.abs(points[:, 1] - SIZE_MM * MM) <= 1e-9)
            & (np.abs(points[:, 0] - c) <= half) & (np.abs(points[:, 2] - c) <= half))


def _from_centre_mm(points):
    """The distance of points (k, 3) [m] from the top face's centre in the max norm [mm]."""
    c = SIZE_MM * MM / 2
    return np.maximum(np.abs(points[:, 0] - c), np.abs(points[:, 2] - c)) / MM


def pressed_fraction(points):
    """The punch's depth at points (k, 3) [m] as a fraction of the face's: 1 under the face,
    falling linearly to 0 across the rim, 0 beyond (the top face's (x, z) alone)."""
    return np.clip((PATCH_MM / 2 + RIM_MM - _from_centre_mm(points)) / RIM_MM, 0.0, 1.0)


def punch(points):
    """The prescribed displacement by where a boundary point lies: held on the base, pressed
    down under the punch's face and rim (held there in x and z), free elsewhere (NaN). The
    rim's outer edge is held too (at 0): the prescribed surface is closed, as a Dirichlet
    boundary is, so a node there carries the field's value and every mesh's nodal values
    interpolate one field."""
    out = np.full(points.shape, np.nan)
    out[np.abs(points[:, 1]) <= 1e-9] = 0.0
    f = pressed_fraction(points)
    under = ((np.abs(points[:, 1] - SIZE_MM * MM) <= 1e-9)
             & (_from_centre_mm(points) <= PATCH_MM / 2 + RIM_MM + 1e-6))
    out[under] = 0.0
    out[under, 1] = -DEPTH_MM * MM * f[under]
    return out


def _top(mesh):
    return mesh.nodes_on_plane("y", SIZE_MM * MM)


def _patch(mesh, grow=0.0):
    """Top nodes inside the centred patch (grown by ``grow`` m on each side)."""
    top = _top(mesh)
    return top[in_patch(mesh.points[top], grow)]


def centre_line(mesh, spacing):
    """Top nodes on the centre line z = L/2 (within a quarter spacing: the unstructured
    meshes move face nodes within the face), ordered by x."""
    top = _top(mesh)
    on = top[np.abs(mesh.points[top, 2] - SIZE_MM * MM / 2) <= 0.25 * spacing]
    return on[np.argsort(mesh.points[on, 0])]


def edge_tets(mesh, spacing):
    """Tetrahedra touching a patch node on the punch's edge (a patch node with a top
    neighbour outside the patch)."""
    patch = set(_patch(mesh).tolist())
    ring = set(_patch(mesh, grow=1.01 * spacing).tolist()) - patch
    edge_nodes = {int(i) for i in patch
                  if any(int(j) in ring for t in mesh.tets[(mesh.tets == i).any(axis=1)]
                         for j in t)}
    return np.flatnonzero(np.isin(mesh.tets, list(edge_nodes)).any(axis=1))


class Indentation(Case):
    narrative = "cases.library.narratives.indentation:IndentationNarrative"
    name = "indentation"
    resolution = Knob("spacing_mm", "lattice spacing [mm]")
    title = (f"Indentation of a {SIZE_MM:g} mm cube on a clamped base by a rigid punch, an "
             f"{PATCH_MM:g} x {PATCH_MM:g} mm flat face with a {RIM_MM:g} mm sloping rim, pressed "
             f"{DEPTH_MM:g} mm (punch force, surface profile, shear under the edge of the punch's "
             "face)")
    settings_class = IndentationSettings
    bcs = ("clamped",)
    headline = "reaction_rel_err"
    headline_pair = "disp_rel_l2_p2"
    decomposed = Scalar("reaction_n", "reaction_fem_p2_n", "punch force")
    qoi_errors = ()          # the edge shear is singular: no error against a reference
    # the edge shear gated as each model's own value (a regression), never compared
    gated = ("edge_shear_pa", "profile_rel_err")
    columns = ("reaction_n", "reaction_fem_p2_n", "profile_rel_err", "edge_shear_pa",
               "edge_shear_fem_pa")

    def mesh(self, family, s):
        n = int(round(SIZE_MM / s.spacing_mm)) + 1
        return cube(n, SIZE_MM * MM, family)

    def dirichlet(self, mesh, bc, s):
        nodes = np.concatenate([mesh.nodes_on_plane("y", 0.0), _top(mesh)])
        given = punch(mesh.points[nodes])
        held = ~np.isnan(given).any(axis=1)
        return {int(i): tuple(v) for i, v in zip(nodes[held], given[held])}

    def dirichlet_fn(self, mesh, bc, s):
        return Region(punch)

    def driven(self, mesh, bc, s):
        # the whole top: the punch force on the models (their free top nodes carry none) and
        # on the references, whose refined punch points beside the patch nodes hand their
        # force to top nodes outside it (the P1 hats of the top face)
        return _top(mesh), 1

    def finite_steps(self, s):
        return s.steps

    def solve_static(self, pm, mesh, bc, s, ref):
        return pm.solve_static(ref.dirichlet, load_steps=s.steps)

    def quantities(self, mesh, u, reaction, s, bc):
        line = centre_line(mesh, s.spacing_mm * MM)
        tau = Shear(mesh, s.material, reading="corner").max_tau(mesh.points + u)
        edge = edge_tets(mesh, s.spacing_mm * MM)
        if not edge.size:
            raise M.MetricError("no tetrahedron touches the punch's edge on this mesh")
        return {"surface_profile_mm": (u[line, 1] / MM).tolist(),
                "edge_shear_pa": float(tau[edge].max())}

    def run_extra(self, pm, mesh, bc, s, ref, st):
        if st is None:
            return {"profile_rel_err": None}
        line = centre_line(mesh, s.spacing_mm * MM)
        return {"profile_rel_err": M.rel_l2(st.u[line, 1], ref.p2.u[line, 1])}

CASE = Indentation()
