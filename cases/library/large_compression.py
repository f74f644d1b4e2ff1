"""Large compression: the paper's cube on a sliding base pushed to 30 % (9.6 mm) in 6 load
steps, against the neo-Hookean reference (and linear FEM, to show where it fails): the
force-strain curve and the lateral expansion at each step."""
from dataclasses import dataclass, field

import numpy as np

from model.mesh import cube
from reference import hyperelastic, linear
from .. import figures
from .. import metrics as M
from ..framework import Case, Knob, MM, Reference, Settings
from . import common

SIZE_MM, NODES = 32.0, 5
PUSH_MM, STEPS = 9.6, 6
LAYERS_MM = (0.0, 8.0, 16.0, 24.0, 32.0)


@dataclass
class LargeCompressionSettings(Settings):
    push_mm: float = PUSH_MM
    steps: int = STEPS

    def problem(self):
        return {**super().problem(), "size_mm": SIZE_MM, "nodes_per_side": NODES,
                "push_mm": self.push_mm, "steps": self.steps, "reference": "neo-Hookean P2"}


def dirichlet_at(mesh, push):
    """The sliding cube with its top pushed down ``push`` [m]."""
    top, _, held = common.cube_boundary_sets(mesh, "sliding", SIZE_MM * MM)
    out = dict(held)
    out.update({int(i): (None, -push, None) for i in top})
    return out


def lateral_strain(mesh, u):
    """Mean outward lateral displacement of the side-face nodes over the five layers, over
    the half side: the lateral expansion as a strain."""
    profile = M.layer_profile(mesh.points, u, [y * MM for y in LAYERS_MM], SIZE_MM * MM)
    return float(profile.mean() / (SIZE_MM * MM / 2))


def top_force(mesh, reaction):
    top = common.cube_boundary_sets(mesh, "sliding", SIZE_MM * MM)[0]
    return float(-reaction[top, 1].sum())


@dataclass
class Curve:
    """A static solution with its force and lateral strain at every load step."""

    final: object
    force: list = field(default_factory=list)
    lateral: list = field(default_factory=list)

    def __getattr__(self, name):       # the final StaticResult's x, u, reaction, residual
        return getattr(self.final, name)


