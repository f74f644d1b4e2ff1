"""reports/index: the scorecard (one population per row: a case's runs under one boundary
condition, its headline error and the metric paired with it, per model, coloured by band in
HTML) and a five-line conclusion written from the numbers."""
import json
import math
import re
from pathlib import Path

import numpy as np

from . import costs, scorecard
from .document import GLOSSARY, Cell, Document, Link, rel, rel_range
from ..measuring.error_model import JUDGES
from ..running.output import SWEEP_MARK

# headline error bands of the scorecard: within 5 %, within 20 %, beyond
BANDS = ((0.05, "#c8e6c9", "within 5 %"), (0.20, "#fff59d", "within 20 %"),
         (float("inf"), "#ffcdd2", "beyond 20 %"))




def _declared(case):
    from ..registry import CASES
    return CASES[case]


def populations(root, cases):
    """The scorecard's populations (``cases.reporting.scorecard``) of the cases' metrics under ``root``,
    and the loaded metrics."""
    data = {c: json.loads((Path(root) / c / "metrics.json").read_text()) for c in cases}
    declared = {c: _declared(c) for c in cases}
    pops = scorecard.populations(
        {c: d["runs"] for c, d in data.items()}, declared,
        {c: d["parameters"]["quick"] for c, d in data.items()},
        {c: set(d.get("patch_tests", declared[c].patch_tests)) for c, d in data.items()},
        {c: d.get("headline_estimate", declared[c].headline_estimate)
         for c, d in data.items()})
    return pops, data


def _band(v):
    return next(b for b in BANDS if v < b[0])


def _cell(p, model, part):
    """The scorecard cell of ``model`` in population ``p`` for one part of the error."""
    if model not in p.parts:
        return ""
    if part == "model_form" and model == p.quantity.p1:
        return Cell("FEM P1 itself (0 by construction)", BANDS[0][1])
    if part == "model_form" and model in p.identity:
        return Cell("identity check, P1's law here: " + scorecard.cell_of(
            p.errors(model, "model_form")), BANDS[0][1])
    rows = {s.model: (s, tie) for _, s, tie in p.standings(part)}
    s, tie = rows[model]
    text = scorecard.cell(s, tie if part == "model_form" and math.isfinite(s.score)
                          else None)
    lost = p.unpaired if part == "model_form" else p.unpaired_total
    if model in lost:
        text += f"; {lost[model]} of {p.quantity.count * s.runs} modes unpaired"
    colour = (BANDS[-1][1] if s.failed or not s.values or lost.get(model)
              else _band(float(np.median(s.values)))[1])
    return Cell(text, colour)


def scorecard_rows(pops, data, models):
    """Two rows per population: the model-form error (what replacing FEM P1 costs: what the
    scorecard ranks) and the total against the continuum; the shared discretisation error and
    the uncertainties in the row's own columns."""
    rows = []
    for p in pops:
        mode = " (quick)" if p.quick else ""
        label = p.label + mode + (" (patch test)" if p.patch_test else "") + (
            " (locking-prone: shown, not in the overall ranking)" if p.locking else "")
        disc = p.discretisation()
        law = "neo-Hookean" if p.finite else "linear"
        shared = (f"{rel(np.median(disc))} [{rel_range(min(disc), max(disc))}]" if disc
                  else "no P1 run")
        u_c = rel(p.u_continuum) + (" (spread over meshes exceeds the estimate)"
                                   if p.spread_defect else "") + (
            " (the estimate alone: each mesh its own continuum problem)" if p.per_mesh else "")
        rows.append([Link(label, f"{p.case}/report.md", f"{p.case}/report.html"),
                     f"{p.quantity.label}: model-form vs FEM P1 ({law})",
                     shared, f"{rel(p.u_model_form, 2)}"]
                    + [_cell(p, m, "model_form") for m in models])
        rows.append(["", f"{p.quantity.label}: total vs the continuum", "", u_c]
                    + [_cell(p, m, "total") for m in models])
    return rows


