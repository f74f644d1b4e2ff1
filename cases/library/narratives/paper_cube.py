"""The paper cube's report prose: its notes, findings (grouped), the Figure 1 analogue, the
layer profiles, the step-time chart and the reaction history. Every sentence is computed from
the runs."""

import re

import numpy as np

from ...reporting import figures, rankings
from ...measuring.metrics import ALTERNATION_CLEAR, PATCH_TOL, PATTERN_TOL
from ...reporting.document import Table, fmt
from ...framework import Narrative
from ..paper_cube import SPEED_MM_S

from model.paper_mesh import PAPER_TETS     # the paper's mesh (section 4), unpublished
CAUCHY_TOL = 0.02    # an apparent Poisson ratio this close to 1/4 does not show anisotropy

# the notes beside the catalogue's definitions
NOTES = ("The dynamic run is repeated at a quarter of the step (dt/4) to see whether its "
         "verdict holds; 'blew up' in dyn vs static is a dynamic run that did not finish.",
         "The sliding base holds lateral motion at two corner nodes only, so its lowest modes "
         "rotate about them (an ill-posed modal problem, softening under refinement): its "
         "modal error, rest times and transient comparisons (reaction over time, the end of "
         "the push, dynamic against static) are not scored (n/a), since the push excites a "
         "motion no stiffness resists; whether a run blew up is still reported. The clamped "
         "base and free-free are scored.",
         "The dynamic comparisons (reaction over time, displacement at the end of the push) "
         "are against the linear FEM transient at the case's push: a linear reference at "
         "finite strain, to be read with the static comparisons of the two regimes beside "
         "it (no nonlinear transient reference yet).")


def notes(cfg):
    """NOTES, their first line saying which dynamic runs were repeated at dt/4."""
    if cfg.repeat_dt4 == "every":
        return NOTES
    return (("Only the dynamic runs that blew up at the case's step dt are repeated at a quarter "
             "of it (dt/4), to see whether the step is to blame; 'dt/4 changes verdict' is n/a "
             "for the others (the full run repeats every one). 'blew up' in dyn vs static is a "
             "dynamic run that did not finish."),) + NOTES[1:]


def cell(metric, run):
    """The table text of the paper cube's cells that say more than a number, else None."""
    if metric.name == "dyn_vs_static_rel_l2" and run["dyn_failed"]:
        return "blew up"
    return None


def _bracket(counts, paper):
    """Whether the tetrahedron counts run bracket the paper's, with their range."""
    if not counts:
        return "are not known: no mesh was built"
    lo, hi = min(counts), max(counts)
    return (f"{'bracket' if lo <= paper <= hi else 'do not bracket'} it ({lo} to {hi} "
            "tetrahedra)")


def what_was_run(cfg, runs):
    size = cfg.problem()["size_mm"]     # the case's geometry, declared once by the case
    return [
        f"Cube of side {size:g} mm, {cfg.nodes_per_side} x {cfg.nodes_per_side} x "
        f"{cfg.nodes_per_side} lattice nodes. The paper's own "
        "374-tetrahedron mesh is not published, so it cannot be reproduced: the meshes here "
        f"{_bracket([r['tets'] for r in runs if 'tets' in r], PAPER_TETS)}.",
        f"Top nodes (y = {size:g} mm) pushed down {cfg.push_mm:g} mm; boundary conditions "
        f"{', '.join(cfg.bcs)} (clamped: bottom fixed, top fully prescribed; sliding: only y "
        "prescribed at top and bottom, rigid motions pinned). The paper does not say which.",
        f"Static equilibrium at {cfg.push_mm:g} mm and the paper's dynamic run: classical RK4, "
        f"{SPEED_MM_S:g} mm/s for {cfg.push_mm / SPEED_MM_S:g} s, then held until at rest (mass damping {cfg.damping:g} 1/s, at most "
        f"{cfg.hold_max:g} s), against the linear FEM {cfg.transient_element} transient (a "
        "linear reference at the finite push: the notes say how it is read).",
        _modal_reference(cfg, runs)]


