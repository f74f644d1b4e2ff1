"""The artefact study's files: metrics.json (the cells, the answers and the rows
the gate reads), report.md/.html (the answers, the metric's check, the decomposition per
hypothesis, the reading table, figures) and cells.md/.html (every cell's signature beside the
reference's scale). Every sentence is computed from the cells it is written with."""
from pathlib import Path

import numpy as np

from ... import catalogue
from ... import figures  # noqa: F401  (selects matplotlib's file backend before pyplot)
from ...document import GLOSSARY, Document, fmt, rel
from ...report import environment, write_study
from ...runner import jsonable
from .analysis import (CLEAR, NEAR, PAPER_COST, RATIO, alternating, answer, classes,
                       failure, how_sure, reading_table, reading_verdict, signature_own,
                       times)
from .study import (DECISIVE, FINEST_NORMAL_READING, LINEAR_SCALE, READINGS, SPLITS,
                    YARDSTICK, short)

GATED = catalogue.gated("alternation_rel", "disp_rel_l2")
PAPER_TETS = 374        # the paper's own cube, as it reports it


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
                          with_normal(models))
    found = {"answer": answer(data["cells"], models), "readings": table,
             "verdict": reading_verdict(table, damping)}
    found["how_sure"] = how_sure(found["answer"], found["verdict"])
    return found


def write(out, study, s, data):
    found = analyse(data, list(s.models), s.damping)
    doc = jsonable({"case": study.name, "study": True, "parameters": s.describe(),
                    "problem": s.problem(), "gated": GATED, "environment": environment(),
                    **data, **found, "gate_runs": gate_rows(data["cells"])})
    return write_study(out, doc, lambda folder: build(folder, study, s, doc))


def conclusion(doc):
    """The study's three lines: the cause, the reading and how sure; a quick run's are a
    preview that decides nothing."""
    lines = [f"**What causes the bulge/neck pattern.** {doc['answer']['text']}",
             f"**Which reading.** {doc['verdict']['text']}", doc["how_sure"]]
    if doc["parameters"].get("quick"):
        return ["**Quick: not decided** (`pbcm run artefact` decides, on meshes of 9 and 17 "
                "nodes per side); what the quick cells show, as a preview:"] + lines
    return lines


def _sig(x):
    return "n/a" if x is None else x if isinstance(x, str) else rel(x)


def _unit(u):
    return f"{u['n']} {u['bc']}"


def build(out, study, s, doc):
    out = Path(out)
    d = Document(f"pbcm report: {study.name}")
    d.opening(conclusion(doc))
    d.p("Every cell's numbers: [cells.md](cells.md). The report is drawn again from the stored "
        "cells with `pbcm run artefact --rewrite`; without `--rewrite` every cell is "
        "computed again.")
    _what_was_run(d, s, doc)
    hyp = doc["answer"].get("hypotheses") or {}
    if hyp:
        _metric_check(d, doc)
        _mirror(d, doc)
        _normal(d, hyp["normal_stress"])
        _consistency(d, hyp["consistency"])
    _reading(d, s, doc)
    _figures(d, out, s, doc)
    d.p(f"Environment: {doc['environment']}.")
    cells_document(doc, s).write(out, stem="cells")
    return d


