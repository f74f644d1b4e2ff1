"""The artefact study's files: metrics.json (the answers and the rows the gate reads),
cells.json (the cells) and lines.json (each cell's side-line signatures), report.md/.html (the answers, the metric's check, the decomposition per
hypothesis, the reading table, figures) and cells.md/.html (every cell's signature beside the
reference's scale). Every sentence is computed from the cells it is written with."""
from pathlib import Path

import numpy as np

from model.paper_mesh import PAPER_TETS     # the paper's own cube, as it reports it
from model.static import SHORTEST_STEP
from ...measuring import catalogue
from ...measuring.metrics import EXACT_DEGREE, SMOOTH_DECAYS, SMOOTH_WIDTHS
from ...reporting import figures  # noqa: F401  (selects matplotlib's file backend before pyplot)
from ...reporting.document import GLOSSARY, Document, fmt, rel
from ...reporting.report import environment, write_study
from ...running.runner import jsonable
from ...library import paper_cube as P
from .analysis import (CLEAR, COARSE, DECAYS, SHARP_DECAYS, DECIDING_LEAK, END_LAYERS, GROWS, LEAK_SHARE,
                       MIN_RESOLVED, NEAR, PAPER_BULGES_MM, PAPER_COST, PAPER_NECKS_MM, RATIO,
                       SAME, TRACKS, WIDTHS, _compress, answer, classes, failure, how_sure,
                       distinct_pairs, paper_figure, paper_figure_text,
                       reading_table, reading_verdict, signature_own, times, counted,
                       threshold_moves)
from .study import (DECISIVE, FIXED_NORMAL_C, HELD_SUFFIX, LINEAR_SCALE, LITERAL_NORMAL,
                    READINGS, SPLITS, SPLITS_TRIED, YARDSTICK, _free_layers, lines_apart,
                    models_on, short)

GATED = catalogue.gated("alternation_rel", "disp_rel_l2")


def readings(models):
    """The shear readings, calibrated and literal, without extra terms, in the study's order."""
    return [m for m in models if m in {f"pbcm-{r}{x}" for r in READINGS
                                       for x in ("", "-literal")}]


def with_normal(models):
    """The readings with a normal-stress term (not in the paper's equations)."""
    return [m for m in models if short(m) != m and short(m).startswith("pbcm-")]


def gate_rows(cells):
    return [{"mesh": c["mesh"], "bc": f"{c['bc']}/{c['load']}", "model": c["model"],
             "alternation_rel": c.get("alternation_rel"), "disp_rel_l2": c.get("disp_rel_l2")}
            for c in cells]


def analyse(data, models, damping):
    table = reading_table(data["cells"], data["step_vs_msm"], readings(models), damping,
                          with_normal(models), data.get("step_vs_msm_range"),
                          data.get("step_vs_msm_sizes"))
    found = {"answer": answer(data["cells"], models, _estimates(data)), "readings": table,
             "verdict": reading_verdict(table, damping, data.get("bench_spread"),
                                        paper_figure(data["cells"], readings(models)),
                                        data.get("sim_vs_msm_sizes"))}
    found["how_sure"] = how_sure(found["answer"], found["verdict"])
    found["thresholds"] = threshold_moves(data["cells"], models, _estimates(data))
    return found


def write(out, study, s, data):
    found = analyse(data, list(s.models), s.damping)
    doc = jsonable({"case": study.name, "study": True, "parameters": s.describe(),
                    "problem": s.problem(), "gated": GATED, "environment": environment(),
                    "names": {m: short(m) for m in s.models},
                    **data, **found, "gate_runs": gate_rows(data["cells"])})
    cells, lines = lines_apart(doc["cells"])
    return write_study(out, {**doc, "cells": cells, "lines": lines},
                       lambda folder: build(folder, study, s, doc), apart=study.record_files)


def conclusion(doc):
    """The study's opening: the cause in plain sentences and the reading in one (the numbers
    that decide them follow in a table and in 'The answer in full'); a quick run's is a
    preview that decides nothing."""
    if doc["parameters"].get("quick"):     # the cells below show what it measured
        return ["**Quick: not decided** (`pbcm run artefact` decides, on meshes of 9 and 17 "
                "nodes per side): the cells and tables below are a preview of its few meshes "
                "and decide nothing."]
    short = " ".join(doc["answer"].get("short") or [])
    return ([f"**What causes the bulge/neck pattern.** {short} The table below gives the "
             "numbers that decide each answer; 'The answer in full' states them with their "
             "uncertainty."] if short else []) + [
            f"**Which reading.** {reading_line(doc['verdict'])}",
            "**How sure.** Each configuration is one mesh per split (n = 1); every u holds the "
            "metric's leaks and the solver's tolerance, not the sensitivity to the fitted "
            "constants nor a spread over meshes, so the answers are provisional on those "
            "(in full below)" + _moved(doc.get("thresholds") or []) + "."]


def _moved(moves):
    """', and on the thresholds: the clear level at 0.005 turns (size) ...': the questions
    whose short answer a threshold tried changes, in the opening."""
    said = [f"{m['word']} at {m['value']:g} (ours {m['ours']:g}) changes "
            + ", ".join("size" if q.startswith("Large") else q.split(" ")[0]
                        for q, _ in m["changed"])
            for m in moves if m["changed"]]
    return ("; they are provisional on this study's thresholds too: " + "; ".join(said)
            + " ('How the answers move with the thresholds')") if said else ""


def reading_line(v):
    """The reading verdict in two sentences: decided or not and why, then plainly what each
    reading's observables measured."""
    head = (f"{v['model']}, {v['sure']}" if v.get("decided") else "Not decided") + (
        f" ({v['why']})" if v.get("why") else "")
    bits = []
    span = v.get("cost_span", {})
    if v.get("cost_miss"):
        measured = [f"{m} {span[m]}" for m in v["cost_miss"] if m in span]
        bits.append(f"{', '.join(v['cost_miss'])} miss the paper's cost (a step over 10 times "
                    "msm's" + ("; measured, a step over msm's on the five split of the "
                               "paper's lattice, median [range over the rounds]: "
                               f"{', '.join(measured)}" if measured else "")
                    + ")")
    if v.get("cost_open"):
        bits.append(f"the cost is not decided for {', '.join(v['cost_open'])}")
    if v.get("unstable"):
        bits.append(f"{', '.join(v['unstable'])} grow beyond the damping we assume")
    if v.get("stable"):
        bits.append(f"{', '.join(v['stable'])} stable (rate 0) on every mesh")
    if v.get("stability_depends"):
        rate = v.get("growth_max", {})
        bits.append("stability (the clamped base, on the conforming splits of the paper's "
                    "lattice) depends on the mesh or the damping for "
                    + ", ".join(m + (f" (largest growth rate {fmt(rate[m], 3)} 1/s)"
                                     if rate.get(m) is not None else "")
                                for m in v["stability_depends"]))
    none = (" No reading reproduces every observable the paper reports." if
            v.get("none_reproduces") else "")
    return (head + "." + (" Plainly: " + "; ".join(bits) + "." if bits else "") + none
            + " The full verdict is in 'Which reading the paper used'.")


