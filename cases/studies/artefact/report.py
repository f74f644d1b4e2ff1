"""The artefact study's files: metrics.json (the cells, the answers and the rows
the gate reads), report.md/.html (the answers per hypothesis, the reading table, figures)
and cells.md/.html (every cell's signature beside the reference's scale). Every sentence is
computed from the cells it is written with."""
from pathlib import Path

import numpy as np

from ... import catalogue, figures
from ...document import GLOSSARY, Document, fmt, rel
from ...metrics import ALTERNATION_CLEAR
from ...report import environment, write_study
from ...runner import jsonable
from .analysis import RATIO, alternating, answer, reading_table, reading_verdict
from .study import (DECISIVE, FINEST_NORMAL_READING, LINEAR_SCALE, READINGS, SPLITS,
                    YARDSTICK, short)

GATED = catalogue.gated("alternation_rel", "disp_rel_l2")


def readings(models):
    """The shear readings, calibrated and literal, without extra terms, in the study's order."""
    return [m for m in models if m in {f"pbcm-{r}{x}" for r in READINGS
                                       for x in ("", "-literal")}]


def gate_rows(cells):
    return [{"mesh": c["mesh"], "bc": f"{c['bc']}/{c['load']}", "model": c["model"],
             "alternation_rel": c.get("alternation_rel"), "disp_rel_l2": c.get("disp_rel_l2")}
            for c in cells]


def analyse(data, models, damping):
    table = reading_table(data["cells"], data["step_vs_msm"], readings(models))
    return {"answer": answer(data["cells"]), "readings": table,
            "verdict": reading_verdict(table, damping)}


def write(out, study, s, data):
    found = analyse(data, list(s.models), s.damping)
    doc = jsonable({"case": study.name, "study": True, "parameters": s.describe(),
                    "problem": s.problem(), "gated": GATED, "environment": environment(),
                    **data, **found, "gate_runs": gate_rows(data["cells"])})
    return write_study(out, doc, lambda folder: build(folder, study, s, doc))


def conclusion(doc):
    """The study's two lines: the cause and the reading; a quick run's are a preview that
    decides nothing."""
    lines = [f"**What causes the bulge/neck pattern.** {doc['answer']['text']}",
             f"**Which reading.** {doc['verdict']['text']}"]
    if doc["parameters"].get("quick"):
        return ["**Quick: not decided** (`pbcm run artefact` decides, on meshes of 9 and 17 "
                "nodes per side); what the quick cells show, as a preview:"] + lines
    return lines


def _sig(x):
    return "n/a" if x is None else fmt(x)