def _what_was_run(d, s, doc):
    d.h(2, "What was run")
    sizes = sorted({spec[1] for spec in s.meshes.values()})
    five = next((c for c in doc["cells"] if c["mesh"] == "five"), None)
    lit = [r for r in doc["readings"] if r["in_paper"] and r["model"].endswith("-literal")]
    d.ul([
        f"Meshes: {', '.join(s.meshes)}: each split of the paper's lattice ("
        + ", ".join(SPLITS[k] for k in dict.fromkeys(spec[0] for spec in s.meshes.values()))
        + f") at {', '.join(map(str, sizes))} nodes per side. The unmirrored five split "
        "splits every cell alike, so its faces' diagonals cross: it is not conforming and is "
        "shown apart, never a control."
        + (f" The paper reports {PAPER_TETS} tetrahedra on its 5-node cube; the mirrored five "
           f"split of the same lattice has {five['tets']}: the paper's own mesh is not among "
           "these meshes." if five else ""),
        f"Models: {len(s.models)}: each shear reading calibrated and literal (c = 1), each "
        "calibrated one with each normal-stress term (with c fitted per mesh: where the fit "
        "sets it to 0 the term changes nothing; the fitted constants are not stored), msm, "
        "msm with the variational shear at c = 1, and "
        f"{YARDSTICK} (FEM P1: constant-strain, small-strain linear FEM on the same "
        "tetrahedra). On the finest meshes each normal-stress term beside the "
        f"{FINEST_NORMAL_READING} reading only, and on the finest bcc the calibrated readings "
        "and FEM P1 only (the cost of 9009 nodes). The literal readings and msm are not "
        "calibrated: their lateral stiffness error is shown beside every signature"
        + (" (patch-test displacement errors " + ", ".join(
            f"{r['name']} {fmt(r['sliding_disp_median'], 2)}" for r in lit) + ")"
           if lit else "") + ".",
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
        + ". It enters every model's signature alike; the floor (FEM P1 on the conforming "
        "splits, against the same reference) bounds its period-2 part, and it cancels in "
        "a model's part (model - FEM P1).",
        "The signature (glossary: alternation): beta of the exact fit profile_k = alpha "
        "reference_k + q(k) + beta (-1)^k over the free layers (every layer sliding, all but "
        "the two held ones clamped), q the polynomial of the highest degree that leaves "
        "(-1)^k apart, which depends on the reference: n - 2 on n free layers beside the "
        "sliding base's uniform reference, n - 3 beside the clamped base's barrel, which is "
        "not exactly symmetric (here: " + ", ".join(
            f"{_unit(u)} degree {u['check']['degree']} on {u['check']['free']}"
            for u in doc["answer"]["hypotheses"]["mirror"]["units"]
            if u["check"].get("degree") is not None) + " free layers). Positive: the "
        "layers of even index from "
        "the base out bulge (the paper's sign). Relative to the reference's mean |lateral "
        "displacement| over all layers (alternation rel, stored and gated: the classes are "
        "ratios of signatures on the same layers and do not depend on it), and relative to "
        "the model's own mean over the free layers (what a picture of its own deformed "
        f"shape shows: the clear level is read on this one). The clear level {CLEAR:g} is a "
        "convention of the metrics module, not derived from the paper, which gives no "
        "amplitude; on these bulges (0.1-0.5 mm) it is 1-5 um. It is used only on units "
        "whose smooth test fields leak below it. A value within "
        f"{NEAR:.0%} of a threshold ({CLEAR:g}, or the factor {RATIO:g}) is 'at the "
        "threshold: not decided'."])


def _metric_check(d, doc):
    us = doc["answer"]["hypotheses"]["mirror"]["units"]
    d.h(2, "The metric's check")
    d.p("The signature's weights on smooth test fields of each (size, base), the layers it "
        "reads: a half-sine barrel, Gaussian bulges of standard deviation 2 and 4 layer "
        "spacings centred on each free layer, an end boundary layer (decay length 2 "
        "spacings) at the base and at the top; each the largest |score| over the field's "
        "height. The pure (-1)^k pattern must read 1; sum |w| is the most any field of "
        f"height 1 can score. A unit decides only with {DECISIVE} or more layers and every "
        f"smooth field below the clear level {CLEAR:g}.")
    rows = []
    for u in us:
        c = u["check"]
        lk = c.get("leaks") or {}
        rows.append([_unit(u), c.get("free", "n/a"), c.get("degree", "n/a"),
                     fmt(c.get("gain"), 3), fmt(c.get("alternation_reads"), 3),
                     fmt(lk.get("barrel"), 2), fmt(lk.get("Gaussian, sd 2 layers"), 2),
                     fmt(lk.get("Gaussian, sd 4 layers"), 2), fmt(lk.get("end boundary layer"), 2),
                     "yes" if u["decides"] else f"no: {c.get('why')}"])
    d.table(["unit (nodes, base)", "free layers", "degree absorbed", "sum |w|",
             "(-1)^k reads", "barrel", "Gaussian sd 2", "Gaussian sd 4", "end layer",
             "decides"], rows)
    view = doc["answer"]["paper_view"]
    msm = next((c for c in doc["cells"] if c["model"] == "msm" and c["mesh"] == "five"
                and c["bc"] == "sliding" and c["load"] == "paper"
                and c.get("bulge_profile_mm")), None)
    if view.get("unit") is not None or view.get("of"):
        d.p(f"The paper's own view (mirrored five, {view['n']} layers, sliding base): "
            f"{len(view['shows'])} of {view['of']} distinct models ({view['run']} run) have "
            "the paper's sign at the clear level of their own mean"
            + (f" ({', '.join(view['shows'])})" if view["shows"] else "")
            + (f"; at the threshold: {', '.join(view['at'])}" if view["at"] else "")
            + ". It decides nothing: on 5 layers the weights absorb only a cubic, and smooth "
            f"fields leak up to {fmt(view['check'].get('worst'), 2)} of their height. "
            + (f"msm's profile there, {', '.join(f'{x:.3f}' for x in msm['bulge_profile_mm'])}"
               f" mm, is a (-1)^k pattern of {fmt(msm['alternation_mm'], 3)} mm "
               f"({fmt(signature_own(msm), 2)} of its own mean): whether a pattern on the "
               "paper's mesh persists under refinement is what the 9- and 17-node units "
               "decide." if msm else ""))


