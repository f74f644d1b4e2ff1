"""The extensions study's files: metrics.json (case rows, fits, tensors, costs, rankings,
failures and the rows the gate reads), report.md/.html and the figures. Every sentence is
computed from the data it is written with."""
from pathlib import Path

import numpy as np

from ...measuring import catalogue
from ...reporting.document import Document, fmt
from ...reporting import figures
from ...reporting.report import environment, write_study
from ...running.runner import jsonable
from ...reporting.costs import COST_TETS
from .study import BASE, TWIN, YARDSTICK, CANDIDATES, conv_fits, short

GATED = catalogue.gated("error", "alternation_max_rel", "e_inf", "moduli_rel_err")
FEM_FACTOR = 1.5      # a model-form error this many times FEM P1's discretisation error fails
ISOTROPIC_TOL = 0.01  # a C_eff modulus this far from the target's: the lattice is not it
CHANGE = 0.25         # a relative change below this is "no change"


# ---------------------------------------------------------------------- rankings
def _median(values):
    v = [x for x in values if x is not None]
    return float(np.median(v)) if v else None


def _population(r):
    """The aggregate a run belongs to: its case under its boundary condition (a patch test
    and a clamped cube are never pooled)."""
    return f"{r['case']}/{r['bc']}"


def _runs_of(data, pop):
    return [r for r in data["case_runs"] if _population(r) == pop]


def _ok(r):
    return not r["failed"] and r["error"] is not None


def excluded(data, models):
    """{case/bc: ['mesh', ...]} where no model of the study has a result (a reference or a
    load the mesh cannot take): left out of every comparison, and said."""
    out = {}
    for pop in dict.fromkeys(_population(r) for r in data["case_runs"]):
        meshes = dict.fromkeys(r["mesh"] for r in _runs_of(data, pop))
        out[pop] = [m for m in meshes if not any(
            _ok(r) for r in _runs_of(data, pop) if r["mesh"] == m and r["model"] in models)]
    return out


def case_errors(data, models, without=None):
    """{case/bc: {model: median model-form error}} over the meshes where some model has a
    result (``excluded`` are left out, and the mesh family ``without``); None for a model
    that failed on one of them, so the others are compared on the same meshes."""
    gone = excluded(data, models)
    out = {}
    for pop in dict.fromkeys(_population(r) for r in data["case_runs"]):
        rs = [r for r in _runs_of(data, pop) if r["model"] in models
              and r["mesh"] not in gone[pop] and r["mesh"] != without]
        out[pop] = {}
        for m in models:
            mine = [r for r in rs if r["model"] == m]
            out[pop][m] = None if not mine or not all(_ok(r) for r in mine) else _median(
                r["error"] for r in mine)
    return out


def discretisation(data):
    """{case/bc: FEM P1's discretisation error on the case's quantity, median over the
    meshes} (the same for every model on a mesh; None where no run has it)."""
    out = {}
    for pop in dict.fromkeys(_population(r) for r in data["case_runs"]):
        per_mesh = {}
        for r in _runs_of(data, pop):
            if r.get("discretisation") is not None:
                per_mesh.setdefault(r["mesh"], r["discretisation"])
        out[pop] = _median(per_mesh.values())
    return out


def pooled(pop):
    """Whether the overall mean pools the population ``case/bc``: neither a patch test (pass
    or fail, never pooled with the rest) nor locking-prone (its model-form error ranks
    closeness to a locked mesh), as the case declares it."""
    from ...registry import CASES
    case, _, bc = pop.partition("/")
    c = CASES.get(case)
    return c is None or (bc not in c.patch_tests and bc not in c.locking_prone)


def _complete(errors):
    """The pooled populations where the paper model has a nonzero result (the ratios' base);
    a candidate's failure there stays in (``_gmean``)."""
    return [e for pop, e in errors.items() if pooled(pop) and e.get(BASE)]


def _gmean(m, es):
    """The geometric mean of ``m``'s errors over the paper model's; 0 where ``m`` has no
    error in some population (FEM P1 against itself), never a mean over its nonzero ones;
    None where ``m`` failed in one (a failure is never left out)."""
    if not es or any(e.get(m) is None for e in es):
        return None
    r = [e[m] / e[BASE] for e in es]
    return 0.0 if min(r) == 0 else float(np.exp(np.mean(np.log(r))))


