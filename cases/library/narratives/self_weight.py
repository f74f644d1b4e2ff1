"""The self-weight case's report prose: what was run, its opening and findings,
computed from the runs."""
from . import sentences
from ...framework import Narrative
from ..self_weight import SIZE_MM


class SelfWeightNarrative(Narrative):
    magnify = 10.0
    notes = (
        "Gravity reaches the particle model as consistent nodal forces, a quarter of rho g V0 "
        "of each tetrahedron at each of its vertices.",)

    def what_was_run(self, s, runs):
        return [f"Cube of side {SIZE_MM:g} mm, nodes every {s.spacing_mm:g} mm, under gravity "
                f"g = {s.g:g} m/s^2; sliding base (y held, rigid motions pinned) and clamped "
                "base. The sliding base is held in y at the closed form's own shape (u_y = "
                "nu rho g r^2 / 2E, r from the base centre), so that the closed form is exact."]

    def conclusion(self, s, runs):
        slide = [r for r in runs if r["bc"] == "sliding"]
        out = [sentences.best_and_worst(runs, "top_settlement_rel_err", "Top settlement",
                                     per_mesh=self.case.per_mesh_continuum)]
        # the closed form is read at each mesh's own top nodes: one pair per mesh
        pairs = {r["mesh"]: (r["top_settlement_fem_mm"], r["top_settlement_cf_mm"])
                 for r in slide if r.get("top_settlement_fem_mm") is not None
                 and r.get("top_settlement_cf_mm") is not None}
        if pairs:
            out.append("Sliding base, FEM P2 against the closed form read at the mesh's own top "
                       "nodes: " + "; ".join(f"{mesh} {fem:.6g} and {cf:.6g} mm"
                                             for mesh, (fem, cf) in pairs.items()) + "; "
                       + sentences.best_and_worst(slide, "top_settlement_cf_rel_err",
                                               "against the closed form", exact=True))
        out.append(sentences.failures(runs))
        return out

    def findings(self, s, runs):
        return {bc: sentences.ranking([r for r in runs if r["bc"] == bc],
                                   "top_settlement_rel_err", "settlement error",
                                   per_mesh=self.case.per_mesh_continuum)
                for bc in s.bcs} | {"Failures": [sentences.failures(runs)]}
