"""The convergence study's files: metrics.json (runs, fits, references, effective elasticity,
accuracy per cost, and the rows the gate reads), report.md/.html and the figures. Every
sentence is computed from the data it is written with."""

from ...measuring import catalogue
from ...measuring.error_model import JUDGES
from ...reporting.document import Document, fmt, rel
from ...reporting.report import environment, write_study
from ...running.runner import jsonable
from .plots import directional_young, error_vs_h, pareto
from .elasticity import ANGLES_DEG, PATCH_MM
from .problems import PROBLEMS
from .cost import cheapest as cheapest_run
from .extrapolation import EXACT, FS_THREE, ORDER_MIN, ROUND_LEVEL, UNDECIDED, UNDECIDED_WHY
from .extrapolation import SAME_ERROR, blind_levels
from .study import FEM_P1, MAX_NODES
from .verification_report import (gate_rows as verification_gate_rows, manufactured_section,
                                  patch_section, steps_section)

# what the gate bounds (two-sided) in the study's rows; fits and tensors are derived from runs
# but gated too, so that a changed verdict shows as a changed e_inf
GATED = catalogue.gated("disp_rel_l2", "reaction_rel_err", "e_inf", "moduli_rel_err",
                        "anisotropy_AU", "mms_order", "mms_rel_l2", "patch_error", "dt_error",
                        "dt_order")
BUDGETS = (0.1, 0.02)   # error targets of the cost table: the cheapest run reaching each
# a reference whose estimate is more than a fifth of an error cannot judge it: the errors below
# this many times its estimate are "not resolved"
REF_MARGIN = float(JUDGES)     # the error model's: a reference judges five times its estimate
STIFFNESS_TOL = 0.01     # a stiffness error this far from 0 past its +- is said (C_eff's tolerance)
ISOTROPIC_TOL = 0.01    # every C_eff modulus within this of the target's: the lattice is it


def gate_rows(data):
    """The study's rows as the gate reads them: (mesh, bc, model) keys where bc names the
    problem, its boundary condition and the level ('paper-cube/clamped/h4'), the fit
    ('.../fit') or the effective tensor ('C_eff')."""
    rows = [{"mesh": r["mesh"], "bc": f"{r['case']}/{r['bc']}/h{r['h_mm']:.4g}",
             "model": r["model"], "disp_rel_l2": r.get("disp_rel_l2"),
             "reaction_rel_err": r.get("reaction_rel_err")} for r in data["runs"]]
    rows += [{"mesh": f["mesh"], "bc": f"{f['case']}/{f['bc']}/fit", "model": f["model"],
              "e_inf": f.get("e_inf")} for f in data["fits"]]
    rows += [{"mesh": e["mesh"], "bc": "C_eff", "model": e["model"],
              "moduli_rel_err": e.get("moduli_rel_err"),
              "anisotropy_AU": e.get("anisotropy_AU")}
             for e in data["elasticity"]]
    return rows + verification_gate_rows(data)


def metrics_document(study, s, data):
    """metrics.json: the runs, fits and tables, with the fits whose finest error is below
    what their reference judges (``unresolved``: 'not resolved', left out of every count)."""
    return jsonable({"case": study.name, "study": True, "parameters": s.describe(),
                     "problem": s.problem(), "gated": GATED, "environment": environment(),
                     **data, "not_resolved": sorted(list(k) for k in unresolved(data)),
                     "gate_runs": gate_rows(data)})


