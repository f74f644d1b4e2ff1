"""The artefact study's files: metrics.json (the cells, the contrasts, the answers and the rows
the gate reads), report.md/.html (the answers, the factor tables, the reading table, figures)
and cells.md/.html (every cell's alternation beside the reference's). Every sentence is
computed from the cells it is written with."""
from pathlib import Path

import numpy as np

from ... import catalogue, figures
from ...document import GLOSSARY, Document, fmt
from ...metrics import ALTERNATION_CLEAR
from ...report import environment, write_study
from ...runner import jsonable
from .analysis import answer, by_level, contrasts, pattern, reading_table, reading_verdict
from .study import LINEAR_SCALE, READINGS, YARDSTICK, short

GATED = catalogue.gated("alternation_rel", "disp_rel_l2")


def readings(models):
    """The shear readings, calibrated and literal, without extra terms, in the study's order."""
    return [m for m in models if m in {f"pbcm-{r}{x}" for r in READINGS
                                       for x in ("", "-literal")}]


def gate_rows(cells):
    return [{"mesh": c["mesh"], "bc": f"{c['bc']}/{c['load']}", "model": c["model"],
             "alternation_rel": c.get("alternation_rel"), "disp_rel_l2": c.get("disp_rel_l2")}
            for c in cells]


def analyse(data, models):
    table = reading_table(data["cells"], data["step_vs_msm"], readings(models))
    return {"contrasts": contrasts(data["cells"]), "answer": answer(
        data["cells"]), "readings": table, "verdict": reading_verdict(table)}


def write(out, study, s, data):
    found = analyse(data, list(s.models))
    doc = jsonable({"case": study.name, "study": True, "parameters": s.describe(),
                    "problem": s.problem(), "gated": GATED, "environment": environment(),
                    **data, **found, "gate_runs": gate_rows(data["cells"])})
    return write_study(out, doc, lambda folder: build(folder, study, s, doc))


def conclusion(doc):
    """The study's three lines: the cause, the reading, and what the study could not see; a
    quick run's are a preview that decides nothing."""
    lines = [f"**What causes the bulge/neck pattern.** {doc['answer']['text']}",
             f"**Which reading.** {doc['verdict']['text']}"]
    if doc["parameters"].get("quick"):
        return ["**Quick: not decided** (`pbcm run artefact` decides, on every mesh); what "
                "the quick cells show, as a preview:"] + lines
    return lines


def build(out, study, s, doc):
    out = Path(out)
    d = Document(f"pbcm report: {study.name}")
    d.opening(conclusion(doc))
    d.p("Every cell's numbers: [cells.md](cells.md). Regenerate with `pbcm run artefact`.")
    d.h(2, "What was run")
    d.ul([study.title + ".",
          f"Meshes: {', '.join(s.meshes)} (Delaunay-374: the lattice's Delaunay tetrahedra, "
          "joggled by seed, flat ones dropped, non-conforming; five/six mix: conforming, 10 "
          "cells in five and 54 in six).",
          f"Models: {len(s.models)}: each shear reading calibrated and literal (c = 1), each "
          "calibrated one with each normal-stress term (beside a literal shear the fit sets "
          "the normal constant to 0), msm, msm with the variational shear at c = 1 (with c "
          f"fitted it is 0 beside the springs) and {YARDSTICK} (the control: constant-strain "
          "FEM on the same tetrahedra).",
          f"Bases: {', '.join(s.bcs)}; loads: the paper's push and {LINEAR_SCALE:g} of it (the "
          "linear regime). The reference: " + "; ".join(
              f"{r['bc']}/{r['load']} error estimate {fmt(r['error_estimate'])}"
              for r in doc["references"]) + ".",
          f"The pattern: an alternation of at least {ALTERNATION_CLEAR:g} of the reference's "
          "mean lateral displacement with the paper's sign (ends and middle out); the reversed "
          "sign is counted apart."])
    d.h(2, "Which factor switches the pattern on or off")
    d.p("Pairs of cells that differ in one factor only (the rest held equal); a pair switches "
        "the alternation (either sign) off when the first cell alternates and the second does "
        "not.")
    d.table(["factor", "from", "to", "pairs", "alternating before", "switched off",
             "switched on"],
            [[c["factor"], c["from"], c["to"], c["pairs"], c["with_pattern_before"],
              c["switched_off"], c["switched_on"]] for c in doc["contrasts"]])
    for key, title in (("split", "mesh split (5 nodes per side)"), ("normal", "normal stress"),
                       ("constant", "shear constant"), ("family", "model family"),
                       ("load", "load"), ("bc", "base")):
        cells = [c for c in doc["cells"] if key != "split" or c["nodes_per_side"] == 5]
        levels = by_level(cells, key)
        d.h(3, f"By {title}")
        d.table([key, "paper's pattern", "reversed", "median |alternation rel|"],
                [[k, f"{p} of {n}", f"{r} of {n}", fmt(m)] for k, (p, r, n, m) in
                 levels.items()])
    d.h(2, "Which reading the paper used")
    d.p(doc["verdict"]["text"])
    d.table(["model", "pattern on paper-size meshes", "median alternation", "step / msm",
             "flutter (clamped)", "largest growth [1/s]",
             "sliding disp. error, linear (median)", "clamped disp. error, paper's push "
             "(median)", "observables matched"],
            [[r["model"], f"{r['pattern'][0]} of {r['pattern'][1]}",
              fmt(r["pattern_median_rel"]), fmt(r["step_vs_msm"]),
              f"{r['flutter'][0]} of {r['flutter'][1]}", fmt(r["growth_max_1_s"]),
              fmt(r["sliding_disp_median"]), fmt(r["paper_push_disp_median"]),
              f"{r['score']} of {len(r['matches'])}"] for r in doc["readings"]])
    d.p(f"Paper-size meshes: 125 nodes, 374 tetrahedra; the pattern is counted on those where "
        "the FEM control does not alternate (the others cannot tell a model's pattern from the "
        "mesh's). Step / msm: the bench's RK4 step on "
        f"the 125-node five cube (a literal reading costs what its calibrated one does). "
        f"Flutter: the linearised growth rate of the clamped cube above half the mass damping "
        f"({s.damping:g} 1/s). Sliding disp. error: the displacement L2 error on the "
        f"sliding cube (a patch test) at {LINEAR_SCALE:g} of the push, median over the "
        "paper-size meshes (not the convergence study's consistency limit); clamped disp. "
        "error: on the clamped cube at the push, against the neo-Hookean reference (a total "
        "error, the mesh's own included).")
    _figures(d, out, s, doc)
    d.p(f"Environment: {doc['environment']}.")
    cells_document(doc, s).write(out, stem="cells")
    return d