def _modal_reference(cfg, runs):
    """The modal reference and the range of its refinement estimates over the runs."""
    line = (f"Modes against FEM P2 (consistent mass) on {cfg.modal_refine} refinement(s) of "
            "the mesh")
    ranges = []
    for key, label in (("modal_fem_estimate", "clamped base"),
                       ("modal_free_fem_estimate", "free-free")):
        est = [r[key] for r in runs if r.get(key) is not None]
        if est:
            ranges.append(f"{fmt(min(est), 2)} to {fmt(max(est), 2)} {label}")
    return line + ("; its estimate (the largest change of the first 10 frequencies over the "
                   "last refinement) " + ", ".join(ranges) + "." if ranges
                   else ", without a refinement estimate.")


def _runs(runs, **kw):
    return [r for r in runs if all(r.get(k) == v for k, v in kw.items())]


def conclusion(cfg, runs):
    """Three lines: the artefact, the accuracy, the dynamics, computed from the runs."""
    solved = [r for r in runs if r.get("disp_rel_l2_p2") is not None]
    where = {}     # model -> the mesh/bc where it shows the pattern at the 5-layer threshold
    for r in solved:
        if _clear(r):
            where.setdefault(r["model"], set()).add(f"{r['mesh']}/{r['bc']}")
    clear = [f"{m} (on {', '.join(sorted(w))})" for m, w in sorted(where.items())]
    fem = sorted({f"{r['mesh']}/{r['bc']}" for r in runs if r.get("paper_pattern_fem")})
    view = ("In the paper's own 5-layer view (which cannot tell a smooth bump from an "
            "alternation, so it decides nothing: the [artefact study](../artefact/report.md) "
            "decides on finer meshes), ")
    shows = (f"the paper's bulge/neck sign pattern with an alternation of at least "
             f"{ALTERNATION_CLEAR:g} of the mean lateral displacement")
    if not clear:
        first = view + f"no model shows {shows}"
    else:
        first = (view + f"{shows} shows in "
                 + (clear[0] if len(clear) == 1 else ", ".join(clear[:-1]) + " and " + clear[-1]))
    if fem:
        first += f", and in the converged FEM on {', '.join(fem)}."
    elif clear:
        first += ", not in the converged FEM."
    else:
        first += ", nor does the converged FEM."
    out = [first]
    patch = [r for r in runs if r["bc"] == "sliding"]
    if patch:       # homogeneous: every consistent discretisation is exact (a patch test)
        passed = sorted({r["model"] for r in patch} - {
            r["model"] for r in patch if r.get("disp_rel_l2_p2") is None
            or r["disp_rel_l2_p2"] >= PATCH_TOL})
        out.append(f"Sliding base, a patch test (error below {PATCH_TOL:g} on every mesh): "
                   f"passed by {', '.join(passed) or 'none'}; failed by "
                   + (", ".join(sorted({r["model"] for r in patch} - set(passed))) or "none")
                   + ".")
    clamped = [r for r in runs if r["bc"] == "clamped"]
    if clamped:
        out.append(rankings.best_and_worst(clamped, "disp_rel_l2_p2",
                                           "Clamped base, displacement against FEM P2",
                                           spread_keys=("reaction_fem_p2_n",)))
    out.append(_blow_ups(runs))
    # every clamped run counts (one without a modal answer against its model), its unpaired
    # FEM modes first: a mode without a partner is a failed mode
    held = [r for r in runs if r["bc"] == "clamped" and "modal_rel_err" in r]
    if any(r.get("modal_rel_err") is not None for r in held):
        out.append(rankings.best_and_worst(held, "modal_rel_err",
                                           "First 10 frequencies, base clamped and top "
                                           "held (unpaired: of 10 FEM modes per run)",
                                           estimate_key="modal_fem_estimate",
                                           lost_key="modes_unpaired_held"))
    return out


def _blow_ups(runs):
    """Which dynamic runs blow up: on the clamped base (scored), and apart on the sliding base,
    whose modal problem is ill-posed (held at two corner nodes), reported and not scored."""
    said = []
    for bc, what in (("clamped", "Dynamic runs on the clamped base"),
                     ("sliding", "on the sliding base (ill-posed: reported, not scored)")):
        rs = [r for r in runs if r["bc"] == bc]
        blown = sorted({r["model"] for r in rs if r.get("dyn_failed")})
        if not rs:
            continue
        said.append(f"{what} " + ("blow up for " + ", ".join(
            f"{m} ({sum(bool(r.get('dyn_failed')) for r in rs if r['model'] == m)} of "
            f"{sum(r['model'] == m for r in rs)} runs)" for m in blown) if blown
            else "all come to rest"))
    return "; ".join(said) + "." if said else "No dynamic run."