def definitions():
    """The study's terms, for the glossary (reports/glossary.md)."""
    return [
        "disp error: ||u_model - u_ref|| / ||u_ref|| over all nodes and components, u_ref the "
        "reference's displacement at the model mesh's nodes.",
        "stiffness (reaction) ratio: model over FEM for a force (paper cube: the top force; "
        "torsion: the torque), FEM over model for a displacement under a given load "
        "(cantilever: the tip deflection), so that above 1 is always stiffer.",
        "order: p of e = e_inf + C h^p observed on the three finest levels (Richardson); with "
        "two levels log(e1 / e2) / log(h1 / h2), the order if e_inf were 0.",
        "e_inf +- err: the extrapolated limit of the error and Roache's grid convergence index "
        "(safety factor 1.25 with three levels or more; with two, first order assumed and "
        "factor 3); with four levels or more the least-squares fit of all, with the larger "
        "uncertainty.",
        f"verdict: 'exact' when every error is below {EXACT:g} (the reference's own level: "
        "the static solver's tolerance and the nonlinearity left at the scaled load); "
        "'diverges' when the finest error exceeds the coarsest by 10 %; 'not asymptotic' on a "
        "family whose meshes are not self-similar (unstructured: never extrapolated) or where "
        "the extrapolated limit lies below zero beyond its uncertainty (a limit is never below "
        "0; a stiffness ratio's limit never at or below 0) or where, with three levels or "
        "more, the error is still falling without an observed order (no limit; at most the "
        "finest error); 'floor' (a consistency limit: the "
        "error no refinement removes) when the error has stopped falling within its uncertainty and "
        "stays above zero beyond it: either the finest levels have stopped (their two changes "
        "not both falls larger than the values' uncertainty u, the reference's estimate, or "
        f"a fall at an order below {ORDER_MIN:g} over them; the floor is the finest error +- "
        "1.25 x the larger change, with u) or, still falling at an observed order, the "
        "extrapolated e_inf exceeds its +- (a constant plus a decaying part); a sequence still "
        "falling without an observed order is never a floor (nor a convergence: 'not "
        "asymptotic'); "
        f"'{UNDECIDED}' ({UNDECIDED_WHY}) where a limit that is not a floor carries an "
        f"uncertainty above {FS_THREE:g} x the finest error (the band of a clean extrapolation "
        "to zero; a wider one cannot tell convergence from a floor at the finest level); "
        "otherwise 'converges' (with the order when one is observed). Every +- includes u in quadrature (u_val). With two "
        "levels no order is observed: first order is assumed and the verdict is 'not decided' "
        "in the report (`pbcm run convergence` decides, on four levels). 'not resolved' marks "
        f"a fit whose finest error is below {REF_MARGIN:g} x its reference's estimate: that "
        "reference cannot judge it. 'cancellation' marks a series "
        "whose error is not monotone in h or whose "
        "stiffness ratio crosses 1: an error falling through zero is small at one level by "
        f"accident, so such a run is never on a cost front; errors at or below {ROUND_LEVEL:g} "
        "(round-off, the 'exact' level) count as equal and a ratio within it of 1 is on "
        "neither side: round-off is never cancellation. A level where every model's error is "
        f"the same to within {SAME_ERROR:.0%} while their stiffness ratios spread ten times as "
        "much tests nothing (the error is the mesh's) and is left out of its family's fits.",
        "patch test with every boundary node prescribed (patch error): the strain error of a "
        "cube whose boundary nodes all follow a homogeneous strain, the interior relaxed; it "
        "checks consistency at the scale of one lattice and is a different number from the "
        "consistency limit.",
        "floor e_inf: a fit's limit, the displacement error that no refinement removes in one "
        "problem; on the sliding cube (uniaxial stress with traction-free sides, no node of "
        "the sides prescribed) it is the displacement part of the consistency limit, whose "
        "other part is the stiffness error |ratio_inf - 1| (the top displacement is prescribed, "
        "so the displacement alone is blind to the stiffness; the index reads the larger); on "
        "the other problems it is neither.",
        "reaching a target only by cancellation (accuracy per cost): a run's error at or below "
        "the target on a mesh where FEM P1's is above it: the discretisation error, shared by "
        "every model on the mesh, exceeds the target, and the model's model-form error (at "
        "least the difference of the two errors) offsets it; such a run is named, never "
        "picked.",
        "C_eff: 6 x 6 in Voigt order (xx, yy, zz, yz, xz, xy), engineering shear; E_i = "
        "1 / S_ii, nu_ij = -S_ij / S_ii, G = 1 / S_44.. with S = C_eff^-1 (symmetric part); "
        "A_U = 5 G_V / G_R + K_V / K_R - 6 (0 for isotropy); K/K and mu_k/2G: the bulk "
        "modulus and the five deviatoric Kelvin moduli (ascending) over the target's, and "
        "moduli err the largest relative error of the six (the isotropy criterion); asymmetry "
        "||C_eff - C_eff^T|| / ||C_eff|| (zero for a model with an energy).",
        "step cost: microseconds per RK4 step of the model on the run's mesh, fem-linear's "
        "bench time interpolated log-log in the tetrahedron count times the model's step "
        "ratio to fem-linear (medians of interleaved rounds)."]


# ---------------------------------------------------------------------- sentences
VERDICTS = ("exact", "converges", "floor", "diverges")   # a limit or a trend
TWO_LEVELS = ("two levels observe no order: a floor, a slow convergence and a rise before the "
              "asymptotic range look alike there")


def _floor_range(fits):
    """'lowest-highest' of the floors, each its e_inf -+ its fit's uncertainty."""
    lo = min(f["e_inf"] - (f.get("e_inf_err") or 0.0) for f in fits)
    hi = max(f["e_inf"] + (f.get("e_inf_err") or 0.0) for f in fits)
    return f"{max(lo, 0.0):.2g}-{hi:.2g} with each fit's +-"


