"""The problems of the convergence study: cases of the library meshed at a given spacing, with
their loads scaled down to the linear regime.

Each problem borrows its geometry, boundary conditions, loads and quantity of interest from
its case in the library (``cases.library``), so the study measures the same problems the case
reports do, at several mesh sizes. The loads are scaled by ``load_scale`` (default 1e-3) so
that every model answers in its linear regime and its limit h -> 0 is the linear continuum:
what stays then is the model's own consistency limit, not geometric nonlinearity (the subject
of large-compression).
"""
from dataclasses import dataclass

import numpy as np

from ...framework import MM, Loads, Traction
from ...library import common
from ...registry import CASES
from ...running.runner import reaction_along


@dataclass(frozen=True)
class Problem:
    """A case of the library as the study runs it.

    ``dims_mm`` the box (x, y, z); ``bcs`` its boundary conditions; ``response`` how its
    stiffness is read: 'driven' (the force on the case's driven nodes), or the name of a
    quantity of interest; ``compliance`` True when that quantity is a displacement under a
    given load (its ratio is then FEM over model, so that above 1 is always stiffer)."""

    case: str
    dims_mm: tuple
    bcs: tuple
    response: str
    compliance: bool = False
    label: str = ""
    ref_ladder_mm: tuple = (8.0, 4.0, 2.0)   # spacings of the reference's P2 levels
    ref_fine_solver: str = None              # the solver of levels below 2 mm (None: the case's)
    # why a level where every model's error is the same tests nothing, ``{cells}`` the cells
    # across the section at that spacing (None: no reason known beyond the runs)
    blind_reason: str = None

    def blind_why(self, h_mm):
        """Why the level at ``h_mm`` tests nothing, where the problem knows (None else)."""
        if self.blind_reason is None:
            return None
        n = self.nodes_per_side(h_mm)
        return self.blind_reason.format(cells=n[1] - 1, nodes=n[1])

    def ref_solver(self, h_mm):
        return self.ref_fine_solver if self.ref_fine_solver and h_mm < 2.0 \
            else self.spec.fem_solver

    @property
    def spec(self):
        return CASES[self.case]

    def settings(self, E, nu):
        return self.spec.settings(E=E, nu=nu)

    def mesh(self, family, h_mm):
        """The box meshed by ``family`` with nodes every ``h_mm`` (SI units out)."""
        return common.bar(family, *self.dims_mm, h_mm)

    def nodes_per_side(self, h_mm):
        return [int(round(d / h_mm)) + 1 for d in self.dims_mm]

    def cost(self, h_mm):
        """The expected cost of a solve at spacing ``h_mm``, to schedule the dearest work
        first: sparse solves grow about as nodes^1.3."""
        return float(np.prod(self.nodes_per_side(h_mm))) ** 1.3

    def reference_cost(self, ladder=None):
        """The expected cost of the reference's ladder (or of the spacings ``ladder``)."""
        return sum(self.cost(h) for h in (ladder or self.ref_ladder_mm))

    def dirichlet(self, mesh, bc, s, scale):
        """The case's prescribed displacements of the linear regime times ``scale``."""
        return {k: tuple(None if v is None else v * scale for v in val)
                for k, val in self.spec.dirichlet_linear(mesh, bc, s).items()}

    def loads(self, mesh, bc, s, scale):
        """The case's loads times ``scale``."""
        loads = self.spec.loads(mesh, bc, s)
        return Loads(tractions=tuple(Traction(t.axis, t.at, tuple(v * scale for v in t.value))
                                     for t in loads.tractions),
                     body_force=None if loads.body_force is None
                     else tuple(v * scale for v in loads.body_force))

    def response_value(self, mesh, u, reaction, bc, s):
        """The scalar the stiffness ratio compares (N, N m or m)."""
        if self.response == "driven":
            return float(reaction_along(reaction, self.spec.driven(mesh, bc, s)))
        value = self.spec.quantities(mesh, u, reaction, s, bc)[self.response]
        return value * MM if self.response.endswith("_mm") else value

    def ratio(self, model, fem):
        """Stiffness ratio: model over FEM for a force, FEM over model for a displacement."""
        if model == 0 or fem == 0 or not np.isfinite(model):
            return None
        return float(fem / model) if self.compliance else float(model / fem)

    def reference_on_reference_mesh(self):
        """Whether the FEM value of the response is taken on the reference mesh (a force: a
        total over a face, the same for any mesh) rather than from the reference's
        displacement at the model's own nodes (a displacement averaged over them)."""
        return not self.compliance


PROBLEMS = {
    "paper-cube": Problem("paper-cube", (common.CUBE_MM,) * 3, ("clamped", "sliding"), "driven",
                          label="top force"),
    "cantilever": Problem("cantilever", common.BAR_MM, ("clamped",), "tip_deflection_mm",
                          compliance=True, label="load / tip deflection"),
    # P2 converges at order 1 here (the clamped root restrains the warping): a fourth level,
    # solved by AMG-CG (the direct solver's fill at that size needs several GB)
    "torsion": Problem("torsion", common.BAR_MM, ("clamped",), "torque_nm",
                       label="torque", ref_ladder_mm=(8.0, 4.0, 2.0, 4.0 / 3.0),
                       ref_fine_solver="amg",
                       # checked by the tests on the five lattice at 8 mm: FEM P1's solution
                       # is the rigid turn's interpolant to round-off, every model's within 1e-3
                       blind_reason="the 16 mm section is {cells} cells across there, "
                       "{nodes} x {nodes} nodes with the axis node alone inside: each section "
                       "turns rigidly, without warping, whatever the model, and the error is "
                       "that field's distance to the continuum"),
}

__all__ = ["Problem", "PROBLEMS"]