def _mirror(d, doc):
    a = doc["answer"]
    m = a["hypotheses"]["mirror"]
    us = m["units"]
    d.h(2, "(a) Mirror symmetry: FEM P1's error and the model's own part")
    d.p("Per (size, base) of the mirrored five split: FEM P1's signature there (the mesh's "
        "discretisation error, shared by every model) against the floor (FEM P1's largest "
        "on the conforming controls run for every model at that size; on the sliding base "
        "FEM P1 is exact, so the floor is the round-off bound 1e-08 of an identity check); "
        "the change of FEM P1's signature from the linear load to the push (the control is "
        "small-strain FEM: it enters the model's part's uncertainty); and the distinct "
        "models by class, n of N (models whose cells agree are one observation).")
    rows = []
    for u in us:
        k = classes(u)
        n = sum(len(v) for v in k.values())
        rows.append([_unit(u), "yes" if u["decides"] else "no",
                     ", ".join(x.split(" ")[0] for x in u["controls"]) + "".join(
                         f"; {x.split(' ')[0]} not run for {len(v)} of {u['run']}"
                         for x, v in u["missing_controls"].items() if v),
                     _sig(u["fem_five"]),
                     ("n/a" if u["fem_five"] is None else "identity check (exact)"
                      if u["identity"] else _sig(u["floor"])),
                     times(u["fem_ratio"]) if not u["identity"] else "n/a",
                     "n/a (P1 exact)" if u["identity"] else
                     fmt(u["law"], 2) + ("" if u["law_from"] in (None, u["n"])
                                         else f" (from {u['law_from']})"),
                     f"{u['distinct']} of {u['run']}",
                     "; ".join(f"{c} {len(v)} of {n}" for c, v in sorted(k.items()))])
    d.table(["unit", "decides", "controls", "FEM P1, mirrored", "floor",
             "FEM P1 / floor", "FEM P1 linear vs push", "distinct models", "classes"], rows)
    d.p("Every distinct model on the mirrored split: its signature (over the reference's "
        "mean), over its own mean lateral displacement, its lateral stiffness error (its "
        "mean lateral displacement over the continuum's, minus 1), its part (model - FEM P1 "
        f"on the same tetrahedra) and the part's uncertainty u = sqrt(leak^2 + law^2 + "
        "round-off^2) (leak: the unit's worst smooth-field leakage times the smooth amplitude "
        "of model - FEM P1; law: FEM P1's change with the load times its signature), the "
        "mirror ratio (|part| on the mirrored split over the largest |part| on the "
        "controls), the unmirrored five split (not conforming, not a control) and the class: "
        f"'own +' / 'own -' where the part is {RATIO:g} times u and the mirror ratio is "
        f"{RATIO:g} or more; 'own on every split' where resolved but not the mirror's; "
        "'mesh only' where the part is not resolved and FEM P1's is; 'none' where neither "
        "is; 'not decided' on a unit whose check fails.")
    rows = []
    for u in us:
        for r in u["rows"]:
            if r["same_as"] is not None or r["kind"].startswith("n/a"):
                continue
            same_ = [x["name"] for x in u["rows"] if x["same_as"] == r["name"]]
            rows.append([r["name"] + (f" (= {', '.join(same_)})" if same_ else ""), _unit(u),
                         _sig(r["five"]), fmt(r["own"], 3),
                         fmt(r["lateral"], 2), _sig(r.get("part")), fmt(r.get("u"), 2),
                         times(r.get("mirror_ratio")), _sig(r["unmirrored"]), r["kind"]])
    d.table(["model", "unit", "signature", "over own mean", "lateral stiffness error",
             "part (model - FEM P1)", "u", "mirror ratio", "unmirrored five", "class"], rows)
    failed = [(u, r) for u in us for r in u["rows"] if r["kind"].startswith("failed")]
    if failed:
        d.p("Failed observations (a hole, counted against the model): " + "; ".join(
            f"{r['name']} at {_unit(u)}: {r['kind']}" for u, r in failed) + ". The study's "
            "static solve splits the load into up to 8 steps before it reports a failure; no "
            "finer stepping was run, so these cells have no number.")
    tags = a.get("by_reading") or {}
    if tags:
        dec = [u for u in us if u["decides"]]
        d.p("The cause, conditional on the reading: each distinct model's class on the "
            "units that decide, and its sign where its own part is resolved and the mirror's.")
        per = {(u["n"], u["bc"]): {r["name"]: r["kind"] for r in u["rows"]} for u in dec}
        d.table(["model"] + [_unit(u) for u in dec] + ["own part"],
                [[name] + [per[(u["n"], u["bc"])].get(name, "not run") for u in dec]
                 + [tag] for name, tag in tags.items()])
    for bc, o in m["orders"].items():
        v = sorted(o["orders"].values())
        d.p(f"Order in h, {bc} base, of the model's own part from {o['sizes'][0]} to "
            f"{o['sizes'][1]} nodes per side: "
            + (f"not computed: {o['why']}." if o["why"] else
               f"median {np.median(v):.2f} [{min(v):.3f}-{max(v):.3f}], {len(v)} of {o['of']} "
               "distinct models resolved at both sizes"
               + (f" ({', '.join(f'{k} {x:.2f}' for k, x in o['orders'].items())})"
                  if v else "")
               + ". From two sizes: one order each, no check that the sizes are in the "
               "asymptotic range and no uncertainty"
               + ("; the orders of unrelated models agree within "
                  f"{max(v) - min(v):.3f}: one common order, not a per-model property (its "
                  "cause is not identified by these runs)" if len(v) > 2
                  and max(v) - min(v) < 0.05 else "") + "." if v else
               "no distinct model resolved at both."))
    lin = a.get("linear") or {}
    for bc, x in lin.items():
        if not x["n"]:
            continue
        d.p(f"The linear-load check, {bc} base, mirrored split: the signature at "
            f"{LINEAR_SCALE:g} of the push over the signature at the push, median "
            f"{fmt(x['median'], 3)} [{fmt(x['range'][0], 2)}-{fmt(x['range'][1], 2)}], "
            f"{x['n']} distinct of {x['of']} model cells with a signature at both loads "
            "(the rest below 1e-05 at the push, or one observation with another)"
            + (", FEM P1 " + ", ".join(f"{fmt(r, 3)} at {n}" for n, r in x["fem"])
               if x["fem"] else "")
            + ". " + (f"Changing by more than {NEAR:.0%} with the load (part of the signature "
                      "is finite strain): " + ", ".join(f"{nm} at {n} ({fmt(r, 2)})"
                                                       for nm, n, r in x["changed"])
                      if x["changed"] else "None changes by more than "
                      f"{NEAR:.0%}: the pattern is a property of the linear regime") + ".")


