"""What the artefact study's cells say: the paper's question (section 5: do the alternating
bulges and necks come from the mirror symmetry of the tetrahedra or from the missing normal
stress?) answered hypothesis by hypothesis from the period-2 signature on meshes of at least
DECISIVE layers, and which reading of the paper's equations its own observables point to.
Everything here is computed from the cells' rows; the mesh is the unit (a model's cells on
one mesh are one observation per base, at the paper's push)."""
import numpy as np
from scipy.stats import spearmanr

from ...document import fmt, rel
from ...metrics import ALTERNATION_CLEAR
from .study import DECISIVE, SPLITS, YARDSTICK as YARDSTICK_MODEL, short

PAPER_COST = 10.0      # the paper: a step costs more than 10 times msm's
SURE_MARGIN = 2        # observables by which the verdict must lead to be called clear
REMOVES = 0.5          # a factor holds as the cause where it removes the pattern this often
TRACKS = 0.7           # a rank correlation from which the signature tracks the patch error
RATIO = 3.0            # one signature dominates another from this factor
ROUND_OFF_FLOOR = 1e-8     # no floor is taken below this (a patch test's exact answer)
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


def floors(cells):
    """{(nodes per side, base): the signature a mesh without the mirror gives FEM P1}: the
    largest |signature| of the FEM control on the conforming splits without the mirror (six,
    bcc) at that size and base, at least ROUND_OFF_FLOOR: what the metric reads of a
    discretisation with no period-2 cause, measured, not assumed."""
    out = {}
    for c in decisive(cells):
        if c["family"] == CONTROL and c["split"] in CONFORMING_CONTROLS \
                and c.get("alternation_rel") is not None:
            k = (c["nodes_per_side"], c["bc"])
            out[k] = max(out.get(k, ROUND_OFF_FLOOR), abs(c["alternation_rel"]))
    return out


def resolved(value, n, bc, floor):
    """Whether a signature on ``n`` layers under base ``bc`` is RATIO times the floor there."""
    f = floor.get((n, bc))
    return value is not None and f is not None and abs(value) >= RATIO * f


def _same(a, b):
    return a is not None and b is not None and abs(a - b) <= 1e-9 * max(abs(a), abs(b))


def mirror(cells):
    """Hypothesis (a), the mirror symmetry, with the mesh as the unit: per size and base (from
    DECISIVE layers), the mirrored five split's signature of each model against the
    conforming splits without the mirror (six, bcc) and against FEM P1 on the same mirrored
    mesh. A model reads 'own' where its signature has the paper's sign, is resolved
    (``floors``) and RATIO times every control's and FEM P1's there; 'shared' where it is
    resolved and RATIO times the controls' but within RATIO of FEM P1's (the mesh's own
    error, which FEM P1 has too); 'reversed' with the opposite sign; 'none' otherwise.
    A model whose mirrored signature equals one already counted in the unit is one
    observation with it (a term that changes nothing); a control not run at a size is left
    out, one that failed makes the model's observation failed. Per (size, base): the models in each class, FEM P1's signature on the
    mirrored and the unmirrored splits, and a failed control named. The hypothesis holds
    where the mirrored split's signature dominates in every (size, base) unit it is resolved
    in; each model's order in h from 9 to 17 nodes per side where resolved at both."""
    at = _index(decisive(cells))
    floor = floors(cells)
    units = []
    seen = {}
    for (n, bc) in sorted({(k[2], k[3]) for k in at}):
        fem = at.get((YARDSTICK_MODEL, MIRRORED, n, bc))
        fem_five = None if fem is None else fem.get("alternation_rel")
        classes = {"own": [], "shared": [], "reversed": [], "none": []}
        failed, ratios = [], []
        for (model, split, k, b), c in sorted(at.items(), key=lambda kv: str(kv[0])):
            if (split, k, b) != (MIRRORED, n, bc) or c["family"] == CONTROL:
                continue
            five = c.get("alternation_rel")
            ctrl = [at[(model, x, n, bc)] for x in CONFORMING_CONTROLS
                    if (model, x, n, bc) in at]          # the controls run at this size
            if not ctrl:
                continue
            if five is None or any(x.get("alternation_rel") is None for x in ctrl):
                failed.append(short(model))
                continue
            if any(_same(five, v) for v in seen.get((n, bc), {}).values()):
                continue                    # the same answer as a model already counted
            seen.setdefault((n, bc), {})[model] = five
            other = max(abs(x["alternation_rel"]) for x in ctrl)
            ratios.append(abs(five) / max(other, ROUND_OFF_FLOOR))
            if not resolved(five, n, bc, floor) or abs(five) < RATIO * other:
                kind = "none"
            elif five < 0:
                kind = "reversed"
            elif fem_five is not None and abs(five) < RATIO * abs(fem_five):
                kind = "shared"
            else:
                kind = "own"
            classes[kind].append(short(model))
        units.append({"n": n, "bc": bc, "floor": floor.get((n, bc)), "fem_five": fem_five,
                      "fem_resolved": resolved(fem_five, n, bc, floor), "classes": classes,
                      "failed": failed,
                      "ratio_median": float(np.median(ratios)) if ratios else None})
    rows = []
    for (model, split, n, bc), c in sorted(at.items(), key=lambda kv: str(kv[0])):
        if split == MIRRORED:
            ctrl = {x: (at.get((model, x, n, bc)) or {}).get("alternation_rel")
                    for x in CONFORMING_CONTROLS}
            rows.append({"model": model, "family": c["family"], "bc": bc, "n": n,
                         "five": c.get("alternation_rel"), "controls": ctrl,
                         "unmirrored": (at.get((model, UNMIRRORED, n, bc)) or {}).get(
                             "alternation_rel"),
                         "kind": next((k for u in units if (u["n"], u["bc"]) == (n, bc)
                                       for k, ms in u["classes"].items() if short(model) in ms),
                                      "control" if c["family"] == CONTROL else "same as "
                                      "another model" if c.get("alternation_rel") is not None
                                      else "failed")})
    orders = {}
    for r in rows:
        fine = at.get((r["model"], MIRRORED, 2 * r["n"] - 1, r["bc"]))
        if fine and resolved(r["five"], r["n"], r["bc"], floor) \
                and resolved(fine.get("alternation_rel"), fine["nodes_per_side"], r["bc"], floor):
            orders[f"{r['model']} / {r['bc']}"] = float(np.log2(
                abs(r["five"]) / abs(fine["alternation_rel"])))
    found = [u for u in units if any(u["classes"][k] for k in ("own", "shared"))]
    return {"units": units, "rows": rows, "orders": orders,
            "holds": bool(found),
            "own": sorted({m for u in units for m in u["classes"]["own"]}),
            "order_range": [min(orders.values()), max(orders.values())] if orders else None,
            "order_median": float(np.median(list(orders.values()))) if orders else None}


