"""What the artefact study's cells say: which factor switches the bulge/neck pattern on and off,
the answer to the paper's question, and which reading of the paper's equations its own
observables point to. Everything here is computed from the cells' rows."""
import numpy as np

from ...metrics import ALTERNATION_CLEAR

PAPER_COST = 10.0      # the paper: a step costs more than 10 times msm's
SURE_MARGIN = 2        # observables by which the verdict must lead to be called clear
OFF_RATE = 0.5         # a factor whose change removes the pattern in this share of pairs


def alternating(row):
    """True where the layers alternate clearly, either sign (the artefact whatever its phase),
    None where the alternation is not defined or the run failed."""
    p = pattern(row)
    return None if p is None else p != "none"


def pattern(row):
    """'paper' (the paper's sign: ends and middle layer out, alternation_rel >= the clear
    level), 'reversed', 'none', or None where the alternation is not defined or the run
    failed."""
    a = row.get("alternation_rel")
    if row.get("failed") or a is None:
        return None
    return "paper" if a >= ALTERNATION_CLEAR else "reversed" if a <= -ALTERNATION_CLEAR \
        else "none"


# a contrast: the factor changed, its baseline level, the coordinates held equal, and which
# rows take part
CONTRASTS = (
    ("split", "mirrored five", ("nodes_per_side", "model", "bc", "load"), lambda r: True),
    ("nodes_per_side", 5, ("split", "model", "bc", "load"),
     lambda r: r["split"] == "mirrored five"),
    ("normal", "none", ("mesh", "reading", "bc", "load"),
     lambda r: r["family"] == "particle" and r["constant"] == "calibrated"),
    ("constant", "calibrated", ("mesh", "reading", "bc", "load"),
     lambda r: r["family"] == "particle" and r["normal"] == "none"),
    ("reading", "variational", ("mesh", "constant", "bc", "load"),
     lambda r: r["family"] == "particle" and r["normal"] == "none"),
    ("shear on msm", "none", ("mesh", "bc", "load"), lambda r: r["family"] == "msm"),
    ("load", "paper", ("mesh", "model", "bc"), lambda r: True),
)


def _level(row, factor):
    return row["reading"] if factor == "shear on msm" else row[factor]


def contrasts(cells):
    """One row per (factor, level against its baseline): the pairs of cells that differ in
    that factor alone, and how many the change switches the alternation (either sign) off
    (present at the baseline, absent at the level) or on."""
    out = []
    for factor, base, held, take in CONTRASTS:
        rows = [r for r in cells if take(r) and alternating(r) is not None]
        groups = {}
        for r in rows:
            groups.setdefault(tuple(r[k] for k in held), []).append(r)
        levels = sorted({_level(r, factor) for r in rows} - {base}, key=str)
        for level in levels:
            n = off = on = kept = 0
            for g in groups.values():
                b = [r for r in g if _level(r, factor) == base]
                v = [r for r in g if _level(r, factor) == level]
                for rb in b:
                    for rv in v:
                        n += 1
                        was, now = alternating(rb), alternating(rv)
                        off += was and not now
                        on += now and not was
                        kept += was and now
            if n:
                out.append({"factor": factor, "from": base, "to": level, "pairs": n,
                            "with_pattern_before": off + kept, "switched_off": off,
                            "switched_on": on})
    return out


def by_level(cells, key):
    """{level: (cells with the paper's pattern, with the reversed one, cells defined, median
    |alternation_rel|)} of one factor."""
    out = {}
    for r in cells:
        if pattern(r) is None:
            continue
        level = r[key]
        p, rev, n, mags = out.get(level, (0, 0, 0, []))
        out[level] = (p + (pattern(r) == "paper"), rev + (pattern(r) == "reversed"), n + 1,
                      mags + [abs(r["alternation_rel"])])
    return {k: (p, rev, n, float(np.median(m))) for k, (p, rev, n, m) in out.items()}


def _off_rate(rows, factor):
    """The share of the pairs that had the pattern where changing ``factor`` removed it."""
    mine = [c for c in rows if c["factor"] == factor]
    had = sum(c["with_pattern_before"] for c in mine)
    return (sum(c["switched_off"] for c in mine) / had if had else None), had