class LargeCompression(Case):
    name = "large-compression"
    load = Knob("push_mm", "push [mm]")
    title = ("The paper's cube on a sliding base pushed to 30 % (9.6 mm) in 6 steps, against "
             "neo-Hookean FEM (and linear FEM, to show where it fails)")
    settings_class = LargeCompressionSettings
    meshes = ("five", "six", "bcc", "unstructured")
    bcs = ("sliding",)
    headline = "force_rel_err_max"
    gated = ("force_rel_err_max", "lateral_rel_err_max")
    columns = ("reaction_n", "reaction_fem_p2_n", "force_rel_err_max", "lateral_rel_err_max",
               "linear_force_rel_err_max")
    magnify = 1.0
    notes = (
        "The reference of this case is neo-Hookean (compressible, the law of "
        "reference.hyperelastic): 'FEM P1' is neo-Hookean P1 on the mesh, 'FEM P2' neo-Hookean "
        "P2 on the mesh (the hyperelastic solver does not refine, so it has no error estimate: "
        "n/a); the standard metrics are taken at the last step, the reaction at 30 % "
        "compression.",)

    def mesh(self, family, s):
        return cube(NODES, SIZE_MM * MM, family)

    def dirichlet(self, mesh, bc, s):
        return dirichlet_at(mesh, s.push_mm * MM)

    def driven(self, mesh, bc, s):
        return common.cube_boundary_sets(mesh, "sliding", SIZE_MM * MM)[0], 1

    def solve_reference(self, mesh, bc, s, probe):
        dirichlet = self.dirichlet(mesh, bc, s)
        force, lateral = [], []

        def record(step, u, reaction):
            force.append(top_force(mesh, reaction))
            lateral.append(lateral_strain(mesh, u))

        p2 = hyperelastic.solve(mesh, s.E, s.nu, dirichlet, element="P2",
                                load_steps=s.steps, on_step=record)
        p1 = hyperelastic.solve(mesh, s.E, s.nu, dirichlet, element="P1", load_steps=s.steps)
        lin = linear.solve(mesh, s.E, s.nu, dirichlet, element="P2")
        k = np.arange(1, s.steps + 1) / s.steps      # linear FEM scales with the load
        lin_force = (top_force(mesh, lin.reaction) * k).tolist()
        lin_lateral = (lateral_strain(mesh, lin.u) * k).tolist()
        return Reference(
            dirichlet=dirichlet, f_ext=None, p1=p1, conv=None, p2=p2,
            tau=probe.max_tau(mesh.points + p2.u), reaction=force[-1], quantities={},
            error_estimate=None,
            extra={"force": force, "lateral": lateral, "linear_force": lin_force,
                   "linear_lateral": lin_lateral})

    def solve_static(self, pm, mesh, bc, s, ref):
        curve = None
        for step in range(1, s.steps + 1):
            st = pm.solve_static(dirichlet_at(mesh, s.push_mm * MM * step / s.steps),
                                 load_steps=step)
            curve = Curve(st, curve.force if curve else [], curve.lateral if curve else [])
            curve.force.append(top_force(mesh, st.reaction))
            curve.lateral.append(lateral_strain(mesh, st.u))
        return curve

    def reference_entries(self, ref):
        e = ref.extra
        nh_f, nh_l = np.array(e["force"]), np.array(e["lateral"])
        return {"force_fem_n_steps": e["force"], "lateral_strain_fem_steps": e["lateral"],
                "force_linear_n_steps": e["linear_force"],
                "lateral_strain_linear_steps": e["linear_lateral"],
                "linear_force_rel_err_max": float(np.abs(np.array(e["linear_force"]) / nh_f
                                                         - 1).max()),
                "linear_lateral_rel_err_max": float(np.abs(np.array(e["linear_lateral"])
                                                           / nh_l - 1).max())}

    def run_extra(self, pm, mesh, bc, s, ref, st):
        if st is None:
            return {k: None for k in ("force_n_steps", "lateral_strain_steps",
                                      "force_rel_err_max", "lateral_rel_err_max")}
        f, lat = np.array(st.force), np.array(st.lateral)
        return {"force_n_steps": st.force, "lateral_strain_steps": st.lateral,
                "force_rel_err_max": M.finite("force_rel_err_max",
                                              np.abs(f / np.array(ref.extra["force"]) - 1).max()),
                "lateral_rel_err_max": M.finite(
                    "lateral_rel_err_max", np.abs(lat / np.array(ref.extra["lateral"]) - 1).max())}

    def references_line(self, s):
        return ("References: neo-Hookean P1 and P2 on the mesh itself at every step (no "
                "refinement, so no error estimate), and linear FEM P2 scaled with the load.")

    def what_was_run(self, s, runs):
        return [f"Cube of side {SIZE_MM:g} mm, {NODES} x {NODES} x {NODES} lattice nodes, "
                f"sliding base; top pushed {s.push_mm:g} mm ({s.push_mm / SIZE_MM:.0%}) in "
                f"{s.steps} equal steps, each model solved statically at every step."]

    def conclusion(self, s, runs):
        ok = [r for r in runs if r.get("linear_force_rel_err_max") is not None]
        line = (f"Linear FEM misses the neo-Hookean top force by up to "
                f"{max(r['linear_force_rel_err_max'] for r in ok):.3g} and the lateral "
                f"expansion by up to {max(r['linear_lateral_rel_err_max'] for r in ok):.3g} "
                f"at {s.push_mm / SIZE_MM:.0%}." if ok else "No neo-Hookean reference.")
        return [common.best_and_worst(runs, "force_rel_err_max", "Force-strain curve"),
                common.best_and_worst(runs, "lateral_rel_err_max", "Lateral expansion"),
                line + " " + common.failures(runs)]

    def findings(self, s, runs):
        return {"Force-strain curve": common.ranking(runs, "force_rel_err_max",
                                                     "largest force error"),
                "Lateral expansion": common.ranking(runs, "lateral_rel_err_max",
                                                    "largest lateral error"),
                "Failures": [common.failures(runs)]}


    def sections(self, doc, s, runs, fields, out):
        strain = [100 * s.push_mm / SIZE_MM * k / s.steps for k in range(1, s.steps + 1)]
        for mesh in s.meshes:
            rs = [r for r in runs if r["mesh"] == mesh and not r.get("failed")]
            if not rs:
                continue
            solved = [r for r in rs if r["force_n_steps"] is not None]
            for key, fem, lin, label, scale in (
                    ("force_n_steps", "force_fem_n_steps", "force_linear_n_steps",
                     "top force [mN]", 1e3),
                    ("lateral_strain_steps", "lateral_strain_fem_steps",
                     "lateral_strain_linear_steps", "lateral strain", 1.0)):
                name = f"{key.split('_')[0]}_{mesh}.png"
                figures.curves(out / name, strain, np.array(rs[0][fem]) * scale,
                               "neo-Hookean P2",
                               [("linear FEM P2", np.array(rs[0][lin]) * scale)]
                               + [(r["model"], np.array(r[key]) * scale) for r in solved],
                               "compression [%]", label, f"{label}, mesh {mesh}")
                doc.img(name, f"{label} against compression, mesh {mesh}")


CASE = LargeCompression()