def decided(f):
    """Whether a fit's verdict is decided: 'exact' on any levels; 'converges', 'floor' and
    'diverges' on three levels or more (two levels observe no order, and the finer levels
    overturn their verdicts)."""
    return f.get("verdict") == "exact" or (f.get("verdict") in VERDICTS
                                           and (f.get("levels") or 0) >= 3)


def unresolved(data):
    """The (case, bc, mesh, model) of every fit, 'exact' aside, whose finest error is below
    what its reference can judge (``unresolved_below``): 'not resolved'."""
    refs = {(r["case"], r["bc"]): unresolved_below(r) for r in data["references"]}
    finest = {}
    for r in data["runs"]:
        k = (r["case"], r["bc"], r["mesh"], r["model"])
        if r.get("disp_rel_l2") is not None and (k not in finest or r["h_mm"] < finest[k][0]):
            finest[k] = (r["h_mm"], r["disp_rel_l2"])
    return {(f["case"], f["bc"], f["mesh"], f["model"]) for f in data["fits"]
            if f.get("verdict") != "exact" and (f["case"], f["bc"], f["mesh"], f["model"])
            in finest and finest[(f["case"], f["bc"], f["mesh"], f["model"])][1]
            < refs.get((f["case"], f["bc"]), 0.0)}


def _by_model(fits, models, skip=()):
    return {m: [f for f in fits if f["model"] == m and decided(f) and (
        f["case"], f["bc"], f["mesh"], f["model"]) not in skip] for m in models}


def conclusion(s, data):
    """The study's headline: which models converge to the continuum, which stop at a floor
    (and how high), what the lattices' effective tensors say, and who is on the cost front;
    a verdict that two levels cannot decide is said to be not decided."""
    models = [FEM_P1] + list(s.models)
    loose = unresolved(data)
    by = _by_model(data["fits"], models, loose)
    pending = {m: [f for f in data["fits"] if f["model"] == m and f.get("verdict") in VERDICTS
                   and not decided(f)] for m in models}
    undecided = sum(len(v) for v in pending.values())
    conv = [m for m in models if by[m] and not pending[m] and all(
        f["verdict"] in ("converges", "exact") for f in by[m])]
    floors = {m: [f for f in by[m] if f["verdict"] == "floor"] for m in models}
    floored = [m for m in models if floors[m]]
    out = []
    # every (problem, bc, family) fitted, whatever its verdict: the denominator of each count
    total = len({(f["case"], f["bc"], f["mesh"]) for f in data["fits"]})
    head = (f"Convergence (h = {', '.join(f'{h:.3g}' for h in s.h_mm)} mm, {total} "
            "problem x mesh family combinations): ")
    if any(f["verdict"] != "exact" for m in models for f in by[m]):
        head += (
            "converging on every fit where a limit is decided: " + (_converging(
                conv, data["fits"], loose, total) or "none") + "; "
            "stopping at a floor that no refinement removes: " + ("; ".join(
                # floors of different problems are different quantities: their range, never
                # a median pooled over them
                f"{m} in {len(floors[m])} of {total} ({len(by[m])} with a limit or a trend; "
                f"floors {_floor_range(floors[m])}, per problem in the tables below)"
                for m in floored)
                or "none"))
        if loose:
            head += (f"; not resolved (the reference's estimate more than a "
                     f"fifth of the finest error, left out of these counts): {len(loose)} fits, "
                     "on " + ", ".join(sorted({f"{k[0]} {k[1]}" for k in loose})))
    wide = [f for f in data["fits"] if f.get("verdict") == UNDECIDED]
    if wide:
        head += (f"; {UNDECIDED} ({UNDECIDED_WHY}: a limit whose +- exceeds "
                 f"{FS_THREE:g} x the finest error): {len(wide)} fits")
    if undecided:
        head += ("; " if head.endswith(")") or head.endswith("none") else "") + (
            f"not decided: {undecided} fits ({TWO_LEVELS}; `pbcm run convergence` decides, on "
            "four levels)")
    out.append(head + f" (loads scaled by {s.load_scale:g}: the linear regime, so that a floor "
               "is the model's consistency limit, not geometric nonlinearity).")
    odd = [f for f in data["fits"] if f.get("verdict") == "not asymptotic"]
    if odd:
        out.append(f"Not asymptotic ({len(odd)} fits: not self-similar, so not "
                   "extrapolated; a limit below zero; or still falling without an observed "
                   "order, no limit): " + ", ".join(sorted({f"{f['model']} on {f['mesh']}" for f in odd}))
                   + ".")
    soft = {}
    for f in data["fits"]:
        if (f["case"], f["bc"]) == ("paper-cube", "sliding") and f.get("ratio_inf") is not None:
            d = abs(f["ratio_inf"] - 1.0)
            if d - (f.get("ratio_inf_err") or 0.0) > STIFFNESS_TOL:
                soft.setdefault(f["model"], []).append(f"{f['mesh']} {d:.2g}")
    if soft:
        out.append("The sliding cube's stiffness error |ratio_inf - 1| (its top displacement "
                   "is prescribed, so the displacement verdicts above do not see it; the "
                   "consistency limit is the larger of the two), beyond "
                   f"{STIFFNESS_TOL:g} past its +-: " + "; ".join(
                       f"{m} on {', '.join(v)}" for m, v in soft.items()) + ".")
    div = sorted({f["model"] for f in data["fits"] if f.get("verdict") == "diverges"
                  and decided(f)})
    if div:
        out.append("Diverging somewhere (error growing as h falls): " + ", ".join(div) + ".")
    eff = [e for e in data["elasticity"] if not e.get("failed")]
    exact = [m for m in s.models if all(e["moduli_rel_err"] < ISOTROPIC_TOL for e in eff
                                         if e["model"] == m)]
    worst = {m: max((e for e in eff if e["model"] == m), key=lambda e: e["moduli_rel_err"])
             for m in s.models if any(e["model"] == m for e in eff)}
    out.append(
        f"Effective elasticity: isotropic and equal to the target (within {ISOTROPIC_TOL:.0%}) "
        f"on every lattice: {', '.join(exact) or 'none'}; farthest: " + "; ".join(
            f"{m} {w['moduli_rel_err']:.2g} on {w['mesh']}" for m, w in sorted(
                worst.items(), key=lambda kv: -kv[1]["moduli_rel_err"]) if m not in exact)
        + ".")
    out.append(_tensor_vs_verdicts(s, data, eff))
    c = data.get("cost")
    if c:
        counts = c["front_counts"]
        out.append("Least error for a given step cost (the Pareto front over every run): "
                   + ", ".join(f"{m} ({n} of the front's points)" for m, n in counts.items())
                   + f", over {len(c['groups'])} problems.")
    return out