def overall(errors, models):
    """The geometric mean, over the pooled populations where the paper model has a result,
    of each model's error over the paper model's (below 1: better than the paper's model);
    None for a model that failed in one of them (``overall_failed`` counts them)."""
    complete = _complete(errors)
    return {m: _gmean(m, complete) for m in models}


def overall_failed(errors, models):
    """{model: the pooled populations where it has no result though the paper model has}."""
    complete = _complete(errors)
    return {m: sum(e.get(m) is None for e in complete) for m in models}


def overall_range(errors, models, data=None):
    """{model: [low, high]}: the geometric mean leaving one population out, or (with the
    runs ``data``) one mesh family out of every population, its lowest and highest (a
    ranking one population or one mesh family decides is no ranking)."""
    complete = _complete(errors)
    families = sorted({r["mesh"] for r in (data or {}).get("case_runs", [])})
    by_family = [_complete(case_errors(data, models, without=f)) for f in families]
    out = {}
    for m in models:
        loo = [v for v in [_gmean(m, complete[:k] + complete[k + 1:])
                           for k in range(len(complete))]
               + [_gmean(m, es) for es in by_family] if v is not None]
        out[m] = [min(loo), max(loo)] if loo else None
    return out


def identical(errors, models, digits=3):
    """[[model, ...]]: groups of models whose errors agree to ``digits`` significant figures
    in every pooled population (one observation of the overall mean, not several)."""
    def key(m):
        return tuple(None if e.get(m) is None else float(f"{e[m]:.{digits}g}")
                     for pop, e in errors.items() if pooled(pop))
    groups = {}
    for m in models:
        groups.setdefault(key(m), []).append(m)
    return [g for g in groups.values() if len(g) > 1]


def alternations(data, models):
    """Each model's largest |alternation| (relative) over its paper-cube runs: the artefact
    is there if it shows on any mesh and base, not on their median (None without a run)."""
    rs = [r for r in data["case_runs"] if r["case"] == "paper-cube"]
    out = {}
    for m in models:
        v = [abs(r["alternation_rel"]) for r in rs
             if r["model"] == m and r.get("alternation_rel") is not None]
        out[m] = max(v) if v else None
    return out


STOPS = ("floor", "diverges")


SLIDING = ("paper-cube", "sliding")     # the convergence study's patch test (the consistency)


def floors(data, models):
    """Per model: the convergence verdicts over the (problem, family) fits, the range of its
    floors (each e_inf -+ its fit's +-; floors of different problems are different quantities,
    so never a median over them) and the largest, and each fit's verdict and e_inf by
    'problem/bc on family'."""
    out = {}
    for m in models:
        fs = [f for f in data["fits"] if f["model"] == m]
        # over the floors alone: a limit of another verdict is no floor
        fl = [f for f in fs if f["verdict"] == "floor" and f.get("e_inf") is not None]
        out[m] = {"floor": sum(f["verdict"] == "floor" for f in fs),
                  "diverges": sum(f["verdict"] == "diverges" for f in fs),
                  "fits": len(fs),
                  "e_inf": max((f["e_inf"] for f in fl), default=None),
                  "range": [max(0.0, min(f["e_inf"] - (f.get("e_inf_err") or 0.0) for f in fl)),
                            max(f["e_inf"] + (f.get("e_inf_err") or 0.0) for f in fl)]
                  if fl else None,
                  "by_fit": {f"{f['case']}/{f['bc']} on {f['mesh']}":
                             [f["verdict"], f["e_inf"], f.get("e_inf_err")] for f in fs},
                  # the sliding cube's stiffness limit, which its displacement (the top
                  # prescribed) is blind to: |ratio_inf - 1| and its fit's +-
                  "stiffness": {f"{f['case']}/{f['bc']} on {f['mesh']}":
                                [abs(f["ratio_inf"] - 1.0), f.get("ratio_inf_err") or 0.0]
                                for f in fs if (f["case"], f["bc"]) == SLIDING
                                and f.get("ratio_inf") is not None}}
    return out


