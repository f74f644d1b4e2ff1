"""What the artefact study's cells say: which factor switches the bulge/neck pattern on and off,
the answer to the paper's question, and which reading of the paper's equations its own
observables point to. Everything here is computed from the cells' rows."""
import numpy as np

from ...metrics import ALTERNATION_CLEAR

PAPER_COST = 10.0      # the paper: a step costs more than 10 times msm's
SURE_MARGIN = 2        # observables by which the verdict must lead to be called clear
OFF_RATE = 0.5         # a factor whose change removes the pattern in this share of pairs


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
    that factor alone, and how many the change switches the paper's pattern off (present at
    the baseline, absent at the level) or on."""
    out = []
    for factor, base, held, take in CONTRASTS:
        rows = [r for r in cells if take(r) and pattern(r) is not None]
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
                        was, now = pattern(rb) == "paper", pattern(rv) == "paper"
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


def answer(cells):
    """The paper's question (section 5: the mirror symmetry of the tetrahedra, or the missing
    normal stress?) answered from the cells, with the counts that decide it."""
    con = contrasts(cells)
    splits = by_level([c for c in cells if c["nodes_per_side"] == 5], "split")
    mesh_off, mesh_had = _off_rate(con, "split")
    normal_off, normal_had = _off_rate(con, "normal")
    normal_on = sum(c["switched_on"] for c in con if c["factor"] == "normal")
    msm_five = [c for c in cells if c["model"] == "msm" and c["split"] == "mirrored five"
                and pattern(c) is not None]
    msm_shows = sum(pattern(c) == "paper" for c in msm_five)
    var = [c for c in cells if c["family"] == "particle" and c["reading"] == "variational"
           and c["normal"] == "none" and pattern(c) is not None]
    five = splits.get("mirrored five", (0, 0, 0, 0.0))
    rest = [v for k, v in splits.items() if k != "mirrored five"]
    rest_p, rest_n = sum(v[0] for v in rest), sum(v[2] for v in rest)
    mirror = mesh_off is not None and mesh_off >= OFF_RATE and five[0] > 0
    normal = (normal_off is not None and normal_off >= OFF_RATE and msm_shows == 0)
    cause = ("the mirror symmetry of the five split, not the missing normal stress"
             if mirror and not normal else
             "the missing normal stress, not the mirror symmetry" if normal and not mirror else
             "both the five split and the missing normal stress" if mirror and normal else
             "neither factor alone (no change of one factor removes it in most cells)")
    parts = [
        f"The bulge/neck pattern with the paper's sign (alternation of at least "
        f"{ALTERNATION_CLEAR:g} of the mean lateral displacement) appears in {five[0]} of "
        f"{five[2]} cells on the mirrored five split at 5 nodes per side and in {rest_p} of "
        f"{rest_n} on every other split of that size"
        + (f"; leaving the five split removes it in {_pct(mesh_off)} of the {mesh_had} pairs "
           "that had it" if mesh_had else "") + ".",
        (f"Adding a normal-stress term removes it in {_pct(normal_off)} of the {normal_had} "
         f"pairs that had it and brings it in {normal_on}." if normal_had else
         "No calibrated reading shows it, so a normal-stress term has nothing to remove; "
         f"adding one brings it in {normal_on} of "
         f"{sum(c['pairs'] for c in con if c['factor'] == 'normal')} pairs."),
        f"msm, whose forces are all along edges (normal forces only), shows it in {msm_shows} "
        f"of its {len(msm_five)} cells on the five split; the variational reading, which has "
        f"no normal stress, in {sum(pattern(c) == 'paper' for c in var)} of its {len(var)} "
        "cells.",
        f"So the pattern comes from {cause}."]
    return {"text": " ".join(parts), "cause": cause, "mesh_off_rate": mesh_off,
            "normal_off_rate": normal_off, "msm_five": [msm_shows, len(msm_five)]}


def _pct(x):
    return "n/a" if x is None else f"{100 * x:.0f} %"


def reading_table(cells, step_vs_msm, readings):
    """One row per reading (calibrated and literal): the paper's observables on the paper-size
    meshes and how many it matches."""
    rows = []
    for model in readings:
        mine = [c for c in cells if c["model"] == model and c["paper_size"]]
        sliding = [c for c in mine if c["bc"] == "sliding" and c["load"] == "paper"
                   and pattern(c) is not None]
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
                     "consistency_median": _median(consistency),
                     "finite_load_median": _median(finite),
                     "matches": matches, "score": sum(matches.values())})
    return rows


def _median(v):
    v = [x for x in v if x is not None]
    return float(np.median(v)) if v else None


def reading_verdict(table):
    """The reading that matches most of the paper's observables, and how sure that is: the
    margin over the runner-up (clear from SURE_MARGIN observables, weak from one, none: a
    tie)."""
    ranked = sorted(table, key=lambda r: (-r["score"], r["consistency_median"] or np.inf))
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
