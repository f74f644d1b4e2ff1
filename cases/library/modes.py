"""Modes: the 32 mm cube (5 x 5 x 5 nodes, as the paper's) free-free and with its base
clamped; the first 10 frequencies of every model linearised at rest against FEM P2."""
from dataclasses import dataclass

import numpy as np

from model.mesh import cube
from . import transient
from ..measuring.error_model import P1_LINEAR, Norm
from ..framework import MM, Case, Reference, Settings
from . import common

SIZE_MM, NODES = common.CUBE_MM, common.PAPER_NODES
N_MODES = transient.N_MODES


@dataclass
class ModesSettings(Settings):
    fem_refine: int = 1        # refinements of the FEM P2 modal reference

    def problem(self):
        return {**super().problem(), "size_mm": SIZE_MM, "nodes_per_side": NODES,
                "modes": N_MODES, "fem_refine": self.fem_refine}


class Modes(Case):
    narrative = "cases.library.narratives.modes:ModesNarrative"
    name = "modes"
    title = (f"The first {N_MODES} frequencies of the {SIZE_MM:g} mm cube, free-free and with a "
             "clamped base, of every model linearised at rest, against FEM P2")
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

CASE = Modes()