def tensors(data, models):
    """{model: {lattice: the largest relative error of C_eff's moduli}}."""
    return {m: {e["mesh"]: e.get("moduli_rel_err") for e in data["elasticity"]
                if e["model"] == m}
            for m in models}


def rankings(data, models):
    errors = case_errors(data, models)
    return {"case_errors": errors, "excluded": excluded(data, models),
            "discretisation": discretisation(data),
            "overall": overall(errors, models),
            "overall_range": overall_range(errors, models, data),
            "overall_over": len(_complete(errors)),
            "overall_failed": overall_failed(errors, models),
            "left_out": [p for p in errors if not pooled(p)],
            "identical": identical(errors, models),
            "alternation": alternations(data, models),
            "floors": floors(data, models),
            "tensors": tensors(data, models), "cost": data["cost_vs_fem_linear"],
            "cost_tets": data.get("cost_tets"), "cost_range": data.get("cost_range") or {}}


def order(values):
    """Models by value, smallest first, those without a value last."""
    return sorted(values, key=lambda m: (values[m] is None, values[m] if values[m] is not None
                                         else 0.0))


# ---------------------------------------------------------------------- failures and fixes
def failures(rank):
    """The paper model's failures, each with the criterion it fails: {what, kind, key, base,
    limit}."""
    out = []
    for case, e in rank["case_errors"].items():
        fem = rank.get("discretisation", {}).get(case)
        if e.get(BASE) is None:
            out.append({"what": f"{case}: failed", "kind": "case", "key": case, "base": None,
                        "limit": None})
        elif fem is not None and e[BASE] > FEM_FACTOR * fem:
            out.append({"what": f"{case} model-form error",
                        "note": f"FEM P1's discretisation error: {fmt(fem)}",
                        "kind": "case", "key": case, "base": e[BASE], "limit": FEM_FACTOR * fem})
    # the paper cube's alternation is its 5-layer view, which decides nothing (the artefact
    # study decides on finer meshes): shown in the table, never a criterion
    for key, (v, e_inf, err) in rank["floors"].get(BASE, {}).get("by_fit", {}).items():
        if v in STOPS:
            out.append({"what": f"convergence of {key}", "note": v, "kind": "floor",
                        "key": key, "base": e_inf, "base_err": err, "limit": None})
    for key, (d, err) in rank["floors"].get(BASE, {}).get("stiffness", {}).items():
        if d - err > ISOTROPIC_TOL:
            out.append({"what": f"stiffness of {key}", "kind": "stiffness", "key": key,
                        "note": f"|reaction ratio limit - 1|, +- {fmt(err)}", "base": d,
                        "limit": ISOTROPIC_TOL})
    for lattice, d in rank["tensors"].get(BASE, {}).items():
        if d is not None and d > ISOTROPIC_TOL:
            out.append({"what": f"C_eff on {lattice}", "kind": "tensor", "key": lattice,
                        "base": d, "limit": ISOTROPIC_TOL})
    return out


def new_failures(rank, model):
    """The criteria ``model`` fails where the paper's model meets them (a stiffness beyond the
    tolerance past its +- where the paper's is within it past its own, a C_eff beyond the
    tolerance, a fit that stops at a floor or diverges where the paper's model's converges),
    each 'what value'."""
    mine, base = rank["floors"].get(model, {}), rank["floors"].get(BASE, {})
    out = []
    for key, (d, err) in mine.get("stiffness", {}).items():
        b = base.get("stiffness", {}).get(key)
        # a pass of the paper's model its own +- cannot support is no contrast
        if d - err > ISOTROPIC_TOL and (b is None or b[0] + b[1] <= ISOTROPIC_TOL):
            out.append(f"stiffness of {key} {fmt(d)} +- {fmt(err)}")
    for key, (v, e_inf, err) in mine.get("by_fit", {}).items():
        b = base.get("by_fit", {}).get(key)
        if v in STOPS and b is not None and b[0] in ("converges", "exact"):
            out.append(f"convergence of {key} ({v}" + (f", e_inf {fmt(e_inf)} +- {fmt(err)}"
                                                       if e_inf is not None else "") + ")")
    for lattice, d in rank["tensors"].get(model, {}).items():
        b = rank["tensors"].get(BASE, {}).get(lattice)
        if d is not None and d > ISOTROPIC_TOL and b is not None and b <= ISOTROPIC_TOL:
            out.append(f"C_eff on {lattice} {fmt(d)}")
    return out


