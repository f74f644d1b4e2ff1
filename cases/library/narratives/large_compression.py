"""The large-compression case's report prose: what was run, its opening, findings
and figures, computed from the runs."""
import numpy as np
from . import sentences
from ...reporting import figures
from ..large_compression import SIZE_MM, NODES, pushes
from ...framework import MM, Narrative
from ...measuring.error_model import u_num


class LargeCompressionNarrative(Narrative):
    magnify = 1.0
    notes = (
        "At the case's load the reference is neo-Hookean (compressible, the law of "
        "reference.hyperelastic): the mixed P2/P1 (u, p) solution on the mesh refined, its "
        "error estimate from the change between refinements; the force curves and the NH "
        "metrics are taken against it, the NH displacement and reaction at 30 % compression. "
        "The standard (P1, P2) metrics are the linear regime's, as in every case.",
        "The homogeneous compression (both plates sliding) is a constitutive check, not a "
        "ranking: FEM represents it exactly, so it shows each model's own stress-stretch law "
        "against the neo-Hookean one.")

    def references_line(self, s):
        times = {1: "once", 2: "twice"}.get(s.nh_levels, f"{s.nh_levels} times")
        return (f"References: neo-Hookean mixed P2/P1 at every step on the mesh and on the "
                f"mesh refined {times} (the finest is the reference), its error estimate the "
                "change between the last two; linear FEM P1 and converged P2 (the linear regime, and "
                "scaled with the load beside the curves); the neo-Hookean law in closed form "
                "for the homogeneous check.")

    def what_was_run(self, s, runs):
        return [f"Cube of side {SIZE_MM:g} mm, {NODES} x {NODES} x {NODES} lattice nodes, "
                f"base and top bonded; top pushed {s.push_mm:g} mm "
                f"({s.push_mm / SIZE_MM:.0%}) in {s.steps} equal steps, each model solved "
                "statically at every step; the same with both plates sliding for the "
                "homogeneous check."]

    def conclusion(self, s, runs):
        ok = [r for r in runs if r.get("linear_force_rel_err_max") is not None]
        line = (f"The linear continuum (linear P2 on the same geometry, not fem-linear) misses "
                f"the neo-Hookean continuum's top force by up to "
                f"{max(r['linear_force_rel_err_max'] for r in ok):.3g} and the lateral "
                f"expansion by up to {max(r['linear_lateral_rel_err_max'] for r in ok):.3g} "
                f"at {s.push_mm / SIZE_MM:.0%}." if ok else "No neo-Hookean reference.")
        nh = "nh_error_estimate"   # the curves are read against the neo-Hookean reference
        twin = [r["force_rel_err_max"] for r in runs if r["model"] == "fem-neohookean"
                and r.get("force_rel_err_max") is not None]
        locking = (f"A locking-prone problem: constant-strain tetrahedra compressed at nu = "
                   f"{s.nu:g} lock, so the model-form twin (neo-Hookean P1 on the same "
                   f"tetrahedra) is itself up to {max(twin):.3g} from the continuum's force "
                   "over the load steps; a model nearer the continuum than that twin is less "
                   "locked, not closer to the law, and the model-form error here ranks "
                   "closeness to a locked mesh." if twin else None)
        return ([locking] if locking else []) + [
            sentences.best_and_worst(runs, "force_rel_err_max", "Force-strain curve",
                                  estimate_key=nh),
            sentences.best_and_worst(runs, "lateral_rel_err_max", "Lateral expansion",
                                  estimate_key=nh),
            " ".join(filter(None, (line, agreement(runs), sentences.failures(runs),
                                   homogeneous_failures(runs))))]

    def findings(self, s, runs):
        nh = "nh_error_estimate"
        return {"Force-strain curve": sentences.ranking(runs, "force_rel_err_max",
                                                     "largest force error", estimate_key=nh),
                "Lateral expansion": sentences.ranking(runs, "lateral_rel_err_max",
                                                    "largest lateral error", estimate_key=nh),
                "Failures": list(filter(None, [sentences.failures(runs),
                                               homogeneous_failures(runs)]))}

    def sections(self, doc, s, runs, fields, out):
        strain = [100 * p / (SIZE_MM * MM) for p in pushes(s)]
        for mesh in s.meshes:
            rs = [r for r in runs if r["mesh"] == mesh and not r.get("failed")]
            if not rs:
                continue
            solved = [r for r in rs if r["force_steps_n"] is not None]
            for key, fem, lin, label, scale in (
                    ("force_steps_n", "force_steps_fem_n", "force_linear_steps_n",
                     "top force [mN]", 1e3),
                    ("lateral_strain_steps", "lateral_strain_fem_steps",
                     "lateral_strain_linear_steps", "lateral strain", 1.0)):
                name = f"{key.split('_')[0]}_{mesh}.png"
                figures.curves(out / name, strain, np.array(rs[0][fem]) * scale,
                               "neo-Hookean P2/P1",
                               [("linear FEM P2", np.array(rs[0][lin]) * scale)]
                               + [(r["model"], np.array(r[key]) * scale) for r in solved],
                               "compression [%]", label, f"{label}, bonded, mesh {mesh}")
                doc.img(name, f"{label} against compression, bonded plates, mesh {mesh}")
        homogeneous(doc, s, runs, strain, out)