def _share(cells):
    """(alternating cells, cells with an alternation) of ``cells``."""
    known = [c for c in cells if alternating(c) is not None]
    return sum(alternating(c) for c in known), len(known)


def _rate(share):
    return share[0] / share[1] if share[1] else 0.0


def answer(cells):
    """The paper's question (section 5: the mirror symmetry of the tetrahedra, or the missing
    normal stress?) answered from the cells: a hypothesis holds when changing its factor alone
    removes the alternation (either sign) in most pairs that had it and the cells without the
    factor show it less than half as often. Also said: where the alternation appears, what
    refinement does, and whether the FEM control alternates."""
    con = contrasts(cells)
    paper_size = [c for c in cells if c["nodes_per_side"] == 5]
    five = _share([c for c in paper_size if c["split"] == "mirrored five"])
    other = _share([c for c in paper_size if c["split"] != "mirrored five"])
    splits = {k: _share([c for c in paper_size if c["split"] == k])
              for k in dict.fromkeys(c["split"] for c in paper_size)}
    mesh_off, mesh_had = _off_rate(con, "split")
    normal_off, normal_had = _off_rate(con, "normal")
    particle = [c for c in cells if c["family"] == "particle"]
    bare = _share([c for c in particle if c["normal"] == "none"])
    normal = _share([c for c in particle if c["normal"] != "none"])
    msm = _share([c for c in cells if c["model"] == "msm"])
    refined = {n: _share([c for c in cells if c["split"] == "mirrored five"
                          and c["nodes_per_side"] == n])
               for n in sorted({c["nodes_per_side"] for c in cells
                                if c["split"] == "mirrored five"})}
    fem = [c for c in cells if c["family"] == "fem" and alternating(c)]
    mirror = (mesh_off is not None and mesh_off >= OFF_RATE
              and _rate(five) > 2 * _rate(other))
    missing_normal = (normal_off is not None and normal_off >= OFF_RATE
                      and _rate(normal) < _rate(bare) / 2 and _rate(msm) < _rate(bare) / 2)
    vanishes = len(refined) > 1 and refined[max(refined)][0] == 0 and five[0] > 0
    cause = ("the mirror symmetry of the five split, not the missing normal stress"
             if mirror and not missing_normal else
             "the missing normal stress, not the mirror symmetry" if missing_normal and not mirror
             else "both the five split and the missing normal stress" if mirror else
             "neither the mirror symmetry nor the missing normal stress"
             + (": a mesh-scale discretisation error that refinement removes" if vanishes
                else ""))
    parts = [
        f"The layers alternate (|alternation| at least {ALTERNATION_CLEAR:g} of the mean "
        "lateral displacement, either sign) on every split of the paper's lattice: "
        + ", ".join(f"{k} {a} of {n}" for k, (a, n) in splits.items()) + " cells"
        + (f"; leaving the five split removes it in {_pct(mesh_off)} of the {mesh_had} pairs "
           "that had it" if mesh_had else "") + ".",
        f"With a normal-stress term {normal[0]} of {normal[1]} particle cells alternate, "
        f"without {bare[0]} of {bare[1]}"
        + (f" (a term removes it in {_pct(normal_off)} of the {normal_had} pairs that had it)"
           if normal_had else "")
        + f"; msm, whose forces are all normal (along edges), in {msm[0]} of {msm[1]}.",
        "Refining the five split: " + ", ".join(f"{n} nodes per side {a} of {k}"
                                                for n, (a, k) in refined.items()) + ".",
        (f"The FEM control alternates in {len(fem)} cells, all on "
         f"{', '.join(sorted({c['mesh'] for c in fem}))}"
         + (" (non-conforming)" if all(c.get("unmatched_faces") for c in fem) else "") + "."
         if fem else "The FEM control never alternates."),
        f"So the pattern comes from {cause}."]
    return {"text": " ".join(parts), "cause": cause, "mesh_off_rate": mesh_off,
            "normal_off_rate": normal_off, "five": list(five), "other_splits": list(other),
            "msm": list(msm), "refined": {str(n): list(v) for n, v in refined.items()}}


