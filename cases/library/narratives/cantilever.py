"""The cantilever's report prose: what was run, its opening and findings, computed
from the runs."""
from . import sentences
from ...framework import Narrative
from ..cantilever import LENGTH_MM, HEIGHT_MM, WIDTH_MM


class CantileverNarrative(Narrative):
    magnify = 3.0
    notes = (
        "The load reaches the particle model as consistent nodal forces (a third of traction x "
        "area of each face triangle to its vertices), FEM integrates the traction itself.",)

    def what_was_run(self, s, runs):
        return [f"Beam {LENGTH_MM:g} x {HEIGHT_MM:g} x {WIDTH_MM:g} mm, nodes every "
                f"{s.spacing_mm:g} mm; x = 0 fully clamped; {s.load_N * 1e3:g} mN in -y as a "
                "uniform traction on x = L."]

    def conclusion(self, s, runs):
        cf = self.case.closed_form(s, "clamped")["tip_deflection_mm"]
        solved = [r for r in runs if r.get("tip_deflection_mm") is not None]
        out = [sentences.best_and_worst(runs, "tip_deflection_rel_err", "Tip deflection")]
        if solved:
            fem = solved[0]["tip_deflection_fem_mm"]
            out.append(f"FEM P2 deflects {fem:.4g} mm ({solved[0]['mesh']}), the closed form "
                       f"{cf:.4g} mm: a fully clamped root is stiffer than beam theory's.")
            soft = sorted({r["model"] for r in solved
                           if r["tip_deflection_mm"] > r["tip_deflection_fem_mm"]})
            out.append("Softer than FEM in bending: " + (", ".join(soft) or "none") + ". "
                       + sentences.failures(runs))
        return out

    def findings(self, s, runs):
        cf = self.case.closed_form(s, "clamped")["tip_deflection_mm"]
        return {"Bending stiffness": sentences.ranking(runs, "tip_deflection_rel_err",
                                                    "tip deflection error"),
                "Reference against the closed form": sentences.vs_closed_form(
                    "tip deflection", runs, "tip_deflection_fem_mm", cf, "mm"),
                "Failures": [sentences.failures(runs)]}