def _sig(x):
    return "n/a" if x is None else x if isinstance(x, str) else rel(x)


def _pm(x, u):
    """'x +- u' of a relative value and its uncertainty."""
    if x is None:
        return "n/a"
    return _sig(x) + ("" if u is None else f" +- {fmt(u, 2)}")


def _unit(u):
    return f"{u['n']} {u['bc']}"


def _estimates(doc):
    return {r["bc"] + "/" + r["load"]: r["error_estimate"] for r in doc["references"]}


def _lateral(x, est):
    """A lateral displacement error, 'not resolved' where it is below the reference's own
    error estimate ``est``."""
    if x is None:
        return "n/a"
    if est is not None and abs(x) < est:
        return f"{fmt(x, 2)} (not resolved: below {fmt(est, 3)})"
    return fmt(x, 2)


CLEAR_WORDS = {"above": "clear", "below": "below", "at": "not decided"}


def _clear(r, decides=True):
    """The clear call of a row with each normalisation's where they differ; on a
    configuration that does not decide (the paper's 5-layer view), the level it reaches
    alone, deciding nothing."""
    if r.get("clear") is None:
        return "n/a"
    if not decides:
        return {"above": f"above {CLEAR:g}", "below": f"below {CLEAR:g}",
                "at": f"near {CLEAR:g}"}[r["clear"]] + " (decides nothing here)"
    by = r.get("clear_by") or {}
    word = CLEAR_WORDS[r["clear"]]
    if r["clear"] == "at":
        word += " (" + ", ".join(f"{k}: {CLEAR_WORDS[v]}" for k, v in by.items()) + ")"
    return word


def build(out, study, s, doc):
    out = Path(out)
    d = Document(f"pbcm report: {study.name}")
    d.opening(conclusion(doc))
    if not doc["parameters"].get("quick") and doc["answer"].get("short_rows"):
        d.table(["question", "answer", "the numbers that decide it"],
                doc["answer"]["short_rows"])
        d.h(2, "The answer in full")
        d.ul(["**What causes the bulge/neck pattern.** " + v if i == 0 else v
              for i, v in enumerate(doc["answer"].get("verdicts") or [])]
             + [f"**The evidence.** {doc['answer']['text']}", doc["how_sure"]])
        _thresholds(d, doc.get("thresholds") or [])
    d.p("Every cell's numbers: [cells.md](cells.md). The report is drawn again from the stored "
        "cells with `pbcm run artefact --rewrite`; without `--rewrite` every cell is "
        "computed again.")
    _what_was_run(d, s, doc)
    hyp = doc["answer"].get("hypotheses") or {}
    if hyp:
        _metric_check(d, doc)
    if doc["parameters"].get("quick"):
        # a class read on these few meshes (one control, no 17-node size) can contradict the
        # full run's: a preview shows what it measured and states no class or verdict
        d.p("Quick: the hypotheses' classes, the linear-load check and the reading's table "
            "are drawn by `pbcm run artefact` only; on these few meshes they could contradict "
            "it. The figures and cells.md show what was measured.")
    else:
        if hyp:
            _mirror(d, doc)
            _normal(d, hyp["normal_stress"])
            _consistency(d, hyp["consistency"], hyp["mirror"]["units"])
        _reading(d, s, doc)
    _figures(d, out, s, doc)
    d.p(f"Environment: {doc['environment']}.")
    cells_document(doc, s).write(out, stem="cells")
    return d


def _thresholds(d, moves):
    """How the short answers move with each threshold this study fixed."""
    if not moves:
        return
    d.h(3, "How the answers move with the thresholds")
    d.p("The clear level, the dominance factor and the tracking correlation are this study's "
        "conventions, not the paper's. Each is tried at a value either side of ours, the "
        "rest held; a question whose answer changes is provisional on that threshold.")
    d.table(["threshold (ours)", "tried", "answers that change"],
            [[f"{m['word']} ({m['ours']:g})", f"{m['value']:g}",
              "; ".join(f"{q} {a}" for q, a in m["changed"]) or "none"] for m in moves])


def recorded_design(s, doc):
    """Whether the record holds every (mesh, model) the design runs, and which it lacks."""
    have = {(c["mesh"], c["model"]) for c in doc["cells"]}
    lacking = {}
    for mesh, spec in s.meshes.items():
        for m in models_on(spec, s.models):
            if (mesh, m) not in have:
                lacking.setdefault(mesh, []).append(short(m))
    if not lacking:
        return ("Every model runs on every mesh; a static solve that fails is a failed cell, "
                "with its cause.")
    n = sum(len(v) for v in lacking.values())
    return (f"The design runs every model on every mesh, but this record lacks {n} (mesh, "
            "model) pairs of it (each a hole in cells.md; a part whose control is missing "
            "is 'not decided', never dropped): " + "; ".join(
                f"{mesh}: {len(v)} ({', '.join(v[:3])}{', ...' if len(v) > 3 else ''})"
                for mesh, v in lacking.items()) + " (`pbcm run artefact` computes them); a "
            "static solve that fails is a failed cell, with its cause.")


