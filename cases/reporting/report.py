"""Write a case's results: metrics.json, report.md/.html, PNG figures and .vtu states. The
layout is the same for every case (conclusion, what was run, definitions, grouped findings, one
table per mesh and boundary condition, figures); what is particular to a case comes from its
hooks (``cases.framework.Case``)."""
import datetime
import json
import platform
import subprocess
from pathlib import Path

import numpy as np

from model.compose import slug
from model.mesh import write as write_mesh
from . import costs, figures
from .document import Document, fmt, rel
from ..measuring import catalogue
from . import rankings
from . import scorecard
from ..running.runner import jsonable

TIMING_KEYS = ("dyn_wall_s",)   # wall times: in run.json, never in metrics.json

def environment():
    import numba
    import scipy
    import skfem
    return {"python": platform.python_version(), "numpy": np.__version__,
            "scipy": scipy.__version__, "numba": numba.__version__,
            "scikit-fem": getattr(skfem, "__version__", "unknown")}


def provenance(runs):
    """What changes from run to run although the results do not: the commit, the date and
    the wall times. It goes to run.json, which git ignores, so that rerunning an unchanged
    case leaves the committed report untouched."""
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                                cwd=Path(__file__).parent, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        commit = ""
    return {"git_commit": commit or "unknown",
            "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "timings": [{"mesh": r["mesh"], "bc": r["bc"], "model": r["model"],
                         **{k: r[k] for k in TIMING_KEYS if k in r}} for r in runs]}


def rows_json(rows):
    """A list of records as JSON, one compact record per line: a large record stays small
    and a change to one row is one changed line."""
    return "[\n" + ",\n".join(json.dumps(r, separators=(",", ":")) for r in rows) + "\n]\n"


def read_study(folder, study):
    """A study's record in ``folder``: its metrics.json with each of its ``record_files``
    read back under its key."""
    folder = Path(folder)
    metrics = json.loads((folder / "metrics.json").read_text())
    for k in study.record_files:
        metrics[k] = json.loads((folder / f"{k}.json").read_text())
    return metrics


def write_study(out, metrics, make_document, apart=()):
    """A study's folder ``out``: ``metrics`` as metrics.json, less each list it keeps
    ``apart`` (written as KEY.json, one record per line: the study's ``record_files``),
    run.json (the commit and the date; no timings) and the report ``make_document(out)``
    draws (its figures into ``out``)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for k in apart:
        (out / f"{k}.json").write_text(rows_json(metrics[k]))
    kept = {k: v for k, v in metrics.items() if k not in apart}
    (out / "metrics.json").write_text(json.dumps(kept, indent=1) + "\n")
    prov = provenance([])
    prov.pop("timings")
    (out / "run.json").write_text(json.dumps(prov, indent=1) + "\n")
    make_document(out).write(out)
    return out


def metrics_document(case, s, runs, extra=None):
    """The metrics.json content of a case run: the parameters, the problem the gate compares,
    the gated metrics with their direction, the runs, and what the case adds (``extra``)."""
    return jsonable({"case": case.name, "parameters": s.describe(), "problem": s.problem(),
                     "params": case.params(s), "gated": {**catalogue.STANDARD_GATED,
                                                          **catalogue.gated(*case.gated)},
                     "headline": case.headline, "headline_pair": case.headline_pair,
                     "headline_estimate": case.headline_estimate,
                     "patch_tests": list(case.patch_tests), **(extra or {}),
                     "environment": environment(),
                     "runs": [{k: v for k, v in r.items() if k not in TIMING_KEYS} for r in runs]})


def reference_summary(case, s, runs):
    """``reference`` (the FEM quantities of the first (mesh, bc) run, with its error estimate),
    ``references`` (every (mesh, bc)) and ``closed_form`` (per bc) for metrics.json."""
    refs = []
    for r in runs:
        key = {"mesh": r["mesh"], "bc": r["bc"]}
        if r.get("failed") or key in [{"mesh": x["mesh"], "bc": x["bc"]} for x in refs]:
            continue
        fem = {k: v for k, v in r.items() if "_fem" in k}
        refs.append({**key, **fem, "p2_error_estimate": r["p2_error_estimate"]})
    closed = {bc: case.closed_form(s, bc) for bc in s.bcs}
    first = dict(refs[0]) if refs else {}
    reference = {k.replace("_fem", ""): v for k, v in first.items()}
    return {"reference": reference, "references": refs,
            "closed_form": {bc: v for bc, v in closed.items() if v}
            if len(s.bcs) > 1 else closed.get(s.bcs[0], {})}


def write_case(out, case, s, runs, fields):
    """Write everything for ``case`` into the folder ``out`` (created)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "vtu").mkdir(exist_ok=True)
    data = metrics_document(case, s, runs, reference_summary(case, s, runs))
    (out / "metrics.json").write_text(json.dumps(data, indent=1) + "\n")
    (out / "run.json").write_text(json.dumps(jsonable(provenance(runs)), indent=1) + "\n")
    for (mesh, bc, model), f in fields.items():
        cdata = {k: f[k] for k in ("max_tau", "pressure") if k in f}
        write_mesh(out / "vtu" / f"{mesh}_{bc}_{slug(model)}.vtu", f["mesh"],
                   point_data={"displacement": f["u"]}, cell_data=cdata)
    build_report(case, s, runs, fields, out).write(out)
    return out