def _stability(r, cfg):
    """What the run at dt/4 and the linearised growth rate say of a blow-up: computed, never
    assumed."""
    g, damp = r["growth_rate_1_s"], cfg.damping / 2
    if not r["dyn_failed_dt4"]:
        return "the step: it comes to rest at dt/4"
    return (f"grows beyond the damping: growth above the {damp:g} 1/s the damping removes, dt/4 "
            "does not cure it"
            if g > damp else f"growth below the {damp:g} 1/s the damping removes, yet dt/4 "
            "blows up too")


def findings(runs, cfg):
    """{group: sentences}, computed from the runs."""
    runs = [r for r in runs if not r.get("failed")]
    return {"The bulge/neck artefact": _artefact(runs, cfg),
            "Accuracy and stiffness": _accuracy(runs, cfg),
            "Dynamics and stability": _dynamics(runs, cfg),
}


def _clear(r):
    """The paper's sign pattern with an alternation of at least ALTERNATION_CLEAR."""
    return bool(r["paper_pattern"]) and (r.get("alternation_rel") or 0.0) >= ALTERNATION_CLEAR


def shape(profile):
    """What a layer profile looks like, read from its second differences: 'a barrel' (all
    negative: one bulge, falling to both ends), 'a waist' (all positive), 'alternating' (their
    signs alternate), else 'uneven'; 'uniform' where none exceeds PATTERN_TOL of the profile."""
    b = np.asarray(profile, float)
    d2 = b[:-2] - 2 * b[1:-1] + b[2:]
    tol = PATTERN_TOL * np.abs(b).max()
    sign = np.where(d2 > tol, 1, np.where(d2 < -tol, -1, 0))
    if not sign.any():
        return "uniform"
    if (sign < 0).all():
        return "a barrel"
    if (sign > 0).all():
        return "a waist"
    if sign.all() and (sign[1:] != sign[:-1]).all():
        return "alternating"
    return "uneven"


