"""reports/index: the scorecard (one population per row: a case's runs under one boundary
condition, its headline error and the metric paired with it, per model, coloured by band in
HTML) and a five-line conclusion written from the numbers."""
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .document import GLOSSARY, Cell, Document, Link
from .metrics import PATCH_TOL
from .output import SWEEP_MARK

# headline error bands of the scorecard: within 5 %, within 20 %, beyond
BANDS = ((0.05, "#c8e6c9", "within 5 %"), (0.20, "#fff59d", "within 20 %"),
         (float("inf"), "#ffcdd2", "beyond 20 %"))




@dataclass
class Population:
    """One aggregate of the scorecard: a case's runs under one boundary condition, for one
    metric (its headline or the one paired with it). ``values`` {model: values over the runs
    that gave one}, ``runs`` {model: runs it had}, ``floor`` the reference's estimate."""

    case: str
    bc: str
    metric: str
    primary: bool
    patch_test: bool
    values: dict
    runs: dict
    floor: float

    @property
    def label(self):
        return f"{self.case}/{self.bc}"

    def complete(self, model):
        full = max(self.runs.values(), default=0)
        return len(self.values.get(model, [])) == self.runs.get(model, -1) == full

    def median(self, model):
        v = self.values.get(model)
        return float(np.median(v)) if v else None


def _declared(case):
    from .registry import CASES
    return CASES[case]


def populations(root, cases):
    """Every scorecard population of the cases' metrics under ``root``, and the loaded
    metrics: per case and boundary condition, its headline and the metric paired with it."""
    out, data = [], {}
    for case in cases:
        d = json.loads((Path(root) / case / "metrics.json").read_text())
        data[case] = d
        declared = _declared(case)
        metrics = [(d.get("headline") or declared.headline, True)]
        pair = d.get("headline_pair", declared.headline_pair)
        if pair:
            metrics.append((pair, False))
        est_key = d.get("headline_estimate", declared.headline_estimate)
        patch = set(d.get("patch_tests", declared.patch_tests))
        bcs = list(dict.fromkeys(r["bc"] for r in d["runs"]))
        for bc in bcs:
            rs = [r for r in d["runs"] if r["bc"] == bc]
            est = [r[est_key] for r in rs if r.get(est_key) is not None]
            for metric, primary in metrics:
                values, had = {}, {}
                for model in d["parameters"]["models"]:
                    mine = [r for r in rs if r["model"] == model]
                    had[model] = len(mine)
                    values[model] = [r[metric] for r in mine if r.get(metric) is not None]
                out.append(Population(case, bc, metric, primary, bc in patch, values, had,
                                      max(est) if est else 0.0))
    return out, data


def _score_cell(p, m):
    vals, total = p.values.get(m, []), p.runs.get(m, 0)
    if not total:
        return ""
    if not vals:
        return f"n/a, 0 of {total}"
    if p.patch_test and p.primary:
        worst = max(vals)
        return Cell(("pass" if worst < PATCH_TOL else f"fail {worst:.2g}")
                    + f", {len(vals)} of {total}",
                    BANDS[0][1] if worst < PATCH_TOL else BANDS[-1][1])
    med = float(np.median(vals))
    return Cell(f"{med:.3g} [{min(vals):.3g}-{max(vals):.3g}] {len(vals)}/{total}",
                _band(med)[1])


def _band(v):
    return next(b for b in BANDS if v < b[0])


def geometric_means(pops, models):
    """{model: (geometric mean, (low, high) leaving one population out)} over the primary,
    non-patch-test populations where every model has a value in every run (the others are
    not comparable), each entry floored at its reference's estimate (an error below what the
    reference resolves counts as that estimate); and the populations used."""
    used = [p for p in pops if p.primary and not p.patch_test
            and all(p.complete(m) for m in models)]

    def gmean(model, ps):
        vals = [max(p.median(model), p.floor, 1e-300) for p in ps]
        return float(np.exp(np.mean(np.log(vals)))) if vals else None

    out = {}
    for m in models:
        g = gmean(m, used)
        if g is None:
            continue
        loo = [gmean(m, used[:k] + used[k + 1:]) for k in range(len(used))] if len(used) > 1 \
            else [g]
        out[m] = (g, (min(loo), max(loo)))
    return out, used


