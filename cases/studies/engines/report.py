"""The engines study's files: metrics.json (each run's errors, the per-solver findings and the
rows the gate reads) and report.md/.html. Every sentence is computed from the runs it is
written with."""
import numpy as np

from ...measuring import catalogue
from ...reporting.document import Document, fmt
from ...reporting.report import environment, write_study
from ...running.runner import jsonable
from .study import CASE_NAMES, CONVERGED, MATCH, SOLVERS, spec

GATED = catalogue.gated("engine_error")
REGIMES = ("linear regime", "at the load")


def _spread(values):
    """'median [min-max], n of N' of the values (None: a failed run, counted in N)."""
    got = [v for v in values if v is not None]
    if not got:
        return f"failed, 0 of {len(values)}"
    med, lo, hi = np.median(got), min(got), max(got)
    return f"{fmt(med, 3)} [{fmt(lo, 3)} to {fmt(hi, 3)}], {len(got)} of {len(values)}"


def _runs(data, case, regime, model):
    return [r for r in data["runs"] if r["case"] == case and r["regime"] == regime
            and r["model"] == model]


def convergence(data, case, regime, solver, ladder):
    """The smallest iteration count from which the quantity stays within CONVERGED (of the
    continuum's |Q_c|) of its value at the ladder's top on every mesh; None where no count
    does or a run failed; the reason beside."""
    top = ladder[-1]
    meshes = sorted({r["mesh"] for r in _runs(data, case, regime, spec(solver, top))})
    if not meshes:
        return None, "not run"
    for n in ladder:
        ok = True
        for mesh in meshes:
            for m in [k for k in ladder if k >= n]:
                a = [r for r in _runs(data, case, regime, spec(solver, m)) if r["mesh"] == mesh]
                b = [r for r in _runs(data, case, regime, spec(solver, top)) if r["mesh"] == mesh]
                if not a or not b or a[0]["failed"] or b[0]["failed"]:
                    return None, f"a run failed (at {m} iterations on {mesh})"
                if abs(a[0]["value_rel"] - b[0]["value_rel"]) > CONVERGED:
                    ok = False
        if ok:
            return n, ("only at the ladder's top: not shown converged" if n == top else None)
    return None, "no count"


def findings(data, ladder):
    """Per solver: its default settings' model-form and total errors per case and regime, the
    iteration count at which its own answer converges, the settings at which it matches FEM P1
    (|model-form error| <= MATCH on every mesh)."""
    out = {}
    for solver in SOLVERS:
        counts = ladder.get(solver, (None,))
        f = {"cases": {}}
        for case in CASE_NAMES:
            for regime in REGIMES:
                default = _runs(data, case, regime, spec(solver, counts[0]))
                if not default:
                    continue
                key = f"{case}/{regime}"
                match = [n for n in counts
                         if (rs := _runs(data, case, regime, spec(solver, n)))
                         and all(r["model_form"] is not None and abs(r["model_form"]) <= MATCH
                                 for r in rs)]
                conv = convergence(data, case, regime, solver, counts) \
                    if solver in ladder else (None, "not iterative")
                top = _runs(data, case, regime, spec(solver, counts[-1]))
                n_runs = sum(len(_runs(data, case, regime, spec(solver, n))) for n in counts)
                n_failed = sum(1 for n in counts for r in _runs(data, case, regime, spec(solver, n))
                               if r["failed"])
                f["cases"][key] = {
                    "top_iterations": counts[-1],
                    "top_model_form": [r["model_form"] for r in top],
                    "runs_failed": [n_failed, n_runs],
                    "dt_s": sorted({r["dt_s"] for r in default if r.get("dt_s")}),
                    "residual_n": [r.get("static_residual_n") for r in default],
                    "model_form": [r["model_form"] for r in default],
                    "total": [r["total"] for r in default],
                    "discretisation": [r["discretisation"] for r in default],
                    "failed": [r["failed"] for r in default if r["failed"]],
                    "matches_p1_at": match, "converged_at": conv[0], "converged_why": conv[1]}
        out[solver] = f
    return out