def conclusion(pops, models, quick):
    """The scorecard's closing lines: the ranking of model-form error in each regime (failed
    runs counted, ties named) and where each model is farthest from FEM P1."""
    out = []
    for finite, regime in ((False, "linear regime"), (True, "finite load")):
        means = scorecard.overall(pops, models, finite)
        if not means:
            continue
        n = len([p for p in pops if p.finite == finite and p.ranked])
        checked = [p.label for p in pops if p.finite == finite and scorecard.counts_failures(p)]
        loose = scorecard.unresolved(pops, models, finite)
        rng = scorecard.spread(pops, models, finite)
        if quick:
            out.append(f"Model-form ranking, {regime}: quick: not decided (run `pbcm report` "
                       "for every mesh).")
            continue
        first = scorecard.ranked(means)[0][1] if means else None
        reach = {b: mesh for b, mesh in scorecard.not_resolved_from(
            pops, models, first, finite).items() if (first, b) not in loose} if first else {}
        out.append(f"Model-form ranking, {regime}, over its {n} populations other than patch "
                   "tests, locking-prone problems and, at finite load, nearly linear loads"
                   + (f" (and, for failures alone, {', '.join(checked)})" if checked else "")
                   + " "
                   "(each model's "
                   "mean rank, a population ranking its models first by unpaired modes, then "
                   "by the median over the meshes with a failed run counted as infinitely "
                   "wrong, and, where a population's numbers are left out, by whether a model "
                   "fails its median there (a failure-only ranking); the geometric mean of its "
                   "scores beside it, each floored at the comparison's uncertainty; FEM P1 "
                   "itself is the identity check and not ranked; an order that reverses "
                   "when one mesh family or one case is left out is not resolved): " + "; ".join(
                       f"{rank}. {m} ({scorecard.describe(entry, rng.get(m))})"
                       + (f", the same mean rank as {tie}" if tie else "")
                       + "".join(f", not resolved from {b} (reverses without {mesh})"
                                 for (a, b), mesh in loose.items() if a == m)
                       # the first against each model that reaches it when a unit is left out
                       + "".join(f", not resolved from {b} (level or before it without "
                                 f"{mesh})" for b, mesh in reach.items() if m == first)
                       for rank, m, entry, tie in scorecard.ranked(means)) + ".")
    worst = {}
    # a quick run's farthest holds for its meshes only; a locking-prone population orders
    # closeness to a locked mesh
    for p in ([] if quick else pops):
        for _, s, _ in p.standings():
            # where FEM P1 locks only a failure at the median is the model's own
            if p.locking and not math.isinf(s.score):
                continue
            if s.runs and (s.model not in worst or s.score > worst[s.model][0]):
                worst[s.model] = (s.score, p)
    if quick:
        out.append("Where each model is farthest from FEM P1: quick: not decided (run `pbcm "
                   "report` for every mesh).")
    elif worst:
        out.append("Where each model is farthest from FEM P1 (median model-form error, a failed "
                   "run counted as infinitely wrong; locking-prone problems left out but for a failure at "
                   "the median): "
                   + "; ".join(
                       f"{m} in {p.label} ("
                       + ("failed at the median" if math.isinf(v) else rel(v)) + ")"
                       for m, (v, p) in worst.items()) + ".")
    # where the numbers are left out, a failure ranks only where it fails the model's median
    failed = [f"{s.model} in {p.label} ({s.failed} of {s.runs}"
              + ("" if p.ranked or p.patch_test else ", where the numbers are left out: "
                 + ("ranked" if scorecard.failure_ranks(p, s.model)
                    else "counted, below its median: no rank")) + ")"
              for p in pops for _, s, _ in p.standings() if s.failed]
    # against the continuum a run fails on its own too (a continuum mode left unpaired)
    total = [f"{s.model} in {p.label} ({s.failed} of {s.runs})" for p in pops
             for _, s, _ in p.standings("total") if s.failed]
    out.append("Failed runs (no model-form number, or a mode left unpaired), counted against "
               "their model: " + (", ".join(failed) if failed else "none")
               + "; against the continuum (the total): " + (", ".join(total) if total else "none")
               + ".")
    return out


# the run keys of the phases every ranking already counts; any other '<check>_failed' key is a
# case's own check (a homogeneous compression, say) whose failure no population shows
RANKED_FAILURES = ("failed", "static_failed", "finite_failed")