def conclusion(pops, models):
    """Five sentences from the scorecard's populations."""
    means, used = geometric_means(pops, models)
    out = []
    primaries = [p for p in pops if p.primary and not p.patch_test]
    if means:
        best = min(means, key=lambda m: means[m][0])
        g, (lo, hi) = means[best]
        out.append(f"Closest to the continuum overall: {best}, geometric mean of its headline "
                   f"errors {g:.3g} (from {lo:.3g} to {hi:.3g} leaving one population out) over "
                   f"the {len(used)} of {len(primaries)} case/boundary-condition populations "
                   "where every model has a result in every run (entries floored at their "
                   "reference's estimate).")
        out.append("Every model so: " + ", ".join(
            f"{m} {means[m][0]:.3g} [{means[m][1][0]:.3g}-{means[m][1][1]:.3g}]"
            for m in sorted(means, key=lambda m: means[m][0])) + "; not comparable (a run "
            "without a result): " + (", ".join(p.label for p in primaries if p not in used)
                                     or "none") + ".")
    else:
        out.append("No population has a result from every model in every run: no overall "
                   "ranking.")
        out.append("Every population lacks some model's run.")
    worst = {}
    for p in primaries:
        for m in models:
            v = p.median(m)
            if v is not None and (m not in worst or v > worst[m][0]):
                worst[m] = (v, p)
    out.append("Where each model is farthest (median headline): " + "; ".join(
        f"{m} in {p.label} ({p.metric} {v:.3g})" for m, (v, p) in worst.items()) + ".")
    within = {p.label: [m for m in models if p.complete(m) and max(p.values[m]) < BANDS[0][0]]
              for p in primaries}
    patch = [p for p in pops if p.primary and p.patch_test]
    out.append("Within 5 % of FEM in every run: " + ("; ".join(
        f"{c}: {', '.join(ms)}" for c, ms in within.items() if ms) or "none") + ". "
        + " ".join(f"Patch test {p.label}: passed (error below {PATCH_TOL:g}) by "
                   + (", ".join(m for m in models if p.complete(m)
                                and max(p.values[m]) < PATCH_TOL) or "none") + "."
                   for p in patch))
    missing = [f"{m} in {p.label} ({len(p.values.get(m, []))} of {p.runs.get(m, 0)} runs)"
               for p in pops if p.primary for m in models if not p.complete(m)]
    out.append("Every model gave a headline number in every run." if not missing else
               "Runs without a headline number: " + ", ".join(missing) + ".")
    return out


def index_documents(root, cases, studies=()):
    """The Markdown and HTML of reports/index: the answers (``cases.answers``) and their
    table first, then the studies, the scorecard and its conclusion."""
    from . import answers
    from .registry import studies as declared
    root = Path(root)
    pops, data = populations(root, cases)
    models = []
    for case in cases:
        models += [m for m in data[case]["parameters"]["models"] if m not in models]
    doc = Document("pbcm reports")
    for line in answers.lines(root, models):
        doc.p(line)
    header, rows = answers.table(root, models)
    doc.table(header, rows)
    doc.p(f"Definitions of every column and metric: [glossary]({GLOSSARY}).")
    shown = [n for n in studies if (root / n / "metrics.json").is_file()]
    if shown:
        doc.h(2, "Studies")
        doc.table(["study", "what it measures", "mode"], [
            [Link(n, f"{n}/report.md", f"{n}/report.html"), declared()[n].title,
             "quick" if json.loads((root / n / "metrics.json").read_text())["parameters"][
                 "quick"] else "full"] for n in shown])
    doc.h(2, "Scorecard")
    doc.p("One row per case, boundary condition and metric: the case's headline error against "
          "its reference, then the metric paired with it (a displacement-driven case's "
          "stiffness error, a force-driven one's displacement error). Each cell is the median "
          "over the meshes [smallest-largest], n of N runs; a patch test reads pass or fail at "
          f"{PATCH_TOL:g}. Colours in the HTML: "
          + ", ".join(f"{label}" for _, _, label in BANDS) + ". Quick-mode cases are marked. "
          "The last rows are measured against reality (the Truth Cube's beads): green within "
          "the measurement's floor at every state, yellow at some, red at none.")
    rows = []
    for p in pops:
        mode = " (quick)" if data[p.case]["parameters"]["quick"] else ""
        label = p.label + mode + (" (patch test)" if p.patch_test else "")
        rows.append([Link(label, f"{p.case}/report.md", f"{p.case}/report.html")
                     if p.primary else "", p.metric] + [_score_cell(p, m) for m in models])
    for n in shown:       # the studies' own rows (the one measured against reality)
        for label, metric, cells in declared()[n].scorecard(
                json.loads((root / n / "metrics.json").read_text())):
            rows.append([Link(label, f"{n}/report.md", f"{n}/report.html"), metric]
                        + [Cell(cells[m][0], BANDS[cells[m][1]][1]) if m in cells else ""
                           for m in models])
    doc.table(["case/bc", "metric"] + models, rows, keys=2)
    for line in conclusion(pops, models):
        doc.p(line)
    doc.p("Each case folder holds metrics.json, report.md, report.html and the figures; "
          "regenerate with `pbcm report`.")
    sweeps = sorted((root / "sweeps").glob(f"*/{SWEEP_MARK}"))
    if sweeps:
        doc.h(2, "Sweeps")
        doc.table(["sweep", "spec"], [
            [Link(json.loads(m.read_text())["title"], f"sweeps/{m.parent.name}/report.md"),
             json.loads(m.read_text())["spec"]] for m in sweeps])
        doc.p("Each is written by `pbcm sweep SPEC` (not by `pbcm report`).")
    return doc.markdown() + "\n", doc.html(root) + "\n"