def _artefact(runs, cfg):
    out = []
    pattern = [r for r in runs if r["paper_pattern"]]
    fem_pattern = {(r["mesh"], r["bc"]) for r in runs if r["paper_pattern_fem"]}

    def listing(rs):
        return "; ".join(f"{r['model']} on {r['mesh']}/{r['bc']} ({shape(r['bulge_profile_mm'])}: "
                         + ", ".join(f"{v:.4f}" for v in r["bulge_profile_mm"])
                         + " mm against FEM's "
                         + ", ".join(f"{v:.4f}" for v in r["bulge_profile_fem_mm"])
                         + ("; alternation n/a: too few free layers)"
                            if r.get("alternation_mm") is None else
                            f"; alternation {r['alternation_mm']:.2g} mm, "
                            f"{100 * r['alternation_rel']:.2g} %)") for r in rs)

    clear = [r for r in pattern if _clear(r)]
    faint = [r for r in pattern if not _clear(r)]
    opposite = [r for r in runs if r.get("alternation_rel") is not None
                and r["alternation_rel"] <= -ALTERNATION_CLEAR]
    # the paper's sign of alternation without its sign pattern (second differences): the two
    # criteria apart, so that no run above the level falls in no list
    unpatterned = [r for r in runs if not r["paper_pattern"]
                   and (r.get("alternation_rel") or 0.0) >= ALTERNATION_CLEAR]
    if clear:
        out.append("In the 5-layer view (which decides nothing), the paper's bulge at "
                   "0/16/32 mm and neck at 8/24 mm shows (the paper's sign pattern in the layers' second differences, and an "
                   "alternating-layer component beyond FEM's profile of at least "
                   f"{100 * ALTERNATION_CLEAR:g} % of its mean lateral displacement) by: "
                   f"{listing(clear)}.")
    if unpatterned:
        out.append(f"An alternation of the paper's sign of at least {100 * ALTERNATION_CLEAR:g} "
                   "% without the paper's sign pattern in the second differences (a bulge "
                   f"the smooth part of the profile outweighs): {listing(unpatterned)}.")
    if faint:
        out.append("The same sign pattern (second differences) appears faintly "
                   f"(alternation below {100 * ALTERNATION_CLEAR:g} %) in: {listing(faint)}.")
    if opposite:
        out.append("A 5-layer alternation score of the opposite sign of at least "
                   f"{100 * ALTERNATION_CLEAR:g} %: {listing(opposite)}.")
    if clear or faint or opposite or unpatterned:
        out.append("These are the paper's own 5-layer view, on the linear regime's profile "
                   "brought to the push (each profile's shape named from its second "
                   "differences): on five layers the period-2 score absorbs at most a cubic, "
                   "so a smooth barrel or waist scores as an alternation, and it decides "
                   "nothing; the artefact study decides on 9 and 17 nodes per side, at the "
                   "push itself ([artefact](../artefact/report.md)).")
    if not pattern:
        out.append("No model reproduces the paper's bulge at 0/16/32 mm and neck at 8/24 mm on "
                   "any mesh and boundary condition run here.")
    none = sorted({(r["model"]) for r in runs} - {r["model"] for r in pattern})
    if none:
        out.append(f"Never showing the pattern: {', '.join(none)}.")
    out.append("The converged FEM reference shows the pattern on "
               + (", ".join(f"{m}/{b}" for m, b in sorted(fem_pattern)) if fem_pattern
                  else "no mesh and boundary condition") + ": where a model shows it, the continuum "
               "does not; whether the mesh, P1's own discretisation or the model causes it is "
               "the artefact study's question.")
    if any(r["bc"] == "clamped" for r in runs):
        out.append("Clamped bottom: the y = 0 layer cannot move laterally, so the paper's "
                   "reported bulge at y = 0 is impossible under a clamped base; the paper's "
                   "base was therefore probably not fully clamped, or the bulge is relative.")
    return out


def _accuracy(runs, cfg):
    out = []
    solved = [r for r in runs if not r["static_failed"]]
    for r in runs:
        if r["static_failed"]:
            out.append(f"No converged static solve for {r['model']} on {r['mesh']}/{r['bc']}: "
                       f"{r['static_failed']}.")
    for bc in cfg.bcs:
        rs = [r for r in solved if r["bc"] == bc]
        if rs:
            best = min(rs, key=lambda r: r["disp_rel_l2_p2"])
            worst = max(rs, key=lambda r: r["disp_rel_l2_p2"])
            out.append(f"{bc}: smallest displacement error against P2 {best['disp_rel_l2_p2']:.3g}"
                       f" ({best['model']}, {best['mesh']}), largest {worst['disp_rel_l2_p2']:.3g}"
                       f" ({worst['model']}, {worst['mesh']}).")
    rows = []
    for model in cfg.models:
        for bc in cfg.bcs:     # one population per row: a patch test is never pooled
            rs = [r for r in solved if r["model"] == model and r["bc"] == bc]
            if rs:
                rr = [r["reaction_ratio"] for r in rs]
                rows.append([model, bc, f"{min(rr):.3g} to {max(rr):.3g}",
                             f"{max(r['net_force_rel'] for r in rs):.2g}",
                             f"{max(r['net_torque_rel'] for r in rs):.2g}"])
    if rows:
        out.append(Table("Stiffness (reaction ratio to FEM P2) over the runs of each boundary "
                         "condition, and the largest net force and torque of the internal "
                         "forces (of the force scale):",
                         ["model", "bc", "reaction ratio", "net force", "net torque"], rows))
    msm = [r for r in solved if r["model"] == "msm" and r["bc"] == "sliding"]
    if msm:
        # the Cauchy relations bind an isotropic central-force network to nu = 1/4: a measured
        # ratio away from it shows the lattice's springs are not isotropic, one near it does not
        out.append(Table(
            f"msm's apparent Poisson ratio from the lateral expansion (sliding), for nu = "
            f"{cfg.nu:g} asked; an isotropic spring network is bound to 1/4 by the Cauchy "
            "relations:", ["mesh", "apparent nu", "lattice"],
            [[r["mesh"], f"{r['apparent_poisson']:.3f}",
              "not isotropic" if abs(r["apparent_poisson"] - 0.25) > CAUCHY_TOL
              else f"within {CAUCHY_TOL:g} of 1/4"] for r in msm]))
    return out