def _what_was_run(d, s, doc):
    d.h(2, "What was run")
    sizes = sorted({spec[1] for spec in s.meshes.values()})
    five = next((c for c in doc["cells"] if c["mesh"] == "five"), None)
    lit = [r for r in doc["readings"] if r["in_paper"] and r["model"].endswith("-literal")]
    asym = doc["answer"].get("asymmetry") or {}
    d.ul([
        f"Meshes: {', '.join(s.meshes)}: each split of the paper's lattice ("
        + ", ".join(SPLITS[k] for k in dict.fromkeys(spec[0] for spec in s.meshes.values()))
        + f") at {', '.join(map(str, sizes))} nodes per side. The unmirrored five split "
        "splits every cell alike, so its faces' diagonals cross: it is not conforming and is "
        "shown apart, never a control (a split of a cube into five tetrahedra conforms only "
        "where each cell is the mirror image of its neighbours, so no conforming unmirrored "
        "five split exists; the conforming splits without the mirror are six and bcc)."
        + (f" The paper reports {PAPER_TETS} tetrahedra on its 5-node cube; the mirrored five "
           f"split of the same lattice has {five['tets']}: the paper's own mesh is not among "
           "these meshes." if five else ""),
        f"Models: {len(s.models)}: each shear reading with the paper's constant (c = 1, "
        "'literal') and with c fitted by the patch-test calibration (the paper's c is 1: a "
        "calibrated reading is the paper's equations with another constant), each calibrated "
        "one with each normal-stress term (not in the paper's equations; the shear's c held "
        "at the reading's own fit on the same mesh and the term's c_n fitted beside it per "
        "mesh, so that a pair with and without the term differs in the normal stress alone; "
        "a fit of c_n = 0 leaves the reading itself; each constant stored with its cells and "
        "printed in cells.md), each literal reading with "
        f"{LITERAL_NORMAL} at c_n = {FIXED_NORMAL_C:g} (beside a literal shear the fit "
        "sets c_n to 0), pbcm-balanced with each normal-stress term at a fixed c_n = "
        f"{FIXED_NORMAL_C:g} (beside it the fit gives c_n near 0 on the mirrored split, so "
        "the fitted pairs cannot test a normal stress beside the paper's sign; its shear c "
        "held likewise), each of these calibrated models "
        "on the other splits with every constant it fits (the shear's c, and a fitted normal "
        "term's c_n) taken from its fit on the mirrored five split of "
        f"the same size ('{HELD_SUFFIX.strip()}': its mirror's controls, which then differ from "
        "it in the split alone), msm, msm with the variational shear "
        f"at c = 1, and {YARDSTICK} (FEM P1: constant-strain FEM with the continuum's own "
        "neo-Hookean law on the same tetrahedra, the control). " + recorded_design(s, doc)
        + " Each cell also "
        "keeps each "
        "vertical line of side-face nodes' own signature (the layer profile's weights applied "
        "to that line; the lines' mean is the layer profile's): the node-level pattern the "
        "layer mean averages over a face. The "
        "literal readings and msm are not calibrated: their lateral displacement error is "
        "shown beside every signature"
        + (" (patch-test displacement errors " + ", ".join(
            f"{r['name']} {fmt(r['sliding_disp_median'], 2)}" for r in lit) + ")"
           if lit else "") + "."
        + (f" Moving inward where the continuum bulges out (a mean lateral displacement "
           f"below 0) on every mesh and base: {', '.join(doc['answer']['inward'])}; the "
           "signature is blind to the profile's scale, sign included, so its signature "
           "reads only the period-2 part of an inverted bulge."
           if doc["answer"].get("inward") else ""),
        f"Bases: {', '.join(s.bcs)}. The clamped base holds the base and the top laterally: "
        "their layers cannot bulge, so the paper's observation (the end layers bulging) can "
        "only appear on the sliding base. Loads: the paper's push "
        f"({doc['problem']['push_mm']:g} mm) and {LINEAR_SCALE:g} of it (the linear regime; "
        "on the sliding base a patch test), the latter below the finest size.",
        "The reference: P2 on the six split (one of the controls' splits) of 5^3 nodes refined "
        f"{doc['problem']['reference']['refinements']} time(s), neo-Hookean at the push, "
        "linear at the linear load; its error estimate (the relative L2 difference of the "
        "displacement from the unrefined solution: one difference, unitless): " + "; ".join(
            f"{r['bc']}/{r['load']} {rel(r['error_estimate'])}" for r in doc["references"])
        + ". A lateral displacement error below it is marked 'not resolved'. The clamped "
        "continuum is reflection-symmetric about the middle layer; the reference's profile "
        "is not exactly ("
        + ", ".join(f"{n} nodes {fmt(v, 2)}" for n, v in asym.items())
        + " of its mean, the largest |r_k - r_(n-1-k)|): that is its own mesh error on the "
        "six split. The reference enters every model's signature alike; the floor (FEM P1's "
        "largest signature on the conforming splits) bounds its period-2 part, and it "
        "cancels in a model's part (model - FEM P1).",
        "The signature (the alternation): beta of the fit profile_k = alpha reference_k + "
        "s_k + beta (-1)^k over the free layers (reference_k: the glossary's profile_FEM, "
        "the continuum's; every layer sliding, all but the two held ones clamped), s_k a "
        "smooth part: whatever varies over two layer spacings or more. beta is read by one "
        "weighted sum of the free layers, exactly blind to the reference at any scale and to "
        f"polynomials up to degree {EXACT_DEGREE} (a tilt, a parabolic barrel), reading a pure "
        "(-1)^k pattern as 1, and of all such sums the one whose squared scores on a family "
        "of smooth fields (Gaussian bulges of standard deviation "
        + ", ".join(f"{x:g}" for x in SMOOTH_WIDTHS) + " layer spacings centred anywhere "
        "along the layers and beyond them, end layers decaying over "
        + ", ".join(f"{x:g}" for x in SMOOTH_DECAYS) + " spacings, a half-sine barrel) sum "
        "least. It is exactly 0 (to round-off) on the reference and on those polynomials; "
        "any other smooth field leaks a little, and an end layer sharper than two spacings "
        "more (on these layers it is half an alternation): the metric's check below states "
        "each configuration's two leaks, and they are in every signature's uncertainty there "
        "(the smooth leak times the field's smooth amplitude, the sharp one times its step "
        "between the two outermost free layers at either end). "
        "Positive: the layers of even index from the base out bulge (the paper's sign). "
        "Two normalisations: over the reference's mean |lateral displacement| over all "
        "layers (the glossary's alternation rel, stored and gated; on the clamped base the "
        "two held layers' zeros are in that mean) and over the model's own mean over its free "
        "layers (what a picture of its own deformed shape shows; a model moving out less "
        f"than the continuum reads larger on it). The clear level {CLEAR:g} (the glossary's, "
        "a convention of the metrics module: the paper gives no amplitude; on these bulges, "
        "0.1-0.5 mm, it is 1-5 um) is read on both, each as the interval |signature| +- u: "
        "clear where both are above it, below where both are below it, else 'not decided' "
        f"(at the threshold, within {NEAR:.0%} of it, or the two disagree). A configuration "
        f"(size, base) decides only where its worst smooth test field leaks below {LEAK_SHARE:g} "
        f"of the clear level ({DECIDING_LEAK:g}: as a reference's estimate must be below a "
        "fifth of the error it ranks); each configuration has one mesh per split (n = 1), so "
        "every uncertainty is the metric's leak alone. A ratio within "
        f"{NEAR:.0%} of the factor {RATIO:g} is 'at the threshold: not decided'."])