def gate_rows(data):
    return [{"mesh": r["mesh"], "bc": f"{r['case']}/{r['bc']}/{r['regime']}", "model": r["model"],
             "engine_error": None if r["model_form"] is None else abs(r["model_form"])}
            for r in data["runs"] if r["solver"]]


def matches(f, ladder):
    """{case: [(solver, least count or None)]}: the solvers within MATCH of FEM P1 in every
    regime of the case on every mesh, each from the least iteration count from which it stays
    so (None: a solver without iterations)."""
    out = {}
    for case in CASE_NAMES:
        got = []
        for solver in SOLVERS:
            cs = [c for k, c in f[solver]["cases"].items() if k.startswith(case + "/")]
            if not cs:
                continue
            counts = ladder.get(solver, (None,))
            common = [n for n in counts if all(n in c["matches_p1_at"] for c in cs)]
            # from a count on: every larger count matches too
            start = next((n for i, n in enumerate(counts) if all(m in common for m in counts[i:])),
                         "none")
            if start != "none":
                got.append((solver, start))
        out[case] = got
    return out


def answer(f, ladder, quick, installed, shear=None):
    """The index's line: per case, which engine replaces FEM P1 there (within MATCH on both
    regimes and every mesh) and from which setting; the bar's sliding support named."""
    if not installed:
        return "not measured: the engines extra is not installed"
    if quick:
        return "quick: not decided (`pbcm run engines` decides)"
    parts = []
    for case, got in matches(f, ladder).items():
        name = CASE_NAMES[case]
        who = ", ".join(f"{sv}" + (f" from {n} iterations" if n else "") for sv, n in got)
        parts.append(f"{name} ({case}): {who or 'none'}")
    laws = ", ".join(f"{sv} " + (f"{fmt(g, 3)} G" if g > 1e-6 else "0 (to first order)")
                     for sv, g in (shear or {}).items())
    same = [sv for sv, g in (shear or {}).items() if abs(g - 1.0) < 1e-6]
    return (f"within {MATCH:g} of FEM P1 (the difference a fraction of the continuum's value, "
            "both regimes, every mesh), with the material mapped as Newton documents it: "
            + "; ".join(parts)
            + (f" ({', '.join(same)}: its law is the material's at small strain, so a match is "
               "its solver reaching FEM P1's answer, FEM P1's own distance from the continuum "
               "included, not an accuracy beyond it)" if same else "")
            + (f"; under that mapping the laws' small-strain shear moduli are {laws}" if laws
               else ""))


def shear_moduli(material):
    """{solver: its law's small-strain shear modulus over G} under the documented mapping."""
    from model.simulators.newton import small_strain_moduli
    return {sv: small_strain_moduli(sv.removeprefix("newton-"), material)[0] / material.G
            for sv in SOLVERS}


def write(out, study, s, data):
    found = findings(data, s.ladder) if data["installed"] else {}
    doc = jsonable({"case": study.name, "study": True, "parameters": s.describe(),
                    "problem": s.problem(), "gated": GATED, "environment": environment(),
                    **data, "findings": found,
                    "answer": answer(found, s.ladder, s.quick, data["installed"],
                                     shear_moduli(s.material) if data["installed"] else None),
                    "gate_runs": gate_rows(data)})
    return write_study(out, doc, lambda folder: build(folder, study, s, doc))


def _signed(values):
    """'median [min to max], n of N' of signed values (None: a failed run, counted in N)."""
    return _spread(values)


def _range(cases, key):
    vals = [v for c in cases.values() for v in c[key] if v is not None]
    return (min(vals), max(vals)) if vals else None


def _where(key):
    case, regime = key.split("/")
    return f"{CASE_NAMES[case]}, {regime}"


