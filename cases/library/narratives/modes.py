"""The modes case's report prose: what was run, its opening, findings, table cells and
figures, computed from the runs."""
import numpy as np
from . import sentences
from ...framework import Narrative
from ...reporting.document import fmt
from ..modes import SIZE_MM, NODES, N_MODES


class ModesNarrative(Narrative):
    notes = ("The table shows the first of the frequencies (f1) of the model and of FEM P2.",
             "Modes are paired by shape, not by rank (mass-weighted MAC): each model mode is "
             "explained by the fewest FEM modes whose span holds 0.8 of its shape; FEM modes "
             "a model mode needs jointly (the cube's degenerate pairs and triples, and modes "
             "a model's error mixes) form one group, paired with the model modes it explains "
             "in frequency order. A FEM mode without one is unpaired and left out of the "
             "errors; a spurious model mode, explained by none, does not shift every later "
             "frequency.")

    def references_line(self, s):
        return (f"Reference: FEM P2 modes (consistent mass) on {s.fem_refine} refinement(s) of "
                "the mesh, its estimate the largest change of the first 10 frequencies over "
                "the last refinement; no static reference.")

    def what_was_run(self, s, runs):
        return [f"Cube of side {SIZE_MM:g} mm, {NODES} x {NODES} x {NODES} lattice nodes; "
                "free-free and base clamped; FEM P2 with consistent mass on "
                f"{s.fem_refine} refinement(s). No static problem: the standard displacement "
                "and stress metrics are n/a."]

    def conclusion(self, s, runs):
        out = [sentences.best_and_worst([r for r in runs if r["bc"] == bc], "modal_rel_err",
                                     f"{bc}: first 10 frequencies", lost_key="modes_unpaired")
               for bc in s.bcs]
        odd = [f"{r['model']} on {r['mesh']}/{r['bc']} ({r['rigid_modes']})" for r in runs
               if r["rigid_modes"] != (6 if r["bc"] == "free" else 0)]
        out.append("Zero modes other than the rigid ones: " + ", ".join(odd) + "." if odd else
                   "Every model has exactly the rigid modes it should (6 free-free, 0 clamped).")
        return out

    def findings(self, s, runs):
        return {f"{bc}": sentences.ranking([r for r in runs if r["bc"] == bc], "modal_rel_err",
                                        "largest frequency error", lost_key="modes_unpaired")
                for bc in s.bcs}

    def cell(self, metric, run):
        if metric.name in ("frequencies_hz", "frequencies_fem_hz"):    # f1
            return fmt(run[metric.name][0] if run[metric.name] else None, 4)
        return super().cell(metric, run)

    def sections(self, doc, s, runs, fields, out):
        from ...reporting import figures
        for bc in s.bcs:
            rs = [r for r in runs if r["bc"] == bc and r["mesh"] == s.meshes[0]
                  and not r.get("failed")]
            if not rs:
                continue
            name = f"frequencies_{s.meshes[0]}_{bc}.png"
            k = np.arange(1, N_MODES + 1)
            figures.curves(out / name, k, rs[0]["frequencies_fem_hz"], "FEM P2",
                           [(r["model"], r["frequencies_hz"]) for r in rs], "mode number",
                           "frequency [Hz]", f"first {N_MODES} frequencies, mesh "
                           f"{s.meshes[0]}, {bc}")
            doc.img(name, f"First {N_MODES} frequencies, mesh {s.meshes[0]}, {bc}")
