"""What the artefact study's cells say: the paper's question (section 5: do the alternating
bulges and necks come from the mirror symmetry of the tetrahedra or from the missing normal
stress?) answered hypothesis by hypothesis from the period-2 signature on meshes of at least
DECISIVE layers, and which reading of the paper's equations its own observables point to.
Everything here is computed from the cells' rows; the mesh is the unit (a model's cells on
one mesh are one observation per base, at the paper's push)."""
import numpy as np
from scipy.stats import spearmanr

from ...document import fmt
from ...metrics import ALTERNATION_CLEAR
from .study import DECISIVE, SPLITS

PAPER_COST = 10.0      # the paper: a step costs more than 10 times msm's
SURE_MARGIN = 2        # observables by which the verdict must lead to be called clear
REMOVES = 0.5          # a factor holds as the cause where it removes the pattern this often
TRACKS = 0.7           # a rank correlation from which the signature tracks the patch error
# a signature is resolved above what the metric reads of a smooth bump two layers wide as
# high as the mean lateral displacement (tests/test_alternation.py: below 3e-3 of its height on
# 9 layers, 1e-4 on 17); visible (the paper's "clear" pattern) from ALTERNATION_CLEAR
RESOLVED = {9: 3e-3, 17: 1e-4}


def resolved(value, n):
    """Whether a signature on ``n`` layers is above the metric's smooth-shape floor there."""
    floor = RESOLVED.get(n, max(RESOLVED.values()))
    return value is not None and abs(value) >= floor
RATIO = 3.0            # one signature dominates another from this factor
MIRRORED, UNMIRRORED = SPLITS["five"], SPLITS["five-unmirrored"]
CONFORMING_CONTROLS = (SPLITS["six"], SPLITS["bcc"])
CONTROL = "fem"


def pattern(row):
    """'paper' (the paper's sign: the layers of even index from the base out, signature at
    least the clear level), 'reversed', 'none', or None where the signature is not defined or
    the run failed."""
    a = row.get("alternation_rel")
    if row.get("failed") or a is None:
        return None
    return "paper" if a >= ALTERNATION_CLEAR else "reversed" if a <= -ALTERNATION_CLEAR \
        else "none"


def alternating(row):
    """True where the signature is clear, either sign; None where it is not defined."""
    p = pattern(row)
    return None if p is None else p != "none"


def decisive(cells):
    """The cells that decide: the paper's push, at least DECISIVE layers."""
    return [c for c in cells if c["load"] == "paper" and c["nodes_per_side"] >= DECISIVE]


def _index(cells):
    return {(c["model"], c["split"], c["nodes_per_side"], c["bc"]): c for c in cells}


def _sizes(cells):
    return sorted({c["nodes_per_side"] for c in cells})


def _size(x):
    return abs(x) if x is not None else None


