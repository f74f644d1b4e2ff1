"""Sentences that rank the models of a case's runs, computed from the runs: medians per model,
ties within the reference's error estimate, the closest and farthest model, failures, and the
case's load against the neo-Hookean reference."""
import numpy as np


def _by_model(runs, metric):
    by = {}
    for r in runs:
        if r.get(metric) is not None:
            by.setdefault(r["model"], []).append(r[metric])
    return by


def estimate(runs, key="p2_error_estimate"):
    """The reference's error estimate a ranking of ``runs`` respects: the largest of their
    references' (one per mesh and bc; None where the reference has none); ``key`` the
    reference's (nh_error_estimate for the neo-Hookean one)."""
    est = [r[key] for r in runs if r.get(key) is not None]
    return max(est) if est else None


def ranking(runs, metric, label, estimate_key="p2_error_estimate"):
    """'model: median metric (range)' sentences, best first, over the runs that gave it; a
    model whose median is within the reference's estimate (``estimate_key``) of the one
    above is called tied with it (the reference cannot order them)."""
    by, est = _by_model(runs, metric), estimate(runs, estimate_key)
    med = {m: float(np.median(v)) for m, v in by.items()}
    order = sorted(by, key=med.get)
    out = []
    for k, m in enumerate(order):
        tie = ""
        if k and est is not None and med[m] - med[order[k - 1]] < est:
            tie = f" Tied with {order[k - 1]} (within the reference's estimate {est:.2g})."
        out.append(f"{m}: {label} median {med[m]:.3g} (from {min(by[m]):.3g} to "
                   f"{max(by[m]):.3g} over {len(by[m])} runs).{tie}")
    return out


def best_and_worst(runs, metric, what, exact=False, estimate_key="p2_error_estimate"):
    """One line naming the model closest to FEM and the farthest, by median ``metric``; the
    models within the reference's estimate (``estimate_key``) of the closest are named tied
    with it, and the line says so where that estimate exceeds a fifth of the smallest error
    it ranks (``exact``: the metric is against a closed form, which has no estimate)."""
    by, est = _by_model(runs, metric), None if exact else estimate(runs, estimate_key)
    if not by:
        return f"No model gave {what}."
    med = {m: float(np.median(v)) for m, v in by.items()}
    best, worst = min(med, key=med.get), max(med, key=med.get)
    line = (f"{what}: closest {best} (median error {med[best]:.3g}), farthest {worst} "
            f"({med[worst]:.3g}).")
    if est is None:
        return line
    tied = [m for m in sorted(med, key=med.get) if m != best and med[m] - med[best] < est]
    if tied:
        line += f" Tied with {best} within the reference's estimate {est:.2g}: {', '.join(tied)}."
    smallest = min(min(v) for v in by.values())
    if est > smallest / 5:
        line += (f" The reference's estimate ({est:.2g}) exceeds a fifth of the smallest "
                 f"error ranked ({smallest:.2g}): differences below it are not resolved.")
    return line


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
        out.append(f"fem-linear's error at the case's load is its linearisation error: "
                   f"median {np.median(lin):.3g} (from {min(lin):.3g} to {max(lin):.3g}).")
    refs = sorted({f"{r['mesh']}/{r['bc']}" for r in runs if r.get(nh) is None
                   and r.get("finite_failed")})
    if refs:
        out.append("No neo-Hookean reference on " + ", ".join(refs) + ".")
    out.append(failures([r for r in runs if r.get(nh) is not None], "finite_failed",
                        "at the case's load"))
    return {"At the case's load, against the neo-Hookean reference": out}