def solver_line(solver, f, ladder, moduli, material):
    """One solver's finding: its law at small strain under the documented mapping, its
    model-form error at its defaults and at the ladder's top, its failures."""
    cases = f["cases"]
    G, lam = moduli
    g = (f"{fmt(G / material.G, 3)} G" if G > 1e-6 * material.G else "0 (to first order)")
    text = (f"**{solver}** ({_setting(solver, ladder, cases)}; its law at small strain: shear "
            f"modulus {g}, lambda {fmt(lam / material.lam, 3)} of the material's): ")
    lo_hi = _range(cases, "model_form")
    text += ("model-form error at its defaults from "
             f"{fmt(lo_hi[0], 3)} to {fmt(lo_hi[1], 3)} (signed, every run)" if lo_hi
             else "no model-form error at its defaults")
    if solver in ladder:
        top = _range(cases, "top_model_form")
        text += (f"; at {ladder[solver][-1]} iterations from {fmt(top[0], 3)} to {fmt(top[1], 3)}"
                 if top else f"; none at {ladder[solver][-1]} iterations")
    failed, total = (sum(c["runs_failed"][i] for c in cases.values()) for i in (0, 1))
    if failed:
        text += (f"; {failed} of {total} runs failed (not at rest), at every setting in "
                 + ", ".join(_where(k) for k, c in cases.items()
                             if c["runs_failed"][0] == c["runs_failed"][1]))
    return text + "."


def findings_rows(doc, ladder, quick):
    rows = []
    for solver in SOLVERS:
        for key, c in doc["findings"][solver]["cases"].items():
            if solver not in ladder:
                conv = "not iterative"
            elif quick:
                conv = "quick: not decided"
            elif c["converged_at"] is not None:
                conv = f"{c['converged_at']}" + (f" ({c['converged_why']})"
                                                 if c["converged_why"] else "")
            else:
                conv = f"not within the ladder ({c['converged_why']})"
            match = ("quick: not decided" if quick else
                     ", ".join(str(n) if n else "its setting" for n in c["matches_p1_at"])
                     or "none")
            top = "-" if solver not in ladder else _signed(c["top_model_form"])
            res = [v for v in c["residual_n"] if v is not None]
            rows.append([solver, _where(key), _signed(c["model_form"]), top,
                         _signed(c["total"]), _signed(c["discretisation"]),
                         fmt(max(res), 2) if res else "n/a", conv, match,
                         f"{c['runs_failed'][0]} of {c['runs_failed'][1]}"])
    return rows


def _setting(solver, ladder, cases=None):
    counts = ladder.get(solver)
    dts = sorted({d for c in (cases or {}).values() for d in c["dt_s"]})
    dt = (f", dt {fmt(dts[0], 3)}" + (f" to {fmt(dts[-1], 3)}" if len(dts) > 1 else "") + " s"
          if dts else "")
    return (f"explicit, at its own stable step{dt}" if counts is None else
            f"{counts[0]} iterations a step by default{dt}; ladder {', '.join(map(str, counts))}")