def mirror(cells):
    """Hypothesis (a), the mirror symmetry: per model, base and size (from DECISIVE layers),
    the signature on the mirrored five split against the conforming splits without the
    mirror (six, bcc). An observation reads 'mirror' where the mirrored split's signature is
    resolved (``resolved``) and RATIO times every control's, 'everywhere' where a control's is
    within that factor, 'unmirrored' where only a control's is resolved, 'none' where none
    is; the hypothesis holds where 'mirror' is at least REMOVES of the resolved observations.
    The FEM control on the same tetrahedra is read alike and counted apart ('control'), and a
    model's 'mirror' observation is its own where it is RATIO times the control's on the same
    mesh and base. Also each model's order in h on the mirrored split (where its signature is
    resolved at 9 and 17 nodes per side) and the median ratio mirrored / largest control."""
    at = _index(decisive(cells))
    rows = []
    count = {"mirror": 0, "everywhere": 0, "unmirrored": 0, "none": 0}
    control = dict.fromkeys(count, 0)
    ratios, own = [], 0
    for (model, split, n, bc), c in sorted(at.items(), key=lambda kv: str(kv[0])):
        if split != MIRRORED or alternating(c) is None:
            continue
        controls = [at.get((model, k, n, bc)) for k in CONFORMING_CONTROLS]
        controls = [x for x in controls if x is not None and alternating(x) is not None]
        if not controls:
            continue
        five, other = abs(c["alternation_rel"]), max(abs(x["alternation_rel"])
                                                     for x in controls)
        kind = ("none" if not (resolved(five, n) or resolved(other, n)) else "unmirrored"
                if not resolved(five, n) else "mirror" if five >= RATIO * other
                else "everywhere")
        fem = next((x for (m, sp, k, b), x in at.items() if sp == MIRRORED and k == n
                    and b == bc and x["family"] == CONTROL), None)
        if c["family"] == CONTROL:
            control[kind] += 1
        else:
            count[kind] += 1
            if resolved(five, n):
                ratios.append(five / max(other, 1e-300))
            if kind == "mirror" and fem is not None and fem.get("alternation_rel") is not None \
                    and five >= RATIO * abs(fem["alternation_rel"]):
                own += 1
        rows.append({"model": model, "family": c["family"], "bc": bc, "n": n, "kind": kind,
                     "five": c["alternation_rel"],
                     "controls": {x["split"]: x["alternation_rel"] for x in controls},
                     "unmirrored": (at.get((model, UNMIRRORED, n, bc)) or {}).get(
                         "alternation_rel")})
    orders = {}
    for r in rows:
        fine = at.get((r["model"], MIRRORED, 2 * r["n"] - 1, r["bc"]))
        if r["family"] != CONTROL and resolved(r["five"], r["n"]) and fine \
                and resolved(fine.get("alternation_rel"), fine["nodes_per_side"]):
            orders[f"{r['model']} / {r['bc']}"] = float(np.log2(
                abs(r["five"]) / abs(fine["alternation_rel"])))
    found = count["mirror"] + count["everywhere"] + count["unmirrored"]
    return {"rows": rows, "count": count, "control": control, "own": own, "orders": orders,
            "holds": found > 0 and count["mirror"] >= REMOVES * found,
            "ratio_median": float(np.median(ratios)) if ratios else None,
            "order_median": float(np.median(list(orders.values()))) if orders else None}


def normal_stress(cells):
    """Hypothesis (b), the missing normal stress: per mesh (from DECISIVE layers), base and
    calibrated reading, the signature without a normal-stress term against it with each term,
    the split held fixed. Per term: the pairs whose signature without it is resolved, how
    many the term reduces by RATIO or more, and the median ratio |with| / |without| there;
    the hypothesis holds where the terms reduce at least REMOVES of those pairs."""
    at = {(c["mesh"], c["bc"], c["reading"], c["normal"]): c for c in decisive(cells)
          if c["family"] == "particle" and c["constant"] == "calibrated"}
    terms = sorted({k[3] for k in at} - {"none"})
    out = {}
    for term in terms:
        had = removed = pairs = 0
        ratios = []
        for (mesh, bc, reading, normal), base in at.items():
            if normal != "none" or alternating(base) is None:
                continue
            w = at.get((mesh, bc, reading, term))
            if w is None or alternating(w) is None:
                continue
            pairs += 1
            if resolved(base["alternation_rel"], base["nodes_per_side"]):
                had += 1
                ratio = abs(w["alternation_rel"]) / abs(base["alternation_rel"])
                removed += ratio * RATIO <= 1.0
                ratios.append(ratio)
        out[term] = {"pairs": pairs, "resolved_without": had, "removed": removed,
                     "ratio_median": float(np.median(ratios)) if ratios else None}
    had = sum(v["resolved_without"] for v in out.values())
    removed = sum(v["removed"] for v in out.values())
    msm = [c for c in decisive(cells) if c["family"] == "msm" and c["reading"] == "none"
           and alternating(c) is not None]
    return {"terms": out, "resolved_without": had, "removed": removed,
            "holds": had > 0 and removed >= REMOVES * had,
            "msm": [sum(resolved(c["alternation_rel"], c["nodes_per_side"]) for c in msm),
                    len(msm)]}