def _runs(runs, **kw):
    return [r for r in runs if all(r.get(k) == v for k, v in kw.items())]


def _constants(runs):
    """One line per model with calibrated constants: its c on each mesh (``c = "auto"`` is
    fitted per lattice, every reading alike: model.calibrate)."""
    by = {}
    for r in runs:
        info = r.get("model_info") or {}
        cs = {k: v for k, v in info.items() if k.endswith("_c") and isinstance(v, float)}
        if cs:
            by.setdefault(r["model"], {})[r["mesh"]] = cs
    return [f"Constants of {m}: " + "; ".join(
        f"{mesh} " + ", ".join(f"{k} = {fmt(v, 4)}" for k, v in cs.items())
        for mesh, cs in meshes.items()) + "." for m, meshes in by.items()]


# finding groups a quick run states as the full run does (facts of its runs, not orders):
# what the bench measured, the runs that failed or could not start
QUICK_AS_FULL = ("Cost", "Failures", "Runs that could not start")


def build_report(case, s, runs, fields, out):
    doc = Document(f"pbcm report: {case.name}")
    story = case.story()
    ok = [r for r in runs if not r.get("failed")]
    opening, costs_of_replacing = [], []
    if case.decompositions():
        opening, costs_of_replacing = scorecard.case_findings(
            case.name, case.decompositions(), runs, case.patch_tests, case.headline_estimate,
            case.per_mesh_continuum, case.locking_prone)
    lines = opening + story.conclusion(s, runs)
    preview = []
    if s.quick:     # a preview on fewer meshes: it decides nothing the full run could reverse
        preview, lines = lines, [
            f"Quick: not decided (`{story.command()}` decides, on every mesh): a preview on "
            f"{', '.join(s.meshes)}, whose findings below measure these meshes and decide "
            "nothing."]
    doc.opening(lines, story.glossary)
    doc.p("Generated by `pbcm` from the runs recorded in metrics.json; every number below was "
          "computed by the run that wrote this file, but the cost, which is `pbcm bench`'s "
          "(reports/bench).")
    doc.h(2, "What was run")
    doc.ul([case.title + "."] + story.what_was_run(s, runs) + [
        f"Meshes {', '.join(s.meshes)}; boundary conditions {', '.join(s.bcs)}; models "
        f"{', '.join(s.models)}.",
        f"Material E = {s.E:g} Pa, nu = {s.nu:g}, rho = {s.rho:g} kg/m^3 "
        f"({story.material_from}).",
        story.references_line(s),
        "Quick mode." if s.quick else "Full mode."] + _constants(runs))
    notes = story.notes_for(s)
    if notes:
        doc.h(2, "Notes")
        doc.ul(notes)
    failed = [r for r in runs if r.get("failed")]
    groups = {"What these meshes show": preview} if preview else {}
    if costs_of_replacing:
        groups["What replacing FEM P1 costs"] = costs_of_replacing
    groups.update(story.findings(s, ok))
    groups.update(rankings.finite_load(ok))
    tets = [r["tets"] for r in runs if r.get("tets")]
    groups["Cost"] = groups.get("Cost", []) + costs.cost_items(
        costs.load(Path(out).parent), s.models,
        float(np.median(tets)) if tets else 1e3)
    if failed:
        groups["Runs that could not start"] = sorted({f"{r['mesh']}/{r['bc']}: {r['failed']}"
                                                      for r in failed})
    doc.h(2, "Findings" + (" (a quick preview: decides nothing)" if s.quick else ""))
    for title, items in groups.items():
        if items:
            # a quick run's orders and verdicts are these meshes' only: each says so where
            # it is read, not once above (the full run can reverse any of them)
            doc.h(3, title + (f" (on mesh{'es' if len(s.meshes) > 1 else ''} "
                              f"{', '.join(s.meshes)} only; quick: not decided, "
                              f"`{story.command()}` decides)"
                              if s.quick and title not in QUICK_AS_FULL else ""))
            doc.items(items)
    _tables(doc, case, s, runs)
    story.sections(doc, s, runs, fields, out)
    _standard_figures(doc, case, story, s, runs, fields, out)
    return doc


