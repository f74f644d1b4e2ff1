"""Large compression: the paper's cube bonded to its base and to the moving top plate,
pushed to 30 % (9.6 mm) in 6 load steps, so that the field is a barrel; judged against the
converged neo-Hookean reference (mixed P2/P1 on the mesh refined, with its estimate), linear
FEM shown beside it. The homogeneous (sliding) compression stays as a constitutive check: each
model's stress-stretch curve drawn against the neo-Hookean law and against its own energy,
reported as curves, not ranked."""
from dataclasses import dataclass, field

import numpy as np

from model.mesh import cube
from reference import hyperelastic, linear
from ..measuring import metrics as M
from ..measuring.error_model import P1_FINITE, Scalar
from ..framework import FINDINGS, Case, Knob, MM, Reference, Settings, linear_scale
from . import common

SIZE_MM, NODES = common.CUBE_MM, common.PAPER_NODES
PUSH_MM, STEPS = 9.6, 6
LAYERS_MM = common.PAPER_LAYERS_MM
ENERGY_STEP = 1e-3     # the energy's central difference: this fraction of the push


@dataclass
class LargeCompressionSettings(Settings):
    push_mm: float = PUSH_MM
    steps: int = STEPS

    def problem(self):
        return {**super().problem(), "size_mm": SIZE_MM, "nodes_per_side": NODES,
                "push_mm": self.push_mm, "steps": self.steps,
                "reference": f"neo-Hookean mixed P2/P1, {self.nh_levels} refinement(s)"}


def dirichlet_at(mesh, bc, push):
    """The cube with its top pushed down ``push`` [m]: ``clamped`` bonds base and top (a
    barrel), ``sliding`` lets both slide (the homogeneous compression)."""
    top, lateral, held = common.cube_boundary_sets(mesh, bc, SIZE_MM * MM)
    out = dict(held)
    out.update({int(i): (lateral[0], -push, lateral[2]) for i in top})
    return out


def lateral_strain(mesh, u):
    """Mean outward lateral displacement of the side-face nodes over the five layers, over
    the half side: the lateral expansion as a strain."""
    profile = M.layer_profile(mesh.points, u, [y * MM for y in LAYERS_MM], SIZE_MM * MM)
    return float(profile.mean() / (SIZE_MM * MM / 2))


def top_force(mesh, reaction):
    top = common.cube_boundary_sets(mesh, "clamped", SIZE_MM * MM)[0]
    return float(-reaction[top, 1].sum())


def pushes(s):
    """The push [m] at each load step."""
    return [s.push_mm * MM * k / s.steps for k in range(1, s.steps + 1)]


def law_force(s):
    """The neo-Hookean law's top force [N] in homogeneous compression at each step."""
    side = SIZE_MM * MM
    return [-hyperelastic.uniaxial(1 - p / side, s.material)[1] * side * side
            for p in pushes(s)]


@dataclass
class Curve:
    """A static solution with its force and lateral strain at every load step."""

    final: object
    force: list = field(default_factory=list)
    lateral: list = field(default_factory=list)

    def __getattr__(self, name):       # the final StaticResult's x, u, reaction, residual
        return getattr(self.final, name)


def homogeneous_curve(pm, mesh, s):
    """The model's sliding compression: its top force at each step and, for a conservative
    model, the force its stored energy implies, dW/d(push) by a central difference of the
    relaxed states at push +- ENERGY_STEP push (None where it has no energy)."""
    force, from_energy = [], []
    for k, p in enumerate(pushes(s), start=1):      # k increments of one step each
        st = pm.solve_static(dirichlet_at(mesh, "sliding", p), load_steps=k)
        force.append(top_force(mesh, st.reaction))
        if not pm.conservative:
            continue
        dp = ENERGY_STEP * s.push_mm * MM
        w = [pm.energy(pm.solve_static(dirichlet_at(mesh, "sliding", p + d), load_steps=k).x)
             for d in (dp, -dp)]
        from_energy.append((w[0] - w[1]) / (2 * dp))
    return force, (from_energy or None)


