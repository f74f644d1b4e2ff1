"""Sentences that rank the models of a case's runs, computed from the runs: one population per
aggregate (each boundary condition apart), each cell 'median [min-max], n of N runs', only
models with a value in every run ranked, ties within the reference's error estimate, the
closest and farthest model, failures, and the case's load against the neo-Hookean
reference."""
import numpy as np

from .document import Table

# what a ranking by a case's own metric measures: the total error, the mesh's own included
# (the model-form ranking is the error model's, cases.scorecard)
AGAINST = (" against its reference (total error, the mesh's discretisation error included: "
           "not a ranking of the models, which the model-form error is)")


def populations(runs):
    """The runs split by boundary condition: each (case, bc) is one population (a patch test
    and a clamped cube are never pooled); {bc: runs}, in the runs' order."""
    out = {}
    for r in runs:
        out.setdefault(r["bc"], []).append(r)
    return out


def _by_model(runs, metric):
    """{model: values} over the runs that gave ``metric``, and {model: runs it had}."""
    by, had = {}, {}
    for r in runs:
        had[r["model"]] = had.get(r["model"], 0) + 1
        if r.get(metric) is not None:
            by.setdefault(r["model"], []).append(r[metric])
    return by, had


def cell(values, total):
    """'median [min-max], n of N runs' of one aggregate."""
    if not values:
        return f"no result, 0 of {total} runs"
    return (f"median {np.median(values):.3g} [{min(values):.3g}-{max(values):.3g}], "
            f"{len(values)} of {total} runs")


def estimate(runs, key="p2_error_estimate"):
    """The reference's error estimate a ranking of ``runs`` respects: the largest of their
    references' (one per mesh and bc; None where the reference has none); ``key`` the
    reference's (nh_error_estimate for the neo-Hookean one)."""
    est = [r[key] for r in runs if r.get(key) is not None]
    return max(est) if est else None


def _complete(by, had):
    """The models with a value in every run they had (the others are not ranked)."""
    full = max(had.values(), default=0)
    return [m for m in by if len(by[m]) == had[m] == full]


def _labelled(runs, line_of):
    """``line_of(population runs)`` per boundary condition, prefixed by the bc when there are
    several populations."""
    pops = populations(runs)
    if len(pops) == 1:
        return [line_of(next(iter(pops.values())))]
    return [f"[{bc}] {line_of(rs)}" for bc, rs in pops.items()]


def ranking(runs, metric, label, estimate_key="p2_error_estimate"):
    """A table (one item of a report's findings): per population (boundary condition) the
    models by median ``metric``, best first, with the range and 'n of N runs'; only the models
    with a value in every run are ranked, the others listed after, unranked; a model within
    the reference's estimate (``estimate_key``) of the one above is tied with it (the
    reference cannot order them)."""
    rows = []
    for bc, rs in populations(runs).items():
        by, had = _by_model(rs, metric)
        est = estimate(rs, estimate_key)
        med = {m: float(np.median(v)) for m, v in by.items()}
        ranked = sorted(_complete(by, had), key=med.get)
        for k, m in enumerate(ranked):
            tie = ""
            if k and est is not None and med[m] - med[ranked[k - 1]] < est:
                tie = f"tied with {ranked[k - 1]} (estimate {est:.2g})"
            rows.append([bc, k + 1, m, *_stats(by[m], had[m]), tie])
        for m in sorted(set(had) - set(ranked)):
            rows.append([bc, "-", m, *_stats(by.get(m, []), had[m]), "incomplete, not ranked"])
    return [Table(f"{label[0].upper()}{label[1:]} ({metric}){AGAINST} per model, median over "
                  "the meshes:",
                  ["bc", "rank", "model", "median", "range", "runs", "note"], rows)]


def _stats(values, total):
    if not values:
        return "n/a", "", f"0 of {total}"
    return (f"{np.median(values):.3g}", f"{min(values):.3g}-{max(values):.3g}",
            f"{len(values)} of {total}")