def _metric_check(d, doc):
    us = doc["answer"]["hypotheses"]["mirror"]["units"]
    d.h(2, "The metric's check")
    d.p("What the check can and cannot show: the signature scores 0, to round-off, on the "
        "continuum and on every polynomial up to degree 2 (a parabolic barrel), and a pure "
        "(-1)^k pattern at its amplitude; on any other smooth field (a Gaussian bulge, an end "
        "layer) a finite set of layers leaves it a small score, the leak, which no weights "
        "remove for every width at once. The requirement the metric was first set, a score "
        "of 0 (to round-off) on every smooth profile, Gaussian bulges of any width above two "
        "layers among them, cannot be met by weights on a finite set of layers; this study "
        "departs from that requirement, on purpose and stated here, and replaces it: 0 on the continuum and on the polynomials the weights absorb, each "
        "other smooth field's leak measured here, and the worst of them carried in every u, "
        "so that no part a leak could make is called resolved.")
    d.p("The signature's weights on test fields of each (size, base), the layers it reads "
        "(centred an eighth of a spacing off the weights' quarter-layer design grid; the "
        "widths 2 and 3, the decay 2 and, on the clamped base, the barrel are among the "
        "design fields, the width 5 and the decay 5 are not): a half-sine barrel, Gaussian bulges of standard "
        "deviation " + ", ".join(map(str, WIDTHS)) + " layer spacings, end boundary layers "
        "decaying over " + " and ".join(f"{x:g}" for x in DECAYS) + " layer spacings from the "
        "first and last free layer (at the base, at the top, at both with the same and with "
        "opposite signs), and, apart, end layers sharper than two spacings (decaying over "
        + " and ".join(f"{x:g}" for x in SHARP_DECAYS) + "); each the largest |score| over "
        "the field's height. The pure (-1)^k pattern must read 1; sum |w| is the most any "
        "field of height 1 can score, ||w||_2 what uncorrelated noise of 1 per layer reads "
        "(rms). 'Leak' is the worst smooth field's and 'sharp leak' the worst sharp end "
        "layer's: the uncertainty of every signature and part in this configuration holds "
        "the leak times the smooth amplitude of the field it reads and the sharp leak times "
        "its end step. 'End alternation' is "
        f"what a pure (-1)^k pattern confined to the {END_LAYERS} free layers at each end "
        "(amplitude 1, 0 between) reads: the metric's sensitivity to an alternation of the "
        "end layers only; below 1 it misses most of it, and a 'below the clear level' there "
        "does not exclude one. 'The paper's period reads': what a pattern at the paper's own "
        "period (bulges 16 mm apart, amplitude 1, at its worst phase) reads: 1 on 5 layers, "
        "where that period is two layers; on more layers it is smooth to this metric. "
        f"A configuration decides only with {DECISIVE} or more layers "
        f"and every smooth field's leak below {LEAK_SHARE:g} of the clear level "
        f"({DECIDING_LEAK:g}), not within {NEAR:.0%} of it.")
    rows, rows2 = [], []
    for u in us:
        c = u["check"]
        lk = c.get("leaks") or {}
        sharp = c.get("sharp") or {}
        rows.append([_unit(u), c.get("free", "n/a"), c.get("degree", "n/a"),
                     fmt(c.get("gain"), 3), fmt(c.get("noise_gain"), 3),
                     fmt(c.get("alternation_reads"), 3), fmt(lk.get("barrel"), 2)]
                    + [fmt(lk.get(f"Gaussian, sd {w} layers"), 2) for w in WIDTHS]
                    + [fmt(lk.get(f"end layer, decay {x:g}"), 2) for x in DECAYS])
        rows2.append([_unit(u)]
                     + [fmt(sharp.get(f"end layer, decay {x:g}"), 2) for x in SHARP_DECAYS]
                     + [fmt(c.get("worst"), 2), fmt(max(sharp.values(), default=None), 2)
                        if sharp else "n/a", fmt(c.get("ends"), 2),
                        fmt(c.get("paper_period"), 2),
                        "yes" if u["decides"] else f"no: {c.get('why')}"])     # clear calls
    d.table(["configuration (nodes, base)", "free layers", "degree absorbed", "sum |w|", "||w||_2",
             "(-1)^k reads", "barrel"] + [f"Gaussian sd {w}" for w in WIDTHS]
            + [f"end layer, decay {x:g}" for x in DECAYS], rows)
    d.table(["configuration (nodes, base)"] + [f"sharp end layer, decay {x:g}"
                                               for x in SHARP_DECAYS]
            + ["leak (worst)", "sharp leak", "end alternation reads",
               "the paper's period reads", "clear calls decide"],
            rows2)
    view = doc["answer"]["paper_view"]
    msm = next((c for c in doc["cells"] if c["model"] == "msm" and c["mesh"] == "five"
                and c["bc"] == "sliding" and c["load"] == "paper"
                and c.get("bulge_profile_mm")), None)
    if view.get("unit") is not None or view.get("of"):
        d.p(f"The paper's own view (mirrored five, {view['n']} layers, sliding base): "
            f"{len(view['shows'])} of {view['of']} distinct models ({view['run']} run) have "
            f"the paper's sign above {CLEAR:g} on both normalisations"
            + (f" ({', '.join(view['shows'])})" if view["shows"] else "")
            + (f"; the reversed sign above it: {', '.join(view['reversed'])}"
               if view.get("reversed") else "")
            + (f"; near it: {', '.join(view['at'])}" if view["at"] else "")
            + ". It decides nothing: on 5 layers the weights have one direction left to reduce "
            "the leak along, and smooth "
            f"fields leak up to {fmt(view['check'].get('worst'), 2)} of their height. "
            + (f"msm's profile there, {', '.join(f'{x:.3f}' for x in msm['bulge_profile_mm'])}"
               f" mm, is a (-1)^k pattern of {fmt(msm['alternation_mm'], 3)} mm "
               f"({fmt(msm['alternation_rel'], 2)} of the reference's mean, "
               f"{fmt(signature_own(msm), 2)} of its own): whether a pattern on the "
               "paper's mesh persists under refinement is what the 9- and 17-node configurations "
               "decide." if msm else ""))