def build(out, study, s, doc):
    out = Path(out)
    d = Document(f"pbcm report: {study.name}")
    d.opening(conclusion(doc))
    d.p("Every cell's numbers: [cells.md](cells.md). Regenerate with `pbcm run artefact`.")
    d.h(2, "What was run")
    sizes = sorted({spec[1] for spec in s.meshes.values()})
    d.ul([study.title + ".",
          f"Meshes: {', '.join(s.meshes)}: each split of the paper's lattice ("
          + ", ".join(SPLITS[k] for k in dict.fromkeys(spec[0] for spec in s.meshes.values()))
          + f") at {', '.join(map(str, sizes))} nodes per side; the unmirrored five split "
          "splits every cell alike, so its faces' diagonals cross: it is not conforming and is "
          "reported apart.",
          f"Models: {len(s.models)}: each shear reading calibrated and literal (c = 1), each "
          "calibrated one with each normal-stress term (beside a literal shear the fit sets "
          "the normal constant to 0), msm, msm with the variational shear at c = 1 (with c "
          f"fitted it is 0 beside the springs) and {YARDSTICK} (the control: constant-strain "
          "FEM on the same tetrahedra). On the finest meshes each normal-stress term beside "
          f"the {FINEST_NORMAL_READING} reading only, and on the finest bcc the calibrated "
          "readings and the control only (the cost of 9009 nodes).",
          f"Bases: {', '.join(s.bcs)}; loads: the paper's push, and {LINEAR_SCALE:g} of it (the "
          "linear regime: a check, and the patch test hypothesis (c) reads) below the finest "
          "size. The reference: " + "; ".join(
              f"{r['bc']}/{r['load']} error estimate {rel(r['error_estimate'])}"
              for r in doc["references"]) + ".",
          f"The signature: the period-2 component of the layer profile beyond the continuum's "
          "shape and the highest-degree polynomial the free layers allow (0 on the continuum "
          "and on smooth barrels, the amplitude of a pure (-1)^k pattern); clear from "
          f"{ALTERNATION_CLEAR:g} of the reference's mean lateral displacement, + the paper's "
          f"sign. It decides from {DECISIVE} layers; on 5 layers (the paper's own view) it "
          "cannot tell a smooth bump from an alternation and is shown, never counted."])
    hyp = doc["answer"].get("hypotheses") or {}
    if hyp:
        m = hyp["mirror"]
        d.h(2, "(a) Mirror symmetry")
        d.p("Per size and base of the mirrored five split (the unit): the floor (FEM P1's "
            "largest signature on the conforming splits without the mirror there), FEM P1's "
            "own signature on the mirrored split, and the models by class: 'own' resolved "
            f"({RATIO:g} times the floor), {RATIO:g} times every conforming split's and FEM P1's, "
            "with the paper's sign; 'shared' the same but within that factor of FEM P1's (the "
            "mesh's own period-2 error); 'reversed' the opposite sign. A model that gives the "
            "same signatures as another (a term that changes nothing) is counted once.")
        d.table(["nodes per side", "bc", "floor", "FEM P1, mirrored", "own", "shared with FEM "
                 "P1", "reversed", "none", "failed", "median mirrored / unmirrored"],
                [[u["n"], u["bc"], _sig(u["floor"]), _sig(u["fem_five"]),
                  ", ".join(u["classes"]["own"]) or "none", len(u["classes"]["shared"]),
                  ", ".join(u["classes"]["reversed"]) or "none", len(u["classes"]["none"]),
                  ", ".join(u["failed"]) or "none", _sig(u["ratio_median"])]
                 for u in m["units"]])
        d.p("Every model's signature on the mirrored split beside the conforming splits "
            "without the mirror and the unmirrored five split (not conforming, apart):")
        d.table(["model", "bc", "nodes per side", "mirrored five", "six (Kuhn)", "bcc",
                 "unmirrored five (non-conforming)", "reads"],
                [[short(r["model"]), r["bc"], r["n"], _sig(r["five"]),
                  _sig(r["controls"].get(SPLITS["six"])), _sig(r["controls"].get(SPLITS["bcc"])),
                  _sig(r["unmirrored"]), r["kind"]] for r in m["rows"]])
        ns = hyp["normal_stress"]
        d.h(2, "(b) Missing normal stress")
        d.p("Pairs of cells on the same mirrored mesh and base, a calibrated reading whose own "
            "signature exists without a normal-stress term, and the same with one term "
            "(from 9 nodes per side, the paper's push)"
            + ("." if ns["decided"] else ": none was run, so (b) is not decided."))
        if ns["decided"]:
            d.table(["term", "pairs", f"reduced {RATIO:g}-fold or more",
                     "median |with| / |without|"],
                    [[t, v["pairs"], v["removed"], _sig(v["ratio_median"])]
                     for t, v in ns["terms"].items()])
        cs = hyp["consistency"]
        d.h(2, "(c) The model's consistency")
        d.p("Per conforming mesh: the rank correlation over the approximations between the "
            "signature at the paper's push and the patch-test error (the displacement error "
            f"at {LINEAR_SCALE:g} of the push), both on the sliding base.")
        d.table(["mesh", "models", "rank correlation", "clear signatures"],
                [[r["mesh"], r["models"], _sig(r["rho"]), r["clear"]] for r in cs["rows"]])
    d.h(2, "Which reading the paper used")
    d.p(doc["verdict"]["text"])
    d.table(["model", "pattern, paper's 5-layer view (not scored)", "signature", "step / msm",
             "flutter (clamped)", "largest growth [1/s]",
             "sliding disp. error, linear", "clamped disp. error, paper's push",
             "observables matched"],
            [[r["model"], f"{r['pattern'][0]} of {r['pattern'][1]}",
              fmt(r["pattern_median_rel"]), fmt(r["step_vs_msm"]),
              f"{r['flutter'][0]} of {r['flutter'][1]}", fmt(r["growth_max_1_s"]),
              fmt(r["sliding_disp_median"]), fmt(r["paper_push_disp_median"]),
              f"{r['score']} of {len(r['matches'])}"] for r in doc["readings"]])
    d.p("On the paper's lattice (mirrored five, 5 nodes per side). Step / msm: the bench's RK4 "
        "step on the 125-node five cube (a literal reading costs what its calibrated one "
        "does). Flutter: the linearised growth rate of the clamped cube above half the mass "
        f"damping we assume ({s.damping:g} 1/s; the paper states none). Sliding disp. error: "
        f"the displacement L2 error on the sliding cube (a patch test) at {LINEAR_SCALE:g} of "
        "the push; clamped disp. error: at the push against the neo-Hookean reference (a total "
        "error, the mesh's own included).")
    _figures(d, out, s, doc)
    d.p(f"Environment: {doc['environment']}.")
    cells_document(doc, s).write(out, stem="cells")
    return d