def _tally(model, fits, loose):
    """{what: [where]} of a model's fits that do not converge: 'not asymptotic', 'not
    decided (uncertainty ...)', 'not decided (two levels)', 'not resolved', 'floor',
    'diverges'; 'converging or exact' holds the rest."""
    out = {}
    for f in fits:
        if f["model"] != model:
            continue
        where = (f["case"], f["bc"], f["mesh"])
        if (f["case"], f["bc"], f["mesh"], f["model"]) in loose:
            what = "not resolved"
        elif f.get("verdict") == UNDECIDED:
            what = f"{UNDECIDED} ({UNDECIDED_WHY})"
        elif f.get("verdict") in VERDICTS and not decided(f):
            what = f"{UNDECIDED} (two levels)"
        elif f.get("verdict") in ("converges", "exact"):
            what = "converging or exact"
        else:
            what = f.get("verdict", "n/a")
        out.setdefault(what, []).append(where)
    return out


def _places(where, fits):
    """'cantilever clamped six, every problem on unstructured': the (case, bc, mesh) in
    ``where``, a family named once where it holds every problem fitted on it."""
    problems = {}
    for f in fits:
        problems.setdefault(f["mesh"], set()).add((f["case"], f["bc"]))
    whole = [m for m in dict.fromkeys(w[2] for w in where) if len(problems[m]) > 1
             and {(c, b) for c, b, mm in where if mm == m} >= problems[m]]
    return ", ".join([f"{c} {b} {m}" for c, b, m in where if m not in whole]
                     + [f"every problem on {m}" for m in whole])


def _converging(conv, fits, loose, total):
    """The converging models, those with the same tally together, each with what the tables
    say of its other fits: 'FEM P1, fem-linear (converging or exact on 7 of 16; not
    asymptotic on 5: ...; ...)'."""
    groups = {}
    for m in conv:
        t = _tally(m, fits, loose)
        k = tuple(sorted((w, tuple(v)) for w, v in t.items()))
        groups.setdefault(k, (t, []))[1].append(m)
    parts = []
    for t, ms in groups.values():
        rest = [f"{w} on {len(v)}: {_places(v, fits)}" for w, v in t.items()
                if w != "converging or exact"]
        parts.append(", ".join(ms) + f" (converging or exact on "
                     f"{len(t.get('converging or exact', []))} of {total}"
                     + "".join(f"; {r}" for r in rest) + ")")
    return "; ".join(parts)