def _normal(d, ns):
    d.h(2, "(b) Missing normal stress")
    d.p("Tested only on pairs where a normal-stress term changes the signature beyond "
        "round-off (relative 1e-6), on a unit that decides, beside a calibrated reading whose "
        "own part (model - FEM P1) is resolved there; the part without and with the term: "
        + (f"{ns['removed']} of {ns['tested']} pairs reduced {RATIO:g}-fold or more."
           if ns["decided"] else "none qualifies, so (b) is not tested."))
    if ns["pairs"]:
        d.table(["unit", "term", "reading", "part without", "part with",
                 "|with| / |without|", f"reduced {RATIO:g}-fold"],
                [[f"{p['n']} {p['bc']}", p["term"], p["base"], _sig(p["without"]),
                  _sig(p["with"]), fmt(p["ratio"], 3),
                  {"above": "yes", "below": "no", "at": "at the threshold"}[p["reduced"]]]
                 for p in ns["pairs"]])
    why = {}
    for n, bc, name, reason in ns["untested"]:
        why.setdefault(reason, []).append(f"{name} ({n} {bc})")
    if why:
        d.p(f"Not tested ({len(ns['untested'])} of {len(ns['untested']) + ns['tested']} "
            "pairs): " + "; ".join(f"{reason}: {len(v)}" + (f" ({', '.join(v)})"
                                                          if len(v) <= 4 else "")
                                   for reason, v in why.items()) + ".")