def normal_stress(cells):
    """Hypothesis (b), the missing normal stress: per mesh (from DECISIVE layers), base and
    calibrated reading whose own signature (``mirror``'s 'own': beyond FEM P1's, which has
    the full normal stress) exists without a normal-stress term, the signature with each term,
    the split held fixed. Per term: those pairs and how many the term reduces RATIO-fold or
    more; not decided where no such pair was run."""
    m = mirror(cells)
    own = {(u["n"], u["bc"], x) for u in m["units"] for x in u["classes"]["own"]}
    at = {(c["mesh"], c["bc"], c["reading"], c["normal"]): c for c in decisive(cells)
          if c["family"] == "particle" and c["constant"] == "calibrated"}
    terms = sorted({k[3] for k in at} - {"none"})
    out = {}
    for term in terms:
        pairs = removed = 0
        ratios = []
        for (mesh, bc, reading, normal), base in at.items():
            if normal != "none" or (base["nodes_per_side"], bc, short(base["model"])) not in own \
                    or base["split"] != MIRRORED:
                continue
            w = at.get((mesh, bc, reading, term))
            if w is None or w.get("alternation_rel") is None:
                continue
            pairs += 1
            ratio = abs(w["alternation_rel"]) / abs(base["alternation_rel"])
            removed += ratio * RATIO <= 1.0
            ratios.append(ratio)
        out[term] = {"pairs": pairs, "removed": removed,
                     "ratio_median": float(np.median(ratios)) if ratios else None}
    pairs = sum(v["pairs"] for v in out.values())
    removed = sum(v["removed"] for v in out.values())
    return {"terms": out, "pairs": pairs, "removed": removed, "decided": pairs > 0,
            "holds": pairs > 0 and removed >= REMOVES * pairs}


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


def paper_view(cells):
    """The paper's own 5-layer view on the mirrored five split (sliding base, the paper's
    push): the models whose signature there has the paper's sign, never a verdict."""
    rows = [c for c in cells if c["split"] == MIRRORED and c["nodes_per_side"] < DECISIVE
            and c["bc"] == "sliding" and c["load"] == "paper" and pattern(c) is not None]
    return [sorted(c["model"] for c in rows if pattern(c) == "paper"), len(rows)]


def _names(models):
    return ", ".join(models) if models else "none"