def _tensor_vs_verdicts(s, data, eff):
    """How the effective tensors and the verdicts agree, counted over (model, lattice) pairs
    whose every verdict is decided."""
    off, on, pending = [], [], 0
    for e in eff:
        mine = [f for f in data["fits"] if f["model"] == e["model"] and f["mesh"] == e["mesh"]]
        if any(f.get("verdict") in VERDICTS and not decided(f) for f in mine):
            pending += 1
            continue
        verdicts = {f["verdict"] for f in mine}
        if not verdicts:
            continue
        bad = bool(verdicts & {"floor", "diverges"})
        (off if e["moduli_rel_err"] >= ISOTROPIC_TOL else on).append((e, bad))
    if not off and not any(b for _, b in on) and pending:
        return (f"Not decided whether the lattices off the target are those that stop at a floor "
                f"or diverge: {pending} (model, lattice) pairs have a verdict that two levels "
                "cannot decide (`pbcm run convergence` decides, on four levels).")
    return (f"Of the {len(off)} (model, lattice) pairs whose tensor is more than "
            f"{ISOTROPIC_TOL:.0%} from the target, {sum(b for _, b in off)} stop at a floor or "
            f"diverge in some problem on that lattice; of the {len(on)} pairs on target, "
            f"{sum(b for _, b in on)} do" + (" (" + ", ".join(
                f"{e['model']} on {e['mesh']}" for e, b in on if b) + ")" if any(
                b for _, b in on) else "")
            + (f"; {pending} pairs not decided (two levels)" if pending else "") + ".")


def unresolved_below(ref):
    """The error below which the reference ``ref`` (its summary) cannot judge a run: REF_MARGIN
    times its own estimate (an estimate more than a fifth of an error cannot judge it)."""
    return REF_MARGIN * (ref.get("error_estimate") or 0.0)


def _reference_margin(data):
    """How far below the errors it judges each reference is: the smallest error of a run
    that is not exact, over the reference's own estimate, per problem; where that is under
    REF_MARGIN the runs it cannot judge are 'not resolved'."""
    exact = {(f["case"], f["bc"], f["mesh"], f["model"]) for f in data["fits"]
             if f.get("verdict") == "exact"}
    parts = []
    for ref in data["references"]:
        errs = [r["disp_rel_l2"] for r in data["runs"] if (r["case"], r["bc"]) ==
                (ref["case"], ref["bc"]) and r.get("disp_rel_l2") is not None
                and (r["case"], r["bc"], r["mesh"], r["model"]) not in exact]
        if errs:
            margin = min(errs) / max(ref["error_estimate"], 1e-300)
            below = unresolved_below(ref)
            parts.append(f"{ref['case']} {ref['bc']}: smallest error {min(errs):.2g}, "
                         f"{margin:.3g}x the reference's estimate"
                         + (f" (not resolved: its estimate {ref['error_estimate']:.2g} is more "
                            "than a fifth of the smallest error, so it cannot judge the "
                            f"{sum(e < below for e in errs)} of {len(errs)} runs with an error "
                            f"below {below:.2g}, nor a fit whose finest error is)"
                            if margin < REF_MARGIN else ""))
    return ("The references against the errors they judge (runs exact at every h left out): "
            + "; ".join(parts) + ".")


def ties(s, data):
    """The reaction ratios explained by the effective tensors: on the sliding cube the state
    is uniaxial stress, so a model whose lattice answers homogeneously gives a reaction ratio
    of E_y,eff / E in the limit."""
    out = []
    eff = {(e["mesh"], e["model"]): e for e in data["elasticity"] if not e.get("failed")}
    for f in data["fits"]:
        if f["case"] != "paper-cube" or f["bc"] != "sliding" or f["model"] == FEM_P1:
            continue
        e = eff.get((f["mesh"], f["model"]))
        rs = [r for r in data["runs"] if (r["case"], r["bc"], r["mesh"], r["model"])
              == ("paper-cube", "sliding", f["mesh"], f["model"])
              and r.get("reaction_ratio") is not None]
        if e is None or not rs:
            continue
        fine = min(rs, key=lambda r: r["h_mm"])
        out.append(f"{f['model']} on {f['mesh']}: sliding-cube reaction ratio "
                   f"{fine['reaction_ratio']:.3g} at h = {fine['h_mm']:.3g} mm (limit "
                   f"{fmt(f.get('ratio_inf'))}), lattice E_y,eff / E = {e['E_y_pa'] / s.E:.3g}, "
                   f"nu_yx = {e['nu_yx']:.3g} (target {s.nu:g}).")
    return out


# ---------------------------------------------------------------------- the document
def write(out, study, s, data):
    """Write metrics.json, run.json, report.md/.html and the PNG figures into ``out``."""
    return write_study(out, metrics_document(study, s, data),
                       lambda folder: build(folder, study, s, data))