def value(rank, failure, model):
    k = failure["kind"]
    if k == "case":
        return rank["case_errors"][failure["key"]].get(model)
    if k == "alternation":
        return rank["alternation"].get(model)
    if k == "floor":
        fit = rank["floors"].get(model, {}).get("by_fit", {}).get(failure["key"])
        return None if fit is None else fit[1]
    if k == "stiffness":
        st = rank["floors"].get(model, {}).get("stiffness", {}).get(failure["key"])
        return None if st is None else st[0]
    return rank["tensors"].get(model, {}).get(failure["key"])


def verdict(failure, v):
    """'fixes' (meets the criterion), 'improves', 'worsens' (by CHANGE or more), 'no change',
    or 'fails' (no value)."""
    if v is None:
        return "fails"
    if failure["limit"] is not None and v <= failure["limit"]:
        return "fixes"
    if failure["base"] is None:
        return "runs"
    if v <= (1 - CHANGE) * failure["base"]:
        return "improves"
    if v >= (1 + CHANGE) * failure["base"]:
        return "worsens"
    return "no change"


def cell(rank, failure, model, v):
    """The text of a value: a convergence failure's is the candidate's fit verdict."""
    if failure["kind"] == "floor":
        fit = rank["floors"].get(model, {}).get("by_fit", {}).get(failure["key"])
        if fit is None:
            return "no fit"
        # a fit without a limit (diverging, not asymptotic) has no e_inf to print
        return fit[0] + (f", e_inf {fmt(fit[1])} +- {fmt(fit[2])}" if fit[1] is not None
                         else "")
    return fmt(v)


def judge(rank, failure, model):
    """(value, verdict) of ``model`` on a failure of the base; a convergence floor is fixed
    where the model's fit converges (or is exact)."""
    v = value(rank, failure, model)
    if failure["kind"] == "floor":
        fit = rank["floors"].get(model, {}).get("by_fit", {}).get(failure["key"])
        if fit is None:
            return v, "fails"
        if fit[0] not in ("converges", "exact", *STOPS):     # not decided, not asymptotic
            return v, fit[0]
        if fit[0] not in STOPS:
            return v, "fixes"
        if v is None or failure["base"] is None:
            return v, "no change"
        # e_inf near zero on both sides is no change, whatever the ratio; two limits within
        # their +- combined are no change either (the fits cannot tell them apart)
        base, scale = abs(failure["base"]), max(abs(failure["base"]), abs(v), 1e-300)
        if abs(abs(v) - base) < float(np.hypot(failure.get("base_err") or 0.0,
                                               fit[2] or 0.0)):
            return v, "no change"
        if abs(v) <= (1 - CHANGE) * base:
            return v, "improves"
        if abs(v) >= (1 + CHANGE) * base and scale > 0:
            return v, "worsens"
        return v, "no change"
    return v, verdict(failure, v)


def fixes(rank, models):
    """{candidate: [(failure, value, verdict)]} for every model but the base and FEM."""
    fs = failures(rank)
    return fs, {m: [(f, *judge(rank, f, m)) for f in fs]
                for m in models if m not in (BASE, YARDSTICK)}


def _overlap(a, b):
    return a is None or b is None or (a[0] <= b[1] and b[0] <= a[1])


def shared_ranks(by, rank):
    """{model: its rank as text}: in the order ``by``, a model whose range leaving one
    population out overlaps its group head's shares the head's rank (the data cannot order
    them); a model without an overall mean (failed) and the yardstick (FEM P1 itself, 0 by
    construction) rank '-'."""
    rng, out, head = rank.get("overall_range", {}), {}, None
    ranked = [m for m in by if rank["overall"].get(m) is not None and m != YARDSTICK]
    for k, m in enumerate(ranked):
        if head is None or not _overlap(rng.get(head), rng.get(m)):
            head, out[m] = m, str(k + 1)
        out[m] = out[head]
    return {m: out.get(m, "-") for m in by}


