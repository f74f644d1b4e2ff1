"""The real-time study's files: metrics.json (each run's errors and the bench's cost beside
them, the verdict and the rows the gate reads), report.md/.html and the figure. Every sentence
is computed from the data it is written with."""
import math
from pathlib import Path

from ...measuring import catalogue
from ...measuring.error_model import standings, u_val
from ...reporting import figures
from ...reporting.costs import REAL_TIME
from ...reporting.document import Document, fmt
from ...reporting.report import environment, write_study
from ...running.runner import jsonable
from .study import ACCURACY_TETS, MODELS, P1, statics_of

GATED = catalogue.gated("disp_rel_l2", "disp_form_rel_l2")


def reach(runs):
    """{model: its run at the largest size at which the bench measured it at real time (at
    most REAL_TIME CPU seconds per simulated second), or None}."""
    out = {}
    for m in MODELS:
        fit = [r for r in runs if r["model"] == m and r["realtime_factor"] is not None
               and r["realtime_factor"] <= REAL_TIME]
        out[m] = max(fit, key=lambda r: r["tets"], default=None)
    return out


def bound(runs, run):
    """A run's error bound: its model-form error plus FEM P1's distance from the continuum on
    the same mesh (the discretisation error every model there shares), the triangle
    inequality's bound of its distance from the continuum; a model whose own distance is
    smaller has an error that cancels part of FEM P1's, luck of that mesh that the bound does
    not reward. None where either part is missing."""
    p1 = next((r for r in runs if r["model"] == P1 and r["tets"] == run["tets"]), None)
    if run["disp_form_rel_l2"] is None or p1 is None or p1["disp_rel_l2"] is None:
        return None
    return run["disp_form_rel_l2"] + p1["disp_rel_l2"]


def verdict(data):
    """The most accurate model at real time: the models ranked by their error bound at their
    real-time reach (``bound``: model-form error plus FEM P1's discretisation error there; a
    model that failed there, or whose error was not computed, counts as failed), ties within
    u_val (the reference's estimate); with the models whose distance from the continuum is
    below their model-form error by more than u_val (their error cancels FEM P1's)."""
    runs = data["runs"]
    at = reach(runs)
    measured = {m: r for m, r in at.items() if r is not None}
    if not measured:
        return {"decided": False, "why": "no model was measured at real time (run `pbcm "
                "bench` on this machine)", "reach": {}, "ranks": []}
    u = u_val(data["error_estimate"] or 0.0)
    bounds = {m: bound(runs, r) for m, r in measured.items()}
    ranked = standings({m: [b] for m, b in bounds.items()}, u)
    first = [s.model for rank, s, _ in ranked if rank == 1 and math.isfinite(s.score)]
    return {"decided": bool(first), "best": first, "u": u, "bounds": bounds,
            "reach": {m: None if r is None else r["tets"] for m, r in at.items()},
            "ranks": [{"rank": rank, "model": s.model, "tied": list(o.tied),
                       "unresolved": list(o.unresolved),
                       "score": None if math.isinf(s.score) else s.score} for rank, s, o in ranked],
            "cancels": [m for m, r in measured.items() if r["disp_form_rel_l2"] is not None
                        and r["disp_rel_l2"] is not None
                        and r["disp_rel_l2"] + u < r["disp_form_rel_l2"]]}


def machine(data):
    m = data.get("machine") or {}
    return f"{m.get('cpu', 'an unnamed processor')}, {m.get('cores', '?')} cores, one used"


def answer_line(data, v, quick):
    """The index's one line: the most accurate model at real time on the bench's machine."""
    if quick:
        return ("Quick: not decided (two mesh sizes; `pbcm run realtime` reads every size the "
                "bench measured).")
    if not v["decided"]:
        return f"Not decided: {v.get('why', 'no model has an error at its real-time reach')}."
    runs = {(r["model"], r["tets"]): r for r in data["runs"]}
    best = [runs[(m, v["reach"][m])] for m in v["best"]]
    said = "; ".join(f"{r['model']}, with {r['tets']} tetrahedra, error bound "
                     f"{fmt(v['bounds'][r['model']], 2)} (model-form "
                     f"{fmt(r['disp_form_rel_l2'], 2)} plus FEM P1's discretisation error "
                     f"there; its distance from the continuum {fmt(r['disp_rel_l2'], 2)})"
                     for r in best)
    tie = " (tied within u_val)" if len(best) > 1 else ""
    return (f"At real time on this machine ({machine(data)}), the most accurate model is "
            f"{said}{tie}, the paper's push on its cube, static.")


def write(out, study, s, data):
    v = verdict(data)
    doc = jsonable({"case": study.name, "study": True, "parameters": s.describe(),
                    "problem": s.problem(), "gated": GATED, "environment": environment(),
                    **data, "verdict": v, "answer": answer_line(data, v, s.quick),
                    "gate_runs": [{"mesh": r["mesh"], "bc": r["bc"], "model": r["model"],
                                   "disp_rel_l2": r["disp_rel_l2"],
                                   "disp_form_rel_l2": r["disp_form_rel_l2"]}
                                  for r in data["runs"] if r["accuracy"]]})
    return write_study(out, doc, lambda folder: build(folder, study, s, doc))