def failed_checks(data, studies=None):
    """'Failed checks ...: MODEL on CASE/MESH/BC (CHECK), ...' over the runs of every case in
    ``data`` ({case: metrics}): the failures of a case's own checks, which no ranking
    counts, named so that none is passed unread; or that none failed. ``studies`` ({study:
    (metrics, the keys holding its runs)}): the studies' failed runs, named after them."""
    bad = [f"{r['model']} on {case}/{r['mesh']}/{r['bc']} ({k[:-len('_failed')]})"
           for case, d in data.items() for r in d["runs"] for k in sorted(r)
           if k.endswith("_failed") and k not in RANKED_FAILURES and r[k]]
    # a run with a mode unpaired where the top is held (the paper cube's second modal
    # problem, against the continuum only): a failed run of that check, per case and model
    held = {}
    for case, d in data.items():
        for r in d["runs"]:
            if r.get("modes_unpaired_held") is not None:
                got = held.setdefault((case, r["model"]), [0, 0])
                got[0] += bool(r["modes_unpaired_held"])
                got[1] += 1
    bad += [f"{model} on {case}, {n} of {t} runs (modes with the top held: a mode unpaired)"
            for (case, model), (n, t) in held.items() if n]
    out = ("Failed checks outside the rankings (each a case's own check, named in its "
           "report): " + (", ".join(bad) if bad else "none") + ".")
    if studies:
        # a study may name its models for display ("names"), as its own report does
        runs = [(name, d, r) for name, (d, keys) in studies.items() for k in keys
                for r in d.get(k) or [] if r.get("failed")]
        # one entry per (study, model, cause), with the runs it holds: a cause that fails a
        # model everywhere is one fact, not one per mesh
        grouped = {}
        for name, d, r in runs:
            where = (f"{r['case']}/" if r.get("case") else "") + r["mesh"] + (
                f"/{r['bc']}" if r.get("bc") else "")
            grouped.setdefault((name, d.get("names", {}).get(r["model"], r["model"]),
                                _cause(r["failed"])), []).append(where)
        out += (" Failed runs of the studies (no number; each named in its report): "
                + ("; ".join(f"{model} on " + (
                    f"{name}/{wheres[0]}" if len(wheres) == 1 else
                    f"{name}, {len(wheres)} runs" + (
                        f" in {len(set(wheres))} places" if len(set(wheres)) < len(wheres)
                        else "") + f" ({_listed(wheres)})") + f" ({why})"
                    for (name, model, why), wheres in grouped.items())
                   if runs else "none") + ".")
    return out


def _cause(failed):
    """A failure's cause as the index groups it: its first clause without its parenthesised
    asides (the numbers, which differ from run to run of one cause; a name's own parentheses,
    'newton-xpbd(iterations=8)', stay)."""
    return re.sub(r"\s+\([^()]*\)", "", str(failed).split(";")[0])


def _listed(wheres, shown=6):
    """``wheres`` once each (two loads on one mesh and base are one place), the first
    ``shown`` of them and how many more."""
    w = list(dict.fromkeys(wheres))
    return ", ".join(w[:shown]) + (f" and {len(w) - shown} more" if len(w) > shown else "")


