"""A user's problem's report prose: its mesh, selections and loads as the TOML gave them, its
measures' notes, an opening and findings per measure, and each profile's figure, computed
from the runs."""
from ..narratives import sentences
from ...framework import MM, Narrative
from ...measuring.catalogue import err_name, ref_name
from ...reporting import figures
from .spec import AXES, nodes_said


class ProblemNarrative(Narrative):
    material_from = "the problem's [material]"
    glossary = "glossary.md"      # written into the problem's own folder: it lives anywhere

    @property
    def up(self):
        return AXES[self.case.spec.up]

    def command(self):
        return f"pbcm run --problem {self.case.spec.path}"

    def references_line(self, s):
        line = super().references_line(s)
        if self.case.spec.neohookean:
            line += (f" At the load: the converged neo-Hookean reference ({s.nh_levels} "
                     "refinement(s)).")
        return line

    def what_was_run(self, s, runs):
        spec = self.case.spec
        out = [f"The problem {spec.path.name}: mesh {spec.mesh_file.name} "
               f"({spec.mesh.n_nodes} nodes, {spec.mesh.n_tets} tetrahedra, lengths in "
               f"{spec.unit}, up {AXES[spec.up]})."]
        out += [f"Selection {sel.name}: {sel.text}, {nodes_said(len(sel.nodes))}."
                for sel in spec.selections.values()]
        out += [f"Prescribed on {held}." for held in spec.held]
        out += [f"Traction {list(f.value)} Pa on {f.on} ({len(f.faces)} boundary triangles)."
                for f in spec.surfaces]
        if spec.gravity:
            out.append(f"Gravity {spec.gravity:g} m/s^2 along -{AXES[spec.up]}.")
        return out

    def notes_for(self, s):
        return tuple(f"{m.name} ({m.key}): {m.text}." for m in self.case.spec.measures) + (
            "The FEM references refine the mesh as it is: their continuum is the body the "
            "tetrahedra fill (a curved surface stays faceted).",)

    def conclusion(self, s, runs):
        first = self.case.spec.measures[0]
        return [sentences.best_and_worst(runs, err_name(first.key), first.name),
                sentences.failures(runs)]

    def findings(self, s, runs):
        out = {m.name: sentences.ranking(runs, err_name(m.key), f"{m.name} error")
               for m in self.case.spec.measures}
        return out | {"Failures": [sentences.failures(runs)]}

    def sections(self, doc, s, runs, fields, out):
        for m in (m for m in self.case.spec.measures if not m.scalar):
            drawn = [r for r in runs if r.get(m.key) is not None]
            if not drawn:
                continue
            name = f"profile_{m.name}.png"
            figures.curves(out / name, m.positions / MM, drawn[0][ref_name(m.key)], "FEM P2",
                           [(r["model"], r[m.key]) for r in drawn],
                           f"{AXES[m.axis]} [mm]", f"u_{AXES[m.component]} [mm]",
                           f"{m.name}: u_{AXES[m.component]} along {AXES[m.axis]}")
            doc.img(name, f"The profile {m.name}, models against FEM P2")
