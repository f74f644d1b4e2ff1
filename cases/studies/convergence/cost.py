"""Accuracy per cost: each run's displacement error against what one RK4 step of its model
costs on its mesh (``cases.costs``, from `pbcm bench`), and the Pareto front of the models: for
a given cost budget, the least error any model reaches.
"""
import numpy as np

from ...costs import SOURCE, step_cost_us


def pareto(points):
    """The indices of the points (cost, error) no other point beats in both (lower cost and
    lower error, one of them strictly), in increasing cost."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], np.inf
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def accuracy_per_cost(runs, bench, exact=0.0, cancelling=()):
    """{"source", "groups": [{case, bc, points: [...], front: [...]}], "front_counts"}: every
    model run with its step cost, grouped by (case, bc), and how often each model is on the
    front; errors below ``exact`` count as equal (the reference's own level), so that no
    rounding puts a point on the front. The runs of a series that may cancel (``cancelling``:
    (case, mesh, bc, model) whose error is not monotone or whose stiffness ratio crosses 1)
    are drawn, marked ``cancellation``, and never put on the front. None without a bench."""
    if not bench:
        return None
    groups, counts = [], {}
    for case, bc in dict.fromkeys((r["case"], r["bc"]) for r in runs):
        pts = []
        for r in runs:
            if (r["case"], r["bc"]) != (case, bc) or r.get("disp_rel_l2") is None:
                continue
            c = step_cost_us(bench, r["model"], r["tets"])
            if c is not None:
                pts.append({"model": r["model"], "mesh": r["mesh"], "h_mm": r["h_mm"],
                            "tets": r["tets"], "cost_us": c, "disp_rel_l2": r["disp_rel_l2"],
                            "cancellation": (case, r["mesh"], bc, r["model"]) in cancelling})
        eligible = [i for i, p in enumerate(pts) if not p["cancellation"]]
        front = [eligible[i] for i in pareto([(pts[i]["cost_us"],
                                               max(pts[i]["disp_rel_l2"], exact))
                                              for i in eligible])]
        for i in front:
            counts[pts[i]["model"]] = counts.get(pts[i]["model"], 0) + 1
        groups.append({"case": case, "bc": bc, "points": pts, "front": front})
    return {"source": SOURCE, "groups": groups,
            "front_counts": dict(sorted(counts.items(), key=lambda kv: -kv[1]))}


__all__ = ["pareto", "accuracy_per_cost"]
