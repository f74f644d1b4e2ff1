"""The torsion case's report prose: what was run, its opening and findings, computed
from the runs."""
from . import sentences
from ...framework import Narrative
from ..torsion import LENGTH_MM, SIDE_MM


class TorsionNarrative(Narrative):
    magnify = 1.0
    notes = (
        "The torque's arms are rest positions: the frame of linear FEM's equilibrium. "
        "Saint-Venant's free warping of a square is not zero; the clamped root restrains it.",
        "In the linear regime the end face gets the linearised rotation u = theta e_x x r, "
        "against linear FEM and Saint-Venant; at the case's angle it gets the exact rotation, "
        "against the neo-Hookean reference (linear FEM would read an exact rotation as a "
        "small strain: a radial contraction of 1 - cos(angle) of the radius at the face, "
        "which is what fem-linear's error there measures).")

    def what_was_run(self, s, runs):
        return [f"Bar {LENGTH_MM:g} mm along x, square section {SIDE_MM:g} mm, nodes every "
                f"{s.spacing_mm:g} mm; x = 0 clamped; the x = L face turned {s.angle_deg:g} "
                "degrees about the axis (y, z prescribed, x free)."]

    def conclusion(self, s, runs):
        cf = self.case.closed_form(s, "clamped")["torque_nm"]
        out = [sentences.best_and_worst(runs, "torque_rel_err", "Torque"),
               sentences.best_and_worst(runs, "warping_rel_err", "End-face warping")]
        ok = [r for r in runs if r.get("torque_fem_nm") is not None]
        if ok:
            ratio = ok[0]["torque_fem_nm"] / cf
            why = ("stiffer than Saint-Venant's free warping: the clamped root restrains it"
                   if ratio > 1.02 else "within 2 % of Saint-Venant")
            out.append(f"FEM P2 needs {ok[0]['torque_fem_nm']:.4g} N m ({ok[0]['mesh']}), "
                       f"Saint-Venant {cf:.4g} N m (ratio {ratio:.3f}: {why}). "
                       + sentences.failures(runs))
        return out

    def findings(self, s, runs):
        cf = self.case.closed_form(s, "clamped")["torque_nm"]
        stiff = sentences.per_run(runs, lambda r: None if r.get("torque_nm") is None
                               else r["torque_nm"] > r["torque_fem_nm"],
                               "Stiffer than FEM in torsion")
        return {"Torsional stiffness": sentences.ranking(runs, "torque_rel_err", "torque error")
                + [stiff],
                "Warping": sentences.ranking(runs, "warping_rel_err", "warping error"),
                "Reference against Saint-Venant": sentences.vs_closed_form(
                    "torque", runs, "torque_fem_nm", cf, "N m"),
                "Failures": [sentences.failures(runs)]}
