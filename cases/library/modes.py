"""Modes: the 32 mm cube (5 x 5 x 5 nodes, as the paper's) free-free and with its base
clamped; the first 10 frequencies of every model linearised at rest against FEM P2."""
from dataclasses import dataclass

import numpy as np

from model.mesh import cube
from . import transient
from ..reporting.document import fmt
from ..measuring.error_model import P1_LINEAR, Norm
from ..framework import MM, Case, Reference, Settings
from . import common

SIZE_MM, NODES = common.CUBE_MM, 5
N_MODES = transient.N_MODES


@dataclass
class ModesSettings(Settings):
    fem_refine: int = 1        # refinements of the FEM P2 modal reference

    def problem(self):
        return {**super().problem(), "size_mm": SIZE_MM, "nodes_per_side": NODES,
                "modes": N_MODES, "fem_refine": self.fem_refine}


class Modes(Case):
    name = "modes"
    title = ("The first 10 frequencies of the 32 mm cube, free-free and with a clamped base, "
             "of every model linearised at rest, against FEM P2")
    settings_class = ModesSettings
    static = False
    bcs = ("free", "clamped")
    quick = {"fem_refine": 0}
    headline = "modal_rel_err"
    decomposed = Norm("modal_rel_err_p1", "modal_rel_err", "first 10 frequencies",
                      unpaired="modes_unpaired_p1", unpaired_total="modes_unpaired",
                      count=N_MODES)
    gated = ("modal_rel_err", "modal_rel_err_median", "rigid_modes", "modes_unpaired")
    columns = ("frequencies_hz", "frequencies_fem_hz", "modal_rel_err", "modal_rel_err_median",
               "modes_unpaired", "modal_rel_err_p1", "modes_unpaired_p1", "rigid_modes")
    notes = ("The table shows the first of the frequencies (f1) of the model and of FEM P2.",
             "Modes are paired by shape, not by rank (mass-weighted MAC): each model mode is "
             "explained by the fewest FEM modes whose span holds 0.8 of its shape; FEM modes "
             "a model mode needs jointly (the cube's degenerate pairs and triples, and modes "
             "a model's error mixes) form one group, paired with the model modes it explains "
             "in frequency order. A FEM mode without one is unpaired and left out of the "
             "errors; a spurious model mode, explained by none, does not shift every later "
             "frequency.")

    def mesh(self, family, s):
        return cube(NODES, SIZE_MM * MM, family)

    def dirichlet(self, mesh, bc, s):
        if bc == "free":
            return {}
        return {int(i): (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("y", 0.0)}

    def solve_reference(self, mesh, bc, s, probe):
        dirichlet = self.dirichlet(mesh, bc, s)
        skip = 6 if bc == "free" else 0
        (freq, shapes), each = transient.fem_frequencies(mesh, s.material, dirichlet,
                                                         s.fem_refine, skip)
        # FEM P1 on the same tetrahedra with the models' lumped mass: the model-form twin
        p1_freq, p1_shapes, _ = transient.first_modes(
            self.build_model(P1_LINEAR, mesh, s), self._free(mesh, dirichlet),
            rigid_expected=skip)
        return Reference(dirichlet=dirichlet, f_ext=None, p1=None, conv=None, p2=None,
                         tau=None, reaction=None, quantities={},
                         error_estimate=None if each is None else float(each.max()),
                         extra={"frequencies_hz": freq, "shapes": shapes,
                                "estimates": None if each is None else each.tolist(),
                                "p1_frequencies_hz": p1_freq, "p1_shapes": p1_shapes})

    @staticmethod
    def _free(mesh, dirichlet):
        """The (3n,) mask of the components the constraints leave free."""
        mask = np.zeros((mesh.n_nodes, 3), dtype=bool)
        for i in dirichlet:
            mask[i] = True
        return ~mask.ravel()

    def solve_static(self, pm, mesh, bc, s, ref):
        return None

    def reference_entries(self, ref):
        return {"frequencies_fem_hz": ref.extra["frequencies_hz"][:N_MODES].tolist(),
                "frequencies_fem_estimate": ref.extra["estimates"]}

    def run_extra(self, pm, mesh, bc, s, ref, st):
        freq, shapes, rigid = transient.first_modes(pm, self._free(mesh, ref.dirichlet))
        worst, median, lost = transient.paired_errors(
            freq, shapes, ref.extra["frequencies_hz"], ref.extra["shapes"], "modal_rel_err",
            mass=pm.mass)
        worst_p1, _, lost_p1 = transient.paired_errors(
            freq, shapes, ref.extra["p1_frequencies_hz"], ref.extra["p1_shapes"],
            "modal_rel_err_p1", mass=pm.mass)
        return {"frequencies_hz": freq[:N_MODES].tolist(), "rigid_modes": rigid,
                "modes_unpaired": lost, "modal_rel_err": worst,
                "modal_rel_err_median": median, "modal_rel_err_p1": worst_p1,
                "modes_unpaired_p1": lost_p1}

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
        out = [common.best_and_worst([r for r in runs if r["bc"] == bc], "modal_rel_err",
                                     f"{bc}: first 10 frequencies", lost_key="modes_unpaired")
               for bc in s.bcs]
        odd = [f"{r['model']} on {r['mesh']}/{r['bc']} ({r['rigid_modes']})" for r in runs
               if r["rigid_modes"] != (6 if r["bc"] == "free" else 0)]
        out.append("Zero modes other than the rigid ones: " + ", ".join(odd) + "." if odd else
                   "Every model has exactly the rigid modes it should (6 free-free, 0 clamped).")
        return out

    def findings(self, s, runs):
        return {f"{bc}": common.ranking([r for r in runs if r["bc"] == bc], "modal_rel_err",
                                        "largest frequency error", lost_key="modes_unpaired")
                for bc in s.bcs}


    def cell(self, metric, run):
        if metric.name in ("frequencies_hz", "frequencies_fem_hz"):    # f1
            return fmt(run[metric.name][0] if run[metric.name] else None, 4)
        return super().cell(metric, run)

    def sections(self, doc, s, runs, fields, out):
        from ..reporting import figures
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


CASE = Modes()