def _dynamics(runs, cfg):
    out = []
    flutter = [r for r in runs if r.get("dyn_verdict") == "unstable (flutter)"]
    if flutter:
        out.append(f"Unstable (grows beyond the damping: linearised growth above half the damping, "
                   f"{cfg.damping / 2:g} 1/s), so their dynamic metrics are not scored "
                   "whatever step they ran at: " + "; ".join(
                       f"{r['model']} on {r['mesh']}/{r['bc']} ({r['growth_rate_1_s']:.3g} 1/s"
                       + (", came to rest at its step" if r.get("dyn_at_rest") else "") + ")"
                       for r in flutter) + ".")
    bad = [r for r in runs if r["dyn_failed"] or r["dyn_failed_dt4"]]
    if bad:
        out.append(Table("Dynamic runs that blew up (at the case's step dt or at dt/4):",
                         ["model", "mesh/bc", "at dt", "at dt/4", "growth [1/s]", "why"],
                         [[r["model"], f"{r['mesh']}/{r['bc']}",
                           _blowup(r["dyn_failed"]), _blowup(r["dyn_failed_dt4"]),
                           f"{r['growth_rate_1_s']:.3g}", _stability(r, cfg)] for r in bad]))
    odd = [r for r in runs if r["rigid_modes_free"] != 6]
    if odd:
        out.append("Rigid modes free-free other than 6 (zero-energy deformation modes, or "
                   "rigid motions the forces resist): " + "; ".join(
                       f"{r['model']} on {r['mesh']}: {r['rigid_modes_free']}" for r in odd) + ".")
    elif runs:
        out.append("Every model has exactly 6 rigid modes free-free on every mesh run.")
    rows = []
    for model in cfg.models:
        rs = [r for r in runs if r["model"] == model and r["reaction_time_rel_l2"] is not None]
        # a run with an unpaired mode is a failed run: no largest error to give; the clamped
        # base's runs alone (the sliding base's modal problem is not scored)
        held = [r for r in runs if r["model"] == model and "modal_rel_err" in r
                and r["bc"] == "clamped"]
        errs = [r["modal_rel_err"] for r in held
                if r.get("modal_rel_err") is not None and not r.get("modes_unpaired_held")]
        failed = len(held) - len(errs)
        if rs:
            rows.append([model, f"{min(r['reaction_time_rel_l2'] for r in rs):.3g} to "
                                f"{max(r['reaction_time_rel_l2'] for r in rs):.3g}",
                         (f"{max(errs):.3g}" if errs else "n/a")
                         + (f"; {failed} of {len(held)} runs failed (unpaired modes)"
                            if failed else "")])
    if rows:
        out.append(Table(f"Against the linear FEM {cfg.transient_element} transient: the top "
                         "reaction over push and hold (relative L2, over the scored runs; a "
                         "linear reference at the finite push scores the law's nonlinearity "
                         "as error, fem-neohookean's distance included, so this column ranks "
                         "no model) and the largest error of the first 10 frequencies, clamped "
                         "base:",
                         ["model", "reaction(t) error", "modal error"], rows))
    unstable = sorted({(r["model"], r["mesh"], r["bc"], r["growth_rate_1_s"]) for r in runs
                       if r["growth_rate_1_s"] > 0})
    if unstable:
        steady = sorted({r["model"] for r in runs} - {u[0] for u in unstable})
        out.append(Table("Flutter: positive growth rate of the undamped linearised model"
                         + (f" (none on any mesh and condition run: {', '.join(steady)})"
                            if steady else "") + ":",
                         ["model", "mesh/bc", "growth [1/s]"],
                         [[m, f"{me}/{b}", f"{g:.3g}"] for m, me, b, g in unstable]))
    return out


DEVIATES = 0.05    # a profile this far from FEM's (largest over layers, of its mean): in colour