def homogeneous_failures(runs):
    """The runs whose homogeneous check (the law's own curve on a homogeneous
    compression) failed, a visible hole; '' where none did."""
    bad = [f"{r['model']} on {r['mesh']}" for r in runs if r.get("homogeneous_failed")]
    return ("The homogeneous check failed (no number, counted as a failed run of that "
            "check) for " + ", ".join(bad) + "." if bad else "")

def agreement(runs):
    """How far the references of the meshes, one continuum problem, are apart, beside
    their own estimates: a spread above the estimates says the estimate (one refinement's
    change) is too small."""
    ref = {r["mesh"]: (r["reaction_fem_nh_n"], r["nh_error_estimate"]) for r in runs
           if r.get("reaction_fem_nh_n") is not None}
    if len(ref) < 2:
        return ""
    f = [v[0] for v in ref.values()]
    est = max(v[1] for v in ref.values())
    # the spread u_num is widened to: one definition (error_model.u_num)
    spread = u_num(0.0, f)[0]
    return (f"The {len(ref)} meshes' references give {min(f):.4g} to {max(f):.4g} N at "
            f"the last step (spread {spread:.2g} of their median, "
            f"{'above' if spread > est else 'within'} their largest estimate {est:.2g}).")

def homogeneous(doc, s, runs, strain, out):
    """The constitutive check: one figure per mesh, each model's homogeneous top force
    (solid) and the force its energy implies (where it has one) against the law."""
    doc.h(2, "Constitutive check: homogeneous compression")
    doc.p("Both plates sliding, so the continuum's field is homogeneous and FEM is exact: "
          "each curve is the model's own stress-stretch law. Where a model is "
          "conservative, the force its stored energy implies (dW/d(push), central "
          "difference) is drawn dashed: it lies on the solid curve when the forces are "
          "the energy's gradient. Not ranked: a law differs from neo-Hookean by "
          "construction.")
    for mesh in s.meshes:
        rs = [r for r in runs if r["mesh"] == mesh and r.get("homogeneous_force_steps_n")]
        if not rs:
            continue
        lines = [(r["model"], np.array(r["homogeneous_force_steps_n"]) * 1e3)
                 for r in rs]
        lines += [(f"{r['model']} (energy)",
                   np.array(r["homogeneous_energy_force_steps_n"]) * 1e3)
                  for r in rs if r.get("homogeneous_energy_force_steps_n")]
        name = f"homogeneous_{mesh}.png"
        figures.curves(out / name, strain,
                       np.array(rs[0]["homogeneous_force_law_steps_n"]) * 1e3,
                       "neo-Hookean law", lines, "compression [%]", "top force [mN]",
                       f"homogeneous compression, mesh {mesh}")
        doc.img(name, f"homogeneous top force against compression, mesh {mesh}")