def _cell(x, digits=3):
    return "n/a" if x is None else fmt(x, digits)


def build(out, study, s, doc):
    out = Path(out)
    d = Document(f"pbcm report: {study.name}")
    v = doc["verdict"]
    d.opening([f"**At a real-time budget.** {doc['answer']}"])
    d.p("The question the paper leaves open: at real time, how large a mesh can each model "
        "run, and how far from the continuum is it there? The cost is what `pbcm bench` "
        f"measured on {machine(doc)}: CPU seconds per simulated second on the bench's five "
        "cubes, the explicit models at their own largest stable RK4 step, the implicit "
        "presets (backward Euler, Newton with conjugate gradients) at their own step; at most "
        f"{REAL_TIME:g} is real time. The accuracy is each model's static equilibrium under "
        "the paper's push (1.7 mm on the 32 mm cube, clamped base: a push at 1.7 mm/s is "
        "quasi-static for the cube, whose lowest mode is tens of hertz), on the same meshes up "
        f"to {ACCURACY_TETS:g} tetrahedra: the distance from the converged continuum "
        "(||u - u_c|| / ||u_c||, neo-Hookean P2) and the model-form error against FEM P1 with "
        f"the continuum's law on the same tetrahedra ({P1}). An implicit preset's equilibrium "
        f"is its explicit twin's ({statics_of(MODELS[-1])}): its step changes the dynamics, "
        "which the paper-cube case judges against the FEM transient where it is run by name. "
        "Differences below u_val (the reference's estimate, "
        f"{fmt(v.get('u'), 2) if v.get('u') is not None else 'n/a'}) are ties.")
    if v.get("ranks") and not doc["parameters"]["quick"]:
        runs = {(r["model"], r["tets"]): r for r in doc["runs"]}
        rows = []
        for k in v["ranks"]:
            r = runs[(k["model"], v["reach"][k["model"]])]
            rows.append([k["rank"], k["model"], r["tets"], _cell(r["realtime_factor"]),
                         _cell(v["bounds"].get(k["model"])), _cell(r["disp_form_rel_l2"]),
                         _cell(r["disp_rel_l2"]), ", ".join(k["tied"]) or "-"])
        d.p("Each model at the largest mesh it runs in real time, ranked by its error bound "
            "there: its model-form error plus FEM P1's distance from the continuum on that "
            "mesh (the discretisation error every model there shares; the bound of its own "
            "distance by the triangle inequality, which a model whose error happens to cancel "
            "FEM P1's on a coarse mesh cannot undercut); a failed run or an error not computed "
            "counts against it:")
        d.table(["rank", "model", "tets", "CPU s per simulated s", "error bound",
                 "model-form error", "distance from continuum", "tied with"], rows)
        costed = {r["model"] for r in doc["runs"] if r["realtime_factor"] is not None}
        none = [m for m, t in v["reach"].items() if t is None and m in costed]
        if none:
            d.p("Not in real time at any size measured: " + ", ".join(none) + ".")
        unmeasured = [m for m in MODELS if m not in costed]
        if unmeasured:
            d.p("Not measured by the bench at any of these sizes (`pbcm bench` times them): "
                + ", ".join(unmeasured) + ".")
        if v.get("cancels"):
            d.p("Closer to the continuum than to FEM P1 on the same mesh (the model's error "
                "cancels part of FEM P1's discretisation error there, a coarse mesh's luck, "
                "not a property of the model): " + ", ".join(v["cancels"]) + ".")
    d.h(2, "Every size")
    d.table(["model", "tets", "CPU s per simulated s", "real time", "distance from continuum",
             "model-form error", "load steps", "failed"],
            [[r["model"], r["tets"], _cell(r["realtime_factor"]),
              "n/a" if r["realtime_factor"] is None else
              ("yes" if r["realtime_factor"] <= REAL_TIME else "no"),
              _cell(r["disp_rel_l2"]) if r["accuracy"] else "not computed",
              _cell(r["disp_form_rel_l2"]) if r["accuracy"] else "not computed",
              r["load_steps"] or "-", r["failed"] or "-"] for r in doc["runs"]])
    d.p("'n/a' cost: the bench did not measure that model's cost per simulated second at "
        "that size (`pbcm bench` measures the stable step and the implicit step up to 2e5 "
        "tetrahedra); 'not computed': above the sizes whose accuracy this study solves.")
    series = []
    for m in MODELS:
        pts = sorted((r["realtime_factor"], r["disp_rel_l2"]) for r in doc["runs"]
                     if r["model"] == m and r["realtime_factor"] is not None
                     and r["disp_rel_l2"] is not None)
        if pts:
            series.append((m, [p[0] for p in pts], [p[1] for p in pts]))
    if series:
        figures.error_against_cost(out / "error_vs_cost.png", series, REAL_TIME,
                                   f"CPU s per simulated s ({machine(doc)})",
                                   "distance from the continuum", "Accuracy against cost, "
                                   "the paper's push")
        d.img("error_vs_cost.png", "distance from the continuum against CPU seconds per "
              "simulated second, every model and size; the dashed line is real time")
    d.p(f"Environment: {doc['environment']}.")
    return d