def _deviates(r, fem):
    """A model drawn in colour in a profile plot: an alternation from the clear level, or a
    profile off FEM's by DEVIATES of its mean magnitude somewhere."""
    off = np.abs(np.asarray(r["bulge_profile_mm"]) - fem).max() / max(np.abs(fem).mean(), 1e-300)
    return off > DEVIATES or abs(r.get("alternation_rel") or 0.0) >= ALTERNATION_CLEAR


def _blowup(message):
    """When a run blew up, from its message: the time to two figures (the step a growing mode
    reaches the bound at differs from one processor to the next; its growth rate, beside it,
    does not), or 'no'."""
    if not message:
        return "no"
    m = re.search(r"step (\d+) \(t = ([0-9.e+-]+) s", message)
    return f"t = {float(m.group(2)):.2g} s" if m else message


def _field(fields, mesh, bc, model):
    f = fields[(mesh, bc, model)]
    return f["mesh"], f["u"], f["max_tau"]


def sections(doc, cfg, runs, fields, out):
    """The layer profiles and Figure 1 analogue per (mesh, bc), the step-time chart (the
    paper's Figure 2 analogue) and the reaction history."""
    doc.h(2, "Layer profiles and the Figure 1 analogue")
    for mesh in cfg.meshes:
        for bc in cfg.bcs:
            rs = [r for r in _runs(runs, mesh=mesh, bc=bc) if not r.get("failed")]
            if not rs:
                continue
            doc.h(3, f"Mesh {mesh}, {bc}")
            solved = [r for r in rs if not r["static_failed"]]
            doc.table(["layer y [mm]", "FEM P2"] + [r["model"] for r in solved],
                      [[fmt(y), fmt(rs[0]["bulge_profile_fem_mm"][k], 4)]
                       + [fmt(r["bulge_profile_mm"][k], 4) for r in solved]
                       for k, y in enumerate(cfg.problem()["layers_mm"])])
            name = f"fig1_{mesh}_{bc}.png"
            panels = [("FEM P2", *_field(fields, mesh, bc, "fem-p2"))]
            panels += [(m, *_field(fields, mesh, bc, m)) for m in cfg.models
                       if (mesh, bc, m) in fields]
            figures.stress_panels(out / name, panels, f"max |tau|, mesh {mesh}, {bc}", 5.0)
            doc.img(name, f"Figure 1 analogue: mesh {mesh}, {bc}")
            name = f"profile_{mesh}_{bc}.png"
            fem = np.asarray(rs[0]["bulge_profile_fem_mm"])
            figures.profiles(out / name, cfg.problem()["layers_mm"],
                             [(r["model"], r["bulge_profile_mm"]) for r in solved],
                             fem, f"layer profile, mesh {mesh}, {bc}",
                             highlight={r["model"] for r in solved if _deviates(r, fem)})
            doc.img(name, f"Layer profiles: mesh {mesh}, {bc}")
    keys = [(r["mesh"], r["bc"]) for r in runs if r["model"] == cfg.models[0]
            and not r.get("failed")]
    if not keys:
        return
    doc.h(2, "Dynamics")
    m0, b0 = keys[0]
    fem = fields[(m0, b0, "fem-p2")]["transient"]
    figures.reaction_history(out / "reaction_time.png",
                             [(r["model"], r["dyn_reaction_t_s"], r["dyn_reaction_n"])
                              for r in _runs(runs, mesh=m0, bc=b0) if not r["dyn_failed"]],
                             _runs(runs, mesh=m0, bc=b0)[0]["reaction_fem_p2_n"],
                             (f"FEM {cfg.transient_element} transient", fem["t"],
                              fem["reaction_y"]), f"dynamic run, mesh {m0}, {b0}",
                             f"FEM P2 static at {cfg.push_mm:g} mm")
    doc.img("reaction_time.png", f"Reaction force against time, mesh {m0}, {b0}")


class PaperCubeNarrative(Narrative):
    draws_stress = True
    notes = NOTES

    def notes_for(self, s):
        return notes(s)

    def what_was_run(self, s, runs):
        return what_was_run(s, runs)

    def conclusion(self, s, runs):
        return conclusion(s, runs)

    def findings(self, s, runs):
        return findings(runs, s)

    def cell(self, metric, run):
        return cell(metric, run) or super().cell(metric, run)

    def sections(self, doc, s, runs, fields, out):
        sections(doc, s, runs, fields, out)