def _tables(doc, case, s, runs):
    shown = [catalogue.metric(n) for n in catalogue.TABLE + case.columns]
    cell = case.story().cell
    for mesh in s.meshes:
        for bc in s.bcs:
            rs = [r for r in _runs(runs, mesh=mesh, bc=bc) if not r.get("failed")]
            if not rs:
                continue
            doc.h(2, f"Mesh {mesh}, {bc}")
            line = f"{rs[0]['nodes']} nodes, {rs[0]['tets']} tetrahedra"
            if rs[0].get("reaction_fem_p2_n") is not None:
                line += f"; FEM P2 reaction {fmt(rs[0]['reaction_fem_p2_n'], 4)} N"
            doc.p(line + f"; P2 reference error estimate {rel(rs[0]['p2_error_estimate'], 2)}.")
            if rs[0].get("linear_scale") is not None:
                doc.p(f"Linear regime: the loads times {fmt(rs[0]['linear_scale'], 3)} (largest "
                      "strain of the linear reference 1e-4), each model's answer divided by "
                      "it again, against linear FEM:")
            doc.table(["model"] + [m.header for m in shown],
                      [[r["model"]] + [cell(m, r) for m in shown] for r in rs])
            _finite_table(doc, case, rs)
            bad = [r for r in rs if r["static_failed"]]
            if bad:
                doc.p("No equilibrium in the linear regime (its metrics are n/a): " + "; ".join(
                    f"{r['model']}: {r['static_failed']}" for r in bad) + ".")


def _finite_table(doc, case, rs):
    """The (mesh, bc)'s runs at the case's load against the neo-Hookean reference."""
    if rs[0].get("nh_error_estimate") is None:
        return
    shown = [catalogue.metric(n) for n in catalogue.FINITE]
    cell = case.story().cell
    line = (f"At the case's load, against the neo-Hookean reference (error estimate "
            f"{rel(rs[0]['nh_error_estimate'], 2)}")
    if rs[0].get("reaction_fem_nh_n") is not None:
        line += f", reaction {fmt(rs[0]['reaction_fem_nh_n'], 4)} N"
    doc.p(line + "):")
    doc.table(["model"] + [m.header for m in shown],
              [[r["model"]] + [cell(m, r) for m in shown] for r in rs])
    bad = [r for r in rs if r.get("finite_failed")]
    if bad:
        doc.p("No equilibrium at the case's load (its metrics are n/a): " + "; ".join(
            f"{r['model']}: {r['finite_failed']}" for r in bad) + ".")


def _standard_figures(doc, case, story, s, runs, fields, out):
    """The headline error of every run as bars per (mesh, bc), and the max |tau| panels of
    the first (mesh, bc) for cases that draw none of their own."""
    keys = [(m, b) for m in s.meshes for b in s.bcs
            if any(not r.get("failed") for r in _runs(runs, mesh=m, bc=b))]
    if not keys:
        return
    metric = case.headline
    doc.h(2, "Headline error")
    figures.grouped_bars(out / "errors.png", [f"{m}/{b}" for m, b in keys], s.models,
                         [[_chart_value(runs, m, b, mo, metric) for mo in s.models]
                          for m, b in keys], f"{metric}", catalogue.metric(metric).label, log=True)
    doc.img("errors.png", f"{catalogue.metric(metric).label} ({metric}) per run")
    for m, b in [k for k in keys if (*k, "fem-p2") in fields][:1]:
        if story.draws_stress:
            break
        panels = [("FEM P2", fields[(m, b, "fem-p2")]["mesh"], fields[(m, b, "fem-p2")]["u"],
                   fields[(m, b, "fem-p2")]["max_tau"])]
        panels += [(mo, fields[(m, b, mo)]["mesh"], fields[(m, b, mo)]["u"],
                    fields[(m, b, mo)]["max_tau"]) for mo in s.models if (m, b, mo) in fields]
        name = f"stress_{m}_{b}.png"
        figures.stress_panels(out / name, panels, f"max |tau|, mesh {m}, {b}",
                              story.magnify, up=story.up)
        doc.img(name, f"Deformed shape and max |tau|: mesh {m}, {b}")


def _chart_value(runs, mesh, bc, model, metric):
    """A run's metric for a chart: NaN (nothing drawn) where the run could not give it."""
    rs = _runs(runs, mesh=mesh, bc=bc, model=model)
    return float("nan") if not rs or rs[0].get(metric) is None else rs[0][metric]