def _lead(rank, cands):
    """The headline's first line: the candidates by geometric mean over the pooled
    populations, with their range leaving one population or one mesh family out; a best is
    named only where its range overlaps no other candidate's, and it beats the paper model only where its range
    lies below 1; failures, identical candidates and the populations left out are said."""
    rng = rank.get("overall_range", {})
    fails = rank.get("overall_failed", {})
    n = rank.get("overall_over", len(rank["case_errors"]))
    ranked = [m for m in order(rank["overall"]) if m in cands]

    def said(m):
        if rank["overall"][m] is None:
            return f"{short(m)} failed (no result on {fails.get(m, 0)} of {n} populations)"
        r = rng.get(m)
        return f"{short(m)} {fmt(rank['overall'][m])}" + (f" [{fmt(r[0])}-{fmt(r[1])}]"
                                                          if r else "")
    ok = [m for m in ranked if rank["overall"][m] is not None]
    if not ok:
        return (f"Over the {n} populations the library averages no candidate has a result "
                "on every one: " + ", ".join(said(m) for m in ranked) + ".")
    b = ok[0]
    level = [m for m in ok[1:] if _overlap(rng.get(b), rng.get(m))]
    r = rng.get(b) or [rank["overall"][b]] * 2
    versus = ("closer to FEM P1 than the paper model whichever population or mesh family is "
              "left out" if r[1] < 1 else
              "farther from FEM P1 than the paper model whichever population or mesh family "
              "is left out"
              if r[0] > 1 else "not resolved from the paper model (its range reaches 1)")
    lead = (f"not resolved between {', '.join(short(m) for m in [b] + level)} (their ranges "
            "leaving one population or one mesh family out overlap)" if level else f"the best is {short(b)}")
    same = [" = ".join(short(m) for m in g) for g in rank.get("identical", [])
            if set(g) <= set(cands)]
    out = (f"Over the {n} populations the library averages, among the normal-stress "
           f"extensions {lead}: the geometric mean of each one's model-form errors (against "
           f"FEM P1 on the same tetrahedra) over the paper model's ({BASE}) [its range leaving "
           f"one population or one mesh family out]: " + ", ".join(said(m) for m in ranked)
           + f"; {short(b)} {versus}.")
    if same:
        out += (" Identical on every averaged population (one observation, not several): "
                + "; ".join(same) + ".")
    if rank.get("left_out"):
        out += (" Not averaged: " + ", ".join(rank["left_out"]) + " (patch tests and "
                "locking-prone problems: in the table, not in the mean).")
    return out


def _cost(rank, model):
    """'3.16 [3-3.3]': a model's step over fem-linear's with its range over the bench's
    rounds (the median alone where the record has no range)."""
    rng = rank.get("cost_range", {}).get(model)
    return fmt(rank["cost"][model]) + (f" [{fmt(rng[0], 2)}-{fmt(rng[1], 2)}]" if rng else "")


def _cost_size(rank):
    """The size the costs were read at: the bench's own, or COST_TETS where a record predates
    it."""
    return rank.get("cost_tets") or f"{COST_TETS:.0e}"