def index_documents(root, cases, studies=(), missing=()):
    """The Markdown and HTML of reports/index: the answers (``cases.reporting.answers``) and their
    table first, then the studies, the scorecard and its conclusion; ``missing``, the
    library's cases without a folder, named first (every answer is over the cases found)."""
    from . import answers
    from .report import read_study
    from ..registry import studies as declared
    root = Path(root)
    pops, data = populations(root, cases)
    models = []
    for case in cases:
        models += [m for m in data[case]["parameters"]["models"] if m not in models]
    quick = any(d["parameters"]["quick"] for d in data.values())
    doc = Document("pbcm reports")
    if missing:
        doc.p(f"Not run here (no folder): {', '.join(missing)}; every answer below is over "
              f"the cases found: {', '.join(cases)}.")
    for line in answers.lines(root, models, pops, quick):
        doc.p(line)
    header, rows = answers.table(root, models, pops, quick)
    doc.table(header, rows)
    kernels = costs.stale_words(costs.load(root))
    doc.p((f"The costs: {kernels[0].lower()}{kernels[1:]} " if kernels else "")
          + f"Definitions of every column and metric: [glossary]({GLOSSARY}).")
    shown = [n for n in studies if (root / n / "metrics.json").is_file()]
    if shown:
        doc.h(2, "Studies")
        doc.table(["study", "what it measures", "mode"], [
            [Link(n, f"{n}/report.md", f"{n}/report.html"), declared()[n].title,
             "quick" if json.loads((root / n / "metrics.json").read_text())["parameters"][
                 "quick"] else declared()[n].full_mode] for n in shown])
    doc.h(2, "Scorecard")
    doc.p("Two rows per case and boundary condition, on the one error model of the glossary: "
          "first each model's model-form error, what replacing FEM P1 (the same law on the "
          "same tetrahedra, the same constraints and load) by it costs, which the scorecard "
          "ranks; then its total error against the converged continuum. The column 'FEM P1 "
          "vs continuum' is the discretisation error the meshes themselves make, shared by "
          "every model on them; 'u_val' is the uncertainty a difference in the row is read "
          "against (model-form: the distance between FEM laws that coincide in the linear "
          "regime, FEM P1's own run against the twin a field is measured on, or the solver's "
          "tolerance; total: the reference's estimate and its spread "
          "over the meshes in quadrature, or the estimate alone where each mesh poses its "
          "own continuum problem). Each cell is the median over the meshes "
          "[smallest-largest], n of N runs; a failed run counts against its model; models "
          "within u_val of the first of the last group (tied), or beyond it but within both "
          "medians' spread over the meshes (not resolved), share its rank, and a cell names "
          "every model within either of any model, whatever its rank. Colours in "
          "the HTML: "
          + ", ".join(f"{label}" for _, _, label in BANDS) + ", red also for a failed run. "
          "Quick-mode cases are marked. The last rows are measured against reality (the "
          "Truth Cube's beads).")
    extra = [(n, r) for n in shown   # the studies' own rows: reality, today's engines
             for r in declared()[n].scorecard(json.loads((root / n / "metrics.json").read_text()))]
    # a model only a study measures (an engine) gets a column of its own, empty in the cases'
    # rows: the library's cases do not run it
    columns = models + [m for _, (_, _, cells, *_) in extra for m in cells if m not in models]
    columns = list(dict.fromkeys(columns))
    rows = [row + [""] * (len(columns) - len(models))
            for row in scorecard_rows(pops, data, models)]
    for n, (label, metric, cells, *shared) in extra:   # shared: (FEM P1 vs continuum, u_val)
        rows.append([Link(label, f"{n}/report.md", f"{n}/report.html"), metric,
                     *(shared[0] if shared else ("", ""))]
                    + [Cell(cells[m][0], BANDS[cells[m][1]][1]) if m in cells else ""
                       for m in columns])
    if len(columns) > len(models):
        doc.p(", ".join(columns[len(models):]) + ": measured by a study, on the meshes its "
              "rows name, not in the library's cases (their cells there are empty); their "
              "rows are the study's, at each model's default settings, and are not ranked "
              "with the cases'.")
    doc.table(["case/bc", "error", "FEM P1 vs continuum", "u_val"] + columns, rows, keys=4)
    recorded = {n: (read_study(root / n, declared()[n]), declared()[n].runs_recorded)
                for n in shown}
    for line in conclusion(pops, models, quick) + [failed_checks(data, recorded)]:
        doc.p(line)
    doc.p("Each case folder holds metrics.json, report.md, report.html and the figures; "
          "regenerate with `pbcm report`.")
    if sorted((root / "sweeps").glob(f"*/{SWEEP_MARK}")):
        doc.p("Sweeps (`pbcm sweep SPEC`, under sweeps/) are read by no verdict here: each is "
              "its own report, valid for the presets it ran.")
    return doc.markdown() + "\n", doc.html(root) + "\n"