def _mirror(d, doc):
    a = doc["answer"]
    m = a["hypotheses"]["mirror"]
    us = m["units"]
    est = _estimates(doc)
    d.h(2, "(a) Mirror symmetry: FEM P1's signature and the model's own part")
    d.p("Per (size, base) of the mirrored five split: whether it reads own parts "
        f"({DECISIVE} or more layers: the leak enters every u) and whether its clear-level "
        "calls decide (the metric's check); the leak; the controls (the conforming splits run "
        "for every model at that size; a model run on more reads its mirror against each it "
        "ran on); FEM P1's signature there (neo-Hookean P1: the mesh's own period-2 error) "
        "+- u (the leaks times its smooth amplitude and end step, and the floor, in "
        "quadrature) and whether it "
        f"is resolved ({RATIO:g} times u); the floor (FEM P1's largest signature on any "
        "conforming split run at that size; on the sliding base FEM P1 is exact, an identity "
        "check); and the distinct models by class, n of N.")
    rows = []
    for u in us:
        k = classes(u)
        n = sum(len(v) for v in k.values())
        rows.append([_unit(u), "yes" if u["reads"] else "no", "yes" if u["decides"] else "no",
                     fmt(u["check"].get("worst"), 2),
                     ", ".join(x.split(" ")[0] for x in u["controls"]) + "".join(
                         f"; {x.split(' ')[0]} for the {u['run'] - len(v)} of {u['run']} "
                         "run on it" for x, v in u["missing_controls"].items() if v),
                     _pm(u["fem_five"], u.get("u_fem")),
                     {"above": "yes", "below": "no", "at": "at the threshold"}.get(
                         u.get("fem_vs"), "n/a") if not u["identity"] else "exact",
                     ("n/a" if u["fem_five"] is None else "identity check (exact)"
                      if u["identity"] else _sig(u["floor"])),
                     times(u["fem_ratio"]) if not u["identity"] else "n/a",
                     f"{u['distinct']} of {u['run']}",
                     "; ".join(f"{c} {len(v)} of {n}" for c, v in sorted(k.items()))])
    d.table(["configuration", "reads parts", "clear calls decide", "leak", "controls",
             "FEM P1, mirrored +- u", "resolved", "floor", "FEM P1 / floor", "distinct models",
             "classes"], rows)
    d.p("Every distinct model on the mirrored split: its signature (over the reference's "
        "mean) +- u (the leaks times the smooth amplitude and end step of model - "
        "reference, and the floor), "
        "over its own mean, whether it is clear (on both "
        "normalisations; where not decided each one's call), its lateral displacement error "
        "(its mean lateral displacement over the free layers over the continuum's, minus 1: "
        "positive moves out more, softer laterally), its own part (model - FEM P1 on the "
        "same tetrahedra) +- u (the leaks times the smooth amplitude and end step of "
        "model - FEM P1), its part "
        "on each control +- its own u (a calibrated reading's controls, marked 'held', are "
        "the same reading with the shear's c fitted on the mirrored five split of the same "
        "size, so that they differ from it in the split alone), the mirror ratio (|part| "
        "over the largest |control part|) and its interval from both uncertainties "
        "((|part| - u) / max(|control| + u_c) to (|part| + u) / max(|control| - u_c), "
        "unbounded where every control's part is unresolved), the unmirrored five split (not "
        "conforming, not a control) and the class: 'not resolved' where |part| is below "
        f"{RATIO:g} u (it cannot be told from 0); 'own +' / 'own -' where resolved, with "
        f"'the mirror's' where the whole ratio interval is {RATIO:g} or more, 'on every "
        "split' where it is all below, else 'mirror not decided' with the reason; 'not "
        f"decided' below {DECISIVE} layers (the paper's view). Whether a signature is clear "
        "(large enough to see) is a column apart: it decides only where the configuration's "
        "leak is below the deciding level.")
    rows = []
    for u in us:
        for r in u["rows"]:
            if r["same_as"] is not None or r["kind"].startswith("n/a"):
                continue
            same_ = [x["name"] for x in u["rows"] if x["same_as"] == r["name"]]
            cps = r.get("control_parts") or {}
            rows.append([r["name"] + (f" (= {_compress(same_)})" if same_ else ""), _unit(u),
                         _pm(r["five"], r.get("u_sig")), f"{fmt(r['own'], 3)}: {_clear(r, u['decides'])}",
                         _lateral(r["lateral"], est.get(f"{u['bc']}/paper")),
                         _pm(r.get("part"), r.get("u")),
                         ("held: " if r.get("controls_held") else "") + (
                             "; ".join(f"{x.split(' ')[0]} {_pm(v['part'], v['u'])}"
                                       for x, v in cps.items()) or "n/a"),
                         (f"{times(r.get('mirror_ratio'))} [{times(max(r['mirror_lo'], 0))}"
                          f"-{times(r['mirror_hi']) if r['mirror_hi'] is not None else 'inf'}]"
                          + ("" if r.get("sign") else " (part not resolved)")
                          if r.get("mirror_lo") is not None else
                          times(r.get("mirror_ratio"))),
                         _sig(r["unmirrored"]), r["kind"]])
    d.table(["model", "configuration", "signature +- u", "over own mean: clear?",
             "lateral displacement error", "part (model - FEM P1) +- u", "control parts +- u",
             "mirror ratio [interval]", "unmirrored five", "class"], rows, keys=2)
    failed = a.get("failed") or []
    if failed:
        d.p(f"Failed cells ({len(failed)}: each a hole counted against its model; a failed "
            "control removes that control from the model's mirror ratio, never the model's "
            "own part): " + "; ".join(f"{m} on {mesh} {bc}" + (
                f" ({load} load)" if load != "paper" else "") + f": {why}"
                + ("" if solved else " (FEM P1 failed the same cell too)")
                for m, mesh, bc, load, why, solved in failed)
            + f". The study's static solve splits the push into up to {SPLITS_TRIED[-1]} equal "
            f"steps, each Newton step backtracked down to {SHORTEST_STEP:g} of its length, "
            "before it reports "
            "a failure; where FEM P1 solves the same cell on the same tetrahedra the problem is "
            "well posed and the failure the model's; these cells have no number.")
    tags = a.get("by_reading") or {}
    if tags:
        dec = [u for u in us if u["reads"]]
        d.p("The cause, conditional on the reading: each model's class on the configurations that "
            "read own parts (a model that is one observation with another takes its class), and "
            "what its own part rests on: its sign with the number of configurations where it is "
            "resolved, n of N, and where it is the mirror's.")
        d.table(["model"] + [_unit(u) for u in dec] + ["own part", "the mirror's on"],
                [[name] + [t["units"].get(_unit(u), "not run" if counted(u) else
                                          "not counted (its smooth fields leak)")
                           for u in dec]
                 + [t["label"], ", ".join(t["mirror"]) or "none"]
                 for name, t in tags.items()])
    for bc, o in m["orders"].items():
        v = sorted(o["orders"].values())
        d.p(f"Order in h, {bc} base, of the model's own part from {o['sizes'][0]} to "
            f"{o['sizes'][1]} nodes per side (where resolved at both with one sign): "
            + (f"not computed: {o['why']}." if o["why"] else
               f"median {np.median(v):.2f} [{min(v):.3f}-{max(v):.3f}], {len(v)} of {o['of']} "
               "distinct models resolved at both sizes"
               + (f" ({', '.join(f'{k} {x:.2f}' for k, x in o['orders'].items())})"
                  if v else "")
               + ". From two sizes: one order each, its uncertainty the parts' u propagated "
               "through the slope (at most "
               + fmt(max((o.get("u") or {0: 0.0}).values()), 2) + "), no check that the "
               "sizes are in the asymptotic range"
               + ("; the orders of unrelated models agree within "
                  f"{max(v) - min(v):.3f}: one common order, not a per-model property (a "
                  "node-level pattern of fixed strain averaged over each layer's side nodes "
                  "falls as h^"
                  f"{np.log2(o['sizes'][1] * (o['sizes'][1] - 1) / (o['sizes'][0] * (o['sizes'][0] - 1))):.2f}"
                  " over these sizes: the layer mean's slope is that averaging's)" if len(v) > 2
                  and max(v) - min(v) < 0.05 else "") + "." if v else
               "no distinct model resolved at both."))
    lin = a.get("linear") or {}
    for bc, x in lin.items():
        if not x["n"]:
            continue
        d.p(f"The linear-load check, {bc} base, mirrored split: the signature in mm at "
            f"{LINEAR_SCALE:g} of the push, scaled to the push, over the signature in mm at the "
            f"push, median {fmt(x['median'], 3)} [{fmt(x['range'][0], 2)}-"
            f"{fmt(x['range'][1], 2)}], {x['n']} distinct of {x['of']} model cells with a "
            "signature at both loads (the rest below 1e-05 at the push, or one observation "
            "with another)"
            + (", FEM P1 " + ", ".join(f"{fmt(r, 6)} at {n}" for n, r in x["fem"])
               + " (neo-Hookean: what it changes is the law's own finite strain)"
               if x["fem"] else "")
            + ". " + (f"Changing by more than {NEAR:.0%} with the load (part of the signature "
                      "is finite strain): " + ", ".join(f"{nm} at {n} ({fmt(r, 2)})"
                                                       for nm, n, r in x["changed"])
                      if x["changed"] else "None changes by more than "
                      f"{NEAR:.0%}: the pattern is a property of the linear regime") + ".")