def build(out, study, s, data):
    doc = Document(f"pbcm report: {study.name}")
    doc.opening(["Quick: not decided (`pbcm run convergence` decides, on finer levels and "
                 "references): the fits and tables below are a preview of its coarse levels "
                 "and decide nothing."] if s.quick else conclusion(s, data))
    doc.p("Generated by `pbcm run convergence` from the runs recorded in metrics.json; every "
          "number below was computed by the run that wrote this file, but the step costs, which "
          "are `pbcm bench`'s (reports/bench).")
    doc.h(2, "What was run")
    refs = data["references"]
    doc.ul([
        study.title + ".",
        "Problems: " + "; ".join(f"{p} ({', '.join(PROBLEMS[p].bcs)}; stiffness read as "
                                 f"{PROBLEMS[p].label})" for p in s.problems) + ".",
        f"Mesh families {', '.join(s.meshes)} at h = {', '.join(f'{h:.3g}' for h in s.h_mm)} "
        f"mm (nodes every h), where the mesh has at most {MAX_NODES} nodes; models "
        f"{', '.join(s.models)}, and FEM P1 (scikit-fem) on the same mesh as the yardstick.",
        f"Loads of each case scaled by {s.load_scale:g}: every model answers in its linear "
        "regime, so its limit h -> 0 is the linear continuum and what remains there is its "
        "consistency limit, not geometric nonlinearity (the subject of large-compression).",
        "Reference per problem: FEM P2 on the 'five' mesh at each spacing of its ladder; the "
        "three finest levels give an order p and the finest level's error estimate; "
        "Richardson's extrapolation of the field from the two finest, u_f + (u_f - u_c) "
        "h_f^p / (h_c^p - h_f^p), is the reference where its estimate (its distance to the same "
        "extrapolation one level coarser, relative L2 at the coarsest mesh's nodes) is the "
        "smaller; evaluated at every model mesh's nodes by the P2 basis functions: "
        + "; ".join(
            f"{r['case']} {r['bc']}: P2 at {', '.join(f'{h:.3g}' for h in r['ladder_mm'])} "
            f"mm, order {fmt(r['order'], 2)}, "
            + ("extrapolated" if r["extrapolated"] else "finest level")
            + f", estimate {rel(r['error_estimate'], 2)} (finest P2 alone "
            f"{rel(r['p2_error_estimate'], 2)})" for r in refs) + ".",
        f"Effective elasticity: a {PATCH_MM:g} mm cube patch of each lattice with {s.patch_n} "
        "nodes per side; surface nodes moved by each unit homogeneous strain, interior relaxed "
        "(the model's Jacobian at rest, condensed); C_eff from the averaged surface forces.",
        f"Material E = {s.E:g} Pa, nu = {s.nu:g}.",
        "Quick mode." if s.quick else "Full mode."])
    doc.p(_reference_margin(data))
    doc.h(2, "Verification")
    doc.p("Before the models are judged against the references, the references are verified "
          "against exact solutions, every model is put to the patch test with every boundary "
          "node prescribed "
          "(cases/studies/convergence/verification.toml declares both) and the particle runs' "
          "time step is checked.")
    manufactured_section(doc, data)
    patch_section(doc, data, [FEM_P1] + list(s.models))
    steps_section(doc, data)
    doc.h(2, "Convergence")
    for name in s.problems:
        for bc in PROBLEMS[name].bcs:
            _problem_section(doc, out, s, data, name, bc)
    doc.h(2, "Effective elasticity")
    _elasticity_section(doc, out, s, data)
    doc.h(2, "Accuracy per cost")
    _cost_section(doc, out, s, data)
    bad = [r for r in data["runs"] if r.get("failed")]
    if bad:
        doc.h(2, "Runs without equilibrium")
        doc.ul(sorted({f"{r['model']} on {r['case']}/{r['bc']}/{r['mesh']} at h = "
                       f"{r['h_mm']:.3g} mm: {r['failed']}" for r in bad}))
    return doc