def build(out, study, s, doc):
    from model.simulators.newton import small_strain_moduli
    d = Document(f"pbcm report: {study.name}")
    if not doc["installed"]:
        d.opening(["**Not measured here**: the engines extra is not installed (`pip install -e "
                   "\".[engines]\"`), so no Newton model ran; every row below reads 'not "
                   "installed'."])
        d.table(["solver", "status"], [[sv, "not installed"] for sv in SOLVERS])
        return d
    ladder, material = s.ladder, s.material
    f = doc["findings"]
    moduli = {sv: small_strain_moduli(sv.removeprefix("newton-"), material) for sv in SOLVERS}
    lines = [solver_line(sv, f[sv], ladder, moduli[sv], material)
             for sv in sorted(SOLVERS, key=lambda sv: -sum(bool(c["matches_p1_at"])
                                                         for c in f[sv]["cases"].values()))]
    head = (["**Quick: not decided** (`pbcm run engines` decides: two meshes, the full "
             "iteration ladders): the lines below are a preview."] if s.quick
            else [f"**In one line:** {doc['answer']}."])
    d.opening(head + lines)
    d.p(f"The Newton engine ({doc['engine']}, single precision on Warp's CPU backend) runs each "
        "case's problem through the cases' own runner, beside FEM P1 on the same tetrahedra: "
        "linear FEM in the linear regime, neo-Hookean FEM at the load (the continuum's law; "
        "not the engine's own, so the model-form error (Q - Q_P1) / |Q_c| holds both what the "
        "engine's law differs from the material's by and what its solver and supports add). "
        "The distance from the continuum (Q - Q_c) / |Q_c| adds FEM P1's own discretisation "
        "error on the mesh, shown beside it: a distance below FEM P1's own is a cancellation "
        "of the two, not accuracy. The material is mapped as Newton's documentation defines its "
        "parameters (k_mu = G, k_lambda = lambda); the small-strain moduli each law then has "
        "are computed from the law as transcribed from the engine's kernels "
        "(docs/simulators.md). Each equilibrium is run to rest: a solver whose motion stops "
        "shrinking, or that is still moving after 200 of the body's slowest periods, is a "
        "failed run; the rest test bounds the motion still to come (1e-3 of the largest "
        "displacement), not how far the engine's law is from balanced, which the residual "
        "column gives (the largest free-node force of that law at rest, linear regime). A "
        f"quantity converges in iterations where it stays within {CONVERGED:g} of |Q_c| of its "
        "value at the ladder's top from that count on, on every mesh; a solver matches FEM P1 "
        f"where |Q - Q_P1| / |Q_c| is at most {MATCH:g} on every mesh. The meshes are the "
        "cases' quick meshes, split 'five' and 'six' (two splits of one lattice size, the "
        "quick run 'five' only), and their references the cases' quick references (each "
        "reference's own estimate in the table of every run). The bar is the block settling "
        "under its own weight on a sliding base (self-weight), the cube the paper's on a "
        "clamped base, the cantilever clamped. Only the iteration count was varied; the "
        "substeps and the step were not. Newton's particles cannot hold one component "
        "of a node: the bar's sliding base is set back after every step, which the explicit "
        "solver then satisfies exactly and the iterative ones (VBD, XPBD) only between steps; "
        "how much of their error on the bar that support makes is not measured here.")
    d.h(2, "Each solver on each case")
    d.p("Per case and regime (signed errors, median [range], n of N meshes): the model-form "
        "error at the solver's defaults and at the top of its iteration ladder, the distance "
        "from the continuum at its defaults and FEM P1's own on the same meshes, the largest "
        "residual force of its law at rest, the iteration count from which its answer stays "
        f"within {CONVERGED:g} of its answer at the ladder's top, the counts at which it is "
        f"within {MATCH:g} of FEM P1 on every mesh, and its failed runs over every setting.")
    d.table(["solver", "case", "model-form error, defaults", "model-form error, ladder's top",
             "from the continuum, defaults", "FEM P1 from the continuum", "residual [N]",
             "converged from (iterations)", f"within {MATCH:g} of FEM P1 at (iterations)",
             "failed runs"], findings_rows(doc, ladder, s.quick), keys=2)
    rows = []
    for r in doc["runs"]:
        rows.append([r["case"], r["regime"], r["model"], r["mesh"],
                     "n/a" if r["value_rel"] is None else fmt(r["value_rel"], 4),
                     "n/a" if r["model_form"] is None else fmt(r["model_form"], 3),
                     "n/a" if r["total"] is None else fmt(r["total"], 3),
                     "n/a" if r["discretisation"] is None else fmt(r["discretisation"], 3),
                     "n/a" if r["estimate"] is None else fmt(r["estimate"], 2),
                     r["failed"] or ""])
    d.h(2, "Every run")
    d.table(["case", "regime", "model", "mesh", "Q / abs(Q_c)", "model-form error (signed)",
             "from the continuum (signed)", "FEM P1 from the continuum", "reference's estimate",
             "failed"], rows, keys=4)
    return d