def _figures(d, out, s, doc):
    meshes, models = list(s.meshes), list(s.models)
    for bc in s.bcs:
        for load in ("paper",):
            grid = {(c["model"], c["mesh"]): c.get("alternation_rel") for c in doc["cells"]
                    if c["bc"] == bc and c["load"] == load}
            if all(v is None for v in grid.values()):
                continue
            name = f"alternation_{bc}.png"
            figures.heatmap(out / name, [short(m) for m in models], meshes,
                            [[grid.get((m, x)) for x in meshes] for m in models],
                            f"alternation rel, {bc} base, the paper's push (grey: n/a)",
                            "alternation rel (+: the paper's sign)", 5 * ALTERNATION_CLEAR)
            d.img(name, f"Alternation of every model on every mesh, {bc} base")
    for mesh in ("five", "mixed374-0", "delaunay374-7"):
        rows = [c for c in doc["cells"] if c["mesh"] == mesh and c["bc"] == "sliding"
                and c["load"] == "paper" and c.get("bulge_profile_mm")]
        if not rows:
            continue
        deviating = {c["model"] for c in rows
                     if pattern(c) in ("paper", "reversed")}
        name = f"profiles_{mesh}.png"
        layers = list(range(0, 33, 32 // (len(rows[0]["bulge_profile_mm"]) - 1)))
        figures.profiles(out / name, layers,
                         [(short(c["model"]), c["bulge_profile_mm"]) for c in rows],
                         rows[0]["bulge_profile_fem_mm"], f"Layer profiles on {mesh}, sliding "
                         "base, the paper's push (colour: an alternation of 0.01 or more)",
                         highlight={short(m) for m in deviating},
                         fem_label="reference (neo-Hookean P2)")
        d.img(name, f"Layer profiles on {mesh}")


def cells_document(doc, s):
    """Every cell: per mesh, one row per model, the alternation [mm] and relative per base and
    load beside the reference's own alternating component."""
    c = Document("pbcm artefact study: every cell")
    c.p("Alternation in mm (relative in brackets) per base and load, beside the reference's "
        "mean lateral displacement in mm (the scale of the relative one; the reference's own "
        "alternation is zero by the metric's definition, and the FEM control's is its row). "
        f"Definitions: [glossary](../{GLOSSARY}).")
    combos = [(bc, load) for bc in s.bcs for load in s.loads]
    for mesh in s.meshes:
        rows = {}
        for x in doc["cells"]:
            if x["mesh"] == mesh:
                rows.setdefault(x["model"], {})[(x["bc"], x["load"])] = x
        if not rows:
            continue
        first = next(iter(rows.values()))
        c.h(2, f"{mesh} ({next(iter(first.values()))['tets']} tetrahedra)")
        c.table(["model"] + [f"{bc}/{load}" for bc, load in combos],
                [["reference, mean lateral [mm]"] + [_scale(first.get(k)) for k in combos]]
                + [[short(m)] + [_cell(r.get(k)) for k in combos] for m, r in rows.items()])
    return c


def _scale(x):
    if not x or not x.get("bulge_profile_fem_mm"):
        return "n/a"
    return fmt(float(np.mean(np.abs(x["bulge_profile_fem_mm"]))))


def _cell(x):
    if x is None:
        return "n/a"
    if x.get("failed"):
        return "failed"
    if x.get("alternation_mm") is None:
        return "n/a"
    return f"{fmt(x['alternation_mm'])} ({fmt(x['alternation_rel'])})"
