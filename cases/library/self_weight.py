"""Self-weight: a 32 mm block standing on its base under gravity. Sliding base: closed form
(a prismatic block under its own weight, exact in 3-D); clamped base: FEM. Top settlement."""
from dataclasses import dataclass

import numpy as np

from model.bc import merge
from model.mesh import cube
from reference import analytic
from ..measuring import metrics as M
from ..measuring.error_model import Scalar
from ..framework import FINDINGS, Case, Knob, Loads, MM, Settings
from . import common

SIZE_MM = common.CUBE_MM
GRAVITY = 9.81


@dataclass
class SelfWeightSettings(Settings):
    spacing_mm: float = 4.0
    g: float = GRAVITY

    def problem(self):
        return {**super().problem(), "size_mm": SIZE_MM, "spacing_mm": self.spacing_mm,
                "g_m_s2": self.g}


def _top(mesh):
    return mesh.nodes_on_plane("y", SIZE_MM * MM)


class SelfWeight(Case):
    narrative = "cases.library.narratives.self_weight:SelfWeightNarrative"
    name = "self-weight"
    resolution = Knob("spacing_mm", "lattice spacing [mm]")
    load = Knob("g", "gravity [m/s^2]")
    title = (f"A {SIZE_MM:g} mm block settling under its own weight, base sliding (closed form) "
             "or clamped (FEM)")
    settings_class = SelfWeightSettings
    bcs = ("sliding", "clamped")
    # sliding: the closed form read at each mesh's own top nodes (its lateral term depends on
    # where they are), so each mesh's continuum value is its own problem's, not a spread
    per_mesh_continuum = ("sliding",)
    # quick (CI): nodes every 8 mm, where the references' refined P2 level has 12 819
    # unknowns instead of 92 451 (the suite's costliest reference at 4 mm: a minute)
    quick = {"spacing_mm": 8.0}
    headline = "top_settlement_rel_err"
    headline_pair = "disp_rel_l2_p2"
    decomposed = Scalar("top_settlement_mm", "top_settlement_fem_mm", "top settlement")
    qoi_errors = ("top_settlement_mm",)
    gated = ("top_settlement_rel_err", "top_settlement_cf_rel_err")
    columns = ("top_settlement_mm", "top_settlement_fem_mm", "top_settlement_cf_mm",
               "top_settlement_rel_err", "top_settlement_cf_rel_err")

    def mesh(self, family, s):
        return cube(int(round(SIZE_MM / s.spacing_mm)) + 1, SIZE_MM * MM, family)

    def dirichlet(self, mesh, bc, s):
        base = mesh.nodes_on_plane("y", 0.0)
        if bc == "clamped":
            return {int(i): (0.0, 0.0, 0.0) for i in base}
        # sliding: the base held in y at the closed form's own shape (it is not flat: u_y =
        # nu rho g r^2 / 2E there, up to 0.11 mm at the corners), so that the closed form is
        # the exact solution; the base centre pinned and one axis node held in z remove the
        # rigid motions without restraining the lateral contraction
        exact = self.exact(mesh.points[base], s)
        p = mesh.points[base]
        c = SIZE_MM * MM / 2
        # (at their closed-form values: on an unstructured base no node sits on the axis)
        k = np.argmin(np.hypot(p[:, 0] - c, p[:, 2] - c))
        j = np.argmin(np.hypot(p[:, 0] - 2 * c, p[:, 2] - c))
        return merge([(int(i), (None, float(uy), None)) for i, uy in zip(base, exact[:, 1])]
                     + [(int(base[k]), tuple(map(float, exact[k]))),
                        (int(base[j]), (None, None, float(exact[j, 2])))])

    def dirichlet_fn(self, mesh, bc, s):
        return None if bc == "clamped" else (lambda points: self.exact(points, s))

    def exact(self, points, s):
        """The closed form (reference.analytic.self_weight) at points [m] of this block."""
        shift = np.array([SIZE_MM * MM / 2, 0.0, SIZE_MM * MM / 2])
        return analytic.self_weight(points - shift, s.material, s.g, SIZE_MM * MM)

    def loads(self, mesh, bc, s):
        return Loads(body_force=(0.0, -s.rho * s.g, 0.0))

    def quantities(self, mesh, u, reaction, s, bc):
        return {"top_settlement_mm": float(-u[_top(mesh), 1].mean() / MM)}

    def settlement_closed_form(self, mesh, s):
        """The closed form's mean settlement over ``mesh``'s top nodes [mm] (the lateral
        term nu rho g r^2 / 2E depends on where the nodes are)."""
        return float(-self.exact(mesh.points[_top(mesh)], s)[:, 1].mean() / MM)

    def closed_form(self, s, bc):
        if bc != "sliding":
            return {}
        return {"top_settlement_mm": self.settlement_closed_form(self.mesh("five", s), s)}

    def run_extra(self, pm, mesh, bc, s, ref, st):
        if bc != "sliding":
            return {"top_settlement_cf_mm": None, "top_settlement_cf_rel_err": None}
        cf = self.settlement_closed_form(mesh, s)
        # the closed form is linear elasticity: it judges the linear regime's settlement
        # (scaled to the case's load), never the finite-load one (a law's nonlinearity
        # would be scored as error)
        try:
            lin = self.solve_linear(pm, mesh, bc, s, ref)
        except FINDINGS:
            return {"top_settlement_cf_mm": cf, "top_settlement_cf_rel_err": None}
        settle = float(-lin.u[_top(mesh), 1].mean() / ref.scale / MM)
        return {"top_settlement_cf_mm": cf, "top_settlement_cf_rel_err": M.finite(
            "top_settlement_cf_rel_err", abs(settle / cf - 1))}

CASE = SelfWeight()