def _consistency(d, cs):
    d.h(2, "(c) The model's consistency")
    d.p("Per conforming mesh with the linear load (from 9 nodes per side: 17 has no linear "
        "load): the signed rank correlation over the distinct models (FEM P1 left out) between "
        "the signature at the push and the patch-test error (the displacement error at "
        f"{LINEAR_SCALE:g} of the push), both on the sliding base, with its 95 % interval "
        "(Fisher z, variance 1.06 / (n - 3)); 'tracks' where the interval lies above 0 and "
        "the correlation is 0.7 or more, 'does not track' where the interval lies below 0.7, "
        "'not testable' where no model has a clear signature on the mesh.")
    d.table(["mesh", "distinct models", "rank correlation", "95 % interval",
             "clear signatures", "verdict"],
            [[r["mesh"], f"{r['models']} of {r['of']}", fmt(r["rho"], 2),
              "n/a" if r["interval"] is None else
              f"[{r['interval'][0]:.2f}, {r['interval'][1]:.2f}]", r["clear"], r["verdict"]]
             for r in cs["rows"]])


def _yes(v):
    return "not measured" if v is None else "yes" if v else "no"


def _reading(d, s, doc):
    d.h(2, "Which reading the paper used")
    rows = doc["readings"]
    refs = {r["bc"] + "/" + r["load"]: r["error_estimate"] for r in doc["references"]}
    finite = [r["paper_push_disp_median"] for r in rows
              if r["paper_push_disp_median"] is not None]
    est = refs.get("clamped/paper")
    ranks = est is not None and finite and est <= min(finite) / 5
    d.p("The verdict is the opening's; per model on the paper's lattice (mirrored five, 5 "
        "nodes per side). Scored: a step over "
        f"{PAPER_COST:g} times msm's and a clamped RK4 run without flutter (a mode grows "
        f"where its undamped growth rate exceeds half the mass damping, {s.damping:g} / 2 = "
        f"{s.damping / 2:g} 1/s, with the damping we assume; without damping where it is "
        "above round-off). Not scored: the 5-layer signature (the unit's check fails), the "
        "displacement errors. Step / msm: the bench's RK4 step on the 125-node five cube, "
        "one ratio per model (no spread stored); a literal reading is not timed (the stored "
        "ratio is its calibrated reading's), nor are the models marked 'not timed'. "
        + (f"The clamped reference's error estimate {rel(est)} is more than a fifth of the "
           f"smallest clamped displacement error ({fmt(min(finite), 3)}): those errors are "
           "shown, not ranked." if est is not None and finite and not ranks else ""))
    d.table(["model", "in the paper's equations", "5-layer signature / own mean",
             "lateral stiffness error", "step / msm", "largest growth [1/s]",
             "stable: damped / undamped", "sliding disp. error, linear",
             "clamped disp. error, push", "matched: damped / undamped"],
            [[r["name"], "yes" if r["in_paper"] else "no (+ a normal-stress term)",
              fmt(r["pattern_own"], 3), fmt(r["lateral"], 2),
              fmt(r["step_vs_msm"], 3) if r["timed"] else
              ("not timed" + (f" (stored {fmt(r['step_assumed'], 3)}: the calibrated "
                              "reading's)" if r["step_assumed"] is not None else "")),
              fmt(r["growth_max_1_s"], 3),
              f"{_yes(r['stable_damped'])} / {_yes(r['stable_undamped'])}",
              fmt(r["sliding_disp_median"], 3), fmt(r["paper_push_disp_median"], 3),
              f"{r['score']} / {r['score_undamped']} of {len(r['matches'])}"]
             for r in rows])