def _normal(d, ns):
    d.h(2, "(b) Missing normal stress")
    word = {"+": "the paper's sign", "-": "the reversed sign"}
    d.p("Tested only on pairs where a normal-stress term changes the signature beyond "
        "round-off (relative 1e-6), on a configuration that reads own parts, beside a "
        "calibrated reading whose own part (model - FEM P1) is resolved there, the split "
        "held fixed; the part without and with the term, and "
        f"whether the term reduces it {RATIO:g}-fold (the ratio's interval from both parts' "
        "u): " + (f"{ns['removed']} of {ns['tested']} pairs reduced {RATIO:g}-fold or more"
                  + (f". Every tested pair is beside a reading of {word[ns['signs'][0]]} ("
                     f"{', '.join(ns['readings'])}): whether a term reduces a part of "
                     f"{word['+' if ns['signs'] == ['-'] else '-']} is not tested"
                     + (f" (beside {', '.join(ns['inactive_other_sign'])} every term changes "
                        "nothing)" if ns.get("inactive_other_sign") else "")
                     if len(ns["signs"]) == 1 else "") + "."
                  if ns["decided"] else "none qualifies, so (b) is not tested."))
    if ns["pairs"]:
        counted = distinct_pairs(ns["pairs"])
        d.table(["configuration", "term", "reading", "its sign", "part without", "part with",
                 "|with| / |without|", f"reduced {RATIO:g}-fold", "counted"],
                [[f"{p['n']} {p['bc']}", p["term"], p["base"], p["sign"], _sig(p["without"]),
                  _sig(p["with"]), fmt(p["ratio"], 3),
                  {"above": "yes", "below": "no", "at": "not decided"}[p["reduced"]],
                  "yes" if any(p is q for q in counted) else
                  "no: one observation with another term's pair above"]
                 for p in ns["pairs"]])
    why = {}
    for x in ns["untested"]:
        why.setdefault(x["why"], []).append(f"{x['name']} ({x['n']} {x['bc']})")
    if why:
        d.p(f"Not tested ({len(ns['untested'])} of {len(ns['untested']) + ns['tested']} "
            "pairs): " + "; ".join(f"{reason}: {len(v)}" + (f" ({', '.join(v)})"
                                                          if len(v) <= 4 else "")
                                   for reason, v in why.items()) + ".")


def _consistency(d, cs, us=()):
    d.h(2, "(c) The model's consistency")
    d.p("Per conforming mesh with the linear load (from 9 nodes per side: 17 has no linear "
        "load), in one regime: the rank correlation over the distinct models (FEM P1 left "
        "out) between the signature at the linear load and the sliding cube's linear-load "
        "error (the displacement error at "
        f"{LINEAR_SCALE:g} of the push), both on the sliding base, signed and on |signature|, "
        f"with models whose signature and that error agree to {SAME:g} (3 significant "
        f"figures) and to {COARSE:g} (2) counted once (near-duplicate variants are one "
        "observation), each with its 95 % interval (Fisher z, variance 1.06 / (n - 3)); "
        f"'tracks' where the whole interval lies at {TRACKS:g} or above, 'does not track' "
        f"where it lies below {TRACKS:g}; the verdict only where all four "
        f"agree; 'not testable' where fewer than {MIN_RESOLVED} models' signatures are "
        f"resolved ({RATIO:g} times their u: a correlation over signatures that cannot be told "
        "from 0 ranks the leak)."
        + "".join(f" On {u['n']} sliding layers the metric reads an alternation confined to "
                  f"the {END_LAYERS} end layers at each end at {fmt(u['check']['ends'], 2)} of "
                  "its amplitude: an alternation of the end layers alone is read weakly there."
                  for u in us if u["bc"] == "sliding" and u["n"] >= DECISIVE
                  and u["check"].get("ends") is not None and u["n"] in {
                      int(r["mesh"].rsplit("-", 1)[-1]) for r in cs["rows"]
                      if r["mesh"].rsplit("-", 1)[-1].isdigit()}))
    d.table(["mesh", "clustered at", "distinct models (reading families: the interval's n)",
             "signed: rho [95 %]", "unsigned: rho [95 %]", "resolved signatures", "verdict"],
            [[r["mesh"], fmt(v["tol"]), f"{v['n']} of {r['of']} ({r.get('families', 'n/a')})",
              _rho(v), _rho(next(w for w in r["variants"] if w["tol"] == v["tol"]
                                 and not w["signed"])),
              f"{r['clear']}" + (f" ({len(r['at'])} at the threshold)" if r["at"] else ""),
              r["verdict"]]
             for r in cs["rows"] for v in r["variants"] if v["signed"]])


def _rho(v):
    return (f"{fmt(v['rho'], 2)} " + ("[n/a]" if v["interval"] is None else
                                      f"[{v['interval'][0]:.2f}, {v['interval'][1]:.2f}]"))


def _yes(v):
    return "not decided" if v is None else "yes" if v else "no"


def _reading(d, s, doc):
    d.h(2, "Which reading the paper used")
    rows = doc["readings"]
    refs = _estimates(doc)
    finite = [r["paper_push_disp_median"] for r in rows
              if r["paper_push_disp_median"] is not None]
    est = refs.get("clamped/paper")
    ranks = est is not None and finite and est <= min(finite) / 5
    d.p(f"**Which reading.** {doc['verdict']['text']}")
    d.p("The verdict is the opening's; per model on the paper's lattice (5 nodes per side). "
        "Scored: the cost, the paper's Figure 2 (the time of one step over msm's, more than "
        f"{PAPER_COST:g}: the bench's in-round RK4 step ratio on the 320-tetrahedron five "
        "cube, read on its range over the bench's rounds; a call stands only where the range "
        "at every other size the bench ran, each its own population, reads the same (the "
        "figure reads the cost's growth with mesh size); a range reaching within "
        f"{NEAR:.0%} of {PAPER_COST:g} is not decided, and so is a ratio without a range; a "
        "literal reading's step is its calibrated reading's (the same kernel: c only scales "
        "the forces); for a "
        "model with a normal-stress term not decided: its added cost is this implementation's "
        "term) and stability (the largest growth rate of the undamped model linearised at "
        "rest, read on the clamped base only (the sliding base's rates are in cells.json, not "
        "read; the paper fixes its nodes at y = 0), on each conforming split of the lattice, this study's own cells: "
        "not an RK4 run and not the paper's mesh; one definition, the glossary's: a mode "
        f"flutters where its rate is above {GROWS:g} 1/s, and grows beyond the damping we "
        f"assume ({s.damping:g} 1/s) where its rate exceeds {s.damping / 2:g} 1/s; matched "
        "only where the rate is 0 on every mesh, missed only where it grows beyond the "
        "damping on every mesh, else not decided "
        "(on the mesh or on the damping the paper does not state: the damping below which the "
        "largest mode grows is twice its rate); the unmirrored five split is not conforming, "
        "its rate shown apart). Not scored: the 5-layer signature (the configuration's check "
        "fails), "
        "the displacement errors. "
        + (f"The clamped reference's error estimate {rel(est)} is more than a fifth of the "
           f"smallest clamped displacement error ({fmt(min(finite), 3)}): those errors are "
           "shown, not ranked." if est is not None and finite and not ranks else ""))
    d.table(["model", "form", "5-layer signature / own mean", "lateral displacement error",
             "step / msm [range]", "cost", "growth [1/s] by mesh",
             "unmirrored five [1/s] (apart)", "stability", "grows below damping [1/s]",
             "sliding disp. error, linear", "clamped disp. error, push",
             "cost / stable matched", "matched (of at most)"],
            [[r["name"], r["form"], fmt(r["pattern_own"], 3), fmt(r["lateral"], 2),
              (_cost_span(r) if r["timed"] else
               ("not timed" + (f" (stored {fmt(r['step_assumed'], 3)}: the calibrated "
                               "reading's)" if r["step_assumed"] is not None else ""))),
              r.get("cost_why") or "n/a",
              ", ".join(f"{m} {fmt(v, 3)}" for m, v in r["growth_by_mesh"].items()) or "n/a",
              ", ".join(fmt(v, 3) for v in r["growth_apart"].values()) or "n/a",
              r["stable_why"],
              fmt(r["flutters_below_damping"], 3) if r["flutters_below_damping"] else "never",
              fmt(r["sliding_disp_median"], 3), fmt(r["paper_push_disp_median"], 3),
              f"{_yes(r['matches']['cost'])} / {_yes(r['matches']['stable'])}",
              f"{r['score']} ({r['possible']})" if r["in_paper"] else "not scored"]
             for r in rows])