def conclusion(data):
    """The study's headline, from a metrics document."""
    models = data["parameters"]["models"]
    rank = data["rankings"]
    fs, table = fixes(rank, models)
    cands = [m for m in models if m not in (BASE, YARDSTICK)]
    lines = []
    lines.append(_lead(rank, cands))
    cost = {m: rank["cost"].get(m) for m in cands if rank["cost"].get(m) is not None}
    if cost and rank["cost"].get(BASE) is not None:
        lo, hi = min(cost, key=cost.get), max(cost, key=cost.get)
        lines.append(f"Each adds cost: at {_cost_size(rank)} tetrahedra an RK4 step of the "
                     f"candidates takes {_cost(rank, lo)} to {_cost(rank, hi)} "
                     f"times fem-linear's, the paper model's {_cost(rank, BASE)} times "
                     "(the bench's median in-round ratios [smallest-largest over its rounds]: "
                     "costs whose ranges overlap are not ordered here).")
    if not fs:
        lines.append(f"{BASE} fails none of the criteria checked here (model-form error "
                     f"within {FEM_FACTOR:g}x FEM P1's discretisation error, C_eff within "
                     f"{ISOTROPIC_TOL:g} of the target, no convergence floor).")
        return lines
    lines.append(f"{BASE} fails {len(fs)} criteria: " + "; ".join(
        f"{f['what']} {fmt(f['base'])}" + (f" ({f['note']})" if f.get("note") else "")
        for f in fs) + ".")
    fixed = {m: [(f, v) for f, v, w in table[m] if w == "fixes"] for m in cands}
    for m in cands:
        worse = [(f, v) for f, v, w in table[m] if w in ("worsens", "fails")]
        said = (f"{short(m)} fixes {len(fixed[m])} of them"
                + (": " + "; ".join(f"{f['what']} {fmt(f['base'])} -> {cell(rank, f, m, v)}"
                                    for f, v in fixed[m]) if fixed[m] else ""))
        if worse:
            said += " and worsens " + "; ".join(
                f"{f['what']} {fmt(f['base'])} -> {cell(rank, f, m, v)}" for f, v in worse)
        new = new_failures(rank, m)
        if new:
            said += "; it fails where the paper's model does not: " + "; ".join(new)
        lines.append(said + ".")
    nobody = [f for i, f in enumerate(fs) if not any(table[m][i][2] == "fixes" for m in cands)]
    if nobody:
        lines.append("No extension fixes " + "; ".join(f["what"] for f in nobody) + ".")
    return lines


# ---------------------------------------------------------------------- files
def gate_rows(data, rank):
    rows = [{"mesh": case, "bc": "median", "model": m, "error": e}
            for case, es in rank["case_errors"].items() for m, e in es.items()]
    rows += [{"mesh": "paper-cube", "bc": "alternation", "model": m, "alternation_max_rel": a}
             for m, a in rank["alternation"].items()]
    rows += [{"mesh": f["mesh"], "bc": f"{f['case']}/{f['bc']}/fit", "model": f["model"],
              "e_inf": f.get("e_inf")} for f in data["fits"] if f["model"] != "FEM P1"]
    rows += [{"mesh": e["mesh"], "bc": "C_eff", "model": e["model"],
              "moduli_rel_err": e.get("moduli_rel_err")} for e in data["elasticity"]]
    return rows


def write(out, study, s, data):
    """Write metrics.json, run.json, report.md/.html and the PNG figures into ``out``; the
    convergence fits derived from the recorded runs by the convergence study's rule."""
    data = {**data, "fits": conv_fits(data)}
    rank = rankings(data, list(s.models))
    doc = jsonable({"case": study.name, "study": True, "parameters": s.describe(),
                    "problem": s.problem(), "gated": GATED, "environment": environment(),
                    **data, "rankings": rank, "gate_runs": gate_rows(data, rank)})
    return write_study(out, doc, lambda folder: build(folder, study, s, doc))