def consistency(cells):
    """Hypothesis (c), the model's consistency: per conforming mesh with the linear regime
    (a patch test on the sliding base) and from DECISIVE layers, the rank correlation over
    the approximations (the control left out) between the signature's magnitude at the
    paper's push on the sliding base and the patch test's displacement error."""
    per = {}
    for c in cells:
        if (c["nodes_per_side"] < DECISIVE or c["bc"] != "sliding" or c["family"] == CONTROL
                or c["split"] == UNMIRRORED or c.get("failed")):
            continue
        per.setdefault(c["mesh"], {}).setdefault(c["model"], {})[c["load"]] = c
    rows = []
    for mesh, by_model in per.items():
        pts = [(abs(v["paper"]["alternation_rel"]), v["linear"]["disp_rel_l2"])
               for v in by_model.values() if "paper" in v and "linear" in v
               and v["paper"].get("alternation_rel") is not None
               and v["linear"].get("disp_rel_l2") is not None]
        if len(pts) < 3:
            continue
        sig, err = np.array(pts).T
        rho = float(spearmanr(sig, err).statistic) if np.ptp(sig) and np.ptp(err) else None
        rows.append({"mesh": mesh, "models": len(pts), "rho": rho,
                     "clear": int((sig >= ALTERNATION_CLEAR).sum())})
    rhos = [r["rho"] for r in rows if r["rho"] is not None]
    median = float(np.median(rhos)) if rhos else None
    return {"rows": rows, "rho_median": median,
            "holds": median is not None and median >= TRACKS}


def control(cells):
    """The FEM control (constant-strain FEM on the same tetrahedra) on the conforming meshes
    from DECISIVE layers: its cells with a resolved signature over its defined ones, and
    where."""
    fem = [c for c in decisive(cells) if c["family"] == CONTROL and c["split"] != UNMIRRORED
           and alternating(c) is not None]
    found = [c for c in fem if resolved(c["alternation_rel"], c["nodes_per_side"])]
    return [len(found), len(fem), sorted({f"{c['mesh']}/{c['bc']}" for c in found})]


def linear_check(cells):
    """The linear-regime load against the paper's push, cell by cell (from DECISIVE layers):
    how often the two agree on whether the signature is clear (the linear load is a check,
    not a second observation)."""
    at = {}
    for c in cells:
        if c["nodes_per_side"] >= DECISIVE and alternating(c) is not None:
            at.setdefault((c["mesh"], c["model"], c["bc"]), {})[c["load"]] = alternating(c)
    both = [v for v in at.values() if len(v) == 2]
    return [sum(v["paper"] == v["linear"] for v in both), len(both)]


def paper_view(cells):
    """The paper's own 5-layer view on the mirrored five split (sliding base, the paper's
    push): the models whose signature there has the paper's sign, never a verdict."""
    rows = [c for c in cells if c["split"] == MIRRORED and c["nodes_per_side"] < DECISIVE
            and c["bc"] == "sliding" and c["load"] == "paper" and pattern(c) is not None]
    return [sorted(c["model"] for c in rows if pattern(c) == "paper"), len(rows)]