def _problem_section(doc, out, s, data, name, bc):
    runs = [r for r in data["runs"] if r["case"] == name and r["bc"] == bc]
    fits = {(f["mesh"], f["model"]): f for f in data["fits"]
            if f["case"] == name and f["bc"] == bc}
    models = [FEM_P1] + list(s.models)
    hs = sorted({r["h_mm"] for r in runs}, reverse=True)
    doc.h(3, f"{name}, {bc}")
    ref = next((r for r in data["references"] if r["case"] == name and r["bc"] == bc), None)
    below = unresolved_below(ref) if ref else 0.0
    if ref:
        doc.p(f"Reference: FEM P2, {ref['dofs']} unknowns, {PROBLEMS[name].label} "
              f"{ref['response_fem']:.4g} (SI units), error estimate "
              f"{rel(ref['error_estimate'], 2)}.")
    label = {n: catalogue.metric(n).label for n in ("disp_rel_l2", "order", "e_inf",
                                                    "reaction_ratio", "ratio_inf")}
    header = ["mesh", "model"] + [f"{label['disp_rel_l2']} @ {h:.3g}" for h in hs] + \
        [label["order"], f"{label['e_inf']} +- err", "verdict",
         f"{label['reaction_ratio']} @ {hs[-1]:.3g}" if hs else label["reaction_ratio"],
         f"{label['ratio_inf']} +- err"]
    rows = []
    series = {}
    for fam in s.meshes:
        for m in models:
            rs = {r["h_mm"]: r for r in runs if r["mesh"] == fam and r["model"] == m}
            if not rs:
                continue
            f = fits.get((fam, m), {})
            pts = [(h, rs[h]["disp_rel_l2"]) for h in hs if h in rs
                   and rs[h].get("disp_rel_l2") is not None]
            if pts:
                series[(fam, m)] = tuple(zip(*pts))
            finest = rs[min(rs)]
            rows.append([fam, m] + [fmt(rs[h].get("disp_rel_l2")) if h in rs else "-"
                                    for h in hs]
                        + [fmt(f.get("order"), 2),
                           "n/a" if f.get("e_inf") is None
                           else f"{f['e_inf']:.2g} +- {f['e_inf_err']:.1g}",
                           verdict_cell(f, rs[min(rs)].get("disp_rel_l2"), below),
                           fmt(finest.get("reaction_ratio")),
                           f"{fmt(f['ratio_inf'])} +- {fmt(f.get('ratio_inf_err') or 0.0, 1)}"
                           if f.get("ratio_inf") is not None
                           else f"n/a ({f.get('ratio_why') or 'no ratio'})"])
    doc.table(header, rows, keys=2)     # a split table repeats the mesh and the model
    blind = blind_text(data, name, bc)
    if blind:
        doc.p(blind)
    png = f"convergence_{name}_{bc}.png"
    error_vs_h(out / png, f"{name}, {bc}: displacement error against h",
                     list(s.meshes), list(s.models), series, FEM_P1)
    doc.img(png, f"{name}, {bc}: error against h, per mesh family (FEM P1 in black)")


def blind_text(data, name, bc):
    """The levels of problem ``name``/``bc`` that test nothing (``blind_levels``), with why:
    those left out of the fits, and those kept because fewer than three levels would remain;
    None where there is none."""
    blind = {k: v for k, v in blind_levels(data["runs"]).items() if k[:2] == (name, bc)}
    if not blind:
        return None
    problem = PROBLEMS.get(name)
    left = {(f["mesh"], h) for f in data.get("fits", ()) if (f["case"], f["bc"]) == (name, bc)
            for h in f.get("left_out_mm") or ()}
    said = {True: [], False: []}
    for (_, _, mesh, h), b in blind.items():
        why = problem.blind_why(h) if problem is not None else None
        said[(mesh, h) in left].append(
            f"h = {h:.3g} mm on {mesh}: every one of the {b['models']} models' displacement "
            f"error there is {b['error']:.3g} to within {b['error_spread']:.1%}, while their "
            f"{problem.label if problem else 'stiffness'} ratios span {b['ratios'][0]:.3g} to "
            f"{b['ratios'][1]:.3g}: the displacement does not depend on the model, so the "
            "error is the mesh's and the level tests nothing" + (f" ({why})" if why else ""))
    out = []
    if said[True]:
        out.append("Left out of the fits (the table shows them, no verdict, order or limit "
                   "uses them): " + "; ".join(said[True]) + ".")
    if said[False]:
        out.append("Kept in the fits, as fewer than three levels would remain, though it "
                   "tests nothing: " + "; ".join(said[False]) + ".")
    return " ".join(out)


def verdict_cell(f, finest, below):
    """A fit's verdict as its table prints it: 'not decided (two levels)' where two levels
    cannot decide it, ', not resolved' where its finest error ``finest`` is below what the
    reference can judge (``below``), ', cancellation' where the series may cancel."""
    v = f.get("verdict", "n/a")
    if v == UNDECIDED:
        v = f"{UNDECIDED} ({UNDECIDED_WHY})"
    elif v in VERDICTS and not decided(f):
        v = "not decided (two levels)"
    elif v != "exact" and finest is not None and finest < below:
        v += ", not resolved"
    return v + (", cancellation" if f.get("cancellation") else "")