def _pct(x):
    return "n/a" if x is None else f"{100 * x:.0f} %"


def reading_table(cells, step_vs_msm, readings):
    """One row per reading (calibrated and literal): the paper's observables on the paper-size
    meshes and how many it matches; the pattern is read only on meshes where the FEM control
    does not alternate (elsewhere the mesh cannot tell a model's pattern from its own)."""
    # where the FEM control alternates the mesh itself makes a pattern: no model's is resolved
    unresolved = {(c["mesh"], c["bc"], c["load"]) for c in cells
                  if c["family"] == "fem" and alternating(c)}
    rows = []
    for model in readings:
        mine = [c for c in cells if c["model"] == model and c["paper_size"]]
        sliding = [c for c in mine if c["bc"] == "sliding" and c["load"] == "paper"
                   and pattern(c) is not None
                   and (c["mesh"], c["bc"], c["load"]) not in unresolved]
        shows = sum(pattern(c) == "paper" for c in sliding)
        clamped = {c["mesh"]: c for c in mine if c["bc"] == "clamped"}
        rates = [c["growth_rate_1_s"] for c in clamped.values()
                 if c.get("growth_rate_1_s") is not None]
        flutter = sum(bool(c.get("flutter")) for c in clamped.values())
        consistency = [c["disp_rel_l2"] for c in mine if c["bc"] == "sliding"
                       and c["load"] == "linear" and c.get("disp_rel_l2") is not None]
        finite = [c["disp_rel_l2"] for c in mine if c["bc"] == "clamped"
                  and c["load"] == "paper" and c.get("disp_rel_l2") is not None]
        cost = step_vs_msm.get(model)
        matches = {"pattern": shows > 0, "cost": cost is not None and cost > PAPER_COST,
                   "stable": bool(rates) and flutter == 0}
        rows.append({"model": model, "pattern": [shows, len(sliding)],
                     "pattern_median_rel": _median([c["alternation_rel"] for c in sliding]),
                     "step_vs_msm": cost, "flutter": [flutter, len(clamped)],
                     "growth_max_1_s": max(rates) if rates else None,
                     "sliding_disp_median": _median(consistency),
                     "paper_push_disp_median": _median(finite),
                     "matches": matches, "score": sum(matches.values())})
    return rows


def _median(v):
    v = [x for x in v if x is not None]
    return float(np.median(v)) if v else None


def reading_verdict(table):
    """The reading that matches most of the paper's observables, and how sure that is: the
    margin over the runner-up (clear from SURE_MARGIN observables, weak from one, none: a
    tie)."""
    ranked = sorted(table, key=lambda r: (-r["score"], r["sliding_disp_median"] or np.inf))
    best, second = ranked[0], ranked[1] if len(ranked) > 1 else None
    margin = best["score"] - (second["score"] if second else 0)
    tied = [r["model"] for r in ranked if r["score"] == best["score"]]
    sure = "clear" if margin >= SURE_MARGIN else "weak" if margin == 1 else "undecided"
    names = {"pattern": "the bulge/neck pattern on a paper-size mesh",
             "cost": f"a step over {PAPER_COST:g} times msm's",
             "stable": "a clamped RK4 run without flutter"}
    said = "; ".join(f"{k}: {'yes' if v else 'no'}" for k, v in
                     ((names[k], v) for k, v in best["matches"].items()))
    if sure == "undecided":
        text = (f"Undecided: {', '.join(tied)} each match {best['score']} of "
                f"{len(best['matches'])} of the paper's observables ({said} for {tied[0]}).")
    else:
        text = (f"{best['model']} matches {best['score']} of {len(best['matches'])} of the "
                f"paper's observables ({said}), {margin} more than the next "
                f"({second['model']}): a {sure} verdict, on reconstructed meshes.")
    return {"model": best["model"], "sure": sure, "margin": margin, "tied": tied, "text": text}