# what the index's answer table and the studies call things, beside the catalogue's metrics
TERMS = {
    "model-form error": "what replacing FEM P1 by a model costs: (Q_model - Q_P1) / |Q_c| "
    "for a case's quantity Q (tip deflection, torque, reaction, punch force, settlement, force "
    "over the load steps), with FEM P1 the same law on the same tetrahedra under the same "
    "constraints and load (linear P1 in the linear regime, neo-Hookean P1 at finite load), "
    "Q_c the converged continuum's; the same quantity in both regimes: at a case's load "
    "(every case with a neo-Hookean reference, its population 'at the load') Q is measured "
    "on the finite-strain solve against neo-Hookean P1 and the neo-Hookean continuum, a run "
    "without an equilibrium a failed run; for the modes, the largest relative frequency "
    "error against P1's modes paired by shape, a run with an unpaired mode a failed run (its "
    "largest error is undefined). What the scorecard ranks (cases/measuring/error_model.py).",
    "discretisation error": "(Q_P1 - Q_c) / |Q_c|: how far FEM P1 on a mesh is from the "
    "converged continuum; the same for every model on that mesh.",
    "total error": "(Q_model - Q_c) / |Q_c| = model-form error + discretisation error for a "
    "scalar (over load steps each is its largest component, and the two parts bound the "
    "total); for a norm the parts bound the total by the triangle inequality; for the "
    "modes, paired by shape separately against P1 "
    "and against the continuum, they need not bound it. A small total with a large "
    "model-form error is two errors cancelling.",
    "u_val": "the validation uncertainty sqrt(u_num^2 + u_input^2 + u_D^2) (ASME V&V 20) a "
    "comparison is read against: u_num the reference's estimate and its spread over the meshes "
    "of one continuum problem, in quadrature (for a model-form error, the distance "
    "between FEM laws that coincide in the linear regime, FEM P1's own run against the "
    "twin a field is measured on, or the solver's tolerance), u_input "
    "the sensitivity to inputs nobody measured (0 for the library's cases: each poses its "
    "material and load exactly, so a model and FEM are compared on one stated problem and no "
    "input of it is unknown; the Truth Cube's plate friction, travel and nu), u_D the "
    "measurement's noise (0 where nothing is measured). Two errors closer than u_val are "
    "tied. On "
    "the Truth Cube, u_input is each unmeasured input's half range of the neo-Hookean "
    "continuum's bead RMS (plate friction, plate travel, nu), in quadrature, the same for "
    "every model (a model's own response beyond it, a P1 mesh locking, is its error), and "
    "u_D the beads' noise.",
    "mean rank": "a model's overall standing in one regime: the mean over the cases of its "
    "rank in each case (the mean over that case's populations, one per boundary condition: "
    "each case weighs one), each population ranking its models first by the parts they "
    "lost (unpaired "
    "modes), then by the median over the meshes with a failed run counted as infinitely "
    "wrong (so a failure never removes a population from anyone's comparison); a model within "
    "u_val of the first of the last group (tied), or within both medians' spread over the "
    "meshes beside it (not resolved), shares its rank (so no model ranks above one with a "
    "smaller median among those that lost as many modes); a failed run counts once, in its "
    "population's rank. A population whose numbers are left out of the ranking (locking-prone, "
    "or nearly linear at finite load; never a patch test) still enters it where a model fails "
    "its median there or loses a mode (a failure-only ranking): the models that did not fail "
    "share the first rank, the failing ones follow, and its case weighs one in the mean like "
    "any other; a model's failed runs there that leave its median to its numbers (fewer than "
    "half its runs) rank nothing and are counted against it only (marked 'counted only', or "
    "'counted, below its median: no rank'; those that rank, 'ranked'). Beside it the geometric mean over the cases of the population "
    "medians, each floored at its population's u_val, with its range over the rankings that "
    "leave one mesh family out; 'failed' where a population whose numbers rank failed at the "
    "median (no finite mean exists), with the mean over the others beside it (a population "
    "ranked for its failures alone adds no score to it).",
    "tied": "two errors whose difference is below the uncertainty of that difference, u_val "
    "(V&V 20); a difference beyond u_val but within both medians' spread over the meshes "
    "(half the range of the medians with one mesh left out, in quadrature with u_val) is "
    "not resolved, never a tie.",
    "not resolved": "what the data cannot establish, from one of two sources, each report "
    "naming which: an order of two models that reverses, or levels, when one mesh (a "
    "population's two medians within both medians' spread over the meshes), one mesh family "
    "(every population's runs on it) or one case is left out (the data cannot order them, "
    "whatever their mean ranks say; judged pair by pair, never chained through a third), "
    "unless the two compared directly (the geometric mean over the cases of their paired "
    "population errors' ratio) keep that order whatever is left out; or a "
    "value below what its uncertainty resolves (a convergence fit whose finest error is below "
    f"{JUDGES} times its reference's estimate; an artefact part within its u of 0). A reference "
    "too coarse to judge a case's differences is said as such, not with this word. The index "
    "judges its pooled order over the cases together, so a pair it resolves there may be "
    "not resolved in one case's population, as that case's report says. A rank column groups "
    "the sorted medians (a model shares the rank of the last group's first where it is not "
    "ordered from it, so no model ranks above one with a smaller median among those that "
    "lost as many modes, which rank first), while its notes "
    "name, pair by pair, every model it is not ordered from, which may sit in another rank: "
    "the rank is the order of the medians, the notes what the data leaves unordered. In one "
    "case's population the two tests differ: its cells use the medians' spread over the "
    "meshes, its opening's 'level with it without MESH' ranks again with each mesh left out, "
    "and may name a pair the cells do not.",
    "failed run": "the one meaning of 'failed' in every ranking, case table and answer: a run "
    "that gave no number (no equilibrium, at the load no converged solve, a metric undefined, "
    "a run that could not start; in the engines study, whose solvers are read at rest, a run "
    "that does not come to rest) or, for the modes, a run that leaves a mode unpaired (one "
    "failed run however many of its modes are unpaired; the unpaired modes are counted apart "
    "and ranked on first); a run fails in the comparison it is read in, so a run that pairs "
    "every mode with FEM P1's (model-form) may leave a continuum mode unpaired (total): it "
    "counts against its model, as infinitely wrong, in its "
    "population's median; the population stays in every other model's comparison. Two other "
    "states are said in their own words: a linearised growth rate above half the damping (the "
    "artefact study's stability call, made without a run) grows beyond the damping, which no "
    "run failed; a case's RK4 run that blows up gave no number, so it is a failed run of the "
    "dynamics (the RK4 run column says 'grows beyond the damping' where its growth rate "
    "explains it), counted outside the rankings. A model that 'fails' a patch test has a "
    "consistency error: a check's verdict on runs that gave numbers, not failed runs.",
    "consistency limit": "the error a model keeps under mesh refinement on a problem whose "
    "answer every consistent discretisation reproduces exactly: the converged limit of the "
    "sliding cube (a homogeneous compression, a patch test) in the linear regime, per "
    "lattice the larger of its displacement error e_inf and its stiffness error (the "
    "reaction ratio's limit's distance from 1; the top displacement is prescribed, so the "
    "displacement alone is blind to the stiffness), +- its extrapolation's uncertainty, "
    "named with which of the two it is; a stiffness error that grows at every refinement "
    "is at least its finest value (+- 1.25 x its last change); FEM's is zero to rounding (a "
    "stiffness error below the patch tolerance where every displacement error is at the "
    "reference's own level is that level: the nonlinearity left at the scaled load). The "
    "index's "
    "'how far from the continuum' reads these limits only. Two limits of one quantity "
    "(two displacement limits, or two stiffness limits) are tied when they "
    "differ by less than their +- combined, pair by pair (ties are not transitive), on the "
    "lattices; each model's families without a limit (diverging, or not asymptotic) are "
    "named beside it.",
    "worst isotropy error": "the largest relative error of the six Kelvin moduli of the "
    "model's effective elasticity tensor (a relaxed lattice patch) against the isotropic "
    "target's, over the lattices.",
    "alternation on the mirrored five split, 5-layer view, linear regime (signed, the larger "
    "over the bases; decides nothing)": "the alternation rel of the paper cube's runs on the "
    "mirrored five split (the paper's lattice), each model solved in the linear regime and "
    "scaled to the push (the artefact study reads it at the push itself), the larger in magnitude of its two bases, signed (positive: "
    "the paper's sign): the paper's own view on five layers, which cannot tell a smooth "
    "barrel from an alternation and decides nothing (the artefact study reads the cause on 9 "
    "and 17 layers).",
    "RK4 run": "grows beyond the damping when the linearised growth rate of the clamped "
    "paper cube exceeds half the mass damping (so that the damped RK4 run grows), else stable "
    "under the damping (a positive growth below it, a flutter, is damped out; the paper cube's "
    "metrics.json records a growth above it as its dyn_verdict 'unstable (flutter)'); the "
    "mass damping is ours, stated in the paper cube's report (the paper "
    "states none).",
    "CPU s per simulated s": "CPU seconds one simulated second costs at the model's own stable "
    "RK4 step (undamped), from `pbcm bench`: in the index at about 1e4 tetrahedra, in a case's "
    "cost table at the bench size nearest the case's meshes; beside it the ratio to "
    "fem-linear's: the median over the bench's rounds of the step-time ratio taken within "
    "each round, times the ratio of the stable steps, with its range over the rounds (not the "
    "ratio of the two median times, which the rounds' drift moves), then those two factors "
    "apart (a model cheap per simulated second by a larger stable step has not a cheaper "
    "step); the seconds themselves are the bench's median round, with the rounds' range where "
    "the bench recorded it. Not "
    "the wall s per simulated s.",
    "wall s per simulated s": "wall-clock seconds one simulated second takes in the real-time "
    "study, under the paper's push on the named mesh, in the model's faster mode (serial or "
    "two threads), median [smallest-largest] over the bench's timing rounds: what real time "
    "(at most 1) is judged on; not the summary table's CPU s per simulated s, which is one "
    "core's at the bench's 1e4 cube.",
    "calibrated / literal": "a shear reading with c fitted so that its deviatoric moduli are "
    "closest to 2G (calibrated), or with the paper's c = 1 (literal).",
    "patch test": "a problem with a homogeneous exact answer that a consistent "
    "discretisation reproduces on any mesh, in two forms named apart: the sliding cube (a "
    "case's boundary conditions; its error under refinement gives the consistency limit) and "
    "the patch test with every boundary node prescribed (the convergence study's patch_error, "
    "on regular and irregular patches); a model that fails either has a consistency error.",
    "population": "the runs of one case under one boundary condition: what a median, a range "
    "or a criterion is taken over (never pooled across populations).",
    "identity check": "a comparison whose answer is known to be zero by construction (FEM P1 "
    "against itself; the FEM laws in the linear regime, where they coincide with P1's; FEM "
    "P1 on a patch test it reproduces exactly): it tests the pipeline, never ranks a model.",
    "unit of analysis": "what an order must survive losing: in the scorecard and the case "
    "reports, the mesh family (leaving one out tests whether an order holds); the artefact "
    "study calls its (mesh size, base) cells configurations, not units.",
    "leak": "how much of a smooth test field (a barrel, a Gaussian bulge) the period-2 "
    "signature reads as alternation on a given number of layers; a signature below the leak "
    "of smooth fields is not resolved.",
    "model names": "pbcm-corner, pbcm-balanced, pbcm-variational: the paper's shear term "
    "under three readings of its garbled equations, with the volume term, their constant c "
    "fitted so that the deviatoric moduli are closest to 2G; -literal: c = 1, the paper's "
    "constant; pbcm-variational+normal: pbcm-variational plus the deviatoric normal-stress "
    "term on the edge strains at each corner (registered as normal, also named normal_edge), "
    "its constant fitted the same way; msm: springs on the mesh edges with van Gelder's "
    "stiffness E sum V0 / L^2, a fixed rule, not fitted (its Poisson ratio is 1/4 whatever "
    "nu is asked for); msm+volume: those springs plus the paper's volume term; fem-linear, "
    "fem-corotated, fem-neohookean: explicit FEM P1 with lumped mass and the named law.",
}