def _cost_span(r):
    span = r.get("step_range")
    return fmt(r["step_vs_msm"], 3) + (f" [{fmt(span[0], 3)}-{fmt(span[1], 3)}]" if span
                                       else " (no range)")


def _figures(d, out, s, doc):
    cells = doc["cells"]
    units = (doc["answer"].get("hypotheses") or {}).get("mirror", {}).get("units", [])
    shown = readings(list(s.models)) + [m for m in ("msm", YARDSTICK) if m in s.models]
    d.p(paper_figure_text(paper_figure(cells, readings(list(s.models)))))
    for name, spec in s.meshes.items():
        if spec[0] != "five":
            continue
        panels = {bc: [c for m in shown for c in cells if c["mesh"] == name and c["bc"] == bc
                       and c["model"] == m and c["load"] == "paper"
                       and c.get("bulge_profile_mm")]
                  for bc in s.bcs}
        if not any(panels.values()):
            continue
        fig = f"paper_profiles_{name}.png"
        clear = {(u["bc"], r["model"]): r.get("clear") for u in units if u["n"] == spec[1]
                 for r in u["rows"]}
        decides = {u["bc"]: u["decides"] for u in units if u["n"] == spec[1]}
        profiles_figure(out / fig, panels, f"mirrored five, {spec[1]} nodes per side, "
                        "the paper's push", decides, clear)
        run = sorted({c["model"] for v in panels.values() for c in v})
        d.img(fig, f"Layer profiles on the mirrored five split at {spec[1]} nodes per side, "
              f"each base: the continuum (black), the readings, msm and FEM P1 ({len(run)}; "
              "every other model's signature is in the tables); the paper's bulges (y = "
              + ", ".join(f"{y:g}" for y in PAPER_BULGES_MM) + " mm, dashed grey) and necks ("
              + ", ".join(f"{y:g}" for y in PAPER_NECKS_MM) + " mm, dotted grey) marked; each "
              "model's profile less its period-2 component dotted in its colour (the gap to "
              "its solid line is the component, layer by layer); the legend "
              "gives each model's period-2 signature over the reference's mean and over its "
              "own mean (n/a: the reference and a quadratic span the free layers, no period-2 "
              "component exists there), marked 'clear' where it is clear on both "
              "normalisations and the configuration decides"
              + ("; on the clamped base, the paper's setting, the 3 free layers of its 5 carry "
                 "no period-2 part, so an alternation like its Figure 1's could show only on "
                 "the sliding base" if spec[1] == 5 else ""))
    meshes, models = list(s.meshes), list(s.models)
    for bc in s.bcs:
        cell = {(c["model"], c["mesh"]): c for c in cells if c["bc"] == bc
                and c["load"] == "paper"}
        if not cell:
            continue
        fig = f"alternation_{bc}.png"
        counts = {(u["n"], u["bc"]) for u in units if counted(u)}
        muted = [j for j, x in enumerate(meshes)
                 if (s.meshes[x][1], bc) not in counts]
        heatmap(out / fig, [short(m) for m in models], meshes,
                [[cell.get((m, x)) for x in meshes] for m in models],
                f"signature over the reference's mean / the clear level {CLEAR:g}, {bc} base, "
                "the paper's push", muted)
        d.img(fig, f"The signature of every model on every mesh, {bc} base, over the "
              f"reference's mean in units of the clear level {CLEAR:g} (colour linear, "
              "saturating at +-1.5: the clear level is +-1 on the bar; a value near 0 is "
              "white), each cell's value written out; 'failed' on dark grey, 'not run' "
              "hatched, 'n/a' (no signature) on light grey; a mesh whose configuration "
              "(size, base) the answers do not count (5 nodes, or a leak above the deciding "
              "level) is greyed over and marked '(not counted)': its colours decide nothing")


def profiles_figure(path, panels, title, decides=None, clear=None):
    """One panel per base: the continuum's layer profile in black, each model's in colour,
    its signature over the reference's and over its own mean in the legend ('clear' where it
    is clear on both normalisations and the configuration decides, ``decides`` {base: bool},
    ``clear``
    {(base, model): call})."""
    decides, clear = decides or {}, clear or {}
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(panels), figsize=(5.6 * len(panels), 5.0), sharey=True,
                             squeeze=False)
    for ax, (bc, rows) in zip(axes[0], panels.items()):
        if rows:
            n = len(rows[0]["bulge_profile_mm"])
            y = np.linspace(0.0, P.SIZE_MM, n)
            ax.plot(rows[0]["bulge_profile_fem_mm"], y, "k-o", lw=2.5,
                    label="continuum (neo-Hookean P2)", zorder=3)
            for yy in PAPER_BULGES_MM:
                ax.axhline(yy, color="0.5", ls="--", lw=0.8)
            for yy in PAPER_NECKS_MM:
                ax.axhline(yy, color="0.5", ls=":", lw=0.8)
            cmap = plt.get_cmap("tab10")
            marks = "os^vD<>ph*"
            for i, c in enumerate(rows):
                own = signature_own(c)
                tag = "n/a" if own is None else (
                    f"{c['alternation_rel']:+.2g} / {own:+.2g}"
                    + (", clear" if clear.get((bc, c["model"])) == "above" and decides.get(bc)
                       else ""))
                ax.plot(c["bulge_profile_mm"], y, "-", marker=marks[i % len(marks)], ms=4.0,
                        lw=1.3, color=cmap(i % 10), label=f"{short(c['model'])} ({tag})")
                if c.get("alternation_mm") is not None:
                    # the profile less its period-2 component: the gap to the solid line is
                    # the component, layer by layer
                    alt = c["alternation_mm"] * (-1.0) ** np.arange(n) * _free_layers(bc, n)
                    ax.plot(np.asarray(c["bulge_profile_mm"]) - alt, y, ":", lw=1.0,
                            color=cmap(i % 10))
        n_free = len(rows[0]["bulge_profile_mm"]) - (2 if bc == "clamped" else 0) if rows else 0
        ax.set_title(f"{bc} base" + ("" if decides.get(bc) else
                                     "\n(the configuration's check not passed: decides nothing)")
                     + ("\n(3 free layers: no period-2 component, n/a)" if n_free == 3
                        else ""), fontsize=9)
        ax.set_xlabel("mean outward lateral displacement [mm]", fontsize=8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2,
                  title="model (signature / reference's mean / own mean)", title_fontsize=7)
    axes[0][0].set_ylabel("layer y [mm]", fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90, bbox_inches="tight")
    plt.close(fig)