# what the index's answer table and the studies call things, beside the catalogue's metrics
TERMS = {
    "consistency error": "the error a model keeps under mesh refinement on a problem whose "
    "answer every consistent discretisation reproduces exactly: the converged limit e_inf of "
    "the sliding cube (a homogeneous compression, a patch test) in the linear regime, per "
    "lattice; FEM's is zero to rounding.",
    "finite-load error": "the headline error of the large-compression case (30 % "
    "compression), against the converged neo-Hookean reference.",
    "worst isotropy error": "the largest relative error of the six Kelvin moduli of the "
    "model's effective elasticity tensor (a relaxed lattice patch) against the isotropic "
    "target's, over the lattices.",
    "largest |alternation|": "the largest |alternation rel| of the paper cube's runs.",
    "RK4 run": "flutters when the linearised growth rate of the clamped paper cube exceeds "
    "half the mass damping (so that the damped RK4 run grows), else stable.",
    "s per simulated s": "CPU seconds one simulated second costs at the model's own stable "
    "RK4 step (undamped), from `pbcm bench` at about 1e4 tetrahedra.",
    "calibrated / literal": "a shear reading with c fitted so that its deviatoric moduli are "
    "closest to 2G (calibrated), or with the paper's c = 1 (literal).",
    "patch test": "a problem with a homogeneous exact answer (the sliding cube): a consistent "
    "discretisation reproduces it on any mesh; a model that does not has a consistency error.",
    "population": "the runs of one case under one boundary condition: what a median, a range "
    "or a criterion is taken over (never pooled across populations).",
}


def glossary_documents():
    """The Markdown and HTML of reports/glossary: the index's terms, then every metric of the
    catalogue (label, name, unit, definition), written once for every report to link to."""
    from . import catalogue
    doc = Document("pbcm glossary")
    doc.h(2, "Terms")
    doc.ul(f"{k}: {v}" for k, v in TERMS.items())
    from .registry import studies
    for name, study in studies().items():
        if study.definitions():
            doc.h(2, f"The {name} study")
            doc.ul(study.definitions())
    doc.h(2, "Metrics")
    doc.table(["label", "name", "unit", "definition"],
              [[m.label, m.name, m.shown[0] if m.shown else m.unit, m.definition]
               for m in sorted(catalogue.CATALOGUE.values(), key=lambda m: m.name)])
    return doc.markdown() + "\n", doc.html(".") + "\n"


def write_index(root, cases, studies):
    """index.md/.html and glossary.md/.html under ``root``, each written atomically."""
    from .output import write_atomic
    root = Path(root)
    md, html = index_documents(root, cases, studies)
    write_atomic(root / "index.md", md)
    write_atomic(root / "index.html", html)
    md, html = glossary_documents()
    write_atomic(root / "glossary.md", md)
    write_atomic(root / "glossary.html", html)
    return root / "index.md"