def _figures(d, out, s, doc):
    cells = doc["cells"]
    shown = readings(list(s.models)) + [YARDSTICK]
    for name, spec in s.meshes.items():
        if spec[0] != "five":
            continue
        rows = [c for c in cells if c["mesh"] == name and c["bc"] == "clamped"
                and c["load"] == "paper" and c.get("bulge_profile_mm") and c["model"] in shown]
        if not rows:
            continue
        n = len(rows[0]["bulge_profile_mm"])
        layers = list(np.linspace(0.0, 32.0, n))
        series = [(f"{short(c['model'])} (period-2 {_sig(c.get('alternation_rel'))})",
                   c["bulge_profile_mm"]) for c in rows]
        fig = f"paper_profiles_{name}.png"
        figures.profiles(out / fig, layers, series, rows[0]["bulge_profile_fem_mm"],
                         f"The paper's setting at {spec[1]} nodes per side: mirrored five, "
                         "clamped base, the paper's push", highlight={
                             lab for (lab, _), c in zip(series, rows) if alternating(c)
                             or c["model"] == YARDSTICK},
                         fem_label="continuum (neo-Hookean P2)")
        d.img(fig, f"Layer profiles, mirrored five at {spec[1]} nodes per side, clamped; the "
              "legend gives each model's period-2 component (relative; n/a where the free "
              "layers cannot separate it), coloured where it is clear and for FEM P1")
    meshes, models = list(s.meshes), list(s.models)
    for bc in s.bcs:
        grid = {(c["model"], c["mesh"]): c.get("alternation_rel") for c in cells
                if c["bc"] == bc and c["load"] == "paper"}
        if all(v is None for v in grid.values()):
            continue
        fig = f"alternation_{bc}.png"
        figures.heatmap(out / fig, [short(m) for m in models], meshes,
                        [[grid.get((m, x)) for x in meshes] for m in models],
                        f"period-2 signature, {bc} base, the paper's push (grey: n/a or not "
                        "run)", "signature rel (+: the paper's sign)", 5 * ALTERNATION_CLEAR)
        d.img(fig, f"The period-2 signature of every model on every mesh, {bc} base")


def cells_document(doc, s):
    """Every cell: per mesh, one row per model, the alternation [mm] and relative per base and
    load beside the reference's own alternating component."""
    c = Document("pbcm artefact study: every cell")
    c.p("Period-2 signature in mm (relative in brackets) per base and load, beside the "
        "reference's mean lateral displacement in mm (the scale of the relative one; the "
        "reference's own signature is zero by the metric's definition, and the FEM control's "
        "is its row; 'not run': the load is not run on the finest meshes). "
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
        return "not run"
    if x.get("failed"):
        return "failed"
    if x.get("alternation_mm") is None:
        return "n/a"
    return f"{fmt(x['alternation_mm'])} ({fmt(x['alternation_rel'])})"