def _status(c):
    if c is None:
        return "not run"
    if c.get("failed"):
        return "failed"
    if c.get("alternation_rel") is None:
        return "n/a"
    return None


def heatmap(path, rows, cols, cells, title, muted=()):
    """The signature of each (row, column) cell over the clear level, on a linear colour
    scale saturating at +-1.5 (the clear level at +-1, marked on the bar), its value written
    in two significant figures ('<1e-8' below round-off, on white); a failed cell on dark
    grey, a cell not run hatched, one without a signature on light grey, each with its word;
    the ``muted`` columns (decide nothing) greyed over and labelled so."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import Normalize
    from matplotlib.patches import Rectangle
    v = np.array([[np.nan if _status(c) else c["alternation_rel"] / CLEAR for c in r]
                  for r in cells], float)
    fig, ax = plt.subplots(figsize=(1.8 + 0.82 * len(cols), 1.8 + 0.3 * len(rows)))
    ax.set_facecolor("white")
    im = ax.imshow(v, cmap="RdBu_r", norm=Normalize(vmin=-1.5, vmax=1.5), aspect="auto")
    face = {"failed": ("0.35", None, "white"), "not run": ("white", "///", "0.4"),
            "n/a": ("0.8", None, "0.2")}
    for i, r in enumerate(cells):
        for j, c in enumerate(r):
            st = _status(c)
            if st:
                fc, hatch, colour = face[st]
                ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, facecolor=fc, hatch=hatch,
                                       edgecolor="0.6", lw=0.3))
                ax.text(j, i, st, ha="center", va="center", fontsize=5.5, color=colour)
                continue
            x = c["alternation_rel"]
            ax.text(j, i, "<1e-8" if abs(x) < 1e-8 else f"{x:.1e}", ha="center", va="center",
                    fontsize=5.2, color="k")
    for j in muted:
        ax.add_patch(Rectangle((j - 0.5, -0.5), 1, len(rows), facecolor="0.85", alpha=0.75,
                               edgecolor="none", zorder=2))
    cols = [f"{x} (not counted)" if j in muted else x for j, x in enumerate(cols)]
    ax.set_xticks(range(len(cols)), cols, rotation=45, ha="right", fontsize=7)
    ax.set_yticks(range(len(rows)), rows, fontsize=6.5)
    ax.set_title(title, fontsize=8)
    bar = fig.colorbar(im, ax=ax, shrink=0.8, ticks=[-1.5, -1, -0.5, 0, 0.5, 1, 1.5])
    bar.set_label(f"signature rel / {CLEAR:g} (+: the paper's sign; +-1: the clear level)",
                  fontsize=7)
    for t in (-1, 1):
        bar.ax.axhline(t, color="k", lw=1.2)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def cells_document(doc, s):
    """Every cell: per mesh, one row per model, the alternation [mm] and relative per base and
    load beside the reference's own alternating component."""
    c = Document("pbcm artefact study: every cell")
    c.p("Period-2 signature in mm (relative to the reference's mean lateral displacement in "
        "brackets) per base and load, beside the reference's mean lateral displacement in mm "
        "(the reference's own signature is zero by the metric's definition; FEM P1's is its "
        "row). 'not run': the cell is not in the study's design (the linear load on the "
        "finest meshes; a held model on the mirrored split, where it is the model it holds); "
        "'n/a': no signature on the free layers "
        "(three free layers of the clamped five-layer cube); 'failed': the static solve "
        f"failed, with its cause. 'constants': each term's constant as built on that mesh "
        "(fitted by the patch-test calibration where the model says auto, else given; a "
        f"model named '{HELD_SUFFIX.strip()}' holds the constants its calibrated twin fits on "
        "the mirrored five split of the same size, and a calibrated reading's normal term holds "
        "the shear's c fitted on the same mesh without it; the calibration reads the split's own "
        "cells, so a constant is the same at every size of one split; a normal term's c_n = 0: its fit "
        "dropped it there, the model is its reading). "
        f"Definitions: [glossary](../{GLOSSARY}).")
    combos = [(bc, load) for bc in s.bcs for load in s.loads]
    # the models run at each size on any split: one missing on a mesh of that size is a hole
    # of the design, shown as its row of 'not run', never left out
    at_size = {}
    for x in doc["cells"]:
        at_size.setdefault(x["nodes_per_side"], {})[x["model"]] = None
    for mesh in s.meshes:
        rows = {}
        for x in doc["cells"]:
            if x["mesh"] == mesh:
                rows.setdefault(x["model"], {})[(x["bc"], x["load"])] = x
        if not rows:
            continue
        first = next(iter(rows.values()))
        size = next(iter(first.values()))["nodes_per_side"]
        spec = s.meshes.get(mesh)
        designed = models_on(spec, s.models) if spec else []
        # every model the design runs here and this record lacks: a visible hole
        absent = [m for m in dict.fromkeys(list(at_size.get(size, {})) + designed)
                  if m not in rows and (not spec or m in designed)]
        c.h(2, f"{mesh} ({next(iter(first.values()))['tets']} tetrahedra)")
        c.table(["model"] + [f"{bc}/{load}" for bc, load in combos] + ["constants"],
                [["reference, mean lateral [mm]"] + [_scale(first.get(k)) for k in combos]
                 + [""]]
                + [[short(m)] + [_cell(r.get(k)) for k in combos] + [_constants(r)]
                   for m, r in rows.items()]
                + [[short(m)] + ["not in this record"] * len(combos)
                   + ["the design runs it here; this record predates it (`pbcm run artefact` "
                      "computes it)"] for m in absent])
    return c


def _constants(row):
    """'shear_c 0.125, normal_edge_c 0' of a model's cells on one mesh (the same in each)."""
    got = next((x.get("constants") for x in row.values() if x.get("constants")), None)
    return ", ".join(f"{k} {fmt(v, 3)}" for k, v in got.items()) if got else "n/a"


def _scale(x):
    if not x or not x.get("bulge_profile_fem_mm"):
        return "n/a"
    return fmt(float(np.mean(np.abs(x["bulge_profile_fem_mm"]))))


def _cell(x):
    if x is None:
        return "not run"
    if x.get("failed"):
        return failure(x)
    if x.get("alternation_mm") is None:
        return "n/a"
    return f"{fmt(x['alternation_mm'])} ({fmt(x['alternation_rel'])})"