def answer(cells):
    """The paper's question answered per hypothesis from the cells of at least DECISIVE
    layers: each hypothesis with the numbers that decide it, and the cause: the hypotheses
    that hold, or none of them. Without such cells: not decided."""
    sizes = [n for n in _sizes(cells) if n >= DECISIVE]
    if not sizes:
        return {"decided": False, "cause": "not decided", "text": (
            f"Not decided: no mesh with {DECISIVE} or more layers was run (the 5-layer view "
            "cannot tell a smooth bump from an alternation)."), "hypotheses": {}}
    m, ns, cs = mirror(cells), normal_stress(cells), consistency(cells)
    fem, lin, view = control(cells), linear_check(cells), paper_view(cells)
    k = m["count"]
    said_sizes = " and ".join(str(n) for n in sizes)
    top = max((c for c in decisive(cells) if alternating(c) is not None
               and c["family"] != CONTROL), key=lambda c: abs(c["alternation_rel"]),
              default=None)
    parts = [
        f"On meshes of {said_sizes} nodes per side, at the paper's push, the largest period-2 "
        "signature is "
        + (f"{fmt(top['alternation_rel'])} of the mean lateral displacement ({top['model']}, "
           f"{top['mesh']}, {top['bc']} base), "
           + ("visible" if abs(top["alternation_rel"]) >= ALTERNATION_CLEAR else "below "
              f"the visible level {ALTERNATION_CLEAR:g}") if top else "not defined")
        + "; resolved from " + ", ".join(f"{v:g} on {n}" for n, v in RESOLVED.items())
        + " layers (the metric's reading of a smooth bump). (a) Mirror symmetry: the mirrored "
        f"five split's signature is resolved and {RATIO:g} times every conforming split's "
        f"without the mirror (six, bcc) in {k['mirror']}, resolved on both within that factor "
        f"in {k['everywhere']}, on the unmirrored splits only in {k['unmirrored']}, unresolved "
        f"in {k['none']} of {sum(k.values())} (model, base, size) observations"
        + (f" (median ratio mirrored / unmirrored {m['ratio_median']:.3g})"
           if m["ratio_median"] is not None else "")
        + f"; {m['own']} of the {k['mirror']} are {RATIO:g} times the FEM control's on the same "
        f"mirrored mesh and base (the model's own), the rest shared with FEM P1, whose own "
        f"signature reads mirror in {m['control']['mirror']} of {sum(m['control'].values())} "
        "(base, size) observations"
        + (f"; where resolved at 9 and 17 nodes per side it falls as h^"
           f"{m['order_median']:.1f} (median order over {len(m['orders'])} models and bases)"
           if m["order_median"] is not None else "") + ".",
        f"(b) Missing normal stress: a normal-stress term, the split held fixed, reduces a "
        f"resolved signature {RATIO:g}-fold or more in {ns['removed']} of "
        f"{ns['resolved_without']} pairs ("
        + ", ".join(f"{t} {v['removed']} of {v['resolved_without']}"
                    + (f", |with| / |without| median {v['ratio_median']:.2f}"
                       if v["ratio_median"] is not None else "")
                    for t, v in ns["terms"].items())
        + f"); msm, whose forces are all normal (along edges), is resolved in {ns['msm'][0]} "
        f"of {ns['msm'][1]}.",
        "(c) The model's consistency: the rank correlation between a model's signature and "
        "its patch-test error on the same mesh (sliding base) is "
        + (", ".join(f"{r['mesh']} {r['rho']:.2f} ({r['models']} models)"
                     for r in cs["rows"] if r["rho"] is not None) or "not defined")
        + ".",
        f"The FEM control's own signature is resolved in {fem[0]} of {fem[1]} conforming cells"
        + (f" ({', '.join(fem[2])})" if fem[2] else "") + "; the linear-regime load agrees "
        f"with the paper's push on whether the signature is visible in {lin[0]} of {lin[1]} "
        "cells. The paper's own 5-layer view (mirrored five, sliding base) shows the paper's "
        f"sign for {len(view[0])} of {view[1]} models"
        + (f" ({', '.join(view[0])})" if view[0] else "") + ": a view, not a verdict."]
    held = [name for name, h in (("the mirror symmetry of the five split", m["holds"]),
                                 ("the missing normal stress", ns["holds"]),
                                 ("the model's consistency error", cs["holds"])) if h]
    resolved = sum(v for kind, v in k.items() if kind != "none") + ns["resolved_without"]
    cause = (" and ".join(held) if held and resolved else
             f"no resolved period-2 pattern from {DECISIVE} nodes per side" if not resolved
             else "none of the three: neither the mirror symmetry, nor the missing normal "
             "stress, nor the model's consistency error")
    parts.append(f"So the pattern comes from {cause}.")
    return {"decided": True, "cause": cause, "text": " ".join(parts),
            "hypotheses": {"mirror": m, "normal_stress": ns, "consistency": cs},
            "control": fem, "linear_check": lin, "paper_view": view}


def _pct(x):
    return "n/a" if x is None else f"{100 * x:.0f} %"