def _figures(d, out, s, doc):
    cells = doc["cells"]
    units = (doc["answer"].get("hypotheses") or {}).get("mirror", {}).get("units", [])
    shown = readings(list(s.models)) + ["msm", YARDSTICK]
    for name, spec in s.meshes.items():
        if spec[0] != "five":
            continue
        panels = {bc: [c for c in cells if c["mesh"] == name and c["bc"] == bc
                       and c["load"] == "paper" and c.get("bulge_profile_mm")
                       and c["model"] in shown] for bc in s.bcs}
        if not any(panels.values()):
            continue
        fig = f"paper_profiles_{name}.png"
        decides = {u["bc"]: u["decides"] for u in units if u["n"] == spec[1]}
        profiles_figure(out / fig, panels, f"mirrored five, {spec[1]} nodes per side, "
                        "the paper's push", decides)
        d.img(fig, f"Layer profiles on the mirrored five split at {spec[1]} nodes per side, "
              "each base: the continuum (black) and each reading, msm and FEM P1; the legend "
              "gives each model's signature over its own mean lateral displacement (n/a: no "
              f"signature on the free layers), marked 'clear' from {CLEAR:g} where the unit "
              "decides")
    meshes, models = list(s.meshes), list(s.models)
    for bc in s.bcs:
        cell = {(c["model"], c["mesh"]): c for c in cells if c["bc"] == bc
                and c["load"] == "paper"}
        if not cell:
            continue
        fig = f"alternation_{bc}.png"
        heatmap(out / fig, [short(m) for m in models], meshes,
                [[cell.get((m, x)) for x in meshes] for m in models],
                f"signature over the reference's mean, {bc} base, the paper's push")
        d.img(fig, f"The signature of every model on every mesh, {bc} base (over the "
              "reference's mean; colour on a symmetric log scale; 'failed', 'not run' and "
              "'n/a' written out)")


def profiles_figure(path, panels, title, decides=None):
    """One panel per base: the continuum's layer profile in black, each model's in colour,
    its signature over its own mean in the legend ('clear' only where the unit decides,
    ``decides`` {base: bool})."""
    decides = decides or {}
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 4.6), sharey=True,
                             squeeze=False)
    for ax, (bc, rows) in zip(axes[0], panels.items()):
        if rows:
            n = len(rows[0]["bulge_profile_mm"])
            y = np.linspace(0.0, 32.0, n)
            ax.plot(rows[0]["bulge_profile_fem_mm"], y, "k-o", lw=2.5,
                    label="continuum (neo-Hookean P2)", zorder=3)
            for c in rows:
                own = signature_own(c)
                tag = "n/a" if own is None else f"{own:+.2g}" + (
                    ", clear" if alternating(c) and decides.get(bc) else "")
                ax.plot(c["bulge_profile_mm"], y, "-s", ms=3.5, lw=1.2,
                        label=f"{short(c['model'])} ({tag})")
        ax.set_title(f"{bc} base" + ("" if decides.get(bc) else
                                     " (the unit's check fails: decides nothing)"), fontsize=9)
        ax.set_xlabel("mean outward lateral displacement [mm]", fontsize=8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6.5, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2,
                  title="model (signature / own mean)", title_fontsize=7)
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


def heatmap(path, rows, cols, cells, title):
    """The signature of each (row, column) cell on a symmetric log colour scale (linear
    below 1e-6), its value written in two significant figures; a failed, not run or
    undefined cell in grey with that word."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import SymLogNorm
    v = np.array([[np.nan if _status(c) else c["alternation_rel"] for c in r] for r in cells],
                 float)
    fig, ax = plt.subplots(figsize=(1.6 + 0.78 * len(cols), 1.6 + 0.3 * len(rows)))
    ax.set_facecolor("0.85")
    norm = SymLogNorm(linthresh=1e-6, vmin=-0.05, vmax=0.05, base=10)
    im = ax.imshow(v, cmap="coolwarm", norm=norm, aspect="auto")
    for i, r in enumerate(cells):
        for j, c in enumerate(r):
            st = _status(c)
            text = st if st else ("<1e-8" if abs(v[i, j]) < 1e-8 else f"{v[i, j]:.1e}")
            ax.text(j, i, text, ha="center", va="center", fontsize=5.5,
                    color="0.3" if st else "k")
    ax.set_xticks(range(len(cols)), cols, rotation=45, ha="right", fontsize=7)
    ax.set_yticks(range(len(rows)), rows, fontsize=6.5)
    ax.set_title(title, fontsize=9)
    fig.colorbar(im, ax=ax, label="signature rel (+: the paper's sign)", shrink=0.8)
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
        "finest meshes, some models on the finest); 'n/a': no signature on the free layers "
        "(three free layers of the clamped five-layer cube); 'failed': the static solve "
        f"failed, with its cause. Definitions: [glossary](../{GLOSSARY}).")
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
        return failure(x)
    if x.get("alternation_mm") is None:
        return "n/a"
    return f"{fmt(x['alternation_mm'])} ({fmt(x['alternation_rel'])})"
