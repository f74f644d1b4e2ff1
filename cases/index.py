"""reports/index: the scorecard (case x model headline errors, coloured by band in HTML) and
a five-line conclusion written from the numbers."""
import json
from pathlib import Path

import numpy as np

from .document import Cell, Document, Link
from .output import SWEEP_MARK

# headline error bands of the scorecard: within 5 %, within 20 %, beyond
BANDS = ((0.05, "#c8e6c9", "within 5 %"), (0.20, "#fff59d", "within 20 %"),
         (float("inf"), "#ffcdd2", "beyond 20 %"))


def headline_table(root, cases):
    """{case: {model: median headline error over the case's runs or None}}, the metric's name
    per case and the loaded metrics."""
    table, metric, data = {}, {}, {}
    for case in cases:
        d = json.loads((Path(root) / case / "metrics.json").read_text())
        # metrics written before the case framework lack "headline": the case declares it
        data[case], metric[case] = d, d.get("headline") or _declared_headline(case)
        table[case] = {}
        for model in d["parameters"]["models"]:
            vals = [r[metric[case]] for r in d["runs"] if r["model"] == model
                    and r.get(metric[case]) is not None]
            table[case][model] = float(np.median(vals)) if vals else None
    return table, metric, data


def _declared_headline(case):
    from .registry import CASES
    return CASES[case].headline.metric


def _band(v):
    return next(b for b in BANDS if v < b[0])


def conclusion(table, metric):
    """Five sentences from the scorecard."""
    models = sorted({m for row in table.values() for m in row})
    scores = {}
    for m in models:
        vals = [row[m] for row in table.values() if row.get(m) is not None and row[m] > 0]
        if vals:
            scores[m] = (float(np.exp(np.mean(np.log(vals)))), len(vals))
    out = []
    if scores:
        best = min(scores, key=lambda m: scores[m][0])
        worst = max(scores, key=lambda m: scores[m][0])
        out.append(f"Closest to the continuum overall: {best} (geometric mean of its headline "
                   f"errors {scores[best][0]:.3g} over {scores[best][1]} cases).")
        out.append(f"Farthest: {worst} ({scores[worst][0]:.3g}); the ranking of every model "
                   "is " + ", ".join(f"{m} {scores[m][0]:.3g}" for m in
                                     sorted(scores, key=lambda m: scores[m][0])) + ".")
    worst_case = {m: max(((row[m], c) for c, row in table.items() if row.get(m) is not None),
                         default=None) for m in models}
    out.append("Where each model fails worst: " + "; ".join(
        f"{m} in {wc[1]} ({metric[wc[1]]} {wc[0]:.3g})" for m, wc in worst_case.items()
        if wc) + ".")
    within = {c: [m for m, v in row.items() if v is not None and v < BANDS[0][0]]
              for c, row in table.items()}
    out.append("Cases where some model is within 5 % of FEM: " + (", ".join(
        f"{c} ({', '.join(ms)})" for c, ms in within.items() if ms) or "none") + "; where none "
        "is: " + (", ".join(c for c, ms in within.items() if not ms) or "none") + ".")
    missing = [(c, m) for c, row in table.items() for m, v in row.items() if v is None]
    out.append("Every model gave a headline number in every case." if not missing else
               "No headline number (every run failed): " + ", ".join(f"{m} in {c}"
                                                                     for c, m in missing) + ".")
    return out


def study_headlines(root, studies):
    """{study: its headline sentences} for the studies whose metrics.json is under ``root``."""
    from .registry import studies as declared
    out = {}
    for name in studies:
        path = Path(root) / name / "metrics.json"
        if path.is_file():
            out[name] = declared()[name].headline(json.loads(path.read_text()))
    return out


def index_documents(root, cases, studies=()):
    """The Markdown and HTML of reports/index: the studies' headlines first (the convergence
    study says whether the models converge at all), then the cases' conclusion and
    scorecard."""
    root = Path(root)
    table, metric, data = headline_table(root, cases)
    models = []
    for row in table.values():
        models += [m for m in row if m not in models]
    doc = Document("pbcm reports")
    for name, lines in study_headlines(root, studies).items():
        mode = " (quick mode)" if json.loads((root / name / "metrics.json").read_text())[
            "parameters"]["quick"] else ""
        doc.p(f"**{name}{mode}** ([report]({name}/report.md)): " + (lines[0] if lines else ""))
        for line in lines[1:]:
            doc.p(line)
    for line in conclusion(table, metric):
        doc.p(line)
    doc.h(2, "Scorecard")
    doc.p("Each cell is the median over the case's meshes and boundary conditions of its "
          "headline error against FEM (named under the case); colours in the HTML: "
          + ", ".join(f"{label}" for _, _, label in BANDS) + ". Quick-mode cases are marked.")
    rows = []
    for case in cases:
        mode = " (quick)" if data[case]["parameters"]["quick"] else ""
        row = [Link(case + mode, f"{case}/report.md", f"{case}/report.html"), metric[case]]
        for m in models:
            v = table[case].get(m)
            row.append("n/a" if v is None else Cell(f"{v:.3g}", _band(v)[1]))
        rows.append(row)
    doc.table(["case", "headline"] + models, rows)
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