OBSERVABLES = {"pattern": "the bulge/neck pattern on the paper's 5-layer mirrored five cube "
                          "(sliding base)",
               "cost": f"a step over {PAPER_COST:g} times msm's",
               "stable": "a clamped RK4 run without flutter"}


def reading_table(cells, step_vs_msm, readings):
    """One row per reading (calibrated and literal): the paper's observables on its own
    lattice (the mirrored five split, 5 nodes per side) and how many it matches; the pattern
    is read only where the FEM control does not alternate there."""
    unresolved = {(c["mesh"], c["bc"], c["load"]) for c in cells
                  if c["family"] == CONTROL and alternating(c)}
    rows = []
    for model in readings:
        mine = [c for c in cells if c["model"] == model and c["split"] == MIRRORED
                and c["nodes_per_side"] < DECISIVE]
        sliding = [c for c in mine if c["bc"] == "sliding" and c["load"] == "paper"
                   and pattern(c) is not None
                   and (c["mesh"], c["bc"], c["load"]) not in unresolved]
        shows = sum(pattern(c) == "paper" for c in sliding)
        clamped = [c for c in mine if c["bc"] == "clamped" and c["load"] == "paper"]
        rates = [c["growth_rate_1_s"] for c in clamped if c.get("growth_rate_1_s") is not None]
        flutter = sum(bool(c.get("flutter")) for c in clamped if c.get("flutter") is not None)
        consistency_ = [c["disp_rel_l2"] for c in mine if c["bc"] == "sliding"
                        and c["load"] == "linear" and c.get("disp_rel_l2") is not None]
        finite = [c["disp_rel_l2"] for c in clamped if c.get("disp_rel_l2") is not None]
        cost = step_vs_msm.get(model)
        matches = {"pattern": shows > 0, "cost": cost is not None and cost > PAPER_COST,
                   "stable": bool(rates) and flutter == 0}
        rows.append({"model": model, "pattern": [shows, len(sliding)],
                     "pattern_median_rel": _median([c["alternation_rel"] for c in sliding]),
                     "step_vs_msm": cost, "flutter": [flutter, len(rates)],
                     "growth_max_1_s": max(rates) if rates else None,
                     "sliding_disp_median": _median(consistency_),
                     "paper_push_disp_median": _median(finite),
                     "matches": matches, "score": sum(matches.values())})
    return rows


def _median(v):
    v = [x for x in v if x is not None]
    return float(np.median(v)) if v else None


def reading_verdict(table, damping):
    """The reading that matches most of the paper's observables, and how sure that is: the
    margin over the runner-up (clear from SURE_MARGIN observables, weak from one, none: a
    tie); where no reading matches them all, said plainly with what each fails. ``damping``
    the mass damping [1/s] the flutter criterion assumes (the paper states none)."""
    ranked = sorted(table, key=lambda r: (-r["score"], r["sliding_disp_median"] or np.inf))
    best, second = ranked[0], ranked[1] if len(ranked) > 1 else None
    margin = best["score"] - (second["score"] if second else 0)
    tied = [r["model"] for r in ranked if r["score"] == best["score"]]
    sure = "clear" if margin >= SURE_MARGIN else "weak" if margin == 1 else "undecided"
    total = len(best["matches"])
    fails = {r["model"]: [OBSERVABLES[k] for k, v in r["matches"].items() if not v]
             for r in ranked}
    none_all = all(fails.values())
    plain = ("No reading reproduces all the paper's observables: "
             + "; ".join(f"{m} lacks {', '.join(f)}" for m, f in fails.items() if f) + ". "
             if none_all else "")
    if sure == "undecided":
        text = (f"Undecided: {', '.join(tied)} each match {best['score']} of {total} of the "
                "paper's observables.")
    else:
        text = (f"{best['model']} matches {best['score']} of {total} of the paper's "
                f"observables, {margin} more than the next ({second['model']}): a {sure} "
                "verdict.")
    text = (plain + text + f" Flutter: a linearised growth rate above half the mass damping "
            f"we assume, {damping:g} 1/s (the paper states none).")
    return {"model": best["model"], "sure": sure, "margin": margin, "tied": tied,
            "none_reproduces": none_all, "fails": fails, "text": text}