def glossary_documents():
    """The Markdown and HTML of reports/glossary: the index's terms, then every metric of the
    catalogue (label, name, unit, definition), written once for every report to link to."""
    from ..measuring import catalogue
    doc = Document("pbcm glossary")
    doc.h(2, "Terms")
    doc.ul(f"{k}: {v}" for k, v in TERMS.items())
    from ..registry import studies
    for name, study in studies().items():
        if study.definitions():
            doc.h(2, f"The {name} study")
            doc.ul(study.definitions())
    doc.h(2, "Metrics")
    doc.table(["label", "name", "unit in metrics.json", "definition"],
              [[m.label, m.name, (f"{m.unit} (tables: {m.shown[0]})" if m.shown else m.unit),
                m.definition]
               for m in sorted(catalogue.CATALOGUE.values(), key=lambda m: m.name)])
    return doc.markdown() + "\n", doc.html(".") + "\n"


def write_index(root, cases, studies, missing=()):
    """index.md/.html and glossary.md/.html under ``root``, each written atomically;
    ``missing``: the library's cases with no folder there (named in the index)."""
    from ..running.output import write_atomic
    root = Path(root)
    md, html = index_documents(root, cases, studies, missing)
    write_atomic(root / "index.md", md)
    write_atomic(root / "index.html", html)
    md, html = glossary_documents()
    write_atomic(root / "glossary.md", md)
    write_atomic(root / "glossary.html", html)
    return root / "index.md"