class LargeCompression(Case):
    narrative = "cases.library.narratives.large_compression:LargeCompressionNarrative"
    name = "large-compression"
    load = Knob("push_mm", "push [mm]")
    title = (f"The paper's cube bonded to base and top plate, pushed to "
             f"{100 * PUSH_MM / SIZE_MM:.0f} % ({PUSH_MM:g} mm) in {STEPS} steps, against "
             "converged neo-Hookean FEM (linear FEM shown beside it)")
    settings_class = LargeCompressionSettings
    meshes = ("five", "six", "bcc", "unstructured")
    bcs = ("clamped",)
    locking_prone = ("clamped",)     # bonded plates at nu = 0.45 on constant-strain tetrahedra
    headline = "force_rel_err_max"
    headline_pair = "disp_rel_l2_nh"
    decomposed = Scalar("force_steps_n", "force_steps_fem_n", "force over the load steps",
                        p1=P1_FINITE)
    decomposed_at_load = None         # the force over the load steps is at the load already
    headline_estimate = "nh_error_estimate"
    gated = ("force_rel_err_max", "lateral_rel_err_max")
    columns = ("reaction_fem_nh_n", "force_rel_err_max", "lateral_rel_err_max",
               "linear_force_rel_err_max", "homogeneous_force_dev_max")

    def mesh(self, family, s):
        return cube(NODES, SIZE_MM * MM, family)

    def dirichlet(self, mesh, bc, s):
        return dirichlet_at(mesh, bc, s.push_mm * MM)

    def driven(self, mesh, bc, s):
        return common.cube_boundary_sets(mesh, bc, SIZE_MM * MM)[0], 1

    def solve_reference(self, mesh, bc, s, probe):
        dirichlet = self.dirichlet(mesh, bc, s)
        force, lateral = [], []

        def record(step, u, reaction):     # every level's steps: the finest come last
            force.append(top_force(mesh, reaction))
            lateral.append(lateral_strain(mesh, u))

        nh = hyperelastic.converged(mesh, s.material, dirichlet, levels=s.nh_levels,
                                    element="P2", mixed=True, load_steps=s.steps,
                                    on_step=record)
        conv = linear.converged(mesh, s.material, dirichlet, levels=s.p2_levels)
        p1 = linear.solve(mesh, s.material, dirichlet, element="P1")
        lin = conv.result
        k = np.arange(1, s.steps + 1) / s.steps      # linear FEM scales with the load
        return Reference(
            dirichlet=dirichlet, f_ext=None, p1=p1, conv=conv, p2=lin,
            tau=probe.max_tau(mesh.points + lin.u),
            reaction=top_force(mesh, lin.reaction), quantities={},
            error_estimate=conv.error_estimate, dirichlet_linear=dirichlet,
            scale=linear_scale(lin, s.material), nonlinear=nh, nonlinear_reaction=force[-1],
            extra={"force": force[-s.steps:], "lateral": lateral[-s.steps:],
                   "linear_force": (top_force(mesh, lin.reaction) * k).tolist(),
                   "linear_lateral": (lateral_strain(mesh, lin.u) * k).tolist(),
                   "law_force": law_force(s)})

    def solve_static(self, pm, mesh, bc, s, ref):
        curve = None
        for step, p in enumerate(pushes(s), start=1):
            st = pm.solve_static(dirichlet_at(mesh, bc, p), load_steps=step)
            curve = Curve(st, curve.force if curve else [], curve.lateral if curve else [])
            curve.force.append(top_force(mesh, st.reaction))
            curve.lateral.append(lateral_strain(mesh, st.u))
        return curve

    def reference_entries(self, ref):
        e = ref.extra
        nh_f, nh_l = np.array(e["force"]), np.array(e["lateral"])
        return {"force_steps_fem_n": e["force"], "lateral_strain_fem_steps": e["lateral"],
                "force_linear_steps_n": e["linear_force"],
                "lateral_strain_linear_steps": e["linear_lateral"],
                "homogeneous_force_law_steps_n": e["law_force"],
                "linear_force_rel_err_max": float(np.abs(np.array(e["linear_force"]) / nh_f
                                                         - 1).max()),
                "linear_lateral_rel_err_max": float(np.abs(np.array(e["linear_lateral"])
                                                           / nh_l - 1).max())}

    def run_extra(self, pm, mesh, bc, s, ref, st):
        out = dict.fromkeys(("force_steps_n", "lateral_strain_steps", "force_rel_err_max",
                             "lateral_rel_err_max", "homogeneous_force_steps_n",
                             "homogeneous_energy_force_steps_n", "homogeneous_force_dev_max",
                             "homogeneous_failed"))
        if st is not None:
            f, lat = np.array(st.force), np.array(st.lateral)
            out.update({
                "force_steps_n": st.force, "lateral_strain_steps": st.lateral,
                "force_rel_err_max": M.finite(
                    "force_rel_err_max", np.abs(f / np.array(ref.extra["force"]) - 1).max()),
                "lateral_rel_err_max": M.finite(
                    "lateral_rel_err_max",
                    np.abs(lat / np.array(ref.extra["lateral"]) - 1).max())})
        try:
            force, from_energy = homogeneous_curve(pm, mesh, s)
        except FINDINGS as exc:
            out["homogeneous_failed"] = str(exc)
            return out
        out.update({"homogeneous_force_steps_n": force,
                    "homogeneous_energy_force_steps_n": from_energy,
                    "homogeneous_force_dev_max": M.finite(
                        "homogeneous_force_dev_max",
                        np.abs(np.array(force) / np.array(ref.extra["law_force"]) - 1).max())})
        return out


CASE = LargeCompression()