def _elasticity_section(doc, out, s, data):
    eff = [e for e in data["elasticity"] if not e.get("failed")]
    G = s.E / (2 * (1 + s.nu))
    doc.p(f"Target: isotropic E = {s.E:g} Pa, nu = {s.nu:g}, G = {G:.4g} Pa. Moduli below are "
          "over the target's.")
    doc.table(["lattice", "model", "E_x/E", "E_y/E", "E_z/E", "E_110/E", "E_111/E", "nu_yx",
               "nu_xz", "G_yz/G", "G_xz/G", "G_xy/G", "A_U", "K/K"]
              + [f"mu_{k}/2G" for k in range(1, 6)] + ["moduli err", "asymmetry"],
              [[e["mesh"], e["model"], fmt(e["E_x_pa"] / s.E), fmt(e["E_y_pa"] / s.E),
                fmt(e["E_z_pa"] / s.E), fmt(e["E_110_pa"] / s.E), fmt(e["E_111_pa"] / s.E),
                fmt(e["nu_yx"]), fmt(e["nu_xz"]), fmt(e["G_yz_pa"] / G), fmt(e["G_xz_pa"] / G),
                fmt(e["G_xy_pa"] / G), fmt(e["anisotropy_AU"], 2), fmt(1 + e["bulk_rel_err"])]
               + [fmt(1 + d) for d in e["deviatoric_rel_err"]]
               + [fmt(e["moduli_rel_err"], 2), fmt(e["asymmetry"], 2)] for e in eff])
    failed = [e for e in data["elasticity"] if e.get("failed")]
    if failed:
        doc.p("No effective tensor: " + "; ".join(f"{e['model']} on {e['mesh']}: {e['failed']}"
                                                  for e in failed) + ".")
    doc.h(3, "What the tensors explain")
    doc.ul(ties(s, data))
    directional_young(out / "directional_young.png", ANGLES_DEG, list(s.meshes),
                            list(s.models), {(e["mesh"], e["model"]): e["E_xy_plane_pa"]
                                             for e in eff}, s.E)
    doc.img("directional_young.png", "Directional Young's modulus per lattice and model")


def _cost_section(doc, out, s, data):
    c = data.get("cost")
    if not c:
        doc.p("No benchmark found (reports/bench/bench.json): run `pbcm bench` for the step "
              "costs.")
        return
    rows = []

    def point(p):
        return (f"{p['model']} ({p['mesh']}, h {p['h_mm']:.3g}: {p['cost_us']:.3g} us, "
                f"e {p['disp_rel_l2']:.2g})")

    u_ref = {(r["case"], r["bc"]): r.get("error_estimate") or 0.0
             for r in data.get("references", [])}

    def pick(g, target):
        u = u_ref.get((g["case"], g["bc"]), 0.0)
        best, by_c = cheapest_run(g["points"], target, u, REF_MARGIN)
        if by_c is None:
            return (f"not judged (the reference's estimate {u:.2g} is above a fifth of the "
                    "target)")
        return (point(best) if best else "none") + ("; reaching it only by cancellation, not "
                                                   "picked: " + "; ".join(
            f"{point(p)}, FEM P1 {p['p1_error']:.2g} there" for p in by_c) if by_c else "")
    for g in c["groups"]:
        rows.append([f"{g['case']} {g['bc']}", len(g["points"]),
                     "; ".join(point(g["points"][i]) for i in g["front"]),
                     pick(g, BUDGETS[0]), pick(g, BUDGETS[1])])
    doc.p("The Pareto front of each problem: the runs no other run beats in both step cost "
          "and displacement error (a gain within the reference's estimate beats nothing), "
          "cheapest first; and the cheapest run that reaches an error "
          f"target, not judged where the reference's estimate exceeds 1/{REF_MARGIN:g} of "
          "the target. A run whose series may cancel rather than converge (its error not monotone "
          "in h, or its stiffness ratio crossing 1; round-off never counts) is never on the "
          "front nor the cheapest, nor is a run whose error is below FEM P1's on the same mesh "
          "and level by more than the reference's estimate (its lead is its model-form error "
          "offsetting the discretisation error every model on that mesh shares), nor a run at "
          "a level left out of the fits because it tests nothing. A run that "
          "reaches a target on a mesh where FEM P1 does not reaches it only by cancellation: "
          "the discretisation error alone exceeds the target there, and the model gets below "
          "it only because its model-form error (at least the difference of the two errors) "
          "offsets it; such runs are named in the cell and never picked.")
    doc.table(["problem", "runs", "front", f"cheapest with e <= {BUDGETS[0]:g}",
               f"cheapest with e <= {BUDGETS[1]:g}"], rows)
    pareto(out / "pareto.png", c["groups"], list(s.models), EXACT)
    doc.img("pareto.png", "Error against the cost of one RK4 step, with the Pareto front "
            f"(errors below {EXACT:g}, exact, drawn on the dotted line)")


__all__ = ["write", "conclusion", "gate_rows", "GATED", "metrics_document"]