def build(out, study, s, doc):
    rank, models = doc["rankings"], list(s.models)
    cases = list(rank["case_errors"])
    d = Document(f"pbcm report: {study.name}")
    d.opening(["**Quick: not decided** (`pbcm run extensions` decides, on every case's full "
               "meshes): the tables below are a preview and decide nothing."]
              if s.quick else conclusion(doc))
    d.p("Generated by `pbcm run extensions` (or `pbcm run extensions --rewrite`, from the same "
        "recorded runs): every number is computed from the runs recorded in metrics.json, but "
        "the step costs, which are `pbcm bench`'s (reports/bench/bench.json).")
    d.h(2, "What was run")
    d.ul([study.title + ".",
          f"The paper's model: {BASE} (the variational reading of docs/model.md, c fitted). Each "
          "candidate adds one deviatoric normal-stress term with c_n = auto (fitted with the "
          "shear c so that the deviatoric moduli of the relaxed lattice patch are closest to "
          "2G): "
          + "; ".join(f"{short(m)} = `{m}`" for m in models if short(m) != m) + ". "
          f"{YARDSTICK} (constant-strain FEM on the same tetrahedra) is the yardstick.",
          f"Cases: {', '.join(cases)}, each with its own {'quick' if s.quick else 'full'} "
          "settings (meshes, boundary conditions, references), as `pbcm run CASE` runs them.",
          "Convergence: the convergence study's problems, mesh families and sizes "
          f"({'quick' if s.quick else 'full'} mode) with these models: the verdict of each "
          "(problem, family) fit and the effective elasticity tensor of each lattice.",
          f"Material E = {s.E:g} Pa, nu = {s.nu:g}."])
    d.h(2, "Criteria")
    d.ul([f"case error: the model-form error of the case's decomposed quantity (its "
          "report's, against FEM P1 with the same law on the same tetrahedra: what replacing "
          "FEM costs; see the glossary), median over its meshes per boundary condition; a "
          f"failure of {BASE} where it exceeds {FEM_FACTOR:g} times FEM P1's own "
          "discretisation error on the same meshes (replacing FEM costs more than FEM's "
          "distance from the continuum there). The FEM P1 of a finite-load case is "
          "neo-Hookean, so fem-linear's error there is its linearisation.",
          f"overall: geometric mean over the averaged populations (neither patch tests nor "
          f"locking-prone problems) of the model-form error over {BASE}'s (below 1: closer "
          "to FEM P1 than the paper's model), each population weighing one (the index's "
          "ranking weighs each case one, its boundary conditions averaged: a case with two "
          "weighs twice here); a model that failed on one has none, and is "
          "ranked last; a best is named only where its range leaving one population or one mesh family out "
          "overlaps no other's.",
          "bulge/neck alternation (shown, not a criterion): the largest |alternation| of the "
          "paper cube's 5-layer profile beyond FEM's over the mean lateral displacement, over "
          "the model's meshes and bases; the 5-layer view decides nothing (the artefact "
          "study's finer meshes do).",
          "convergence floor: fits (of the convergence study) whose verdict is floor or "
          "diverges, and the range of the floors, each e_inf with its fit's +- (floors of "
          "different problems are different quantities: never pooled into a median).",
          "stiffness: on the sliding cube (its top displacement prescribed, so its "
          "displacement error is blind to the stiffness), the reaction ratio's limit's "
          "distance from 1, |ratio_inf - 1|, per lattice; a failure where it exceeds "
          f"{ISOTROPIC_TOL:g} beyond its fit's +- (the tolerance of C_eff, whose uniaxial "
          "modulus it measures).",
          "C_eff: the largest relative error of its bulk modulus and five deviatoric Kelvin "
          f"moduli against the target's on each lattice; a failure above {ISOTROPIC_TOL:g}.",
          f"cost: RK4 step time over fem-linear's at {_cost_size(doc['rankings'])} "
          "tetrahedra, the bench's size closest to "
          f"{COST_TETS:.0e}: its interleaved in-process ratio, the median over its rounds.",
          f"fixes: meets the criterion; improves / worsens: changes the value by "
          f"{CHANGE:.0%} or more, and, for a convergence floor, by more than the two fits' "
          "+- combined (a change within it is 'no change', whatever its size); the criteria "
          "a candidate fails where the paper's model meets them are named after its fixes."])
    d.h(2, "Ranking by model-form error")
    by = order(rank["overall"])
    ranks = shared_ranks(by, rank)
    d.table(["rank", "model", "overall"] + cases,
            [[ranks[m], short(m), "failed" if rank["overall"][m] is None
              and rank.get("overall_failed", {}).get(m) else fmt(rank["overall"][m])]
             + [fmt(rank["case_errors"][c][m]) for c in cases] for i, m in enumerate(by)])
    figures.grouped_bars(Path(out) / "case_errors.png", cases, [short(m) for m in models],
                         [[rank["case_errors"][c][m] or np.nan for m in models] for c in cases],
                         "model-form error", "Model-form error of each case", log=True)
    d.img("case_errors.png", "model-form error of each case per model")
    gone = {c: ks for c, ks in rank.get("excluded", {}).items() if ks}
    if gone:
        first = {c: next(r["failed"] for r in doc["case_runs"] if r["case"] == c
                         and f"{r['mesh']}/{r['bc']}" == ks[0]) for c, ks in gone.items()}
        d.p("Left out of every comparison, because no model (FEM included) has a result there: "
            + "; ".join(f"{c} on {', '.join(ks)} ({first[c]})" for c, ks in gone.items()) + ".")
    # no per-case winner is named: an order of medians resolved against no uncertainty is
    # not a finding (the index's scorecard reads each case against its u_val)
    d.p("Per case, the medians over the meshes are in the table above; which model is "
        "closest in each case, read against its uncertainty, is in the index's "
        "[scorecard](../index.md).")
    dropped = {}
    for r in doc["case_runs"]:
        for t in r.get("dropped") or []:
            dropped.setdefault((short(r["model"]), t), set()).add(r["mesh"])
    if dropped:
        d.p("The joint calibration set c_n to 0, dropping the term (the shear term alone is "
            "already stiffer than G in the modes it adds), for " + "; ".join(
                f"{m} on {', '.join(sorted(ms))}" for (m, _), ms in sorted(dropped.items()))
            + ": there the candidate is the paper's model.")
    d.h(2, "Cost, the 5-layer alternation, convergence floors and effective elasticity")
    lattices = sorted({e["mesh"] for e in doc["elasticity"]})
    fl = rank["floors"]
    d.table(["model", "step / fem-linear", "alternation (5-layer view)", "floor + diverges",
             "floors (each with its +-)"] + [f"C_eff {lat}" for lat in lattices],
            [[short(m), _cost(rank, m) if rank["cost"].get(m) is not None else "n/a",
              fmt(rank["alternation"].get(m)),
              f"{fl[m]['floor'] + fl[m]['diverges']} of {fl[m]['fits']}",
              f"{fmt(fl[m]['range'][0])}-{fmt(fl[m]['range'][1])}" if fl[m].get("range")
              else "none"]
             + [fmt(rank["tensors"][m].get(lat)) for lat in lattices] for m in models])
    twin, edge = doc.get("cost_same_terms", {}).get(TWIN), rank["cost"].get(CANDIDATES[0])
    # equal to the last digit: one bench row read twice, not two timings
    if twin is not None and edge is not None and twin != edge:
        d.p(f"The bench timed +normal_edge's terms twice, as the preset {TWIN} "
            f"({fmt(twin)}) and as +normal_edge ({fmt(edge)}), in two runs: "
            f"{abs(edge / twin - 1):.0%} apart (two medians; the bench's rounds spread wider, "
            "bench.md gives each row's range).")
    missing = [short(m) for m in models if rank["cost"].get(m) is None]
    if missing:
        d.p(f"Not in bench.json, so without a cost: {', '.join(missing)}; `pbcm bench --merge "
            "--models ...` adds them.")
    figures.grouped_bars(Path(out) / "ceff_moduli.png", lattices, [short(m) for m in models],
                         [[rank["tensors"][m].get(lat) or np.nan for m in models]
                          for lat in lattices], "largest relative modulus error",
                         "Effective tensor: its moduli's largest error against the isotropic "
                         "target", log=True)
    d.img("ceff_moduli.png", "effective elasticity: largest modulus error per lattice and model")
    d.h(2, "Which extension fixes which failure")
    fs, table = fixes(rank, models)
    cands = [m for m in models if m not in (BASE, YARDSTICK)]
    if fs:
        d.p("A convergence failure's value is the fit's extrapolated error e_inf; it is fixed "
            "where the candidate's fit converges.")
        d.table(["failure of " + BASE, "value", "criterion"] + [short(m) for m in cands],
                [[f["what"] + (f" ({f['note']})" if f.get("note") else ""), fmt(f["base"]),
                  fmt(f["limit"]) if f["limit"] is not None else "converges"]
                 + [f"{cell(rank, f, m, table[m][i][1])} ({table[m][i][2]})" for m in cands]
                 for i, f in enumerate(fs)])
    else:
        d.p(f"{BASE} meets every criterion here.")
    return d