def best_and_worst(runs, metric, what, exact=False, estimate_key="p2_error_estimate"):
    """Per population (boundary condition), one line naming the model closest to FEM and the
    farthest by median ``metric`` among the models with a value in every run; the models
    within the reference's estimate (``estimate_key``) of the closest are named tied with it,
    the line says so where that estimate exceeds a fifth of the smallest error it ranks
    (``exact``: the metric is against a closed form, which has no estimate), and it names
    the models left out for a missing run."""
    def line_of(rs):
        by, had = _by_model(rs, metric)
        est = None if exact else estimate(rs, estimate_key)
        ranked = _complete(by, had)
        if not ranked:
            return f"No model gave {what} in every run."
        med = {m: float(np.median(by[m])) for m in ranked}
        best, worst = min(med, key=med.get), max(med, key=med.get)
        line = (f"{what}{AGAINST}: smallest {best} ({cell(by[best], had[best])}), largest "
                f"{worst} ({cell(by[worst], had[worst])}).")
        left = sorted(set(had) - set(ranked))
        if left:
            line += (" Left out, a run without a value: " + ", ".join(
                f"{m} ({len(by.get(m, []))} of {had[m]} gave one)" for m in left) + ".")
        if est is None:
            return line
        tied = [m for m in sorted(med, key=med.get) if m != best and med[m] - med[best] < est]
        if tied:
            line += (f" Tied with {best} within the reference's estimate {est:.2g}: "
                     f"{', '.join(tied)}.")
        smallest = min(min(by[m]) for m in ranked)
        if est > smallest / 5:
            line += (f" The reference's estimate ({est:.2g}) exceeds a fifth of the smallest "
                     f"error ranked ({smallest:.2g}): differences below it are not resolved.")
        return line
    return " ".join(_labelled(runs, line_of))


def per_run(runs, holds, what):
    """'what' said run by run, never of a median: the models for which ``holds(run)`` is true
    in every run that gave an answer, those for which it is true in some (with where), and
    those for which it never is."""
    by = {}
    for r in runs:
        v = holds(r)
        if v is not None:
            by.setdefault(r["model"], []).append((f"{r['mesh']}/{r['bc']}", bool(v)))
    every = [m for m, vs in by.items() if all(v for _, v in vs)]
    some = [f"{m} (on {', '.join(w for w, v in vs if v)}, {sum(v for _, v in vs)} of {len(vs)})"
            for m, vs in by.items() if any(v for _, v in vs) and not all(v for _, v in vs)]
    never = [m for m, vs in by.items() if not any(v for _, v in vs)]
    return (f"{what} in every run: {', '.join(every) or 'none'}; in some runs: "
            f"{'; '.join(some) or 'none'}; in none: {', '.join(never) or 'none'}.")


def failures(runs, key="static_failed", where="in the linear regime"):
    """One line on the runs whose static solve (``key``) failed, or that none did."""
    bad = [f"{r['model']} on {r['mesh']}/{r['bc']}" for r in runs if r.get(key)]
    return (f"No static equilibrium {where} for " + ", ".join(bad) + "." if bad
            else f"Every model found its static equilibrium {where} on every mesh run.")


def finite_load(runs):
    """{group title: sentences} on the case's load against the neo-Hookean reference, or {}
    where no run has one: the ranking by displacement (and reaction), fem-linear's error
    named its linearisation error, and the failures."""
    if not any(r.get("nh_error_estimate") is not None or r.get("finite_failed")
               for r in runs):
        return {}
    nh = "nh_error_estimate"
    out = [best_and_worst(runs, "disp_rel_l2_nh", "Displacement at the case's load",
                          estimate_key=nh)]
    out += ranking(runs, "disp_rel_l2_nh", "displacement error", nh)
    if any(r.get("reaction_rel_err_nh") is not None for r in runs):
        out += ranking(runs, "reaction_rel_err_nh", "reaction error", nh)
    lin = [r["disp_rel_l2_nh"] for r in runs
           if r["model"] == "fem-linear" and r.get("disp_rel_l2_nh") is not None]
    if lin:
        out.append("fem-linear's error at the case's load is its linearisation error: "
                   f"{cell(lin, len(lin))}.")
    refs = sorted({f"{r['mesh']}/{r['bc']}" for r in runs if r.get(nh) is None
                   and r.get("finite_failed")})
    if refs:
        out.append("No neo-Hookean reference on " + ", ".join(refs) + ".")
    out.append(failures([r for r in runs if r.get(nh) is not None], "finite_failed",
                        "at the case's load"))
    return {"At the case's load, against the neo-Hookean reference": out}
