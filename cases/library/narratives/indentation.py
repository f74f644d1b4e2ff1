"""The indentation case's report prose: what was run, its opening, findings and
figures, computed from the runs."""
from . import sentences
from ..indentation import SIZE_MM, PATCH_MM, DEPTH_MM, RIM_MM, DEVIATES, centre_line
from ...framework import MM, Narrative


class IndentationNarrative(Narrative):
    magnify = 2.0
    notes = (
        "The punch force is the reaction on the top face along y (the punch's: the rest of "
        "the top is free).",
        "The prescribed field has kinks at the edges of the punch's face and rim: the "
        "continuum's shear there is not bounded (it grows as the mesh is refined), so no "
        "error of the edge shear against a reference is taken: each model's own value is "
        "shown and gated as a regression, never compared or ranked.")

    def what_was_run(self, s, runs):
        return [f"Cube of side {SIZE_MM:g} mm, nodes every {s.spacing_mm:g} mm, base clamped; "
                f"the centred {PATCH_MM:g} x {PATCH_MM:g} mm face of the punch moves the top "
                f"(0, -{DEPTH_MM:g}, 0) mm in {s.steps} load steps, its {RIM_MM:g} mm rim "
                "slopes linearly to the free surface (the punch holds what it presses): one "
                "displacement field, prescribed at the models' top nodes and at the "
                "references' every boundary point of every refinement."]

    def conclusion(self, s, runs):
        return [sentences.best_and_worst(runs, "reaction_rel_err", "Punch force"),
                sentences.best_and_worst(runs, "profile_rel_err", "Surface profile"),
                "The shear under the edge of the punch's face is not bounded in the continuum "
                "(it grows as the mesh is refined): its values are in the tables, never "
                "ranked. " + sentences.failures(runs)]

    def findings(self, s, runs):
        stiff = sentences.per_run(runs, lambda r: None if r.get("reaction_ratio") is None
                               else r["reaction_ratio"] > 1, "Stiffer than FEM under the punch")
        return {"Punch force": sentences.ranking(runs, "reaction_rel_err", "force error")
                + [stiff],
                "Surface profile": sentences.ranking(runs, "profile_rel_err", "profile error"),
                "Failures": [sentences.failures(runs)]}

    def sections(self, doc, s, runs, fields, out):
        from ...reporting import figures
        for mesh in s.meshes:
            rs = [r for r in runs if r["mesh"] == mesh and not r.get("failed")]
            if not rs:
                continue
            m = fields[(mesh, "clamped", "fem-p2")]["mesh"]
            x = m.points[centre_line(m, s.spacing_mm * MM), 0] / MM
            name = f"profile_{mesh}.png"
            drawn = [r for r in rs if r["surface_profile_mm"] is not None]
            figures.curves(out / name, x, rs[0]["surface_profile_fem_mm"], "FEM P2",
                           [(r["model"], r["surface_profile_mm"]) for r in drawn],
                           "x along the centre line [mm]", "u_y of the top surface [mm]",
                           f"surface profile under the punch, mesh {mesh}",
                           highlight={r["model"] for r in drawn
                                      if (r.get("profile_rel_err") or 0.0) > DEVIATES})
            doc.img(name, f"Surface profile along the centre line, mesh {mesh}")