def answer(cells):
    """The paper's question answered per hypothesis from the cells of at least DECISIVE
    layers, the unit a (size, base) of the mirrored mesh: each hypothesis with the numbers
    that decide it or 'not decided', and the cause. Without such cells: not decided."""
    sizes = [n for n in _sizes(cells) if n >= DECISIVE]
    if not sizes:
        return {"decided": False, "cause": "not decided", "text": (
            f"Not decided: no mesh with {DECISIVE} or more layers was run (the 5-layer view "
            "cannot tell a smooth bump from an alternation)."), "hypotheses": {}}
    m, ns, cs = mirror(cells), normal_stress(cells), consistency(cells)
    view = paper_view(cells)
    top = max((c for c in decisive(cells) if c.get("alternation_rel") is not None
               and c["family"] != CONTROL), key=lambda c: abs(c["alternation_rel"]),
              default=None)
    visible = top is not None and abs(top["alternation_rel"]) >= ALTERNATION_CLEAR
    units = []
    for u in m["units"]:
        k = u["classes"]
        units.append(
            f"{u['n']} nodes per side, {u['bc']} base (floor {rel(u['floor'], 2)}; FEM P1 "
            f"{rel(u['fem_five'], 2)}" + (", resolved" if u["fem_resolved"] else "")
            + f"): own {_names(k['own'])}; shared with FEM P1 {len(k['shared'])}; reversed "
            f"{_names(k['reversed'])}; none {len(k['none'])}"
            + (f"; failed {_names(u['failed'])}" if u["failed"] else ""))
    parts = [
        f"On meshes of {' and '.join(map(str, sizes))} nodes per side, at the paper's push, "
        "the largest period-2 signature is "
        + (f"{fmt(top['alternation_rel'])} of the mean lateral displacement ({top['model']}, "
           f"{top['mesh']}, {top['bc']} base): "
           + ("visible" if visible else f"nothing reaches the visible level "
              f"{ALTERNATION_CLEAR:g}, so any link to the paper's visible pattern is an "
              "extrapolation") if top else "not defined") + ".",
        "(a) Mirror symmetry, per (size, base) of the mirrored five split, a model's "
        f"signature resolved (RATIO {RATIO:g} times the floor: FEM P1's largest on the "
        "conforming splits without the mirror there) and "
        f"{RATIO:g} times every such split's: " + "; ".join(units)
        + (f". Where resolved at 9 and 17 nodes per side it falls as h^"
           f"{m['order_range'][0]:.1f} to h^{m['order_range'][1]:.1f} (median "
           f"{m['order_median']:.1f}, two sizes)" if m["order_range"] else "") + ".",
        "(b) Missing normal stress: "
        + ("not decided: no normal-stress term was run beside a reading whose own signature "
           "(beyond FEM P1's, which has the full normal stress) exists" if not ns["decided"]
           else f"a term reduces a model's own signature {RATIO:g}-fold or more in "
           f"{ns['removed']} of {ns['pairs']} pairs (" + ", ".join(
               f"{t} {v['removed']} of {v['pairs']}" for t, v in ns["terms"].items()
               if v["pairs"]) + ")") + ".",
        "(c) The model's consistency: "
        + ("the rank correlation between a model's signature and its patch-test error "
           "(sliding base) is " + ", ".join(f"{r['mesh']} {r['rho']:.2f}" for r in cs["rows"]
                                            if r["rho"] is not None)
           + (": it tracks it" if cs["holds"] else ": not resolved (it changes sign or "
              f"stays below {TRACKS:g})") if cs["rows"] else "not defined") + ".",
        "The paper's own 5-layer view (mirrored five, sliding base) shows the paper's sign "
        f"for {len(view[0])} of {view[1]} models"
        + (f" ({', '.join(view[0])})" if view[0] else "") + ": a view, not a verdict."]
    own = m["own"]
    shared = any(u["classes"]["shared"] or u["fem_resolved"] for u in m["units"])
    if not m["holds"]:
        cause = (f"not decided: no resolved period-2 signature from {DECISIVE} nodes per side"
                 if not own and not shared else "none of the three hypotheses")
    else:
        cause = ("the mirror symmetry of the five split"
                 + (": FEM P1 on the mirrored split has it too where the base is clamped "
                    "(the mesh's own period-2 error)" if shared else "")
                 + (f", and beyond it the model's own in {', '.join(own)}" if own else "")
                 + ("; the missing normal stress "
                    + ("adds to it" if ns["holds"] else "does not change it")
                    if ns["decided"] else "; the missing normal stress: not decided"))
    parts.append(f"So the pattern comes from {cause}.")
    return {"decided": m["holds"], "cause": cause, "text": " ".join(parts),
            "hypotheses": {"mirror": m, "normal_stress": ns, "consistency": cs},
            "paper_view": view, "visible": visible, "ratio": RATIO, "decisive": DECISIVE,
            "largest": None if top is None else top["alternation_rel"]}


def _pct(x):
    return "n/a" if x is None else f"{100 * x:.0f} %"


# the observables a run can decide; the paper's pattern is seen on its 5 layers only, where
# the signature cannot tell a smooth bump from an alternation: shown, never scored
OBSERVABLES = {"cost": f"a step over {PAPER_COST:g} times msm's",
               "stable": "a clamped RK4 run without flutter"}


def reading_table(cells, step_vs_msm, readings):
    """One row per reading (calibrated and literal): the paper's observables on its own
    lattice (the mirrored five split, 5 nodes per side) and how many of the decidable ones
    (OBSERVABLES) it matches; the 5-layer pattern is shown beside them, read only where the
    FEM control does not alternate there."""
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
        matches = {"cost": cost is not None and cost > PAPER_COST,
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
    text = (plain + text + " The paper's bulge/neck pattern is seen on its 5 layers only, "
            "where the signature cannot tell a smooth bump from an alternation: shown in the "
            "table, not scored. Flutter: a linearised growth rate above half the mass damping "
            f"we assume, {damping:g} 1/s (the paper states none).")
    return {"model": best["model"], "sure": sure, "margin": margin, "tied": tied,
            "none_reproduces": none_all, "fails": fails, "text": text}
